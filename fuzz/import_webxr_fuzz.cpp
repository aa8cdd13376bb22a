// libFuzzer target: WebXR hand captures (IWER ActionRecorder JS modules) through
// import_webxr_capture_text, the in-memory half of import_webxr_capture (lobesketch import-webxr).
#include <cstdint>

#include "fuzz/fuzz_common.h"
#include "input/importers.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    const std::string text = lobe::fuzz::as_string(data, size);
    return lobe::fuzz::run_reader([&] {
        lobe::ReadReport report;
        const lobe::Recording rec = lobe::import_webxr_capture_text(text, "fuzz.js", &report);
        lobe::fuzz::check_report(report.problems);
        lobe::fuzz::check_recording(rec);
    });
}
