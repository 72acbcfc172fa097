//! Renders the synthetic reference of a scene to PNG for eyeballing:
//! `cargo run --release -p umbra-oracle --example oracle_view -- SCENE OUT.png ex ey ez tx ty tz lx ly lz lw`
//! Lit samples light, shadowed ones dark (both shaded by a fixed head-light-ish normal term), band samples red, background black.

use std::path::PathBuf;

use umbra_oracle::synthetic::{primary_samples, PinholeCamera};
use umbra_oracle::{reference, Bvh, SampleClass, Samples};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() != 12 {
        return Err("usage: oracle_view SCENE OUT.png ex ey ez tx ty tz lx ly lz lw".into());
    }
    let nums: Vec<f32> = args[2..].iter().map(|a| a.parse::<f32>()).collect::<Result<_, _>>()?;
    let mesh = umbra_geom::load::load_path(&PathBuf::from(&args[0]))?;
    let welded = umbra_geom::weld::weld(&mesh);
    let bvh = Bvh::build(&welded.positions, &welded.triangles)?;
    let camera = PinholeCamera {
        eye: [nums[0], nums[1], nums[2]],
        target: [nums[3], nums[4], nums[5]],
        up: [0.0, 1.0, 0.0],
        fov_y: 60f32.to_radians(),
        width: 640,
        height: 360,
    };
    let (pos, tri) = primary_samples(&bvh, &camera);
    let samples = Samples { width: camera.width, height: camera.height, world_pos: &pos, triangle: &tri };
    let light = [nums[6], nums[7], nums[8], nums[9]];
    let r = reference(&welded, &bvh, &samples, light, camera.eye)?;
    let mut rgba = Vec::with_capacity(pos.len() * 4);
    for (i, &t) in tri.iter().enumerate() {
        let shade = if t == u32::MAX {
            0.0
        } else {
            let [a, b, c] = welded.triangles[t as usize].map(|k| welded.positions[k as usize]);
            let e1 = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
            let e2 = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
            let n = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]];
            let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt().max(1e-30);
            0.4 + 0.6 * ((n[0] * 0.3 + n[1] * 0.8 + n[2] * 0.5) / l).abs()
        };
        let s = |c: [u8; 3]| c.map(|x| (x as f32 * shade) as u8);
        let c = match (r.class[i], r.band[i]) {
            (SampleClass::Background, _) => [0, 0, 0],
            (_, true) => [255, 0, 0],
            (SampleClass::Lit, _) => s([255, 240, 200]),
            (SampleClass::Shadowed, _) => s([70, 70, 110]),
        };
        rgba.extend_from_slice(&[c[0], c[1], c[2], 255]);
    }
    let file = std::fs::File::create(&args[1])?;
    let mut enc = png::Encoder::new(std::io::BufWriter::new(file), camera.width, camera.height);
    enc.set_color(png::ColorType::Rgba);
    enc.set_depth(png::BitDepth::Eight);
    enc.write_header()?.write_image_data(&rgba)?;
    Ok(())
}
