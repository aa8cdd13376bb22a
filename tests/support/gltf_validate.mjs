// Runs the Khronos glTF validator (npm package gltf-validator, installed by scripts/setup.sh
// into build/tools/gltf-validator) on one .glb/.gltf file.
//
//   node tests/support/gltf_validate.mjs [--validator DIR] [--summary] FILE
//
// Prints the validator's report as JSON (with --summary: one line of counts instead).
// Exit status: 0 when the report has no errors, 1 when it has (a one-line summary goes to
// stderr), 2 when the file or the validator cannot be read.
// DIR is the npm prefix the validator was installed into; default: $GLTF_VALIDATOR_DIR, else
// build/tools/gltf-validator of this project.
import { readFileSync } from 'node:fs';
import { createRequire } from 'node:module';
import { basename, dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';

const here = dirname(fileURLToPath(import.meta.url));
let validatorDir = process.env.GLTF_VALIDATOR_DIR || join(here, '..', 'build', 'tools', 'gltf-validator');
let summaryOnly = false;
let file = null;
const args = process.argv.slice(2);
for (let i = 0; i < args.length; ++i) {
  if (args[i] === '--validator' && i + 1 < args.length) validatorDir = args[++i];
  else if (args[i] === '--summary') summaryOnly = true;
  else if (file === null && !args[i].startsWith('--')) file = args[i];
  else {
    console.error(`gltf_validate: unexpected argument ${args[i]}`);
    process.exit(2);
  }
}
if (file === null) {
  console.error('usage: node tests/support/gltf_validate.mjs [--validator DIR] [--summary] FILE');
  process.exit(2);
}

let validator;
try {
  validator = createRequire(join(resolve(validatorDir), 'package.json'))('gltf-validator');
} catch (e) {
  console.error(`gltf_validate: gltf-validator not found under ${validatorDir}: run scripts/setup.sh`);
  process.exit(2);
}

let bytes;
try {
  bytes = new Uint8Array(readFileSync(file));
} catch (e) {
  console.error(`${file}: ${e.message}`);
  process.exit(2);
}

let report;
try {
  report = await validator.validateBytes(bytes, { uri: basename(file), maxIssues: 0, writeTimestamp: false });
} catch (e) {
  console.error(`${file}: the validator could not read the file: ${e}`);
  process.exit(2);
}

const n = report.issues;
const summary = `${file}: ${n.numErrors} errors, ${n.numWarnings} warnings, ${n.numInfos} infos, ` +
  `${n.numHints} hints (gltf-validator ${validator.version()})`;
console.log(summaryOnly ? summary : JSON.stringify(report, null, 2));
if (n.numErrors > 0) {
  console.error(summary);
  process.exitCode = 1; // not process.exit(): that could cut a long report short on a pipe
}
