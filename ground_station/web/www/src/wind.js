// The wind as the scene states it: the server's mean wind as arrows on a
// grid over the world, and particles carried by it; with turbulence on, each
// particle also wanders with the Dryden intensities the server flies (a
// picture of how strong the gusts are, not the server's field itself, which
// only the server evaluates). Hidden in calm air.
import * as THREE from 'three';

const ARROWS_MAX = 400;
const PARTICLES = 600;

export class WindLayer {
  constructor(scene) {
    this.group = new THREE.Group();
    scene.add(this.group);
    this.info = { speed: 0, arrows: 0, particles: 0, turbulence: false, sigma: [0, 0, 0], gusts_per_minute: 0 };
  }

  set(wind, bounds, z0) {
    for (const c of [...this.group.children]) {
      this.group.remove(c);
      c.geometry?.dispose();
      c.material?.dispose();
    }
    this.points = null;
    const w = wind ?? {};
    const finite = (a) => [0, 1, 2].map((k) => (Number.isFinite(a?.[k]) ? a[k] : 0));  // null: unknown
    const steady = new THREE.Vector3(...finite(w.steady));
    const sigma = finite(w.sigma);
    const speed = steady.length();
    const calm = speed === 0 && !w.turbulence && !(w.gusts_per_minute > 0);
    this.info = { speed, arrows: 0, particles: 0, turbulence: !!w.turbulence, sigma, gusts_per_minute: w.gusts_per_minute ?? 0 };
    if (calm) return;
    this.steady = steady;
    this.sigma = sigma;
    this.bounds = bounds.clone();
    const size = bounds.getSize(new THREE.Vector3());

    // Arrows: one per cell of a grid 2.5 m above the ground, up to ARROWS_MAX.
    if (speed > 0) {
      const step = Math.max(8, Math.sqrt((size.x * size.y) / ARROWS_MAX));
      const len = Math.min(step * 0.8, 1.2 * speed);
      const shaft = new THREE.CylinderGeometry(0.06, 0.06, len * 0.75, 6).translate(0, len * 0.375, 0);
      const head = new THREE.ConeGeometry(0.25, len * 0.25, 8).translate(0, len * 0.875, 0);
      const geo = mergeTwo(shaft, head);
      const cells = [];
      for (let x = bounds.min.x + step / 2; x < bounds.max.x; x += step)
        for (let y = bounds.min.y + step / 2; y < bounds.max.y; y += step) cells.push([x, y]);
      const arrows = new THREE.InstancedMesh(geo, new THREE.MeshBasicMaterial({ color: 0x2f6fb0, transparent: true, opacity: 0.7 }), cells.length);
      const q = new THREE.Quaternion().setFromUnitVectors(new THREE.Vector3(0, 1, 0), steady.clone().normalize());
      const m = new THREE.Matrix4();
      cells.forEach(([x, y], i) => arrows.setMatrixAt(i, m.compose(new THREE.Vector3(x, y, z0 + 2.5), q, new THREE.Vector3(1, 1, 1))));
      arrows.computeBoundingSphere();
      this.group.add(arrows);
      this.info.arrows = cells.length;
    }

    // Particles: spread over the bounds up to 15 m, carried by the mean wind.
    const pos = new Float32Array(3 * PARTICLES);
    const top = Math.min(bounds.max.z, z0 + 15);
    for (let i = 0; i < PARTICLES; i++) {
      pos[3 * i] = bounds.min.x + Math.random() * size.x;
      pos[3 * i + 1] = bounds.min.y + Math.random() * size.y;
      pos[3 * i + 2] = z0 + 0.5 + Math.random() * (top - z0 - 0.5);
    }
    const geo = new THREE.BufferGeometry();
    geo.setAttribute('position', new THREE.BufferAttribute(pos, 3));
    this.points = new THREE.Points(geo, new THREE.PointsMaterial({ color: 0xf4f8ff, size: 0.18, transparent: true, opacity: 0.85 }));
    this.points.frustumCulled = false;
    this.group.add(this.points);
    this.info.particles = PARTICLES;
    this.top = top;
    this.z0 = z0;
  }

  // dt: s of wall time; the particles move at the wind's speed (rate 1).
  update(dt) {
    if (!this.points || !(dt > 0)) return;
    const p = this.points.geometry.attributes.position;
    const a = p.array, b = this.bounds, s = this.sigma, v = this.steady;
    const k = Math.sqrt(Math.min(dt, 0.1));
    for (let i = 0; i < a.length; i += 3) {
      a[i] += v.x * dt + (Math.random() - 0.5) * 3.4 * s[0] * k;
      a[i + 1] += v.y * dt + (Math.random() - 0.5) * 3.4 * s[1] * k;
      a[i + 2] += v.z * dt + (Math.random() - 0.5) * 3.4 * s[2] * k;
      if (a[i] > b.max.x) a[i] -= b.max.x - b.min.x; else if (a[i] < b.min.x) a[i] += b.max.x - b.min.x;
      if (a[i + 1] > b.max.y) a[i + 1] -= b.max.y - b.min.y; else if (a[i + 1] < b.min.y) a[i + 1] += b.max.y - b.min.y;
      if (a[i + 2] > this.top) a[i + 2] = this.z0 + 0.5; else if (a[i + 2] < this.z0 + 0.5) a[i + 2] = this.top;
    }
    p.needsUpdate = true;
  }
}

// The two parts of an arrow as one geometry (non-indexed).
function mergeTwo(a, b) {
  const x = a.toNonIndexed(), y = b.toNonIndexed();
  const pos = new Float32Array(x.attributes.position.count * 3 + y.attributes.position.count * 3);
  pos.set(x.attributes.position.array, 0);
  pos.set(y.attributes.position.array, x.attributes.position.array.length);
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.BufferAttribute(pos, 3));
  g.computeVertexNormals();
  return g;
}
