#include "growth/lsystem/turtle.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "core/errors.h"

namespace lobe::lsystem {

namespace {

constexpr double kDegToRad = 3.14159265358979323846 / 180.0;
/// Farthest the turtle goes from the origin, model units (positions stay well inside floats).
constexpr double kMaxCoordinate = 1e9;

/// Everything `[` saves and `]` restores.
struct TurtleState {
    glm::dvec3 pos{0.0};
    glm::dvec3 h{0.0, 1.0, 0.0};
    glm::dvec3 l{-1.0, 0.0, 0.0};
    glm::dvec3 u{0.0, 0.0, 1.0};
    double width = 1.0;
    double elasticity = 0.0;
    int node = -1;   ///< the node at pos; -1 after a move without drawing (or before the first segment)
    int anchor = -1; ///< the last node this state was at: the parent of a Detached node
};

/// a, b turned in their plane: a towards b by the angle of (c, s).
inline void turn(glm::dvec3& a, glm::dvec3& b, double c, double s)
{
    const glm::dvec3 a0 = a;
    a = a0 * c + b * s;
    b = b * c - a0 * s;
}

inline bool finite3(const glm::dvec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

/// v turned about unit `axis` by the angle of (c, s) (Rodrigues).
inline glm::dvec3 rotate(const glm::dvec3& v, const glm::dvec3& axis, double c, double s)
{
    return v * c + glm::cross(axis, v) * s + axis * (glm::dot(axis, v) * (1.0 - c));
}

} // namespace

void start_frame(const glm::dvec3& heading, glm::dvec3& h, glm::dvec3& l, glm::dvec3& u)
{
    h = glm::dvec3(0.0, 1.0, 0.0);
    l = glm::dvec3(-1.0, 0.0, 0.0);
    const double n = glm::length(heading);
    if (!(n > 1e-12) || !finite3(heading)) {
        u = glm::cross(h, l);
        return;
    }
    h = heading / n;
    // L is horizontal: +Z × H, which is −X for H = +Y; for H along ±Z, −X.
    const glm::dvec3 side = glm::cross(glm::dvec3(0.0, 0.0, 1.0), h);
    const double s = glm::length(side);
    l = s > 1e-9 ? side / s : glm::dvec3(-1.0, 0.0, 0.0);
    u = glm::cross(h, l);
}

namespace {

/// One walk of the turtle over a word: drawing into a TurtleResult, or answering queries.
class Walker {
public:
    Walker(const TurtleSymbols& symbols, const ViewSettings& view, const glm::dvec3& heading)
        : symbols_(symbols), view_(view)
    {
        start_frame(heading, state_.h, state_.l, state_.u);
        const double a = view.angle_increment_deg * kDegToRad;
        default_cos_ = std::cos(a);
        default_sin_ = std::sin(a);
        tropism_ = view.tropism_direction;
        const double t = glm::length(tropism_);
        use_tropism_ = view.tropism && t > 0.0 && std::isfinite(t);
        if (use_tropism_) tropism_ /= t;
        state_.width = view.initial_line_width;
        state_.elasticity = view.elasticity;
    }

    /// Drawing: the graph (model units until finish()), leaves and messages go to `out`.
    void draw_into(TurtleResult& out, const TurtleOptions& options)
    {
        out_ = &out;
        options_ = &options;
    }
    /// Answering queries: the query modules' parameters are written in `params`.
    void answer_into(double* params, const Environment* environment)
    {
        query_params_ = params;
        environment_ = environment;
    }

    void walk(const Word& word);
    /// Model units to metres (and the fit to a height); the messages gathered.
    void finish();

private:
    /// The module's first parameter, or `fallback` when it has none; false (the module is
    /// skipped) when the parameter is not a finite number.
    bool arg(const Word& word, const Module& m, double fallback, double& value)
    {
        if (m.param_count == 0) {
            value = fallback;
            return true;
        }
        value = word.params[m.first_param];
        if (std::isfinite(value)) return true;
        ++skipped_;
        return false;
    }
    /// The cosine and sine of the module's angle (degrees; the angle increment without one).
    bool angle(const Word& word, const Module& m, double& c, double& s)
    {
        if (m.param_count == 0) {
            c = default_cos_;
            s = default_sin_;
            return true;
        }
        double a = 0.0;
        if (!arg(word, m, 0.0, a)) return false;
        if (a != last_angle_) { // words repeat their angles: one cosine and sine per new one
            last_angle_ = a;
            last_cos_ = std::cos(a * kDegToRad);
            last_sin_ = std::sin(a * kDegToRad);
        }
        c = last_cos_;
        s = last_sin_;
        return true;
    }

    void step(double d, bool draw);
    void add_segment(const glm::dvec3& from, const glm::dvec3& h);
    int add_node(const glm::dvec3& p, int parent, TreeNodeKind kind);
    void bend();
    void roll_horizontal();
    void leaf(const glm::dvec3& base, const glm::dvec3& axis, double length, double width, bool model_units);
    void warn_once(SymbolId id, const std::string& line);
    void answer(const Module& m, TurtleOp op);
    bool apply(const Word& word, std::size_t& i);

    const TurtleSymbols& symbols_;
    const ViewSettings& view_;
    TurtleResult* out_ = nullptr;
    const TurtleOptions* options_ = nullptr;
    double* query_params_ = nullptr;
    const Environment* environment_ = nullptr;

    TurtleState state_;
    std::vector<TurtleState> stack_;
    double default_cos_ = 1.0, default_sin_ = 0.0;
    double last_angle_ = 0.0, last_cos_ = 1.0, last_sin_ = 0.0;
    glm::dvec3 tropism_{0.0, -1.0, 0.0};
    bool use_tropism_ = false;

    int joinable_ = -1; ///< the node the next straight segment may extend
    glm::dvec3 joinable_h_{0.0};
    double joinable_width_ = 0.0;

    std::vector<char> leaf_in_model_units_; ///< per leaf: its size scales with the model (a disc)
    std::vector<char> warned_;              ///< per symbol: its warning was given
    std::size_t skipped_ = 0, unmatched_ = 0;
    bool stopped_ = false, polygon_warned_ = false;
    std::string stop_reason_;
};

int Walker::add_node(const glm::dvec3& p, int parent, TreeNodeKind kind)
{
    TreeGraph& tree = out_->tree;
    TreeNode n;
    n.position = glm::vec3(p);
    n.parent = parent;
    n.radius = static_cast<float>(0.5 * state_.width);
    n.kind = kind;
    tree.nodes.push_back(n);
    return static_cast<int>(tree.nodes.size()) - 1;
}

/// A drawn segment from `from` to the turtle's position, heading `h`.
void Walker::add_segment(const glm::dvec3& from, const glm::dvec3& h)
{
    TreeGraph& tree = out_->tree;
    if (tree.nodes.size() + 2 > options_->max_nodes) {
        stopped_ = true;
        stop_reason_ = "turtle: the tree reached " + std::to_string(tree.nodes.size()) +
                       " nodes, the most it may have; the rest of the word is not drawn";
        return;
    }
    if (state_.node < 0) {
        // Nothing here yet: the first segment starts the root, any other a branch of its own.
        state_.node = tree.nodes.empty() ? add_node(from, -1, TreeNodeKind::Root)
                                         : add_node(from, state_.anchor >= 0 ? state_.anchor : 0, TreeNodeKind::Detached);
        joinable_ = -1;
    }
    ++out_->segments;
    if (joinable_ == state_.node && h == joinable_h_ && state_.width == joinable_width_) {
        tree.nodes[static_cast<std::size_t>(joinable_)].position = glm::vec3(state_.pos); // one longer segment
        return;
    }
    state_.node = add_node(state_.pos, state_.node, TreeNodeKind::Grown);
    joinable_ = state_.node;
    joinable_h_ = h;
    joinable_width_ = state_.width;
}

/// Tropism (ABOP §2.4): H turns towards T by e·|H × T|, never past it.
void Walker::bend()
{
    if (!use_tropism_ || state_.elasticity == 0.0) return;
    const glm::dvec3 axis = glm::cross(state_.h, tropism_);
    const double sin_t = glm::length(axis);
    if (sin_t < 1e-12) return;
    double alpha = state_.elasticity * sin_t;
    if (std::abs(state_.elasticity) > 1.0) { // only then can α pass the angle θ to T (sin θ ≤ θ)
        const double between = std::atan2(sin_t, glm::dot(state_.h, tropism_));
        alpha = std::clamp(alpha, -between, between);
    }
    const glm::dvec3 k = axis / sin_t;
    const double c = std::cos(alpha), s = std::sin(alpha);
    state_.h = glm::normalize(rotate(state_.h, k, c, s));
    state_.l = rotate(state_.l, k, c, s);
    state_.l = glm::normalize(state_.l - glm::dot(state_.l, state_.h) * state_.h);
    state_.u = glm::cross(state_.h, state_.l);
}

void Walker::step(double d, bool draw)
{
    const glm::dvec3 from = state_.pos;
    const glm::dvec3 h = state_.h;
    state_.pos += h * d;
    if (!finite3(state_.pos) || std::abs(state_.pos.x) > kMaxCoordinate || std::abs(state_.pos.y) > kMaxCoordinate ||
        std::abs(state_.pos.z) > kMaxCoordinate) {
        stopped_ = true;
        stop_reason_ = "turtle: a step took the turtle more than 1e9 units from the origin; the rest of the word is not drawn";
        state_.pos = from;
        return;
    }
    if (!draw) {
        if (state_.node >= 0) state_.anchor = state_.node;
        state_.node = -1;
        joinable_ = -1;
        return;
    }
    if (d != 0.0 && out_) add_segment(from, h);
    bend();
}

/// `$` and `@v`: L = V × H / |V × H| with V = +Y, U = H × L; unchanged when H is vertical.
void Walker::roll_horizontal()
{
    const glm::dvec3 v(0.0, 1.0, 0.0);
    const glm::dvec3 l = glm::cross(v, state_.h);
    const double n = glm::length(l);
    if (n < 1e-9) return;
    state_.l = l / n;
    state_.u = glm::cross(state_.h, state_.l);
}

void Walker::leaf(const glm::dvec3& base, const glm::dvec3& axis, double length, double width, bool model_units)
{
    if (!out_) return;
    if (out_->leaves.size() >= options_->max_leaves) {
        stopped_ = true;
        stop_reason_ = "turtle: the tree reached " + std::to_string(out_->leaves.size()) +
                       " leaves, the most it may have; the rest of the word is not drawn";
        return;
    }
    if (!(length > 0.0) || !(width > 0.0)) return; // nothing to see
    PlacedLeaf p;
    p.base = glm::vec3(base);
    p.axis = glm::vec3(axis);
    p.across = glm::vec3(state_.l);
    p.length_m = static_cast<float>(length);
    p.width_m = static_cast<float>(width);
    p.node = state_.node >= 0 ? state_.node : std::max(state_.anchor, 0);
    out_->leaves.push_back(p);
    leaf_in_model_units_.push_back(model_units ? 1 : 0);
    joinable_ = -1;
}

void Walker::warn_once(SymbolId id, const std::string& line)
{
    if (!out_) return;
    if (warned_.size() <= id) warned_.resize(static_cast<std::size_t>(id) + 1, 0);
    if (warned_[id]) return;
    warned_[id] = 1;
    out_->messages.push_back(line);
}

void Walker::answer(const Module& m, TurtleOp op)
{
    if (!query_params_ || m.param_count == 0) return;
    double* p = query_params_ + m.first_param;
    const std::size_t n = std::min<std::size_t>(m.param_count, 3);
    switch (op) {
    case TurtleOp::QueryPosition:
        for (std::size_t k = 0; k < n; ++k) p[k] = state_.pos[static_cast<glm::length_t>(k)];
        break;
    case TurtleOp::QueryHeading:
        for (std::size_t k = 0; k < n; ++k) p[k] = state_.h[static_cast<glm::length_t>(k)];
        break;
    case TurtleOp::QueryLeft:
        for (std::size_t k = 0; k < n; ++k) p[k] = state_.l[static_cast<glm::length_t>(k)];
        break;
    case TurtleOp::QueryUp:
        for (std::size_t k = 0; k < n; ++k) p[k] = state_.u[static_cast<glm::length_t>(k)];
        break;
    default: // ?E
        p[0] = !environment_ || environment_->inside(state_.pos) ? 1.0 : 0.0;
        break;
    }
}

/// Applies module i (and the module naming a surface after `~`, moving i past it).
bool Walker::apply(const Word& word, std::size_t& i)
{
    const Module& m = word.modules[i];
    const TurtleOp op = symbols_.op(m.symbol);
    double c = 1.0, s = 0.0, v = 0.0;
    switch (op) {
    case TurtleOp::None: break;
    case TurtleOp::Draw:
    case TurtleOp::Move:
        if (arg(word, m, 1.0, v)) step(v, op == TurtleOp::Draw);
        break;
    case TurtleOp::TurnLeft:
    case TurtleOp::TurnRight:
        if (angle(word, m, c, s)) turn(state_.h, state_.l, c, op == TurtleOp::TurnLeft ? s : -s);
        break;
    case TurtleOp::PitchDown:
    case TurtleOp::PitchUp:
        if (angle(word, m, c, s)) turn(state_.h, state_.u, c, op == TurtleOp::PitchUp ? s : -s);
        break;
    case TurtleOp::RollLeft:
    case TurtleOp::RollRight:
        if (angle(word, m, c, s)) turn(state_.u, state_.l, c, op == TurtleOp::RollLeft ? s : -s);
        break;
    case TurtleOp::TurnAround:
        state_.h = -state_.h;
        state_.l = -state_.l;
        break;
    case TurtleOp::RollHorizontal: roll_horizontal(); break;
    case TurtleOp::Push:
        if (stack_.size() >= kMaxTurtleDepth)
            throw InvalidInput("turtle: branches nest deeper than " + std::to_string(kMaxTurtleDepth) + " levels");
        stack_.push_back(state_);
        joinable_ = -1;
        break;
    case TurtleOp::Pop:
        if (stack_.empty()) {
            ++unmatched_;
        } else {
            state_ = stack_.back();
            stack_.pop_back();
        }
        joinable_ = -1;
        break;
    case TurtleOp::WidthDown:
    case TurtleOp::WidthUp: {
        const double inc = op == TurtleOp::WidthUp ? view_.line_width_increment : -view_.line_width_increment;
        if (arg(word, m, state_.width + inc, v)) state_.width = std::max(0.0, v);
        if (out_) out_->widths_set = true;
        break;
    }
    case TurtleOp::Disc:
        if (arg(word, m, state_.width, v) && v > 0.0) leaf(state_.pos - 0.5 * v * state_.h, state_.h, v, v, true);
        break;
    case TurtleOp::Surface:
    case TurtleOp::NamedSurface: {
        // `~` with the surface's name as the next module, or `~X` as one symbol.
        std::string name(symbols_.name(m.symbol).substr(1));
        double scale = 1.0;
        bool ok = m.param_count == 0 || arg(word, m, 1.0, scale);
        if (op == TurtleOp::Surface && i + 1 < word.modules.size()) {
            const Module& next = word.modules[++i];
            name = std::string(symbols_.name(next.symbol));
            if (next.param_count > 0) ok = arg(word, next, 1.0, scale);
        }
        if (name != "l") warn_once(m.symbol, "turtle: surface ~" + name + " is drawn as a leaf card (.s surface files are not read)");
        if (ok && out_) leaf(state_.pos, state_.h, options_->surface_length_m * scale, options_->surface_width_m * scale, false);
        break;
    }
    case TurtleOp::Elasticity:
        if (arg(word, m, state_.elasticity + view_.elasticity_increment, v)) state_.elasticity = v;
        break;
    case TurtleOp::QueryPosition:
    case TurtleOp::QueryHeading:
    case TurtleOp::QueryLeft:
    case TurtleOp::QueryUp:
    case TurtleOp::QueryEnvironment: answer(m, op); break;
    case TurtleOp::Polygon:
        if (out_ && !polygon_warned_) out_->messages.push_back("turtle: polygons ({ . }) are not drawn");
        polygon_warned_ = true;
        break;
    case TurtleOp::Unsupported:
        warn_once(m.symbol, "turtle: " + std::string(symbols_.name(m.symbol)) + " is not a turtle command here; ignored");
        break;
    }
    return !stopped_;
}

void Walker::walk(const Word& word)
{
    if (out_) {
        // One node per drawn step at most, and the root: reserve once.
        std::size_t draws = 1;
        for (const Module& m : word.modules) draws += symbols_.op(m.symbol) == TurtleOp::Draw;
        out_->tree.nodes.reserve(std::min(draws + 1, options_->max_nodes));
    }
    for (std::size_t i = 0; i < word.modules.size(); ++i)
        if (!apply(word, i)) break;
}

void Walker::finish()
{
    if (!out_) return;
    TurtleResult& r = *out_;
    TreeGraph& tree = r.tree;
    double k = options_->metres_per_unit;
    double extent = 0.0; // the drawing's largest extent, model units
    if (!tree.empty()) {
        glm::dvec3 lo(tree.nodes[0].position), hi = lo;
        for (const TreeNode& n : tree.nodes) {
            lo = glm::min(lo, glm::dvec3(n.position));
            hi = glm::max(hi, glm::dvec3(n.position));
        }
        extent = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
        // The tree's height above its first node, else its largest extent.
        double height = hi.y - static_cast<double>(tree.nodes[0].position.y);
        if (!(height > 1e-9)) height = extent;
        if (options_->fit_height_m > 0.0 && height > 1e-9 && std::isfinite(height)) k = options_->fit_height_m / height;
    }
    r.metres_per_unit = k;
    // Widths in model units scale with the model; cpfg's pixel widths are drawn as if the
    // whole drawing were kPixelsAcrossDrawing pixels across.
    const double radius_k = view_.width_unit == ViewSettings::WidthUnit::Model || !(extent > 1e-9) || !std::isfinite(extent)
                                ? k
                                : k * extent / kPixelsAcrossDrawing;
    const glm::dvec3 o = options_->origin;
    for (TreeNode& n : tree.nodes) {
        n.position = glm::vec3(o + k * glm::dvec3(n.position));
        n.radius = static_cast<float>(radius_k * static_cast<double>(n.radius));
    }
    for (std::size_t i = 0; i < r.leaves.size(); ++i) {
        PlacedLeaf& p = r.leaves[i];
        p.base = glm::vec3(o + k * glm::dvec3(p.base));
        if (leaf_in_model_units_[i]) {
            p.length_m = static_cast<float>(k * static_cast<double>(p.length_m));
            p.width_m = static_cast<float>(k * static_cast<double>(p.width_m));
        }
    }
    if (skipped_)
        r.messages.push_back("turtle: " + std::to_string(skipped_) +
                             " module(s) with a parameter that is not a finite number were skipped");
    if (unmatched_) r.messages.push_back("turtle: " + std::to_string(unmatched_) + " ] without a [ before it were ignored");
    if (stopped_) r.messages.push_back(stop_reason_);
}

} // namespace

TurtleOp TurtleSymbols::op_of(std::string_view n)
{
    if (n.size() == 1) {
        switch (n[0]) {
        case 'F':
        case 'G': return TurtleOp::Draw;
        case 'f':
        case 'g': return TurtleOp::Move;
        case '+': return TurtleOp::TurnLeft;
        case '-': return TurtleOp::TurnRight;
        case '&': return TurtleOp::PitchDown;
        case '^': return TurtleOp::PitchUp;
        case '\\': return TurtleOp::RollLeft;
        case '/': return TurtleOp::RollRight;
        case '|': return TurtleOp::TurnAround;
        case '$': return TurtleOp::RollHorizontal;
        case '[': return TurtleOp::Push;
        case ']': return TurtleOp::Pop;
        case '!': return TurtleOp::WidthDown;
        case '#': return TurtleOp::WidthUp;
        case '~': return TurtleOp::Surface;
        case '{':
        case '}':
        case '.': return TurtleOp::Polygon;
        default: return TurtleOp::None;
        }
    }
    if (n == "@v") return TurtleOp::RollHorizontal;
    if (n == "@o" || n == "@O") return TurtleOp::Disc;
    if (n == "@Ts") return TurtleOp::Elasticity;
    if (n == "?P") return TurtleOp::QueryPosition;
    if (n == "?H") return TurtleOp::QueryHeading;
    if (n == "?L") return TurtleOp::QueryLeft;
    if (n == "?U") return TurtleOp::QueryUp;
    if (n == "?E") return TurtleOp::QueryEnvironment;
    if (n.size() > 1 && n[0] == '~') return TurtleOp::NamedSurface;
    if (n.size() > 1 && n[0] == '@') return TurtleOp::Unsupported;
    return TurtleOp::None;
}

TurtleSymbols::TurtleSymbols(const LSystem& system)
{
    const std::size_t n = system.symbol_count();
    ops_.reserve(n);
    names_.reserve(n);
    for (std::size_t i = 0; i < n; ++i) {
        names_.emplace_back(system.symbol_name(static_cast<SymbolId>(i)));
        ops_.push_back(op_of(names_.back()));
    }
}

TurtleSymbols::TurtleSymbols(std::span<const std::string_view> names)
{
    ops_.reserve(names.size());
    names_.reserve(names.size());
    for (const std::string_view n : names) {
        names_.emplace_back(n);
        ops_.push_back(op_of(n));
    }
}

TurtleResult interpret(const TurtleSymbols& symbols, const Word& word, const TurtleOptions& options)
{
    TurtleResult result;
    Walker walker(symbols, options.view, options.heading);
    walker.draw_into(result, options);
    walker.walk(word);
    walker.finish();
    return result;
}

TurtleResult interpret(const LSystem& system, const Word& word, const TurtleOptions& options)
{
    return interpret(TurtleSymbols(system), word, options);
}

void answer_queries(const TurtleSymbols& symbols, Word& word, const ViewSettings& view, const Environment* environment,
                    const glm::dvec3& heading)
{
    Walker walker(symbols, view, heading);
    walker.answer_into(word.params.data(), environment);
    walker.walk(word);
}

std::function<void(Word&)> query_answerer(const LSystem& system, const ViewSettings& view, const Environment* environment,
                                          const glm::dvec3& heading)
{
    auto symbols = std::make_shared<const TurtleSymbols>(system);
    return [symbols, view, environment, heading](Word& word) { answer_queries(*symbols, word, view, environment, heading); };
}

} // namespace lobe::lsystem
