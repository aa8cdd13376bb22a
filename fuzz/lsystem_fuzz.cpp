// libFuzzer target: cpfg L-system files (`.l`) and view files (`.v`) through parse_lsystem and
// parse_view (growth/lsystem/lsystem.h), the in-memory halves of load_lsystem_file; every input
// goes to both readers. A system that parses is derived for a few steps within small limits,
// given its homomorphism and written as text: the words must keep Word's promises.
#include <cmath>
#include <cstdint>

#include "fuzz/fuzz_common.h"
#include "growth/lsystem/lsystem.h"

namespace {

void check_word(const lobe::lsystem::LSystem& sys, const lobe::lsystem::Word& w, std::size_t max_modules)
{
    using lobe::fuzz::require;
    require(w.modules.size() <= max_modules, "a word past max_modules");
    for (const lobe::lsystem::Module& m : w.modules) {
        require(m.symbol < sys.symbol_count(), "a module whose symbol is not the system's");
        require(static_cast<std::size_t>(m.first_param) + m.param_count <= w.params.size(), "parameters out of range");
    }
    for (const double v : w.params) require(std::isfinite(v), "a non-finite parameter");
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    const std::string text = lobe::fuzz::as_string(data, size);
    lobe::fuzz::run_reader([&] {
        std::vector<std::string> warnings;
        (void)lobe::lsystem::parse_view(text, "fuzz.v", &warnings);
        lobe::fuzz::check_report(warnings);
    });
    return lobe::fuzz::run_reader([&] {
        std::vector<std::string> warnings;
        const lobe::lsystem::LSystem sys = lobe::lsystem::parse_lsystem(text, "fuzz.l", &warnings);
        lobe::fuzz::check_report(warnings);
        lobe::lsystem::DeriveOptions o;
        o.steps = std::min(sys.derivation_length(), 6);
        o.seed = size;
        o.max_modules = 4096;
        o.max_param_values = 4096;
        o.max_operations = 2'000'000;
        o.answer_queries = [](lobe::lsystem::Word& w) {
            for (double& v : w.params) v = 0.5;
        };
        const lobe::lsystem::Word w = lobe::lsystem::derive(sys, o);
        check_word(sys, w, o.max_modules);
        const lobe::lsystem::Word shown = lobe::lsystem::interpretation_word(sys, w, o);
        check_word(sys, shown, o.max_modules);
        const std::string s = lobe::lsystem::to_string(sys, shown);
        lobe::fuzz::require(shown.empty() || !s.empty(), "an empty text for a word");
    });
}
