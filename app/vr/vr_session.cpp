#include "app/vr/vr_session.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>

#include <glm/geometric.hpp>
#include <glm/gtc/constants.hpp>
#include <glm/mat3x3.hpp>

#include "app/export/export_scene.h"
#include "app/session/panel_controls.h"
#include "app/render/render_scene.h"
#include "app/render/scene_parts.h"
#include "core/errors.h"
#include "growth/grower.h"

namespace lobe {

namespace {

constexpr std::uint64_t kDynamicKey = 10ull << 56;
constexpr std::uint64_t kPanelKey = kDynamicKey | (1ull << 40);
constexpr std::uint64_t kPhotoKey = kDynamicKey | (2ull << 40);

// Panel geometry (metres) and poke thresholds. A fingertip presses a button when it reaches
// kPressDepth in front of the board (or goes through it) inside the button, having come from
// at least kArmDistance in front; it must go back out past kArmDistance before pressing again,
// so resting a finger on the board presses once.
constexpr float kButtonW = 0.060f, kButtonH = 0.034f, kButtonGap = 0.008f;
constexpr float kPressDepth = 0.004f, kArmDistance = 0.015f, kPokeBehind = 0.03f;
constexpr double kHighlightS = 0.35;

constexpr std::array<float, 4> kBoardColor{0.10f, 0.12f, 0.15f, 1.0f};
constexpr std::array<float, 4> kButtonColor{0.28f, 0.32f, 0.38f, 1.0f};
constexpr std::array<float, 4> kPressedColor{1.0f, 0.80f, 0.15f, 1.0f};
constexpr std::array<float, 4> kTextColor{0.95f, 0.96f, 0.98f, 1.0f};
constexpr std::array<float, 4> kHandColor{0.78f, 0.80f, 0.86f, 1.0f};
constexpr std::array<float, 4> kPinchColor{1.0f, 0.80f, 0.15f, 1.0f};
constexpr std::array<float, 4> kGrabColor{0.30f, 0.75f, 1.0f, 1.0f};
constexpr std::array<float, 4> kLobeInkColor{1.0f, 1.0f, 1.0f, 1.0f};
constexpr std::array<float, 4> kTrunkInkColor{0.55f, 0.33f, 0.16f, 1.0f};
constexpr std::array<float, 4> kDragInkColor{0.25f, 0.65f, 1.0f, 1.0f};

/// Setting buttons: what they change and by how much (multiplicative steps for sizes).
enum SettingButton : int {
    kAngleDown = 1, kAngleUp, kLeafDown, kLeafUp, kLeavesDown, kLeavesUp, kNextSpecies, kNextSeed, kNextGrower,
    kStepBack, kStepOn, kWidthDown, kWidthUp, kNextLeafColor, kNextBarkColor, kTwigDown, kTwigUp, kPipeDown, kPipeUp,
};

/// What the colour buttons step through (linear RGB): the species' colours, then others.
constexpr double kLeafPalette[][3] = {{0.2, 0.42, 0.12}, {0.07, 0.22, 0.1},  {0.45, 0.58, 0.2},
                                      {0.36, 0.6, 0.16}, {0.62, 0.42, 0.08}, {0.55, 0.12, 0.06}};
constexpr double kBarkPalette[][3] = {{0.36, 0.25, 0.17}, {0.3, 0.24, 0.2}, {0.42, 0.35, 0.24},
                                      {0.78, 0.76, 0.7},  {0.2, 0.17, 0.15}};

/// The packed colour after `now` in `palette` (its first when `now` is not in it).
template <std::size_t N> double next_color(const double (&now)[3], const double (&palette)[N][3])
{
    const int packed = pack_color(now);
    std::size_t at = N - 1;
    for (std::size_t i = 0; i < N; ++i)
        if (pack_color(palette[i]) == packed) at = i;
    return double(pack_color(palette[(at + 1) % N]));
}

/// The button a key or setting button is made from (positions come from the layout).
VrButton key_button(const char* text, int key) { return VrButton{text, key, 0, 0.0, {}, 0.0f, 0.0f}; }
VrButton setting_button(const char* text, int which) { return VrButton{text, 0, which, 0.0, {}, 0.0f, 0.0f}; }

const char* tool_label(Tool t)
{
    switch (t) {
    case Tool::DrawLobe: return "DRAW LOBE";
    case Tool::DrawTrunk: return "DRAW TRUNK";
    case Tool::DeformLobe: return "PINCH LOBE";
    case Tool::EditStroke: return "BEND STROKE";
    case Tool::MoveLobe: return "MOVE LOBE";
    case Tool::RotateLobe: return "TURN LOBE";
    case Tool::ScaleLobe: return "SCALE LOBE";
    }
    return "";
}

/// Angle of v's horizontal part, increasing with a turn about +Y (R_y(a) adds a).
float heading(const glm::vec3& v) { return std::atan2(-v.z, v.x); }

float wrap_pi(float a)
{
    while (a > glm::pi<float>()) a -= glm::two_pi<float>();
    while (a < -glm::pi<float>()) a += glm::two_pi<float>();
    return a;
}

/// An orientation whose +Z points from `from` towards `to` (horizontal only when `level`),
/// +Y as close to up as it can be.
glm::quat facing(const glm::vec3& from, const glm::vec3& to, bool level)
{
    glm::vec3 n = to - from;
    if (level) n.y = 0.0f;
    if (glm::length(n) < 1e-6f) n = glm::vec3(0, 0, 1);
    n = glm::normalize(n);
    glm::vec3 x = glm::cross(glm::vec3(0, 1, 0), n);
    if (glm::length(x) < 1e-6f) x = glm::vec3(1, 0, 0);
    x = glm::normalize(x);
    const glm::vec3 y = glm::cross(n, x);
    return glm::quat_cast(glm::mat3(x, y, n));
}

void to_document(SurfaceGeometry& g, const SceneTransform& t)
{
    if (t.identity()) return;
    const glm::quat inv = glm::inverse(t.rotation());
    for (glm::vec3& p : g.positions) p = t.to_document(p);
    for (glm::vec3& n : g.normals) n = inv * n;
}

} // namespace

// ---------------------------------------------------------------------------------------------
VrPanel vr_panel_layout(const Pose& head)
{
    // In front of where the head first was, below and to the left of the line of sight (the
    // right hand draws in front), turned to face the eyes.
    glm::vec3 forward = head.orientation * glm::vec3(0, 0, -1);
    forward.y = 0.0f;
    forward = glm::length(forward) < 1e-3f ? glm::vec3(0, 0, -1) : glm::normalize(forward);
    const glm::vec3 right = glm::normalize(glm::cross(forward, glm::vec3(0, 1, 0)));
    VrPanel panel;
    panel.origin = head.position + 0.40f * forward - 0.24f * right - glm::vec3(0, 0.36f, 0);
    panel.orientation = facing(panel.origin, head.position, false);

    const std::vector<std::vector<VrButton>> rows = {
        {key_button("LOBE", keys::kDrawLobe), key_button("NEW LOBE", keys::kNewLobe),
         key_button("TRUNK", keys::kDrawTrunk), key_button("GROW", keys::kGrow),
         key_button("PHOTO", vr_keys::kPlacePhoto), key_button("SAVE", vr_keys::kSave)},
        {key_button("BEND", keys::kEditStroke), key_button("PINCH", keys::kDeformLobe),
         key_button("MOVE", keys::kMoveLobe), key_button("TURN", keys::kRotateLobe),
         key_button("SCALE", keys::kScaleLobe), key_button("EXPORT", vr_keys::kExport)},
        {key_button("UNDO", keys::kUndo), key_button("REDO", keys::kRedo), key_button("DELETE", keys::kDeleteLobe),
         key_button("COPY", keys::kDuplicate), key_button("MIRROR", keys::kMirror), key_button("QUIT", vr_keys::kQuit)},
        {setting_button("ANGLE -", kAngleDown), setting_button("ANGLE +", kAngleUp),
         setting_button("LEAF -", kLeafDown), setting_button("LEAF +", kLeafUp),
         setting_button("LEAVES -", kLeavesDown), setting_button("LEAVES +", kLeavesUp)},
        {setting_button("SPECIES", kNextSpecies), setting_button("SEED", kNextSeed),
         key_button("DEL STROKE", keys::kDeleteStroke), setting_button("GROWER", kNextGrower),
         setting_button("STEP -", kStepBack), setting_button("STEP +", kStepOn)},
        {setting_button("WIDTH -", kWidthDown), setting_button("WIDTH +", kWidthUp),
         setting_button("LEAF COLOUR", kNextLeafColor), setting_button("BARK COLOUR", kNextBarkColor),
         setting_button("TWIG -", kTwigDown), setting_button("TWIG +", kTwigUp)},
        {setting_button("PIPE -", kPipeDown), setting_button("PIPE +", kPipeUp)},
        // The L-system sketch mode (app/live/lsystem_sketch_mode.h): on/off, a branch from the
        // trunk node at the fingertip, scrap, divergence and iterations. (TRUNK goes back to
        // the trunk, DEL STROKE erases the node at the fingertip while it is on.)
        {key_button("L-SYSTEM", keys::kLSystemSketch), key_button("BRANCH", lsystem_sketch_keys::kBranch),
         key_button("SCRAP", lsystem_sketch_keys::kScrap), key_button("DIV -", lsystem_sketch_keys::kDivergenceDown),
         key_button("DIV +", lsystem_sketch_keys::kDivergenceUp), key_button("ITER +", lsystem_sketch_keys::kIterationForward)},
        {key_button("ITER -", lsystem_sketch_keys::kIterationBack), key_button("GROW -", lsystem_sketch_keys::kGrowthDown),
         key_button("GROW +", lsystem_sketch_keys::kGrowthUp)},
    };
    const float pitch_x = kButtonW + kButtonGap, pitch_y = kButtonH + kButtonGap;
    const float top = 0.5f * float(rows.size() - 1) * pitch_y;
    for (std::size_t r = 0; r < rows.size(); ++r) {
        const float left = -0.5f * float(6 - 1) * pitch_x;
        for (std::size_t c = 0; c < rows[r].size(); ++c) {
            VrButton b = rows[r][c];
            const glm::vec3 local(left + float(c) * pitch_x, top - float(r) * pitch_y, 0.0f);
            b.centre = panel.origin + panel.orientation * local;
            b.half_width = 0.5f * kButtonW;
            b.half_height = 0.5f * kButtonH;
            panel.buttons.push_back(std::move(b));
        }
    }
    return panel;
}
// ---------------------------------------------------------------------------------------------
/// What is the VR app's own around the live session: the recording's clock and event track,
/// the panel and its pokes, the two-handed scene grab, the reference photo, the hands and
/// labels drawn each frame.
struct VrSession::Impl {
    VrSession& self;
    LiveSession& live;
    const InputPipeline& pipeline;
    VrOptions options;

    std::vector<InputEvent> pending;  ///< panel presses and scene moves, applied by the next frame
    std::size_t next_replay_event = 0; ///< into options.events
    std::size_t next_clock = 0;        ///< into options.clock
    bool panel_placed = false;
    double time = 0.0;
    bool started = false;

    // Panel pokes, per hand.
    std::array<bool, kHandCount> armed{};
    int highlighted = -1;
    double highlight_until = 0.0;
    std::uint64_t panel_version = 0;
    bool panel_dirty = true;
    SceneTransform panel_built_for;
    std::vector<RenderItem> panel_items; ///< the panel's meshes as last built

    // The two-handed scene grab.
    bool grabbing_scene = false;
    SceneTransform grab_start;
    glm::vec3 grab_anchor_doc{0.0f}; ///< the document point under the hands' midpoint at the start
    float grab_distance = 0.0f, grab_heading = 0.0f;

    // The reference photo.
    RgbaImage photo;
    std::optional<glm::vec3> photo_centre; ///< document space
    glm::quat photo_orientation{1.0f, 0.0f, 0.0f, 0.0f};
    std::uint64_t photo_version = 0;

    std::uint64_t dynamic_version = 0;
    HandFrame last_frame;

    Impl(VrSession& s, LiveSession& l, VrOptions o) : self(s), live(l), pipeline(l.pipeline()), options(std::move(o)) {}

    const Document& document() const { return live.document(); }

    void push(const InputEvent& e, std::vector<int>& commands)
    {
        if (e.kind == InputEventKind::Key && e.value == 1) commands.push_back(e.code);
        live.push_event(e);
    }

    void frame(const HandFrame& input);
    void run_commands(const std::vector<int>& commands, const HandFrame& f);
    void poke_panel(const HandFrame& f);
    void press(const VrButton& b, int index);
    void grab_scene(const HandFrame& f);
    void add_dynamic_items();
    void update_status();
};

void VrSession::Impl::frame(const HandFrame& input)
{
    HandFrame f = input;
    // Snap to the recording's own clock (VrOptions::clock): the next recorded time not before
    // this one, when it is that close.
    const std::vector<double>& clock = options.clock;
    while (next_clock < clock.size() && clock[next_clock] < f.time - 5e-7) ++next_clock;
    if (next_clock < clock.size() && std::abs(clock[next_clock] - f.time) <= 5e-7) f.time = clock[next_clock];
    f.time = started && f.time <= time ? time + 1e-4 : f.time;
    started = true;
    time = f.time;
    if (!panel_placed && f.head_valid) {
        self.panel_ = vr_panel_layout(f.head);
        panel_placed = panel_dirty = true;
    }

    // Raw events first, in the order replay applies them: the event track given (at its own
    // times, up to this frame's), then what the panel and the grab made during the last frame.
    std::vector<int> commands;
    while (next_replay_event < options.events.size() && options.events[next_replay_event].time <= f.time)
        push(options.events[next_replay_event++], commands);
    for (InputEvent& e : pending) {
        e.time = f.time;
        push(e, commands);
    }
    pending.clear();

    live.push_frame(f);
    live.apply_actions();
    run_commands(commands, f);

    if (panel_placed) poke_panel(f);
    grab_scene(f);

    live.update();
    last_frame = f;
    update_status();
    add_dynamic_items();
}

void VrSession::Impl::run_commands(const std::vector<int>& commands, const HandFrame& f)
{
    for (int code : commands) {
        if (code == vr_keys::kSave) self.save();
        if (code == vr_keys::kExport) self.export_tree();
        if (code == vr_keys::kQuit) self.quit_ = true;
        if (code == vr_keys::kPlacePhoto) {
            if (photo.pixels.empty()) {
                live.note("photo: no picture (start with --photo FILE)");
                continue;
            }
            const HandState& right = f.hand(Hand::Right);
            const HandGesture& g = pipeline.gestures().hand(Hand::Right);
            if (!g.tracked || !right.active) {
                live.note("photo: the right hand is not tracked");
                continue;
            }
            const SceneTransform& t = pipeline.scene_transform();
            // Standing at the fingertip, turned to the head, 0.6 m tall as the person sees it.
            photo_centre = t.to_document(g.index_tip);
            const glm::vec3 head = f.head_valid ? f.head.position : g.index_tip + glm::vec3(0, 0, 1);
            photo_orientation = glm::inverse(t.rotation()) * facing(g.index_tip, head, true);
            ++photo_version;
            live.note("photo placed");
        }
    }
}

void VrSession::Impl::poke_panel(const HandFrame& f)
{
    const VrPanel& panel = self.panel_;
    const glm::quat inv = glm::inverse(panel.orientation);
    for (int h = 0; h < kHandCount; ++h) {
        const HandGesture& g = pipeline.gestures().hand(static_cast<Hand>(h));
        if (!g.tracked || !f.hands[std::size_t(h)].active || g.pinching || g.grabbing) {
            armed[std::size_t(h)] = false;
            continue;
        }
        // The raw index tip: the press lands where the finger is, not where the filter lags.
        const glm::vec3 tip = f.hands[std::size_t(h)][Joint::IndexTip].pose.position;
        const glm::vec3 local_board = inv * (tip - panel.origin);
        if (local_board.z > kArmDistance) {
            armed[std::size_t(h)] = true;
            continue;
        }
        if (!armed[std::size_t(h)] || local_board.z > kPressDepth || local_board.z < -kPokeBehind) continue;
        for (std::size_t i = 0; i < panel.buttons.size(); ++i) {
            const VrButton& b = panel.buttons[i];
            const glm::vec3 local = inv * (tip - b.centre);
            if (std::abs(local.x) > b.half_width || std::abs(local.y) > b.half_height) continue;
            armed[std::size_t(h)] = false;
            press(b, int(i));
            break;
        }
    }
}

void VrSession::Impl::press(const VrButton& b, int index)
{
    highlighted = index;
    highlight_until = time + kHighlightS;
    panel_dirty = true;
    if (b.key != 0) {
        InputEvent e;
        e.kind = InputEventKind::Key;
        e.code = b.key;
        e.value = 1;
        pending.push_back(e);
        e.value = 0;
        pending.push_back(e);
        return;
    }
    const Document& doc = document();
    InputEvent e;
    e.kind = InputEventKind::Setting;
    e.value = 0; // the whole tree
    double v = 0.0;
    switch (b.setting) {
    // Steps and ranges: the panel controls (app/session/panel_controls.h), as the desktop's
    // sliders; the leaf size goes by a quarter per press, rounded to the millimetre.
    case kAngleDown:
    case kAngleUp: {
        const PanelControl& c = *find_panel_control(SettingId::SplitAngle);
        e.code = static_cast<int>(c.id);
        v = std::clamp(doc.settings.growth.split_angle_deg + (b.setting == kAngleUp ? c.step : -c.step), c.lo, c.hi);
        break;
    }
    case kLeafDown:
    case kLeafUp: {
        const PanelControl& c = *find_panel_control(SettingId::LeafLength);
        e.code = static_cast<int>(c.id);
        v = std::clamp(doc.settings.leaves.length_m * (b.setting == kLeafUp ? 1.25 : 0.8), c.lo, c.hi);
        v = std::round(v * 1000.0) / 1000.0;
        break;
    }
    case kLeavesDown:
    case kLeavesUp: {
        const PanelControl& c = *find_panel_control(SettingId::LeavesPerNode);
        e.code = static_cast<int>(c.id);
        v = std::clamp(doc.settings.leaves.per_node + (b.setting == kLeavesUp ? c.step : -c.step), c.lo, c.hi);
        break;
    }
    case kNextSpecies: {
        e.code = static_cast<int>(SettingId::Species);
        int current = 0;
        for (int i = 0; i < kSettingSpeciesCount; ++i)
            if (doc.settings.growth.species == kSettingSpecies[i]) current = i;
        v = (current + 1) % kSettingSpeciesCount;
        break;
    }
    case kNextGrower: {
        // The next of every grower there is (growth/grower.h), round again after the last.
        e.code = static_cast<int>(SettingId::Grower);
        const auto list = growers();
        std::size_t current = 0;
        for (std::size_t i = 0; i < list.size(); ++i)
            if (list[i]->name() == scene_grower(doc).name) current = i;
        v = list[(current + 1) % list.size()]->panel_code();
        break;
    }
    case kStepBack:
    case kStepOn: {
        // The scene grower's growth one step back or on (growth/grower.h steps_param); a
        // grower without steps is told so by the session, as a setting it refuses.
        e.code = static_cast<int>(SettingId::GrowthSteps);
        const std::optional<double> after = growth_steps_after(scene_grower(doc), b.setting == kStepOn ? 1 : -1);
        v = after ? *after : 1.0;
        break;
    }
    case kWidthDown:
    case kWidthUp: {
        // As the leaf length: a quarter per press, rounded to the millimetre.
        const PanelControl& c = *find_panel_control(SettingId::LeafWidth);
        e.code = static_cast<int>(c.id);
        v = std::clamp(doc.settings.leaves.width_m * (b.setting == kWidthUp ? 1.25 : 0.8), c.lo, c.hi);
        v = std::round(v * 1000.0) / 1000.0;
        break;
    }
    case kNextLeafColor:
        e.code = static_cast<int>(SettingId::LeafColor);
        v = next_color(doc.settings.leaves.color, kLeafPalette);
        break;
    case kNextBarkColor:
        e.code = static_cast<int>(SettingId::BarkColor);
        v = next_color(doc.settings.branches.bark_color, kBarkPalette);
        break;
    case kTwigDown:
    case kTwigUp: {
        const PanelControl& c = *find_panel_control(SettingId::TipRadius);
        e.code = static_cast<int>(c.id);
        v = std::clamp(doc.settings.branches.tip_radius_m + (b.setting == kTwigUp ? c.step : -c.step), c.lo, c.hi);
        v = std::round(v * 10000.0) / 10000.0;
        break;
    }
    case kPipeDown:
    case kPipeUp: {
        const PanelControl& c = *find_panel_control(SettingId::PipeExponent);
        e.code = static_cast<int>(c.id);
        v = std::clamp(doc.settings.branches.pipe_exponent + (b.setting == kPipeUp ? c.step : -c.step), c.lo, c.hi);
        v = std::round(v * 10.0) / 10.0;
        break;
    }
    case kNextSeed:
        e.code = static_cast<int>(SettingId::Seed);
        v = double(doc.seed % 16777215u + 1u);
        break;
    default: return;
    }
    e.x = static_cast<float>(v);
    pending.push_back(e);
}

void VrSession::Impl::grab_scene(const HandFrame& f)
{
    const HandGesture& gl = pipeline.gestures().hand(Hand::Left);
    const HandGesture& gr = pipeline.gestures().hand(Hand::Right);
    const bool both = gl.tracked && gr.tracked && gl.grabbing && gr.grabbing && f.hand(Hand::Left).active &&
                      f.hand(Hand::Right).active;
    if (!both) {
        grabbing_scene = false;
        return;
    }
    const glm::vec3 a = f.hand(Hand::Left)[Joint::Palm].pose.position, b = f.hand(Hand::Right)[Joint::Palm].pose.position;
    const glm::vec3 mid = 0.5f * (a + b);
    const float distance = glm::length(glm::vec2(b.x - a.x, b.z - a.z));
    if (!grabbing_scene) {
        grabbing_scene = true;
        grab_start = pipeline.scene_transform();
        grab_anchor_doc = grab_start.to_document(mid);
        grab_distance = std::max(distance, 0.05f);
        grab_heading = heading(b - a);
        return;
    }
    SceneTransform t;
    t.scale = std::clamp(grab_start.scale * std::max(distance, 0.05f) / grab_distance, kMinSceneScale, kMaxSceneScale);
    t.yaw = wrap_pi(grab_start.yaw + wrap_pi(heading(b - a) - grab_heading));
    t.translation = mid - t.rotation() * (t.scale * grab_anchor_doc);
    for (int c = 0; c < 3; ++c)
        t.translation[c] = std::clamp(t.translation[c], -kMaxSceneTranslation, kMaxSceneTranslation);
    // Only what changed goes into the recording, as float (what the events carry).
    const SceneTransform& now = pipeline.scene_transform();
    auto send = [&](SceneComponent c, float value, float current) {
        if (value == current) return;
        InputEvent e;
        e.kind = InputEventKind::Scene;
        e.code = static_cast<int>(c);
        e.x = value;
        pending.push_back(e);
    };
    send(SceneComponent::Scale, t.scale, now.scale);
    send(SceneComponent::Yaw, t.yaw, now.yaw);
    send(SceneComponent::TranslationX, t.translation.x, now.translation.x);
    send(SceneComponent::TranslationY, t.translation.y, now.translation.y);
    send(SceneComponent::TranslationZ, t.translation.z, now.translation.z);
}

void VrSession::Impl::update_status()
{
    VrStatus& s = self.status_;
    s.tool = pipeline.tool();
    s.grown = live.grown();
    s.drawing = pipeline.drawing(Hand::Right) || pipeline.drawing(Hand::Left);
    s.scaling = grabbing_scene;
    s.regrowing = live.regrowing();
    for (int h = 0; h < kHandCount; ++h) s.hands_tracked[h] = pipeline.gestures().hand(static_cast<Hand>(h)).tracked;
    s.strokes = document().strokes.size();
    s.lobes = document().lobes.size();
    s.edits = document().edits.size();
    s.revision = live.revision();
    s.last_message = live.last_message();
    s.tree_error = live.tree_error();
    std::string label = grabbing_scene ? "MOVING SCENE" : tool_label(s.tool);
    if (s.drawing) label += s.tool == Tool::DrawLobe || s.tool == Tool::DrawTrunk ? " - DRAWING" : " - DRAGGING";
    if (live.grown()) label += s.regrowing ? "  GROWING..." : "  TREE";
    if (live.grown() && live.built() && live.built()->wood.co2_kg > 0.0) {
        // The tree's CO2 as grown (docs/wood-and-co2.md), to a tenth of a kilogram.
        char co2[48];
        std::snprintf(co2, sizeof co2, "  CO2 %.1f KG", live.built()->wood.co2_kg);
        label += co2;
    }
    s.label = label;
}

void VrSession::Impl::add_dynamic_items()
{
    RenderScene& scene = live.begin_frame_items();
    const SceneTransform& t = pipeline.scene_transform();
    auto add = [&](std::uint64_t key, std::uint64_t version, RenderMaterial material, std::array<float, 4> color,
                   SurfaceGeometry g) {
        if (g.triangles.empty()) return;
        RenderItem item;
        item.key = key;
        item.version = version;
        item.material = material;
        item.color = color;
        item.geometry = std::move(g);
        scene.items.push_back(std::move(item));
    };
    std::uint64_t n = 0;
    auto add_moving = [&](RenderMaterial material, std::array<float, 4> color, SurfaceGeometry g) {
        to_document(g, t);
        add(kDynamicKey | n++, ++dynamic_version, material, color, std::move(g));
    };

    // Hands, the fingertip marker (the tool's colour) and the label by the right hand.
    for (int h = 0; h < kHandCount; ++h) {
        const HandState& hand = last_frame.hands[std::size_t(h)];
        if (!hand.active) continue;
        const HandGesture& g = pipeline.gestures().hand(static_cast<Hand>(h));
        add_moving(RenderMaterial::Stroke, g.pinching ? kPinchColor : g.grabbing ? kGrabColor : kHandColor,
                   hand_geometry(hand));
        if (g.tracked) {
            SurfaceGeometry marker;
            append_sphere(marker, g.index_tip, 0.007f, 6, 10);
            add_moving(RenderMaterial::Stroke, tool_color(self.status_.tool), std::move(marker));
        }
    }
    const HandState& right = last_frame.hand(Hand::Right);
    if (right.active && !self.status_.label.empty()) {
        const glm::vec3 at = right[Joint::Wrist].pose.position + glm::vec3(0, 0.07f, 0);
        const glm::vec3 head = last_frame.head_valid ? last_frame.head.position : at + glm::vec3(0, 0, 1);
        SurfaceGeometry text;
        append_text(text, self.status_.label, at, facing(at, head, true), 0.012f);
        add_moving(RenderMaterial::Stroke, tool_color(self.status_.tool), std::move(text));
    }
    for (int h = 0; h < kHandCount; ++h) {
        if (!pipeline.drawing(static_cast<Hand>(h))) continue;
        const Stroke& s = pipeline.current_stroke(static_cast<Hand>(h));
        std::vector<glm::vec3> pts;
        for (const StrokePoint& p : s.points) pts.push_back(p.position); // already in the document
        const Tool tool = self.status_.tool;
        const auto color = tool == Tool::DrawLobe ? kLobeInkColor : tool == Tool::DrawTrunk ? kTrunkInkColor : kDragInkColor;
        add(kDynamicKey | n++, ++dynamic_version, RenderMaterial::Stroke, color,
            polyline_tube(pts, 0.0035f / t.scale, 6));
    }

    // The panel: rebuilt (and uploaded) only when it moves in the document or lights up.
    if (panel_placed) {
        if (highlighted >= 0 && time > highlight_until) {
            highlighted = -1;
            panel_dirty = true;
        }
        const bool moved = t.scale != panel_built_for.scale || t.yaw != panel_built_for.yaw ||
                           t.translation != panel_built_for.translation;
        if (panel_dirty || moved || panel_items.empty()) {
            ++panel_version;
            panel_items.clear();
            const VrPanel& panel = self.panel_;
            SurfaceGeometry board, buttons, lit, text;
            append_board(board, panel.origin, panel.orientation, 6 * (kButtonW + kButtonGap) + kButtonGap,
                         5 * (kButtonH + kButtonGap) + kButtonGap, -0.002f);
            for (std::size_t i = 0; i < panel.buttons.size(); ++i) {
                const VrButton& b = panel.buttons[i];
                append_board(int(i) == highlighted ? lit : buttons, b.centre, panel.orientation, 2 * b.half_width,
                             2 * b.half_height);
                append_text(text, b.text, b.centre, panel.orientation, 0.0075f, 0.001f);
            }
            std::uint64_t part = 0;
            for (auto& [g, color] : {std::pair{&board, kBoardColor}, std::pair{&buttons, kButtonColor},
                                     std::pair{&lit, kPressedColor}, std::pair{&text, kTextColor}}) {
                to_document(*g, t);
                const std::uint64_t key = kPanelKey | part++; // each part keeps its key
                if (g->triangles.empty()) continue;
                RenderItem item;
                item.key = key;
                item.version = panel_version;
                item.material = RenderMaterial::Stroke;
                item.color = color;
                item.geometry = std::move(*g);
                panel_items.push_back(std::move(item));
            }
        }
        panel_dirty = false;
        panel_built_for = t;
        // Unchanged, the panel's meshes keep their key and version: nothing is rebuilt or uploaded.
        scene.items.insert(scene.items.end(), panel_items.begin(), panel_items.end());
    }

    // The reference photo, in the document (it scales and turns with the sketch).
    if (photo_centre && !photo.pixels.empty()) {
        const float height = 0.6f / t.scale;
        const float width = height * float(photo.width) / float(std::max(1, photo.height));
        SurfaceGeometry g;
        append_board(g, *photo_centre, photo_orientation, width, height);
        add(kPhotoKey, photo_version, RenderMaterial::Photo, {1.0f, 1.0f, 1.0f, 1.0f}, std::move(g));
    }
}

// ---------------------------------------------------------------------------------------------
VrSession::VrSession(Document doc, VrOptions options)
{
    std::stable_sort(options.events.begin(), options.events.end(),
                     [](const InputEvent& a, const InputEvent& b) { return a.time < b.time; });
    RgbaImage photo;
    if (!options.photo_path.empty()) photo = read_picture_file(options.photo_path);
    LiveSessionOptions o;
    o.session_path = options.session_path;
    o.autosave_path = options.autosave_path;
    o.record_path = options.record_path;
    o.export_path = options.export_path;
    o.recording_header.source =
        "lobesketch vr" + (options.runtime_name.empty() ? std::string() : " (" + options.runtime_name + ")");
    o.recording_header.device = options.device_name.empty() ? "OpenXR hand tracking" : options.device_name;
    o.recording_header.nominal_rate_hz =
        options.nominal_rate_hz > 0.0 && std::isfinite(options.nominal_rate_hz) ? options.nominal_rate_hz : 90.0;
    o.recording_flush_frames = 9; // 0.1 s at 90 Hz
    o.background_regrowth = options.background_regrowth;
    o.lod = 1; // the tree's middle LOD: the full one is for export and pictures (docs/vr.md)
    o.app = std::string("vr");
    o.grow_hint = std::string("GROW on the panel");
    o.export_file_hint = std::string("start with --export FILE.glb");
    o.imports_refused = std::string("the VR app imports no meshes (use lobesketch desktop)");
    o.lsystem_platform = sketch_platform_for(o.recording_header.source);
    o.lsystem_sketch_file = options.lsystem_sketch_file;
    live_ = std::make_unique<LiveSession>(std::move(doc), std::move(o));
    Bounds floor;
    floor.add(glm::vec3(-0.5f, 0.0f, -0.5f));
    floor.add(glm::vec3(0.5f, 1.0f, 0.5f));
    live_->view().set_empty_area(floor);
    impl_ = std::make_unique<Impl>(*this, *live_, std::move(options));
    if (!photo.pixels.empty()) {
        impl_->photo = std::move(photo);
        RenderScene& scene = live_->begin_frame_items();
        scene.photo_texture = impl_->photo;
        scene.photo_texture_version = 1;
    }
    impl_->update_status();
}

VrSession::~VrSession()
{
    try {
        finish(impl_->time + 1e-3);
    } catch (const Error&) {
        // A recording that cannot be flushed at exit: nothing more can be done here.
    }
}

const RenderScene& VrSession::scene() const { return live_->scene(); }
const Document& VrSession::document() const { return live_->document(); }
const std::deque<std::string>& VrSession::messages() const { return live_->messages(); }

void VrSession::frame(const HandFrame& frame)
{
    if (live_->finished()) return;
    impl_->frame(frame);
}

EyeView VrSession::eye_in_document(const EyeView& stage_eye) const
{
    const SceneTransform& t = live_->pipeline().scene_transform();
    EyeView e = stage_eye;
    if (t.identity()) return e;
    e.position = t.to_document(stage_eye.position);
    e.orientation = glm::inverse(t.rotation()) * stage_eye.orientation;
    e.near_m = stage_eye.near_m / t.scale;
    e.far_m = stage_eye.far_m / t.scale;
    return e;
}

const SceneTransform& VrSession::scene_transform() const { return live_->pipeline().scene_transform(); }

bool VrSession::save()
{
    const bool ok = live_->save();
    status_.last_message = live_->last_message();
    return ok;
}

bool VrSession::export_tree()
{
    const bool ok = live_->export_tree();
    status_.last_message = live_->last_message();
    status_.tree_error = live_->tree_error();
    return ok;
}

void VrSession::wait_for_regrowth() { live_->wait_for_regrowth(); }

void VrSession::finish(double time)
{
    Impl& im = *impl_;
    if (live_->finished()) return;
    const double t = std::max(time, im.time);
    std::vector<int> commands;
    while (im.next_replay_event < im.options.events.size()) im.push(im.options.events[im.next_replay_event++], commands);
    for (InputEvent& e : im.pending) {
        e.time = t;
        im.push(e, commands);
    }
    im.pending.clear();
    const std::uint64_t revision = live_->finish_input(); // autosaves from here on hold the end of the recording too
    im.run_commands(commands, im.last_frame);
    live_->close(revision);
    if (!im.options.session_path.empty()) save();
}

} // namespace lobe
