// Experimenter view (#/experimenter): start or resume a protocol for a
// participant code (optionally simulated); follow the running session live
// (progress with times, the staircase track with its reversals, correctness
// per trial); the stored sessions with their dates and states; exports (CSV,
// MATLAB .mat, the analysis figures) made by the library and handed over as
// download links; and a protocol editor generated from the protocol schema,
// checked by the engine's own validation. Everything shown comes from the
// studio's messages (`experiment.list/current/trials/export/protocol/validate`);
// with a PostgreSQL store, every station's progress and shipping lag
// (`experiment.stations`).

import uPlot from 'uplot';
import 'uplot/dist/uPlot.min.css';
import { studio } from './ws';
import { h, base64ToBytes, download } from './util';
import { protocolEditor } from './protocol-editor';
import type { ExperimentListReply, ExperimentStartRequest, ExperimentStationsReply, ExportedFile, StoredSession } from './generated/messages';

/** A trial row as column → cell text (the schema's TrialCells; "" = missing). */
type TrialCells = Record<string, string | undefined>;

/** An error as the experimenter should read it: no message type in front. */
export function plain(e: unknown): string {
  const m = e instanceof Error ? e.message : String(e);
  return m.replace(/^experiment\.[a-z_]+: /, '');
}

/** "2026-11-26T18:20:01.123Z" → "2026-11-26 18:20" (local time). */
function when(iso: string): string {
  const d = new Date(iso);
  if (!iso || isNaN(d.getTime())) return '—';
  const p = (n: number) => String(n).padStart(2, '0');
  return `${d.getFullYear()}-${p(d.getMonth() + 1)}-${p(d.getDate())} ${p(d.getHours())}:${p(d.getMinutes())}`;
}

function duration(ms: number): string {
  if (!isFinite(ms) || ms < 0) return '—';
  if (ms < 60000) return `${(ms / 1000).toFixed(ms < 10000 ? 1 : 0)} s`;
  const s = Math.round(ms / 1000);
  const m = Math.floor(s / 60);
  if (m < 60) return `${m} min ${s % 60} s`;
  return `${Math.floor(m / 60)} h ${m % 60} min`;
}

type State = StoredSession['state'];
/** A stored session's state: the library's word (session_state.hpp), which the service sets for the session it holds. */
function stateOf(s: StoredSession, _activeId: number | null): State {
  return s.state;
}

const num = (c: string | undefined) => (c === undefined || c === '' ? NaN : Number(c));

/** The live track: the block's adaptive variable over its trials, reversals and correctness marked. */
class Track {
  readonly el: HTMLElement;
  private u: uPlot | null = null;
  private host: HTMLElement;
  private caption: HTMLElement;
  constructor() {
    this.host = h('div', { class: 'plot', 'data-testid': 'staircase-plot', role: 'img', 'aria-label': 'Staircase track' });
    this.caption = h('p', { class: 'plot-caption', 'data-testid': 'staircase-caption' });
    this.el = h('div', { class: 'track' }, this.host, this.caption);
  }
  /** Draws the last block with an adaptive variable; returns false if there is none. */
  draw(rows: TrialCells[]): boolean {
    const adaptive = rows.filter((r) => r.variable && isFinite(num(r.intensity)));
    if (!adaptive.length) {
      this.el.hidden = true;
      return false;
    }
    this.el.hidden = false;
    const block = adaptive[adaptive.length - 1].block;
    const rs = adaptive.filter((r) => r.block === block);
    const x = rs.map((r) => num(r.trial_in_block) + 1);
    const y = rs.map((r) => num(r.intensity));
    const pick = (f: (r: TrialCells) => boolean) => rs.map((r, i) => (f(r) ? y[i] : null));
    const data: uPlot.AlignedData = [x, y, pick((r) => r.correct === '1'), pick((r) => r.correct === '0'), pick((r) => r.reversal === '1' || r.reversal === 'true')];
    const variable = rs[0].variable ?? '';
    const reversals = rs.filter((r) => r.reversal === '1' || r.reversal === 'true').length;
    const lastNext = num(rs[rs.length - 1].next_intensity);
    this.host.setAttribute('aria-label', `Staircase track of block ${block}: ${variable} over ${rs.length} trials, ${reversals} reversals`);
    this.caption.textContent = `Block ${block}: ${variable} per trial (${rs.length} trials, ${reversals} reversals${isFinite(lastNext) ? `, next ${lastNext}` : ''}). Green: correct, red: wrong, ring: reversal.`;
    const pts = (fill: string, size = 8) => ({ show: true, size, fill, stroke: fill });
    if (!this.u || this.u.series[1].label !== variable) {
      this.u?.destroy();
      this.u = new uPlot(
        {
          width: Math.max(320, this.host.clientWidth || 640),
          height: 220,
          scales: { x: { time: false } },
          legend: { live: false },
          axes: [{ label: 'trial in block', incrs: [1, 2, 5, 10, 20, 50, 100, 200, 500] }, { label: variable }],
          series: [
            {},
            { label: variable, stroke: '#2a6fdb', width: 1.5 },
            { label: 'correct', stroke: '#1a7f37', paths: () => null, points: pts('#1a7f37') },
            { label: 'wrong', stroke: '#b3261e', paths: () => null, points: pts('#b3261e') },
            { label: 'reversal', stroke: '#1b1f24', paths: () => null, points: { show: true, size: 14, fill: 'transparent', stroke: '#1b1f24', width: 1.5 } },
          ],
        },
        data,
        this.host,
      );
    } else this.u.setData(data);
    return true;
  }
}

export function mountExperimenter(root: HTMLElement): void {
  const client = studio();
  const status = h('div', { class: 'status', role: 'status', 'aria-live': 'polite', 'data-testid': 'experimenter-status' });
  const say = (text: string, error = false) => {
    status.textContent = text;
    status.classList.toggle('error', error);
  };
  const protoSel = h('select', { id: 'protocol', 'data-testid': 'protocol' }) as HTMLSelectElement;
  // Browsers compile `pattern` with the RegExp `v` flag, where a literal `-`
  // in a class must be escaped: unescaped, the pattern is invalid and silently
  // ignored (Chromium logs a console error, Firefox raises a page error on
  // every validity check), so any participant id would pass the form.
  const participant = h('input', { id: 'participant', 'data-testid': 'participant', placeholder: 'S01', pattern: '[A-Za-z0-9._\\-]{1,64}', required: true, autocomplete: 'off' }) as HTMLInputElement;
  const simulate = h('input', { id: 'simulate', 'data-testid': 'simulate', placeholder: 'e.g. default, or target=4sin (blank: a person answers)', autocomplete: 'off' }) as HTMLInputElement;
  const resume = h('input', { type: 'checkbox', id: 'resume', 'data-testid': 'resume' }) as HTMLInputElement;
  const active = h('div', { class: 'active', 'data-testid': 'active-session', 'aria-live': 'polite' });
  const sessionsBody = h('tbody', {});
  const shownRows = new Map<number, { key: string; el: HTMLElement }>();
  const openLink = h('a', { href: '#/participant', target: '_blank', rel: 'noopener', class: 'button', 'data-testid': 'open-participant' }, 'Open the participant screen');
  let list: ExperimentListReply | null = null;
  // Stations (PostgreSQL store only): hidden while the store is one SQLite file.
  const stationsBody = h('tbody', {});
  const stationsNote = h('p', { class: 'hint', 'data-testid': 'stations-note' });
  const stationsSection = h(
    'section',
    { 'aria-label': 'Stations', 'data-testid': 'stations', hidden: true },
    h('h2', {}, 'Stations'),
    stationsNote,
    h(
      'table',
      {},
      h('thead', {}, h('tr', {}, ...['Station', 'Host', 'Trials stored', 'On the server', 'Sessions', 'Shipping lag', 'Last heard'].map((t) => h('th', {}, t)))),
      stationsBody,
    ),
  );

  function seconds(s: number): string {
    return s < 1 ? `${Math.round(s * 1000)} ms` : s < 120 ? `${s.toFixed(1)} s` : duration(s * 1000);
  }

  async function refreshStations(): Promise<void> {
    let r: ExperimentStationsReply;
    try {
      r = await client.call('experiment.stations', {}, 15000);
    } catch {
      return; // the sessions' refresh reports errors
    }
    stationsSection.hidden = !r.multi_station;
    if (!r.multi_station) return;
    const me = r.this_station;
    const notes: string[] = [];
    if (me) {
      notes.push(me.connected ? `This studio is station ${me.station}: ${me.trials_shipped} of ${me.trials_local} trials on the server.`
        : `This studio is station ${me.station}, running on its journal: the server is not reachable (${me.error}).`);
      notes.push(...me.conflicts.map((c) => `Conflict: ${c}`));
    }
    if (r.server_error) notes.push(`Stations unknown: ${r.server_error}`);
    stationsNote.textContent = notes.join(' ');
    stationsBody.replaceChildren(
      ...r.stations.map((st) =>
        h(
          'tr',
          { 'data-testid': `station-${st.station}` },
          h('td', {}, st.station),
          h('td', {}, st.host),
          h('td', {}, String(st.trials_local)),
          h('td', {}, String(st.trials_shipped)),
          h('td', {}, String(st.sessions) + (st.completions_pending ? ` (${st.completions_pending} completion${st.completions_pending > 1 ? 's' : ''} waiting)` : '')),
          h('td', {}, st.trials_local > st.trials_shipped ? seconds(st.lag_s) : 'none'),
          h('td', {}, `${seconds(st.last_report_s)} ago`),
        ),
      ),
    );
  }

  async function start(protocol: ExperimentStartRequest['protocol'], code: string, resumeIt: boolean, sim: string): Promise<void> {
    const name = typeof protocol === 'string' ? protocol : String(protocol.name ?? 'the edited protocol');
    say(`Starting ${name} for ${code}…`);
    try {
      const body: Omit<ExperimentStartRequest, 'type' | 'id'> = { protocol, participant: code };
      if (resumeIt) body.resume = true;
      if (sim) body.simulate = sim;
      await client.call('experiment.start', body, 120000);
      say(`${name} ${resumeIt ? 'resumed' : 'running'} for ${code}`);
      watched = null;
    } catch (e) {
      say(plain(e), true);
    }
    await refresh();
  }

  const form = h(
    'form',
    { class: 'controls', 'aria-label': 'Start a session' },
    h('div', { class: 'ctl' }, h('label', { for: 'protocol' }, 'Protocol'), protoSel),
    h('div', { class: 'ctl' }, h('label', { for: 'participant' }, 'Participant code'), participant),
    h('div', { class: 'ctl' }, h('label', { for: 'simulate' }, 'Simulate (optional)'), simulate),
    h('label', { class: 'inline' }, resume, ' Resume an unfinished session'),
    h('div', { class: 'btn-row' }, h('button', { type: 'submit', class: 'primary', 'data-testid': 'start' }, 'Start')),
  );
  form.addEventListener('submit', (e) => {
    e.preventDefault();
    if (!participant.value.trim() || !participant.checkValidity()) {
      participant.focus();
      say('Enter a participant code: 1 to 64 letters, digits, dots, dashes or underscores.', true);
      return;
    }
    void start(protoSel.value, participant.value.trim(), resume.checked, simulate.value.trim());
  });

  // Stop: the session is closed for now (writer lock released) and resumes
  // later from the sessions table. Pause: the session stays open, every
  // participant screen shows "Please wait" and the trial's clock stops until
  // Continue (docs/studio.md, the token rule).
  async function stop(): Promise<void> {
    try {
      const finished = active.dataset.state === 'experiment.finished';
      await client.call('experiment.stop', {}, 30000);
      say(finished ? 'Session closed.' : 'Session stopped: resume it from the sessions table.');
    } catch (e) {
      say(plain(e), true);
    }
    await refresh();
  }
  const stopBtn = h('button', { type: 'button', 'data-testid': 'stop', onclick: () => void stop() }, 'Stop');
  async function pauseOrContinue(): Promise<void> {
    const paused = active.dataset.state === 'experiment.suspended';
    try {
      await client.call(paused ? 'experiment.resume' : 'experiment.suspend', {}, 30000);
      say(paused ? 'Session continues: the participant sees the same trial.' : 'Session paused: the participant sees "Please wait".');
    } catch (e) {
      say(plain(e), true);
    }
    await refresh();
  }
  const pauseBtn = h('button', { type: 'button', 'data-testid': 'pause', onclick: () => void pauseOrContinue() }, 'Pause');

  // Sessions started with a simulate spec can be answered by the engine's
  // simulated participant (experiment.answer {trial, simulated: true}).
  let simulating = false;
  const simulateBtn = h('button', { type: 'button', 'data-testid': 'simulate-run' }, 'Run the simulated participant') as HTMLButtonElement;
  simulateBtn.addEventListener('click', async () => {
    simulating = !simulating;
    simulateBtn.textContent = simulating ? 'Pause the simulation' : 'Run the simulated participant';
    while (simulating && document.body.contains(root)) {
      try {
        const cur = await client.call('experiment.current', {}, 30000);
        if (cur.type !== 'experiment.question') break;
        await client.call('experiment.answer', { trial: cur.question.trial, simulated: true }, 60000);
      } catch (e) {
        say(plain(e), true);
        break;
      }
    }
    simulating = false;
    simulateBtn.textContent = 'Run the simulated participant';
    await refresh();
  });

  // ---- the session followed: progress with times, track, trials
  let watched: number | null = null; // a session picked in the table; null = the running one
  let shownKey = '';
  let lastShown: number | null = null;
  const track = new Track();
  const timesEl = h('p', { 'data-testid': 'session-times' });
  const trialsBody = h('tbody', {});
  const detailTitle = h('h3', { 'data-testid': 'detail-title' });
  const detail = h(
    'section',
    { class: 'detail', 'data-testid': 'session-detail', 'aria-label': 'Session details', hidden: true },
    h('h2', {}, 'Session details'),
    detailTitle,
    timesEl,
    track.el,
    h(
      'div',
      { class: 'trials-scroll', tabindex: 0, role: 'region', 'aria-label': 'Answered trials' },
      h('table', { class: 'sessions trials', 'data-testid': 'trials' }, h('thead', {}, h('tr', {}, ...['Trial', 'Block', 'Value', 'Answer', 'Reaction time', 'Answered at'].map((c) => h('th', { scope: 'col' }, c)))), trialsBody),
    ),
  );

  async function showSession(id: number, info: StoredSession): Promise<void> {
    const key = JSON.stringify([id, info.trials_done, info.updated_at, info.status, stateOf(info, list?.active?.id ?? null)]);
    if (key === shownKey) return;
    const r = await client.call('experiment.trials', { session: id }, 30000);
    shownKey = key;
    lastShown = id;
    const rows = r.rows as TrialCells[];
    detail.hidden = false;
    const state = stateOf(r.session, list?.active?.id ?? null);
    detailTitle.textContent = `Session ${id}: ${r.session.participant}, ${r.session.protocol} (${state})`;
    const start = Date.parse(r.session.created_at);
    const end = state === 'running' ? Date.now() : Date.parse(r.session.updated_at);
    const answered = rows.map((x) => Date.parse(x.answered_at ?? '')).filter((t) => isFinite(t));
    const gaps = answered.slice(1).map((t, i) => t - answered[i]);
    const rts = rows.map((x) => num(x.rt_ms)).filter((v) => isFinite(v));
    const median = (v: number[]) => (v.length ? [...v].sort((a, b) => a - b)[Math.floor(v.length / 2)] : NaN);
    const correct = rows.filter((x) => x.correct === '1').length;
    const scored = rows.filter((x) => x.correct === '1' || x.correct === '0').length;
    timesEl.textContent = [
      `${rows.length}${r.session.trials_planned > 0 ? ` of ${r.session.trials_planned}` : ''} trials answered`,
      `started ${when(r.session.created_at)}`,
      `${state === 'running' ? 'running for' : 'lasted'} ${duration(end - start)}`,
      `median reaction time ${duration(median(rts))}`,
      gaps.length ? `median time between answers ${duration(median(gaps))}` : '',
      scored ? `${correct} of ${scored} correct` : '',
    ]
      .filter(Boolean)
      .join(' · ');
    track.draw(rows);
    const shown = rows.slice(-200).reverse();
    trialsBody.replaceChildren(
      ...shown.map((x) => {
        const c = x.correct === '1' ? 'correct' : x.correct === '0' ? 'wrong' : '—';
        const value = isFinite(num(x.intensity)) ? `${x.intensity}${x.reversal === '1' || x.reversal === 'true' ? ' (reversal)' : ''}` : '—';
        return h(
          'tr',
          { 'data-trial': x.trial ?? '' },
          h('td', {}, x.trial_number || String(num(x.trial) + 1)),
          h('td', {}, `${x.block ?? ''}${x.practice === '1' || x.practice === 'true' ? ' (practice)' : ''}`),
          h('td', {}, value),
          h('td', { class: `answer ${c}`, 'data-testid': 'trial-correct' }, c === '—' ? (x.response ?? '—') : `${x.response ?? ''} (${c})`),
          h('td', {}, duration(num(x.rt_ms))),
          h('td', {}, when(x.answered_at ?? '')),
        );
      }),
    );
    root.dataset.trialsShown = String(rows.length);
  }

  function row(s: StoredSession, state: State): HTMLElement {
    const who = `session ${s.id} (${s.participant}, ${s.protocol})`;
    const actions = h('div', { class: 'btn-row' });
    if (state === 'stopped')
      actions.append(h('button', { type: 'button', 'aria-label': `Resume ${who}`, onclick: () => void start(s.protocol, s.participant, true, '') }, 'Resume'));
    if (state === 'running') actions.append(h('button', { type: 'button', 'aria-label': `Stop ${who}`, onclick: () => void stop() }, 'Stop'));
    actions.append(
      h('button', { type: 'button', 'aria-label': `Show ${who}`, 'data-testid': 'show-session', onclick: () => ((watched = s.id), (shownKey = ''), void refresh()) }, 'Show'),
      h('button', { type: 'button', 'aria-label': `Download ${who} as CSV`, onclick: () => void exportAs('csv', s.id) }, 'CSV'),
    );
    return h(
      'tr',
      { 'data-session': s.id, 'data-finished': String(s.finished), 'data-state': state },
      h('td', {}, String(s.id)),
      h('td', {}, s.participant),
      h('td', {}, s.protocol),
      h('td', { class: 'progress-cell' }, s.trials_planned > 0 ? `${s.trials_done} / ${s.trials_planned}` : `${s.trials_done} (adaptive)`),
      h('td', {}, when(s.created_at)),
      h('td', {}, s.finished ? when(s.updated_at) : '—'),
      h('td', { 'data-testid': 'session-state' }, state),
      h('td', {}, actions),
    );
  }

  async function refresh(): Promise<void> {
    let l: ExperimentListReply;
    try {
      l = await client.call('experiment.list', {}, 15000);
    } catch (e) {
      say(plain(e), true);
      return;
    }
    list = l;
    const keep = protoSel.value;
    const options = l.protocols.map((p) => h('option', { value: p.name }, p.study ? `${p.name} (${p.study})` : p.name));
    if (protoSel.options.length !== options.length) {
      protoSel.replaceChildren(...options);
      templateSel.replaceChildren(...options.map((o) => o.cloneNode(true)));
    }
    if (keep) protoSel.value = keep;
    const activeId = l.active?.id ?? null;
    // Rows are rebuilt only when their session changed: the view refreshes
    // every 2 s, and a button replaced under the pointer loses its click.
    const rows = l.sessions.map((s) => {
      const state = stateOf(s, activeId);
      const key = JSON.stringify([s, state]);
      const old = shownRows.get(s.id);
      if (old && old.key === key) return old.el;
      const el = row(s, state);
      shownRows.set(s.id, { key, el });
      return el;
    });
    if (rows.length !== sessionsBody.children.length || rows.some((el, k) => sessionsBody.children[k] !== el)) sessionsBody.replaceChildren(...rows);
    if (l.active) {
      let progress = '';
      try {
        const cur = await client.call('experiment.current', {}, 15000);
        if (cur.type !== 'experiment.idle')
          progress = cur.progress.planned > 0 ? `${cur.progress.done} / ${cur.progress.planned} trials` : `${cur.progress.done} trials (adaptive)`;
        const finished = cur.type === 'experiment.finished';
        if (finished) {
          progress += ', finished';
          say(`${l.active.protocol} finished for ${l.active.participant}`);
        }
        // A finished session still holds the participant screen until it is closed.
        stopBtn.textContent = finished ? 'Close the session' : 'Stop';
        pauseBtn.textContent = cur.type === 'experiment.suspended' ? 'Continue' : 'Pause';
        pauseBtn.hidden = finished;
        if (cur.type === 'experiment.suspended') progress += ', paused';
        active.dataset.state = cur.type;
      } catch {
        /* the list is enough */
      }
      const simulated = l.active.simulated;
      const key = JSON.stringify([l.active.id, l.active.participant, l.active.protocol, progress, simulated]);
      if (active.dataset.key !== key) {
        active.dataset.key = key;
        active.replaceChildren(
          h('strong', {}, `Session ${l.active.id}: ${l.active.participant}, ${l.active.protocol}`),
          ' ',
          h('span', { 'data-testid': 'active-progress' }, progress),
          ' ',
          pauseBtn,
          ' ',
          stopBtn,
          ' ',
          openLink,
          simulated ? simulateBtn : '',
        );
      }
    } else if (active.dataset.state !== 'idle') {
      active.dataset.state = 'idle';
      active.dataset.key = '';
      active.replaceChildren(h('span', {}, 'No session is running.'), ' ', openLink);
    }
    // The session picked in the table, else the running one, else the one shown last.
    const followed = l.sessions.find((s) => s.id === (watched ?? activeId ?? lastShown));
    if (followed) await showSession(followed.id, followed).catch((e) => say(plain(e), true));
    root.dataset.ready = 'true';
  }

  // ---- exports: the library writes them, the page offers them as links
  const exportsOut = h('div', { class: 'exports', 'data-testid': 'exports', 'aria-live': 'polite' });
  const urls: string[] = [];
  function link(f: ExportedFile): HTMLAnchorElement {
    const url = URL.createObjectURL(new Blob([base64ToBytes(f.data_base64) as BlobPart], { type: f.mime }));
    urls.push(url);
    return h('a', { href: url, download: f.name, class: 'button', 'data-testid': 'export-link' }, `${f.name} (${(f.bytes / 1024).toFixed(1)} kB)`) as HTMLAnchorElement;
  }
  async function exportAs(as: 'csv' | 'mat' | 'figures', session?: number): Promise<void> {
    const what = session ? `session ${session}` : 'all sessions';
    say(`Exporting ${what}…`);
    try {
      const r = await client.call('experiment.export', session ? { as, session } : { as }, 180000);
      while (urls.length) URL.revokeObjectURL(urls.pop()!);
      const items = r.files.map((f) => {
        const a = link(f);
        return f.mime.startsWith('image/') ? h('figure', {}, h('img', { src: a.href, alt: `Analysis figure ${f.name}` }), h('figcaption', {}, a)) : a;
      });
      exportsOut.replaceChildren(
        h('p', {}, `${as === 'figures' ? `${r.files.length} figures` : as.toUpperCase()} of ${what} (${r.trials} trials):`),
        h('div', { class: as === 'figures' ? 'figures' : 'btn-row' }, ...items),
        r.summary ? h('details', {}, h('summary', {}, 'Analysis summary'), h('pre', {}, r.summary)) : '',
      );
      say(r.files.length ? `Ready: ${r.files.map((f) => f.name).join(', ')}` : `No figures for ${what}: too few answered trials.`);
    } catch (e) {
      say(plain(e), true);
    }
  }

  // ---- protocol editor
  const editor = protocolEditor();
  const templateSel = h('select', { id: 'template', 'data-testid': 'template' }) as HTMLSelectElement;
  const editorStatus = h('p', { class: 'status', role: 'status', 'aria-live': 'polite', 'data-testid': 'editor-status' });
  const editorSay = (text: string, error = false) => {
    editorStatus.textContent = text;
    editorStatus.classList.toggle('error', error);
  };
  async function loadTemplate(): Promise<void> {
    try {
      const r = await client.call('experiment.protocol', { name: templateSel.value }, 30000);
      editor.load(r.protocol as Record<string, never>);
      editorSay(`Loaded ${r.file}. Change what you need, then check it.`);
    } catch (e) {
      editorSay(plain(e), true);
    }
  }
  async function validate(): Promise<Record<string, unknown> | null> {
    const v = editor.value();
    editor.clearErrors();
    if ('error' in v) {
      editorSay(v.error, true);
      return null;
    }
    try {
      const r = await client.call('experiment.validate', { protocol: v.protocol }, 30000);
      editorSay(`Valid: ${r.name} (${r.study}), ${r.trials_planned > 0 ? `${r.trials_planned} trials` : 'adaptive length'}.`);
      return v.protocol;
    } catch (e) {
      // At the field the engine names (1-based blocks, as the form's legends), and here.
      const shown = editor.showError(plain(e));
      editorSay(shown.atField ? `${shown.text} (shown at the field)` : shown.text, true);
      return null;
    }
  }
  const editorSection = h(
    'section',
    { 'aria-label': 'Protocol editor', class: 'editor' },
    h('h2', {}, 'Protocol editor'),
    h('p', { class: 'hint' }, 'Start from a shipped protocol, change its fields, check it with the engine, then start it for the participant code above or download it.'),
    h('div', { class: 'ctl-row' }, h('label', { for: 'template' }, 'Template'), templateSel, h('button', { type: 'button', 'data-testid': 'load-template', onclick: () => void loadTemplate() }, 'Load')),
    editor.el,
    h(
      'div',
      { class: 'btn-row' },
      h('button', { type: 'button', 'data-testid': 'validate', onclick: () => void validate() }, 'Check'),
      h('button', {
        type: 'button',
        'data-testid': 'start-edited',
        onclick: async () => {
          const p = await validate();
          if (!p) return;
          if (!participant.value.trim() || !participant.checkValidity()) {
            editorSay('Enter a participant code under "Start a protocol" first.', true);
            participant.focus();
            return;
          }
          await start(p as ExperimentStartRequest['protocol'], participant.value.trim(), false, simulate.value.trim());
        },
      }, 'Start for the participant code above'),
      h('button', {
        type: 'button',
        'data-testid': 'download-protocol',
        onclick: async () => {
          const p = await validate();
          if (!p) return;
          download(`${String(p.name)}.json`, 'application/json', new TextEncoder().encode(JSON.stringify(p, null, 2) + '\n'));
        },
      }, 'Download .json'),
    ),
    editorStatus,
  );

  root.replaceChildren(
    h(
      'div',
      { class: 'experimenter' },
      h('section', { 'aria-label': 'Start a protocol' }, h('h2', {}, 'Start a protocol'), form),
      h('section', { 'aria-label': 'Active session' }, h('h2', {}, 'Active session'), active),
      detail,
      h(
        'section',
        { 'aria-label': 'Sessions' },
        h('h2', {}, 'Sessions'),
        h(
          'table',
          { class: 'sessions', 'data-testid': 'sessions' },
          h('thead', {}, h('tr', {}, ...['#', 'Participant', 'Protocol', 'Trials', 'Started', 'Ended', 'State', 'Actions'].map((c) => h('th', { scope: 'col' }, c)))),
          sessionsBody,
        ),
      ),
      h(
        'section',
        { 'aria-label': 'Export' },
        h('h2', {}, 'Export all sessions'),
        h(
          'div',
          { class: 'btn-row' },
          h('button', { type: 'button', 'data-testid': 'export-csv', onclick: () => void exportAs('csv') }, 'Trials as CSV'),
          h('button', { type: 'button', 'data-testid': 'export-mat', onclick: () => void exportAs('mat') }, 'Trials as MATLAB .mat'),
          h('button', { type: 'button', 'data-testid': 'export-figures', onclick: () => void exportAs('figures') }, 'Analysis figures'),
        ),
        exportsOut,
      ),
      stationsSection,
      editorSection,
      status,
    ),
  );
  void refresh();
  void refreshStations();
  const timer = setInterval(() => {
    if (!document.body.contains(root) || !root.querySelector('.experimenter')) {
      clearInterval(timer);
      while (urls.length) URL.revokeObjectURL(urls.pop()!);
    } else {
      void refresh();
      void refreshStations();
    }
  }, 2000);
}
