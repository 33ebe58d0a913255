// Texel Studio front end: hash routes to the three pages, one shared
// WebSocket client (ws.ts). The participant screen hides the navigation so a
// participant sees only the study.
import './style.css';
import { studio } from './ws';
import { mountDesigner } from './designer';
import { mountExperimenter } from './experimenter';
import { mountParticipant } from './participant';
import { mountSurface2d } from './surface2d';

const routes: Record<string, (root: HTMLElement) => void> = {
  designer: mountDesigner,
  experimenter: mountExperimenter,
  participant: mountParticipant,
  surface: mountSurface2d,
};

function route(): void {
  const name = location.hash.replace(/^#\/?/, '').split('?')[0] || 'designer';
  const page = routes[name] ? name : 'designer';
  const main = document.getElementById('main')!;
  // A fresh root per page: timers of the old page see it detached and stop.
  const root = document.createElement('div');
  root.className = `page page-${page}`;
  root.dataset.page = page;
  // Every page has one level-one heading naming it (for screen readers'
  // heading lists; visually the navigation says where one is). Participants
  // see the study, not the studio's page names.
  const title = page === 'participant' ? 'Study' : `${page[0].toUpperCase()}${page.slice(1)}`;
  const h1 = document.createElement('h1');
  h1.className = 'visually-hidden';
  h1.textContent = title;
  main.replaceChildren(h1, root);
  document.body.dataset.page = page;
  for (const a of document.querySelectorAll<HTMLAnchorElement>('nav a'))
    a.setAttribute('aria-current', a.dataset.route === page ? 'page' : 'false');
  document.title = page === 'participant' ? 'Study' : `Texel Studio – ${title}`;
  routes[page](root);
}

const conn = document.getElementById('connection')!;
studio().onState((s) => {
  conn.textContent = s === 'open' ? 'connected' : s === 'connecting' ? 'connecting…' : 'disconnected, retrying…';
  conn.dataset.state = s;
});

window.addEventListener('hashchange', route);
route();
