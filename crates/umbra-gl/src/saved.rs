//! Saving and restoring the caller's GL state around a frame (library-first: the renderer
//! may run on somebody else's context).
//!
//! Restored exactly: every [`GlState`] field, the current program, vertex array, draw and
//! read framebuffers, viewport, SCISSOR_TEST, RASTERIZER_DISCARD, CLIP_DISTANCE0..7 (desktop
//! GL; the volume pass enables 0 for the near-plane clip of light caps and 1..6 for the z-pass
//! scene box), the uniform buffer at SCENE_CLIP_BINDING and the generic one, the generic and indexed
//! (binding 0) SHADER_STORAGE_BUFFER bindings, glDepthRange, and glClipControl's origin and
//! depth mode (when the renderer has glClipControl; without it the renderer never changes
//! them).

use glow::HasContext;

use crate::extra::GlExtra;
use crate::gl_names::{buffer, framebuffer, program, texture, vertex_array};
use crate::scene::{NORMALS_BINDING, SCENE_CLIP_BINDING};
use crate::state::GlState;

/// Everything the renderer changes on the context, as it was before.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SavedState {
    state: GlState,
    program: u32,
    vertex_array: u32,
    draw_framebuffer: u32,
    read_framebuffer: u32,
    viewport: [i32; 4],
    scissor_test: bool,
    rasterizer_discard: bool,
    /// GL_CLIP_DISTANCE0..7 (0: the near-plane clip of light caps; 1..6: the z-pass scene box
    /// clip; the volume pass turns 7 off); None on OpenGL ES (no clip distances in ES 3.x core).
    clip_distances: Option<[bool; 8]>,
    /// Uniform buffer at SCENE_CLIP_BINDING (name, start, size) and the generic binding.
    ubo_indexed: (u32, i64, i64),
    ubo_generic: u32,
    ssbo_generic: u32,
    ssbo_indexed: u32,
    ssbo_offset: i64,
    ssbo_size: i64,
    clip_origin: u32,
    clip_depth_mode: u32,
    depth_range: [f32; 2],
    /// glPolygonMode (front and back are the same in core GL); None on OpenGL ES (no polygon
    /// mode there).
    polygon_mode: Option<u32>,
    blend_color: [f32; 4],
}

impl SavedState {
    pub(crate) fn capture(gl: &glow::Context) -> Self {
        // SAFETY: glGet* queries of core state on the current context.
        unsafe {
            let mut viewport = [0; 4];
            gl.get_parameter_i32_slice(glow::VIEWPORT, &mut viewport);
            let mut depth_range = [0.0; 2];
            gl.get_parameter_f32_slice(glow::DEPTH_RANGE, &mut depth_range);
            // GL_POLYGON_MODE answers two values (front, back) on some drivers, one on others.
            let mut polygon_mode = [glow::FILL as i32; 2];
            let is_embedded = gl.version().is_embedded;
            if !is_embedded {
                gl.get_parameter_i32_slice(glow::POLYGON_MODE, &mut polygon_mode);
            }
            let mut blend_color = [0.0; 4];
            gl.get_parameter_f32_slice(glow::BLEND_COLOR, &mut blend_color);
            Self {
                state: GlState::capture(gl),
                program: gl.get_parameter_i32(glow::CURRENT_PROGRAM) as u32,
                vertex_array: gl.get_parameter_i32(glow::VERTEX_ARRAY_BINDING) as u32,
                draw_framebuffer: gl.get_parameter_i32(glow::DRAW_FRAMEBUFFER_BINDING) as u32,
                read_framebuffer: gl.get_parameter_i32(glow::READ_FRAMEBUFFER_BINDING) as u32,
                viewport,
                scissor_test: gl.is_enabled(glow::SCISSOR_TEST),
                rasterizer_discard: gl.is_enabled(glow::RASTERIZER_DISCARD),
                clip_distances: (!gl.version().is_embedded)
                    .then(|| std::array::from_fn(|i| gl.is_enabled(glow::CLIP_DISTANCE0 + i as u32))),
                ubo_indexed: (
                    gl.get_parameter_indexed_i32(glow::UNIFORM_BUFFER_BINDING, SCENE_CLIP_BINDING) as u32,
                    gl.get_parameter_indexed_i64(glow::UNIFORM_BUFFER_START, SCENE_CLIP_BINDING),
                    gl.get_parameter_indexed_i64(glow::UNIFORM_BUFFER_SIZE, SCENE_CLIP_BINDING),
                ),
                ubo_generic: gl.get_parameter_i32(glow::UNIFORM_BUFFER_BINDING) as u32,
                ssbo_generic: gl.get_parameter_i32(glow::SHADER_STORAGE_BUFFER_BINDING) as u32,
                ssbo_indexed: gl.get_parameter_indexed_i32(glow::SHADER_STORAGE_BUFFER_BINDING, NORMALS_BINDING) as u32,
                ssbo_offset: gl.get_parameter_indexed_i64(glow::SHADER_STORAGE_BUFFER_START, NORMALS_BINDING),
                ssbo_size: gl.get_parameter_indexed_i64(glow::SHADER_STORAGE_BUFFER_SIZE, NORMALS_BINDING),
                clip_origin: gl.get_parameter_i32(glow::CLIP_ORIGIN) as u32,
                clip_depth_mode: gl.get_parameter_i32(glow::CLIP_DEPTH_MODE) as u32,
                depth_range,
                polygon_mode: (!is_embedded).then_some(polygon_mode[0] as u32),
                blend_color,
            }
        }
    }

    pub(crate) fn restore(&self, gl: &glow::Context, extra: &GlExtra) {
        self.state.apply(gl);
        // SAFETY: the context `extra` was loaded for is current (the renderer's contract); the
        // values are the ones GL reported. Returns false without glClipControl, in which case
        // the renderer did not change it either.
        unsafe { extra.clip_control(self.clip_origin, self.clip_depth_mode) };
        // SAFETY: re-binding names that were bound before (still alive: the renderer deletes
        // none of the caller's objects).
        unsafe {
            gl.use_program(program(self.program));
            gl.bind_vertex_array(vertex_array(self.vertex_array));
            gl.bind_framebuffer(glow::DRAW_FRAMEBUFFER, framebuffer(self.draw_framebuffer));
            gl.bind_framebuffer(glow::READ_FRAMEBUFFER, framebuffer(self.read_framebuffer));
            let [x, y, w, h] = self.viewport;
            gl.viewport(x, y, w, h);
            gl.depth_range_f32(self.depth_range[0], self.depth_range[1]);
            if let Some(mode) = self.polygon_mode {
                gl.polygon_mode(glow::FRONT_AND_BACK, mode);
            }
            let [r, g, b, a] = self.blend_color;
            gl.blend_color(r, g, b, a);
            for (cap, on) in
                [(glow::SCISSOR_TEST, self.scissor_test), (glow::RASTERIZER_DISCARD, self.rasterizer_discard)]
            {
                if on {
                    gl.enable(cap)
                } else {
                    gl.disable(cap)
                }
            }
            match buffer(self.ssbo_indexed) {
                // A range binding with size 0 means the whole buffer was bound (glBindBufferBase).
                Some(b) if self.ssbo_size > 0 => gl.bind_buffer_range(
                    glow::SHADER_STORAGE_BUFFER,
                    NORMALS_BINDING,
                    Some(b),
                    self.ssbo_offset as i32,
                    self.ssbo_size as i32,
                ),
                other => gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, NORMALS_BINDING, other),
            }
            gl.bind_buffer(glow::SHADER_STORAGE_BUFFER, buffer(self.ssbo_generic));
            if let Some(on) = self.clip_distances {
                for (i, on) in on.iter().enumerate() {
                    let cap = glow::CLIP_DISTANCE0 + i as u32;
                    if *on {
                        gl.enable(cap)
                    } else {
                        gl.disable(cap)
                    }
                }
            }
            let (ubo, start, size) = self.ubo_indexed;
            match buffer(ubo) {
                Some(b) if size > 0 => {
                    gl.bind_buffer_range(glow::UNIFORM_BUFFER, SCENE_CLIP_BINDING, Some(b), start as i32, size as i32)
                }
                other => gl.bind_buffer_base(glow::UNIFORM_BUFFER, SCENE_CLIP_BINDING, other),
            }
            gl.bind_buffer(glow::UNIFORM_BUFFER, buffer(self.ubo_generic));
        }
    }
}

/// Bindings a shadow method may change on the context beyond [`SavedState`]'s list (its
/// storage buffers, vertex and indirect buffers, patch size, the shadow map's texture unit),
/// saved and restored around every call that runs a method on a caller's context.
pub(crate) struct MethodBindings {
    /// SHADER_STORAGE_BUFFER indexed bindings 1.. (binding 0 is in SavedState): buffer,
    /// offset, size.
    ssbo: Vec<(u32, i64, i64)>,
    array_buffer: u32,
    copy_read_buffer: u32,
    draw_indirect_buffer: u32,
    /// GL_DISPATCH_INDIRECT_BUFFER (hier-triangle's indirect compute dispatches).
    dispatch_indirect_buffer: u32,
    patch_vertices: i32,
    active_texture: u32,
    /// Unit 0 (the shadow map's MAP_UNIT, the wide counter's unit): 2D and cube-map textures.
    texture_2d: u32,
    texture_cube: u32,
}

/// Indexed storage-buffer bindings saved: 0 (in SavedState) up to this, exclusive; the
/// methods use 1-8 (8: hier-silhouette's counts).
const SAVED_SSBO_BINDINGS: u32 = 9;

impl MethodBindings {
    pub(crate) fn capture(gl: &glow::Context) -> Self {
        // SAFETY: glGet* queries of core state on the current context; the active texture
        // unit is switched to 0 for the two texture queries and set back.
        unsafe {
            let ssbo = (1..SAVED_SSBO_BINDINGS)
                .map(|i| {
                    (
                        gl.get_parameter_indexed_i32(glow::SHADER_STORAGE_BUFFER_BINDING, i) as u32,
                        gl.get_parameter_indexed_i64(glow::SHADER_STORAGE_BUFFER_START, i),
                        gl.get_parameter_indexed_i64(glow::SHADER_STORAGE_BUFFER_SIZE, i),
                    )
                })
                .collect();
            let active_texture = gl.get_parameter_i32(glow::ACTIVE_TEXTURE) as u32;
            gl.active_texture(glow::TEXTURE0);
            let texture_2d = gl.get_parameter_i32(glow::TEXTURE_BINDING_2D) as u32;
            let texture_cube = gl.get_parameter_i32(glow::TEXTURE_BINDING_CUBE_MAP) as u32;
            gl.active_texture(active_texture);
            Self {
                ssbo,
                array_buffer: gl.get_parameter_i32(glow::ARRAY_BUFFER_BINDING) as u32,
                copy_read_buffer: gl.get_parameter_i32(glow::COPY_READ_BUFFER_BINDING) as u32,
                draw_indirect_buffer: gl.get_parameter_i32(glow::DRAW_INDIRECT_BUFFER_BINDING) as u32,
                dispatch_indirect_buffer: gl.get_parameter_i32(glow::DISPATCH_INDIRECT_BUFFER_BINDING) as u32,
                patch_vertices: gl.get_parameter_i32(glow::PATCH_VERTICES),
                active_texture,
                texture_2d,
                texture_cube,
            }
        }
    }

    pub(crate) fn restore(&self, gl: &glow::Context) {
        // SAFETY: re-binding names that were bound before (still alive: umbra deletes none of
        // the caller's objects) and a patch size GL reported.
        unsafe {
            for (i, &(name, offset, size)) in (1..).zip(&self.ssbo) {
                match buffer(name) {
                    // A range binding with size 0 means the whole buffer was bound.
                    Some(b) if size > 0 => {
                        gl.bind_buffer_range(glow::SHADER_STORAGE_BUFFER, i, Some(b), offset as i32, size as i32)
                    }
                    other => gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, i, other),
                }
            }
            gl.bind_buffer(glow::ARRAY_BUFFER, buffer(self.array_buffer));
            gl.bind_buffer(glow::COPY_READ_BUFFER, buffer(self.copy_read_buffer));
            gl.bind_buffer(glow::DRAW_INDIRECT_BUFFER, buffer(self.draw_indirect_buffer));
            gl.bind_buffer(glow::DISPATCH_INDIRECT_BUFFER, buffer(self.dispatch_indirect_buffer));
            gl.patch_parameter_i32(glow::PATCH_VERTICES, self.patch_vertices);
            gl.active_texture(glow::TEXTURE0);
            gl.bind_texture(glow::TEXTURE_2D, texture(self.texture_2d));
            gl.bind_texture(glow::TEXTURE_CUBE_MAP, texture(self.texture_cube));
            gl.active_texture(self.active_texture);
        }
    }
}
