// The preprocessing of umbra-three, apart from any drawing API (the WebGL 2 drawer is
// webgl/; a WebGPU drawer would read the same buffers):
// * a caster's topology: of the buffers `umbra export` writes, the welded mesh, the welded
//   vertices of every edge record and the edge triangles (sides-data and caps-data repeat the
//   welded positions per record and triangle: the drawer reads them by index instead), and
//   its per-frame work (the z-pass test, the silhouette), computed from its
//   BufferGeometry's positions and index by umbra-geom compiled to WebAssembly
//   (../../umbra-geom-wasm), once per geometry version;
// * every drawn mesh's de-indexed triangles with their flat normals (flatTriangles), what the
//   depth and mask passes draw.
// Bad geometry (no positions, NaN, index out of range) is a TopologyError naming the mesh.
// No three.js import: geometries are read through their attributes' own accessors.
import { loadUmbraGeom, UmbraGeomError } from '../../umbra-geom-wasm/index.js';

export { UmbraGeomError };

/** A geometry umbra cannot prepare; the message starts with the mesh's name (or uuid). */
export class TopologyError extends Error {
  constructor(message) {
    super(message);
    this.name = 'TopologyError';
  }
}

/** How umbra names a mesh in its errors: its name, else its uuid. */
export function meshName(mesh) {
  return mesh.name || mesh.uuid;
}

/**
 * A position attribute as x y z floats: the array itself when it is a plain Float32Array of
 * item size 3, else read through getX/getY/getZ (interleaved, normalized or integer data).
 */
export function positionArray(attr) {
  if (!attr.isInterleavedBufferAttribute && attr.itemSize === 3 && attr.array instanceof Float32Array && !attr.normalized) {
    return attr.array.length === 3 * attr.count ? attr.array : attr.array.subarray(0, 3 * attr.count);
  }
  const out = new Float32Array(3 * attr.count);
  for (let i = 0; i < attr.count; i++) {
    out[3 * i] = attr.getX(i);
    out[3 * i + 1] = attr.getY(i);
    out[3 * i + 2] = attr.getZ(i);
  }
  return out;
}

/** The geometry's positions, or a TopologyError naming `name` when it has none. */
export function geometryPositions(geometry, name) {
  const attr = geometry?.attributes?.position;
  if (!attr || !attr.count) throw new TopologyError(`${name}: the geometry has no position attribute: the mesh is drawn but casts no shadow and is not in umbra's depth pass`);
  return positionArray(attr);
}

/**
 * The unit normal of triangle (a, b, c), given as offsets of its vertices' x in `p` (x y z per
 * vertex): umbra_geom::flat_normal (crates/umbra-geom/src/mesh.rs) in f64, counter-clockwise =
 * front, [0, 0, 0] for a zero-area triangle. Rounded to f32 by the caller's array.
 */
export function flatNormal(p, a, b, c) {
  const ux = p[b] - p[a];
  const uy = p[b + 1] - p[a + 1];
  const uz = p[b + 2] - p[a + 2];
  const wx = p[c] - p[a];
  const wy = p[c + 1] - p[a + 1];
  const wz = p[c + 2] - p[a + 2];
  const nx = uy * wz - uz * wy;
  const ny = uz * wx - ux * wz;
  const nz = ux * wy - uy * wx;
  const len = Math.sqrt(nx * nx + ny * ny + nz * nz);
  return len > 0 && Number.isFinite(len) ? [nx / len, ny / len, nz / len] : [0, 0, 0];
}

/**
 * The triangles of `positions` (x y z per vertex) and `index` (or none: every three vertices),
 * de-indexed, with each triangle's flat normal on its three vertices: umbra_geom::flat_normal
 * (crates/umbra-geom/src/mesh.rs) in f64, rounded to f32, zero for a zero-area triangle.
 * Triangles with an index out of range are left out (topology() reports them).
 */
export function flatTriangles(positions, index) {
  const vertices = positions.length / 3;
  const total = index ? Math.floor(index.length / 3) : Math.floor(vertices / 3);
  const pos = new Float32Array(9 * total);
  const nrm = new Float32Array(9 * total);
  let t = 0;
  for (let i = 0; i < total; i++) {
    const v = index ? [index[3 * i], index[3 * i + 1], index[3 * i + 2]] : [3 * i, 3 * i + 1, 3 * i + 2];
    if (!v.every((x) => x < vertices)) continue;
    const [a, b, c] = v.map((x) => [positions[3 * x], positions[3 * x + 1], positions[3 * x + 2]]);
    const unit = flatNormal(positions, 3 * v[0], 3 * v[1], 3 * v[2]);
    for (let k = 0; k < 3; k++) {
      pos.set([a, b, c][k], 9 * t + 3 * k);
      nrm.set(unit, 9 * t + 3 * k);
    }
    t++;
  }
  return { positions: pos.subarray(0, 9 * t), normals: nrm.subarray(0, 9 * t), triangles: t };
}

/** umbra-geom's WebAssembly module, ready to prepare casters. */
export class Topology {
  /**
   * Loads the module: `source` as loadUmbraGeom takes it (default: umbra_wasm.wasm beside
   * this module's file; in Node its bytes).
   */
  static async load(source) {
    return new Topology(await loadUmbraGeom(source));
  }

  constructor(geom) {
    this.geom = geom;
  }

  /**
   * The caster buffers of `geometry` (positions in its own space), named `name` in errors:
   * { maxMult, records, triangles, vertices, positions (welded, x y z each), indices (3 welded
   * vertices per triangle), recordVertices (A, B of every edge record), edgeTriangles, cull,
   * caster, ms }; `caster` is the geometry's per-frame work in the wasm (umbra-geom-wasm's
   * Caster: the z-pass test, the silhouette, the cull with `cull`; the
   * caller frees it). Throws TopologyError.
   */
  prepare(geometry, name, cull = false) {
    const positions = geometryPositions(geometry, name);
    const t0 = performance.now();
    let p;
    try {
      p = this.geom.prepare({ name, positions, index: geometry.index ? geometry.index.array.subarray(0, geometry.index.count) : null, caster: true });
    } catch (e) {
      if (e instanceof UmbraGeomError) throw new TopologyError(e.message);
      throw e;
    }
    return {
      maxMult: p.maxMult,
      records: p.counts.sidesDataRecords,
      triangles: p.counts.triangles,
      // Input triangles the welding dropped (degenerate): the welded triangles are the others,
      // in input order (sides.js weldedTriangleCounts).
      degenerate: p.counts.degenerateTriangles,
      vertices: p.counts.vertices,
      positions: p.positions,
      indices: p.indices,
      recordVertices: p.caster.recordVertices(),
      cull,
      edgeTriangles: p.edgeTriangles,
      caster: p.caster,
      ms: performance.now() - t0,
    };
  }
}
