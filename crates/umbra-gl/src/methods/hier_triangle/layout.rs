//! hier-triangle's memory: the shared view-sample hierarchy ([`crate::methods::hier::layout`],
//! re-exported here) plus the per-triangle planes of each light's shadow frusta (Sintorn,
//! Kämpe, Olsson, Assarsson, "Per-Triangle Shadow Volumes Using a View-Sample Cluster
//! Hierarchy", I3D 2014, Section 3: a triangle's shadow frustum as four planes).

pub use crate::methods::hier::layout::*;

/// Bytes of one triangle's data per light: the oriented triangle plane and three edge planes,
/// each also over the view's rays, and the bound of its directions from the light
/// (frustum.glsl).
pub const PLANE_BYTES: usize = 144;

/// Bytes of the per-triangle planes of a scene of `triangles` triangles.
pub fn plane_bytes(triangles: usize) -> usize {
    PLANE_BYTES * triangles
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bytes_per_resolution() {
        // The numbers docs/benchmarks.md states (a 262,267-triangle Crytek Sponza).
        let t = 262_267;
        for (w, h, mib) in [(640, 360, 55.5), (1920, 1080, 107.3), (3840, 2160, 278.2)] {
            let l = Layout::new(w, h, t, 1.0);
            let got = (l.frame_bytes() + plane_bytes(t)) as f64 / (1 << 20) as f64;
            assert!((got - mib).abs() < 0.1, "{w}x{h}: {got:.1} MiB");
        }
    }
}
