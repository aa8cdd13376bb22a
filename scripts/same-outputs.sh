#!/usr/bin/env bash
# Shows that two builds of lobesketch give a user the same files: every shipped recording
# replayed (strokes, session, lobes, .glb), fed through the live VR session (`sketch`, with
# and without its event track), exported again from its session; the demo's pictures; grown
# from a model and with other options (.glb and .obj); lobes alone; the synthesizer's
# recordings from the shipped scenarios; and the two desktop test scripts run in a window
# under Xvfb (session, autosaves, recording, export, script log). Timing lines and absolute
# paths aside, the two sets of outputs must be equal byte for byte.
#
#   scripts/same-outputs.sh OLD_LOBESKETCH NEW_LOBESKETCH [WORK_DIR]
#
# e.g. after a refactoring: build the commit before it into another folder, then
#   scripts/same-outputs.sh ../before/build/release/app/lobesketch build/release/app/lobesketch
set -uo pipefail
cd "$(dirname "$0")/.."
[ $# -ge 2 ] || { sed -n '2,13p' "$0" >&2; exit 2; }
old="$(realpath "$1")" new="$(realpath "$2")"
work="${3:-$(mktemp -d)}"
mkdir -p "$work"

capture() { # BIN OUT
  local bin="$1" out="$2" rec n s
  rm -rf "$out"
  mkdir -p "$out/export" "$out/render" "$out/grow" "$out/synth"
  for rec in recordings/*.lrec; do
    n="$(basename "$rec" .lrec)"
    mkdir -p "$out/sketch/$n" "$out/sketch-events/$n"
    "$bin" replay "$rec" --out "$out/replay/$n" >/dev/null 2>"$out/replay-$n.err"
    "$bin" sketch "$rec" --session "$out/sketch/$n/session.json" \
      --record "$out/sketch/$n/rec.lrec" --inline-regrowth >/dev/null 2>&1
    "$bin" sketch "$rec" --events-from-recording --session "$out/sketch-events/$n/session.json" \
      --inline-regrowth >/dev/null 2>&1
    "$bin" export "$out/replay/$n/session.json" --out "$out/export/$n.glb" >/dev/null 2>&1
  done
  "$bin" render "$out/replay/demo/tree.glb" --view front --out "$out/render/demo_front.png" >/dev/null 2>&1
  "$bin" render "$out/replay/demo/tree.glb" --view side --out "$out/render/demo_side.png" >/dev/null 2>&1
  "$bin" render recordings/pinch-edit.lrec --show tree,leaves,lobes,strokes --out "$out/render/pinch.png" >/dev/null 2>&1
  [ -f ../shared/data/models/stanford-bunny.obj ] &&
    "$bin" grow ../shared/data/models/stanford-bunny.obj --out "$out/grow/bunny.glb" >/dev/null 2>&1
  "$bin" grow recordings/demo.lrec --species conifer --seed 7 --out "$out/grow/demo-conifer.glb" >/dev/null 2>&1
  "$bin" grow recordings/demo.lrec --out "$out/grow/demo.obj" >/dev/null 2>&1
  "$bin" grow recordings/demo.lrec --out "$out/grow/demo-all.obj" --lod all --bark-normal-map >/dev/null 2>&1
  "$bin" grow recordings/demo.lrec --out "$out/grow/demo-compressed.glb" --compress --bark-normal-map \
    --texture-size 256 --billboard 512 >/dev/null 2>&1
  "$bin" grow recordings/demo.lrec --out "$out/grow/demo-quantized.glb" --quantize >/dev/null 2>&1
  "$bin" lobes recordings/table1-3lobes-16strokes.lrec --out "$out/lobes" >/dev/null 2>&1
  for s in recordings/*.scenario.json; do
    n="$(basename "$s" .scenario.json)"
    "$bin" synth "$s" -o "$out/synth/$n.lrec" >/dev/null 2>&1
  done
  if command -v xvfb-run >/dev/null; then
    for s in tests/data/desktop_every_tool.script tests/data/desktop_save.script; do
      n="$(basename "$s" .script)"
      mkdir -p "$out/desktop/$n"
      xvfb-run -a -s "-screen 0 800x600x24" "$bin" desktop "$out/desktop/$n/session.json" --script "$s" \
        --script-log "$out/desktop/$n/log.jsonl" --record "$out/desktop/$n/rec.lrec" \
        --export "$out/desktop/$n/tree.glb" --size 720x360 >/dev/null 2>"$out/desktop/$n.err"
    done
  fi
  # The output folder's own path is written into sessions and messages: made relative.
  grep -rl --include="*.json" --include="*.jsonl" --include="*.err" --include="*.json.1" "$out" "$out" 2>/dev/null |
    while read -r f; do sed -i "s#$out#OUT#g" "$f"; done
}

capture "$old" "$work/old"
capture "$new" "$work/new"
if diff -r -I 'frames in .* s; frame' -I 'median .* ms' "$work/old" "$work/new"; then
  echo "same outputs: $(find "$work/new" -type f | wc -l) files"
else
  echo "the outputs differ (kept in $work)" >&2
  exit 1
fi
