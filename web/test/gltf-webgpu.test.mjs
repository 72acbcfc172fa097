// The glTF example (examples/gltf/) on three.js's WebGPURenderer (`renderer=webgpu`: the
// import map loads three.webgpu.js and three.tsl.js, the page umbra-three/webgpu), in Debian's
// Chromium with WebGPU on SwiftShader (testlib/exactness.mjs IMPLEMENTATIONS.webgpu). Headless
// Chromium cannot present a WebGPU canvas, so the page runs with `offscreen=1`: every frame is
// drawn into a RenderTarget and copied to the canvas through a 2D context.
//
// * Its first light's mask (window.umbra.readMask(), a Promise on WebGPU; the page's `mask=1`
//   view shows it, pixel for pixel) judged by `umbra verify --external-mask` with the page's
//   flags and --subpixel-bits WEBGPU_SUBPIXEL_BITS: 0 samples outside the band for the default
//   model with its point light and with a directional light, an OBJ through `model=`, and the
//   default model with FrontSide materials (`side=front`), also mirrored (`mirror=1`), judged
//   with `--receivers front` (the cases of test/gltf.test.mjs).
// * M switches to three.js's shadow maps (the lights' twins) and back; the label says which.
//   L shows the light gizmo, outside umbra's scene.
// * What umbra's WebGPU path does not draw yet is said on the page and in window.umbra, never a
//   blank page: `ortho=1` (and O) keeps the perspective camera with a warning; an animated
//   glTF's skinned column is named in umbra.errors and in the warning box, the page drawn.
// * `renderer=` with another value is an error page naming the parameter.
//
// Skipped with a message when Chromium is absent or gives no WebGPU adapter. Needs the package
// built (node build-wasm.mjs; node umbra-three/build.mjs), `npm ci` in web/ and the umbra binary
// (UMBRA_BIN, else $CARGO_TARGET_DIR/release/umbra, else target/release/umbra).
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { existsSync } from 'node:fs';
import { mkdtemp, readFile, rm, writeFile } from 'node:fs/promises';
import { tmpdir } from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { createServer, listen } from '../serve.mjs';
import { launch, openViewer, judge, WEBGPU_SUBPIXEL_BITS } from '../testlib/exactness.mjs';
import { encodePng } from '../testlib/png.mjs';
import { makeAnimatedGlb } from '../testlib/animated-glb.mjs';

const here = path.dirname(fileURLToPath(import.meta.url));
const webDir = path.join(here, '..');
const repo = path.join(webDir, '..');
const CHROMIUM = process.env.UMBRA_CHROMIUM || '/usr/bin/chromium';
const PACKAGE = path.join(webDir, 'umbra-three', 'dist', 'webgpu.js');
const MODEL = path.join(webDir, 'examples', 'gltf', 'scene.gltf');
const W = 320;
const H = 180;
// The OBJ of test/gltf.test.mjs: a floor, a tilted open quad over it and a box on it.
const OBJ = 'v -3 0 -2\nv 3 0 -2\nv 3 0 2\nv -3 0 2\nv -1 1.2 -0.5\nv 0.5 1.4 -0.5\nv 0.5 1.1 0.5\nv -1 0.9 0.5\n'
  + 'v 1 0 0.2\nv 1.8 0 0.2\nv 1.8 0 1\nv 1 0 1\nv 1 0.8 0.2\nv 1.8 0.8 0.2\nv 1.8 0.8 1\nv 1 0.8 1\n'
  + 'f 1 3 2\nf 1 4 3\nf 5 6 7\nf 5 7 8\nf 13 14 15\nf 13 15 16\nf 9 10 14\nf 9 14 13\nf 10 11 15\nf 10 15 14\nf 11 12 16\nf 11 16 15\nf 12 9 13\nf 12 13 16\n';
const WEBGPU = 'renderer=webgpu&offscreen=1';

const umbraBin = [process.env.UMBRA_BIN, process.env.CARGO_TARGET_DIR && path.join(process.env.CARGO_TARGET_DIR, 'release', 'umbra'), path.join(repo, 'target', 'release', 'umbra')]
  .find((c) => c && existsSync(c));
let skip = !existsSync(CHROMIUM) ? `${CHROMIUM} is absent (apt-get install chromium): glTF example WebGPU test skipped`
  : !umbraBin ? 'no umbra binary (cargo build --release -p umbra-cli, or UMBRA_BIN): glTF example WebGPU test skipped' : false;
if (skip) console.log(`SKIP: ${skip}`);

let tmp, server, base, ctx, objFile, mirroredModelFile;

before(async () => {
  if (skip) return;
  if (!existsSync(PACKAGE)) throw new Error(`${PACKAGE} is missing: build the package first (node build-wasm.mjs && node umbra-three/build.mjs, in web/)`);
  tmp = await mkdtemp(path.join(tmpdir(), 'umbra-gltf-webgpu-'));
  objFile = path.join(tmp, 'canopy.obj');
  await writeFile(objFile, OBJ);
  // scene.gltf as mirror=1 draws it, under a root node of scale (-1, 1, 1) (see gltf.test.mjs).
  const gltf = JSON.parse(await readFile(MODEL, 'utf8'));
  gltf.nodes.push({ name: 'mirror', scale: [-1, 1, 1], children: gltf.scenes[gltf.scene ?? 0].nodes });
  gltf.scenes[gltf.scene ?? 0].nodes = [gltf.nodes.length - 1];
  mirroredModelFile = path.join(tmp, 'scene-mirrored.gltf');
  await writeFile(mirroredModelFile, JSON.stringify(gltf));
  // web/ as the example is served to a user (node serve.mjs --root .): a http://127.0.0.1 page.
  server = createServer([['/', webDir], ['/models/', tmp]]);
  base = `${await listen(server, 0)}examples/gltf/`;
  ctx = await launch(CHROMIUM, 'webgpu', tmp);
  const page = await ctx.newPage();
  try {
    await page.goto(`${base}view.js`); // any http://127.0.0.1 page
    const adapter = await page.evaluate(async () => {
      const a = navigator.gpu && await navigator.gpu.requestAdapter();
      return a ? `${a.info.vendor} ${a.info.architecture}` : null;
    });
    if (!adapter) {
      skip = 'this Chromium gives no WebGPU adapter: glTF example WebGPU test skipped';
      console.log(`SKIP: ${skip}`);
    } else {
      console.log(`WebGPU adapter: ${adapter}`);
    }
  } finally {
    await page.close();
  }
});

after(async () => {
  if (ctx) await ctx.close();
  if (server) await new Promise((r) => server.close(r));
  if (tmp) await rm(tmp, { recursive: true, force: true });
});

/** Opens the example on WebGPU with `query` at W x H, mask view; the first light's mask as a PNG, checked against the mask view. */
async function maskOf(query, name) {
  const { page, status, logs } = await openViewer(ctx, `${base}?${WEBGPU}&size=${W}x${H}&mask=1&${query}`, 300_000);
  try {
    assert.equal(status.state, 'ready', `${query}: ${status.error}\n${logs.join('\n')}`);
    assert.match(status.renderer, /^WebGPU/);
    const page0 = await page.evaluate(() => ({ backend: window.umbra.backend, errors: window.umbra.errors.map((e) => `${e.mesh}: ${e.message}`), warnings: window.umbra.warnings, info: window.umbra.umbraInfo }));
    assert.equal(page0.backend, 'webgpu');
    assert.equal(page0.info.backend, 'webgpu', 'drawn by umbra-three/webgpu');
    assert.deepEqual(page0.errors, [], 'nothing refused');
    assert.deepEqual(page0.warnings, [], 'no warning');
    const bytes = Buffer.from(await page.evaluate(() => window.umbra.readMask()), 'latin1');
    assert.equal(bytes.length, W * H, 'readMask: one byte per pixel');
    const rgba = new Uint8Array(W * H * 4);
    for (let i = 0; i < W * H; i++) rgba.set([bytes[i], bytes[i], bytes[i], 255], 4 * i);
    const png = path.join(tmp, `${name}.png`);
    await writeFile(png, encodePng(W, H, rgba));
    // The mask view on the canvas (mask=1) is that decision, pixel for pixel.
    const shown = Buffer.from(await page.evaluate(() => window.umbra.readCanvas()), 'latin1');
    assert.equal(shown.length, W * H, 'canvas size');
    let differ = 0;
    for (let i = 0; i < W * H; i++) if (shown[i] !== bytes[i]) differ += 1;
    assert.equal(differ, 0, 'pixels where the mask view differs from readMask');
    const shadowed = bytes.filter((v) => v === 0).length;
    const lit = bytes.filter((v) => v === 255).length;
    return { png, shadowed, lit, info: page0.info };
  } finally {
    await page.close();
  }
}

const CASES = [
  { name: 'default', query: '', scene: () => MODEL, flags: [] },
  { name: 'directional', query: 'light=-0.4,1,0.5,0', scene: () => MODEL, flags: ['--light', '-0.4,1,0.5,0'] },
  { name: 'obj', query: 'model=/models/canopy.obj&light=0.5,3,1.5', scene: () => objFile, flags: ['--light', '0.5,3,1.5'] },
  { name: 'default FrontSide', query: 'side=front', scene: () => MODEL, flags: ['--receivers', 'front'] },
  { name: 'default FrontSide mirrored', query: 'side=front&mirror=1', scene: () => mirroredModelFile, flags: ['--receivers', 'front'] },
  // method=ray-bvh: the package's shadow rays (rays.js) instead of the volumes.
  { name: 'ray-bvh', query: 'method=ray-bvh', scene: () => MODEL, flags: [], method: 'ray-bvh' },
  { name: 'ray-bvh directional', query: 'method=ray-bvh&light=-0.4,1,0.5,0', scene: () => MODEL, flags: ['--light', '-0.4,1,0.5,0'], method: 'ray-bvh' },
];

for (const c of CASES) {
  test(`webgpu: ${c.name}: the example's mask has 0 samples outside the band`, async (t) => {
    if (skip) return t.skip(skip);
    const m = await maskOf(c.query, `webgpu-${c.name}`);
    assert.equal(m.info.method, c.method ?? 'cs-silhouette', 'the method the page asked for');
    // A mask with both decisions in it: a test that can fail both ways.
    assert.ok(m.shadowed > 100 && m.lit > 100, `shadowed ${m.shadowed}, lit ${m.lit}`);
    assert.equal(m.shadowed + m.lit, W * H, 'every pixel is 0 or 255');
    const r = judge(umbraBin, { scene: c.scene(), size: `${W}x${H}`, maskPng: m.png, extra: [...c.flags, '--subpixel-bits', String(WEBGPU_SUBPIXEL_BITS)], explain: 20 });
    assert.ok(r.browser, `no row for the mask: ${r.stderr}`);
    console.log(JSON.stringify({ case: c.name, samples: r.browser.samples, band: r.browser.band_samples, outside: r.browser.mismatches_outside_band, shadowed: m.shadowed }));
    assert.equal(r.browser.mismatches_outside_band, 0, `${r.falseShadow} false shadow, ${r.falseLight} false light:\n${r.explained.join('\n')}`);
  });
}

test('webgpu: M switches to three.js shadow maps and back, the label says which; L shows the light gizmo', async (t) => {
  if (skip) return t.skip(skip);
  const { page, status, logs } = await openViewer(ctx, `${base}?${WEBGPU}&size=${W}x${H}`, 300_000);
  try {
    assert.equal(status.state, 'ready', `${status.error}\n${logs.join('\n')}`);
    // The canvas read first (readCanvas draws a frame), then what the page says.
    const shown = () => page.evaluate(async () => {
      const canvas = await window.umbra.readCanvas();
      return { mode: window.umbra.mode, frames: window.umbra.frames, label: document.getElementById('mode').textContent, state: window.umbra.state, canvas };
    });
    const before = await shown();
    assert.equal(before.mode, 'umbra');
    assert.match(before.label, /umbra.*WebGPU/);
    const images = { umbra: before.canvas };
    for (const expected of ['maps', 'umbra']) {
      const frames = (await shown()).frames;
      await page.keyboard.press('m');
      await page.waitForFunction((n) => window.umbra.frames > n, frames, { timeout: 120_000 });
      const now = await shown();
      assert.equal(now.state, 'ready', now.state === 'error' ? await page.evaluate(() => window.umbra.error) : '');
      assert.equal(now.mode, expected);
      assert.match(now.label, expected === 'maps' ? /three\.js shadow maps/ : /umbra/);
      images[`${expected}2`] = now.canvas;
    }
    // The maps draw another image (their shadows are not umbra's); back on umbra, umbra's again.
    assert.notEqual(images.maps2, images.umbra, 'the shadow maps frame differs from umbra\'s');
    assert.equal(images.umbra2, images.umbra, 'back on umbra: the same frame as before');
    // L: the light's gizmo, drawn after umbra's frame in a scene of its own: nothing refused.
    const frames = (await shown()).frames;
    await page.keyboard.press('l');
    await page.waitForFunction((n) => window.umbra.frames > n, frames, { timeout: 120_000 });
    const gizmo = await page.evaluate(() => ({ state: window.umbra.state, errors: window.umbra.errors.length, casters: window.umbra.umbraInfo.casters }));
    assert.deepEqual(gizmo, { state: 'ready', errors: 0, casters: 6 }, 'the gizmo is not in umbra\'s scene');
  } finally {
    await page.close();
  }
});

test('webgpu: ortho=1 and O keep the perspective camera, said on the page and in window.umbra.warnings', async (t) => {
  if (skip) return t.skip(skip);
  const { page, status, logs } = await openViewer(ctx, `${base}?${WEBGPU}&size=${W}x${H}&ortho=1`, 300_000);
  try {
    assert.equal(status.state, 'ready', `${status.error}\n${logs.join('\n')}`);
    const read = () => page.evaluate(() => ({ projection: window.umbra.projection, warnings: window.umbra.warnings, frames: window.umbra.frames, box: document.getElementById('warning').textContent, boxShown: getComputedStyle(document.getElementById('warning')).display !== 'none', errors: window.umbra.errors.length }));
    const o = await read();
    assert.equal(o.projection, 'perspective');
    assert.equal(o.warnings.length, 1, JSON.stringify(o.warnings));
    assert.match(o.warnings[0], /orthographic camera is not drawn by umbra-three\/webgpu/);
    assert.ok(o.boxShown, 'the warning is shown on the page');
    assert.match(o.box, /orthographic/);
    assert.equal(o.errors, 0, 'umbra drew the perspective frame');
    await page.keyboard.press('o');
    await page.waitForFunction((n) => window.umbra.frames > n, o.frames, { timeout: 120_000 });
    const after = await read();
    assert.equal(after.projection, 'perspective');
    assert.equal(after.warnings.length, 1, 'said once');
  } finally {
    await page.close();
  }
});

test('webgpu: an animated glTF: its skinned column is refused by name on the page and in umbra.errors, the rest drawn and shadowed', async (t) => {
  if (skip) return t.skip(skip);
  const maker = await openViewer(ctx, `${base}?${WEBGPU}&size=64x64`, 300_000);
  try {
    await writeFile(path.join(tmp, 'animated.glb'), await makeAnimatedGlb(maker.page));
  } finally {
    await maker.page.close();
  }
  const { page, status, logs } = await openViewer(ctx, `${base}?${WEBGPU}&size=${W}x${H}&model=/models/animated.glb&light=4,3,3`, 300_000);
  try {
    assert.equal(status.state, 'ready', `${status.error}\n${logs.join('\n')}`);
    const r = await page.evaluate(async () => ({
      animations: window.umbra.animations,
      errors: window.umbra.errors.map((e) => ({ ...e })),
      info: window.umbra.umbraInfo,
      box: document.getElementById('warning').textContent,
      boxShown: getComputedStyle(document.getElementById('warning')).display !== 'none',
      mask: await window.umbra.readMask(),
    }));
    assert.equal(r.animations, 1, 'the clip travels with the model');
    assert.equal(r.errors.length, 1, JSON.stringify(r.errors));
    assert.equal(r.errors[0].mesh, 'column');
    assert.match(r.errors[0].message, /SkinnedMesh: not drawn by umbra's WebGPU path yet/);
    assert.ok(r.boxShown, 'the refusal is shown on the page');
    assert.match(r.box, /column: SkinnedMesh/);
    // The floor and the three instances cast; the boxes shadow the floor towards the eye (the
    // column, refused, casts no umbra shadow).
    assert.equal(r.info.casters, 4, JSON.stringify(r.info));
    const shadowed = Buffer.from(r.mask, 'latin1').filter((v) => v === 0).length;
    assert.ok(shadowed > 100, `the instances cast: ${shadowed} pixels shadowed`);
  } finally {
    await page.close();
  }
});

test('webgpu: renderer= with another value is an error page naming the parameter', async (t) => {
  if (skip) return t.skip(skip);
  const { page, status } = await openViewer(ctx, `${base}?size=64x64&renderer=vulkan`, 120_000);
  await page.close();
  assert.equal(status.state, 'error');
  assert.match(status.error, /URL parameter renderer=vulkan: expected webgl \(the default\) or webgpu/);
  assert.ok(status.visible, 'the message is shown on the page');
});
