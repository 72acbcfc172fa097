//! GL unit tests of the tessellation stages: Alg. 5 observed through transform feedback.

use glow::HasContext;
use umbra_geom::weld::weld;
use umbra_geom::{EdgeAdjacency, Light, Mesh};

use super::patches::EdgePatches;
use super::*;
use crate::context::{ContextOptions, GlApi, HeadlessContext};

pub(crate) fn context() -> HeadlessContext {
    HeadlessContext::with_options(ContextOptions { api: GlApi::Gl45Core, debug: true })
        .unwrap_or_else(|e| panic!("no headless GL 4.5 context: {e}"))
}

/// Links `stages` with transform feedback of `gl_Position`, runs `draw` with the rasterizer
/// off and returns the captured triangles (clip space).
pub(crate) fn capture_triangles(
    gl: &glow::Context,
    stages: &[(u32, String)],
    defines: &[&str],
    draw: impl FnOnce(glow::Program),
) -> Vec<[[f32; 4]; 3]> {
    const CAPACITY_TRIANGLES: usize = 1 << 14;
    // A complete framebuffer must be bound for any draw, rasterizer discard or not (the
    // surfaceless default framebuffer is incomplete).
    let target = crate::target::RenderTarget::new(gl, 4, 4, Default::default()).unwrap();
    // SAFETY: test-only GL object creation, capture and readback on the current context.
    let triangles = unsafe {
        gl.bind_framebuffer(glow::FRAMEBUFFER, Some(target.framebuffer()));
        let program = gl.create_program().unwrap();
        let mut shaders = Vec::new();
        for (stage, source) in stages {
            let sh = gl.create_shader(*stage).unwrap();
            let extra: String = defines.iter().map(|d| format!("#define {d}\n")).collect();
            let source = source.replacen("#version 450 core\n", &format!("#version 450 core\n{extra}"), 1);
            gl.shader_source(sh, &source);
            gl.compile_shader(sh);
            assert!(gl.get_shader_compile_status(sh), "{}", gl.get_shader_info_log(sh));
            gl.attach_shader(program, sh);
            shaders.push(sh);
        }
        gl.transform_feedback_varyings(program, &["gl_Position"], glow::INTERLEAVED_ATTRIBS);
        gl.link_program(program);
        assert!(gl.get_program_link_status(program), "{}", gl.get_program_info_log(program));
        let buffer = gl.create_named_buffer().unwrap();
        let bytes = CAPACITY_TRIANGLES * 3 * 16;
        gl.named_buffer_data_size(buffer, bytes as i32, glow::STREAM_READ);
        gl.bind_buffer_base(glow::TRANSFORM_FEEDBACK_BUFFER, 0, Some(buffer));
        let generated = gl.create_query().unwrap();
        let written = gl.create_query().unwrap();
        gl.enable(glow::RASTERIZER_DISCARD);
        gl.use_program(Some(program));
        gl.begin_query(glow::PRIMITIVES_GENERATED, generated);
        gl.begin_query(glow::TRANSFORM_FEEDBACK_PRIMITIVES_WRITTEN, written);
        gl.begin_transform_feedback(glow::TRIANGLES);
        draw(program);
        gl.end_transform_feedback();
        gl.end_query(glow::TRANSFORM_FEEDBACK_PRIMITIVES_WRITTEN);
        gl.end_query(glow::PRIMITIVES_GENERATED);
        gl.disable(glow::RASTERIZER_DISCARD);
        let n_generated = gl.get_query_parameter_u32(generated, glow::QUERY_RESULT) as usize;
        let n = gl.get_query_parameter_u32(written, glow::QUERY_RESULT) as usize;
        assert_eq!(n, n_generated, "transform feedback buffer too small");
        let mut out = vec![0u8; n * 3 * 16];
        gl.bind_buffer(glow::TRANSFORM_FEEDBACK_BUFFER, Some(buffer));
        gl.get_buffer_sub_data(glow::TRANSFORM_FEEDBACK_BUFFER, 0, &mut out);
        gl.bind_buffer_base(glow::TRANSFORM_FEEDBACK_BUFFER, 0, None);
        gl.delete_buffer(buffer);
        gl.delete_query(generated);
        gl.delete_query(written);
        for sh in shaders {
            gl.delete_shader(sh);
        }
        gl.delete_program(program);
        let floats: Vec<f32> = out.chunks_exact(4).map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect();
        floats
            .chunks_exact(12)
            .map(|t| [0, 1, 2].map(|v| [t[4 * v], t[4 * v + 1], t[4 * v + 2], t[4 * v + 3]]))
            .collect()
    };
    // SAFETY: unbinding and deleting the test framebuffer.
    unsafe { gl.bind_framebuffer(glow::FRAMEBUFFER, None) };
    target.destroy(gl);
    triangles
}

/// The edge (0,0,0) -> (1,0,0) with `up` opposite vertices below it at z < 0 (triangles
/// A -> B -> O facing +y: +1 each for a light above) and `down` at z > 0 (-1 each).
pub(crate) fn fan(up: usize, down: usize) -> Mesh {
    let mut m = Mesh { positions: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]], ..Default::default() };
    for i in 0..up + down {
        let z = if i < up { -1.0 - 0.1 * i as f32 } else { 1.0 + 0.1 * i as f32 };
        m.positions.push([0.5 + 0.01 * i as f32, 0.0, z]);
        m.triangles.push([0, 1, 2 + i as u32]);
    }
    m
}

pub(crate) const ABOVE: Light = [0.5, 5.0, 0.25, 1.0];

pub(crate) const IDENTITY: [f32; 16] = [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0];

/// Checks that `triangles` cover the side quad of edge A = (0,0,0) -> B = (1,0,0) (identity
/// clip transform) with signed multiplicity `m`, in the winding of umbra_geom::silhouette
/// (B A A_inf B_inf for m > 0, reversed for m < 0): every vertex is one of the four corners,
/// degenerate triangles aside every triangle lies in the quad, and counted with its winding
/// (+1 as the m > 0 quad, -1 reversed) the triangles pair up into exactly m whole quads. With
/// `single_sign`, no triangle may be wound against sgn(m) and there are exactly 2|m| of them
/// (one patch: no cancelling pairs).
pub(crate) fn assert_side_quads(triangles: &[[[f32; 4]; 3]], m: i32, light: Light, single_sign: bool, what: &str) {
    let (a, b) = ([0.0f32, 0.0, 0.0], [1.0f32, 0.0, 0.0]);
    let ext = |p: [f32; 3]| umbra_geom::silhouette::extrude(p, light);
    let point = |p: [f32; 3]| [p[0], p[1], p[2], 1.0];
    // The m > 0 quad, CCW from outside (umbra_geom::silhouette).
    let quad: [[f32; 4]; 4] = [point(b), point(a), ext(a), ext(b)];
    // Exact equality (0.0 == -0.0: the identity transform may turn one into the other).
    let corner = |v: [f32; 4]| {
        quad.iter().position(|q| *q == v).unwrap_or_else(|| panic!("{what}: vertex {v:?} is no corner of {quad:?}"))
    };
    let mut net = std::collections::HashMap::<[usize; 3], i32>::new();
    let (mut positive, mut negative) = (0, 0);
    for t in triangles {
        let c = t.map(corner);
        if c[0] == c[1] || c[1] == c[2] || c[0] == c[2] {
            continue; // zero area: never rasterized
        }
        // Rotate so the smallest corner comes first; wound as the quad iff the rest increase.
        let r = (0..3).min_by_key(|&i| c[i]).unwrap();
        let rot = [c[r], c[(r + 1) % 3], c[(r + 2) % 3]];
        let (key, sign) = if rot[1] < rot[2] { (rot, 1) } else { ([rot[0], rot[2], rot[1]], -1) };
        if sign > 0 {
            positive += 1;
        } else {
            negative += 1;
        }
        *net.entry(key).or_default() += sign;
    }
    let n = |t: [usize; 3]| net.get(&t).copied().unwrap_or(0);
    // Diagonal 0-2: {0,1,2} + {0,2,3}; diagonal 1-3: {0,1,3} + {1,2,3}.
    assert_eq!(n([0, 1, 2]), n([0, 2, 3]), "{what}: half quads {net:?}");
    assert_eq!(n([0, 1, 3]), n([1, 2, 3]), "{what}: half quads {net:?}");
    assert_eq!(n([0, 1, 2]) + n([0, 1, 3]), m, "{what}: net quads {net:?}");
    if single_sign {
        let (with, against) = if m >= 0 { (positive, negative) } else { (negative, positive) };
        assert_eq!(against, 0, "{what}: {against} triangles wound against the multiplicity");
        assert_eq!(with, 2 * m.unsigned_abs() as usize, "{what}: {with} triangles for |m| = {}", m.abs());
    }
}

/// Alg. 5 on this GL's tessellator: for every multiplicity 0..=29 of either sign, one patch
/// produces exactly |m| copies of the side quad with the right winding, and only degenerate
/// triangles besides.
#[test]
fn alg5_tessellation_gives_m_side_quads() {
    let ctx = context();
    let gl = ctx.gl();
    let stages = [
        (glow::VERTEX_SHADER, with_prelude(SIDES_VERT)),
        (glow::TESS_CONTROL_SHADER, with_prelude(SIDES_TESC)),
        (glow::TESS_EVALUATION_SHADER, with_prelude(SIDES_TESE)),
    ];
    let llvmpipe = ctx.renderer_string().contains("llvmpipe");
    let mut checked = 0;
    for (up, down) in (1..=29).map(|n| (n, 0)).chain((1..=29).map(|n| (0, n))).chain([(5, 3), (2, 7), (29, 0)]) {
        let w = weld(&fan(up, down));
        let adj = EdgeAdjacency::build(&w);
        let patches = EdgePatches::build(&w, &adj, 29).unwrap();
        let m = up as i32 - down as i32;
        let upload = upload(gl, &patches).unwrap();
        // Only the spine patch: the first edge in adjacency order is (0, 1).
        assert_eq!(patches.elements[..2], [0, 1]);
        let tris = capture_triangles(gl, &stages, &[], |program| unsafe {
            gl.uniform_matrix_4_f32_slice(
                gl.get_uniform_location(program, "u_clip_from_world").as_ref(),
                false,
                &IDENTITY,
            );
            gl.uniform_4_f32_slice(gl.get_uniform_location(program, "u_light").as_ref(), &ABOVE);
            gl.bind_vertex_array(Some(upload.vao));
            gl.patch_parameter_i32(glow::PATCH_VERTICES, upload.patch_vertices);
            gl.draw_elements(glow::PATCHES, upload.patch_vertices, glow::UNSIGNED_INT, 0);
        });
        assert_side_quads(&tris, m, ABOVE, true, &format!("up {up} down {down}"));
        checked += (m != 0) as usize;
        // The corner rotation of sides.tesc.glsl, tuned to llvmpipe's tessellator: for
        // |m| <= 2 every drawn triangle starts on the edge (w = 1), never at infinity.
        if llvmpipe && m.abs() <= 2 {
            for t in tris.iter().filter(|t| t[0] != t[1] && t[1] != t[2] && t[0] != t[2]) {
                assert_eq!(t[0][3], 1.0, "up {up} down {down}: triangle {t:?} starts at infinity");
            }
        }
        // SAFETY: test objects.
        unsafe {
            gl.delete_vertex_array(upload.vao);
            gl.delete_buffer(upload.vertices);
            gl.delete_buffer(upload.elements);
        }
    }
    assert!(checked >= 60);
    assert!(ctx.take_gl_errors().is_empty());
}

/// The 3-edge variant tessellates the same way (here every triangle is far from edge-on, so
/// the 3-edge test agrees with the reference edge).
#[test]
fn alg5_three_edge_variant_same_quads() {
    let ctx = context();
    let gl = ctx.gl();
    let stages = [
        (glow::VERTEX_SHADER, with_prelude(SIDES_VERT)),
        (glow::TESS_CONTROL_SHADER, with_prelude(SIDES_TESC)),
        (glow::TESS_EVALUATION_SHADER, with_prelude(SIDES_TESE)),
    ];
    for (up, down) in [(1, 0), (0, 3), (7, 2)] {
        let w = weld(&fan(up, down));
        let adj = EdgeAdjacency::build(&w);
        let patches = EdgePatches::build(&w, &adj, 29).unwrap();
        let m = up as i32 - down as i32;
        let upload = upload(gl, &patches).unwrap();
        let tris = capture_triangles(gl, &stages, &["UMBRA_THREE_EDGE"], |program| unsafe {
            gl.uniform_matrix_4_f32_slice(
                gl.get_uniform_location(program, "u_clip_from_world").as_ref(),
                false,
                &IDENTITY,
            );
            gl.uniform_4_f32_slice(gl.get_uniform_location(program, "u_light").as_ref(), &ABOVE);
            gl.bind_vertex_array(Some(upload.vao));
            gl.patch_parameter_i32(glow::PATCH_VERTICES, upload.patch_vertices);
            gl.draw_elements(glow::PATCHES, upload.patch_vertices, glow::UNSIGNED_INT, 0);
        });
        assert_side_quads(&tris, m, ABOVE, true, &format!("3-edge up {up} down {down}"));
        // SAFETY: test objects.
        unsafe {
            gl.delete_vertex_array(upload.vao);
            gl.delete_buffer(upload.vertices);
            gl.delete_buffer(upload.elements);
        }
    }
}

/// CPU twin of determinism.glsl's UMBRA_THREE_EDGE side contribution of opposite `o` to edge
/// `a -> b` (a < b): Alg. 3's branches with Pečiva 2013's 3-edge test on the sorted triangle.
pub(crate) fn three_edge_contribution(p: &[[f32; 3]], a: u32, b: u32, o: u32, light: Light) -> i32 {
    use umbra_geom::multiplicity::triangle_orientation_3edge;
    use umbra_geom::order::greater;
    let (pa, pb, po) = (p[a as usize], p[b as usize], p[o as usize]);
    if greater(pa, po) > 0 {
        triangle_orientation_3edge(p, [o, a, b], light)
    } else if greater(pb, po) > 0 {
        -triangle_orientation_3edge(p, [a, o, b], light)
    } else {
        triangle_orientation_3edge(p, [a, b, o], light)
    }
}

/// A triangle A = (0,0,0), B = (1,0,0), O and a point light almost in its plane, such that the
/// reference edge (Alg. 3-4) orients it (`!= 0`) while the three edge planes disagree (3-edge
/// test: discarded). Found by a deterministic search.
pub(crate) fn inconsistent_triangle() -> (Mesh, Light, i32) {
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 40) as f32 / (1u64 << 24) as f32
    };
    for _ in 0..200_000 {
        let o = [0.2 + 0.6 * next(), 0.5 * (next() - 0.5), -1.0 - next()];
        // A light in the triangle's plane (through A with normal n), nudged by a few ulps.
        let n = [0.0, -o[2], o[1]]; // (B - A) x (O - A) for B - A = (1, 0, 0)
        let (s, t) = (3.0 * next() - 1.0, 3.0 * next() - 1.0);
        let mut l = [s + 0.5 * t, t * o[1], t * o[2]];
        l[1] += (next() - 0.5) * 1e-6 * n[1].signum();
        let light = [l[0], l[1], l[2], 1.0];
        let m =
            Mesh { positions: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], o], triangles: vec![[0, 1, 2]], normals: None };
        let reference = umbra_geom::multiplicity::triangle_orientation(&m.positions, [0, 1, 2], light);
        if reference != 0 && three_edge_contribution(&m.positions, 0, 1, 2, light) == 0 {
            return (m, light, reference);
        }
    }
    panic!("no triangle with inconsistent edge planes found");
}

/// The sides of a triangle whose three edge planes disagree: the reference-edge program
/// draws its side quad (Alg. 3-4), the 3-edge program discards it (Pečiva 2013).
#[test]
fn three_edge_discards_inconsistent_triangle() {
    let ctx = context();
    let gl = ctx.gl();
    let (mesh, light, reference) = inconsistent_triangle();
    let w = weld(&mesh);
    let adj = EdgeAdjacency::build(&w);
    assert_eq!(adj.edges[0], [0, 1]);
    let patches = EdgePatches::build(&w, &adj, 2).unwrap();
    let b = upload(gl, &patches).unwrap();
    let stages = [
        (glow::VERTEX_SHADER, with_prelude(SIDES_VERT)),
        (glow::TESS_CONTROL_SHADER, with_prelude(SIDES_TESC)),
        (glow::TESS_EVALUATION_SHADER, with_prelude(SIDES_TESE)),
    ];
    for three_edge in [false, true] {
        let defines: &[&str] = if three_edge { &["UMBRA_THREE_EDGE"] } else { &[] };
        let tris = capture_triangles(gl, &stages, defines, |program| unsafe {
            gl.uniform_matrix_4_f32_slice(
                gl.get_uniform_location(program, "u_clip_from_world").as_ref(),
                false,
                &IDENTITY,
            );
            gl.uniform_4_f32_slice(gl.get_uniform_location(program, "u_light").as_ref(), &light);
            gl.bind_vertex_array(Some(b.vao));
            gl.patch_parameter_i32(glow::PATCH_VERTICES, b.patch_vertices);
            gl.draw_elements(glow::PATCHES, b.patch_vertices, glow::UNSIGNED_INT, 0);
        });
        if three_edge {
            assert!(tris.is_empty(), "3-edge: the inconsistent triangle casts no side ({} triangles)", tris.len());
        } else {
            assert_side_quads(&tris, reference, light, true, "reference edge");
        }
    }
    // SAFETY: test objects.
    unsafe {
        gl.delete_vertex_array(b.vao);
        gl.delete_buffer(b.vertices);
        gl.delete_buffer(b.elements);
    }
    assert!(ctx.take_gl_errors().is_empty());
}
