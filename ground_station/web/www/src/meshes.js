// Mesh obstacles: each of the scene's meshes is fetched from the bridge (it
// serves a file only when its bytes are the ones the server loaded) with
// three.js's OBJ, STL or glTF loader, and placed as the server places it:
// world = p + q (scale * file), ENU. Until it arrives, or when the bridge has
// no such file, the mesh's bounds stand in for it as a translucent box.
import * as THREE from 'three';
import { OBJLoader } from 'three/addons/loaders/OBJLoader.js';
import { STLLoader } from 'three/addons/loaders/STLLoader.js';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';

function triangles(object) {
  let n = 0;
  object.traverse((o) => {
    if (!o.isMesh || !o.geometry) return;
    const g = o.geometry;
    n += (g.index ? g.index.count : g.attributes.position.count) / 3;
  });
  return n;
}

function load(url) {
  const ext = url.slice(url.lastIndexOf('.')).toLowerCase();
  return new Promise((resolve, reject) => {
    if (ext === '.obj') new OBJLoader().load(url, resolve, undefined, reject);
    else if (ext === '.stl') new STLLoader().load(url, (g) => resolve(new THREE.Mesh(g)), undefined, reject);
    else if (ext === '.gltf' || ext === '.glb') new GLTFLoader().load(url, (g) => resolve(g.scene), undefined, reject);
    else reject(new Error(`no loader for ${ext}`));
  });
}

export class MeshLayer {
  constructor(material) {
    this.material = material;
    this.generation = 0;
    this.items = [];  // what the page shows of each mesh (test hook)
  }

  // Adds the scene's meshes to group (the world's static group, emptied on every scene).
  set(meshes, group) {
    const gen = ++this.generation;
    this.items = (meshes ?? []).map((m) => ({
      file: m.file, url: m.url, expected: m.triangles, drawn: 0,
      state: m.url ? 'loading' : 'bounds', why: m.url ? '' : (m.why || 'not served'),
    }));
    (meshes ?? []).forEach((m, i) => {
      const item = this.items[i];
      const lo = new THREE.Vector3(...m.bounds_min), hi = new THREE.Vector3(...m.bounds_max);
      const size = new THREE.Vector3().subVectors(hi, lo).max(new THREE.Vector3(0.05, 0.05, 0.05));
      const stand = new THREE.Mesh(new THREE.BoxGeometry(size.x, size.y, size.z),
        new THREE.MeshBasicMaterial({ color: 0xb07a4a, transparent: true, opacity: 0.35, depthWrite: false }));
      stand.position.addVectors(lo, hi).multiplyScalar(0.5);
      group.add(stand);
      if (!m.url) return;
      load(m.url).then((object) => {
        if (gen !== this.generation) return;  // a newer scene came meanwhile
        object.traverse((o) => {
          if (!o.isMesh) return;
          o.material = this.material;
          o.castShadow = o.receiveShadow = true;
        });
        const holder = new THREE.Group();
        holder.position.set(...m.p);
        holder.quaternion.set(m.q[1], m.q[2], m.q[3], m.q[0]);
        holder.scale.setScalar(m.scale);
        holder.add(object);
        group.remove(stand);
        stand.geometry.dispose();
        stand.material.dispose();
        group.add(holder);
        item.drawn = triangles(object);
        item.state = 'loaded';
      }).catch((e) => {
        if (gen !== this.generation) return;
        item.state = 'failed';
        item.why = String(e?.message ?? e);
      });
    });
  }
}
