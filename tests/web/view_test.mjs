// The web view in a real browser: the page loads and draws as many drones as fly;
// each drawn position matches the DDS truth within 0.1 m; clicking Take off
// makes the swarm airborne by the DDS state; screenshots are saved; the
// bridge keeps serving after a browser drops mid-stream and after malformed
// client messages. Truth comes from `ddswarm-gs status --drones` (--gs), or
// from the mock bridge's /api/dev/state (--truth mock) when developing.
//
//   node tests/web/view_test.mjs --url http://127.0.0.1:PORT/ --drones N --out DIR
//        (--gs BIN/ddswarm-gs --domain D [--config YAML] | --truth mock)
import { execFile } from 'node:child_process';
import { promisify } from 'node:util';
import fs from 'node:fs';
import path from 'node:path';
import { launch, openPage, waitFor, until, measureFps, check, parseArgs } from './browser.mjs';

const run = promisify(execFile);
const a = parseArgs(process.argv.slice(2));
const url = a.url;
const N = Number(a.drones);
const out = path.resolve(a.out ?? '.');
const TOL = 0.1;  // m
if (!url || !Number.isInteger(N) || N < 1) {
  console.error('usage: view_test.mjs --url URL --drones N --out DIR (--gs PATH --domain D | --truth mock)');
  process.exit(2);
}
fs.mkdirSync(out, { recursive: true });

// ---- the truth: what the DDS state says
async function gs(...args) {
  const base = ['--domain', String(a.domain)];
  if (a.config) base.push('--config', a.config);
  const { stdout } = await run(a.gs, [...base, ...args], { timeout: 30000 });
  return stdout;
}
async function truth() {
  if (a.truth === 'mock') {
    const s = await (await fetch(new URL('api/dev/state', url))).json();
    return { airborne: s.airborne, drones: s.drones.map((d) => ({ id: d.id, p: d.p })), text: JSON.stringify(s) };
  }
  const text = await gs('status', '--drones');
  const drones = [];
  for (const line of text.split('\n')) {
    const m = line.match(/^\s*(\d+)\s+(-?\d+\.\d+)\s+(-?\d+\.\d+)\s+(-?\d+\.\d+)\s/);
    if (m) drones.push({ id: Number(m[1]), p: [Number(m[2]), Number(m[3]), Number(m[4])] });
  }
  const air = text.match(/\|\s*(\d+) airborne/);
  return { airborne: air ? Number(air[1]) : NaN, drones, text };
}
const shown = (page) => page.evaluate(() => window.ddswarm.drones);
function maxError(page, truthDrones) {
  const byId = new Map(page.map((d) => [d.id, d.p]));
  let worst = { err: -1, id: -1 };
  for (const t of truthDrones) {
    const p = byId.get(t.id);
    const err = p ? Math.hypot(p[0] - t.p[0], p[1] - t.p[1], p[2] - t.p[2]) : Infinity;
    if (err > worst.err) worst = { err, id: t.id, page: p, truth: t.p };
  }
  return worst;
}

const browser = await launch();
let failed = false;
try {
  const page = await openPage(browser, url);
  const gl = await page.evaluate(() => window.ddswarm?.gl);
  console.log(`browser: ${browser.version()}, WebGL: ${gl}`);

  // 1. The page loads and draws as many drones as fly.
  await waitFor(page, (n) => window.ddswarm.connected && window.ddswarm.droneCount === n, N, { what: `${N} drones drawn` });
  const t0 = await truth();
  check(t0.drones.length === N, `the DDS state has ${N} drones (got ${t0.drones.length})`);
  check((await page.evaluate(() => window.ddswarm.droneCount)) === t0.drones.length, `the page draws ${N} drones, as many as the DDS state has`);
  await waitFor(page, () => window.ddswarm.fps > 0, null, { what: 'the render loop' });

  // 2. Drawn positions match the truth while the swarm is still (on the
  //    ground before take-off: a lockstep swarm is paused, idle).
  const still = await until(async () => {
    const before = await shown(page);
    const tr = await truth();
    const after = await shown(page);
    const moving = maxError(after, before.map((d) => ({ id: d.id, p: d.p }))).err;
    return moving < 0.005 ? { page: after, truth: tr } : null;
  }, { timeout: 30000, what: 'a still swarm' });
  const worst = maxError(still.page, still.truth.drones);
  check(worst.err <= TOL, `every drawn position is within ${TOL} m of the DDS truth (worst: drone ${worst.id}, ${worst.err.toFixed(4)} m)`);
  const ground = path.join(out, 'web_view_ground.png');
  await page.screenshot({ path: ground });
  console.log(`screenshot: ${ground}`);

  // 3. Take off from the page; the DDS state confirms the swarm is airborne.
  await page.fill('#i-alt', '2');
  await page.click('#c-takeoff');
  const ack = await waitFor(page, () => window.ddswarm.lastAck, null, { timeout: 60000, what: 'the takeoff ack' });
  check(ack.ok === true, `takeoff acknowledged in the page: "${ack.message}"`);
  const logText = await page.textContent('#log');
  check(logText.includes(ack.message), 'the ack is shown in the log');
  const air = await until(async () => { const t = await truth(); return t.airborne === N ? t : null; }, { timeout: 90000, what: `${N} drones airborne per DDS` });
  check(air.airborne === N, `the DDS state has all ${N} drones airborne`);
  await waitFor(page, (n) => window.ddswarm.drones.filter((d) => d.flags & 1).length === n && window.ddswarm.drones.every((d) => d.p[2] > 1), N,
    { timeout: 20000, what: 'the page to draw the swarm airborne' });
  console.log('ok: the page draws every drone airborne (flag and height)');
  await page.evaluate(() => window.ddswarm.setCamera('follow'));
  await page.waitForTimeout(2500);
  const fps = await measureFps(page, 3);
  console.log(`fps: ${fps.mean.toFixed(1)} (min ${fps.min.toFixed(1)}) with ${N} drones, quality ${await page.evaluate(() => window.ddswarm.quality)}`);
  const airborne = path.join(out, 'web_view_airborne.png');
  await page.screenshot({ path: airborne });
  console.log(`screenshot: ${airborne}`);

  // 4. The bridge survives a browser leaving mid-stream and malformed messages.
  const second = await openPage(browser, url);
  await waitFor(second, () => window.ddswarm.connected && window.ddswarm.frames > 0, null, { what: 'a second page streaming' });
  await second.close();  // drops its WebSocket mid-stream
  const errors = await page.evaluate((wsUrl) => new Promise((resolve) => {
    const ws = new WebSocket(wsUrl);
    const got = [];
    ws.onopen = () => {
      ws.send('this is not json');
      ws.send(JSON.stringify({ type: 'command', id: 1, cmd: 'fly-to-the-moon' }));
      ws.send(JSON.stringify({ type: 'subscribe', fps: 1e9, rays: false }));
      ws.send(JSON.stringify({ type: 'command', id: 2, cmd: 'move', v: [1, 'x', 0], duration: 1 }));
    };
    ws.onmessage = (e) => { const m = JSON.parse(e.data); if (m.type === 'error') got.push(m.message); if (got.length === 4) { ws.close(); resolve(got); } };
    setTimeout(() => { ws.close(); resolve(got); }, 8000);
  }), new URL('ws', url.replace(/^http/, 'ws')).href);
  check(errors.length === 4, `four malformed messages got four error replies (${JSON.stringify(errors)})`);
  const before = await page.evaluate(() => window.ddswarm.messages);
  await page.waitForTimeout(3000);
  const after = await page.evaluate(() => ({ m: window.ddswarm.messages, c: window.ddswarm.connected }));
  check(after.c && after.m > before, `the first page is still connected and receiving (${after.m - before} messages in 3 s)`);
  await page.click('#c-land');
  const landAck = await waitFor(page, (id) => { const k = window.ddswarm.lastAck; return k && k.id !== id ? k : null; }, ack.id, { timeout: 60000, what: 'the land ack' });
  check(landAck.ok === true, `the bridge still commands the swarm: land acknowledged ("${landAck.message}")`);
  check(page.problems.length === 0, `no errors in the page (${JSON.stringify(page.problems)})`);
} catch (e) {
  failed = true;
  console.error(`FAIL: ${e.message}`);
} finally {
  await browser.close();
}
process.exit(failed ? 1 : 0);
