// The participant page of a 2-D study (direction-independence, task
// oddity-2d): the page is the display's touch surface. Each interval shows
// the line to stroke along and nothing of the trial; strokes by mouse, touch
// and pen reach the studio's 2-D player and are recorded; leaving an interval
// stroked along another line brings the reminder; the answer is stored with
// the strokes (response_json.strokes per interval, and the export's strokes,
// stroke_deviation_deg, direction_compliant). Strokes of another trial or of
// an interval not playing are refused.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import { join } from 'node:path';
import { withStudio, screenshot } from './studio.mjs';
import { control, exportRows } from './participant-helpers.mjs';

/** The stored responses (response_json) of the store's trials, by trial, and the events stored with them. */
function storedResponses(db) {
  const py = 'import sqlite3,sys,json; c=sqlite3.connect(sys.argv[1]); print(json.dumps([[t, json.loads(r), [list(e) for e in c.execute("select kind, detail from events where trial = ? order by seq", (t,))]] for t, r in c.execute("select trial, response_json from trials order by trial")]))';
  const r = spawnSync('/usr/bin/python3', ['-c', py, db], { encoding: 'utf8' });
  assert.equal(r.status, 0, r.stderr);
  return JSON.parse(r.stdout);
}

const strokes = (p) => p.evaluate(() => ({ ...window.__texelStrokes }));

/** Strokes the surface along `deg` (degrees from +x towards +y, down the screen) through its centre. */
async function strokeAlong(p, deg, input, { passes = 2 } = {}) {
  const box = await p.locator('[data-testid=stroke-surface]').boundingBox();
  const [cx, cy] = [box.x + box.width / 2, box.y + box.height / 2];
  const half = 0.3 * Math.min(box.width, box.height);
  const a = (deg * Math.PI) / 180;
  const at = (f) => [Math.round(cx + Math.cos(a) * half * f), Math.round(cy + Math.sin(a) * half * f)];
  const steps = 40; // small steps: a stroke's samples stay below the recorder's jump speed
  for (let k = 0; k < passes; k++) {
    const from = k % 2 ? 1 : -1;
    const path = Array.from({ length: steps + 1 }, (_, i) => at(from - (2 * from * i) / steps));
    await input.down(...path[0]);
    for (const pt of path.slice(1)) await input.move(...pt);
    await input.up(...path[path.length - 1]);
  }
}

test('participant page, 2-D study: strokes on the page drive the 2-D player and are stored with the answer', { timeout: 300_000 }, async () => {
  await withStudio(async ({ studio, context, page, errors }) => {
    await page.goto(`${studio.url}#/experimenter`);
    const p = await context.newPage();
    p.on('pageerror', (e) => errors.push(String(e)));
    await p.setViewportSize({ width: 820, height: 1180 }); // a tablet in the participant's hands (portrait)
    await p.goto(`${studio.url}#/participant`);
    await p.waitForSelector('[data-testid=waiting]');

    let [r] = await control(page, { type: 'experiment.start', protocol: 'direction-independence', participant: 'D1' });
    assert.equal(r.type, 'experiment.started', JSON.stringify(r));
    await p.waitForSelector('.question[data-task=oddity-2d] [data-testid=stroke-surface]');
    assert.equal(await p.locator('.feel-strip, [data-testid=feel-strip]').count(), 0, 'no 1-D strip on a 2-D question');
    const [cur] = await control(page, { type: 'experiment.current' });
    assert.ok(cur.surface.width_mm > 200 && cur.surface.height_mm > 150, `the display's surface: ${JSON.stringify(cur.surface)}`);
    const token = cur.handout.token;
    // Before an interval is chosen nothing is sent.
    const box0 = await p.locator('[data-testid=stroke-surface]').boundingBox();
    await p.mouse.move(box0.x + 50, box0.y + 50);
    await p.mouse.down();
    await p.mouse.move(box0.x + 150, box0.y + 60, { steps: 5 });
    await p.mouse.up();
    assert.equal((await strokes(p)).samplesSent, 0);

    const mouse = { down: async (x, y) => (await p.mouse.move(x, y), p.mouse.down()), move: (x, y) => p.mouse.move(x, y), up: () => p.mouse.up() };
    const cdp = await p.context().newCDPSession(p);
    const touch = {
      down: (x, y) => cdp.send('Input.dispatchTouchEvent', { type: 'touchStart', touchPoints: [{ x, y }] }),
      move: (x, y) => cdp.send('Input.dispatchTouchEvent', { type: 'touchMove', touchPoints: [{ x, y }] }),
      up: () => cdp.send('Input.dispatchTouchEvent', { type: 'touchEnd', touchPoints: [] }),
    };
    const pen = {
      down: (x, y) => cdp.send('Input.dispatchMouseEvent', { type: 'mousePressed', pointerType: 'pen', button: 'left', buttons: 1, clickCount: 1, x, y, force: 0.5 }),
      move: (x, y) => cdp.send('Input.dispatchMouseEvent', { type: 'mouseMoved', pointerType: 'pen', button: 'left', buttons: 1, x, y, force: 0.5 }),
      up: (x, y) => cdp.send('Input.dispatchMouseEvent', { type: 'mouseReleased', pointerType: 'pen', button: 'left', buttons: 0, clickCount: 1, x, y }),
    };
    const lines = [];
    const feel = async (i) => {
      const before = await strokes(p);
      await p.locator(`button.stimulus[data-stimulus="${i}"]`).click();
      await p.waitForFunction(() => window.__texelStrokes.line !== null, null, { timeout: 60_000 });
      const s = await strokes(p);
      lines[i] = s.line;
      return before;
    };
    // Interval 1 by mouse along its line; interval 2 by touch across its line; interval 3 by pen along its line.
    await feel(0);
    assert.match(await p.textContent('[data-testid=stroke-line]'), /^Stroke texture 1 along the line: /);
    await screenshot(p, 'participant-2d-tablet-interval');
    await strokeAlong(p, lines[0], mouse);
    await feel(1);
    await strokeAlong(p, lines[1] + 90, touch);
    // The 2-D player got the page's samples (the 2-D pad's player, playing the participant's interval).
    const [st] = await control(page, { type: 'feel2d.state' });
    assert.equal(st.mode, 'participant', JSON.stringify(st));
    assert.ok(st.samples > 40, `samples played: ${st.samples}`);
    await screenshot(p, 'participant-2d-tablet-strokes');
    await feel(2);
    const notice = p.locator('[data-testid=participant-notice]');
    await notice.waitFor({ state: 'visible' });
    assert.match(await notice.textContent(), /You stroked texture 2 along another line than its own: /);
    await screenshot(p, 'participant-2d-tablet-reminder');
    await strokeAlong(p, lines[2], pen);
    await p.waitForFunction(() => window.__texelStrokes.samplesRecorded === window.__texelStrokes.samplesSent, null, { timeout: 10_000 });
    const sent = await strokes(p);
    assert.ok(sent.samplesRecorded > 200 && sent.refused === 0, JSON.stringify(sent));

    // Nothing of the trial on the page: no condition, mode or which is odd.
    const text = await p.textContent('.question');
    assert.doesNotMatch(text, /path|bitmap|spectral|oriented|condition|baseline|odd one is \d|1d|2d/i);

    // Guards: a stroke for an interval not playing, or with another token, is refused and not recorded.
    const [wrongInterval, wrongToken] = await control(
      page,
      { type: 'experiment.stroke', trial: 0, token, stimulus: 0, samples: [[1, 10, 10, true]] },
      { type: 'experiment.stroke', trial: 0, token: 'x' + token.slice(1), stimulus: 2, samples: [[1, 10, 10, true]] },
    );
    assert.equal(wrongInterval.code, 'conflict', JSON.stringify(wrongInterval));
    assert.equal(wrongToken.code, 'conflict', JSON.stringify(wrongToken));

    await p.locator('[data-testid=choices] button').first().click();
    await p.locator('[data-testid=submit]:not([disabled])').click();
    await p.waitForSelector('.question[data-trial="1"]');
    // The answered trial's strokes are closed: its token is refused now.
    const [late] = await control(page, { type: 'experiment.stroke', trial: 0, token, stimulus: 2, samples: [[1, 10, 10, true]] });
    assert.equal(late.code, 'conflict', JSON.stringify(late));

    const [row] = exportRows(join(studio.dir, 's.db'));
    assert.equal(row.trial_number, '1');
    assert.ok(Number(row.strokes) >= 6, `strokes ${row.strokes}`);
    assert.equal(row.direction_compliant, '0', 'interval 2 was stroked across its line');
    assert.ok(Number(row.stroke_deviation_deg) > 80, `deviation ${row.stroke_deviation_deg}`);
    const [[trial, resp, events]] = storedResponses(join(studio.dir, 's.db'));
    assert.equal(trial, 0);
    assert.deepEqual(resp.strokes.map((s) => [s.stimulus, s.compliant]), [['1', true], ['2', false], ['3', true]], JSON.stringify(resp.strokes));
    for (const [i, s] of resp.strokes.entries()) {
      assert.ok(Math.abs(s.instructed_deg - ((lines[i] % 180) + 180) % 180) < 1e-6, `instructed ${s.instructed_deg} vs shown ${lines[i]}`);
      assert.ok(s.strokes >= 2 && s.path_mm > 50, JSON.stringify(s));
    }
    assert.ok(events.some(([kind, detail]) => kind === 'stroke_reminder' && detail === '2'), `the reminder is an event of the trial: ${JSON.stringify(events)}`);

    // A phone-sized page: the surface fits the screen.
    await p.setViewportSize({ width: 390, height: 844 });
    await feel(0);
    const box = await p.locator('[data-testid=stroke-surface]').boundingBox();
    assert.ok(box.width <= 390 && box.width > 300, `surface on a phone: ${JSON.stringify(box)}`);
    await screenshot(p, 'participant-2d-phone');
  });
});
