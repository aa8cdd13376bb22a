#include "app/live/autosave.h"

#include <filesystem>
#include <system_error>
#include <utility>

#include "core/atomic_file.h"
#include "core/errors.h"
#include "input/recording.h"

namespace lobe {

Document at_recording_position(const Document& doc, bool recorded, std::uint64_t frames, bool finished)
{
    Document out = doc;
    out.recording_frames = recorded ? std::optional<std::uint64_t>(frames) : std::nullopt;
    out.recording_finished = recorded && finished;
    return out;
}

AutosaveWriter::AutosaveWriter(std::string path) : path_(std::move(path)), thread_([this] { run(); }) {}

AutosaveWriter::~AutosaveWriter()
{
    {
        std::lock_guard<std::mutex> lock(mutex_);
        stop_ = true;
    }
    wake_.notify_all();
    thread_.join();
}

void AutosaveWriter::submit(Document doc)
{
    {
        std::lock_guard<std::mutex> lock(mutex_);
        pending_ = std::move(doc); // replaces a waiting one: newest wins
    }
    wake_.notify_one();
}

void AutosaveWriter::submit_beside(std::string path, std::string text)
{
    {
        std::lock_guard<std::mutex> lock(mutex_);
        pending_beside_ = std::make_pair(std::move(path), std::move(text));
    }
    wake_.notify_one();
}

std::string AutosaveWriter::submit_after_change(RecordingWriter* recording, const Document& doc, std::uint64_t frames,
                                                bool finished, bool wait_for_disk)
{
    try {
        if (recording) recording->flush();
    } catch (const Error& e) {
        return e.what();
    }
    submit(at_recording_position(doc, recording != nullptr, frames, finished));
    if (wait_for_disk) wait();
    return {};
}

void AutosaveWriter::wait()
{
    std::unique_lock<std::mutex> lock(mutex_);
    idle_.wait(lock, [&] { return !pending_ && !pending_beside_ && !busy_; });
}

std::vector<std::string> AutosaveWriter::take_failures()
{
    std::lock_guard<std::mutex> lock(mutex_);
    return std::exchange(failures_, {});
}

std::uint64_t AutosaveWriter::written() const
{
    std::lock_guard<std::mutex> lock(mutex_);
    return written_;
}

namespace {

/// Writes `text` atomically to `path`, or removes `path` when `text` is empty.
/// \throw FileError
void write_beside(const std::string& path, const std::string& text)
{
    if (!text.empty()) {
        write_file_atomic(path, text);
        return;
    }
    std::error_code ec;
    std::filesystem::remove(path, ec);
    if (ec) throw FileError(path, "cannot be removed: " + ec.message());
}

} // namespace

void AutosaveWriter::run()
{
    for (;;) {
        std::optional<Document> doc;
        std::optional<std::pair<std::string, std::string>> beside;
        {
            std::unique_lock<std::mutex> lock(mutex_);
            wake_.wait(lock, [&] { return stop_ || pending_.has_value() || pending_beside_.has_value(); });
            // Stopping writes what is still waiting: it is the newest state of the session.
            if (!pending_ && !pending_beside_) return;
            doc = std::move(pending_);
            beside = std::move(pending_beside_);
            pending_.reset();
            pending_beside_.reset();
            busy_ = true;
        }
        std::vector<std::string> why;
        const auto attempt = [&why](const std::string& path, auto&& write) {
            try {
                write();
            } catch (const Error& e) {
                why.push_back(e.what());
            } catch (const std::bad_alloc&) {
                why.push_back(path + ": out of memory while writing the autosave");
            } catch (const std::exception& e) {
                // Nothing may escape the thread (it would end the program): e.g. a JSON library
                // error for a name that is not UTF-8.
                why.push_back(one_line_message(path + ": " + e.what()));
            }
        };
        bool doc_written = false;
        if (doc) attempt(path_, [&] { save_autosave(path_, *doc); doc_written = true; });
        if (beside) attempt(beside->first, [&] { write_beside(beside->first, beside->second); });
        {
            std::lock_guard<std::mutex> lock(mutex_);
            busy_ = false;
            if (doc_written) ++written_;
            for (std::string& w : why)
                if (failures_.size() < 100) failures_.push_back(std::move(w));
        }
        idle_.notify_all();
    }
}

} // namespace lobe
