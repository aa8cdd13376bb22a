// Per-frame CPU cost of the VR loop without its drawing: VrSession::frame (input filters,
// gestures, panel, scene grab, the document, autosave, taking finished regrowths and building
// the scene's moving parts) on the largest Table 1 session, with regrowth on its worker thread
// as in the headset. The frame thread's budget at 90 Hz is 11.1 ms, drawing included.
#include <algorithm>
#include <chrono>
#include <ctime>
#include <filesystem>
#include <vector>

#include <benchmark/benchmark.h>

#include "app/vr/vr_session.h"
#include "input/recording.h"
#include "tests/support/test_paths.h"

using namespace lobe;

namespace {

const Recording& table1_four_lobes()
{
    static const Recording rec = read_recording(test::source_path("recordings/table1-4lobes-22strokes.lrec"));
    return rec;
}

double thread_cpu_ms()
{
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return double(t.tv_sec) * 1e3 + double(t.tv_nsec) * 1e-6;
}

/// One whole session per iteration; per-frame times (ms) go into the counters: wall time
/// (frame_*), and the frame thread's CPU time (cpu_*), which a shared, busy machine does not
/// inflate by preempting the thread.
void run_session(benchmark::State& state, bool autosave)
{
    const Recording& rec = table1_four_lobes();
    const double t0 = rec.frames.front().time;
    const std::string dir = (std::filesystem::temp_directory_path() / "lobesketch_vr_bench").string();
    std::filesystem::create_directories(dir);
    std::vector<double> ms, cpu;
    ms.reserve(rec.frames.size() * 4);
    cpu.reserve(rec.frames.size() * 4);
    for (auto _ : state) {
        state.PauseTiming();
        VrOptions o;
        for (InputEvent e : rec.events) {
            e.time -= t0;
            o.events.push_back(e);
        }
        if (autosave) {
            o.autosave_path = dir + "/autosave.json";
            o.record_path = dir + "/session.lrec";
        }
        auto session = std::make_unique<VrSession>(Document{}, o);
        state.ResumeTiming();
        for (HandFrame f : rec.frames) {
            f.time -= t0;
            const auto a = std::chrono::steady_clock::now();
            const double c = thread_cpu_ms();
            session->frame(f);
            benchmark::DoNotOptimize(session->scene().items.size());
            cpu.push_back(thread_cpu_ms() - c);
            ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - a).count());
        }
        state.PauseTiming();
        session.reset(); // joins the regrowth worker
        state.ResumeTiming();
    }
    auto report = [&](std::vector<double>& v, const std::string& name) {
        std::sort(v.begin(), v.end());
        auto at = [&](double q) { return v.empty() ? 0.0 : v[std::min(v.size() - 1, std::size_t(q * double(v.size())))]; };
        double sum = 0.0;
        for (double x : v) sum += x;
        state.counters[name + "_mean_ms"] = v.empty() ? 0.0 : sum / double(v.size());
        state.counters[name + "_p50_ms"] = at(0.5);
        state.counters[name + "_p99_ms"] = at(0.99);
        state.counters[name + "_max_ms"] = v.empty() ? 0.0 : v.back();
    };
    report(ms, "frame");
    report(cpu, "cpu");
    state.counters["frames"] = double(rec.frames.size());
}

} // namespace

static void BM_VrSessionFrameTable1FourLobes(benchmark::State& state) { run_session(state, false); }
BENCHMARK(BM_VrSessionFrameTable1FourLobes)->Unit(benchmark::kMillisecond)->Iterations(1);

static void BM_VrSessionFrameTable1FourLobesRecordedAndAutosaved(benchmark::State& state) { run_session(state, true); }
BENCHMARK(BM_VrSessionFrameTable1FourLobesRecordedAndAutosaved)->Unit(benchmark::kMillisecond)->Iterations(1);
