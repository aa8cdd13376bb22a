// libFuzzer target: desktop scripts (`lobesketch desktop --script FILE`). The CLI reads the file
// (size-limited) and parses it with parse_desktop_script (app/desktop/desktop_script.h); the steps it
// returns must keep the header's promises: at most 200,000, sorted by frame, frames in
// 0..10^7, finite coordinates and values that fit the floats of the input events.
#include <cmath>
#include <cstdint>
#include <limits>

#include "app/desktop/desktop_script.h"
#include "fuzz/fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    const std::string text = lobe::fuzz::as_string(data, size);
    return lobe::fuzz::run_reader([&] {
        using lobe::fuzz::require;
        const std::vector<lobe::ScriptStep> steps = lobe::parse_desktop_script(text, "fuzz.script");
        require(steps.size() <= 200000, "more than 200,000 steps");
        for (std::size_t i = 0; i < steps.size(); ++i) {
            const lobe::ScriptStep& s = steps[i];
            require(s.frame >= 0 && s.frame <= 10000000, "a frame outside 0..10^7");
            require(i == 0 || steps[i - 1].frame <= s.frame, "steps not sorted by frame");
            require(std::isfinite(s.x) && std::isfinite(s.y), "a coordinate that is not finite");
            require(std::isfinite(s.value) && std::abs(s.value) <= std::numeric_limits<float>::max(),
                    "a value that does not fit a float");
        }
    });
}
