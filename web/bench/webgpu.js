// The WebGPU benchmark page (bench/run.mjs --webgpu drives it; never a test): one model drawn
// by three.js's WebGPURenderer the ways a three.js user can draw it, frame by frame on request:
//   gpunone      WebGPURenderer, no shadows (the point light, castShadow off)
//   gpumap2048   PointLight.castShadow, shadow.mapSize 2048 (three.js's point shadow map)
//   gpudir2048   DirectionalLight.castShadow, shadow.mapSize 2048, its shadow camera around
//                the model (examples/gltf/main.js's directional light)
//   gpuumbra     umbra-three/webgpu (UmbraShadows of 'umbra-three/webgpu'), the point light
//   gpuumbradir  the same with the directional light
//   gpuumbra and gpuumbradir draw the package's defaults: volumes culled on the GPU
//   gpunocull    umbra-three/webgpu with volumeCull: false (every volume whole), the point light
//   gpunoculldir the same with the directional light
//   gpuzfail     umbra-three/webgpu with zpass: false (every light z-fail), the point light
//   gpurays      umbra-three/webgpu with method 'ray-bvh' (shadow rays through a BVH), the point light
//   gpuraysdir   the same with the directional light
// Every mesh gets a MeshLambertNodeMaterial, both faces drawn, as bench.js. The camera and the
// point light are `umbra render`'s defaults for the file (examples/gltf/view.js); the
// directional light comes from (-0.45, 1, 0.6), the glTF example's second light. Each row has
// its own light object (only the row's own is visible), so that no row's light carries
// another's shadow node or map. three.js draws into a RenderTarget of the page's size: headless
// Chromium cannot present a WebGPU canvas.
//
// Query: model=URL (.obj .gltf .glb .ply, optionally .gz), size=WxH.
// window.bench: { ready, error, triangles, renderer (the adapter), features,
//   first(mode) -> ms (set-up and first frame, to the queue's onSubmittedWorkDone),
//   frame(mode) -> { gpu, cpu, umbraCpu }: gpu = ms from the render call to
//     device.queue.onSubmittedWorkDone() (the queue was idle before it), cpu = ms of the render
//     call itself (umbra.render or renderer.render, no wait inside), umbraCpu = umbra.info.cpuMs,
//   passes(mode) -> { gpu, passes: [{ label, ms }] }: one more frame with a timestamp query
//     around every render and compute pass that frame encodes (umbra's and three.js's), from
//     outside (the device's createCommandEncoder wrapped for that frame),
//   info(mode), memory(), view(eye, target), shot(mode) -> PNG data URL }.
import * as THREE from 'three/webgpu';
import { loadModel } from '../examples/gltf/load.js';
import { viewFor, triangleBounds } from '../examples/gltf/view.js';

const params = new URLSearchParams(location.search);
const bench = { ready: false, error: null };
window.bench = bench;
const say = (t) => {
  document.getElementById('status').textContent = t;
};

export const ROWS = ['gpunone', 'gpumap2048', 'gpudir2048', 'gpuumbra', 'gpuumbradir', 'gpunocull', 'gpunoculldir', 'gpuzfail', 'gpurays', 'gpuraysdir'];

async function start() {
  if (!navigator.gpu) throw new Error('no navigator.gpu: this browser has no WebGPU (flags: testlib/exactness.mjs IMPLEMENTATIONS.webgpu, a http://127.0.0.1 page)');
  const m = /^(\d+)x(\d+)$/.exec(params.get('size') || '640x360');
  if (!m) throw new Error(`URL parameter size=${params.get('size')}: expected WxH`);
  const [width, height] = [Number(m[1]), Number(m[2])];
  const renderer = new THREE.WebGPURenderer({ antialias: false });
  renderer.setPixelRatio(1);
  renderer.setSize(width, height, false);
  renderer.shadowMap.enabled = true;
  renderer.shadowMap.type = THREE.PCFShadowMap;
  await renderer.init();
  if (!renderer.backend.isWebGPUBackend) throw new Error('the WebGPURenderer fell back to WebGL 2: no WebGPU adapter');
  const device = renderer.backend.device;
  const adapterInfo = renderer.backend.adapter?.info ?? device.adapterInfo;
  bench.renderer = adapterInfo ? `WebGPU: ${adapterInfo.vendor} ${adapterInfo.architecture} ${adapterInfo.description || ''}`.trim() : 'WebGPU';
  bench.features = [...device.features];
  const target = new THREE.RenderTarget(width, height);
  renderer.setRenderTarget(target);

  const url = params.get('model');
  if (!url) throw new Error('URL parameter model= is required');
  let t = performance.now();
  const model = await loadModel(url);
  model.updateMatrixWorld(true);
  bench.loadMs = performance.now() - t;
  const plain = new THREE.MeshLambertNodeMaterial({ color: 0xcccccc, side: THREE.DoubleSide });
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
  if (view.light[3] !== 1) throw new Error('the benchmark\'s first light is a point light: light= needs W = 1');
  const b = triangleBounds(model);
  const diagonal = b ? Math.hypot(...[0, 1, 2].map((i) => b.max[i] - b.min[i])) : 2;
  const centre = b ? [0, 1, 2].map((i) => 0.5 * (b.min[i] + b.max[i])) : [0, 0, 0];
  const camera = new THREE.PerspectiveCamera(view.fov, width / height, view.near, diagonal * 4);
  camera.up.set(...view.up);
  camera.position.set(...view.eye);
  camera.lookAt(...view.target);

  const point = (shadow) => {
    const light = new THREE.PointLight(0xffffff, 2.5, 0, 0);
    light.position.set(view.light[0], view.light[1], view.light[2]);
    light.castShadow = shadow;
    light.shadow.mapSize.set(2048, 2048);
    light.shadow.camera.near = diagonal * 1e-2;
    light.shadow.camera.far = diagonal * 2;
    return light;
  };
  // examples/gltf/main.js's directional light: from d, at d scaled by a power of two, the
  // target at the origin, its shadow camera around the whole model.
  const direction = [-0.45, 1, 0.6];
  const directional = () => {
    const light = new THREE.DirectionalLight(0xffffff, 1.2);
    const reach = Math.hypot(...centre) + diagonal;
    const scale = 2 ** Math.ceil(Math.log2(reach / Math.hypot(...direction)));
    light.position.set(direction[0] * scale, direction[1] * scale, direction[2] * scale);
    light.target.position.set(0, 0, 0);
    const s = light.shadow.camera;
    const half = Math.hypot(...centre) + diagonal / 2;
    [s.left, s.right, s.top, s.bottom, s.near, s.far] = [-half, half, half, -half, 0, Math.hypot(...direction) * scale + half];
    light.shadow.mapSize.set(2048, 2048);
    light.castShadow = true;
    return light;
  };
  const lights = { gpunone: point(false), gpumap2048: point(true), gpudir2048: directional(), gpuumbra: point(true), gpuumbradir: directional(), gpunocull: point(true), gpunoculldir: directional(), gpuzfail: point(true), gpurays: point(true), gpuraysdir: directional() };
  for (const l of Object.values(lights)) {
    scene.add(l);
    if (l.isDirectionalLight) scene.add(l.target);
  }
  scene.updateMatrixWorld(true);

  const umbras = {};
  const setup = {
    gpunone: () => {},
    gpumap2048: () => {},
    gpudir2048: () => {},
    gpuumbra: async () => {
      const { UmbraShadows } = await import('umbra-three/webgpu');
      umbras.gpuumbra = await UmbraShadows.create(renderer);
    },
    gpuumbradir: async () => {
      const { UmbraShadows } = await import('umbra-three/webgpu');
      umbras.gpuumbradir = await UmbraShadows.create(renderer);
    },
    gpunocull: async () => {
      const { UmbraShadows } = await import('umbra-three/webgpu');
      umbras.gpunocull = await UmbraShadows.create(renderer, { volumeCull: false });
    },
    gpunoculldir: async () => {
      const { UmbraShadows } = await import('umbra-three/webgpu');
      umbras.gpunoculldir = await UmbraShadows.create(renderer, { volumeCull: false });
    },
    gpuzfail: async () => {
      const { UmbraShadows } = await import('umbra-three/webgpu');
      umbras.gpuzfail = await UmbraShadows.create(renderer, { zpass: false });
    },
    gpurays: async () => {
      const { UmbraShadows } = await import('umbra-three/webgpu');
      umbras.gpurays = await UmbraShadows.create(renderer, { method: 'ray-bvh' });
    },
    gpuraysdir: async () => {
      const { UmbraShadows } = await import('umbra-three/webgpu');
      umbras.gpuraysdir = await UmbraShadows.create(renderer, { method: 'ray-bvh' });
    },
  };
  const draw = (mode) => {
    for (const [k, l] of Object.entries(lights)) l.visible = k === mode;
    if (umbras[mode]) umbras[mode].render(scene, camera);
    else renderer.render(scene, camera);
  };
  const check = (mode) => {
    if (umbras[mode]?.errors.length) throw new Error(`${mode}: umbra refused meshes: ${JSON.stringify(umbras[mode].errors.slice(0, 3))}`);
  };
  const idle = () => device.queue.onSubmittedWorkDone();
  const timed = async (mode) => {
    await idle();
    const t0 = performance.now();
    draw(mode);
    const cpu = performance.now() - t0;
    await idle();
    const gpu = performance.now() - t0;
    check(mode);
    return { gpu, cpu, umbraCpu: umbras[mode] ? umbras[mode].info.cpuMs : null };
  };
  bench.first = async (mode) => {
    if (!setup[mode]) throw new Error(`unknown mode ${mode}`);
    await idle();
    const t0 = performance.now();
    await setup[mode]();
    draw(mode);
    await idle();
    check(mode);
    return performance.now() - t0;
  };
  bench.frame = (mode) => timed(mode);

  // Pass timing from outside: for one frame, every render and compute pass of every command
  // encoder made on the device gets timestamp writes (begin, end) into one query set.
  const QUERIES = 256;
  const timestamps = device.features.has('timestamp-query');
  const querySet = timestamps ? device.createQuerySet({ type: 'timestamp', count: QUERIES }) : null;
  const resolved = timestamps ? device.createBuffer({ size: 8 * QUERIES, usage: GPUBufferUsage.QUERY_RESOLVE | GPUBufferUsage.COPY_SRC }) : null;
  const createCommandEncoder = device.createCommandEncoder.bind(device);
  let probe = null;
  device.createCommandEncoder = (descriptor) => {
    const encoder = createCommandEncoder(descriptor);
    if (!probe) return encoder;
    for (const kind of ['beginRenderPass', 'beginComputePass']) {
      const begin = encoder[kind].bind(encoder);
      encoder[kind] = (d = {}) => {
        if (d.timestampWrites || 2 * probe.labels.length + 2 > QUERIES) return begin(d);
        const i = probe.labels.length;
        probe.labels.push(d.label || `${descriptor?.label || 'encoder'} ${kind === 'beginRenderPass' ? 'render' : 'compute'} pass`);
        return begin({ ...d, timestampWrites: { querySet, beginningOfPassWriteIndex: 2 * i, endOfPassWriteIndex: 2 * i + 1 } });
      };
    }
    return encoder;
  };
  bench.passes = async (mode) => {
    if (!timestamps) return { gpu: null, passes: [], note: 'the device has no timestamp-query' };
    await idle();
    probe = { labels: [] };
    let labels;
    const t0 = performance.now();
    try {
      draw(mode);
    } finally {
      labels = probe.labels;
      probe = null;
    }
    await idle();
    const gpu = performance.now() - t0;
    const n = 2 * labels.length;
    if (!n) return { gpu, passes: [] };
    const read = device.createBuffer({ size: 8 * n, usage: GPUBufferUsage.COPY_DST | GPUBufferUsage.MAP_READ });
    const encoder = createCommandEncoder({ label: 'bench timestamps' });
    encoder.resolveQuerySet(querySet, 0, n, resolved, 0);
    encoder.copyBufferToBuffer(resolved, 0, read, 0, 8 * n);
    device.queue.submit([encoder.finish()]);
    await read.mapAsync(GPUMapMode.READ);
    const ns = new BigInt64Array(read.getMappedRange().slice(0));
    read.unmap();
    read.destroy();
    const t = (k) => Number(ns[k]) / 1e6;
    const first = t(0);
    return { gpu, passes: labels.map((label, i) => ({ label, ms: t(2 * i + 1) - t(2 * i), at: t(2 * i) - first })) };
  };
  // Bytes on the GPU: three.js's own vertex and index buffers of the model, and each umbra
  // row's info.gpuBytes after its last frame.
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
  bench.info = async (mode) => ({ ...umbras[mode].info, volumes: await umbras[mode].readVolumesAsync() });
  bench.view = (eye, target) => {
    camera.position.set(...eye);
    camera.lookAt(...target);
    camera.updateMatrixWorld();
  };
  // What a row draws, as a PNG data URL (run.mjs --shots): the render target read back.
  bench.shot = async (mode) => {
    draw(mode);
    const px = await renderer.readRenderTargetPixelsAsync(target, 0, 0, width, height);
    const canvas = document.createElement('canvas');
    canvas.width = width;
    canvas.height = height;
    const ctx = canvas.getContext('2d');
    const image = ctx.createImageData(width, height);
    image.data.set(px.subarray(0, 4 * width * height));
    for (let i = 3; i < image.data.length; i += 4) image.data[i] = 255;
    ctx.putImageData(image, 0, 0);
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
