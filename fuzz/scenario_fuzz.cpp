// libFuzzer target: scenario files (`lobesketch synth SCENARIO`) through the in-memory half of
// load_scenario: the JSON is parsed, then scenario_from_json reads and validates it (a JSON
// type error is refused too: load_scenario turns it into a one-line FileError). A scenario that
// reads and would take at most 30 s of hand motion is synthesized, and the recording must keep
// recording.h's promises; longer ones are left out so that a run stays fast.
#include <cstdint>

#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>

#include "fuzz/fuzz_common.h"
#include "input/synth.h"

namespace {

/// An upper bound of the scenario's duration in seconds: the timed steps, and every stroke at
/// the slowest speed the synthesizer picks (0.2 m/s unless the step sets one) plus 3 s for
/// reaching it, pinching and releasing.
double longest_duration_s(const lobe::Scenario& sc)
{
    double total = 0.0;
    for (const lobe::ScenarioStep& st : sc.steps) {
        total += st.duration_s + 3.0;
        if (st.type != lobe::ScenarioStep::Type::Stroke && st.type != lobe::ScenarioStep::Type::Drag) continue;
        double length = 0.0;
        for (std::size_t i = 1; i < st.stroke.curve.size(); ++i)
            length += glm::length(st.stroke.curve[i] - st.stroke.curve[i - 1]);
        total += length / (st.stroke.speed_mps > 0.0 ? st.stroke.speed_mps : 0.2);
    }
    return total;
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    const std::string text = lobe::fuzz::as_string(data, size);
    return lobe::fuzz::run_reader([&] {
        const nlohmann::json j = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
        if (j.is_discarded()) return;
        lobe::Scenario sc;
        try {
            sc = lobe::scenario_from_json(j);
        } catch (const nlohmann::json::exception&) {
            return; // load_scenario: FileError(path, one_line(what))
        }
        if (longest_duration_s(sc) > 30.0) return;
        const lobe::SynthResult r = lobe::synthesize(sc);
        lobe::fuzz::check_recording(r.recording);
        for (const lobe::GroundTruthStroke& t : r.truth)
            for (const glm::vec3& p : t.points) lobe::fuzz::require(lobe::fuzz::finite(p), "a non-finite ground-truth point");
    });
}
