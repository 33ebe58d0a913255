// Participant screens (#/participant), driven entirely by the engine's
// `experiment.current` / `experiment.question` replies: whatever the question
// asks (stimuli, choices, rating scale, sliders, confidence, timed phases,
// digit recall) is shown, and nothing else — the question never carries the
// answer, and this page shows no maps unless the question says `show_maps`.
//
// The screen follows the session (docs/studio.md "The token rule"): the
// service pushes every change — a suspend, stop, session switch, the next
// question after another screen's answer — and a lost connection (a server
// restart) shows the same neutral "Please wait" screen, without countdown.
// Answers carry the question's token; one the engine refuses (stale trial,
// stopped, paused or another session) shows its plain reason here and the
// screen then shows what is current.
//
// Timing is the server's: the trial's onset and clock are kept per token, so
// the countdown continues where it was after a reload or a pause (handout
// elapsed_s), and the stored reaction time runs from onset without paused
// time. The page's own events (select, choice, …) are sent with the answer,
// t_s from when this page showed the question.
//
// 2-D studies (task oddity-2d; the reply carries `surface`): the page is the
// touch surface of the studio's 2-D display (pointer, pen or touch; a tablet
// in the participant's hands). Each interval shows only the line to stroke
// along (experiment.selected's stroke_words, drawn across the surface); the
// strokes go to the studio (experiment.stroke, with the question's token and
// the interval playing), which plays them on its device and records them as
// a 2-D display's strokes, stored with the answer.

import { studio, StudioError } from './ws';
import { h, isoNow, decodeF32 } from './util';
import { FeelStrip } from './feel';
import { Store } from './store';
import type { ExperimentQuestionReply, Question, Response, Scale, ServerMessages, TrialEvent } from './generated/messages';


function radioGroup(label: string, options: { value: string; text: string }[], onPick: (v: string) => void, testid: string, labelledBy?: string): { el: HTMLElement; value: () => string | null } {
  let picked: string | null = null;
  const buttons = options.map((o) =>
    h('button', { type: 'button', role: 'radio', 'aria-checked': 'false', class: 'big choice', 'data-value': o.value, 'aria-label': `${label}: ${o.text}` }, o.text),
  );
  const el = h('div', { role: 'radiogroup', 'aria-label': labelledBy ? undefined : label, 'aria-labelledby': labelledBy, class: 'choices', 'data-testid': testid }, ...buttons);
  buttons.forEach((b, i) => {
    b.tabIndex = i === 0 ? 0 : -1;
    b.addEventListener('click', () => {
      picked = options[i].value;
      buttons.forEach((x) => x.setAttribute('aria-checked', String(x === b)));
      onPick(picked);
    });
    b.addEventListener('keydown', (e) => {
      const d = e.key === 'ArrowRight' || e.key === 'ArrowDown' ? 1 : e.key === 'ArrowLeft' || e.key === 'ArrowUp' ? -1 : 0;
      if (!d) return;
      e.preventDefault();
      const n = buttons[(i + d + buttons.length) % buttons.length];
      buttons.forEach((x) => (x.tabIndex = x === n ? 0 : -1));
      n.focus();
      n.click(); // arrows select, as in a native radio group
    });
  });
  return { el, value: () => picked };
}

function drawMiniMap(canvas: HTMLCanvasElement, values: Float32Array): void {
  const ctx = canvas.getContext('2d')!;
  const w = canvas.width;
  const hgt = canvas.height;
  ctx.clearRect(0, 0, w, hgt);
  ctx.strokeStyle = '#2a6fdb';
  ctx.beginPath();
  for (let px = 0; px < w; px++) {
    const i0 = Math.floor((px * values.length) / w);
    const i1 = Math.max(i0 + 1, Math.floor(((px + 1) * values.length) / w));
    let lo = 1;
    let hi = 0;
    for (let i = i0; i < i1; i++) {
      lo = Math.min(lo, values[i]);
      hi = Math.max(hi, values[i]);
    }
    ctx.moveTo(px + 0.5, (1 - hi) * hgt);
    ctx.lineTo(px + 0.5, (1 - lo) * hgt + 1);
  }
  ctx.stroke();
}

/** Test hooks of the 2-D touch surface (test builds only). */
const hooks2d = { samplesSent: 0, samplesRecorded: 0, refused: 0, line: null as number | null };
if (__TEXEL_TEST_HOOKS__) (window as unknown as { __texelStrokes: typeof hooks2d }).__texelStrokes = hooks2d;

/**
 * The 2-D touch surface of one question: the display's rectangle (its aspect kept), the line to stroke
 * along drawn across it, and the participant's strokes of the interval playing. Samples (page time,
 * surface mm, touch) go out one message at a time, batched while one is in flight.
 */
class StrokeSurface {
  readonly el: HTMLElement;
  readonly canvas: HTMLCanvasElement;
  private line: number | null = null;
  private trail: [number, number, boolean][] = [];
  private queue: [number, number, number, boolean][] = [];
  private inFlight: Promise<void> | null = null;
  private pointer: number | null = null;
  private last: [number, number] | null = null;
  interval = -1; // the stimulus playing; -1: none (strokes are not sent)

  constructor(
    readonly width_mm: number,
    readonly height_mm: number,
    private readonly sendBatch: (interval: number, samples: [number, number, number, boolean][]) => Promise<void>,
  ) {
    this.canvas = h('canvas', {
      class: 'stroke-canvas',
      'data-testid': 'stroke-surface',
      role: 'img',
      'aria-label': 'Touch surface: stroke it with a finger or the pen along the line shown',
    }) as HTMLCanvasElement;
    this.el = h('div', { class: 'stroke-surface', style: `aspect-ratio: ${width_mm} / ${height_mm}; max-width: calc(62vh * ${width_mm / height_mm})` }, this.canvas);
    const c = this.canvas;
    c.addEventListener('pointerdown', (e) => {
      if (this.pointer !== null || (e.pointerType === 'mouse' && e.button !== 0)) return;
      e.preventDefault();
      this.pointer = e.pointerId;
      c.setPointerCapture(e.pointerId);
      this.sample(e, true);
    });
    c.addEventListener('pointermove', (e) => {
      if (e.pointerId !== this.pointer) return;
      e.preventDefault();
      const all = typeof e.getCoalescedEvents === 'function' ? e.getCoalescedEvents() : [];
      for (const ce of all.length ? all : [e]) this.sample(ce, true);
    });
    const up = (e: PointerEvent) => {
      if (e.pointerId !== this.pointer) return;
      this.sample(e, false);
      this.pointer = null;
    };
    c.addEventListener('pointerup', up);
    c.addEventListener('pointercancel', up);
    c.addEventListener('lostpointercapture', up);
    this.resize.observe(this.el);
  }

  private readonly resize = new ResizeObserver(() => this.draw());

  /** The question left the screen. */
  dispose(): void {
    this.resize.disconnect();
  }

  /** The interval playing and its line (degrees from +x towards +y, down the screen); clears its drawn strokes. */
  show(interval: number, lineDeg: number | null): void {
    this.interval = interval;
    this.line = lineDeg;
    this.trail = [];
    hooks2d.line = lineDeg;
    this.draw();
  }

  private sample(e: PointerEvent, touch: boolean): void {
    const r = this.canvas.getBoundingClientRect();
    if (!r.width || !r.height) return;
    const x = Math.min(Math.max(((e.clientX - r.left) / r.width) * this.width_mm, 0), this.width_mm);
    const y = Math.min(Math.max(((e.clientY - r.top) / r.height) * this.height_mm, 0), this.height_mm);
    if (this.interval < 0) return;
    if (!touch && !this.last) return;
    this.last = touch ? [x, y] : null;
    this.trail.push([x, y, touch]);
    if (this.trail.length > 4000) this.trail.splice(0, 1000);
    this.queue.push([e.timeStamp, x, y, touch]);
    this.draw();
    this.pump();
  }

  private pump(): void {
    if (this.inFlight || !this.queue.length) return;
    const batch = this.queue.splice(0, 512);
    const interval = this.interval;
    this.inFlight = this.sendBatch(interval, batch)
      .catch(() => undefined)
      .then(() => {
        this.inFlight = null;
        this.pump();
      });
  }

  /** Resolves when every sample taken so far has been sent (before an answer). */
  async flush(): Promise<void> {
    while (this.inFlight || this.queue.length) {
      this.pump();
      await this.inFlight;
    }
  }

  /** Lifts a finger still down (switching intervals, answering): the stroke ends and the player rests. */
  lift(): void {
    if (this.last && this.interval >= 0) {
      this.queue.push([performance.now(), this.last[0], this.last[1], false]);
      this.pump();
    }
    this.pointer = null;
    this.last = null;
  }

  private draw(): void {
    const c = this.canvas;
    const dpr = window.devicePixelRatio || 1;
    const w = Math.max(1, Math.round(c.clientWidth * dpr));
    const hh = Math.max(1, Math.round(c.clientHeight * dpr));
    if (c.width !== w || c.height !== hh) {
      c.width = w;
      c.height = hh;
    }
    const ctx = c.getContext('2d');
    if (!ctx) return;
    ctx.clearRect(0, 0, w, hh);
    const k = w / this.width_mm; // px per mm (the aspect is the display's)
    if (this.line !== null) {
      // The line to stroke along, through the centre, with arrowheads both ways (a line, not a direction).
      const a = (this.line * Math.PI) / 180;
      const [dx, dy] = [Math.cos(a), Math.sin(a)];
      const half = 0.42 * Math.min(this.width_mm, this.height_mm) * k;
      const [cx, cy] = [w / 2, hh / 2];
      const [x0, y0, x1, y1] = [cx - dx * half, cy - dy * half, cx + dx * half, cy + dy * half];
      ctx.strokeStyle = '#2a6fdb';
      ctx.lineWidth = 6 * dpr;
      ctx.lineCap = 'round';
      ctx.setLineDash([18 * dpr, 12 * dpr]);
      ctx.beginPath();
      ctx.moveTo(x0, y0);
      ctx.lineTo(x1, y1);
      ctx.stroke();
      ctx.setLineDash([]);
      const head = 22 * dpr;
      for (const [px, py, sx] of [[x1, y1, 1], [x0, y0, -1]] as const) {
        ctx.beginPath();
        ctx.moveTo(px, py);
        ctx.lineTo(px - sx * head * (dx * 0.87 - dy * 0.5), py - sx * head * (dy * 0.87 + dx * 0.5));
        ctx.moveTo(px, py);
        ctx.lineTo(px - sx * head * (dx * 0.87 + dy * 0.5), py - sx * head * (dy * 0.87 - dx * 0.5));
        ctx.stroke();
      }
    }
    // The participant's strokes of this interval.
    ctx.strokeStyle = 'rgba(29,29,29,0.55)';
    ctx.lineWidth = 3 * dpr;
    ctx.beginPath();
    let down = false;
    for (const [x, y, t] of this.trail) {
      if (t && down) ctx.lineTo(x * k, y * k);
      else if (t) ctx.moveTo(x * k, y * k);
      down = t;
    }
    ctx.stroke();
  }
}

type StateMessage = ServerMessages['experiment.question'] | ServerMessages['experiment.idle'] | ServerMessages['experiment.suspended'] | ServerMessages['experiment.finished'];

export function mountParticipant(root: HTMLElement): void {
  const client = studio();
  let idleTimer: ReturnType<typeof setTimeout> | null = null;
  let shownToken: string | null = null; // token of the question on screen
  let endQuestion: (() => void) | null = null; // stops the timers of the question on screen
  const alive = () => document.body.contains(root) && !!root.querySelector('.participant');

  const screen = h('div', { class: 'participant-screen' });
  // A refused answer's reason stays visible over whatever comes next.
  const notice = h('p', {
    class: 'notice',
    role: 'alert',
    'data-testid': 'participant-notice',
    hidden: true,
    style: 'background:#fff4d6;border-left:4px solid #8a5a00;padding:0.6rem 0.9rem;color:#1d1d1d',
  });
  let noticeTimer: ReturnType<typeof setTimeout> | null = null;
  const showNotice = (text: string) => {
    notice.textContent = text;
    notice.hidden = false;
    if (noticeTimer) clearTimeout(noticeTimer);
    noticeTimer = setTimeout(() => (notice.hidden = true), 10_000);
  };
  // No mm scale and no texture drawing: a participant feels, never sees, the stimuli (the
  // texture's layout would give the odd one away; visual-practice maps are drawn separately).
  const strip = new FeelStrip({ length_mm: NaN, scale: false, label: 'Feel the selected texture here: move a finger or the pointer along the strip' });
  // The player's position in mm is an engineering figure: not for a participant's eyes.
  strip.el.querySelectorAll<HTMLElement>('.feel-status > span, #player-position').forEach((e) => (e.hidden = true));
  root.replaceChildren(h('div', { class: 'participant' }, notice, screen));

  async function load(reload = false): Promise<void> {
    if (idleTimer) clearTimeout(idleTimer);
    try {
      const cur = await client.call('experiment.current', { screen: true, ...(reload ? { reload: true } : {}) }, 60000);
      show(cur);
    } catch (e) {
      if (e instanceof StudioError && e.code === 'disconnected') return; // onState shows the wait screen and reloads
      screen.replaceChildren(h('p', { class: 'status error', role: 'alert' }, e instanceof Error ? e.message : String(e)));
      idleTimer = setTimeout(() => alive() && void load(), 2000);
    }
  }

  function leaveQuestion(): void {
    endQuestion?.();
    endQuestion = null;
    shownToken = null;
  }

  function wait(state: string, detail: string): void {
    leaveQuestion();
    root.dataset.state = state;
    screen.replaceChildren(h('div', { class: 'waiting', 'data-testid': 'waiting', role: 'status' }, h('h1', {}, 'Please wait'), h('p', {}, detail)));
  }

  function show(cur: StateMessage): void {
    if (!alive()) return;
    if (idleTimer) clearTimeout(idleTimer);
    if (cur.type === 'experiment.question') {
      // The same question again (this screen's own reply and the push): keep it as it is.
      if (cur.handout.token === shownToken) return;
      leaveQuestion();
      root.dataset.state = cur.type;
      shownToken = cur.handout.token;
      void renderQuestion(cur);
    } else if (cur.type === 'experiment.finished') {
      leaveQuestion();
      root.dataset.state = cur.type;
      screen.replaceChildren(h('div', { class: 'thanks', 'data-testid': 'thank-you', role: 'status' }, h('h1', {}, 'Thank you'), h('p', {}, 'The session is complete.')));
    } else if (cur.type === 'experiment.suspended') {
      wait(cur.type, 'The session is paused. It will continue shortly.');
    } else {
      wait(cur.type, 'The experimenter will start the session shortly.');
      idleTimer = setTimeout(() => alive() && void load(), 5000); // pushes do the work; this is a fallback
    }
  }

  // Pushed by the service whenever the session changes.
  const off = [
    client.on('experiment.question', (m) => m.id === null && show(m)),
    client.on('experiment.idle', (m) => m.id === null && show(m)),
    client.on('experiment.suspended', (m) => m.id === null && show(m)),
    client.on('experiment.finished', (m) => m.id === null && show(m)),
    client.onState((st) => {
      if (!alive()) return off.forEach((o) => o());
      if (st === 'closed') wait('disconnected', 'The connection to the studio was lost; reconnecting.');
      else if (st === 'open') void load();
    }),
  ];

  async function renderQuestion(reply: ExperimentQuestionReply): Promise<void> {
    const q: Question = reply.question;
    const w = q.wording;
    const named = (i: number) => w.stimulus_names[i] ?? `texture ${i + 1}`;
    const handout = reply.handout;
    const shownPerf = performance.now();
    const events: TrialEvent[] = [];
    const ev = (kind: string, detail: string) => events.push({ t_s: (performance.now() - shownPerf) / 1000, kind, detail, at: isoNow() });
    ev('show', `trial ${handout.trial_number}`);
    const timers: ReturnType<typeof setTimeout>[] = [];
    const clearTimers = () => timers.forEach((t) => clearTimeout(t));
    endQuestion = clearTimers;
    const current = () => alive() && shownToken === handout.token;
    // A 2-D question: this page is the display's touch surface (no strip).
    const surf = reply.surface;
    const lineText = h('p', { class: 'stroke-line', 'data-testid': 'stroke-line', 'aria-live': 'polite' }, 'Choose a texture to feel, then stroke the surface below along the line shown.');
    const surface = surf
      ? new StrokeSurface(surf.width_mm, surf.height_mm, async (interval, samples) => {
          if (!current()) return;
          try {
            const r = await client.call('experiment.stroke', { trial: q.trial, token: handout.token, stimulus: interval, samples }, 30000);
            if (__TEXEL_TEST_HOOKS__) hooks2d.samplesRecorded += r.samples;
          } catch {
            if (__TEXEL_TEST_HOOKS__) hooks2d.refused++; // another trial, paused, or another interval: the push shows what is current
          }
          if (__TEXEL_TEST_HOOKS__) hooks2d.samplesSent += samples.length;
        })
      : null;
    if (surface) endQuestion = () => (clearTimers(), surface.dispose());

    // The strip's length is the protocol's device's (the question carries no documents).
    if (typeof reply.strip_mm === 'number') strip.setLength(reply.strip_mm);

    // ---- the trial's one state: inputs write it, render() enables Submit from it
    type Answer = Pick<Response, 'choice' | 'rating' | 'confidence' | 'digit' | 'slider_p' | 'slider_i' | 'presses'>;
    const trial = new Store<{ answer: Answer; inputsReady: boolean; timedOut: boolean; saving: boolean }>({
      answer: {},
      inputsReady: q.phases.length === 0,
      timedOut: false,
      saving: false,
    });
    const setAnswer = (p: Answer) => trial.update((t) => ({ answer: { ...t.answer, ...p } }));
    const submit = h('button', { type: 'button', class: 'big primary submit', 'data-testid': 'submit', disabled: true }, 'Submit') as HTMLButtonElement;
    const needs = {
      choice: q.choices.length > 0,
      rating: !!q.rating_scale,
      confidence: q.confidence,
      digit: q.recall_cell >= -1, // -1: the recall question indicates all cells (control matrix); -2: none
      sliders: q.sliders.length >= 2,
    };
    trial.subscribe(({ answer, inputsReady, saving }) => {
      submit.disabled =
        saving ||
        !inputsReady ||
        (needs.choice && answer.choice === undefined) ||
        (needs.rating && answer.rating === undefined) ||
        (needs.confidence && answer.confidence === undefined) ||
        (needs.digit && answer.digit === undefined);
    });

    // ---- stimuli
    const stimulusButtons = q.stimuli.map((_, i) => {
      const b = h('button', { type: 'button', class: 'big stimulus', 'aria-pressed': 'false', 'data-stimulus': i }, `Feel ${named(i)}`) as HTMLButtonElement;
      b.addEventListener('click', () => void selectStimulus(i));
      return b;
    });
    async function selectStimulus(i: number): Promise<void> {
      if (trial.get().timedOut) return;
      stimulusButtons.forEach((b, k) => b.setAttribute('aria-pressed', String(k === i)));
      ev('select', q.stimuli[i]?.label ?? String(i));
      const left = surface?.interval ?? -1;
      if (surface) {
        surface.lift();
        await surface.flush(); // the interval left keeps its strokes
        surface.show(-1, null);
        lineText.textContent = 'Please wait…';
      }
      try {
        const r = await client.call('experiment.select', { trial: q.trial, stimulus: i }, 30000);
        if (surface && current() && r.stroke_deg !== undefined) {
          surface.show(i, r.stroke_deg);
          lineText.textContent = `Stroke ${named(i)} along the line: ${r.stroke_words ?? ''}`;
          if (r.reminder) {
            ev('stroke_reminder', q.stimuli[left]?.label ?? String(left)); // the interval left, as the terminal records it
            showNotice(r.reminder);
          }
        }
      } catch (e) {
        msg.textContent = e instanceof Error ? e.message : String(e);
      }
    }
    const msg = h('p', { class: 'status', role: 'status', 'aria-live': 'polite', 'data-testid': 'participant-status' });

    const parts: (HTMLElement | null)[] = [];
    // planned is -1 for adaptive protocols (a staircase decides when to stop).
    const progress =
      reply.progress && reply.progress.planned > 0 ? `${Math.min(reply.progress.done + 1, reply.progress.planned)} of ${reply.progress.planned}` : '';
    parts.push(
      h('header', { class: 'q-head' },
        h('h1', { class: 'trial', 'data-testid': 'trial-number', 'data-trial': q.trial }, `Trial ${handout.trial_number}`),
        progress ? h('span', { class: 'progress', 'data-testid': 'progress' }, progress) : null,
        q.practice ? h('span', { class: 'badge' }, 'practice') : null),
    );
    if (q.prompt) parts.push(h('p', { class: 'prompt', id: 'prompt' }, q.prompt));

    const countdown = h('div', { class: 'countdown', 'data-testid': 'countdown', 'aria-live': 'off' });
    if (handout.time_limit_s > 0 && q.phases.length === 0) {
      parts.push(countdown);
      // The server's clock: what is left of the limit since onset (a reload or a pause does not reset it).
      const end = shownPerf + (handout.time_limit_s - handout.elapsed_s) * 1000;
      const tick = () => {
        if (!current()) return;
        const left = Math.max(0, (end - performance.now()) / 1000);
        countdown.dataset.left = left.toFixed(2); // seconds left (tests read it)
        countdown.textContent = `${Math.ceil(left)} s left to feel`;
        if (left <= 0) {
          trial.update({ timedOut: true });
          ev('timeout', `${q.time_limit_s} s`);
          stimulusButtons.forEach((b) => (b.disabled = true));
          countdown.textContent = 'Time is up: please answer.';
          return;
        }
        timers.push(setTimeout(tick, 250));
      };
      tick();
    }

    const phaseArea = h('div', { class: 'phase', 'data-testid': 'phase', 'aria-live': 'polite' });
    const answerArea = h('div', { class: 'answers' });
    if (q.phases.length === 0) {
      if (stimulusButtons.length)
        parts.push(
          h('h2', { id: 'feel-heading', class: 'group-label' }, 'Feel each texture'),
          h('div', { class: 'stimuli', role: 'group', 'aria-labelledby': 'feel-heading' }, ...stimulusButtons),
        );
      if (q.show_maps) {
        const maps = h('div', { class: 'maps' });
        parts.push(maps);
        // The studio sends the rendered maps (never the documents: their parameters and seeds).
        for (const s of q.stimuli) {
          const c = h('canvas', { width: 600, height: 60, class: 'mini-map', 'aria-label': `Map of ${s.label}`, role: 'img' }) as HTMLCanvasElement;
          maps.append(h('div', {}, h('span', {}, s.label), c));
          if (s.map_f32) drawMiniMap(c, decodeF32(s.map_f32));
        }
      }
    } else {
      parts.push(phaseArea);
    }
    if (surface) parts.push(lineText, surface.el);
    else parts.push(strip.el);
    parts.push(answerArea);

    // ---- answer inputs
    if (needs.sliders) {
      setAnswer({ slider_p: q.sliders[0].start, slider_i: q.sliders[1].start });
      let inFlight = false;
      let again = false;
      const preview = async () => {
        if (inFlight) {
          again = true;
          return;
        }
        inFlight = true;
        try {
          const { slider_p, slider_i } = trial.get().answer;
          await client.call('experiment.preview', { trial: q.trial, slider_p: slider_p!, slider_i: slider_i! }, 30000);
        } catch (e) {
          msg.textContent = e instanceof Error ? e.message : String(e);
        }
        inFlight = false;
        if (again) {
          again = false;
          void preview();
        }
      };
      q.sliders.slice(0, 2).forEach((s, k) => {
        const id = `slider-${s.name}`;
        const input = h('input', { type: 'range', id, min: s.min, max: s.max, step: (s.max - s.min) / 200, value: s.start, class: 'big-slider', 'data-testid': id }) as HTMLInputElement;
        input.addEventListener('input', () => {
          setAnswer(k === 0 ? { slider_p: Number(input.value) } : { slider_i: Number(input.value) });
          void preview();
        });
        input.addEventListener('change', () => ev('slider', `${s.name}=${input.value}`));
        answerArea.append(h('div', { class: 'ctl' }, h('label', { for: id }, s.label || s.name), input));
      });
    }
    // Every word the participant reads is the library's (question.wording), as the terminal prints it.
    if (needs.choice) {
      // Visibly different from the row above: a heading says this row answers.
      const question = w.choice_question;
      const g = radioGroup(question, q.choices.map((c, i) => ({ value: c, text: w.choice_labels[i] ?? c })), (v) => {
        ev('choice', v);
        setAnswer({ choice: v });
      }, 'choices', 'answer-heading');
      answerArea.append(h('h2', { id: 'answer-heading', class: 'group-label' }, question), g.el);
    }
    /** A numbered scale: its question, its ends' words, one button per step. */
    const scale = (s: Scale, testid: string, pick: (v: number) => void) => {
      const opts = [];
      for (let v = s.min; v <= s.max; v++) opts.push({ value: String(v), text: String(v) });
      const ends = `${s.min}${s.min_label ? ` (${s.min_label})` : ''} to ${s.max}${s.max_label ? ` (${s.max_label})` : ''}`;
      const g = radioGroup(`${s.question} ${ends}`, opts, (v) => pick(Number(v)), testid);
      answerArea.append(h('p', { class: 'scale-label', 'data-testid': `${testid}-question` }, `${s.question} ${ends}`), g.el);
    };
    if (q.rating_scale && w.rating)
      scale(w.rating, 'rating', (v) => {
        ev('rating', String(v));
        setAnswer({ rating: v });
      });
    if (needs.digit && w.recall) scale(w.recall, 'digit', (v) => setAnswer({ digit: v }));
    if (q.confidence && w.confidence) scale(w.confidence, 'confidence', (v) => setAnswer({ confidence: v }));
    answerArea.append(submit, msg);

    submit.addEventListener('click', async () => {
      if (submit.disabled) return;
      trial.update({ saving: true });
      submit.textContent = 'Saving…';
      // A 2-D study's next textures are prepared before its clock starts (a bitmap takes seconds the first time).
      if (surface) timers.push(setTimeout(() => current() && trial.get().saving && (submit.textContent = 'Please wait: preparing the next textures…'), 1500));
      const answer = trial.get().answer;
      ev('answer', answer.choice ?? (answer.rating !== undefined ? String(answer.rating) : 'sliders'));
      // Every stroke sample reaches the studio before the answer (one lane, in order).
      if (surface) {
        surface.lift();
        await surface.flush();
      }
      // rt_ms, shown_at and answered_at are the server's (its onset per token).
      const response: Response = { ...answer, events };
      try {
        const next = await client.call('experiment.answer', { trial: q.trial, token: handout.token, response }, 60000);
        notice.hidden = true;
        show(next);
      } catch (e) {
        submit.textContent = 'Submit';
        if (e instanceof StudioError && (e.code === 'conflict' || e.code === 'not_found' || e.code === 'disconnected')) {
          // Refused by the token rule (or the connection was lost): say so on this
          // screen, then show what the engine holds now.
          showNotice(e.code === 'disconnected' ? 'The connection was lost before the answer arrived; it was not stored.' : e.message);
          wait('refused', 'The next step follows in a moment.');
          idleTimer = setTimeout(() => alive() && void load(), 1500);
        } else {
          msg.textContent = e instanceof Error ? e.message : String(e);
          msg.classList.add('error');
          trial.update({ saving: false });
        }
      }
    });

    screen.replaceChildren(h('div', { class: 'question', 'data-task': q.task, 'data-trial': q.trial, 'aria-describedby': q.prompt ? 'prompt' : undefined }, ...parts.filter((p): p is HTMLElement => !!p)));
    trial.update({});

    // ---- timed phases (working memory): stimulus, matrix, stimulus, then the questions
    if (q.phases.length) {
      answerArea.hidden = true;
      const runPhase = (k: number) => {
        if (!current()) return;
        if (k >= q.phases.length) {
          phaseArea.replaceChildren(h('p', {}, 'Now answer the questions.'));
          answerArea.hidden = false;
          trial.update({ inputsReady: true });
          return;
        }
        const ph = q.phases[k];
        const end = performance.now() + ph.duration_s * 1000;
        const left = h('span', { class: 'countdown' });
        if (ph.kind === 'stimulus') {
          phaseArea.replaceChildren(h('p', { class: 'prompt' }, `Feel ${named(ph.stimulus)} on the strip.`), left);
          void selectStimulus(ph.stimulus);
        } else if (ph.kind === 'matrix') {
          ev('matrix', 'shown');
          const cells = (q.matrix ?? []).map((d, i) => h('div', { class: 'cell', role: 'gridcell', 'aria-label': `row ${Math.floor(i / 4) + 1}, column ${(i % 4) + 1}: ${d || 'empty'}` }, d ? String(d) : ''));
          const rows = [0, 1, 2, 3].map((r) => h('div', { role: 'row', class: 'mrow' }, ...cells.slice(r * 4, r * 4 + 4)));
          phaseArea.replaceChildren(h('p', { class: 'prompt' }, 'Remember the digits.'), h('div', { class: 'matrix', role: 'grid', 'aria-label': 'Digit matrix', 'data-testid': 'matrix' }, ...rows), left);
        } else if (ph.kind === 'sequence') {
          // Working memory's digit sequence (verbal, executive): one digit at a
          // time, each shown for 80 % of its slot then blank (a repeated digit
          // is seen twice), as the terminal does. Executive (q.nback): each
          // press of Respond is a response to the digit on screen (or just gone).
          ev('sequence', 'shown');
          const seq = q.sequence ?? [];
          let stopKeys = () => {};
          const slot = (ph.duration_s * 1000) / Math.max(1, seq.length);
          const start = performance.now();
          const digit = h('div', { class: 'sequence-digit', 'data-testid': 'sequence-digit', 'aria-live': 'off' });
          const item = () => Math.min(seq.length - 1, Math.floor((performance.now() - start) / slot));
          const children: HTMLElement[] = [h('p', { class: 'prompt' }, `${w.sequence_instruction ?? ''}${q.nback ? ' Press Respond (or the space bar) each time.' : ''}`), digit];
          if (q.nback) {
            const presses: number[] = [];
            const respond = h('button', { type: 'button', class: 'big primary respond', 'data-testid': 'respond' }, 'Respond') as HTMLButtonElement;
            respond.addEventListener('click', () => {
              const i = item();
              if (!current() || i < 0 || presses[presses.length - 1] === i) return; // one response per digit
              presses.push(i);
              ev('respond', String(i));
              setAnswer({ presses: [...presses] });
            });
            children.push(respond);
            timers.push(setTimeout(() => respond.focus(), 0));
            // The space bar responds wherever the focus is (a focused button clicks itself).
            const onKey = (e: KeyboardEvent) => {
              if (e.code !== 'Space' || document.activeElement === respond) return;
              e.preventDefault();
              respond.click();
            };
            document.addEventListener('keydown', onKey);
            stopKeys = () => document.removeEventListener('keydown', onKey);
          }
          phaseArea.replaceChildren(...children, left);
          const draw = () => {
            const t = performance.now() - start;
            const i = Math.floor(t / slot);
            if (!current() || i >= seq.length) return stopKeys();
            const blank = t - i * slot >= 0.8 * slot;
            digit.textContent = blank ? '' : String(seq[i]);
            digit.dataset.item = blank ? '' : String(i);
            timers.push(setTimeout(draw, 20));
          };
          draw();
        } else {
          phaseArea.replaceChildren(h('p', {}, 'Please wait.'), left);
        }
        const tick = () => {
          if (!current()) return;
          const s = Math.max(0, (end - performance.now()) / 1000);
          left.textContent = `${Math.ceil(s)} s`;
          if (s <= 0) runPhase(k + 1);
          else timers.push(setTimeout(tick, 200));
        };
        tick();
      };
      runPhase(0);
    }
  }

  void load(true);
}
