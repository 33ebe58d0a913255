// Feel it: a mouse sweep and a touch sweep over the strip reach the engine's
// player (null backend), whose reported position (#player-position, polled
// from feel.state) follows the pointer.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { withStudio, openDesigner, screenshot } from './studio.mjs';

const TPAD_MM = 19200 * 0.0053;

async function stripBox(page) {
  await page.locator('[data-testid=feel-strip]').scrollIntoViewIfNeeded();
  const b = await page.locator('[data-testid=feel-strip]').boundingBox();
  assert.ok(b && b.width > 100, 'the strip is visible');
  return b;
}

async function waitPlayerAt(page, mm, tol = 1.0) {
  await page.waitForFunction(
    ([want, tol]) => {
      const el = document.querySelector('#player-position');
      const v = Number(el?.dataset.mm);
      return el?.dataset.mm !== '' && Math.abs(v - want) <= tol;
    },
    [mm, tol],
    { timeout: 10_000 },
  );
  return Number(await page.getAttribute('#player-position', 'data-mm'));
}

test('feel: a mouse sweep reaches the player', { timeout: 120_000 }, async () => {
  await withStudio(async ({ studio, page, errors }) => {
    await openDesigner(page, studio.url);
    const b = await stripBox(page);
    const y = b.y + b.height / 2;
    const seen = [];
    // Hovering counts as touch for a mouse (feel.ts); the sweep goes left to right.
    for (const f of [0.1, 0.3, 0.5, 0.7, 0.9]) {
      const x = b.x + 2 + f * (b.width - 4);
      await page.mouse.move(x, y, { steps: 4 });
      const want = ((x - b.x) / b.width) * TPAD_MM;
      seen.push(await waitPlayerAt(page, want));
    }
    for (let i = 1; i < seen.length; i++) assert.ok(seen[i] > seen[i - 1], `positions increase: ${seen.join(', ')}`);
    await page.waitForFunction(() => document.querySelector('#player-position').dataset.touching === 'true');
    await screenshot(page, 'feel-mouse');
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
      const at = (f) => Math.round(b.x + 2 + f * (b.width - 4));
      await cdp.send('Input.dispatchTouchEvent', { type: 'touchStart', touchPoints: [{ x: at(0.8), y }] });
      const seen = [await waitPlayerAt(page, ((at(0.8) - b.x) / b.width) * TPAD_MM)];
      for (const f of [0.6, 0.4, 0.2]) {
        for (let k = 1; k <= 5; k++) {
          const g = f + 0.2 * (1 - k / 5);
          await cdp.send('Input.dispatchTouchEvent', { type: 'touchMove', touchPoints: [{ x: at(g), y }] });
        }
        seen.push(await waitPlayerAt(page, ((at(f) - b.x) / b.width) * TPAD_MM));
      }
      await page.waitForFunction(() => document.querySelector('#player-position').dataset.touching === 'true');
      await screenshot(page, 'feel-touch');
      await cdp.send('Input.dispatchTouchEvent', { type: 'touchEnd', touchPoints: [] });
      await page.waitForFunction(() => document.querySelector('#player-position').dataset.touching === 'false', null, { timeout: 10_000 });
      for (let i = 1; i < seen.length; i++) assert.ok(seen[i] < seen[i - 1], `positions decrease: ${seen.join(', ')}`);
      assert.deepEqual(errors, []);
    },
    { contextOptions: { hasTouch: true, isMobile: false, viewport: { width: 1024, height: 1366 } } },
  );
});
