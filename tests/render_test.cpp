// Offscreen pictures (app/renderer.h, app/render_scene.h, `lobesketch render`) of the tree of
// a shipped recording, small (192×144) so the suite stays fast on lavapipe.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>

#include <sys/wait.h>

#include "app/edit_hooks.h"
#include "app/export_scene.h"
#include "app/render_scene.h"
#include "app/renderer.h"
#include "app/tree_output.h"
#include "app/tree_pipeline.h"
#include "input/pipeline.h"
#include "input/recording.h"
#include "input/session_builder.h"
#include "meshing/edit_ops.h"
#include "tests/cli_run.h"
#include "tests/test_paths.h"

namespace lobe {
namespace {

namespace fs = std::filesystem;

constexpr int kW = 192, kH = 144;

std::string rec(const std::string& name) { return test::source_path("recordings/" + name + ".lrec"); }

/// The 1-lobe, 5-stroke Table 1 tree, its geometry and one renderer, made once for the suite.
struct Shared {
    Document doc;
    BuiltTree tree;
    TreeGeometry geometry;
    std::unique_ptr<Renderer> renderer;
};

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
    const RenderScene scene = tree_scene();
    const RgbaImage front = draw(scene, camera_for(scene, front_view()));
    const RgbaImage side = draw(scene, camera_for(scene, side_view()));
    const double differing = coverage(front, side);
    EXPECT_GT(differing, 0.05);
}

TEST(RenderPicture, LeafColouredAndBarkColouredPixelsAreBothPresent)
{
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
    const RenderScene tree = tree_scene();
    RenderContent all;
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

TEST(RenderScene, BadMeshesAndSizesAreRefusedWithOneLine)
{
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
    ASSERT_EQ(run_cli("grow " + rec("table1-1lobe-5strokes") + " --out " + out + "/tree.glb --lobes --strokes").code, 0);
    const CliRun glb = run_cli("render " + out + "/tree.glb --out " + out + "/glb.png --size 192x144 --show tree,leaves,lobes,strokes");
    ASSERT_EQ(glb.code, 0) << glb.out;
    EXPECT_EQ(png_size(out + "/glb.png"), std::make_pair(192, 144));
    const CliRun side = run_cli("render " + rec("table1-1lobe-5strokes") + " --out " + out + "/side.png --view side --size 160x120 --lod 1");
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
        {"render " + r + " --out " + out + "/x.jpg", "written as .png", 1},
        {"render " + out + "/missing.glb --out " + out + "/x.png", "missing.glb", 1},
        {"render " + rec("table1-1lobe-5strokes") + " --out " + out + "/x.png --lod 7", "--lod: LOD 7 does not exist", 1},
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
    ASSERT_EQ(run_cli("grow " + rec("table1-1lobe-5strokes") + " --out " + out + "/tree.glb").code, 0);
    const CliRun r = run_cli("render " + out + "/tree.glb --out " + out + "/x.png",
                             "VK_ICD_FILENAMES=" + out + "/none.json VK_DRIVER_FILES=" + out + "/none.json");
    EXPECT_EQ(r.code, 1) << r.out;
    EXPECT_EQ(count(r.out, "error:"), 1u) << r.out;
    EXPECT_NE(r.out.find("mesa-vulkan-drivers"), std::string::npos) << r.out;
    EXPECT_FALSE(fs::exists(out + "/x.png"));
}

} // namespace
} // namespace lobe
