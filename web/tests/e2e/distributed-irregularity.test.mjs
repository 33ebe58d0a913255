// The distributed-irregularity study on the participant page, done as a
// participant does it (issue #40): the shipped protocol's test block cut to
// one level, two shifts and a control (5 trials). The studio was started as
// any lab starts it (one channel); starting the study on its four-actuator
// device reopens the presentation with four channels. In every trial the
// participant feels the three textures and answers; the export stores each
// answer and scores it, with both odd playbacks and the control; nothing on the
// screen or in the frames the page receives names the condition; every
// message matches the schema (withStudio's check).
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { join } from 'node:path';
import { withStudio, screenshot, paths, startSession } from './studio.mjs';
import { exportRows, control } from './participant-helpers.mjs';

function protocol() {
  const p = JSON.parse(readFileSync(join(paths.protocols, 'distributed-irregularity.json'), 'utf8'));
  const t = p.blocks.find((b) => b.name === 'test');
  Object.assign(t, { irregularity_levels_db: [0.7918], shifts_db: [-3, 3], repeats: 2, control_repeats: 1 });
  p.name = 'distributed-irregularity-fast';
  p.blocks = [t];
  return p;
}

test('distributed irregularity: three textures felt per trial on four channels, scored as answered, nothing of the condition shown', { timeout: 300_000 }, async () => {
  await withStudio(async ({ studio, context, page, errors }) => {
    await page.goto(`${studio.url}#/experimenter`);
    await page.waitForSelector('#protocol option', { state: 'attached' });
    const p = await context.newPage();
    p.on('pageerror', (e) => errors.push(String(e)));
    const frames = [];
    p.on('websocket', (ws) => ws.on('framereceived', (f) => typeof f.payload === 'string' && frames.push(f.payload)));
    const r = await startSession(page, protocol(), 'S-di');
    assert.equal(r.type, 'experiment.started', JSON.stringify(r));
    await p.goto(`${studio.url}#/participant`);
    const texts = [];
    const answered = [];
    for (let n = 0; n < 5; n++) {
      const q = p.locator('.question');
      await q.waitFor({ timeout: 60_000 });
      const trial = Number(await q.getAttribute('data-trial'));
      assert.deepEqual(await p.locator('button.stimulus').allTextContents(), ['Feel texture 1', 'Feel texture 2', 'Feel texture 3']);
      for (let i = 0; i < 3; i++) {
        await p.locator('button.stimulus').nth(i).click();
        await p.waitForSelector(`button.stimulus:nth-child(${i + 1})[aria-pressed=true]`);
      }
      // What the presentation is playing: four channels, the texture just selected.
      const [state] = await control(page, { type: 'feel.state' });
      assert.match(state.backend ?? '', /4 channels/, JSON.stringify(state));
      if (n === 0) await screenshot(p, 'participant-distributed-irregularity');
      texts.push(await p.textContent('.participant'));
      const answer = String((n % 3) + 1);
      answered.push(answer);
      await p.locator(`[data-testid=choices] button:text-is("texture ${answer}")`).click();
      await p.locator('[data-testid=submit]:not([disabled])').click();
      await p.waitForFunction(
        (t) => document.querySelector('[data-testid=thank-you]') || Number(document.querySelector('.question')?.dataset.trial) !== t,
        trial,
        { timeout: 60_000 },
      );
    }
    const whole = texts.join('\n').toLowerCase();
    for (const word of ['simultaneous', 'sequential', 'control', 'irregularity', 'shift', 'playback', 'correct', 'pad-4'])
      assert.ok(!whole.includes(word), `the participant's screen never shows '${word}'`);
    const received = frames.join('\n');
    for (const word of ['simultaneous', 'sequential', '"condition"', '"block"', 'correct_answer', '"document"', 'irregularity'])
      assert.ok(!received.includes(word), `no frame to the participant's page holds ${word}`);

    const rows = exportRows(join(studio.dir, 's.db')).filter((x) => x.protocol === 'distributed-irregularity-fast');
    assert.equal(rows.length, 5);
    assert.deepEqual(rows.map((x) => x.response), answered);
    for (const x of rows) assert.equal(x.correct, x.response === x.correct_answer ? '1' : '0', JSON.stringify(x));
    assert.deepEqual(rows.map((x) => x.condition).sort(), ['control', 'odd-sequential', 'odd-sequential', 'odd-simultaneous', 'odd-simultaneous']);
    assert.ok(rows.every((x) => x.task === 'playback-oddity'));
    assert.deepEqual(errors, []);
  });
});
