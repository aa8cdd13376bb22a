// Per-frame CPU cost of the VR loop without its drawing: VrSession::frame (input filters,
// gestures, panel, scene grab, the document, autosave, taking finished regrowths and building
// the scene's moving parts) on the largest Table 1 session, with regrowth on its worker thread
// as in the headset. The frame thread's budget at 90 Hz is 11.1 ms, drawing included.
#include <algorithm>
#include <chrono>
#include <filesystem>
#include <vector>

#include <benchmark/benchmark.h>

#include "app/vr_session.h"
#include "input/recording.h"
#include "tests/test_paths.h"

using namespace lobe;

namespace {

const Recording& table1_four_lobes()
{
    static const Recording rec = read_recording(test::source_path("recordings/table1-4lobes-22strokes.lrec"));
    return rec;
}

/// One whole session per iteration; per-frame times (ms) go into the counters.
void run_session(benchmark::State& state, bool autosave)
{
    const Recording& rec = table1_four_lobes();
    const double t0 = rec.frames.front().time;
    const std::string dir = (std::filesystem::temp_directory_path() / "lobesketch_vr_bench").string();
    std::filesystem::create_directories(dir);
    std::vector<double> ms;
    ms.reserve(rec.frames.size() * 4);
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
            session->frame(f);
            benchmark::DoNotOptimize(session->scene().items.size());
            ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - a).count());
        }
        state.PauseTiming();
        session.reset(); // joins the regrowth worker
        state.ResumeTiming();
    }
    std::sort(ms.begin(), ms.end());
    auto at = [&](double q) { return ms.empty() ? 0.0 : ms[std::min(ms.size() - 1, std::size_t(q * double(ms.size())))]; };
    double sum = 0.0;
    for (double v : ms) sum += v;
    state.counters["frame_mean_ms"] = ms.empty() ? 0.0 : sum / double(ms.size());
    state.counters["frame_p50_ms"] = at(0.5);
    state.counters["frame_p99_ms"] = at(0.99);
    state.counters["frame_max_ms"] = ms.empty() ? 0.0 : ms.back();
    state.counters["frames"] = double(rec.frames.size());
}

} // namespace

static void BM_VrSessionFrameTable1FourLobes(benchmark::State& state) { run_session(state, false); }
BENCHMARK(BM_VrSessionFrameTable1FourLobes)->Unit(benchmark::kMillisecond)->Iterations(1);

static void BM_VrSessionFrameTable1FourLobesRecordedAndAutosaved(benchmark::State& state) { run_session(state, true); }
BENCHMARK(BM_VrSessionFrameTable1FourLobesRecordedAndAutosaved)->Unit(benchmark::kMillisecond)->Iterations(1);
