// libFuzzer target: OFF meshes through parse_mesh, the in-memory half of read_mesh
// (the format is chosen by the name's extension, as for a file called *.off).
#include <cstdint>

#include "fuzz/fuzz_common.h"
#include "meshing/mesh_io.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    const std::string bytes = lobe::fuzz::as_string(data, size);
    return lobe::fuzz::run_reader([&] { lobe::fuzz::check_mesh(lobe::parse_mesh(bytes, "fuzz.off")); });
}
