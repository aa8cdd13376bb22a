#pragma once
/// \file outputs.h
/// Files the CLI writes besides the session document.

#include <string>
#include <vector>

#include "core/stroke.h"

namespace lobe {

/// `{"format":"lobesketch-strokes","version":1,"source":…,"strokes":[{id, kind, closed, hand,
/// points:[[x,y,z] metres…], times:[s…]}]}`, written atomically.
void write_strokes_json(const std::string& path, const std::vector<Stroke>& strokes, const std::string& source);

} // namespace lobe
