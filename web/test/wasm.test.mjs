// umbra-geom compiled to WebAssembly (crates/umbra-wasm, web/umbra-geom-wasm/): a three.js-style
// geometry (positions, optional Uint16/Uint32 index) prepared in the module gives the buffers
// `umbra export` writes, byte for byte; open, non-manifold, unwelded and degenerate input is
// normal; bad input is an error naming the mesh and the element.
//
// Needs: web/umbra-geom-wasm/umbra_wasm.wasm (node build-wasm.mjs; skipped with a message when
// absent), the umbra binary for the byte comparisons (UMBRA_BIN, else
// $CARGO_TARGET_DIR/release/umbra, else target/release/umbra; skipped with a message when
// absent), Crytek Sponza in UMBRA_SCENES for the shared-scene comparison (skipped when absent).
// Run: cd web && node --test test/
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { existsSync } from 'node:fs';
import http from 'node:http';
import { mkdtemp, readFile, rm } from 'node:fs/promises';
import { tmpdir } from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { loadUmbraGeom, UmbraGeomError } from '../umbra-geom-wasm/index.js';

const here = path.dirname(fileURLToPath(import.meta.url));
const webDir = path.join(here, '..');
const repo = path.join(webDir, '..');
const WASM = path.join(webDir, 'umbra-geom-wasm', 'umbra_wasm.wasm');
const SCENES_DIR = process.env.UMBRA_SCENES || path.join(repo, '..', 'shared', 'scenes');
const SPONZA = path.join(SCENES_DIR, 'crytek-sponza.obj.gz');

const UMBRA = [process.env.UMBRA_BIN, process.env.CARGO_TARGET_DIR && path.join(process.env.CARGO_TARGET_DIR, 'release', 'umbra'), path.join(repo, 'target', 'release', 'umbra')].find((c) => c && existsSync(c));

const skip = existsSync(WASM) ? false : `${WASM} is absent (node build-wasm.mjs): wasm test skipped`;
if (skip) console.log(`SKIP: ${skip}`);
const skipExport = skip || (UMBRA ? false : 'no umbra binary (cargo build --release -p umbra-cli, or UMBRA_BIN): comparison with umbra export skipped');
if (skipExport && !skip) console.log(`SKIP: ${skipExport}`);
const skipSponza = skipExport || (existsSync(SPONZA) ? false : `${SPONZA} is absent (UMBRA_SCENES): Sponza comparison skipped`);
if (skipSponza && !skipExport) console.log(`SKIP: ${skipSponza}`);

// Buffer of the prepared geometry -> file of `umbra export`.
const FILES = { positions: 'positions.bin', normals: 'normals.bin', indices: 'indices.bin', sides: 'sides.bin', caps: 'caps.bin', edgeTriangles: 'edge_triangles.bin' };

let geom, tmp;

before(async () => {
  if (skip) return;
  geom = await loadUmbraGeom(await readFile(WASM));
  tmp = await mkdtemp(path.join(tmpdir(), 'umbra-wasm-'));
});

after(async () => {
  if (tmp) await rm(tmp, { recursive: true, force: true });
});

const bytes = (a) => Buffer.from(a.buffer, a.byteOffset, a.byteLength);

/** Sizes against paper 003's Eq. 8 and Eq. 9 and the counts. */
function checkSizes(p) {
  const c = p.counts;
  assert.equal(p.positions.length, 3 * c.vertices);
  assert.equal(p.normals.length, 3 * c.triangles);
  assert.equal(p.indices.length, 3 * c.triangles);
  assert.equal(4 * p.sides.length, 16 * (2 + p.maxMult) * c.sidesDataRecords, 'Eq. 8');
  assert.equal(4 * p.caps.length, 48 * c.triangles, 'Eq. 9');
  assert.equal(p.edgeTriangles.length, p.maxMult * c.sidesDataRecords);
  assert.ok(p.maxMult >= 1 && p.maxMult <= 14);
  assert.equal(c.triangles + c.degenerateTriangles, c.inputTriangles);
}

/** `positions` indexed by `index`: every triangle with its own three vertices. */
function soup(positions, index) {
  const out = new Float32Array(3 * index.length);
  index.forEach((v, i) => out.set(positions.subarray(3 * v, 3 * v + 3), 3 * i));
  return out;
}

/** Exports `spec` with the native binary and checks the module reproduces every file from `input`. */
async function compareWithExport(spec, dir, inputs) {
  execFileSync(UMBRA, ['export', spec, '--out', dir], { stdio: ['ignore', 'ignore', 'inherit'] });
  const manifest = JSON.parse(await readFile(path.join(dir, 'manifest.json'), 'utf8'));
  const files = {};
  for (const [key, file] of Object.entries(FILES)) files[key] = await readFile(path.join(dir, file));
  const positions = new Float32Array(files.positions.buffer.slice(files.positions.byteOffset, files.positions.byteOffset + files.positions.byteLength));
  const indices = new Uint32Array(files.indices.buffer.slice(files.indices.byteOffset, files.indices.byteOffset + files.indices.byteLength));
  const timings = [];
  for (const input of inputs(positions, indices)) {
    const start = performance.now();
    const p = geom.prepare(input);
    timings.push(`${input.name}: ${(performance.now() - start).toFixed(0)} ms`);
    checkSizes(p);
    for (const [key, file] of Object.entries(FILES)) {
      assert.equal(p[key].byteLength, files[key].length, `${input.name}: ${key} has ${p[key].byteLength} bytes, ${file} ${files[key].length}`);
      assert.ok(bytes(p[key]).equals(files[key]), `${input.name}: ${key} differs from ${file}`);
    }
    const m = manifest;
    assert.deepEqual(
      [p.counts.vertices, p.counts.triangles, p.counts.edges, p.counts.sidesDataRecords, p.maxMult],
      [m.counts.vertices, m.counts.triangles, m.counts.edges, m.counts.sides_data_records, m.max_mult],
      input.name,
    );
    assert.deepEqual(p.bounds, { min: m.bounds.min.map(Math.fround), max: m.bounds.max.map(Math.fround) }, input.name);
  }
  return timings;
}

test('default scene: indexed and unindexed input reproduce every buffer of umbra export byte for byte', { skip: skipExport }, async () => {
  const timings = await compareWithExport('default', path.join(tmp, 'default'), (positions, indices) => [
    { name: 'default indexed', positions, index: indices },
    { name: 'default soup', positions: soup(positions, indices) },
  ]);
  console.log(`wasm prepare: ${timings.join(', ')}`);
});

test('Crytek Sponza: the export fed back as an indexed geometry reproduces every buffer', { skip: skipSponza }, async () => {
  const timings = await compareWithExport(SPONZA, path.join(tmp, 'sponza'), (positions, indices) => [{ name: 'sponza', positions, index: indices }]);
  console.log(`wasm prepare: ${timings.join(', ')}`);
});

// An open quad in the y = 0 plane, counter-clockwise seen from +y.
const QUAD = new Float32Array([0, 0, 0, 0, 0, 1, 1, 0, 1, 1, 0, 0]);
const QUAD_INDEX = new Uint16Array([0, 1, 2, 0, 2, 3]);

test('open quad (Uint16 index): 5 edges, 4 of them open, maxMult 2', { skip }, () => {
  const p = geom.prepare({ name: 'quad', positions: QUAD, index: QUAD_INDEX });
  checkSizes(p);
  assert.deepEqual(p.counts, { vertices: 4, triangles: 2, edges: 5, sidesDataRecords: 5, inputTriangles: 2, degenerateTriangles: 0 });
  assert.equal(p.maxMult, 2);
  assert.deepEqual(Array.from(p.normals), [0, 1, 0, 0, 1, 0]);
  assert.deepEqual(p.bounds, { min: [0, 0, 0], max: [1, 0, 1] });
  assert.deepEqual(Array.from(p.caps.subarray(0, 4)), [0, 0, 0, 1], 'caps-data: (P, 1)');
  // Every record's used slots name a triangle (±(T + 1)); the diagonal has both.
  const used = Array.from(p.edgeTriangles).filter((v) => v !== 0);
  assert.equal(used.length, 6, 'one slot per (edge, triangle)');
  assert.ok(used.every((v) => Math.abs(v) === 1 || Math.abs(v) === 2));
  // The same quad as a Uint32 index and as a plain array: the same buffers.
  for (const index of [new Uint32Array(QUAD_INDEX), Array.from(QUAD_INDEX)]) {
    const q = geom.prepare({ name: 'quad', positions: Array.from(QUAD), index });
    for (const key of Object.keys(FILES)) assert.ok(bytes(q[key]).equals(bytes(p[key])), key);
  }
});

test('non-manifold fan: three triangles on one edge, maxMult 3', { skip }, () => {
  const positions = new Float32Array([0, 0, 0, 0, 1, 0, 1, 0, 0, 0, 0, 1, -1, 0, 0]);
  const p = geom.prepare({ name: 'fan', positions, index: new Uint32Array([0, 1, 2, 0, 1, 3, 0, 1, 4]) });
  checkSizes(p);
  assert.deepEqual([p.counts.edges, p.counts.sidesDataRecords, p.maxMult], [7, 7, 3]);
  // The spine's record: three opposite slots, |T + 1| = 1, 2, 3.
  const spine = [];
  for (let r = 0; r < 7; r++) {
    const slots = Array.from(p.edgeTriangles.subarray(3 * r, 3 * r + 3));
    if (slots.every((v) => v !== 0)) spine.push(slots.map(Math.abs).sort());
    // sides-data: a.w = the record's number of opposites.
    assert.equal(p.sides[4 * 5 * r + 3], slots.filter((v) => v !== 0).length);
  }
  assert.deepEqual(spine, [[1, 2, 3]]);
});

test('unwelded cube (36 vertices, no index) equals the indexed cube; degenerate and zero-area triangles', { skip }, () => {
  const corners = [];
  for (let i = 0; i < 8; i++) corners.push(i & 1 ? 1 : -1, i & 2 ? 1 : -1, i & 4 ? 1 : -1);
  const faces = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
  const index = new Uint16Array(faces.flatMap(([a, b, c, d]) => [a, b, c, a, c, d]));
  const positions = new Float32Array(corners);
  const indexed = geom.prepare({ name: 'cube', positions, index });
  const unwelded = geom.prepare({ name: 'cube soup', positions: soup(positions, index) });
  checkSizes(indexed);
  assert.deepEqual(indexed.counts, { vertices: 8, triangles: 12, edges: 18, sidesDataRecords: 18, inputTriangles: 12, degenerateTriangles: 0 });
  assert.equal(indexed.maxMult, 2, 'closed and manifold');
  assert.deepEqual(unwelded.counts, indexed.counts);
  for (const key of Object.keys(FILES)) assert.ok(bytes(unwelded[key]).equals(bytes(indexed[key])), key);
  // -0 welds with +0.
  const negZero = geom.prepare({ name: 'quad -0', positions: QUAD.map((v) => (v === 0 ? -0 : v)), index: QUAD_INDEX });
  assert.ok(bytes(negZero.positions).equals(bytes(geom.prepare({ name: 'quad', positions: QUAD, index: QUAD_INDEX }).positions)));

  // A triangle with a repeated vertex is dropped and counted; a collinear one is kept (zero normal).
  const p = geom.prepare({ name: 'degenerate', positions: new Float32Array([...QUAD, 2, 0, 0]), index: new Uint16Array([0, 1, 2, 0, 0, 1, 0, 3, 4]) });
  checkSizes(p);
  assert.deepEqual([p.counts.triangles, p.counts.degenerateTriangles, p.counts.inputTriangles], [2, 1, 3]);
  assert.deepEqual(Array.from(p.normals.subarray(3)), [0, 0, 0], 'collinear: zero normal');
  const none = geom.prepare({ name: 'only degenerate', positions: QUAD, index: new Uint16Array([1, 1, 2]) });
  assert.deepEqual([none.counts.triangles, none.sides.length, none.bounds], [0, 0, null]);
});

test('bad input: an error naming the mesh and the element, never a trap', { skip }, () => {
  const fails = (input, message) => {
    assert.throws(() => geom.prepare(input), (e) => {
      assert.ok(e instanceof UmbraGeomError, `${e}`);
      assert.equal(e.message, message);
      return true;
    });
  };
  fails({ name: 'empty', positions: new Float32Array(0) }, 'empty: no positions: the position attribute is empty');
  fails({ name: 'missing' }, 'missing: no positions: the position attribute is empty');
  fails({ name: 'short', positions: new Float32Array(4) }, 'short: positions: 4 floats, not a multiple of 3 (x, y, z per vertex)');
  fails({ name: 'nan', positions: new Float32Array([0, 0, 0, 1, NaN, 0, 0, 0, 1]) }, 'nan: positions[4] (vertex 1, y) is NaN: coordinates must be finite');
  fails({ name: 'inf', positions: new Float32Array([0, 0, 0, 1, 0, 0, 0, 0, Infinity]) }, 'inf: positions[8] (vertex 2, z) is inf: coordinates must be finite');
  fails({ name: 'range', positions: QUAD, index: new Uint16Array([0, 1, 2, 0, 2, 7]) }, 'range: index[5] = 7 (triangle 1) is out of range: the geometry has 4 vertices');
  fails({ name: 'count', positions: QUAD, index: new Uint32Array([0, 1, 2, 0, 2]) }, 'count: index: 5 entries, not a multiple of 3 (three per triangle)');
  fails({ name: 'soup', positions: QUAD }, 'soup: no index and 4 vertices, not a multiple of 3 (three per triangle without an index)');
  fails({ name: 'Säule ①', positions: new Float32Array(2) }, 'Säule ①: positions: 2 floats, not a multiple of 3 (x, y, z per vertex)');
  // The module still works, and the failed calls freed their memory.
  const big = { name: 'again', positions: new Float32Array(300_001) };
  assert.throws(() => geom.prepare(big), UmbraGeomError);
  const memory = geom.memoryBytes();
  for (let i = 0; i < 100; i++) assert.throws(() => geom.prepare(big), UmbraGeomError);
  assert.equal(geom.memoryBytes(), memory, 'no memory kept by failed calls');
  assert.equal(geom.prepare({ name: 'quad', positions: QUAD, index: QUAD_INDEX }).counts.triangles, 2);
});

test('loading by URL: streamed (application/wasm), compiled from bytes (other types), HTTP errors named', { skip }, async () => {
  const wasm = await readFile(WASM);
  const server = http.createServer((req, res) => {
    if (req.url === '/streamed.wasm') res.writeHead(200, { 'Content-Type': 'application/wasm' }).end(wasm);
    else if (req.url === '/octet.wasm') res.writeHead(200, { 'Content-Type': 'application/octet-stream' }).end(wasm);
    else res.writeHead(404).end();
  });
  await new Promise((resolve) => server.listen(0, '127.0.0.1', resolve));
  const base = `http://127.0.0.1:${server.address().port}`;
  try {
    for (const file of ['streamed.wasm', 'octet.wasm']) {
      const g = await loadUmbraGeom(`${base}/${file}`);
      assert.equal(g.prepare({ name: file, positions: QUAD, index: QUAD_INDEX }).counts.edges, 5, file);
    }
    await assert.rejects(loadUmbraGeom(`${base}/missing.wasm`), (e) => e instanceof UmbraGeomError && /missing\.wasm: HTTP 404$/.test(e.message));
    await assert.rejects(loadUmbraGeom(new Uint8Array([0, 97, 115, 109, 9, 0, 0, 0])), WebAssembly.CompileError);
  } finally {
    server.close();
  }
});

test('receiver cull through the glue: a map of one cell culls and clamps, z-pass raises, bad grids refused, freed handles throw', { skip }, () => {
  // A floor (10 x 10 at y = 0) and a unit square at y = 1, one geometry; a point light above.
  const positions = new Float32Array([-5, 0, -5, 5, 0, -5, 5, 0, 5, -5, 0, 5, 0, 1, 0, 1, 1, 0, 1, 1, 1, 0, 1, 1]);
  const index = new Uint32Array([0, 2, 1, 0, 3, 2, 4, 6, 5, 4, 7, 6]);
  const p = geom.prepare({ name: 'floor and square', positions, index, caster: true });
  const light = [0.5, 4, 0.5, 1];
  const I = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1];
  // The camera: above and in front, looking at the square (a perspective matrix, fov 90°).
  const view = { worldFromObject: I, objectFromWorld: I, clipFromObject: lookDown(), width: 200, height: 200, zfail: false };
  const at = (world) => ({ ...view, worldFromObject: world });
  const r = geom.receivers();
  assert.equal(r.setGrid(light, [-5, 0, -5, 5, 1, 5], 100), null, 'a side that is not a power of two');
  assert.equal(r.setGrid([0, 0, 0, 0], [-5, 0, -5, 5, 1, 5], 128), null, 'a directional light without a direction');
  const grid = r.setGrid(light, [-5, 0, -5, 5, 1, 5], 128);
  assert.deepEqual(Array.from(grid.subarray(0, 5)), [0, 128, 0.5, 4, 0.5], 'a point light: the cube, its light');
  const cells = r.cells();
  assert.equal(cells.length, 6 * 128 * 128);
  // No sample at all: every triangle dropped, nothing drawn.
  cells.fill(-Infinity);
  assert.ok(r.build());
  let s = p.caster.cull(r, view, light);
  assert.deepEqual([s.kept, s.records.length, s.triangles.length], [0, 0, 0]);
  assert.ok(Array.from(s.orientation).every((o) => o === 0));
  // One sample straight under the light on the floor (face -y, its centre cell), 4 from the
  // light: the square is kept, its far vertices just past the floor (scale 4.1 / 3) where the
  // clamp pays: for the square alone (the floor receives only), seen from above and in front,
  // its unclamped sides would run down to their vanishing point.
  r.cells().fill(-Infinity);
  r.cells()[(3 * 128 + 64) * 128 + 64] = 4.1;
  assert.ok(r.build());
  const square = geom.prepare({ name: 'square', positions: positions.subarray(12), index: new Uint32Array([0, 2, 1, 0, 3, 2]), caster: true });
  const q = square.caster.cull(r, view, light);
  assert.ok(q.clamped, 'clamped: fewer pixels');
  assert.deepEqual(Array.from(q.triangles), [0, 1], 'the square kept');
  assert.equal(q.far.length, 4 * 4);
  for (let v = 0; v < 4; v++) {
    const [x, y, z, w] = q.far.subarray(4 * v, 4 * v + 4);
    assert.equal(w, 1, 'clamped: a finite far vertex');
    assert.ok(y < 0 && y > -0.2, `vertex ${v}: far end at y = ${y}, just below the floor`);
    assert.ok(Math.abs((x - 0.5) / (positions[12 + 3 * v] - 0.5) - (4 - y) / 3) < 1e-5, 'on the ray from the light');
    assert.ok(Number.isFinite(z));
  }
  assert.equal(q.records.length, 4, "the square's border");
  square.caster.free();
  // With the floor in the same caster, the floor is kept too (its cone holds the sample, 4.1 >
  // its distance 4), and its far cap would cover most of the view: every far end at infinity.
  s = p.caster.cull(r, view, light);
  assert.deepEqual(Array.from(s.triangles), [0, 1, 2, 3]);
  assert.ok(!s.clamped, 'unclamped: the far caps would cost more');
  for (let v = 4; v < 8; v++) assert.equal(s.far[4 * v + 3], 0, 'at infinity');
  assert.equal(s.records.length, 8, "the square's and the floor's borders");
  // Its records' welded vertices: two per record, all below the vertex count.
  const rv = p.caster.recordVertices();
  assert.equal(rv.length, 2 * p.counts.sidesDataRecords);
  assert.ok(rv.every((v) => v < 8));
  // z-pass: the near pyramid under the square is raised; a NaN one drops the map (no cull).
  assert.ok(r.raise([0.5, 0.5, 0.5, 0.45, 0.4, 0.45, 0.55, 0.4, 0.45, 0.55, 0.4, 0.55, 0.45, 0.4, 0.55]));
  assert.ok(!r.raise([NaN, 0, 0]));
  assert.equal(p.caster.cull(r, view, light), null, 'no map: not culled');
  // A projective world matrix is not culled either.
  assert.ok(r.build());
  assert.equal(p.caster.cull(r, at([1, 0, 0, 0.5, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]), light), null);
  // The GPU cull's uniform (umbra_geom::receivers::gpu_cull_words): the grid's side, faces,
  // coarsest level and level offsets; under z-pass the near pyramid's rectangle and its
  // farthest value raised (order-preserving encoding: above any positive float's word of a
  // smaller value); none raised for null; null where the cube cannot bound the points.
  const words = r.gpuCull(null);
  assert.equal(words.length, 52);
  assert.deepEqual(Array.from(words.subarray(30, 33)), [128, 6, 7], 'side, faces, top');
  assert.deepEqual(Array.from(words.subarray(36, 40)), [0, 6 * 128 * 128, 6 * (128 * 128 + 64 * 64), 6 * (128 * 128 + 64 * 64 + 32 * 32)]);
  assert.deepEqual(Array.from(words.subarray(24, 30)), [0, 0, 0, 0, 0, 0], 'nothing raised');
  const raised = r.gpuCull([0.5, 0.5, 0.5, 0.45, 0.4, 0.45, 0.55, 0.4, 0.45, 0.55, 0.4, 0.55, 0.45, 0.4, 0.55]);
  const [i0, i1, j0, j1, face, word] = raised.subarray(24, 30);
  assert.equal(face, 3, 'below the light: face -y');
  assert.ok(i0 <= 64 && 64 <= i1 && j0 <= 64 && 64 <= j1, `the rectangle ${[i0, i1, j0, j1]} holds the cell under the light`);
  const encode = (x) => new Uint32Array(Float32Array.of(x).buffer)[0] | 0x80000000;
  assert.ok(word >>> 0 > encode(3.6) >>> 0, 'raised to beyond the farthest point (3.6 from the light)');
  assert.equal(r.gpuCull([0.5, 4, 0.5, 0.5, 4, 0.5, 0.5, 4, 0.5]), null, 'the points at the light: no face bounds them');
  assert.equal(r.gpuCull([1, 2]), null, 'not x y z triples');
  r.free();
  r.free();
  assert.throws(() => r.build(), UmbraGeomError);
  p.caster.free();
  assert.throws(() => p.caster.cull(r, view, light), UmbraGeomError);
});

/** A clip-from-world matrix (column-major): the eye at (0.5, 3, 4) looking at (0.5, 0, 0.5), fov 90°, near 0.1. */
function lookDown() {
  const eye = [0.5, 3, 4];
  const f = [0, -3, -3.5];
  const n = Math.hypot(...f);
  const fw = f.map((x) => x / n);
  const s = [1, 0, 0]; // fw x up(0,1,0), normalised: along +x here
  const up = [s[1] * fw[2] - s[2] * fw[1], s[2] * fw[0] - s[0] * fw[2], s[0] * fw[1] - s[1] * fw[0]];
  const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  const view = [s[0], up[0], -fw[0], 0, s[1], up[1], -fw[1], 0, s[2], up[2], -fw[2], 0, -dot(s, eye), -dot(up, eye), dot(fw, eye), 1];
  const proj = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, -1, 0, 0, 0.1, 0];
  const out = new Array(16).fill(0);
  for (let c = 0; c < 4; c++) for (let row = 0; row < 4; row++) for (let k = 0; k < 4; k++) out[4 * c + row] += proj[4 * k + row] * view[4 * c + k];
  return out;
}
