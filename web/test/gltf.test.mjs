// The glTF example (examples/gltf/) in a real browser: Debian's Chromium on SwiftShader and on
// ANGLE over the system's EGL (Mesa llvmpipe), driven by playwright-core.
//
// * Its mask (umbra.readMask of the first light, which the page's `mask=1` view shows, pixel for
//   pixel) judged by the oracle, `umbra verify --external-mask` with the flags the page was
//   given (testlib/exactness.mjs):
//   0 samples outside the band for the default model (scene.gltf: a torus knot, an open wall,
//   nodes with rotations and scales) with its default point light, with a directional light,
//   and for an OBJ through `model=`; the default model with FrontSide materials (`side=front`:
//   back faces culled, as three.js draws by default), also mirrored in x (`mirror=1`: a world
//   matrix of negative determinant), judged with `--receivers front`. The page's view is
//   umbra's (test/gltf-view.test.mjs), so no camera flag is passed to either side.
// * The M key switches to three.js's shadow maps and back; the label says which.
// * The O key switches to an orthographic camera and back (`ortho=1` starts with it); its mask
//   (SwiftShader) judged by `umbra verify --method none --ortho H --ortho-far F
//   --external-mask` with the page's height and far plane: 0 samples outside the band.
// * A missing model and an unknown format: an error page naming the file, never a blank page.
//
// Needs the package built (node build-wasm.mjs; node umbra-three/build.mjs), `npm ci` in web/,
// the umbra binary (UMBRA_BIN, else $CARGO_TARGET_DIR/release/umbra, else
// target/release/umbra) and /usr/bin/chromium (skipped with a message when absent).
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import { existsSync } from 'node:fs';
import { mkdtemp, readFile, rm, writeFile } from 'node:fs/promises';
import { tmpdir } from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { createServer, listen } from '../serve.mjs';
import { launch, openViewer, judge } from '../testlib/exactness.mjs';
import { encodePng } from '../testlib/png.mjs';
import { makeAnimatedGlb } from '../testlib/animated-glb.mjs';

const here = path.dirname(fileURLToPath(import.meta.url));
const webDir = path.join(here, '..');
const repo = path.join(webDir, '..');
const CHROMIUM = process.env.UMBRA_CHROMIUM || '/usr/bin/chromium';
const PACKAGE = path.join(webDir, 'umbra-three', 'dist', 'index.js');
const MODEL = path.join(webDir, 'examples', 'gltf', 'scene.gltf');
const W = 320;
const H = 180;
// A floor, a tilted open quad over it and a box on it (OBJ: three.js's OBJLoader).
const OBJ = 'v -3 0 -2\nv 3 0 -2\nv 3 0 2\nv -3 0 2\nv -1 1.2 -0.5\nv 0.5 1.4 -0.5\nv 0.5 1.1 0.5\nv -1 0.9 0.5\n'
  + 'v 1 0 0.2\nv 1.8 0 0.2\nv 1.8 0 1\nv 1 0 1\nv 1 0.8 0.2\nv 1.8 0.8 0.2\nv 1.8 0.8 1\nv 1 0.8 1\n'
  + 'f 1 3 2\nf 1 4 3\nf 5 6 7\nf 5 7 8\nf 13 14 15\nf 13 15 16\nf 9 10 14\nf 9 14 13\nf 10 11 15\nf 10 15 14\nf 11 12 16\nf 11 16 15\nf 12 9 13\nf 12 13 16\n';

function umbraBin() {
  const candidates = [process.env.UMBRA_BIN, process.env.CARGO_TARGET_DIR && path.join(process.env.CARGO_TARGET_DIR, 'release', 'umbra'), path.join(repo, 'target', 'release', 'umbra')];
  const found = candidates.find((c) => c && existsSync(c));
  if (!found) throw new Error(`no umbra binary (tried ${candidates.filter(Boolean).join(', ')}): run cargo build --release -p umbra-cli or set UMBRA_BIN`);
  return found;
}

const skip = existsSync(CHROMIUM) ? false : `${CHROMIUM} is absent (apt-get install chromium): glTF example test skipped`;
if (skip) console.log(`SKIP: ${skip}`);

let tmp, server, base, umbra, objFile, mirroredModelFile;
const contexts = {};

before(async () => {
  if (skip) return;
  if (!existsSync(PACKAGE)) throw new Error(`${PACKAGE} is missing: build the package first (node build-wasm.mjs && node umbra-three/build.mjs, in web/)`);
  umbra = umbraBin();
  tmp = await mkdtemp(path.join(tmpdir(), 'umbra-gltf-'));
  objFile = path.join(tmp, 'canopy.obj');
  await writeFile(objFile, OBJ);
  // scene.gltf as the page's mirror=1 draws it: under one more root node of scale (-1, 1, 1),
  // whose triangles umbra's loader flips to keep them counter-clockwise (glTF's rule for a
  // mirroring transform; three.js turns glFrontFace to CW instead).
  const gltf = JSON.parse(await readFile(MODEL, 'utf8'));
  gltf.nodes.push({ name: 'mirror', scale: [-1, 1, 1], children: gltf.scenes[gltf.scene ?? 0].nodes });
  gltf.scenes[gltf.scene ?? 0].nodes = [gltf.nodes.length - 1];
  mirroredModelFile = path.join(tmp, 'scene-mirrored.gltf');
  await writeFile(mirroredModelFile, JSON.stringify(gltf));
  // web/ as the example is served to a user (node serve.mjs --root .), the OBJ beside it.
  server = createServer([['/', webDir], ['/models/', tmp]]);
  base = `${await listen(server, 0)}examples/gltf/`;
  contexts.swiftshader = await launch(CHROMIUM, 'swiftshader', tmp);
  contexts.egl = await launch(CHROMIUM, 'egl', tmp);
});

after(async () => {
  for (const k of ['swiftshader', 'egl']) if (contexts[k]) await contexts[k].close();
  if (server) await new Promise((r) => server.close(r));
  if (tmp) await rm(tmp, { recursive: true, force: true });
});

/** Opens the example with `query` at W x H, mask view; returns the page's status, its first light's mask as a PNG file and the page's umbraInfo. */
async function maskOf(ctx, query, name) {
  const { page, status, logs } = await openViewer(ctx, `${base}?size=${W}x${H}&mask=1&${query}`, 300_000);
  try {
    assert.equal(status.state, 'ready', `${query}: ${status.error}\n${logs.join('\n')}`);
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
    // What umbra.info said after the last frame (count, cull, silhouettes per light).
    const info = await page.evaluate(() => window.umbra.umbraInfo);
    return { status, png, shadowed, lit, info };
  } finally {
    await page.close();
  }
}

const CASES = [
  { name: 'default', query: '', scene: () => MODEL, flags: [] },
  { name: 'directional', query: 'light=-0.4,1,0.5,0', scene: () => MODEL, flags: ['--light', '-0.4,1,0.5,0'] },
  { name: 'obj', query: 'model=/models/canopy.obj&light=0.5,3,1.5', scene: () => objFile, flags: ['--light', '0.5,3,1.5'] },
  // FrontSide materials (three.js's default): three.js culls back faces; judged on the samples
  // of a depth pass that culls them too (`--receivers front`). Also mirrored in x (a world
  // matrix of negative determinant, where three.js turns glFrontFace to CW): culling the wrong
  // face would show the insides of the closed box and knot.
  { name: 'default FrontSide', query: 'side=front', scene: () => MODEL, flags: ['--receivers', 'front'] },
  { name: 'default FrontSide mirrored', query: 'side=front&mirror=1', scene: () => mirroredModelFile, flags: ['--receivers', 'front'] },
  // The OBJ's box is wound inwards: under FrontSide the eye looks through the box's near wall
  // (culled) onto the inside of its far wall, in the shadow of its top; the near wall is a
  // caster in front of the sample, whose light cap is counted at its true depth there
  // (docs/web.md "FrontSide"). Both counts (zpass=0: z-fail), with the volumes culled to their
  // receivers (SwiftShader's and llvmpipe's default) and not (cull=0), and with the GPU's
  // silhouettes (unculled only): `expect` is what umbra.info must say of the first light.
  ...[
    ['', { zpass: true, culled: true }],
    ['&zpass=0', { zpass: false, culled: true }],
    ['&cull=0', { zpass: true, culled: false }],
    ['&cull=0&zpass=0', { zpass: false, culled: false }],
    ['&cull=0&silhouettes=gpu', { zpass: true, culled: false, silhouettes: 'gpu' }],
    ['&cull=0&zpass=0&silhouettes=gpu', { zpass: false, culled: false, silhouettes: 'gpu' }],
  ].map(([q, expect]) => ({
    name: `obj FrontSide${q.replaceAll('&', ' ')}`, query: `model=/models/canopy.obj&light=0.5,3,1.5&side=front${q}`, scene: () => objFile,
    flags: ['--light', '0.5,3,1.5', '--receivers', 'front'], expect,
  })),
];

for (const impl of ['swiftshader', 'egl']) {
  for (const c of CASES) {
    test(`${impl}: ${c.name}: the example's mask has 0 samples outside the band`, { skip }, async (t) => {
      if (impl === 'egl' && !(await eglIsLlvmpipe())) return t.skip('ANGLE/EGL is not Mesa llvmpipe here');
      const m = await maskOf(contexts[impl], c.query, `${impl}-${c.name.replaceAll(' ', '_')}`);
      if (c.expect) {
        const info = m.info;
        assert.equal(info.zpass[0] !== null, c.expect.zpass, `z-pass asked ${c.expect.zpass}, info.zpass ${JSON.stringify(info.zpass)}`);
        assert.equal(info.volumes[0].culled, c.expect.culled, `culled asked ${c.expect.culled}: ${JSON.stringify(info.volumes)}`);
        if (c.expect.silhouettes) assert.equal(info.silhouettes, c.expect.silhouettes);
      }
      // A mask with both decisions in it: a test that can fail both ways.
      assert.ok(m.shadowed > 100 && m.lit > 100, `shadowed ${m.shadowed}, lit ${m.lit}`);
      assert.equal(m.shadowed + m.lit, W * H, 'every pixel is 0 or 255');
      const bits = Number.isInteger(m.status.subpixelBits) && m.status.subpixelBits >= 4 ? ['--subpixel-bits', String(m.status.subpixelBits)] : [];
      const r = judge(umbra, { scene: c.scene(), size: `${W}x${H}`, maskPng: m.png, extra: [...c.flags, ...bits], explain: 20 });
      assert.ok(r.browser, `no row for the mask: ${r.stderr}`);
      console.log(`${impl}: ${c.name}: ${JSON.stringify(r.browser)}`);
      assert.equal(r.browser.mismatches_outside_band, 0, `${r.falseShadow} false shadow, ${r.falseLight} false light:\n${r.explained.join('\n')}`);
    });
  }
}

test('swiftshader: side=front culls the back faces three.js culls: the OBJ\'s box, wound inwards, seen from inside, another mask than DoubleSide\'s', { skip }, async () => {
  const query = 'model=/models/canopy.obj&light=0.5,3,1.5';
  const double = await maskOf(contexts.swiftshader, query, 'canopy-double');
  const front = await maskOf(contexts.swiftshader, `${query}&side=front`, 'canopy-front');
  assert.ok(Math.abs(front.shadowed - double.shadowed) > 1000, `shadowed: FrontSide ${front.shadowed}, DoubleSide ${double.shadowed}`);
});

let eglProbe = null;
async function eglIsLlvmpipe() {
  if (eglProbe === null) {
    const { page, status } = await openViewer(contexts.egl, `${base}?size=64x64`, 300_000);
    await page.close();
    eglProbe = /llvmpipe/.test(status.renderer || '');
    if (!eglProbe) console.log(`SKIP the ANGLE/EGL rows: Chromium's EGL back end gave ${status.renderer || status.error}`);
  }
  return eglProbe;
}

test('M switches to three.js shadow maps and back, the label says which', { skip }, async () => {
  const { page, status, logs } = await openViewer(contexts.swiftshader, `${base}?size=${W}x${H}`, 300_000);
  try {
    assert.equal(status.state, 'ready', `${status.error}\n${logs.join('\n')}`);
    const shown = () => page.evaluate(() => ({ mode: window.umbra.mode, frames: window.umbra.frames, label: document.getElementById('mode').textContent, state: window.umbra.state }));
    const before = await shown();
    assert.equal(before.mode, 'umbra');
    assert.match(before.label, /umbra/);
    for (const expected of ['maps', 'umbra']) {
      const frames = (await shown()).frames;
      await page.keyboard.press('m');
      await page.waitForFunction((n) => window.umbra.frames > n, frames, { timeout: 120_000 });
      const now = await shown();
      assert.equal(now.state, 'ready');
      assert.equal(now.mode, expected);
      assert.match(now.label, expected === 'maps' ? /three\.js shadow maps/ : /umbra/);
    }
  } finally {
    await page.close();
  }
});

test('O switches to an orthographic camera and back (ortho=1 starts with it): its mask has 0 samples outside the band (umbra verify --ortho --ortho-far)', { skip }, async () => {
  const { page, status, logs } = await openViewer(contexts.swiftshader, `${base}?size=${W}x${H}&mask=1&ortho=1`, 300_000);
  try {
    assert.equal(status.state, 'ready', `${status.error}\n${logs.join('\n')}`);
    const shown = () => page.evaluate(() => ({ projection: window.umbra.projection, ortho: window.umbra.ortho, height: window.umbra.orthoHeight, frames: window.umbra.frames, label: document.getElementById('mode').textContent, errors: window.umbra.errors.map((e) => `${e.mesh}: ${e.message}`) }));
    const o = await shown();
    assert.equal(o.projection, 'orthographic');
    assert.match(o.label, /orthographic/);
    assert.deepEqual(o.errors, [], 'nothing refused');
    assert.ok(o.ortho && o.ortho.far > o.ortho.near, `umbra drew it orthographic: ${JSON.stringify(o.ortho)}`);
    const bytes = Buffer.from(await page.evaluate(() => window.umbra.readMask()), 'latin1');
    const rgba = new Uint8Array(W * H * 4);
    for (let i = 0; i < W * H; i++) rgba.set([bytes[i], bytes[i], bytes[i], 255], 4 * i);
    const png = path.join(tmp, 'swiftshader-ortho.png');
    await writeFile(png, encodePng(W, H, rgba));
    const shadowed = bytes.filter((v) => v === 0).length;
    assert.ok(shadowed > 100 && W * H - shadowed > 100, `shadowed ${shadowed} of ${W * H}`);
    // The example's default view and light are umbra's for the file: only the projection is named.
    const args = ['verify', '--scene', MODEL, '--method', 'none', '--size', `${W}x${H}`, '--ortho', String(o.height), '--ortho-far', String(o.ortho.far),
      '--subpixel-bits', String(status.subpixelBits), '--external-mask', png, '--json', '--explain', '20'];
    const r = spawnSync(umbra, args, { encoding: 'utf8' });
    assert.ok(r.status === 0 || r.status === 1, `umbra ${args.join(' ')}: exit ${r.status}: ${r.stderr}`);
    const row = JSON.parse(r.stdout).find((x) => x.method === png);
    console.log(JSON.stringify({ ortho: o.ortho, height: o.height, samples: row.samples, band: row.band_samples, outside: row.mismatches_outside_band }));
    assert.equal(row.mismatches_outside_band, 0, r.stderr.split('\n').filter((l) => l.startsWith(png)).join('\n'));
    for (const expected of ['perspective', 'orthographic']) {
      await page.keyboard.press('o');
      await page.waitForFunction((p) => window.umbra.projection === p && window.umbra.state === 'ready', expected, { timeout: 120_000 });
      await page.waitForFunction((p) => (window.umbra.ortho === null) === (p === 'perspective'), expected, { timeout: 120_000 });
    }
  } finally {
    await page.close();
  }
});

test('an animated glTF (a skinned column bending, EXT_mesh_gpu_instancing boxes) plays through the example: every instance and the skinned mesh cast, the shadow follows the animation; L shows the light gizmo outside umbra\'s depth pass', { skip }, async () => {
  // The model, written by three.js's own GLTFExporter in the page (testlib/animated-glb.mjs):
  // a floor, a two-bone column whose joint turns back and forth over 2 s, three instanced boxes.
  const maker = await openViewer(contexts.swiftshader, `${base}?size=64x64`, 300_000);
  try {
    await writeFile(path.join(tmp, 'animated.glb'), await makeAnimatedGlb(maker.page));
  } finally {
    await maker.page.close();
  }
  const { page, status, logs } = await openViewer(contexts.swiftshader, `${base}?size=${W}x${H}&model=/models/animated.glb&light=0.5,4,1`, 300_000);
  try {
    assert.equal(status.state, 'ready', `${status.error}\n${logs.join('\n')}`);
    const read = () => page.evaluate(() => ({ frames: window.umbra.frames, info: window.umbra.umbraInfo, animations: window.umbra.animations, errors: window.umbra.errors.map((e) => `${e.mesh}: ${e.message}`), mask: window.umbra.readMask() }));
    const first = await read();
    assert.equal(first.animations, 1, 'the clip travels with the model');
    assert.deepEqual(first.errors, [], 'no mesh refused');
    // The floor, the column and three instances (each light).
    assert.equal(first.info.casters, 5, `every instance and the skinned column cast: ${JSON.stringify(first.info)}`);
    // It keeps drawing while the animation plays.
    await page.waitForFunction((n) => window.umbra.frames > n + 2, first.frames, { timeout: 120_000 });
    await page.waitForTimeout(500);
    const later = await read();
    assert.notEqual(later.mask, first.mask, 'the column\'s shadow follows its animation');
    // L: the light's gizmo, drawn in a scene of its own: umbra's casters unchanged.
    await page.keyboard.press('l');
    await page.waitForFunction((n) => window.umbra.frames > n, later.frames, { timeout: 120_000 });
    const gizmo = await read();
    assert.equal(gizmo.info.casters, 5, 'the gizmo is not in umbra\'s scene');
    assert.deepEqual(gizmo.errors, []);
  } finally {
    await page.close();
  }
});

test('a missing model and an unknown format: an error page naming the file', { skip }, async () => {
  for (const [model, re] of [['nothere.gltf', /nothere\.gltf: HTTP 404/], ['model.xyz', /model\.xyz: unknown model format "\.xyz"/]]) {
    const { page, status } = await openViewer(contexts.swiftshader, `${base}?size=64x64&model=${model}`, 120_000);
    await page.close();
    assert.equal(status.state, 'error');
    assert.match(status.error, re);
    assert.ok(status.visible, 'the message is shown on the page');
    assert.match(status.message, re);
  }
});
