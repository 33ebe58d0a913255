// Shared helpers of the end-to-end browser tests: start the real
// `texel studio` (null backend, a fresh database, the shipped protocols) on a
// free loopback port, launch Debian's Chromium through playwright-core (never
// a downloaded browser), and always stop both — also when a test fails or
// hangs (a hard timeout kills the server).
//
// Environment (paths relative to web/ unless absolute):
//   TEXEL_BIN        texel binary            (default ../build/bin/texel)
//   TEXEL_WEB        test build of the front end (default ../build/web-test)
//   TEXEL_ARTIFACTS  screenshots, latency    (default ../build/browser-artifacts)
//   TEXEL_PROTOCOLS  shipped protocols       (default ../examples/protocols)
//   TEXEL_CHROMIUM   browser executable      (default /usr/bin/chromium)
//   TEXEL_FIREFOX    Firefox ESR executable  (default /usr/bin/firefox-esr;
//                    firefox.test.mjs only, driven by puppeteer-core over
//                    WebDriver BiDi)

import { spawn, spawnSync } from 'node:child_process';
import { mkdirSync, mkdtempSync, readFileSync, rmSync, existsSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { basename, dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';

const webDir = resolve(dirname(fileURLToPath(import.meta.url)), '..', '..');
const fromWeb = (p) => resolve(webDir, p);

export const paths = {
  bin: fromWeb(process.env.TEXEL_BIN ?? '../build/bin/texel'),
  web: fromWeb(process.env.TEXEL_WEB ?? '../build/web-test'),
  artifacts: fromWeb(process.env.TEXEL_ARTIFACTS ?? '../build/browser-artifacts'),
  protocols: fromWeb(process.env.TEXEL_PROTOCOLS ?? '../examples/protocols'),
  chromium: process.env.TEXEL_CHROMIUM ?? '/usr/bin/chromium',
  firefox: process.env.TEXEL_FIREFOX ?? '/usr/bin/firefox-esr',
};

// Flags that work on this closed network (.library/env/machines/cpp.md):
// without the background-networking ones Chromium keeps dialling out.
const CHROMIUM_FLAGS = [
  '--no-sandbox',
  '--disable-gpu',
  '--disable-quic',
  '--no-first-run',
  '--disable-background-networking',
  '--disable-component-update',
  '--disable-sync',
  '--autoplay-policy=no-user-gesture-required',
];

const live = new Set();
function killAll() {
  for (const p of live) {
    try {
      p.kill('SIGKILL');
    } catch {
      /* already gone */
    }
  }
}
process.on('exit', killAll);
for (const sig of ['SIGINT', 'SIGTERM'])
  process.on(sig, () => {
    killAll();
    process.exit(130);
  });

/**
 * Starts `texel studio --port 0` (or `port`) on a fresh database (or `db`,
 * e.g. to restart a server on the same one); resolves {url, stop, log} once
 * it printed its address.
 */
/**
 * A shipped protocol without its practice blocks (texel-length's ten untimed
 * practice trials), so the first question is a timed test trial.
 */
export function withoutPractice(name) {
  const p = JSON.parse(readFileSync(join(paths.protocols, `${name}.json`), 'utf8'));
  p.blocks = p.blocks.filter((b) => !b.practice);
  return p;
}

export async function startStudio({ hardTimeoutMs = 600_000, db = null, port = 0 } = {}) {
  for (const [what, p] of [['TEXEL_BIN', paths.bin], ['TEXEL_WEB', join(paths.web, 'index.html')]])
    if (!existsSync(p)) throw new Error(`${what}: ${p} does not exist (build it first; see web/tests/e2e/studio.mjs)`);
  const dir = mkdtempSync(join(tmpdir(), 'texel-e2e-'));
  const args = ['studio', '--port', String(port), '--web', paths.web, '--db', db ?? join(dir, 's.db'), '--backend', 'null', '--protocols', paths.protocols];
  const proc = spawn(paths.bin, args, { stdio: ['ignore', 'pipe', 'pipe'] });
  live.add(proc);
  let log = '';
  proc.stderr.on('data', (d) => (log += d));
  const hard = setTimeout(() => {
    console.error(`texel studio still running after ${hardTimeoutMs} ms: killed`);
    proc.kill('SIGKILL');
  }, hardTimeoutMs);
  hard.unref();
  const exited = new Promise((r) => proc.on('exit', (code, sig) => r({ code, sig })));

  const url = await new Promise((res, rej) => {
    let out = '';
    const timer = setTimeout(() => rej(new Error(`texel studio printed no address within 20 s; stdout: ${out} stderr: ${log}`)), 20_000);
    proc.stdout.on('data', (d) => {
      out += d;
      const m = out.match(/Texel Studio at (http:\/\/[^\s/]+\/)/);
      if (m) {
        clearTimeout(timer);
        res(m[1]);
      }
    });
    exited.then(({ code, sig }) => {
      clearTimeout(timer);
      rej(new Error(`texel studio exited (${code ?? sig}) before printing its address: ${log}`));
    });
  });

  async function stop() {
    clearTimeout(hard);
    if (proc.exitCode === null && proc.signalCode === null) {
      proc.kill('SIGTERM');
      // unref: the grace timer must not keep node alive once the server exited
      const done = await Promise.race([exited, new Promise((r) => setTimeout(() => r(null), 5000).unref())]);
      if (!done) proc.kill('SIGKILL');
      await exited;
    }
    live.delete(proc);
    rmSync(dir, { recursive: true, force: true });
  }
  return { url, stop, log: () => log, dir };
}

/** Debian's Chromium, headless. playwright-core gives every launch a fresh, empty user-data-dir. */
export async function launchBrowser() {
  return chromium.launch({ executablePath: paths.chromium, headless: true, args: CHROMIUM_FLAGS, timeout: 60_000 });
}

// Firefox preferences for this closed network, on top of puppeteer's own
// test defaults (@puppeteer/browsers: no app/add-on updates, no safe
// browsing lists, no health report): nothing that dials out by itself.
// Remote services point at a closed loopback port rather than a name, so not
// even a DNS lookup leaves the machine.
const NOWHERE = 'http://127.0.0.1:9/';
export const FIREFOX_PREFS = {
  // updates (app, add-ons, search engines, plugins/GMP, remote settings)
  'app.update.auto': false,
  'app.update.enabled': false,
  'app.update.url': NOWHERE,
  'extensions.update.enabled': false,
  'extensions.blocklist.enabled': false,
  'extensions.getAddons.cache.enabled': false,
  'extensions.systemAddon.update.enabled': false,
  'browser.search.update': false,
  'media.gmp-manager.updateEnabled': false,
  'media.gmp-manager.url': NOWHERE,
  'media.gmp-gmpopenh264.enabled': false,
  'media.gmp-widevinecdm.enabled': false,
  // Remote settings: on a release build the server pref counts only with
  // MOZ_DISABLE_NONLOCAL_CONNECTIONS=1 (set in launchFirefox, as Mozilla's
  // own test harnesses do); this dummy URL then skips all its network activity.
  'services.settings.server': 'data:,#remote-settings-dummy/v1',
  'services.settings.poll_interval': 86400 * 365,
  // telemetry, studies, normandy, messaging experiments
  'toolkit.telemetry.enabled': false,
  'toolkit.telemetry.unified': false,
  'toolkit.telemetry.archive.enabled': false,
  'toolkit.telemetry.server': NOWHERE,
  'toolkit.telemetry.shutdownPingSender.enabled': false,
  'toolkit.telemetry.firstShutdownPing.enabled': false,
  'toolkit.telemetry.newProfilePing.enabled': false,
  'toolkit.telemetry.updatePing.enabled': false,
  'toolkit.telemetry.bhrPing.enabled': false,
  'datareporting.healthreport.uploadEnabled': false,
  'datareporting.policy.dataSubmissionEnabled': false,
  'app.normandy.enabled': false,
  'app.normandy.api_url': '',
  'app.shield.optoutstudies.enabled': false,
  'messaging-system.rsexperimentloader.enabled': false,
  'browser.discovery.enabled': false,
  'browser.ping-centre.telemetry': false,
  'browser.newtabpage.activity-stream.feeds.telemetry': false,
  'browser.newtabpage.activity-stream.telemetry': false,
  'browser.newtabpage.activity-stream.feeds.snippets': false,
  'browser.newtabpage.activity-stream.feeds.section.topstories': false,
  'browser.region.update.enabled': false,
  'browser.region.network.url': '',
  'browser.search.geoip.url': '',
  // captive portal and connectivity checks
  'network.captive-portal-service.enabled': false,
  'network.connectivity-service.enabled': false,
  'captivedetect.canonicalURL': NOWHERE,
  // safe browsing (lists and download checks)
  'browser.safebrowsing.malware.enabled': false,
  'browser.safebrowsing.phishing.enabled': false,
  'browser.safebrowsing.downloads.enabled': false,
  'browser.safebrowsing.downloads.remote.enabled': false,
  'browser.safebrowsing.blockedURIs.enabled': false,
  'browser.safebrowsing.provider.google4.updateURL': '',
  'browser.safebrowsing.provider.google.updateURL': '',
  'browser.safebrowsing.provider.mozilla.updateURL': '',
  // speculative connections, DNS-over-HTTPS, proxies from the environment
  'network.prefetch-next': false,
  'network.dns.disablePrefetch': true,
  'network.http.speculative-parallel-limit': 0,
  'browser.urlbar.speculativeConnect.enabled': false,
  'network.trr.mode': 5,
  'network.proxy.type': 0,
  // the page's audio (Hear it) may start without a gesture, as with Chromium's flag
  'media.autoplay.default': 0,
  'media.autoplay.block-webaudio': false,
};

/**
 * Debian's Firefox ESR, headless, driven by puppeteer-core over WebDriver
 * BiDi (puppeteer-core never downloads a browser), with a fresh profile
 * directory and FIREFOX_PREFS. Resolves {browser, close}; `close()` always
 * ends the browser (SIGKILL after 10 s) and removes the profile, and a hard
 * timeout kills it should the test never get there. A missing Firefox is an
 * error, not a skip: `make test` installs firefox-esr.
 */
export async function launchFirefox({ hardTimeoutMs = 600_000 } = {}) {
  if (!existsSync(paths.firefox))
    throw new Error(
      `Firefox ESR not found at ${paths.firefox}: install Debian's firefox-esr (scripts/install-deps.sh, run by make test) or set TEXEL_FIREFOX`,
    );
  const { default: puppeteer } = await import('puppeteer-core');
  const profile = mkdtempSync(join(tmpdir(), 'texel-firefox-'));
  let browser;
  try {
    browser = await puppeteer.launch({
      browser: 'firefox',
      executablePath: paths.firefox,
      headless: true,
      userDataDir: profile,
      extraPrefsFirefox: FIREFOX_PREFS,
      defaultViewport: { width: 1280, height: 900 },
      timeout: 60_000,
      protocolTimeout: 60_000,
      // MOZ_DISABLE_NONLOCAL_CONNECTIONS: Firefox refuses connections to
      // anything but this machine (the studio is on 127.0.0.1).
      env: { ...process.env, MOZ_CRASHREPORTER_DISABLE: '1', MOZ_DISABLE_NONLOCAL_CONNECTIONS: '1' },
    });
  } catch (e) {
    rmSync(profile, { recursive: true, force: true });
    throw e;
  }
  const proc = browser.process();
  if (proc) live.add(proc);
  const exited = proc ? (proc.exitCode !== null ? Promise.resolve() : new Promise((r) => proc.once('exit', r))) : Promise.resolve();
  const hard = setTimeout(() => {
    console.error(`firefox still running after ${hardTimeoutMs} ms: killed`);
    proc?.kill('SIGKILL');
  }, hardTimeoutMs);
  hard.unref();
  async function close() {
    clearTimeout(hard);
    let grace;
    await Promise.race([browser.close().catch(() => {}), new Promise((r) => (grace = setTimeout(r, 10_000)))]);
    clearTimeout(grace);
    if (proc && proc.exitCode === null && proc.signalCode === null) {
      proc.kill('SIGKILL');
      await exited;
    }
    if (proc) live.delete(proc);
    rmSync(profile, { recursive: true, force: true });
  }
  return { browser, close, profile };
}

/**
 * Runs `fn({studio, browser, page, context})` against a fresh server and browser and
 * always tears both down. Page errors and console errors are collected in `errors`.
 * Every WebSocket frame the pages send and receive is recorded and, once the
 * flow passed, checked against docs/schema/studio-messages.schema.json
 * (tests/check_messages.py; the frames stay in the artifacts as ws-*.jsonl).
 */
export async function withStudio(fn, { contextOptions = {} } = {}) {
  const studio = await startStudio();
  const frames = [];
  let browser;
  let result;
  try {
    browser = await launchBrowser();
    const context = await browser.newContext({ viewport: { width: 1280, height: 900 }, acceptDownloads: true, ...contextOptions });
    context.on('page', (p) =>
      p.on('websocket', (ws) => {
        ws.on('framesent', (f) => typeof f.payload === 'string' && frames.push({ dir: 'sent', text: f.payload }));
        ws.on('framereceived', (f) => typeof f.payload === 'string' && frames.push({ dir: 'received', text: f.payload }));
      }),
    );
    const page = await context.newPage();
    const errors = [];
    page.on('pageerror', (e) => errors.push(String(e)));
    result = await fn({ studio, browser, context, page, errors });
  } finally {
    await browser?.close().catch(() => {});
    await studio.stop();
  }
  checkFrames(frames);
  return result;
}

let flows = 0;
/** Validates recorded frames with python3-jsonschema against the message schema; throws naming the first mismatches. */
export function checkFrames(frames) {
  mkdirSync(paths.artifacts, { recursive: true });
  const file = join(paths.artifacts, `ws-${basename(process.argv[1] ?? 'flow', '.test.mjs')}-${++flows}.jsonl`);
  writeFileSync(file, frames.map((f) => JSON.stringify(f)).join('\n') + '\n');
  const r = spawnSync('/usr/bin/python3', [join(webDir, 'tests', 'check_messages.py'), resolve(webDir, '..'), file], { encoding: 'utf8' });
  if (r.status !== 0) throw new Error(`messages not as docs/schema/studio-messages.schema.json says (${file}):\n${r.stdout}${r.stderr}`);
  return r.stdout;
}

export function artifact(name) {
  mkdirSync(paths.artifacts, { recursive: true });
  return join(paths.artifacts, name);
}

export async function screenshot(page, name) {
  await page.screenshot({ path: artifact(`${name}.png`), fullPage: true });
}

/** The page's test hook (web/src/util.ts: window.__texelStats). */
export function stats(page) {
  return page.evaluate(() => JSON.parse(JSON.stringify(window.__texelStats)));
}

export function quantile(xs, p) {
  if (!xs.length) return NaN;
  const s = [...xs].sort((a, b) => a - b);
  const pos = (s.length - 1) * p;
  const lo = Math.floor(pos);
  const hi = Math.ceil(pos);
  return s[lo] + (s[hi] - s[lo]) * (pos - lo);
}

/** Opens the designer and waits for its first drawn design. */
export async function openDesigner(page, url) {
  await page.goto(`${url}#/designer`);
  await page.waitForFunction(() => window.__texelStats && window.__texelStats.designsDrawn >= 1, null, { timeout: 30_000 });
}

/** Waits until the designer drew a design newer than `n` and returns the stats. */
export async function nextDraw(page, n) {
  await page.waitForFunction((k) => window.__texelStats.designsDrawn > k, n, { timeout: 30_000 });
  return stats(page);
}

/** Sets a range input as a drag would: new value, then an `input` event. */
export function setRange(page, selector, value) {
  return page.$eval(
    selector,
    (el, v) => {
      el.value = String(v);
      el.dispatchEvent(new Event('input', { bubbles: true }));
    },
    value,
  );
}

/** A hash of a plot's drawn pixels (its uPlot canvas), to see that it was redrawn. */
export function canvasHash(page, testid) {
  return page.$eval(`[data-testid=${testid}] canvas`, (c) => {
    const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
    let h = 0;
    for (let i = 0; i < d.length; i += 4) h = (h * 31 + d[i] + 7 * d[i + 1] + 13 * d[i + 2]) >>> 0;
    return h;
  });
}

/** Waits until the designer's plotted map (data checksum) differs from `prev`; returns the stats. */
export async function mapChanged(page, prev) {
  await page.waitForFunction((p) => window.__texelStats.lastMapChecksum !== p, prev, { timeout: 30_000 });
  return stats(page);
}

/**
 * Sends `msgs` in order over a WebSocket of the page's own (not the page's
 * client) and returns their replies; then lets the engine's simulated
 * participant answer up to `simulated` trials (sessions started with
 * `simulate`). For tests that set the studio up behind the page's back.
 */
export function askStudio(page, msgs, { simulated = 0 } = {}) {
  return page.evaluate(
    async ([msgs, simulated]) => {
      const ws = new WebSocket(`ws://${location.host}/ws`);
      await new Promise((r) => (ws.onopen = r));
      // Replies carry the request's id; state pushes (id null) are skipped.
      const call = (msg) =>
        new Promise((res) => {
          ws.onmessage = (e) => {
            const m = JSON.parse(e.data);
            if (m.id !== null && m.id !== undefined) res(m);
          };
          ws.send(JSON.stringify({ id: 1, ...msg }));
        });
      const replies = [];
      for (const m of msgs) replies.push(await call(m));
      for (let i = 0; i < simulated; i++) {
        const cur = await call({ type: 'experiment.current' });
        if (cur.type !== 'experiment.question') break;
        await call({ type: 'experiment.answer', trial: cur.question.trial, simulated: true });
      }
      ws.close();
      return replies;
    },
    [msgs, simulated],
  );
}

/** Stops whatever runs and starts `proto` (object or shipped name) for `participant`; returns the start reply. */
export async function startSession(page, proto, participant, extra = {}) {
  const replies = await askStudio(page, [{ type: 'experiment.stop' }, { type: 'experiment.start', protocol: proto, participant, ...extra }]);
  return replies[1];
}
