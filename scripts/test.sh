#!/usr/bin/env bash
# The README's test command: set up, build, and run the whole test suite, first optimised,
# then under AddressSanitizer + UndefinedBehaviorSanitizer, then every fuzz target of that
# build for 15 seconds (docs/fuzzing.md). In between, the two builds (GCC -O3 and Clang -O1)
# must replay the shipped recordings to the same bytes.
set -euo pipefail
cd "$(dirname "$0")/.."
JOBS="$(nproc)"

./scripts/setup.sh release --blender
ctest --preset release -j "$JOBS"

cmake --preset asan >/dev/null
cmake --build --preset asan
ctest --preset asan -j "$JOBS"

# The application is a function of the hand stream (DESIGN.md), whichever compiler built it:
# lobes, their remeshing, the tree and the session, byte for byte; and so is every grower.
replays="$(mktemp -d)"
trap 'rm -rf "$replays"' EXIT
for rec in recordings/*.lrec; do
  name="$(basename "$rec" .lrec)"
  for build in release asan; do
    "./build/$build/app/lobesketch" replay "$rec" --out "$replays/$build/$name" >/dev/null
  done
done
# The other growers too: a self-organizing tree in the demo's lobes, a stochastic L-system and
# a sketched one.
for build in release asan; do
  "./build/$build/app/lobesketch" grow recordings/demo.lrec --grower self-organizing \
    --out "$replays/$build/demo-self-organizing.glb" >/dev/null
  "./build/$build/app/lobesketch" lsystem willow --seed 5 --out "$replays/$build/willow.glb" >/dev/null
  # A sketched L-system tree: the live mode's recording replayed, its rules, sketch and tree.
  "./build/$build/app/lobesketch" lsystem --sketch recordings/lsystem-sketch/maple.lrec --growth 14 \
    --rules-out "$replays/$build/maple-sketch.l" --sketch-out "$replays/$build/maple-sketch.json" \
    --out "$replays/$build/maple-sketch.glb" >/dev/null 2>&1
done
diff -r "$replays/release" "$replays/asan" >/dev/null ||
  { echo "the release and asan builds replay a recording to different bytes:" >&2; diff -rq "$replays/release" "$replays/asan" >&2; exit 1; }
echo "release and asan builds: every recording replays to the same bytes, and the other growers grow the same trees"

# Blender imports every level of an exported tree (LOD0-2 and the billboard, plain and
# quantized, and the OBJ levels) with the triangles the file holds (docs/export.md).
exports="$(mktemp -d)"
trap 'rm -rf "$replays" "$exports"' EXIT
./build/release/app/lobesketch grow recordings/demo.lrec --out "$exports/demo.glb" -q
mkdir -p "$exports/quantized"
./build/release/app/lobesketch grow recordings/demo.lrec --quantize --out "$exports/quantized/demo.glb" -q
./build/release/app/lobesketch grow recordings/demo.lrec --lod all --out "$exports/demo.obj" -q
./scripts/blender-import.sh "$exports/demo.glb" "$exports/quantized/demo.glb" "$exports"/demo*.obj

./scripts/fuzz.sh 15
