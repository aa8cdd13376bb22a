#include "app/desktop/desktop_session.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <filesystem>
#include <system_error>

#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include "app/render/render_scene.h"
#include "app/render/scene_parts.h"
#include "core/errors.h"

namespace lobe {

namespace {

constexpr float kOrbitDegPerPixel = 0.3f;
constexpr float kDepthStepM = 0.02f; ///< fingertip plane step per wheel notch at 2 m
constexpr std::uint64_t kDynamicKey = 9ull << 56;

/// Colours of the simulated hand and the stroke being drawn (linear RGB).
constexpr std::array<float, 4> kHandColor{0.78f, 0.80f, 0.86f, 1.0f};
constexpr std::array<float, 4> kPinchColor{1.0f, 0.80f, 0.15f, 1.0f};
constexpr std::array<float, 4> kLobeInkColor{1.0f, 1.0f, 1.0f, 1.0f};
constexpr std::array<float, 4> kTrunkInkColor{0.55f, 0.33f, 0.16f, 1.0f};
constexpr std::array<float, 4> kDragInkColor{0.25f, 0.65f, 1.0f, 1.0f};


} // namespace

// ---------------------------------------------------------------------------------------------
glm::vec3 OrbitCamera::eye() const { return target - forward() * distance_m; }

glm::vec3 OrbitCamera::forward() const
{
    const float az = glm::radians(azimuth_deg), el = glm::radians(elevation_deg);
    return -glm::vec3(std::cos(el) * std::sin(az), std::sin(el), std::cos(el) * std::cos(az));
}

Camera OrbitCamera::camera() const
{
    Camera c;
    c.eye = eye();
    c.target = target;
    c.fov_y_deg = fov_y_deg;
    c.near_m = std::max(0.01f, distance_m * 0.01f);
    c.far_m = std::max(100.0f, distance_m * 50.0f);
    return c;
}

glm::vec3 OrbitCamera::ray(glm::vec2 pixel, int width, int height) const
{
    const float w = float(std::max(width, 1)), h = float(std::max(height, 1));
    const float nx = 2.0f * (pixel.x + 0.5f) / w - 1.0f, ny = 1.0f - 2.0f * (pixel.y + 0.5f) / h;
    const glm::vec3 f = forward();
    const glm::vec3 right = glm::normalize(glm::cross(f, glm::vec3(0, 1, 0)));
    const glm::vec3 up = glm::cross(right, f);
    const float tan_y = std::tan(glm::radians(fov_y_deg) * 0.5f);
    return glm::normalize(f + right * (nx * tan_y * (w / h)) + up * (ny * tan_y));
}

// ---------------------------------------------------------------------------------------------
DesktopSession::DesktopSession(Document doc, DesktopOptions options)
{
    LiveSessionOptions o;
    o.session_path = std::move(options.session_path);
    o.autosave_path = std::move(options.autosave_path);
    o.record_path = std::move(options.record_path);
    o.export_path = std::move(options.export_path);
    o.recording_header.source = "lobesketch desktop";
    o.recording_header.device = "mouse (simulated right hand)";
    o.recording_header.nominal_rate_hz = 60.0;
    o.recording_flush_frames = 6; // 0.1 s at 60 Hz
    o.background_regrowth = options.background_regrowth;
    o.lod = 0; // the whole tree; the window lowers it when frames take too long
    o.lsystem_platform = sketch_platform_for(o.recording_header.source);
    o.lsystem_sketch_file = std::move(options.lsystem_sketch_file);
    live_ = std::make_unique<LiveSession>(std::move(doc), std::move(o));
    frame_view_on_scene();
}

DesktopSession::~DesktopSession()
{
    try {
        finish(time_ + 1e-3);
    } catch (const Error&) {
        // A recording that cannot be flushed at exit: nothing more can be done here.
    }
}

void DesktopSession::mouse_move(float x, float y)
{
    InputEvent e;
    e.kind = InputEventKind::MouseMove;
    e.x = x;
    e.y = y;
    pending_.push_back(e);
}

void DesktopSession::mouse_button(int button, bool down)
{
    InputEvent e;
    e.kind = InputEventKind::MouseButton;
    e.code = button;
    e.value = down ? 1 : 0;
    e.x = cursor_.x;
    e.y = cursor_.y;
    pending_.push_back(e);
}

void DesktopSession::mouse_wheel(float dy)
{
    InputEvent e;
    e.kind = InputEventKind::MouseWheel;
    e.y = dy;
    pending_.push_back(e);
}

void DesktopSession::key(int key, bool down)
{
    InputEvent e;
    e.kind = InputEventKind::Key;
    e.code = key;
    e.value = down ? 1 : 0;
    pending_.push_back(e);
}

void DesktopSession::setting(int id, std::int64_t lobe_id, double value)
{
    InputEvent e;
    e.kind = InputEventKind::Setting;
    e.code = id;
    e.value = static_cast<std::int32_t>(std::clamp<std::int64_t>(lobe_id, 0, 0x7fffffff));
    e.x = static_cast<float>(value);
    pending_.push_back(e);
}

bool DesktopSession::import_mesh(const std::string& path, double size_m)
{
    const bool started = live_->import_mesh(path, size_m);
    status_.importing = live_->importing();
    status_.last_message = live_->last_message();
    return started;
}

void DesktopSession::take_import(bool wait)
{
    // A finished import goes in with this frame's input, placed at the fingertip.
    if (std::optional<InputEvent> e = live_->take_import(wait)) pending_.push_back(*e);
    status_.importing = live_->importing();
}

void DesktopSession::wait_for_import() { take_import(true); }

void DesktopSession::handle(const InputEvent& e, int height)
{
    using namespace desktop_keys;
    switch (e.kind) {
    case InputEventKind::MouseMove: {
        const glm::vec2 p(e.x, e.y);
        const glm::vec2 d = cursor_seen_ ? p - cursor_ : glm::vec2(0.0f);
        if (right_down_) {
            orbit_.azimuth_deg = std::fmod(orbit_.azimuth_deg - d.x * kOrbitDegPerPixel, 360.0f);
            orbit_.elevation_deg = std::clamp(orbit_.elevation_deg + d.y * kOrbitDegPerPixel, -85.0f, 85.0f);
        }
        if (middle_down_) {
            const glm::vec3 f = orbit_.forward();
            const glm::vec3 right = glm::normalize(glm::cross(f, glm::vec3(0, 1, 0)));
            const glm::vec3 up = glm::cross(right, f);
            const float m_per_px =
                2.0f * orbit_.distance_m * std::tan(glm::radians(orbit_.fov_y_deg) * 0.5f) / float(std::max(height, 1));
            orbit_.target += (-right * d.x + up * d.y) * m_per_px;
        }
        cursor_ = p;
        cursor_seen_ = true;
        break;
    }
    case InputEventKind::MouseButton:
        if (e.code == kMouseLeft) {
            left_down_ = e.value != 0;
            // A press on the panel belongs to the panel until it is released.
            pinch_ = left_down_ && !ui_capture_;
        } else if (e.code == kMouseRight) {
            right_down_ = e.value != 0;
        } else if (e.code == kMouseMiddle) {
            middle_down_ = e.value != 0;
        }
        break;
    case InputEventKind::MouseWheel:
        if (shift_) {
            orbit_.distance_m = std::clamp(orbit_.distance_m * std::pow(0.9f, e.y), 0.2f, 60.0f);
        } else {
            depth_m_ += e.y * kDepthStepM * std::max(0.5f, orbit_.distance_m / 2.0f);
            depth_m_ = std::clamp(depth_m_, 0.15f - orbit_.distance_m, 20.0f);
        }
        break;
    case InputEventKind::Key:
        if (e.code == kLeftShift || e.code == kRightShift) shift_ = e.value != 0;
        break;
    default: break;
    }
}

void DesktopSession::frame(double time, int width, int height)
{
    if (live_->finished()) return;
    time_ = time > time_ ? time : time_ + 1e-4;
    take_import(false);
    // Where the ground is drawn while nothing is: around the point the camera circles.
    Bounds around;
    around.add(orbit_.target - glm::vec3(0.5f));
    around.add(orbit_.target + glm::vec3(0.5f));
    live_->view().set_empty_area(around);
    std::vector<int> commands;
    for (InputEvent& e : pending_) {
        e.time = time_;
        handle(e, height);
        if (e.kind == InputEventKind::Key && e.value == 1) commands.push_back(e.code);
        live_->push_event(e); // recorded; the pipeline acts on key presses and settings only
    }
    pending_.clear();

    DesktopHandPose pose;
    pose.forward = orbit_.forward();
    const glm::vec3 ray = orbit_.ray(cursor_, width, height);
    const float depth = std::max(0.1f, orbit_.distance_m + depth_m_);
    pose.tip = orbit_.eye() + ray * (depth / std::max(0.05f, glm::dot(ray, pose.forward)));
    pose.pinched = pinch_;
    const HandFrame hand_frame = desktop_frame(time_, pose, cursor_seen_ && cursor_inside_);
    live_->push_frame(hand_frame);
    live_->apply_actions();

    for (int code : commands) {
        if (code == desktop_keys::kSave) save();
        if (code == desktop_keys::kExport) export_tree();
        if (code == desktop_keys::kFrame) frame_view_on_scene();
        if (code == desktop_keys::kQuit) quit_ = true;
    }
    live_->update();

    const InputPipeline& pipeline = live_->pipeline();
    const HandGesture& g = pipeline.gestures().hand(Hand::Right);
    status_.tool = pipeline.tool();
    status_.grown = live_->grown();
    status_.pinching = g.pinching;
    status_.drawing = pipeline.drawing(Hand::Right);
    status_.regrowing = live_->regrowing();
    status_.importing = live_->importing();
    status_.depth_m = depth;
    status_.tip = pose.tip;
    status_.strokes = document().strokes.size();
    status_.lobes = document().lobes.size();
    status_.edits = document().edits.size();
    status_.revision = live_->revision();
    status_.last_message = live_->last_message();
    status_.tree_error = live_->tree_error();
    status_.lod = live_->view().lod_shown();
    status_.tree_triangles = live_->view().tree_triangles();
    const RegrowResult* built = live_->grown() ? live_->built() : nullptr;
    status_.wood_m3 = built ? built->wood.wood_volume_m3 : 0.0;
    status_.co2_kg = built ? built->wood.co2_kg : 0.0;
    last_hand_ = hand_frame.hand(Hand::Right);
    add_frame_items();
}

void DesktopSession::add_frame_items()
{
    RenderScene& scene = live_->begin_frame_items();
    const std::size_t first = scene.items.size();
    auto add = [&](RenderMaterial material, std::array<float, 4> color, SurfaceGeometry g) {
        if (g.triangles.empty()) return;
        RenderItem item;
        item.key = kDynamicKey | (scene.items.size() - first);
        item.version = ++dynamic_version_;
        item.material = material;
        item.color = color;
        item.geometry = std::move(g);
        scene.items.push_back(std::move(item));
    };
    if (last_hand_.active) {
        SurfaceGeometry hand = hand_geometry(last_hand_);
        add(RenderMaterial::Stroke, status_.pinching ? kPinchColor : kHandColor, std::move(hand));
        SurfaceGeometry marker;
        append_sphere(marker, status_.tip, 0.008f, 6, 10);
        add(RenderMaterial::Stroke, tool_color(status_.tool), std::move(marker));
    }
    if (status_.drawing) {
        const Stroke& s = live_->pipeline().current_stroke(Hand::Right);
        std::vector<glm::vec3> pts;
        for (const StrokePoint& p : s.points) pts.push_back(p.position);
        const Tool t = status_.tool;
        const auto color = t == Tool::DrawLobe ? kLobeInkColor : t == Tool::DrawTrunk ? kTrunkInkColor : kDragInkColor;
        add(RenderMaterial::Stroke, color, polyline_tube(pts, 0.0035f, 6));
    }
}

bool DesktopSession::save()
{
    const bool ok = live_->save();
    status_.last_message = live_->last_message();
    return ok;
}

bool DesktopSession::export_tree()
{
    const bool ok = live_->export_tree();
    status_.last_message = live_->last_message();
    return ok;
}

void DesktopSession::set_lod(int lod)
{
    live_->set_lod(lod);
    status_.lod = live_->view().lod_shown();
    status_.tree_triangles = live_->view().tree_triangles();
    add_frame_items();
}

void DesktopSession::frame_view_on_scene()
{
    Bounds b;
    const RenderScene& scene = live_->scene();
    for (std::size_t i = 0; i < std::min(live_->view().static_items(), scene.items.size()); ++i)
        for (const glm::vec3& p : scene.items[i].geometry.positions) b.add(p);
    if (b.empty()) return; // nothing drawn yet: keep the default view
    const Camera c = frame_view(b, {orbit_.azimuth_deg, orbit_.elevation_deg}, 1.6f, orbit_.fov_y_deg, 0.1f);
    orbit_.target = c.target;
    orbit_.distance_m = std::max(0.2f, glm::length(c.eye - c.target));
}

void DesktopSession::wait_for_regrowth() { live_->wait_for_regrowth(); }

void DesktopSession::finish(double time)
{
    if (live_->finished()) return;
    take_import(true); // an import still being made goes in last, not lost
    for (InputEvent& e : pending_) {
        e.time = std::max(time, time_);
        live_->push_event(e);
    }
    pending_.clear();
    live_->close(live_->finish_input());
}

} // namespace lobe
