//! [`extract_kept`]: the volume of the triangles a receiver cull kept, with each far end where
//! it costs the fewest fragments: at the clamp (CC shadow volumes' clamping, Lloyd et al. EGSR
//! 2004) or at infinity (001 Eq. 2). Both give every visible sample the same count
//! (docs/exactness.md, "Volumes clamped to their receivers"); the choice is a matter of fill
//! alone, estimated from the volume's screen area ([`estimate_fill`]). umbra-gl's and
//! umbra-wgpu's `cpu-silhouette` both draw what this returns.

use super::clamp::VolumeClamp;
use super::fill::{estimate_fill, ScreenClip};
use super::indexed::{extract_clamped, IndexedVolume};
use super::slots::TriangleSlots;
use crate::adjacency::EdgeAdjacency;
use crate::weld::WeldedMesh;
use crate::Light;

/// [`extract_clamped`] of `clamp`'s kept triangles into `out`; then, when `fill` is given and
/// the clamped volume would cover more of the screen than the same triangles' volumes running
/// to infinity, `clamp`'s finite far ends are moved to infinity and the volume is extracted
/// again. Returns whether the volume drawn is clamped. Without `fill` (an orthographic view,
/// which cannot draw a far end at infinity) the clamped volume is kept as it is.
#[allow(clippy::too_many_arguments)]
pub fn extract_kept(
    mesh: &WeldedMesh,
    adj: &EdgeAdjacency,
    slots: &TriangleSlots,
    light: Light,
    caps: bool,
    clamp: &mut VolumeClamp,
    fill: Option<&ScreenClip>,
    out: &mut IndexedVolume,
) -> bool {
    extract_clamped(mesh, adj, slots, light, caps, clamp, out);
    let Some(clip) = fill else { return true };
    let estimate = estimate_fill(out, &mesh.positions, light, caps, clip);
    if estimate.clamped < estimate.unclamped {
        return true;
    }
    for f in clamp.far.iter_mut().filter(|f| **f > 0.0) {
        *f = f32::INFINITY;
    }
    extract_clamped(mesh, adj, slots, light, caps, clamp, out);
    false
}

/// What one light's volume drew, as a renderer reports it (`bench --json`'s
/// `volume_triangles` and `volume_edges`, umbra-gl's and umbra-wgpu's `drawn_volume`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DrawnVolume {
    /// Caster triangles not dropped by the receiver cull (all of them when not culled).
    pub triangles: u64,
    /// Silhouette edges drawn, each counted with its multiplicity `|m|` (the side quads).
    pub edges: u64,
    /// Whether the volume was culled against the light's receivers.
    pub culled: bool,
    /// Whether its sides ended at the receivers (closed by far caps) rather than at infinity:
    /// the method's choice, where it estimates fewer fragments.
    pub clamped: bool,
}
