// Validates each GLB file named on the command line with the Khronos glTF
// validator and prints one JSON line per file: its path, the validator's
// version, and the numbers and codes of errors, warnings, infos and hints.
"use strict";
const fs = require("fs");
const validator = require("gltf-validator");

async function check(path) {
  const data = new Uint8Array(fs.readFileSync(path));
  const report = await validator.validateBytes(data, {
    maxIssues: 0,
    externalResourceFunction: () => Promise.reject(new Error("no external resources")),
  });
  const issues = report.issues;
  const codes = (severity) => {
    const seen = {};
    for (const m of issues.messages) {
      if (m.severity === severity) seen[m.code] = (seen[m.code] || 0) + 1;
    }
    return seen;
  };
  return {
    path,
    validator: report.validatorVersion,
    errors: issues.numErrors,
    warnings: issues.numWarnings,
    infos: issues.numInfos,
    hints: issues.numHints,
    error_codes: codes(0),
    warning_codes: codes(1),
    info_codes: codes(2),
    first: issues.messages.slice(0, 5).map((m) => `${m.code} ${m.pointer || ""}: ${m.message}`),
  };
}

(async () => {
  for (const path of process.argv.slice(2)) {
    try {
      console.log(JSON.stringify(await check(path)));
    } catch (e) {
      console.log(JSON.stringify({ path, failure: String(e) }));
    }
  }
})();
