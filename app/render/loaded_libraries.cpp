#include "app/render/loaded_libraries.h"

#include <algorithm>

#include <dlfcn.h>
#include <link.h>

namespace lobe {

std::vector<std::string> loaded_libraries()
{
    std::vector<std::string> out;
    dl_iterate_phdr(
        [](dl_phdr_info* info, std::size_t, void* data) {
            if (info->dlpi_name && info->dlpi_name[0]) static_cast<std::vector<std::string>*>(data)->push_back(info->dlpi_name);
            return 0;
        },
        &out);
    return out;
}

void keep_loaded_since(const std::vector<std::string>& before)
{
    for (const std::string& lib : loaded_libraries())
        if (std::find(before.begin(), before.end(), lib) == before.end())
            dlopen(lib.c_str(), RTLD_NOW | RTLD_NOLOAD | RTLD_NODELETE);
}

} // namespace lobe
