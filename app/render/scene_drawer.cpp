// The scene's pipelines, textures, mesh cache and draws (app/render/scene_drawer.h).
#include "app/render/scene_drawer.h"

#include <algorithm>
#include <cstddef>
#include <initializer_list>
#include <string>
#include <unordered_set>
#include <utility>

#include <glm/geometric.hpp>
#include <glm/matrix.hpp>

#include "app/render/leaf_instances.h"
#include "app/render/pipelines.h"
#include "app/render/textures.h"
#include "app/render/vk_check.h"

namespace lobe::vk {

SceneDrawer::SceneDrawer(const VulkanContext& ctx, VkRenderPass pass, const FrameFormat& format, bool instanced_leaves)
    : ctx_(ctx), instanced_leaves_(instanced_leaves)
{
    try {
        create(pass, format);
    } catch (...) {
        destroy();
        throw;
    }
}

SceneDrawer::~SceneDrawer() { destroy(); }

void SceneDrawer::set_scene(const RenderScene& scene, RenderStats& stats)
{
    // Check everything before touching the GPU: a bad scene leaves the last one drawn. A
    // mesh the cache holds under the same key and version was checked when it was uploaded
    // (the interactive apps pass their whole scene every frame).
    std::unordered_set<std::uint64_t> keys;
    for (const RenderItem& item : scene.items) {
        if (!keys.insert(item.key).second)
            throw InvalidInput("render: mesh key " + std::to_string(item.key) + " appears twice in the scene");
        if (auto cached = cache_.find(item.key); cached != cache_.end() && cached->second.version == item.version)
            continue;
        const SurfaceGeometry& g = item.geometry;
        const std::size_t n = g.positions.size();
        if (g.normals.size() != n || (!g.uvs.empty() && g.uvs.size() != n))
            throw InvalidInput("render: mesh " + std::to_string(item.key) + " has " + std::to_string(n) +
                               " positions but " + std::to_string(g.normals.size()) + " normals and " +
                               std::to_string(g.uvs.size()) + " uvs");
        for (const auto& t : g.triangles)
            for (std::uint32_t i : t)
                if (i >= n)
                    throw InvalidInput("render: mesh " + std::to_string(item.key) + " has a triangle index " +
                                       std::to_string(i) + " out of range (" + std::to_string(n) + " vertices)");
    }
    const bool has_leaf_texture = check_rgba(scene.leaf_texture, "a leaf texture");
    const bool has_photo_texture = check_rgba(scene.photo_texture, "a photo texture");

    stats.meshes_uploaded = stats.meshes_kept = stats.bytes_uploaded = stats.leaf_instances = 0;
    for (auto it = cache_.begin(); it != cache_.end();) {
        if (!keys.count(it->first)) {
            ctx_.destroy(it->second.buffer);
            it = cache_.erase(it);
        } else {
            ++it;
        }
    }
    draws_.clear();
    for (const RenderItem& item : scene.items) {
        auto it = cache_.find(item.key);
        // Instances are drawn by the leaf pipeline only: an instanced mesh given another
        // material is uploaded again, as a mesh.
        if (it != cache_.end() && it->second.version == item.version &&
            (it->second.instance_count == 0 || item.material == RenderMaterial::Leaf)) {
            ++stats.meshes_kept;
        } else {
            if (it != cache_.end()) ctx_.destroy(it->second.buffer);
            it = cache_.insert_or_assign(item.key, upload(item, stats)).first;
            ++stats.meshes_uploaded;
        }
        it->second.material = item.material;
        it->second.color = glm::vec4(item.color[0], item.color[1], item.color[2], item.color[3]);
        if (it->second.index_count > 0) draws_.push_back(item.key);
        stats.leaf_instances += it->second.instance_count;
    }
    update_texture(leaf_texture_, kLeafTextureBinding, has_leaf_texture ? scene.leaf_texture : kWhiteTexel, has_leaf_texture,
                   scene.leaf_texture_version, stats);
    update_texture(photo_texture_, kPhotoTextureBinding, has_photo_texture ? scene.photo_texture : kWhiteTexel,
                   has_photo_texture, scene.photo_texture_version, stats);
    ground_ = scene.ground;
    bounds_ = scene.ground_area.empty() ? scene_bounds(scene) : scene.ground_area;
    ground_y_ = scene.ground_y;
}

void SceneDrawer::record(VkCommandBuffer cmd, const FrameView& frame, VkExtent2D extent) const
{
    const glm::mat4& view_proj = frame.view_proj;
    const glm::vec4 eye(frame.eye, 1.0f);

    VkViewport viewport{0.0f, 0.0f, float(extent.width), float(extent.height), 0.0f, 1.0f};
    VkRect2D scissor{{0, 0}, extent};
    vkCmdSetViewport(cmd, 0, 1, &viewport);
    vkCmdSetScissor(cmd, 0, 1, &scissor);
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, layout_, 0, 1, &descriptor_set_, 0, nullptr);
    auto push = [&](const PushBlock& p) {
        vkCmdPushConstants(cmd, layout_, VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0, sizeof(PushBlock), &p);
    };

    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, sky_);
    push({glm::inverse(view_proj), glm::vec4(0.0f), eye, glm::vec4(0.0f)});
    vkCmdDraw(cmd, 3, 1, 0, 0);

    if (ground_) {
        Bounds b = bounds_;
        if (b.empty()) b = Bounds{glm::vec3(-0.5f), glm::vec3(0.5f)};
        const glm::vec3 size = b.hi - b.lo;
        const float extent_m = std::max({size.x, size.y, size.z, 0.1f});
        const float half = std::max(8.0f * extent_m, 4.0f);
        const float cell = extent_m > 3.0f ? 1.0f : 0.1f; // 10 cm cells (1 m for big scenes), a stronger line every 10
        vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, ground_pipeline_);
        push({view_proj, glm::vec4(0.5f * (b.lo.x + b.hi.x), ground_y_, 0.5f * (b.lo.z + b.hi.z), half), eye,
              glm::vec4(cell, 0.0f, 0.0f, 0.0f)});
        vkCmdDraw(cmd, 6, 1, 0, 0);
    }

    auto draw = [&](const GpuMesh& m) {
        if (m.instance_count > 0) {
            // The shared quad's uvs (binding 0) and the leaves (binding 1) in one buffer.
            const VkBuffer buffers[2] = {m.buffer.buffer, m.buffer.buffer};
            const VkDeviceSize offsets[2] = {0, m.instance_offset};
            vkCmdBindVertexBuffers(cmd, 0, 2, buffers, offsets);
        } else {
            const VkDeviceSize offset = 0;
            vkCmdBindVertexBuffers(cmd, 0, 1, &m.buffer.buffer, &offset);
        }
        vkCmdBindIndexBuffer(cmd, m.buffer.buffer, m.index_offset, VK_INDEX_TYPE_UINT32);
        push({view_proj, m.color, eye, glm::vec4(float(static_cast<int>(m.material)), 0.0f, 0.0f, 0.0f)});
        vkCmdDrawIndexed(cmd, m.index_count, std::max(m.instance_count, 1u), 0, 0, 0);
    };
    // The meshes of `materials` in scene order; instanced leaves with leaf_instanced_.
    auto draw_all = [&](VkPipeline pipeline, std::initializer_list<RenderMaterial> materials) {
        VkPipeline bound = VK_NULL_HANDLE;
        for (std::uint64_t key : draws_) {
            const GpuMesh& m = cache_.at(key);
            if (std::find(materials.begin(), materials.end(), m.material) == materials.end()) continue;
            const VkPipeline wanted = m.instance_count > 0 ? leaf_instanced_ : pipeline;
            if (wanted != bound) vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, wanted);
            bound = wanted;
            draw(m);
        }
    };
    draw_all(opaque_, {RenderMaterial::Bark, RenderMaterial::Stroke});
    // Leaves and photos: opaque and two-sided (mesh.frag tells them apart).
    draw_all(leaf_, {RenderMaterial::Leaf, RenderMaterial::Photo});
    // Translucent lobes last, far to near (by their centres), without depth writes.
    std::vector<std::pair<float, std::uint64_t>> lobes;
    for (std::uint64_t key : draws_) {
        const GpuMesh& m = cache_.at(key);
        if (m.material == RenderMaterial::Lobe) lobes.emplace_back(-glm::length(m.centre - frame.eye), key);
    }
    std::sort(lobes.begin(), lobes.end());
    if (!lobes.empty()) vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, lobe_);
    for (const auto& [distance, key] : lobes) draw(cache_.at(key));
}

SceneDrawer::GpuMesh SceneDrawer::upload(const RenderItem& item, RenderStats& stats) const
{
    const SurfaceGeometry& g = item.geometry;
    GpuMesh m;
    m.version = item.version;
    m.index_count = static_cast<std::uint32_t>(g.triangles.size() * 3u);
    if (g.triangles.empty()) return m;
    if (instanced_leaves_ && item.material == RenderMaterial::Leaf) {
        std::vector<LeafInstance> instances;
        std::array<glm::vec2, 4> uvs;
        if (as_leaf_instances(g, instances, uvs)) return upload_leaf_instances(item, instances, uvs, stats);
    }
    std::vector<Vertex> vertices(g.positions.size());
    Bounds b;
    for (std::size_t i = 0; i < vertices.size(); ++i) {
        const glm::vec3& p = g.positions[i];
        const glm::vec3& n = g.normals[i];
        const glm::vec2 uv = g.uvs.empty() ? glm::vec2(0.0f) : g.uvs[i];
        vertices[i] = {{p.x, p.y, p.z}, {n.x, n.y, n.z}, {uv.x, uv.y}};
        b.add(p);
    }
    m.centre = 0.5f * (b.lo + b.hi);
    const std::size_t vertex_bytes = vertices.size() * sizeof(Vertex);
    m.index_offset = (vertex_bytes + 15u) & ~VkDeviceSize(15u);
    const std::size_t index_bytes = g.triangles.size() * sizeof(g.triangles[0]);
    m.buffer = ctx_.create_buffer(m.index_offset + index_bytes,
                                  VK_BUFFER_USAGE_VERTEX_BUFFER_BIT | VK_BUFFER_USAGE_INDEX_BUFFER_BIT,
                                  VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    try {
        ctx_.write(m.buffer, 0, vertices.data(), vertex_bytes);
        ctx_.write(m.buffer, m.index_offset, g.triangles.data(), index_bytes);
    } catch (...) {
        ctx_.destroy(m.buffer);
        throw;
    }
    stats.bytes_uploaded += vertex_bytes + index_bytes;
    return m;
}

SceneDrawer::GpuMesh SceneDrawer::upload_leaf_instances(const RenderItem& item, const std::vector<LeafInstance>& instances,
                                                        const std::array<glm::vec2, 4>& uvs, RenderStats& stats) const
{
    GpuMesh m;
    m.version = item.version;
    Bounds b;
    for (const glm::vec3& p : item.geometry.positions) b.add(p);
    m.centre = 0.5f * (b.lo + b.hi);
    static constexpr std::uint32_t kQuad[6] = {0, 1, 2, 0, 2, 3}; // leaves.cpp's two triangles
    static_assert(sizeof(uvs) == 32);
    m.index_offset = sizeof(uvs);
    m.index_count = 6;
    m.instance_offset = 64;
    m.instance_count = static_cast<std::uint32_t>(instances.size());
    const std::size_t instance_bytes = instances.size() * sizeof(LeafInstance);
    m.buffer = ctx_.create_buffer(m.instance_offset + instance_bytes,
                                  VK_BUFFER_USAGE_VERTEX_BUFFER_BIT | VK_BUFFER_USAGE_INDEX_BUFFER_BIT,
                                  VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    try {
        ctx_.write(m.buffer, 0, uvs.data(), sizeof(uvs));
        ctx_.write(m.buffer, m.index_offset, kQuad, sizeof(kQuad));
        ctx_.write(m.buffer, m.instance_offset, instances.data(), instance_bytes);
    } catch (...) {
        ctx_.destroy(m.buffer);
        throw;
    }
    stats.bytes_uploaded += sizeof(uvs) + sizeof(kQuad) + instance_bytes;
    return m;
}

void SceneDrawer::update_texture(TextureSlot& slot, std::uint32_t binding, const RgbaImage& tex, bool is_real,
                                 std::uint64_t version, RenderStats& stats)
{
    if (!is_real) version = 0;
    if (slot.ready && slot.is_real == is_real && slot.version == version) return;
    GpuImage fresh = upload_rgba_texture(ctx_, tex);
    ctx_.destroy(slot.image);
    slot.image = fresh;
    slot.version = version;
    slot.is_real = is_real;
    slot.ready = true;
    stats.bytes_uploaded += tex.pixels.size();
    write_texture_descriptor(ctx_.device(), descriptor_set_, sampler_, slot.image, binding);
}

void SceneDrawer::create(VkRenderPass pass, const FrameFormat& format)
{
    const VkDevice dev = ctx_.device();
    // One texture (the overlay's font), and the scene's two: the leaf texture and the photo.
    const VkDescriptorSetLayoutBinding bindings[2] = {
        {kLeafTextureBinding, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1, VK_SHADER_STAGE_FRAGMENT_BIT, nullptr},
        {kPhotoTextureBinding, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1, VK_SHADER_STAGE_FRAGMENT_BIT, nullptr},
    };
    auto set_layout = vk_struct<VkDescriptorSetLayoutCreateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO);
    set_layout.bindingCount = 1;
    set_layout.pBindings = bindings;
    CHECK_VKCMD(vkCreateDescriptorSetLayout(dev, &set_layout, nullptr, &set_layout_));
    set_layout.bindingCount = 2;
    CHECK_VKCMD(vkCreateDescriptorSetLayout(dev, &set_layout, nullptr, &scene_set_layout_));
    layout_ = create_pipeline_layout(dev, scene_set_layout_,
                                     {VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0, sizeof(PushBlock)});
    allocate_sampler_set(dev, scene_set_layout_, descriptor_pool_, descriptor_set_, 2);
    auto sampler = vk_struct<VkSamplerCreateInfo>(VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO);
    sampler.magFilter = VK_FILTER_LINEAR;
    sampler.minFilter = VK_FILTER_LINEAR;
    sampler.mipmapMode = VK_SAMPLER_MIPMAP_MODE_NEAREST;
    sampler.addressModeU = sampler.addressModeV = sampler.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
    sampler.maxLod = 0.0f;
    CHECK_VKCMD(vkCreateSampler(dev, &sampler, nullptr, &sampler_));

    VkVertexInputBindingDescription vertex_binding{0, sizeof(Vertex), VK_VERTEX_INPUT_RATE_VERTEX};
    const VkVertexInputAttributeDescription attributes[3] = {
        {0, 0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(Vertex, position)},
        {1, 0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(Vertex, normal)},
        {2, 0, VK_FORMAT_R32G32_SFLOAT, offsetof(Vertex, uv)},
    };
    auto mesh = vk_struct<VkPipelineVertexInputStateCreateInfo>(VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO);
    mesh.vertexBindingDescriptionCount = 1;
    mesh.pVertexBindingDescriptions = &vertex_binding;
    mesh.vertexAttributeDescriptionCount = 3;
    mesh.pVertexAttributeDescriptions = attributes;
    auto make = [&](const PipelineState& state) { return create_pipeline(dev, pass, format, layout_, state); };
    sky_ = make({"sky.vert", "sky.frag", nullptr, VK_CULL_MODE_NONE, false, false, false});
    ground_pipeline_ = make({"ground.vert", "ground.frag", nullptr, VK_CULL_MODE_NONE, true, true, false});
    opaque_ = make({"mesh.vert", "mesh.frag", &mesh, VK_CULL_MODE_BACK_BIT, true, true, false});
    leaf_ = make({"mesh.vert", "mesh.frag", &mesh, VK_CULL_MODE_NONE, true, true, false});
    // Instanced leaves: the shared quad's uvs per vertex, the leaves per instance.
    const VkVertexInputBindingDescription leaf_bindings[2] = {
        {0, sizeof(glm::vec2), VK_VERTEX_INPUT_RATE_VERTEX},
        {1, sizeof(LeafInstance), VK_VERTEX_INPUT_RATE_INSTANCE},
    };
    const VkVertexInputAttributeDescription leaf_attributes[5] = {
        {0, 0, VK_FORMAT_R32G32_SFLOAT, 0},
        {1, 1, VK_FORMAT_R32G32B32_SFLOAT, offsetof(LeafInstance, corner0)},
        {2, 1, VK_FORMAT_R32G32B32_SFLOAT, offsetof(LeafInstance, corner1)},
        {3, 1, VK_FORMAT_R32G32B32_SFLOAT, offsetof(LeafInstance, corner3)},
        {4, 1, VK_FORMAT_R32G32B32_SFLOAT, offsetof(LeafInstance, normal)},
    };
    auto leaf_input = vk_struct<VkPipelineVertexInputStateCreateInfo>(VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO);
    leaf_input.vertexBindingDescriptionCount = 2;
    leaf_input.pVertexBindingDescriptions = leaf_bindings;
    leaf_input.vertexAttributeDescriptionCount = 5;
    leaf_input.pVertexAttributeDescriptions = leaf_attributes;
    leaf_instanced_ = make({"leaf.vert", "mesh.frag", &leaf_input, VK_CULL_MODE_NONE, true, true, false});
    lobe_ = make({"mesh.vert", "mesh.frag", &mesh, VK_CULL_MODE_NONE, true, false, true});
}

void SceneDrawer::destroy()
{
    const VkDevice dev = ctx_.device();
    for (auto& [key, mesh] : cache_) ctx_.destroy(mesh.buffer);
    cache_.clear();
    ctx_.destroy(leaf_texture_.image);
    ctx_.destroy(photo_texture_.image);
    for (VkPipeline p : {sky_, ground_pipeline_, opaque_, leaf_, leaf_instanced_, lobe_})
        if (p) vkDestroyPipeline(dev, p, nullptr);
    if (sampler_) vkDestroySampler(dev, sampler_, nullptr);
    if (descriptor_pool_) vkDestroyDescriptorPool(dev, descriptor_pool_, nullptr);
    if (layout_) vkDestroyPipelineLayout(dev, layout_, nullptr);
    if (set_layout_) vkDestroyDescriptorSetLayout(dev, set_layout_, nullptr);
    if (scene_set_layout_) vkDestroyDescriptorSetLayout(dev, scene_set_layout_, nullptr);
}

} // namespace lobe::vk
