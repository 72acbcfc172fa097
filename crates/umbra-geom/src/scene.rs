//! Procedural test scenes and scene specifications.
//!
//! * `spheres:N` is the synthetic benchmark of paper 001, Sec. 3.1 / Tables 3-5 ("Sphere
//!   scene: adjustable number of spheres (typically 100) with configurable amount of
//!   detailness"): an N x N grid of UV spheres floating over a ground plane. With the
//!   default tessellation (18 slices x 10 stacks = 324 triangles per sphere) `spheres:10`
//!   has the 32,400 sphere triangles of the first row of Table 3.
//! * `spheres:N:T` picks the tessellation so the total triangle count (spheres plus the
//!   two ground triangles) is within 2% of `T` (Table 5: "1 million triangles (with
//!   deviation max 2%)"). `T` accepts a `k` or `M` suffix (`spheres:10:1M`).
//! * `box` is a closed cube, `default` a small shadow show-case (a sphere, a box, a tilted
//!   torus and a tetrahedron over a ground plane, about 5.6k triangles).
//! * Anything else is a file path loaded with [`crate::load::load_path`].
//!
//! All solids are closed after an exact-position weld and wound counter-clockwise seen
//! from outside; every generated solid has per-vertex normals ([`book`], a non-manifold test
//! surface, has none). Y is up.

use crate::load::{self, LoadError};
use crate::Mesh;
use std::f64::consts::PI;
use std::path::PathBuf;

/// Largest triangle count a procedural spec may ask for (keeps a typo from eating all memory).
pub const MAX_PROCEDURAL_TRIANGLES: u64 = 50_000_000;

/// Default sphere tessellation of `spheres:N` (324 triangles per sphere, paper 001 Table 3).
pub const DEFAULT_SPHERE_SLICES: u32 = 18;
/// See [`DEFAULT_SPHERE_SLICES`].
pub const DEFAULT_SPHERE_STACKS: u32 = 10;

/// Sphere radius in the `spheres` scenes.
pub const SPHERES_RADIUS: f32 = 1.0;
/// Distance between neighbouring sphere centres in the `spheres` scenes.
pub const SPHERES_SPACING: f32 = 3.0;

/// A parsed scene specification.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum SceneSpec {
    /// `default`: a few objects over a ground plane.
    Default,
    /// `box`: a closed cube of side 2 centred at the origin.
    Box,
    /// `spheres:N` or `spheres:N:T`: an `n` x `n` grid of spheres with `slices` x `stacks`
    /// tessellation over a ground plane. `target_triangles` is `T` when given.
    Spheres {
        /// Spheres per row and column.
        n: u32,
        /// Segments around each sphere.
        slices: u32,
        /// Segments from pole to pole.
        stacks: u32,
        /// The requested total triangle count T, if given.
        target_triangles: Option<u64>,
    },
    /// A mesh file, loaded by extension.
    File(PathBuf),
}

impl SceneSpec {
    /// The exact number of triangles [`build`] yields, when known without loading a file.
    pub fn triangle_count(&self) -> Option<u64> {
        match *self {
            SceneSpec::Default => Some(default_scene().triangles.len() as u64),
            SceneSpec::Box => Some(12),
            SceneSpec::Spheres { n, slices, stacks, .. } => Some(spheres_triangle_count(n, slices, stacks)),
            SceneSpec::File(_) => None,
        }
    }
}

/// Why a scene could not be made: a bad spec, or a file that failed to load.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The spec string is not valid.
    #[error("scene spec {spec:?}: {message}")]
    InvalidSpec {
        /// The spec string.
        spec: String,
        /// What is wrong with it.
        message: String,
    },
    /// The spec named a file that could not be loaded (the error names the file).
    #[error("{0}")]
    Load(#[from] LoadError),
}

/// Parses `default`, `box`, `spheres:N`, `spheres:N:T`; any other string is a file path.
pub fn parse(spec: &str) -> Result<SceneSpec, SceneError> {
    let invalid = |message: String| SceneError::InvalidSpec { spec: spec.to_string(), message };
    let trimmed = spec.trim();
    match trimmed {
        "default" => return Ok(SceneSpec::Default),
        "box" => return Ok(SceneSpec::Box),
        "" => return Err(invalid("empty scene spec; use default, box, spheres:N[:T] or a file path".into())),
        _ => {}
    }
    let Some(rest) = trimmed.strip_prefix("spheres:") else {
        return Ok(SceneSpec::File(PathBuf::from(spec)));
    };
    let mut parts = rest.split(':');
    let n_str = parts.next().unwrap_or("");
    let t_str = parts.next();
    if parts.next().is_some() {
        return Err(invalid("expected spheres:N or spheres:N:T (too many ':')".into()));
    }
    let n = parse_count(n_str).ok_or_else(|| invalid(format!("N = {n_str:?} is not a positive integer")))?;
    if n == 0 {
        return Err(invalid("N must be at least 1".into()));
    }
    let n = u32::try_from(n)
        .ok()
        .filter(|&n| spheres_triangle_count(n, 3, 2) <= MAX_PROCEDURAL_TRIANGLES)
        .ok_or_else(|| invalid(format!("N = {n} is too large (at most {MAX_PROCEDURAL_TRIANGLES} triangles)")))?;
    match t_str {
        None => {
            let (slices, stacks) = (DEFAULT_SPHERE_SLICES, DEFAULT_SPHERE_STACKS);
            let count = spheres_triangle_count(n, slices, stacks);
            if count > MAX_PROCEDURAL_TRIANGLES {
                return Err(invalid(format!("{count} triangles is more than the limit of {MAX_PROCEDURAL_TRIANGLES}")));
            }
            Ok(SceneSpec::Spheres { n, slices, stacks, target_triangles: None })
        }
        Some(t_str) => {
            let t = parse_count(t_str)
                .ok_or_else(|| invalid(format!("T = {t_str:?} is not a positive integer (k/M suffix allowed)")))?;
            if t > MAX_PROCEDURAL_TRIANGLES {
                return Err(invalid(format!("T = {t} exceeds the limit of {MAX_PROCEDURAL_TRIANGLES} triangles")));
            }
            let (slices, stacks) = tessellation_for_target(n, t).ok_or_else(|| {
                let min = spheres_triangle_count(n, 3, 2);
                invalid(format!(
                    "no sphere tessellation gives {n}x{n} spheres a total within 2% of {t} triangles \
                     (the coarsest possible has {min})"
                ))
            })?;
            Ok(SceneSpec::Spheres { n, slices, stacks, target_triangles: Some(t) })
        }
    }
}

/// Builds the mesh of a spec; only [`SceneSpec::File`] can fail.
pub fn build(spec: &SceneSpec) -> Result<Mesh, LoadError> {
    Ok(match spec {
        SceneSpec::Default => default_scene(),
        SceneSpec::Box => cuboid([0.0; 3], [1.0; 3]),
        &SceneSpec::Spheres { n, slices, stacks, .. } => spheres_scene(n, slices, stacks),
        SceneSpec::File(path) => load::load_path(path)?,
    })
}

/// [`parse`] then [`build`].
pub fn load_scene(spec: &str) -> Result<Mesh, SceneError> {
    Ok(build(&parse(spec)?)?)
}

/// Parses a decimal count with optional `_` separators and a `k` (x1000) or `M` (x10^6) suffix.
fn parse_count(s: &str) -> Option<u64> {
    let (digits, scale) = match s.as_bytes().last()? {
        b'k' | b'K' => (&s[..s.len() - 1], 1_000u64),
        b'M' | b'm' => (&s[..s.len() - 1], 1_000_000u64),
        _ => (s, 1),
    };
    let mut value: u64 = 0;
    let mut any_digit = false;
    for c in digits.bytes() {
        match c {
            b'0'..=b'9' => {
                value = value.checked_mul(10)?.checked_add(u64::from(c - b'0'))?;
                any_digit = true;
            }
            b'_' => {}
            _ => return None,
        }
    }
    if !any_digit {
        return None;
    }
    value.checked_mul(scale)
}

/// Largest `slices` or `stacks` of [`uv_sphere`] (and segments of [`torus`]): keeps every
/// vertex index within `u32`. Larger arguments are clamped.
pub const MAX_SEGMENTS: u32 = 65_535;

/// Triangles of one UV sphere with shared poles: `2 * slices * (stacks - 1)` (after the
/// same clamping as [`uv_sphere`]).
pub fn sphere_triangle_count(slices: u32, stacks: u32) -> u64 {
    2 * u64::from(slices.clamp(3, MAX_SEGMENTS)) * u64::from(stacks.clamp(2, MAX_SEGMENTS) - 1)
}

/// Triangles of the `spheres` scene: `n^2` spheres plus the two ground triangles
/// (saturating at `u64::MAX`).
pub fn spheres_triangle_count(n: u32, slices: u32, stacks: u32) -> u64 {
    (u64::from(n) * u64::from(n)).saturating_mul(sphere_triangle_count(slices, stacks)).saturating_add(2)
}

/// The `(slices, stacks)` for which `spheres:n` has a total triangle count within 2% of
/// `target`, preferring (among counts within 0.5%, else within 2%) the most even
/// quads: `slices` close to `2 * (stacks - 1)`. `None` if no tessellation is within 2%.
pub fn tessellation_for_target(n: u32, target: u64) -> Option<(u32, u32)> {
    let spheres = u64::from(n) * u64::from(n);
    if n == 0 || target < 3 {
        return None;
    }
    let per_sphere = (target - 2) as f64 / spheres as f64;
    // per sphere 2 * s * m with m = stacks - 1 >= 1 and s >= 3
    let max_m = ((per_sphere / 6.0).ceil() as u64).clamp(1, u64::from(MAX_SEGMENTS) - 1);
    let mut best: [Option<(f64, u64, u32, u32)>; 2] = [None, None];
    for m in 1..=max_m {
        let s_real = per_sphere / (2.0 * m as f64);
        for s in [s_real.floor(), s_real.ceil()] {
            if !(3.0..=f64::from(MAX_SEGMENTS)).contains(&s) {
                continue;
            }
            let (s, m32) = (s as u32, m as u32);
            let total = spheres_triangle_count(n, s, m32 + 1);
            let err = total.abs_diff(target);
            let rel = err as f64 / target as f64;
            let aspect = (f64::from(s) / (2.0 * m as f64)).ln().abs();
            for (slot, tolerance) in best.iter_mut().zip([0.005, 0.02]) {
                if rel <= tolerance {
                    let better = match slot {
                        None => true,
                        Some((a, e, _, _)) => aspect < *a || (aspect == *a && err < *e),
                    };
                    if better {
                        *slot = Some((aspect, err, s, m32 + 1));
                    }
                }
            }
        }
    }
    best[0].or(best[1]).map(|(_, _, s, k)| (s, k))
}

/// A closed UV sphere: `slices` (3..=[`MAX_SEGMENTS`]) vertices around, `stacks`
/// (2..=[`MAX_SEGMENTS`]) bands from pole to pole, single shared pole vertices, `2 + slices * (stacks - 1)` vertices and
/// `2 * slices * (stacks - 1)` triangles, counter-clockwise seen from outside, unit normals.
pub fn uv_sphere(center: [f32; 3], radius: f32, slices: u32, stacks: u32) -> Mesh {
    let slices = slices.clamp(3, MAX_SEGMENTS);
    let stacks = stacks.clamp(2, MAX_SEGMENTS);
    let rings = stacks - 1;
    let mut positions = Vec::with_capacity(2 + slices as usize * rings as usize);
    let mut normals = Vec::with_capacity(positions.capacity());
    let mut push = |d: [f64; 3]| {
        positions.push([0, 1, 2].map(|k| (f64::from(center[k]) + f64::from(radius) * d[k]) as f32));
        normals.push(d.map(|x| x as f32));
    };
    push([0.0, 1.0, 0.0]);
    for i in 1..stacks {
        let phi = PI * f64::from(i) / f64::from(stacks);
        let (r, y) = (phi.sin(), phi.cos());
        for j in 0..slices {
            let theta = 2.0 * PI * f64::from(j) / f64::from(slices);
            push([r * theta.cos(), y, r * theta.sin()]);
        }
    }
    push([0.0, -1.0, 0.0]);
    let north = 0u32;
    let south = 1 + slices * rings;
    let ring = |i: u32, j: u32| 1 + i * slices + (j % slices);
    let mut triangles = Vec::with_capacity(sphere_triangle_count(slices, stacks) as usize);
    for j in 0..slices {
        triangles.push([north, ring(0, j + 1), ring(0, j)]);
    }
    for i in 0..rings - 1 {
        for j in 0..slices {
            let (u0, u1, l0, l1) = (ring(i, j), ring(i, j + 1), ring(i + 1, j), ring(i + 1, j + 1));
            triangles.push([u0, u1, l1]);
            triangles.push([u0, l1, l0]);
        }
    }
    for j in 0..slices {
        triangles.push([south, ring(rings - 1, j), ring(rings - 1, j + 1)]);
    }
    Mesh { positions, triangles, normals: Some(normals) }
}

/// A horizontal square at `y = center[1]`, side `2 * half_size`, two triangles,
/// counter-clockwise seen from above (normal +Y).
pub fn ground_plane(center: [f32; 3], half_size: f32) -> Mesh {
    let [x, y, z] = center;
    let h = half_size;
    Mesh {
        positions: vec![[x - h, y, z - h], [x + h, y, z - h], [x + h, y, z + h], [x - h, y, z + h]],
        triangles: vec![[0, 3, 2], [0, 2, 1]],
        normals: Some(vec![[0.0, 1.0, 0.0]; 4]),
    }
}

/// Appends a horizontal receiving plane (normal +Y) at the mesh's lowest Y, centred under
/// the mesh, whose side is ten times the larger horizontal (x or z) extent (or
/// `max(diagonal, 1)` when that is 0). An empty mesh gets a 10 x 10 plane at the origin.
pub fn add_ground(mesh: &mut Mesh) {
    let ground = match referenced_bounds(mesh) {
        None => ground_plane([0.0; 3], 5.0),
        Some((min, max)) => {
            let extent = (max[0] - min[0]).max(max[2] - min[2]);
            let diagonal = (0..3).map(|k| (max[k] - min[k]).powi(2)).sum::<f32>().sqrt();
            let extent = if extent > 0.0 && extent.is_finite() { extent } else { diagonal.max(1.0) };
            let center = [0.5 * (min[0] + max[0]), min[1], 0.5 * (min[2] + max[2])];
            ground_plane(center, 5.0 * extent)
        }
    };
    mesh.append(&ground);
}

/// Bounds of the vertices referenced by valid triangle indices (never panics).
fn referenced_bounds(mesh: &Mesh) -> Option<([f32; 3], [f32; 3])> {
    let mut it = mesh.triangles.iter().flatten().filter_map(|&i| mesh.positions.get(i as usize));
    let first = *it.next()?;
    Some(it.fold((first, first), |(mut lo, mut hi), p| {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
        (lo, hi)
    }))
}

/// An axis-aligned box with 24 vertices (4 per face, face normals), 12 triangles,
/// counter-clockwise seen from outside; closed once positions are welded.
pub fn cuboid(center: [f32; 3], half_extent: [f32; 3]) -> Mesh {
    // (normal, u, v) with u x v = normal
    const FACES: [([f32; 3], [f32; 3], [f32; 3]); 6] = [
        ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]),
        ([-1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]),
        ([0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]),
        ([0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
        ([0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
        ([0.0, 0.0, -1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]),
    ];
    let mut mesh = Mesh { normals: Some(Vec::with_capacity(24)), ..Mesh::default() };
    for (n, u, v) in FACES {
        let base = mesh.positions.len() as u32;
        for (su, sv) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
            mesh.positions.push([0, 1, 2].map(|k| center[k] + half_extent[k] * (n[k] + su * u[k] + sv * v[k])));
            if let Some(normals) = &mut mesh.normals {
                normals.push(n);
            }
        }
        mesh.triangles.push([base, base + 1, base + 2]);
        mesh.triangles.push([base, base + 2, base + 3]);
    }
    mesh
}

/// A closed torus around the Y axis: `major_segments` around the ring, `minor_segments`
/// around the tube (each clamped to 3..=[`MAX_SEGMENTS`]), `2 * major * minor` triangles, outward CCW.
pub fn torus(center: [f32; 3], major_radius: f32, minor_radius: f32, major_segments: u32, minor_segments: u32) -> Mesh {
    let (nu, nv) = (major_segments.clamp(3, MAX_SEGMENTS), minor_segments.clamp(3, MAX_SEGMENTS));
    let (big_r, small_r) = (f64::from(major_radius), f64::from(minor_radius));
    let mut mesh = Mesh { normals: Some(Vec::new()), ..Mesh::default() };
    let mut normals = Vec::with_capacity(nu as usize * nv as usize);
    for i in 0..nu {
        let u = 2.0 * PI * f64::from(i) / f64::from(nu);
        for j in 0..nv {
            let v = 2.0 * PI * f64::from(j) / f64::from(nv);
            let n = [v.cos() * u.cos(), v.sin(), v.cos() * u.sin()];
            let ring = big_r + small_r * v.cos();
            let p = [ring * u.cos(), small_r * v.sin(), ring * u.sin()];
            mesh.positions.push([0, 1, 2].map(|k| (f64::from(center[k]) + p[k]) as f32));
            normals.push(n.map(|x| x as f32));
        }
    }
    mesh.normals = Some(normals);
    let q = |i: u32, j: u32| (i % nu) * nv + (j % nv);
    for i in 0..nu {
        for j in 0..nv {
            let (q00, q01, q10, q11) = (q(i, j), q(i, j + 1), q(i + 1, j), q(i + 1, j + 1));
            mesh.triangles.push([q00, q01, q11]);
            mesh.triangles.push([q00, q11, q10]);
        }
    }
    mesh
}

/// A regular tetrahedron with circumradius `radius`: 4 flat faces (12 vertices, face
/// normals), counter-clockwise seen from outside.
pub fn tetrahedron(center: [f32; 3], radius: f32) -> Mesh {
    let s = radius / 3f32.sqrt();
    let corners: [[f32; 3]; 4] = [[1.0, 1.0, 1.0], [1.0, -1.0, -1.0], [-1.0, 1.0, -1.0], [-1.0, -1.0, 1.0]]
        .map(|c| [0, 1, 2].map(|k| center[k] + s * c[k]));
    let mut mesh = Mesh { normals: Some(Vec::with_capacity(12)), ..Mesh::default() };
    for omit in 0..4 {
        let mut f: Vec<[f32; 3]> = (0..4).filter(|&i| i != omit).map(|i| corners[i]).collect();
        let n = cross(sub(f[1], f[0]), sub(f[2], f[0]));
        // the omitted corner lies behind an outward-facing triangle
        if dot(n, sub(corners[omit], f[0])) > 0.0 {
            f.swap(1, 2);
        }
        let n = normalize(cross(sub(f[1], f[0]), sub(f[2], f[0])));
        let base = mesh.positions.len() as u32;
        mesh.positions.extend_from_slice(&f);
        if let Some(normals) = &mut mesh.normals {
            normals.extend_from_slice(&[n; 3]);
        }
        mesh.triangles.push([base, base + 1, base + 2]);
    }
    mesh
}

/// A "book": `pages` quads (two triangles each) hinged on the spine (0, 1, 0)-(0, 1, 1), page
/// `i`'s free edge at `(cos a, 1 + 0.9 sin a)` with `a` spread evenly over 0.05π..0.95π: ONE
/// edge with `pages` opposite vertices (multiplicities far beyond 3 bits), the torture input
/// of the silhouette methods. No normals.
pub fn book(pages: usize) -> Mesh {
    let mut m = Mesh::default();
    m.positions.push([0.0, 1.0, 0.0]);
    m.positions.push([0.0, 1.0, 1.0]);
    for i in 0..pages {
        let angle = std::f32::consts::PI * (0.05 + 0.9 * i as f32 / (pages - 1).max(1) as f32);
        let (x, y) = (angle.cos(), 1.0 + angle.sin() * 0.9);
        let base = m.positions.len() as u32;
        m.positions.push([x, y, 0.0]);
        m.positions.push([x, y, 1.0]);
        m.triangles.push([0, 1, base]);
        m.triangles.push([1, base + 1, base]);
    }
    m
}

/// The `default` scene: a sphere, a box resting on the ground, a tilted torus and a
/// floating tetrahedron over a 16 x 16 ground plane at y = 0.
fn default_scene() -> Mesh {
    let mut mesh = ground_plane([0.0, 0.0, 0.0], 8.0);
    mesh.append(&uv_sphere([-2.2, 1.4, 0.3], 1.0, 48, 24));
    mesh.append(&cuboid([1.8, 0.8, -1.2], [0.8, 0.8, 0.8]));
    let mut ring = torus([0.0; 3], 0.9, 0.22, 64, 24);
    rotate_about_x(&mut ring, 35f32.to_radians());
    translate(&mut ring, [0.6, 2.6, 1.8]);
    mesh.append(&ring);
    mesh.append(&tetrahedron([2.6, 2.2, 1.6], 0.7));
    mesh
}

/// The `spheres:N` scene: an N x N grid (spacing [`SPHERES_SPACING`], centred on the
/// origin in XZ) of spheres of radius [`SPHERES_RADIUS`] floating one radius above a
/// ground plane at y = 0 that is twice as wide as the grid.
fn spheres_scene(n: u32, slices: u32, stacks: u32) -> Mesh {
    let half_grid = 0.5 * SPHERES_SPACING * n as f32;
    let mut mesh = ground_plane([0.0; 3], 2.0 * half_grid);
    let one = uv_sphere([0.0; 3], SPHERES_RADIUS, slices, stacks);
    let spheres = (n as usize) * (n as usize);
    mesh.positions.reserve(one.positions.len() * spheres);
    mesh.triangles.reserve(one.triangles.len() * spheres);
    if let Some(normals) = &mut mesh.normals {
        normals.reserve(one.positions.len() * spheres);
    }
    let offset = |i: u32| (i as f32 + 0.5) * SPHERES_SPACING - half_grid;
    for row in 0..n {
        for col in 0..n {
            let mut sphere = one.clone();
            translate(&mut sphere, [offset(col), 2.0 * SPHERES_RADIUS, offset(row)]);
            mesh.append(&sphere);
        }
    }
    mesh
}

fn translate(mesh: &mut Mesh, by: [f32; 3]) {
    for p in &mut mesh.positions {
        *p = [p[0] + by[0], p[1] + by[1], p[2] + by[2]];
    }
}

fn rotate_about_x(mesh: &mut Mesh, angle: f32) {
    let (s, c) = angle.sin_cos();
    let rot = |v: [f32; 3]| [v[0], c * v[1] - s * v[2], s * v[1] + c * v[2]];
    for p in &mut mesh.positions {
        *p = rot(*p);
    }
    if let Some(normals) = &mut mesh.normals {
        for n in normals {
            *n = rot(*n);
        }
    }
}

fn sub(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn dot(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn cross(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}
fn normalize(a: [f32; 3]) -> [f32; 3] {
    let l = dot(a, a).sqrt();
    if l > 0.0 {
        a.map(|x| x / l)
    } else {
        a
    }
}
