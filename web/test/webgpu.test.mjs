// umbra-three's WebGPU path (`umbra-three/webgpu`) in three.js's WebGPURenderer, in Debian's
// Chromium with WebGPU on SwiftShader (headless, a http://127.0.0.1 page; flags in
// testlib/exactness.mjs IMPLEMENTATIONS.webgpu). three.js renders into a RenderTarget (the
// canvas cannot present headless here). Judged by the oracle: the page writes the drawn
// triangles out in world space (the matrices hold only 0, +-1, +-0.5 and dyadic offsets, so
// every world position is exact in f32), reads each light's mask back with readMaskAsync, and
// `umbra verify --external-mask` judges it with the page's view: 0 samples outside the band,
// for a point and a directional light, with the eye outside and inside a shadow volume, a
// mirrored caster and an instanced one. Also: the shadow reaches three.js's node materials
// through the light's shadow node (a shadowed floor pixel is darker than a lit one).
//
// Needs: /usr/bin/chromium with a WebGPU adapter, the wasm module (node build-wasm.mjs) and
// the umbra binary (cargo build --release -p umbra-cli, or UMBRA_BIN); skipped with a message
// when one is absent. Run: cd web && node --test test/webgpu.test.mjs
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { existsSync } from 'node:fs';
import { mkdtemp, mkdir, readFile, rm, writeFile } from 'node:fs/promises';
import { tmpdir } from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { createServer, listen } from '../serve.mjs';
import { buildPackage } from '../umbra-three/build.mjs';
import { launch, judge, WEBGPU_SUBPIXEL_BITS } from '../testlib/exactness.mjs';
import { encodePng } from '../testlib/png.mjs';

const here = path.dirname(fileURLToPath(import.meta.url));
const webDir = path.join(here, '..');
const repo = path.join(webDir, '..');
const CHROMIUM = process.env.UMBRA_CHROMIUM || '/usr/bin/chromium';
const WASM = path.join(webDir, 'umbra-geom-wasm', 'umbra_wasm.wasm');
const umbraBin = [process.env.UMBRA_BIN, process.env.CARGO_TARGET_DIR && path.join(process.env.CARGO_TARGET_DIR, 'release', 'umbra'), path.join(repo, 'target', 'release', 'umbra')]
  .find((c) => c && existsSync(c));
let skip = !existsSync(CHROMIUM) ? `${CHROMIUM} is absent (apt-get install chromium): WebGPU test skipped`
  : !existsSync(WASM) ? `${WASM} is absent (node build-wasm.mjs): WebGPU test skipped`
    : !umbraBin ? 'no umbra binary (cargo build --release -p umbra-cli, or UMBRA_BIN): WebGPU test skipped' : false;
if (skip) console.log(`SKIP: ${skip}`);

const SCENES_DIR = process.env.UMBRA_SCENES || path.join(repo, '..', 'shared', 'scenes');
const SHARED = ['crytek-sponza.obj.gz', 'conference.obj.gz', 'sibenik.obj.gz'];
const sharedSkip = () => skip || (SHARED.every((s) => existsSync(path.join(SCENES_DIR, s))) ? false : `the shared scenes are absent from ${SCENES_DIR} (UMBRA_SCENES): shared-scene WebGPU test skipped`);

const W = 320;
const H = 240;
const PAGE = `<!doctype html>
<html><head><meta charset="utf-8">
<script type="importmap">
{ "imports": { "three": "/three/build/three.webgpu.js", "three/webgpu": "/three/build/three.webgpu.js", "three/tsl": "/three/build/three.tsl.js", "three/addons/": "/three/examples/jsm/", "umbra-three/webgpu": "/umbra-three/webgpu.js" } }
</script></head>
<body></body></html>
`;

let tmp, server, base, ctx, page;

before(async () => {
  if (skip) return;
  tmp = await mkdtemp(path.join(tmpdir(), 'umbra-webgpu-'));
  const dist = await buildPackage(path.join(tmp, 'umbra-three'));
  const root = path.join(tmp, 'root');
  await mkdir(root);
  await writeFile(path.join(root, 'index.html'), PAGE);
  const mounts = [['/', root], ['/three/', path.join(webDir, 'node_modules', 'three')], ['/umbra-three/', dist], ['/testlib/', path.join(webDir, 'testlib')]];
  if (existsSync(SCENES_DIR)) mounts.push(['/scenes/', SCENES_DIR]);
  server = createServer(mounts);
  base = await listen(server, 0);
  ctx = await launch(CHROMIUM, 'webgpu', tmp);
  page = await ctx.newPage();
  page.on('pageerror', (e) => console.log(`page error: ${e}`));
  await page.goto(base);
  const adapter = await page.evaluate(async () => {
    const a = navigator.gpu && await navigator.gpu.requestAdapter();
    return a ? `${a.info.vendor} ${a.info.architecture}` : null;
  });
  if (!adapter) {
    skip = 'this Chromium gives no WebGPU adapter: WebGPU test skipped';
    console.log(`SKIP: ${skip}`);
    return;
  }
  console.log(`WebGPU adapter: ${adapter}`);
  await page.evaluate(([w, h]) => {
    window.makeWorld = async (options) => {
      const THREE = await import('three/webgpu');
      const { UmbraShadows } = await import('umbra-three/webgpu');
      const renderer = new THREE.WebGPURenderer({ antialias: false });
      renderer.setPixelRatio(1);
      renderer.setSize(w, h, false);
      renderer.shadowMap.enabled = true;
      const umbra = await UmbraShadows.create(renderer, options);
      const target = new THREE.RenderTarget(w, h);
      renderer.setRenderTarget(target);
      const scene = new THREE.Scene();
      const mat = () => new THREE.MeshStandardNodeMaterial({ color: 0xcccccc, side: THREE.DoubleSide, roughness: 1, metalness: 0 });
      const meshes = [];
      const add = (m) => {
        m.castShadow = true;
        m.receiveShadow = true;
        scene.add(m);
        meshes.push(m);
        return m;
      };
      add(new THREE.Mesh(new THREE.PlaneGeometry(10, 10).rotateX(-Math.PI / 2), mat())).name = 'floor';
      // Matrices of 0, +-1, +-0.5 and dyadic offsets: the world positions are exact.
      const m4 = (r0, r1, r2, t) => new THREE.Matrix4().set(...r0, t[0], ...r1, t[1], ...r2, t[2], 0, 0, 0, 1);
      const box = add(new THREE.Mesh(new THREE.BoxGeometry(1, 1, 1), mat()));
      box.name = 'box';
      box.position.set(-1.5, 1, 0);
      // Mirrored (determinant -1): its winding turns, its shadow must not.
      const mirrored = add(new THREE.Mesh(new THREE.ConeGeometry(0.5, 1.5, 12), mat()));
      mirrored.name = 'mirrored';
      mirrored.matrixAutoUpdate = false;
      mirrored.matrix.copy(m4([-1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, -1]));
      const boxes = add(new THREE.InstancedMesh(new THREE.TorusGeometry(0.5, 0.125, 6, 12), mat(), 2));
      boxes.name = 'instances';
      boxes.setMatrixAt(0, m4([1, 0, 0], [0, 0, -1], [0, 1, 0], [1, 0.25, 1.5]));
      boxes.setMatrixAt(1, m4([0, 0, 0.5], [0, 0.5, 0], [-0.5, 0, 0], [-1, 1.5, 2]));
      const point = new THREE.PointLight(0xffffff, 12, 0, 0);
      point.position.set(0.5, 4.5, 1);
      point.castShadow = true;
      const sun = new THREE.DirectionalLight(0xffffff, 1.5);
      sun.position.set(3, 4, 2);
      sun.castShadow = true;
      scene.add(point, sun, sun.target, new THREE.AmbientLight(0xffffff, 0.2));
      scene.updateMatrixWorld(true);

      // Every drawn triangle in world space (what umbra verify judges): f64 then f32.
      const { addWorldTriangles, meshFileNear, trianglesObj } = await import('/testlib/page-world.js');
      const world = () => {
        const pos = [];
        const addGeometry = (geometry, m) => addWorldTriangles(pos, geometry, m.elements);
        const m = new THREE.Matrix4();
        for (const mesh of meshes) {
          if (!mesh.visible) continue;
          if (mesh.isInstancedMesh) for (let i = 0; i < mesh.count; i++) addGeometry(mesh.geometry, mesh.getMatrixAt(i, m).premultiply(mesh.matrixWorld));
          else addGeometry(mesh.geometry, mesh.matrixWorld);
        }
        return { obj: trianglesObj(pos), near: meshFileNear(pos), triangles: pos.length / 9 };
      };
      const camera = new THREE.PerspectiveCamera(50, w / h, 0.1, 100);
      const latin1 = (a) => {
        let s = '';
        for (let i = 0; i < a.length; i += 8192) s += String.fromCharCode.apply(null, a.subarray(i, i + 8192));
        return s;
      };
      const frame = async () => {
        const out = world();
        camera.near = out.near;
        camera.updateProjectionMatrix();
        umbra.render(scene, camera);
        const masks = [latin1(await umbra.readMaskAsync(point)), latin1(await umbra.readMaskAsync(sun))];
        const colour = await renderer.readRenderTargetPixelsAsync(target, 0, 0, w, h);
        return { ...out, masks, colour: latin1(colour), errors: umbra.errors.slice(), info: { ...umbra.info }, volumes: await umbra.readVolumesAsync() };
      };
      window.T = { THREE, umbra, scene, camera, point, sun, meshes, box, frame };
    };
    // A shared scene through OBJLoader (gzip), drawn at w x h from `view` ({ eye, target, up,
    // fov, near }) with a point and a directional light; returns each light's mask (latin1) and
    // the frame's info.
    window.sharedFrame = async (url, w, h, view, pointAt, sunFrom, options = {}) => {
      const THREE = await import('three/webgpu');
      const { UmbraShadows } = await import('umbra-three/webgpu');
      const { OBJLoader } = await import('three/addons/loaders/OBJLoader.js');
      const text = await new Response((await fetch(url)).body.pipeThrough(new DecompressionStream('gzip'))).text();
      const object = new OBJLoader().parse(text);
      const mat = new THREE.MeshStandardNodeMaterial({ color: 0xcccccc, side: THREE.DoubleSide });
      object.traverse((o) => {
        if (!o.isMesh) return;
        o.material = mat;
        o.castShadow = true;
        o.receiveShadow = true;
      });
      const renderer = new THREE.WebGPURenderer({ antialias: false });
      renderer.setPixelRatio(1);
      renderer.setSize(w, h, false);
      renderer.shadowMap.enabled = true;
      const umbra = await UmbraShadows.create(renderer, options);
      const target = new THREE.RenderTarget(w, h);
      renderer.setRenderTarget(target);
      const scene = new THREE.Scene();
      scene.add(object);
      const point = new THREE.PointLight(0xffffff, 8, 0, 0);
      point.position.fromArray(pointAt);
      point.castShadow = true;
      const sun = new THREE.DirectionalLight(0xffffff, 1);
      sun.position.fromArray(sunFrom);
      sun.castShadow = true;
      scene.add(point, sun, sun.target);
      const camera = new THREE.PerspectiveCamera(view.fov, w / h, view.near, 1000);
      camera.position.fromArray(view.eye);
      camera.up.fromArray(view.up);
      camera.lookAt(...view.target);
      scene.updateMatrixWorld(true);
      umbra.render(scene, camera);
      const latin1 = (a) => {
        let s = '';
        for (let i = 0; i < a.length; i += 8192) s += String.fromCharCode.apply(null, a.subarray(i, i + 8192));
        return s;
      };
      const masks = [latin1(await umbra.readMaskAsync(point)), latin1(await umbra.readMaskAsync(sun))];
      const info = { ...umbra.info, volumes: await umbra.readVolumesAsync() };
      const errors = umbra.errors.slice();
      umbra.dispose();
      target.dispose();
      renderer.dispose();
      return { masks, info, errors };
    };
  }, [W, H]);
});

after(async () => {
  if (ctx) await ctx.close();
  if (server) await new Promise((r) => server.close(r));
  if (tmp) await rm(tmp, { recursive: true, force: true });
});

/** The page's frame from `eye`, each light's mask judged by `umbra verify --external-mask`. */
async function judged(name, eye, target = [0, 0, 0]) {
  const f = await page.evaluate(async ([e, at]) => {
    window.T.camera.position.set(...e);
    window.T.camera.lookAt(...at);
    window.T.camera.updateMatrixWorld();
    return window.T.frame();
  }, [eye, target]);
  const obj = path.join(tmp, `${name}.obj`);
  await writeFile(obj, f.obj);
  const lights = await page.evaluate(() => [[...window.T.point.position.toArray()], [...window.T.sun.position.toArray(), 0]]);
  const rows = [];
  for (let k = 0; k < 2; k++) {
    const gray = Buffer.from(f.masks[k], 'latin1');
    const rgba = new Uint8Array(4 * W * H);
    for (let i = 0; i < gray.length; i++) rgba.set([gray[i], gray[i], gray[i], 255], 4 * i);
    const png = path.join(tmp, `${name}-${k}.png`);
    await writeFile(png, encodePng(W, H, rgba));
    const extra = ['--eye', eye.join(','), '--target', target.join(','), '--fov', '50', '--light', lights[k].join(','), '--subpixel-bits', String(WEBGPU_SUBPIXEL_BITS)];
    const r = judge(umbraBin, { scene: obj, size: `${W}x${H}`, maskPng: png, extra, explain: 20 });
    let dark = 0;
    for (let i = 0; i < gray.length; i++) dark += gray[i] === 0;
    rows.push({ ...r, dark });
  }
  return { rows, frame: f };
}

test('WebGPURenderer: a point and a directional light, a mirrored and an instanced caster, the eye outside and inside a shadow: every mask 0 samples outside the band, and the node materials receive it', async (t) => {
  if (skip) return t.skip(skip);
  // Culled on the GPU (the default) and drawn whole (`volumeCull: false`): both exact.
  const zpassViews = [];
  for (const volumeCull of [true, false]) {
    await page.evaluate((o) => window.makeWorld(o), { volumeCull });
    // The second view: the eye under the box, inside its shadow volumes. Lights are counted
    // z-pass where the eye's count is proven (zpass.js), from that count, which under the box
    // is not 0.
    // The third view: a corner of the floor that no caster's shadow reaches.
    for (const [name, eye, target] of [['outside', [0, 5, 7]], ['inside', [-1.5, 0.25, 0.25]], ['corner', [4, 1, 4], [4.8, 0, 4.8]]]) {
      const { rows, frame } = await judged(`${name}-${volumeCull}`, eye, target);
      zpassViews.push(frame.info.zpass);
      console.log(JSON.stringify({ name, volumeCull, rows: rows.map((r) => ({ outside: r.browser.mismatches_outside_band, band: r.browser.band_samples, samples: r.browser.samples, shadowed: r.browser.shadowed_reference, dark: r.dark })), info: frame.info, volumes: frame.volumes, errors: frame.errors }));
      assert.deepEqual(frame.errors, [], 'no mesh refused');
      assert.equal(frame.info.casters, 5, 'floor, box, mirrored cone and two instances cast');
      rows.forEach((r, k) => {
        assert.equal(r.browser.mismatches_outside_band, 0, `${name}, volumeCull ${volumeCull}, light ${k}: 0 outside the band: ${r.explained.join('; ')}`);
        if (name !== 'corner') assert.ok(r.browser.shadowed_reference > 500, `${name}, light ${k}: the casters shadow something`);
      });
      // What the volumes drew. At the floor's corner, where no caster's shadow reaches, a culled
      // light keeps the floor alone (2 triangles, kept by its own samples, which lie in its cells
      // beyond it): no other caster's volume is drawn.
      assert.equal(frame.volumes.length, 2);
      frame.volumes.forEach((v, k) => {
        assert.equal(v.culled, volumeCull && frame.info.culled[k], `${name}, light ${k}: ${JSON.stringify(v)}`);
        if (!volumeCull) assert.equal(v.triangles, frame.info.casterTriangles, `${name}, light ${k}`);
        else if (name === 'corner' && v.culled) assert.ok(v.triangles <= 2, `${name}, light ${k}: the cull keeps ${v.triangles} of ${frame.info.casterTriangles}`);
        else assert.ok(v.triangles <= frame.info.casterTriangles, `${name}, light ${k}`);
        if (name !== 'corner') assert.ok(v.edges > 0, `${name}, light ${k}: side quads drawn`);
      });
      // Culled unless z-pass needs the eye's near pyramid raised and the point light's map
      // cannot bound it (at the corner, a pyramid across cube faces: drawn whole).
      if (volumeCull && name !== 'corner') assert.deepEqual(frame.info.culled, [true, true], `${name}: both lights culled`);
      if (volumeCull && name === 'corner') assert.ok(frame.info.culled[1], 'the directional light is culled at the corner');
      if (name === 'outside') {
        // The decision reaches three.js's shading: among floor pixels both lights light, the
        // darkest and the brightest differ by more than the ambient term alone would allow.
        const colour = Buffer.from(frame.colour, 'latin1');
        const [m0, m1] = frame.masks.map((s) => Buffer.from(s, 'latin1'));
        let shadowedSum = 0;
        let shadowedN = 0;
        let litSum = 0;
        let litN = 0;
        for (let i = 0; i < W * H; i++) {
          const g = colour[4 * i + 1];
          if (m0[i] === 0 && m1[i] === 0) {
            shadowedSum += g;
            shadowedN++;
          } else if (m0[i] === 255 && m1[i] === 255) {
            litSum += g;
            litN++;
          }
        }
        assert.ok(shadowedN > 100 && litN > 100, `both kinds of pixel are seen (${shadowedN} shadowed by both, ${litN} lit by both)`);
        assert.ok(shadowedSum / shadowedN < 0.5 * (litSum / litN), `pixels both lights leave shadowed are darker (${(shadowedSum / shadowedN).toFixed(1)}) than those both light (${(litSum / litN).toFixed(1)})`);
      }
    }
  }
  console.log(`z-pass per view and light: ${JSON.stringify(zpassViews)}`);
  assert.ok(zpassViews.flat().some((z) => z === true), 'some light of some view was counted z-pass');
  // A frame umbra does not draw (disabled; an OrthographicCamera, refused with an entry in
  // `errors`) is shaded unshadowed: the masks the shadow nodes read are cleared to lit.
  const off = await page.evaluate(async () => {
    const { THREE, umbra, scene, camera, point } = window.T;
    const lit = async () => (await umbra.readMaskAsync(point)).every((v) => v === 255);
    umbra.enabled = false;
    umbra.render(scene, camera);
    const disabled = await lit();
    umbra.enabled = true;
    umbra.render(scene, camera);
    const drawn = await lit();
    const ortho = new THREE.OrthographicCamera(-4, 4, 3, -3, 0.1, 100);
    ortho.name = 'ortho';
    ortho.position.set(0, 5, 7);
    ortho.lookAt(0, 0, 0);
    umbra.render(scene, ortho);
    return { disabled, drawn, refused: await lit(), errors: umbra.errors.map((e) => e.mesh), texture: umbra.maskTexture(point)?.isTexture === true };
  });
  assert.deepEqual(off, { disabled: true, drawn: false, refused: true, errors: ['ortho'], texture: true });
});

// The decision is the count AND the seen side's facing (passes.js, the facing pass): without the
// facing, samples on triangles whose unlit side the camera sees rested on their own volume's
// sides and fell outside the band (Crytek Sponza 640x360: 59).
/**
 * Each of `scenes` through OBJLoader at each of `sizes` from its default view, with its default
 * point light and a directional one, UmbraShadows made with `options`: every mask judged.
 */
async function sharedScenesJudged(t, scenes, sizes, options) {
  const why = sharedSkip();
  if (why) {
    console.log(`SKIP: ${why}`);
    return t.skip(why);
  }
  const sun = [0.3, 1, 0.2];
  const outside = [];
  for (const s of scenes) {
    const scene = path.join(SCENES_DIR, s);
    // The scene's default view and light, as `umbra export` writes them (the view verify judges by default).
    const dir = path.join(tmp, `export-${s}`);
    execFileSync(umbraBin, ['export', scene, '--out', dir], { stdio: ['ignore', 'ignore', 'inherit'] });
    const { camera, light } = JSON.parse(await readFile(path.join(dir, 'manifest.json'), 'utf8'));
    await rm(dir, { recursive: true, force: true });
    const view = { eye: camera.eye, target: camera.target, up: camera.up, fov: camera.fov_y_degrees, near: camera.near };
    for (const [w, h] of sizes) {
      const f = await page.evaluate(([url, ww, hh, v, p, d, o]) => window.sharedFrame(url, ww, hh, v, p, d, o), [`/scenes/${s}`, w, h, view, light.slice(0, 3), sun, options]);
      assert.deepEqual(f.errors, [], `${s}: no mesh refused`);
      for (const [k, l] of [[0, light.slice(0, 3)], [1, [...sun, 0]]]) {
        const gray = Buffer.from(f.masks[k], 'latin1');
        const rgba = new Uint8Array(4 * w * h);
        for (let i = 0; i < gray.length; i++) rgba.set([gray[i], gray[i], gray[i], 255], 4 * i);
        // UMBRA_DIFF_DIR: keep the masks and the diff images there (for --explain by hand).
        const png = path.join(process.env.UMBRA_DIFF_DIR || tmp, `${s}-${w}-${k}.mask.png`);
        await writeFile(png, encodePng(w, h, rgba));
        const extra = ['--eye', view.eye.join(','), '--target', view.target.join(','), '--up', view.up.join(','), '--fov', String(view.fov), '--light', l.join(','), '--subpixel-bits', String(WEBGPU_SUBPIXEL_BITS)];
        const r = judge(umbraBin, { scene, size: `${w}x${h}`, maskPng: png, extra, explain: 20, diff: process.env.UMBRA_DIFF_DIR ? path.join(process.env.UMBRA_DIFF_DIR, `${s}-${w}-${k}.png`) : null });
        console.log(JSON.stringify({ scene: s, method: f.info.method, zpass: f.info.zpass[k], culled: f.info.culled?.[k], kept: f.info.volumes?.[k]?.triangles, edges: f.info.volumes?.[k]?.edges, size: `${w}x${h}`, light: k ? 'directional' : 'point', outside: r.browser.mismatches_outside_band, band: r.browser.band_samples, samples: r.browser.samples, shadowed: r.browser.shadowed_reference, triangles: f.info.triangles, cpuMs: f.info.cpuMs }));
        // The sun reaches into Sponza's atrium only (Conference and Sibenik are closed rooms).
        if (k === 0 || s === 'crytek-sponza.obj.gz') assert.ok(r.browser.shadowed_reference > 1000 && r.browser.samples - r.browser.shadowed_reference > 1000, `${s} ${w}x${h} light ${k}: shadow and light in view`);
        if (r.browser.mismatches_outside_band !== 0) outside.push(`${s} ${w}x${h} light ${k}: ${r.browser.mismatches_outside_band} (${r.explained.slice(0, 3).join('; ')})`);
      }
    }
  }
  // Every row judged before the verdict, so that the log has them all.
  assert.deepEqual(outside, [], 'samples outside the band');
}

test('WebGPURenderer: Crytek Sponza, Conference and Sibenik through OBJLoader at 640x360 and 1280x720, a point and a directional light (Sibenik\'s eye inside 4 volumes): every mask 0 samples outside the band', { timeout: 1_800_000 }, async (t) => {
  await sharedScenesJudged(t, SHARED, [[640, 360], [1280, 720]], {});
});

// A known defect, kept running (a todo: reported, not failing the suite): the eye just below the
// mirrored cone's base, inside its point-light shadow. A few samples on the base's triangles,
// 0.0015-0.009 pixel from the rim, come out lit against a shadowed reference, z-pass and z-fail
// alike (so not the count): SwiftShader's depth pass shows another surface there than the
// oracle's band allows for.
test('WebGPURenderer: the eye just below the mirrored cone (known defect: samples at the base\'s rim outside the band)', { todo: 'samples at the rim of a base seen from just below fall outside the band (docs/web.md, "On WebGPU")' }, async (t) => {
  if (skip) return t.skip(skip);
  const outside = {};
  for (const method of ['cs-silhouette', 'ray-bvh']) {
    await page.evaluate((m) => window.makeWorld({ method: m }), method);
    for (const [name, eye] of [['under-mirrored-a', [1.11, 0.2, -1.46]], ['under-mirrored-b', [1.13, 0.1, -1.51]]]) {
      const { rows, frame } = await judged(`${method}-${name}`, eye);
      outside[`${method} ${name} (z-pass ${frame.info.zpass})`] = rows.map((r) => r.browser.mismatches_outside_band);
    }
  }
  console.log(JSON.stringify(outside));
  assert.ok(Object.values(outside).flat().every((n) => n === 0), `samples outside the band: ${JSON.stringify(outside)}`);
});

// ray-bvh in the page (rays.js): native ray-bvh's walk (umbra-wgpu's ray_bvh.wgsl) over the
// wasm's BVH of the casters, judged as the volumes are.
test('WebGPURenderer, method ray-bvh: the world of the first test (point and directional light, mirrored and instanced casters, the eye outside and inside a shadow) and Sibenik at 640x360: every mask 0 samples outside the band', { timeout: 900_000 }, async (t) => {
  if (skip) return t.skip(skip);
  const refused = await page.evaluate(async () => {
    const THREE = await import('three/webgpu');
    const { UmbraShadows } = await import('umbra-three/webgpu');
    try {
      await UmbraShadows.create(new THREE.WebGPURenderer(), { method: 'ray-bvh-typo' });
      return null;
    } catch (e) {
      return e.message;
    }
  });
  assert.match(refused ?? '', /unknown method 'ray-bvh-typo' \(expected 'cs-silhouette' or 'ray-bvh'\)/);
  await page.evaluate(() => window.makeWorld({ method: 'ray-bvh' }));
  for (const [name, eye] of [['rays-outside', [0, 5, 7]], ['rays-inside', [-1.5, 0.25, 0.25]]]) {
    const { rows, frame } = await judged(name, eye);
    console.log(JSON.stringify({ name, rows: rows.map((r) => ({ outside: r.browser.mismatches_outside_band, band: r.browser.band_samples, samples: r.browser.samples, shadowed: r.browser.shadowed_reference, dark: r.dark })), info: frame.info, errors: frame.errors }));
    assert.deepEqual(frame.errors, [], 'no mesh refused');
    assert.equal(frame.info.method, 'ray-bvh');
    assert.equal(frame.info.silhouettes, null);
    assert.ok(frame.info.bvh.nodes > 1 && frame.info.bvh.bytes > 0, `a BVH was built: ${JSON.stringify(frame.info.bvh)}`);
    rows.forEach((r, k) => {
      assert.equal(r.browser.mismatches_outside_band, 0, `${name}, light ${k}: 0 outside the band: ${r.explained.join('; ')}`);
      assert.ok(r.browser.shadowed_reference > 500, `${name}, light ${k}: the casters shadow something`);
    });
  }
  // No volume buffers on this path: the surface's three and the BVH's alone.
  const owned = await page.evaluate(() => window.T.umbra.volumes.scene.owned);
  assert.deepEqual(owned, ['positions', 'indices', 'normals'], 'the ray path makes no volume buffers');
  // A caster that moves: the BVH is built again (no stale hierarchy), and the mask follows.
  await page.evaluate(() => {
    window.T.box.position.x += 0.5;
    window.T.box.updateMatrixWorld();
  });
  const moved = await judged('rays-moved', [0, 5, 7]);
  assert.equal(moved.rows[0].browser.mismatches_outside_band, 0, `after the box moved: 0 outside the band: ${moved.rows[0].explained.join('; ')}`);
  await page.evaluate(() => {
    window.T.box.position.x -= 0.5;
    window.T.box.updateMatrixWorld();
  });
  await sharedScenesJudged(t, ['sibenik.obj.gz'], [[640, 360]], { method: 'ray-bvh' });
});
