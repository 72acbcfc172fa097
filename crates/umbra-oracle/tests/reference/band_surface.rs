//! The SURFACE band part: a sample within the envelope of a surface that casts, at a crease
//! or on a wall seen at a grazing angle.

use crate::{clip_from_world_looking, run, Scene, BG};
use umbra_oracle::{Bvh, SampleClass, Samples};

#[test]
fn crease_within_the_envelope_is_surface_band() {
    use umbra_oracle::BandParts;
    // A wall x = 0 standing on the ground; the light on the -x side, so ground samples at
    // x < 0 are lit. A sample 1e-6 from the crease (within 2^-20 of ~7 units, 7e-6) could be
    // seen on either surface by the depth pass, and the wall's light cap pushed to the far
    // plane assumes it hides what lies behind it: SURFACE. 1e-3 away it is plain.
    let band_at = |x: f32| {
        let mut scene = Scene::with_ground();
        let wall = [[0.0, 0.0, -3.0], [0.0, 0.0, 3.0], [0.0, 3.0, 3.0], [0.0, 3.0, -3.0]];
        scene.add([wall[0], wall[1], wall[2]]);
        scene.add([wall[0], wall[2], wall[3]]);
        let r = run(
            &scene,
            &[[x, 0.0, 0.3]],
            &[Scene::ground_triangle(x, 0.3)],
            1,
            1,
            [-1.0, 1.0, 0.0, 0.0],
            [-5.0, 5.0, 0.0],
        );
        (r.class[0], r.parts[0])
    };
    let (class, parts) = band_at(-1e-6);
    assert_eq!(class, SampleClass::Lit);
    assert!(parts.contains(BandParts::SURFACE), "{:?}", parts.names());
    let (class, parts) = band_at(-1e-3);
    assert_eq!((class, parts.intersects(BandParts::SURFACE)), (SampleClass::Lit, false), "{:?}", parts.names());
}

#[test]
fn sample_on_a_wall_seen_at_a_grazing_angle_has_a_stretched_envelope() {
    use umbra_oracle::{reference_in_view, BandParts, RasterView};
    // Crytek Sponza, torture pose 2 at 240 x 180 (eye 0.0099 outside a wall): pixel (116, 56)
    // holds a sample of a wall (triangle 63483, plane z = -1.5635) seen at ~6 degrees, 0.0007
    // pixel from the wall's edge x = -6.1289 on the screen but, along the wall, 4.7e-4 units
    // beyond it: inside the corner, where the perpendicular wall (triangle 63681, x = -6.1289)
    // shadows it. The rasterizer's snapping of the wall alone moves a sample that far: band. A
    // round envelope (lateral bound times the pixel's footprint, 4.6e-4 here) missed it by 2 %.
    let wall = [[-5.984375f32, 3.251953, -1.563476], [-6.128906, 3.251953, -1.563476], [-6.128906, 4.125, -1.563476]];
    let corner = [[-6.128906f32, 4.125, -1.563476], [-6.128906, 3.251953, -1.563476], [-6.128906, 3.251953, -1.419922]];
    let mut scene = Scene::new();
    let t = scene.add(wall);
    scene.add(corner);
    let mesh = scene.mesh();
    let bvh = Bvh::build(&mesh.positions, &mesh.triangles).unwrap();
    let eye = [5.431641f32, 4.555811, -0.2421875];
    let mut clip_from_world = clip_from_world_looking(
        eye.map(f64::from),
        [-5.0273436, 1.1539064, -1.671875],
        60.0,
        240.0 / 180.0,
        0.028966757,
    );
    // Reversed-Z with a float buffer, as rendered: clip z = near, window depth near / d.
    (clip_from_world[2], clip_from_world[6], clip_from_world[10], clip_from_world[14]) = (0.0, 0.0, 0.0, 0.028966757);
    let mut view = RasterView::new(clip_from_world);
    view.subpixel_bits = 8;
    let (w, h) = (240u32, 180u32);
    let (px, py) = (116usize, 56usize);
    let mut pos = vec![[0.0f32; 3]; (w * h) as usize];
    let mut tri = vec![BG; (w * h) as usize];
    pos[py * w as usize + px] = [-6.129376, 3.387719, -1.5634769];
    tri[py * w as usize + px] = t;
    let samples = Samples { width: w, height: h, world_pos: &pos, triangle: &tri };
    let r =
        reference_in_view(&mesh, &bvh, &samples, [-0.37890625, 4.0698245, -0.2421875, 1.0], eye, Some(&view)).unwrap();
    let i = py * w as usize + px;
    assert_eq!(r.class[i], SampleClass::Shadowed);
    assert!(r.parts[i].contains(BandParts::SURFACE), "{:?}", r.parts[i].names());
}
