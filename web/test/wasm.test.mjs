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
