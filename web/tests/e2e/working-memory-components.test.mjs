// The working-memory components study on the participant page, done as a
// participant does it (issue #40): the shipped protocol's coarse conditions,
// one trial each, with short phases. The page shows the source's matrix, the
// verbal digit sequence one digit at a time, and the executive 2-back stream
// with its Respond button; the test reads each off the screen, presses
// Respond while a 2-back target is shown, and answers the recall questions
// from what it saw. The export then holds exactly that score (every recall
// right, 3 hits of 3 and no false alarm), which only holds if the page showed
// the question's own sequence in order and each press reached the digit on
// screen; no screen names the condition; every message matches the schema
// (withStudio's check).
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { join } from 'node:path';
import { withStudio, screenshot, paths, startSession } from './studio.mjs';
import { exportRows } from './participant-helpers.mjs';

function protocol() {
  const p = JSON.parse(readFileSync(join(paths.protocols, 'working-memory-components.json'), 'utf8'));
  const test = p.blocks.find((b) => b.name === 'test');
  Object.assign(test, { texture_s: 0.5, matrix_s: 6, trials_per_condition: 1 });
  test.conditions = test.conditions.filter((c) => c.stimulus === 'coarse');
  p.name = 'working-memory-components-fast';
  p.blocks = [test];
  return p;
}

// In the page, from the moment the question is on screen until its answers
// show: what the distractor shows — the matrix's cells, or the sequence's
// digits by their item number — and, when there is a Respond button (2-back),
// a response while a digit equal to the one two before it is on screen: the
// first with the button, the others with the space bar (focus elsewhere).
function followDistractor() {
  return new Promise((resolve) => {
    const out = { kind: null, cells: null, seen: [], pressed: 0 };
    const poll = () => {
      const m = document.querySelector('[data-testid=matrix]');
      if (m && !out.cells) {
        out.kind = 'matrix';
        out.cells = [...m.querySelectorAll('.cell')].map((c) => c.textContent);
      }
      const d = document.querySelector('[data-testid=sequence-digit]');
      if (d) {
        const respond = document.querySelector('[data-testid=respond]');
        out.kind = respond ? '2-back' : 'sequence';
        const i = d.dataset.item === undefined || d.dataset.item === '' ? -1 : Number(d.dataset.item);
        if (i >= 0 && out.seen[i] === undefined) {
          out.seen[i] = Number(d.textContent);
          if (respond && i >= 2 && out.seen[i] === out.seen[i - 2]) {
            if (out.pressed === 0) respond.click();
            else {
              document.activeElement?.blur();
              document.dispatchEvent(new KeyboardEvent('keydown', { code: 'Space', key: ' ', bubbles: true }));
            }
            out.pressed++;
          }
        }
      }
      if (out.kind && document.querySelector('.answers:not([hidden])')) resolve(out);
      else setTimeout(poll, 10);
    };
    poll();
  });
}

test('working-memory components: matrix, digit sequence and 2-back on the participant page, scored as answered', { timeout: 300_000 }, async () => {
  await withStudio(async ({ studio, context, page, errors }) => {
    await page.goto(`${studio.url}#/experimenter`);
    await page.waitForSelector('#protocol option', { state: 'attached' });
    const p = await context.newPage();
    p.on('pageerror', (e) => errors.push(String(e)));
    const frames = []; // what the participant's page receives (readable in devtools)
    p.on('websocket', (ws) => ws.on('framereceived', (f) => typeof f.payload === 'string' && frames.push(f.payload)));
    const r = await startSession(page, protocol(), 'S-wmc');
    assert.equal(r.type, 'experiment.started', JSON.stringify(r));
    await p.goto(`${studio.url}#/participant`);
    const kinds = [];
    const texts = [];
    for (let n = 0; n < 4; n++) {
      const q = p.locator('.question');
      await q.waitFor({ timeout: 60_000 });
      const trial = Number(await q.getAttribute('data-trial'));
      const following = p.evaluate(followDistractor); // watches from now on, in the page
      await p.waitForSelector('[data-testid=matrix], [data-testid=sequence-digit]', { timeout: 20_000 });
      texts.push(await p.textContent('.question'));
      // The distractor on screen (the watcher in the page keeps following meanwhile).
      const shown = (await p.locator('[data-testid=matrix]').count()) ? 'matrix' : (await p.locator('[data-testid=respond]').count()) ? '2back' : 'sequence';
      await screenshot(p, `screen-wm-components-${shown}`);
      const { kind, cells, seen, pressed } = await following;
      kinds.push(kind);
      let answerDigit = null;
      if (kind === 'matrix') {
        assert.equal(cells.length, 16);
        const question = await p.textContent('[data-testid=digit-question]');
        const at = question.match(/row (\d), column (\d)/);
        answerDigit = at ? cells[(Number(at[1]) - 1) * 4 + Number(at[2]) - 1] : '1';
        if (!at) assert.ok(cells.every((c) => c === '1'), `the control matrix holds only 1s: ${cells}`);
      } else if (kind === '2-back') {
        assert.equal(seen.filter((x) => x !== undefined).length, 10, `ten digits one at a time: ${seen}`);
        assert.equal(pressed, 3, `three 2-back targets on screen: ${seen}`);
        assert.equal(await p.locator('[data-testid=digit-question]').count(), 0, 'the 2-back has no recall question');
      } else {
        const question = await p.textContent('[data-testid=digit-question]');
        const at = question.match(/number (\d) of the (\d)/);
        assert.ok(at, question);
        assert.equal(seen.filter((x) => x !== undefined).length, 5, `five digits one at a time: ${seen}`);
        answerDigit = String(seen[Number(at[1]) - 1]);
      }
      assert.equal(await p.locator('[data-testid=sequence-digit], [data-testid=matrix]').count(), 0, 'the distractor is gone when the questions come');
      texts.push(await p.textContent('.question'));
      await p.locator('[data-testid=choices] button').first().click();
      if (answerDigit !== null) await p.locator(`[data-testid=digit] button:text-is("${answerDigit}")`).click();
      await p.locator('[data-testid=submit]:not([disabled])').click();
      await p.waitForFunction(
        (t) => document.querySelector('[data-testid=thank-you]') || Number(document.querySelector('.question')?.dataset.trial) !== t,
        trial,
        { timeout: 60_000 },
      );
    }
    assert.deepEqual([...kinds].sort(), ['2-back', 'matrix', 'matrix', 'sequence'], String(kinds));
    const whole = texts.join('\n').toLowerCase();
    for (const word of ['coarse', 'control', 'visuospatial', 'verbal', 'executive', 'back', 'target', 'correct', 'patch'])
      assert.ok(!whole.includes(word), `the participant's screen never shows '${word}'`);
    // Nor do the frames the page receives: no condition, block, correct answer or stimulus document.
    const received = frames.join('\n');
    assert.ok(frames.some((f) => f.includes('"sequence"')), 'the page received a digit sequence');
    for (const word of ['coarse-', 'fine-', '"condition"', '"block"', 'correct_answer', '"document"', 'patch-', 'visuospatial', 'executive'])
      assert.ok(!received.includes(word), `no frame to the participant's page holds ${word}`);

    const rows = exportRows(join(studio.dir, 's.db')).filter((x) => x.protocol === 'working-memory-components-fast');
    assert.equal(rows.length, 4);
    for (const row of rows) {
      if (row.condition.endsWith('executive')) {
        assert.deepEqual([row.nback_targets, row.nback_hits, row.nback_false_alarms], ['3', '3', '0'], JSON.stringify(row));
      } else {
        assert.equal(row.digit_correct, '1', `${row.condition}: the digit read off the screen is the one asked`);
        assert.equal(row.nback_targets, '');
      }
    }
    assert.deepEqual(errors, []);
  });
});
