#pragma once
/// \file turtle.h
/// The 3D turtle that draws a derived L-system word (lsystem.h) as a tree graph
/// (core/tree.h), as cpfg does (*The Algorithmic Beauty of Plants*, "ABOP", §1.5 and §2.4;
/// the cpfg manual). docs/lsystem-turtle.md describes it.
///
/// The turtle has a position and three unit vectors, heading H, left L and up U (H × L = U).
/// It starts at the model's origin with H = +Y (up), L = −X and U = +Z, so the model's +Y is
/// up and, seen from the front (looking along −Z), `+` turns to the left. Angles without a
/// parameter are the view file's angle increment; a step without a parameter is 1 model unit.
///
///   F(d) G(d)  move d forward and draw a branch segment (G as F: there are no polygons)
///   f(d) g(d)  move d forward without drawing: the next segment is not joined to the last
///              (it starts at a TreeNodeKind::Detached node)
///   +(a) -(a)  turn left / right about U (H turns towards L / −L)
///   &(a) ^(a)  pitch down / up about L (H turns towards −U / U)
///   \(a) /(a)  roll left / right about H (U turns towards L / −L)
///   |          turn 180° about U
///   $  @v      roll about H so that L is horizontal and U points up as far as it can
///   [ ]        push / pop the whole state (position, vectors, width, elasticity)
///   !(w) #(w)  set the width to w; without a parameter: decrease / increase it by the view
///              file's line width increment (never below 0)
///   @o(d) @O(d) a disc (sphere) of diameter d (else the width): a round leaf card
///   ~X(s)      surface X scaled by s: a leaf card (PlacedLeaf) of the surface size × s
///   @Ts(e)     set the turtle's elasticity to e; without a parameter add the view file's
///              elasticity increment (L-Py's name; cpfg sets it in the view file only)
///   ; , % ?P ?H ?L ?U ?E and every other module: nothing drawn
///
/// A step that would take the turtle more than 10⁹ units from the origin stops it (what is
/// drawn so far is kept, with a message).
///
/// Widths: the view file's initial line width, then `!` and `#`; a node's radius is half the
/// width of the segment that ends at it. Widths in model units (ViewSettings::width_unit,
/// the view file's `polygons` or `line style: cylinder`) scale with the model (times
/// metres_per_unit); cpfg's default, pixels, is drawn as if the whole drawing were
/// kPixelsAcrossDrawing pixels across (about the size of the book's figures), so that the
/// book's `!(10)` trunk is 2.5 % of the tree's largest extent across. Tropism (ABOP §2.4), when the
/// view file gives one: after each drawn step H turns towards the tropism vector T by
/// α = e·|H × T| radians (never past T), L and U with it, e the turtle's elasticity.
///
/// Segments along one straight line with one width, with nothing branching or hanging
/// between them, become one segment; every other drawn step makes one node whose parent is
/// the node the step started from. The turtle allocates nothing per module beyond the
/// growth of its output and its branch stack.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <glm/vec3.hpp>

#include "core/tree.h"
#include "growth/leaves.h"
#include "growth/lsystem/lsystem.h"

namespace lobe::lsystem {

/// How many pixels a drawing is across when its widths are cpfg's pixel widths (turtle.h).
inline constexpr double kPixelsAcrossDrawing = 400.0;

/// What the turtle does with a module.
enum class TurtleOp : std::uint8_t {
    None,           ///< not a turtle command (letters, `;`, `,`, `%`, …)
    Draw,           ///< F G
    Move,           ///< f g
    TurnLeft,       ///< +
    TurnRight,      ///< -
    PitchDown,      ///< &
    PitchUp,        ///< ^
    RollLeft,       ///< backslash
    RollRight,      ///< /
    TurnAround,     ///< |
    RollHorizontal, ///< $ @v
    Push,           ///< [
    Pop,            ///< ]
    WidthDown,      ///< !
    WidthUp,        ///< #
    Disc,           ///< @o @O
    Surface,        ///< ~ followed by the surface's name as the next module
    NamedSurface,   ///< ~X as one symbol
    Elasticity,     ///< @Ts
    QueryPosition,  ///< ?P
    QueryHeading,   ///< ?H
    QueryLeft,      ///< ?L
    QueryUp,        ///< ?U
    QueryEnvironment, ///< ?E
    Polygon,        ///< { } . (polygons are not drawn: one warning)
    Unsupported,    ///< another @ command (one warning)
};

/// The turtle's reading of every symbol of a system, looked up once.
class TurtleSymbols {
public:
    explicit TurtleSymbols(const LSystem& system);
    /// From the symbols' names by id (for words built by hand).
    explicit TurtleSymbols(std::span<const std::string_view> names);

    TurtleOp op(SymbolId id) const { return id < ops_.size() ? ops_[id] : TurtleOp::None; }
    std::string_view name(SymbolId id) const { return id < names_.size() ? std::string_view(names_[id]) : std::string_view(); }
    std::size_t size() const { return ops_.size(); }

    /// What `name` means to the turtle.
    static TurtleOp op_of(std::string_view name);

private:
    std::vector<TurtleOp> ops_;
    std::vector<std::string> names_;
};

/// Deepest nesting of `[` the turtle follows; deeper is refused (memory stays bounded:
/// about 100 bytes a level).
inline constexpr std::size_t kMaxTurtleDepth = std::size_t{1} << 20;

struct TurtleOptions {
    ViewSettings view;
    /// Where the model's origin is, metres, stage space; the model's axes are the stage's.
    glm::dvec3 origin{0.0};
    /// The turtle's first heading (start_frame); +Y, the default, gives the frame above.
    glm::dvec3 heading{0.0, 1.0, 0.0};
    /// Metres per model unit (positions, radii and disc sizes).
    double metres_per_unit = 1.0;
    /// When > 0: metres_per_unit is chosen instead so that the drawn tree is this tall (its
    /// highest node above its root; a tree that does not rise: its largest extent).
    double fit_height_m = 0.0;
    /// A surface's leaf card at scale 1, metres (its size in the `.s` file is not known).
    double surface_length_m = 0.08;
    double surface_width_m = 0.05;
    /// Most nodes and leaves; past either the turtle stops with a message.
    std::size_t max_nodes = 5000000;
    std::size_t max_leaves = 5000000;
};

struct TurtleResult {
    /// nodes[0] (TreeNodeKind::Root) is where the first segment starts; the rest Grown, or
    /// Detached where a move without drawing came before. Radii from the widths, metres.
    /// Empty when nothing is drawn.
    TreeGraph tree;
    std::vector<PlacedLeaf> leaves; ///< from `~` and `@o`, in word order
    bool widths_set = false;        ///< the word holds `!` or `#`
    std::size_t segments = 0;       ///< drawn steps (F, G) of non-zero length
    double metres_per_unit = 1.0;   ///< the scale used (TurtleOptions::fit_height_m may choose it)
    std::vector<std::string> messages; ///< one line each: unsupported commands, caps, skipped modules
};

/// Draws `word`. \throw InvalidInput when branches nest deeper than kMaxTurtleDepth.
TurtleResult interpret(const TurtleSymbols& symbols, const Word& word, const TurtleOptions& options);
TurtleResult interpret(const LSystem& system, const Word& word, const TurtleOptions& options);

/// Fills the query modules of `word` by walking it with the turtle (nothing is drawn):
/// `?P(x, y, z)` the position, `?H`, `?L`, `?U` the vectors, all in model units and axes;
/// `?E(v)` v = 1 when `environment` (model units) holds the position or is null, else 0. A
/// query with fewer parameters gets the first ones. The word is read as derived (before
/// homomorphism). \throw InvalidInput as interpret.
void answer_queries(const TurtleSymbols& symbols, Word& word, const ViewSettings& view,
                    const Environment* environment = nullptr, const glm::dvec3& heading = {0.0, 1.0, 0.0});

/// answer_queries for DeriveOptions::answer_queries; `environment` must outlive it.
std::function<void(Word&)> query_answerer(const LSystem& system, const ViewSettings& view,
                                          const Environment* environment = nullptr,
                                          const glm::dvec3& heading = {0.0, 1.0, 0.0});

/// The turtle's first frame for a first heading: H = heading (normalised), L horizontal
/// (+Z × H; −X when H is along ±Z), U = H × L. +Y gives H = +Y, L = −X, U = +Z; a zero or
/// non-finite heading gives that too.
void start_frame(const glm::dvec3& heading, glm::dvec3& h, glm::dvec3& l, glm::dvec3& u);

} // namespace lobe::lsystem
