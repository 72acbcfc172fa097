// The page side of the tests that judge umbra-three's masks on the triangles the page drew
// (test/instances.test.mjs, ortho.test.mjs, webgpu.test.mjs): a browser ES module, served at
// /testlib/page-world.js and imported in the page. No three.js import: geometries are read
// through their attributes' own accessors, matrices as their `elements`.

/**
 * Appends the world-space triangles of `geometry` under the column-major 4x4 `e` (f64) to
 * `pos`, each coordinate rounded once to f32: Math.fround(e0 x + e4 y + e8 z + e12), the
 * expression umbra-three's own world-space positions use. `range` ({ indexStart, indexCount }:
 * a BatchedMesh geometry's) limits the index range; `posedBy` (a skinned or morphed mesh) reads
 * each vertex in its pose (getVertexPosition, f64).
 */
export function addWorldTriangles(pos, geometry, e, range = null, posedBy = null) {
  const p = geometry.attributes.position;
  const idx = geometry.index;
  const first = range ? range.indexStart : 0;
  const n = range ? range.indexCount : idx ? idx.count : p.count;
  const v = [0, 0, 0];
  for (let k = first; k < first + n; k++) {
    const i = idx ? idx.getX(k) : k;
    if (posedBy) {
      // Any Vector3 as the target: the mesh's own position's class, no three.js import here.
      const q = posedBy.getVertexPosition(i, posedBy.position.clone());
      v[0] = q.x;
      v[1] = q.y;
      v[2] = q.z;
    } else {
      v[0] = p.getX(i);
      v[1] = p.getY(i);
      v[2] = p.getZ(i);
    }
    for (let r = 0; r < 3; r++) pos.push(Math.fround(e[r] * v[0] + e[4 + r] * v[1] + e[8 + r] * v[2] + e[12 + r]));
  }
}

/**
 * umbra's near plane for a mesh file of the triangles `pos` (crates/umbra-cli/src/session.rs):
 * 1e-3 of the f32 diagonal of their bounds (a diagonal under 1e-6 counts as 1e-6).
 */
export function meshFileNear(pos) {
  const f = Math.fround;
  const lo = [Infinity, Infinity, Infinity];
  const hi = [-Infinity, -Infinity, -Infinity];
  for (let i = 0; i < pos.length; i++) {
    lo[i % 3] = Math.min(lo[i % 3], pos[i]);
    hi[i % 3] = Math.max(hi[i % 3], pos[i]);
  }
  const d = [0, 1, 2].map((a) => f(hi[a] - lo[a]));
  const diagonal = f(Math.sqrt(f(f(f(d[0] * d[0]) + f(d[1] * d[1])) + f(d[2] * d[2]))));
  return Math.max(diagonal, 1e-6) * 1e-3;
}

/** An OBJ of the triangles `pos` (x y z per vertex, three vertices per triangle, unwelded). */
export function trianglesObj(pos) {
  const lines = [];
  for (let i = 0; i < pos.length; i += 3) lines.push(`v ${pos[i]} ${pos[i + 1]} ${pos[i + 2]}`);
  for (let t = 0; t < pos.length / 9; t++) lines.push(`f ${3 * t + 1} ${3 * t + 2} ${3 * t + 3}`);
  return `${lines.join('\n')}\n`;
}
