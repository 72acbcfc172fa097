//! `Renderer::set_count_volume_fragments`: per light, the fragments its volume pass
//! rasterized (one GL query around `draw_volumes`), only when asked, only for methods that
//! fill volumes, and never while a host's own query holds the target.

mod common;

use common::*;
use glow::HasContext;
use umbra_gl::{create_method, FrameParams, HeadlessContext, Renderer, SceneGpu, VolumeFragmentQuery};

/// The sphere over the ground from `default_camera`, lit from above (its shadow and volume in
/// view) and by a second light beside it (two lights: one count each).
fn frame() -> FrameParams {
    FrameParams {
        camera: default_camera(),
        width: 160,
        height: 120,
        lights: vec![POINT_LIGHT, [4.0, 5.0, -1.0, 1.0]],
        ..FrameParams::default()
    }
}

/// Renders `method` once per entry of `counting` (count on or off for that frame) on one
/// renderer; returns each frame's `last_volume_fragments` and the query kind at the end.
fn counts(
    ctx: &HeadlessContext,
    method: &str,
    counting: &[bool],
    around: impl Fn(&glow::Context, &mut dyn FnMut()),
) -> (Vec<Vec<Option<u64>>>, Option<VolumeFragmentQuery>) {
    let gl = ctx.gl();
    let scene = SceneGpu::upload(gl, sphere_over_ground()).expect("upload");
    let mut m = create_method(method).expect("registered method");
    let mut r = Renderer::new(gl).expect("renderer").with_error_log(ctx.error_log().cloned());
    let p = frame();
    let mut out = Vec::new();
    for &on in counting {
        r.set_count_volume_fragments(on);
        around(gl, &mut || {
            r.render(gl, &scene, m.as_mut(), &p, None).unwrap_or_else(|e| panic!("{method}: {e}"));
        });
        out.push(r.last_volume_fragments().to_vec());
    }
    let kind = r.volume_fragment_query();
    m.destroy(gl);
    r.destroy(gl);
    scene.destroy(gl);
    (out, kind)
}

fn plain(_: &glow::Context, f: &mut dyn FnMut()) {
    f()
}

#[test]
fn cpu_silhouette_counts_its_volume_fragments_when_asked() {
    let ctx = context();
    let (frames, kind) = counts(&ctx, "cpu-silhouette", &[true, false], plain);
    let expected = VolumeFragmentQuery::for_context(ctx.gl()).expect("a GL 4.5 core context has a fragment query");
    assert_eq!(kind, Some(expected));
    eprintln!("{}: {} counts {:?}", ctx.renderer_string(), expected.name(), frames[0]);
    match frames[0][..] {
        [Some(above), Some(beside)] => {
            assert!(above > 0 && beside > 0, "both lights' volumes are in view, yet {above} and {beside} fragments");
        }
        ref other => panic!("two counted lights expected, got {other:?}"),
    }
    assert_eq!(frames[1], [None, None], "counting switched off: no counts (no stall)");
}

#[test]
fn methods_without_volume_fragments() {
    let ctx = context();
    // `none` has a volume pass that draws nothing: counted, zero.
    let (none, _) = counts(&ctx, "none", &[true], plain);
    assert_eq!(none[0], [Some(0), Some(0)]);
    // hier-triangle fills no volumes: nothing to count.
    let (hier, kind) = counts(&ctx, "hier-triangle", &[true], plain);
    assert_eq!(hier[0], [None, None]);
    assert_eq!(kind, None, "no pass was counted, so no query was chosen");
}

/// A host that has its own query of the same target running around the frame: the renderer
/// does not begin a second one (a GL error, which `render` would return), counts nothing, and
/// the host's query still counts the frame's fragments.
#[test]
fn a_hosts_active_query_is_left_alone() {
    let ctx = context();
    let kind = VolumeFragmentQuery::for_context(ctx.gl()).expect("fragment query");
    let host_count = std::cell::Cell::new(0u64);
    let (frames, _) = counts(&ctx, "cpu-silhouette", &[true], |gl, f| {
        // SAFETY: a test's own query around the frame, on the current context.
        unsafe {
            let q = gl.create_query().expect("query");
            gl.begin_query(kind.target(), q);
            f();
            gl.end_query(kind.target());
            host_count.set(gl.get_query_parameter_u64(q, glow::QUERY_RESULT));
            gl.delete_query(q);
        }
    });
    assert_eq!(frames[0], [None, None], "not counted under the host's query");
    assert!(host_count.get() > 0, "the host's query counted the frame");
}
