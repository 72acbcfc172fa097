//! Wavefront OBJ loader (the polygonal subset: `v`, `vn`, `f`).
//!
//! * `v x y z [w]`: the optional `w` (and the `r g b` colour extension some exporters
//!   append) is ignored; a position is never divided by `w`.
//! * `f` vertices may be `v`, `v/vt`, `v//vn` or `v/vt/vn`; indices are 1-based, negative
//!   ones relative to the vertices defined so far; an index must refer to an already
//!   defined vertex; `vt` indices are syntax-checked only (texture coordinates are not
//!   loaded). Polygons are fan-triangulated from their first vertex; faces with
//!   fewer than three vertices are skipped with a warning.
//! * Triangles index the `v` list directly (no vertex splitting), so the vertex count is the
//!   number of `v` statements. Normals are returned only when every face vertex has a
//!   `vn` and each position is always paired with the same normal (unreferenced positions
//!   get a zero normal); otherwise they are dropped with a warning.
//! * `vt`, `o`, `g`, `s`, `usemtl`, `mtllib`, `l`, `p`, curves and unknown statements are
//!   ignored; `#` starts a comment; a UTF-8 BOM is skipped; a file starting with a UTF-16
//!   byte-order mark is converted to UTF-8 first (assimp's `box_UTF16BE.obj`, which would
//!   otherwise load silently as an empty mesh); `\` line continuation is not supported.

use super::text::{parse_f32, parse_i64, show, tokens, utf16_to_utf8, Lines};
use super::{LoadError, Location};
use crate::Mesh;

const UNSET: u32 = u32::MAX;

pub(crate) fn parse(bytes: &[u8], file: &str, warnings: &mut Vec<String>) -> Result<Mesh, LoadError> {
    if let Some(utf8) = utf16_to_utf8(bytes, file)? {
        return parse_utf8(&utf8, file, warnings);
    }
    parse_utf8(bytes, file, warnings)
}

fn parse_utf8(bytes: &[u8], file: &str, warnings: &mut Vec<String>) -> Result<Mesh, LoadError> {
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    let mut positions: Vec<[f32; 3]> = Vec::new();
    let mut vns: Vec<[f32; 3]> = Vec::new();
    let mut triangles: Vec<[u32; 3]> = Vec::new();
    // normal index each position is used with, while normals are still consistent
    let mut normal_of: Vec<u32> = Vec::new();
    let mut normals_consistent = true;
    let mut drop_reason = "";
    let mut short_faces = 0u64;
    let mut first_short_face = 0u64;
    let mut face: Vec<(u32, Option<u32>)> = Vec::new();

    for (line_no, line) in Lines::new(bytes, 1) {
        let line = match line.iter().position(|&b| b == b'#') {
            Some(i) => &line[..i],
            None => line,
        };
        let mut toks = tokens(line);
        let Some(keyword) = toks.next() else { continue };
        let at = || Location::Line(line_no);
        match keyword {
            b"v" | b"vn" => {
                let mut xyz = [0f32; 3];
                for (k, c) in xyz.iter_mut().enumerate() {
                    let tok = toks.next().ok_or_else(|| LoadError::Malformed {
                        file: file.to_string(),
                        location: at(),
                        message: format!("`{}` statement has {k} coordinates, needs 3", show(keyword)),
                    })?;
                    *c = coordinate(tok, file, at)?;
                }
                if keyword == b"v" {
                    if positions.len() >= UNSET as usize {
                        return Err(too_many(file, at(), "vertices"));
                    }
                    positions.push(xyz);
                    if normals_consistent {
                        normal_of.push(UNSET);
                    }
                } else {
                    if vns.len() >= UNSET as usize {
                        return Err(too_many(file, at(), "normals"));
                    }
                    vns.push(xyz);
                }
            }
            b"f" | b"fo" => {
                face.clear();
                for tok in toks {
                    face.push(face_vertex(tok, positions.len(), vns.len(), file, line_no)?);
                }
                if face.len() < 3 {
                    if short_faces == 0 {
                        first_short_face = line_no;
                    }
                    short_faces += 1;
                    continue;
                }
                if normals_consistent {
                    for &(v, n) in &face {
                        let Some(n) = n else {
                            normals_consistent = false;
                            drop_reason = "some face vertices have no normal index";
                            break;
                        };
                        let slot = &mut normal_of[v as usize];
                        if *slot == UNSET {
                            *slot = n;
                        } else if *slot != n && vns[*slot as usize] != vns[n as usize] {
                            normals_consistent = false;
                            drop_reason = "a position is used with different normals";
                            break;
                        }
                    }
                    if !normals_consistent {
                        normal_of = Vec::new();
                    }
                }
                let first = face[0].0;
                for pair in face[1..].windows(2) {
                    triangles.push([first, pair[0].0, pair[1].0]);
                }
            }
            _ => {}
        }
    }
    if short_faces > 0 {
        warnings
            .push(format!("{file}: line {first_short_face}: skipped {short_faces} face(s) with fewer than 3 vertices"));
    }
    let normals = if normals_consistent && !vns.is_empty() && !triangles.is_empty() {
        Some(normal_of.iter().map(|&n| vns.get(n as usize).copied().unwrap_or([0.0; 3])).collect())
    } else {
        if !vns.is_empty() && !triangles.is_empty() {
            warnings.push(format!("{file}: vertex normals dropped: {drop_reason}"));
        }
        None
    };
    Ok(Mesh { positions, triangles, normals })
}

fn too_many(file: &str, location: Location, what: &str) -> LoadError {
    LoadError::Malformed { file: file.to_string(), location, message: format!("more than {UNSET} {what}") }
}

fn coordinate(tok: &[u8], file: &str, at: impl Fn() -> Location) -> Result<f32, LoadError> {
    let v = parse_f32(tok).ok_or_else(|| LoadError::Malformed {
        file: file.to_string(),
        location: at(),
        message: format!("malformed number {:?}", show(tok)),
    })?;
    if !v.is_finite() {
        return Err(LoadError::NonFinite { file: file.to_string(), location: at(), value: show(tok) });
    }
    Ok(v)
}

/// Parses `v`, `v/vt`, `v//vn` or `v/vt/vn` into 0-based (position, normal) indices.
fn face_vertex(
    tok: &[u8],
    n_positions: usize,
    n_normals: usize,
    file: &str,
    line_no: u64,
) -> Result<(u32, Option<u32>), LoadError> {
    let mut parts = tok.split(|&b| b == b'/');
    let v = parts.next().unwrap_or(&[]);
    let vt = parts.next();
    let vn = parts.next();
    if parts.next().is_some() {
        return Err(malformed_index(tok, file, line_no));
    }
    let v = resolve(v, n_positions, tok, file, line_no)?;
    if let Some(vt) = vt {
        if !vt.is_empty() && parse_i64(vt).is_none() {
            return Err(malformed_index(tok, file, line_no));
        }
    }
    let n = match vn {
        Some(vn) if !vn.is_empty() => Some(resolve(vn, n_normals, tok, file, line_no)?),
        Some(_) => return Err(malformed_index(tok, file, line_no)),
        None => None,
    };
    Ok((v, n))
}

fn malformed_index(tok: &[u8], file: &str, line_no: u64) -> LoadError {
    LoadError::Malformed {
        file: file.to_string(),
        location: Location::Line(line_no),
        message: format!("malformed face vertex {:?}", show(tok)),
    }
}

/// A 1-based or negative (relative) OBJ index into a list of `count` items, 0-based.
fn resolve(index: &[u8], count: usize, tok: &[u8], file: &str, line_no: u64) -> Result<u32, LoadError> {
    let i = parse_i64(index).ok_or_else(|| malformed_index(tok, file, line_no))?;
    let count_i = count as i64;
    let zero_based = if i > 0 { i - 1 } else { count_i.saturating_add(i) };
    if i == 0 || zero_based < 0 || zero_based >= count_i {
        return Err(LoadError::IndexOutOfRange {
            file: file.to_string(),
            location: Location::Line(line_no),
            index: i,
            count: count as u64,
        });
    }
    Ok(zero_based as u32)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// UTF-16 text encoded with a byte-order mark.
    fn utf16(text: &str, big_endian: bool) -> Vec<u8> {
        let mut out = if big_endian { vec![0xFE, 0xFF] } else { vec![0xFF, 0xFE] };
        for u in text.encode_utf16() {
            out.extend(if big_endian { u.to_be_bytes() } else { u.to_le_bytes() });
        }
        out
    }

    /// Regression (assimp-testmodels `OBJ/box_UTF16BE.obj`): a UTF-16 big-endian OBJ with a
    /// byte-order mark loaded as an empty mesh, without any error or warning.
    #[test]
    fn regression_assimp_box_utf16be_obj_loads() {
        let text = "# box\r\nv 0 0 0\r\nv 1 0 0\r\nv 0 1 0\r\nv 0 0 1\r\nf 1 2 3\r\nf 1 2 4\r\n";
        let plain = parse(text.as_bytes(), "box.obj", &mut Vec::new()).unwrap();
        assert_eq!(plain.triangles, vec![[0, 1, 2], [0, 1, 3]]);
        for big_endian in [true, false] {
            let mesh = parse(&utf16(text, big_endian), "box_UTF16.obj", &mut Vec::new()).unwrap();
            assert_eq!(mesh, plain, "big endian {big_endian}");
        }
        // errors keep the original line numbers
        let bad = utf16("v 0 0 0\nv 1 0 0\nf 1 2 9\n", true);
        let err = parse(&bad, "bad.obj", &mut Vec::new()).unwrap_err();
        assert_eq!(err.location(), Some(&Location::Line(3)), "{err}");
    }

    #[test]
    fn regression_utf16_odd_length_and_lone_surrogate_are_errors() {
        let mut odd = utf16("v 0 0 0\n", true);
        odd.push(0);
        let err = parse(&odd, "odd.obj", &mut Vec::new()).unwrap_err();
        assert!(matches!(err, LoadError::Truncated { location: Location::Byte(18), .. }), "{err:?}");
        let mut lone = utf16("v", false);
        lone.extend([0x00, 0xD8, b' ', 0]);
        let err = parse(&lone, "lone.obj", &mut Vec::new()).unwrap_err();
        assert!(matches!(err, LoadError::Malformed { location: Location::Byte(4), .. }), "{err:?}");
    }
}
