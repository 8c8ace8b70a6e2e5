//! The engine check: an [`EngineCase`] decoded from the bytes, run through the builder, the
//! criterion and the engine the way the CLI does, its output checked.

use std::fmt::Write as _;

use crate::camera::Camera;
use crate::criterion::esc::Threshold;
use crate::criterion::view::{Mapping, ViewCriterion};
use crate::criterion::Plan;
use crate::engine::{self, EngineOptions};
use crate::io::obj;
use crate::io::patches;
use crate::mesh::strips;
use crate::pattern::hardware::Partitioning;
use crate::pattern::Pattern;
use crate::surface::{BuildOptions, Orientation, SurfaceSet};
use crate::topology::weld::Weld;
use crate::verify;

use super::shapes::*;
use super::*;

/// A tessellation scheme, as `--scheme` names them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scheme {
    Uniform,
    Transition,
    SemiUniform,
    Sd2,
    Hardware(Partitioning),
    Esc,
}

/// How an engine case chooses its factors (the CLI's criterion flags).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Criterion {
    /// `--factor`.
    Factor(f64),
    /// `--tolerance`, as a share of the bounding-box diagonal.
    Tolerance(f64),
    /// `--pixel-error`.
    PixelError(f64),
    /// `--distance` or `--silhouette`: FMIN:FMAX.
    View(ViewCriterion, f64, f64),
}

/// One decoded engine case, kept whole so a failure can print everything that led to it.
#[derive(Debug, Clone)]
pub struct EngineCase {
    /// What the input was generated as.
    pub shape: Shape,
    /// The generated input, Newell patch text or OBJ text.
    pub text: String,
    /// A patch or face left out, which opens a closed shape.
    pub dropped: Option<usize>,
    /// Welding and orientation for the surface builder.
    pub build: BuildOptions,
    /// The `--camera` spec, None for the default framing camera.
    pub camera: Option<String>,
    pub scheme: Scheme,
    pub criterion: Criterion,
    /// Semi-uniform's `--max-level`, ESC's `Lmax`.
    pub max_level: u32,
    /// SD-2's `--warp`; ESC: a fixed `--level` (the max level) instead of the camera's.
    pub variant: bool,
    /// ESC's distance-test threshold (`--quality`, `--threshold`).
    pub esc_threshold: Threshold,
    /// Corner parameters, strips and the memory limit asked of the engine.
    pub options: EngineOptions,
}

/// What [`check_engine`] did with its input, so that tests can see they are not vacuous.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EngineOutcome {
    /// The surface builder, the criterion or the engine refused the case with an error.
    Refused,
    /// The engine produced a consistent mesh; `checked_watertight` when the input was closed
    /// by construction and the output was verified watertight.
    Tessellated { checked_watertight: bool },
}

/// Factors the engine cases stay within, so a case costs microseconds, not seconds.
const MAX_CASE_FACTOR: u32 = 16;

/// Checks the engine: decodes the bytes into an [`EngineCase`] (a small surface set, a
/// scheme with its criterion and factors ≤ 16, a camera; culling off) and builds the plan the
/// way the CLI does. The engine must produce a consistent mesh or an error, strips must
/// decode to the triangle list, and when the shape is closed by construction its topology
/// must say so and the output must have no boundary and no non-manifold edge.
pub fn check_engine(data: &[u8]) -> EngineOutcome {
    let case = decode_engine_case(data);
    run_engine_case(&case)
}

/// Decodes fuzz bytes into an engine case; every input gives one.
pub fn decode_engine_case(data: &[u8]) -> EngineCase {
    let mut d = Decisions::new(data);
    let shape = Shape::ALL[d.below(Shape::ALL.len() as u32) as usize];
    let closed_shape = shape.is_watertight_by_construction();
    let dropped = (d.one_in(8) && closed_shape).then(|| d.below(12) as usize);
    let weld = match d.below(4) {
        // Lattice points are at least 2 apart, so this tolerance never merges two of them.
        0 => Weld::Within(0.25),
        1 => Weld::Off,
        _ => Weld::Exact,
    };
    let orientation = if d.one_in(2) { Orientation::Outward } else { Orientation::AsGiven };
    let build = BuildOptions { weld, orientation, flip: d.one_in(4) };
    let camera = (!d.one_in(3)).then(|| {
        let mut spec = format!(
            "eye={},{},{},target={},{},{},fov={},size={}x{}",
            d.int_in(-40, 40),
            d.int_in(-40, 40),
            d.int_in(-40, 40),
            d.int_in(-3, 3),
            d.int_in(-3, 3),
            d.int_in(-3, 3),
            d.int_in(1, 179),
            d.int_in(1, 2048),
            d.int_in(1, 2048)
        );
        if d.one_in(4) {
            let _ = write!(spec, ",up={},{},{}", d.int_in(-1, 1), d.int_in(-1, 1), d.int_in(-1, 1));
        }
        spec
    });
    let scheme = match d.below(9) {
        0 => Scheme::Uniform,
        1 => Scheme::Transition,
        2 => Scheme::SemiUniform,
        3 => Scheme::Sd2,
        4 => Scheme::Hardware(Partitioning::Integer),
        5 => Scheme::Hardware(Partitioning::Pow2),
        6 => Scheme::Hardware(Partitioning::FractionalOdd),
        7 => Scheme::Hardware(Partitioning::FractionalEven),
        _ => Scheme::Esc,
    };
    let max_level = d.below(5);
    let view_criterion = match d.below(4) {
        0 => ViewCriterion::Distance(Mapping::Linear),
        1 => ViewCriterion::Distance(Mapping::Quadratic),
        2 => ViewCriterion::SilhouetteVertices,
        _ => ViewCriterion::Silhouetteness,
    };
    let top = f64::from(MAX_CASE_FACTOR);
    let criterion = match d.below(4) {
        0 => {
            let (a, b) = (d.factor(1.0, top), d.factor(1.0, top));
            Criterion::View(view_criterion, a.min(b), a.max(b))
        }
        1 => Criterion::Tolerance([0.001, 0.005, 0.02, 0.1][d.below(4) as usize]),
        2 => Criterion::PixelError([0.25, 1.0, 4.0, 32.0][d.below(4) as usize]),
        _ => Criterion::Factor(d.factor(1.0, top)),
    };
    let esc_threshold = match d.below(3) {
        0 => Threshold::High,
        1 => Threshold::Medium,
        _ => Threshold::Absolute(f64::from(d.below(8)) * 0.25),
    };
    let variant = d.one_in(2);
    // Asking a pattern without a strip form for strips is an error, so ask mostly the two
    // patterns that have one.
    let strips = if matches!(scheme, Scheme::Sd2 | Scheme::Esc) { d.one_in(2) } else { d.one_in(8) };
    let options = EngineOptions {
        corner_params: d.one_in(2),
        memory_limit: Some(1 << 26),
        strips,
        ..EngineOptions::default()
    };
    // The geometry comes last: it takes most of the bytes, and an input that runs out while
    // jittering points has still chosen its scheme.
    let text = match shape {
        Shape::CubePatches => cube_patches(&mut d, dropped),
        Shape::Spindle => spindle(&mut d, dropped),
        Shape::Torus => torus(&mut d, dropped),
        Shape::Octahedron | Shape::CubeMesh | Shape::Tetrahedron => closed_mesh(&mut d, shape, dropped),
        Shape::RandomPatches => random_patches(&mut d),
        Shape::RandomMesh => random_mesh(&mut d),
    };
    EngineCase {
        shape,
        text,
        dropped,
        build,
        camera,
        scheme,
        criterion,
        max_level,
        variant,
        esc_threshold,
        options,
    }
}

/// Builds the case's surface set, or None when the builder refuses it.
fn build_set(case: &EngineCase) -> Option<SurfaceSet> {
    if is_mesh_shape(case.shape) {
        let mesh = obj::parse_obj(&case.text, label())
            .unwrap_or_else(|e| panic!("generated OBJ does not parse: {e}\n{}", case.text));
        SurfaceSet::pn_from_mesh(&mesh, label(), case.build).ok()
    } else {
        let file = patches::parse_patches(&case.text, label())
            .unwrap_or_else(|e| panic!("generated patches do not parse: {e}\n{}", case.text));
        Some(SurfaceSet::from_patch_file(&file, case.build))
    }
}

/// The plan and pattern for a case, through [`crate::scheme::Scheme::plan`] as the CLI makes
/// them without `--cull`; None where the library refuses the combination or the criterion
/// errs.
fn plan_case(case: &EngineCase, set: &SurfaceSet, camera: &Camera) -> Option<(Plan, Box<dyn Pattern>)> {
    use crate::scheme::{self, PlanOptions};
    let top = f64::from(MAX_CASE_FACTOR);
    let library_scheme = match case.scheme {
        Scheme::Uniform => scheme::Scheme::Uniform,
        Scheme::Transition => scheme::Scheme::Transition,
        Scheme::SemiUniform => scheme::Scheme::SemiUniform { max_level: case.max_level },
        Scheme::Sd2 => scheme::Scheme::Sd2 { warp: case.variant },
        Scheme::Hardware(p) => scheme::Scheme::Hardware(p),
        Scheme::Esc => scheme::Scheme::Esc { max_level: case.max_level.min(3) },
    };
    let integer = matches!(case.scheme, Scheme::Uniform | Scheme::Transition | Scheme::SemiUniform);
    let criterion = match (case.scheme, case.criterion) {
        (Scheme::Esc, _) => scheme::Criterion::Esc {
            threshold: case.esc_threshold,
            level: case.variant.then_some(case.max_level.min(3)),
        },
        // Integer factors only; semi-uniform also needs a power of two.
        (Scheme::SemiUniform, Criterion::Factor(f)) => scheme::Criterion::Factor(f64::from(
            1u32 << (f.round() as u32).max(1).ilog2().min(case.max_level),
        )),
        (_, Criterion::Factor(f)) if integer => scheme::Criterion::Factor(f.round()),
        (Scheme::Hardware(p), Criterion::Factor(f)) => {
            scheme::Criterion::Factor(f.min(top.min(f64::from(p.range().1))))
        }
        (_, Criterion::Factor(f)) => scheme::Criterion::Factor(f),
        (_, Criterion::Tolerance(share)) => {
            let (lo, hi) = set.bounds();
            scheme::Criterion::Tolerance(share * lo.distance(hi))
        }
        (_, Criterion::PixelError(px)) => scheme::Criterion::PixelError(px),
        // The CLI's integer FMIN:FMAX for the integer schemes.
        (_, Criterion::View(criterion, fmin, fmax)) if integer => {
            scheme::Criterion::View { criterion, fmin: fmin.round(), fmax: fmax.round() }
        }
        (_, Criterion::View(criterion, fmin, fmax)) => scheme::Criterion::View { criterion, fmin, fmax },
    };
    let options =
        PlanOptions { camera: Some(*camera), max_factor: MAX_CASE_FACTOR, ..PlanOptions::default() };
    let planned = library_scheme.plan(set, &criterion, &options).ok()?;
    Some((planned.plan, Box::new(planned.pattern)))
}

/// Runs a decoded case through the builder, the criterion and the engine, asserting what
/// [`check_engine`] documents.
pub fn run_engine_case(case: &EngineCase) -> EngineOutcome {
    let Some(set) = build_set(case) else { return EngineOutcome::Refused };
    // `from_patch_file` hands the builder every patch's own 16 points, so without welding no
    // two patches share a curve (`Weld::Off` matches by index only where the builder gets
    // indices: meshes).
    let unshared = case.build.weld == Weld::Off && !is_mesh_shape(case.shape);
    let strict = case.shape.is_watertight_by_construction() && case.dropped.is_none() && !unshared;
    let report = set.topology.report;
    if strict {
        assert!(
            report.is_closed() && report.inconsistently_oriented_edges == 0,
            "a closed, consistently oriented input has topology {report:?}\n{case:#?}"
        );
    }
    let (lo, hi) = set.bounds();
    let default = Camera::framing(lo, hi, 1280, 720);
    // A spec the parser refuses would stop the CLI; the default camera keeps the case useful.
    let camera = case.camera.as_deref().and_then(|s| Camera::parse(s, &default).ok()).unwrap_or(default);
    let Some((plan, pattern)) = plan_case(case, &set, &camera) else { return EngineOutcome::Refused };
    if case.scheme == Scheme::Uniform {
        // The engine trusts the precondition; fuzz/regressions/engine/uniform-* broke it.
        if let Some(why) = uniform_precondition_broken(&set, &plan) {
            panic!("{why}\n{case:#?}");
        }
    }
    assert!(plan.visible.iter().all(|&v| v != 0), "a plan made without culling hides patches\n{case:#?}");
    let Ok(mesh) = engine::tessellate(&set, &plan, pattern.as_ref(), case.options) else {
        return EngineOutcome::Refused;
    };
    assert_mesh_consistent(&mesh, "engine");
    if case.options.corner_params {
        assert!(mesh.corner_params.is_some(), "corner parameters asked for and not filled\n{case:#?}");
    }
    if let Some(strips) = &mesh.strips {
        let nondegenerate = |t: &[u32; 3]| t[0] != t[1] && t[1] != t[2] && t[0] != t[2];
        let listed: Vec<[u32; 3]> =
            (0..mesh.triangle_count()).map(|t| mesh.triangle(t)).filter(nondegenerate).collect();
        let decoded: Vec<[u32; 3]> = strips::decode(strips).into_iter().filter(nondegenerate).collect();
        assert_eq!(
            canonical_triangles(decoded),
            canonical_triangles(listed),
            "the strips do not decode to the triangle list\n{case:#?}"
        );
    }
    let watertight = verify::watertight(&mesh);
    if strict && !(watertight.boundary_edges == 0 && watertight.nonmanifold_edges == 0) {
        panic!("closed input, output not watertight: {watertight:?}\ninput topology {report:?}\n{case:#?}");
    }
    EngineOutcome::Tessellated { checked_watertight: strict }
}

/// Why a plan breaks the [`Uniform`] pattern's precondition (every edge of a patch has
/// `interior[0]` segments), or None. The engine trusts it: a plan that breaks it gives local
/// indices past the patch's vertices (wrong indices in the mesh, or an index panic when
/// corner parameters are asked for).
fn uniform_precondition_broken(set: &SurfaceSet, plan: &Plan) -> Option<String> {
    (0..set.patches.len()).find_map(|p| {
        let corners = set.patches[p].domain().corner_count();
        let segments: Vec<u32> =
            (0..corners).map(|l| plan.segments(set.topology.patch_edges[p][l].edge as usize)).collect();
        let n = plan.interior[p][0];
        segments.iter().any(|&s| s != n).then(|| {
            format!(
                "the plan gives patch {p} interior factors {:?} but edge segments {segments:?}; the \
                 uniform pattern needs every edge at interior[0]",
                plan.interior[p]
            )
        })
    })
}

/// Triangles rotated to start at their smallest index (winding kept), sorted: equal lists
/// hold the same oriented triangles in any order.
fn canonical_triangles(mut triangles: Vec<[u32; 3]>) -> Vec<[u32; 3]> {
    for t in &mut triangles {
        let k = (0..3).min_by_key(|&k| t[k]).unwrap_or(0);
        t.rotate_left(k);
    }
    triangles.sort_unstable();
    triangles
}
