//! GL unit tests of the geometry stage, observed through transform feedback.

use glow::HasContext;
use umbra_geom::weld::weld;
use umbra_geom::{EdgeAdjacency, Light, Mesh};

use super::*;
use crate::methods::ts_silhouette::tests::{
    assert_side_quads, capture_triangles, context, fan, inconsistent_triangle, ABOVE, IDENTITY,
};

/// Captures the side triangles the geometry shader emits for the spine (0,0,0)-(1,0,0) of
/// `fan(up, down)` with patch capacity `capacity`.
fn capture(gl: &glow::Context, up: usize, down: usize, capacity: usize, three_edge: bool) -> Vec<[[f32; 4]; 3]> {
    capture_spine(gl, &fan(up, down), ABOVE, up + down, capacity, three_edge)
}

/// The side triangles of the first edge of `mesh` (with `opposites` opposite vertices).
fn capture_spine(
    gl: &glow::Context,
    mesh: &Mesh,
    light: Light,
    opposites: usize,
    capacity: usize,
    three_edge: bool,
) -> Vec<[[f32; 4]; 3]> {
    let w = weld(mesh);
    let adj = EdgeAdjacency::build(&w);
    let patches = EdgePatches::build(&w, &adj, capacity).unwrap();
    let b = upload(gl, &patches).unwrap();
    let defines = [
        format!("UMBRA_PATCH_CAPACITY {capacity}"),
        format!("UMBRA_PATCH_STRIDE {}", capacity + 3),
        format!("UMBRA_ELEMENTS_BINDING {ELEMENTS_BINDING}"),
        format!("UMBRA_VERTICES_BINDING {VERTICES_BINDING}"),
    ];
    let mut defines: Vec<&str> = defines.iter().map(String::as_str).collect();
    if three_edge {
        defines.push(THREE_EDGE_DEFINE);
    }
    let stages = [(glow::VERTEX_SHADER, with_prelude(SIDES_VERT)), (glow::GEOMETRY_SHADER, with_prelude(SIDES_GEOM))];
    // Only the spine's patches: they come first (edge (0, 1) is first in adjacency order).
    let spine_patches = opposites.div_ceil(capacity) as i32;
    let tris = capture_triangles(gl, &stages, &defines, |program| unsafe {
        gl.uniform_matrix_4_f32_slice(gl.get_uniform_location(program, "u_clip_from_world").as_ref(), false, &IDENTITY);
        gl.uniform_4_f32_slice(gl.get_uniform_location(program, "u_light").as_ref(), &light);
        gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, ELEMENTS_BINDING, Some(b.elements));
        gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, VERTICES_BINDING, Some(b.vertices));
        gl.bind_vertex_array(Some(b.vao));
        gl.draw_arrays(glow::POINTS, 0, spine_patches);
    });
    // SAFETY: test objects.
    unsafe {
        gl.delete_vertex_array(b.vao);
        gl.delete_buffer(b.vertices);
        gl.delete_buffer(b.elements);
    }
    tris
}

/// One invocation: exactly |m| quads with the winding of umbra_geom::silhouette, for every
/// multiplicity a 25-capacity patch holds (the GL minimums' limit, patches.rs
/// gs_capacity_limit), either sign.
#[test]
fn one_patch_emits_m_quads() {
    let ctx = context();
    let gl = ctx.gl();
    for (up, down) in [(1, 0), (0, 1), (2, 0), (0, 2), (5, 2), (1, 6), (25, 0), (0, 25), (13, 12), (3, 3)] {
        let m = up as i32 - down as i32;
        let tris = capture(gl, up, down, 25, false);
        assert_side_quads(&tris, m, ABOVE, true, &format!("up {up} down {down}"));
        // cpu-silhouette's triangles, starting on the edge: Q1 Q2 Q0, Q0 Q2 Q3 per copy.
        let ext = |p: [f32; 3]| umbra_geom::silhouette::extrude(p, ABOVE);
        let (a, b) = ([0.0, 0.0, 0.0, 1.0], [1.0, 0.0, 0.0, 1.0]);
        let q = if m > 0 {
            [b, a, ext([0.0; 3]), ext([1.0, 0.0, 0.0])]
        } else {
            [a, b, ext([1.0, 0.0, 0.0]), ext([0.0; 3])]
        };
        for (i, t) in tris.iter().enumerate() {
            let want = if i % 2 == 0 { [q[1], q[2], q[0]] } else { [q[0], q[2], q[3]] };
            assert_eq!(*t, want, "up {up} down {down}: triangle {i}");
        }
    }
    assert!(ctx.take_gl_errors().is_empty());
}

/// Split edges: 40 pages in patches of 3 or 8 opposites (sub-multiplicities of both signs
/// when the pages face both ways) add up to the edge's multiplicity, for both tests.
#[test]
fn split_patches_add_up() {
    let ctx = context();
    let gl = ctx.gl();
    for three_edge in [false, true] {
        for (up, down, capacity) in [(40, 0, 3), (0, 40, 8), (25, 15, 8), (13, 27, 3), (20, 20, 7)] {
            let m = up as i32 - down as i32;
            let tris = capture(gl, up, down, capacity, three_edge);
            assert_side_quads(&tris, m, ABOVE, false, &format!("up {up} down {down} K {capacity} 3-edge {three_edge}"));
        }
    }
    assert!(ctx.take_gl_errors().is_empty());
}

/// A triangle whose three edge planes disagree: a side quad with the reference edge, none with
/// Pečiva 2013's 3-edge test.
#[test]
fn three_edge_discards_inconsistent_triangle() {
    let ctx = context();
    let gl = ctx.gl();
    let (mesh, light, reference) = inconsistent_triangle();
    assert_side_quads(&capture_spine(gl, &mesh, light, 1, 2, false), reference, light, true, "reference edge");
    assert!(capture_spine(gl, &mesh, light, 1, 2, true).is_empty(), "3-edge: discarded");
    assert!(ctx.take_gl_errors().is_empty());
}
