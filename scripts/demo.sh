#!/usr/bin/env bash
# The README's main command: set up, build, and replay the bundled demo recording.
# Writes out/demo/strokes.json, session.json, lobes/lobe_N.ply and tree.glb, and pictures of
# the tree: tree_front.png and tree_side.png (software rendering when there is no GPU).
set -euo pipefail
cd "$(dirname "$0")/.."
# Only the program and what it needs: the tests and benchmarks are test.sh's.
./scripts/setup.sh demo
OUT="${1:-out/demo}"
./build/release/app/lobesketch replay recordings/demo.lrec --out "$OUT"
./build/release/app/lobesketch render "$OUT/tree.glb" --view front --out "$OUT/tree_front.png"
./build/release/app/lobesketch render "$OUT/tree.glb" --view side --out "$OUT/tree_side.png"
echo "demo: results in $OUT"
