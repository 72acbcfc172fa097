//! The headless example runs as its users run it (the function its `main` calls) and its PNG
//! is checked: the size asked for, a ground pixel under the sphere in shadow of the point
//! light, one far from it lit.

mod common;
#[path = "../examples/wgpu_headless.rs"]
mod headless;

#[test]
fn headless_example_writes_the_png() {
    let Some(_gpu) = common::gpu() else { return };
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("umbra-wgpu-examples");
    std::fs::create_dir_all(&dir).expect("output directory");
    let out = dir.join("headless-wgpu.png");
    let params = headless::render_png(&out, "cs-silhouette").expect("the example runs");
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&out).expect("written")));
    let mut reader = decoder.read_info().expect("a PNG");
    let mut buf = vec![0; reader.output_buffer_size().expect("size")];
    let info = reader.next_frame(&mut buf).expect("pixels");
    assert_eq!((info.width, info.height), (params.width, params.height));
    let brightness = |p: [f64; 3]| {
        let q = params.camera.project(p, params.width, params.height).expect("in view");
        let i = 4 * (q[1] as usize * params.width as usize + q[0] as usize);
        buf[i] as u32 + buf[i + 1] as u32 + buf[i + 2] as u32
    };
    // The point light at (1, 6, 0.5) over the sphere at (0, 2, 0): the ground at about
    // (-0.3, 0, -0.12) is in its shadow; (2, 0, 3) is lit by both lights.
    let (shadowed, lit) = (brightness([-0.3, 0.0, -0.12]), brightness([2.0, 0.0, 3.0]));
    assert!(lit > shadowed + 60, "lit {lit} vs shadowed {shadowed}");
}
