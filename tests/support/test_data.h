#pragma once
/// \file test_data.h
/// The data files and folders tests read: the project's recordings/, tests/data/ and fuzz
/// seeds (fuzz/corpus/), and ../shared/data (models/, real/). Missing data fails the running test with one line,
/// "missing test data: PATH", at the line that asked for it (never a crash, never a skip);
/// the caller gets an empty path or false and stops:
///
///     const std::string spot = test::shared_data("data/models/spot.obj");
///     if (spot.empty()) return;
///
/// The failure is fatal, so a fixture's SetUp that asks for missing data keeps the test body
/// from running.

#include <string>

namespace lobe::test {

/// source_path(rel) (relative to the project root) when it exists, else "" and the test failed.
std::string source_data(const std::string& rel, const char* file = __builtin_FILE(), int line = __builtin_LINE());
/// shared_path(rel) (relative to ../shared) when it exists, else "" and the test failed.
std::string shared_data(const std::string& rel, const char* file = __builtin_FILE(), int line = __builtin_LINE());
/// True when `path` (a file or folder) exists, else false and the test failed.
bool require_data(const std::string& path, const char* file = __builtin_FILE(), int line = __builtin_LINE());

} // namespace lobe::test
