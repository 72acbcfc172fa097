//! The soak checked by mutation: a method wrapped so that it leaks a GL buffer, or heap, per
//! frame fails the check that should catch it.

use crate::check::check;
use crate::plan::create_all;
use crate::soak;
use umbra_gl::glow;
use umbra_gl::{Classification, GlError, SceneGpu, SceneId, ShadowMethod, VolumeFrame};

/// How [`Leaky`] leaks, once per frame.
#[derive(Clone, Copy)]
pub(crate) enum Leak {
    /// A 4 KiB GL buffer created and never deleted.
    GlBuffer,
    /// 64 KiB of heap, written (so resident) and never freed.
    Heap,
}

/// A registered method that leaks once per `draw_volumes` (the mutation tests).
pub(crate) struct Leaky {
    pub(crate) inner: Box<dyn ShadowMethod>,
    pub(crate) leak: Leak,
}

impl ShadowMethod for Leaky {
    fn name(&self) -> &'static str {
        self.inner.name()
    }
    fn stages(&self) -> &'static [&'static str] {
        self.inner.stages()
    }
    fn prepare(&mut self, gl: &glow::Context, scene: &SceneGpu) -> Result<(), GlError> {
        self.inner.prepare(gl, scene)
    }
    fn prepared_scene(&self) -> Option<SceneId> {
        self.inner.prepared_scene()
    }
    fn draw_volumes(
        &mut self,
        gl: &glow::Context,
        scene: &SceneGpu,
        frame: &mut VolumeFrame<'_>,
    ) -> Result<(), GlError> {
        match self.leak {
            Leak::GlBuffer => {
                use glow::HasContext;
                // SAFETY: creates and fills a buffer on the current context; the binding is
                // restored to none (the renderer re-binds what it needs).
                unsafe {
                    let b = gl.create_buffer().expect("buffer");
                    gl.bind_buffer(glow::COPY_WRITE_BUFFER, Some(b));
                    gl.buffer_data_size(glow::COPY_WRITE_BUFFER, 4096, glow::STATIC_DRAW);
                    gl.bind_buffer(glow::COPY_WRITE_BUFFER, None);
                }
            }
            Leak::Heap => {
                let block: &mut [u8] = Box::leak(vec![0u8; 64 * 1024].into_boxed_slice());
                for (i, b) in block.iter_mut().enumerate() {
                    *b = i as u8;
                }
                std::hint::black_box(&block);
            }
        }
        self.inner.draw_volumes(gl, scene, frame)
    }
    fn silhouette_sides(&self) -> bool {
        self.inner.silhouette_sides()
    }
    fn classification(&self) -> Classification {
        self.inner.classification()
    }
    fn lighting_glsl(&self) -> Option<&'static str> {
        self.inner.lighting_glsl()
    }
    fn bind_lighting(
        &mut self,
        gl: &glow::Context,
        program: glow::Program,
        frame: &VolumeFrame<'_>,
    ) -> Result<(), GlError> {
        self.inner.bind_lighting(gl, program, frame)
    }
    fn gpu_bytes(&self) -> usize {
        self.inner.gpu_bytes()
    }
    fn destroy(&mut self, gl: &glow::Context) {
        self.inner.destroy(gl)
    }
}

/// Every registered method, those named in `leaking` leaking as `leak` says.
pub(crate) fn with_leak(leak: Leak, leaking: &[&str]) -> Vec<Box<dyn ShadowMethod>> {
    let wrap = |m: Box<dyn ShadowMethod>| -> Box<dyn ShadowMethod> {
        if leaking.contains(&m.name()) {
            Box::new(Leaky { inner: m, leak })
        } else {
            m
        }
    };
    create_all().into_iter().map(wrap).collect()
}

/// Mutation: one GL buffer not deleted per frame fails the exact object check.
#[test]
fn soak_detects_a_leaked_gl_buffer_per_frame() {
    let record = soak(2, || with_leak(Leak::GlBuffer, &["cpu-silhouette"]));
    let problems = check(&record);
    assert!(problems.iter().any(|p| p.starts_with("GL objects: block")), "the leak went unnoticed: {problems:?}");
    assert!(problems.iter().any(|p| p.starts_with("GL objects left")), "the leak went unnoticed: {problems:?}");
}

/// Mutation: 64 KiB of memory leaked per frame fails the slope check. Five measured blocks:
/// four windows after the settling one, two blocks (408 frames) between the thirds, so the
/// windows' scatter (up to 12 MB, measured) moves the reading by at most 30 KiB per frame.
#[test]
fn soak_detects_leaked_memory_per_frame() {
    let record = soak(5, || with_leak(Leak::Heap, umbra_gl::method_names()));
    let problems = check(&record);
    assert!(problems.iter().any(|p| p.contains("KiB per frame")), "the leak went unnoticed: {problems:?}");
    assert!(!problems.iter().any(|p| p.starts_with("GL objects")), "a heap leak is not a GL object: {problems:?}");
}
