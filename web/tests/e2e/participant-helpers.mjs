// Helpers of the participant-screen tests (participant.test.mjs in Chromium,
// participant-firefox.test.mjs in Firefox, participant-2d.test.mjs).
import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import { mkdtempSync, readFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { paths } from './studio.mjs';

/** The store's trials as `texel experiment export` writes them (CSV rows as objects). */
export function exportRows(db) {
  const out = join(mkdtempSync(join(tmpdir(), 'texel-export-')), 'x.csv');
  const r = spawnSync(paths.bin, ['experiment', 'export', '--db', db, '-o', out], { encoding: 'utf8' });
  assert.equal(r.status, 0, r.stderr);
  const [head, ...lines] = readFileSync(out, 'utf8').trim().split('\n');
  const cols = head.split(',');
  return lines.map((l) => Object.fromEntries(l.split(',').map((v, i) => [cols[i], v])));
}

/**
 * Sends messages one after another from `page` over a WebSocket of its own
 * (the experimenter's side); resolves their replies, matched by id (the
 * session state the service pushes to every client is skipped).
 */
export function control(page, ...msgs) {
  return page.evaluate(async (msgs) => {
    const ws = new WebSocket(`ws://${location.host}/ws`);
    await new Promise((r) => (ws.onopen = r));
    const out = [];
    for (const [i, m] of msgs.entries()) {
      out.push(
        await new Promise((res) => {
          ws.onmessage = (e) => {
            const r = JSON.parse(e.data);
            if (r.id === 1000 + i) res(r);
          };
          ws.send(JSON.stringify({ id: 1000 + i, ...m }));
        }),
      );
    }
    ws.close();
    return out;
  }, msgs);
}

/**
 * A script to run before the page's own (addInitScript / evaluateOnNewDocument):
 * with window.__dropPushes set, the page's WebSocket drops the service's
 * pushes (messages with id null) — a screen that missed them, the situation
 * of issue #22.
 */
export const STALE_HOOK = `(() => {
  const Native = window.WebSocket;
  window.WebSocket = class extends Native {
    set onmessage(fn) {
      super.onmessage = (ev) => {
        if (window.__dropPushes) {
          try { if (JSON.parse(ev.data).id === null) return; } catch {}
        }
        fn(ev);
      };
    }
    get onmessage() { return super.onmessage; }
  };
})();`;
