//! The shadow reference on analytic scenes whose shadows can be computed by hand: the
//! scenes and helpers shared by the modules, one module per concept the tests pin (the
//! shadow classes, the envelope's size, and each band part).

mod band_cancelling;
mod band_light;
mod band_near_cut;
mod band_side_face;
mod band_surface;
mod envelope;
mod shadows;

use umbra_geom::WeldedMesh;
use umbra_oracle::{reference, Bvh, Reference, SampleClass, Samples};

const BG: u32 = u32::MAX;

struct Scene {
    positions: Vec<[f32; 3]>,
    triangles: Vec<[u32; 3]>,
}

impl Scene {
    fn new() -> Scene {
        Scene { positions: Vec::new(), triangles: Vec::new() }
    }
    fn add(&mut self, p: [[f32; 3]; 3]) -> u32 {
        // Shared positions are given the same index (a welded mesh).
        let mut idx = [0u32; 3];
        for (k, v) in p.iter().enumerate() {
            idx[k] = match self.positions.iter().position(|q| q == v) {
                Some(i) => i as u32,
                None => {
                    self.positions.push(*v);
                    self.positions.len() as u32 - 1
                }
            };
        }
        self.triangles.push(idx);
        self.triangles.len() as u32 - 1
    }
    /// Ground: the square [-3,3]^2 at y = 0 as a 6x6 grid of unit cells, each split into two
    /// triangles along the diagonal from (x1, z0) to (x0, z1), normal +y. Triangle ids 0..72.
    fn with_ground() -> Scene {
        let mut s = Scene::new();
        for j in 0..6 {
            for i in 0..6 {
                let (x0, z0) = (i as f32 - 3.0, j as f32 - 3.0);
                let (x1, z1) = (x0 + 1.0, z0 + 1.0);
                s.add([[x0, 0.0, z0], [x0, 0.0, z1], [x1, 0.0, z0]]);
                s.add([[x1, 0.0, z0], [x0, 0.0, z1], [x1, 0.0, z1]]);
            }
        }
        s
    }
    /// Id of the ground triangle containing (x, z) (points on the diagonal go to the first).
    fn ground_triangle(x: f32, z: f32) -> u32 {
        let i = ((x + 3.0).floor() as i32).clamp(0, 5) as u32;
        let j = ((z + 3.0).floor() as i32).clamp(0, 5) as u32;
        let (fx, fz) = (x + 3.0 - i as f32, z + 3.0 - j as f32);
        2 * (j * 6 + i) + if fx + fz <= 1.0 { 0 } else { 1 }
    }
    /// The square [-1,1]^2 at height y, two triangles, wound either way.
    fn add_square_occluder(&mut self, y: f32, flip: bool) {
        let mut q = [[-1.0, y, -1.0], [1.0, y, -1.0], [1.0, y, 1.0], [-1.0, y, 1.0]];
        if flip {
            q.reverse();
        }
        self.add([q[0], q[1], q[2]]);
        self.add([q[0], q[2], q[3]]);
    }
    fn mesh(&self) -> WeldedMesh {
        WeldedMesh {
            positions: self.positions.clone(),
            triangles: self.triangles.clone(),
            source_triangle: (0..self.triangles.len() as u32).collect(),
            degenerate_triangles: 0,
        }
    }
}

/// A 60x60 image of ground samples: pixel (px, py) is the point (x, 0, z) with
/// x = -3 + 0.1 (px + 0.5), z = -3 + 0.1 (py + 0.5) (top row = smallest z).
fn ground_samples() -> (Vec<[f32; 3]>, Vec<u32>) {
    let mut pos = Vec::new();
    let mut tri = Vec::new();
    for py in 0..60 {
        for px in 0..60 {
            let (x, z) = (-3.0 + 0.1 * (px as f32 + 0.5), -3.0 + 0.1 * (py as f32 + 0.5));
            pos.push([x, 0.0, z]);
            tri.push(Scene::ground_triangle(x, z));
        }
    }
    (pos, tri)
}

fn run(scene: &Scene, pos: &[[f32; 3]], tri: &[u32], w: u32, h: u32, light: [f32; 4], eye: [f32; 3]) -> Reference {
    let mesh = scene.mesh();
    let bvh = Bvh::build(&mesh.positions, &mesh.triangles).unwrap();
    let samples = Samples { width: w, height: h, world_pos: pos, triangle: tri };
    reference(&mesh, &bvh, &samples, light, eye).unwrap()
}

fn count(class: &[SampleClass], c: SampleClass) -> usize {
    class.iter().filter(|&&k| k == c).count()
}

/// One ground sample at (x, 0, z) under the square occluder at y = 1, point light (0, 10, 0):
/// (class, band for a silhouette method) of a 1x1 image.
fn single_sample_under_square(x: f32, z: f32) -> (SampleClass, bool) {
    let mut scene = Scene::with_ground();
    scene.add_square_occluder(1.0, false);
    let r = run(&scene, &[[x, 0.0, z]], &[Scene::ground_triangle(x, z)], 1, 1, [0.0, 10.0, 0.0, 1.0], [0.0, 20.0, 5.0]);
    (r.class[0], r.parts[0].intersects(umbra_oracle::BandParts::SILHOUETTE))
}

/// GL's perspective with an infinite far plane (standard depth convention, NEGATIVE_ONE_TO_ONE)
/// looking from `eye` at `target` (up +y), column-major clip_from_world.
fn clip_from_world_looking(eye: [f64; 3], target: [f64; 3], fovy_degrees: f64, aspect: f64, near: f64) -> [f64; 16] {
    let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let cross =
        |a: [f64; 3], b: [f64; 3]| [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
    let unit = |a: [f64; 3]| {
        let l = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
        a.map(|c| c / l)
    };
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let f = unit(sub(target, eye));
    let r = unit(cross(f, [0.0, 1.0, 0.0]));
    let u = cross(r, f);
    // view_from_world rows: r, u, -f; translation -R eye.
    let view = [r, u, f.map(|c| -c)];
    let t = [-dot(r, eye), -dot(u, eye), dot(f, eye)];
    let g = 1.0 / (fovy_degrees.to_radians() / 2.0).tan();
    // clip rows: x = g/aspect * xv, y = g * yv, z = -zv - 2 near, w = -zv.
    let mut m = [0.0; 16];
    for col in 0..4 {
        let v = |row: usize| if col < 3 { view[row][col] } else { t[row] };
        m[col * 4] = g / aspect * v(0);
        m[col * 4 + 1] = g * v(1);
        m[col * 4 + 2] = -v(2) - if col == 3 { 2.0 * near } else { 0.0 };
        m[col * 4 + 3] = -v(2);
    }
    m
}
