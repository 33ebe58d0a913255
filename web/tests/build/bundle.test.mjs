// No test hooks in the production bundle (`npm run build`, served by
// `texel studio`): window.__texelStats and its counters exist only in the
// test build (`npm run build:test`, TEXEL_TEST_HOOKS=1) the browser tests use.
// The feel worker and the audio worklet are bundled modules, not code in strings.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { existsSync, readdirSync, readFileSync } from 'node:fs';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';

const web = join(dirname(fileURLToPath(import.meta.url)), '..', '..');
const prod = resolve(web, process.env.TEXEL_WEB_PROD ?? '../build/web');
const testBuild = resolve(web, process.env.TEXEL_WEB ?? '../build/web-test');
const hooks = ['__texelStats', 'designsDrawn', 'pointerToAckMs', 'sliderToRedrawMs', 'lastMapChecksum'];

function scripts(dir) {
  const assets = join(dir, 'assets');
  assert.ok(existsSync(assets), `${assets} is missing: build it first (make web web-test)`);
  return readdirSync(assets)
    .filter((f) => f.endsWith('.js'))
    .map((f) => ({ f, text: readFileSync(join(assets, f), 'utf8') }));
}

test('the production bundle has no test hooks', () => {
  for (const { f, text } of scripts(prod)) for (const h of hooks) assert.ok(!text.includes(h), `${f} contains ${h}`);
});

test('the test build has them (the browser tests read window.__texelStats)', () => {
  assert.ok(scripts(testBuild).some(({ text }) => text.includes('__texelStats')));
});

test('the feel worker and the audio worklet are modules of their own', () => {
  const names = scripts(prod).map(({ f }) => f);
  assert.ok(names.some((f) => f.startsWith('feel-worker-')), names.join(', '));
  assert.ok(names.some((f) => f.startsWith('audio-worklet-')), names.join(', '));
  assert.ok(names.some((f) => f.startsWith('audio2d-worklet-')), names.join(', '));
  for (const { f, text } of scripts(prod))
    assert.ok(!text.includes('registerProcessor') || f.startsWith('audio-worklet-') || f.startsWith('audio2d-worklet-'), f);
});
