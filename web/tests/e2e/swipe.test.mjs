// Swipe measures from the browser's own clock (issue #36): a participant's
// scripted pointer stroke at a known speed, over the participant screen's
// strip in Chromium against the real `texel studio`, is stored with that
// speed within 2 % whether its messages go out paced (one every 10 ms) or
// queue and leave in one burst. The stroke's times are the input events'
// own (CDP Input.dispatchMouseEvent `timestamp`), which Chromium hands to
// the page as PointerEvent.timeStamp; the page sends them with each sample
// (feel.move t_ms), and the studio measures from them (docs/studio.md
// "Experiments"). Stamped on arrival instead, a burst measured ~10⁵–10⁶ mm/s.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { withStudio, withoutPractice } from './studio.mjs';
import { control } from './participant-helpers.mjs';

const TL = withoutPractice('texel-length');
const SAMPLES = 30; // 29 intervals
const STEP_MS = 10;
const TPAD_MM = 19200 * 0.0053; // the protocol's device: the strip's length

/**
 * Strokes the participant's strip left to right: SAMPLES mouse moves STEP_PX apart whose input
 * times are STEP_MS apart. `burst`: dispatched all at once (times in the past, as queued input);
 * otherwise one every STEP_MS. Returns the stroke's true speed (mm/s, strip mm per px × px / s).
 */
async function stroke(p, cdp, { burst }) {
  const strip = p.locator('[data-testid=feel-strip]');
  await strip.scrollIntoViewIfNeeded();
  const r = await p.evaluate(() => {
    const b = document.querySelector('[data-testid=feel-strip]').getBoundingClientRect();
    return { left: b.left, width: b.width, top: b.top, height: b.height };
  });
  const stepPx = 8;
  const y = r.top + r.height / 2;
  const x0 = r.left + 0.2 * r.width;
  // Queued input is newer than any input the page has already had: the pointer's
  // way to the stimulus button may have crossed the strip just now, so a burst
  // (times up to 0.4 s in the past) waits until that is further back.
  if (burst) await new Promise((res) => setTimeout(res, 600));
  // The page's clock as epoch time (CDP's timestamp); the stroke's times end before "now".
  const now = await p.evaluate(() => performance.timeOrigin + performance.now());
  const start = burst ? now - (SAMPLES + 10) * STEP_MS : now - 5 * STEP_MS;
  const move = (k) =>
    cdp.send('Input.dispatchMouseEvent', { type: 'mouseMoved', x: x0 + k * stepPx, y, timestamp: (start + k * STEP_MS) / 1000 });
  if (burst) await Promise.all([...Array(SAMPLES).keys()].map(move));
  else
    for (let k = 0; k < SAMPLES; k++) {
      await move(k);
      await new Promise((res) => setTimeout(res, STEP_MS));
    }
  // Off the strip: the finger lifts.
  await cdp.send('Input.dispatchMouseEvent', { type: 'mouseMoved', x: x0, y: Math.max(0, r.top - 150) });
  return (stepPx * (TPAD_MM / r.width) * 1000) / STEP_MS;
}

test('swipe: a scripted stroke at a known speed is stored at that speed, paced or in one burst', { timeout: 300_000 }, async () => {
  await withStudio(async ({ context, page, studio, errors }) => {
    await page.goto(`${studio.url}#/experimenter`);
    const [r] = await control(page, { type: 'experiment.start', protocol: TL, participant: 'SW1' });
    assert.equal(r.type, 'experiment.started', JSON.stringify(r));
    const session = r.session.id;
    const p = await context.newPage();
    p.on('pageerror', (e) => errors.push(String(e)));
    await p.goto(`${studio.url}#/participant`);
    const cdp = await context.newCDPSession(p);
    // What the page receives: each pointer sample's time as the browser gives it.
    await p.evaluate(() => {
      window.__moves = [];
      document.addEventListener(
        'pointermove',
        (e) => {
          for (const c of e.getCoalescedEvents ? e.getCoalescedEvents() : [e]) window.__moves.push([c.timeStamp, c.clientX]);
        },
        true,
      );
    });
    const want = [];
    for (const [trial, burst] of [[0, false], [1, true]]) {
      await p.waitForSelector(`.question[data-trial="${trial}"]`);
      await p.locator('button.stimulus').first().click();
      await p.waitForFunction(() => document.querySelector('[data-testid=feel-strip]')?.getAttribute('aria-valuemax'));
      assert.equal(await p.locator('[data-testid=feel-strip]').getAttribute('aria-valuemax'), String(Math.round(TPAD_MM)));
      await p.evaluate(() => (window.__moves = []));
      want.push(await stroke(p, cdp, { burst }));
      const moves = await p.evaluate(() => window.__moves);
      const dts = moves.slice(1).map((m, i) => +(m[0] - moves[i][0]).toFixed(2));
      assert.ok(moves.length >= SAMPLES - 1, `the page saw the stroke: ${moves.length} samples`);
      assert.ok(dts.filter((d) => Math.abs(d - STEP_MS) < 0.5).length >= SAMPLES - 3, `the input times are the stroke's: Δt ${dts.join(' ')}`);
      await p.locator('[data-testid=choices] button').first().click();
      await p.locator('[data-testid=submit]:not([disabled])').click();
    }
    await p.waitForSelector('.question[data-trial="2"]');
    const [t] = await control(page, { type: 'experiment.trials', session });
    assert.equal(t.rows.length, 2);
    for (const [i, row] of t.rows.entries()) {
      const got = Number(row.swipe_mean_speed_mm_s);
      const how = i === 0 ? 'paced' : 'one burst';
      console.log(`${how}: stored ${got} mm/s (SD ${row.swipe_sd_speed_mm_s}) for a ${want[i].toFixed(3)} mm/s stroke`);
      assert.equal(row.swipe_flag, '', `${how}: not flagged (${row.swipe_flag})`);
      assert.ok(Math.abs(got - want[i]) <= 0.02 * want[i], `${how}: stored ${got} mm/s for a ${want[i].toFixed(2)} mm/s stroke`);
      assert.ok(Number(row.directional_proportion) > 0.9, `${how}: left to right (${row.directional_proportion})`);
    }
    assert.deepEqual(errors, []);
  });
});
