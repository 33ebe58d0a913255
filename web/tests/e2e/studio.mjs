// Shared helpers of the end-to-end browser tests: start the real
// `texel studio` (null backend, a fresh database, the shipped protocols) on a
// free loopback port, launch Debian's Chromium through playwright-core (never
// a downloaded browser), and always stop both — also when a test fails or
// hangs (a hard timeout kills the server).
//
// Environment (paths relative to web/ unless absolute):
//   TEXEL_BIN        texel binary            (default ../build/bin/texel)
//   TEXEL_WEB        built front end         (default ../build/web)
//   TEXEL_ARTIFACTS  screenshots, latency    (default ../build/browser-artifacts)
//   TEXEL_PROTOCOLS  shipped protocols       (default ../examples/protocols)
//   TEXEL_CHROMIUM   browser executable      (default /usr/bin/chromium)

import { spawn } from 'node:child_process';
import { mkdirSync, mkdtempSync, rmSync, existsSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';

const webDir = resolve(dirname(fileURLToPath(import.meta.url)), '..', '..');
const fromWeb = (p) => resolve(webDir, p);

export const paths = {
  bin: fromWeb(process.env.TEXEL_BIN ?? '../build/bin/texel'),
  web: fromWeb(process.env.TEXEL_WEB ?? '../build/web'),
  artifacts: fromWeb(process.env.TEXEL_ARTIFACTS ?? '../build/browser-artifacts'),
  protocols: fromWeb(process.env.TEXEL_PROTOCOLS ?? '../examples/protocols'),
  chromium: process.env.TEXEL_CHROMIUM ?? '/usr/bin/chromium',
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

/** Starts `texel studio --port 0`; resolves {url, stop, log} once it printed its address. */
export async function startStudio({ hardTimeoutMs = 600_000 } = {}) {
  for (const [what, p] of [['TEXEL_BIN', paths.bin], ['TEXEL_WEB', join(paths.web, 'index.html')]])
    if (!existsSync(p)) throw new Error(`${what}: ${p} does not exist (build it first; see web/tests/e2e/studio.mjs)`);
  const dir = mkdtempSync(join(tmpdir(), 'texel-e2e-'));
  const args = ['studio', '--port', '0', '--web', paths.web, '--db', join(dir, 's.db'), '--backend', 'null', '--protocols', paths.protocols];
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
      const done = await Promise.race([exited, new Promise((r) => setTimeout(() => r(null), 5000))]);
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

/**
 * Runs `fn({studio, browser, page, context})` against a fresh server and browser and
 * always tears both down. Page errors and console errors are collected in `errors`.
 */
export async function withStudio(fn, { contextOptions = {} } = {}) {
  const studio = await startStudio();
  let browser;
  try {
    browser = await launchBrowser();
    const context = await browser.newContext({ viewport: { width: 1280, height: 900 }, acceptDownloads: true, ...contextOptions });
    const page = await context.newPage();
    const errors = [];
    page.on('pageerror', (e) => errors.push(String(e)));
    return await fn({ studio, browser, context, page, errors });
  } finally {
    await browser?.close().catch(() => {});
    await studio.stop();
  }
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
