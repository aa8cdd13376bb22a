// Scenarios: the JSON form read into a Scenario (with the "ellipse" and "section" curve
// generators), and the checks every scenario passes before it is synthesized. Format and
// limits: docs/scenario-format.md.
#include "input/synth_scenario.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <sstream>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>

#include "core/atomic_file.h"
#include "core/errors.h"
#include "input/synth_geometry.h"
#include "input/synth_random.h"

namespace lobe {

namespace synth {

using json = nlohmann::json;

std::string num(double v)
{
    std::ostringstream os;
    os.imbue(std::locale::classic());
    os.precision(6);
    os << v;
    return os.str();
}

[[noreturn]] void fail(const std::string& field, const std::string& what)
{
    throw InvalidInput(field + ": " + what);
}

std::string one_line(std::string s)
{
    for (char& c : s)
        if (c == '\n' || c == '\r') c = ' ';
    return s;
}

namespace {

std::string step_field(std::size_t i, const char* field)
{
    return "steps[" + std::to_string(i) + "]" + (field[0] ? std::string(".") + field : std::string());
}

void check_point(const glm::vec3& p, const std::string& field)
{
    for (int a = 0; a < 3; ++a) {
        if (!std::isfinite(p[a])) fail(field, "coordinate is not finite");
        if (std::abs(p[a]) > kMaxCoordinate)
            fail(field, "coordinate " + num(p[a]) + " m is beyond " + num(kMaxCoordinate) + " m");
    }
}

void allow_only(const json& obj, const std::string& field, std::initializer_list<const char*> keys)
{
    for (auto it = obj.begin(); it != obj.end(); ++it) {
        bool known = it.key() == "comment";
        for (const char* k : keys) known = known || it.key() == k;
        if (!known) fail(field, "unknown field '" + it.key() + "'");
    }
}

glm::vec3 parse_vec3(const json& v, const std::string& field)
{
    if (!v.is_array() || v.size() != 3) fail(field, "expected [x, y, z]");
    glm::vec3 p;
    for (int a = 0; a < 3; ++a) {
        const json& c = v[static_cast<std::size_t>(a)];
        if (!c.is_number()) fail(field, "expected [x, y, z] numbers");
        double d = c.get<double>();
        if (!std::isfinite(d)) fail(field, "coordinate is not finite");
        if (std::abs(d) > kMaxCoordinate) fail(field, "coordinate " + num(d) + " m is beyond " + num(kMaxCoordinate) + " m");
        p[a] = static_cast<float>(d);
    }
    return p;
}

glm::vec3 required_vec3(const json& obj, const char* key, const std::string& field)
{
    auto it = obj.find(key);
    if (it == obj.end()) fail(field, std::string("missing '") + key + "'");
    return parse_vec3(*it, field + "." + key);
}

int parse_key(const json& v, const std::string& field)
{
    if (v.is_number_integer()) {
        auto k = v.get<std::int64_t>();
        if (k < 32 || k > 348) fail(field, std::to_string(k) + " is not a GLFW key code (32–348)");
        return static_cast<int>(k);
    }
    if (v.is_string()) {
        std::string s = v.get<std::string>();
        if (s.size() == 1) {
            char c = s[0];
            if (c >= 'a' && c <= 'z') c = static_cast<char>(c - 'a' + 'A');
            if ((c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9')) return c; // GLFW_KEY_A = 'A', GLFW_KEY_0 = '0'
        }
        fail(field, "unknown key \"" + one_line(s.substr(0, 40)) + "\" (a letter, a digit or a GLFW code)");
    }
    fail(field, "expected a key letter or a GLFW key code");
}

} // namespace

// ---------------------------------------------------------------------------------------
// Validation shared by JSON scenarios and scenarios built in code
// ---------------------------------------------------------------------------------------

void validate_scenario(const Scenario& s)
{
    if (!(s.rate_hz >= kMinRateHz && s.rate_hz <= kMaxRateHz))
        fail("rate_hz", num(s.rate_hz) + " Hz is outside [" + num(kMinRateHz) + ", " + num(kMaxRateHz) + "]");
    if (s.steps.size() > kMaxSteps)
        fail("steps", std::to_string(s.steps.size()) + " steps exceed the limit of " + std::to_string(kMaxSteps));
    if (!(s.uniform_joint_radius_m >= 0.0 && s.uniform_joint_radius_m <= 0.05))
        fail("uniform_joint_radius", num(s.uniform_joint_radius_m) + " m is outside [0, 0.05]");
    for (std::size_t k = 0; k < s.surfaces.size(); ++k)
        validate_truth_surface(s.surfaces[k], "surfaces[" + std::to_string(k) + "]");
    double estimate = 1.5;
    double total_length = 0.0;
    for (std::size_t i = 0; i < s.steps.size(); ++i) {
        const ScenarioStep& st = s.steps[i];
        switch (st.type) {
        case ScenarioStep::Type::Stroke:
        case ScenarioStep::Type::Drag: {
            const ScenarioStroke& sk = st.stroke;
            const std::string field = step_field(i, "curve");
            if (sk.curve.size() > kMaxCurvePoints)
                fail(field, std::to_string(sk.curve.size()) + " points exceed the limit of " +
                                std::to_string(kMaxCurvePoints));
            for (std::size_t k = 0; k < sk.curve.size(); ++k)
                check_point(sk.curve[k], field + "[" + std::to_string(k) + "]");
            const std::size_t distinct = distinct_points(sk.curve, sk.closed).size();
            if (distinct < (sk.closed ? 3u : 2u))
                fail(field, std::string("needs at least ") + (sk.closed ? "3" : "2") + " distinct points");
            double len = polyline_length(sk.curve, sk.closed);
            if (len > kMaxStrokeLength)
                fail(field, "curve is " + num(len) + " m long, more than " + num(kMaxStrokeLength) + " m");
            total_length += len;
            if (total_length > kMaxTotalStrokeLength)
                fail("steps", "strokes add up to more than " + num(kMaxTotalStrokeLength) + " m");
            if (sk.surface != -1) {
                if (st.type == ScenarioStep::Type::Drag || sk.surface < 0 ||
                    static_cast<std::size_t>(sk.surface) >= s.surfaces.size())
                    fail(step_field(i, "surface"), "names no surface (the scenario has " +
                                                       std::to_string(s.surfaces.size()) + ")");
                const TruthSurface& surf = s.surfaces[static_cast<std::size_t>(sk.surface)];
                for (std::size_t k = 0; k < sk.curve.size(); ++k) {
                    const double gap = radial_gap(surf, to_d(sk.curve[k]));
                    if (!(std::abs(gap) <= kMaxSurfaceGap) || glm::distance(to_d(sk.curve[k]), surf.center) < 1e-6)
                        fail(field + "[" + std::to_string(k) + "]",
                             "lies " + num(gap * 1000.0) + " mm off surface " + std::to_string(sk.surface) +
                                 " (a stroke drawn on a surface must lie on it within 1 mm)");
                }
            }
            if (sk.speed_mps != 0.0 && !(sk.speed_mps >= kMinSpeed && sk.speed_mps <= kMaxSpeed))
                fail(step_field(i, "speed"), num(sk.speed_mps) + " m/s is outside [" + num(kMinSpeed) + ", " +
                                                 num(kMaxSpeed) + "]");
            estimate += 1.875 * len / (sk.speed_mps > 0.0 ? sk.speed_mps : 1.0) + 1.3;
            break;
        }
        case ScenarioStep::Type::NearPinch:
        case ScenarioStep::Type::Grab: {
            check_point(st.where, step_field(i, "at"));
            const double lo = st.type == ScenarioStep::Type::Grab ? 0.5 : 0.3;
            if (!(st.duration_s >= lo && st.duration_s <= 60.0))
                fail(step_field(i, "duration"), num(st.duration_s) + " s is outside [" + num(lo) + ", 60]");
            estimate += st.duration_s + 0.6;
            break;
        }
        case ScenarioStep::Type::Key:
            if (st.key < 32 || st.key > 348)
                fail(step_field(i, "key"), std::to_string(st.key) + " is not a GLFW key code (32–348)");
            estimate += 0.35;
            break;
        case ScenarioStep::Type::Pause:
            if (!(st.duration_s >= 0.0 && st.duration_s <= 3600.0))
                fail(step_field(i, "duration"), num(st.duration_s) + " s is outside [0, 3600]");
            estimate += st.duration_s;
            break;
        }
        if (estimate > kMaxDurationS)
            fail("steps", "the scenario lasts more than " + num(kMaxDurationS) + " s (2 h)");
    }
}

// ---------------------------------------------------------------------------------------
// JSON scenarios
// ---------------------------------------------------------------------------------------

double get_number(const json& obj, const char* key, const std::string& field, double fallback)
{
    auto it = obj.find(key);
    if (it == obj.end()) return fallback;
    if (!it->is_number()) fail(field + "." + key, "expected a number");
    return it->get<double>();
}

Hand parse_hand(const json& obj, const std::string& field)
{
    auto it = obj.find("hand");
    if (it == obj.end()) return Hand::Right;
    if (it->is_string()) {
        if (*it == "right") return Hand::Right;
        if (*it == "left") return Hand::Left;
    }
    fail(field + ".hand", "expected \"left\" or \"right\"");
}

std::vector<glm::vec3> parse_curve(const json& v, const std::string& field)
{
    if (!v.is_array()) fail(field, "expected an array of [x, y, z]");
    if (v.size() > kMaxCurvePoints)
        fail(field, std::to_string(v.size()) + " points exceed the limit of " + std::to_string(kMaxCurvePoints));
    std::vector<glm::vec3> out;
    out.reserve(v.size());
    for (std::size_t k = 0; k < v.size(); ++k) out.push_back(parse_vec3(v[k], field + "[" + std::to_string(k) + "]"));
    return out;
}

/// The "ellipse" generator: an ellipse or elliptic arc with smooth wobble and optional dents

namespace {

std::vector<glm::vec3> ellipse_curve(const json& e, const std::string& field, std::uint64_t seed, bool& full)
{
    if (!e.is_object()) fail(field, "expected an object");
    allow_only(e, field, {"center", "radii", "normal", "major_axis", "start_angle_deg", "sweep_deg", "wobble_mm", "dents"});
    const dvec3 center = to_d(required_vec3(e, "center", field));
    auto rit = e.find("radii");
    if (rit == e.end()) fail(field, "missing 'radii'");
    if (!rit->is_array() || rit->size() != 2 || !(*rit)[0].is_number() || !(*rit)[1].is_number())
        fail(field + ".radii", "expected [a, b] in metres");
    const double a = (*rit)[0].get<double>(), b = (*rit)[1].get<double>();
    for (double r : {a, b})
        if (!(r >= 0.01 && r <= 3.0)) fail(field + ".radii", num(r) + " m is outside [0.01, 3]");
    dvec3 normal(0.0, 1.0, 0.0);
    if (e.contains("normal")) normal = to_d(parse_vec3(e["normal"], field + ".normal"));
    if (glm::length(normal) < 1e-6) fail(field + ".normal", "must not be zero");
    normal = glm::normalize(normal);
    dvec3 major = std::abs(normal.x) < 0.9 ? dvec3(1.0, 0.0, 0.0) : dvec3(0.0, 0.0, -1.0);
    if (e.contains("major_axis")) major = to_d(parse_vec3(e["major_axis"], field + ".major_axis"));
    dvec3 u = major - glm::dot(major, normal) * normal;
    if (glm::length(u) < 1e-3) fail(field + ".major_axis", "must not be parallel to the normal");
    u = glm::normalize(u);
    const dvec3 v = glm::cross(normal, u);
    const double start = get_number(e, "start_angle_deg", field, 0.0);
    const double sweep = get_number(e, "sweep_deg", field, 360.0);
    const double wobble = get_number(e, "wobble_mm", field, 0.0) * 0.001;
    if (!(std::abs(start) <= 3600.0)) fail(field + ".start_angle_deg", "expected a finite angle within ±3600°");
    if (!(sweep > 0.0 && sweep <= 360.0)) fail(field + ".sweep_deg", num(sweep) + "° is outside (0, 360]");
    if (!(wobble >= 0.0 && wobble <= 0.05)) fail(field + ".wobble_mm", "expected 0–50 mm");

    struct Dent { double angle, depth, width; };
    std::vector<Dent> dents;
    if (e.contains("dents")) {
        const json& d = e["dents"];
        if (!d.is_array() || d.size() > kMaxDents) fail(field + ".dents", "expected an array of at most 8 dents");
        for (std::size_t k = 0; k < d.size(); ++k) {
            const std::string f = field + ".dents[" + std::to_string(k) + "]";
            if (!d[k].is_object()) fail(f, "expected {angle_deg, depth_mm, width_deg}");
            allow_only(d[k], f, {"angle_deg", "depth_mm", "width_deg"});
            Dent dent{get_number(d[k], "angle_deg", f, 0.0), get_number(d[k], "depth_mm", f, 0.0) * 0.001,
                      get_number(d[k], "width_deg", f, 60.0)};
            if (!(std::abs(dent.angle) <= 3600.0)) fail(f + ".angle_deg", "expected a finite angle within ±3600°");
            if (!(dent.depth >= 0.0 && dent.depth <= 0.8 * std::min(a, b)))
                fail(f + ".depth_mm", "expected 0 up to 80 % of the smaller radius");
            if (!(dent.width >= 1.0 && dent.width <= 180.0)) fail(f + ".width_deg", "expected 1–180°");
            dents.push_back(dent);
        }
    }

    // Smooth wobble: integer harmonics of the angle, so a loop closes on itself.
    Rng rng(seed);
    std::array<double, 3> amp_r{}, ph_r{}, amp_n{}, ph_n{};
    const std::array<double, 3> harm = {2.0, 3.0, 4.0};
    const std::array<double, 3> share = {0.5, 0.3, 0.2};
    for (int h = 0; h < 3; ++h) {
        amp_r[h] = wobble * share[h] * rng.uniform(0.7, 1.3);
        ph_r[h] = rng.uniform(0.0, kTwoPi);
        amp_n[h] = 0.5 * wobble * share[h] * rng.uniform(0.7, 1.3);
        ph_n[h] = rng.uniform(0.0, kTwoPi);
    }

    full = sweep >= 360.0;
    const std::size_t n = full ? 48 : std::max<std::size_t>(4, static_cast<std::size_t>(std::ceil(sweep / 7.5)));
    std::vector<glm::vec3> out;
    for (std::size_t k = 0; k < (full ? n : n + 1); ++k) {
        const double deg = start + sweep * static_cast<double>(k) / static_cast<double>(n);
        const double th = deg * kPi / 180.0;
        const dvec3 radial = a * std::cos(th) * u + b * std::sin(th) * v;
        const dvec3 rdir = glm::normalize(radial);
        double off = 0.0, up = 0.0;
        for (int h = 0; h < 3; ++h) {
            off += amp_r[h] * std::sin(harm[h] * th + ph_r[h]);
            up += amp_n[h] * std::sin(harm[h] * th + ph_n[h]);
        }
        for (const Dent& d : dents) {
            double diff = std::remainder(deg - d.angle, 360.0);
            double sigma = 0.5 * d.width;
            off -= d.depth * std::exp(-0.5 * (diff / sigma) * (diff / sigma));
        }
        out.push_back(glm::vec3(center + radial + off * rdir + up * normal));
    }
    return out;
}

/// The "section" generator: the intersection of a lobe surface with a plane, every 2° of
/// azimuth, with an optional smooth wobble that slides the points along the surface
/// (docs/scenario-format.md). Returns the control polyline; `full` tells a whole loop and
/// `surface` which surface it lies on.
std::vector<glm::vec3> section_curve(const json& e, const std::string& field, std::uint64_t seed,
                                     const std::vector<TruthSurface>& surfaces, bool& full, int& surface)
{
    if (!e.is_object()) fail(field, "expected an object");
    allow_only(e, field, {"surface", "normal", "offset_m", "start_angle_deg", "sweep_deg", "wobble_mm", "direction"});
    auto sit = e.find("surface");
    if (sit == e.end()) fail(field, "missing 'surface'");
    if (!sit->is_number_integer() || sit->get<std::int64_t>() < 0 ||
        sit->get<std::int64_t>() >= static_cast<std::int64_t>(surfaces.size()))
        fail(field + ".surface", surfaces.empty() ? std::string("the scenario defines no \"surfaces\"")
                                                  : "expected an index 0–" + std::to_string(surfaces.size() - 1) +
                                                        " into \"surfaces\"");
    surface = static_cast<int>(sit->get<std::int64_t>());
    SurfaceSection sec;
    if (e.contains("normal")) sec.plane_normal = to_d(parse_vec3(e["normal"], field + ".normal"));
    if (glm::length(sec.plane_normal) < 1e-6) fail(field + ".normal", "must not be zero");
    sec.plane_normal = glm::normalize(sec.plane_normal);
    sec.offset_m = get_number(e, "offset_m", field, 0.0);
    if (!(std::abs(sec.offset_m) <= kMaxSurfaceRadius)) fail(field + ".offset_m", "expected a distance within ±2 m");
    sec.start_angle_deg = get_number(e, "start_angle_deg", field, 0.0);
    sec.sweep_deg = get_number(e, "sweep_deg", field, 360.0);
    if (!(std::abs(sec.start_angle_deg) <= 3600.0)) fail(field + ".start_angle_deg", "expected a finite angle within ±3600°");
    if (!(sec.sweep_deg > 0.0 && sec.sweep_deg <= 360.0)) fail(field + ".sweep_deg", num(sec.sweep_deg) + "° is outside (0, 360]");
    if (e.contains("direction")) {
        const json& d = e["direction"];
        if (!d.is_number_integer() || (d.get<std::int64_t>() != 1 && d.get<std::int64_t>() != -1))
            fail(field + ".direction", "expected 1 (counter-clockwise about the normal) or -1");
        sec.direction = static_cast<int>(d.get<std::int64_t>());
    }
    const double wobble = get_number(e, "wobble_mm", field, 0.0) * 0.001;
    if (!(wobble >= 0.0 && wobble <= kMaxSectionWobble)) fail(field + ".wobble_mm", "expected 0–20 mm");
    sec.step_deg = 2.0;

    // Smooth wobble across the curve: integer harmonics of the azimuth, so a loop closes on
    // itself. It slides the points along the surface (section_points), never off it.
    Rng rng(seed);
    std::array<double, 3> amp{}, ph{};
    const std::array<double, 3> harm = {2.0, 3.0, 4.0};
    const std::array<double, 3> share = {0.5, 0.3, 0.2};
    for (int h = 0; h < 3; ++h) {
        amp[h] = wobble * share[h] * rng.uniform(0.7, 1.3);
        ph[h] = rng.uniform(0.0, kTwoPi);
    }
    SectionAcross across;
    if (wobble > 0.0)
        across = [amp, ph, harm](double phi) {
            double off = 0.0;
            for (int h = 0; h < 3; ++h) off += amp[h] * std::sin(harm[h] * phi + ph[h]);
            return off;
        };
    full = sec.sweep_deg >= 360.0;
    const std::vector<dvec3> pts = section_points(surfaces[static_cast<std::size_t>(surface)], sec, field, across);
    std::vector<glm::vec3> out;
    out.reserve(pts.size());
    for (const dvec3& p : pts) out.push_back(glm::vec3(p));
    return out;
}

ScenarioStroke parse_stroke_path(const json& s, const std::string& field, std::uint64_t gen_seed, bool drag,
                                 const std::vector<TruthSurface>& surfaces)
{
    ScenarioStroke st;
    st.hand = parse_hand(s, field);
    if (!drag && s.contains("kind")) {
        if (!s["kind"].is_string()) fail(field + ".kind", "expected \"lobe\" or \"trunk\"");
        try {
            st.kind = stroke_kind_from_name(s["kind"].get<std::string>());
        } catch (const InvalidInput& e) {
            fail(field + ".kind", e.what());
        }
    }
    bool default_closed = false;
    int sources = 0;
    if (s.contains("curve")) {
        st.curve = parse_curve(s["curve"], field + ".curve");
        ++sources;
    }
    if (!drag && s.contains("ellipse")) {
        bool full = false;
        st.curve = ellipse_curve(s["ellipse"], field + ".ellipse", gen_seed, full);
        default_closed = full;
        ++sources;
    }
    if (drag && (s.contains("from") || s.contains("to"))) {
        st.curve = {required_vec3(s, "from", field), required_vec3(s, "to", field)};
        ++sources;
    }
    if (!drag && s.contains("section")) {
        bool full = false;
        st.curve = section_curve(s["section"], field + ".section", gen_seed, surfaces, full, st.surface);
        default_closed = full;
        ++sources;
    }
    if (sources != 1)
        fail(field, drag ? "give exactly one of 'curve' or 'from'/'to'"
                         : "give exactly one of 'curve', 'ellipse' or 'section'");
    st.closed = default_closed;
    if (s.contains("closed")) {
        if (!s["closed"].is_boolean()) fail(field + ".closed", "expected true or false");
        st.closed = s["closed"].get<bool>();
    }
    st.speed_mps = get_number(s, "speed", field, 0.0);
    if (s.contains("speed") && !(st.speed_mps >= kMinSpeed && st.speed_mps <= kMaxSpeed))
        fail(field + ".speed", num(st.speed_mps) + " m/s is outside [" + num(kMinSpeed) + ", " + num(kMaxSpeed) + "]");
    return st;
}

ScenarioStep parse_step(const json& s, std::size_t i, std::uint64_t seed, const std::vector<TruthSurface>& surfaces)
{
    const std::string field = step_field(i, "");
    if (!s.is_object()) fail(field, "expected an object");
    auto tit = s.find("type");
    if (tit == s.end() || !tit->is_string()) fail(field + ".type", "missing step type");
    const std::string type = tit->get<std::string>();
    ScenarioStep st;
    const std::uint64_t gen_seed = stream_seed(seed, kTagGenerator + i);
    if (type == "stroke") {
        allow_only(s, field, {"type", "kind", "hand", "closed", "curve", "ellipse", "section", "speed"});
        st.type = ScenarioStep::Type::Stroke;
        st.stroke = parse_stroke_path(s, field, gen_seed, false, surfaces);
        st.hand = st.stroke.hand;
    } else if (type == "drag") {
        allow_only(s, field, {"type", "hand", "closed", "curve", "from", "to", "speed"});
        st.type = ScenarioStep::Type::Drag;
        st.stroke = parse_stroke_path(s, field, gen_seed, true, surfaces);
        st.hand = st.stroke.hand;
    } else if (type == "near_pinch" || type == "grab") {
        allow_only(s, field, {"type", "hand", "at", "duration"});
        st.type = type == "grab" ? ScenarioStep::Type::Grab : ScenarioStep::Type::NearPinch;
        st.hand = parse_hand(s, field);
        st.where = required_vec3(s, "at", field);
        st.duration_s = get_number(s, "duration", field, type == "grab" ? 1.0 : 0.6);
    } else if (type == "key") {
        allow_only(s, field, {"type", "key"});
        st.type = ScenarioStep::Type::Key;
        auto kit = s.find("key");
        if (kit == s.end()) fail(field, "missing 'key'");
        st.key = parse_key(*kit, field + ".key");
    } else if (type == "pause") {
        allow_only(s, field, {"type", "duration"});
        st.type = ScenarioStep::Type::Pause;
        st.duration_s = get_number(s, "duration", field, 0.5);
    } else {
        fail(field + ".type", "unknown step type \"" + one_line(type.substr(0, 40)) +
                                  "\" (stroke, drag, near_pinch, grab, key, pause)");
    }
    return st;
}

} // namespace

} // namespace synth

using namespace synth;

Scenario scenario_from_json(const nlohmann::json& j)
{
    if (!j.is_object()) fail("scenario", "expected a JSON object");
    allow_only(j, "scenario", {"format", "version", "name", "description", "seed", "rate_hz", "steps",
                               "uniform_joint_radius", "noise", "dropouts", "surfaces"});
    auto fit = j.find("format");
    if (fit == j.end() || !fit->is_string() || *fit != kScenarioFormat)
        fail("format", std::string("expected \"") + kScenarioFormat + "\"");
    auto vit = j.find("version");
    if (vit == j.end() || !vit->is_number_integer()) fail("version", "missing integer version");
    if (vit->get<std::int64_t>() != 1)
        fail("version", "unsupported version " + std::to_string(vit->get<std::int64_t>()) + " (this build reads 1)");
    Scenario s;
    if (j.contains("name")) {
        if (!j["name"].is_string()) fail("name", "expected a string");
        s.name = j["name"].get<std::string>();
    }
    if (j.contains("seed")) {
        const json& sd = j["seed"];
        if (sd.is_number_unsigned()) s.seed = sd.get<std::uint64_t>();
        else if (sd.is_number_integer() && sd.get<std::int64_t>() >= 0) s.seed = static_cast<std::uint64_t>(sd.get<std::int64_t>());
        else fail("seed", "expected a non-negative integer");
    }
    s.rate_hz = get_number(j, "rate_hz", "scenario", 90.0);
    s.uniform_joint_radius_m = get_number(j, "uniform_joint_radius", "scenario", 0.0);
    for (const char* flag : {"noise", "dropouts"}) {
        if (!j.contains(flag)) continue;
        if (!j[flag].is_boolean()) fail(flag, "expected true or false");
        (std::string(flag) == "noise" ? s.noise : s.dropouts) = j[flag].get<bool>();
    }
    s.surfaces = truth_surfaces_from_json(j);
    auto sit = j.find("steps");
    if (sit == j.end() || !sit->is_array()) fail("steps", "missing array of steps");
    if (sit->size() > kMaxSteps)
        fail("steps", std::to_string(sit->size()) + " steps exceed the limit of " + std::to_string(kMaxSteps));
    s.steps.reserve(sit->size());
    for (std::size_t i = 0; i < sit->size(); ++i) s.steps.push_back(parse_step((*sit)[i], i, s.seed, s.surfaces));
    validate_scenario(s);
    return s;
}

Scenario load_scenario(const std::string& path)
{
    const std::string text = read_file_limited(path, kMaxScenarioBytes);
    json j;
    try {
        j = json::parse(text);
    } catch (const json::parse_error& e) {
        // Where it went wrong, in the file's terms; not the JSON library's text.
        std::size_t line = 1, column = 1;
        const std::size_t end = std::min<std::size_t>(e.byte > 0 ? e.byte - 1 : 0, text.size());
        for (std::size_t i = 0; i < end; ++i) {
            if (text[i] == '\n') {
                ++line;
                column = 1;
            } else {
                ++column;
            }
        }
        throw FileError(path, "not a scenario: not valid JSON (line " + std::to_string(line) + ", column " +
                                  std::to_string(column) + "); a scenario is a JSON document (docs/scenario-format.md)");
    }
    try {
        return scenario_from_json(j);
    } catch (const InvalidInput& e) {
        throw FileError(path, one_line(e.what()));
    } catch (const json::exception& e) {
        // "[json.exception.type_error.302] type must be …": the library's tag dropped.
        std::string why = one_line(e.what());
        if (why.rfind("[json.exception.", 0) == 0 && why.find("] ") != std::string::npos) why.erase(0, why.find("] ") + 2);
        throw FileError(path, "not a scenario: " + why + " (docs/scenario-format.md)");
    }
}

} // namespace lobe
