#!/usr/bin/env bash
# Instructions per added stroke in the lobe benchmarks that time adding a stroke
# (BM_AddStrokeToTenStrokeLobe, BM_AddRingBetweenTwoOfTenStackedRings), counted by callgrind.
# Wall time on a shared 2-core VM spreads by up to 20 % from run to run; these counts do not
# move, so they tell changes of a few per cent apart. Needs a release build (./scripts/setup.sh).
#
#   scripts/count-instructions.sh [BENCHMARK_REGEX] [BUILD_DIR]
#   scripts/count-instructions.sh 'BM_AddStrokeToTenStrokeLobe/1$'
set -euo pipefail
cd "$(dirname "$0")/.."
filter="${1:-BM_AddStrokeToTenStrokeLobe/[0-9]+\$|BM_AddRingBetweenTwoOfTenStackedRings\$}"
build="${2:-build/release}"
bench="$build/tests/lobe_bench"
[ -x "$bench" ] || { echo "no $bench: run ./scripts/setup.sh release first" >&2; exit 1; }
if ! command -v valgrind >/dev/null; then
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -qq && $SUDO apt-get install -y -qq --no-install-recommends valgrind >/dev/null
fi
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
for name in $("$bench" --benchmark_list_tests --benchmark_filter="$filter"); do
  file="$out/callgrind.out"
  valgrind --tool=callgrind --callgrind-out-file="$file" --toggle-collect='*add_timed*' \
    "$bench" --benchmark_filter="^${name}\$" --benchmark_min_time=0.3 >/dev/null 2>&1
  total=$(awk '/^totals:/ {print $2}' "$file")
  # add_timed is the caller of what it calls, "(Nx)": N strokes added.
  calls=$(callgrind_annotate --tree=caller "$file" 2>/dev/null |
    awk '/ < .*add_timed.*\([0-9,]+x\)/ { n = $0; sub(/.*\(/, "", n); sub(/x\).*/, "", n); gsub(",", "", n); if (n + 0 > calls) calls = n + 0 }
         END { print calls + 0 }')
  [ "$calls" -gt 0 ] || { echo "$name: no timed adding found" >&2; exit 1; }
  awk -v n="$name" -v t="$total" -v c="$calls" 'BEGIN { printf "%-50s %8.3f M instructions per stroke (%d strokes)\n", n, t / c / 1e6, c }'
done
