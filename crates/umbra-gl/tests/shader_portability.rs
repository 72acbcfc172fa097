//! GLSL that Mesa accepts but another vendor's compiler rejects, caught here without that GPU.
//!
//! Each pattern fails on an NVIDIA H100 (driver 580.159) while llvmpipe passes every test:
//! - `dvec2(1.0e300)`: an unsuffixed literal is a `float` (GLSL 4.50, 4.1.4), and 1e300 is
//!   beyond its range. Mesa quietly makes it infinity; NVIDIA fails the compile with
//!   "C0153: floating point constant overflow", and the program does not link. A double
//!   literal needs `lf` (`1.0e300LF`).
//!
//! A depth-first walk written as one constant-bound loop per level (which NVIDIA's compiler
//! unrolls 16^7 times and never finishes linking) is not a lexical pattern;
//! hier/walk.comp.glsl and hier_triangle/traverse.comp.glsl say how their walks are written
//! instead.

use std::path::{Path, PathBuf};

fn glsl_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display())) {
        let path = entry.expect("directory entry").path();
        if path.is_dir() {
            glsl_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "glsl") {
            out.push(path);
        }
    }
}

/// The floating-point literals of one line of GLSL with their suffix (`f`, `lf`, or none), as
/// (text without suffix, suffix, column).
fn float_literals(line: &str) -> Vec<(String, String, usize)> {
    let code = line.split("//").next().unwrap_or("");
    let bytes = code.as_bytes();
    let mut found = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        let c = bytes[i];
        let starts_number = (c.is_ascii_digit() || (c == b'.' && bytes.get(i + 1).is_some_and(u8::is_ascii_digit)))
            && (i == 0 || !(bytes[i - 1].is_ascii_alphanumeric() || bytes[i - 1] == b'_' || bytes[i - 1] == b'.'));
        if !starts_number {
            i += 1;
            continue;
        }
        let start = i;
        while i < bytes.len() && (bytes[i].is_ascii_digit() || bytes[i] == b'.') {
            i += 1;
        }
        let mut is_float = code[start..i].contains('.');
        if i < bytes.len() && (bytes[i] == b'e' || bytes[i] == b'E') {
            let mut j = i + 1;
            if j < bytes.len() && (bytes[j] == b'+' || bytes[j] == b'-') {
                j += 1;
            }
            if j < bytes.len() && bytes[j].is_ascii_digit() {
                while j < bytes.len() && bytes[j].is_ascii_digit() {
                    j += 1;
                }
                i = j;
                is_float = true;
            }
        }
        let text = code[start..i].to_string();
        let suffix_start = i;
        while i < bytes.len() && bytes[i].is_ascii_alphabetic() {
            i += 1;
        }
        let suffix = code[suffix_start..i].to_ascii_lowercase();
        if is_float || suffix == "f" || suffix == "lf" {
            found.push((text, suffix, start + 1));
        }
    }
    found
}

#[test]
fn the_literal_scanner_reads_suffixes_and_exponents() {
    let got = float_literals("dvec2 a = dvec2(1.0e300LF) + 2.5 * x1.0; float b = 3e38f; // 1e999");
    let got: Vec<(&str, &str)> = got.iter().map(|(t, s, _)| (t.as_str(), s.as_str())).collect();
    assert_eq!(got, [("1.0e300", "lf"), ("2.5", ""), ("3e38", "f")]);
    assert!(float_literals("uint k = 65535u; vec4 v4;").is_empty());
}

#[test]
fn no_float_literal_lies_beyond_the_range_of_its_type() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    glsl_files(&root, &mut files);
    assert!(files.len() > 20, "only {} GLSL files under {}", files.len(), root.display());
    let mut bad = Vec::new();
    for file in &files {
        let text = std::fs::read_to_string(file).expect("GLSL source");
        for (n, line) in text.lines().enumerate() {
            for (literal, suffix, column) in float_literals(line) {
                let value: f64 = literal.parse().unwrap_or(f64::INFINITY);
                if suffix != "lf" && value.abs() > f64::from(f32::MAX) {
                    bad.push(format!(
                        "{}:{}:{column}: {literal}{suffix} is a float beyond f32's range (write {literal}LF for a double)",
                        file.strip_prefix(&root).unwrap_or(file).display(),
                        n + 1
                    ));
                }
            }
        }
    }
    assert!(bad.is_empty(), "{}", bad.join("\n"));
}
