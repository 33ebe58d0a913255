// Firefox: the core flows of the studio in Debian's Firefox ESR, driven by
// puppeteer-core over WebDriver BiDi (playwright-core cannot drive a stock
// Firefox). Against the real `texel studio` (null backend):
//   designer    "connected"; the map, histogram and spectrum drawn (the
//               page's window.__texelStats and non-blank uPlot canvases);
//   slider      Central Pitch moved with the keyboard and with a click on
//               its track: the map, its pixels and the encoded bitstream
//               change, and a seed ≥ 2^14 grows the encoded size;
//   Feel it     a mouse sweep over the strip: #player-position follows;
//   experiment  the experimenter view refuses a participant id with a space
//               (its input pattern) and starts guided-exploration; the
//               participant screen (a second tab) renders trial 1, takes an
//               answer by clicking and moves on to trial 2.
// Screenshots: $TEXEL_ARTIFACTS/firefox-*.png. No page error may occur.
// Firefox missing (/usr/bin/firefox-esr, or $TEXEL_FIREFOX) is a failure.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { startStudio, launchFirefox, artifact, paths } from './studio.mjs';

const TPAD_MM = 19200 * 0.0053;
const TOL_MM = 3;
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

// puppeteer's waitForFunction takes (fn, options, ...args); poll on a timer,
// not requestAnimationFrame (a tab in the background gets no frames).
const until = (page, fn, arg, timeout = 30_000) => page.waitForFunction(fn, { timeout, polling: 50 }, arg);
const stats = (page) => page.evaluate(() => JSON.parse(JSON.stringify(window.__texelStats)));
const shot = (page, name) => page.screenshot({ path: artifact(`firefox-${name}.png`), fullPage: true });
const attr = (page, sel, name) => page.$eval(sel, (el, n) => el.getAttribute(n), name);
const text = (page, sel) => page.$eval(sel, (el) => el.textContent);

/** Non-transparent pixels of a plot's uPlot canvas (0: nothing drawn) and a hash of them. */
function plotPixels(page, testid) {
  return page.$eval(`[data-testid=${testid}] canvas`, (c) => {
    const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
    let ink = 0;
    let h = 0;
    for (let i = 0; i < d.length; i += 4) {
      if (d[i + 3]) ink++;
      h = (h * 31 + d[i] + 7 * d[i + 1] + 13 * d[i + 2]) >>> 0;
    }
    return { ink, hash: h, w: c.width, h: c.height };
  });
}

async function box(page, sel) {
  const el = await page.waitForSelector(sel, { timeout: 30_000 });
  await el.evaluate((e) => e.scrollIntoView({ block: 'center' }));
  const b = await el.boundingBox();
  assert.ok(b && b.width > 0, `${sel} is visible`);
  return b;
}

/** Resolves fn()'s result, or rejects after ms (so teardown runs even if a browser call hangs). */
function deadline(ms, fn) {
  let timer;
  return Promise.race([
    fn().finally(() => clearTimeout(timer)),
    new Promise((_, rej) => (timer = setTimeout(() => rej(new Error(`firefox test body still running after ${ms} ms`)), ms))),
  ]);
}

test('firefox: designer, slider, Feel it sweep and a participant trial in Firefox ESR', { timeout: 300_000 }, async () => {
  const studio = await startStudio({ hardTimeoutMs: 330_000 });
  let ff;
  try {
    ff = await launchFirefox({ hardTimeoutMs: 330_000 });
    const { browser } = ff;
    const version = await browser.version();
    console.log(`browser: ${version} (${paths.firefox})`);
    assert.match(version, /firefox/i);
    await deadline(240_000, () => flows(browser, studio.url));
  } finally {
    await ff?.close();
    await studio.stop();
  }
});

async function flows(browser, url) {
  const errors = [];
  const consoleErrors = [];
  const watch = (p) => {
    p.on('pageerror', (e) => errors.push(String(e)));
    p.on('console', (m) => m.type() === 'error' && consoleErrors.push(m.text()));
  };
  const page = await browser.newPage();
  watch(page);

  // ---- designer: connected, first design drawn in all three plots
  await page.goto(`${url}#/designer`);
  await until(page, () => document.querySelector('#connection')?.dataset.state === 'open');
  assert.equal(await text(page, '#connection'), 'connected');
  await until(page, () => window.__texelStats && window.__texelStats.designsDrawn >= 1);
  await page.waitForSelector('[data-testid=encoded-bytes][data-bytes]');
  await sleep(300); // the spectrum and detail redraw in the same task; let layout settle
  const s0 = await stats(page);
  assert.ok(s0.lastMapChecksum !== null && s0.lastHistChecksum !== null, 'map and histogram data plotted');
  const px0 = {};
  for (const plot of ['map-plot', 'histogram-plot', 'spectrum-plot']) {
    px0[plot] = await plotPixels(page, plot);
    assert.ok(px0[plot].w > 100 && px0[plot].h > 50, `${plot} canvas has a size (${px0[plot].w}×${px0[plot].h})`);
    assert.ok(px0[plot].ink > 1000, `${plot} drawn (${px0[plot].ink} pixels inked)`);
  }
  const hex0 = await attr(page, '[data-testid=encoded-hex]', 'title');
  const bytes0 = Number(await attr(page, '[data-testid=encoded-bytes]', 'data-bytes'));
  assert.ok(bytes0 > 0, `encoded size shown (${bytes0})`);
  await shot(page, 'designer-initial');

  // ---- Central Pitch: keyboard (each press an input event), then a click on the track
  const pitch0 = await page.$eval('#central-pitch', (el) => el.value);
  await page.focus('#central-pitch');
  for (let i = 0; i < 15; i++) await page.keyboard.press('ArrowRight');
  await until(page, (v) => document.querySelector('#central-pitch').value !== v, pitch0);
  await until(page, (n) => window.__texelStats.designsDrawn > n, s0.designsDrawn);
  await sleep(400); // the last coalesced design lands
  const s1 = await stats(page);
  const pitch1 = await page.$eval('#central-pitch', (el) => el.value);
  assert.ok(Number(pitch1) > Number(pitch0), `the keyboard moved the slider (${pitch0} → ${pitch1})`);
  assert.notEqual(s1.lastMapChecksum, s0.lastMapChecksum, 'the map changed');
  assert.notEqual(s1.lastHistChecksum, s0.lastHistChecksum, 'the histogram changed');
  assert.notEqual((await plotPixels(page, 'map-plot')).hash, px0['map-plot'].hash, 'the map was redrawn');
  const hex1 = await attr(page, '[data-testid=encoded-hex]', 'title');
  assert.notEqual(hex1, hex0, 'the encoded bitstream changed');
  assert.match(await text(page, '[data-testid=pitch-cpm]'), /cycles\/mm/);

  const track = await box(page, '#central-pitch');
  await page.mouse.click(Math.round(track.x + track.width * 0.85), Math.round(track.y + track.height / 2));
  await until(page, (v) => document.querySelector('#central-pitch').value !== v, pitch1);
  await until(page, (n) => window.__texelStats.designsDrawn > n, s1.designsDrawn);
  await sleep(400);
  const s2 = await stats(page);
  const pitch2 = await page.$eval('#central-pitch', (el) => el.value);
  assert.ok(Number(pitch2) > Number(pitch1), `a click on the track moved the slider (${pitch1} → ${pitch2})`);
  assert.notEqual(s2.lastMapChecksum, s1.lastMapChecksum, 'the map changed again');
  assert.notEqual(await attr(page, '[data-testid=encoded-hex]', 'title'), hex1, 'the encoded bitstream changed again');
  assert.equal(s2.lastEncodedBytes, Number(await attr(page, '[data-testid=encoded-bytes]', 'data-bytes')), 'shown size = drawn size');

  // A seed of 2^14 or more needs a longer varint: the encoded size grows.
  await page.$eval('#seed', (el) => el.select());
  await page.type('#seed', '20000');
  await page.keyboard.press('Tab'); // commits the number input: a change event
  await until(page, (n) => window.__texelStats.designsDrawn > n, s2.designsDrawn);
  await sleep(300);
  const s3 = await stats(page);
  assert.ok(s3.lastEncodedBytes > s2.lastEncodedBytes, `encoded size grew with the seed (${s2.lastEncodedBytes} → ${s3.lastEncodedBytes})`);
  await shot(page, 'designer-after-slider');

  // ---- Feel it: a mouse sweep at a hand's pace (~1 mm per 10 ms); hovering touches.
  // Hear it on: the AudioWorklet synthesizes from the map as the pointer moves.
  await page.click('#hear-it');
  const b = await box(page, '[data-testid=feel-strip]');
  assert.ok(b.width > 100, 'the strip is visible');
  const y = Math.round(b.y + b.height / 2);
  const xAt = (f) => Math.round(b.x + 2 + f * (b.width - 4));
  await page.mouse.move(xAt(0.1), y);
  const seen = [];
  let f = 0.1;
  for (const g of [0.3, 0.5, 0.7, 0.9]) {
    const steps = Math.max(1, Math.round(Math.abs(g - f) * TPAD_MM));
    for (let k = 1; k <= steps; k++) {
      await page.mouse.move(xAt(f + ((g - f) * k) / steps), y);
      await sleep(10);
    }
    f = g;
    const want = ((xAt(g) - b.x) / b.width) * TPAD_MM;
    await until(
      page,
      ([w, tol]) => {
        const el = document.querySelector('#player-position');
        return el?.dataset.mm !== '' && Math.abs(Number(el.dataset.mm) - w) <= tol;
      },
      [want, TOL_MM],
      10_000,
    ).catch(async (e) => {
      throw new Error(`player not at ${want.toFixed(2)} mm (±${TOL_MM}): shows ${await attr(page, '#player-position', 'data-mm')} mm; ${e.message}`);
    });
    seen.push(Number(await attr(page, '#player-position', 'data-mm')));
  }
  for (let i = 1; i < seen.length; i++) assert.ok(seen[i] > seen[i - 1], `positions increase: ${seen.join(', ')}`);
  await until(page, () => document.querySelector('#player-position').dataset.touching === 'true');
  await shot(page, 'feel-mouse');
  // Leaving the strip lifts the finger.
  await page.mouse.move(Math.round(b.x + b.width / 2), Math.max(1, Math.round(b.y - 200)));
  await until(page, () => document.querySelector('#player-position').dataset.touching === 'false', undefined, 10_000);
  const s4 = await stats(page);
  assert.ok(s4.feelAcks > 0 && s4.feelAcks <= s4.feelMovesSent, `acks ${s4.feelAcks} of ${s4.feelMovesSent}`);
  assert.ok(await page.$eval('#hear-it', (el) => el.checked), 'Hear it stayed on (the worklet started)');
  assert.equal(await text(page, '[data-testid=designer-status]'), '');

  // ---- experimenter view starts guided-exploration; the participant answers trial 1
  await page.goto(`${url}#/experimenter`);
  await page.waitForSelector('#protocol option[value="guided-exploration"]', { timeout: 30_000 });
  await page.select('#protocol', 'guided-exploration');
  // The participant id's pattern is checked (it was an invalid `v`-flag regexp: ignored).
  await page.click('#participant');
  await page.type('#participant', 'F F!');
  assert.ok(await page.$eval('#participant', (el) => el.validity.patternMismatch), 'an id with a space is refused');
  await page.$eval('#participant', (el) => (el.value = ''));
  await page.type('#participant', 'FF01');
  assert.ok(await page.$eval('#participant', (el) => el.validity.valid), 'FF01 is a valid id');
  await page.click('[data-testid=start]');
  await until(page, () => /FF01/.test(document.querySelector('[data-testid=active-session]')?.textContent ?? ''), undefined, 60_000);
  await shot(page, 'experimenter-started');

  const p = await browser.newPage();
  watch(p);
  await p.bringToFront();
  await p.goto(`${url}#/participant`);
  await p.waitForSelector('[data-testid=trial-number]', { timeout: 60_000 });
  assert.equal(await attr(p, '[data-testid=trial-number]', 'data-trial'), '0');
  assert.equal(await attr(p, '.question', 'data-task'), 'guided');
  assert.equal(await p.$$eval('.mini-map', (els) => els.length), 0, 'no maps on the participant screen');
  const nStimuli = await p.$$eval('button.stimulus', (els) => els.length);
  assert.ok(nStimuli >= 2, `stimuli shown (${nStimuli})`);
  for (let i = 0; i < nStimuli; i++) {
    await p.click(`button.stimulus[data-stimulus="${i}"]`);
    await until(p, (k) => document.querySelector(`button.stimulus[data-stimulus="${k}"]`).getAttribute('aria-pressed') === 'true', i);
  }
  assert.deepEqual(await p.$$eval('[data-testid=choices] button', (els) => els.map((e) => e.textContent)), ['A', 'B', 'Unsure']);
  assert.ok(await p.$eval('[data-testid=submit]', (el) => el.disabled), 'Submit waits for an answer');
  await p.click('[data-testid=choices] button[data-value]');
  await until(p, () => !document.querySelector('[data-testid=submit]').disabled);
  await shot(p, 'participant-trial');
  await p.click('[data-testid=submit]');
  await until(
    p,
    () => document.querySelector('[data-testid=thank-you]') || document.querySelector('[data-testid=trial-number]')?.dataset.trial === '1',
    undefined,
    60_000,
  );
  assert.equal(await attr(p, '[data-testid=trial-number]', 'data-trial'), '1', 'the next trial came');
  assert.equal(await text(p, '[data-testid=participant-status]'), '');
  await shot(p, 'participant-next-trial');

  // The experimenter view counts the answered trial.
  await page.bringToFront();
  await until(page, () => /^1 \//.test(document.querySelector('[data-testid=active-progress]')?.textContent ?? ''), undefined, 30_000);
  await shot(page, 'experimenter-progress');

  if (consoleErrors.length) console.log(`console errors (not failures): ${consoleErrors.join(' | ')}`);
  assert.deepEqual(errors, []);
}
