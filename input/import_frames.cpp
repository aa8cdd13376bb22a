#include "input/import_frames.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/errors.h"

namespace lobe {

namespace {

using nlohmann::json;

/// Why a frame at source time `t` (seconds) cannot follow the last kept frame at `last`
/// (NaN when there is none yet), or "" when it can: times must increase strictly.
std::string frame_time_problem(double t, double last)
{
    if (!std::isfinite(t)) return "time is not a finite number";
    if (std::isnan(last)) return {};
    if (t < last) return "time goes backwards";
    if (t == last) return "time repeats the previous frame's";
    if (t - last > kMaxFrameGapSeconds) return "time jumps ahead by more than an hour";
    return {};
}

/// Median interval of strictly increasing times as a rate (Hz), or `fallback` when there are
/// fewer than two frames.
double median_rate_hz(const std::vector<HandFrame>& frames, double fallback)
{
    if (frames.size() < 2) return fallback;
    std::vector<double> dt;
    dt.reserve(frames.size() - 1);
    for (std::size_t i = 1; i < frames.size(); ++i) dt.push_back(frames[i].time - frames[i - 1].time);
    const auto mid = dt.begin() + static_cast<std::ptrdiff_t>(dt.size() / 2);
    std::nth_element(dt.begin(), mid, dt.end());
    return *mid > 0.0 ? 1.0 / *mid : fallback;
}

/// Refuses a capture with no usable frame or no frame with a usable hand, notes an early
/// stop, sets the nominal rate and fills the report from `logs` (in order).
/// \param stop why reading stopped early, or "" when the frames array was read to its end
void finish_import(Recording& rec, const std::string& name, const std::string& stop, std::size_t with_hand,
                   std::size_t dropped, ProblemLog& problems, const std::vector<const ProblemLog*>& logs,
                   ReadReport* report)
{
    if (!stop.empty())
        problems.add("frames end early (" + stop + "); the " + std::to_string(rec.frames.size()) +
                     " frames before are kept");
    if (rec.frames.empty()) {
        const std::string why = !stop.empty() ? stop : problems.count() ? problems.first() : "the frames array is empty";
        throw FileError(name, "no usable frame (" + why + ")");
    }
    if (with_hand == 0)
        throw FileError(name, "no frame with a usable hand" +
                                  (problems.count() ? " (" + problems.first() + ")" : std::string()));
    rec.header.nominal_rate_hz = median_rate_hz(rec.frames, rec.header.nominal_rate_hz);
    if (report != nullptr) {
        report->frames_read += rec.frames.size();
        report->frames_dropped += dropped;
        for (const ProblemLog* log : logs) log->write_to(report);
    }
}

} // namespace

void import_frames(std::string_view text, std::size_t frames_offset, const std::string& name,
                   const FrameSource& source, Recording& rec, ReadReport* report,
                   const ProblemLog* earlier_problems)
{
    const double s = source.seconds_per_unit;
    ProblemLog problems;
    std::size_t dropped = 0;
    std::size_t with_hand = 0;
    double first = std::numeric_limits<double>::quiet_NaN();
    double last = std::numeric_limits<double>::quiet_NaN();
    auto drop = [&](std::size_t index, const std::string& why) {
        ++dropped;
        problems.add("frame " + std::to_string(index) + " dropped: " + why);
    };

    std::string stop;
    try {
        stop = for_each_array_element(
            text, frames_offset,
            [&](const json& element, std::size_t index) {
                if (rec.frames.size() >= kMaxRecordingFrames) {
                    problems.add("more than " + std::to_string(kMaxRecordingFrames) + " frames: the rest ignored");
                    return false;
                }
                double t = 0.0;
                const std::string unreadable = source.read_time(element, t);
                if (!unreadable.empty()) {
                    drop(index, unreadable);
                    return true;
                }
                const std::string time_problem = frame_time_problem(t * s, std::isnan(last) ? last : last * s);
                if (!time_problem.empty()) {
                    drop(index, time_problem);
                    return true;
                }
                HandFrame frame;
                const std::string why = source.read_frame(element, index, frame, problems);
                if (!why.empty()) {
                    drop(index, why);
                    return true;
                }
                if (std::isnan(first)) first = t;
                last = t;
                frame.time = (t - first) * s;
                if (frame.hands[0].active || frame.hands[1].active) ++with_hand;
                rec.frames.push_back(frame);
                return true;
            },
            drop);
    } catch (const LiteralError&) {
        throw FileError(name, "frames is not an array");
    }
    std::vector<const ProblemLog*> logs;
    if (earlier_problems != nullptr) logs.push_back(earlier_problems);
    logs.push_back(&problems);
    finish_import(rec, name, stop, with_hand, dropped, problems, logs, report);
}

} // namespace lobe
