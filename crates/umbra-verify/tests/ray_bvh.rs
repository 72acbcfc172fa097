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

use common::{closed_room, for_each_shared_scene_default_view, turned_face_planes, verify_exact};
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

/// A light inside a closed room (common/mod.rs, `closed_room`).
#[test]
fn light_inside_geometry() {
    let (m, camera, light) = closed_room();
    verify("light inside a closed room", &m, camera, vec![light], 200, 150);
}

/// Samples exactly on face planes, the scene turned (common/mod.rs, `turned_face_planes`).
#[test]
fn samples_exactly_on_a_face_plane() {
    let (m, camera, point, dir) = turned_face_planes();
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
