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

interface TexelParams {
  central_pitch_db: number;
  irregularity_db: number;
  texel_length_mm: number;
  seed: number;
  parameterization: 'moments' | 'log';
  quantization_db: number;
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
}

const defaults = (): TexelParams => ({
  central_pitch_db: 10,
  irregularity_db: -5,
  texel_length_mm: 0.25,
  seed: 1,
  parameterization: 'moments',
  quantization_db: 0,
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
    central_pitch_db: round(t.central_pitch_db, 2),
    irregularity_db: round(t.irregularity_db, 2),
    texel_length_mm: round(t.texel_length_mm, 3),
    seed: t.seed,
    parameterization: t.parameterization,
    quantization_db: t.quantization_db,
    coarse_strength: t.coarse_strength,
    fine_strength: t.fine_strength,
  };
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
    'quantization_db', 'coarse', 'coarse_strength', 'fine_strength',
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

interface SliderCtl {
  row: HTMLElement;
  input: HTMLInputElement;
  set(v: number): void;
}

function slider(
  id: string,
  label: string,
  min: number,
  max: number,
  step: number,
  value: number,
  unit: string,
  onInput: (v: number) => void,
  extra?: HTMLElement,
): SliderCtl {
  const input = h('input', { type: 'range', id, min, max, step, value, 'data-testid': id }) as HTMLInputElement;
  const num = h('input', { type: 'number', min, max, step, value, 'aria-label': `${label} (${unit})`, class: 'num' }) as HTMLInputElement;
  input.addEventListener('input', () => {
    num.value = input.value;
    onInput(Number(input.value));
  });
  num.addEventListener('change', () => {
    const v = Math.min(max, Math.max(min, Number(num.value)));
    if (!Number.isFinite(v)) return;
    input.value = String(v);
    num.value = String(v);
    onInput(v);
  });
  const row = h('div', { class: 'ctl' }, h('label', { for: id }, label, ' ', h('span', { class: 'unit' }, `(${unit})`)), h('div', { class: 'ctl-row' }, input, num), extra ?? null);
  return {
    row,
    input,
    set(v: number) {
      input.value = String(v);
      num.value = String(v);
    },
  };
}

function select(id: string, label: string, options: [string, string][], value: string, onChange: (v: string) => void): { row: HTMLElement; el: HTMLSelectElement } {
  const el = h('select', { id, 'data-testid': id }) as HTMLSelectElement;
  for (const [v, t] of options) el.append(h('option', { value: v }, t));
  el.value = value;
  el.addEventListener('change', () => onChange(el.value));
  return { row: h('div', { class: 'ctl' }, h('label', { for: id }, label), el), el };
}

// ---------------------------------------------------------------- page

export function mountDesigner(root: HTMLElement): void {
  // The page's one state: controls write it, render() (below) reads it.
  const store = new Store<DesignerState>({
    device: 'tpad',
    split: false,
    reference: '4sin',
    reference_seed: 1,
    reference_version: 3,
    texel: defaults(),
    extra: {},
    overlays: {},
  });
  const setTexel = (p: Partial<TexelParams>) => store.update((st) => ({ texel: { ...st.texel, ...p } }));
  const client = studio();

  const mapPlot = new MapPlot();
  const hist = new HistogramPlot();
  const spec = new SpectrumPlot();
  let lastSpectrum: Spectrum | null = null;
  let lastSelectedKey = '';
  let stripActiveUntil = 0;

  const status = h('div', { class: 'status', role: 'status', 'aria-live': 'polite', 'data-testid': 'designer-status' });
  const bytesEl = h('span', { class: 'bytes', 'data-testid': 'encoded-bytes', id: 'encoded-bytes' }, '–');
  const hexEl = h('code', { class: 'hex', 'data-testid': 'encoded-hex' });
  const pitchCpm = h('span', { class: 'cpm', 'data-testid': 'pitch-cpm' });
  const irrCpm = h('span', { class: 'cpm', 'data-testid': 'irregularity-cpm' });
  const texelsEl = h('span', { 'data-testid': 'texels' });
  const elapsedEl = h('span', { 'data-testid': 'elapsed' });

  // --- design requests and redraw timing
  let gen = 0;
  let drawnGen = 0;
  const t0s: { g: number; t0: number }[] = [];
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

  function showError(e: unknown): void {
    status.textContent = e instanceof Error ? e.message : String(e);
    status.classList.add('error');
  }

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
      if (g >= drawnGen) showError(e);
      return;
    }
    if (!reply || g < drawnGen) return; // superseded or stale
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
    status.textContent = '';
    status.classList.remove('error');
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
    pitchCpm.textContent = typeof r.central_pitch_cpm === 'number' ? `= ${fmt(r.central_pitch_cpm, 3)} cycles/mm` : '';
    irrCpm.textContent = typeof r.irregularity_cpm === 'number' ? `= ${fmt(r.irregularity_cpm, 3)} cycles/mm` : '';
    texelsEl.textContent = r.texels !== undefined ? `${r.texels} texels` : '';
    elapsedEl.textContent = r.elapsed_ms !== undefined ? `engine ${fmt(r.elapsed_ms, 1)} ms` : '';
    strip.setLength(r.grid.count * r.grid.spacing_mm);
  }

  // --- controls: each writes the store; render() shows the store in them
  const t = store.get().texel;
  const pitch = slider('central-pitch', 'Central Pitch', -10, 19.5, 0.1, t.central_pitch_db, 'dB re 1 cycle/mm', (v) => setTexel({ central_pitch_db: v }), pitchCpm);
  const irr = slider('irregularity', 'Irregularity', -30, 20, 0.1, t.irregularity_db, 'dB', (v) => setTexel({ irregularity_db: v }), irrCpm);
  const length = slider('texel-length', 'Texel length', 0.05, 10, 0.01, t.texel_length_mm, 'mm', (v) => setTexel({ texel_length_mm: v }));
  const seedIn = h('input', { type: 'number', id: 'seed', min: 0, step: 1, value: t.seed, 'data-testid': 'seed', class: 'num' }) as HTMLInputElement;
  seedIn.addEventListener('change', () => setTexel({ seed: Math.max(0, Math.floor(Number(seedIn.value) || 0)) }));
  const newDraw = h('button', { type: 'button', 'data-testid': 'new-draw', onclick: () => setTexel({ seed: Math.floor(Math.random() * 2 ** 31) }) }, 'New draw');
  const param = select('parameterization', 'Parameterization', [['moments', 'moments (mean, SD)'], ['log', 'log (lognormal μ, σ)']], t.parameterization, (v) => {
    const irregularity = v === 'log' && store.get().texel.irregularity_db < 0 ? { irregularity_db: 0 } : {};
    setTexel({ parameterization: v as 'moments' | 'log', ...irregularity });
  });
  const quant = slider('quantization', 'Quantization', 0, 20, 0.5, t.quantization_db, 'dB, 0 = off', (v) => setTexel({ quantization_db: v }));
  const cStrength = slider('coarse-strength', 'Coarse strength C', 0, 1, 0.01, t.coarse_strength, '0…1', (v) => setTexel({ coarse_strength: v }));
  const fStrength = slider('fine-strength', 'Fine strength F', 0, 1, 0.01, t.fine_strength, '0…1', (v) => setTexel({ fine_strength: v }));

  const constVal = slider('coarse-value', 'Constant value', 0, 1, 0.01, t.coarse_value, '0…1', (v) => setTexel({ coarse_value: v }));
  const sinePeriod = slider('sine-period', 'Sine period', 0.5, 50, 0.1, t.sine_period_mm, 'mm', (v) => setTexel({ sine_period_mm: v }));
  const sinePhase = slider('sine-phase', 'Sine phase', 0, 360, 1, t.sine_phase_deg, 'degrees', (v) => setTexel({ sine_phase_deg: v }));
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
  const matchInfo = h('span', { class: 'hint', 'data-testid': 'match-info' });
  matchBtn.addEventListener('click', async () => {
    matchBtn.disabled = true;
    matchInfo.textContent = 'encoding…';
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
      // 1 JND: the smallest difference in felt pitch or noisiness a person notices (docs/encoder.md).
      matchInfo.textContent =
        `matched in ${r.encoded.bytes} bytes; felt distance ${fmt(r.distance_jnd, 2)} JND (model ${r.encoded.result.model.version}; ` +
        `below 1 JND the two feel alike)` + (flags.length ? ` — ${flags.join('; ')}` : '');
      store.update((st) => {
        const ns: DesignerState = { ...st, overlays: { target: r.target_spectrum, match: r.match_spectrum } };
        if (reg?.texture?.kind === 'texel') applyTexel(ns, reg.texture);
        return ns;
      });
    } catch (e) {
      matchInfo.textContent = '';
      showError(e);
    } finally {
      matchBtn.disabled = !store.get().split;
    }
  });

  function shown(v: number): number {
    return Math.round(v * 1e4) / 1e4;
  }

  /** Shows the store's state in every control (the only way controls change). */
  function render(s: DesignerState, prev: DesignerState): void {
    const t = s.texel;
    pitch.set(shown(t.central_pitch_db));
    irr.set(shown(t.irregularity_db));
    length.set(shown(t.texel_length_mm));
    seedIn.value = String(t.seed);
    param.el.value = t.parameterization;
    quant.set(shown(t.quantization_db));
    cStrength.set(shown(t.coarse_strength));
    fStrength.set(shown(t.fine_strength));
    constVal.set(shown(t.coarse_value));
    sinePeriod.set(shown(t.sine_period_mm));
    sinePhase.set(shown(t.sine_phase_deg));
    coarseSel.el.value = t.coarse;
    splitSel.el.value = s.split ? 'split' : 'single';
    refRow.hidden = !s.split;
    matchBtn.disabled = !s.split;
    if (typeof s.device === 'string') {
      if (![...deviceSel.el.options].some((o) => o.value === s.device)) deviceSel.el.append(h('option', { value: s.device as string }, s.device as string));
      deviceSel.el.value = s.device;
    }
    refSel.el.value = s.reference;
    showCoarse(t);
    if (s.overlays !== prev.overlays && lastSpectrum) spec.set(lastSpectrum, s.overlays.target, s.overlays.match);
    void design();
  }
  store.subscribe(render);

  // --- import / export, drag and drop
  const fileIn = h('input', { type: 'file', id: 'import-file', 'aria-label': 'Import a file', 'data-testid': 'import-file', accept: '.json,.texel,.bin,.npy,.csv,.wav', class: 'visually-hidden' }) as HTMLInputElement;
  fileIn.addEventListener('change', () => {
    if (fileIn.files?.[0]) void importFile(fileIn.files[0]);
    fileIn.value = '';
  });
  async function importFile(f: File): Promise<void> {
    status.textContent = `importing ${f.name}…`;
    try {
      const bytes = new Uint8Array(await f.arrayBuffer());
      const device = store.get().device;
      const dev = typeof device === 'string' ? device : device.name;
      const r = await client.call('import', { name: f.name, data_base64: bytesToBase64(bytes), device: dev }, 120000);
      status.textContent = `imported ${f.name}`;
      status.dataset.imported = f.name;
      store.update(stateFromDocument(r.document as TextureDocument, store.get()));
    } catch (e) {
      showError(e);
    }
  }
  async function exportAs(as: ExportRequest['as']): Promise<void> {
    try {
      const r = await client.call('export', { document: buildDocument(store.get()), as }, 60000);
      download(r.name, r.mime, base64ToBytes(r.data_base64));
    } catch (e) {
      showError(e);
    }
  }
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
    h('fieldset', {}, h('legend', {}, 'Fine texture'), pitch.row, irr.row, length.row,
      h('div', { class: 'ctl' }, h('label', { for: 'seed' }, 'Seed'), h('div', { class: 'ctl-row' }, seedIn, newDraw)),
      param.row, quant.row, fStrength.row),
    h('fieldset', {}, h('legend', {}, 'Coarse profile'), coarseSel.row, coarseParams, drawBtn, cStrength.row),
    h('fieldset', {}, h('legend', {}, 'Device and regions'), deviceSel.row, splitSel.row, refRow, h('div', { class: 'ctl-row' }, matchBtn, matchInfo)),
    h('fieldset', {}, h('legend', {}, 'Files'),
      h('div', { class: 'btn-row' },
        h('button', { type: 'button', onclick: () => fileIn.click(), 'data-testid': 'import' }, 'Import…'),
        fileIn,
        h('button', { type: 'button', onclick: () => void exportAs('document'), 'data-testid': 'export-document' }, 'Export .texel.json'),
        h('button', { type: 'button', onclick: () => void exportAs('bitstream'), 'data-testid': 'export-bitstream' }, 'Export .texel'),
        h('button', { type: 'button', onclick: () => void exportAs('device'), 'data-testid': 'export-device' }, 'Export device .bin')),
      h('p', { class: 'hint' }, 'Or drop a file anywhere on the page.'),
      stimulusSaver(() => buildDocument(store.get()))),
  );

  const summary = h('div', { class: 'summary' }, h('div', { class: 'size' }, h('span', { class: 'label' }, 'Encoded size'), bytesEl), h('div', { class: 'meta' }, texelsEl, ' · ', elapsedEl), hexEl);
  const plots = h(
    'div',
    { class: 'plots' },
    summary,
    h('h2', {}, 'Friction map'),
    h('p', { class: 'hint' }, 'Drag to zoom, double-click to reset.'),
    mapPlot.el,
    h('h2', {}, 'Feel it'),
    strip.el,
    h('label', { class: 'inline' }, hear, ' Hear it (browser audio, when no display is attached)'),
    h('div', { class: 'two' }, h('div', {}, h('h2', {}, 'Texel frequencies'), hist.el), h('div', {}, h('h2', {}, 'Spectrum'), spec.el)),
  );
  root.replaceChildren(h('div', { class: 'designer' }, controls, plots), status, dropHint);
  showCoarse(store.get().texel);

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
    .catch(showError);
}
