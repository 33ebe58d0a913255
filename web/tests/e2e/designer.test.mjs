// Designer: sliders drive the map, histogram and encoded size; a coarse
// profile drawn on the map changes the map; a document exported and
// re-imported restores the sliders.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { withStudio, openDesigner, nextDraw, stats, screenshot, artifact, setRange, canvasHash, mapChanged } from './studio.mjs';

test('designer: slider, drawn coarse profile, export and re-import', { timeout: 180_000 }, async () => {
  await withStudio(async ({ studio, page, errors }) => {
    await openDesigner(page, studio.url);
    await page.waitForSelector('[data-testid=encoded-bytes][data-bytes]');
    const s0 = await stats(page);
    const hex0 = await page.getAttribute('[data-testid=encoded-hex]', 'title');
    const px0 = { map: await canvasHash(page, 'map-plot'), hist: await canvasHash(page, 'histogram-plot') };
    await screenshot(page, 'designer-initial');

    // Move the Central Pitch slider with the keyboard (each key press is an input event).
    const pitch = page.locator('#central-pitch');
    await pitch.focus();
    for (let i = 0; i < 15; i++) await page.keyboard.press('ArrowRight');
    await page.waitForFunction((v) => document.querySelector('#central-pitch').value !== v, '10');
    let s1 = await nextDraw(page, s0.designsDrawn);
    // Let the last coalesced design land.
    await page.waitForFunction(() => window.__texelStats.designsDrawn >= 1 && !document.querySelector('.status.error'));
    await page.waitForTimeout(300);
    s1 = await stats(page);
    assert.notEqual(s1.lastMapChecksum, s0.lastMapChecksum, 'the map changed');
    assert.notEqual(s1.lastHistChecksum, s0.lastHistChecksum, 'the histogram changed');
    assert.notEqual(await canvasHash(page, 'map-plot'), px0.map, 'the map was redrawn');
    assert.notEqual(await canvasHash(page, 'histogram-plot'), px0.hist, 'the histogram was redrawn');
    const hex1 = await page.getAttribute('[data-testid=encoded-hex]', 'title');
    assert.notEqual(hex1, hex0, 'the encoded bitstream changed');
    assert.match(await page.textContent('[data-testid=pitch-cpm]'), /cycles\/mm/);

    // A seed of 2^14 or more needs a longer varint: the encoded size changes.
    const bytes1 = s1.lastEncodedBytes;
    await page.fill('#seed', '20000');
    await page.locator('#seed').dispatchEvent('change');
    await nextDraw(page, s1.designsDrawn);
    await page.waitForTimeout(300); // both change events' designs have landed
    const s2 = await stats(page);
    assert.ok(s2.lastEncodedBytes > bytes1, `encoded size grew with the seed (${bytes1} → ${s2.lastEncodedBytes})`);
    await screenshot(page, 'designer-after-slider');

    // Draw a coarse profile with the pointer on the map.
    const px2 = await canvasHash(page, 'map-plot');
    await page.click('[data-testid=draw-coarse]');
    const over = await page.locator('[data-testid=map-plot] .u-over').boundingBox();
    await page.mouse.move(over.x + over.width * 0.05, over.y + over.height * 0.9);
    await page.mouse.down();
    for (let i = 1; i <= 30; i++) {
      const f = i / 30;
      await page.mouse.move(over.x + over.width * (0.05 + 0.9 * f), over.y + over.height * (0.9 - 0.8 * Math.abs(Math.sin(3 * f))));
    }
    await page.mouse.up();
    const s3 = await mapChanged(page, s2.lastMapChecksum); // the drawn profile changed the map
    await page.waitForTimeout(100);
    assert.notEqual(await canvasHash(page, 'map-plot'), px2, 'the map was redrawn with the profile');
    assert.match(await page.textContent('[data-testid=points-info]'), /\d+ drawn points/);
    assert.ok(s3.lastEncodedBytes > s2.lastEncodedBytes, 'the coarse section adds bytes');
    await screenshot(page, 'designer-drawn-coarse');

    // Export the document, change the sliders, re-import: the sliders come back.
    const exported = { pitch: await pitch.inputValue(), length: await page.inputValue('#texel-length') };
    const [download] = await Promise.all([page.waitForEvent('download'), page.click('[data-testid=export-document]')]);
    const file = artifact('exported.texel.json');
    await download.saveAs(file);
    assert.match(download.suggestedFilename(), /\.json$/);
    await setRange(page, '#central-pitch', 0);
    await setRange(page, '#texel-length', 2);
    await page.waitForTimeout(200);
    assert.equal(await pitch.inputValue(), '0');
    const before = (await stats(page)).designsDrawn;
    await page.setInputFiles('#import-file', file);
    await page.waitForSelector('[data-testid=designer-status][data-imported]');
    await nextDraw(page, before);
    assert.equal(await pitch.inputValue(), exported.pitch, 'Central Pitch restored');
    assert.equal(await page.inputValue('#texel-length'), exported.length, 'texel length restored');
    assert.equal(await page.inputValue('#coarse-kind'), 'points', 'drawn profile restored');
    await screenshot(page, 'designer-reimported');

    // A bitstream (.texel) dropped on the page imports too (decoded on the device).
    const [bits] = await Promise.all([page.waitForEvent('download'), page.click('[data-testid=export-bitstream]')]);
    assert.match(bits.suggestedFilename(), /\.texel$/);
    const bitsFile = artifact('exported.texel');
    await bits.saveAs(bitsFile);
    const bytes = [...readFileSync(bitsFile)];
    assert.equal(bytes[0], 0x54, 'bitstream magic');
    await setRange(page, '#central-pitch', 0);
    const dt = await page.evaluateHandle((b) => {
      const d = new DataTransfer();
      d.items.add(new File([new Uint8Array(b)], 'dropped.texel', { type: 'application/octet-stream' }));
      return d;
    }, bytes);
    await page.dispatchEvent('.page-designer', 'drop', { dataTransfer: dt });
    await page.waitForFunction(() => document.querySelector('[data-testid=designer-status]').dataset.imported === 'dropped.texel');
    assert.equal(await pitch.inputValue(), exported.pitch, 'Central Pitch restored from the dropped bitstream');
    assert.deepEqual(errors, []);
  });
});

test('designer: reference left, rendering right, and match', { timeout: 240_000 }, async () => {
  await withStudio(async ({ studio, page, errors }) => {
    await openDesigner(page, studio.url);
    const s0 = await stats(page);
    await page.selectOption('#regions', 'split');
    await nextDraw(page, s0.designsDrawn);
    await page.selectOption('#reference', '4sin');
    await page.waitForTimeout(300);
    const pitchBefore = await page.inputValue('#central-pitch');
    await page.click('[data-testid=match]');
    await page.waitForFunction(() => /matched in \d+ bytes/.test(document.querySelector('[data-testid=match-info]').textContent), null, { timeout: 180_000 });
    const pitchAfter = await page.inputValue('#central-pitch');
    assert.notEqual(pitchAfter, pitchBefore, 'the match moved the Central Pitch slider');
    await page.waitForTimeout(500);
    await screenshot(page, 'designer-match');
    assert.deepEqual(errors, []);
  });
});
