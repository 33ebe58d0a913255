// Experiments: the experimenter starts guided-exploration for a participant;
// the participant screen completes the whole session by clicking (select the
// stimuli, A/B/Unsure + Submit, then the ratings); a reload mid-session shows
// the same trial; the experimenter view shows the session finished.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { withStudio, screenshot } from './studio.mjs';

async function currentTrial(page) {
  const el = await page.waitForSelector('[data-testid=trial-number], [data-testid=thank-you]', { timeout: 60_000 });
  if ((await el.getAttribute('data-testid')) === 'thank-you') return null;
  return Number(await el.getAttribute('data-trial'));
}

test('experiment: guided-exploration through the participant screen, with a reload', { timeout: 600_000 }, async () => {
  await withStudio(async ({ studio, context, page, errors }) => {
    // Experimenter starts the protocol.
    await page.goto(`${studio.url}#/experimenter`);
    await page.waitForSelector('#protocol option[value="guided-exploration"]', { state: 'attached' });
    await page.selectOption('#protocol', 'guided-exploration');
    await page.fill('#participant', 'P07');
    await page.click('[data-testid=start]');
    await page.waitForFunction(() => /P07/.test(document.querySelector('[data-testid=active-session]')?.textContent ?? ''), null, { timeout: 60_000 });
    await screenshot(page, 'experimenter-started');

    // Participant screen in a second tab.
    const p = await context.newPage();
    p.on('pageerror', (e) => errors.push(String(e)));
    await p.goto(`${studio.url}#/participant`);
    let trial = await currentTrial(p);
    assert.equal(trial, 0);
    const tasks = new Map();
    let reloaded = false;
    let answered = 0;
    let rng = 7;
    const rand = (n) => ((rng = (rng * 1103515245 + 12345) % 2 ** 31), rng % n);

    while (trial !== null) {
      const q = p.locator('.question');
      const task = await q.getAttribute('data-task');
      tasks.set(task, (tasks.get(task) ?? 0) + 1);
      // The question never shows the answer: no maps unless show_maps, no "correct" text.
      assert.equal(await p.locator('.mini-map').count(), 0);

      if (trial === 5 && !reloaded) {
        // Reload mid-session: the same trial comes back.
        await p.locator('[data-testid=choices] button').first().click();
        await p.reload();
        reloaded = true;
        assert.equal(await currentTrial(p), trial, 'the same trial after a reload');
      }
      const stimuli = p.locator('button.stimulus');
      const n = await stimuli.count();
      for (let i = 0; i < n; i++) {
        await stimuli.nth(i).click();
        await p.waitForTimeout(5);
      }
      if (task === 'guided') {
        const labels = await p.locator('[data-testid=choices] button').allTextContents();
        assert.deepEqual(labels, ['A', 'B', 'Unsure']);
        // The choice's heading is the library's wording (question.wording.choice_question), as the terminal's.
        assert.equal(await p.locator('#answer-heading').textContent(), 'More like the reference');
        await p.getByRole('radio', { name: `More like the reference: ${['A', 'B', 'Unsure'][rand(3)]}` }).click();
      } else if (task === 'rating') {
        const buttons = p.locator('[data-testid=rating] button');
        await buttons.nth(rand(await buttons.count())).click();
      } else {
        assert.fail(`unexpected task ${task}`);
      }
      if (answered === 3) await screenshot(p, `participant-${task}`);
      const submit = p.locator('[data-testid=submit]');
      await submit.click();
      // No double answers: Submit is disabled until the engine replied.
      answered++;
      const next = await p.waitForFunction(
        (t) => {
          const el = document.querySelector('[data-testid=trial-number]');
          if (document.querySelector('[data-testid=thank-you]')) return 'done';
          return el && Number(el.dataset.trial) !== t ? el.dataset.trial : false;
        },
        trial,
        { timeout: 60_000 },
      );
      const v = await next.jsonValue();
      trial = v === 'done' ? null : Number(v);
      if (trial !== null && tasks.get('rating') === 1 && task === 'rating') await screenshot(p, 'participant-rating');
    }
    await screenshot(p, 'participant-thank-you');
    assert.ok(reloaded);
    assert.ok(tasks.get('guided') >= 30, `guided trials: ${tasks.get('guided')}`);
    assert.ok(tasks.get('rating') >= 9, `rating trials: ${tasks.get('rating')}`);

    // The experimenter view shows the session finished.
    await page.bringToFront();
    await page.waitForFunction(
      () => [...document.querySelectorAll('[data-testid=sessions] tbody tr')].some((r) => /P07/.test(r.textContent) && r.dataset.finished === 'true'),
      null,
      { timeout: 30_000 },
    );
    await screenshot(page, 'experimenter-finished');
    assert.deepEqual(errors, []);
  });
});

test('experiment: a simulated session run from the experimenter view', { timeout: 300_000 }, async () => {
  await withStudio(async ({ studio, page, errors }) => {
    await page.goto(`${studio.url}#/experimenter`);
    await page.waitForSelector('#protocol option[value="texel-length"]', { state: 'attached' });
    await page.selectOption('#protocol', 'texel-length');
    await page.fill('#participant', 'SIM1');
    await page.fill('#simulate', 'threshold=6mm');
    await page.click('[data-testid=start]');
    await page.click('[data-testid=simulate-run]', { timeout: 30_000 });
    await page.waitForFunction(
      () => [...document.querySelectorAll('[data-testid=sessions] tbody tr')].some((r) => /SIM1/.test(r.textContent) && r.dataset.finished === 'true'),
      null,
      { timeout: 240_000 },
    );
    await screenshot(page, 'experimenter-simulated');
    assert.deepEqual(errors, []);
  });
});
