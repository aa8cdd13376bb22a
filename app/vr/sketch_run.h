#pragma once
/// \file sketch_run.h
/// A recording's hand frames fed one by one through the live VrSession: what `lobesketch
/// sketch` does, and what the soak (tests/app/vr/soak.cpp) repeats for half an hour in one process.

#include <functional>
#include <string>
#include <vector>

#include "core/document.h"
#include "input/recording.h"

namespace lobe {

struct SketchRunOptions {
    std::string session_path;  ///< written (atomically) when the recording ends
    std::string autosave_path; ///< written after every change of the document
    std::string record_path;   ///< the session's own recording
    bool realtime = false;     ///< feed each frame at its time (else as fast as the session runs)
    bool events_from_recording = false; ///< apply the recording's event track at its times
    bool background_regrowth = true;    ///< regrow off the frame thread, as live
};

struct SketchRunResult {
    Document document;            ///< the session's document once it ended
    std::vector<double> frame_ms;     ///< wall time VrSession::frame took, per frame fed
    std::vector<double> frame_cpu_ms; ///< CPU time of the calling thread in it: what the frame itself
                                      ///< cost, without the waits a busy machine adds
    double total_s = 0.0;         ///< wall time of the whole run
    double session_s = 0.0;       ///< time of the last frame fed, from the first
};

/// Runs `rec` through a VrSession that starts from `doc`. `on_message` (may be empty) gets
/// every new status line as it appears. Stops early when the panel's Quit is pressed.
/// \throw FileError when the autosave, session or recording cannot be written.
SketchRunResult run_sketch(const Recording& rec, Document doc, const SketchRunOptions& options,
                           const std::function<void(const std::string&)>& on_message = {});

/// "N frames in S s; frame M ms mean, P ms p99, X ms max; CPU M ms mean, P ms p99, X ms max".
std::string frame_time_summary(const SketchRunResult& result);

} // namespace lobe
