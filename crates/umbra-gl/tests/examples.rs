//! The library examples (examples/headless.rs, examples/host_renderer.rs) run as their users
//! run them — the same functions their `main` calls — and their output checked: a pixel that
//! must be lit is, a pixel that must be in shadow is, and the shadow mask a host renderer gets
//! from umbra's stencil equals umbra's own frame outside the one-pixel boundary band.

#[path = "../examples/headless.rs"]
mod headless;
#[path = "../examples/host_renderer.rs"]
mod host_renderer;

use umbra_gl::{
    create_method, Camera, ContextOptions, GlApi, HeadlessContext, Image, LightCapture, Renderer, SceneGpu,
};

fn context() -> HeadlessContext {
    match HeadlessContext::with_options(ContextOptions { api: GlApi::Gl45Core, debug: true }) {
        Ok(c) => c,
        Err(e) => panic!("no headless GL 4.5 context: {e}"),
    }
}

/// Pixel (x from the left, y from the top) showing world point `p`.
fn pixel(camera: &Camera, p: [f64; 3], w: u32, h: u32) -> (u32, u32) {
    let s = camera.project(p, w, h).expect("point in front of the camera");
    assert!(
        s[0] >= 0.0 && s[1] >= 0.0 && s[0] < w as f64 && s[1] < h as f64,
        "{p:?} projects outside the image: {s:?}"
    );
    (s[0] as u32, s[1] as u32)
}

fn output_path(name: &str) -> std::path::PathBuf {
    let dir = std::env::var_os("UMBRA_TEST_OUTPUT")
        .map(std::path::PathBuf::from)
        .unwrap_or_else(|| std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("test-output"));
    std::fs::create_dir_all(&dir).expect("output directory");
    dir.join(name)
}

fn read_png(path: &std::path::Path) -> Image<[u8; 4]> {
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(path).expect("open png")));
    let mut reader = decoder.read_info().expect("png header");
    let mut buf = vec![0; reader.output_buffer_size().expect("size")];
    let info = reader.next_frame(&mut buf).expect("png frame");
    assert_eq!(info.color_type, png::ColorType::Rgba, "RGBA PNG");
    let pixels = buf[..info.buffer_size()].chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]).collect();
    Image { width: info.width, height: info.height, pixels }
}

#[test]
fn headless_example_writes_a_png_with_a_shadow_under_the_sphere() {
    let out = output_path("example-headless.png");
    let _ = std::fs::remove_file(&out);
    let p = headless::render_png(&out).expect("headless example");
    let img = read_png(&out);
    assert_eq!((img.width, img.height), (p.width, p.height));
    // The point light at (1, 6, 0.5) casts the sphere (centre (0, 2, 0)) onto the ground
    // around light + 1.5 * (centre - light) = (-0.5, 0, -0.25); (3, 0, 3) sees the light.
    let ambient = (p.albedo[0] * p.ambient * 255.0).round() as u8;
    let (sx, sy) = pixel(&p.camera, [-0.5, 0.0, -0.25], p.width, p.height);
    let (lx, ly) = pixel(&p.camera, [3.0, 0.0, 3.0], p.width, p.height);
    let shadow = img.get(sx, sy).expect("in image");
    let lit = img.get(lx, ly).expect("in image");
    assert!(shadow[..3].iter().all(|&c| c.abs_diff(ambient) <= 1), "shadowed ground is ambient {ambient}: {shadow:?}");
    assert!(lit[..3].iter().all(|&c| c > ambient + 40), "lit ground is well above ambient {ambient}: {lit:?}");
}

/// Pixels whose 3x3 neighbourhood in `bits` is not uniform: the one-pixel boundary band.
fn band(bits: &Image<u8>) -> Vec<bool> {
    let (w, h) = (bits.width as i64, bits.height as i64);
    let at = |x: i64, y: i64| bits.pixels[(y.clamp(0, h - 1) * w + x.clamp(0, w - 1)) as usize];
    (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| (-1..=1).any(|dy| (-1..=1).any(|dx| at(x + dx, y + dy) != at(x, y))))
        .collect()
}

#[test]
fn host_renderer_gets_umbras_exact_shadows_for_two_lights() {
    let ctx = context();
    let gl = ctx.gl();
    for method_name in ["cpu-silhouette", "vs-silhouette", "shadow-map-cube:1024"] {
        let host = host_renderer::draw_host_frame(gl, method_name).expect("host frame");
        let p = &host.params;
        assert_eq!(p.lights.len(), 2);
        assert_eq!((p.lights[0][3], p.lights[1][3]), (1.0, 0.0), "one point light, one directional");
        host.rgba.save_png(&output_path(&format!("example-host-{method_name}.png"))).expect("png");

        // Known pixels: the sphere's shadow from the point light (1.5, 6, 0.5) around
        // (-0.75, 0, -0.25), from the directional light (-0.4, 1, 0.3) around (0.8, 0, -0.6);
        // (3, 0, 3) sees both lights.
        let bits_at = |q: [f64; 3]| {
            let (x, y) = pixel(&p.camera, q, p.width, p.height);
            (host.lit_bits.get(x, y).expect("in image"), host.rgba.get(x, y).expect("in image"))
        };
        let (b_point_shadow, c_point_shadow) = bits_at([-0.75, 0.0, -0.25]);
        let (b_dir_shadow, c_dir_shadow) = bits_at([0.8, 0.0, -0.6]);
        let (b_both, c_both) = bits_at([3.0, 0.0, 3.0]);
        assert_eq!(b_point_shadow, 0b10, "{method_name}: in the point light's shadow, lit by the directional one");
        assert_eq!(b_dir_shadow, 0b01, "{method_name}: in the directional light's shadow, lit by the point one");
        assert_eq!(b_both, 0b11, "{method_name}: lit by both");
        let ambient = (p.albedo[0] * p.ambient * 255.0).round() as u8;
        for (what, c) in [("point shadow", c_point_shadow), ("directional shadow", c_dir_shadow)] {
            assert!(
                c[0] > ambient + 20 && c[0] + 20 < c_both[0],
                "{method_name}: {what} {c:?} between ambient and {c_both:?}"
            );
        }

        // umbra's own frame of the same view: its per-light lit masks (its final decision).
        let scene = SceneGpu::upload(gl, host_renderer::host_scene()).expect("upload");
        let mut renderer = Renderer::new(gl).expect("renderer").with_error_log(ctx.error_log().cloned());
        let mut method = create_method(method_name).expect("method");
        let mut own = p.clone();
        own.capture.lit_mask = LightCapture::AllLights;
        let frame = renderer.render(gl, &scene, method.as_mut(), &own, None).expect("umbra's own frame");
        let mut bits = Image::new(p.width, p.height, 0u8);
        for m in &frame.lit_masks {
            for (b, &l) in bits.pixels.iter_mut().zip(&m.image.pixels) {
                *b |= u8::from(l != 0) << m.light;
            }
        }
        let band = band(&bits);
        let (mut outside, mut inside, mut counts) = (0, 0, [[0usize; 2]; 2]);
        for ((&mine, &theirs), &in_band) in bits.pixels.iter().zip(&host.lit_bits.pixels).zip(&band) {
            match (mine == theirs, in_band) {
                (false, false) => outside += 1,
                (false, true) => inside += 1,
                _ => {}
            }
            for (light, c) in counts.iter_mut().enumerate() {
                c[usize::from(mine >> light & 1)] += 1;
            }
        }
        println!("{method_name}: host vs umbra lit bits differ at {outside} pixels outside the band, {inside} inside");
        assert_eq!(outside, 0, "{method_name}: host's shadow mask differs from umbra's own frame outside the band");
        for (light, c) in counts.iter().enumerate() {
            assert!(c[0] > 5000 && c[1] > 5000, "{method_name}: light {light} has both lit and unlit pixels: {c:?}");
        }
        method.destroy(gl);
        renderer.destroy(gl);
        scene.destroy(gl);
    }
    assert!(ctx.take_gl_errors().is_empty(), "no GL errors");
}
