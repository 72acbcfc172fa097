//! Real scenes (shared/scenes, found through $UMBRA_SCENES or ../shared/scenes; SKIPPED with
//! a message when absent): every shadow method's final lit decision (the lit mask: the
//! classification passed AND the seen side faces the light) is compared with a brute-force
//! ray cast from each sampled pixel's world position to the light.
//!
//! Expected "shadowed": the segment to the light hits another triangle, or the side of the
//! pixel's own triangle that the camera sees faces away from the light. Mismatches are
//! allowed only in the one-pixel band where the rendered or the ray-cast classification
//! changes between neighbours.

mod common;

use std::path::PathBuf;
use std::sync::Arc;

use common::*;
use umbra_geom::WeldedMesh;
use umbra_gl::{Camera, FrameImages, FrameParams, NO_TRIANGLE};

fn scenes_dir() -> PathBuf {
    std::env::var_os("UMBRA_SCENES")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/scenes"))
}

fn load(name: &str) -> Option<Arc<WeldedMesh>> {
    let path = scenes_dir().join(name);
    if !path.exists() {
        println!("SKIPPED: {} not found (set UMBRA_SCENES)", path.display());
        return None;
    }
    let mesh = umbra_geom::load::load_path(&path).unwrap_or_else(|e| panic!("loading {}: {e}", path.display()));
    Some(Arc::new(umbra_geom::weld::weld(&mesh)))
}

type V = [f64; 3];
fn sub(a: V, b: V) -> V {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn dot(a: V, b: V) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn cross(a: V, b: V) -> V {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

/// Möller-Trumbore: the parameter t of the segment origin + t * dir hitting the triangle,
/// if t in (t_min, t_max).
fn hit(o: V, d: V, t_min: f64, t_max: f64, [a, b, c]: [V; 3]) -> Option<f64> {
    let (e1, e2) = (sub(b, a), sub(c, a));
    let p = cross(d, e2);
    let det = dot(e1, p);
    if det.abs() < 1e-300 {
        return None;
    }
    let inv = 1.0 / det;
    let s = sub(o, a);
    let u = dot(s, p) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = cross(s, e1);
    let v = dot(d, q) * inv;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    let t = dot(e2, q) * inv;
    (t > t_min && t < t_max).then_some(t)
}

/// Why a pixel is expected shadowed: its seen side faces away, or the first occluder found.
#[derive(Clone, Copy, Debug)]
enum Occlusion {
    Lit,
    /// With the cosine between the seen side's normal and the direction to the light.
    SeenSideFacesAway(#[allow(dead_code)] f64),
    Occluder {
        triangle: usize,
        t: f64,
    },
}

/// Triangles in f64 with their bounding boxes, for the brute-force ray casts.
struct Triangles {
    corners: Vec<[V; 3]>,
    boxes: Vec<[V; 2]>,
    /// Scene diagonal: no occluder is farther than this from a scene point.
    diagonal: f64,
}

impl Triangles {
    fn new(mesh: &WeldedMesh) -> Self {
        let corners: Vec<[V; 3]> =
            mesh.triangles.iter().map(|t| t.map(|v| mesh.positions[v as usize].map(f64::from))).collect();
        let boxes: Vec<[V; 2]> = corners
            .iter()
            .map(|c| {
                [
                    [0, 1, 2].map(|k| c[0][k].min(c[1][k]).min(c[2][k])),
                    [0, 1, 2].map(|k| c[0][k].max(c[1][k]).max(c[2][k])),
                ]
            })
            .collect();
        let lo = [0, 1, 2].map(|k| boxes.iter().map(|b| b[0][k]).fold(f64::INFINITY, f64::min));
        let hi = [0, 1, 2].map(|k| boxes.iter().map(|b| b[1][k]).fold(f64::NEG_INFINITY, f64::max));
        let diagonal = dot(sub(hi, lo), sub(hi, lo)).sqrt();
        Self { corners, boxes, diagonal }
    }
}

/// `epsilon`: occluders closer than this distance along the segment are ignored (the world
/// position is an f32 interpolation, so a point next to a shared edge may sit a hair behind
/// the neighbour's plane: "shadow acne" of this reference, not of the renderer).
fn expected_shadowed(
    mesh: &WeldedMesh,
    tris: &Triangles,
    own: usize,
    world: V,
    eye: V,
    light: [f32; 4],
    epsilon: f64,
) -> Occlusion {
    let l = light.map(f64::from);
    let to_light = sub([l[0], l[1], l[2]], world.map(|x| x * l[3]));
    let n = umbra_gl::scene::flat_normal(&mesh.positions, mesh.triangles[own]).map(f64::from);
    let seen = if dot(n, sub(eye, world)) < 0.0 { n.map(|x| -x) } else { n };
    let cos = dot(seen, to_light) / dot(to_light, to_light).sqrt();
    if cos <= 0.0 {
        return Occlusion::SeenSideFacesAway(cos);
    }
    // Point light: the segment ends at the light (t < 1); directional: unbounded.
    let t_max = if l[3] == 1.0 { 1.0 } else { f64::INFINITY };
    let scale = dot(to_light, to_light).sqrt();
    let t_min = epsilon / scale.max(1e-30);
    // Box of the part of the segment that can meet scene geometry.
    let t_box = t_max.min(2.0 * tris.diagonal / scale.max(1e-30));
    let end = [0, 1, 2].map(|k| world[k] + t_box * to_light[k]);
    let (lo, hi) = ([0, 1, 2].map(|k| world[k].min(end[k])), [0, 1, 2].map(|k| world[k].max(end[k])));
    (0..tris.corners.len())
        .filter(|&i| i != own)
        .filter(|&i| {
            let b = &tris.boxes[i];
            (0..3).all(|k| b[0][k] <= hi[k] && b[1][k] >= lo[k])
        })
        .find_map(|i| {
            hit(world, to_light, t_min, t_max, tris.corners[i]).map(|t| Occlusion::Occluder { triangle: i, t })
        })
        .unwrap_or(Occlusion::Lit)
}

/// Ray-cast classifications of the sampled pixels of the last view, shared by all methods.
struct RayCache {
    tris: Triangles,
    key: Option<(umbra_gl::TriangleIdImage, umbra_gl::WorldPosImage, [f32; 4])>,
    results: Vec<(u32, u32, u32, Occlusion)>,
}

/// Result of comparing one scene view.
#[derive(Debug, Default)]
struct Tally {
    /// Sampled pixels showing geometry.
    checked: usize,
    /// ... of which the segment to the light is blocked.
    occluded: usize,
    /// ... of which the seen side faces away from the light (only colour is compared).
    facing_away: usize,
    /// Stencil and ray cast disagree, inside the one-pixel band where either
    /// classification changes between neighbours.
    band_mismatches: usize,
}

/// Compares sampled pixels (every `step`-th in x and y) of `img` against ray casting.
///
/// * Seen side facing away from the light: no light can arrive; the lit mask must be 0 and the
///   colour ambient (whatever the stencil says: for surfaces nearly edge-on to the light the
///   volume sides run within a few depth quanta of the surface).
/// * Otherwise: lit mask 0 exactly when the segment to the light is blocked, except in the
///   one-pixel band where the rendered or the ray-cast classification changes.
#[allow(clippy::too_many_arguments)]
fn compare(
    ctx: &umbra_gl::HeadlessContext,
    test: &'static str,
    mesh: &WeldedMesh,
    img: &FrameImages,
    p: &FrameParams,
    step: u32,
    epsilon: f64,
    cache: &mut RayCache,
) -> Tally {
    let (wp, ids) = (img.world_pos.as_ref().expect("wp"), img.triangle_id.as_ref().expect("ids"));
    let st = &img.stencil[0].image;
    let mask = &img.lit_masks[0].image;
    let light = p.lights[0];
    let tris = &cache.tris;
    let classify = |x: u32, y: u32| -> Option<(u32, Occlusion)> {
        let id = ids.get(x, y)?;
        if id == NO_TRIANGLE {
            return None;
        }
        let w = wp.get(x, y)?;
        let world = [w[0], w[1], w[2]].map(f64::from);
        Some((id, expected_shadowed(mesh, tris, id as usize, world, p.camera.eye, light, epsilon)))
    };
    let samples: Vec<(u32, u32)> = (1..p.height - 1)
        .step_by(step as usize)
        .flat_map(|y| (1..p.width - 1).step_by(step as usize).map(move |x| (x, y)))
        .collect();
    // The ray casts depend only on the depth pass (ids, world positions) and the light, which
    // every method shares: computed once per view.
    let key = (ids.clone(), wp.clone(), light);
    if cache.key.as_ref() != Some(&key) {
        cache.results = std::thread::scope(|s| {
            let handles: Vec<_> = samples
                .chunks(samples.len().div_ceil(2).max(1))
                .map(|chunk| {
                    s.spawn(move || {
                        chunk
                            .iter()
                            .filter_map(|&(x, y)| classify(x, y).map(|(id, o)| (x, y, id, o)))
                            .collect::<Vec<_>>()
                    })
                })
                .collect();
            handles.into_iter().flat_map(|h| h.join().expect("ray thread")).collect()
        });
        cache.key = Some(key);
    }
    let results = cache.results.clone();
    let ambient = expected_ambient_u8(p);
    let mut checks = PixelChecks::new(ctx, test, &img.rgba);
    let mut tally = Tally::default();
    for (x, y, id, why) in results {
        tally.checked += 1;
        let got = mask.get(x, y).is_some_and(|v| v == 0);
        let expected = match why {
            Occlusion::SeenSideFacesAway(_) => {
                tally.facing_away += 1;
                let c = img.rgba.get(x, y).unwrap_or([0; 4]);
                checks.check(x, y, c[0].abs_diff(ambient) <= 1 && got, || {
                    format!(
                        "seen side faces away ({why:?}) but colour {c:?} (ambient {ambient}), lit mask {}",
                        u8::from(!got)
                    )
                });
                continue;
            }
            Occlusion::Lit => false,
            Occlusion::Occluder { .. } => {
                tally.occluded += 1;
                true
            }
        };
        if expected != got {
            let neighbours = || {
                (-1i64..=1).flat_map(|dy| (-1i64..=1).map(move |dx| ((x as i64 + dx) as u32, (y as i64 + dy) as u32)))
            };
            let mask_band = neighbours().any(|(nx, ny)| mask.get(nx, ny).is_some_and(|v| (v == 0) != got));
            let ray_band = neighbours()
                .any(|(nx, ny)| classify(nx, ny).is_some_and(|(_, o)| !matches!(o, Occlusion::Lit) != expected));
            if mask_band || ray_band {
                tally.band_mismatches += 1;
                continue;
            }
        }
        checks.check(x, y, expected == got, || {
            let detail = match why {
                Occlusion::Occluder { triangle, t } => {
                    let (a, b) = (mesh.triangles[id as usize], mesh.triangles[triangle]);
                    let shared = a.iter().filter(|v| b.contains(v)).count();
                    format!("occluder {triangle} {b:?} at t = {t:e}, {shared} vertices shared with own {id} {a:?}")
                }
                other => format!("{other:?}, own triangle {id}"),
            };
            format!(
                "ray cast shadowed {expected}, lit mask {}, stencil {} ({detail})",
                u8::from(!got),
                st.get(x, y).unwrap_or(0)
            )
        });
    }
    checks.finish();
    tally
}

/// Camera and lights from the scene bounds: `inside` puts the eye inside the bounding box
/// (interiors: the eye is then usually inside some shadow volume, which z-fail must handle).
/// `open_roof`: the interior is lit from above through an opening (Sponza's atrium), so a
/// light above the scene centre and a directional light are used there.
fn check_scene(file: &str, test: &'static str, inside: bool, open_roof: bool) {
    let Some(mesh) = load(file) else { return };
    let ctx = context();
    let b = umbra_geom::Mesh { positions: mesh.positions.clone(), triangles: mesh.triangles.clone(), normals: None }
        .bounds()
        .expect("non-empty scene");
    let (c, d) = (b.center().map(f64::from), f64::from(b.diagonal()));
    let e = b.extent().map(f64::from);
    let camera = if inside {
        Camera {
            eye: [c[0] - 0.3 * e[0], c[1] - 0.25 * e[1], c[2] + 0.1 * e[2]],
            target: [c[0] + 0.3 * e[0], c[1] - 0.35 * e[1], c[2] - 0.1 * e[2]],
            near: d * 1e-4,
            ..Camera::default()
        }
    } else {
        Camera {
            eye: [c[0] + 0.45 * d, c[1] + 0.35 * d, c[2] + 0.55 * d],
            target: c,
            near: d * 1e-3,
            ..Camera::default()
        }
    };
    let lights = if inside {
        // Point lights inside the room (a directional light is blocked by the roof): one
        // above the eye, one above the middle of the view.
        let above = |q: [f64; 3], h: f64| [q[0] as f32, (q[1] + h * e[1]) as f32, q[2] as f32, 1.0];
        let mid = [0, 1, 2].map(|k| 0.5 * (camera.eye[k] + camera.target[k]));
        if open_roof {
            vec![above(mid, 0.15), above(c, 0.2), [0.2, 1.0, 0.1, 0.0]]
        } else {
            vec![above(camera.eye, 0.1), above(mid, 0.15)]
        }
    } else {
        vec![[(c[0] - 0.2 * d) as f32, (c[1] + 0.6 * d) as f32, (c[2] + 0.1 * d) as f32, 1.0], [0.3, 1.0, -0.4, 0.0]]
    };
    let mut cache = RayCache { tris: Triangles::new(&mesh), key: None, results: Vec::new() };
    for (li, light) in lights.into_iter().enumerate() {
        let p = params(camera, vec![light], 200, 112);
        for method in shadow_methods() {
            let img = render_once(&ctx, &mesh, method, &p);
            if std::env::var_os("UMBRA_KEEP_IMAGES").is_some() {
                let name = format!("{test}-{method}-light{li}.png");
                img.rgba.save_png(&output_dir().join(name)).expect("png");
            }
            // Brute-force rays are slow unoptimised: debug builds sample 16x fewer pixels.
            let (step, min) = if cfg!(debug_assertions) { (8, 4) } else { (2, 50) };
            let t = compare(&ctx, test, &mesh, &img, &p, step, 1e-5 * d, &mut cache);
            println!("{file} {method} light {light:?}: {t:?}");
            let lit = t.checked - t.occluded - t.facing_away;
            assert!(
                t.checked > 10 * min && t.occluded > min && lit > min,
                "{t:?}: the view must show light and shadow"
            );
        }
    }
}

#[test]
#[ignore = "slow (~500 s on 2 loaded cores) and superseded by the torture suite (umbra-verify), which runs every method on the shared scenes; run with --ignored"]
fn sibenik_outside_stencil_matches_ray_casting() {
    check_scene("sibenik.obj.gz", "sibenik_outside", false, false);
}

#[test]
#[ignore = "slow (~500 s on 2 loaded cores) and superseded by the torture suite (umbra-verify), which runs every method on the shared scenes; run with --ignored"]
fn sibenik_inside_stencil_matches_ray_casting() {
    check_scene("sibenik.obj.gz", "sibenik_inside", true, false);
}

#[test]
#[ignore = "slow (~500 s on 2 loaded cores) and superseded by the torture suite (umbra-verify), which runs every method on the shared scenes; run with --ignored"]
fn sponza_inside_stencil_matches_ray_casting() {
    check_scene("crytek-sponza.obj.gz", "sponza_inside", true, true);
}

#[test]
#[ignore = "slow (~500 s on 2 loaded cores) and superseded by the torture suite (umbra-verify), which runs every method on the shared scenes; run with --ignored"]
fn conference_inside_stencil_matches_ray_casting() {
    check_scene("conference.obj.gz", "conference_inside", true, false);
}

/// Debug helper: prints everything about one pixel of the inside-Sponza point-light view.
/// `UMBRA_DEBUG_PIXEL=x,y cargo test --release --test real_scenes debug_pixel -- --ignored --nocapture`
#[test]
#[ignore]
fn debug_pixel() {
    let Some(spec) = std::env::var("UMBRA_DEBUG_PIXEL").ok() else { return };
    let file = std::env::var("UMBRA_DEBUG_SCENE").unwrap_or("crytek-sponza.obj.gz".into());
    let (x, y) = spec.split_once(',').map(|(a, b)| (a.parse().unwrap_or(0), b.parse().unwrap_or(0))).unwrap_or((0, 0));
    let Some(mesh) = load(&file) else { return };
    let ctx = context();
    let b = umbra_geom::Mesh { positions: mesh.positions.clone(), triangles: mesh.triangles.clone(), normals: None }
        .bounds()
        .expect("bounds");
    let (c, d) = (b.center().map(f64::from), f64::from(b.diagonal()));
    let e = b.extent().map(f64::from);
    let camera = Camera {
        eye: [c[0] - 0.3 * e[0], c[1] - 0.25 * e[1], c[2] + 0.1 * e[2]],
        target: [c[0] + 0.3 * e[0], c[1] - 0.35 * e[1], c[2] - 0.1 * e[2]],
        near: d * 1e-4,
        ..Camera::default()
    };
    let light = [c[0] as f32, (c[1] + 0.2 * e[1]) as f32, c[2] as f32, 1.0];
    let p = params(camera, vec![light], 200, 112);
    let img = render_once(&ctx, &mesh, "cpu-silhouette", &p);
    let (wp, ids, st) =
        (img.world_pos.as_ref().expect("wp"), img.triangle_id.as_ref().expect("id"), &img.stencil[0].image);
    println!("camera {camera:?}\nlight {light:?}");
    for dy in -2i64..=2 {
        let row: Vec<String> = (-2i64..=2)
            .map(|dx| {
                let (px, py) = ((x as i64 + dx) as u32, (y as i64 + dy) as u32);
                format!("{:>7}:{:<3}", ids.get(px, py).unwrap_or(0) as i64, st.get(px, py).unwrap_or(0))
            })
            .collect();
        println!("{}", row.join(" "));
    }
    let id = ids.get(x, y).expect("pixel");
    let w = wp.get(x, y).expect("pixel");
    let t = mesh.triangles[id as usize];
    println!("pixel ({x},{y}) world {w:?} triangle {id} {t:?}");
    for v in t {
        println!("  v{v} {:?}", mesh.positions[v as usize]);
    }
    println!("orientation (geom) {}", umbra_geom::multiplicity::triangle_orientation(&mesh.positions, t, light));
    let same: Vec<usize> = mesh
        .triangles
        .iter()
        .enumerate()
        .filter(|(_, o)| {
            let mut a = **o;
            a.sort();
            let mut b = t;
            b.sort();
            a == b
        })
        .map(|(i, _)| i)
        .collect();
    println!("triangles on the same three vertices: {same:?}");
    println!(
        "{:?}",
        expected_shadowed(
            &mesh,
            &Triangles::new(&mesh),
            id as usize,
            [w[0], w[1], w[2]].map(f64::from),
            camera.eye,
            light,
            1e-5 * d
        )
    );
}
