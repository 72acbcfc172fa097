// Which faces three.js draws of a mesh, so that umbra's depth, position and mask passes show
// the surface three.js shows: a material's `side` culls as three.js culls it (FrontSide: back
// faces culled, BackSide: front faces, DoubleSide: none), per geometry group for a mesh with an
// array of materials. The volumes ignore this: casters cast from both faces.
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
