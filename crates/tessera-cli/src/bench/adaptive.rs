//! `adaptive`: triangles against **measured** max error for every scheme, on each patch model
//! and three meshes — the curve a user reads to choose a scheme — and, at target errors, the
//! cheapest tessellation of each scheme whose measured error meets the target, as a share of
//! the smallest uniform one that does (the equal-error comparison of the adaptive tests).
//!
//! Each scheme has one knob, swept on a grid and then bisected near each target: uniform the
//! factor; transition and semi-uniform the guaranteed tolerance; SD-2 and fractional-odd (no
//! error bound) the largest factor of paper 001's distance level function from the framing
//! camera (f_min = f_max / 2); ESC the level L = 1..6 and its distance-test threshold ρ (a
//! grid of both, no bisection; its curve is the grid's Pareto front). Every point is
//! measured with `tessera::verify::approximation_error` (order 5, as the tests and
//! `tessera check --against` do).

use super::plot::{self, Axes, Series};
use super::speed::short;
use super::table::{num, Cell, Table};
use super::{scenes, BenchResult, Ctx};
use tessera::camera::Camera;
use tessera::criterion::esc::Threshold;
use tessera::criterion::view::{Mapping, ViewCriterion};
use tessera::engine::{tessellate, EngineOptions};
use tessera::pattern::hardware::Partitioning;
use tessera::scheme::{Criterion, ErrorBound, PlanOptions, Scheme};
use tessera::surface::{Domain, SurfaceSet};
use tessera::verify;

/// The schemes, each with its knob.
#[derive(Clone, Copy, PartialEq)]
enum Knob {
    /// Uniform factor `n = s`.
    Uniform,
    /// Tolerance `diagonal · 10^-s` (error-bounded schemes), planned with a bound.
    Tolerance(Scheme, ErrorBound),
    /// Distance level function with `f_max = s` (schemes without a bound).
    Distance(Scheme),
    /// ESC at level `L = ⌊s / 10⌋` with `ρ = diagonal · 10^-(s mod 10)`: two knobs in one
    /// number, so that a point names both.
    Esc,
}

/// Semi-uniform at level 8 (factors up to 256), as the tests, so the cap rarely stops a bound.
const SEMI_UNIFORM: Scheme = Scheme::SemiUniform { max_level: 8 };

const SCHEMES: [(&str, Knob); 8] = [
    ("uniform", Knob::Uniform),
    ("transition", Knob::Tolerance(Scheme::Transition, ErrorBound::Hessian)),
    ("transition-taylor", Knob::Tolerance(Scheme::Transition, ErrorBound::Taylor)),
    ("transition-expansion", Knob::Tolerance(Scheme::Transition, ErrorBound::Expansion)),
    ("semi-uniform", Knob::Tolerance(SEMI_UNIFORM, ErrorBound::Hessian)),
    ("sd2", Knob::Distance(Scheme::Sd2 { warp: false })),
    ("fractional-odd", Knob::Distance(Scheme::Hardware(Partitioning::FractionalOdd))),
    ("esc", Knob::Esc),
];

/// One measured tessellation.
#[derive(Clone, Copy)]
struct Point {
    s: f64,
    triangles: usize,
    error: f64,
    /// The certified bound, for the error-bounded schemes.
    bound: Option<f64>,
}

struct Sizes {
    targets: &'static [f64],
    tolerance_grid: Vec<f64>,
    factor_grid: &'static [u32],
    distance_grid: &'static [u32],
    esc_grid: Vec<f64>,
    bisections: u32,
    max_triangles: u64,
}

fn sizes(quick: bool) -> Sizes {
    let steps = |lo: f64, hi: f64, step: f64| {
        let n = ((hi - lo) / step).round() as usize;
        (0..=n).map(|k| lo + k as f64 * step).collect::<Vec<_>>()
    };
    if quick {
        Sizes {
            targets: &[1e-2, 1e-3],
            tolerance_grid: steps(1.5, 3.5, 0.5),
            factor_grid: &[1, 2, 4, 8, 16],
            distance_grid: &[2, 4, 8, 16],
            esc_grid: steps(1.0, 3.0, 1.0),
            bisections: 3,
            max_triangles: 150_000,
        }
    } else {
        Sizes {
            targets: &[1e-2, 1e-3, 1e-4],
            tolerance_grid: steps(1.0, 4.5, 0.25),
            factor_grid: &[1, 2, 3, 4, 6, 8, 12, 16, 24, 32, 48, 64, 96, 128],
            distance_grid: &[2, 3, 4, 6, 8, 12, 16, 24, 32, 48, 63],
            esc_grid: steps(0.5, 4.5, 0.5),
            bisections: 5,
            max_triangles: 1_500_000,
        }
    }
}

/// A model with what the knobs need.
struct Model {
    name: String,
    set: SurfaceSet,
    diagonal: f64,
    camera: Camera,
}

impl Model {
    fn applies(&self, knob: Knob) -> bool {
        let quads = self.set.patches.iter().all(|p| p.domain() == Domain::Quad);
        let tris = self.set.patches.iter().all(|p| p.domain() == Domain::Tri);
        match knob {
            Knob::Distance(Scheme::Sd2 { .. }) => tris,
            Knob::Esc => {
                quads && self.set.patches.iter().all(|p| matches!(p, tessera::surface::Patch::Bicubic(_)))
            }
            _ => true,
        }
    }

    /// Tessellates with knob value `s` and measures the max error; None when the output
    /// would exceed `max_triangles`.
    fn measure(&self, knob: Knob, s: f64, max_triangles: u64) -> BenchResult<Option<Point>> {
        let bound = match knob {
            Knob::Tolerance(_, bound) => bound,
            _ => ErrorBound::Hessian,
        };
        let (scheme, criterion, max_factor) = match knob {
            Knob::Uniform => (Scheme::Uniform, Criterion::Factor(s.round().max(1.0)), 64),
            Knob::Tolerance(scheme, _) => {
                (scheme, Criterion::Tolerance(self.diagonal * 10f64.powf(-s)), 4096)
            }
            Knob::Distance(scheme) => {
                let criterion = ViewCriterion::Distance(Mapping::Linear);
                (scheme, Criterion::View { criterion, fmin: (s / 2.0).max(1.0), fmax: s }, 64)
            }
            Knob::Esc => {
                let (level, r) = ((s / 10.0).floor(), s % 10.0);
                let threshold = Threshold::Absolute(self.diagonal * 10f64.powf(-r));
                (Scheme::Esc { max_level: 6 }, Criterion::Esc { threshold, level: Some(level as u32) }, 64)
            }
        };
        let options =
            PlanOptions { camera: Some(self.camera), cull: false, max_factor, max_triangles, bound };
        let too_large = |e: &tessera::Error| matches!(e, tessera::Error::OutputTooLarge { .. });
        let planned = match scheme.plan(&self.set, &criterion, &options) {
            Ok(p) => p,
            Err(e) if too_large(&e) => return Ok(None),
            Err(e) => return Err(format!("{} {}: {e}", self.name, scheme.name()).into()),
        };
        let engine =
            EngineOptions { corner_params: true, max_triangles: Some(max_triangles), ..Default::default() };
        let mesh = match tessellate(&self.set, &planned.plan, &planned.pattern, engine) {
            Ok(m) => m,
            Err(e) if too_large(&e) => return Ok(None),
            Err(e) => return Err(e.into()),
        };
        let error = verify::approximation_error(&mesh, &self.set, 5)?.max;
        let bound = planned.report.map(|r| r.worst_bound);
        Ok(Some(Point { s, triangles: mesh.triangle_count(), error, bound }))
    }
}

/// The points no other point beats in both error and triangles, by error (for a knob of two
/// dimensions, whose grid order is no curve).
fn pareto(mut points: Vec<(f64, f64)>) -> Vec<(f64, f64)> {
    points.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    // By rising error, a point is on the front when it needs fewer triangles than every
    // point of smaller error.
    let mut front: Vec<(f64, f64)> = Vec::new();
    for p in points {
        if front.last().is_none_or(|q| p.1 < q.1) {
            front.push(p);
        }
    }
    front
}

/// The cheapest point of `points` whose error meets `target`.
fn cheapest(points: &[Point], target: f64) -> Option<Point> {
    points.iter().filter(|p| p.error <= target).min_by_key(|p| p.triangles).copied()
}

/// The equal-error point of one scheme: for uniform the smallest factor that meets `target`
/// (scanning the factors between the grid's bracket, as the tests do); for the others, the
/// grid's bracket bisected `bisections` times on the knob, keeping the cheapest point that
/// meets the target. New points are added to `points`.
fn at_error(
    model: &Model,
    knob: Knob,
    points: &mut Vec<Point>,
    target: f64,
    sz: &Sizes,
) -> BenchResult<Option<Point>> {
    points.sort_by(|a, b| a.s.total_cmp(&b.s));
    let Some(first) = points.iter().position(|p| p.error <= target) else { return Ok(None) };
    if first == 0 || knob == Knob::Esc {
        return Ok(cheapest(points, target));
    }
    let (mut lo, mut hi) = (points[first - 1].s, points[first].s);
    if knob == Knob::Uniform {
        for n in (lo as u32 + 1)..(hi as u32) {
            if points.iter().any(|p| p.s == n as f64) {
                continue;
            }
            match model.measure(knob, n as f64, sz.max_triangles)? {
                Some(p) => {
                    points.push(p);
                    if p.error <= target {
                        break;
                    }
                }
                None => break,
            }
        }
        return Ok(points.iter().filter(|p| p.error <= target).min_by(|a, b| a.s.total_cmp(&b.s)).copied());
    }
    for _ in 0..sz.bisections {
        let mid = 0.5 * (lo + hi);
        let Some(p) = model.measure(knob, mid, sz.max_triangles)? else { break };
        points.push(p);
        if p.error <= target {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    Ok(cheapest(points, target))
}

pub fn run(ctx: &Ctx) -> BenchResult<Vec<Table>> {
    let sz = sizes(ctx.quick);
    let models: &[&str] = if ctx.quick {
        &["patches/teapot.patches", "patches/teacup.patches", "meshes/helmet.obj"]
    } else {
        &[
            "patches/teapot.patches",
            "patches/teacup.patches",
            "patches/teapot_teasetorig.patches",
            "meshes/spot.obj",
            "meshes/cow.obj",
            "meshes/elephant.obj",
        ]
    };
    ctx.plan_steps((models.len() * SCHEMES.len()) as u64);
    let mut curves = Table::new(
        "adaptive_curves",
        "adaptive: every measured point (triangles against measured max error)",
        &["model", "scheme", "knob", "knob value", "triangles", "max error", "max error / diagonal"],
    );
    curves.print = false;
    let mut equal = Table::new(
        "adaptive_equal_error",
        "adaptive: the cheapest tessellation of each scheme that meets a measured max error",
        &[
            "model",
            "target / diagonal",
            "scheme",
            "triangles",
            "measured / diagonal",
            "knob value",
            "share of uniform %",
        ],
    );
    equal.print = false;
    let mut columns = vec!["model", "target / diagonal", "uniform triangles"];
    columns.extend(SCHEMES[1..].iter().map(|s| s.0));
    columns.push("fewest triangles");
    let mut ratio = Table::new(
        "adaptive_ratio",
        "adaptive: triangles at equal measured max error, % of uniform's",
        &columns,
    );
    let mut tightness = Table::new(
        "adaptive_bounds",
        "adaptive: measured max error against the certified bound, per model, scheme and bound",
        &[
            "model",
            "scheme",
            "tolerance / diagonal",
            "triangles",
            "measured / diagonal",
            "certified / diagonal",
            "measured / certified",
        ],
    );
    let threads = *ctx.threads.iter().max().unwrap_or(&1);
    for rel in models {
        let set = scenes::load(ctx, rel)?;
        let (lo, hi) = set.bounds();
        let model = Model {
            name: short(rel),
            diagonal: lo.distance(hi),
            camera: Camera::framing(lo, hi, 1280, 720),
            set,
        };
        let mut lines = Vec::new();
        // Per scheme and target: the equal-error point.
        let mut best: Vec<Vec<Option<Point>>> = Vec::new();
        for &(name, knob) in &SCHEMES {
            ctx.step(&format!("adaptive: {} {name}", model.name));
            if !model.applies(knob) {
                best.push(vec![None; sz.targets.len()]);
                continue;
            }
            let grid: Vec<f64> = match knob {
                Knob::Uniform => sz.factor_grid.iter().map(|&f| f as f64).collect(),
                Knob::Tolerance(..) => sz.tolerance_grid.clone(),
                Knob::Distance(_) => sz.distance_grid.iter().map(|&f| f as f64).collect(),
                Knob::Esc => {
                    (1..=6).flat_map(|l| sz.esc_grid.iter().map(move |r| 10.0 * l as f64 + r)).collect()
                }
            };
            let (points, at) = ctx.on_threads(threads, || -> BenchResult<_> {
                let mut points = Vec::new();
                for &s in &grid {
                    match model.measure(knob, s, sz.max_triangles)? {
                        Some(p) => points.push(p),
                        // Finer knobs only grow (ESC: the next level's coarse ρ may still fit).
                        None if knob == Knob::Esc => continue,
                        None => break,
                    }
                }
                let mut at = Vec::new();
                for &share in sz.targets {
                    at.push(at_error(&model, knob, &mut points, share * model.diagonal, &sz)?);
                }
                points.sort_by(|a, b| a.s.total_cmp(&b.s));
                Ok((points, at))
            })??;
            let knob_name = match knob {
                Knob::Uniform => "factor",
                Knob::Tolerance(..) => "-log10(tolerance / diagonal)",
                Knob::Distance(_) => "f_max (distance, f_min = f_max/2)",
                Knob::Esc => "10 L - log10(rho / diagonal)",
            };
            if let Knob::Tolerance(..) = knob {
                // The grid's points at 1 %, 0.1 % and 0.01 % of the diagonal.
                for p in points.iter().filter(|p| [2.0, 3.0, 4.0].contains(&p.s)) {
                    let Some(bound) = p.bound else { continue };
                    tightness.row(vec![
                        model.name.clone().into(),
                        name.into(),
                        format!("{:e}", 10f64.powf(-p.s)).into(),
                        p.triangles.into(),
                        num(p.error / model.diagonal, 7),
                        num(bound / model.diagonal, 7),
                        num(p.error / bound, 3),
                    ]);
                }
            }
            for p in &points {
                curves.row(vec![
                    model.name.clone().into(),
                    name.into(),
                    knob_name.into(),
                    num(p.s, 3),
                    p.triangles.into(),
                    num(p.error, 6),
                    num(p.error / model.diagonal, 7),
                ]);
            }
            let mut line: Vec<(f64, f64)> =
                points.iter().map(|p| (p.error / model.diagonal, p.triangles as f64)).collect();
            if knob == Knob::Esc {
                line = pareto(line);
            }
            lines.push(Series { name: name.into(), points: line });
            best.push(at);
        }
        for (k, &share) in sz.targets.iter().enumerate() {
            let uniform = best[0][k];
            let mut row: Vec<Cell> = vec![model.name.clone().into(), format!("{share:e}").into()];
            row.push(uniform.map(|p| p.triangles).into());
            for (j, &(name, _)) in SCHEMES.iter().enumerate() {
                let p = best[j][k];
                let share_of_uniform = match (p, uniform) {
                    (Some(p), Some(u)) => Some(100.0 * p.triangles as f64 / u.triangles as f64),
                    _ => None,
                };
                equal.row(vec![
                    model.name.clone().into(),
                    format!("{share:e}").into(),
                    name.into(),
                    p.map(|p| p.triangles).into(),
                    p.map_or(Cell::None, |p| num(p.error / model.diagonal, 7)),
                    p.map_or(Cell::None, |p| num(p.s, 3)),
                    share_of_uniform.map_or(Cell::None, |r| num(r, 1)),
                ]);
                if j > 0 {
                    // Where uniform misses the target there is no share to give, but a scheme
                    // that meets it still has its count: shown as such, not as a dash.
                    row.push(match (share_of_uniform, p) {
                        (Some(r), _) => num(r, 1),
                        (None, Some(p)) => Cell::text(format!("{} tri", p.triangles)),
                        (None, None) => Cell::None,
                    });
                }
            }
            // Every scheme with the fewest triangles (ties, e.g. the untessellated base mesh,
            // are named together).
            let fewest = (0..SCHEMES.len()).filter_map(|j| best[j][k].map(|p| p.triangles)).min();
            let winners: Vec<&str> = (0..SCHEMES.len())
                .filter(|&j| fewest.is_some() && best[j][k].map(|p| p.triangles) == fewest)
                .map(|j| SCHEMES[j].0)
                .collect();
            row.push(if winners.is_empty() { Cell::None } else { winners.join(" = ").into() });
            ratio.row(row);
        }
        let title = format!("{}: triangles against measured max error", model.name);
        plot::lines(
            &ctx.out.join(format!("adaptive_{}.svg", model.name)),
            &Axes {
                title: &title,
                x: "measured max error / bounding-box diagonal",
                y: "triangles",
                log_x: true,
                log_y: true,
            },
            &lines,
        )?;
    }
    ratio.note(format!(
        "For each target (a share of the model's bounding-box diagonal): uniform = the smallest factor whose measured \
         max error meets it; each other scheme = its cheapest measured tessellation that meets it (knob grid, then {} \
         bisection steps near the target); — = the scheme does not apply (SD-2: triangles only; ESC: bicubic only) or \
         does not reach the target below {} triangles; where uniform does not reach it, the others give their \
         triangle counts (\"N tri\") instead of a share. Knobs: transition, semi-uniform (M = 8): the guaranteed \
         tolerance; SD-2, fractional-odd: f_max of the distance level function from the framing camera (f_min = \
         f_max/2, no error bound); ESC: levels 1–6 × a grid of ρ. Errors: tessera::verify::approximation_error, order 5.",
        sz.bisections, sz.max_triangles
    ));
    tightness.note(
        "Each error-bounded scheme at tolerances of 1 %, 0.1 % and 0.01 % of the diagonal (the points of its knob grid; \
         the quick run has no 0.01 %): the measured max error (order 5, as above) and the plan's certified bound \
         (BoundReport::worst_bound, the largest over the patches). \"transition-taylor\" plans with ErrorBound::Taylor \
         (tessera mesh --bound taylor), \"transition-expansion\" with ErrorBound::Expansion \
         (--bound expansion), the others with the second-derivative bound."
            .to_string(),
    );
    Ok(vec![ratio, tightness, equal, curves])
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_front_keeps_what_nothing_beats() {
        let points =
            vec![(0.1, 50.0), (0.01, 500.0), (0.05, 80.0), (0.01, 900.0), (0.03, 600.0), (0.2, 60.0)];
        assert_eq!(super::pareto(points), vec![(0.01, 500.0), (0.05, 80.0), (0.1, 50.0)]);
    }
}
