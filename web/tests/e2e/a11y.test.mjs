// Accessibility: axe-core (npm devDependency, injected into the page) on every
// page of the studio — the designer, the experimenter view (idle, with a
// running session, with the session table), and every participant screen
// state the shipped protocols reach: idle ("please wait"), the first question
// of each task kind (oddity, practice oddity, two-alternative, match, guided,
// rating, same-different in both of its phases, the 2-D oddity on the touch
// surface) and finished; the
// experimenter view also with a session's staircase track, the exported
// figures and the protocol editor open. Each page is
// its own subtest: 0 critical and 0 serious findings. Every finding (any
// impact) is printed by page, so a failure names the rule and the element.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { createRequire } from 'node:module';
import { join } from 'node:path';
import { withStudio, screenshot, paths, startStudio, launchFirefox, askStudio, startSession } from './studio.mjs';

const axeSource = readFileSync(createRequire(import.meta.url).resolve('axe-core/axe.min.js'), 'utf8');

/** Runs axe on the page as it is now; returns its violations, simplified. */
async function audit(page) {
  if (!(await page.evaluate(() => typeof window.axe === 'object'))) await page.addScriptTag({ content: axeSource });
  return page.evaluate(async () => {
    // Audio/haptic players and the plots' canvases are not content: axe's
    // default rules (WCAG 2.x A/AA and best practices) on the whole document.
    const r = await window.axe.run(document, { resultTypes: ['violations'] });
    return r.violations.map((v) => ({
      id: v.id,
      impact: v.impact,
      help: v.help,
      nodes: v.nodes.slice(0, 4).map((n) => n.target.join(' ')),
      count: v.nodes.length,
    }));
  });
}

const findings = new Map();
async function check(page, label, shot = true) {
  const v = await audit(page);
  findings.set(label, v);
  if (shot) await screenshot(page, `a11y-${label}`);
  const lines = v.map((f) => `  [${f.impact}] ${f.id} (${f.count}): ${f.help} — ${f.nodes.join(', ')}`);
  console.log(`axe ${label}: ${v.length ? `${v.length} rule(s)\n${lines.join('\n')}` : 'no findings'}`);
  return v;
}

function severe(v) {
  return v.filter((f) => f.impact === 'critical' || f.impact === 'serious');
}

function protocol(name, edit = (p) => p) {
  return edit(JSON.parse(readFileSync(join(paths.protocols, `${name}.json`), 'utf8')));
}

const start = startSession;

test('axe-core: no critical or serious finding on any page', { timeout: 600_000 }, async (t) => {
  await withStudio(async ({ studio, context, page }) => {
    const pages = [];
    const audited = async (p, label) => pages.push([label, await check(p, label)]);

    await page.goto(`${studio.url}#/designer`);
    await page.waitForFunction(() => window.__texelStats && window.__texelStats.designsDrawn >= 1, null, { timeout: 30_000 });
    await audited(page, 'designer');

    await page.goto(`${studio.url}#/surface`);
    await page.waitForFunction(() => window.__texel2d && window.__texel2d.viewsDrawn >= 1, null, { timeout: 60_000 });
    await audited(page, 'surface2d');

    await page.goto(`${studio.url}#/experimenter`);
    await page.waitForSelector('.page-experimenter[data-ready=true]');
    await audited(page, 'experimenter-idle');

    const p = await context.newPage();
    await p.goto(`${studio.url}#/participant`);
    await p.waitForSelector('[data-testid=waiting]', { timeout: 30_000 });
    await audited(p, 'participant-idle');

    // The first question of each task kind the shipped protocols ask.
    const firsts = [
      ['texel-length', 'oddity'],
      ['texel-length-visual-practice', 'oddity'],
      ['coarse-features', 'two-alternative'],
      ['free-exploration', 'match'],
      ['guided-exploration', 'guided'],
      ['quantization', 'rating'],
      ['working-memory', 'familiarisation'],
      ['direction-independence', 'oddity-2d'], // the page as the 2-D display's touch surface
    ];
    let n = 0;
    for (const [name, task] of firsts) {
      const r = await start(page, name, `A11Y${++n}`);
      assert.equal(r.type, 'experiment.started', JSON.stringify(r));
      await p.reload();
      await p.waitForSelector(`.question[data-task=${task}]`, { timeout: 60_000 });
      await p.locator('button.stimulus').first().click();
      await audited(p, `participant-${name}-${task}`);
    }

    // Working memory (phases shortened): the matrix, then the questions.
    const wm = protocol('working-memory', (x) => {
      x.name = 'working-memory-fast';
      // The familiarisation (untimed, first) is audited on its own; here the timed trials.
      x.blocks = x.blocks.filter((b) => b.task !== 'familiarisation');
      for (const b of x.blocks) Object.assign(b, { texture_s: 1, matrix_s: 1 });
      return x;
    });
    assert.equal((await start(page, wm, 'A11Y-wm')).type, 'experiment.started');
    await p.reload();
    await p.waitForSelector('[data-testid=matrix]', { timeout: 30_000 });
    await audited(p, 'participant-working-memory-matrix');
    await p.locator('.answers:not([hidden])').waitFor({ timeout: 30_000 });
    await audited(p, 'participant-working-memory-answers');

    // Finished: a one-pair rating protocol answered from the keyboard.
    const one = protocol('quantization', (x) => {
      x.name = 'quantization-one';
      x.blocks[0].pairs = x.blocks[0].pairs.slice(0, 1);
      if ('repetitions' in x.blocks[0]) x.blocks[0].repetitions = 1;
      return x;
    });
    const r = await start(page, one, 'A11Y-fin');
    assert.equal(r.type, 'experiment.started', JSON.stringify(r));
    await p.reload();
    await p.waitForSelector('.question[data-task=rating]', { timeout: 60_000 });
    await p.locator('[data-testid=rating] button').first().click();
    await p.locator('[data-testid=submit]:not([disabled])').click();
    await p.waitForSelector('[data-testid=thank-you]', { timeout: 60_000 });
    await audited(p, 'participant-finished');

    // The experimenter view with sessions in its table and one running.
    await start(page, 'texel-length', 'A11Y-run');
    await page.bringToFront();
    await page.reload();
    await page.waitForFunction(() => document.querySelectorAll('[data-testid=sessions] tbody tr').length >= 8, null, { timeout: 30_000 });
    await page.waitForFunction(() => /A11Y-run/.test(document.querySelector('[data-testid=active-session]')?.textContent ?? ''), null, { timeout: 30_000 });
    await audited(page, 'experimenter-running');

    // …with the followed session's track and trials, exports and the protocol editor open.
    await start(page, 'texel-length', 'A11Y-sim', { simulate: 'threshold=6mm' });
    await askStudio(page, [], { simulated: 8 });
    await page.waitForSelector('[data-testid=staircase-plot] canvas', { timeout: 30_000 });
    await page.click('[data-testid=export-figures]');
    await page.waitForSelector('[data-testid=exports] figure img', { timeout: 120_000 });
    await page.selectOption('#template', 'working-memory');
    await page.click('[data-testid=load-template]');
    await page.waitForSelector('[data-testid=protocol-block]');
    await audited(page, 'experimenter-track-exports-editor');

    for (const [label, v] of pages)
      await t.test(label, () => {
        assert.deepEqual(
          severe(v).map((f) => `${f.impact} ${f.id}: ${f.nodes.join(', ')}`),
          [],
          `${label}: axe-core critical/serious findings`,
        );
      });
  });
});

// The same audit in Firefox ESR (puppeteer-core over WebDriver BiDi) on the
// designer, the experimenter view and a participant question and idle screen.
test('axe-core in Firefox ESR: no critical or serious finding', { timeout: 300_000 }, async (t) => {
  const studio = await startStudio({ hardTimeoutMs: 330_000 });
  let ff;
  const pages = [];
  try {
    ff = await launchFirefox({ hardTimeoutMs: 330_000 });
    const page = await ff.browser.newPage();
    await page.goto(`${studio.url}#/designer`);
    await page.waitForFunction(() => window.__texelStats && window.__texelStats.designsDrawn >= 1, { timeout: 60_000 });
    pages.push(['firefox-designer', await check(page, 'firefox-designer', false)]);
    await page.goto(`${studio.url}#/participant`);
    await page.waitForSelector('[data-testid=waiting]', { timeout: 30_000 });
    pages.push(['firefox-participant-idle', await check(page, 'firefox-participant-idle', false)]);
    await page.goto(`${studio.url}#/experimenter`);
    await page.waitForSelector('.page-experimenter[data-ready=true]', { timeout: 30_000 });
    const r = await start(page, 'texel-length', 'FFA11Y');
    assert.equal(r.type, 'experiment.started', JSON.stringify(r));
    await page.waitForSelector('[data-testid=staircase-plot], [data-testid=session-detail]:not([hidden])', { timeout: 30_000 });
    pages.push(['firefox-experimenter', await check(page, 'firefox-experimenter', false)]);
    await page.goto(`${studio.url}#/participant`);
    await page.waitForSelector('.question[data-task=oddity]', { timeout: 60_000 });
    pages.push(['firefox-participant-oddity', await check(page, 'firefox-participant-oddity', false)]);
  } finally {
    await ff?.close();
    await studio.stop();
  }
  for (const [label, v] of pages)
    await t.test(label, () => {
      assert.deepEqual(
        severe(v).map((f) => `${f.impact} ${f.id}: ${f.nodes.join(', ')}`),
        [],
        `${label}: axe-core critical/serious findings`,
      );
    });
});
