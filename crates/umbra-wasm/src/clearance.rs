//! The per-frame z-pass question of the browser drawer, asked of one prepared geometry: is the
//! eye's near pyramid provably inside the same `W0` shadow volumes everywhere, and how many
//! ([`umbra_geom::clearance::ClearanceIndex::near_winding`], the test the native renderers ask
//! before counting z-pass)?
//!
//! [`Clearance`] keeps what that test reads (the welded mesh, its edge adjacency and its
//! cluster boxes), built once per geometry next to its export buffers. The question is asked
//! in the geometry's own (object) space: the caller moves the eye, the near-plane corners and
//! the light there with the mesh's inverse world transform. An affine map keeps convex hulls,
//! segment-triangle crossings and the order of points along a line, so the answer is the
//! world-space one; the transform's f64 rounding (about 1e-16 relative) lies far below the
//! test's margin (1e-6 of the scene's scale), and the light it is asked with is the same f32
//! value the volumes are drawn with.

//!
//! **A union of casters.** A model a loader splits into groups (OBJLoader: one mesh per `g`/`o`,
//! Crytek Sponza's 25) has open edges along every group's border where the whole model has
//! none, and a group's own count varies across the eye's near pyramid wherever such an edge
//! lies between the pyramid and the light. The count z-pass must start from is the sum over
//! casters, the winding of all their triangles together, so for casters that share a world
//! matrix (one space) the question may be asked of their union instead
//! ([`Clearance::union`]: their welded meshes concatenated and welded again, which closes the
//! borders that share positions): when the union's winding is provably `W0` over the whole
//! pyramid, so is the sum the stencil counts, whichever caster each face belongs to.

use umbra_geom::clearance::ClearanceIndex;
use umbra_geom::weld::weld;
use umbra_geom::{EdgeAdjacency, Light, Mesh, WeldedMesh};

/// One geometry's clearance data (see the module documentation).
#[derive(Clone, Debug)]
pub struct Clearance {
    mesh: WeldedMesh,
    adjacency: EdgeAdjacency,
    index: ClearanceIndex,
}

impl Clearance {
    /// Builds the edge adjacency and the cluster boxes of `mesh` (once per geometry).
    pub fn new(mesh: WeldedMesh) -> Clearance {
        let adjacency = EdgeAdjacency::build(&mesh);
        let index = ClearanceIndex::build(&mesh);
        Clearance { mesh, adjacency, index }
    }

    /// `W0` of the hull of `points` (the eye and the near-plane corners, object space) towards
    /// `light` (object space, w = 0 directional), or None when it is not provably one count
    /// (then the drawer counts z-fail). The adjacency is passed: the browser's volumes have
    /// sides on edges of nonzero multiplicity only (paper 003's vs-silhouette).
    pub fn near_winding(&self, points: &[[f64; 3]], light: Light) -> Option<u32> {
        self.index.near_winding(&self.mesh, Some(&self.adjacency), points, light)
    }

    /// The clearance data of the union of `meshes` (one space): positions concatenated,
    /// triangles renumbered, welded again (module documentation).
    pub fn union<'a>(meshes: impl IntoIterator<Item = &'a WeldedMesh>) -> Clearance {
        let mut all = Mesh::default();
        for m in meshes {
            let base = all.positions.len() as u32;
            all.positions.extend_from_slice(&m.positions);
            all.triangles.extend(m.triangles.iter().map(|t| t.map(|i| i + base)));
        }
        Clearance::new(weld(&all))
    }

    /// The welded mesh.
    pub fn mesh(&self) -> &WeldedMesh {
        &self.mesh
    }

    /// Its edge adjacency.
    pub fn adjacency(&self) -> &EdgeAdjacency {
        &self.adjacency
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::prepare_welded;

    /// A unit square at z = 1 (two triangles), the light above it at z = 3.
    fn square() -> Clearance {
        let p = [0.0, 0.0, 1.0, 1.0, 0.0, 1.0, 1.0, 1.0, 1.0, 0.0, 1.0, 1.0];
        let (_, welded) = prepare_welded("square", &p, Some(&[0, 1, 2, 0, 2, 3])).expect("square");
        Clearance::new(welded)
    }

    /// The eye at `eye` looking down -z, a near rectangle 0.1 below it, 0.02 wide.
    fn pyramid(eye: [f64; 3]) -> Vec<[f64; 3]> {
        let mut points = vec![eye];
        for (dx, dy) in [(-0.01, -0.01), (0.01, -0.01), (0.01, 0.01), (-0.01, 0.01)] {
            points.push([eye[0] + dx, eye[1] + dy, eye[2] - 0.1]);
        }
        points
    }

    /// The square split in two triangles, each its own caster: under the square near its
    /// diagonal, each half alone cannot prove one count (the other half's border, open for it,
    /// lies between the pyramid and the light); their union can, and its `W0` is the sum.
    #[test]
    fn a_union_proves_what_its_parts_cannot() {
        let half = |idx: [u32; 3]| {
            let p = [0.0, 0.0, 1.0, 1.0, 0.0, 1.0, 1.0, 1.0, 1.0, 0.0, 1.0, 1.0];
            let (_, welded) = prepare_welded("half", &p, Some(&idx)).expect("half");
            welded
        };
        let (a, b) = (half([0, 1, 2]), half([0, 2, 3]));
        let light = [0.5, 0.5, 3.0, 1.0];
        let eye = pyramid([0.5, 0.52, 0.5]);
        assert_eq!(Clearance::new(a.clone()).near_winding(&eye, light), None);
        assert_eq!(Clearance::new(b.clone()).near_winding(&eye, light), None);
        let u = Clearance::union([&a, &b]);
        assert_eq!((u.mesh().positions.len(), u.mesh().triangles.len()), (4, 2), "the shared edge welded");
        assert_eq!(u.near_winding(&eye, light), Some(1));
        assert_eq!(u.near_winding(&pyramid([3.0, 0.5, 0.5]), light), Some(0));
    }

    #[test]
    fn eye_in_the_open_in_the_shadow_and_at_the_caster() {
        let c = square();
        let light = [0.5, 0.5, 3.0, 1.0];
        // Beside the square: no triangle between the pyramid and the light.
        assert_eq!(c.near_winding(&pyramid([3.0, 0.5, 0.5]), light), Some(0));
        // Under the square: every point's segment to the light crosses one triangle.
        assert_eq!(c.near_winding(&pyramid([0.3, 0.6, 0.5]), light), Some(1));
        // The near rectangle cut by the square's plane: unknown.
        assert_eq!(c.near_winding(&pyramid([0.5, 0.5, 1.05]), light), None);
        // Directional light straight down the z axis, from above: the eye under the square.
        assert_eq!(c.near_winding(&pyramid([0.3, 0.6, 0.5]), [0.0, 0.0, 1.0, 0.0]), Some(1));
        // A non-finite point is never "clear".
        assert_eq!(c.near_winding(&[[f64::NAN, 0.0, 0.0]], light), None);
    }
}
