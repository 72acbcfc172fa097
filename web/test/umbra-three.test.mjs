// umbra-three's parts that need no browser, under node --test: the light order against
// three.js's own WebGLLights, the de-indexed flat normals against umbra-geom's (wasm), the
// topology errors naming the mesh, the material patch, and the camera matrices.
// Needs: `npm ci` in web/ (three), web/umbra-geom-wasm/umbra_wasm.wasm (node build-wasm.mjs;
// the wasm tests are skipped with a message when it is absent). Run: cd web && node --test test/
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { existsSync } from 'node:fs';
import { readFile } from 'node:fs/promises';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import * as THREE from 'three';
import { WebGLLights } from 'three/src/renderers/webgl/WebGLLights.js';
import { gatherLights, lightSlots } from '../umbra-three/src/lights.js';
import { Topology, TopologyError, flatTriangles, positionArray } from '../umbra-three/src/topology.js';
import { casterPieces, triangleNormals } from '../umbra-three/src/webgpu/world.js';
import { patchedLightsChunk, patchMaterial, createUniforms, isReceiverMaterial } from '../umbra-three/src/materials.js';
import { clipFromObject, infiniteProjection, mul } from '../umbra-three/src/camera.js';
import { sidesOf, culledCapRanges, weldedTriangleCounts, CULL_NONE, CULL_BACK, CULL_FRONT } from '../umbra-three/src/sides.js';

const here = path.dirname(fileURLToPath(import.meta.url));
const WASM = path.join(here, '..', 'umbra-geom-wasm', 'umbra_wasm.wasm');
const noWasm = existsSync(WASM) ? false : `${WASM} is absent (node build-wasm.mjs): wasm tests skipped`;
if (noWasm) console.log(`SKIP: ${noWasm}`);

test('light slots: the uniform index three.js\'s WebGLLights gives every point and directional light', () => {
  const scene = new THREE.Scene();
  const camera = new THREE.PerspectiveCamera();
  // Interleaved kinds, shadow casters late, one hidden subtree, one light off the camera's layers.
  const make = [
    () => new THREE.PointLight(), () => new THREE.DirectionalLight(), () => new THREE.PointLight(),
    () => new THREE.AmbientLight(), () => new THREE.PointLight(), () => new THREE.DirectionalLight(),
    () => new THREE.SpotLight(), () => new THREE.PointLight(), () => new THREE.DirectionalLight(),
  ];
  const lights = make.map((f, i) => {
    const l = f();
    l.intensity = i + 1; // three.js's uniform colour = colour * intensity: tells the lights apart
    l.castShadow = [2, 5, 7, 8].includes(i);
    return l;
  });
  const group = new THREE.Group();
  group.add(lights[4], lights[5]);
  const hidden = new THREE.Group();
  hidden.visible = false;
  const ghost = new THREE.PointLight(0xffffff, 99);
  ghost.castShadow = true;
  hidden.add(ghost);
  const offLayer = new THREE.PointLight(0xffffff, 98);
  offLayer.layers.set(3);
  scene.add(lights[0], lights[1], group, lights[2], lights[3], hidden, lights[6], offLayer, lights[7], lights[8]);

  const gathered = gatherLights(scene, camera);
  assert.ok(!gathered.includes(ghost) && !gathered.includes(offLayer), 'hidden and off-layer lights are not gathered');
  const three = new WebGLLights({ has: () => false });
  three.setup(gathered);
  const slots = lightSlots(gathered);
  let points = 0;
  let directionals = 0;
  for (const l of gathered) {
    const s = slots.get(l);
    if (l.isPointLight) {
      points++;
      assert.equal(s.kind, 'point');
      assert.equal(three.state.point[s.index].color.r, l.intensity, `point light of intensity ${l.intensity}: slot ${s.index}`);
    } else if (l.isDirectionalLight) {
      directionals++;
      assert.equal(s.kind, 'directional');
      assert.equal(three.state.directional[s.index].color.r, l.intensity, `directional light of intensity ${l.intensity}: slot ${s.index}`);
    } else {
      assert.equal(s.kind, 'other');
    }
  }
  assert.equal(points, 4);
  assert.equal(directionals, 3);
  // Shadow casters first: the last point light added (castShadow) is slot 0 or 1, not 3.
  assert.ok(slots.get(lights[7]).index < 2);
});

test('flat normals of the de-indexed mesh are umbra-geom\'s, bit for bit; bad indices are left out', { skip: noWasm }, async () => {
  const topo = await Topology.load(await readFile(WASM));
  // A random indexed soup (distinct vertices per triangle, so welding drops nothing).
  let seed = 7;
  const rand = () => ((seed = (seed * 1103515245 + 12345) % 2147483648) / 2147483648) * 20 - 10;
  const positions = new Float32Array(3 * 200).map(rand);
  const index = [];
  for (let t = 0; t < 300; t++) {
    const a = t % 200;
    index.push(a, (a + 1 + (t % 7)) % 200, (a + 50 + (t % 13)) % 200);
  }
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.BufferAttribute(positions, 3));
  g.setIndex(index);
  const flat = flatTriangles(positions, new Uint32Array(index));
  const prepared = topo.geom.prepare({ name: 'soup', positions, index: new Uint32Array(index) });
  assert.equal(flat.triangles, prepared.counts.triangles);
  for (let t = 0; t < flat.triangles; t++) {
    for (let c = 0; c < 3; c++) {
      assert.ok(Object.is(flat.normals[9 * t + c], prepared.normals[3 * t + c]), `triangle ${t}, component ${c}`);
      assert.equal(flat.normals[9 * t + 3 + c], flat.normals[9 * t + c], 'the same normal on every vertex');
    }
  }
  const bad = flatTriangles(new Float32Array(9), new Uint32Array([0, 1, 2, 0, 1, 9]));
  assert.equal(bad.triangles, 1, 'the triangle with index 9 of 3 vertices is left out');
});

test('topology errors name the mesh: no positions, NaN, index out of range', { skip: noWasm }, async () => {
  const topo = await Topology.load(await readFile(WASM));
  assert.throws(() => topo.prepare(new THREE.BufferGeometry(), 'empty-one'), (e) => e instanceof TopologyError && /^empty-one: the geometry has no position attribute/.test(e.message));
  const nan = new THREE.BufferGeometry();
  nan.setAttribute('position', new THREE.Float32BufferAttribute([0, 0, 0, NaN, 0, 0, 0, 1, 0], 3));
  assert.throws(() => topo.prepare(nan, 'nan-one'), (e) => e instanceof TopologyError && /^nan-one: positions\[3\].*NaN/.test(e.message));
  const range = new THREE.BufferGeometry();
  range.setAttribute('position', new THREE.Float32BufferAttribute([0, 0, 0, 1, 0, 0, 0, 1, 0], 3));
  range.setIndex([0, 1, 3]);
  assert.throws(() => topo.prepare(range, 'range-one'), (e) => e instanceof TopologyError && /^range-one: index\[2\] = 3 .*out of range/.test(e.message));
  // Interleaved positions are read through the attribute, not its raw array.
  const inter = new THREE.InterleavedBuffer(new Float32Array([0, 0, 0, 9, 1, 0, 0, 9, 0, 1, 0, 9]), 4);
  const attr = new THREE.InterleavedBufferAttribute(inter, 3, 0);
  assert.deepEqual(Array.from(positionArray(attr)), [0, 0, 0, 1, 0, 0, 0, 1, 0]);
  const ok = new THREE.BufferGeometry();
  ok.setAttribute('position', attr);
  const p = topo.prepare(ok, 'interleaved');
  assert.equal(p.triangles, 1);
  assert.equal(p.records, 3);
});

test('materials: lit materials patched once, the user\'s onBeforeCompile and cache key kept, each light multiplied by its select', () => {
  const chunk = patchedLightsChunk();
  assert.match(chunk, /getPointLightInfo\( pointLight, geometryPosition, directLight \);\s*directLight\.color \*= umbraLit\( umbraPointSelect\[ i \] \);/);
  assert.match(chunk, /getDirectionalLightInfo\( directionalLight, directLight \);\s*directLight\.color \*= umbraLit\( umbraDirectionalSelect\[ i \] \);/);
  assert.throws(() => patchedLightsChunk('void main() {}'), /needs three r187/);
  for (const M of [THREE.MeshStandardMaterial, THREE.MeshPhysicalMaterial, THREE.MeshPhongMaterial, THREE.MeshLambertMaterial]) assert.ok(isReceiverMaterial(new M()), M.name);
  for (const M of [THREE.MeshBasicMaterial, THREE.MeshNormalMaterial, THREE.ShaderMaterial]) assert.ok(!isReceiverMaterial(new M()), M.name);

  const uniforms = createUniforms(null);
  const patched = new WeakSet();
  const m = new THREE.MeshPhongMaterial();
  const calls = [];
  m.onBeforeCompile = (shader) => calls.push(shader.fragmentShader.length);
  m.customProgramCacheKey = () => 'mine';
  patchMaterial(m, uniforms, patched);
  patchMaterial(m, uniforms, patched);
  assert.equal(m.customProgramCacheKey(), 'mine|umbra-three:1');
  const shader = { uniforms: {}, fragmentShader: 'uniform vec3 diffuse;\nvoid main() {\n#include <lights_fragment_begin>\n}\n' };
  m.onBeforeCompile(shader, null);
  assert.equal(calls.length, 1, 'the user\'s onBeforeCompile ran once');
  assert.equal(shader.uniforms.umbraMask, uniforms.umbraMask, 'the shared uniforms');
  assert.ok(shader.fragmentShader.indexOf('float umbraLit') < shader.fragmentShader.indexOf('void main()'));
  assert.ok(!shader.fragmentShader.includes('#include <lights_fragment_begin>') && shader.fragmentShader.includes('umbraPointSelect[ i ]'));
  const basic = new THREE.MeshBasicMaterial();
  const before = basic.onBeforeCompile;
  patchMaterial(basic, uniforms, patched);
  assert.equal(basic.onBeforeCompile, before, 'unsupported materials untouched');
});

test('camera: clip from object is projection * view * model; reversed-Z puts the near plane at depth 1 and infinity at 0', () => {
  const cam = new THREE.PerspectiveCamera(60, 16 / 9, 0.5, 100);
  cam.position.set(1, 2, 3);
  cam.lookAt(0, 0, 0);
  cam.updateMatrixWorld();
  const p = infiniteProjection(cam.getEffectiveFOV(), cam.aspect, cam.near, true);
  const identity = new THREE.Matrix4().elements;
  assert.deepEqual(Array.from(clipFromObject(p, cam.matrixWorldInverse.elements, identity)), Array.from(new Float32Array(mul(p, cam.matrixWorldInverse.elements))));
  const model = new THREE.Matrix4().makeTranslation(3, 0, -2);
  const m = clipFromObject(p, cam.matrixWorldInverse.elements, model.elements);
  const w = clipFromObject(p, cam.matrixWorldInverse.elements, identity);
  const apply = (M, v) => [0, 1, 2, 3].map((r) => M[r] * v[0] + M[4 + r] * v[1] + M[8 + r] * v[2] + M[12 + r] * v[3]);
  const a = apply(m, [0, 0, 0, 1]);
  const b = apply(w, [3, 0, -2, 1]);
  for (let k = 0; k < 4; k++) assert.ok(Math.abs(a[k] - b[k]) < 1e-5 * Math.abs(b[3]), 'the model matrix moves the mesh');
  // A point on the near plane straight ahead: depth z / w = 1; a direction (w = 0): z = 0.
  const view = (v) => apply(mul(p, identity), v);
  const near = view([0, 0, -0.5, 1]);
  assert.ok(Math.abs(near[2] / near[3] - 1) < 1e-12);
  assert.equal(view([0, 0, -1, 0])[2], 0);
});

test('sides: the ranges three.js draws and how each culls (FrontSide back faces, BackSide front faces, DoubleSide none), per group with an array of materials', () => {
  const geometry = new THREE.BoxGeometry(); // 12 triangles, 6 groups of 6 indices
  const single = (side) => Array.from(sidesOf(new THREE.MeshBasicMaterial({ side }), geometry, 36));
  assert.deepEqual(single(THREE.FrontSide), [0, 36, CULL_BACK]);
  assert.deepEqual(single(THREE.BackSide), [0, 36, CULL_FRONT]);
  assert.deepEqual(single(THREE.DoubleSide), [0, 36, CULL_NONE]);
  // The default material is FrontSide.
  assert.deepEqual(Array.from(sidesOf(new THREE.Mesh(geometry).material, geometry, 36)), [0, 36, CULL_BACK]);
  // An array of materials: by groups only, a group whose material is missing is not drawn.
  const sides = [THREE.FrontSide, THREE.BackSide, THREE.DoubleSide].map((side) => new THREE.MeshBasicMaterial({ side }));
  assert.deepEqual(Array.from(sidesOf([sides[0], sides[1], sides[2], sides[0]], geometry, 36)), [
    0, 6, CULL_BACK, 6, 6, CULL_FRONT, 12, 6, CULL_NONE, 18, 6, CULL_BACK,
  ]);
  // Groups in any order and of any length, clamped to the drawn vertices.
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.BufferAttribute(new Float32Array(27), 3));
  g.addGroup(3, Infinity, 1);
  g.addGroup(0, 3, 0);
  assert.deepEqual(Array.from(sidesOf([sides[2], sides[1]], g, 9)), [3, 6, CULL_FRONT, 0, 3, CULL_NONE]);
});

test('true-depth caps: the one-sided ranges in the caster\'s welded triangles; the welding\'s dropped triangles counted as umbra-geom drops them', { skip: noWasm }, async () => {
  // 6 triangles over 7 vertices: triangle 1 has two vertices at one position (0 and 3), 3
  // at +0 and -0 (welded as one), triangle 4 repeats one index; 0, 2 and 5 are kept.
  const positions = new Float32Array([0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 0, -0, 0, 0, 1, 1, 0, 2, 2, 2]);
  const index = new Uint32Array([0, 1, 2, 0, 3, 1, 1, 5, 2, 0, 4, 2, 5, 5, 6, 2, 5, 6]);
  const before = weldedTriangleCounts(positions, index);
  assert.deepEqual(Array.from(before), [0, 1, 1, 2, 2, 2, 3]);
  const topo = await Topology.load(await readFile(WASM));
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.BufferAttribute(positions, 3));
  g.setIndex(Array.from(index));
  const p = topo.prepare(g, 'degenerate');
  p.caster.free();
  assert.equal(p.degenerate, 3);
  assert.equal(p.triangles, before[6]);
  // Welded triangle before[t] is input triangle t (where kept): the same three positions.
  for (const t of [0, 2, 5]) {
    for (let c = 0; c < 3; c++) {
      const w = p.indices[3 * before[t] + c];
      assert.deepEqual(Array.from(p.positions.subarray(3 * w, 3 * w + 3)), Array.from(positions.subarray(3 * index[3 * t + c], 3 * index[3 * t + c] + 3)), `triangle ${t}, corner ${c}`);
    }
  }
  // The ranges: DoubleSide ones left out, FrontSide keeps back faces' caps (keepFront 0),
  // BackSide front faces' (1); adjacent ranges of one cull joined; input triangles mapped to
  // the welded ones (empty ranges dropped).
  assert.deepEqual(Array.from(culledCapRanges(Int32Array.of(0, 18, CULL_NONE), before)), []);
  assert.deepEqual(Array.from(culledCapRanges(Int32Array.of(0, 18, CULL_BACK), null)), [0, 6, 0]);
  assert.deepEqual(Array.from(culledCapRanges(Int32Array.of(0, 6, CULL_BACK, 6, 6, CULL_BACK, 12, 6, CULL_FRONT), before)), [0, 2, 0, 2, 3, 1]);
  assert.deepEqual(Array.from(culledCapRanges(Int32Array.of(3, 3, CULL_FRONT, 9, 6, CULL_NONE, 15, 3, CULL_BACK), before)), [2, 3, 0]);
});

test('webgpu world.js triangleNormals: the flat normal per triangle as topology.js flatTriangles gives it (umbra_geom::flat_normal), w 0, zero for a zero-area triangle', () => {
  const positions = new Float32Array([0, 0, 0, 1, 0, 0, 0, 0, -1, 0.1, 0.2, 0.3, 2, 2, 2, 4, 4, 4]);
  const indices = new Uint32Array([0, 1, 2, 2, 1, 0, 3, 1, 2, 0, 4, 5]);
  const n = triangleNormals(positions, indices);
  assert.equal(n.length, 16);
  const flat = flatTriangles(positions, indices).normals;
  for (let t = 0; t < 4; t++) assert.deepEqual([...n.subarray(4 * t, 4 * t + 4)], [...flat.subarray(9 * t, 9 * t + 3), 0], `triangle ${t}`);
  assert.deepEqual(Array.from(n.subarray(0, 4), (x) => x + 0), [0, 1, 0, 0]); // -0 + 0 is 0
  assert.deepEqual([...n.subarray(12, 16)], [0, 0, 0, 0]);
});

test('webgpu world.js casterPieces: triangles joined across the edges they share (umbra_geom caster_pieces), records of one edge split over several joined too, numbered by first triangle', () => {
  // Triangles 0-1 share edge (0, 1); 2 is alone; 3 and 4 share edge (5, 6) through two records
  // of that edge (a split edge).
  const records = new Uint32Array([
    0, 1, 0, 2,
    2, 3, 2, 1,
    5, 6, 3, 1,
    5, 6, 4, 1,
  ]);
  const slots = new Uint32Array([0 << 1, (1 << 1) | 1, 2 << 1, 3 << 1, (4 << 1) | 1]);
  const { pieces, count } = casterPieces(records, slots, 6);
  assert.equal(count, 4);
  assert.deepEqual(Array.from(pieces), [0, 0, 1, 2, 2, 3], 'triangle 5 is in no record: a piece of its own');
});
