#pragma once
/// \file skeleton.h
/// The tree's skeleton from the sketched trunk strokes (§5.1): the stroke with the lowest
/// point becomes the main branch, rooted at its lower end (the trunk base, on the ground);
/// the other strokes join one by one, the one nearest the skeleton first, at the skeleton node
/// nearest the stroke, through the stroke's point nearest it (an end, or a point in its middle:
/// then the stroke grows both ways from there). A stroke more than 30 cm from every lobe is
/// kept, with a message. With no trunk strokes a default trunk rises from the ground below the lobes
/// and reaches into each of them. A lobe that no skeleton node enters gets a limb from the
/// nearest skeleton node to its centre, with a message when the trunk stays more than 5 cm
/// from it (a stroke ending just short of a lobe touches it). docs/growth.md.

#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "core/mesh.h"
#include "core/settings.h"
#include "core/tree.h"

namespace lobe {

class MeshRaycaster;

struct SkeletonOptions {
    double spacing_m = GrowthSettings{}.skeleton_spacing_m; ///< distance between skeleton nodes along a stroke
    /// The default trunk's base lies this fraction of the lobes' total height below the
    /// lowest lobe (and never below the stage floor y = 0 when the lobes are above it).
    double default_trunk_fraction = 0.6;
    /// The trunk (default or sketched) continues from its highest point as a leader up
    /// through the crown (growth/species_form.h, GrowthSettings::leader), its nodes
    /// whorl_spacing × the crown's height apart (0: spacing_m).
    bool leader = false;
    double whorl_spacing = 0.0;
};

/// Most trunk strokes used, and most skeleton nodes (the spacing grows to stay below it).
inline constexpr std::size_t kMaxTrunkStrokes = 512;
inline constexpr std::size_t kMaxSkeletonNodes = 20000;

struct Skeleton {
    TreeGraph graph;         ///< nodes[0] = root (TreeNodeKind::Root), the rest TreeNodeKind::Skeleton
    std::vector<int> owner;  ///< per node: -1 shared by every lobe, or the lobe a limb was made for
    std::vector<std::string> messages; ///< one line each: strokes left out, limbs added
    bool from_strokes = false; ///< false: the default trunk
};

/// \param trunk_strokes raw trunk stroke points (metres); unusable strokes (fewer than 2
///        finite points, shorter than the spacing) are left out with a message.
/// \param lobes the lobes the tree grows in (closed meshes), for the default trunk and limbs.
/// Returns an empty graph only when there are neither usable strokes nor lobes.
/// \param rays (optional) ray casters of `lobes`, same order, when the caller has them.
Skeleton build_skeleton(const std::vector<std::vector<glm::vec3>>& trunk_strokes,
                        const std::vector<TriangleMesh>& lobes, const SkeletonOptions& options = {},
                        const std::vector<MeshRaycaster>* rays = nullptr);

} // namespace lobe
