// umbra's WebGL 2 drawer: the per-light shadow decision of every pixel, drawn into umbra's own
// render target before three.js draws the frame. Multi-pass stencil shadow volumes
// (Heidmann 1991; Everitt & Kilgard 2002, z-fail with the infinite far plane) with paper 003's
// vertex-shader silhouettes (volumes.js), the passes of crates/umbra-gl/src/renderer.rs:
//   1. depth of every visible mesh (depth.vert.glsl), once per frame;
//   per light (up to 4, a channel of the RGBA8 mask target each):
//   2. each caster's silhouette towards the light (the wasm's triangle orientations and edge
//      records of nonzero multiplicity) uploaded, then its volumes into the stencil
//      (sides always, caps for z-fail; volumes.js), colour and depth masked: z-pass from the
//      stencil start sum(W0) when the caller proved the eye's near pyramid inside one count
//      for every caster (f.zpass[k], umbra_geom::clearance), z-fail otherwise;
//   3. the mask pass (mask.frag.glsl): 1 into the light's channel where stencil == 0, depth
//      EQUAL and the seen side faces the light, 0 elsewhere.
// Meshes are drawn in their own space with their clip-from-object matrix, and volumes with the
// same matrix and the light moved into that space: rigid transforms change per frame without
// redoing the preprocessing, and a caster's sides meet its depth-pass surface bit for bit.
//
// The target: DEPTH32F_STENCIL8 + RGBA8 of the drawing buffer's size, so the user's canvas
// needs neither stencil nor depth, and antialiasing there changes nothing here (one sample per
// pixel). Depth convention (camera.rs DepthConvention; every choice below is derived from it):
// * reversed-Z (when the browser offers EXT_clip_control; WebGL 2 core has no glClipControl):
//   clip control ZERO_TO_ONE, clear depth 0, "strictly nearer" = GREATER, light caps at
//   u_far_clip_z = 0 — the native renderer's convention and depth format, so the oracle's band
//   (built for it) applies;
// * standard (without EXT_clip_control, or `depth: 'standard'`): DEPTH24_STENCIL8, clear
//   depth 1, LESS, u_far_clip_z = 1; its depth steps grow with the square of the distance.
// These are exactly VolumeFrame::far_clip_z / shadow_volume_state of the two conventions
// (shared/depth.glsl). No three.js import: the caller (umbra-shadows.js) hands in matrices.
import { ShadowVolumes, VolumePrograms, dataTexture, upload } from './volumes.js';
import { snapGlsl, elementsGlsl } from './vs_silhouette.js';
import { link, GlSetupError } from './program.js';
import { plainUnpack } from './unpack.js';
import { CULL_BACK, CULL_NONE } from '../sides.js';
import depthVert from './glsl/depth.vert.glsl';
import depthFrag from './glsl/depth.frag.glsl';
import maskFrag from './glsl/mask.frag.glsl';
import positionFrag from './glsl/position.frag.glsl';
import scatterVert from './glsl/scatter.vert.glsl';
import scatterFrag from './glsl/scatter.frag.glsl';

export { GlSetupError };

/** Lights one mask target holds: one per RGBA8 channel. */
export const MAX_LIGHTS = 4;

/** The flat normal of every triangle of `tri` (flatTriangles: the same one on its 3 vertices), one x y z each. */
function triangleNormals(tri) {
  const n = new Float32Array(3 * tri.triangles);
  for (let t = 0; t < tri.triangles; t++) n.set(tri.normals.subarray(9 * t, 9 * t + 3), 3 * t);
  return n;
}

export class WebGLDrawer {
  /**
   * @param {WebGL2RenderingContext} gl
   * @param {{depth?: 'reversed'|'standard', depthClamp?: boolean, volumeCull?: boolean|'auto', receiverScatter?: 'auto'|'gpu'|'cpu'}} opts
   *   volumeCull (true, false, or 'auto', the default: on a software rasteriser only): the
   *   receiver maps' passes, when the context can render RGBA32F (EXT_color_buffer_float);
   *   `volumeCull` then says whether they are on, `volumeCullMessage` why not. The maps are read
   *   back every frame, so the main thread waits for the frame's depth pass: on a GPU that
   *   wait costs more than the fill the cull saves, and keeps the silhouettes from being
   *   kept across frames (cache); on a software rasteriser the fill is the frame. receiverScatter: where the samples are scattered into the maps: 'gpu' (a point
   *   per pixel into an R32F map with MAX blending, EXT_float_blend; the map read back),
   *   'cpu' (the positions read back, scattered in the wasm), 'auto' (default: 'cpu' on a
   *   software rasteriser, where a point per pixel costs more than the read-back, else 'gpu')
   */
  constructor(gl, opts = {}) {
    this.gl = gl;
    this.clipControl = opts.depth === 'standard' ? null : gl.getExtension('EXT_clip_control');
    this.reversedZ = !!this.clipControl;
    // Depth clamp (the native counting state enables it, state.rs shadow_volume_for): used
    // when the browser offers EXT_depth_clamp; without it the w = 0 vertices still land
    // exactly on the far plane (z_clip = w_clip: rows 2 and 3 of the infinite projection
    // have the same xyz), inside the clip volume.
    this.depthClamp = opts.depthClamp === false ? null : gl.getExtension('EXT_depth_clamp');
    const dbg = gl.getExtension('WEBGL_debug_renderer_info');
    this.rendererName = dbg ? gl.getParameter(dbg.UNMASKED_RENDERER_WEBGL) : gl.getParameter(gl.RENDERER);
    this.subpixelBits = gl.getParameter(gl.SUBPIXEL_BITS);
    // A CPU rasteriser (what a user without a GPU gets), whose costs differ from a GPU's: the
    // receiver cull's choices (receiverScatter, the clamp's cost per polygon) follow it.
    this.software = /SwiftShader|llvmpipe|softpipe|Software/i.test(this.rendererName);
    // Diagnostic (positionPass 'mrt'): the positions written by the depth pass itself instead of
    // a pass of their own over its depth.
    this.positionPass = opts.positionPass === 'mrt' ? 'mrt' : 'equal';

    const version = '#version 300 es\n';
    if (!depthVert.startsWith(version)) throw new GlSetupError('glsl/depth.vert.glsl must start with #version 300 es');
    const vert = `${version}precision highp float;\n${snapGlsl}\n${elementsGlsl}\n${depthVert.slice(version.length)}`;
    this.depthProgram = link(gl, 'depth pass', 'glsl/depth.vert.glsl', vert, 'glsl/depth.frag.glsl', depthFrag);
    this.maskProgram = link(gl, 'mask pass', 'glsl/depth.vert.glsl', vert, 'glsl/mask.frag.glsl', maskFrag);
    this.volumePrograms = new VolumePrograms(gl);
    this.target = null;
    this.maskTexture = null;
    // The receiver cull's passes (crates/umbra-wasm/src/cull.rs): the visible samples' world
    // positions in an RGBA32F target, scattered per light into its map (receiverScatter).
    // Its state changes are those of position.frag.glsl, scatter.vert.glsl and scatter().
    // getExtension: enables rendering to RGBA32F (and below, blending R32F) on this context.
    this.volumeCull = false;
    this.volumeCullMessage = null;
    this.cullTargets = null;
    this.receiverScatter = null;
    const cullAsked = opts.volumeCull === undefined || opts.volumeCull === 'auto' ? this.software : opts.volumeCull !== false;
    if (!cullAsked && opts.volumeCull !== false) {
      this.volumeCullMessage = `volumeCull is off: 'auto' culls on a software rasteriser only, and this is a GPU (${this.rendererName}), where reading the receiver maps back every frame would make the main thread wait for it; volumeCull: true turns it on`;
    }
    if (cullAsked) {
      if (!gl.getExtension('EXT_color_buffer_float')) {
        this.volumeCullMessage = 'volumeCull is off: this WebGL 2 context lacks EXT_color_buffer_float (the receiver maps are made of the visible samples\' RGBA32F world positions); every volume is drawn unculled';
      } else {
        const asked = opts.receiverScatter === 'gpu' || opts.receiverScatter === 'cpu' ? opts.receiverScatter : (this.software ? 'cpu' : 'gpu');
        // The GPU scatter blends 32-bit floats: without EXT_float_blend the wasm scatters.
        this.receiverScatter = asked === 'gpu' && gl.getExtension('EXT_float_blend') ? 'gpu' : 'cpu';
        this.positionProgram = link(gl, 'position pass', 'glsl/depth.vert.glsl', vert, 'glsl/position.frag.glsl', positionFrag);
        if (this.receiverScatter === 'gpu') {
          this.scatterProgram = link(gl, 'receiver scatter', 'glsl/scatter.vert.glsl', scatterVert, 'glsl/scatter.frag.glsl', scatterFrag);
          // The scatter reads textures only: an empty vertex array.
          this.emptyVao = gl.createVertexArray();
        }
        this.volumeCull = true;
      }
    }
  }

  /** The shadow volumes of one caster's prepared buffers (topology.js). */
  createVolumes(data) {
    return new ShadowVolumes(this.gl, this.volumePrograms, data);
  }

  /**
   * A mesh's de-indexed triangles (topology.js flatTriangles) as a vertex array of their
   * positions and an RGB32F texture of their flat normals, one texel per triangle (2^shift
   * wide, as the volumes' data textures; depth.vert.glsl).
   */
  createMeshBuffers(tri) {
    const gl = this.gl;
    const vao = gl.createVertexArray();
    gl.bindVertexArray(vao);
    const b = gl.createBuffer();
    gl.bindBuffer(gl.ARRAY_BUFFER, b);
    // STATIC_DRAW: uploaded once per geometry version, drawn by every frame.
    gl.bufferData(gl.ARRAY_BUFFER, tri.positions, gl.STATIC_DRAW);
    gl.vertexAttribPointer(0, 3, gl.FLOAT, false, 0, 0);
    gl.enableVertexAttribArray(0);
    gl.bindVertexArray(null);
    gl.bindBuffer(gl.ARRAY_BUFFER, null);
    // The flat normals: volumes.js's data texture, one RGB32F texel per triangle.
    plainUnpack(gl);
    const normals = dataTexture(gl, this.volumePrograms.shift, gl.RGB32F, gl.RGB, gl.FLOAT, triangleNormals(tri), 3, Math.max(1, tri.triangles), 'flat normals');
    return { vao, buffers: [b], normals: normals.tex, vertices: 3 * tri.triangles, bytes: tri.positions.byteLength + normals.bytes };
  }

  /**
   * Bytes of the drawer's own targets (mask RGBA8; depth-stencil counted at 8 bytes a pixel
   * for DEPTH32F_STENCIL8, 4 for DEPTH24_STENCIL8; the cull's RGBA32F positions and R32F map)
   * and of the volumes' shared polygon storage. The casters' and meshes' buffers are their own.
   */
  get gpuBytes() {
    let bytes = this.volumePrograms.gpuBytes;
    const t = this.target;
    if (t) bytes += t.width * t.height * (4 + (this.reversedZ ? 8 : 4));
    const c = this.cullTargets;
    if (c) bytes += c.width * c.height * 16 + c.side * 6 * c.side * 4;
    return bytes;
  }

  /** A mesh's buffers (createMeshBuffers) refilled with `tri` of the same triangle count (a posed mesh). */
  updateMeshBuffers(m, tri) {
    const gl = this.gl;
    if (3 * tri.triangles !== m.vertices) throw new Error(`umbra-three: a posed mesh has ${tri.triangles} triangles, its buffers ${m.vertices / 3}`);
    gl.bindBuffer(gl.ARRAY_BUFFER, m.buffers[0]);
    gl.bufferSubData(gl.ARRAY_BUFFER, 0, tri.positions);
    gl.bindBuffer(gl.ARRAY_BUFFER, null);
    plainUnpack(gl);
    gl.bindTexture(gl.TEXTURE_2D, m.normals);
    upload(gl, 2 ** this.volumePrograms.shift, gl.RGB, gl.FLOAT, triangleNormals(tri), 0, 3, tri.triangles);
    gl.bindTexture(gl.TEXTURE_2D, null);
  }

  deleteMeshBuffers(m) {
    const gl = this.gl;
    gl.deleteVertexArray(m.vao);
    for (const b of m.buffers) gl.deleteBuffer(b);
    gl.deleteTexture(m.normals);
  }

  /** umbra's target (depth-stencil + RGBA8 mask) of the drawing buffer's size; returns the framebuffer. */
  ensureTarget(width, height) {
    const gl = this.gl;
    if (this.target && this.target.width === width && this.target.height === height) return this.target.framebuffer;
    this.deleteTarget();
    const framebuffer = gl.createFramebuffer();
    const mask = gl.createTexture();
    gl.bindTexture(gl.TEXTURE_2D, mask);
    gl.texStorage2D(gl.TEXTURE_2D, 1, gl.RGBA8, width, height);
    // NEAREST: one level, complete without mipmaps; materials read it with texelFetch.
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.NEAREST);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.NEAREST);
    gl.bindTexture(gl.TEXTURE_2D, null);
    const depth = gl.createRenderbuffer();
    gl.bindRenderbuffer(gl.RENDERBUFFER, depth);
    // Float depth: reversed-Z keeps ~24 significant bits of n / d at every distance (camera.rs).
    gl.renderbufferStorage(gl.RENDERBUFFER, this.reversedZ ? gl.DEPTH32F_STENCIL8 : gl.DEPTH24_STENCIL8, width, height);
    gl.bindRenderbuffer(gl.RENDERBUFFER, null);
    gl.bindFramebuffer(gl.FRAMEBUFFER, framebuffer);
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, mask, 0);
    gl.framebufferRenderbuffer(gl.FRAMEBUFFER, gl.DEPTH_STENCIL_ATTACHMENT, gl.RENDERBUFFER, depth);
    const status = gl.checkFramebufferStatus(gl.FRAMEBUFFER);
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    if (status !== gl.FRAMEBUFFER_COMPLETE) throw new GlSetupError(`umbra's depth-stencil + RGBA8 framebuffer is incomplete (0x${status.toString(16)})`);
    this.target = { framebuffer, mask, depth, width, height };
    this.maskTexture = mask;
    return framebuffer;
  }

  /**
   * The receiver cull's targets for a frame of `width` x `height` (after ensureTarget) and maps
   * of `side` cells a side: the position target (RGBA32F, sharing umbra's depth-stencil) and
   * the map (R32F, side x 6 side: a point light's six faces, or a directional light's one).
   */
  ensureCullTargets(width, height, side) {
    const gl = this.gl;
    const c = this.cullTargets;
    if (c && c.width === width && c.height === height && c.side === side && c.depth === this.target.depth) return c;
    this.deleteCullTargets();
    const texture = (format, w, h) => {
      const t = gl.createTexture();
      // Bound only to set it up; unbound again below.
      gl.bindTexture(gl.TEXTURE_2D, t);
      gl.texStorage2D(gl.TEXTURE_2D, 1, format, w, h);
      // NEAREST: float textures are incomplete with filtering; both are read texel by texel.
      gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.NEAREST);
      gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.NEAREST);
      gl.bindTexture(gl.TEXTURE_2D, null);
      return t;
    };
    const framebuffer = (tex, depth) => {
      const fb = gl.createFramebuffer();
      // Bound only to attach and check it; the default framebuffer bound again after.
      gl.bindFramebuffer(gl.FRAMEBUFFER, fb);
      gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, tex, 0);
      if (depth) gl.framebufferRenderbuffer(gl.FRAMEBUFFER, gl.DEPTH_STENCIL_ATTACHMENT, gl.RENDERBUFFER, depth);
      const status = gl.checkFramebufferStatus(gl.FRAMEBUFFER);
      gl.bindFramebuffer(gl.FRAMEBUFFER, null);
      return { fb, status };
    };
    const positions = texture(gl.RGBA32F, width, height);
    const map = texture(gl.R32F, side, 6 * side);
    const p = framebuffer(positions, this.target.depth);
    const m = framebuffer(map, null);
    this.cullTargets = { width, height, side, depth: this.target.depth, positions, map, positionFbo: p.fb, mapFbo: m.fb, readRed: false };
    if (p.status !== gl.FRAMEBUFFER_COMPLETE || m.status !== gl.FRAMEBUFFER_COMPLETE) {
      this.deleteCullTargets();
      throw new GlSetupError(`the receiver maps' framebuffers are incomplete (0x${p.status.toString(16)}, 0x${m.status.toString(16)})`);
    }
    // How the map reads back: RED/FLOAT where the implementation offers it, else RGBA/FLOAT
    // (always allowed for a float colour buffer).
    // The implementation's read format is a property of the bound read framebuffer.
    gl.bindFramebuffer(gl.FRAMEBUFFER, m.fb);
    this.cullTargets.readRed = gl.getParameter(gl.IMPLEMENTATION_COLOR_READ_FORMAT) === gl.RED && gl.getParameter(gl.IMPLEMENTATION_COLOR_READ_TYPE) === gl.FLOAT;
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    return this.cullTargets;
  }

  deleteCullTargets() {
    const gl = this.gl;
    const c = this.cullTargets;
    if (!c) return;
    gl.deleteFramebuffer(c.positionFbo);
    gl.deleteFramebuffer(c.mapFbo);
    gl.deleteTexture(c.positions);
    gl.deleteTexture(c.map);
    this.cullTargets = null;
  }

  /**
   * Light k's receiver map (scatter.vert.glsl) from the position pass's samples, read back into
   * `cells` (faces * side * side floats, cell (face * side + j) * side + i; -Infinity empty).
   * `grid`: the wasm's grid parameters (crates/umbra-wasm/src/cull.rs Receivers::params);
   * `cells()`: that array (fetched after the GL calls, as a view of wasm memory).
   * Leaves umbra's target bound with blending off.
   */
  scatter(k, grid, width, height, cells, lap = null) {
    const gl = this.gl;
    const c = this.cullTargets;
    const side = grid[1];
    const faces = grid[0] === 0 ? 6 : 1;
    // The grid's light: a point light's position (the cube's centre), or w = 0 (the flat grid).
    const light = grid[0] === 0 ? [grid[2], grid[3], grid[4], 1] : [0, 0, 0, 0];
    const P = this.scatterProgram;
    // Into the map, one pixel per cell: the faces used, one above the other.
    gl.bindFramebuffer(gl.FRAMEBUFFER, c.mapFbo);
    gl.viewport(0, 0, side, faces * side);
    // Every cell starts empty: -Infinity, below every value (a float target: not clamped).
    gl.colorMask(true, true, true, true);
    gl.clearBufferfv(gl.COLOR, 0, [-Infinity, 0, 0, 0]);
    // No depth or stencil here (the map has none); MAX blending keeps each cell's largest value
    // (EXT_float_blend: blending a 32-bit float target).
    gl.disable(gl.DEPTH_TEST);
    gl.disable(gl.STENCIL_TEST);
    gl.enable(gl.BLEND);
    gl.blendEquation(gl.MAX);
    gl.useProgram(P.program);
    gl.uniform1i(P.u.u_positions, 0);
    gl.uniform1i(P.u.u_width, width);
    gl.uniform1i(P.u.u_light_bit, 1 << k);
    gl.uniform4fv(P.u.u_light, light);
    gl.uniform1i(P.u.u_side, side);
    gl.uniform1i(P.u.u_faces, faces);
    if (grid[0] !== 0) {
      gl.uniform3fv(P.u.u_origin, grid.subarray(5, 8));
      gl.uniform3fv(P.u.u_u, grid.subarray(8, 11));
      gl.uniform3fv(P.u.u_v, grid.subarray(11, 14));
      gl.uniform3fv(P.u.u_travel, grid.subarray(14, 17));
      gl.uniform2fv(P.u.u_lo, grid.subarray(17, 19));
      gl.uniform2fv(P.u.u_scale, grid.subarray(19, 21));
    }
    // The samples on unit 0 (u_positions); the points read textures only: an empty vertex array.
    gl.activeTexture(gl.TEXTURE0);
    gl.bindTexture(gl.TEXTURE_2D, c.positions);
    gl.bindVertexArray(this.emptyVao);
    gl.drawArrays(gl.POINTS, 0, width * height);
    lap?.('receivers.scatter');
    // Nothing of ours left bound for the passes after.
    gl.bindVertexArray(null);
    gl.bindTexture(gl.TEXTURE_2D, null);
    // Back to the blending the other passes assume: off, FUNC_ADD.
    gl.disable(gl.BLEND);
    gl.blendEquation(gl.FUNC_ADD);
    // Read into client memory: no pack buffer bound.
    gl.bindBuffer(gl.PIXEL_PACK_BUFFER, null);
    const n = faces * side * side;
    if (c.readRed) {
      gl.readPixels(0, 0, side, faces * side, gl.RED, gl.FLOAT, cells().subarray(0, n));
    } else {
      const rgba = new Float32Array(4 * n);
      gl.readPixels(0, 0, side, faces * side, gl.RGBA, gl.FLOAT, rgba);
      const out = cells();
      for (let i = 0; i < n; i++) out[i] = rgba[4 * i];
    }
    lap?.('receivers.read');
  }

  deleteTarget() {
    const gl = this.gl;
    this.deleteCullTargets();
    if (!this.target) return;
    gl.deleteFramebuffer(this.target.framebuffer);
    gl.deleteTexture(this.target.mask);
    gl.deleteRenderbuffer(this.target.depth);
    this.target = null;
    this.maskTexture = null;
  }

  /** Waits for the GPU (a 1-pixel readPixels, as paper 003 timed its frames). */
  sync() {
    const gl = this.gl;
    const px = new Uint8Array(4);
    // Read from umbra's RGBA8 target whatever is bound for drawing (a float map, say), then
    // give the read binding back.
    const bound = gl.getParameter(gl.READ_FRAMEBUFFER_BINDING);
    if (this.target) gl.bindFramebuffer(gl.READ_FRAMEBUFFER, this.target.framebuffer);
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, px);
    gl.bindFramebuffer(gl.READ_FRAMEBUFFER, bound);
  }

  /**
   * Draws one frame's decisions into the mask target. Leaves GL's default state behind it
   * (the caller then calls renderer.resetState()).
   * @param {{width: number, height: number, snap?: number, timing?: object|null,
   *   meshes: {buffers: object, clipFromObject: Float32Array, flip: number, sides?: Int32Array, lights: Float32Array[], volumes: ShadowVolumes|null,
   *     silhouette: ((k: number) => {silhouette: {orientation: Int8Array, records: Int32Array}|null, key: string|null, slot?: number})|null}[],
   *   lights: number, zpass?: (number|null)[]}} f  lights: how many (<= MAX_LIGHTS); mesh.lights[k]: light k in the mesh's space;
   *   zpass[k]: light k's z-pass stencil start (sum of W0 mod 256), or null/absent for z-fail;
   *   mesh.silhouette(k): a caster's silhouette towards light k, its key and the caster's slot
   *   that holds it (volumes.js prepare(); default k), culled or not, or silhouette null when
   *   that slot holds the one of that key already;
   *   cull (with `volumeCull` only): { side, grids: per light the wasm's grid parameters or null,
   *   cells(k): the wasm's cells of light k (a Float32Array view, fetched just before it is
   *   written), samples(n): the wasm's block for the frame's n floats of samples (the same),
   *   receive(k, fromSamples): builds light k's map from its cells or the samples, before its
   *   casters' silhouettes };
   *   mesh.world: its world-from-object matrix (f32), for the position pass;
   *   mesh.sides: the vertex ranges three.js draws and how it culls each (sides.js sidesOf;
   *   absent: every vertex, no culling);
   *   mesh.trueCaps: a caster's triangles of one-sided materials (sides.js culledCapRanges;
   *   absent or empty: none), whose light caps are also counted at their true depth
   */
  frame(f) {
    const gl = this.gl;
    const rz = this.reversedZ;
    const snap = f.snap || 0;
    const timing = f.timing;
    let t = timing ? performance.now() : 0;
    const lap = (name) => {
      if (!timing) return;
      this.sync();
      const now = performance.now();
      timing[name] = (timing[name] || 0) + (now - t);
      t = now;
    };
    // The parts of the volumes pass (volumes.silhouette, .polygons, .fans), inside its lap.
    let ts = 0;
    const tick = timing ? (name) => {
      this.sync();
      const now = performance.now();
      timing[name] = (timing[name] || 0) + (now - ts);
      ts = now;
    } : null;
    const fbo = this.ensureTarget(f.width, f.height);
    const bindTarget = () => {
      gl.bindFramebuffer(gl.FRAMEBUFFER, fbo);
      gl.viewport(0, 0, f.width, f.height);
    };
    // The receiver cull's targets first (making them binds framebuffers); a context that cannot
    // make them turns the cull off, with the reason, and draws every volume unculled.
    let cull = null;
    if (this.volumeCull && f.cull && f.cull.grids.some(Boolean)) {
      try {
        cull = this.ensureCullTargets(f.width, f.height, f.cull.side);
      } catch (e) {
        if (!(e instanceof GlSetupError)) throw e;
        this.volumeCull = false;
        this.volumeCullMessage = `volumeCull is off: ${e.message}; every volume is drawn unculled`;
      }
    }
    bindTarget();
    // The silhouettes are uploaded from wasm memory: plain unpacking (no flip or premultiply,
    // which three.js sets per texture; tight rows; no unpack buffer). resetState() restores
    // three.js's own after the frame.
    plainUnpack(gl);
    // Reversed-Z: clip z in [0, w].
    if (rz) this.clipControl.clipControlEXT(this.clipControl.LOWER_LEFT_EXT, this.clipControl.ZERO_TO_ONE_EXT);
    const nearer = rz ? gl.GREATER : gl.LESS;
    // Clear: every write mask on first (clears obey them); mask 0 = shadowed.
    gl.colorMask(true, true, true, true);
    gl.depthMask(true);
    gl.stencilMask(0xff);
    gl.clearColor(0, 0, 0, 0);
    gl.clearDepth(rz ? 0 : 1); // The far plane's depth (DepthConvention::far_depth).
    gl.clearStencil(0);
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT | gl.STENCIL_BUFFER_BIT);

    // Pass 1: depth. Strictly nearer wins, depth writes on, colour off; no stencil, no
    // blending; faces culled as three.js culls them (drawMeshes).
    gl.enable(gl.DEPTH_TEST);
    gl.depthFunc(nearer);
    gl.disable(gl.STENCIL_TEST);
    gl.disable(gl.BLEND);
    gl.colorMask(false, false, false, false);
    // The depth, position and mask passes draw each mesh's ranges with its materials' sides
    // (mesh.sides, sides.js): the surface three.js shows at a pixel is the one umbra decides
    // for. Reason for each state: CULL_FACE on with glCullFace(BACK) for FrontSide and
    // glCullFace(FRONT) for BackSide, off for DoubleSide (no inside to hide), as three.js
    // culls; glFrontFace stays CCW (GL's default, what gl_FrontFacing and u_flip in the mask
    // and position shaders assume), so for a mirroring world matrix, where three.js turns
    // glFrontFace to CW and culls the same face, the other face is culled here: the same
    // triangles. Culling off again after the pass: the volumes count both faces.
    const cullFace = (cull, flip) => ((cull === CULL_BACK) === (flip > 0) ? gl.BACK : gl.FRONT);
    const drawMeshes = (program, perMesh) => {
      gl.useProgram(program.program);
      gl.uniform1f(program.u.u_snap, snap);
      gl.uniform2f(program.u.u_viewport_size, f.width, f.height);
      // Each mesh's normals on unit 0 (u_normals; unused, and maybe inactive, in the depth pass).
      gl.uniform1i(program.u.u_texture_shift, this.volumePrograms.shift);
      if (program.u.u_normals) gl.uniform1i(program.u.u_normals, 0);
      gl.activeTexture(gl.TEXTURE0);
      gl.frontFace(gl.CCW);
      for (const m of f.meshes) {
        if (m.buffers.vertices === 0) continue;
        gl.uniformMatrix4fv(program.u.u_clip_from_world, false, m.clipFromObject);
        gl.bindTexture(gl.TEXTURE_2D, m.buffers.normals);
        perMesh?.(m);
        gl.bindVertexArray(m.buffers.vao);
        const sides = m.sides ?? Int32Array.of(0, m.buffers.vertices, CULL_NONE);
        for (let i = 0; i < sides.length; i += 3) {
          const cull = sides[i + 2];
          if (cull === CULL_NONE) {
            gl.disable(gl.CULL_FACE);
          } else {
            gl.enable(gl.CULL_FACE);
            gl.cullFace(cullFace(cull, m.flip));
          }
          gl.drawArrays(gl.TRIANGLES, sides[i], sides[i + 1]);
        }
      }
      gl.disable(gl.CULL_FACE);
      gl.bindVertexArray(null);
      gl.bindTexture(gl.TEXTURE_2D, null);
    };
    const positionUniforms = (P) => (m) => {
      gl.uniformMatrix4fv(P.u.u_world_from_object, false, m.world);
      const lights = new Float32Array(16);
      for (let k = 0; k < f.lights; k++) lights.set(m.lights[k], 4 * k);
      gl.uniform4fv(P.u['u_lights[0]'], lights);
      gl.uniform1i(P.u.u_light_count, f.lights);
      gl.uniform1f(P.u.u_flip, m.flip);
    };
    if (cull && this.positionPass === 'mrt') {
      // The depth pass itself writes every sample's world position (position.frag.glsl) into
      // the position target beside umbra's depth: cleared to w = -1 (no sample), colour writes
      // on. "Nearer or equal" wins, so that of coplanar fragments at one depth the LAST drawn
      // leaves its position and facing bits, as it leaves its decision in the mask pass (depth
      // EQUAL, last write wins); the depth itself is the same (the nearest).
      gl.bindFramebuffer(gl.FRAMEBUFFER, cull.positionFbo);
      gl.colorMask(true, true, true, true);
      gl.clearBufferfv(gl.COLOR, 0, [0, 0, 0, -1]);
      gl.depthFunc(rz ? gl.GEQUAL : gl.LEQUAL);
      drawMeshes(this.positionProgram, positionUniforms(this.positionProgram));
      // Back to the depth pass's state for what follows: colour writes off, strictly nearer.
      gl.colorMask(false, false, false, false);
      gl.depthFunc(nearer);
    } else {
      drawMeshes(this.depthProgram);
    }
    if (cull && this.positionPass !== 'mrt') {
      // Every visible sample's world position (position.frag.glsl) into the position target
      // beside umbra's depth, drawn over the depth pass's depth with depth EQUAL and no depth
      // writes, so the shader runs for the visible fragments only (the depth pass runs none);
      // cleared to w = -1 (no sample); colour writes on. Of coplanar fragments at one depth
      // the LAST drawn leaves its position and facing bits, as it leaves its decision in the
      // mask pass (the same test, the same order).
      gl.bindFramebuffer(gl.FRAMEBUFFER, cull.positionFbo);
      gl.colorMask(true, true, true, true);
      gl.clearBufferfv(gl.COLOR, 0, [0, 0, 0, -1]);
      gl.depthFunc(gl.EQUAL);
      gl.depthMask(false);
      drawMeshes(this.positionProgram, positionUniforms(this.positionProgram));
      // Back to the depth pass's state for what follows: colour writes off, depth writes on,
      // strictly nearer.
      gl.colorMask(false, false, false, false);
      gl.depthMask(true);
      gl.depthFunc(nearer);
    }
    lap('depth');
    if (cull && this.receiverScatter === 'cpu') {
      // Every pixel's sample (x y z w), read once into the wasm's memory for all lights' maps.
      // Into client memory: no pack buffer bound.
      gl.bindBuffer(gl.PIXEL_PACK_BUFFER, null);
      gl.readPixels(0, 0, f.width, f.height, gl.RGBA, gl.FLOAT, f.cull.samples(4 * f.width * f.height));
      lap('receivers.read');
    }
    bindTarget();

    for (let k = 0; k < f.lights; k++) {
      const casters = f.meshes.filter((m) => m.volumes);
      const start = f.zpass?.[k] ?? null;
      const zpass = start !== null;
      if (cull && casters.length && f.cull.grids[k]) {
        // Light k's receiver map, scattered on the GPU and read back, or scattered in the wasm
        // from the samples read above (its casters are culled against it when their
        // silhouettes are computed below).
        const gpu = this.receiverScatter === 'gpu';
        if (gpu) this.scatter(k, f.cull.grids[k], f.width, f.height, () => f.cull.cells(k), timing ? (name) => lap(name) : null);
        f.cull.receive(k, !gpu);
        bindTarget();
        lap('receivers.map');
      }
      if (casters.length) {
        // The count starts at 0 (z-fail), or at W0 (z-pass: the eye's near pyramid lies in
        // W0 volumes, so a sample's count W(p) - W0 + W0 is 0 exactly when it is lit).
        gl.stencilMask(0xff);
        gl.clearStencil(zpass ? start : 0);
        gl.clear(gl.STENCIL_BUFFER_BIT);
        gl.clearStencil(0);
        for (const m of casters) {
          const light = m.lights[k];
          // Each triangle of the caster oriented once towards the light, and its silhouette
          // records, from the wasm into the caster's textures of light slot k (nothing, when
          // they hold the silhouette of this light position already).
          if (tick) ts = performance.now();
          const s = m.silhouette(k);
          m.volumes.prepare(s.slot ?? k, s.silhouette, s.key, light);
          tick?.('volumes.silhouette');
          // Pass 2: counting (state.rs shadow_volume_for(zpass, convention)): stencil test
          // always passes; z-fail: back faces behind the sample +1, front faces behind it -1;
          // z-pass: front faces in front of it +1, back faces in front of it -1; wrapping
          // (exact modulo 256); depth func strictly nearer (caps at the far plane fail
          // everywhere, background included, so z-pass may leave them out); no depth or
          // colour writes; no culling (both faces count in one pass); CCW = outward = front, in
          // the caster's space: a mirroring world matrix (m.flip -1) turns every volume face's
          // winding on screen, so CW is its front there (else its counts would take the
          // opposite sign and cancel another caster's where their shadows overlap).
          gl.enable(gl.DEPTH_TEST);
          gl.enable(gl.STENCIL_TEST);
          gl.stencilFunc(gl.ALWAYS, 0, 0xff);
          gl.stencilMask(0xff);
          if (zpass) {
            gl.stencilOpSeparate(gl.FRONT, gl.KEEP, gl.KEEP, gl.INCR_WRAP);
            gl.stencilOpSeparate(gl.BACK, gl.KEEP, gl.KEEP, gl.DECR_WRAP);
          } else {
            gl.stencilOpSeparate(gl.FRONT, gl.KEEP, gl.DECR_WRAP, gl.KEEP);
            gl.stencilOpSeparate(gl.BACK, gl.KEEP, gl.INCR_WRAP, gl.KEEP);
          }
          gl.depthFunc(nearer);
          gl.depthMask(false);
          gl.colorMask(false, false, false, false);
          gl.frontFace(m.flip < 0 ? gl.CW : gl.CCW);
          // Nothing of a volume may be clipped (state.rs): depth clamp when available (the
          // volume program clips to the viewport, and light caps to the near plane, itself).
          if (this.depthClamp) gl.enable(this.depthClamp.DEPTH_CLAMP_EXT);
          // A caster whose material culls a face (FrontSide, BackSide; m.trueCaps, sides.js
          // culledCapRanges) may lie in front of the sample the depth pass shows through its
          // culled face, where its light cap pushed to the far plane (Eq. 6) counts as if it
          // lay behind: so those faces' light caps are also drawn at their true depth, the
          // same polygons, and counted where they lie strictly in front of the sample
          // (docs/web.md, "FrontSide: the surface three.js shows").
          const trueCaps = m.trueCaps?.length ? {
            ranges: m.trueCaps,
            count: () => {
              // Depth pass (strictly nearer): front faces +1, back faces -1, wrapping; depth
              // fail (the cap behind the sample, or the pushed cap's own samples): kept.
              // Under z-fail this undoes the pushed cap's count (its facing is the true cap's:
              // the push keeps x, y and w) where the cap lies in front of the sample; under
              // z-pass it is the crossing the count needs (the pushed caps are never drawn
              // there) and the state set above already.
              gl.stencilOpSeparate(gl.FRONT, gl.KEEP, gl.KEEP, gl.INCR_WRAP);
              gl.stencilOpSeparate(gl.BACK, gl.KEEP, gl.KEEP, gl.DECR_WRAP);
            },
          } : null;
          m.volumes.draw({ clipFromWorld: m.clipFromObject, light, farClipZ: rz ? 0.0 : 1.0, snap, viewport: [f.width, f.height], caps: !zpass, tick, trueCaps });
          if (this.depthClamp) gl.disable(this.depthClamp.DEPTH_CLAMP_EXT);
          // GL's default winding again for the passes after.
          gl.frontFace(gl.CCW);
        }
        lap('volumes');
      }
      // Pass 3: the decision into channel k only: cleared to 0 (shadowed), then 1 where the
      // stencil count is 0 on exactly the depth pass's surface (depth EQUAL, invariant
      // positions) and the surface faces the light. No depth or stencil writes.
      bindTarget();
      const channel = [0, 1, 2, 3].map((c) => c === k);
      gl.colorMask(...channel);
      gl.disable(gl.DEPTH_TEST);
      gl.disable(gl.STENCIL_TEST);
      gl.clear(gl.COLOR_BUFFER_BIT);
      gl.enable(gl.DEPTH_TEST);
      gl.depthMask(false);
      gl.depthFunc(gl.EQUAL);
      if (casters.length) {
        gl.enable(gl.STENCIL_TEST);
        gl.stencilFunc(gl.EQUAL, 0, 0xff);
        gl.stencilOp(gl.KEEP, gl.KEEP, gl.KEEP);
      }
      drawMeshes(this.maskProgram, (m) => {
        gl.uniform4fv(this.maskProgram.u.u_light, m.lights[k]);
        gl.uniform1f(this.maskProgram.u.u_flip, m.flip);
      });
      lap('mask');
    }

    // GL's defaults, as three.js's resetState() assumes them: clip control back to
    // NEGATIVE_ONE_TO_ONE (three.js sets its own when it uses reversed depth), masks on,
    // tests off, the default framebuffer.
    if (rz) this.clipControl.clipControlEXT(this.clipControl.LOWER_LEFT_EXT, this.clipControl.NEGATIVE_ONE_TO_ONE_EXT);
    gl.colorMask(true, true, true, true);
    gl.depthMask(true);
    gl.stencilMask(0xffffffff);
    gl.depthFunc(gl.LESS);
    gl.disable(gl.DEPTH_TEST);
    gl.disable(gl.STENCIL_TEST);
    gl.stencilFunc(gl.ALWAYS, 0, 0xffffffff);
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
  }

  /** Channel `channel` of the mask target: width * height bytes, rows top-down, 255 lit / 0 shadowed. */
  readMask(channel) {
    const gl = this.gl;
    if (!this.target) return null;
    const { width, height, framebuffer } = this.target;
    const rgba = new Uint8Array(4 * width * height);
    gl.bindFramebuffer(gl.FRAMEBUFFER, framebuffer);
    // Tightly packed rows: RGBA8 rows are always 4-byte aligned.
    gl.readPixels(0, 0, width, height, gl.RGBA, gl.UNSIGNED_BYTE, rgba);
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    const out = new Uint8Array(width * height);
    for (let y = 0; y < height; y++) {
      const src = (height - 1 - y) * width; // readPixels rows come bottom-up
      for (let x = 0; x < width; x++) out[y * width + x] = rgba[4 * (src + x) + channel] >= 128 ? 255 : 0;
    }
    return out;
  }

  dispose() {
    const gl = this.gl;
    this.deleteTarget();
    if (this.positionProgram) gl.deleteProgram(this.positionProgram.program);
    if (this.scatterProgram) {
      gl.deleteProgram(this.scatterProgram.program);
      gl.deleteVertexArray(this.emptyVao);
    }
    gl.deleteProgram(this.depthProgram.program);
    gl.deleteProgram(this.maskProgram.program);
    this.volumePrograms.dispose();
  }
}
