// umbra-geom in the browser: the buffers `umbra export` writes (welded mesh, flat normals,
// paper 003's sides-data (Eq. 8) and caps-data (Eq. 9), edge triangles), computed from a
// three.js BufferGeometry's positions and optional index by the same Rust code, compiled to
// WebAssembly (crates/umbra-wasm). Byte-identical to `umbra export` for the same welded mesh.
//
// Browser: `const geom = await loadUmbraGeom()` fetches umbra_wasm.wasm next to this file
// (or pass its URL). Node: pass the bytes, `await loadUmbraGeom(await readFile(wasmPath))`.
// Then `geom.prepare({ name, positions, index })`; see index.d.ts and README.md. With
// `caster: true` the result also carries the geometry's per-frame work (`caster`: the z-pass
// test nearWinding, crates/umbra-wasm/src/clearance.rs, and the silhouette,
// crates/umbra-wasm/src/silhouette.rs), which lives in the module until `free()`. The
// receiver cull (crates/umbra-wasm/src/cull.rs): `geom.receivers()` is one light's receiver
// map (its grid, the cells the page scattered, raise for z-pass), and `caster.cull(map, ...)`
// the silhouette of the triangles it keeps, with their far vertices.
// Build the .wasm: node ../build-wasm.mjs.

/** ABI version of crates/umbra-wasm/src/ffi.rs this module speaks. */
const ABI_VERSION = 5;

/** Buffer numbers of `umbra_result_buffer_ptr` and the typed arrays they are read as. */
const BUFFERS = [
  ['positions', Float32Array],
  ['normals', Float32Array],
  ['indices', Uint32Array],
  ['sides', Float32Array],
  ['caps', Float32Array],
  ['edgeTriangles', Int32Array],
];

/** Count numbers of `umbra_result_count`. */
const COUNTS = ['vertices', 'triangles', 'edges', 'sidesDataRecords', 'inputTriangles', 'degenerateTriangles'];

/** A geometry umbra cannot prepare, or a module that cannot be loaded; the message names which. */
export class UmbraGeomError extends Error {
  constructor(message) {
    super(message);
    this.name = 'UmbraGeomError';
  }
}

async function instantiate(source) {
  const imports = {};
  if (source instanceof WebAssembly.Module) return WebAssembly.instantiate(source, imports);
  if (source instanceof ArrayBuffer || ArrayBuffer.isView(source)) {
    return (await WebAssembly.instantiate(source, imports)).instance;
  }
  const url = source ?? new URL('./umbra_wasm.wasm', import.meta.url);
  const response = typeof Response !== 'undefined' && url instanceof Response ? url : await fetch(url);
  if (!response.ok) throw new UmbraGeomError(`${response.url || url}: HTTP ${response.status}`);
  if (typeof WebAssembly.instantiateStreaming === 'function') {
    try {
      return (await WebAssembly.instantiateStreaming(response.clone(), imports)).instance;
    } catch {
      // Served without Content-Type application/wasm: compile from the bytes instead.
    }
  }
  return (await WebAssembly.instantiate(await response.arrayBuffer(), imports)).instance;
}

/**
 * Loads the WebAssembly module: `source` is its URL (default: umbra_wasm.wasm next to this
 * file), a Response, its bytes (ArrayBuffer or typed array) or a compiled WebAssembly.Module.
 */
export async function loadUmbraGeom(source) {
  const instance = await instantiate(source);
  const w = instance.exports;
  const abi = typeof w.umbra_abi_version === 'function' ? w.umbra_abi_version() : 0;
  if (abi !== ABI_VERSION) throw new UmbraGeomError(`umbra-wasm: this module speaks ABI ${ABI_VERSION}, the .wasm is ABI ${abi}: rebuild it (node build-wasm.mjs)`);
  const encoder = new TextEncoder();
  const decoder = new TextDecoder();

  // Pointers and sizes are wasm32 i32 results: `>>> 0` reads them unsigned (memory above 2 GiB).
  const u = (v) => v >>> 0;
  const alloc = (bytes) => {
    const ptr = u(w.umbra_alloc(bytes));
    if (ptr === 0) throw new UmbraGeomError(`umbra-wasm: out of memory allocating ${bytes} bytes`);
    return ptr;
  };

  // Scratch blocks for points (f64, grown as needed), a light (4 f32), bounds (6 f32) and two
  // matrices (32 f64), shared by every handle: each call fills them, then reads its results.
  const scratch = { points: 0, pointsBytes: 0, light: 0, bounds: 0, matrices: 0 };
  const scratchPoints = (p) => {
    if (8 * p.length > scratch.pointsBytes) {
      if (scratch.points) w.umbra_free(scratch.points, scratch.pointsBytes);
      scratch.points = 0;
      scratch.pointsBytes = 8 * p.length;
      scratch.points = alloc(scratch.pointsBytes);
    }
    new Float64Array(w.memory.buffer, scratch.points, p.length).set(p);
    return scratch.points;
  };
  const scratchBlock = (key, Type, values) => {
    // 'matrices': the cull's 53 f64 or the box clamp's 42 (crates/umbra-wasm/src/ffi.rs CULL_PARAMS,
    // CLAMP_BOX_PARAMS).
    if (!scratch[key]) scratch[key] = alloc(key === 'matrices' ? 512 : 32);
    new Type(w.memory.buffer, scratch[key], values.length).set(values);
    return scratch[key];
  };

  // A handle of umbra_receivers_new: one light's receiver map.
  function receiversOf() {
    let live = u(w.umbra_receivers_new());
    if (!live) throw new UmbraGeomError('umbra-wasm: out of memory creating a receiver map');
    const check = () => {
      if (!live) throw new UmbraGeomError('umbra-wasm: receiver map used after free()');
    };
    return {
      get handle() {
        return live;
      },
      setGrid(light, bounds, side) {
        check();
        const l = scratchBlock('light', Float32Array, light);
        const b = scratchBlock('bounds', Float32Array, bounds);
        if (!w.umbra_receivers_set_grid(live, l, b, side)) return null;
        return Float32Array.from(new Float32Array(w.memory.buffer, u(w.umbra_receivers_params_ptr(live)), 24));
      },
      cells() {
        check();
        return new Float32Array(w.memory.buffer, u(w.umbra_receivers_cells_ptr(live)), u(w.umbra_receivers_cells_len(live)));
      },
      build() {
        check();
        return w.umbra_receivers_build(live) !== 0;
      },
      /** The map from `samples` (samplesBuffer()'s: x y z w per pixel), bit `bit` of w left out. */
      buildFromSamples(samples, bit) {
        check();
        return w.umbra_receivers_build_from_samples(live, samples.ptr, samples.length, bit) !== 0;
      },
      raise(points) {
        check();
        return w.umbra_receivers_raise_hull(live, scratchPoints(points), points.length) !== 0;
      },
      /**
       * The GPU cull's uniform for the grid (umbra_geom::receivers::gpu_cull_words: 52 u32, a
       * copy), with the cells of `points` (world x y z per point, f64: z-pass's near pyramid)
       * raised, or none raised for null; null without a grid or when the grid cannot bound them.
       */
      gpuCull(points = null) {
        check();
        const n = points ? points.length : 0;
        const at = u(w.umbra_receivers_gpu_cull(live, n ? scratchPoints(points) : 0, n));
        return at ? Uint32Array.from(new Uint32Array(w.memory.buffer, at, 52)) : null;
      },
      free() {
        if (!live) return;
        w.umbra_receivers_free(live);
        live = 0;
      },
    };
  }

  // A block of f32 in the module's memory that the page reads pixels into (the receiver maps'
  // samples), grown as needed.
  function samplesBuffer() {
    let ptr = 0;
    let bytes = 0;
    return {
      get ptr() {
        return ptr;
      },
      length: 0,
      /** A view of `n` floats (valid until the module's memory grows: use it at once). */
      view(n) {
        if (4 * n > bytes) {
          if (ptr) w.umbra_free(ptr, bytes);
          ptr = 0;
          bytes = 4 * n;
          ptr = alloc(bytes);
        }
        this.length = n;
        return new Float32Array(w.memory.buffer, ptr, n);
      },
      free() {
        if (ptr) w.umbra_free(ptr, bytes);
        ptr = 0;
        bytes = 0;
        this.length = 0;
      },
    };
  }

  // A handle of umbra_union_new: the z-pass test of casters that share one space.
  function unionOf(casters) {
    const handles = casters.map((c) => c.handle);
    if (handles.some((h) => !h)) throw new UmbraGeomError('umbra-wasm: union of a freed caster');
    const list = alloc(4 * handles.length);
    new Uint32Array(w.memory.buffer, list, handles.length).set(handles);
    let live = 0;
    try {
      live = u(w.umbra_union_new(list, handles.length));
    } finally {
      w.umbra_free(list, 4 * handles.length);
    }
    if (!live) throw new UmbraGeomError('umbra-wasm: out of memory building a union of casters');
    return {
      /** As Caster.nearWinding, for the union (W0 of all its triangles together), or null. */
      nearWinding(p, l) {
        if (!live) throw new UmbraGeomError('umbra-wasm: nearWinding after free()');
        const points = scratchPoints(p);
        const light = scratchBlock('light', Float32Array, l);
        const r = w.umbra_union_near_winding(live, points, p.length, light);
        return r < 0 ? null : r;
      },
      free() {
        if (!live) return;
        w.umbra_union_free(live);
        live = 0;
      },
    };
  }

  // A handle of umbra_result_caster: the per-frame work of one geometry.
  function casterOf(handle, triangles, vertices) {
    let live = handle;
    // Scratch blocks for the points (f64) and the light (f32), grown as needed.
    let points = 0;
    let pointsBytes = 0;
    const light = alloc(16);
    const silhouetteViews = (n) => {
      // Views of the module's memory (no copy): valid until the next call.
      const memory = w.memory.buffer;
      return {
        orientation: new Int8Array(memory, u(w.umbra_caster_orientation_ptr(live)), triangles),
        records: new Int32Array(memory, u(w.umbra_caster_records_ptr(live)), n),
        single: u(w.umbra_caster_single_records(live)),
      };
    };
    return {
      nearWinding(p, l) {
        if (!live) throw new UmbraGeomError('umbra-wasm: nearWinding after free()');
        if (8 * p.length > pointsBytes) {
          if (points) w.umbra_free(points, pointsBytes);
          points = 0;
          pointsBytes = 8 * p.length;
          points = alloc(pointsBytes);
        }
        const memory = w.memory.buffer;
        new Float64Array(memory, points, p.length).set(p);
        new Float32Array(memory, light, 4).set(l);
        const r = w.umbra_caster_near_winding(live, points, p.length, light);
        return r < 0 ? null : r;
      },
      silhouette(l) {
        if (!live) throw new UmbraGeomError('umbra-wasm: silhouette after free()');
        new Float32Array(w.memory.buffer, light, 4).set(l);
        return silhouetteViews(u(w.umbra_caster_silhouette(live, light)));
      },
      cull(receivers, { worldFromObject, objectFromWorld, clipFromObject, width, height, zfail, polygonPixels = 0, clamp = 'auto' }, l) {
        if (!live) throw new UmbraGeomError('umbra-wasm: cull after free()');
        const mode = clamp === 'always' ? 1 : clamp === 'never' ? 2 : 0;
        const params = [...worldFromObject, ...objectFromWorld, ...clipFromObject, width, height, zfail ? 1 : 0, polygonPixels, mode];
        const m = scratchBlock('matrices', Float64Array, params);
        new Float32Array(w.memory.buffer, light, 4).set(l);
        const n = w.umbra_caster_cull(live, receivers.handle, m, params.length, light);
        if (n < 0) return null;
        const s = silhouetteViews(n);
        const memory = w.memory.buffer;
        s.clamped = w.umbra_caster_clamped(live) !== 0;
        s.kept = u(w.umbra_caster_cull_kept(live));
        s.triangles = new Int32Array(memory, u(w.umbra_caster_kept_ptr(live)), u(w.umbra_caster_kept_len(live)));
        s.far = new Float32Array(memory, u(w.umbra_caster_far_ptr(live)), u(w.umbra_caster_far_len(live)));
        return s;
      },
      // Every volume closed at finite far ends beyond the world box (an orthographic view;
      // crates/umbra-wasm/src/ffi.rs umbra_caster_clamp_box), its silhouette towards `l`.
      clampBeyondBox({ worldFromObject, objectFromWorld, bounds, lightWorld }, l) {
        if (!live) throw new UmbraGeomError('umbra-wasm: clampBeyondBox after free()');
        const params = [...worldFromObject, ...objectFromWorld, ...bounds, ...lightWorld];
        const m = scratchBlock('matrices', Float64Array, params);
        new Float32Array(w.memory.buffer, light, 4).set(l);
        const n = w.umbra_caster_clamp_box(live, m, params.length, light);
        if (n === -2) throw new UmbraGeomError('a shadow volume cannot be closed at a finite distance (f32) beyond the scene: a triangle lies too close to the light for an orthographic view');
        if (n < 0) return null;
        const s = silhouetteViews(n);
        const memory = w.memory.buffer;
        s.clamped = true;
        s.kept = u(w.umbra_caster_cull_kept(live));
        s.triangles = new Int32Array(memory, u(w.umbra_caster_kept_ptr(live)), u(w.umbra_caster_kept_len(live)));
        s.far = new Float32Array(memory, u(w.umbra_caster_far_ptr(live)), u(w.umbra_caster_far_len(live)));
        return s;
      },
      get handle() {
        return live;
      },
      recordVertices() {
        if (!live) throw new UmbraGeomError('umbra-wasm: recordVertices after free()');
        const n = u(w.umbra_caster_record_vertices_len(live));
        return new Uint32Array(w.memory.buffer, u(w.umbra_caster_record_vertices_ptr(live)), n).slice();
      },
      vertices,
      free() {
        if (!live) return;
        w.umbra_caster_free(live);
        if (points) w.umbra_free(points, pointsBytes);
        w.umbra_free(light, 16);
        live = 0;
      },
    };
  }

  function prepare({ name = 'geometry', positions, index, caster = false } = {}) {
    name = String(name);
    const nameBytes = encoder.encode(name);
    const positionsLength = positions?.length ?? 0;
    const hasIndex = index !== undefined && index !== null;
    const indexLength = hasIndex ? index.length ?? 0 : 0;
    const blocks = [];
    let result = 0;
    try {
      const namePtr = alloc(nameBytes.length);
      blocks.push([namePtr, nameBytes.length]);
      const positionsPtr = alloc(4 * positionsLength);
      blocks.push([positionsPtr, 4 * positionsLength]);
      const indexPtr = alloc(4 * indexLength);
      blocks.push([indexPtr, 4 * indexLength]);
      // Views after every allocation: growing the memory detaches the old ArrayBuffer.
      const memory = w.memory.buffer;
      new Uint8Array(memory, namePtr, nameBytes.length).set(nameBytes);
      if (positionsLength) new Float32Array(memory, positionsPtr, positionsLength).set(positions);
      // Uint16 (or any) indices become u32 here.
      if (indexLength) new Uint32Array(memory, indexPtr, indexLength).set(index);
      result = u(w.umbra_prepare(namePtr, nameBytes.length, positionsPtr, positionsLength, indexPtr, indexLength, hasIndex ? 1 : 0));
      if (result === 0) throw new UmbraGeomError(`${name}: umbra-wasm ran out of memory`);
      const out = w.memory.buffer;
      const errorLength = u(w.umbra_result_error_len(result));
      if (errorLength) throw new UmbraGeomError(decoder.decode(new Uint8Array(out, u(w.umbra_result_error_ptr(result)), errorLength)));
      const prepared = {};
      BUFFERS.forEach(([key, Type], i) => {
        prepared[key] = new Type(out, u(w.umbra_result_buffer_ptr(result, i)), u(w.umbra_result_buffer_len(result, i))).slice();
      });
      prepared.maxMult = u(w.umbra_result_max_mult(result));
      prepared.counts = Object.fromEntries(COUNTS.map((key, i) => [key, u(w.umbra_result_count(result, i))]));
      const b = u(w.umbra_result_bounds(result));
      const bounds = b ? Array.from(new Float32Array(out, b, 6)) : null;
      prepared.bounds = bounds && { min: bounds.slice(0, 3), max: bounds.slice(3) };
      if (caster) {
        const handle = u(w.umbra_result_caster(result));
        if (handle === 0) throw new UmbraGeomError(`${name}: umbra-wasm could not build the caster's per-frame data`);
        prepared.caster = casterOf(handle, prepared.counts.triangles, prepared.counts.vertices);
      }
      return prepared;
    } finally {
      if (result) w.umbra_result_free(result);
      for (const [ptr, bytes] of blocks) w.umbra_free(ptr, bytes);
    }
  }

  /**
   * The BVH native `ray-bvh` walks (umbra_geom::ray_bvh::build; crates/umbra-wasm/src/ffi/ray_bvh.rs)
   * of world `positions` (x y z per vertex) and `indices` (3 per triangle): { nodes,
   * triangles (Float32Array vec4s), nodeCount, depth, eps (the reference's, as f32), constants
   * (the WGSL the shared walk is prepended with) }. Throws UmbraGeomError on bad input.
   */
  function rayBvh(positions, indices) {
    const blocks = [];
    let handle = 0;
    try {
      const positionsPtr = alloc(4 * positions.length);
      blocks.push([positionsPtr, 4 * positions.length]);
      const indicesPtr = alloc(4 * indices.length);
      blocks.push([indicesPtr, 4 * indices.length]);
      new Float32Array(w.memory.buffer, positionsPtr, positions.length).set(positions);
      new Uint32Array(w.memory.buffer, indicesPtr, indices.length).set(indices);
      handle = u(w.umbra_ray_bvh_build(positionsPtr, positions.length, indicesPtr, indices.length));
      if (handle === 0) throw new UmbraGeomError('umbra-wasm: out of memory building a BVH');
      const out = w.memory.buffer;
      const errorLength = u(w.umbra_ray_bvh_error_len(handle));
      if (errorLength) throw new UmbraGeomError(decoder.decode(new Uint8Array(out, u(w.umbra_ray_bvh_error_ptr(handle)), errorLength)));
      const bytes = (which) => new Uint8Array(out, u(w.umbra_ray_bvh_buffer_ptr(handle, which)), u(w.umbra_ray_bvh_buffer_len(handle, which))).slice();
      const floats = (which) => new Float32Array(bytes(which).buffer);
      const eps = new Float32Array(new Uint32Array([u(w.umbra_ray_bvh_figure(handle, 2))]).buffer)[0];
      return {
        nodes: floats(0),
        triangles: floats(1),
        constants: decoder.decode(bytes(2)),
        nodeCount: u(w.umbra_ray_bvh_figure(handle, 0)),
        depth: u(w.umbra_ray_bvh_figure(handle, 1)),
        eps,
      };
    } finally {
      if (handle) w.umbra_ray_bvh_free(handle);
      for (const [ptr, n] of blocks) w.umbra_free(ptr, n);
    }
  }

  return {
    prepare,
    /** A new receiver map (one light's; crates/umbra-wasm/src/cull.rs), freed by its free(). */
    receivers: receiversOf,
    /** A block of floats the page reads its samples into, for receivers' buildFromSamples. */
    samples: samplesBuffer,
    /** The z-pass test of the union of casters that share one space (crates/umbra-wasm/src/clearance.rs), freed by its free(). */
    union: unionOf,
    rayBvh,
    /** Bytes of the module's linear memory (it grows, never shrinks). */
    memoryBytes: () => w.memory.buffer.byteLength,
  };
}
