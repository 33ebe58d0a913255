// The participant screen's session-following and the token rule in Firefox
// ESR (puppeteer-core over WebDriver BiDi; participant.test.mjs is the
// Chromium run with more cases): a stale screen's answer after a session
// switch is refused with a sentence and nothing is stored; suspend shows
// "Please wait" without countdown and resume the same trial with its clock;
// a reload keeps the countdown; stop shows "Please wait".
// Screenshots: $TEXEL_ARTIFACTS/firefox-participant-*.png.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { startStudio, launchFirefox, artifact, withoutPractice } from './studio.mjs';

const TL = withoutPractice('texel-length'); // the first question is a timed staircase trial
import { control, STALE_HOOK } from './participant-helpers.mjs';

const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
const until = (page, fn, arg, timeout = 30_000) => page.waitForFunction(fn, { timeout, polling: 50 }, arg);
const shot = (page, name) => page.screenshot({ path: artifact(`firefox-participant-${name}.png`), fullPage: true });
const text = (page, sel) => page.$eval(sel, (el) => el.textContent);
const endsIn = (page) => page.$eval('[data-testid=countdown]', (el) => Number(el.dataset.left));



test('firefox: the participant screen follows the session; a stale answer is refused', { timeout: 300_000 }, async () => {
  const studio = await startStudio({ hardTimeoutMs: 330_000 });
  let ff;
  try {
    ff = await launchFirefox({ hardTimeoutMs: 330_000 });
    const errors = [];
    const page = await ff.browser.newPage();
    page.on('pageerror', (e) => errors.push(String(e)));
    await page.goto(`${studio.url}#/experimenter`);
    const p = await ff.browser.newPage();
    p.on('pageerror', (e) => errors.push(String(e)));
    await p.evaluateOnNewDocument(STALE_HOOK);
    await p.goto(`${studio.url}#/participant`);
    await p.waitForSelector('[data-testid=waiting]');

    let [r] = await control(page, { type: 'experiment.start', protocol: TL, participant: 'FZ1' });
    assert.equal(r.type, 'experiment.started', JSON.stringify(r));
    await p.waitForSelector('.question[data-task=oddity]', { timeout: 60_000 });
    assert.equal(await text(p, '#answer-heading'), 'The odd one is');
    await shot(p, 'oddity');

    // A stale screen answers Z1's trial after the switch to Z2: refused, nothing stored.
    await p.evaluate(() => (window.__dropPushes = true));
    await control(page, { type: 'experiment.stop' }, { type: 'experiment.start', protocol: TL, participant: 'FZ2' });
    await p.click('[data-testid=choices] button');
    await until(p, () => !document.querySelector('[data-testid=submit]').disabled);
    await p.click('[data-testid=submit]');
    await until(p, () => !document.querySelector('[data-testid=participant-notice]').hidden);
    assert.match(await text(p, '[data-testid=participant-notice]'), /another session is running/);
    await shot(p, 'refused');
    const [list] = await control(page, { type: 'experiment.list' });
    assert.deepEqual(list.sessions.map((s) => s.trials_done), [0, 0], 'nothing stored');
    await p.evaluate(() => (window.__dropPushes = false));
    assert.equal(await p.$$eval('.question', (els) => els.length), 0, 'the refused question left the screen');
    await p.waitForSelector('.question[data-trial="0"]');

    // Suspend → wait without countdown; resume → the same trial, the clock where it stopped.
    await sleep(1000);
    const before = await endsIn(p);
    await control(page, { type: 'experiment.suspend' });
    await p.waitForSelector('[data-testid=waiting]');
    assert.equal(await p.$$eval('[data-testid=countdown]', (els) => els.length), 0);
    await shot(p, 'suspended');
    await sleep(2500);
    [r] = await control(page, { type: 'experiment.resume' });
    assert.equal(r.type, 'experiment.question');
    await p.waitForSelector('.question[data-trial="0"]');
    const after = await endsIn(p);
    assert.ok(Math.abs(after - before) < 1, `countdown ${before} → ${after} s across a 2.5 s pause`);

    // A reload keeps the countdown.
    await sleep(2000);
    await p.reload();
    await p.waitForSelector('.question[data-trial="0"]');
    const reloaded = await endsIn(p);
    assert.ok(reloaded < after - 1.5, `a reload does not restart the countdown: ${after} → ${reloaded}`);

    // Stop → wait.
    await control(page, { type: 'experiment.stop' });
    await p.waitForSelector('[data-testid=waiting]');
    await shot(p, 'stopped');
    assert.deepEqual(errors, []);
  } finally {
    await ff?.close();
    await studio.stop();
  }
});
