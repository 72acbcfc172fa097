// The viewer (src/main.js, a three.js page drawing with the umbra-three package) in a real
// browser: Debian's Chromium (/usr/bin/chromium, driven by playwright-core, never a downloaded
// browser), headless, on the two WebGL 2 implementations this machine has: SwiftShader (what a
// user without a GPU gets) and ANGLE on the system's EGL (Mesa llvmpipe here, the native
// renderer's rasteriser). Scenes are loaded through three.js's own loaders — OBJLoader and
// GLTFLoader, from model files written out of an `umbra export` (testlib/models.mjs), and the
// shared scenes' .obj.gz as they are — drawn with UmbraShadows, and each light's decision is
// judged by the oracle itself, `umbra verify --method vs-silhouette --external-mask`
// (testlib/exactness.mjs): the same reference, the same per-sample band and the same --explain
// as every native method gets, with the page's eye, target, up, fov, near plane and light.
//
// * The default scene (OBJLoader: both depth paths, point and directional light; GLTFLoader;
//   and the export itself, scene=DIR): 0 samples outside the band on both implementations.
// * A caster the camera's near plane cuts (a wall 0.005 in front of the eye, near plane
//   0.0143): 0 outside the band on both; the light cap's near-plane cut is what makes it so.
// * The same wall as a mesh with a world transform (its file moved by -offset, the mesh by
//   +offset), and two lights at once (each light's mask read with umbra.readMask): 0.
// * Both counts the package picks (umbra.info().zpass): the default scene's views, Sponza's
//   and Conference's count z-pass from 0, Sibenik's from 4 (its eye inside 4 volumes), the eye
//   behind the moved wall in its shadow z-pass from 1, the wall cut by the near plane z-fail;
//   all judged by the oracle, 0 outside the band.
// * The three shared scenes (UMBRA_SCENES, default ../shared/scenes beside the repository;
//   skipped with a message when absent), 320 x 180, OBJLoader: 0 outside the band on both.
// * Every mask is judged with the band of the precision its WebGL context reports
//   (`SUBPIXEL_BITS`, passed as `umbra verify --subpixel-bits`: 4 on both here).
// * SwiftShader is held to the same 0: its masks were decided on umbra's own depth pass,
//   whose 1/16-pixel snapping may show another surface than the reference's sample near a
//   crease or a silhouette; the band has that part (SEEN_SURFACE, crates/umbra-oracle/src/
//   seen_surface.rs) for every external mask.
// * The mask view against the shaded view, shadows off, the frame time, the error pages (no
//   WebGL 2, truncated buffer, version mismatch, missing export), the controls, and
//   screenshots saved as test artefacts (web/test-artifacts/).
//
// Needs: the umbra binary (UMBRA_BIN, else $CARGO_TARGET_DIR/release/umbra, else
// target/release/umbra: build it with `cargo build --release -p umbra-cli`), the wasm module
// (node build-wasm.mjs) and /usr/bin/chromium (apt-get install chromium) — the test is
// skipped with a message when either is absent — and `npm ci` in web/.
// Run: cd web && node --test test/
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { existsSync } from 'node:fs';
import { mkdtemp, mkdir, rm, readFile, writeFile, cp, truncate } from 'node:fs/promises';
import { tmpdir } from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { createServer, listen } from '../serve.mjs';
import { build } from '../build.mjs';
import { launch, openViewer, readCanvas, maskAgainstReference, writeLightMask, judge } from '../testlib/exactness.mjs';
import { readExport, toObj, toGltf, viewOf } from '../testlib/models.mjs';

const here = path.dirname(fileURLToPath(import.meta.url));
const webDir = path.join(here, '..');
const repo = path.join(webDir, '..');
const CHROMIUM = process.env.UMBRA_CHROMIUM || '/usr/bin/chromium';
const artifacts = path.join(webDir, 'test-artifacts');
const W = 320;
const H = 240;
// The shared scenes: small, so that three scenes on two software rasterisers stay in CI's
// budget (seconds per frame on SwiftShader for Sponza at this size).
const SW = 320;
const SH = 180;
const SCENES_DIR = process.env.UMBRA_SCENES || path.join(repo, '..', 'shared', 'scenes');
const SHARED = ['crytek-sponza.obj.gz', 'conference.obj.gz', 'sibenik.obj.gz'];
// The stencil start each default view counts z-pass from (umbra.info().zpass): Sibenik's eye
// lies inside 4 of its volumes.
const SHARED_ZPASS = { 'crytek-sponza.obj.gz': 0, 'conference.obj.gz': 0, 'sibenik.obj.gz': 4 };

function umbraBin() {
  const candidates = [process.env.UMBRA_BIN, process.env.CARGO_TARGET_DIR && path.join(process.env.CARGO_TARGET_DIR, 'release', 'umbra'), path.join(repo, 'target', 'release', 'umbra')];
  const found = candidates.find((c) => c && existsSync(c));
  if (!found) throw new Error(`no umbra binary (tried ${candidates.filter(Boolean).join(', ')}): run cargo build --release -p umbra-cli or set UMBRA_BIN`);
  return found;
}

const WASM = path.join(webDir, 'umbra-geom-wasm', 'umbra_wasm.wasm');
const skip = !existsSync(CHROMIUM) ? `${CHROMIUM} is absent (apt-get install chromium): browser test skipped`
  : !existsSync(WASM) ? `${WASM} is absent (node build-wasm.mjs): browser test skipped` : false;
if (skip) console.log(`SKIP: ${skip}`);
const sharedMissing = SHARED.filter((s) => !existsSync(path.join(SCENES_DIR, s)));
const skipShared = skip || (sharedMissing.length ? `${sharedMissing.join(', ')} absent from ${SCENES_DIR} (UMBRA_SCENES): shared-scene browser test skipped` : false);
if (skipShared && !skip) console.log(`SKIP: ${skipShared}`);

// The near-plane case: a floor and a wall; the camera stands 0.005 in front of the wall, closer
// than its near plane (1e-3 of the scene's diagonal: 0.0143), so the near plane cuts the whole
// wall away and the floor behind it is seen, half in the wall's shadow.
const WALL_OBJ = `v -5 0 -5\nv 5 0 -5\nv 5 0 5\nv -5 0 5\nv -2 0 0\nv 2 0 0\nv 2 2 0\nv -2 2 0\nf 1 3 2\nf 1 4 3\nf 5 6 7\nf 5 7 8\n`;
const WALL_VIEW = { eye: '0,1,-0.005', target: '0,1,5', light: '0,4,-3' };

const WALL_OFFSET = [3, 0, -2];

let tmp, server, base, umbra, manifest, wallObj, wallManifest, modelFiles;
const sharedManifests = [];
const contexts = {};

before(async () => {
  if (skip) return;
  umbra = umbraBin();
  tmp = await mkdtemp(path.join(tmpdir(), 'umbra-browser-'));
  const dist = await build(path.join(tmp, 'dist'));
  const exp = (spec, dir, extra = []) => execFileSync(umbra, ['export', spec, '--out', path.join(tmp, dir), ...extra], { stdio: ['ignore', 'ignore', 'inherit'] });
  exp('default', 'scene');
  manifest = JSON.parse(await readFile(path.join(tmp, 'scene', 'manifest.json'), 'utf8'));
  wallObj = path.join(tmp, 'wall.obj');
  await writeFile(wallObj, WALL_OBJ);
  exp(wallObj, 'wall', ['--eye', WALL_VIEW.eye, '--target', WALL_VIEW.target, '--light', WALL_VIEW.light]);
  // The default scene and the wall as model files for three.js's loaders, and the wall moved
  // by -WALL_OFFSET (drawn with the mesh at +WALL_OFFSET: integers, exact in f32).
  const models = path.join(tmp, 'models');
  await mkdir(models, { recursive: true });
  const def = await readExport(path.join(tmp, 'scene'));
  await writeFile(path.join(models, 'default.obj'), toObj(def.positions, def.indices));
  await writeFile(path.join(models, 'default.gltf'), toGltf(def.positions, def.indices));
  const wall = await readExport(path.join(tmp, 'wall'));
  wallManifest = wall.manifest;
  await writeFile(path.join(models, 'wall-local.obj'), toObj(wall.positions, wall.indices, WALL_OFFSET));
  modelFiles = { default: path.join(models, 'default.obj'), gltf: path.join(models, 'default.gltf') };
  const mounts = [['/', dist], ['/scene/', path.join(tmp, 'scene')], ['/models/', models]];
  if (!skipShared) {
    mounts.push(['/scenes/', SCENES_DIR]);
    for (const [i, s] of SHARED.entries()) {
      exp(path.join(SCENES_DIR, s), `shared${i}`);
      sharedManifests[i] = JSON.parse(await readFile(path.join(tmp, `shared${i}`, 'manifest.json'), 'utf8'));
    }
  }
  // Broken exports for the error pages.
  await cp(path.join(tmp, 'scene'), path.join(tmp, 'truncated'), { recursive: true });
  await truncate(path.join(tmp, 'truncated', 'sides.bin'), manifest.sides_data_bytes - 16);
  await cp(path.join(tmp, 'scene'), path.join(tmp, 'version'), { recursive: true });
  await writeFile(path.join(tmp, 'version', 'manifest.json'), JSON.stringify({ ...manifest, version: 999 }));
  mounts.push(['/truncated/', path.join(tmp, 'truncated')], ['/version/', path.join(tmp, 'version')]);
  server = createServer(mounts);
  base = await listen(server, 0);
  contexts.swiftshader = await launch(CHROMIUM, 'swiftshader', tmp);
  contexts.egl = await launch(CHROMIUM, 'egl', tmp);
  // ANGLE on EGL is only the second implementation where the machine's EGL is Mesa's llvmpipe.
  const probe = await openViewer(contexts.egl, `${base}?size=64x64`);
  contexts.eglRenderer = probe.status.renderer || probe.status.error;
  await probe.page.close();
  if (!/llvmpipe/.test(contexts.eglRenderer)) console.log(`SKIP the ANGLE/EGL rows: Chromium's EGL back end gave ${contexts.eglRenderer}`);
});

after(async () => {
  for (const k of ['swiftshader', 'egl']) if (contexts[k]) await contexts[k].close();
  if (server) await new Promise((r) => server.close(r));
  if (tmp) await rm(tmp, { recursive: true, force: true });
});

/** The WebGL 2 implementations to judge: SwiftShader always, ANGLE/EGL where it is llvmpipe. */
const implementations = () => ['swiftshader', ...(/llvmpipe/.test(contexts.eglRenderer) ? ['egl'] : [])];

/** Opens the viewer in SwiftShader (or `ctx`) with `query`; returns page and status. */
const open = (query, ctx = contexts.swiftshader) => openViewer(ctx, `${base}?${query}`, 120_000);

/** The viewer's mask of `query` (its scene or model and view) judged by the oracle: { native, browser, falseShadow, falseLight, explained, status }. */
async function judged(impl, { scene, width, height, query = '', extra = [] }) {
  const maskPng = path.join(tmp, `mask-${impl}-${width}x${height}-${query.replace(/[^a-z0-9]+/gi, '_').slice(0, 120)}.png`);
  return maskAgainstReference(contexts[impl], umbra, { base, query, scene, width, height, maskPng, extra, explain: 1_000_000 });
}

/** What each light's volumes drew (umbra.info().volumes): culled or not, triangles, edge records. */
const volumesText = (v) => (v || []).map((l) => `${l.culled ? 'culled' : 'unculled'} ${l.triangles} triangles, ${l.edges} edges`).join('; ');

function report(what, r) {
  console.log(`${what}: ${r.browser.mismatches_outside_band} samples outside the band (${r.falseShadow} false shadow, ${r.falseLight} false light), ${r.browser.band_mismatches} in it, of ${r.browser.samples}; native vs-silhouette ${r.native.mismatches_outside_band}; ${r.status.depth} depth, SUBPIXEL_BITS ${r.status.subpixelBits}, frame ${r.status.frameMs.toFixed(0)} ms; volumes ${volumesText(r.status.volumes)}`);
  for (const l of r.explained.slice(0, 5)) console.log(`    ${l}`);
}

const BG = 0, SHADOW = 1, LIT = 2, AMBIGUOUS = 3;
/** Classes of a shaded image: background colour, ambient only (shadow), more (lit). */
function classify(rgba) {
  const bg = [0.1, 0.12, 0.16].map((c) => Math.round(c * 255));
  const ambient = Math.round(0.8 * 0.15 * 255);
  const out = new Uint8Array(W * H);
  for (let i = 0; i < W * H; i++) {
    const [r, g, b] = [rgba[4 * i], rgba[4 * i + 1], rgba[4 * i + 2]];
    if (Math.abs(r - bg[0]) <= 1 && Math.abs(g - bg[1]) <= 1 && Math.abs(b - bg[2]) <= 1) out[i] = BG;
    else if (Math.max(r, g, b) <= ambient + 1) out[i] = SHADOW;
    // A lit surface seen at a grazing angle to the light adds less than a few levels: neither.
    else if (Math.max(r, g, b) <= ambient + 4) out[i] = AMBIGUOUS;
    else out[i] = LIT;
  }
  return out;
}

test('default scene through OBJLoader, GLTFLoader and its export: 0 samples outside the band on SwiftShader and ANGLE/llvmpipe, both depth paths, point and directional light', { skip }, async () => {
  // The manifest's point light, and a directional one (no dark caps: zero area).
  const point = viewOf(manifest.camera, manifest.light);
  const directional = viewOf(manifest.camera, [0.3, 1, 0.2, 0]);
  const cases = [
    ['OBJLoader', `model=models/default.obj&${point.query}`, modelFiles.default, point.flags, 'reversed-z'],
    ['OBJLoader, standard depth', `model=models/default.obj&${point.query}&depth=standard`, modelFiles.default, point.flags, 'standard'],
    ['OBJLoader, directional light', `model=models/default.obj&${directional.query}`, modelFiles.default, directional.flags, 'reversed-z'],
    ['GLTFLoader', `model=models/default.gltf&${point.query}`, modelFiles.gltf, point.flags, 'reversed-z'],
    ['umbra export', 'scene=scene/', 'default', [], 'reversed-z'],
  ];
  for (const impl of implementations()) {
    for (const [what, query, scene, extra, depth] of cases) {
      const r = await judged(impl, { scene, width: W, height: H, query, extra });
      report(`default scene, ${impl}, ${what}`, r);
      assert.equal(r.status.state, 'ready');
      assert.deepEqual(r.status.zpass, [0], `${what}: the eye in the open, counted z-pass from 0`);
      assert.equal(r.status.depth, depth, 'reversed-Z where EXT_clip_control is offered, standard on request');
      assert.ok(r.browser.shadowed_reference > 500 && r.browser.samples - r.browser.shadowed_reference > 500, 'the view shows shadow and light');
      assert.equal(r.native.mismatches_outside_band, 0, 'native vs-silhouette');
      assert.equal(r.browser.mismatches_outside_band, 0, `${impl}, ${what}: the page disagrees with the reference outside the band`);
    }
  }
});

test('volumes culled to their receivers and not (cull=0), point and directional light, z-pass and z-fail (zpass=0), both scatters: 0 samples outside the band', { skip }, async () => {
  // The first test judges the default (culled, z-pass, the wasm's scatter on these software
  // rasterisers) point and directional views; here the other corners.
  const point = viewOf(manifest.camera, manifest.light);
  const directional = viewOf(manifest.camera, [0.3, 1, 0.2, 0]);
  const cases = [
    ['point, unculled, z-pass', point, 'cull=0', false, 0],
    ['point, culled, z-fail', point, 'zpass=0', true, null],
    ['point, unculled, z-fail', point, 'cull=0&zpass=0', false, null],
    ['point, culled, GPU scatter', point, 'scatter=gpu', true, 0],
    ['directional, unculled, z-pass', directional, 'cull=0', false, 0],
    ['directional, culled, z-fail', directional, 'zpass=0', true, null],
    ['directional, unculled, z-fail', directional, 'cull=0&zpass=0', false, null],
    // Far ends short of infinity and far caps everywhere the cull keeps a triangle (the
    // package clamps where that covers fewer pixels; on a software rasteriser seldom).
    ['point, clamped, z-pass', point, 'volumeclamp=always', true, 0],
    ['point, clamped, z-fail', point, 'volumeclamp=always&zpass=0', true, null],
    ['directional, clamped, z-pass', directional, 'volumeclamp=always', true, 0],
  ];
  for (const impl of implementations()) {
    for (const [what, view, flags, culled, zpass] of cases) {
      const r = await judged(impl, { scene: modelFiles.default, width: W, height: H, query: `model=models/default.obj&${view.query}&${flags}`, extra: view.flags });
      report(`default scene, ${impl}, ${what}`, r);
      assert.equal(r.status.state, 'ready');
      assert.deepEqual(r.status.zpass, [zpass], `${what}: counted ${zpass === null ? 'z-fail' : 'z-pass'}`);
      assert.equal(r.status.volumes[0].culled, culled, `${what}: culled or not as asked`);
      if (/volumeclamp=always/.test(flags)) assert.equal(r.status.volumes[0].clamped, 1, `${what}: clamped`);
      assert.ok(r.browser.shadowed_reference > 500 && r.browser.samples - r.browser.shadowed_reference > 500, 'the view shows shadow and light');
      assert.equal(r.browser.mismatches_outside_band, 0, `${impl}, ${what}: the page disagrees with the reference outside the band`);
    }
  }
});

test('a caster the near plane cuts: its light cap is cut too (ES 3.00 has no clip distances); the same wall with a world transform', { skip }, async () => {
  const v = viewOf(wallManifest.camera, wallManifest.light);
  const cases = [
    ['OBJLoader', `model=models/wall-local.obj&offset=${WALL_OFFSET.join(',')}&${v.query}`],
  ];
  for (const impl of implementations()) {
    for (const [what, query] of cases) {
      const r = await judged(impl, { scene: wallObj, width: SW, height: SH, query, extra: v.flags });
      report(`wall cut by the near plane, mesh moved by ${WALL_OFFSET}, ${impl}, ${what}`, r);
      assert.deepEqual(r.status.zpass, [null], 'the near plane cuts the wall: z-fail');
      // Both shadow and light behind the cut wall; without the cut every sample is wrong.
      assert.ok(r.browser.shadowed_reference > 1000 && r.browser.samples - r.browser.shadowed_reference > 1000, 'the floor behind the wall is half in its shadow');
      assert.equal(r.native.mismatches_outside_band, 0);
      assert.equal(r.browser.mismatches_outside_band, 0, `${impl}: samples seen through the cut wall`);
    }
  }
});

test('the eye inside the moved wall\'s shadow: counted z-pass from 1, 0 samples outside the band', { skip }, async () => {
  // Behind the wall (z = 0, height 2) from the light (0, 4, -3): the eye's segment to the light
  // crosses it; looking down the floor, half in its shadow near the wall.
  const camera = { ...wallManifest.camera, eye: [0, 0.5, 1.5], target: [0, 0, 4], up: [0, 1, 0] };
  const v = viewOf(camera, wallManifest.light);
  for (const impl of implementations()) {
    const query = `model=models/wall-local.obj&offset=${WALL_OFFSET.join(',')}&${v.query}`;
    const r = await judged(impl, { scene: wallObj, width: SW, height: SH, query, extra: v.flags });
    report(`eye in the wall's shadow, ${impl}`, r);
    assert.deepEqual(r.status.zpass, [1], 'z-pass from 1');
    assert.ok(r.browser.shadowed_reference > 1000 && r.browser.samples - r.browser.shadowed_reference > 1000, 'shadow and light in view');
    assert.equal(r.browser.mismatches_outside_band, 0, `${impl}: the z-pass count from 1 disagrees with the reference`);
  }
});

test('two lights, a point and a directional one: each light\'s decision (umbra.readMask) 0 samples outside the band', { skip }, async () => {
  const lights = [manifest.light, [0.3, 1, 0.2, 0]];
  const views = lights.map((l) => viewOf(manifest.camera, l));
  for (const impl of implementations()) {
    const { page, status, logs } = await openViewer(contexts[impl], `${base}?size=${W}x${H}&model=models/default.obj&${views[0].query}&light2=${lights[1].join(',')}`, 120_000);
    assert.equal(status.state, 'ready', `${status.error}\n${logs.join('\n')}`);
    const pngs = [];
    for (const k of [0, 1]) {
      pngs[k] = path.join(tmp, `two-lights-${impl}-${k}.png`);
      await writeLightMask(page, k, W, H, pngs[k]);
    }
    await page.close();
    for (const k of [0, 1]) {
      const bits = ['--subpixel-bits', String(status.subpixelBits)];
      const r = { ...judge(umbra, { scene: modelFiles.default, size: `${W}x${H}`, maskPng: pngs[k], extra: [...views[k].flags, ...bits], explain: 1_000_000 }), status };
      report(`two lights, light ${k}, ${impl}`, r);
      assert.ok(r.browser.shadowed_reference > 500 && r.browser.samples - r.browser.shadowed_reference > 500, 'the view shows shadow and light');
      assert.equal(r.browser.mismatches_outside_band, 0, `${impl}, light ${k}`);
    }
  }
});

test('shared scenes: 0 samples outside the band on SwiftShader and ANGLE/llvmpipe, culled (and on SwiftShader also every culled volume clamped); the page names the file', { skip: skipShared }, async () => {
  const totals = {};
  const runs = implementations().flatMap((impl) => [[impl, ''], ...(impl === 'swiftshader' ? [[impl, '&volumeclamp=always']] : [])]);
  for (const [impl, clamp] of runs) {
    for (const [i, s] of SHARED.entries()) {
      const scene = path.join(SCENES_DIR, s);
      const v = viewOf(sharedManifests[i].camera, sharedManifests[i].light);
      const r = await judged(impl, { scene, width: SW, height: SH, query: `model=scenes/${s}&${v.query}${clamp}` });
      report(`${s}, ${impl}${clamp ? ', every volume clamped' : ''}, ${SW}x${SH}`, r);
      if (clamp) assert.ok(r.status.volumes[0].clamped > 0, `${s}: clamped`);
      assert.equal(r.status.state, 'ready');
      assert.deepEqual(r.status.zpass, [SHARED_ZPASS[s]], `${s}: its default view counts z-pass from ${SHARED_ZPASS[s]}`);
      // Culled to the receivers (the package's default), and some of each scene's triangles
      // dropped.
      assert.equal(r.status.volumes[0].culled, true, `${s}: culled`);
      assert.ok(r.status.volumes[0].triangles < sharedManifests[i].counts.triangles, `${s}: ${r.status.volumes[0].triangles} triangles kept`);
      assert.match(r.status.info, new RegExp(`^${s.replace(/\./g, '\\.')}: \\d+ triangles`), 'the file name, first');
      assert.ok(!r.status.info.includes(path.dirname(scene)), `the page shows a path: ${r.status.info}`);
      assert.equal(r.native.mismatches_outside_band, 0, `${s}: native vs-silhouette`);
      assert.ok(r.browser.shadowed_reference > 1000 && r.browser.samples - r.browser.shadowed_reference > 1000, `${s}: shadow and light in view`);
      totals[impl] = (totals[impl] || 0) + r.browser.mismatches_outside_band;
      assert.equal(r.browser.mismatches_outside_band, 0, `${s} on ${impl}`);
    }
  }
  console.log(`shared scenes at ${SW}x${SH}, samples outside the band: ${Object.entries(totals).map(([k, v]) => `${k} ${v}`).join(', ')}`);
});

test('shared scene with GPU silhouettes (silhouettes=gpu, cull=0: the orientation pass, every record visited), SwiftShader: 0 samples outside the band', { skip: skipShared }, async () => {
  const i = SHARED.indexOf('crytek-sponza.obj.gz');
  const s = SHARED[i];
  const v = viewOf(sharedManifests[i].camera, sharedManifests[i].light);
  const r = await judged('swiftshader', { scene: path.join(SCENES_DIR, s), width: SW, height: SH, query: `model=scenes/${s}&${v.query}&cull=0&silhouettes=gpu` });
  report(`${s}, swiftshader, GPU silhouettes, ${SW}x${SH}`, r);
  assert.equal(r.status.state, 'ready');
  assert.equal(r.status.silhouettes, 'gpu', 'the GPU silhouettes as asked');
  assert.equal(r.status.volumes[0].culled, false, 'unculled');
  assert.ok(r.browser.shadowed_reference > 1000 && r.browser.samples - r.browser.shadowed_reference > 1000, `${s}: shadow and light in view`);
  assert.equal(r.browser.mismatches_outside_band, 0, `${s}: GPU silhouettes`);
});

test('mask view agrees with the shaded view; shadows off; frame time', { skip }, async () => {
  const { page, status, logs } = await open(`size=${W}x${H}`);
  assert.equal(status.state, 'ready', `viewer failed: ${status.error}\n${logs.join('\n')}`);
  console.log(`Chromium WebGL renderer (SwiftShader set-up): ${status.renderer}; depth: ${status.depth}; EXT_depth_clamp: ${status.depthClamp}; first frame ${status.frameMs.toFixed(1)} ms at ${W}x${H}`);
  await mkdir(artifacts, { recursive: true });
  await page.locator('#canvas').screenshot({ path: path.join(artifacts, 'browser-default.png') });
  const shaded = classify((await readCanvas(page)).rgba);

  // The shadow-mask view: black only where the shaded view shows the ambient term alone, and
  // white wherever the shaded view is clearly lit (a white pixel may look unlit when shaded:
  // a surface facing the light at a grazing angle adds less than one level).
  const m = await open(`size=${W}x${H}&mask=1`);
  assert.equal(m.status.state, 'ready', m.status.error);
  await m.page.locator('#canvas').screenshot({ path: path.join(artifacts, 'browser-default-mask.png') });
  const mask = (await readCanvas(m.page)).rgba;
  let disagree = 0, grazing = 0;
  for (let i = 0; i < W * H; i++) {
    if (shaded[i] === BG) continue;
    const white = mask[4 * i] === 255 && mask[4 * i + 1] === 255 && mask[4 * i + 2] === 255;
    const black = mask[4 * i] === 0 && mask[4 * i + 1] === 0 && mask[4 * i + 2] === 0;
    if (!white && !black) disagree++;
    else if (black && shaded[i] !== SHADOW && shaded[i] !== AMBIGUOUS) disagree++;
    else if (white && shaded[i] === SHADOW) grazing++;
  }
  console.log(`mask view: ${disagree} disagreements with the shaded view, ${grazing} lit-at-grazing-angle pixels`);
  assert.equal(disagree, 0, 'mask view and shaded view disagree');

  // Frame time of a second frame (the first includes shader compilation).
  await page.evaluate(() => new Promise((resolve) => {
    const n = window.umbra.frames;
    window.umbra.redraw();
    const wait = () => (window.umbra.frames > n ? resolve() : requestAnimationFrame(wait));
    wait();
  }));
  const ms = await page.evaluate(() => window.umbra.frameMs);
  console.log(`second frame (readPixels-synchronised): ${ms.toFixed(1)} ms at ${W}x${H}`);
  assert.ok(ms > 0);

  // Shadows off: every shadowed pixel that faces the light becomes lit.
  const off = await open(`size=${W}x${H}&shadows=0`);
  const noShadow = classify((await readCanvas(off.page)).rgba);
  const shadowed = (cls) => cls.reduce((n, c) => n + (c === SHADOW), 0);
  assert.ok(shadowed(noShadow) < shadowed(shaded) / 2, `shadows off: ${shadowed(noShadow)} vs on: ${shadowed(shaded)} shadow pixels`);
  for (const p of [page, m.page, off.page]) await p.close();
});

test('error pages: no WebGL 2, truncated buffer, version mismatch, missing export, missing model', { skip }, async () => {
  const cases = [
    ['nowebgl=1', /no WebGL 2/],
    ['model=models/nothing.obj', /models\/nothing\.obj: HTTP 404/],
    ['scene=truncated/', /sides\.bin: has \d+ bytes, but \$\.buffers\.sides_data needs/],
    ['scene=version/', /\$\.version: this viewer reads version 2, the scene is version 999/],
    ['scene=nothing-here/', /manifest\.json: HTTP 404/],
  ];
  for (const [q, re] of cases) {
    const { page, status } = await open(q);
    assert.equal(status.state, 'error', `${q}: expected an error page`);
    assert.ok(status.visible, `${q}: the message must be visible`);
    assert.match(status.message, re, q);
    await page.close();
  }
});

test('controls: drag orbits, wheel zooms, shift-drag and arrows move the light, S and M toggle', { skip }, async () => {
  const { page, status } = await open(`size=${W}x${H}`);
  assert.equal(status.state, 'ready', status.error);
  const frame = async (act) => {
    const n = await page.evaluate(() => window.umbra.frames);
    await act();
    await page.waitForFunction((k) => window.umbra.frames > k, n, { timeout: 60_000 });
    return (await readCanvas(page)).rgba;
  };
  const differs = (a, b) => a.some((v, i) => v !== b[i]);
  const box = await page.locator('#canvas').boundingBox();
  const cx = box.x + box.width / 2, cy = box.y + box.height / 2;
  let before = (await readCanvas(page)).rgba;
  const steps = [
    ['drag orbits the camera', async () => { await page.mouse.move(cx, cy); await page.mouse.down(); await page.mouse.move(cx + 40, cy + 10); await page.mouse.up(); }],
    ['wheel zooms', async () => { await page.mouse.move(cx, cy); await page.mouse.wheel(0, 300); }],
    ['shift-drag moves the light', async () => { await page.keyboard.down('Shift'); await page.mouse.move(cx, cy); await page.mouse.down(); await page.mouse.move(cx + 60, cy); await page.mouse.up(); await page.keyboard.up('Shift'); }],
    ['arrow key moves the light', async () => { await page.keyboard.press('ArrowLeft'); }],
    ['S toggles shadows', async () => { await page.keyboard.press('s'); }],
    ['M toggles the mask view', async () => { await page.keyboard.press('m'); }],
  ];
  for (const [what, act] of steps) {
    const after = await frame(act);
    assert.ok(differs(before, after), `${what}: the image must change`);
    before = after;
  }
  assert.equal(await page.evaluate(() => window.umbra.state), 'ready');
  assert.match(await page.locator('#time').textContent(), /^frame \d+\.\d ms \(no shadows\) · mask$/);
  await page.close();
});
