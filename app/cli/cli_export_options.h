#pragma once
/// \file cli_export_options.h
/// The options of `grow`, `export` and `replay` that say how the tree file is written
/// (docs/export.md): the billboard level, texture sizes, the bark normal map, and mesh
/// optimisation and compression for engines.

#include <CLI/CLI.hpp>

#include "app/export/export_scene.h"

namespace lobe::cli {

struct TreeFileArgs {
    int billboard = 256;       ///< billboard texture size; 0: no billboard level
    int texture_size = 0;      ///< leaf and bark texture size; 0: the tree's (128)
    bool bark_normal_map = false;
    bool optimize = false;
    bool compress = false;
    bool quantize = false;
};

/// Registers --billboard, --texture-size, --bark-normal-map, --optimize, --quantize and --compress; a bad
/// value (not a power of two in range) is a bad command line (exit 2).
void add_tree_file_options(CLI::App* cmd, TreeFileArgs& a);

/// `a` as export options (the other members of ExportOptions left as they are in `into`).
void apply_tree_file_options(const TreeFileArgs& a, ExportOptions& into);

} // namespace lobe::cli
