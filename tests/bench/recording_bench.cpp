// Recording encode/decode throughput on a 90 Hz × 60 s two-hand session built in memory.
#include <benchmark/benchmark.h>

#include <cmath>

#include <glm/gtc/quaternion.hpp>

#include "input/recording.h"

using namespace lobe;

namespace {

const Recording& minute_of_two_hands()
{
    static const Recording rec = [] {
        Recording r;
        r.header.source = "bench";
        const int frames = 90 * 60;
        r.frames.reserve(frames);
        for (int i = 0; i < frames; ++i) {
            HandFrame f;
            f.time = i / 90.0;
            const float t = static_cast<float>(f.time);
            f.head_valid = true;
            f.head.position = {0.0f, 1.6f, 0.0f};
            f.head.orientation = glm::angleAxis(0.1f * std::sin(t), glm::vec3(0, 1, 0));
            for (int h = 0; h < kHandCount; ++h) {
                HandState& hand = f.hands[h];
                hand.active = true;
                for (int j = 0; j < kJointCount; ++j) {
                    const float fj = static_cast<float>(j);
                    JointState& js = hand.joints[j];
                    js.pose.position = {(h == 0 ? -0.2f : 0.2f) + 0.01f * fj + 0.1f * std::sin(t),
                                        1.2f + 0.05f * std::cos(t + fj), -0.4f + 0.002f * fj};
                    js.pose.orientation =
                        glm::angleAxis(t + 0.1f * fj, glm::normalize(glm::vec3(1.0f, std::sin(fj), 0.5f)));
                    js.radius = 0.004f + 0.0002f * fj;
                    js.flags = kAllJointFlags;
                }
            }
            r.frames.push_back(f);
            if (i % 9 == 0) {
                InputEvent e;
                e.time = f.time;
                e.kind = InputEventKind::MouseMove;
                e.x = static_cast<float>(i % 800);
                e.y = 300.0f;
                r.events.push_back(e);
            }
        }
        return r;
    }();
    return rec;
}

void report(benchmark::State& state, std::size_t bytes)
{
    const auto frames = static_cast<std::int64_t>(minute_of_two_hands().frames.size());
    state.SetItemsProcessed(state.iterations() * frames);
    state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(bytes));
    state.counters["file_MB"] = static_cast<double>(bytes) / 1e6;
}

void BM_RecordingEncodeBinary(benchmark::State& state)
{
    const Recording& rec = minute_of_two_hands();
    std::size_t bytes = 0;
    for (auto _ : state) {
        std::string out = encode_recording_binary(rec);
        bytes = out.size();
        benchmark::DoNotOptimize(out.data());
    }
    report(state, bytes);
}
BENCHMARK(BM_RecordingEncodeBinary)->Unit(benchmark::kMillisecond);

void BM_RecordingDecodeBinary(benchmark::State& state)
{
    const std::string bytes = encode_recording_binary(minute_of_two_hands());
    for (auto _ : state) {
        Recording rec = parse_recording(bytes, "bench.lrec");
        benchmark::DoNotOptimize(rec.frames.data());
    }
    report(state, bytes.size());
}
BENCHMARK(BM_RecordingDecodeBinary)->Unit(benchmark::kMillisecond);

void BM_RecordingEncodeText(benchmark::State& state)
{
    const Recording& rec = minute_of_two_hands();
    std::size_t bytes = 0;
    for (auto _ : state) {
        std::string out = encode_recording_text(rec);
        bytes = out.size();
        benchmark::DoNotOptimize(out.data());
    }
    report(state, bytes);
}
BENCHMARK(BM_RecordingEncodeText)->Unit(benchmark::kMillisecond);

void BM_RecordingDecodeText(benchmark::State& state)
{
    const std::string text = encode_recording_text(minute_of_two_hands());
    for (auto _ : state) {
        Recording rec = parse_recording(text, "bench.txt");
        benchmark::DoNotOptimize(rec.frames.data());
    }
    report(state, text.size());
}
BENCHMARK(BM_RecordingDecodeText)->Unit(benchmark::kMillisecond);

} // namespace
