// "Hear it" for the 2-D pad: the page's side of audio2d-worklet.ts (see there).
import workletUrl from './audio2d-worklet?worker&url';
import type { Hear2DMessage } from './audio2d-worklet';

export class Hear2D {
  private ctx: AudioContext | null = null;
  private node: AudioWorkletNode | null = null;
  private source: Hear2DMessage | null = null;
  enabled = false;

  async enable(): Promise<void> {
    if (!this.ctx) {
      this.ctx = new AudioContext();
      await this.ctx.audioWorklet.addModule(workletUrl);
      this.node = new AudioWorkletNode(this.ctx, 'texel-hear-2d', { outputChannelCount: [2] });
      this.node.connect(this.ctx.destination);
      if (this.source) this.node.port.postMessage(this.source);
    }
    await this.ctx.resume();
    this.enabled = true;
  }

  async disable(): Promise<void> {
    this.enabled = false;
    this.node?.port.postMessage({ x: 0, y: 0, s: 0, touch: false } satisfies Hear2DMessage);
    await this.ctx?.suspend();
  }

  /** What is heard: the texture's 1-D map along the path, or a 2-D raster at (x, y). */
  setSource(m: Hear2DMessage): void {
    this.source = m;
    this.node?.port.postMessage(m);
  }

  finger(x: number, y: number, s: number, touch: boolean): void {
    if (this.enabled) this.node?.port.postMessage({ x, y, s, touch } satisfies Hear2DMessage);
  }
}
