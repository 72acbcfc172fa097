//! Window-space depth functions of volume faces, evaluated in the fragment shader: the shared
//! GLSL (`shared/side_plane.glsl`) and its uniforms.
//!
//! Paper 001, Section 2.3 (depths set in the fragment shader). Two uses:
//! * ts-triangle and ts-triangle-1pass give every side fragment its canonical plane's depth
//!   (see [`crate::methods::ts_triangle`]);
//! * the volume passes whose depth was rasterized (gs-triangle, vs-triangle, the silhouette
//!   methods and their caps) give every fragment the depth of its face's plane instead of the
//!   interpolated one, which llvmpipe's f32 triangle setup gets wrong on needle-shaped faces
//!   and NaN on faces of zero float area, so z-fail counts it like the face
//!   it belongs to.

use glow::HasContext;

use crate::camera::DepthConvention;
use crate::methods::method::VolumeFrame;

/// The shared GLSL (no `#version`; after `shared/multiplicity.glsl` and `shared/depth.glsl`):
/// `umbra_window_depth_plane`, `umbra_side_depth_plane`, `umbra_face_depth_*`; it declares
/// `u_clip_from_world`.
pub(crate) const SIDE_PLANE_GLSL: &str = include_str!("shared/side_plane.glsl");

/// The fragment side of the rasterized-depth passes (no `#version`): declares
/// `face_window_depth` and `umbra_write_face_depth()`.
pub(crate) const FACE_DEPTH_FRAG_GLSL: &str = include_str!("shared/face_depth.frag.glsl");

/// Components one flat `dvec3 face_window_depth` adds to every geometry-shader output vertex
/// (doubles count twice towards GL_MAX_GEOMETRY_TOTAL_OUTPUT_COMPONENTS).
pub const FACE_DEPTH_COMPONENTS: i32 = 6;

/// `#version 450 core` + the face-depth snippet + a fragment shader `body` without `#version`
/// that calls `umbra_write_face_depth()`.
pub(crate) fn face_depth_fragment(body: &str) -> String {
    format!("#version 450 core\n{FACE_DEPTH_FRAG_GLSL}\n{body}")
}

/// `z_window = a * z_ndc + b` for the frame's depth convention, as `[a, b]`: (0.5, 0.5) for
/// [`DepthConvention::Standard`] (clip z in -w..w, glDepthRange(0, 1)), (1, 0) for
/// [`DepthConvention::ReversedZ`] (glClipControl ZERO_TO_ONE: the window depth is z_ndc).
pub fn depth_from_ndc(convention: DepthConvention) -> [f32; 2] {
    match convention {
        DepthConvention::Standard => [0.5, 0.5],
        DepthConvention::ReversedZ => [1.0, 0.0],
    }
}

/// Window depth that makes a volume fragment never count: it passes the depth test in z-fail
/// (the near plane) and fails it in z-pass (the far plane). Given to side fragments seen
/// exactly edge-on (ts_triangle/side_depth.frag.glsl, shared/side_plane.glsl). The far plane's
/// window depth is `far_clip_z` (1 Standard, 0 reversed-Z), the near plane's the other end of
/// the 0..1 range.
pub fn edge_on_depth(far_clip_z: f32, zpass: bool) -> f32 {
    if zpass {
        far_clip_z
    } else {
        1.0 - far_clip_z
    }
}

/// Uniforms of shared/side_plane.glsl (`u_viewport_size`, `u_depth_from_ndc`,
/// `u_edge_on_depth`), wherever it is spliced.
pub(crate) struct DepthUniforms {
    u_viewport_size: Option<glow::UniformLocation>,
    u_depth_from_ndc: Option<glow::UniformLocation>,
    u_edge_on_depth: Option<glow::UniformLocation>,
}

impl DepthUniforms {
    pub(crate) fn locate(gl: &glow::Context, program: glow::Program) -> Self {
        Self {
            u_viewport_size: crate::program::uniform(gl, program, "u_viewport_size"),
            u_depth_from_ndc: crate::program::uniform(gl, program, "u_depth_from_ndc"),
            u_edge_on_depth: crate::program::uniform(gl, program, "u_edge_on_depth"),
        }
    }

    /// Sets them for `frame` on the current program.
    pub(crate) fn set(&self, gl: &glow::Context, frame: &VolumeFrame<'_>) {
        self.set_for(gl, [frame.width, frame.height], frame.depth_convention(), frame.zpass);
    }

    /// Sets them on the current program for a `viewport_size` viewport, the depth
    /// `convention` and the counting mode (`zpass`).
    pub(crate) fn set_for(
        &self,
        gl: &glow::Context,
        viewport_size: [u32; 2],
        convention: DepthConvention,
        zpass: bool,
    ) {
        // SAFETY: uniform setters on the current program with matching types.
        unsafe {
            gl.uniform_2_f32(self.u_viewport_size.as_ref(), viewport_size[0] as f32, viewport_size[1] as f32);
            let [a, b] = depth_from_ndc(convention);
            gl.uniform_2_f32(self.u_depth_from_ndc.as_ref(), a, b);
            gl.uniform_1_f32(self.u_edge_on_depth.as_ref(), edge_on_depth(convention.far_clip_z(), zpass));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn window_depth_of_the_planes_per_convention() {
        for convention in [DepthConvention::Standard, DepthConvention::ReversedZ] {
            let [a, b] = depth_from_ndc(convention);
            let far = convention.far_clip_z(); // z_ndc of the far plane
                                               // The far plane's window depth is the depth buffer's far value.
            assert_eq!(a * far + b, convention.far_depth());
            // Edge-on sides: never counted - nearer than anything in z-fail, the far plane in z-pass.
            assert_eq!(edge_on_depth(far, true), convention.far_depth());
            assert_eq!(edge_on_depth(far, false), 1.0 - convention.far_depth());
        }
    }
}
