#!/usr/bin/env bash
# Measures the size table of docs/export.md ("Sizes"): for the demo recording, the demo as a
# conifer and the Spot reference mesh, the triangles of every level (LOD0-2 and the
# billboard), the bytes of each level written alone (`--lod k`, plain and `--compress`), and
# the whole file plain, `--quantize` and `--compress`. Prints the table rows in Markdown; paste
# them into docs/export.md after the growth or the export changes.
#
#   scripts/export-sizes.sh [LOBESKETCH]
#
# LOBESKETCH defaults to build/release/app/lobesketch. Spot is read from ../shared/data.
set -euo pipefail
cd "$(dirname "$0")/.."
bin="${1:-build/release/app/lobesketch}"
[ -x "$bin" ] || { echo "export-sizes.sh: $bin is not an executable (build it: cmake --build build/release --target lobesketch)" >&2; exit 2; }
spot=../shared/data/models/spot.obj
[ -f "$spot" ] || spot="$(find ../shared/data -name 'spot*.obj' | head -n 1)"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT

# Triangles per mesh of a .glb, summed over the mesh's primitives (mode 4, indexed).
triangles() {
  python3 - "$1" <<'EOF'
import json, struct, sys
data = open(sys.argv[1], 'rb').read()
length = struct.unpack_from('<I', data, 12)[0]
doc = json.loads(data[20:20 + length])
for mesh in doc['meshes']:
    n = sum(doc['accessors'][p['indices']]['count'] // 3 for p in mesh['primitives'])
    print(mesh['name'], n)
EOF
}
bytes() { stat -c %s "$1"; }
mb() { awk -v b="$1" 'BEGIN { if (b >= 1e6) printf "%.2f MB", b / 1e6; else printf "%.0f KB", b / 1e3 }'; }
pct() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.1f %%", 100 * a / b }'; }
fmt() { echo "$1" | sed ':a;s/\B[0-9]\{3\}\>/,&/;ta'; }

row() { # NAME INPUT [OPTIONS...]
  local name="$1" input="$2"; shift 2
  "$bin" grow "$input" "$@" -q --out "$tmp/t.glb"
  local t0 t1 t2 tb
  t0=$(triangles "$tmp/t.glb" | awk '$1 ~ /_LOD0$/ && $1 !~ /billboard/ { s += $2 } END { print s }')
  t1=$(triangles "$tmp/t.glb" | awk '$1 ~ /_LOD1$/ && $1 !~ /billboard/ { s += $2 } END { print s }')
  t2=$(triangles "$tmp/t.glb" | awk '$1 ~ /_LOD2$/ && $1 !~ /billboard/ { s += $2 } END { print s }')
  tb=$(triangles "$tmp/t.glb" | awk '$1 ~ /billboard/ { s += $2 } END { print s + 0 }')
  local all quant comp levels=""
  all=$(bytes "$tmp/t.glb")
  "$bin" grow "$input" "$@" -q --quantize --out "$tmp/t.glb"; quant=$(bytes "$tmp/t.glb")
  "$bin" grow "$input" "$@" -q --compress --out "$tmp/t.glb"; comp=$(bytes "$tmp/t.glb")
  for k in 0 1 2 3; do
    "$bin" grow "$input" "$@" -q --lod "$k" --out "$tmp/t.glb"; local p; p=$(bytes "$tmp/t.glb")
    "$bin" grow "$input" "$@" -q --lod "$k" --compress --out "$tmp/t.glb"; local c; c=$(bytes "$tmp/t.glb")
    levels="$levels | $(mb "$p") ($(mb "$c"))"
  done
  echo "| $name | $(fmt "$t0") | $(fmt "$t1") ($(pct "$t1" "$t0")) | $(fmt "$t2") ($(pct "$t2" "$t0")) | $tb$levels | $(mb "$all") | $(mb "$quant") | $(mb "$comp") |"
}

echo "| tree | LOD0 tris | LOD1 | LOD2 | billboard | LOD0 bytes (compressed) | LOD1 | LOD2 | LOD3 = billboard | all | all \`--quantize\` | all \`--compress\` |"
echo "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"
row demo recordings/demo.lrec
row "demo \`--species conifer\`" recordings/demo.lrec --species conifer
row "demo \`--height 8\`" recordings/demo.lrec --height 8
row "Spot (mesh lobe)" "$spot"
