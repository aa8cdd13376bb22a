#pragma once
/// \file import_frames.h
/// The frame loop both capture importers run (input/import_leap.cpp, input/import_webxr.cpp):
/// the capture's `frames` array read one element at a time, each frame's time checked and
/// counted from the first kept frame, frames kept or dropped with a problem line, and the
/// common end (a capture with nothing usable refused, the nominal rate, the report). Limits:
/// docs/importers.md, "Untrusted input and limits".

#include <cstddef>
#include <functional>
#include <string>
#include <string_view>

#include <nlohmann/json_fwd.hpp>

#include "core/hand_frame.h"
#include "input/hand_derive.h"
#include "input/recording.h"

namespace lobe {

/// What an importer knows about its source's frames.
struct FrameSource {
    /// Seconds per unit of the source's time stamps (µs: 1e-6, ms: 1e-3).
    double seconds_per_unit = 1.0;
    /// The time stamp of one element of `frames`, in source units, or why the element is
    /// dropped ("not an object"); return "" when `time` was set.
    std::function<std::string(const nlohmann::json& element, double& time)> read_time;
    /// The head and hands of an element whose time was accepted (`frame.time` is set by the
    /// loop afterwards). Returns why the frame is dropped, or ""; a hand that cannot be used
    /// is left inactive with a line in `problems`.
    std::function<std::string(const nlohmann::json& element, std::size_t index, HandFrame& frame,
                              ProblemLog& problems)>
        read_frame;
};

/// Reads the array starting at byte `frames_offset` of `text` into `rec.frames` (at most
/// kMaxRecordingFrames; the rest ignored with a problem line). A frame is dropped, with one
/// problem line ("frame 7 dropped: time goes backwards"), when its element is too large or
/// does not parse, when `read_time` or `read_frame` refuse it, or when its time is not finite,
/// does not increase strictly or jumps ahead by more than kMaxFrameGapSeconds. Kept frames
/// get time = (stamp − first kept stamp) · seconds_per_unit. A truncated array keeps the
/// frames before the cut ("frames end early"). Then `rec.header.nominal_rate_hz` is set from
/// the median frame interval, and `report` (null is fine) gets the counts and the problem
/// lines: those of `earlier_problems` (null: none) first, then the loop's.
/// \throw FileError naming `name` when `frames_offset` does not start an array, when no frame
///        is usable, or when no kept frame has an active hand.
void import_frames(std::string_view text, std::size_t frames_offset, const std::string& name,
                   const FrameSource& source, Recording& rec, ReadReport* report,
                   const ProblemLog* earlier_problems = nullptr);

} // namespace lobe
