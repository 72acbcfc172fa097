// The WebGL 2 frame of the viewer: multi-pass stencil shadow volumes (Heidmann 1991; Everitt &
// Kilgard 2002, z-fail with the infinite far plane) with paper 003's vertex-shader silhouettes
// (vs_silhouette.js), the same three passes as crates/umbra-gl/src/renderer.rs:
//   1. depth + ambient;
//   2. the volumes into the stencil (sides always, caps for z-fail), colour and depth masked;
//   3. lighting where stencil == 0, depth func EQUAL, additive.
// Depth convention (camera.rs DepthConvention; every choice below is derived from it, as in the
// native renderer):
// * standard (the default): the drawing buffer (24-bit depth, 8-bit stencil), clear depth 1,
//   LESS, u_far_clip_z = 1. WebGL 2 core; measured exact against the native method on the
//   default scene (docs/web.md);
// * reversed-Z with depth=reversed when the browser offers EXT_clip_control (WebGL 2 core has
//   no glClipControl):
//   clip control ZERO_TO_ONE, the frame drawn into the viewer's own DEPTH32F_STENCIL8 + RGBA8
//   framebuffer (the native renderer's target format; the drawing buffer's depth is fixed
//   point) and blitted to the canvas; clear depth 0, "strictly nearer" = GREATER, light caps at
//   u_far_clip_z = 0. Opt-in: on SwiftShader it disagrees with the native frame in a few
//   pixels more than the standard path on the default scene (docs/web.md).
// These are exactly VolumeFrame::far_clip_z / shadow_volume_state of the two conventions
// (shared/depth.glsl): the native shaders need no change for WebGL.
import { sidesVertexSource, capsVertexSource, fragmentSource, recordsPerInstance } from './vs_silhouette.js';
import sceneVert from './glsl/scene.vert.glsl';
import ambientFrag from './glsl/ambient.frag.glsl';
import litFrag from './glsl/lit.frag.glsl';

export class GlSetupError extends Error {}

/** The shading constants of FrameParams::default() (renderer.rs), so images are comparable. */
export const SHADING = {
  lightColor: [1, 1, 1],
  ambient: 0.15,
  albedo: [0.8, 0.8, 0.8],
  specular: 0.25,
  shininess: 32,
  background: [0.1, 0.12, 0.16, 1],
};

function compile(gl, type, name, src) {
  const s = gl.createShader(type);
  gl.shaderSource(s, src);
  gl.compileShader(s);
  if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) {
    const log = gl.getShaderInfoLog(s);
    gl.deleteShader(s);
    throw new GlSetupError(`${name}: compile failed: ${log}`);
  }
  return s;
}

function link(gl, name, vertName, vert, fragName, frag) {
  const p = gl.createProgram();
  const vs = compile(gl, gl.VERTEX_SHADER, vertName, vert);
  const fs = compile(gl, gl.FRAGMENT_SHADER, fragName, frag);
  gl.attachShader(p, vs);
  gl.attachShader(p, fs);
  gl.linkProgram(p);
  gl.deleteShader(vs);
  gl.deleteShader(fs);
  if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new GlSetupError(`${name}: link failed: ${gl.getProgramInfoLog(p)}`);
  const u = {};
  const n = gl.getProgramParameter(p, gl.ACTIVE_UNIFORMS);
  for (let i = 0; i < n; i++) {
    const info = gl.getActiveUniform(p, i);
    u[info.name] = gl.getUniformLocation(p, info.name);
  }
  return { program: p, u };
}

/** One record buffer and its vertex arrays (twin of mod.rs RecordArrays). */
function recordArrays(gl, data, vec4s, perInstance) {
  const records = data.length / (4 * vec4s);
  const recordBytes = 16 * vec4s;
  const stride = recordBytes * perInstance;
  const mainInstances = Math.floor(records / perInstance);
  const rest = records % perInstance;
  const buffer = gl.createBuffer();
  gl.bindBuffer(gl.ARRAY_BUFFER, buffer);
  // STATIC_DRAW: uploaded once per scene, read by every frame.
  gl.bufferData(gl.ARRAY_BUFFER, data, gl.STATIC_DRAW);
  const vao = (sets, base) => {
    const v = gl.createVertexArray();
    gl.bindVertexArray(v);
    for (let j = 0; j < sets; j++) {
      for (let f = 0; f < vec4s; f++) {
        const loc = j * vec4s + f;
        gl.vertexAttribPointer(loc, 4, gl.FLOAT, false, stride, base + (j * vec4s + f) * 16);
        gl.enableVertexAttribArray(loc);
        // Divisor 1: the record is the same for all of the instance's vertices (003 §2.6).
        gl.vertexAttribDivisor(loc, 1);
      }
    }
    return v;
  };
  const main = mainInstances > 0 ? vao(perInstance, 0) : null;
  const remainder = rest > 0 ? vao(rest, mainInstances * perInstance * recordBytes) : null;
  gl.bindVertexArray(null);
  gl.bindBuffer(gl.ARRAY_BUFFER, null);
  return {
    draw(vertices) {
      const count = vertices * perInstance;
      if (main) {
        gl.bindVertexArray(main);
        gl.drawArraysInstanced(gl.TRIANGLES, 0, count, mainInstances);
      }
      if (remainder) {
        // Disabled sets read the generic attribute value: all zero = an empty record.
        for (let loc = rest * vec4s; loc < perInstance * vec4s; loc++) gl.vertexAttrib4f(loc, 0, 0, 0, 0);
        gl.bindVertexArray(remainder);
        gl.drawArraysInstanced(gl.TRIANGLES, 0, count, 1);
        for (let loc = rest * vec4s; loc < perInstance * vec4s; loc++) gl.vertexAttrib4f(loc, 0, 0, 0, 1);
      }
    },
  };
}

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

    this.ambient = link(gl, 'ambient', 'glsl/scene.vert.glsl', sceneVert, 'glsl/ambient.frag.glsl', ambientFrag);
    this.lit = link(gl, 'lighting', 'glsl/scene.vert.glsl', sceneVert, 'glsl/lit.frag.glsl', litFrag);

    // Volumes: the layout of the export (maxMult planned for 16 attributes, the WebGL 2
    // minimum), records per instance from this browser's attribute count.
    const attribs = gl.getParameter(gl.MAX_VERTEX_ATTRIBS);
    const maxMult = m.max_mult;
    if (2 + maxMult > attribs) throw new GlSetupError(`maxMult ${maxMult} needs ${2 + maxMult} vertex attributes, this WebGL 2 has ${attribs}`);
    this.maxMult = maxMult;
    this.sidesPerInstance = recordsPerInstance(2 + maxMult, attribs);
    if (this.sidesPerInstance < 1) {
      throw new GlSetupError(`maxMult ${maxMult}: one edge record is ${16 * (2 + maxMult)} bytes, above WebGL's 255-byte vertex stride limit (maxMult <= 13 in WebGL 2)`);
    }
    this.capsPerInstance = recordsPerInstance(3, attribs);
    this.records = m.counts.sides_data_records;
    this.triangles = t;
    const frag = fragmentSource();
    this.sides = link(gl, 'vs-silhouette sides', 'vs_silhouette/sides.vert.glsl', sidesVertexSource(maxMult, this.sidesPerInstance), 'vs_silhouette/volume.frag.glsl', frag);
    this.caps = link(gl, 'vs-silhouette caps', 'vs_silhouette/caps.vert.glsl', capsVertexSource(this.capsPerInstance), 'vs_silhouette/volume.frag.glsl', frag);
    this.sidesData = recordArrays(gl, scene.sides_data, 2 + maxMult, this.sidesPerInstance);
    this.capsData = recordArrays(gl, scene.caps_data, 3, this.capsPerInstance);
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
      // Nothing of a volume may be clipped (state.rs): depth clamp when available.
      if (this.depthClamp) gl.enable(this.depthClamp.DEPTH_CLAMP_EXT);
      const bind = (p, capVertices) => {
        gl.useProgram(p.program);
        gl.uniformMatrix4fv(p.u.u_clip_from_world, false, f.clipFromWorld);
        gl.uniform4fv(p.u.u_light, f.light);
        // VolumeFrame::far_clip_z of the convention (shared/depth.glsl): 0 reversed-Z, 1 standard.
        if (p.u.u_far_clip_z) gl.uniform1f(p.u.u_far_clip_z, rz ? 0.0 : 1.0);
        if (p.u.u_cap_vertices) gl.uniform1i(p.u.u_cap_vertices, capVertices);
      };
      if (this.records > 0) {
        bind(this.sides, 0);
        this.sidesData.draw(6 * this.maxMult);
      }
      if (this.triangles > 0) {
        // A directional light's dark cap has zero area: only the light cap (mod.rs).
        const vertices = f.light[3] === 0 ? 3 : 6;
        bind(this.caps, vertices);
        this.capsData.draw(vertices);
      }
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
