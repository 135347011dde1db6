// Validates glTF files with the Khronos glTF Validator (npm `gltf-validator`) and prints, for
// each, one JSON object: the file, the report's error, warning, info and hint counts and every
// message (code, severity, pointer, text). Exits 0 when no file has an error, 1 when one has,
// 2 on a usage or read failure.
//
//   node tools/gltf-validate/validate.mjs out_yaw0.glb out_yaw90.glb
//
// External resources (a .gltf's buffers) are read from beside the file, as a viewer would.
import { readFile } from "node:fs/promises";
import { dirname, join } from "node:path";
import validator from "gltf-validator";

const SEVERITIES = ["error", "warning", "info", "hint"];

async function validate(path) {
  const bytes = new Uint8Array(await readFile(path));
  const report = await validator.validateBytes(bytes, {
    uri: path,
    maxIssues: 0,
    writeTimestamp: false,
    externalResourceFunction: async (uri) =>
      new Uint8Array(await readFile(join(dirname(path), decodeURIComponent(uri)))),
  });
  const issues = report.issues;
  return {
    file: path,
    errors: issues.numErrors,
    warnings: issues.numWarnings,
    infos: issues.numInfos,
    hints: issues.numHints,
    messages: issues.messages.map((m) => ({
      code: m.code,
      severity: SEVERITIES[m.severity] ?? String(m.severity),
      pointer: m.pointer ?? null,
      message: m.message,
    })),
  };
}

const files = process.argv.slice(2);
if (files.length === 0) {
  console.error("usage: node validate.mjs FILE.glb|FILE.gltf ...");
  process.exit(2);
}
let failed = false;
for (const file of files) {
  try {
    const result = await validate(file);
    failed ||= result.errors > 0;
    console.log(JSON.stringify(result));
  } catch (e) {
    console.error(`${file}: ${e.message ?? e}`);
    process.exit(2);
  }
}
process.exit(failed ? 1 : 0);
