#pragma once
/// \file renderer.h
/// Pictures of a tree and its sketch: a Vulkan renderer behind a plain C++ interface (no
/// Vulkan type here; the Vulkan code is in app/render/renderer.cpp and the parts it puts
/// together, app/render/vulkan_context.h and the headers beside it). What it draws, the camera
/// framing and device selection are described in docs/rendering.md.
///
/// ```cpp
/// Renderer renderer;                       // instance + device (GPU, else lavapipe)
/// renderer.set_scene(scene);               // uploads only the meshes whose version changed
/// RgbaImage png_pixels = renderer.render(frame_view(scene_bounds(scene), front_view(), 16.0f / 9.0f), 1280, 720);
/// ```
///
/// In a window (GLFW; the window must outlive the Renderer, which owns the surface):
/// ```cpp
/// RendererOptions o;
/// o.presentation = true;
/// o.instance_extensions = {names from glfwGetRequiredInstanceExtensions};
/// Renderer renderer(o);
/// renderer.attach_window([&](std::uint64_t instance) { /* glfwCreateWindowSurface */ return surface; });
/// renderer.set_overlay(panel);             // optional 2D triangles over the scene (Dear ImGui)
/// renderer.present(camera, fb_width, fb_height);  // false when minimised (0 × 0)
/// ```
///
/// For a headset (OpenXR, XR_KHR_vulkan_enable2; docs/rendering.md):
/// ```cpp
/// RendererOptions o;
/// o.vulkan_hooks = {create_instance, physical_device, create_device};  // xrCreateVulkanInstanceKHR, ...
/// Renderer renderer(o);
/// VulkanHandles h = renderer.vulkan_handles();  // XrGraphicsBindingVulkan2KHR
/// renderer.render_to(eye_view, {swapchain_image, VK_FORMAT_R8G8B8A8_SRGB, width, height, 0});  // per eye
/// ```

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>

#include "core/errors.h"
#include "growth/tree_geometry.h"

namespace lobe {

/// A Vulkan call failed; the message names the call, its result and file:line.
class RenderError : public Error {
public:
    using Error::Error;
};

/// No Vulkan instance or no usable device: the message (one line) names what to install.
class RenderUnavailable : public RenderError {
public:
    using RenderError::RenderError;
};

/// How a mesh is shaded (app/render/shaders/mesh.frag).
enum class RenderMaterial : std::uint8_t {
    Bark,   ///< opaque, lit, back faces culled
    Leaf,   ///< alpha-tested from the leaf texture, two-sided; leaf quads drawn instanced (RendererOptions::instanced_leaves)
    Lobe,   ///< translucent (alpha blend, after the opaque meshes, no depth write), two-sided
    Stroke, ///< opaque, nearly unlit (stroke tubes)
    Photo,  ///< opaque, unlit, two-sided, coloured by RenderScene::photo_texture at the item's uvs (times `color`)
};

/// One mesh of a scene.
struct RenderItem {
    std::uint64_t key = 0;     ///< names the mesh across set_scene calls (unique in a scene)
    std::uint64_t version = 0; ///< changes whenever `geometry` changes: equal key and version are not re-uploaded
    RenderMaterial material = RenderMaterial::Bark;
    std::array<float, 4> color{1.0f, 1.0f, 1.0f, 1.0f}; ///< linear RGBA (alpha used by lobes)
    SurfaceGeometry geometry; ///< world space (metres, +Y up); uvs used by leaves and photos only (may be empty otherwise; v = 0 is a texture's top row)
};

/// Axis-aligned bounding box; empty when lo > hi.
struct Bounds {
    glm::vec3 lo{1e30f};
    glm::vec3 hi{-1e30f};
    bool empty() const { return lo.x > hi.x || lo.y > hi.y || lo.z > hi.z; }
    void add(const glm::vec3& p);
};

/// Everything a picture shows besides the sky.
struct RenderScene {
    std::vector<RenderItem> items;
    RgbaImage leaf_texture;                ///< RGBA8 (sRGB colours, alpha cut-out); empty: white
    std::uint64_t leaf_texture_version = 0; ///< as RenderItem::version
    RgbaImage photo_texture;                ///< RGBA8 (sRGB colours) for RenderMaterial::Photo; empty: white
    std::uint64_t photo_texture_version = 0; ///< as RenderItem::version
    bool ground = true;                    ///< the ground grid at `ground_y`
    float ground_y = 0.0f;                 ///< height of the trunk base
    /// What the ground grid is centred under and sized by (8 × its largest side, at least
    /// 4 m across each way); empty: the items' bounds.
    Bounds ground_area;
};

/// Bounds of every item of `scene` (the ground excluded).
Bounds scene_bounds(const RenderScene& scene);

/// A perspective camera.
struct Camera {
    glm::vec3 eye{0.0f, 0.0f, 1.0f};
    glm::vec3 target{0.0f};
    glm::vec3 up{0.0f, 1.0f, 0.0f};
    float fov_y_deg = 30.0f;
    float near_m = 0.01f;
    float far_m = 100.0f;
};

/// Where a camera looks from: the direction it looks along is −(cos e · sin a, sin e, cos e · cos a)
/// for azimuth a and elevation e, so azimuth 0 looks along −Z and azimuth 90° along −X.
struct ViewAngles {
    float azimuth_deg = 0.0f;
    float elevation_deg = 0.0f;
};
ViewAngles front_view(); ///< looks along −Z (from +Z), horizontally
ViewAngles side_view();  ///< looks along −X (from +X), horizontally
ViewAngles top_view();   ///< looks down −Y; −Z is up in the picture

/// A camera looking at the centre of `bounds` from `view`, as close as it can be with every
/// corner of the box inside the frame (plus a margin of `margin` of the frame on each side).
/// `aspect` is width / height. An empty box frames a 1 m box at the origin.
Camera frame_view(const Bounds& bounds, const ViewAngles& view, float aspect, float fov_y_deg = 30.0f,
                  float margin = 0.06f);

/// One vertex of the 2D overlay: window pixels (origin top-left, y down), texture coordinates
/// into Overlay::font, and a colour, sRGB, bytes R, G, B, A in memory (Dear ImGui's IM_COL32).
struct OverlayVertex {
    float x = 0, y = 0, u = 0, v = 0;
    std::uint32_t rgba = 0xffffffffu;
};

/// One draw of the overlay: indices [first_index, first_index + index_count) of
/// Overlay::indices, each plus vertex_offset naming a vertex; only pixels whose centre lies in
/// clip = x0, y0, x1, y1 (pixels, clamped to the frame) are drawn.
struct OverlayCommand {
    std::uint32_t first_index = 0, index_count = 0;
    std::int32_t vertex_offset = 0;
    float clip[4]{};
};

/// 2D triangles drawn over the 3D scene, in window pixels (origin top-left, y down), e.g. a
/// Dear ImGui panel's draw data converted by the caller. Alpha blended, no depth, in order.
struct Overlay {
    std::vector<OverlayVertex> vertices;
    std::vector<std::uint32_t> indices;
    std::vector<OverlayCommand> commands;
    RgbaImage font;                 ///< RGBA8 atlas the uvs index (sRGB colours, linear alpha); empty: one white texel
    std::uint64_t font_version = 0; ///< re-uploaded only when this (or whether there is a font) changes
};

struct RendererOptions {
    int samples = 4;             ///< MSAA samples (1, 2, 4, 8); lowered to what the device supports
    bool prefer_software = false; ///< pick the CPU device (lavapipe) even when a GPU is present
    /// Instance extensions to enable, e.g. what glfwGetRequiredInstanceExtensions names
    /// (VK_KHR_surface and the platform's surface extension).
    std::vector<std::string> instance_extensions;
    /// Enable VK_KHR_swapchain: only devices that have it are chosen. Needed by attach_window.
    bool presentation = false;
    /// Draw a RenderMaterial::Leaf mesh made of leaf quads as growth/leaves.cpp emits them
    /// (4 vertices and 2 triangles per quad, parallelograms, one normal per quad, the same uvs
    /// on every quad) instanced: one shared quad, one instance per leaf. Any other leaf mesh is
    /// drawn as an ordinary mesh. false: every leaf mesh as an ordinary mesh (the reference).
    bool instanced_leaves = true;
    /// Where the Vulkan instance and device come from. Empty (the default): the renderer
    /// makes them itself. Set (all three): an OpenXR runtime makes them
    /// (XR_KHR_vulkan_enable2's xrCreateVulkanInstanceKHR, xrGetVulkanGraphicsDevice2KHR,
    /// xrCreateVulkanDeviceKHR), as `lobesketch vr` needs. The renderer still fills the create
    /// infos (API version, extensions, queues) and owns and destroys what comes back.
    /// The renderer calls Vulkan through the loader it links (libvulkan's exported functions),
    /// so the hooks must make the objects through that loader too: pass `vkGetInstanceProcAddr`
    /// as XrVulkanInstanceCreateInfoKHR::pfnGetInstanceProcAddr. With hooks, `prefer_software`
    /// is ignored, the queue is the first graphics queue family of the hooks' physical device,
    /// and `presentation` needs VK_KHR_swapchain on it. A hook returning 0 makes the
    /// constructor throw RenderUnavailable (one line naming the hook and the VkResult); only
    /// some of the three set is a RenderError.
    struct VulkanHooks {
        /// Gets a `const VkInstanceCreateInfo*`; returns the VkInstance as an integer, or 0
        /// with `vk_result` (a VkResult) saying why.
        std::function<std::uint64_t(const void* instance_create_info, int& vk_result)> create_instance;
        /// Gets the VkInstance; returns the VkPhysicalDevice the runtime wants (0: none).
        std::function<std::uint64_t(std::uint64_t vk_instance)> physical_device;
        /// Gets the VkPhysicalDevice and a `const VkDeviceCreateInfo*`; returns the VkDevice,
        /// or 0 with `vk_result` saying why.
        std::function<std::uint64_t(std::uint64_t vk_physical_device, const void* device_create_info, int& vk_result)>
            create_device;
        bool empty() const { return !create_instance; }
    } vulkan_hooks;
};

/// The renderer's Vulkan objects as integers, for an OpenXR session's graphics binding
/// (XrGraphicsBindingVulkan2KHR) and for swapchain images made on its device.
struct VulkanHandles {
    std::uint64_t instance = 0, physical_device = 0, device = 0;
    std::uint32_t queue_family = 0, queue_index = 0;
};

/// One eye of a stereo view as OpenXR gives it (XrView): the eye's pose in world space and
/// its field of view as four angles in radians (left and down negative), so asymmetric
/// frusta are drawn exactly.
struct EyeView {
    glm::vec3 position{0.0f};
    glm::quat orientation{1.0f, 0.0f, 0.0f, 0.0f}; ///< −Z is the viewing direction, +Y up
    float angle_left = -0.785f, angle_right = 0.785f, angle_up = 0.785f, angle_down = -0.785f;
    float near_m = 0.05f;
    float far_m = 100.0f;
};

/// An image the caller owns that the renderer draws into (an OpenXR swapchain image):
/// a 2D colour image on the renderer's device, in VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL
/// before and after.
/// The picture is copied (same format, R8G8B8A8_SRGB) or blitted (the others) into it, so the
/// image needs TRANSFER_DST usage (XR_SWAPCHAIN_USAGE_TRANSFER_DST_BIT). An sRGB image gets
/// the picture's sRGB bytes (channels in its order); a UNORM one gets linear colours (what a
/// compositor expects of a UNORM swapchain; 8-bit linear bands in the darks: prefer sRGB).
struct ExternalImage {
    std::uint64_t vk_image = 0;
    int vk_format = 0;   ///< a VkFormat: R8G8B8A8 or B8G8R8A8, UNORM or SRGB
    int width = 0, height = 0;
    int array_layer = 0;
};

/// How much GPU upload the last set_scene did, and what the last render took.
struct RenderStats {
    std::size_t meshes_uploaded = 0; ///< by the last set_scene
    std::size_t meshes_kept = 0;     ///< cached meshes the last set_scene did not touch
    std::size_t bytes_uploaded = 0;  ///< by the last set_scene (vertices, indices, instances, texture)
    std::size_t leaf_instances = 0;  ///< leaf quads of the scene set last that are drawn instanced
    double record_ms = 0.0;          ///< CPU time recording the last frame's command buffer
    double gpu_ms = 0.0;             ///< submit to fence of the last frame (drawing, resolve, copy or blit)
};

/// Loads the Vulkan drivers once (a throwaway instance) and keeps them loaded until the
/// process ends, as every Renderer does for the drivers it loads. Call it before other code
/// enumerates Vulkan (GLFW's glfwGetRequiredInstanceExtensions loads and unloads every
/// driver, and Mesa's drivers leave state behind each time they are unloaded). Does nothing
/// when no Vulkan instance can be made.
void keep_vulkan_drivers_loaded();

/// A Vulkan renderer with an offscreen target. Not thread-safe: one thread uses it.
class Renderer {
public:
    /// Creates the Vulkan instance and device: the first discrete GPU, else an integrated
    /// one, else any other, else the CPU (lavapipe); with `presentation`, only among devices
    /// with VK_KHR_swapchain. Sets XDG_RUNTIME_DIR to a private temp folder when it is unset
    /// (lavapipe warns without it).
    /// \throw RenderUnavailable when no instance or no device can be made, an instance
    /// extension is missing, or `presentation` and no device can present; RenderError.
    explicit Renderer(const RendererOptions& options = {});
    ~Renderer();
    Renderer(const Renderer&) = delete;
    Renderer& operator=(const Renderer&) = delete;

    const std::string& device_name() const; ///< e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"
    bool is_software() const;               ///< the device is a CPU implementation
    int samples() const;                    ///< MSAA samples in use

    /// Makes `scene` the one drawn. Meshes whose key and version are cached stay on the GPU;
    /// new or changed ones are uploaded; ones no longer in the scene are freed.
    /// \throw InvalidInput for a mesh with mismatched array sizes or out-of-range indices,
    /// repeated keys, or a texture whose byte count is not width × height × 4.
    void set_scene(const RenderScene& scene);

    /// Draws the scene into a width × height offscreen picture (4× MSAA resolved) and reads it
    /// back: RGBA8, sRGB-encoded, rows top to bottom, alpha 255.
    /// \throw InvalidInput for a size outside 1..16384; RenderError.
    RgbaImage render(const Camera& camera, int width, int height);

    /// Makes `overlay` the 2D layer drawn over the scene by render() and present() (copied to
    /// host-visible GPU buffers now; the font only when its version changes). An empty overlay
    /// (no commands) draws nothing.
    /// \throw InvalidInput (one line; the previous overlay stays) for a command whose indices
    /// run past `indices`, an index + vertex_offset outside `vertices`, a clip rectangle that is
    /// not finite, or a font whose byte count is not width × height × 4.
    void set_overlay(const Overlay& overlay);

    /// Gives the renderer a window to present to. `create_surface` gets the VkInstance as an
    /// integer and returns a VkSurfaceKHR made on it as an integer (glfwCreateWindowSurface);
    /// the renderer owns the surface from then on and destroys it (before the instance) when
    /// destroyed or given another window. The window must outlive the renderer.
    /// \throw RenderError when the renderer was made without `presentation` or VK_KHR_surface,
    /// or the callback returns 0; RenderUnavailable when the device's queue cannot present to
    /// the surface (the surface is destroyed).
    void attach_window(const std::function<std::uint64_t(std::uint64_t vk_instance)>& create_surface);

    /// Draws the scene and the overlay exactly as render() does (into a width × height
    /// offscreen MSAA target, resolved), blits it into the window's next swapchain image and
    /// presents it (FIFO: waits for the display's vertical blank when the queue is full).
    /// Makes or remakes the swapchain when the size changes or the surface says it is out of
    /// date or suboptimal. Returns false, drawing nothing, when width or height is 0
    /// (minimised) or no swapchain image could be had; true when a frame was submitted.
    /// \throw RenderError before attach_window, or when presenting fails; InvalidInput for a
    /// negative size or one over 16384.
    bool present(const Camera& camera, int width, int height);

    /// The pixels of the last frame drawn by render() or present() (as render() returns them),
    /// read back from the offscreen target now; empty before any frame. For screenshots and
    /// tests: costs nothing until called.
    RgbaImage last_frame();

    const RenderStats& stats() const;

    /// The Vulkan objects the renderer uses (see VulkanHandles).
    VulkanHandles vulkan_handles() const;

    /// Draws the scene (no overlay) as seen by `eye` into `target`, exactly as render() draws
    /// (MSAA offscreen, resolved), then copies it into the target image; returns when the GPU
    /// has finished, so the image can be handed back to the runtime at once. The offscreen
    /// targets are kept per size. last_frame() reads this picture back too.
    /// The projection is asymmetric, exactly the four angles; a symmetric EyeView draws what
    /// render() draws for a Camera at the same place looking along the same −Z, with
    /// fov_y_deg = 2 · angle_up and an image of aspect tan(angle_right) / tan(angle_up).
    /// Submits to the renderer's queue (vulkan_handles()) from the calling thread.
    /// \throw InvalidInput for a size outside 1..16384, a format not listed, or a null image,
    /// a negative array layer, or an eye that is not finite, has an orientation of length 0,
    /// near ≤ 0 or far ≤ near, or angles not ordered left < right, down < up within ±90°;
    /// RenderUnavailable when the device cannot blit into the format; RenderError.
    void render_to(const EyeView& eye, const ExternalImage& target);

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

} // namespace lobe
