// The shadow volumes of one caster: paper 003's vs-silhouette (vs_silhouette.js) as WebGL 2
// objects. Owns the caster's data textures (from topology.js: the buffers `umbra export`
// writes), the orientation pass (its R8I target and framebuffer), the polygon pass (its
// transform-feedback buffer and the RGBA32F texture the polygons are copied to) and the fan
// pass, with programs shared by every caster (VolumePrograms); the drawer (drawer.js) owns the
// frame, calls prepare() per light and draw() under the counting state it set.
import { link, GlSetupError } from './program.js';
import {
  orientationVertexSource, pointFragmentSource, polygonsVertexSource, fanVertexSource, fanFragmentSource, volumeFragmentSource,
  POLYGON_VARYINGS, FAN_VERTICES, polygonsPerInstance, textureShift, textureRows,
} from './vs_silhouette.js';

/** Texels (vec4) per polygon of the polygon pass: 8 vertices and (count, repeat). */
const POLYGON_TEXELS = POLYGON_VARYINGS.length;

/**
 * An immutable texture of `texels` elements of `perTexel` components, 2^shift texels wide,
 * element i at (i mod width, i / width), filled from `data` (a typed array) when given.
 */
function dataTexture(gl, shift, internalFormat, format, type, data, perTexel, texels, what) {
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
  return { tex, width, rows };
}

/** `texels` elements into the bound texture, from `source` (a typed array, or a byte offset
 * into the bound PIXEL_UNPACK_BUFFER) at element `first`: the full rows, then the rest. Texels
 * of 4 bytes or more: every row starts aligned whatever UNPACK_ALIGNMENT is. */
function upload(gl, width, format, type, source, first, perTexel, texels) {
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
const UNIT_DATA = 0;
const UNIT_EDGE_TRIANGLES = 1;
const UNIT_ORIENTATION = 2;
const UNIT_POLYGONS = 3;

/** The three volume programs, linked once per context and shared by every caster. */
export class VolumePrograms {
  /** @param {WebGL2RenderingContext} gl */
  constructor(gl) {
    const frag = volumeFragmentSource();
    this.shift = textureShift(gl.getParameter(gl.MAX_TEXTURE_SIZE));
    this.orient = link(gl, 'orientation pass', 'glsl/orientation.vert.glsl', orientationVertexSource(), 'glsl/point.frag.glsl', pointFragmentSource());
    this.polygons = link(gl, 'polygon pass', 'glsl/polygons.vert.glsl', polygonsVertexSource(), 'vs_silhouette/volume.frag.glsl', frag, POLYGON_VARYINGS);
    this.fan = link(gl, 'fan pass', 'glsl/fan.vert.glsl', fanVertexSource(), 'glsl/fan.frag.glsl', fanFragmentSource());
    this.gl = gl;
  }

  dispose() {
    for (const p of [this.orient, this.polygons, this.fan]) this.gl.deleteProgram(p.program);
  }
}

export class ShadowVolumes {
  /**
   * @param {WebGL2RenderingContext} gl
   * @param {VolumePrograms} programs
   * @param {{maxMult: number, records: number, triangles: number, sides: Float32Array, caps: Float32Array, edgeTriangles: Int32Array}} data
   *   one caster's buffers (topology.js), in the caster's own (object) space
   */
  constructor(gl, programs, data) {
    this.gl = gl;
    this.maxMult = data.maxMult;
    this.records = data.records;
    this.triangles = data.triangles;
    const s = programs.shift;
    this.shift = s;
    this.sidesTex = dataTexture(gl, s, gl.RGBA32F, gl.RGBA, gl.FLOAT, data.sides, 4, this.records * (2 + this.maxMult), 'sides-data').tex;
    this.capsTex = dataTexture(gl, s, gl.RGBA32F, gl.RGBA, gl.FLOAT, data.caps, 4, 3 * this.triangles, 'caps-data').tex;
    this.edgeTrianglesTex = dataTexture(gl, s, gl.R32I, gl.RED_INTEGER, gl.INT, data.edgeTriangles, 1, Math.max(1, this.records * this.maxMult), 'edge triangles').tex;
    // The orientations: R8I (integer formats are colour-renderable in ES 3.0), one per triangle.
    this.orientation = dataTexture(gl, s, gl.R8I, gl.RED_INTEGER, gl.BYTE, null, 1, this.triangles, 'triangle orientations');
    this.orientationFbo = gl.createFramebuffer();
    gl.bindFramebuffer(gl.FRAMEBUFFER, this.orientationFbo);
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, this.orientation.tex, 0);
    const status = gl.checkFramebufferStatus(gl.FRAMEBUFFER);
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    if (status !== gl.FRAMEBUFFER_COMPLETE) throw new GlSetupError(`the R8I orientation framebuffer is incomplete (0x${status.toString(16)})`);
    // The polygons of one set (sides, light caps or dark caps) at a time: one capture buffer
    // and one texture for the largest set, reused by the three.
    const polygons = Math.max(this.records, this.triangles, 1);
    this.polygonBuffer = gl.createBuffer();
    gl.bindBuffer(gl.TRANSFORM_FEEDBACK_BUFFER, this.polygonBuffer);
    // DYNAMIC_COPY: written by the GPU (transform feedback) and read by the GPU, every frame.
    gl.bufferData(gl.TRANSFORM_FEEDBACK_BUFFER, 16 * POLYGON_TEXELS * polygons, gl.DYNAMIC_COPY);
    gl.bindBuffer(gl.TRANSFORM_FEEDBACK_BUFFER, null);
    this.polygonTex = dataTexture(gl, s, gl.RGBA32F, gl.RGBA, gl.FLOAT, null, 4, POLYGON_TEXELS * polygons, 'volume polygons').tex;
    this.feedback = gl.createTransformFeedback();

    // The orientation pass reads caps-data as attributes: one point per triangle.
    this.capsVao = gl.createVertexArray();
    gl.bindVertexArray(this.capsVao);
    const caps = gl.createBuffer();
    gl.bindBuffer(gl.ARRAY_BUFFER, caps);
    // STATIC_DRAW: uploaded once per scene, read by every frame.
    gl.bufferData(gl.ARRAY_BUFFER, data.caps, gl.STATIC_DRAW);
    this.capsBuffer = caps;
    for (let k = 0; k < 3; k++) {
      gl.vertexAttribPointer(k, 4, gl.FLOAT, false, 48, 16 * k);
      gl.enableVertexAttribArray(k);
    }
    gl.bindVertexArray(null);
    gl.bindBuffer(gl.ARRAY_BUFFER, null);
    // The other passes read textures only: an empty vertex array.
    this.emptyVao = gl.createVertexArray();

    this.orient = programs.orient;
    this.polygons = programs.polygons;
    this.fan = programs.fan;
  }

  /** Frees every GL object of this caster (not the shared programs). */
  dispose() {
    const gl = this.gl;
    for (const t of [this.sidesTex, this.capsTex, this.edgeTrianglesTex, this.orientation.tex, this.polygonTex]) gl.deleteTexture(t);
    gl.deleteFramebuffer(this.orientationFbo);
    gl.deleteBuffer(this.polygonBuffer);
    gl.deleteBuffer(this.capsBuffer);
    gl.deleteTransformFeedback(this.feedback);
    gl.deleteVertexArray(this.capsVao);
    gl.deleteVertexArray(this.emptyVao);
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
   * The orientation pass: every triangle's orientation towards `light` (in this caster's
   * space) into the R8I texture. Leaves the framebuffer unbound, depth, stencil, blend and cull off and colour
   * writes on (the renderer sets its own state after).
   */
  prepare(light) {
    const gl = this.gl;
    gl.bindFramebuffer(gl.FRAMEBUFFER, this.orientationFbo);
    gl.viewport(0, 0, this.orientation.width, this.orientation.rows);
    // One fragment per point, written as is: no tests, no blending, every channel.
    gl.disable(gl.DEPTH_TEST);
    gl.disable(gl.STENCIL_TEST);
    gl.disable(gl.BLEND);
    gl.disable(gl.CULL_FACE);
    gl.colorMask(true, true, true, true);
    this.setUniforms(this.orient, { u_texture_shift: this.shift, u_texture_rows: this.orientation.rows });
    gl.uniform4fv(this.orient.u.u_light, light);
    gl.bindVertexArray(this.capsVao);
    gl.drawArrays(gl.POINTS, 0, this.triangles);
    gl.bindVertexArray(null);
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
  }

  /**
   * The volumes into the stencil under the counting state the caller set and its viewport:
   * the sides of every silhouette edge, the light caps and (point lights) the dark caps, each
   * set through the polygon pass, then the fan pass. `clipFromWorld`: this caster's clip
   * from object matrix, the one the depth pass drew it with; `light` in object space. `farClipZ`: VolumeFrame::far_clip_z of
   * the depth convention (1 standard, 0 reversed-Z); `snap`, `viewport`: the snap=N diagnostic
   * (glsl/snap.glsl) and the viewport's size in pixels. After prepare() for the same light.
   */
  draw({ clipFromWorld, light, farClipZ, snap = 0, viewport }) {
    const gl = this.gl;
    const P = this.polygons;
    this.setUniforms(P, {
      u_texture_shift: this.shift, u_max_mult: this.maxMult,
      u_data: UNIT_DATA, u_edge_triangles: UNIT_EDGE_TRIANGLES, u_orientation: UNIT_ORIENTATION,
    });
    gl.uniformMatrix4fv(P.u.u_clip_from_world, false, clipFromWorld);
    gl.uniform4fv(P.u.u_light, light);
    gl.uniform1f(P.u.u_far_clip_z, farClipZ);
    this.bindTexture(UNIT_EDGE_TRIANGLES, this.edgeTrianglesTex);
    this.bindTexture(UNIT_ORIENTATION, this.orientation.tex);
    gl.bindVertexArray(this.emptyVao);
    const set = (mode, data, count, repeat) => {
      if (count === 0) return;
      // Polygon pass: one point per record, its polygon captured; nothing rasterised.
      gl.useProgram(P.program);
      gl.uniform1i(P.u.u_mode, mode);
      this.bindTexture(UNIT_DATA, data);
      gl.bindTransformFeedback(gl.TRANSFORM_FEEDBACK, this.feedback);
      gl.bindBufferBase(gl.TRANSFORM_FEEDBACK_BUFFER, 0, this.polygonBuffer);
      gl.enable(gl.RASTERIZER_DISCARD);
      gl.beginTransformFeedback(gl.POINTS);
      gl.drawArrays(gl.POINTS, 0, count);
      gl.endTransformFeedback();
      gl.disable(gl.RASTERIZER_DISCARD);
      // WebGL forbids a buffer bound for transform feedback and for another use at once.
      gl.bindBufferBase(gl.TRANSFORM_FEEDBACK_BUFFER, 0, null);
      gl.bindTransformFeedback(gl.TRANSFORM_FEEDBACK, null);
      // The polygons into their texture (a copy on the GPU side).
      gl.bindBuffer(gl.PIXEL_UNPACK_BUFFER, this.polygonBuffer);
      gl.bindTexture(gl.TEXTURE_2D, this.polygonTex);
      upload(gl, 2 ** this.shift, gl.RGBA, gl.FLOAT, 0, 0, 4, POLYGON_TEXELS * count);
      gl.bindTexture(gl.TEXTURE_2D, null);
      gl.bindBuffer(gl.PIXEL_UNPACK_BUFFER, null);
      // Fan pass: the polygons into the stencil.
      const per = polygonsPerInstance(repeat);
      this.setUniforms(this.fan, { u_texture_shift: this.shift, u_polygons: UNIT_POLYGONS });
      this.bindTexture(UNIT_POLYGONS, this.polygonTex);
      gl.uniform1i(this.fan.u.u_count, count);
      gl.uniform1f(this.fan.u.u_far_clip_z, farClipZ);
      gl.uniform1f(this.fan.u.u_snap, snap);
      gl.uniform2f(this.fan.u.u_viewport_size, viewport[0], viewport[1]);
      gl.uniform1i(this.fan.u.u_repeat, repeat);
      gl.uniform1i(this.fan.u.u_per_instance, per);
      gl.drawArraysInstanced(gl.TRIANGLES, 0, per * repeat * FAN_VERTICES, Math.ceil(count / per));
    };
    set(0, this.sidesTex, this.records, this.maxMult);
    set(1, this.capsTex, this.triangles, 1);
    // A directional light's dark cap has zero area: none.
    if (light[3] !== 0) set(2, this.capsTex, this.triangles, 1);
    gl.bindVertexArray(null);
  }
}
