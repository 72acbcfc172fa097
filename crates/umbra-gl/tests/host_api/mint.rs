//! The host API's mint types convert to umbra's at the boundary.

use crate::common::*;
use crate::host::{Host, H, W};
use crate::{view, POINT};
use umbra_gl::{
    camera::to_f32_cols, create_method, read_stencil, DepthConvention, FrameParams, FrameTarget, Renderer, SceneGpu,
};

/// Math types at the boundary: a host's mint vectors and matrices work where umbra takes
/// plain arrays (camera, light), and give the same stencil as the arrays.
#[test]
fn mint_types_convert_at_the_boundary() {
    let eye = mint::Point3 { x: 0.0, y: 5.0, z: 8.0 };
    let target = mint::Point3 { x: 0.0, y: 0.5, z: 0.0 };
    let camera = umbra_gl::Camera::look_at(eye, target).with_up(mint::Vector3 { x: 0.0, y: 1.0, z: 0.0 });
    let arrays = umbra_gl::Camera::look_at([0.0, 5.0, 8.0], [0.0, 0.5, 0.0]);
    assert_eq!(camera, arrays);
    let clip: mint::ColumnMatrix4<f64> =
        camera.clip_from_world_cols(W as f64 / H as f64, DepthConvention::Standard).into();
    let cols = to_f32_cols(&camera.clip_from_world_in(W as f64 / H as f64, DepthConvention::Standard));
    assert_eq!(
        [clip.x.x as f32, clip.y.x as f32, clip.w.z as f32, clip.w.w as f32],
        [cols[0], cols[4], cols[14], cols[15]]
    );

    let ctx = context();
    let gl = ctx.gl();
    let scene = SceneGpu::upload(gl, sphere_over_ground()).expect("upload");
    let mut renderer = Renderer::new(gl).expect("renderer").with_error_log(ctx.error_log().cloned());
    let mut method = create_method("vs-silhouette").expect("method");
    let p = FrameParams { camera, ..view(POINT, DepthConvention::Standard) };
    let host = Host::new(gl, &scene, DepthConvention::Standard);
    let target = FrameTarget { framebuffer: Some(host.fbo) };
    let mut stencils = Vec::new();
    let mint_light = mint::Vector4 { x: POINT[0], y: POINT[1], z: POINT[2], w: POINT[3] };
    for light in [mint_light, POINT.into()] {
        host.draw_scene(&ctx, &p);
        renderer.count_shadows(gl, &scene, method.as_mut(), &p, light, target).expect("count_shadows");
        host.plain_state(&ctx);
        stencils.push(read_stencil(gl, Some(host.fbo), W, H));
    }
    assert_eq!(stencils[0], stencils[1], "mint light and array light count the same");
    assert!(stencils[0].pixels.iter().any(|&s| s != 0), "the sphere casts a shadow");
    assert!(ctx.take_gl_errors().is_empty());
    host.destroy(gl);
    method.destroy(gl);
    renderer.destroy(gl);
    scene.destroy(gl);
}
