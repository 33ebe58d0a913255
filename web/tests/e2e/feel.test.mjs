// Feel it: a mouse sweep and a touch sweep over the strip reach the engine's
// player (null backend), whose reported position (#player-position, polled
// from feel.state) follows the pointer.
//
// The sweeps move at a hand's pace (~1 mm per 10 ms). The player extrapolates
// up to 30 ms past its newest sample at the finger's last velocity
// (PlayerConfig::extrapolate_s) and holds there once samples stop, so the
// reported position may lead the last pointer sample by ~velocity × 30 ms:
// the tolerance (3 mm) allows for it.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { withStudio, openDesigner, screenshot } from './studio.mjs';

const TPAD_MM = 19200 * 0.0053;
const TOL_MM = 3;

async function stripBox(page) {
  await page.locator('[data-testid=feel-strip]').scrollIntoViewIfNeeded();
  const b = await page.locator('[data-testid=feel-strip]').boundingBox();
  assert.ok(b && b.width > 100, 'the strip is visible');
  return b;
}

async function waitPlayerAt(page, mm) {
  await page.waitForFunction(
    ([want, tol]) => {
      const el = document.querySelector('#player-position');
      return el?.dataset.mm !== '' && Math.abs(Number(el.dataset.mm) - want) <= tol;
    },
    [mm, TOL_MM],
    { timeout: 10_000 },
  );
  return Number(await page.getAttribute('#player-position', 'data-mm'));
}

/** Moves from fraction f0 to f1 of the strip in ~1 mm steps; `move(x)` sends one sample at client x. */
async function sweep(page, b, f0, f1, move) {
  const steps = Math.max(1, Math.round(Math.abs(f1 - f0) * TPAD_MM));
  for (let k = 1; k <= steps; k++) {
    await move(b.x + 2 + (f0 + ((f1 - f0) * k) / steps) * (b.width - 4));
    await page.waitForTimeout(10);
  }
  return ((2 + f1 * (b.width - 4)) / b.width) * TPAD_MM;
}

test('feel: a mouse sweep reaches the player', { timeout: 120_000 }, async () => {
  await withStudio(async ({ studio, page, errors }) => {
    await openDesigner(page, studio.url);
    // Browser audio on (AudioWorklet; headless Chromium plays to a null sink).
    await page.check('#hear-it');
    const b = await stripBox(page);
    const y = b.y + b.height / 2;
    // Hovering counts as touch for a mouse (feel.ts); the sweep goes left to right.
    await page.mouse.move(b.x + 2 + 0.1 * (b.width - 4), y);
    const seen = [];
    let f = 0.1;
    for (const g of [0.3, 0.5, 0.7, 0.9]) {
      const want = await sweep(page, b, f, g, (x) => page.mouse.move(x, y));
      f = g;
      seen.push(await waitPlayerAt(page, want));
    }
    for (let i = 1; i < seen.length; i++) assert.ok(seen[i] > seen[i - 1], `positions increase: ${seen.join(', ')}`);
    await page.waitForFunction(() => document.querySelector('#player-position').dataset.touching === 'true');
    await screenshot(page, 'feel-mouse');
    assert.ok(await page.isChecked('#hear-it'), 'Hear it stayed on (the worklet started)');
    assert.equal(await page.textContent('[data-testid=designer-status]'), '');
    // Leaving the strip lifts the finger.
    await page.mouse.move(b.x + b.width / 2, b.y - 200);
    await page.waitForFunction(() => document.querySelector('#player-position').dataset.touching === 'false', null, { timeout: 10_000 });
    const s = await page.evaluate(() => window.__texelStats);
    assert.ok(s.feelAcks > 0 && s.feelAcks <= s.feelMovesSent, `acks ${s.feelAcks} of ${s.feelMovesSent}`);
    assert.deepEqual(errors, []);
  });
});

test('feel: a touch sweep reaches the player', { timeout: 120_000 }, async () => {
  await withStudio(
    async ({ studio, page, context, errors }) => {
      await openDesigner(page, studio.url);
      const b = await stripBox(page);
      const y = Math.round(b.y + b.height / 2);
      const cdp = await context.newCDPSession(page);
      const touch = (type, x) => cdp.send('Input.dispatchTouchEvent', { type, touchPoints: x === undefined ? [] : [{ x: Math.round(x), y }] });
      await touch('touchStart', b.x + 2 + 0.8 * (b.width - 4));
      const seen = [await waitPlayerAt(page, ((2 + 0.8 * (b.width - 4)) / b.width) * TPAD_MM)];
      let f = 0.8;
      for (const g of [0.6, 0.4, 0.2]) {
        const want = await sweep(page, b, f, g, (x) => touch('touchMove', x));
        f = g;
        seen.push(await waitPlayerAt(page, want));
      }
      await page.waitForFunction(() => document.querySelector('#player-position').dataset.touching === 'true');
      await screenshot(page, 'feel-touch');
      await touch('touchEnd');
      await page.waitForFunction(() => document.querySelector('#player-position').dataset.touching === 'false', null, { timeout: 10_000 });
      for (let i = 1; i < seen.length; i++) assert.ok(seen[i] < seen[i - 1], `positions decrease: ${seen.join(', ')}`);
      assert.deepEqual(errors, []);
    },
    { contextOptions: { hasTouch: true, viewport: { width: 1024, height: 1366 } } },
  );
});

// Issue #22: the strip showed no texture or mm scale, and a sweep ending near
// 100.7 mm left the player at 105.37 mm on a 101.76 mm surface.
test('feel: the strip shows the texture and a mm scale; the player stays on the surface', { timeout: 120_000 }, async () => {
  await withStudio(async ({ studio, page, errors }) => {
    await openDesigner(page, studio.url);
    const b = await stripBox(page);
    const ticks = await page.$$eval('[data-testid=strip-scale] .tick', (els) => els.map((e) => e.textContent));
    assert.deepEqual(ticks, ['0', '10', '20', '30', '40', '50', '60', '70', '80', '90', '100']);
    assert.match(await page.textContent('[data-testid=strip-scale]'), /mm \(surface 101\.76 mm\)/);
    const ink = await page.$eval('[data-testid=strip-texture]', (c) => {
      const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
      let n = 0;
      for (let i = 3; i < d.length; i += 4) if (d[i]) n++;
      return { n, of: d.length / 4 };
    });
    assert.ok(ink.n > ink.of * 0.05, `the texture is drawn on the strip (${ink.n} of ${ink.of} pixels)`);
    // A fast sweep that ends at the right edge: the player's 30 ms extrapolation overshoots the surface.
    const y = b.y + b.height / 2;
    await page.mouse.move(b.x + 2 + 0.5 * (b.width - 4), y);
    for (let k = 1; k <= 20; k++) {
      await page.mouse.move(b.x + 2 + (0.5 + (0.4995 * k) / 20) * (b.width - 4), y);
      await page.waitForTimeout(8);
    }
    await page.waitForFunction(() => Number(document.querySelector('#player-position').dataset.mm) > 95, null, { timeout: 10_000 });
    let raw = 0;
    for (let i = 0; i < 10; i++) {
      const mm = Number(await page.getAttribute('#player-position', 'data-mm'));
      raw = Math.max(raw, Number(await page.getAttribute('#player-position', 'data-raw-mm')));
      assert.ok(mm >= 0 && mm <= TPAD_MM + 1e-9, `player at ${mm} mm on a ${TPAD_MM} mm surface`);
      await page.waitForTimeout(30);
    }
    console.log(`player's own report reached ${raw.toFixed(2)} mm; shown at most ${TPAD_MM} mm`);
    assert.match(await page.textContent('#player-position'), /^\d+\.\d\d mm/);
    await screenshot(page, 'feel-strip-scale');
    assert.deepEqual(errors, []);
  });
});
