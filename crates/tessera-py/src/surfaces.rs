//! `load` and the `SurfaceSet` class: a set read by `tessera::io::load`, as the command line
//! reads it.

use crate::errors::{parameter_error, to_py_err};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;
use std::sync::Arc;
use tessera::io::glb::UriScope;
use tessera::io::{LoadOptions, SurfaceKind};
use tessera::subdivision::isolation::IsolationLevels;
use tessera::surface::{BuildOptions, Orientation};
use tessera::topology::weld::Weld;

/// Patches with the topology that ties them together, read from a file by `tessera.load`.
/// Immutable; tessellate it with `tessera.tessellate` or a `tessera.Tessellator`.
#[pyclass(frozen, module = "tessera._tessera")]
pub struct SurfaceSet {
    pub set: Arc<tessera::surface::SurfaceSet>,
    /// The file it was read from, for messages.
    pub path: String,
}

/// Reads `path` (by extension: .patches, .bezt, .obj, .ply, .stl, .glb, .gltf) into a
/// surface set, with the command line's rules and repairs. The GIL is released while it
/// reads.
#[pyfunction]
#[pyo3(signature = (path, surface = "auto", weld = None, keep_orientation = false, flip_normals = false, allow_outside_uris = false, isolation_smooth = 2, isolation_sharp = 6))]
#[allow(clippy::too_many_arguments)]
pub fn load(
    py: Python<'_>,
    path: PathBuf,
    surface: &str,
    weld: Option<f64>,
    keep_orientation: bool,
    flip_normals: bool,
    allow_outside_uris: bool,
    isolation_smooth: u8,
    isolation_sharp: u8,
) -> PyResult<SurfaceSet> {
    let surface = match surface {
        "auto" => SurfaceKind::Auto,
        "pn" => SurfaceKind::Pn,
        "catmull-clark" | "catmull_clark" => SurfaceKind::CatmullClark,
        "loop" => SurfaceKind::Loop,
        other => {
            return Err(parameter_error(
                py,
                format!("surface={other:?}: use \"auto\", \"pn\", \"catmull-clark\" or \"loop\""),
            ))
        }
    };
    let weld = match weld {
        None => Weld::Exact,
        Some(eps) if eps.is_finite() && eps >= 0.0 => Weld::Within(eps),
        Some(eps) => {
            return Err(parameter_error(py, format!("weld={eps}: the distance must be finite and ≥ 0")))
        }
    };
    for (name, levels) in [("isolation_smooth", isolation_smooth), ("isolation_sharp", isolation_sharp)] {
        if !(1..=10).contains(&levels) {
            return Err(parameter_error(py, format!("{name}={levels}: use 1 to 10")));
        }
    }
    let options = LoadOptions {
        build: BuildOptions {
            weld,
            orientation: if keep_orientation { Orientation::AsGiven } else { Orientation::Outward },
            flip: flip_normals,
        },
        uri_scope: if allow_outside_uris { UriScope::Anywhere } else { UriScope::ModelFolder },
        surface,
        isolation: IsolationLevels { smooth: isolation_smooth, sharp: isolation_sharp },
    };
    let read = py.detach(|| tessera::io::load(&path, options));
    let set = read.map_err(|e| to_py_err(py, e, None))?;
    Ok(SurfaceSet { set: Arc::new(set), path: path.display().to_string() })
}

#[pymethods]
impl SurfaceSet {
    /// The number of patches.
    #[getter]
    fn patch_count(&self) -> usize {
        self.set.patches.len()
    }

    /// The file the set was read from.
    #[getter]
    fn path(&self) -> &str {
        &self.path
    }

    /// The bounding box of the control points: `((xmin, ymin, zmin), (xmax, ymax, zmax))`.
    #[getter]
    fn bounds(&self) -> ([f64; 3], [f64; 3]) {
        let (lo, hi) = self.set.bounds();
        (lo.to_array(), hi.to_array())
    }

    /// The bounding box's diagonal, the unit of `tolerance="0.1%"`.
    #[getter]
    fn diagonal(&self) -> f64 {
        let (lo, hi) = self.set.bounds();
        lo.distance(hi)
    }

    /// The model's up axis for default cameras: `"z"` or `"y"` (the format's convention).
    #[getter]
    fn up(&self) -> &'static str {
        match self.set.up {
            tessera::camera::UpAxis::Z => "z",
            tessera::camera::UpAxis::Y => "y",
        }
    }

    /// Whether the set is the limit surface of a subdivision cage (Catmull-Clark or Loop).
    #[getter]
    fn is_subdivision_cage(&self) -> bool {
        !self.set.origins.is_empty()
    }

    /// For a subdivision cage, each patch's cage face (None for other sets): `patch_faces[p]`
    /// is the face of the OBJ (0-based, in file order) that patch `p` belongs to.
    #[getter]
    fn patch_faces(&self) -> Option<Vec<u32>> {
        (!self.set.origins.is_empty()).then(|| self.set.origins.iter().map(|o| o.face).collect())
    }

    /// The input's topology: `boundary_edges`, `nonmanifold_edges`,
    /// `euler_characteristic` and the other counts of its shared-edge graph.
    #[getter]
    fn topology<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let t = self.set.topology.report;
        let d = PyDict::new(py);
        d.set_item("boundary_edges", t.boundary_edges)?;
        d.set_item("nonmanifold_edges", t.nonmanifold_edges)?;
        d.set_item("inconsistently_oriented_edges", t.inconsistently_oriented_edges)?;
        d.set_item("euler_characteristic", t.euler_characteristic)?;
        d.set_item("is_closed", t.is_closed())?;
        Ok(d)
    }

    /// What reading the input repaired, by kind (`tessera mesh --stats`' `repairs`, less the
    /// tessellation's own `collapsed_triangles`).
    #[getter]
    fn repairs<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        repairs_dict(py, &self.set.repairs, None)
    }

    fn __len__(&self) -> usize {
        self.set.patches.len()
    }

    fn __repr__(&self) -> String {
        format!("<tessera.SurfaceSet {:?}: {} patches>", self.path, self.set.patches.len())
    }
}

/// The repairs as `--stats` gives them (the library's list): every count by key, and
/// `flipped`; `collapsed_triangles` when a frame was drawn.
pub fn repairs_dict<'py>(
    py: Python<'py>,
    r: &tessera::surface::Repairs,
    collapsed_triangles: Option<usize>,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for (key, n, _) in r.counted(collapsed_triangles.unwrap_or(0)) {
        if key != "collapsed_triangles" || collapsed_triangles.is_some() {
            d.set_item(key, n)?;
        }
    }
    d.set_item("flipped", r.flipped)?;
    Ok(d)
}

/// The set behind a Python argument.
pub fn inner(set: &Bound<'_, SurfaceSet>) -> (Arc<tessera::surface::SurfaceSet>, String) {
    let s = set.get();
    (Arc::clone(&s.set), s.path.clone())
}
