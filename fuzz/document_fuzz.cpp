// libFuzzer target: session documents. load_document reads the file (size-limited) and does
// exactly this: parse the JSON without exceptions, then document_from_json, whose
// InvalidInput it turns into a FileError.
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
        lobe::document_from_json(j);
    });
}
