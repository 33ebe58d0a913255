// One state store per page: the page's state lives here only. Controls write
// to it (update), and one render function per page reads from it
// (subscribe), so a change from any source — a slider, an import, a match
// reply — reaches every control the same way, with no control-to-control
// syncing.
export class Store<S extends object> {
  private listeners = new Set<(s: S, prev: S) => void>();

  constructor(private state: S) {}

  get(): S {
    return this.state;
  }

  /** Replaces the state by a new object (never mutates the old one) and tells every subscriber. */
  update(patch: Partial<S> | ((s: S) => Partial<S>)): void {
    const prev = this.state;
    this.state = { ...prev, ...(typeof patch === 'function' ? patch(prev) : patch) };
    for (const l of this.listeners) l(this.state, prev);
  }

  subscribe(l: (s: S, prev: S) => void): () => void {
    this.listeners.add(l);
    return () => this.listeners.delete(l);
  }
}
