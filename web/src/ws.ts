// The one WebSocket client of the page (docs/studio.md): numbered requests
// whose replies resolve promises, fire-and-forget messages (finger samples),
// listeners by reply type, and reconnection with backoff.
//
// Coalescing. The service answers only the newest of a client's queued
// `design` jobs (latest wins), so an older request may never get a reply.
// Requests sent with a `lane` are therefore settled as superseded (resolved
// with null) as soon as a reply to a *newer* request of the same lane arrives.
//
// Types. Requests, their bodies and their replies are the ones generated from
// docs/schema/studio-messages.schema.json (generated/messages.ts): a key the
// schema does not list, or a reply field it does not have, fails tsc. The
// same client runs in the page and in the feel worker (feel-worker.ts).

import type { Body, Replies, RequestType, ServerMessage, ServerMessages } from './generated/messages';

export class StudioError extends Error {
  constructor(
    public code: string,
    message: string,
    /** Why the token rule refused an answer (error replies with code conflict; docs/studio.md). */
    public reason?: string,
  ) {
    super(message);
    this.name = 'StudioError';
  }
}

type Listener = (msg: ServerMessage) => void;

interface Pending {
  resolve: (v: ServerMessage | null) => void;
  reject: (e: Error) => void;
  lane?: string;
  timer?: ReturnType<typeof setTimeout>;
}

export interface RequestOptions {
  lane?: string;
  timeoutMs?: number;
}

export type ConnectionState = 'connecting' | 'open' | 'closed';

export class StudioClient {
  private ws: WebSocket | null = null;
  private nextId = 1;
  private pending = new Map<number, Pending>();
  private listeners = new Map<string, Set<Listener>>();
  private stateListeners = new Set<(s: ConnectionState) => void>();
  private openWaiters: (() => void)[] = [];
  private backoffMs = 250;
  state: ConnectionState = 'connecting';

  constructor(private url: string) {
    this.connect();
  }

  private setState(s: ConnectionState): void {
    this.state = s;
    for (const l of this.stateListeners) l(s);
  }

  private connect(): void {
    this.setState('connecting');
    const ws = new WebSocket(this.url);
    this.ws = ws;
    ws.onopen = () => {
      this.backoffMs = 250;
      this.setState('open');
      const waiters = this.openWaiters;
      this.openWaiters = [];
      for (const w of waiters) w();
    };
    ws.onmessage = (ev) => this.receive(ev.data);
    ws.onclose = () => {
      if (this.ws !== ws) return;
      this.ws = null;
      // Replies to requests in flight are lost with the connection.
      for (const [id, p] of this.pending) {
        if (p.timer) clearTimeout(p.timer);
        p.reject(new StudioError('disconnected', 'connection to the studio closed'));
        this.pending.delete(id);
      }
      this.setState('closed');
      const delay = this.backoffMs;
      this.backoffMs = Math.min(this.backoffMs * 2, 4000);
      setTimeout(() => this.connect(), delay);
    };
  }

  private receive(data: unknown): void {
    if (typeof data !== 'string') return;
    let msg: ServerMessage;
    try {
      msg = JSON.parse(data) as ServerMessage;
    } catch {
      return;
    }
    if (!msg || typeof msg.type !== 'string') return;
    if (typeof msg.id === 'number' && this.pending.has(msg.id)) {
      const p = this.pending.get(msg.id)!;
      this.pending.delete(msg.id);
      if (p.timer) clearTimeout(p.timer);
      if (p.lane) {
        for (const [oid, o] of this.pending)
          if (o.lane === p.lane && oid < msg.id) {
            this.pending.delete(oid);
            if (o.timer) clearTimeout(o.timer);
            o.resolve(null);
          }
      }
      if (msg.type === 'error') {
        p.reject(new StudioError(msg.code, msg.message, msg.reason));
      } else {
        p.resolve(msg);
      }
    }
    const ls = this.listeners.get(msg.type);
    if (ls) for (const l of ls) l(msg);
  }

  /** Resolves when the socket is open. */
  ready(): Promise<void> {
    if (this.state === 'open') return Promise.resolve();
    return new Promise((r) => this.openWaiters.push(r));
  }

  /** Sends a request and resolves with its reply (null if superseded in its lane). */
  async request<K extends RequestType>(type: K, body: Body<K>, opts: RequestOptions = {}): Promise<Replies[K] | null> {
    await this.ready();
    const id = this.nextId++;
    return new Promise<Replies[K] | null>((resolve, reject) => {
      const p: Pending = { resolve: resolve as (v: ServerMessage | null) => void, reject, lane: opts.lane };
      if (opts.timeoutMs)
        p.timer = setTimeout(() => {
          this.pending.delete(id);
          reject(new StudioError('timeout', `${type}: no reply within ${opts.timeoutMs} ms`));
        }, opts.timeoutMs);
      this.pending.set(id, p);
      this.ws!.send(JSON.stringify({ type, id, ...body }));
    });
  }

  /** Like request() but for replies that must arrive (throws when superseded). */
  async call<K extends RequestType>(type: K, body: Body<K>, timeoutMs = 60000): Promise<Replies[K]> {
    const r = await this.request(type, body, { timeoutMs });
    if (r === null) throw new StudioError('superseded', `${type} was superseded`);
    return r;
  }

  /** Fire and forget; dropped while disconnected (finger samples are perishable). */
  send<K extends RequestType>(type: K, body: Body<K>): boolean {
    if (!this.ws || this.state !== 'open') return false;
    this.ws.send(JSON.stringify({ type, ...body }));
    return true;
  }

  on<K extends keyof ServerMessages>(type: K, l: (msg: ServerMessages[K]) => void): () => void {
    let s = this.listeners.get(type);
    if (!s) this.listeners.set(type, (s = new Set()));
    s.add(l as Listener);
    return () => s!.delete(l as Listener);
  }

  onState(l: (s: ConnectionState) => void): () => void {
    this.stateListeners.add(l);
    return () => this.stateListeners.delete(l);
  }
}

let client: StudioClient | null = null;

/** /ws of the serving origin (the page's, or the worker's: the same). */
export function studioUrl(): string {
  const proto = location.protocol === 'https:' ? 'wss:' : 'ws:';
  return `${proto}//${location.host}/ws`;
}

/** The page's client, connected to /ws of the serving origin. */
export function studio(): StudioClient {
  if (!client) client = new StudioClient(studioUrl());
  return client;
}
