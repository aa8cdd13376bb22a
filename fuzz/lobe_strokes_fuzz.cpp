// libFuzzer target: lobes drawn stroke by stroke (meshing/lobe.h), the heart of the sketching.
// The input bytes describe up to six strokes round one lobe: loops and arcs of any tilt, size,
// height, wobble, direction and point count, some up to 30 cm off, doubled, folded back,
// collapsed to a point or a line, or carrying a NaN or an enormous coordinate. Each is added
// with Lobe::add_stroke, as a drawing session adds it. Promises checked (docs/lobes.md):
// - a refused stroke gives one line (InvalidInput) and leaves the lobe exactly as it was;
// - every surface is closed, 2-manifold, outward-oriented, one piece, free of
//   self-intersections;
// - a stroke added while the centre stays gives, byte for byte, the whole build of the same
//   strokes with the regions it left as they were kept (build_lobe_surface, then
//   keep_unchanged_regions), though it builds only the changed regions and follows the
//   previous build's searches. The whole build may refuse what the continued one made only
//   where the continued one kept regions (their fill, refitted, can fall under its limit);
//   a lobe whose centre moved although its centroid stayed was refused round that centre;
// - the last lobe, remeshed as the apps remesh it (lobe_remesh.h), is one closed,
//   2-manifold, outward-oriented piece, or refused in one line.
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include <glm/geometric.hpp>

#include "fuzz/fuzz_common.h"
#include "meshing/lobe.h"
#include "meshing/lobe_regions.h"
#include "meshing/lobe_remesh.h"
#include "meshing/lobe_surface.h"
#include "meshing/mesh_quality.h"
#include "meshing/repair.h"

namespace {

constexpr double kPi = 3.14159265358979323846;

/// Reads the input a byte at a time; zeros once it is used up.
struct Bytes {
    const std::uint8_t* data;
    std::size_t size, at = 0;
    int next() { return at < size ? data[at++] : 0; }
    double unit() { return next() / 255.0; }
};

std::vector<glm::vec3> make_stroke(Bytes& in, const std::vector<std::vector<glm::vec3>>& before)
{
    const glm::dvec3 c(0.0, 1.3, -0.4);
    const int kind = in.next();
    const double tilt = kPi * in.unit(), turn = 2.0 * kPi * in.unit();
    const double r = 0.2 * (0.2 + 1.3 * in.unit());
    const double h = (in.unit() - 0.5) * 1.6 * r;
    const int n = 4 + in.next() % 160;
    const double sweep = (kind & 1) ? 0.1 + 0.9 * in.unit() : 1.0; // arcs and loops
    const double wobble = 0.005 * in.unit(), frequency = in.next() % 12;
    const bool reverse = (kind & 2) != 0;
    const glm::dvec3 axis(std::sin(tilt) * std::cos(turn), std::cos(tilt), std::sin(tilt) * std::sin(turn));
    glm::dvec3 u = glm::cross(axis, glm::dvec3(0.3, 0.1, 0.9));
    u = glm::length(u) > 1e-9 ? glm::normalize(u) : glm::dvec3(1, 0, 0);
    const glm::dvec3 v = glm::cross(axis, u);
    // Up to 30 cm off: a stroke farther from every lobe starts a lobe of its own (the session
    // builder's choice, not the lobe's), and a lobe a metre or two across fills up to the cap
    // of 20,000 interpolated vertices, seconds a build under ASan.
    const glm::dvec3 shift = (kind & 4) ? glm::dvec3(in.unit() - 0.5, in.unit() - 0.5, in.unit() - 0.5) * 0.6 : glm::dvec3(0.0);
    const double rr = std::sqrt(std::max(0.0, r * r - h * h));
    std::vector<glm::vec3> raw;
    for (int i = 0; i < n; ++i) {
        const double t = sweep * 2.0 * kPi * (reverse ? n - 1 - i : i) / n;
        const double w = wobble * std::sin(frequency * t);
        raw.emplace_back(c + shift + h * axis + (rr + w) * (std::cos(t) * u + std::sin(t) * v));
    }
    switch ((kind >> 3) % 16) { // the rest leave the stroke as it is
    case 0: // folded back on itself
        for (int i = n - 2; i >= 0; --i) raw.push_back(raw[static_cast<std::size_t>(i)]);
        break;
    case 1: // all at one point
        for (glm::vec3& p : raw) p = raw[0];
        break;
    case 2: // on one line
        for (int i = 0; i < n; ++i) raw[static_cast<std::size_t>(i)] = glm::vec3(c + (0.3 * i / n) * u);
        break;
    case 3: // a stroke drawn before, again
        if (!before.empty()) raw = before[static_cast<std::size_t>(in.next()) % before.size()];
        break;
    case 4: // a NaN
        raw[static_cast<std::size_t>(in.next()) % raw.size()].y = std::numeric_limits<float>::quiet_NaN();
        break;
    case 5: // an enormous coordinate
        raw[static_cast<std::size_t>(in.next()) % raw.size()].x = 3e30f;
        break;
    case 6: // the first points only: too few
        raw.resize(static_cast<std::size_t>(1 + in.next() % 3));
        break;
    default:
        break;
    }
    return raw;
}

bool same_surface(const lobe::LobeSurface& a, const lobe::LobeSurface& b)
{
    if (a.mesh.positions.size() != b.mesh.positions.size() || a.mesh.triangles != b.mesh.triangles ||
        a.mesh.feature_edges != b.mesh.feature_edges || a.origins.size() != b.origins.size() || a.centre != b.centre)
        return false;
    for (std::size_t i = 0; i < a.mesh.positions.size(); ++i)
        if (a.mesh.positions[i] != b.mesh.positions[i] || a.origins[i].kind != b.origins[i].kind ||
            a.origins[i].stroke != b.origins[i].stroke || a.origins[i].sample != b.origins[i].sample)
            return false;
    return true;
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    using namespace lobe;
    Bytes in{data, size};
    const int strokes = 1 + in.next() % 6;
    Lobe lobe;
    std::vector<std::vector<glm::vec3>> drawn;
    for (int k = 0; k < strokes; ++k) {
        const std::vector<glm::vec3> raw = make_stroke(in, drawn);
        drawn.push_back(raw);
        const bool first = lobe.empty();
        const LobeSurface before = first ? LobeSurface{} : lobe.surface();
        const SurfaceRegions before_regions = lobe.regions();
        const std::size_t before_strokes = lobe.strokes().size();
        const glm::dvec3 centre = lobe.centre();
        try {
            lobe.add_stroke(k + 1, raw);
        } catch (const InvalidInput& e) {
            fuzz::check_one_line(e.what());
            fuzz::require(lobe.strokes().size() == before_strokes, "a refused stroke changed the lobe's strokes");
            fuzz::require(first ? lobe.empty() : same_surface(lobe.surface(), before), "a refused stroke changed the surface");
            continue;
        }
        const LobeSurface& now = lobe.surface();
        const MeshQuality q = measure_quality(now.mesh);
        fuzz::require(q.closed && q.manifold && q.outward && q.components == 1,
                      "a lobe surface that is not one closed, 2-manifold, outward-oriented piece");
        fuzz::require(!self_intersects(now.mesh), "a lobe surface that intersects itself");
        if (first) continue;
        LobeSurfaceOptions options = LobeOptions{}.surface;
        options.reference_radius_m = before.reference_radius;
        if (lobe.centre() != centre) {
            // The centre moves when the strokes' centroid drifted from it, or when the lobe
            // cannot be built round it: then the whole build round it is refused too.
            double sum = 0.0;
            std::size_t n = 0;
            for (const LobeStrokeSamples& s : lobe.strokes())
                for (const glm::vec3& p : s.points) {
                    sum += glm::length(glm::dvec3(p) - centre);
                    ++n;
                }
            const double drift = glm::distance(lobe_stroke_centroid(lobe.strokes()), centre);
            if (drift <= LobeOptions{}.recentre_fraction * sum / static_cast<double>(n)) {
                bool refused = false;
                try {
                    build_lobe_surface(lobe.strokes(), centre, options);
                } catch (const InvalidInput&) {
                    refused = true;
                }
                fuzz::require(refused, "the lobe moved its centre though the whole build round the kept one works");
            }
            continue;
        }
        // The same strokes built whole around the same centre, with the same fill density,
        // and the regions the stroke left kept.
        LobeSurface whole;
        try {
            whole = build_lobe_surface(lobe.strokes(), centre, options);
        } catch (const InvalidInput&) {
            // The whole build fits every region's fill to the radius model of all strokes and
            // may refuse a region (a fill radius under a quarter of the strokes' least) that
            // the continued build kept, with its fill, as it was. Any other refusal is not.
            fuzz::require(lobe.last_kept().built_changed_only && lobe.last_kept().kept > 0,
                          "the whole build refuses a lobe the continued build made without keeping a region");
            continue;
        }
        SurfaceRegions whole_regions;
        keep_unchanged_regions(before, before_regions, whole, whole_regions);
        fuzz::require(same_surface(now, whole), "a continued lobe differs from the whole build with the unchanged regions kept");
        fuzz::require(whole_regions.edges == lobe.regions().edges, "the regions handed on differ from the whole build's");
    }
    // The last lobe remeshed as the apps remesh it (region by region, vertices lifted along
    // their rays from the centre onto the coarse fill): a valid lobe, or a one-line refusal.
    // At 5 cm rather than the apps' 3 cm: a lobe a metre across (strokes 30 cm off) took 17 s
    // under ASan at 3 cm (0.1 s in a release build), near the 30 s timeout.
    if (!lobe.empty()) {
        try {
            RemeshOptions o;
            o.target_edge_length_m = 0.05;
            o.relax_feature_edges = true;
            o.iterations = 4;
            const TriangleMesh remeshed = remesh_lobe_surface(lobe.surface(), o);
            const MeshQuality q = measure_quality(remeshed);
            fuzz::require(q.closed && q.manifold && q.outward && q.components == 1,
                          "a remeshed lobe that is not one closed, 2-manifold, outward-oriented piece");
            for (const glm::vec3& p : remeshed.positions)
                fuzz::require(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z), "a remeshed vertex not finite");
        } catch (const InvalidInput& e) {
            fuzz::check_one_line(e.what());
        }
    }
    return 0;
}
