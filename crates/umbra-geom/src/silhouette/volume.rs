//! Shadow-volume geometry in homogeneous world space: [`VolumeGeometry`], a vertex extruded
//! to infinity away from the light (paper 001, Eq. 2), and the light and dark caps of a
//! triangle oriented towards the light (Section 2.3).

use crate::Light;

/// Shadow-volume triangles in world space, homogeneous; every 3 vertices form a triangle,
/// counter-clockwise seen from outside the volume.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct VolumeGeometry {
    /// Silhouette sides: two vertices at `w = 1` on the edge, two at infinity (`w = 0`).
    pub sides: Vec<[f32; 4]>,
    /// Light caps: the light-facing-oriented triangles themselves (`w = 1`). The renderer
    /// pushes them to the far plane (paper 003, Eq. 6).
    pub light_caps: Vec<[f32; 4]>,
    /// Dark caps at infinity (`w = 0`), point lights only.
    pub dark_caps: Vec<[f32; 4]>,
}

impl VolumeGeometry {
    /// Empties every list, keeping the allocations.
    pub fn clear(&mut self) {
        self.sides.clear();
        self.light_caps.clear();
        self.dark_caps.clear();
    }
}

/// `P` extruded away from the light to infinity: `(P·l_w - L.xyz, 0)` (001 Eq. 2).
#[inline(always)]
pub fn extrude(p: [f32; 3], light: Light) -> [f32; 4] {
    [p[0] * light[3] - light[0], p[1] * light[3] - light[1], p[2] * light[3] - light[2], 0.0]
}

#[inline(always)]
pub(super) fn point(p: [f32; 3]) -> [f32; 4] {
    [p[0], p[1], p[2], 1.0]
}

/// Whether a volume for `light` has dark caps: point lights only. A directional light
/// (`l_w = 0`) extrudes every vertex to the same point `-L.xyz`, so its dark caps would have
/// zero area.
#[inline]
pub fn has_dark_caps(light: Light) -> bool {
    light[3] != 0.0
}

/// The cap of a triangle with orientation `s != 0` ([`triangle_orientation`]): its vertices
/// wound so that it faces the light (the light cap's winding).
///
/// [`triangle_orientation`]: crate::multiplicity::triangle_orientation
#[inline(always)]
pub(super) fn oriented(tri: [u32; 3], s: i8) -> [u32; 3] {
    if s > 0 {
        tri
    } else {
        [tri[0], tri[2], tri[1]]
    }
}

/// The light cap and the dark cap of the oriented cap `[i0, i1, i2]` (see [`oriented`]): the
/// triangle `P0 P1 P2` at `w = 1` and, reversed so that it faces out of the volume, `P0∞ P2∞
/// P1∞` (001 Eq. 2). The one definition of both caps' geometry: [`extract`] writes it,
/// [`IndexedVolume::expand_into`] expands indexed caps with it, and the cpu-silhouette vertex
/// shader draws the same (light caps from the indices, dark caps from the same indices
/// extruded and drawn with the front face flipped).
///
/// [`extract`]: super::extract
/// [`IndexedVolume::expand_into`]: super::IndexedVolume::expand_into
#[inline(always)]
pub(super) fn cap_vertices(positions: &[[f32; 3]], cap: [u32; 3], light: Light) -> ([[f32; 4]; 3], [[f32; 4]; 3]) {
    let [p0, p1, p2] = cap.map(|i| positions[i as usize]);
    ([point(p0), point(p1), point(p2)], [extrude(p0, light), extrude(p2, light), extrude(p1, light)])
}
