#pragma once
/// \file scene_drawer.h
/// The scene's side of a frame: the pipelines (sky, ground, opaque meshes, leaves and photos,
/// instanced leaves, translucent lobes), the leaf and photo textures, the per-mesh GPU buffer
/// cache (keyed by RenderItem::key, uploaded again only when RenderItem::version changes), and
/// the draws of one frame recorded into any render pass of the same formats
/// (docs/rendering.md, "What is drawn"). Internal to app/render/.

#include <array>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "app/render/frame_view.h"
#include "app/render/gpu_types.h"
#include "app/render/vulkan_context.h"

namespace lobe::vk {

/// Pipelines, the leaf texture, the mesh cache, and the draws of one frame.
class SceneDrawer {
public:
    /// The pipelines for `pass` (made with `format`); `instanced_leaves` as
    /// RendererOptions::instanced_leaves. \throw RenderError
    SceneDrawer(const VulkanContext& ctx, VkRenderPass pass, const FrameFormat& format, bool instanced_leaves);
    ~SceneDrawer();
    SceneDrawer(const SceneDrawer&) = delete;
    SceneDrawer& operator=(const SceneDrawer&) = delete;

    /// Makes `scene` the one drawn, as Renderer::set_scene states (app/render/renderer.h);
    /// `stats` gets what was uploaded and kept.
    /// \throw InvalidInput for a bad mesh, a repeated key or a bad texture (the last scene
    /// stays); RenderError.
    void set_scene(const RenderScene& scene, RenderStats& stats);

    /// A set layout of one texture at binding 0 (the overlay's font).
    VkDescriptorSetLayout texture_set_layout() const { return set_layout_; }
    VkSampler sampler() const { return sampler_; }

    /// The draws of one frame, inside a begun render pass of `extent`.
    void record(VkCommandBuffer cmd, const FrameView& frame, VkExtent2D extent) const;

private:
    struct GpuMesh {
        std::uint64_t version = 0;
        // Vertices (Vertex), then uint32 indices at index_offset. Instanced leaves: the shared
        // quad's four uvs (vec2), its 6 indices at index_offset, the leaves (LeafInstance) at
        // instance_offset.
        GpuBuffer buffer;
        VkDeviceSize index_offset = 0;
        std::uint32_t index_count = 0;
        VkDeviceSize instance_offset = 0;
        std::uint32_t instance_count = 0; // 0: drawn as a mesh
        RenderMaterial material = RenderMaterial::Bark;
        glm::vec4 color{1.0f};
        glm::vec3 centre{0.0f};
    };

    GpuMesh upload(const RenderItem& item, RenderStats& stats) const;

    /// A leaf mesh as instances (see as_leaf_instances): 32 bytes of uvs and 24 of indices
    /// for the shared quad, 48 bytes per leaf, instead of 4 vertices (128 bytes) and 2
    /// triangles (24 bytes) per leaf.
    GpuMesh upload_leaf_instances(const RenderItem& item, const std::vector<LeafInstance>& instances,
                                  const std::array<glm::vec2, 4>& uvs, RenderStats& stats) const;

    /// A texture of the scene and what it was made from.
    struct TextureSlot {
        GpuImage image;
        std::uint64_t version = 0;
        bool ready = false;
        bool is_real = false; // false: the white texel
    };
    static constexpr std::uint32_t kLeafTextureBinding = 0, kPhotoTextureBinding = 1; // app/render/shaders/mesh.frag

    /// Uploads `tex` into `slot` (and points `binding` at it) unless it holds that version
    /// already. The white texel stands for "no texture": a texture replacing it (or replaced
    /// by it) is uploaded whatever its version.
    void update_texture(TextureSlot& slot, std::uint32_t binding, const RgbaImage& tex, bool is_real, std::uint64_t version,
                        RenderStats& stats);

    void create(VkRenderPass pass, const FrameFormat& format);
    void destroy();

    const VulkanContext& ctx_;
    VkDescriptorSetLayout set_layout_ = VK_NULL_HANDLE;       // one texture (the overlay's set)
    VkDescriptorSetLayout scene_set_layout_ = VK_NULL_HANDLE; // leaf texture and photo
    VkPipelineLayout layout_ = VK_NULL_HANDLE;
    VkDescriptorPool descriptor_pool_ = VK_NULL_HANDLE;
    VkDescriptorSet descriptor_set_ = VK_NULL_HANDLE;
    VkSampler sampler_ = VK_NULL_HANDLE;
    VkPipeline sky_ = VK_NULL_HANDLE, ground_pipeline_ = VK_NULL_HANDLE, opaque_ = VK_NULL_HANDLE, leaf_ = VK_NULL_HANDLE,
               leaf_instanced_ = VK_NULL_HANDLE, lobe_ = VK_NULL_HANDLE;
    bool instanced_leaves_ = true;
    TextureSlot leaf_texture_, photo_texture_;
    std::unordered_map<std::uint64_t, GpuMesh> cache_;
    std::vector<std::uint64_t> draws_; // keys in scene order
    bool ground_ = true;
    float ground_y_ = 0.0f;
    Bounds bounds_;
};

} // namespace lobe::vk
