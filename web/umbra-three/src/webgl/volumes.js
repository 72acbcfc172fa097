// The shadow volumes of one caster: paper 003's vs-silhouette (vs_silhouette.js) as WebGL 2
// objects. Owns the caster's geometry textures (from topology.js: its welded vertices, the
// welded vertices of every triangle and edge record, and the edge triangles `umbra export`
// writes), the silhouette's textures per light slot (the triangles' orientations, R8I, and the
// list of edge records of nonzero multiplicity, R32I, both computed by the wasm per light, kept
// while the light does not move in the caster's space); the polygon and fan passes, with their
// programs and the polygons' storage, are shared by every caster (VolumePrograms); the drawer
// (drawer.js) owns the frame, calls prepare() per light and draw() under the counting state it
// set. Culled to the receivers (`volumeCull`, crates/umbra-wasm/src/cull.rs), a caster also
// holds, per light, the far end of every welded vertex and the list of its kept triangles of
// nonzero orientation.
import { link, GlSetupError } from './program.js';
import { plainUnpack } from './unpack.js';
import {
  polygonsVertexSource, fanVertexSource, fanFragmentSource, volumeFragmentSource, orientVertexSource,
  POLYGON_VARYINGS, FAN_VERTICES, polygonsPerInstance, textureShift, textureRows,
} from './vs_silhouette.js';

/** Texels (vec4) per polygon of the polygon pass: 8 vertices and (count, repeat). */
const POLYGON_TEXELS = POLYGON_VARYINGS.length;

/**
 * An immutable texture of `texels` elements of `perTexel` components, 2^shift texels wide,
 * element i at (i mod width, i / width), filled from `data` (a typed array) when given.
 */
export function dataTexture(gl, shift, internalFormat, format, type, data, perTexel, texels, what) {
  const width = 2 ** shift;
  const rows = textureRows(texels, shift);
  const max = gl.getParameter(gl.MAX_TEXTURE_SIZE);
  if (rows > max) throw new GlSetupError(`${what}: ${texels} texels need ${rows} rows of ${width}; this WebGL 2 allows ${max}`);
  const tex = gl.createTexture();
  gl.bindTexture(gl.TEXTURE_2D, tex);
  gl.texStorage2D(gl.TEXTURE_2D, 1, internalFormat, width, rows);
  // NEAREST: 32-bit float and integer textures are incomplete with filtering (ES 3.0
  // §3.8.13), and texelFetch never filters anyway.
  gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.NEAREST);
  gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.NEAREST);
  if (data) upload(gl, width, format, type, data, 0, perTexel, texels);
  gl.bindTexture(gl.TEXTURE_2D, null);
  // What it holds on the GPU: whole rows of texels (1, 2 or 4 bytes per component).
  const bytes = width * rows * perTexel * (type === gl.BYTE || type === gl.UNSIGNED_BYTE ? 1 : type === gl.SHORT ? 2 : 4);
  return { tex, width, rows, bytes };
}

/**
 * Polygons one polygon pass captures at most (2^13: 1.2 MB of buffer and as much of texture);
 * a larger set is drawn in chunks of this many (a few more draws, each still thousands of
 * polygons).
 */
export const POLYGON_CHUNK = 1 << 13;

/** `texels` elements into the bound texture, from `source` (a typed array, or a byte offset
 * into the bound PIXEL_UNPACK_BUFFER) at element `first`: the full rows, then the rest. Rows
 * are 2^11 texels or more wide: every row starts aligned whatever UNPACK_ALIGNMENT is. */
export function upload(gl, width, format, type, source, first, perTexel, texels) {
  const full = Math.floor(texels / width);
  const rest = texels - full * width;
  const fromBuffer = typeof source === 'number';
  const at = (t) => (fromBuffer ? source + 4 * perTexel * t : t * perTexel);
  if (full > 0) {
    if (fromBuffer) gl.texSubImage2D(gl.TEXTURE_2D, 0, 0, 0, width, full, format, type, at(0));
    else gl.texSubImage2D(gl.TEXTURE_2D, 0, 0, 0, width, full, format, type, source, at(0));
  }
  if (rest > 0) {
    if (fromBuffer) gl.texSubImage2D(gl.TEXTURE_2D, 0, 0, full, rest, 1, format, type, at(full * width));
    else gl.texSubImage2D(gl.TEXTURE_2D, 0, 0, full, rest, 1, format, type, source, at(full * width));
  }
}

// Texture units, one per sampler (samplers of different types may not share a unit).
const UNIT_VERTICES = 0;
const UNIT_EDGE_TRIANGLES = 1;
const UNIT_ORIENTATION = 2;
const UNIT_POLYGONS = 3;
const UNIT_RECORDS = 4;
const UNIT_FAR = 5;
const UNIT_RECORD_VERTICES = 6;
const UNIT_TRIANGLE_VERTICES = 7;
const UNIT_KEPT = 8;

/**
 * The two volume programs, linked once per context, and the storage of the polygons between
 * them, all shared by every caster: one set (a caster's sides, light caps or dark caps) is
 * drawn at a time, so one capture buffer and one texture serve all, sized to the largest
 * chunk drawn so far (at most POLYGON_CHUNK polygons), grown when a larger one comes.
 */
export class VolumePrograms {
  /** @param {WebGL2RenderingContext} gl */
  constructor(gl) {
    const frag = volumeFragmentSource();
    this.shift = textureShift(gl.getParameter(gl.MAX_TEXTURE_SIZE));
    this.polygons = link(gl, 'polygon pass', 'glsl/polygons.vert.glsl', polygonsVertexSource(), 'vs_silhouette/volume.frag.glsl', frag, POLYGON_VARYINGS);
    this.fan = link(gl, 'fan pass', 'glsl/fan.vert.glsl', fanVertexSource(), 'glsl/fan.frag.glsl', fanFragmentSource());
    // The fan pass of the true-depth light caps of one-sided casters (UMBRA_CULLED_FACES),
    // linked when a frame first has such a caster (culledFan()): a scene of DoubleSide
    // materials never links it.
    this.fanCulled = null;
    // The GPU silhouettes' orientation pass, linked when first used (silhouettes: 'gpu').
    this.orient = null;
    this.orientBuffer = null;
    this.orientCapacity = 0;
    this.gl = gl;
    this.storage = null;
    this.feedback = gl.createTransformFeedback();
    // The passes read textures only: an empty vertex array.
    this.emptyVao = gl.createVertexArray();
  }

  /**
   * The polygon storage for a chunk of `count` polygons (<= POLYGON_CHUNK): { buffer, tex,
   * capacity, bytes }, made or grown to the next power of two of `count` when it is smaller.
   */
  polygonStorage(count) {
    const gl = this.gl;
    if (this.storage && this.storage.capacity >= count) return this.storage;
    this.deleteStorage();
    const capacity = Math.min(POLYGON_CHUNK, 2 ** Math.ceil(Math.log2(Math.max(count, 1024))));
    const buffer = gl.createBuffer();
    gl.bindBuffer(gl.TRANSFORM_FEEDBACK_BUFFER, buffer);
    // DYNAMIC_COPY: written by the GPU (transform feedback) and read by the GPU, every frame.
    gl.bufferData(gl.TRANSFORM_FEEDBACK_BUFFER, 16 * POLYGON_TEXELS * capacity, gl.DYNAMIC_COPY);
    gl.bindBuffer(gl.TRANSFORM_FEEDBACK_BUFFER, null);
    const tex = dataTexture(gl, this.shift, gl.RGBA32F, gl.RGBA, gl.FLOAT, null, 4, POLYGON_TEXELS * capacity, 'volume polygons');
    this.storage = { buffer, tex: tex.tex, capacity, bytes: 16 * POLYGON_TEXELS * capacity + tex.bytes };
    return this.storage;
  }

  /** The fan program of the true-depth light caps (fan.frag.glsl with UMBRA_CULLED_FACES), linked when first asked for. */
  culledFan() {
    this.fanCulled ??= link(this.gl, 'fan pass (culled faces)', 'glsl/fan.vert.glsl', fanVertexSource(true), 'glsl/fan.frag.glsl', fanFragmentSource(true));
    return this.fanCulled;
  }

  /** The orientation pass and a capture buffer for `triangles` ints (grown as needed). */
  orientation(triangles) {
    const gl = this.gl;
    this.orient ??= link(gl, 'orientation pass', 'glsl/orient.vert.glsl', orientVertexSource(), 'vs_silhouette/volume.frag.glsl', volumeFragmentSource(), ['v_orientation']);
    if (this.orientCapacity < triangles) {
      if (this.orientBuffer) gl.deleteBuffer(this.orientBuffer);
      this.orientCapacity = 2 ** Math.ceil(Math.log2(Math.max(triangles, 1024)));
      this.orientBuffer = gl.createBuffer();
      gl.bindBuffer(gl.TRANSFORM_FEEDBACK_BUFFER, this.orientBuffer);
      // DYNAMIC_COPY: written by transform feedback, copied into a texture on the GPU.
      gl.bufferData(gl.TRANSFORM_FEEDBACK_BUFFER, 4 * this.orientCapacity, gl.DYNAMIC_COPY);
      gl.bindBuffer(gl.TRANSFORM_FEEDBACK_BUFFER, null);
    }
    return { program: this.orient, buffer: this.orientBuffer };
  }

  deleteStorage() {
    if (!this.storage) return;
    this.gl.deleteBuffer(this.storage.buffer);
    this.gl.deleteTexture(this.storage.tex);
    this.storage = null;
  }

  /** Bytes of the shared polygon storage and the orientation pass's buffer. */
  get gpuBytes() {
    return (this.storage ? this.storage.bytes : 0) + 4 * this.orientCapacity;
  }

  dispose() {
    for (const p of [this.polygons, this.fan, this.fanCulled]) if (p) this.gl.deleteProgram(p.program);
    this.deleteStorage();
    if (this.orient) this.gl.deleteProgram(this.orient.program);
    if (this.orientBuffer) this.gl.deleteBuffer(this.orientBuffer);
    this.gl.deleteTransformFeedback(this.feedback);
    this.gl.deleteVertexArray(this.emptyVao);
  }
}

export class ShadowVolumes {
  /**
   * @param {WebGL2RenderingContext} gl
   * @param {VolumePrograms} programs
   * @param {{maxMult: number, records: number, triangles: number, vertices: number, positions: Float32Array, indices: Uint32Array,
   *   recordVertices: Uint32Array, edgeTriangles: Int32Array, cull?: boolean}} data
   *   one caster's buffers (topology.js), in the caster's own (object) space: its welded
   *   vertices (x y z each), the 3 welded vertices of every triangle and the 2 (A, B) of every
   *   edge record, its edge triangles; `cull`: its volumes may be culled to the receivers
   */
  constructor(gl, programs, data) {
    this.gl = gl;
    this.maxMult = data.maxMult;
    this.records = data.records;
    this.triangles = data.triangles;
    const s = programs.shift;
    this.shift = s;
    // Bytes of every texture this caster owns (gpuBytes), counted as each is made.
    this.bytes = 0;
    const made = (t) => {
      this.bytes += t.bytes;
      return t;
    };
    this.made = made;
    // The geometry: the welded vertices (RGB32F) and, by index, every edge record's and
    // triangle's; what paper 003's sides-data and caps-data repeat per record and triangle
    // (16 (2 + maxMult) and 48 bytes each), in 12 bytes per vertex, 8 per record and 12 per
    // triangle (glsl/polygons.vert.glsl).
    this.vertices = data.vertices;
    // Integer data as R16I where every value fits in 16 signed bits (a caster of at most 32,767
    // vertices or triangles: half the bytes), else R32I; the shaders' isampler2D reads either.
    const ints = (a, largest, texels, what) => {
      const short = largest <= 32767;
      const view = short ? Int16Array.from(a) : new Int32Array(a.buffer, a.byteOffset, a.length);
      return made(dataTexture(gl, s, short ? gl.R16I : gl.R32I, gl.RED_INTEGER, short ? gl.SHORT : gl.INT, view, 1, texels, what)).tex;
    };
    this.vertexTex = made(dataTexture(gl, s, gl.RGB32F, gl.RGB, gl.FLOAT, data.positions, 3, Math.max(1, this.vertices), 'welded vertices')).tex;
    this.recordVerticesTex = ints(data.recordVertices, this.vertices - 1, Math.max(1, 2 * this.records), 'record vertices');
    this.triangleVerticesTex = ints(data.indices, this.vertices - 1, Math.max(1, 3 * this.triangles), 'triangle vertices');
    // Edge triangles are ±(triangle + 1).
    this.edgeTrianglesTex = ints(data.edgeTriangles, this.triangles, Math.max(1, this.records * this.maxMult), 'edge triangles');
    // The silhouette towards each light slot k (prepare(k, ...)): every triangle's orientation
    // (R8I, one per triangle) and the edge records of nonzero multiplicity (R32I, at most all),
    // and the key it was computed for (the light in this caster's space; null when culled,
    // which depends on the frame's receivers). A slot whose key matches the next frame's is
    // drawn as it is: a light and a caster that did not move cost neither the wasm's
    // silhouette nor an upload. Slot 0 at once, the others when a light first uses them.
    this.slots = [];
    this.slot = this.silhouetteSlot(0);
    // The receiver cull's textures (with `cull`): per light every vertex's far end and the
    // kept triangles.
    this.cull = null;
    if (data.cull) this.cull = this.cullTextures();
    // Whether the current light's silhouette is culled (prepare()) and clamped (finite far
    // ends), and its kept triangles.
    this.culled = false;
    this.clamped = false;
    this.keptTriangles = 0;
    // The polygons between the polygon and fan passes: the programs' shared storage.
    this.programs = programs;
    this.feedback = programs.feedback;
    this.emptyVao = programs.emptyVao;

    this.polygons = programs.polygons;
    this.fan = programs.fan;
  }

  /**
   * The textures of a culled or clamped silhouette: every welded vertex's far end (RGBA32F)
   * and the kept triangles (R32I). Made with the caster under `volumeCull`, else when a frame
   * first draws such a silhouette (an orthographic view's volumes closed beyond the box).
   */
  cullTextures() {
    const gl = this.gl;
    const s = this.shift;
    return {
      far: this.made(dataTexture(gl, s, gl.RGBA32F, gl.RGBA, gl.FLOAT, null, 4, Math.max(1, this.vertices), 'far vertices')).tex,
      kept: this.made(dataTexture(gl, s, gl.R32I, gl.RED_INTEGER, gl.INT, null, 1, Math.max(1, this.triangles), 'kept triangles')).tex,
    };
  }

  /** Bytes of this caster's own textures (its data, every light slot's silhouette, the cull's). */
  get gpuBytes() {
    return this.bytes;
  }

  /** Frees every GL object of this caster (not the shared programs). */
  dispose() {
    const gl = this.gl;
    for (const t of [this.vertexTex, this.recordVerticesTex, this.triangleVerticesTex, this.edgeTrianglesTex]) gl.deleteTexture(t);
    for (const slot of this.slots) for (const t of [slot.orientation?.tex, slot.recordList?.tex, slot.gpuOrientation?.tex]) if (t) gl.deleteTexture(t);
    if (this.cull) for (const t of Object.values(this.cull)) gl.deleteTexture(t);
    this.bytes = 0;
  }

  /** This caster's integer uniforms (the programs are shared: set before each use). */
  setUniforms(p, values) {
    const gl = this.gl;
    gl.useProgram(p.program);
    for (const [name, v] of Object.entries(values)) if (p.u[name]) gl.uniform1i(p.u[name], v);
  }

  bindTexture(unit, tex) {
    const gl = this.gl;
    gl.activeTexture(gl.TEXTURE0 + unit);
    gl.bindTexture(gl.TEXTURE_2D, tex);
    gl.activeTexture(gl.TEXTURE0);
  }

  /**
   * The welded vertices moved to `positions` (x y z each, this caster's space: a skinned or
   * morphed mesh's pose), read by the GPU silhouettes and every polygon after. Sets the plain
   * unpack state it needs (three.js sets its own per texture; resetState() after umbra's frame).
   */
  setVertices(positions) {
    const gl = this.gl;
    plainUnpack(gl);
    gl.bindTexture(gl.TEXTURE_2D, this.vertexTex);
    upload(gl, 2 ** this.shift, gl.RGB, gl.FLOAT, positions, 0, 3, this.vertices);
    gl.bindTexture(gl.TEXTURE_2D, null);
    // Every slot's silhouette was of the old vertices.
    for (const slot of this.slots) slot.key = null;
  }

  /** Light slot k's silhouette textures, made when first asked for. */
  silhouetteSlot(k) {
    while (this.slots.length <= k) {
      this.slots.push({
        // The wasm's silhouette: orientations (R8I) and the record list (R32I, sized to the
        // longest list so far, grown to the next power of two), made when first used.
        orientation: null,
        recordList: null,
        // The GPU silhouettes' orientations (R32I, what transform feedback captures), made
        // when first used.
        gpuOrientation: null,
        gpu: false,
        records: 0,
        single: 0,
        key: null,
      });
    }
    return this.slots[k];
  }

  /** Whether light slot k holds the unculled silhouette computed for `key` (prepare(k, null, key) then draws it). */
  holds(k, key) {
    return key !== null && k < this.slots.length && this.slots[k].key === key;
  }

  /**
   * Light slot k's silhouette, which draw() then draws: the wasm's Silhouette (`orientation`,
   * one Int8Array element per triangle, and `records`, the Int32Array of edge records of
   * nonzero multiplicity, the `single` ones of multiplicity ±1 first) into the slot's two
   * textures, remembered as computed for `key` (null: not to be reused); `silhouette` null:
   * the slot already holds the one for `key` (holds(k, key)), nothing uploaded. Culled (the
   * wasm's cull: also `triangles`, the Int32Array of kept triangles of nonzero orientation,
   * `far`, 4 floats per welded vertex, and `clamped`: false when every far end is at infinity)
   * also those two, and draw() then draws the culled volume. `silhouette` 'gpu': the
   * orientations computed on the GPU towards `light` (this caster's space; orientOnGpu), and
   * every record visited by the sides. Needs the unpack state the drawer sets (no flip, no
   * premultiply, no row length or skips, no unpack buffer).
   */
  prepare(k, silhouette, key = null, light = null) {
    const gl = this.gl;
    const width = 2 ** this.shift;
    const slot = this.silhouetteSlot(k);
    this.slot = slot;
    if (!silhouette) {
      if (!this.holds(k, key)) throw new Error(`umbra-three: light slot ${k} holds no silhouette for ${key}`);
      // An unculled silhouette: nothing of the cull's.
      this.culled = false;
      this.clamped = false;
      this.keptTriangles = 0;
      return;
    }
    if (silhouette === 'gpu') {
      this.orientOnGpu(slot, light);
      this.culled = false;
      this.clamped = false;
      this.keptTriangles = 0;
      slot.gpu = true;
      slot.records = this.records;
      slot.single = 0;
      slot.key = key;
      return;
    }
    slot.gpu = false;
    const { orientation, records, single, triangles = null, far = null, clamped = true } = silhouette;
    slot.orientation ??= this.made(dataTexture(gl, this.shift, gl.R8I, gl.RED_INTEGER, gl.BYTE, null, 1, this.triangles, 'triangle orientations'));
    if (!slot.recordList || slot.recordList.texels < records.length) {
      if (slot.recordList) {
        gl.deleteTexture(slot.recordList.tex);
        this.bytes -= slot.recordList.bytes;
      }
      const texels = Math.min(Math.max(1, this.records), 2 ** Math.ceil(Math.log2(Math.max(records.length, 256))));
      slot.recordList = { ...this.made(dataTexture(gl, this.shift, gl.R32I, gl.RED_INTEGER, gl.INT, null, 1, texels, 'silhouette records')), texels };
    }
    gl.bindTexture(gl.TEXTURE_2D, slot.orientation.tex);
    upload(gl, width, gl.RED_INTEGER, gl.BYTE, orientation, 0, 1, this.triangles);
    if (records.length) {
      gl.bindTexture(gl.TEXTURE_2D, slot.recordList.tex);
      upload(gl, width, gl.RED_INTEGER, gl.INT, records, 0, 1, records.length);
    }
    if (far && triangles && !this.cull) this.cull = this.cullTextures();
    this.culled = !!(far && triangles && this.cull);
    this.clamped = this.culled && clamped;
    this.keptTriangles = 0;
    if (this.culled) {
      // Bound to upload the far vertices and the kept triangles, as the silhouette above.
      gl.bindTexture(gl.TEXTURE_2D, this.cull.far);
      upload(gl, width, gl.RGBA, gl.FLOAT, far, 0, 4, this.vertices);
      if (triangles.length) {
        gl.bindTexture(gl.TEXTURE_2D, this.cull.kept);
        upload(gl, width, gl.RED_INTEGER, gl.INT, triangles, 0, 1, triangles.length);
      }
      this.keptTriangles = triangles.length;
    }
    gl.bindTexture(gl.TEXTURE_2D, null);
    slot.records = records.length;
    slot.single = single;
    // A culled silhouette depends on the frame's receivers: never reused.
    slot.key = this.culled ? null : key;
  }

  /**
   * Every triangle's orientation towards `light` (this caster's space) by the orientation
   * pass (glsl/orient.vert.glsl) into `slot`'s R32I texture: captured by transform feedback
   * (rasteriser off), then copied on the GPU through the unpack buffer binding.
   */
  orientOnGpu(slot, light) {
    const gl = this.gl;
    if (this.triangles === 0) return;
    const width = 2 ** this.shift;
    slot.gpuOrientation ??= this.made(dataTexture(gl, this.shift, gl.R32I, gl.RED_INTEGER, gl.INT, null, 1, this.triangles, 'GPU orientations'));
    const { program: O, buffer } = this.programs.orientation(this.triangles);
    this.setUniforms(O, { u_texture_shift: this.shift, u_vertices: UNIT_VERTICES, u_triangle_vertices: UNIT_TRIANGLE_VERTICES });
    gl.uniform4fv(O.u.u_light, light);
    this.bindTexture(UNIT_VERTICES, this.vertexTex);
    this.bindTexture(UNIT_TRIANGLE_VERTICES, this.triangleVerticesTex);
    gl.bindVertexArray(this.emptyVao);
    gl.bindTransformFeedback(gl.TRANSFORM_FEEDBACK, this.feedback);
    gl.bindBufferBase(gl.TRANSFORM_FEEDBACK_BUFFER, 0, buffer);
    gl.enable(gl.RASTERIZER_DISCARD);
    gl.beginTransformFeedback(gl.POINTS);
    gl.drawArrays(gl.POINTS, 0, this.triangles);
    gl.endTransformFeedback();
    gl.disable(gl.RASTERIZER_DISCARD);
    // WebGL forbids a buffer bound for transform feedback and for another use at once.
    gl.bindBufferBase(gl.TRANSFORM_FEEDBACK_BUFFER, 0, null);
    gl.bindTransformFeedback(gl.TRANSFORM_FEEDBACK, null);
    gl.bindVertexArray(null);
    gl.bindBuffer(gl.PIXEL_UNPACK_BUFFER, buffer);
    gl.bindTexture(gl.TEXTURE_2D, slot.gpuOrientation.tex);
    upload(gl, width, gl.RED_INTEGER, gl.INT, 0, 0, 1, this.triangles);
    gl.bindTexture(gl.TEXTURE_2D, null);
    gl.bindBuffer(gl.PIXEL_UNPACK_BUFFER, null);
    for (const unit of [UNIT_VERTICES, UNIT_TRIANGLE_VERTICES]) this.bindTexture(unit, null);
  }

  /**
   * The volumes into the stencil under the counting state the caller set and its viewport:
   * the sides of every silhouette edge, the light caps and (point lights) the dark caps, each
   * set through the polygon pass, then the fan pass. `clipFromWorld`: this caster's clip
   * from object matrix, the one the depth pass drew it with; `light` in object space. `farClipZ`: VolumeFrame::far_clip_z of
   * the depth convention (1 standard, 0 reversed-Z); `snap`, `viewport`: the snap=N diagnostic
   * (glsl/snap.glsl) and the viewport's size in pixels. `caps` false (z-pass): the sides only,
   * the caps' polygon and fan passes skipped (light caps lie on the far plane and dark caps at
   * infinity: under the strictly-nearer test z-pass never counts them). After prepare() for
   * the same light (its slot). A culled silhouette (prepare()) draws its sides to the far ends and its
   * far caps in both counts (a clamped far cap may lie in front of a sample), the light caps
   * of its kept triangles under z-fail. `tick(name)`, when given, is called after each polygon and fan pass (timing).
   * `trueCaps` (a caster with a one-sided material): { ranges, count }: after the volume, the
   * light caps at their true depth (polygons.vert.glsl u_mode 3) of the triangles of each
   * range, an Int32Array of [first, end, keepFront] triples (this caster's triangles; keepFront
   * 1 where the depth pass culls front faces, 0 back faces), drawn by the culled-faces fan pass
   * (fan.frag.glsl: only the faces the depth pass culls) after `count()`, the drawer's counting
   * state for them; a culled silhouette's kept triangles only, as its light caps.
   */
  draw({ clipFromWorld, light, farClipZ, snap = 0, viewport, caps = true, tick = null, trueCaps = null }) {
    const gl = this.gl;
    const P = this.polygons;
    const culled = this.culled;
    this.setUniforms(P, {
      u_texture_shift: this.shift, u_max_mult: this.maxMult,
      u_vertices: UNIT_VERTICES, u_edge_triangles: UNIT_EDGE_TRIANGLES, u_orientation: UNIT_ORIENTATION, u_records: UNIT_RECORDS,
      u_far: UNIT_FAR, u_record_vertices: UNIT_RECORD_VERTICES, u_triangle_vertices: UNIT_TRIANGLE_VERTICES, u_kept: UNIT_KEPT,
      u_culled: culled ? 1 : 0,
      u_all_records: this.slot.gpu ? 1 : 0,
      // A far cap all at infinity is the dark cap: only where the unclamped volume draws it.
      u_skip_infinite: caps && light[3] !== 0 ? 0 : 1,
    });
    gl.uniformMatrix4fv(P.u.u_clip_from_world, false, clipFromWorld);
    gl.uniform4fv(P.u.u_light, light);
    gl.uniform1f(P.u.u_far_clip_z, farClipZ);
    this.bindTexture(UNIT_EDGE_TRIANGLES, this.edgeTrianglesTex);
    this.bindTexture(UNIT_ORIENTATION, this.slot.gpu ? this.slot.gpuOrientation.tex : this.slot.orientation.tex);
    // The record list (the wasm's silhouettes only: the GPU's visit every record).
    this.bindTexture(UNIT_RECORDS, this.slot.gpu ? null : this.slot.recordList.tex);
    // The cull's units are bound either way: WebGL refuses a draw whose active sampler's unit
    // holds a texture of another type (three.js's, say); null reads as an incomplete texture.
    this.bindTexture(UNIT_FAR, culled ? this.cull.far : null);
    this.bindTexture(UNIT_KEPT, culled ? this.cull.kept : null);
    // The geometry's indices, read by every set (its vertices: bound in each, below).
    this.bindTexture(UNIT_RECORD_VERTICES, this.recordVerticesTex);
    this.bindTexture(UNIT_TRIANGLE_VERTICES, this.triangleVerticesTex);
    gl.bindVertexArray(this.emptyVao);
    // One set of polygons: the polygon pass over points `start` ..< `count`, then a fan pass
    // (program `fan`) per [first, end, repeat] range of `fans` (repeat: the potential copies
    // each polygon there is drawn with).
    const set = (mode, count, fans, start = 0, fan = this.fan) => {
      // In chunks of at most POLYGON_CHUNK polygons (the shared storage's most), each drawn
      // whole before the next is captured over it.
      for (let c0 = start; c0 < count; c0 += POLYGON_CHUNK) {
        const n = Math.min(POLYGON_CHUNK, count - c0);
        const storage = this.programs.polygonStorage(n);
        // Polygon pass: one point per record, its polygon captured; nothing rasterised. The
        // chunk's points are records c0 ..< c0 + n (gl_VertexID counts from drawArrays'
        // first), captured from the buffer's start.
        gl.useProgram(P.program);
        gl.uniform1i(P.u.u_mode, mode);
        // Bound again each chunk: the copy below binds the polygon texture on the active
        // unit, 0, the vertices' unit.
        this.bindTexture(UNIT_VERTICES, this.vertexTex);
        gl.bindTransformFeedback(gl.TRANSFORM_FEEDBACK, this.feedback);
        gl.bindBufferBase(gl.TRANSFORM_FEEDBACK_BUFFER, 0, storage.buffer);
        gl.enable(gl.RASTERIZER_DISCARD);
        gl.beginTransformFeedback(gl.POINTS);
        gl.drawArrays(gl.POINTS, c0, n);
        gl.endTransformFeedback();
        gl.disable(gl.RASTERIZER_DISCARD);
        // WebGL forbids a buffer bound for transform feedback and for another use at once.
        gl.bindBufferBase(gl.TRANSFORM_FEEDBACK_BUFFER, 0, null);
        gl.bindTransformFeedback(gl.TRANSFORM_FEEDBACK, null);
        // The polygons into their texture (a copy on the GPU side).
        gl.bindBuffer(gl.PIXEL_UNPACK_BUFFER, storage.buffer);
        gl.bindTexture(gl.TEXTURE_2D, storage.tex);
        upload(gl, 2 ** this.shift, gl.RGBA, gl.FLOAT, 0, 0, 4, POLYGON_TEXELS * n);
        gl.bindTexture(gl.TEXTURE_2D, null);
        gl.bindBuffer(gl.PIXEL_UNPACK_BUFFER, null);
        tick?.('volumes.polygons');
        // Fan pass: the polygons into the stencil, each range of `fans` cut to the chunk and
        // counted from its start.
        this.setUniforms(fan, { u_texture_shift: this.shift, u_polygons: UNIT_POLYGONS });
        this.bindTexture(UNIT_POLYGONS, storage.tex);
        gl.uniform1f(fan.u.u_far_clip_z, farClipZ);
        gl.uniform1f(fan.u.u_snap, snap);
        gl.uniform2f(fan.u.u_viewport_size, viewport[0], viewport[1]);
        for (const [from, to, repeat] of fans) {
          const first = Math.max(from, c0) - c0;
          const end = Math.min(to, c0 + n) - c0;
          if (end <= first) continue;
          const per = polygonsPerInstance(repeat);
          gl.uniform1i(fan.u.u_first, first);
          gl.uniform1i(fan.u.u_count, end);
          gl.uniform1i(fan.u.u_repeat, repeat);
          gl.uniform1i(fan.u.u_per_instance, per);
          gl.drawArraysInstanced(gl.TRIANGLES, 0, per * repeat * FAN_VERTICES, Math.ceil((end - first) / per));
        }
        tick?.('volumes.fans');
      }
    };
    // The sides: the listed records only (every other record's multiplicity is 0: no side).
    // Sides of multiplicity ±1 with one potential copy each, the others with maxMult.
    const n = this.slot.records;
    set(0, n, [[0, this.slot.single, 1], [this.slot.single, n, this.maxMult]]);
    if (culled) {
      // The kept triangles of nonzero orientation: light caps (z-fail), far caps (both).
      const kept = [[0, this.keptTriangles, 1]];
      if (caps) set(1, this.keptTriangles, kept);
      // Far caps: those of a clamped volume (both counts), else the dark caps at infinity
      // where the unclamped volume draws them (z-fail, point lights).
      if (this.clamped || (caps && light[3] !== 0)) set(2, this.keptTriangles, kept);
    } else if (caps) {
      const all = [[0, this.triangles, 1]];
      set(1, this.triangles, all);
      // A directional light's dark cap has zero area: none.
      if (light[3] !== 0) set(2, this.triangles, all);
    }
    if (trueCaps && trueCaps.ranges.length) {
      // The light caps at their true depth (docs/web.md, "FrontSide"), under the counting
      // state the drawer sets for them; per one-sided range, the faces its material culls.
      trueCaps.count();
      const fan = this.programs.culledFan();
      for (let i = 0; i < trueCaps.ranges.length; i += 3) {
        const [first, end, keepFront] = trueCaps.ranges.subarray(i, i + 3);
        gl.useProgram(P.program);
        gl.uniform2i(P.u.u_range, first, end);
        gl.useProgram(fan.program);
        gl.uniform1i(fan.u.u_keep_front, keepFront);
        // Culled: the kept triangles (those of the range pass the polygon pass's u_range);
        // else the range's own triangles.
        if (culled) set(3, this.keptTriangles, [[0, this.keptTriangles, 1]], 0, fan);
        else set(3, end, [[first, end, 1]], first, fan);
      }
    }
    // The units left unbound, as the other draws expect them.
    for (const unit of [UNIT_FAR, UNIT_RECORD_VERTICES, UNIT_TRIANGLE_VERTICES, UNIT_KEPT, UNIT_VERTICES]) this.bindTexture(unit, null);
    gl.bindVertexArray(null);
  }
}
