// umbra-three under a three.js OrthographicCamera, in Debian's Chromium (headless) on both
// WebGL 2 implementations this machine has (SwiftShader, and ANGLE on the system's EGL: Mesa
// llvmpipe). Every volume is closed at finite far ends beyond the drawn meshes' world box and
// counted z-fail, with umbra's own projection's far plane beyond those ends (docs/web.md,
// "Orthographic cameras"). Judged by the oracle: the page writes the scene's triangles out in
// world space (the small scene) or the test names the file it loaded (Crytek Sponza, through
// OBJLoader), and `umbra verify --method none --ortho H --ortho-far F --external-mask`
// judges each light's mask in the page's orthographic view, with the far plane the page drew
// with (`umbra.info.ortho.far`): 0 samples outside the band for a point and a directional
// light, drawn in one frame (one mask channel each).
//
// * The small scene: a floor, a box, a box turned a quarter and halved, a mirrored box and a
//   slab, seen from above at an angle (H = 9) and from the side along the floor (H = 6).
// * Crytek Sponza (UMBRA_SCENES, default ../shared/scenes; skipped with a message when
//   absent), 320 x 180: under the west gallery (eye -5,2.5,0 towards -10,0.5,-1, H = 8), along
//   the atrium (eye -12,4,0.5 towards 10,2,0, H = 14) and from above (eye 0,40,0.1 towards the
//   origin, H = 30), with its default point light and the directional light 0.3,1,0.2,0.
// * Also: the frame is counted z-fail (info.zpass), a frame with nothing moved is reused with
//   the same far plane, and the camera moved changes the mask.
//
// Needs: /usr/bin/chromium, the wasm module (node build-wasm.mjs) and the umbra binary
// (cargo build --release -p umbra-cli, or UMBRA_BIN); skipped with a message when one is
// absent. Run: cd web && UMBRA_SCENES=/work/shared/scenes node --test test/ortho.test.mjs
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import { existsSync } from 'node:fs';
import { mkdtemp, mkdir, rm, writeFile } from 'node:fs/promises';
import { tmpdir } from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { createServer, listen } from '../serve.mjs';
import { buildPackage } from '../umbra-three/build.mjs';
import { launch } from '../testlib/exactness.mjs';
import { encodePng } from '../testlib/png.mjs';

const here = path.dirname(fileURLToPath(import.meta.url));
const webDir = path.join(here, '..');
const repo = path.join(webDir, '..');
const CHROMIUM = process.env.UMBRA_CHROMIUM || '/usr/bin/chromium';
const WASM = path.join(webDir, 'umbra-geom-wasm', 'umbra_wasm.wasm');
const SCENES_DIR = process.env.UMBRA_SCENES || path.join(repo, '..', 'shared', 'scenes');
const SPONZA = 'crytek-sponza.obj.gz';
const umbraBin = [process.env.UMBRA_BIN, process.env.CARGO_TARGET_DIR && path.join(process.env.CARGO_TARGET_DIR, 'release', 'umbra'), path.join(repo, 'target', 'release', 'umbra')]
  .find((c) => c && existsSync(c));
const skip = !existsSync(CHROMIUM) ? `${CHROMIUM} is absent (apt-get install chromium): orthographic test skipped`
  : !existsSync(WASM) ? `${WASM} is absent (node build-wasm.mjs): orthographic test skipped`
    : !umbraBin ? 'no umbra binary (cargo build --release -p umbra-cli, or UMBRA_BIN): orthographic test skipped' : false;
if (skip) console.log(`SKIP: ${skip}`);
const skipSponza = skip || (!existsSync(path.join(SCENES_DIR, SPONZA)) ? `${SPONZA} absent from ${SCENES_DIR} (UMBRA_SCENES): orthographic Sponza test skipped` : false);
if (skipSponza && !skip) console.log(`SKIP: ${skipSponza}`);

const PAGE = `<!doctype html>
<html><head><meta charset="utf-8">
<script type="importmap">
{ "imports": { "three": "/three/build/three.module.js", "three/addons/": "/three/examples/jsm/", "umbra-three": "/umbra-three/index.js" } }
</script></head>
<body></body></html>
`;

let tmp, server, base;
const contexts = {};

before(async () => {
  if (skip) return;
  tmp = await mkdtemp(path.join(tmpdir(), 'umbra-ortho-'));
  const dist = await buildPackage(path.join(tmp, 'umbra-three'));
  const root = path.join(tmp, 'root');
  await mkdir(root);
  await writeFile(path.join(root, 'index.html'), PAGE);
  const mounts = [['/', root], ['/three/', path.join(webDir, 'node_modules', 'three')], ['/umbra-three/', dist], ['/testlib/', path.join(webDir, 'testlib')]];
  if (!skipSponza) mounts.push(['/scenes/', SCENES_DIR]);
  server = createServer(mounts);
  base = await listen(server, 0);
});

after(async () => {
  for (const ctx of Object.values(contexts)) await ctx.close();
  if (server) await new Promise((r) => server.close(r));
  if (tmp) await rm(tmp, { recursive: true, force: true });
});

/** A page on implementation `impl` with window.makeWorld(kind, view) ready. */
async function pageOn(impl) {
  contexts[impl] ??= await launch(CHROMIUM, impl, path.join(tmp, impl));
  const page = await contexts[impl].newPage();
  page.on('pageerror', (e) => console.log(`page error: ${e}`));
  await page.goto(base);
  await page.evaluate(() => {
    // kind 'small' (built here) or 'sponza' (OBJLoader); view: { w, h, eye, target, height, point, directional }.
    window.makeWorld = async (kind, view) => {
      const THREE = await import('three');
      const { UmbraShadows } = await import('umbra-three');
      const canvas = document.createElement('canvas');
      document.body.appendChild(canvas);
      const renderer = new THREE.WebGLRenderer({ canvas });
      renderer.setPixelRatio(1);
      renderer.setSize(view.w, view.h, false);
      const umbra = await UmbraShadows.create(renderer);
      const scene = new THREE.Scene();
      const mat = () => new THREE.MeshLambertMaterial({ color: 0xcccccc, side: THREE.DoubleSide });
      // The meshes whose triangles the oracle judges, with their world matrices.
      const meshes = [];
      if (kind === 'small') {
        const add = (geometry, matrix) => {
          const m = new THREE.Mesh(geometry, mat());
          m.castShadow = true;
          if (matrix) {
            m.matrixAutoUpdate = false;
            m.matrix.copy(matrix);
          }
          scene.add(m);
          meshes.push(m);
        };
        // Matrices of 0, +-1, +-0.5 and dyadic offsets: the world positions are exact in f32.
        const m4 = (r0, r1, r2, t) => new THREE.Matrix4().set(...r0, t[0], ...r1, t[1], ...r2, t[2], 0, 0, 0, 1);
        add(new THREE.PlaneGeometry(10, 10).rotateX(-Math.PI / 2));
        add(new THREE.BoxGeometry(1, 1, 1), m4([1, 0, 0], [0, 1, 0], [0, 0, 1], [-2, 1, 0]));
        add(new THREE.BoxGeometry(1, 1, 1), m4([0, 0, 0.5], [0, 0.5, 0], [-0.5, 0, 0], [2, 1, 1]));
        // Mirrored (determinant -1): its winding turns, its shadow must not.
        add(new THREE.BoxGeometry(1, 1, 1), m4([-1, 0, 0], [0, 1, 0], [0, 0, 1], [0, 1.5, -1]));
        add(new THREE.BoxGeometry(1.5, 0.25, 0.5), m4([1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 2.5, -0.5]));
      } else {
        const { OBJLoader } = await import('three/addons/loaders/OBJLoader.js');
        const response = await fetch(view.url);
        const text = await new Response(response.body.pipeThrough(new DecompressionStream('gzip'))).text();
        const object = new OBJLoader().parse(text);
        object.traverse((o) => {
          if (!o.isMesh) return;
          o.material = mat();
          o.castShadow = true;
          meshes.push(o);
        });
        scene.add(object);
      }
      const point = new THREE.PointLight(0xffffff, 8, 0, 0);
      point.position.fromArray(view.point);
      point.castShadow = true;
      const directional = new THREE.DirectionalLight(0xffffff, 1);
      directional.position.fromArray(view.directional);
      directional.castShadow = true;
      scene.add(point, directional, directional.target, new THREE.AmbientLight(0xffffff, 0.3));
      scene.updateMatrixWorld(true);

      // Every mesh's triangles in world space (f64 then f32), and umbra's near plane for a mesh
      // file (crates/umbra-cli/src/session.rs): 1e-3 of the f32 diagonal of their bounds.
      const { addWorldTriangles, meshFileNear, trianglesObj } = await import('/testlib/page-world.js');
      const world = () => {
        const pos = [];
        for (const m of meshes) addWorldTriangles(pos, m.geometry, m.matrixWorld.elements);
        return { pos, near: meshFileNear(pos) };
      };
      const out = world();
      const aspect = view.w / view.h;
      const camera = new THREE.OrthographicCamera(-0.5 * view.height * aspect, 0.5 * view.height * aspect, 0.5 * view.height, -0.5 * view.height, out.near, 1000);
      camera.position.fromArray(view.eye);
      camera.lookAt(...view.target);
      camera.updateMatrixWorld(true);
      const toString = (mask) => {
        let s = '';
        for (let i = 0; i < mask.length; i += 8192) s += String.fromCharCode.apply(null, mask.subarray(i, i + 8192));
        return s;
      };
      const frame = () => {
        umbra.render(scene, camera);
        const info = umbra.info;
        return {
          masks: [toString(umbra.readMask(point)), toString(umbra.readMask(directional))],
          errors: umbra.errors.slice(),
          info: { casters: info.casters, zpass: info.zpass, ortho: info.ortho, reused: info.reused, volumes: info.volumes },
          subpixelBits: umbra.subpixelBits,
          lights: [[...point.position.toArray(), 1], [...directional.position.toArray(), 0]],
        };
      };
      const obj = () => trianglesObj(out.pos);
      window.T = { THREE, umbra, scene, camera, frame, obj };
    };
  });
  return page;
}

/**
 * Light k's mask of frame `f` judged by `umbra verify --method none --ortho H --ortho-far F
 * --external-mask` on `scene`; returns the mask's JSON row and the explained mismatches.
 */
function judgeOrtho(name, f, k, { scene, view }) {
  const gray = Buffer.from(f.masks[k], 'latin1');
  const rgba = new Uint8Array(4 * view.w * view.h);
  for (let i = 0; i < gray.length; i++) rgba.set([gray[i], gray[i], gray[i], 255], 4 * i);
  const png = path.join(tmp, `${name}-light${k}.png`);
  return writeFile(png, encodePng(view.w, view.h, rgba)).then(() => {
    const args = ['verify', '--scene', scene, '--method', 'none', '--size', `${view.w}x${view.h}`,
      '--eye', view.eye.join(','), '--target', view.target.join(','), '--ortho', String(view.height), '--ortho-far', String(f.info.ortho.far),
      '--light', f.lights[k].join(','), '--subpixel-bits', String(f.subpixelBits), '--external-mask', png, '--json', '--explain', '20'];
    const r = spawnSync(umbraBin, args, { encoding: 'utf8', maxBuffer: 64 << 20 });
    if (r.status !== 0 && r.status !== 1) throw new Error(`umbra ${args.join(' ')}: exit ${r.status}: ${r.stderr}`);
    const row = JSON.parse(r.stdout).find((x) => x.method === png);
    const explained = r.stderr.split('\n').filter((l) => l.startsWith(`${png} `)).map((l) => l.slice(png.length + 1));
    let dark = 0;
    for (let i = 0; i < gray.length; i++) dark += gray[i] === 0;
    return { row, explained, dark };
  });
}

/** Draws `kind` in `view` on `impl`, judges both lights' masks; returns the frame and the rows. */
async function drawAndJudge(page, impl, name, kind, view, scene) {
  await page.evaluate(([kd, v]) => window.makeWorld(kd, v), [kind, view]);
  const f = await page.evaluate(() => window.T.frame());
  if (kind === 'small') {
    scene = path.join(tmp, `${name}.obj`);
    await writeFile(scene, await page.evaluate(() => window.T.obj()));
  }
  assert.deepEqual(f.errors, [], 'nothing refused');
  assert.ok(f.info.ortho && f.info.ortho.far > f.info.ortho.near, `info.ortho holds the far plane: ${JSON.stringify(f.info.ortho)}`);
  assert.deepEqual(f.info.zpass, [null, null], 'counted z-fail');
  const rows = [];
  for (const k of [0, 1]) {
    const r = await judgeOrtho(`${impl}-${name}`, f, k, { scene, view });
    console.log(JSON.stringify({ impl, name, light: f.lights[k], far: f.info.ortho.far, samples: r.row.samples, shadowed: r.row.shadowed_reference, band: r.row.band_samples, mismatches: r.row.mismatches, outside: r.row.mismatches_outside_band, dark: r.dark }));
    assert.equal(r.row.mismatches_outside_band, 0, `${impl} ${name} light ${k}: 0 outside the band: ${r.explained.join('; ')}`);
    assert.ok(r.row.shadowed_reference > 0.02 * r.row.samples, `${impl} ${name} light ${k}: the view holds shadow (${r.row.shadowed_reference} of ${r.row.samples})`);
    rows.push(r);
  }
  return { f, rows };
}

const SMALL = [
  ['above', { w: 320, h: 240, eye: [0, 5, 7], target: [0, 0, 0], height: 9, point: [0.5, 4.5, 1], directional: [2, 5, 1] }],
  ['side', { w: 320, h: 240, eye: [-7, 1.25, 2], target: [0, 0.75, 0], height: 6, point: [0.5, 4.5, 1], directional: [2, 5, 1] }],
];

for (const impl of ['swiftshader', 'egl']) {
  test(`${impl}: an OrthographicCamera over a small scene (turned, scaled and mirrored boxes), a point and a directional light, z-fail: 0 samples outside the band; a still frame is reused, a moved camera moves the mask`, { skip }, async () => {
    const page = await pageOn(impl);
    try {
      for (const [name, view] of SMALL) {
        const { f } = await drawAndJudge(page, impl, name, 'small', view);
        assert.equal(f.info.casters, 5, 'every mesh casts');
        if (name !== 'above') continue;
        // Nothing moved: the mask target is kept, with the same far plane.
        const again = await page.evaluate(() => window.T.frame());
        assert.equal(again.info.reused, true, 'a still frame is reused');
        assert.deepEqual(again.info.ortho, f.info.ortho, 'with the same far plane');
        assert.deepEqual(again.masks, f.masks, 'and the same masks');
        // The camera moved sideways: another mask.
        const moved = await page.evaluate(() => {
          window.T.camera.position.x += 1;
          window.T.camera.updateMatrixWorld(true);
          return window.T.frame();
        });
        assert.equal(moved.info.reused, false, 'a moved camera draws again');
        assert.notEqual(moved.masks[0], f.masks[0], 'and the mask moves');
      }
    } finally {
      await page.close();
    }
  });

  test(`${impl}: Crytek Sponza through OBJLoader under an OrthographicCamera, under the gallery, along the atrium and from above, a point and a directional light, z-fail: 0 samples outside the band`, { skip: skipSponza, timeout: 1_800_000 }, async () => {
    const page = await pageOn(impl);
    const scene = path.join(SCENES_DIR, SPONZA);
    try {
      for (const [name, eye, target, height] of [['gallery', [-5, 2.5, 0], [-10, 0.5, -1], 8], ['atrium', [-12, 4, 0.5], [10, 2, 0], 14], ['above', [0, 40, 0.1], [0, 0, 0], 30]]) {
        const view = { w: 320, h: 180, eye, target, height, point: [2.18, 6.01, 0.76], directional: [0.3, 1, 0.2], url: `/scenes/${SPONZA}` };
        await drawAndJudge(page, impl, `sponza-${name}`, 'sponza', view, scene);
      }
    } finally {
      await page.close();
    }
  });
}
