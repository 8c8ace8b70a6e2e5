//! `check`, `write_mesh` and `pattern`: the library's verification, writers and domain
//! patterns on arrays from Python.

use crate::arrays;
use crate::errors::{parameter_error, to_py_err};
use crate::surfaces::SurfaceSet;
use numpy::{PyReadonlyArray1, PyReadonlyArray2, PyReadonlyArray3};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;
use tessera::mesh::Mesh;
use tessera::scheme::domain_pattern::{self, PatternRequest};
use tessera::scheme::Scheme;
use tessera::surface::Domain;

/// Rows of an `(n, N)` array, copied into the library's layout, or an error naming `name`.
fn rows_of<const N: usize, T: numpy::Element + Copy + Default>(
    py: Python<'_>,
    a: &PyReadonlyArray2<'_, T>,
    name: &str,
) -> PyResult<Vec<[T; N]>> {
    let view = a.as_array();
    if view.ncols() != N {
        return Err(parameter_error(py, format!("{name}: expected shape (n, {N}), got {:?}", view.shape())));
    }
    Ok(view.rows().into_iter().map(|r| std::array::from_fn(|k| r[k])).collect())
}

/// A library mesh from Python's arrays (copied). `faces` must index `vertices`.
fn mesh_from(
    py: Python<'_>,
    vertices: &PyReadonlyArray2<'_, f32>,
    faces: &PyReadonlyArray2<'_, u32>,
) -> PyResult<Mesh> {
    let positions = rows_of::<3, f32>(py, vertices, "vertices")?;
    let triangles = rows_of::<3, u32>(py, faces, "faces")?;
    let n = positions.len() as u64;
    if let Some(bad) = triangles.iter().flatten().find(|&&i| u64::from(i) >= n) {
        return Err(parameter_error(py, format!("faces: index {bad} is out of range for {n} vertices")));
    }
    let m = triangles.len();
    Ok(Mesh {
        normals: vec![[0.0; 3]; positions.len()],
        uvs: vec![[0.0; 2]; positions.len()],
        vertex_patch: vec![0; positions.len()],
        positions,
        indices: triangles.into_iter().flatten().collect(),
        triangle_patch: vec![0; m],
        ..Mesh::default()
    })
}

/// Checks a mesh as `tessera check` does: welds positions by exact bits and counts boundary,
/// non-manifold and misoriented edges, degenerate triangles, the Euler characteristic and
/// the triangle quality. With `set` (the input it was made from), also the problems
/// `tessera mesh` warns about: what is wrong with the mesh that was not wrong with the input
/// (`culled` patches left out on purpose excuse the holes). The GIL is released while it works.
#[pyfunction]
#[pyo3(signature = (vertices, faces, set = None, culled = 0))]
pub fn check<'py>(
    py: Python<'py>,
    vertices: PyReadonlyArray2<'py, f32>,
    faces: PyReadonlyArray2<'py, u32>,
    set: Option<&Bound<'py, SurfaceSet>>,
    culled: usize,
) -> PyResult<Bound<'py, PyDict>> {
    let mesh = mesh_from(py, &vertices, &faces)?;
    let (w, q) = py.detach(|| (tessera::verify::watertight(&mesh), tessera::verify::quality(&mesh)));
    let d = PyDict::new(py);
    d.set_item("vertices", w.vertices)?;
    d.set_item("triangles", w.triangles)?;
    d.set_item("edges", w.edges)?;
    d.set_item("boundary_edges", w.boundary_edges)?;
    d.set_item("nonmanifold_edges", w.nonmanifold_edges)?;
    d.set_item("misoriented_edges", w.misoriented_edges)?;
    d.set_item("degenerate_triangles", w.degenerate_triangles())?;
    d.set_item("euler_characteristic", w.euler_characteristic)?;
    d.set_item("is_closed", w.is_closed())?;
    d.set_item("min_angle", q.min_angle)?;
    d.set_item("max_aspect_ratio", q.max_aspect_ratio)?;
    d.set_item("min_angle_histogram", q.min_angle_histogram.to_vec())?;
    if let Some(set) = set {
        let problems = tessera::verify::output_problems(&set.get().set.topology.report, &w, culled);
        d.set_item("problems", problems)?;
    }
    Ok(d)
}

/// Measures a mesh's approximation error against the exact surface of `set`, the set it was
/// made from with `corner_params=True` (as `tessera mesh --measure-error`): every triangle
/// sampled at `order`² points, each compared with the surface point at the same patch
/// parameters. Returns `{"max", "rms", "max_triangle", "samples"}`. The GIL is released
/// while it works. Cost: O(triangles · order²) surface evaluations, parallel.
#[pyfunction]
#[pyo3(signature = (set, vertices, faces, face_patch, corner_params, order = 6))]
pub fn measure_error<'py>(
    py: Python<'py>,
    set: &Bound<'py, SurfaceSet>,
    vertices: PyReadonlyArray2<'py, f32>,
    faces: PyReadonlyArray2<'py, u32>,
    face_patch: PyReadonlyArray1<'py, u32>,
    corner_params: PyReadonlyArray3<'py, f32>,
    order: u32,
) -> PyResult<Bound<'py, PyDict>> {
    let mut mesh = mesh_from(py, &vertices, &faces)?;
    mesh.triangle_patch = face_patch.as_array().to_vec();
    set_corner_params(py, &mut mesh, &corner_params)?;
    let set = &set.get().set;
    let measured = py.detach(|| tessera::verify::approximation_error(&mesh, set, order));
    let e = measured.map_err(|e| to_py_err(py, e, None))?;
    let d = PyDict::new(py);
    d.set_item("max", e.max)?;
    d.set_item("rms", e.rms)?;
    d.set_item("max_triangle", e.max_triangle)?;
    d.set_item("samples", e.samples)?;
    Ok(d)
}

/// `mesh.corner_params` from an `(m, 3, 2)` array of the mesh's `m` triangles.
fn set_corner_params(py: Python<'_>, mesh: &mut Mesh, a: &PyReadonlyArray3<'_, f32>) -> PyResult<()> {
    let view = a.as_array();
    if view.shape()[1..] != [3, 2] || view.shape()[0] != mesh.triangle_count() {
        return Err(parameter_error(
            py,
            format!(
                "corner_params: expected shape ({}, 3, 2), got {:?}",
                mesh.triangle_count(),
                view.shape()
            ),
        ));
    }
    mesh.corner_params =
        Some(view.outer_iter().flat_map(|t| (0..3).map(move |k| [t[[k, 0]], t[[k, 1]]])).collect());
    Ok(())
}

/// Writes a mesh by `path`'s extension (.obj, .ply, .stl, .glb) with the library's writers,
/// whole or not at all. Every array but `vertices` and `faces` may be None (written as
/// zeros); `corner_params` `(m, 3, 2)` goes into a `.ply`'s `patch_uv`.
#[pyfunction]
#[pyo3(signature = (path, vertices, faces, normals = None, uvs = None, vertex_patch = None, face_patch = None, corner_params = None))]
#[allow(clippy::too_many_arguments)]
pub fn write_mesh(
    py: Python<'_>,
    path: PathBuf,
    vertices: PyReadonlyArray2<'_, f32>,
    faces: PyReadonlyArray2<'_, u32>,
    normals: Option<PyReadonlyArray2<'_, f32>>,
    uvs: Option<PyReadonlyArray2<'_, f32>>,
    vertex_patch: Option<PyReadonlyArray1<'_, u32>>,
    face_patch: Option<PyReadonlyArray1<'_, u32>>,
    corner_params: Option<PyReadonlyArray3<'_, f32>>,
) -> PyResult<()> {
    tessera::io::check_output_path(&path).map_err(|e| to_py_err(py, e, None))?;
    let mut mesh = mesh_from(py, &vertices, &faces)?;
    let (n, m) = (mesh.vertex_count(), mesh.triangle_count());
    let length = |name: &str, got: usize, want: usize| -> PyResult<()> {
        if got == want {
            Ok(())
        } else {
            Err(parameter_error(py, format!("{name}: {got} rows, the mesh has {want}")))
        }
    };
    if let Some(a) = &normals {
        mesh.normals = rows_of::<3, f32>(py, a, "normals")?;
        length("normals", mesh.normals.len(), n)?;
    }
    if let Some(a) = &uvs {
        mesh.uvs = rows_of::<2, f32>(py, a, "uvs")?;
        length("uvs", mesh.uvs.len(), n)?;
    }
    if let Some(a) = &vertex_patch {
        mesh.vertex_patch = a.as_array().to_vec();
        length("vertex_patch", mesh.vertex_patch.len(), n)?;
    }
    if let Some(a) = &face_patch {
        mesh.triangle_patch = a.as_array().to_vec();
        length("face_patch", mesh.triangle_patch.len(), m)?;
    }
    if let Some(a) = &corner_params {
        set_corner_params(py, &mut mesh, a)?;
    }
    let written = py.detach(|| tessera::io::write_mesh(&mesh, &path));
    written.map_err(|e| to_py_err(py, e, None))
}

/// The domain pattern of a scheme for given edge and inside factors (Direct3D's edge order),
/// as `tessera pattern` draws it: `(points (k, 2), triangles (t, 3), regions (t,),
/// region_kind, edge_factors, inside_factors)`.
#[pyfunction]
#[pyo3(signature = (scheme, domain, edges = Vec::new(), inside = Vec::new(), level = 2, mask = "10"))]
pub fn pattern<'py>(
    py: Python<'py>,
    scheme: &str,
    domain: &str,
    edges: Vec<f64>,
    inside: Vec<f64>,
    level: u32,
    mask: &str,
) -> PyResult<Bound<'py, pyo3::types::PyTuple>> {
    let scheme = Scheme::from_name(scheme).ok_or_else(|| {
        parameter_error(
            py,
            format!("scheme={scheme:?}: use one of {}", crate::frames::scheme_names().join(", ")),
        )
    })?;
    let domain = match domain {
        "tri" | "triangle" => Domain::Tri,
        "quad" => Domain::Quad,
        other => return Err(parameter_error(py, format!("domain={other:?}: use \"tri\" or \"quad\""))),
    };
    let request = PatternRequest { scheme, domain, edges: &edges, inside: &inside, level, mask };
    let p = domain_pattern::build(&request).map_err(|e| to_py_err(py, e, None))?;
    let items: Vec<Bound<'py, PyAny>> = vec![
        arrays::rows(py, p.points)?,
        arrays::rows(py, p.triangles)?,
        arrays::column(py, p.regions),
        p.region_kind.into_pyobject(py)?.into_any(),
        p.edge_factors.into_pyobject(py)?.into_any(),
        p.inside_factors.into_pyobject(py)?.into_any(),
    ];
    pyo3::types::PyTuple::new(py, items)
}
