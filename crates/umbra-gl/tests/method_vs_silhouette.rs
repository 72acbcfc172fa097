//! vs-silhouette (paper 003): what the torture suite cannot see.
//! * the buffers actually uploaded have exactly the sizes of Eq. 8 and Eq. 9;
//! * edge splitting (records with opposite signs over one edge) gives the same stencil as
//!   cpu-silhouette, for every split size down to one opposite per record;
//! * the shaders are GLSL ES 3.00 as well: compiled, linked and drawn on an OpenGL ES 3
//!   context with a minimal ES draw path, the stencil equals the GL 4.5 one.

mod common;

use std::sync::Arc;

use common::*;
use umbra_geom::scene::book;
use umbra_geom::sides_data::{caps_data_bytes, record_count, sides_data_bytes, MAX_MULT_LIMIT};
use umbra_geom::{weld::weld, EdgeAdjacency, WeldedMesh};
use umbra_gl::glow::{self, HasContext};
use umbra_gl::methods::vs_silhouette::{
    caps_vertex_source, fragment_source, plan_layout, records_per_instance, sides_vertex_source, ShaderDialect,
    VolumeDraw, VsSilhouette,
};
use umbra_gl::program::{link_program, ShaderSource};
use umbra_gl::{
    Camera, DepthConvention, FrameParams, GlState, HeadlessContext, Renderer, RgbaImage, SceneGpu, ShadowMethod,
    StencilImage,
};

/// Sphere over ground plus a 40-page book and a 3-fin edge, on the ground.
fn torture_mesh() -> Arc<WeldedMesh> {
    let mut m = umbra_geom::scene::uv_sphere([0.0, 2.0, 0.0], 1.0, 48, 24);
    let mut b = book(40);
    for p in &mut b.positions {
        p[0] += 3.0;
    }
    m.append(&b);
    // Three fins on one edge.
    let base = m.positions.len() as u32;
    m.positions.extend_from_slice(&[
        [-3.0, 0.5, 0.0],
        [-3.0, 0.5, 1.0],
        [-2.0, 1.5, 0.5],
        [-4.0, 1.5, 0.5],
        [-3.0, 2.0, 0.5],
    ]);
    m.triangles.extend_from_slice(&[
        [base, base + 1, base + 2],
        [base + 1, base, base + 3],
        [base, base + 1, base + 4],
    ]);
    m.append(&umbra_geom::scene::ground_plane([0.0, 0.0, 0.0], 10.0));
    Arc::new(weld(&m))
}

fn stencil_with(
    ctx: &HeadlessContext,
    mesh: &Arc<WeldedMesh>,
    method: &mut dyn ShadowMethod,
    p: &FrameParams,
) -> StencilImage {
    let gl = ctx.gl();
    let scene = SceneGpu::upload(gl, mesh.clone()).expect("upload");
    let mut r = Renderer::new(gl).expect("renderer").with_error_log(ctx.error_log().cloned());
    let s = r.render_stencil(gl, &scene, method, p, 0).unwrap_or_else(|e| panic!("render with {}: {e}", method.name()));
    method.destroy(gl);
    r.destroy(gl);
    scene.destroy(gl);
    s
}

fn grey(s: &StencilImage) -> RgbaImage {
    let mut img = RgbaImage::new(s.width, s.height, [0, 0, 0, 255]);
    for (d, &v) in img.pixels.iter_mut().zip(&s.pixels) {
        let g = v.saturating_mul(60);
        *d = [g, g, g, 255];
    }
    img
}

/// Equal stencils, or the actual/difference images and a panic.
fn assert_same_stencil(ctx: &HeadlessContext, test: &str, expected: &StencilImage, actual: &StencilImage) {
    assert_eq!((expected.width, expected.height), (actual.width, actual.height), "{test}: sizes");
    let differing = expected.pixels.iter().zip(&actual.pixels).filter(|(a, b)| a != b).count();
    if differing > 0 {
        let mut diff = grey(expected);
        for (d, (a, b)) in diff.pixels.iter_mut().zip(expected.pixels.iter().zip(&actual.pixels)) {
            if a != b {
                *d = [255, 0, 0, 255];
            }
        }
        let note = write_failure_images(ctx, test, &grey(actual), &diff);
        panic!("{test}: {differing} stencil values differ on {}; {note}", ctx.renderer_string());
    }
}

fn views() -> Vec<(Camera, [f32; 4])> {
    vec![
        (default_camera(), POINT_LIGHT),
        (default_camera(), [1.5, 5.0, 0.7, 1.0]),
        (default_camera(), [-0.4, 1.0, 0.3, 0.0]),
        (Camera { eye: [6.0, 3.0, -5.0], ..default_camera() }, [3.2, 4.0, 0.4, 1.0]),
    ]
}

#[test]
fn uploaded_buffers_have_exactly_the_eq8_and_eq9_sizes() {
    let ctx = context();
    let gl = ctx.gl();
    // SAFETY: plain query on the current context.
    let attribs = unsafe { gl.get_parameter_i32(glow::MAX_VERTEX_ATTRIBS) } as usize;
    for (mesh, cap) in
        [(sphere_over_ground(), None), (torture_mesh(), None), (torture_mesh(), Some(3)), (torture_mesh(), Some(1))]
    {
        let adj = EdgeAdjacency::build(&mesh);
        let mut m = cap.map_or_else(VsSilhouette::new, VsSilhouette::with_max_mult_cap);
        m.prepare_mesh(gl, ShaderDialect::Glsl450, &mesh, &adj).expect("prepare");
        let l = m.layout().expect("prepared");
        let (sides, caps) = m.uploaded_buffer_bytes(gl).expect("prepared");
        assert!(l.max_mult >= 1 && l.max_mult <= cap.unwrap_or(MAX_MULT_LIMIT));
        assert_eq!(l.records, record_count(&adj, l.max_mult));
        assert_eq!(sides, sides_data_bytes(l.records, l.max_mult), "Eq. 8: 16 (2 + maxMult) e");
        assert_eq!(sides, 16 * (2 + l.max_mult) * l.records);
        assert_eq!(caps, caps_data_bytes(mesh.triangles.len()), "Eq. 9: 48 t");
        assert_eq!(caps, 48 * mesh.triangles.len());
        assert_eq!(m.gpu_bytes(), sides + caps);
        if cap.is_none() {
            // Without a forced cap the layout is the one `umbra info` can plan without GL.
            assert_eq!(plan_layout(&adj, mesh.triangles.len(), attribs, MAX_MULT_LIMIT), l);
        }
        if adj.max_opposites() > l.max_mult {
            assert!(l.records > l.edges, "edges with more than maxMult opposites are split");
        }
        m.destroy(gl);
        assert_eq!(m.gpu_bytes(), 0);
    }
    assert_eq!(ctx.take_gl_errors(), Vec::<String>::new());
}

/// Pixels whose lit / shadowed classification (stencil zero or not) differs between
/// `expected` and `actual`, and how many of them are NOT on the shadow boundary of `expected`
/// (a pixel is on the boundary when a pixel of its 3x3 neighbourhood is classified the other
/// way): the one-pixel band the torture suite also excludes.
fn classification_differences(expected: &StencilImage, actual: &StencilImage) -> (usize, usize) {
    let (w, h) = (expected.width as i64, expected.height as i64);
    let lit = |x: i64, y: i64| expected.pixels[(y * w + x) as usize] == 0;
    let (mut all, mut off_boundary) = (0, 0);
    for y in 0..h {
        for x in 0..w {
            let i = (y * w + x) as usize;
            if (expected.pixels[i] == 0) == (actual.pixels[i] == 0) {
                continue;
            }
            all += 1;
            let on_boundary = (-1..=1)
                .flat_map(|dy| (-1..=1).map(move |dx| (x + dx, y + dy)))
                .any(|(nx, ny)| nx >= 0 && ny >= 0 && nx < w && ny < h && lit(nx, ny) != lit(x, y));
            if !on_boundary {
                off_boundary += 1;
            }
        }
    }
    (all, off_boundary)
}

/// z-fail and z-pass, point and directional lights, several views: with the default maxMult
/// (here only the 40-page spine is split) the stencil equals cpu-silhouette's value for
/// value, with 1 to 8 records per instance. A forced small maxMult splits every edge with more
/// opposites into records of both signs whose quads must cancel: the lit / shadowed
/// classification must stay the same everywhere off the one-pixel shadow boundary; a count
/// inside a shadow may differ by a cancelling pair that did not cancel at a sample where the
/// side grazes a surface (the clipper cuts the reversed triangles at w = 0 with different
/// rounding), which changes nothing visible.
#[test]
fn split_records_give_the_cpu_silhouette_stencil() {
    let ctx = context();
    let mesh = torture_mesh();
    let adj = EdgeAdjacency::build(&mesh);
    assert_eq!(adj.max_opposites(), 40);
    let mut report = Vec::new();
    for (v, (camera, light)) in views().into_iter().enumerate() {
        for zpass in [false, true] {
            let mut p = params(camera, vec![light], 256, 192);
            p.zpass = zpass;
            // z-fail when asked for, not auto z-pass (auto_zpass.rs tests the choice).
            p.auto_zpass = false;
            let expected =
                stencil_with(&ctx, &mesh, umbra_gl::create_method("cpu-silhouette").expect("registered").as_mut(), &p);
            assert!(expected.pixels.iter().any(|&v| v != 0), "the view shows shadow");
            // (maxMult cap, records-per-instance cap): the default, the paper's one record per
            // instance, 3 per instance (remainder instances with disabled attribute sets), and
            // forced splits.
            let configs = [
                (None, None),
                (None, Some(1)),
                (None, Some(3)),
                (Some(1), None),
                (Some(2), Some(3)),
                (Some(3), Some(2)),
            ];
            for (cap, per_instance) in configs {
                let mut m = cap.map_or_else(VsSilhouette::new, VsSilhouette::with_max_mult_cap);
                if let Some(n) = per_instance {
                    m = m.with_records_per_instance_cap(n);
                }
                let actual = stencil_with(&ctx, &mesh, &mut m, &p);
                let zmode = if zpass { "zpass" } else { "zfail" };
                let test = format!("vs_split_view{v}_cap{}_per{}_{zmode}", cap.unwrap_or(0), per_instance.unwrap_or(0));
                let (all, off_boundary) = classification_differences(&expected, &actual);
                let values = expected.pixels.iter().zip(&actual.pixels).filter(|(a, b)| a != b).count();
                report.push(format!(
                    "{test}: {values} values differ, {all} lit/shadowed ({off_boundary} off the boundary)"
                ));
                if (cap.is_none() && values > 0) || off_boundary > 0 {
                    assert_same_stencil(&ctx, &test, &expected, &actual);
                }
            }
        }
    }
    println!("{}", report.join("\n"));
}

// ---- OpenGL ES 3 ----

const ES_SCENE_VERT: &str = "#version 300 es
// Minimal ES depth pass: the same expression as umbra-gl's scene.vert.glsl, so the depths
// equal the GL 4.5 renderer's.
layout(location = 0) in vec3 a_world_pos;
uniform mat4 u_clip_from_world;
invariant gl_Position;
void main() {
    gl_Position = u_clip_from_world * vec4(a_world_pos, 1.0);
}
";
const ES_FULLSCREEN_VERT: &str = "#version 300 es
// One triangle covering the viewport.
void main() {
    vec2 p = vec2(float((gl_VertexID & 1) * 4 - 1), float((gl_VertexID & 2) * 2 - 1));
    gl_Position = vec4(p, 0.0, 1.0);
}
";
const ES_VALUE_FRAG: &str = "#version 300 es
precision highp float;
uniform float u_value;
out vec4 o_color;
void main() {
    o_color = vec4(u_value, 0.0, 0.0, 1.0);
}
";

struct EsTarget {
    fbo: glow::Framebuffer,
    color: glow::Renderbuffer,
    depth_stencil: glow::Renderbuffer,
}

/// An ES 3.0 framebuffer with RGBA8 colour and DEPTH24_STENCIL8.
fn es_target(gl: &glow::Context, w: i32, h: i32) -> EsTarget {
    // SAFETY: ES 3.0 object creation on the current ES context.
    unsafe {
        let fbo = gl.create_framebuffer().expect("fbo");
        let color = gl.create_renderbuffer().expect("colour rb");
        let depth_stencil = gl.create_renderbuffer().expect("depth-stencil rb");
        gl.bind_renderbuffer(glow::RENDERBUFFER, Some(color));
        gl.renderbuffer_storage(glow::RENDERBUFFER, glow::RGBA8, w, h);
        gl.bind_renderbuffer(glow::RENDERBUFFER, Some(depth_stencil));
        gl.renderbuffer_storage(glow::RENDERBUFFER, glow::DEPTH24_STENCIL8, w, h);
        gl.bind_framebuffer(glow::FRAMEBUFFER, Some(fbo));
        gl.framebuffer_renderbuffer(glow::FRAMEBUFFER, glow::COLOR_ATTACHMENT0, glow::RENDERBUFFER, Some(color));
        gl.framebuffer_renderbuffer(
            glow::FRAMEBUFFER,
            glow::DEPTH_STENCIL_ATTACHMENT,
            glow::RENDERBUFFER,
            Some(depth_stencil),
        );
        assert_eq!(gl.check_framebuffer_status(glow::FRAMEBUFFER), glow::FRAMEBUFFER_COMPLETE);
        gl.viewport(0, 0, w, h);
        EsTarget { fbo, color, depth_stencil }
    }
}

fn es_program(gl: &glow::Context, name: &str, vert: &str, frag: &str) -> glow::Program {
    link_program(gl, name, &[ShaderSource::vertex(name, vert), ShaderSource::fragment(name, frag)], &[])
        .unwrap_or_else(|e| panic!("ES program {name}: {e}"))
}

/// The ES stencil mask of vs-silhouette for one light (z-fail), top row first.
fn es_stencil(ctx: &HeadlessContext, mesh: &WeldedMesh, p: &FrameParams) -> StencilImage {
    let gl = ctx.gl();
    let (w, h) = (p.width as i32, p.height as i32);
    let target = es_target(gl, w, h);
    let clip = umbra_gl::camera::to_f32_cols(&p.camera.clip_from_world(p.width as f64 / p.height as f64));
    let depth_clamp = gl.supported_extensions().contains("GL_EXT_depth_clamp");

    // Pass 1: depth (and a stencil of 0).
    let scene_prog = es_program(
        gl,
        "es scene",
        ES_SCENE_VERT,
        "#version 300 es\nprecision highp float;\nout vec4 o;\nvoid main() { o = vec4(0.0); }\n",
    );
    // SAFETY: as above; buffers sized from the mesh.
    unsafe {
        let vao = gl.create_vertex_array().expect("vao");
        gl.bind_vertex_array(Some(vao));
        let vbo = gl.create_buffer().expect("vbo");
        gl.bind_buffer(glow::ARRAY_BUFFER, Some(vbo));
        let pos: Vec<u8> = mesh.positions.iter().flatten().flat_map(|v| v.to_le_bytes()).collect();
        gl.buffer_data_u8_slice(glow::ARRAY_BUFFER, &pos, glow::STATIC_DRAW);
        gl.vertex_attrib_pointer_f32(0, 3, glow::FLOAT, false, 12, 0);
        gl.enable_vertex_attrib_array(0);
        let ibo = gl.create_buffer().expect("ibo");
        gl.bind_buffer(glow::ELEMENT_ARRAY_BUFFER, Some(ibo));
        let idx: Vec<u8> = mesh.triangles.iter().flatten().flat_map(|v| v.to_le_bytes()).collect();
        gl.buffer_data_u8_slice(glow::ELEMENT_ARRAY_BUFFER, &idx, glow::STATIC_DRAW);
        GlState { depth_test: true, depth_func: glow::LESS, color_write: [false; 4], ..GlState::default() }.apply(gl);
        if !depth_clamp {
            // GlState::apply sets DEPTH_CLAMP, which plain ES 3.0 does not know: drop that error.
            while gl.get_error() != glow::NO_ERROR {}
        }
        gl.clear_color(0.0, 0.0, 0.0, 0.0);
        gl.clear_depth_f32(1.0);
        gl.clear_stencil(0);
        gl.clear(glow::COLOR_BUFFER_BIT | glow::DEPTH_BUFFER_BIT | glow::STENCIL_BUFFER_BIT);
        gl.use_program(Some(scene_prog));
        gl.uniform_matrix_4_f32_slice(gl.get_uniform_location(scene_prog, "u_clip_from_world").as_ref(), false, &clip);
        gl.draw_elements(glow::TRIANGLES, (mesh.triangles.len() * 3) as i32, glow::UNSIGNED_INT, 0);
        gl.bind_vertex_array(None);
        gl.delete_vertex_array(vao);
        gl.delete_buffer(vbo);
        gl.delete_buffer(ibo);
        gl.delete_program(scene_prog);
    }

    // Pass 2: the method's own ES draw path (its programs in ESSL 3.00).
    let adj = EdgeAdjacency::build(mesh);
    let mut m = VsSilhouette::new();
    m.prepare_mesh(gl, ShaderDialect::Essl300, mesh, &adj).expect("vs-silhouette prepares on ES 3");
    let mut state = GlState::shadow_volume(false);
    state.depth_clamp = depth_clamp;
    let d = VolumeDraw {
        clip_from_world: clip,
        light: p.lights[0],
        zpass: false,
        viewport_size: [p.width, p.height],
        depth_convention: DepthConvention::Standard,
        state,
    };
    let mut stages = Vec::new();
    m.draw_volume(gl, &d, &mut |_, s| stages.push(s)).expect("ES draw");
    assert_eq!(stages, ["sides", "caps"]);
    // SAFETY: as above.
    unsafe {
        if !depth_clamp {
            while gl.get_error() != glow::NO_ERROR {}
        }
        assert_eq!(gl.get_error(), glow::NO_ERROR, "ES draw of vs-silhouette");
    }
    m.destroy(gl);

    // Stencil -> colour: ES 3.0 cannot glReadPixels the stencil. Bit b of the stencil adds
    // 2^b / 255 (exact in unorm8) where (stencil & 2^b) != 0: red = the stencil value.
    let conv = es_program(gl, "es stencil to colour", ES_FULLSCREEN_VERT, ES_VALUE_FRAG);
    // SAFETY: as above; the read buffer is w * h RGBA8.
    let pixels = unsafe {
        gl.use_program(Some(conv));
        let u = gl.get_uniform_location(conv, "u_value");
        let vao = gl.create_vertex_array().expect("vao");
        gl.bind_vertex_array(Some(vao));
        for bit in 0..8 {
            let face = umbra_gl::StencilFace {
                func: glow::EQUAL,
                reference: 1 << bit,
                value_mask: 1 << bit,
                write_mask: 0,
                stencil_fail: glow::KEEP,
                depth_fail: glow::KEEP,
                depth_pass: glow::KEEP,
            };
            GlState {
                stencil_test: true,
                stencil_front: face,
                stencil_back: face,
                depth_write: false,
                blend: Some(umbra_gl::BlendState::ADDITIVE),
                ..GlState::default()
            }
            .apply(gl);
            gl.uniform_1_f32(u.as_ref(), (1u32 << bit) as f32 / 255.0);
            gl.draw_arrays(glow::TRIANGLES, 0, 3);
        }
        while !depth_clamp && gl.get_error() != glow::NO_ERROR {}
        let mut buf = vec![0u8; (w * h * 4) as usize];
        gl.read_pixels(0, 0, w, h, glow::RGBA, glow::UNSIGNED_BYTE, glow::PixelPackData::Slice(Some(&mut buf)));
        assert_eq!(gl.get_error(), glow::NO_ERROR, "ES stencil readback");
        gl.bind_vertex_array(None);
        gl.delete_vertex_array(vao);
        gl.delete_program(conv);
        gl.bind_framebuffer(glow::FRAMEBUFFER, None);
        gl.delete_framebuffer(target.fbo);
        gl.delete_renderbuffer(target.color);
        gl.delete_renderbuffer(target.depth_stencil);
        buf
    };
    let bottom_up: Vec<u8> = pixels.chunks_exact(4).map(|p| p[0]).collect();
    StencilImage::from_bottom_up(p.width, p.height, bottom_up)
}

#[test]
fn shaders_compile_as_glsl_es_300_for_every_max_mult() {
    let ctx = HeadlessContext::new_gles3().unwrap_or_else(|e| panic!("no OpenGL ES 3 context: {e}"));
    assert!(ctx.version_string().contains("OpenGL ES"), "{}", ctx.version_string());
    let gl = ctx.gl();
    // Every maxMult with every number of records per instance that fits the 16 vertex
    // attributes ES 3.0 / WebGL 2 guarantee.
    let frag = fragment_source(ShaderDialect::Essl300);
    for max_mult in 1..=MAX_MULT_LIMIT {
        for records in 1..=records_per_instance(2 + max_mult, 16) {
            let src = sides_vertex_source(ShaderDialect::Essl300, max_mult, records);
            let p = es_program(gl, "vs-silhouette sides (ES)", &src, &frag);
            // SAFETY: our program on the current ES context.
            unsafe { gl.delete_program(p) };
        }
    }
    for records in 1..=records_per_instance(3, 16) {
        let p = es_program(gl, "vs-silhouette caps (ES)", &caps_vertex_source(ShaderDialect::Essl300, records), &frag);
        // SAFETY: as above.
        unsafe { gl.delete_program(p) };
    }
    assert_eq!(records_per_instance(4, 16), 4);
    assert_eq!(records_per_instance(16, 16), 1);
    assert_eq!(records_per_instance(3, 16), 5);
}

/// The vs-silhouette shaders in ESSL 3.00, drawn by the method's own (ES 3.0-only) GL code on
/// an OpenGL ES 3 context, mark the same stencil as the GL 4.5 renderer with vs-silhouette
/// and with cpu-silhouette: sphere over a plane, point and directional light.
#[test]
fn es3_stencil_equals_the_gl45_stencil() {
    let mesh = sphere_over_ground();
    for light in [POINT_LIGHT, [-0.4, 1.0, 0.3, 0.0]] {
        let p = params(default_camera(), vec![light], 320, 240);
        let gl45 = {
            let ctx = context();
            let gl45 = stencil_with(&ctx, &mesh, &mut VsSilhouette::new(), &p);
            let cpu =
                stencil_with(&ctx, &mesh, umbra_gl::create_method("cpu-silhouette").expect("registered").as_mut(), &p);
            assert_same_stencil(&ctx, "vs_gl45_vs_cpu", &cpu, &gl45);
            gl45
        };
        let shadowed = gl45.pixels.iter().filter(|&&v| v != 0).count();
        assert!(shadowed > 500, "the view shows the sphere's shadow ({shadowed} pixels)");
        let es = HeadlessContext::new_gles3().unwrap_or_else(|e| panic!("no OpenGL ES 3 context: {e}"));
        let es_mask = es_stencil(&es, &mesh, &p);
        // GLSL ES 3.00 has no `precise`: the compiler may contract or reorder the arithmetic
        // of the multiplicity test and the transforms differently from the GL 4.5 build, so a
        // sample on the shadow boundary may go either way (on llvmpipe: one pixel of the
        // point light's boundary); off the one-pixel boundary the classification must be the
        // GL 4.5 one, and boundary differences stay rare (< 0.5 % of the shadowed pixels).
        let (all, off_boundary) = classification_differences(&gl45, &es_mask);
        println!("ES 3 vs GL 4.5, light {light:?}: {all} boundary pixels differ, {off_boundary} off the boundary");
        if off_boundary > 0 || all * 200 > shadowed {
            assert_same_stencil(&es, "vs_es3_vs_gl45", &gl45, &es_mask);
        }
    }
}

// ---- Timing (ignored by default: run with --ignored --nocapture; asserts nothing timed) ----

/// User + system CPU time of this process (all threads, llvmpipe's included), from
/// /proc/self/stat (clock ticks of 10 ms); 0 where unavailable.
fn process_cpu_ms() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    // Fields after the parenthesised command name; utime and stime are fields 14 and 15.
    let rest = stat.rsplit_once(')').map_or("", |(_, r)| r);
    let f: Vec<f64> = rest.split_whitespace().map(|x| x.parse().unwrap_or(0.0)).collect();
    if f.len() > 13 {
        (f[11] + f[12]) * 10.0
    } else {
        0.0
    }
}

/// Crytek Sponza at 1280x720, pose 0 of the torture suite: whole-frame wall time (glFinish)
/// of cpu-silhouette, vs-silhouette and cs-silhouette after warm-up (llvmpipe compiles a
/// shader on its first draw), median of 7 frames; then one synchronous frame per method for
/// the per-stage split.
#[test]
#[ignore]
fn sponza_frame_ms() {
    let dir = std::env::var_os("UMBRA_SCENES")
        .map(std::path::PathBuf::from)
        .unwrap_or_else(|| std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/scenes"));
    let path = dir.join("crytek-sponza.obj.gz");
    if !path.is_file() {
        println!("SKIPPED: {} not found (set UMBRA_SCENES)", path.display());
        return;
    }
    let mesh = umbra_geom::load::load_path(&path).unwrap_or_else(|e| panic!("{e}"));
    let b = mesh.bounds().expect("non-empty");
    let at = |f: [f64; 3]| [0, 1, 2].map(|k| b.min[k] as f64 + f[k] * (b.max[k] - b.min[k]) as f64);
    let mesh = Arc::new(weld(&mesh));
    let ctx = HeadlessContext::with_options(umbra_gl::ContextOptions { api: umbra_gl::GlApi::Gl45Core, debug: false })
        .unwrap_or_else(|e| panic!("{e}"));
    let gl = ctx.gl();
    let light = at([0.61, 0.7, 0.57]);
    let camera = Camera {
        eye: at([0.3, 0.45, 0.5]),
        target: at([0.7, 0.3, 0.5]),
        near: 1e-3 * b.diagonal() as f64,
        ..default_camera()
    };
    let scene = SceneGpu::upload(gl, mesh.clone()).expect("upload");
    // 1280x720 as asked; 128x72 shows the per-method work without the shared fill cost.
    for (width, height) in [(1280, 720), (128, 72)] {
        let p = FrameParams {
            camera,
            width,
            height,
            lights: vec![[light[0] as f32, light[1] as f32, light[2] as f32, 1.0]],
            ..FrameParams::default()
        };
        let target =
            umbra_gl::RenderTarget::new(gl, p.width, p.height, umbra_gl::Attachments::default()).expect("target");
        let mut r = Renderer::new(gl).expect("renderer");
        println!(
            "Crytek Sponza {} triangles, {}x{}, {}",
            mesh.triangles.len(),
            p.width,
            p.height,
            ctx.renderer_string()
        );
        for name in ["none", "cpu-silhouette", "vs-silhouette", "cs-silhouette"] {
            let mut m = umbra_gl::create_method(name).expect("registered");
            let fb = umbra_gl::FrameTarget { framebuffer: Some(target.framebuffer()) };
            let t0 = std::time::Instant::now();
            r.draw_frame(gl, &scene, m.as_mut(), &p, fb, None).expect("frame");
            // SAFETY: glFinish on the current context.
            unsafe { gl.finish() };
            let first = t0.elapsed().as_secs_f64() * 1e3;
            let mut times = Vec::new();
            let mut cpu_ms = 0.0;
            for i in 0..9 {
                let (t, c) = (std::time::Instant::now(), process_cpu_ms());
                r.draw_frame(
                    gl,
                    &scene,
                    m.as_mut(),
                    &p,
                    umbra_gl::FrameTarget { framebuffer: Some(target.framebuffer()) },
                    None,
                )
                .expect("frame");
                // SAFETY: as above.
                unsafe { gl.finish() };
                if i >= 2 {
                    times.push(t.elapsed().as_secs_f64() * 1e3);
                    cpu_ms += process_cpu_ms() - c;
                }
            }
            let cpu_ms = cpu_ms / 7.0;
            times.sort_by(f64::total_cmp);
            let mut hook = umbra_gl::TimestampHook::synchronous();
            r.draw_frame(
                gl,
                &scene,
                m.as_mut(),
                &p,
                umbra_gl::FrameTarget { framebuffer: Some(target.framebuffer()) },
                Some(&mut hook),
            )
            .expect("frame");
            let stages: Vec<String> = hook
                .finish(gl)
                .iter()
                .map(|s| {
                    format!(
                        "{}:{} {:.1}/{:.1}",
                        s.mark.source,
                        s.mark.label,
                        s.gpu_ns as f64 / 1e6,
                        s.cpu_ns as f64 / 1e6
                    )
                })
                .collect();
            hook.destroy(gl);
            println!(
            "{name:16} first {first:8.1} ms, warm median {:7.1} ms (min {:.1}), process CPU {cpu_ms:.1} ms/frame, gpu_bytes {}; stages (gpu/wall ms): {}",
            times[times.len() / 2],
            times[0],
            m.gpu_bytes(),
            stages.join(", ")
        );
            m.destroy(gl);
        }
        r.destroy(gl);
        target.destroy(gl);
    }
    let l = plan_layout(&EdgeAdjacency::build(&mesh), mesh.triangles.len(), 16, MAX_MULT_LIMIT);
    println!("vs-silhouette layout: {l:?}; max opposites {}", EdgeAdjacency::build(&mesh).max_opposites());
    scene.destroy(gl);
}
