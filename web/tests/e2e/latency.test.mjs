// Latency, measured in the browser with performance.now() (web/src: the
// designer and the strip record each sample in window.__texelStats):
//   slider change → map and histogram redrawn (tpad), one change at a time;
//   pointer move  → feel.ack received (the sample is queued on the player),
//                   from the pointer handler's post to the finger worker to
//                   the ack's arrival in that worker.
// Written to $TEXEL_ARTIFACTS/latency.json and printed. Only generous sanity
// bounds are asserted here; the goals (p95 < 50 ms, < 10 ms) are reported by
// `make bench`.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { writeFileSync } from 'node:fs';
import { withStudio, openDesigner, nextDraw, stats, quantile, artifact } from './studio.mjs';

const summary = (xs) => ({ p50: +quantile(xs, 0.5).toFixed(3), p95: +quantile(xs, 0.95).toFixed(3), max: +Math.max(...xs).toFixed(3), n: xs.length });

test('latency: slider → redraw and pointer → player', { timeout: 300_000 }, async () => {
  await withStudio(async ({ studio, page, browser }) => {
    await openDesigner(page, studio.url);
    await page.selectOption('#device', 'tpad');
    await nextDraw(page, 0);
    await page.waitForTimeout(500);

    // Slider: 60 changes, each waited for, as a slowly dragged slider.
    await page.evaluate(() => (window.__texelStats.sliderToRedrawMs.length = 0));
    const pitch = page.locator('#central-pitch');
    await pitch.focus();
    for (let i = 0; i < 60; i++) {
      const n = (await stats(page)).designsDrawn;
      await page.keyboard.press(i % 20 < 10 ? 'ArrowRight' : 'ArrowLeft');
      await nextDraw(page, n);
    }
    const slider = (await stats(page)).sliderToRedrawMs;

    // Pointer: 250 moves over the strip at ~250 Hz (a pen's rate).
    await page.evaluate(() => (window.__texelStats.pointerToAckMs.length = 0));
    const b = await page.locator('[data-testid=feel-strip]').boundingBox();
    const y = b.y + b.height / 2;
    await page.mouse.move(b.x + 5, y);
    // Chromium may coalesce moves within one frame into one pointermove: keep
    // moving until 250 samples were acknowledged.
    const moves = 250;
    for (let i = 0; i < 5000; i++) {
      const f = 0.5 + 0.45 * Math.sin((2 * Math.PI * i) / 100);
      await page.mouse.move(b.x + f * b.width, y);
      await page.waitForTimeout(4);
      if (i % 25 === 24 && (await page.evaluate(() => window.__texelStats.pointerToAckMs.length)) >= moves) break;
    }
    await page.waitForFunction((k) => window.__texelStats.pointerToAckMs.length >= k, moves, { timeout: 20_000 });
    const pointer = (await stats(page)).pointerToAckMs;

    // Baseline in the same run: a bare WebSocket round trip through the
    // server and the service (feel.state is answered inline, no work), one
    // request at a time from the page. Ratios to it compare across machines.
    const baseline = await page.evaluate(async () => {
      const ws = new WebSocket(`ws://${location.host}/ws`);
      await new Promise((ok, fail) => ((ws.onopen = ok), (ws.onerror = fail)));
      const rtt = [];
      for (let k = 0; k < 250; k++) {
        const t0 = performance.now();
        await new Promise((ok) => {
          ws.onmessage = ok;
          ws.send(JSON.stringify({ type: 'feel.state', id: k }));
        });
        rtt.push(performance.now() - t0);
      }
      ws.close();
      return rtt;
    });

    const result = {
      slider_to_redraw_ms: summary(slider),
      pointer_to_player_ms: summary(pointer),
      baseline_ws_round_trip_ms: summary(baseline),
      device: 'tpad',
      browser: `chromium ${browser.version()}`,
      measured_at: new Date().toISOString(),
      note:
        'browser clocks (performance.timeOrigin + now). slider: input event → the design reply drawn by uPlot (map, detail, histogram, spectrum), one change at a time; ' +
        'pointer: pointer event handled → feel.ack received by the finger worker that sends feel.move (web/src/feel.ts)',
    };
    writeFileSync(artifact('latency.json'), JSON.stringify(result, null, 2) + '\n');
    console.log(`slider → redraw  p50 ${result.slider_to_redraw_ms.p50} ms  p95 ${result.slider_to_redraw_ms.p95} ms  (n ${slider.length}; goal p95 < 50 ms)`);
    console.log(`pointer → player p50 ${result.pointer_to_player_ms.p50} ms  p95 ${result.pointer_to_player_ms.p95} ms  (n ${pointer.length}; goal p95 < 10 ms)`);
    console.log(`baseline: WebSocket round trip p50 ${result.baseline_ws_round_trip_ms.p50} ms  p95 ${result.baseline_ws_round_trip_ms.p95} ms`);
    assert.ok(slider.length >= 50, `slider samples ${slider.length}`);
    assert.ok(pointer.length >= 200, `pointer samples ${pointer.length}`);
    assert.ok(result.slider_to_redraw_ms.p95 < 500, 'slider p95 sanity bound');
    assert.ok(result.pointer_to_player_ms.p95 < 500, 'pointer p95 sanity bound');
  });
});
