// The soak (issue: reliability; docs/soak.md): the shipped recordings back to back, round
// after round in one process, each through the whole pipeline as the VR app and the main job
// run it: the live VrSession (panel events, background regrowth, autosave after every change,
// its own recording), then the lobes, the tree, the .glb and a picture on the Vulkan renderer.
// Until the recordings' session time adds up to --minutes (default 30: a half-hour session)
// and at least 8 rounds ran.
//
// It checks what a long session must not do: peak and resident memory flat after the first
// (warm-up) round (growth < 5 %, judged from 6 rounds on), no growth in open file descriptors or threads, and every
// part's result (document, .glb, picture) the same as that part replayed alone in a fresh
// process (this program with --part). Prints a row per round and exits non-zero naming what
// failed. Not part of the default test run (a 30-minute session takes minutes of wall time);
// ctest runs a short form (three small recordings, three rounds) under the label `soak`.
//
//   lobe_soak [--minutes M | --rounds N] [--work DIR] [REC...]
#include <malloc.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <vector>
#include <nlohmann/json.hpp>

#include "app/export/export_scene.h"
#include "app/cli/outputs.h"
#include "app/render/render_scene.h"
#include "app/render/renderer.h"
#include "app/vr/sketch_run.h"
#include "app/export/tree_output.h"
#include "app/session/tree_pipeline.h"
#include "core/atomic_file.h"
#include "core/document.h"
#include "core/errors.h"
#include "input/recording.h"

namespace fs = std::filesystem;
using namespace lobe;

namespace {

std::string hex(std::uint64_t v)
{
    char s[17];
    std::snprintf(s, sizeof s, "%016llx", static_cast<unsigned long long>(v));
    return s;
}

std::string read_bytes(const std::string& path)
{
    std::ifstream in(path, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

/// What a part produced, as hashes: equal hashes, equal results.
struct PartDigest {
    std::string document, glb, picture;
    bool operator==(const PartDigest&) const = default;
    std::string text() const { return "document " + document + " glb " + glb + " picture " + picture; }
};

/// One recording through the whole pipeline, its files in `dir` (emptied first). The picture
/// is drawn by `renderer`, the process's one, as the desktop and VR apps keep one renderer for
/// a whole session.
PartDigest run_part(const std::string& rec_path, const std::string& dir, Renderer& renderer, double* session_s)
{
    std::error_code ec;
    fs::remove_all(dir, ec);
    fs::create_directories(dir);
    const Recording rec = read_recording(rec_path);
    SketchRunOptions o;
    o.session_path = dir + "/session.json";
    o.autosave_path = dir + "/autosave.json";
    o.record_path = dir + "/session.lrec";
    o.events_from_recording = true;
    SketchRunResult run = run_sketch(rec, Document{}, o);
    if (session_s) *session_s = run.session_s;
    Document& doc = run.document;

    PartDigest d;
    const std::string json = document_to_json(doc).dump();
    d.document = hex(bytes_hash(json.data(), json.size()));
    std::vector<std::string> warnings;
    std::vector<BuiltLobe> lobes;
    write_document_lobes(doc, dir, warnings, &lobes);
    if (lobes.empty()) return d;
    const BuiltTree tree = grow_document_tree(doc, std::move(lobes));
    const TreeGeometry geometry = document_tree_geometry(doc, tree);
    write_tree_file(dir + "/tree.glb", doc, tree, geometry, ExportOptions{});
    const std::string glb = read_bytes(dir + "/tree.glb");
    d.glb = hex(bytes_hash(glb.data(), glb.size()));

    RenderContent content;
    content.lobes = true;
    const RenderScene scene = tree_render_scene(geometry, {}, {}, tree.growth.tree.nodes[0].position.y, content);
    renderer.set_scene(scene);
    const int w = 320, h = 240;
    const RgbaImage image = renderer.render(frame_view(scene_bounds(scene), front_view(), float(w) / float(h)), w, h);
    d.picture = hex(bytes_hash(image.pixels.data(), image.pixels.size()));
    const std::vector<std::uint8_t> png = encode_png(image);
    write_file_atomic(dir + "/tree.png", std::string_view(reinterpret_cast<const char*>(png.data()), png.size()));
    return d;
}

/// A number from /proc/self/status ("VmRSS", "VmHWM" in kB; "Threads").
long proc_status(const std::string& key)
{
    std::ifstream in("/proc/self/status");
    std::string line;
    while (std::getline(in, line))
        if (line.compare(0, key.size() + 1, key + ":") == 0) return std::atol(line.c_str() + key.size() + 1);
    return -1;
}

long open_fds()
{
    long n = 0;
    for ([[maybe_unused]] const auto& e : fs::directory_iterator("/proc/self/fd")) ++n;
    return n - 1; // the iterator's own
}

/// Starts a new peak: VmHWM becomes the current RSS (Linux ≥ 4.0).
void reset_peak()
{
    std::ofstream("/proc/self/clear_refs") << "5";
}

struct RoundStats {
    double session_min = 0.0, wall_s = 0.0;
    long peak_kb = 0, rss_kb = 0, heap_kb = 0, fds = 0, threads = 0;
    std::vector<long> part_peak_kb, part_rss_kb; ///< per recording, during and after its part
};

double median(std::vector<double> v)
{
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    return n == 0 ? 0.0 : n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

int usage(const char* why)
{
    std::cerr << "lobe_soak: " << why << "\n"
              << "usage: lobe_soak [--minutes M | --rounds N] [--work DIR] [REC...]\n"
                 "       lobe_soak --part REC --work DIR   (one part, alone; prints its digest)\n";
    return 2;
}

} // namespace

int main(int argc, char** argv)
{
    double minutes = 30.0;
    int rounds = 0;
    std::string work = (fs::temp_directory_path() / "lobe_soak").string(), part;
    std::vector<std::string> recs;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        const bool has_value = i + 1 < argc;
        if (a == "--minutes" && has_value) minutes = std::atof(argv[++i]);
        else if (a == "--rounds" && has_value) rounds = std::atoi(argv[++i]);
        else if (a == "--work" && has_value) work = argv[++i];
        else if (a == "--part" && has_value) part = argv[++i];
        else if (!a.empty() && a[0] == '-') return usage(("unknown option " + a).c_str());
        else recs.push_back(a);
    }
    try {
        if (!part.empty()) {
            Renderer renderer(RendererOptions{});
            std::cout << run_part(part, work, renderer, nullptr).text() << "\n";
            return 0;
        }
        if (recs.empty())
            for (const char* name : {"demo", "edit-stroke-transform", "pinch-edit", "table1-1lobe-5strokes",
                                     "table1-3lobes-16strokes", "table1-4lobes-22strokes"})
                recs.push_back(std::string(LOBE_SOURCE_DIR) + "/recordings/" + name + ".lrec");
        if (rounds < 0 || minutes <= 0.0) return usage("--rounds and --minutes must be positive");

        // The parts, each alone in a fresh process.
        const std::string self = fs::read_symlink("/proc/self/exe").string();
        std::vector<PartDigest> expected;
        for (std::size_t i = 0; i < recs.size(); ++i) {
            // The same folder as in the rounds: the document names its recording's path.
            const std::string dir = work + "/part";
            const std::string command = "'" + self + "' --part '" + recs[i] + "' --work '" + dir + "'";
            FILE* pipe = popen(command.c_str(), "r");
            if (!pipe) return usage("cannot start a part");
            char buf[512] = {};
            std::string out;
            while (std::fgets(buf, sizeof buf, pipe)) out += buf;
            if (pclose(pipe) != 0) {
                std::cerr << "lobe_soak: the part " << recs[i] << " failed alone\n";
                return 1;
            }
            std::istringstream s(out);
            PartDigest d;
            std::string k1, k2, k3;
            s >> k1 >> d.document >> k2 >> d.glb >> k3 >> d.picture;
            expected.push_back(d);
            std::printf("part %zu alone: %s  %s\n", i, d.text().c_str(), fs::path(recs[i]).filename().c_str());
        }
        std::fflush(stdout);

        // Round after round in this process.
        Renderer renderer(RendererOptions{});
        std::vector<RoundStats> stats;
        std::vector<std::string> failures;
        double session_total_s = 0.0;
        const auto start = std::chrono::steady_clock::now();
        std::printf("%5s %11s %7s %9s %9s %9s %4s %7s\n", "round", "session_min", "wall_s", "peak_MB", "rss_MB",
                    "heap_MB", "fds", "threads");
        for (int r = 0;; ++r) {
            if (rounds > 0 ? r >= rounds : (session_total_s >= minutes * 60.0 && r >= 8)) break;
            const auto round_start = std::chrono::steady_clock::now();
            RoundStats st;
            for (std::size_t i = 0; i < recs.size(); ++i) {
                double session_s = 0.0;
                reset_peak();
                const PartDigest d = run_part(recs[i], work + "/part", renderer, &session_s);
                malloc_trim(0);
                st.part_peak_kb.push_back(proc_status("VmHWM"));
                st.part_rss_kb.push_back(proc_status("VmRSS"));
                st.peak_kb = std::max(st.peak_kb, st.part_peak_kb.back());
                session_total_s += session_s;
                if (!(d == expected[i]))
                    failures.push_back("round " + std::to_string(r + 1) + ", " + fs::path(recs[i]).filename().string() +
                                       ": " + d.text() + " differs from the part alone");
            }
            st.session_min = session_total_s / 60.0;
            st.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - round_start).count();
            st.rss_kb = st.part_rss_kb.back();
            st.heap_kb = static_cast<long>(mallinfo2().uordblks / 1024);
            st.fds = open_fds();
            st.threads = proc_status("Threads");
            stats.push_back(st);
            std::printf("%5d %11.1f %7.1f %9.1f %9.1f %9.1f %4ld %7ld\n", r + 1, st.session_min, st.wall_s,
                        double(st.peak_kb) / 1024.0, double(st.rss_kb) / 1024.0, double(st.heap_kb) / 1024.0, st.fds,
                        st.threads);
            std::fflush(stdout);
        }
        const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

        // Round 1 warms up (allocator arenas, the renderer's driver, caches). The allocator
        // and the timing of the background regrowth make a part's peak wander by ±15 % from
        // round to round (which thread's arena a regrowth used, whether an old tree was still
        // held when the new one arrived), so flat is judged as a trend, part by part: the
        // median peak and resident figures of the second half of the rounds after the warm-up
        // against those of the first half. A leak shifts the median; a spike does not.
        if (stats.size() < 2) failures.push_back("fewer than 2 rounds: nothing to compare after the warm-up");
        else if (stats.size() < 6)
            std::printf("memory: not judged (%zu rounds; it takes 6: a warm-up and two halves to compare)\n",
                        stats.size());
        else {
            const std::size_t mid = 1 + (stats.size() - 1) / 2;
            double peak_growth = -1.0, rss_growth = -1.0;
            for (std::size_t i = 0; i < recs.size(); ++i) {
                auto growth = [&](std::vector<long> RoundStats::*field) {
                    std::vector<double> first, second;
                    for (std::size_t r = 1; r < stats.size(); ++r)
                        (r < mid ? first : second).push_back(double((stats[r].*field)[i]));
                    return median(second) / median(first) - 1.0;
                };
                peak_growth = std::max(peak_growth, growth(&RoundStats::part_peak_kb));
                rss_growth = std::max(rss_growth, growth(&RoundStats::part_rss_kb));
            }
            std::printf("after warm-up, the part that grew most: peak memory %+.1f %%, resident memory %+.1f %% "
                        "(median of rounds %zu-%zu against 2-%zu)\n",
                        100.0 * peak_growth, 100.0 * rss_growth, mid + 1, stats.size(), mid);
            if (peak_growth >= 0.05) failures.push_back("peak memory grew " + std::to_string(100.0 * peak_growth) + " %");
            if (rss_growth >= 0.05) failures.push_back("resident memory grew " + std::to_string(100.0 * rss_growth) + " %");
        }
        if (stats.size() >= 2) {
            for (std::size_t r = 1; r < stats.size(); ++r) {
                if (stats[r].fds > stats[0].fds)
                    failures.push_back("round " + std::to_string(r + 1) + " ends with " + std::to_string(stats[r].fds) +
                                       " open files, round 1 with " + std::to_string(stats[0].fds));
                if (stats[r].threads > stats[0].threads)
                    failures.push_back("round " + std::to_string(r + 1) + " ends with " +
                                       std::to_string(stats[r].threads) + " threads, round 1 with " +
                                       std::to_string(stats[0].threads));
            }
        }
        std::printf("%.1f minutes of sessions (%zu parts) in %.0f s of wall time\n", session_total_s / 60.0,
                    stats.size() * recs.size(), wall_s);
        for (const std::string& f : failures) std::printf("FAILED: %s\n", f.c_str());
        std::printf("soak: %s\n", failures.empty() ? "ok" : "FAILED");
        return failures.empty() ? 0 : 1;
    } catch (const std::exception& e) {
        std::cerr << "lobe_soak: " << e.what() << "\n";
        return 1;
    }
}
