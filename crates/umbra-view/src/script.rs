//! Scripted camera paths for `umbra view --script`: one camera pose per drawn frame, read
//! from a text file in the format of umbra's fly-through files (bench/*.flythrough):
//! `eye_x eye_y eye_z target_x target_y target_z` per line, optionally spelled
//! `eye x y z target x y z`; numbers separated by whitespace and/or commas; `#` starts a
//! comment; blank lines are ignored. Unlike `umbra bench`, nothing is interpolated: line k is
//! frame k, so the last line is exactly the view a screenshot shows.
//!
//! Toggles: a line `wireframe on` or `wireframe off` sets the shadow-volume wireframe (the
//! viewer's F key) for the poses that follow it (off until the first such line). A script
//! must hold at least one pose.

use std::path::Path;

use crate::ViewError;

/// One frame's camera: where the eye is and what it looks at (world space).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pose {
    /// Camera position.
    pub eye: [f64; 3],
    /// Point the camera looks at.
    pub target: [f64; 3],
    /// Whether the current light's shadow-volume wireframe is drawn in this frame (the last
    /// `wireframe on|off` line before the pose; off without one).
    pub wireframe: bool,
}

fn script_error(file: &str, line: usize, message: impl Into<String>) -> ViewError {
    ViewError::Script { file: file.to_string(), line, message: message.into() }
}

/// Parses script text; `file` names it in errors (`file:line: message`).
pub fn parse(text: &str, file: &str) -> Result<Vec<Pose>, ViewError> {
    let mut poses = Vec::new();
    let mut wireframe = false;
    for (i, raw) in text.lines().enumerate() {
        let line = i + 1;
        let content = raw.split('#').next().unwrap_or("").trim();
        if content.is_empty() {
            continue;
        }
        let words: Vec<&str> = content.split_whitespace().collect();
        if words.first().is_some_and(|w| w.eq_ignore_ascii_case("wireframe")) {
            wireframe = match words.get(1..) {
                Some([v]) if v.eq_ignore_ascii_case("on") => true,
                Some([v]) if v.eq_ignore_ascii_case("off") => false,
                _ => {
                    return Err(script_error(
                        file,
                        line,
                        format!("expected `wireframe on` or `wireframe off`, found {content:?}"),
                    ))
                }
            };
            continue;
        }
        let fields: Vec<&str> = content
            .split(|c: char| c == ',' || c.is_whitespace())
            .filter(|s| !s.is_empty() && !s.eq_ignore_ascii_case("eye") && !s.eq_ignore_ascii_case("target"))
            .collect();
        if fields.len() != 6 {
            return Err(script_error(
                file,
                line,
                format!("expected 6 numbers (eye x y z target x y z), found {} in {content:?}", fields.len()),
            ));
        }
        let mut v = [0.0f64; 6];
        for (slot, field) in v.iter_mut().zip(&fields) {
            *slot = field
                .parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| script_error(file, line, format!("{field:?} is not a finite number")))?;
        }
        let pose = Pose { eye: [v[0], v[1], v[2]], target: [v[3], v[4], v[5]], wireframe };
        if pose.eye == pose.target {
            return Err(script_error(file, line, "the eye and the target must differ"));
        }
        poses.push(pose);
    }
    if poses.is_empty() {
        return Err(script_error(file, 0, "no camera poses in the script"));
    }
    Ok(poses)
}

/// Reads and parses a script file.
pub fn load(path: &Path) -> Result<Vec<Pose>, ViewError> {
    let name = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|source| ViewError::Io { path: name.clone(), source })?;
    parse(&text, &name)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn both_spellings_comments_and_commas() {
        let text = "# a path\neye 1 2 3 target 0 0 0\n\n4,5,6, 0,1,0  # trailing comment\n";
        let p = parse(text, "t.path").expect("valid");
        assert_eq!(
            p,
            vec![
                Pose { eye: [1.0, 2.0, 3.0], target: [0.0; 3], wireframe: false },
                Pose { eye: [4.0, 5.0, 6.0], target: [0.0, 1.0, 0.0], wireframe: false }
            ]
        );
    }

    #[test]
    fn flythrough_files_are_scripts() {
        let text = include_str!("../../../bench/sponza.flythrough");
        assert!(parse(text, "sponza.flythrough").expect("valid").len() > 3);
    }

    #[test]
    fn wrong_count_names_file_and_line() {
        let err = parse("1 2 3 4 5 6\n1 2 3 4 5\n", "cam.txt").expect_err("five numbers");
        assert!(err.to_string().starts_with("cam.txt:2:"), "{err}");
    }

    #[test]
    fn non_numbers_and_infinities_are_errors() {
        assert!(parse("1 2 x 4 5 6", "a").expect_err("x").to_string().contains("\"x\""));
        assert!(parse("1 2 inf 4 5 6", "a").is_err());
        assert!(parse("1 2 NaN 4 5 6", "a").is_err());
    }

    #[test]
    fn eye_equal_to_target_is_an_error() {
        assert!(parse("1 1 1 1 1 1", "a").expect_err("degenerate").to_string().contains("a:1:"));
    }

    #[test]
    fn wireframe_toggles_apply_to_the_following_poses() {
        let text = "1 1 1 0 0 0\nwireframe on\n2 2 2 0 0 0\n3 3 3 0 0 0\nWireframe Off # done\n4 4 4 0 0 0\n";
        let p = parse(text, "t").expect("valid");
        assert_eq!(p.iter().map(|p| p.wireframe).collect::<Vec<_>>(), [false, true, true, false]);
    }

    #[test]
    fn bad_wireframe_toggle_names_file_and_line() {
        let err = parse("1 1 1 0 0 0\nwireframe yes\n", "w.path").expect_err("bad toggle");
        assert!(err.to_string().starts_with("w.path:2:"), "{err}");
        assert!(parse("wireframe\n1 1 1 0 0 0\n", "w").is_err());
        // Only toggles, no pose.
        assert!(parse("wireframe on\n", "w").is_err());
    }

    #[test]
    fn empty_script_is_an_error() {
        assert!(parse("# nothing\n\n", "empty.txt").is_err());
    }
}
