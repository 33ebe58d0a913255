// The "Feel it" strip: the display on the page. Pointer Events (mouse, pen,
// touch; `touch-action: none`) and the arrow keys stream finger samples to the
// engine's player as `feel.move {seq, t_ms, x_mm, touch, coalesced?}`; the
// player's own report (`feel.state`, polled at 10 Hz) is shown as #player-position.
//
// Every sample carries the time the browser took it (the event's timeStamp:
// the page's monotonic clock, ms), and a pointermove carries the samples
// coalesced into it (getCoalescedEvents, where the browser has it): the
// studio plays each sample on arrival but measures the swipe (speed, its SD,
// direction) from these times, so a message that waited in a queue does not
// make the finger look fast.
//
// Touch semantics [choice]: a finger or pen touches while in contact
// (pointerdown … pointerup/cancel). A mouse touches while its button is held;
// with "Mouse hover touches" on (the default on the designer: a mouse has no
// contact sense, and sweeping it is the quickest way to feel), hovering over
// the strip counts as touch too. Leaving the strip always lifts the finger.

import { studio } from './ws';
import { h, stats, fmt } from './util';
import { hearIt } from './audio';
import FeelWorker from './feel-worker?worker';
import type { FingerSample, FromFeelWorker } from './feel-worker';
import type { FeelStateReply } from './generated/messages';

// Finger samples travel on their own WebSocket, owned by a small worker
// (feel-worker.ts, bundled by Vite as a module of its own).
let seq = 0;
let worker: Worker | null | undefined;
const sentAt = new Map<number, number>(); // fallback path (no Worker): main-thread times
let ackInstalled = false;

export function feelWorker(): Worker | null {
  if (worker !== undefined) return worker;
  try {
    const w = new FeelWorker();
    w.onmessage = (e: MessageEvent<FromFeelWorker>) => {
      if (!__TEXEL_TEST_HOOKS__) return;
      const m = e.data;
      if ('ack' in m) {
        stats.feelAcks++;
        if (typeof m.ms === 'number') pushAck(m.ms);
      } else if ('dropped' in m) stats.feelMovesSent--;
    };
    worker = w;
  } catch {
    worker = null;
  }
  return worker;
}

function pushAck(ms: number): void {
  if (!__TEXEL_TEST_HOOKS__) return;
  stats.pointerToAckMs.push(ms);
  if (stats.pointerToAckMs.length > 5000) stats.pointerToAckMs.splice(0, 1000);
}

function installAck(): void {
  if (ackInstalled) return;
  ackInstalled = true;
  studio().on('feel.ack', (m) => {
    const t0 = sentAt.get(m.seq);
    if (__TEXEL_TEST_HOOKS__) stats.feelAcks++;
    if (t0 !== undefined) {
      sentAt.delete(m.seq);
      pushAck(performance.now() - t0);
    }
  });
}

let lastT = 0; // the newest time sent: the studio refuses a clock that goes back

/**
 * Sends one finger sample taken at `t_ms` (an event's timeStamp, the page's clock) and, before it, the
 * samples coalesced into the same pointer event ([t_ms, x_mm], oldest first).
 */
export function sendMove(x_mm: number, touch: boolean, t_ms: number = performance.now(), coalesced: [number, number][] = []): void {
  const s = ++seq;
  // Input events carry the time of the input, others (blur, a key) their dispatch: one may trail the
  // other by a fraction of a millisecond, so the times sent never go back.
  const earlier: [number, number][] = [];
  for (const [t, x] of coalesced.slice(-64)) {
    lastT = Math.max(lastT, t);
    earlier.push([lastT, x]);
  }
  lastT = Math.max(lastT, t_ms);
  const t = lastT;
  const w = feelWorker();
  if (w) {
    const sample: FingerSample = { seq: s, t_ms: t, x_mm, touch, t0: performance.timeOrigin + performance.now(), ...(earlier.length ? { coalesced: earlier } : {}) };
    w.postMessage(sample);
    if (__TEXEL_TEST_HOOKS__) stats.feelMovesSent++;
  } else {
    installAck();
    if (sentAt.size > 2000) sentAt.clear();
    sentAt.set(s, performance.now());
    if (studio().send('feel.move', { seq: s, t_ms: t, x_mm, touch, ...(earlier.length ? { coalesced: earlier } : {}) }) && __TEXEL_TEST_HOOKS__)
      stats.feelMovesSent++;
  }
  hearIt.pointer(x_mm, touch);
}

export interface StripOptions {
  length_mm: number;
  hoverTouches?: boolean;
  onEnter?: () => void;
  label?: string;
  /** Draw the mm scale under the strip (default true; a participant's strip has none). */
  scale?: boolean;
}

export class FeelStrip {
  readonly el: HTMLElement;
  private strip: HTMLElement;
  private texture: HTMLCanvasElement;
  private scale: HTMLElement;
  private map: { values: Float32Array; origin_mm: number; spacing_mm: number } | null = null;
  private finger: HTMLElement;
  private playerMark: HTMLElement;
  private posText: HTMLElement;
  private pressed = false;
  private lastX = 0;
  private pollTimer: ReturnType<typeof setInterval> | null = null;
  length_mm: number;
  hoverTouches: boolean;

  constructor(private opts: StripOptions) {
    this.length_mm = opts.length_mm;
    this.hoverTouches = opts.hoverTouches ?? true;
    this.finger = h('div', { class: 'finger', 'aria-hidden': 'true' });
    this.playerMark = h('div', { class: 'player-mark', 'aria-hidden': 'true' });
    // The texture under the finger (the friction map drawn across the strip) and a mm scale below it.
    this.texture = h('canvas', { class: 'strip-texture', 'aria-hidden': 'true', 'data-testid': 'strip-texture' });
    this.scale = h('div', { class: 'strip-scale', 'aria-hidden': 'true', 'data-testid': 'strip-scale' });
    this.strip = h(
      'div',
      {
        class: 'strip',
        tabindex: 0,
        role: 'slider',
        'aria-label': opts.label ?? 'Feel it: the display. Move the pointer or a finger over it, or use the arrow keys',
        'aria-valuemin': 0,
        'aria-valuemax': Number.isFinite(this.length_mm) ? Math.round(this.length_mm) : undefined,
        'aria-valuenow': 0,
        'data-testid': 'feel-strip',
      },
      this.texture,
      this.finger,
      this.playerMark,
    );
    this.posText = h('span', { id: 'player-position', 'data-testid': 'player-position', 'data-mm': '', 'aria-live': 'off' }, '–');
    const hover = h('input', { type: 'checkbox', id: 'hover-touches', checked: this.hoverTouches }) as HTMLInputElement;
    hover.addEventListener('change', () => (this.hoverTouches = hover.checked));
    this.el = h(
      'section',
      { class: 'feel', 'aria-label': 'Feel it' },
      this.strip,
      this.scale,
      h(
        'div',
        { class: 'feel-status' },
        h('span', {}, 'Player: '),
        this.posText,
        h('label', { class: 'inline' }, hover, ' Mouse hover touches'),
      ),
    );
    this.bind();
    this.startPolling();
    feelWorker(); // connect before the first touch
  }

  private xOf(e: { clientX: number }): number {
    const r = this.strip.getBoundingClientRect();
    const f = Math.min(1, Math.max(0, (e.clientX - r.left) / r.width));
    return f * this.length_mm;
  }

  /** Moves the finger to `x` as of event `e` (its timeStamp), after the samples coalesced into it. */
  private move(x: number, touch: boolean, e?: Event, coalesced: [number, number][] = []): void {
    if (!Number.isFinite(x)) return; // the device's length is not known yet (hello)
    this.lastX = x;
    // A transform, not `left`: the marker moves on the compositor without a
    // layout or paint, so the frame after a pointer event is cheap and the
    // main thread is free for the next message (feel.ack) sooner.
    this.finger.style.transform = `translateX(${(100 * x) / this.length_mm}%)`;
    this.finger.classList.toggle('touching', touch);
    this.strip.setAttribute('aria-valuenow', x.toFixed(1));
    sendMove(x, touch, e ? e.timeStamp : performance.now(), coalesced);
  }

  private bind(): void {
    const s = this.strip;
    s.addEventListener('pointerenter', () => this.opts.onEnter?.());
    s.addEventListener('pointerdown', (e) => {
      this.pressed = true;
      s.setPointerCapture(e.pointerId);
      e.preventDefault();
      s.focus({ preventScroll: true });
      this.move(this.xOf(e), true, e);
    });
    s.addEventListener('pointermove', (e) => {
      const touch = this.pressed || (e.pointerType === 'mouse' && this.hoverTouches);
      if (!touch && e.pointerType !== 'mouse') return;
      // The samples the browser coalesced into this event, oldest first; the newest is the event itself.
      const all = typeof e.getCoalescedEvents === 'function' ? e.getCoalescedEvents() : [];
      const last = all.length ? all[all.length - 1] : e;
      const earlier = all.slice(0, -1).map((c): [number, number] => [c.timeStamp, this.xOf(c)]);
      this.move(this.xOf(last), touch, last, earlier);
    });
    const lift = (e: PointerEvent) => {
      this.pressed = false;
      const stillHover = e.type === 'pointerup' && e.pointerType === 'mouse' && this.hoverTouches;
      this.move(this.xOf(e), stillHover, e);
    };
    s.addEventListener('pointerup', lift);
    s.addEventListener('pointercancel', lift);
    s.addEventListener('pointerleave', (e) => {
      if (this.pressed) return; // captured: leave comes with pointerup
      this.move(this.xOf(e), false, e);
    });
    s.addEventListener('keydown', (e) => {
      const step = e.shiftKey ? 10 : 1;
      let x = this.lastX;
      if (e.key === 'ArrowRight') x += step;
      else if (e.key === 'ArrowLeft') x -= step;
      else if (e.key === 'Home') x = 0;
      else if (e.key === 'End') x = this.length_mm;
      else return;
      e.preventDefault();
      this.opts.onEnter?.();
      this.move(Math.min(this.length_mm, Math.max(0, x)), true, e);
    });
    s.addEventListener('keyup', (e) => {
      if (e.key.startsWith('Arrow') || e.key === 'Home' || e.key === 'End') this.move(this.lastX, false, e);
    });
    s.addEventListener('blur', (e) => this.move(this.lastX, false, e));
  }

  setLength(length_mm: number): void {
    if (length_mm === this.length_mm) return;
    this.length_mm = length_mm;
    this.strip.setAttribute('aria-valuemax', String(Math.round(length_mm)));
    this.drawScale();
    this.drawTexture();
  }

  /** The friction map to draw on the strip (the same samples the plots show). */
  setMap(values: Float32Array, origin_mm: number, spacing_mm: number): void {
    this.map = { values, origin_mm, spacing_mm };
    this.drawTexture();
  }

  private drawScale(): void {
    const L = this.length_mm;
    this.scale.replaceChildren();
    if (!(L > 0) || this.opts.scale === false) return;
    const step = L > 200 ? 50 : L > 50 ? 10 : L > 10 ? 5 : 1;
    for (let x = 0; x <= L + 1e-9; x += step) {
      const tick = h('span', { class: 'tick', style: `left: ${(100 * x) / L}%` }, `${x}`);
      this.scale.append(tick);
    }
    this.scale.append(h('span', { class: 'scale-unit' }, `mm (surface ${fmt(L, 2)} mm)`));
  }

  private drawTexture(): void {
    const c = this.texture;
    const m = this.map;
    const L = this.length_mm;
    const w = Math.max(200, Math.round(this.strip.clientWidth || 800));
    const ht = Math.max(40, Math.round(this.strip.clientHeight || 96));
    if (c.width !== w || c.height !== ht) {
      c.width = w;
      c.height = ht;
    }
    const ctx = c.getContext('2d');
    if (!ctx) return;
    ctx.clearRect(0, 0, w, ht);
    if (!m || !(L > 0) || !m.values.length) return;
    // Per pixel column: the min … max of the samples under it (a dense texture reads as a band)
    // and the mean drive over the millimetre around it (a line; a shorter window would alias).
    ctx.fillStyle = 'rgba(42, 111, 219, 0.3)';
    ctx.strokeStyle = '#1b3f8f';
    ctx.lineWidth = 1.5;
    ctx.beginPath();
    const n = m.values.length;
    const prefix = new Float64Array(n + 1);
    for (let i = 0; i < n; i++) prefix[i + 1] = prefix[i] + m.values[i];
    const half = Math.max(1, Math.round(0.5 / m.spacing_mm));
    for (let px = 0; px < w; px++) {
      const a = Math.max(0, Math.floor(((px / w) * L - m.origin_mm) / m.spacing_mm));
      const b = Math.min(n, Math.ceil((((px + 1) / w) * L - m.origin_mm) / m.spacing_mm) + 1);
      if (a >= b) continue;
      let lo = Infinity;
      let hi = -Infinity;
      for (let i = a; i < b; i++) {
        const v = m.values[i];
        if (v < lo) lo = v;
        if (v > hi) hi = v;
      }
      const c = (a + b) >> 1;
      const [ma, mb] = [Math.max(0, c - half), Math.min(n, c + half + 1)];
      const mean = (prefix[mb] - prefix[ma]) / (mb - ma);
      const y = (v: number) => ht - 4 - Math.min(1, Math.max(0, v)) * (ht - 8);
      ctx.fillRect(px, y(hi), 1, Math.max(1, y(lo) - y(hi)));
      if (px === 0) ctx.moveTo(px, y(mean));
      else ctx.lineTo(px, y(mean));
    }
    ctx.stroke();
  }

  private startPolling(): void {
    this.pollTimer = setInterval(async () => {
      if (!document.body.contains(this.el)) {
        if (this.pollTimer) clearInterval(this.pollTimer);
        return;
      }
      if (studio().state !== 'open') return;
      try {
        const st = await studio().request('feel.state', {}, { lane: 'feel.state', timeoutMs: 2000 });
        if (!st) return;
        this.showState(st);
      } catch {
        /* transient: next poll */
      }
    }, 100);
  }

  private showState(st: FeelStateReply): void {
    const p = st.position_mm;
    if (p === null || p === undefined || !Number.isFinite(p)) {
      this.posText.textContent = '–';
      this.posText.dataset.mm = '';
    } else {
      // The player extrapolates the finger up to 30 ms ahead (PlayerConfig::extrapolate_s), which may
      // run past an end of the surface: the position shown is the point of the surface under the finger.
      const onSurface = Number.isFinite(this.length_mm) ? Math.min(Math.max(p, 0), this.length_mm) : p;
      this.posText.textContent = `${fmt(onSurface, 2)} mm${st.touching ? ' (touching)' : ''}`;
      this.posText.dataset.mm = String(onSurface);
      this.posText.dataset.rawMm = String(p);
      this.playerMark.style.transform = `translateX(${(100 * onSurface) / this.length_mm}%)`;
    }
    this.posText.dataset.touching = String(!!st.touching);
    this.playerMark.classList.toggle('touching', !!st.touching);
  }
}
