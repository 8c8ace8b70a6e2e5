//! Criteria: decide how finely each shared edge and each patch interior is sampled.
//!
//! A criterion *proposes* — per use of an edge (a patch side), a real factor — and
//! [`resolve`] *decides*: the maximum over the patches sharing the edge (the CudaTess rule),
//! then the scheme's edge rule (integer, power of two, fractional spacing) and its caps. The
//! result is a [`Plan`]: plain arrays, one row per canonical edge of the topology and one per
//! patch, that every engine reads as they are. Crack-freeness rests on one rule: the sampling
//! of an edge is decided once, from data all its patches agree on, and every patch reads it.
//!
//! [`Criterion`] names what decides the factors; which criteria go with which pattern is
//! [`crate::scheme::Scheme`]'s business ([`crate::scheme::validate`]).

pub mod bounds;
pub mod esc;
pub(crate) mod pattern_shapes;
pub mod resolve;
pub(crate) mod rows;
pub mod screen;
pub mod sd2;
pub mod taylor;
pub mod tolerance;
pub mod view;

use crate::error::{Error, Result};
use crate::sampling::{EdgeRow, SamplingKind};
use crate::surface::SurfaceSet;
use esc::Threshold;
use view::ViewCriterion;

pub use crate::sampling::MAX_FACTOR;

/// Which guaranteed bound the error-bounded criteria (a tolerance, a pixel error) plan with.
/// Both are proven upper bounds of the linear interpolation error; they differ in slack and
/// cost.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ErrorBound {
    /// One second-derivative bound per patch ([`bounds`]): O(1) a grid, and what the GPU
    /// engine's own plans compute.
    #[default]
    Hessian,
    /// The smaller of that and the Taylor bound ([`taylor`]): the second derivatives where each
    /// triangle is, plus a third-derivative remainder, and on coarse triangles the error
    /// sampled on a lattice (for the kinds without a Taylor expansion, with the first bound
    /// as its margin). Fewer triangles for the same guarantee on every surface kind; about
    /// one evaluation a grid cell in the check, tens where it refines. The CPU plans it; the
    /// GPU engine draws such plans but does not yet plan them itself.
    Taylor,
    /// The smaller of the second-derivative bound and the Taylor expansion alone
    /// ([`taylor::TaylorBound::expansion`]): the Taylor bound without its sampled
    /// refinements, so every query has a fixed, small cost. Polynomial bicubics, Bézier and
    /// PN triangles; other kinds keep the second-derivative bound. Between the two others in
    /// triangles (teapot at 0.1 %: 12,642 / 9,364 / 8,128 for Hessian / Expansion / Taylor;
    /// spot 23,224 / 11,332 / 11,332) and a fifth of the Taylor bound's planning time on
    /// patches. The part of the Taylor bound the GPU's check computes too
    /// ([`crate::scheme::Engine::GpuFromCamera`], `tessera-gpu`'s `expansion.wgsl`).
    Expansion,
}

/// What decides the factors.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Criterion {
    /// One factor everywhere (a real number for SD-2 and the fractional partitionings).
    Factor(f64),
    /// Guaranteed object-space error on every patch.
    Tolerance(f64),
    /// Guaranteed screen-space error in pixels, for [`crate::scheme::PlanOptions::camera`].
    PixelError(f64),
    /// A view heuristic without guarantee: factors in `[fmin, fmax]`.
    View { criterion: ViewCriterion, fmin: f64, fmax: f64 },
    /// ESC's own criterion: a level per object from the camera (or `level` for every patch)
    /// and the distance test with `threshold`.
    Esc { threshold: Threshold, level: Option<u32> },
}

impl Criterion {
    /// Whether the criterion guarantees an error bound, so its plans need every patch's
    /// second-derivative bounds ([`Prepared::new`] with bounds).
    pub fn needs_bounds(&self) -> bool {
        matches!(self, Criterion::Tolerance(_) | Criterion::PixelError(_))
    }

    /// A short name for messages.
    pub fn name(&self) -> &'static str {
        match self {
            Criterion::Factor(_) => "a fixed factor",
            Criterion::Tolerance(_) => "an error tolerance",
            Criterion::PixelError(_) => "a pixel error",
            Criterion::View { criterion: ViewCriterion::Distance(_), .. } => "distance factors",
            Criterion::View { criterion: ViewCriterion::SilhouetteVertices, .. } => "vertex silhouettes",
            Criterion::View { criterion: ViewCriterion::Silhouetteness, .. } => "silhouetteness",
            Criterion::Esc { .. } => "the ESC criterion",
        }
    }
}

/// What the criteria need that does not depend on the view or the tolerance, computed once
/// per surface set: the topology's minimum samplings, for the error-bounded criteria every
/// patch's second-derivative bounds, and for the screen criteria every patch's box, sphere
/// and normal cone (made on first use).
#[derive(Debug, Clone, Default)]
pub struct Prepared {
    /// Minimum segments per edge ([`tolerance::minimum_segments`]).
    pub minimum_segments: Vec<u32>,
    /// Minimum interior factors per patch ([`tolerance::minimum_interior`]).
    pub minimum_interior: Vec<[u32; 2]>,
    /// Second-derivative bound per patch ([`bounds::hessian`]); empty unless asked for.
    pub hessians: Vec<bounds::HessianBound>,
    /// Second-derivative bound of each patch's boundary curves ([`tolerance::curve_bounds`]);
    /// empty unless asked for.
    pub curves: Vec<[f64; 4]>,
    views: std::sync::OnceLock<Vec<screen::PatchView>>,
    boxes: std::sync::OnceLock<Vec<[glam::DVec3; 2]>>,
    triangle_errors: std::sync::OnceLock<Vec<bounds::TriangleErrors>>,
    taylor: std::sync::OnceLock<Vec<taylor::TaylorBound>>,
    expansions: std::sync::OnceLock<Vec<taylor::TaylorBound>>,
    vertex_data: std::sync::OnceLock<Vec<(glam::DVec3, glam::DVec3)>>,
    edge_midpoints: std::sync::OnceLock<Vec<[(glam::DVec3, glam::DVec3); 2]>>,
}

impl Prepared {
    /// Prepares `set`; `with_bounds` also computes the error bounds. Cost: O(E + P), plus a
    /// bound per patch with `with_bounds`.
    pub fn new(set: &SurfaceSet, with_bounds: bool) -> Prepared {
        use rayon::prelude::*;
        let hessians: Vec<bounds::HessianBound> =
            if with_bounds { set.patches.par_iter().map(bounds::hessian).collect() } else { Vec::new() };
        Prepared {
            minimum_segments: tolerance::minimum_segments(set),
            minimum_interior: tolerance::minimum_interior(set),
            curves: if with_bounds { tolerance::curve_bounds(set, &hessians) } else { Vec::new() },
            hessians,
            views: Default::default(),
            boxes: Default::default(),
            triangle_errors: Default::default(),
            taylor: Default::default(),
            expansions: Default::default(),
            vertex_data: Default::default(),
            edge_midpoints: Default::default(),
        }
    }

    /// [`Prepared::new`] with the bounds where `criterion` needs them (the error-bounded
    /// criteria). Cost: that of `new`.
    pub fn for_criterion(set: &SurfaceSet, criterion: &Criterion) -> Prepared {
        Prepared::new(set, criterion.needs_bounds())
    }

    /// Every patch's [`taylor::TaylorBound`], computed on the first call and kept, for plans
    /// asked for [`ErrorBound::Taylor`]. Preconditions: `set` is the set this was prepared
    /// for. Cost: the first call O(P) (a tree's: O(leaves)), parallel, about 700 bytes a
    /// patch (a tree: about as much a leaf); later calls nothing.
    pub fn taylor_bounds(&self, set: &SurfaceSet) -> &[taylor::TaylorBound] {
        use rayon::prelude::*;
        let errors = self.triangle_errors();
        self.taylor.get_or_init(|| {
            let errors = |p: usize| errors.get(p).filter(|_| errors.len() == set.patches.len());
            set.patches
                .par_iter()
                .enumerate()
                .map(|(p, patch)| taylor::TaylorBound::with_errors(patch, errors(p)))
                .collect()
        })
    }

    /// Every patch's [`taylor::TaylorBound::expansion`], computed on the first call and kept,
    /// for plans asked for [`ErrorBound::Expansion`]. Cost: the first call O(P), parallel,
    /// about a kilobyte a bicubic (its third derivatives' nets too); later calls nothing.
    pub fn expansion_bounds(&self, set: &SurfaceSet) -> &[taylor::TaylorBound] {
        use rayon::prelude::*;
        self.expansions.get_or_init(|| set.patches.par_iter().map(taylor::TaylorBound::expansion).collect())
    }

    /// The per-patch bounds `bound` plans with beside the second-derivative bound: None for
    /// [`ErrorBound::Hessian`], else [`Prepared::taylor_bounds`] or
    /// [`Prepared::expansion_bounds`].
    pub fn bounds_for(&self, set: &SurfaceSet, bound: ErrorBound) -> Option<&[taylor::TaylorBound]> {
        match bound {
            ErrorBound::Hessian => None,
            ErrorBound::Taylor => Some(self.taylor_bounds(set)),
            ErrorBound::Expansion => Some(self.expansion_bounds(set)),
        }
    }

    /// Every patch's [`bounds::TriangleErrors`] (what the a-posteriori check's triangle bound
    /// needs of the patch's [`bounds::HessianBound`]: scalings and eigenvalues, a dozen square
    /// roots), computed on the first call and kept; empty where the bounds were not asked for.
    /// Cost: the first call O(P), parallel; later calls nothing.
    pub fn triangle_errors(&self) -> &[bounds::TriangleErrors] {
        use rayon::prelude::*;
        self.triangle_errors.get_or_init(|| self.hessians.par_iter().map(|h| h.triangle_errors()).collect())
    }

    /// Every patch's [`screen::PatchView`] (box, sphere, normal cone), computed on the first
    /// call and kept. Precondition: `set` is the set this was prepared for. Cost: the first
    /// call O(P) cone computations, parallel; later calls nothing.
    pub fn views(&self, set: &SurfaceSet) -> &[screen::PatchView] {
        use rayon::prelude::*;
        self.views.get_or_init(|| set.patches.par_iter().map(screen::PatchView::new).collect())
    }

    /// Every patch's control-point box ([`screen::PatchView::bounding_box`]), computed on the
    /// first call and kept beside the views: the pixel tolerance of every frame reads these
    /// alone ([`screen::tolerances_into`]). Precondition as [`Prepared::views`]. Cost: the
    /// first call O(P) (and the views, if not made yet); later calls nothing.
    pub fn boxes(&self, set: &SurfaceSet) -> &[[glam::DVec3; 2]] {
        self.boxes.get_or_init(|| self.views(set).iter().map(screen::PatchView::bounding_box).collect())
    }

    /// Position and normal of every topology vertex (the view criteria's data), computed on
    /// the first call and kept. Precondition: `set` is the set this was prepared for. Cost:
    /// the first call O(V) evaluations.
    pub fn vertex_data(&self, set: &SurfaceSet) -> &[(glam::DVec3, glam::DVec3)] {
        self.vertex_data.get_or_init(|| view::vertex_data(set))
    }

    /// Every edge's midpoint and normals as its first and last patch see them (the
    /// silhouetteness criterion's data), computed on the first call and kept. Precondition:
    /// `set` is the set this was prepared for. Cost: the first call O(E) evaluations.
    pub fn edge_midpoints(&self, set: &SurfaceSet) -> &[[(glam::DVec3, glam::DVec3); 2]] {
        self.edge_midpoints.get_or_init(|| view::edge_midpoints(set))
    }

    /// The caps for `max_factor` over these minimums.
    pub fn caps(&self, max_factor: f64) -> resolve::Caps<'_> {
        resolve::Caps {
            max_factor,
            minimum_segments: &self.minimum_segments,
            minimum_interior: &self.minimum_interior,
        }
    }
}

/// The buffers a plan is made with, kept by a per-frame loop so that planning allocates
/// nothing once they have grown to the set ([`crate::scheme::Scheme::plan_into`]).
#[derive(Debug, Default)]
pub struct PlanScratch {
    pub(crate) tolerances: Vec<Option<f64>>,
    pub(crate) tolerance: tolerance::Scratch,
    pub(crate) per_edge: Vec<f64>,
    pub(crate) proposals: Vec<resolve::Proposals>,
    /// Time of the last plan's per-patch view stage and of its resolve stage.
    pub(crate) criterion_time: std::time::Duration,
    pub(crate) resolve_time: std::time::Duration,
}

impl PlanScratch {
    /// The patterns the last plan's a-posteriori check built, for the engine that writes
    /// that plan ([`tolerance::Scratch::take_patterns`]); None when it built none or they
    /// were taken.
    pub(crate) fn check_patterns(&mut self) -> Option<&mut crate::pattern::cache::PatternCache> {
        self.tolerance.take_patterns()
    }

    /// The last plan's pattern counts per patch, where its a-posteriori check found them
    /// ([`tolerance::Scratch::plan_counts`]), for the layout of that plan.
    pub(crate) fn plan_counts(&self) -> Option<&[(u32, u32)]> {
        self.tolerance.plan_counts()
    }

    /// The last plan's inner samples per edge, where its a-posteriori check counted them
    /// ([`tolerance::Scratch::edge_counts`]), for the layout of that plan.
    pub(crate) fn edge_counts(&self) -> Option<&[u32]> {
        self.tolerance.edge_counts()
    }

    /// How long the last plan made with these buffers spent in its criterion stage
    /// (culling, tolerances) and in resolving (proposals, edges, checks), where the plan
    /// measures them (the error-bounded criteria); zero otherwise.
    pub fn stage_times(&self) -> (std::time::Duration, std::time::Duration) {
        (self.criterion_time, self.resolve_time)
    }
}

/// Samplings for every edge and interior factors for every patch, as plain arrays a GPU can
/// upload as they are.
///
/// Per edge `e` (in `topology.edges` order, canonical orientation): `segments[e]` and
/// `factors[e]` always; `depths[e]` for [`SamplingKind::Warped`] plans (empty otherwise);
/// `lattice[lattice_offsets[e]..][..segments[e] + 1]` for [`SamplingKind::Lattice`] plans
/// (both empty otherwise). Per patch `p`: `interior[p]` and `visible[p]`.
#[derive(Debug, Clone, PartialEq)]
pub struct Plan {
    /// How the per-edge arrays turn into parameters ([`crate::sampling::param`]).
    pub kind: SamplingKind,
    /// Segments of each edge (`≥ 1`).
    pub segments: Vec<u32>,
    /// The real factor of each edge; equal to `segments` for uniform samplings, the lattice
    /// size for lattice samplings.
    pub factors: Vec<f32>,
    /// Depths of each edge's canonical start and end vertex (warped plans).
    pub depths: Vec<[f32; 2]>,
    /// Start of each edge's numerators in `lattice` (lattice plans).
    pub lattice_offsets: Vec<u32>,
    /// Lattice numerators of every edge, edge after edge (lattice plans).
    pub lattice: Vec<u32>,
    /// Interior factors per patch (`[u, v]`; triangles use the first).
    pub interior: Vec<[u32; 2]>,
    /// 1 for patches to tessellate, 0 for culled ones, which emit nothing (their edges with
    /// visible neighbours are still sampled as those neighbours need).
    pub visible: Vec<u32>,
}

impl Default for Plan {
    /// An empty plan (no edges, no patches), to fill with [`Plan::set_uniform`] or
    /// [`crate::scheme::Scheme::plan_into`].
    fn default() -> Self {
        Plan::integer(Vec::new(), Vec::new(), 0)
    }
}

impl Plan {
    /// The uniform plan: factor `n` everywhere. Errors for `n = 0` or `n > MAX_FACTOR`.
    pub fn uniform(set: &SurfaceSet, n: u32) -> Result<Plan> {
        let mut plan = Plan::default();
        plan.set_uniform(set, n)?;
        Ok(plan)
    }

    /// Makes this the uniform plan of factor `n` for `set`, every patch visible, reusing the
    /// buffers. Errors for `n = 0` or `n > MAX_FACTOR`. Cost: O(E + P), no allocation once
    /// the buffers have the set's size.
    pub fn set_uniform(&mut self, set: &SurfaceSet, n: u32) -> Result<()> {
        if n == 0 || n > MAX_FACTOR {
            return Err(Error::FactorOutOfRange {
                scheme: "uniform",
                factor: n as f64,
                expected: format!("an integer from 1 to {MAX_FACTOR}"),
            });
        }
        let (edges, patches) = (set.topology.edges.len(), set.patches.len());
        self.kind = SamplingKind::Uniform;
        self.segments.clear();
        self.segments.resize(edges, n);
        self.factors.clear();
        self.factors.resize(edges, n as f32);
        self.depths.clear();
        self.lattice_offsets.clear();
        self.lattice.clear();
        self.interior.clear();
        self.interior.resize(patches, [n, n]);
        self.visible.clear();
        self.visible.resize(patches, 1);
        Ok(())
    }

    /// A plan of uniform samplings with the given segments and interiors, every patch
    /// visible.
    pub fn integer(segments: Vec<u32>, interior: Vec<[u32; 2]>, patches: usize) -> Plan {
        Plan {
            kind: SamplingKind::Uniform,
            factors: segments.iter().map(|&s| s as f32).collect(),
            segments,
            depths: Vec::new(),
            lattice_offsets: Vec::new(),
            lattice: Vec::new(),
            interior,
            visible: vec![1; patches],
        }
    }

    /// `Some((n, interior))` when every edge has `n` segments of a uniform sampling, every
    /// patch the interior factors `interior`, and every patch is visible: then patches of one
    /// domain share one pattern input (the uniform writers' and the arithmetic layout's
    /// precondition). Cost: O(E + P), vectorized folds.
    pub fn one_factor(&self) -> Option<(u32, [u32; 2])> {
        if self.kind != SamplingKind::Uniform {
            return None;
        }
        let (&n, &interior) = (self.segments.first()?, self.interior.first()?);
        // Folds rather than `all`, which stops early and does not vectorize.
        let same = self.segments.iter().fold(true, |all, &s| all & (s == n))
            && self.interior.iter().fold(true, |all, f| all & (*f == interior))
            && self.visible.iter().fold(true, |all, &v| all & (v != 0));
        same.then_some((n, interior))
    }

    /// Number of edges the plan covers.
    pub fn edge_count(&self) -> usize {
        self.segments.len()
    }

    /// Whether patch `p` is tessellated.
    #[inline]
    pub fn is_visible(&self, p: usize) -> bool {
        self.visible[p] != 0
    }

    /// How many patches the plan leaves out (culled). Cost: O(P).
    pub fn culled_count(&self) -> usize {
        self.visible.iter().filter(|&&v| v == 0).count()
    }

    /// Segments of edge `e`.
    #[inline]
    pub fn segments(&self, e: usize) -> u32 {
        self.segments[e]
    }

    /// The real factor of edge `e`: the segment count for integer samplings.
    #[inline]
    pub fn factor(&self, e: usize) -> f64 {
        match self.kind {
            SamplingKind::Uniform | SamplingKind::Lattice => self.segments[e] as f64,
            _ => self.factors[e] as f64,
        }
    }

    /// Edge `e`'s row, as [`crate::sampling::param`] reads it.
    #[inline]
    pub fn row(&self, e: usize) -> EdgeRow<'_> {
        EdgeRow {
            segments: self.segments[e],
            factor: self.factors[e],
            depths: self.depths.get(e).copied().unwrap_or([1.0; 2]),
            lattice: match self.kind {
                SamplingKind::Lattice => &self.lattice[self.lattice_offsets[e] as usize..],
                _ => &[],
            },
        }
    }

    /// The `k`-th parameter of edge `e` in canonical orientation, `0 ≤ k ≤ segments`.
    #[inline]
    pub fn param(&self, e: usize, k: u32) -> f64 {
        crate::sampling::param(self.kind, &self.row(e), k)
    }

    /// Edge `e`'s inner parameters `k = 1 .. segments − 1` in canonical orientation, in order
    /// ([`crate::sampling::params`]: [`Plan::param`]'s values, shared work done once).
    #[inline]
    pub fn inner_params(&self, e: usize) -> impl Iterator<Item = f64> + '_ {
        crate::sampling::params(self.kind, &self.row(e), 1..self.segments[e])
    }

    /// The `k`-th parameter of edge `e` as seen by a patch that runs along it reversed or not.
    #[inline]
    pub fn local_param(&self, e: usize, k: u32, reversed: bool) -> f64 {
        if reversed {
            1.0 - self.param(e, self.segments[e] - k)
        } else {
            self.param(e, k)
        }
    }

    /// Checks that the plan was made for `set`: one row per edge and per patch, every array
    /// of its kind present, segments ≥ 1. Errors with [`Error::PlanMismatch`]. Cost: O(E + P).
    pub fn check(&self, set: &SurfaceSet) -> Result<()> {
        let (edges, patches) = (set.topology.edges.len(), set.patches.len());
        let mismatch = |what: String| Err(Error::PlanMismatch { what });
        if self.segments.len() != edges || self.factors.len() != edges {
            return mismatch(format!("{} edge rows for {edges} edges", self.segments.len()));
        }
        if self.interior.len() != patches || self.visible.len() != patches {
            return mismatch(format!("{} patch rows for {patches} patches", self.interior.len()));
        }
        if let Some(e) = self.segments.iter().position(|&s| s == 0) {
            return mismatch(format!("edge {e} has 0 segments"));
        }
        match self.kind {
            SamplingKind::Warped if self.depths.len() != edges => {
                mismatch(format!("{} depth rows for {edges} edges", self.depths.len()))
            }
            SamplingKind::Lattice => {
                let fits = self.lattice_offsets.len() == edges
                    && (0..edges).all(|e| {
                        self.lattice.len() as u64 > self.lattice_offsets[e] as u64 + self.segments[e] as u64
                    });
                if fits {
                    Ok(())
                } else {
                    mismatch("lattice rows do not cover every edge".into())
                }
            }
            _ => Ok(()),
        }
    }
}
