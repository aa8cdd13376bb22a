// libFuzzer target: settings files (--settings). The CLI's load_settings_file (app/cli/cli_common.cpp)
// reads the file (size-limited) and does exactly this: parse the JSON without exceptions and
// read a bare settings object or a session document's "settings" with settings_from_json.
// validate_settings, which every command runs before using them, runs too.
#include <cstdint>

#include <nlohmann/json.hpp>

#include "core/settings_json.h"
#include "core/settings_table.h"
#include "fuzz/fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    const std::string text = lobe::fuzz::as_string(data, size);
    return lobe::fuzz::run_reader([&] {
        const nlohmann::json j = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
        if (j.is_discarded()) return;
        const bool document = j.is_object() && j.contains("format") && j.contains("settings");
        const lobe::Settings s = lobe::settings_from_json(document ? j["settings"] : j);
        lobe::validate_settings(s);
    });
}
