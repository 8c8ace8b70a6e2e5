//! Command-line criteria: turn `--factor`, `--tolerance`, `--pixel-error`, `--distance` or
//! `--silhouette` (with `--camera`, `--scheme`, `--max-factor`, `--no-cull`) into a plan and
//! the pattern that draws it.

use clap::{Args, ValueEnum};
use tessera::camera::Camera;
use tessera::criterion::tolerance::{self, Layout, PlanReport};
use tessera::criterion::view::{self, Mapping, ViewCriterion};
use tessera::criterion::{screen, Plan};
use tessera::pattern::semi_uniform::SemiUniform;
use tessera::pattern::transition::Transition;
use tessera::pattern::uniform::Uniform;
use tessera::pattern::Pattern;
use tessera::surface::SurfaceSet;

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum SchemeArg {
    /// One factor everywhere.
    Uniform,
    /// CudaTess: uniform core with Bresenham-like transition strips to each edge's factor.
    Transition,
    /// Semi-uniform (paper 000): power-of-two edge factors, the dyadic pattern of the patch's
    /// level with coarser edges snapped.
    SemiUniform,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum MappingArg {
    Linear,
    Quadratic,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum SilhouetteMode {
    /// DRS08 silhouetteness of each edge from its patches' normals (paper 000).
    Silhouetteness,
    /// Front/back classification of the edge's end vertices (paper 001).
    Vertices,
}

#[derive(Args)]
#[group(skip)]
pub struct CriterionArgs {
    /// Uniform factor: every edge is cut into N segments (the default criterion, N = 8).
    #[arg(long, value_name = "N", conflicts_with_all = ["tolerance", "pixel_error", "distance", "silhouette"])]
    pub factor: Option<u32>,
    /// Guaranteed object-space error: a distance, or a share of the bounding-box diagonal
    /// written with % (e.g. 0.1%).
    #[arg(long, value_name = "E", conflicts_with_all = ["factor", "pixel_error", "distance", "silhouette"])]
    pub tolerance: Option<String>,
    /// Guaranteed screen-space error in pixels for the camera (--camera); patches outside
    /// the view or facing away are culled unless --no-cull.
    #[arg(long, value_name = "P", conflicts_with_all = ["factor", "tolerance", "distance", "silhouette"])]
    pub pixel_error: Option<f64>,
    /// Factors from the distance to the eye plane, FMIN:FMAX (near edges get FMAX).
    #[arg(long, value_name = "FMIN:FMAX", conflicts_with_all = ["factor", "tolerance", "pixel_error", "silhouette"])]
    pub distance: Option<String>,
    /// Refine silhouettes: FMIN:FMAX (silhouette edges get FMAX).
    #[arg(long, value_name = "FMIN:FMAX", conflicts_with_all = ["factor", "tolerance", "pixel_error", "distance"])]
    pub silhouette: Option<String>,
    /// The mapping g of --distance.
    #[arg(long, value_enum, default_value = "linear")]
    pub mapping: MappingArg,
    /// How --silhouette finds silhouette edges.
    #[arg(long, value_enum, default_value = "silhouetteness")]
    pub silhouette_mode: SilhouetteMode,
    /// The camera: eye=X,Y,Z,target=X,Y,Z,fov=DEG,size=WxH with optional up=X,Y,Z, near=D,
    /// far=D (any subset; the rest from the default camera, which frames the model's
    /// bounding box at 1280x720 with a 45° vertical field of view).
    #[arg(long, value_name = "SPEC")]
    pub camera: Option<String>,
    /// Tessellation pattern (default: uniform for --factor, transition otherwise).
    #[arg(long, value_enum)]
    pub scheme: Option<SchemeArg>,
    /// Largest factor an adaptive criterion may use; when it stops a bound, tessera says so.
    #[arg(long, value_name = "N", default_value_t = 64)]
    pub max_factor: u32,
    /// Keep every patch (no view-frustum or back-face culling), so a closed input stays closed.
    #[arg(long)]
    pub no_cull: bool,
}

/// A plan, its pattern, a one-line description, and the guarantee report where one applies.
pub struct Chosen {
    pub plan: Plan,
    pub pattern: Box<dyn Pattern>,
    pub description: String,
    pub report: Option<PlanReport>,
    pub tolerance: Option<f64>,
}

fn range(text: &str, flag: &str) -> Result<(u32, u32), String> {
    let parse = |s: &str| s.trim().parse::<u32>().ok().filter(|&v| v >= 1);
    match text.split_once(':').map(|(a, b)| (parse(a), parse(b))) {
        Some((Some(a), Some(b))) if a <= b => Ok((a, b)),
        _ => Err(format!("{flag} {text}: expected FMIN:FMAX, integers with 1 ≤ FMIN ≤ FMAX")),
    }
}

/// Parses `0.1%` (of `diagonal`) or an absolute distance.
pub fn parse_tolerance(text: &str, diagonal: f64) -> Result<f64, String> {
    let (number, relative) = match text.strip_suffix('%') {
        Some(n) => (n, true),
        None => (text, false),
    };
    let v: f64 = number.trim().parse().map_err(|_| format!("--tolerance {text}: not a number"))?;
    if !(v.is_finite() && v > 0.0) {
        return Err(format!("--tolerance {text}: must be a positive number"));
    }
    Ok(if relative { v / 100.0 * diagonal } else { v })
}

pub fn camera(args: &CriterionArgs, set: &SurfaceSet) -> Result<Camera, tessera::Error> {
    let (lo, hi) = set.bounds();
    let default = Camera::framing(lo, hi, 1280, 720);
    match &args.camera {
        Some(spec) => Camera::parse(spec, &default),
        None => Ok(default),
    }
}

pub fn choose(args: &CriterionArgs, set: &SurfaceSet) -> Result<Chosen, Box<dyn std::error::Error>> {
    let adaptive = args.factor.is_none()
        && (args.tolerance.is_some()
            || args.pixel_error.is_some()
            || args.distance.is_some()
            || args.silhouette.is_some());
    let scheme = args.scheme.unwrap_or(if adaptive { SchemeArg::Transition } else { SchemeArg::Uniform });
    let (layout, pattern): (Layout, Box<dyn Pattern>) = match scheme {
        SchemeArg::Uniform => (Layout::Uniform, Box::new(Uniform)),
        SchemeArg::Transition => (Layout::Transition, Box::new(Transition)),
        SchemeArg::SemiUniform => (Layout::Dyadic, Box::new(SemiUniform)),
    };
    if args.max_factor == 0 || args.max_factor > tessera::criterion::MAX_FACTOR {
        return Err(
            format!("--max-factor {}: use 1 to {}", args.max_factor, tessera::criterion::MAX_FACTOR).into()
        );
    }
    let scheme_name = match scheme {
        SchemeArg::Uniform => "uniform",
        SchemeArg::Transition => "transition",
        SchemeArg::SemiUniform => "semi-uniform",
    };
    if !adaptive {
        let n = args.factor.unwrap_or(8);
        if scheme == SchemeArg::SemiUniform && !n.is_power_of_two() {
            return Err(format!("--factor {n} with --scheme semi-uniform: use a power of two").into());
        }
        let plan = Plan::uniform(set, n)?;
        return Ok(Chosen {
            plan,
            pattern,
            description: format!("{scheme_name}, factor {n}"),
            report: None,
            tolerance: None,
        });
    }
    let cull = !args.no_cull;
    if let Some(t) = &args.tolerance {
        let (lo, hi) = set.bounds();
        let eps = parse_tolerance(t, lo.distance(hi))?;
        let (plan, report) = tolerance::plan(
            set,
            &vec![Some(eps); set.patches.len()],
            layout,
            pattern.as_ref(),
            args.max_factor,
        );
        return Ok(Chosen {
            plan,
            pattern,
            description: format!("{scheme_name}, tolerance {eps:.4e}"),
            report: Some(report),
            tolerance: Some(eps),
        });
    }
    let cam = camera(args, set)?;
    if let Some(px) = args.pixel_error {
        if !(px.is_finite() && px > 0.0) {
            return Err(format!("--pixel-error {px}: must be a positive number of pixels").into());
        }
        let eps = screen::tolerances(set, &cam, px, cull);
        let (plan, report) = tolerance::plan(set, &eps, layout, pattern.as_ref(), args.max_factor);
        return Ok(Chosen {
            plan,
            pattern,
            description: format!("{scheme_name}, {px} px screen-space error"),
            report: Some(report),
            tolerance: None,
        });
    }
    let (criterion, text, flag) = match (&args.distance, &args.silhouette) {
        (Some(d), _) => {
            let mapping =
                if args.mapping == MappingArg::Linear { Mapping::Linear } else { Mapping::Quadratic };
            (ViewCriterion::Distance(mapping), d, "--distance")
        }
        (None, Some(s)) => {
            let c = match args.silhouette_mode {
                SilhouetteMode::Silhouetteness => ViewCriterion::Silhouetteness,
                SilhouetteMode::Vertices => ViewCriterion::SilhouetteVertices,
            };
            (c, s, "--silhouette")
        }
        (None, None) => unreachable!("adaptive implies a criterion"),
    };
    let (fmin, fmax) = range(text, flag)?;
    let fmax = fmax.min(args.max_factor);
    let plan = view::plan(set, &cam, criterion, fmin.min(fmax), fmax, layout, cull);
    Ok(Chosen {
        plan,
        pattern,
        description: format!("{scheme_name}, {flag} {text}"),
        report: None,
        tolerance: None,
    })
}
