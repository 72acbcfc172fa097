//! Which backend draws (`--backend`).

/// The drawing backend of `render`, `verify`, `bench` and `info`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Backend {
    /// OpenGL 4.5 through EGL (umbra-gl), the default.
    Gl,
    /// wgpu: Vulkan, Metal or DX12 (umbra-wgpu).
    Wgpu,
}

impl Backend {
    /// `gl` or `wgpu`, as the flag and the JSON outputs name it.
    pub fn name(self) -> &'static str {
        match self {
            Backend::Gl => "gl",
            Backend::Wgpu => "wgpu",
        }
    }
}
