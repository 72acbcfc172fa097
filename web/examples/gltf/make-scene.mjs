// Writes scene.gltf, the glTF example's default model: a small courtyard made of three.js
// primitives, exported with three.js's own GLTFExporter (positions and indices only; the page
// computes normals). It holds what CAD and BIM models hold and shadow volumes must survive:
// closed solids, an open wall (a single plane, no back faces, non-manifold edges), a torus
// knot (many silhouette edges), a mesh under a rotated and scaled node, and a ground plane.
//
// Usage: node examples/gltf/make-scene.mjs   (from web/; rewrites examples/gltf/scene.gltf)
import { writeFileSync } from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import * as THREE from 'three';
import { GLTFExporter } from 'three/addons/exporters/GLTFExporter.js';

// GLTFExporter reads its buffers back with the browser's FileReader, which Node lacks: the
// two calls it makes, on Node's Blob.
globalThis.FileReader ??= class {
  async readAsArrayBuffer(blob) {
    this.result = await blob.arrayBuffer();
    this.onloadend?.();
  }
  async readAsDataURL(blob) {
    const bytes = Buffer.from(await blob.arrayBuffer());
    this.result = `data:${blob.type || 'application/octet-stream'};base64,${bytes.toString('base64')}`;
    this.onloadend?.();
  }
};

const scene = new THREE.Scene();
const material = new THREE.MeshStandardMaterial();
function add(name, geometry, position, rotation = [0, 0, 0], scale = [1, 1, 1]) {
  geometry.deleteAttribute('normal');
  geometry.deleteAttribute('uv');
  const mesh = new THREE.Mesh(geometry, material);
  mesh.name = name;
  mesh.position.set(...position);
  mesh.rotation.set(...rotation);
  mesh.scale.set(...scale);
  scene.add(mesh);
  return mesh;
}

// 8 x 6 ground at exactly y = 0, facing up (x is the long axis: umbra's default camera looks
// along it): PlaneGeometry's (x, y, 0) laid down as (x, 0, -y) by hand, since a rotation
// matrix would leave y at about 1e-16 instead of 0.
const ground = new THREE.PlaneGeometry(8, 6);
const p = ground.attributes.position;
for (let i = 0; i < p.count; i++) p.setXYZ(i, p.getX(i), 0, -p.getY(i));
add('ground', ground, [0, 0, 0]);
// An open wall along the back, 3 high: the scene's height.
add('wall', new THREE.PlaneGeometry(6, 3), [0.5, 1.5, -2.2]);
add('box', new THREE.BoxGeometry(0.8, 0.8, 0.8), [1.8, 0.4, -1.0], [0, 0.5, 0]);
add('column', new THREE.CylinderGeometry(0.25, 0.25, 1.6, 12), [-0.2, 0.8, -1.1]);
add('knot', new THREE.TorusKnotGeometry(0.35, 0.1, 32, 5), [2.4, 0.75, 0.9], [0.4, 0.3, 0], [1, 1.3, 1]);
add('ball', new THREE.IcosahedronGeometry(0.4, 1), [0.6, 0.9, 1.2]);

const gltf = await new GLTFExporter().parseAsync(scene, { binary: false });
gltf.asset.generator = 'umbra web/examples/gltf/make-scene.mjs (three.js GLTFExporter)';
const out = path.join(path.dirname(fileURLToPath(import.meta.url)), 'scene.gltf');
writeFileSync(out, JSON.stringify(gltf) + '\n');
console.log(`${out}: ${JSON.stringify(gltf).length + 1} bytes`);
