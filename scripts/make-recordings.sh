#!/usr/bin/env bash
# Regenerates the shipped synthetic recordings (and their .truth.json ground truth) from every
# recordings/*.scenario.json (deterministic: the same build gives the same bytes). Run after
# changing the synthesizer or a scenario; the test
# ReplayScenario.ShippedRecordingsAreUpToDateWithTheirScenarios says when it is needed.
set -euo pipefail
cd "$(dirname "$0")/.."
CLI="${LOBESKETCH:-./build/release/app/lobesketch}"
if [[ ! -x "$CLI" ]]; then
  echo "make-recordings: $CLI not found; build first (cmake --build build/release) or set LOBESKETCH" >&2
  exit 1
fi
shopt -s nullglob
scenarios=(recordings/*.scenario.json recordings/lsystem-sketch/*.scenario.json)
if (( ${#scenarios[@]} == 0 )); then
  echo "make-recordings: no recordings/*.scenario.json" >&2
  exit 1
fi
for sc in "${scenarios[@]}"; do
  out="${sc%.scenario.json}.lrec"
  "$CLI" synth "$sc" -o "$out"
done
# The demo is the largest Table 1 scene.
ln -sf table1-4lobes-22strokes.lrec recordings/demo.lrec
ln -sf table1-4lobes-22strokes.truth.json recordings/demo.truth.json
