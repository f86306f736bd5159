// The drones: a quadrotor model (body, four arms with motor pods, four
// two-blade rotors with a blur disc) drawn with one InstancedMesh per part,
// so 128+ drones cost a handful of draw calls. Attitude comes from the
// state's quaternion (body FLU -> world ENU); rotors turn at their measured
// rad/s, slowed down for the eye. Also: trails (one LineSegments, a ring of
// time slots shared by every drone), sensor rays, collision flashes and a
// ring under drones in failsafe or whose agent is lost.
import * as THREE from 'three';
import { mergeGeometries } from 'three/addons/utils/BufferGeometryUtils.js';
import { FLAG } from './protocol.js';
import { LIT_FRAGMENT_SHADER, surface } from './world.js';

// Rotor layout (sim_server/quadrotor.hpp): 0 front-right CCW, 1 rear-left CCW,
// 2 front-left CW, 3 rear-right CW; arms at -45, 135, 45, -135 degrees.
const ROTOR_ANGLE = [-45, 135, 45, -135].map((d) => (d * Math.PI) / 180);
const ROTOR_SPIN = [1, 1, -1, -1];   // +1: counter-clockwise seen from above
export const SPIN_SCALE = 0.045;     // drawn rad/s per real rad/s (500 rad/s -> ~3.6 turns/s)

// Trails: at most TRAIL_BUDGET segments in all (every one costs vertex and
// line work each frame: on SwiftShader 16k segments cost as much as the
// drones), up to 480 points a drone, a point every 0.25 s of sim time or more
// so that a trail spans at least 30 s (120 s for a few drones).
const TRAIL_BUDGET = 6144;
const TRAIL_MAX_SLOTS = 480;
const TRAIL_LIFE = 120;              // s of sim time a trail point stays visible
const FLASH_MS = 900;

const HEX = Array.from({ length: 14 }, (_, i) => (i % 2 ? Math.sin : Math.cos)((Math.floor(i / 2) * Math.PI) / 3));
const COL_FAILSAFE = new THREE.Color(0xf3a531);
const COL_LOST = new THREE.Color(0x7a828c);
const COL_FLASH = new THREE.Color(0xff2222);
const COL_WHITE = new THREE.Color(0xffffff);
const COL_SELECT = new THREE.Color(0x4fb3ff);

export function droneColour(id, out = new THREE.Color()) {
  // Golden-angle hues: neighbouring ids get well separated colours.
  return out.setHSL(((id * 0.381966) % 1 + 0.58) % 1, 0.78, 0.5);
}

// One instance per drone: on software GL (SwiftShader) each instance has a
// fixed cost (about 25 us here), so the whole quadrotor (body, canopy, nose,
// arms, motors, blades) is one geometry, and the rotors spin in the vertex
// shader from a per-instance attribute of four angles. Low-poly (under 200
// vertices) and lit per vertex: on software GL the vertex and pixel counts
// are the cost, and flat faces under a directional and a hemisphere light
// look the same lit per vertex as per pixel.
// Vertex attributes: color (paint), bodyMask (1: takes the drone's instance
// colour), rotor (k: spins with rotor k; -1: rigid).
// lite (quality low): body, arms and blades only, under 100 vertices; the
// front arm is red instead of a nose.
function quadGeometry(arm, lite = false) {
  const parts = [];
  const add = (geo, hex, { body = 0, rotor = -1 } = {}) => {
    geo.deleteAttribute('uv');
    const n = geo.attributes.position.count, c = new THREE.Color(hex);
    const col = new Float32Array(3 * n);
    for (let i = 0; i < n; i++) c.toArray(col, 3 * i);
    geo.setAttribute('color', new THREE.BufferAttribute(col, 3));
    geo.setAttribute('bodyMask', new THREE.BufferAttribute(new Float32Array(n).fill(body), 1));
    geo.setAttribute('rotor', new THREE.BufferAttribute(new Float32Array(n).fill(rotor), 1));
    parts.push(geo);
  };
  const bodyL = arm * 0.95, bodyW = arm * 0.62, bodyH = arm * 0.3;
  add(new THREE.BoxGeometry(bodyL, bodyW, bodyH), 0xffffff, { body: 1 });
  if (!lite) add(new THREE.SphereGeometry(bodyW * 0.42, 6, 2, 0, Math.PI * 2, 0, Math.PI / 2).scale(1.3, 1, 0.8).translate(0, 0, bodyH / 2), 0xdde3ea);
  if (!lite) add(new THREE.BoxGeometry(arm * 0.12, arm * 0.22, arm * 0.12).translate(bodyL / 2, 0, 0), 0xff4d2e);  // nose: the front (body +x)
  if (lite) {
    // Four arms, the front two red.
    for (let k = 0; k < 4; k++) add(new THREE.BoxGeometry(arm, arm * 0.1, arm * 0.08).translate(arm / 2, 0, 0).rotateZ(ROTOR_ANGLE[k]), k === 0 || k === 2 ? 0xd8432a : 0x2f333a);
  } else {
    // Two straight arms: rotor 0 (-45 deg) to 1 (135), rotor 2 (45) to 3 (-135).
    add(new THREE.BoxGeometry(2 * arm, arm * 0.09, arm * 0.07).rotateZ(ROTOR_ANGLE[0]), 0x2f333a);
    add(new THREE.BoxGeometry(2 * arm, arm * 0.09, arm * 0.07).rotateZ(ROTOR_ANGLE[2]), 0x2f333a);
  }
  const rotorZ = arm * 0.17, prop = arm * 0.55;
  for (let k = 0; k < 4; k++) {
    const cx = Math.cos(ROTOR_ANGLE[k]) * arm, cy = Math.sin(ROTOR_ANGLE[k]) * arm;
    if (!lite) add(new THREE.CylinderGeometry(arm * 0.07, arm * 0.1, arm * 0.24, 6, 1, true).rotateX(Math.PI / 2).translate(cx, cy, arm * 0.05), 0x1b1d21);
    add(new THREE.PlaneGeometry(2 * prop, arm * 0.1).translate(cx, cy, rotorZ), k < 2 ? 0x0d0f12 : 0x2a2e35, { rotor: k });
  }
  return { geo: mergeGeometries(parts), rotorZ, prop, centres: ROTOR_ANGLE.map((a) => new THREE.Vector3(Math.cos(a) * arm, Math.sin(a) * arm, rotorZ)) };
}

// Per-vertex Lambert under the world's hemisphere and sun (same formula as
// three's MeshLambertMaterial), the drone's colour on the body only, rotor spin.
function quadMaterial(centres) {
  return new THREE.ShaderMaterial({
    vertexColors: true,
    fog: true,
    side: THREE.DoubleSide,
    uniforms: THREE.UniformsUtils.merge([THREE.UniformsLib.fog, {
      rotorCentre: { value: centres },
      uSunDir: { value: new THREE.Vector3(0, 0, 1) },
      uSun: { value: new THREE.Color(1, 1, 1) },
      uSky: { value: new THREE.Color(1, 1, 1) },
      uGround: { value: new THREE.Color(0.3, 0.3, 0.3) },
      uUp: { value: new THREE.Vector3(0, 0, 1) },
    }]),
    vertexShader: `
      #include <common>
      #include <fog_pars_vertex>
      attribute float bodyMask;
      attribute float rotor;
      attribute vec4 rotorPhase;
      uniform vec3 rotorCentre[4];
      uniform vec3 uSunDir, uSun, uSky, uGround, uUp;
      varying vec3 vLit;
      void main() {
        vec3 p = position;
        if (rotor > -0.5) {
          int k = int(rotor + 0.5);
          float a = rotorPhase[k];
          vec2 c = rotorCentre[k].xy, d = p.xy - c;
          p.xy = c + vec2(cos(a) * d.x - sin(a) * d.y, sin(a) * d.x + cos(a) * d.y);
        }
        mat4 m = modelMatrix * instanceMatrix;
        vec3 n = normalize(mat3(m) * normal);
        vec3 base = color;
        #ifdef USE_INSTANCING_COLOR
          base *= mix(vec3(1.0), instanceColor, bodyMask);
        #endif
        vec3 irradiance = mix(uGround, uSky, 0.5 * dot(n, uUp) + 0.5) + uSun * max(dot(n, uSunDir), 0.0);
        vLit = base * irradiance * RECIPROCAL_PI;
        vec4 mvPosition = viewMatrix * m * vec4(p, 1.0);
        gl_Position = projectionMatrix * mvPosition;
        #include <fog_vertex>
      }`,
    fragmentShader: LIT_FRAGMENT_SHADER,
  });
}

function discsGeometry(centres, prop) {
  return mergeGeometries(centres.map((c) => new THREE.CircleGeometry(prop * 1.02, 12).translate(c.x, c.y, c.z + 0.002)));
}

export class Drones {
  constructor(scene, { sun, hemi } = {}) {
    this.scene = scene;
    this.sun = sun;
    this.hemi = hemi;
    this.group = new THREE.Group();
    scene.add(this.group);
    this.n = 0;
    this.scale = 2;
    this.showTrails = true;
    this.showRays = false;
    this.blobShadows = false;
    this.selected = -1;
    this.tmp = { m: new THREE.Matrix4(), r: new THREE.Matrix4(), q: new THREE.Quaternion(), p: new THREE.Vector3(), s: new THREE.Vector3(), c: new THREE.Color(), v: new THREE.Vector3() };
  }

  // (Re)creates the meshes for n drones with the scene's arm length and rays.
  configure(n, arm = 0.2275, sensorCount = 8, groundZ = 0) {
    this.dispose();
    this.groundZ = groundZ;
    this.n = n;
    this.arm = arm > 0 ? arm : 0.2275;
    this.sensorCount = Math.max(0, Math.min(256, sensorCount | 0)); // rays per scan (rows x columns)
    const g = quadGeometry(this.arm);
    const mk = (geo, mat, count, shadow = true) => {
      const m = new THREE.InstancedMesh(geo, mat, count);
      m.instanceMatrix.setUsage(THREE.DynamicDrawUsage);
      m.frustumCulled = false;
      m.castShadow = shadow;
      m.count = 0;
      this.group.add(m);
      return m;
    };
    this.phase = new THREE.InstancedBufferAttribute(new Float32Array(4 * n), 4).setUsage(THREE.DynamicDrawUsage);
    g.geo.setAttribute('rotorPhase', this.phase);
    this.geoFull = g.geo;
    this.geoLite = quadGeometry(this.arm, true).geo;
    this.geoLite.setAttribute('rotorPhase', this.phase);
    this.quads = mk(this.blobShadows ? this.geoLite : this.geoFull, quadMaterial(g.centres), n);
    this.quads.instanceColor = new THREE.InstancedBufferAttribute(new Float32Array(3 * n), 3).setUsage(THREE.DynamicDrawUsage);
    // Blur discs while the motors turn (not at quality low: one more instance a drone).
    this.discs = mk(discsGeometry(g.centres, g.prop), new THREE.MeshBasicMaterial({ color: 0xcfd6de, transparent: true, opacity: 0.22, depthWrite: false, side: THREE.DoubleSide }), n, false);
    this.discs.visible = !this.blobShadows;
    this.rings = mk(new THREE.RingGeometry(this.arm * 2.0, this.arm * 2.5, 24), new THREE.MeshBasicMaterial({ color: 0xffffff, transparent: true, opacity: 0.9, depthWrite: false, side: THREE.DoubleSide }), n, false);
    this.rings.instanceColor = new THREE.InstancedBufferAttribute(new Float32Array(3 * n), 3).setUsage(THREE.DynamicDrawUsage);
    // Blob shadows, for when the world has no shadow maps (quality low).
    // Blob shadows (quality low): one plain geometry of n hexagons moved on
    // the CPU, not an InstancedMesh: on SwiftShader 128 instances of a tiny
    // transparent disc cost more than rewriting 128 x 18 vertices.
    const bg = new THREE.BufferGeometry();
    bg.setAttribute('position', new THREE.BufferAttribute(new Float32Array(n * 18 * 3), 3).setUsage(THREE.DynamicDrawUsage));
    this.blobs = new THREE.Mesh(bg, new THREE.MeshBasicMaterial({ color: 0x000000, transparent: true, opacity: 0.22, depthWrite: false }));
    this.blobs.frustumCulled = false;
    this.blobs.visible = this.blobShadows;
    this.group.add(this.blobs);

    this.pos = new Float64Array(3 * n);       // as rendered
    this.quat = new Float32Array(4 * n);
    this.w = new Float32Array(4 * n);
    this.angle = new Float32Array(4 * n).map(() => Math.random() * Math.PI);
    this.flags = new Uint16Array(n);
    this.flashUntil = new Float64Array(n);
    this.colSum = new Float64Array(n).fill(-1);
    this.present = new Uint8Array(n);
    this.base = Array.from({ length: n }, (_, i) => droneColour(i));
    this.count = 0;
    this.liveKnown = false;
    this.liveMask = new Uint8Array(n);

    // Trails: slot k of drone i is segment (k * n + i): two vertices.
    this.trailSlots = Math.max(32, Math.min(TRAIL_MAX_SLOTS, Math.floor(TRAIL_BUDGET / n)));
    this.trailDt = Math.max(0.25, 30 / this.trailSlots);
    this.trailFilled = 0;
    const tv = this.trailSlots * n * 2;
    const tg = new THREE.BufferGeometry();
    tg.setAttribute('position', new THREE.BufferAttribute(new Float32Array(3 * tv), 3).setUsage(THREE.DynamicDrawUsage));
    tg.setAttribute('tcolor', new THREE.BufferAttribute(new Float32Array(3 * tv), 3).setUsage(THREE.DynamicDrawUsage));
    tg.setAttribute('stamp', new THREE.BufferAttribute(new Float32Array(tv).fill(-1e9), 1).setUsage(THREE.DynamicDrawUsage));
    this.trailMat = new THREE.ShaderMaterial({
      uniforms: { uNow: { value: 0 }, uLife: { value: TRAIL_LIFE } },
      vertexShader: `attribute vec3 tcolor; attribute float stamp; uniform float uNow, uLife;
        varying vec3 vC; varying float vA;
        void main() { vC = tcolor; vA = 1.0 - (uNow - stamp) / uLife;
          gl_Position = projectionMatrix * modelViewMatrix * vec4(position, 1.0); }`,
      fragmentShader: `varying vec3 vC; varying float vA;
        void main() { if (vA <= 0.0) discard; gl_FragColor = vec4(vC, 0.25 + 0.65 * vA); }`,
      transparent: true, depthWrite: false,
    });
    tg.setDrawRange(0, 0);
    this.trails = new THREE.LineSegments(tg, this.trailMat);
    this.trails.frustumCulled = false;
    this.trails.visible = this.showTrails;
    this.group.add(this.trails);
    this.trailSlot = 0;
    this.trailT = -Infinity;
    this.trailLast = new Float32Array(3 * n);
    this.trailHasLast = new Uint8Array(n);

    // Rays: per drone sensorCount segments.
    const rv = Math.max(1, this.sensorCount) * n * 2;
    const rg = new THREE.BufferGeometry();
    rg.setAttribute('position', new THREE.BufferAttribute(new Float32Array(3 * rv), 3).setUsage(THREE.DynamicDrawUsage));
    rg.setAttribute('color', new THREE.BufferAttribute(new Float32Array(3 * rv), 3).setUsage(THREE.DynamicDrawUsage));
    this.rays = new THREE.LineSegments(rg, new THREE.LineBasicMaterial({ vertexColors: true, transparent: true, opacity: 0.8, depthWrite: false }));
    this.rays.frustumCulled = false;
    this.rays.visible = this.showRays;
    this.group.add(this.rays);
  }

  dispose() {
    this.geoFull?.dispose();
    this.geoLite?.dispose();
    for (const c of [...this.group.children]) {
      this.group.remove(c);
      c.geometry?.dispose();
      c.material?.dispose();
      c.dispose?.();
    }
    this.n = 0;
    this.count = 0;
  }

  clearTrails() {
    if (!this.n) return;
    const st = this.trails.geometry.attributes.stamp;
    st.array.fill(-1e9);
    st.clearUpdateRanges();
    st.needsUpdate = true;
    this.trailHasLast.fill(0);
    this.trailT = -Infinity;
    this.trailSlot = 0;
    this.trailFilled = 0;
    this.trails.geometry.setDrawRange(0, 0);
  }

  // Applies a `frame` message: positions, attitude, rotor speeds, flags.
  applyFrame(f, nowMs) {
    const ds = f.drones ?? [];
    let count = 0;
    this.present.fill(0);
    for (const d of ds) {
      const i = d?.id;
      if (!Number.isInteger(i) || i < 0 || i >= this.n || !Array.isArray(d.p)) continue;
      this.present[i] = 1;
      count++;
      this.pos[3 * i] = d.p[0]; this.pos[3 * i + 1] = d.p[1]; this.pos[3 * i + 2] = d.p[2];
      const q = Array.isArray(d.q) ? d.q : [1, 0, 0, 0];
      // [w,x,y,z] -> three's (x,y,z,w)
      this.quat[4 * i] = q[1]; this.quat[4 * i + 1] = q[2]; this.quat[4 * i + 2] = q[3]; this.quat[4 * i + 3] = q[0];
      for (let k = 0; k < 4; k++) this.w[4 * i + k] = Array.isArray(d.w) ? d.w[k] || 0 : 0;
      this.flags[i] = d.flags | 0;
      const col = Array.isArray(d.col) ? d.col[0] + d.col[1] + d.col[2] : 0;
      if (this.colSum[i] >= 0 && col > this.colSum[i]) this.flash(i, nowMs);
      this.colSum[i] = col;
    }
    this.count = count;
    const t = f.t;
    if (Number.isFinite(t)) {
      if (t < this.trailT - 1e-6) this.clearTrails();   // the clock went back: a seek or a new run
      if (t - this.trailT >= this.trailDt) this.addTrailPoint(t);
      this.trailMat.uniforms.uNow.value = t;
    }
    if (this.showRays && Array.isArray(f.rays)) this.applyRays(f.rays);
  }

  flash(i, nowMs = performance.now()) {
    if (i >= 0 && i < this.n) this.flashUntil[i] = nowMs + FLASH_MS;
  }

  addTrailPoint(t) {
    const n = this.n, slot = this.trailSlot;
    const pa = this.trails.geometry.attributes.position, ca = this.trails.geometry.attributes.tcolor, sa = this.trails.geometry.attributes.stamp;
    const P = pa.array, C = ca.array, S = sa.array;
    for (let i = 0; i < n; i++) {
      const v = 2 * (slot * n + i);
      const x = this.pos[3 * i], y = this.pos[3 * i + 1], z = this.pos[3 * i + 2];
      if (!this.present[i] || !this.trailHasLast[i]) {
        S[v] = S[v + 1] = -1e9;
      } else {
        P.set([this.trailLast[3 * i], this.trailLast[3 * i + 1], this.trailLast[3 * i + 2], x, y, z], 3 * v);
        const c = this.base[i];
        C.set([c.r, c.g, c.b, c.r, c.g, c.b], 3 * v);
        S[v] = this.trailT; S[v + 1] = t;
      }
      if (this.present[i]) {
        this.trailLast[3 * i] = x; this.trailLast[3 * i + 1] = y; this.trailLast[3 * i + 2] = z;
        this.trailHasLast[i] = 1;
      }
    }
    // Only the slot just written goes to the GPU.
    for (const [a, size] of [[pa, 3], [ca, 3], [sa, 1]]) {
      a.clearUpdateRanges();
      a.addUpdateRange(2 * slot * n * size, 2 * n * size);
      a.needsUpdate = true;
    }
    this.trailSlot = (slot + 1) % this.trailSlots;
    this.trailT = t;
    this.trailFilled = Math.min(this.trailSlots, this.trailFilled + 1);
    this.trails.geometry.setDrawRange(0, this.trailFilled * n * 2);
  }

  applyRays(rays) {
    const n = this.n, m = this.sensorCount;
    if (!m) return;
    const pa = this.rays.geometry.attributes.position, ca = this.rays.geometry.attributes.color;
    const P = pa.array, C = ca.array;
    const { q, v } = this.tmp;
    let seg = 0;
    for (let i = 0; i < n && i < rays.length; i++) {
      const r = rays[i];
      if (!this.present[i] || !r || !Array.isArray(r.a) || !Array.isArray(r.r)) continue;
      q.set(this.quat[4 * i], this.quat[4 * i + 1], this.quat[4 * i + 2], this.quat[4 * i + 3]);
      const x = this.pos[3 * i], y = this.pos[3 * i + 1], z = this.pos[3 * i + 2];
      const e = Array.isArray(r.e) ? r.e : [];
      for (let k = 0; k < Math.min(m, r.a.length); k++) {
        const len = r.r[k];
        if (!Number.isFinite(len)) continue;
        // Body yaw and elevation (up from the body x-y plane; 0: the ring), turned with the body.
        const el = Number.isFinite(e[k]) ? e[k] : 0, ce = Math.cos(el);
        v.set(ce * Math.cos(r.a[k]), ce * Math.sin(r.a[k]), Math.sin(el)).applyQuaternion(q).multiplyScalar(len);
        P.set([x, y, z, x + v.x, y + v.y, z + v.z], 6 * seg);
        const hit = r.hit?.[k];
        if (hit) C.set([1, 0.45, 0.1, 1, 0.25, 0.05], 6 * seg);
        else C.set([0.25, 0.65, 1, 0.25, 0.65, 1], 6 * seg);
        seg++;
      }
    }
    this.rays.geometry.setDrawRange(0, 2 * seg);
    pa.needsUpdate = ca.needsUpdate = true;
  }

  setRays(on) {
    this.showRays = on;
    if (this.rays) this.rays.visible = on;
  }

  // Quality low: blob shadows instead of shadow maps, no blur discs.
  setBlobShadows(on) {
    this.blobShadows = on;
    if (this.blobs) this.blobs.visible = on;
    if (this.discs) this.discs.visible = !on;
    if (this.quads) {
      this.quads.castShadow = !on;
      this.quads.geometry = on ? this.geoLite : this.geoFull;
    }
  }

  setTrails(on) {
    this.showTrails = on;
    if (this.trails) this.trails.visible = on;
  }

  // Per drawn frame: instance matrices, rotor angles, colours.
  // The server's list of live agents (status.live) overrides the per-drone
  // AGENT_LIVE bit, which is only as fresh as the last published tick (a
  // paused lockstep swarm still shows tick 0's).
  setLive(ids) {
    if (!this.n) return;
    if (!Array.isArray(ids)) { this.liveKnown = false; return; }
    this.liveMask = new Uint8Array(this.n);
    for (const i of ids) if (i >= 0 && i < this.n) this.liveMask[i] = 1;
    this.liveKnown = true;
  }

  isLost(i) {
    return this.liveKnown ? !this.liveMask[i] : !(this.flags[i] & FLAG.AGENT_LIVE);
  }

  update(dt, nowMs) {
    const n = this.n;
    if (!n) return;
    const { m, r, q, p, s, c } = this.tmp;
    const sc = this.scale;
    let b = 0, ringN = 0, discN = 0;
    const P = this.phase.array;
    for (let i = 0; i < n; i++) {
      if (!this.present[i]) continue;
      p.set(this.pos[3 * i], this.pos[3 * i + 1], this.pos[3 * i + 2]);
      q.set(this.quat[4 * i], this.quat[4 * i + 1], this.quat[4 * i + 2], this.quat[4 * i + 3]);
      if (q.lengthSq() < 1e-12) q.identity(); else q.normalize();
      m.compose(p, q, s.set(sc, sc, sc));
      this.quads.setMatrixAt(b, m);
      for (let k = 0; k < 4; k++) {
        const j = 4 * i + k;
        this.angle[j] = (this.angle[j] + ROTOR_SPIN[k] * this.w[j] * SPIN_SCALE * dt) % (2 * Math.PI);
        P[4 * b + k] = this.angle[j];
      }
      if ((this.flags[i] & FLAG.MOTORS_ON) !== 0 || this.w[4 * i] > 1) this.discs.setMatrixAt(discN++, m);
      // Body colour: collision flash over failsafe / lost over the drone's own.
      const flags = this.flags[i];
      const mark = flags & FLAG.FAILSAFE ? COL_FAILSAFE : this.isLost(i) ? COL_LOST : null;
      c.copy(mark ?? this.base[i]);
      const left = this.flashUntil[i] - nowMs;
      if (left > 0) {
        const f = left / FLASH_MS, pulse = 0.5 + 0.5 * Math.cos((1 - f) * Math.PI * 6);
        c.lerp(COL_FLASH, Math.min(1, 1.2 * f)).lerp(COL_WHITE, 0.35 * pulse * f);
      }
      this.quads.setColorAt(b, c);
      // Ring under marked or selected drones (only those are drawn).
      if (mark || i === this.selected || left > 0) {
        const ringColour = left > 0 ? COL_FLASH : mark ?? COL_SELECT;
        r.makeTranslation(p.x, p.y, p.z - this.arm * 0.5 * sc);
        r.scale(s.set(sc, sc, sc));
        this.rings.setMatrixAt(ringN, r);
        this.rings.setColorAt(ringN, ringColour);
        ringN++;
      }
      if (this.blobShadows) {
        const rad = this.arm * 1.15 * sc * Math.max(0.35, 1 - (p.z - this.groundZ) / 25), z = this.groundZ + 0.02;
        const B = this.blobs.geometry.attributes.position.array;
        for (let k = 0, o = 54 * b; k < 6; k++, o += 9) {
          B[o] = p.x; B[o + 1] = p.y; B[o + 2] = z;
          B[o + 3] = p.x + rad * HEX[2 * k]; B[o + 4] = p.y + rad * HEX[2 * k + 1]; B[o + 5] = z;
          B[o + 6] = p.x + rad * HEX[2 * k + 2]; B[o + 7] = p.y + rad * HEX[2 * k + 3]; B[o + 8] = z;
        }
      }
      b++;
    }
    this.quads.count = b;
    if (this.blobShadows) {
      this.blobs.geometry.setDrawRange(0, 18 * b);
      this.blobs.geometry.attributes.position.needsUpdate = true;
    }
    this.rings.count = ringN;
    this.discs.count = discN;
    for (const mesh of [this.quads, this.discs, this.rings]) mesh.instanceMatrix.needsUpdate = true;
    this.phase.needsUpdate = true;
    const u = this.quads.material.uniforms;
    if (this.sun) {
      u.uSunDir.value.subVectors(this.sun.position, this.sun.target.position).normalize();
      u.uSun.value.copy(this.sun.color).multiplyScalar(this.sun.intensity);
    }
    if (this.hemi) {
      u.uSky.value.copy(this.hemi.color).multiplyScalar(this.hemi.intensity);
      u.uGround.value.copy(this.hemi.groundColor).multiplyScalar(this.hemi.intensity);
      u.uUp.value.copy(this.hemi.position).normalize();
    }
    this.quads.instanceColor.needsUpdate = true;
    this.rings.instanceColor.needsUpdate = true;
  }

  // Centroid and radius of the drones shown.
  centroid(out = new THREE.Vector3()) {
    let k = 0;
    out.set(0, 0, 0);
    for (let i = 0; i < this.n; i++) {
      if (!this.present[i]) continue;
      out.x += this.pos[3 * i]; out.y += this.pos[3 * i + 1]; out.z += this.pos[3 * i + 2];
      k++;
    }
    if (!k) return null;
    out.multiplyScalar(1 / k);
    let rad = 0;
    for (let i = 0; i < this.n; i++) {
      if (!this.present[i]) continue;
      rad = Math.max(rad, Math.hypot(this.pos[3 * i] - out.x, this.pos[3 * i + 1] - out.y, this.pos[3 * i + 2] - out.z));
    }
    out.radius = rad;
    return out;
  }

  // The drones as rendered (for the test hook).
  snapshot() {
    const out = [];
    for (let i = 0; i < this.n; i++) {
      if (this.present[i]) out.push({ id: i, p: [this.pos[3 * i], this.pos[3 * i + 1], this.pos[3 * i + 2]], flags: this.flags[i] });
    }
    return out;
  }
}
