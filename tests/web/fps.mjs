// Frame rate of the web view in headless Chromium (SwiftShader WebGL): opens
// the page at each quality level and prints the page's own frame count.
// A measurement to report, never a pass/fail threshold.
//
//   node tests/web/fps.mjs --url http://127.0.0.1:PORT/ [--seconds 10] [--quality auto|high|medium|low|all]
//        [--width 1280 --height 720] [--shot DIR] [--cam orbit|follow|top]
import path from 'node:path';
import fs from 'node:fs';
import { launch, openPage, waitFor, measureFps, parseArgs } from './browser.mjs';

// CPU time (ms) used so far by this process's descendants (the browser's
// processes): per drawn frame, it is a cost that other load on the machine
// does not change much, unlike frames per second.
function browserCpuMs() {
  const procs = new Map();
  for (const d of fs.readdirSync('/proc')) {
    if (!/^\d+$/.test(d)) continue;
    try {
      const st = fs.readFileSync(`/proc/${d}/stat`, 'utf8');
      const f = st.slice(st.lastIndexOf(')') + 2).split(' ');
      procs.set(Number(d), { ppid: Number(f[1]), ticks: Number(f[11]) + Number(f[12]) });
    } catch { /* gone */ }
  }
  const mine = new Set([process.pid]);
  for (let grew = true; grew;) {
    grew = false;
    for (const [pid, p] of procs) if (!mine.has(pid) && mine.has(p.ppid)) { mine.add(pid); grew = true; }
  }
  mine.delete(process.pid);
  let ticks = 0;
  for (const pid of mine) ticks += procs.get(pid).ticks;
  return ticks * 10;  // USER_HZ 100
}

const a = parseArgs(process.argv.slice(2));
const seconds = Number(a.seconds ?? 10);
const levels = (a.quality ?? 'all') === 'all' ? ['high', 'medium', 'low', 'auto'] : [a.quality];
const width = Number(a.width ?? 1280), height = Number(a.height ?? 720);
const browser = await launch();
let rc = 0;
try {
  // Reference: an empty WebGL page (a clear per frame) at the same size, for
  // what this machine's load leaves to any page.
  {
    const page = await browser.newPage({ viewport: { width, height } });
    await page.setContent(`<canvas id=c style="display:block;width:100vw;height:100vh"></canvas><script>
      const c = document.getElementById('c'); c.width = innerWidth; c.height = innerHeight;
      const gl = c.getContext('webgl2'); window.drawn = 0;
      const f = () => { gl.clearColor(0.5, 0.6, 0.5, 1); gl.clear(gl.COLOR_BUFFER_BIT); window.drawn++; requestAnimationFrame(f); };
      requestAnimationFrame(f);</script>`);
    await page.waitForTimeout(2000);
    const c0 = browserCpuMs(), d0 = await page.evaluate(() => window.drawn), t0 = Date.now();
    await page.waitForTimeout(1000 * Math.min(seconds, 5));
    const frames = (await page.evaluate(() => window.drawn)) - d0;
    console.log(`fps empty  ${((frames * 1000) / (Date.now() - t0)).toFixed(1)}: an empty WebGL page, ${width}x${height}; browser CPU ${((browserCpuMs() - c0) / Math.max(1, frames)).toFixed(1)} ms per frame`);
    await page.close();
  }
  for (const q of levels) {
    const u = new URL(a.url);
    u.searchParams.set('quality', q);
    if (a.cam) u.searchParams.set('cam', a.cam);
    const page = await openPage(browser, u.href, { width, height });
    await waitFor(page, () => window.ddswarm.connected && window.ddswarm.droneCount > 0, null, { what: 'drones drawn' });
    if (a.cam) await page.evaluate((c) => window.ddswarm.setCamera(c), a.cam);
    await page.waitForTimeout(q === 'auto' ? 8000 : 3000);  // warm up (auto: let it settle)
    const c0 = browserCpuMs(), d0 = await page.evaluate(() => window.ddswarm.drawn);
    const f = await measureFps(page, seconds);
    const cpuPerFrame = (browserCpuMs() - c0) / Math.max(1, (await page.evaluate(() => window.ddswarm.drawn)) - d0);
    const info = await page.evaluate(() => ({ n: window.ddswarm.droneCount, q: window.ddswarm.quality, ms: window.ddswarm.renderMs, gl: window.ddswarm.gl }));
    console.log(`fps ${q.padEnd(6)} ${f.mean.toFixed(1)} (min ${f.min.toFixed(1)}, max ${f.max.toFixed(1)}) over ${seconds} s: ${info.n} drones, ` +
      `${width}x${height} viewport, drawing at ${info.q}; browser CPU ${cpuPerFrame.toFixed(1)} ms per frame ` +
      `(idle 2 cores: ~${Math.min(60, 1000 / cpuPerFrame).toFixed(0)}-${Math.min(60, 2000 / cpuPerFrame).toFixed(0)} fps); ${info.gl}`);
    if (a.shot) {
      fs.mkdirSync(a.shot, { recursive: true });
      const p = path.resolve(a.shot, `web_fps_${q}.png`);
      await page.screenshot({ path: p });
      console.log(`screenshot: ${p}`);
    }
    if (page.problems.length) { console.log(`page problems: ${page.problems.join('; ')}`); rc = 1; }
    await page.close();
  }
} finally {
  await browser.close();
}
process.exit(rc);
