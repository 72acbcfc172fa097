// Which faces three.js draws of a mesh, so that umbra's depth, position and mask passes show
// the surface three.js shows: a material's `side` culls as three.js culls it (FrontSide: back
// faces culled, BackSide: front faces, DoubleSide: none), per geometry group for a mesh with an
// array of materials. The volumes cast from both faces of every caster; a caster's faces that its
// material culls also get their light caps counted at their true depth (culledCapRanges,
// drawer.js), since the surface seen through them lies behind them.
import { BackSide, DoubleSide, FrontSide } from 'three';

/** Cull codes of the ranges sidesOf returns (the drawer turns them into glCullFace). */
export const CULL_NONE = 0;
export const CULL_BACK = 1;
export const CULL_FRONT = 2;

/** The cull code of a material's side: FrontSide culls back faces, BackSide front faces. */
function cullOf(material) {
  switch (material.side) {
    case FrontSide:
      return CULL_BACK;
    case BackSide:
      return CULL_FRONT;
    case DoubleSide:
      return CULL_NONE;
    default:
      // Not a side three.js knows: three.js draws it as FrontSide (its default branch).
      return CULL_BACK;
  }
}

/**
 * The ranges of `geometry`'s de-indexed triangles (topology.js flatTriangles: triangle t is the
 * index range [3t, 3t + 3), vertices [3t, 3t + 3) of the drawn buffer) that three.js draws with
 * `material` (a mesh's), with their cull code: `[first vertex, vertex count, cull]` triples,
 * flat. `vertices`: the drawn buffer's vertex count. One range for a single material; with an
 * array of materials, one per geometry group whose material exists ([start, start + count)
 * indices: triangles [start / 3, (start + count) / 3)), as three.js draws an array of
 * materials: by groups only.
 * @param {import('three').Material|import('three').Material[]} material
 * @param {import('three').BufferGeometry} geometry
 * @param {number} vertices
 * @returns {Int32Array}
 */
export function sidesOf(material, geometry, vertices) {
  if (!Array.isArray(material)) return Int32Array.of(0, vertices, cullOf(material));
  const out = [];
  for (const g of geometry.groups) {
    const m = material[g.materialIndex];
    if (!m) continue;
    const first = 3 * Math.floor(g.start / 3);
    const end = Math.min(vertices, 3 * Math.floor((g.start + g.count) / 3));
    if (end > first) out.push(first, end - first, cullOf(m));
  }
  return Int32Array.from(out);
}

/**
 * Of a caster's `sides` (sidesOf), the ranges whose material culls a face, in the caster's
 * own (welded) triangles: `[first, end, keepFront]` triples, flat, adjacent ranges of one cull
 * joined; keepFront 1 where front faces are culled (BackSide), 0 where back faces are
 * (FrontSide). `weldedBefore`: for every input triangle t (and the count after the last), how
 * many of the triangles before it the welding kept (umbra_geom::weld drops the degenerate
 * ones, keeping the others' order); null when it dropped none. Empty for DoubleSide.
 * @param {Int32Array} sides
 * @param {Int32Array|null} weldedBefore
 * @returns {Int32Array}
 */
export function culledCapRanges(sides, weldedBefore) {
  const out = [];
  for (let i = 0; i < sides.length; i += 3) {
    const cull = sides[i + 2];
    if (cull === CULL_NONE) continue;
    const a = sides[i] / 3;
    const b = (sides[i] + sides[i + 1]) / 3;
    const first = weldedBefore ? weldedBefore[Math.min(a, weldedBefore.length - 1)] : a;
    const end = weldedBefore ? weldedBefore[Math.min(b, weldedBefore.length - 1)] : b;
    const keepFront = cull === CULL_FRONT ? 1 : 0;
    if (end <= first) continue;
    const n = out.length;
    if (n && out[n - 2] === first && out[n - 1] === keepFront) {
      out[n - 2] = end;
    } else {
      out.push(first, end, keepFront);
    }
  }
  return Int32Array.from(out);
}

/**
 * For every triangle of `positions` (x y z per vertex) and `index` (or none), the number of
 * triangles before it that umbra_geom::weld keeps, and the total after the last: it drops a
 * triangle two of whose vertices share a position (welding by exact position, -0 as +0).
 * @returns {Int32Array}
 */
export function weldedTriangleCounts(positions, index) {
  const vertices = positions.length / 3;
  const total = index ? Math.floor(index.length / 3) : Math.floor(vertices / 3);
  const out = new Int32Array(total + 1);
  const same = (u, v) => positions[3 * u] === positions[3 * v] && positions[3 * u + 1] === positions[3 * v + 1] && positions[3 * u + 2] === positions[3 * v + 2];
  let kept = 0;
  for (let t = 0; t < total; t++) {
    out[t] = kept;
    const [a, b, c] = index ? [index[3 * t], index[3 * t + 1], index[3 * t + 2]] : [3 * t, 3 * t + 1, 3 * t + 2];
    if (!(same(a, b) || same(b, c) || same(a, c))) kept++;
  }
  out[total] = kept;
  return out;
}
