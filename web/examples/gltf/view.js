// The view `umbra render` draws for a mesh file, computed from a three.js scene graph, so that
// the page's mask can be judged by `umbra verify --external-mask` with the same flags.
//
// The rules are umbra-cli's (crates/umbra-cli/src/scenes.rs, config/view.rs, session.rs), in
// the same arithmetic:
// * bounds: the world positions of every vertex a triangle references, in f32 (umbra's glTF
//   loader transforms in f64 and rounds each coordinate to f32; OBJ and PLY have no
//   transforms);
// * a file is framed as an interior: eye at 45 % of the height, 30 % of the way in from one
//   end of the longer horizontal axis, target 40 % further along it at 30 % of the height
//   (f64 arithmetic on the f32 centre and extent); up 0,1,0; fov 60 degrees;
// * the light: centre + 0.11 x-extent, floor + 0.7 height, centre + 0.07 z-extent, computed
//   in f32 (umbra's Light is [f32; 4]);
// * the near plane: 1e-3 of the bounds' f32 diagonal (the far plane is at infinity).
// No three.js import: the scene graph is walked through its public fields, so this module also
// runs in Node (test/gltf-view.test.mjs compares it with `umbra export`'s manifest).

const f = Math.fround;

/**
 * Bounds of the world positions of the vertices triangles reference, over every visible mesh
 * under `root` (matrixWorld must be current: root.updateMatrixWorld()). Returns
 * { min, max } as f32 values, or null when no mesh has a triangle.
 */
export function triangleBounds(root) {
  let min = null;
  let max = null;
  root.traverse((o) => {
    if (!o.isMesh || !o.geometry?.attributes?.position) return;
    const p = o.geometry.attributes.position;
    const e = o.matrixWorld.elements;
    const index = o.geometry.index;
    const n = index ? index.count : p.count;
    const seen = new Uint8Array(p.count);
    for (let k = 0; k < n - (n % 3); k++) {
      const i = index ? index.getX(k) : k;
      if (i >= p.count || seen[i]) continue;
      seen[i] = 1;
      const x = p.getX(i);
      const y = p.getY(i);
      const z = p.getZ(i);
      // umbra's transform_point: m[r] x + m[4 + r] y + m[8 + r] z + m[12 + r], in f64, then f32.
      const w = [0, 1, 2].map((r) => f(e[r] * x + e[4 + r] * y + e[8 + r] * z + e[12 + r]));
      if (!w.every(Number.isFinite)) continue;
      if (!min) {
        min = [...w];
        max = [...w];
      } else {
        for (let a = 0; a < 3; a++) {
          min[a] = Math.min(min[a], w[a]);
          max[a] = Math.max(max[a], w[a]);
        }
      }
    }
  });
  return min ? { min, max } : null;
}

/**
 * umbra's default view of bounds `b` ({ min, max }, f32 values; null: umbra's fallback box
 * -1..1) for a mesh file: { eye, target, up, fov, near, light: [x, y, z, 1] }.
 */
export function defaultView(b) {
  const box = b || { min: [-1, -1, -1], max: [1, 1, 1] };
  const c = [0, 1, 2].map((i) => f(f(0.5) * f(box.min[i] + box.max[i])));
  const e = [0, 1, 2].map((i) => f(box.max[i] - box.min[i]));
  const minY = box.min[1];
  let eye;
  let target;
  if (e[0] >= e[2]) {
    eye = [c[0] - 0.2 * e[0], minY + 0.45 * e[1], c[2]];
    target = [c[0] + 0.2 * e[0], minY + 0.3 * e[1], c[2]];
  } else {
    eye = [c[0], minY + 0.45 * e[1], c[2] - 0.2 * e[2]];
    target = [c[0], minY + 0.3 * e[1], c[2] + 0.2 * e[2]];
  }
  const light = [f(c[0] + f(f(0.11) * e[0])), f(minY + f(f(0.7) * e[1])), f(c[2] + f(f(0.07) * e[2])), 1];
  // session.rs: near = max(diagonal, 1e-6) * 1e-3, the diagonal in f32 (1 without triangles).
  const diagonal = b ? f(Math.sqrt(f(f(f(e[0] * e[0]) + f(e[1] * e[1])) + f(e[2] * e[2])))) : 1;
  return { eye, target, up: [0, 1, 0], fov: 60, near: Math.max(diagonal, 1e-6) * 1e-3, light };
}

/** `X,Y,Z` from a query value (null if absent); a clear error otherwise. */
export function parseVector(params, name) {
  return numbers(params, name, [3]);
}

/**
 * `light=X,Y,Z[,W]` as umbra's --light reads it: W = 0 a directional light coming from X,Y,Z,
 * any other W a point light at X/W, Y/W, Z/W; each coordinate rounded to f32. Null if absent.
 */
export function parseLight(params) {
  const v = numbers(params, 'light', [3, 4]);
  if (!v) return null;
  const w = v.length === 4 ? v[3] : 1;
  if (w === 0) {
    if (v.slice(0, 3).every((c) => c === 0)) throw new Error(`URL parameter light=${params.get('light')}: a directional light (W = 0) needs a non-zero direction`);
    return [f(v[0]), f(v[1]), f(v[2]), 0];
  }
  return [f(v[0] / w), f(v[1] / w), f(v[2] / w), 1];
}

function numbers(params, name, counts) {
  const s = params.get(name);
  if (s === null) return null;
  const v = s.split(',').map((t) => (t.trim() === '' ? NaN : Number(t)));
  if (!counts.includes(v.length) || !v.every(Number.isFinite)) throw new Error(`URL parameter ${name}=${s}: expected ${counts.join(' or ')} comma-separated numbers`);
  return v;
}

/**
 * The view for `root` and the page's query `params` (eye, target, up, fov, light override
 * the defaults, as umbra's --eye, --target, --up, --fov, --light do).
 */
export function viewFor(root, params) {
  const v = defaultView(triangleBounds(root));
  const eye = parseVector(params, 'eye') || v.eye;
  const target = parseVector(params, 'target') || v.target;
  const up = parseVector(params, 'up') || v.up;
  if (up.every((x) => x === 0)) throw new Error('URL parameter up: must not be zero');
  if (eye.every((x, i) => x === target[i])) throw new Error('URL parameters eye and target: the eye and the target must differ');
  const fovText = params.get('fov');
  const fov = fovText === null ? v.fov : Number(fovText);
  if (!(fov > 0 && fov < 180)) throw new Error(`URL parameter fov=${fovText}: must be in (0, 180) degrees`);
  const light = parseLight(params) || v.light;
  return { eye, target, up, fov, near: v.near, light };
}
