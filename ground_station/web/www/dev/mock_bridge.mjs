#!/usr/bin/env node
// A stand-in for `ddswarm-gs --web`: serves the page exactly as the bridge
// does (webroot at /, node_modules/three at /vendor/three/) and speaks
// protocol v1 (docs/web_view.md) over /ws with N synthetic drones, so the
// page can be developed and its frame rate measured without DDS.
//
//   node dev/mock_bridge.mjs [--port 8090] [--drones 128] [--start ground|air|task]
//                            [--failsafe 3,4] [--lost 5] [--duration S]
//
// It prints "web: serving http://127.0.0.1:PORT/" like the bridge. The
// drones follow a simple kinematic swarm law (not the simulator's physics):
// good enough to look at, never a reference for the real thing.
import http from 'node:http';
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { WebSocketServer } from 'ws';
import { FLAG, PHASES, COMMANDS, checkCommand } from '../src/protocol.js';

const here = path.dirname(fileURLToPath(import.meta.url));
const args = parseArgs(process.argv.slice(2));
const webroot = path.resolve(args.webroot ?? path.join(here, '..'));
const host = args.host ?? '127.0.0.1';
const N = Math.max(1, Number(args.drones ?? 6));
const DT = 0.02;  // s, 50 Hz control rate

function parseArgs(a) {
  const o = {};
  for (let i = 0; i < a.length; i++) {
    if (!a[i].startsWith('--')) continue;
    const k = a[i].slice(2);
    if (i + 1 < a.length && !a[i + 1].startsWith('--')) o[k] = a[++i]; else o[k] = true;
  }
  return o;
}
const idList = (s) => (typeof s === 'string' ? s.split(',').map(Number).filter(Number.isInteger) : []);

// ---------------------------------------------------------------- scene
function thesisScene(n) {
  const cylinders = [];
  for (const [y, xs] of [[20, [-12, -4, 4, 12]], [28, [-8, 0, 8]], [36, [-12, -4, 4, 12]], [44, [-8, 0, 8]]]) {
    for (const x of xs) cylinders.push({ x, y, r: 1, h: 12 });
  }
  const wide = n > 24;
  return {
    type: 'scene', name: wide ? `thesis_course_${n}` : 'thesis_course', seed: 1, num_drones: n, mode: 'realtime', ground_z: 0,
    cylinders, boxes: [{ c: [20, 60, 1.5], s: [4, 2, 3], yaw: 0.4 }],
    bounds_min: [-40, -20, 0], bounds_max: [40, 100, 30],
    finish_a: [-40, 68, 0], finish_b: [40, 68, 0], goal: [0, 75, 0],
    drone_radius: 0.3, arm_length: 0.2275, sensor_count: 8, sensor_range: 6,
  };
}

// Start positions: a hexagonal cluster around (0, 0), 2 m apart (y <= 12).
function startPositions(n) {
  const pts = [[0, 0]];
  for (let ring = 1; pts.length < n; ring++) {
    for (let k = 0; k < 6 * ring && pts.length < n; k++) {
      const side = Math.floor(k / ring), step = k % ring;
      const a0 = (side * Math.PI) / 3 - Math.PI / 2, a1 = ((side + 1) * Math.PI) / 3 - Math.PI / 2;
      const x0 = ring * Math.cos(a0), y0 = ring * Math.sin(a0), x1 = ring * Math.cos(a1), y1 = ring * Math.sin(a1);
      pts.push([2 * (x0 + ((x1 - x0) * step) / ring), 2 * (y0 + ((y1 - y0) * step) / ring)]);
    }
  }
  return pts.map(([x, y]) => [x, y - (n > 30 ? 4 : 0), 0.05]);
}

// ---------------------------------------------------------------- swarm
class MockSwarm {
  constructor(scene, opts = {}) {
    this.scene = scene;
    this.n = scene.num_drones;
    this.tick = 0;
    this.t = 0;
    this.dint = 4;
    this.mission = { type: 'idle' };
    this.task = { state: 'none', elapsed: 0, reason: '' };
    this.taskStart = 0;
    this.events = [];
    this.failsafe = new Set(opts.failsafe ?? []);
    this.lost = new Set(opts.lost ?? []);
    this.d = startPositions(this.n).map((p, id) => ({
      id, p: [...p], v: [0, 0, 0], a: [0, 0, 0], w: [0, 0, 0, 0], yaw: 0, phase: 0, alt: 2,
      col: [0, 0, 0], touching: new Set(), flags: 0, nearest: null, pastFinish: false,
    }));
  }

  airborne() { return this.d.filter((d) => d.p[2] > 0.5).length; }

  taskMessage() {
    const d = this.d;
    let maxPair = 0;
    for (const a of d) for (const b of d) if (b.id > a.id) maxPair = Math.max(maxPair, Math.hypot(a.p[0] - b.p[0], a.p[1] - b.p[1], a.p[2] - b.p[2]));
    return {
      type: 'task', state: this.task.state, phase: this.task.state, elapsed: r3(this.task.elapsed), reason: this.task.reason,
      speed: this.mission.speed ?? 0, epsilon: 2 * this.dint + 1, drones: this.n, past_finish: d.filter((a) => a.pastFinish).length,
      max_pair: r3(maxPair), min_inter_drone: null, min_clearance: null, collisions: [0, 0, 0],
    };
  }

  command(cmd, m) {
    const n = this.n, ok = (msg) => ({ ok: true, message: msg ?? `${cmd} ${n}/${n} acknowledged` });
    const bad = (why) => ({ ok: false, message: `${cmd}: rejected by ${n} drone(s): ${why}` });
    const air = this.airborne();
    switch (cmd) {
      case 'takeoff':
        this.mission = { type: 'takeoff' };
        for (const d of this.d) { d.alt = m.altitude; d.phase = 1; }
        return ok();
      case 'move':
        if (air < n) return bad('not airborne');
        this.mission = { type: 'move', v: m.v, until: this.t + m.duration };
        for (const d of this.d) d.phase = 3;
        return ok();
      case 'distance':
        this.dint = m.value;
        return ok();
      case 'land':
        this.mission = { type: 'land' };
        for (const d of this.d) d.phase = 7;
        return ok();
      case 'hold':
        this.mission = { type: 'hold' };
        for (const d of this.d) if (d.p[2] > 0.5) d.phase = 2;
        return ok();
      case 'task':
        if (air < n) return bad('not airborne');
        this.mission = { type: 'task', speed: m.speed };
        for (const d of this.d) { d.phase = 4; d.pastFinish = false; }
        this.task = { state: 'running', elapsed: 0, reason: '' };
        this.taskStart = this.t;
        this.events.push(this.taskMessage());
        return ok();
      case 'follow':
        if (m.leader >= n) return bad(`no drone ${m.leader}`);
        if (air < n) return bad('not airborne');
        this.mission = { type: 'follow', leader: m.leader, v: [0, 0, 0] };
        for (const d of this.d) d.phase = 6;
        return ok();
      case 'teleop':
        if (this.mission.type !== 'follow') return bad('not following');
        this.mission.v = m.v;
        return ok(`teleop ${n}/${n} acknowledged`);
      default:
        return bad('unknown');
    }
  }

  step() {
    const { d, n } = this, dint = this.dint, sc = this.scene, mi = this.mission;
    const cx = d.reduce((s, x) => s + x.p[0], 0) / n, cy = d.reduce((s, x) => s + x.p[1], 0) / n;
    const taskRunning = mi.type === 'task';
    for (const a of d) {
      const vc = [0, 0, 0];
      let nearAll = Infinity;
      for (const b of d) if (b !== a) nearAll = Math.min(nearAll, Math.hypot(b.p[0] - a.p[0], b.p[1] - a.p[1], b.p[2] - a.p[2]));
      a.nearest = Number.isFinite(nearAll) ? nearAll : null;
      const flying = a.phase !== 0 && !(a.phase === 7 && a.p[2] < 0.08);
      if (!flying) { a.v = [0, 0, 0]; a.a = [0, 0, 0]; a.w = [0, 0, 0, 0]; continue; }
      // Repulsion-attraction to peers (a linear law, normalised).
      let ax = 0, ay = 0, near = Infinity;
      for (const b of d) {
        if (b === a) continue;
        const dx = b.p[0] - a.p[0], dy = b.p[1] - a.p[1], r = Math.hypot(dx, dy) || 1e-6;
        near = Math.min(near, Math.hypot(dx, dy, b.p[2] - a.p[2]));
        const f = r > dint ? (0.25 * (r - dint)) / Math.max(1, (n - 1) / 6) : -1.2 * (dint - r);
        ax += (f * dx) / r; ay += (f * dy) / r;
      }
      vc[0] += clamp(ax, -1.5, 1.5); vc[1] += clamp(ay, -1.5, 1.5);
      // Obstacles: push away from pillars closer than 4 m, slide round them.
      for (const c of sc.cylinders) {
        const dx = a.p[0] - c.x, dy = a.p[1] - c.y, r = Math.hypot(dx, dy), clr = r - c.r;
        if (clr < 4 && a.p[2] < c.h) {
          const k = 1.6 * (4 - clr) / 4;
          vc[0] += (k * dx) / r; vc[1] += (k * dy) / r;
          vc[0] += (0.6 * k * Math.sign(dx || 1) * Math.abs(dy)) / r * 0.3;
        }
      }
      // The mission.
      if (taskRunning) {
        if (a.p[1] > sc.finish_a[1]) { a.pastFinish = true; a.phase = 5; }
        if (!a.pastFinish) vc[1] += mi.speed;
        else { vc[0] += clamp(0.15 * (sc.goal[0] - cx), -0.8, 0.8); vc[1] += clamp(0.15 * (sc.goal[1] - cy), -0.8, 0.8); }
      } else if (mi.type === 'move') {
        if (this.t < mi.until) { vc[0] += mi.v[0]; vc[1] += mi.v[1]; a.alt += mi.v[2] * DT; } else { this.mission = { type: 'hold' }; a.phase = 2; }
      } else if (mi.type === 'follow') {
        const L = d[mi.leader];
        if (a === L) { vc[0] = mi.v[0]; vc[1] = mi.v[1]; a.alt = Math.max(0.5, a.alt + mi.v[2] * DT); } else { vc[0] += clamp(0.4 * (L.p[0] - a.p[0]), -1.5, 1.5); vc[1] += clamp(0.4 * (L.p[1] - a.p[1]), -1.5, 1.5); a.alt = L.alt; }
      }
      if (a.phase === 7) vc[2] = -0.6; else vc[2] = clamp(1.2 * (a.alt - a.p[2]), -1, 1.5);
      if (a.phase === 1 && a.p[2] > a.alt - 0.2) a.phase = 2;
      if (a.p[2] < 0.5 && a.phase !== 1 && a.phase !== 7) { vc[0] = 0; vc[1] = 0; }
      const sp = Math.hypot(vc[0], vc[1]);
      if (sp > 3) { vc[0] *= 3 / sp; vc[1] *= 3 / sp; }
      // First-order velocity response; tilt from the acceleration.
      const k = 1 - Math.exp(-DT / 0.35);
      for (let i = 0; i < 3; i++) { a.a[i] = (vc[i] - a.v[i]) / 0.35; a.v[i] += (vc[i] - a.v[i]) * k; }
    }
    for (const a of d) {
      for (let i = 0; i < 3; i++) a.p[i] += a.v[i] * DT;
      if (a.p[2] < 0.05) a.p[2] = 0.05;
      if (a.phase === 7 && a.p[2] <= 0.06) { a.phase = 0; a.v = [0, 0, 0]; }
      const flying = a.phase !== 0;
      const thrust = Math.hypot(a.a[0], a.a[1], 9.81 + a.a[2]) / 9.81;
      for (let r = 0; r < 4; r++) a.w[r] = flying ? 455 * Math.sqrt(Math.max(0.2, thrust)) * (1 + 0.02 * Math.sin(this.t * 3 + r + a.id)) : 0;
      let f = FLAG.AGENT_LIVE;
      if (a.p[2] > 0.5) f |= FLAG.AIRBORNE;
      if (flying) f |= FLAG.MOTORS_ON;
      if (a.pastFinish) f |= FLAG.PAST_FINISH;
      if (this.failsafe.has(a.id)) f |= FLAG.FAILSAFE;
      if (this.lost.has(a.id)) f &= ~FLAG.AGENT_LIVE;
      a.flags = f;
    }
    this.contacts();
    this.tick++;
    this.t = this.tick * DT;
    if (taskRunning) {
      this.task.elapsed = this.t - this.taskStart;
      const past = d.filter((x) => x.pastFinish).length;
      if (past === n && Math.hypot(cx - sc.goal[0], cy - sc.goal[1]) < 1.5) {
        this.task = { state: 'complete', elapsed: this.t - this.taskStart, reason: '' };
        this.events.push(this.taskMessage());
        this.mission = { type: 'hold' };
        for (const x of d) x.phase = 2;
      } else if (this.tick % 25 === 0) {
        this.events.push(this.taskMessage());
      }
    }
  }

  contacts() {
    const rad = this.scene.drone_radius;
    for (const a of this.d) {
      const now = new Set();
      for (const c of this.scene.cylinders) if (Math.hypot(a.p[0] - c.x, a.p[1] - c.y) < c.r + rad && a.p[2] < c.h) now.add(`o${c.x},${c.y}`);
      for (const b of this.d) if (b.id > a.id && Math.hypot(b.p[0] - a.p[0], b.p[1] - a.p[1], b.p[2] - a.p[2]) < 2 * rad) now.add(`d${b.id}`);
      for (const key of now) {
        if (a.touching.has(key)) continue;
        const kind = key[0] === 'o' ? 'obstacle' : 'drone';
        a.col[kind === 'obstacle' ? 0 : 1]++;
        this.events.push({ type: 'collision', tick: this.tick, t: this.t, drone: a.id, kind, other: kind === 'drone' ? Number(key.slice(1)) : -1, where: a.p.map(r3) });
      }
      a.touching = now;
    }
  }

  quat(a) {
    // Thrust along (ax, ay, g + az); yaw a.yaw.
    const t = [a.a[0], a.a[1], 9.81 + a.a[2]], l = Math.hypot(...t);
    const z = [t[0] / l, t[1] / l, t[2] / l];
    // Shortest arc from (0,0,1) to z, then the yaw about z.
    const w0 = 1 + z[2], qx = -z[1], qy = z[0], ln = Math.hypot(w0, qx, qy) || 1;
    const tq = [w0 / ln, qx / ln, qy / ln, 0];
    const cy = Math.cos(a.yaw / 2), sy = Math.sin(a.yaw / 2);
    return [tq[0] * cy - tq[3] * sy, tq[1] * cy + tq[2] * sy, tq[2] * cy - tq[1] * sy, tq[3] * cy + tq[0] * sy];
  }

  rays(a) {
    const m = this.scene.sensor_count, R = this.scene.sensor_range, out = { a: [], e: [], r: [], hit: [] };
    for (let k = 0; k < m; k++) {
      const ang = (2 * Math.PI * k) / m, wa = ang + a.yaw, dx = Math.cos(wa), dy = Math.sin(wa);
      let best = R;
      for (const c of this.scene.cylinders) {
        if (a.p[2] > c.h) continue;
        const ox = a.p[0] - c.x, oy = a.p[1] - c.y, b = ox * dx + oy * dy, cc = ox * ox + oy * oy - c.r * c.r, disc = b * b - cc;
        if (disc < 0) continue;
        const s = -b - Math.sqrt(disc);
        if (s > 0 && s < best) best = s;
      }
      out.a.push(r3(ang)); out.e.push(0); out.r.push(r3(best)); out.hit.push(best < R ? 1 : 0);
    }
    return out;
  }

  frame(withRays) {
    const f = {
      type: 'frame', tick: this.tick, t: r3(this.t),
      drones: this.d.map((a) => ({
        id: a.id, p: a.p.map(r4), q: this.quat(a).map(r4), v: a.v.map(r3), w: a.w.map((x) => Math.round(x)),
        flags: a.flags, phase: PHASES[a.phase], col: a.col.slice(), nearest: a.nearest === null ? null : r3(a.nearest),
      })),
    };
    if (withRays) f.rays = this.d.map((a) => this.rays(a));
    return f;
  }

  status() {
    const live = this.d.filter((a) => !this.lost.has(a.id)).map((a) => a.id);
    const col = this.d.reduce((s, a) => [s[0] + a.col[0], s[1] + a.col[1], s[2] + a.col[2]], [0, 0, 0]);
    return {
      type: 'status', tick: this.tick, t: r3(this.t), rtf: 1, state: 'running', mode: 'realtime', num_drones: this.n,
      agents_live: live.length, live, airborne: this.airborne(), failsafe: this.failsafe.size, collisions: col, rejected: 0,
    };
  }
}

const clamp = (x, a, b) => Math.max(a, Math.min(b, x));
const r3 = (x) => Math.round(x * 1000) / 1000;
const r4 = (x) => Math.round(x * 10000) / 10000;

// ---------------------------------------------------------------- the live swarm
const scene = thesisScene(N);
const swarm = new MockSwarm(scene, { failsafe: idList(args.failsafe), lost: idList(args.lost) });
const start = args.start ?? 'ground';
if (start === 'air' || start === 'task') {
  for (const d of swarm.d) { d.p[2] = 2; d.phase = 2; }
  swarm.mission = { type: 'hold' };
  if (start === 'task') swarm.command('task', { speed: Number(args.speed ?? 0.8) });
}
const clients = new Set();
const encoded = { tick: -1, plain: null, rays: null };
function encodedFrame(rays) {
  if (encoded.tick !== swarm.tick) Object.assign(encoded, { tick: swarm.tick, plain: null, rays: null });
  const k = rays ? 'rays' : 'plain';
  if (!encoded[k]) encoded[k] = JSON.stringify(swarm.frame(rays));
  return encoded[k];
}
setInterval(() => {
  swarm.step();
  for (const ev of swarm.events.splice(0)) for (const c of clients) if (c.source === 'live') c.send(ev);
}, DT * 1000);
setInterval(() => { for (const c of clients) if (c.source === 'live') c.send(swarm.status()); }, 500);

// ---------------------------------------------------------------- recordings
let recording = null;  // frames of a synthetic run, made on first upload
function makeRecording(name) {
  const s = new MockSwarm(scene);
  s.command('takeoff', { altitude: 2 });
  const frames = [];
  for (let i = 0; i < 90 / DT; i++) {
    if (i === Math.round(8 / DT)) s.command('task', { speed: 1.2 });
    s.step();
    s.events.length = 0;
    if (i % 5 === 0) frames.push(s.frame(false));
  }
  return { id: 'rec-1', name, frames, start: frames[0].t, duration: frames.at(-1).t - frames[0].t };
}

// ---------------------------------------------------------------- HTTP
const TYPES = { '.html': 'text/html; charset=utf-8', '.js': 'text/javascript; charset=utf-8', '.mjs': 'text/javascript; charset=utf-8', '.css': 'text/css; charset=utf-8', '.json': 'application/json', '.png': 'image/png', '.svg': 'image/svg+xml', '.wasm': 'application/wasm' };
const server = http.createServer((req, res) => {
  const url = new URL(req.url, 'http://x');
  if (req.method === 'POST' && url.pathname === '/api/recording') {
    const chunks = [];
    let size = 0;
    req.on('data', (c) => { size += c.length; if (size <= 64 << 20) chunks.push(c); });
    req.on('end', () => {
      const body = Buffer.concat(chunks);
      const magic = Buffer.from([0x89, 0x4d, 0x43, 0x41, 0x50, 0x30, 0x0d, 0x0a]);
      res.setHeader('Content-Type', 'application/json');
      if (size > 64 << 20) { res.statusCode = 400; res.end(JSON.stringify({ error: `recording of ${size} bytes is over the mock's 64 MiB` })); return; }
      if (body.length < 8 || !body.subarray(0, 8).equals(magic)) { res.statusCode = 400; res.end(JSON.stringify({ error: 'not an MCAP file (no MCAP magic)' })); return; }
      recording = makeRecording(url.searchParams.get('name') || 'recording.mcap');
      res.end(JSON.stringify({ id: recording.id, name: recording.name, duration: r3(recording.duration), frames: recording.frames.length }));
    });
    return;
  }
  if (url.pathname === '/api/dev/state') {
    // Mock only: the truth the browser tests compare the page with.
    res.setHeader('Content-Type', 'application/json');
    res.end(JSON.stringify({ tick: swarm.tick, t: swarm.t, airborne: swarm.airborne(), drones: swarm.d.map((a) => ({ id: a.id, p: a.p.map(r4), flags: a.flags })) }));
    return;
  }
  if (req.method !== 'GET' && req.method !== 'HEAD') { res.statusCode = 405; res.end(); return; }
  let rel = decodeURIComponent(url.pathname);
  let root = webroot;
  if (rel.startsWith('/vendor/three/')) { root = path.join(webroot, 'node_modules', 'three'); rel = rel.slice('/vendor/three'.length); }
  if (rel.endsWith('/')) rel += 'index.html';
  const file = path.resolve(root, '.' + path.posix.normalize(rel));
  if (!file.startsWith(root + path.sep) || rel.includes('\0')) { res.statusCode = 404; res.end('not found'); return; }
  fs.readFile(file, (err, data) => {
    if (err) { res.statusCode = 404; res.end('not found'); return; }
    res.setHeader('Content-Type', TYPES[path.extname(file)] ?? 'application/octet-stream');
    res.setHeader('Cache-Control', 'no-cache');
    res.end(req.method === 'HEAD' ? undefined : data);
  });
});

// ---------------------------------------------------------------- WebSocket
const wss = new WebSocketServer({ server, path: '/ws', maxPayload: 1 << 20 });
wss.on('connection', (ws) => {
  const c = { ws, fps: 30, rays: false, source: 'live', lastTick: -1, timer: null, replay: null, replayAt: 0, errors: 0 };
  c.send = (obj) => { if (ws.readyState === ws.OPEN) ws.send(typeof obj === 'string' ? obj : JSON.stringify(obj)); };
  clients.add(c);
  const hello = () => {
    c.send({ type: 'hello', version: 1, source: c.source, gs_name: 'mock-bridge' });
    c.send(c.source === 'replay' ? { ...scene, num_drones: N } : scene);
    c.send(c.source === 'live' ? swarm.taskMessage() : { type: 'task', state: 'none', phase: 'none', elapsed: 0, reason: '' });
    if (c.source === 'live') c.send(swarm.status());
  };
  const pace = () => {
    clearInterval(c.timer);
    let last = performance.now();
    c.timer = setInterval(() => {
      const now = performance.now(), dt = (now - last) / 1000;
      last = now;
      if (ws.bufferedAmount > (1 << 20)) return;  // slow client: skip, never queue
      if (c.source === 'live') {
        if (swarm.tick === c.lastTick) return;
        c.lastTick = swarm.tick;
        c.send(encodedFrame(c.rays));
      } else {
        const r = c.replay, fr = r.rec.frames;
        if (r.playing) r.t = Math.min(r.rec.start + r.rec.duration, r.t + dt * r.rate);
        if (r.playing && r.t >= r.rec.start + r.rec.duration) r.playing = false;
        let lo = 0, hi = fr.length - 1;
        while (lo < hi) { const mid = (lo + hi + 1) >> 1; if (fr[mid].t <= r.t) lo = mid; else hi = mid - 1; }
        if (lo !== c.lastTick) { c.lastTick = lo; c.send(fr[lo]); }
        if (now - c.replayAt > 250) { c.replayAt = now; sendReplay(c); }
      }
    }, 1000 / c.fps);
  };
  const sendReplay = (cl) => {
    const r = cl.replay;
    cl.send({ type: 'replay', duration: r3(r.rec.duration), start: r.rec.start, t: r3(r.t), playing: r.playing, rate: r.rate, name: r.rec.name, frames: r.rec.frames.length });
  };
  const error = (message) => { c.errors++; c.send({ type: 'error', message }); };
  hello();
  pace();
  ws.on('message', (data, isBinary) => {
    if (isBinary) return error('binary frames are not accepted');
    if (data.length > 64 * 1024) return error(`message of ${data.length} bytes is over 64 KiB`);
    let m;
    try { m = JSON.parse(String(data)); } catch { return error('message is not JSON'); }
    if (!m || typeof m !== 'object') return error('message is not a JSON object');
    switch (m.type) {
      case 'subscribe': {
        const fps = m.fps ?? 30;
        if (!Number.isFinite(fps) || fps < 1 || fps > 60) return error(`subscribe: fps ${JSON.stringify(m.fps)} is not in 1..60`);
        c.fps = fps; c.rays = !!m.rays; pace();
        return;
      }
      case 'command': {
        if (!Number.isFinite(m.id)) return error(`command: id ${JSON.stringify(m.id)} is not a number`);
        if (!(m.cmd in COMMANDS)) return error(`command: unknown cmd ${JSON.stringify(m.cmd)}`);
        const args = { ...m };
        if (m.cmd === 'task' && args.epsilon === undefined) args.epsilon = 0;
        const bad = checkCommand(m.cmd, args);
        if (bad) return error(bad);
        if (c.source !== 'live') return c.send({ type: 'ack', id: m.id, cmd: m.cmd, ok: false, message: `${m.cmd}: this page is playing a recording` });
        const a = swarm.command(m.cmd, args);
        setTimeout(() => c.send({ type: 'ack', id: m.id, cmd: m.cmd, ...a }), 60);
        return;
      }
      case 'open':
        if (!recording || m.recording !== recording.id) return error(`open: no recording ${JSON.stringify(m.recording)}`);
        c.source = 'replay';
        c.replay = { rec: recording, t: recording.start, playing: true, rate: 1 };
        c.lastTick = -1;
        hello(); sendReplay(c);
        return;
      case 'live':
        c.source = 'live'; c.replay = null; c.lastTick = -1;
        hello();
        return;
      case 'replay': {
        if (c.source !== 'replay') return error('replay: no recording is open');
        const r = c.replay;
        if (m.action === 'play') r.playing = true;
        else if (m.action === 'pause') r.playing = false;
        else if (m.action === 'seek') {
          if (!Number.isFinite(m.t)) return error(`replay: seek t ${JSON.stringify(m.t)} is not a number`);
          r.t = clamp(m.t, r.rec.start, r.rec.start + r.rec.duration);
        } else if (m.action === 'rate') {
          if (!Number.isFinite(m.rate) || m.rate < 0.1 || m.rate > 16) return error(`replay: rate ${JSON.stringify(m.rate)} is not in 0.1..16`);
          r.rate = m.rate;
        } else return error(`replay: unknown action ${JSON.stringify(m.action)}`);
        sendReplay(c);
        return;
      }
      default:
        return error(`unknown type ${JSON.stringify(m.type)}`);
    }
  });
  ws.on('close', () => { clearInterval(c.timer); clients.delete(c); });
  ws.on('error', () => {});
});

server.listen(Number(args.port ?? 0), host, () => {
  console.log(`web: serving http://${host}:${server.address().port}/ (mock bridge, ${N} drones, ${PHASES[swarm.d[0].phase]})`);
});
if (args.duration) setTimeout(() => process.exit(0), Number(args.duration) * 1000);
for (const sig of ['SIGINT', 'SIGTERM']) process.on(sig, () => process.exit(0));
