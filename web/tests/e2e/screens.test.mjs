// Every participant screen renders from the engine's question and takes an
// answer by clicking: oddity with its countdown (texel-length), two sliders +
// confidence (free-exploration), the coarse two-reference choice
// (coarse-features) and the timed working-memory trial (stimulus, 4 × 4
// matrix, stimulus, then same/different + digit recall; the protocol's 10 s
// phases shortened to 1 s here). Then the experimenter suspends the running
// session and resumes an earlier one from the sessions table: the
// participant continues at its next unanswered trial.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { join } from 'node:path';
import { withStudio, screenshot, paths, withoutPractice, startSession } from './studio.mjs';

function protocol(name, edit = (p) => p) {
  return edit(JSON.parse(readFileSync(join(paths.protocols, `${name}.json`), 'utf8')));
}

const start = startSession;

/** Answers the question on screen by clicking; returns the task answered. */
async function answer(p) {
  const q = p.locator('.question');
  await q.waitFor({ timeout: 60_000 });
  const task = await q.getAttribute('data-task');
  const trial = Number(await q.getAttribute('data-trial'));
  // Timed phases first (working memory): the answers appear after them.
  await p.locator('.answers:not([hidden])').waitFor({ timeout: 60_000 });
  const stimuli = p.locator('button.stimulus');
  for (let i = 0; i < (await stimuli.count()); i++) if (await stimuli.nth(i).isEnabled()) await stimuli.nth(i).click();
  for (const s of await p.locator('.answers input[type=range]').all()) {
    const box = await s.boundingBox();
    await p.mouse.click(box.x + box.width * 0.3, box.y + box.height / 2); // a click on the track moves the slider
  }
  for (const g of await p.locator('.answers [role=radiogroup]').all()) await g.locator('button').last().click();
  await p.locator('[data-testid=submit]:not([disabled])').click();
  await p.waitForTimeout(50);
  const status = await p.textContent('[data-testid=participant-status]').catch(() => '');
  assert.ok(!status, `${task}: ${status}`);
  await p.waitForFunction(
    (t) => document.querySelector('[data-testid=thank-you]') || Number(document.querySelector('.question')?.dataset.trial) !== t,
    trial,
    { timeout: 60_000 },
  );
  return task;
}

test('participant screens: oddity, match + confidence, two-alternative, working memory; suspend and resume', { timeout: 600_000 }, async () => {
  await withStudio(async ({ studio, context, page, errors }) => {
    await page.goto(`${studio.url}#/experimenter`);
    await page.waitForSelector('#protocol option', { state: 'attached' });
    const p = await context.newPage();
    p.on('pageerror', (e) => errors.push(String(e)));

    // Oddity: three stimuli, choices 1–3, the countdown of time_limit_s.
    let r = await start(page, withoutPractice('texel-length'), 'S-odd');
    assert.equal(r.type, 'experiment.started', JSON.stringify(r));
    await p.goto(`${studio.url}#/participant`);
    await p.waitForSelector('.question[data-task=oddity]');
    assert.equal(await p.locator('button.stimulus').count(), 3);
    assert.match(await p.textContent('[data-testid=countdown]'), /\d+ s left/);
    await screenshot(p, 'screen-oddity');
    assert.equal(await answer(p), 'oddity');
    assert.equal(await answer(p), 'oddity');

    // Matching: two sliders (previews while moving) and a 1–5 confidence.
    r = await start(page, 'free-exploration', 'S-match');
    assert.equal(r.type, 'experiment.started', JSON.stringify(r));
    await p.reload();
    await p.waitForSelector('.question[data-task=match]');
    assert.equal(await p.locator('.answers input[type=range]').count(), 2);
    assert.equal(await p.locator('[data-testid=confidence] button').count(), 5);
    await screenshot(p, 'screen-match');
    assert.equal(await answer(p), 'match');

    // Coarse two-reference choice: stimuli A, B, Test; answer A or B.
    r = await start(page, 'coarse-features', 'S-coarse');
    assert.equal(r.type, 'experiment.started', JSON.stringify(r));
    await p.reload();
    await p.waitForSelector('.question[data-task=two-alternative]');
    await screenshot(p, 'screen-two-alternative');
    assert.equal(await answer(p), 'two-alternative');

    // Working memory with 1 s phases: the matrix appears, then the questions.
    const wm = protocol('working-memory', (x) => {
      x.name = 'working-memory-fast';
      // The familiarisation (untimed, first) is audited on its own; here the timed trials.
      x.blocks = x.blocks.filter((b) => b.task !== 'familiarisation');
      for (const b of x.blocks) Object.assign(b, { texture_s: 1, matrix_s: 1 });
      return x;
    });
    r = await start(page, wm, 'S-wm');
    assert.equal(r.type, 'experiment.started', JSON.stringify(r));
    await p.reload();
    await p.waitForSelector('.question[data-task=same-different]');
    await p.waitForSelector('[data-testid=matrix]', { timeout: 10_000 });
    assert.equal(await p.locator('[data-testid=matrix] .cell').count(), 16);
    await screenshot(p, 'screen-working-memory-matrix');
    await p.locator('.answers:not([hidden])').waitFor({ timeout: 10_000 });
    assert.equal(await p.locator('[data-testid=matrix]').count(), 0, 'the matrix is gone when the questions come');
    await screenshot(p, 'screen-working-memory-recall');
    assert.equal(await answer(p), 'same-different');

    // Suspend from the experimenter view; resume the oddity session (two
    // trials answered, suspended when the next protocol started) from the
    // sessions table: the participant continues at its trial 2.
    await page.reload();
    await page.waitForSelector('[data-testid=stop]');
    await page.click('[data-testid=stop]');
    await p.reload();
    await p.waitForSelector('[data-testid=waiting]');
    await page.waitForSelector('tr:has-text("S-odd") button:has-text("Resume")');
    await page.click('tr:has-text("S-odd") button:has-text("Resume")');
    await p.waitForSelector('.question[data-task=oddity]', { timeout: 30_000 });
    assert.equal(await p.getAttribute('.question', 'data-trial'), '2', 'resumed at the next unanswered trial');
    await page.waitForFunction(() => /S-odd/.test(document.querySelector('[data-testid=active-session]').textContent));
    await screenshot(page, 'experimenter-resumed');
    assert.deepEqual(errors, []);
  });
});
