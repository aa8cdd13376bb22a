// libFuzzer target: Leap Motion leapjs-playback JSON captures through import_leap_json_text,
// the in-memory half of import_leap_json (lobesketch import-leap).
#include <cstdint>

#include "fuzz/fuzz_common.h"
#include "input/importers.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    const std::string text = lobe::fuzz::as_string(data, size);
    return lobe::fuzz::run_reader([&] {
        lobe::ReadReport report;
        const lobe::Recording rec = lobe::import_leap_json_text(text, "fuzz.json", &report);
        lobe::fuzz::check_report(report.problems);
        lobe::fuzz::check_recording(rec);
    });
}
