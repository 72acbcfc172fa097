// vs-silhouette in WebGL 2: paper 003 (Milet et al., WebGL 1.0 shadows) Section 2, sides by
// Algorithm 1 and caps by Algorithm 2 in the vertex shader from sides-data and caps-data in
// the compact instanced layout of Section 2.6 (Eq. 8 / Eq. 9).
//
// The shader bodies are the native method's own files, included at build time by build.mjs
// (module `umbra:vs-silhouette`): sides.vert.glsl, caps.vert.glsl, volume.frag.glsl,
// shared/multiplicity.glsl, shared/depth.glsl, the ES 3.00 prelude and UMBRA_CULLED of
// vs_silhouette/mod.rs. What mod.rs GENERATES (the record-access code: R sets of vec4
// attributes and the function returning set r) is generated here by the same rules —
// recordAccess below is the line-for-line twin of mod.rs's record_access — and so are the
// GL calls: one static buffer per data set, R attribute sets per instance with divisor 1,
// a remainder instance whose missing sets read the all-zero generic value.
import native from 'umbra:vs-silhouette';

export const sources = native;

/** Twin of mod.rs `record_access`. */
export function recordAccess(structName, structBody, fn, fields, records) {
  let g = `#define UMBRA_RECORDS ${records}\nstruct ${structName} { ${structBody} };\n`;
  for (let r = 0; r < records; r++) {
    for (let f = 0; f < fields.length; f++) g += `layout(location = ${r * fields.length + f}) in vec4 a_r${r}_${f};\n`;
  }
  g += `${structName} ${fn}(int r) {\n    ${structName} rec;\n`;
  for (let r = 0; r < records; r++) {
    const assign = fields.map((name, f) => ` rec.${name} = a_r${r}_${f};`).join('');
    const last = r + 1 === records;
    const guard = last ? '    {' : `    if (r == ${r}) {`;
    g += `${guard}${assign} }${last ? '' : ' else'}\n`;
  }
  g += '    return rec;\n}\n';
  return g;
}

const prelude = () => native.essl300Prelude + native.culledDefine;

/** Twin of mod.rs `sides_vertex_source(ShaderDialect::Essl300, ..)`. */
export function sidesVertexSource(maxMult, records) {
  const fields = ['a', 'b', ...Array.from({ length: maxMult }, (_, i) => `o[${i}]`)];
  const access = recordAccess('UmbraEdgeRecord', 'vec4 a; vec4 b; vec4 o[UMBRA_MAX_MULT];', 'umbra_edge_record', fields, records);
  return `${prelude()}#define UMBRA_MAX_MULT ${maxMult}\n${native.multiplicity}\n${native.depth}\n${access}\n${native.sidesVert}`;
}

/** Twin of mod.rs `caps_vertex_source(ShaderDialect::Essl300, ..)`. */
export function capsVertexSource(records) {
  const access = recordAccess('UmbraTriangleRecord', 'vec4 p0; vec4 p1; vec4 p2;', 'umbra_triangle_record', ['p0', 'p1', 'p2'], records);
  return `${prelude()}${native.multiplicity}\n${native.depth}\n${access}\n${native.capsVert}`;
}

export function fragmentSource() {
  return `${prelude()}${native.volumeFrag}`;
}

/** WebGL 2 refuses vertex-attribute strides above 255 bytes (WebGL 1.0 spec §6.9 "Vertex Attribute Data Stride",
 * kept by WebGL 2), a limit native GL does not have. */
export const MAX_STRIDE = 255;

/** Twin of mod.rs `records_per_instance`, further limited so that `records * 16 * vec4s`
 * (the stride of each attribute set) stays within WebGL's 255 bytes. 0 when even one record
 * is too large (maxMult 14: 16 x 16 = 256 bytes). The layout and bytes are unchanged: only
 * how many records one instance reads. */
export function recordsPerInstance(vec4s, attribs) {
  const native = Math.min(8, Math.max(1, Math.floor(attribs / Math.max(1, vec4s))));
  return Math.min(native, Math.floor(MAX_STRIDE / (16 * vec4s)));
}
