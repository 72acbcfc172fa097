// A glTF (or OBJ, PLY) model in a plain three.js app, with umbra-three's exact shadows from a
// PointLight and a DirectionalLight; the M key switches to three.js's own shadow maps and back.
//
// URL parameters (also the test hooks): model=URL (.gltf .glb .obj .ply, optionally .gz;
// default scene.gltf beside this page), size=WxH (fixed canvas size), mask=1 (show the first
// light's decision: white lit, black shadowed, as `umbra render`'s lit mask), eye=X,Y,Z,
// target=X,Y,Z, up=X,Y,Z, fov=DEGREES, light=X,Y,Z[,W] (W = 0: directional, coming from
// X,Y,Z), maps=1 (start with three.js's shadow maps), side=front (every material
// FrontSide, three.js's default: back faces culled, judged with `umbra verify --receivers
// front`; default: DoubleSide), mirror=1 (the model mirrored in x by its root's scale) and
// ortho=1 (start with the orthographic camera), zpass=0, cull=0 and silhouettes=gpu|wasm
// (WebGL 2: the package's options zpass: false, volumeCull: false and silhouettes, as the
// viewer's parameters), renderer=webgpu (three.js's WebGPURenderer
// and umbra-three/webgpu instead of WebGLRenderer and umbra-three; the import map in
// index.html follows it), method=ray-bvh (WebGPU only: the package's option `method`, shadow
// rays through a BVH instead of the volumes) and offscreen=1 (WebGPU only: every frame drawn into a RenderTarget
// and copied to the canvas through the CPU, for headless Chromium, which cannot present a
// WebGPU canvas).
// On WebGPU the orthographic camera (O, ortho=1) is refused with a warning and the view stays
// perspective, and skinned, morphed and batched meshes are named in umbra.errors (umbra's
// WebGPU path does not draw them yet); the warning box on the page says so.
// `scene=URL` is taken as `model=URL`
// (a model file: this page loads no `umbra export` folder). A model's animations (a skinned or
// morphed glTF) play through an AnimationMixer, every clip looping (animate=0: held at their
// first frame); instanced parts (EXT_mesh_gpu_instancing, InstancedMesh in three.js) cast per
// instance. Keys: M (three.js's maps and back), V (the mask view), L (a gizmo to drag the
// first light with), O (an orthographic camera and back: the same eye and target, the height
// the perspective view has at the target).
// The camera and the first light are the ones `umbra render --scene MODEL` uses with the same
// flags (view.js), so `umbra verify --external-mask` can judge the mask.
// State: document.body.dataset.state (loading, ready, error) and window.umbra: { state, error,
// frameMs, frames, backend ('webgl' or 'webgpu'), renderer (the GL renderer string, or the
// WebGPU adapter), subpixelBits (WebGL's SUBPIXEL_BITS; null on WebGPU, which reports none),
// warnings (what the page refused, also shown on the page), mode ('umbra' or 'maps'), projection ('perspective'
// or 'orthographic'), orthoHeight (the orthographic view's height, `umbra verify --ortho`),
// ortho (umbra.info.ortho: the orthographic frame's near and far planes, or null), view,
// animations (the
// model's clips), umbraInfo (casters, mapCasters, silhouettes, volumeCull, zpass, volumes, cpuMs, gpuBytes of
// umbra.info after the last frame; on WebGPU also backend, method, bvh, lights, triangles), light (the first light's position once dragged), errors (meshes
// umbra refused), readMask() (the first light's decision, rows top-down, 255 lit / 0
// shadowed, as a latin1 string; on WebGPU a Promise of it), readMaskAsync() (a Promise of it on
// both), readCanvas() (a frame drawn and its red channel read back the same way; on WebGPU a
// Promise, and only with offscreen=1), redraw() }.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { TransformControls } from 'three/addons/controls/TransformControls.js';
import { loadModel } from './load.js';
import { defaultView, triangleBounds, viewFor } from './view.js';

const params = new URLSearchParams(location.search);
const $ = (id) => document.getElementById(id);
const status = { state: 'loading', frames: 0, mode: 'umbra', warnings: [] };
window.umbra = status;
const backend = params.get('renderer') ?? 'webgl';
status.backend = backend;

/** A warning on the page and in window.umbra.warnings (once each). */
function warn(text) {
  if (status.warnings.includes(text)) return;
  status.warnings.push(text);
  showWarnings();
}

function showWarnings(extra = []) {
  const lines = [...status.warnings, ...extra];
  $('warning').textContent = lines.join('\n');
  $('warning').classList.toggle('shown', lines.length > 0);
}

function fail(e) {
  const text = `${e.name === 'ModelError' ? 'The model could not be loaded' : 'Error'}:\n${e.message}`;
  $('message').textContent = text;
  $('mode').textContent = '';
  $('time').textContent = '';
  status.state = 'error';
  status.error = text;
  document.body.dataset.state = 'error';
  console.error(text);
}

function canvasSize(canvas) {
  const size = params.get('size');
  if (!size) return [Math.max(320, window.innerWidth), Math.max(240, window.innerHeight - 40)];
  const m = /^(\d+)x(\d+)$/.exec(size);
  if (!m || !(Number(m[1]) >= 1 && Number(m[2]) >= 1 && Number(m[1]) <= 16384 && Number(m[2]) <= 16384)) throw new Error(`URL parameter size=${size}: expected WxH`);
  canvas.width = Number(m[1]);
  canvas.height = Number(m[2]);
  return [canvas.width, canvas.height];
}

/** The model's lights: the first from `light` (umbra's default light), a second of the other kind. */
function makeLights(view, bounds) {
  const c = bounds ? [0, 1, 2].map((i) => 0.5 * (bounds.min[i] + bounds.max[i])) : [0, 0, 0];
  const diagonal = bounds ? Math.hypot(...[0, 1, 2].map((i) => bounds.max[i] - bounds.min[i])) : 2;
  // A directional light from direction d: at d scaled by a power of two (exact, so the
  // direction position - target is d's own), the target at the origin, far enough out that
  // its shadow camera (for three.js's maps) sees the whole model.
  const directional = (d) => {
    const light = new THREE.DirectionalLight(0xffffff, 1.2);
    const reach = Math.hypot(...c) + diagonal;
    const scale = 2 ** Math.ceil(Math.log2(reach / Math.hypot(...d)));
    light.position.set(d[0] * scale, d[1] * scale, d[2] * scale);
    light.target.position.set(0, 0, 0);
    const s = light.shadow.camera;
    const half = Math.hypot(...c) + diagonal / 2;
    [s.left, s.right, s.top, s.bottom, s.near, s.far] = [-half, half, half, -half, 0, Math.hypot(...d) * scale + half];
    light.shadow.mapSize.set(2048, 2048);
    return light;
  };
  const point = (p) => {
    // No fall-off (decay 0): the model is lit evenly whatever its units.
    const light = new THREE.PointLight(0xffffff, 2.2, 0, 0);
    light.position.set(p[0], p[1], p[2]);
    light.shadow.camera.near = diagonal * 1e-3;
    light.shadow.camera.far = diagonal * 2;
    light.shadow.mapSize.set(2048, 2048);
    return light;
  };
  const first = view.light[3] === 0 ? directional(view.light) : point(view.light);
  // The second: from above and to the side, or, when the first is directional, a point light
  // where umbra's default light is.
  const second = view.light[3] === 0 ? point(defaultView(bounds).light) : directional([-0.45, 1, 0.6]);
  second.intensity *= 0.5;
  for (const l of [first, second]) l.castShadow = true;
  return [first, second];
}

/** A full-screen quad showing a mask (rows top-down, 255 lit) on the canvas. */
function maskView(width, height) {
  const texture = new THREE.DataTexture(new Uint8Array(width * height), width, height, THREE.RedFormat);
  const material = new THREE.ShaderMaterial({
    uniforms: { mask: { value: texture } },
    vertexShader: 'varying vec2 uv2; void main() { uv2 = uv; gl_Position = vec4(position.xy, 0.0, 1.0); }',
    // readMask's rows are top-down, texture rows bottom-up: flip v. Grey = red channel.
    fragmentShader: 'uniform sampler2D mask; varying vec2 uv2; void main() { gl_FragColor = vec4(vec3(texture2D(mask, vec2(uv2.x, 1.0 - uv2.y)).r), 1.0); }',
    depthTest: false,
    depthWrite: false,
  });
  const scene = new THREE.Scene();
  scene.add(new THREE.Mesh(new THREE.PlaneGeometry(2, 2), material));
  return { scene, camera: new THREE.Camera(), texture };
}

/** The same on WebGPU: a QuadMesh whose node material reads the mask (TSL). */
function maskViewWebGPU(width, height, tsl) {
  const texture = new THREE.DataTexture(new Uint8Array(width * height), width, height, THREE.RedFormat);
  texture.minFilter = THREE.NearestFilter;
  texture.magFilter = THREE.NearestFilter;
  const material = new THREE.MeshBasicNodeMaterial();
  // WebGPU's conventions (three.js's QuadMesh and texture rows): v = 0 is the top row, which is
  // readMask's first row, so no flip.
  const { texture: sample, uv, vec4 } = tsl;
  material.colorNode = vec4(sample(texture, uv()).rrr, 1);
  return { quad: new THREE.QuadMesh(material), texture };
}

async function start() {
  const canvas = $('canvas');
  const [width, height] = canvasSize(canvas);
  if (backend !== 'webgl' && backend !== 'webgpu') throw new Error(`URL parameter renderer=${backend}: expected webgl (the default) or webgpu`);
  const webgpu = backend === 'webgpu';
  const offscreen = webgpu && params.get('offscreen') === '1';
  // Antialias off: one sample per pixel, as `umbra render`'s mask; no stencil asked for (the
  // package brings its own depth-stencil target).
  let renderer;
  let umbra;
  let gl = null;
  let target = null;
  let tsl = null;
  if (webgpu) {
    if (!THREE.WebGPURenderer) throw new Error('renderer=webgpu: the import map did not load three.js\'s WebGPU build (three.webgpu.js)');
    tsl = await import('three/tsl');
    const { UmbraShadows } = await import('umbra-three/webgpu');
    // offscreen=1: the renderer draws into a RenderTarget and never touches #canvas, which
    // shows each frame through a 2D context.
    renderer = new THREE.WebGPURenderer(offscreen ? { antialias: false } : { canvas, antialias: false });
    renderer.setPixelRatio(1);
    renderer.setSize(width, height, false);
    // umbra-three/webgpu's decision reaches the materials as each light's shadow node, which
    // three.js builds only with its shadow map on.
    renderer.shadowMap.enabled = true;
    renderer.shadowMap.type = THREE.PCFShadowMap;
    try {
      // method=ray-bvh: the package's option `method` (shadow rays through a BVH instead of
      // the volumes); default cs-silhouette. cull=0: `volumeCull: false` (every volume whole).
      const options = params.get('method') ? { method: params.get('method') } : {};
      if (params.get('cull') === '0') options.volumeCull = false;
      umbra = await UmbraShadows.create(renderer, options);
    } catch (e) {
      throw new Error(`renderer=webgpu: ${e.message}\n(Without WebGPU, leave renderer out: the WebGL 2 path.)`);
    }
    const info = renderer.backend.device.adapterInfo || {};
    status.renderer = `WebGPU: ${[info.vendor, info.architecture, info.description].filter(Boolean).join(' ') || 'adapter'}`;
    status.subpixelBits = null;
    if (offscreen) {
      target = new THREE.RenderTarget(width, height);
      // The canvas's colour encoding, so the copy looks as a presented frame does.
      target.texture.colorSpace = THREE.SRGBColorSpace;
      renderer.setRenderTarget(target);
    }
  } else {
    const { UmbraShadows } = await import('umbra-three');
    renderer = new THREE.WebGLRenderer({ canvas, antialias: false });
    renderer.setPixelRatio(1);
    renderer.setSize(width, height, false);
    renderer.shadowMap.enabled = false;
    renderer.shadowMap.type = THREE.PCFShadowMap;
    gl = renderer.getContext();
    const dbg = gl.getExtension('WEBGL_debug_renderer_info');
    status.renderer = dbg ? gl.getParameter(dbg.UNMASKED_RENDERER_WEBGL) : gl.getParameter(gl.RENDERER);
    // The rasteriser's sub-pixel precision: `umbra verify --subpixel-bits` judges with it.
    status.subpixelBits = gl.getParameter(gl.SUBPIXEL_BITS);
    // zpass=0, cull=0, silhouettes=gpu|wasm: the package's options `zpass: false`,
    // `volumeCull: false` and `silhouettes` (the viewer's parameters), for the tests.
    if (params.get('method')) warn(`method=${params.get('method')}: the WebGL 2 path draws shadow volumes only; method is an option of renderer=webgpu`);
    umbra = await UmbraShadows.create(renderer, {
      zpass: params.get('zpass') !== '0',
      volumeCull: params.get('cull') === '0' ? false : 'auto',
      silhouettes: params.get('silhouettes') || 'auto',
    });
  }
  umbra.onError = (err) => console.warn(`umbra: ${err.mesh}: ${err.message}`);

  const url = params.get('model') || params.get('scene') || 'scene.gltf';
  const model = await loadModel(url);
  // mirror=1: the model mirrored in x by its root's scale (a world matrix of negative
  // determinant, where three.js turns glFrontFace to CW).
  if (params.get('mirror') === '1') model.scale.x = -model.scale.x;
  model.updateMatrixWorld(true);
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0x20242e);
  scene.add(model);
  let meshes = 0;
  let triangles = 0;
  model.traverse((o) => {
    if (!o.isMesh) return;
    meshes += 1;
    const g = o.geometry;
    triangles += Math.floor((g.index ? g.index.count : g.attributes.position?.count || 0) / 3);
    // Models without normals (positions only) are shaded flat.
    if (g.attributes.position && !g.attributes.normal) g.computeVertexNormals();
    o.castShadow = true;
    o.receiveShadow = true;
    // Both faces drawn (CAD and BIM models do not wind their faces consistently), or with
    // side=front the front faces only; umbra decides for the surface three.js shows either way.
    const side = params.get('side') === 'front' ? THREE.FrontSide : THREE.DoubleSide;
    for (const m of Array.isArray(o.material) ? o.material : [o.material]) m.side = side;
  });

  const bounds = triangleBounds(model);
  const view = viewFor(model, params);
  status.view = view;
  let camera = new THREE.PerspectiveCamera(view.fov, width / height, view.near, Math.max(view.near * 1e6, 1));
  camera.up.set(...view.up);
  // Orbit controls first: their constructor moves the camera (update()); the view set below
  // then stays exactly umbra's until the user drags.
  const controls = new OrbitControls(camera, canvas);
  camera.position.set(...view.eye);
  camera.lookAt(...view.target);
  camera.updateMatrixWorld(true);
  // O: an OrthographicCamera in its place (umbra-three closes every volume beyond the model's
  // box there), as tall as the perspective view is at the target, with its eye, target, up and
  // near plane; the orbit controls and the gizmo follow whichever is drawn.
  const perspective = camera;
  const orthographic = new THREE.OrthographicCamera(-1, 1, 1, -1, view.near, camera.far);
  orthographic.up.copy(camera.up);
  const useCamera = (ortho) => {
    if (ortho && webgpu) {
      warn('O / ortho=1: the orthographic camera is not drawn by umbra-three/webgpu yet (PerspectiveCamera only); the view stays perspective. The WebGL 2 path (no renderer=webgpu) has it.');
      return;
    }
    const from = ortho ? perspective : orthographic;
    const to = ortho ? orthographic : perspective;
    to.position.copy(from.position);
    to.quaternion.copy(from.quaternion);
    if (ortho) {
      const tall = 2 * perspective.position.distanceTo(controls.target) * Math.tan((perspective.fov * Math.PI) / 360);
      const aspect = width / height;
      Object.assign(orthographic, { left: -0.5 * tall * aspect, right: 0.5 * tall * aspect, top: 0.5 * tall, bottom: -0.5 * tall, zoom: 1 });
    }
    to.updateProjectionMatrix();
    to.updateMatrixWorld(true);
    camera = to;
    controls.object = to;
    gizmo.camera = to;
    status.projection = ortho ? 'orthographic' : 'perspective';
    status.orthoHeight = ortho ? (orthographic.top - orthographic.bottom) / orthographic.zoom : null;
  };
  status.projection = 'perspective';
  const lights = makeLights(view, bounds);
  scene.add(new THREE.HemisphereLight(0xc8d4ff, 0x403830, 0.35));
  for (const l of lights) {
    scene.add(l);
    if (l.isDirectionalLight) scene.add(l.target);
  }
  // On WebGPU, umbra's lights read umbra's decision as their shadow node, and three.js keeps a
  // light's shadow node once built: M switches to a twin of each light (no shadow node of
  // umbra's: three.js's own shadow map) instead, the other set hidden.
  const mapLights = webgpu ? lights.map((l) => {
    const twin = l.clone();
    if (l.isDirectionalLight) twin.target = l.target;
    twin.visible = false;
    scene.add(twin);
    return twin;
  }) : null;

  const state = { maps: params.get('maps') === '1', mask: params.get('mask') === '1' };
  // The model's animations, every clip looping; the frame loop runs while they play.
  const mixer = model.animations?.length ? new THREE.AnimationMixer(model) : null;
  if (mixer) for (const clip of model.animations) mixer.clipAction(clip).play();
  const animating = !!mixer && params.get('animate') !== '0';
  const clock = new THREE.Clock();
  status.animations = model.animations?.length ?? 0;
  // L: a gizmo on the first light (a point light: moved; a directional one: its position, so
  // its direction), drawn after umbra's frame in a scene of its own, so that umbra's depth pass
  // never sees it; orbiting pauses while it is dragged.
  const gizmo = new TransformControls(camera, canvas);
  const gizmoScene = new THREE.Scene();
  gizmoScene.add(gizmo.getHelper());
  gizmo.addEventListener('dragging-changed', (e) => {
    controls.enabled = !e.value;
  });
  gizmo.addEventListener('change', () => {
    status.light = lights[0].position.toArray();
    redraw();
  });
  state.gizmo = false;
  const mask = webgpu ? maskViewWebGPU(width, height, tsl) : maskView(width, height);
  const pixel = new Uint8Array(4);
  status.errors = umbra.errors;
  const latin1 = (m) => {
    let s = '';
    for (let i = 0; i < m.length; i += 8192) s += String.fromCharCode.apply(null, m.subarray(i, i + 8192));
    return s;
  };
  status.readMask = webgpu ? async () => latin1(await umbra.readMaskAsync(lights[0])) : () => latin1(umbra.readMask(lights[0]));
  status.readMaskAsync = async () => status.readMask();
  const label = () => {
    status.mode = state.maps ? 'maps' : 'umbra';
    $('mode').textContent = `${state.maps ? 'three.js shadow maps (2048)' : 'umbra: exact shadows'}${camera.isOrthographicCamera ? ' · orthographic' : ''}${webgpu ? ' · WebGPU' : ''}`;
    if (webgpu) showWarnings(umbra.errors.map((e) => `umbra-three/webgpu: ${e.mesh}: ${e.message}`));
    const refused = umbra.errors.length ? ` · ${umbra.errors.length} mesh(es) refused: ${umbra.errors.map((e) => `${e.mesh}: ${e.message}`).join('; ')}` : '';
    $('info').textContent = `${url}: ${meshes} meshes, ${triangles} triangles · ${status.renderer}${refused}`;
  };

  let pending = false;
  const frame = () => {
    pending = false;
    try {
      const t0 = performance.now();
      // The two modes: umbra's exact decision per light (three.js's maps off), or three.js's
      // own shadow maps (umbra off: umbra.render is then a plain renderer.render).
      renderer.shadowMap.enabled = state.maps;
      umbra.enabled = !state.maps;
      if (mixer) mixer.update(animating ? clock.getDelta() : 0);
      umbra.render(scene, camera);
      if (state.gizmo) {
        // The gizmo over the frame (its own scene: not in umbra's depth pass, not shadowed).
        renderer.autoClear = false;
        renderer.render(gizmoScene, camera);
        renderer.autoClear = true;
      }
      if (state.mask && !state.maps) {
        mask.texture.image.data.set(umbra.readMask(lights[0]));
        mask.texture.needsUpdate = true;
        renderer.render(mask.scene, mask.camera);
      }
      // Synchronise: a readPixels waits for the whole frame.
      gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, pixel);
      done(t0);
    } catch (e) {
      fail(e);
    }
  };
  const done = (t0) => {
    const ms = performance.now() - t0;
    status.frames += 1;
    status.frameMs = ms;
    label();
    $('time').textContent = `frame ${ms.toFixed(1)} ms${state.mask && !state.maps ? ' · mask' : ''}`;
    status.state = 'ready';
    status.ortho = umbra.info.ortho ?? null;
    status.umbraInfo = { casters: umbra.info.casters, mapCasters: umbra.info.mapCasters, silhouettes: umbra.info.silhouettes, volumeCull: umbra.info.volumeCull, zpass: umbra.info.zpass, volumes: umbra.info.volumes, cpuMs: umbra.info.cpuMs, gpuBytes: umbra.info.gpuBytes };
    if (webgpu) Object.assign(status.umbraInfo, { backend: umbra.info.backend, method: umbra.info.method, bvh: umbra.info.bvh, lights: umbra.info.lights, triangles: umbra.info.triangles, culled: umbra.info.culled });
    document.body.dataset.state = 'ready';
    if (animating) redraw();
  };
  // WebGPU: a frame awaits its reads (the mask view's mask, the offscreen copy), so frames are
  // chained, one at a time.
  const canvas2d = offscreen ? canvas.getContext('2d') : null;
  let running = Promise.resolve();
  const frameWebGPU = async () => {
    pending = false;
    try {
      const t0 = performance.now();
      // umbra's lights (umbra's shadow nodes) or their twins (three.js's shadow maps).
      umbra.enabled = !state.maps;
      lights.forEach((l, i) => {
        l.visible = !state.maps;
        mapLights[i].visible = state.maps;
        mapLights[i].position.copy(l.position);
      });
      if (mixer) mixer.update(animating ? clock.getDelta() : 0);
      umbra.render(scene, camera);
      if (state.gizmo) {
        renderer.autoClear = false;
        renderer.render(gizmoScene, camera);
        renderer.autoClear = true;
      }
      if (state.mask && !state.maps) {
        mask.texture.image.data.set(await umbra.readMaskAsync(lights[0]));
        mask.texture.needsUpdate = true;
        mask.quad.render(renderer);
      }
      if (offscreen) {
        const rgba = await renderer.readRenderTargetPixelsAsync(target, 0, 0, width, height);
        canvas2d.putImageData(new ImageData(new Uint8ClampedArray(rgba.buffer, rgba.byteOffset, rgba.byteLength), width, height), 0, 0);
      } else {
        await renderer.backend.device.queue.onSubmittedWorkDone();
      }
      done(t0);
    } catch (e) {
      fail(e);
    }
  };
  const runFrame = () => {
    running = running.then(frameWebGPU);
    return running;
  };
  const redraw = () => {
    if (!pending) {
      pending = true;
      requestAnimationFrame(webgpu ? runFrame : frame);
    }
  };
  status.redraw = redraw;
  // A frame drawn now and the canvas read back in the same task (before the drawing buffer is
  // presented): its red channel, rows top-down, as a latin1 string (the tests' view of mask=1).
  status.readCanvas = () => {
    if (webgpu) return readCanvasWebGPU();
    frame();
    const rgba = new Uint8Array(width * height * 4);
    gl.readPixels(0, 0, width, height, gl.RGBA, gl.UNSIGNED_BYTE, rgba);
    let s = '';
    for (let y = height - 1; y >= 0; y--) {
      const row = new Uint8Array(width);
      for (let x = 0; x < width; x++) row[x] = rgba[4 * (y * width + x)];
      s += String.fromCharCode.apply(null, row);
    }
    return s;
  };
  // WebGPU (offscreen=1): a frame drawn, then the canvas's red channel, rows top-down.
  const readCanvasWebGPU = async () => {
    if (!offscreen) throw new Error('readCanvas on WebGPU needs offscreen=1 (a WebGPU canvas cannot be read back)');
    await runFrame();
    const rgba = canvas2d.getImageData(0, 0, width, height).data;
    const red = new Uint8Array(width * height);
    for (let i = 0; i < red.length; i++) red[i] = rgba[4 * i];
    return latin1(red);
  };

  controls.target.set(...view.target);
  controls.addEventListener('change', redraw);
  if (params.get('ortho') === '1') useCamera(true);
  window.addEventListener('keydown', (e) => {
    if (e.key === 'm' || e.key === 'M') state.maps = !state.maps;
    else if (e.key === 'v' || e.key === 'V') state.mask = !state.mask;
    else if (e.key === 'o' || e.key === 'O') useCamera(!camera.isOrthographicCamera);
    else if (e.key === 'l' || e.key === 'L') {
      state.gizmo = !state.gizmo;
      if (state.gizmo) gizmo.attach(lights[0]);
      else gizmo.detach();
    } else return;
    e.preventDefault();
    redraw();
  });
  redraw();
}

start().catch(fail);
