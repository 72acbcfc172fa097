// The umbra WebGL 2 viewer: loads a scene written by `umbra export`, draws it with
// paper 003's vertex-shader silhouette shadow volumes (renderer.js), and lets the user orbit
// the camera (drag, wheel), move the light (shift + drag, arrows, PageUp/PageDown), switch
// shadows off (S) and show the shadow mask (M). The frame time is measured as paper 003 did
// without timer queries: performance.now() around a frame made synchronous by a readPixels.
//
// URL parameters (also the test hooks): scene=DIR (the export, default "scene/"), size=WxH
// (fixed canvas size), mask=1, shadows=0, light=X,Y,Z[,W], eye=X,Y,Z, target=X,Y,Z, and
// clamp=0 (no EXT_depth_clamp even when offered), depth=standard (the drawing buffer's fixed
// point depth even when the browser offers EXT_clip_control for reversed-Z; renderer.js), snap=N
// (diagnostic: every vertex on a 1/N-pixel grid, glsl/snap.glsl), and nowebgl=1 / nostencil=1 (simulate a browser without WebGL 2 or without a stencil buffer).
// The page's state is in document.body.dataset.state: loading, ready, error; on error the
// message is shown on the page (never a blank page) and in window.umbra.error.
import { loadScene, SceneError, sceneName } from './scene.js';
import { Renderer, GlSetupError } from './renderer.js';
import { clipFromWorld, sub, normalize, cross } from './math.js';

const params = new URLSearchParams(location.search);
const $ = (id) => document.getElementById(id);
const status = { state: 'loading', frames: 0 };
window.umbra = status;

function fail(e) {
  const kind = e instanceof SceneError ? 'The scene files are missing or malformed' : e instanceof GlSetupError ? 'WebGL 2 set-up failed' : 'Error';
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
  // stencil: shadow volumes count in it; antialias off: one sample per pixel, as the native
  // frame; preserveDrawingBuffer: the frame can be read back (tests, the timing readPixels).
  const gl = params.get('nowebgl') === '1' ? null : canvas.getContext('webgl2', {
    stencil: params.get('nostencil') !== '1',
    depth: true,
    antialias: false,
    preserveDrawingBuffer: true,
    alpha: false,
  });
  if (!gl) throw new GlSetupError('this browser has no WebGL 2 (canvas.getContext("webgl2") returned null). Enable hardware acceleration or use a browser with WebGL 2.');

  const base = new URL(params.get('scene') || 'scene/', location.href);
  if (!base.pathname.endsWith('/')) base.pathname += '/';
  const scene = await loadScene(base.toString());
  const m = scene.manifest;
  // nostencil=1 simulates a browser without stencil: no stencil in the drawing buffer, which
  // the standard-depth path draws into (the reversed-Z path has its own depth-stencil).
  const renderer = new Renderer(gl, scene, {
    standardDepth: params.get('depth') === 'standard' || params.get('nostencil') === '1',
    noDepthClamp: params.get('clamp') === '0',
  });
  status.renderer = renderer.rendererName;
  status.depthClamp = !!renderer.depthClamp;
  // The rasterizer's sub-pixel precision, which the oracle's band needs to judge this
  // browser's mask (`umbra verify --subpixel-bits`): 4 on SwiftShader and on ANGLE/llvmpipe
  // (which really snaps to 1/256 pixel but reports the ES 3.0 minimum).
  status.subpixelBits = gl.getParameter(gl.SUBPIXEL_BITS);
  status.depth = renderer.reversedZ ? 'reversed-z' : 'standard';
  // The scene's file name, not its path (`umbra export` records the spec it was given, which
  // for a mesh file is wherever it lay on the exporting machine).
  status.sceneName = sceneName(m.scene);
  document.title = `${status.sceneName} · umbra`;
  $('info').textContent = `${status.sceneName}: ${m.counts.triangles} triangles, ${m.counts.sides_data_records} edge records, maxMult ${m.max_mult} · ${status.depth} depth · ${renderer.rendererName}`;

  const cam = { ...m.camera, eye: vec('eye', 3) || m.camera.eye, target: vec('target', 3) || m.camera.target };
  let light = vec('light', 4) || m.light;
  // snap=N: the diagnostic of glsl/snap.glsl (vertices on a 1/N-pixel grid); 0 = off.
  const snap = Number(params.get('snap') || 0);
  if (!(Number.isInteger(snap) && snap >= 0)) throw new Error(`URL parameter snap=${params.get('snap')}: expected a whole number of positions per pixel`);
  const view = { shadows: params.get('shadows') !== '0', mask: params.get('mask') === '1' };
  $('shadows').checked = view.shadows;
  $('mask').checked = view.mask;
  const ext = [0, 1, 2].map((k) => m.bounds.max[k] - m.bounds.min[k]);
  const step = 0.02 * Math.hypot(...ext);

  let pending = false;
  const pixel = new Uint8Array(4);
  const frame = () => {
    pending = false;
    const t0 = performance.now();
    renderer.draw({
      clipFromWorld: clipFromWorld(cam, canvas.width / canvas.height, renderer.reversedZ),
      eye: cam.eye,
      light,
      shadows: view.shadows,
      mask: view.mask,
      snap,
      width: canvas.width,
      height: canvas.height,
    });
    // Synchronise: a readPixels waits for the whole frame (paper 003's timing).
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, pixel);
    const ms = performance.now() - t0;
    const err = gl.getError();
    if (err !== gl.NO_ERROR) return fail(new GlSetupError(`GL error 0x${err.toString(16)} during the frame`));
    status.frames += 1;
    status.frameMs = ms;
    status.state = 'ready';
    document.body.dataset.state = 'ready';
    $('time').textContent = `frame ${ms.toFixed(1)} ms${view.shadows ? '' : ' (no shadows)'}${view.mask ? ' · mask' : ''}`;
  };
  const redraw = () => {
    if (!pending) {
      pending = true;
      requestAnimationFrame(frame);
    }
  };
  status.redraw = redraw;

  // Orbit camera around the target; shift-drag moves the light in the image plane.
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
    const f = normalize(sub(cam.target, cam.eye));
    const right = normalize(cross(f, cam.up));
    const up = cross(right, f);
    if (drag.shift) {
      const s = step * 0.25;
      light = [0, 1, 2].map((k) => light[k] + s * (dx * right[k] - dy * up[k])).concat([light[3]]);
    } else {
      const off = sub(cam.eye, cam.target);
      const r = Math.hypot(...off);
      let yaw = Math.atan2(off[0], off[2]) - dx * 0.005;
      let pitch = Math.asin(Math.max(-1, Math.min(1, off[1] / r))) + dy * 0.005;
      pitch = Math.max(-1.5, Math.min(1.5, pitch));
      cam.eye = [cam.target[0] + r * Math.cos(pitch) * Math.sin(yaw), cam.target[1] + r * Math.sin(pitch), cam.target[2] + r * Math.cos(pitch) * Math.cos(yaw)];
    }
    redraw();
  });
  canvas.addEventListener('wheel', (e) => {
    e.preventDefault();
    const off = sub(cam.eye, cam.target);
    const k = Math.exp(Math.sign(e.deltaY) * 0.1);
    if (Math.hypot(...off) * k > 4 * cam.near) cam.eye = [0, 1, 2].map((i) => cam.target[i] + off[i] * k);
    redraw();
  }, { passive: false });
  window.addEventListener('keydown', (e) => {
    const moves = { ArrowLeft: [-1, 0, 0], ArrowRight: [1, 0, 0], ArrowUp: [0, 0, -1], ArrowDown: [0, 0, 1], PageUp: [0, 1, 0], PageDown: [0, -1, 0] };
    if (moves[e.key]) {
      light = [0, 1, 2].map((k) => light[k] + step * moves[e.key][k]).concat([light[3]]);
    } else if (e.key === 's' || e.key === 'S') {
      view.shadows = !view.shadows;
      $('shadows').checked = view.shadows;
    } else if (e.key === 'm' || e.key === 'M') {
      view.mask = !view.mask;
      $('mask').checked = view.mask;
    } else {
      return;
    }
    e.preventDefault();
    redraw();
  });
  $('shadows').addEventListener('change', (e) => { view.shadows = e.target.checked; redraw(); });
  $('mask').addEventListener('change', (e) => { view.mask = e.target.checked; redraw(); });
  redraw();
}

start().catch(fail);
