//! The indexed triangle mesh every loader and procedural generator yields.

/// Positions, triangles (indices into `positions`) and optional per-vertex normals.
///
/// A mesh straight from a loader is a *soup*: vertices may be duplicated, triangles may be
/// degenerate, edges open or shared by any number of triangles. That is normal input.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    /// Vertex positions.
    pub positions: Vec<[f32; 3]>,
    /// Triangles as three indices into `positions`.
    pub triangles: Vec<[u32; 3]>,
    /// Per-vertex normals, same length as `positions`, when the file had them.
    pub normals: Option<Vec<[f32; 3]>>,
}

/// An axis-aligned bounding box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Smallest x, y, z.
    pub min: [f32; 3],
    /// Largest x, y, z.
    pub max: [f32; 3],
}

impl Aabb {
    /// The centre point.
    pub fn center(&self) -> [f32; 3] {
        [0, 1, 2].map(|i| 0.5 * (self.min[i] + self.max[i]))
    }
    /// Size along x, y, z.
    pub fn extent(&self) -> [f32; 3] {
        [0, 1, 2].map(|i| self.max[i] - self.min[i])
    }
    /// Length of the diagonal.
    pub fn diagonal(&self) -> f32 {
        let e = self.extent();
        (e[0] * e[0] + e[1] * e[1] + e[2] * e[2]).sqrt()
    }
}

impl Mesh {
    /// Bounds of the vertices referenced by triangles; `None` for a mesh without triangles.
    /// Indices out of range (which no loader produces) are ignored.
    pub fn bounds(&self) -> Option<Aabb> {
        let mut it = self.triangles.iter().flatten().filter_map(|&i| self.positions.get(i as usize).copied());
        let first = it.next()?;
        let mut b = Aabb { min: first, max: first };
        for p in it {
            b.min = [0, 1, 2].map(|k| b.min[k].min(p[k]));
            b.max = [0, 1, 2].map(|k| b.max[k].max(p[k]));
        }
        Some(b)
    }

    /// Appends `other`, offsetting its indices. Normals are kept only if both meshes have them.
    pub fn append(&mut self, other: &Mesh) {
        let base = self.positions.len() as u32;
        let keep_normals = (self.normals.is_some() || self.positions.is_empty()) && other.normals.is_some();
        match (&mut self.normals, &other.normals) {
            (Some(n), Some(on)) if keep_normals => n.extend_from_slice(on),
            (None, Some(on)) if keep_normals => self.normals = Some(on.clone()),
            _ => self.normals = None,
        }
        self.positions.extend_from_slice(&other.positions);
        self.triangles.extend(other.triangles.iter().map(|t| t.map(|i| i + base)));
    }
}

/// Unit normal of triangle `t` (counter-clockwise = front), computed in f64; zero for a
/// zero-area triangle.
pub fn flat_normal(p: &[[f32; 3]], t: [u32; 3]) -> [f32; 3] {
    let [a, b, c] = t.map(|i| p[i as usize].map(f64::from));
    let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
    let n = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]];
    let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    if len > 0.0 && len.is_finite() {
        n.map(|x| (x / len) as f32)
    } else {
        [0.0; 3]
    }
}
