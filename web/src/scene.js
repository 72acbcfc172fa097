// Loads a scene written by `umbra export` (crates/umbra-cli/src/export.rs): manifest.json and
// its little-endian binary buffers, fetched as ArrayBuffers (paper 003 Section 2.6: sides-data
// and caps-data are preprocessed once and downloaded). Everything is checked before any GL
// call: the manifest's format and version, every field's type, the sizes against each other
// and against paper 003's Eq. 8 (sides-data, 16 (2 + maxMult) e bytes) and Eq. 9 (caps-data,
// 48 t bytes), and every fetched buffer's length. Failures are SceneError naming the file and
// the JSON path (or the byte counts), shown on the page by main.js.
//
// No DOM or WebGL here: the same code runs under node --test (test/scene.test.mjs).

export const FORMAT = 'umbra-export';
export const VERSION = 2;
export const MAX_MULT_LIMIT = 14;

export class SceneError extends Error {
  /** @param {string} file @param {string} where JSON path or '' @param {string} message */
  constructor(file, where, message) {
    super(`${file}: ${where ? where + ': ' : ''}${message}`);
    this.name = 'SceneError';
    this.file = file;
    this.where = where;
  }
}

function field(file, obj, path, key, kind) {
  const p = `${path}.${key}`;
  if (obj === null || typeof obj !== 'object' || Array.isArray(obj)) throw new SceneError(file, path, 'expected an object');
  if (!(key in obj)) throw new SceneError(file, p, 'missing');
  const v = obj[key];
  const bad = (what) => new SceneError(file, p, `expected ${what}, got ${JSON.stringify(v)}`);
  switch (kind) {
    case 'uint':
      if (!Number.isSafeInteger(v) || v < 0) throw bad('an unsigned integer');
      return v;
    case 'number':
      if (typeof v !== 'number' || !Number.isFinite(v)) throw bad('a finite number');
      return v;
    case 'string':
      if (typeof v !== 'string') throw bad('a string');
      return v;
    case 'bool':
      if (typeof v !== 'boolean') throw bad('true or false');
      return v;
    case 'object':
      if (v === null || typeof v !== 'object' || Array.isArray(v)) throw bad('an object');
      return v;
    default: {
      const n = Number(kind.slice(3)); // 'vec3' / 'vec4'
      if (!Array.isArray(v) || v.length !== n || !v.every((x) => typeof x === 'number' && Number.isFinite(x))) {
        throw bad(`an array of ${n} finite numbers`);
      }
      return v;
    }
  }
}

/** The last component of a scene spec that is a path (`/a/b/sibenik.obj.gz`, `C:\\m\\x.obj`);
 * procedural specs (`default`, `spheres:10`) as they are. */
export function sceneName(spec) {
  return spec.split(/[\\/]/).filter(Boolean).pop() || spec;
}

export const BUFFERS = ['positions', 'normals', 'indices', 'sides_data', 'caps_data', 'edge_triangles'];

/**
 * Parses and checks manifest.json's text (the twin of export.rs's parse_manifest).
 * @returns {object} the manifest
 */
export function parseManifest(text, file = 'manifest.json') {
  let m;
  try {
    m = JSON.parse(text);
  } catch (e) {
    throw new SceneError(file, '', `not valid JSON (${e.message}); is the export complete?`);
  }
  const f = (obj, path, key, kind) => field(file, obj, path, key, kind);
  if (f(m, '$', 'format', 'string') !== FORMAT) throw new SceneError(file, '$.format', `expected "${FORMAT}"`);
  const version = f(m, '$', 'version', 'uint');
  if (version !== VERSION) {
    throw new SceneError(file, '$.version', `this viewer reads version ${VERSION}, the scene is version ${version}: re-export it with this umbra`);
  }
  const counts = f(m, '$', 'counts', 'object');
  for (const k of ['vertices', 'triangles', 'edges', 'sides_data_records']) f(counts, '$.counts', k, 'uint');
  const maxMult = f(m, '$', 'max_mult', 'uint');
  if (maxMult < 1 || maxMult > MAX_MULT_LIMIT) throw new SceneError(file, '$.max_mult', `must be between 1 and ${MAX_MULT_LIMIT}, got ${maxMult}`);
  f(m, '$', 'sides_data_bytes', 'uint');
  f(m, '$', 'caps_data_bytes', 'uint');
  const bounds = f(m, '$', 'bounds', 'object');
  f(bounds, '$.bounds', 'min', 'vec3');
  f(bounds, '$.bounds', 'max', 'vec3');
  f(m, '$', 'light', 'vec4');
  const cam = f(m, '$', 'camera', 'object');
  for (const k of ['eye', 'target', 'up']) f(cam, '$.camera', k, 'vec3');
  f(cam, '$.camera', 'fov_y_degrees', 'number');
  if (!(f(cam, '$.camera', 'near', 'number') > 0)) throw new SceneError(file, '$.camera.near', 'must be > 0');
  const buffers = f(m, '$', 'buffers', 'object');
  const c = counts;
  const expected = {
    positions: [3, c.vertices, 'f32'],
    normals: [3, c.triangles, 'f32'],
    indices: [3, c.triangles, 'u32'],
    sides_data: [4, c.sides_data_records * (2 + maxMult), 'f32'],
    caps_data: [4, 3 * c.triangles, 'f32'],
    // Version 2: per edge record, the signed triangle behind each opposite slot (export.rs).
    edge_triangles: [maxMult, c.sides_data_records, 'i32'],
  };
  for (const name of BUFFERS) {
    const path = `$.buffers.${name}`;
    const b = f(buffers, '$.buffers', name, 'object');
    const fileName = f(b, path, 'file', 'string');
    if (!/^[A-Za-z0-9._-]+$/.test(fileName) || fileName === '.' || fileName === '..') {
      throw new SceneError(file, `${path}.file`, `${JSON.stringify(fileName)} is not a plain file name`);
    }
    for (const k of ['offset', 'bytes', 'components', 'count']) f(b, path, k, 'uint');
    const [components, count, type] = expected[name];
    if (f(b, path, 'component_type', 'string') !== type) throw new SceneError(file, `${path}.component_type`, `expected "${type}"`);
    if (b.components !== components || b.count !== count) {
      throw new SceneError(file, path, `expected ${count} elements of ${components} components (from $.counts), got ${b.count} of ${b.components}`);
    }
    if (b.bytes !== 4 * components * count) throw new SceneError(file, `${path}.bytes`, `expected ${4 * components * count}, got ${b.bytes}`);
    if (b.offset % 4 !== 0) throw new SceneError(file, `${path}.offset`, 'must be a multiple of 4');
  }
  // Paper 003 Eq. 8 and Eq. 9.
  const eq8 = 16 * (2 + maxMult) * c.sides_data_records;
  const eq9 = 48 * c.triangles;
  if (m.sides_data_bytes !== eq8) throw new SceneError(file, '$.sides_data_bytes', `Eq. 8 gives ${eq8}, the manifest states ${m.sides_data_bytes}`);
  if (m.caps_data_bytes !== eq9) throw new SceneError(file, '$.caps_data_bytes', `Eq. 9 gives ${eq9}, the manifest states ${m.caps_data_bytes}`);
  return m;
}

/**
 * The typed array of buffer `name` inside `data` (a whole fetched file), after checking its
 * length against the manifest.
 */
export function bufferView(m, name, data) {
  const b = m.buffers[name];
  if (!(data instanceof ArrayBuffer)) throw new SceneError(b.file, '', 'not an ArrayBuffer');
  if (data.byteLength < b.offset + b.bytes) {
    throw new SceneError(b.file, '', `has ${data.byteLength} bytes, but $.buffers.${name} needs ${b.offset + b.bytes} (offset ${b.offset} + ${b.bytes}): truncated or stale export`);
  }
  const n = b.bytes / 4;
  if (b.component_type === 'u32') return new Uint32Array(data, b.offset, n);
  return b.component_type === 'i32' ? new Int32Array(data, b.offset, n) : new Float32Array(data, b.offset, n);
}

/**
 * Fetches and checks a whole export under `base` (a URL ending in '/').
 * Little-endian data is read with the platform's typed arrays: every WebGL2 platform is
 * little-endian, checked here so a big-endian one fails loudly instead of drawing garbage.
 */
export async function loadScene(base, fetchFn = fetch) {
  if (new Uint8Array(new Uint16Array([1]).buffer)[0] !== 1) throw new SceneError('(platform)', '', 'big-endian platforms are not supported');
  const get = async (file) => {
    let r;
    try {
      r = await fetchFn(new URL(file, base).toString());
    } catch (e) {
      throw new SceneError(file, '', `could not be fetched (${e.message})`);
    }
    if (!r.ok) throw new SceneError(file, '', `HTTP ${r.status}: missing? Export a scene with \`umbra export SCENE --out DIR\``);
    return r;
  };
  const manifest = parseManifest(await (await get('manifest.json')).text());
  const arrays = {};
  const cache = new Map();
  for (const name of BUFFERS) {
    const file = manifest.buffers[name].file;
    if (!cache.has(file)) cache.set(file, await (await get(file)).arrayBuffer());
    arrays[name] = bufferView(manifest, name, cache.get(file));
  }
  const t = manifest.counts.triangles;
  const v = manifest.counts.vertices;
  for (let i = 0; i < 3 * t; i++) {
    if (arrays.indices[i] >= v) {
      throw new SceneError(manifest.buffers.indices.file, '', `index ${i} (byte ${4 * i}) is ${arrays.indices[i]}, but there are ${v} vertices`);
    }
  }
  return { manifest, ...arrays };
}
