#include "growth/lsystem/sketch.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>

#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>

#include "core/errors.h"
#include "growth/lsystem/lsystem_grower.h"

namespace lobe::lsystem {

namespace {

using nlohmann::json;

constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = 180.0 / kPi;
/// Section and apex modules of the branch types (none is a turtle command).
constexpr char kBranchSections[] = "CDEHIJKM";
constexpr char kBranchApexes[] = "QRSVWXYZ";
static_assert(sizeof kBranchSections - 1 >= kMaxSketchBranches && sizeof kBranchApexes - 1 >= kMaxSketchBranches);

bool finite3(const glm::dvec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

std::string point_text(const glm::dvec3& p)
{
    char buf[96];
    std::snprintf(buf, sizeof buf, "(%g, %g, %g)", p.x, p.y, p.z);
    return buf;
}

void check_nodes(const std::vector<glm::dvec3>& nodes, const std::string& where, const glm::dvec3* before)
{
    if (nodes.size() > kMaxSketchNodes)
        throw InvalidInput(where + ": " + std::to_string(nodes.size()) + " nodes, more than " + std::to_string(kMaxSketchNodes));
    for (std::size_t i = 0; i < nodes.size(); ++i) {
        const glm::dvec3& p = nodes[i];
        const std::string at = where + "[" + std::to_string(i) + "]";
        if (!finite3(p)) throw InvalidInput(at + ": a coordinate is not a finite number");
        if (std::fabs(p.x) > kMaxSketchCoordinateM || std::fabs(p.y) > kMaxSketchCoordinateM || std::fabs(p.z) > kMaxSketchCoordinateM)
            throw InvalidInput(at + ": " + point_text(p) + " is more than " + std::to_string(static_cast<int>(kMaxSketchCoordinateM)) +
                               " m from the origin");
        const glm::dvec3* prev = i > 0 ? &nodes[i - 1] : before;
        if (prev && finite3(*prev) && glm::length(p - *prev) < kMinSketchSectionM)
            throw InvalidInput(at + ": the section ending here is shorter than 0.1 mm (a zero-length section)");
    }
}

} // namespace

void check_sketch(const Sketch& s, const std::string& where)
{
    if (s.trunk.size() < 2)
        throw InvalidInput(where + ": the trunk has " + std::to_string(s.trunk.size()) +
                           " nodes; a sketch needs at least two (one section)");
    check_nodes(s.trunk, where + ": trunk", nullptr);
    if (s.branches.size() > kMaxSketchBranches)
        throw InvalidInput(where + ": " + std::to_string(s.branches.size()) + " branch types, more than " +
                           std::to_string(kMaxSketchBranches));
    const int n = s.trunk_sections();
    for (std::size_t b = 0; b < s.branches.size(); ++b) {
        const SketchBranch& br = s.branches[b];
        const std::string at = where + ": branches[" + std::to_string(b) + "]";
        if (br.attach < 1 || br.attach > n - 1)
            throw InvalidInput(at + ".attach: trunk node " + std::to_string(br.attach) + " does not exist to branch from (nodes 1 to " +
                               std::to_string(n - 1) + " of a " + std::to_string(n) + "-section trunk)");
        for (std::size_t o = 0; o < b; ++o)
            if (s.branches[o].attach == br.attach)
                throw InvalidInput(at + ".attach: trunk node " + std::to_string(br.attach) + " already has branch type " +
                                   std::to_string(o));
        if (br.points.empty()) throw InvalidInput(at + ".points: a branch needs at least one point");
        check_nodes(br.points, at + ".points", &s.trunk[static_cast<std::size_t>(br.attach)]);
    }
    if (s.iterations < 0 || s.iterations > kMaxSketchIterations)
        throw InvalidInput(where + ": iterations " + std::to_string(s.iterations) + " is outside 1 to " +
                           std::to_string(kMaxSketchIterations));
    if (!(s.divergence_deg >= 0.0 && s.divergence_deg <= 360.0))
        throw InvalidInput(where + ": divergence_deg must be a number of degrees from 0 to 360");
}

namespace {

std::vector<glm::dvec3> read_points(const json& a, const std::string& where)
{
    if (!a.is_array()) throw InvalidInput(where + ": expected an array of [x, y, z] points");
    if (a.size() > kMaxSketchNodes)
        throw InvalidInput(where + ": " + std::to_string(a.size()) + " points, more than " + std::to_string(kMaxSketchNodes));
    std::vector<glm::dvec3> out;
    out.reserve(a.size());
    for (std::size_t i = 0; i < a.size(); ++i) {
        const json& p = a[i];
        if (!p.is_array() || p.size() != 3 || !p[0].is_number() || !p[1].is_number() || !p[2].is_number())
            throw InvalidInput(where + "[" + std::to_string(i) + "]: expected [x, y, z], three numbers (metres)");
        out.emplace_back(p[0].get<double>(), p[1].get<double>(), p[2].get<double>());
    }
    return out;
}

} // namespace

Sketch parse_sketch(std::string_view text, const std::string& name)
{
    if (text.size() > kMaxSketchFileBytes)
        throw InvalidInput(name + ": " + std::to_string(text.size()) + " bytes, more than a sketch may have (" +
                           std::to_string(kMaxSketchFileBytes) + ")");
    const json j = json::parse(text.begin(), text.end(), nullptr, /*allow_exceptions=*/false);
    if (j.is_discarded()) throw InvalidInput(name + ": not valid JSON");
    if (!j.is_object()) throw InvalidInput(name + ": expected a JSON object {\"trunk\": [...], ...}");
    Sketch s;
    for (const auto& [key, value] : j.items()) {
        if (key == "trunk") {
            s.trunk = read_points(value, name + ": trunk");
        } else if (key == "branches") {
            if (!value.is_array()) throw InvalidInput(name + ": branches: expected an array");
            if (value.size() > kMaxSketchBranches)
                throw InvalidInput(name + ": " + std::to_string(value.size()) + " branch types, more than " +
                                   std::to_string(kMaxSketchBranches));
            for (std::size_t b = 0; b < value.size(); ++b) {
                const std::string at = name + ": branches[" + std::to_string(b) + "]";
                const json& br = value[b];
                if (!br.is_object()) throw InvalidInput(at + ": expected {\"attach\": i, \"points\": [...]}");
                SketchBranch out;
                bool has_attach = false, has_points = false;
                for (const auto& [k, v] : br.items()) {
                    if (k == "attach") {
                        if (!v.is_number_integer()) throw InvalidInput(at + ".attach: expected a whole trunk node number");
                        const auto a = v.get<std::int64_t>();
                        out.attach = static_cast<int>(std::clamp<std::int64_t>(a, -1, 1000000));
                        has_attach = true;
                    } else if (k == "points") {
                        out.points = read_points(v, at + ".points");
                        has_points = true;
                    } else {
                        throw InvalidInput(at + ": unknown key \"" + k.substr(0, 40) + "\" (a branch has attach and points)");
                    }
                }
                if (!has_attach || !has_points) throw InvalidInput(at + ": a branch needs attach and points");
                s.branches.push_back(std::move(out));
            }
        } else if (key == "iterations") {
            if (!value.is_number_integer()) throw InvalidInput(name + ": iterations: expected a whole number");
            const auto n = value.get<std::int64_t>();
            s.iterations = n < 0 || n > kMaxSketchIterations ? -1 : static_cast<int>(n);
            if (s.iterations < 1)
                throw InvalidInput(name + ": iterations: expected 1 to " + std::to_string(kMaxSketchIterations));
        } else if (key == "divergence_deg") {
            if (!value.is_number()) throw InvalidInput(name + ": divergence_deg: expected a number of degrees");
            s.divergence_deg = value.get<double>();
        } else {
            throw InvalidInput(name + ": unknown key \"" + key.substr(0, 40) +
                               "\" (a sketch has trunk, branches, iterations and divergence_deg)");
        }
    }
    check_sketch(s, name);
    return s;
}

std::string sketch_json(const Sketch& s)
{
    auto pts = [](const std::vector<glm::dvec3>& v) {
        json a = json::array();
        for (const glm::dvec3& p : v) a.push_back({p.x, p.y, p.z});
        return a;
    };
    json j;
    j["trunk"] = pts(s.trunk);
    json b = json::array();
    for (const SketchBranch& br : s.branches) b.push_back({{"attach", br.attach}, {"points", pts(br.points)}});
    j["branches"] = std::move(b);
    if (s.iterations > 0) j["iterations"] = s.iterations;
    j["divergence_deg"] = s.divergence_deg;
    return j.dump();
}

std::vector<glm::dvec3> sketch_curve(const std::vector<glm::dvec3>& nodes, int steps)
{
    std::vector<glm::dvec3> out;
    if (nodes.empty()) return out;
    const std::size_t n = nodes.size();
    auto tangent = [&](std::size_t i) {
        if (n < 2) return glm::dvec3(0.0);
        if (i == 0) return nodes[1] - nodes[0];
        if (i == n - 1) return nodes[n - 1] - nodes[n - 2];
        return (nodes[i + 1] - nodes[i - 1]) * 0.5;
    };
    out.push_back(nodes[0]);
    for (std::size_t k = 0; k + 1 < n; ++k) {
        const glm::dvec3 b0 = nodes[k];
        const glm::dvec3 b3 = nodes[k + 1];
        const glm::dvec3 b1 = b0 + tangent(k) / 3.0;
        const glm::dvec3 b2 = b3 - tangent(k + 1) / 3.0;
        for (int s = 1; s <= steps; ++s) {
            if (s == steps) {
                out.push_back(b3);
                break;
            }
            const double t = static_cast<double>(s) / steps;
            const double u = 1.0 - t;
            out.push_back(b0 * (u * u * u) + b1 * (3.0 * u * u * t) + b2 * (3.0 * u * t * t) + b3 * (t * t * t));
        }
    }
    return out;
}

namespace {

/// The turtle's frame as the rules' blueprints move it (turtle.h: `+` turns H towards L
/// about U, `&` turns H towards −U about L).
struct Frame {
    glm::dvec3 pos{0.0};
    glm::dvec3 h{0.0, 1.0, 0.0};
    glm::dvec3 l{-1.0, 0.0, 0.0};
    glm::dvec3 u{0.0, 0.0, 1.0};
};

void turn(glm::dvec3& a, glm::dvec3& b, double c, double s)
{
    const glm::dvec3 a0 = a;
    a = a0 * c + b * s;
    b = b * c - a0 * s;
}

/// A number for the rules: fixed, at most 9 decimals, no exponent (cpfg reads it).
std::string num(double v)
{
    if (std::fabs(v) < 5e-10) return "0";
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.9f", v);
    std::string s(buf);
    while (!s.empty() && s.back() == '0') s.pop_back();
    if (!s.empty() && s.back() == '.') s.pop_back();
    return s;
}

/// The turtle commands that draw the curve `pts` (pts[0] where the frame is) and move the
/// frame along it; lengths scaled by `grow` (an expression).
std::string blueprint(Frame& f, const std::vector<glm::dvec3>& pts, std::size_t first, std::size_t last, const std::string& grow)
{
    std::string out;
    for (std::size_t i = first + 1; i <= last; ++i) {
        const glm::dvec3 d = pts[i] - f.pos;
        const double len = glm::length(d);
        if (!(len > 0.0)) continue;
        const double dh = glm::dot(d, f.h), dl = glm::dot(d, f.l), du = glm::dot(d, f.u);
        const double yaw = std::atan2(dl, dh);
        const double pitch = std::atan2(-du, std::sqrt(dh * dh + dl * dl));
        // The angles as written (degrees, rounded) are what the turtle turns by.
        const double yaw_deg = std::stod(num(yaw * kDeg));
        const double pitch_deg = std::stod(num(pitch * kDeg));
        if (yaw_deg != 0.0) {
            out += "+(" + num(yaw_deg) + ")";
            turn(f.h, f.l, std::cos(yaw_deg / kDeg), std::sin(yaw_deg / kDeg));
        }
        if (pitch_deg != 0.0) {
            out += "&(" + num(pitch_deg) + ")";
            turn(f.h, f.u, std::cos(pitch_deg / kDeg), -std::sin(pitch_deg / kDeg));
        }
        const double len_w = std::stod(num(len));
        out += "F(" + num(len_w) + "*" + grow + ")";
        f.pos += f.h * len_w;
    }
    return out;
}

/// The homomorphism productions of one axis: `sym(x, t) : x % count == k --> …`, the curve
/// through `nodes` from frame `f` (moved to the end).
void axis_blueprints(std::string& out, char sym, Frame& f, const std::vector<glm::dvec3>& nodes, int steps,
                     std::vector<Frame>* node_frames)
{
    const std::vector<glm::dvec3> pts = sketch_curve(nodes, steps);
    const std::size_t sections = nodes.size() - 1;
    if (node_frames) node_frames->push_back(f);
    const std::string head = std::string(1, sym) + "(x,t) : x % " + std::to_string(sections) + " == ";
    for (std::size_t k = 0; k < sections; ++k) {
        const std::string body = blueprint(f, pts, k * static_cast<std::size_t>(steps), (k + 1) * static_cast<std::size_t>(steps),
                                           "min(1,GROWTH-t)");
        if (k == 0) {
            // The turn into the first section is where the axis leaves its parent (or the
            // ground): the axis's first section takes it; a repeat of the blueprints goes on
            // in the direction the axis has (repeating the turn would curl the axis).
            out += std::string(1, sym) + "(x,t) : x == 0 --> " + body + "\n";
            out += head + "0 --> " + body.substr(body.find("F(")) + "\n";
        } else {
            out += head + std::to_string(k) + " --> " + body + "\n";
        }
        if (node_frames) node_frames->push_back(f);
    }
}

void branch_rate(const Sketch& s, const SketchBranch& br, SketchBranchRule& r)
{
    // The first branch appears with its first section one iteration after the trunk passes
    // its node (iteration attach + 1) and has grown the rest by iteration N (the trunk's
    // sections): (sections − 1) in (N − attach − 1) iterations, at most one per iteration.
    const int later = s.trunk_sections() - br.attach - 1;
    const int more = r.sections - 1;
    if (later <= 0 || more >= later) {
        r.rate_num = 1;
        r.rate_den = 1;
    } else {
        r.rate_num = more;
        r.rate_den = later;
        if (more > 0) {
            const int g = std::gcd(more, later);
            r.rate_num /= g;
            r.rate_den /= g;
        }
    }
}

std::string branch_successor(const SketchBranchRule& r, const std::string& step)
{
    return "[/(b*DIV)" + std::string(1, r.section) + "(0," + step + ")" + std::string(1, r.apex) + "(0,0," + step + ")]";
}

} // namespace

SketchRules sketch_rules(const Sketch& s, const SketchRulesOptions& o)
{
    check_sketch(s, "sketch");
    if (o.curve_steps < 1 || o.curve_steps > 16) throw InvalidInput("sketch: curve steps must be 1 to 16");
    SketchRules r;
    r.growth = o.growth > 0.0 ? o.growth : static_cast<double>(s.shown_iterations());
    if (!(r.growth > 0.0 && r.growth <= kMaxSketchIterations))
        throw InvalidInput("sketch: growth " + num(r.growth) + " is outside (0, " + std::to_string(kMaxSketchIterations) + "]");
    r.derivation_length = static_cast<int>(std::ceil(r.growth)) - 1;
    r.trunk_sections = s.trunk_sections();
    for (std::size_t b = 0; b < s.branches.size(); ++b) {
        SketchBranchRule br;
        br.section = kBranchSections[b];
        br.apex = kBranchApexes[b];
        br.interval = s.branches[b].attach;
        br.sections = static_cast<int>(s.branches[b].points.size());
        branch_rate(s, s.branches[b], br);
        r.branches.push_back(br);
    }

    // Blueprints: the trunk from the root (the model's origin), then each branch type from
    // the frame the trunk has at its node.
    const glm::dvec3 root = s.trunk[0];
    std::vector<glm::dvec3> trunk;
    for (const glm::dvec3& p : s.trunk) trunk.push_back(p - root);
    std::string homomorphism;
    std::vector<Frame> trunk_frames;
    Frame f;
    axis_blueprints(homomorphism, 'A', f, trunk, o.curve_steps, &trunk_frames);
    for (std::size_t b = 0; b < s.branches.size(); ++b) {
        const SketchBranch& br = s.branches[b];
        std::vector<glm::dvec3> nodes{trunk[static_cast<std::size_t>(br.attach)]};
        for (const glm::dvec3& p : br.points) nodes.push_back(p - root);
        Frame bf = trunk_frames[static_cast<std::size_t>(br.attach)];
        axis_blueprints(homomorphism, r.branches[b].section, bf, nodes, o.curve_steps, nullptr);
    }

    // Growth: the trunk's tip B(b, s) adds a section every step, with a branch at every n-th
    // node (the type drawn from the farthest node first where several fall on one node); a
    // branch's tip adds rate_num / rate_den sections per step and branches likewise.
    std::vector<std::size_t> order(r.branches.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
        return r.branches[a].interval != r.branches[b].interval ? r.branches[a].interval > r.branches[b].interval : a < b;
    });
    std::string prods;
    for (const std::size_t i : order) {
        const SketchBranchRule& br = r.branches[i];
        prods += "A(x,t) < B(b,s) : (x+1) % " + std::to_string(br.interval) + " == 0 --> " + branch_successor(br, "s+1") +
                 "A(x+1,s+1)B(b+1,s+1)\n";
    }
    prods += "A(x,t) < B(b,s) --> A(x+1,s+1)B(b,s+1)\n";
    for (const SketchBranchRule& br : r.branches) {
        const std::string sec(1, br.section), apex(1, br.apex);
        const std::string p = std::to_string(br.rate_num), q = std::to_string(br.rate_den);
        prods += sec + "(x,t) < " + apex + "(c,b,s) : c+" + p + " >= " + q + " && (x+1) % " + std::to_string(br.interval) +
                 " == 0 --> " + branch_successor(br, "s+1") + sec + "(x+1,s+1)" + apex + "(c+" + p + "-" + q + ",b+1,s+1)\n";
        prods += sec + "(x,t) < " + apex + "(c,b,s) : c+" + p + " >= " + q + " --> " + sec + "(x+1,s+1)" + apex + "(c+" + p +
                 "-" + q + ",b,s+1)\n";
        prods += apex + "(c,b,s) --> " + apex + "(c+" + p + ",b,s+1)\n";
    }

    std::string& l = r.lsystem;
    l += "/* A tree sketched as " + std::to_string(r.trunk_sections) + " trunk sections and " +
         std::to_string(r.branches.size()) + (r.branches.size() == 1 ? " branch type" : " branch types") +
         ", as a parametric 2L-system (docs/lsystem-sketch.md).\n";
    l += "   A(x,t): trunk section x (blueprint x % " + std::to_string(r.trunk_sections) + "), grown at step t; B(b,s): the trunk's tip";
    l += ",\n   b branches so far, s the step.";
    for (const SketchBranchRule& br : r.branches)
        l += "\n   " + std::string(1, br.section) + "(x,t), " + std::string(1, br.apex) + "(c,b,s): branch type from trunk node " +
             std::to_string(br.interval) + ", every " + std::to_string(br.interval) + " nodes, growing " +
             std::to_string(br.rate_num) + "/" + std::to_string(br.rate_den) + " section per step.";
    l += " */\n";
    l += "#define GROWTH " + num(r.growth - 0.0) + "\n";
    l += "#define DIV " + num(s.divergence_deg) + "\n";
    l += "Lsystem: 1\n";
    l += "derivation length: " + std::to_string(r.derivation_length) + "\n";
    l += "Axiom: A(0,0)B(0,0)\n";
    l += prods;
    l += "homomorphism\n";
    l += homomorphism;
    l += "endlsystem\n";
    r.view = "/* The view of a sketched tree: angles in degrees, one model unit is one metre. */\n"
             "angle increment: 137.5\n"
             "metres per unit: 1\n";
    return r;
}

GrowerChoice sketch_grower_choice(const SketchRules& rules, const std::string& name)
{
    GrowerChoice choice;
    choice.name = kGrowerName;
    choice.version = lsystem_grower().version();
    choice.params["source"] = rules.lsystem;
    choice.params["source_name"] = name;
    choice.params["view"] = rules.view;
    return choice;
}

SketchGrown grow_sketch(const Sketch& sketch, const SketchRulesOptions& options, std::uint64_t seed, std::size_t max_tree_nodes)
{
    SketchGrown out;
    out.rules = sketch_rules(sketch, options);
    GrowerInput in;
    in.choice = sketch_grower_choice(out.rules);
    in.seed = seed;
    in.max_tree_nodes = max_tree_nodes;
    LSystemRun run = run_lsystem(in);
    out.modules = run.word.size();
    out.growth = std::move(run.growth);
    return out;
}

} // namespace lobe::lsystem
