// The page: connects to the bridge, draws the newest frame at display rate,
// keeps the panel current, and exposes window.ddswarm for tests.
import { World } from './world.js';
import { Drones, droneColour } from './drones.js';
import { Panel } from './panel.js';
import { Controls } from './controls.js';
import { Connection } from './connection.js';
import { PROTOCOL_VERSION } from './protocol.js';

const params = new URLSearchParams(location.search);
const wsUrl = params.get('ws') ?? `${location.protocol === 'https:' ? 'wss' : 'ws'}://${location.host}/ws`;
const fpsWanted = Math.max(1, Math.min(60, Number(params.get('fps')) || 30));

// ?quality=high|medium|low fixes the quality; the default adapts (world.js).
const world = new World(document.getElementById('view'), { quality: params.get('quality') ?? 'auto' });
const drones = new Drones(world.scene, { sun: world.sun, hemi: world.hemi });
const panel = new Panel({ onSelect: (i) => { drones.selected = i; if (i >= 0) document.getElementById('i-leader').value = i; } });
const conn = new Connection(wsUrl, { fps: fpsWanted, rays: false });
const controls = new Controls(conn, panel);

const state = {
  scene: null, frame: null, frameNew: false, frames: 0, status: null, task: null,
  source: 'live', recording: null, framed: false, fps: 0, renderMs: 0, errors: [], drawn: 0,
};

conn.on('state', (s) => {
  panel.setConnection(s);
  controls.enable();
  if (s === 'open') panel.log(`connected to ${wsUrl}`);
  else if (s === 'closed') panel.log('connection lost; reconnecting…', 'bad');
});
conn.on('log', (m) => panel.log(m.text, m.level));
conn.on('hello', (m) => {
  if (m.version !== PROTOCOL_VERSION) panel.log(`bridge speaks protocol ${m.version}, this page ${PROTOCOL_VERSION}`, 'bad');
  const changed = m.source !== state.source;
  state.source = m.source ?? 'live';
  panel.setSource(state.source, state.recording);
  controls.setSource(state.source);
  if (changed) {
    drones.clearTrails();
    state.framed = false;
    state.status = null;
    drones.setLive(null);  // a recording's liveness is in its frames' flags
    if (state.source === 'replay') setCamera('follow');
  }
  if (m.gs_name) document.title = `ddswarm · ${m.gs_name}`;
});
conn.on('scene', (s) => {
  state.scene = s;
  world.setScene(s);
  drones.configure(s.num_drones ?? 0, s.arm_length, s.sensor_count, s.ground_z ?? 0);
  drones.setBlobShadows(world.quality === 'low');
  panel.setScene(s);
  panel.buildTable(s.num_drones ?? 0);
  colourTable();
  document.getElementById('i-leader').max = Math.max(0, (s.num_drones ?? 1) - 1);
  state.framed = false;
  state.frame = null;
});
conn.on('frame', (f) => {
  state.frame = f;
  state.frameNew = true;
  state.frames++;
});
conn.on('status', (st) => {
  state.status = st;
  panel.setStatus(st);
  drones.setLive(st.live);
});
conn.on('task', (t) => {
  const prev = state.task?.state;
  state.task = t;
  panel.setTask(t, state.frame?.t);
  if (t.state !== prev && t.state !== 'none') panel.log(`task ${t.state}${t.phase && t.phase !== t.state ? ` (${t.phase})` : ''}${t.reason ? `: ${t.reason}` : ''}`, t.state === 'failed' ? 'bad' : 'info');
});
// Collisions flash at once; the log gets at most one line a second.
const pendingHits = [];
conn.on('collision', (c) => {
  const now = performance.now();
  drones.flash(c.drone, now);
  if (c.kind === 'drone' && Number.isInteger(c.other)) drones.flash(c.other, now);
  panel.markHit(c.drone, now);
  pendingHits.push(`drone ${c.drone} with ${c.kind === 'drone' ? `drone ${c.other}` : c.kind} at t=${Number(c.t).toFixed(2)} s`);
});
setInterval(() => {
  if (!pendingHits.length) return;
  const more = pendingHits.length > 3 ? ` and ${pendingHits.length - 3} more` : '';
  panel.log(`collision: ${pendingHits.slice(0, 3).join('; ')}${more}`, 'bad');
  pendingHits.length = 0;
}, 1000);
conn.on('ack', (a) => controls.onAck(a));
conn.on('replay', (r) => {
  state.recording = r.name ?? state.recording;
  panel.setSource(state.source, state.recording);
  controls.onReplay(r);
});
conn.on('error', (e) => {
  state.errors.push(e.message);
  panel.log(`bridge: ${e.message}`, 'bad');
});

// A recording has no live status: the panel shows what its frames say.
function statusOfFrame(f) {
  const ds = f.drones ?? [];
  const col = [0, 0, 0];
  let air = 0, live = 0, fs = 0;
  for (const d of ds) {
    if (d.flags & 1) air++;
    if (d.flags & 2) fs++;
    if (d.flags & 4) live++;
    if (Array.isArray(d.col)) for (let k = 0; k < 3; k++) col[k] += d.col[k] | 0;
  }
  const r = controls.replay;
  return { mode: 'replay', state: r ? (r.playing ? `playing ×${r.rate}` : 'paused') : '', rtf: null, agents_live: live, num_drones: ds.length, airborne: air, failsafe: fs, collisions: col };
}

function colourTable() {
  panel.rows.forEach((row, i) => {
    const sw = document.createElement('span');
    sw.className = 'swatch';
    sw.style.background = `#${droneColour(i).getHexString()}`;
    row.cells[0].textContent = '';
    row.cells[0].append(sw, String(i));
  });
}

// HUD options.
for (const b of document.querySelectorAll('[data-cam]')) b.onclick = () => setCamera(b.dataset.cam);
function setCamera(mode) {
  world.setMode(mode);
  for (const b of document.querySelectorAll('[data-cam]')) b.classList.toggle('on', b.dataset.cam === mode);
  if (mode === 'top') world.fitTop();
  applyScale();
  if (mode === 'follow' || mode === 'orbit') {
    const c = drones.centroid();
    if (c && mode === 'follow') world.frame(c, c.radius);
  }
}
world.onQuality = (q) => {
  drones.setBlobShadows(q === 'low');
  const sel = document.getElementById('opt-quality');
  if (!world.auto) sel.value = q;
  sel.options[0].textContent = world.auto ? `auto (${q})` : 'auto';
};
world.onQuality(world.quality);
document.getElementById('opt-quality').onchange = (e) => {
  world.auto = e.target.value === 'auto';
  if (!world.auto) world.setQuality(e.target.value);
  else world.onQuality(world.quality);
};
document.getElementById('opt-trails').onchange = (e) => drones.setTrails(e.target.checked);
document.getElementById('opt-rays').onchange = (e) => { drones.setRays(e.target.checked); conn.subscribe({ rays: e.target.checked }); };
// Drawn size: the slider's, doubled in the top-down view where the course
// is seen whole and a drone would be a dot.
const applyScale = () => { drones.scale = Number(document.getElementById('opt-scale').value) * (world.mode === 'top' ? 2 : 1); };
document.getElementById('opt-scale').oninput = applyScale;
applyScale();
if (params.get('cam')) setCamera(params.get('cam'));
if (params.get('rays') === '1') { document.getElementById('opt-rays').checked = true; drones.setRays(true); conn.sub.rays = true; }
if (params.get('scale')) { document.getElementById('opt-scale').value = params.get('scale'); applyScale(); }

// Render loop.
let last = performance.now(), fpsCount = 0, fpsSince = last, tableAt = 0, renderSum = 0;
const fpsEl = document.getElementById('fps');
function loop(now) {
  requestAnimationFrame(loop);
  const dt = Math.min(0.1, (now - last) / 1000);
  last = now;
  if (state.frameNew && state.frame && drones.n) {
    state.frameNew = false;
    drones.applyFrame(state.frame, now);
    if (!state.framed) {
      const c = drones.centroid();
      if (c) { world.frame(c, c.radius); state.framed = true; }
    }
  }
  if (now - tableAt > 250) {
    tableAt = now;
    panel.updateTable(state.frame, (i) => drones.isLost(i), now);
    if (state.frame) panel.setTime(state.frame.t);  // text changes cost layout and paint: 4 Hz
    if (state.source === 'replay' && state.frame) panel.setStatus(statusOfFrame(state.frame));
  }
  drones.update(dt, now);
  world.update(dt, world.mode === 'follow' ? drones.centroid() : null);
  const t0 = performance.now();
  world.render();
  renderSum += performance.now() - t0;
  fpsCount++;
  state.drawn++;
  if (now - fpsSince >= 1000) {
    state.fps = (fpsCount * 1000) / (now - fpsSince);
    state.renderMs = renderSum / fpsCount;
    fpsEl.textContent = `${state.fps.toFixed(0)} fps · ${drones.count} drones`;
    // Auto quality: two slow seconds in a row (while drones are shown and the
    // page is visible) step the quality down once.
    state.slow = drones.count && !document.hidden && state.fps < 27 ? (state.slow ?? 0) + 1 : 0;
    if (world.auto && state.slow >= 2 && world.lowerQuality()) {
      panel.log(`drawing at ${state.fps.toFixed(0)} fps: quality lowered to ${world.quality}`);
      state.slow = 0;
    }
    fpsCount = 0; renderSum = 0; fpsSince = now;
  }
}
requestAnimationFrame(loop);
conn.connect();

// Test hook: what the page shows, as it shows it.
window.ddswarm = {
  get connected() { return conn.open; },
  get droneCount() { return drones.count; },
  get drones() { return drones.snapshot(); },
  get fps() { return state.fps; },
  get drawn() { return state.drawn; },
  get renderMs() { return state.renderMs; },
  get lastAck() { return controls.lastAck; },
  get source() { return state.source; },
  get frames() { return state.frames; },
  get messages() { return conn.received; },
  get tick() { return state.frame?.tick ?? null; },
  get t() { return state.frame?.t ?? null; },
  get scene() { return state.scene; },
  get meshes() { return world.meshLayer.items.map((m) => ({ ...m })); },
  get wind() { return { ...world.wind.info }; },
  get status() { return state.status; },
  get task() { return state.task; },
  get replay() { return controls.replay; },
  get errors() { return state.errors.slice(); },
  get camera() { return world.mode; },
  get quality() { return world.quality; },
  get gl() { return world.gl.name; },
  setQuality: (q) => { world.auto = q === 'auto'; if (!world.auto) world.setQuality(q); },
  setCamera,
  upload: (file) => controls.upload(file),
};
// For profiling in the browser's console; not an interface.
Object.defineProperty(window.ddswarm, '_internals', { value: { world, drones, panel, conn, controls } });
