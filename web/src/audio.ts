// "Hear it": when no haptic hardware is attached, the page plays the
// vibration through the browser's audio so a texture can at least be heard.
// Presentation only, no texture logic: an AudioWorklet samples the map of the
// last `design` reply at the finger's position, interpolated between pointer
// samples, and removes DC with a one-pole high-pass (a finger at rest is
// silent, as on the display). Gain ramps over ~5 ms on touch changes (no clicks).

import workletUrl from './audio-worklet?worker&url';
import type { HearMessage } from './audio-worklet';

export class HearIt {
  private ctx: AudioContext | null = null;
  private node: AudioWorkletNode | null = null;
  private pendingMap: { map: Float32Array; origin: number; spacing: number } | null = null;
  enabled = false;

  async enable(): Promise<void> {
    if (!this.ctx) {
      this.ctx = new AudioContext();
      await this.ctx.audioWorklet.addModule(workletUrl);
      this.node = new AudioWorkletNode(this.ctx, 'texel-hear', { outputChannelCount: [2] });
      this.node.connect(this.ctx.destination);
      if (this.pendingMap) this.post(this.pendingMap);
    }
    await this.ctx.resume();
    this.enabled = true;
  }

  async disable(): Promise<void> {
    this.enabled = false;
    this.post({ x: 0, touch: false });
    await this.ctx?.suspend();
  }

  setMap(map: Float32Array, origin: number, spacing: number): void {
    this.pendingMap = { map, origin, spacing };
    this.post({ map: map.slice(), origin, spacing });
  }

  private post(m: HearMessage): void {
    this.node?.port.postMessage(m);
  }

  pointer(x_mm: number, touch: boolean): void {
    if (this.enabled) this.post({ x: x_mm, touch });
  }
}

export const hearIt = new HearIt();
