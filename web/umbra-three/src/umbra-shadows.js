// UmbraShadows: exact shadows for a three.js WebGLRenderer. Each frame, in place of
// renderer.render(scene, camera):
//   1. the scene's lights, casters and receivers are gathered (lights.js replays three.js's
//      light order), casters prepared once per geometry version (topology.js, wasm);
//   2. per light, each caster's z-pass test (in the wasm, topology.js: the eye's near pyramid
//      and the light in the caster's own space) picks the count: z-pass from sum(W0) when
//      every caster answers, z-fail otherwise; the WebGL 2 drawer (webgl/drawer.js) draws
//      every light's decision into umbra's own mask target from each caster's silhouette
//      (also computed in the wasm), on umbra's own depth pass (umbra's camera convention:
//      reversed-Z, infinite far plane; the camera's fov, aspect and near);
//   3. renderer.resetState(), then renderer.render(scene, camera) with the patched materials
//      (materials.js) reading the decision of their pixel.
// With `volumeCull` (default 'auto': on a software rasteriser), step 2 draws only the volumes something visible receives:
// per light a receiver map of the frame's visible samples (the drawer's position pass and
// scatter, read back), against which the wasm culls and clamps each caster's volume
// (crates/umbra-wasm/src/cull.rs; umbra_geom::receivers), in world space; z-pass first raises
// the eye's near pyramid into the map, and a light whose map cannot bound it is drawn unculled.
// Nothing thrown inside render(): a refused mesh or a failed frame is an entry in `errors`
// (and onError), and the frame is drawn by three.js all the same.
import { ExternalTexture, Matrix4, Vector2, Vector3 } from 'three';
import { Topology, TopologyError, flatTriangles, geometryPositions, meshName, positionArray } from './topology.js';
import { gatherLights, lightSlots } from './lights.js';
import { reportOnce } from './report.js';
import { createUniforms, patchMaterial } from './materials.js';
import { WebGLDrawer, MAX_LIGHTS } from './webgl/drawer.js';
import { sidesOf, culledCapRanges, weldedTriangleCounts } from './sides.js';
import { infiniteProjection, orthographicProjection, clipFromObject, mul, nearPyramidPoints, transformPoints } from './camera.js';
import { UnionCache, zpassStart } from './zpass.js';

const CHANNEL_SELECT = [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]];

/**
 * Whether a mesh's material discards fragments by their alpha (three.js's alphaTest, with or
 * without an alphaMap, or alphaHash): its shadow is not its triangles'. Any of a mesh's
 * materials does it for the whole mesh.
 */
function alphaTested(mesh) {
  const materials = Array.isArray(mesh.material) ? mesh.material : [mesh.material];
  return materials.some((m) => m && (m.alphaTest > 0 || m.alphaHash === true));
}

/** Instances of an InstancedMesh or BatchedMesh that keep their own silhouettes (`cache`); the others' are computed every frame. */
const INSTANCE_SLOTS = 16;

/** Cells along a side of a light's receiver map (crates/umbra-wasm/src/cull.rs PAGE_RECEIVER_SIDE). */
const RECEIVER_SIDE = 128;

/**
 * What drawing one more polygon (a far cap: a point through the polygon pass, its fan's 18
 * vertices) costs against one pixel of volume fill, in the choice between a clamped volume and
 * the same one running to infinity (crates/umbra-wasm/src/cull.rs choose_clamp). On a software
 * rasteriser a far cap costs about 3.5 us (Sponza and Sibenik along their fly-throughs at
 * 640 x 360 on SwiftShader: every clamped view slower than the same volumes unclamped;
 * docs/web-speed.md), a thousand pixels of fill; a GPU runs vertices far cheaper.
 */
const POLYGON_PIXELS = { software: 1024, gpu: 16 };

/** The world box of a mesh's local box `b` ({min, max}) under its world matrix `m` (f64 elements). */
function worldBox(b, m, into) {
  for (let c = 0; c < 8; c++) {
    const p = [c & 1 ? b.max[0] : b.min[0], c & 2 ? b.max[1] : b.min[1], c & 4 ? b.max[2] : b.min[2]];
    for (let r = 0; r < 3; r++) {
      const v = m[r] * p[0] + m[4 + r] * p[1] + m[8 + r] * p[2] + m[12 + r];
      into[r] = Math.min(into[r], v);
      into[3 + r] = Math.max(into[3 + r], v);
    }
  }
}

/** The box of x y z positions, {min, max}, or null when there are none or one is not finite. */
function boxOf(positions) {
  if (positions.length < 3) return null;
  const min = [Infinity, Infinity, Infinity];
  const max = [-Infinity, -Infinity, -Infinity];
  for (let i = 0; i < positions.length; i += 3) {
    for (let a = 0; a < 3; a++) {
      const v = positions[i + a];
      if (v < min[a]) min[a] = v;
      if (v > max[a]) max[a] = v;
    }
  }
  return [...min, ...max].every(Number.isFinite) ? { min, max } : null;
}

/** Whether two values of a frame's inputs are equal: typed arrays and arrays element by element, others by identity. */
function sameValue(a, b) {
  if (a === b) return true;
  if (!a || !b || typeof a !== 'object' || typeof b !== 'object') return false;
  const list = (x) => ArrayBuffer.isView(x) || Array.isArray(x);
  if (!list(a) || !list(b) || a.length !== b.length) return false;
  for (let i = 0; i < a.length; i++) if (!sameValue(a[i], b[i])) return false;
  return true;
}

/**
 * Whether frame `b` draws what frame `a` drew: the same settings and lights (`a.key`), and the
 * same meshes in the same order, each with the same buffers, volumes and every other value the
 * drawer reads (matrices, lights in its space, flip...); its functions (the silhouette) are
 * derived from those.
 */
function sameFrame(a, b) {
  if (!a || !b || !sameValue(a.key, b.key) || a.meshes.length !== b.meshes.length) return false;
  for (let i = 0; i < a.meshes.length; i++) {
    const m = a.meshes[i];
    const n = b.meshes[i];
    const keys = Object.keys(m);
    if (keys.length !== Object.keys(n).length) return false;
    for (const k of keys) if (typeof m[k] !== 'function' && !sameValue(m[k], n[k])) return false;
  }
  return true;
}

export class UmbraShadows {
  /**
   * Loads the wasm preprocessing and sets up the WebGL 2 drawer on `renderer`'s context.
   * Throws a clear Error when the context is not WebGL 2 or lacks what umbra needs.
   * @param {import('three').WebGLRenderer} renderer
   * @param {{wasm?: any, depth?: 'reversed'|'standard', depthClamp?: boolean, snap?: number, zpass?: boolean, volumeCull?: boolean|'auto', cache?: boolean}} options
   *   wasm: the module's URL, Response or bytes (default: umbra_wasm.wasm beside this file);
   *   depth, depthClamp, snap: diagnostics (docs/web.md); zpass: false counts every light
   *   z-fail (a diagnostic: the two counts give the same decision); volumeCull (default 'auto':
   *   on a software rasteriser): volumes only where a visible sample may receive them (false:
   *   every volume to infinity); cache (default true): what did not move is kept (the
   *   silhouettes of a light that stayed put, a frame's decisions when nothing moved)
   */
  static async create(renderer, options = {}) {
    if (renderer?.isWebGPURenderer) {
      throw new Error("umbra-three: a WebGPURenderer: import UmbraShadows from 'umbra-three/webgpu' for it (this entry draws into a WebGLRenderer)");
    }
    const gl = renderer?.getContext?.();
    if (!gl || typeof WebGL2RenderingContext === 'undefined' || !(gl instanceof WebGL2RenderingContext)) {
      throw new Error('umbra-three: the renderer has no WebGL 2 context (umbra needs WebGL 2: transform feedback, integer and float textures)');
    }
    const topology = await Topology.load(options.wasm);
    return new UmbraShadows(renderer, topology, options);
  }

  constructor(renderer, topology, options = {}) {
    this.renderer = renderer;
    this.topology = topology;
    this.options = options;
    const gl = renderer.getContext();
    try {
      this.drawer = new WebGLDrawer(gl, options);
    } catch (e) {
      throw new Error(`umbra-three: WebGL 2 set-up failed: ${e.message}`);
    }
    renderer.resetState();
    this.enabled = true;
    this.disposed = false;
    this.timing = false;
    this.errors = [];
    this.onError = null;
    this.mask = new ExternalTexture(null);
    this.uniforms = createUniforms(this.mask);
    this.patched = new WeakSet();
    this.casters = new WeakMap(); // geometry -> { key, volumes and wasm | error }
    this.drawn = new WeakMap(); // geometry -> { key, buffers }
    this.batched = new WeakMap(); // BatchedMesh -> Map geometry id -> its geometry (batchedGeometry)
    this.owned = new Set(); // GL objects and wasm caster handles to free on dispose
    this.reported = new Set();
    this.channels = new Map(); // light -> channel of the last frame
    this.unions = new UnionCache(topology.geom); // z-pass tests of casters sharing a world matrix
    this.frameCount = 0;
    // The inputs of the last frame whose decisions are in the mask target (null: none): a frame
    // with the same ones reuses them (`cache`).
    this.lastFrame = null;
    this.cache = options.cache !== false;
    // Casters whose material discards fragments (alphaTested): to three.js's shadow map
    // ('shadowMap', the default: a leaf casts a leaf) or as their whole triangles ('triangles').
    const alpha = options.alphaCasters ?? 'shadowMap';
    if (!['shadowMap', 'triangles'].includes(alpha)) throw new Error(`umbra-three: alphaCasters: '${alpha}': expected 'shadowMap' or 'triangles'`);
    this.alphaCasters = alpha;
    this.mapCasters = new Set();
    // Where the unculled silhouettes are computed: 'wasm' (the orientations and the list of
    // silhouette records on the main thread) or 'gpu' (the orientation pass and every record
    // visited by the sides' polygon pass: no main-thread work per light move); 'auto' (the
    // default): the GPU where it is hardware, the wasm on a software rasteriser, whose "GPU"
    // is the same CPU and where the wasm's short list draws far fewer polygons.
    const asked = options.silhouettes ?? 'auto';
    if (!['auto', 'wasm', 'gpu'].includes(asked)) throw new Error(`umbra-three: silhouettes: '${asked}': expected 'auto', 'wasm' or 'gpu'`);
    this.silhouettes = asked === 'auto' ? (this.drawer.software ? 'wasm' : 'gpu') : asked;
    this.receivers = []; // per light slot, its receiver map in the wasm (volumeCull)
    this.samples = null; // the frame's samples in the wasm (volumeCull, receiverScatter 'cpu')
    this.info = {
      lights: 0, casters: 0, mapCasters: [], triangles: 0, prepareMs: 0, cpuMs: 0, reused: false, gpuBytes: 0, passes: {}, zpass: [],
      volumeCull: this.drawer.volumeCull, volumeCullMessage: this.drawer.volumeCullMessage, receiverScatter: this.drawer.receiverScatter, silhouettes: this.silhouettes, volumes: [],
      ortho: null,
    };
    // The last orthographic frame's { near, far } (info.ortho of a reused frame).
    this.lastOrtho = null;
  }

  /** The renderer's name (WEBGL_debug_renderer_info) and its SUBPIXEL_BITS, for tests. */
  get rendererName() {
    return this.drawer.rendererName;
  }

  get subpixelBits() {
    return this.drawer.subpixelBits;
  }

  /** Whether umbra's depth pass is reversed-Z (EXT_clip_control) or standard. */
  get depth() {
    return this.drawer.reversedZ ? 'reversed-z' : 'standard';
  }

  report(object, message) {
    reportOnce(this, object, message);
  }

  /** Draws `scene` from `camera` with umbra's shadows (or plainly when umbra cannot). */
  render(scene, camera) {
    let shadowed = false;
    // umbra's own main-thread time this frame (info.cpuMs): its passes' commands, the wasm's
    // work and the read-backs it waits for; three.js's frame after it is not counted.
    const t0 = performance.now();
    if (this.enabled && !this.disposed) {
      try {
        shadowed = this.drawDecisions(scene, camera);
      } catch (e) {
        this.report('(frame)', `umbra could not draw this frame's shadows: ${e.message}`);
        shadowed = false;
      }
      this.renderer.resetState();
    }
    if (!shadowed) {
      this.lastFrame = null;
      this.channels = new Map();
      this.setSelects(new Map(), new Map());
    }
    this.info.cpuMs = performance.now() - t0;
    // three.js's shadow maps stay off in umbra's frame (a light would be shadowed twice);
    // the selects go back to "lit" after it, so that a plain renderer.render() of the same
    // scene (three.js's own shadow maps, say) is three.js's own image.
    const shadowMap = this.renderer.shadowMap.enabled;
    if (this.enabled) this.renderer.shadowMap.enabled = false;
    // Alpha-tested casters (`alphaCasters: 'shadowMap'`) cast through three.js's own shadow
    // map in this frame, umbra through its volumes for the rest: the map on (its programs
    // multiply each light by its map, the patch by umbra's decision: the product), only those
    // casters casting into it, every mesh receiving it as it receives umbra's shadows. Each
    // flag is the user's again after the frame.
    const restore = [];
    if (this.enabled && !this.disposed && this.mapCasters.size) {
      this.renderer.shadowMap.enabled = true;
      scene.traverse((o) => {
        if (!o.isMesh) return;
        restore.push([o, o.castShadow, o.receiveShadow]);
        o.castShadow = this.mapCasters.has(o);
        o.receiveShadow = true;
      });
    }
    try {
      this.renderer.render(scene, camera);
    } finally {
      for (const [o, cast, receive] of restore) {
        o.castShadow = cast;
        o.receiveShadow = receive;
      }
      this.renderer.shadowMap.enabled = shadowMap;
      this.setSelects(new Map(), new Map());
    }
  }

  setSelects(slots, channels) {
    const point = this.uniforms.umbraPointSelect.value;
    const dir = this.uniforms.umbraDirectionalSelect.value;
    for (const v of point) v.set(0, 0, 0, 0);
    for (const v of dir) v.set(0, 0, 0, 0);
    for (const [light, c] of channels) {
      const s = slots.get(light);
      const target = s.kind === 'point' ? point[s.index] : dir[s.index];
      if (target) target.fromArray(CHANNEL_SELECT[c]);
    }
  }

  /** The caster state of a mesh's geometry (prepared once per version), or null with an error reported. */
  casterOf(mesh, g = mesh.geometry) {
    const pos = g?.attributes?.position;
    const key = `${pos?.version}/${pos?.count}/${g?.index?.version}/${g?.index?.count}`;
    let c = this.casters.get(g);
    if (!c || c.key !== key) {
      if (c?.volumes) {
        c.volumes.dispose();
        this.owned.delete(c.volumes);
      }
      if (c?.wasm) {
        c.wasm.dispose();
        this.owned.delete(c.wasm);
      }
      c = { key, volumes: null, wasm: null, error: null };
      try {
        const data = this.topology.prepare(g, meshName(mesh), this.drawer.volumeCull);
        this.info.prepareMs += data.ms;
        if (data.triangles > 0) {
          c.volumes = this.drawer.createVolumes(data);
          this.owned.add(c.volumes);
          // The per-frame work (z-pass test, silhouette) lives in the wasm module's memory:
          // freed with the volumes.
          c.wasm = { caster: data.caster, dispose: () => data.caster.free() };
          // The welded rest positions (a posed mesh's welded vertices start from them).
          c.welded = data.positions;
          // Input triangles the welding dropped (weldedBefore() maps the others).
          c.degenerate = data.degenerate;
          c.weldedBefore = null;
          this.owned.add(c.wasm);
        } else {
          data.caster?.free();
        }
      } catch (e) {
        if (!(e instanceof TopologyError)) throw e;
        c.error = e.message;
      }
      this.casters.set(g, c);
    }
    if (c.error) this.report(meshName(mesh), c.error);
    return c.volumes ? c : null;
  }

  /**
   * For caster `c` of `geometry` (casterOf), its welded triangle count before every input
   * triangle (sides.js weldedTriangleCounts), or null where the welding dropped none (the
   * identity); computed once per prepared geometry.
   */
  weldedBefore(c, geometry) {
    if (!c.degenerate) return null;
    c.weldedBefore ??= weldedTriangleCounts(geometryPositions(geometry, ''), geometry.index ? geometry.index.array.subarray(0, geometry.index.count) : null);
    return c.weldedBefore;
  }

  /**
   * The positions (x y z per vertex, the mesh's space) of a skinned or morphed mesh `m` in the
   * pose three.js draws it in this frame (Mesh / SkinnedMesh getVertexPosition: its morph
   * targets, then its bones, in f64, rounded to f32), or null when `m` is neither (or its
   * morph influences are all 0).
   */
  posed(m, geometry) {
    const morphed = !!geometry.morphAttributes?.position?.length && (m.morphTargetInfluences || []).some((x) => x !== 0);
    if (!m.isSkinnedMesh && !morphed) return null;
    const count = geometry.attributes.position.count;
    const out = new Float32Array(3 * count);
    const v = new Vector3();
    for (let i = 0; i < count; i++) {
      m.getVertexPosition(i, v);
      out[3 * i] = v.x;
      out[3 * i + 1] = v.y;
      out[3 * i + 2] = v.z;
    }
    return out;
  }

  /**
   * A caster's welded vertices in `pose` (posed()): each welded vertex takes the posed position
   * of the first input vertex welded into it (welding is by exact rest position: the map is
   * built once per caster from its rest positions and the wasm's welded ones).
   */
  weldedPose(caster, geometry, pose) {
    if (!caster.weldMap) {
      const key = (x, y, z) => `${x === 0 ? 0 : x},${y === 0 ? 0 : y},${z === 0 ? 0 : z}`;
      const welded = new Map();
      const w = caster.welded;
      for (let i = 0; i < w.length / 3; i++) welded.set(key(w[3 * i], w[3 * i + 1], w[3 * i + 2]), i);
      const rest = positionArray(geometry.attributes.position);
      const map = new Int32Array(rest.length / 3).fill(-1);
      for (let i = 0; i < map.length; i++) map[i] = welded.get(key(rest[3 * i], rest[3 * i + 1], rest[3 * i + 2])) ?? -1;
      caster.weldMap = map;
    }
    const out = Float32Array.from(caster.welded);
    const done = new Uint8Array(out.length / 3);
    caster.weldMap.forEach((wv, i) => {
      if (wv < 0 || done[wv]) return;
      done[wv] = 1;
      out.set(pose.subarray(3 * i, 3 * i + 3), 3 * wv);
    });
    return out;
  }

  /**
   * Geometry `id` of BatchedMesh `m` as a geometry of its own (what casterOf and buffersOf
   * read: a position attribute and an index with versions): its range of the batch's vertices
   * and indices, the indices counted from the range's first vertex. One object per (mesh, id),
   * refilled (its version raised) when the batch's buffers or the range change.
   */
  batchedGeometry(m, id) {
    let views = this.batched.get(m);
    if (!views) this.batched.set(m, (views = new Map()));
    const g = m.geometry;
    const pos = g.attributes.position;
    const r = m.getGeometryRangeAt(id);
    const key = `${pos.version}/${g.index?.version}/${r.vertexStart}/${r.vertexCount}/${r.indexStart}/${r.indexCount}`;
    let v = views.get(id);
    if (v && v.key === key) return v.geometry;
    const positions = new Float32Array(3 * r.vertexCount);
    for (let i = 0; i < r.vertexCount; i++) {
      positions[3 * i] = pos.getX(r.vertexStart + i);
      positions[3 * i + 1] = pos.getY(r.vertexStart + i);
      positions[3 * i + 2] = pos.getZ(r.vertexStart + i);
    }
    let index = null;
    if (g.index) {
      index = new Uint32Array(r.indexCount);
      for (let j = 0; j < r.indexCount; j++) index[j] = g.index.getX(r.indexStart + j) - r.vertexStart;
    }
    const version = v ? v.geometry.attributes.position.version + 1 : 0;
    const geometry = v ? v.geometry : { uuid: `${m.uuid}/geometry ${id}`, attributes: {}, index: null };
    geometry.attributes.position = { array: positions, itemSize: 3, count: r.vertexCount, normalized: false, version };
    geometry.index = index ? { array: index, count: index.length, version } : null;
    views.set(id, { key, geometry });
    return geometry;
  }

  /** A mesh's depth/mask-pass buffers (once per geometry version), or null (no positions). */
  buffersOf(mesh, g = mesh.geometry) {
    const pos = g?.attributes?.position;
    const key = `${pos?.version}/${pos?.count}/${g?.index?.version}/${g?.index?.count}`;
    let d = this.drawn.get(g);
    if (!d || d.key !== key) {
      if (d?.buffers) {
        this.drawer.deleteMeshBuffers(d.buffers);
        this.owned.delete(d.buffers);
      }
      d = { key, buffers: null, box: null, error: null };
      try {
        const positions = geometryPositions(g, meshName(mesh));
        const index = g.index ? g.index.array.subarray(0, g.index.count) : null;
        const tri = flatTriangles(positions, index);
        d.buffers = this.drawer.createMeshBuffers(tri);
        // Its box (the triangles' vertices), for the receiver maps' bounds.
        d.box = boxOf(tri.positions);
        this.owned.add(d.buffers);
      } catch (e) {
        if (!(e instanceof TopologyError)) throw e;
        d.error = e.message;
      }
      this.drawn.set(g, d);
    }
    if (d.error) this.report(meshName(mesh), d.error);
    return d.buffers ? d : null;
  }

  /** Steps 1-2 of the frame; false when there is nothing umbra shadows (a plain render). */
  drawDecisions(scene, camera) {
    // Where the main thread's time goes (info.cpu): the scene walked and every mesh placed,
    // the z-pass tests, the passes issued (silhouettes, uploads and read-backs included).
    this.mapCasters = new Set();
    const cpu = { scene: 0, clearance: 0, passes: 0 };
    this.info.cpu = cpu;
    let tc = performance.now();
    if (scene.matrixWorldAutoUpdate) scene.updateMatrixWorld();
    if (camera.parent === null && camera.matrixWorldAutoUpdate) camera.updateMatrixWorld();
    const gathered = gatherLights(scene, camera);
    const slots = lightSlots(gathered);
    const lights = [];
    for (const l of gathered) {
      if (!l.castShadow || !(l.isPointLight || l.isDirectionalLight)) continue;
      if (lights.length === MAX_LIGHTS) {
        this.report(l.name || l.uuid, `more than ${MAX_LIGHTS} shadow-casting lights: this one is drawn without umbra's shadow`);
        continue;
      }
      lights.push(l);
    }
    // Every drawn mesh, receivers and casters, in scene order (the depth pass needs them all).
    const meshes = [];
    const visit = (o) => {
      if (o.visible === false) return;
      // A mesh whose every material is invisible is not drawn by three.js: not in the depth pass.
      const materials = Array.isArray(o.material) ? o.material : [o.material];
      if (o.isMesh && o.layers.test(camera.layers) && materials.some((m) => m && m.visible !== false)) meshes.push(o);
      for (const c of o.children) visit(c);
    };
    visit(scene);
    for (const m of meshes) for (const mat of Array.isArray(m.material) ? m.material : [m.material]) patchMaterial(mat, this.uniforms, this.patched);
    this.info.lights = lights.length;
    if (lights.length === 0) return false;
    // An OrthographicCamera: every volume closed at finite far ends beyond the drawn meshes'
    // world box (a point at infinity has clip w = 0 under an orthographic projection, so no
    // volume may reach it), counted z-fail, drawn with a projection whose finite far plane lies
    // beyond every far end (orthoFrame(); docs/web.md, "Orthographic cameras").
    const ortho = !!camera.isOrthographicCamera;
    if (!camera.isPerspectiveCamera && !ortho) {
      this.report(camera.name || camera.uuid, `${camera.type}: umbra-three draws shadows for a PerspectiveCamera or an OrthographicCamera only; the frame is drawn without them`);
      return false;
    }

    const size = this.renderer.getDrawingBufferSize(new Vector2());
    const reversed = this.drawer.reversedZ;
    // Orthographic: the projection needs the far plane, known once every volume is closed
    // (orthoFrame); each mesh's clip-from-object matrix is made there.
    const projection = ortho ? null : infiniteProjection(camera.getEffectiveFOV(), camera.aspect, camera.near, reversed);
    const view = camera.matrixWorldInverse.elements;
    const lightWorld = lights.map((l) => {
      const p = new Vector3().setFromMatrixPosition(l.matrixWorld);
      if (l.isPointLight) return [p.x, p.y, p.z, 1];
      // Directional: w = 0, xyz towards the light (from its target to its position).
      const t = new Vector3().setFromMatrixPosition(l.target.matrixWorld);
      return [p.x - t.x, p.y - t.y, p.z - t.z, 0];
    });
    const inverse = new Matrix4();
    // The z-pass test's points (the eye and the near-plane corners), world space.
    const eye = new Vector3().setFromMatrixPosition(camera.matrixWorld);
    // Orthographic: no near pyramid (the eye is at infinity); every light is counted z-fail.
    const worldFromClip = ortho ? null : new Matrix4().fromArray(mul(projection, view)).invert().elements;
    const pyramid = this.options.zpass === false || ortho ? null : nearPyramidPoints(worldFromClip, [eye.x, eye.y, eye.z], reversed);
    const tests = [];
    const frameMeshes = [];
    let casters = 0;
    let triangles = 0;
    // The receiver cull of this frame: per light whether its map was built (frame.cull.receive),
    // and what its volumes drew.
    const cullOn = this.drawer.volumeCull;
    const gpuSilhouettes = this.silhouettes === 'gpu';
    const culledLights = lights.map(() => false);
    // Each light's count, once known (the z-pass tests run after this loop).
    const zpassOf = lights.map(() => null);
    const drawnVolumes = lights.map(() => ({ culled: false, triangles: 0, edges: 0, clamped: 0, cached: 0 }));
    // Every visible sample lies in the union of the drawn meshes' world boxes.
    const bounds = [Infinity, Infinity, Infinity, -Infinity, -Infinity, -Infinity];
    let affineWorlds = true;
    // One drawn mesh: `geometry` (a mesh's own, or one of a BatchedMesh's) placed by `world`
    // (its matrixWorld, times an instance's matrix); `instance` names the instance (null for
    // a plain mesh), so that each keeps its own silhouettes (`cache`).
    const mapCasting = this.alphaCasters === 'shadowMap';
    const mapCasters = new Set();
    // Orthographic: every drawn mesh's f64 world matrix (its clip matrix is made in orthoFrame),
    // and every caster with what its volumes are closed by; a posed caster (its rest pose is
    // what the wasm holds) refuses the frame.
    const orthoMeshes = [];
    const orthoCasters = [];
    let orthoPosed = null;
    const placeMesh = (m, geometry, world, instance) => {
      const drawn = this.buffersOf(m, geometry);
      if (!drawn) return;
      const buffers = drawn.buffers;
      const we = world.elements;
      if (!(we[3] === 0 && we[7] === 0 && we[11] === 0 && we[15] === 1 && we.every(Number.isFinite))) affineWorlds = false;
      // A skinned or morphed mesh in the pose three.js draws this frame (posed()): its depth-pass
      // triangles and, as a caster, its welded vertices are those of the pose; its silhouettes
      // come from the GPU, its count is z-fail (the z-pass test knows the rest pose only), and
      // the frame is not culled (the receiver maps' bounds are the rest pose's).
      const pose = instance === null ? this.posed(m, geometry) : null;
      if (pose) {
        this.drawer.updateMeshBuffers(buffers, flatTriangles(pose, geometry.index ? geometry.index.array.subarray(0, geometry.index.count) : null));
        affineWorlds = false;
      }
      if ((cullOn || ortho) && drawn.box) worldBox(drawn.box, we, bounds);
      // Orthographic: a posed mesh's samples lie on its pose, which the box must hold too.
      if (ortho && pose) {
        const posedBox = boxOf(pose);
        if (posedBox) worldBox(posedBox, we, bounds);
      }
      // An alpha-tested caster goes to three.js's shadow map (render()): not umbra's.
      const toMap = m.castShadow && mapCasting && alphaTested(m);
      if (toMap) mapCasters.add(m);
      const caster = m.castShadow && !toMap ? this.casterOf(m, geometry) : null;
      const volumes = caster ? caster.volumes : null;
      if (volumes) {
        casters++;
        triangles += volumes.triangles;
        if (pose) volumes.setVertices(this.weldedPose(caster, geometry, pose));
      }
      inverse.copy(world).invert();
      const e = inverse.elements;
      const toObject = (v) => new Float32Array([0, 1, 2, 3].map((r) => e[r] * v[0] + e[4 + r] * v[1] + e[8 + r] * v[2] + e[12 + r] * v[3]));
      const objectLights = lightWorld.map(toObject);
      if (caster) {
        // The test in the caster's space (an affine map keeps what it proves; see
        // crates/umbra-wasm/src/clearance.rs); a projective world matrix: no test, z-fail.
        const w = world.elements;
        const affine = w[3] === 0 && w[7] === 0 && w[11] === 0 && w[15] === 1;
        tests.push({
          caster: caster.wasm.caster, points: pyramid && affine && !pose ? transformPoints(e, pyramid) : null, lights: objectLights,
          // Casters of one world matrix share a space: asked as a union where needed.
          group: w.join(','), key: `${geometry.uuid}/${caster.key}`,
        });
      }
      const worldFromObject = world.elements.slice();
      const clip = ortho ? null : clipFromObject(projection, view, world.elements);
      // What the wasm's cull reads: the caster's world matrix and its inverse (its samples are
      // in world space), and where its volume is drawn (clamped only where that covers fewer
      // pixels).
      const place = {
        worldFromObject, objectFromWorld: e.slice(), clipFromObject: clip, width: size.x, height: size.y, zfail: true,
        polygonPixels: this.drawer.software ? POLYGON_PIXELS.software : POLYGON_PIXELS.gpu, clamp: this.options.volumeClamp ?? 'auto',
      };
      // Light k's silhouette: culled against its map when it was built (null from the wasm:
      // a projective world matrix, drawn unculled), else every triangle's, which the caster's
      // slot k keeps while the light stays where it is in the caster's space (its key: the
      // light's four f32 object-space coordinates, what the wasm orients the triangles by).
      const index = instance === null ? null : typeof instance === 'number' ? instance : Number(instance.slice(1));
      const instanceSlot = index !== null && index < INSTANCE_SLOTS ? MAX_LIGHTS * (1 + index) : null;
      // Orthographic: the volumes closed beyond the box, computed in orthoFrame (per light k).
      const closed = [];
      if (ortho) {
        orthoMeshes.push(worldFromObject);
        if (caster && pose) orthoPosed = meshName(m);
        if (caster) orthoCasters.push({ caster, worldFromObject, objectFromWorld: e.slice(), objectLights, closed });
      }
      const silhouette = (k) => {
        if (ortho) return closed[k];
        const w = caster.wasm.caster;
        const v = drawnVolumes[k];
        if (culledLights[k]) {
          place.zfail = zpassOf[k] === null;
          const s = w.cull(this.receivers[k], place, objectLights[k]);
          if (s) {
            v.triangles += s.kept;
            v.edges += s.records.length;
            v.clamped += s.clamped ? 1 : 0;
            return { silhouette: s, key: null, slot: k };
          }
        }
        v.triangles += caster.volumes.triangles;
        // The caster's slot for light k: its own per instance for the first ones; the others
        // share slot k, computed again every frame (key null).
        const slot = instanceSlot === null ? k : instanceSlot + k;
        const key = this.cache && !pose && (instanceSlot !== null || instance === null) ? objectLights[k].join(',') : null;
        if (caster.volumes.holds(slot, key) && caster.volumes.slots[slot].gpu === gpuSilhouettes) {
          v.edges += caster.volumes.slots[slot].records;
          v.cached++;
          return { silhouette: null, key, slot };
        }
        if (gpuSilhouettes || pose) {
          // Oriented on the GPU; the sides visit every record.
          v.edges += caster.volumes.records;
          return { silhouette: 'gpu', key, slot };
        }
        const u = w.silhouette(objectLights[k]);
        v.edges += u.records.length;
        return { silhouette: u, key, slot };
      };
      // The ranges three.js draws and the faces its materials cull there (sides.js).
      const sides = sidesOf(m.material, geometry, buffers.vertices);
      frameMeshes.push({
        buffers,
        volumes: caster ? caster.volumes : null,
        clipFromObject: clip,
        world: new Float32Array(worldFromObject),
        // A mirroring transform turns the winding: the mask pass flips gl_FrontFacing back.
        flip: world.determinant() < 0 ? -1 : 1,
        // A posed mesh's frame is never the last one's (its pose is read every frame).
        pose: pose ? this.frameCount : -1,
        sides,
        // A caster's triangles of one-sided materials, whose light caps the drawer also counts
        // at their true depth (empty for DoubleSide: nothing more drawn).
        trueCaps: caster ? culledCapRanges(sides, this.weldedBefore(caster, geometry)) : null,
        lights: objectLights,
        silhouette: caster ? silhouette : null,
      });
    };
    const instanceWorld = new Matrix4();
    for (const m of meshes) {
      if (m.isBatchedMesh) {
        // Every active, visible instance: its geometry's range of the batch, by its matrix.
        const info = m._instanceInfo;
        for (let i = 0; i < info.length; i++) {
          if (!info[i].active || !info[i].visible) continue;
          const geometry = this.batchedGeometry(m, info[i].geometryIndex);
          if (!geometry) continue;
          m.getMatrixAt(i, instanceWorld).premultiply(m.matrixWorld);
          placeMesh(m, geometry, instanceWorld.clone(), `b${i}`);
        }
      } else if (m.isInstancedMesh) {
        // The first `count` instances, each by its matrix; one topology serves them all.
        for (let i = 0; i < m.count; i++) {
          m.getMatrixAt(i, instanceWorld).premultiply(m.matrixWorld);
          placeMesh(m, m.geometry, instanceWorld.clone(), i);
        }
      } else {
        placeMesh(m, m.geometry, m.matrixWorld, null);
      }
    }
    this.mapCasters = mapCasters;
    this.info.mapCasters = [...mapCasters].map(meshName);
    this.info.casters = casters;
    this.info.triangles = triangles;
    // No caster: nothing is shadowed, and the frame is three.js's own.
    if (casters === 0) return false;
    // Nothing moved since the last frame drawn (`cache`): the same settings, camera, lights (and
    // their slots in three.js's uniforms) and the same meshes with the same buffers, volumes,
    // matrices and lights in their space. Every pass below reads only those, so the mask target
    // holds this frame's decisions already: no pass, no z-pass test, no silhouette.
    if (ortho && (orthoPosed !== null || !affineWorlds)) {
      const why = orthoPosed !== null ? `the skinned or morphed caster ${orthoPosed} (its volumes are closed from the rest pose the wasm holds)` : 'a mesh with a projective world matrix (its volumes are closed in world space)';
      this.report(camera.name || camera.uuid, `OrthographicCamera: umbra-three cannot close the volumes of ${why}; the frame is drawn without shadows`);
      return false;
    }
    // The frame's projection: the perspective one, or the orthographic one's inputs (its x and
    // y rows and near plane: its far plane follows from the rest of the key).
    const pm = camera.projectionMatrix.elements;
    const frame = {
      key: [size.x, size.y, reversed, this.options.snap || 0, this.options.zpass !== false, this.options.volumeClamp ?? 'auto', cullOn,
        ortho ? ['ortho', pm[0], pm[1], pm[4], pm[5], pm[8], pm[9], pm[12], pm[13], camera.near] : projection.slice(),
        view.slice(), lights, lights.map((l) => [slots.get(l).kind, slots.get(l).index]), lightWorld],
      meshes: frameMeshes,
    };
    if (this.cache && sameFrame(this.lastFrame, frame) && this.drawer.maskTexture) {
      this.info.reused = true;
      this.info.ortho = ortho ? this.lastOrtho : null;
      this.info.passes = {};
      this.mask.sourceTexture = this.drawer.maskTexture;
      this.setSelects(slots, this.channels);
      return true;
    }
    this.lastFrame = null;
    this.info.reused = false;
    const timing = this.timing ? {} : null;
    const t0 = timing ? performance.now() : 0;
    cpu.scene = performance.now() - tc;
    tc = performance.now();
    const zpass = lights.map((_, k) => zpassStart(tests, k, (group) => this.unions.of(group, this.frameCount)));
    this.unions.prune(this.frameCount);
    this.frameCount++;
    zpass.forEach((z, k) => (zpassOf[k] = z));
    if (timing) timing.clearance = performance.now() - t0;
    cpu.clearance = performance.now() - tc;
    tc = performance.now();
    let cull = null;
    // The map is made of world positions (x y z of the world matrix times the object point):
    // a projective world matrix anywhere in the frame would misplace its samples, so such a
    // frame is drawn unculled.
    if (cullOn && !ortho && affineWorlds && bounds.every(Number.isFinite)) {
      const box = Float32Array.from(bounds);
      while (this.receivers.length < lights.length) this.receivers.push(this.topology.geom.receivers());
      cull = {
        side: RECEIVER_SIDE,
        // A light the wasm refuses a grid for (no direction, say) is drawn unculled.
        grids: lights.map((_, k) => this.receivers[k].setGrid(Float32Array.from(lightWorld[k]), box, RECEIVER_SIDE)),
        cells: (k) => this.receivers[k].cells(),
        samples: (n) => {
          this.samples ??= this.topology.geom.samples();
          return this.samples.view(n);
        },
        // z-pass counts from the eye's near pyramid: raised into the map first, or no cull.
        receive: (k, fromSamples) => {
          const r = this.receivers[k];
          const built = fromSamples ? r.buildFromSamples(this.samples, 1 << k) : r.build();
          culledLights[k] = built && (zpass[k] === null || r.raise(pyramid));
          drawnVolumes[k].culled = culledLights[k];
        },
      };
    }
    let drawn = frameMeshes;
    this.info.ortho = null;
    if (ortho) {
      // Every caster's volumes closed beyond the box, then the projection whose far plane lies
      // beyond them all, and each mesh's clip matrix with it (the frame's entries keep null, so
      // that the next frame compares their inputs).
      const o = this.orthoFrame(camera, view, reversed, bounds, lightWorld, orthoCasters, drawnVolumes);
      drawn = frameMeshes.map((m, i) => ({ ...m, clipFromObject: clipFromObject(o.projection, view, orthoMeshes[i]) }));
      this.info.ortho = { near: camera.near, far: o.far };
      this.lastOrtho = this.info.ortho;
    }
    this.drawer.frame({ width: size.x, height: size.y, snap: this.options.snap || 0, timing, meshes: drawn, lights: lights.length, zpass, cull });
    cpu.passes = performance.now() - tc;
    this.info.passes = timing || {};
    this.info.zpass = zpass;
    this.info.volumes = drawnVolumes;
    this.info.volumeCull = this.drawer.volumeCull;
    this.info.receiverScatter = this.drawer.receiverScatter;
    this.info.volumeCullMessage = this.drawer.volumeCullMessage;
    this.mask.sourceTexture = this.drawer.maskTexture;
    this.channels = new Map(lights.map((l, c) => [l, c]));
    this.setSelects(slots, this.channels);
    this.lastFrame = this.cache ? frame : null;
    this.info.gpuBytes = this.gpuBytes();
    return true;
  }

  /**
   * An orthographic frame's volumes and projection. Every caster's volume towards every light
   * is closed at finite far ends beyond the world box `bounds` of the drawn meshes (the wasm's
   * clampBeyondBox: umbra_geom::receivers::clamp_beyond_box in world space, the far ends moved
   * into the caster's space; docs/exactness.md, "Orthographic views"), its silhouette copied
   * into `closed[k]` of the caster's entry for the drawer. The far plane lies beyond the
   * farthest of the box's corners and of every far end along the view direction (view
   * distance), so that neither the depth pass nor a volume is cut by it: beyond it by 1 % of
   * the box's diagonal, plus |near|, plus 2^-10 of that distance (far more than the f32
   * roundings of the far ends and of the GPU's clip z). Returns { projection, far }.
   */
  orthoFrame(camera, view, reversed, bounds, lightWorld, casters, drawnVolumes) {
    const near = camera.near;
    // View distance d = -z_view: row 2 of the view matrix (column-major), negated.
    const row = (m) => [0, 1, 2, 3].map((j) => view[2] * m[4 * j] + view[6] * m[4 * j + 1] + view[10] * m[4 * j + 2] + view[14] * m[4 * j + 3]);
    let farthest = -Infinity;
    for (let c = 0; c < 8; c++) {
      const p = [0, 1, 2].map((a) => bounds[(c >> a) & 1 ? 3 + a : a]);
      farthest = Math.max(farthest, -(view[2] * p[0] + view[6] * p[1] + view[10] * p[2] + view[14]));
    }
    for (const { caster, worldFromObject, objectFromWorld, objectLights, closed } of casters) {
      const r = row(worldFromObject);
      closed.length = 0;
      lightWorld.forEach((l, k) => {
        const s = caster.wasm.caster.clampBeyondBox({ worldFromObject, objectFromWorld, bounds, lightWorld: l }, objectLights[k]);
        if (!s) throw new Error('a caster\'s volumes could not be closed beyond the box (a matrix that is not affine, or a light that is not finite)');
        const far = s.far;
        for (let i = 0; i < far.length; i += 4) {
          // w = 0: a vertex of no kept triangle (never drawn); every other far end is finite.
          if (far[i + 3] !== 0) farthest = Math.max(farthest, -(r[0] * far[i] + r[1] * far[i + 1] + r[2] * far[i + 2] + r[3]));
        }
        const v = drawnVolumes[k];
        v.triangles += s.kept;
        v.edges += s.records.length;
        v.clamped++;
        // Copies: the views are the wasm's memory, valid until its next call.
        closed.push({
          silhouette: { orientation: s.orientation.slice(), records: s.records.slice(), single: s.single, triangles: s.triangles.slice(), far: far.slice(), clamped: true },
          key: null,
          slot: k,
        });
      });
    }
    const diagonal = Math.max(Math.hypot(bounds[3] - bounds[0], bounds[4] - bounds[1], bounds[5] - bounds[2]), 1e-6);
    const beyond = Math.max(farthest, near);
    const far = beyond + 0.01 * diagonal + Math.abs(near) + Math.abs(beyond) * 2 ** -10;
    return { projection: orthographicProjection(camera.projectionMatrix.elements, near, far, reversed), far };
  }

  /** Bytes of umbra's GPU buffers and textures now: every live caster's and mesh's, and the drawer's targets. */
  gpuBytes() {
    let bytes = this.drawer.gpuBytes;
    for (const o of this.owned) bytes += o.gpuBytes ?? o.bytes ?? 0;
    return bytes;
  }

  /** The texture holding `light`'s decision (screen sized; channel maskChannel(light)), or null. */
  maskTexture(light) {
    return this.channels.has(light) ? this.mask : null;
  }

  /** The RGBA channel of maskTexture(light) holding its decision (1 lit, 0 shadowed), or -1. */
  maskChannel(light) {
    return this.channels.has(light) ? this.channels.get(light) : -1;
  }

  /**
   * `light`'s decision of the last frame: Uint8Array of width * height, rows top-down, 255 lit /
   * 0 shadowed (0 where no surface is seen); null when the last frame did not shadow that light.
   */
  readMask(light) {
    if (!this.channels.has(light)) return null;
    const out = this.drawer.readMask(this.channels.get(light));
    this.renderer.resetState();
    return out;
  }

  /** Frees umbra's GL objects; render() is then renderer.render() and patched materials see every light as lit. */
  dispose() {
    if (this.disposed) return;
    this.disposed = true;
    for (const o of this.owned) {
      if (o.dispose) o.dispose();
      else this.drawer.deleteMeshBuffers(o);
    }
    this.owned.clear();
    for (const r of this.receivers) r.free();
    this.receivers = [];
    this.unions.clear();
    this.samples?.free();
    this.samples = null;
    this.casters = new WeakMap();
    this.drawn = new WeakMap();
    this.batched = new WeakMap();
    this.drawer.dispose();
    this.mask.sourceTexture = null;
    this.channels = new Map();
    this.setSelects(new Map(), new Map());
    this.renderer.resetState();
  }
}
