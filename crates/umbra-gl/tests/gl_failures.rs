//! GL failures leave the process usable: a shadow-map
//! resolution above `GL_MAX_CUBE_MAP_TEXTURE_SIZE` and storage the driver refuses
//! (`GL_OUT_OF_MEMORY`, provoked for real: a scene buffer, a method's buffer, a shadow map, a
//! render target) give typed errors, never a panic or an abort, and afterwards the SAME
//! context and [`Renderer`] draw a normal frame whose PNG bytes equal those of the same frame
//! drawn before the failure and on a fresh context.
//!
//! How the driver is made to refuse, without allocating gigabytes on a shared machine:
//! * texture: llvmpipe checks a texture's total size against its resource limit
//!   (`LP_MAX_TEXTURE_SIZE`, `llvmpipe_can_create_resource`) before allocating, and Mesa turns
//!   the refusal into `GL_OUT_OF_MEMORY` (`glTexStorage*(texture too large)`); a
//!   `shadow-map-cube:16384` (16384 = GL_MAX_CUBE_MAP_TEXTURE_SIZE on llvmpipe, 6 GiB of
//!   depth32F) is accepted by size but refused that way, in milliseconds, with no memory
//!   touched;
//! * buffer: llvmpipe `malloc`s (and zeroes) every buffer store, so it only refuses when malloc
//!   fails. A child process of this test binary limits its own address space (`setrlimit
//!   RLIMIT_AS` = its current size + 256 MiB) just around `SceneGpu::upload` of a scene whose
//!   position buffer is 480 MB (40 M positions, all but the scene's own unused and zero,
//!   `calloc`ed so never resident): llvmpipe's malloc fails and Mesa reports
//!   `GL_OUT_OF_MEMORY in glNamedBufferData`. The limit makes even a driver that did allocate
//!   fail instead of eating memory, so the same child also runs the texture case under it;
//! * a method's own buffer, in `prepare`: the same limit, with a headroom of 1.5 x the size
//!   of `ts-silhouette`'s extended vertex buffer (72 MB, over 6 M unused positions placed
//!   before the scene's own): the CPU copy the method builds fits, llvmpipe's copy does not;
//! * sizes GL cannot take at all (a `GLsizeiptr` near `isize::MAX`): umbra never passes them
//!   (`checked_size`: more than 2 GiB per buffer is `InvalidParams` before any GL call, tested
//!   with 2.2 GB of `calloc`ed, never resident, positions); what the driver itself does with
//!   such a size is probed with a raw `glNamedBufferData(isize::MAX)`: `GL_OUT_OF_MEMORY`, and
//!   the context stays usable.
//!
//! The address-space limit is process-wide, so the tests that set it run in a child process
//! (`--exact NAME --ignored`, as `determinism.rs` does for rayon), where nothing else runs.

mod common;

use common::child::{is_child, run_in_child, status_kib, with_address_space_headroom, CHILD_DONE};
use common::*;
use glow::HasContext;
use std::path::PathBuf;
use std::sync::Arc;
use umbra_geom::WeldedMesh;
use umbra_gl::{create_method, FrameParams, GlError, HeadlessContext, Renderer, SceneGpu, ShadowMethod};

/// Methods drawn as "a normal frame" before and after each failure: a stencil method and the
/// shadow-map family that fails in the texture case.
const NORMAL_METHODS: [&str; 2] = ["cpu-silhouette", "shadow-map-cube:256"];

fn out_dir() -> PathBuf {
    let dir = output_dir().join("gl_failures");
    std::fs::create_dir_all(&dir).expect("create the gl_failures output directory");
    dir
}

fn frame() -> FrameParams {
    FrameParams { capture: Default::default(), ..params(default_camera(), vec![POINT_LIGHT], 96, 72) }
}

/// Renders the normal frames with `renderer` on `ctx` (fresh method instances, a fresh upload
/// of the sphere scene) and returns their PNG files' bytes, one per [`NORMAL_METHODS`] entry.
fn normal_frames(ctx: &HeadlessContext, renderer: &mut Renderer, tag: &str) -> Vec<Vec<u8>> {
    let gl = ctx.gl();
    let scene = SceneGpu::upload(gl, sphere_over_ground()).unwrap_or_else(|e| panic!("{tag}: upload: {e}"));
    let mut pngs = Vec::new();
    for name in NORMAL_METHODS {
        let mut method = create_method(name).expect("registered method");
        let images = renderer
            .render(gl, &scene, method.as_mut(), &frame(), None)
            .unwrap_or_else(|e| panic!("{tag}: {name}: a normal frame failed: {e}"));
        method.destroy(gl);
        let path = out_dir().join(format!("{tag}-{}.png", name.replace(':', "-")));
        images.rgba.save_png(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        pngs.push(std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display())));
    }
    scene.destroy(gl);
    pngs
}

/// The same frames on a brand-new context and renderer.
fn fresh_frames(tag: &str) -> Vec<Vec<u8>> {
    let ctx = context();
    let mut renderer = Renderer::new(ctx.gl()).expect("renderer").with_error_log(ctx.error_log().cloned());
    let pngs = normal_frames(&ctx, &mut renderer, tag);
    renderer.destroy(ctx.gl());
    pngs
}

/// The frames after a failure equal the ones before it and the fresh context's, byte for byte.
fn assert_same_pngs(what: &str, before: &[Vec<u8>], after: &[Vec<u8>], fresh: &[Vec<u8>]) {
    for (i, name) in NORMAL_METHODS.iter().enumerate() {
        assert!(distinct_colours(&before[i]) > 3, "{what}: {name}: the frame is (nearly) uniform");
        assert!(after[i] == before[i], "{what}: {name}: the frame after the failure differs from the one before it");
        assert!(after[i] == fresh[i], "{what}: {name}: the frame after the failure differs from a fresh context's");
    }
}

/// Distinct RGBA colours of a PNG: the normal frame shows ground, sphere and shadow, so a
/// blank or uniform image (which any failure could produce twice) does not pass.
fn distinct_colours(png: &[u8]) -> usize {
    let mut reader = png::Decoder::new(std::io::Cursor::new(png)).read_info().expect("our own PNG decodes");
    let mut buf = vec![0; reader.output_buffer_size().expect("sized PNG")];
    let info = reader.next_frame(&mut buf).expect("one frame");
    let mut colours: Vec<&[u8]> = buf[..info.buffer_size()].chunks_exact(4).collect();
    colours.sort_unstable();
    colours.dedup();
    colours.len()
}

#[test]
fn cube_map_above_the_gl_limit_is_a_typed_error_and_the_context_stays_usable() {
    let ctx = context();
    let gl = ctx.gl();
    // SAFETY: integer queries on the current context.
    let (max_cube, max_2d) = unsafe {
        (gl.get_parameter_i32(glow::MAX_CUBE_MAP_TEXTURE_SIZE), gl.get_parameter_i32(glow::MAX_TEXTURE_SIZE))
    };
    println!("GL_MAX_CUBE_MAP_TEXTURE_SIZE = {max_cube}, GL_MAX_TEXTURE_SIZE = {max_2d} on {}", ctx.renderer_string());
    let mut renderer = Renderer::new(gl).expect("renderer").with_error_log(ctx.error_log().cloned());
    let before = normal_frames(&ctx, &mut renderer, "limit-before");
    let scene = SceneGpu::upload(gl, sphere_over_ground()).expect("upload");
    let name = format!("shadow-map-cube:{}", max_cube as u32 + 1);
    let mut too_big = create_method(&name).expect("any positive RES parses");
    match renderer.render(gl, &scene, too_big.as_mut(), &frame(), None) {
        Err(GlError::Unsupported { method, reason }) => {
            println!("{name}: {reason}");
            assert_eq!(method, name);
            assert!(
                reason.contains("GL_MAX_CUBE_MAP_TEXTURE_SIZE") && reason.contains(&max_cube.to_string()),
                "{reason}"
            );
        }
        other => panic!("{name}: expected Unsupported, got {:?}", other.map(|_| ())),
    }
    // The refusal comes before any allocation (the size is checked against the limit), so the
    // method holds nothing; resident memory is not asserted (an instantaneous figure).
    assert_eq!(too_big.gpu_bytes(), 0, "nothing allocated");
    // the failed method itself fails the same way again (it is not left half-prepared)
    assert!(matches!(renderer.render(gl, &scene, too_big.as_mut(), &frame(), None), Err(GlError::Unsupported { .. })));
    too_big.destroy(gl);
    scene.destroy(gl);
    assert!(ctx.take_gl_errors().is_empty(), "the failure left GL errors behind");
    let after = normal_frames(&ctx, &mut renderer, "limit-after");
    renderer.destroy(gl);
    assert_same_pngs("above GL_MAX_CUBE_MAP_TEXTURE_SIZE", &before, &after, &fresh_frames("limit-fresh"));
}

/// Address space granted above the current size while the driver is asked to allocate.
const HEADROOM: u64 = 256 << 20;

/// Runs `f` with the process's address space limited to its current size + [`HEADROOM`], then
/// restores the previous limit. Only ever called in a child process (see the module doc).
fn with_address_space_limit<T>(f: impl FnOnce() -> T) -> T {
    with_address_space_headroom(HEADROOM, f)
}

/// The sphere scene plus `extra` unused vertices at the origin: a position buffer of
/// 12 x (vertices + extra) bytes. `vec![[0.0; 3]; n]` is `calloc`ed: the pages stay
/// untouched (not resident) until written.
fn scene_with_unused_vertices(extra: usize) -> Arc<WeldedMesh> {
    let base = sphere_over_ground();
    let mut positions = vec![[0f32; 3]; base.positions.len() + extra];
    positions[..base.positions.len()].copy_from_slice(&base.positions);
    Arc::new(WeldedMesh {
        positions,
        triangles: base.triangles.clone(),
        source_triangle: base.source_triangle.clone(),
        degenerate_triangles: base.degenerate_triangles,
    })
}

/// The sphere scene after `extra` unused vertices at the origin (its triangles' indices
/// shifted by `extra`): what is sized by the highest index used, such as ts-silhouette's
/// extended vertex buffer, covers the unused vertices too. `calloc`ed as above.
fn scene_after_unused_vertices(extra: usize) -> Arc<WeldedMesh> {
    let base = sphere_over_ground();
    let mut positions = vec![[0f32; 3]; extra + base.positions.len()];
    positions[extra..].copy_from_slice(&base.positions);
    let shift = u32::try_from(extra).expect("extra fits u32 indices");
    Arc::new(WeldedMesh {
        positions,
        triangles: base.triangles.iter().map(|t| t.map(|i| i + shift)).collect(),
        source_triangle: base.source_triangle.clone(),
        degenerate_triangles: base.degenerate_triangles,
    })
}

#[test]
fn storage_the_driver_refuses_is_out_of_memory_and_the_context_stays_usable() {
    run_in_child("child_out_of_memory");
}

#[test]
#[ignore = "helper: run in a child process by storage_the_driver_refuses_is_out_of_memory_and_the_context_stays_usable"]
fn child_out_of_memory() {
    if !is_child("child_out_of_memory") {
        return;
    }
    let ctx = context();
    let gl = ctx.gl();
    println!("{} {}", ctx.renderer_string(), ctx.version_string());
    let mut renderer = Renderer::new(gl).expect("renderer").with_error_log(ctx.error_log().cloned());
    let before = normal_frames(&ctx, &mut renderer, "oom-before");

    // 1. a buffer: the scene's 480 MB position buffer
    let extra = 40_000_000;
    let big = scene_with_unused_vertices(extra);
    let position_bytes = 12 * big.positions.len();
    let rss = status_kib("VmRSS");
    let result = with_address_space_limit(|| SceneGpu::upload(gl, big.clone()));
    let grown = status_kib("VmRSS").saturating_sub(rss);
    match result {
        Err(GlError::OutOfMemory { what, bytes, messages }) => {
            println!(
                "scene upload: {}",
                GlError::OutOfMemory { what: what.clone(), bytes, messages: messages.clone() }
            );
            assert!(what.contains("position buffer"), "{what}");
            assert_eq!(bytes, position_bytes);
            assert!(messages.iter().any(|m| m.contains("GL_OUT_OF_MEMORY")), "{messages:?}");
        }
        Err(e) => panic!("scene upload: expected OutOfMemory, got {e}"),
        Ok(_) => panic!("a {position_bytes}-byte buffer was allocated within a {HEADROOM}-byte address-space headroom"),
    }
    // Printed, not asserted (an instantaneous figure): the address-space limit already
    // guarantees that no 480 MB store exists.
    println!("resident memory grew by {grown} KiB during the refused upload");
    assert!(ctx.take_gl_errors().is_empty(), "the failed upload left GL errors behind (the next frame would fail)");
    drop(big);
    let after_buffer = normal_frames(&ctx, &mut renderer, "oom-after-buffer");

    // 2. a texture: a cube map the driver accepts by size (= GL_MAX_CUBE_MAP_TEXTURE_SIZE)
    // but refuses to allocate; the limit keeps a driver that would allocate from doing so.
    // SAFETY: integer query on the current context.
    let max_cube = unsafe { gl.get_parameter_i32(glow::MAX_CUBE_MAP_TEXTURE_SIZE) };
    let name = format!("shadow-map-cube:{max_cube}");
    let scene = SceneGpu::upload(gl, sphere_over_ground()).expect("upload");
    let mut huge = create_method(&name).expect("method");
    let rss = status_kib("VmRSS");
    let started = std::time::Instant::now();
    let result = with_address_space_limit(|| renderer.render(gl, &scene, huge.as_mut(), &frame(), None));
    let (elapsed, grown) = (started.elapsed(), status_kib("VmRSS").saturating_sub(rss));
    match result {
        Err(GlError::OutOfMemory { what, bytes, messages }) => {
            println!("{name}: out of memory allocating {what} ({bytes} bytes): {messages:?} in {elapsed:?}");
            assert_eq!(bytes, 6 * 4 * (max_cube as usize).pow(2));
            assert!(what.contains(&name), "{what}");
        }
        Err(e) => panic!("{name}: expected OutOfMemory, got {e}"),
        Ok(_) => panic!(
            "{name}: a {} MiB cube map was allocated within the address-space headroom",
            (24 * (max_cube as u64).pow(2)) >> 20
        ),
    }
    // Printed, not asserted (an instantaneous figure): the address-space limit already
    // guarantees that no cube map of that size exists.
    println!("resident memory grew by {grown} KiB during the refused cube map");
    assert_eq!(huge.gpu_bytes(), 0);
    huge.destroy(gl);
    scene.destroy(gl);
    assert!(ctx.take_gl_errors().is_empty(), "the failed frame left GL errors behind");
    let after_texture = normal_frames(&ctx, &mut renderer, "oom-after-texture");
    renderer.destroy(gl);

    let fresh = fresh_frames("oom-fresh");
    assert_same_pngs("GL_OUT_OF_MEMORY on a buffer", &before, &after_buffer, &fresh);
    assert_same_pngs("GL_OUT_OF_MEMORY on a texture", &before, &after_texture, &fresh);
    println!("{CHILD_DONE}");
}

/// A buffer above what umbra passes to GL (2 GiB, glow's `i32` sizes): a typed error before
/// any GL call. The 2.2 GB of positions are `calloc`ed and never written: not resident.
#[test]
fn buffer_beyond_the_gl_size_limit_is_rejected_before_gl() {
    // Under strict overcommit (mode 2) a 2.2 GB calloc is charged in full and may fail (an
    // abort in Rust); the default heuristic mode hands out untouched pages for free.
    if std::fs::read_to_string("/proc/sys/vm/overcommit_memory").is_ok_and(|m| m.trim() == "2") {
        println!("skipped: vm.overcommit_memory = 2 (strict), a 2.2 GB calloc would be charged in full");
        return;
    }
    let ctx = context();
    let gl = ctx.gl();
    let extra = (i32::MAX as usize) / 12 + 1;
    let rss = status_kib("VmRSS");
    let big = scene_with_unused_vertices(extra);
    match SceneGpu::upload(gl, big) {
        Err(GlError::InvalidParams(m)) => {
            println!("scene upload: {m}");
            assert!(m.contains("position buffer") && m.contains("2 GiB"), "{m}");
        }
        Err(e) => panic!("expected InvalidParams, got {e}"),
        Ok(_) => panic!("a buffer over 2 GiB was accepted"),
    }
    // Resident memory is printed, never asserted (an instantaneous figure); the rejection
    // before any GL call is what is asserted.
    println!("resident memory grew by {} KiB", status_kib("VmRSS").saturating_sub(rss));
    assert!(ctx.take_gl_errors().is_empty(), "no GL call was made, so no GL error");
    let mut renderer = Renderer::new(gl).expect("renderer").with_error_log(ctx.error_log().cloned());
    let after = normal_frames(&ctx, &mut renderer, "size-after");
    renderer.destroy(gl);
    let fresh = fresh_frames("size-fresh");
    assert_same_pngs("buffer over 2 GiB", &after, &after, &fresh);
}

/// What the driver does with a `GLsizeiptr` near `isize::MAX` (a size umbra never passes):
/// `glNamedBufferData` called directly refuses it with `GL_OUT_OF_MEMORY` (Mesa rejects
/// buffer stores above 4 GiB before allocating), and the context keeps working.
#[test]
fn driver_refuses_a_buffer_size_near_isize_max() {
    use khronos_egl as egl;
    type NamedBufferDataFn =
        unsafe extern "system" fn(buffer: u32, size: isize, data: *const std::ffi::c_void, usage: u32);
    let ctx = context();
    let gl = ctx.gl();
    // SAFETY: loads the system libEGL, which the headless context already uses.
    let instance = unsafe { egl::DynamicInstance::<egl::EGL1_4>::load_required() }.expect("libEGL");
    let pointer = instance.get_proc_address("glNamedBufferData").expect("glNamedBufferData");
    // SAFETY: eglGetProcAddress returned exactly this GL 4.5 entry point, whose C signature
    // the type spells out.
    let named_buffer_data = unsafe { std::mem::transmute::<extern "system" fn(), NamedBufferDataFn>(pointer) };
    let rss = status_kib("VmRSS");
    // SAFETY: a buffer of this context, which is current; no data pointer (no copy).
    let errors = unsafe {
        let buffer = gl.create_named_buffer().expect("buffer");
        named_buffer_data(buffer.0.get(), isize::MAX - 4095, std::ptr::null(), glow::STATIC_DRAW);
        let errors = ctx.take_gl_errors();
        gl.delete_buffer(buffer);
        errors
    };
    println!("glNamedBufferData(isize::MAX - 4095): {errors:?}");
    assert!(errors.iter().any(|e| e.contains("GL_OUT_OF_MEMORY")), "{errors:?}");
    println!("resident memory grew by {} KiB", status_kib("VmRSS").saturating_sub(rss));
    let mut renderer = Renderer::new(gl).expect("renderer").with_error_log(ctx.error_log().cloned());
    let after = normal_frames(&ctx, &mut renderer, "isize-after");
    renderer.destroy(gl);
    let fresh = fresh_frames("isize-fresh");
    assert_same_pngs("glNamedBufferData(isize::MAX)", &after, &after, &fresh);
}

/// A render target the driver refuses: a 16384 x 16384 frame (1 GiB of RGBA8 alone) under the
/// address-space limit. `RenderTarget::new` checks `glGetError` after each
/// `glTextureStorage2D`: the render returns `OutOfMemory` naming the attachment, nothing
/// becomes resident, no GL error is left for the next frame, and the normal frames after it
/// equal the ones before it and a fresh context's.
#[test]
fn render_target_the_driver_refuses_is_out_of_memory_and_the_context_stays_usable() {
    run_in_child("child_render_target_out_of_memory");
}

#[test]
#[ignore = "helper: run in a child process by render_target_the_driver_refuses_is_out_of_memory_and_the_context_stays_usable"]
fn child_render_target_out_of_memory() {
    if !is_child("child_render_target_out_of_memory") {
        return;
    }
    let ctx = context();
    let gl = ctx.gl();
    // SAFETY: integer query on the current context.
    let max = unsafe { gl.get_parameter_i32(glow::MAX_RENDERBUFFER_SIZE) }.clamp(1, 16384) as u32;
    let mut renderer = Renderer::new(gl).expect("renderer").with_error_log(ctx.error_log().cloned());
    let before = normal_frames(&ctx, &mut renderer, "target-before");
    let scene = SceneGpu::upload(gl, sphere_over_ground()).expect("upload");
    let mut method = create_method("cpu-silhouette").expect("method");
    let huge = FrameParams { capture: Default::default(), ..params(default_camera(), vec![POINT_LIGHT], max, max) };
    let rss = status_kib("VmRSS");
    let started = std::time::Instant::now();
    let result = with_address_space_limit(|| renderer.render(gl, &scene, method.as_mut(), &huge, None).map(|_| ()));
    let (elapsed, grown) = (started.elapsed(), status_kib("VmRSS").saturating_sub(rss));
    println!("{max} x {max} frame in {elapsed:?}, resident memory grew by {grown} KiB: {result:?}");
    match result {
        Err(GlError::OutOfMemory { what, bytes, messages }) => {
            assert!(what.contains("render target") && what.contains(&format!("{max}x{max}")), "{what}");
            // the smallest attachment of this frame (RGBA8 colour or D24S8) takes 4 bytes a pixel
            assert!(bytes >= 4 * (max as usize).pow(2), "{what}: {bytes} bytes");
            assert!(messages.iter().any(|m| m.contains("GL_OUT_OF_MEMORY")), "{messages:?}");
        }
        Err(e) => panic!("{max} x {max} frame: expected OutOfMemory, got {e}"),
        Ok(()) => panic!("{max} x {max} frame: allocated within a {HEADROOM}-byte address-space headroom"),
    }
    assert!(ctx.take_gl_errors().is_empty(), "the refused render target left GL errors behind");
    // the same renderer refuses the same frame again the same way (no half-made target kept)
    let again = with_address_space_limit(|| renderer.render(gl, &scene, method.as_mut(), &huge, None).map(|_| ()));
    assert!(matches!(again, Err(GlError::OutOfMemory { .. })), "second try: {again:?}");
    assert!(ctx.take_gl_errors().is_empty(), "the second refusal left GL errors behind");
    method.destroy(gl);
    scene.destroy(gl);
    let after = normal_frames(&ctx, &mut renderer, "target-after");
    renderer.destroy(gl);
    assert_same_pngs("GL_OUT_OF_MEMORY on the render target", &before, &after, &fresh_frames("target-fresh"));
    println!("{CHILD_DONE}");
}

/// A method's own buffer the driver refuses, in `prepare`: `ts-silhouette`'s extended vertex
/// buffer (`12 · (V + K)` bytes: every welded position up to the highest one used, then the
/// count vertices) for the sphere scene after 6 M unused positions, 72 MB. The CPU builds that array itself
/// before uploading it, so the headroom (1.5 x its size) lets the CPU copy be allocated and
/// refuses llvmpipe's second copy. `prepare` returns `OutOfMemory` naming the buffer, the
/// method does not count itself prepared, no GL error is left, and the SAME method instance
/// then prepares and draws the normal scene exactly as a fresh instance on a fresh context.
#[test]
fn a_method_buffer_the_driver_refuses_fails_prepare_and_the_method_stays_usable() {
    run_in_child("child_method_buffer_out_of_memory");
}

/// PNG bytes of one frame of `method` (an existing instance) over the sphere scene.
fn method_frame(ctx: &HeadlessContext, renderer: &mut Renderer, method: &mut dyn ShadowMethod, tag: &str) -> Vec<u8> {
    let gl = ctx.gl();
    let scene = SceneGpu::upload(gl, sphere_over_ground()).unwrap_or_else(|e| panic!("{tag}: upload: {e}"));
    let images = renderer
        .render(gl, &scene, method, &frame(), None)
        .unwrap_or_else(|e| panic!("{tag}: {}: the frame failed: {e}", method.name()));
    scene.destroy(gl);
    let path = out_dir().join(format!("{tag}.png"));
    images.rgba.save_png(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

#[test]
#[ignore = "helper: run in a child process by a_method_buffer_the_driver_refuses_fails_prepare_and_the_method_stays_usable"]
fn child_method_buffer_out_of_memory() {
    if !is_child("child_method_buffer_out_of_memory") {
        return;
    }
    const NAME: &str = "ts-silhouette";
    let ctx = context();
    let gl = ctx.gl();
    let mut renderer = Renderer::new(gl).expect("renderer").with_error_log(ctx.error_log().cloned());
    let mut method = create_method(NAME).expect("method");
    // prepared once for the normal scene: programs linked, caps ready (nothing left to
    // allocate in the limited prepare but the patches)
    let before = method_frame(&ctx, &mut renderer, method.as_mut(), "method-oom-before");

    let big = SceneGpu::upload(gl, scene_after_unused_vertices(6_000_000)).expect("the big scene itself fits");
    big.adjacency(); // built outside the limit: only the patches are allocated under it
    let vertex_bytes = 12 * big.mesh().positions.len(); // + 12 K count vertices
    let headroom = (vertex_bytes + vertex_bytes / 2) as u64;
    let rss = status_kib("VmRSS");
    let result = with_address_space_headroom(headroom, || method.prepare(gl, &big));
    let grown = status_kib("VmRSS").saturating_sub(rss);
    println!("{NAME} prepare with {headroom} bytes of headroom: {result:?}; resident memory grew by {grown} KiB");
    match result {
        Err(GlError::OutOfMemory { what, bytes, messages }) => {
            assert!(what.contains("ts-silhouette vertex buffer"), "{what}");
            assert!(bytes > vertex_bytes && (bytes - vertex_bytes).is_multiple_of(12), "{bytes} bytes");
            assert!(messages.iter().any(|m| m.contains("GL_OUT_OF_MEMORY")), "{messages:?}");
        }
        Err(e) => panic!("{NAME} prepare: expected OutOfMemory, got {e}"),
        Ok(()) => panic!("{NAME} prepare: a second {vertex_bytes}-byte copy fit in {headroom} bytes of headroom"),
    }
    assert_eq!(method.prepared_scene(), None, "the failed prepare counts as prepared");
    assert!(ctx.take_gl_errors().is_empty(), "the failed prepare left GL errors behind");
    big.destroy(gl);

    let after = method_frame(&ctx, &mut renderer, method.as_mut(), "method-oom-after");
    method.destroy(gl);
    renderer.destroy(gl);
    let fresh_ctx = context();
    let mut fresh_renderer =
        Renderer::new(fresh_ctx.gl()).expect("renderer").with_error_log(fresh_ctx.error_log().cloned());
    let mut fresh_method = create_method(NAME).expect("method");
    let fresh = method_frame(&fresh_ctx, &mut fresh_renderer, fresh_method.as_mut(), "method-oom-fresh");
    fresh_method.destroy(fresh_ctx.gl());
    fresh_renderer.destroy(fresh_ctx.gl());
    assert!(distinct_colours(&before) > 3, "{NAME}: the frame is (nearly) uniform");
    assert!(after == before, "{NAME}: the frame after the failed prepare differs from the one before it");
    assert!(after == fresh, "{NAME}: the frame after the failed prepare differs from a fresh context's");
    println!("{CHILD_DONE}");
}
