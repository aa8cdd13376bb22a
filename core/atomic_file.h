#pragma once
/// \file atomic_file.h
/// Saving without ever losing the previous version: write a temporary file beside the
/// target, flush it to disk, then rename it over the target (atomic on POSIX).

#include <cstddef>
#include <string>
#include <string_view>

namespace lobe {

/// \throw FileError when the temporary file cannot be written or renamed; the target is
/// then untouched.
void write_file_atomic(const std::string& path, std::string_view content);

/// Reads a whole file, refusing files larger than max_bytes.
/// \throw FileError when the file is missing, unreadable or too large.
std::string read_file_limited(const std::string& path, std::size_t max_bytes);

} // namespace lobe
