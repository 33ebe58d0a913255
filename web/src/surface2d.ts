// The 2-D page (#/surface, docs/studio.md "The 2-D page"): a version-4 or -5 2-D
// document — the designer's texture laid out on a 2-D display in a chosen
// design, or an opened .texel.json — shown as its friction map, with zoom
// (wheel, pinch, buttons) and pan; a 2-D feel pad whose finger samples reach
// the engine's 2-D player (feel2d.*) while the drawn path stays on the map;
// 2-D coarse profiles placed by dragging or imported from a PNG; and a scan
// along a chosen direction whose spectrum is plotted beside the 1-D texture's.
// Every number comes from the engine's replies (surface2d.view/scan).

import uPlot from 'uplot';
import 'uplot/dist/uPlot.min.css';
import './surface2d.css';
import { studio } from './ws';
import { h, fmt, base64ToBytes, bytesToBase64, decodeF32, download } from './util';
import { Hear2D } from './audio2d';
import { interpLog } from './plots';
import { greyOf, greyPng, toGreyPng } from './png2d';
import type { DeviceProfile, Feel2DStateReply, HelloReply, Surface2DDocument, Surface2DViewReply } from './generated/messages';
import type { TexelTexture } from './document';

type Json = null | boolean | number | string | Json[] | { [k: string]: Json };
type Coarse2D = { kind: string; [k: string]: Json };
type Field2D = 'tile' | 'spectral' | 'cells' | 'oriented';
type Tool = 'feel' | 'pan' | 'shape' | 'paint';
type Shape = 'disc' | 'edge' | 'grid' | 'bump' | 'ramp';

interface Region2D {
  name: string;
  x_mm?: number;
  y_mm?: number;
  width_mm?: number;
  height_mm?: number;
  field?: Field2D;
  orientation_deg?: number;
  texture: TexelTexture;
  coarse2d?: Coarse2D;
  [k: string]: unknown;
}

interface Saved {
  document: Surface2DDocument;
  images: Record<string, string>;
}

const SAVED_KEY = 'texel.surface2d.v1';
const DESIGNER_KEY = 'texel.designer.v1';

/** Test hooks (test build only; window.__texel2d). */
const hooks = {
  viewsDrawn: 0,
  lastView: null as null | { columns: number; rows: number; stride: number; view_pitch_mm: number; mm_per_px: number },
  movesSent: 0,
  acks: 0,
  playerSamples: 0,
  peakMax: 0,
  touching: false,
  scansDrawn: 0,
  selected: null as null | string,
  hearRaster: null as null | { columns: number; rows: number; pitch: number; whole: boolean },
  device: null as null | { holds: boolean; backend: string; device: string },
};
if (__TEXEL_TEST_HOOKS__) (window as unknown as { __texel2d: typeof hooks }).__texel2d = hooks;

function bitmapOf(d: DeviceProfile | undefined): { width_px: number; height_px: number; pixel_pitch_mm: number } | null {
  const b = d?.bitmap as { width_px?: number; height_px?: number; pixel_pitch_mm?: number } | undefined;
  return b && b.width_px && b.height_px && b.pixel_pitch_mm ? { width_px: b.width_px, height_px: b.height_px, pixel_pitch_mm: b.pixel_pitch_mm } : null;
}

/** The designer's saved Texel texture (its last Texel region), without its 1-D coarse profile. */
function designerTexture(): TexelTexture {
  const fallback: TexelTexture = { kind: 'texel', central_pitch_db: 0, irregularity_db: -5, texel_length_mm: 1, seed: 1 };
  try {
    const saved = JSON.parse(localStorage.getItem(DESIGNER_KEY) ?? 'null') as { document?: { texture?: TexelTexture; regions?: { texture: TexelTexture }[] } } | null;
    const doc = saved?.document;
    const textures = [doc?.texture, ...(doc?.regions ?? []).map((r) => r.texture)].filter((t): t is TexelTexture => t?.kind === 'texel');
    const t = textures.length ? { ...textures[textures.length - 1] } : fallback;
    delete t.coarse;
    return t;
  } catch {
    return fallback;
  }
}

/** A new 2-D document: version 5 with the tile field (fast, isotropic); opened documents keep their version. */
function newDocument(device: string, texture: TexelTexture): Surface2DDocument {
  const region: Region2D = {
    name: 'surface',
    field: 'tile',
    texture: { ...texture, coarse_strength: texture.coarse_strength ?? 0.8, fine_strength: texture.fine_strength ?? 0.6 },
    coarse2d: { kind: 'constant', value: 1 },
  };
  return { format: 'texel-document', version: 5, device, surface2d: { regions: [region as unknown as { [k: string]: unknown }] } };
}

/** A 2-D document: version 4, or 5 (whose regions default to the tile field). */
function is2d(d: Surface2DDocument | null | undefined): boolean {
  return (d?.version === 4 || d?.version === 5) && Array.isArray(d.surface2d?.regions);
}

function loadSaved(): Saved | null {
  try {
    const s = JSON.parse(localStorage.getItem(SAVED_KEY) ?? 'null') as Saved | null;
    return is2d(s?.document) ? s : null;
  } catch {
    return null;
  }
}

/** A plain file name the studio accepts for an image (letters, digits, . _ -; .png). */
function imageName(name: string): string {
  const base = name.replace(/\.png$/i, '').replace(/[^A-Za-z0-9._-]/g, '_').replace(/^\.+/, '').slice(0, 56) || 'coarse';
  return `${base}.png`;
}

function label(text: string, control: HTMLElement, unit = ''): HTMLElement {
  return h('div', { class: 'ctl' }, h('label', { for: control.id }, text, unit ? h('span', { class: 'unit' }, ` (${unit})`) : null), control);
}

export function mountSurface2d(root: HTMLElement): void {
  const client = studio();
  const saved = loadSaved();
  let doc: Surface2DDocument = saved?.document ?? newDocument('tablet-2d', designerTexture());
  let images: Record<string, string> = saved?.images ?? {};
  let hello: HelloReply | null = null;
  let surface: Surface2DViewReply['surface'] | null = null;
  const region = (): Region2D => doc.surface2d.regions[0] as unknown as Region2D;

  // ---------------------------------------------------------------- controls
  const status = h('p', { class: 'status', role: 'status', 'data-testid': 'surface2d-status' });
  const setError = (m: string) => {
    status.textContent = m;
    status.classList.toggle('error', !!m);
  };
  const deviceSel = h('select', { id: 's2d-device' });
  const fieldSel = h(
    'select',
    { id: 's2d-field' },
    h('option', { value: 'tile' }, 'isotropic, tiled (fast; version 5)'),
    h('option', { value: 'spectral' }, 'isotropic (spectral field)'),
    h('option', { value: 'cells' }, 'texel cells'),
    h('option', { value: 'oriented' }, 'oriented grating'),
  );
  const orient = h('input', { id: 's2d-orientation', type: 'number', class: 'num', min: -360, max: 360, step: 1, value: 0 });
  const fromDesigner = h('button', { type: 'button', 'data-testid': 's2d-from-designer' }, "Use the designer's texture");
  const openDoc = h('input', { id: 's2d-open', type: 'file', accept: '.json,application/json' });
  const saveDoc = h('button', { type: 'button' }, 'Download .texel.json');
  const docText = h('textarea', { id: 's2d-json', readonly: true, rows: 10, 'data-testid': 'document2d-json', spellcheck: 'false' });

  const toolGroup = h('div', { class: 'btn-row', role: 'radiogroup', 'aria-label': 'What the pointer does on the map' });
  const tools: [Tool, string][] = [
    ['feel', 'Feel (pad)'],
    ['pan', 'Pan'],
    ['shape', 'Place a shape'],
    ['paint', 'Paint'],
  ];
  let tool: Tool = 'feel';
  const toolInputs = tools.map(([t, text]) => {
    const input = h('input', { type: 'radio', name: 's2d-tool', id: `s2d-tool-${t}`, value: t, checked: t === tool }) as HTMLInputElement;
    input.addEventListener('change', () => {
      if (input.checked) tool = t;
      view.el.dataset.tool = tool;
    });
    toolGroup.append(h('label', { class: 'inline', for: input.id }, input, text));
    return input;
  });
  void toolInputs;
  const shapeSel = h(
    'select',
    { id: 's2d-shape' },
    ...(['disc', 'bump', 'edge', 'ramp', 'grid'] as Shape[]).map((s) => h('option', { value: s }, s)),
  );
  const coarseNone = h('button', { type: 'button' }, 'No coarse profile');
  const brush = h('input', { id: 's2d-brush', type: 'number', class: 'num', min: 0.2, max: 100, step: 0.5, value: 3 }) as HTMLInputElement;
  const importPng = h('input', { id: 's2d-png', type: 'file', accept: '.png,image/png', 'data-testid': 's2d-png' });
  const invert = h('input', { id: 's2d-invert', type: 'checkbox' }) as HTMLInputElement;
  const coarseText = h('p', { class: 'hint', 'data-testid': 's2d-coarse' });

  const modeSel = h('select', { id: 's2d-mode' }, h('option', { value: 'path' }, 'path-indexed'), h('option', { value: 'bitmap' }, 'bitmap'));
  const hear = h('input', { id: 's2d-hear', type: 'checkbox' }) as HTMLInputElement;
  const clearPath = h('button', { type: 'button', 'data-testid': 's2d-clear-path' }, 'Clear the path');
  const playerText = h('span', { 'data-testid': 's2d-player', 'aria-live': 'off' }, '–');
  const deviceText = h('span', { 'data-testid': 's2d-drives', 'aria-live': 'polite' }, '–');

  const angle = h('input', { id: 's2d-angle', type: 'range', min: 0, max: 179, step: 1, value: 0 }) as HTMLInputElement;
  const angleNum = h('input', { id: 's2d-angle-num', type: 'number', class: 'num', min: 0, max: 179, step: 1, value: 0, 'aria-label': 'Scan direction (degrees), typed' }) as HTMLInputElement;
  const scanText = h('p', { class: 'plot-caption', 'data-testid': 's2d-scan-caption' });

  // ---------------------------------------------------------------- map view
  const view = new MapView();
  view.el.dataset.tool = tool;
  const zoomIn = h('button', { type: 'button', 'aria-label': 'Zoom in', 'data-testid': 's2d-zoom-in' }, '+');
  const zoomOut = h('button', { type: 'button', 'aria-label': 'Zoom out', 'data-testid': 's2d-zoom-out' }, '−');
  const zoomFit = h('button', { type: 'button', 'data-testid': 's2d-zoom-fit' }, 'Fit');
  const scaleText = h('span', { class: 'hint', 'data-testid': 's2d-scale' });

  // ---------------------------------------------------------------- spectrum
  const specHost = h('div', { class: 'plot', 'data-testid': 's2d-spectrum', role: 'img', 'aria-label': 'Spectrum of the scan along the chosen direction beside the 1-D texture\'s: dB re amplitude 1 over spatial frequency (cycles/mm, log)' });
  const spec = new uPlot(
    {
      width: 500,
      height: 220,
      legend: { show: true },
      scales: { x: { time: false, distr: 3 } },
      axes: [{ label: 'spatial frequency (cycles/mm, log)' }, { label: 'dB re amplitude 1' }],
      series: [
        { label: 'cycles/mm' },
        { label: '1-D texture (target)', stroke: '#c44', width: 1.5, dash: [6, 3], points: { show: false } },
        { label: 'scan of the map', stroke: '#1b3f8f', width: 1.25, points: { show: false } },
      ],
    },
    [[1], [null], [null]],
    specHost,
  );
  new ResizeObserver(() => {
    const w = Math.max(240, Math.floor(specHost.clientWidth));
    if (Math.abs(w - spec.width) > 2) spec.setSize({ width: w, height: 220 });
  }).observe(specHost);

  root.append(
    h(
      'div',
      { class: 'designer surface2d' },
      h(
        'div',
        { class: 'controls' },
        h(
          'fieldset',
          {},
          h('legend', {}, '2-D document'),
          label('Display (devices with a bitmap)', deviceSel),
          label('Design of the fine texture', fieldSel),
          label('Grating direction (oriented)', orient, '°'),
          h('div', { class: 'btn-row' }, fromDesigner, saveDoc),
          label('Open a 2-D .texel.json (version 4 or 5)', openDoc),
          label('Document', docText),
        ),
        h(
          'fieldset',
          {},
          h('legend', {}, 'Coarse profile'),
          label('Shape placed by dragging on the map ("Place a shape")', shapeSel),
          label('Brush radius ("Paint": strokes paint c = 1 into an image over the region)', brush, 'mm'),
          label('Import an image (PNG; turned grey, stretched over the region)', importPng),
          h('label', { class: 'inline', for: invert.id }, invert, ' Invert the image'),
          h('div', { class: 'btn-row' }, coarseNone),
          coarseText,
        ),
        h(
          'fieldset',
          {},
          h('legend', {}, 'Feel pad'),
          label("2-D player's mode", modeSel),
          h('label', { class: 'inline', for: hear.id }, hear, ' Hear it (browser audio)'),
          h('div', { class: 'btn-row' }, clearPath),
          h('p', { class: 'hint' }, 'Player: ', playerText),
        ),
        status,
      ),
      h(
        'div',
        { class: 'plots' },
        h('div', { class: 'btn-row map2d-bar' }, toolGroup, h('span', { class: 'zoom' }, zoomOut, zoomIn, zoomFit), scaleText),
        h('p', { class: 'hint' }, 'The pad plays on: ', deviceText),
        view.el,
        h('h2', {}, 'Scan along a direction'),
        h('div', { class: 'ctl-row' }, h('label', { for: angle.id }, 'Direction (°, 0 = +x, towards +y)'), angle, angleNum),
        specHost,
        scanText,
      ),
    ),
  );

  // ------------------------------------------------------------------ state
  const hearIt = new Hear2D();
  let pathS = 0; // travelled path length while touching (mm), as the path-indexed player keeps it
  let lastFinger: [number, number] | null = null;

  function save(): void {
    try {
      localStorage.setItem(SAVED_KEY, JSON.stringify({ document: doc, images } satisfies Saved));
    } catch {
      /* a large image may not fit: the page keeps it until reloaded */
    }
  }

  function showControls(): void {
    const r = region();
    const name = typeof doc.device === 'string' ? doc.device : String((doc.device as { name?: string }).name ?? 'inline');
    // An opened document's inline profile is offered as itself.
    deviceSel.querySelector('option[data-inline]')?.remove();
    if (![...deviceSel.options].some((o) => o.value === name))
      deviceSel.append(h('option', { value: name, 'data-inline': 'true', disabled: true }, `${name} (the document's own profile)`));
    deviceSel.value = name;
    fieldSel.value = r.field ?? (doc.version === 5 ? 'tile' : 'spectral');
    orient.value = String(r.orientation_deg ?? 0);
    (orient as HTMLInputElement).disabled = fieldSel.value !== 'oriented';
    const c = r.coarse2d ?? { kind: 'constant' };
    invert.checked = c.kind === 'image' && c.invert === true;
    coarseText.textContent =
      c.kind === 'constant' ? 'No coarse feature (constant).' : `${c.kind}: ${Object.entries(c).filter(([k]) => k !== 'kind').map(([k, v]) => `${k} ${typeof v === 'number' ? fmt(v, 2) : v}`).join(', ')}`;
    docText.value = JSON.stringify(doc, null, 1);
  }

  /** The document changed: save it, show it, re-render the view, the scan and the player's map. */
  function changed(): void {
    save();
    showControls();
    view.request();
    requestScan();
    selectFeel();
  }

  function setCoarse(c: Coarse2D): void {
    const r = region();
    r.coarse2d = c;
    // A coarse profile with C = 0 would not show: give it full strength, as the designer's drawing does.
    if (c.kind !== 'constant' && !(Number(r.texture.coarse_strength) > 0)) r.texture.coarse_strength = 1;
    changed();
  }

  const body = () => ({ document: doc, ...(Object.keys(images).length ? { images } : {}) });

  // ------------------------------------------------------------- map window
  view.fetch = async (win) => {
    const r = await client.request('surface2d.view', { ...body(), ...win }, { lane: 'surface2d.view', timeoutMs: 60000 });
    return r;
  };
  view.onView = (r) => {
    surface = r.surface;
    setError('');
    if (__TEXEL_TEST_HOOKS__) {
      hooks.viewsDrawn++;
      hooks.lastView = { columns: r.columns, rows: r.rows, stride: r.stride, view_pitch_mm: r.view_pitch_mm, mm_per_px: view.scale };
    }
  };
  view.onError = (m) => setError(m);
  view.onScale = () => {
    surface = view.surfaceInfo();
    if (!surface) return;
    const pxPerDevice = surface.pixel_pitch_mm / view.scale;
    scaleText.textContent = `pixel pitch ${fmt(surface.pixel_pitch_mm, 4)} mm · 1 screen px = ${fmt(view.scale, 4)} mm (${pxPerDevice >= 1 ? `${fmt(pxPerDevice, 1)} px per bitmap pixel` : `1 in ${fmt(1 / pxPerDevice, 1)} bitmap pixels`}) · surface ${fmt(surface.width_mm, 1)} × ${fmt(surface.height_mm, 1)} mm`;
    scaleText.dataset.mmPerPx = String(view.scale);
  };
  zoomIn.addEventListener('click', () => view.zoomBy(1 / 1.5));
  zoomOut.addEventListener('click', () => view.zoomBy(1.5));
  zoomFit.addEventListener('click', () => view.fit());

  // ------------------------------------------------------------ the feel pad
  function sendFinger(x: number, y: number, touch: boolean): void {
    if (touch && lastFinger) pathS += Math.hypot(x - lastFinger[0], y - lastFinger[1]);
    lastFinger = touch ? [x, y] : null;
    if (client.send('feel2d.move', { seq: ++seq, x_mm: x, y_mm: y, touch }) && __TEXEL_TEST_HOOKS__) hooks.movesSent++;
    hearIt.finger(x, y, pathS, touch);
  }
  let seq = 0;
  client.on('feel2d.ack', () => {
    if (__TEXEL_TEST_HOOKS__) hooks.acks++;
  });
  view.onFinger = (x, y, touch) => {
    if (tool === 'feel') sendFinger(x, y, touch);
  };
  view.isFeel = () => tool === 'feel';
  view.isPan = () => tool === 'pan';
  view.onShape = (a, b, done) => {
    if (tool !== 'shape') return false;
    const r = region();
    const ox = r.x_mm ?? 0;
    const oy = r.y_mm ?? 0;
    const dx = b[0] - a[0];
    const dy = b[1] - a[1];
    const len = Math.hypot(dx, dy);
    const deg = (Math.atan2(dy, dx) * 180) / Math.PI;
    const x = a[0] - ox;
    const y = a[1] - oy;
    const kind = shapeSel.value as Shape;
    view.preview = { kind, a, b };
    if (!done) return true;
    view.preview = null;
    if (len < 0.2) return true;
    const c: Record<Shape, Coarse2D> = {
      disc: { kind: 'disc', x_mm: x, y_mm: y, radius_mm: len, edge_mm: Math.max(0.1, 0.1 * len), inside: 1, outside: 0.2 },
      bump: { kind: 'bump', x_mm: x, y_mm: y, sigma_mm: len / 2, peak: 1, base: 0.2 },
      edge: { kind: 'edge', x_mm: x, y_mm: y, angle_deg: deg, width_mm: len, low: 0.2, high: 1 },
      ramp: { kind: 'ramp', angle_deg: deg, start_mm: x * Math.cos((deg * Math.PI) / 180) + y * Math.sin((deg * Math.PI) / 180), length_mm: len, from: 0.2, to: 1 },
      grid: { kind: 'grid', period_mm: Math.max(1, len), line_width_mm: Math.max(0.2, len / 8), angle_deg: deg, line: 1, background: 0.2 },
    };
    setCoarse(c[kind]);
    return true;
  };
  clearPath.addEventListener('click', () => view.clearPath());

  // Freehand: strokes paint c = 1 into a grey image over the region (background 0.2), kept as painted.png.
  let paint: { canvas: HTMLCanvasElement; pxPerMm: number } | null = null;
  view.isPaint = () => tool === 'paint';
  view.onPaint = async (pts, done) => {
    const r = region();
    const w = r.width_mm ?? (surface ? surface.width_mm - (r.x_mm ?? 0) : 100);
    const ht = r.height_mm ?? (surface ? surface.height_mm - (r.y_mm ?? 0) : 100);
    const pxPerMm = 512 / Math.max(w, ht);
    const c = region().coarse2d;
    if (!paint || paint.pxPerMm !== pxPerMm || c?.kind !== 'image' || c.path !== 'painted.png') {
      const canvas = document.createElement('canvas');
      canvas.width = Math.max(1, Math.round(w * pxPerMm));
      canvas.height = Math.max(1, Math.round(ht * pxPerMm));
      const ctx = canvas.getContext('2d', { willReadFrequently: true })!;
      ctx.fillStyle = 'rgb(51,51,51)';
      ctx.fillRect(0, 0, canvas.width, canvas.height);
      paint = { canvas, pxPerMm };
    }
    view.paintRadius = Number(brush.value) || 3;
    if (!done) return;
    const ctx = paint.canvas.getContext('2d', { willReadFrequently: true })!;
    ctx.strokeStyle = ctx.fillStyle = '#fff';
    ctx.lineCap = ctx.lineJoin = 'round';
    ctx.lineWidth = 2 * view.paintRadius * pxPerMm;
    ctx.beginPath();
    pts.forEach(([x, y], i) => {
      const px = (x - (r.x_mm ?? 0)) * pxPerMm;
      const py = (y - (r.y_mm ?? 0)) * pxPerMm;
      if (i) ctx.lineTo(px, py);
      else ctx.moveTo(px, py);
    });
    if (pts.length === 1) ctx.lineTo((pts[0][0] - (r.x_mm ?? 0)) * pxPerMm + 0.01, (pts[0][1] - (r.y_mm ?? 0)) * pxPerMm);
    ctx.stroke();
    const png = await greyPng(greyOf(ctx, paint.canvas.width, paint.canvas.height), paint.canvas.width, paint.canvas.height);
    images = { 'painted.png': bytesToBase64(png) };
    setCoarse({ kind: 'image', path: 'painted.png', x_mm: 0, y_mm: 0, width_mm: 0, height_mm: 0, invert: false });
  };

  async function selectFeel(): Promise<void> {
    const mode = modeSel.value as 'path' | 'bitmap';
    try {
      const r = await client.request('feel2d.select', { ...body(), mode }, { lane: 'feel2d.select', timeoutMs: 120000 });
      if (!r) return;
      if (__TEXEL_TEST_HOOKS__) hooks.selected = r.mode;
      view.el.dataset.playerMode = r.mode;
      await hearSource();
    } catch (e) {
      setError((e as Error).message);
    }
  }
  /**
   * What Hear it plays: path mode, the texture's own 1-D map on the display's 1-D grid; bitmap mode, the bitmap at the
   * device's resolution and depth (feel2d.raster: the whole bitmap up to 4 MiB of pixels, else the 1024 x 1024 device
   * pixels about the view's centre), so what is heard does not depend on the zoom.
   */
  let hearWhole = false;
  async function hearSource(): Promise<void> {
    if (!hearIt.enabled) return;
    if (modeSel.value === 'path') {
      // A 1-D document: an inline profile without its bitmap (versions 1-3 have none).
      const device = typeof doc.device === 'string' ? doc.device : (({ bitmap: _b, ...d }) => d as DeviceProfile)(doc.device as DeviceProfile);
      const d = await client.request(
        'design',
        { document: { format: 'texel-document', version: 1, device, texture: region().texture } },
        { lane: 'design2d' },
      );
      if (d) hearIt.setSource({ line: decodeF32(d.map_f32), spacing: d.grid.spacing_mm });
    } else {
      const v = view.lastRaster();
      const p = surface?.pixel_pitch_mm ?? 0;
      const win =
        v && p > 0
          ? { x_px: Math.max(0, Math.round(v.x0 / p)), y_px: Math.max(0, Math.round(v.y0 / p)), width_px: Math.max(1, Math.round((v.columns * v.pitch) / p)), height_px: Math.max(1, Math.round((v.rows * v.pitch) / p)) }
          : {};
      const r = await client.request('feel2d.raster', { ...body(), ...win }, { lane: 'feel2d.raster', timeoutMs: 120000 });
      if (!r) return;
      const bytes = base64ToBytes(r.amplitude);
      const n = r.width_px * r.height_px;
      const raster = new Float32Array(n);
      if (r.depth_bits === 8) for (let i = 0; i < n; i++) raster[i] = bytes[i] / 255;
      else for (let i = 0; i < n; i++) raster[i] = (bytes[2 * i] | (bytes[2 * i + 1] << 8)) / 65535;
      hearWhole = r.whole;
      const pitch = r.pixel_pitch_mm;
      hearIt.setSource({ raster, columns: r.width_px, rows: r.height_px, x0: r.x_px * pitch, y0: r.y_px * pitch, pitch });
      if (__TEXEL_TEST_HOOKS__) hooks.hearRaster = { columns: r.width_px, rows: r.height_px, pitch, whole: r.whole };
    }
  }
  let hearTimer: ReturnType<typeof setTimeout> | null = null;
  view.onRaster = () => {
    // A bitmap too large to send whole: the device pixels about the view follow the view (debounced).
    if (modeSel.value !== 'bitmap' || hearWhole || !hearIt.enabled) return;
    if (hearTimer) clearTimeout(hearTimer);
    hearTimer = setTimeout(() => void hearSource().catch((e) => setError((e as Error).message)), 300);
  };
  modeSel.addEventListener('change', () => void selectFeel());
  hear.addEventListener('change', async () => {
    try {
      if (hear.checked) {
        await hearIt.enable();
        await hearSource();
      } else await hearIt.disable();
    } catch (e) {
      hear.checked = false;
      setError(`Hear it: ${(e as Error).message}`);
    }
  });

  const poll = setInterval(async () => {
    if (!document.body.contains(root)) {
      clearInterval(poll);
      return;
    }
    if (client.state !== 'open') return;
    try {
      const st = (await client.request('feel2d.state', {}, { lane: 'feel2d.state', timeoutMs: 2000 })) as Feel2DStateReply | null;
      if (!st) return;
      playerText.textContent = st.mode
        ? `${st.mode === 'path' ? 'path-indexed' : 'bitmap'}, ${st.samples} finger samples, x ${fmt(st.x_mm, 1)} mm${st.touching ? ' (touching)' : ''}, peak drive ${fmt(st.peak, 3)}`
        : 'no map selected yet';
      playerText.dataset.touching = String(st.touching);
      if (st.finger === 'display') {
        playerText.textContent += ` · the finger is the display's own sensor (${st.reports ?? 0} reports; the pad only shows it)`;
        if (st.trail?.length) view.displayFinger(st.trail as [number, number, boolean][]);
      }
      deviceText.textContent = st.holds_device
        ? `${st.backend}${st.underruns ? `, ${st.underruns} underruns` : ''}`
        : `${st.device}, not now: the 1-D Feel-it strip or a participant's stimulus has it; touch the pad to take it`;
      if (st.error) deviceText.textContent += ` — ${st.error}`;
      deviceText.dataset.holds = String(st.holds_device);
      if (__TEXEL_TEST_HOOKS__) hooks.device = { holds: st.holds_device, backend: st.backend, device: st.device };
      if (__TEXEL_TEST_HOOKS__) {
        hooks.playerSamples = st.samples;
        hooks.peakMax = Math.max(hooks.peakMax, st.peak);
        hooks.touching = st.touching;
      }
    } catch {
      /* transient: next poll */
    }
  }, 100);

  // ------------------------------------------------------------------ scans
  let scanTimer: ReturnType<typeof setTimeout> | null = null;
  function requestScan(): void {
    if (scanTimer) clearTimeout(scanTimer);
    scanTimer = setTimeout(async () => {
      try {
        const r = await client.request('surface2d.scan', { ...body(), angle_deg: Number(angle.value) }, { lane: 'surface2d.scan', timeoutMs: 60000 });
        if (!r) return;
        const xs: number[] = [];
        const ys: number[] = [];
        for (let i = 0; i < r.scan.frequency_cpm.length; i++)
          if (r.scan.frequency_cpm[i] > 0) {
            xs.push(r.scan.frequency_cpm[i]);
            ys.push(r.scan.magnitude_db[i]);
          }
        spec.setData([xs, xs.map((f) => interpLog(r.target.frequency_cpm, r.target.magnitude_db, f)), ys]);
        view.scanLine = [r.from_mm as [number, number], r.to_mm as [number, number]];
        view.draw();
        scanText.textContent = `Scan of region ${r.region} through its centre at ${fmt(r.angle_deg, 0)}°: ${r.samples} samples ${fmt(r.spacing_mm, 4)} mm apart (the dashed line on the map); the 1-D texture rendered over the same length.`;
        if (__TEXEL_TEST_HOOKS__) hooks.scansDrawn++;
      } catch (e) {
        setError((e as Error).message);
      }
    }, 80);
  }
  angle.addEventListener('input', () => {
    angleNum.value = angle.value;
    requestScan();
  });
  angleNum.addEventListener('change', () => {
    const v = Math.min(179, Math.max(0, Math.round(Number(angleNum.value) || 0)));
    angleNum.value = angle.value = String(v);
    requestScan();
  });

  // ------------------------------------------------------- document controls
  deviceSel.addEventListener('change', () => {
    doc.device = deviceSel.value;
    view.fitNext = true;
    changed();
  });
  fieldSel.addEventListener('change', () => {
    region().field = fieldSel.value as Field2D;
    if (fieldSel.value === 'tile') doc.version = 5; // the tile field needs version 5; the others render alike in 4 and 5
    changed();
  });
  orient.addEventListener('change', () => {
    const v = Number((orient as HTMLInputElement).value);
    if (Number.isFinite(v)) region().orientation_deg = v;
    changed();
  });
  fromDesigner.addEventListener('click', () => {
    const t = designerTexture();
    const r = region();
    r.texture = { ...t, coarse_strength: r.texture.coarse_strength ?? t.coarse_strength ?? 0.8, fine_strength: t.fine_strength ?? r.texture.fine_strength ?? 0.6 };
    changed();
  });
  saveDoc.addEventListener('click', () => download('surface.texel.json', 'application/json', new TextEncoder().encode(JSON.stringify(doc, null, 1) + '\n')));
  openDoc.addEventListener('change', async () => {
    const f = (openDoc as HTMLInputElement).files?.[0];
    if (!f) return;
    try {
      const j = JSON.parse(await f.text()) as Surface2DDocument;
      if (!is2d(j)) throw new Error(`${f.name} is not a 2-D document (version 4 or 5 with "surface2d")`);
      doc = j;
      view.fitNext = true;
      changed();
    } catch (e) {
      setError((e as Error).message);
    }
  });
  coarseNone.addEventListener('click', () => setCoarse({ kind: 'constant', value: 1 }));
  importPng.addEventListener('change', async () => {
    const f = (importPng as HTMLInputElement).files?.[0];
    if (!f) return;
    try {
      const { png } = await toGreyPng(f);
      const name = imageName(f.name);
      images = { [name]: bytesToBase64(png) };
      setCoarse({ kind: 'image', path: name, x_mm: 0, y_mm: 0, width_mm: 0, height_mm: 0, invert: invert.checked });
    } catch (e) {
      setError(`${f.name}: not an image the browser can read (${(e as Error).message})`);
    }
  });
  invert.addEventListener('change', () => {
    const c = region().coarse2d;
    if (c?.kind === 'image') setCoarse({ ...c, invert: invert.checked });
  });

  // ------------------------------------------------------------------ start
  (async () => {
    try {
      hello = await client.call('hello', {}, 15000);
      const withBitmap = hello.devices.filter((d) => bitmapOf(d));
      deviceSel.replaceChildren(...withBitmap.map((d) => h('option', { value: d.name, title: d.description ?? '' }, d.name)));
      showControls();
      view.fitNext = true;
      changed();
    } catch (e) {
      setError((e as Error).message);
    }
  })();
}

// ------------------------------------------------------------------ MapView

interface Window2D {
  x_px: number;
  y_px: number;
  width_px: number;
  height_px: number;
  stride: number;
}
type RasterMsg = { raster: Float32Array; columns: number; rows: number; x0: number; y0: number; pitch: number };

/**
 * The friction map as an image: a canvas showing the engine's view window,
 * an overlay with the drawn path, the scan line, the shape being placed and
 * a mm scale bar. Zoom: wheel (about the pointer), pinch (two pointers),
 * buttons; pan: drag in "Pan", or two-finger drag. The window asked for is
 * what the screen shows at the zoom's resolution (every stride-th bitmap
 * pixel, about one per screen pixel), never the whole bitmap.
 */
class MapView {
  readonly el: HTMLElement;
  private image: HTMLCanvasElement;
  private overlay: HTMLCanvasElement;
  private shown: { canvas: HTMLCanvasElement; x0: number; y0: number; w: number; h: number; stride: number } | null = null;
  private raster: RasterMsg | null = null;
  private surf: Surface2DViewReply['surface'] | null = null;
  private strokes: { pts: [number, number][]; type: string }[] = [];
  private pointers = new Map<number, { x: number; y: number; type: string }>();
  private pinch: { d: number; mid: [number, number]; scale: number; cx: number; cy: number } | null = null;
  private drag: { id: number; start: [number, number]; cx: number; cy: number; screen: [number, number] } | null = null;
  private shapeStart: [number, number] | null = null;
  private pending = false;
  cx = 0;
  cy = 0;
  scale = 0.3; // mm per CSS pixel
  fitNext = true;
  scanLine: [[number, number], [number, number]] | null = null;
  preview: { kind: string; a: [number, number]; b: [number, number] } | null = null;
  fetch: (w: Window2D) => Promise<Surface2DViewReply | null> = async () => null;
  onView: (r: Surface2DViewReply) => void = () => {};
  onRaster: (m: RasterMsg) => void = () => {};
  onError: (m: string) => void = () => {};
  onScale: () => void = () => {};
  onFinger: (x: number, y: number, touch: boolean) => void = () => {};
  onShape: (a: [number, number], b: [number, number], done: boolean) => boolean = () => false;
  isFeel: () => boolean = () => true;
  isPan: () => boolean = () => false;
  isPaint: () => boolean = () => false;
  onPaint: (pts: [number, number][], done: boolean) => void = () => {};
  paintRadius = 3;
  private paintStroke: [number, number][] | null = null;

  constructor() {
    this.image = h('canvas', { class: 'map2d-image', 'data-testid': 'map2d-image', 'aria-hidden': 'true' });
    this.overlay = h('canvas', { class: 'map2d-overlay', 'data-testid': 'map2d-path', 'aria-hidden': 'true' });
    this.el = h(
      'div',
      {
        class: 'map2d',
        tabindex: 0,
        role: 'application',
        'aria-label': '2-D friction map and feel pad: drag on it with a mouse, pen or finger to feel the surface; the wheel or a pinch zooms; arrow keys move the finger 1 mm (Shift: 10 mm)',
        'data-testid': 'map2d',
      },
      this.image,
      this.overlay,
    );
    new ResizeObserver(() => this.resize()).observe(this.el);
    this.bind();
  }

  surfaceInfo(): Surface2DViewReply['surface'] | null {
    return this.surf;
  }

  lastRaster(): RasterMsg | null {
    return this.raster;
  }

  private size(): [number, number] {
    return [Math.max(200, this.el.clientWidth || 800), Math.max(200, this.el.clientHeight || 560)];
  }

  private resize(): void {
    const [w, ht] = this.size();
    const dpr = devicePixelRatio || 1;
    for (const c of [this.image, this.overlay]) {
      if (c.width !== Math.round(w * dpr) || c.height !== Math.round(ht * dpr)) {
        c.width = Math.round(w * dpr);
        c.height = Math.round(ht * dpr);
      }
    }
    this.draw();
    this.request();
  }

  /** Screen (CSS px, relative to the view) → surface mm. */
  toMm(sx: number, sy: number): [number, number] {
    const [w, ht] = this.size();
    return [this.cx + (sx - w / 2) * this.scale, this.cy + (sy - ht / 2) * this.scale];
  }
  toScreen(x: number, y: number): [number, number] {
    const [w, ht] = this.size();
    return [(x - this.cx) / this.scale + w / 2, (y - this.cy) / this.scale + ht / 2];
  }

  fit(): void {
    if (!this.surf) {
      this.fitNext = true;
      this.request();
      return;
    }
    const [w, ht] = this.size();
    this.scale = Math.max(this.surf.width_mm / (w - 8), this.surf.height_mm / (ht - 8));
    this.cx = this.surf.width_mm / 2;
    this.cy = this.surf.height_mm / 2;
    this.changedView();
  }

  private limits(): void {
    if (!this.surf) return;
    const [w, ht] = this.size();
    const most = 1.5 * Math.max(this.surf.width_mm / w, this.surf.height_mm / ht);
    const least = this.surf.pixel_pitch_mm / 32; // 32 screen px per bitmap pixel
    this.scale = Math.min(most, Math.max(least, this.scale));
    this.cx = Math.min(this.surf.width_mm, Math.max(0, this.cx));
    this.cy = Math.min(this.surf.height_mm, Math.max(0, this.cy));
  }

  zoomBy(f: number, about?: [number, number]): void {
    const [w, ht] = this.size();
    const [sx, sy] = about ?? [w / 2, ht / 2];
    const [mx, my] = this.toMm(sx, sy);
    this.scale *= f;
    this.limits();
    // Keep the point under the pointer where it was.
    this.cx = mx - (sx - w / 2) * this.scale;
    this.cy = my - (sy - ht / 2) * this.scale;
    this.changedView();
  }

  private changedView(): void {
    this.limits();
    this.el.dataset.mmPerPx = String(this.scale);
    this.onScale();
    this.draw();
    this.request();
  }

  /** Asks for the window on screen (coalesced to one request per frame; the lane keeps the newest). */
  request(): void {
    if (this.pending) return;
    this.pending = true;
    requestAnimationFrame(() => {
      this.pending = false;
      void this.load();
    });
  }

  private async load(): Promise<void> {
    let win: Window2D = { x_px: 0, y_px: 0, width_px: 1, height_px: 1, stride: 1 };
    const fitting = this.fitNext || !this.surf;
    if (!fitting && this.surf) {
      const p = this.surf.pixel_pitch_mm;
      const [w, ht] = this.size();
      const [x0, y0] = this.toMm(0, 0);
      const [x1, y1] = this.toMm(w, ht);
      const stride = Math.max(1, Math.floor(this.scale / p));
      const i0 = Math.max(0, Math.floor(x0 / p / stride) * stride);
      const j0 = Math.max(0, Math.floor(y0 / p / stride) * stride);
      const i1 = Math.min(this.surf.width_px, Math.ceil(x1 / p) + stride);
      const j1 = Math.min(this.surf.height_px, Math.ceil(y1 / p) + stride);
      if (i1 <= i0 || j1 <= j0 || i0 >= this.surf.width_px || j0 >= this.surf.height_px) return;
      win = { x_px: i0, y_px: j0, width_px: i1 - i0, height_px: j1 - j0, stride };
    }
    try {
      const r = await this.fetch(win);
      if (!r) return;
      this.surf = r.surface;
      if (fitting) {
        this.fitNext = false;
        this.fit();
        return;
      }
      this.show(r);
      this.onView(r);
    } catch (e) {
      this.onError((e as Error).message);
    }
  }

  private show(r: Surface2DViewReply): void {
    const bytes = base64ToBytes(r.amplitude_u8);
    const c = document.createElement('canvas');
    c.width = r.columns;
    c.height = r.rows;
    const ctx = c.getContext('2d')!;
    const img = ctx.createImageData(r.columns, r.rows);
    const values = new Float32Array(bytes.length);
    for (let i = 0; i < bytes.length; i++) {
      const v = bytes[i];
      values[i] = v / 255;
      img.data[4 * i] = v;
      img.data[4 * i + 1] = v;
      img.data[4 * i + 2] = v;
      img.data[4 * i + 3] = 255;
    }
    ctx.putImageData(img, 0, 0);
    const p = r.surface.pixel_pitch_mm;
    // Sample (u, v) sits at pixel (x_px + u·stride, …): it covers stride pixels from there.
    this.shown = { canvas: c, x0: r.x_px * p, y0: r.y_px * p, w: r.columns * r.stride * p, h: r.rows * r.stride * p, stride: r.stride };
    this.raster = { raster: values, columns: r.columns, rows: r.rows, x0: r.x_px * p, y0: r.y_px * p, pitch: r.view_pitch_mm };
    this.onRaster(this.raster);
    this.image.dataset.columns = String(r.columns);
    this.image.dataset.stride = String(r.stride);
    this.draw();
  }

  clearPath(): void {
    this.strokes = [];
    this.draw();
  }

  private displayDown = false;
  /** A serial display's own finger (its reports, [x, y, touch]): drawn as a path of its own (violet), the newest 20,000 points. */
  displayFinger(trail: [number, number, boolean][]): void {
    for (const [x, y, touch] of trail) {
      if (!touch) {
        this.displayDown = false;
        continue;
      }
      if (!this.displayDown) this.strokes.push({ pts: [], type: 'display' });
      this.displayDown = true;
      this.strokes[this.strokes.length - 1].pts.push([x, y]);
    }
    let n = this.strokes.reduce((a, s) => a + s.pts.length, 0);
    while (n > 20000 && this.strokes.length > 1) n -= this.strokes.shift()!.pts.length;
    this.drawOverlay();
  }

  draw(): void {
    const dpr = devicePixelRatio || 1;
    const ctx = this.image.getContext('2d')!;
    ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
    const [w, ht] = this.size();
    ctx.fillStyle = '#e9edf3';
    ctx.fillRect(0, 0, w, ht);
    if (this.surf) {
      const [sx0, sy0] = this.toScreen(0, 0);
      ctx.fillStyle = '#000';
      ctx.fillRect(sx0, sy0, this.surf.width_mm / this.scale, this.surf.height_mm / this.scale);
    }
    if (this.shown) {
      const s = this.shown;
      const [sx, sy] = this.toScreen(s.x0, s.y0);
      ctx.imageSmoothingEnabled = s.w / this.scale < s.canvas.width; // shrinking: smooth; enlarging bitmap pixels: keep them square
      ctx.drawImage(s.canvas, sx, sy, s.w / this.scale, s.h / this.scale);
    }
    this.drawOverlay();
  }

  private drawOverlay(): void {
    const dpr = devicePixelRatio || 1;
    const ctx = this.overlay.getContext('2d')!;
    ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
    const [w, ht] = this.size();
    ctx.clearRect(0, 0, w, ht);
    // The scan line.
    if (this.scanLine) {
      ctx.save();
      ctx.strokeStyle = '#2a6fdb';
      ctx.lineWidth = 2;
      ctx.setLineDash([8, 5]);
      ctx.beginPath();
      ctx.moveTo(...this.toScreen(...this.scanLine[0]));
      ctx.lineTo(...this.toScreen(...this.scanLine[1]));
      ctx.stroke();
      ctx.restore();
    }
    // The drawn path: every stroke since "Clear the path".
    ctx.save();
    ctx.lineCap = 'round';
    ctx.lineJoin = 'round';
    for (const s of this.strokes) {
      ctx.strokeStyle = s.type === 'pen' ? '#d6336c' : s.type === 'touch' ? '#2f9e44' : s.type === 'display' ? '#7048e8' : '#f76707';
      ctx.lineWidth = 3;
      ctx.beginPath();
      s.pts.forEach((p, i) => (i ? ctx.lineTo(...this.toScreen(...p)) : ctx.moveTo(...this.toScreen(...p))));
      if (s.pts.length === 1) {
        const [x, y] = this.toScreen(...s.pts[0]);
        ctx.arc(x, y, 2, 0, 2 * Math.PI);
      }
      ctx.stroke();
    }
    ctx.restore();
    // The shape being placed.
    if (this.preview) {
      const { kind, a, b } = this.preview;
      const [ax, ay] = this.toScreen(...a);
      const [bx, by] = this.toScreen(...b);
      ctx.save();
      ctx.strokeStyle = '#f0a500';
      ctx.lineWidth = 2;
      ctx.setLineDash([4, 3]);
      ctx.beginPath();
      if (kind === 'disc' || kind === 'bump') ctx.arc(ax, ay, Math.hypot(bx - ax, by - ay) / (kind === 'bump' ? 2 : 1), 0, 2 * Math.PI);
      ctx.moveTo(ax, ay);
      ctx.lineTo(bx, by);
      ctx.stroke();
      ctx.restore();
    }
    // The stroke being painted.
    if (this.paintStroke) {
      ctx.save();
      ctx.strokeStyle = 'rgba(255,255,255,0.8)';
      ctx.lineCap = ctx.lineJoin = 'round';
      ctx.lineWidth = (2 * this.paintRadius) / this.scale;
      ctx.beginPath();
      this.paintStroke.forEach((p, i) => (i ? ctx.lineTo(...this.toScreen(...p)) : ctx.moveTo(...this.toScreen(...p))));
      ctx.stroke();
      ctx.restore();
    }
    // A mm scale bar: a round length near 120 screen px.
    const want = 120 * this.scale;
    const pow = 10 ** Math.floor(Math.log10(want));
    const len = [1, 2, 5, 10].map((m) => m * pow).reduce((a, b) => (Math.abs(b - want) < Math.abs(a - want) ? b : a));
    const px = len / this.scale;
    ctx.save();
    ctx.fillStyle = 'rgba(255,255,255,0.85)';
    ctx.fillRect(8, ht - 30, px + 70, 24);
    ctx.strokeStyle = '#1b2a41';
    ctx.lineWidth = 2;
    ctx.beginPath();
    ctx.moveTo(14, ht - 12);
    ctx.lineTo(14 + px, ht - 12);
    ctx.moveTo(14, ht - 17);
    ctx.lineTo(14, ht - 7);
    ctx.moveTo(14 + px, ht - 17);
    ctx.lineTo(14 + px, ht - 7);
    ctx.stroke();
    ctx.fillStyle = '#1b2a41';
    ctx.font = '12px sans-serif';
    ctx.fillText(`${len >= 1 ? len : len.toPrecision(1)} mm`, 20 + px, ht - 13);
    ctx.restore();
  }

  private local(e: PointerEvent | WheelEvent): [number, number] {
    const r = this.el.getBoundingClientRect();
    return [e.clientX - r.left, e.clientY - r.top];
  }

  private onSurface(x: number, y: number): boolean {
    return !!this.surf && x >= 0 && y >= 0 && x < this.surf.width_mm && y < this.surf.height_mm;
  }

  private bind(): void {
    const el = this.el;
    el.addEventListener(
      'wheel',
      (e) => {
        e.preventDefault();
        this.zoomBy(Math.exp(Math.max(-0.5, Math.min(0.5, e.deltaY * 0.0015))), this.local(e));
      },
      { passive: false },
    );
    el.addEventListener('pointerdown', (e) => {
      if (e.pointerType === 'mouse' && e.button !== 0 && e.button !== 1) return;
      e.preventDefault();
      el.focus({ preventScroll: true });
      el.setPointerCapture(e.pointerId);
      const [sx, sy] = this.local(e);
      this.pointers.set(e.pointerId, { x: sx, y: sy, type: e.pointerType });
      if (this.pointers.size === 2) {
        // A second finger: pinch and pan; the first finger's touch ends.
        if (this.fingerDown) this.lift();
        this.shapeStart = null;
        this.preview = null;
        this.paintStroke = null;
        const [p, q] = [...this.pointers.values()];
        this.pinch = { d: Math.hypot(p.x - q.x, p.y - q.y) || 1, mid: [(p.x + q.x) / 2, (p.y + q.y) / 2], scale: this.scale, cx: this.cx, cy: this.cy };
        return;
      }
      if (this.pointers.size > 2) return;
      const [x, y] = this.toMm(sx, sy);
      if (this.isPaint()) {
        this.paintStroke = [[x, y]];
        this.onPaint(this.paintStroke, false);
        this.drawOverlay();
      } else if (this.isPan() || e.button === 1) {
        this.drag = { id: e.pointerId, start: [x, y], cx: this.cx, cy: this.cy, screen: [sx, sy] };
      } else if (this.onShape([x, y], [x, y], false)) {
        this.shapeStart = [x, y];
        this.drawOverlay();
      } else if (this.isFeel()) {
        this.touch(x, y, e.pointerType);
      }
    });
    el.addEventListener('pointermove', (e) => {
      const known = this.pointers.get(e.pointerId);
      if (!known) return;
      const [sx, sy] = this.local(e);
      known.x = sx;
      known.y = sy;
      if (this.pinch && this.pointers.size >= 2) {
        const [p, q] = [...this.pointers.values()];
        const d = Math.hypot(p.x - q.x, p.y - q.y) || 1;
        const mid: [number, number] = [(p.x + q.x) / 2, (p.y + q.y) / 2];
        const [w, ht] = this.size();
        const pin = this.pinch;
        // The point under the first midpoint follows the fingers' midpoint.
        const mx = pin.cx + (pin.mid[0] - w / 2) * pin.scale;
        const my = pin.cy + (pin.mid[1] - ht / 2) * pin.scale;
        this.scale = (pin.scale * pin.d) / d;
        this.limits();
        this.cx = mx - (mid[0] - w / 2) * this.scale;
        this.cy = my - (mid[1] - ht / 2) * this.scale;
        this.changedView();
        return;
      }
      if (this.drag && this.drag.id === e.pointerId) {
        this.cx = this.drag.cx - (sx - this.drag.screen[0]) * this.scale;
        this.cy = this.drag.cy - (sy - this.drag.screen[1]) * this.scale;
        this.changedView();
        return;
      }
      const [x, y] = this.toMm(sx, sy);
      if (this.paintStroke) {
        this.paintStroke.push([x, y]);
        this.drawOverlay();
        return;
      }
      if (this.shapeStart) {
        this.onShape(this.shapeStart, [x, y], false);
        this.drawOverlay();
        return;
      }
      if (this.fingerDown) {
        // Every coalesced sample the browser saw since the last event (pens and touch report faster than frames).
        const events = typeof e.getCoalescedEvents === 'function' ? e.getCoalescedEvents() : [];
        for (const c of events.length ? events : [e]) {
          const [cx, cy] = this.local(c);
          this.touch(...this.toMm(cx, cy), e.pointerType);
        }
      }
    });
    const up = (e: PointerEvent) => {
      if (!this.pointers.delete(e.pointerId)) return;
      if (this.pinch) {
        if (this.pointers.size < 2) this.pinch = null;
        return;
      }
      if (this.drag && this.drag.id === e.pointerId) this.drag = null;
      const [x, y] = this.toMm(...this.local(e));
      if (this.paintStroke) {
        const pts = this.paintStroke;
        this.paintStroke = null;
        this.onPaint(pts, true);
        return;
      }
      if (this.shapeStart) {
        const a = this.shapeStart;
        this.shapeStart = null;
        this.onShape(a, [x, y], true);
        this.drawOverlay();
        return;
      }
      if (this.fingerDown) this.lift();
    };
    el.addEventListener('pointerup', up);
    el.addEventListener('pointercancel', up);
    el.addEventListener('keydown', (e) => {
      const step = e.shiftKey ? 10 : 1;
      const [x, y] = this.keyFinger ?? [this.cx, this.cy];
      let to: [number, number] | null = null;
      if (e.key === 'ArrowRight') to = [x + step, y];
      else if (e.key === 'ArrowLeft') to = [x - step, y];
      else if (e.key === 'ArrowDown') to = [x, y + step];
      else if (e.key === 'ArrowUp') to = [x, y - step];
      else if (e.key === '+' || e.key === '=') this.zoomBy(1 / 1.5);
      else if (e.key === '-') this.zoomBy(1.5);
      else return;
      e.preventDefault();
      if (to && this.isFeel()) {
        this.keyFinger = to;
        this.touch(to[0], to[1], 'keyboard');
      }
    });
    el.addEventListener('keyup', (e) => {
      if (e.key.startsWith('Arrow') && this.fingerDown) this.lift();
    });
    el.addEventListener('blur', () => {
      if (this.fingerDown) this.lift();
    });
  }

  private fingerDown = false;
  private keyFinger: [number, number] | null = null;
  private last: [number, number] = [0, 0];

  private touch(x: number, y: number, type: string): void {
    if (!this.onSurface(x, y)) {
      // Off the surface counts as lifted (the player ramps out there too).
      if (this.fingerDown) this.lift();
      return;
    }
    if (!this.fingerDown) this.strokes.push({ pts: [], type });
    this.fingerDown = true;
    this.last = [x, y];
    this.strokes[this.strokes.length - 1].pts.push([x, y]);
    this.el.dataset.touching = 'true';
    this.onFinger(x, y, true);
    this.drawOverlay();
  }

  private lift(): void {
    this.fingerDown = false;
    this.el.dataset.touching = 'false';
    this.onFinger(this.last[0], this.last[1], false);
  }
}
