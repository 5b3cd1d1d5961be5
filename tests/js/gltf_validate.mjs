// Runs the Khronos glTF-Validator (npm gltf-validator, pinned in package-lock.json) on each
// model named on the command line and prints one JSON object: {"MODEL": [{"code", "severity",
// "pointer", "message"}, ...], ...}, every issue the validator reports (no limit on their
// number). Buffer files are read relative to the model. Exit status 0 unless a file cannot be
// read; test_gltf_diagnostics compares the findings with shadergen's import diagnostics.
//
//   node tests/js/gltf_validate.mjs MODEL.glb [MODEL.gltf ...]
import { readFile } from 'node:fs/promises';
import path from 'node:path';
import * as validator from 'gltf-validator';

const severities = ['error', 'warning', 'information', 'hint'];
const out = {};
for (const file of process.argv.slice(2)) {
  const bytes = new Uint8Array(await readFile(file));
  const report = await validator.validateBytes(bytes, {
    uri: path.basename(file),
    maxIssues: 0,  // 0: every issue
    externalResourceFunction: (uri) => readFile(path.resolve(path.dirname(file), decodeURIComponent(uri))),
  });
  out[file] = report.issues.messages.map((m) => ({
    code: m.code,
    severity: severities[m.severity] ?? String(m.severity),
    pointer: m.pointer ?? '',
    message: m.message,
  }));
}
process.stdout.write(JSON.stringify(out, null, 1) + '\n');
