// Validates a .glb with the Khronos glTF validator and prints its JSON report on stdout.
// Usage: node tools/validate_gltf.mjs FILE.glb   (exit 0 when it has 0 errors, 1 otherwise)
import { readFile } from 'node:fs/promises';
import { createRequire } from 'node:module';

const require = createRequire(import.meta.url);
const validator = require('gltf-validator');

const path = process.argv[2];
const data = new Uint8Array(await readFile(path));
const report = await validator.validateBytes(data, { maxIssues: 100, uri: path });
console.log(JSON.stringify(report, null, 1));
process.exit(report.issues.numErrors === 0 ? 0 : 1);
