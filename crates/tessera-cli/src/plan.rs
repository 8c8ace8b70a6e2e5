//! Command-line criteria: map `--factor`, `--tolerance`, `--pixel-error`, `--distance`,
//! `--silhouette` or ESC's flags (with `--camera`, `--scheme`, `--max-factor`, `--cull`) to
//! the library's [`Scheme`], [`Criterion`] and [`PlanOptions`]. No scheme rule lives here.

use clap::{Args, ValueEnum};
use tessera::camera::Camera;
use tessera::criterion::esc::Threshold;
use tessera::criterion::view::{Mapping, ViewCriterion};
use tessera::pattern::hardware::Partitioning;
use tessera::scheme::{Criterion, PlanOptions, Scheme};
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
    /// The guaranteed bound --tolerance and --pixel-error plan with: `hessian`, one
    /// second-derivative bound per patch; `taylor`, also the second derivatives where each
    /// triangle is with a third-derivative remainder, and the error sampled on coarse
    /// triangles (fewer triangles for the same guarantee on every surface kind; planned on
    /// the CPU, more slowly); `expansion`, the Taylor expansion without that sampling, on
    /// polynomial patches and triangles (between the two, each query of a fixed cost;
    /// `--engine gpu` plans it on the GPU too).
    #[arg(long, value_enum, default_value = "hessian")]
    pub bound: BoundArg,
}

/// The guaranteed bound of the error-bounded criteria (`--bound`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum BoundArg {
    /// One second-derivative bound per patch (the GPU engine plans with it too).
    Hessian,
    /// The smaller of that and the Taylor bound at each triangle.
    Taylor,
    /// The smaller of the first and the Taylor expansion alone, without the sampled
    /// refinements: between the two in triangles and planning time; the GPU engine plans
    /// with it too.
    Expansion,
}

impl BoundArg {
    /// The library's bound.
    pub fn bound(self) -> tessera::scheme::ErrorBound {
        match self {
            BoundArg::Hessian => tessera::scheme::ErrorBound::Hessian,
            BoundArg::Taylor => tessera::scheme::ErrorBound::Taylor,
            BoundArg::Expansion => tessera::scheme::ErrorBound::Expansion,
        }
    }
}

/// Which engine tessellates (`--engine`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum EngineArg {
    /// The CPU engine (rayon).
    Cpu,
    /// The GPU engine (tessera-gpu on wgpu).
    Gpu,
}

impl std::fmt::Display for EngineArg {
    /// The command-line name, as messages and `--stats` print it.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            EngineArg::Cpu => "cpu",
            EngineArg::Gpu => "gpu",
        })
    }
}

/// A plan, its scheme and pattern, a one-line description, and the guarantee report where
/// one applies.
pub struct Chosen {
    pub scheme: Scheme,
    pub criterion: Criterion,
    pub options: PlanOptions,
    pub description: String,
    pub tolerance: Option<f64>,
}

/// Parses `FMIN:FMAX` (any numbers; the scheme checks their range).
fn range(text: &str, flag: &str) -> Result<(f64, f64), String> {
    let parse = |s: &str| s.trim().parse::<f64>().ok().filter(|v| v.is_finite());
    match text.split_once(':').map(|(a, b)| (parse(a), parse(b))) {
        Some((Some(a), Some(b))) => Ok((a, b)),
        _ => Err(format!("{flag} {text}: expected FMIN:FMAX, two numbers")),
    }
}

/// The criterion's camera: `--camera` on the default framing camera, whose up axis is the
/// model's (its format's convention, [`tessera::io::up_axis_of`]).
pub fn camera(args: &CriterionArgs, set: &SurfaceSet) -> Result<Camera, tessera::Error> {
    let (lo, hi) = set.bounds();
    let default = Camera::framing_up(lo, hi, 1280, 720, set.up);
    match &args.camera {
        Some(spec) => Camera::parse(spec, &default),
        None => Ok(default),
    }
}

/// Says on stderr which way is up for a default camera (`--camera` without `up=`), since the
/// view depends on it and the convention is the format's guess: `input` names the model.
pub fn note_up_axis(spec: Option<&str>, input: &std::path::Path) {
    if spec.is_some_and(|s| s.split(',').any(|kv| kv.trim_start().starts_with("up="))) {
        return;
    }
    let (up, why) = tessera::io::up_axis_of(input);
    let (axis, other) = match up {
        tessera::camera::UpAxis::Y => ("+Y", "up=0,0,1"),
        tessera::camera::UpAxis::Z => ("+Z", "up=0,1,0"),
    };
    eprintln!("note: the camera takes {axis} as up ({why}); give --camera {other} if the model's up differs");
}

impl SchemeArg {
    /// The library scheme, with `--max-level` and `--warp`.
    pub fn scheme(self, max_level: Option<u32>, warp: bool) -> Scheme {
        match self {
            SchemeArg::Uniform => Scheme::Uniform,
            SchemeArg::Transition => Scheme::Transition,
            SchemeArg::SemiUniform => {
                Scheme::SemiUniform { max_level: max_level.unwrap_or(Scheme::DEFAULT_SEMI_UNIFORM_LEVEL) }
            }
            SchemeArg::Sd2 => Scheme::Sd2 { warp },
            SchemeArg::Integer => Scheme::Hardware(Partitioning::Integer),
            SchemeArg::Pow2 => Scheme::Hardware(Partitioning::Pow2),
            SchemeArg::FractionalOdd => Scheme::Hardware(Partitioning::FractionalOdd),
            SchemeArg::FractionalEven => Scheme::Hardware(Partitioning::FractionalEven),
            SchemeArg::Esc => Scheme::Esc { max_level: max_level.unwrap_or(Scheme::DEFAULT_ESC_LEVEL) },
        }
    }

    /// The command-line name (the library's).
    pub fn name(self) -> &'static str {
        self.scheme(None, false).name()
    }
}

/// The criterion the flags name (`scheme` only picks the default silhouette test), and its
/// text for the description.
fn criterion(
    args: &CriterionArgs,
    set: &SurfaceSet,
    scheme: Option<Scheme>,
) -> Result<(Criterion, String), String> {
    if let Some(f) = args.factor {
        return Ok((Criterion::Factor(f), format!("factor {f}")));
    }
    if let Some(t) = &args.tolerance {
        let (lo, hi) = set.bounds();
        let eps =
            tessera::criterion::tolerance::parse_tolerance(t, lo.distance(hi)).map_err(|e| match e {
                tessera::Error::InvalidParameter { reason, .. } => format!("--tolerance {reason}"),
                e => e.to_string(),
            })?;
        return Ok((Criterion::Tolerance(eps), format!("tolerance {eps:.4e}")));
    }
    if let Some(px) = args.pixel_error {
        return Ok((Criterion::PixelError(px), format!("{px} px screen-space error")));
    }
    if let Some(text) = &args.distance {
        let (fmin, fmax) = range(text, "--distance")?;
        let mapping = if args.mapping == MappingArg::Linear { Mapping::Linear } else { Mapping::Quadratic };
        return Ok((
            Criterion::View { criterion: ViewCriterion::Distance(mapping), fmin, fmax },
            format!("--distance {text}"),
        ));
    }
    if let Some(text) = &args.silhouette {
        let (fmin, fmax) = range(text, "--silhouette")?;
        let criterion = match args.silhouette_mode {
            Some(SilhouetteMode::Silhouetteness) => ViewCriterion::Silhouetteness,
            Some(SilhouetteMode::Vertices) => ViewCriterion::SilhouetteVertices,
            None => scheme.unwrap_or(Scheme::Transition).default_silhouette(),
        };
        return Ok((Criterion::View { criterion, fmin, fmax }, format!("--silhouette {text}")));
    }
    let esc_flags = args.level.is_some() || args.quality.is_some() || args.threshold.is_some();
    if esc_flags || matches!(scheme, Some(Scheme::Esc { .. })) {
        let threshold = match (args.threshold, args.quality) {
            (Some(d), _) => Threshold::Absolute(d),
            (None, Some(QualityArg::High)) => Threshold::High,
            (None, _) => Threshold::Medium,
        };
        let what = match threshold {
            Threshold::High => "high quality".to_string(),
            Threshold::Medium => "medium quality".to_string(),
            Threshold::Absolute(d) => format!("threshold {d}"),
        };
        return Ok((Criterion::Esc { threshold, level: args.level }, what));
    }
    Ok((Criterion::Factor(8.0), "factor 8".into()))
}

/// Maps the flags to a scheme, a criterion and plan options: every rule, cap and
/// compatibility check is the library's ([`Scheme::plan`], run by the caller's
/// [`tessera::tessellator::Tessellator`]). `max_triangles` bounds what the error-bounded
/// criteria may build while they check their bounds.
pub fn choose(
    args: &CriterionArgs,
    set: &SurfaceSet,
    max_triangles: u64,
) -> Result<Chosen, Box<dyn std::error::Error>> {
    if args.warp && args.scheme != Some(SchemeArg::Sd2) {
        return Err("--warp applies to --scheme sd2 only".into());
    }
    let named = args.scheme.map(|s| s.scheme(args.max_level, args.warp));
    let (criterion, text) = criterion(args, set, named)?;
    let scheme = named.unwrap_or_else(|| Scheme::default_for(&criterion));
    let options = PlanOptions {
        camera: Some(camera(args, set)?),
        cull: args.cull,
        max_factor: args.max_factor,
        max_triangles,
        bound: args.bound.bound(),
    };
    let mut description = format!("{}, {text}", scheme.name());
    match scheme {
        Scheme::Sd2 { warp: true } => description += ", warped",
        Scheme::Esc { max_level } => {
            description += &match args.level {
                Some(l) => format!(", level {l}"),
                None => format!(", Lmax {max_level}"),
            }
        }
        _ => {}
    }
    Ok(Chosen {
        scheme,
        criterion,
        options,
        description,
        tolerance: match criterion {
            Criterion::Tolerance(eps) => Some(eps),
            _ => None,
        },
    })
}
