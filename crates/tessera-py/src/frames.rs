//! `Tessellator`: the library's front door for Python — a set prepared once for a scheme and
//! a criterion, tessellated per frame, each frame's buffers handed to numpy.
//!
//! The keyword arguments are the command line's flags (`tessera mesh --help`), mapped to the
//! same library values; the scheme rules, ranges and refusals are the library's
//! (`tessera::scheme::validate`).

use crate::arrays;
use crate::camera::{default_camera, Camera};
use crate::errors::{parameter_error, to_py_err};
use crate::surfaces::{inner, repairs_dict, SurfaceSet};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use std::sync::Arc;
use std::time::{Duration, Instant};
use tessera::criterion::esc::Threshold;
use tessera::criterion::view::{Mapping, ViewCriterion};
use tessera::engine::EngineOptions;
use tessera::scheme::{Criterion, ErrorBound, PlanOptions, Scheme};
use tessera::tessellator::{Tessellator as Inner, TessellatorOptions};

/// Every scheme name `scheme=` takes, in the command line's order.
#[pyfunction]
pub fn scheme_names() -> Vec<&'static str> {
    Scheme::ALL.iter().map(Scheme::name).collect()
}

/// The scheme, criterion and plan options of a request, as `tessera mesh` chooses them from
/// its flags.
struct Chosen {
    scheme: Scheme,
    criterion: Criterion,
    plan: PlanOptions,
    tolerance: Option<f64>,
}

/// The criterion and plan keyword arguments of `Tessellator`, as given (None where left
/// out): `tessera mesh`'s flags.
struct Request<'a, 'py> {
    /// A name of `Scheme::ALL`; None: the criterion's default scheme.
    scheme: Option<&'a str>,
    /// The criteria, at most one given.
    factor: Option<f64>,
    tolerance: Option<&'a Bound<'py, PyAny>>,
    pixel_error: Option<f64>,
    distance: Option<(f64, f64)>,
    silhouette: Option<(f64, f64)>,
    /// How `silhouette` finds silhouettes, and how `distance` maps to factors.
    silhouette_mode: Option<&'a str>,
    mapping: &'a str,
    /// Culling and the adaptive criteria's cap.
    cull: bool,
    max_factor: u32,
    /// Semi-uniform's or ESC's highest level; ESC's fixed level and distance test.
    max_level: Option<u32>,
    level: Option<u32>,
    quality: Option<&'a str>,
    threshold: Option<f64>,
    /// SD-2's reverse projection.
    warp: bool,
    /// The guaranteed bound of `tolerance` and `pixel_error`: "hessian", "taylor" or
    /// "expansion".
    bound: &'a str,
}

/// Maps the keyword arguments to the library's request; every rule it applies is the
/// library's (`Scheme::default_for`, `default_silhouette`, `parse_tolerance`).
fn choose(
    py: Python<'_>,
    set: &tessera::surface::SurfaceSet,
    r: &Request<'_, '_>,
    camera: Option<tessera::camera::Camera>,
    max_triangles: u64,
) -> PyResult<Chosen> {
    let named = match r.scheme {
        None => None,
        Some(name) => Some(
            Scheme::from_name(name)
                .ok_or_else(|| {
                    parameter_error(py, format!("scheme={name:?}: use one of {}", scheme_names().join(", ")))
                })
                .map(|s| match s {
                    Scheme::SemiUniform { .. } => Scheme::SemiUniform {
                        max_level: r.max_level.unwrap_or(Scheme::DEFAULT_SEMI_UNIFORM_LEVEL),
                    },
                    Scheme::Esc { .. } => {
                        Scheme::Esc { max_level: r.max_level.unwrap_or(Scheme::DEFAULT_ESC_LEVEL) }
                    }
                    Scheme::Sd2 { .. } => Scheme::Sd2 { warp: r.warp },
                    other => other,
                })?,
        ),
    };
    if r.warp && !matches!(named, Some(Scheme::Sd2 { .. })) {
        return Err(parameter_error(py, "warp=True applies to scheme=\"sd2\" only"));
    }
    let given = [
        r.factor.is_some(),
        r.tolerance.is_some(),
        r.pixel_error.is_some(),
        r.distance.is_some(),
        r.silhouette.is_some(),
    ];
    if given.iter().filter(|&&g| g).count() > 1 {
        return Err(parameter_error(
            py,
            "give one criterion: factor, tolerance, pixel_error, distance or silhouette",
        ));
    }
    let mut tolerance_value = None;
    let criterion = if let Some(f) = r.factor {
        Criterion::Factor(f)
    } else if let Some(t) = r.tolerance {
        // A number or text such as "0.1%": the one parser of the command line's --tolerance.
        let text = match t.extract::<f64>() {
            Ok(v) => v.to_string(),
            Err(_) => t.extract::<String>().map_err(|_| {
                parameter_error(py, "tolerance: give a number (model units) or text such as \"0.1%\"")
            })?,
        };
        let (lo, hi) = set.bounds();
        let eps = tessera::criterion::tolerance::parse_tolerance(&text, lo.distance(hi))
            .map_err(|e| to_py_err(py, e, None))?;
        tolerance_value = Some(eps);
        Criterion::Tolerance(eps)
    } else if let Some(px) = r.pixel_error {
        Criterion::PixelError(px)
    } else if let Some((fmin, fmax)) = r.distance {
        let mapping = match r.mapping {
            "linear" => Mapping::Linear,
            "quadratic" => Mapping::Quadratic,
            other => {
                return Err(parameter_error(
                    py,
                    format!("mapping={other:?}: use \"linear\" or \"quadratic\""),
                ))
            }
        };
        Criterion::View { criterion: ViewCriterion::Distance(mapping), fmin, fmax }
    } else if let Some((fmin, fmax)) = r.silhouette {
        let criterion = match r.silhouette_mode {
            Some("silhouetteness") => ViewCriterion::Silhouetteness,
            Some("vertices") => ViewCriterion::SilhouetteVertices,
            None => named.unwrap_or(Scheme::Transition).default_silhouette(),
            Some(other) => {
                return Err(parameter_error(
                    py,
                    format!("silhouette_mode={other:?}: use \"silhouetteness\" or \"vertices\""),
                ))
            }
        };
        Criterion::View { criterion, fmin, fmax }
    } else if r.level.is_some()
        || r.quality.is_some()
        || r.threshold.is_some()
        || matches!(named, Some(Scheme::Esc { .. }))
    {
        let threshold = match (r.threshold, r.quality) {
            (Some(d), None) => Threshold::Absolute(d),
            (None, Some("high")) => Threshold::High,
            (None, Some("medium") | None) => Threshold::Medium,
            (Some(_), Some(_)) => return Err(parameter_error(py, "give quality or threshold, not both")),
            (None, Some(other)) => {
                return Err(parameter_error(py, format!("quality={other:?}: use \"high\" or \"medium\"")))
            }
        };
        Criterion::Esc { threshold, level: r.level }
    } else {
        Criterion::Factor(8.0)
    };
    let scheme = named.unwrap_or_else(|| Scheme::default_for(&criterion));
    let camera = camera.unwrap_or_else(|| default_camera(set, (1280, 720)));
    let bound = match r.bound {
        "hessian" => ErrorBound::Hessian,
        "taylor" => ErrorBound::Taylor,
        "expansion" => ErrorBound::Expansion,
        other => {
            let message = format!("bound={other:?}: use \"hessian\", \"taylor\" or \"expansion\"");
            return Err(parameter_error(py, message));
        }
    };
    let plan =
        PlanOptions { camera: Some(camera), cull: r.cull, max_factor: r.max_factor, max_triangles, bound };
    Ok(Chosen { scheme, criterion, plan, tolerance: tolerance_value })
}

/// A surface set prepared for one scheme and criterion, tessellated per frame.
///
/// The set is shared (an `Arc`) and kept alive by the tessellator: the library's
/// `Tessellator<'a>` borrows its set, and a Python object cannot carry a borrow, so the borrow
/// is made `'static` over the `Arc`'s allocation, which outlives it (see `Drop`).
#[pyclass(module = "tessera._tessera")]
pub struct Tessellator {
    /// Dropped first (declared first): it borrows `set`'s allocation.
    inner: Option<Inner<'static>>,
    set: Arc<tessera::surface::SurfaceSet>,
    path: String,
    scheme: Scheme,
    tolerance: Option<f64>,
    prepare: Duration,
}

impl Drop for Tessellator {
    fn drop(&mut self) {
        // The borrow of the set goes before the set (fields drop in order; said twice).
        self.inner = None;
    }
}

#[pymethods]
impl Tessellator {
    /// Prepares `set` (error bounds, topology minimums) for the scheme and the criterion;
    /// see `tessera.Tessellator` for the arguments. Refuses what the library refuses.
    #[new]
    #[pyo3(signature = (set, *, scheme = None, factor = None, tolerance = None, pixel_error = None, distance = None, silhouette = None, silhouette_mode = None, mapping = "linear", camera = None, cull = false, max_factor = 64, max_level = None, level = None, quality = None, threshold = None, warp = false, bound = "hessian", strips = false, corner_params = false, max_triangles = None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        set: &Bound<'_, SurfaceSet>,
        scheme: Option<&str>,
        factor: Option<f64>,
        tolerance: Option<&Bound<'_, PyAny>>,
        pixel_error: Option<f64>,
        distance: Option<(f64, f64)>,
        silhouette: Option<(f64, f64)>,
        silhouette_mode: Option<&str>,
        mapping: &str,
        camera: Option<PyRef<'_, Camera>>,
        cull: bool,
        max_factor: u32,
        max_level: Option<u32>,
        level: Option<u32>,
        quality: Option<&str>,
        threshold: Option<f64>,
        warp: bool,
        bound: &str,
        strips: bool,
        corner_params: bool,
        max_triangles: Option<u64>,
    ) -> PyResult<Tessellator> {
        let (set, path) = inner(set);
        if max_triangles == Some(0) {
            return Err(parameter_error(py, "max_triangles=0: use 1 or more"));
        }
        let engine =
            EngineOptions { strips, ..EngineOptions::within_available_memory(max_triangles, corner_params) };
        let request = Request {
            scheme,
            factor,
            tolerance,
            pixel_error,
            distance,
            silhouette,
            silhouette_mode,
            mapping,
            cull,
            max_factor,
            max_level,
            level,
            quality,
            threshold,
            warp,
            bound,
        };
        let camera = camera.map(|c| c.camera);
        let chosen = choose(py, &set, &request, camera, engine.max_triangles.unwrap_or(u64::MAX))?;
        // SAFETY: the allocation behind `set` lives as long as this object's `set` field, and
        // `inner`, the only holder of this reference, is dropped before it (see `Drop`).
        let borrowed: &'static tessera::surface::SurfaceSet = unsafe { &*Arc::as_ptr(&set) };
        let options = TessellatorOptions { plan: chosen.plan, engine };
        let start = Instant::now();
        let made = py.detach(|| Inner::new(borrowed, chosen.scheme, chosen.criterion, options));
        let tess = made.map_err(|e| to_py_err(py, e, Some(&path)))?;
        Ok(Tessellator {
            inner: Some(tess),
            set,
            path,
            scheme: chosen.scheme,
            tolerance: chosen.tolerance,
            prepare: start.elapsed(),
        })
    }

    /// Tessellates one frame seen from `camera` (None: the tessellator's camera) and hands
    /// its buffers over: `(vertices, normals, uvs, vertex_patch, faces, face_patch,
    /// corner_params, strips, info)`. The GIL is released while it works.
    #[pyo3(signature = (camera = None))]
    fn frame<'py>(
        &mut self,
        py: Python<'py>,
        camera: Option<PyRef<'_, Camera>>,
    ) -> PyResult<Bound<'py, PyTuple>> {
        let camera = camera.map(|c| c.camera);
        let tess = self.inner.as_mut().expect("a tessellator keeps its engine until dropped");
        let drawn = py.detach(|| -> tessera::Result<(tessera::mesh::Mesh, usize)> {
            tess.plan_frame(camera.as_ref())?;
            tess.write_frame()?;
            let mut mesh = tess.take_mesh();
            let culled = tess.plan().map_or(0, |p| p.culled_count());
            // As `tessera mesh`: a culled mesh holds only the vertices its triangles use.
            if culled > 0 {
                mesh.drop_unused_vertices();
            }
            Ok((mesh, culled))
        });
        let (mesh, culled) = drawn.map_err(|e| to_py_err(py, e, Some(&self.path)))?;
        let info = self.info(py, &mesh, culled)?;
        let tessera::mesh::Mesh {
            positions,
            normals,
            uvs,
            vertex_patch,
            indices,
            triangle_patch,
            corner_params,
            strips,
            ..
        } = mesh;
        let corner_params = corner_params.map(|c| arrays::corners(py, c)).transpose()?;
        let items: Vec<Bound<'py, PyAny>> = vec![
            arrays::rows(py, positions)?,
            arrays::rows(py, normals)?,
            arrays::rows(py, uvs)?,
            arrays::column(py, vertex_patch),
            arrays::triples(py, indices)?,
            arrays::column(py, triangle_patch),
            corner_params.unwrap_or_else(|| py.None().into_bound(py)),
            strips.map_or_else(|| py.None().into_bound(py), |s| arrays::column(py, s)),
            info.into_any(),
        ];
        PyTuple::new(py, items)
    }

    /// The scheme's name.
    #[getter]
    fn scheme(&self) -> &'static str {
        self.scheme.name()
    }

    /// The set this tessellator draws.
    #[getter]
    fn set(&self) -> SurfaceSet {
        SurfaceSet { set: Arc::clone(&self.set), path: self.path.clone() }
    }
}

impl Tessellator {
    /// The frame's `--stats` figures that do not need the mesh checked: counts, stage times,
    /// the guarantee, the repairs.
    fn info<'py>(
        &self,
        py: Python<'py>,
        mesh: &tessera::mesh::Mesh,
        culled: usize,
    ) -> PyResult<Bound<'py, PyDict>> {
        let tess = self.inner.as_ref().expect("a tessellator keeps its engine until dropped");
        let t = tess.timings();
        let seconds = t.total().as_secs_f64();
        let d = PyDict::new(py);
        d.set_item("input", &self.path)?;
        d.set_item("scheme", self.scheme.name())?;
        d.set_item("patches", self.set.patches.len())?;
        d.set_item("culled_patches", culled)?;
        d.set_item("triangles", mesh.triangle_count())?;
        d.set_item("vertices", mesh.vertex_count())?;
        let input = self.set.topology.report;
        d.set_item("input_euler_characteristic", input.euler_characteristic)?;
        d.set_item("input_boundary_edges", input.boundary_edges)?;
        d.set_item("input_nonmanifold_edges", input.nonmanifold_edges)?;
        d.set_item("seconds", seconds)?;
        d.set_item("mtri_per_s", mesh.triangle_count() as f64 / seconds / 1e6)?;
        d.set_item("threads", rayon::current_num_threads())?;
        let stages = PyDict::new(py);
        stages.set_item("prepare", self.prepare.as_secs_f64())?;
        stages.set_item("criterion", t.criterion.as_secs_f64())?;
        stages.set_item("resolve", t.resolve.as_secs_f64())?;
        stages.set_item("layout", t.layout.as_secs_f64())?;
        stages.set_item("write", t.write.as_secs_f64())?;
        stages.set_item("write_vertices", t.write_vertices.as_secs_f64())?;
        stages.set_item("write_indices", t.write_indices.as_secs_f64())?;
        d.set_item("stages", stages)?;
        if let Some(r) = tess.report() {
            d.set_item("guaranteed_bound", r.worst_bound)?;
            d.set_item("bound_met", r.capped_patches == 0)?;
            d.set_item("capped_patches", r.capped_patches)?;
        }
        if let Some(eps) = self.tolerance {
            d.set_item("tolerance", eps)?;
        }
        d.set_item("repairs", repairs_dict(py, &self.set.repairs, Some(mesh.collapsed_triangles))?)?;
        Ok(d)
    }
}
