#pragma once
/// \file lobe.h
/// Progressive lobes (§4.2, Fig. 5): strokes join a lobe one at a time and the lobe's
/// closed surface follows at once. See docs/lobes.md.

#include <cstdint>
#include <optional>
#include <vector>

#include <glm/vec3.hpp>

#include "meshing/lobe_regions.h"
#include "meshing/lobe_surface.h"
#include "meshing/sampling.h"

namespace lobe {

/// Options of progressive lobes.
struct LobeOptions {
    SamplingOptions sampling;
    ClosureOptions closure;
    LobeSurfaceOptions surface;
    /// A stroke whose samples all lie within this distance of one stroke of the lobe
    /// duplicates it and is refused.
    double duplicate_distance_m = 0.004;
    /// Raw points are kept between the curvature samples (Eq. 1) where the chord between two
    /// samples would leave the drawn stroke by more than this (Douglas–Peucker), so the lobe
    /// passes within it of every drawn point. 0 keeps the samples alone.
    double max_chord_deviation_m = 0.0015;
    /// The lobe's centre stays where it is while the centroid of its strokes is within
    /// this fraction of the lobe's mean radius of it, so adding a stroke changes only the
    /// region around that stroke; beyond it the centre moves and the lobe is re-laid.
    double recentre_fraction = 0.2;
};

/// Sampling (Eq. 1) and closing (§4.1) of one raw lobe stroke, plus the raw points needed to
/// keep the stroke within LobeOptions::max_chord_deviation_m.
/// \throw InvalidInput for degenerate strokes (fewer than 4 points, zero length, all on one
/// line, not finite, beyond 1 km).
LobeStrokeSamples prepare_lobe_stroke(std::int64_t id, const std::vector<glm::vec3>& raw,
                                      const LobeOptions& options = {});

/// One lobe built progressively. Every change either succeeds or leaves the lobe exactly as
/// it was (strong guarantee) and throws InvalidInput with a one-line reason.
class Lobe {
public:
    explicit Lobe(LobeOptions options = {});

    /// Adds a raw stroke: sampled, closed when its ends meet, then joined to the surface.
    /// While the centre stays, every region of the surface that the stroke leaves as it was
    /// keeps its triangles and vertices bit for bit, and only the changed regions are built
    /// (continue_lobe_surface): the surface after a stroke depends on the surface before it,
    /// so a lobe is the strokes added in their order (as LobeBuildCache and a replay both add
    /// them).
    void add_stroke(std::int64_t id, const std::vector<glm::vec3>& raw);
    /// Adds an already prepared stroke.
    void add_prepared(LobeStrokeSamples stroke);
    /// Removes a stroke (by id); false when the lobe has no such stroke. Throws when the
    /// remaining strokes cannot make a lobe (the lobe is left unchanged then).
    bool remove_stroke(std::int64_t id);

    bool empty() const { return strokes_.empty(); }
    /// What the last add_stroke / add_prepared kept of the surface before it.
    const KeptRegions& last_kept() const { return last_kept_; }
    /// The regions of surface() (surface_regions of its mesh), kept for the next stroke.
    const SurfaceRegions& regions() const { return regions_; }
    const std::vector<LobeStrokeSamples>& strokes() const { return strokes_; }
    /// The closed surface through every stroke, before remeshing.
    /// \pre !empty()
    const LobeSurface& surface() const { return *surface_; }
    const glm::dvec3& centre() const { return centre_; }
    /// Mean distance of the stroke samples from the centre.
    double mean_radius() const;
    /// Smallest distance from any of `points` to any stroke sample of the lobe (metres);
    /// infinity for an empty lobe.
    double distance_to(const std::vector<glm::vec3>& points) const;

private:
    void rebuild(std::vector<LobeStrokeSamples> strokes, bool keep_regions);
    LobeOptions options_;
    std::vector<LobeStrokeSamples> strokes_;
    std::optional<LobeSurface> surface_;
    glm::dvec3 centre_{0.0};
    KeptRegions last_kept_;
    SurfaceRegions regions_; ///< of surface_ (kept for the next stroke)
};

} // namespace lobe
