// "Hear it" on the 2-D page (audio2d.ts loads it; Vite bundles it as a module
// of its own). Presentation only, like the 1-D worklet: in path mode it reads
// the texture's 1-D map at the finger's travelled path length s, in bitmap
// mode the 2-D view's samples at the finger's (x, y); both glided between
// pointer samples, high-passed so a still finger is silent, with gain ramps
// on touch changes (no clicks).

declare const sampleRate: number;
declare class AudioWorkletProcessor {
  readonly port: MessagePort;
}
declare function registerProcessor(name: string, ctor: new () => AudioWorkletProcessor): void;

/** Page → worklet: the 1-D line (path mode), the 2-D raster (bitmap mode), or the finger. */
export type Hear2DMessage =
  | { line: Float32Array; spacing: number }
  | { raster: Float32Array; columns: number; rows: number; x0: number; y0: number; pitch: number }
  | { x: number; y: number; s: number; touch: boolean };

class TexelHear2D extends AudioWorkletProcessor {
  private line: Float32Array | null = null;
  private spacing = 1;
  private raster: Float32Array | null = null;
  private cols = 0;
  private rows = 0;
  private x0 = 0;
  private y0 = 0;
  private pitch = 1;
  private pos = [0, 0, 0];
  private target = [0, 0, 0];
  private touch = false;
  private gain = 0;
  private hpX = 0;
  private hpY = 0;
  private glide = Math.min(1, 4 / (0.016 * sampleRate));

  constructor() {
    super();
    this.port.onmessage = (e: MessageEvent<Hear2DMessage>) => {
      const m = e.data;
      if ('line' in m) {
        this.line = m.line;
        this.spacing = m.spacing;
        this.raster = null;
      } else if ('raster' in m) {
        this.raster = m.raster;
        this.cols = m.columns;
        this.rows = m.rows;
        this.x0 = m.x0;
        this.y0 = m.y0;
        this.pitch = m.pitch;
        this.line = null;
      } else {
        if (!this.touch && m.touch) this.pos = [m.x, m.y, m.s];
        this.target = [m.x, m.y, m.s];
        this.touch = m.touch;
      }
    };
  }

  private value(): number {
    if (this.line && this.line.length > 1) {
      const n = this.line.length;
      const f = (((this.pos[2] / this.spacing) % n) + n) % n;
      const k = Math.floor(f);
      const t = f - k;
      return this.line[k] * (1 - t) + this.line[(k + 1) % n] * t;
    }
    if (this.raster && this.cols > 1 && this.rows > 1) {
      const u = Math.min(this.cols - 1.001, Math.max(0, (this.pos[0] - this.x0) / this.pitch));
      const v = Math.min(this.rows - 1.001, Math.max(0, (this.pos[1] - this.y0) / this.pitch));
      const i = Math.floor(u);
      const j = Math.floor(v);
      const a = u - i;
      const b = v - j;
      const r = this.raster;
      const c = this.cols;
      return (r[j * c + i] * (1 - a) + r[j * c + i + 1] * a) * (1 - b) + (r[(j + 1) * c + i] * (1 - a) + r[(j + 1) * c + i + 1] * a) * b;
    }
    return 0;
  }

  process(_in: Float32Array[][], outputs: Float32Array[][]): boolean {
    const out = outputs[0][0];
    if (!out) return true;
    const hp = 0.995; // high-pass pole (~35 Hz at 48 kHz)
    for (let i = 0; i < out.length; i++) {
      for (let k = 0; k < 3; k++) this.pos[k] += (this.target[k] - this.pos[k]) * this.glide;
      const v = this.value();
      this.gain += ((this.touch ? 1 : 0) - this.gain) * 0.004;
      const y = v - this.hpX + hp * this.hpY;
      this.hpX = v;
      this.hpY = y;
      out[i] = y * this.gain * 0.8;
    }
    for (let c = 1; c < outputs[0].length; c++) outputs[0][c].set(out);
    return true;
  }
}
registerProcessor('texel-hear-2d', TexelHear2D);
