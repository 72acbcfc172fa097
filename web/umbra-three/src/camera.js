// Camera matrices in f64 (JS numbers), uploaded as f32: the twins of crates/umbra-gl/src/
// camera.rs (glam's look_at_rh and the infinite-far perspective of Everitt & Kilgard 2002), in
// both of its depth conventions: reversed-Z (the native renderer's default; in WebGL 2 only
// with the EXT_clip_control extension) and standard (clip z in [-w, w], depth 1 at infinity,
// the fallback). x and y rows are the same in both, so coverage is the native frame's. A
// three.js PerspectiveCamera gives fov, aspect and near (its far plane is replaced by
// infinity: shadow volumes reach it) and its view matrix (matrixWorldInverse).
// No three.js import here: plain arrays, testable under node --test.

const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
// glam's normalize: a * (1 / sqrt(a . a)), same operations in the same order.
const normalize = (a) => {
  const r = 1 / Math.sqrt(dot(a, a));
  return [a[0] * r, a[1] * r, a[2] * r];
};
export { sub, dot, cross, normalize };

/** Column-major 4x4 (array of 16), glam's DMat4::look_at_rh. */
export function lookAt(eye, target, up) {
  const f = normalize(sub(target, eye));
  const s = normalize(cross(f, up));
  const u = cross(s, f);
  return [s[0], u[0], -f[0], 0, s[1], u[1], -f[1], 0, s[2], u[2], -f[2], 0, -dot(s, eye), -dot(u, eye), dot(f, eye), 1];
}

/** Infinite-far perspective, standard convention (camera.rs module doc, first matrix). */
export function infinitePerspective(fovYDegrees, aspect, near) {
  const f = 1 / Math.tan(0.5 * (fovYDegrees * Math.PI) / 180);
  return [f / aspect, 0, 0, 0, 0, f, 0, 0, 0, 0, -1, -1, 0, 0, -2 * near, 0];
}

/** a * b, column-major. */
export function mul(a, b) {
  const o = new Array(16).fill(0);
  for (let c = 0; c < 4; c++) for (let r = 0; r < 4; r++) {
    let s = 0;
    for (let k = 0; k < 4; k++) s += a[k * 4 + r] * b[c * 4 + k];
    o[c * 4 + r] = s;
  }
  return o;
}

/** Infinite-far perspective, reversed-Z (camera.rs module doc, second matrix; needs
 * EXT_clip_control ZERO_TO_ONE): depth n / d, exactly 0 at infinity. */
export function infinitePerspectiveReversedZ(fovYDegrees, aspect, near) {
  const f = 1 / Math.tan(0.5 * (fovYDegrees * Math.PI) / 180);
  return [f / aspect, 0, 0, 0, 0, f, 0, 0, 0, 0, 0, -1, 0, 0, near, 0];
}

/**
 * Orthographic clip_from_view (umbra_geom::camera orthographic_clip_from_view): the x and y
 * rows of `p` (a three.js OrthographicCamera's projectionMatrix.elements, column-major: its
 * left, right, top, bottom, zoom and view offset, what three.js draws with), the depth row
 * linear in the view distance d with view distance `near` at the near plane's clip z and
 * `far` at the far plane's: (d - near) / (far - near) standard, (far - d) / (far - near)
 * reversed-Z; w_clip = 1. A finite far plane: a point at infinity has clip w = 0 here.
 */
export function orthographicProjection(p, near, far, reversedZ) {
  const span = far - near;
  // z_clip = a z_view + b with z_view = -d.
  const [a, b] = reversedZ ? [1 / span, far / span] : [-2 / span, -(far + near) / span];
  return [p[0], p[1], 0, 0, p[4], p[5], 0, 0, p[8], p[9], a, 0, p[12], p[13], b, 1];
}

/** clip_from_world in the standard or the reversed-Z convention (f64 product, f32 upload). */
export function clipFromWorld(cam, aspect, reversedZ = false) {
  const p = (reversedZ ? infinitePerspectiveReversedZ : infinitePerspective)(cam.fov_y_degrees, aspect, cam.near);
  return new Float32Array(mul(p, lookAt(cam.eye, cam.target, cam.up)));
}

/**
 * clip_from_object of a mesh: projection (fov, aspect, near; infinite far) * view * model,
 * all f64 column-major arrays of 16 (three.js Matrix4.elements), rounded once to f32.
 */
export function clipFromObject(projection, view, model) {
  return new Float32Array(mul(mul(projection, view), model));
}

/** The infinite projection of the convention: reversed-Z or standard. */
export function infiniteProjection(fovYDegrees, aspect, near, reversedZ) {
  return (reversedZ ? infinitePerspectiveReversedZ : infinitePerspective)(fovYDegrees, aspect, near);
}

/**
 * The points whose hull with a light must be clear for z-pass (umbra_geom::camera::
 * near_pyramid_points): the eye, then the corners of the near-plane rectangle pushed 2 %
 * outwards from its centre, as 15 f64 (x y z each). `worldFromClip`: the inverse of the
 * frame's clip-from-world (column-major, f64) in its convention (near plane at NDC z = 1
 * reversed-Z, -1 standard).
 */
export function nearPyramidPoints(worldFromClip, eye, reversedZ) {
  const z = reversedZ ? 1 : -1;
  const m = worldFromClip;
  const corners = [[-1, -1], [1, -1], [1, 1], [-1, 1]].map(([x, y]) => {
    const h = [0, 1, 2, 3].map((r) => m[r] * x + m[4 + r] * y + m[8 + r] * z + m[12 + r]);
    return [h[0] / h[3], h[1] / h[3], h[2] / h[3]];
  });
  const mid = [0, 1, 2].map((a) => corners.reduce((s, c) => s + c[a], 0) / 4);
  const out = new Float64Array(15);
  out.set(eye, 0);
  corners.forEach((c, i) => out.set([0, 1, 2].map((a) => mid[a] + 1.02 * (c[a] - mid[a])), 3 + 3 * i));
  return out;
}

/** Points (x y z each, f64) through an affine column-major matrix (f64), into a new Float64Array. */
export function transformPoints(m, points) {
  const out = new Float64Array(points.length);
  for (let i = 0; i < points.length; i += 3) {
    const [x, y, z] = [points[i], points[i + 1], points[i + 2]];
    for (let r = 0; r < 3; r++) out[i + r] = m[r] * x + m[4 + r] * y + m[8 + r] * z + m[12 + r];
  }
  return out;
}
