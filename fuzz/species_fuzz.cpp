// libFuzzer target: species preset files (--species file.json) through parse_species, the
// in-memory half of load_species; a preset that parses is applied to default settings.
#include <cstdint>

#include "fuzz/fuzz_common.h"
#include "growth/species.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    const std::string text = lobe::fuzz::as_string(data, size);
    return lobe::fuzz::run_reader([&] {
        const lobe::SpeciesPreset p = lobe::parse_species(text, "fuzz.json");
        lobe::Settings s;
        lobe::apply_species(s, p);
    });
}
