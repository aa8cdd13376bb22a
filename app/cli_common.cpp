#include "app/cli_common.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <iostream>

#include <nlohmann/json.hpp>

#include "app/edit_hooks.h"
#include "core/atomic_file.h"
#include "input/pipeline.h"
#include "input/session_builder.h"
#include "core/document.h"
#include "core/errors.h"

namespace lobe::cli {

namespace {
bool g_quiet = false;
}

void set_quiet(bool quiet) { g_quiet = quiet; }
void warn(const std::string& line) { std::cerr << "lobesketch: warning: " << line << '\n'; }
void error(const std::string& line) { std::cerr << "lobesketch: error: " << line << '\n'; }
void progress(const std::string& line)
{
    if (!g_quiet) std::cerr << line << '\n';
}

void print_report(const std::string& path, const ReadReport& report)
{
    for (const std::string& p : report.problems) warn(path + ": " + p);
    if (report.frames_dropped > 0)
        warn(path + ": dropped " + std::to_string(report.frames_dropped) + " frame(s), kept " +
             std::to_string(report.frames_read));
}

Recording load_recording_verbose(const std::string& path)
{
    ReadReport report;
    Recording rec;
    try {
        rec = read_recording(path, &report);
    } catch (const FileError& e) {
        // Captures of other programs are a common mix-up: say which command converts them.
        std::string head;
        if (std::ifstream in{path, std::ios::binary}) {
            head.resize(16);
            in.read(head.data(), 16);
            head.resize(static_cast<std::size_t>(in.gcount()));
        }
        const std::string what = e.what();
        if (head.rfind("{", 0) == 0 && what.find("magic") != std::string::npos)
            throw Error(what + " (a Leap Motion JSON capture? convert it with 'lobesketch import-leap')");
        if (head.rfind("var ", 0) == 0 && what.find("magic") != std::string::npos)
            throw Error(what + " (a WebXR capture? convert it with 'lobesketch import-webxr')");
        throw;
    }
    print_report(path, report);
    return rec;
}

Settings load_settings_file(const std::string& path)
{
    const std::string text = read_file_limited(path, 16u << 20);
    nlohmann::json j = nlohmann::json::parse(text, nullptr, false);
    if (j.is_discarded()) throw FileError(path, "not valid JSON");
    try {
        // Accept a bare settings object or a whole session document's "settings".
        if (j.is_object() && j.contains("format") && j.contains("settings")) return settings_from_json_checked(j["settings"]);
        return settings_from_json_checked(j);
    } catch (const InvalidInput& e) {
        throw FileError(path, e.what());
    }
}

std::string lower_extension(const std::string& path)
{
    std::string ext = std::filesystem::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return ext;
}

Document replay_into_document(const std::string& path, Document doc, std::size_t* drags)
{
    const Recording rec = load_recording_verbose(path);
    const double duration = rec.frames.empty() ? 0.0 : rec.frames.back().time - rec.frames.front().time;
    progress("replaying " + std::to_string(rec.frames.size()) + " frames (" + std::to_string(duration).substr(0, 6) +
             " s) of " + path);
    const InputResult result = run_input_pipeline(rec, doc.settings.input);
    for (const std::string& m : result.messages) warn(path + ": " + m);
    if (drags) *drags = result.drags.size();
    doc.source_recording = std::filesystem::absolute(path).lexically_normal().string();
    SessionBuilder builder(std::move(doc), EditPickOptions{}, meshing_edit_hooks());
    builder.apply(result.actions);
    for (const std::string& m : builder.messages()) warn(path + ": " + m);
    return builder.take_document();
}

} // namespace lobe::cli
