// Designer: sliders drive the map, histogram and encoded size; a coarse
// profile drawn on the map changes the map; a document exported and
// re-imported restores the sliders.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { withStudio, openDesigner, nextDraw, stats, screenshot, artifact, setRange, canvasHash, mapChanged, paths, startStudio, launchFirefox, askStudio } from './studio.mjs';

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
    await page.locator('[data-testid=map-plot]').scrollIntoViewIfNeeded();
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
    await page.waitForFunction(() => /Matched in \d+ bytes/.test(document.querySelector('[data-testid=match-info]').textContent), null, { timeout: 180_000 });
    const pitchAfter = await page.inputValue('#central-pitch');
    assert.notEqual(pitchAfter, pitchBefore, 'the match moved the Central Pitch slider');
    // The distance in JNDs, with what 1 JND means (it read "model distance 0.44" on main).
    assert.match(await page.textContent('[data-testid=match-distance]'), /^Felt distance \d+\.\d\d JND$/);
    assert.match(await page.textContent('[data-testid=jnd-meaning]'), /1 JND \(just-noticeable difference\) is a 1 dB change in felt pitch/);
    await page.waitForTimeout(800);
    // Both curves visible: the legend names them, and the plot holds the match's pale green band and the design's dark line.
    const legend = await page.$$eval('[data-testid=spectrum-plot] .u-legend .u-series .u-label', (els) => els.map((e) => e.textContent));
    for (const name of ['design', 'match (decoded)', 'reference (target)']) assert.ok(legend.includes(name), `legend has ${name}: ${legend}`);
    const ink = await page.$eval('[data-testid=spectrum-plot] canvas', (c) => {
      const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
      let green = 0;
      let dark = 0;
      for (let i = 0; i < d.length; i += 4) {
        const [r, g, b] = [d[i], d[i + 1], d[i + 2]];
        if (g > r + 30 && g > b + 10) green++;
        if (Math.abs(r - 27) < 30 && Math.abs(g - 63) < 30 && Math.abs(b - 143) < 30) dark++;
      }
      return { green, dark };
    });
    assert.ok(ink.green > 200 && ink.dark > 200, `match band and design line both drawn (${JSON.stringify(ink)})`);
    await page.locator('[data-testid=spectrum-plot]').scrollIntoViewIfNeeded();
    await screenshot(page, 'designer-match');
    assert.deepEqual(errors, []);
  });
});

// ---------------------------------------------------------------------------
// Issue #22 item 6: a designer a researcher trusts. Each test reproduces a
// defect seen on main and asserts its fix.

/** The visible refusal text of a field, and whether its input is marked invalid. */
async function refusal(page, id, input = `#${id}-value`) {
  const err = page.locator(`[data-testid=${id}-error]`);
  return { visible: await err.isVisible(), text: (await err.textContent()) ?? '', invalid: await page.getAttribute(input, 'aria-invalid') };
}

async function typeInto(page, selector, text) {
  await page.fill(selector, text);
  await page.press(selector, 'Enter');
}

/** True when the element's box lies inside the viewport. */
function inView(page, selector) {
  return page.$eval(selector, (el) => {
    const r = el.getBoundingClientRect();
    // Within a pixel: scrolling into view may leave a sub-pixel edge (0.125 px) outside.
    return r.height > 0 && r.top >= -1 && r.bottom <= window.innerHeight + 1;
  });
}

test('designer: invalid typed values are refused at the field, never clamped or read as 0', { timeout: 180_000 }, async () => {
  await withStudio(async ({ studio, page, errors }) => {
    await openDesigner(page, studio.url);
    await page.waitForSelector('[data-testid=encoded-bytes][data-bytes]');
    const s0 = await stats(page);

    // "abc" and an empty field became 0 dB on main.
    // The range stated is the engine's on this device: the library's -40 … 40 dB within tpad's renderable band.
    for (const [text, why] of [['abc', /"abc" is not a number/], ['', /enter a number/], ['45', /outside the allowed range -20 … 19\.74\d* dB/]]) {
      await typeInto(page, '#central-pitch-value', text);
      const r = await refusal(page, 'central-pitch');
      assert.ok(r.visible, `refusal of "${text}" shown`);
      assert.match(r.text, why);
      assert.match(r.text, /keeps 10 dB/);
      assert.equal(r.invalid, 'true');
      assert.equal(await page.inputValue('#central-pitch-value'), '10', 'the field shows what the document holds');
      assert.equal(await page.inputValue('#central-pitch'), '10');
      assert.ok(await inView(page, '[data-testid=central-pitch-error]'), 'the message is where the user is looking');
    }
    await screenshot(page, 'designer-refused-typed');
    const s1 = await stats(page);
    assert.equal(s1.lastMapChecksum, s0.lastMapChecksum, 'no refused value reached the design');

    // Inside the library's range but above this display's renderable band: refused with that band, at the field.
    await typeInto(page, '#central-pitch-value', '25');
    await page.waitForFunction(() => !document.querySelector('[data-testid=central-pitch-error]').hidden, null, { timeout: 30_000 });
    assert.match((await refusal(page, 'central-pitch')).text, /outside the allowed range -20 … 19\.74/);
    await page.waitForFunction(() => document.querySelector('#central-pitch-value').value === '10');
    assert.equal(await page.inputValue('#central-pitch'), '10', 'the document kept 10 dB');

    // A valid value clears the message and is used as typed.
    const drawnBefore = (await stats(page)).lastMapChecksum;
    await typeInto(page, '#central-pitch-value', '12.5');
    await mapChanged(page, drawnBefore);
    assert.equal(await page.inputValue('#central-pitch'), '12.5');
    assert.equal((await refusal(page, 'central-pitch')).visible, false);
    assert.equal(await page.getAttribute('#central-pitch-value', 'aria-invalid'), null);

    // The seed showed −5 or 3.7 while the document held 0 or 3.
    for (const [text, why] of [['-5', /outside the allowed range/], ['3.7', /not a whole number/]]) {
      await typeInto(page, '#seed', text);
      const r = await refusal(page, 'seed', '#seed');
      assert.ok(r.visible && r.invalid === 'true', `seed ${text} refused`);
      assert.match(r.text, why);
      assert.equal(await page.inputValue('#seed'), '1', 'the seed field shows the document seed');
    }
    await typeInto(page, '#seed', '3');
    await page.waitForFunction(() => document.querySelector('[data-testid=seed-error]').hidden);
    assert.equal(await page.inputValue('#seed'), '3');

    // Irregularity "" is not 0 dB either.
    await typeInto(page, '#irregularity-value', ' ');
    assert.match((await refusal(page, 'irregularity')).text, /enter a number.*keeps -5 dB/);

    // Issue #37: a refusal no longer stays red once the field holds a value the engine takes and is
    // left with Tab, be it the kept value typed back (no change event) or a new one.
    for (const [text, want] of [['-5', '-5'], ['-7.25', '-7.25']]) {
      await typeInto(page, '#irregularity-value', 'abc');
      assert.ok((await refusal(page, 'irregularity')).visible);
      await page.fill('#irregularity-value', text);
      await page.press('#irregularity-value', 'Tab');
      await page.waitForFunction(() => document.querySelector('[data-testid=irregularity-error]').hidden, null, { timeout: 10_000 });
      assert.equal(await page.getAttribute('#irregularity-value', 'aria-invalid'), null, `${text}: not marked invalid`);
      assert.equal(await page.inputValue('#irregularity-value'), want);
    }
    // A refusal shown by Tab itself stays (change, then blur).
    await page.fill('#irregularity-value', 'xyz');
    await page.press('#irregularity-value', 'Tab');
    assert.ok((await refusal(page, 'irregularity')).visible, 'refused on Tab');
    assert.deepEqual(errors, []);
  });
});

// Issue #37: typed values are stored exactly as typed (the document, the
// browser's saved copy and the engine's export hold them to the last digit),
// or refused with the range the engine applies, stated as the engine states it.
test('designer: typed values are stored exactly as typed, or refused with the range the engine applies', { timeout: 240_000 }, async () => {
  await withStudio(async ({ studio, page, errors }) => {
    await openDesigner(page, studio.url);
    await page.waitForSelector('[data-testid=encoded-bytes][data-bytes]');
    const savedTexture = () => page.evaluate(() => JSON.parse(localStorage.getItem('texel.designer.v1') ?? 'null')?.document?.texture ?? null);
    /** Types `text` into field `id` and finds it in the field, the saved document and the engine's exported document. */
    async function storedExactly(id, text, read) {
      const n = (await stats(page)).designsDrawn;
      await typeInto(page, `#${id}-value`, text);
      await nextDraw(page, n);
      assert.equal((await refusal(page, id)).visible, false, `${id} ${text} accepted: ${(await refusal(page, id)).text}`);
      assert.equal(await page.inputValue(`#${id}-value`), text, `the ${id} field shows ${text}`);
      const want = Number(text);
      // The saved copy follows (debounced).
      await page.waitForFunction(([k, v]) => {
        const t = JSON.parse(localStorage.getItem('texel.designer.v1') ?? 'null')?.document?.texture;
        return !!t && (k in t ? t[k] : t.coarse?.[k]) === v;
      }, [read, want], { timeout: 10_000 }).catch(() => undefined);
      const tex = await savedTexture();
      const got = read in tex ? tex[read] : tex.coarse[read];
      assert.equal(got, want, `the saved document holds ${read} ${text}, got ${got}`);
      const doc = await page.evaluate(() => JSON.parse(localStorage.getItem('texel.designer.v1')).document);
      const [ex] = await askStudio(page, [{ type: 'export', as: 'document', document: doc }]);
      assert.equal(ex.type, 'export', JSON.stringify(ex).slice(0, 300));
      const engine = JSON.parse(Buffer.from(ex.data_base64, 'base64').toString('utf8'));
      const t = engine.texture ?? engine.regions.at(-1).texture;
      assert.equal(read in t ? t[read] : t.coarse[read], want, `the engine's document holds ${read} ${text}`);
    }
    async function refusedWith(id, text, why) {
      await typeInto(page, `#${id}-value`, text);
      const r = await refusal(page, id);
      assert.ok(r.visible && r.invalid === 'true', `${id} ${text} refused`);
      assert.match(r.text, why);
      return r.text;
    }

    // Central Pitch 6.0206 dB showed 6.0206 while the document held 6.02 ("= 3.999 cycles/mm").
    await storedExactly('central-pitch', '6.0206', 'central_pitch_db');
    assert.match(await page.textContent('[data-testid=pitch-cpm]'), /^= 4\.000 cycles\/mm/);
    // 0.0004 mm was refused as "texel_length_mm is 0"; 0.0006 was stored as 0.001.
    await storedExactly('texel-length', '0.0004', 'texel_length_mm');
    await storedExactly('texel-length', '0.0006', 'texel_length_mm');
    await storedExactly('coarse-strength', '0.123456789', 'coarse_strength');
    await page.selectOption('#coarse-kind', 'sine');
    await storedExactly('sine-period', '0.0003', 'period_mm');
    await storedExactly('sine-phase', '12345678.9', 'phase_deg');

    // Refused with the range stated, which is the engine's: its bound is accepted, a hair beyond is refused.
    const [hello] = await askStudio(page, [{ type: 'hello' }]);
    const shortest = (19200 * 0.0053) / hello.limits.max_map_samples;
    const lengthText = await refusedWith('texel-length', '0.000001', /outside the allowed range /);
    assert.ok(lengthText.includes(`range ${shortest} … 1000 mm`), `${lengthText} states ${shortest} … 1000 mm`);
    const pitch = hello.device_limits.find((d) => d.device === 'tpad').central_pitch_db;
    await refusedWith('central-pitch', '19.8', new RegExp(`outside the allowed range ${pitch.min} … ${String(pitch.max).replace('.', '\\.')} dB`));
    await refusedWith('sine-period', '0', /outside the allowed range 1e-9 … 1000000000 mm/);
    await refusedWith('sine-phase', '2e9', /outside the allowed range -1000000000 … 1000000000 degrees/);
    await page.selectOption('#coarse-kind', 'constant');
    await refusedWith('coarse-value', '1.5', /outside the allowed range 0 … 1/);
    const doc = (texel_length_mm, central_pitch_db = 10) => ({
      format: 'texel-document', version: 1, device: 'tpad',
      texture: { kind: 'texel', central_pitch_db, irregularity_db: -5, texel_length_mm, seed: 1 },
    });
    const verdicts = await askStudio(page, [
      { type: 'design', document: doc(shortest) },
      { type: 'design', document: doc(shortest * (1 - 1e-9)) },
      { type: 'design', document: doc(0.25, pitch.max) },
      { type: 'design', document: doc(0.25, pitch.max + 1e-6) },
      { type: 'design', document: doc(0.25, pitch.min) },
      { type: 'design', document: doc(0.25, pitch.min - 1e-6) },
    ]);
    assert.deepEqual(verdicts.map((v) => v.type), ['design', 'error', 'design', 'error', 'design', 'error'], verdicts.map((v) => v.message ?? v.type).join(' | '));
    assert.deepEqual(errors, []);
  });
});

test('designer: ranges cover every shipped protocol', { timeout: 120_000 }, async () => {
  const { readdirSync } = await import('node:fs');
  const { join } = await import('node:path');
  const keys = { central_pitch_db: 'central-pitch', irregularity_db: 'irregularity', texel_length_mm: 'texel-length', quantization_db: 'quantization', period_mm: 'sine-period', coarse_strength: 'coarse-strength', fine_strength: 'fine-strength' };
  const seen = {};
  const walk = (o) => {
    if (Array.isArray(o)) return o.forEach(walk);
    if (o && typeof o === 'object')
      for (const [k, v] of Object.entries(o)) {
        if (k in keys && typeof v === 'number') (seen[k] ??= []).push(v);
        else walk(v);
      }
  };
  const dir = paths.protocols;
  for (const f of readdirSync(dir).filter((f) => f.endsWith('.json'))) walk(JSON.parse(readFileSync(join(dir, f), 'utf8')));
  assert.ok(Math.max(...seen.texel_length_mm) >= 26, 'the texel-length protocol starts at 26 mm');
  await withStudio(async ({ studio, page, errors }) => {
    await openDesigner(page, studio.url);
    await page.selectOption('#coarse-kind', 'sine');
    for (const [k, id] of Object.entries(keys)) {
      const [min, max] = [Number(await page.getAttribute(`#${id}`, 'min')), Number(await page.getAttribute(`#${id}`, 'max'))];
      for (const v of seen[k] ?? []) assert.ok(v >= min && v <= max, `${k} ${v} lies on the ${id} slider (${min} … ${max})`);
    }
    // 26 mm, typed, is a design (it stopped at 10 mm on main).
    const n = (await stats(page)).designsDrawn;
    await typeInto(page, '#texel-length-value', '26');
    await nextDraw(page, n);
    assert.equal(await page.inputValue('#texel-length'), '26');
    assert.equal(await page.isVisible('[data-testid=texel-length-error]'), false);
    // Three whole 26 mm texels on the tpad's 101.76 mm: the last 23.76 mm are flat, and the page says so (issue #37).
    assert.match(await page.textContent('[data-testid=flat-warning]'), /With 26 mm texels, 3 whole texels .* the last 23\.76 mm of it are flat/);
    assert.ok(await page.isVisible('[data-testid=flat-warning]'));
    // The texel-length study's texture, made with the controls: its band floor, abrupt boundaries and whole texels
    // (the designer had no band, phase or fill controls, so a shipped protocol's texture could not be reproduced).
    const proto = JSON.parse(readFileSync(join(dir, 'texel-length-visual-practice.json'), 'utf8'));
    const shipped = JSON.stringify(proto).match(/"band_min_cpm":([0-9.]+)/);
    assert.ok(shipped, 'the protocol sets band_min_cpm');
    let n1 = (await stats(page)).designsDrawn;
    await typeInto(page, '#band-min-value', shipped[1]);
    await nextDraw(page, n1);
    n1 = (await stats(page)).designsDrawn;
    await page.selectOption('#phase', 'reset');
    await nextDraw(page, n1);
    assert.equal(await page.inputValue('#fill'), 'whole');
    const [docDl] = await Promise.all([page.waitForEvent('download'), page.click('[data-testid=export-document]')]);
    const tex = JSON.parse(readFileSync(await docDl.path(), 'utf8')).texture;
    assert.equal(tex.band_min_cpm, Number(shipped[1]));
    assert.equal(tex.phase, 'reset');
    assert.equal(tex.fill, 'whole');
    // A Central Pitch below the band's floor is refused with the band's edge (0 dB = 1 cycle/mm).
    await typeInto(page, '#central-pitch-value', '-1');
    assert.match((await refusal(page, 'central-pitch')).text, /outside the allowed range 0 … /);
    // A band floor of 0, or at the band's top (the tpad's Nyquist frequency), is refused with the renderer's rule.
    await typeInto(page, '#band-min-value', '0');
    assert.match((await refusal(page, 'band-min')).text, /outside the allowed range 1e-12 … below 94\.339\d* cycles\/mm/);
    await typeInto(page, '#band-min-value', String(1 / (2 * 0.0053)));
    assert.match((await refusal(page, 'band-min')).text, /outside the allowed range 1e-12 … below 94/);
    // A final partial texel textures the region's end: no flat part, no warning.
    n1 = (await stats(page)).designsDrawn;
    await page.selectOption('#fill', 'partial');
    await nextDraw(page, n1);
    assert.equal(await page.isVisible('[data-testid=flat-warning]'), false, 'a partial last texel leaves nothing flat');
    await page.locator('#fill').scrollIntoViewIfNeeded();
    await screenshot(page, 'designer-band-layout');
    n1 = (await stats(page)).designsDrawn;
    await page.selectOption('#fill', 'whole');
    await nextDraw(page, n1);
    // .hjif, as the CLI writes it.
    const [download] = await Promise.all([page.waitForEvent('download'), page.click('[data-testid=export-hjif]')]);
    assert.equal(download.suggestedFilename(), 'texture.hjif');
    const hjif = JSON.parse(readFileSync(await download.path(), 'utf8'));
    assert.ok(Array.isArray(hjif.perceptions) && hjif.perceptions.length > 0, 'an MPEG-I Haptics file with its perceptions');
    const n2 = (await stats(page)).designsDrawn;
    await typeInto(page, '#texel-length-value', '0.25');
    await nextDraw(page, n2);
    assert.equal(await page.isVisible('[data-testid=flat-warning]'), false, 'no warning once texels cover the device');
    assert.deepEqual(errors, []);
  });
});

test('designer: Hz at a swipe speed beside every spatial frequency, and a warning above the display corner', { timeout: 120_000 }, async () => {
  await withStudio(async ({ studio, page, errors }) => {
    await openDesigner(page, studio.url);
    await page.waitForFunction(() => /Hz/.test(document.querySelector('[data-testid=pitch-cpm]').textContent));
    // The default 10 cycles/mm is 1 kHz at 100 mm/s: above the tpad's 400 Hz corner.
    assert.match(await page.textContent('[data-testid=pitch-cpm]'), /10\.000 cycles\/mm = 1000 Hz at 100 mm\/s/);
    assert.match(await page.textContent('[data-testid=irregularity-cpm]'), /Hz at 100 mm\/s/);
    assert.ok(await page.isVisible('[data-testid=drive-warning]'), 'the drive warning is shown');
    assert.match(await page.textContent('[data-testid=drive-warning]'), /1000 Hz, above tpad's response corner of 400 Hz/);
    await page.locator('[data-testid=drive-warning]').scrollIntoViewIfNeeded();
    await screenshot(page, 'designer-drive-warning');
    // At 30 mm/s the same texture drives 300 Hz: no warning.
    assert.match(await page.textContent('[data-testid=hz-note]'), /At 100 mm\/s, 1 cycle\/mm is 100 Hz; tpad's 400 Hz corner is 4\.00 cycles\/mm/);
    await typeInto(page, '#swipe-speed-value', '30');
    await page.waitForFunction(() => document.querySelector('[data-testid=drive-warning]').hidden);
    assert.match(await page.textContent('[data-testid=pitch-cpm]'), /= 300 Hz at 30 mm\/s/);
    assert.match(await page.textContent('[data-testid=hz-note]'), /At 30 mm\/s, 1 cycle\/mm is 30 Hz/);
    // The sine period's frequency too.
    await page.selectOption('#coarse-kind', 'sine');
    assert.match(await page.textContent('[data-testid=sine-period-cpm]'), /0\.200 cycles\/mm = 6\.0 Hz at 30 mm\/s/);
    // A speed of 0 is refused (no frequency at rest).
    await typeInto(page, '#swipe-speed-value', '0');
    assert.match((await refusal(page, 'swipe-speed')).text, /outside the allowed range above 0/);
    assert.deepEqual(errors, []);
  });
});

test('designer: every plot has axes with units and stated references', { timeout: 120_000 }, async () => {
  await withStudio(async ({ studio, page, errors }) => {
    await openDesigner(page, studio.url);
    // uPlot draws axis titles on its canvas; each plot's host names them (the same strings) in data-axes.
    const labels = async (id) => (await page.getAttribute(`[data-testid=${id}]`, 'data-axes')).split('|');
    assert.deepEqual(await labels('map-plot'), ['position on the surface (mm)', 'drive (0…1)']);
    assert.deepEqual(await labels('detail-plot'), ['position on the surface (mm)', 'drive (0…1)'], 'the detail plot has an amplitude scale');
    assert.deepEqual(await labels('histogram-plot'), ['texel frequency (cycles/mm)', 'texels (count)']);
    assert.deepEqual(await labels('spectrum-plot'), ['spatial frequency (cycles/mm, log)', 'dB re amplitude 1'], "the spectrum's dB has a reference");
    assert.match(await page.textContent('.plots'), /0 dB is a sine of amplitude 1 \(full drive\)/);
    // The detail plot's amplitude axis has ticks at 0, 0.5 and 1 (pixels drawn left of its plot area).
    const ink = await page.$eval('[data-testid=detail-plot] canvas', (c) => {
      const d = c.getContext('2d').getImageData(0, 0, Math.round(c.width * 0.06), c.height).data;
      let n = 0;
      for (let i = 3; i < d.length; i += 4) if (d[i]) n++;
      return n;
    });
    assert.ok(ink > 200, `the detail plot's y axis is drawn (${ink} pixels)`);
    await page.locator('[data-testid=detail-plot]').scrollIntoViewIfNeeded();
    await screenshot(page, 'designer-axes');
    assert.deepEqual(errors, []);
  });
});

test('designer: a two-region design keeps both regions in its file; .texel says it holds one', { timeout: 180_000 }, async () => {
  await withStudio(async ({ studio, page, errors }) => {
    await openDesigner(page, studio.url);
    const s0 = await stats(page);
    await page.selectOption('#regions', 'split');
    await nextDraw(page, s0.designsDrawn);
    assert.ok(await page.isDisabled('[data-testid=export-bitstream]'), 'no .texel of only the right-hand region');
    assert.match(await page.textContent('[data-testid=bitstream-note]'), /export \.texel\.json to keep both regions/);
    await typeInto(page, '#central-pitch-value', '7');
    await page.waitForTimeout(300);
    const [dl] = await Promise.all([page.waitForEvent('download'), page.click('[data-testid=export-document]')]);
    const file = artifact('two-regions.texel.json');
    await dl.saveAs(file);
    const doc = JSON.parse(readFileSync(file, 'utf8'));
    assert.equal(doc.regions.length, 2, 'both regions exported');
    assert.equal(doc.regions[0].texture.kind, 'reference');
    assert.equal(doc.regions[1].texture.central_pitch_db, 7);
    // Back to a single texture, then re-import: both regions return.
    await page.selectOption('#regions', 'single');
    await setRange(page, '#central-pitch', 3);
    await page.setInputFiles('#import-file', file);
    await page.waitForSelector('[data-testid=designer-status][data-imported]');
    assert.equal(await page.inputValue('#regions'), 'split');
    assert.equal(await page.inputValue('#reference'), doc.regions[0].texture.name);
    assert.equal(await page.inputValue('#central-pitch'), '7');
    assert.deepEqual(errors, []);
  });
});

test('designer: a raw .bin asks first, showing size and device; invalid files are refused with a message', { timeout: 180_000 }, async () => {
  await withStudio(async ({ studio, page, errors }) => {
    await openDesigner(page, studio.url);
    await page.waitForSelector('[data-testid=encoded-bytes][data-bytes]');
    const s0 = await stats(page);
    const noise = Buffer.alloc(3000);
    for (let i = 0; i < noise.length; i++) noise[i] = (i * 7919 + 13) % 251;
    await page.setInputFiles('#import-file', { name: 'noise.bin', mimeType: 'application/octet-stream', buffer: noise });
    await page.waitForSelector('[data-testid=import-confirm][open]');
    const text = await page.textContent('[data-testid=import-confirm-text]');
    assert.match(text, /3000 bytes = 1500 u16le samples/);
    assert.match(text, /device tpad/);
    assert.match(text, /8333 Hz/);
    assert.match(text, /not a whole device map/);
    await screenshot(page, 'designer-raw-bin-confirm');
    await page.click('[data-testid=import-confirm-no]');
    await page.waitForFunction(() => /cancelled; the design is unchanged/.test(document.querySelector('[data-testid=designer-status]').textContent));
    assert.equal((await stats(page)).lastMapChecksum, s0.lastMapChecksum, 'cancel leaves the design');
    // Confirmed: the engine encodes it.
    await page.setInputFiles('#import-file', { name: 'noise.bin', mimeType: 'application/octet-stream', buffer: noise });
    await page.waitForSelector('[data-testid=import-confirm][open]');
    await page.click('[data-testid=import-confirm-yes]');
    await page.waitForSelector('[data-testid=designer-status][data-imported="noise.bin"]', { timeout: 120_000 });
    // Not a whole number of samples, and a broken document: refused, said next to the Files buttons.
    for (const f of [{ name: 'odd.bin', buffer: Buffer.alloc(3001, 1) }, { name: 'broken.texel.json', buffer: Buffer.from('{"format": "texel-doc') }]) {
      await page.setInputFiles('#import-file', { ...f, mimeType: 'application/octet-stream' });
      if (f.name.endsWith('.bin')) {
        await page.waitForSelector('[data-testid=import-confirm][open]');
        assert.match(await page.textContent('[data-testid=import-confirm-text]'), /not a whole number of u16le samples/);
        await page.click('[data-testid=import-confirm-yes]');
      }
      await page.waitForSelector('[data-testid=files-error]:not([hidden])', { timeout: 30_000 });
      assert.match(await page.textContent('[data-testid=files-error]'), new RegExp(`${f.name.replace('.', '\\.')} was not imported: `));
      assert.ok(await inView(page, '[data-testid=files-error]'), 'the refusal is in view');
    }
    await screenshot(page, 'designer-import-refused');
    assert.deepEqual(errors, []);
  });
});

test('designer: the design survives a reload; undo, redo and a fresh start', { timeout: 180_000 }, async () => {
  await withStudio(async ({ studio, page, errors }) => {
    await openDesigner(page, studio.url);
    await page.waitForSelector('[data-testid=encoded-bytes][data-bytes]');
    assert.ok(await page.isDisabled('[data-testid=undo]'));
    await setRange(page, '#central-pitch', 5);
    await page.waitForTimeout(700); // a separate step (changes within 0.5 s join one)
    await setRange(page, '#texel-length', 2);
    // Reload within 100 ms of the change, inside the save's 250 ms debounce: the page's end writes
    // it (pagehide), so the design is restored from this browser whatever the machine's load.
    await page.reload();
    await page.waitForFunction(() => window.__texelStats && window.__texelStats.designsDrawn >= 1, null, { timeout: 30_000 });
    assert.equal(await page.inputValue('#central-pitch'), '5');
    assert.equal(await page.inputValue('#texel-length'), '2');
    assert.match(await page.textContent('[data-testid=saved-note]'), /Restored/);
    // Undo / redo with buttons and keys.
    await setRange(page, '#central-pitch', 7);
    await page.waitForTimeout(700);
    await setRange(page, '#texel-length', 3);
    await page.waitForTimeout(300);
    await page.focus('#central-pitch');
    await page.keyboard.press('Control+z');
    assert.equal(await page.inputValue('#texel-length'), '2', 'Ctrl+Z undid the length');
    assert.equal(await page.inputValue('#central-pitch'), '7');
    await page.click('[data-testid=undo]');
    assert.equal(await page.inputValue('#central-pitch'), '5', 'Undo undid the pitch');
    await page.focus('#central-pitch');
    await page.keyboard.press('Control+Shift+Z');
    assert.equal(await page.inputValue('#central-pitch'), '7', 'Ctrl+Shift+Z redid it');
    await page.click('[data-testid=redo]');
    assert.equal(await page.inputValue('#texel-length'), '3');
    assert.ok(await page.isDisabled('[data-testid=redo]'));
    await screenshot(page, 'designer-undo');
    // Start fresh: defaults, and a reload stays fresh.
    await page.click('[data-testid=new-design]');
    assert.equal(await page.inputValue('#central-pitch'), '10');
    await page.waitForTimeout(500);
    await page.reload();
    await page.waitForFunction(() => window.__texelStats && window.__texelStats.designsDrawn >= 1, null, { timeout: 30_000 });
    assert.equal(await page.inputValue('#central-pitch'), '10');
    assert.equal(await page.inputValue('#texel-length'), '0.25');
    assert.deepEqual(errors, []);
  });
});

test('designer: every control is labelled; the hidden file input is out of the tab order', { timeout: 120_000 }, async () => {
  await withStudio(async ({ studio, page, errors }) => {
    await openDesigner(page, studio.url);
    await page.selectOption('#regions', 'split');
    const unlabelled = await page.$$eval('.page-designer input, .page-designer select, .page-designer button, .page-designer [role=slider]', (els) =>
      els
        .filter((el) => {
          if (el.getAttribute('aria-label') || el.getAttribute('aria-labelledby')) return false;
          if (el.id && document.querySelector(`label[for="${el.id}"]`)) return false;
          if (el.closest('label')) return false;
          if (el.tagName === 'BUTTON' && el.textContent.trim()) return false;
          return true;
        })
        .map((el) => el.outerHTML.slice(0, 120)),
    );
    assert.deepEqual(unlabelled, []);
    assert.equal(await page.getAttribute('#import-file', 'tabindex'), '-1');
    assert.ok(await page.getAttribute('#import-file', 'aria-label'));
    assert.deepEqual(errors, []);
  });
});

// The same refusals, Hz and strip in Firefox ESR (puppeteer-core over WebDriver BiDi, as firefox.test.mjs).
test('designer in Firefox: typed refusals, Hz and warning, strip scale', { timeout: 240_000 }, async () => {
  const studio = await startStudio({ hardTimeoutMs: 260_000 });
  let ff;
  try {
    ff = await launchFirefox({ hardTimeoutMs: 260_000 });
    const page = await ff.browser.newPage();
    const errors = [];
    page.on('pageerror', (e) => errors.push(String(e)));
    const until = (fn, arg) => page.waitForFunction(fn, { timeout: 30_000, polling: 50 }, arg);
    const text = (sel) => page.$eval(sel, (el) => el.textContent);
    const value = (sel) => page.$eval(sel, (el) => el.value);
    const type = async (sel, t) => {
      await page.$eval(sel, (el) => el.select());
      if (t) await page.type(sel, t);
      else await page.keyboard.press('Backspace');
      await page.keyboard.press('Enter');
    };
    await page.goto(`${studio.url}#/designer`);
    await until(() => window.__texelStats && window.__texelStats.designsDrawn >= 1);
    await until(() => /Hz/.test(document.querySelector('[data-testid=pitch-cpm]').textContent));
    for (const [t, why] of [['abc', /"abc" is not a number/], ['', /enter a number/], ['45', /outside the allowed range/]]) {
      await type('#central-pitch-value', t);
      await until(() => !document.querySelector('[data-testid=central-pitch-error]').hidden);
      assert.match(await text('[data-testid=central-pitch-error]'), why);
      assert.equal(await value('#central-pitch-value'), '10');
      assert.equal(await value('#central-pitch'), '10');
    }
    await type('#seed', '3.7');
    await until(() => !document.querySelector('[data-testid=seed-error]').hidden);
    assert.equal(await value('#seed'), '1');
    assert.match(await text('[data-testid=pitch-cpm]'), /1000 Hz at 100 mm\/s/);
    assert.match(await text('[data-testid=drive-warning]'), /above tpad's response corner of 400 Hz/);
    const ticks = await page.$$eval('[data-testid=strip-scale] .tick', (els) => els.length);
    assert.equal(ticks, 11);
    await page.screenshot({ path: artifact('firefox-designer-refused.png'), fullPage: true });
    assert.deepEqual(errors, []);
  } finally {
    await ff?.close();
    await studio.stop();
  }
});
