// The static world: renderer, lights, ground, pillars, boxes, mesh
// obstacles, the wind, finish line, world bounds and goal, built from the
// bridge's `scene` message; and the
// three camera modes. Coordinates are the simulation's ENU metres as they
// are (x east, y north, z up): every camera has up = +z except the top-down
// one, whose screen-up is north.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { MeshLayer } from './meshes.js';
import { WindLayer } from './wind.js';

// The fragment half of the vertex-lit materials (pillars here, drones in
// drones.js): the vertex shader computes vLit, this only writes it out.
export const LIT_FRAGMENT_SHADER = `
  #include <common>
  #include <fog_pars_fragment>
  varying vec3 vLit;
  void main() {
    gl_FragColor = vec4(vLit, 1.0);
    #include <tonemapping_fragment>
    #include <colorspace_fragment>
    #include <fog_fragment>
  }`;

const Z_UP = new THREE.Vector3(0, 0, 1);

// Lit surfaces. Lambert, not the physically based standard material: on
// software GL (headless Chromium's SwiftShader) the per-pixel cost decides
// the frame rate, and matte Lambert looks the same on these plain shapes.
export const surfaceKind = new URLSearchParams(location.search).get('pbr') === '1' ? 'standard' : 'lambert';
export function surface({ roughness, metalness, ...p }) {
  if (surfaceKind !== 'standard') return new THREE.MeshLambertMaterial(p);
  return new THREE.MeshStandardMaterial({ roughness: roughness ?? 0.8, metalness: metalness ?? 0, ...p });
}

// Quality levels, best first. On software GL (SwiftShader, llvmpipe) the
// per-pixel cost decides the frame rate, so 'auto' starts there at medium
// and steps down while the page draws fewer than 27 frames a second.
//   high:   multisampling (when the context has it), soft shadow maps, full pixel ratio
//   medium: hard shadow maps (one tap), pixel ratio 1
//   low:    no shadow maps (blob shadows under the drones), pixel ratio 0.75, and
//           no ground plane: the ground is the clear colour and only the sky
//           above the horizon is drawn (a full-screen plane is the costliest
//           thing on software GL)
export const QUALITY = ['high', 'medium', 'low'];

export function softwareGL() {
  try {
    const gl = document.createElement('canvas').getContext('webgl2');
    const ext = gl?.getExtension('WEBGL_debug_renderer_info');
    const name = ext ? gl.getParameter(ext.UNMASKED_RENDERER_WEBGL) : gl?.getParameter(gl.RENDERER) ?? '';
    gl?.getExtension('WEBGL_lose_context')?.loseContext();
    return { software: /swiftshader|llvmpipe|software|softpipe/i.test(name), name };
  } catch {
    return { software: false, name: '' };
  }
}

export class World {
  constructor(container, { quality = 'auto', pixelRatio = window.devicePixelRatio || 1 } = {}) {
    this.container = container;
    this.gl = softwareGL();
    this.auto = !QUALITY.includes(quality);
    const start = this.auto ? (this.gl.software ? 'medium' : 'high') : quality;
    this.dpr = pixelRatio;
    const renderer = new THREE.WebGLRenderer({ antialias: start === 'high', powerPreference: 'high-performance' });
    renderer.shadowMap.enabled = true;
    renderer.toneMapping = THREE.ACESFilmicToneMapping;
    renderer.toneMappingExposure = 1.05;
    container.prepend(renderer.domElement);
    this.renderer = renderer;
    this.onQuality = null;

    const scene = new THREE.Scene();
    scene.background = new THREE.Color(0xc9dbe8);
    scene.fog = new THREE.Fog(0xc9dbe8, 150, 420);
    this.scene = scene;

    const hemi = new THREE.HemisphereLight(0xe8f2ff, 0x55604a, 1.6);
    hemi.position.set(0, 0, 1);
    scene.add(hemi);
    this.hemi = hemi;
    const sun = new THREE.DirectionalLight(0xfff1dc, 2.6);
    sun.castShadow = true;
    sun.shadow.mapSize.set(2048, 2048);
    sun.shadow.bias = -0.0004;
    sun.shadow.normalBias = 0.03;
    scene.add(sun, sun.target);
    this.sun = sun;
    this.groundLit = surface({ color: 0x8fa38a, roughness: 0.95 });
    this.groundColour = new THREE.Color(0x9fb39a);
    this.skyColour = new THREE.Color(0xc9dbe8);
    this.sky = skyDome(this.skyColour, this.groundColour);
    scene.add(this.sky);
    this.quality = start;

    // Perspective camera for orbit and follow.
    this.camera = new THREE.PerspectiveCamera(50, 1, 0.1, 1500);
    this.camera.up.copy(Z_UP);
    this.camera.position.set(0, -30, 20);
    this.controls = new OrbitControls(this.camera, renderer.domElement);
    this.controls.enableDamping = true;
    this.controls.dampingFactor = 0.12;
    this.controls.maxPolarAngle = Math.PI * 0.495;  // stay above the ground
    this.controls.target.set(0, 10, 0);

    // Orthographic top-down camera: north up, pan and zoom only.
    this.top = new THREE.OrthographicCamera(-1, 1, 1, -1, 0.1, 2000);
    this.top.up.set(0, 1, 0);
    this.topControls = new OrbitControls(this.top, renderer.domElement);
    this.topControls.enableRotate = false;
    this.topControls.screenSpacePanning = true;
    this.topControls.enabled = false;
    this.topHeight = 60;  // m of world shown vertically at zoom 1

    this.litMeshes = [];
    this.mode = 'orbit';
    this.followTarget = new THREE.Vector3();
    this.followValid = false;
    this.staticGroup = new THREE.Group();
    scene.add(this.staticGroup);
    this.bounds = new THREE.Box3(new THREE.Vector3(-40, -20, 0), new THREE.Vector3(40, 100, 30));
    this.meshLayer = new MeshLayer(surface({ color: 0xc8b8a2, roughness: 0.85, side: THREE.DoubleSide }));
    this.wind = new WindLayer(scene);

    new ResizeObserver(() => this.resize()).observe(container);
    this.setQuality(start);
  }

  setQuality(q) {
    if (!QUALITY.includes(q)) return;
    this.quality = q;
    const r = this.renderer;
    r.setPixelRatio(q === 'high' ? Math.min(this.dpr, 2) : q === 'medium' ? 1 : 0.75);
    r.shadowMap.enabled = q !== 'low';
    r.shadowMap.type = q === 'high' ? THREE.PCFShadowMap : THREE.BasicShadowMap;
    r.shadowMap.needsUpdate = true;
    if (this.ground) this.ground.visible = q !== 'low';
    this.applyLitQuality();
    this.sky.visible = q === 'low';
    this.scene.background = q === 'low' ? this.groundColour : this.skyColour;
    this.scene.traverse((o) => { if (o.material) [].concat(o.material).forEach((m) => { m.needsUpdate = true; }); });
    this.resize();
    this.onQuality?.(q);
  }

  // Quality low lights the pillars and boxes per vertex (cheaper pixels).
  applyLitQuality() {
    for (const m of this.litMeshes ?? []) m.material = this.quality === 'low' ? m.userData.flat : m.userData.lit;
  }

  // One step down, for 'auto' when frames are slow; false at the bottom.
  lowerQuality() {
    const i = QUALITY.indexOf(this.quality);
    if (i < 0 || i + 1 >= QUALITY.length) return false;
    this.setQuality(QUALITY[i + 1]);
    return true;
  }

  resize() {
    const w = Math.max(1, this.container.clientWidth), h = Math.max(1, this.container.clientHeight);
    this.renderer.setSize(w, h, false);
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
    const a = w / h, hh = this.topHeight / 2;
    Object.assign(this.top, { left: -hh * a, right: hh * a, top: hh, bottom: -hh });
    this.top.updateProjectionMatrix();
  }

  get activeCamera() { return this.mode === 'top' ? this.top : this.camera; }

  // Builds the static scene from a `scene` message.
  setScene(s) {
    for (const c of [...this.staticGroup.children]) {
      this.staticGroup.remove(c);
      c.traverse((o) => {
        o.geometry?.dispose();
        if (o.material && o !== this.ground) [].concat(o.material).forEach((m) => { m.map?.dispose(); m.dispose(); });
      });
    }
    const g = this.staticGroup;
    this.litMeshes = [];
    const z0 = s.ground_z ?? 0;
    const bmin = new THREE.Vector3(...(s.bounds_min ?? [-40, -20, z0]));
    const bmax = new THREE.Vector3(...(s.bounds_max ?? [40, 100, z0 + 30]));
    this.bounds.set(bmin, bmax);
    const size = new THREE.Vector3().subVectors(bmax, bmin);
    const centre = new THREE.Vector3().addVectors(bmin, bmax).multiplyScalar(0.5);

    // Ground: a plane beyond the bounds, with a 5 m grid over the bounds.
    const margin = Math.max(60, 0.5 * Math.max(size.x, size.y));
    const ground = new THREE.Mesh(new THREE.PlaneGeometry(size.x + 2 * margin, size.y + 2 * margin), this.groundLit);
    ground.visible = this.quality !== 'low';
    this.ground = ground;
    ground.position.set(centre.x, centre.y, z0);
    ground.receiveShadow = true;
    g.add(ground);
    const step = 5;
    const gw = Math.ceil(size.x / step) * step, gh = Math.ceil(size.y / step) * step;
    const grid = [];
    for (let x = -gw / 2; x <= gw / 2 + 1e-9; x += step) grid.push(centre.x + x, centre.y - gh / 2, z0 + 0.01, centre.x + x, centre.y + gh / 2, z0 + 0.01);
    for (let y = -gh / 2; y <= gh / 2 + 1e-9; y += step) grid.push(centre.x - gw / 2, centre.y + y, z0 + 0.01, centre.x + gw / 2, centre.y + y, z0 + 0.01);
    const gridGeo = new THREE.BufferGeometry();
    gridGeo.setAttribute('position', new THREE.Float32BufferAttribute(grid, 3));
    g.add(new THREE.LineSegments(gridGeo, new THREE.LineBasicMaterial({ color: 0x6e8069, transparent: true, opacity: 0.55 })));

    // Pillars and boxes, instanced.
    const concrete = surface({ color: 0xd6d0c4, roughness: 0.85 });
    const cyl = s.cylinders ?? [];
    if (cyl.length) {
      const geo = new THREE.CylinderGeometry(1, 1, 1, 40).rotateX(Math.PI / 2).translate(0, 0, 0.5);
      const mesh = new THREE.InstancedMesh(geo, concrete, cyl.length);
      this.litMeshes.push(mesh);
      const m = new THREE.Matrix4();
      cyl.forEach((c, i) => mesh.setMatrixAt(i, m.makeScale(c.r, c.r, c.h).setPosition(c.x, c.y, z0)));
      mesh.castShadow = mesh.receiveShadow = true;
      mesh.computeBoundingSphere();
      g.add(mesh);
    }
    const boxes = s.boxes ?? [];
    if (boxes.length) {
      const mesh = new THREE.InstancedMesh(new THREE.BoxGeometry(1, 1, 1), surface({ color: 0xb9a48a, roughness: 0.8 }), boxes.length);
      this.litMeshes.push(mesh);
      const m = new THREE.Matrix4(), q = new THREE.Quaternion();
      boxes.forEach((b, i) => {
        q.setFromAxisAngle(Z_UP, b.yaw ?? 0);
        mesh.setMatrixAt(i, m.compose(new THREE.Vector3(...b.c), q, new THREE.Vector3(...b.s)));
      });
      mesh.castShadow = mesh.receiveShadow = true;
      mesh.computeBoundingSphere();
      g.add(mesh);
    }

    // Mesh obstacles (fetched from the bridge) and the wind.
    this.meshLayer.set(s.meshes, g);
    this.wind.set(s.wind, this.bounds, z0);

    // Finish line: a chequered strip on the ground with a post at each end.
    if (s.finish_a && s.finish_b) {
      const a = new THREE.Vector2(s.finish_a[0], s.finish_a[1]), b = new THREE.Vector2(s.finish_b[0], s.finish_b[1]);
      const len = a.distanceTo(b);
      if (len > 0) {
        const tex = chequerTexture();
        tex.wrapS = THREE.RepeatWrapping;
        tex.repeat.set(Math.max(1, Math.round(len / 1.6)), 1);
        const strip = new THREE.Mesh(new THREE.PlaneGeometry(len, 0.8),
          surface({ map: tex, roughness: 0.7, polygonOffset: true, polygonOffsetFactor: -2 }));
        strip.position.set((a.x + b.x) / 2, (a.y + b.y) / 2, z0 + 0.02);
        strip.rotation.z = Math.atan2(b.y - a.y, b.x - a.x);
        strip.receiveShadow = true;
        g.add(strip);
        const postGeo = new THREE.CylinderGeometry(0.12, 0.12, 4, 12).rotateX(Math.PI / 2).translate(0, 0, 2);
        const postMat = surface({ color: 0x2b2f36, roughness: 0.5 });
        for (const p of [a, b]) {
          const post = new THREE.Mesh(postGeo, postMat);
          post.position.set(p.x, p.y, z0);
          post.castShadow = true;
          g.add(post);
        }
      }
    }

    // Goal: a ring on the ground and a floating diamond.
    if (s.goal) {
      const ring = new THREE.Mesh(new THREE.RingGeometry(1.3, 1.6, 48),
        new THREE.MeshBasicMaterial({ color: 0x2fbf71, transparent: true, opacity: 0.85, side: THREE.DoubleSide, depthWrite: false }));
      ring.position.set(s.goal[0], s.goal[1], z0 + 0.03);
      g.add(ring);
      const gem = new THREE.Mesh(new THREE.OctahedronGeometry(0.5), surface({ color: 0x2fbf71, emissive: 0x0e5a32, roughness: 0.3 }));
      gem.position.set(s.goal[0], s.goal[1], z0 + 4);
      gem.scale.set(1, 1, 1.6);
      gem.castShadow = true;
      g.add(gem);
      this.goalGem = gem;
    }

    // World bounds: a wireframe box.
    const boundsGeo = new THREE.EdgesGeometry(new THREE.BoxGeometry(size.x, size.y, size.z));
    const boundsLines = new THREE.LineSegments(boundsGeo, new THREE.LineBasicMaterial({ color: 0x34506b, transparent: true, opacity: 0.6 }));
    boundsLines.position.copy(centre);
    g.add(boundsLines);

    // The sun's shadow covers the bounds.
    const half = 0.5 * Math.hypot(size.x, size.y) + 5;
    this.sun.position.copy(centre).add(new THREE.Vector3(-0.45, -0.6, 1).normalize().multiplyScalar(half + size.z + 40));
    this.sun.target.position.copy(centre);
    const sc = this.sun.shadow.camera;
    Object.assign(sc, { left: -half, right: half, top: half, bottom: -half, near: 1, far: 2 * half + size.z + 100 });
    sc.updateProjectionMatrix();

    for (const m of this.litMeshes) { m.userData.lit = m.material; m.userData.flat = vertexLit(m.material.color, this); }
    this.applyLitQuality();
    this.scene.fog.near = 1.2 * Math.max(size.x, size.y);
    this.scene.fog.far = 4 * Math.max(size.x, size.y) + 200;
    this.fitTop();
  }

  // Top-down view over the whole bounds.
  fitTop() {
    const c = this.bounds.getCenter(new THREE.Vector3()), s = this.bounds.getSize(new THREE.Vector3());
    const a = this.camera.aspect;
    this.top.zoom = Math.min(this.topHeight / (s.y * 1.08), (this.topHeight * a) / (s.x * 1.08));
    this.top.position.set(c.x, c.y, this.bounds.max.z + 100);
    this.topControls.target.set(c.x, c.y, this.bounds.min.z);
    this.top.updateProjectionMatrix();
    this.topControls.update();
  }

  // Frames a group of points (e.g. the swarm) from behind (south), above.
  frame(centre, radius) {
    const d = Math.max(24, radius * 2.6);
    this.controls.target.copy(centre);
    this.camera.position.set(centre.x - 0.35 * d, centre.y - d, centre.z + d * 0.95);
    this.controls.update();
  }

  setMode(mode) {
    this.mode = mode;
    this.controls.enabled = mode !== 'top';
    this.topControls.enabled = mode === 'top';
    this.followValid = false;
  }

  // Called every frame with the swarm centroid (or null).
  update(dt, centroid) {
    if (this.mode === 'follow' && centroid) {
      if (!this.followValid) { this.followTarget.copy(this.controls.target); this.followValid = true; }
      const k = 1 - Math.exp(-dt * 4);
      const next = this.followTarget.clone().lerp(centroid, k);
      const delta = next.clone().sub(this.followTarget);
      this.followTarget.copy(next);
      this.controls.target.add(delta);
      this.camera.position.add(delta);
    }
    if (this.goalGem) this.goalGem.rotation.z += dt * 0.8;
    this.wind.update(dt);
    if (this.mode === 'top') this.topControls.update(); else this.controls.update();
  }

  render() {
    const cam = this.activeCamera;
    this.sky.position.copy(cam.position);
    this.renderer.render(this.scene, cam);
  }
}

// Lambert lit per vertex under the world's hemisphere light and sun (for
// quality low; the same formula as three's per-pixel MeshLambertMaterial).
function vertexLit(colour, world) {
  const sunDir = new THREE.Vector3().subVectors(world.sun.position, world.sun.target.position).normalize();
  return new THREE.ShaderMaterial({
    fog: true,
    uniforms: THREE.UniformsUtils.merge([THREE.UniformsLib.fog, {
      uColour: { value: colour.clone() },
      uSunDir: { value: sunDir },
      uSun: { value: world.sun.color.clone().multiplyScalar(world.sun.intensity) },
      uSky: { value: world.hemi.color.clone().multiplyScalar(world.hemi.intensity) },
      uGround: { value: world.hemi.groundColor.clone().multiplyScalar(world.hemi.intensity) },
    }]),
    vertexShader: `
      #include <common>
      #include <fog_pars_vertex>
      uniform vec3 uColour, uSunDir, uSun, uSky, uGround;
      varying vec3 vLit;
      void main() {
        mat4 m = modelMatrix;
        #ifdef USE_INSTANCING
          m = m * instanceMatrix;
        #endif
        vec3 n = normalize(mat3(m) * normal);
        vLit = uColour * (mix(uGround, uSky, 0.5 * n.z + 0.5) + uSun * max(dot(n, uSunDir), 0.0)) * RECIPROCAL_PI;
        vec4 mvPosition = viewMatrix * m * vec4(position, 1.0);
        gl_Position = projectionMatrix * mvPosition;
        #include <fog_vertex>
      }`,
    fragmentShader: LIT_FRAGMENT_SHADER,
  });
}

// The sky above the horizon (and a band below it fading to the ground
// colour), as a cap of a sphere around the camera: drawn first, behind
// everything, covering only the pixels where sky shows.
function skyDome(sky, ground) {
  const geo = new THREE.SphereGeometry(900, 24, 12, 0, Math.PI * 2, 0, Math.PI * 0.56).rotateX(Math.PI / 2);
  const pos = geo.attributes.position, col = new Float32Array(3 * pos.count);
  const haze = sky.clone().lerp(new THREE.Color(0xffffff), 0.25), c = new THREE.Color();
  for (let i = 0; i < pos.count; i++) {
    const el = Math.asin(Math.max(-1, Math.min(1, pos.getZ(i) / 900)));  // elevation, rad
    if (el < 0) c.copy(haze).lerp(ground, Math.min(1, -el / (Math.PI * 0.06)));
    else c.copy(haze).lerp(sky, Math.min(1, el / 0.35));
    c.toArray(col, 3 * i);
  }
  geo.setAttribute('color', new THREE.BufferAttribute(col, 3));
  const m = new THREE.Mesh(geo, new THREE.MeshBasicMaterial({ vertexColors: true, side: THREE.BackSide, depthWrite: false, depthTest: false, fog: false, toneMapped: false }));
  m.renderOrder = -10;
  m.frustumCulled = false;
  m.visible = false;
  return m;
}

function chequerTexture() {
  const c = document.createElement('canvas');
  c.width = 64; c.height = 32;
  const x = c.getContext('2d');
  x.fillStyle = '#f4f4f4'; x.fillRect(0, 0, 64, 32);
  x.fillStyle = '#1d1f22';
  for (let i = 0; i < 4; i++) for (let j = 0; j < 2; j++) if ((i + j) % 2 === 0) x.fillRect(i * 16, j * 16, 16, 16);
  const t = new THREE.CanvasTexture(c);
  t.colorSpace = THREE.SRGBColorSpace;
  t.magFilter = THREE.NearestFilter;
  return t;
}
