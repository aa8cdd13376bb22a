#pragma once
/// \file lsystem_sketch_mode.h
/// The L-system sketch mode of the live apps (seed 000; docs/lsystem-sketch.md): on a small
/// platform (a world in miniature) a person pinches trunk sections at the fingertip, picks,
/// drags and erases nodes, starts branches from earlier trunk nodes, steps the growth, turns
/// the divergence, and the full-size tree grows beside the platform from the parametric
/// 2L-system derived from the sketch (growth/lsystem/sketch.h).
///
/// The mode reads raw input only (hand frames, key presses), so a recording replays it
/// exactly (replay_lsystem_sketch): keys::kLSystemSketch (P) turns it on and off (the input
/// pipeline then leaves the hands and keys to it), and while it is on:
///   right-hand pinch   away from a node: adds a section at the fingertip to the axis being
///                      drawn (the trunk, or the branch started with B); on a node (within
///                      kPickRadiusM on the platform): picks it and drags it until released
///   left-hand pinch    on the platform (within kGrabRadiusM of its centre): grabs it and
///                      moves it with the hand until released
///   B                  starts (or goes on drawing) a branch from the trunk node at the
///                      fingertip (after at least two trunk sections; not the root or tip)
///   T                  goes back to drawing the trunk
///   Backspace          erases the node at the fingertip (a trunk node takes the branches
///                      drawn from it with it; the sections beside it join)
///   Delete             scraps the sketch
///   [ ]                divergence −/+ 5° (0 … 360)
///   , .                growth one iteration back / forward; - = by a tenth of an iteration
/// A change that would make a bad sketch (a zero-length section, a branch off a node that
/// is gone) is refused with one message line and changes nothing. The preview is the section
/// the next pinch would add: from the axis's last node to the right fingertip.
///
/// Units: stage space, metres. The sketch is kept at full size: platform point q is sketch
/// point R_y(−yaw)·(q − platform position) / scale; the tree stands `tree_offset` beside the
/// platform (turned with it), at full size.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "core/hand_frame.h"
#include "growth/grow.h"
#include "growth/lsystem/sketch.h"
#include "input/gestures.h"
#include "input/recording.h"

namespace lobe {

/// Mode keys (GLFW codes) besides keys::kLSystemSketch (input/tools.h).
namespace lsystem_sketch_keys {
inline constexpr int kBranch = 66;        // B
inline constexpr int kTrunk = 84;         // T
inline constexpr int kErase = 259;        // Backspace
inline constexpr int kScrap = 261;        // Delete
inline constexpr int kDivergenceDown = 91; // [
inline constexpr int kDivergenceUp = 93;   // ]
inline constexpr int kIterationBack = 44;  // ,
inline constexpr int kIterationForward = 46; // .
inline constexpr int kGrowthDown = 45;     // -
inline constexpr int kGrowthUp = 61;       // =
} // namespace lsystem_sketch_keys

struct SketchPlatform {
    glm::dvec3 position{0.0, 1.0, -0.45}; ///< its top's centre (the trunk's root), stage metres
    double yaw = 0.0;                     ///< radians about +Y
    double scale = 0.1;                   ///< platform metres per sketch metre (1:10)
    glm::dvec3 tree_offset{0.9, -1.0, 0.0}; ///< the full-size tree's root from the platform's centre (platform axes, metres)
};

class LSystemSketchMode {
public:
    /// Fingertip within this of a node (stage metres) picks it.
    static constexpr double kPickRadiusM = 0.015;
    /// Left fingertip within this of the platform's centre grabs it.
    static constexpr double kGrabRadiusM = 0.12;
    /// Most segments of a tree the growth keys grow on to (a regrowth stays within a frame).
    static constexpr std::size_t kMaxLiveSegments = 30000;

    explicit LSystemSketchMode(SketchPlatform platform = {});

    /// A raw key event (press: value 1); false when the mode does not use it (or is off and
    /// it is not the mode key).
    bool push_event(const InputEvent& e);
    /// A frame of both hands, stage space; read only while the mode is on (gestures always).
    void push_frame(const HandFrame& frame);

    /// Starts from `sketch` (a sketch file's, e.g. the one saved beside an opened session), as
    /// if it had been drawn: the growth shown is its `iterations` when it has them, the trunk
    /// is the axis being drawn; on or off stays as it is. \throw InvalidInput, one line
    /// starting with `name`, when it is not a sketch the mode can hold or grow (nothing changes).
    void load(lsystem::Sketch sketch, const std::string& name);

    bool active() const { return active_; }
    const lsystem::Sketch& sketch() const { return sketch_; }
    /// The sketch as a sketch file holds it: with the growth shown as its iterations when that
    /// is a whole number other than the trunk's section count.
    lsystem::Sketch sketch_file() const;
    const SketchPlatform& platform() const { return platform_; }
    /// The axis pinches add to: 0 the trunk, else the trunk node the branch being drawn
    /// comes from (its first pinch makes the branch type when there is none on that node).
    int drawing_from() const { return from_; }
    /// The growth shown (iterations); follows the trunk's sections until a growth key is used.
    double growth() const;
    /// The next section's preview, stage space (from, to); none when the fingertip is not
    /// tracked or is on a node.
    const std::optional<std::pair<glm::dvec3, glm::dvec3>>& preview() const { return preview_; }
    /// The picked node being dragged: axis (-1 trunk) and node; none.
    const std::optional<std::pair<int, int>>& dragging() const { return drag_; }
    /// The full-size tree, stage space (radii by the pipe model); empty before two trunk nodes.
    const TreeGraph& tree() const { return tree_; }
    /// Counts regrowths, to notice a new tree.
    std::uint64_t tree_generation() const { return generation_; }
    /// Sketch node (full size) → stage (on the platform), and the tree's points.
    glm::dvec3 platform_point(const glm::dvec3& sketch_point) const;
    glm::dvec3 tree_point(const glm::dvec3& sketch_point) const;
    /// Every message line so far (refusals, what was done), oldest first, at most 200.
    const std::vector<std::string>& messages() const { return messages_; }

private:
    glm::dvec3 to_sketch(const glm::dvec3& stage) const;
    /// The node (axis, index) nearest `stage` within the pick radius; root excluded.
    std::optional<std::pair<int, int>> pick(const glm::dvec3& stage) const;
    /// Sets the sketch to `next` and regrows, or refuses it with `what` and a message (none
    /// when `quiet`), changing nothing.
    bool commit(lsystem::Sketch next, const std::string& what, bool quiet = false);
    /// The tree of `s` at the growth shown (sketch space). \throw InvalidInput
    TreeGraph grow(const lsystem::Sketch& s) const;
    void place_tree();
    void note(std::string line);
    void key(int code);
    void erase(const std::pair<int, int>& n);
    void start_branch();
    void step_growth(double by);
    void right_hand(const HandGesture& g);
    void left_hand(const HandGesture& g);

    SketchPlatform platform_;
    lsystem::Sketch sketch_;
    GestureRecognizer gestures_;
    bool active_ = false;
    int from_ = 0;
    std::optional<double> growth_;
    std::optional<std::pair<glm::dvec3, glm::dvec3>> preview_;
    std::optional<std::pair<int, int>> drag_;
    std::optional<glm::dvec3> grab_from_; ///< left fingertip when the platform was grabbed
    glm::dvec3 grab_platform_{0.0};
    glm::dvec3 right_tip_{0.0};
    bool right_tracked_ = false;
    TreeGraph tree_local_; ///< the tree in sketch space (root at the origin)
    TreeGraph tree_;       ///< tree_local_ beside the platform
    std::size_t segments_ = 0;
    std::uint64_t generation_ = 0;
    std::vector<std::string> messages_;
};

/// Where the platform stands for the app that made a recording (RecordingHeader::source):
/// for the desktop ("lobesketch desktop…") 1:5 below the camera's first target, on the
/// plane the mouse's fingertip moves in; else (VR, synthesized) 1:10 at waist height half an
/// arm in front. The live apps and replay take it from here, so a replay stands it alike.
SketchPlatform sketch_platform_for(const std::string& recording_source);

/// Replays the raw input of a recording (events at a frame's time before that frame, as the
/// live apps push them) through a fresh mode with the platform of sketch_platform_for: the
/// sketch, platform and tree as they were.
LSystemSketchMode replay_lsystem_sketch(const Recording& recording);

} // namespace lobe
