//! `FrameParams::auto_zpass`: z-pass for the lights whose volumes provably leave the eye out
//! (umbra_geom::clearance), with the volumes clipped to the scene box; z-fail for the others.
//! Whatever it chooses, every counting method must give the z-fail image, byte for byte, and
//! the z-fail count on every visible sample.

mod common;

use std::sync::Arc;

use common::*;
use umbra_geom::WeldedMesh;
use umbra_gl::{create_method, Camera, FrameImages, FrameParams, HeadlessContext, Renderer, SceneGpu, NO_TRIANGLE};

/// Renders once; returns the images and which lights counted z-pass.
fn render(ctx: &HeadlessContext, mesh: &Arc<WeldedMesh>, method: &str, p: &FrameParams) -> (FrameImages, Vec<bool>) {
    let gl = ctx.gl();
    let scene = SceneGpu::upload(gl, mesh.clone()).expect("upload");
    let mut m = create_method(method).expect("registered method");
    let mut r = Renderer::new(gl).expect("renderer").with_error_log(ctx.error_log().cloned());
    let out = r.render(gl, &scene, m.as_mut(), p, None).unwrap_or_else(|e| panic!("render with {method}: {e}"));
    let zpass = r.last_zpass().to_vec();
    m.destroy(gl);
    r.destroy(gl);
    scene.destroy(gl);
    (out, zpass)
}

/// Counts of visible samples (a triangle id) that differ between two stencil captures.
fn visible_count_differences(a: &FrameImages, b: &FrameImages, light: usize) -> usize {
    let ids = a.triangle_id.as_ref().expect("ids captured");
    let sa = &a.stencil.iter().find(|s| s.light == light).expect("stencil").image;
    let sb = &b.stencil.iter().find(|s| s.light == light).expect("stencil").image;
    let mut n = 0;
    for y in 0..ids.height {
        for x in 0..ids.width {
            if ids.get(x, y) != Some(NO_TRIANGLE) && sa.get(x, y) != sb.get(x, y) {
                n += 1;
            }
        }
    }
    n
}

fn zfail(p: &FrameParams) -> FrameParams {
    FrameParams { zpass: false, auto_zpass: false, ..p.clone() }
}

#[test]
fn auto_zpass_is_chosen_when_the_eye_is_clear_and_equals_zfail() {
    let ctx = context();
    let mesh = sphere_over_ground();
    // The eye above and beside the scene; a point light and a directional light. The sphere's
    // volumes run below the ground, out of the scene box: the clip is exercised.
    let p = params(default_camera(), vec![POINT_LIGHT, [0.4, 1.0, -0.3, 0.0]], 320, 240);
    assert!(p.auto_zpass, "auto z-pass is the default");
    for method in counting_methods() {
        let (auto, zpass) = render(&ctx, &mesh, method, &p);
        assert_eq!(zpass, vec![true, true], "{method}: the eye is clear of both lights' volumes");
        let (reference, zpass) = render(&ctx, &mesh, method, &zfail(&p));
        assert_eq!(zpass, vec![false, false], "{method}: z-fail asked for");
        assert_same_image(&ctx, &format!("auto_zpass_clear_{method}"), &reference.rgba, &auto.rgba);
        for light in 0..2 {
            assert_eq!(visible_count_differences(&auto, &reference, light), 0, "{method}: light {light} counts differ");
        }
    }
}

#[test]
fn auto_zpass_with_the_eye_in_shadow_equals_zfail() {
    let ctx = context();
    let mesh = sphere_over_ground();
    // The eye under the sphere: inside the point light's volume, where plain z-pass is wrong
    // (render.rs: camera_inside_the_shadow_volume_is_wrong_with_zpass). Auto counts z-pass
    // from W0 when every near-pyramid ray crosses the same sphere triangles, z-fail otherwise:
    // either way the z-fail image.
    let eye = Camera {
        eye: [0.0, 0.3, 0.0],
        target: [0.8, 0.0, 0.3],
        up: [0.0, 1.0, 0.0],
        fov_y_degrees: 60.0,
        near: 0.05,
        ..Camera::default()
    };
    let p = params(eye, vec![POINT_LIGHT], 320, 240);
    for method in counting_methods() {
        let (auto, _) = render(&ctx, &mesh, method, &p);
        let (reference, _) = render(&ctx, &mesh, method, &zfail(&p));
        assert_same_image(&ctx, &format!("auto_zpass_shadowed_{method}"), &reference.rgba, &auto.rgba);
        assert_eq!(visible_count_differences(&auto, &reference, 0), 0, "{method}");
        // And plain z-pass really is wrong here.
        let (forced, zpass) = render(&ctx, &mesh, method, &FrameParams { zpass: true, ..p.clone() });
        assert_eq!(zpass, vec![true]);
        assert_ne!(
            visible_count_differences(&forced, &reference, 0),
            0,
            "{method}: forced z-pass should be wrong here"
        );
    }
}

/// Ground (y = 0) and a square roof at y = 2 over [-3, 3]^2, split along its x = z diagonal.
fn roof_over_ground() -> Arc<WeldedMesh> {
    let mut mesh = umbra_geom::scene::ground_plane([0.0, 2.0, 0.0], 3.0);
    mesh.append(&umbra_geom::scene::ground_plane([0.0, 0.0, 0.0], 10.0));
    Arc::new(umbra_geom::weld::weld(&mesh))
}

#[test]
fn auto_zpass_under_a_roof_starts_from_its_winding() {
    let ctx = context();
    let mesh = roof_over_ground();
    // Under the middle of one roof triangle, the light straight above it: the whole near
    // pyramid lies in that triangle's volume (W0 = 1), so z-pass counts from a stencil
    // cleared to 1. The camera sees shadowed ground under the roof and lit ground beyond it.
    let eye = Camera {
        eye: [1.5, 0.5, -1.5],
        target: [5.0, 0.0, 1.0],
        up: [0.0, 1.0, 0.0],
        fov_y_degrees: 60.0,
        near: 0.05,
        ..Camera::default()
    };
    let p = params(eye, vec![[1.5, 6.0, -1.5, 1.0]], 320, 240);
    for method in counting_methods() {
        let (auto, zpass) = render(&ctx, &mesh, method, &p);
        assert_eq!(zpass, vec![true], "{method}: the pyramid is inside exactly one volume");
        let (reference, _) = render(&ctx, &mesh, method, &zfail(&p));
        assert_same_image(&ctx, &format!("auto_zpass_roof_{method}"), &reference.rgba, &auto.rgba);
        assert_eq!(visible_count_differences(&auto, &reference, 0), 0, "{method}");
        // Without the start value (plain z-pass) every visible count is off by one.
        let (forced, _) = render(&ctx, &mesh, method, &FrameParams { zpass: true, ..p.clone() });
        assert_ne!(visible_count_differences(&forced, &reference, 0), 0, "{method}: plain z-pass should be wrong");
    }
    // Under the roof's diagonal: the two triangles' shared edge (multiplicity 0) runs through
    // the pyramid's cone, W stays 1 across it: still z-pass from 1.
    let eye = Camera {
        eye: [0.0, 0.5, 0.0],
        target: [5.0, 0.0, 1.0],
        up: [0.0, 1.0, 0.0],
        fov_y_degrees: 60.0,
        near: 0.05,
        ..Camera::default()
    };
    let p = params(eye, vec![[0.0, 6.0, 0.0, 1.0]], 320, 240);
    for method in ["cpu-silhouette", "vs-silhouette"] {
        let (auto, zpass) = render(&ctx, &mesh, method, &p);
        assert_eq!(zpass, vec![true], "{method}: an edge of multiplicity 0 changes nothing");
        let (reference, _) = render(&ctx, &mesh, method, &zfail(&p));
        assert_same_image(&ctx, &format!("auto_zpass_roof_diagonal_{method}"), &reference.rgba, &auto.rgba);
        assert_eq!(visible_count_differences(&auto, &reference, 0), 0, "{method}");
    }
    // Under the roof's outer edge (x = 3, an open edge: multiplicity 1), the shadow boundary
    // crosses the pyramid: unknown, so z-fail.
    let eye = Camera {
        eye: [3.0, 0.5, 0.0],
        target: [6.0, 0.0, 1.0],
        up: [0.0, 1.0, 0.0],
        fov_y_degrees: 60.0,
        near: 0.05,
        ..Camera::default()
    };
    let p = params(eye, vec![[3.0, 6.0, 0.0, 1.0]], 320, 240);
    for method in ["cpu-silhouette", "vs-silhouette"] {
        let (auto, zpass) = render(&ctx, &mesh, method, &p);
        assert_eq!(zpass, vec![false], "{method}: a shadow boundary crosses the pyramid");
        let (reference, _) = render(&ctx, &mesh, method, &zfail(&p));
        assert_same_image(&ctx, &format!("auto_zpass_roof_edge_{method}"), &reference.rgba, &auto.rgba);
    }
}

/// The eye clear of one light and in an unknown state for the other: chosen per light.
#[test]
fn auto_zpass_is_chosen_per_light() {
    let ctx = context();
    let mesh = roof_over_ground();
    // Under the roof's outer edge: the point light above it casts the edge's shadow boundary
    // through the pyramid (z-fail); a low directional light from +x reaches the eye past the
    // roof (clear: z-pass).
    let eye = Camera {
        eye: [3.0, 0.5, 0.0],
        target: [6.0, 0.0, 1.0],
        up: [0.0, 1.0, 0.0],
        fov_y_degrees: 60.0,
        near: 0.05,
        ..Camera::default()
    };
    let p = params(eye, vec![[3.0, 6.0, 0.0, 1.0], [1.0, 0.3, 0.0, 0.0]], 320, 240);
    for method in counting_methods() {
        let (auto, zpass) = render(&ctx, &mesh, method, &p);
        assert_eq!(zpass, vec![false, true], "{method}");
        let (reference, _) = render(&ctx, &mesh, method, &zfail(&p));
        assert_same_image(&ctx, &format!("auto_zpass_per_light_{method}"), &reference.rgba, &auto.rgba);
        for light in 0..2 {
            assert_eq!(visible_count_differences(&auto, &reference, light), 0, "{method}: light {light}");
        }
    }
}
