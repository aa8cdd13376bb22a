#include "app/desktop/desktop_panel.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>

#include <imgui.h>

#include "app/desktop/desktop_script.h"
#include "app/desktop/desktop_session.h"
#include "app/session/panel_controls.h"
#include "core/document.h"
#include "growth/grower.h"
#include "input/recording.h"
#include "input/tools.h"

namespace lobe {

namespace {

/// The Grower section: the growth model, and stepping its growth for a grower that grows in
/// steps.
void draw_grower_section(DesktopSession& session, const Document& doc, DesktopPanelState& state)
{
    // Every growth model there is; the scene's tree grows with the one chosen.
    const GrowerChoice& current = scene_grower(doc);
    if (ImGui::BeginCombo("model", current.name.c_str())) {
        for (const Grower* g : growers()) {
            const std::string name(g->name());
            if (ImGui::Selectable(name.c_str(), name == current.name))
                session.setting(static_cast<int>(SettingId::Grower), 0, g->panel_code());
            if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", std::string(g->title()).c_str());
        }
        ImGui::EndCombo();
    }
    // A grower that grows in steps: its growth one step back or on (growth/grower.h
    // steps_param), from its default when the session does not give the steps.
    // (The default may mean parsing an L-system: once per choice, not once per frame.)
    if (state.steps_of != current) {
        state.steps_of = current;
        state.steps = growth_steps(current);
    }
    if (const std::optional<int> steps = state.steps) {
        const Grower* g = find_grower(current.name);
        const bool given = current.params.count(std::string(g->steps_param())) != 0;
        const auto step = [&](int delta) {
            if (const std::optional<double> v = growth_steps_after(current, delta))
                session.setting(static_cast<int>(SettingId::GrowthSteps), 0, *v);
        };
        if (ImGui::ArrowButton("##step-back", ImGuiDir_Left)) step(-1);
        if (ImGui::IsItemHovered()) ImGui::SetTooltip("one growth step back");
        ImGui::SameLine();
        if (ImGui::ArrowButton("##step-on", ImGuiDir_Right)) step(+1);
        if (ImGui::IsItemHovered()) ImGui::SetTooltip("one growth step on");
        ImGui::SameLine();
        if (given) ImGui::Text("step %d", *steps);
        else ImGui::Text("step %d (default)", *steps);
    }
}

/// The whole tree's leaf width and colours and its radii (pipe model); `send` sends one
/// Setting event. Labels and ranges: the panel controls; lengths in cm and mm.
template <class Send> void draw_tree_appearance(const Document& doc, const Send& send)
{
    const auto control = [](SettingId id) -> const PanelControl& { return *find_panel_control(id); };
    const PanelControl& width_c = control(SettingId::LeafWidth);
    float width = float(doc.settings.leaves.width_m * 100.0);
    ImGui::SliderFloat(width_c.label, &width, float(width_c.lo * 100.0), float(width_c.hi * 100.0), "%.1f cm");
    if (ImGui::IsItemDeactivatedAfterEdit()) send(SettingId::LeafWidth, width / 100.0);
    // Colours: linear RGB, sent packed (pack_color) when the picker is let go.
    const auto colour = [&](SettingId id, const double (&rgb)[3]) {
        float c[3] = {float(rgb[0]), float(rgb[1]), float(rgb[2])};
        ImGui::ColorEdit3(control(id).label, c, ImGuiColorEditFlags_Float);
        if (ImGui::IsItemDeactivatedAfterEdit()) {
            const double picked[3] = {c[0], c[1], c[2]};
            send(id, pack_color(picked));
        }
    };
    colour(SettingId::LeafColor, doc.settings.leaves.color);
    colour(SettingId::BarkColor, doc.settings.branches.bark_color);
    const PanelControl& pipe_c = control(SettingId::PipeExponent);
    float pipe = float(doc.settings.branches.pipe_exponent);
    ImGui::SliderFloat(pipe_c.label, &pipe, float(pipe_c.lo), float(pipe_c.hi), "%.1f");
    if (ImGui::IsItemDeactivatedAfterEdit()) send(SettingId::PipeExponent, std::round(pipe * 10.0) / 10.0);
    const PanelControl& tip_c = control(SettingId::TipRadius);
    float tip = float(doc.settings.branches.tip_radius_m * 1000.0);
    ImGui::SliderFloat(tip_c.label, &tip, float(tip_c.lo * 1000.0), float(tip_c.hi * 1000.0), "%.1f mm");
    if (ImGui::IsItemDeactivatedAfterEdit()) send(SettingId::TipRadius, std::round(double(tip) * 10.0) / 10000.0);
}

} // namespace

/// The panel: stages, tools, edits, appearance, file, status. Buttons press the keys the
/// keyboard has (so the recording holds key events either way); settings are sent as
/// Setting events when a slider is let go.
void draw_desktop_panel(DesktopSession& session, const std::string& session_name, DesktopPanelState& state, float height)
{
    const DesktopStatus& st = session.status();
    const Document& doc = session.document();
    constexpr float kWidth = kDesktopPanelWidth, kHalf = 113.0f;
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
    if (st.co2_kg > 0.0) ImGui::Text("wood %.4f m3, CO2 %.2f kg", st.wood_m3, st.co2_kg);
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
    if (ImGui::CollapsingHeader("Grower", ImGuiTreeNodeFlags_DefaultOpen)) draw_grower_section(session, doc, state);
    if (ImGui::CollapsingHeader("Appearance", ImGuiTreeNodeFlags_DefaultOpen)) {
        std::string target = state.target_lobe == 0 ? "whole tree" : "lobe " + std::to_string(state.target_lobe);
        if (ImGui::BeginCombo("for", target.c_str())) {
            if (ImGui::Selectable("whole tree", state.target_lobe == 0)) state.target_lobe = 0;
            for (const LobeRecord& l : doc.lobes) {
                const std::string label = "lobe " + std::to_string(l.id);
                if (ImGui::Selectable(label.c_str(), state.target_lobe == l.id)) state.target_lobe = int(l.id);
            }
            ImGui::EndCombo();
        }
        const LobeRecord* lobe = nullptr;
        for (const LobeRecord& l : doc.lobes)
            if (l.id == state.target_lobe) lobe = &l;
        if (!lobe) state.target_lobe = 0;
        const auto send = [&](SettingId id, double v) { session.setting(static_cast<int>(id), state.target_lobe, v); };
        // Labels and ranges: the panel controls (app/session/panel_controls.h); lengths in cm.
        const auto control = [](SettingId id) -> const PanelControl& { return *find_panel_control(id); };
        const PanelControl& split_c = control(SettingId::SplitAngle);
        float split = float(lobe && lobe->split_angle_deg ? *lobe->split_angle_deg : doc.settings.growth.split_angle_deg);
        ImGui::SliderFloat(split_c.label, &split, float(split_c.lo), float(split_c.hi), "%.0f deg");
        if (ImGui::IsItemDeactivatedAfterEdit()) send(SettingId::SplitAngle, split);
        int species = 0;
        const std::string& current = lobe && !lobe->species.empty() ? lobe->species : doc.settings.growth.species;
        for (int i = 0; i < kSettingSpeciesCount; ++i)
            if (current == kSettingSpecies[i]) species = i;
        if (ImGui::Combo(control(SettingId::Species).label, &species, kSettingSpecies, kSettingSpeciesCount))
            send(SettingId::Species, species);
        if (state.target_lobe == 0) {
            // The attractor spacing is the same for every lobe (one density for the tree).
            const PanelControl& c = control(SettingId::AttractorSpacing);
            float spacing = float(doc.settings.lobes.edge_length_m * 100.0);
            ImGui::SliderFloat(c.label, &spacing, float(c.lo * 100.0), float(c.hi * 100.0), "%.1f cm");
            if (ImGui::IsItemDeactivatedAfterEdit()) send(SettingId::AttractorSpacing, spacing / 100.0);
        }
        // Leaves and seed: the tree's, or the lobe's own (shown: what the lobe grows with).
        const PanelControl& leaf_c = control(SettingId::LeafLength);
        float leaf = float((lobe && lobe->leaf_length_m ? *lobe->leaf_length_m : doc.settings.leaves.length_m) * 100.0);
        ImGui::SliderFloat(leaf_c.label, &leaf, float(leaf_c.lo * 100.0), float(leaf_c.hi * 100.0), "%.1f cm");
        if (ImGui::IsItemDeactivatedAfterEdit()) send(SettingId::LeafLength, leaf / 100.0);
        int leaves = lobe && lobe->leaves_per_node ? *lobe->leaves_per_node : doc.settings.leaves.per_node;
        const PanelControl& leaves_c = control(SettingId::LeavesPerNode);
        ImGui::SliderInt(leaves_c.label, &leaves, int(leaves_c.lo), int(leaves_c.hi));
        if (ImGui::IsItemDeactivatedAfterEdit()) send(SettingId::LeavesPerNode, leaves);
        if (state.target_lobe == 0) draw_tree_appearance(doc, send);
        const PanelControl& seed_c = control(SettingId::Seed);
        int seed = int(std::min<std::uint64_t>(lobe && lobe->seed ? *lobe->seed : doc.seed, std::uint64_t(seed_c.hi)));
        if (ImGui::InputInt(seed_c.label, &seed, int(seed_c.step), 10) && seed >= seed_c.lo && seed <= seed_c.hi)
            send(SettingId::Seed, seed);
    }
    if (ImGui::CollapsingHeader("Import a mesh as a lobe")) {
        // OBJ, PLY or OFF, made on a thread of its own; the lobe appears centred on the
        // fingertip (the cursor's point on the depth plane) when the import is done.
        ImGui::InputText("file", state.import_path.data(), state.import_path.size());
        ImGui::SliderFloat("size", &state.import_size_m, 0.1f, 5.0f, "%.2f m");
        if (ImGui::Button("Import", ImVec2(kHalf, 0)) && state.import_path[0] != 0)
            session.import_mesh(state.import_path.data(), state.import_size_m);
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

} // namespace lobe
