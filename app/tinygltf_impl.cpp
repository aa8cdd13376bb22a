// The one translation unit that compiles tinygltf and stb_image/stb_image_write. stb is made
// static here so that another module compiling its own copy cannot clash with this one;
// everything else reaches PNG encoding through encode_png (app/export_scene.h) and glTF
// through tinygltf's public functions.
#define TINYGLTF_IMPLEMENTATION
#define STB_IMAGE_IMPLEMENTATION
#define STB_IMAGE_STATIC
#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STB_IMAGE_WRITE_STATIC
#include <tiny_gltf.h>

#include "app/export_scene.h"
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

} // namespace lobe
