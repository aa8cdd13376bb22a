#include "app/vr/sketch_run.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <thread>
#include <utility>

#include "app/vr/vr_session.h"

namespace lobe {

namespace {

double thread_cpu_ms()
{
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return double(t.tv_sec) * 1e3 + double(t.tv_nsec) * 1e-6;
}

/// "M ms mean, P ms p99, X ms max" of `ms`.
std::string spread(std::vector<double> ms)
{
    std::sort(ms.begin(), ms.end());
    double sum = 0.0;
    for (double v : ms) sum += v;
    const double mean = ms.empty() ? 0.0 : sum / double(ms.size());
    const double p99 = ms.empty() ? 0.0 : ms[std::min(ms.size() - 1, static_cast<std::size_t>(0.99 * double(ms.size())))];
    char line[128];
    std::snprintf(line, sizeof line, "%.2f ms mean, %.2f ms p99, %.2f ms max", mean, p99, ms.empty() ? 0.0 : ms.back());
    return line;
}

} // namespace

SketchRunResult run_sketch(const Recording& rec, Document doc, const SketchRunOptions& options,
                           const std::function<void(const std::string&)>& on_message)
{
    SketchRunResult result;
    if (rec.frames.empty()) {
        result.document = std::move(doc);
        return result;
    }
    // The session counts time from the first frame.
    const double t0 = rec.frames.front().time;
    VrOptions o;
    o.session_path = options.session_path;
    o.autosave_path = options.autosave_path;
    o.record_path = options.record_path;
    o.background_regrowth = options.background_regrowth;
    o.runtime_name = "sketch";
    o.device_name = rec.header.device;
    o.nominal_rate_hz = rec.header.nominal_rate_hz;
    if (options.events_from_recording) {
        o.events = rec.events;
        for (InputEvent& e : o.events) e.time = std::max(0.0, e.time - t0);
    }
    VrSession session(std::move(doc), std::move(o));

    using Clock = std::chrono::steady_clock;
    const Clock::time_point start = Clock::now();
    result.frame_ms.reserve(rec.frames.size());
    result.frame_cpu_ms.reserve(rec.frames.size());
    std::string last_message;
    double time = 0.0;
    for (const HandFrame& input : rec.frames) {
        HandFrame f = input;
        f.time = input.time - t0;
        time = f.time;
        if (options.realtime) std::this_thread::sleep_until(start + std::chrono::duration<double>(f.time));
        const Clock::time_point before = Clock::now();
        const double cpu_before = thread_cpu_ms();
        session.frame(f);
        result.frame_cpu_ms.push_back(thread_cpu_ms() - cpu_before);
        result.frame_ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - before).count());
        if (session.status().last_message != last_message) {
            last_message = session.status().last_message;
            if (!last_message.empty() && on_message) on_message(last_message);
        }
        if (session.quit_requested()) break;
    }
    session.finish(time + 1e-3);
    result.total_s = std::chrono::duration<double>(Clock::now() - start).count();
    result.session_s = time;
    result.document = session.document();
    return result;
}

std::string frame_time_summary(const SketchRunResult& result)
{
    char head[96];
    std::snprintf(head, sizeof head, "%zu frames in %.2f s; ", result.frame_ms.size(), result.total_s);
    return head + ("frame " + spread(result.frame_ms)) + "; CPU " + spread(result.frame_cpu_ms);
}

} // namespace lobe
