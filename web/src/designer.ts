// Designer page (#/designer): the texture's parameters as controls, the
// document they make (docs/format.md), and live plots of the engine's answer
// to `design` on every input event (the service coalesces: latest wins).

import { studio, StudioError } from './ws';
import { h, decodeF32, download, base64ToBytes, bytesToBase64, fmt, stats, checksum } from './util';
import { stimulusSaver } from './stimuli';
import { MapPlot, HistogramPlot, SpectrumPlot } from './plots';
import { FeelStrip } from './feel';
import { hearIt } from './audio';
import { Store } from './store';
import type { CoarseProfile, RegionDoc, TexelTexture, TextureDocument } from './document';
import type { DesignReply, DeviceProfile, ExportRequest, HelloReply, Spectrum } from './generated/messages';
import './designer.css';

interface TexelParams {
  central_pitch_db: number;
  irregularity_db: number;
  texel_length_mm: number;
  seed: number;
  parameterization: 'moments' | 'log';
  quantization_db: number;
  /** The renderable band and how a texel is laid (docs/format.md): the library's defaults unless set. */
  out_of_band: 'redraw' | 'clamp';
  band_min_cpm: number;
  band_max_cpm: number;
  phase: 'continuous' | 'reset';
  fill: 'whole' | 'partial';
  coarse: 'constant' | 'sine' | 'points';
  coarse_value: number;
  sine_period_mm: number;
  sine_phase_deg: number;
  points: [number, number][];
  coarse_strength: number;
  fine_strength: number;
}

interface DesignerState {
  device: string | DeviceProfile;
  split: boolean;
  reference: string;
  reference_seed: number;
  /**
   * Format version of the reference's bytes (docs/format.md): 3 for a reference made here,
   * 2 for one imported from a version-2 (or 1) document, which keeps rendering its old bytes.
   */
  reference_version: number;
  texel: TexelParams;
  /** Keys of an imported texel texture the controls do not show (kept as they are). */
  extra: Record<string, unknown>;
  /** The last match's target and matched spectra, drawn over the spectrum. */
  overlays: { target?: Spectrum; match?: Spectrum };
  /** Swipe speed (mm/s) at which spatial frequencies are also shown in Hz (not part of the document). */
  speed_mm_s: number;
}

/** Where the page keeps the design between visits (this browser only). */
const SAVED_KEY = 'texel.designer.v1';
interface Saved {
  document: TextureDocument;
  speed_mm_s: number;
}

const defaults = (): TexelParams => ({
  central_pitch_db: 10,
  irregularity_db: -5,
  texel_length_mm: 0.25,
  seed: 1,
  parameterization: 'moments',
  quantization_db: 0,
  out_of_band: 'redraw',
  band_min_cpm: 0.01,
  band_max_cpm: 0,
  phase: 'continuous',
  fill: 'whole',
  coarse: 'constant',
  coarse_value: 1,
  sine_period_mm: 5,
  sine_phase_deg: 0,
  points: [],
  coarse_strength: 0,
  fine_strength: 1,
});

let hello: HelloReply | null = null;

export async function getHello(): Promise<HelloReply> {
  if (!hello) hello = await studio().call('hello', {}, 15000);
  return hello;
}

function deviceProfile(dev: string | DeviceProfile): DeviceProfile | undefined {
  if (typeof dev === 'object') return dev;
  return hello?.devices.find((d) => d.name === dev);
}

/** The device's length (mm) from its profile (the server's hello); NaN while unknown. */
export function deviceLength(dev: string | DeviceProfile): number {
  const p = deviceProfile(dev);
  return p ? p.samples * p.spacing_mm : NaN;
}

function halves(dev: string | DeviceProfile): { left: [number, number]; right: [number, number] } {
  const p = deviceProfile(dev);
  const l = p?.layout?.find((r) => r.name === 'left');
  const r = p?.layout?.find((r) => r.name === 'right');
  if (l && r) return { left: [l.start_mm, l.length_mm], right: [r.start_mm, r.length_mm] };
  const len = deviceLength(dev);
  // Half of the samples each, on the grid (a region must end inside the device).
  const half = p ? Math.floor(p.samples / 2) * p.spacing_mm : len / 2;
  return { left: [0, half], right: [half, half] };
}

function texelTexture(t: TexelParams, extra: Record<string, unknown>): TexelTexture {
  const tex: TexelTexture = {
    ...(extra as object),
    kind: 'texel',
    // Exactly as typed or set (never rounded: the document is what the page shows).
    central_pitch_db: t.central_pitch_db,
    irregularity_db: t.irregularity_db,
    texel_length_mm: t.texel_length_mm,
    seed: t.seed,
    parameterization: t.parameterization,
    quantization_db: t.quantization_db,
    coarse_strength: t.coarse_strength,
    fine_strength: t.fine_strength,
  };
  // The band and layout keys only where they differ from the library's defaults (the same texture either way).
  const d = defaults();
  if (t.out_of_band !== d.out_of_band) tex.out_of_band = t.out_of_band;
  if (t.band_min_cpm !== d.band_min_cpm) tex.band_min_cpm = t.band_min_cpm;
  if (t.band_max_cpm !== d.band_max_cpm) tex.band_max_cpm = t.band_max_cpm;
  if (t.phase !== d.phase) tex.phase = t.phase;
  if (t.fill !== d.fill) tex.fill = t.fill;
  let coarse: CoarseProfile;
  if (t.coarse === 'sine') coarse = { kind: 'sine', period_mm: t.sine_period_mm, phase_deg: t.sine_phase_deg };
  else if (t.coarse === 'points' && t.points.length) coarse = { kind: 'points', points: t.points };
  else coarse = { kind: 'constant', value: t.coarse_value };
  tex.coarse = coarse;
  return tex;
}

function round(x: number, d: number): number {
  const f = 10 ** d;
  return Math.round(x * f) / f;
}

export function buildDocument(s: DesignerState): TextureDocument {
  if (!s.split) return { format: 'texel-document', version: 1, device: s.device, texture: texelTexture(s.texel, s.extra) };
  const hv = halves(s.device);
  return {
    format: 'texel-document',
    version: s.reference_version,
    description: 'reference left, rendering right',
    device: s.device,
    regions: [
      { name: 'left', start_mm: hv.left[0], length_mm: hv.left[1], texture: { kind: 'reference', name: s.reference, seed: s.reference_seed } },
      { name: 'right', start_mm: hv.right[0], length_mm: hv.right[1], texture: texelTexture(s.texel, s.extra) },
    ],
  };
}

/** Reads a document back into the designer's state (what the controls cannot show is kept in `extra`). */
function stateFromDocument(doc: TextureDocument, prev: DesignerState): DesignerState {
  const s: DesignerState = { ...prev, texel: { ...prev.texel }, extra: {}, device: doc.device ?? prev.device };
  let texel: TexelTexture | undefined;
  if (doc.texture) {
    s.split = false;
    if (doc.texture.kind === 'texel') texel = doc.texture;
  } else if (doc.regions) {
    const ref = doc.regions.find((r) => r.texture.kind === 'reference');
    const tex = [...doc.regions].reverse().find((r) => r.texture.kind === 'texel');
    s.split = !!ref && doc.regions.length > 1;
    if (ref && ref.texture.kind === 'reference') {
      s.reference = ref.texture.name;
      s.reference_seed = ref.texture.seed ?? 1;
      s.reference_version = doc.version >= 3 ? 3 : 2;
    }
    if (tex) texel = tex.texture as TexelTexture;
  }
  if (texel) applyTexel(s, texel);
  return s;
}

/** Puts a texel texture into `s` (a fresh copy: its texel and extra are replaced). */
function applyTexel(s: DesignerState, t: TexelTexture): void {
  const known = new Set([
    'kind', 'central_pitch_db', 'irregularity_db', 'texel_length_mm', 'seed', 'parameterization',
    'quantization_db', 'coarse', 'coarse_strength', 'fine_strength', 'out_of_band', 'band_min_cpm', 'band_max_cpm', 'phase', 'fill',
  ]);
  s.extra = {};
  for (const [k, v] of Object.entries(t)) if (!known.has(k)) s.extra[k] = v;
  const p = (s.texel = { ...s.texel });
  p.central_pitch_db = t.central_pitch_db;
  p.irregularity_db = t.irregularity_db;
  p.texel_length_mm = t.texel_length_mm;
  p.seed = Number(t.seed ?? 1);
  p.parameterization = t.parameterization ?? 'moments';
  p.quantization_db = t.quantization_db ?? 0;
  const d = defaults();
  p.out_of_band = t.out_of_band ?? d.out_of_band;
  p.band_min_cpm = t.band_min_cpm ?? d.band_min_cpm;
  p.band_max_cpm = t.band_max_cpm ?? d.band_max_cpm;
  p.phase = t.phase ?? d.phase;
  p.fill = t.fill ?? d.fill;
  p.coarse_strength = t.coarse_strength ?? 0;
  p.fine_strength = t.fine_strength ?? 1;
  const c = t.coarse;
  p.coarse = 'constant';
  p.coarse_value = 1;
  if (c?.kind === 'constant') p.coarse_value = c.value ?? 1;
  else if (c?.kind === 'sine') {
    p.coarse = 'sine';
    p.sine_period_mm = c.period_mm;
    p.sine_phase_deg = c.phase_deg ?? 0;
  } else if (c?.kind === 'points') {
    p.coarse = 'points';
    p.points = c.points;
  } else if (c) s.extra.coarse = c; // values / reference profiles: kept, not editable here
}

// ---------------------------------------------------------------- controls

/**
 * A typed value's allowed range and whether it must be a whole number: the engine's own rule
 * (hello's texture_limits, from the library's constants), so what the page states is what the
 * engine applies. null = unbounded (any finite number).
 */
interface Rule {
  min: number | null;
  max: number | null;
  exclusiveMin?: boolean;
  exclusiveMax?: boolean;
  integer?: boolean;
}

/** The allowed range in words: "0.25 … 1000 mm", "above 0 mm", "any finite number". */
export function rangeText(rule: Rule, unit: string): string {
  const u = unit ? ` ${unit}` : '';
  const { min, max } = rule;
  if (min !== null && max !== null) return `${rule.exclusiveMin ? 'above ' : ''}${min} … ${rule.exclusiveMax ? 'below ' : ''}${max}${u}`;
  if (min !== null) return `${rule.exclusiveMin ? 'above' : 'at least'} ${min}${u}`;
  if (max !== null) return `at most ${max}${u}`;
  return 'any finite number';
}

/**
 * Reads a typed value: a number inside `rule`, or the reason it is refused
 * (never clamped, never rounded, never read as 0).
 */
export function parseTyped(text: string, rule: Rule, unit: string): { value: number } | { error: string } {
  const t = text.trim().replace(/\u2212/g, '-');
  if (t === '') return { error: 'enter a number' };
  const v = Number(t);
  if (!Number.isFinite(v) || !/^[-+]?(\d+\.?\d*|\.\d+)(e[-+]?\d+)?$/i.test(t)) return { error: `"${text.trim()}" is not a number` };
  const u = unit ? ` ${unit}` : '';
  if (rule.integer && !Number.isInteger(v)) return { error: `${t} is not a whole number` };
  const low = rule.min !== null && (rule.exclusiveMin ? v <= rule.min : v < rule.min);
  if (low || (rule.max !== null && (rule.exclusiveMax ? v >= rule.max : v > rule.max))) return { error: `${t}${u} is outside the allowed range ${rangeText(rule, unit)}` };
  return { value: v };
}

interface FieldCtl {
  row: HTMLElement;
  input: HTMLInputElement;
  num: HTMLInputElement;
  /** Shows the document's value (the only way the field changes). */
  set(v: number): void;
  /** Shows why a typed value was refused, at the field. */
  refuse(message: string): void;
  clear(): void;
}

/**
 * A range slider and a typed value for one parameter. The slider covers a
 * useful range (every shipped protocol's values); the typed value may be
 * anything the library accepts (`rule()`, from hello). A refused typed value
 * leaves the document unchanged and says why next to the field.
 */
function field(
  id: string,
  label: string,
  slider: { min: number; max: number; step: number },
  rule: () => Rule,
  value: number,
  unit: string,
  onValue: (v: number, typed: boolean) => void,
  extra?: HTMLElement,
): FieldCtl {
  const input = h('input', { type: 'range', id, min: slider.min, max: slider.max, step: slider.step, value, 'data-testid': id }) as HTMLInputElement;
  const err = h('p', { class: 'field-error', id: `${id}-error`, 'data-testid': `${id}-error`, hidden: true });
  const num = h('input', {
    type: 'text',
    inputmode: 'decimal',
    id: `${id}-value`,
    value,
    'aria-label': `${label} (${unit}), typed`,
    'aria-describedby': `${id}-error`,
    'data-testid': `${id}-value`,
    class: 'num',
  }) as HTMLInputElement;
  let shownValue = value;
  const ctl: FieldCtl = {
    row: h('div', { class: 'ctl' }, h('label', { for: id }, label, ' ', h('span', { class: 'unit' }, `(${unit})`)), h('div', { class: 'ctl-row' }, input, num), err, extra ?? null),
    input,
    num,
    set(v: number) {
      shownValue = v;
      input.value = String(v);
      if (document.activeElement !== num || num.getAttribute('aria-invalid') === 'true') num.value = String(v);
    },
    refuse(message: string) {
      editedSinceRefusal = false;
      num.value = String(shownValue);
      num.setAttribute('aria-invalid', 'true');
      err.textContent = `${label}: ${message}. The design keeps ${shownValue} ${unit}.`;
      err.hidden = false;
      err.scrollIntoView({ block: 'nearest' });
    },
    clear() {
      num.removeAttribute('aria-invalid');
      err.hidden = true;
      err.textContent = '';
    },
  };
  input.addEventListener('input', () => {
    ctl.clear();
    num.value = input.value;
    onValue(Number(input.value), false);
  });
  const unitWord = unit.startsWith('dB') ? 'dB' : unit.startsWith('cycles/mm') ? 'cycles/mm' : unit === 'mm' || unit === 'degrees' || unit === 'mm/s' ? unit : '';
  // The range the engine accepts, stated at the field (its tooltip) as in its refusals.
  num.addEventListener('focus', () => (num.title = `Allowed: ${rangeText(rule(), unitWord)}`));
  const commit = () => {
    if (num.value.trim() === String(shownValue) && num.getAttribute('aria-invalid') !== 'true') return;
    const r = parseTyped(num.value, rule(), unitWord);
    if ('error' in r) {
      ctl.refuse(r.error);
      return;
    }
    ctl.clear();
    if (r.value !== shownValue) onValue(r.value, true);
  };
  num.addEventListener('change', commit);
  // Leaving a refused field after typing in it commits what it holds: a value the browser's own
  // change event misses (one equal to the value on focus, as the kept value typed back) clears the
  // refusal too. (A Tab fires change, then blur: the refusal that change shows stays.)
  let editedSinceRefusal = false;
  num.addEventListener('input', () => (editedSinceRefusal = true));
  num.addEventListener('blur', () => {
    if (num.getAttribute('aria-invalid') === 'true' && editedSinceRefusal) commit();
  });
  num.addEventListener('keydown', (e) => {
    if (e.key === 'Enter') {
      e.preventDefault();
      commit();
    }
  });
  return ctl;
}

function select(id: string, label: string, options: [string, string][], value: string, onChange: (v: string) => void): { row: HTMLElement; el: HTMLSelectElement } {
  const el = h('select', { id, 'data-testid': id }) as HTMLSelectElement;
  for (const [v, t] of options) el.append(h('option', { value: v }, t));
  el.value = value;
  el.addEventListener('change', () => onChange(el.value));
  return { row: h('div', { class: 'ctl' }, h('label', { for: id }, label), el), el };
}

// ---------------------------------------------------------------- page

function initialState(): DesignerState {
  return {
    device: 'tpad',
    split: false,
    reference: '4sin',
    reference_seed: 1,
    reference_version: 3,
    texel: defaults(),
    extra: {},
    overlays: {},
    speed_mm_s: 100,
  };
}

function loadSaved(): Saved | null {
  try {
    const text = localStorage.getItem(SAVED_KEY);
    if (!text) return null;
    const s = JSON.parse(text) as Saved;
    return s && typeof s === 'object' && s.document?.format === 'texel-document' ? s : null;
  } catch {
    return null;
  }
}

/**
 * Writes the mounted designer's waiting save at once. The page's end (reload,
 * close, navigation, a hidden tab that may be discarded) calls it: pagehide
 * and beforeunload fire on a reload or close, visibilitychange to "hidden"
 * also on mobile browsers, which may skip the other two.
 */
let flushSavedDesign: (() => void) | null = null;
window.addEventListener('pagehide', () => flushSavedDesign?.());
window.addEventListener('beforeunload', () => flushSavedDesign?.());
document.addEventListener('visibilitychange', () => {
  if (document.visibilityState === 'hidden') flushSavedDesign?.();
});

/** The state without what belongs to one moment (match overlays): what undo, redo and saving keep. */
function lasting(s: DesignerState): string {
  return JSON.stringify(buildDocument(s)) + `|${s.speed_mm_s}`;
}

export function mountDesigner(root: HTMLElement): void {
  // The page's one state: controls write it, render() (below) reads it.
  const saved = loadSaved();
  const start = initialState();
  const store = new Store<DesignerState>(saved ? { ...stateFromDocument(saved.document, start), speed_mm_s: saved.speed_mm_s || 100 } : start);
  const setTexel = (p: Partial<TexelParams>) => store.update((st) => ({ texel: { ...st.texel, ...p } }));
  const client = studio();

  const mapPlot = new MapPlot();
  const hist = new HistogramPlot();
  const spec = new SpectrumPlot();
  let lastSpectrum: Spectrum | null = null;
  let lastReply: DesignReply | null = null;
  let lastSelectedKey = '';
  let stripActiveUntil = 0;

  // Errors: a status bar that stays in view (role=alert), or a message at the control concerned.
  const status = h('div', { class: 'status designer-status', role: 'status', 'aria-live': 'polite', 'data-testid': 'designer-status' });
  const alertBox = h('div', { class: 'designer-alert', role: 'alert', 'data-testid': 'designer-alert', hidden: true });
  const bytesEl = h('span', { class: 'bytes', 'data-testid': 'encoded-bytes', id: 'encoded-bytes' }, '–');
  const hexEl = h('code', { class: 'hex', 'data-testid': 'encoded-hex' });
  const pitchCpm = h('span', { class: 'cpm', 'data-testid': 'pitch-cpm' });
  const irrCpm = h('span', { class: 'cpm', 'data-testid': 'irregularity-cpm' });
  const periodCpm = h('span', { class: 'cpm', 'data-testid': 'sine-period-cpm' });
  const driveWarn = h('p', { class: 'drive-warning', 'data-testid': 'drive-warning', hidden: true });
  const hzNote = h('p', { class: 'hint', 'data-testid': 'hz-note' });
  const texelsEl = h('span', { 'data-testid': 'texels' });
  const flatWarn = h('p', { class: 'drive-warning', 'data-testid': 'flat-warning', role: 'status', hidden: true });
  const elapsedEl = h('span', { 'data-testid': 'elapsed' });

  // --- design requests and redraw timing
  let gen = 0;
  let drawnGen = 0;
  const t0s: { g: number; t0: number }[] = [];
  /** A typed value the engine has yet to accept: refused (and undone) if its design fails. */
  let pending: { g: number; ctl: FieldCtl; prev: DesignerState } | null = null;
  // Its length comes from the device's profile (hello) and each design reply's grid.
  const strip = new FeelStrip({ length_mm: NaN, onEnter: () => {
    stripActiveUntil = performance.now() + 30000;
    void selectForFeel();
  } });

  async function selectForFeel(): Promise<void> {
    const doc = buildDocument(store.get());
    const key = JSON.stringify(doc);
    if (key === lastSelectedKey) return;
    lastSelectedKey = key;
    try {
      await client.request('feel.select', { document: doc }, { lane: 'feel.select', timeoutMs: 30000 });
    } catch (e) {
      lastSelectedKey = '';
      showError(e);
    }
  }

  function message(e: unknown): string {
    return e instanceof Error ? e.message : String(e);
  }

  /** Shows an error next to `near` when given (else in the alert bar, which stays in view). */
  function showError(e: unknown, near?: HTMLElement): void {
    const text = message(e);
    status.textContent = '';
    if (near) {
      near.textContent = text;
      near.hidden = false;
      near.scrollIntoView({ block: 'nearest' });
      return;
    }
    alertText.textContent = text;
    alertBox.hidden = false;
  }
  const alertText = h('span', { 'data-testid': 'designer-alert-text' });
  const alertClose = h('button', { type: 'button', class: 'link', 'aria-label': 'Dismiss the message', onclick: () => (alertBox.hidden = true) }, '×');
  alertBox.append(alertText, alertClose);

  async function design(): Promise<void> {
    const g = ++gen;
    if (__TEXEL_TEST_HOOKS__) {
      t0s.push({ g, t0: performance.now() });
      if (t0s.length > 500) t0s.splice(0, t0s.length - 500);
    }
    if (__TEXEL_TEST_HOOKS__) stats.designsSent++;
    let reply: DesignReply | null;
    try {
      reply = await client.request('design', { document: buildDocument(store.get()) }, { lane: 'design', timeoutMs: 60000 });
    } catch (e) {
      if (e instanceof StudioError && e.code === 'superseded') return;
      if (pending && g >= pending.g) {
        // The engine refused a typed value: say so at its field and keep the design as it was.
        const p = pending;
        pending = null;
        applying = true;
        store.update(p.prev);
        applying = false;
        // The refused value is no step to undo.
        if (undoStack.length && lasting(undoStack[undoStack.length - 1]) === lasting(p.prev)) undoStack.pop();
        undoBtn.disabled = !undoStack.length;
        p.ctl.refuse(message(e));
        return;
      }
      if (g >= drawnGen) showError(e);
      return;
    }
    if (!reply || g < drawnGen) return; // superseded or stale
    if (pending && g >= pending.g) pending = null;
    drawnGen = g;
    draw(reply);
    await Promise.resolve(); // uPlot commits its redraw in a microtask queued by setData
    if (__TEXEL_TEST_HOOKS__) {
      const t1 = performance.now();
      for (let i = t0s.length - 1; i >= 0; i--)
        if (t0s[i].g <= g) {
          stats.sliderToRedrawMs.push(t1 - t0s[i].t0);
          t0s.splice(i, 1);
        }
      if (stats.sliderToRedrawMs.length > 5000) stats.sliderToRedrawMs.splice(0, 1000);
      stats.designsDrawn++;
    }
    if (performance.now() < stripActiveUntil) void selectForFeel();
  }

  function draw(r: DesignReply): void {
    lastReply = r;
    alertBox.hidden = true;
    const values = decodeF32(r.map_f32);
    const analysed = [...r.regions].reverse().find((x) => x.kind === 'texel') ?? r.regions[r.regions.length - 1];
    mapPlot.setMap(r.grid.origin_mm, r.grid.spacing_mm, values, r.regions, analysed ? analysed.start_mm + Math.min(3, analysed.length_mm / 2) : undefined);
    if (__TEXEL_TEST_HOOKS__) stats.lastMapChecksum = checksum(values);
    hearIt.setMap(values, r.grid.origin_mm, r.grid.spacing_mm);
    if (r.histogram) {
      hist.set(r.histogram.edges_cpm, r.histogram.counts, r.histogram.pdf);
      if (__TEXEL_TEST_HOOKS__) stats.lastHistChecksum = checksum(r.histogram.counts.concat(r.histogram.edges_cpm));
    }
    if (r.spectrum) {
      lastSpectrum = r.spectrum;
      const overlays = store.get().overlays;
      spec.set(r.spectrum, overlays.target, overlays.match);
    }
    if (r.encoded && r.encoded.bytes !== null) {
      bytesEl.textContent = `${r.encoded.bytes} bytes`;
      bytesEl.dataset.bytes = String(r.encoded.bytes);
      const hex = r.encoded.hex ?? '';
      hexEl.textContent = hex.length > 72 ? `${hex.slice(0, 72)}…` : hex;
      hexEl.title = hex;
      if (__TEXEL_TEST_HOOKS__) stats.lastEncodedBytes = r.encoded.bytes;
    } else {
      bytesEl.textContent = r.encoded?.error ? 'not encodable' : '–';
      bytesEl.dataset.bytes = '';
      hexEl.textContent = r.encoded?.error ?? '';
    }
    texelsEl.textContent = r.texels !== undefined ? `${r.texels} texels` : '';
    // Whole texels only: what the last texel does not reach stays flat. Say so (it was silent) when a
    // finger can feel it: 1 mm or more (0.25 mm texels leave 0.04 mm of the tpad, not worth a word).
    const flat = r.uncovered_mm ?? 0;
    const L = store.get().texel.texel_length_mm;
    flatWarn.hidden = !(flat >= 1);
    flatWarn.textContent = flatWarn.hidden
      ? ''
      : `With ${L} mm texels, ${r.texels} whole texel${r.texels === 1 ? '' : 's'} cover the texture region; the last ${fmt(flat, 2)} mm of it are flat (no texel fits there). ` +
        'A shorter texel length, a length that divides the region, or "a final partial texel" (Region end) textures all of it.';
    elapsedEl.textContent = r.elapsed_ms !== undefined ? `engine ${fmt(r.elapsed_ms, 1)} ms` : '';
    strip.setLength(r.grid.count * r.grid.spacing_mm);
    strip.setMap(values, r.grid.origin_mm, r.grid.spacing_mm);
    showFrequencies();
  }

  /**
   * Spatial frequencies in Hz at the chosen swipe speed (f = cycles/mm × mm/s),
   * and a warning when the drive lies above the display's response corner
   * (the device profile's response, from hello).
   */
  function showFrequencies(): void {
    const s = store.get();
    const v = s.speed_mm_s;
    const hz = (cpm: number) => `${fmt(cpm * v, cpm * v >= 100 ? 0 : 1)} Hz`;
    const r = lastReply;
    const pitch = r && typeof r.central_pitch_cpm === 'number' ? r.central_pitch_cpm : null;
    const irrV = r && typeof r.irregularity_cpm === 'number' ? r.irregularity_cpm : null;
    pitchCpm.textContent = pitch !== null ? `= ${fmt(pitch, 3)} cycles/mm = ${hz(pitch)} at ${v} mm/s` : '';
    irrCpm.textContent = irrV !== null ? `= ${fmt(irrV, 3)} cycles/mm = ${hz(irrV)} at ${v} mm/s` : '';
    const period = s.texel.sine_period_mm;
    periodCpm.textContent = period > 0 ? `= ${fmt(1 / period, 3)} cycles/mm = ${hz(1 / period)} at ${v} mm/s` : '';
    const dev = deviceProfile(s.device);
    const corner = dev?.response?.corner_hz;
    spec.setCorner(corner ? corner / v : null, corner ? `${dev!.name} corner ${corner} Hz at ${v} mm/s` : '');
    hzNote.textContent =
      `At ${v} mm/s, 1 cycle/mm is ${v} Hz` + (corner ? `; ${dev!.name}'s ${corner} Hz corner is ${fmt(corner / v, 2)} cycles/mm.` : '.');
    const warnings: string[] = [];
    if (corner && pitch !== null && pitch * v > corner)
      warnings.push(
        `At ${v} mm/s the Central Pitch drives ${hz(pitch)}, above ${dev!.name}'s response corner of ${corner} Hz ` +
          `(order ${dev!.response!.order ?? 1} low-pass): the display renders it weaker than drawn. ` +
          `Slower swipes or a lower Central Pitch stay within its response.`,
      );
    if (dev && pitch !== null && pitch * v > dev.refresh_hz / 2)
      warnings.push(`It also lies above half of ${dev.name}'s ${dev.refresh_hz} Hz refresh rate, so it aliases.`);
    driveWarn.textContent = warnings.join(' ');
    driveWarn.hidden = !warnings.length;
  }

  // --- controls: each writes the store; render() shows the store in them
  const lim = (k: keyof NonNullable<HelloReply['texture_limits']>, fallback: Rule): (() => Rule) => () => {
    const r = hello?.texture_limits?.[k];
    return r ? { min: r.min, max: r.max, exclusiveMin: r.exclusive_min, exclusiveMax: r.exclusive_max } : fallback;
  };
  // Central Pitch on a device lies in its renderable band too (hello's device_limits).
  const pitchRule = (): Rule => {
    const dev = store.get().device;
    const name = typeof dev === 'string' ? dev : dev.name;
    const d = hello?.device_limits.find((x) => x.device === name)?.central_pitch_db;
    const r = d ? { min: d.min, max: d.max } : lim('central_pitch_db', { min: -40, max: 40 })();
    // The texture's own band narrows it (device_limits assume the default band_min of 0.01 cycles/mm).
    const t = store.get().texel;
    const lo = 10 * Math.log10(t.band_min_cpm);
    const hi = t.band_max_cpm > 0 ? 10 * Math.log10(t.band_max_cpm) : Infinity;
    return { min: Math.max(r.min ?? -Infinity, round(lo, 6)), max: Math.min(r.max ?? Infinity, hi === Infinity ? Infinity : round(hi, 6)) };
  };
  // Irregularity under the log parameterization is a dB of log-spread (>= 0).
  const irrRule = () => lim(store.get().texel.parameterization === 'log' ? 'irregularity_db_log' : 'irregularity_db', { min: -60, max: 40 })();
  // A texel length also makes at most max_map_samples texels on the device (the studio's cap, checked
  // by the engine as this same quotient).
  const lengthRule = (): Rule => {
    const r = lim('texel_length_mm', { min: 1e-6, max: 1000 })();
    const cap = hello?.limits.max_map_samples;
    const len = deviceLength(store.get().device);
    const shortest = cap && Number.isFinite(len) ? len / cap : 0;
    return { ...r, min: Math.max(r.min ?? 0, shortest) };
  };
  /** Commits a value; a typed one stays pending until the engine accepts it (design() refuses it otherwise). */
  const commitTexel = (ctl: () => FieldCtl, p: Partial<TexelParams>, typed: boolean) => {
    const prev = store.get();
    setTexel(p);
    if (typed) pending = { g: gen, ctl: ctl(), prev };
  };
  const t = store.get().texel;
  const pitch: FieldCtl = field('central-pitch', 'Central Pitch', { min: -10, max: 19.5, step: 0.1 }, pitchRule, t.central_pitch_db, 'dB re 1 cycle/mm',
    (v, typed) => commitTexel(() => pitch, { central_pitch_db: v }, typed), pitchCpm);
  const irr: FieldCtl = field('irregularity', 'Irregularity', { min: -30, max: 20, step: 0.1 }, irrRule, t.irregularity_db, 'dB',
    (v, typed) => commitTexel(() => irr, { irregularity_db: v }, typed), irrCpm);
  const length: FieldCtl = field('texel-length', 'Texel length', { min: 0.05, max: 100, step: 0.01 }, lengthRule, t.texel_length_mm, 'mm',
    (v, typed) => commitTexel(() => length, { texel_length_mm: v }, typed));
  const seedErr = h('p', { class: 'field-error', id: 'seed-error', 'data-testid': 'seed-error', hidden: true });
  const seedIn = h('input', { type: 'text', inputmode: 'numeric', id: 'seed', value: t.seed, 'data-testid': 'seed', class: 'num', 'aria-describedby': 'seed-error' }) as HTMLInputElement;
  const seedCtl: FieldCtl = {
    row: h('div'),
    input: seedIn,
    num: seedIn,
    set(v: number) {
      seedIn.value = String(v);
    },
    refuse(msg: string) {
      seedIn.value = String(store.get().texel.seed);
      seedIn.setAttribute('aria-invalid', 'true');
      seedErr.textContent = `Seed: ${msg}. The design keeps seed ${store.get().texel.seed}.`;
      seedErr.hidden = false;
      seedErr.scrollIntoView({ block: 'nearest' });
    },
    clear() {
      seedIn.removeAttribute('aria-invalid');
      seedErr.hidden = true;
    },
  };
  seedIn.addEventListener('change', () => {
    // A seed is a whole number 0 … 2^53 − 1 (exact in the page's numbers and the document's JSON).
    const r = parseTyped(seedIn.value, { min: 0, max: Number.MAX_SAFE_INTEGER, integer: true }, '');
    if ('error' in r) return seedCtl.refuse(r.error);
    seedCtl.clear();
    commitTexel(() => seedCtl, { seed: r.value }, true);
  });
  const newDraw = h('button', { type: 'button', 'data-testid': 'new-draw', onclick: () => { seedCtl.clear(); setTexel({ seed: Math.floor(Math.random() * 2 ** 31) }); } }, 'New draw');
  const param = select('parameterization', 'Parameterization', [['moments', 'moments (mean, SD)'], ['log', 'log (lognormal μ, σ)']], t.parameterization, (v) => {
    const irregularity = v === 'log' && store.get().texel.irregularity_db < 0 ? { irregularity_db: 0 } : {};
    setTexel({ parameterization: v as 'moments' | 'log', ...irregularity });
  });
  const quant: FieldCtl = field('quantization', 'Quantization', { min: 0, max: 20, step: 0.5 }, lim('quantization_db', { min: 0, max: 20 }), t.quantization_db, 'dB, 0 = off',
    (v, typed) => commitTexel(() => quant, { quantization_db: v }, typed));
  // The band's top on this device: the texture's band_max where set, else (and at most) the grid's Nyquist
  // frequency — the renderer's rule; band_min must lie below it.
  const bandMinRule = (): Rule => {
    const dev = store.get().device;
    const name = typeof dev === 'string' ? dev : dev.name;
    const d = hello?.device_limits.find((x) => x.device === name)?.band_min_cpm;
    const r: Rule = d ? { min: d.min, max: d.max, exclusiveMax: d.exclusive_max } : lim('band_min_cpm', { min: 1e-12, max: 1e12 })();
    const own = store.get().texel.band_max_cpm;
    return own > 0 && (r.max === null || own < r.max) ? { ...r, max: own, exclusiveMax: true } : r;
  };
  const oob = select('out-of-band', 'Draws outside the band', [['redraw', 'redrawn'], ['clamp', 'clamped to the edge']], t.out_of_band, (v) =>
    setTexel({ out_of_band: v as TexelParams['out_of_band'] }));
  const bandMin: FieldCtl = field('band-min', 'Lowest texel frequency', { min: 0.01, max: 5, step: 0.01 }, bandMinRule, t.band_min_cpm, 'cycles/mm',
    (v, typed) => commitTexel(() => bandMin, { band_min_cpm: v }, typed));
  const bandMax: FieldCtl = field('band-max', 'Highest texel frequency', { min: 0, max: 10, step: 0.1 }, lim('band_max_cpm', { min: 0, max: 1e12 }), t.band_max_cpm, 'cycles/mm, 0 = Nyquist',
    (v, typed) => commitTexel(() => bandMax, { band_max_cpm: v }, typed));
  const phaseSel = select('phase', 'Texel phase', [['continuous', 'continuous'], ['reset', 'reset (abrupt boundaries)']], t.phase, (v) =>
    setTexel({ phase: v as TexelParams['phase'] }));
  const fillSel = select('fill', 'Region end', [['whole', 'whole texels, then flat'], ['partial', 'a final partial texel']], t.fill, (v) =>
    setTexel({ fill: v as TexelParams['fill'] }));
  const cStrength: FieldCtl = field('coarse-strength', 'Coarse strength C', { min: 0, max: 1, step: 0.01 }, lim('coarse_strength', { min: 0, max: 1 }), t.coarse_strength, '0…1',
    (v, typed) => commitTexel(() => cStrength, { coarse_strength: v }, typed));
  const fStrength: FieldCtl = field('fine-strength', 'Fine strength F', { min: 0, max: 1, step: 0.01 }, lim('fine_strength', { min: 0, max: 1 }), t.fine_strength, '0…1',
    (v, typed) => commitTexel(() => fStrength, { fine_strength: v }, typed));

  const constVal: FieldCtl = field('coarse-value', 'Constant value', { min: 0, max: 1, step: 0.01 }, lim('coarse_value', { min: 0, max: 1 }), t.coarse_value, '0…1',
    (v, typed) => commitTexel(() => constVal, { coarse_value: v }, typed));
  const sinePeriod: FieldCtl = field('sine-period', 'Sine period', { min: 0.5, max: 100, step: 0.1 }, lim('sine_period_mm', { min: 1e-9, max: 1e9 }), t.sine_period_mm, 'mm',
    (v, typed) => commitTexel(() => sinePeriod, { sine_period_mm: v }, typed), periodCpm);
  const sinePhase: FieldCtl = field('sine-phase', 'Sine phase', { min: 0, max: 360, step: 1 }, lim('sine_phase_deg', { min: -1e9, max: 1e9 }), t.sine_phase_deg, 'degrees',
    (v, typed) => commitTexel(() => sinePhase, { sine_phase_deg: v }, typed));
  const speed: FieldCtl = field('swipe-speed', 'Swipe speed', { min: 10, max: 500, step: 1 }, () => ({ min: 0, max: 10000, exclusiveMin: true }), store.get().speed_mm_s, 'mm/s',
    (v) => store.update({ speed_mm_s: v }));
  const pointsInfo = h('p', { class: 'hint', 'data-testid': 'points-info' });
  const drawBtn = h('button', { type: 'button', 'aria-pressed': 'false', 'data-testid': 'draw-coarse' }, 'Draw on the map') as HTMLButtonElement;
  const coarseSel = select('coarse-kind', 'Coarse profile', [['constant', 'constant'], ['sine', 'sine'], ['points', 'drawn on the map']], t.coarse, (v) => {
    setDrawMode(v === 'points' && !store.get().texel.points.length);
    setTexel({ coarse: v as TexelParams['coarse'] });
  });
  const coarseParams = h('div', { class: 'coarse-params' });
  function showCoarse(t: TexelParams): void {
    coarseParams.replaceChildren();
    if (t.coarse === 'constant') coarseParams.append(constVal.row);
    else if (t.coarse === 'sine') coarseParams.append(sinePeriod.row, sinePhase.row);
    else {
      pointsInfo.textContent = t.points.length ? `${t.points.length} drawn points` : 'Press "Draw on the map" and drag over the map.';
      coarseParams.append(pointsInfo);
    }
  }
  function setDrawMode(on: boolean): void {
    mapPlot.drawMode = on;
    drawBtn.setAttribute('aria-pressed', String(on));
    drawBtn.textContent = on ? 'Drawing: drag over the map (click to stop)' : 'Draw on the map';
    mapPlot.el.classList.toggle('drawing', on);
  }
  drawBtn.addEventListener('click', () => setDrawMode(!mapPlot.drawMode));
  mapPlot.onDrawn = (pts) => {
    const s = store.get();
    const hv = halves(s.device);
    const start = s.split ? hv.right[0] : 0;
    const len = s.split ? hv.right[1] : deviceLength(s.device);
    const local = pts
      .map(([x, v]) => [x - start, v] as [number, number])
      .filter(([x]) => x >= 0 && x <= len)
      .sort((a, b) => a[0] - b[0]);
    const out: [number, number][] = [];
    for (const [x, v] of local) if (!out.length || x > out[out.length - 1][0] + 1e-3) out.push([round(x, 3), round(v, 3)]);
    if (!out.length) {
      showError('Draw over the rendering (the texel region) to set its coarse profile.');
      return;
    }
    setDrawMode(false);
    // C = 0 would hide the profile: show it at full strength.
    setTexel({ points: out, coarse: 'points', ...(s.texel.coarse_strength === 0 ? { coarse_strength: 1 } : {}) });
  };

  // device, regions, reference
  const deviceSel = select('device', 'Device', [['tpad', 'tpad']], 'tpad', (v) => store.update({ device: v }));
  const splitSel = select('regions', 'Regions', [['single', 'single texture'], ['split', 'reference left, rendering right']], 'single', (v) =>
    store.update({ split: v === 'split', overlays: {} }),
  );
  // A reference chosen here is a new one (format version 3).
  const refSel = select('reference', 'Reference', [['4sin', '4sin']], store.get().reference, (v) => store.update({ reference: v, reference_version: 3, overlays: {} }));
  const refRow = refSel.row;
  refRow.hidden = true;

  const matchBtn = h('button', { type: 'button', 'data-testid': 'match', disabled: true }, 'Match a reference') as HTMLButtonElement;
  const matchInfo = h('p', { class: 'hint match-info', 'data-testid': 'match-info', 'aria-live': 'polite' });
  const matchErr = h('p', { class: 'field-error', role: 'alert', 'data-testid': 'match-error', hidden: true });
  matchBtn.addEventListener('click', async () => {
    matchBtn.disabled = true;
    matchErr.hidden = true;
    matchInfo.textContent = 'encoding the reference…';
    try {
      // Region 0 is the reference on the left; the service puts the match into the last Texel region.
      const r = await client.call('match', { document: buildDocument(store.get()), region: 0 }, 120000);
      const reg = r.region as unknown as RegionDoc;
      const est = r.encoded.result.estimate;
      const flags = [
        est.no_texture ? 'the reference has no texture' : '',
        est.at_bound.central_pitch ? 'Central Pitch at the edge of the search range' : '',
        est.at_bound.irregularity ? 'Irregularity at the edge of the search range' : '',
      ].filter(Boolean);
      const d = r.distance_jnd;
      const verdict = d < 1 ? 'below 1 JND: the model predicts the two feel alike' : `${fmt(d, 1)} times what a person just notices: the two should feel different`;
      // The model's JND (docs/encoder.md, "distance"): 1 dB of felt pitch or of noisiness.
      matchInfo.replaceChildren(
        h('strong', { 'data-testid': 'match-distance' }, `Felt distance ${fmt(d, 2)} JND`),
        ` (${verdict}). Matched in ${r.encoded.bytes} bytes. `,
        h('span', { 'data-testid': 'jnd-meaning' },
          `1 JND (just-noticeable difference) is a 1 dB change in felt pitch (about 25 % in vibration frequency) or 1 dB in noisiness, ` +
          `the smallest change a person reliably feels; the distance combines both (perception model ${r.encoded.result.model.version}). `),
        'The spectrum shows the reference (dashed), the match (wide pale band) and the design (line).',
        flags.length ? ` Note: ${flags.join('; ')}.` : '',
      );
      store.update((st) => {
        const ns: DesignerState = { ...st, overlays: { target: r.target_spectrum, match: r.match_spectrum } };
        if (reg?.texture?.kind === 'texel') applyTexel(ns, reg.texture);
        return ns;
      });
    } catch (e) {
      matchInfo.textContent = '';
      showError(e, matchErr);
    } finally {
      matchBtn.disabled = !store.get().split;
    }
  });

  // A field shows the document's value exactly (String(v): the shortest form that reads back as v).
  const shown = (v: number): number => v;

  // --- undo / redo and the design saved in this browser
  const undoStack: DesignerState[] = [];
  const redoStack: DesignerState[] = [];
  let applying = false;
  let lastPush = 0;
  const undoBtn = h('button', { type: 'button', 'data-testid': 'undo', disabled: true, 'aria-keyshortcuts': 'Control+Z', onclick: () => undo() }, 'Undo') as HTMLButtonElement;
  const redoBtn = h('button', { type: 'button', 'data-testid': 'redo', disabled: true, 'aria-keyshortcuts': 'Control+Shift+Z', onclick: () => redo() }, 'Redo') as HTMLButtonElement;
  const savedNote = h('span', { class: 'hint', 'data-testid': 'saved-note' }, saved ? 'Restored the design saved in this browser.' : '');
  function history(s: DesignerState, prev: DesignerState): void {
    if (applying || lasting(s) === lasting(prev)) return;
    const now = performance.now();
    // A slider drag is one step: changes less than 0.5 s apart join the step before.
    if (now - lastPush > 500 || !undoStack.length) undoStack.push({ ...prev, overlays: {} });
    if (undoStack.length > 200) undoStack.shift();
    lastPush = now;
    redoStack.length = 0;
  }
  function restore(s: DesignerState): void {
    applying = true;
    pending = null;
    for (const c of [pitch, irr, length, quant, cStrength, fStrength, constVal, sinePeriod, sinePhase, speed, seedCtl]) c.clear();
    store.update({ ...s, overlays: {} });
    applying = false;
    lastPush = 0;
  }
  function undo(): void {
    const s = undoStack.pop();
    if (!s) return;
    redoStack.push(store.get());
    restore(s);
  }
  function redo(): void {
    const s = redoStack.pop();
    if (!s) return;
    undoStack.push(store.get());
    restore(s);
  }
  root.addEventListener('keydown', (e) => {
    if (!(e.ctrlKey || e.metaKey) || e.altKey) return;
    const k = e.key.toLowerCase();
    const target = e.target as HTMLElement;
    // Typing in a text field keeps the field's own undo.
    if (target instanceof HTMLInputElement && target.type === 'text') return;
    if (k === 'z' && !e.shiftKey) undo();
    else if ((k === 'z' && e.shiftKey) || k === 'y') redo();
    else return;
    e.preventDefault();
  });
  // Saving waits 250 ms for a slider drag to settle, but never past the page's end: a reload,
  // a closed tab or a hidden page writes what is waiting at once (flushSavedDesign, below).
  let saveTimer: ReturnType<typeof setTimeout> | null = null;
  let unsaved: DesignerState | null = null;
  function flushSave(): void {
    if (saveTimer) clearTimeout(saveTimer);
    saveTimer = null;
    const s = unsaved;
    unsaved = null;
    if (!s) return;
    try {
      const v: Saved = { document: buildDocument(s), speed_mm_s: s.speed_mm_s };
      localStorage.setItem(SAVED_KEY, JSON.stringify(v));
      root.dataset.saved = 'true';
    } catch (e) {
      showError(`The design could not be saved in this browser: ${message(e)}`);
    }
  }
  function save(s: DesignerState): void {
    unsaved = s;
    if (saveTimer) clearTimeout(saveTimer);
    saveTimer = setTimeout(flushSave, 250);
  }
  flushSavedDesign = flushSave;
  const freshBtn = h('button', { type: 'button', 'data-testid': 'new-design', onclick: () => {
    if (saveTimer) clearTimeout(saveTimer);
    unsaved = null;
    localStorage.removeItem(SAVED_KEY);
    undoStack.push(store.get());
    redoStack.length = 0;
    restore(initialState());
    savedNote.textContent = 'Started a new design (Undo brings the last one back).';
  } }, 'New design');

  /** Shows the store's state in every control (the only way controls change). */
  function render(s: DesignerState, prev: DesignerState): void {
    history(s, prev);
    const t = s.texel;
    pitch.set(shown(t.central_pitch_db));
    irr.set(shown(t.irregularity_db));
    length.set(shown(t.texel_length_mm));
    seedIn.value = String(t.seed);
    param.el.value = t.parameterization;
    quant.set(shown(t.quantization_db));
    oob.el.value = t.out_of_band;
    bandMin.set(shown(t.band_min_cpm));
    bandMax.set(shown(t.band_max_cpm));
    phaseSel.el.value = t.phase;
    fillSel.el.value = t.fill;
    cStrength.set(shown(t.coarse_strength));
    fStrength.set(shown(t.fine_strength));
    constVal.set(shown(t.coarse_value));
    sinePeriod.set(shown(t.sine_period_mm));
    sinePhase.set(shown(t.sine_phase_deg));
    speed.set(s.speed_mm_s);
    coarseSel.el.value = t.coarse;
    splitSel.el.value = s.split ? 'split' : 'single';
    refRow.hidden = !s.split;
    matchBtn.disabled = !s.split;
    // A .texel holds one texture: with two regions the document file is the one that keeps both.
    exportBits.disabled = s.split;
    bitsNote.hidden = !s.split;
    if (typeof s.device === 'string') {
      if (![...deviceSel.el.options].some((o) => o.value === s.device)) deviceSel.el.append(h('option', { value: s.device as string }, s.device as string));
      deviceSel.el.value = s.device;
    }
    refSel.el.value = s.reference;
    showCoarse(t);
    undoBtn.disabled = !undoStack.length;
    redoBtn.disabled = !redoStack.length;
    if (s.overlays !== prev.overlays && lastSpectrum) spec.set(lastSpectrum, s.overlays.target, s.overlays.match);
    if (s.speed_mm_s !== prev.speed_mm_s) showFrequencies();
    if (lasting(s) !== lasting(prev)) save(s);
    if (JSON.stringify(buildDocument(s)) !== JSON.stringify(buildDocument(prev))) void design();
  }
  store.subscribe(render);

  // --- import / export, drag and drop
  const filesErr = h('p', { class: 'field-error', role: 'alert', 'data-testid': 'files-error', hidden: true });
  const fileIn = h('input', {
    type: 'file',
    id: 'import-file',
    'data-testid': 'import-file',
    accept: '.json,.texel,.bin,.npy,.csv,.wav',
    class: 'visually-hidden',
    tabindex: -1,
    'aria-label': 'Import a file (.texel.json, .texel, device .bin, .npy, .csv, .wav)',
  }) as HTMLInputElement;
  fileIn.addEventListener('change', () => {
    if (fileIn.files?.[0]) void importFile(fileIn.files[0]);
    fileIn.value = '';
  });

  // Raw device maps carry no header: say how the bytes will be read and ask first.
  const confirmText = h('p', { 'data-testid': 'import-confirm-text', id: 'import-confirm-text' });
  const confirmDlg = h('dialog', { class: 'confirm', 'data-testid': 'import-confirm', 'aria-labelledby': 'import-confirm-title', 'aria-describedby': 'import-confirm-text' },
    h('h2', { id: 'import-confirm-title' }, 'Import a raw device map?'), confirmText,
    h('div', { class: 'btn-row' },
      h('button', { type: 'button', class: 'primary', 'data-testid': 'import-confirm-yes', value: 'yes' }, 'Import and replace the design'),
      h('button', { type: 'button', 'data-testid': 'import-confirm-no', value: 'no' }, 'Cancel'))) as HTMLDialogElement;
  function confirmRaw(f: File, bytes: number): Promise<boolean> {
    const s = store.get();
    const dev = deviceProfile(s.device);
    if (!dev) return Promise.resolve(true);
    const width = /(^|[^0-9])8$/.test(dev.format) ? 1 : /32|f32/.test(dev.format) ? 4 : 2;
    const n = bytes / width;
    const whole = Number.isInteger(n);
    confirmText.textContent =
      `"${f.name}" has no header: it will be read as a map of device ${dev.name} — ${bytes} bytes` +
      (whole ? ` = ${n} ${dev.format} samples, ${dev.spacing_mm} mm apart (${fmt(n * dev.spacing_mm, 2)} mm)` : ` (not a whole number of ${dev.format} samples)`) +
      `; ${dev.name} holds ${dev.samples} samples over ${fmt(dev.samples * dev.spacing_mm, 2)} mm, played at ${dev.refresh_hz} Hz. ` +
      (whole && n !== dev.samples ? 'It is not a whole device map. ' : '') +
      'The engine encodes it as a Texel texture, replacing the current design (Undo brings it back).';
    return new Promise((resolve) => {
      const yes = confirmDlg.querySelector('[value=yes]') as HTMLButtonElement;
      const no = confirmDlg.querySelector('[value=no]') as HTMLButtonElement;
      const done = (ok: boolean) => {
        yes.onclick = no.onclick = null;
        confirmDlg.onclose = null;
        if (confirmDlg.open) confirmDlg.close();
        resolve(ok);
      };
      yes.onclick = () => done(true);
      no.onclick = () => done(false);
      confirmDlg.onclose = () => done(false);
      confirmDlg.showModal();
      no.focus();
    });
  }

  async function importFile(f: File): Promise<void> {
    filesErr.hidden = true;
    delete status.dataset.imported;
    try {
      const bytes = new Uint8Array(await f.arrayBuffer());
      if (/\.bin$/i.test(f.name) && !(await confirmRaw(f, bytes.length))) {
        status.textContent = `Import of ${f.name} cancelled; the design is unchanged.`;
        return;
      }
      status.textContent = `importing ${f.name}…`;
      const device = store.get().device;
      const dev = typeof device === 'string' ? device : device.name;
      const r = await client.call('import', { name: f.name, data_base64: bytesToBase64(bytes), device: dev }, 120000);
      const doc = r.document as TextureDocument;
      const next = stateFromDocument(doc, store.get());
      status.textContent = `imported ${f.name}`;
      status.dataset.imported = f.name;
      store.update(next);
      // The page edits one texture, or a reference beside one: say so when a file holds more.
      const had = doc.regions?.length ?? 1;
      const kept = buildDocument(next).regions?.length ?? 1;
      if (kept < had)
        showError(`${f.name} has ${had} regions; the designer shows ${kept} of them (the reference and the last Texel region). ` +
          'Exporting from here writes only those.', filesErr);
    } catch (e) {
      status.textContent = '';
      showError(`${f.name} was not imported: ${message(e)}`, filesErr);
    }
  }
  async function exportAs(as: ExportRequest['as']): Promise<void> {
    filesErr.hidden = true;
    try {
      const r = await client.call('export', { document: buildDocument(store.get()), as }, 60000);
      download(r.name, r.mime, base64ToBytes(r.data_base64));
    } catch (e) {
      showError(e, filesErr);
    }
  }
  const exportBits = h('button', { type: 'button', onclick: () => void exportAs('bitstream'), 'data-testid': 'export-bitstream' }, 'Export .texel') as HTMLButtonElement;
  const bitsNote = h('p', { class: 'hint', 'data-testid': 'bitstream-note', hidden: true },
    'A .texel holds one texture: export .texel.json to keep both regions.');
  const dropHint = h('div', { class: 'drop-hint', 'aria-hidden': 'true' }, 'Drop a .texel.json, .texel or device file to import it');
  root.addEventListener('dragover', (e) => {
    e.preventDefault();
    root.classList.add('dragging');
  });
  root.addEventListener('dragleave', (e) => {
    if (e.target === root) root.classList.remove('dragging');
  });
  root.addEventListener('drop', (e) => {
    e.preventDefault();
    root.classList.remove('dragging');
    const f = e.dataTransfer?.files?.[0];
    if (f) void importFile(f);
  });

  const hear = h('input', { type: 'checkbox', id: 'hear-it', 'data-testid': 'hear-it' }) as HTMLInputElement;
  hear.addEventListener('change', async () => {
    try {
      if (hear.checked) await hearIt.enable();
      else await hearIt.disable();
    } catch (e) {
      hear.checked = false;
      showError(e);
    }
  });

  const controls = h(
    'form',
    { class: 'controls', 'aria-label': 'Texture parameters', onsubmit: (e: Event) => e.preventDefault() },
    h('div', { class: 'btn-row history' }, undoBtn, redoBtn, freshBtn, savedNote),
    h('fieldset', {}, h('legend', {}, 'Fine texture'), pitch.row, irr.row, length.row, flatWarn,
      h('div', { class: 'ctl' }, h('label', { for: 'seed' }, 'Seed ', h('span', { class: 'unit' }, '(whole number ≥ 0)')), h('div', { class: 'ctl-row' }, seedIn, newDraw), seedErr),
      param.row, quant.row, fStrength.row),
    h('fieldset', {}, h('legend', {}, 'Band and texel layout'), bandMin.row, bandMax.row, oob.row, phaseSel.row, fillSel.row),
    h('fieldset', {}, h('legend', {}, 'Swipe speed'), speed.row, driveWarn),
    h('fieldset', {}, h('legend', {}, 'Coarse profile'), coarseSel.row, coarseParams, drawBtn, cStrength.row),
    h('fieldset', {}, h('legend', {}, 'Device and regions'), deviceSel.row, splitSel.row, refRow, h('div', { class: 'ctl-row' }, matchBtn), matchInfo, matchErr),
    h('fieldset', {}, h('legend', {}, 'Files'),
      h('div', { class: 'btn-row' },
        h('button', { type: 'button', onclick: () => fileIn.click(), 'data-testid': 'import' }, 'Import…'),
        fileIn,
        h('button', { type: 'button', onclick: () => void exportAs('document'), 'data-testid': 'export-document' }, 'Export .texel.json'),
        exportBits,
        h('button', { type: 'button', onclick: () => void exportAs('device'), 'data-testid': 'export-device' }, 'Export device .bin'),
        h('button', { type: 'button', onclick: () => void exportAs('hjif'), 'data-testid': 'export-hjif', title: 'MPEG-I Haptics interchange (texel export -o x.hjif)' }, 'Export .hjif')),
      bitsNote, filesErr,
      h('p', { class: 'hint' }, 'Or drop a file anywhere on the page. The design is also kept in this browser.'),
      stimulusSaver(() => buildDocument(store.get()))),
  );

  const summary = h('div', { class: 'summary' }, h('div', { class: 'size' }, h('span', { class: 'label' }, 'Encoded size'), bytesEl), h('div', { class: 'meta' }, texelsEl, ' · ', elapsedEl), hexEl);
  const plots = h(
    'div',
    { class: 'plots' },
    summary,
    h('h2', {}, 'Friction map'),
    h('p', { class: 'hint' }, 'Drag to zoom, double-click to reset. Drive 0…1: 1 is the display’s full friction change.'),
    mapPlot.el,
    h('h2', {}, 'Feel it'),
    strip.el,
    h('label', { class: 'inline' }, hear, ' Hear it (browser audio, when no display is attached)'),
    h('div', { class: 'two' }, h('div', {}, h('h2', {}, 'Texel frequencies'), hist.el, hzNote),
      h('div', {}, h('h2', {}, 'Spectrum'), spec.el,
        h('p', { class: 'hint' }, 'Amplitude spectrum of the analysed region: 0 dB is a sine of amplitude 1 (full drive); −20 dB is amplitude 0.1.'))),
  );
  root.replaceChildren(h('div', { class: 'designer' }, controls, plots), status, alertBox, dropHint, confirmDlg);
  showCoarse(store.get().texel);
  render(store.get(), store.get());

  void getHello()
    .then((hi) => {
      const s = store.get();
      deviceSel.el.replaceChildren(...hi.devices.map((d) => h('option', { value: d.name, title: d.description ?? '' }, d.name)));
      deviceSel.el.value = typeof s.device === 'string' ? s.device : s.device.name;
      refSel.el.replaceChildren(...hi.references.map((r) => h('option', { value: r.name, title: r.description ?? '' }, r.name)));
      refSel.el.value = s.reference;
      strip.setLength(deviceLength(s.device));
      root.dataset.ready = 'true';
      void design();
    })
    .catch((e) => showError(e));
}
