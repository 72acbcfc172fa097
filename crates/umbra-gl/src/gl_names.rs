//! GL object names from the integers `glGet*` reports (0 = none), for re-binding what was
//! bound before.

use std::num::NonZeroU32;

/// The buffer named `name`; None for 0.
pub(crate) fn buffer(name: u32) -> Option<glow::Buffer> {
    NonZeroU32::new(name).map(glow::NativeBuffer)
}

/// The framebuffer named `name`; None for 0 (the default framebuffer).
pub(crate) fn framebuffer(name: u32) -> Option<glow::Framebuffer> {
    NonZeroU32::new(name).map(glow::NativeFramebuffer)
}

/// The program named `name`; None for 0.
pub(crate) fn program(name: u32) -> Option<glow::Program> {
    NonZeroU32::new(name).map(glow::NativeProgram)
}

/// The vertex array named `name`; None for 0.
pub(crate) fn vertex_array(name: u32) -> Option<glow::VertexArray> {
    NonZeroU32::new(name).map(glow::NativeVertexArray)
}

/// The texture named `name`; None for 0.
pub(crate) fn texture(name: u32) -> Option<glow::Texture> {
    NonZeroU32::new(name).map(glow::NativeTexture)
}
