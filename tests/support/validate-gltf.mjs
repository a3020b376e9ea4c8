// Runs the Khronos glTF validator (npm package `gltf-validator`) on the files given as
// arguments and prints one JSON line per file: {file, errors, warnings, infos, messages}.
//
// The package is looked up in $GLTF_VALIDATOR_DIR (an `npm install --prefix` directory) first,
// then through ordinary node_modules resolution. Exit codes: 0 = all files validated (read the
// counts), 3 = validator package not found (callers treat that as "skip"), 1 = other failure.
import { createRequire } from "node:module";
import { readFileSync } from "node:fs";
import path from "node:path";

function loadValidator() {
  const bases = [];
  if (process.env.GLTF_VALIDATOR_DIR) {
    bases.push(path.join(path.resolve(process.env.GLTF_VALIDATOR_DIR), "package.json"));
  }
  bases.push(import.meta.url);
  for (const base of bases) {
    try {
      return createRequire(base)("gltf-validator");
    } catch {
      // try the next place
    }
  }
  return null;
}

const validator = loadValidator();
if (!validator) {
  console.error("gltf-validator not found (set GLTF_VALIDATOR_DIR)");
  process.exit(3);
}

try {
  for (const file of process.argv.slice(2)) {
    const dir = path.dirname(path.resolve(file));
    const report = await validator.validateBytes(new Uint8Array(readFileSync(file)), {
      uri: path.basename(file),
      // Every issue counted: patched avatars carry hundreds of hints, which must not hide a
      // warning behind the cut.
      maxIssues: 0,
      // A `.gltf`'s buffers and images are read beside it, as a loader would (a file that is
      // not there is the validator's IO_ERROR).
      externalResourceFunction: (uri) =>
        new Promise((resolve, reject) => {
          try {
            resolve(new Uint8Array(readFileSync(path.resolve(dir, decodeURIComponent(uri)))));
          } catch (e) {
            reject(`${uri}: ${e.message}`);
          }
        }),
    });
    const issues = report.issues;
    console.log(
      JSON.stringify({
        file,
        errors: issues.numErrors,
        warnings: issues.numWarnings,
        infos: issues.numInfos,
        messages: issues.messages.map((m) => `${m.severity} ${m.code} ${m.pointer ?? ""}: ${m.message}`),
      }),
    );
  }
} catch (e) {
  console.error(`validation failed: ${e}`);
  process.exit(1);
}
