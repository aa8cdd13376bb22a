#pragma once
/// \file hole_meshes.h
/// Meshes with one long hole, as scans and cut models have them, for the repair tests and the
/// `hole_fill` fuzz target: a dome whose open base runs up and down in waves, and a sphere
/// with a long slit. Header-only: the fuzz targets link no test library.

#include <cmath>
#include <cstddef>
#include <cstdint>

#include "core/mesh.h"

namespace lobe::test {

/// A dome (a unit sphere above latitude −40°) whose open base runs up and down by
/// ±`amplitude_deg` of latitude in `waves` waves over `segments` edges, as the cut-off base of
/// a scan can.
inline TriangleMesh dome_with_wavy_base(int segments, int waves, double amplitude_deg)
{
    constexpr double kPi = 3.14159265358979323846;
    TriangleMesh m;
    constexpr int kRings = 6;
    for (int r = 0; r < kRings; ++r)
        for (int i = 0; i < segments; ++i) {
            const double lon = 2.0 * kPi * i / segments;
            const double lat = (-40.0 + 130.0 * r / kRings + (r == 0 ? amplitude_deg * std::sin(waves * lon) : 0.0)) * kPi / 180.0;
            m.positions.emplace_back(std::cos(lat) * std::cos(lon), std::sin(lat), std::cos(lat) * std::sin(lon));
        }
    m.positions.emplace_back(0.0f, 1.0f, 0.0f);
    for (int r = 0; r + 1 < kRings; ++r)
        for (int i = 0; i < segments; ++i) {
            const int a = r * segments + i, b = r * segments + (i + 1) % segments;
            const int c = (r + 1) * segments + (i + 1) % segments, d = (r + 1) * segments + i;
            m.triangles.push_back({a, c, b});
            m.triangles.push_back({a, d, c});
        }
    const int pole = kRings * segments;
    for (int i = 0; i < segments; ++i)
        m.triangles.push_back({(kRings - 1) * segments + i, pole, (kRings - 1) * segments + (i + 1) % segments});
    return m;
}

/// A UV sphere (`segments` longitudes, `rings` latitude bands) with a slit cut out of the
/// band just north of the equator over its first `slit_degrees` of longitude: a long, thin,
/// curved hole whose border, seen along its vector area, runs over itself.
inline TriangleMesh sphere_with_slit(int segments, int rings, double slit_degrees)
{
    constexpr double kPi = 3.14159265358979323846;
    TriangleMesh m;
    for (int r = 1; r < rings; ++r) {
        const double lat = -0.5 * kPi + kPi * r / rings;
        for (int i = 0; i < segments; ++i) {
            const double lon = 2.0 * kPi * i / segments;
            m.positions.emplace_back(std::cos(lat) * std::cos(lon), std::cos(lat) * std::sin(lon), std::sin(lat));
        }
    }
    const int south = static_cast<int>(m.positions.size());
    m.positions.emplace_back(0.0f, 0.0f, -1.0f);
    m.positions.emplace_back(0.0f, 0.0f, 1.0f);
    auto at = [&](int r, int i) { return (r - 1) * segments + i % segments; };
    for (int r = 1; r + 1 < rings; ++r)
        for (int i = 0; i < segments; ++i) {
            if (r == rings / 2 && i < segments * slit_degrees / 360.0) continue;
            m.triangles.push_back({at(r, i), at(r, i + 1), at(r + 1, i + 1)});
            m.triangles.push_back({at(r, i), at(r + 1, i + 1), at(r + 1, i)});
        }
    for (int i = 0; i < segments; ++i) {
        m.triangles.push_back({south, at(1, i + 1), at(1, i)});
        m.triangles.push_back({south + 1, at(rings - 1, i), at(rings - 1, i + 1)});
    }
    return m;
}

/// Moves vertex `first` + k by byte k of `bytes`: by up to ±5 % of the unit radius (the low
/// four bits, 0–15 for −5 %…+5 %) along axis x, y or z (the high four bits, modulo 3).
inline void move_vertices(TriangleMesh& m, std::size_t first, const std::uint8_t* bytes, std::size_t count)
{
    for (std::size_t k = 0; k < count && first + k < m.positions.size(); ++k) {
        const double amount = 0.05 * (static_cast<double>(bytes[k] & 15) - 7.5) / 7.5;
        m.positions[first + k][(bytes[k] >> 4) % 3] += static_cast<float>(amount);
    }
}

/// The mesh the `hole_fill` fuzz target makes of its input (fuzz/hole_fill_fuzz.cpp says how
/// the bytes are read); empty for fewer than five bytes.
inline TriangleMesh hole_fill_mesh(const std::uint8_t* data, std::size_t size)
{
    if (size < 5) return {};
    const int wide = data[1] | (data[2] << 8);
    TriangleMesh m;
    std::size_t first = 0; // the first vertex beside the hole
    if ((data[0] & 1) == 0) {
        const int segments = 201 + wide % 500;
        m = dome_with_wavy_base(segments, data[3] % (segments / 2), data[4] % 51);
    } else {
        const int rings = 20 + data[3] % 64;
        constexpr int kSegments = 240;
        m = sphere_with_slit(kSegments, rings, 60.0 + wide % 271);
        first = static_cast<std::size_t>((rings / 2 - 1) * kSegments); // ring rings/2, below the slit
    }
    move_vertices(m, first, data + 5, size - 5);
    return m;
}

} // namespace lobe::test
