// umbra-three as users install it: `npm pack` of web/umbra-three (its prepack script builds
// dist/), the tarball and three@0.187.0 installed from npm into an empty folder outside the
// repository, and a page there (import map, no bundler, three.js's OBJLoader from the
// installed three) that draws a small scene with the package in Debian's Chromium
// (SwiftShader). Asserts:
// * the tarball holds what package.json's "files" names (the module, the wasm, the types, the
//   README) and nothing of the sources;
// * the page gets to `ready`, no mesh refused;
// * the light's mask: the floor under the box (along the light) shadowed, the floor far from
//   it and the box's top lit, every pixel 0 or 255;
// * with the umbra binary: `umbra verify --external-mask` of that mask, with the same eye,
//   target, light and near plane (from `umbra export`'s manifest), 0 samples outside the band.
// Skipped with a message when the npm registry cannot be reached or Chromium is absent.
// Needs the wasm module the package's build copies (node build-wasm.mjs, in web/) and `npm ci`.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync, spawnSync } from 'node:child_process';
import { existsSync, readdirSync } from 'node:fs';
import { mkdtemp, mkdir, readFile, rm, writeFile } from 'node:fs/promises';
import { tmpdir } from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import * as THREE from 'three';
import { createServer, listen } from '../serve.mjs';
import { launch, judge } from '../testlib/exactness.mjs';
import { encodePng } from '../testlib/png.mjs';

const here = path.dirname(fileURLToPath(import.meta.url));
const webDir = path.join(here, '..');
const repo = path.join(webDir, '..');
const packageDir = path.join(webDir, 'umbra-three');
const CHROMIUM = process.env.UMBRA_CHROMIUM || '/usr/bin/chromium';
const THREE_VERSION = '0.187.0';
const W = 320;
const H = 240;

// A 10 x 10 floor and a closed box floating over it.
const OBJ = `v -5 0 -5\nv 5 0 -5\nv 5 0 5\nv -5 0 5\nf 1 3 2\nf 1 4 3\n${[...Array(8).keys()].map((i) => `v ${i & 1 ? 0.5 : -0.5} ${i & 2 ? 2 : 1} ${i & 4 ? 0.5 : -0.5}`).join('\n')}\n`
  + [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]].map(([a, b, c, d]) => `f ${a + 5} ${b + 5} ${c + 5}\nf ${a + 5} ${c + 5} ${d + 5}`).join('\n') + '\n';
const VIEW = { eye: '0,4,6', target: '0,0.5,0', light: '0.3,5,0.2' };

const PAGE = `<!doctype html>
<meta charset="utf-8">
<script type="importmap">
{ "imports": { "three": "./node_modules/three/build/three.module.js",
               "three/addons/": "./node_modules/three/examples/jsm/",
               "umbra-three": "./node_modules/umbra-three/MAIN" } }
</script>
<canvas id="c" width="${W}" height="${H}"></canvas>
<script type="module">
import * as THREE from 'three';
import { OBJLoader } from 'three/addons/loaders/OBJLoader.js';
import { UmbraShadows } from 'umbra-three';
const q = new URLSearchParams(location.search);
const v = (k) => q.get(k).split(',').map(Number);
window.app = { state: 'loading' };
try {
  const renderer = new THREE.WebGLRenderer({ canvas: document.getElementById('c') });
  const umbra = await UmbraShadows.create(renderer);
  const scene = new THREE.Scene();
  const model = new OBJLoader().parse(await (await fetch('scene.obj')).text());
  model.traverse((o) => { if (o.isMesh) { o.material = new THREE.MeshStandardMaterial({ side: THREE.DoubleSide }); o.castShadow = true; } });
  scene.add(model);
  const light = new THREE.PointLight(0xffffff, 30);
  light.position.set(...v('light'));
  light.castShadow = true;
  scene.add(light);
  const camera = new THREE.PerspectiveCamera(60, ${W} / ${H}, Number(q.get('near')), 100);
  camera.position.set(...v('eye'));
  camera.lookAt(...v('target'));
  umbra.render(scene, camera);
  const mask = umbra.readMask(light);
  let s = '';
  for (let i = 0; i < mask.length; i += 8192) s += String.fromCharCode.apply(null, mask.subarray(i, i + 8192));
  window.app = { state: 'ready', mask: s, errors: umbra.errors, subpixelBits: renderer.getContext().getParameter(renderer.getContext().SUBPIXEL_BITS) };
} catch (e) {
  window.app = { state: 'error', error: String(e.stack || e) };
}
</script>
`;

const npm = (args, cwd, timeout = 300_000) => spawnSync('npm', args, { cwd, encoding: 'utf8', timeout, env: { ...process.env, npm_config_audit: 'false', npm_config_fund: 'false', npm_config_update_notifier: 'false' } });

let skip = existsSync(CHROMIUM) ? false : `${CHROMIUM} is absent (apt-get install chromium): npm-pack test skipped`;
if (!skip) {
  const r = npm(['view', `three@${THREE_VERSION}`, 'version'], webDir, 60_000);
  if (r.status !== 0 || r.stdout.trim() !== THREE_VERSION) skip = `the npm registry is unreachable (npm view three@${THREE_VERSION}: ${(r.stderr || r.error?.message || '').trim().split('\n').pop()}): npm-pack test skipped`;
}
if (skip) console.log(`SKIP: ${skip}`);

let tmp, app, tarball;
before(async () => {
  if (skip) return;
  tmp = await mkdtemp(path.join(tmpdir(), 'umbra-pack-'));
  const packed = npm(['pack', '--json', '--pack-destination', tmp], packageDir);
  assert.equal(packed.status, 0, `npm pack: ${packed.stderr}`);
  // The JSON report follows whatever the package's prepack script (its build) printed.
  const [info] = JSON.parse(packed.stdout.slice(packed.stdout.search(/^\[/m)));
  tarball = { file: path.join(tmp, info.filename), files: info.files.map((f) => f.path) };
  // An empty project outside the repository, as a user starts one.
  app = path.join(tmp, 'app');
  await mkdir(app);
  await writeFile(path.join(app, 'package.json'), JSON.stringify({ name: 'umbra-pack-app', private: true, type: 'module' }));
  const installed = npm(['install', tarball.file, `three@${THREE_VERSION}`], app);
  assert.equal(installed.status, 0, `npm install: ${installed.stderr}`);
});

after(async () => {
  if (tmp) await rm(tmp, { recursive: true, force: true });
});

test('the tarball holds the module, the wasm, the types and the README, no sources', { skip }, () => {
  const pkg = JSON.parse(execFileSync('node', ['-p', 'JSON.stringify(require("./package.json"))'], { cwd: packageDir, encoding: 'utf8' }));
  for (const f of ['package.json', 'README.md', pkg.types.replace(/^\.\//, ''), 'dist/index.js', 'dist/umbra_wasm.wasm']) assert.ok(tarball.files.includes(f), `${f} missing from ${tarball.files.join(', ')}`);
  assert.ok(!tarball.files.some((f) => f.startsWith('src/') || f === 'build.mjs'), `sources in the tarball: ${tarball.files.join(', ')}`);
  assert.equal(pkg.peerDependencies.three, '^0.187.0');
  assert.ok(!existsSync(path.join(app, 'node_modules', 'umbra-three', 'src')));
  assert.deepEqual(readdirSync(path.join(app, 'node_modules')).filter((d) => !d.startsWith('.')).sort(), ['three', 'umbra-three']);
});

test('a page in the installed folder draws exact shadows with the package', { skip }, async () => {
  const pkg = JSON.parse(await readFile(path.join(app, 'node_modules', 'umbra-three', 'package.json'), 'utf8'));
  const main = (pkg.exports?.['.']?.default ?? pkg.exports?.['.'] ?? pkg.module ?? pkg.main).replace(/^\.\//, '');
  await writeFile(path.join(app, 'index.html'), PAGE.replace('MAIN', main));
  const obj = path.join(app, 'scene.obj');
  await writeFile(obj, OBJ);
  // The near plane `umbra render` uses for this file (1e-3 of the diagonal), from `umbra export`.
  const umbra = [process.env.UMBRA_BIN, process.env.CARGO_TARGET_DIR && path.join(process.env.CARGO_TARGET_DIR, 'release', 'umbra'), path.join(repo, 'target', 'release', 'umbra')].find((c) => c && existsSync(c));
  let near = 1e-3 * Math.hypot(10, 2, 10);
  if (umbra) {
    execFileSync(umbra, ['export', obj, '--out', path.join(tmp, 'export'), '--eye', VIEW.eye, '--target', VIEW.target, '--light', VIEW.light], { stdio: ['ignore', 'ignore', 'inherit'] });
    near = JSON.parse(await readFile(path.join(tmp, 'export', 'manifest.json'), 'utf8')).camera.near;
  } else {
    console.log('SKIP the umbra verify part: no umbra binary (cargo build --release -p umbra-cli, or UMBRA_BIN)');
  }
  const server = createServer([['/', app]]);
  const base = await listen(server, 0);
  const ctx = await launch(CHROMIUM, 'swiftshader', tmp);
  let result;
  try {
    const page = await ctx.newPage();
    const logs = [];
    page.on('console', (m) => logs.push(m.text()));
    page.on('pageerror', (e) => logs.push(String(e)));
    await page.goto(`${base}?eye=${VIEW.eye}&target=${VIEW.target}&light=${VIEW.light}&near=${near}`);
    await page.waitForFunction(() => window.app && window.app.state !== 'loading', null, { timeout: 300_000, polling: 250 });
    result = await page.evaluate(() => window.app);
    assert.equal(result.state, 'ready', `${result.error}\n${logs.join('\n')}`);
  } finally {
    await ctx.close();
    server.close();
  }
  assert.deepEqual(result.errors, []);
  const mask = Buffer.from(result.mask, 'latin1');
  assert.equal(mask.length, W * H);
  assert.ok(mask.every((b) => b === 0 || b === 255), 'every pixel 0 (shadowed) or 255 (lit)');

  // Where points land on the canvas, with the page's camera (three.js's own projection).
  const camera = new THREE.PerspectiveCamera(60, W / H, near, 100);
  camera.position.set(...VIEW.eye.split(',').map(Number));
  camera.lookAt(...VIEW.target.split(',').map(Number));
  camera.updateMatrixWorld(true);
  const at = (p) => {
    const v = new THREE.Vector3(...p).project(camera);
    const x = Math.floor((v.x * 0.5 + 0.5) * W);
    const y = Math.floor((0.5 - v.y * 0.5) * H);
    return mask[y * W + x];
  };
  const light = VIEW.light.split(',').map(Number);
  // The box's centre (0, 1.5, 0) seen from the light, on the floor.
  const t = light[1] / (light[1] - 1.5);
  const underBox = [light[0] - t * light[0], 0, light[2] - t * light[2]];
  assert.equal(at(underBox), 0, `the floor under the box, ${underBox}, is shadowed`);
  assert.equal(at([3, 0, 3]), 255, 'the floor far from the box is lit');
  assert.equal(at([-3, 0, -2]), 255, 'the floor behind the box, away from its shadow, is lit');
  assert.equal(at([0, 2, 0]), 255, 'the box\'s top is lit');

  if (umbra) {
    const rgba = new Uint8Array(W * H * 4);
    for (let i = 0; i < W * H; i++) rgba.set([mask[i], mask[i], mask[i], 255], 4 * i);
    const png = path.join(tmp, 'mask.png');
    await writeFile(png, encodePng(W, H, rgba));
    const bits = result.subpixelBits >= 4 ? ['--subpixel-bits', String(result.subpixelBits)] : [];
    const r = judge(umbra, { scene: obj, size: `${W}x${H}`, maskPng: png, extra: ['--eye', VIEW.eye, '--target', VIEW.target, '--light', VIEW.light, ...bits], explain: 20 });
    assert.equal(r.browser.mismatches_outside_band, 0, r.explained.join('\n'));
  }
});
