// Recordings replayed through the input pipeline: real captures and every shipped scenario.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>

#include "input/importers.h"
#include "input/pipeline.h"
#include "input/synth.h"
#include "tests/support/test_data.h"

using namespace lobe;

namespace {

double point_segment_distance(const glm::vec3& p, const glm::vec3& a, const glm::vec3& b)
{
    const glm::vec3 ab = b - a;
    const float len2 = glm::dot(ab, ab);
    const float t = len2 > 0 ? std::clamp(glm::dot(p - a, ab) / len2, 0.0f, 1.0f) : 0.0f;
    return glm::distance(p, a + t * ab);
}

double distance_to_polyline(const glm::vec3& p, const std::vector<glm::vec3>& line)
{
    double best = std::numeric_limits<double>::max();
    for (std::size_t i = 1; i < line.size(); ++i) best = std::min(best, point_segment_distance(p, line[i - 1], line[i]));
    if (line.size() == 1) best = glm::distance(p, line[0]);
    return best;
}

double mean_distance(const Stroke& s, const std::vector<glm::vec3>& truth)
{
    double sum = 0;
    for (const StrokePoint& p : s.points) sum += distance_to_polyline(p.position, truth);
    return sum / static_cast<double>(s.points.size());
}

double polyline_length(const std::vector<glm::vec3>& line)
{
    double len = 0;
    for (std::size_t i = 1; i < line.size(); ++i) len += glm::distance(line[i - 1], line[i]);
    return len;
}

/// The scenarios in `recordings` (the project's recordings/ folder), sorted.
std::vector<std::string> shipped_scenarios(const std::string& recordings)
{
    std::vector<std::string> out;
    for (const auto& e : std::filesystem::directory_iterator(recordings)) {
        const std::string name = e.path().filename().string();
        if (name.size() > 14 && name.ends_with(".scenario.json")) out.push_back(e.path().string());
    }
    std::sort(out.begin(), out.end());
    return out;
}

// Checks that every drawn ground-truth stroke is recovered exactly once (no split, no merge,
// no spurious stroke), of the right kind, within 3 mm on average, covering the curve.
void expect_strokes_match_truth(const InputResult& r, const std::vector<GroundTruthStroke>& truth,
                                const std::string& name)
{
    std::vector<const GroundTruthStroke*> drawn;
    for (const GroundTruthStroke& t : truth)
        if (!t.drag) drawn.push_back(&t);
    ASSERT_EQ(r.strokes.size(), drawn.size()) << name;
    std::vector<int> hits(drawn.size(), 0);
    for (const Stroke& s : r.strokes) {
        // The truth stroke this one belongs to: the one whose time span it overlaps most.
        int best = -1;
        double best_overlap = 0;
        for (std::size_t i = 0; i < drawn.size(); ++i) {
            const double lo = std::max(s.points.front().time, drawn[i]->t_begin);
            const double hi = std::min(s.points.back().time, drawn[i]->t_end);
            if (hi - lo > best_overlap) {
                best_overlap = hi - lo;
                best = static_cast<int>(i);
            }
        }
        ASSERT_GE(best, 0) << name << ": stroke " << s.id << " matches no ground-truth stroke";
        ++hits[best];
        const GroundTruthStroke& t = *drawn[best];
        EXPECT_EQ(s.kind, t.kind) << name << " stroke " << s.id;
        EXPECT_LE(mean_distance(s, t.points), 0.003) << name << " stroke " << s.id;
        EXPECT_GE(s.length(), 0.9 * polyline_length(t.points)) << name << " stroke " << s.id;
        EXPECT_LE(s.length(), 1.1 * polyline_length(t.points)) << name << " stroke " << s.id;
    }
    for (std::size_t i = 0; i < drawn.size(); ++i)
        EXPECT_EQ(hits[i], 1) << name << ": ground-truth stroke " << i << " recovered " << hits[i] << " times";
}

} // namespace

TEST(ReplayRealCapture, LeapPinchClipYieldsExactlyOnePinch)
{
    const std::string path = test::shared_data("data/real/leap-pinch.json");
    if (path.empty()) return;
    Recording rec = import_leap_json(path);
    InputPipeline pipe;
    int starts = 0, ends = 0;
    for (const HandFrame& f : rec.frames) {
        pipe.push_frame(f);
        const HandGesture& g = pipe.gestures().hand(Hand::Right);
        starts += g.pinch_started;
        ends += g.pinch_ended;
        EXPECT_FALSE(g.grabbing) << "t=" << f.time;
    }
    EXPECT_EQ(starts, 1);
    EXPECT_EQ(ends, 1);
}

TEST(ReplayRealCapture, LeapGrabClipIsAGrabAndDrawsNoStroke)
{
    const std::string path = test::shared_data("data/real/leap-grab.json");
    if (path.empty()) return;
    Recording rec = import_leap_json(path);
    InputResult r = run_input_pipeline(rec);
    EXPECT_EQ(r.pinches, 0u);
    EXPECT_GE(r.grabs, 1u);
    EXPECT_TRUE(r.strokes.empty());
    EXPECT_TRUE(r.drags.empty());
}

TEST(ReplayRealCapture, QuestWebXRCaptureGivesFiniteStrokesNearTheHead)
{
    const std::string path = test::shared_data("data/real/quest3-webxr-capture.min.js");
    if (path.empty()) return;
    Recording rec = import_webxr_capture(path);
    InputResult r = run_input_pipeline(rec);
    glm::vec3 head(0.0f);
    int n = 0;
    for (const HandFrame& f : rec.frames)
        if (f.head_valid) {
            head += f.head.position;
            ++n;
        }
    ASSERT_GT(n, 0);
    head /= static_cast<float>(n);
    for (const Stroke& s : r.strokes)
        for (const StrokePoint& p : s.points) {
            EXPECT_TRUE(std::isfinite(p.position.x) && std::isfinite(p.position.y) && std::isfinite(p.position.z));
            EXPECT_LT(glm::distance(p.position, head), 1.5f);
        }
}

TEST(ReplayScenario, EveryShippedRecordingRecoversEachGroundTruthStrokeOnce)
{
    const std::string recordings = test::source_data("recordings");
    if (recordings.empty()) return;
    auto scenarios = shipped_scenarios(recordings);
    ASSERT_GE(scenarios.size(), 4u);
    for (const std::string& sc : scenarios) {
        const std::string stem = sc.substr(0, sc.size() - std::string(".scenario.json").size());
        const std::string rec_path = stem + ".lrec";
        if (!test::require_data(rec_path) || !test::require_data(stem + ".truth.json")) return;
        Recording rec = read_recording(rec_path);
        auto truth = load_ground_truth(stem + ".truth.json");
        expect_strokes_match_truth(run_input_pipeline(rec), truth, rec_path);
    }
}

TEST(ReplayScenario, FreshlySynthesizedScenariosRecoverEachGroundTruthStrokeOnce)
{
    // The shipped recordings are fixed fixtures; this checks the synthesizer and the pipeline
    // agree today on the same scenarios, including through the text form.
    const std::string recordings = test::source_data("recordings");
    if (recordings.empty()) return;
    for (const std::string& sc : shipped_scenarios(recordings)) {
        SynthResult fresh = synthesize(load_scenario(sc));
        expect_strokes_match_truth(run_input_pipeline(fresh.recording), fresh.truth, sc);
        Recording text = parse_recording(encode_recording_text(fresh.recording), sc + " (text)");
        expect_strokes_match_truth(run_input_pipeline(text), fresh.truth, sc + " (text)");
    }
}

TEST(ReplayScenario, ShippedRecordingsAreUpToDateWithTheirScenarios)
{
    // The synthesizer is deterministic, so each shipped recording and truth file must be what
    // its scenario gives today; when this fails, run scripts/make-recordings.sh.
    auto read_all = [](const std::string& path) {
        std::ifstream in(path, std::ios::binary);
        std::ostringstream os;
        os << in.rdbuf();
        return os.str();
    };
    const std::string recordings = test::source_data("recordings");
    if (recordings.empty()) return;
    for (const std::string& sc : shipped_scenarios(recordings)) {
        const std::string stem = sc.substr(0, sc.size() - std::string(".scenario.json").size());
        if (!test::require_data(stem + ".lrec") || !test::require_data(stem + ".truth.json")) continue;
        SCOPED_TRACE(sc);
        const SynthResult fresh = synthesize(load_scenario(sc));
        EXPECT_TRUE(encode_recording_binary(fresh.recording) == read_all(stem + ".lrec"))
            << stem << ".lrec is stale: run scripts/make-recordings.sh";
        const nlohmann::json truth = nlohmann::json::parse(read_all(stem + ".truth.json"));
        EXPECT_TRUE(truth == ground_truth_to_json(fresh.truth, fresh.surfaces))
            << stem << ".truth.json is stale: run scripts/make-recordings.sh";
    }
}

TEST(ReplayScenario, ReplayIsDeterministic)
{
    const std::string rec_path = test::source_data("recordings/demo.lrec");
    if (rec_path.empty()) return;
    Recording rec = read_recording(rec_path);
    InputResult a = run_input_pipeline(rec);
    InputResult b = run_input_pipeline(rec);
    ASSERT_EQ(a.strokes.size(), b.strokes.size());
    for (std::size_t i = 0; i < a.strokes.size(); ++i) {
        ASSERT_EQ(a.strokes[i].points.size(), b.strokes[i].points.size());
        for (std::size_t k = 0; k < a.strokes[i].points.size(); ++k)
            ASSERT_EQ(a.strokes[i].points[k].position, b.strokes[i].points[k].position);
    }
}
