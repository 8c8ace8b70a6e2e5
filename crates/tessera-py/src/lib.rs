//! `tessera._tessera`: the extension module behind the `tessera` Python package.
//!
//! A thin layer: every rule (formats, schemes, criteria, validation, the watertightness and
//! problem checks, the domain patterns) is the `tessera` crate's, called as the command line
//! calls it, so a Python mesh equals the CLI's. What lives here is only the mapping of
//! Python's arguments and the hand-over of the engine's buffers to numpy without a copy.
//! The Pythonic surface (keyword defaults, the `Mesh` class, `to_trimesh`) is
//! `python/tessera/__init__.py`; the exception classes are `python/tessera/errors.py`.

use pyo3::prelude::*;

mod arrays;
mod camera;
mod checks;
mod errors;
mod frames;
mod surfaces;

#[pymodule]
fn _tessera(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<surfaces::SurfaceSet>()?;
    m.add_class::<camera::Camera>()?;
    m.add_class::<frames::Tessellator>()?;
    m.add_function(wrap_pyfunction!(surfaces::load, m)?)?;
    m.add_function(wrap_pyfunction!(checks::check, m)?)?;
    m.add_function(wrap_pyfunction!(checks::write_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(checks::measure_error, m)?)?;
    m.add_function(wrap_pyfunction!(checks::pattern, m)?)?;
    m.add_function(wrap_pyfunction!(frames::scheme_names, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
