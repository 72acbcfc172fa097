//! The options of [`winding_bound`], what it found, and the errors it reports.
//!
//! [`winding_bound`]: super::winding_bound

use crate::Light;

/// The count an 8-bit stencil cannot hold: `W >= 256` may wrap to 0.
pub const STENCIL8_LIMIT: u64 = 256;

/// Tuning of [`winding_bound`].
///
/// [`winding_bound`]: super::winding_bound
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BoundOptions {
    /// Cells counting at least this many triangles are refined (the question asked is
    /// "is W < threshold everywhere").
    pub threshold: u64,
    /// Cells per side of the first grid of every domain.
    pub base_resolution: u32,
    /// Cells per side of the sub-grid of a refined cell.
    pub refine_resolution: u32,
    /// Refinement levels below the first grid.
    pub max_depth: u32,
    /// Most triangle-cell entries created by refinement per domain (cube face or plane);
    /// 0 = 64 per triangle + 2^22 (about 0.4 s for 280,000 triangles here).
    pub budget: usize,
}

impl Default for BoundOptions {
    /// Threshold 256, 256 x 256 cells per domain, 4 x 4 sub-grids, 5 levels (down to 262,144
    /// cells per cube face side, ~6e-6 rad), default budget.
    fn default() -> Self {
        Self { threshold: STENCIL8_LIMIT, base_resolution: 256, refine_resolution: 4, max_depth: 5, budget: 0 }
    }
}

/// What [`winding_bound`] found.
///
/// [`winding_bound`]: super::winding_bound
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct WindingBound {
    /// An upper bound of `W(p)` over every point `p` for this light.
    pub bound: u64,
    /// Cells counted in all (every level).
    pub cells: u64,
    /// Cells that were refined.
    pub refined_cells: u64,
    /// Whether the work budget stopped a refinement (the bound may then be loose).
    pub budget_exhausted: bool,
    /// Whether some finest cell kept at least `threshold` triangles, after which refinement
    /// stopped everywhere (the question "below the threshold?" is answered: no). The bound is
    /// then the largest count seen, sound but not tight.
    pub threshold_reached: bool,
}

impl WindingBound {
    /// Whether an 8-bit wrapping stencil provably holds every count exactly (`bound < 256`).
    pub fn stencil8_exact(&self) -> bool {
        self.bound < STENCIL8_LIMIT
    }
}

/// Bad input to [`winding_bound`].
///
/// [`winding_bound`]: super::winding_bound
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum BoundError {
    /// A triangle index past the end of the positions.
    #[error("triangle {triangle} references vertex {index}, but there are {vertices} vertices")]
    IndexOutOfRange {
        /// The triangle (its position in the triangle list).
        triangle: usize,
        /// The bad index.
        index: u32,
        /// How many positions there are.
        vertices: usize,
    },
    /// A light that is not finite, or whose w is not 0 or 1, or a zero direction.
    #[error("light {light:?} is not finite with w = 0 or 1 (or is directional with a zero direction)")]
    BadLight {
        /// The light as given.
        light: Light,
    },
}
