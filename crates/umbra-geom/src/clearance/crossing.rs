//! The strict segment-triangle crossing of the clearance test (Moller & Trumbore 1997, with
//! margins): inside, outside, or "cannot tell" near an edge, an end, or edge-on.

use crate::vec3::{cross, dot, norm, sub};

type V3 = [f64; 3];

/// Relative margin of [`crossing`]: barycentric coordinates and the segment parameter
/// must clear 0 and 1 by this much.
pub const CROSSING_MARGIN: f64 = 1e-6;

/// Whether the segment `a -> b` crosses triangle `t`: `Some(true)` strictly inside, `Some(false)`
/// strictly outside (a barycentric coordinate or the segment parameter beyond the range by
/// [`CROSSING_MARGIN`]), `None` when it cannot tell (near an edge, an end, or edge-on).
pub fn crossing(a: V3, b: V3, t: [V3; 3]) -> Option<bool> {
    let dir = sub(b, a);
    let e1 = sub(t[1], t[0]);
    let e2 = sub(t[2], t[0]);
    let pv = cross(dir, e2);
    let det = dot(e1, pv);
    if !(det.abs() > 1e-9 * norm(dir) * norm(e1) * norm(e2)) {
        return None;
    }
    let inv = 1.0 / det;
    let tv = sub(a, t[0]);
    let u = dot(tv, pv) * inv;
    let qv = cross(tv, e1);
    let v = dot(dir, qv) * inv;
    let s = dot(e2, qv) * inv;
    let m = CROSSING_MARGIN;
    if u > m && v > m && u + v < 1.0 - m && s > m && s < 1.0 - m {
        Some(true)
    } else if u < -m || v < -m || u + v > 1.0 + m || s < -m || s > 1.0 + m {
        Some(false)
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crossing_is_strict_and_says_when_it_cannot_tell() {
        let t = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        assert_eq!(crossing([0.2, 0.2, -1.0], [0.2, 0.2, 1.0], t), Some(true));
        // Through an edge, a vertex, ending on the plane, edge-on: not strict.
        assert_ne!(crossing([0.5, 0.0, -1.0], [0.5, 0.0, 1.0], t), Some(true));
        assert_ne!(crossing([0.0, 0.0, -1.0], [0.0, 0.0, 1.0], t), Some(true));
        assert_ne!(crossing([0.2, 0.2, -1.0], [0.2, 0.2, 0.0], t), Some(true));
        assert_ne!(crossing([-1.0, 0.2, 0.0], [2.0, 0.2, 0.0], t), Some(true));
        // Clearly outside; near an edge: unknown, not "outside".
        assert_eq!(crossing([2.0, 0.2, -1.0], [2.0, 0.2, 1.0], t), Some(false));
        assert_eq!(crossing([0.2, 0.2, 0.5], [0.2, 0.2, 1.0], t), Some(false));
        assert_eq!(crossing([0.5, 1e-9, -1.0], [0.5, 1e-9, 1.0], t), None);
        // A zero-area triangle: never.
        assert_ne!(
            crossing([0.2, 0.2, -1.0], [0.2, 0.2, 1.0], [[0.0; 3], [1.0, 1.0, 0.0], [2.0, 2.0, 0.0]]),
            Some(true)
        );
    }
}
