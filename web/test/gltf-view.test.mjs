// The glTF example's view (examples/gltf/view.js) is the one `umbra render` uses for the same
// file: each model is loaded by three.js's own loader (in Node: GLTFLoader, OBJLoader,
// PLYLoader) and its default eye, target, up, fov, near plane and light compared with those
// `umbra export` writes to its manifest (the camera `umbra render` uses, near plane included).
// Also the query flags (eye, target, up, fov, light as --light reads it) and their errors.
//
// Needs the umbra binary (UMBRA_BIN, else $CARGO_TARGET_DIR/release/umbra, else
// target/release/umbra; skipped with a message when absent) and `npm ci` in web/ (three).
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { existsSync } from 'node:fs';
import { mkdtemp, readFile, rm, writeFile } from 'node:fs/promises';
import { tmpdir } from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { defaultView, parseLight, triangleBounds, viewFor } from '../examples/gltf/view.js';

const here = path.dirname(fileURLToPath(import.meta.url));
const webDir = path.join(here, '..');
const repo = path.join(webDir, '..');
const umbra = [process.env.UMBRA_BIN, process.env.CARGO_TARGET_DIR && path.join(process.env.CARGO_TARGET_DIR, 'release', 'umbra'), path.join(repo, 'target', 'release', 'umbra')].find((c) => c && existsSync(c));
const skip = umbra ? false : 'no umbra binary (cargo build --release -p umbra-cli, or UMBRA_BIN): view comparison skipped';
if (skip) console.log(`SKIP: ${skip}`);

// three.js's loaders report progress with the browser's ProgressEvent, which Node lacks.
globalThis.ProgressEvent ??= class extends Event {
  constructor(type, init = {}) {
    super(type);
    Object.assign(this, init);
  }
};
const { GLTFLoader } = await import('three/addons/loaders/GLTFLoader.js');
const { OBJLoader } = await import('three/addons/loaders/OBJLoader.js');
const { PLYLoader } = await import('three/addons/loaders/PLYLoader.js');
const THREE = await import('three');

// A tall, deep OBJ (z the longer horizontal axis: the other framing branch), off-centre,
// with a vertex no face references (umbra's bounds leave it out).
const OBJ = 'v 10 -2 5\nv 14 -2 5\nv 14 -2 25\nv 10 -2 25\nv 12 6.5 14\nv 100 100 100\nf 1 2 3\nf 1 3 4\nf 1 2 5\n';
// An ASCII PLY, wider than deep.
const PLY = 'ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n-3 0.25 -1\n3 0.25 -1\n3 0.25 1\n0 2.75 0\n3 0 1 2\n3 0 1 3\n';

let tmp;
before(async () => {
  tmp = await mkdtemp(path.join(tmpdir(), 'umbra-gltf-view-'));
});
after(async () => {
  if (tmp) await rm(tmp, { recursive: true, force: true });
});

async function load(file) {
  const bytes = await readFile(file);
  let root;
  if (file.endsWith('.gltf')) root = (await new GLTFLoader().parseAsync(bytes.toString('utf8'), '')).scene;
  else if (file.endsWith('.obj')) root = new OBJLoader().parse(bytes.toString('utf8'));
  else root = new THREE.Mesh(new PLYLoader().parse(bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.length)));
  root.updateMatrixWorld(true);
  return root;
}

function manifestOf(file, dir, flags = []) {
  execFileSync(umbra, ['export', file, '--out', path.join(tmp, dir), ...flags], { stdio: ['ignore', 'ignore', 'inherit'] });
  return readFile(path.join(tmp, dir, 'manifest.json'), 'utf8').then(JSON.parse);
}

for (const [name, text] of [['scene.gltf', null], ['room.obj', OBJ], ['tent.ply', PLY]]) {
  test(`${name}: the default view is umbra's, to the bit`, { skip }, async () => {
    const file = text === null ? path.join(webDir, 'examples', 'gltf', name) : path.join(tmp, name);
    if (text !== null) await writeFile(file, text);
    const manifest = await manifestOf(file, `${name}.out`);
    const view = viewFor(await load(file), new URLSearchParams());
    assert.deepEqual(view.eye, manifest.camera.eye, 'eye');
    assert.deepEqual(view.target, manifest.camera.target, 'target');
    assert.deepEqual(view.up, manifest.camera.up, 'up');
    assert.equal(view.fov, manifest.camera.fov_y_degrees, 'fov');
    assert.equal(view.near, manifest.camera.near, 'near plane');
    // The manifest's light is f32, printed as the shortest f32 decimal.
    assert.deepEqual(view.light.map(Math.fround), manifest.light.map(Math.fround), 'light');
  });
}

test('query flags: eye, target and light as umbra reads them; up and fov taken as given', { skip }, async () => {
  const file = path.join(tmp, 'flags.obj');
  await writeFile(file, OBJ);
  // `umbra export` takes --eye, --target and --light (render's --up and --fov pass through as they are).
  const flags = { eye: '1,2,3', target: '12,0.5,14', light: '2,4,6,2' };
  const manifest = await manifestOf(file, 'flags', Object.entries(flags).flatMap(([k, v]) => [`--${k}`, v]));
  const view = viewFor(await load(file), new URLSearchParams({ ...flags, up: '0,0,1', fov: '35' }));
  assert.deepEqual(view.eye, manifest.camera.eye);
  assert.deepEqual(view.target, manifest.camera.target);
  assert.deepEqual(view.up, [0, 0, 1]);
  assert.equal(view.fov, 35);
  assert.equal(view.near, manifest.camera.near);
  assert.deepEqual(view.light, [1, 2, 3, 1]);
  assert.deepEqual(view.light.map(Math.fround), manifest.light.map(Math.fround));
});

test('a directional light keeps its direction, rounded to f32', () => {
  assert.deepEqual(parseLight(new URLSearchParams('light=0.1,1,-0.3,0')), [Math.fround(0.1), 1, Math.fround(-0.3), 0]);
  assert.throws(() => parseLight(new URLSearchParams('light=0,0,0,0')), /light=0,0,0,0: a directional light/);
});

test('bad query values are errors naming the parameter', () => {
  const empty = { traverse() {} };
  for (const [q, re] of [['eye=1,2', /eye=1,2: expected 3/], ['light=1,x,3', /light=1,x,3: expected 3 or 4/], ['fov=180', /fov=180: must be in \(0, 180\)/], ['up=0,0,0', /up: must not be zero/], ['eye=1,1,1&target=1,1,1', /must differ/]]) {
    assert.throws(() => viewFor(empty, new URLSearchParams(q)), re, q);
  }
});

test('a scene without triangles falls back to umbra\'s -1..1 box, near plane 1e-3', () => {
  const root = { traverse() {} };
  assert.equal(triangleBounds(root), null);
  const v = defaultView(null);
  assert.deepEqual(v.eye, [-0.4, -1 + 0.45 * 2, 0]);
  assert.equal(v.near, 1e-3);
});
