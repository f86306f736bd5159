// Shared by the browser tests: Debian's chromium driven by playwright-core,
// with WebGL on SwiftShader (no GPU here, nor in CI).
import { chromium } from 'playwright-core';

export const CHROMIUM = process.env.DDSWARM_CHROMIUM ?? '/usr/bin/chromium';
export const ARGS = ['--no-sandbox', '--use-gl=angle', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--disable-dev-shm-usage'];

export function parseArgs(argv) {
  const o = {};
  for (let i = 0; i < argv.length; i++) {
    if (!argv[i].startsWith('--')) continue;
    const k = argv[i].slice(2);
    if (i + 1 < argv.length && !argv[i + 1].startsWith('--')) o[k] = argv[++i]; else o[k] = true;
  }
  return o;
}

export async function launch() {
  return chromium.launch({ executablePath: CHROMIUM, args: ARGS, headless: true });
}

// Opens the page; collects its console errors and uncaught exceptions.
export async function openPage(browser, url, { width = 1400, height = 820 } = {}) {
  const page = await browser.newPage({ viewport: { width, height } });
  page.problems = [];
  page.on('pageerror', (e) => page.problems.push(`page error: ${e.message}`));
  page.on('console', (m) => { if (m.type() === 'error') page.problems.push(`console error: ${m.text()}`); });
  await page.goto(url, { waitUntil: 'load', timeout: 30000 });
  return page;
}

// Polls fn (evaluated in the page) until it returns truthy; returns its value.
export async function waitFor(page, fn, arg, { timeout = 30000, what = 'condition' } = {}) {
  const end = Date.now() + timeout;
  let last;
  while (Date.now() < end) {
    last = await page.evaluate(fn, arg);
    if (last) return last;
    await new Promise((r) => setTimeout(r, 100));
  }
  throw new Error(`timed out after ${timeout / 1000} s waiting for ${what} (last: ${JSON.stringify(last)})`);
}

export async function until(fn, { timeout = 30000, what = 'condition', every = 500 } = {}) {
  const end = Date.now() + timeout;
  let last;
  while (Date.now() < end) {
    last = await fn();
    if (last) return last;
    await new Promise((r) => setTimeout(r, every));
  }
  throw new Error(`timed out after ${timeout / 1000} s waiting for ${what}`);
}

// Frame rate the page reports (its own rAF count) averaged over `seconds`.
export async function measureFps(page, seconds) {
  const samples = [];
  for (let i = 0; i < seconds; i++) {
    await page.waitForTimeout(1000);
    samples.push(await page.evaluate(() => ({ fps: window.ddswarm.fps, ms: window.ddswarm.renderMs })));
  }
  const fps = samples.map((s) => s.fps).filter(Number.isFinite);
  return { mean: fps.reduce((a, b) => a + b, 0) / Math.max(1, fps.length), min: Math.min(...fps), max: Math.max(...fps), samples: fps };
}

export function check(cond, msg) {
  if (!cond) throw new Error(msg);
  console.log(`ok: ${msg}`);
}
