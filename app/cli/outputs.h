#pragma once
/// \file outputs.h
/// Files the CLI writes besides the session document.

#include <string>
#include <vector>

#include "core/document.h"
#include "core/stroke.h"
#include "app/session/lobe_document.h"

namespace lobe {

/// `{"format":"lobesketch-strokes","version":1,"source":…,"strokes":[{id, kind, closed, hand,
/// points:[[x,y,z] metres…], times:[s…]}]}`, written atomically.
void write_strokes_json(const std::string& path, const std::vector<Stroke>& strokes, const std::string& source);

/// Rebuilds every lobe of `doc` (app/session/lobe_document.h) and writes each as
/// `out_dir/lobes/lobe_<id>.ply`, recording the relative path in the lobe's mesh_file.
/// Lobes that cannot be built get an empty mesh_file. Warnings are appended, one line each.
/// `lobe_<n>.ply` files of an earlier run that this one did not write are removed, so the
/// folder holds this session's lobes only (remove_stale_lobe_files).
/// Returns the number of lobe files written; `built` (when given) receives the lobes.
/// \throw FileError
std::size_t write_document_lobes(Document& doc, const std::string& out_dir, std::vector<std::string>& warnings,
                                 std::vector<BuiltLobe>* built = nullptr);

/// Removes the files `lobes_dir/lobe_<digits>.ply` whose names are not in `kept` (other files
/// are left alone); returns how many were removed. \throw FileError when one cannot be.
std::size_t remove_stale_lobe_files(const std::string& lobes_dir, const std::vector<std::string>& kept);

} // namespace lobe
