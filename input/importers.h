#pragma once
/// \file importers.h
/// Importers for real hand-tracking captures made by other programs, mapped onto the
/// 26-joint OpenXR layout (palm, orientations and radii derived where the source lacks them),
/// in metres, stage space, time in seconds from the first kept frame. Each treats the file as
/// hostile: what it drops or repairs is listed in `report` (null is fine). Mappings and
/// limits: docs/importers.md.

#include <string>

#include "input/recording.h"

namespace lobe {

/// leapjs-playback JSON (`{metadata, frames[]}`, millimetres, Leap device frame, +Y up).
/// The device is placed at `kLeapDeviceOrigin` in stage space (a desk in front of a seated
/// user), converted to metres.
/// \throw FileError naming the file and the problem when nothing usable remains.
Recording import_leap_json(const std::string& path, ReadReport* report = nullptr);
/// The same from the file's text in memory; `name` stands for the file in messages.
Recording import_leap_json_text(const std::string& text, const std::string& name, ReadReport* report = nullptr);

/// WebXR hand capture written by the Immersive Web Emulation Runtime's ActionRecorder (a JS
/// module `var a={schema,frames}`; 25 joints without palm, relative to the target-ray pose).
/// \throw FileError naming the file and the problem when nothing usable remains.
Recording import_webxr_capture(const std::string& path, ReadReport* report = nullptr);
/// The same from the file's text in memory; `name` stands for the file in messages.
Recording import_webxr_capture_text(const std::string& text, const std::string& name, ReadReport* report = nullptr);

} // namespace lobe
