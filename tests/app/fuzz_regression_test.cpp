// Every input a fuzz target (fuzz/, docs/fuzzing.md) found to crash, hang or exhaust memory
// lives in tests/data/fuzz-regressions/<target>/ and is read here through the reader's file
// entry point (what a user's file goes through): each must give a clean one-line error that
// names the file.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "app/cli/cli_common.h"
#include "app/desktop/desktop_script.h"
#include "core/atomic_file.h"
#include "core/document.h"
#include "core/errors.h"
#include "core/settings_table.h"
#include "growth/species.h"
#include "input/importers.h"
#include "input/recording.h"
#include "input/synth.h"
#include "meshing/mesh_io.h"
#include "meshing/model_import.h"
#include "tests/support/test_data.h"
#include "tests/support/test_paths.h"

using namespace lobe;
namespace fs = std::filesystem;

namespace {

/// fuzz target name → the file reader it fuzzes.
const std::map<std::string, std::function<void(const std::string&)>>& readers()
{
    static const std::map<std::string, std::function<void(const std::string&)>> r = {
        {"recording_binary", [](const std::string& p) { read_recording(p); }},
        {"recording_text", [](const std::string& p) { read_recording(p); }},
        {"import_leap", [](const std::string& p) { import_leap_json(p); }},
        {"import_webxr", [](const std::string& p) { import_webxr_capture(p); }},
        {"document", [](const std::string& p) { load_document(p); }},
        {"settings", [](const std::string& p) { validate_settings(cli::load_settings_file(p)); }},
        {"species", [](const std::string& p) { Settings s; apply_species(s, load_species(p)); }},
        {"mesh_obj", [](const std::string& p) { read_mesh(p); }},
        {"mesh_ply", [](const std::string& p) { read_mesh(p); }},
        {"mesh_off", [](const std::string& p) { read_mesh(p); }},
        {"mesh_repair", [](const std::string& p) {
             LobeFromModelOptions o;
             o.target_edge_length_m = 0.15; // as the fuzz target
             lobe_from_model(p, o);
         }},
        {"desktop_script", [](const std::string& p) { parse_desktop_script(read_file_limited(p, 16u << 20), p); }},
        {"scenario", [](const std::string& p) { load_scenario(p); }},
    };
    return r;
}

} // namespace

TEST(FuzzRegressions, EveryFoundInputGivesAOneLineError)
{
    const std::string folder = test::source_data("tests/data/fuzz-regressions");
    if (folder.empty()) return;
    const fs::path root = folder;
    ASSERT_TRUE(fs::is_directory(root)) << root;
    std::size_t files = 0;
    for (const auto& dir : fs::directory_iterator(root)) {
        if (!dir.is_directory()) continue;
        const std::string target = dir.path().filename().string();
        const auto reader = readers().find(target);
        ASSERT_NE(reader, readers().end()) << "no reader for " << dir.path();
        std::vector<fs::path> inputs;
        for (const auto& f : fs::directory_iterator(dir.path()))
            if (f.is_regular_file()) inputs.push_back(f.path());
        std::sort(inputs.begin(), inputs.end());
        for (const fs::path& input : inputs) {
            SCOPED_TRACE(input.string());
            ++files;
            const std::string path = input.string();
            try {
                reader->second(path);
                ADD_FAILURE() << "no error";
            } catch (const Error& e) {
                const std::string msg = e.what();
                EXPECT_NE(msg.find(input.filename().string()), std::string::npos) << msg;
                EXPECT_EQ(msg.find_first_of("\r\n"), std::string::npos) << msg;
            }
        }
    }
    RecordProperty("inputs", static_cast<int>(files));
}
