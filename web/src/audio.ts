// "Hear it": when no haptic hardware is attached, the page plays the
// vibration through the browser's audio so a texture can at least be heard.
// Presentation only, no texture logic: an AudioWorklet samples the map of the
// last `design` reply at the finger's position, interpolated between pointer
// samples, and removes DC with a one-pole high-pass (a finger at rest is
// silent, as on the display). Gain ramps over ~5 ms on touch changes (no clicks).

const WORKLET = `
class TexelHear extends AudioWorkletProcessor {
  constructor() {
    super();
    this.map = new Float32Array(0); this.origin = 0; this.spacing = 1;
    this.pos = 0; this.target = 0; this.touch = false; this.gain = 0;
    this.hpX = 0; this.hpY = 0;
    // Pointer samples arrive at ~60-250 Hz: glide to the newest over ~16 ms.
    this.glide = 1 / (0.016 * sampleRate);
    this.port.onmessage = (e) => {
      const m = e.data;
      if (m.map) { this.map = m.map; this.origin = m.origin; this.spacing = m.spacing; }
      if (m.x !== undefined) {
        if (!this.touch && m.touch) this.pos = m.x;
        this.target = m.x; this.touch = m.touch;
      }
    };
  }
  process(_in, outputs) {
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
`;

export class HearIt {
  private ctx: AudioContext | null = null;
  private node: AudioWorkletNode | null = null;
  private pendingMap: { map: Float32Array; origin: number; spacing: number } | null = null;
  enabled = false;

  async enable(): Promise<void> {
    if (!this.ctx) {
      this.ctx = new AudioContext();
      const url = URL.createObjectURL(new Blob([WORKLET], { type: 'text/javascript' }));
      await this.ctx.audioWorklet.addModule(url);
      URL.revokeObjectURL(url);
      this.node = new AudioWorkletNode(this.ctx, 'texel-hear', { outputChannelCount: [2] });
      this.node.connect(this.ctx.destination);
      if (this.pendingMap) this.node.port.postMessage(this.pendingMap);
    }
    await this.ctx.resume();
    this.enabled = true;
  }

  async disable(): Promise<void> {
    this.enabled = false;
    this.node?.port.postMessage({ x: 0, touch: false });
    await this.ctx?.suspend();
  }

  setMap(map: Float32Array, origin: number, spacing: number): void {
    this.pendingMap = { map, origin, spacing };
    this.node?.port.postMessage({ map: map.slice(), origin, spacing });
  }

  pointer(x_mm: number, touch: boolean): void {
    if (this.enabled) this.node?.port.postMessage({ x: x_mm, touch });
  }
}

export const hearIt = new HearIt();
