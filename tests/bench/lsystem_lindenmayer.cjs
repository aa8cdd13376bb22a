// The grammars of tests/bench/lsystem_bench.cpp in the npm package `lindenmayer`
// (scripts/setup.sh installs it into build/tools/lindenmayer), for
// scripts/lsystem-compare.sh: each derived RUNS times; prints one JSON line per grammar with
// the median time and the modules written (the sum of the word's length after every step,
// as the C++ benchmark counts them).
//
// usage: node tests/bench/lsystem_lindenmayer.cjs LINDENMAYER_DIR [RUNS]
'use strict';
const path = require('path');

const dir = process.argv[2];
const runs = Number(process.argv[3] || 7);
if (!dir) {
  console.error('usage: node lsystem_lindenmayer.cjs LINDENMAYER_DIR [RUNS]');
  process.exit(2);
}
const LSystem = require(path.resolve(dir, 'node_modules/lindenmayer'));

// The Algorithmic Beauty of Plants, Fig. 1.24d (the C++ file's kBracketed): strings.
function bracketed() {
  return new LSystem({axiom: 'X', productions: {X: 'F[+X]F[-X]+X', F: 'FF'}});
}

// The C++ file's kParametric: modules as {symbol, params} objects, productions as a
// condition and a successor function each (lindenmayer's parametric form).
function parametric() {
  const m = (symbol, ...params) => ({symbol, params});
  return new LSystem({
    axiom: [m('A', 1, 1)],
    productions: {
      A: {
        successors: [
          {
            condition: ({part}) => part.params[0] >= 0.2,
            successor: ({part}) => {
              const [l, w] = part.params;
              return [m('!', w), m('F', l), m('['), m('+', 30), m('A', l * 0.8, w * 0.7), m(']'), m('/', 137.5),
                m('['), m('-', 30), m('A', l * 0.9, w * 0.7), m(']')];
            },
          },
          {
            condition: ({part}) => part.params[0] < 0.2,
            successor: ({part}) => {
              const [l, w] = part.params;
              return [m('!', w), m('F', l), m('/', 90), m('A', l * 4, w)];
            },
          },
        ],
      },
      F: {condition: ({part}) => part.params[0] < 10, successor: ({part}) => m('F', part.params[0] * 1.02)},
    },
  });
}

// The Algorithmic Beauty of Plants, Fig. 1.27 (the C++ file's kStochastic): weights.
function stochastic() {
  return new LSystem({
    axiom: 'F',
    productions: {
      F: {
        successors: [
          {weight: 33, successor: 'F[+F]F[-F]F'},
          {weight: 33, successor: 'F[+F]F'},
          {weight: 34, successor: 'F[-F]F'},
        ],
      },
    },
  });
}

const grammars = [
  {name: 'bracketed', make: bracketed, steps: 12},
  {name: 'parametric', make: parametric, steps: 18},
  {name: 'stochastic', make: stochastic, steps: 10},
];

function median(xs) {
  const s = [...xs].sort((a, b) => a - b);
  const n = s.length;
  return n % 2 ? s[(n - 1) / 2] : (s[n / 2 - 1] + s[n / 2]) / 2;
}

for (const g of grammars) {
  // The modules written, counted once outside the timed runs.
  const counted = g.make();
  let written = 0;
  for (let i = 0; i < g.steps; ++i) written += counted.iterate(1).length;
  const finalSize = counted.getRaw().length;

  const times = [];
  const writtenPerRun = [];
  for (let r = 0; r < runs; ++r) {
    const ls = g.make();
    const t0 = process.hrtime.bigint();
    const word = ls.iterate(g.steps);
    // A string word is a rope until read: reading one character flattens it, so the time
    // includes a word as usable as the C++ one.
    if (typeof word === 'string') word.charCodeAt(word.length >> 1);
    const t1 = process.hrtime.bigint();
    times.push(Number(t1 - t0) / 1e6);
    writtenPerRun.push(word.length);
  }
  const ms = median(times);
  console.log(JSON.stringify({
    grammar: g.name, steps: g.steps, runs, median_ms: ms, min_ms: Math.min(...times), max_ms: Math.max(...times),
    modules_final: finalSize, modules_written: written, modules_per_s: written / (ms / 1000),
  }));
}
