#!/usr/bin/env bash
# L-system rewriting side by side: Lobesketch's engine (tests/bench/lsystem_bench.cpp, Google
# Benchmark) and the npm package lindenmayer (tests/bench/lsystem_lindenmayer.cjs) on the same
# grammars for the same number of steps: the bracketed context-free and the parametric ones
# give the same words in both (their module counts are printed and compared); the stochastic
# one draws other random numbers in each, so its words differ in length and only modules/s
# compare. Each side runs RUNS times (default 9); the table gives medians and the ratio
# lindenmayer time / Lobesketch time for the same modules.
#
# usage: scripts/lsystem-compare.sh [RUNS]     (after scripts/setup.sh: build/release and
#        build/tools/lindenmayer)
set -euo pipefail
cd "$(dirname "$0")/.."

RUNS="${1:-9}"
BENCH="build/release/tests/lobe_bench"
LINDENMAYER_DIR="build/tools/lindenmayer"
[ -x "$BENCH" ] || { echo "lsystem-compare: $BENCH missing: run scripts/setup.sh (or build the release preset's lobe_bench)" >&2; exit 1; }
[ -f "$LINDENMAYER_DIR/node_modules/lindenmayer/package.json" ] || {
  echo "lsystem-compare: $LINDENMAYER_DIR missing: run scripts/setup.sh" >&2; exit 1; }

out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT

"$BENCH" --benchmark_filter='^BM_LSystem(Bracketed|Parametric|Stochastic)(/real_time)?$' \
  --benchmark_repetitions="$RUNS" --benchmark_format=json --benchmark_out="$out/cpp.json" >/dev/null
node tests/bench/lsystem_lindenmayer.cjs "$LINDENMAYER_DIR" "$RUNS" >"$out/js.jsonl"

node - "$out/cpp.json" "$out/js.jsonl" "$RUNS" <<'JS'
const fs = require('fs');
const [cppFile, jsFile, runs] = process.argv.slice(2);
const cpp = JSON.parse(fs.readFileSync(cppFile, 'utf8'));
const js = fs.readFileSync(jsFile, 'utf8').trim().split('\n').map(JSON.parse);
const median = xs => { const s = [...xs].sort((a, b) => a - b), n = s.length;
  return n % 2 ? s[(n - 1) / 2] : (s[n / 2 - 1] + s[n / 2]) / 2; };
const names = {bracketed: 'BM_LSystemBracketed', parametric: 'BM_LSystemParametric', stochastic: 'BM_LSystemStochastic'};
const pad = (s, n) => String(s).padStart(n);
console.log(`L-system rewriting, medians of ${runs} runs each (${require('os').cpus()[0].model}, ${require('os').cpus().length} CPUs)`);
console.log(['grammar', 'steps', 'modules written', 'Lobesketch ms', 'M mod/s', 'lindenmayer ms', 'M mod/s', 'ratio'].map((s, i) => pad(s, [10, 5, 16, 13, 8, 14, 8, 7][i])).join(' '));
let mismatch = false;
for (const j of js) {
  // Per-repetition runs of the benchmark (not its aggregates): their real times, in ms.
  const reps = cpp.benchmarks.filter(b => b.run_name.split('/')[0] === names[j.grammar] && b.run_type === 'iteration');
  if (!reps.length) { console.error(`no C++ runs of ${names[j.grammar]}`); process.exit(1); }
  const ms = median(reps.map(b => b.real_time * ({ns: 1e-6, us: 1e-3, ms: 1, s: 1e3}[b.time_unit])));
  const written = reps[0].modules_written;
  const same = written === j.modules_written && reps[0].modules_final === j.modules_final;
  if (!same && j.grammar !== 'stochastic') mismatch = true;
  const cppRate = written / ms / 1e3, jsRate = j.modules_per_s / 1e6;
  console.log([j.grammar, j.steps, written + (same ? '' : ` / ${j.modules_written}`), ms.toFixed(1), cppRate.toFixed(1),
    j.median_ms.toFixed(1), jsRate.toFixed(1), (cppRate / jsRate).toFixed(2) + 'x']
    .map((s, i) => pad(s, [10, 5, 16, 13, 8, 14, 8, 7][i])).join(' '));
}
console.log('ratio: Lobesketch modules/s over lindenmayer modules/s (for the same words, lindenmayer time / Lobesketch time).');
if (mismatch) { console.error('lsystem-compare: the two derived different words for a deterministic grammar'); process.exit(1); }
JS
