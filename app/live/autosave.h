#pragma once
/// \file autosave.h
/// Autosaves of the live sessions (desktop and VR): the document stamped with how much of the
/// session's recording it holds, written after the recording is flushed, so that
/// `lobesketch recover` can replay the rest of the recording (docs/crash-safety.md).

#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "core/document.h"

namespace lobe {

class RecordingWriter;

/// `doc` stamped with how much of the session's recording it holds: `frames` hand frames,
/// and the end of the recording when `finished` (Document::recording_frames).
Document at_recording_position(const Document& doc, bool recorded, std::uint64_t frames, bool finished);

/// Autosaves written on a thread of their own, so that the frame that completes a stroke never
/// waits for the JSON and the disk (a few milliseconds for a large session, more on a slow
/// card). The caller flushes the session's recording first and submits the document stamped
/// with that position (at_recording_position): whichever autosave is on disk when the program
/// dies, the recording holds everything it holds, and `recover` replays the rest. Newest wins:
/// a document submitted while another is being written replaces any waiting one.
class AutosaveWriter {
public:
    explicit AutosaveWriter(std::string path);
    ~AutosaveWriter(); ///< writes the waiting document, then stops
    AutosaveWriter(const AutosaveWriter&) = delete;
    AutosaveWriter& operator=(const AutosaveWriter&) = delete;

    /// Queues `doc` (stamped) to be written as the autosave. Never waits for the disk.
    void submit(Document doc);
    /// Queues `text` to be written atomically to `path` beside the autosave (empty `text`: the
    /// file is removed), on the same thread after the waiting document: what a live session
    /// keeps outside its document (the L-system sketch). Newest wins, as for documents.
    void submit_beside(std::string path, std::string text);
    /// Waits until every document and file submitted so far is written (or failed to be).
    void wait();
    /// Why writes failed since the last call, one line each, oldest first.
    std::vector<std::string> take_failures();
    /// How many documents were written (not counting the ones a newer one replaced).
    std::uint64_t written() const;
    const std::string& path() const { return path_; }

    /// The autosave after a change of a live session: the session's `recording` (may be null)
    /// flushed on the calling thread, so that it covers what the autosave holds, then `doc`
    /// stamped with that position (at_recording_position) queued. With `wait`, returns once
    /// it is on disk. Empty when queued, else why not (one line: the recording could not be
    /// flushed, and no autosave is queued that it would not cover).
    std::string submit_after_change(RecordingWriter* recording, const Document& doc, std::uint64_t frames,
                                    bool finished, bool wait);

private:
    void run();

    std::string path_;
    mutable std::mutex mutex_;
    std::condition_variable wake_, idle_;
    std::optional<Document> pending_;
    std::optional<std::pair<std::string, std::string>> pending_beside_; ///< path, text
    bool busy_ = false, stop_ = false;
    std::uint64_t written_ = 0;
    std::vector<std::string> failures_;
    std::thread thread_;
};

} // namespace lobe
