// uPlot views of the designer's numbers: the friction map (zoomable, with a
// 6 mm detail and a pointer-drawn coarse profile), the texel-frequency
// histogram over the distribution's density, and the spectrum (log
// frequency). Every value plotted comes from a `design`/`match` reply.

import uPlot from 'uplot';
import 'uplot/dist/uPlot.min.css';
import { h } from './util';
import type { Spectrum } from './generated/messages';

function widthOf(el: HTMLElement, fallback: number): number {
  return Math.max(200, Math.floor(el.clientWidth || fallback));
}

function autoResize(u: uPlot, host: HTMLElement, height: number): void {
  const ro = new ResizeObserver(() => {
    const w = widthOf(host, u.width);
    if (Math.abs(w - u.width) > 2) u.setSize({ width: w, height });
  });
  ro.observe(host);
}

// Axis titles (uPlot draws them on its canvas; each plot's host also carries
// them as data-axes, x|y, for tests and assistive text).
const MAP_AXES = ['position on the surface (mm)', 'drive (0…1)'] as const;
const HIST_AXES = ['texel frequency (cycles/mm)', 'texels (count)'] as const;
const SPECTRUM_AXES = ['spatial frequency (cycles/mm, log)', 'dB re amplitude 1'] as const;
const axesAttr = (a: readonly string[]) => a.join('|');

export interface RegionMark {
  name: string;
  start_mm: number;
  length_mm: number;
}

/** The friction map: main plot (drag to zoom, double-click to reset) plus a 6 mm detail. */
export class MapPlot {
  readonly el: HTMLElement;
  private main: uPlot;
  private detail: uPlot;
  private x = new Float64Array(0);
  private y: Float32Array = new Float32Array(0);
  private regions: RegionMark[] = [];
  private detailCentre = NaN;
  private drawCanvas: HTMLCanvasElement;
  private drawing: [number, number][] | null = null;
  drawMode = false;
  /** Called with absolute (position_mm, value 0…1) points when a drawn stroke ends. */
  onDrawn: (points: [number, number][]) => void = () => {};

  constructor(height = 220) {
    const mainHost = h('div', { class: 'plot', 'data-testid': 'map-plot', 'data-axes': axesAttr(MAP_AXES), 'aria-label': 'Friction map: drive 0…1 (1 = full friction change) over position (mm)', role: 'img' });
    const detailHost = h('div', { class: 'plot detail', 'data-testid': 'detail-plot', 'data-axes': axesAttr(MAP_AXES), 'aria-label': '6 mm detail of the friction map: drive 0…1 over position (mm)', role: 'img' });
    this.el = h('div', { class: 'map-plots' }, mainHost, h('div', { class: 'plot-caption' }, '6 mm detail (follows the cursor on the map)'), detailHost);
    const regionsHook = (u: uPlot) => {
      const ctx = u.ctx;
      ctx.save();
      ctx.strokeStyle = '#c44';
      ctx.fillStyle = '#c44';
      ctx.setLineDash([4, 4]);
      ctx.font = `${Math.round(11 * devicePixelRatio)}px sans-serif`;
      for (const r of this.regions) {
        const px = u.valToPos(r.start_mm, 'x', true);
        if (px >= u.bbox.left && px <= u.bbox.left + u.bbox.width) {
          ctx.beginPath();
          ctx.moveTo(px, u.bbox.top);
          ctx.lineTo(px, u.bbox.top + u.bbox.height);
          ctx.stroke();
        }
        const mid = u.valToPos(r.start_mm + r.length_mm / 2, 'x', true);
        if (mid >= u.bbox.left && mid <= u.bbox.left + u.bbox.width && this.regions.length > 1)
          ctx.fillText(r.name, mid, u.bbox.top + 12 * devicePixelRatio);
      }
      ctx.restore();
    };
    this.main = new uPlot(
      {
        width: 800,
        height,
        cursor: { drag: { x: true, y: false }, points: { show: false } },
        legend: { show: false },
        scales: { x: { time: false }, y: { range: [0, 1] } },
        axes: [{ label: MAP_AXES[0] }, { label: MAP_AXES[1] }],
        series: [{}, { stroke: '#2a6fdb', width: 1, points: { show: false } }],
        hooks: {
          draw: [regionsHook],
          setCursor: [
            (u) => {
              if (u.cursor.idx !== null && u.cursor.idx !== undefined && this.x.length && !this.drawing) this.setDetail(this.x[u.cursor.idx]);
            },
          ],
        },
      },
      [[], []],
      mainHost,
    );
    this.detail = new uPlot(
      {
        width: 800,
        height: 170,
        cursor: { drag: { x: false, y: false }, points: { show: false } },
        legend: { show: false },
        scales: { x: { time: false, auto: false }, y: { range: [0, 1] } },
        axes: [{ label: MAP_AXES[0] }, { label: MAP_AXES[1], splits: () => [0, 0.5, 1] }],
        series: [{}, { stroke: '#2a6fdb', width: 1.5, points: { show: false } }],
      },
      [[], []],
      detailHost,
    );
    requestAnimationFrame(() => {
      this.main.setSize({ width: widthOf(mainHost, 800), height });
      this.detail.setSize({ width: widthOf(detailHost, 800), height: 170 });
    });
    autoResize(this.main, mainHost, height);
    autoResize(this.detail, detailHost, 170);

    // Drawing a coarse profile: a canvas over the plot area shows the stroke.
    this.drawCanvas = h('canvas', { class: 'draw-overlay', 'aria-hidden': 'true' });
    this.main.over.append(this.drawCanvas);
    const over = this.main.over;
    over.addEventListener('pointerdown', (e) => {
      if (!this.drawMode || !this.x.length) return;
      e.preventDefault(); // no zoom drag, no compatibility mouse events
      over.setPointerCapture(e.pointerId);
      this.drawing = [];
      this.addDrawPoint(e);
    });
    over.addEventListener('pointermove', (e) => {
      if (this.drawing) this.addDrawPoint(e);
    });
    const end = () => {
      if (!this.drawing) return;
      const pts = this.drawing;
      this.drawing = null;
      const ctx = this.drawCanvas.getContext('2d');
      ctx?.clearRect(0, 0, this.drawCanvas.width, this.drawCanvas.height);
      if (pts.length >= 2) this.onDrawn(pts);
    };
    over.addEventListener('pointerup', end);
    over.addEventListener('pointercancel', end);
  }

  private addDrawPoint(e: PointerEvent): void {
    const r = this.main.over.getBoundingClientRect();
    const px = Math.min(Math.max(e.clientX - r.left, 0), r.width);
    const py = Math.min(Math.max(e.clientY - r.top, 0), r.height);
    const xmm = this.main.posToVal(px, 'x');
    const v = Math.min(1, Math.max(0, 1 - py / r.height));
    this.drawing!.push([xmm, v]);
    const c = this.drawCanvas;
    if (c.width !== Math.round(r.width) || c.height !== Math.round(r.height)) {
      c.width = Math.round(r.width);
      c.height = Math.round(r.height);
    }
    const ctx = c.getContext('2d')!;
    ctx.clearRect(0, 0, c.width, c.height);
    ctx.strokeStyle = '#e07b00';
    ctx.lineWidth = 3;
    ctx.beginPath();
    this.drawing!.forEach(([x, val], i) => {
      const X = this.main.valToPos(x, 'x');
      const Y = (1 - val) * r.height;
      if (i === 0) ctx.moveTo(X, Y);
      else ctx.lineTo(X, Y);
    });
    ctx.stroke();
  }

  setDetail(centre_mm: number): void {
    if (!this.x.length) return;
    const lo = this.x[0];
    const hi = this.x[this.x.length - 1];
    const c = Math.min(Math.max(centre_mm, lo + 3), Math.max(lo + 3, hi - 3));
    this.detailCentre = c;
    this.detail.setScale('x', { min: c - 3, max: c + 3 });
  }

  /** New map samples; keeps the zoom unless the grid changed. */
  setMap(origin_mm: number, spacing_mm: number, values: Float32Array, regions: RegionMark[], focus_mm?: number): void {
    let gridChanged = this.x.length !== values.length || this.x[0] !== origin_mm || (this.x.length > 1 && Math.abs(this.x[1] - this.x[0] - spacing_mm) > 1e-12);
    if (gridChanged) {
      this.x = new Float64Array(values.length);
      for (let i = 0; i < values.length; i++) this.x[i] = origin_mm + i * spacing_mm;
    }
    this.y = values;
    this.regions = regions;
    const data: uPlot.AlignedData = [this.x, this.y];
    // setData(…, false) keeps the zoom but does not repaint (uPlot 1.6): redraw explicitly.
    this.main.setData(data, gridChanged);
    if (!gridChanged) this.main.redraw(true, false);
    this.detail.setData(data, false);
    if (gridChanged || !Number.isFinite(this.detailCentre)) this.setDetail(focus_mm ?? origin_mm + (values.length * spacing_mm) / 2);
    else this.setDetail(this.detailCentre);
  }
}

/** Texel-frequency histogram (bars) over the distribution's density (line). */
export class HistogramPlot {
  readonly el: HTMLElement;
  private u: uPlot;

  constructor(height = 200) {
    this.el = h('div', { class: 'plot', 'data-testid': 'histogram-plot', 'data-axes': axesAttr(HIST_AXES), role: 'img', 'aria-label': 'Histogram of texel frequencies (cycles/mm) over the distribution density' });
    this.u = new uPlot(
      {
        width: 400,
        height,
        legend: { show: true },
        cursor: { drag: { x: true, y: false } },
        scales: { x: { time: false } },
        axes: [{ label: HIST_AXES[0] }, { label: HIST_AXES[1] }],
        series: [
          { label: 'cpm' },
          { label: 'texels', stroke: '#2a6fdb', fill: 'rgba(42,111,219,0.35)', paths: uPlot.paths.bars!({ size: [0.95, 100] }), points: { show: false } },
          { label: 'density', stroke: '#e07b00', width: 2, points: { show: false } },
        ],
      },
      [[], [], []],
      this.el,
    );
    requestAnimationFrame(() => this.u.setSize({ width: widthOf(this.el, 400), height }));
    autoResize(this.u, this.el, height);
  }

  set(edges: number[], counts: number[], pdf: number[]): void {
    const n = counts.length;
    const centres = new Array<number>(n);
    for (let i = 0; i < n; i++) centres[i] = (edges[i] + edges[i + 1]) / 2;
    this.u.setData([centres, counts, pdf.length === n ? pdf : counts.map(() => null)]);
  }
}

/** ys at x, interpolated linearly in log x between the points of ascending xs; null outside them. */
export function interpLog(xs: number[], ys: number[], x: number): number | null {
  if (!xs.length || x < xs[0] || x > xs[xs.length - 1]) return null;
  let lo = 0;
  let hi = xs.length - 1;
  while (hi - lo > 1) {
    const m = (lo + hi) >> 1;
    if (xs[m] <= x) lo = m;
    else hi = m;
  }
  if (xs[hi] === xs[lo]) return ys[lo];
  const t = (Math.log(x) - Math.log(xs[lo])) / (Math.log(xs[hi]) - Math.log(xs[lo]));
  return ys[lo] + t * (ys[hi] - ys[lo]);
}

/** Spectrum (dB over log frequency), with optional target/match overlays. */
export class SpectrumPlot {
  readonly el: HTMLElement;
  private u: uPlot;

  constructor(height = 200) {
    this.el = h('div', { class: 'plot', 'data-testid': 'spectrum-plot', 'data-axes': axesAttr(SPECTRUM_AXES), role: 'img', 'aria-label': 'Spectrum: magnitude (dB re amplitude 1, a full-scale sine) over spatial frequency (cycles/mm, log)' });
    this.u = new uPlot(
      {
        width: 400,
        height,
        legend: { show: true },
        cursor: { drag: { x: true, y: false } },
        scales: { x: { time: false, distr: 3 } },
        axes: [{ label: SPECTRUM_AXES[0] }, { label: SPECTRUM_AXES[1] }],
        // Drawn in this order: the match as a wide pale band under the design's
        // thin line, so the two stay visible when they coincide.
        series: [
          { label: 'cycles/mm' },
          { label: 'match (decoded)', stroke: 'rgba(42,157,63,0.45)', width: 6, points: { show: false } },
          { label: 'reference (target)', stroke: '#c44', width: 1.5, dash: [6, 3], points: { show: false } },
          { label: 'design', stroke: '#1b3f8f', width: 1.25, points: { show: false } },
        ],
        hooks: { draw: [(u) => this.drawCorner(u)] },
      },
      [[1], [null], [null], [null]],
      this.el,
    );
    requestAnimationFrame(() => this.u.setSize({ width: widthOf(this.el, 400), height }));
    autoResize(this.u, this.el, height);
  }

  set(main: Spectrum, target?: Spectrum | null, match?: Spectrum | null): void {
    const xs: number[] = [];
    const ys: number[] = [];
    for (let i = 0; i < main.frequency_cpm.length; i++) {
      const f = main.frequency_cpm[i];
      if (f > 0 && Number.isFinite(main.magnitude_db[i])) {
        xs.push(f);
        ys.push(main.magnitude_db[i]);
      }
    }
    const over = (s?: Spectrum | null) => xs.map((f) => (s ? interpLog(s.frequency_cpm, s.magnitude_db, f) : null));
    this.u.setData([xs, over(match), over(target), ys]);
  }

  /** Marks the spatial frequency at which the drive reaches the display's corner (corner Hz / swipe speed). */
  setCorner(cpm: number | null, label: string): void {
    this.corner = cpm !== null && Number.isFinite(cpm) && cpm > 0 ? { cpm, label } : null;
    this.u.redraw(false, false);
  }

  private corner: { cpm: number; label: string } | null = null;

  private drawCorner(u: uPlot): void {
    if (!this.corner) return;
    const px = u.valToPos(this.corner.cpm, 'x', true);
    if (!(px >= u.bbox.left && px <= u.bbox.left + u.bbox.width)) return;
    const ctx = u.ctx;
    ctx.save();
    ctx.strokeStyle = '#b3261e';
    ctx.fillStyle = '#b3261e';
    ctx.setLineDash([3, 3]);
    ctx.beginPath();
    ctx.moveTo(px, u.bbox.top);
    ctx.lineTo(px, u.bbox.top + u.bbox.height);
    ctx.stroke();
    ctx.font = `${Math.round(11 * devicePixelRatio)}px sans-serif`;
    ctx.textAlign = px > u.bbox.left + u.bbox.width * 0.6 ? 'right' : 'left';
    ctx.fillText(this.corner.label, px + (ctx.textAlign === 'right' ? -4 : 4) * devicePixelRatio, u.bbox.top + 12 * devicePixelRatio);
    ctx.restore();
  }
}
