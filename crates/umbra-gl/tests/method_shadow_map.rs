//! `shadow-map-cube:RES`: analytic pixels (ground under the sphere dark, far ground lit) for
//! the point (cube map, layered and six-pass) and directional (2D map) variants, with and
//! without PCF; resolution limits and allocation failures are typed errors that leave the
//! context usable; gpu_bytes formula; registry parsing.

mod common;

use common::*;
use umbra_gl::glow::HasContext;
use umbra_gl::methods::shadow_map::{FacePasses, ShadowMapConfig, ShadowMapCube};
use umbra_gl::{
    create_method, glow, method_names, FrameParams, GlError, HeadlessContext, Renderer, SceneGpu, ShadowMethod,
};

/// Distance from the sphere centre to the segment world -> light (w = 1) or the ray towards
/// the light (w = 0).
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

/// Renders with `method` and checks ground points: well inside the umbra (analytic distance
/// of the light ray to the sphere centre < 0.8 R) ambient only; well outside (> 1.25 R) the
/// analytic lit colour. Returns (shadowed, lit) counts.
fn check_ground(
    ctx: &HeadlessContext,
    test: &'static str,
    method: &mut dyn ShadowMethod,
    p: &FrameParams,
    points: &[[f64; 2]],
) -> (usize, usize) {
    let gl = ctx.gl();
    let mesh = sphere_over_ground();
    let scene = SceneGpu::upload(gl, mesh).expect("upload");
    let mut r = Renderer::new(gl).expect("renderer").with_error_log(ctx.error_log().cloned());
    let img = r.render(gl, &scene, method, p, None).unwrap_or_else(|e| panic!("{test}: {e}"));
    let light = p.lights[0];
    let wp = img.world_pos.as_ref().expect("world positions captured");
    let mut checks = PixelChecks::new(ctx, test, &img.rgba);
    let (mut shadowed, mut lit) = (0, 0);
    for &[x, z] in points {
        let (px, py) = pixel_of(&p.camera, [x, 0.0, z], p.width, p.height);
        let w = wp.get(px, py).expect("in image");
        let world = [w[0], w[1], w[2]].map(f64::from);
        let d = segment_distance_to_center(world, light);
        assert!(
            !(0.8..=1.25).contains(&(d / SPHERE_RADIUS)),
            "{test}: point ({x}, {z}) too close to the shadow edge: {d}"
        );
        let c = img.rgba.get(px, py).expect("in image");
        if d < SPHERE_RADIUS {
            shadowed += 1;
            let e = expected_ambient_u8(p);
            checks.check(px, py, c[0].abs_diff(e) <= 1, || {
                format!("({x}, {z}) under the sphere: {c:?}, expected ambient {e}")
            });
        } else {
            lit += 1;
            let e = to_u8(expected_lit(p, world, [0.0, 1.0, 0.0], light));
            checks.check(px, py, c[0].abs_diff(e) <= 2, || {
                format!("({x}, {z}) far from the sphere: {c:?}, expected lit {e}")
            });
        }
    }
    checks.finish();
    method.destroy(gl);
    r.destroy(gl);
    scene.destroy(gl);
    (shadowed, lit)
}

const POINT_GROUND: [[f64; 2]; 8] =
    [[0.2, 0.3], [-0.5, 0.4], [0.0, 0.0], [0.3, -0.4], [3.0, 0.0], [-3.0, 1.0], [2.5, 2.5], [0.0, 3.5]];

#[test]
fn point_light_ground_under_sphere_is_dark_and_far_ground_lit() {
    let ctx = context();
    let p = params(default_camera(), vec![POINT_LIGHT], 320, 240);
    for (what, faces, pcf) in [
        ("layered", FacePasses::Layered, false),
        ("six passes", FacePasses::SixPasses, false),
        ("layered + pcf", FacePasses::Layered, true),
    ] {
        let mut m = ShadowMapCube::new(ShadowMapConfig { faces, pcf, ..ShadowMapConfig::new(1024) });
        let (s, l) = check_ground(&ctx, "shadow_map_point", &mut m, &p, &POINT_GROUND);
        assert!(s >= 4 && l >= 4, "{what}: {s} shadowed / {l} lit");
    }
}

#[test]
fn directional_light_uses_one_orthographic_map() {
    let ctx = context();
    // Light from (0.3, 1, 0.2): the sphere centre's shadow lands at (-0.6, 0, -0.4).
    let light = [0.3, 1.0, 0.2, 0.0];
    let p = params(default_camera(), vec![light], 320, 240);
    let points = [[-0.6, -0.4], [-0.4, -0.2], [-0.8, -0.5], [0.6, 0.6], [2.5, 0.0], [-3.0, 2.0], [-2.5, -2.5]];
    for pcf in [false, true] {
        let mut m = ShadowMapCube::new(ShadowMapConfig { pcf, ..ShadowMapConfig::new(2048) });
        let (s, l) = check_ground(&ctx, "shadow_map_directional", &mut m, &p, &points);
        assert!(s >= 3 && l >= 3, "pcf {pcf}: {s} shadowed / {l} lit");
        assert_eq!(m.gpu_bytes(), 0, "check_ground destroyed the method: its maps are freed");
    }
}

/// The one-pass layered cube and the six-pass cube store the same depths (same matrices, same
/// rasterisation), so the frames agree to the pixel.
#[test]
fn layered_and_six_pass_cubes_give_the_same_frame() {
    let ctx = context();
    let gl = ctx.gl();
    let scene = SceneGpu::upload(gl, sphere_over_ground()).expect("upload");
    let mut r = Renderer::new(gl).expect("renderer").with_error_log(ctx.error_log().cloned());
    let p = params(default_camera(), vec![POINT_LIGHT, [1.5, 4.0, -1.0, 1.0]], 256, 192);
    let mut images = Vec::new();
    for faces in [FacePasses::Layered, FacePasses::SixPasses] {
        let mut m = ShadowMapCube::new(ShadowMapConfig { faces, ..ShadowMapConfig::new(512) });
        images.push(r.render(gl, &scene, &mut m, &p, None).expect("render").rgba);
        assert_eq!(m.gpu_bytes(), 6 * 512 * 512 * 4, "one cube map, reused for both lights");
        m.destroy(gl);
    }
    assert_same_image(&ctx, "shadow_map_layered_vs_six", &images[0], &images[1]);
    r.destroy(gl);
    scene.destroy(gl);
}

#[test]
fn gpu_bytes_count_the_cube_and_the_directional_map() {
    let ctx = context();
    let gl = ctx.gl();
    let scene = SceneGpu::upload(gl, sphere_over_ground()).expect("upload");
    let mut r = Renderer::new(gl).expect("renderer").with_error_log(ctx.error_log().cloned());
    let mut m = create_method("shadow-map-cube:256").expect("parameterised name");
    assert_eq!(m.gpu_bytes(), 0, "nothing allocated before the first frame");
    let mut p = params(default_camera(), vec![POINT_LIGHT], 64, 48);
    r.render(gl, &scene, m.as_mut(), &p, None).expect("render");
    assert_eq!(m.gpu_bytes(), 6 * 256 * 256 * 4);
    p.lights.push([0.3, 1.0, 0.2, 0.0]);
    r.render(gl, &scene, m.as_mut(), &p, None).expect("render");
    assert_eq!(m.gpu_bytes(), 7 * 256 * 256 * 4);
    m.destroy(gl);
    assert_eq!(m.gpu_bytes(), 0);
    r.destroy(gl);
    scene.destroy(gl);
}

#[test]
fn registry_parses_the_resolution_suffix() {
    let names = method_names();
    assert!(names.contains(&"shadow-map-cube:1024") && names.contains(&"shadow-map-cube:2048"), "{names:?}");
    assert_eq!(create_method("shadow-map-cube:8192").expect("8K").name(), "shadow-map-cube:8192");
    assert_eq!(create_method("shadow-map-cube:4k").expect("4k suffix").name(), "shadow-map-cube:4096");
    for bad in
        ["shadow-map-cube", "shadow-map-cube:", "shadow-map-cube:0", "shadow-map-cube:big", "shadow-map-cube:12x"]
    {
        let err = create_method(bad).err().unwrap_or_else(|| panic!("{bad} must be rejected"));
        assert!(err.to_string().contains(bad), "{err}");
    }
}

/// RES above GL_MAX_CUBE_MAP_TEXTURE_SIZE: a typed error naming the limit, and the same
/// renderer and context keep working afterwards.
#[test]
fn resolution_above_the_limit_is_a_clear_error() {
    let ctx = context();
    let gl = ctx.gl();
    // SAFETY: integer query on the current context.
    let max = unsafe { gl.get_parameter_i32(glow::MAX_CUBE_MAP_TEXTURE_SIZE) };
    let scene = SceneGpu::upload(gl, sphere_over_ground()).expect("upload");
    let mut r = Renderer::new(gl).expect("renderer").with_error_log(ctx.error_log().cloned());
    let p = params(default_camera(), vec![POINT_LIGHT], 64, 48);
    let mut too_big = create_method(&format!("shadow-map-cube:{}", max as u32 + 1)).expect("any positive RES parses");
    match r.render(gl, &scene, too_big.as_mut(), &p, None) {
        Err(GlError::Unsupported { method, reason }) => {
            assert!(method.starts_with("shadow-map-cube:"));
            assert!(reason.contains("GL_MAX_CUBE_MAP_TEXTURE_SIZE") && reason.contains(&max.to_string()), "{reason}");
        }
        other => panic!("expected Unsupported, got {:?}", other.map(|_| ())),
    }
    assert_eq!(too_big.gpu_bytes(), 0);
    let mut ok = create_method("shadow-map-cube:128").expect("method");
    r.render(gl, &scene, ok.as_mut(), &p, None).expect("the context is still usable");
    ok.destroy(gl);
    r.destroy(gl);
    scene.destroy(gl);
}

/// GL_OUT_OF_MEMORY while allocating is caught: typed error, context usable. Allocating
/// gigabytes on a shared machine is opt-in: set UMBRA_TEST_SHADOW_MAP_OOM=RES (or `max` for
/// GL_MAX_CUBE_MAP_TEXTURE_SIZE).
#[test]
fn out_of_memory_is_caught() {
    let Some(res) = std::env::var_os("UMBRA_TEST_SHADOW_MAP_OOM") else {
        println!("skipped: set UMBRA_TEST_SHADOW_MAP_OOM=RES|max to try a huge cube map allocation");
        return;
    };
    let ctx = context();
    let gl = ctx.gl();
    // SAFETY: integer query on the current context.
    let limit = unsafe { gl.get_parameter_i32(glow::MAX_CUBE_MAP_TEXTURE_SIZE) } as u32;
    let max = res.to_str().and_then(|s| s.parse().ok()).unwrap_or(limit);
    println!("GL_MAX_CUBE_MAP_TEXTURE_SIZE = {limit}, trying {max}");
    let scene = SceneGpu::upload(gl, sphere_over_ground()).expect("upload");
    let mut r = Renderer::new(gl).expect("renderer").with_error_log(ctx.error_log().cloned());
    let p = params(default_camera(), vec![POINT_LIGHT], 64, 48);
    let mut huge = create_method(&format!("shadow-map-cube:{max}")).expect("method");
    let result = r.render(gl, &scene, huge.as_mut(), &p, None);
    println!("cube {max}: {:?}", result.as_ref().map(|_| ()));
    if let Err(e) = &result {
        assert!(matches!(e, GlError::Unsupported { .. } | GlError::OutOfMemory { .. }), "{e}");
    }
    huge.destroy(gl);
    let mut ok = create_method("shadow-map-cube:128").expect("method");
    r.render(gl, &scene, ok.as_mut(), &p, None).expect("the context is still usable");
    ok.destroy(gl);
    r.destroy(gl);
    scene.destroy(gl);
}
