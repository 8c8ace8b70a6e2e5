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
    /// A file that an input refers to (a glTF buffer's URI) could not be read: `file` is the
    /// input, `referenced` the file its reference names, `what` which reference it is.
    #[error("{}: {what}: {}: {source}", .file.display(), .referenced.display())]
    Referenced {
        file: PathBuf,
        referenced: PathBuf,
        what: String,
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
    /// A file name whose extension (`role`: input, mesh or output) tessera does not read or
    /// write; `supported` lists those it does.
    #[error("{}: {}; supported: {supported}", .path.display(), describe_extension(.role, .extension))]
    UnknownFormat { path: PathBuf, role: &'static str, extension: Option<String>, supported: &'static str },
    /// A mesh handed to a writer breaks its invariants (array lengths, indices in range,
    /// finite numbers); nothing was written.
    #[error("invalid mesh: {reason}")]
    InvalidMesh { reason: String },
    /// The mesh is valid but exceeds what the output format can hold (STL's or GLB's size
    /// limits, glTF's exact float range); nothing was written.
    #[error("{format}: {reason}")]
    FormatLimit { format: &'static str, reason: String },
    /// A parameter is out of its range or malformed: `name` says which (`camera`,
    /// `tolerance`, `esc threshold`, ...).
    #[error("{name}: {reason}")]
    InvalidParameter { name: &'static str, reason: String },
    /// A factor the scheme cannot tessellate; `expected` says what it accepts.
    #[error("factor {factor} is out of range for the {scheme} scheme: use {expected}")]
    FactorOutOfRange { scheme: &'static str, factor: f64, expected: String },
    /// The scheme does not accept the criterion (e.g. an error tolerance for a scheme without
    /// error bounds); `hint` names what it accepts.
    #[error("the {scheme} scheme does not accept {criterion}: {hint}")]
    CriterionNotAccepted { scheme: &'static str, criterion: &'static str, hint: String },
    /// The scheme cannot tessellate this kind of patch (`patch` is the first such patch).
    #[error("the {scheme} scheme does not tessellate {kind} patches (patch {patch} is one): {hint}")]
    PatchKindNotAccepted { scheme: &'static str, kind: &'static str, patch: usize, hint: &'static str },
    /// The engine does not draw this request (a scheme, criterion or option of another
    /// engine); [`crate::scheme::validate`] decides.
    #[error("the {engine} engine does not support {what}")]
    EngineNotSupported { engine: &'static str, what: String },
    /// The criterion (or culling) needs a camera and none was given.
    #[error("{what} needs a camera")]
    NeedsCamera { what: &'static str },
    /// A plan used with a surface set it was not made for.
    #[error("the plan does not match the surface set: {what}")]
    PlanMismatch { what: String },
    /// Triangle strips were asked of a pattern that has no strip form.
    #[error("the {pattern} pattern has no triangle-strip form")]
    NoStripForm { pattern: &'static str },
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

fn describe_extension(role: &str, extension: &Option<String>) -> String {
    match extension {
        Some(e) => format!("unsupported {role} extension \".{e}\""),
        None => format!("the {role} file has no extension"),
    }
}

/// Result alias used throughout the crate.
pub type Result<T, E = Error> = std::result::Result<T, E>;
