#!/usr/bin/env bash
# The README's main command: set up, build, and replay the bundled demo recording.
# Writes out/demo/strokes.json, session.json, lobes/lobe_N.ply and tree.glb.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/setup.sh release
OUT="${1:-out/demo}"
./build/release/app/lobesketch replay recordings/demo.lrec --out "$OUT"
echo "demo: results in $OUT"
