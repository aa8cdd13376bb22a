#pragma once
// The Khronos glTF validator (npm gltf-validator, installed by scripts/setup.sh) run from
// tests on exported files.
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

namespace lobe::test {

/// Runs tests/support/gltf_validate.mjs on `file` and parses its report into `report`; fails with the
/// reason when node or the validator is missing (run scripts/setup.sh) or the run breaks.
::testing::AssertionResult validate_gltf(const std::string& file, nlohmann::json& report);
/// The report's messages, one per line, for failure output.
std::string describe_gltf_issues(const nlohmann::json& report);

} // namespace lobe::test
