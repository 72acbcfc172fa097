// The umbra-three package as a three.js user loads it: its built dist (umbra-three/build.mjs)
// and three.js's own module through an import map on a blank page, no bundler, in Debian's
// Chromium (SwiftShader, headless). What the exactness test (browser.test.mjs) does not cover:
// * bad meshes (no position attribute, NaN positions, index out of range): an entry in
//   umbra.errors naming each mesh, once, and onError; umbra.render never throws; the frame is
//   drawn and the good caster still shadows;
// * the GL state umbra touches is restored: after an umbra frame, three.js draws another scene
//   exactly as a fresh renderer does (also with three.js's reversedDepthBuffer); a scene
//   without casters, umbra.enabled = false, a camera that is neither a PerspectiveCamera nor an
//   OrthographicCamera (refused with an entry in umbra.errors) and a plain renderer.render()
//   after an umbra frame give three.js's own image; an OrthographicCamera is shadowed
//   (web/test/ortho.test.mjs judges its masks);
//   three.js's shadow maps stay off inside umbra's frame and the user's setting comes back;
// * the user's renderer with stencil on or off and antialias on or off: the same decision,
//   and the shading follows it;
// * a mesh's world transform and a light may change every frame without re-preparing;
// * the light order: a shadowed light added after an unshadowed one is multiplied by its own
//   decision (three.js puts shadow-casting lights first), pixel for pixel;
// * the count each light gets: z-pass with the eye in the open (start 0) and inside a
//   transformed box's shadow (start 2: the eye's segment to the light crosses its bottom and
//   top), z-fail with the box cut by the near plane, and a directional light; each mask equal
//   to the one the same frame gets counted z-fail everywhere (`zpass: false`).
//
// Needs: /usr/bin/chromium and the wasm module (node build-wasm.mjs), the test skipped with a
// message when either is absent; `npm ci` in web/. Run: cd web && node --test test/
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { existsSync } from 'node:fs';
import { mkdtemp, rm, writeFile } from 'node:fs/promises';
import { tmpdir } from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { createServer, listen } from '../serve.mjs';
import { buildPackage } from '../umbra-three/build.mjs';
import { launch } from '../testlib/exactness.mjs';

const here = path.dirname(fileURLToPath(import.meta.url));
const webDir = path.join(here, '..');
const CHROMIUM = process.env.UMBRA_CHROMIUM || '/usr/bin/chromium';
const WASM = path.join(webDir, 'umbra-geom-wasm', 'umbra_wasm.wasm');
const skip = !existsSync(CHROMIUM) ? `${CHROMIUM} is absent (apt-get install chromium): umbra-three browser test skipped`
  : !existsSync(WASM) ? `${WASM} is absent (node build-wasm.mjs): umbra-three browser test skipped` : false;
if (skip) console.log(`SKIP: ${skip}`);

const PAGE = `<!doctype html>
<html><head><meta charset="utf-8">
<script type="importmap">
{ "imports": { "three": "/three/build/three.module.js", "umbra-three": "/umbra-three/index.js" } }
</script></head>
<body></body></html>
`;

let tmp, server, base, ctx, page;

before(async () => {
  if (skip) return;
  tmp = await mkdtemp(path.join(tmpdir(), 'umbra-three-'));
  const dist = await buildPackage(path.join(tmp, 'umbra-three'));
  const root = path.join(tmp, 'root');
  await (await import('node:fs/promises')).mkdir(root);
  await writeFile(path.join(root, 'index.html'), PAGE);
  server = createServer([['/', root], ['/three/', path.join(webDir, 'node_modules', 'three')], ['/umbra-three/', dist]]);
  base = await listen(server, 0);
  ctx = await launch(CHROMIUM, 'swiftshader', tmp);
  page = await ctx.newPage();
  page.on('pageerror', (e) => console.log(`page error: ${e}`));
  await page.goto(base);
  // The scene every test starts from: a floor, a box above it (both casting), a point light.
  await page.evaluate(async () => {
    const THREE = await import('three');
    const { UmbraShadows } = await import('umbra-three');
    window.T = { THREE, UmbraShadows };
    window.makeRenderer = (opts = {}, w = 160, h = 120) => {
      const canvas = document.createElement('canvas');
      canvas.width = w;
      canvas.height = h;
      document.body.appendChild(canvas);
      const r = new THREE.WebGLRenderer({ canvas, preserveDrawingBuffer: true, ...opts });
      r.setPixelRatio(1);
      r.setSize(w, h, false);
      r.setClearColor(0x203040);
      return r;
    };
    window.makeScene = () => {
      const scene = new THREE.Scene();
      const mat = new THREE.MeshLambertMaterial({ color: 0xcccccc, side: THREE.DoubleSide });
      const floor = new THREE.Mesh(new THREE.PlaneGeometry(10, 10).rotateX(-Math.PI / 2), mat);
      floor.name = 'floor';
      floor.castShadow = true;
      const box = new THREE.Mesh(new THREE.BoxGeometry(1, 1, 1), new THREE.MeshStandardMaterial({ color: 0xffffff }));
      box.name = 'box';
      box.position.set(0, 1, 0);
      box.castShadow = true;
      const light = new THREE.PointLight(0xffffff, 8, 0, 0);
      light.position.set(1, 4, 1);
      light.castShadow = true;
      scene.add(floor, box, light, new THREE.AmbientLight(0xffffff, 0.3));
      const camera = new THREE.PerspectiveCamera(50, 160 / 120, 0.1, 100);
      camera.position.set(0, 4, 6);
      camera.lookAt(0, 0, 0);
      return { scene, camera, light, box, floor };
    };
    window.pixels = (r) => {
      const gl = r.getContext();
      const out = new Uint8Array(4 * gl.drawingBufferWidth * gl.drawingBufferHeight);
      gl.readPixels(0, 0, gl.drawingBufferWidth, gl.drawingBufferHeight, gl.RGBA, gl.UNSIGNED_BYTE, out);
      return out;
    };
    window.differing = (a, b) => a.reduce((n, v, i) => n + (v !== b[i]), 0);
    window.zeros = (m) => m.reduce((n, v) => n + (v === 0), 0);
  });
});

after(async () => {
  if (ctx) await ctx.close();
  if (server) await new Promise((r) => server.close(r));
  if (tmp) await rm(tmp, { recursive: true, force: true });
});

test('bad meshes: an error naming each, once; never an exception; the frame drawn and the good caster still shadows', { skip }, async () => {
  const r = await page.evaluate(async () => {
    const { THREE, UmbraShadows } = window.T;
    const renderer = makeRenderer();
    const umbra = await UmbraShadows.create(renderer);
    const seen = [];
    umbra.onError = (e) => seen.push(e.mesh);
    const { scene, camera, light } = makeScene();
    const bad = (name, geometry) => {
      const m = new THREE.Mesh(geometry, new THREE.MeshLambertMaterial());
      m.name = name;
      m.castShadow = true;
      scene.add(m);
      return m;
    };
    bad('no-positions', new THREE.BufferGeometry());
    const nan = new THREE.BufferGeometry();
    nan.setAttribute('position', new THREE.Float32BufferAttribute([0, 0, 0, 1, NaN, 0, 0, 1, 0], 3));
    bad('nan-mesh', nan);
    const range = new THREE.BufferGeometry();
    range.setAttribute('position', new THREE.Float32BufferAttribute([0, 0, 0, 1, 0, 0, 0, 1, 0], 3));
    range.setIndex([0, 1, 7]);
    const unnamed = bad('', range);
    let threw = null;
    try {
      umbra.render(scene, camera);
      umbra.render(scene, camera);
    } catch (e) {
      threw = String(e);
    }
    const mask = umbra.readMask(light);
    const px = pixels(renderer);
    // Pixels that are not the clear colour (0x203040).
    let drawn = 0;
    for (let i = 0; i < px.length; i += 4) drawn += px[i] !== 0x20 || px[i + 1] !== 0x30 || px[i + 2] !== 0x40;
    return { threw, errors: umbra.errors.map((e) => ({ ...e })), seen, uuid: unnamed.uuid, shadowed: zeros(mask), drawn, casters: umbra.info.casters };
  });
  assert.equal(r.threw, null, 'umbra.render threw');
  const text = r.errors.map((e) => `${e.mesh}: ${e.message}`).join('\n');
  console.log(text);
  assert.ok(r.errors.some((e) => e.mesh === 'no-positions' && /no position attribute/.test(e.message)), text);
  assert.ok(r.errors.some((e) => e.mesh === 'nan-mesh' && /NaN/.test(e.message)), text);
  assert.ok(r.errors.some((e) => e.mesh === r.uuid && /out of range/.test(e.message)), text);
  assert.equal(r.errors.length, r.seen.length, 'onError once per entry');
  assert.equal(new Set(r.errors.map((e) => `${e.mesh}|${e.message}`)).size, r.errors.length, 'each error once, not once per frame');
  assert.equal(r.casters, 2, 'the floor and the box still cast');
  assert.ok(r.shadowed > 200, `the box's shadow: ${r.shadowed} shadowed pixels`);
  assert.ok(r.drawn > 160 * 120 / 2, `the frame is drawn: ${r.drawn} pixels`);
});

test('state restored: three.js draws after an umbra frame as a fresh renderer does; no casters, enabled = false and a plain Camera give three.js\'s own image; an OrthographicCamera is shadowed', { skip }, async () => {
  const r = await page.evaluate(async () => {
    const { THREE, UmbraShadows } = window.T;
    const renderer = makeRenderer();
    const fresh = makeRenderer();
    const umbra = await UmbraShadows.create(renderer);
    const a = makeScene();
    umbra.render(a.scene, a.camera);
    const shadowed = zeros(umbra.readMask(a.light));
    // Another scene (unpatched materials, blending, depth) right after umbra's frame.
    const other = new THREE.Scene();
    const k = new THREE.Mesh(new THREE.TorusKnotGeometry(1, 0.3, 64, 8), new THREE.MeshNormalMaterial());
    const glass = new THREE.Mesh(new THREE.SphereGeometry(1.2), new THREE.MeshBasicMaterial({ color: 0xff8800, transparent: true, opacity: 0.5 }));
    other.add(k, glass);
    renderer.render(other, a.camera);
    fresh.render(other, a.camera);
    const afterUmbra = differing(pixels(renderer), pixels(fresh));
    // Casters off: a plain frame (the patched materials see every light as lit).
    const b = makeScene();
    b.box.castShadow = false;
    b.floor.castShadow = false;
    umbra.render(b.scene, b.camera);
    const c = makeScene();
    c.box.castShadow = false;
    c.floor.castShadow = false;
    fresh.render(c.scene, c.camera);
    const noCasters = differing(pixels(renderer), pixels(fresh));
    // umbra.enabled = false with casters.
    umbra.enabled = false;
    umbra.render(a.scene, a.camera);
    const d = makeScene();
    fresh.render(d.scene, d.camera);
    const disabled = differing(pixels(renderer), pixels(fresh));
    umbra.enabled = true;
    // An OrthographicCamera: shadowed. A plain Camera with its projection: refused, drawn by
    // three.js.
    const ortho = new THREE.OrthographicCamera(-5, 5, 4, -4, 0.1, 100);
    ortho.position.set(0, 4, 6);
    ortho.lookAt(0, 0, 0);
    let threw = null;
    try {
      umbra.render(a.scene, ortho);
    } catch (e) {
      threw = String(e);
    }
    const orthoShadowed = zeros(umbra.readMask(a.light));
    const plain = new THREE.Camera();
    plain.position.copy(ortho.position);
    plain.quaternion.copy(ortho.quaternion);
    plain.projectionMatrix.copy(ortho.projectionMatrix);
    plain.projectionMatrixInverse.copy(ortho.projectionMatrixInverse);
    umbra.render(a.scene, plain);
    fresh.render(d.scene, plain);
    const orthographic = differing(pixels(renderer), pixels(fresh));
    // A plain renderer.render() of the shadowed scene right after an umbra frame: three.js's own image.
    umbra.render(a.scene, a.camera);
    renderer.render(a.scene, a.camera);
    fresh.render(d.scene, d.camera);
    const plainAfter = differing(pixels(renderer), pixels(fresh));
    // three.js's shadow maps left on by the user: off inside umbra's frame, on again after it.
    umbra.render(a.scene, a.camera);
    const withoutMaps = pixels(renderer);
    renderer.shadowMap.enabled = true;
    umbra.render(a.scene, a.camera);
    const mapsOn = differing(pixels(renderer), withoutMaps);
    const mapsRestored = renderer.shadowMap.enabled;
    renderer.shadowMap.enabled = false;
    // A renderer with three.js's own reversed depth buffer (it sets clip control itself).
    const rev = makeRenderer({ reversedDepthBuffer: true });
    const revFresh = makeRenderer({ reversedDepthBuffer: true });
    const revUmbra = await UmbraShadows.create(rev);
    const e = makeScene();
    revUmbra.render(e.scene, e.camera);
    const reversedShadowed = zeros(revUmbra.readMask(e.light));
    // Its own camera: three.js sets a camera's projection for the renderer's depth convention.
    rev.render(other, e.camera);
    revFresh.render(other, e.camera);
    const reversed = differing(pixels(rev), pixels(revFresh));
    // dispose(): umbra's GL objects freed, render() is three.js's own frame from then on.
    umbra.dispose();
    umbra.render(a.scene, a.camera);
    fresh.render(d.scene, d.camera);
    const disposed = differing(pixels(renderer), pixels(fresh));
    const glError = renderer.getContext().getError();
    return { shadowed, afterUmbra, noCasters, disabled, orthographic, plainAfter, mapsOn, mapsRestored, reversed, reversedShadowed, disposed, glError, threw, orthoShadowed, errors: umbra.errors.map((e) => `${e.mesh}: ${e.message}`) };
  });
  console.log(JSON.stringify(r));
  assert.ok(r.shadowed > 200, 'the umbra frame had a shadow');
  assert.equal(r.afterUmbra, 0, 'three.js after an umbra frame differs from a fresh renderer');
  assert.equal(r.noCasters, 0, 'no casters: not three.js\'s own image');
  assert.equal(r.disabled, 0, 'enabled = false: not three.js\'s own image');
  assert.equal(r.threw, null);
  assert.ok(r.orthoShadowed > 200, `an OrthographicCamera's frame has a shadow: ${r.orthoShadowed}`);
  assert.equal(r.orthographic, 0, 'a plain Camera: not three.js\'s own image');
  assert.ok(r.errors.some((e) => /Camera: umbra-three draws shadows for a PerspectiveCamera or an OrthographicCamera only/.test(e)), r.errors.join('\n'));
  assert.ok(!r.errors.some((e) => /OrthographicCamera/.test(e.split(': ')[1] ?? '')), `the OrthographicCamera is not refused: ${r.errors.join('\n')}`);
  assert.equal(r.plainAfter, 0, 'renderer.render() after an umbra frame: not three.js\'s own image');
  assert.equal(r.mapsOn, 0, 'shadowMap.enabled = true changed umbra\'s frame');
  assert.equal(r.mapsRestored, true, 'shadowMap.enabled is the user\'s again');
  assert.ok(r.reversedShadowed > 200, 'reversedDepthBuffer: umbra still shadows');
  assert.equal(r.reversed, 0, 'reversedDepthBuffer: three.js after an umbra frame differs from a fresh renderer');
  assert.equal(r.disposed, 0, 'after dispose(): not three.js\'s own image');
  assert.equal(r.glError, 0, 'a GL error');
});

test('stencil on/off, antialias on/off: the same decision, and the shading follows it', { skip }, async () => {
  const r = await page.evaluate(async () => {
    const { UmbraShadows } = window.T;
    const out = [];
    for (const stencil of [true, false]) {
      for (const antialias of [false, true]) {
        const renderer = makeRenderer({ stencil, antialias });
        const umbra = await UmbraShadows.create(renderer);
        const { scene, camera, light } = makeScene();
        umbra.render(scene, camera);
        const mask = umbra.readMask(light);
        const px = pixels(renderer);
        // Mean brightness of floor pixels umbra shadowed against lit ones (rows: readMask's
        // top-down against readPixels' bottom-up), away from the edges (MSAA blends them).
        const w = 160;
        const h = 120;
        let lit = 0, nLit = 0, dark = 0, nDark = 0;
        for (let y = 1; y < h - 1; y++) for (let x = 1; x < w - 1; x++) {
          const i = y * w + x;
          const same = [i - 1, i + 1, i - w, i + w].every((j) => mask[j] === mask[i]);
          if (!same) continue;
          const p = 4 * ((h - 1 - y) * w + x);
          const v = px[p] + px[p + 1] + px[p + 2];
          if (mask[i]) { lit += v; nLit++; } else { dark += v; nDark++; }
        }
        out.push({ stencil, antialias, mask: Array.from(mask).join(''), lit: lit / nLit, dark: dark / nDark, shadowed: zeros(mask), errors: umbra.errors.length });
      }
    }
    return out;
  });
  for (const row of r) {
    console.log(`stencil ${row.stencil}, antialias ${row.antialias}: ${row.shadowed} shadowed pixels, mean lit ${row.lit.toFixed(1)} / shadowed ${row.dark.toFixed(1)}`);
    assert.equal(row.errors, 0);
    assert.ok(row.shadowed > 200, 'a shadow');
    assert.equal(row.mask, r[0].mask, `stencil ${row.stencil}, antialias ${row.antialias}: another decision than stencil on, antialias off`);
    assert.ok(row.lit > row.dark + 60, 'shadowed pixels are darker');
  }
});

test('a moving caster and a moving light: the shadow follows without re-preparing', { skip }, async () => {
  const r = await page.evaluate(async () => {
    const { UmbraShadows } = window.T;
    const renderer = makeRenderer();
    const umbra = await UmbraShadows.create(renderer);
    const { scene, camera, light, box } = makeScene();
    umbra.render(scene, camera);
    const first = umbra.readMask(light);
    const prepared = umbra.info.prepareMs;
    box.position.x += 1;
    box.rotation.y = 0.5;
    umbra.render(scene, camera);
    const moved = umbra.readMask(light);
    light.position.x -= 2;
    umbra.render(scene, camera);
    const lit = umbra.readMask(light);
    return { moved: differing(first, moved), lit: differing(moved, lit), samePrepare: umbra.info.prepareMs === prepared };
  });
  console.log(JSON.stringify(r));
  assert.ok(r.moved > 50, 'moving the box moves its shadow');
  assert.ok(r.lit > 50, 'moving the light moves the shadow');
  assert.ok(r.samePrepare, 'no topology prepared again for a transform or a light');
});

test('cache: nothing moved, the decisions reused; the camera moved, each light\'s silhouettes kept; after the camera, a light and then a caster moved, every mask that of a fresh frame (cache: false), culled and not, two lights', { skip }, async () => {
  const r = await page.evaluate(async () => {
    const { THREE, UmbraShadows } = window.T;
    const out = {};
    for (const volumeCull of [false, true]) {
      // Two of everything: the cached instance and the one that recomputes every frame, each
      // on its own renderer and scene (an instance patches its scene's materials).
      const make = async (cache) => {
        const renderer = makeRenderer();
        const umbra = await UmbraShadows.create(renderer, { cache, volumeCull });
        const s = makeScene();
        const second = new THREE.PointLight(0xffffff, 4, 0, 0);
        second.position.set(-2, 3, 0.5);
        second.castShadow = true;
        s.scene.add(second);
        return { umbra, ...s, second };
      };
      const a = await make(true);
      const b = await make(false);
      const steps = [];
      const step = (name, change) => {
        for (const x of [a, b]) change(x);
        for (const x of [a, b]) x.umbra.render(x.scene, x.camera);
        const masks = [a, b].map((x) => [x.umbra.readMask(x.light), x.umbra.readMask(x.second)]);
        steps.push({
          name,
          reused: a.umbra.info.reused,
          freshReused: b.umbra.info.reused,
          cached: a.umbra.info.volumes.map((v) => v.cached),
          freshCached: b.umbra.info.volumes.map((v) => v.cached),
          differing: differing(masks[0][0], masks[1][0]) + differing(masks[0][1], masks[1][1]),
          shadowed: zeros(masks[0][0]) + zeros(masks[0][1]),
          cpuMs: a.umbra.info.cpuMs,
        });
      };
      step('first', () => {});
      step('nothing moved', () => {});
      step('camera', (x) => {
        x.camera.position.set(1, 4.5, 5.5);
        x.camera.lookAt(0, 0, 0);
      });
      step('light', (x) => x.light.position.set(1.5, 4, 0.5));
      step('caster', (x) => x.box.position.set(0.5, 1.2, 0));
      step('nothing moved again', () => {});
      out[volumeCull ? 'culled' : 'unculled'] = { steps, volumeCull: a.umbra.info.volumeCull };
    }
    return out;
  });
  console.log(JSON.stringify(r));
  for (const [name, { steps, volumeCull }] of Object.entries(r)) {
    assert.equal(volumeCull, name === 'culled', `${name}: volumeCull as asked`);
    const at = (s) => steps.find((x) => x.name === s);
    for (const s of steps) {
      assert.equal(s.differing, 0, `${name}, ${s.name}: the cached instance's masks are the fresh one's`);
      assert.ok(s.shadowed > 100, `${name}, ${s.name}: something is shadowed (the masks are not blank)`);
      assert.equal(s.freshReused, false, `${name}, ${s.name}: cache: false never reuses a frame`);
      assert.deepEqual(s.freshCached, [0, 0], `${name}, ${s.name}: cache: false keeps no silhouette`);
      assert.ok(s.cpuMs > 0, `${name}, ${s.name}: info.cpuMs measured`);
    }
    for (const s of ['first', 'camera', 'light', 'caster']) assert.equal(at(s).reused, false, `${name}, ${s}: a frame where something moved is drawn`);
    for (const s of ['nothing moved', 'nothing moved again']) assert.equal(at(s).reused, true, `${name}, ${s}: reused`);
    if (name === 'unculled') {
      // Two casters (floor and box) per light.
      assert.deepEqual(at('camera').cached, [2, 2], 'the camera moved: both lights\' silhouettes of both casters kept');
      assert.deepEqual(at('light').cached, [0, 2], 'the first light moved: its silhouettes computed again, the second light\'s kept');
      assert.deepEqual(at('caster').cached, [1, 1], 'the box moved: its silhouettes computed again, the floor\'s kept');
    } else {
      // Culled silhouettes depend on the frame's receivers: never kept.
      for (const s of steps) assert.deepEqual(s.cached, [0, 0], `culled, ${s.name}: nothing kept`);
    }
  }
});

test('memory: a caster of more polygons than the shared polygon storage holds at once (80,000 triangles, z-fail caps: ten chunks) decides as its 2-triangle twin; info.gpuBytes counts umbra\'s buffers', { skip }, async () => {
  const r = await page.evaluate(async () => {
    const { THREE, UmbraShadows } = window.T;
    const run = async (segments) => {
      const renderer = makeRenderer();
      // z-fail everywhere: the floor's light and dark caps are drawn, 80,000 polygons a set.
      const umbra = await UmbraShadows.create(renderer, { zpass: false, volumeCull: false });
      const s = makeScene();
      s.floor.geometry = new THREE.PlaneGeometry(10, 10, segments, segments).rotateX(-Math.PI / 2);
      umbra.render(s.scene, s.camera);
      const mask = umbra.readMask(s.light);
      return { mask, info: { ...umbra.info }, storage: umbra.drawer.volumePrograms.storage?.capacity ?? 0 };
    };
    const fine = await run(200);
    const coarse = await run(1);
    return {
      differing: differing(fine.mask, coarse.mask), shadowed: zeros(coarse.mask), triangles: fine.info.triangles,
      zpass: fine.info.zpass, gpuBytes: [fine.info.gpuBytes, coarse.info.gpuBytes], storage: [fine.storage, coarse.storage],
    };
  });
  console.log(JSON.stringify(r));
  assert.ok(r.triangles > 80000, 'the fine floor has more triangles than one chunk');
  assert.deepEqual(r.zpass, [null], 'counted z-fail: caps drawn');
  assert.ok(r.shadowed > 1000, 'the box shadows the floor');
  // The two floors' depth differs by rounding only: a pixel or two on the shadow's edge.
  assert.ok(r.differing <= r.shadowed / 200, `fine and coarse floors decide alike (${r.differing} of ${r.shadowed})`);
  assert.equal(r.storage[0], 8192, 'the fine floor\'s sets are drawn in chunks of the largest storage (POLYGON_CHUNK)');
  assert.ok(r.storage[1] < 8192, 'a small scene keeps a small storage');
  // 160 x 120: mask 4 + depth-stencil 8 bytes a pixel at least, and the casters' textures.
  assert.ok(r.gpuBytes[1] > 160 * 120 * 12, `gpuBytes counts the targets (${r.gpuBytes[1]})`);
  assert.ok(r.gpuBytes[0] > r.gpuBytes[1] + 80000 * 48, `gpuBytes counts the fine floor's caps-data (${r.gpuBytes[0]})`);
});

test('silhouettes: \'gpu\' (the orientation pass, every record visited) decides as the wasm\'s silhouettes after the camera, a light and a caster moved, z-pass and z-fail, two lights; kept while a light stays put', { skip }, async () => {
  const r = await page.evaluate(async () => {
    const { THREE, UmbraShadows } = window.T;
    const out = [];
    for (const zpass of [true, false]) {
      const make = async (silhouettes) => {
        const renderer = makeRenderer();
        const umbra = await UmbraShadows.create(renderer, { silhouettes, volumeCull: false, zpass });
        const s = makeScene();
        const second = new THREE.PointLight(0xffffff, 4, 0, 0);
        second.position.set(-2, 3, 0.5);
        second.castShadow = true;
        s.scene.add(second);
        return { umbra, ...s, second };
      };
      const a = await make('gpu');
      const b = await make('wasm');
      const step = (name, change) => {
        for (const x of [a, b]) change(x);
        for (const x of [a, b]) x.umbra.render(x.scene, x.camera);
        const masks = [a, b].map((x) => [x.umbra.readMask(x.light), x.umbra.readMask(x.second)]);
        out.push({
          name: `${zpass ? 'z-pass' : 'z-fail'}, ${name}`, silhouettes: [a.umbra.info.silhouettes, b.umbra.info.silhouettes], zpass: a.umbra.info.zpass,
          cached: a.umbra.info.volumes.map((v) => v.cached), errors: a.umbra.errors.length,
          differing: differing(masks[0][0], masks[1][0]) + differing(masks[0][1], masks[1][1]), shadowed: zeros(masks[0][0]) + zeros(masks[0][1]),
        });
      };
      step('first', () => {});
      step('camera', (x) => {
        x.camera.position.set(1, 4.5, 5.5);
        x.camera.lookAt(0, 0, 0);
      });
      step('light', (x) => x.light.position.set(1.5, 4, 0.5));
      step('caster', (x) => x.box.position.set(0.5, 1.2, 0));
    }
    return out;
  });
  console.log(JSON.stringify(r));
  for (const s of r) {
    assert.deepEqual(s.silhouettes, ['gpu', 'wasm'], `${s.name}: the silhouettes as asked`);
    assert.equal(s.errors, 0, `${s.name}: no error`);
    assert.equal(s.differing, 0, `${s.name}: the GPU silhouettes' masks are the wasm's`);
    assert.ok(s.shadowed > 100, `${s.name}: something is shadowed`);
  }
  assert.deepEqual(r.find((s) => s.name === 'z-fail, camera').zpass, [null, null], 'z-fail counted where asked');
  assert.deepEqual(r.find((s) => s.name === 'z-pass, camera').cached, [2, 2], 'the camera moved: the GPU orientations kept');
  assert.deepEqual(r.find((s) => s.name === 'z-pass, light').cached, [0, 2], 'a light moved: its orientations computed again');
});

test('alpha-tested casters: a checkered leaf (alphaTest with an alphaMap) casts a checkered shadow through three.js\'s map while umbra decides for the rest; alphaCasters: \'triangles\' casts its whole quad; the user\'s flags kept', { skip }, async () => {
  const r = await page.evaluate(async () => {
    const { THREE, UmbraShadows } = window.T;
    const run = async ({ alphaCasters, leafCasts }) => {
      const renderer = makeRenderer();
      const umbra = await UmbraShadows.create(renderer, alphaCasters ? { alphaCasters } : {});
      const s = makeScene();
      s.floor.receiveShadow = false; // the user's choice: umbra's shadows and the map's reach it anyway
      // A 4 x 4 checker of alpha 0 and 1 on a 1 x 1 quad, 2.5 above the floor.
      const alpha = new Uint8Array(4 * 16);
      for (let i = 0; i < 16; i++) alpha.set(((i & 3) + (i >> 2)) % 2 ? [255, 255, 255, 255] : [0, 0, 0, 255], 4 * i);
      const alphaMap = new THREE.DataTexture(alpha, 4, 4);
      alphaMap.needsUpdate = true;
      const leaf = new THREE.Mesh(new THREE.PlaneGeometry(1, 1).rotateX(-Math.PI / 2), new THREE.MeshLambertMaterial({ color: 0x44aa44, alphaMap, alphaTest: 0.5, side: THREE.DoubleSide }));
      leaf.name = 'leaf';
      leaf.position.set(-0.5, 2.5, 1.5);
      leaf.castShadow = leafCasts;
      s.scene.add(leaf);
      s.light.shadow.mapSize.set(1024, 1024);
      umbra.render(s.scene, s.camera);
      return {
        mask: umbra.readMask(s.light), image: pixels(renderer), mapCasters: umbra.info.mapCasters, errs: umbra.errors,
        flags: { box: s.box.castShadow, floorReceives: s.floor.receiveShadow, leafCasts: leaf.castShadow, shadowMap: renderer.shadowMap.enabled }, errors: umbra.errors.length,
      };
    };
    const map = await run({ leafCasts: true });
    const none = await run({ leafCasts: false });
    const triangles = await run({ alphaCasters: 'triangles', leafCasts: true });
    for (const x of [map, none, triangles]) if (!x.mask) throw new Error(`no mask: ${JSON.stringify(x.errs)}`);
    // Pixels the leaf darkens in the shaded image (the map), and pixels its whole quad shadows
    // in umbra's mask (triangles).
    let darker = 0;
    for (let i = 0; i < map.image.length; i += 4) if (map.image[i + 1] + 8 < none.image[i + 1]) darker++;
    return {
      darker, quad: differing(triangles.mask, none.mask), maskSame: differing(map.mask, none.mask), mapCasters: [map.mapCasters, triangles.mapCasters],
      flags: map.flags, errors: map.errors + none.errors + triangles.errors, shadowed: zeros(none.mask),
    };
  });
  console.log(JSON.stringify(r));
  assert.equal(r.errors, 0);
  assert.deepEqual(r.mapCasters, [['leaf'], []], 'the leaf goes to the map; with alphaCasters: triangles, to umbra');
  assert.equal(r.maskSame, 0, 'umbra\'s decision leaves the alpha-tested leaf out');
  assert.ok(r.shadowed > 100, 'umbra still shadows the box');
  assert.ok(r.quad > 200, `alphaCasters: triangles: the whole quad shadows the floor (${r.quad} pixels)`);
  assert.ok(r.darker > 0.2 * r.quad && r.darker < 0.8 * r.quad, `the map's shadow is the leaf's checker, about half the quad's (${r.darker} of ${r.quad})`);
  assert.deepEqual(r.flags, { box: true, floorReceives: false, leafCasts: true, shadowMap: false }, 'the user\'s flags after the frame');
});

test('light order: a shadow-casting light added after another lands on its own uniform (three.js sorts casters first)', { skip }, async () => {
  const r = await page.evaluate(async () => {
    const { THREE, UmbraShadows } = window.T;
    const build = (withA, withB) => {
      const s = makeScene();
      s.scene.remove(s.light);
      // A: no umbra shadow, added first; B: umbra's, added second, on the other side.
      const a = new THREE.PointLight(0xff0000, 6, 0, 0);
      a.position.set(-3, 4, 0);
      const b = new THREE.PointLight(0x00ff00, 6, 0, 0);
      b.position.set(3, 4, 1);
      b.castShadow = true;
      if (withA) s.scene.add(a);
      if (withB) s.scene.add(b);
      return { ...s, b };
    };
    const renderer = makeRenderer();
    const fresh = makeRenderer();
    const umbra = await UmbraShadows.create(renderer);
    const both = build(true, true);
    umbra.render(both.scene, both.camera);
    const mask = umbra.readMask(both.b);
    const shaded = pixels(renderer);
    const onlyA = build(true, false);
    fresh.render(onlyA.scene, onlyA.camera);
    const refA = pixels(fresh);
    const bothPlain = build(true, true);
    fresh.render(bothPlain.scene, bothPlain.camera);
    const refBoth = pixels(fresh);
    // Shadowed by B: as if B were absent; lit by B: both lights. Rows: readMask top-down.
    const w = 160, h = 120;
    let wrong = 0, shadowed = 0;
    for (let y = 0; y < h; y++) for (let x = 0; x < w; x++) {
      const p = 4 * ((h - 1 - y) * w + x);
      const ref = mask[y * w + x] ? refBoth : refA;
      if (!mask[y * w + x]) shadowed++;
      if ([0, 1, 2].some((c) => Math.abs(shaded[p + c] - ref[p + c]) > 1)) wrong++;
    }
    return { wrong, shadowed, differs: differing(refA, refBoth) };
  });
  console.log(JSON.stringify(r));
  assert.ok(r.shadowed > 1000 && r.differs > 5000, 'B shadows part of the view and lights the rest');
  // Only silhouette pixels, where three.js's rasteriser and umbra's depth pass may show
  // different surfaces, may differ.
  assert.ok(r.wrong < 60, `${r.wrong} pixels shaded as neither "B shadowed" nor "B lit"`);
});

test('z-pass where the near pyramid is proven inside one count (eye in the open, eye in a shadow), z-fail where a caster cuts it: the same mask as z-fail everywhere', { skip }, async () => {
  const r = await page.evaluate(async () => {
    const { THREE, UmbraShadows } = window.T;
    const auto = await UmbraShadows.create(makeRenderer());
    const zfail = await UmbraShadows.create(makeRenderer(), { zpass: false });
    const views = {
      open: (s) => s,
      // Under the box (scaled and turned: the test runs in its own space), inside its shadow,
      // looking down at the floor, part of it in that shadow.
      inShadow: (s) => {
        s.box.scale.set(1.3, 1, 1.2);
        s.box.rotation.y = 0.3;
        s.camera.position.set(0, 0.3, 0);
        s.camera.lookAt(-1.5, 0, -1);
        return s;
      },
      // The near plane (0.1 in front of the eye at z = 0.52) cuts the box's corner at
      // x = 0.5, z = 0.5: the left of the view inside the box, the right past it.
      nearCut: (s) => {
        s.camera.position.set(0.53, 1.2, 0.52);
        s.camera.lookAt(0.9, 0, -2);
        return s;
      },
      directional: (s) => {
        s.scene.remove(s.light);
        const d = new THREE.DirectionalLight(0xffffff, 2);
        d.position.set(-2, 5, 1);
        d.castShadow = true;
        s.scene.add(d, d.target);
        s.light = d;
        return s;
      },
    };
    const out = {};
    for (const [name, view] of Object.entries(views)) {
      const a = view(makeScene());
      a.camera.updateMatrixWorld();
      auto.render(a.scene, a.camera);
      const mask = auto.readMask(a.light);
      const b = view(makeScene());
      b.camera.updateMatrixWorld();
      zfail.render(b.scene, b.camera);
      const ref = zfail.readMask(b.light);
      out[name] = {
        zpass: auto.info.zpass, reference: zfail.info.zpass, differing: differing(mask, ref),
        lit: mask.reduce((n, v) => n + (v === 255), 0), dark: zeros(mask),
      };
    }
    return out;
  });
  console.log(JSON.stringify(r));
  assert.deepEqual(r.open.zpass, [0], 'eye in the open: z-pass from 0');
  assert.deepEqual(r.inShadow.zpass, [2], 'eye in the box\'s shadow: z-pass from 2');
  assert.deepEqual(r.nearCut.zpass, [null], 'the box cut by the near plane: z-fail');
  assert.deepEqual(r.directional.zpass, [0], 'directional light, eye in the open: z-pass');
  for (const [name, v] of Object.entries(r)) {
    assert.deepEqual(v.reference, [null], `${name}: zpass: false counts z-fail`);
    assert.equal(v.differing, 0, `${name}: the mask differs from z-fail's on ${v.differing} pixels`);
    assert.ok(v.lit > 500 && v.dark > 500, `${name}: the view is partly lit, partly dark (${v.lit} / ${v.dark})`);
  }
});

test('volumeCull: the mask of every volume to infinity, but for pixels on shadow boundaries (point and directional light, z-pass and z-fail, both scatters, clamped and not); the volumes of shadows out of view are not drawn', { skip }, async () => {
  const r = await page.evaluate(async () => {
    const { THREE, UmbraShadows } = window.T;
    // A floor and a 5 x 5 grid of turned boxes under a point light; the camera looks down at
    // one corner, so most boxes' shadows fall on floor it does not see.
    const build = (directional) => {
      const s = makeScene();
      s.scene.remove(s.box);
      const mat = new THREE.MeshStandardMaterial({ color: 0xffffff });
      for (let i = 0; i < 25; i++) {
        const b = new THREE.Mesh(new THREE.BoxGeometry(0.5, 0.8, 0.5), mat);
        b.position.set(-4 + 2 * (i % 5), 0.6, -4 + 2 * Math.floor(i / 5));
        b.rotation.set(0.2 * i, 0.3 * i, 0);
        b.castShadow = true;
        s.scene.add(b);
      }
      if (directional) {
        s.scene.remove(s.light);
        const d = new THREE.DirectionalLight(0xffffff, 2);
        d.position.set(-2, 5, 1);
        d.castShadow = true;
        s.scene.add(d, d.target);
        s.light = d;
      } else {
        // High above: every box's cone lies inside one face of the light's cube map.
        s.light.position.set(0.3, 8, 0.2);
      }
      s.camera.position.set(4.6, 1.8, 5.2);
      s.camera.lookAt(3.8, 0, 3.6);
      s.camera.updateMatrixWorld();
      return s;
    };
    const renderers = {
      off: (zpass) => UmbraShadows.create(makeRenderer(), { zpass, volumeCull: false }),
      cpu: (zpass) => UmbraShadows.create(makeRenderer(), { zpass, receiverScatter: 'cpu' }),
      gpu: (zpass) => UmbraShadows.create(makeRenderer(), { zpass, receiverScatter: 'gpu' }),
      clamped: (zpass) => UmbraShadows.create(makeRenderer(), { zpass, volumeClamp: 'always' }),
      // A context without EXT_color_buffer_float: the cull off, and why, in umbra.info.
      noext: (zpass) => {
        const r = makeRenderer();
        const gl = r.getContext();
        const get = gl.getExtension.bind(gl);
        gl.getExtension = (name) => (name === 'EXT_color_buffer_float' ? null : get(name));
        return UmbraShadows.create(r, { zpass });
      },
    };
    const out = {};
    for (const directional of [false, true]) {
      for (const zpass of [true, false]) {
        const row = {};
        for (const [name, make] of Object.entries(renderers)) {
          const umbra = await make(zpass);
          const s = build(directional);
          umbra.render(s.scene, s.camera);
          row[name] = { mask: umbra.readMask(s.light), info: JSON.parse(JSON.stringify(umbra.info)), errors: umbra.errors.length };
        }
        const ref = row.off.mask;
        // Pixels that differ from the unculled mask, and of those, the ones not on a shadow
        // boundary (all 8 neighbours alike in the unculled mask).
        const w = 160, h = 120;
        const inside = (m) => {
          let n = 0;
          for (let i = 0; i < m.length; i++) {
            if (m[i] === ref[i]) continue;
            const [x, y] = [i % w, Math.floor(i / w)];
            let mixed = false;
            for (let dy = -1; dy <= 1; dy++) for (let dx = -1; dx <= 1; dx++) {
              const [u, v] = [x + dx, y + dy];
              if (u >= 0 && v >= 0 && u < w && v < h && ref[v * w + u] !== ref[i]) mixed = true;
            }
            if (!mixed) n++;
          }
          return n;
        };
        out[`${directional ? 'directional' : 'point'}, ${zpass ? 'z-pass' : 'z-fail'}`] = Object.fromEntries(Object.entries(row).map(([k, v]) => [k, {
          differing: differing(v.mask, ref), offBoundary: inside(v.mask), dark: zeros(v.mask), errors: v.errors, zpass: v.info.zpass, volumes: v.info.volumes,
          volumeCull: v.info.volumeCull, receiverScatter: v.info.receiverScatter, volumeCullMessage: v.info.volumeCullMessage,
        }]));
      }
    }
    return out;
  });
  console.log(JSON.stringify(r));
  for (const [what, row] of Object.entries(r)) {
    const off = row.off.volumes[0];
    assert.equal(row.off.volumeCull, false);
    assert.ok(!off.culled, `${what}: volumeCull false draws unculled`);
    assert.ok(row.off.dark > 500 && row.off.dark < 18000, `${what}: partly shadowed (${row.off.dark} dark pixels)`);
    assert.deepEqual(row.off.zpass, what.endsWith('z-pass') ? [0] : [null], `${what}: its count`);
    assert.ok(row.clamped.volumes[0].clamped > 0, `${what}: volumeClamp 'always' clamps`);
    assert.equal(row.noext.volumeCull, false, `${what}: no EXT_color_buffer_float, no cull`);
    assert.match(row.noext.volumeCullMessage, /EXT_color_buffer_float/);
    assert.equal(row.noext.differing, 0, `${what}: unculled without the extension, the unculled mask`);
    assert.equal(row.noext.errors, 0);
    for (const scatter of ['cpu', 'gpu', 'clamped']) {
      const v = row[scatter];
      assert.equal(v.errors, 0, `${what}, ${scatter}: no errors`);
      assert.equal(v.receiverScatter, scatter === 'gpu' ? 'gpu' : 'cpu');
      // Both masks are exact (the oracle judges them: browser.test.mjs); their volumes are
      // different polygons, so a pixel centre within the rasteriser's precision of a shadow
      // boundary may fall either way, and only there.
      assert.equal(v.offBoundary, 0, `${what}, ${scatter} scatter: ${v.offBoundary} pixels away from every shadow boundary differ from the unculled mask`);
      assert.ok(v.differing <= 10, `${what}, ${scatter} scatter: the culled mask differs from the unculled one on ${v.differing} pixels`);
      const on = v.volumes[0];
      assert.ok(on.culled, `${what}, ${scatter}: culled`);
      // Most boxes' shadows are out of view: their triangles and silhouettes are not drawn.
      assert.ok(on.triangles < 0.6 * off.triangles, `${what}, ${scatter}: ${on.triangles} of ${off.triangles} triangles kept`);
      assert.ok(on.edges < 0.6 * off.edges, `${what}, ${scatter}: ${on.edges} of ${off.edges} silhouette records drawn`);
    }
  }
});

test('z-pass for casters that share a world matrix: a roof split in two meshes, the eye under its seam, counted z-pass from 1 by their union; the same mask as z-fail', { skip }, async () => {
  const r = await page.evaluate(async () => {
    const { THREE, UmbraShadows } = window.T;
    const build = () => {
      const s = makeScene();
      s.scene.remove(s.box);
      // A 4 x 4 roof at y = 3 in two halves (x < 0 and x > 0): each half's border at x = 0 is
      // open for it alone, closed for the two together.
      const mat = new THREE.MeshLambertMaterial({ color: 0xffffff, side: THREE.DoubleSide });
      for (const side of [-1, 1]) {
        const half = new THREE.Mesh(new THREE.PlaneGeometry(2, 4).rotateX(Math.PI / 2).translate(side, 3, 0), mat);
        half.name = `roof ${side}`;
        half.castShadow = true;
        s.scene.add(half);
      }
      s.light.position.set(0, 6, 0.2);
      // Under the roof, at its seam: every ray from the near rectangle to the light crosses the
      // roof, some through one half and some through the other.
      s.camera.position.set(0, 2, 0);
      s.camera.lookAt(2, 0, 1.5);
      s.camera.updateMatrixWorld();
      return s;
    };
    const out = {};
    for (const [name, options] of Object.entries({ auto: {}, zfail: { zpass: false }, unculled: { volumeCull: false } })) {
      const umbra = await UmbraShadows.create(makeRenderer(), options);
      const s = build();
      umbra.render(s.scene, s.camera);
      out[name] = { mask: umbra.readMask(s.light), zpass: umbra.info.zpass, errors: umbra.errors.length, unions: umbra.unions.size };
    }
    const ref = out.zfail.mask;
    return Object.fromEntries(Object.entries(out).map(([k, v]) => [k, { zpass: v.zpass, errors: v.errors, unions: v.unions, differing: differing(v.mask, ref), dark: zeros(v.mask) }]));
  });
  console.log(JSON.stringify(r));
  assert.deepEqual(r.zfail.zpass, [null]);
  assert.ok(r.zfail.dark > 500 && r.zfail.dark < 18000, `partly shadowed (${r.zfail.dark} dark pixels)`);
  for (const k of ['auto', 'unculled']) {
    assert.equal(r[k].errors, 0);
    assert.deepEqual(r[k].zpass, [1], `${k}: the union of the roof's halves and the floor proves one count under the roof`);
    assert.equal(r[k].unions, 1, `${k}: one union (the casters of the identity matrix)`);
    assert.equal(r[k].differing, 0, `${k}: ${r[k].differing} pixels differ from the z-fail mask`);
  }
});
