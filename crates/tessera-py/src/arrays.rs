//! The engine's buffers handed to numpy: each `Vec` becomes the memory of a numpy array
//! (numpy keeps it alive and frees it through Rust), reshaped to rows — no element is copied.

use numpy::{Element, PyArray1, PyArrayMethods};
use pyo3::prelude::*;

/// `v` as a numpy array of shape `(v.len(), N)`, owning `v`'s buffer. Cost: O(1).
pub fn rows<'py, T: Element + bytemuck::Pod, const N: usize>(
    py: Python<'py>,
    v: Vec<[T; N]>,
) -> PyResult<Bound<'py, PyAny>>
where
    [T; N]: bytemuck::Pod,
{
    let n = v.len();
    // Same alignment, and N·T bytes per row: the flat buffer is the same allocation.
    let flat: Vec<T> = bytemuck::allocation::cast_vec(v);
    Ok(PyArray1::from_vec(py, flat).reshape([n, N])?.into_any())
}

/// `v` as a one-dimensional numpy array owning its buffer. Cost: O(1).
pub fn column<T: Element>(py: Python<'_>, v: Vec<T>) -> Bound<'_, PyAny> {
    PyArray1::from_vec(py, v).into_any()
}

/// A flat `Vec<T>` of `3·m` entries as an `(m, 3)` array owning the buffer. Cost: O(1).
pub fn triples<T: Element>(py: Python<'_>, v: Vec<T>) -> PyResult<Bound<'_, PyAny>> {
    let m = v.len() / 3;
    Ok(PyArray1::from_vec(py, v).reshape([m, 3])?.into_any())
}

/// Corner parameters, three `[u, v]` per triangle, as an `(m, 3, 2)` array owning the buffer.
/// Cost: O(1).
pub fn corners(py: Python<'_>, v: Vec<[f32; 2]>) -> PyResult<Bound<'_, PyAny>> {
    let m = v.len() / 3;
    let flat: Vec<f32> = bytemuck::allocation::cast_vec(v);
    Ok(PyArray1::from_vec(py, flat).reshape([m, 3, 2])?.into_any())
}
