// Crash safety (docs/crash-safety.md): the autosave and recording of live sessions, and
// `lobesketch recover`. The live VR session (`lobesketch sketch`) is killed with SIGKILL at
// seeded random moments; after every kill the last autosave loads, holds every stroke completed
// before it, the recording reads up to its last complete batch, and `recover` gives what a
// replay of the surviving recording gives.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <optional>
#include <random>
#include <sstream>
#include <thread>

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "app/live/autosave.h"
#include "app/desktop/desktop_session.h"
#include "app/session/edit_hooks.h"
#include "core/atomic_file.h"
#include "core/document.h"
#include "core/errors.h"
#include "growth/lsystem/sketch.h"
#include "input/tools.h"
#include "input/pipeline.h"
#include "input/recording.h"
#include "app/session/session_builder.h"
#include "tests/support/cli_run.h"
#include "tests/support/test_data.h"
#include "tests/support/test_paths.h"

extern char** environ;

namespace lobe {
namespace {

namespace fs = std::filesystem;
using test::cli_path;
using test::run_cli;
using test::temp_dir;

#if defined(__SANITIZE_ADDRESS__)
constexpr bool kSanitized = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr bool kSanitized = true;
#else
constexpr bool kSanitized = false;
#endif
#else
constexpr bool kSanitized = false;
#endif

// ---------------------------------------------------------------------------------------------
// Replays of a recording, as `replay` and `recover` do them.

SessionBuilder make_builder(const std::string& rec_path, Document doc = {})
{
    EditHooks hooks = meshing_edit_hooks();
    hooks.import_model = [rec_path](int n) -> std::shared_ptr<const LobeModel> {
        throw InvalidInput("import " + std::to_string(n) + " is not expected in " + rec_path);
    };
    return SessionBuilder(std::move(doc), EditPickOptions{}, std::move(hooks));
}

/// The whole recording, as `lobesketch replay` takes it (run_input_pipeline, then the builder).
Document replay_all(const Recording& rec, const std::string& rec_path)
{
    SessionBuilder b = make_builder(rec_path);
    b.apply(run_input_pipeline(rec, Document{}.settings.input).actions);
    return b.take_document();
}

/// What a live session had made after its first `frames` frames (the actions of those frames
/// and the events up to the last of them; no end of input).
Document replay_frames(const Recording& rec, const std::string& rec_path, std::size_t frames)
{
    InputPipeline pipe(Document{}.settings.input);
    SessionBuilder b = make_builder(rec_path);
    std::size_t e = 0;
    for (std::size_t i = 0; i < frames && i < rec.frames.size(); ++i) {
        while (e < rec.events.size() && rec.events[e].time <= rec.frames[i].time) pipe.push_event(rec.events[e++]);
        pipe.push_frame(rec.frames[i]);
        b.apply(pipe.take_actions());
    }
    return b.take_document();
}

/// Same strokes (ids, kinds, points) in the same order; empty when they are, else what differs.
std::string stroke_difference(const std::vector<Stroke>& got, const std::vector<Stroke>& want)
{
    std::ostringstream out;
    if (got.size() != want.size()) {
        out << got.size() << " strokes instead of " << want.size() << " (ids:";
        for (const Stroke& s : got) out << ' ' << s.id;
        out << " vs";
        for (const Stroke& s : want) out << ' ' << s.id;
        out << ')';
        return out.str();
    }
    for (std::size_t i = 0; i < got.size(); ++i) {
        const Stroke &g = got[i], &w = want[i];
        if (g.id != w.id || g.kind != w.kind || g.points.size() != w.points.size()) {
            out << "stroke " << i << ": id " << g.id << " kind " << int(g.kind) << " points " << g.points.size()
                << " instead of id " << w.id << " kind " << int(w.kind) << " points " << w.points.size();
            return out.str();
        }
        for (std::size_t k = 0; k < g.points.size(); ++k)
            if (glm::distance(g.points[k].position, w.points[k].position) > 1e-6f) {
                out << "stroke " << g.id << " point " << k << " differs";
                return out.str();
            }
    }
    return {};
}

/// Every stroke of `part` is in `whole` (same id, kind and points).
bool strokes_contained(const std::vector<Stroke>& part, const std::vector<Stroke>& whole)
{
    for (const Stroke& p : part) {
        bool found = false;
        for (const Stroke& w : whole)
            found = found || (w.id == p.id && stroke_difference({w}, {p}).empty());
        if (!found) return false;
    }
    return true;
}

/// Lines of `s` that are errors ("lobesketch: error: …"); warnings about the input may precede.
int count_error_lines(const std::string& s)
{
    int n = 0;
    std::istringstream in(s);
    for (std::string line; std::getline(in, line);) n += line.rfind("lobesketch: error: ", 0) == 0;
    return n;
}

// ---------------------------------------------------------------------------------------------
TEST(CrashSafetyDocument, RecordingPositionRoundTripsAndIsValidated)
{
    Document doc;
    doc.source_recording = "/tmp/session.lrec";
    EXPECT_EQ(document_to_json(doc).count("recording_frames"), 0u) << "absent when the document is at no position";
    doc.recording_frames = 1234;
    doc.recording_finished = true;
    const Document back = document_from_json(document_to_json(doc));
    ASSERT_TRUE(back.recording_frames.has_value());
    EXPECT_EQ(*back.recording_frames, 1234u);
    EXPECT_TRUE(back.recording_finished);
    doc.recording_finished = false;
    EXPECT_FALSE(document_from_json(document_to_json(doc)).recording_finished);

    auto refused = [](nlohmann::json j, const std::string& expect) {
        try {
            document_from_json(j);
            return std::string("accepted");
        } catch (const InvalidInput& e) {
            const std::string what = e.what();
            if (what.find(expect) == std::string::npos || what.find('\n') != std::string::npos) return what;
            return std::string();
        }
    };
    nlohmann::json j = document_to_json(Document{});
    j["recording_frames"] = -1;
    EXPECT_EQ(refused(j, "recording_frames"), "");
    j["recording_frames"] = "12";
    EXPECT_EQ(refused(j, "recording_frames"), "");
    j["recording_frames"] = 1.5;
    EXPECT_EQ(refused(j, "recording_frames"), "");
    j["recording_frames"] = std::uint64_t{1} << 40;
    EXPECT_EQ(refused(j, "recording_frames"), "");
    j["recording_frames"] = 10;
    j["recording_finished"] = 1;
    EXPECT_EQ(refused(j, "recording_finished"), "");
    j.erase("recording_frames");
    j["recording_finished"] = true;
    EXPECT_EQ(refused(j, "recording_finished"), "");
}

TEST(CrashSafetyDocument, AutosaveKeepsThePreviousGenerationWhole)
{
    const std::string dir = temp_dir("autosave-generations");
    const std::string path = dir + "/a.json";
    Document doc;
    for (std::uint64_t seed = 1; seed <= 3; ++seed) {
        doc.seed = seed;
        save_autosave(path, doc);
        EXPECT_EQ(load_document(path).seed, seed);
        if (seed > 1) {
            EXPECT_EQ(load_document(previous_autosave_path(path)).seed, seed - 1);
        }
    }
    EXPECT_FALSE(fs::exists(previous_autosave_path(path) + ".tmp"));
}

// The live apps' autosaves are written on a thread of their own (app/live/autosave.h).
TEST(CrashSafetyDocument, AutosaveWriterWritesTheNewestDocumentAndWaitMeansItIsOnDisk)
{
    const std::string dir = temp_dir("autosave-writer");
    const std::string path = dir + "/a.json";
    {
        AutosaveWriter w(path);
        Document doc;
        for (std::uint64_t seed = 1; seed <= 50; ++seed) {
            doc.seed = seed;
            w.submit(doc);
        }
        w.wait();
        EXPECT_EQ(load_document(path).seed, 50u); // the newest, whatever was skipped
        EXPECT_GE(w.written(), 1u);
        EXPECT_LE(w.written(), 50u);
        EXPECT_TRUE(w.take_failures().empty());
        doc.seed = 51;
        w.submit(doc); // not waited for: the destructor writes it
    }
    EXPECT_EQ(load_document(path).seed, 51u);
    EXPECT_FALSE(fs::exists(path + ".tmp"));
}

TEST(CrashSafetyDocument, AutosaveWriterReportsAFailedWriteInOneLineAndGoesOn)
{
    const std::string dir = temp_dir("autosave-writer-fails");
    const std::string path = dir + "/no-such-folder/a.json";
    AutosaveWriter w(path);
    w.submit(Document{});
    w.wait();
    const std::vector<std::string> failures = w.take_failures();
    ASSERT_EQ(failures.size(), 1u);
    EXPECT_NE(failures[0].find("no-such-folder/a.json"), std::string::npos) << failures[0];
    EXPECT_EQ(failures[0].find('\n'), std::string::npos);
    EXPECT_TRUE(w.take_failures().empty());
    fs::create_directories(dir + "/no-such-folder");
    w.submit(Document{});
    w.wait();
    EXPECT_TRUE(w.take_failures().empty());
    EXPECT_EQ(w.written(), 1u);
}

TEST(CrashSafetyDocument, KilledWhileSavingLeavesTheOldOrTheNewFileWhole)
{
    // Two documents large enough for a save to take a while (about 1 MB each); a child process
    // saves them in turn, as the autosave and a session save do, and is killed at random
    // moments: both files are always one of the two, whole.
    const std::string dir = temp_dir("killed-saving");
    Document docs[2];
    for (int d = 0; d < 2; ++d) {
        docs[d].seed = 100 + std::uint64_t(d);
        for (int k = 0; k < 12; ++k) {
            Stroke st;
            st.id = k + 1;
            for (int i = 0; i < 1000; ++i) {
                StrokePoint p;
                p.position = glm::vec3(0.001f * float(i), 1.0f + 0.01f * float(k), 0.1f * float(d));
                p.time = 0.01 * i;
                st.points.push_back(p);
            }
            docs[d].strokes.push_back(std::move(st));
        }
    }
    const std::string autosave = dir + "/a.json", session = dir + "/s.json";
    // Two autosaves, so that the previous generation exists before the first kill (a kill
    // before the child's first save would otherwise find none).
    save_autosave(autosave, docs[1]);
    save_autosave(autosave, docs[0]);
    save_document(session, docs[0]);
    std::mt19937 rng(7);
    std::uniform_int_distribution<int> delay_us(1000, kSanitized ? 100000 : 40000);
    const int kills = kSanitized ? 5 : 15;
    int mid_saves = 0;
    for (int k = 0; k < kills; ++k) {
        const pid_t child = ::fork();
        ASSERT_GE(child, 0);
        if (child == 0) {
            try {
                for (int i = 0;; ++i) {
                    save_autosave(autosave, docs[(i + 1) % 2]);
                    save_document(session, docs[i % 2]);
                }
            } catch (...) {
            }
            ::_exit(3);
        }
        std::this_thread::sleep_for(std::chrono::microseconds(delay_us(rng)));
        ::kill(child, SIGKILL);
        int status = 0;
        ASSERT_EQ(::waitpid(child, &status, 0), child);
        // A temporary file left beside the targets: the kill came in the middle of a save.
        bool mid_save = false;
        for (const auto& entry : fs::directory_iterator(dir))
            if (entry.path().filename().string().find(".tmp") != std::string::npos) {
                mid_save = true;
                fs::remove(entry.path());
            }
        mid_saves += mid_save;
        for (const std::string& f : {autosave, previous_autosave_path(autosave), session}) {
            SCOPED_TRACE("kill " + std::to_string(k) + ": " + f);
            const Document got = load_document(f); // throws, failing the test, when partial
            ASSERT_TRUE(got.seed == 100 || got.seed == 101);
            EXPECT_EQ(stroke_difference(got.strokes, docs[got.seed - 100].strokes), "");
        }
    }
    EXPECT_GE(mid_saves, 1) << "some kills came in the middle of a save";
    std::cout << "[ crash    ] " << kills << " kills while saving, " << mid_saves << " in the middle of a save\n";
}

// ---------------------------------------------------------------------------------------------
// The desktop session: its files copied while it runs are what a SIGKILL at that moment leaves
// (whatever was flushed is in the files, the rest is lost), so every copy must recover.

constexpr int kW = 640, kH = 360;

struct DesktopDriver {
    explicit DesktopDriver(DesktopSession& session) : s(session) {}
    DesktopSession& s;
    int frame = 0;
    std::function<void()> after_frame;
    bool realtime = false; ///< a frame every 1/60 s, as the window has them
    void step(int n = 1)
    {
        for (int i = 0; i < n; ++i) {
            if (realtime) std::this_thread::sleep_for(std::chrono::microseconds(16667));
            s.frame(++frame / 60.0, kW, kH);
            if (after_frame) after_frame();
        }
    }
    void move(float x, float y)
    {
        s.mouse_move(x, y);
        step();
    }
    void circle(float cx, float cy, float r, int frames)
    {
        move(cx + r, cy);
        s.mouse_button(desktop_keys::kMouseLeft, true);
        step();
        for (int i = 1; i <= frames; ++i) {
            const double a = 2.0 * M_PI * 1.06 * i / frames;
            move(cx + r * float(std::cos(a)), cy - r * float(std::sin(a)));
        }
        s.mouse_button(desktop_keys::kMouseLeft, false);
        step(6);
    }
    /// A click (a pinch of the simulated hand) at window pixel (x, y).
    void click(float x, float y)
    {
        move(x, y);
        step();
        s.mouse_button(desktop_keys::kMouseLeft, true);
        step(5);
        s.mouse_button(desktop_keys::kMouseLeft, false);
        step(3);
    }
    void press(int key)
    {
        s.key(key, true);
        step();
        s.key(key, false);
        step();
    }
};

/// Sketches an L-system tree in the sketch mode (the platform is below the camera's target,
/// at the window's centre, about 5 mm per pixel): four trunk sections and a branch from trunk
/// node 2 (as tests/data/desktop_lsystem_sketch.script does in the window); P first turns the
/// mode on unless it is on.
void sketch_lsystem_tree(DesktopDriver& d)
{
    if (!d.s.lsystem_sketch().active()) d.press(keys::kLSystemSketch);
    const float trunk[][2] = {{322, 190}, {318, 170}, {324, 150}, {320, 130}};
    for (const auto& p : trunk) d.click(p[0], p[1]);
    d.move(318, 170);
    d.step(3); // the simulated fingertip settles on the node
    d.press(lsystem_sketch_keys::kBranch);
    d.click(345, 160);
    d.click(365, 150);
    d.press(lsystem_sketch_keys::kTrunk);
}

/// The sketch file the session's L-system sketch mode holds (what Save writes beside it).
std::string sketch_file_text(const DesktopSession& s)
{
    return lsystem::sketch_json(s.lsystem_sketch().sketch_file()) + "\n";
}

TEST(CrashSafetyDesktop, EverySnapshotOfARunningSessionRecovers)
{
    const std::string dir = temp_dir("crash-desktop");
    DesktopOptions o;
    o.background_regrowth = true; // the document does not wait for lobes or trees
    o.autosave_path = dir + "/session.autosave.json";
    o.record_path = dir + "/session.lrec";
    int snapshots = 0;
    {
        DesktopSession session(Document{}, o);
        DesktopDriver d(session);
        // At the window's pace: the autosaves are written beside the frames (app/live/autosave.h),
        // so how many frames pass before one is on disk depends on how fast frames come.
        d.realtime = true;
        // Every 7th frame (not a multiple of the recording's flush batch of 6), the files as
        // they are on disk.
        d.after_frame = [&] {
            if (d.frame % 7 != 0 || !fs::exists(o.autosave_path)) return;
            const std::string snap = dir + "/snap" + std::to_string(snapshots++);
            fs::create_directories(snap);
            fs::copy_file(o.autosave_path, snap + "/session.autosave.json");
            fs::copy_file(o.record_path, snap + "/session.lrec");
        };
        d.circle(320, 180, 60, 40);
        d.circle(330, 170, 45, 30);
        d.circle(310, 190, 70, 35);
        // A stroke cut by the "crash": the last snapshots are taken while it is being drawn.
        d.move(300, 100);
        session.mouse_button(desktop_keys::kMouseLeft, true);
        d.step();
        for (int i = 1; i <= 25; ++i) d.move(300.0f + 4.0f * float(i), 100.0f + 0.2f * float(i * i));
    }
    ASSERT_GE(snapshots, 12);
    int beyond_autosave = 0; ///< snapshots whose recovery holds strokes their autosave lacks
    for (int k = 0; k < snapshots; ++k) {
        SCOPED_TRACE("snapshot " + std::to_string(k));
        const std::string snap = dir + "/snap" + std::to_string(k);
        const std::string rec_path = snap + "/session.lrec";
        const Document autosave = load_document(snap + "/session.autosave.json");
        ASSERT_TRUE(autosave.recording_frames.has_value());
        const Recording rec = read_recording(rec_path);
        ASSERT_GE(rec.frames.size(), *autosave.recording_frames) << "the recording covers the autosave";
        EXPECT_EQ(stroke_difference(autosave.strokes, replay_frames(rec, rec_path, *autosave.recording_frames).strokes), "")
            << "the autosave holds every stroke completed before it";

        const test::CliRun r = run_cli("-q recover " + snap + "/session.autosave.json --recording " + rec_path);
        ASSERT_EQ(r.code, 0) << r.out;
        const Document recovered = load_document(snap + "/session.autosave.recovered.json");
        EXPECT_EQ(stroke_difference(recovered.strokes, replay_all(rec, rec_path).strokes), "")
            << "recover gives what a replay of the surviving recording gives";
        EXPECT_TRUE(strokes_contained(autosave.strokes, recovered.strokes));
        beyond_autosave += recovered.strokes.size() > autosave.strokes.size();
        EXPECT_TRUE(recovered.recording_finished);
        EXPECT_EQ(recovered.recording_frames, rec.frames.size());
    }
    EXPECT_GE(beyond_autosave, 2) << "strokes finished or cut short after the last autosave survive";
    // The finished session's autosave holds the whole recording: recover replays nothing.
    const Document last = load_document(o.autosave_path);
    EXPECT_TRUE(last.recording_finished);
    const test::CliRun r = run_cli("recover " + o.autosave_path + " --out " + dir + "/final.json");
    ASSERT_EQ(r.code, 0) << r.out;
    EXPECT_NE(r.out.find("nothing to replay"), std::string::npos) << r.out;
    EXPECT_EQ(stroke_difference(load_document(dir + "/final.json").strokes, last.strokes), "");
}

TEST(CrashSafetyDesktop, TheLSystemSketchIsAutosavedAndRecoveredByteForByte)
{
    const std::string dir = temp_dir("crash-desktop-lsystem");
    DesktopOptions o;
    o.background_regrowth = false; // every autosave is on disk when its frame ends
    o.autosave_path = dir + "/session.autosave.json";
    o.record_path = dir + "/session.lrec";
    const std::string sketch_autosave = lsystem_sketch_path(o.autosave_path);
    EXPECT_EQ(fs::path(sketch_autosave).filename().string(), "session.autosave.lsystem-sketch.json");
    const std::string snap = dir + "/snap";
    std::string live_sketch; ///< the mode's sketch file at the "crash"
    {
        DesktopSession session(Document{}, o);
        DesktopDriver d(session);
        sketch_lsystem_tree(d);
        ASSERT_EQ(session.lsystem_sketch().sketch().trunk_sections(), 4);
        ASSERT_EQ(session.lsystem_sketch().sketch().branches.size(), 1u);
        EXPECT_TRUE(session.document().strokes.empty());
        // Only the sketch changed: the session's first autosave is made with it, so that
        // recover finds both.
        ASSERT_TRUE(fs::exists(o.autosave_path));
        live_sketch = sketch_file_text(session);
        EXPECT_EQ(read_file_limited(sketch_autosave, 1 << 20), live_sketch);
        // The files as a kill at this moment leaves them.
        fs::create_directories(snap);
        for (const std::string& f : {o.autosave_path, sketch_autosave, o.record_path})
            fs::copy_file(f, snap + "/" + fs::path(f).filename().string());

        // The growth and the divergence are in the sketch file too; a scrapped sketch leaves
        // no sketch autosave behind.
        d.press(lsystem_sketch_keys::kIterationForward);
        d.press(lsystem_sketch_keys::kDivergenceUp);
        EXPECT_EQ(read_file_limited(sketch_autosave, 1 << 20), sketch_file_text(session));
        EXPECT_NE(sketch_file_text(session), live_sketch);
        EXPECT_NE(sketch_file_text(session).find("\"iterations\":5"), std::string::npos) << sketch_file_text(session);
        d.press(lsystem_sketch_keys::kScrap);
        EXPECT_FALSE(fs::exists(sketch_autosave));
        sketch_lsystem_tree(d); // drawn again
        session.finish(d.frame / 60.0 + 0.01);
    }
    // The end of the session: the sketch autosave holds the sketch its recording replays to.
    EXPECT_EQ(read_file_limited(sketch_autosave, 1 << 20),
              lsystem::sketch_json(replay_lsystem_sketch(read_recording(o.record_path)).sketch_file()) + "\n");

    const test::CliRun r = run_cli("recover " + snap + "/session.autosave.json --recording " + snap + "/session.lrec");
    ASSERT_EQ(r.code, 0) << r.out;
    EXPECT_NE(r.out.find("session.autosave.recovered.lsystem-sketch.json"), std::string::npos) << r.out;
    EXPECT_TRUE(fs::exists(snap + "/session.autosave.recovered.json"));
    EXPECT_EQ(read_file_limited(snap + "/session.autosave.recovered.lsystem-sketch.json", 1 << 20), live_sketch)
        << "recover puts the sketch back beside the recovered session, byte for byte";
    // An existing sketch beside the output is not replaced without --force.
    fs::remove(snap + "/session.autosave.recovered.json");
    test::CliRun again = run_cli("-q recover " + snap + "/session.autosave.json");
    EXPECT_EQ(again.code, 1) << again.out;
    EXPECT_EQ(count_error_lines(again.out), 1) << again.out;
    EXPECT_NE(again.out.find("lsystem-sketch.json: exists"), std::string::npos) << again.out;
    EXPECT_FALSE(fs::exists(snap + "/session.autosave.recovered.json"));
    again = run_cli("-q recover " + snap + "/session.autosave.json --force");
    EXPECT_EQ(again.code, 0) << again.out;
}

TEST(CrashSafetyRecover, ADamagedSketchAutosaveIsOneLineAndTheSessionStillRecovers)
{
    const std::string dir = temp_dir("recover-lsystem-damaged");
    DesktopOptions o;
    o.background_regrowth = false;
    o.autosave_path = dir + "/a.json";
    o.record_path = dir + "/a.lrec";
    {
        DesktopSession session(Document{}, o);
        DesktopDriver d(session);
        d.circle(320, 180, 60, 40);
        sketch_lsystem_tree(d);
        session.finish(d.frame / 60.0 + 0.01);
    }
    const std::string sketch_autosave = lsystem_sketch_path(o.autosave_path);
    const std::string text = read_file_limited(sketch_autosave, 1 << 20);
    const std::vector<std::string> damages = {
        text.substr(0, text.size() / 2),            // cut in half
        R"({"trunk": [[0, 0, 0]]})",                // one trunk node: no section
        R"({"trunk": [[0, 0, 0], [0, 0, 0]]})",     // a zero-length section
        std::string(3000, '\x5a'),                  // not JSON
    };
    for (std::size_t i = 0; i < damages.size(); ++i) {
        SCOPED_TRACE("damage " + std::to_string(i));
        std::ofstream(sketch_autosave, std::ios::binary | std::ios::trunc) << damages[i];
        const std::string out = dir + "/r" + std::to_string(i) + ".json";
        const test::CliRun r = run_cli("-q recover " + o.autosave_path + " --out " + out);
        ASSERT_EQ(r.code, 0) << r.out;
        int warnings = 0;
        std::istringstream in(r.out);
        for (std::string line; std::getline(in, line);) warnings += line.rfind("lobesketch: warning: ", 0) == 0;
        EXPECT_EQ(warnings, 1) << r.out;
        EXPECT_NE(r.out.find("a.lsystem-sketch.json"), std::string::npos) << r.out;
        EXPECT_NE(r.out.find("without its L-system sketch"), std::string::npos) << r.out;
        EXPECT_EQ(load_document(out).strokes.size(), 1u);
        EXPECT_FALSE(fs::exists(lsystem_sketch_path(out)));
        EXPECT_EQ(read_file_limited(sketch_autosave, 1 << 20), damages[i]) << "left as it is";
    }
}

// ---------------------------------------------------------------------------------------------
/// A recorded desktop session cut at frame `cut` (its autosave and recording as a crash there
/// leaves them), for the failure messages of recover.
struct CrashedSession {
    std::string dir, autosave, recording;
};

CrashedSession crashed_desktop_session(const std::string& name)
{
    CrashedSession c;
    c.dir = temp_dir(name);
    DesktopOptions o;
    o.autosave_path = c.autosave = c.dir + "/a.json";
    o.record_path = c.recording = c.dir + "/a.lrec";
    DesktopSession session(Document{}, o);
    DesktopDriver d(session);
    d.circle(320, 180, 60, 40);
    d.circle(330, 170, 45, 30);
    session.finish(d.frame / 60.0 + 0.01);
    // As if the session had crashed after its first stroke: the autosave of that moment.
    Document doc = load_document(c.autosave);
    const Recording rec = read_recording(c.recording);
    Document first = replay_frames(rec, c.recording, 50);
    first.source_recording = doc.source_recording;
    first.recording_frames = 50;
    save_document(c.autosave, first);
    return c;
}

TEST(CrashSafetyRecover, RecoversTheRestAndNeverOverwrites)
{
    const CrashedSession c = crashed_desktop_session("recover-basic");
    const Recording rec = read_recording(c.recording);
    ASSERT_EQ(load_document(c.autosave).strokes.size(), 1u);
    test::CliRun r = run_cli("-q recover " + c.autosave);
    ASSERT_EQ(r.code, 0) << r.out;
    const Document recovered = load_document(c.dir + "/a.recovered.json");
    EXPECT_EQ(recovered.strokes.size(), 2u);
    EXPECT_EQ(stroke_difference(recovered.strokes, replay_all(rec, c.recording).strokes), "");

    // An existing output is not replaced without --force.
    r = run_cli("-q recover " + c.autosave);
    EXPECT_EQ(r.code, 1);
    EXPECT_NE(r.out.find("exists"), std::string::npos) << r.out;
    EXPECT_EQ(count_error_lines(r.out), 1) << r.out;
    EXPECT_EQ(run_cli("-q recover " + c.autosave + " --force").code, 0);
    r = run_cli("-q recover " + c.autosave + " --out " + c.autosave + " --force");
    EXPECT_EQ(r.code, 1) << "never over the autosave itself";
    EXPECT_EQ(load_document(c.autosave).strokes.size(), 1u);
}

TEST(CrashSafetyRecover, ADamagedAutosaveFallsBackToThePreviousGeneration)
{
    const CrashedSession c = crashed_desktop_session("recover-generation");
    const Recording rec = read_recording(c.recording);
    fs::copy_file(c.autosave, previous_autosave_path(c.autosave), fs::copy_options::overwrite_existing);
    // Half of the newest autosave (as a disk fault, not a crash, could leave it).
    std::string text = read_file_limited(c.autosave, 1 << 26);
    std::ofstream(c.autosave, std::ios::binary | std::ios::trunc) << text.substr(0, text.size() / 2);
    test::CliRun r = run_cli("-q recover " + c.autosave + " --out " + c.dir + "/r.json");
    ASSERT_EQ(r.code, 0) << r.out;
    EXPECT_NE(r.out.find("previous generation"), std::string::npos) << r.out;
    EXPECT_EQ(stroke_difference(load_document(c.dir + "/r.json").strokes, replay_all(rec, c.recording).strokes), "");

    fs::remove(previous_autosave_path(c.autosave));
    r = run_cli("-q recover " + c.autosave + " --out " + c.dir + "/r2.json");
    EXPECT_EQ(r.code, 1);
    EXPECT_NE(r.out.find("no good autosave"), std::string::npos) << r.out;
    EXPECT_EQ(count_error_lines(r.out), 1) << r.out;
    EXPECT_FALSE(fs::exists(c.dir + "/r2.json"));
}

TEST(CrashSafetyRecover, EveryFailureIsOneLine)
{
    const CrashedSession c = crashed_desktop_session("recover-failures");
    auto fails = [&](const std::string& args, const std::string& expect) {
        const test::CliRun r = run_cli("-q recover " + args);
        EXPECT_EQ(r.code, 1) << args << ": " << r.out;
        EXPECT_NE(r.out.find(expect), std::string::npos) << args << ": " << r.out;
        EXPECT_EQ(count_error_lines(r.out), 1) << args << ": " << r.out;
    };
    fails(c.dir + "/missing.json --out " + c.dir + "/o1.json", "no good autosave");

    // A session that is no autosave of a recorded session.
    Document plain = load_document(c.autosave);
    plain.recording_frames.reset();
    save_document(c.dir + "/plain.json", plain);
    fails(c.dir + "/plain.json --out " + c.dir + "/o2.json", "recording_frames");

    // A recording shorter than the autosave says it holds.
    Document ahead = load_document(c.autosave);
    ahead.recording_frames = 1000000;
    save_document(c.dir + "/ahead.json", ahead);
    fails(c.dir + "/ahead.json --out " + c.dir + "/o3.json", "fewer than");

    // A corrupt recording.
    std::ofstream(c.dir + "/garbage.lrec", std::ios::binary) << std::string(4096, '\x5a');
    fails(c.autosave + " --recording " + c.dir + "/garbage.lrec --out " + c.dir + "/o4.json", "garbage.lrec");

    // The recording of another session: the strokes it had made by then are not in the autosave.
    const std::string other = test::source_data("recordings/table1-1lobe-5strokes.lrec");
    if (other.empty()) return;
    Document mismatched = load_document(c.autosave);
    mismatched.recording_frames = read_recording(other).frames.size() / 2;
    save_document(c.dir + "/mismatched.json", mismatched);
    fails(c.dir + "/mismatched.json --recording " + other + " --out " + c.dir + "/o5.json", "does not match");

    // No recording named.
    Document unnamed = load_document(c.autosave);
    unnamed.source_recording.clear();
    save_document(c.dir + "/unnamed.json", unnamed);
    fails(c.dir + "/unnamed.json --out " + c.dir + "/o6.json", "--recording");

    for (int i = 1; i <= 6; ++i) EXPECT_FALSE(fs::exists(c.dir + "/o" + std::to_string(i) + ".json"));
}

// ---------------------------------------------------------------------------------------------
// The live VR session, killed.

/// Starts `lobesketch ARGS…` with its output into `log`. Returns the child's pid.
pid_t spawn_cli(const std::vector<std::string>& args, const std::string& log)
{
    std::vector<std::string> argv_s{cli_path()};
    argv_s.insert(argv_s.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (std::string& s : argv_s) argv.push_back(s.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_addopen(&fa, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&fa, 1, 2);
    pid_t pid = -1;
    const int rc = posix_spawn(&pid, argv[0], &fa, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&fa);
    return rc == 0 ? pid : -1;
}

/// The first `seconds` of a shipped recording (frames and events), written beside the test;
/// empty when the recording is missing (the test has then failed with one line).
std::string shortened_recording(const std::string& name, double seconds, const std::string& dir)
{
    const std::string original = test::source_data("recordings/" + name + ".lrec");
    if (original.empty()) return {};
    Recording rec = read_recording(original);
    const double end = rec.frames.front().time + seconds;
    std::erase_if(rec.frames, [&](const HandFrame& f) { return f.time > end; });
    std::erase_if(rec.events, [&](const InputEvent& e) { return e.time > end; });
    rec.annotations.clear();
    const std::string path = dir + "/" + name + ".short.lrec";
    write_recording_binary(path, rec);
    return path;
}

TEST(CrashSafetySketch, KilledAtRandomMomentsLosesNoCompletedStroke)
{
    const std::string dir = temp_dir("crash-sketch");
    // About 20 s of sketching: the first strokes of the lobe.
    const std::string source = shortened_recording("table1-1lobe-5strokes", 20.0, dir);
    if (source.empty()) return;
    const Recording src = read_recording(source);
    const double t0 = src.frames.front().time;

    auto args = [&](const std::string& run) {
        return std::vector<std::string>{"-q", "sketch", source, "--events-from-recording", "--autosave",
                                        run + "/a.json", "--record", run + "/a.lrec", "--session", run + "/s.json"};
    };
    // The old session file a kill during the final save must leave whole (or the new one).
    Document old_session;
    old_session.seed = 777;

    // One run to the end: how long it takes, and the session it saves.
    const std::string full = dir + "/full";
    fs::create_directories(full);
    save_document(full + "/s.json", old_session);
    const auto t_start = std::chrono::steady_clock::now();
    const pid_t pid = spawn_cli(args(full), full + "/log.txt");
    ASSERT_GT(pid, 0);
    int status = 0;
    ASSERT_EQ(::waitpid(pid, &status, 0), pid);
    const double run_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
    ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << read_file_limited(full + "/log.txt", 1 << 20);
    const Document final_session = load_document(full + "/s.json");
    const Recording full_rec = read_recording(full + "/a.lrec");
    ASSERT_EQ(full_rec.frames.size(), src.frames.size());
    ASSERT_GE(final_session.strokes.size(), 2u) << "the shortened recording draws strokes";
    EXPECT_EQ(stroke_difference(final_session.strokes, replay_all(full_rec, full + "/a.lrec").strokes), "")
        << "the live session makes what a replay of its recording makes";
    EXPECT_EQ(stroke_difference(final_session.strokes, replay_all(src, source).strokes), "")
        << "and what a replay of the recording it was fed makes";

    // Kills at seeded random moments over the whole run, a third of them in its last fifth
    // (the last strokes, the end of the recording and the final save).
    const int kills = kSanitized ? 4 : std::clamp(int(18.0 / (0.7 * run_s + 0.4)), 6, 30);
    std::mt19937 rng(20261202);
    std::uniform_real_distribution<double> anywhere(0.02, 1.0), late(0.85, 1.15);
    int with_autosave = 0, with_new_session = 0, exited = 0;
    for (int k = 0; k < kills; ++k) {
        const double at = (k % 3 == 2 ? late(rng) : anywhere(rng)) * run_s;
        const std::string run = dir + "/kill" + std::to_string(k);
        SCOPED_TRACE("kill " + std::to_string(k) + " at " + std::to_string(at) + " s of " + std::to_string(run_s));
        fs::create_directories(run);
        save_document(run + "/s.json", old_session);
        const pid_t child = spawn_cli(args(run), run + "/log.txt");
        ASSERT_GT(child, 0);
        std::this_thread::sleep_for(std::chrono::duration<double>(at));
        ::kill(child, SIGKILL);
        ASSERT_EQ(::waitpid(child, &status, 0), child);
        exited += WIFEXITED(status);

        // The session file is the old one or the new one, whole.
        const Document s = load_document(run + "/s.json");
        if (s.seed == 777) {
            EXPECT_TRUE(s.strokes.empty());
        } else {
            ++with_new_session;
            EXPECT_EQ(stroke_difference(s.strokes, final_session.strokes), "");
        }
        if (!fs::exists(run + "/a.json")) continue; // killed before the first change: nothing to recover yet
        ++with_autosave;
        // The recording reads up to its last complete batch: a prefix of what was fed.
        const Recording rec = read_recording(run + "/a.lrec");
        ASSERT_LE(rec.frames.size(), src.frames.size());
        for (std::size_t i = 0; i < rec.frames.size(); i += 7) {
            ASSERT_NEAR(rec.frames[i].time, src.frames[i].time - t0, 1e-6) << "frame " << i;
            for (int h = 0; h < kHandCount; ++h)
                ASSERT_EQ(rec.frames[i].hands[h].active, src.frames[i].hands[h].active) << "frame " << i;
        }
        // The last autosave loads and holds every stroke completed before it.
        const Document autosave = load_document(run + "/a.json");
        ASSERT_TRUE(autosave.recording_frames.has_value()) << "the live session stamps its autosaves";
        ASSERT_LE(*autosave.recording_frames, rec.frames.size()) << "the recording covers the autosave";
        EXPECT_EQ(stroke_difference(autosave.strokes, replay_frames(rec, run + "/a.lrec", *autosave.recording_frames).strokes),
                  "");
        if (fs::exists(previous_autosave_path(run + "/a.json"))) load_document(previous_autosave_path(run + "/a.json"));
        // Recover gives what a replay of the surviving recording gives.
        const test::CliRun r = run_cli("-q recover " + run + "/a.json --out " + run + "/r.json");
        ASSERT_EQ(r.code, 0) << r.out;
        const Document recovered = load_document(run + "/r.json");
        EXPECT_EQ(stroke_difference(recovered.strokes, replay_all(rec, run + "/a.lrec").strokes), "");
        EXPECT_TRUE(strokes_contained(autosave.strokes, recovered.strokes));
    }
    EXPECT_GE(with_autosave, kills / 2) << "most kills come after the first completed stroke";
    std::cout << "[ crash    ] " << kills << " kills of a " << run_s << " s run: " << with_autosave
              << " with an autosave, " << with_new_session << " after the final save, " << exited
              << " ended before the kill\n";
}

} // namespace
} // namespace lobe
