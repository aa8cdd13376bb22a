#!/usr/bin/env bash
# The product .cpp files (core, input, meshing, growth, app) whose compilation reads a header,
# from the compiler's dependency records of the last build (ninja -t deps), and their count.
# Heavy headers reached through public headers cost compile time on every change (DESIGN.md).
#
#   scripts/header-reach.sh [HEADER] [BUILD_DIR]
#   scripts/header-reach.sh nlohmann/json.hpp build/release
set -euo pipefail
cd "$(dirname "$0")/.."
header="${1:-nlohmann/json.hpp}"
build="${2:-build/release}"
[ -f "$build/build.ninja" ] || { echo "no $build/build.ninja: build first (./scripts/setup.sh release)" >&2; exit 1; }
files="$(ninja -C "$build" -t deps | awk -v h="/$header" '
  /^[^ ].*: #deps/ { src = ""; next }
  /^    / { f = $1
            if (src == "" && f ~ /\.cpp$/) src = f
            if (src != "" && substr(f, length(f) - length(h) + 1) == h) hit[src] = 1 }
  END { for (s in hit) print s }' | sed 's#^\(\.\./\)*##' | grep -E '^(core|input|meshing|growth|app)/' | sort -u || true)"
total="$(find core input meshing growth app -name '*.cpp' | wc -l)"
[ -n "$files" ] && echo "$files"
echo "$(printf '%s' "$files" | grep -c . || true) of $total product .cpp files read $header"
