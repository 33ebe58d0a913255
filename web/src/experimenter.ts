// Experimenter view (#/experimenter): shipped protocols and stored sessions
// (`experiment.list`), start or resume a protocol for a participant code
// (optionally simulated), suspend it, follow its progress, and open the
// participant screen.

import { studio } from './ws';
import { h } from './util';
import type { ExperimentListReply, ExperimentStartRequest, StoredSession } from './generated/messages';

export function mountExperimenter(root: HTMLElement): void {
  const client = studio();
  const status = h('div', { class: 'status', role: 'status', 'aria-live': 'polite', 'data-testid': 'experimenter-status' });
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

  async function start(protocol: string, code: string, resumeIt: boolean, sim: string): Promise<void> {
    status.classList.remove('error');
    status.textContent = `starting ${protocol} for ${code}…`;
    try {
      const body: Omit<ExperimentStartRequest, 'type' | 'id'> = { protocol, participant: code };
      if (resumeIt) body.resume = true;
      if (sim) body.simulate = sim;
      await client.call('experiment.start', body, 120000);
      status.textContent = `${protocol} running for ${code}`;
    } catch (e) {
      status.textContent = e instanceof Error ? e.message : String(e);
      status.classList.add('error');
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
    if (!participant.value.trim()) {
      participant.focus();
      return;
    }
    void start(protoSel.value, participant.value.trim(), resume.checked, simulate.value.trim());
  });

  const stopBtn = h('button', { type: 'button', 'data-testid': 'stop', onclick: async () => {
    try {
      await client.call('experiment.stop', {}, 30000);
      status.textContent = 'session suspended (resumable)';
    } catch (e) {
      status.textContent = e instanceof Error ? e.message : String(e);
    }
    await refresh();
  } }, 'Stop (suspend)');

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
        status.textContent = e instanceof Error ? e.message : String(e);
        break;
      }
    }
    simulating = false;
    simulateBtn.textContent = 'Run the simulated participant';
    await refresh();
  });

  function row(s: StoredSession): HTMLElement {
    const resumeBtn = s.finished
      ? h('span', {}, '')
      : h('button', { type: 'button', 'aria-label': `Resume session ${s.id} (${s.participant}, ${s.protocol})`, onclick: () => void start(s.protocol, s.participant, true, '') }, 'Resume');
    return h(
      'tr',
      { 'data-session': s.id, 'data-finished': String(s.finished) },
      h('td', {}, String(s.id)),
      h('td', {}, s.participant),
      h('td', {}, s.protocol),
      h('td', { class: 'progress-cell' }, s.trials_planned > 0 ? `${s.trials_done} / ${s.trials_planned}` : `${s.trials_done} (adaptive)`),
      h('td', { 'data-testid': 'session-state' }, s.finished ? 'finished' : 'unfinished'),
      h('td', {}, resumeBtn),
    );
  }

  async function refresh(): Promise<void> {
    let l: ExperimentListReply;
    try {
      l = await client.call('experiment.list', {}, 15000);
    } catch (e) {
      status.textContent = e instanceof Error ? e.message : String(e);
      return;
    }
    const keep = protoSel.value;
    protoSel.replaceChildren(...l.protocols.map((p) => h('option', { value: p.name }, p.study ? `${p.name} (${p.study})` : p.name)));
    if (keep) protoSel.value = keep;
    // Rows are rebuilt only when their session changed: the view refreshes
    // every 2 s, and a button replaced under the pointer loses its click.
    const rows = l.sessions.map((s) => {
      const key = JSON.stringify(s);
      const old = shownRows.get(s.id);
      if (old && old.key === key) return old.el;
      const el = row(s);
      shownRows.set(s.id, { key, el });
      return el;
    });
    if (rows.length !== sessionsBody.children.length || rows.some((el, k) => sessionsBody.children[k] !== el))
      sessionsBody.replaceChildren(...rows);
    if (l.active) {
      let progress = '';
      try {
        const cur = await client.call('experiment.current', {}, 15000);
        if (cur.type !== 'experiment.idle')
          progress = cur.progress.planned > 0 ? `${cur.progress.done} / ${cur.progress.planned} trials` : `${cur.progress.done} trials (adaptive)`;
        const finished = cur.type === 'experiment.finished';
        if (finished) {
          progress += ', finished';
          status.textContent = `${l.active.protocol} finished for ${l.active.participant}`;
        }
        // A finished session still holds the display until it is closed.
        stopBtn.textContent = finished ? 'Close the session' : 'Stop (suspend)';
        active.dataset.state = cur.type;
      } catch {
        /* list is enough */
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
    root.dataset.ready = 'true';
  }

  root.replaceChildren(
    h(
      'div',
      { class: 'experimenter' },
      h('section', { 'aria-label': 'Start a protocol' }, h('h2', {}, 'Start a protocol'), form),
      h('section', { 'aria-label': 'Active session' }, h('h2', {}, 'Active session'), active),
      h(
        'section',
        { 'aria-label': 'Sessions' },
        h('h2', {}, 'Sessions'),
        h('table', { class: 'sessions', 'data-testid': 'sessions' }, h('thead', {}, h('tr', {}, ...['#', 'Participant', 'Protocol', 'Trials', 'State', 'Actions'].map((c) => h('th', { scope: 'col' }, c)))), sessionsBody),
      ),
      status,
    ),
  );
  void refresh();
  const timer = setInterval(() => {
    if (!document.body.contains(root) || !root.querySelector('.experimenter')) clearInterval(timer);
    else void refresh();
  }, 2000);
}
