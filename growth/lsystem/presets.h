#pragma once
/// \file presets.h
/// The L-system presets Lobesketch ships: cpfg `.l` files (with their `.v` view files where
/// they have one) from growth/data/lsystems/, compiled into the program, so a preset's name
/// works wherever a `.l` file does (docs/lsystems.md lists them with their sources).
/// A preset's name is its file's stem: `ordinary-tree`, `willow`, `lobe-filler`, ….

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "growth/lsystem/lsystem.h"

namespace lobe::lsystem {

/// One shipped preset: its `.l` text and, when it has one, its `.v` text.
struct Preset {
    std::string name;        ///< the file's stem, lower case with '-'
    std::string_view lsystem; ///< the `.l` file's bytes
    std::string_view view;    ///< the `.v` file's bytes; empty when the preset has none
};

/// Every shipped preset, sorted by name.
const std::vector<Preset>& presets();

/// The preset named `name`, or null.
const Preset* find_preset(std::string_view name);

/// Parses the preset named `name` as load_lsystem_file() would read its files (source names
/// `NAME.l` and `NAME.v`, for messages).
/// \throw InvalidInput when no preset has that name (the message lists them), or as
/// parse_lsystem / parse_view.
LSystemFile load_preset(std::string_view name);

/// `file_or_preset` read as a file when one exists at that path, else as a preset name.
/// \throw FileError when it is neither (naming the path and the presets); as
/// load_lsystem_file / load_preset otherwise.
LSystemFile load_lsystem_or_preset(const std::filesystem::path& file_or_preset);

} // namespace lobe::lsystem
