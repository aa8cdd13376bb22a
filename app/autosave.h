#pragma once
/// \file autosave.h
/// Autosaves of the live sessions (desktop and VR): the document stamped with how much of the
/// session's recording it holds, written after the recording is flushed, so that
/// `lobesketch recover` can replay the rest of the recording (docs/crash-safety.md).

#include <cstdint>
#include <string>

#include "core/document.h"
#include "input/recording.h"

namespace lobe {

/// `doc` stamped with how much of the session's recording it holds: `frames` hand frames,
/// and the end of the recording when `finished` (Document::recording_frames).
Document at_recording_position(const Document& doc, bool recorded, std::uint64_t frames, bool finished);

/// The autosave after a change: the recording flushed first, so that it always covers what the
/// autosave holds. Empty when it worked, else why not (one line).
std::string write_autosave(const std::string& path, RecordingWriter* recording, const Document& doc,
                           std::uint64_t frames, bool finished);

} // namespace lobe
