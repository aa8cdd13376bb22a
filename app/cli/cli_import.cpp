// `lobesketch import-leap IN -o OUT`, `lobesketch import-webxr IN -o OUT`, and `synth`.
#include <cstring>
#include <filesystem>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "app/cli/cli.h"
#include "app/cli/cli_common.h"
#include "core/atomic_file.h"
#include "input/importers.h"
#include "input/synth.h"

namespace lobe::cli {

namespace {

bool wants_text(const std::string& path)
{
    const std::string ext = std::filesystem::path(path).extension().string();
    return ext == ".txt";
}

void write_recording_any(const std::string& path, const Recording& rec)
{
    if (wants_text(path)) write_recording_text(path, rec);
    else write_recording_binary(path, rec);
}

void add_import(CLI::App& app, int& exit_code, const char* name, const char* help,
                Recording (*importer)(const std::string&, ReadReport*))
{
    auto* cmd = app.add_subcommand(name, help);
    auto in = std::make_shared<std::string>();
    auto out = std::make_shared<std::string>();
    cmd->add_option("IN", *in, "Capture to import")->required();
    cmd->add_option("-o,--out", *out, "Recording to write (.lrec binary, .txt text form)")->required();
    cmd->callback([in, out, importer, &exit_code] {
        ReadReport report;
        Recording rec = importer(*in, &report);
        print_report(*in, report);
        write_recording_any(*out, rec);
        std::size_t hands[2] = {0, 0};
        for (const HandFrame& f : rec.frames)
            for (int h = 0; h < 2; ++h) hands[h] += f.hands[h].active ? 1 : 0;
        progress("wrote " + *out + ": " + std::to_string(rec.frames.size()) + " frames (left hand in " +
                 std::to_string(hands[0]) + ", right hand in " + std::to_string(hands[1]) + ")");
        exit_code = kExitOk;
    });
}

} // namespace

void add_import_commands(CLI::App& app, int& exit_code)
{
    add_import(app, exit_code, "import-leap", "Convert a Leap Motion leapjs-playback JSON recording",
               [](const std::string& p, ReadReport* r) { return import_leap_json(p, r); });
    add_import(app, exit_code, "import-webxr", "Convert a WebXR hand capture (Immersive Web Emulation Runtime)",
               [](const std::string& p, ReadReport* r) { return import_webxr_capture(p, r); });
}

void add_synth_command(CLI::App& app, int& exit_code)
{
    auto* cmd = app.add_subcommand("synth", "Synthesize a realistic hand-tracking recording from a scenario");
    auto in = std::make_shared<std::string>();
    auto out = std::make_shared<std::string>();
    cmd->add_option("SCENARIO", *in, "Scenario JSON (docs/scenario-format.md)")->required();
    cmd->add_option("-o,--out", *out, "Recording to write (.lrec binary, .txt text form); the ground truth goes "
                                      "beside it as <name>.truth.json")->required();
    cmd->callback([in, out, &exit_code] {
        Scenario sc = load_scenario(*in);
        progress("synthesizing " + std::to_string(sc.steps.size()) + " steps of " + *in);
        SynthResult r = synthesize(sc);
        write_recording_any(*out, r.recording);
        std::filesystem::path truth(*out);
        // a/b/name.lrec → a/b/name.truth.json; a/b/name.lrec.txt → a/b/name.truth.json
        std::string stem = truth.filename().string();
        for (const char* ext : {".txt", ".lrec"})
            if (stem.size() > std::strlen(ext) && stem.ends_with(ext)) stem.resize(stem.size() - std::strlen(ext));
        truth.replace_filename(stem + ".truth.json");
        write_file_atomic(truth.string(), ground_truth_to_json(r.truth, r.surfaces).dump(1) + "\n");
        const double duration = r.recording.frames.empty() ? 0.0 : r.recording.frames.back().time;
        progress("wrote " + *out + " (" + std::to_string(r.recording.frames.size()) + " frames, " +
                 std::to_string(duration).substr(0, 6) + " s) and " + truth.string() + " (" +
                 std::to_string(r.truth.size()) + " strokes)");
        exit_code = kExitOk;
    });
}

} // namespace lobe::cli
