// Participant frames carry nothing the participant must not know (issue #37):
// over a whole session of every task kind the participant page supports —
// oddity (with drawn maps), two-alternative, match, guided, rating,
// familiarisation, same-different (with each distractor), playback-oddity, oddity-2d — every frame the participant
// screen receives is free of the block (names, index), the condition, seeds
// (the protocol's, the session's, the stimuli's documents) and the
// participant code, though all of them are readable in devtools otherwise.
// The session is answered by the studio's simulated participant from the
// experimenter's side; the participant screen follows every question.
//
// And what the participant is asked is one text (issue #37): the first
// questions' wording (question.wording: stimulus names, the choice's heading
// and labels, the rating, confidence and digit scales with their end labels)
// is what the page shows and what `texel experiment run` prints for the same
// participant and protocol (the same draws: the session's seed is the
// protocol's mixed with the participant code).
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { spawn } from 'node:child_process';
import { mkdtempSync, readFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { withStudio, paths } from './studio.mjs';
import { control } from './participant-helpers.mjs';

// One shipped protocol per task kind (texel-length-visual-practice: oddity with show_maps).
const PROTOCOLS = [
  'texel-length-visual-practice',
  'coarse-features',
  'free-exploration',
  'guided-exploration',
  'quantization',
  'working-memory',
  'working-memory-components',
  'distributed-irregularity',
  'direction-independence',
];
// What a participant types in the terminal for the first questions of each protocol (then q).
const TERMINAL = {
  'texel-length-visual-practice': 'a 1\na 2\nq\n',
  'coarse-features': 'a A\na B\nq\n',
  'free-exploration': 'a\n3\nq\n',
  'guided-exploration': 'a A\na unsure\nq\n',
  quantization: 'a 3\na 4\nq\n',
  'working-memory': 'a continue\na same\n5\nq\n',
  'working-memory-components': 'a continue\na same\n5\nq\n',
  'distributed-irregularity': 'a 1\na 2\nq\n',
};

// The longer sessions are audited over their first questions (every distractor and condition comes up
// within them, practice included); the others to their end.
const QUESTIONS = { 'working-memory-components': 24, 'distributed-irregularity': 12 };

/** Every string of a question's words: its prompt and wording (the confidence and digit questions follow an answer: `answered`). */
function wordingStrings(q, answered = true) {
  const w = q.wording;
  const out = [q.prompt, w.choice_question, ...w.choice_labels, ...w.stimulus_names.slice(0, 1), w.sequence_instruction];
  for (const k of answered ? ['rating', 'confidence', 'recall'] : ['rating'])
    if (w[k]) out.push(w[k].question, w[k].min_label, w[k].max_label, `${w[k].min}`, `${w[k].max}`);
  return out.filter((x) => x);
}

/**
 * `texel experiment run` for `name` as participant `code`, typing `input`: its output once it ends. The
 * working-memory runs spend half a minute in their timed phases, so every run starts at the beginning
 * and runs beside the studio's sessions.
 */
function terminalRun(name, code, input) {
  const db = join(mkdtempSync(join(tmpdir(), 'texel-terminal-')), 't.db');
  const child = spawn(paths.bin, ['experiment', 'run', join(paths.protocols, `${name}.json`), '--participant', code, '--db', db, '--backend', 'null']);
  let stdout = '';
  let stderr = '';
  child.stdout.on('data', (d) => (stdout += d));
  child.stderr.on('data', (d) => (stderr += d));
  child.stdin.end(input);
  const timer = setTimeout(() => child.kill('SIGKILL'), 240_000);
  return new Promise((resolve) =>
    child.on('close', (status) => {
      clearTimeout(timer);
      resolve({ stdout, stderr, status });
    }),
  );
}

const FORBIDDEN_KEYS = new Set(['block', 'block_index', 'trial_in_block', 'block_trials', 'condition', 'seed', 'participant', 'session', 'document', 'correct_answer', 'intensity']);

/** Every key and string value of a parsed frame. */
function walk(v, keys, strings) {
  if (Array.isArray(v)) v.forEach((x) => walk(x, keys, strings));
  else if (v && typeof v === 'object')
    for (const [k, x] of Object.entries(v)) {
      keys.add(k);
      walk(x, keys, strings);
    }
  else if (typeof v === 'string') strings.add(v);
}

test('participant frames: no block, condition, seed or participant code over a whole session of every task kind', { timeout: 1_200_000 }, async () => {
  await withStudio(async ({ context, page, studio, errors }) => {
    await page.goto(`${studio.url}#/experimenter`);
    const p = await context.newPage();
    p.on('pageerror', (e) => errors.push(String(e)));
    const frames = [];
    p.on('websocket', (ws) => ws.on('framereceived', (f) => typeof f.payload === 'string' && frames.push(f.payload)));
    await p.goto(`${studio.url}#/participant`);
    await p.waitForSelector('[data-testid=waiting]');
    const tasksSeen = new Set();
    const terminals = new Map(PROTOCOLS.filter((name) => TERMINAL[name]).map((name) => [name, terminalRun(name, `QZX${PROTOCOLS.indexOf(name)}K`, TERMINAL[name])]));
    for (const [n, name] of PROTOCOLS.entries()) {
      const proto = JSON.parse(readFileSync(join(paths.protocols, `${name}.json`), 'utf8'));
      const code = `QZX${n}K`;
      frames.length = 0;
      const [, started] = await control(page, { type: 'experiment.stop' }, { type: 'experiment.start', protocol: name, participant: code, simulate: 'default' });
      assert.equal(started.type, 'experiment.started', JSON.stringify(started));
      // Answer every question as the simulated participant; the participant screen follows each push.
      const limit = QUESTIONS[name] ?? 5000;
      for (let guard = 0; guard < limit; guard++) {
        const [cur] = await control(page, { type: 'experiment.current' });
        if (cur.type !== 'experiment.question') break;
        tasksSeen.add(cur.question.task);
        // The page lays out the library's words for this question (every one of them).
        const t = cur.question.trial;
        await p.waitForSelector(`.question[data-trial="${t}"]`, { timeout: 30_000 });
        const text = await p.locator('.participant').textContent();
        const w = cur.question.wording;
        for (const x of [...wordingStrings(cur.question), ...w.stimulus_names.map((n) => `Feel ${n}`)])
          // A timed question shows its phases one at a time: the sequence's words come in its phase (working-memory-components.test).
          if (!cur.question.phases.length || !(x.startsWith('Feel ') || x === w.sequence_instruction)) assert.ok(text.includes(x), `${name}, trial ${t + 1}: the page does not say "${x}": ${text}`);
        const [a] = await control(page, { type: 'experiment.answer', trial: cur.question.trial, simulated: true });
        assert.ok(a.type !== 'error', JSON.stringify(a));
      }
      if (!QUESTIONS[name]) await p.waitForSelector('[data-testid=thank-you]', { timeout: 60_000 });
      const questions = frames.filter((f) => f.includes('"experiment.question"'));
      assert.ok(questions.length > 0, `${name}: the participant screen received its questions`);
      // What must not reach the participant's screen, as this session has it.
      const words = new Set([code]);
      for (const b of proto.blocks) {
        // A block named after its task kind ("guided") says no more than the question's task, which the page needs.
        if (b.name !== b.task) words.add(b.name);
        if (b.condition) words.add(b.condition);
      }
      const seeds = [String(started.session.seed), ...(proto.seed >= 1000 ? [String(proto.seed)] : [])];
      for (const f of frames) {
        const keys = new Set();
        const strings = new Set();
        walk(JSON.parse(f), keys, strings);
        for (const k of keys) assert.ok(!FORBIDDEN_KEYS.has(k), `${name}: a participant frame has "${k}": ${f.slice(0, 400)}`);
        for (const s of strings)
          for (const w of words) assert.ok(!(s === w || s.includes(code)), `${name}: a participant frame carries "${w}": ${f.slice(0, 400)}`);
        for (const s of seeds) assert.ok(!f.includes(s), `${name}: a participant frame carries the seed ${s}: ${f.slice(0, 400)}`);
      }
      // The page shows the wording of the question on screen; the terminal prints the same words.
      const byTrial = new Map();
      for (const f of frames) {
        const m = JSON.parse(f);
        if (m.type === 'experiment.question' && !byTrial.has(m.question.trial)) byTrial.set(m.question.trial, m.question);
      }
      if (terminals.has(name)) {
        const r = await terminals.get(name);
        const out = r.stdout;
        const shown = [...out.matchAll(/^Trial (\d+)/gm)].map((m) => Number(m[1]) - 1);
        assert.ok(shown.length > 0, `${name}: the terminal showed a question: ${out.slice(0, 2000)} ${r.stderr}`);
        for (const [n, t] of shown.entries()) {
          const q = byTrial.get(t);
          assert.ok(q, `${name}: the studio handed out trial ${t}`);
          for (const text of wordingStrings(q, n < shown.length - 1)) assert.ok(out.includes(text), `${name}, trial ${t + 1}: the terminal does not say "${text}":\n${out}`);
        }
      }
      if (name === 'texel-length-visual-practice')
        assert.ok(frames.some((f) => f.includes('"map_f32"')), 'the visual practice draws its maps from the rendered maps');
    }
    for (const t of ['oddity', 'two-alternative', 'match', 'guided', 'rating', 'familiarisation', 'same-different', 'playback-oddity', 'oddity-2d'])
      assert.ok(tasksSeen.has(t), `task kind ${t} was covered (${[...tasksSeen].join(', ')})`);
    assert.deepEqual(errors, []);
  });
});
