#pragma once
/// \file embedded_shaders.h
/// The renderer's SPIR-V, compiled from app/render/shaders/*.{vert,frag} by glslc at build time
/// and embedded by app/render/embed_spirv.cmake.

#include <cstdint>
#include <span>
#include <string_view>

namespace lobe {

/// The SPIR-V words of a shader by its file name ("mesh.vert"); empty when there is none.
std::span<const std::uint32_t> embedded_shader(std::string_view name);

} // namespace lobe
