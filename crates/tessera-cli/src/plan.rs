//! Command-line criteria: turn `--factor`, `--tolerance`, `--pixel-error`, `--distance` or
//! `--silhouette` (with `--camera`, `--scheme`, `--max-factor`, `--cull`) into a plan and
//! the pattern that draws it.

use clap::{Args, ValueEnum};
use std::path::Path;
use tessera::camera::Camera;
use tessera::criterion::esc::{self, EscOptions, Threshold};
use tessera::criterion::sd2::{self, LevelFunction, Sd2Options};
use tessera::criterion::tolerance::{self, Layout, PlanReport};
use tessera::criterion::view::{self, FractionalFactors, Mapping, ViewCriterion};
use tessera::criterion::{screen, Plan};
use tessera::pattern::hardware::{Hardware, Partitioning};
use tessera::pattern::semi_uniform::SemiUniform;
use tessera::pattern::semi_uniform::MAX_LEVEL;
use tessera::pattern::transition::Transition;
use tessera::pattern::uniform::Uniform;
use tessera::pattern::Pattern;
use tessera::sampling::Spacing;
use tessera::surface::SurfaceSet;

#[derive(Clone, Copy, PartialEq, Eq, Debug, ValueEnum)]
pub enum SchemeArg {
    /// One factor everywhere.
    Uniform,
    /// CudaTess: uniform core with Bresenham-like transition strips to each edge's factor.
    Transition,
    /// Semi-uniform (paper 000): power-of-two edge factors, the dyadic pattern of the patch's
    /// level with coarser edges snapped.
    SemiUniform,
    /// SD-2 (paper 001): at most two different fractional factors per triangle from a level
    /// function (--distance or --silhouette), parallel × radial lines, strips. Triangles only.
    Sd2,
    /// The Direct3D 11 hardware tessellator, integer partitioning: factors rounded up, the
    /// exact points and triangles of the D3D11 reference tessellator.
    Integer,
    /// The hardware tessellator with factors rounded up to powers of two (pow2).
    Pow2,
    /// The hardware tessellator's fractional_odd partitioning: real factors, points move
    /// continuously.
    FractionalOdd,
    /// The hardware tessellator's fractional_even partitioning.
    FractionalEven,
    /// ESC (paper 002): bicubic patches only; 18 coarse triangles per patch, a level per
    /// object from the camera, candidates inserted by the distance test (--quality,
    /// --threshold), strips with virtual vertices.
    Esc,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum QualityArg {
    /// Threshold 0.4 % of each object's bounding-box diagonal (≈ 94 % of the non-adaptive
    /// triangles on the paper's Teacups scene).
    High,
    /// Threshold 2.2 % of the diagonal (≈ 53 %).
    Medium,
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
    /// Uniform factor: every edge is cut into N segments (the default criterion, N = 8); a
    /// real number for the fractional schemes and SD-2.
    #[arg(long, value_name = "N", conflicts_with_all = ["tolerance", "pixel_error", "distance", "silhouette"])]
    pub factor: Option<f64>,
    /// Guaranteed object-space error: a distance, or a share of the bounding-box diagonal
    /// written with % (e.g. 0.1%).
    #[arg(long, value_name = "E", conflicts_with_all = ["factor", "pixel_error", "distance", "silhouette"])]
    pub tolerance: Option<String>,
    /// Guaranteed screen-space error in pixels for the camera (--camera); with --cull,
    /// patches outside the view or facing away are left out.
    #[arg(long, value_name = "P", conflicts_with_all = ["factor", "tolerance", "distance", "silhouette"])]
    pub pixel_error: Option<f64>,
    /// Factors from the distance to the eye plane, FMIN:FMAX (near edges get FMAX; reals for
    /// SD-2 and the fractional schemes).
    #[arg(long, value_name = "FMIN:FMAX", conflicts_with_all = ["factor", "tolerance", "pixel_error", "silhouette"])]
    pub distance: Option<String>,
    /// Refine silhouettes: FMIN:FMAX (silhouette edges get FMAX).
    #[arg(long, value_name = "FMIN:FMAX", conflicts_with_all = ["factor", "tolerance", "pixel_error", "distance"])]
    pub silhouette: Option<String>,
    /// The mapping g of --distance.
    #[arg(long, value_enum, default_value = "linear")]
    pub mapping: MappingArg,
    /// How --silhouette finds silhouette edges (default: vertices for SD-2, which needs a
    /// level function, silhouetteness otherwise).
    #[arg(long, value_enum)]
    pub silhouette_mode: Option<SilhouetteMode>,
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
    /// The highest level: semi-uniform M (edge factors up to 2^M; 0 to 8, default 5), ESC
    /// Lmax (0 to 6, default 3).
    #[arg(long, value_name = "M")]
    pub max_level: Option<u32>,
    /// ESC: one level L (0 to 6) for every patch instead of the camera's.
    #[arg(long, value_name = "L")]
    pub level: Option<u32>,
    /// ESC: the distance-test preset.
    #[arg(long, value_enum, conflicts_with = "threshold")]
    pub quality: Option<QualityArg>,
    /// ESC: the distance-test threshold ρ in model units (instead of --quality).
    #[arg(long, value_name = "D")]
    pub threshold: Option<f64>,
    /// SD-2: reverse-project the pattern with the vertex depths (paper 001, §3.3), so it is
    /// uniform on screen rather than in the domain.
    #[arg(long)]
    pub warp: bool,
    /// Leave out patches outside the camera's view frustum or facing away from it
    /// (conservative normal cone), as a renderer would: the mesh is then open where they
    /// were, and tessera says how many it culled. Off by default, so a closed input gives a
    /// closed mesh.
    #[arg(long)]
    pub cull: bool,
    /// Keep every patch: the default (kept so that older command lines still run).
    #[arg(long, hide = true, conflicts_with = "cull")]
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

fn range_f64(text: &str, flag: &str) -> Result<(f64, f64), String> {
    let parse = |s: &str| s.trim().parse::<f64>().ok().filter(|v| v.is_finite() && *v >= 1.0);
    match text.split_once(':').map(|(a, b)| (parse(a), parse(b))) {
        Some((Some(a), Some(b))) if a <= b => Ok((a, b)),
        _ => Err(format!("{flag} {text}: expected FMIN:FMAX, numbers with 1 ≤ FMIN ≤ FMAX")),
    }
}

pub fn scheme_name(scheme: SchemeArg) -> &'static str {
    match scheme {
        SchemeArg::Uniform => "uniform",
        SchemeArg::Transition => "transition",
        SchemeArg::SemiUniform => "semi-uniform",
        SchemeArg::Sd2 => "sd2",
        SchemeArg::Integer => "integer",
        SchemeArg::Pow2 => "pow2",
        SchemeArg::FractionalOdd => "fractional-odd",
        SchemeArg::FractionalEven => "fractional-even",
        SchemeArg::Esc => "esc",
    }
}

/// The view criterion of --distance / --silhouette, its text and flag.
fn view_criterion(args: &CriterionArgs, scheme: SchemeArg) -> Option<(ViewCriterion, &str, &'static str)> {
    match (&args.distance, &args.silhouette) {
        (Some(d), _) => {
            let mapping =
                if args.mapping == MappingArg::Linear { Mapping::Linear } else { Mapping::Quadratic };
            Some((ViewCriterion::Distance(mapping), d.as_str(), "--distance"))
        }
        (None, Some(s)) => {
            let default = if scheme == SchemeArg::Sd2 {
                SilhouetteMode::Vertices
            } else {
                SilhouetteMode::Silhouetteness
            };
            let c = match args.silhouette_mode.unwrap_or(default) {
                SilhouetteMode::Silhouetteness => ViewCriterion::Silhouetteness,
                SilhouetteMode::Vertices => ViewCriterion::SilhouetteVertices,
            };
            Some((c, s.as_str(), "--silhouette"))
        }
        (None, None) => None,
    }
}

/// Chooses the plan and pattern; `input` names the file in errors about its contents.
/// `max_triangles` bounds what the error-bounded criteria may build while they check their
/// bounds (they refuse with `Error::OutputTooLarge` beyond it).
pub fn choose(
    args: &CriterionArgs,
    set: &SurfaceSet,
    input: &Path,
    max_triangles: u64,
) -> Result<Chosen, Box<dyn std::error::Error>> {
    let adaptive = args.factor.is_none()
        && (args.tolerance.is_some()
            || args.pixel_error.is_some()
            || args.distance.is_some()
            || args.silhouette.is_some());
    let scheme = args.scheme.unwrap_or(if adaptive { SchemeArg::Transition } else { SchemeArg::Uniform });
    let name = scheme_name(scheme);
    if args.max_factor == 0 || args.max_factor > tessera::criterion::MAX_FACTOR {
        return Err(
            format!("--max-factor {}: use 1 to {}", args.max_factor, tessera::criterion::MAX_FACTOR).into()
        );
    }
    if args.warp && scheme != SchemeArg::Sd2 {
        return Err("--warp applies to --scheme sd2 only".into());
    }
    if scheme != SchemeArg::Esc
        && (args.level.is_some() || args.quality.is_some() || args.threshold.is_some())
    {
        return Err("--level, --quality and --threshold apply to --scheme esc only".into());
    }
    if scheme == SchemeArg::Esc {
        return choose_esc(args, set, input);
    }
    let max_level = args.max_level.unwrap_or(DEFAULT_MAX_LEVEL);
    if max_level > MAX_LEVEL {
        return Err(format!("--max-level {max_level}: use 0 to {MAX_LEVEL}").into());
    }
    match scheme {
        SchemeArg::Sd2
        | SchemeArg::Integer
        | SchemeArg::Pow2
        | SchemeArg::FractionalOdd
        | SchemeArg::FractionalEven => {
            return choose_fractional(args, set, scheme);
        }
        _ => {}
    }
    let (layout, pattern): (Layout, Box<dyn Pattern>) = match scheme {
        SchemeArg::Transition => (Layout::Transition, Box::new(Transition)),
        SchemeArg::SemiUniform => (Layout::Dyadic, Box::new(SemiUniform)),
        _ => (Layout::Uniform, Box::new(Uniform)),
    };
    // Semi-uniform: edge levels 0..=M, so factors up to 2^M.
    let max_factor =
        if scheme == SchemeArg::SemiUniform { args.max_factor.min(1 << max_level) } else { args.max_factor };
    if !adaptive {
        let f = args.factor.unwrap_or(8.0);
        if f.fract() != 0.0 || !(1.0..=tessera::criterion::MAX_FACTOR as f64).contains(&f) {
            return Err(format!(
                "--factor {f} with --scheme {name}: use an integer from 1 to {} (real factors need \
                 --scheme fractional-odd, fractional-even or sd2)",
                tessera::criterion::MAX_FACTOR
            )
            .into());
        }
        let n = f as u32;
        if scheme == SchemeArg::SemiUniform && (!n.is_power_of_two() || n > 1 << max_level) {
            return Err(format!(
                "--factor {n} with --scheme semi-uniform: use a power of two up to 2^{max_level} (--max-level)"
            )
            .into());
        }
        let mut plan = Plan::uniform(set, n)?;
        if args.cull {
            // A fixed factor has no camera of its own; --cull culls against --camera (or the
            // default camera) all the same.
            let cam = camera(args, set)?;
            plan.visible = set.patches.iter().map(|p| !screen::culled(p, &cam)).collect();
        }
        return Ok(Chosen {
            plan,
            pattern,
            description: format!("{name}, factor {n}"),
            report: None,
            tolerance: None,
        });
    }
    let cull = args.cull;
    if let Some(t) = &args.tolerance {
        let (lo, hi) = set.bounds();
        let eps = parse_tolerance(t, lo.distance(hi))?;
        let (plan, report) = tolerance::plan_limited(
            set,
            &vec![Some(eps); set.patches.len()],
            layout,
            pattern.as_ref(),
            max_factor,
            max_triangles,
        )?;
        return Ok(Chosen {
            plan,
            pattern,
            description: format!("{name}, tolerance {eps:.4e}"),
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
        let (plan, report) =
            tolerance::plan_limited(set, &eps, layout, pattern.as_ref(), max_factor, max_triangles)?;
        return Ok(Chosen {
            plan,
            pattern,
            description: format!("{name}, {px} px screen-space error"),
            report: Some(report),
            tolerance: None,
        });
    }
    let (criterion, text, flag) = view_criterion(args, scheme).expect("adaptive implies a criterion");
    let (fmin, fmax) = range(text, flag)?;
    let fmax = fmax.min(max_factor);
    let plan = view::plan(set, &cam, criterion, fmin.min(fmax), fmax, layout, cull);
    Ok(Chosen { plan, pattern, description: format!("{name}, {flag} {text}"), report: None, tolerance: None })
}

/// SD-2 and the fractional schemes: real factors, no error guarantee.
fn choose_fractional(
    args: &CriterionArgs,
    set: &SurfaceSet,
    scheme: SchemeArg,
) -> Result<Chosen, Box<dyn std::error::Error>> {
    let name = scheme_name(scheme);
    if args.tolerance.is_some() || args.pixel_error.is_some() {
        return Err(format!(
            "--scheme {name} gives no error guarantee: use --factor, --distance or --silhouette with it, \
             or --tolerance / --pixel-error with uniform, transition or semi-uniform"
        )
        .into());
    }
    let cam = camera(args, set)?;
    let cull = args.cull;
    let view = view_criterion(args, scheme);
    let (factors, description) = match (args.factor, view) {
        (Some(_), _) | (None, None) => {
            let f = args.factor.unwrap_or(8.0);
            if !(f.is_finite() && f >= 1.0 && f <= args.max_factor as f64) {
                return Err(
                    format!("--factor {f}: use a number from 1 to --max-factor {}", args.max_factor).into()
                );
            }
            // The hardware clamps larger factors; say so rather than tessellate another factor.
            if let Some(p) = partitioning(scheme) {
                let hi = p.range().1 as f64;
                if f > hi {
                    return Err(
                        format!("--factor {f}: the hardware's {} range is 1 to {hi}", p.name()).into()
                    );
                }
            }
            (FractionalFactors::Fixed(f), format!("{name}, factor {f}"))
        }
        (None, Some((criterion, text, flag))) => {
            let (fmin, fmax) = range_f64(text, flag)?;
            // Hardware schemes: the top of the range is the hardware's largest factor.
            let hardware_top = partitioning(scheme).map_or(f64::INFINITY, |p| p.range().1 as f64);
            let fmax = fmax.min(args.max_factor as f64).min(hardware_top);
            (
                FractionalFactors::View { criterion, fmin: fmin.min(fmax), fmax },
                format!("{name}, {flag} {text}"),
            )
        }
    };
    if scheme == SchemeArg::Sd2 {
        let level = match factors {
            FractionalFactors::Fixed(_) => LevelFunction::Distance(Mapping::Linear),
            FractionalFactors::View { criterion: ViewCriterion::Distance(m), .. } => {
                LevelFunction::Distance(m)
            }
            FractionalFactors::View { criterion: ViewCriterion::SilhouetteVertices, .. } => {
                LevelFunction::Silhouette
            }
            FractionalFactors::View { criterion: ViewCriterion::Silhouetteness, .. } => {
                return Err(
                    "--scheme sd2 needs a level function: use --silhouette-mode vertices (the default \
                            for sd2) or --distance"
                        .into(),
                )
            }
        };
        let (fmin, fmax) = match factors {
            FractionalFactors::Fixed(f) => (f, f),
            FractionalFactors::View { fmin, fmax, .. } => (fmin, fmax),
        };
        let options = Sd2Options { level, fmin, fmax, warp: args.warp, cull };
        let (plan, pattern) = sd2::plan(set, &cam, &options)?;
        let warp = if args.warp { ", warped" } else { "" };
        return Ok(Chosen {
            plan,
            pattern: Box::new(pattern),
            description: format!("{description}{warp}"),
            report: None,
            tolerance: None,
        });
    }
    let partitioning = partitioning(scheme).expect("a hardware scheme");
    let plan = view::fractional_plan(set, &cam, factors, Spacing::Hardware(partitioning), cull);
    Ok(Chosen {
        plan,
        pattern: Box::new(Hardware { partitioning }),
        description,
        report: None,
        tolerance: None,
    })
}

/// The hardware tessellator's partitioning of a scheme, if it is one of the four.
pub fn partitioning(scheme: SchemeArg) -> Option<Partitioning> {
    match scheme {
        SchemeArg::Integer => Some(Partitioning::Integer),
        SchemeArg::Pow2 => Some(Partitioning::Pow2),
        SchemeArg::FractionalOdd => Some(Partitioning::FractionalOdd),
        SchemeArg::FractionalEven => Some(Partitioning::FractionalEven),
        _ => None,
    }
}

/// Semi-uniform's default highest level M (paper 000's benchmarks use 3 and 5).
pub const DEFAULT_MAX_LEVEL: u32 = 5;

/// ESC: its own criterion (level per object from the camera, distance test).
fn choose_esc(
    args: &CriterionArgs,
    set: &SurfaceSet,
    input: &Path,
) -> Result<Chosen, Box<dyn std::error::Error>> {
    if args.cull {
        return Err("--scheme esc chooses one level per object and culls nothing: leave out --cull".into());
    }
    if let Some(p) = set.patches.iter().position(|p| p.domain() != tessera::surface::Domain::Quad) {
        return Err(format!(
            "{}: patch {p} is a triangle patch (a mesh gives PN triangles); --scheme esc tessellates bicubic Bézier patches only",
            input.display()
        )
        .into());
    }
    if args.factor.is_some()
        || args.tolerance.is_some()
        || args.pixel_error.is_some()
        || args.distance.is_some()
        || args.silhouette.is_some()
    {
        return Err("--scheme esc has its own criterion: use --quality high|medium or --threshold D, with \
                    --camera, --max-level or --level"
            .into());
    }
    let threshold = match (args.threshold, args.quality) {
        (Some(d), _) => Threshold::Absolute(d),
        (None, Some(QualityArg::High)) => Threshold::High,
        (None, _) => Threshold::Medium,
    };
    let options = EscOptions {
        max_level: args.max_level.unwrap_or(3),
        level: args.level,
        threshold,
        ..EscOptions::default()
    };
    let cam = camera(args, set)?;
    let (plan, pattern) = esc::plan(set, &cam, &options)?;
    let what = match threshold {
        Threshold::High => "high quality".to_string(),
        Threshold::Medium => "medium quality".to_string(),
        Threshold::Absolute(d) => format!("threshold {d}"),
    };
    let level = match args.level {
        Some(l) => format!("level {l}"),
        None => format!("Lmax {}", options.max_level),
    };
    Ok(Chosen {
        plan,
        pattern: Box::new(pattern),
        description: format!("esc, {what}, {level}"),
        report: None,
        tolerance: None,
    })
}
