// Validate glTF files with the Khronos glTF-Validator; print one JSON report per file.
// usage: node tools/node/validate.js FILE.glb [...]
const fs = require("fs");
const validator = require("gltf-validator");

async function main(files) {
  for (const file of files) {
    const data = new Uint8Array(fs.readFileSync(file));
    const report = await validator.validateBytes(data, { maxIssues: 100 });
    console.log(JSON.stringify({ file, issues: report.issues }));
  }
}
main(process.argv.slice(2)).catch((err) => { console.error(String(err)); process.exit(1); });
