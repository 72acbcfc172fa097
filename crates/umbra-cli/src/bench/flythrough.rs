//! Camera paths for `umbra bench`: fly-through files of keyframes interpolated with a uniform
//! Catmull-Rom spline (Catmull & Rom 1974; the curve passes through every keyframe), and the
//! default `orbit` around (exteriors) or inside (interiors) the scene's bounds.
//!
//! File format: one keyframe per line, `eye_x eye_y eye_z target_x target_y target_z`
//! (whitespace and/or commas between the six numbers); `#` starts a comment; blank lines are
//! ignored. Any other line is an error naming the file and the line.

use std::path::Path;

use umbra_geom::Aabb;

use crate::error::CliError;
use crate::scenes::Framing;

/// One camera position: where the eye is, what it looks at (world space).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Keyframe {
    pub eye: [f64; 3],
    pub target: [f64; 3],
}

/// A fly-through file that cannot be used, with the file and 1-based line.
fn line_error(file: &str, line: usize, message: impl std::fmt::Display) -> CliError {
    CliError::Other(format!("{file}:{line}: {message}"))
}

/// Parses fly-through text; `file` names it in errors.
pub fn parse(text: &str, file: &str) -> Result<Vec<Keyframe>, CliError> {
    let mut keys = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        let line_no = i + 1;
        let content = raw.split('#').next().unwrap_or("").trim();
        if content.is_empty() {
            continue;
        }
        let fields: Vec<&str> =
            content.split(|c: char| c == ',' || c.is_whitespace()).filter(|s| !s.is_empty()).collect();
        if fields.len() != 6 {
            return Err(line_error(
                file,
                line_no,
                format!("expected 6 numbers (eye x y z, target x y z), found {} in {content:?}", fields.len()),
            ));
        }
        let mut v = [0.0f64; 6];
        for (slot, f) in v.iter_mut().zip(&fields) {
            let x: f64 = f.parse().map_err(|_| line_error(file, line_no, format!("{f:?} is not a number")))?;
            if !x.is_finite() {
                return Err(line_error(file, line_no, format!("{f:?} is not finite")));
            }
            *slot = x;
        }
        let key = Keyframe { eye: [v[0], v[1], v[2]], target: [v[3], v[4], v[5]] };
        if key.eye == key.target {
            return Err(line_error(file, line_no, "the eye and the target are the same point"));
        }
        keys.push(key);
    }
    if keys.is_empty() {
        return Err(CliError::Other(format!("{file}: no keyframes (one line per keyframe: eye x y z, target x y z)")));
    }
    Ok(keys)
}

/// Reads and parses a fly-through file.
pub fn load(path: &Path) -> Result<Vec<Keyframe>, CliError> {
    let name = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|source| CliError::Io { path: name.clone(), source })?;
    parse(&text, &name)
}

/// Uniform Catmull-Rom through p0..p3 at u in [0, 1] (the segment p1 -> p2).
fn catmull_rom_point(p0: [f64; 3], p1: [f64; 3], p2: [f64; 3], p3: [f64; 3], u: f64) -> [f64; 3] {
    let (u2, u3) = (u * u, u * u * u);
    [0, 1, 2].map(|k| {
        0.5 * (2.0 * p1[k]
            + (-p0[k] + p2[k]) * u
            + (2.0 * p0[k] - 5.0 * p1[k] + 4.0 * p2[k] - p3[k]) * u2
            + (-p0[k] + 3.0 * p1[k] - 3.0 * p2[k] + p3[k]) * u3)
    })
}

/// `frames` cameras spread evenly in spline parameter over the keyframes: frame 0 is the first
/// keyframe, the last frame the last one; with `frames - 1` a multiple of `keys - 1`, every
/// keyframe is hit exactly. End segments use reflected outer controls (`2 P0 - P1`).
pub fn interpolate(keys: &[Keyframe], frames: usize) -> Vec<Keyframe> {
    if keys.is_empty() || frames == 0 {
        return Vec::new();
    }
    let n = keys.len();
    (0..frames)
        .map(|f| {
            if n == 1 || frames == 1 {
                return keys[0];
            }
            let t = f as f64 * (n - 1) as f64 / (frames - 1) as f64;
            let seg = (t.floor() as usize).min(n - 2);
            let u = t - seg as f64;
            if u == 0.0 {
                return keys[seg];
            }
            if u == 1.0 {
                return keys[seg + 1];
            }
            // Outer controls beyond the ends are reflected (P(-1) = 2 P0 - P1), so the end
            // segments keep the speed of their neighbours (and straight paths stay straight).
            let reflect = |a: Keyframe, b: Keyframe| Keyframe {
                eye: [0, 1, 2].map(|k| 2.0 * a.eye[k] - b.eye[k]),
                target: [0, 1, 2].map(|k| 2.0 * a.target[k] - b.target[k]),
            };
            let k0 = if seg == 0 { reflect(keys[0], keys[1]) } else { keys[seg - 1] };
            let (k1, k2) = (keys[seg], keys[seg + 1]);
            let k3 = if seg + 2 < n { keys[seg + 2] } else { reflect(keys[n - 1], keys[n - 2]) };
            Keyframe {
                eye: catmull_rom_point(k0.eye, k1.eye, k2.eye, k3.eye, u),
                target: catmull_rom_point(k0.target, k1.target, k2.target, k3.target, u),
            }
        })
        .collect()
}

/// `frames` cameras on a closed orbit. Exteriors: a circle around the bounds' centre at the
/// default camera's distance and height (above the objects, so their shadows on the ground
/// are seen), looking at the centre. Interiors: an ellipse at 30 % of the horizontal extents
/// around the centre at 45 % of the height, looking across the centre at the opposite side
/// at 30 % of the height (inside the room, like the default camera).
pub fn orbit(bounds: &Aabb, framing: Framing, frames: usize) -> Vec<Keyframe> {
    let c = bounds.center().map(f64::from);
    let e = bounds.extent().map(f64::from);
    let min_y = f64::from(bounds.min[1]);
    let horizontal = e[0].max(e[2]);
    (0..frames)
        .map(|f| {
            let a = std::f64::consts::TAU * f as f64 / frames.max(1) as f64;
            let (s, co) = a.sin_cos();
            match framing {
                Framing::Exterior => {
                    let r = ((0.3 * e[0]).powi(2) + (0.4 * e[2]).powi(2)).sqrt().max(0.5 * horizontal).max(1e-3);
                    // Start where the default camera is (front-left), then go round.
                    let a0 = (0.4 * e[2]).atan2(-0.3 * e[0]);
                    let (s0, c0) = (a0 + a).sin_cos();
                    Keyframe { eye: [c[0] + r * c0, c[1] + 0.25 * horizontal + 0.5 * e[1], c[2] + r * s0], target: c }
                }
                Framing::Interior => {
                    let (rx, rz) = (0.3 * e[0], 0.3 * e[2]);
                    Keyframe {
                        eye: [c[0] - rx * co, min_y + 0.45 * e[1], c[2] - rz * s],
                        target: [c[0] + rx * co, min_y + 0.3 * e[1], c[2] + rz * s],
                    }
                }
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn keys() -> Vec<Keyframe> {
        parse("# a path\n0 1 2  3 4 5\n1,1,1, 0,0,0 # trailing comment\n\n-2 5 7 2 -1 0\n4 4 4 0 0 1\n", "t.fly")
            .expect("valid")
    }

    #[test]
    fn parses_numbers_with_commas_comments_and_blank_lines() {
        let k = keys();
        assert_eq!(k.len(), 4);
        assert_eq!(k[0], Keyframe { eye: [0.0, 1.0, 2.0], target: [3.0, 4.0, 5.0] });
        assert_eq!(k[1].target, [0.0; 3]);
    }

    #[test]
    fn bad_lines_name_file_and_line() {
        let cases = [
            ("0 0 0 1 1 1\n0 0 0 1 1\n", "f.fly:2:", "expected 6 numbers"),
            ("\n\n0 0 x 1 1 1\n", "f.fly:3:", "\"x\" is not a number"),
            ("0 0 0 1 1 1 1\n", "f.fly:1:", "found 7"),
            ("# c\n1 2 3 1 2 3\n", "f.fly:2:", "same point"),
            ("0 0 inf 1 1 1\n", "f.fly:1:", "not finite"),
            ("# only comments\n\n", "f.fly:", "no keyframes"),
        ];
        for (text, at, what) in cases {
            let e = parse(text, "f.fly").expect_err(text).to_string();
            assert!(e.starts_with(at) && e.contains(what), "{text:?}: {e}");
        }
    }

    #[test]
    fn catmull_rom_passes_through_every_keyframe() {
        let k = keys();
        // 3 segments, 4 frames per segment: frames 0, 4, 8, 12 are the keyframes.
        let path = interpolate(&k, 13);
        assert_eq!(path.len(), 13);
        for (i, key) in k.iter().enumerate() {
            assert_eq!(path[4 * i], *key, "keyframe {i}");
        }
        // In between: not a keyframe, and continuous (small steps compared to key spacing).
        assert!(k.iter().all(|key| *key != path[2]));
        for w in path.windows(2) {
            let d: f64 = (0..3).map(|j| (w[1].eye[j] - w[0].eye[j]).powi(2)).sum::<f64>().sqrt();
            assert!(d < 6.0, "jump {d}");
        }
    }

    #[test]
    fn catmull_rom_on_a_line_stays_on_it_evenly() {
        // Collinear, evenly spaced keys: uniform Catmull-Rom reproduces linear motion.
        let k: Vec<Keyframe> =
            (0..4).map(|i| Keyframe { eye: [i as f64, 0.0, 0.0], target: [i as f64, 0.0, -1.0] }).collect();
        let path = interpolate(&k, 7);
        for (f, key) in path.iter().enumerate().skip(1).take(4) {
            assert!((key.eye[0] - f as f64 * 0.5).abs() < 1e-12, "{key:?}");
        }
        assert_eq!(interpolate(&k[..1], 3), vec![k[0]; 3]);
        assert_eq!(interpolate(&k, 1), vec![k[0]]);
        assert!(interpolate(&k, 0).is_empty());
    }

    #[test]
    fn orbits_stay_inside_interiors_and_outside_exteriors() {
        let b = Aabb { min: [-10.0, 0.0, -5.0], max: [10.0, 8.0, 5.0] };
        for k in orbit(&b, Framing::Interior, 16) {
            assert!((0..3).all(|i| k.eye[i] > f64::from(b.min[i]) && k.eye[i] < f64::from(b.max[i])), "{k:?}");
            assert_ne!(k.eye, k.target);
        }
        for k in orbit(&b, Framing::Exterior, 16) {
            let outside = (0..3).any(|i| k.eye[i] < f64::from(b.min[i]) || k.eye[i] > f64::from(b.max[i]));
            assert!(outside && k.eye[1] > 8.0, "{k:?}");
            assert_eq!(k.target, [0.0, 4.0, 0.0]);
        }
        let o = orbit(&b, Framing::Exterior, 4);
        assert_ne!(o[0].eye, o[1].eye);
    }
}
