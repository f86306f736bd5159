// The recording player in a real browser: "Open recording…" uploads an MCAP
// of a run that took off, the page switches to it (live controls off), draws
// its drones, plays (the take-off is seen: a drone above 1.5 m), seeks back
// to the start (every drone on the ground again), and returns to live.
//   node tests/web/replay_test.mjs --url URL --recording FILE.mcap --drones N --out DIR
import path from 'node:path';
import { launch, openPage, waitFor, check, parseArgs } from './browser.mjs';

const a = parseArgs(process.argv.slice(2));
const N = Number(a.drones);
const browser = await launch();
let failed = false;
try {
  const page = await openPage(browser, a.url);
  await waitFor(page, () => window.ddswarm.connected && window.ddswarm.source === 'live', null, { what: 'the live page' });
  await page.setInputFiles('#i-rec', a.recording);
  const r = await waitFor(page, (n) => window.ddswarm.source === 'replay' && window.ddswarm.replay && window.ddswarm.droneCount === n && window.ddswarm.replay,
    N, { timeout: 60000, what: 'the recording to open' });
  check(r.duration > 1, `the recording opened: ${r.name}, ${Number(r.duration).toFixed(1)} s, ${r.frames} frames, ${N} drones drawn`);
  check(await page.evaluate(() => document.getElementById('c-takeoff').disabled), 'live controls are off while a recording plays');
  check(await page.evaluate(() => !document.getElementById('replay-bar').hidden), 'the timeline is shown');

  // Pause, seek to the start: the swarm is on the ground, as when recording began.
  if (await page.evaluate(() => window.ddswarm.replay.playing)) await page.click('#rp-play');
  await waitFor(page, () => window.ddswarm.replay.playing === false, null, { what: 'pause' });
  await page.evaluate(() => { const s = document.getElementById('rp-seek'); s.value = s.min; s.dispatchEvent(new Event('input')); s.dispatchEvent(new Event('change')); });
  const low = await waitFor(page, (t0) => { const z = Math.max(...window.ddswarm.drones.map((d) => d.p[2])); return z < 0.3 && Math.abs(window.ddswarm.t - t0) < 0.1 ? { z, t: window.ddswarm.t } : null; },
    r.start, { timeout: 20000, what: 'the seek to the start' });
  check(low.z < 0.3, `seeking to the start shows the swarm on the ground (t=${low.t.toFixed(2)} s, highest ${low.z.toFixed(2)} m)`);

  // Play at normal rate: the recorded take-off is seen.
  await page.selectOption('#rp-rate', '1');
  await page.click('#rp-play');
  const high = await waitFor(page, () => { const z = Math.max(...window.ddswarm.drones.map((d) => d.p[2])); return z > 1.5 ? z : null; },
    null, { timeout: 60000, what: 'the recorded take-off' });
  check(high > 1.5, `playing shows the recorded take-off (a drone at ${high.toFixed(2)} m)`);
  const shot = path.resolve(a.out ?? '.', 'web_view_replay.png');
  await page.screenshot({ path: shot });
  console.log(`screenshot: ${shot}`);

  await page.click('#rp-live');
  await waitFor(page, () => window.ddswarm.source === 'live' && document.getElementById('replay-bar').hidden, null, { what: 'back to live' });
  const f0 = await page.evaluate(() => window.ddswarm.messages);
  await page.waitForTimeout(2000);
  check((await page.evaluate(() => window.ddswarm.messages)) > f0, 'back to the live swarm');
  check(page.problems.length === 0, `no errors in the page (${JSON.stringify(page.problems)})`);
} catch (e) {
  failed = true;
  console.error(`FAIL: ${e.message}`);
} finally {
  await browser.close();
}
process.exit(failed ? 1 : 0);
