//! Caps of the GPU silhouette methods (ts-silhouette, gs-silhouette and their `-3edge`
//! variants), drawn in a geometry shader from the scene's own triangles.
//!
//! Paper 001, Section 2.3: the caps of the silhouette method come from a geometry shader that
//! orients every triangle towards the light with the same deterministic test as the sides
//! (reference edge, Alg. 3-4; or Pečiva 2013's 3-edge test for the `-3edge` variants), so sides
//! and caps agree bit for bit and every volume is closed. Light caps are pushed to the far
//! plane (paper 003, Eq. 6, `umbra_push_to_far`); dark caps are extruded to infinity (Eq. 2),
//! point lights only. In z-pass mode no caps are drawn (Heidmann 1991 counts only the faces in
//! front of the sample, which the caps never are once pushed to far / infinity).
//!
//! Input: the scene's vertex array (welded positions at location 0 and its index buffer), one
//! `glDrawElements(GL_TRIANGLES)` over all triangles: no buffer of its own
//! ([`SilhouetteCaps::gpu_bytes`] is 0).
//!
//! Also home of the GLSL shared by the sides and caps of these methods
//! (`determinism.glsl`: `umbra_side_contribution`, `umbra_cap_orientation`,
//! `umbra_clip_from_world_point`) and their fragment shader, which gives every fragment its
//! face's plane depth (`shared/face_depth.frag.glsl`; every cap and
//! side carries its face's depth function, `shared/side_plane.glsl`).

use glow::HasContext;

use crate::error::GlError;
use crate::methods::face_depth::{face_depth_fragment, DepthUniforms, SIDE_PLANE_GLSL};
use crate::methods::method::VolumeFrame;
use crate::program::{link_program, uniform, ShaderSource};
use crate::scene::SceneGpu;

/// Shared deterministic multiplicity (paper 001 Alg. 2-4, Pečiva 2013 3-edge test).
pub(crate) const MULTIPLICITY_GLSL: &str = include_str!("../shared/multiplicity.glsl");
/// Far-plane push of light caps (paper 003 Eq. 6).
pub(crate) const DEPTH_GLSL: &str = include_str!("../shared/depth.glsl");
/// Which orientation test sides and caps use (see the file's header).
pub(crate) const DETERMINISM_GLSL: &str = include_str!("determinism.glsl");
/// Fragment shader body (the stencil operations count; every fragment gets its face's plane depth).
pub(crate) const VOLUME_FRAG_GLSL: &str = include_str!("volume.frag.glsl");

const CAPS_VERT: &str = include_str!("caps.vert.glsl");
const CAPS_GEOM: &str = include_str!("caps.geom.glsl");

/// The `#define` selecting Pečiva 2013's 3-edge test in `determinism.glsl`.
pub(crate) const THREE_EDGE_DEFINE: &str = "UMBRA_THREE_EDGE";

/// `#version 450 core` + the shared GLSL every silhouette stage needs (including the face
/// depth functions of `shared/side_plane.glsl`, which declares `u_clip_from_world`) + `body`.
pub(crate) fn with_prelude(body: &str) -> String {
    format!("#version 450 core\n{MULTIPLICITY_GLSL}\n{DEPTH_GLSL}\n{SIDE_PLANE_GLSL}\n{DETERMINISM_GLSL}\n{body}")
}

/// Source of the fragment shader of every silhouette volume pass (sides and caps).
pub(crate) fn fragment_source() -> String {
    face_depth_fragment(VOLUME_FRAG_GLSL)
}

/// The defines of a method variant (`three_edge`: Pečiva 2013's test).
pub(crate) fn variant_defines(three_edge: bool) -> &'static [&'static str] {
    if three_edge {
        &[THREE_EDGE_DEFINE]
    } else {
        &[]
    }
}

struct Gpu {
    program: glow::Program,
    u_clip_from_world: Option<glow::UniformLocation>,
    u_light: Option<glow::UniformLocation>,
    u_far_clip_z: Option<glow::UniformLocation>,
    depth: DepthUniforms,
}

/// Geometry-shader caps; see the module documentation.
pub struct SilhouetteCaps {
    three_edge: bool,
    gpu: Option<Gpu>,
}

impl SilhouetteCaps {
    /// Caps oriented by the reference edge (`three_edge == false`) or by Pečiva 2013's 3-edge
    /// test. No GL calls.
    pub fn new(three_edge: bool) -> Self {
        Self { three_edge, gpu: None }
    }

    /// Compiles the program (once; later calls do nothing).
    pub fn prepare(&mut self, gl: &glow::Context) -> Result<(), GlError> {
        if self.gpu.is_some() {
            return Ok(());
        }
        let (vert, geom, frag) = (with_prelude(CAPS_VERT), with_prelude(CAPS_GEOM), fragment_source());
        let program = link_program(
            gl,
            if self.three_edge { "silhouette caps (3-edge)" } else { "silhouette caps" },
            &[
                ShaderSource::vertex("silhouette_caps/caps.vert.glsl", &vert),
                ShaderSource { stage: glow::GEOMETRY_SHADER, name: "silhouette_caps/caps.geom.glsl", source: &geom },
                ShaderSource::fragment("silhouette_caps/volume.frag.glsl", &frag),
            ],
            variant_defines(self.three_edge),
        )?;
        self.gpu = Some(Gpu {
            u_clip_from_world: uniform(gl, program, "u_clip_from_world"),
            u_light: uniform(gl, program, "u_light"),
            u_far_clip_z: uniform(gl, program, "u_far_clip_z"),
            depth: DepthUniforms::locate(gl, program),
            program,
        });
        Ok(())
    }

    /// Draws the light and dark caps of every triangle into the stencil, with the frame's
    /// counting state. Draws nothing in z-pass mode.
    pub fn draw(&self, gl: &glow::Context, scene: &SceneGpu, frame: &VolumeFrame<'_>) -> Result<(), GlError> {
        let gpu =
            self.gpu.as_ref().ok_or_else(|| GlError::InvalidParams("silhouette caps: draw before prepare".into()))?;
        if frame.zpass || scene.triangle_count() == 0 {
            // z-pass counts only volume faces in front of the sample: caps are not needed.
            return Ok(());
        }
        // Counting state (z-fail two-sided stencil, depth clamp, no colour/depth writes); the
        // reason for every field is in GlState::shadow_volume.
        frame.shadow_volume_state().apply(gl);
        // SAFETY: our linked program and the scene's vertex array (positions at location 0,
        // index buffer of 3 * triangle_count in-range indices).
        unsafe {
            gl.use_program(Some(gpu.program));
            gl.uniform_matrix_4_f32_slice(gpu.u_clip_from_world.as_ref(), false, &frame.clip_from_world_f32());
            gl.uniform_4_f32_slice(gpu.u_light.as_ref(), &frame.light);
            gl.uniform_1_f32(gpu.u_far_clip_z.as_ref(), frame.far_clip_z());
        }
        // The face depth functions every fragment's depth comes from (shared/side_plane.glsl).
        gpu.depth.set(gl, frame);
        // SAFETY: the scene's vertex array (positions at location 0, in-range indices).
        unsafe {
            // The scene's own VAO: its triangles are the caps' input primitives.
            gl.bind_vertex_array(Some(scene.vertex_array()));
        }
        scene.draw_triangles(gl);
        Ok(())
    }

    /// Bytes of GPU buffers the caps own: none (they read the scene's buffers).
    pub fn gpu_bytes(&self) -> usize {
        0
    }

    /// Deletes the program (context current).
    pub fn destroy(&mut self, gl: &glow::Context) {
        if let Some(g) = self.gpu.take() {
            // SAFETY: our own program, not used afterwards.
            unsafe { gl.delete_program(g.program) };
        }
    }
}

#[cfg(test)]
mod tests {
    use glow::HasContext;
    use umbra_geom::silhouette::{extract, VolumeGeometry};
    use umbra_geom::weld::weld;
    use umbra_geom::{EdgeAdjacency, Light, Mesh};

    use super::*;
    use crate::methods::ts_silhouette::tests::{capture_triangles, context, inconsistent_triangle, IDENTITY};

    /// Caps of `mesh` from the geometry shader (identity clip transform, far plane z = w).
    fn capture_caps(gl: &glow::Context, mesh: &Mesh, light: Light, three_edge: bool) -> Vec<[[f32; 4]; 3]> {
        let w = std::sync::Arc::new(weld(mesh));
        let scene = SceneGpu::upload(gl, w).unwrap();
        let stages = [(glow::VERTEX_SHADER, with_prelude(CAPS_VERT)), (glow::GEOMETRY_SHADER, with_prelude(CAPS_GEOM))];
        let tris = capture_triangles(gl, &stages, variant_defines(three_edge), |program| unsafe {
            gl.uniform_matrix_4_f32_slice(
                gl.get_uniform_location(program, "u_clip_from_world").as_ref(),
                false,
                &IDENTITY,
            );
            gl.uniform_4_f32_slice(gl.get_uniform_location(program, "u_light").as_ref(), &light);
            gl.uniform_1_f32(gl.get_uniform_location(program, "u_far_clip_z").as_ref(), 1.0);
            gl.bind_vertex_array(Some(scene.vertex_array()));
            scene.draw_triangles(gl);
        });
        scene.destroy(gl);
        tris
    }

    /// The caps equal cpu-silhouette's (umbra_geom::silhouette::extract), triangle for triangle
    /// and vertex for vertex: light caps with z pushed to w, dark caps for point lights only.
    #[test]
    fn caps_equal_cpu_extract() {
        let ctx = context();
        let gl = ctx.gl();
        let mut mesh = umbra_geom::scene::uv_sphere([0.0, 2.0, 0.0], 1.0, 12, 6);
        mesh.append(&Mesh {
            positions: vec![[0.0, 0.5, 0.0], [1.0, 0.5, 0.0], [0.0, 0.5, 1.0]],
            triangles: vec![[0, 1, 2], [0, 2, 1]],
            normals: None,
        });
        for light in [[0.3, 6.0, 0.2, 1.0], [-0.5, 1.0, 0.2, 0.0], [0.0, 2.0, 0.0, 1.0]] {
            let tris = capture_caps(gl, &mesh, light, false);
            let w = weld(&mesh);
            let mut cpu = VolumeGeometry::default();
            extract(&w, &EdgeAdjacency::build(&w), light, true, &mut cpu);
            let light_caps: Vec<[f32; 4]> = cpu.light_caps.iter().map(|v| [v[0], v[1], v[3], v[3]]).collect();
            let per_triangle = if light[3] == 0.0 { 1 } else { 2 };
            assert_eq!(tris.len(), per_triangle * light_caps.len() / 3, "light {light:?}");
            for (t, tri) in tris.chunks(per_triangle).enumerate() {
                assert_eq!(tri[0].to_vec(), light_caps[3 * t..3 * t + 3].to_vec(), "light cap {t}, light {light:?}");
                if per_triangle == 2 {
                    assert_eq!(
                        tri[1].to_vec(),
                        cpu.dark_caps[3 * t..3 * t + 3].to_vec(),
                        "dark cap {t}, light {light:?}"
                    );
                }
            }
        }
        assert!(ctx.take_gl_errors().is_empty());
    }

    /// A triangle whose edge planes disagree keeps its caps with the reference edge and loses
    /// them with the 3-edge test, as its sides do.
    #[test]
    fn three_edge_caps_discard_inconsistent_triangle() {
        let ctx = context();
        let gl = ctx.gl();
        let (mesh, light, _) = inconsistent_triangle();
        assert_eq!(capture_caps(gl, &mesh, light, false).len(), 2, "reference edge: light + dark cap");
        assert!(capture_caps(gl, &mesh, light, true).is_empty(), "3-edge: discarded");
    }
}
