// Small DOM and data helpers shared by the pages.

type Attrs = Record<string, string | number | boolean | EventListener | undefined>;

/** Creates an element: h('button', {class: 'big', onclick: f}, 'Text'). */
export function h<K extends keyof HTMLElementTagNameMap>(
  tag: K,
  attrs: Attrs = {},
  ...children: (Node | string | null | undefined | false)[]
): HTMLElementTagNameMap[K] {
  const el = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) {
    if (v === undefined || v === false) continue;
    if (k.startsWith('on') && typeof v === 'function') el.addEventListener(k.slice(2), v as EventListener);
    else if (k === 'class') el.className = String(v);
    else if (v === true) el.setAttribute(k, '');
    else el.setAttribute(k, String(v));
  }
  for (const c of children) if (c !== null && c !== undefined && c !== false) el.append(c);
  return el;
}

export function base64ToBytes(b64: string): Uint8Array {
  const bin = atob(b64);
  const out = new Uint8Array(bin.length);
  for (let i = 0; i < bin.length; i++) out[i] = bin.charCodeAt(i);
  return out;
}

export function bytesToBase64(bytes: Uint8Array): string {
  let s = '';
  const chunk = 0x8000;
  for (let i = 0; i < bytes.length; i += chunk) s += String.fromCharCode(...bytes.subarray(i, i + chunk));
  return btoa(s);
}

/** base64 little-endian float32 → Float32Array (the `map_f32` of a design reply). */
export function decodeF32(b64: string): Float32Array {
  const bytes = base64ToBytes(b64);
  const n = bytes.length >> 2;
  const out = new Float32Array(n);
  const dv = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  for (let i = 0; i < n; i++) out[i] = dv.getFloat32(i * 4, true);
  return out;
}

/** Offers `bytes` as a download named `name`. */
export function download(name: string, mime: string, bytes: Uint8Array): void {
  const blob = new Blob([bytes as BlobPart], { type: mime || 'application/octet-stream' });
  const url = URL.createObjectURL(blob);
  const a = h('a', { href: url, download: name });
  document.body.append(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(url), 10000);
}

export function isoNow(): string {
  return new Date().toISOString();
}

export function fmt(x: number | undefined | null, digits = 2): string {
  return x === undefined || x === null || !Number.isFinite(x) ? '–' : x.toFixed(digits);
}

/** p-quantile of a sample (linear interpolation between order statistics). */
export function quantile(xs: number[], p: number): number {
  if (!xs.length) return NaN;
  const s = [...xs].sort((a, b) => a - b);
  const pos = (s.length - 1) * p;
  const lo = Math.floor(pos);
  const hi = Math.ceil(pos);
  return s[lo] + (s[hi] - s[lo]) * (pos - lo);
}

/**
 * Test hook, built only in the test build (__TEXEL_TEST_HOOKS__, env.d.ts):
 * small counters and timing samples the browser tests read as
 * window.__texelStats. Every write sits behind `if (__TEXEL_TEST_HOOKS__)`,
 * so the production bundle has none of it.
 */
export interface TexelStats {
  designsSent: number;
  designsDrawn: number;
  sliderToRedrawMs: number[];
  pointerToAckMs: number[];
  feelMovesSent: number;
  feelAcks: number;
  lastEncodedBytes: number | null;
  lastMapChecksum: number | null;
  lastHistChecksum: number | null;
}

export const stats: TexelStats = {
  designsSent: 0,
  designsDrawn: 0,
  sliderToRedrawMs: [],
  pointerToAckMs: [],
  feelMovesSent: 0,
  feelAcks: 0,
  lastEncodedBytes: null,
  lastMapChecksum: null,
  lastHistChecksum: null,
};
if (__TEXEL_TEST_HOOKS__) (window as unknown as { __texelStats: TexelStats }).__texelStats = stats;

/** A cheap order-sensitive checksum so tests can tell that a plotted series changed. */
export function checksum(xs: ArrayLike<number>): number {
  let s = 0;
  const step = Math.max(1, Math.floor(xs.length / 4096));
  for (let i = 0; i < xs.length; i += step) s = (s * 31 + Math.round((xs[i] || 0) * 1e6)) % 2147483647;
  return s;
}
