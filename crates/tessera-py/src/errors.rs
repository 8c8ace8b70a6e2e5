//! The library's typed errors as the package's exception classes (`tessera.errors`, written
//! in Python so that each can also be the built-in exception a Python caller expects:
//! `ParseError` is a `ValueError`, `FileError` an `OSError`, …). The message is the
//! library's, which names the file, the line and the reason.

use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// The exception class of `e` and its attributes.
fn class_of(e: &tessera::Error) -> (&'static str, Option<(String, usize)>) {
    use tessera::Error as E;
    match e {
        E::Io { path, .. } | E::Write { path, .. } => ("FileError", Some((path.display().to_string(), 0))),
        E::Referenced { file, .. } => ("FileError", Some((file.display().to_string(), 0))),
        E::Parse { at, .. } => ("ParseError", Some((at.file.display().to_string(), at.line))),
        E::Unsupported { at, .. } => {
            ("UnsupportedInputError", Some((at.file.display().to_string(), at.line)))
        }
        E::UnknownFormat { path, .. } => ("UnsupportedInputError", Some((path.display().to_string(), 0))),
        E::InvalidMesh { .. } | E::FormatLimit { .. } => ("MeshError", None),
        E::OutputTooLarge { .. } => ("OutputTooLargeError", None),
        E::InvalidParameter { .. }
        | E::FactorOutOfRange { .. }
        | E::CriterionNotAccepted { .. }
        | E::PatchKindNotAccepted { .. }
        | E::EngineNotSupported { .. }
        | E::NeedsCamera { .. }
        | E::PlanMismatch { .. }
        | E::NoStripForm { .. } => ("ParameterError", None),
    }
}

/// `e` as the package's exception, its message prefixed by `context` (the input file, for
/// errors about its patches that do not name it themselves).
pub fn to_py_err(py: Python<'_>, e: tessera::Error, context: Option<&str>) -> PyErr {
    let (class, mut at) = class_of(&e);
    let message = match (&e, context) {
        (tessera::Error::PatchKindNotAccepted { .. }, Some(file)) => {
            at = Some((file.to_string(), 0));
            format!("{file}: {e}")
        }
        _ => e.to_string(),
    };
    let size = match e {
        tessera::Error::OutputTooLarge { vertices, triangles, bytes } => Some((vertices, triangles, bytes)),
        _ => None,
    };
    exception(py, class, message, |kwargs| {
        if let Some((file, line)) = &at {
            kwargs.set_item("file", file)?;
            kwargs.set_item("line", if *line == 0 { None } else { Some(*line) })?;
        }
        if let Some((vertices, triangles, bytes)) = size {
            kwargs.set_item("vertices", vertices)?;
            kwargs.set_item("triangles", triangles)?;
            kwargs.set_item("bytes", bytes)?;
        }
        Ok(())
    })
}

/// A `tessera.errors.ParameterError` with `message`: an argument the Python layer itself
/// refuses (two criteria at once, an unknown name).
pub fn parameter_error(py: Python<'_>, message: impl Into<String>) -> PyErr {
    exception(py, "ParameterError", message.into(), |_| Ok(()))
}

/// An instance of `tessera.errors.<class>` with `message` and the keyword arguments `fill`
/// sets.
fn exception(
    py: Python<'_>,
    class: &str,
    message: String,
    fill: impl FnOnce(&Bound<'_, PyDict>) -> PyResult<()>,
) -> PyErr {
    let build = || -> PyResult<PyErr> {
        let module = py.import("tessera.errors")?;
        let kwargs = PyDict::new(py);
        fill(&kwargs)?;
        let exception = module.getattr(class)?.call((message.clone(),), Some(&kwargs))?;
        Ok(PyErr::from_value(exception))
    };
    // The classes are the package's own: failing to build one is a broken installation.
    build().unwrap_or_else(|import| {
        PyRuntimeError::new_err(format!("{message} (and tessera.errors could not be used: {import})"))
    })
}
