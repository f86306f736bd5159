// The mesh world in a real browser: the bridge serves each of the Scene's
// mesh files at the URL the scene message gives, with the file's exact
// bytes, and answers 404 for any other /mesh/ path; the page draws each mesh
// with the triangle count the server loaded; the wind the Scene states
// reaches the page's data (arrows, particles, turbulence) and its panel.
//
//   node tests/web/mesh_world_test.mjs --url URL --out DIR --files A,B --triangles NA,NB
import fs from 'node:fs';
import path from 'node:path';
import { launch, openPage, waitFor, check, parseArgs } from './browser.mjs';

const a = parseArgs(process.argv.slice(2));
const files = (a.files ?? '').split(',');
const triangles = (a.triangles ?? '').split(',').map(Number);
const out = path.resolve(a.out ?? '.');
fs.mkdirSync(out, { recursive: true });

const browser = await launch();
let failed = false;
try {
  const page = await openPage(browser, a.url);
  const scene = await waitFor(page, () => window.ddswarm.scene?.meshes?.length ? window.ddswarm.scene : null, null, { what: 'a scene with meshes' });
  check(scene.meshes.length === files.length, `the scene has ${files.length} meshes (got ${scene.meshes.length})`);

  // 1. Each mesh file is served, byte for byte, where the scene says.
  for (let i = 0; i < files.length; i++) {
    const m = scene.meshes[i];
    check(typeof m.url === 'string' && m.url.startsWith('/mesh/'), `mesh ${i} (${m.file}) is served (url ${m.url}, why '${m.why}')`);
    check(m.triangles === triangles[i], `mesh ${i} has ${triangles[i]} triangles in the scene (got ${m.triangles})`);
    const res = await fetch(new URL(m.url, a.url));
    const body = Buffer.from(await res.arrayBuffer());
    check(res.status === 200 && body.equals(fs.readFileSync(files[i])), `GET ${m.url} answers ${files[i]}'s ${body.length} bytes`);
  }
  for (const p of ['/mesh/0000000000000000.obj', '/mesh/town.obj', '/mesh/meshes%2Ftown.obj', '/mesh/']) {
    const res = await fetch(new URL(p, a.url));
    check(res.status === 404, `GET ${p} is 404 (got ${res.status})`);
  }

  // 2. The page draws every mesh, with the server's triangle count.
  const meshes = await waitFor(page, (n) => {
    const m = window.ddswarm.meshes;
    return m.length === n && m.every((x) => x.state !== 'loading') ? m : null;
  }, files.length, { what: 'the meshes loaded' });
  meshes.forEach((m, i) => check(m.state === 'loaded' && m.drawn === triangles[i],
    `the page draws ${m.file} with ${triangles[i]} triangles (state ${m.state}, drawn ${m.drawn}${m.why ? `, ${m.why}` : ''})`));

  // 3. The wind reaches the page.
  const wind = await page.evaluate(() => window.ddswarm.wind);
  check(Math.abs(wind.speed - 3) < 1e-9, `the page has the server's mean wind, 3 m/s (got ${wind.speed})`);
  check(wind.arrows > 0 && wind.particles > 0, `the page draws the wind (${wind.arrows} arrows, ${wind.particles} particles)`);
  check(wind.turbulence && wind.sigma.every((s) => s > 0), `the page knows the turbulence's intensities (${wind.sigma.map((s) => s.toFixed(2)).join('/')} m/s)`);
  check(wind.gusts_per_minute === 2, `the page knows the gusts' rate (${wind.gusts_per_minute}/min)`);
  const text = await page.textContent('#s-wind');
  check(text.includes('3.0 m/s toward 90°') && text.includes('turbulence') && text.includes('gusts 2/min'), `the panel says the wind: '${text}'`);

  // The view from above the start, the bridge and the town ahead; once the page draws.
  await waitFor(page, () => window.ddswarm.fps > 0, null, { timeout: 60000, what: 'the render loop' });
  await page.evaluate(() => {
    const w = window.ddswarm._internals.world;
    w.camera.position.set(-22, -18, 26);
    w.controls.target.set(0, 34, 0);
    w.controls.update();
  });
  await page.waitForTimeout(1500);
  const shot = path.join(out, 'web_view_mesh_world.png');
  await page.screenshot({ path: shot });
  console.log(`screenshot: ${shot}`);
  check(page.problems.length === 0, `the page reported no errors (${page.problems.join('; ')})`);
} catch (e) {
  console.error(`FAIL: ${e.message}`);
  failed = true;
} finally {
  await browser.close();
}
process.exit(failed ? 1 : 0);
