// A screenshot of the web view (for the README and for looking at a run):
//   node tests/web/shot.mjs --url http://127.0.0.1:PORT/ --out view.png
//        [--wait 5] [--cam orbit|follow|top] [--quality high] [--width 1600 --height 900] [--rays]
import path from 'node:path';
import { launch, openPage, waitFor, parseArgs } from './browser.mjs';

const a = parseArgs(process.argv.slice(2));
const u = new URL(a.url);
u.searchParams.set('quality', a.quality ?? 'high');
if (a.rays) u.searchParams.set('rays', '1');
if (a.scale) u.searchParams.set('scale', a.scale);
const browser = await launch();
try {
  const page = await openPage(browser, u.href, { width: Number(a.width ?? 1600), height: Number(a.height ?? 900) });
  await waitFor(page, () => window.ddswarm.connected && window.ddswarm.droneCount > 0, null, { what: 'drones drawn' });
  if (a.cam) await page.evaluate((c) => window.ddswarm.setCamera(c), a.cam);
  if (a['hide-fps']) await page.evaluate(() => { document.getElementById('fps').style.visibility = 'hidden'; });
  await page.waitForTimeout(1000 * Number(a.wait ?? 5));
  const out = path.resolve(a.out ?? 'view.png');
  await page.screenshot({ path: out });
  console.log(`screenshot: ${out} (${await page.evaluate(() => `${window.ddswarm.droneCount} drones, t=${window.ddswarm.t} s`)})`);
} finally {
  await browser.close();
}
