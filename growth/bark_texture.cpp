#include "growth/bark_texture.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>

#include "core/errors.h"

namespace lobe {

namespace {

// Value noise on a periodic lattice of `nx` × `ny` cells over the unit square, so the
// texture tiles: lattice values come from a hash of the wrapped cell corner.
double lattice_value(int x, int y, int nx, int ny, std::uint32_t salt)
{
    std::uint32_t h = static_cast<std::uint32_t>(((x % nx) + nx) % nx) * 0x9E3779B1u ^
                      static_cast<std::uint32_t>(((y % ny) + ny) % ny) * 0x85EBCA77u ^ salt;
    h ^= h >> 15;
    h *= 0x2C1B3C6Du;
    h ^= h >> 12;
    h *= 0x297A2D39u;
    h ^= h >> 15;
    return static_cast<double>(h & 0xFFFFFFu) / static_cast<double>(0xFFFFFFu);
}

double periodic_noise(double u, double v, int nx, int ny, std::uint32_t salt)
{
    const double x = u * nx, y = v * ny;
    const int ix = static_cast<int>(std::floor(x)), iy = static_cast<int>(std::floor(y));
    const double fx = x - ix, fy = y - iy;
    const double sx = fx * fx * (3 - 2 * fx), sy = fy * fy * (3 - 2 * fy);
    const double a = lattice_value(ix, iy, nx, ny, salt), b = lattice_value(ix + 1, iy, nx, ny, salt);
    const double c = lattice_value(ix, iy + 1, nx, ny, salt), d = lattice_value(ix + 1, iy + 1, nx, ny, salt);
    return (a + (b - a) * sx) * (1 - sy) + (c + (d - c) * sx) * sy;
}

std::uint8_t to_byte(double v) { return static_cast<std::uint8_t>(std::clamp(v, 0.0, 1.0) * 255.0 + 0.5); }

} // namespace

RgbaImage make_bark_texture(int size)
{
    if (size < 8 || size > 2048) throw InvalidInput("bark texture: size must be in [8, 2048]");
    RgbaImage img;
    img.width = size;
    img.height = size;
    img.pixels.resize(static_cast<std::size_t>(img.width) * static_cast<std::size_t>(img.height) * 4);
    constexpr double kPi = std::numbers::pi;
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x) {
            const double u = (x + 0.5) / img.width, v = (y + 0.5) / img.height;
            // Furrows run along the branch (v): ridges across u, wobbling with v.
            const double wobble = periodic_noise(u, v, 4, 3, 0x1234u) - 0.5;
            const double ridge = std::fabs(std::sin(kPi * (5.0 * u + 0.9 * wobble)));
            const double furrow = std::pow(ridge, 0.35); // narrow dark cracks, broad plates
            const double grain = 0.5 * periodic_noise(u, v, 16, 24, 0xBEEFu) + 0.5 * periodic_noise(u, v, 32, 48, 0x51u);
            const double light = 0.55 + 0.4 * furrow + 0.12 * (grain - 0.5);
            const double warm = 0.03 * (periodic_noise(u, v, 3, 2, 0x77u) - 0.5);
            std::uint8_t* p = &img.pixels[(static_cast<std::size_t>(y) * static_cast<std::size_t>(img.width) +
                                           static_cast<std::size_t>(x)) * 4];
            p[0] = to_byte(light + warm);
            p[1] = to_byte(light);
            p[2] = to_byte(light - warm);
            p[3] = 255;
        }
    return img;
}

} // namespace lobe
