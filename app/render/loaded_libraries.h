#pragma once
/// \file loaded_libraries.h
/// Keeping shared libraries that a driver or a windowing library loaded (and would unload on
/// shutdown) in the process until it ends. Mesa's Vulkan drivers and X11 keep global state
/// they do not free when unloaded; pinned, they are not loaded twice, and a leak checker can
/// still name them at exit.

#include <string>
#include <vector>

namespace lobe {

/// Paths of the shared libraries loaded in the process now.
std::vector<std::string> loaded_libraries();

/// Pins every library loaded now that is not in `before` (RTLD_NODELETE).
void keep_loaded_since(const std::vector<std::string>& before);

} // namespace lobe
