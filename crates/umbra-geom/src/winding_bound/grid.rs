//! The counting grid of one domain and its adaptive refinement: a first grid counted from the
//! footprints' rectangles (a 2D difference array), then every cell at or above the threshold
//! recounted with the exact polygon test and split into a sub-grid, down to the depth or
//! budget limit; a cell that stops keeps its count, an upper bound.

use super::footprint::{Footprint, Rect, FULL};
use super::options::BoundOptions;

/// Where refinement stopped with the threshold reached: the domain (cube face 0..6, or 0 for a
/// directional light), the cell, and the footprints (indices into that domain's list) in it.
#[derive(Clone, Debug)]
// `cell` and `footprints` are read by the shared-scenes diagnosis test only.
#[cfg_attr(not(test), allow(dead_code))]
pub(super) struct StopCell {
    pub(super) domain: usize,
    pub(super) cell: Rect,
    pub(super) footprints: Vec<u32>,
}

#[derive(Default)]
pub(super) struct Stats {
    pub(super) bound: u64,
    pub(super) cells: u64,
    pub(super) refined: u64,
    pub(super) exhausted: bool,
    pub(super) budget_left: usize,
    /// A finest cell kept >= threshold: refine no more (the answer is known).
    pub(super) stop: bool,
    /// That cell.
    pub(super) stop_cell: Option<StopCell>,
}

/// Index range `[i0, i1]` of the `res` cells along one axis of `[lo, lo + size]` that the
/// interval `[a, b]` touches (clamped).
fn cell_range(a: f64, b: f64, lo: f64, size: f64, res: usize) -> (usize, usize) {
    let index = |v: f64| -> usize {
        let f = ((v - lo) / size * res as f64).floor();
        if f.is_nan() || f < 0.0 {
            0
        } else {
            (f as usize).min(res - 1)
        }
    };
    (index(a), index(b))
}

fn sub_rect(cell: &Rect, res: usize, i: usize, j: usize) -> Rect {
    let (w, h) = (cell.x1 - cell.x0, cell.y1 - cell.y0);
    Rect {
        x0: cell.x0 + w * i as f64 / res as f64,
        x1: cell.x0 + w * (i + 1) as f64 / res as f64,
        y0: cell.y0 + h * j as f64 / res as f64,
        y1: cell.y0 + h * (j + 1) as f64 / res as f64,
    }
}

/// Largest count over a domain: a `base_resolution` grid counted from the footprints'
/// rectangles (a 2D difference array), then every cell at or above the threshold recounted
/// with the exact polygon test and refined ([`cell_bound`]).
pub(super) fn domain_bound(fps: &[Footprint], o: &BoundOptions, s: &mut Stats) -> u64 {
    let n = o.base_resolution.max(1) as usize;
    let range = |f: &Footprint| {
        let (i0, i1) = cell_range(f.rect.x0, f.rect.x1, 0.0, 1.0, n);
        let (j0, j1) = cell_range(f.rect.y0, f.rect.y1, 0.0, 1.0, n);
        (i0, i1, j0, j1)
    };
    let stride = n + 1;
    let mut diff = vec![0i64; stride * stride];
    for f in fps {
        let (i0, i1, j0, j1) = range(f);
        diff[j0 * stride + i0] += 1;
        diff[j0 * stride + i1 + 1] -= 1;
        diff[(j1 + 1) * stride + i0] -= 1;
        diff[(j1 + 1) * stride + i1 + 1] += 1;
    }
    let mut counts = vec![0u64; n * n];
    let mut column = vec![0i64; n];
    for j in 0..n {
        let mut run = 0i64;
        for i in 0..n {
            run += diff[j * stride + i];
            column[i] += run;
            counts[j * n + i] = column[i].max(0) as u64;
        }
    }
    s.cells += (n * n) as u64;
    let mut best = 0u64;
    let mut hot_index = vec![u32::MAX; n * n];
    let mut hot = Vec::new();
    for (k, &c) in counts.iter().enumerate() {
        if c < o.threshold {
            best = best.max(c);
        } else {
            hot_index[k] = hot.len() as u32;
            hot.push(k);
        }
    }
    if hot.is_empty() {
        return best;
    }
    // The exact membership below tests every (footprint, hot cell) pair of the rectangles: the
    // sum of the hot counts. Beyond the budget, stop with the counts (sound, not refined).
    let work: usize = hot.iter().map(|&k| counts[k] as usize).sum();
    if work > s.budget_left {
        s.exhausted = true;
        s.stop = true;
        return hot.iter().map(|&k| counts[k]).fold(best, u64::max);
    }
    s.budget_left -= work;
    // Exact membership of the hot cells.
    let mut lists: Vec<Vec<u32>> = vec![Vec::new(); hot.len()];
    for (t, f) in fps.iter().enumerate() {
        let (i0, i1, j0, j1) = range(f);
        for j in j0..=j1 {
            for i in i0..=i1 {
                let h = hot_index[j * n + i];
                if h != u32::MAX && f.touches(&sub_rect(&FULL, n, i, j)) {
                    lists[h as usize].push(t as u32);
                }
            }
        }
    }
    for (h, list) in lists.into_iter().enumerate() {
        let k = hot[h];
        let b = cell_bound(fps, list, sub_rect(&FULL, n, k % n, k / n), 1, o, s);
        best = best.max(b);
    }
    best
}

/// Bound of one cell whose exact footprint list is `list`: its length if below the threshold
/// (or when refinement must stop), else the largest bound of its sub-cells.
fn cell_bound(fps: &[Footprint], list: Vec<u32>, cell: Rect, depth: u32, o: &BoundOptions, s: &mut Stats) -> u64 {
    let c = list.len() as u64;
    if c < o.threshold || s.stop {
        return c;
    }
    let n = o.refine_resolution as usize;
    if depth > o.max_depth || n < 2 {
        s.stop = true;
        s.stop_cell = Some(StopCell { domain: 0, cell, footprints: list });
        return c;
    }
    if s.budget_left < list.len() * 4 {
        s.exhausted = true;
        s.stop = true;
        s.stop_cell = Some(StopCell { domain: 0, cell, footprints: list });
        return c;
    }
    s.refined += 1;
    s.cells += (n * n) as u64;
    let (w, h) = (cell.x1 - cell.x0, cell.y1 - cell.y0);
    let mut subs: Vec<Vec<u32>> = vec![Vec::new(); n * n];
    let mut pushed = 0usize;
    for &t in &list {
        let f = &fps[t as usize];
        let (i0, i1) = cell_range(f.rect.x0, f.rect.x1, cell.x0, w, n);
        let (j0, j1) = cell_range(f.rect.y0, f.rect.y1, cell.y0, h, n);
        for j in j0..=j1 {
            for i in i0..=i1 {
                if f.touches(&sub_rect(&cell, n, i, j)) {
                    subs[j * n + i].push(t);
                    pushed += 1;
                }
            }
        }
    }
    drop(list);
    s.budget_left = s.budget_left.saturating_sub(pushed);
    let mut best = 0;
    for (k, sub) in subs.into_iter().enumerate() {
        let b = cell_bound(fps, sub, sub_rect(&cell, n, k % n, k / n), depth + 1, o, s);
        best = best.max(b);
    }
    best.min(c)
}
