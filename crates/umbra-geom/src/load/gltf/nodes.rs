//! The node graph of a glTF document: the root nodes of the default scene, a node's local
//! transform (`matrix`, or `translation`, `rotation`, `scale` as T * R * S), and the
//! column-major 4x4 math that applies them to positions and (inverse transpose) normals.

use super::doc::Doc;
use crate::load::LoadError;
use gltf::json::Value;

impl<'a> Doc<'a> {
    pub(super) fn root_nodes(&self) -> Result<Vec<usize>, LoadError> {
        let scenes = self.array("scenes")?;
        if scenes.is_empty() {
            // no scenes: every node that is nobody's child
            let nodes = self.array("nodes")?;
            let mut is_child = vec![false; nodes.len()];
            for (i, n) in nodes.iter().enumerate() {
                if let Some(children) = n.get("children").and_then(Value::as_array) {
                    for (k, c) in children.iter().enumerate() {
                        let c = self.index_value(c, &format!("nodes[{i}].children[{k}]"))?;
                        if let Some(flag) = is_child.get_mut(c) {
                            *flag = true;
                        }
                    }
                }
            }
            return Ok((0..nodes.len()).filter(|&i| !is_child[i]).collect());
        }
        let scene_index = match self.json.get("scene") {
            Some(v) => self.index_value(v, "scene")?,
            None => 0,
        };
        let scene = self.element("scenes", scene_index)?;
        let path = format!("scenes[{scene_index}].nodes");
        match scene.get("nodes") {
            None => Ok(Vec::new()),
            Some(Value::Array(nodes)) => {
                nodes.iter().enumerate().map(|(k, n)| self.index_value(n, &format!("{path}[{k}]"))).collect()
            }
            Some(_) => Err(self.malformed(path, "must be an array".into())),
        }
    }

    /// The node's local transform as a column-major 4x4 matrix.
    pub(super) fn local_transform(&self, node: &Value, path: &str) -> Result<[f64; 16], LoadError> {
        if let Some(m) = self.numbers::<16>(node, "matrix", path)? {
            return Ok(m);
        }
        let t = self.numbers::<3>(node, "translation", path)?.unwrap_or([0.0; 3]);
        let [x, y, z, w] = self.numbers::<4>(node, "rotation", path)?.unwrap_or([0.0, 0.0, 0.0, 1.0]);
        let s = self.numbers::<3>(node, "scale", path)?.unwrap_or([1.0; 3]);
        // rotation matrix of the unit quaternion (normalised here for robustness)
        let len = (x * x + y * y + z * z + w * w).sqrt();
        let (x, y, z, w) = if len > 0.0 { (x / len, y / len, z / len, w / len) } else { (0.0, 0.0, 0.0, 1.0) };
        let r = [
            [1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y + z * w), 2.0 * (x * z - y * w)],
            [2.0 * (x * y - z * w), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z + x * w)],
            [2.0 * (x * z + y * w), 2.0 * (y * z - x * w), 1.0 - 2.0 * (x * x + y * y)],
        ];
        // M = T * R * S, column-major: column c = R column c * s[c]
        let mut m = IDENTITY;
        for c in 0..3 {
            for row in 0..3 {
                m[4 * c + row] = r[c][row] * s[c];
            }
        }
        m[12] = t[0];
        m[13] = t[1];
        m[14] = t[2];
        Ok(m)
    }
}

pub(super) const IDENTITY: [f64; 16] = [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0];

/// Column-major 4x4 product `a * b`.
pub(super) fn mul(a: &[f64; 16], b: &[f64; 16]) -> [f64; 16] {
    let mut out = [0.0; 16];
    for c in 0..4 {
        for r in 0..4 {
            out[4 * c + r] = (0..4).map(|k| a[4 * k + r] * b[4 * c + k]).sum();
        }
    }
    out
}

/// Affine transform of a point (glTF node matrices are affine; the bottom row is ignored).
pub(super) fn transform_point(m: &[f64; 16], p: [f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|r| m[r] * p[0] + m[4 + r] * p[1] + m[8 + r] * p[2] + m[12 + r])
}

/// Determinant of the upper-left 3x3 block.
pub(super) fn det3(m: &[f64; 16]) -> f64 {
    let a = |r: usize, c: usize| m[4 * c + r];
    a(0, 0) * (a(1, 1) * a(2, 2) - a(1, 2) * a(2, 1)) - a(0, 1) * (a(1, 0) * a(2, 2) - a(1, 2) * a(2, 0))
        + a(0, 2) * (a(1, 0) * a(2, 1) - a(1, 1) * a(2, 0))
}

/// Row-major 3x3 inverse transpose of the upper-left block (the cofactor matrix; the
/// determinant's scale is irrelevant because normals are renormalised, its sign is kept).
pub(super) fn inverse_transpose3(m: &[f64; 16]) -> [[f64; 3]; 3] {
    let a = |r: usize, c: usize| m[4 * c + r];
    let cof = |r: usize, c: usize| {
        let (r1, r2) = ((r + 1) % 3, (r + 2) % 3);
        let (c1, c2) = ((c + 1) % 3, (c + 2) % 3);
        a(r1, c1) * a(r2, c2) - a(r1, c2) * a(r2, c1)
    };
    let s = if det3(m) < 0.0 { -1.0 } else { 1.0 };
    [0, 1, 2].map(|r| [0, 1, 2].map(|c| s * cof(r, c)))
}

pub(super) fn mul3(m: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    m.map(|row| row[0] * v[0] + row[1] * v[1] + row[2] * v[2])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::load::LoadOptions;

    #[test]
    fn trs_matches_spec_order() {
        // scale 2, rotate 90 degrees about Z, translate (1, 0, 0): (1,0,0) -> (2,0,0) -> (0,2,0) -> (1,2,0)
        let s = std::f64::consts::FRAC_1_SQRT_2;
        let node: Value = gltf::json::deserialize::from_str(&format!(
            r#"{{"translation":[1,0,0],"rotation":[0,0,{s},{s}],"scale":[2,2,2]}}"#
        ))
        .unwrap();
        let json = Value::Null;
        let opts = LoadOptions::default();
        let doc = Doc {
            file: "t",
            json: &json,
            bin: None,
            base_dir: None,
            options: &opts,
            buffers: Vec::new(),
            input_len: 0,
        };
        let m = doc.local_transform(&node, "nodes[0]").unwrap();
        let p = transform_point(&m, [1.0, 0.0, 0.0]);
        for (a, b) in p.iter().zip([1.0, 2.0, 0.0]) {
            assert!((a - b).abs() < 1e-12, "{p:?}");
        }
    }
}
