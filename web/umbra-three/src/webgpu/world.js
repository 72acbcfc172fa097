// The frame's geometry for the WebGPU drawer, in world space: every caster's welded
// triangles (topology.js, wasm) moved by its world matrix, and every other drawn mesh's
// triangles, merged into one vertex buffer and one index buffer, casters first; and the
// casters' edge records in cs-silhouette's layout (crates/umbra-wgpu/src/methods/
// cs_silhouette.rs: per record (A, B, first slot, slot count), per slot `t << 1 | against`,
// the triangle behind the slot and whether it walks the edge from B to A).
//
// Why world space: the compute passes (umbra-wgpu's transform, orientation and sides WGSL)
// read one array of positions, so the whole frame is one dispatch per pass and light, and a
// mirroring world matrix needs no special case (the orientation is taken in world space, where
// the stencil counts). The positions are rounded to f32 once, here, from three.js's f64
// matrix: the same expression the tests write out for `umbra verify` (worldPositions).
// No three.js import: plain arrays, testable under node --test.
import { flatNormal } from '../topology.js';

/**
 * `local` (x y z per vertex, f32) moved by the column-major 4x4 `e` (three.js
 * Matrix4.elements, f64) and rounded once to f32: fround(e0 x + e4 y + e8 z + e12), ... The
 * fourth row is ignored (an affine matrix; a projective world matrix is refused by the caller).
 */
export function worldPositions(local, e, into = new Float32Array(local.length)) {
  for (let i = 0; i < local.length; i += 3) {
    const x = local[i];
    const y = local[i + 1];
    const z = local[i + 2];
    for (let r = 0; r < 3; r++) into[i + r] = e[r] * x + e[4 + r] * y + e[8 + r] * z + e[12 + r];
  }
  return into;
}

/**
 * A caster's edge records in cs-silhouette's layout, from the vs-silhouette tables the wasm
 * builds (umbra_geom::edge_triangles): `recordVertices` (A, B per record) and `edgeTriangles`
 * (`maxMult` slots per record, `sign (T + 1)`: + when T walks the edge A -> B, 0 unused).
 * Returns { records: Uint32Array (4 per record), slots: Uint32Array }; records with no used
 * slot are left out (they emit nothing).
 */
export function casterRecords(recordVertices, edgeTriangles, maxMult) {
  const count = recordVertices.length / 2;
  const records = new Uint32Array(4 * count);
  const slots = new Uint32Array(edgeTriangles.length);
  let r = 0;
  let s = 0;
  for (let e = 0; e < count; e++) {
    const first = s;
    for (let k = 0; k < maxMult; k++) {
      const v = edgeTriangles[e * maxMult + k];
      if (v === 0) continue;
      // Alg. 3's term is sign * orientation(T): `against` (bit 0) negates it in cs_sides.wgsl.
      slots[s++] = ((Math.abs(v) - 1) << 1) | (v < 0 ? 1 : 0);
    }
    if (s === first) continue;
    records.set([recordVertices[2 * e], recordVertices[2 * e + 1], first, s - first], 4 * r++);
  }
  return { records: records.subarray(0, 4 * r), slots: slots.subarray(0, s) };
}

/**
 * The merged frame: `parts` in order, each { positions (world, f32 x y z), indices (into its
 * own positions), records?, slots? } with the casters (those with records) first. Returns {
 * positions, indices, records, slots, casterVertices, casterTriangles, triangles, bounds }: the
 * casters' vertices and triangles are the first casterVertices / casterTriangles of the merged
 * arrays (what the compute passes visit); the rest are drawn only (depth).
 */
export function mergeParts(parts) {
  let vertices = 0;
  let indices = 0;
  let records = 0;
  let slots = 0;
  let casterVertices = 0;
  let casterTriangles = 0;
  let castersDone = false;
  for (const p of parts) {
    const caster = !!p.records;
    if (caster && castersDone) throw new Error('mergeParts: casters must come first');
    if (!caster) castersDone = true;
    vertices += p.positions.length / 3;
    indices += p.indices.length;
    if (caster) {
      records += p.records.length;
      slots += p.slots.length;
      casterVertices += p.positions.length / 3;
      casterTriangles += p.indices.length / 3;
    }
  }
  const out = {
    positions: new Float32Array(3 * vertices),
    indices: new Uint32Array(indices),
    records: new Uint32Array(records),
    slots: new Uint32Array(slots),
    casterVertices,
    casterTriangles,
    triangles: indices / 3,
    // The world box of every drawn position (min x y z, max x y z): every sample lies in it.
    bounds: [Infinity, Infinity, Infinity, -Infinity, -Infinity, -Infinity],
  };
  let v = 0;
  let i = 0;
  let r = 0;
  let s = 0;
  for (const p of parts) {
    const t = i / 3;
    out.positions.set(p.positions, 3 * v);
    for (let k = 0; k < p.positions.length; k++) {
      const x = p.positions[k];
      const axis = k % 3;
      if (x < out.bounds[axis]) out.bounds[axis] = x;
      if (x > out.bounds[3 + axis]) out.bounds[3 + axis] = x;
    }
    for (let k = 0; k < p.indices.length; k++) out.indices[i + k] = p.indices[k] + v;
    if (p.records) {
      for (let k = 0; k < p.records.length; k += 4) {
        out.records[r + k] = p.records[k] + v;
        out.records[r + k + 1] = p.records[k + 1] + v;
        out.records[r + k + 2] = p.records[k + 2] + s;
        out.records[r + k + 3] = p.records[k + 3];
      }
      // A slot names its triangle in the caster (t << 1 | against): moved by the caster's first triangle.
      for (let k = 0; k < p.slots.length; k++) out.slots[s + k] = p.slots[k] + 2 * t;
      r += p.records.length;
      s += p.slots.length;
    }
    v += p.positions.length / 3;
    i += p.indices.length;
  }
  return out;
}

/**
 * The pieces of the merged casters (umbra_geom::silhouette::caster_pieces, the unit in which
 * umbra-wgpu's GPU cull drops volumes): triangles joined across every edge they share. From
 * `records` and `slots` (mergeParts'): the triangles of one record's slots, and of every record
 * of the same two vertices, are one piece. Returns { pieces: Uint32Array (per caster triangle,
 * numbered by each piece's first triangle), count }.
 */
export function casterPieces(records, slots, triangles) {
  const parent = new Uint32Array(triangles);
  for (let t = 0; t < triangles; t++) parent[t] = t;
  const find = (x) => {
    while (parent[x] !== x) {
      parent[x] = parent[parent[x]];
      x = parent[x];
    }
    return x;
  };
  const join = (a, b) => {
    const ra = find(a);
    const rb = find(b);
    if (ra !== rb) parent[Math.max(ra, rb)] = Math.min(ra, rb);
  };
  // The first triangle of each edge (A, B), over the records that split it.
  const firstOf = new Map();
  for (let r = 0; r < records.length; r += 4) {
    const [a, b, first, count] = [records[r], records[r + 1], records[r + 2], records[r + 3]];
    if (count === 0) continue;
    const key = `${a},${b}`;
    const t0 = firstOf.get(key) ?? slots[first] >>> 1;
    firstOf.set(key, t0);
    for (let k = 0; k < count; k++) join(t0, slots[first + k] >>> 1);
  }
  const pieces = new Uint32Array(triangles);
  let count = 0;
  for (let t = 0; t < triangles; t++) {
    const r = find(t);
    pieces[t] = r === t ? count++ : pieces[r];
  }
  return { pieces, count };
}

/**
 * One unit normal per triangle of `positions` (x y z per vertex, f32) and `indices` (3 per
 * triangle), as Float32Array(4 * triangles) (x y z 0): umbra_geom::flat_normal
 * (crates/umbra-geom/src/mesh.rs) in f64, rounded to f32, zero for a zero-area triangle;
 * counter-clockwise = front. What the facing pass reads (wgsl/surface.wgsl).
 */
export function triangleNormals(positions, indices, into = new Float32Array(4 * Math.floor(indices.length / 3))) {
  for (let t = 0; 3 * t + 2 < indices.length; t++) {
    into.set(flatNormal(positions, 3 * indices[3 * t], 3 * indices[3 * t + 1], 3 * indices[3 * t + 2]), 4 * t);
    into[4 * t + 3] = 0;
  }
  return into;
}
