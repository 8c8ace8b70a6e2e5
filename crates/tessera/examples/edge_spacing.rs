//! How many triangles could non-uniform edge spacing save? An optimistic estimate, for the
//! decision the certified-bounds issue asks for ("only if it measurably lowers triangle
//! counts at equal bound").
//!
//! For each model, tolerance (1 %, 0.1 %, 0.01 % of the diagonal) and the transition scheme
//! with the Taylor bound, the plan is made as `tessera mesh` makes it. Then every edge's
//! segment count is cut by the share that spacing its samples by curvature would save on the
//! curve alone: a uniform spacing needs `sqrt(max|c''| / 8ε)` segments for its chord error,
//! one that equidistributes the error `∫ sqrt(|c''| / 8ε) dt` (the asymptotic optimum), so
//! the edge keeps `ceil(s · ∫ sqrt|c''| / sqrt max|c''|)` of its `s` segments. The patches'
//! interiors stay as planned, and the triangles are counted again with the same pattern.
//!
//! Why this overstates the gain (so a small figure settles the question): the cut is taken
//! as if every edge's count came from its own curve, where most come from the patch's grid
//! (its interior needs); the strip triangles next to a sparser edge are wider across the
//! strip too, which the estimate lets through without checking their bound; and the ceiling
//! of an optimum is rounded for each edge on its own.
//!
//! Run from the repository root: `cargo run --release -p tessera --example edge_spacing [DATA_DIR]`
//! (default `../shared/data`).

use std::path::PathBuf;

use tessera::criterion::taylor::TaylorBound;
use tessera::criterion::ErrorBound;
use tessera::engine::layout::pattern_input;
use tessera::pattern::Pattern;
use tessera::scheme::{Criterion, PlanOptions, Scheme};
use tessera::surface::SurfaceSet;

/// Samples along an edge for its curvature profile.
const SAMPLES: usize = 64;

/// `∫ sqrt|c''| / sqrt max|c''|` along each edge (1 where the patch has no second
/// derivatives to read, a rational patch: no cut). Cost: [`SAMPLES`] evaluations an edge.
fn edge_ratios(set: &SurfaceSet) -> Vec<f64> {
    let mut ratio = vec![1.0; set.topology.edges.len()];
    let mut done = vec![false; ratio.len()];
    for (p, patch) in set.patches.iter().enumerate() {
        let bound = TaylorBound::of(patch);
        let domain = set.topology.patch_domains[p];
        for (l, pe) in set.topology.patch_edges[p][..domain.corner_count()].iter().enumerate() {
            let e = pe.edge as usize;
            if done[e] {
                continue;
            }
            done[e] = true;
            let d = domain.edge_point(l, 1.0) - domain.edge_point(l, 0.0);
            let curvature = |t: f64| {
                let [a, b, c] = bound.second_derivatives(domain.edge_point(l, t));
                (a * (d.x * d.x) + b * (2.0 * d.x * d.y) + c * (d.y * d.y)).length()
            };
            // Midpoint rule for the integral; the samples' largest for the maximum.
            let values: Vec<f64> =
                (0..SAMPLES).map(|i| curvature((i as f64 + 0.5) / SAMPLES as f64)).collect();
            let most = values.iter().copied().fold(curvature(0.0).max(curvature(1.0)), f64::max);
            if most > 0.0 && bound.is_some() {
                let integral = values.iter().map(|c| c.sqrt()).sum::<f64>() / SAMPLES as f64;
                ratio[e] = (integral / most.sqrt()).min(1.0);
            }
        }
    }
    ratio
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let data = PathBuf::from(std::env::args().nth(1).unwrap_or_else(|| "../shared/data".into()));
    let models = [
        "patches/teapot.patches",
        "patches/teacup.patches",
        "patches/teapot_teasetorig.patches",
        "meshes/spot.obj",
        "meshes/cow.obj",
        "meshes/bunny.obj",
        "meshes/elephant.obj",
        "meshes/helmet.obj",
    ];
    println!("| model | tolerance | triangles | edge-side segments (% of triangles) | with curvature-spaced edges | saving |");
    println!("| --- | --- | --- | --- | --- | --- |");
    for rel in models {
        let set = tessera::io::load(&data.join(rel), tessera::io::LoadOptions::default())?;
        let (lo, hi) = set.bounds();
        let diagonal = lo.distance(hi);
        let ratios = edge_ratios(&set);
        for share in [1e-2, 1e-3, 1e-4] {
            let options = PlanOptions { bound: ErrorBound::Taylor, ..PlanOptions::default() };
            let planned = Scheme::Transition.plan(&set, &Criterion::Tolerance(share * diagonal), &options)?;
            let plan = &planned.plan;
            let count = |plan: &tessera::criterion::Plan| -> (u64, u64) {
                let (mut triangles, mut sides) = (0u64, 0u64);
                for p in 0..set.patches.len() {
                    let input = pattern_input(&set, plan, p);
                    triangles += planned.pattern.counts(&input).1 as u64;
                    sides +=
                        input.segments[..input.domain.corner_count()].iter().map(|&s| s as u64).sum::<u64>();
                }
                (triangles, sides)
            };
            let (triangles, sides) = count(plan);
            let mut spaced = plan.clone();
            for (e, s) in spaced.segments.iter_mut().enumerate() {
                *s = ((*s as f64 * ratios[e]).ceil() as u32).max(1);
            }
            let (fewer, _) = count(&spaced);
            println!(
                "| {rel} | {}% | {triangles} | {sides} ({:.0}%) | {fewer} | {:.1}% |",
                share * 100.0,
                100.0 * sides as f64 / triangles as f64,
                100.0 * (triangles as f64 - fewer as f64) / triangles as f64
            );
        }
    }
    Ok(())
}
