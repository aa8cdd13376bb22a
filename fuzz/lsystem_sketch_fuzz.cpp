// libFuzzer target: sketch files (`lobesketch lsystem --sketch SKETCH.json`) through
// parse_sketch (growth/lsystem/sketch.h), the in-memory half of what the command reads. A
// sketch that parses must write back to the same sketch (sketch_json), its rules (at a growth
// of at most 6 iterations) must parse without a warning, and derive and interpret within
// small limits: the rules the program writes are never malformed.
#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "fuzz/fuzz_common.h"
#include "growth/lsystem/lsystem.h"
#include "growth/lsystem/sketch.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    using lobe::fuzz::require;
    namespace ls = lobe::lsystem;
    const std::string text = lobe::fuzz::as_string(data, size);
    lobe::fuzz::run_reader([&] {
        const ls::Sketch s = ls::parse_sketch(text, "fuzz.json");
        const ls::Sketch back = ls::parse_sketch(ls::sketch_json(s), "again.json");
        require(back.trunk == s.trunk && back.branches.size() == s.branches.size() &&
                    back.divergence_deg == s.divergence_deg && back.iterations == s.iterations,
                "a sketch that does not read back as written");
        ls::SketchRulesOptions o;
        o.growth = std::min(6.0, static_cast<double>(s.shown_iterations()));
        const ls::SketchRules r = ls::sketch_rules(s, o);
        std::vector<std::string> warnings;
        const ls::LSystem sys = ls::parse_lsystem(r.lsystem, "rules.l", &warnings);
        ls::parse_view(r.view, "rules.v", &warnings);
        require(warnings.empty(), "derived rules that warn");
        ls::DeriveOptions d;
        d.max_modules = 4096;
        d.max_param_values = 4096 * 8;
        d.max_operations = 2000000;
        try {
            const ls::Word w = ls::derive(sys, d);
            ls::interpretation_word(sys, w, d);
        } catch (const lobe::InvalidInput& e) {
            lobe::fuzz::check_one_line(e.what()); // a tree past the small limits here
        }
    });
    return 0;
}
