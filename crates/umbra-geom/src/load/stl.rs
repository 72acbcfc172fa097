//! STL loader, ASCII and binary.
//!
//! * Binary: 80-byte header, little-endian u32 facet count, 50 bytes per facet (normal,
//!   three vertices as 3 x f32 each, u16 attribute). The count is checked against the file
//!   size before anything is allocated.
//! * Detection: a file whose size is exactly `84 + 50 * count` is binary even when its
//!   header starts with `solid` (many exporters write that); otherwise a file starting with
//!   `solid` and whose first 4 KiB are printable ASCII is ASCII; anything else is binary
//!   (trailing bytes after the last facet are ignored with a warning).
//! * ASCII: `solid` / `facet normal` / `outer loop` / `vertex` / `endloop` / `endfacet` /
//!   `endsolid`, several solids allowed; a facet with more than three vertices is
//!   fan-triangulated. Keywords are matched case-insensitively.
//! * STL shares no vertices: every facet yields three new vertices (weld later). Facet
//!   normals become per-vertex normals, unless some facet normal is zero or not finite, in
//!   which case normals are dropped (many exporters write zeros).

use super::text::{parse_f32, show, tokens, Lines};
use super::{LoadError, Location};
use crate::Mesh;

const HEADER: usize = 80;
const FACET: u64 = 50;

pub(crate) fn parse(bytes: &[u8], file: &str, warnings: &mut Vec<String>) -> Result<Mesh, LoadError> {
    let count = bytes.get(HEADER..HEADER + 4).map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]));
    let exact_binary = count.is_some_and(|c| 84 + FACET * u64::from(c) == bytes.len() as u64);
    let starts_solid = {
        let start = bytes.iter().position(|&b| !b.is_ascii_whitespace()).unwrap_or(bytes.len());
        bytes.get(start..start + 5).is_some_and(|s| s.eq_ignore_ascii_case(b"solid"))
    };
    // a binary file with a `solid` header but a wrong size has control or high bytes early on
    let looks_text = bytes.iter().take(4096).all(|&b| b.is_ascii_graphic() || b.is_ascii_whitespace());
    if exact_binary || !starts_solid || !looks_text {
        parse_binary(bytes, file, warnings)
    } else {
        parse_ascii(bytes, file)
    }
}

fn parse_binary(bytes: &[u8], file: &str, warnings: &mut Vec<String>) -> Result<Mesh, LoadError> {
    let Some(c) = bytes.get(HEADER..HEADER + 4) else {
        return Err(LoadError::Truncated {
            file: file.to_string(),
            location: Location::Byte(bytes.len() as u64),
            what: format!(
                "binary STL needs an 84-byte header (80 bytes + facet count), the file has {} bytes",
                bytes.len()
            ),
        });
    };
    let count = u64::from(u32::from_le_bytes([c[0], c[1], c[2], c[3]]));
    let available = bytes.len() as u64 - 84;
    if count * FACET > available {
        return Err(LoadError::TooManyElements {
            file: file.to_string(),
            location: Location::Byte(80),
            what: "facets".into(),
            claimed: count,
            available,
            max_possible: available / FACET,
        });
    }
    if count * FACET < available {
        warnings.push(format!(
            "{file}: byte offset {}: ignored {} bytes after the last of {count} facets",
            84 + count * FACET,
            available - count * FACET
        ));
    }
    let count = count as usize; // count * 50 <= bytes.len(), so it fits
    let mut positions = Vec::with_capacity(3 * count);
    let mut normals = Vec::with_capacity(3 * count);
    let mut normals_valid = true;
    let body = bytes.get(84..).unwrap_or(&[]);
    for (i, facet) in body.chunks_exact(FACET as usize).take(count).enumerate() {
        let f = |k: usize| f32::from_le_bytes([facet[4 * k], facet[4 * k + 1], facet[4 * k + 2], facet[4 * k + 3]]);
        let n = [f(0), f(1), f(2)];
        normals_valid &= n.iter().all(|c| c.is_finite()) && n != [0.0; 3];
        for v in 0..3 {
            let p = [f(3 + 3 * v), f(4 + 3 * v), f(5 + 3 * v)];
            if let Some(k) = p.iter().position(|c| !c.is_finite()) {
                return Err(LoadError::NonFinite {
                    file: file.to_string(),
                    location: Location::Byte(84 + i as u64 * FACET + 12 + 12 * v as u64 + 4 * k as u64),
                    value: p[k].to_string(),
                });
            }
            positions.push(p);
            normals.push(n);
        }
    }
    Ok(soup(positions, normals, normals_valid))
}

/// Three vertices per facet, triangles `[3i, 3i+1, 3i+2]`.
fn soup(positions: Vec<[f32; 3]>, normals: Vec<[f32; 3]>, normals_valid: bool) -> Mesh {
    let triangles = (0..positions.len() as u32 / 3).map(|i| [3 * i, 3 * i + 1, 3 * i + 2]).collect();
    let normals = (normals_valid && !positions.is_empty()).then_some(normals);
    Mesh { positions, triangles, normals }
}

#[derive(PartialEq)]
enum State {
    /// Outside `solid ... endsolid`.
    Outside,
    /// Inside a solid, between facets.
    Solid,
    /// Inside `facet ... endfacet`.
    Facet,
}

fn parse_ascii(bytes: &[u8], file: &str) -> Result<Mesh, LoadError> {
    let mut positions = Vec::new();
    let mut normals = Vec::new();
    let mut normals_valid = true;
    let mut facet: Vec<[f32; 3]> = Vec::new();
    let mut facet_normal = [0f32; 3];
    let mut state = State::Outside;
    let mut last_line = 0;
    for (line_no, line) in Lines::new(bytes, 1) {
        last_line = line_no;
        let at = Location::Line(line_no);
        let malformed =
            |message: String| LoadError::Malformed { file: file.to_string(), location: at.clone(), message };
        let mut toks = tokens(line);
        let Some(keyword) = toks.next() else { continue };
        let kw = keyword.to_ascii_lowercase();
        match (kw.as_slice(), &state) {
            (b"solid", State::Outside) => state = State::Solid,
            (b"endsolid", State::Solid) => state = State::Outside,
            (b"facet", State::Solid) => {
                let normal_kw = toks.next().unwrap_or(b"");
                if !normal_kw.eq_ignore_ascii_case(b"normal") {
                    return Err(malformed(format!("expected `facet normal`, found {:?}", show(normal_kw))));
                }
                facet_normal = three_numbers(&mut toks, file, &at, false)?;
                facet.clear();
                state = State::Facet;
            }
            (b"outer", State::Facet) | (b"endloop", State::Facet) => {}
            (b"vertex", State::Facet) => facet.push(three_numbers(&mut toks, file, &at, true)?),
            (b"endfacet", State::Facet) => {
                if facet.len() < 3 {
                    return Err(malformed(format!("facet has {} vertices, needs at least 3", facet.len())));
                }
                normals_valid &= facet_normal.iter().all(|c| c.is_finite()) && facet_normal != [0.0; 3];
                for pair in facet[1..].windows(2) {
                    positions.extend_from_slice(&[facet[0], pair[0], pair[1]]);
                    normals.extend_from_slice(&[facet_normal; 3]);
                }
                state = State::Solid;
            }
            _ => {
                return Err(malformed(format!(
                    "unexpected {:?} {}",
                    show(keyword),
                    match state {
                        State::Outside => "outside a solid (expected `solid`)",
                        State::Solid => "inside a solid (expected `facet` or `endsolid`)",
                        State::Facet => "inside a facet (expected `outer loop`, `vertex`, `endloop` or `endfacet`)",
                    }
                )));
            }
        }
    }
    if state != State::Outside {
        return Err(LoadError::Truncated {
            file: file.to_string(),
            location: Location::Line(last_line),
            what: format!("file ends inside a {}", if state == State::Facet { "facet" } else { "solid" }),
        });
    }
    Ok(soup(positions, normals, normals_valid))
}

fn three_numbers<'a>(
    toks: &mut impl Iterator<Item = &'a [u8]>,
    file: &str,
    at: &Location,
    must_be_finite: bool,
) -> Result<[f32; 3], LoadError> {
    let mut out = [0f32; 3];
    for (k, c) in out.iter_mut().enumerate() {
        let tok = toks.next().ok_or_else(|| LoadError::Malformed {
            file: file.to_string(),
            location: at.clone(),
            message: format!("expected 3 numbers, found {k}"),
        })?;
        *c = parse_f32(tok).ok_or_else(|| LoadError::Malformed {
            file: file.to_string(),
            location: at.clone(),
            message: format!("malformed number {:?}", show(tok)),
        })?;
        if must_be_finite && !c.is_finite() {
            return Err(LoadError::NonFinite { file: file.to_string(), location: at.clone(), value: show(tok) });
        }
    }
    Ok(out)
}
