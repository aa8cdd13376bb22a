#include "app/desktop/desktop_session.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <filesystem>
#include <system_error>

#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include "app/live/autosave.h"
#include "app/session/edit_hooks.h"
#include "app/render/render_scene.h"
#include "app/render/scene_parts.h"
#include "app/export/tree_output.h"
#include "core/errors.h"
#include "app/session/edit_ops.h"
#include "meshing/mesh_io.h"
#include "meshing/mesh_quality.h"
#include "meshing/model_import.h"

namespace lobe {

namespace {

constexpr float kOrbitDegPerPixel = 0.3f;
constexpr float kDepthStepM = 0.02f; ///< fingertip plane step per wheel notch at 2 m
constexpr std::size_t kMaxMessages = 200;
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
    : options_(std::move(options)), pipeline_(doc.settings.input)
{
    if (!options_.record_path.empty()) {
        RecordingHeader header;
        header.source = "lobesketch desktop";
        header.device = "mouse (simulated right hand)";
        header.nominal_rate_hz = 60.0;
        // Flushed every 6 frames (0.1 s at 60 Hz): a crash loses at most that much input.
        recording_ = std::make_unique<RecordingWriter>(options_.record_path, header, 6);
        doc.source_recording = std::filesystem::absolute(options_.record_path).lexically_normal().string();
    }
    // A loaded document's position in its old recording no longer holds; the saves of this
    // session stamp theirs (at_recording_position).
    doc.recording_frames.reset();
    doc.recording_finished = false;
    EditHooks hooks = meshing_edit_hooks();
    // Imports of this session, by number (the recording's ImportMesh events).
    hooks.import_model = [this](int n) {
        const auto it = imports_.find(n);
        if (it == imports_.end()) throw InvalidInput("import " + std::to_string(n) + " was not made in this session");
        return it->second;
    };
    builder_ = std::make_unique<SessionBuilder>(std::move(doc), EditPickOptions{}, std::move(hooks));
    if (!options_.autosave_path.empty()) autosaver_ = std::make_unique<AutosaveWriter>(options_.autosave_path);
    worker_ = std::make_unique<RegrowWorker>();
    if (!document().strokes.empty()) request_regrowth();
    rebuild_static_scene();
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

void DesktopSession::note(std::string line)
{
    status_.last_message = line;
    messages_.push_back(std::move(line));
    while (messages_.size() > kMaxMessages) messages_.pop_front();
}

void DesktopSession::record(const InputEvent& e)
{
    if (recording_) recording_->append(e);
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
    const Document& doc = document();
    LobeFromModelOptions o;
    o.size_m = size_m;
    o.target_edge_length_m = doc.settings.lobes.edge_length_m;
    o.iterations = static_cast<unsigned>(doc.settings.lobes.remesh_iterations);
    try {
        if (import_) throw InvalidInput("another import is still being made");
        if (!(size_m > 0.01 && size_m <= 100.0)) throw InvalidInput("the size must be in (0.01, 100] m");
        std::error_code ec;
        if (!std::filesystem::is_regular_file(path, ec)) throw FileError(path, "not found, or not a file");
    } catch (const Error& e) {
        note(std::string("import: ") + e.what());
        return false;
    }
    const int n = static_cast<int>(imports_.size()) + 1;
    // Beside the recording, so that replaying it imports the same mesh.
    const std::string beside = recording_ ? import_mesh_path(options_.record_path, n) : std::string();
    auto make = [path, o, beside]() {
        TriangleMesh mesh = lobe_from_model(path, o);
        // Centred on the origin; the import event places it at the fingertip.
        glm::dvec3 lo, hi;
        bounding_box(mesh, lo, hi);
        const glm::dvec3 centre = 0.5 * (lo + hi);
        for (glm::vec3& p : mesh.positions) p = glm::vec3(glm::dvec3(p) - centre);
        std::string source = std::filesystem::path(path).filename().string();
        if (!beside.empty()) {
            write_ply(beside, mesh);
            source = std::filesystem::path(beside).filename().string();
        }
        return std::make_shared<const LobeModel>(LobeModel{source, std::move(mesh)});
    };
    try {
        import_ = PendingImport{n, path, std::async(std::launch::async, std::move(make))};
    } catch (const std::system_error& e) {
        note(std::string("import: no thread to make it on: ") + e.what());
        return false;
    }
    status_.importing = true;
    note("importing " + path + " ...");
    return true;
}

void DesktopSession::take_import(bool wait)
{
    if (!import_) return;
    if (!wait && import_->model.wait_for(std::chrono::seconds(0)) != std::future_status::ready) return;
    PendingImport done = std::move(*import_);
    import_.reset();
    status_.importing = false;
    try {
        imports_[done.number] = done.model.get();
    } catch (const Error& e) {
        note(std::string("import: ") + e.what());
        return;
    } catch (const std::exception& e) {
        note("import: " + one_line_message(done.path + ": " + e.what()));
        return;
    }
    InputEvent e;
    e.kind = InputEventKind::ImportMesh;
    e.code = done.number;
    pending_.push_back(e);
    note("imported " + done.path + " as a lobe at the fingertip");
}

void DesktopSession::wait_for_import() { take_import(true); }

void DesktopSession::handle(const InputEvent& e, int width, int height)
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
    (void)width;
}

void DesktopSession::frame(double time, int width, int height)
{
    if (finished_) return;
    time_ = time > time_ ? time : time_ + 1e-4;
    take_import(false); // a finished import goes in with this frame's input
    std::vector<int> commands;
    for (InputEvent& e : pending_) {
        e.time = time_;
        handle(e, width, height);
        record(e);
        if (e.kind == InputEventKind::Key && e.value == 1) commands.push_back(e.code);
        pipeline_.push_event(e); // the pipeline acts on key presses and settings only
    }
    pending_.clear();

    DesktopHandPose pose;
    pose.forward = orbit_.forward();
    const glm::vec3 ray = orbit_.ray(cursor_, width, height);
    const float depth = std::max(0.1f, orbit_.distance_m + depth_m_);
    pose.tip = orbit_.eye() + ray * (depth / std::max(0.05f, glm::dot(ray, pose.forward)));
    pose.pinched = pinch_;
    const HandFrame hand_frame = desktop_frame(time_, pose, cursor_seen_ && cursor_inside_);
    pipeline_.push_frame(hand_frame);
    if (recording_) {
        recording_->append(hand_frame);
        ++frames_recorded_;
    }
    apply_actions();

    for (int code : commands) {
        if (code == desktop_keys::kSave) save();
        if (code == desktop_keys::kExport) export_tree();
        if (code == desktop_keys::kFrame) frame_view_on_scene();
        if (code == desktop_keys::kQuit) quit_ = true;
    }

    if (options_.background_regrowth) take_regrowth(worker_->take());
    report_autosave_failures();

    const HandGesture& g = pipeline_.gestures().hand(Hand::Right);
    status_.tool = pipeline_.tool();
    status_.grown = grown_;
    status_.pinching = g.pinching;
    status_.drawing = pipeline_.drawing(Hand::Right);
    status_.regrowing = requested_generation_ > 0 && (!built_ || built_->generation < requested_generation_);
    status_.depth_m = depth;
    status_.tip = pose.tip;
    status_.strokes = document().strokes.size();
    status_.lobes = document().lobes.size();
    status_.edits = document().edits.size();
    status_.revision = revision_;
    last_hand_ = hand_frame.hand(Hand::Right);
    update_live_edits();
    add_dynamic_items();
}

void DesktopSession::update_live_edits()
{
    // The lobes and the tree follow an editing drag at the regrowth's pace; when it ends
    // without an edit, the document's own are grown again.
    DragPreview::Step preview = drag_preview_.update(pipeline_, *builder_, !worker_->has_waiting());
    if (preview.preview) submit_preview(std::move(*preview.preview));
    else if (preview.ended && preview_generation_ > requested_generation_) request_regrowth();

    const std::uint64_t have = built_ ? built_->generation : 0;
    const std::vector<BuiltLobe>* lobes = built_ ? &built_->tree.lobes : nullptr;
    const bool pinch = live_pinch_.update(pipeline_, *builder_, lobes, have, requested_generation_);
    const bool moved = live_transform_.update(pipeline_, *builder_, lobes, have, requested_generation_);
    if (live_stroke_edit_.update(pipeline_, *builder_)) {
        // A bent stroke's tube alone; the document's strokes again when the drag is over.
        const Stroke* bent = live_stroke_edit_.stroke();
        if (!bent || !replace_stroke_item(scene_, *bent)) {
            rebuild_static_scene();
            return;
        }
    }
    if (!pinch && !moved) return;
    // Only the lobe's item (and a moved lobe's strokes) change while it is dragged; when the
    // edit ends, the lobes and strokes as built.
    bool shown = false;
    if (built_)
        for (std::size_t i = 0; i < built_->tree.lobes.size(); ++i)
            if (const TriangleMesh* m = live_lobe(built_->tree.lobes[i].lobe_id)) {
                shown = replace_lobe_item(scene_, i, *m);
                break;
            }
    if (shown && moved) {
        if (live_transform_.strokes().empty()) shown = false; // released: the document's strokes again
        for (const Stroke& st : live_transform_.strokes()) shown = replace_stroke_item(scene_, st) && shown;
    }
    if (!shown) rebuild_static_scene();
}

const TriangleMesh* DesktopSession::live_lobe(std::int64_t lobe_id) const
{
    const std::uint64_t have = built_ ? built_->generation : 0;
    if (const TriangleMesh* m = live_pinch_.mesh_for(lobe_id, pipeline_, have, requested_generation_)) return m;
    return live_transform_.mesh_for(lobe_id, have, requested_generation_);
}

void DesktopSession::apply_actions()
{
    bool changed = false;
    for (const InputAction& a : pipeline_.take_actions()) {
        if (a.type == InputAction::Type::StrokeDiscarded) note("stroke discarded: " + a.message);
        if (a.type == InputAction::Type::Grow && !grown_) {
            grown_ = true;
            note("growing the tree");
            request_regrowth();
        }
        if (builder_->apply(a)) changed = true;
    }
    const auto& builder_messages = builder_->messages();
    for (; builder_messages_seen_ < builder_messages.size(); ++builder_messages_seen_)
        note(builder_messages[builder_messages_seen_]);
    if (changed) document_changed();
}

void DesktopSession::document_changed()
{
    ++revision_;
    autosave();
    request_regrowth();
    rebuild_static_scene(); // strokes show at once; lobes and the tree follow the regrowth
}

void DesktopSession::autosave()
{
    if (!autosaver_) return;
    // As in the VR session: the recording flushed here, the JSON and the disk on the writer's
    // thread, so the window never waits for them (docs/crash-safety.md). Without background
    // regrowth (scripted runs) it is on disk before the frame ends.
    const std::string why = autosaver_->submit_after_change(recording_.get(), document(), frames_recorded_, finished_,
                                                            !options_.background_regrowth);
    if (!why.empty()) note("autosave failed: " + why);
}

void DesktopSession::report_autosave_failures()
{
    if (!autosaver_) return;
    for (const std::string& why : autosaver_->take_failures()) note("autosave failed: " + why);
}

void DesktopSession::request_regrowth()
{
    requested_generation_ = worker_->submit(document(), grown_);
    if (!options_.background_regrowth) take_regrowth(worker_->wait_for(requested_generation_));
}

void DesktopSession::wait_for_regrowth()
{
    if (built_ && built_->generation >= requested_generation_) return;
    if (requested_generation_ == 0) return;
    take_regrowth(worker_->wait_for(requested_generation_));
}

void DesktopSession::submit_preview(Document doc)
{
    preview_generation_ = worker_->submit(std::move(doc), grown_);
    if (!options_.background_regrowth) take_regrowth(worker_->wait_for(preview_generation_));
}

void DesktopSession::take_regrowth(std::optional<RegrowResult> result)
{
    if (!result) return;
    if (built_ && result->generation < built_->generation) return;
    // A drag preview's result (asked for after the last change of the document) is shown; what
    // it reports goes to the status line alone (preview_report).
    if (result->generation <= requested_generation_) {
        status_.tree_error = result->error;
        if (!result->error.empty()) note("tree: " + result->error);
        for (const std::string& w : result->tree.warnings) note(w);
    } else if (std::string report = preview_report(*result); !report.empty()) {
        status_.last_message = std::move(report);
    }
    built_ = std::move(result);
    rebuild_static_scene();
}

void DesktopSession::rebuild_static_scene()
{
    std::vector<TriangleMesh> lobes;
    const TreeGeometry empty;
    const TreeGeometry* geometry = &empty;
    if (built_) {
        for (const BuiltLobe& l : built_->tree.lobes) {
            const TriangleMesh* live = live_lobe(l.lobe_id);
            lobes.push_back(live ? *live : l.mesh);
        }
        if (built_->grown && grown_ && !built_->geometry.lods.empty()) geometry = &built_->geometry;
    }
    RenderContent content;
    content.tree = content.leaves = geometry != &empty;
    content.lobes = content.strokes = true;
    content.lod = content.tree ? std::min(lod_, int(geometry->lods.size()) - 1) : 0;
    status_.lod = content.lod;
    status_.tree_triangles = content.tree ? lod_triangles(geometry->lods[std::size_t(content.lod)]) : 0;
    std::vector<Stroke> strokes = effective_strokes(document());
    live_transform_.apply_to(strokes);
    live_stroke_edit_.apply_to(strokes);
    scene_ = tree_render_scene(*geometry, lobes, strokes, 0.0f, content);
    Bounds area = scene_bounds(scene_);
    if (area.empty()) {
        area.add(orbit_.target - glm::vec3(0.5f));
        area.add(orbit_.target + glm::vec3(0.5f));
    }
    scene_.ground_area = area;
    static_items_ = scene_.items.size();
}

void DesktopSession::add_dynamic_items()
{
    scene_.items.resize(static_items_);
    auto add = [&](RenderMaterial material, std::array<float, 4> color, SurfaceGeometry g) {
        if (g.triangles.empty()) return;
        RenderItem item;
        item.key = kDynamicKey | (scene_.items.size() - static_items_);
        item.version = ++dynamic_version_;
        item.material = material;
        item.color = color;
        item.geometry = std::move(g);
        scene_.items.push_back(std::move(item));
    };
    if (last_hand_.active) {
        SurfaceGeometry hand = hand_geometry(last_hand_);
        add(RenderMaterial::Stroke, status_.pinching ? kPinchColor : kHandColor, std::move(hand));
        SurfaceGeometry marker;
        append_sphere(marker, status_.tip, 0.008f, 6, 10);
        add(RenderMaterial::Stroke, tool_color(status_.tool), std::move(marker));
    }
    if (status_.drawing) {
        const Stroke& s = pipeline_.current_stroke(Hand::Right);
        std::vector<glm::vec3> pts;
        for (const StrokePoint& p : s.points) pts.push_back(p.position);
        const Tool t = status_.tool;
        const auto color = t == Tool::DrawLobe ? kLobeInkColor : t == Tool::DrawTrunk ? kTrunkInkColor : kDragInkColor;
        add(RenderMaterial::Stroke, color, polyline_tube(pts, 0.0035f, 6));
    }
}

bool DesktopSession::save()
{
    if (options_.session_path.empty()) {
        note("save: no session file (start with `lobesketch desktop SESSION.json`)");
        return false;
    }
    try {
        if (recording_ && !finished_) recording_->flush(); // closed once finished
        save_document(options_.session_path,
                      at_recording_position(document(), recording_ != nullptr, frames_recorded_, finished_));
        note("saved " + options_.session_path);
        return true;
    } catch (const Error& e) {
        note(std::string("save failed: ") + e.what());
        return false;
    }
}

bool DesktopSession::export_tree()
{
    if (!grown_) {
        note("export: grow the tree first (G)");
        return false;
    }
    wait_for_regrowth();
    if (!built_ || !built_->grown || built_->geometry.lods.empty()) {
        note("export: there is no tree to export" + (status_.tree_error.empty() ? "" : ": " + status_.tree_error));
        return false;
    }
    if (options_.export_path.empty()) {
        note("export: no export file");
        return false;
    }
    try {
        ExportOptions o;
        o.include_lobes = o.include_strokes = true;
        write_tree_file(options_.export_path, document(), built_->tree, built_->geometry, o);
        note("exported " + options_.export_path + " (" + lod_triangle_summary(built_->geometry) + ")");
        return true;
    } catch (const Error& e) {
        note(std::string("export failed: ") + e.what());
        return false;
    }
}

void DesktopSession::set_lod(int lod)
{
    lod = std::clamp(lod, 0, 7);
    if (lod == lod_) return;
    lod_ = lod;
    rebuild_static_scene();
    add_dynamic_items();
}

void DesktopSession::frame_view_on_scene()
{
    Bounds b;
    for (std::size_t i = 0; i < std::min(static_items_, scene_.items.size()); ++i)
        for (const glm::vec3& p : scene_.items[i].geometry.positions) b.add(p);
    if (b.empty()) return; // nothing drawn yet: keep the default view
    const Camera c = frame_view(b, {orbit_.azimuth_deg, orbit_.elevation_deg}, 1.6f, orbit_.fov_y_deg, 0.1f);
    orbit_.target = c.target;
    orbit_.distance_m = std::max(0.2f, glm::length(c.eye - c.target));
}

void DesktopSession::finish(double time)
{
    if (finished_) return;
    take_import(true); // an import still being made goes in last, not lost
    for (InputEvent& e : pending_) {
        e.time = std::max(time, time_);
        record(e);
        pipeline_.push_event(e);
    }
    pending_.clear();
    pipeline_.finish();
    finished_ = true; // an autosave from here on holds the end of the recording too
    const std::uint64_t revision = revision_;
    apply_actions();
    // The end changed nothing: the last autosave still says so, for `recover` to see that
    // nothing of the recording is left to replay.
    if (revision_ == revision && revision_ > 0) autosave();
    if (autosaver_) {
        autosaver_->wait();
        report_autosave_failures();
    }
    if (recording_) recording_->close();
}

} // namespace lobe
