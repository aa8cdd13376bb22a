// Offscreen pictures (app/render/renderer.h, app/render/render_scene.h, `lobesketch render`) of the tree of
// a shipped recording, small (192×144) so the suite stays fast on lavapipe.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <stdexcept>
#include <type_traits>

#include <dlfcn.h>
#include <sys/wait.h>

#include <glm/gtc/constants.hpp>
#include <vulkan/vulkan.h>

#include "app/session/edit_hooks.h"
#include "app/export/export_gltf.h"
#include "app/export/export_scene.h"
#include "app/render/render_scene.h"
#include "app/render/renderer.h"
#include "app/export/tree_output.h"
#include "app/session/tree_pipeline.h"
#include "input/pipeline.h"
#include "input/recording.h"
#include "app/session/session_builder.h"
#include "app/session/edit_ops.h"
#include "tests/support/cli_run.h"
#include "tests/support/test_data.h"
#include "tests/support/test_paths.h"

namespace lobe {
namespace {

namespace fs = std::filesystem;

constexpr int kW = 192, kH = 144;

/// recordings/<name>.lrec; empty when it is missing (the test has then failed with one line).
std::string rec(const std::string& name, const char* file = __builtin_FILE(), int line = __builtin_LINE())
{
    return test::source_data("recordings/" + name + ".lrec", file, line);
}

/// The 1-lobe, 5-stroke Table 1 tree, its geometry and one renderer, made once for the suite
/// from its recording. A test that uses it, itself or through the helpers below, starts with
/// `if (!has_shared_recording()) return;`.
struct Shared {
    Document doc;
    BuiltTree tree;
    TreeGeometry geometry;
    std::unique_ptr<Renderer> renderer;
    std::unique_ptr<Renderer> reference; // leaves as plain triangles (made on first use)
};

/// True when the suite's recording is there; else the test has failed with one line.
bool has_shared_recording(const char* file = __builtin_FILE(), int line = __builtin_LINE())
{
    return !rec("table1-1lobe-5strokes", file, line).empty();
}

Shared& shared()
{
    static Shared s = [] {
        Shared out;
        const Recording recording = read_recording(rec("table1-1lobe-5strokes"));
        const InputResult r = run_input_pipeline(recording);
        SessionBuilder b(Document{}, EditPickOptions{}, meshing_edit_hooks());
        b.apply(r.actions);
        out.doc = b.take_document();
        out.tree = build_document_tree(out.doc);
        out.geometry = document_tree_geometry(out.doc, out.tree);
        out.renderer = std::make_unique<Renderer>();
        return out;
    }();
    return s;
}

RenderScene tree_scene(const RenderContent& content = {})
{
    Shared& s = shared();
    std::vector<TriangleMesh> lobes;
    for (const BuiltLobe& l : s.tree.lobes) lobes.push_back(l.mesh);
    return tree_render_scene(s.geometry, lobes, effective_strokes(s.doc), s.tree.growth.tree.nodes[0].position.y, content);
}

RgbaImage draw(const RenderScene& scene, const Camera& camera, int w = kW, int h = kH)
{
    Renderer& r = *shared().renderer;
    r.set_scene(scene);
    return r.render(camera, w, h);
}

/// The renderer that draws every leaf mesh as plain triangles (RendererOptions::instanced_leaves
/// off): the reference for the instanced leaves.
Renderer& reference_renderer()
{
    Shared& s = shared();
    if (!s.reference) {
        RendererOptions options;
        options.instanced_leaves = false;
        s.reference = std::make_unique<Renderer>(options);
    }
    return *s.reference;
}

RgbaImage draw_reference(const RenderScene& scene, const Camera& camera, int w = kW, int h = kH)
{
    Renderer& r = reference_renderer();
    r.set_scene(scene);
    EXPECT_EQ(r.stats().leaf_instances, 0u);
    return r.render(camera, w, h);
}

/// The same sky and ground, nothing else: what a pixel of no tree looks like.
RgbaImage background_of(const RenderScene& scene, const Camera& camera, int w = kW, int h = kH)
{
    RenderScene empty;
    empty.ground_y = scene.ground_y;
    empty.ground_area = scene.ground_area.empty() ? scene_bounds(scene) : scene.ground_area;
    return draw(empty, camera, w, h);
}

Camera camera_for(const RenderScene& scene, const ViewAngles& view, int w = kW, int h = kH)
{
    return frame_view(scene_bounds(scene), view, float(w) / float(h));
}

/// Hue in degrees (0..360) and saturation (0..1) of linear RGB.
std::pair<double, double> hue_saturation(double r, double g, double b)
{
    const double hi = std::max({r, g, b}), lo = std::min({r, g, b});
    if (hi <= 0.0 || hi - lo < 1e-9) return {0.0, 0.0};
    const double d = hi - lo;
    double h = 0.0;
    if (hi == r)
        h = 60.0 * std::fmod((g - b) / d + 6.0, 6.0);
    else if (hi == g)
        h = 60.0 * ((b - r) / d + 2.0);
    else
        h = 60.0 * ((r - g) / d + 4.0);
    return {h, d / hi};
}

double srgb_to_linear(std::uint8_t v)
{
    const double c = v / 255.0;
    return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

double hue_distance(double a, double b)
{
    const double d = std::fmod(std::abs(a - b), 360.0);
    return std::min(d, 360.0 - d);
}

std::string png_bytes(const RgbaImage& image)
{
    const std::vector<std::uint8_t> png = encode_png(image);
    return std::string(png.begin(), png.end());
}

TEST(RenderPicture, FrontViewOfTheTreeCoversAPlausibleShareOfTheFrameOverSkyAndGround)
{
    if (!has_shared_recording()) return;
    const RenderScene scene = tree_scene();
    const Camera camera = camera_for(scene, front_view());
    const RgbaImage picture = draw(scene, camera);
    ASSERT_EQ(picture.width, kW);
    ASSERT_EQ(picture.height, kH);
    ASSERT_EQ(picture.pixels.size(), std::size_t(kW) * kH * 4);
    const RgbaImage background = background_of(scene, camera);
    // The background itself is not flat: a sky gradient above a ground.
    const std::uint8_t* top = &background.pixels[(std::size_t(kW) / 2) * 4];
    const std::uint8_t* bottom = &background.pixels[(std::size_t(kH - 1) * kW + kW / 2) * 4];
    EXPECT_GT(int(top[2]), int(top[0]) + 40) << "the sky at the top is blue";
    EXPECT_GT(std::abs(int(top[2]) - int(bottom[2])), 40) << "the ground at the bottom is not sky";
    const double share = coverage(picture, background);
    EXPECT_GT(share, 0.10);
    EXPECT_LT(share, 0.70);
}

TEST(RenderPicture, FrontAndSideViewsDiffer)
{
    if (!has_shared_recording()) return;
    const RenderScene scene = tree_scene();
    const RgbaImage front = draw(scene, camera_for(scene, front_view()));
    const RgbaImage side = draw(scene, camera_for(scene, side_view()));
    const double differing = coverage(front, side);
    EXPECT_GT(differing, 0.05);
}

TEST(RenderPicture, LeafColouredAndBarkColouredPixelsAreBothPresent)
{
    if (!has_shared_recording()) return;
    const RenderScene scene = tree_scene();
    const Camera camera = camera_for(scene, front_view());
    const RgbaImage picture = draw(scene, camera);
    std::vector<std::uint8_t> mask;
    coverage(picture, background_of(scene, camera), 24, &mask);
    const auto& g = shared().geometry;
    const double leaf_hue = hue_saturation(g.leaf_color[0], g.leaf_color[1], g.leaf_color[2]).first;
    const double bark_hue = hue_saturation(g.bark_color[0], g.bark_color[1], g.bark_color[2]).first;
    ASSERT_GT(hue_distance(leaf_hue, bark_hue), 50.0);
    std::size_t leaf = 0, bark = 0, tree = 0;
    for (std::size_t i = 0; i < mask.size(); ++i) {
        if (!mask[i]) continue;
        ++tree;
        const std::uint8_t* p = &picture.pixels[4 * i];
        const auto [h, s] = hue_saturation(srgb_to_linear(p[0]), srgb_to_linear(p[1]), srgb_to_linear(p[2]));
        if (s < 0.25) continue;
        if (hue_distance(h, leaf_hue) < 25.0) ++leaf;
        if (hue_distance(h, bark_hue) < 15.0) ++bark;
    }
    ASSERT_GT(tree, 0u);
    EXPECT_GT(double(leaf) / double(tree), 0.30) << leaf << " leaf pixels of " << tree;
    EXPECT_GT(bark, 10u) << bark << " bark pixels of " << tree;
}

TEST(RenderPicture, TwoIdenticalRunsGiveByteIdenticalPictures)
{
    if (!has_shared_recording()) return;
    const RenderScene scene = tree_scene();
    const Camera camera = camera_for(scene, side_view());
    const std::string a = png_bytes(draw(scene, camera));
    const std::string b = png_bytes(draw(scene, camera));
    EXPECT_EQ(a, b);
    // A fresh renderer (new device, new buffers) draws the same bytes too.
    Renderer other;
    other.set_scene(scene);
    EXPECT_EQ(png_bytes(other.render(camera, kW, kH)), a);
}

TEST(RenderPicture, WithoutMultisamplingTheSameTreeCoversTheSameShareOfThePicture)
{
    if (!has_shared_recording()) return;
    const RenderScene scene = tree_scene();
    const Camera camera = camera_for(scene, front_view());
    RendererOptions options;
    options.samples = 1;
    Renderer single(options);
    EXPECT_EQ(single.samples(), 1);
    EXPECT_EQ(shared().renderer->samples(), 4);
    single.set_scene(scene);
    const RgbaImage aliased = single.render(camera, kW, kH);
    RenderScene empty;
    empty.ground_y = scene.ground_y;
    empty.ground_area = scene_bounds(scene);
    single.set_scene(empty);
    const double share1 = coverage(aliased, single.render(camera, kW, kH));
    const double share4 = coverage(draw(scene, camera), background_of(scene, camera));
    EXPECT_NEAR(share1, share4, 0.03);
}

struct LodSilhouette {
    std::size_t both = 0, only_lod0 = 0, only_lod = 0;
    double iou() const { return double(both) / double(std::max<std::size_t>(1, both + only_lod0 + only_lod)); }
    double lod0_covered() const { return double(both) / double(std::max<std::size_t>(1, both + only_lod0)); }
};

/// Silhouettes (pixels that differ from sky and ground) of LOD1 and LOD2 against LOD0, all
/// from LOD0's front camera over the same ground.
std::vector<LodSilhouette> lod_silhouettes()
{
    RenderContent content;
    const RenderScene lod0 = tree_scene(content);
    const Bounds area = scene_bounds(lod0);
    const Camera camera = camera_for(lod0, front_view());
    RenderScene empty;
    empty.ground_y = lod0.ground_y;
    empty.ground_area = area;
    const RgbaImage background = draw(empty, camera);
    std::vector<std::uint8_t> mask0;
    coverage(draw(lod0, camera), background, 24, &mask0);
    std::vector<LodSilhouette> out;
    for (int lod = 1; lod <= 2 && std::size_t(lod) < shared().geometry.lods.size(); ++lod) {
        content.lod = lod;
        RenderScene scene = tree_scene(content);
        scene.ground_area = area;
        std::vector<std::uint8_t> mask;
        coverage(draw(scene, camera), background, 24, &mask);
        LodSilhouette s;
        for (std::size_t i = 0; i < mask.size(); ++i) {
            s.both += mask[i] && mask0[i];
            s.only_lod0 += mask0[i] && !mask[i];
            s.only_lod += mask[i] && !mask0[i];
        }
        out.push_back(s);
    }
    return out;
}

std::string describe(const LodSilhouette& s, int lod)
{
    return "LOD" + std::to_string(lod) + ": IoU " + std::to_string(s.iou()) + ", " + std::to_string(s.both) +
           " pixels in both, " + std::to_string(s.only_lod0) + " only in LOD0, " + std::to_string(s.only_lod) +
           " only in LOD" + std::to_string(lod);
}

// The growth issue's LOD check: coarse LODs keep LOD0's silhouette (coarse leaves are fewer
// and larger, grown mostly in width about their centre so the crown's outline stays).
TEST(RenderPicture, CoarserLodsKeepTheSilhouetteOfLod0WithIntersectionOverUnionOfAtLeast0_9)
{
    if (!has_shared_recording()) return;
    const std::vector<LodSilhouette> lods = lod_silhouettes();
    ASSERT_EQ(lods.size(), 2u);
    for (int lod = 1; lod <= 2; ++lod) {
        const LodSilhouette& s = lods[std::size_t(lod - 1)];
        EXPECT_GE(s.iou(), 0.9) << describe(s, lod);
        EXPECT_GE(s.lod0_covered(), 0.95) << describe(s, lod);
        RecordProperty("silhouette_lod" + std::to_string(lod), describe(s, lod));
    }
}

TEST(RenderPicture, LobesAndStrokesAreDrawnOverTheTreeWhenAsked)
{
    if (!has_shared_recording()) return;
    // Branches only: the tips reach the lobe surface, so leaves there cover much of the lobe.
    RenderContent bare;
    bare.leaves = false;
    const RenderScene tree = tree_scene(bare);
    RenderContent all = bare;
    all.lobes = all.strokes = true;
    RenderScene sketch = tree_scene(all);
    sketch.ground_area = scene_bounds(tree);
    const Camera camera = camera_for(tree, front_view());
    const RgbaImage plain = draw(tree, camera);
    const RgbaImage with_sketch = draw(sketch, camera);
    EXPECT_GT(coverage(with_sketch, plain), 0.02);
    // Stroke tubes are orange: strongly red, little blue.
    std::size_t orange = 0;
    for (std::size_t i = 0; i < with_sketch.pixels.size(); i += 4)
        orange += with_sketch.pixels[i] > 170 && with_sketch.pixels[i + 2] < 90 && with_sketch.pixels[i + 1] > 80;
    EXPECT_GT(orange, 20u);
}

TEST(RenderScene, UnchangedMeshesStayOnTheGpuAndOnlyChangedOnesAreUploaded)
{
    if (!has_shared_recording()) return;
    Renderer& r = *shared().renderer;
    RenderContent content;
    const RenderScene lod0 = tree_scene(content);
    r.set_scene(RenderScene{});
    r.set_scene(lod0);
    EXPECT_EQ(r.stats().meshes_uploaded, 2u); // branches and leaves
    EXPECT_GT(r.stats().bytes_uploaded, 0u);
    r.set_scene(lod0);
    EXPECT_EQ(r.stats().meshes_uploaded, 0u);
    EXPECT_EQ(r.stats().meshes_kept, 2u);
    EXPECT_EQ(r.stats().bytes_uploaded, 0u);
    // Adding the lobes uploads only the lobes.
    content.lobes = true;
    const RenderScene with_lobes = tree_scene(content);
    r.set_scene(with_lobes);
    EXPECT_EQ(r.stats().meshes_kept, 2u);
    EXPECT_EQ(r.stats().meshes_uploaded, with_lobes.items.size() - 2u);
    // A changed mesh under the same key is uploaded again.
    RenderScene moved = lod0;
    moved.items[0].geometry.positions[0].x += 0.01f;
    moved.items[0].version += 1;
    r.set_scene(moved);
    EXPECT_EQ(r.stats().meshes_uploaded, 1u);
    EXPECT_EQ(r.stats().meshes_kept, 1u);
}

/// How two pictures of the same size differ: pixels with any channel different, and the
/// largest channel difference.
struct PictureDifference {
    std::size_t pixels = 0;
    int max_channel = 0;
    std::string describe() const
    {
        return std::to_string(pixels) + " pixel(s) differ, by at most " + std::to_string(max_channel) + " of 255";
    }
};

PictureDifference difference(const RgbaImage& a, const RgbaImage& b)
{
    PictureDifference d;
    EXPECT_EQ(a.pixels.size(), b.pixels.size());
    for (std::size_t i = 0; i + 3 < std::min(a.pixels.size(), b.pixels.size()); i += 4) {
        int m = 0;
        for (std::size_t k = 0; k < 3; ++k) m = std::max(m, std::abs(int(a.pixels[i + k]) - int(b.pixels[i + k])));
        d.pixels += m > 0;
        d.max_channel = std::max(d.max_channel, m);
    }
    return d;
}

/// The leaf item of a tree scene.
const RenderItem& leaf_item(const RenderScene& scene)
{
    for (const RenderItem& item : scene.items)
        if (item.material == RenderMaterial::Leaf) return item;
    ADD_FAILURE() << "no leaf item";
    return scene.items.front();
}

// The rendering issue's "leaves instanced": growth/leaves.cpp's quads are drawn as one
// instance each over a shared quad, and the picture is the one the same leaves give drawn as
// plain triangles. Only rounding differs: the quad's fourth corner is computed on the GPU.
TEST(RenderLeaves, InstancedLeavesDrawTheSamePictureAsTheLeafTriangles)
{
    if (!has_shared_recording()) return;
    struct Case {
        int lod;
        ViewAngles view;
        const char* name;
    };
    const Case cases[] = {{0, front_view(), "lod0_front"}, {0, side_view(), "lod0_side"}, {2, front_view(), "lod2_front"}};
    for (const Case& c : cases) {
        RenderContent content;
        content.lod = c.lod;
        const RenderScene scene = tree_scene(content);
        const Camera camera = camera_for(scene, c.view);
        const RgbaImage instanced = draw(scene, camera);
        const std::size_t quads = leaf_item(scene).geometry.triangle_count() / 2;
        ASSERT_GT(quads, 100u);
        EXPECT_EQ(shared().renderer->stats().leaf_instances, quads) << c.name;
        const RgbaImage reference = draw_reference(scene, camera);
        const PictureDifference d = difference(instanced, reference);
        // Near identity: a handful of edge samples may fall the other way.
        EXPECT_LE(d.pixels, std::size_t(kW * kH) / 1000) << c.name << ": " << d.describe();
        EXPECT_LE(d.max_channel, 64) << c.name << ": " << d.describe();
        RecordProperty(std::string("difference_") + c.name, d.describe());
        std::printf("instanced vs triangles, %s: %s (of %d)\n", c.name, d.describe().c_str(), kW * kH);
    }
}

// GPU memory: 48 bytes per leaf (and 56 for the shared quad) instead of 4 vertices of 32
// bytes and 2 triangles of 12.
TEST(RenderLeaves, InstancedLeavesUploadAThirdOfTheBytes)
{
    if (!has_shared_recording()) return;
    RenderContent content;
    content.tree = false;
    const RenderScene leaves = tree_scene(content);
    RenderScene texture_only = leaves;
    texture_only.items.clear();
    const std::size_t quads = leaf_item(leaves).geometry.triangle_count() / 2;
    auto leaf_bytes = [&](Renderer& r) {
        r.set_scene(texture_only); // the texture first: the next call uploads only the leaves
        r.set_scene(leaves);
        EXPECT_EQ(r.stats().meshes_uploaded, 1u);
        return r.stats().bytes_uploaded;
    };
    const std::size_t instanced = leaf_bytes(*shared().renderer), triangles = leaf_bytes(reference_renderer());
    EXPECT_EQ(instanced, 56 + 48 * quads);
    EXPECT_EQ(triangles, 152 * quads);
    RecordProperty("leaf_bytes", std::to_string(quads) + " leaves: " + std::to_string(triangles) + " bytes as triangles, " +
                                     std::to_string(instanced) + " instanced");
    std::printf("%zu leaves: %zu bytes as triangles, %zu instanced\n", quads, triangles, instanced);
    // The same leaves again under the same version: nothing is uploaded.
    shared().renderer->set_scene(leaves);
    EXPECT_EQ(shared().renderer->stats().bytes_uploaded, 0u);
    EXPECT_EQ(shared().renderer->stats().leaf_instances, quads);
}

// Leaf meshes that are not leaves.cpp's quads are drawn as meshes, as before: the pictures
// are byte for byte those of the renderer that draws every leaf mesh as triangles.
TEST(RenderLeaves, LeafMeshesThatAreNotLeafQuadsAreDrawnAsMeshes)
{
    if (!has_shared_recording()) return;
    const RenderScene tree = tree_scene();
    const Camera camera = camera_for(tree, front_view());
    const std::size_t leaf_index = std::size_t(&leaf_item(tree) - tree.items.data());
    std::vector<std::pair<std::string, RenderScene>> variants;
    auto variant = [&](const std::string& name, const std::function<void(SurfaceGeometry&)>& change) {
        RenderScene s = tree;
        s.items[leaf_index].version += 1 + variants.size(); // a version of its own: uploaded
        change(s.items[leaf_index].geometry);
        variants.emplace_back(name, std::move(s));
    };
    variant("an extra triangle", [](SurfaceGeometry& g) { g.triangles.push_back({0, 2, 3}); });
    variant("a quad split along its other diagonal", [](SurfaceGeometry& g) {
        g.triangles[10] = {20, 21, 23};
        g.triangles[11] = {21, 22, 23};
    });
    variant("a quad that is not a parallelogram", [](SurfaceGeometry& g) { g.positions[42] += glm::vec3(0.0f, 0.01f, 0.0f); });
    variant("a quad with other uvs", [](SurfaceGeometry& g) { g.uvs[9] = glm::vec2(0.5f, 0.5f); });
    variant("a vertex with its own normal", [](SurfaceGeometry& g) { g.normals[6] = glm::normalize(g.normals[6] + glm::vec3(0.1f, 0.0f, 0.0f)); });
    variant("the triangles in another order", [](SurfaceGeometry& g) { std::reverse(g.triangles.begin(), g.triangles.end()); });
    // An arbitrary triangle mesh: the stroke tubes, with uvs inside the leaf's blade.
    {
        RenderScene s = tree;
        SurfaceGeometry tubes;
        for (const Stroke& stroke : effective_strokes(shared().doc)) {
            std::vector<glm::vec3> points;
            for (const StrokePoint& p : stroke.points) points.push_back(p.position);
            const SurfaceGeometry tube = polyline_tube(points, 0.02f);
            const auto first = static_cast<std::uint32_t>(tubes.positions.size());
            tubes.positions.insert(tubes.positions.end(), tube.positions.begin(), tube.positions.end());
            tubes.normals.insert(tubes.normals.end(), tube.normals.begin(), tube.normals.end());
            for (const auto& t : tube.triangles) tubes.triangles.push_back({t[0] + first, t[1] + first, t[2] + first});
        }
        tubes.uvs.assign(tubes.positions.size(), glm::vec2(0.5f, 0.5f));
        ASSERT_FALSE(tubes.empty());
        s.items[leaf_index].geometry = tubes;
        s.items[leaf_index].version += 1 + variants.size();
        variants.emplace_back("stroke tubes as a leaf mesh", std::move(s));
    }
    const RgbaImage background = background_of(tree, camera);
    shared().renderer->set_scene(tree); // the branches stay cached: each variant uploads its leaves only
    for (const auto& [name, scene] : variants) {
        const RgbaImage picture = draw(scene, camera);
        EXPECT_EQ(shared().renderer->stats().leaf_instances, 0u) << name;
        EXPECT_EQ(shared().renderer->stats().meshes_uploaded, 1u) << name;
        const RgbaImage reference = draw_reference(scene, camera);
        EXPECT_EQ(picture.pixels, reference.pixels) << name << ": " << difference(picture, reference).describe();
        EXPECT_GT(coverage(picture, background), 0.05) << name;
    }
}

// An instanced leaf mesh given another material under the same key and version is uploaded
// again, as a mesh (instances are drawn by the leaf pipeline only), and looks as it does
// from the reference renderer.
TEST(RenderLeaves, AnInstancedMeshGivenAnotherMaterialIsUploadedAgainAsAMesh)
{
    if (!has_shared_recording()) return;
    RenderScene scene = tree_scene();
    const Camera camera = camera_for(scene, front_view());
    Renderer& r = *shared().renderer;
    r.set_scene(scene);
    EXPECT_GT(r.stats().leaf_instances, 0u);
    RenderItem& leaves = scene.items[std::size_t(&leaf_item(scene) - scene.items.data())];
    leaves.material = RenderMaterial::Bark;
    r.set_scene(scene);
    EXPECT_EQ(r.stats().leaf_instances, 0u);
    EXPECT_EQ(r.stats().meshes_uploaded, 1u);
    const RgbaImage picture = r.render(camera, kW, kH);
    EXPECT_EQ(picture.pixels, draw_reference(scene, camera).pixels);
    // Back to Leaf: instanced again.
    leaves.material = RenderMaterial::Leaf;
    leaves.version += 1;
    r.set_scene(scene);
    EXPECT_EQ(r.stats().leaf_instances, leaves.geometry.triangle_count() / 2);
}

// A tree exported to .glb and read back keeps its leaves as quads: they are drawn instanced.
TEST(RenderLeaves, LeavesReadFromAnExportedGlbAreDrawnInstanced)
{
    if (!has_shared_recording()) return;
    Shared& s = shared();
    const std::string dir = test::temp_dir("render-leaves-glb");
    ExportScene e;
    e.tree = &s.geometry;
    e.base = s.tree.growth.tree.nodes[0].position;
    write_glb(dir + "/tree.glb", e);
    const RenderScene scene = glb_render_scene(dir + "/tree.glb", RenderContent{});
    const std::size_t quads = leaf_item(scene).geometry.triangle_count() / 2;
    ASSERT_GT(quads, 0u);
    s.renderer->set_scene(scene);
    EXPECT_EQ(s.renderer->stats().leaf_instances, quads);
    const Camera camera = camera_for(scene, front_view());
    const PictureDifference d = difference(s.renderer->render(camera, kW, kH), draw_reference(scene, camera));
    EXPECT_LE(d.pixels, std::size_t(kW * kH) / 1000) << d.describe();
    std::printf("instanced vs triangles, from a .glb: %s (of %d)\n", d.describe().c_str(), kW * kH);
}

TEST(RenderScene, BadMeshesAndSizesAreRefusedWithOneLine)
{
    if (!has_shared_recording()) return;
    Renderer& r = *shared().renderer;
    RenderScene scene;
    RenderItem item;
    item.key = 7;
    item.geometry.positions = {glm::vec3(0), glm::vec3(1, 0, 0), glm::vec3(0, 1, 0)};
    item.geometry.normals = item.geometry.positions;
    item.geometry.triangles = {{0, 1, 3}};
    scene.items.push_back(item);
    EXPECT_THROW(r.set_scene(scene), InvalidInput);
    scene.items[0].geometry.triangles = {{0, 1, 2}};
    scene.items.push_back(scene.items[0]);
    EXPECT_THROW(r.set_scene(scene), InvalidInput); // key 7 twice
    EXPECT_THROW(r.render(Camera{}, 0, 10), InvalidInput);
    EXPECT_THROW(parse_show_list("tree,bark"), InvalidInput);
    EXPECT_THROW(parse_show_list(""), InvalidInput);
}

TEST(RenderScene, FramingKeepsEveryCornerOfTheBoxInsideThePicture)
{
    Bounds b{glm::vec3(-0.3f, 1.0f, -0.2f), glm::vec3(0.4f, 1.6f, 0.25f)};
    for (const ViewAngles& v : {front_view(), side_view(), top_view(), ViewAngles{37.0f, 15.0f}}) {
        const Camera c = frame_view(b, v, 4.0f / 3.0f);
        const glm::vec3 f = glm::normalize(c.target - c.eye), right = glm::normalize(glm::cross(f, c.up)),
                        up = glm::cross(right, f);
        const float ty = std::tan(glm::radians(c.fov_y_deg) / 2), tx = ty * 4.0f / 3.0f;
        float widest = 0.0f;
        for (int i = 0; i < 8; ++i) {
            const glm::vec3 p((i & 1) ? b.hi.x : b.lo.x, (i & 2) ? b.hi.y : b.lo.y, (i & 4) ? b.hi.z : b.lo.z);
            const glm::vec3 d = p - c.eye;
            const float z = glm::dot(d, f);
            ASSERT_GT(z, c.near_m);
            const float x = std::abs(glm::dot(d, right)) / (z * tx), y = std::abs(glm::dot(d, up)) / (z * ty);
            EXPECT_LE(x, 1.0f);
            EXPECT_LE(y, 1.0f);
            widest = std::max({widest, x, y});
        }
        EXPECT_GT(widest, 0.8f) << "the box fills the frame on one axis";
    }
    // Front looks along -Z, side along -X, top down -Y.
    EXPECT_NEAR(glm::normalize(frame_view(b, front_view(), 1.0f).target - frame_view(b, front_view(), 1.0f).eye).z, -1.0f, 1e-5f);
    EXPECT_NEAR(glm::normalize(frame_view(b, side_view(), 1.0f).target - frame_view(b, side_view(), 1.0f).eye).x, -1.0f, 1e-5f);
    EXPECT_NEAR(glm::normalize(frame_view(b, top_view(), 1.0f).target - frame_view(b, top_view(), 1.0f).eye).y, -1.0f, 1e-5f);
}

// --- the 2D overlay and presenting to a window ---------------------------------------------------

constexpr int kOw = 64, kOh = 48; // overlay pictures: small, the overlay is all they test

/// IM_COL32's layout: bytes R, G, B, A in memory.
constexpr std::uint32_t rgba32(std::uint32_t r, std::uint32_t g, std::uint32_t b, std::uint32_t a)
{
    return r | g << 8 | b << 16 | a << 24;
}

/// Appends a rectangle [x0, x1) × [y0, y1) as two triangles with its own command.
void add_quad(Overlay& o, float x0, float y0, float x1, float y1, std::uint32_t color, std::array<float, 4> clip = {0, 0, 1e6f, 1e6f},
              float u = 0.0f, float v = 0.0f)
{
    const auto first = static_cast<std::uint32_t>(o.indices.size());
    const auto base = static_cast<std::int32_t>(o.vertices.size());
    for (const auto& [x, y] : {std::pair{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}}) o.vertices.push_back({x, y, u, v, color});
    for (std::uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) o.indices.push_back(i); // relative to the command's vertex_offset
    OverlayCommand c;
    c.first_index = first;
    c.index_count = 6;
    c.vertex_offset = base;
    std::copy(clip.begin(), clip.end(), c.clip);
    o.commands.push_back(c);
}

/// Sky and ground only, and a camera for them.
struct OverlayFixture {
    RenderScene scene;
    Camera camera = frame_view(Bounds{glm::vec3(-0.5f), glm::vec3(0.5f)}, front_view(), float(kOw) / float(kOh));
    RgbaImage background; // with no overlay
    OverlayFixture()
    {
        Renderer& r = *shared().renderer;
        r.set_overlay(Overlay{});
        r.set_scene(scene);
        background = r.render(camera, kOw, kOh);
    }
    ~OverlayFixture() { shared().renderer->set_overlay(Overlay{}); } // the other tests draw none
    RgbaImage with(const Overlay& overlay) const
    {
        Renderer& r = *shared().renderer;
        r.set_overlay(overlay);
        return r.render(camera, kOw, kOh);
    }
};

const std::uint8_t* pixel(const RgbaImage& im, int x, int y) { return &im.pixels[(std::size_t(y) * std::size_t(im.width) + std::size_t(x)) * 4]; }

std::uint8_t linear_to_srgb(double c)
{
    c = std::clamp(c, 0.0, 1.0);
    const double e = c <= 0.0031308 ? c * 12.92 : 1.055 * std::pow(c, 1.0 / 2.4) - 0.055;
    return static_cast<std::uint8_t>(std::lround(e * 255.0));
}

/// Pixels inside [x0, x1) × [y0, y1) are checked by `inside`; every other one must equal the
/// background's bytes. Returns how many pixels differ from the background.
template <class Inside>
std::size_t check_rect(const RgbaImage& picture, const RgbaImage& background, int x0, int y0, int x1, int y1, Inside inside)
{
    std::size_t changed = 0;
    for (int y = 0; y < picture.height; ++y)
        for (int x = 0; x < picture.width; ++x) {
            const std::uint8_t* p = pixel(picture, x, y);
            const std::uint8_t* b = pixel(background, x, y);
            changed += !std::equal(p, p + 4, b);
            if (x >= x0 && x < x1 && y >= y0 && y < y1)
                inside(p, b, x, y);
            else
                EXPECT_TRUE(std::equal(p, p + 4, b)) << "pixel " << x << "," << y << " outside the rectangle changed";
        }
    return changed;
}

TEST(RenderOverlay, AnOpaqueQuadKeepsItsSrgbColourAndNoPixelOutsideItChanges)
{
    if (!has_shared_recording()) return;
    OverlayFixture f;
    Overlay o;
    add_quad(o, 10, 8, 30, 24, rgba32(200, 40, 40, 255));
    const RgbaImage picture = f.with(o);
    ASSERT_EQ(picture.width, kOw);
    ASSERT_EQ(picture.height, kOh);
    const std::size_t changed = check_rect(picture, f.background, 10, 8, 30, 24, [](const std::uint8_t* p, const std::uint8_t*, int x, int y) {
        EXPECT_NEAR(int(p[0]), 200, 1) << x << "," << y;
        EXPECT_NEAR(int(p[1]), 40, 1) << x << "," << y;
        EXPECT_NEAR(int(p[2]), 40, 1) << x << "," << y;
        EXPECT_EQ(int(p[3]), 255);
    });
    EXPECT_EQ(changed, 20u * 16u);
}

TEST(RenderOverlay, AHalfTransparentQuadBlendsWithTheSceneInLinearLight)
{
    if (!has_shared_recording()) return;
    OverlayFixture f;
    Overlay o;
    add_quad(o, 4, 20, 60, 44, rgba32(200, 40, 40, 128)); // over sky and ground
    const RgbaImage picture = f.with(o);
    const double a = 128.0 / 255.0;
    const int colour[3] = {200, 40, 40};
    check_rect(picture, f.background, 4, 20, 60, 44, [&](const std::uint8_t* p, const std::uint8_t* b, int x, int y) {
        for (int c = 0; c < 3; ++c) {
            const int expected = linear_to_srgb(a * srgb_to_linear(std::uint8_t(colour[c])) + (1.0 - a) * srgb_to_linear(b[c]));
            EXPECT_NEAR(int(p[c]), expected, 2) << "channel " << c << " at " << x << "," << y;
        }
    });
}

/// Two commands: an off-screen quad with a clip far beyond the frame (clamped), and a quad
/// over [10, 30) × [8, 24) read through vertex_offset 4 and clipped to x 15..20, y 10..40.
Overlay clipped_overlay()
{
    Overlay o;
    add_quad(o, -100, -100, -50, -50, rgba32(0, 0, 255, 255), {-1e9f, -1e9f, 1e9f, 1e9f});
    add_quad(o, 10, 8, 30, 24, rgba32(20, 220, 60, 255), {15, 10, 20, 40});
    return o;
}
constexpr int kClipX0 = 15, kClipY0 = 10, kClipX1 = 20, kClipY1 = 24; // the drawn pixels

void expect_clip_colour(const std::uint8_t* p, int x, int y)
{
    EXPECT_NEAR(int(p[0]), 20, 1) << x << "," << y;
    EXPECT_NEAR(int(p[1]), 220, 1) << x << "," << y;
    EXPECT_NEAR(int(p[2]), 60, 1) << x << "," << y;
}

TEST(RenderOverlay, EachCommandIsClippedToItsScissorRectangleAndUsesItsVertexOffset)
{
    if (!has_shared_recording()) return;
    // Single-sampled, the scissor is exact: lavapipe (Mesa 22.3) lets the samples of the pixel
    // row and column just outside a scissor's top and left edges through with 4x MSAA.
    RendererOptions options;
    options.samples = 1;
    Renderer r(options);
    const OverlayFixture f;
    r.set_scene(f.scene);
    const RgbaImage background = r.render(f.camera, kOw, kOh);
    const Overlay o = clipped_overlay();
    ASSERT_EQ(o.commands[1].vertex_offset, 4);
    r.set_overlay(o);
    const RgbaImage picture = r.render(f.camera, kOw, kOh);
    const std::size_t changed = check_rect(picture, background, kClipX0, kClipY0, kClipX1, kClipY1,
                                           [](const std::uint8_t* p, const std::uint8_t*, int x, int y) { expect_clip_colour(p, x, y); });
    EXPECT_EQ(changed, std::size_t(kClipX1 - kClipX0) * std::size_t(kClipY1 - kClipY0));
    // A clip rectangle that misses the frame draws nothing.
    Overlay outside;
    add_quad(outside, 0, 0, kOw, kOh, rgba32(255, 255, 255, 255), {float(kOw), 0, float(kOw) + 10, float(kOh)});
    r.set_overlay(outside);
    EXPECT_EQ(r.render(f.camera, kOw, kOh).pixels, background.pixels);
}

TEST(RenderOverlay, WithMultisamplingTheScissorHoldsToWithinOnePixelOfItsEdges)
{
    if (!has_shared_recording()) return;
    OverlayFixture f;
    const RgbaImage picture = f.with(clipped_overlay());
    std::size_t changed = 0;
    for (int y = 0; y < kOh; ++y)
        for (int x = 0; x < kOw; ++x) {
            const std::uint8_t* p = pixel(picture, x, y);
            const bool same = std::equal(p, p + 4, pixel(f.background, x, y));
            changed += !same;
            if (x >= kClipX0 + 1 && x < kClipX1 - 1 && y >= kClipY0 + 1 && y < kClipY1 - 1) {
                expect_clip_colour(p, x, y);
            } else if (x < kClipX0 - 1 || x > kClipX1 || y < kClipY0 - 1 || y > kClipY1) {
                EXPECT_TRUE(same) << "pixel " << x << "," << y << " well outside the clip changed";
            }
        }
    EXPECT_GE(changed, std::size_t(kClipX1 - kClipX0 - 2) * std::size_t(kClipY1 - kClipY0 - 2));
    EXPECT_LE(changed, std::size_t(kClipX1 - kClipX0 + 2) * std::size_t(kClipY1 - kClipY0 + 2));
}

TEST(RenderOverlay, OutOfRangeIndicesAndBadFontsAreRefusedWithOneLineAndThePreviousOverlayStays)
{
    if (!has_shared_recording()) return;
    OverlayFixture f;
    Overlay good;
    add_quad(good, 10, 8, 30, 24, rgba32(200, 40, 40, 255));
    const RgbaImage before = f.with(good);
    ASSERT_NE(before.pixels, f.background.pixels);

    std::vector<Overlay> bad(5, good);
    bad[0].indices[2] = 4;                  // index 4 of 4 vertices
    bad[1].commands[0].index_count = 7;     // past the 6 indices
    bad[2].commands[0].vertex_offset = -1;  // index 0 - 1
    bad[3].commands[0].clip[2] = std::nanf("");
    bad[4].font = RgbaImage{2, 2, std::vector<std::uint8_t>(15, 255)}; // 15 bytes, not 16
    Renderer& r = *shared().renderer;
    for (std::size_t i = 0; i < bad.size(); ++i) {
        try {
            r.set_overlay(bad[i]);
            ADD_FAILURE() << "bad overlay " << i << " was accepted";
        } catch (const InvalidInput& e) {
            const std::string what = e.what();
            EXPECT_EQ(what.find('\n'), std::string::npos) << what;
            EXPECT_NE(what.find("overlay"), std::string::npos) << what;
        }
    }
    EXPECT_EQ(r.render(f.camera, kOw, kOh).pixels, before.pixels) << "the good overlay is still drawn";
}

TEST(RenderOverlay, TheFontIsSampledAndUploadedAgainOnlyWhenItsVersionChanges)
{
    if (!has_shared_recording()) return;
    OverlayFixture f;
    // Texel 0 opaque white, texel 1 transparent; the quad samples the centre of texel 1.
    Overlay o;
    o.font = RgbaImage{2, 1, {255, 255, 255, 255, 0, 0, 0, 0}};
    o.font_version = 1;
    add_quad(o, 10, 8, 30, 24, rgba32(200, 40, 40, 255), {0, 0, 1e6f, 1e6f}, 0.75f, 0.5f);
    EXPECT_EQ(f.with(o).pixels, f.background.pixels) << "a transparent texel hides the quad";
    // The same version with other pixels is not uploaded again: still transparent.
    Overlay same = o;
    same.font.pixels = {255, 255, 255, 255, 255, 255, 255, 255};
    EXPECT_EQ(f.with(same).pixels, f.background.pixels);
    // A new version is.
    same.font_version = 2;
    const RgbaImage shown = f.with(same);
    EXPECT_NEAR(int(pixel(shown, 20, 16)[0]), 200, 1);
    EXPECT_NEAR(int(pixel(shown, 20, 16)[1]), 40, 1);
    // The empty font is one white texel, whatever the version.
    Overlay white = o;
    white.font = RgbaImage{};
    EXPECT_NEAR(int(pixel(f.with(white), 20, 16)[0]), 200, 1);
}

TEST(RenderOverlay, LastFrameReadsBackTheLastPictureWithoutDrawingAgain)
{
    if (!has_shared_recording()) return;
    Renderer& r = *shared().renderer;
    OverlayFixture f;
    Overlay o;
    add_quad(o, 10, 8, 30, 24, rgba32(200, 40, 40, 255));
    const RgbaImage picture = f.with(o);
    r.set_overlay(Overlay{}); // not drawn until the next frame
    const RgbaImage again = r.last_frame();
    EXPECT_EQ(again.width, kOw);
    EXPECT_EQ(again.height, kOh);
    EXPECT_EQ(again.pixels, picture.pixels);
}

TEST(RenderWindow, PresentationOptionsAndAttachWindowFailClearlyWithoutADisplay)
{
    if (!has_shared_recording()) return;
    RendererOptions unknown;
    unknown.instance_extensions = {"VK_LOBE_no_such_extension"};
    try {
        Renderer r(unknown);
        ADD_FAILURE() << "an unknown instance extension was accepted";
    } catch (const RenderUnavailable& e) {
        EXPECT_NE(std::string(e.what()).find("VK_LOBE_no_such_extension"), std::string::npos) << e.what();
    }
    // Without presentation, and before a window, the window calls are refused; the callback is
    // never called.
    Renderer& plain = *shared().renderer;
    bool called = false;
    EXPECT_THROW(plain.attach_window([&](std::uint64_t) { return called = true, std::uint64_t(0); }), RenderError);
    EXPECT_FALSE(called);
    EXPECT_THROW(plain.present(Camera{}, kOw, kOh), RenderError);
    // With presentation (lavapipe has VK_KHR_swapchain) and VK_KHR_surface, a callback that
    // makes no surface is refused; it got a Vulkan instance.
    RendererOptions options;
    options.presentation = true;
    options.instance_extensions = {"VK_KHR_surface"};
    Renderer presenting(options);
    EXPECT_TRUE(presenting.last_frame().pixels.empty()) << "no frame yet";
    std::uint64_t instance = 0;
    EXPECT_THROW(presenting.attach_window([&](std::uint64_t vk_instance) { return instance = vk_instance, std::uint64_t(0); }), RenderError);
    EXPECT_NE(instance, 0u);
    EXPECT_THROW(presenting.present(Camera{}, kOw, kOh), RenderError);
}

/// The pixels an X11 window shows (RGBA, alpha 255), read with XGetImage through the GLFW
/// library's glfwGetX11Display/glfwGetX11Window and libX11.so.6, loaded at run time; empty
/// when either or the X11 headers are missing (defined at the end of this file, apart from
/// Xlib's macros).
RgbaImage read_x11_window(void* glfw_library, void* glfw_window, int width, int height);

/// GLFW 3, loaded at run time (the suite does not link it): what the window test needs.
struct Glfw {
    void* lib = nullptr;
    int (*init)() = nullptr;
    void (*terminate)() = nullptr;
    void (*window_hint)(int, int) = nullptr;
    void* (*create_window)(int, int, const char*, void*, void*) = nullptr;
    void (*destroy_window)(void*) = nullptr;
    const char** (*required_extensions)(std::uint32_t*) = nullptr;
    int (*create_surface)(void*, void*, const void*, std::uint64_t*) = nullptr; // VkResult (VkInstance, GLFWwindow*, allocator, VkSurfaceKHR*)
    void (*framebuffer_size)(void*, int*, int*) = nullptr;
    void (*set_window_size)(void*, int, int) = nullptr;
    void (*poll_events)() = nullptr;
    static constexpr int kClientApi = 0x00022001, kNoApi = 0;

    bool load()
    {
        lib = dlopen("libglfw.so.3", RTLD_NOW | RTLD_LOCAL); // never closed: X11 keeps state in it
        if (!lib) return false;
        auto get = [&](auto& fn, const char* name) {
            fn = reinterpret_cast<std::remove_reference_t<decltype(fn)>>(dlsym(lib, name));
            return fn != nullptr;
        };
        return get(init, "glfwInit") && get(terminate, "glfwTerminate") && get(window_hint, "glfwWindowHint") &&
               get(create_window, "glfwCreateWindow") && get(destroy_window, "glfwDestroyWindow") &&
               get(required_extensions, "glfwGetRequiredInstanceExtensions") && get(create_surface, "glfwCreateWindowSurface") &&
               get(framebuffer_size, "glfwGetFramebufferSize") && get(set_window_size, "glfwSetWindowSize") &&
               get(poll_events, "glfwPollEvents");
    }
};

// Needs an X server (xvfb-run) and libglfw.so.3 at run time; skipped otherwise.
TEST(RenderWindow, PresentShowsTheFrameRenderDrawsAndFollowsAResize)
{
    if (!std::getenv("DISPLAY") || !*std::getenv("DISPLAY")) GTEST_SKIP() << "DISPLAY is unset: presenting needs an X server (xvfb-run)";
    Glfw glfw;
    if (!glfw.load()) GTEST_SKIP() << "libglfw.so.3 (package libglfw3) is not installed";
    if (!has_shared_recording()) return;
    ASSERT_TRUE(glfw.init()) << "glfwInit failed on DISPLAY=" << std::getenv("DISPLAY");
    glfw.window_hint(Glfw::kClientApi, Glfw::kNoApi);
    void* window = glfw.create_window(kOw, kOh, "lobesketch render test", nullptr, nullptr);
    ASSERT_NE(window, nullptr);
    {
        std::uint32_t n = 0;
        const char** names = glfw.required_extensions(&n);
        ASSERT_NE(names, nullptr) << "GLFW finds no Vulkan loader";
        RendererOptions options;
        options.presentation = true;
        options.instance_extensions.assign(names, names + n);
        Renderer r(options);
        r.attach_window([&](std::uint64_t instance) {
            std::uint64_t surface = 0;
            return glfw.create_surface(reinterpret_cast<void*>(instance), window, nullptr, &surface) == 0 ? surface : 0;
        });
        OverlayFixture f; // sky, ground and a camera
        r.set_scene(f.scene);
        Overlay o;
        add_quad(o, 10, 8, 30, 24, rgba32(200, 40, 40, 255));
        r.set_overlay(o);
        int w = 0, h = 0;
        glfw.framebuffer_size(window, &w, &h);
        ASSERT_EQ(w, kOw);
        ASSERT_EQ(h, kOh);
        for (int frame = 0; frame < 3; ++frame) ASSERT_TRUE(r.present(f.camera, w, h)) << "frame " << frame;
        EXPECT_GT(r.stats().gpu_ms, 0.0);
        const RgbaImage presented = r.last_frame();
        const RgbaImage rendered = r.render(f.camera, w, h);
        EXPECT_EQ(presented.pixels, rendered.pixels) << "present draws what render draws";
        // What the window shows (Xvfb has no compositor: the window's pixels are the screen's).
        const RgbaImage shown = read_x11_window(glfw.lib, window, w, h);
        if (shown.pixels.empty()) {
            std::printf("RenderWindow: not comparing the X window's pixels (no X11 headers, libX11 or GLFW X11 functions)\n");
        } else {
            EXPECT_EQ(shown.pixels, presented.pixels) << "the window shows the presented frame";
        }
        EXPECT_NEAR(int(pixel(presented, 20, 16)[0]), 200, 1) << "with the overlay";
        EXPECT_FALSE(r.present(f.camera, 0, 0)) << "minimised: nothing drawn";
        EXPECT_EQ(r.last_frame().pixels, rendered.pixels);
        // A new size remakes the swapchain and the frame.
        glfw.set_window_size(window, 80, 60);
        for (int i = 0; i < 50 && (w != 80 || h != 60); ++i) {
            glfw.poll_events();
            glfw.framebuffer_size(window, &w, &h);
        }
        ASSERT_EQ(w, 80);
        ASSERT_EQ(h, 60);
        for (int frame = 0; frame < 2; ++frame) ASSERT_TRUE(r.present(f.camera, w, h)) << "frame " << frame << " after the resize";
        const RgbaImage resized = r.last_frame();
        EXPECT_EQ(resized.width, 80);
        EXPECT_EQ(resized.height, 60);
        const RgbaImage shown_resized = read_x11_window(glfw.lib, window, 80, 60);
        if (!shown_resized.pixels.empty()) {
            EXPECT_EQ(shown_resized.pixels, resized.pixels) << "the window shows the resized frame";
        }
        // A frame of another size than the window's is scaled into it.
        EXPECT_TRUE(r.present(f.camera, 40, 30));
        EXPECT_EQ(r.last_frame().width, 40);
    } // the renderer (and the surface) before the window
    glfw.destroy_window(window);
    glfw.terminate();
}

// --- the command line -------------------------------------------------------------------------

using test::CliRun;
using test::run_cli;

std::size_t count(const std::string& text, const std::string& needle)
{
    std::size_t n = 0;
    for (std::size_t pos = text.find(needle); pos != std::string::npos; pos = text.find(needle, pos + 1)) ++n;
    return n;
}

/// Width and height from a PNG's IHDR chunk; {0, 0} when it is not a PNG.
std::pair<int, int> png_size(const std::string& path)
{
    std::ifstream in(path, std::ios::binary);
    std::string head(24, '\0');
    in.read(head.data(), 24);
    if (in.gcount() != 24 || head.compare(0, 8, "\x89PNG\r\n\x1a\n") != 0) return {0, 0};
    auto be = [&](std::size_t o) {
        return int(std::uint8_t(head[o])) << 24 | int(std::uint8_t(head[o + 1])) << 16 | int(std::uint8_t(head[o + 2])) << 8 |
               int(std::uint8_t(head[o + 3]));
    };
    return {be(16), be(20)};
}

TEST(RenderCli, RendersAGlbMadeByGrowAndARecordingFromFrontSideAndOrbit)
{
    const std::string out = test::temp_dir("render-cli");
    const std::string recording = rec("table1-1lobe-5strokes");
    if (recording.empty()) return;
    ASSERT_EQ(run_cli("grow " + recording + " --out " + out + "/tree.glb --lobes --strokes").code, 0);
    const CliRun glb = run_cli("render " + out + "/tree.glb --out " + out + "/glb.png --size 192x144 --show tree,leaves,lobes,strokes");
    ASSERT_EQ(glb.code, 0) << glb.out;
    EXPECT_EQ(png_size(out + "/glb.png"), std::make_pair(192, 144));
    const CliRun side = run_cli("render " + recording + " --out " + out + "/side.png --view side --size 160x120 --lod 1");
    ASSERT_EQ(side.code, 0) << side.out;
    EXPECT_EQ(png_size(out + "/side.png"), std::make_pair(160, 120));
    const CliRun orbit = run_cli("render " + out + "/tree.glb --out " + out + "/spin.png --view orbit --frames 3 --size 64x48");
    ASSERT_EQ(orbit.code, 0) << orbit.out;
    for (const char* f : {"spin_000.png", "spin_001.png", "spin_002.png"}) EXPECT_EQ(png_size(out + "/" + f), std::make_pair(64, 48)) << f;
    EXPECT_FALSE(fs::exists(out + "/spin_003.png"));
}

TEST(RenderCli, BadOptionsGiveOneLineAndExitCodes)
{
    const std::string out = test::temp_dir("render-bad");
    const std::string r = rec("table1-1lobe-5strokes");
    if (r.empty()) return;
    struct Case {
        std::string args, expect;
        int code;
    };
    const Case cases[] = {
        {"render " + r + " --out " + out + "/x.png --size 10x10", "expected WxH with each side 16 to 8192", 2},
        {"render " + r + " --out " + out + "/x.png --size 1280by720", "expected WxH", 2},
        {"render " + r + " --out " + out + "/x.png --size 9000x100", "expected WxH", 2},
        {"render " + r + " --out " + out + "/x.png --show tree,bark", "unknown item 'bark'", 2},
        {"render " + r + " --out " + out + "/x.png --view diagonal", "--view", 2},
        {"render " + r + " --out " + out + "/x.jpg", "written as .png", 2},
        {"render " + out + "/missing.glb --out " + out + "/x.png", "missing.glb", 1},
        {"render " + r + " --out " + out + "/x.png --lod 7", "--lod: LOD 7 does not exist", 1},
    };
    for (const Case& c : cases) {
        const CliRun run = run_cli(c.args);
        EXPECT_EQ(run.code, c.code) << c.args << "\n" << run.out;
        EXPECT_NE(run.out.find(c.expect), std::string::npos) << c.args << "\n" << run.out;
        if (c.code == 1) {
            EXPECT_EQ(count(run.out, "error:"), 1u) << run.out;
        }
    }
    EXPECT_FALSE(fs::exists(out + "/x.png"));
    EXPECT_FALSE(fs::exists(out + "/x.jpg"));
}

TEST(RenderCli, WithoutAVulkanDriverItExitsWithOneLineNamingThePackage)
{
    const std::string out = test::temp_dir("render-novk");
    const std::string recording = rec("table1-1lobe-5strokes");
    if (recording.empty()) return;
    ASSERT_EQ(run_cli("grow " + recording + " --out " + out + "/tree.glb").code, 0);
    const CliRun r = run_cli("render " + out + "/tree.glb --out " + out + "/x.png",
                             "VK_ICD_FILENAMES=" + out + "/none.json VK_DRIVER_FILES=" + out + "/none.json");
    EXPECT_EQ(r.code, 1) << r.out;
    EXPECT_EQ(count(r.out, "error:"), 1u) << r.out;
    EXPECT_NE(r.out.find("mesa-vulkan-drivers"), std::string::npos) << r.out;
    EXPECT_FALSE(fs::exists(out + "/x.png"));
}

} // namespace
} // namespace lobe

// Apart from the code above: Xlib's macros (None, Bool, Status, ...) clash with names there.
#if __has_include(<X11/Xlib.h>) && __has_include(<X11/Xutil.h>)
#include <X11/Xlib.h>
#include <X11/Xutil.h>

namespace lobe {
namespace {

RgbaImage read_x11_window(void* glfw_library, void* glfw_window, int width, int height)
{
    void* x11 = dlopen("libX11.so.6", RTLD_NOW | RTLD_LOCAL); // never closed, as GLFW
    if (!x11) return {};
    auto display_of = reinterpret_cast<Display* (*)()>(dlsym(glfw_library, "glfwGetX11Display"));
    auto window_of = reinterpret_cast<Window (*)(void*)>(dlsym(glfw_library, "glfwGetX11Window"));
    auto get_image = reinterpret_cast<decltype(&XGetImage)>(dlsym(x11, "XGetImage"));
    auto sync = reinterpret_cast<decltype(&XSync)>(dlsym(x11, "XSync"));
    if (!display_of || !window_of || !get_image || !sync || !display_of()) return {};
    Display* display = display_of();
    sync(display, False);
    XImage* image = get_image(display, window_of(glfw_window), 0, 0, unsigned(width), unsigned(height), AllPlanes, ZPixmap);
    if (!image) return {};
    RgbaImage out{width, height, std::vector<std::uint8_t>(std::size_t(width) * std::size_t(height) * 4)};
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const unsigned long v = XGetPixel(image, x, y); // 24-bit TrueColor: 0xRRGGBB
            std::uint8_t* p = &out.pixels[(std::size_t(y) * std::size_t(width) + std::size_t(x)) * 4];
            p[0] = std::uint8_t(v >> 16);
            p[1] = std::uint8_t(v >> 8);
            p[2] = std::uint8_t(v);
            p[3] = 255;
        }
    XDestroyImage(image);
    return out;
}

} // namespace
} // namespace lobe
#else
namespace lobe {
namespace {
RgbaImage read_x11_window(void*, void*, int, int) { return {}; }
} // namespace
} // namespace lobe
#endif

// --- OpenXR: the instance and device from hooks, drawing into a caller's image, photos -----------

namespace lobe {
namespace {

constexpr int kEw = 64, kEh = 64; // eye and photo pictures: small

#define LOBE_TEST_VK(call)                                                                    \
    do {                                                                                      \
        if (const VkResult r_ = (call); r_ != VK_SUCCESS)                                     \
            throw std::runtime_error(std::string(#call) + " failed with " + std::to_string(r_)); \
    } while (0)

/// A zero-initialised Vulkan info struct with its sType set.
template <class T>
T vk_info(VkStructureType type)
{
    T s{};
    s.sType = type;
    return s;
}

template <class Handle>
Handle from_integer(std::uint64_t v)
{
    if constexpr (std::is_pointer_v<Handle>)
        return reinterpret_cast<Handle>(static_cast<std::uintptr_t>(v));
    else
        return static_cast<Handle>(v);
}

template <class Handle>
std::uint64_t to_integer(Handle h)
{
    if constexpr (std::is_pointer_v<Handle>)
        return static_cast<std::uint64_t>(reinterpret_cast<std::uintptr_t>(h));
    else
        return static_cast<std::uint64_t>(h);
}

/// A colour image made on the renderer's device as an OpenXR runtime makes a swapchain image
/// (COLOR_ATTACHMENT and TRANSFER_DST usage, `layers` array layers), cleared to magenta and
/// left in COLOR_ATTACHMENT_OPTIMAL; read() copies a layer out and leaves it in that layout.
class TestImage {
public:
    TestImage(const VulkanHandles& h, VkFormat format, int width, int height, int layers = 1)
        : device_(from_integer<VkDevice>(h.device)), format_(format), width_(width), height_(height)
    {
        vkGetDeviceQueue(device_, h.queue_family, h.queue_index, &queue_);
        VkPhysicalDeviceMemoryProperties memory;
        vkGetPhysicalDeviceMemoryProperties(from_integer<VkPhysicalDevice>(h.physical_device), &memory);
        auto memory_type = [&](std::uint32_t bits, VkMemoryPropertyFlags flags) {
            for (std::uint32_t i = 0; i < memory.memoryTypeCount; ++i)
                if ((bits & (1u << i)) && (memory.memoryTypes[i].propertyFlags & flags) == flags) return i;
            throw std::runtime_error("no memory type");
        };
        auto info = vk_info<VkImageCreateInfo>(VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO);
        info.imageType = VK_IMAGE_TYPE_2D;
        info.format = format;
        info.extent = {std::uint32_t(width), std::uint32_t(height), 1};
        info.mipLevels = 1;
        info.arrayLayers = std::uint32_t(layers);
        info.samples = VK_SAMPLE_COUNT_1_BIT;
        info.tiling = VK_IMAGE_TILING_OPTIMAL;
        info.usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
        info.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
        LOBE_TEST_VK(vkCreateImage(device_, &info, nullptr, &image_));
        VkMemoryRequirements req;
        vkGetImageMemoryRequirements(device_, image_, &req);
        auto alloc = vk_info<VkMemoryAllocateInfo>(VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO);
        alloc.allocationSize = req.size;
        alloc.memoryTypeIndex = memory_type(req.memoryTypeBits, 0);
        LOBE_TEST_VK(vkAllocateMemory(device_, &alloc, nullptr, &image_memory_));
        LOBE_TEST_VK(vkBindImageMemory(device_, image_, image_memory_, 0));
        auto buffer = vk_info<VkBufferCreateInfo>(VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO);
        buffer.size = VkDeviceSize(width) * VkDeviceSize(height) * 4u;
        buffer.usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT;
        LOBE_TEST_VK(vkCreateBuffer(device_, &buffer, nullptr, &buffer_));
        vkGetBufferMemoryRequirements(device_, buffer_, &req);
        alloc.allocationSize = req.size;
        alloc.memoryTypeIndex = memory_type(req.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
        LOBE_TEST_VK(vkAllocateMemory(device_, &alloc, nullptr, &buffer_memory_));
        LOBE_TEST_VK(vkBindBufferMemory(device_, buffer_, buffer_memory_, 0));
        auto pool = vk_info<VkCommandPoolCreateInfo>(VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO);
        pool.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
        pool.queueFamilyIndex = h.queue_family;
        LOBE_TEST_VK(vkCreateCommandPool(device_, &pool, nullptr, &pool_));
        auto cb = vk_info<VkCommandBufferAllocateInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO);
        cb.commandPool = pool_;
        cb.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
        cb.commandBufferCount = 1;
        LOBE_TEST_VK(vkAllocateCommandBuffers(device_, &cb, &cmd_));
        auto fence = vk_info<VkFenceCreateInfo>(VK_STRUCTURE_TYPE_FENCE_CREATE_INFO);
        LOBE_TEST_VK(vkCreateFence(device_, &fence, nullptr, &fence_));
        submit([&](VkCommandBuffer cmd) {
            const VkImageSubresourceRange all{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, std::uint32_t(layers)};
            barrier(cmd, all, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL);
            const VkClearColorValue magenta{{1.0f, 0.0f, 1.0f, 1.0f}};
            vkCmdClearColorImage(cmd, image_, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &magenta, 1, &all);
            barrier(cmd, all, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL);
        });
    }
    ~TestImage()
    {
        vkDeviceWaitIdle(device_);
        vkDestroyFence(device_, fence_, nullptr);
        vkDestroyCommandPool(device_, pool_, nullptr);
        vkDestroyBuffer(device_, buffer_, nullptr);
        vkFreeMemory(device_, buffer_memory_, nullptr);
        vkDestroyImage(device_, image_, nullptr);
        vkFreeMemory(device_, image_memory_, nullptr);
    }
    TestImage(const TestImage&) = delete;
    TestImage& operator=(const TestImage&) = delete;

    ExternalImage target(int layer = 0) const { return {to_integer(image_), int(format_), width_, height_, layer}; }

    /// Layer `layer` as RGBA bytes (B8G8R8A8 swizzled), rows top to bottom.
    RgbaImage read(int layer = 0)
    {
        submit([&](VkCommandBuffer cmd) {
            const VkImageSubresourceRange range{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, std::uint32_t(layer), 1};
            barrier(cmd, range, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
            VkBufferImageCopy region{};
            region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, std::uint32_t(layer), 1};
            region.imageExtent = {std::uint32_t(width_), std::uint32_t(height_), 1};
            vkCmdCopyImageToBuffer(cmd, image_, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, buffer_, 1, &region);
            barrier(cmd, range, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL);
        });
        RgbaImage out{width_, height_, std::vector<std::uint8_t>(std::size_t(width_) * std::size_t(height_) * 4)};
        void* mapped = nullptr;
        LOBE_TEST_VK(vkMapMemory(device_, buffer_memory_, 0, VK_WHOLE_SIZE, 0, &mapped));
        std::memcpy(out.pixels.data(), mapped, out.pixels.size());
        vkUnmapMemory(device_, buffer_memory_);
        if (format_ == VK_FORMAT_B8G8R8A8_SRGB || format_ == VK_FORMAT_B8G8R8A8_UNORM)
            for (std::size_t i = 0; i < out.pixels.size(); i += 4) std::swap(out.pixels[i], out.pixels[i + 2]);
        return out;
    }

private:
    void barrier(VkCommandBuffer cmd, const VkImageSubresourceRange& range, VkImageLayout from, VkImageLayout to) const
    {
        auto b = vk_info<VkImageMemoryBarrier>(VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER);
        b.srcAccessMask = VK_ACCESS_MEMORY_WRITE_BIT;
        b.dstAccessMask = VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT;
        b.oldLayout = from;
        b.newLayout = to;
        b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
        b.image = image_;
        b.subresourceRange = range;
        vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0, 0, nullptr, 0, nullptr,
                             1, &b);
    }
    void submit(const std::function<void(VkCommandBuffer)>& record)
    {
        LOBE_TEST_VK(vkResetCommandBuffer(cmd_, 0));
        auto begin = vk_info<VkCommandBufferBeginInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO);
        LOBE_TEST_VK(vkBeginCommandBuffer(cmd_, &begin));
        record(cmd_);
        LOBE_TEST_VK(vkEndCommandBuffer(cmd_));
        LOBE_TEST_VK(vkResetFences(device_, 1, &fence_));
        auto info = vk_info<VkSubmitInfo>(VK_STRUCTURE_TYPE_SUBMIT_INFO);
        info.commandBufferCount = 1;
        info.pCommandBuffers = &cmd_;
        LOBE_TEST_VK(vkQueueSubmit(queue_, 1, &info, fence_));
        LOBE_TEST_VK(vkWaitForFences(device_, 1, &fence_, VK_TRUE, UINT64_MAX));
    }

    VkDevice device_;
    VkQueue queue_ = VK_NULL_HANDLE;
    VkFormat format_;
    int width_, height_;
    VkImage image_ = VK_NULL_HANDLE;
    VkDeviceMemory image_memory_ = VK_NULL_HANDLE, buffer_memory_ = VK_NULL_HANDLE;
    VkBuffer buffer_ = VK_NULL_HANDLE;
    VkCommandPool pool_ = VK_NULL_HANDLE;
    VkCommandBuffer cmd_ = VK_NULL_HANDLE;
    VkFence fence_ = VK_NULL_HANDLE;
};

// The photo's four quadrants (sRGB), far from the sky's and the ground's colours.
constexpr std::array<std::uint8_t, 3> kTopLeft{220, 30, 30}, kTopRight{30, 200, 60}, kBottomLeft{200, 40, 200},
    kBottomRight{230, 210, 40};

/// 8×8 texels, a colour per 4×4 quadrant (row 0 is the top).
RgbaImage quadrant_texture()
{
    RgbaImage t{8, 8, std::vector<std::uint8_t>(8 * 8 * 4)};
    for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 8; ++x) {
            const auto& c = y < 4 ? (x < 4 ? kTopLeft : kTopRight) : (x < 4 ? kBottomLeft : kBottomRight);
            std::uint8_t* p = &t.pixels[std::size_t(y * 8 + x) * 4];
            std::copy(c.begin(), c.end(), p);
            p[3] = 255;
        }
    return t;
}

/// Sky, ground and a 1 m photo quad in the plane z = 0, x in [−0.5, 0.5], y in [0.5, 1.5],
/// facing +Z, the texture's top-left corner at its top-left.
RenderScene photo_scene(std::uint64_t texture_version = 1)
{
    RenderScene scene;
    RenderItem photo;
    photo.key = 1;
    photo.version = 1;
    photo.material = RenderMaterial::Photo;
    photo.geometry.positions = {{-0.5f, 1.5f, 0.0f}, {0.5f, 1.5f, 0.0f}, {0.5f, 0.5f, 0.0f}, {-0.5f, 0.5f, 0.0f}};
    photo.geometry.normals.assign(4, glm::vec3(0.0f, 0.0f, 1.0f));
    photo.geometry.uvs = {{0.0f, 0.0f}, {1.0f, 0.0f}, {1.0f, 1.0f}, {0.0f, 1.0f}};
    photo.geometry.triangles = {{0, 2, 1}, {0, 3, 2}};
    scene.items.push_back(photo);
    scene.photo_texture = quadrant_texture();
    scene.photo_texture_version = texture_version;
    scene.ground_area = Bounds{glm::vec3(-0.5f, 0.0f, -0.5f), glm::vec3(0.5f, 1.5f, 0.5f)};
    return scene;
}

/// The camera of the eye tests: 3 m in front of the photo's centre, looking along −Z, 40°.
Camera eye_camera()
{
    Camera c;
    c.eye = glm::vec3(0.0f, 1.0f, 3.0f);
    c.target = c.eye + glm::vec3(0.0f, 0.0f, -1.0f);
    c.fov_y_deg = 40.0f;
    c.near_m = 0.05f;
    c.far_m = 100.0f;
    return c;
}

/// eye_camera() as an OpenXR view of a square image: ±20° each way.
EyeView eye_view()
{
    EyeView e;
    e.position = glm::vec3(0.0f, 1.0f, 3.0f);
    const float half = glm::radians(20.0f);
    e.angle_left = e.angle_down = -half;
    e.angle_right = e.angle_up = half;
    e.near_m = 0.05f;
    e.far_m = 100.0f;
    return e;
}

/// Largest per-channel difference of the RGB of two pictures, and how many pixels differ.
std::pair<int, std::size_t> rgb_difference(const RgbaImage& a, const RgbaImage& b)
{
    int most = 0;
    std::size_t pixels = 0;
    for (std::size_t i = 0; i < a.pixels.size() && i < b.pixels.size(); i += 4) {
        int d = 0;
        for (int c = 0; c < 3; ++c) d = std::max(d, std::abs(int(a.pixels[i + c]) - int(b.pixels[i + c])));
        most = std::max(most, d);
        pixels += d > 0;
    }
    return {most, pixels};
}

bool near_colour(const std::uint8_t* p, const std::array<std::uint8_t, 3>& c, int tolerance)
{
    for (int k = 0; k < 3; ++k)
        if (std::abs(int(p[k]) - int(c[k])) > tolerance) return false;
    return true;
}

/// Centre (pixel coordinates) of the pixels showing one of the photo's colours.
glm::dvec2 photo_centre(const RgbaImage& im)
{
    glm::dvec2 sum(0.0);
    std::size_t n = 0;
    for (int y = 0; y < im.height; ++y)
        for (int x = 0; x < im.width; ++x) {
            const std::uint8_t* p = pixel(im, x, y);
            for (const auto& c : {kTopLeft, kTopRight, kBottomLeft, kBottomRight})
                if (near_colour(p, c, 6)) {
                    sum += glm::dvec2(x, y);
                    ++n;
                    break;
                }
        }
    return n ? sum / double(n) : glm::dvec2(-1.0);
}

/// Hooks that make the instance and device as the renderer would, with the first device;
/// what they made and saw is recorded in `seen`.
struct HookRecord {
    std::uint64_t instance = 0, physical = 0, device = 0;
    std::uint32_t api_version = 0, queue_family = ~0u;
    int instance_calls = 0, physical_calls = 0, device_calls = 0;
};

RendererOptions::VulkanHooks direct_hooks(HookRecord& seen)
{
    RendererOptions::VulkanHooks h;
    h.create_instance = [&seen](const void* create_info, int& result) -> std::uint64_t {
        ++seen.instance_calls;
        const auto* info = static_cast<const VkInstanceCreateInfo*>(create_info);
        if (info->pApplicationInfo) seen.api_version = info->pApplicationInfo->apiVersion;
        VkInstance instance = VK_NULL_HANDLE;
        result = vkCreateInstance(info, nullptr, &instance);
        return seen.instance = result == VK_SUCCESS ? to_integer(instance) : 0;
    };
    h.physical_device = [&seen](std::uint64_t instance) -> std::uint64_t {
        ++seen.physical_calls;
        std::uint32_t n = 1;
        VkPhysicalDevice first = VK_NULL_HANDLE;
        vkEnumeratePhysicalDevices(from_integer<VkInstance>(instance), &n, &first); // VK_INCOMPLETE with more
        return seen.physical = n ? to_integer(first) : 0;
    };
    h.create_device = [&seen](std::uint64_t physical, const void* create_info, int& result) -> std::uint64_t {
        ++seen.device_calls;
        const auto* info = static_cast<const VkDeviceCreateInfo*>(create_info);
        if (info->queueCreateInfoCount == 1) seen.queue_family = info->pQueueCreateInfos[0].queueFamilyIndex;
        VkDevice device = VK_NULL_HANDLE;
        result = vkCreateDevice(from_integer<VkPhysicalDevice>(physical), info, nullptr, &device);
        return seen.device = result == VK_SUCCESS ? to_integer(device) : 0;
    };
    return h;
}

/// The message of the RenderUnavailable `make` throws ("" when it throws none).
std::string unavailable_message(const std::function<void()>& make)
{
    try {
        make();
    } catch (const RenderUnavailable& e) {
        return e.what();
    }
    return "";
}

TEST(RenderXr, HooksMakeTheInstanceAndDeviceAndTheRendererDrawsAsTheDefaultOne)
{
    if (!has_shared_recording()) return;
    HookRecord seen;
    RendererOptions options;
    options.vulkan_hooks = direct_hooks(seen);
    Renderer hooked(options);
    EXPECT_EQ(seen.instance_calls, 1);
    EXPECT_EQ(seen.physical_calls, 1);
    EXPECT_EQ(seen.device_calls, 1);
    EXPECT_GE(seen.api_version, VK_API_VERSION_1_1);
    const VulkanHandles h = hooked.vulkan_handles();
    EXPECT_EQ(h.instance, seen.instance);
    EXPECT_EQ(h.physical_device, seen.physical);
    EXPECT_EQ(h.device, seen.device);
    EXPECT_EQ(h.queue_family, seen.queue_family);
    EXPECT_EQ(h.queue_index, 0u);

    const RenderScene scene = photo_scene();
    hooked.set_scene(scene);
    const RgbaImage picture = hooked.render(eye_camera(), kEw, kEh);
    ASSERT_EQ(picture.pixels.size(), std::size_t(kEw) * kEh * 4);
    EXPECT_NE(photo_centre(picture).x, -1.0) << "the photo is drawn";
    Renderer& plain = *shared().renderer;
    if (plain.device_name() == hooked.device_name()) {
        plain.set_scene(scene);
        EXPECT_EQ(plain.render(eye_camera(), kEw, kEh).pixels, picture.pixels);
    }
}

TEST(RenderXr, AHookReturning0IsRenderUnavailableInOneLineNamingTheHookAndTheResult)
{
    HookRecord seen;
    RendererOptions options;
    options.vulkan_hooks = direct_hooks(seen);
    options.vulkan_hooks.create_instance = [](const void*, int& result) -> std::uint64_t {
        result = VK_ERROR_INCOMPATIBLE_DRIVER;
        return 0;
    };
    std::string m = unavailable_message([&] { Renderer r(options); });
    EXPECT_NE(m.find("create_instance"), std::string::npos) << m;
    EXPECT_NE(m.find("VK_ERROR_INCOMPATIBLE_DRIVER"), std::string::npos) << m;
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    EXPECT_EQ(seen.physical_calls, 0);

    options.vulkan_hooks = direct_hooks(seen);
    options.vulkan_hooks.physical_device = [](std::uint64_t) -> std::uint64_t { return 0; };
    m = unavailable_message([&] { Renderer r(options); });
    EXPECT_NE(m.find("physical_device"), std::string::npos) << m;
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    EXPECT_EQ(seen.device_calls, 0);

    options.vulkan_hooks = direct_hooks(seen);
    options.vulkan_hooks.create_device = [](std::uint64_t, const void*, int& result) -> std::uint64_t {
        result = VK_ERROR_DEVICE_LOST;
        return 0;
    };
    m = unavailable_message([&] { Renderer r(options); });
    EXPECT_NE(m.find("create_device"), std::string::npos) << m;
    EXPECT_NE(m.find("VK_ERROR_DEVICE_LOST"), std::string::npos) << m;
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;

    options.vulkan_hooks.create_device = [](std::uint64_t, const void*, int&) -> std::uint64_t { return 0; };
    m = unavailable_message([&] { Renderer r(options); });
    EXPECT_NE(m.find("no VkResult"), std::string::npos) << m;

    // Some of the three but not all is a mistake of the caller's.
    RendererOptions partial;
    partial.vulkan_hooks.create_instance = direct_hooks(seen).create_instance;
    EXPECT_THROW(Renderer r(partial), RenderError);
}

TEST(RenderXr, RenderToASymmetricEyeDrawsWhatRenderDrawsForTheSameCameraInEveryFormat)
{
    if (!has_shared_recording()) return;
    Renderer& r = *shared().renderer;
    r.set_overlay(Overlay{});
    r.set_scene(photo_scene());
    const RgbaImage expected = r.render(eye_camera(), kEw, kEh);
    ASSERT_TRUE(near_colour(pixel(expected, 25, 25), kTopLeft, 2)) << "the photo is upright and not mirrored";
    ASSERT_TRUE(near_colour(pixel(expected, 38, 38), kBottomRight, 2));
    for (VkFormat format : {VK_FORMAT_R8G8B8A8_SRGB, VK_FORMAT_B8G8R8A8_SRGB}) {
        SCOPED_TRACE(format == VK_FORMAT_R8G8B8A8_SRGB ? "R8G8B8A8_SRGB" : "B8G8R8A8_SRGB");
        TestImage image(r.vulkan_handles(), format, kEw, kEh, 2);
        r.render_to(eye_view(), image.target(1));
        const RgbaImage drawn = image.read(1);
        const auto [most, pixels] = rgb_difference(drawn, expected);
        EXPECT_LE(most, 1) << pixels << " pixels differ";
        EXPECT_EQ(rgb_difference(r.last_frame(), expected).first, 0) << "last_frame() reads the eye's picture back";
        const RgbaImage untouched = image.read(0);
        EXPECT_TRUE(near_colour(pixel(untouched, 0, 0), {255, 0, 255}, 0)) << "only the asked layer is written";
        // Again into the same image: it was left in COLOR_ATTACHMENT_OPTIMAL.
        r.render_to(eye_view(), image.target(1));
        EXPECT_EQ(image.read(1).pixels, drawn.pixels);
    }
    // The linear formats get linear colours: sRGB 220 is linear 0.716, byte 183.
    TestImage unorm(r.vulkan_handles(), VK_FORMAT_R8G8B8A8_UNORM, kEw, kEh);
    r.render_to(eye_view(), unorm.target());
    const RgbaImage linear = unorm.read();
    const std::uint8_t* p = pixel(linear, 25, 25);
    EXPECT_NEAR(double(p[0]), srgb_to_linear(kTopLeft[0]) * 255.0, 1.0);
}

TEST(RenderXr, AnEyeTurnedOrOffCentreMovesThePictureTheWayItsPoseAndAnglesSay)
{
    if (!has_shared_recording()) return;
    Renderer& r = *shared().renderer;
    r.set_overlay(Overlay{});
    r.set_scene(photo_scene());
    TestImage image(r.vulkan_handles(), VK_FORMAT_R8G8B8A8_SRGB, kEw, kEh);
    r.render_to(eye_view(), image.target());
    const glm::dvec2 centred = photo_centre(image.read());
    EXPECT_NEAR(centred.x, 31.5, 0.5);
    EXPECT_NEAR(centred.y, 31.5, 0.5);
    // The frustum shifted right by 0.2 in tangent (of a width of 2 tan 20° = 0.728): what is
    // straight ahead is 0.2 / 0.728 of the picture's width left of its centre.
    const double shift = 0.2 / (2.0 * std::tan(glm::radians(20.0))) * kEw;
    EyeView right = eye_view();
    right.angle_left = std::atan(std::tan(right.angle_left) + 0.2f);
    right.angle_right = std::atan(std::tan(right.angle_right) + 0.2f);
    r.render_to(right, image.target());
    glm::dvec2 c = photo_centre(image.read());
    EXPECT_NEAR(c.x, centred.x - shift, 0.5);
    EXPECT_NEAR(c.y, centred.y, 0.5);
    // Shifted up: it is below the centre (rows go down).
    EyeView up = eye_view();
    up.angle_down = std::atan(std::tan(up.angle_down) + 0.2f);
    up.angle_up = std::atan(std::tan(up.angle_up) + 0.2f);
    r.render_to(up, image.target());
    c = photo_centre(image.read());
    EXPECT_NEAR(c.x, centred.x, 0.5);
    EXPECT_NEAR(c.y, centred.y + shift, 0.5);
    // Turned 10° to the left (about +Y): the photo moves right by tan 10° / tan 20° of half the width.
    EyeView turned = eye_view();
    turned.orientation = glm::angleAxis(glm::radians(10.0f), glm::vec3(0.0f, 1.0f, 0.0f));
    r.render_to(turned, image.target());
    c = photo_centre(image.read());
    EXPECT_GT(c.x, centred.x + 0.7 * std::tan(glm::radians(10.0)) / std::tan(glm::radians(20.0)) * kEw / 2);
    EXPECT_NEAR(c.y, centred.y, 1.0);
    // Turned to look along −X, it equals render()'s camera looking along −X.
    EyeView side = eye_view();
    side.orientation = glm::angleAxis(glm::half_pi<float>(), glm::vec3(0.0f, 1.0f, 0.0f));
    Camera side_camera = eye_camera();
    side_camera.target = side_camera.eye + glm::vec3(-1.0f, 0.0f, 0.0f);
    r.render_to(side, image.target());
    const auto [most, pixels] = rgb_difference(image.read(), r.render(side_camera, kEw, kEh));
    EXPECT_LE(pixels, std::size_t(kEw * kEh / 100)) << "largest difference " << most;
}

TEST(RenderXr, BadEyesAndImagesAreRefusedWithOneLine)
{
    if (!has_shared_recording()) return;
    Renderer& r = *shared().renderer;
    TestImage image(r.vulkan_handles(), VK_FORMAT_R8G8B8A8_SRGB, 8, 8);
    std::vector<std::pair<EyeView, ExternalImage>> bad;
    auto with_image = [&](auto change) {
        ExternalImage t = image.target();
        change(t);
        bad.emplace_back(eye_view(), t);
    };
    auto with_eye = [&](auto change) {
        EyeView e = eye_view();
        change(e);
        bad.emplace_back(e, image.target());
    };
    with_image([](ExternalImage& t) { t.width = 0; });
    with_image([](ExternalImage& t) { t.height = 16385; });
    with_image([](ExternalImage& t) { t.vk_image = 0; });
    with_image([](ExternalImage& t) { t.vk_format = VK_FORMAT_R16G16B16A16_SFLOAT; });
    with_image([](ExternalImage& t) { t.array_layer = -1; });
    with_eye([](EyeView& e) { e.angle_left = e.angle_right; });
    with_eye([](EyeView& e) { e.angle_up = 1.6f; });
    with_eye([](EyeView& e) { e.near_m = 0.0f; });
    with_eye([](EyeView& e) { e.far_m = e.near_m; });
    with_eye([](EyeView& e) { e.orientation = glm::quat(0.0f, 0.0f, 0.0f, 0.0f); });
    with_eye([](EyeView& e) { e.position.x = std::nanf(""); });
    for (const auto& [eye, target] : bad) {
        try {
            r.render_to(eye, target);
            ADD_FAILURE() << "accepted";
        } catch (const InvalidInput& e) {
            EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
        }
    }
}

TEST(RenderPhoto, APhotoShowsItsTextureUnlitFromBothSidesTimesItsColourAndWhiteWithout)
{
    if (!has_shared_recording()) return;
    Renderer& r = *shared().renderer;
    r.set_overlay(Overlay{});
    RenderScene scene = photo_scene();
    r.set_scene(scene);
    RgbaImage picture = r.render(eye_camera(), kEw, kEh);
    EXPECT_TRUE(near_colour(pixel(picture, 25, 25), kTopLeft, 1));
    EXPECT_TRUE(near_colour(pixel(picture, 38, 25), kTopRight, 1));
    EXPECT_TRUE(near_colour(pixel(picture, 25, 38), kBottomLeft, 1));
    EXPECT_TRUE(near_colour(pixel(picture, 38, 38), kBottomRight, 1));
    // From behind: two-sided, mirrored left to right.
    Camera behind = eye_camera();
    behind.eye.z = -3.0f;
    behind.target = behind.eye + glm::vec3(0.0f, 0.0f, 1.0f);
    picture = r.render(behind, kEw, kEh);
    EXPECT_TRUE(near_colour(pixel(picture, 25, 25), kTopRight, 1));
    EXPECT_TRUE(near_colour(pixel(picture, 38, 38), kBottomLeft, 1));
    // Times the colour (linear): half the red.
    scene.items[0].color = {0.5f, 1.0f, 1.0f, 1.0f};
    scene.items[0].version = 2;
    r.set_scene(scene);
    picture = r.render(eye_camera(), kEw, kEh);
    EXPECT_NEAR(int(pixel(picture, 25, 25)[0]), int(linear_to_srgb(0.5 * srgb_to_linear(kTopLeft[0]))), 1);
    EXPECT_NEAR(int(pixel(picture, 25, 25)[1]), int(kTopLeft[1]), 1);
    // No texture: white.
    scene.items[0].color = {1.0f, 1.0f, 1.0f, 1.0f};
    scene.photo_texture = {};
    r.set_scene(scene);
    picture = r.render(eye_camera(), kEw, kEh);
    EXPECT_TRUE(near_colour(pixel(picture, 25, 25), {255, 255, 255}, 0));
    EXPECT_TRUE(near_colour(pixel(picture, 38, 38), {255, 255, 255}, 0));
}

TEST(RenderPhoto, ThePhotoIsUploadedOnlyWhenItsVersionChangesAndABadOneIsRefused)
{
    if (!has_shared_recording()) return;
    Renderer& r = *shared().renderer;
    RenderScene scene = photo_scene(5);
    r.set_scene(scene);
    r.set_scene(scene);
    EXPECT_EQ(r.stats().bytes_uploaded, 0u);
    scene.photo_texture_version = 6;
    r.set_scene(scene);
    EXPECT_EQ(r.stats().bytes_uploaded, scene.photo_texture.pixels.size());
    scene.photo_texture.pixels.pop_back();
    scene.photo_texture_version = 7;
    try {
        r.set_scene(scene);
        ADD_FAILURE() << "a short photo was accepted";
    } catch (const InvalidInput& e) {
        EXPECT_NE(std::string(e.what()).find("photo"), std::string::npos) << e.what();
    }
}

} // namespace
} // namespace lobe
