//! Counting the fragments of the volume passes ([`Renderer::set_count_volume_fragments`]): one
//! GL query around each light's [`crate::ShadowMethod::draw_volumes`], begun and ended in
//! `volume_pass`.
//!
//! No query nests inside another: the renderer begins this one query only, and ends it before
//! the pass returns (on error too); no shadow method begins a query of its own (stage timing
//! is glQueryCounter(GL_TIMESTAMP), which has no begin/end); and a query a host left active on
//! the same target (GL allows one per target, and one among the occlusion targets) is seen
//! with glGetQueryiv(GL_CURRENT_QUERY) and the pass is then not counted.

use glow::HasContext;

use super::Renderer;

/// `GL_FRAGMENT_SHADER_INVOCATIONS` (ARB_pipeline_statistics_query; core in GL 4.6).
const FRAGMENT_SHADER_INVOCATIONS: u32 = 0x82F4;

/// The query that counts a volume pass's fragments ([`Renderer::volume_fragment_query`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VolumeFragmentQuery {
    /// `GL_FRAGMENT_SHADER_INVOCATIONS` (ARB_pipeline_statistics_query, GL 4.6): every
    /// fragment the pass rasterized, since the volume shaders write gl_FragDepth (no early
    /// depth test culls one before its shader runs). Preferred.
    FragmentShaderInvocations,
    /// `GL_SAMPLES_PASSED`, without that extension: only the samples that pass the depth and
    /// stencil tests, so a lower bound (z-fail counts at the fragments that fail the depth
    /// test).
    SamplesPassed,
}

impl VolumeFragmentQuery {
    /// The best query `gl` offers: [`VolumeFragmentQuery::FragmentShaderInvocations`] on
    /// GL 4.6 or with ARB_pipeline_statistics_query, else
    /// [`VolumeFragmentQuery::SamplesPassed`]; `None` on OpenGL ES (it has neither).
    pub fn for_context(gl: &glow::Context) -> Option<Self> {
        let v = gl.version();
        let extension = gl.supported_extensions().contains("GL_ARB_pipeline_statistics_query");
        Self::choose(v.is_embedded, (v.major, v.minor), extension)
    }

    fn choose(embedded: bool, version: (u32, u32), pipeline_statistics: bool) -> Option<Self> {
        match (embedded, version >= (4, 6) || pipeline_statistics) {
            (true, _) => None,
            (false, true) => Some(Self::FragmentShaderInvocations),
            (false, false) => Some(Self::SamplesPassed),
        }
    }

    /// The name `umbra bench --json` writes (`volume_fragments_query`):
    /// `"fragment_shader_invocations"` or `"samples_passed"`.
    pub fn name(self) -> &'static str {
        match self {
            Self::FragmentShaderInvocations => "fragment_shader_invocations",
            Self::SamplesPassed => "samples_passed",
        }
    }

    /// The GL query target.
    pub fn target(self) -> u32 {
        match self {
            Self::FragmentShaderInvocations => FRAGMENT_SHADER_INVOCATIONS,
            Self::SamplesPassed => glow::SAMPLES_PASSED,
        }
    }

    /// The targets whose active query makes glBeginQuery(self.target()) fail: its own, and for
    /// an occlusion query all three occlusion targets (they share one slot).
    fn busy_targets(self) -> &'static [u32] {
        match self {
            Self::FragmentShaderInvocations => &[FRAGMENT_SHADER_INVOCATIONS],
            Self::SamplesPassed => {
                &[glow::SAMPLES_PASSED, glow::ANY_SAMPLES_PASSED, glow::ANY_SAMPLES_PASSED_CONSERVATIVE]
            }
        }
    }
}

impl Renderer {
    /// The query the fragment counts use ([`Renderer::set_count_volume_fragments`]): chosen
    /// at the first counted pass ([`VolumeFragmentQuery::for_context`]); `None` before, or
    /// where the context has no such query.
    pub fn volume_fragment_query(&self) -> Option<VolumeFragmentQuery> {
        self.fragment_query_kind
    }

    /// Begins counting one volume pass's fragments: the query and its kind, or `None` when
    /// the context has no query for it or a host's query holds its target.
    pub(super) fn begin_fragment_count(&mut self, gl: &glow::Context) -> Option<(glow::Query, VolumeFragmentQuery)> {
        let kind = match self.fragment_query_kind {
            Some(k) => k,
            None => {
                let k = VolumeFragmentQuery::for_context(gl)?;
                self.fragment_query_kind = Some(k);
                k
            }
        };
        // SAFETY: glGetQueryiv(CURRENT_QUERY) on the current context, for targets it knows
        // (the kind was chosen from this context's version and extensions).
        if kind.busy_targets().iter().any(|&t| unsafe { self.extra.current_query(t) }.is_some_and(|q| q != 0)) {
            return None;
        }
        let query = match self.fragment_query {
            Some(q) => q,
            None => {
                // SAFETY: creating a query name on the current context.
                let q = unsafe { gl.create_query() }.ok()?;
                self.fragment_query = Some(q);
                q
            }
        };
        // SAFETY: our own query, not active (ended in end_fragment_count); its target is
        // free (checked above). A method may bind other framebuffers inside (a shadow map's
        // depth pass): both kinds count fragments whatever the framebuffer, so that pass is
        // counted as part of the method's fill.
        unsafe { gl.begin_query(kind.target(), query) };
        Some((query, kind))
    }

    /// Ends the count begun by [`Renderer::begin_fragment_count`] and reads it: waits for the
    /// pass (a stall; only when counting was asked for).
    pub(super) fn end_fragment_count(
        &mut self,
        gl: &glow::Context,
        (query, kind): (glow::Query, VolumeFragmentQuery),
    ) -> u64 {
        // SAFETY: ends the query begun on this target; reading its result waits for the pass.
        unsafe {
            gl.end_query(kind.target());
            gl.get_query_parameter_u64(query, glow::QUERY_RESULT)
        }
    }
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use umbra_geom::scene::{ground_plane, uv_sphere};
    use umbra_geom::weld::weld;

    use super::VolumeFragmentQuery as Q;
    use crate::context::{ContextOptions, GlApi, HeadlessContext};
    use crate::{create_method, Camera, FrameParams, Renderer, SceneGpu};

    /// The fallback on a GL that has the preferred query too: `GL_SAMPLES_PASSED` begun and
    /// ended around the pass without a GL error, counting the volume's samples in front of
    /// the sphere and the ground.
    #[test]
    fn samples_passed_counts_where_chosen() {
        let ctx = HeadlessContext::with_options(ContextOptions { api: GlApi::Gl45Core, debug: true })
            .unwrap_or_else(|e| panic!("no headless GL 4.5 context: {e}"));
        let gl = ctx.gl();
        let mut mesh = uv_sphere([0.0, 2.0, 0.0], 1.0, 24, 12);
        mesh.append(&ground_plane([0.0, 0.0, 0.0], 10.0));
        let scene = SceneGpu::upload(gl, Arc::new(weld(&mesh))).expect("upload");
        let mut method = create_method("cpu-silhouette").expect("registered");
        let mut r = Renderer::new(gl).expect("renderer").with_error_log(ctx.error_log().cloned());
        r.fragment_query_kind = Some(Q::SamplesPassed);
        r.set_count_volume_fragments(true);
        let camera = Camera { eye: [0.0, 5.0, 8.0], target: [0.0, 0.5, 0.0], ..Camera::default() };
        let p = FrameParams { camera, width: 96, height: 72, lights: vec![[0.0, 6.0, 0.0, 1.0]], ..Default::default() };
        r.render(gl, &scene, method.as_mut(), &p, None).expect("counted frame");
        let counted = r.last_volume_fragments().to_vec();
        assert_eq!(r.volume_fragment_query(), Some(Q::SamplesPassed));
        method.destroy(gl);
        r.destroy(gl);
        scene.destroy(gl);
        assert!(matches!(counted[..], [Some(n)] if n > 0), "{counted:?}");
    }

    #[test]
    fn pipeline_statistics_where_offered_samples_passed_otherwise_none_on_es() {
        assert_eq!(Q::choose(false, (4, 5), true), Some(Q::FragmentShaderInvocations));
        assert_eq!(Q::choose(false, (4, 6), false), Some(Q::FragmentShaderInvocations), "core in 4.6");
        assert_eq!(Q::choose(false, (4, 5), false), Some(Q::SamplesPassed));
        assert_eq!(Q::choose(true, (3, 2), false), None);
        assert_eq!(Q::FragmentShaderInvocations.name(), "fragment_shader_invocations");
        assert_eq!(Q::SamplesPassed.target(), glow::SAMPLES_PASSED);
    }
}
