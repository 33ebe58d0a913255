// "Hear it"'s AudioWorklet processor (audio.ts loads it; Vite bundles it as
// a module of its own). Samples the map of the last design reply at the
// finger's position, glided between pointer samples, high-passed so a still
// finger is silent; gain ramps on touch changes (no clicks).

// The AudioWorkletGlobalScope, which TypeScript's DOM library does not describe.
declare const sampleRate: number;
declare class AudioWorkletProcessor {
  readonly port: MessagePort;
}
declare function registerProcessor(name: string, ctor: new () => AudioWorkletProcessor): void;

/** Page → worklet: a new map, or the finger. */
export type HearMessage = { map: Float32Array; origin: number; spacing: number } | { x: number; touch: boolean };

class TexelHear extends AudioWorkletProcessor {
  private map: Float32Array = new Float32Array(0);
  private origin = 0;
  private spacing = 1;
  private pos = 0;
  private target = 0;
  private touch = false;
  private gain = 0;
  private hpX = 0;
  private hpY = 0;
  // Pointer samples arrive at ~60-250 Hz: glide to the newest over ~16 ms.
  private glide = 1 / (0.016 * sampleRate);

  constructor() {
    super();
    this.port.onmessage = (e: MessageEvent<HearMessage>) => {
      const m = e.data;
      if ('map' in m) {
        this.map = m.map;
        this.origin = m.origin;
        this.spacing = m.spacing;
      } else {
        if (!this.touch && m.touch) this.pos = m.x;
        this.target = m.x;
        this.touch = m.touch;
      }
    };
  }

  process(_in: Float32Array[][], outputs: Float32Array[][]): boolean {
    const out = outputs[0][0];
    if (!out) return true;
    const n = this.map.length;
    const a = 0.995; // high-pass pole (~35 Hz at 48 kHz)
    for (let i = 0; i < out.length; i++) {
      this.pos += (this.target - this.pos) * Math.min(1, this.glide * 4);
      let v = 0;
      if (n > 1) {
        const f = (this.pos - this.origin) / this.spacing;
        const k = Math.floor(f);
        if (k >= 0 && k < n - 1) { const t = f - k; v = this.map[k] * (1 - t) + this.map[k + 1] * t; }
      }
      const g = this.touch ? 1 : 0;
      this.gain += (g - this.gain) * 0.004;
      const y = v - this.hpX + a * this.hpY; this.hpX = v; this.hpY = y;
      out[i] = y * this.gain * 0.8;
    }
    for (let c = 1; c < outputs[0].length; c++) outputs[0][c].set(out);
    return true;
  }
}
registerProcessor('texel-hear', TexelHear);
