// libFuzzer target: binary recordings (.lrec) through parse_recording, the in-memory half of
// read_recording. An input without the binary magic gets it prepended, so every run
// exercises the binary reader (the text form has its own target).
#include <cstdint>
#include <string>

#include "fuzz/fuzz_common.h"
#include "input/recording.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    static const std::string kMagic("LOBEREC\x1a", 8);
    std::string bytes = lobe::fuzz::as_string(data, size);
    if (bytes.compare(0, kMagic.size(), kMagic) != 0) bytes.insert(0, kMagic);
    return lobe::fuzz::run_reader([&] {
        lobe::ReadReport report;
        const lobe::Recording rec = lobe::parse_recording(bytes, "fuzz.lrec", &report);
        lobe::fuzz::check_report(report.problems);
        lobe::fuzz::check_recording(rec);
    });
}
