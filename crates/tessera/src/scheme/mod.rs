//! Schemes: each published tessellation scheme as one closed type that owns its pattern, its
//! edge rule, its interior rule, its caps and the criteria it accepts.
//!
//! ```text
//! Scheme::plan(set, criterion, options) ─► SchemePlan { plan (plain arrays), pattern, report }
//!                                             └─► engine::tessellate(set, &plan, &pattern, ..)
//! ```
//!
//! | scheme | edge rule | interior rule | criteria |
//! | --- | --- | --- | --- |
//! | [`Scheme::Uniform`] | integer, one factor everywhere | global | factor, tolerance, pixel error, view |
//! | [`Scheme::Transition`] (CudaTess) | integer, maximum over the edge's patches | core + transition strips | the same |
//! | [`Scheme::SemiUniform`] (paper 000) | powers of two up to `2^max_level` | the patch level | the same |
//! | [`Scheme::Sd2`] (paper 001) | symmetric real factors (warped) | largest edge | factor, distance, vertex silhouettes |
//! | [`Scheme::Hardware`] (Direct3D 11) | its partitioning, in 16.16 fixed point | `max` reduction | factor, view |
//! | [`Scheme::Esc`] (paper 002) | lattice points chosen by the distance test | level `3n` | its own ([`Criterion::Esc`]) |
//!
//! What a scheme accepts — criterion, factor ranges, surface kinds, engine — is decided in one
//! place, [`validate`], which every planner, the GPU engine and the command-line tool call:
//! a criterion it does not accept is an [`Error::CriterionNotAccepted`], a factor it cannot
//! draw an [`Error::FactorOutOfRange`], a patch kind it is not defined for an
//! [`Error::PatchKindNotAccepted`], an engine that does not draw it an
//! [`Error::EngineNotSupported`]. Applications use the [`crate::tessellator::Tessellator`],
//! which plans through [`Scheme::plan_into`] each frame.

use crate::camera::Camera;
use crate::criterion::esc::{self as esc_criterion, EscOptions};
use crate::criterion::resolve::{EdgeRule, InteriorRule};
use crate::criterion::sd2::{self as sd2_criterion, LevelFunction, Sd2Options};
use crate::criterion::tolerance::{self, BoundReport};
use crate::criterion::view::{self, EdgeFactors, Mapping, ViewCriterion};
pub use crate::criterion::PlanScratch;
use crate::criterion::{screen, Plan, MAX_FACTOR};
use crate::error::{Error, Result};
use crate::pattern::esc::Esc;
use crate::pattern::hardware::{Hardware, Partitioning};
use crate::pattern::sd2::Sd2;
use crate::pattern::semi_uniform::{SemiUniform, MAX_LEVEL as SEMI_UNIFORM_MAX_LEVEL};
use crate::pattern::transition::Transition;
use crate::pattern::uniform::Uniform;
use crate::pattern::{LocalTessellation, Pattern, PatternInput};
use crate::sampling::Spacing;
use crate::surface::SurfaceSet;
use rayon::prelude::*;

pub mod domain_pattern;
mod validate;
pub use validate::{
    pinched_beyond_the_gpu, pinched_on_gpu, validate, Accepted, Engine, GPU_CHECK_MAX_FACTOR,
};

/// A tessellation scheme: a pattern with the rules that feed it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scheme {
    /// One factor everywhere: the baseline.
    Uniform,
    /// CudaTess (paper 003): per-edge factors, a uniform core, transition strips.
    Transition,
    /// Semi-uniform (paper 000): power-of-two edge factors up to `2^max_level`
    /// (`max_level ≤ 8`), the dyadic pattern of the patch's level with coarser edges snapped.
    SemiUniform { max_level: u32 },
    /// SD-2 (paper 001): at most two real factors per triangle, strips; `warp`
    /// reverse-projects the pattern with the vertex depths (§3.3). Triangles only.
    Sd2 { warp: bool },
    /// The Direct3D 11 hardware tessellator with one of its partitionings.
    Hardware(Partitioning),
    /// ESC (paper 002): bicubic patches only, level per object up to `max_level` (`≤ 6`).
    Esc { max_level: u32 },
}

/// Options of [`Scheme::plan`] that are not the criterion.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlanOptions {
    /// The camera, for view-dependent criteria, SD-2 and ESC levels and culling. Criteria
    /// that need one fail with [`Error::NeedsCamera`] without it.
    pub camera: Option<Camera>,
    /// Leave out patches outside the view or facing away from [`PlanOptions::camera`] (the
    /// mesh is then open where they were).
    pub cull: bool,
    /// Largest factor an adaptive criterion may use (`1..=MAX_FACTOR`); where it stops a
    /// bound, the report says so.
    pub max_factor: u32,
    /// Largest output the error-bounded criteria may build while they check their bounds;
    /// beyond it they refuse with [`Error::OutputTooLarge`].
    pub max_triangles: u64,
    /// The guaranteed bound the error-bounded criteria plan with ([`ErrorBound`]).
    pub bound: ErrorBound,
}

impl Default for PlanOptions {
    fn default() -> Self {
        PlanOptions {
            camera: None,
            cull: false,
            max_factor: 64,
            max_triangles: u64::MAX,
            bound: ErrorBound::Hessian,
        }
    }
}

pub use crate::criterion::{Criterion, ErrorBound, Prepared};

/// A plan, the pattern that draws it, and the guarantee report where the criterion has one.
#[derive(Debug, Clone)]
pub struct SchemePlan {
    pub plan: Plan,
    pub pattern: SchemePattern,
    pub report: Option<BoundReport>,
}

impl Default for SchemePlan {
    /// An empty uniform plan, for [`Scheme::plan_into`] to fill.
    fn default() -> Self {
        SchemePlan { plan: Plan::default(), pattern: SchemePattern::Uniform(Uniform), report: None }
    }
}

/// The pattern of each scheme, as one closed type (no allocation, and an engine can match on
/// it).
#[derive(Debug, Clone)]
pub enum SchemePattern {
    Uniform(Uniform),
    Transition(Transition),
    SemiUniform(SemiUniform),
    Sd2(Sd2),
    Hardware(Hardware),
    Esc(Esc),
}

impl SchemePattern {
    fn inner(&self) -> &dyn Pattern {
        match self {
            SchemePattern::Uniform(p) => p,
            SchemePattern::Transition(p) => p,
            SchemePattern::SemiUniform(p) => p,
            SchemePattern::Sd2(p) => p,
            SchemePattern::Hardware(p) => p,
            SchemePattern::Esc(p) => p,
        }
    }
}

impl Pattern for SchemePattern {
    fn counts(&self, input: &PatternInput) -> (u32, u32) {
        self.inner().counts(input)
    }
    fn triangulate(&self, input: &PatternInput, out: &mut LocalTessellation) {
        self.inner().triangulate(input, out)
    }
    fn interior_grid(&self, input: &PatternInput) -> Option<[u32; 2]> {
        self.inner().interior_grid(input)
    }
    fn grid_cells(&self, input: &PatternInput) -> Option<[u32; 2]> {
        self.inner().grid_cells(input)
    }
    fn core_cells(&self, input: &PatternInput) -> Option<([u32; 2], u32)> {
        self.inner().core_cells(input)
    }
    fn core_grid(&self, input: &PatternInput) -> Option<crate::pattern::CoreGrid> {
        self.inner().core_grid(input)
    }
    fn build_after_core(&self, input: &PatternInput, out: &mut LocalTessellation) {
        self.inner().build_after_core(input, out)
    }
    fn depends_on_patch(&self) -> bool {
        self.inner().depends_on_patch()
    }
    fn cut_through_corners_0_and_2(&self) -> bool {
        self.inner().cut_through_corners_0_and_2()
    }
    fn strips(&self, input: &PatternInput, out: &mut Vec<u32>) -> bool {
        self.inner().strips(input, out)
    }
    fn name(&self) -> &'static str {
        self.inner().name()
    }
    fn as_any(&self) -> Option<&dyn std::any::Any> {
        self.inner().as_any()
    }
}

impl Scheme {
    /// Semi-uniform's default highest level (paper 000's benchmarks use 3 and 5).
    pub const DEFAULT_SEMI_UNIFORM_LEVEL: u32 = 5;
    /// ESC's default `Lmax` (the paper's).
    pub const DEFAULT_ESC_LEVEL: u32 = 3;

    /// The scheme used when none is named: uniform for a fixed factor, ESC for its own
    /// criterion, transition for the adaptive criteria.
    pub fn default_for(criterion: &Criterion) -> Scheme {
        match criterion {
            Criterion::Factor(_) => Scheme::Uniform,
            Criterion::Esc { .. } => Scheme::Esc { max_level: Self::DEFAULT_ESC_LEVEL },
            _ => Scheme::Transition,
        }
    }

    /// Every scheme, in the command line's order, with the default levels and no warp.
    pub const ALL: [Scheme; 9] = [
        Scheme::Uniform,
        Scheme::Transition,
        Scheme::SemiUniform { max_level: Self::DEFAULT_SEMI_UNIFORM_LEVEL },
        Scheme::Sd2 { warp: false },
        Scheme::Hardware(Partitioning::Integer),
        Scheme::Hardware(Partitioning::Pow2),
        Scheme::Hardware(Partitioning::FractionalOdd),
        Scheme::Hardware(Partitioning::FractionalEven),
        Scheme::Esc { max_level: Self::DEFAULT_ESC_LEVEL },
    ];

    /// The scheme of a [`Scheme::name`] (default levels, no warp), for front ends that take
    /// the scheme as text. Cost: O(1).
    pub fn from_name(name: &str) -> Option<Scheme> {
        Self::ALL.into_iter().find(|s| s.name() == name)
    }

    /// The name the command line and reports use.
    pub fn name(&self) -> &'static str {
        match self {
            Scheme::Uniform => "uniform",
            Scheme::Transition => "transition",
            Scheme::SemiUniform { .. } => "semi-uniform",
            Scheme::Sd2 { .. } => "sd2",
            Scheme::Hardware(Partitioning::Integer) => "integer",
            Scheme::Hardware(Partitioning::Pow2) => "pow2",
            Scheme::Hardware(Partitioning::FractionalOdd) => "fractional-odd",
            Scheme::Hardware(Partitioning::FractionalEven) => "fractional-even",
            Scheme::Esc { .. } => "esc",
        }
    }

    /// The silhouette test [`ViewCriterion`] a scheme draws silhouettes with by default:
    /// SD-2 needs a level function (vertex classification), the others use silhouetteness.
    pub fn default_silhouette(&self) -> ViewCriterion {
        match self {
            Scheme::Sd2 { .. } => ViewCriterion::SilhouetteVertices,
            _ => ViewCriterion::Silhouetteness,
        }
    }

    /// How resolved factors become edge samplings (None for ESC, whose edges are decided by
    /// their owner patch's distance test).
    pub fn edge_rule(&self) -> Option<EdgeRule> {
        match self {
            Scheme::Uniform | Scheme::Transition => Some(EdgeRule::Integer),
            Scheme::SemiUniform { .. } => Some(EdgeRule::PowerOfTwo),
            Scheme::Sd2 { .. } => Some(EdgeRule::Fractional(Spacing::Symmetric)),
            Scheme::Hardware(p) => Some(EdgeRule::Fractional(Spacing::Hardware(*p))),
            Scheme::Esc { .. } => None,
        }
    }

    /// How interior factors follow from the edges.
    pub fn interior_rule(&self) -> InteriorRule {
        match self {
            Scheme::Uniform => InteriorRule::Global,
            Scheme::Transition => InteriorRule::Core,
            Scheme::SemiUniform { .. } | Scheme::Esc { .. } => InteriorRule::Level,
            Scheme::Sd2 { .. } | Scheme::Hardware(_) => InteriorRule::MaxEdge,
        }
    }

    /// The largest edge factor the scheme itself can draw (before `--max-factor`).
    pub fn factor_cap(&self) -> f64 {
        match self {
            Scheme::SemiUniform { max_level } => (1u32 << (*max_level).min(SEMI_UNIFORM_MAX_LEVEL)) as f64,
            Scheme::Hardware(p) => p.range().1 as f64,
            _ => MAX_FACTOR as f64,
        }
    }

    /// The scheme's pattern where it depends on the scheme alone: all but ESC's (its
    /// insertion grids come with the plan) and the warped SD-2's (its corner depths come from
    /// the camera), which give None. For drawing or describing a plan made elsewhere (the GPU
    /// engine's). Cost: O(1).
    pub fn fixed_pattern(&self) -> Option<SchemePattern> {
        Some(match *self {
            Scheme::Uniform => SchemePattern::Uniform(Uniform),
            Scheme::Transition => SchemePattern::Transition(Transition),
            Scheme::SemiUniform { .. } => SchemePattern::SemiUniform(SemiUniform),
            Scheme::Hardware(partitioning) => SchemePattern::Hardware(Hardware { partitioning }),
            Scheme::Sd2 { warp: false } => SchemePattern::Sd2(Sd2::default()),
            Scheme::Sd2 { warp: true } | Scheme::Esc { .. } => return None,
        })
    }

    /// Plans `set` under `criterion`. Checks everything a caller can get wrong first: the
    /// criterion ([`Scheme::accepts`]), the factor ranges ([`Error::FactorOutOfRange`]), the
    /// patch kinds ([`Error::PatchKindNotAccepted`]), the camera ([`Error::NeedsCamera`]).
    /// Cost: that of the criterion — O(V + E + P) evaluations for the view criteria, bound
    /// computations and a-posteriori pattern checks for the error-bounded ones.
    pub fn plan(&self, set: &SurfaceSet, criterion: &Criterion, options: &PlanOptions) -> Result<SchemePlan> {
        validate(*self, criterion, options, set, Engine::Cpu)?;
        self.plan_prepared(set, &Prepared::for_criterion(set, criterion), criterion, options)
    }

    /// [`Scheme::plan`] with the view-independent data prepared once ([`Prepared`]).
    /// Preconditions: `prepared` was made for `set` (with bounds for the error-bounded
    /// criteria; they are computed here otherwise).
    pub fn plan_prepared(
        &self,
        set: &SurfaceSet,
        prepared: &Prepared,
        criterion: &Criterion,
        options: &PlanOptions,
    ) -> Result<SchemePlan> {
        let mut planned = SchemePlan::default();
        self.plan_into(set, prepared, criterion, options, &mut PlanScratch::default(), &mut planned)?;
        Ok(planned)
    }

    /// [`Scheme::plan_prepared`] into `out`, reusing its buffers and `scratch`'s, as a
    /// per-frame loop ([`crate::tessellator::Tessellator`]) calls it: for the uniform and
    /// error-bounded criteria (factor, tolerance, pixel error) with the integer schemes, a
    /// frame allocates nothing once the buffers have grown to the set. On error `out` is
    /// left in an unspecified but valid state.
    pub fn plan_into(
        &self,
        set: &SurfaceSet,
        prepared: &Prepared,
        criterion: &Criterion,
        options: &PlanOptions,
        scratch: &mut PlanScratch,
        out: &mut SchemePlan,
    ) -> Result<()> {
        scratch.tolerance.forget_patterns();
        let accepted = validate(*self, criterion, options, set, Engine::Cpu)?;
        scratch.criterion_time = Default::default();
        scratch.resolve_time = Default::default();
        if let Scheme::Esc { max_level } = *self {
            *out = self.plan_esc(set, criterion, options, max_level)?;
            return Ok(());
        }
        if let Scheme::Sd2 { warp } = *self {
            *out = self.plan_sd2(set, criterion, options, warp, accepted.cap)?;
            return Ok(());
        }
        let rule = accepted.edge_rule.expect("every scheme but ESC has an edge rule");
        let interior = accepted.interior_rule;
        out.pattern = self.fixed_pattern().expect("SD-2 and ESC are planned above");
        out.report = None;
        let cap = accepted.cap;
        let caps = prepared.caps(cap);
        let camera = options.camera;
        let cull_camera = || camera.ok_or(Error::NeedsCamera { what: "culling" });
        match *criterion {
            Criterion::Factor(f) if rule == EdgeRule::Integer || rule == EdgeRule::PowerOfTwo => {
                let plan = &mut out.plan;
                plan.set_uniform(set, f as u32)?;
                if options.cull {
                    let view = cull_camera()?.view();
                    screen::visibility_into(set, prepared.views(set), &view, true, &mut plan.visible);
                }
            }
            Criterion::Factor(_) | Criterion::View { .. } => {
                let (camera, factors) = match *criterion {
                    Criterion::Factor(f) => {
                        let camera = if options.cull {
                            cull_camera()?
                        } else {
                            camera.unwrap_or_else(|| framing(set))
                        };
                        (camera, EdgeFactors::Fixed(f))
                    }
                    Criterion::View { criterion, fmin, fmax } => {
                        let camera = camera.ok_or(Error::NeedsCamera { what: "a view criterion" })?;
                        let fmax = fmax.min(cap);
                        (camera, EdgeFactors::View { criterion, fmin: fmin.min(fmax), fmax })
                    }
                    _ => unreachable!("matched above"),
                };
                let cull = options.cull;
                let plan = &mut out.plan;
                view::plan_into(set, prepared, &camera, factors, rule, interior, &caps, cull, scratch, plan);
            }
            Criterion::Tolerance(_) | Criterion::PixelError(_) => {
                // Each patch's object-space tolerance (None: culled).
                let start = std::time::Instant::now();
                let eps = &mut scratch.tolerances;
                match *criterion {
                    Criterion::PixelError(px) => {
                        let camera = camera.ok_or(Error::NeedsCamera { what: "a pixel error" })?;
                        screen::tolerances_into(
                            set,
                            prepared.views(set),
                            prepared.boxes(set),
                            &camera.view(),
                            px,
                            options.cull,
                            eps,
                        );
                    }
                    Criterion::Tolerance(e) if options.cull => {
                        let view = cull_camera()?.view();
                        let views = prepared.views(set);
                        eps.resize(set.patches.len(), None);
                        eps.par_iter_mut().zip(&set.patches).zip(views).for_each(|((o, patch), v)| {
                            *o = (!v.culled(patch, &view)).then_some(e);
                        });
                    }
                    Criterion::Tolerance(e) => {
                        eps.clear();
                        eps.resize(set.patches.len(), Some(e));
                    }
                    _ => unreachable!("matched above"),
                }
                scratch.criterion_time = start.elapsed();
                let start = std::time::Instant::now();
                let report = tolerance::plan_limited(
                    set,
                    prepared,
                    eps,
                    rule,
                    interior,
                    &out.pattern,
                    cap as u32,
                    options.max_triangles,
                    prepared.bounds_for(set, options.bound),
                    &mut scratch.tolerance,
                    &mut out.plan,
                )?;
                scratch.resolve_time = start.elapsed();
                out.report = Some(report);
            }
            Criterion::Esc { .. } => unreachable!("refused by accepts"),
        }
        Ok(())
    }

    fn plan_sd2(
        &self,
        set: &SurfaceSet,
        criterion: &Criterion,
        options: &PlanOptions,
        warp: bool,
        cap: f64,
    ) -> Result<SchemePlan> {
        let (level, fmin, fmax) = match *criterion {
            Criterion::Factor(f) => (LevelFunction::Distance(Mapping::Linear), f, f),
            Criterion::View { criterion: ViewCriterion::Distance(m), fmin, fmax } => {
                let fmax = fmax.min(cap);
                (LevelFunction::Distance(m), fmin.min(fmax), fmax)
            }
            Criterion::View { criterion: ViewCriterion::SilhouetteVertices, fmin, fmax } => {
                let fmax = fmax.min(cap);
                (LevelFunction::Silhouette, fmin.min(fmax), fmax)
            }
            _ => unreachable!("refused by accepts"),
        };
        // A fixed factor needs no camera, but the warp and culling do.
        let camera = match (options.camera, criterion) {
            (Some(c), _) => c,
            (None, Criterion::Factor(_)) if !warp && !options.cull => framing(set),
            _ => return Err(Error::NeedsCamera { what: "SD-2 with a level function, the warp or culling" }),
        };
        let sd2_options = Sd2Options { level, fmin, fmax, warp, cull: options.cull };
        let (plan, pattern) = sd2_criterion::plan(set, &camera, &sd2_options)?;
        Ok(SchemePlan { plan, pattern: SchemePattern::Sd2(pattern), report: None })
    }

    fn plan_esc(
        &self,
        set: &SurfaceSet,
        criterion: &Criterion,
        options: &PlanOptions,
        max_level: u32,
    ) -> Result<SchemePlan> {
        // Bicubic patches only: `validate` checked.
        let Criterion::Esc { threshold, level } = *criterion else { unreachable!("refused by accepts") };
        let camera = match (options.camera, level) {
            (Some(c), _) => c,
            (None, Some(_)) => framing(set),
            (None, None) => return Err(Error::NeedsCamera { what: "ESC's levels per object" }),
        };
        let esc_options = EscOptions { max_level, level, threshold, ..EscOptions::default() };
        let (plan, pattern) = esc_criterion::plan(set, &camera, &esc_options)?;
        Ok(SchemePlan { plan, pattern: SchemePattern::Esc(pattern), report: None })
    }
}

/// The camera that frames the set's bounding box (1280×720, 45°): where a plan needs some
/// camera for data the criterion does not depend on.
fn framing(set: &SurfaceSet) -> Camera {
    let (lo, hi) = set.bounds();
    Camera::framing(lo, hi, 1280, 720)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::criterion::esc::Threshold;
    use crate::surface::{Patch, RationalBicubic};
    use glam::DVec3;

    #[test]
    fn every_scheme_is_found_by_its_name_once() {
        let names: Vec<&str> = Scheme::ALL.iter().map(Scheme::name).collect();
        for (k, name) in names.iter().enumerate() {
            assert_eq!(Scheme::from_name(name), Some(Scheme::ALL[k]));
            assert!(!names[..k].contains(name), "{name} twice");
        }
        assert_eq!(Scheme::from_name("fractional_odd"), None);
        assert_eq!(Scheme::from_name(""), None);
    }

    /// One flat cubic Bézier triangle.
    pub(super) fn triangles() -> SurfaceSet {
        let points = std::array::from_fn(|k| DVec3::new(k as f64, (k * k % 7) as f64, 0.0));
        let patch = Patch::BezierTriangle(crate::surface::BezierTriangle { points });
        SurfaceSet::from_patches(vec![patch], Default::default())
    }

    pub(super) fn flat() -> SurfaceSet {
        let points = std::array::from_fn(|k| DVec3::new((k / 4) as f64, (k % 4) as f64, 0.0));
        SurfaceSet::from_patches(
            vec![Patch::Bicubic(RationalBicubic { points, weights: [1.0; 16] })],
            Default::default(),
        )
    }

    #[test]
    fn schemes_refuse_what_they_cannot_honour_with_typed_errors() {
        let set = flat();
        let options = PlanOptions::default();
        let err = |scheme: Scheme, criterion: Criterion| scheme.plan(&set, &criterion, &options).unwrap_err();
        let hardware = Scheme::Hardware(Partitioning::FractionalOdd);
        assert!(matches!(
            err(hardware, Criterion::Tolerance(0.1)),
            Error::CriterionNotAccepted { scheme: "fractional-odd", .. }
        ));
        assert!(matches!(
            err(Scheme::Transition, Criterion::Esc { threshold: Threshold::High, level: None }),
            Error::CriterionNotAccepted { .. }
        ));
        assert!(matches!(
            err(Scheme::Esc { max_level: 3 }, Criterion::Factor(4.0)),
            Error::CriterionNotAccepted { scheme: "esc", .. }
        ));
        assert!(matches!(
            err(Scheme::Uniform, Criterion::Factor(5.5)),
            Error::FactorOutOfRange { scheme: "uniform", .. }
        ));
        assert!(matches!(
            err(Scheme::SemiUniform { max_level: 5 }, Criterion::Factor(6.0)),
            Error::FactorOutOfRange { scheme: "semi-uniform", .. }
        ));
        assert!(matches!(err(hardware, Criterion::Factor(64.0)), Error::FactorOutOfRange { .. }));
        assert!(matches!(err(Scheme::Transition, Criterion::PixelError(1.0)), Error::NeedsCamera { .. }));
        assert!(matches!(
            err(Scheme::Transition, Criterion::Tolerance(-1.0)),
            Error::InvalidParameter { .. }
        ));
        assert!(matches!(
            err(Scheme::Sd2 { warp: false }, Criterion::Factor(3.0)),
            Error::PatchKindNotAccepted { scheme: "sd2", kind: "quad", patch: 0, .. }
        ));
        let camera = Camera::framing(DVec3::ZERO, DVec3::ONE, 64, 64);
        let culled = PlanOptions { camera: Some(camera), cull: true, ..options };
        assert!(matches!(
            Scheme::Esc { max_level: 3 }.plan(
                &set,
                &Criterion::Esc { threshold: Threshold::High, level: Some(1) },
                &culled
            ),
            Err(Error::InvalidParameter { name: "cull", .. })
        ));
    }

    #[test]
    fn every_scheme_plans_its_default_criterion() {
        let set = flat();
        let camera = Camera::framing(DVec3::ZERO, DVec3::new(3.0, 3.0, 0.0), 64, 64);
        let options = PlanOptions { camera: Some(camera), ..PlanOptions::default() };
        for scheme in [
            Scheme::Uniform,
            Scheme::Transition,
            Scheme::SemiUniform { max_level: 5 },
            Scheme::Hardware(Partitioning::Integer),
            Scheme::Hardware(Partitioning::Pow2),
            Scheme::Hardware(Partitioning::FractionalOdd),
            Scheme::Hardware(Partitioning::FractionalEven),
        ] {
            let planned = scheme.plan(&set, &Criterion::Factor(8.0), &options).unwrap();
            planned.plan.check(&set).unwrap();
            // Factor 8 everywhere; fractional_odd cuts it into 9 segments (odd counts).
            let segments = if scheme == Scheme::Hardware(Partitioning::FractionalOdd) { 9 } else { 8 };
            assert!(
                planned.plan.segments.iter().all(|&s| s == segments),
                "{scheme:?}: {:?}",
                planned.plan.segments
            );
            assert!(planned.plan.factors.iter().all(|&f| f == 8.0), "{scheme:?}: {:?}", planned.plan.factors);
            assert_eq!(
                planned.pattern.name(),
                match scheme {
                    Scheme::Hardware(p) => p.name(),
                    _ => scheme.name(),
                }
            );
        }
        let esc = Scheme::Esc { max_level: 2 };
        let criterion = Criterion::Esc { threshold: Threshold::Medium, level: None };
        assert_eq!(Scheme::default_for(&criterion), Scheme::Esc { max_level: Scheme::DEFAULT_ESC_LEVEL });
        let planned = esc.plan(&set, &criterion, &options).unwrap();
        planned.plan.check(&set).unwrap();
        assert_eq!(planned.plan.kind, crate::sampling::SamplingKind::Lattice);
    }
}
