// The one translation unit that compiles tinygltf and stb_image/stb_image_write. stb is made
// static here so that another module compiling its own copy cannot clash with this one;
// everything else reaches PNG encoding through encode_png (app/export/export_scene.h) and glTF
// through tinygltf's public functions.
#define TINYGLTF_IMPLEMENTATION
#define STB_IMAGE_IMPLEMENTATION
#define STB_IMAGE_STATIC
#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STB_IMAGE_WRITE_STATIC
#include <tiny_gltf.h>

#include <algorithm>
#include <fstream>
#include <iterator>

#include "app/export/export_scene.h"
#include "core/errors.h"

namespace lobe {

namespace {
void append_bytes(void* context, void* data, int size)
{
    auto* out = static_cast<std::vector<std::uint8_t>*>(context);
    const auto* bytes = static_cast<const std::uint8_t*>(data);
    out->insert(out->end(), bytes, bytes + size);
}
} // namespace

std::vector<std::uint8_t> encode_png(const RgbaImage& image)
{
    if (image.width <= 0 || image.height <= 0 ||
        image.pixels.size() != std::size_t(image.width) * std::size_t(image.height) * 4u)
        throw InvalidInput("png: an image of " + std::to_string(image.width) + "x" + std::to_string(image.height) +
                           " with " + std::to_string(image.pixels.size()) + " bytes cannot be encoded");
    std::vector<std::uint8_t> png;
    if (stbi_write_png_to_func(append_bytes, &png, image.width, image.height, 4, image.pixels.data(),
                               image.width * 4) == 0)
        throw InvalidInput("png: encoding failed");
    return png;
}

RgbaImage read_picture_file(const std::string& path, int max_side)
{
    constexpr std::size_t kMaxBytes = 64u << 20;
    constexpr int kMaxSide = 16384;
    std::ifstream in(path, std::ios::binary);
    if (!in) throw FileError(path, "cannot open the picture");
    in.seekg(0, std::ios::end);
    const std::streamoff size = in.tellg();
    if (size < 0) throw FileError(path, "cannot read the picture");
    if (std::size_t(size) > kMaxBytes) throw FileError(path, "picture file larger than 64 MB");
    in.seekg(0);
    std::vector<unsigned char> bytes(static_cast<std::size_t>(size));
    if (!bytes.empty() && !in.read(reinterpret_cast<char*>(bytes.data()), size)) throw FileError(path, "cannot read the picture");
    int w = 0, h = 0, channels = 0;
    if (bytes.empty() || !stbi_info_from_memory(bytes.data(), int(bytes.size()), &w, &h, &channels))
        throw FileError(path, "not a PNG or JPEG picture");
    if (w <= 0 || h <= 0 || w > kMaxSide || h > kMaxSide)
        throw FileError(path, "picture of " + std::to_string(w) + "x" + std::to_string(h) + " pixels (at most 16384 a side)");
    unsigned char* data = stbi_load_from_memory(bytes.data(), int(bytes.size()), &w, &h, &channels, 4);
    if (!data) throw FileError(path, std::string("cannot decode the picture: ") + stbi_failure_reason());
    // A box filter down to max_side: a reference photo needs no more texels than a panel shows.
    const int step = std::max(1, (std::max(w, h) + std::max(1, max_side) - 1) / std::max(1, max_side));
    RgbaImage out;
    out.width = std::max(1, w / step);
    out.height = std::max(1, h / step);
    out.pixels.assign(std::size_t(out.width) * std::size_t(out.height) * 4u, 0);
    for (int y = 0; y < out.height; ++y)
        for (int x = 0; x < out.width; ++x)
            for (int c = 0; c < 4; ++c) {
                unsigned sum = 0, n = 0;
                for (int dy = 0; dy < step && y * step + dy < h; ++dy)
                    for (int dx = 0; dx < step && x * step + dx < w; ++dx, ++n)
                        sum += data[(std::size_t(y * step + dy) * std::size_t(w) + std::size_t(x * step + dx)) * 4u + std::size_t(c)];
                out.pixels[(std::size_t(y) * std::size_t(out.width) + std::size_t(x)) * 4u + std::size_t(c)] =
                    static_cast<std::uint8_t>(n ? sum / n : 0);
            }
    stbi_image_free(data);
    return out;
}

} // namespace lobe
