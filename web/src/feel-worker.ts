// The finger's own connection: a worker that sends each finger sample the
// moment the page posts it and time-stamps the feel.ack as it arrives,
// whatever the page's main thread is doing (after a pointer event Chromium
// renders a frame first, which would otherwise add up to a frame to every
// measured ack). It runs the page's one WebSocket client (ws.ts) on a
// connection of its own. Times are absolute (timeOrigin + now), so the
// page's and the worker's clocks agree.
import { StudioClient, studioUrl } from './ws';

/** Page → worker: one finger sample. */
export interface FingerSample {
  seq: number;
  /** When the browser took the sample: the page's event timeStamp (ms, the page's clock). */
  t_ms: number;
  x_mm: number;
  touch: boolean;
  /** Earlier samples of the same pointer event, [t_ms, x_mm], oldest first. */
  coalesced?: [number, number][];
  /** When the page posted it (timeOrigin + now), for the measured ack latency. */
  t0: number;
}

/** Worker → page. */
export type FromFeelWorker = { ack: number; ms: number | null } | { dropped: number } | { error: string };

const scope = self as unknown as {
  postMessage(m: FromFeelWorker): void;
  onmessage: ((e: MessageEvent<FingerSample>) => void) | null;
};

const client = new StudioClient(studioUrl());
const sent = new Map<number, number>();
let waiting: FingerSample | null = null; // while connecting, only the newest sample (where the finger is now)

function send(m: FingerSample): boolean {
  if (sent.size > 4096) sent.clear();
  sent.set(m.seq, m.t0);
  return client.send('feel.move', { seq: m.seq, t_ms: m.t_ms, x_mm: m.x_mm, touch: m.touch, ...(m.coalesced ? { coalesced: m.coalesced } : {}) });
}

client.on('feel.ack', (m) => {
  const t = performance.timeOrigin + performance.now();
  const t0 = sent.get(m.seq);
  sent.delete(m.seq);
  scope.postMessage({ ack: m.seq, ms: t0 === undefined ? null : t - t0 });
});
client.on('error', (m) => scope.postMessage({ error: m.message }));
client.onState((s) => {
  if (s !== 'open' || !waiting) return;
  const m = waiting;
  waiting = null;
  send(m);
});

scope.onmessage = (e) => {
  const m = e.data;
  if (client.state === 'open' && send(m)) return;
  if (waiting) scope.postMessage({ dropped: waiting.seq });
  waiting = m;
};
