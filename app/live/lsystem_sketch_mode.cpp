#include "app/live/lsystem_sketch_mode.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <glm/geometric.hpp>

#include "core/errors.h"
#include "growth/radii.h"
#include "input/tools.h"

namespace lobe {

namespace {

constexpr std::size_t kMaxMessages = 200;
constexpr double kDivergenceStepDeg = 5.0;

glm::dvec3 rotate_y(const glm::dvec3& v, double yaw)
{
    const double c = std::cos(yaw), s = std::sin(yaw);
    return {c * v.x + s * v.z, v.y, -s * v.x + c * v.z};
}

/// A sketch the mode may hold: empty (the root alone, nothing drawn yet) or a checked one.
void check_live(const lsystem::Sketch& s)
{
    if (s.trunk.size() < 2 && s.branches.empty()) return;
    lsystem::check_sketch(s, "sketch");
}

glm::dvec3& node_of(lsystem::Sketch& s, const std::pair<int, int>& n)
{
    if (n.first < 0) return s.trunk[static_cast<std::size_t>(n.second)];
    return s.branches[static_cast<std::size_t>(n.first)].points[static_cast<std::size_t>(n.second)];
}

std::string number(double v)
{
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.1f", v);
    return buf;
}

} // namespace

LSystemSketchMode::LSystemSketchMode(SketchPlatform platform) : platform_(platform)
{
    sketch_.trunk.push_back(glm::dvec3(0.0)); // the root, at the platform's centre
}

glm::dvec3 LSystemSketchMode::platform_point(const glm::dvec3& p) const
{
    return platform_.position + rotate_y(p * platform_.scale, platform_.yaw);
}

glm::dvec3 LSystemSketchMode::tree_point(const glm::dvec3& p) const
{
    return platform_.position + rotate_y(platform_.tree_offset + p, platform_.yaw);
}

glm::dvec3 LSystemSketchMode::to_sketch(const glm::dvec3& stage) const
{
    return rotate_y(stage - platform_.position, -platform_.yaw) / platform_.scale;
}

double LSystemSketchMode::growth() const
{
    return growth_ ? *growth_ : std::max(1.0, static_cast<double>(sketch_.trunk_sections()));
}

lsystem::Sketch LSystemSketchMode::sketch_file() const
{
    lsystem::Sketch s = sketch_;
    const double g = growth();
    if (growth_ && g == std::floor(g) && static_cast<int>(g) != s.trunk_sections()) s.iterations = static_cast<int>(g);
    return s;
}

void LSystemSketchMode::note(std::string line)
{
    messages_.push_back(std::move(line));
    if (messages_.size() > kMaxMessages) messages_.erase(messages_.begin());
}

std::optional<std::pair<int, int>> LSystemSketchMode::pick(const glm::dvec3& stage) const
{
    std::optional<std::pair<int, int>> best;
    double best_d = kPickRadiusM;
    auto consider = [&](int axis, int i, const glm::dvec3& p) {
        const double d = glm::length(platform_point(p) - stage);
        if (d <= best_d) {
            best_d = d;
            best = std::make_pair(axis, i);
        }
    };
    for (std::size_t i = 1; i < sketch_.trunk.size(); ++i) consider(-1, static_cast<int>(i), sketch_.trunk[i]);
    for (std::size_t b = 0; b < sketch_.branches.size(); ++b)
        for (std::size_t i = 0; i < sketch_.branches[b].points.size(); ++i)
            consider(static_cast<int>(b), static_cast<int>(i), sketch_.branches[b].points[i]);
    return best;
}

TreeGraph LSystemSketchMode::grow(const lsystem::Sketch& s) const
{
    if (s.trunk.size() < 2) return {};
    lsystem::SketchRulesOptions o;
    o.growth = growth_ ? *growth_ : std::max(1.0, static_cast<double>(s.trunk_sections()));
    lsystem::SketchGrown g = lsystem::grow_sketch(s, o, 1, 4 * kMaxLiveSegments);
    assign_pipe_radii(g.growth.tree);
    return std::move(g.growth.tree);
}

void LSystemSketchMode::place_tree()
{
    tree_ = tree_local_;
    for (TreeNode& n : tree_.nodes) n.position = glm::vec3(tree_point(glm::dvec3(n.position)));
    ++generation_;
}

bool LSystemSketchMode::commit(lsystem::Sketch next, const std::string& what, bool quiet)
{
    try {
        check_live(next);
        TreeGraph tree = grow(next);
        sketch_ = std::move(next);
        tree_local_ = std::move(tree);
        segments_ = tree_local_.empty() ? 0 : tree_local_.size() - 1;
        place_tree();
        return true;
    } catch (const InvalidInput& e) {
        if (!quiet) note(what + " refused: " + e.what());
        return false;
    }
}

void LSystemSketchMode::load(lsystem::Sketch s, const std::string& name)
{
    // The growth is the mode's own: a sketch file's iterations are the growth it was saved at.
    const std::optional<double> growth =
        s.iterations > 0 ? std::optional<double>(static_cast<double>(s.iterations)) : std::nullopt;
    s.iterations = 0;
    const std::optional<double> before = growth_;
    growth_ = growth;
    try {
        check_live(s);
        TreeGraph tree = grow(s);
        sketch_ = std::move(s);
        tree_local_ = std::move(tree);
    } catch (const InvalidInput& e) {
        growth_ = before;
        throw InvalidInput(name + ": " + e.what());
    }
    segments_ = tree_local_.empty() ? 0 : tree_local_.size() - 1;
    from_ = 0;
    drag_.reset();
    place_tree();
}

void LSystemSketchMode::erase(const std::pair<int, int>& n)
{
    lsystem::Sketch next = sketch_;
    int from = from_;
    if (n.first >= 0) {
        auto& pts = next.branches[static_cast<std::size_t>(n.first)].points;
        pts.erase(pts.begin() + n.second);
        if (pts.empty()) next.branches.erase(next.branches.begin() + n.first);
    } else {
        const int k = n.second;
        next.trunk.erase(next.trunk.begin() + k);
        const int last = next.trunk_sections() - 1; // the highest node a branch may come from
        std::vector<lsystem::SketchBranch> kept;
        for (lsystem::SketchBranch b : next.branches) {
            if (b.attach == k) continue; // drawn from the erased node: erased with it
            if (b.attach > k) --b.attach;
            if (b.attach >= 1 && b.attach <= last) kept.push_back(std::move(b));
        }
        if (kept.size() != next.branches.size())
            note("erased " + std::to_string(next.branches.size() - kept.size()) + " branch type(s) with trunk node " +
                 std::to_string(k));
        next.branches = std::move(kept);
        if (from == k) from = 0;
        else if (from > k) --from;
        if (from > last) from = 0;
    }
    if (commit(std::move(next), "erasing the node")) from_ = from;
}

void LSystemSketchMode::start_branch()
{
    if (sketch_.trunk_sections() < 2) {
        note("a branch starts from an earlier trunk node: draw at least two trunk sections first");
        return;
    }
    const std::optional<std::pair<int, int>> n = right_tracked_ ? pick(right_tip_) : std::nullopt;
    if (!n || n->first >= 0 || n->second < 1 || n->second > sketch_.trunk_sections() - 1) {
        note("point at a trunk node below the tip (not the root) to start a branch from it");
        return;
    }
    const bool exists = std::any_of(sketch_.branches.begin(), sketch_.branches.end(),
                                    [&](const lsystem::SketchBranch& b) { return b.attach == n->second; });
    if (!exists && sketch_.branches.size() >= lsystem::kMaxSketchBranches) {
        note("at most " + std::to_string(lsystem::kMaxSketchBranches) + " branch types");
        return;
    }
    from_ = n->second;
    note("drawing a branch from trunk node " + std::to_string(from_));
}

void LSystemSketchMode::step_growth(double by)
{
    const double g = std::clamp(std::round((growth() + by) * 10.0) / 10.0, 1.0, static_cast<double>(lsystem::kMaxSketchIterations));
    if (by > 0 && segments_ > kMaxLiveSegments) {
        note("the tree has " + std::to_string(segments_) + " segments, the most the live view grows on from");
        return;
    }
    const std::optional<double> before = growth_;
    growth_ = g;
    if (!commit(sketch_, "growing to " + number(g))) growth_ = before;
}

void LSystemSketchMode::key(int code)
{
    namespace k = lsystem_sketch_keys;
    switch (code) {
    case k::kBranch: start_branch(); break;
    case k::kTrunk: from_ = 0; break;
    case k::kErase: {
        const std::optional<std::pair<int, int>> n = right_tracked_ ? pick(right_tip_) : std::nullopt;
        if (n) erase(*n);
        else note("point at a node to erase it");
        break;
    }
    case k::kScrap: {
        lsystem::Sketch empty;
        empty.trunk.push_back(glm::dvec3(0.0));
        empty.divergence_deg = sketch_.divergence_deg;
        growth_.reset();
        from_ = 0;
        drag_.reset();
        commit(std::move(empty), "scrapping the sketch");
        note("sketch scrapped");
        break;
    }
    case k::kDivergenceDown:
    case k::kDivergenceUp: {
        lsystem::Sketch next = sketch_;
        next.divergence_deg = std::clamp(next.divergence_deg + (code == k::kDivergenceUp ? kDivergenceStepDeg : -kDivergenceStepDeg), 0.0, 360.0);
        if (commit(std::move(next), "the divergence")) note("divergence " + number(sketch_.divergence_deg) + "°");
        break;
    }
    case k::kIterationBack: step_growth(-1.0); break;
    case k::kIterationForward: step_growth(1.0); break;
    case k::kGrowthDown: step_growth(-0.1); break;
    case k::kGrowthUp: step_growth(0.1); break;
    default: break;
    }
}

bool LSystemSketchMode::push_event(const InputEvent& e)
{
    if (e.kind != InputEventKind::Key) return false;
    if (e.code == keys::kLSystemSketch) {
        if (e.value == 1) {
            active_ = !active_;
            if (!active_) {
                drag_.reset();
                grab_from_.reset();
                preview_.reset();
            }
        }
        return true;
    }
    if (!active_) return false;
    if (e.value == 1) key(e.code);
    return true;
}

void LSystemSketchMode::right_hand(const HandGesture& g)
{
    right_tracked_ = g.tracked;
    const glm::dvec3 tip(g.index_tip);
    if (g.tracked) right_tip_ = tip;
    if (g.pinch_started && g.tracked) {
        if (const std::optional<std::pair<int, int>> n = pick(tip)) {
            drag_ = n;
        } else {
            lsystem::Sketch next = sketch_;
            const glm::dvec3 p = to_sketch(tip);
            if (from_ == 0) {
                next.trunk.push_back(p);
            } else {
                auto it = std::find_if(next.branches.begin(), next.branches.end(),
                                       [&](const lsystem::SketchBranch& b) { return b.attach == from_; });
                if (it == next.branches.end()) next.branches.push_back({from_, {p}});
                else it->points.push_back(p);
            }
            commit(std::move(next), "adding a section");
        }
    } else if (drag_ && g.tracked && g.pinching) {
        lsystem::Sketch next = sketch_;
        glm::dvec3& p = node_of(next, *drag_);
        const glm::dvec3 moved = to_sketch(tip);
        // A drag that passes through a bad sketch (a node on its neighbour) waits there.
        if (p != moved) {
            p = moved;
            commit(std::move(next), "dragging the node", /*quiet=*/true);
        }
    }
    if (g.pinch_ended) drag_.reset();
    preview_.reset();
    if (g.tracked && !g.pinching && !pick(tip)) {
        glm::dvec3 from = sketch_.trunk.back();
        if (from_ > 0) {
            from = sketch_.trunk[static_cast<std::size_t>(from_)];
            for (const lsystem::SketchBranch& b : sketch_.branches)
                if (b.attach == from_ && !b.points.empty()) from = b.points.back();
        }
        preview_ = std::make_pair(platform_point(from), tip);
    }
}

void LSystemSketchMode::left_hand(const HandGesture& g)
{
    const glm::dvec3 tip(g.index_tip);
    if (g.pinch_started && g.tracked && glm::length(tip - platform_.position) <= kGrabRadiusM) {
        grab_from_ = tip;
        grab_platform_ = platform_.position;
    } else if (grab_from_ && g.tracked && g.pinching) {
        platform_.position = grab_platform_ + (tip - *grab_from_);
        place_tree();
    }
    if (g.pinch_ended) grab_from_.reset();
}

void LSystemSketchMode::push_frame(const HandFrame& frame)
{
    const auto& gs = gestures_.update(frame);
    if (!active_) return;
    right_hand(gs[static_cast<int>(Hand::Right)]);
    left_hand(gs[static_cast<int>(Hand::Left)]);
}

SketchPlatform sketch_platform_for(const std::string& source)
{
    SketchPlatform p;
    if (source.rfind("lobesketch desktop", 0) == 0) {
        p.position = {0.0, 0.95, 0.0};
        p.scale = 0.2;
        p.tree_offset = {0.6, -0.95, 0.0};
    }
    return p;
}

LSystemSketchMode replay_lsystem_sketch(const Recording& rec)
{
    LSystemSketchMode mode(sketch_platform_for(rec.header.source));
    std::size_t e = 0;
    for (const HandFrame& f : rec.frames) {
        while (e < rec.events.size() && rec.events[e].time <= f.time) mode.push_event(rec.events[e++]);
        mode.push_frame(f);
    }
    while (e < rec.events.size()) mode.push_event(rec.events[e++]);
    return mode;
}

} // namespace lobe
