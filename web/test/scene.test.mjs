// The viewer's scene loader (src/scene.js) rejects malformed exports with a message naming the
// file and the JSON path, before any WebGL: version mismatch, missing field, wrong type, sizes
// against paper 003's Eq. 8 / Eq. 9, truncated buffers, out-of-range indices, HTTP 404.
// Run: node --test test/
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { parseManifest, loadScene, SceneError, sceneName } from '../src/scene.js';

/** A valid export of one triangle (3 vertices, 3 edges of 1 opposite each, maxMult 1). */
function sample() {
  const m = {
    format: 'umbra-export', version: 2, scene: 't', ground: false,
    counts: { vertices: 3, triangles: 1, edges: 3, sides_data_records: 3 },
    max_mult: 1, sides_data_bytes: 16 * 3 * 3, caps_data_bytes: 48,
    bounds: { min: [0, 0, 0], max: [1, 1, 0] }, light: [0, 0, 5, 1],
    camera: { eye: [0, 0, 3], target: [0, 0, 0], up: [0, 1, 0], fov_y_degrees: 60, near: 0.01 },
    buffers: {},
  };
  const b = (file, type, components, count) => ({ file, offset: 0, bytes: 4 * components * count, component_type: type, components, count });
  m.buffers = { positions: b('positions.bin', 'f32', 3, 3), normals: b('normals.bin', 'f32', 3, 1), indices: b('indices.bin', 'u32', 3, 1),
    sides_data: b('sides.bin', 'f32', 4, 9), caps_data: b('caps.bin', 'f32', 4, 3), edge_triangles: b('edge_triangles.bin', 'i32', 1, 3) };
  const files = {
    'positions.bin': new Float32Array([0, 0, 0, 1, 0, 0, 0, 1, 0]).buffer,
    'normals.bin': new Float32Array([0, 0, 1]).buffer,
    'indices.bin': new Uint32Array([0, 1, 2]).buffer,
    'sides.bin': new Float32Array(36).buffer,
    'caps.bin': new Float32Array(12).buffer,
    'edge_triangles.bin': new Int32Array([1, -1, 1]).buffer,
  };
  return { m, files };
}

function fetcher(manifestText, files) {
  return async (url) => {
    const name = url.split('/').pop();
    if (name === 'manifest.json') return { ok: manifestText !== null, status: manifestText === null ? 404 : 200, text: async () => manifestText };
    if (!(name in files)) return { ok: false, status: 404 };
    return { ok: true, status: 200, arrayBuffer: async () => files[name] };
  };
}

const err = (f) => {
  try {
    f();
  } catch (e) {
    assert.ok(e instanceof SceneError, `not a SceneError: ${e}`);
    return e.message;
  }
  assert.fail('no error');
};

test('a valid export loads', async () => {
  const { m, files } = sample();
  const s = await loadScene('http://x/scene/', fetcher(JSON.stringify(m), files));
  assert.equal(s.indices.length, 3);
  assert.equal(s.sides_data.length, 36);
  assert.ok(s.edge_triangles instanceof Int32Array, 'edge triangles are signed');
  assert.deepEqual(Array.from(s.edge_triangles), [1, -1, 1]);
});

test('edge triangles: maxMult i32 per edge record', () => {
  let { m } = sample();
  m.buffers.edge_triangles.component_type = 'f32';
  assert.match(err(() => parseManifest(JSON.stringify(m))), /\$\.buffers\.edge_triangles\.component_type: expected "i32"/);
  ({ m } = sample());
  m.buffers.edge_triangles.count = 2;
  assert.match(err(() => parseManifest(JSON.stringify(m))), /\$\.buffers\.edge_triangles: expected 3 elements of 1 components/);
});

test('truncated manifest text', () => {
  const { m } = sample();
  const t = JSON.stringify(m);
  assert.match(err(() => parseManifest(t.slice(0, t.length / 2))), /^manifest\.json: not valid JSON/);
});

test('version mismatch names $.version', () => {
  const { m } = sample();
  m.version = 1;
  assert.match(err(() => parseManifest(JSON.stringify(m))), /^manifest\.json: \$\.version: this viewer reads version 2, the scene is version 1: re-export it/);
});

test('missing and mistyped fields name their JSON path', () => {
  let { m } = sample();
  delete m.buffers.caps_data.bytes;
  assert.equal(err(() => parseManifest(JSON.stringify(m))), 'manifest.json: $.buffers.caps_data.bytes: missing');
  ({ m } = sample());
  m.max_mult = '1';
  assert.match(err(() => parseManifest(JSON.stringify(m))), /^manifest\.json: \$\.max_mult: expected an unsigned integer/);
  ({ m } = sample());
  m.buffers.positions.file = '../x.bin';
  assert.match(err(() => parseManifest(JSON.stringify(m))), /\$\.buffers\.positions\.file: .* not a plain file name/);
});

test('sizes must follow Eq. 8 and Eq. 9', () => {
  let { m } = sample();
  m.sides_data_bytes += 16;
  assert.match(err(() => parseManifest(JSON.stringify(m))), /\$\.sides_data_bytes: Eq\. 8 gives 144/);
  ({ m } = sample());
  m.caps_data_bytes = 47;
  assert.match(err(() => parseManifest(JSON.stringify(m))), /\$\.caps_data_bytes: Eq\. 9 gives 48/);
});

test('a truncated buffer names its file and the byte counts', async () => {
  const { m, files } = sample();
  files['sides.bin'] = files['sides.bin'].slice(0, 100);
  await assert.rejects(loadScene('http://x/scene/', fetcher(JSON.stringify(m), files)), (e) => e instanceof SceneError && /^sides\.bin: has 100 bytes, but \$\.buffers\.sides_data needs 144/.test(e.message));
});

test('an out-of-range index is rejected with its byte offset', async () => {
  const { m, files } = sample();
  files['indices.bin'] = new Uint32Array([0, 1, 3]).buffer;
  await assert.rejects(loadScene('http://x/scene/', fetcher(JSON.stringify(m), files)), /indices\.bin: index 2 \(byte 8\) is 3, but there are 3 vertices/);
});

test('missing files are reported with a hint', async () => {
  const { m, files } = sample();
  await assert.rejects(loadScene('http://x/scene/', fetcher(null, files)), /manifest\.json: HTTP 404: missing\? Export a scene/);
  delete files['caps.bin'];
  await assert.rejects(loadScene('http://x/scene/', fetcher(JSON.stringify(m), files)), /caps\.bin: HTTP 404/);
});

test('the page names the scene by its file name, never its path', () => {
  assert.equal(sceneName('/work/shared/scenes/sibenik.obj.gz'), 'sibenik.obj.gz');
  assert.equal(sceneName('C:\\models\\sponza.obj'), 'sponza.obj');
  assert.equal(sceneName('../shared/scenes/conference.obj.gz'), 'conference.obj.gz');
  assert.equal(sceneName('default'), 'default');
  assert.equal(sceneName('spheres:10:4000'), 'spheres:10:4000');
});
