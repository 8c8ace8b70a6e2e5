//! Typed errors. Every input error names the file, the line (1-based, 0 when the problem is not
//! tied to one line) and the reason, so the CLI can print one clear line.

use std::path::PathBuf;

/// Where in which input a problem was found.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Location {
    /// The file, or a label such as `<memory>` for inputs parsed from a string.
    pub file: PathBuf,
    /// 1-based line number; 0 when the problem concerns the whole file.
    pub line: usize,
}

impl std::fmt::Display for Location {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.line == 0 {
            write!(f, "{}", self.file.display())
        } else {
            write!(f, "{}:{}", self.file.display(), self.line)
        }
    }
}

/// Every error the library returns.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The input could not be read from disk.
    #[error("{path}: cannot read: {source}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// The input is malformed: syntax, counts, indices or non-finite numbers.
    #[error("{at}: {reason}")]
    Parse { at: Location, reason: String },
    /// The input is well formed but cannot be used for the requested operation
    /// (a polygon where a triangle is needed, a mesh with no faces, ...).
    #[error("{at}: {reason}")]
    Unsupported { at: Location, reason: String },
    /// An argument is out of range (factor 0, negative tolerance, ...).
    #[error("invalid argument: {0}")]
    InvalidArgument(String),
    /// The output would exceed a limit (memory, triangle count or the u32 index range); it
    /// was refused before anything of its size was allocated.
    #[error(
        "output too large: {vertices} vertices and {triangles} triangles would need {:.1} GiB",
        *bytes as f64 / (1u64 << 30) as f64
    )]
    OutputTooLarge { vertices: u64, triangles: u64, bytes: u64 },
    /// Writing an output failed.
    #[error("{path}: cannot write: {source}")]
    Write {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
}

impl Error {
    /// A parse error at `file:line`.
    pub fn parse(file: impl Into<PathBuf>, line: usize, reason: impl Into<String>) -> Self {
        Error::Parse { at: Location { file: file.into(), line }, reason: reason.into() }
    }

    /// An unsupported-input error at `file:line`.
    pub fn unsupported(file: impl Into<PathBuf>, line: usize, reason: impl Into<String>) -> Self {
        Error::Unsupported { at: Location { file: file.into(), line }, reason: reason.into() }
    }
}

/// Result alias used throughout the crate.
pub type Result<T, E = Error> = std::result::Result<T, E>;
