// Validates a glTF file with the Khronos glTF Validator (npm: gltf-validator); prints the issues as JSON.
const fs = require('fs'); const path = require('path');
const validator = require('gltf-validator');
const file = process.argv[2];
validator.validateBytes(new Uint8Array(fs.readFileSync(file)), {
  uri: path.basename(file), maxIssues: 50,
  externalResourceFunction: (uri) => new Promise((res, rej) => fs.readFile(path.resolve(path.dirname(file), decodeURIComponent(uri)), (e, d) => e ? rej(e.toString()) : res(new Uint8Array(d)))),
}).then((r) => console.log(JSON.stringify(r.issues))).catch((e) => { console.error(e); process.exit(1); });
