// `lobesketch desktop [SESSION]`: the sketching app in a window (docs/desktop.md). GLFW gives
// the window and its input, Dear ImGui the panel (drawn by the renderer's overlay), the
// DesktopSession everything else.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <memory>
#include <set>
#include <sstream>

#include <CLI/CLI.hpp>
#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>
#include <imgui.h>
#include <nlohmann/json.hpp>

#include "app/session/session_file.h"
#include "app/cli/cli.h"
#include "app/cli/cli_common.h"
#include "app/desktop/desktop_script.h"
#include "app/desktop/desktop_session.h"
#include "app/export/export_scene.h"
#include "app/render/loaded_libraries.h"
#include "app/render/renderer.h"
#include "core/atomic_file.h"
#include "core/errors.h"
#include "input/tools.h"

namespace lobe::cli {

namespace {

namespace fs = std::filesystem;

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
        if (!me->scripted) me->session->mouse_move(float(x), float(y));
    });
    glfwSetMouseButtonCallback(w, [](GLFWwindow* win, int button, int action, int) {
        Window* me = window_of(win);
        if (!me->scripted && action != GLFW_REPEAT) me->session->mouse_button(button, action == GLFW_PRESS);
    });
    glfwSetScrollCallback(w, [](GLFWwindow* win, double, double dy) {
        Window* me = window_of(win);
        if (me->scripted) return;
        if (ImGui::GetIO().WantCaptureMouse)
            ImGui::GetIO().MouseWheel += float(dy);
        else
            me->session->mouse_wheel(float(dy));
    });
    glfwSetKeyCallback(w, [](GLFWwindow* win, int key, int, int action, int) {
        Window* me = window_of(win);
        if (!me->scripted && action != GLFW_REPEAT) me->session->key(key, action == GLFW_PRESS);
    });
    glfwSetCursorEnterCallback(w, [](GLFWwindow* win, int entered) {
        Window* me = window_of(win);
        if (!me->scripted) me->session->set_cursor_inside(entered != 0);
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

/// The panel: stages, tools, edits, appearance, file, status. Buttons press the keys the
/// keyboard has (so the recording holds key events either way); settings are sent as
/// Setting events when a slider is let go.
void draw_panel(DesktopSession& session, const std::string& session_name, int& target_lobe, float height)
{
    const DesktopStatus& st = session.status();
    const Document& doc = session.document();
    constexpr float kWidth = 250.0f, kHalf = 113.0f;
    ImGui::SetNextWindowPos(ImVec2(6, 6), ImGuiCond_Always);
    ImGui::SetNextWindowSize(ImVec2(kWidth, std::max(120.0f, height - 12.0f)), ImGuiCond_Always);
    ImGui::PushStyleVar(ImGuiStyleVar_ItemSpacing, ImVec2(6, 3));
    ImGui::PushStyleVar(ImGuiStyleVar_FramePadding, ImVec2(5, 2));
    ImGui::Begin(("Lobesketch  " + session_name).c_str(), nullptr,
                 ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoSavedSettings |
                     ImGuiWindowFlags_NoCollapse);
    auto press = [&](const char* action) {
        const int key = panel_action_key(action);
        session.key(key, true);
        session.key(key, false);
    };
    // A button of half the panel's width; `active` marks the current stage or tool.
    int column = 0;
    auto button = [&](const char* action, bool active = false) {
        for (const PanelAction& a : panel_actions())
            if (std::string(a.name) == action) {
                if (column++ % 2 == 1) ImGui::SameLine();
                if (active) ImGui::PushStyleColor(ImGuiCol_Button, ImVec4(0.2f, 0.55f, 0.25f, 1.0f));
                if (ImGui::Button(a.label, ImVec2(kHalf, 0))) press(action);
                if (active) ImGui::PopStyleColor();
            }
    };
    // Status first: what the hand does now.
    ImGui::Text("%s%s", tool_name(st.tool), st.pinching ? "  - pinching" : "");
    ImGui::Text("%zu strokes, %zu lobes, %zu edits", st.strokes, st.lobes, st.edits);
    ImGui::Text("depth %.2f m%s%s", st.depth_m, st.regrowing ? "  building..." : "", st.importing ? "  importing..." : "");
    if (st.tree_triangles) ImGui::Text("tree: LOD%d, %zu triangles", st.lod, st.tree_triangles);
    if (!st.last_message.empty()) ImGui::TextWrapped("%s", st.last_message.c_str());

    if (ImGui::CollapsingHeader("Stages and tools", ImGuiTreeNodeFlags_DefaultOpen)) {
        column = 0;
        button("draw-lobe", !st.grown && st.tool == Tool::DrawLobe);
        button("draw-trunk", !st.grown && st.tool == Tool::DrawTrunk);
        button("grow", st.grown);
        button("new-lobe");
        button("deform", st.tool == Tool::DeformLobe);
        button("edit-stroke", st.tool == Tool::EditStroke);
        button("move", st.tool == Tool::MoveLobe);
        button("rotate", st.tool == Tool::RotateLobe);
        button("scale", st.tool == Tool::ScaleLobe);
    }
    if (ImGui::CollapsingHeader("Edit (under the fingertip)", ImGuiTreeNodeFlags_DefaultOpen)) {
        column = 0;
        button("delete-stroke");
        button("delete-lobe");
        button("duplicate");
        button("mirror");
        button("undo");
        button("redo");
    }
    if (ImGui::CollapsingHeader("Appearance", ImGuiTreeNodeFlags_DefaultOpen)) {
        std::string target = target_lobe == 0 ? "whole tree" : "lobe " + std::to_string(target_lobe);
        if (ImGui::BeginCombo("for", target.c_str())) {
            if (ImGui::Selectable("whole tree", target_lobe == 0)) target_lobe = 0;
            for (const LobeRecord& l : doc.lobes) {
                const std::string label = "lobe " + std::to_string(l.id);
                if (ImGui::Selectable(label.c_str(), target_lobe == l.id)) target_lobe = int(l.id);
            }
            ImGui::EndCombo();
        }
        const LobeRecord* lobe = nullptr;
        for (const LobeRecord& l : doc.lobes)
            if (l.id == target_lobe) lobe = &l;
        if (!lobe) target_lobe = 0;
        const auto send = [&](SettingId id, double v) { session.setting(static_cast<int>(id), target_lobe, v); };
        float split = float(lobe && lobe->split_angle_deg ? *lobe->split_angle_deg : doc.settings.growth.split_angle_deg);
        ImGui::SliderFloat("split t", &split, 5.0f, 90.0f, "%.0f deg");
        if (ImGui::IsItemDeactivatedAfterEdit()) send(SettingId::SplitAngle, split);
        int species = 0;
        const std::string& current = lobe && !lobe->species.empty() ? lobe->species : doc.settings.growth.species;
        for (int i = 0; i < kSettingSpeciesCount; ++i)
            if (current == kSettingSpecies[i]) species = i;
        if (ImGui::Combo("species", &species, kSettingSpecies, kSettingSpeciesCount)) send(SettingId::Species, species);
        if (target_lobe == 0) {
            // The attractor spacing is the same for every lobe (one density for the tree).
            float spacing = float(doc.settings.lobes.edge_length_m * 100.0);
            ImGui::SliderFloat("spacing", &spacing, 1.0f, 10.0f, "%.1f cm");
            if (ImGui::IsItemDeactivatedAfterEdit()) send(SettingId::AttractorSpacing, spacing / 100.0);
        }
        // Leaves and seed: the tree's, or the lobe's own (shown: what the lobe grows with).
        float leaf = float((lobe && lobe->leaf_length_m ? *lobe->leaf_length_m : doc.settings.leaves.length_m) * 100.0);
        ImGui::SliderFloat("leaf size", &leaf, 1.0f, 20.0f, "%.1f cm");
        if (ImGui::IsItemDeactivatedAfterEdit()) send(SettingId::LeafLength, leaf / 100.0);
        int leaves = lobe && lobe->leaves_per_node ? *lobe->leaves_per_node : doc.settings.leaves.per_node;
        ImGui::SliderInt("leaves", &leaves, 0, 16);
        if (ImGui::IsItemDeactivatedAfterEdit()) send(SettingId::LeavesPerNode, leaves);
        int seed = int(std::min<std::uint64_t>(lobe && lobe->seed ? *lobe->seed : doc.seed, 16777215));
        if (ImGui::InputInt("seed", &seed, 1, 10) && seed >= 1 && seed < (1 << 24)) send(SettingId::Seed, seed);
    }
    if (ImGui::CollapsingHeader("Import a mesh as a lobe")) {
        // OBJ, PLY or OFF, made on a thread of its own; the lobe appears centred on the
        // fingertip (the cursor's point on the depth plane) when the import is done.
        static char path[1024] = "";
        static float size_m = 1.5f;
        ImGui::InputText("file", path, sizeof path);
        ImGui::SliderFloat("size", &size_m, 0.1f, 5.0f, "%.2f m");
        if (ImGui::Button("Import", ImVec2(kHalf, 0)) && path[0] != 0) session.import_mesh(path, size_m);
    }
    if (ImGui::CollapsingHeader("File", ImGuiTreeNodeFlags_DefaultOpen)) {
        column = 0;
        button("save");
        button("export");
        button("frame");
    }
    ImGui::TextDisabled("left: pinch   right: orbit");
    ImGui::TextDisabled("middle: pan   wheel: depth");
    ImGui::TextDisabled("shift+wheel: zoom");
    ImGui::End();
    ImGui::PopStyleVar(2);
}

nlohmann::json summary(const DesktopSession& s, const std::string& label, int frame)
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
    return {{"mark", label},
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
            {"last_message", s.status().last_message}};
}

} // namespace

void add_desktop_command(CLI::App& app, int& exit_code)
{
    auto* cmd = app.add_subcommand("desktop", "Sketch lobes and trunks with the mouse in a window and grow the tree");
    struct Args {
        std::string session, record, autosave, export_path, size = "1280x800", script, script_log, screenshot;
        bool recover = false, software = false;
        int frames = 0, samples = 4, lod = -1;
    };
    auto a = std::make_shared<Args>();
    cmd->add_option("SESSION", a->session, "Session document (.json) to open; created on the first save when missing");
    cmd->add_option("--record", a->record, "The session's recording (default: SESSION_STEM.<time>.lrec beside it)");
    cmd->add_option("--autosave", a->autosave, "Autosave file (default: SESSION_STEM.autosave.json beside it)");
    cmd->add_option("--export", a->export_path, "Where Export writes the tree (default: SESSION_STEM.glb)");
    cmd->add_option("--size", a->size, "Window size WxH")->capture_default_str();
    cmd->add_option("--script", a->script, "Drive the window with scripted mouse and key input (docs/desktop.md)");
    cmd->add_option("--script-log", a->script_log, "With --script: JSON lines describing the document at each `mark`");
    cmd->add_option("--screenshot", a->screenshot, "Write the last frame as PNG when the window closes");
    cmd->add_option("--frames", a->frames, "Close the window after this many frames (0: when closed)");
    cmd->add_flag("--recover", a->recover, "Open SESSION's autosave (after a crash or when SESSION is damaged)");
    cmd->add_flag("--software", a->software, "Render on the CPU (lavapipe) even when a GPU is present");
    cmd->add_option("--lod", a->lod, "Draw the tree at this level of detail (default: finest that keeps frames under 40 ms)")
        ->check(CLI::Range(0, 7));
    cmd->add_option("--samples", a->samples, "Multisampling: 1, 2, 4 or 8 samples per pixel")
        ->check(CLI::IsMember({1, 2, 4, 8}))
        ->capture_default_str();
    cmd->callback([a, &exit_code] {
        int width = 0, height = 0;
        {
            char x = 0, rest = 0;
            if (std::sscanf(a->size.c_str(), "%d%c%d%c", &width, &x, &height, &rest) != 3 || (x != 'x' && x != 'X') ||
                width < 64 || height < 64 || width > 8192 || height > 8192)
                throw CLI::ValidationError("--size", "expected WxH with sides in 64..8192, got '" + a->size + "'");
        }
        // Where the session, its autosave, recording and export live.
        const std::string session = a->session.empty() ? "lobesketch-" + timestamp() + ".json" : a->session;
        const std::string autosave = a->autosave.empty() ? beside(session, ".autosave.json") : a->autosave;
        DesktopOptions options;
        options.session_path = session;
        options.autosave_path = autosave;
        options.record_path = a->record.empty() ? beside(session, "." + timestamp() + ".lrec") : a->record;
        options.export_path = a->export_path.empty() ? beside(session, ".glb") : a->export_path;
        options.background_regrowth = a->script.empty();

        Document doc;
        std::error_code ec;
        if (a->recover) {
            if (!fs::exists(autosave, ec)) throw FileError(autosave, "there is no autosave to recover");
            doc = load_session(autosave);
            // The damaged or older session file stays as it is: saves go beside it.
            if (fs::exists(session, ec)) options.session_path = beside(session, ".recovered.json");
            progress("recovered " + autosave + "; Save writes " + options.session_path);
        } else if (fs::exists(session, ec)) {
            try {
                doc = load_session(session);
            } catch (const Error& e) {
                std::string offer = fs::exists(autosave, ec)
                                        ? " The autosave " + autosave + " holds your last work: open it with "
                                              "`lobesketch desktop " + session + " --recover`."
                                        : "";
                throw Error(std::string(e.what()) + "; nothing was changed." + offer);
            }
            // Work after the last save (a crash, a killed program) is in a newer autosave.
            std::error_code e1, e2;
            const auto saved_at = fs::last_write_time(session, e1), autosaved_at = fs::last_write_time(autosave, e2);
            try {
                if (!e1 && !e2 && autosaved_at > saved_at &&
                    read_file_limited(autosave, kMaxDocumentBytes) != read_file_limited(session, kMaxDocumentBytes))
                    warn(autosave + " is newer than " + session + " and differs: to continue from it, run "
                         "`lobesketch desktop " + session + " --recover`");
            } catch (const Error&) {
                // An unreadable autosave offers nothing; the session opened.
            }
        }

        std::vector<ScriptStep> script;
        if (!a->script.empty()) script = parse_desktop_script(read_file_limited(a->script, 16u << 20), a->script);
        std::unique_ptr<std::ofstream> log;
        if (!a->script_log.empty()) {
            log = std::make_unique<std::ofstream>(a->script_log, std::ios::trunc);
            if (!*log) throw FileError(a->script_log, "cannot write the script log");
        }

        glfwSetErrorCallback(nullptr);
        // GLFW loads X11 (and the Vulkan loader its drivers) at run time: keep them loaded
        // past glfwTerminate so their leftovers are not reported as leaks of unknown modules.
        const std::vector<std::string> libraries_before = loaded_libraries();
        keep_vulkan_drivers_loaded(); // before GLFW enumerates Vulkan
        if (!glfwInit())
            throw RenderUnavailable("desktop: cannot open a window (" + last_glfw_error() +
                                    "); set DISPLAY, or run it under xvfb-run (package xvfb)");
        Window win;
        struct PinLibraries { // destroyed before win, i.e. before glfwTerminate
            const std::vector<std::string>& before;
            ~PinLibraries() { keep_loaded_since(before); }
        } pin{libraries_before};
        glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
        win.handle = glfwCreateWindow(width, height, ("Lobesketch - " + fs::path(session).filename().string()).c_str(),
                                      nullptr, nullptr);
        if (!win.handle) throw RenderUnavailable("desktop: cannot open a window (" + last_glfw_error() + ")");
        if (!glfwVulkanSupported())
            throw RenderUnavailable("desktop: GLFW finds no Vulkan loader; install libvulkan1 and mesa-vulkan-drivers");
        std::uint32_t n_ext = 0;
        const char** ext = glfwGetRequiredInstanceExtensions(&n_ext);
        RendererOptions ropts;
        ropts.prefer_software = a->software;
        ropts.samples = a->samples;
        ropts.presentation = true;
        for (std::uint32_t i = 0; i < n_ext; ++i) ropts.instance_extensions.emplace_back(ext[i]);
        Renderer renderer(ropts);
        renderer.attach_window([&](std::uint64_t instance) {
            VkSurfaceKHR surface = VK_NULL_HANDLE;
            if (glfwCreateWindowSurface(reinterpret_cast<VkInstance>(instance), win.handle, nullptr, &surface) != VK_SUCCESS)
                throw RenderUnavailable("desktop: cannot make a Vulkan surface for the window (" + last_glfw_error() + ")");
            return reinterpret_cast<std::uint64_t>(surface);
        });
        progress("desktop: " + renderer.device_name() + ", session " + options.session_path + ", recording " +
                 options.record_path);

        DesktopSession ds(std::move(doc), options);
        win.session = &ds;
        win.scripted = !script.empty();
        glfwSetWindowUserPointer(win.handle, &win);
        install_callbacks(win.handle);

        win.imgui = ImGui::CreateContext();
        ImGuiIO& io = ImGui::GetIO();
        io.IniFilename = nullptr;
        unsigned char* font_pixels = nullptr;
        int font_w = 0, font_h = 0;
        io.Fonts->GetTexDataAsRGBA32(&font_pixels, &font_w, &font_h);
        RgbaImage font{font_w, font_h, std::vector<std::uint8_t>(font_pixels, font_pixels + std::size_t(font_w) * font_h * 4)};
        io.Fonts->SetTexID(reinterpret_cast<ImTextureID>(std::intptr_t(1)));
        ImGui::StyleColorsDark();

        const auto start = std::chrono::steady_clock::now();
        std::size_t next_step = 0;
        int target_lobe = 0;
        PanelInput panel;
        std::vector<double> session_ms, present_ms;
        const std::string session_name = fs::path(options.session_path).filename().string();
        for (int frame = 0;; ++frame) {
            glfwPollEvents();
            // Scripted input: this frame's steps, through the same calls as the callbacks.
            bool wait = false, quit = false;
            while (next_step < script.size() && script[next_step].frame <= frame) {
                const ScriptStep& s = script[next_step++];
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
                    if (log) *log << summary(ds, s.name, frame).dump() << "\n" << std::flush;
                    break;
                case ScriptStep::Kind::Quit: quit = true; break;
                }
            }
            int fb_w = 0, fb_h = 0;
            glfwGetFramebufferSize(win.handle, &fb_w, &fb_h);
            double dt = 1.0 / 60.0;
            double t = frame / 60.0; // scripted: exact 60 Hz frame times, so runs replay alike
            if (!win.scripted) {
                t = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            }

            if (!win.scripted) {
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
            draw_panel(ds, session_name, target_lobe, io.DisplaySize.y);
            ds.set_ui_capture(io.WantCaptureMouse);
            ImGui::Render();

            const auto t0 = std::chrono::steady_clock::now();
            ds.frame(t, std::max(fb_w, 1), std::max(fb_h, 1));
            if (wait) {
                ds.wait_for_regrowth();
                ds.frame(t + 0.5 / 60.0, std::max(fb_w, 1), std::max(fb_h, 1));
            }
            renderer.set_overlay(overlay_of(ImGui::GetDrawData(), font, 1));
            renderer.set_scene(ds.scene());
            const auto t1 = std::chrono::steady_clock::now();
            renderer.present(ds.camera(), fb_w, fb_h);
            session_ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
            present_ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t1).count());
            // Adaptive detail: a coarser LOD when the last 8 frames took over 40 ms to draw, a
            // finer one when they took under 12 ms (software rendering, big trees).
            if (a->lod >= 0) {
                ds.set_lod(a->lod);
            } else if (present_ms.size() >= 8 && frame % 8 == 0) {
                std::vector<double> recent(present_ms.end() - 8, present_ms.end());
                std::sort(recent.begin(), recent.end());
                const double m = recent[4];
                if (m > 40.0 && ds.status().tree_triangles > 0 && ds.lod() < 2) ds.set_lod(ds.lod() + 1);
                if (m < 12.0 && ds.lod() > 0) ds.set_lod(ds.lod() - 1);
            }

            const bool script_done = win.scripted && next_step >= script.size();
            if (quit || ds.quit_requested() || glfwWindowShouldClose(win.handle) || (a->frames > 0 && frame + 1 >= a->frames) ||
                script_done)
                break;
        }
        ds.finish(0.0);
        if (!a->screenshot.empty()) {
            const std::vector<std::uint8_t> png = encode_png(renderer.last_frame());
            write_file_atomic(a->screenshot, std::string_view(reinterpret_cast<const char*>(png.data()), png.size()));
        }
        std::set<std::string> shown; // each warning once
        for (const std::string& m : ds.messages())
            if (m.rfind("saved ", 0) != 0 && m.rfind("exported ", 0) != 0 && shown.insert(m).second) warn(m);
        auto median = [](std::vector<double> v) {
            if (v.empty()) return 0.0;
            std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(v.size() / 2), v.end());
            return v[v.size() / 2];
        };
        char timing[160];
        std::snprintf(timing, sizeof timing, "%zu frames, median %.2f ms input+session (scene included), %.1f ms to present",
                      present_ms.size(), median(session_ms), median(present_ms));
        progress("desktop: " + std::to_string(ds.document().strokes.size()) + " strokes, " +
                 std::to_string(ds.document().lobes.size()) + " lobes; " + timing + "; autosave " + options.autosave_path);
        exit_code = kExitOk;
    });
}

} // namespace lobe::cli
