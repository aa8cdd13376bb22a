#pragma once
/// \file textures.h
/// The renderer's RGBA8 textures (the leaf texture, the photo, the overlay's font): checking
/// what the caller gives, uploading it and pointing a descriptor at it. Internal to
/// app/render/.

#include <cstdint>

#include "app/render/gpu_types.h"
#include "app/render/vulkan_context.h"
#include "growth/tree_geometry.h"

namespace lobe::vk {

/// "an RGBA8 image" check shared by the leaf texture and the overlay's font: throws
/// InvalidInput naming `what` unless it is empty (0 × 0) or has width × height × 4 bytes.
/// Returns false for an empty image (the caller draws kWhiteTexel instead).
bool check_rgba(const RgbaImage& tex, const char* what);

/// What stands for "no texture": one opaque white texel.
inline const RgbaImage kWhiteTexel{1, 1, {255, 255, 255, 255}};

/// An RGBA8 sRGB texture (`tex` checked by the caller), uploaded through a staging buffer and
/// left in SHADER_READ_ONLY_OPTIMAL.
/// \throw RenderError
GpuImage upload_rgba_texture(const VulkanContext& ctx, const RgbaImage& tex);

/// Points `binding` of `set` at `texture` through `sampler`.
void write_texture_descriptor(VkDevice device, VkDescriptorSet set, VkSampler sampler, const GpuImage& texture,
                              std::uint32_t binding = 0);

} // namespace lobe::vk
