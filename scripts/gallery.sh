#!/usr/bin/env bash
# Draws the gallery (docs/gallery.md): the tree of every shipped recording (recordings/*.lrec,
# grown as `lobesketch grow` grows it: the session's settings, sketch size), from the front
# and from the side, with and without its lobes, with `lobesketch render`; then writes
# docs/gallery.md beside the pictures (docs/images/gallery/). Run it again after the growth
# changes; it replaces every picture and the page.
#
#   scripts/gallery.sh [LOBESKETCH] [SIZE]
#
# LOBESKETCH defaults to build/release/app/lobesketch, SIZE (WxH) to 480x360.
set -euo pipefail
cd "$(dirname "$0")/.."
bin="${1:-build/release/app/lobesketch}"
size="${2:-480x360}"
[ -x "$bin" ] || { echo "gallery.sh: $bin is not an executable (build it: cmake --build build/release --target lobesketch)" >&2; exit 2; }
out=docs/images/gallery
rm -rf "$out"
mkdir -p "$out"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT

page=docs/gallery.md
{
  echo "# Gallery"
  echo
  echo "The tree of every shipped recording (\`recordings/*.lrec\`), grown with the recording's own"
  echo "settings at the size it was sketched, drawn by \`lobesketch render\` from the front (looking"
  echo "along −Z) and from the side (along −X), without and with its lobes."
  echo "Made by \`scripts/gallery.sh\` ($("$bin" --version 2>/dev/null | head -n 1 || true)); run it again to refresh"
  echo "the pictures after the growth changes. Species at real scale: [growth.md](growth.md#species-form)."
  echo
} > "$page"

for rec in recordings/*.lrec; do
  n="$(basename "$rec" .lrec)"
  echo "gallery: $n" >&2
  for view in front side; do
    "$bin" render "$rec" --view "$view" --size "$size" --show tree,leaves --out "$out/$n-$view.png" -q
    "$bin" render "$rec" --view "$view" --size "$size" --show tree,leaves,lobes --out "$out/$n-$view-lobes.png" -q
  done
  nodes="$("$bin" grow "$rec" --out "$tmp/t.glb" 2>&1 | sed -n 's/^.*grew \([0-9]*\) nodes.*$/\1/p' | head -n 1)"
  {
    echo "## $n"
    echo
    echo "\`$rec\`${nodes:+: $nodes nodes}."
    echo
    echo "| front | side | front, lobes | side, lobes |"
    echo "| --- | --- | --- | --- |"
    echo "| ![$n front](images/gallery/$n-front.png) | ![$n side](images/gallery/$n-side.png) | ![$n front with lobes](images/gallery/$n-front-lobes.png) | ![$n side with lobes](images/gallery/$n-side-lobes.png) |"
    echo
  } >> "$page"
done
echo "gallery: wrote $page and $(ls "$out" | wc -l) pictures in $out" >&2
