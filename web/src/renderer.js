// The WebGL 2 frame of the viewer: multi-pass stencil shadow volumes (Heidmann 1991; Everitt &
// Kilgard 2002, z-fail with the infinite far plane) with paper 003's vertex-shader silhouettes
// (vs_silhouette.js, volumes.js), the same three passes as crates/umbra-gl/src/renderer.rs,
// after a pass that orients every triangle once for the frame:
//   0. (shadows on) every triangle's orientation towards the light into a texture (volumes.js);
//   1. depth + ambient;
//   2. the volumes into the stencil (sides always, caps for z-fail; each set first turned into
//      clipped polygons by transform feedback, volumes.js), colour and depth masked;
//   3. lighting where stencil == 0, depth func EQUAL, additive.
// Depth convention (camera.rs DepthConvention; every choice below is derived from it, as in the
// native renderer):
// * reversed-Z (the default when the browser offers EXT_clip_control; WebGL 2 core has no
//   glClipControl): clip control ZERO_TO_ONE, the frame drawn into the viewer's own
//   DEPTH32F_STENCIL8 + RGBA8 framebuffer (the native renderer's convention and target
//   format) and blitted to the canvas; clear depth 0, "strictly nearer" = GREATER, light caps
//   at u_far_clip_z = 0. The native renderer's depth precision, so the oracle's band (built for
//   it) applies: ANGLE on llvmpipe is exact on the shared scenes only with it (docs/web.md);
// * standard (without EXT_clip_control, or depth=standard): the drawing buffer (24-bit fixed
//   point depth, 8-bit stencil), clear depth 1, LESS, u_far_clip_z = 1. WebGL 2 core; its
//   depth steps grow with the square of the distance, far coarser than reversed-Z's at the
//   scenes' far walls (1-2 samples outside the band per shared scene on llvmpipe).
// These are exactly VolumeFrame::far_clip_z / shadow_volume_state of the two conventions
// (shared/depth.glsl).
import { ShadowVolumes } from './volumes.js';
import { snapGlsl } from './vs_silhouette.js';
import { link, GlSetupError } from './program.js';
import sceneVert from './glsl/scene.vert.glsl';
import ambientFrag from './glsl/ambient.frag.glsl';
import litFrag from './glsl/lit.frag.glsl';

export { GlSetupError };

/** The shading constants of FrameParams::default() (crates/umbra-geom/src/frame.rs), so images are comparable. */
export const SHADING = {
  lightColor: [1, 1, 1],
  ambient: 0.15,
  albedo: [0.8, 0.8, 0.8],
  specular: 0.25,
  shininess: 32,
  background: [0.1, 0.12, 0.16, 1],
};

export class Renderer {
  /** @param {WebGL2RenderingContext} gl @param scene from loadScene */
  constructor(gl, scene, opts = {}) {
    this.gl = gl;
    const m = scene.manifest;
    this.manifest = m;
    this.clipControl = opts.standardDepth ? null : gl.getExtension('EXT_clip_control');
    this.reversedZ = !!this.clipControl;
    this.fbo = null;
    if (!this.reversedZ) {
      const stencilBits = gl.getParameter(gl.STENCIL_BITS);
      if (stencilBits < 8) throw new GlSetupError(`the WebGL 2 drawing buffer has ${stencilBits} stencil bits; shadow volumes need 8`);
    }
    // Depth clamp (the native counting state enables it, state.rs shadow_volume_for): used
    // when the browser offers EXT_depth_clamp; without it the w = 0 vertices still land
    // exactly on the far plane (z_clip = w_clip: rows 2 and 3 of the infinite projection
    // have the same xyz), inside the clip volume.
    this.depthClamp = opts.noDepthClamp ? null : gl.getExtension('EXT_depth_clamp');
    const dbg = gl.getExtension('WEBGL_debug_renderer_info');
    this.rendererName = dbg ? gl.getParameter(dbg.UNMASKED_RENDERER_WEBGL) : gl.getParameter(gl.RENDERER);

    // Scene: de-indexed, one flat normal per triangle on its three vertices.
    const t = m.counts.triangles;
    const pos = new Float32Array(9 * t);
    const nrm = new Float32Array(9 * t);
    for (let i = 0; i < t; i++) {
      for (let k = 0; k < 3; k++) {
        const v = scene.indices[3 * i + k];
        for (let c = 0; c < 3; c++) {
          pos[9 * i + 3 * k + c] = scene.positions[3 * v + c];
          nrm[9 * i + 3 * k + c] = scene.normals[3 * i + c];
        }
      }
    }
    this.sceneVertices = 3 * t;
    this.sceneVao = gl.createVertexArray();
    gl.bindVertexArray(this.sceneVao);
    for (const [loc, data] of [[0, pos], [1, nrm]]) {
      const b = gl.createBuffer();
      gl.bindBuffer(gl.ARRAY_BUFFER, b);
      gl.bufferData(gl.ARRAY_BUFFER, data, gl.STATIC_DRAW);
      gl.vertexAttribPointer(loc, 3, gl.FLOAT, false, 0, 0);
      gl.enableVertexAttribArray(loc);
    }
    gl.bindVertexArray(null);
    gl.bindBuffer(gl.ARRAY_BUFFER, null);

    // The scene vertex shader with snap.glsl (the snap=N diagnostic) after its #version line.
    const version = '#version 300 es\n';
    if (!sceneVert.startsWith(version)) throw new GlSetupError('glsl/scene.vert.glsl must start with #version 300 es');
    const sceneVertSrc = `${version}precision highp float;\n${snapGlsl}\n${sceneVert.slice(version.length)}`;
    this.ambient = link(gl, 'ambient', 'glsl/scene.vert.glsl', sceneVertSrc, 'glsl/ambient.frag.glsl', ambientFrag);
    this.lit = link(gl, 'lighting', 'glsl/scene.vert.glsl', sceneVertSrc, 'glsl/lit.frag.glsl', litFrag);

    // Volumes: paper 003's vs-silhouette (volumes.js), its data in textures.
    this.volumes = new ShadowVolumes(gl, scene);
  }

  /**
   * Draws one frame into the drawing buffer.
   * @param {{clipFromWorld: Float32Array, eye: number[], light: number[], shadows: boolean, mask: boolean, width: number, height: number}} f
   */
  /** The reversed-Z target (DEPTH32F_STENCIL8 + RGBA8) of the canvas's size. */
  target(width, height) {
    const gl = this.gl;
    if (this.fbo && this.fbo.width === width && this.fbo.height === height) return this.fbo.framebuffer;
    if (this.fbo) {
      gl.deleteFramebuffer(this.fbo.framebuffer);
      gl.deleteRenderbuffer(this.fbo.color);
      gl.deleteRenderbuffer(this.fbo.depth);
    }
    const framebuffer = gl.createFramebuffer();
    const color = gl.createRenderbuffer();
    const depth = gl.createRenderbuffer();
    gl.bindRenderbuffer(gl.RENDERBUFFER, color);
    gl.renderbufferStorage(gl.RENDERBUFFER, gl.RGBA8, width, height);
    gl.bindRenderbuffer(gl.RENDERBUFFER, depth);
    // Float depth: reversed-Z keeps ~24 significant bits of n / d at every distance (camera.rs).
    gl.renderbufferStorage(gl.RENDERBUFFER, gl.DEPTH32F_STENCIL8, width, height);
    gl.bindRenderbuffer(gl.RENDERBUFFER, null);
    gl.bindFramebuffer(gl.FRAMEBUFFER, framebuffer);
    gl.framebufferRenderbuffer(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.RENDERBUFFER, color);
    gl.framebufferRenderbuffer(gl.FRAMEBUFFER, gl.DEPTH_STENCIL_ATTACHMENT, gl.RENDERBUFFER, depth);
    const status = gl.checkFramebufferStatus(gl.FRAMEBUFFER);
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    if (status !== gl.FRAMEBUFFER_COMPLETE) throw new GlSetupError(`the DEPTH32F_STENCIL8 framebuffer is incomplete (0x${status.toString(16)}); try depth=standard`);
    this.fbo = { framebuffer, color, depth, width, height };
    return framebuffer;
  }

  draw(f) {
    const gl = this.gl;
    const S = SHADING;
    const rz = this.reversedZ;
    // Pass 0: each triangle oriented and each edge counted once for the frame (pass 2 reads them).
    if (f.shadows) this.volumes.prepare(f.light);
    // Reversed-Z: our own float depth-stencil target and clip z in [0, w].
    gl.bindFramebuffer(gl.FRAMEBUFFER, rz ? this.target(f.width, f.height) : null);
    if (rz) this.clipControl.clipControlEXT(this.clipControl.LOWER_LEFT_EXT, this.clipControl.ZERO_TO_ONE_EXT);
    const nearer = rz ? gl.GREATER : gl.LESS;
    gl.viewport(0, 0, f.width, f.height);
    // Clear: every write mask on first (clears obey them).
    gl.colorMask(true, true, true, true);
    gl.depthMask(true);
    gl.stencilMask(0xff);
    const bg = f.mask ? [0, 0, 0.5, 1] : S.background;
    gl.clearColor(bg[0], bg[1], bg[2], bg[3]);
    gl.clearDepth(rz ? 0 : 1); // The far plane's depth (DepthConvention::far_depth).
    gl.clearStencil(0);
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT | gl.STENCIL_BUFFER_BIT);

    // Pass 1: depth + ambient. Strictly nearer wins, writes on; no stencil, no blending, no
    // culling (two-sided surfaces: triangle soups have no inside).
    gl.enable(gl.DEPTH_TEST);
    gl.depthFunc(nearer);
    gl.disable(gl.STENCIL_TEST);
    gl.disable(gl.BLEND);
    gl.disable(gl.CULL_FACE);
    gl.useProgram(this.ambient.program);
    gl.uniformMatrix4fv(this.ambient.u.u_clip_from_world, false, f.clipFromWorld);
    gl.uniform1f(this.ambient.u.u_snap, f.snap || 0);
    gl.uniform2f(this.ambient.u.u_viewport_size, f.width, f.height);
    const a = f.mask ? [0, 0, 0] : S.albedo.map((x) => x * S.ambient);
    gl.uniform3fv(this.ambient.u.u_ambient_color, a);
    gl.bindVertexArray(this.sceneVao);
    gl.drawArrays(gl.TRIANGLES, 0, this.sceneVertices);

    if (f.shadows) {
      // Pass 2: z-fail counting (state.rs shadow_volume_for(false, convention)): stencil test
      // always passes; back faces behind the sample +1, front faces behind it -1, wrapping
      // (exact modulo 256); depth func strictly nearer (caps at the far plane fail
      // everywhere, background included); no depth or colour writes; no culling (both faces
      // count in one pass); CCW = outward = front.
      gl.enable(gl.STENCIL_TEST);
      gl.stencilFunc(gl.ALWAYS, 0, 0xff);
      gl.stencilMask(0xff);
      gl.stencilOpSeparate(gl.FRONT, gl.KEEP, gl.DECR_WRAP, gl.KEEP);
      gl.stencilOpSeparate(gl.BACK, gl.KEEP, gl.INCR_WRAP, gl.KEEP);
      gl.depthFunc(nearer);
      gl.depthMask(false);
      gl.colorMask(false, false, false, false);
      gl.frontFace(gl.CCW);
      // Nothing of a volume may be clipped (state.rs): depth clamp when available (the volume
      // program clips to the viewport, and light caps to the near plane, itself).
      if (this.depthClamp) gl.enable(this.depthClamp.DEPTH_CLAMP_EXT);
      // VolumeFrame::far_clip_z of the convention (shared/depth.glsl): 0 reversed-Z, 1 standard.
      this.volumes.draw({ clipFromWorld: f.clipFromWorld, light: f.light, farClipZ: rz ? 0.0 : 1.0, snap: f.snap || 0, viewport: [f.width, f.height] });
      if (this.depthClamp) gl.disable(this.depthClamp.DEPTH_CLAMP_EXT);
      gl.bindVertexArray(null);
      // Pass 3 tests stencil == 0 and keeps it.
      gl.stencilFunc(gl.EQUAL, 0, 0xff);
      gl.stencilOp(gl.KEEP, gl.KEEP, gl.KEEP);
    }

    // Pass 3: lighting on exactly the visible surface (depth EQUAL, invariant positions),
    // added onto the ambient (blend ONE, ONE), no depth writes.
    gl.colorMask(true, true, true, true);
    gl.depthMask(false);
    gl.depthFunc(gl.EQUAL);
    gl.enable(gl.BLEND);
    gl.blendFunc(gl.ONE, gl.ONE);
    gl.useProgram(this.lit.program);
    const u = this.lit.u;
    gl.uniformMatrix4fv(u.u_clip_from_world, false, f.clipFromWorld);
    gl.uniform1f(u.u_snap, f.snap || 0);
    gl.uniform2f(u.u_viewport_size, f.width, f.height);
    gl.uniform4fv(u.u_light, f.light);
    gl.uniform3fv(u.u_light_color, S.lightColor);
    gl.uniform3fv(u.u_eye, f.eye);
    gl.uniform3fv(u.u_albedo, S.albedo);
    gl.uniform1f(u.u_specular, S.specular);
    gl.uniform1f(u.u_shininess, S.shininess);
    gl.uniform1i(u.u_mask, f.mask ? 1 : 0);
    gl.bindVertexArray(this.sceneVao);
    gl.drawArrays(gl.TRIANGLES, 0, this.sceneVertices);
    gl.bindVertexArray(null);
    // Back to the defaults the next frame's clear and pass 1 expect.
    gl.disable(gl.BLEND);
    gl.disable(gl.STENCIL_TEST);
    gl.depthMask(true);
    gl.depthFunc(gl.LESS);
    if (rz) {
      // Clip control back to GL's default; the frame's colour to the canvas, pixel for pixel.
      this.clipControl.clipControlEXT(this.clipControl.LOWER_LEFT_EXT, this.clipControl.NEGATIVE_ONE_TO_ONE_EXT);
      gl.bindFramebuffer(gl.READ_FRAMEBUFFER, this.fbo.framebuffer);
      gl.bindFramebuffer(gl.DRAW_FRAMEBUFFER, null);
      gl.blitFramebuffer(0, 0, f.width, f.height, 0, 0, f.width, f.height, gl.COLOR_BUFFER_BIT, gl.NEAREST);
      gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    }
  }
}
