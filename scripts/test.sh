#!/usr/bin/env bash
# The README's test command: set up, build, and run the whole test suite, first optimised,
# then under AddressSanitizer + UndefinedBehaviorSanitizer, then every fuzz target of that
# build for 15 seconds (docs/fuzzing.md).
set -euo pipefail
cd "$(dirname "$0")/.."
JOBS="$(nproc)"

./scripts/setup.sh release
ctest --preset release -j "$JOBS"

cmake --preset asan >/dev/null
cmake --build --preset asan
ctest --preset asan -j "$JOBS"
./scripts/fuzz.sh 15
