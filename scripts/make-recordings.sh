#!/usr/bin/env bash
# Regenerates the shipped synthetic recordings from their scenarios (deterministic: the same
# build gives the same bytes). Run after changing the synthesizer or a scenario; the test
# ReplayScenario.ShippedRecordingsAreUpToDateWithTheirScenarios says when it is needed.
set -euo pipefail
cd "$(dirname "$0")/.."
CLI="${LOBESKETCH:-./build/release/app/lobesketch}"
for sc in recordings/*.scenario.json; do
  out="${sc%.scenario.json}.lrec"
  "$CLI" synth "$sc" -o "$out"
done
# The demo is the largest Table 1 scene.
ln -sf table1-4lobes-22strokes.lrec recordings/demo.lrec
ln -sf table1-4lobes-22strokes.truth.json recordings/demo.truth.json
