// UmbraShadows for three.js's WebGPURenderer (`umbra-three/webgpu`): exact shadows from
// umbra's compute-shader silhouettes (native cs-silhouette, umbra-wgpu's WGSL) on the
// renderer's own GPUDevice. Each frame, in place of renderer.render(scene, camera):
//   1. the scene's shadow-casting lights and drawn meshes are gathered; each caster's
//      topology is prepared once per geometry version (topology.js, wasm), and the frame's
//      triangles are moved to world space and merged (world.js) when a mesh, its matrix or
//      its geometry changed;
//   2. webgpu/passes.js draws umbra's depth pass and, per light, the silhouettes and the
//      z-fail count into umbra's own depth-stencil target, and the decision into the light's
//      mask (a three.js RenderTarget, r8unorm, 255 lit / 0 shadowed); with the option
//      `method: 'ray-bvh'`, each visible sample's shadow ray through a BVH of the casters
//      instead (webgpu/rays.js);
//   3. renderer.render(scene, camera): each light's shadow is its shadow node
//      (light.shadow.shadowNode, set here), which reads the mask at the fragment's pixel, so
//      every lit node material and a user's TSL receive umbra's decision.
// Nothing thrown inside render(): a refused mesh or light is an entry in `errors` (and
// onError), and three.js draws the frame all the same.
import { Matrix4, NearestFilter, RedFormat, RenderTarget, UnsignedByteType, Vector2, Vector3 } from 'three/webgpu';
import { screenUV, texture } from 'three/tsl';
import { Topology, TopologyError, meshName, positionArray } from '../topology.js';
import { gatherLights } from '../lights.js';
import { infinitePerspectiveReversedZ, mul, nearPyramidPoints, transformPoints } from '../camera.js';
import { UnionCache, zpassStart } from '../zpass.js';
import { CULL_SIDE, WebGPUVolumes } from './passes.js';
import { WebGPURays } from './rays.js';
import { reportOnce } from '../report.js';
import { casterRecords, mergeParts, worldPositions } from './world.js';

/** Whether an object's world matrix is affine (its fourth row 0 0 0 1). */
function affine(e) {
  return e[3] === 0 && e[7] === 0 && e[11] === 0 && e[15] === 1;
}

/** A geometry's index as Uint32Array (or 0 .. count-1 without one), checked against its vertex count. */
function indicesOf(geometry, vertices, name) {
  const index = geometry.index;
  if (!index) {
    const n = vertices - (vertices % 3);
    const out = new Uint32Array(n);
    for (let i = 0; i < n; i++) out[i] = i;
    return out;
  }
  const n = index.count - (index.count % 3);
  const out = new Uint32Array(n);
  for (let i = 0; i < n; i++) {
    const v = index.getX(i);
    if (!(v >= 0 && v < vertices)) throw new TopologyError(`${name}: index ${i} is ${v}, but the geometry has ${vertices} vertices`);
    out[i] = v;
  }
  return out;
}

/** The methods of this path, by their native `--method` names. */
export const METHODS = ['cs-silhouette', 'ray-bvh'];

/** options.method checked (default 'cs-silhouette'); throws naming the valid ones. */
function methodOf(options) {
  const method = options.method ?? 'cs-silhouette';
  if (!METHODS.includes(method)) throw new Error(`umbra-three/webgpu: unknown method '${method}' (expected ${METHODS.map((m) => `'${m}'`).join(' or ')})`);
  return method;
}

/** Whether every value is finite. */
function finite(a) {
  for (let i = 0; i < a.length; i++) if (!Number.isFinite(a[i])) return false;
  return true;
}

export class UmbraShadows {
  /**
   * Prepares umbra for `renderer` (a three.js WebGPURenderer): awaits its init, loads the
   * wasm (options.wasm: a URL, Response, bytes or Module of umbra_wasm.wasm; default beside
   * this module). Throws when the renderer runs on its WebGL 2 backend (no WebGPU adapter:
   * use `UmbraShadows` of 'umbra-three' with a WebGLRenderer there) or its GPUDevice lacks a
   * feature the passes need.
   */
  static async create(renderer, options = {}) {
    if (!renderer?.isWebGPURenderer) throw new Error('umbra-three/webgpu: expected a three.js WebGPURenderer (from three/webgpu); for a WebGLRenderer use UmbraShadows from \'umbra-three\'');
    await renderer.init();
    if (!renderer.backend?.isWebGPUBackend || !renderer.backend.device) {
      throw new Error('umbra-three/webgpu: the WebGPURenderer runs on its WebGL 2 backend (this browser gave no WebGPU adapter); umbra\'s WebGPU path needs compute shaders. Use a WebGLRenderer and UmbraShadows from \'umbra-three\' there');
    }
    methodOf(options);
    const topology = await Topology.load(options.wasm);
    return new UmbraShadows(renderer, topology, options);
  }

  constructor(renderer, topology, options = {}) {
    this.renderer = renderer;
    this.topology = topology;
    this.options = options;
    const device = renderer.backend.device;
    // depth32float-stencil8: the depth precision the band is computed for (f32 depth).
    const depthFormat = device.features.has('depth32float-stencil8') ? 'depth32float-stencil8' : 'depth24plus-stencil8';
    try {
      this.volumes = new WebGPUVolumes(device, depthFormat);
    } catch (e) {
      throw new Error(`umbra-three/webgpu: WebGPU set-up failed: ${e.message}`);
    }
    const method = methodOf(options);
    if (method === 'ray-bvh') this.volumes.rays = new WebGPURays(this.volumes, topology.geom);
    if (![undefined, true, false].includes(options.volumeCull)) throw new Error(`umbra-three/webgpu: volumeCull must be true or false, got ${JSON.stringify(options.volumeCull)}`);
    // The GPU cull (passes.js): on by default; not with ray-bvh, which draws no volumes.
    this.volumeCull = method !== 'ray-bvh' && options.volumeCull !== false;
    this.receivers = []; // per light slot, its receiver grid in the wasm (the cull's uniform)
    this.enabled = true;
    this.disposed = false;
    this.errors = [];
    this.onError = null;
    this.reported = new Set();
    this.prepared = new WeakMap(); // geometry -> { key, caster: {positions, indices, records, slots} | receiver: {...} | error }
    this.parts = new Map(); // mesh uuid + instance -> { key, part }
    this.lastKey = null;
    this.masks = new Map(); // light -> { target: RenderTarget, node }
    this.casters = new Set(); // the wasm's caster handles of the prepared geometries (their z-pass tests)
    this.unions = new UnionCache(topology.geom); // z-pass tests of casters sharing a world matrix
    this.info = {
      backend: 'webgpu', method, silhouettes: method === 'ray-bvh' ? null : 'compute', bvh: null, lights: 0, casters: 0, triangles: 0, casterTriangles: 0, records: 0,
      zpass: [], volumeCull: this.volumeCull, culled: [], prepareMs: 0, cpuMs: 0, gpuBytes: 0, depthFormat,
    };
  }

  /** The depth-stencil format of umbra's depth pass. */
  get depthFormat() {
    return this.volumes.depthFormat;
  }

  report(object, message) {
    reportOnce(this, object, message);
  }

  /** The shadow node of `light`: its mask read at the fragment's pixel (1 lit, 0 shadowed). */
  maskOf(light, width, height) {
    let m = this.masks.get(light);
    if (!m) {
      const target = new RenderTarget(width, height, { format: RedFormat, type: UnsignedByteType, depthBuffer: false, generateMipmaps: false, minFilter: NearestFilter, magFilter: NearestFilter });
      // The decision of the pixel being shaded: screenUV is the fragment's pixel centre over the
      // frame's size, which is the mask's, so nearest filtering reads exactly its texel.
      const node = texture(target.texture, screenUV).r;
      m = { target, node, width, height };
      this.masks.set(light, m);
      light.shadow.shadowNode = node;
    } else if (m.width !== width || m.height !== height) {
      m.target.setSize(width, height);
      m.width = width;
      m.height = height;
    }
    this.renderer.initRenderTarget(m.target);
    return m;
  }

  /** The prepared data of a mesh's geometry (caster or not), cached per geometry version; throws TopologyError. */
  prepare(mesh, geometry, caster) {
    const pos = geometry.attributes.position;
    const key = `${caster}:${pos?.version}:${pos?.count}:${geometry.index?.version}:${geometry.index?.count}`;
    const cached = this.prepared.get(geometry);
    if (cached && cached.key === key) {
      if (cached.error) throw cached.error;
      return cached;
    }
    if (cached?.caster) {
      this.casters.delete(cached.caster);
      cached.caster.free();
    }
    const name = meshName(mesh);
    let entry;
    try {
      if (!pos || !pos.count) throw new TopologyError(`${name}: the geometry has no position attribute`);
      if (caster) {
        const t0 = performance.now();
        const p = this.topology.prepare(geometry, name);
        const { records, slots } = casterRecords(p.recordVertices, p.edgeTriangles, p.maxMult);
        // The caster handle stays for its z-pass test (zpass.js), freed with this entry.
        entry = { key, positions: p.positions, indices: p.indices, records, slots, caster: p.caster, uuid: geometry.uuid };
        this.casters.add(p.caster);
        this.info.prepareMs += performance.now() - t0;
      } else {
        const positions = positionArray(pos);
        if (!finite(positions)) throw new TopologyError(`${name}: a position is not finite`);
        entry = { key, positions, indices: indicesOf(geometry, pos.count, name) };
      }
    } catch (e) {
      if (!(e instanceof TopologyError)) throw e;
      this.prepared.set(geometry, { key, error: e });
      throw e;
    }
    this.prepared.set(geometry, entry);
    return entry;
  }

  /** The frame's world-space parts, casters first, and the key that says whether they changed. */
  gather(scene, camera) {
    const casters = [];
    const others = [];
    const keys = [];
    // Per caster instance: its handle and world matrix, for the z-pass test (zpassOf).
    const tests = [];
    scene.traverseVisible((o) => {
      if (!o.isMesh || !o.layers.test(camera.layers)) return;
      const name = meshName(o);
      if (o.isBatchedMesh || o.isSkinnedMesh || o.morphTargetInfluences?.some((w) => w !== 0)) {
        this.report(name, `${o.isBatchedMesh ? 'BatchedMesh' : o.isSkinnedMesh ? 'SkinnedMesh' : 'a morphed mesh'}: not drawn by umbra's WebGPU path yet; it casts no umbra shadow and is not in umbra's depth pass`);
        return;
      }
      const matrices = [];
      if (o.isInstancedMesh) {
        const m = new o.matrixWorld.constructor();
        for (let i = 0; i < o.count; i++) matrices.push(o.getMatrixAt(i, m).premultiply(o.matrixWorld).elements.slice());
      } else {
        matrices.push(o.matrixWorld.elements);
      }
      let data;
      try {
        data = this.prepare(o, o.geometry, !!o.castShadow);
      } catch (e) {
        this.report(name, e.message);
        return;
      }
      matrices.forEach((e, i) => {
        if (!affine(e)) {
          this.report(name, 'a projective world matrix: umbra closes volumes in world space; the mesh is left out');
          return;
        }
        const key = `${o.uuid}:${i}`;
        const partKey = `${data.key}|${Array.prototype.join.call(e, ',')}|${o.castShadow}`;
        let p = this.parts.get(key);
        if (!p || p.key !== partKey || p.data !== data) {
          const part = { positions: worldPositions(data.positions, e), indices: data.indices };
          if (data.records) {
            part.records = data.records;
            part.slots = data.slots;
          }
          p = { key: partKey, data, part };
          this.parts.set(key, p);
        }
        p.frame = this.frame;
        keys.push(key, partKey);
        if (data.caster) tests.push({ caster: data.caster, world: e, key: `${data.uuid}/${data.key}` });
        (data.records ? casters : others).push(p.part);
      });
    });
    for (const [k, p] of this.parts) if (p.frame !== this.frame) this.parts.delete(k);
    return { parts: [...casters, ...others], key: keys.join(';'), casters: casters.length, tests };
  }

  /** Draws `scene` from `camera` with umbra's shadows (or plainly when umbra cannot). */
  render(scene, camera) {
    const t0 = performance.now();
    this.frame = (this.frame ?? 0) + 1;
    let drawn = false;
    try {
      if (this.enabled && !this.disposed) drawn = this.drawShadows(scene, camera);
    } catch (e) {
      this.report(camera.name || camera.uuid, `the frame failed: ${e.message}`);
    }
    // A frame umbra did not draw (disabled, refused or failed) is shaded unshadowed: a light's
    // shadow node stays in three.js's built materials, so its mask is cleared to lit rather
    // than left with an older frame's decisions.
    if (!drawn && !this.disposed) this.clearMasks();
    this.info.cpuMs = performance.now() - t0;
    this.renderer.render(scene, camera);
  }

  /** Every light's mask cleared to lit (255). */
  clearMasks() {
    const views = [];
    for (const m of this.masks.values()) {
      const t = this.renderer.backend.get(m.target.texture).texture;
      if (t) views.push(t.createView());
    }
    if (views.length) this.volumes.clearMasks(views);
  }

  /**
   * Light `light`'s mask as a three.js Texture (r8unorm, the frame's size; 1 lit, 0 shadowed;
   * sample it at `screenUV` with nearest filtering), or null before the light cast a shadow:
   * what its shadow node reads, for a user's own TSL (a debug view, another effect).
   */
  maskTexture(light) {
    return this.masks.get(light)?.target.texture ?? null;
  }

  drawShadows(scene, camera) {
    if (!camera.isPerspectiveCamera) {
      this.report(camera.name || camera.uuid, `${camera.type}: umbra's WebGPU path draws shadows for a PerspectiveCamera only; the frame is drawn without them`);
      return false;
    }
    if (scene.matrixWorldAutoUpdate === true) scene.updateMatrixWorld();
    if (camera.parent === null && camera.matrixWorldAutoUpdate === true) camera.updateMatrixWorld();
    const target = this.renderer.getRenderTarget();
    const size = target ? new Vector2(target.width, target.height) : this.renderer.getDrawingBufferSize(new Vector2());
    const lights = gatherLights(scene, camera).filter((l) => l.castShadow && (l.isPointLight || l.isSpotLight || l.isDirectionalLight));
    const { parts, key, casters, tests } = this.gather(scene, camera);
    if (key !== this.lastKey) {
      const merged = mergeParts(parts);
      this.volumes.setScene(merged);
      if (this.volumes.rays) {
        this.volumes.rays.setScene(merged);
        this.info.bvh = { ...this.volumes.rays.figures };
      }
      this.lastKey = key;
      this.info.triangles = merged.triangles;
      this.info.casterTriangles = merged.casterTriangles;
      this.info.records = merged.records.length / 4;
    }
    this.volumes.setSize(size.x, size.y);
    const lightWorld = lights.map((l) => {
      const p = new Vector3().setFromMatrixPosition(l.matrixWorld);
      if (!l.isDirectionalLight) return [p.x, p.y, p.z, 1];
      // Directional: w = 0, xyz towards the light (from its target to its position).
      const t = new Vector3().setFromMatrixPosition(l.target.matrixWorld);
      return [p.x - t.x, p.y - t.y, p.z - t.z, 0];
    });
    const masks = lights.map((l) => this.maskOf(l, size.x, size.y));
    const views = masks.map((m) => this.renderer.backend.get(m.target.texture).texture.createView());
    // umbra's camera: the camera's fov, aspect and near, an infinite far plane, reversed-Z
    // (WebGPU's depth range is [0, 1]: depth near / d, exactly 0 at infinity).
    const projection = infinitePerspectiveReversedZ(camera.getEffectiveFOV(), camera.aspect, camera.near);
    const clipFromWorldF64 = mul(projection, camera.matrixWorldInverse.elements);
    const clipFromWorld = new Float32Array(clipFromWorldF64);
    const zpass = this.volumes.rays ? lights.map(() => null) : this.zpassOf(clipFromWorldF64, camera, lightWorld, tests);
    const cull = this.cullOf(clipFromWorldF64, camera, lightWorld, zpass);
    this.volumes.draw(clipFromWorld, lightWorld, views, zpass, cull);
    this.info.lights = lights.length;
    this.info.casters = casters;
    this.info.zpass = zpass.map((z) => z !== null);
    this.info.culled = cull.map((c) => c !== null);
    this.info.gpuBytes = this.volumes.gpuBytes + masks.reduce((a, m) => a + m.width * m.height, 0);
    return true;
  }

  /**
   * Per light, the eye's count W0 when z-pass is proven for it, else null (z-fail): the eye's
   * near pyramid (umbra's own camera: reversed-Z, infinite far plane) tested against every
   * caster instance in its own space, and against the union of those that share a world matrix
   * where one alone cannot answer (zpass.js). Refused (z-fail) with options.zpass false, and
   * for every light when an instance's world matrix is projective. A mirroring matrix needs
   * nothing more: a point's count is the number of triangles between it and the light (each
   * triangle's volume is turned by its orientation towards the light), which an affine map
   * keeps, though this path builds its volumes from the world-space triangles.
   */
  zpassOf(clipFromWorld, camera, lightWorld, tests) {
    const none = lightWorld.map(() => null);
    if (this.options.zpass === false || tests.length === 0) {
      this.unions.prune(this.frame);
      return none;
    }
    const eye = new Vector3().setFromMatrixPosition(camera.matrixWorld);
    const worldFromClip = new Matrix4().fromArray(clipFromWorld).invert().elements;
    const pyramid = nearPyramidPoints(worldFromClip, [eye.x, eye.y, eye.z], true);
    const inverse = new Matrix4();
    const asked = tests.map((t) => {
      const w = t.world;
      const m = inverse.fromArray(w);
      const det = m.determinant();
      const usable = affine(w) && det !== 0 && Number.isFinite(det);
      const e = m.invert().elements;
      const toObject = (v) => new Float32Array([0, 1, 2, 3].map((r) => e[r] * v[0] + e[4 + r] * v[1] + e[8 + r] * v[2] + e[12 + r] * v[3]));
      return {
        caster: t.caster, key: t.key, group: Array.prototype.join.call(w, ','),
        points: usable ? transformPoints(e, pyramid) : null, lights: lightWorld.map(toObject),
      };
    });
    const zpass = lightWorld.map((_, k) => zpassStart(asked, k, (group) => this.unions.of(group, this.frame)));
    this.unions.prune(this.frame);
    return zpass;
  }

  /**
   * Per light, the GPU cull's uniform (the wasm's gpuCull over the box of every drawn position;
   * under z-pass the eye's near pyramid raised into the map), or null where the light is drawn
   * whole: `volumeCull` off, no caster, or a z-pass light whose near pyramid no one face of a
   * point light's map bounds (docs/exactness.md, "Volumes culled on the GPU").
   */
  cullOf(clipFromWorld, camera, lightWorld, zpass) {
    const s = this.volumes.scene;
    const none = lightWorld.map(() => null);
    if (!this.volumeCull || !s || !s.triangles || !s.bounds || !finite(s.bounds)) return none;
    let pyramid = null;
    if (zpass.some((z) => z !== null)) {
      const eye = new Vector3().setFromMatrixPosition(camera.matrixWorld);
      const worldFromClip = new Matrix4().fromArray(clipFromWorld).invert().elements;
      pyramid = nearPyramidPoints(worldFromClip, [eye.x, eye.y, eye.z], true);
    }
    const box = Float32Array.from(s.bounds);
    while (this.receivers.length < lightWorld.length) this.receivers.push(this.topology.geom.receivers());
    return lightWorld.map((l, k) => {
      const r = this.receivers[k];
      if (!r.setGrid(Float32Array.from(l), box, CULL_SIDE)) return null;
      return r.gpuCull(zpass[k] !== null ? pyramid : null);
    });
  }

  /**
   * What each light's volumes drew in the last frame (in the order of info.culled), read back
   * from the GPU: [{ culled, triangles, edges }], the caster triangles kept (all when not
   * culled) and the side quads drawn; [] with ray-bvh.
   */
  async readVolumesAsync() {
    return this.volumes.readVolumes();
  }

  /** Light `light`'s decision of the last frame: rows top-down, 255 lit / 0 shadowed (Uint8Array). */
  async readMaskAsync(light) {
    const m = this.masks.get(light);
    if (!m) throw new Error('umbra-three/webgpu: readMaskAsync: that light has no mask (it did not cast a shadow in the last frame)');
    return this.volumes.readMask(this.renderer.backend.get(m.target.texture).texture);
  }

  dispose() {
    if (this.disposed) return;
    this.disposed = true;
    for (const [light, m] of this.masks) {
      if (light.shadow.shadowNode === m.node) light.shadow.shadowNode = undefined;
      m.target.dispose();
    }
    this.masks.clear();
    this.unions.clear();
    for (const c of this.casters) c.free();
    this.casters.clear();
    for (const r of this.receivers) r.free();
    this.receivers = [];
    this.volumes.dispose();
  }
}
