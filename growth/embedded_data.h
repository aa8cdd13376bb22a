#pragma once
/// \file embedded_data.h
/// The files of growth/data/ (subtree library, species presets, L-system presets), compiled
/// into the program.

#include <string>
#include <string_view>
#include <vector>

namespace lobe {

struct EmbeddedFile {
    std::string name;      ///< path relative to growth/data/, e.g. "species/broadleaf.json",
                           ///< "lsystems/willow.l"
    std::string_view text; ///< the file's bytes
};

const std::vector<EmbeddedFile>& embedded_growth_data();

} // namespace lobe
