#pragma once
/// \file gpu_types.h
/// The small types the renderer's parts share: Vulkan struct and handle helpers, GPU buffers
/// and images, the push-constant block and the vertex layouts of app/render/shaders/, and the
/// formats of a frame. Internal to app/render/ (it includes Vulkan; app/render/renderer.h does
/// not).

#include <cstdint>
#include <type_traits>

#include <glm/mat4x4.hpp>
#include <glm/vec4.hpp>
#include <vulkan/vulkan.h>

namespace lobe::vk {

/// A zero-initialised Vulkan info struct with its sType set.
template <class T>
T vk_struct(VkStructureType type)
{
    T s{};
    s.sType = type;
    return s;
}

/// The format of every picture the renderer draws: 8-bit RGBA, sRGB-encoded.
inline constexpr VkFormat kColorFormat = VK_FORMAT_R8G8B8A8_SRGB;

/// A Vulkan handle from an integer, e.g. the VkSurfaceKHR attach_window's callback returns or
/// the VkInstance a RendererOptions::vulkan_hooks function returns (handles are pointers on
/// 64-bit builds; non-dispatchable ones are 64-bit integers on 32-bit ones).
template <class Handle>
Handle handle_from_integer(std::uint64_t v)
{
    if constexpr (std::is_pointer_v<Handle>)
        return reinterpret_cast<Handle>(static_cast<std::uintptr_t>(v));
    else
        return static_cast<Handle>(v);
}

/// The integer of a Vulkan handle (the inverse of handle_from_integer).
template <class Handle>
std::uint64_t handle_to_integer(Handle h)
{
    if constexpr (std::is_pointer_v<Handle>)
        return static_cast<std::uint64_t>(reinterpret_cast<std::uintptr_t>(h));
    else
        return static_cast<std::uint64_t>(h);
}

/// What every scene pipeline gets (app/render/shaders/*: the same 112-byte block, read per shader).
struct PushBlock {
    glm::mat4 matrix;   // view-projection (sky: its inverse)
    glm::vec4 color;    // material colour (ground: centre and half size)
    glm::vec4 eye;      // camera position
    glm::vec4 params;   // x: material (mesh) or cell size (ground)
};
static_assert(sizeof(PushBlock) == 112);

/// One vertex of a mesh (app/render/shaders/mesh.vert): world position and normal, texture coordinates.
struct Vertex {
    float position[3];
    float normal[3];
    float uv[2];
};
static_assert(sizeof(Vertex) == 32);

/// One leaf quad drawn instanced (app/render/shaders/leaf.vert): corners 0, 1 and 3 of its four
/// vertices (corner 2 is 1 + (3 − 0)) and its normal.
struct LeafInstance {
    float corner0[3];
    float corner1[3];
    float corner3[3];
    float normal[3];
};
static_assert(sizeof(LeafInstance) == 48);

/// A buffer and its memory; `size` in bytes.
struct GpuBuffer {
    VkBuffer buffer = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    VkDeviceSize size = 0;
};

/// An image, its memory and its view.
struct GpuImage {
    VkImage image = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    VkImageView view = VK_NULL_HANDLE;
};

/// Semaphores of a submit: waited on at `wait_stage` before it runs, signalled after it.
struct SubmitSync {
    VkSemaphore wait = VK_NULL_HANDLE;
    VkPipelineStageFlags wait_stage = VK_PIPELINE_STAGE_TRANSFER_BIT;
    VkSemaphore signal = VK_NULL_HANDLE;
};

/// Formats and sample count shared by the render pass, the targets and the pipelines.
struct FrameFormat {
    VkFormat color = kColorFormat;
    VkFormat depth = VK_FORMAT_D32_SFLOAT;
    VkSampleCountFlagBits samples = VK_SAMPLE_COUNT_4_BIT;
};

inline bool multisampled(const FrameFormat& f) { return f.samples != VK_SAMPLE_COUNT_1_BIT; }

} // namespace lobe::vk
