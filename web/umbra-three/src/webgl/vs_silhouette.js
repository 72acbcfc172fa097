// vs-silhouette in WebGL 2: paper 003 (Milet et al., WebGL 1.0 shadows) Section 2, the
// shadow-volume sides (Alg. 1) and caps (Alg. 2) of every silhouette evaluated in vertex
// shaders from the preprocessed sides-data and caps-data (Section 2.6, Eq. 8 / Eq. 9), made
// exact on every WebGL 2 implementation the browser test runs (docs/web.md). Per frame:
//
// 1. the wasm (crates/umbra-wasm/src/silhouette.rs) orients every triangle ONCE, uploaded one
//    texel per triangle, and everything after reads that value (the export's edge_triangles
//    name the triangle behind each opposite slot of an edge), so no compiler contraction can
//    give a triangle two orientations (ES 3.00 has no `precise`); it also lists the edge
//    records of nonzero multiplicity (the silhouette), uploaded beside it;
// 2. the polygon pass (glsl/polygons.vert.glsl, transform feedback) turns every listed edge
//    record and every triangle into its side or cap polygon clipped to just inside the
//    viewport, and light caps to the near plane (glsl/clip.glsl), once: no rasteriser clips a
//    volume;
// 3. the fan pass (glsl/fan.vert.glsl) draws those polygons into the stencil.
//
// The scene's data live in textures read with texelFetch by element index
// (glsl/elements.glsl): neither WebGL's 255-byte attribute stride nor the 16-attribute limit
// bounds maxMult.
//
// Shader text: the native method's shared files (multiplicity.glsl: 001 Alg. 2-4;
// depth.glsl: 003 Eq. 6 and the near-plane distance; volume.frag.glsl; the ES 3.00 prelude and
// UMBRA_CULLED of vs_silhouette/mod.rs), read by umbra-three/build.mjs at build time as module
// `umbra:vs-silhouette`, and the package's own glsl/*.glsl.
import native from 'umbra:vs-silhouette';
import elementsGlsl from './glsl/elements.glsl';
import clipGlsl from './glsl/clip.glsl';
import polygonsVert from './glsl/polygons.vert.glsl';
import fanVert from './glsl/fan.vert.glsl';
import fanFrag from './glsl/fan.frag.glsl';
import snapGlsl from './glsl/snap.glsl';
import orientVert from './glsl/orient.vert.glsl';

export const sources = native;
export { snapGlsl, elementsGlsl };

const prelude = () => native.essl300Prelude + native.culledDefine;

export function polygonsVertexSource() {
  return `${prelude()}${native.multiplicity}\n${native.depth}\n${elementsGlsl}\n${clipGlsl}\n${polygonsVert}`;
}

/** `UMBRA_CULLED_FACES` defined: the fan pass of the true-depth light caps (polygons.vert.glsl
 * u_mode 3), which counts only the faces a depth pass culls (fan.frag.glsl). */
const culledFaces = (yes) => (yes ? '#define UMBRA_CULLED_FACES\n' : '');

export function fanVertexSource(culled = false) {
  return `${prelude()}${culledFaces(culled)}${native.depth}\n${elementsGlsl}\n${clipGlsl}\n${snapGlsl}\n${fanVert}`;
}

/** The orientation pass of the GPU silhouettes (glsl/orient.vert.glsl). */
export function orientVertexSource() {
  return `${prelude()}${native.multiplicity}\n${elementsGlsl}\n${orientVert}`;
}

/** The fragment shader of the polygon pass (nothing rasterised). */
export function volumeFragmentSource() {
  return `${prelude()}${native.volumeFrag}`;
}

/** The fan pass's fragment shader (colour writes off: stencil only; each fragment's depth kept
 * within its triangle's corners). */
export function fanFragmentSource(culled = false) {
  return `${prelude()}${culledFaces(culled)}${fanFrag}`;
}

/** The polygon pass's outputs, in the order they are captured (9 vec4 per polygon). */
export const POLYGON_VARYINGS = ['v_p0', 'v_p1', 'v_p2', 'v_p3', 'v_p4', 'v_p5', 'v_p6', 'v_p7', 'v_info'];

/** Vertices of one potential side or cap: the fan of a clipped polygon of up to 8 vertices
 * (glsl/clip.glsl UMBRA_CLIP_MAX, glsl/volume.vert.glsl UMBRA_FAN). */
export const FAN_VERTICES = 3 * (8 - 2);

/** Vertices per instance the volume draws aim for (a few thousand: llvmpipe runs its vertex
 * pipeline per instance, so instances should not be tiny). */
const VERTICES_PER_INSTANCE = 4096;

/** Polygons per instance of the fan pass for `repeat` potential copies per polygon. */
export function polygonsPerInstance(repeat) {
  return Math.max(1, Math.floor(VERTICES_PER_INSTANCE / (repeat * FAN_VERTICES)));
}

/** Width exponent of the data textures: 4096 texels wide, or the implementation's largest
 * power of two below that (WebGL 2 guarantees 2048). */
export function textureShift(maxTextureSize) {
  return Math.min(12, Math.floor(Math.log2(maxTextureSize)));
}

/** Rows a data texture of `texels` elements needs at width 2^shift (at least 1). */
export function textureRows(texels, shift) {
  return Math.max(1, Math.ceil(texels / 2 ** shift));
}
