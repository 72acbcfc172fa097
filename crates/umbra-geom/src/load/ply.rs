//! PLY (Stanford polygon file) loader: `ascii`, `binary_little_endian`,
//! `binary_big_endian`.
//!
//! * `vertex` element: `x y z` of any numeric type (required when there are vertices),
//!   optional `nx ny nz` (all three, else no normals; non-finite normals drop the normals
//!   with a warning). Other vertex properties, scalar or list, are skipped.
//! * `face` element: the list property `vertex_indices` (or `vertex_index`) of any integer
//!   types; polygons are fan-triangulated, faces with fewer than 3 indices skipped with a
//!   warning. Indices are checked against the vertex count declared in the header.
//! * Every other element (edges, materials, ...) and property is skipped, lists included;
//!   `tristrips` is skipped with a warning.
//! * Before any allocation, the element counts are checked against the body size: binary
//!   elements need at least the size of their scalar properties and list counts, ASCII
//!   elements at least two bytes per property.
//! * Header lines starting with an unknown keyword are ignored with a warning (free-text
//!   lines written without `comment` by old exporters).
//! * Errors name the header line, the body line (ASCII) or the byte offset (binary).

use super::text::{is_space, parse_f32, parse_i64, show, tokens, Lines};
use super::{LoadError, Location};
use crate::Mesh;

#[derive(Clone, Copy, Debug, PartialEq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn from_name(name: &[u8]) -> Option<Scalar> {
        Some(match name {
            b"char" | b"int8" => Scalar::I8,
            b"uchar" | b"uint8" => Scalar::U8,
            b"short" | b"int16" => Scalar::I16,
            b"ushort" | b"uint16" => Scalar::U16,
            b"int" | b"int32" => Scalar::I32,
            b"uint" | b"uint32" => Scalar::U32,
            b"float" | b"float32" => Scalar::F32,
            b"double" | b"float64" => Scalar::F64,
            _ => return None,
        })
    }
    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }
    fn is_int(self) -> bool {
        !matches!(self, Scalar::F32 | Scalar::F64)
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Kind {
    Scalar(Scalar),
    List { count: Scalar, item: Scalar },
}

#[derive(Debug)]
struct Property {
    name: Vec<u8>,
    kind: Kind,
}

#[derive(Debug)]
struct Element {
    name: Vec<u8>,
    count: u64,
    properties: Vec<Property>,
    header_line: u64,
}

#[derive(Clone, Copy, PartialEq)]
enum Encoding {
    Ascii,
    LittleEndian,
    BigEndian,
}

struct Header {
    encoding: Encoding,
    elements: Vec<Element>,
    /// Byte offset of the body.
    body_start: usize,
    /// Line number of the first body line.
    body_line: u64,
}

pub(crate) fn parse(bytes: &[u8], file: &str, warnings: &mut Vec<String>) -> Result<Mesh, LoadError> {
    let header = parse_header(bytes, file, warnings)?;
    let body = bytes.get(header.body_start..).unwrap_or(&[]);
    check_counts(&header, body.len() as u64, file)?;
    let mut reader = match header.encoding {
        Encoding::Ascii => Body::Ascii { file, tokens: AsciiTokens::new(body, header.body_line) },
        enc => Body::Binary {
            file,
            bytes: body,
            pos: 0,
            base: header.body_start as u64,
            big_endian: enc == Encoding::BigEndian,
        },
    };
    let vertex_count = header.elements.iter().find(|e| e.name == b"vertex").map_or(0, |e| e.count);
    let mut mesh = Mesh::default();
    let mut seen_vertex = false;
    let mut seen_face = false;
    let mut short_faces = 0u64;
    for element in &header.elements {
        match element.name.as_slice() {
            b"vertex" if !seen_vertex => {
                seen_vertex = true;
                read_vertices(element, &mut reader, &mut mesh, file, warnings)?;
            }
            b"face" if !seen_face => {
                seen_face = true;
                short_faces = read_faces(element, &mut reader, &mut mesh, vertex_count, file)?;
            }
            b"vertex" | b"face" => {
                return Err(LoadError::Malformed {
                    file: file.to_string(),
                    location: Location::Line(element.header_line),
                    message: format!("second `{}` element", show(&element.name)),
                })
            }
            name => {
                if name == b"tristrips" && element.count > 0 {
                    warnings.push(format!(
                        "{file}: line {}: `tristrips` element not supported, skipped",
                        element.header_line
                    ));
                }
                skip_element(element, &mut reader)?;
            }
        }
    }
    if short_faces > 0 {
        warnings.push(format!("{file}: skipped {short_faces} face(s) with fewer than 3 vertex indices"));
    }
    Ok(mesh)
}

fn parse_header(bytes: &[u8], file: &str, warnings: &mut Vec<String>) -> Result<Header, LoadError> {
    let malformed = |line: u64, message: String| LoadError::Malformed {
        file: file.to_string(),
        location: Location::Line(line),
        message,
    };
    let mut pos = 0usize;
    let mut line_no = 0u64;
    let mut encoding = None;
    let mut elements: Vec<Element> = Vec::new();
    loop {
        line_no += 1;
        let Some(len) = bytes.get(pos..).and_then(|rest| rest.iter().position(|&b| b == b'\n')) else {
            return Err(LoadError::Truncated {
                file: file.to_string(),
                location: Location::Line(line_no),
                what: if line_no == 1 && bytes.is_empty() {
                    "empty file, expected a `ply` header".into()
                } else {
                    "header has no `end_header` line".into()
                },
            });
        };
        let raw = &bytes[pos..pos + len];
        pos += len + 1;
        let line = raw.strip_suffix(b"\r").unwrap_or(raw);
        if line_no == 1 {
            if line.trim_ascii() != b"ply" {
                return Err(malformed(1, format!("not a PLY file: first line is {:?}, expected `ply`", show(line))));
            }
            continue;
        }
        let mut toks = tokens(line);
        let Some(keyword) = toks.next() else { continue };
        match keyword {
            b"comment" | b"obj_info" => {}
            b"format" => {
                encoding = Some(match toks.next().unwrap_or(b"") {
                    b"ascii" => Encoding::Ascii,
                    b"binary_little_endian" => Encoding::LittleEndian,
                    b"binary_big_endian" => Encoding::BigEndian,
                    other => return Err(malformed(line_no, format!("unknown PLY format {:?}", show(other)))),
                });
            }
            b"element" => {
                let name = toks.next().ok_or_else(|| malformed(line_no, "element without a name".into()))?;
                let count_tok = toks.next().unwrap_or(b"");
                let count = std::str::from_utf8(count_tok)
                    .ok()
                    .and_then(|c| c.parse::<u64>().ok())
                    .ok_or_else(|| malformed(line_no, format!("bad element count {:?}", show(count_tok))))?;
                elements.push(Element { name: name.to_vec(), count, properties: Vec::new(), header_line: line_no });
            }
            b"property" => {
                let element =
                    elements.last_mut().ok_or_else(|| malformed(line_no, "property before any element".into()))?;
                let first = toks.next().unwrap_or(b"");
                let scalar = |tok: &[u8]| {
                    Scalar::from_name(tok)
                        .ok_or_else(|| malformed(line_no, format!("unknown property type {:?}", show(tok))))
                };
                let kind = if first == b"list" {
                    let count = scalar(toks.next().unwrap_or(b""))?;
                    let item = scalar(toks.next().unwrap_or(b""))?;
                    if !count.is_int() {
                        return Err(malformed(line_no, "list count type must be an integer type".into()));
                    }
                    Kind::List { count, item }
                } else {
                    Kind::Scalar(scalar(first)?)
                };
                let name = toks.next().ok_or_else(|| malformed(line_no, "property without a name".into()))?;
                element.properties.push(Property { name: name.to_vec(), kind });
            }
            b"end_header" => break,
            // free text without `comment` (Blender 2.47 wrote "Created by Blender3D ..."):
            // skipped like a comment, as other readers do, but not silently
            other => {
                warnings.push(format!("{file}: line {line_no}: unknown header keyword {:?}, line ignored", show(other)))
            }
        }
    }
    let encoding = encoding.ok_or_else(|| malformed(line_no, "header has no `format` line".into()))?;
    Ok(Header { encoding, elements, body_start: pos, body_line: line_no + 1 })
}

/// Rejects headers whose element counts cannot fit in the body, before anything is allocated.
fn check_counts(header: &Header, body_len: u64, file: &str) -> Result<(), LoadError> {
    let mut needed: u64 = 0;
    for e in &header.elements {
        let min_size: u64 = match header.encoding {
            Encoding::Ascii => 2 * e.properties.len() as u64,
            _ => e
                .properties
                .iter()
                .map(|p| match p.kind {
                    Kind::Scalar(s) => s.size() as u64,
                    Kind::List { count, .. } => count.size() as u64,
                })
                .sum(),
        };
        if min_size == 0 {
            continue;
        }
        let available = body_len.saturating_sub(needed);
        // an ASCII file may lack the final separator: one byte of slack
        let slack = u64::from(header.encoding == Encoding::Ascii);
        let total = e.count.checked_mul(min_size);
        match total {
            Some(t) if t <= available + slack => needed = needed.saturating_add(t),
            _ => {
                return Err(LoadError::TooManyElements {
                    file: file.to_string(),
                    location: Location::Line(e.header_line),
                    what: format!("`{}` elements of at least {min_size} bytes each", show(&e.name)),
                    claimed: e.count,
                    available,
                    max_possible: (available + slack) / min_size,
                })
            }
        }
    }
    Ok(())
}

fn read_vertices(
    element: &Element,
    reader: &mut Body,
    mesh: &mut Mesh,
    file: &str,
    warnings: &mut Vec<String>,
) -> Result<(), LoadError> {
    if element.count > u64::from(u32::MAX) {
        return Err(LoadError::Malformed {
            file: file.to_string(),
            location: Location::Line(element.header_line),
            message: format!("{} vertices do not fit 32-bit indices", element.count),
        });
    }
    // slot of each property: 0-2 position, 3-5 normal, None skipped
    let slots: Vec<Option<usize>> = element
        .properties
        .iter()
        .map(|p| {
            [&b"x"[..], b"y", b"z", b"nx", b"ny", b"nz"]
                .iter()
                .position(|n| *n == p.name.as_slice())
                .filter(|_| matches!(p.kind, Kind::Scalar(_)))
        })
        .collect();
    let has = |k: usize| slots.contains(&Some(k));
    if element.count > 0 && !(has(0) && has(1) && has(2)) {
        let missing: Vec<&str> =
            ["x", "y", "z"].into_iter().enumerate().filter(|&(k, _)| !has(k)).map(|(_, n)| n).collect();
        return Err(LoadError::Malformed {
            file: file.to_string(),
            location: Location::Line(element.header_line),
            message: format!(
                "vertex element lacks scalar propert{} {}",
                if missing.len() == 1 { "y" } else { "ies" },
                missing.join(", ")
            ),
        });
    }
    let with_normals = has(3) && has(4) && has(5);
    let count = element.count as usize;
    mesh.positions.reserve(count);
    let mut normals = if with_normals { Vec::with_capacity(count) } else { Vec::new() };
    let mut normals_finite = true;
    for _ in 0..count {
        let mut v = [0f32; 6];
        for (p, slot) in element.properties.iter().zip(&slots) {
            match (p.kind, slot) {
                (Kind::Scalar(s), Some(k)) => {
                    let (value, at) = reader.read_f32(s)?;
                    if *k < 3 && !value.is_finite() {
                        return Err(LoadError::NonFinite {
                            file: file.to_string(),
                            location: at,
                            value: value.to_string(),
                        });
                    }
                    if let Some(c) = v.get_mut(*k) {
                        *c = value;
                    }
                }
                (kind, _) => reader.skip(kind)?,
            }
        }
        mesh.positions.push([v[0], v[1], v[2]]);
        if with_normals {
            normals_finite &= v[3..].iter().all(|c| c.is_finite());
            normals.push([v[3], v[4], v[5]]);
        }
    }
    if with_normals && !normals_finite {
        warnings.push(format!("{file}: vertex normals dropped: some are not finite"));
    }
    mesh.normals = (with_normals && normals_finite).then_some(normals);
    Ok(())
}

/// Reads the faces, fan-triangulating; returns how many had fewer than 3 indices.
fn read_faces(
    element: &Element,
    reader: &mut Body,
    mesh: &mut Mesh,
    vertex_count: u64,
    file: &str,
) -> Result<u64, LoadError> {
    let index_prop = element.properties.iter().position(|p| p.name == b"vertex_indices" || p.name == b"vertex_index");
    let index_prop = match index_prop {
        Some(i) => i,
        None if element.count == 0 => return skip_element(element, reader).map(|_| 0),
        None => {
            return Err(LoadError::Malformed {
                file: file.to_string(),
                location: Location::Line(element.header_line),
                message: "face element has no `vertex_indices` list property".into(),
            })
        }
    };
    let (count_type, item_type) = match element.properties.get(index_prop).map(|p| p.kind) {
        Some(Kind::List { count, item }) if item.is_int() => (count, item),
        _ => {
            return Err(LoadError::Malformed {
                file: file.to_string(),
                location: Location::Line(element.header_line),
                message: "`vertex_indices` must be a list of an integer type".into(),
            })
        }
    };
    mesh.triangles.reserve(element.count as usize);
    let mut face: Vec<u32> = Vec::new();
    let mut short = 0u64;
    for _ in 0..element.count {
        for (i, p) in element.properties.iter().enumerate() {
            if i != index_prop {
                reader.skip(p.kind)?;
                continue;
            }
            let (n, at) = reader.read_int(count_type)?;
            let n = u64::try_from(n).map_err(|_| LoadError::Malformed {
                file: file.to_string(),
                location: at,
                message: format!("negative list length {n}"),
            })?;
            face.clear();
            for _ in 0..n {
                let (index, at) = reader.read_int(item_type)?;
                if index < 0 || index as u64 >= vertex_count {
                    return Err(LoadError::IndexOutOfRange {
                        file: file.to_string(),
                        location: at,
                        index,
                        count: vertex_count,
                    });
                }
                face.push(index as u32);
            }
            if face.len() < 3 {
                short += 1;
            } else {
                let first = face[0];
                mesh.triangles.extend(face[1..].windows(2).map(|w| [first, w[0], w[1]]));
            }
        }
    }
    Ok(short)
}

fn skip_element(element: &Element, reader: &mut Body) -> Result<(), LoadError> {
    if element.properties.is_empty() {
        return Ok(());
    }
    // fast path: binary fixed-size elements are skipped in one step
    if let Body::Binary { .. } = reader {
        let fixed: Option<usize> = element
            .properties
            .iter()
            .map(|p| match p.kind {
                Kind::Scalar(s) => Some(s.size()),
                Kind::List { .. } => None,
            })
            .sum();
        if let Some(size) = fixed {
            let total = element.count.checked_mul(size as u64).and_then(|t| usize::try_from(t).ok());
            return reader.skip_bytes(total.unwrap_or(usize::MAX));
        }
    }
    for _ in 0..element.count {
        for p in &element.properties {
            reader.skip(p.kind)?;
        }
    }
    Ok(())
}

/// Whitespace-separated tokens across lines, with their line numbers.
struct AsciiTokens<'a> {
    lines: Lines<'a>,
    line: &'a [u8],
    line_no: u64,
}

impl<'a> AsciiTokens<'a> {
    fn new(body: &'a [u8], first_line: u64) -> Self {
        AsciiTokens { lines: Lines::new(body, first_line), line: &[], line_no: first_line.saturating_sub(1) }
    }
    fn next(&mut self) -> Option<(&'a [u8], u64)> {
        loop {
            let start = self.line.iter().position(|&b| !is_space(b));
            match start {
                Some(s) => {
                    let rest = &self.line[s..];
                    let end = rest.iter().position(|&b| is_space(b)).unwrap_or(rest.len());
                    self.line = &rest[end..];
                    return Some((&rest[..end], self.line_no));
                }
                None => {
                    let (no, line) = self.lines.next()?;
                    self.line = line;
                    self.line_no = no;
                }
            }
        }
    }
}

enum Body<'a> {
    Ascii { file: &'a str, tokens: AsciiTokens<'a> },
    Binary { file: &'a str, bytes: &'a [u8], pos: usize, base: u64, big_endian: bool },
}

impl<'a> Body<'a> {
    fn truncated(&self, what: &str) -> LoadError {
        match self {
            Body::Ascii { file, tokens } => LoadError::Truncated {
                file: file.to_string(),
                location: Location::Line(tokens.line_no.max(1)),
                what: format!("file ends while reading {what}"),
            },
            Body::Binary { file, bytes, base, .. } => LoadError::Truncated {
                file: file.to_string(),
                location: Location::Byte(base + bytes.len() as u64),
                what: format!("file ends while reading {what}"),
            },
        }
    }

    fn token(&mut self) -> Result<(&'a [u8], u64), LoadError> {
        match self {
            Body::Ascii { tokens, .. } => match tokens.next() {
                Some(t) => Ok(t),
                None => Err(self.truncated("a property value")),
            },
            Body::Binary { .. } => Err(self.truncated("a property value")),
        }
    }

    /// The raw bytes of one binary scalar and its file offset.
    fn raw(&mut self, size: usize) -> Result<([u8; 8], u64), LoadError> {
        let Body::Binary { bytes, pos, base, big_endian, .. } = self else {
            return Err(self.truncated("a property value"));
        };
        let at = *base + *pos as u64;
        let Some(src) = bytes.get(*pos..*pos + size) else {
            return Err(self.truncated("a property value"));
        };
        *pos += size;
        let mut out = [0u8; 8];
        // normalise to little-endian order in out[..size]
        for (i, &b) in src.iter().enumerate() {
            let j = if *big_endian { size - 1 - i } else { i };
            if let Some(o) = out.get_mut(j) {
                *o = b;
            }
        }
        Ok((out, at))
    }

    fn read_f32(&mut self, s: Scalar) -> Result<(f32, Location), LoadError> {
        if let Body::Ascii { file, .. } = self {
            let file = *file;
            let (tok, line) = self.token()?;
            let v = parse_f32(tok).ok_or_else(|| LoadError::Malformed {
                file: file.to_string(),
                location: Location::Line(line),
                message: format!("malformed number {:?}", show(tok)),
            })?;
            return Ok((v, Location::Line(line)));
        }
        let (b, at) = self.raw(s.size())?;
        let v = match s {
            Scalar::F32 => f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
            Scalar::F64 => f64::from_le_bytes(b) as f32,
            _ => int_from_le(s, b) as f32,
        };
        Ok((v, Location::Byte(at)))
    }

    fn read_int(&mut self, s: Scalar) -> Result<(i64, Location), LoadError> {
        if let Body::Ascii { file, .. } = self {
            let file = *file;
            let (tok, line) = self.token()?;
            let v = parse_i64(tok).ok_or_else(|| LoadError::Malformed {
                file: file.to_string(),
                location: Location::Line(line),
                message: format!("malformed integer {:?}", show(tok)),
            })?;
            return Ok((v, Location::Line(line)));
        }
        let (b, at) = self.raw(s.size())?;
        Ok((int_from_le(s, b), Location::Byte(at)))
    }

    fn skip(&mut self, kind: Kind) -> Result<(), LoadError> {
        match kind {
            Kind::Scalar(s) => self.skip_scalar(s),
            Kind::List { count, item } => {
                let (n, at) = self.read_int(count)?;
                if n < 0 {
                    return Err(LoadError::Malformed {
                        file: self.file().to_string(),
                        location: at,
                        message: format!("negative list length {n}"),
                    });
                }
                if let Body::Binary { .. } = self {
                    let bytes = (n as u64).checked_mul(item.size() as u64).and_then(|b| usize::try_from(b).ok());
                    return self.skip_bytes(bytes.unwrap_or(usize::MAX));
                }
                for _ in 0..n {
                    self.skip_scalar(item)?;
                }
                Ok(())
            }
        }
    }

    fn skip_scalar(&mut self, s: Scalar) -> Result<(), LoadError> {
        match self {
            Body::Ascii { .. } => self.token().map(|_| ()),
            Body::Binary { .. } => self.skip_bytes(s.size()),
        }
    }

    fn skip_bytes(&mut self, n: usize) -> Result<(), LoadError> {
        match self {
            Body::Binary { bytes, pos, .. } if bytes.len().saturating_sub(*pos) >= n => {
                *pos += n;
                Ok(())
            }
            _ => Err(self.truncated("skipped properties")),
        }
    }

    fn file(&self) -> &'a str {
        match self {
            Body::Ascii { file, .. } | Body::Binary { file, .. } => file,
        }
    }
}

/// An integer scalar from its little-endian bytes (floats are truncated toward zero).
fn int_from_le(s: Scalar, b: [u8; 8]) -> i64 {
    match s {
        Scalar::I8 => i64::from(b[0] as i8),
        Scalar::U8 => i64::from(b[0]),
        Scalar::I16 => i64::from(i16::from_le_bytes([b[0], b[1]])),
        Scalar::U16 => i64::from(u16::from_le_bytes([b[0], b[1]])),
        Scalar::I32 => i64::from(i32::from_le_bytes([b[0], b[1], b[2], b[3]])),
        Scalar::U32 => i64::from(u32::from_le_bytes([b[0], b[1], b[2], b[3]])),
        Scalar::F32 => f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as i64,
        Scalar::F64 => f64::from_le_bytes(b) as i64,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Regression (assimp-testmodels `PLY/Wuson.ply`, Blender 2.47): a free-text header
    /// line without the `comment` keyword made the whole file an error.
    #[test]
    fn regression_assimp_wuson_ply_free_text_header_line() {
        let text = "ply\nformat ascii 1.0\nCreated by Blender3D 247 - www.blender.org, source file: \n\
                    element vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
                    element face 1\nproperty list uchar int vertex_indices\nend_header\n\
                    0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
        let mut warnings = Vec::new();
        let mesh = parse(text.as_bytes(), "Wuson.ply", &mut warnings).unwrap();
        assert_eq!(mesh.positions, vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
        assert_eq!(mesh.triangles, vec![[0, 1, 2]]);
        assert_eq!(warnings.len(), 1, "{warnings:?}");
        assert!(warnings[0].contains("Wuson.ply: line 3") && warnings[0].contains("Created"), "{warnings:?}");
    }
}
