// The benchmark page (bench/run.mjs drives it; never a test): one model, drawn the ways a
// three.js user can draw it with a point light, frame by frame on request:
//   none     three.js, no shadows
//   map1024  PointLight.castShadow, shadow.mapSize 1024 (three.js's cube shadow map)
//   map2048  the same with 2048
//   bvh      a three-mesh-bvh shadow ray per pixel (bvh-shadow.js)
//   umbra    the umbra-three package (exact shadow volumes)
//   umbranocull  the same with volumeCull off (every volume to infinity); umbraclamp and
//            umbranoclamp: culled volumes always clamped / never clamped (volumeClamp)
// Every mesh gets a MeshLambertMaterial, both faces drawn (the bvh row: the same shading in
// its ShaderMaterial).
// The camera and the light are `umbra render`'s defaults for the file (examples/gltf/view.js);
// eye, target, fov, light query parameters override them as there.
//
// Query: model=URL (.obj .gltf .glb .ply, optionally .gz), size=WxH.
// window.bench: { ready, error, triangles, renderer, first(mode) -> ms (that mode's set-up
// and first frame: for bvh the BVH build, for umbra the module's loading and the scene's
// preprocessing), frame(mode) -> ms, split(mode) -> { cpu, frame } (the render call's
// main-thread ms, then the frame's until the readPixels), passes(n) -> umbra's pass breakdown averaged over n frames
// (umbra.timing on), info(mode), view(eye, target) }. A frame is made synchronous with a
// readPixels of 1 pixel.
import * as THREE from 'three';
import { loadModel } from '../examples/gltf/load.js';
import { viewFor, triangleBounds } from '../examples/gltf/view.js';
import { bvhShadowMaterial } from './bvh-shadow.js';

const params = new URLSearchParams(location.search);
const bench = { ready: false, error: null };
window.bench = bench;
const say = (t) => {
  document.getElementById('status').textContent = t;
};

async function start() {
  const canvas = document.getElementById('canvas');
  const m = /^(\d+)x(\d+)$/.exec(params.get('size') || '640x360');
  if (!m) throw new Error(`URL parameter size=${params.get('size')}: expected WxH`);
  const [width, height] = [Number(m[1]), Number(m[2])];
  // As a user creates it: default attributes (no stencil since r163, no antialias).
  const renderer = new THREE.WebGLRenderer({ canvas });
  renderer.setPixelRatio(1);
  renderer.setSize(width, height, false);
  renderer.shadowMap.type = THREE.PCFShadowMap;
  const gl = renderer.getContext();
  const dbg = gl.getExtension('WEBGL_debug_renderer_info');
  bench.renderer = dbg ? gl.getParameter(dbg.UNMASKED_RENDERER_WEBGL) : gl.getParameter(gl.RENDERER);

  const url = params.get('model');
  if (!url) throw new Error('URL parameter model= is required');
  let t = performance.now();
  const model = await loadModel(url);
  model.updateMatrixWorld(true);
  bench.loadMs = performance.now() - t;
  // Both faces drawn (DoubleSide), as CAD and BIM models need and as umbra decides: the nearest
  // surface whatever its winding. With front faces only, three.js would show Crytek Sponza's
  // atrium floor through a down-facing sheet just above it, which the maps and the rays then
  // (rightly) find in that sheet's shadow.
  const plain = new THREE.MeshLambertMaterial({ color: 0xcccccc, side: THREE.DoubleSide });
  // umbra's meshes get their own material instance, so that the rows without umbra draw
  // three.js's material untouched by the package's shader patch.
  const patched = plain.clone();
  // The package's other rows (each UmbraShadows patches its own instance): its options.
  // The rows timed frame by frame over one view draw every frame in full (cache: false: a
  // frame with nothing moved would reuse the last one's decisions); umbracache and
  // umbracachenocull are the package's defaults (cache on), for the orbit (bench.orbit), and
  // umbragpu what a GPU gets by default (unculled, silhouettes on the GPU).
  const VARIANTS = {
    umbra: { cache: false }, umbranocull: { volumeCull: false, cache: false }, umbraclamp: { volumeClamp: 'always', cache: false },
    umbranoclamp: { volumeClamp: 'never', cache: false }, umbramrt: { positionPass: 'mrt', cache: false },
    umbracache: {}, umbracachenocull: { volumeCull: false }, umbragpu: { volumeCull: false, silhouettes: 'gpu' },
  };
  const variantMaterial = Object.fromEntries(Object.keys(VARIANTS).map((k) => [k, k === 'umbra' ? patched : plain.clone()]));
  const meshes = [];
  let triangles = 0;
  model.traverse((o) => {
    if (!o.isMesh) return;
    if (!o.geometry.attributes.normal) o.geometry.computeVertexNormals();
    o.material = plain;
    o.castShadow = true;
    o.receiveShadow = true;
    meshes.push(o);
    triangles += (o.geometry.index ? o.geometry.index.count : o.geometry.attributes.position.count) / 3;
  });
  bench.triangles = triangles;
  const scene = new THREE.Scene();
  scene.add(model);
  scene.add(new THREE.AmbientLight(0xffffff, 0.25));

  const view = viewFor(model, params);
  if (view.light[3] !== 1) throw new Error('the benchmark compares point lights: light= needs W = 1');
  bench.view = view;
  const b = triangleBounds(model);
  const diagonal = b ? Math.hypot(...[0, 1, 2].map((i) => b.max[i] - b.min[i])) : 2;
  const camera = new THREE.PerspectiveCamera(view.fov, width / height, view.near, diagonal * 4);
  camera.up.set(...view.up);
  camera.position.set(...view.eye);
  camera.lookAt(...view.target);
  // Two point lights at the same place, one per map size, so that the interleaved rows never
  // reallocate a cube map: only the row's own light is visible.
  const lights = [1024, 2048].map((size) => {
    const light = new THREE.PointLight(0xffffff, 2.5, 0, 0);
    light.position.set(view.light[0], view.light[1], view.light[2]);
    light.shadow.mapSize.set(size, size);
    light.shadow.camera.near = diagonal * 1e-2;
    light.shadow.camera.far = diagonal * 2;
    scene.add(light);
    return light;
  });

  let bvh = null;
  const umbras = {};
  const pixel = new Uint8Array(4);
  const setup = {
    none: () => {},
    map1024: () => {},
    map2048: () => {},
    bvh: () => {
      bvh = bvhShadowMaterial(model, lights[1], { color: 0xcccccc, ambient: 0.25, offset: diagonal * 1e-5 });
    },
    ...Object.fromEntries(Object.entries(VARIANTS).map(([k, options]) => [k, async () => {
      const { UmbraShadows } = await import('umbra-three');
      umbras[k] = await UmbraShadows.create(renderer, options);
    }])),
  };
  const instance = (mode) => umbras[mode] ?? null;
  const draw = (mode) => {
    const map = mode === 'map1024' || mode === 'map2048';
    renderer.shadowMap.enabled = map;
    lights[0].visible = mode === 'map1024';
    lights[1].visible = mode !== 'map1024';
    lights[0].castShadow = mode === 'map1024';
    lights[1].castShadow = mode === 'map2048' || mode in VARIANTS;
    for (const o of meshes) o.material = variantMaterial[mode] ?? plain;
    scene.overrideMaterial = mode === 'bvh' ? bvh.material : null;
    if (mode === 'bvh') {
      scene.updateMatrixWorld();
      bvh.update();
    }
    if (instance(mode)) instance(mode).render(scene, camera);
    else renderer.render(scene, camera);
  };
  const timed = (mode) => {
    const t0 = performance.now();
    draw(mode);
    // Synchronise: a readPixels waits for the whole frame.
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, pixel);
    const ms = performance.now() - t0;
    const err = gl.getError();
    if (err !== gl.NO_ERROR) throw new Error(`${mode}: GL error 0x${err.toString(16)}`);
    if (instance(mode)?.errors.length) throw new Error(`umbra refused meshes: ${JSON.stringify(instance(mode).errors.slice(0, 3))}`);
    return ms;
  };
  bench.first = async (mode) => {
    if (!setup[mode]) throw new Error(`unknown mode ${mode}`);
    const t0 = performance.now();
    await setup[mode]();
    timed(mode);
    return performance.now() - t0;
  };
  bench.frame = (mode) => timed(mode);
  // One frame, split (run.mjs --webgpu): the main-thread ms of the row's render call (no GPU
  // sync inside the span), then the frame's ms until a 1-pixel readPixels returned.
  bench.split = (mode) => {
    const t0 = performance.now();
    draw(mode);
    const cpu = performance.now() - t0;
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, pixel);
    const frame = performance.now() - t0;
    const err = gl.getError();
    if (err !== gl.NO_ERROR) throw new Error(`${mode}: GL error 0x${err.toString(16)}`);
    if (instance(mode)?.errors.length) throw new Error(`umbra refused meshes: ${JSON.stringify(instance(mode).errors.slice(0, 3))}`);
    return { cpu, frame, umbraCpu: instance(mode) ? instance(mode).info.cpuMs : null };
  };
  bench.passes = (n, mode = 'umbra') => {
    const u = instance(mode);
    u.timing = true;
    const sum = {};
    try {
      for (let i = 0; i < n; i++) {
        timed(mode);
        for (const [k, v] of Object.entries(u.info.passes || {})) sum[k] = (sum[k] || 0) + v / n;
      }
    } finally {
      u.timing = false;
    }
    return { passes: sum, info: { ...u.info, passes: undefined } };
  };
  // Bytes on the GPU: three.js's own vertex and index buffers of the model (every attribute
  // array and index of its meshes' geometries, each geometry once), and each umbra row's
  // info.gpuBytes after its last frame.
  bench.memory = () => {
    const seen = new Set();
    let three = 0;
    for (const o of meshes) {
      const g = o.geometry;
      if (seen.has(g)) continue;
      seen.add(g);
      for (const a of Object.values(g.attributes)) three += a.array.byteLength;
      if (g.index) three += g.index.array.byteLength;
    }
    return { three, umbra: Object.fromEntries(Object.entries(umbras).map(([k, u]) => [k, u.info.gpuBytes])) };
  };
  // What the package's last frame drew (umbra.info without the pass times).
  bench.info = (mode = 'umbra') => ({ ...instance(mode).info, passes: undefined });
  // A view of a fly-through (run.mjs --flythrough): the camera moved, the light left in place.
  bench.view = (eye, target) => {
    camera.position.set(...eye);
    camera.lookAt(...target);
    camera.updateMatrixWorld();
  };
  // One frame of an orbit (run.mjs --orbit): the camera at angle 2 pi i / n around the view's
  // target (about the up axis, at the eye's distance and height), the light still or, with
  // moveLight, on a small circle around its place (diagonal / 100); returns the main-thread ms
  // of the row's render call (no GPU sync inside: what the page's script costs), then the
  // frame's ms until a readPixels returned (the GPU's work included), and umbra's info.cpuMs.
  const orbitUp = new THREE.Vector3(...view.up).normalize();
  const orbitTarget = new THREE.Vector3(...view.target);
  const orbitEye = new THREE.Vector3(...view.eye).sub(orbitTarget);
  bench.orbit = (mode, i, n, moveLight = false) => {
    const a = (2 * Math.PI * i) / n;
    camera.position.copy(orbitEye).applyAxisAngle(orbitUp, a).add(orbitTarget);
    camera.up.copy(orbitUp);
    camera.lookAt(orbitTarget);
    camera.updateMatrixWorld();
    const r = moveLight ? diagonal / 100 : 0;
    for (const l of lights) l.position.set(view.light[0] + r * Math.cos(a), view.light[1], view.light[2] + r * Math.sin(a));
    const t0 = performance.now();
    draw(mode);
    const cpu = performance.now() - t0;
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, pixel);
    const frame = performance.now() - t0;
    if (instance(mode)?.errors.length) throw new Error(`umbra refused meshes: ${JSON.stringify(instance(mode).errors.slice(0, 3))}`);
    const info = instance(mode)?.info;
    return { cpu, frame, umbraCpu: info ? info.cpuMs : null, parts: info ? info.cpu : null, reused: info ? info.reused : null, cached: info ? info.volumes.reduce((x, v) => x + v.cached, 0) : null };
  };
  // What a row draws, as a PNG data URL (run.mjs --shots): read in the frame's own task,
  // before the drawing buffer is presented and cleared.
  bench.shot = (mode) => {
    draw(mode);
    return canvas.toDataURL('image/png');
  };
  bench.ready = true;
  say(`${url}: ${triangles} triangles, ${width}x${height}, ${bench.renderer}`);
  document.body.dataset.state = 'ready';
}

start().catch((e) => {
  bench.error = String(e && e.stack ? `${e.message}\n${e.stack}` : e);
  say(`Error: ${bench.error}`);
  document.body.dataset.state = 'error';
});
