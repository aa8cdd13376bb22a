#include "app/autosave.h"

#include "core/errors.h"

namespace lobe {

Document at_recording_position(const Document& doc, bool recorded, std::uint64_t frames, bool finished)
{
    Document out = doc;
    out.recording_frames = recorded ? std::optional<std::uint64_t>(frames) : std::nullopt;
    out.recording_finished = recorded && finished;
    return out;
}

std::string write_autosave(const std::string& path, RecordingWriter* recording, const Document& doc,
                           std::uint64_t frames, bool finished)
{
    try {
        if (recording) recording->flush();
        save_autosave(path, at_recording_position(doc, recording != nullptr, frames, finished));
        return {};
    } catch (const Error& e) {
        return e.what();
    }
}

} // namespace lobe
