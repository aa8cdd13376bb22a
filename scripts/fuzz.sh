#!/usr/bin/env bash
# Runs the libFuzzer targets (fuzz/, docs/fuzzing.md) for SECONDS each (default 15), one after
# the other, from the committed seeds (fuzz/corpus/<target>) into a scratch corpus that is
# kept between runs (build/fuzz/<target>/corpus). Prints each target's statistics and exits
# non-zero when any target found something: a crash, a sanitizer report, an uncaught
# exception, a multi-line error, a timeout (10 s, lobe_strokes 30 s, hole_fill 45 s; LOBE_FUZZ_TIMEOUT=S sets
# another, for runs on a loaded machine) or more than 2 GiB of memory. The inputs
# that did it are in build/fuzz/<target>/artifacts/.
#
#   scripts/fuzz.sh [SECONDS] [TARGET...]     targets: the names below, e.g. mesh_ply
#
# The targets come from the asan build (cmake --preset asan; cmake --build --preset asan);
# LOBE_FUZZ_BUILD names another build folder configured with -DLOBE_FUZZ=ON.
set -euo pipefail
cd "$(dirname "$0")/.."

DURATION="${1:-15}"
[ $# -gt 0 ] && shift
BUILD="${LOBE_FUZZ_BUILD:-build/asan}"

# target → largest input libFuzzer makes (bytes): a few records, frames or faces is enough
# to reach every branch, and small inputs keep the runs fast.
declare -A MAX_LEN=(
  [recording_binary]=16384 [recording_text]=16384
  [import_leap]=16384 [import_webxr]=16384
  [document]=16384 [settings]=8192 [species]=4096
  [mesh_obj]=8192 [mesh_ply]=8192 [mesh_off]=8192 [mesh_repair]=4096 [hole_fill]=1024 [lobe_strokes]=128
  [desktop_script]=4096 [scenario]=8192 [lsystem]=4096 [lsystem_sketch]=4096
)
# target → seconds one input may take (LOBE_FUZZ_TIMEOUT sets every target's): a lobe of six
# strokes, each built twice (continued and whole) and checked for self-intersections, takes
# a few seconds under ASan. A hole_fill dome folded through itself is repaired twice (its cut
# bisected, and by whole triangles; docs/lobes-from-models.md, step 5): the slowest seed takes
# 19 s under ASan (1.4 s in release), the slowest input found so far 34 s (3.5 s).
declare -A TIMEOUT=([lobe_strokes]=30 [hole_fill]=45)
ALL=(recording_binary recording_text import_leap import_webxr document settings species lsystem lsystem_sketch mesh_obj mesh_ply mesh_off mesh_repair hole_fill lobe_strokes desktop_script scenario)
TARGETS=("$@")
[ ${#TARGETS[@]} -eq 0 ] && TARGETS=("${ALL[@]}")

export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"

failed=()
printf '%-17s %10s %8s %6s %6s %6s %6s %8s  %s\n' target execs exec/s cov ft corpus new rss_mb result
for t in "${TARGETS[@]}"; do
  if [ -z "${MAX_LEN[$t]:-}" ]; then
    echo "fuzz: unknown target '$t' (known: ${ALL[*]})" >&2
    exit 2
  fi
  bin="$BUILD/fuzz/${t}_fuzz"
  if [ ! -x "$bin" ]; then
    echo "fuzz: $bin is missing: build it with 'cmake --preset asan && cmake --build --preset asan --target fuzz'" >&2
    exit 2
  fi
  work="build/fuzz/$t"
  mkdir -p "$work/corpus" "$work/artifacts"
  log="$work/last-run.log"
  rc=0
  "$bin" -max_total_time="$DURATION" -max_len="${MAX_LEN[$t]}" -timeout="${LOBE_FUZZ_TIMEOUT:-${TIMEOUT[$t]:-10}}" -rss_limit_mb=2048 \
    -malloc_limit_mb=2048 -print_final_stats=1 -artifact_prefix="$work/artifacts/" \
    "$work/corpus" "fuzz/corpus/$t" >"$log" 2>&1 || rc=$?
  stat_of() { sed -n "s/^stat::$1: *//p" "$log" | tail -1; }
  last="$(grep -E '^#[0-9]+.*cov: ' "$log" | tail -1 || true)"
  cov="$(sed -n 's/.* cov: \([0-9]*\).*/\1/p' <<<"$last")"
  ft="$(sed -n 's/.* ft: \([0-9]*\).*/\1/p' <<<"$last")"
  corp="$(sed -n 's/.* corp: \([0-9]*\).*/\1/p' <<<"$last")"
  result=ok
  if [ "$rc" -ne 0 ]; then
    result="FOUND (exit $rc)"
    failed+=("$t")
  fi
  printf '%-17s %10s %8s %6s %6s %6s %6s %8s  %s\n' "$t" "$(stat_of number_of_executed_units)" \
    "$(stat_of average_exec_per_sec)" "${cov:-?}" "${ft:-?}" "${corp:-?}" "$(stat_of new_units_added)" \
    "$(stat_of peak_rss_mb)" "$result"
  if [ "$rc" -ne 0 ]; then
    echo "---- $t: last lines of $log" >&2
    grep -vE '^#[0-9]+' "$log" | tail -40 >&2
    echo "---- reproduce: $bin $work/artifacts/<file> (artifacts: $(ls "$work/artifacts" | tr '\n' ' '))" >&2
  fi
done

if [ ${#failed[@]} -gt 0 ]; then
  echo "fuzz: findings in ${failed[*]} (docs/fuzzing.md: every finding becomes a regression test)" >&2
  exit 1
fi
