// The procedural bark texture: opaque, light enough to be tinted, deterministic, and tiling
// along the branch (v) and around it (u) with REPEAT sampling.
#include <cstdlib>

#include <gtest/gtest.h>

#include "core/errors.h"
#include "growth/bark_texture.h"

namespace lobe {
namespace {

int lightness(const RgbaImage& img, int x, int y)
{
    const std::uint8_t* p = &img.pixels[(static_cast<std::size_t>(y) * static_cast<std::size_t>(img.width) +
                                         static_cast<std::size_t>(x)) * 4];
    return (p[0] + p[1] + p[2]) / 3;
}

TEST(BarkTexture, OpaqueLightDeterministicAndSquare)
{
    const RgbaImage a = make_bark_texture(64), b = make_bark_texture(64);
    EXPECT_EQ(a.width, 64);
    EXPECT_EQ(a.height, 64);
    EXPECT_EQ(a.pixels, b.pixels);
    long sum = 0;
    int darkest = 255, lightest = 0;
    for (int y = 0; y < a.height; ++y)
        for (int x = 0; x < a.width; ++x) {
            EXPECT_EQ(a.pixels[(static_cast<std::size_t>(y) * 64 + static_cast<std::size_t>(x)) * 4 + 3], 255);
            const int l = lightness(a, x, y);
            sum += l;
            darkest = std::min(darkest, l);
            lightest = std::max(lightest, l);
        }
    const double mean = static_cast<double>(sum) / (64.0 * 64.0);
    EXPECT_GT(mean, 150.0); // light: the bark colour tints it
    EXPECT_GT(lightest - darkest, 60); // with visible furrows
}

TEST(BarkTexture, TilesSeamlesslyInBothDirections)
{
    const RgbaImage t = make_bark_texture(64);
    // The step across the wrap (last row to first) is no larger than steps inside the image.
    auto row_step = [&](int y0, int y1) {
        long d = 0;
        for (int x = 0; x < t.width; ++x) d += std::abs(lightness(t, x, y0) - lightness(t, x, y1));
        return static_cast<double>(d) / t.width;
    };
    auto col_step = [&](int x0, int x1) {
        long d = 0;
        for (int y = 0; y < t.height; ++y) d += std::abs(lightness(t, x0, y) - lightness(t, x1, y));
        return static_cast<double>(d) / t.height;
    };
    double inner_rows = 0.0, inner_cols = 0.0;
    for (int y = 1; y < t.height; ++y) inner_rows = std::max(inner_rows, row_step(y - 1, y));
    for (int x = 1; x < t.width; ++x) inner_cols = std::max(inner_cols, col_step(x - 1, x));
    EXPECT_LE(row_step(t.height - 1, 0), inner_rows * 1.05 + 1.0);
    EXPECT_LE(col_step(t.width - 1, 0), inner_cols * 1.05 + 1.0);
}

TEST(BarkTexture, RefusesSizesOutOfRange)
{
    EXPECT_THROW(make_bark_texture(4), InvalidInput);
    EXPECT_THROW(make_bark_texture(4096), InvalidInput);
}

} // namespace
} // namespace lobe
