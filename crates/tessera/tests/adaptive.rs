//! Error-bounded adaptive tessellation: bounds hold when measured, on every model; outputs
//! stay watertight; screen-space bounds hold for random cameras.

mod common;

use glam::{DVec2, DVec3, Vec3};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};
use tessera::camera::Camera;
use tessera::criterion::tolerance::BoundReport;
use tessera::criterion::Plan;
use tessera::engine::{tessellate, EngineOptions};
use tessera::mesh::Mesh;
use tessera::pattern::uniform::Uniform;
use tessera::pattern::Pattern;
use tessera::scheme::{Criterion, ErrorBound, PlanOptions, Scheme, SchemePattern};
use tessera::surface::SurfaceSet;
use tessera::verify;

/// Semi-uniform at its highest level, so that the factor cap rarely stops a bound.
const SEMI_UNIFORM: Scheme = Scheme::SemiUniform { max_level: 8 };

/// The plan, pattern and report of an error-bounded criterion, factors up to 4096.
fn plan(
    set: &SurfaceSet,
    scheme: Scheme,
    criterion: Criterion,
    camera: Option<Camera>,
    cull: bool,
) -> (Plan, SchemePattern, BoundReport) {
    plan_with(set, scheme, criterion, camera, cull, ErrorBound::Hessian)
}

/// [`plan`] with the given bound.
fn plan_with(
    set: &SurfaceSet,
    scheme: Scheme,
    criterion: Criterion,
    camera: Option<Camera>,
    cull: bool,
    bound: ErrorBound,
) -> (Plan, SchemePattern, BoundReport) {
    let options = PlanOptions { camera, cull, max_factor: 4096, bound, ..PlanOptions::default() };
    let planned = scheme.plan(set, &criterion, &options).unwrap();
    (planned.plan, planned.pattern, planned.report.expect("an error-bounded criterion reports"))
}

fn run(set: &SurfaceSet, plan: &Plan, pattern: &dyn Pattern) -> Mesh {
    tessellate(set, plan, pattern, EngineOptions { corner_params: true, ..Default::default() }).unwrap()
}

fn diagonal(set: &SurfaceSet) -> f64 {
    let (lo, hi) = set.bounds();
    lo.distance(hi)
}

#[test]
fn tolerance_bounds_hold_on_the_fast_models() {
    tolerance_bounds_hold(&common::fast_models(), true);
}

#[test]
#[ignore = "slow tier (every model): scripts/test runs it"]
fn tolerance_bounds_hold_on_every_model() {
    tolerance_bounds_hold(&common::all_surface_models(), false);
}

/// Every scheme at 1 %, 0.1 % (transition also 0.01 %) of the diagonal, with both bounds
/// (transition also with the expansion bound), the measured error within the certified
/// bound and, for transition with the Taylor bound, at least 0.8 of it; with `every_taylor`
/// false the Taylor and expansion bounds only for transition at 1 % and
/// 0.1 % (measuring every large mesh again at 0.01 % would add a minute of CI;
/// `the_taylor_bound_cuts_triangles_at_the_same_guarantee`, `taylor_bound.rs` and `tessera
/// bench --suite adaptive` cover the rest).
fn tolerance_bounds_hold(models: &[std::path::PathBuf], every_taylor: bool) {
    for path in models {
        let set = common::load(path).unwrap();
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        for share in [1e-2, 1e-3, 1e-4] {
            let eps = share * diagonal(&set);
            for (scheme, bound) in [Scheme::Transition, Scheme::Uniform, SEMI_UNIFORM]
                .into_iter()
                .flat_map(|s| [(s, ErrorBound::Hessian), (s, ErrorBound::Taylor), (s, ErrorBound::Expansion)])
            {
                if bound == ErrorBound::Expansion && scheme != Scheme::Transition {
                    continue; // the expansion bound's rules are the Taylor bound's (tested with every scheme)
                }
                if scheme != Scheme::Transition && share < 1e-3 {
                    continue; // uniform and dyadic outputs at 0.01% are large; 1% and 0.1% cover them
                }
                if bound != ErrorBound::Hessian
                    && !every_taylor
                    && (scheme != Scheme::Transition || share < 1e-3)
                {
                    continue;
                }
                let (plan, pattern, report) =
                    plan_with(&set, scheme, Criterion::Tolerance(eps), None, false, bound);
                assert_eq!(report.capped_patches, 0, "{name}");
                assert!(report.worst_bound <= eps * (1.0 + 1e-9));
                let mesh = run(&set, &plan, &pattern);
                let err = verify::approximation_error(&mesh, &set, 5).unwrap();
                assert!(
                    err.max <= report.worst_bound,
                    "{name} {scheme:?} {bound:?} {share}: measured {:.3e} > bound {:.3e}",
                    err.max,
                    report.worst_bound
                );
                if (scheme, bound) == (Scheme::Transition, ErrorBound::Taylor) {
                    // The certified bound within 1.25× of the truth. Order 5 samples 15 points
                    // inside a triangle; at 1 % a PN mesh's triangles are whole patches, whose
                    // largest error can lie between them: those are measured again, denser.
                    let mut measured = err.max;
                    if measured < 0.8 * report.worst_bound {
                        measured = measured.max(verify::approximation_error(&mesh, &set, 16).unwrap().max);
                    }
                    assert!(
                        measured >= 0.8 * report.worst_bound,
                        "{name} {share}: measured {measured:.3e} < 0.8 × bound {:.3e}",
                        report.worst_bound
                    );
                }
                common::expect_topology(&set, &plan, &mesh, &name);
            }
        }
    }
}

/// Rational models (the teapot and the torus with weights a function of position,
/// [`tessera::scene::position_weights`], so shared curves keep theirs): the rational bound
/// (derivatives of the numerator and the weight over the smallest weight), and with the
/// Taylor option its sampled refinement, hold when measured on the output of the f32 rational
/// kernels, the refinement with fewer triangles; the output has the input's topology.
#[test]
fn tolerance_bounds_hold_on_rational_models() {
    for rel in ["patches/teapot.patches", "bench/torus_64x32.patches"] {
        let file = tessera::io::patches::read_patches(&common::model(rel)).unwrap();
        let set = SurfaceSet::from_patch_file(&tessera::scene::position_weights(&file), Default::default());
        let name = format!("{rel} rational");
        for share in [1e-2, 1e-3] {
            let eps = share * diagonal(&set);
            let mut triangles = [0; 2];
            for scheme in [Scheme::Transition, Scheme::Uniform] {
                // Both bounds: the Taylor option samples rational patches (the sampled bound).
                for (k, bound) in [ErrorBound::Hessian, ErrorBound::Taylor].into_iter().enumerate() {
                    let (plan, pattern, report) =
                        plan_with(&set, scheme, Criterion::Tolerance(eps), None, false, bound);
                    assert_eq!(report.capped_patches, 0, "{name}");
                    let mesh = run(&set, &plan, &pattern);
                    let err = verify::approximation_error(&mesh, &set, 5).unwrap();
                    assert!(
                        err.max <= report.worst_bound && report.worst_bound <= eps * (1.0 + 1e-9),
                        "{name} {scheme:?} {bound:?} {share}: measured {:.3e}, bound {:.3e}, {eps:.3e}",
                        err.max,
                        report.worst_bound
                    );
                    common::expect_topology(&set, &plan, &mesh, &name);
                    if scheme == Scheme::Transition {
                        triangles[k] = mesh.triangle_count();
                    }
                }
            }
            println!(
                "{name} {share}: transition {} triangles, {} with the Taylor option",
                triangles[0], triangles[1]
            );
            assert!(triangles[1] < triangles[0], "{name} {share}: {triangles:?}");
        }
    }
}

/// Largest projected distance, in pixels, between a mesh point and the surface point at the
/// same parameters, over points whose both projections are inside the view.
fn projected_error(mesh: &Mesh, set: &SurfaceSet, camera: &Camera) -> f64 {
    let params = mesh.corner_params.as_ref().unwrap();
    let mut worst = 0.0f64;
    let bary: Vec<DVec3> = (0..=4)
        .flat_map(|i| (0..=4 - i).map(move |j| DVec3::new(i as f64, j as f64, (4 - i - j) as f64) / 4.0))
        .collect();
    for t in 0..mesh.triangle_count() {
        let patch = &set.patches[mesh.triangle_patch[t] as usize];
        let x = mesh.triangle(t).map(|i| Vec3::from(mesh.positions[i as usize]).as_dvec3());
        let uv = [0, 1, 2].map(|c| DVec2::from(params[3 * t + c].map(f64::from)));
        for b in &bary {
            let linear = x[0] * b.x + x[1] * b.y + x[2] * b.z;
            let exact = patch.position(uv[0] * b.x + uv[1] * b.y + uv[2] * b.z);
            if camera.sees(linear) && camera.sees(exact) {
                let (p, q) = (camera.project(linear).unwrap(), camera.project(exact).unwrap());
                worst = worst.max(p.distance(q));
            }
        }
    }
    worst
}

/// For seeded random cameras: the output is watertight (exactly the input's topology
/// without culling; with culling, open only along culled neighbours), and the measured projected
/// error of visible patches stays under the requested pixels.
#[test]
fn screen_space_bounds_hold_for_random_cameras_on_the_fast_models() {
    screen_space_bounds_hold(&common::fast_models(), 12, 0.5);
}

#[test]
#[ignore = "slow tier (every model, 10 cameras): scripts/test runs it"]
fn screen_space_bounds_hold_for_random_cameras_on_every_model() {
    screen_space_bounds_hold(&common::all_surface_models(), 10, 0.2);
}

/// `cases` seeded cameras per model; a camera plans with the Taylor bound or (as likely) the
/// expansion bound with probability `taylor` (their planning is the slower on the large
/// meshes).
fn screen_space_bounds_hold(models: &[std::path::PathBuf], cases: u32, taylor: f64) {
    for path in models {
        let set = common::load(path).unwrap();
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        let start = std::time::Instant::now();
        // Seeded: the same cameras on every run.
        let mut runner = TestRunner::new_with_rng(
            Config { cases, failure_persistence: None, ..Config::default() },
            TestRng::deterministic_rng(RngAlgorithm::ChaCha),
        );
        runner
            .run(
                &(
                    common::random_camera(&set),
                    any::<bool>(),
                    any::<bool>(),
                    proptest::bool::weighted(taylor),
                    any::<bool>(),
                ),
                |((camera, px), cull, dyadic, taylor, expansion)| {
                    // Both adaptive patterns: CudaTess transition and semi-uniform (dyadic),
                    // and every bound.
                    let scheme = if dyadic { SEMI_UNIFORM } else { Scheme::Transition };
                    let bound = match (taylor, expansion) {
                        (false, _) => ErrorBound::Hessian,
                        (true, false) => ErrorBound::Taylor,
                        (true, true) => ErrorBound::Expansion,
                    };
                    let (plan, pattern, report) =
                        plan_with(&set, scheme, Criterion::PixelError(px), Some(camera), cull, bound);
                    prop_assert_eq!(
                        report.capped_patches,
                        0,
                        "{:?} px {} cull {} {:?}",
                        camera,
                        px,
                        cull,
                        report
                    );
                    let mesh = run(&set, &plan, &pattern);
                    common::expect_topology(&set, &plan, &mesh, &name);
                    let err = projected_error(&mesh, &set, &camera);
                    prop_assert!(err <= px, "{}: {:.3} px > {:.3} px", name, err, px);
                    Ok(())
                },
            )
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        println!("{name}: {cases} cameras in {:.1} s", start.elapsed().as_secs_f64());
    }
}

/// Triangles of the smallest uniform tessellation whose measured max error is ≤ `target`.
fn uniform_triangles_for(set: &SurfaceSet, target: f64) -> (usize, f64) {
    for n in 1..=512 {
        let mesh = run(set, &Plan::uniform(set, n).unwrap(), &Uniform);
        let e = verify::approximation_error(&mesh, set, 5).unwrap().max;
        if e <= target {
            return (mesh.triangle_count(), e);
        }
    }
    panic!("no uniform factor reaches {target}");
}

/// Triangles of the adaptive (transition) tessellation with the largest tolerance whose
/// measured max error is ≤ `target` (tolerances tried from `target` upwards in 2 % steps: the
/// guaranteed bound is conservative, so the measured error sits below the tolerance).
fn adaptive_triangles_for(set: &SurfaceSet, target: f64) -> (usize, f64, f64) {
    let mut best = None;
    let mut eps = target;
    while eps < 8.0 * target {
        let (plan, pattern, _) = plan(set, Scheme::Transition, Criterion::Tolerance(eps), None, false);
        let mesh = run(set, &plan, &pattern);
        let e = verify::approximation_error(&mesh, set, 5).unwrap().max;
        if e <= target {
            best = Some((mesh.triangle_count(), e, eps));
        }
        eps *= 1.02;
    }
    best.expect("the tolerance equal to the target always meets it")
}

/// At equal measured max error, adaptive output uses at most 60 % of the uniform output's
/// triangles on the teapot and the teacup (figures printed with --nocapture).
#[test]
fn adaptive_beats_uniform_at_equal_measured_error() {
    for rel in ["patches/teapot.patches", "patches/teacup.patches"] {
        let set = common::load(&common::model(rel)).unwrap();
        for share in [1e-3, 1e-4] {
            let target = share * diagonal(&set);
            let (tu, eu) = uniform_triangles_for(&set, target);
            let (ta, ea, eps) = adaptive_triangles_for(&set, target);
            let ratio = ta as f64 / tu as f64;
            println!(
                "{rel} target {target:.3e}: uniform {tu} triangles (measured {eu:.3e}), adaptive {ta} triangles (measured {ea:.3e}, tolerance {eps:.3e}): {:.1} %",
                100.0 * ratio
            );
            assert!(
                ratio <= 0.6,
                "{rel} at {target:.3e}: adaptive uses {:.1} % of uniform's triangles",
                100.0 * ratio
            );
        }
    }
}

/// Issue 27's bound: on the three patch models and spot's PN triangles at 1 %, 0.1 % and
/// 0.01 % of the diagonal, transition planned with the Taylor bound has its certified bound
/// within 1.25× of the measured error (measured ≥ 0.8 × bound) without it ever being
/// exceeded, and at 0.1 % and 0.01 % needs at most 80 % of the triangles the
/// second-derivative bound needs for the same guarantee; the expansion bound (the part a GPU
/// check could compute) at most 90 % (0.5 px: 0.74–0.84), its bound never exceeded either.
#[test]
fn the_taylor_bound_cuts_triangles_at_the_same_guarantee() {
    const BOUNDS: [ErrorBound; 3] = [ErrorBound::Hessian, ErrorBound::Taylor, ErrorBound::Expansion];
    let models = [
        "patches/teapot.patches",
        "patches/teacup.patches",
        "patches/teapot_teasetorig.patches",
        "meshes/spot.obj",
    ];
    for rel in models {
        let set = common::load(&common::model(rel)).unwrap();
        for share in [1e-2, 1e-3, 1e-4] {
            let eps = share * diagonal(&set);
            let mut counts = [0usize; 3];
            for (k, bound) in BOUNDS.into_iter().enumerate() {
                let (plan, pattern, report) =
                    plan_with(&set, Scheme::Transition, Criterion::Tolerance(eps), None, false, bound);
                let mesh = run(&set, &plan, &pattern);
                let measured = verify::approximation_error(&mesh, &set, 5).unwrap().max;
                counts[k] = mesh.triangle_count();
                println!(
                    "{rel} {share}: {bound:?} {} triangles, measured {measured:.3e} / bound {:.3e} = {:.3}",
                    counts[k],
                    report.worst_bound,
                    measured / report.worst_bound
                );
                assert!(measured <= report.worst_bound, "{rel} {share} {bound:?}: the bound is exceeded");
                if bound == ErrorBound::Taylor {
                    assert!(
                        measured >= 0.8 * report.worst_bound,
                        "{rel} {share}: measured / bound below 0.8"
                    );
                }
            }
            // At 1 % spot's patches are single triangles with either bound: no fewer there.
            // The expansion bound keeps less of the gain (its share 0.71–0.76 at 0.1 % and
            // 0.01 %): at most 0.9.
            for (k, most) in [(1, 0.8), (2, 0.9)] {
                assert!(
                    share > 1e-3 || counts[k] as f64 <= most * counts[0] as f64,
                    "{rel} {share}: {} triangles with the {:?} bound, {} without",
                    counts[k],
                    BOUNDS[k],
                    counts[0]
                );
            }
        }
        // The same at 0.5 px from three cameras: the framing one and two more around the model.
        let (lo, hi) = set.bounds();
        let framing = Camera::framing(lo, hi, 1280, 720);
        let (centre, d) = ((lo + hi) / 2.0, lo.distance(hi));
        for eye in [None, Some(DVec3::new(1.5, 1.0, 2.0)), Some(DVec3::new(-1.0, 2.5, 0.5))] {
            let camera = match eye {
                None => framing,
                Some(dir) => {
                    let e = centre + dir * d;
                    Camera::parse(&format!("eye={},{},{}", e.x, e.y, e.z), &framing).unwrap()
                }
            };
            let mut counts = [0usize; 3];
            for (k, bound) in BOUNDS.into_iter().enumerate() {
                let (plan, pattern, _) = plan_with(
                    &set,
                    Scheme::Transition,
                    Criterion::PixelError(0.5),
                    Some(camera),
                    false,
                    bound,
                );
                let mesh = run(&set, &plan, &pattern);
                counts[k] = mesh.triangle_count();
                let px = projected_error(&mesh, &set, &camera);
                assert!(px <= 0.5, "{rel} {eye:?} {bound:?}: {px} px");
            }
            println!(
                "{rel} 0.5 px from {eye:?}: {} triangles with the Taylor bound, {} with the expansion bound, {} \
                 with neither",
                counts[1], counts[2], counts[0]
            );
            assert!(counts[1] as f64 <= 0.8 * counts[0] as f64, "{rel} 0.5 px from {eye:?}: {counts:?}");
            assert!(counts[2] as f64 <= 0.9 * counts[0] as f64, "{rel} 0.5 px from {eye:?}: {counts:?}");
        }
    }
}
