// The umbra viewer, an example of the umbra-three package: a three.js scene (MeshLambertMaterial,
// an ambient light and a PointLight or DirectionalLight with castShadow) drawn with
// UmbraShadows, whose exact shadow decision replaces a shadow map. It loads a scene written
// by `umbra export` (scene=DIR: its positions and indices into a BufferGeometry) or a model
// file through three.js's loaders (model=URL: OBJ, .obj.gz, glTF/GLB); the user orbits the
// camera (drag, wheel), moves the light (shift + drag, arrows, PageUp/PageDown), switches
// shadows off (S) and shows the shadow mask (M). The frame time is measured as paper 003 did
// without timer queries: performance.now() around a frame made synchronous by a readPixels.
//
// URL parameters (also the test hooks): scene=DIR (an export, default "scene/"), model=URL,
// size=WxH (fixed canvas size), mask=1, shadows=0, light=X,Y,Z[,W] (W = 0: directional),
// light2=X,Y,Z[,W] (a second shadowed light), eye=X,Y,Z, target=X,Y,Z, up=X,Y,Z, fov=DEG,
// near=D, offset=X,Y,Z (the model's world translation; the camera and light stay in world
// space), antialias=1, timing=1 (umbra.info.passes: each pass waited for), and the diagnostics clamp=0 (no EXT_depth_clamp), depth=standard (no
// reversed-Z even when EXT_clip_control is offered), snap=N (every vertex on a 1/N-pixel grid),
// zpass=0 (every light counted z-fail; umbra.info().zpass says which count each light got),
// cull=0 (volumeCull off: every volume to infinity; umbra.info().volumes says what each light drew),
// silhouettes=gpu|wasm (where the unculled silhouettes are computed; umbra.info().silhouettes),
// nowebgl=1 / nostencil=1 (a browser without WebGL 2 / a canvas without a stencil buffer).
// The page's state is in document.body.dataset.state: loading, ready, error; on error the
// message is shown on the page (never a blank page) and in window.umbra.error.
// window.umbra: { state, error, frameMs, renderer, subpixelBits, frames, depth, info, view,
// errors, redraw(), readMask(k) (light k's decision as a latin1 string, rows top-down) }.
import * as THREE from 'three';
import { OBJLoader } from 'three/examples/jsm/loaders/OBJLoader.js';
import { GLTFLoader } from 'three/examples/jsm/loaders/GLTFLoader.js';
import { UmbraShadows } from '../umbra-three/src/index.js';
import { loadScene, SceneError, sceneName } from './scene.js';
import { defaultView } from '../examples/gltf/view.js';

const params = new URLSearchParams(location.search);
const $ = (id) => document.getElementById(id);
const status = { state: 'loading', frames: 0 };
window.umbra = status;

class SetupError extends Error {}

function fail(e) {
  const kind = e instanceof SceneError ? 'The scene files are missing or malformed' : e instanceof SetupError ? 'WebGL 2 set-up failed' : 'Error';
  const text = `${kind}:\n${e.message}`;
  $('message').textContent = text;
  $('time').textContent = '';
  status.state = 'error';
  status.error = text;
  document.body.dataset.state = 'error';
  console.error(text);
}

function vec(name, n) {
  const s = params.get(name);
  if (s === null) return null;
  const v = s.split(',').map(Number);
  if (!(v.length === n || (n === 4 && v.length === 3)) || !v.every(Number.isFinite)) throw new Error(`URL parameter ${name}=${s}: expected ${n} comma-separated numbers`);
  return n === 4 && v.length === 3 ? [...v, 1] : v;
}

function num(name) {
  const s = params.get(name);
  if (s === null) return null;
  const v = Number(s);
  if (!Number.isFinite(v) || v <= 0) throw new Error(`URL parameter ${name}=${s}: expected a positive number`);
  return v;
}

/** A model file through three.js's loaders: its meshes' geometries in file order. */
async function loadModel(url) {
  const r = await fetch(url);
  if (!r.ok) throw new SceneError(url, '', `HTTP ${r.status}`);
  const path = new URL(url, location.href).pathname.toLowerCase();
  let object;
  if (/\.(gltf|glb)$/.test(path)) {
    object = (await new GLTFLoader().parseAsync(await r.arrayBuffer(), new URL('.', new URL(url, location.href)).href)).scene;
  } else if (/\.obj(\.gz)?$/.test(path)) {
    let body = r.body;
    if (path.endsWith('.gz')) body = body.pipeThrough(new DecompressionStream('gzip'));
    object = new OBJLoader().parse(await new Response(body).text());
  } else {
    throw new SceneError(url, '', 'expected .obj, .obj.gz, .gltf or .glb');
  }
  object.updateMatrixWorld(true);
  const geometries = [];
  object.traverse((o) => {
    if (!o.isMesh) return;
    // World space of the file (glTF node transforms), as umbra's own loader flattens it.
    const g = o.geometry.clone();
    g.applyMatrix4(o.matrixWorld);
    g.name = o.name;
    geometries.push(g);
  });
  return geometries;
}

async function start() {
  const canvas = $('canvas');
  const size = params.get('size');
  if (size) {
    const m = /^(\d+)x(\d+)$/.exec(size);
    if (!m) throw new Error(`URL parameter size=${size}: expected WxH`);
    canvas.width = Number(m[1]);
    canvas.height = Number(m[2]);
  } else {
    canvas.width = Math.max(320, window.innerWidth);
    canvas.height = Math.max(240, window.innerHeight - 40);
  }
  if (params.get('nowebgl') === '1') throw new SetupError('this browser has no WebGL 2 (canvas.getContext("webgl2") returned null). Enable hardware acceleration or use a browser with WebGL 2.');
  // stencil / antialias as a user would pick them: umbra draws into its own targets.
  // preserveDrawingBuffer: the frame can be read back (tests, the timing readPixels).
  let renderer;
  try {
    renderer = new THREE.WebGLRenderer({ canvas, stencil: params.get('nostencil') !== '1', antialias: params.get('antialias') === '1', preserveDrawingBuffer: true });
  } catch (e) {
    throw new SetupError(`this browser has no WebGL 2 (${e.message}). Enable hardware acceleration or use a browser with WebGL 2.`);
  }
  renderer.setPixelRatio(1);
  renderer.setSize(canvas.width, canvas.height, false);
  // umbra's native colours as they are (FrameParams::default()): linear output, no sRGB encoding.
  renderer.outputColorSpace = THREE.LinearSRGBColorSpace;
  renderer.setClearColor(new THREE.Color(0.1, 0.12, 0.16));
  const snap = Number(params.get('snap') || 0);
  if (!(Number.isInteger(snap) && snap >= 0)) throw new Error(`URL parameter snap=${params.get('snap')}: expected a whole number of positions per pixel`);
  let umbra;
  try {
    umbra = await UmbraShadows.create(renderer, { depth: params.get('depth') === 'standard' ? 'standard' : 'reversed', depthClamp: params.get('clamp') !== '0', snap, zpass: params.get('zpass') !== '0', volumeCull: params.get('cull') !== '0', volumeClamp: params.get('volumeclamp') || 'auto', receiverScatter: params.get('scatter') || 'auto', positionPass: params.get('positions') || 'equal', silhouettes: params.get('silhouettes') || 'auto' });
  } catch (e) {
    throw new SetupError(e.message);
  }
  status.renderer = umbra.rendererName;
  // The rasterizer's sub-pixel precision, which the oracle's band needs to judge this
  // browser's mask (`umbra verify --subpixel-bits`): 4 on SwiftShader and on ANGLE/llvmpipe.
  status.subpixelBits = umbra.subpixelBits;
  status.depth = umbra.depth;
  status.depthClamp = params.get('clamp') !== '0';
  status.errors = umbra.errors;
  umbra.timing = params.get('timing') === '1';

  // The scene: an export or a model file, as BufferGeometries.
  let geometries;
  let view;
  let name;
  let counts;
  const model = params.get('model');
  if (model) {
    geometries = await loadModel(model);
    name = sceneName(new URL(model, location.href).pathname);
    const box = new THREE.Box3();
    for (const g of geometries) {
      g.computeBoundingBox();
      box.union(g.boundingBox);
    }
    // umbra render's default view for the file, in its own arithmetic (the glTF example's
    // view.js, tested against `umbra export` bit for bit).
    const { fov, ...framing } = defaultView(box.isEmpty() ? null : { min: box.min.toArray(), max: box.max.toArray() });
    view = { ...framing, fov_y_degrees: fov };
    counts = `${geometries.reduce((n, g) => n + (g.index ? g.index.count : g.attributes.position.count) / 3, 0)} triangles, ${geometries.length} meshes`;
  } else {
    const base = new URL(params.get('scene') || 'scene/', location.href);
    if (!base.pathname.endsWith('/')) base.pathname += '/';
    const scene = await loadScene(base.toString());
    const m = scene.manifest;
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.BufferAttribute(scene.positions, 3));
    g.setIndex(new THREE.BufferAttribute(scene.indices, 1));
    geometries = [g];
    // The scene's file name, not its path (`umbra export` records the spec it was given).
    name = sceneName(m.scene);
    view = { ...m.camera, light: m.light };
    counts = `${m.counts.triangles} triangles, ${m.counts.sides_data_records} edge records, maxMult ${m.max_mult}`;
  }
  status.sceneName = name;
  document.title = `${name} · umbra`;

  const scene = new THREE.Scene();
  // Two-sided Lambert, umbra's albedo 0.8 and ambient 0.15 (FrameParams::default()).
  const material = new THREE.MeshLambertMaterial({ color: new THREE.Color(0.8, 0.8, 0.8), side: THREE.DoubleSide });
  const offset = vec('offset', 3) || [0, 0, 0];
  for (const g of geometries) {
    const mesh = new THREE.Mesh(g, material);
    mesh.name = g.name || name;
    mesh.castShadow = true;
    mesh.receiveShadow = true;
    mesh.position.fromArray(offset);
    scene.add(mesh);
  }
  // Ambient 0.15 of the albedo: three.js's Lambert divides irradiance by pi.
  scene.add(new THREE.AmbientLight(0xffffff, 0.15 * Math.PI));
  const makeLight = (l) => {
    // decay 0: light that does not fall off, as umbra's native shading; intensity pi cancels
    // three.js's Lambert 1/pi.
    const light = l[3] === 0 ? new THREE.DirectionalLight(0xffffff, Math.PI) : new THREE.PointLight(0xffffff, Math.PI, 0, 0);
    light.castShadow = true;
    scene.add(light);
    if (light.isDirectionalLight) scene.add(light.target);
    return light;
  };
  const place = (light, l) => {
    if (light.isDirectionalLight) {
      light.position.set(l[0], l[1], l[2]);
      light.target.position.set(0, 0, 0);
    } else {
      light.position.set(l[0], l[1], l[2]);
    }
  };
  let lightVec = vec('light', 4) || view.light;
  const lights = [makeLight(lightVec)];
  const second = vec('light2', 4);
  if (second) lights.push(makeLight(second));
  place(lights[0], lightVec);
  if (second) place(lights[1], second);

  const cam = { eye: vec('eye', 3) || view.eye, target: vec('target', 3) || view.target, up: vec('up', 3) || view.up };
  const fov = num('fov') || view.fov_y_degrees;
  const near = num('near') || view.near;
  const camera = new THREE.PerspectiveCamera(fov, canvas.width / canvas.height, near, near * 1e7);
  const placeCamera = () => {
    camera.position.fromArray(cam.eye);
    camera.up.fromArray(cam.up);
    camera.lookAt(...cam.target);
    camera.updateMatrixWorld();
  };
  placeCamera();
  // The camera as placed (eye, target, up), for tools that orbit from it (bench-zpass.mjs).
  status.view = () => ({ eye: [...cam.eye], target: [...cam.target], up: [...cam.up] });

  // The mask view: light 0's decision (white lit, black shadowed) over the whole canvas.
  const maskScene = new THREE.Scene();
  const maskMaterial = new THREE.ShaderMaterial({
    uniforms: { u_mask: { value: null }, u_channel: { value: new THREE.Vector4(1, 0, 0, 0) } },
    vertexShader: 'void main() { gl_Position = vec4(position.xy, 0.0, 1.0); }',
    fragmentShader: 'uniform highp sampler2D u_mask; uniform vec4 u_channel; void main() { float lit = dot(texelFetch(u_mask, ivec2(gl_FragCoord.xy), 0), u_channel); gl_FragColor = vec4(vec3(lit), 1.0); }',
    depthTest: false,
    depthWrite: false,
  });
  maskScene.add(new THREE.Mesh(new THREE.PlaneGeometry(2, 2), maskMaterial));
  const maskCamera = new THREE.OrthographicCamera();

  const viewState = { shadows: params.get('shadows') !== '0', mask: params.get('mask') === '1' };
  $('shadows').checked = viewState.shadows;
  $('mask').checked = viewState.mask;
  const box = new THREE.Box3();
  for (const g of geometries) {
    g.computeBoundingBox();
    box.union(g.boundingBox);
  }
  const step = 0.02 * box.getSize(new THREE.Vector3()).length();
  const gl = renderer.getContext();
  $('info').textContent = `${name}: ${counts} · ${umbra.depth} depth · ${umbra.rendererName}`;

  status.readMask = (k = 0) => {
    const m = umbra.readMask(lights[k]);
    if (!m) return null;
    let s = '';
    for (let i = 0; i < m.length; i += 8192) s += String.fromCharCode.apply(null, m.subarray(i, i + 8192));
    return s;
  };
  status.info = () => ({ ...umbra.info });

  let pending = false;
  const pixel = new Uint8Array(4);
  const frame = () => {
    pending = false;
    const t0 = performance.now();
    umbra.enabled = viewState.shadows || viewState.mask;
    umbra.render(scene, camera);
    if (viewState.mask) {
      maskMaterial.uniforms.u_mask.value = umbra.maskTexture(lights[0]);
      maskMaterial.uniforms.u_channel.value.set(...[0, 1, 2, 3].map((c) => (c === umbra.maskChannel(lights[0]) ? 1 : 0)));
      renderer.render(maskScene, maskCamera);
    }
    // Synchronise: a readPixels waits for the whole frame (paper 003's timing).
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, pixel);
    const ms = performance.now() - t0;
    const err = gl.getError();
    if (err !== gl.NO_ERROR) return fail(new SetupError(`GL error 0x${err.toString(16)} during the frame`));
    if (umbra.errors.length && (viewState.shadows || viewState.mask)) console.warn(`umbra: ${umbra.errors.map((e) => `${e.mesh}: ${e.message}`).join('; ')}`);
    status.frames += 1;
    status.frameMs = ms;
    status.state = 'ready';
    document.body.dataset.state = 'ready';
    $('time').textContent = `frame ${ms.toFixed(1)} ms${viewState.shadows ? '' : ' (no shadows)'}${viewState.mask ? ' · mask' : ''}`;
  };
  const redraw = () => {
    if (!pending) {
      pending = true;
      requestAnimationFrame(frame);
    }
  };
  status.redraw = redraw;

  // Orbit camera around the target; shift-drag moves the light in the image plane.
  const moveLight = (d) => {
    lightVec = [0, 1, 2].map((k) => lightVec[k] + d[k]).concat([lightVec[3]]);
    place(lights[0], lightVec);
  };
  let drag = null;
  canvas.addEventListener('pointerdown', (e) => {
    drag = { x: e.clientX, y: e.clientY, shift: e.shiftKey };
    canvas.setPointerCapture(e.pointerId);
  });
  canvas.addEventListener('pointerup', () => { drag = null; });
  canvas.addEventListener('pointermove', (e) => {
    if (!drag) return;
    const dx = e.clientX - drag.x;
    const dy = e.clientY - drag.y;
    drag.x = e.clientX;
    drag.y = e.clientY;
    const f = new THREE.Vector3().fromArray(cam.target).sub(new THREE.Vector3().fromArray(cam.eye)).normalize();
    const right = new THREE.Vector3().crossVectors(f, new THREE.Vector3().fromArray(cam.up)).normalize();
    const up = new THREE.Vector3().crossVectors(right, f);
    if (drag.shift) {
      const s = step * 0.25;
      moveLight([0, 1, 2].map((k) => s * (dx * right.getComponent(k) - dy * up.getComponent(k))));
    } else {
      const off = [0, 1, 2].map((k) => cam.eye[k] - cam.target[k]);
      const r = Math.hypot(...off);
      const yaw = Math.atan2(off[0], off[2]) - dx * 0.005;
      let pitch = Math.asin(Math.max(-1, Math.min(1, off[1] / r))) + dy * 0.005;
      pitch = Math.max(-1.5, Math.min(1.5, pitch));
      cam.eye = [cam.target[0] + r * Math.cos(pitch) * Math.sin(yaw), cam.target[1] + r * Math.sin(pitch), cam.target[2] + r * Math.cos(pitch) * Math.cos(yaw)];
      placeCamera();
    }
    redraw();
  });
  canvas.addEventListener('wheel', (e) => {
    e.preventDefault();
    const off = [0, 1, 2].map((k) => cam.eye[k] - cam.target[k]);
    const k = Math.exp(Math.sign(e.deltaY) * 0.1);
    if (Math.hypot(...off) * k > 4 * near) cam.eye = [0, 1, 2].map((i) => cam.target[i] + off[i] * k);
    placeCamera();
    redraw();
  }, { passive: false });
  window.addEventListener('keydown', (e) => {
    const moves = { ArrowLeft: [-1, 0, 0], ArrowRight: [1, 0, 0], ArrowUp: [0, 0, -1], ArrowDown: [0, 0, 1], PageUp: [0, 1, 0], PageDown: [0, -1, 0] };
    if (moves[e.key]) {
      moveLight(moves[e.key].map((x) => x * step));
    } else if (e.key === 's' || e.key === 'S') {
      viewState.shadows = !viewState.shadows;
      $('shadows').checked = viewState.shadows;
    } else if (e.key === 'm' || e.key === 'M') {
      viewState.mask = !viewState.mask;
      $('mask').checked = viewState.mask;
    } else {
      return;
    }
    e.preventDefault();
    redraw();
  });
  $('shadows').addEventListener('change', (e) => { viewState.shadows = e.target.checked; redraw(); });
  $('mask').addEventListener('change', (e) => { viewState.mask = e.target.checked; redraw(); });
  redraw();
}

start().catch(fail);
