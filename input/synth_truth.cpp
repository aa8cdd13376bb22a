// The ground-truth file of a synthesized recording: the strokes as the index tip really
// followed them and the scenario's lobe surfaces. Format: docs/scenario-format.md, "Ground
// truth".
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/atomic_file.h"
#include "core/errors.h"
#include "input/synth.h"
#include "input/synth_scenario.h"

namespace lobe {

using json = nlohmann::json;
using namespace synth;

nlohmann::json ground_truth_to_json(const std::vector<GroundTruthStroke>& truth, const std::vector<TruthSurface>& surfaces)
{
    json surf = json::array();
    for (const TruthSurface& s : surfaces) surf.push_back(truth_surface_to_json(s));
    json strokes = json::array();
    for (const GroundTruthStroke& g : truth) {
        json pts = json::array();
        for (const glm::vec3& p : g.points) pts.push_back({p.x, p.y, p.z});
        json stroke = {{"kind", stroke_kind_name(g.kind)},
                       {"hand", hand_name(g.hand)},
                       {"closed", g.closed},
                       {"drag", g.drag},
                       {"t_begin", g.t_begin},
                       {"t_end", g.t_end}};
        if (g.surface >= 0) {
            if (static_cast<std::size_t>(g.surface) >= surfaces.size())
                throw InvalidInput("ground_truth_to_json: a stroke names surface " + std::to_string(g.surface) + " of " +
                                   std::to_string(surfaces.size()) + " given surfaces");
            stroke["surface"] = g.surface;
        }
        stroke["points"] = std::move(pts);
        strokes.push_back(std::move(stroke));
    }
    return {{"format", kTruthFormat}, {"version", 1}, {"surfaces", std::move(surf)}, {"strokes", std::move(strokes)}};
}

std::vector<GroundTruthStroke> load_ground_truth(const std::string& path)
{
    const std::string text = read_file_limited(path, kMaxTruthBytes);
    json j;
    try {
        j = json::parse(text);
    } catch (const json::exception& e) {
        throw FileError(path, "not valid JSON: " + one_line(e.what()));
    }
    try {
        if (!j.is_object() || !j.contains("format") || j["format"] != kTruthFormat)
            fail("format", std::string("expected \"") + kTruthFormat + "\"");
        if (!j.contains("version") || !j["version"].is_number_integer() || j["version"].get<std::int64_t>() != 1)
            fail("version", "unsupported (this build reads 1)");
        if (!j.contains("strokes") || !j["strokes"].is_array()) fail("strokes", "missing array");
        const std::size_t surface_count = truth_surfaces_from_json(j).size();
        std::vector<GroundTruthStroke> out;
        const json& arr = j["strokes"];
        for (std::size_t i = 0; i < arr.size(); ++i) {
            const std::string field = "strokes[" + std::to_string(i) + "]";
            const json& s = arr[i];
            if (!s.is_object()) fail(field, "expected an object");
            GroundTruthStroke g;
            if (!s.contains("kind") || !s["kind"].is_string()) fail(field + ".kind", "missing");
            try {
                g.kind = stroke_kind_from_name(s["kind"].get<std::string>());
            } catch (const InvalidInput& e) {
                fail(field + ".kind", e.what());
            }
            g.hand = parse_hand(s, field);
            for (const char* flag : {"closed", "drag"}) {
                if (!s.contains(flag)) continue;
                if (!s[flag].is_boolean()) fail(field + "." + flag, "expected true or false");
                (std::string(flag) == "closed" ? g.closed : g.drag) = s[flag].get<bool>();
            }
            g.t_begin = get_number(s, "t_begin", field, 0.0);
            g.t_end = get_number(s, "t_end", field, 0.0);
            if (!std::isfinite(g.t_begin) || !std::isfinite(g.t_end) || g.t_end < g.t_begin)
                fail(field, "t_begin/t_end are not a time span");
            if (s.contains("surface")) {
                const json& sf = s["surface"];
                if (!sf.is_number_integer() || sf.get<std::int64_t>() < 0 ||
                    sf.get<std::int64_t>() >= static_cast<std::int64_t>(surface_count))
                    fail(field + ".surface", "expected an index into the file's " + std::to_string(surface_count) +
                                                 " surfaces");
                g.surface = static_cast<int>(sf.get<std::int64_t>());
            }
            if (!s.contains("points")) fail(field + ".points", "missing");
            g.points = parse_curve(s["points"], field + ".points");
            out.push_back(std::move(g));
        }
        return out;
    } catch (const InvalidInput& e) {
        throw FileError(path, one_line(e.what()));
    } catch (const json::exception& e) {
        throw FileError(path, one_line(e.what()));
    }
}

} // namespace lobe
