#include "app/render/scene_parts.h"

#include <cmath>
#include <cstring>
#include <vector>

#include <glm/gtc/constants.hpp>

#include "app/render/render_scene.h"

// stb_easy_font is a header of static functions (libstb-dev): only this file uses it.
#if defined(__clang__)
#pragma clang diagnostic push
#pragma clang diagnostic ignored "-Wunused-function"
#elif defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#endif
#include <stb_easy_font.h>
#if defined(__clang__)
#pragma clang diagnostic pop
#elif defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

namespace lobe {

namespace {

/// Joints of each finger from the wrist to the tip (OpenXR order), for the bones.
const std::array<std::vector<int>, 5> kFingerChains = {{
    {1, 2, 3, 4, 5},         // wrist, thumb metacarpal … tip
    {1, 6, 7, 8, 9, 10},     // wrist, index metacarpal … tip
    {1, 11, 12, 13, 14, 15}, // middle
    {1, 16, 17, 18, 19, 20}, // ring
    {1, 21, 22, 23, 24, 25}, // little
}};


} // namespace

/// The fingertip marker's colour says the tool (and so what a pinch does).
std::array<float, 4> tool_color(Tool t)
{
    switch (t) {
    case Tool::DrawLobe: return {0.35f, 0.85f, 0.30f, 1.0f};
    case Tool::DrawTrunk: return {0.60f, 0.38f, 0.18f, 1.0f};
    case Tool::DeformLobe: return {0.85f, 0.25f, 0.85f, 1.0f};
    case Tool::EditStroke: return {1.0f, 0.55f, 0.10f, 1.0f};
    case Tool::MoveLobe: return {0.20f, 0.60f, 1.0f, 1.0f};
    case Tool::RotateLobe: return {0.10f, 0.85f, 0.85f, 1.0f};
    case Tool::ScaleLobe: return {0.95f, 0.95f, 0.30f, 1.0f};
    }
    return {1.0f, 1.0f, 1.0f, 1.0f};
}

/// A UV sphere appended to `g`.
void append_sphere(SurfaceGeometry& g, const glm::vec3& centre, float radius, int rings, int segments)
{
    const auto base = static_cast<std::uint32_t>(g.positions.size());
    for (int r = 0; r <= rings; ++r) {
        const float phi = glm::pi<float>() * float(r) / float(rings);
        for (int s = 0; s <= segments; ++s) {
            const float theta = glm::two_pi<float>() * float(s) / float(segments);
            const glm::vec3 n(std::sin(phi) * std::cos(theta), std::cos(phi), std::sin(phi) * std::sin(theta));
            g.positions.push_back(centre + radius * n);
            g.normals.push_back(n);
        }
    }
    const auto row = static_cast<std::uint32_t>(segments + 1);
    for (int r = 0; r < rings; ++r)
        for (int s = 0; s < segments; ++s) {
            const std::uint32_t a = base + std::uint32_t(r) * row + std::uint32_t(s), b = a + row;
            g.triangles.push_back({a, a + 1, b});
            g.triangles.push_back({a + 1, b + 1, b});
        }
}

void append_geometry(SurfaceGeometry& into, const SurfaceGeometry& part)
{
    const auto base = static_cast<std::uint32_t>(into.positions.size());
    into.positions.insert(into.positions.end(), part.positions.begin(), part.positions.end());
    into.normals.insert(into.normals.end(), part.normals.begin(), part.normals.end());
    for (const auto& t : part.triangles) into.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
}


SurfaceGeometry hand_geometry(const HandState& hand)
{
    SurfaceGeometry g;
    if (!hand.active) return g;
    for (int j = 1; j < kJointCount; ++j) // the palm joint is not drawn
        append_sphere(g, hand.joints[std::size_t(j)].pose.position, 0.45f * hand.joints[std::size_t(j)].radius);
    for (const auto& chain : kFingerChains) {
        std::vector<glm::vec3> pts;
        for (int j : chain) pts.push_back(hand.joints[std::size_t(j)].pose.position);
        append_geometry(g, polyline_tube(pts, 0.0025f, 5));
    }
    return g;
}

namespace {

/// A quad of corners a, b, c, d (counter-clockwise seen from +Z of the board) with normal `n`,
/// drawn from both sides.
void append_quad(SurfaceGeometry& g, const std::array<glm::vec3, 4>& p, const glm::vec3& n,
                 const std::array<glm::vec2, 4>& uv)
{
    for (int side = 0; side < 2; ++side) {
        const auto base = static_cast<std::uint32_t>(g.positions.size());
        for (int i = 0; i < 4; ++i) {
            g.positions.push_back(p[std::size_t(i)]);
            g.normals.push_back(side == 0 ? n : -n);
            g.uvs.push_back(uv[std::size_t(i)]);
        }
        if (side == 0) {
            g.triangles.push_back({base, base + 1, base + 2});
            g.triangles.push_back({base, base + 2, base + 3});
        } else {
            g.triangles.push_back({base, base + 2, base + 1});
            g.triangles.push_back({base, base + 3, base + 2});
        }
    }
}

} // namespace

void append_board(SurfaceGeometry& g, const glm::vec3& centre, const glm::quat& orientation, float width,
                  float height, float lift)
{
    const glm::vec3 x = orientation * glm::vec3(0.5f * width, 0, 0), y = orientation * glm::vec3(0, 0.5f * height, 0);
    const glm::vec3 n = orientation * glm::vec3(0, 0, 1), c = centre + lift * n;
    // Keep uvs in step with positions for every mesh that has any (Photo items read them).
    if (g.uvs.size() < g.positions.size()) g.uvs.resize(g.positions.size(), glm::vec2(0.0f));
    append_quad(g, {c - x + y, c - x - y, c + x - y, c + x + y}, n,
                {glm::vec2(0, 0), glm::vec2(0, 1), glm::vec2(1, 1), glm::vec2(1, 0)});
}

float append_text(SurfaceGeometry& g, const std::string& text, const glm::vec3& centre, const glm::quat& orientation,
                  float height, float lift)
{
    std::string s;
    for (char ch : text)
        if (ch >= 32 && ch < 127) s += ch;
    if (s.empty()) return 0.0f;
    // stb_easy_font: about 7 units per capital letter, y down; 4 vertices of 16 bytes per quad.
    std::vector<char> buffer(s.size() * 64 * 16 + 64);
    unsigned char colour[4] = {255, 255, 255, 255};
    const int quads = stb_easy_font_print(0.0f, 0.0f, s.data(), colour, buffer.data(), int(buffer.size()));
    const float units_w = float(stb_easy_font_width(s.data()));
    const float k = height / 7.0f;
    const glm::vec3 ax = orientation * glm::vec3(1, 0, 0), ay = orientation * glm::vec3(0, 1, 0);
    const glm::vec3 n = orientation * glm::vec3(0, 0, 1);
    const glm::vec3 origin = centre + lift * n - ax * (0.5f * units_w * k) + ay * (0.5f * height);
    if (g.uvs.size() < g.positions.size()) g.uvs.resize(g.positions.size(), glm::vec2(0.0f));
    for (int q = 0; q < quads; ++q) {
        std::array<glm::vec3, 4> p;
        for (int i = 0; i < 4; ++i) {
            float xy[2];
            std::memcpy(xy, buffer.data() + (q * 4 + i) * 16, sizeof xy);
            p[std::size_t(i)] = origin + ax * (xy[0] * k) - ay * (xy[1] * k);
        }
        // stb's quads run clockwise on screen (y down): counter-clockwise seen from +Z.
        append_quad(g, p, n, {glm::vec2(0), glm::vec2(0), glm::vec2(0), glm::vec2(0)});
    }
    return units_w * k;
}

} // namespace lobe
