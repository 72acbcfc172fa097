//! Shadow-map math (Williams 1978; omnidirectional cube shadow maps, the baseline of paper 003,
//! Section 3.1, Tables 1-2, and paper 001, Tables 6 and 8), shared by umbra-gl's and
//! umbra-wgpu's `shadow-map-cube:RES` (moved here from umbra-gl's methods/shadow_map): the six
//! cube faces in GL's order and face selection (GL 4.5 Table 8.19), the directional map fitted
//! to the scene's bounds, and the method names. Depth convention of the maps: REVERSED
//! (larger = closer to the light); cube faces store `n / d`, infinite far plane.

use glam::{DMat4, DVec3, DVec4};

use crate::Aabb;

/// Name prefix of the family; a full name is `shadow-map-cube:RES[+pcf]`.
pub const PREFIX: &str = "shadow-map-cube";

/// Near distance of the cube faces, as a fraction of the scene's bounding-box diagonal.
pub const NEAR_FRACTION: f64 = 1e-3;

/// Parses `shadow-map-cube:RES[+pcf]` (RES a positive decimal integer, optional `k` suffix =
/// x1024, so `shadow-map-cube:8k` is 8192) into (RES, PCF). `None` for any other name.
pub fn parse_name(name: &str) -> Option<(u32, bool)> {
    let res = name.strip_prefix(PREFIX)?.strip_prefix(':')?;
    let (res, pcf) = match res.strip_suffix("+pcf") {
        Some(r) => (r, true),
        None => (res, false),
    };
    let (digits, scale) = match res.strip_suffix(['k', 'K']) {
        Some(d) => (d, 1024u32),
        None => (res, 1),
    };
    if digits.is_empty() || !digits.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    let resolution = digits.parse::<u32>().ok()?.checked_mul(scale)?;
    (resolution > 0).then_some((resolution, pcf))
}

/// `shadow-map-cube:RES[+pcf]` (what [`parse_name`] reads) as a method's registry name, a
/// `&'static str`: each distinct name is allocated once and reused.
pub fn name(resolution: u32, pcf: bool) -> &'static str {
    use std::sync::Mutex;
    static NAMES: Mutex<Vec<&'static str>> = Mutex::new(Vec::new());
    let name = format!("{PREFIX}:{resolution}{}", if pcf { "+pcf" } else { "" });
    let mut names = NAMES.lock().unwrap_or_else(|e| e.into_inner());
    if let Some(n) = names.iter().find(|n| **n == name) {
        return n;
    }
    let leaked: &'static str = Box::leak(name.into_boxed_str());
    names.push(leaked);
    leaked
}

/// The three rows (`x`, `y`, `w` of clip space) of cube face `face` as functions of the
/// direction `r = p - L`, in GL face order +X -X +Y -Y +Z -Z: clip x / w = sc / |ma| and
/// clip y / w = tc / |ma| of GL 4.5 Table 8.19, so texel (s, t) of a face receives the
/// direction the cube lookup maps to it.
pub fn face_rows(face: usize) -> [[f64; 3]; 3] {
    match face {
        0 => [[0.0, 0.0, -1.0], [0.0, -1.0, 0.0], [1.0, 0.0, 0.0]],
        1 => [[0.0, 0.0, 1.0], [0.0, -1.0, 0.0], [-1.0, 0.0, 0.0]],
        2 => [[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]],
        3 => [[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, -1.0, 0.0]],
        4 => [[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0]],
        _ => [[-1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, -1.0]],
    }
}

/// Clip z of a given window depth `depth_expr` (as a row) for the context's clip depth mode:
/// with GL_ZERO_TO_ONE window depth = z / w, with GL_NEGATIVE_ONE_TO_ONE it is
/// (z / w + 1) / 2, so z = 2 depth - w there.
fn z_row(depth_row: DVec4, w_row: DVec4, zero_to_one: bool) -> DVec4 {
    if zero_to_one {
        depth_row
    } else {
        2.0 * depth_row - w_row
    }
}

/// Light clip space from world space of cube face `face` for a point light at `light`,
/// near distance `near`: window depth = near / d (reversed, infinite far plane).
pub fn face_clip_from_world(face: usize, light: DVec3, near: f64, zero_to_one: bool) -> DMat4 {
    let [sx, sy, sw] = face_rows(face).map(DVec3::from);
    // Row a applied to r = p - L is (a, -a.L) applied to (p, 1).
    let row = |a: DVec3| DVec4::new(a.x, a.y, a.z, -a.dot(light));
    let w = row(sw);
    // Window depth near / w: clip z = near (constant) when z / w is the window depth.
    let depth_times_w = DVec4::new(0.0, 0.0, 0.0, near);
    DMat4::from_cols(row(sx), row(sy), z_row(depth_times_w, w, zero_to_one), w).transpose()
}

/// The orthographic map of a directional light (coming FROM `direction`) over `bounds`:
/// `(s, t, depth, 1)` with s, t, depth in [0, 1], depth 1 closest to the light.
pub fn map_from_world(direction: DVec3, bounds: &Aabb) -> DMat4 {
    let l = direction.normalize();
    // Any orthonormal frame (u, v, l); avoid an `up` parallel to l.
    let up = if l.y.abs() < 0.9 { DVec3::Y } else { DVec3::X };
    let u = up.cross(l).normalize();
    let v = l.cross(u);
    let (lo, hi) = (DVec3::from(bounds.min.map(f64::from)), DVec3::from(bounds.max.map(f64::from)));
    let mut min = DVec3::splat(f64::INFINITY);
    let mut max = DVec3::splat(f64::NEG_INFINITY);
    for i in 0..8 {
        let c = DVec3::new(
            if i & 1 == 0 { lo.x } else { hi.x },
            if i & 2 == 0 { lo.y } else { hi.y },
            if i & 4 == 0 { lo.z } else { hi.z },
        );
        let q = DVec3::new(u.dot(c), v.dot(c), l.dot(c));
        min = min.min(q);
        max = max.max(q);
    }
    // A margin of 0.1 % keeps the bounds' own faces off the map's border texels and off the
    // depth range ends; a flat scene still gets a non-zero range.
    let pad = (max - min).max(DVec3::splat(1e-6)) * 1e-3;
    let (min, max) = (min - pad, max + pad);
    let size = max - min;
    let row = |a: DVec3, lo: f64, span: f64| DVec4::new(a.x / span, a.y / span, a.z / span, -lo / span);
    DMat4::from_cols(row(u, min.x, size.x), row(v, min.y, size.y), row(l, min.z, size.z), DVec4::W).transpose()
}

/// Clip space of the directional map (`zero_to_one`: clip z in [0, w], wgpu's and
/// glClipControl ZERO_TO_ONE's; else [-w, w]): x, y = 2 s - 1, 2 t - 1; z per clip depth mode.
pub fn map_clip_from_world(map: &DMat4, zero_to_one: bool) -> DMat4 {
    let t = map.transpose(); // columns of t = rows of map
    let (s, tt, d, w) = (t.x_axis, t.y_axis, t.z_axis, t.w_axis);
    DMat4::from_cols(2.0 * s - w, 2.0 * tt - w, z_row(d, w, zero_to_one), w).transpose()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn name_is_what_parse_name_reads_and_interned_once() {
        assert_eq!(name(2048, false), "shadow-map-cube:2048");
        assert_eq!(name(512, true), "shadow-map-cube:512+pcf");
        assert_eq!(parse_name(name(77, true)), Some((77, true)));
        assert!(std::ptr::eq(name(77, true), name(77, true)), "interned once");
    }

    /// Every face maps a direction to clip x/w, y/w = the (sc, tc) / |ma| of GL's cube lookup,
    /// w = |ma| > 0 for the directions it owns, and window depth n / |ma| in both clip modes.
    #[test]
    fn faces_match_gl_cube_lookup() {
        let light = DVec3::new(1.0, -2.0, 0.5);
        let near = 0.01;
        let dirs = [
            DVec3::new(3.0, 0.5, -1.0),
            DVec3::new(-3.0, 0.5, -1.0),
            DVec3::new(0.2, 4.0, -1.0),
            DVec3::new(0.2, -4.0, 1.0),
            DVec3::new(0.2, 1.0, 5.0),
            DVec3::new(0.2, 1.0, -5.0),
        ];
        for (face, r) in dirs.iter().enumerate() {
            // GL 4.5 Table 8.19.
            let (sc, tc, ma) = match face {
                0 => (-r.z, -r.y, r.x),
                1 => (r.z, -r.y, r.x),
                2 => (r.x, r.z, r.y),
                3 => (r.x, -r.z, r.y),
                4 => (r.x, -r.y, r.z),
                _ => (-r.x, -r.y, r.z),
            };
            for zero_to_one in [true, false] {
                let c = face_clip_from_world(face, light, near, zero_to_one) * (light + *r).extend(1.0);
                assert!((c.w - ma.abs()).abs() < 1e-12, "face {face}: w {}", c.w);
                assert!((c.x / c.w - sc / ma.abs()).abs() < 1e-12);
                assert!((c.y / c.w - tc / ma.abs()).abs() < 1e-12);
                let window = if zero_to_one { c.z / c.w } else { 0.5 * (c.z / c.w) + 0.5 };
                assert!((window - near / ma.abs()).abs() < 1e-12, "face {face}: depth {window}");
            }
        }
    }

    #[test]
    fn directional_map_covers_bounds_with_depth_one_towards_the_light() {
        let b = Aabb { min: [-2.0, 0.0, -1.0], max: [3.0, 2.0, 4.0] };
        let dir = DVec3::new(0.3, 1.0, 0.2);
        let m = map_from_world(dir, &b);
        for i in 0..8 {
            let c = DVec3::new(
                if i & 1 == 0 { -2.0 } else { 3.0 },
                if i & 2 == 0 { 0.0 } else { 2.0 },
                if i & 4 == 0 { -1.0 } else { 4.0 },
            );
            let s = m * c.extend(1.0);
            assert!((0.0..=1.0).contains(&s.x) && (0.0..=1.0).contains(&s.y) && (0.0..=1.0).contains(&s.z), "{s:?}");
        }
        // Moving towards the light raises the depth.
        let p = DVec3::new(0.5, 1.0, 1.5);
        let a = (m * p.extend(1.0)).z;
        let q = (m * (p + 0.1 * dir).extend(1.0)).z;
        assert!(q > a);
        for zero_to_one in [true, false] {
            let c = map_clip_from_world(&m, zero_to_one) * p.extend(1.0);
            let s = m * p.extend(1.0);
            assert!((c.x - (2.0 * s.x - 1.0)).abs() < 1e-12 && (c.y - (2.0 * s.y - 1.0)).abs() < 1e-12);
            let window = if zero_to_one { c.z } else { 0.5 * c.z + 0.5 };
            assert!((window - s.z).abs() < 1e-12);
        }
    }
}
