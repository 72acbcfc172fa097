//! Typed loader errors. Every variant's `Display` names the file and where in it the
//! problem is: a 1-based line for text formats, a byte offset for binary ones, a JSON
//! path (`accessors[3]`) for glTF documents.

use std::fmt;

/// Where in a file an error was found.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Location {
    /// 1-based line number of a text file.
    Line(u64),
    /// 0-based byte offset into the (decompressed) file.
    Byte(u64),
    /// A position inside a glTF JSON document, e.g. `accessors[3].count`.
    Json(String),
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Location::Line(l) => write!(f, "line {l}"),
            Location::Byte(b) => write!(f, "byte offset {b}"),
            Location::Json(p) => write!(f, "{p}"),
        }
    }
}

/// Why a file could not be loaded. `file` is the name the caller gave (a path or the
/// `name_for_errors` of [`crate::load::load_bytes`]).
#[derive(Debug, thiserror::Error)]
pub enum LoadError {
    /// The file could not be opened or read.
    #[error("{file}: cannot read file (byte offset 0): {source}")]
    Io {
        /// The file name the caller gave.
        file: String,
        /// The I/O error.
        #[source]
        source: std::io::Error,
    },
    /// The extension names no supported format.
    #[error("{file}: unknown mesh format {extension:?} (byte offset 0); supported: .obj .ply .stl .gltf .glb, optionally .gz")]
    UnknownFormat {
        /// The file name the caller gave.
        file: String,
        /// The extension found.
        extension: String,
    },
    /// The gzip stream is corrupt.
    #[error("{file}: gzip decompression failed at decompressed byte offset {offset}: {message}")]
    Decompress {
        /// The file name the caller gave.
        file: String,
        /// Byte offset in the decompressed stream.
        offset: u64,
        /// What is wrong.
        message: String,
    },
    /// The (decompressed) input is larger than `LoadOptions::max_input_bytes`.
    #[error("{file}: input exceeds the limit of {limit} bytes (at byte offset {limit}); raise LoadOptions::max_input_bytes to load it")]
    InputTooLarge {
        /// The file name the caller gave.
        file: String,
        /// The limit in bytes.
        limit: u64,
    },
    /// The file ends before the data its header or syntax promises.
    #[error("{file}: {location}: file truncated: {what}")]
    Truncated {
        /// The file name the caller gave.
        file: String,
        /// Where in the file (line or byte offset).
        location: Location,
        /// What was expected or found.
        what: String,
    },
    /// A vertex index refers to a vertex that does not exist.
    #[error("{file}: {location}: vertex index {index} out of range (the file has {count} vertices)")]
    IndexOutOfRange {
        /// The file name the caller gave.
        file: String,
        /// Where in the file (line or byte offset).
        location: Location,
        /// The index as written in the file.
        index: i64,
        /// Vertices the file has.
        count: u64,
    },
    /// A coordinate is NaN or infinite.
    #[error("{file}: {location}: coordinate is not finite ({value})")]
    NonFinite {
        /// The file name the caller gave.
        file: String,
        /// Where in the file (line or byte offset).
        location: Location,
        /// The value as written.
        value: String,
    },
    /// A number or token could not be parsed, or a structure is invalid.
    #[error("{file}: {location}: {message}")]
    Malformed {
        /// The file name the caller gave.
        file: String,
        /// Where in the file (line or byte offset).
        location: Location,
        /// What is wrong.
        message: String,
    },
    /// A header claims more elements than the rest of the file can possibly hold
    /// (checked before allocating anything for them).
    #[error("{file}: {location}: header claims {claimed} {what} but only {available} bytes remain, enough for at most {max_possible}")]
    TooManyElements {
        /// The file name the caller gave.
        file: String,
        /// Where in the file (line or byte offset).
        location: Location,
        /// The kind of element.
        what: String,
        /// How many the header claims.
        claimed: u64,
        /// Bytes left in the file.
        available: u64,
        /// How many elements those bytes could hold at most.
        max_possible: u64,
    },
    /// The mesh a small file expands to (glTF nodes instancing one mesh many times) would
    /// exceed `LoadOptions::max_input_bytes` bytes of positions, normals and triangles.
    #[error("{file}: {location}: the loaded mesh would hold {bytes} bytes (positions, normals, triangles), over the limit of {limit} bytes; raise LoadOptions::max_input_bytes to load it")]
    OutputTooLarge {
        /// The file name the caller gave.
        file: String,
        /// Where in the file (line or byte offset).
        location: Location,
        /// Bytes the mesh would need.
        bytes: u64,
        /// The limit in bytes.
        limit: u64,
    },
    /// The file uses a feature this loader does not implement (e.g. a required glTF extension).
    #[error("{file}: {location}: unsupported: {what}")]
    Unsupported {
        /// The file name the caller gave.
        file: String,
        /// Where in the file (line or byte offset).
        location: Location,
        /// What was expected or found.
        what: String,
    },
}

impl LoadError {
    /// The file name the error refers to.
    pub fn file(&self) -> &str {
        match self {
            LoadError::Io { file, .. }
            | LoadError::UnknownFormat { file, .. }
            | LoadError::Decompress { file, .. }
            | LoadError::InputTooLarge { file, .. }
            | LoadError::Truncated { file, .. }
            | LoadError::IndexOutOfRange { file, .. }
            | LoadError::NonFinite { file, .. }
            | LoadError::Malformed { file, .. }
            | LoadError::TooManyElements { file, .. }
            | LoadError::OutputTooLarge { file, .. }
            | LoadError::Unsupported { file, .. } => file,
        }
    }

    /// Where in the file, when the error has a precise location.
    pub fn location(&self) -> Option<&Location> {
        match self {
            LoadError::Truncated { location, .. }
            | LoadError::IndexOutOfRange { location, .. }
            | LoadError::NonFinite { location, .. }
            | LoadError::Malformed { location, .. }
            | LoadError::TooManyElements { location, .. }
            | LoadError::OutputTooLarge { location, .. }
            | LoadError::Unsupported { location, .. } => Some(location),
            _ => None,
        }
    }
}
