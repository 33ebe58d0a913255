// The experimenter view a lab can use (issue #22 item 5): a simulated
// texel-length session followed live (staircase track with reversals,
// correctness per trial, progress with times), the session list with dates
// and states (a running session offers Stop, never Resume), plain-word
// errors, exports (CSV, .mat, analysis figures) as download links, and the
// protocol editor: a shipped template as a form, refused by the engine's
// validation with the field named, a designed texture put into a block as a
// saved stimulus, and the edited protocol started.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { withStudio, screenshot, openDesigner, askStudio } from './studio.mjs';

const rowOf = (page, code) => page.locator(`[data-testid=sessions] tbody tr:has(td:text-is("${code}"))`);

async function download(page, locator) {
  const [d] = await Promise.all([page.waitForEvent('download'), locator.click()]);
  return { name: d.suggestedFilename(), data: readFileSync(await d.path()) };
}

test('experimenter view: live track, sessions, exports, protocol editor', { timeout: 600_000 }, async () => {
  await withStudio(async ({ studio, page, errors }) => {
    // A designed texture saved as a named stimulus (designer, same browser).
    await openDesigner(page, studio.url);
    await page.fill('[data-testid=stimulus-name]', 'fine grating');
    await page.click('[data-testid=save-stimulus]');
    assert.match(await page.textContent('[data-testid=stimulus-status]'), /Saved "fine grating"/);

    await page.goto(`${studio.url}#/experimenter`);
    await page.waitForSelector('#protocol option[value="texel-length"]', { state: 'attached' });
    await page.selectOption('#protocol', 'texel-length');
    await page.fill('#participant', 'SIM1');
    await page.fill('#simulate', 'threshold=20mm'); // near the start (26 mm): reversals within the first staircase trials
    await page.click('[data-testid=start]');

    // Running: the row offers Stop, not Resume.
    const run = rowOf(page, 'SIM1');
    await run.locator('[data-testid=session-state]:text-is("running")').waitFor({ timeout: 30_000 });
    assert.equal(await run.getByRole('button', { name: /^Resume/ }).count(), 0, 'a running session offers no Resume');
    assert.equal(await run.getByRole('button', { name: /^Stop/ }).count(), 1);
    assert.match(await run.locator('td').nth(4).textContent(), /^\d{4}-\d\d-\d\d \d\d:\d\d$/, 'start date');

    // Simulated answers for a while: the track and the trial table follow.
    // (ten untimed practice trials first, then the staircase)
    await askStudio(page, [], { simulated: 25 });
    await page.waitForFunction(() => Number(document.querySelector('.page-experimenter')?.dataset.trialsShown ?? 0) >= 25, null, { timeout: 60_000 });
    await page.waitForSelector('[data-testid=staircase-plot] canvas');
    const caption = await page.textContent('[data-testid=staircase-caption]');
    assert.match(caption, /texel_length_mm per trial \(\d+ trials, \d+ reversals/);
    assert.ok(Number(caption.match(/(\d+) reversals/)[1]) >= 1, caption);
    const marks = await page.locator('[data-testid=trial-correct]').allTextContents();
    assert.ok(marks.some((m) => /\(correct\)/.test(m)) && marks.some((m) => /\(wrong\)/.test(m)), marks.join('|'));
    assert.match(await page.textContent('[data-testid=session-times]'), /trials answered · started .* · running for .* · median reaction time/);
    assert.match(await page.textContent('[data-testid=active-progress]'), /^\d+ trials \(adaptive\)|^\d+ \/ \d+ trials/);
    await screenshot(page, 'experimenter-live-track');

    // Stop: the row becomes stopped (resumable) and offers Resume.
    await page.click('[data-testid=stop]');
    await run.locator('[data-testid=session-state]:text-is("stopped")').waitFor({ timeout: 30_000 });
    assert.equal(await run.getByRole('button', { name: /^Resume/ }).count(), 1);

    // Starting it again without "resume": a plain-word refusal.
    await page.click('[data-testid=start]');
    await page.waitForFunction(() => document.querySelector('[data-testid=experimenter-status]').classList.contains('error'));
    const refusal = await page.textContent('[data-testid=experimenter-status]');
    assert.match(refusal, /unfinished texel-length session; resume it/);
    assert.doesNotMatch(refusal, /experiment\.|resume: true|\(experiment/);

    // Exports: CSV, .mat and figures of every session, as download links.
    await page.click('[data-testid=export-csv]');
    let link = page.locator('[data-testid=export-link]').first();
    await link.waitFor();
    let f = await download(page, link);
    assert.equal(f.name, 'trials.csv');
    const csv = f.data.toString('utf8').split('\n');
    assert.match(csv[0], /(^|,)participant(,|$)/);
    assert.equal(csv.filter((l) => l.includes('SIM1')).length, 25);

    await page.click('[data-testid=export-mat]');
    link = page.locator('[data-testid=export-link]:has-text("trials.mat")');
    await link.waitFor();
    f = await download(page, link);
    assert.match(f.data.subarray(0, 116).toString('latin1'), /^MATLAB 5\.0 MAT-file/);

    await page.click('[data-testid=export-figures]');
    await page.waitForSelector('[data-testid=exports] figure img', { timeout: 120_000 });
    await page.waitForFunction(() => [...document.querySelectorAll('[data-testid=exports] img')].every((i) => i.complete && i.naturalWidth > 100));
    const figures = await page.locator('[data-testid=exports] figcaption a').allTextContents();
    assert.ok(figures.some((n) => /^texel-length-.*\.png/.test(n)), figures.join(', '));
    await screenshot(page, 'experimenter-exports');

    // Protocol editor: the texel-length template as a form.
    await page.selectOption('#template', 'texel-length');
    await page.click('[data-testid=load-template]');
    await page.waitForSelector('[data-testid=protocol-block]');
    const name = page.locator('[data-field="protocol.name"] input');
    assert.equal(await name.inputValue(), 'texel-length');
    await name.fill('texel-length-lab');
    // A value the engine refuses: the message names the field, in plain words.
    const limit = page.locator('[data-field="blocks[0].time_limit_s"] input');
    await limit.fill('-3');
    await page.click('[data-testid=validate]');
    await page.waitForFunction(() => document.querySelector('[data-testid=editor-status]').classList.contains('error'));
    const why = await page.textContent('[data-testid=editor-status]');
    // 1-based, as the form's legend "Block 1: …" (the engine's path is 0-based), and at the field.
    assert.match(why, /Block 1 › time_limit_s/);
    assert.doesNotMatch(why, /^experiment\.|blocks\[0\]/);
    const atField = page.locator('[data-field="blocks[0].time_limit_s"] [data-testid=field-error]');
    assert.ok(await atField.isVisible(), 'the refusal is shown at the field');
    assert.match(await atField.textContent(), /Block 1 › time_limit_s/);
    assert.equal(await limit.getAttribute('aria-invalid'), 'true');
    await limit.fill('20');
    assert.equal(await atField.isVisible(), false, 'a changed field is no longer marked refused');
    assert.equal(await limit.getAttribute('aria-invalid'), null);
    // The designed texture as the block's stimulus.
    await page.locator('[data-field="blocks[0].texture"] select').selectOption('fine grating');
    const texture = JSON.parse(await page.locator('[data-field="blocks[0].texture"] textarea').inputValue());
    assert.equal(texture.kind, 'texel');
    await page.click('[data-testid=validate]');
    await page.waitForFunction(() => /^Valid: texel-length-lab/.test(document.querySelector('[data-testid=editor-status]').textContent));
    await screenshot(page, 'experimenter-protocol-editor');
    await page.fill('#participant', 'LAB1');
    await page.fill('#simulate', '');
    await page.click('[data-testid=start-edited]');
    await rowOf(page, 'LAB1').locator('[data-testid=session-state]:text-is("running")').waitFor({ timeout: 30_000 });
    assert.match(await rowOf(page, 'LAB1').textContent(), /texel-length-lab/);
    assert.deepEqual(errors, []);
  });
});
