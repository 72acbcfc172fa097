//! Per-method frame and stage times of one measurement, and their statistics (mean, median,
//! nearest-rank 95th percentile, per-stage means).

/// Per-method results of one measurement.
#[derive(Clone, Debug, Default)]
pub struct MethodStats {
    pub method: String,
    /// Whole-frame times of the measured rounds, in round order (ms).
    pub frame_ms: Vec<f64>,
    /// Per stage (first-seen order): the stage's time in each stage-timed round (ms).
    pub stage_ms: Vec<(String, Vec<f64>)>,
    pub gpu_bytes: usize,
    /// The method's per-scene preprocessing figures (`Driver::scene_figures`).
    pub figures: Vec<(&'static str, f64)>,
    pub error: Option<String>,
    /// The counter the method's volume pass used ("stencil8", "float32", or "none" for a
    /// method that does not count in the stencil).
    pub counter: String,
    /// Per work-counted round (the stage-timed ones): the frame's work counts; empty for
    /// methods that count no work.
    pub work: Vec<umbra_gl::WorkCounts>,
    /// Measured frames' lights counted z-pass, and all measured frames' lights.
    pub zpass_lights: usize,
    pub lights: usize,
    /// Whether the method culled its volumes against the receivers (`--volume-cull`).
    pub volume_cull: bool,
    /// Per volume-counted round (the stage-timed ones): what the volume passes drew.
    pub volume: Vec<VolumeCounts>,
}

/// What one frame's volume passes drew, summed over its lights
/// ([`umbra_gl::Renderer::last_drawn`], [`umbra_gl::Renderer::last_volume_fragments`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct VolumeCounts {
    /// Fragments rasterized (`None` where the GL cannot count them).
    pub fragments: Option<u64>,
    /// The query that counted them ([`umbra_gl::Renderer::volume_fragment_query`]).
    pub query: Option<umbra_gl::VolumeFragmentQuery>,
    /// Caster triangles not dropped by the receiver cull and silhouette edges drawn, with
    /// their multiplicities (side quads); `None` for methods that do not report them.
    pub drawn: Option<(u64, u64)>,
}

impl MethodStats {
    pub fn mean(&self) -> Option<f64> {
        (!self.frame_ms.is_empty()).then(|| self.frame_ms.iter().sum::<f64>() / self.frame_ms.len() as f64)
    }
    pub fn median(&self) -> Option<f64> {
        percentile_sorted(&sorted(&self.frame_ms), 0.5)
    }
    pub fn p95(&self) -> Option<f64> {
        percentile_sorted(&sorted(&self.frame_ms), 0.95)
    }
    /// Means per counted frame of the volume counts: fragments, and (triangles, edges); each
    /// `None` unless every counted frame has it.
    pub fn volume_means(&self) -> (Option<f64>, Option<(f64, f64)>) {
        if self.volume.is_empty() {
            return (None, None);
        }
        let n = self.volume.len() as f64;
        let fragments = self.volume.iter().map(|v| v.fragments.map(|f| f as f64)).sum::<Option<f64>>().map(|s| s / n);
        let drawn = self
            .volume
            .iter()
            .try_fold((0.0, 0.0), |(t, e), v| v.drawn.map(|(vt, ve)| (t + vt as f64, e + ve as f64)))
            .map(|(t, e)| (t / n, e / n));
        (fragments, drawn)
    }
    /// The query behind [`MethodStats::volume_means`]' fragments (`volume_fragments_query`):
    /// the counted frames' (all on one context, so one kind); `None` when those are absent.
    pub fn volume_fragments_query(&self) -> Option<&'static str> {
        self.volume_means().0?;
        self.volume.iter().find_map(|v| v.query).map(umbra_gl::VolumeFragmentQuery::name)
    }
    /// Mean per counted frame of each work count (key, mean), in [`umbra_gl::WorkCounts::entries`]
    /// order; empty without counts.
    pub fn work_means(&self) -> Vec<(&'static str, f64)> {
        if self.work.is_empty() {
            return Vec::new();
        }
        let n = self.work.len() as f64;
        let mut sums: Vec<(&'static str, f64)> =
            umbra_gl::WorkCounts::default().entries().iter().map(|(k, _)| (*k, 0.0)).collect();
        for w in &self.work {
            for (sum, (_, v)) in sums.iter_mut().zip(w.entries()) {
                sum.1 += v as f64;
            }
        }
        sums.into_iter().map(|(k, s)| (k, s / n)).collect()
    }

    /// Mean of each stage over the stage-timed rounds.
    pub fn stage_means(&self) -> Vec<(String, f64)> {
        self.stage_ms
            .iter()
            .filter(|(_, v)| !v.is_empty())
            .map(|(n, v)| (n.clone(), v.iter().sum::<f64>() / v.len() as f64))
            .collect()
    }
}

fn sorted(v: &[f64]) -> Vec<f64> {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    s
}

/// Median (q = 0.5: mean of the middle two for even counts) or nearest-rank percentile.
fn percentile_sorted(s: &[f64], q: f64) -> Option<f64> {
    if s.is_empty() {
        return None;
    }
    if q == 0.5 {
        let n = s.len();
        return Some(if n % 2 == 1 { s[n / 2] } else { 0.5 * (s[n / 2 - 1] + s[n / 2]) });
    }
    let rank = ((q * s.len() as f64).ceil() as usize).clamp(1, s.len());
    Some(s[rank - 1])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percentiles() {
        let st = MethodStats { frame_ms: vec![5.0, 1.0, 3.0, 2.0, 4.0], ..Default::default() };
        assert_eq!(st.mean(), Some(3.0));
        assert_eq!(st.median(), Some(3.0));
        assert_eq!(st.p95(), Some(5.0));
        let even = MethodStats { frame_ms: vec![4.0, 1.0, 3.0, 2.0], ..Default::default() };
        assert_eq!(even.median(), Some(2.5));
        let twenty = MethodStats { frame_ms: (1..=20).map(f64::from).collect(), ..Default::default() };
        assert_eq!(twenty.p95(), Some(19.0), "nearest rank: ceil(0.95 * 20) = 19th");
        assert_eq!(MethodStats::default().mean(), None);
    }

    #[test]
    fn volume_fragments_query_only_with_volume_fragments() {
        use umbra_gl::VolumeFragmentQuery as Q;
        let counted = |fragments: Option<u64>| VolumeCounts {
            fragments,
            query: fragments.map(|_| Q::FragmentShaderInvocations),
            drawn: None,
        };
        let st = MethodStats { volume: vec![counted(Some(10)), counted(Some(20))], ..Default::default() };
        assert_eq!(st.volume_means().0, Some(15.0));
        assert_eq!(st.volume_fragments_query(), Some("fragment_shader_invocations"));
        let partial = MethodStats { volume: vec![counted(Some(10)), counted(None)], ..Default::default() };
        assert_eq!((partial.volume_means().0, partial.volume_fragments_query()), (None, None));
        assert_eq!(MethodStats::default().volume_fragments_query(), None);
    }
}
