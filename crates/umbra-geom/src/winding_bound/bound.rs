//! [`winding_bound`]: the footprints of every triangle in each domain (six cube faces for a
//! point light, one plane for a directional light), each domain bounded in parallel, the
//! largest count plus the triangles of unknown footprint.

use rayon::prelude::*;

use super::footprint::{cube_face_footprint, parallel_footprints, Footprint};
use super::grid::{domain_bound, Stats, StopCell};
use super::options::{BoundError, BoundOptions, WindingBound};
use crate::Light;

/// An upper bound of the shadow-volume count `W` of `triangles` (indices into `positions`) for
/// `light`; see the module doc.
pub fn winding_bound(
    positions: &[[f32; 3]],
    triangles: &[[u32; 3]],
    light: Light,
    options: &BoundOptions,
) -> Result<WindingBound, BoundError> {
    bound_with_stop(positions, triangles, light, options).map(|(b, _)| b)
}

/// [`winding_bound`], plus the first cell that stopped refinement (for diagnosis).
pub(super) fn bound_with_stop(
    positions: &[[f32; 3]],
    triangles: &[[u32; 3]],
    light: Light,
    options: &BoundOptions,
) -> Result<(WindingBound, Option<StopCell>), BoundError> {
    if light.iter().any(|v| !v.is_finite())
        || !(light[3] == 0.0 || light[3] == 1.0)
        || (light[3] == 0.0 && light[0] == 0.0 && light[1] == 0.0 && light[2] == 0.0)
    {
        return Err(BoundError::BadLight { light });
    }
    let mut corners = Vec::with_capacity(triangles.len());
    for (t, tri) in triangles.iter().enumerate() {
        let mut c = [[0.0f64; 3]; 3];
        for (k, &i) in tri.iter().enumerate() {
            let p = positions.get(i as usize).ok_or(BoundError::IndexOutOfRange {
                triangle: t,
                index: i,
                vertices: positions.len(),
            })?;
            c[k] = p.map(f64::from);
        }
        corners.push(c);
    }
    let (finite, unknown): (Vec<[[f64; 3]; 3]>, Vec<_>) =
        corners.into_iter().partition(|c| c.iter().flatten().all(|v| v.is_finite()));
    let everywhere = unknown.len() as u64;
    let domains: Vec<Vec<Footprint>> = if light[3] == 1.0 {
        let l = [light[0], light[1], light[2]].map(f64::from);
        (0..6)
            .into_par_iter()
            .map(|face| finite.iter().filter_map(|c| cube_face_footprint(c, l, face)).collect())
            .collect()
    } else {
        vec![parallel_footprints(&finite, [light[0], light[1], light[2]].map(f64::from))]
    };
    let per_domain =
        if options.budget == 0 { 64 * triangles.len() + (1 << 22) } else { options.budget / domains.len().max(1) };
    let results: Vec<Stats> = domains
        .par_iter()
        .enumerate()
        .map(|(domain, fps)| {
            let mut s = Stats { budget_left: per_domain, ..Stats::default() };
            s.bound = domain_bound(fps, options, &mut s);
            if let Some(c) = s.stop_cell.as_mut() {
                c.domain = domain;
            }
            s
        })
        .collect();
    let mut stop = None;
    let mut out =
        WindingBound { bound: 0, cells: 0, refined_cells: 0, budget_exhausted: false, threshold_reached: false };
    for s in results {
        out.bound = out.bound.max(s.bound);
        out.cells += s.cells;
        out.refined_cells += s.refined;
        out.budget_exhausted |= s.exhausted;
        out.threshold_reached |= s.stop;
        if stop.is_none() {
            stop = s.stop_cell;
        }
    }
    out.bound += everywhere;
    Ok((out, stop))
}
