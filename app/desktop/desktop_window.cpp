#include "app/desktop/desktop_window.h"

#include <algorithm>
#include <chrono>
#include <cstdint>

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>
#include <imgui.h>
#include <nlohmann/json.hpp>

#include "app/desktop/desktop_panel.h"
#include "app/desktop/desktop_session.h"
#include "app/render/loaded_libraries.h"
#include "app/render/renderer.h"
#include "core/errors.h"
#include "core/document.h"
#include "core/settings_json.h"
#include "input/tools.h"

namespace lobe {

namespace {

std::string last_glfw_error()
{
    const char* description = nullptr;
    glfwGetError(&description);
    return description ? description : "unknown GLFW error";
}

/// The window, its GLFW callbacks and the ImGui context, torn down in order.
struct Window {
    GLFWwindow* handle = nullptr;
    ImGuiContext* imgui = nullptr;
    DesktopSession* session = nullptr;
    bool scripted = false; ///< a script drives the input: the real mouse and keys are ignored
    ~Window()
    {
        if (imgui) ImGui::DestroyContext(imgui);
        if (handle) glfwDestroyWindow(handle);
        glfwTerminate();
    }
};

Window* window_of(GLFWwindow* w) { return static_cast<Window*>(glfwGetWindowUserPointer(w)); }

void install_callbacks(GLFWwindow* w)
{
    glfwSetCursorPosCallback(w, [](GLFWwindow* win, double x, double y) {
        Window* me = window_of(win);
        if (me->session && !me->scripted) me->session->mouse_move(float(x), float(y));
    });
    glfwSetMouseButtonCallback(w, [](GLFWwindow* win, int button, int action, int) {
        Window* me = window_of(win);
        if (me->session && !me->scripted && action != GLFW_REPEAT) me->session->mouse_button(button, action == GLFW_PRESS);
    });
    glfwSetScrollCallback(w, [](GLFWwindow* win, double, double dy) {
        Window* me = window_of(win);
        if (!me->session || me->scripted) return;
        if (ImGui::GetIO().WantCaptureMouse)
            ImGui::GetIO().MouseWheel += float(dy);
        else
            me->session->mouse_wheel(float(dy));
    });
    glfwSetKeyCallback(w, [](GLFWwindow* win, int key, int, int action, int) {
        Window* me = window_of(win);
        if (me->session && !me->scripted && action != GLFW_REPEAT) me->session->key(key, action == GLFW_PRESS);
    });
    glfwSetCursorEnterCallback(w, [](GLFWwindow* win, int entered) {
        Window* me = window_of(win);
        if (me->session && !me->scripted) me->session->set_cursor_inside(entered != 0);
    });
}

/// Mouse state the panel sees (from the same input the session gets).
struct PanelInput {
    float x = -1e6f, y = -1e6f;
    bool left = false;
    float wheel = 0.0f;
};

/// ImGui's draw lists as the renderer's overlay.
Overlay overlay_of(const ImDrawData* data, const RgbaImage& font, std::uint64_t font_version)
{
    Overlay o;
    o.font = font;
    o.font_version = font_version;
    if (!data) return o;
    for (int l = 0; l < data->CmdListsCount; ++l) {
        const ImDrawList* list = data->CmdLists[l];
        const auto vertex_base = static_cast<std::int32_t>(o.vertices.size());
        const auto index_base = static_cast<std::uint32_t>(o.indices.size());
        for (const ImDrawVert& v : list->VtxBuffer) o.vertices.push_back({v.pos.x, v.pos.y, v.uv.x, v.uv.y, v.col});
        for (ImDrawIdx i : list->IdxBuffer) o.indices.push_back(i);
        for (const ImDrawCmd& c : list->CmdBuffer) {
            if (c.UserCallback) continue;
            OverlayCommand cmd;
            cmd.first_index = index_base + c.IdxOffset;
            cmd.index_count = c.ElemCount;
            cmd.vertex_offset = vertex_base + static_cast<std::int32_t>(c.VtxOffset);
            cmd.clip[0] = c.ClipRect.x - data->DisplayPos.x;
            cmd.clip[1] = c.ClipRect.y - data->DisplayPos.y;
            cmd.clip[2] = c.ClipRect.z - data->DisplayPos.x;
            cmd.clip[3] = c.ClipRect.w - data->DisplayPos.y;
            o.commands.push_back(cmd);
        }
    }
    return o;
}

double median(std::vector<double> v)
{
    if (v.empty()) return 0.0;
    std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(v.size() / 2), v.end());
    return v[v.size() / 2];
}

} // namespace

struct DesktopWindow::Impl {
    DesktopWindowOptions options;
    Window win;
    /// GLFW loads X11 (and the Vulkan loader its drivers) at run time: they are kept loaded
    /// past glfwTerminate, so their leftovers are not reported as leaks of unknown modules.
    std::vector<std::string> libraries_before;
    struct PinLibraries { // destroyed before win, i.e. before glfwTerminate
        const std::vector<std::string>* before = nullptr;
        ~PinLibraries()
        {
            if (before) keep_loaded_since(*before);
        }
    } pin;
    std::unique_ptr<Renderer> renderer;
    RgbaImage font;

    explicit Impl(DesktopWindowOptions o) : options(std::move(o)) {}
    /// One frame's scripted steps, through the same calls as the callbacks.
    void script_steps(DesktopSession& ds, std::size_t& next, int frame, PanelInput& panel, bool& wait, bool& quit);
};

DesktopWindow::DesktopWindow(DesktopWindowOptions options) : impl_(std::make_unique<Impl>(std::move(options)))
{
    Impl& im = *impl_;
    glfwSetErrorCallback(nullptr);
    im.libraries_before = loaded_libraries();
    keep_vulkan_drivers_loaded(); // before GLFW enumerates Vulkan
    if (!glfwInit())
        throw RenderUnavailable("desktop: cannot open a window (" + last_glfw_error() +
                                "); set DISPLAY, or run it under xvfb-run (package xvfb)");
    im.pin.before = &im.libraries_before;
    glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
    im.win.handle = glfwCreateWindow(im.options.width, im.options.height, im.options.title.c_str(), nullptr, nullptr);
    if (!im.win.handle) throw RenderUnavailable("desktop: cannot open a window (" + last_glfw_error() + ")");
    if (!glfwVulkanSupported())
        throw RenderUnavailable("desktop: GLFW finds no Vulkan loader; install libvulkan1 and mesa-vulkan-drivers");
    std::uint32_t n_ext = 0;
    const char** ext = glfwGetRequiredInstanceExtensions(&n_ext);
    RendererOptions ropts;
    ropts.prefer_software = im.options.software;
    ropts.samples = im.options.samples;
    ropts.presentation = true;
    for (std::uint32_t i = 0; i < n_ext; ++i) ropts.instance_extensions.emplace_back(ext[i]);
    im.renderer = std::make_unique<Renderer>(ropts);
    GLFWwindow* handle = im.win.handle;
    im.renderer->attach_window([handle](std::uint64_t instance) {
        VkSurfaceKHR surface = VK_NULL_HANDLE;
        if (glfwCreateWindowSurface(reinterpret_cast<VkInstance>(instance), handle, nullptr, &surface) != VK_SUCCESS)
            throw RenderUnavailable("desktop: cannot make a Vulkan surface for the window (" + last_glfw_error() + ")");
        return reinterpret_cast<std::uint64_t>(surface);
    });
    im.win.scripted = !im.options.script.empty();
    glfwSetWindowUserPointer(im.win.handle, &im.win);
    install_callbacks(im.win.handle);

    im.win.imgui = ImGui::CreateContext();
    ImGuiIO& io = ImGui::GetIO();
    io.IniFilename = nullptr;
    unsigned char* font_pixels = nullptr;
    int font_w = 0, font_h = 0;
    io.Fonts->GetTexDataAsRGBA32(&font_pixels, &font_w, &font_h);
    im.font = RgbaImage{font_w, font_h, std::vector<std::uint8_t>(font_pixels, font_pixels + std::size_t(font_w) * font_h * 4)};
    io.Fonts->SetTexID(reinterpret_cast<ImTextureID>(std::intptr_t(1)));
    ImGui::StyleColorsDark();
}

DesktopWindow::~DesktopWindow() = default;

Renderer& DesktopWindow::renderer() { return *impl_->renderer; }

void DesktopWindow::Impl::script_steps(DesktopSession& ds, std::size_t& next, int frame, PanelInput& panel, bool& wait,
                                       bool& quit)
{
    const std::vector<ScriptStep>& script = options.script;
    while (next < script.size() && script[next].frame <= frame) {
        const ScriptStep& s = script[next++];
        switch (s.kind) {
        case ScriptStep::Kind::Move: ds.mouse_move(s.x, s.y), panel.x = s.x, panel.y = s.y; break;
        case ScriptStep::Kind::Down:
        case ScriptStep::Kind::Up:
            ds.mouse_button(s.code, s.kind == ScriptStep::Kind::Down);
            if (s.code == desktop_keys::kMouseLeft) panel.left = s.kind == ScriptStep::Kind::Down;
            break;
        case ScriptStep::Kind::Wheel: ds.mouse_wheel(s.y); break;
        case ScriptStep::Kind::KeyPress: ds.key(s.code, true); break;
        case ScriptStep::Kind::KeyRelease: ds.key(s.code, false); break;
        case ScriptStep::Kind::Panel: {
            const int key = panel_action_key(s.name);
            ds.key(key, true);
            ds.key(key, false);
            break;
        }
        case ScriptStep::Kind::Set: ds.setting(s.code, s.lobe, s.value); break;
        case ScriptStep::Kind::Import:
            // A script waits for its import, so that its run is the same every time.
            if (ds.import_mesh(s.name, s.value)) ds.wait_for_import();
            break;
        case ScriptStep::Kind::Wait: wait = true; break;
        case ScriptStep::Kind::Mark:
            if (options.mark) options.mark(desktop_mark_json(ds, s.name, frame));
            break;
        case ScriptStep::Kind::Quit: quit = true; break;
        }
    }
}

DesktopRunResult DesktopWindow::run(DesktopSession& ds, const std::string& session_name)
{
    Impl& im = *impl_;
    Window& win = im.win;
    Renderer& renderer = *im.renderer;
    win.session = &ds;
    ImGuiIO& io = ImGui::GetIO();
    const auto start = std::chrono::steady_clock::now();
    std::size_t next_step = 0;
    DesktopPanelState panel_state;
    PanelInput panel;
    std::vector<double> session_ms, present_ms;
    for (int frame = 0;; ++frame) {
        glfwPollEvents();
        bool wait = false, quit = false;
        im.script_steps(ds, next_step, frame, panel, wait, quit);
        int fb_w = 0, fb_h = 0;
        glfwGetFramebufferSize(win.handle, &fb_w, &fb_h);
        const double dt = 1.0 / 60.0;
        double t = frame / 60.0; // scripted: exact 60 Hz frame times, so runs replay alike
        if (!win.scripted) {
            t = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            double mx = 0, my = 0;
            glfwGetCursorPos(win.handle, &mx, &my);
            panel.x = float(mx);
            panel.y = float(my);
            panel.left = glfwGetMouseButton(win.handle, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS;
        }
        io.DisplaySize = ImVec2(float(std::max(fb_w, 1)), float(std::max(fb_h, 1)));
        io.DeltaTime = float(dt);
        io.MousePos = ImVec2(panel.x, panel.y);
        io.MouseDown[0] = panel.left;
        ImGui::NewFrame();
        draw_desktop_panel(ds, session_name, panel_state, io.DisplaySize.y);
        ds.set_ui_capture(io.WantCaptureMouse);
        ImGui::Render();

        const auto t0 = std::chrono::steady_clock::now();
        ds.frame(t, std::max(fb_w, 1), std::max(fb_h, 1));
        if (wait) {
            ds.wait_for_regrowth();
            ds.frame(t + 0.5 / 60.0, std::max(fb_w, 1), std::max(fb_h, 1));
        }
        renderer.set_overlay(overlay_of(ImGui::GetDrawData(), im.font, 1));
        renderer.set_scene(ds.scene());
        const auto t1 = std::chrono::steady_clock::now();
        renderer.present(ds.camera(), fb_w, fb_h);
        session_ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
        present_ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t1).count());
        // Adaptive detail: a coarser LOD when the last 8 frames took over 40 ms to draw, a
        // finer one when they took under 12 ms (software rendering, big trees).
        if (im.options.lod >= 0) {
            ds.set_lod(im.options.lod);
        } else if (present_ms.size() >= 8 && frame % 8 == 0) {
            std::vector<double> recent(present_ms.end() - 8, present_ms.end());
            std::sort(recent.begin(), recent.end());
            const double m = recent[4];
            if (m > 40.0 && ds.status().tree_triangles > 0 && ds.lod() < 2) ds.set_lod(ds.lod() + 1);
            if (m < 12.0 && ds.lod() > 0) ds.set_lod(ds.lod() - 1);
        }

        const bool script_done = win.scripted && next_step >= im.options.script.size();
        if (quit || ds.quit_requested() || glfwWindowShouldClose(win.handle) ||
            (im.options.frames > 0 && frame + 1 >= im.options.frames) || script_done)
            break;
    }
    win.session = nullptr;
    DesktopRunResult r;
    r.frames = present_ms.size();
    r.median_session_ms = median(session_ms);
    r.median_present_ms = median(present_ms);
    return r;
}

/// The L-system sketch mode's state in a script mark.
static nlohmann::json lsystem_sketch_mark(const LSystemSketchMode& m)
{
    nlohmann::json branches = nlohmann::json::array();
    for (const lsystem::SketchBranch& b : m.sketch().branches) branches.push_back({{"attach", b.attach}, {"points", b.points.size()}});
    return {{"active", m.active()},
            {"trunk_sections", m.sketch().trunk_sections()},
            {"branches", branches},
            {"growth", m.growth()},
            {"divergence_deg", m.sketch().divergence_deg},
            {"tree_nodes", m.tree().size()}};
}

std::string desktop_mark_json(const DesktopSession& s, const std::string& label, int frame)
{
    const Document& d = s.document();
    nlohmann::json lobes = nlohmann::json::array();
    for (const LobeRecord& l : d.lobes) {
        nlohmann::json j{{"id", l.id}, {"strokes", l.stroke_ids}, {"species", l.species}};
        if (l.split_angle_deg) j["split_angle_deg"] = *l.split_angle_deg;
        if (l.leaf_length_m) j["leaf_length_m"] = *l.leaf_length_m;
        if (l.leaves_per_node) j["leaves_per_node"] = *l.leaves_per_node;
        if (l.seed) j["seed"] = *l.seed;
        if (l.model) j["model_triangles"] = l.model->mesh.triangles.size();
        lobes.push_back(j);
    }
    nlohmann::json strokes = nlohmann::json::array();
    for (const Stroke& st : d.strokes) strokes.push_back({{"id", st.id}, {"kind", stroke_kind_name(st.kind)}, {"points", st.points.size()}});
    nlohmann::json edits = nlohmann::json::array();
    for (const EditOperation& e : d.edits)
        edits.push_back({{"id", e.id}, {"type", edit_kind_name(e.kind())}, {"target", e.target}});
    const nlohmann::json mark{{"mark", label},
            {"frame", frame},
            {"tool", tool_name(s.status().tool)},
            {"grown", s.status().grown},
            {"strokes", strokes},
            {"lobes", lobes},
            {"edits", edits},
            {"settings", settings_json(d.settings)},
            {"seed", d.seed},
            {"tree_triangles", s.status().tree_triangles},
            {"tree_error", s.status().tree_error},
            {"last_message", s.status().last_message},
            {"lsystem_sketch", lsystem_sketch_mark(s.lsystem_sketch())}};
    return mark.dump();
}

} // namespace lobe
