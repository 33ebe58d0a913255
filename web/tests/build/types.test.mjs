// The front end's message types are generated from the one message schema
// (docs/schema/studio-messages.schema.json, scripts/gen-messages.mjs), so a
// schema and a page that disagree fail the build. Shown here on a copy of
// web/ in a temp dir: the sources as they are type-check; the same sources
// against a schema that renamed a request key the designer sends, or dropped
// a reply field the designer reads, do not.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { cpSync, mkdtempSync, readFileSync, rmSync, symlinkSync, writeFileSync, mkdirSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { dirname, join } from 'node:path';
import { fileURLToPath } from 'node:url';
import { spawnSync } from 'node:child_process';

const web = join(dirname(fileURLToPath(import.meta.url)), '..', '..');
const schemaFile = join(web, '..', 'docs', 'schema', 'studio-messages.schema.json');

/** Copies web/ (sources, generator, tsconfig) and the schema, alters the schema, generates and type-checks. */
function check(alter) {
  const dir = mkdtempSync(join(tmpdir(), 'texel-web-types-'));
  try {
    const w = join(dir, 'web');
    mkdirSync(w);
    for (const p of ['src', 'scripts', 'tsconfig.json', 'vite.config.ts', 'package.json'])
      cpSync(join(web, p), join(w, p), { recursive: true, filter: (s) => !s.includes(`${join('src', 'generated')}`) });
    symlinkSync(join(web, 'node_modules'), join(w, 'node_modules'), 'dir');
    const schema = JSON.parse(readFileSync(schemaFile, 'utf8'));
    alter(schema);
    mkdirSync(join(dir, 'docs', 'schema'), { recursive: true });
    writeFileSync(join(dir, 'docs', 'schema', 'studio-messages.schema.json'), JSON.stringify(schema));
    const gen = spawnSync(process.execPath, ['scripts/gen-messages.mjs'], { cwd: w, encoding: 'utf8' });
    assert.equal(gen.status, 0, gen.stderr);
    const tsc = spawnSync(process.execPath, [join(web, 'node_modules', 'typescript', 'bin', 'tsc'), '--noEmit'], { cwd: w, encoding: 'utf8' });
    return { ok: tsc.status === 0, out: tsc.stdout + tsc.stderr };
  } finally {
    rmSync(dir, { recursive: true, force: true });
  }
}

test('the front end type-checks against the schema as it is', () => {
  const r = check(() => {});
  assert.ok(r.ok, r.out);
});

test('a request key renamed in the schema fails the build', () => {
  // The designer sends match {document, region: 0}.
  const r = check((s) => {
    const m = s.$defs.MatchRequest;
    m.properties.region_index = m.properties.region;
    delete m.properties.region;
    m.required = m.required.map((k) => (k === 'region' ? 'region_index' : k));
  });
  assert.ok(!r.ok, 'tsc passed although the schema renamed match.region');
  assert.match(r.out, /src\/designer\.ts.*region/);
});

test('a reply field dropped from the schema fails the build', () => {
  // The designer shows the match reply's distance_jnd.
  const r = check((s) => {
    delete s.$defs.MatchReply.properties.distance_jnd;
    s.$defs.MatchReply.required = s.$defs.MatchReply.required.filter((k) => k !== 'distance_jnd');
  });
  assert.ok(!r.ok, 'tsc passed although the schema dropped match.distance_jnd');
  assert.match(r.out, /src\/designer\.ts.*distance_jnd/);
});

test('a message type dropped from the schema fails the build', () => {
  const r = check((s) => {
    s.$defs.ClientMessage.oneOf = s.$defs.ClientMessage.oneOf.filter((m) => m.$ref !== '#/$defs/ExperimentStopRequest');
  });
  assert.ok(!r.ok, 'tsc passed although experiment.stop left the schema');
  assert.match(r.out, /src\/experimenter\.ts.*experiment\.stop/);
});
