//! ray-bvh (one shadow ray per sample through a BVH, compute shaders) against the ray-traced
//! reference, on the cases its design must get right, the cases of hier-triangle's test (the
//! same rule, decided another way):
//! * its eps is the reference's (`segment_epsilon`, computed in each crate);
//! * a light inside geometry (a closed room, the light and a caster inside it);
//! * samples exactly on a face plane: a box resting on the floor (its bottom face coplanar with
//!   the floor, its side planes through floor samples), a triangle lying in the floor's plane
//!   over it, and the floor split into coplanar triangles — point and directional lights;
//! * the three shared scenes' default views (the CLI's default camera and light,
//!   crates/umbra-cli/src/config.rs), small; skipped with a message when the scenes are absent.
//!   The big grid (640x360 to 2560x1440, fly-through keyframes) is scripts/exactness_grid.py;
//! * the same with walks cut into passes of 2 steps (every walk parked and resumed hundreds of
//!   times): still exact.
//!
//! Every case demands both classes in the reference (1 % at least) so that it tests something.

mod common;

use common::{for_each_shared_scene_default_view, rotate, verify_exact};
use umbra_geom::scene::{cuboid, ground_plane};
use umbra_geom::{Light, Mesh};
use umbra_gl::methods::ray_bvh::RayBvhMethod;
use umbra_gl::Camera;

/// Verifies ray-bvh (walks of at most `budget` steps a pass) on `mesh` seen by `camera` with
/// `lights` at `w x h`: 0 samples outside the band, both classes present. Returns (samples,
/// shadowed).
fn verify_budget(
    name: &str,
    mesh: &Mesh,
    camera: Camera,
    lights: Vec<Light>,
    w: u32,
    h: u32,
    budget: u32,
) -> (usize, usize) {
    verify_exact(name, mesh, camera, lights, (w, h), &mut RayBvhMethod::with_budget(budget))
}

fn verify(name: &str, mesh: &Mesh, camera: Camera, lights: Vec<Light>, w: u32, h: u32) -> (usize, usize) {
    verify_budget(name, mesh, camera, lights, w, h, umbra_gl::methods::ray_bvh::DEFAULT_BUDGET)
}

#[test]
fn its_eps_is_the_references() {
    let sets: Vec<Vec<[f32; 3]>> = vec![
        vec![],
        vec![[1.0, 2.0, 3.0]],
        vec![[-3.0, 0.5, 2.0], [4.0, -1.0, 0.25], [0.0, 7.0, -2.0]],
        vec![[1e5, 1e5, 1e5], [1e5 + 1.0, 1e5, 1e5 - 2.0]],
        vec![[f32::NAN, 0.0, 0.0], [1.0, 1.0, 1.0], [f32::INFINITY, 2.0, 2.0], [2.0, 3.0, 0.0]],
        vec![[1e-20, -1e-20, 0.0], [3e-20, 0.0, 1e-20]],
    ];
    for p in sets {
        let ours = umbra_geom::ray_bvh::segment_epsilon(&p);
        let reference = umbra_oracle::segment_epsilon(&p);
        assert_eq!(ours.to_bits(), reference.to_bits(), "{p:?}: {ours} vs {reference}");
    }
}

/// A closed room (a cuboid seen from inside, the camera inside too) with the light and a box
/// inside: the box shadows the floor and walls, the walls shadow nothing they enclose.
#[test]
fn light_inside_geometry() {
    let mut m = cuboid([0.0, 2.5, 0.0], [4.0, 2.5, 4.0]);
    m.append(&cuboid([0.0, 0.75, 0.0], [0.5, 0.75, 0.5]));
    let camera = Camera { eye: [3.2, 4.2, 3.5], target: [0.0, 0.5, 0.0], near: 0.01, ..Camera::default() };
    verify("light inside a closed room", &m, camera, vec![[-1.0, 3.0, 0.7, 1.0]], 200, 150);
}

/// Samples exactly on face planes: the box's bottom lies in the floor's plane, its side faces'
/// planes cut the floor along its foot, a triangle and a second floor patch lie in the floor's
/// plane over parts of it, and the floor itself is split into coplanar triangles. The whole
/// scene is turned about an oblique axis, so that the rasterized positions scatter by rounding
/// on both sides of the planes. Coplanar surfaces meet a sample's segment only at t ~ 0: they
/// must not shadow it (the reference's eps; without it this test fails).
#[test]
fn samples_exactly_on_a_face_plane() {
    let mut m = ground_plane([0.0, 0.0, 0.0], 6.0);
    m.append(&ground_plane([1.5, 0.0, 1.0], 2.0));
    m.append(&cuboid([-0.5, 0.5, -0.5], [0.5, 0.5, 0.5]));
    let base = m.positions.len() as u32;
    m.positions.extend_from_slice(&[[-3.0, 0.0, 2.0], [-1.0, 0.0, 3.5], [-2.0, 0.0, 0.5]]);
    m.triangles.push([base, base + 1, base + 2]);
    let axis = [1.0 / 14f64.sqrt(), 2.0 / 14f64.sqrt(), 3.0 / 14f64.sqrt()];
    let turn = |p: [f64; 3]| rotate(p, axis, 0.7);
    for q in &mut m.positions {
        *q = turn(q.map(f64::from)).map(|c| c as f32);
    }
    let up = turn([0.0, 1.0, 0.0]);
    let camera =
        Camera { eye: turn([4.0, 5.0, 6.0]), target: turn([-0.5, 0.0, 0.0]), up, near: 0.01, ..Camera::default() };
    let point = turn([-3.0, 2.0, -2.0]).map(|c| c as f32);
    let dir = turn([-0.6, 0.8, -0.4]).map(|c| c as f32);
    let (point, dir) = ([point[0], point[1], point[2], 1.0], [dir[0], dir[1], dir[2], 0.0]);
    verify("on face planes, point light", &m, camera, vec![point], 200, 150);
    verify("on face planes, directional light", &m, camera, vec![dir], 200, 150);
    verify("on face planes, both lights", &m, camera, vec![point, dir], 200, 150);
}

/// The shared scenes' default views at 320 x 180 (common/mod.rs, `for_each_shared_scene_default_view`).
#[test]
fn shared_scenes_default_views() {
    for_each_shared_scene_default_view(|file, mesh, camera, light| {
        verify(file, mesh, camera, vec![light], 320, 180);
    });
}

/// The sphere scene and the face-plane case with walks of 2 steps a pass: every walk is parked
/// in its result word and resumed by the indirect passes, hundreds of times; the decision must
/// stay exact.
#[test]
fn walks_cut_into_passes_of_two_steps_stay_exact() {
    let mut m = ground_plane([0.0, 0.0, 0.0], 6.0);
    m.append(&cuboid([-0.5, 0.5, -0.5], [0.5, 0.5, 0.5]));
    m.append(&cuboid([1.5, 1.5, 1.0], [0.3, 0.2, 0.4]));
    let camera = Camera { eye: [4.0, 5.0, 6.0], target: [0.0, 0.0, 0.0], near: 0.01, ..Camera::default() };
    let lights = vec![[-2.0, 4.0, -1.0, 1.0], [0.4, 1.0, 0.3, 0.0]];
    verify_budget("two steps a pass", &m, camera, lights, 160, 120, 2);
}
