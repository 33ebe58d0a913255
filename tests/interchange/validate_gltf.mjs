// Validates glTF assets with Khronos' glTF-Validator (npm gltf-validator).
// Usage: node validate_gltf.mjs WEB_DIR FILE...
// Exit 1 when a report has any message other than UNSUPPORTED_EXTENSION for
// the MPEG extensions Texel writes (the validator does not know them).
import { readFileSync } from 'node:fs';
import { createRequire } from 'node:module';
import { basename, join } from 'node:path';

const [web, ...files] = process.argv.slice(2);
const require = createRequire(join(web, 'package.json'));
const validator = require('gltf-validator');
const mpeg = new Set(['MPEG_media', 'MPEG_haptic', 'MPEG_haptic_material']);
let bad = 0;
for (const file of files) {
  const report = await validator.validateBytes(new Uint8Array(readFileSync(file)), {
    uri: basename(file),
    maxIssues: 0,
    format: file.endsWith('.glb') ? 'glb' : 'gltf',
    externalResourceFunction: (uri) => Promise.reject(new Error(`unexpected external resource ${uri}`)),
  });
  const unexpected = report.issues.messages.filter(
    (m) => !(m.code === 'UNSUPPORTED_EXTENSION' && [...mpeg].some((e) => m.message.includes(e))));
  const unknown = report.issues.messages.length - unexpected.length;
  console.log(`${file}: ${report.issues.numErrors} errors, ${report.issues.numWarnings} warnings, ` +
              `${report.issues.numInfos} infos, ${report.issues.numHints} hints; ${unknown} unknown MPEG extensions`);
  for (const m of unexpected) console.log(`  ${['error', 'warning', 'info', 'hint'][m.severity]} ${m.code} ${m.pointer ?? ''}: ${m.message}`);
  if (report.issues.numErrors > 0 || unexpected.length > 0) bad++;
}
process.exit(bad ? 1 : 0);
