#pragma once
/// \file cli.h
/// The `lobesketch` command line (CLI11). Exit codes: 0 success, 1 failure of the work
/// (nothing usable in the input), 2 bad command line, 3 partial success with warnings is
/// still 0 (warnings go to stderr).

namespace lobe {

inline constexpr int kExitOk = 0;
inline constexpr int kExitFailure = 1;
inline constexpr int kExitUsage = 2;

int run_cli(int argc, char** argv);

} // namespace lobe
