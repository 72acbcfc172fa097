// Type declarations of index.js (hand-written; the module has no build step of its own).

/** A geometry umbra cannot prepare, or a module that cannot be loaded; the message names which. */
export class UmbraGeomError extends Error {
  name: 'UmbraGeomError';
}

/** What a three.js BufferGeometry holds: `geometry.attributes.position.array` and `geometry.index?.array`. */
export interface GeometryInput {
  /** Starts every error message (default "geometry"). */
  name?: string;
  /** x, y, z per vertex; finite. */
  positions: Float32Array | ArrayLike<number>;
  /** Three vertex numbers per triangle; without it, vertices 3t, 3t + 1, 3t + 2 form triangle t. */
  index?: Uint16Array | Uint32Array | ArrayLike<number> | null;
  /** Also build the geometry's per-frame work (PreparedGeometry.caster). */
  caster?: boolean;
}

/** The silhouette of a geometry towards one light: views of the module's memory, valid until the next call. */
export interface SilhouetteResult {
  /** Per triangle: +1 faces the light, -1 faces away, 0 edge-on (paper 001 Alg. 4, f32). */
  orientation: Int8Array;
  /** The sides-data records whose multiplicity is not 0: those of ±1 ascending, then the others ascending. */
  records: Int32Array;
  /** How many of `records` (the first ones) have multiplicity ±1. */
  single: number;
}

/**
 * The per-frame work of one prepared geometry, kept in the module's memory until free(): its
 * z-pass test (umbra_geom::clearance::ClearanceIndex::near_winding with its welded mesh and
 * edge adjacency) and its silhouette (crates/umbra-wasm/src/silhouette.rs).
 */
export interface Caster {
  /**
   * W0, the number of this geometry's shadow volumes every point of the hull of `points` (the
   * eye and the near-plane corners, x y z each, in the geometry's own space) lies in, towards
   * `light` (x y z w, w = 0 directional; the f32 value the volumes are drawn with); null when it
   * is not provably one count (z-fail).
   */
  nearWinding(points: Float64Array | ArrayLike<number>, light: Float32Array | ArrayLike<number>): number | null;
  /** Every triangle's orientation towards `light` (x y z w, the geometry's own space) and the records of nonzero multiplicity. */
  silhouette(light: Float32Array | ArrayLike<number>): SilhouetteResult;
  /**
   * The silhouette of the triangles `receivers`' map keeps (crates/umbra-wasm/src/cull.rs),
   * towards `light` (the geometry's own space, as its volumes are drawn), with every welded
   * vertex's far end; null when nothing was culled (no map, a matrix that is not affine).
   */
  cull(receivers: Receivers, place: CullPlace, light: Float32Array | ArrayLike<number>): CullResult | null;
  /**
   * Every volume of the caster closed at finite far ends beyond the world box `bounds` (an
   * orthographic view: umbra_geom::receivers::clamp_beyond_box), with the silhouette of the
   * kept triangles towards `light` (the caster's space): as cull()'s result, `clamped` true and
   * every kept vertex's far end finite. null when a matrix is not affine or a light not finite;
   * throws UmbraGeomError when a far end does not fit in an f32. Views valid until the next call.
   */
  clampBeyondBox(place: BoxPlace, light: Float32Array | ArrayLike<number>): CullResult | null;
  /** Its handle in the module (0 once freed). */
  readonly handle: number;
  /** The welded vertices A, B of every edge record (2 per record, sides-data's order). */
  recordVertices(): Uint32Array;
  /** Welded vertices. */
  readonly vertices: number;
  /** Frees the module memory it holds (nearWinding and silhouette then throw). */
  free(): void;
}

/** Where a caster is, for clampBeyondBox(): column-major f64 matrices, the world box and light. */
export interface BoxPlace {
  worldFromObject: ArrayLike<number>;
  objectFromWorld: ArrayLike<number>;
  /** min x y z, max x y z (world space): holds every visible sample and every caster vertex. */
  bounds: ArrayLike<number>;
  /** The light in world space (x y z w; w = 0 directional). */
  lightWorld: ArrayLike<number>;
}

/** Where a caster is, for cull(): column-major f64 matrices and the viewport. */
export interface CullPlace {
  worldFromObject: ArrayLike<number>;
  objectFromWorld: ArrayLike<number>;
  /** The clip-from-object matrix its volume is drawn with (the clamp's screen-area estimate). */
  clipFromObject: ArrayLike<number>;
  width: number;
  height: number;
  /** z-fail: light caps and (point lights) dark caps drawn. */
  zfail: boolean;
  /** What a polygon costs against a pixel of fill (default 0). */
  polygonPixels?: number;
  /** Clamp where it covers fewer pixels ('auto', default), 'always' or 'never'. */
  clamp?: 'auto' | 'always' | 'never';
}

/** A culled silhouette: views of the module's memory, valid until the next call. */
export interface CullResult extends SilhouetteResult {
  /** Triangles kept (any orientation). */
  kept: number;
  /** The kept triangles of nonzero orientation (their caps are drawn). */
  triangles: Int32Array;
  /** x y z w per welded vertex: its far end in the geometry's space (w = 0 at infinity). */
  far: Float32Array;
  /** Whether the far ends stayed clamped (else all at infinity). */
  clamped: boolean;
}

/** One light's receiver map in the module (crates/umbra-wasm/src/cull.rs Receivers). */
export interface Receivers {
  /** The grid of the world light over the world box [min xyz, max xyz], side cells a side (a power of two); its 24 parameters, or null when refused. */
  setGrid(light: ArrayLike<number>, bounds: ArrayLike<number>, side: number): Float32Array | null;
  /** The cells to fill before build(): a view of the module's memory. */
  cells(): Float32Array;
  /** The map from the cells (-Infinity: empty, NaN: unbounded). */
  build(): boolean;
  /** The map from samples (x y z w each; w < 0 or bit `bit` set: left out), scattered in the wasm. */
  buildFromSamples(samples: SamplesBuffer, bit: number): boolean;
  /** Raises the hull of world-space points (x y z each) into the map; false drops the map. */
  raise(points: Float64Array | ArrayLike<number>): boolean;
  free(): void;
}

/** A block of floats in the module's memory for the page's samples. */
export interface SamplesBuffer {
  /** A view of n floats (valid until the memory grows: fill it at once). */
  view(n: number): Float32Array;
  readonly length: number;
  free(): void;
}

/** The counts `umbra export` writes in its manifest, and what welding dropped. */
export interface PreparedCounts {
  /** Welded vertices. */
  vertices: number;
  /** Welded, non-degenerate triangles (t of paper 003's Eq. 9). */
  triangles: number;
  /** Unique edges. */
  edges: number;
  /** Edge records (e of Eq. 8; more than `edges` when some were split). */
  sidesDataRecords: number;
  /** Triangles of the input. */
  inputTriangles: number;
  /** Input triangles dropped because two of their welded vertices coincide. */
  degenerateTriangles: number;
}

/** The buffers of `umbra export`, byte for byte (copied out of the module's memory). */
export interface PreparedGeometry {
  /** positions.bin: welded positions, 3 per vertex. */
  positions: Float32Array;
  /** normals.bin: flat unit normal per triangle, 3 per triangle (0 for a zero-area one). */
  normals: Float32Array;
  /** indices.bin: 3 welded vertex numbers per triangle, counter-clockwise = front. */
  indices: Uint32Array;
  /** sides.bin: sides-data, (2 + maxMult) vec4 per edge record (Eq. 8). */
  sides: Float32Array;
  /** caps.bin: caps-data, 3 vec4 per triangle (Eq. 9). */
  caps: Float32Array;
  /** edge_triangles.bin: maxMult signed triangle numbers (±(T + 1), 0 unused) per edge record. */
  edgeTriangles: Int32Array;
  /** Opposite-vertex slots per edge record (at least 1, at most 14). */
  maxMult: number;
  counts: PreparedCounts;
  /** The per-frame work, when prepare() was asked for it (`caster: true`). */
  caster?: Caster;
  /** Bounds of the vertices the triangles use; null without triangles. */
  bounds: { min: [number, number, number]; max: [number, number, number] } | null;
}

export interface UmbraGeom {
  /** Welds and prepares a geometry; throws UmbraGeomError naming `name` and the bad element. */
  prepare(input: GeometryInput): PreparedGeometry;
  /** A new receiver map (one light's), freed by its free(). */
  receivers(): Receivers;
  /** A block for the page's samples, freed by its free(). */
  samples(): SamplesBuffer;
  /** The z-pass test of the union of casters that share one space (their meshes welded together), freed by its free(). */
  union(casters: Caster[]): { nearWinding(points: Float64Array | ArrayLike<number>, light: Float32Array | ArrayLike<number>): number | null; free(): void };
  /** Bytes of the module's linear memory (it grows, never shrinks). */
  memoryBytes(): number;
}

/**
 * Loads the WebAssembly module: its URL (default: umbra_wasm.wasm next to index.js, fetched,
 * streamed when served as application/wasm), a Response, its bytes or a compiled module.
 * In Node pass the bytes.
 */
export function loadUmbraGeom(source?: string | URL | Response | ArrayBuffer | ArrayBufferView | WebAssembly.Module): Promise<UmbraGeom>;
