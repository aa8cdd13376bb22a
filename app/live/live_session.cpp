#include "app/live/live_session.h"

#include <algorithm>
#include <chrono>
#include <exception>
#include <filesystem>
#include <system_error>

#include "app/export/tree_output.h"
#include "app/session/edit_hooks.h"
#include "app/session/edit_ops.h"
#include "app/session/stage_options.h"
#include "core/atomic_file.h"
#include "core/errors.h"
#include "meshing/mesh_io.h"
#include "meshing/mesh_quality.h"
#include "meshing/model_import.h"

namespace lobe {

namespace {

constexpr std::size_t kMaxMessages = 200;

} // namespace

LiveSession::LiveSession(Document doc, LiveSessionOptions options)
    : options_(std::move(options)), pipeline_(input_options(doc.settings)), scene_(options_.lod),
      lsystem_sketch_(options_.lsystem_platform)
{
    if (!options_.record_path.empty()) {
        recording_ = std::make_unique<RecordingWriter>(options_.record_path, options_.recording_header,
                                                       options_.recording_flush_frames);
        doc.source_recording = std::filesystem::absolute(options_.record_path).lexically_normal().string();
    }
    // A loaded document's position in its old recording no longer holds; the saves of this
    // session stamp theirs (at_recording_position).
    doc.recording_frames.reset();
    doc.recording_finished = false;
    EditHooks hooks = meshing_edit_hooks(edit_apply_options(doc.settings));
    // Imports of this session, by number (the recording's ImportMesh events).
    hooks.import_model = [this](int n) -> std::shared_ptr<const LobeModel> {
        if (!options_.imports_refused.empty())
            throw InvalidInput("import " + std::to_string(n) + ": " + options_.imports_refused);
        const auto it = imports_.find(n);
        if (it == imports_.end()) throw InvalidInput("import " + std::to_string(n) + " was not made in this session");
        return it->second;
    };
    const EditPickOptions pick = edit_pick_options(doc.settings);
    builder_ = std::make_unique<SessionBuilder>(std::move(doc), pick, std::move(hooks));
    if (!options_.autosave_path.empty()) autosaver_ = std::make_unique<AutosaveWriter>(options_.autosave_path);
    worker_ = std::make_unique<RegrowWorker>([this](RegrowResult& r) { scene_.prepare(r); });
    load_lsystem_sketch();
    // A loaded sketch is autosaved with the first change: until then an older session's
    // autosaves (of a crash not yet recovered) stay as they are.
    lsystem_autosaved_generation_ = lsystem_sketch_.tree_generation();
    if (!document().strokes.empty() || !document().lobes.empty()) request_regrowth();
    show_strokes();
}

LiveSession::~LiveSession()
{
    try {
        if (!finished_) close(finish_input());
        else if (!closed_) close(revision_);
    } catch (const Error&) {
        // A recording that cannot be flushed at exit: nothing more can be done here.
    }
    worker_.reset(); // its thread uses scene_ (prepare) until it is joined
}

void LiveSession::load_lsystem_sketch()
{
    const std::string& path = options_.lsystem_sketch_file;
    std::error_code ec;
    if (path.empty() || !std::filesystem::exists(path, ec)) return;
    try {
        lsystem_sketch_.load(lsystem::parse_sketch(read_file_limited(path, lsystem::kMaxSketchFileBytes), path), path);
    } catch (const Error& e) {
        // Left as it is: save() writes over it only once a new sketch is drawn.
        note(std::string("L-system sketch not loaded: ") + e.what());
    }
}

void LiveSession::note_lsystem_messages()
{
    for (; lsystem_messages_seen_ < lsystem_sketch_.messages().size(); ++lsystem_messages_seen_)
        note(lsystem_sketch_.messages()[lsystem_messages_seen_]);
}

std::string LiveSession::lsystem_sketch_text() const
{
    if (lsystem_sketch_.sketch().trunk.size() < 2) return {};
    return lsystem::sketch_json(lsystem_sketch_.sketch_file()) + "\n";
}

void LiveSession::note(std::string line)
{
    last_message_ = line;
    messages_.push_back(std::move(line));
    while (messages_.size() > kMaxMessages) messages_.pop_front();
}

// ---------------------------------------------------------------------------------------------
void LiveSession::push_event(const InputEvent& e)
{
    if (recording_) recording_->append(e);
    pipeline_.push_event(e);
    lsystem_sketch_.push_event(e);
    note_lsystem_messages();
}

RenderScene& LiveSession::begin_frame_items()
{
    lsystem_view_.reclaim(scene_.items_before_frame());
    RenderScene& scene = scene_.begin_frame_items();
    lsystem_view_.append(lsystem_sketch_, scene, pipeline_.scene_transform());
    return scene;
}

std::string lsystem_sketch_path(const std::string& session_path)
{
    std::filesystem::path p(session_path);
    p.replace_extension(".lsystem-sketch.json");
    return p.string();
}

void LiveSession::push_frame(const HandFrame& frame)
{
    pipeline_.push_frame(frame);
    lsystem_sketch_.push_frame(frame);
    note_lsystem_messages();
    if (recording_) {
        recording_->append(frame);
        ++frames_recorded_;
    }
}

void LiveSession::apply_actions()
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

void LiveSession::update()
{
    if (options_.background_regrowth) take_regrowth(worker_->take());
    update_live_edits();
    autosave_lsystem_sketch(false);
    report_autosave_failures();
}

void LiveSession::document_changed()
{
    ++revision_;
    autosave();
    request_regrowth();
    show_strokes(); // strokes show at once; lobes and the tree follow the regrowth
}

void LiveSession::show_strokes()
{
    std::vector<Stroke> strokes = effective_strokes(document());
    // A lobe being moved shows its strokes where it is dragged, a bent stroke as it is bent.
    transform_.apply_to(strokes);
    bend_.apply_to(strokes);
    scene_.set_strokes(strokes);
}

// ---------------------------------------------------------------------------------------------
void LiveSession::autosave()
{
    if (!autosaver_) return;
    // The recording is flushed on this thread (a write of a few frames, no sync), so that
    // whichever autosave is on disk when the program dies, the recording holds all it holds;
    // the JSON and the disk are the writer's thread's (app/live/autosave.h). Without background
    // regrowth (scripted runs, tests) it is on disk before the frame ends.
    const std::string why = autosaver_->submit_after_change(recording_.get(), document(), frames_recorded_, finished_,
                                                            !options_.background_regrowth);
    if (!why.empty()) note("autosave failed: " + why);
    document_autosaved_ = true;
    autosave_lsystem_sketch(true);
}

void LiveSession::autosave_lsystem_sketch(bool with_document)
{
    if (!autosaver_) return;
    const std::uint64_t generation = lsystem_sketch_.tree_generation();
    if (!with_document && generation == lsystem_autosaved_generation_) return;
    lsystem_autosaved_generation_ = generation;
    // What save() would write beside the session; none (the file removed) for a scrapped one.
    std::string text = lsystem_sketch_text();
    if (lsystem_autosaved_ && *lsystem_autosaved_ == text) return;
    if (!document_autosaved_) {
        // Nothing drawn yet: an older session's autosaves stay until this session makes its own.
        if (text.empty()) return;
        // The first autosave of this session: the document goes with the sketch, so that
        // `recover` finds both (autosave() comes back here).
        autosave();
        return;
    }
    lsystem_autosaved_ = text;
    autosaver_->submit_beside(lsystem_sketch_path(options_.autosave_path), std::move(text));
    if (!options_.background_regrowth) autosaver_->wait();
}

void LiveSession::report_autosave_failures()
{
    if (!autosaver_) return;
    for (const std::string& why : autosaver_->take_failures()) note("autosave failed: " + why);
}

// ---------------------------------------------------------------------------------------------
void LiveSession::request_regrowth()
{
    requested_generation_ = worker_->submit(document(), grown_);
    if (!options_.background_regrowth) take_regrowth(worker_->wait_for(requested_generation_));
}

void LiveSession::submit_preview(Document doc)
{
    preview_generation_ = worker_->submit(std::move(doc), grown_);
    if (!options_.background_regrowth) take_regrowth(worker_->wait_for(preview_generation_));
}

void LiveSession::wait_for_regrowth()
{
    if (requested_generation_ == 0) return;
    if (built_ && built_->generation >= requested_generation_) return;
    take_regrowth(worker_->wait_for(requested_generation_));
    place_live_lobe(false);
}

bool LiveSession::regrowing() const
{
    return requested_generation_ > 0 && (!built_ || built_->generation < requested_generation_);
}

void LiveSession::take_regrowth(std::optional<RegrowResult> result)
{
    if (!result) return;
    if (built_ && result->generation < built_->generation) return;
    // A drag preview's result (asked for after the last change of the document) is shown; what
    // it reports goes to the status line alone (preview_report).
    if (result->generation <= requested_generation_) {
        tree_error_ = result->error;
        if (!result->error.empty()) note("tree: " + result->error);
        for (const std::string& w : result->tree.warnings) note(w);
    } else if (std::string report = preview_report(*result); !report.empty()) {
        last_message_ = std::move(report);
    }
    scene_.take(*result);
    built_ = std::move(result);
}

void LiveSession::set_lod(int lod)
{
    lod = std::clamp(lod, 0, 7);
    if (lod == scene_.lod()) return;
    scene_.set_lod(lod, built_ ? &*built_ : nullptr);
    // The grown items were made again from the lobes as built: the one shown live goes in again.
    live_shown_.reset();
    place_live_lobe(true);
}

const TriangleMesh* LiveSession::live_lobe(std::int64_t lobe_id) const
{
    const std::uint64_t have = built_ ? built_->generation : 0;
    if (const TriangleMesh* m = deform_.mesh_for(lobe_id, pipeline_, have, requested_generation_)) return m;
    return transform_.mesh_for(lobe_id, pipeline_, have, requested_generation_);
}

void LiveSession::update_live_edits()
{
    // The lobes and the tree follow an editing drag at the regrowth's pace; when it ends
    // without an edit, the document's own are grown again.
    DragPreview::Step preview = drag_preview_.update(pipeline_, *builder_, !worker_->has_waiting());
    if (preview.preview) submit_preview(std::move(*preview.preview));
    else if (preview.ended && preview_generation_ > requested_generation_) request_regrowth();

    const std::uint64_t have = built_ ? built_->generation : 0;
    const std::vector<BuiltLobe>* lobes = built_ ? &built_->tree.lobes : nullptr;
    const bool deformed = deform_.update(pipeline_, *builder_, lobes, have, requested_generation_);
    const bool moved = transform_.update(pipeline_, *builder_, lobes, have, requested_generation_);
    const bool bent = bend_.update(pipeline_, *builder_, lobes, have, requested_generation_);
    // A bent stroke's tube and a moved lobe's strokes: as dragged, or the document's again
    // once the drag is over.
    std::vector<std::int64_t> put_back;
    for (const auto& [changed, view] : {std::pair{bent, &bend_}, std::pair{moved, &transform_}}) {
        if (!changed) continue;
        for (const Stroke& st : view->strokes()) scene_.refresh_stroke(st);
        if (view->strokes().empty()) put_back.insert(put_back.end(), view->stroke_ids().begin(), view->stroke_ids().end());
    }
    if (!put_back.empty())
        for (const Stroke& st : effective_strokes(document()))
            if (std::find(put_back.begin(), put_back.end(), st.id) != put_back.end()) scene_.refresh_stroke(st);
    place_live_lobe(deformed || moved);
}

void LiveSession::place_live_lobe(bool changed)
{
    // A new regrowth result brought its own lobe items: the edited lobe goes into them again.
    const std::uint64_t have = built_ ? built_->generation : 0;
    const bool fresh = have != live_shown_generation_;
    if (!changed && !fresh) return;
    if (live_shown_ && !fresh && built_ && *live_shown_ < built_->tree.lobes.size())
        scene_.replace_lobe(*live_shown_, built_->tree.lobes[*live_shown_].mesh);
    live_shown_.reset();
    live_shown_generation_ = have;
    if (!built_) return;
    for (std::size_t i = 0; i < built_->tree.lobes.size(); ++i)
        if (const TriangleMesh* m = live_lobe(built_->tree.lobes[i].lobe_id)) {
            if (scene_.replace_lobe(i, *m)) live_shown_ = i;
            break;
        }
}

// ---------------------------------------------------------------------------------------------
bool LiveSession::import_mesh(const std::string& path, double size_m)
{
    const LobeFromModelOptions o = model_import_options(document().settings, size_m);
    try {
        if (!options_.imports_refused.empty()) throw InvalidInput(options_.imports_refused);
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
    note("importing " + path + " ...");
    return true;
}

std::optional<InputEvent> LiveSession::take_import(bool wait)
{
    if (!import_) return std::nullopt;
    if (!wait && import_->model.wait_for(std::chrono::seconds(0)) != std::future_status::ready) return std::nullopt;
    PendingImport done = std::move(*import_);
    import_.reset();
    try {
        imports_[done.number] = done.model.get();
    } catch (const Error& e) {
        note(std::string("import: ") + e.what());
        return std::nullopt;
    } catch (const std::exception& e) {
        note("import: " + one_line_message(done.path + ": " + e.what()));
        return std::nullopt;
    }
    InputEvent e;
    e.kind = InputEventKind::ImportMesh;
    e.code = done.number;
    note("imported " + done.path + " as a lobe at the fingertip");
    return e;
}

// ---------------------------------------------------------------------------------------------
bool LiveSession::save()
{
    if (options_.session_path.empty()) {
        note("save: no session file (start with `lobesketch " + options_.app + " SESSION.json`)");
        return false;
    }
    try {
        if (recording_ && !finished_) recording_->flush(); // closed once finished
        save_document(options_.session_path,
                      at_recording_position(document(), recording_ != nullptr, frames_recorded_, finished_));
        note("saved " + options_.session_path);
        if (const std::string text = lsystem_sketch_text(); !text.empty()) {
            const std::string path = lsystem_sketch_path(options_.session_path);
            write_file_atomic(path, text);
            note("saved the L-system sketch to " + path);
        }
        return true;
    } catch (const Error& e) {
        note(std::string("save failed: ") + e.what());
        return false;
    }
}

bool LiveSession::export_tree()
{
    if (!grown_) {
        note("export: grow the tree first (" + options_.grow_hint + ")");
        return false;
    }
    wait_for_regrowth();
    if (!built_ || !built_->grown || built_->geometry.lods.empty()) {
        note("export: there is no tree to export" + (tree_error_.empty() ? "" : ": " + tree_error_));
        return false;
    }
    if (options_.export_path.empty()) {
        note("export: no export file" + (options_.export_file_hint.empty() ? "" : " (" + options_.export_file_hint + ")"));
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

// ---------------------------------------------------------------------------------------------
std::uint64_t LiveSession::finish_input()
{
    const std::uint64_t revision = revision_;
    if (finished_) return revision;
    pipeline_.finish();
    finished_ = true; // an autosave from here on holds the end of the recording too
    apply_actions();
    return revision;
}

void LiveSession::close(std::uint64_t revision_before)
{
    if (closed_) return;
    closed_ = true;
    // The end changed nothing: the last autosave still says so, for `recover` to see that
    // nothing of the recording is left to replay.
    if (revision_ == revision_before && document_autosaved_) autosave();
    autosave_lsystem_sketch(false);
    if (autosaver_) {
        autosaver_->wait();
        report_autosave_failures();
    }
    if (recording_) recording_->close();
}

} // namespace lobe
