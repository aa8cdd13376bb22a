#include "app/vr/vr_session.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>

#include <glm/geometric.hpp>
#include <glm/gtc/constants.hpp>
#include <glm/mat3x3.hpp>

#include "app/live/autosave.h"
#include "app/session/edit_hooks.h"
#include "app/export/export_scene.h"
#include "app/live/drag_preview.h"
#include "app/live/live_pinch.h"
#include "app/live/live_stroke_edit.h"
#include "app/live/live_transform.h"
#include "app/render/render_scene.h"
#include "app/render/scene_parts.h"
#include "app/export/tree_output.h"
#include "core/errors.h"

namespace lobe {

namespace {

constexpr std::size_t kMaxMessages = 200;
constexpr std::uint64_t kDynamicKey = 10ull << 56;
constexpr std::uint64_t kPanelKey = kDynamicKey | (1ull << 40);
constexpr std::uint64_t kPhotoKey = kDynamicKey | (2ull << 40);

/// What a stroke's tube is made from (its points, round again when closed), hashed.
std::uint64_t stroke_fingerprint(const Stroke& st)
{
    std::vector<glm::vec3> pts;
    pts.reserve(st.points.size() + 1);
    for (const StrokePoint& p : st.points) pts.push_back(p.position);
    if (st.closed && pts.size() > 2) pts.push_back(pts.front());
    return bytes_hash(pts.data(), pts.size() * sizeof(glm::vec3));
}

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
    kAngleDown = 1, kAngleUp, kLeafDown, kLeafUp, kLeavesDown, kLeavesUp, kNextSpecies, kNextSeed,
};

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
         key_button("DEL STROKE", keys::kDeleteStroke)},
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

/// The regrowth's part of the VR scene (lobes; the tree's middle LOD once grown: the full one
/// is for export and pictures, docs/vr.md), made on the regrowth worker's thread
/// (RegrowWorker's prepare hook) with its bounds in ground_area, so that taking a new tree
/// costs the frame only moves.
void prepare_grown_scene(RegrowResult& r)
{
    std::vector<TriangleMesh> lobes;
    lobes.reserve(r.tree.lobes.size());
    for (const BuiltLobe& l : r.tree.lobes) lobes.push_back(l.mesh);
    RenderContent content;
    content.tree = content.leaves = r.grown && !r.geometry.lods.empty();
    content.lobes = true;
    content.strokes = false;
    content.lod = content.tree ? std::min(1, int(r.geometry.lods.size()) - 1) : 0;
    r.scene = tree_render_scene(r.geometry, lobes, {}, 0.0f, content);
    r.scene.ground_area = scene_bounds(r.scene);
}

// ---------------------------------------------------------------------------------------------
struct VrSession::Impl {
    VrSession& self;
    VrOptions options;
    InputPipeline pipeline;
    std::unique_ptr<RecordingWriter> recording;
    std::unique_ptr<AutosaveWriter> autosaver;
    std::unique_ptr<RegrowWorker> worker;

    std::vector<InputEvent> pending;  ///< panel presses and scene moves, applied by the next frame
    std::size_t next_replay_event = 0; ///< into options.events
    std::size_t next_clock = 0;        ///< into options.clock
    bool panel_placed = false;
    double time = 0.0;
    bool started = false, finished = false;
    std::uint64_t frames_recorded = 0;

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

    bool grown = false;
    std::uint64_t revision = 0, requested_generation = 0, dynamic_version = 0;
    std::optional<RegrowResult> built;
    std::size_t builder_messages_seen = 0;
    // The scene's items: [0, grown_items) the regrowth's lobes and tree (made on the worker),
    // [grown_items, static_items) the strokes, then the hands, panel and labels of this frame.
    std::size_t grown_items = 0, static_items = 0;
    Bounds grown_bounds, stroke_bounds;
    struct StrokeTube {
        std::int64_t id = 0;
        std::uint64_t fingerprint = 0; ///< of the points the tube was made from
    };
    /// What scene_.items[grown_items, static_items) were made from, in order: a stroke's tube
    /// is made again only when its points changed.
    std::vector<StrokeTube> stroke_tubes;
    HandFrame last_frame;
    // The lobe being deformed live (app/live/live_pinch.h): which grown item shows it, and the
    // regrowth generation whose items those are.
    LivePinchView live_pinch;
    LiveTransformView live_transform; ///< the lobe being moved, turned or scaled live, with its strokes
    LiveStrokeEditView live_stroke_edit; ///< the stroke being bent live
    DragPreview drag_preview; ///< the document as an editing drag would leave it, regrown while it goes on
    std::uint64_t preview_generation = 0; ///< the regrowth last asked for a drag preview
    std::optional<std::size_t> live_shown;
    std::uint64_t live_shown_generation = 0;

    Impl(VrSession& s, VrOptions o, const Document& doc) : self(s), options(std::move(o)), pipeline(doc.settings.input) {}

    SessionBuilder& builder() { return *self.builder_; }
    const Document& document() const { return self.builder_->document(); }

    void note(std::string line)
    {
        self.status_.last_message = line;
        self.messages_.push_back(std::move(line));
        while (self.messages_.size() > kMaxMessages) self.messages_.pop_front();
    }

    void push(const InputEvent& e, std::vector<int>& commands)
    {
        if (recording) recording->append(e);
        if (e.kind == InputEventKind::Key && e.value == 1) commands.push_back(e.code);
        pipeline.push_event(e);
    }

    void frame(const HandFrame& input);
    void apply_actions();
    void run_commands(const std::vector<int>& commands, const HandFrame& f);
    void poke_panel(const HandFrame& f);
    void press(const VrButton& b, int index);
    void grab_scene(const HandFrame& f);
    void document_changed();
    void request_regrowth();
    void submit_preview(Document doc);
    void take_regrowth(std::optional<RegrowResult> result);
    void update_live_edits();
    void refresh_stroke_item(const Stroke& stroke);
    void rebuild_stroke_items();
    void update_ground_area();
    void autosave();
    void report_autosave_failures();
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

    pipeline.push_frame(f);
    if (recording) recording->append(f);
    ++frames_recorded;
    apply_actions();
    run_commands(commands, f);

    if (panel_placed) poke_panel(f);
    grab_scene(f);

    if (options.background_regrowth) take_regrowth(worker->take());
    update_live_edits();
    report_autosave_failures();
    last_frame = f;
    update_status();
    add_dynamic_items();
}

void VrSession::Impl::apply_actions()
{
    bool changed = false;
    for (const InputAction& a : pipeline.take_actions()) {
        if (a.type == InputAction::Type::StrokeDiscarded) note("stroke discarded: " + a.message);
        if (a.type == InputAction::Type::Grow && !grown) {
            grown = true;
            note("growing the tree");
            request_regrowth();
        }
        if (builder().apply(a)) changed = true;
    }
    const auto& builder_messages = builder().messages();
    for (; builder_messages_seen < builder_messages.size(); ++builder_messages_seen)
        note(builder_messages[builder_messages_seen]);
    if (changed) document_changed();
}

void VrSession::Impl::run_commands(const std::vector<int>& commands, const HandFrame& f)
{
    for (int code : commands) {
        if (code == vr_keys::kSave) self.save();
        if (code == vr_keys::kExport) self.export_tree();
        if (code == vr_keys::kQuit) self.quit_ = true;
        if (code == vr_keys::kPlacePhoto) {
            if (photo.pixels.empty()) {
                note("photo: no picture (start with --photo FILE)");
                continue;
            }
            const HandState& right = f.hand(Hand::Right);
            const HandGesture& g = pipeline.gestures().hand(Hand::Right);
            if (!g.tracked || !right.active) {
                note("photo: the right hand is not tracked");
                continue;
            }
            const SceneTransform& t = pipeline.scene_transform();
            // Standing at the fingertip, turned to the head, 0.6 m tall as the person sees it.
            photo_centre = t.to_document(g.index_tip);
            const glm::vec3 head = f.head_valid ? f.head.position : g.index_tip + glm::vec3(0, 0, 1);
            photo_orientation = glm::inverse(t.rotation()) * facing(g.index_tip, head, true);
            ++photo_version;
            note("photo placed");
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
    case kAngleDown:
    case kAngleUp:
        e.code = static_cast<int>(SettingId::SplitAngle);
        v = std::clamp(doc.settings.growth.split_angle_deg + (b.setting == kAngleUp ? 5.0 : -5.0), 5.0, 90.0);
        break;
    case kLeafDown:
    case kLeafUp:
        e.code = static_cast<int>(SettingId::LeafLength);
        v = std::clamp(doc.settings.leaves.length_m * (b.setting == kLeafUp ? 1.25 : 0.8), 0.005, 0.5);
        v = std::round(v * 1000.0) / 1000.0;
        break;
    case kLeavesDown:
    case kLeavesUp:
        e.code = static_cast<int>(SettingId::LeavesPerNode);
        v = std::clamp(doc.settings.leaves.per_node + (b.setting == kLeavesUp ? 1 : -1), 0, 16);
        break;
    case kNextSpecies: {
        e.code = static_cast<int>(SettingId::Species);
        int current = 0;
        for (int i = 0; i < kSettingSpeciesCount; ++i)
            if (doc.settings.growth.species == kSettingSpecies[i]) current = i;
        v = (current + 1) % kSettingSpeciesCount;
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

void VrSession::Impl::document_changed()
{
    ++revision;
    autosave();
    request_regrowth();
    rebuild_stroke_items(); // strokes show at once; lobes and the tree follow the regrowth
}

void VrSession::Impl::autosave()
{
    if (!autosaver) return;
    // The recording is flushed on this thread (a write of at most 9 frames, no sync), so that
    // whichever autosave is on disk when the program dies, the recording holds all it holds;
    // the JSON and the disk are the writer thread's (app/live/autosave.h). Without background
    // regrowth (tests) it is on disk before the frame ends.
    const std::string why = autosaver->submit_after_change(recording.get(), document(), frames_recorded, finished,
                                                           !options.background_regrowth);
    if (!why.empty()) note("autosave failed: " + why);
}

void VrSession::Impl::report_autosave_failures()
{
    if (!autosaver) return;
    for (const std::string& why : autosaver->take_failures()) note("autosave failed: " + why);
}

void VrSession::Impl::request_regrowth()
{
    requested_generation = worker->submit(document(), grown);
    if (!options.background_regrowth) take_regrowth(worker->wait_for(requested_generation));
}

void VrSession::Impl::submit_preview(Document doc)
{
    preview_generation = worker->submit(std::move(doc), grown);
    if (!options.background_regrowth) take_regrowth(worker->wait_for(preview_generation));
}

void VrSession::Impl::take_regrowth(std::optional<RegrowResult> result)
{
    if (!result) return;
    if (built && result->generation < built->generation) return;
    // A drag preview's result (asked for after the last change of the document) is shown; what
    // it reports goes to the status line alone (preview_report).
    if (result->generation <= requested_generation) {
        self.status_.tree_error = result->error;
        if (!result->error.empty()) note("tree: " + result->error);
        for (const std::string& w : result->tree.warnings) note(w);
    } else if (std::string report = preview_report(*result); !report.empty()) {
        self.status_.last_message = std::move(report);
    }
    RenderScene& scene = self.scene_;
    // The regrowth's items, made on the worker (prepare_grown_scene), replace the old ones;
    // the strokes' items stay as they are.
    scene.items.resize(static_items); // this frame's hands and panel are added again
    scene.items.erase(scene.items.begin(), scene.items.begin() + std::ptrdiff_t(grown_items));
    static_items -= grown_items;
    grown_items = result->scene.items.size();
    static_items += grown_items;
    scene.items.insert(scene.items.begin(), std::make_move_iterator(result->scene.items.begin()),
                       std::make_move_iterator(result->scene.items.end()));
    result->scene.items.clear();
    scene.leaf_texture = std::move(result->scene.leaf_texture);
    scene.leaf_texture_version = result->scene.leaf_texture_version;
    grown_bounds = result->scene.ground_area;
    built = std::move(result);
    update_ground_area();
}

void VrSession::Impl::update_live_edits()
{
    // The lobes and the tree follow an editing drag at the regrowth's pace; when it ends
    // without an edit, the document's own are grown again.
    DragPreview::Step preview = drag_preview.update(pipeline, builder(), !worker->has_waiting());
    if (preview.preview) submit_preview(std::move(*preview.preview));
    else if (preview.ended && preview_generation > requested_generation) request_regrowth();

    const std::uint64_t have = built ? built->generation : 0;
    const std::vector<BuiltLobe>* lobes = built ? &built->tree.lobes : nullptr;
    const bool pinched = live_pinch.update(pipeline, builder(), lobes, have, requested_generation);
    const bool moved = live_transform.update(pipeline, builder(), lobes, have, requested_generation);
    // A bent stroke's tube and a moved lobe's strokes: as dragged, or the document's again
    // once the drag is over.
    std::vector<std::int64_t> put_back;
    if (live_stroke_edit.update(pipeline, builder())) {
        if (const Stroke* bent = live_stroke_edit.stroke()) refresh_stroke_item(*bent);
        else put_back.push_back(live_stroke_edit.bent_stroke_id());
    }
    if (moved) {
        for (const Stroke& st : live_transform.strokes()) refresh_stroke_item(st);
        if (live_transform.strokes().empty())
            put_back.insert(put_back.end(), live_transform.moved_stroke_ids().begin(), live_transform.moved_stroke_ids().end());
    }
    if (!put_back.empty())
        for (const Stroke& st : effective_strokes(document()))
            if (std::find(put_back.begin(), put_back.end(), st.id) != put_back.end()) refresh_stroke_item(st);
    // A new regrowth result brought its own lobe items: the edited lobe goes into them again.
    const bool fresh = have != live_shown_generation;
    if (!pinched && !moved && !fresh) return;
    RenderScene& scene = self.scene_;
    if (live_shown && !fresh && built && *live_shown < built->tree.lobes.size())
        replace_lobe_item(scene, *live_shown, built->tree.lobes[*live_shown].mesh);
    live_shown.reset();
    live_shown_generation = have;
    if (!built) return;
    for (std::size_t i = 0; i < built->tree.lobes.size(); ++i) {
        const std::int64_t id = built->tree.lobes[i].lobe_id;
        const TriangleMesh* m = live_pinch.mesh_for(id, pipeline, have, requested_generation);
        if (!m) m = live_transform.mesh_for(id, have, requested_generation);
        if (m) {
            if (replace_lobe_item(scene, i, *m)) live_shown = i;
            break;
        }
    }
}

void VrSession::Impl::refresh_stroke_item(const Stroke& stroke)
{
    // The tube and the fingerprint rebuild_stroke_items keeps for it, so that the next
    // rebuild makes the tube again exactly when the document's points differ from these.
    for (std::size_t i = 0; i < stroke_tubes.size(); ++i)
        if (stroke_tubes[i].id == stroke.id && grown_items + i < self.scene_.items.size()) {
            if (!replace_stroke_item(self.scene_, stroke)) return;
            stroke_tubes[i].fingerprint = stroke_fingerprint(stroke);
            return;
        }
}

void VrSession::Impl::rebuild_stroke_items()
{
    // A tube only for a stroke that is new or changed (most changes add one); the others are
    // moved from the scene's stroke items as they are.
    RenderScene& scene = self.scene_;
    std::map<std::int64_t, std::pair<std::uint64_t, RenderItem>> old;
    for (std::size_t i = 0; i < stroke_tubes.size(); ++i)
        old.emplace(stroke_tubes[i].id,
                    std::make_pair(stroke_tubes[i].fingerprint, std::move(scene.items[grown_items + i])));
    scene.items.resize(grown_items);
    stroke_tubes.clear();
    stroke_bounds = Bounds{};
    std::vector<Stroke> strokes = effective_strokes(document());
    live_transform.apply_to(strokes); // a lobe being moved shows its strokes where it is dragged
    live_stroke_edit.apply_to(strokes);
    for (const Stroke& st : strokes) {
        const std::uint64_t fingerprint = stroke_fingerprint(st);
        const auto it = old.find(st.id);
        RenderItem item;
        if (it != old.end() && it->second.first == fingerprint) item = std::move(it->second.second);
        else {
            RenderContent content;
            content.tree = content.leaves = content.lobes = false;
            content.strokes = true;
            RenderScene one = tree_render_scene(TreeGeometry{}, {}, {st}, 0.0f, content);
            if (one.items.empty()) continue;
            item = std::move(one.items.front());
        }
        for (const glm::vec3& p : item.geometry.positions) stroke_bounds.add(p);
        scene.items.push_back(std::move(item));
        stroke_tubes.push_back({st.id, fingerprint});
    }
    static_items = scene.items.size();
    update_ground_area();
}

void VrSession::Impl::update_ground_area()
{
    Bounds area = grown_bounds;
    if (!stroke_bounds.empty()) {
        area.add(stroke_bounds.lo);
        area.add(stroke_bounds.hi);
    }
    if (area.empty()) {
        area.add(glm::vec3(-0.5f, 0.0f, -0.5f));
        area.add(glm::vec3(0.5f, 1.0f, 0.5f));
    }
    self.scene_.ground_area = area;
}

void VrSession::Impl::update_status()
{
    VrStatus& s = self.status_;
    s.tool = pipeline.tool();
    s.grown = grown;
    s.drawing = pipeline.drawing(Hand::Right) || pipeline.drawing(Hand::Left);
    s.scaling = grabbing_scene;
    s.regrowing = requested_generation > 0 && (!built || built->generation < requested_generation);
    for (int h = 0; h < kHandCount; ++h) s.hands_tracked[h] = pipeline.gestures().hand(static_cast<Hand>(h)).tracked;
    s.strokes = document().strokes.size();
    s.lobes = document().lobes.size();
    s.edits = document().edits.size();
    s.revision = revision;
    std::string label = grabbing_scene ? "MOVING SCENE" : tool_label(s.tool);
    if (s.drawing) label += s.tool == Tool::DrawLobe || s.tool == Tool::DrawTrunk ? " - DRAWING" : " - DRAGGING";
    if (grown) label += s.regrowing ? "  GROWING..." : "  TREE";
    s.label = label;
}

void VrSession::Impl::add_dynamic_items()
{
    RenderScene& scene = self.scene_;
    scene.items.resize(static_items);
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
    impl_ = std::make_unique<Impl>(*this, std::move(options), doc);
    VrOptions& o = impl_->options;
    std::stable_sort(o.events.begin(), o.events.end(),
                     [](const InputEvent& a, const InputEvent& b) { return a.time < b.time; });
    if (!o.photo_path.empty()) {
        impl_->photo = read_picture_file(o.photo_path);
        scene_.photo_texture = impl_->photo;
        scene_.photo_texture_version = 1;
    }
    if (!o.record_path.empty()) {
        RecordingHeader header;
        header.source = "lobesketch vr" + (o.runtime_name.empty() ? std::string() : " (" + o.runtime_name + ")");
        header.device = o.device_name.empty() ? "OpenXR hand tracking" : o.device_name;
        header.nominal_rate_hz = o.nominal_rate_hz > 0.0 && std::isfinite(o.nominal_rate_hz) ? o.nominal_rate_hz : 90.0;
        // Flushed every 9 frames (0.1 s at 90 Hz): a crash loses at most that much input.
        impl_->recording = std::make_unique<RecordingWriter>(o.record_path, header, 9);
        doc.source_recording = std::filesystem::absolute(o.record_path).lexically_normal().string();
    }
    EditHooks hooks = meshing_edit_hooks();
    hooks.import_model = [](int n) -> std::shared_ptr<const LobeModel> {
        throw InvalidInput("import " + std::to_string(n) + ": the VR app imports no meshes (use lobesketch desktop)");
    };
    // A loaded document's position in its old recording no longer holds; the saves of this
    // session stamp theirs (at_recording_position).
    doc.recording_frames.reset();
    doc.recording_finished = false;
    builder_ = std::make_unique<SessionBuilder>(std::move(doc), EditPickOptions{}, std::move(hooks));
    if (!o.autosave_path.empty()) impl_->autosaver = std::make_unique<AutosaveWriter>(o.autosave_path);
    impl_->worker = std::make_unique<RegrowWorker>(prepare_grown_scene);
    if (!document().strokes.empty() || !document().lobes.empty()) impl_->request_regrowth();
    impl_->rebuild_stroke_items();
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

void VrSession::frame(const HandFrame& frame)
{
    if (impl_->finished) return;
    impl_->frame(frame);
}

EyeView VrSession::eye_in_document(const EyeView& stage_eye) const
{
    const SceneTransform& t = impl_->pipeline.scene_transform();
    EyeView e = stage_eye;
    if (t.identity()) return e;
    e.position = t.to_document(stage_eye.position);
    e.orientation = glm::inverse(t.rotation()) * stage_eye.orientation;
    e.near_m = stage_eye.near_m / t.scale;
    e.far_m = stage_eye.far_m / t.scale;
    return e;
}

const SceneTransform& VrSession::scene_transform() const { return impl_->pipeline.scene_transform(); }

bool VrSession::save()
{
    if (impl_->options.session_path.empty()) {
        impl_->note("save: no session file (start with `lobesketch vr SESSION.json`)");
        return false;
    }
    Impl& im = *impl_;
    try {
        if (im.recording && !im.finished) im.recording->flush(); // closed once finished
        save_document(im.options.session_path,
                      at_recording_position(document(), im.recording != nullptr, im.frames_recorded, im.finished));
        impl_->note("saved " + impl_->options.session_path);
        return true;
    } catch (const Error& e) {
        impl_->note(std::string("save failed: ") + e.what());
        return false;
    }
}

bool VrSession::export_tree()
{
    Impl& im = *impl_;
    if (!im.grown) {
        im.note("export: grow the tree first (GROW on the panel)");
        return false;
    }
    wait_for_regrowth();
    if (!im.built || !im.built->grown || im.built->geometry.lods.empty()) {
        im.note("export: there is no tree to export" + (status_.tree_error.empty() ? "" : ": " + status_.tree_error));
        return false;
    }
    if (im.options.export_path.empty()) {
        im.note("export: no export file (start with --export FILE.glb)");
        return false;
    }
    try {
        ExportOptions o;
        o.include_lobes = o.include_strokes = true;
        write_tree_file(im.options.export_path, document(), im.built->tree, im.built->geometry, o);
        im.note("exported " + im.options.export_path + " (" + lod_triangle_summary(im.built->geometry) + ")");
        return true;
    } catch (const Error& e) {
        im.note(std::string("export failed: ") + e.what());
        return false;
    }
}

void VrSession::wait_for_regrowth()
{
    Impl& im = *impl_;
    if (im.requested_generation == 0) return;
    if (im.built && im.built->generation >= im.requested_generation) return;
    im.take_regrowth(im.worker->wait_for(im.requested_generation));
}

void VrSession::finish(double time)
{
    Impl& im = *impl_;
    if (im.finished) return;
    im.finished = true;
    const double t = std::max(time, im.time);
    std::vector<int> commands;
    while (im.next_replay_event < im.options.events.size()) im.push(im.options.events[im.next_replay_event++], commands);
    for (InputEvent& e : im.pending) {
        e.time = t;
        im.push(e, commands);
    }
    im.pending.clear();
    im.pipeline.finish();
    const std::uint64_t revision = im.revision;
    im.apply_actions(); // autosaves from here on hold the end of the recording too
    im.run_commands(commands, im.last_frame);
    // The end changed nothing: the last autosave still says so, for `recover` to see that
    // nothing of the recording is left to replay.
    if (im.revision == revision && im.revision > 0) im.autosave();
    if (im.autosaver) {
        im.autosaver->wait();
        im.report_autosave_failures();
    }
    if (im.recording) im.recording->close();
    if (!im.options.session_path.empty()) save();
}

} // namespace lobe
