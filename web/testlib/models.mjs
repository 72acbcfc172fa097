// Model files written from an `umbra export` (its welded positions and indices), so that a
// browser test can load the very scene `umbra verify` judges through three.js's own loaders:
// OBJ (OBJLoader) and glTF (GLTFLoader, one embedded buffer). Coordinates are printed as the
// shortest decimal of their f32 value, which every parser (f32 directly, or f64 then f32)
// reads back to the same f32.
import { readFile } from 'node:fs/promises';
import path from 'node:path';

/** { positions: Float32Array, indices: Uint32Array, manifest } of the export in `dir`. */
export async function readExport(dir) {
  const manifest = JSON.parse(await readFile(path.join(dir, 'manifest.json'), 'utf8'));
  const buf = async (name) => {
    const b = manifest.buffers[name];
    const data = await readFile(path.join(dir, b.file));
    return data.buffer.slice(data.byteOffset + b.offset, data.byteOffset + b.offset + b.bytes);
  };
  return { manifest, positions: new Float32Array(await buf('positions')), indices: new Uint32Array(await buf('indices')) };
}

/** An OBJ of `positions` (x y z per vertex) and `indices` (three per triangle), `offset` subtracted. */
export function toObj(positions, indices, offset = [0, 0, 0]) {
  const lines = [];
  const f = new Float32Array(3);
  for (let i = 0; i < positions.length; i += 3) {
    for (let k = 0; k < 3; k++) f[k] = positions[i + k] - offset[k];
    lines.push(`v ${f[0]} ${f[1]} ${f[2]}`);
  }
  for (let i = 0; i < indices.length; i += 3) lines.push(`f ${indices[i] + 1} ${indices[i + 1] + 1} ${indices[i + 2] + 1}`);
  return `${lines.join('\n')}\n`;
}

/** A glTF 2.0 JSON file with one mesh of `positions` and `indices`, its buffer embedded. */
export function toGltf(positions, indices) {
  const pos = Buffer.from(positions.buffer, positions.byteOffset, positions.byteLength);
  const idx = Buffer.from(indices.buffer, indices.byteOffset, indices.byteLength);
  const min = [0, 1, 2].map((k) => Math.min(...positions.filter((_, i) => i % 3 === k)));
  const max = [0, 1, 2].map((k) => Math.max(...positions.filter((_, i) => i % 3 === k)));
  return JSON.stringify({
    asset: { version: '2.0' },
    scene: 0,
    scenes: [{ nodes: [0] }],
    nodes: [{ mesh: 0, name: 'model' }],
    meshes: [{ primitives: [{ attributes: { POSITION: 0 }, indices: 1 }] }],
    buffers: [{ byteLength: pos.length + idx.length, uri: `data:application/octet-stream;base64,${Buffer.concat([pos, idx]).toString('base64')}` }],
    bufferViews: [{ buffer: 0, byteOffset: 0, byteLength: pos.length, target: 34962 }, { buffer: 0, byteOffset: pos.length, byteLength: idx.length, target: 34963 }],
    accessors: [
      { bufferView: 0, componentType: 5126, count: positions.length / 3, type: 'VEC3', min, max },
      { bufferView: 1, componentType: 5125, count: indices.length, type: 'SCALAR' },
    ],
  });
}

/** The page query and the `umbra verify` flags of a view: eye, target, up, fov, near, light. */
export function viewOf(camera, light) {
  const j = (v) => v.join(',');
  return {
    query: `eye=${j(camera.eye)}&target=${j(camera.target)}&up=${j(camera.up)}&fov=${camera.fov_y_degrees}&near=${camera.near}&light=${j(light)}`,
    flags: ['--eye', j(camera.eye), '--target', j(camera.target), '--up', j(camera.up), '--fov', String(camera.fov_y_degrees), '--light', j(light)],
  };
}
