//! Shared helpers for the text formats (OBJ, ASCII PLY, ASCII STL): line splitting with
//! 1-based line numbers, whitespace tokenising, number parsing on byte slices, and UTF-16
//! (with a byte-order mark) to UTF-8 conversion.

use super::{LoadError, Location};

/// Iterates the lines of `bytes` as `(line_number, line)`, 1-based, without the line
/// terminator (`\n`, `\r\n`, or a lone `\r` at the very end of a line).
pub(crate) struct Lines<'a> {
    rest: &'a [u8],
    line: u64,
    done: bool,
}

impl<'a> Lines<'a> {
    pub(crate) fn new(bytes: &'a [u8], first_line: u64) -> Self {
        Lines { rest: bytes, line: first_line.saturating_sub(1), done: false }
    }
}

impl<'a> Iterator for Lines<'a> {
    type Item = (u64, &'a [u8]);
    fn next(&mut self) -> Option<Self::Item> {
        if self.done {
            return None;
        }
        self.line += 1;
        let (line, rest) = match memchr(b'\n', self.rest) {
            Some(i) => (&self.rest[..i], &self.rest[i + 1..]),
            None => {
                self.done = true;
                if self.rest.is_empty() {
                    return None;
                }
                (self.rest, &self.rest[self.rest.len()..])
            }
        };
        self.rest = rest;
        let line = line.strip_suffix(b"\r").unwrap_or(line);
        Some((self.line, line))
    }
}

fn memchr(needle: u8, haystack: &[u8]) -> Option<usize> {
    haystack.iter().position(|&b| b == needle)
}

#[inline]
pub(crate) fn is_space(b: u8) -> bool {
    matches!(b, b' ' | b'\t' | b'\r' | 0x0b | 0x0c)
}

/// Whitespace-separated tokens of one line.
pub(crate) fn tokens(line: &[u8]) -> impl Iterator<Item = &[u8]> {
    line.split(|&b| is_space(b)).filter(|t| !t.is_empty())
}

/// Parses a decimal float straight to f32 (correctly rounded).
pub(crate) fn parse_f32(token: &[u8]) -> Option<f32> {
    // std's parser is correctly rounded and fast enough (Eisel-Lemire); measured in the
    // load_scenes test on the real scenes.
    std::str::from_utf8(token).ok()?.parse::<f32>().ok()
}

/// Parses an optionally signed decimal integer, `None` on overflow or a bad character.
pub(crate) fn parse_i64(token: &[u8]) -> Option<i64> {
    let (neg, digits) = match token.first()? {
        b'-' => (true, &token[1..]),
        b'+' => (false, &token[1..]),
        _ => (false, token),
    };
    if digits.is_empty() {
        return None;
    }
    let mut v: i64 = 0;
    for &c in digits {
        if !c.is_ascii_digit() {
            return None;
        }
        let d = i64::from(c - b'0');
        v = v.checked_mul(10)?;
        v = if neg { v.checked_sub(d)? } else { v.checked_add(d)? };
    }
    Some(v)
}

/// A token shown in an error message: lossy UTF-8, at most 40 characters.
pub(crate) fn show(token: &[u8]) -> String {
    let s = String::from_utf8_lossy(token);
    let mut out: String = s.chars().take(40).collect();
    if s.chars().count() > 40 {
        out.push('…');
    }
    out
}

/// A UTF-16 text (starting with a byte-order mark, big- or little-endian) re-encoded as
/// UTF-8 without the mark; `Ok(None)` when `bytes` has no UTF-16 byte-order mark. Line
/// breaks are kept, so line numbers stay those of the original file. An unpaired surrogate
/// or an odd byte count is an error at its byte offset.
pub(crate) fn utf16_to_utf8(bytes: &[u8], file: &str) -> Result<Option<Vec<u8>>, LoadError> {
    let big_endian = match bytes.get(..2) {
        Some([0xFE, 0xFF]) => true,
        Some([0xFF, 0xFE]) => false,
        _ => return Ok(None),
    };
    let body = &bytes[2..];
    if !body.len().is_multiple_of(2) {
        return Err(LoadError::Truncated {
            file: file.to_string(),
            location: Location::Byte(bytes.len() as u64 - 1),
            what: "UTF-16 text has an odd number of bytes".into(),
        });
    }
    let units = body.chunks_exact(2).map(|c| {
        if big_endian {
            u16::from_be_bytes([c[0], c[1]])
        } else {
            u16::from_le_bytes([c[0], c[1]])
        }
    });
    let mut out = Vec::with_capacity(body.len() / 2);
    let mut at = 2u64;
    let mut buf = [0u8; 4];
    for c in char::decode_utf16(units) {
        let c = c.map_err(|e| LoadError::Malformed {
            file: file.to_string(),
            location: Location::Byte(at),
            message: format!("unpaired UTF-16 surrogate {:#06x}", e.unpaired_surrogate()),
        })?;
        at += 2 * c.len_utf16() as u64;
        out.extend_from_slice(c.encode_utf8(&mut buf).as_bytes());
    }
    Ok(Some(out))
}
