//! The Direct3D 11 partitionings (`integer`, `pow2`, `fractional_odd`, `fractional_even`) on
//! the GPU engine against the CPU engine, on lavapipe in CI. Every expected value comes from
//! the CPU library (`tessera::engine`, `tessera::scheme`, `tessera::criterion`), never from
//! the GPU itself.
//!
//! No adapter is a failure, not a skip: the message names the packages to install.

mod common;

use common::*;
use tessera::criterion::resolve::{self, EdgeRule, InteriorRule};
use tessera::criterion::view::{Mapping, ViewCriterion};
use tessera::criterion::Plan;
use tessera::pattern::hardware::{edge_segments, Hardware, Partitioning};
use tessera::pattern::{Pattern, PatternInput};
use tessera::sampling::{SamplingKind, Spacing};
use tessera::scheme::{Criterion, PlanOptions, Prepared, Scheme};
use tessera::surface::{Domain, SurfaceSet};
use tessera_gpu::tessellator::{Capacity, ScreenCriterion};
use tessera_gpu::{GpuError, GpuTessellator};

const PARTITIONINGS: [Partitioning; 4] =
    [Partitioning::Integer, Partitioning::Pow2, Partitioning::FractionalOdd, Partitioning::FractionalEven];

/// A real factor per partitioning that exercises it: between counts, not a power of two.
fn real_factor(p: Partitioning) -> f64 {
    match p {
        Partitioning::Integer => 4.2,
        Partitioning::Pow2 => 5.3,
        Partitioning::FractionalOdd => 5.3,
        Partitioning::FractionalEven => 6.7,
    }
}

/// The GPU output of `plan` equals the CPU engine's ([`assert_pattern_equals_cpu`]: offsets,
/// triangles index for index, positions, the watertightness report), and every vertex's
/// domain parameters are the CPU's bit for bit: the hardware's points are 16.16 fixed-point
/// values, exact in f32 on both sides, so the edge parameters (`edge_param`) and the interior
/// points must agree exactly.
fn assert_hardware_frame(name: &str, set: &SurfaceSet, gpu: &mut GpuTessellator, plan: &Plan) {
    let Some(p) = partitioning_of(plan) else { panic!("{name}: not a hardware plan") };
    let pattern = Hardware { partitioning: p };
    assert_pattern_equals_cpu(name, set, gpu, plan, &pattern);
    assert_parameters_equal_the_cpu(name, set, gpu, plan, &pattern);
}

fn partitioning_of(plan: &Plan) -> Option<Partitioning> {
    match plan.kind {
        SamplingKind::Fractional(Spacing::Hardware(p)) => Some(p),
        _ => None,
    }
}

/// Every vertex's uv bit for bit against the CPU engine's, on a frame already submitted.
fn assert_parameters_equal_the_cpu(
    name: &str,
    set: &SurfaceSet,
    gpu: &GpuTessellator,
    plan: &Plan,
    pattern: &dyn Pattern,
) {
    let got = gpu.read_mesh(ctx(), set).unwrap();
    let want = tessera::engine::tessellate(set, plan, pattern, Default::default()).unwrap();
    assert_eq!(got.uvs.len(), want.uvs.len(), "{name}: vertices");
    for (v, (g, w)) in got.uvs.iter().zip(&want.uvs).enumerate() {
        assert!(
            g[0].to_bits() == w[0].to_bits() && g[1].to_bits() == w[1].to_bits(),
            "{name}: vertex {v} at uv {g:?}, the CPU's {w:?}"
        );
    }
}

/// A hardware plan with real factors on every edge from random per-patch proposals in
/// `[1, max]`, resolved by the CPU's own resolver (`resolve::edges` with the partitioning's
/// `EdgeRule::Fractional`: the maximum over the edge's patches, the hull shader's rounding,
/// settled factors, segments by the partition; the interiors by `InteriorRule::MaxEdge`), as
/// `Scheme::Hardware` plans are; every third patch culled when `cull`.
fn random_plan(set: &SurfaceSet, p: Partitioning, max: f64, rng: &mut Lcg, cull: bool) -> Plan {
    let prepared = Prepared::new(set, false);
    let caps = prepared.caps(p.range().1 as f64);
    let proposals: Vec<[f64; 4]> = (0..set.patches.len())
        .map(|_| std::array::from_fn(|_| 1.0 + (max - 1.0) * (rng.next() as f64 / (1u64 << 31) as f64)))
        .collect();
    let rule = EdgeRule::Fractional(Spacing::Hardware(p));
    let mut plan = Plan::uniform(set, 1).unwrap();
    resolve::edges(
        set,
        &proposals,
        rule,
        InteriorRule::MaxEdge,
        &caps,
        &mut plan.segments,
        &mut plan.factors,
    );
    resolve::interiors(set, &plan.segments, InteriorRule::MaxEdge, &caps, &mut plan.interior);
    plan.kind = SamplingKind::Fractional(Spacing::Hardware(p));
    if cull {
        plan.visible.iter_mut().step_by(3).for_each(|v| *v = 0);
    }
    plan
}

/// The CPU's own plan of `scheme` under a fixed factor.
fn factor_plan(set: &SurfaceSet, p: Partitioning, factor: f64) -> Plan {
    Scheme::Hardware(p).plan(set, &Criterion::Factor(factor), &PlanOptions::default()).unwrap().plan
}

/// Distinct factors and segments of a plan, to be sure a test draws what it claims.
fn distinct(plan: &Plan) -> (usize, usize) {
    let factors: std::collections::BTreeSet<u32> = plan.factors.iter().map(|f| f.to_bits()).collect();
    let segments: std::collections::BTreeSet<u32> = plan.segments.iter().copied().collect();
    (factors.len(), segments.len())
}

#[test]
fn hardware_plans_equal_the_cpu_engine_on_every_patch_model() {
    let mut rng = Lcg(5);
    for model in patch_models() {
        let set = load(&model);
        let mut gpu = tessellator(&set);
        // The torus is large: smaller factors there keep the fast tier fast.
        let large = set.patches.len() > 500;
        for p in PARTITIONINGS {
            let factor = if large { 2.6 } else { real_factor(p) };
            let plan = factor_plan(&set, p, factor);
            assert_hardware_frame(&format!("{model} {} factor {factor}", p.name()), &set, &mut gpu, &plan);
            let max = if large { 4.0 } else { 13.0 };
            for round in 0..if large { 1 } else { 2 } {
                let plan = random_plan(&set, p, max, &mut rng, round == 1);
                let (factors, segments) = distinct(&plan);
                // pow2 factors are powers of two.
                let least = if p == Partitioning::Pow2 { 1 } else { 4 };
                assert!(
                    factors > least && segments > 1,
                    "{model}: {factors} factors, {segments} segment counts"
                );
                let name = format!("{model} {} random round {round}", p.name());
                assert_hardware_frame(&name, &set, &mut gpu, &plan);
            }
        }
    }
}

/// Loop cages (triangle trees of quartic and Gregory triangles, `tree.wgsl`): every
/// partitioning at its fixed factor and on random factors, culling included.
#[test]
fn hardware_plans_equal_the_cpu_engine_on_loop_cages() {
    let options = tessera::io::LoadOptions { surface: tessera::io::SurfaceKind::Loop, ..Default::default() };
    let mut rng = Lcg(29);
    for cage in ["loop_cube_creases0", "loop_xord_interior", "loop_triangle_edgecorner"] {
        let set = tessera::io::load(&data_dir().join(format!("subdivision/{cage}.obj")), options).unwrap();
        let mut gpu = tessellator(&set);
        for (i, p) in PARTITIONINGS.into_iter().enumerate() {
            let plan = factor_plan(&set, p, real_factor(p));
            assert_hardware_frame(
                &format!("{cage} {} factor {}", p.name(), real_factor(p)),
                &set,
                &mut gpu,
                &plan,
            );
            let plan = random_plan(&set, p, 9.0, &mut rng, i % 2 == 1);
            assert_hardware_frame(&format!("{cage} {} random", p.name()), &set, &mut gpu, &plan);
        }
    }
}

/// Catmull-Clark cages (bicubic faces, trees of isolated faces, sub-faces of n-gons, holes,
/// creases) and the corners pinched at a valence-2 vertex, which Direct3D's pattern never
/// cuts across at corners 0 and 2 (`Hardware::cut_through_corners_0_and_2`), so the GPU draws
/// them as the CPU does: every partitioning at its fixed factor, on random factors and from
/// the camera.
#[test]
fn hardware_plans_equal_the_cpu_engine_on_catmull_clark_cages() {
    let options =
        tessera::io::LoadOptions { surface: tessera::io::SurfaceKind::CatmullClark, ..Default::default() };
    let load_cage = |cage: &str| tessera::io::load(&data_dir().join(cage), options).unwrap();
    let mut rng = Lcg(31);
    let mut pinched = 0;
    let cages = ["catmark_val2_interior", "catmark_nonquads", "catmark_hole_test1"]
        .map(|c| format!("subdivision/{c}.obj"));
    for cage in &cages {
        let set = load_cage(cage);
        pinched += set.topology.patch_pinched.iter().filter(|c| c.iter().any(|&x| x)).count();
        let mut gpu = tessellator(&set);
        for (i, p) in PARTITIONINGS.into_iter().enumerate() {
            let plan = factor_plan(&set, p, real_factor(p));
            let name = format!("{cage} {} factor {}", p.name(), real_factor(p));
            assert_hardware_frame(&name, &set, &mut gpu, &plan);
            for round in 0..2 {
                let plan = random_plan(&set, p, if round == 0 { 3.0 } else { 9.0 }, &mut rng, i % 2 == 1);
                assert_hardware_frame(
                    &format!("{cage} {} random round {round}", p.name()),
                    &set,
                    &mut gpu,
                    &plan,
                );
            }
        }
    }
    assert!(pinched > 0, "no pinched corner among the cages");
    // Planned on the GPU from the camera: every partitioning, silhouetteness and a factor.
    let (_, counts) = hardware_from_the_camera(&cages[..1], load_cage, 8, 5, 1);
    check_factor_counts(&counts);
}

#[test]
fn hardware_plans_equal_the_cpu_engine_on_triangle_patches() {
    // PN triangles: the meshes under 40 kB (the blob, the knob, the non-manifold and the
    // unwelded teapots, the bunny at resolution 4, ...); Bézier triangles: two of them.
    let mut rng = Lcg(17);
    for model in mesh_models() {
        if std::fs::metadata(data_dir().join(&model)).unwrap().len() > 40_000 {
            continue;
        }
        let pn = load(&model);
        let mut sets = vec![("PN", pn.clone())];
        if model.ends_with("blob.obj") || model.ends_with("teapot_tri_nonmanifold.obj") {
            sets.push(("Bézier", as_bezier_triangles(&pn)));
        }
        for (kind, set) in sets {
            let mut gpu = tessellator(&set);
            for (i, p) in PARTITIONINGS.into_iter().enumerate() {
                let plan = factor_plan(&set, p, real_factor(p));
                let name = format!("{model} {kind} {} factor {}", p.name(), real_factor(p));
                assert_hardware_frame(&name, &set, &mut gpu, &plan);
                let plan = random_plan(&set, p, 9.0, &mut rng, i % 2 == 1);
                let name = format!("{model} {kind} {} random", p.name());
                assert_hardware_frame(&name, &set, &mut gpu, &plan);
            }
        }
    }
}

#[test]
#[ignore = "slow tier: every mesh model (PN triangles), two partitionings each, random real factors up to 20"]
fn hardware_plans_equal_the_cpu_engine_on_every_mesh() {
    let mut rng = Lcg(71);
    for (m, model) in mesh_models().into_iter().enumerate() {
        let set = load(&model);
        let mut gpu = tessellator(&set);
        // About 50,000 triangles a frame at most.
        let max = (50_000.0 / set.patches.len() as f64).sqrt().clamp(2.0, 20.0);
        for p in [PARTITIONINGS[m % 4], PARTITIONINGS[(m + 2) % 4]] {
            let plan = random_plan(&set, p, max, &mut rng, false);
            assert_hardware_frame(
                &format!("{model} {} random up to {max:.1}", p.name()),
                &set,
                &mut gpu,
                &plan,
            );
        }
    }
}

#[test]
#[ignore = "slow tier: every patch model at large real factors, up to the hardware's range"]
fn hardware_plans_equal_the_cpu_engine_at_large_factors() {
    let mut rng = Lcg(404);
    for model in patch_models() {
        let set = load(&model);
        let mut gpu = tessellator(&set);
        let large = set.patches.len() > 500;
        for p in PARTITIONINGS {
            let top = p.range().1 as f64;
            let factors: &[f64] = if large { &[9.5, 16.2] } else { &[23.7, top] };
            for &factor in factors {
                let plan = factor_plan(&set, p, factor);
                assert_hardware_frame(
                    &format!("{model} {} factor {factor}", p.name()),
                    &set,
                    &mut gpu,
                    &plan,
                );
            }
            let plan = random_plan(&set, p, if large { 12.0 } else { top }, &mut rng, true);
            assert_hardware_frame(&format!("{model} {} random to the top", p.name()), &set, &mut gpu, &plan);
        }
    }
}

/// The CPU's view-criterion plans (distance and silhouetteness: a real factor per edge from
/// the camera), every patch uploaded visible and the GPU culling for that camera: the culled
/// set equals the CPU's (but for counted ties) and so does the output.
#[test]
fn hardware_view_plans_with_gpu_culling_equal_the_cpu_engine() {
    let ctx = ctx();
    let mut counts = SweepCounts::default();
    for model in ["patches/teapot.patches", "patches/teacup.patches", "meshes/blob.obj"] {
        let set = load(model);
        let prepared = Prepared::new(&set, false);
        let mut gpu = tessellator(&set);
        for (c, camera) in cameras(&set, 2, 41).into_iter().enumerate() {
            for (i, p) in PARTITIONINGS.into_iter().enumerate() {
                let view = if (c + i) % 2 == 0 {
                    ViewCriterion::Distance(Mapping::Linear)
                } else {
                    ViewCriterion::Silhouetteness
                };
                let criterion = Criterion::View { criterion: view, fmin: 1.0, fmax: 11.5 };
                let options = PlanOptions { camera: Some(camera), cull: true, ..Default::default() };
                let planned =
                    Scheme::Hardware(p).plan_prepared(&set, &prepared, &criterion, &options).unwrap();
                let mut plan = planned.plan.clone();
                assert!(distinct(&plan).0 > 1, "{model}: one factor everywhere");
                plan.visible.fill(1);
                gpu.set_cull_camera(ctx, Some(&camera));
                gpu.prepare(ctx, &set, &plan, &planned.pattern).unwrap();
                record_frame(&gpu);
                let name = format!("{model} camera {c} {} {view:?}", p.name());
                plan.visible = check_culling(&name, &set, &gpu, &planned.plan.visible, &camera, &mut counts);
                assert_gpu_equals_cpu_after_record(&name, &set, &gpu, &plan, &planned.pattern);
                assert_parameters_equal_the_cpu(&name, &set, &gpu, &plan, &planned.pattern);
            }
        }
        gpu.set_cull_camera(ctx, None);
    }
    eprintln!("{counts:?}");
    assert!(counts.culled > 0, "the cameras culled nothing");
}

/// Plans the GPU cannot draw as the CPU would are refused with a typed error, never drawn
/// wrong: a kind other than the pattern's, a partitioning other than the pattern's, segments
/// that are not the factors', a factor that is not a finite positive number.
#[test]
fn hardware_plans_against_the_preconditions_are_refused() {
    let ctx = ctx();
    let set = load("patches/teapot.patches");
    let mut gpu = tessellator(&set);
    let odd = Hardware { partitioning: Partitioning::FractionalOdd };
    let plan = factor_plan(&set, Partitioning::FractionalOdd, 5.3);
    gpu.prepare(ctx, &set, &plan, &odd).unwrap();
    let unsupported = |r: Result<(), GpuError>| matches!(r, Err(GpuError::Unsupported { .. }));
    let mismatch =
        |r: Result<(), GpuError>| matches!(r, Err(GpuError::Tessera(tessera::Error::PlanMismatch { .. })));
    let integer_plan = Plan::uniform(&set, 4).unwrap();
    assert!(unsupported(gpu.prepare(ctx, &set, &integer_plan, &odd)), "a uniform plan");
    let even = Hardware { partitioning: Partitioning::FractionalEven };
    assert!(unsupported(gpu.prepare(ctx, &set, &plan, &even)), "another partitioning");
    let mut wrong = plan.clone();
    wrong.segments[3] += 2;
    assert!(mismatch(gpu.prepare(ctx, &set, &wrong, &odd)), "segments unlike the factor");
    for bad in [f32::NAN, f32::INFINITY, 0.0, -3.0] {
        let mut wrong = plan.clone();
        wrong.factors[1] = bad;
        assert!(unsupported(gpu.prepare(ctx, &set, &wrong, &odd)), "factor {bad}");
    }
    // The scheme-level checks of `prepare_screen`.
    let prepared = Prepared::new(&set, true);
    let camera = cameras(&set, 1, 3)[0];
    let screen = |scheme, criterion, max_factor| ScreenCriterion::new(scheme, criterion, max_factor);
    let odd_scheme = Scheme::Hardware(Partitioning::FractionalOdd);
    let refused = |gpu: &mut GpuTessellator, s: ScreenCriterion| {
        gpu.prepare_screen(ctx, &set, &prepared, &camera, s).is_err()
    };
    assert!(refused(&mut gpu, screen(odd_scheme, Criterion::Factor(63.5), 64)), "past the odd range");
    assert!(refused(&mut gpu, screen(odd_scheme, Criterion::Factor(9.0), 8)), "past the max factor");
    assert!(refused(&mut gpu, screen(odd_scheme, Criterion::Factor(f64::NAN), 64)), "NaN");
    assert!(refused(&mut gpu, screen(odd_scheme, Criterion::PixelError(1.0), 64)), "a pixel error");
    let distance =
        Criterion::View { criterion: ViewCriterion::Distance(Mapping::Linear), fmin: 1.0, fmax: 8.0 };
    assert!(refused(&mut gpu, screen(odd_scheme, distance, 64)), "distance factors");
    let silhouettes = Criterion::View { criterion: ViewCriterion::Silhouetteness, fmin: 3.5, fmax: 2.0 };
    assert!(refused(&mut gpu, screen(odd_scheme, silhouettes, 64)), "FMIN > FMAX");
    let silhouettes = Criterion::View { criterion: ViewCriterion::Silhouetteness, fmin: 1.5, fmax: 7.25 };
    assert!(!refused(&mut gpu, screen(odd_scheme, silhouettes, 64)), "real FMIN:FMAX");
}

/// `prepare_screen`'s output room for a hardware frame is the pattern's counts with every
/// edge at the largest factor a frame can resolve to; that bounds every frame only if the
/// pattern's output grows with its factors. Checked on the CPU pattern: random factor sets
/// (quads and triangles, every partitioning, collapsed corners aside) never count more
/// vertices or triangles than every factor at their largest.
#[test]
fn the_hardware_worst_case_bounds_every_frame() {
    let mut rng = Lcg(2718);
    let mut unit = || rng.next() as f64 / (1u64 << 31) as f64;
    for p in PARTITIONINGS {
        for domain in [Domain::Quad, Domain::Tri] {
            for _ in 0..3000 {
                let top = 1.0 + unit() * (p.range().1 as f64 - 1.0);
                let factors: [f64; 4] = std::array::from_fn(|_| {
                    let f = if unit() < 0.3 { top } else { 1.0 + unit() * (top - 1.0) };
                    tessera::pattern::hardware::settled_factor(p.hull_factor(f), p, 1.0 / 64.0) as f32 as f64
                });
                let input = |factors: [f64; 4]| PatternInput {
                    segments: factors.map(|f| edge_segments(f, p)),
                    factors,
                    ..PatternInput::new(domain, [1; 4], [1; 2])
                };
                let worst = p.hull_factor(top).min(p.range().1 as f64) as f32 as f64;
                let pattern = Hardware { partitioning: p };
                let (v, t) = pattern.counts(&input(factors));
                let (wv, wt) = pattern.counts(&input([worst; 4]));
                let inner: u32 = (0..domain.corner_count()).map(|e| input(factors).segments[e] - 1).sum();
                let worst_inner: u32 = (0..domain.corner_count()).map(|_| edge_segments(worst, p) - 1).sum();
                assert!(
                    v + inner <= wv + worst_inner && t <= wt,
                    "{} {domain:?} factors {factors:?}: {v} + {inner} vertices and {t} triangles, \
                     over the worst case {wv} + {worst_inner} and {wt} at {worst}",
                    p.name()
                );
            }
        }
    }
}

/// What the camera sweeps saw, reported at the end.
#[derive(Debug, Default)]
struct FactorCounts {
    frames: usize,
    edges: usize,
    /// Edges whose GPU factor is not the CPU's bit for bit (silhouetteness strictly between
    /// 0 and 1 only: f32 data on the GPU, f64 on the CPU).
    rounding: usize,
    /// Of those, edges whose segments differ from the CPU's.
    segment_ties: usize,
    /// The largest relative difference of a real factor.
    worst_relative: f64,
    /// Edges at intermediate silhouetteness, where a difference may arise.
    intermediate: usize,
}

/// Output size of a sweep frame: factors chosen so that no frame exceeds about this many
/// triangles (lavapipe and the CPU comparison stay fast).
const SWEEP_TRIANGLES: usize = 25_000;

/// Relative difference of a real silhouetteness factor computed from f32 copies of the CPU's
/// f64 midpoints and normals: `1 − 4·(c·nL)(c·nR)` loses about 8 f32 roundings of the
/// products (≈ 1e-6 of the factor range), well within this bound.
const ROUNDING: f64 = 1e-5;

/// The hardware frame from the camera alone on `models`, `cameras_per_model` seeded cameras
/// each, one frame per camera, against the CPU library: silhouetteness factors in
/// `1..=cap − ¼` and a fixed real factor taking turns, each with every partitioning in turn
/// (eight cameras cover every pair; the start moves from model to model). The GPU culls and
/// resolves the factors (`GpuTessellator::prepare_screen`); its culled set equals the CPU
/// plan's (`Scheme::Hardware(p).plan_prepared`) but for counted [`near_cull_tie`]s; its real
/// factors equal the CPU's bit for bit, but for silhouetteness strictly between 0 and 1,
/// where they may differ by rounding (counted, at most [`ROUNDING`] relative); its segments
/// are `edge_segments` of its own factors, so they differ from the CPU's only where its
/// factor does (counted); its interiors are `resolve::interiors` of its segments. Then the
/// output equals the CPU engine's for the plan the GPU drew, every `mesh_every`-th frame.
fn hardware_from_the_camera(
    models: &[String],
    load: impl Fn(&str) -> SurfaceSet,
    cameras_per_model: usize,
    seed: u64,
    mesh_every: usize,
) -> (SweepCounts, FactorCounts) {
    let ctx = ctx();
    let mut sweep = SweepCounts::default();
    let mut counts = FactorCounts::default();
    for (m, model) in models.iter().enumerate() {
        let start = std::time::Instant::now();
        let set = load(model);
        let prepared = Prepared::new(&set, true);
        let mut gpu = tessellator(&set);
        // The factor cap from the size: about 2f² triangles a quad at factor f, at least 2
        // (fractional_even's smallest factor).
        let per_patch = SWEEP_TRIANGLES / set.patches.len();
        let cap = (2..=16u32).rev().find(|f| 2 * (f * f) as usize <= per_patch).unwrap_or(2);
        let culled_before = sweep.culled;
        for (c, camera) in cameras(&set, cameras_per_model, seed).into_iter().enumerate() {
            let turn = c + 2 * m;
            let p = PARTITIONINGS[(turn / 2) % 4];
            let (criterion, what) = if turn % 2 == 0 {
                let fmax = cap as f64 - 0.25;
                let c = Criterion::View { criterion: ViewCriterion::Silhouetteness, fmin: 1.0, fmax };
                (c, format!("silhouetteness 1:{fmax}"))
            } else {
                let f = (cap as f64 - 0.3).max(1.0);
                (Criterion::Factor(f), format!("factor {f}"))
            };
            let name = format!("{model} camera {c} {} {what}", p.name());
            let options =
                PlanOptions { camera: Some(camera), cull: true, max_factor: cap, ..Default::default() };
            let scheme = Scheme::Hardware(p);
            let cpu = scheme.plan_prepared(&set, &prepared, &criterion, &options).unwrap().plan;
            let screen = ScreenCriterion::new(scheme, criterion, cap);
            screen_frame(&mut gpu, &set, &prepared, &camera, screen);
            assert!(!gpu.read_status(ctx).unwrap().0, "{name}: the frame overflowed its worst case");
            let visible = check_culling(&name, &set, &gpu, &cpu.visible, &camera, &mut sweep);
            let drawn = gpu.read_plan(ctx).unwrap();
            assert_eq!(drawn.visible, visible, "{name}");
            assert_eq!(drawn.kind, cpu.kind, "{name}");
            compare_factors(&name, &set, &camera, &criterion, cap, &cpu, &drawn, &mut counts);
            let mut interior = Vec::new();
            let caps = prepared.caps(cap as f64);
            resolve::interiors(&set, &drawn.segments, InteriorRule::MaxEdge, &caps, &mut interior);
            assert_eq!(drawn.interior, interior, "{name}: interior factors");
            if drawn.segments == cpu.segments {
                assert_eq!(drawn.interior, cpu.interior, "{name}: interior factors");
            }
            counts.frames += 1;
            sweep.frames += 1;
            if c % mesh_every == 0 {
                let pattern = Hardware { partitioning: p };
                assert_gpu_equals_cpu_after_record(&name, &set, &gpu, &drawn, &pattern);
            }
        }
        assert!(sweep.culled > culled_before, "{model}: the cameras culled nothing, the sweep proves little");
        eprintln!("{model}: cap {cap}, {:.1} s", start.elapsed().as_secs_f64());
    }
    eprintln!("{sweep:?}\n{counts:?}");
    (sweep, counts)
}

/// The GPU's factors and segments against the CPU plan's (see [`hardware_from_the_camera`]).
#[allow(clippy::too_many_arguments)]
fn compare_factors(
    name: &str,
    set: &SurfaceSet,
    camera: &tessera::camera::Camera,
    criterion: &Criterion,
    cap: u32,
    cpu: &Plan,
    drawn: &Plan,
    counts: &mut FactorCounts,
) {
    let p = partitioning_of(cpu).unwrap();
    // The silhouetteness before resolving, as `Scheme::plan_into` bounds the range.
    let real = match *criterion {
        Criterion::View { criterion, fmin, fmax } => {
            let fmax = fmax.min(Scheme::Hardware(p).factor_cap().min(cap as f64));
            Some((
                tessera::criterion::view::edge_factors(set, camera, criterion, fmin.min(fmax), fmax),
                fmin,
                fmax,
            ))
        }
        _ => None,
    };
    for e in 0..cpu.segments.len() {
        let (g, w) = (drawn.factors[e], cpu.factors[e]);
        assert_eq!(
            drawn.segments[e],
            edge_segments(g as f64, p),
            "{name}: edge {e}: segments unlike its factor {g}"
        );
        counts.edges += 1;
        let intermediate = real.as_ref().is_some_and(|(real, lo, hi)| real[e] > lo.max(1.0) && real[e] < *hi);
        counts.intermediate += intermediate as usize;
        if g.to_bits() == w.to_bits() {
            assert_eq!(drawn.segments[e], cpu.segments[e], "{name}: edge {e}");
            continue;
        }
        let relative = ((g - w) as f64 / w as f64).abs();
        assert!(
            intermediate && relative <= ROUNDING,
            "{name}: edge {e} has the factor {g}, the CPU's {w} (silhouetteness factor {:?})",
            real.as_ref().map(|r| r.0[e])
        );
        counts.rounding += 1;
        counts.worst_relative = counts.worst_relative.max(relative);
        counts.segment_ties += (drawn.segments[e] != cpu.segments[e]) as usize;
    }
}

/// The rounding differences must stay what they are: a few last bits on intermediate edges,
/// and segments one count boundary apart only rarely.
fn check_factor_counts(counts: &FactorCounts) {
    assert!(counts.intermediate > 0, "no intermediate silhouetteness: the real factors were never tested");
    assert!(1000 * counts.segment_ties <= counts.edges, "{counts:?}");
}

#[test]
fn hardware_from_the_camera_on_the_gpu_equals_the_cpu_plan() {
    // The fast tier: the small patch models and the meshes under 15 kB, 2 cameras each.
    let models: Vec<String> = all_models()
        .into_iter()
        .filter(|m| {
            m.starts_with("patches/") || std::fs::metadata(data_dir().join(m)).unwrap().len() < 15_000
        })
        .collect();
    let (_, counts) = hardware_from_the_camera(&models, load, 3, 3, 1);
    check_factor_counts(&counts);
}

#[test]
#[ignore = "slow tier: every patch and mesh model, 10 seeded cameras each (4 on the three meshes over 40,000 patches), every partitioning"]
fn hardware_from_the_camera_on_every_model_10_cameras() {
    let (rest, large) = models_by_size();
    let (mut sweep, mut counts) = hardware_from_the_camera(&rest, load, 10, 2026, 3);
    let (more_sweep, more) = hardware_from_the_camera(&large, load, 4, 2026, 3);
    sweep.add(&more_sweep);
    counts.frames += more.frames;
    counts.edges += more.edges;
    counts.rounding += more.rounding;
    counts.segment_ties += more.segment_ties;
    counts.intermediate += more.intermediate;
    counts.worst_relative = counts.worst_relative.max(more.worst_relative);
    eprintln!("total: {sweep:?}\n{counts:?}");
    check_factor_counts(&counts);
    assert!(100 * sweep.cull_ties <= sweep.culled.max(100), "{sweep:?}");
}

/// The output room of a hardware frame planned on the GPU, at the top of the hardware's
/// range from a camera inside the model: the default room (the worst case) holds the frame,
/// and a frame started with room for 16 triangles overflows (drawing nothing), grows and,
/// drawn again, equals the CPU engine's output for the plan the GPU drew. A fixed factor
/// (fractional_odd 62.5) and silhouetteness (fractional_even up to 64).
#[test]
fn hardware_capacity_holds_the_worst_frame_or_grows() {
    let ctx = ctx();
    let set = load("patches/teapot.patches");
    let prepared = Prepared::new(&set, true);
    let camera = close_camera(&set);
    let silhouettes = Criterion::View { criterion: ViewCriterion::Silhouetteness, fmin: 1.0, fmax: 64.0 };
    for (p, criterion) in
        [(Partitioning::FractionalOdd, Criterion::Factor(62.5)), (Partitioning::FractionalEven, silhouettes)]
    {
        let scheme = Scheme::Hardware(p);
        let options = PlanOptions { camera: Some(camera), cull: true, max_factor: 64, ..Default::default() };
        let cpu = scheme.plan_prepared(&set, &prepared, &criterion, &options).unwrap().plan;
        let tiny = Capacity { vertices: 16, triangles: 16 };
        for (start, capacity) in [("default room", None), ("room for 16 triangles", Some(tiny))] {
            let name = format!("{} {criterion:?}, {start}", p.name());
            let mut gpu = tessellator(&set);
            let screen = ScreenCriterion { capacity, ..ScreenCriterion::new(scheme, criterion, 64) };
            gpu.prepare_screen(ctx, &set, &prepared, &camera, screen).unwrap();
            let grown = record_until_complete(&mut gpu, &name);
            assert_eq!(grown > 0, capacity.is_some(), "{name}: grown {grown} times");
            let drawn = gpu.read_plan(ctx).unwrap();
            assert_eq!(drawn.visible, cpu.visible, "{name}: culled set");
            if matches!(criterion, Criterion::Factor(_)) {
                assert_eq!(drawn.factors, cpu.factors, "{name}: factors");
            }
            assert!(
                drawn.segments.iter().any(|&s| s >= 62),
                "{name}: the frame is not at the top of the range"
            );
            assert_gpu_equals_cpu_after_record(&name, &set, &gpu, &drawn, &Hardware { partitioning: p });
        }
    }
}
