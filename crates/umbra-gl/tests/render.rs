//! Render tests with analytically known pixels: a sphere above a ground plane.

mod common;

use common::*;
use umbra_gl::{
    create_method, Camera, Classification, DepthConvention, FrameImages, FrameParams, HeadlessContext, LightCapture,
    NO_TRIANGLE,
};

/// Distance from the sphere centre to the segment world -> light (light w = 1) or the ray
/// world -> direction (w = 0).
fn segment_distance_to_center(world: [f64; 3], light: [f32; 4]) -> f64 {
    let l = light.map(f64::from);
    let c = SPHERE_CENTER;
    let d = if l[3] == 1.0 { [l[0] - world[0], l[1] - world[1], l[2] - world[2]] } else { [l[0], l[1], l[2]] };
    let w = [c[0] - world[0], c[1] - world[1], c[2] - world[2]];
    let dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    let mut t = (w[0] * d[0] + w[1] * d[1] + w[2] * d[2]) / dd;
    t = if l[3] == 1.0 { t.clamp(0.0, 1.0) } else { t.max(0.0) };
    let p = [world[0] + t * d[0], world[1] + t * d[1], world[2] + t * d[2]];
    ((p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2) + (p[2] - c[2]).powi(2)).sqrt()
}

/// Checks ground points (x, z): the rendered world position, triangle id (a ground
/// triangle), the lit mask (0 behind the sphere, 1 elsewhere), for counting methods
/// (`counting`) the stencil (exactly 2 = the two sphere triangles between point and light,
/// or 0), and colour (ambient, or ambient + analytic diffuse + specular).
#[allow(clippy::too_many_arguments)]
fn check_ground(
    ctx: &HeadlessContext,
    test: &'static str,
    img: &FrameImages,
    p: &FrameParams,
    light_index: usize,
    points: &[[f64; 2]],
    triangle_count: usize,
    method: &str,
    counting: bool,
) -> (usize, usize) {
    let light = p.lights[light_index];
    let wp = img.world_pos.as_ref().expect("world positions captured");
    let ids = img.triangle_id.as_ref().expect("ids captured");
    let stencil = &img.stencil.iter().find(|s| s.light == light_index).expect("stencil captured").image;
    let mask = &img.lit_masks.iter().find(|s| s.light == light_index).expect("lit mask captured").image;
    let mut checks = PixelChecks::new(ctx, test, &img.rgba);
    let (mut shadowed, mut lit) = (0, 0);
    for &[x, z] in points {
        let (px, py) = pixel_of(&p.camera, [x, 0.0, z], p.width, p.height);
        let w = wp.get(px, py).expect("in image");
        let id = ids.get(px, py).expect("in image");
        checks.check(px, py, id as usize >= triangle_count - 2 && id != NO_TRIANGLE, || {
            format!("id {id} is not a ground triangle")
        });
        checks.check(px, py, w[3] == 1.0 && w[1].abs() < 1e-4, || format!("world position {w:?} not on the ground"));
        let world = [w[0], w[1], w[2]].map(f64::from);
        let d = segment_distance_to_center(world, light);
        // The tessellated sphere is inscribed in the ideal one (48 x 24: radius >= 0.991).
        assert!(
            (d - SPHERE_RADIUS).abs() > 0.1,
            "{test}: test point ({x}, {z}) is too close to the shadow boundary (d = {d})"
        );
        let s = stencil.get(px, py).expect("in image");
        let m = mask.get(px, py).expect("in image");
        let checks_before = checks.failures();
        let c = img.rgba.get(px, py).expect("in image");
        if d < SPHERE_RADIUS {
            shadowed += 1;
            checks.check(px, py, m == 0, || format!("ground ({x}, {z}) behind the sphere: lit mask {m}, expected 0"));
            checks.check(px, py, !counting || s == 2, || {
                format!("ground ({x}, {z}) behind the sphere: stencil {s}, expected 2")
            });
            let e = expected_ambient_u8(p);
            checks.check(px, py, c[0].abs_diff(e) <= 1 && c[2].abs_diff(e) <= 1, || {
                format!("shadowed colour {c:?}, expected {e}")
            });
        } else {
            lit += 1;
            checks.check(px, py, m == 1, || format!("ground ({x}, {z}) lit: lit mask {m}, expected 1"));
            checks.check(px, py, !counting || s == 0, || format!("ground ({x}, {z}) lit: stencil {s}, expected 0"));
            let e = to_u8(expected_lit(p, world, [0.0, 1.0, 0.0], light));
            checks.check(px, py, c[0].abs_diff(e) <= 2, || format!("lit colour {c:?}, expected {e}"));
        }
        if checks.failures() > checks_before {
            checks.check(px, py, false, || format!("(the failures above are {method}'s)"));
        }
    }
    checks.finish();
    (shadowed, lit)
}

const GROUND_POINTS: [[f64; 2]; 9] =
    [[0.2, 0.3], [-0.5, 0.4], [0.6, -0.5], [0.0, 0.9], [3.0, 0.0], [-3.0, 1.0], [2.5, 2.5], [0.0, 3.5], [-2.0, -1.0]];

#[test]
fn point_light_shadows_the_ground_under_the_sphere() {
    let ctx = context();
    let mesh = sphere_over_ground();
    let p = params(default_camera(), vec![POINT_LIGHT], 320, 240);
    let counting = counting_methods();
    for method in overlap_exact_methods() {
        let img = render_once(&ctx, &mesh, method, &p);
        let c = counting.contains(&method);
        let (s, l) =
            check_ground(&ctx, "point_light_ground", &img, &p, 0, &GROUND_POINTS, mesh.triangles.len(), method, c);
        assert!(s >= 4 && l >= 4, "{method}: {s} shadowed / {l} lit test points");
        // The top of the sphere faces the light: lit (stencil 0 for counting methods).
        let (px, py) = pixel_of(&p.camera, [0.0, 2.99, 0.0], p.width, p.height);
        assert_eq!(img.lit_masks[0].image.get(px, py), Some(1), "{method}: sphere top must be lit");
        if c {
            assert_eq!(img.stencil[0].image.get(px, py), Some(0), "{method}: sphere top has stencil 0");
        }
    }
}

#[test]
fn directional_light_shadows_the_ground_along_its_direction() {
    let ctx = context();
    let mesh = sphere_over_ground();
    // Light from (0.3, 1, 0.2): the sphere centre's shadow lands at (-0.6, 0, -0.4).
    let light = [0.3, 1.0, 0.2, 0.0];
    let p = params(default_camera(), vec![light], 320, 240);
    let points = [[-0.6, -0.4], [-0.2, -0.1], [-1.0, -0.6], [0.6, 0.6], [2.5, 0.0], [-3.0, 2.0], [-2.5, -2.5]];
    let counting = counting_methods();
    for method in overlap_exact_methods() {
        let img = render_once(&ctx, &mesh, method, &p);
        let c = counting.contains(&method);
        let (s, l) =
            check_ground(&ctx, "directional_light_ground", &img, &p, 0, &points, mesh.triangles.len(), method, c);
        assert!(s >= 3 && l >= 3, "{method}: {s} shadowed / {l} lit test points");
    }
}

/// Eye on the ground beneath the sphere (inside its shadow volume), looking sideways and down.
fn inside_shadow_camera() -> Camera {
    Camera {
        eye: [0.0, 0.3, 0.0],
        target: [0.8, 0.0, 0.3],
        up: [0.0, 1.0, 0.0],
        fov_y_degrees: 60.0,
        near: 0.05,
        ..Camera::default()
    }
}

/// Ground points seen by `inside_shadow_camera`: two in the shadow, two far outside it.
const INSIDE_POINTS: [[f64; 2]; 4] = [[0.8, 0.3], [0.6, 0.1], [2.8, 1.05], [3.5, 0.5]];

#[test]
fn camera_inside_the_shadow_volume_is_right_with_zfail() {
    let ctx = context();
    let mesh = sphere_over_ground();
    let p = params(inside_shadow_camera(), vec![POINT_LIGHT], 320, 240);
    assert!(segment_distance_to_center(p.camera.eye, POINT_LIGHT) < 0.5, "the eye must be in the umbra");
    let counting = counting_methods();
    for method in overlap_exact_methods() {
        let img = render_once(&ctx, &mesh, method, &p);
        let c = counting.contains(&method);
        let (s, l) =
            check_ground(&ctx, "inside_shadow_zfail", &img, &p, 0, &INSIDE_POINTS, mesh.triangles.len(), method, c);
        assert_eq!((s, l), (2, 2), "{method}");
    }
}

/// The documented failure of z-pass (why z-fail is the default): z-pass counts the volume
/// faces between the eye and the sample, i.e. winding(sample) - winding(eye). With the eye
/// under the sphere its own winding is 2 (both sphere triangles lie between it and the
/// light), so shadowed ground reads 2 - 2 = 0 and is drawn LIT, and lit ground reads
/// 0 - 2 = 254 (mod 256) and is drawn SHADOWED.
#[test]
fn camera_inside_the_shadow_volume_is_wrong_with_zpass() {
    let ctx = context();
    let mesh = sphere_over_ground();
    let mut p = params(inside_shadow_camera(), vec![POINT_LIGHT], 320, 240);
    p.zpass = true;
    // z-pass is a counting scheme: only the stencil-counting methods have it.
    for method in counting_methods() {
        let img = render_once(&ctx, &mesh, method, &p);
        let st = &img.stencil[0].image;
        let wp = img.world_pos.as_ref().expect("captured");
        let ambient = expected_ambient_u8(&p);
        for (i, &[x, z]) in INSIDE_POINTS.iter().enumerate() {
            let (px, py) = pixel_of(&p.camera, [x, 0.0, z], p.width, p.height);
            let s = st.get(px, py).expect("in image");
            let c = img.rgba.get(px, py).expect("in image");
            if i < 2 {
                assert_eq!(s, 0, "{method}: z-pass count in the shadow: 2 - 2");
                let w = wp.get(px, py).expect("in image");
                let lit = to_u8(expected_lit(&p, [w[0], w[1], w[2]].map(f64::from), [0.0, 1.0, 0.0], POINT_LIGHT));
                assert!(
                    c[0].abs_diff(lit) <= 2 && lit > ambient + 20,
                    "{method}: shadowed ground drawn lit by z-pass: {c:?}"
                );
            } else {
                assert_eq!(s, 254, "{method}: z-pass count outside the shadow: 0 - 2 wraps to 254");
                assert!(c[0].abs_diff(ambient) <= 1, "{method}: lit ground drawn shadowed by z-pass: {c:?}");
            }
        }
    }
}

#[test]
fn zpass_and_zfail_agree_when_the_camera_is_outside_every_volume() {
    let ctx = context();
    let mesh = sphere_over_ground();
    let mut p = params(default_camera(), vec![POINT_LIGHT, [0.4, 1.0, -0.3, 0.0]], 320, 240);
    for method in shadow_methods() {
        p.zpass = false;
        p.auto_zpass = false; // really z-fail (auto would pick z-pass here)
        let zfail = render_once(&ctx, &mesh, method, &p);
        p.zpass = true;
        let zpass = render_once(&ctx, &mesh, method, &p);
        assert_same_image(&ctx, &format!("zpass_vs_zfail_{method}"), &zfail.rgba, &zpass.rgba);
    }
}

#[test]
fn the_none_method_lights_everything() {
    let ctx = context();
    let mesh = sphere_over_ground();
    let p = params(default_camera(), vec![POINT_LIGHT], 320, 240);
    let img = render_once(&ctx, &mesh, "none", &p);
    let (px, py) = pixel_of(&p.camera, [0.2, 0.0, 0.3], p.width, p.height);
    assert_eq!(img.stencil[0].image.get(px, py), Some(0));
    let w = img.world_pos.as_ref().and_then(|w| w.get(px, py)).expect("captured");
    let e = to_u8(expected_lit(&p, [w[0], w[1], w[2]].map(f64::from), [0.0, 1.0, 0.0], POINT_LIGHT));
    let c = img.rgba.get(px, py).expect("in image");
    assert!(c[0].abs_diff(e) <= 2, "none: ground under the sphere is lit: {c:?} vs {e}");
}

#[test]
fn rendering_is_deterministic_to_the_png_byte() {
    let ctx = context();
    let mesh = sphere_over_ground();
    let p = params(default_camera(), vec![POINT_LIGHT, [0.3, 1.0, 0.2, 0.0]], 256, 192);
    for method in shadow_methods() {
        let a = render_once(&ctx, &mesh, method, &p);
        let b = render_once(&ctx, &mesh, method, &p);
        assert_same_image(&ctx, "determinism", &a.rgba, &b.rgba);
        assert_eq!(a, b, "{method}: every captured image must repeat exactly");
        let dir = output_dir().join("determinism");
        let (pa, pb) = (dir.join(format!("{method}-a.png")), dir.join(format!("{method}-b.png")));
        a.rgba.save_png(&pa).expect("png");
        b.rgba.save_png(&pb).expect("png");
        assert_eq!(std::fs::read(&pa).expect("read"), std::fs::read(&pb).expect("read"), "{method}: PNG bytes");
    }
}

/// Every drawn pixel's world position lies on the triangle its id names (index into
/// WeldedMesh::triangles); background pixels have w = 0 and NO_TRIANGLE.
#[test]
fn triangle_ids_name_the_triangle_under_each_pixel() {
    let ctx = context();
    let mesh = sphere_over_ground();
    let p = params(default_camera(), vec![POINT_LIGHT], 200, 150);
    let img = render_once(&ctx, &mesh, "cpu-silhouette", &p);
    let (wp, ids) = (img.world_pos.as_ref().expect("wp"), img.triangle_id.as_ref().expect("ids"));
    let (mut drawn, mut background) = (0, 0);
    for (w, &id) in wp.pixels.iter().zip(&ids.pixels) {
        if id == NO_TRIANGLE {
            background += 1;
            assert_eq!(*w, [0.0; 4], "background pixel with a world position");
            continue;
        }
        drawn += 1;
        assert_eq!(w[3], 1.0);
        let t = mesh.triangles[id as usize];
        let [a, b, c] = t.map(|i| mesh.positions[i as usize].map(f64::from));
        let n = umbra_gl::scene::flat_normal(&mesh.positions, t).map(f64::from);
        let q = [w[0], w[1], w[2]].map(f64::from);
        let dist = (0..3).map(|k| (q[k] - a[k]) * n[k]).sum::<f64>().abs();
        assert!(dist < 1e-3, "pixel world position {q:?} is {dist} off the plane of triangle {id}");
        for k in 0..3 {
            let (lo, hi) = (a[k].min(b[k]).min(c[k]), a[k].max(b[k]).max(c[k]));
            assert!(q[k] > lo - 0.05 && q[k] < hi + 0.05, "pixel {q:?} outside triangle {id}'s box");
        }
    }
    assert!(drawn > 1000 && background > 1000, "{drawn} drawn, {background} background pixels");
}

/// Two lights add: where both light a point, the colour is ambient + both contributions;
/// where one is blocked, only the other adds.
#[test]
fn several_lights_add_their_contributions() {
    let ctx = context();
    let mesh = sphere_over_ground();
    let l1 = POINT_LIGHT;
    let l2 = [4.0, 5.0, 1.0, 1.0];
    // Dimmer lights so that the sum stays below 8-bit saturation.
    let dim = |lights| FrameParams { light_color: [0.45; 3], ..params(default_camera(), lights, 320, 240) };
    let both = render_once(&ctx, &mesh, "cpu-silhouette", &dim(vec![l1, l2]));
    let only1 = render_once(&ctx, &mesh, "cpu-silhouette", &dim(vec![l1]));
    let only2 = render_once(&ctx, &mesh, "cpu-silhouette", &dim(vec![l2]));
    let p = dim(vec![l1, l2]);
    let ambient = i32::from(expected_ambient_u8(&p));
    let mut checks = PixelChecks::new(&ctx, "several_lights", &both.rgba);
    for [x, z] in [[0.2, 0.3], [3.0, 0.0], [-2.0, -1.0], [0.0, 3.5]] {
        let (px, py) = pixel_of(&p.camera, [x, 0.0, z], p.width, p.height);
        let c = i32::from(both.rgba.get(px, py).expect("in")[0]);
        let c1 = i32::from(only1.rgba.get(px, py).expect("in")[0]);
        let c2 = i32::from(only2.rgba.get(px, py).expect("in")[0]);
        // 8-bit rounding happens once per pass: allow 2 levels.
        checks.check(px, py, (c - (c1 + c2 - ambient)).abs() <= 2, || format!("both {c} != {c1} + {c2} - {ambient}"));
        let s1 = both.stencil[0].image.get(px, py).expect("in");
        let s1_alone = only1.stencil[0].image.get(px, py).expect("in");
        checks.check(px, py, s1 == s1_alone, || format!("light 0 stencil {s1} vs {s1_alone} alone"));
    }
    // The point under the sphere is shadowed from light 1 but lit by light 2.
    let (px, py) = pixel_of(&p.camera, [0.2, 0.0, 0.3], p.width, p.height);
    checks.check(px, py, both.stencil[0].image.get(px, py) == Some(2), || "light 0 must be blocked".into());
    checks.check(px, py, both.stencil[1].image.get(px, py) == Some(0), || "light 1 must reach".into());
    checks.finish();
}

/// The lit mask is the renderer's final per-pixel decision: for counting methods
/// (Classification::StencilZero) exactly "stencil == 0 AND the seen side faces the light", per
/// light, 0 on background; and the colour agrees with it (ambient where 0, brighter where 1).
/// `none` (stencil 0 everywhere) shows the facing part: the sphere's dark side, seen from the
/// camera, has stencil 0 and mask 0; the shadow methods show the stencil part (their pushed
/// light caps make every dark side count as shadowed in the stencil too).
#[test]
fn lit_mask_is_stencil_zero_and_facing_the_light() {
    let ctx = context();
    let mesh = sphere_over_ground();
    let lights = vec![POINT_LIGHT, [0.3, 1.0, 0.2, 0.0]];
    let p = params(default_camera(), lights.clone(), 320, 240);
    let single = params(default_camera(), vec![POINT_LIGHT], 320, 240);
    let ambient = expected_ambient_u8(&p);
    let counting: Vec<&str> = std::iter::once("none")
        .chain(shadow_methods())
        .filter(|m| create_method(m).expect("registered").classification() == Classification::StencilZero)
        .collect();
    assert!(counting.contains(&"cpu-silhouette"), "{counting:?}");
    for method in counting {
        let img = render_once(&ctx, &mesh, method, &p);
        let (wp, ids) = (img.world_pos.as_ref().expect("wp"), img.triangle_id.as_ref().expect("ids"));
        assert_eq!(
            img.lit_masks.iter().map(|m| m.light).collect::<Vec<_>>(),
            vec![0, 1],
            "{method}: one mask per light, in order"
        );
        let mut checks = PixelChecks::new(&ctx, "lit_mask_stencil_facing", &img.rgba);
        for (li, &light) in lights.iter().enumerate() {
            let (mask, st) = (&img.lit_masks[li].image, &img.stencil[li].image);
            let (mut lit, mut shadowed, mut facing_away_stencil_zero, mut ambiguous, mut drawn) = (0, 0, 0, 0, 0);
            for y in 0..p.height {
                for x in 0..p.width {
                    let (m, s, id) =
                        (mask.get(x, y).expect("in"), st.get(x, y).expect("in"), ids.get(x, y).expect("in"));
                    assert!(m <= 1, "{method}: mask values are 0 / 1, got {m}");
                    if id == NO_TRIANGLE {
                        checks.check(x, y, m == 0, || format!("{method} light {li}: background marked lit"));
                        continue;
                    }
                    drawn += 1;
                    let w = wp.get(x, y).expect("in");
                    let Some(faces) =
                        seen_side_faces_light(&mesh, id, [w[0], w[1], w[2]].map(f64::from), p.camera.eye, light)
                    else {
                        ambiguous += 1;
                        continue;
                    };
                    let expected = s == 0 && faces;
                    lit += usize::from(expected);
                    shadowed += usize::from(faces && s != 0);
                    facing_away_stencil_zero += usize::from(!faces && s == 0);
                    if u8::from(expected) != m {
                        checks.check(x, y, false, || {
                            format!("{method} light {li}: mask {m}, stencil {s}, seen side faces light {faces}")
                        });
                    }
                }
            }
            // The cases the mask must tell apart occur.
            let counts = format!("{method} light {li}: {lit} lit, {shadowed} shadowed, {facing_away_stencil_zero} facing away with stencil 0");
            assert!(lit > 1000, "{counts}");
            if method == "none" {
                assert!(shadowed == 0 && facing_away_stencil_zero > 200, "{counts}");
            } else {
                assert!(shadowed > 200, "{counts}");
            }
            assert!(
                ambiguous * 200 < drawn,
                "{method} light {li}: {ambiguous} of {drawn} pixels edge-on to camera or light"
            );
        }
        checks.finish();

        // The colour agrees with the mask (one light, so the colour is ambient + that light).
        let one = render_once(&ctx, &mesh, method, &single);
        let mask = &one.lit_masks[0].image;
        let ids = one.triangle_id.as_ref().expect("ids");
        let mut checks = PixelChecks::new(&ctx, "lit_mask_matches_colour", &one.rgba);
        let (mut dark, mut bright) = (0, 0);
        for y in 0..single.height {
            for x in 0..single.width {
                if ids.get(x, y) == Some(NO_TRIANGLE) {
                    continue;
                }
                let c = one.rgba.get(x, y).expect("in")[0];
                if mask.get(x, y) == Some(0) {
                    dark += 1;
                    checks.check(x, y, c.abs_diff(ambient) <= 1, || {
                        format!("{method}: mask 0 but colour {c} != ambient {ambient}")
                    });
                } else if c > ambient + 1 {
                    bright += 1;
                }
            }
        }
        assert!(dark > 300 && bright > 1000, "{method}: {dark} unlit, {bright} lit pixels");
        checks.finish();

        // Capturing one light gives exactly that light's mask.
        let mut p1 = p.clone();
        p1.capture.lit_mask = LightCapture::Light(1);
        let only = render_once(&ctx, &mesh, method, &p1);
        assert_eq!(only.lit_masks.len(), 1, "{method}");
        assert_eq!(only.lit_masks[0], img.lit_masks[1], "{method}: Light(1) capture equals AllLights' mask of light 1");
        assert_same_image(&ctx, "lit_mask_capture_does_not_change_colour", &img.rgba, &only.rgba);
    }
}

/// Standard (DEPTH24_STENCIL8, [-1, 1]) and reversed-Z (DEPTH32F_STENCIL8, glClipControl
/// ZERO_TO_ONE) frames of the same scene. In general the two may differ only in the one-pixel
/// band around shadow boundaries (where their depth precisions may decide differently); on
/// this scene, whose volumes never graze a surface, they agree exactly, and so must every
/// method.
#[test]
fn standard_and_reversed_z_give_the_same_image() {
    let ctx = context();
    let mesh = sphere_over_ground();
    let base = params(default_camera(), vec![POINT_LIGHT, [0.3, 1.0, 0.2, 0.0]], 320, 240);
    let standard = FrameParams { depth_convention: DepthConvention::Standard, ..base.clone() };
    let reversed = FrameParams { depth_convention: DepthConvention::ReversedZ, ..base.clone() };
    assert_eq!(base.depth_convention, DepthConvention::ReversedZ, "reversed-Z is the default");
    for method in std::iter::once("none").chain(shadow_methods()) {
        let a = render_once(&ctx, &mesh, method, &standard);
        let b = render_once(&ctx, &mesh, method, &reversed);
        assert_eq!(a.triangle_id, b.triangle_id, "{method}: the same visible triangle at every pixel");
        assert_same_image(&ctx, "standard_vs_reversed_z", &a.rgba, &b.rgba);
        assert_eq!(a.lit_masks, b.lit_masks, "{method}: the same lit decisions");
    }
}
