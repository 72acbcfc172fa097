//! Debug probe: what does the shadow ray of one pixel hit?
use umbra_oracle::synthetic::{primary_samples, PinholeCamera};
use umbra_oracle::Bvh;
fn main() {
    let mesh = umbra_geom::load::load_path(std::path::Path::new("/work/shared/scenes/crytek-sponza.obj.gz")).unwrap();
    let w = umbra_geom::weld::weld(&mesh);
    let bvh = Bvh::build(&w.positions, &w.triangles).unwrap();
    for target in [[6.1f64, 2.1, 1.0], [6.1, 0.5, 0.2], [8.5, 1.5, 0.0]] {
        let o = [-2.0f64, 1.0, 0.0];
        let d = [target[0] - o[0], target[1] - o[1], target[2] - o[2]];
        let h = bvh.intersect(o, d, 0.0, f64::INFINITY).unwrap();
        println!("towards {target:?}: t {} point {:?} tri {}", h.t, [0, 1, 2].map(|k| o[k] + h.t * d[k]), h.triangle);
    }
    let cam = PinholeCamera { eye: [0.0, 3.0, 0.0], target: [10.0, 3.0, 0.4], up: [0.0, 1.0, 0.0], fov_y: 1.047, width: 640, height: 360 };
    let (pos, tri) = primary_samples(&bvh, &cam);
    for (x, y) in [(320usize, 350usize), (320, 300), (100, 200)] {
        let i = y * 640 + x;
        let p = pos[i];
        let d = [0.3f64, 1.0, 0.2];
        let o = p.map(|c| c as f64);
        let h = bvh.intersect(o, d, 1e-4, f64::INFINITY);
        println!("pixel ({x},{y}) pos {p:?} tri {} {:?}", tri[i], w.triangles[tri[i] as usize].map(|k| w.positions[k as usize]));
        if let Some(h) = h {
            println!("   hit t {} tri {} {:?}", h.t, h.triangle, w.triangles[h.triangle as usize].map(|k| w.positions[k as usize]));
        }
    }
}
