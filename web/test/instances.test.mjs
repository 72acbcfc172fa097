// umbra-three with the meshes real three.js apps draw many copies with: an InstancedMesh (its
// first `count` instances, one of them mirrored, one turned and scaled) and a BatchedMesh (two
// geometries, three instances, one hidden with setVisibleAt), over a floor, in Debian's
// Chromium (SwiftShader, headless). Each instance casts from its own matrix with the one
// topology of its geometry. Judged by the oracle: the page writes the instanced geometry
// out in world space (every drawn instance's triangles; the matrices hold only 0, ±1, ±0.5
// and dyadic offsets, so every world position is exact in f32), and `umbra verify
// --external-mask` judges each light's mask with the page's view: 0 samples outside the band.
// Also: the hidden instance and the instances past `count` cast nothing, and moving one
// instance moves its shadow only.
//
// Needs: /usr/bin/chromium, the wasm module (node build-wasm.mjs) and the umbra binary
// (cargo build --release -p umbra-cli, or UMBRA_BIN); skipped with a message when one is
// absent. Run: cd web && node --test test/instances.test.mjs
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { existsSync } from 'node:fs';
import { mkdtemp, mkdir, rm, writeFile } from 'node:fs/promises';
import { tmpdir } from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { createServer, listen } from '../serve.mjs';
import { buildPackage } from '../umbra-three/build.mjs';
import { launch, judge } from '../testlib/exactness.mjs';
import { encodePng } from '../testlib/png.mjs';

const here = path.dirname(fileURLToPath(import.meta.url));
const webDir = path.join(here, '..');
const repo = path.join(webDir, '..');
const CHROMIUM = process.env.UMBRA_CHROMIUM || '/usr/bin/chromium';
const WASM = path.join(webDir, 'umbra-geom-wasm', 'umbra_wasm.wasm');
const umbraBin = [process.env.UMBRA_BIN, process.env.CARGO_TARGET_DIR && path.join(process.env.CARGO_TARGET_DIR, 'release', 'umbra'), path.join(repo, 'target', 'release', 'umbra')]
  .find((c) => c && existsSync(c));
const skip = !existsSync(CHROMIUM) ? `${CHROMIUM} is absent (apt-get install chromium): instanced-mesh test skipped`
  : !existsSync(WASM) ? `${WASM} is absent (node build-wasm.mjs): instanced-mesh test skipped`
    : !umbraBin ? 'no umbra binary (cargo build --release -p umbra-cli, or UMBRA_BIN): instanced-mesh test skipped' : false;
if (skip) console.log(`SKIP: ${skip}`);

const W = 320;
const H = 240;
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
  tmp = await mkdtemp(path.join(tmpdir(), 'umbra-instances-'));
  const dist = await buildPackage(path.join(tmp, 'umbra-three'));
  const root = path.join(tmp, 'root');
  await mkdir(root);
  await writeFile(path.join(root, 'index.html'), PAGE);
  server = createServer([['/', root], ['/three/', path.join(webDir, 'node_modules', 'three')], ['/umbra-three/', dist], ['/testlib/', path.join(webDir, 'testlib')]]);
  base = await listen(server, 0);
  ctx = await launch(CHROMIUM, 'swiftshader', tmp);
  page = await ctx.newPage();
  page.on('pageerror', (e) => console.log(`page error: ${e}`));
  await page.goto(base);
  await page.evaluate(([w, h]) => {
    window.makeWorld = async (options) => {
      const THREE = await import('three');
      const { UmbraShadows } = await import('umbra-three');
      const canvas = document.createElement('canvas');
      document.body.appendChild(canvas);
      const renderer = new THREE.WebGLRenderer({ canvas });
      renderer.setPixelRatio(1);
      renderer.setSize(w, h, false);
      const umbra = await UmbraShadows.create(renderer, options);
      const scene = new THREE.Scene();
      const mat = () => new THREE.MeshLambertMaterial({ color: 0xcccccc, side: THREE.DoubleSide });
      const floor = new THREE.Mesh(new THREE.PlaneGeometry(10, 10).rotateX(-Math.PI / 2), mat());
      floor.castShadow = true;
      // Matrices of 0, ±1, ±0.5 and dyadic offsets: the world positions are exact.
      const m4 = (r0, r1, r2, t) => new THREE.Matrix4().set(...r0, t[0], ...r1, t[1], ...r2, t[2], 0, 0, 0, 1);
      const boxes = new THREE.InstancedMesh(new THREE.BoxGeometry(1, 1, 1), mat(), 4);
      boxes.name = 'boxes';
      boxes.castShadow = true;
      boxes.setMatrixAt(0, m4([1, 0, 0], [0, 1, 0], [0, 0, 1], [-2, 1, 0]));
      // Mirrored (determinant -1): its winding turns, its shadow must not.
      boxes.setMatrixAt(1, m4([-1, 0, 0], [0, 1, 0], [0, 0, 1], [0, 1.5, -1]));
      // Turned a quarter about y and halved.
      boxes.setMatrixAt(2, m4([0, 0, 0.5], [0, 0.5, 0], [-0.5, 0, 0], [2, 1, 1]));
      // Past `count`: neither drawn nor casting.
      boxes.setMatrixAt(3, m4([1, 0, 0], [0, 1, 0], [0, 0, 1], [0, 1, 2]));
      boxes.count = 3;
      scene.add(boxes);
      const batch = new THREE.BatchedMesh(4, 200, 400, mat());
      batch.name = 'batch';
      batch.castShadow = true;
      const cone = batch.addGeometry(new THREE.ConeGeometry(0.5, 1, 8));
      const slab = batch.addGeometry(new THREE.BoxGeometry(1.5, 0.25, 0.5));
      const b0 = batch.addInstance(cone);
      batch.setMatrixAt(b0, m4([1, 0, 0], [0, 1, 0], [0, 0, 1], [-1, 0.75, 2]));
      const b1 = batch.addInstance(slab);
      batch.setMatrixAt(b1, m4([1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 2.5, -0.5]));
      const b2 = batch.addInstance(cone);
      batch.setMatrixAt(b2, m4([1, 0, 0], [0, 1, 0], [0, 0, 1], [3, 0.75, -2]));
      batch.setVisibleAt(b2, false);
      scene.add(batch);
      // The floor last: the first caster drawn is an instance whose shadow is seen, so that a
      // volume pass that loses a binding on its first set (the polygon storage made in it)
      // shows as false light.
      scene.add(floor);
      const light = new THREE.PointLight(0xffffff, 8, 0, 0);
      light.position.set(0.5, 4.5, 1);
      light.castShadow = true;
      scene.add(light, new THREE.AmbientLight(0xffffff, 0.3));
      scene.updateMatrixWorld(true);

      // Every drawn instance's triangles in world space (what umbra verify judges), f64 then f32.
      // Meshes the tests add (skinned, morphed), baked in their pose.
      const extra = [];
      const { addWorldTriangles, meshFileNear, trianglesObj } = await import('/testlib/page-world.js');
      const world = () => {
        const pos = [];
        const add = (geometry, m, range = null, posedBy = null) => addWorldTriangles(pos, geometry, m.elements, range, posedBy);
        const m = new THREE.Matrix4();
        add(floor.geometry, floor.matrixWorld);
        for (let i = 0; i < boxes.count; i++) add(boxes.geometry, boxes.getMatrixAt(i, m).premultiply(boxes.matrixWorld));
        for (const id of [b0, b1, b2]) {
          if (!batch.getVisibleAt(id)) continue;
          add(batch.geometry, batch.getMatrixAt(id, m).premultiply(batch.matrixWorld), batch.getGeometryRangeAt(batch.getGeometryIdAt(id)));
        }
        // Skinned and morphed meshes the tests add, in their pose.
        for (const x of extra) add(x.geometry, x.matrixWorld, null, x);
        return { obj: trianglesObj(pos), near: meshFileNear(pos), triangles: pos.length / 9 };
      };
      const camera = new THREE.PerspectiveCamera(50, w / h, 0.1, 100);
      camera.position.set(0, 5, 7);
      camera.lookAt(0, 0, 0);
      const frame = () => {
        const out = world();
        camera.near = out.near;
        camera.updateProjectionMatrix();
        umbra.render(scene, camera);
        const mask = umbra.readMask(light);
        let s = '';
        for (let i = 0; i < mask.length; i += 8192) s += String.fromCharCode.apply(null, mask.subarray(i, i + 8192));
        return { ...out, mask: s, errors: umbra.errors.slice(), info: { casters: umbra.info.casters, triangles: umbra.info.triangles, volumes: umbra.info.volumes, zpass: umbra.info.zpass }, subpixelBits: umbra.subpixelBits };
      };
      window.T = { THREE, umbra, scene, camera, light, boxes, batch, frame, m4, ids: [b0, b1, b2], extra };
    };
  }, [W, H]);
});

after(async () => {
  if (ctx) await ctx.close();
  if (server) await new Promise((r) => server.close(r));
  if (tmp) await rm(tmp, { recursive: true, force: true });
});

/** The page's frame judged by `umbra verify --external-mask`; returns the browser row and the frame. */
async function judged(name) {
  const f = await page.evaluate(() => window.T.frame());
  const obj = path.join(tmp, `${name}.obj`);
  await writeFile(obj, f.obj);
  const gray = Buffer.from(f.mask, 'latin1');
  const rgba = new Uint8Array(4 * W * H);
  for (let i = 0; i < gray.length; i++) rgba.set([gray[i], gray[i], gray[i], 255], 4 * i);
  const png = path.join(tmp, `${name}.png`);
  await writeFile(png, encodePng(W, H, rgba));
  const cam = await page.evaluate(() => ({ eye: window.T.camera.position.toArray(), light: window.T.light.position.toArray() }));
  const extra = ['--eye', cam.eye.join(','), '--target', '0,0,0', '--fov', '50', '--light', cam.light.join(','), '--subpixel-bits', String(f.subpixelBits)];
  const r = judge(umbraBin, { scene: obj, size: `${W}x${H}`, maskPng: png, extra, explain: 20 });
  let dark = 0;
  for (let i = 0; i < gray.length; i++) dark += gray[i] === 0;
  return { browser: r.browser, explained: r.explained, frame: f, dark };
}

for (const [name, options] of [['default', {}], ['GPU silhouettes, unculled', { silhouettes: 'gpu', volumeCull: false }]]) {
  test(`${name}: InstancedMesh and BatchedMesh cast from every drawn instance (mirrored, turned, scaled; a hidden one and those past count cast nothing): 0 samples outside the band; a moved instance moves its shadow`, { skip }, async () => {
    await page.evaluate((o) => window.makeWorld(o), options);
    const first = await judged('instances');
    console.log(JSON.stringify({ row: first.browser, info: first.frame.info, errors: first.frame.errors, triangles: first.frame.triangles, dark: first.dark }));
    assert.deepEqual(first.frame.errors, [], 'no mesh refused');
    // floor + 3 boxes + 2 batch instances.
    assert.equal(first.frame.info.casters, 6, 'one caster per drawn instance');
    assert.equal(first.browser.mismatches_outside_band, 0, `0 outside the band: ${first.explained.join('; ')}`);
    assert.ok(first.browser.shadowed_reference > 1000, 'the instances shadow the floor');
    assert.ok(first.browser.samples > 0.5 * W * H, 'the floor fills the view');
    // The hidden batch instance and the instance past `count`, shown: more shadow.
    await page.evaluate(() => {
      const { boxes, batch, ids } = window.T;
      boxes.count = 4;
      batch.setVisibleAt(ids[2], true);
    });
    const shown = await judged('shown');
    assert.equal(shown.frame.info.casters, 8, 'the shown instances cast too');
    assert.equal(shown.browser.mismatches_outside_band, 0, `shown: 0 outside the band: ${shown.explained.join('; ')}`);
    assert.ok(shown.dark > first.dark + 100, 'the shown instances add shadow');
    // One instance moved: judged again (its silhouette kept by slot must not be stale).
    await page.evaluate(() => {
      const { boxes, m4 } = window.T;
      boxes.setMatrixAt(0, m4([1, 0, 0], [0, 1, 0], [0, 0, 1], [-2.5, 1, -1.5]));
      boxes.instanceMatrix.needsUpdate = true;
    });
    const moved = await judged('moved');
    assert.equal(moved.browser.mismatches_outside_band, 0, `moved: 0 outside the band: ${moved.explained.join('; ')}`);
    assert.notEqual(moved.frame.mask, shown.frame.mask, 'the moved instance moved its shadow');
  });
}

test('a SkinnedMesh (a bent, jointed column) and a morphed box cast from the pose three.js draws, frame after frame: 0 samples outside the band', { skip }, async () => {
  await page.evaluate(async () => {
    await window.makeWorld({});
    const { THREE, scene, extra } = window.T;
    // A column of 2 bones, its vertices weighted to the lower or upper bone by height.
    const geometry = new THREE.CylinderGeometry(0.25, 0.25, 2, 8, 4);
    geometry.translate(0, 1, 0);
    const p = geometry.attributes.position;
    const skinIndex = [];
    const skinWeight = [];
    for (let i = 0; i < p.count; i++) {
      const upper = p.getY(i) > 1;
      skinIndex.push(upper ? 1 : 0, 0, 0, 0);
      skinWeight.push(1, 0, 0, 0);
    }
    geometry.setAttribute('skinIndex', new THREE.Uint16BufferAttribute(skinIndex, 4));
    geometry.setAttribute('skinWeight', new THREE.Float32BufferAttribute(skinWeight, 4));
    const root = new THREE.Bone();
    const joint = new THREE.Bone();
    joint.position.y = 1;
    root.add(joint);
    const column = new THREE.SkinnedMesh(geometry, new THREE.MeshLambertMaterial({ color: 0xcccccc, side: THREE.DoubleSide }));
    column.name = 'column';
    column.castShadow = true;
    column.add(root);
    column.bind(new THREE.Skeleton([root, joint]));
    column.position.set(0.5, 0, -2);
    scene.add(column);
    // A box whose top is pulled up by a morph target.
    const box = new THREE.BoxGeometry(1, 0.5, 1);
    const up = box.attributes.position.clone();
    for (let i = 0; i < up.count; i++) if (up.getY(i) > 0) up.setY(i, up.getY(i) + 1);
    box.morphAttributes.position = [up];
    const morphed = new THREE.Mesh(box, new THREE.MeshLambertMaterial({ color: 0xcccccc, side: THREE.DoubleSide }));
    morphed.name = 'morphed';
    morphed.castShadow = true;
    morphed.position.set(-2.5, 0.25, -1.5);
    morphed.morphTargetInfluences = [0.5];
    scene.add(morphed);
    scene.updateMatrixWorld(true);
    extra.push(column, morphed);
    window.T.pose = (angle, influence) => {
      joint.rotation.z = angle;
      morphed.morphTargetInfluences[0] = influence;
      scene.updateMatrixWorld(true);
    };
  });
  const masks = [];
  for (const [angle, influence] of [[0.6, 0.5], [1.2, 1], [-0.8, 0.25]]) {
    await page.evaluate(([a, i]) => window.T.pose(a, i), [angle, influence]);
    const r = await judged(`posed-${angle}`);
    console.log(JSON.stringify({ angle, influence, row: r.browser.mismatches_outside_band, band: r.browser.band_samples, shadowed: r.browser.shadowed_reference, errors: r.frame.errors, info: r.frame.info }));
    assert.deepEqual(r.frame.errors, [], 'no mesh refused');
    assert.equal(r.frame.info.casters, 8, 'the floor, 3 boxes, 2 batch instances, the column and the morphed box cast');
    assert.deepEqual(r.frame.info.zpass, [null], 'a posed caster is counted z-fail');
    assert.equal(r.browser.mismatches_outside_band, 0, `pose ${angle}, ${influence}: 0 outside the band: ${r.explained.join('; ')}`);
    masks.push(r.frame.mask);
  }
  assert.notEqual(masks[0], masks[1], 'the pose moved the shadow');
  assert.notEqual(masks[1], masks[2], 'and again');
});
