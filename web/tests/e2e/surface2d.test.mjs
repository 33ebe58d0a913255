// The 2-D page (#/surface): the map view shows the engine's friction map and
// zooming changes its scale and the window asked for; a stroke on the 2-D
// feel pad reaches the engine's 2-D player (finger samples counted by the
// player, non-zero drive reported by feel2d.state) and stays drawn on the
// map; a shape placed by dragging and a painted stroke become the document's
// 2-D coarse profile; the scan along a chosen direction is plotted.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { createRequire } from 'node:module';
import { withStudio, screenshot } from './studio.mjs';

const axeSource = readFileSync(createRequire(import.meta.url).resolve('axe-core/axe.min.js'), 'utf8');

// A small inline display (600 × 400 pixels of 0.25 mm) keeps the engine's
// work (a bitmap-mode map is the whole bitmap) to a fraction of a second.
const SMALL = {
  format: 'texel-document',
  version: 4,
  device: {
    name: 'pad-150x100', samples: 600, spacing_mm: 0.25, format: 'f32le', refresh_hz: 6250, band_min_cpm: 0.01, band_max_cpm: 0, layout: [],
    bitmap: { width_px: 600, height_px: 400, pixel_pitch_mm: 0.25, depth_bits: 8, polarity: 'darker_more_friction' },
  },
  surface2d: {
    regions: [
      {
        name: 'surface', field: 'spectral',
        texture: { kind: 'texel', central_pitch_db: -3, irregularity_db: -8, texel_length_mm: 2, seed: 4, coarse_strength: 0.8, fine_strength: 0.6 },
        coarse2d: { kind: 'constant', value: 1 },
      },
    ],
  },
};

/** The map's box in the viewport, scrolled into view first (controls below it may have scrolled the page). */
async function mapBox(page) {
  await page.locator('[data-testid=map2d]').scrollIntoViewIfNeeded();
  return page.locator('[data-testid=map2d]').boundingBox();
}

const hooks = (page) => page.evaluate(() => ({ ...window.__texel2d }));

/** Alpha of the overlay canvas (the drawn path) at view points (CSS px). */
function overlayAlpha(page, pts) {
  return page.$eval(
    '[data-testid=map2d-path]',
    (c, pts) => {
      const ctx = c.getContext('2d');
      const k = c.width / c.clientWidth;
      return pts.map(([x, y]) => ctx.getImageData(Math.round(x * k), Math.round(y * k), 1, 1).data[3]);
    },
    pts,
  );
}

test('2-D page: map view, zoom, feel pad reaching the 2-D player, coarse shapes, scans', { timeout: 180_000 }, async () => {
  await withStudio(async ({ studio, page, errors }) => {
    // The small display's document, in place before the page's first script runs.
    await page.addInitScript((d) => localStorage.setItem('texel.surface2d.v1', JSON.stringify({ document: d, images: {} })), SMALL);
    await page.goto(`${studio.url}#/surface`);
    await page.waitForFunction(() => window.__texel2d?.viewsDrawn > 0, null, { timeout: 60_000 });

    // The map view shows an image: many grey levels on the image canvas.
    const levels = await page.$eval('[data-testid=map2d-image]', (c) => {
      const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
      const seen = new Set();
      for (let i = 0; i < d.length; i += 4 * 97) seen.add(d[i]);
      return seen.size;
    });
    assert.ok(levels > 20, `the map shows an image (${levels} grey levels)`);
    const before = await hooks(page);
    assert.match(await page.textContent('[data-testid=s2d-scale]'), /pixel pitch 0\.2500 mm/);

    // Zoom in twice: the scale (mm per screen px) shrinks and a finer window is asked for.
    await page.click('[data-testid=s2d-zoom-in]');
    await page.click('[data-testid=s2d-zoom-in]');
    // The window asked for narrows with the zoom (the newest reply answers the newest request).
    const spanMm = (v) => v.columns * v.view_pitch_mm;
    await page.waitForFunction(
      (span) => window.__texel2d.lastView.columns * window.__texel2d.lastView.view_pitch_mm < 0.6 * span,
      spanMm(before.lastView),
      { timeout: 30_000 },
    );
    const zoomed = await hooks(page);
    assert.ok(zoomed.lastView.mm_per_px < 0.5 * before.lastView.mm_per_px, `${before.lastView.mm_per_px} → ${zoomed.lastView.mm_per_px} mm per px`);
    assert.ok(zoomed.lastView.stride <= before.lastView.stride);
    assert.ok(Number(await page.getAttribute('[data-testid=s2d-scale]', 'data-mm-per-px')) < before.lastView.mm_per_px);
    await page.click('[data-testid=s2d-zoom-fit]');
    await page.waitForFunction((s) => Math.abs(window.__texel2d.lastView.mm_per_px - s) < 1e-9, before.lastView.mm_per_px, { timeout: 30_000 });

    // The 2-D feel pad: a mouse stroke (button held) along a diagonal, heard through the browser too.
    await page.waitForFunction(() => window.__texel2d.selected === 'path', null, { timeout: 60_000 });
    await page.check('#s2d-hear');
    let box = await mapBox(page);
    const path = [];
    for (let k = 0; k <= 40; k++) path.push([box.width * (0.25 + 0.45 * (k / 40)), box.height * (0.3 + 0.35 * (k / 40))]);
    const beforeInk = await overlayAlpha(page, path.filter((_, i) => i % 5 === 2));
    assert.ok(beforeInk.every((a) => a === 0), 'no path drawn yet');
    await page.mouse.move(box.x + path[0][0], box.y + path[0][1]);
    await page.mouse.down();
    for (const [x, y] of path.slice(1)) {
      await page.mouse.move(box.x + x, box.y + y);
      await page.waitForTimeout(8);
    }
    await page.waitForFunction(() => window.__texel2d.touching && window.__texel2d.peakMax > 0, null, { timeout: 10_000 });
    await page.mouse.up();
    const ink = await overlayAlpha(page, path.filter((_, i) => i % 5 === 2));
    assert.ok(ink.every((a) => a > 0), `the path is drawn on the map (overlay alpha ${ink.join(', ')})`);
    await page.waitForFunction(() => !window.__texel2d.touching, null, { timeout: 10_000 });
    const fed = await hooks(page);
    assert.ok(fed.movesSent >= 30 && fed.acks > 0 && fed.acks <= fed.movesSent, `moves ${fed.movesSent}, acks ${fed.acks}`);
    assert.ok(fed.playerSamples >= fed.acks, `the 2-D player counted ${fed.playerSamples} finger samples`);
    assert.ok(fed.peakMax > 0, `the player's drive was not silent (peak ${fed.peakMax})`);
    assert.ok(fed.device?.holds && /^null /.test(fed.device.backend), `the pad says which backend it drives: ${JSON.stringify(fed.device)}`);
    assert.match(await page.textContent('[data-testid=s2d-drives]'), /^null /);
    await screenshot(page, 'surface2d-pad-path');

    // Bitmap mode: the same pad drives the player from the rendered map.
    await page.selectOption('#s2d-mode', 'bitmap');
    await page.waitForFunction(() => window.__texel2d.selected === 'bitmap', null, { timeout: 60_000 });
    // Hear it plays the bitmap at the device's resolution, whatever the zoom.
    await page.waitForFunction(() => window.__texel2d.hearRaster !== null, null, { timeout: 60_000 });
    const heard = await hooks(page);
    const pixelPitch = heard.lastView.view_pitch_mm / heard.lastView.stride;
    assert.ok(heard.hearRaster.whole && Math.abs(heard.hearRaster.pitch - pixelPitch) < 1e-12, `Hear it: ${JSON.stringify(heard.hearRaster)}, view ${JSON.stringify(heard.lastView)}`);
    assert.ok(heard.hearRaster.columns * pixelPitch > 0.99 * heard.lastView.columns * heard.lastView.view_pitch_mm, 'the whole width, every device pixel');

    // A disc placed by dragging becomes the region's coarse2d.
    await page.check('#s2d-tool-shape');
    await page.selectOption('#s2d-shape', 'disc');
    box = await mapBox(page);
    await page.mouse.move(box.x + box.width * 0.5, box.y + box.height * 0.5);
    await page.mouse.down();
    await page.mouse.move(box.x + box.width * 0.6, box.y + box.height * 0.5, { steps: 5 });
    await page.mouse.up();
    await page.waitForFunction(() => /"kind": "disc"/.test(document.querySelector('[data-testid=document2d-json]').value), null, { timeout: 10_000 });
    const doc = JSON.parse(await page.inputValue('[data-testid=document2d-json]'));
    assert.equal(doc.version, 4);
    const disc = doc.surface2d.regions[0].coarse2d;
    assert.ok(disc.radius_mm > 5 && disc.x_mm > 50, `disc ${JSON.stringify(disc)}`);

    // A painted stroke becomes an image profile whose PNG travels with the messages.
    await page.check('#s2d-tool-paint');
    box = await mapBox(page);
    const n = (await hooks(page)).viewsDrawn;
    await page.mouse.move(box.x + box.width * 0.3, box.y + box.height * 0.7);
    await page.mouse.down();
    await page.mouse.move(box.x + box.width * 0.7, box.y + box.height * 0.75, { steps: 8 });
    await page.mouse.up();
    await page.waitForFunction(() => /"path": "painted.png"/.test(document.querySelector('[data-testid=document2d-json]').value), null, { timeout: 10_000 });
    await page.waitForFunction((n) => window.__texel2d.viewsDrawn > n, n, { timeout: 60_000 });

    // The scan along 45°: plotted beside the 1-D texture's spectrum.
    await page.fill('#s2d-angle-num', '45');
    await page.press('#s2d-angle-num', 'Enter');
    await page.waitForFunction(() => /at 45°/.test(document.querySelector('[data-testid=s2d-scan-caption]').textContent), null, { timeout: 60_000 });
    await screenshot(page, 'surface2d-shapes-scan');

    // A touch stroke (Pointer Events with pointerType touch) is drawn too, in its own colour.
    await page.check('#s2d-tool-feel');
    box = await mapBox(page);
    const cdp = await page.context().newCDPSession(page);
    const touchAt = (type, f) =>
      cdp.send('Input.dispatchTouchEvent', { type, touchPoints: f === undefined ? [] : [{ x: Math.round(box.x + box.width * f), y: Math.round(box.y + box.height * 0.2) }] });
    const movesBefore = (await hooks(page)).movesSent;
    await touchAt('touchStart', 0.2);
    for (let k = 1; k <= 10; k++) await touchAt('touchMove', 0.2 + 0.03 * k);
    await touchAt('touchEnd');
    assert.ok((await hooks(page)).movesSent >= movesBefore + 10, 'touch samples were sent');
    const touchInk = await overlayAlpha(page, [[box.width * 0.35, box.height * 0.2]]);
    assert.ok(touchInk[0] > 0, 'the touch path is drawn');
    // A pen stroke (CDP mouse events with pointerType pen).
    const pen = (type, f) =>
      cdp.send('Input.dispatchMouseEvent', { type, pointerType: 'pen', button: 'left', buttons: type === 'mouseReleased' ? 0 : 1, clickCount: 1, x: Math.round(box.x + box.width * f), y: Math.round(box.y + box.height * 0.85), force: 0.5 });
    const beforePen = (await hooks(page)).movesSent;
    await pen('mousePressed', 0.2);
    for (let k = 1; k <= 10; k++) await pen('mouseMoved', 0.2 + 0.03 * k);
    await pen('mouseReleased', 0.5);
    assert.ok((await hooks(page)).movesSent >= beforePen + 10, 'pen samples were sent');
    const penInk = await overlayAlpha(page, [[box.width * 0.35, box.height * 0.85]]);
    assert.ok(penInk[0] > 0, 'the pen path is drawn');
    await page.waitForFunction(() => !window.__texel2d.touching, null, { timeout: 10_000 });
    assert.ok(await page.isChecked('#s2d-hear'), 'Hear it stayed on (the 2-D worklet started)');
    assert.match(await page.textContent('#s2d-device'), /pad-150x100 \(the document's own profile\)/);
    await screenshot(page, 'surface2d-touch-pen');

    // The tile field (version 5's default design): choosing it makes the document version 5, and the view renders it.
    const tileViews = (await hooks(page)).viewsDrawn;
    await page.selectOption('#s2d-field', 'tile');
    await page.waitForFunction(() => /"version": 5/.test(document.querySelector('[data-testid=document2d-json]').value), null, { timeout: 10_000 });
    assert.equal(JSON.parse(await page.inputValue('[data-testid=document2d-json]')).surface2d.regions[0].field, 'tile');
    await page.waitForFunction((n) => window.__texel2d.viewsDrawn > n, tileViews, { timeout: 60_000 });
    assert.equal(await page.getAttribute('[data-testid=surface2d-status]', 'class'), 'status', await page.textContent('[data-testid=surface2d-status]'));
    await screenshot(page, 'surface2d-tile');

    // A two-finger pinch zooms in about the fingers.
    const mmPerPx = async () => Number(await page.getAttribute('[data-testid=map2d]', 'data-mm-per-px'));
    const pinchFrom = await mmPerPx();
    const [cx, cy] = [Math.round(box.x + box.width / 2), Math.round(box.y + box.height / 2)];
    const fingers = (d) => [{ x: cx - d, y: cy, id: 1 }, { x: cx + d, y: cy, id: 2 }];
    await cdp.send('Input.dispatchTouchEvent', { type: 'touchStart', touchPoints: fingers(20) });
    for (let d = 30; d <= 100; d += 10) await cdp.send('Input.dispatchTouchEvent', { type: 'touchMove', touchPoints: fingers(d) });
    await cdp.send('Input.dispatchTouchEvent', { type: 'touchEnd', touchPoints: [] });
    assert.ok((await mmPerPx()) < 0.4 * pinchFrom, `pinch: ${pinchFrom} → ${await mmPerPx()} mm per px`);

    // axe-core: no critical or serious finding on the 2-D page.
    await page.addScriptTag({ content: axeSource });
    const violations = await page.evaluate(async () =>
      (await window.axe.run(document, { resultTypes: ['violations'] })).violations.map((v) => `${v.impact} ${v.id}: ${v.nodes.map((n) => n.target.join(' ')).slice(0, 3).join(', ')}`),
    );
    console.log(`axe surface2d: ${violations.length ? violations.join('; ') : 'no findings'}`);
    assert.deepEqual(violations.filter((v) => /^(critical|serious)/.test(v)), []);
    assert.equal(await page.textContent('[data-testid=surface2d-status]'), '');
    assert.deepEqual(errors, []);
  }, { contextOptions: { hasTouch: true } });
});

test('2-D page: a new document is version 5 with the tile field; an opened one keeps its version', { timeout: 120_000 }, async () => {
  await withStudio(async ({ studio, page, errors }) => {
    await page.goto(`${studio.url}#/surface`); // nothing saved: a new document
    await page.waitForFunction(() => document.querySelector('[data-testid=document2d-json]')?.value, null, { timeout: 30_000 });
    const doc = JSON.parse(await page.inputValue('[data-testid=document2d-json]'));
    assert.equal(doc.version, 5);
    assert.equal(doc.surface2d.regions[0].field, 'tile');
    assert.equal(await page.inputValue('#s2d-field'), 'tile');
    await page.waitForFunction(() => window.__texel2d?.viewsDrawn > 0, null, { timeout: 60_000 });
    assert.equal(await page.getAttribute('[data-testid=surface2d-status]', 'class'), 'status', await page.textContent('[data-testid=surface2d-status]'));
    // An opened version-4 document stays version 4 (its spectral field, its bytes).
    await page.evaluate((d) => localStorage.setItem('texel.surface2d.v1', JSON.stringify({ document: d, images: {} })), SMALL);
    await page.reload();
    await page.waitForFunction(() => /"version": 4/.test(document.querySelector('[data-testid=document2d-json]')?.value ?? ''), null, { timeout: 30_000 });
    assert.equal(await page.inputValue('#s2d-field'), 'spectral');
    assert.deepEqual(errors, []);
  });
});
