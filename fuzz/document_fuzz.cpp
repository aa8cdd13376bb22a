// libFuzzer target: session documents. load_document reads the file (size-limited) and does
// exactly this: parse the JSON without exceptions, then document_from_json, whose
// InvalidInput it turns into a FileError. A document it accepts is written back and read
// again: the second reading accepts it and writes the same JSON (every edit operation, of
// every kind, round-trips).
#include <cstdint>

#include <nlohmann/json.hpp>

#include "core/document.h"
#include "fuzz/fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    const std::string text = lobe::fuzz::as_string(data, size);
    return lobe::fuzz::run_reader([&] {
        const nlohmann::json j = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
        if (j.is_discarded()) return;
        const nlohmann::json written = lobe::document_to_json(lobe::document_from_json(j));
        lobe::Document again;
        try {
            again = lobe::document_from_json(written);
        } catch (const lobe::Error&) {
            lobe::fuzz::require(false, "a document it wrote is read back");
        }
        lobe::fuzz::require(lobe::document_to_json(again) == written, "a document it wrote is written again the same");
    });
}
