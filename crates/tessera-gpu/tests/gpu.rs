//! The GPU engine against the CPU engine, on lavapipe in CI. Every expected value comes from
//! the CPU library (`tessera::engine`) or a CPU scan, never from the GPU itself.
//!
//! No adapter is a failure, not a skip: the message names the packages to install.

mod common;

use common::*;
use tessera::criterion::Plan;
use tessera::engine::{EngineOptions, Layout};
use tessera::pattern::transition::Transition;
use tessera::pattern::uniform::Uniform;
use tessera::surface::SurfaceSet;
use tessera_gpu::scan::{Scan, ScanPipelines};
use tessera_gpu::tessellator::{Capacity, ScreenCriterion};
use tessera_gpu::{readback, GpuError, GpuTessellator};

#[test]
fn no_adapter_error_names_the_packages() {
    let e = GpuError::NoAdapter { reason: "none".into() };
    assert!(e.to_string().contains("apt-get install -y mesa-vulkan-drivers libvulkan1"), "{e}");
}

/// Scans `input` with `base` on the GPU and compares every element with the CPU's exclusive
/// scan, whose sums `add` makes.
fn assert_scan_equals_the_cpus(
    pipelines: &ScanPipelines,
    input: &[u32],
    base: u32,
    add: fn(u32, u32) -> u32,
) {
    let ctx = ctx();
    let len = input.len();
    let mut expected = Vec::with_capacity(len);
    let mut sum = base;
    for &x in input {
        expected.push(sum);
        sum = add(sum, x);
    }
    let buffer = tessera_gpu::upload::storage_buffer(&ctx.device, "scan test", input);
    let scan = Scan::new(&ctx.device, pipelines, &buffer, len as u32, base);
    let mut encoder = ctx.device.create_command_encoder(&Default::default());
    {
        let mut pass = encoder.begin_compute_pass(&Default::default());
        scan.record(pipelines, &mut pass);
    }
    ctx.queue.submit([encoder.finish()]);
    let got: Vec<u32> = readback::read(ctx, &buffer, len).unwrap();
    if let Some(i) = (0..len).find(|&i| got[i] != expected[i]) {
        panic!("length {len}: element {i} is {} instead of {}", got[i], expected[i]);
    }
}

#[test]
fn scan_of_any_length_equals_a_cpu_scan() {
    let pipelines = ScanPipelines::new(&ctx().device);
    let mut rng = Lcg(12);
    for len in [0u32, 1, 255, 256, 257, 65_535, 1_000_003, (1 << 24) + 3] {
        let base = rng.next() % 1000;
        let input: Vec<u32> = (0..len).map(|_| rng.next() % 16).collect();
        assert_scan_equals_the_cpus(&pipelines, &input, base, |a, b| a + b);
    }
}

/// Counts whose sums pass the u32 range: every prefix from there on is `u32::MAX` (the scan
/// saturates, so a frame that large reads as overflowing instead of wrapping to a small
/// total), and the prefixes before it are exact — over one block and over several levels.
#[test]
fn scan_saturates_past_the_u32_range() {
    let pipelines = ScanPipelines::new(&ctx().device);
    let mut rng = Lcg(7);
    for (len, largest) in [(5u32, u32::MAX), (1_025, 1 << 24), (300_007, 1 << 16), (2_000_003, 1 << 13)] {
        let input: Vec<u32> = (0..len).map(|_| rng.next() % largest).collect();
        let total = input.iter().fold(3u32, |a, &b| a.saturating_add(b));
        assert_eq!(total, u32::MAX, "length {len}: the test's counts must pass the u32 range");
        assert_scan_equals_the_cpus(&pipelines, &input, 3, u32::saturating_add);
    }
}

#[test]
fn uniform_tessellation_equals_the_cpu_engine_on_every_patch_model() {
    for model in patch_models() {
        let set = load(&model);
        let mut gpu = tessellator(&set);
        // The torus is large: fewer factors there keep the fast tier fast.
        let factors: &[u32] = if set.patches.len() > 500 { &[1, 5] } else { &[1, 2, 3, 8] };
        for &n in factors {
            let plan = Plan::uniform(&set, n).unwrap();
            assert_gpu_equals_cpu(&format!("{model} n={n}"), &set, &mut gpu, &plan);
        }
    }
}

#[test]
fn uniform_pn_triangles_equal_the_cpu_engine_on_small_meshes() {
    // The fast tier: the meshes under 40 kB (a closed blob, a knob, the non-manifold and the
    // unwelded teapots, the bunny at resolution 4, ...), two factors; the slow tier has them all.
    for model in mesh_models() {
        if std::fs::metadata(data_dir().join(&model)).unwrap().len() > 40_000 {
            continue;
        }
        let set = load(&model);
        let mut gpu = tessellator(&set);
        for n in [1, 4] {
            let plan = Plan::uniform(&set, n).unwrap();
            assert_gpu_equals_cpu(&format!("{model} n={n}"), &set, &mut gpu, &plan);
        }
    }
}

#[test]
#[ignore = "slow tier: every mesh model (PN triangles) at three factors"]
fn uniform_pn_triangles_equal_the_cpu_engine_on_every_mesh() {
    for model in mesh_models() {
        let set = load(&model);
        let mut gpu = tessellator(&set);
        for n in [2, 3, 7] {
            let plan = Plan::uniform(&set, n).unwrap();
            assert_gpu_equals_cpu(&format!("{model} n={n}"), &set, &mut gpu, &plan);
        }
    }
}

#[test]
#[ignore = "slow tier: larger factors on every patch model"]
fn uniform_tessellation_equals_the_cpu_engine_at_larger_factors() {
    for model in patch_models() {
        let set = load(&model);
        let mut gpu = tessellator(&set);
        // Torus factor 32: 4,194,304 triangles, 65,536 workgroups: the 2D dispatch layout.
        let factors: &[u32] = if set.patches.len() > 500 { &[3, 16, 32] } else { &[5, 13, 32, 64] };
        for &n in factors {
            let plan = Plan::uniform(&set, n).unwrap();
            assert_gpu_equals_cpu(&format!("{model} n={n}"), &set, &mut gpu, &plan);
        }
    }
}

#[test]
fn culled_patches_emit_nothing_as_on_the_cpu() {
    let mut rng = Lcg(3);
    for model in ["patches/teapot.patches", "patches/teacup.patches"] {
        let set = load(model);
        let mut gpu = tessellator(&set);
        for round in 0..3 {
            let mut plan = Plan::uniform(&set, 4 + round).unwrap();
            for v in plan.visible.iter_mut() {
                *v = (rng.next() % 3 != 0) as u32;
            }
            assert_gpu_equals_cpu(&format!("{model} culled round {round}"), &set, &mut gpu, &plan);
        }
    }
}

#[test]
fn an_output_past_the_device_limits_is_refused_not_truncated() {
    let ctx = ctx();
    let set = load("patches/teapot.patches");
    // `new` compiles its own pipelines (every other test shares one set).
    let mut gpu = GpuTessellator::new(ctx, &set).unwrap();
    let plan = Plan::uniform(&set, tessera::criterion::MAX_FACTOR).unwrap();
    let err = gpu.prepare(ctx, &set, &plan, &tessera::pattern::uniform::Uniform).unwrap_err();
    assert!(matches!(err, GpuError::OutputTooLarge { .. }), "{err}");
    // A plan of another set is refused too.
    let other = load("patches/teacup.patches");
    let plan = Plan::uniform(&other, 2).unwrap();
    assert!(gpu.prepare(ctx, &set, &plan, &tessera::pattern::uniform::Uniform).is_err());
}

/// Seeded cameras around the model: eyes on a sphere of 0.6–3 bounding radii (some inside

#[test]
fn gpu_culling_equals_the_cpu_on_20_seeded_cameras() {
    culling_equals_the_cpu(20, 7);
}

#[test]
#[ignore = "slow tier: 50 more cameras per model"]
fn gpu_culling_equals_the_cpu_on_50_more_cameras() {
    culling_equals_the_cpu(50, 1234);
}

/// The GPU's culled set (f32) equals the CPU's (f64) and so does the whole mesh. The two
/// could differ for a patch lying within rounding of a frustum plane or of the cone bound;
/// the seeded cameras here hit no such case (and the shader avoids acos/asin, whose f32
/// values are far less precise near 0 and 1).
fn culling_equals_the_cpu(cameras_per_model: usize, seed: u64) {
    use tessera::scheme::{Criterion, PlanOptions, Scheme};
    let ctx = ctx();
    for model in patch_models() {
        let set = load(&model);
        let mut gpu = tessellator(&set);
        let n = if set.patches.len() > 500 { 2 } else { 4 };
        let mut culled_somewhere = 0;
        for (c, camera) in cameras(&set, cameras_per_model, seed).into_iter().enumerate() {
            let options = PlanOptions { camera: Some(camera), cull: true, ..Default::default() };
            let cpu_plan = Scheme::Uniform.plan(&set, &Criterion::Factor(n as f64), &options).unwrap().plan;
            let expected = tessera::criterion::screen::visibility(&set, &camera, true);
            assert_eq!(cpu_plan.visible, expected);
            culled_somewhere += expected.iter().filter(|&&v| v == 0).count();
            // The GPU gets the plan with every patch visible and culls by itself.
            let uncull = Plan::uniform(&set, n).unwrap();
            gpu.set_cull_camera(ctx, Some(&camera));
            gpu.prepare(ctx, &set, &uncull, &tessera::pattern::uniform::Uniform).unwrap();
            record_frame(&gpu);
            let visible = gpu.read_visible(ctx).unwrap();
            let differ: Vec<usize> = (0..expected.len()).filter(|&p| visible[p] != expected[p]).collect();
            let why: Vec<bool> = differ
                .iter()
                .map(|&p| tessera::criterion::screen::back_facing(&set.patches[p], camera.eye))
                .collect();
            assert!(
                differ.is_empty(),
                "{model} camera {c}: patches {differ:?} culled differently (CPU back-facing: {why:?})"
            );
            assert_gpu_equals_cpu_after_record(
                &format!("{model} camera {c}"),
                &set,
                &gpu,
                &cpu_plan,
                &Uniform,
            );
        }
        assert!(culled_somewhere > 0, "{model}: the cameras culled nothing, the test proves little");
        // Without a culling camera the plan's own row counts again.
        gpu.set_cull_camera(ctx, None);
        let mut plan = Plan::uniform(&set, n).unwrap();
        plan.visible.iter_mut().step_by(2).for_each(|v| *v = 0);
        assert_gpu_equals_cpu(&format!("{model} without a culling camera"), &set, &mut gpu, &plan);
    }
}

#[test]
fn output_buffers_grow_with_the_plan_and_the_output_stays_complete() {
    let set = load("patches/teacup.patches");
    let mut gpu = tessellator(&set);
    let mut last = 0;
    for n in [2, 9, 3, 17] {
        let plan = Plan::uniform(&set, n).unwrap();
        assert_gpu_equals_cpu(&format!("teacup n={n}"), &set, &mut gpu, &plan);
        let capacity = gpu.capacity().unwrap().triangles;
        assert!(capacity >= last, "capacity shrank");
        last = capacity;
    }
}

#[test]
fn transition_tessellation_equals_the_cpu_engine_on_every_patch_model() {
    use tessera::scheme::{Criterion, PlanOptions, Scheme};
    for model in patch_models() {
        let set = load(&model);
        let mut gpu = tessellator(&set);
        let diagonal = diagonal(&set);
        // CudaTess's own plans: per-edge factors from an object-space tolerance.
        let tolerances: &[f64] = if set.patches.len() > 500 { &[1e-3] } else { &[1e-2, 1e-3] };
        for &rel in tolerances {
            let planned = Scheme::Transition
                .plan(&set, &Criterion::Tolerance(rel * diagonal), &PlanOptions::default())
                .unwrap();
            let distinct: std::collections::BTreeSet<u32> = planned.plan.segments.iter().copied().collect();
            assert!(distinct.len() > 1, "{model}: one factor everywhere, no strips tested");
            assert_pattern_equals_cpu(
                &format!("{model} tolerance {rel}"),
                &set,
                &mut gpu,
                &planned.plan,
                &planned.pattern,
            );
        }
    }
}

#[test]
fn transition_equals_the_cpu_on_arbitrary_edge_and_core_factors() {
    transition_on_random_factors(
        &["patches/teapot.patches", "patches/teacup.patches", "patches/teapot_teasetorig.patches"],
        4,
        9,
        99,
    );
}

#[test]
#[ignore = "slow tier: more random factor sets, up to 33, every patch model"]
fn transition_equals_the_cpu_on_many_random_factor_sets() {
    let models = patch_models();
    let models: Vec<&str> = models.iter().map(|m| m.as_str()).collect();
    transition_on_random_factors(&models, 6, 33, 2024);
}

/// Any combination of segments per edge and core factors (1 to `max`): strips on any side,
/// raised cores, collapsed edges with strips (the teapot's apex); every fourth round culls a
/// third of the patches.
fn transition_on_random_factors(models: &[&str], rounds: u32, max: u32, seed: u64) {
    let mut rng = Lcg(seed);
    for &model in models {
        let set = load(model);
        let mut gpu = tessellator(&set);
        for round in 0..rounds {
            let segments = (0..set.topology.edges.len()).map(|_| 1 + rng.next() % max).collect();
            let interior =
                (0..set.patches.len()).map(|_| [1 + rng.next() % max, 1 + rng.next() % max]).collect();
            let mut plan = Plan::integer(segments, interior, set.patches.len());
            if round % 4 == 3 {
                plan.visible.iter_mut().step_by(3).for_each(|v| *v = 0);
            }
            let name = format!("{model} random round {round}");
            assert_pattern_equals_cpu(
                &name,
                &set,
                &mut gpu,
                &plan,
                &tessera::pattern::transition::Transition,
            );
        }
    }
}

#[test]
fn uniform_bezier_triangles_equal_the_cpu_engine() {
    // Cubic Bézier triangles (normals from the derivatives): the PN geometry of two meshes.
    for model in ["meshes/blob.obj", "awkward/teapot_tri_nonmanifold.obj"] {
        let set = as_bezier_triangles(&load(model));
        let mut gpu = tessellator(&set);
        for n in [1, 3, 6] {
            let plan = Plan::uniform(&set, n).unwrap();
            assert_gpu_equals_cpu(&format!("{model} as Bézier triangles, n={n}"), &set, &mut gpu, &plan);
        }
    }
}

#[test]
fn transition_on_triangle_patches_equals_the_cpu_engine() {
    // CudaTess's triangle regions (strips, raised cores, the two-region modification) on PN
    // triangles and cubic Bézier triangles: the CPU's own transition plans from an
    // object-space tolerance, then arbitrary per-edge and core factors.
    use tessera::scheme::{Criterion, PlanOptions, Scheme};
    let mut rng = Lcg(31);
    for model in ["meshes/blob.obj", "awkward/teapot_tri_nonmanifold.obj"] {
        let pn = load(model);
        for (kind, set) in [("PN", pn.clone()), ("Bézier", as_bezier_triangles(&pn))] {
            let mut gpu = tessellator(&set);
            let diagonal = diagonal(&set);
            for rel in [1e-2, 2e-3] {
                let planned = Scheme::Transition
                    .plan(&set, &Criterion::Tolerance(rel * diagonal), &PlanOptions::default())
                    .unwrap();
                let distinct: std::collections::BTreeSet<u32> =
                    planned.plan.segments.iter().copied().collect();
                assert!(distinct.len() > 1, "{model}: one factor everywhere, no strips tested");
                let name = format!("{model} {kind} tolerance {rel}");
                assert_pattern_equals_cpu(&name, &set, &mut gpu, &planned.plan, &planned.pattern);
            }
            for round in 0..3 {
                let max = 7;
                let segments = (0..set.topology.edges.len()).map(|_| 1 + rng.next() % max).collect();
                let interior = (0..set.patches.len())
                    .map(|_| {
                        let n = 1 + rng.next() % max;
                        [n, n]
                    })
                    .collect();
                let mut plan = Plan::integer(segments, interior, set.patches.len());
                if round == 2 {
                    plan.visible.iter_mut().step_by(3).for_each(|v| *v = 0);
                }
                let name = format!("{model} {kind} random round {round}");
                assert_pattern_equals_cpu(
                    &name,
                    &set,
                    &mut gpu,
                    &plan,
                    &tessera::pattern::transition::Transition,
                );
            }
        }
    }
}

/// Output size of a sweep frame: factors chosen so that no frame exceeds about this many
/// triangles (lavapipe and the CPU comparison stay fast).
const SWEEP_TRIANGLES: usize = 25_000;

/// The CPU's pixel-error value before `ceil` of the factor that decides the uniform plan's
/// global factor: the largest over the visible patches of `tolerance::uniform_factor` and
/// `curve_factor`'s square roots (the same formulas, in f64), for explaining a GPU factor
/// one off the CPU's.
fn uniform_pixel_error_root(
    set: &SurfaceSet,
    prepared: &tessera::scheme::Prepared,
    camera: &tessera::camera::Camera,
    pixels: f64,
    visible: &[u32],
) -> f64 {
    let view = camera.view();
    let views = prepared.views(set);
    let mut root = 0.0f64;
    for p in (0..set.patches.len()).filter(|&p| visible[p] != 0) {
        let eps = views[p].tolerance(&set.patches[p], &view, pixels, false).unwrap();
        let m = &prepared.hessians[p];
        root = root.max(((m.uu + 2.0 * m.uv + m.vv) / (8.0 * eps)).sqrt());
        for l in 0..set.patches[p].domain().corner_count() {
            root = root.max((prepared.curves[p][l] / (8.0 * eps)).sqrt());
        }
    }
    root
}

/// The acceptance sweep on `models`: `cameras_per_model` seeded cameras each, two or three
/// frames per camera, each against the CPU library:
///
/// - **uniform, from the camera alone**: the GPU culls and computes the pixel-error factor
///   ([`GpuTessellator::prepare_screen`]); its culled set and plan (segments, interior
///   factors) equal `Scheme::Uniform`'s pixel-error plan on the CPU, but for the counted
///   rounding ties ([`near_cull_tie`]; a factor one off where the CPU's root is within
///   1e-5 relative of an integer);
/// - **transition, from the camera alone**: odd cameras, the GPU culls and computes
///   silhouetteness factors (per edge, maximum over the edge's patches, the core rule);
///   its plan equals `Scheme::Transition`'s on the CPU but for counted rounding ties;
///   even cameras, the pixel error: CudaTess's per-edge factors and the a-posteriori check
///   on the GPU ([`checked_frame`]: the plan, the rounds and the capped patches
///   equal the CPU's but for counted ties, and every bound verified in f64);
/// - **semi-uniform, from the camera alone**, every camera: the pixel error's edge
///   levels and patch levels checked a posteriori on the GPU ([`checked_frame`], as for
///   transition);
/// - **SD-2, from the camera alone**, on the triangle models, every fourth camera (the
///   others): the distance level function, every other time with the reverse projection
///   ([`sd2_frame_from_the_camera`]: real factors and depths as the CPU's, never three
///   different a triangle).
///
/// Then the whole output equals the CPU engine's for the plan the GPU drew
/// ([`assert_gpu_equals_cpu_after_record`]: offsets, triangle count, triangles index for
/// index, positions within 1e-5 of the diagonal, the watertightness report).
fn acceptance_sweep(models: &[String], cameras_per_model: usize, seed: u64) -> SweepCounts {
    // The checked frames plan with the second-derivative bound: the expansion bound's
    // pipelines take lavapipe about half a minute to compile, and `tests/check.rs` compares
    // its plans with the CPU's.
    let bound = tessera::scheme::ErrorBound::Hessian;
    use tessera::criterion::view::{Mapping, ViewCriterion};
    use tessera::scheme::{Criterion, PlanOptions, Scheme};
    let ctx = ctx();
    let mut counts = SweepCounts::default();
    for model in models {
        let start = std::time::Instant::now();
        let set = load(model);
        let prepared = tessera::scheme::Prepared::new(&set, true);
        let mut gpu = tessellator(&set);
        // The factor cap from the size: 2n² triangles a quad at factor n.
        let per_patch = SWEEP_TRIANGLES / set.patches.len();
        let cap = (1..=8u32).rev().find(|n| 2 * (n * n) as usize <= per_patch.max(2)).unwrap_or(1);
        // Pixel errors: the uniform frame's global factor is the finest patch's, so it needs a
        // coarser error to fall below the cap on some cameras.
        // The largest meshes' patches are a few pixels wide: a finer error gives them strips.
        let (uniform_pixels, pixels) = (16.0, if set.patches.len() > 40_000 { 2.0 } else { 4.0 });
        // Transition strips need two factors: a cap of at least 2.
        let transition_options = |camera| PlanOptions {
            camera: Some(camera),
            cull: true,
            max_factor: cap.max(2),
            ..Default::default()
        };
        let (culled_before, strips_before) = (counts.culled, counts.strips);
        for (c, camera) in cameras(&set, cameras_per_model, seed).into_iter().enumerate() {
            let options =
                PlanOptions { camera: Some(camera), cull: true, max_factor: cap, ..Default::default() };
            // Uniform: the GPU plans the frame from the camera.
            let name = format!("{model} camera {c} uniform");
            let criterion = Criterion::PixelError(uniform_pixels);
            let cpu = Scheme::Uniform.plan_prepared(&set, &prepared, &criterion, &options).unwrap().plan;
            let screen = ScreenCriterion::new(Scheme::Uniform, Criterion::PixelError(uniform_pixels), cap);
            screen_frame(&mut gpu, &set, &prepared, &camera, screen);
            let visible = check_culling(&name, &set, &gpu, &cpu.visible, &camera, &mut counts);
            let drawn = gpu.read_plan(ctx).unwrap();
            assert_eq!(drawn.visible, visible);
            let (want, got) = (cpu.segments.iter().max().copied(), drawn.segments.iter().max().copied());
            assert!(drawn.segments.iter().all(|&s| Some(s) == got), "{name}: segments not uniform");
            assert!(
                drawn.interior.iter().all(|&[u, v]| Some(u) == got && Some(v) == got),
                "{name}: interiors"
            );
            if got != want {
                // Only a rounding tie of the deciding root, with the same culled set.
                let root = uniform_pixel_error_root(&set, &prepared, &camera, uniform_pixels, &visible);
                let tie = (root - root.round()).abs() <= 1e-5 * root;
                assert!(
                    visible == cpu.visible && tie && want.unwrap().abs_diff(got.unwrap()) == 1,
                    "{name}: GPU factor {got:?}, the CPU's {want:?} (root {root})"
                );
                counts.factor_ties += 1;
            } else if visible == cpu.visible {
                assert_eq!(drawn.segments, cpu.segments, "{name}: segments");
                assert_eq!(drawn.interior, cpu.interior, "{name}: interior factors");
            }
            counts.below_cap += (got.unwrap() < cap) as usize;
            assert_gpu_equals_cpu_after_record(&name, &set, &gpu, &drawn, &Uniform);

            // Transition, from the camera on the GPU: odd cameras silhouetteness factors, even
            // cameras a pixel error (CudaTess's per-edge factors, checked a posteriori).
            let options = transition_options(camera);
            let (name, plan, pattern) = if c % 2 == 1 {
                let name = format!("{model} camera {c} transition from the camera");
                let fmax = options.max_factor as f64;
                let criterion = Criterion::View { criterion: ViewCriterion::Silhouetteness, fmin: 1.0, fmax };
                let planned =
                    Scheme::Transition.plan_prepared(&set, &prepared, &criterion, &options).unwrap();
                let screen = ScreenCriterion::new(Scheme::Transition, criterion, options.max_factor);
                screen_frame(&mut gpu, &set, &prepared, &camera, screen);
                check_culling(&name, &set, &gpu, &planned.plan.visible, &camera, &mut counts);
                let drawn = gpu.read_plan(ctx).unwrap();
                if drawn.segments != planned.plan.segments {
                    // Only rounding ties (see `silhouetteness_on_the_gpu`), counted.
                    let real = tessera::criterion::view::edge_factors(
                        &set,
                        &camera,
                        ViewCriterion::Silhouetteness,
                        1.0,
                        fmax,
                    );
                    for e in (0..real.len()).filter(|&e| drawn.segments[e] != planned.plan.segments[e]) {
                        assert!((real[e] - real[e].floor() - 0.5).abs() <= 1e-4, "{name}: edge {e} factor");
                        counts.factor_ties += 1;
                    }
                } else {
                    assert_eq!(drawn.interior, planned.plan.interior, "{name}: interior factors");
                }
                (name, drawn, planned.pattern)
            } else {
                let name = format!("{model} camera {c} transition {pixels} px");
                let cap = options.max_factor;
                let scheme = Scheme::Transition;
                let plan = checked_frame(
                    scheme,
                    bound,
                    &name,
                    &set,
                    &prepared,
                    &mut gpu,
                    &camera,
                    pixels,
                    cap,
                    &mut counts,
                );
                (name, plan, tessera::scheme::SchemePattern::Transition(Transition))
            };
            assert_gpu_equals_cpu_after_record(&name, &set, &gpu, &plan, &pattern);
            let s = &plan.segments;
            counts.strips += s.iter().any(|&x| x != s[0]) as usize;
            counts.frames += 2;

            // Semi-uniform: the pixel error's levels checked a posteriori on the GPU, under the
            // largest power-of-two cap within the cap.
            {
                let name = format!("{model} camera {c} semi-uniform {pixels} px");
                let scheme = Scheme::SemiUniform { max_level: tessera::pattern::semi_uniform::MAX_LEVEL };
                let cap = 1 << cap.max(2).ilog2();
                let plan = checked_frame(
                    scheme,
                    bound,
                    &name,
                    &set,
                    &prepared,
                    &mut gpu,
                    &camera,
                    pixels,
                    cap,
                    &mut counts,
                );
                let pattern = tessera::pattern::semi_uniform::SemiUniform;
                assert_gpu_equals_cpu_after_record(&name, &set, &gpu, &plan, &pattern);
                counts.frames += 1;
            }
            // SD-2 on triangle models, from the camera alone: paper 001's three level functions
            // in turn (the distance's linear and quadratic mappings, the vertex silhouettes),
            // every other time reverse-projected.
            let triangles = set.patches.iter().all(|p| p.domain() == tessera::surface::Domain::Tri);
            if triangles {
                let name = format!("{model} camera {c} sd2");
                let fmax = options.max_factor as f64 + 0.5;
                let level = [
                    ViewCriterion::Distance(Mapping::Linear),
                    ViewCriterion::Distance(Mapping::Quadratic),
                    ViewCriterion::SilhouetteVertices,
                ][c % 3];
                let criterion = Criterion::View { criterion: level, fmin: 1.0, fmax };
                let frame = Sd2Frame { warp: c % 2 == 1, criterion, max_factor: options.max_factor + 1 };
                sd2_frame_from_the_camera(&name, &set, &prepared, &mut gpu, &camera, frame, &mut counts);
            }
            // ESC on bicubic models, planned on the GPU from the camera alone (levels per
            // object, distance tests, grids), the two presets in turn.
            let bicubic = set.patches.iter().all(|p| matches!(p, tessera::surface::Patch::Bicubic(_)));
            if bicubic {
                let name = format!("{model} camera {c} esc");
                use tessera::criterion::esc::Threshold;
                let threshold = if c % 2 == 0 { Threshold::Medium } else { Threshold::High };
                let criterion = Criterion::Esc { threshold, level: None };
                let ties = &mut counts.esc_ties;
                esc_frame_from_the_camera(&name, &set, &prepared, &mut gpu, &camera, criterion, ties);
                counts.frames += 1;
            }
        }
        assert!(
            counts.culled > culled_before,
            "{model}: the cameras culled nothing, the sweep proves little"
        );
        assert!(counts.strips > strips_before, "{model}: no transition frame had two edge factors");
        eprintln!("{model}: cap {cap}, {:.1} s", start.elapsed().as_secs_f64());
    }
    eprintln!("{counts:?}");
    counts
}

#[test]
fn acceptance_sweep_on_the_small_models() {
    // The fast tier: the small patch models and the meshes under 15 kB, 4 cameras each.
    let models: Vec<String> = all_models()
        .into_iter()
        .filter(|m| {
            std::fs::metadata(data_dir().join(m)).unwrap().len() < 15_000 || m.starts_with("patches/")
        })
        .collect();
    let counts = acceptance_sweep(&models, 3, 77);
    assert!(counts.below_cap > 0, "no uniform frame below the cap: the GPU factor was never tested");
    assert_eq!(counts.check_ties, 0, "{counts:?}");
}

#[test]
#[ignore = "slow tier: every patch and mesh model, 10 seeded cameras each, uniform, transition, semi-uniform, SD-2 and ESC"]
fn acceptance_sweep_on_every_model_10_cameras() {
    // The three meshes of over 40,000 patches take 4 cameras each (they dominate the time;
    // at factors 1 and 2 most of their work is the CPU side of the comparison).
    let (rest, large) = models_by_size();
    let mut counts = acceptance_sweep(&rest, 10, 2026);
    counts.add(&acceptance_sweep(&large, 4, 2026));
    assert!(counts.check_rounds > 0, "no pixel-error transition frame needed a fix round: {counts:?}");
    // The check's decisions met no f32 rounding tie in these frames: none is allowed, so a
    // difference is a bug until shown to be a tie.
    assert_eq!(counts.check_ties, 0, "{counts:?}");
    assert!(counts.below_cap > 0, "no uniform frame below the cap: the GPU factor was never tested");
    // Rounding ties must stay rare: at most one frame or patch in a hundred.
    assert!(100 * counts.factor_ties <= counts.frames, "{counts:?}");
    assert!(counts.esc_ties <= counts.frames, "{counts:?}");
    assert!(100 * counts.cull_ties <= counts.culled.max(100), "{counts:?}");
}

/// The capacity test on `model` at factor cap `cap`: a close camera and a fine pixel error
/// drive the GPU's factor to the cap (checked on the CPU plan). Started with the default
/// room (the worst case within the device's limits) the frame fits or reports an overflow
/// and grows; started with room for 16 triangles it must overflow, grow and rerun. Either
/// way the final frame is complete: its layout (every offset, so every patch's triangle
/// count) equals the CPU's for the CPU plan, and so does the triangle total.
fn capacity_at_the_cap(model: &str, cap: u32) {
    use tessera::scheme::{Criterion, PlanOptions, Scheme};
    let ctx = ctx();
    let set = load(model);
    let prepared = tessera::scheme::Prepared::new(&set, true);
    let camera = close_camera(&set);
    let pixels = 0.001;
    let options = PlanOptions { camera: Some(camera), cull: true, max_factor: cap, ..Default::default() };
    let cpu = Scheme::Uniform
        .plan_prepared(&set, &prepared, &Criterion::PixelError(pixels), &options)
        .unwrap()
        .plan;
    assert_eq!(cpu.segments.iter().max(), Some(&cap), "{model}: the camera does not reach the cap");
    let mut layout = Layout::default();
    layout.build(&set, &cpu, &Uniform, &EngineOptions::default()).unwrap();
    let total = *layout.triangle_offsets.last().unwrap();
    let tiny = Capacity { vertices: 16, triangles: 16 };
    for (start, capacity) in [("default room", None), ("room for 16 triangles", Some(tiny))] {
        let name = format!("{model} cap {cap}, {start}");
        let mut gpu = tessellator(&set);
        let screen = ScreenCriterion {
            capacity,
            ..ScreenCriterion::new(Scheme::Uniform, Criterion::PixelError(pixels), cap)
        };
        gpu.prepare_screen(ctx, &set, &prepared, &camera, screen).unwrap();
        let grown = record_until_complete(&mut gpu, &name);
        assert!(capacity.is_none() || grown > 0, "{name}: 16 triangles of room and no overflow");
        let (overflow, _, triangles) = gpu.read_status(ctx).unwrap();
        assert!(!overflow, "{name}");
        assert_eq!(triangles, total, "{name}: triangle total");
        assert_eq!(gpu.read_plan(ctx).unwrap().visible, cpu.visible, "{name}: culled set");
        let (edge_offsets, interior_offsets, triangle_offsets) = gpu.read_layout(ctx).unwrap();
        assert_eq!(triangle_offsets, layout.triangle_offsets, "{name}: triangle offsets");
        assert_eq!(edge_offsets, layout.edge_offsets, "{name}: edge offsets");
        assert_eq!(interior_offsets, layout.interior_offsets, "{name}: interior offsets");
        eprintln!(
            "{name}: {total} triangles, grown {grown} times, capacity {:?}, device limit {} bytes",
            gpu.capacity().unwrap(),
            ctx.limits.max_storage_buffer_binding_size.min(ctx.limits.max_buffer_size)
        );
    }
}

#[test]
fn capacity_at_the_cap_fits_or_grows_and_the_output_is_complete() {
    capacity_at_the_cap("patches/teapot.patches", 64);
}

#[test]
#[ignore = "slow tier: the torus at factor cap 64 (a worst case past the storage binding limit)"]
fn capacity_at_the_cap_on_the_torus() {
    capacity_at_the_cap("bench/torus_64x32.patches", 64);
    // A frame past the storage binding limit overflows, draws nothing (zero indirect counts,
    // no partial mesh) and growing refuses with the sizes, so no patch is dropped silently.
    // The limit is the adapter's (lavapipe 128 MiB, an H200 2 GiB), so the cap is raised
    // until the CPU plan's frame itself needs more than the limit.
    use tessera::scheme::{Criterion, PlanOptions, Scheme};
    let ctx = ctx();
    let set = load("bench/torus_64x32.patches");
    let prepared = tessera::scheme::Prepared::new(&set, true);
    let camera = close_camera(&set);
    let criterion = Criterion::PixelError(0.001);
    let limit = ctx.limits.max_storage_buffer_binding_size.min(ctx.limits.max_buffer_size);
    let frame_triangles = |cap: u32| {
        let options = PlanOptions { camera: Some(camera), cull: true, max_factor: cap, ..Default::default() };
        let plan = Scheme::Uniform.plan_prepared(&set, &prepared, &criterion, &options).unwrap().plan;
        let mut layout = Layout::default();
        layout.build(&set, &plan, &Uniform, &EngineOptions::default()).unwrap();
        u64::from(*layout.triangle_offsets.last().unwrap())
    };
    let cap = [256, 512, 1024, 2048]
        .into_iter()
        .find(|&cap| frame_triangles(cap) * 12 > limit)
        .unwrap_or_else(|| panic!("no cap up to 2048 passes the binding limit of {limit} bytes"));
    let mut gpu = tessellator(&set);
    let screen = ScreenCriterion::new(Scheme::Uniform, criterion, cap);
    screen_frame(&mut gpu, &set, &prepared, &camera, screen);
    let draw: Vec<u32> = readback::read(ctx, gpu.indirect_buffer(), 5).unwrap();
    assert_eq!(draw[0], 0, "cap {cap}: an overflowing frame drew {} indices", draw[0]);
    match gpu.grow_if_overflowed(ctx) {
        Err(GpuError::OutputTooLarge { triangles, limit, .. }) => {
            assert!(triangles * 12 > limit, "refused {triangles} triangles under the limit {limit}")
        }
        other => panic!("cap {cap}: expected OutputTooLarge, got {other:?}"),
    }
}

/// A cap whose worst case passes the u32 range of the scans (the teapot's 32 patches at
/// factor 16,384: 2³⁴ triangles) is prepared, not refused: a camera that asks for a small
/// frame gets it whole, equal to the CPU plan's layout, in the room the caller gave; a
/// camera that drives every patch to the cap overflows (the saturated totals fit no buffer;
/// wrapped, they would sum to 0 mod 2³²), draws nothing, and growing refuses with the sizes.
#[test]
fn a_worst_case_past_the_u32_range_is_drawn_when_the_frame_fits() {
    use tessera::scheme::{Criterion, PlanOptions, Scheme};
    let ctx = ctx();
    let set = load("patches/teapot.patches");
    let prepared = tessera::scheme::Prepared::new(&set, true);
    let cap = tessera::criterion::MAX_FACTOR;
    let room = Capacity { vertices: 1 << 20, triangles: 1 << 20 };
    let screen = |pixels| ScreenCriterion {
        capacity: Some(room),
        ..ScreenCriterion::new(Scheme::Uniform, Criterion::PixelError(pixels), cap)
    };
    // The framing camera at 1 px: a frame of thousands of triangles.
    let (lo, hi) = set.bounds();
    let camera = tessera::camera::Camera::framing(lo, hi, 1280, 720);
    let options = PlanOptions { camera: Some(camera), cull: true, max_factor: cap, ..Default::default() };
    let cpu =
        Scheme::Uniform.plan_prepared(&set, &prepared, &Criterion::PixelError(1.0), &options).unwrap().plan;
    let mut layout = Layout::default();
    layout.build(&set, &cpu, &Uniform, &EngineOptions::default()).unwrap();
    let mut gpu = tessellator(&set);
    gpu.prepare_screen(ctx, &set, &prepared, &camera, screen(1.0)).unwrap();
    assert_eq!(record_until_complete(&mut gpu, "teapot at 1 px"), 0, "the frame fits the room given");
    assert_eq!(gpu.read_plan(ctx).unwrap().segments, cpu.segments, "factors");
    let (_, _, triangle_offsets) = gpu.read_layout(ctx).unwrap();
    assert_eq!(triangle_offsets, layout.triangle_offsets, "triangle offsets");
    assert!(*layout.triangle_offsets.last().unwrap() > 1000);

    // Every patch at the cap: 32 · 2 · 16,384² triangles.
    screen_frame(&mut gpu, &set, &prepared, &close_camera(&set), screen(1e-6));
    let plan = gpu.read_plan(ctx).unwrap();
    let at_cap = plan.segments.iter().filter(|&&s| s == cap).count();
    assert!(at_cap > 20, "the close camera drives {at_cap} edges to the cap");
    let (overflow, vertices, triangles) = gpu.read_status(ctx).unwrap();
    assert!(overflow, "{vertices} vertices and {triangles} triangles seemed to fit");
    assert_eq!(triangles, u32::MAX, "the triangle total saturates");
    let draw: Vec<u32> = readback::read(ctx, gpu.indirect_buffer(), 5).unwrap();
    assert_eq!(draw[0], 0, "an overflowing frame drew {} indices", draw[0]);
    match gpu.grow_if_overflowed(ctx) {
        Err(GpuError::OutputTooLarge { triangles, .. }) => assert_eq!(triangles, u32::MAX as u64),
        other => panic!("expected OutputTooLarge, got {other:?}"),
    }
}

/// The GPU's pixel-error factor against the CPU plan's on `cameras_per_model` seeded
/// cameras per patch model and four pixel errors each, at a cap of 32: equal but for
/// rounding ties of the deciding root (counted, at most one in a hundred), and spread over
/// many values (the cap must not decide them all).
fn gpu_factors_equal_the_cpu_plans(cameras_per_model: usize, seed: u64) {
    use tessera::scheme::{Criterion, PlanOptions, Scheme};
    let ctx = ctx();
    let cap = 32;
    let (mut frames, mut ties) = (0, 0);
    let mut seen = std::collections::BTreeSet::new();
    for model in ["patches/teapot.patches", "patches/teacup.patches", "patches/teapot_teasetorig.patches"] {
        let set = load(model);
        let prepared = tessera::scheme::Prepared::new(&set, true);
        let mut gpu = tessellator(&set);
        for (c, camera) in cameras(&set, cameras_per_model, seed).into_iter().enumerate() {
            for pixels in [0.5, 2.0, 8.0, 32.0] {
                let name = format!("{model} camera {c} {pixels} px");
                let options =
                    PlanOptions { camera: Some(camera), cull: true, max_factor: cap, ..Default::default() };
                let criterion = Criterion::PixelError(pixels);
                let cpu = Scheme::Uniform.plan_prepared(&set, &prepared, &criterion, &options).unwrap().plan;
                let screen = ScreenCriterion::new(Scheme::Uniform, Criterion::PixelError(pixels), cap);
                screen_frame(&mut gpu, &set, &prepared, &camera, screen);
                let got = gpu.read_plan(ctx).unwrap();
                frames += 1;
                if got.visible != cpu.visible {
                    // A culling tie: the factors then follow another set of patches.
                    let differ = (0..got.visible.len()).filter(|&p| got.visible[p] != cpu.visible[p]);
                    assert!(differ.clone().all(|p| near_cull_tie(&set, p, &camera)), "{name}: culling");
                    ties += 1;
                    continue;
                }
                let want = cpu.segments[0];
                seen.insert(want);
                if got.segments != cpu.segments || got.interior != cpu.interior {
                    let root = uniform_pixel_error_root(&set, &prepared, &camera, pixels, &cpu.visible);
                    let tie = (root - root.round()).abs() <= 1e-5 * root;
                    assert!(
                        tie && got.segments.iter().all(|&s| s.abs_diff(want) == 1),
                        "{name}: GPU factor {:?}, the CPU's {want} (root {root})",
                        got.segments.first()
                    );
                    ties += 1;
                }
            }
        }
    }
    eprintln!("{frames} frames, {ties} rounding ties, factors {seen:?}");
    assert!(100 * ties <= frames, "{ties} ties in {frames} frames");
    assert!(seen.len() >= 8, "factors {seen:?}: too few distinct values to test the criterion");
}

#[test]
fn gpu_pixel_error_factors_equal_the_cpu_plans() {
    gpu_factors_equal_the_cpu_plans(5, 5);
}

#[test]
#[ignore = "slow tier: 20 more cameras per patch model"]
fn gpu_pixel_error_factors_equal_the_cpu_plans_on_20_more_cameras() {
    gpu_factors_equal_the_cpu_plans(20, 55);
}

/// The transition frame from the camera alone (silhouetteness, `ViewCriterion::
/// Silhouetteness` with factors 1 to 12, cap 16): the GPU's plan equals
/// `Scheme::Transition`'s on the CPU — segments but for counted rounding ties (an edge whose
/// real factor `view::edge_factors` lies within 1e-4 of a half-integer, one off), interiors
/// exactly those of `resolve::interiors` on the GPU's segments, the culled set but for
/// [`near_cull_tie`]s — and every `mesh_every`-th frame's output equals the CPU engine's for
/// the plan drawn.
fn silhouetteness_on_the_gpu(models: &[&str], cameras_per_model: usize, seed: u64, mesh_every: usize) {
    use tessera::criterion::resolve::InteriorRule;
    use tessera::criterion::view::ViewCriterion;
    use tessera::scheme::{Criterion, PlanOptions, Scheme};
    let ctx = ctx();
    let (cap, fmin, fmax) = (16, 1.0, 12.0);
    let criterion = Criterion::View { criterion: ViewCriterion::Silhouetteness, fmin, fmax };
    let (mut frames, mut edges, mut ties, mut strips) = (0, 0, 0, 0);
    for &model in models {
        let set = load(model);
        let prepared = tessera::scheme::Prepared::new(&set, true);
        let mut gpu = tessellator(&set);
        for (c, camera) in cameras(&set, cameras_per_model, seed).into_iter().enumerate() {
            let name = format!("{model} camera {c} silhouetteness");
            let options =
                PlanOptions { camera: Some(camera), cull: true, max_factor: cap, ..Default::default() };
            let planned = Scheme::Transition.plan_prepared(&set, &prepared, &criterion, &options).unwrap();
            let cpu = &planned.plan;
            let screen = ScreenCriterion::new(Scheme::Transition, criterion, cap);
            screen_frame(&mut gpu, &set, &prepared, &camera, screen);
            let drawn = gpu.read_plan(ctx).unwrap();
            check_culling(&name, &set, &gpu, &cpu.visible, &camera, &mut SweepCounts::default());
            if drawn.segments != cpu.segments {
                let real = tessera::criterion::view::edge_factors(
                    &set,
                    &camera,
                    ViewCriterion::Silhouetteness,
                    fmin,
                    fmax,
                );
                for e in (0..cpu.segments.len()).filter(|&e| drawn.segments[e] != cpu.segments[e]) {
                    let tie = (real[e] - real[e].floor() - 0.5).abs() <= 1e-4;
                    assert!(
                        tie && drawn.segments[e].abs_diff(cpu.segments[e]) == 1,
                        "{name}: edge {e} has {} segments, the CPU's {} (factor {})",
                        drawn.segments[e],
                        cpu.segments[e],
                        real[e]
                    );
                    ties += 1;
                }
            }
            assert_interiors_follow_the_edges(&name, &set, &prepared, &drawn, InteriorRule::Core, cap);
            if drawn.segments == cpu.segments {
                assert_eq!(drawn.interior, cpu.interior, "{name}: interior factors");
            }
            strips += drawn.segments.iter().any(|&s| s != drawn.segments[0]) as usize;
            edges += cpu.segments.len();
            frames += 1;
            if c % mesh_every == 0 {
                assert_gpu_equals_cpu_after_record(&name, &set, &gpu, &drawn, &planned.pattern);
            }
        }
    }
    eprintln!(
        "silhouetteness: {frames} frames, {edges} edges, {ties} rounding ties, {strips} frames with strips"
    );
    assert!(strips * 2 >= frames, "too few frames with two factors: {strips} of {frames}");
    assert!(1000 * ties <= edges, "{ties} rounding ties in {edges} edges");
}

#[test]
fn transition_from_the_camera_on_the_gpu_equals_the_cpu_plan() {
    silhouetteness_on_the_gpu(
        &["patches/teapot.patches", "patches/teacup.patches", "meshes/blob.obj", "meshes/dragknob.obj"],
        4,
        8,
        2,
    );
}

#[test]
#[ignore = "slow tier: the transition frame from the camera on every patch model and three meshes, 10 cameras"]
fn transition_from_the_camera_on_the_gpu_on_10_cameras() {
    silhouetteness_on_the_gpu(
        &[
            "patches/teapot.patches",
            "patches/teacup.patches",
            "patches/teapot_teasetorig.patches",
            "bench/torus_64x32.patches",
            "meshes/blob.obj",
            "meshes/dragknob.obj",
            "awkward/teapot_tri_nonmanifold.obj",
        ],
        10,
        88,
        5,
    );
}

/// Subdivision cages tessellate on the GPU index for index as on the CPU, uniform and
/// transition. Catmull-Clark: regular faces as exact bicubic Bézier patches, the faces next to
/// extraordinary vertices, creases and n-gons as their trees of B-spline pieces and Gregory
/// end caps (`tree.wgsl`), views of one tree (a split quad's quarters, turned patches)
/// included. Loop: every triangle a tree of quartic Bézier triangles and Gregory triangles,
/// walked as Bfr walks it.
fn subdivision_cages_equal_the_cpu_engine(
    surface: tessera::io::SurfaceKind,
    cages: &[String],
    factors: &[u32],
    camera_count: usize,
) {
    use tessera::io::LoadOptions;
    use tessera::scheme::{Criterion, PlanOptions, Scheme};
    use tessera::surface::Patch;
    let options = LoadOptions { surface, ..Default::default() };
    let mut trees = 0;
    for cage in cages {
        let path = tessera::test_support::data(cage);
        let set = tessera::io::load(&path, options).unwrap();
        trees += set
            .patches
            .iter()
            .filter(|p| match p {
                Patch::Subdivision(_) => true,
                // A Loop tree of more than one leaf: an isolated face.
                Patch::Loop(t) => t.leaves().len() > 1,
                _ => false,
            })
            .count();
        let mut gpu = tessellator(&set);
        for &n in factors {
            let plan = Plan::uniform(&set, n).unwrap();
            assert_gpu_equals_cpu(&format!("{cage} n={n}"), &set, &mut gpu, &plan);
        }
        let planned = Scheme::Transition
            .plan(&set, &Criterion::Tolerance(1e-3 * diagonal(&set)), &PlanOptions::default())
            .unwrap();
        assert_pattern_equals_cpu(
            &format!("{cage} tolerance"),
            &set,
            &mut gpu,
            &planned.plan,
            &planned.pattern,
        );
        // Planned on the GPU from the camera: culling by the trees' boxes, the factors and the
        // a-posteriori check by their bounds (the CPU's `Prepared`), then the frame.
        let prepared = tessera::scheme::Prepared::new(&set, true);
        let mut counts = SweepCounts::default();
        for (c, camera) in cameras(&set, camera_count, 11).into_iter().enumerate() {
            let name = format!("{cage} camera {c} transition 1 px");
            let plan = checked_frame(
                Scheme::Transition,
                tessera::scheme::ErrorBound::Hessian,
                &name,
                &set,
                &prepared,
                &mut gpu,
                &camera,
                1.0,
                16,
                &mut counts,
            );
            assert_gpu_equals_cpu_after_record(&name, &set, &gpu, &plan, &Transition);
            // And semi-uniform (paper 000): each patch's level checked a posteriori.
            let name = format!("{cage} camera {c} semi-uniform 1 px");
            let scheme = Scheme::SemiUniform { max_level: tessera::pattern::semi_uniform::MAX_LEVEL };
            let plan = checked_frame(
                scheme,
                tessera::scheme::ErrorBound::Hessian,
                &name,
                &set,
                &prepared,
                &mut gpu,
                &camera,
                1.0,
                16,
                &mut counts,
            );
            let pattern = tessera::pattern::semi_uniform::SemiUniform;
            assert_gpu_equals_cpu_after_record(&name, &set, &gpu, &plan, &pattern);
        }
    }
    assert!(trees > 0, "no isolated face among {cages:?}");
}

/// The transition pattern at corners pinched at a valence-2 vertex (`catmark_val2_interior`):
/// random segments on every edge and random core factors on every patch, so that strips
/// start and end at pinched corners with and without a neighbouring strip (the walk's pinned
/// steps, the raised cores: `transition` module doc, "Pinched corners"), index for index
/// against the CPU engine, which would cut any chord left there (`Pattern::build`).
#[test]
fn transition_at_pinched_corners_equals_the_cpu_engine() {
    let options =
        tessera::io::LoadOptions { surface: tessera::io::SurfaceKind::CatmullClark, ..Default::default() };
    let set = tessera::io::load(&data_dir().join("subdivision/catmark_val2_interior.obj"), options).unwrap();
    assert!(set.topology.patch_pinched.iter().any(|c| c.contains(&true)), "no pinched corner");
    let mut gpu = tessellator(&set);
    let mut rng = Lcg(41);
    for round in 0..12 {
        let segments: Vec<u32> = (0..set.topology.edges.len()).map(|_| 1 + rng.next() % 5).collect();
        let interior = (0..set.patches.len()).map(|_| [1 + rng.next() % 5, 1 + rng.next() % 5]).collect();
        let plan = Plan::integer(segments, interior, set.patches.len());
        assert_pattern_equals_cpu(&format!("val2 round {round}"), &set, &mut gpu, &plan, &Transition);
    }
}

#[test]
fn subdivision_cages_equal_the_cpu_engine_on_the_feature_cages() {
    let cages = [
        "catmark_torus",
        "catmark_edgecorner",
        "catmark_cube",
        "catmark_nonquads",
        "catmark_torus_creases0",
        "catmark_val2_interior",
        "catmark_hole_test1",
    ];
    let cages: Vec<String> = cages.iter().map(|c| format!("subdivision/{c}.obj")).collect();
    subdivision_cages_equal_the_cpu_engine(tessera::io::SurfaceKind::CatmullClark, &cages, &[1, 4], 2);
}

#[test]
#[ignore = "slow tier (every manifold cage): scripts/test runs it"]
fn subdivision_cages_equal_the_cpu_engine_on_every_cage() {
    let non_manifold = ["catmark_fan.obj", "catmark_gregory_test4.obj", "catmark_nonman_edges.obj"];
    let mut cages: Vec<String> = std::fs::read_dir(data_dir().join("subdivision"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .filter(|n| n.starts_with("catmark_") && n.ends_with(".obj") && !non_manifold.contains(&n.as_str()))
        .map(|n| format!("subdivision/{n}"))
        .collect();
    cages.sort();
    assert!(cages.len() >= 30, "{cages:?}");
    subdivision_cages_equal_the_cpu_engine(tessera::io::SurfaceKind::CatmullClark, &cages, &[3], 1);
}

/// Loop cages on the GPU as on the CPU: uniform at factors 1 and 8, transition at a
/// tolerance, and transition and semi-uniform planned on the GPU from a camera; a creased
/// cage, one with extraordinary vertices inside, one with a boundary corner, and a real one
/// (pbrt's Killeroo control mesh: 8,316 triangles, open, nine pieces).
#[test]
fn loop_cages_equal_the_cpu_engine() {
    let cages = ["loop_cube_creases0", "loop_xord_interior", "loop_triangle_edgecorner"];
    let mut cages: Vec<String> = cages.iter().map(|c| format!("subdivision/{c}.obj")).collect();
    cages.push("meshes/killeroo_cage.obj".into());
    subdivision_cages_equal_the_cpu_engine(tessera::io::SurfaceKind::Loop, &cages, &[1, 8], 1);
}

/// Every manifold Loop cage (`loop_val2_interior` has an edge of four triangles, which the
/// Loop surface refuses) on the GPU as on the CPU, from 8 cameras each.
#[test]
#[ignore = "slow tier (every Loop cage, 8 cameras): scripts/test runs it"]
fn loop_cages_equal_the_cpu_engine_on_every_cage_8_cameras() {
    let mut cages: Vec<String> = std::fs::read_dir(data_dir().join("subdivision"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .filter(|n| n.starts_with("loop_") && n.ends_with(".obj") && n != "loop_val2_interior.obj")
        .map(|n| format!("subdivision/{n}"))
        .collect();
    cages.sort();
    assert!(cages.len() >= 11, "{cages:?}");
    subdivision_cages_equal_the_cpu_engine(tessera::io::SurfaceKind::Loop, &cages, &[3], 8);
}

/// `subdivision/{cage}.obj`, its set and its stencils: Catmull-Clark, or Loop with `loop_`.
fn cage_with_stencils(
    cage: &str,
    loop_: bool,
) -> (tessera::surface::PolygonMesh, SurfaceSet, tessera::subdivision::CageStencils) {
    use tessera::subdivision::{CageOptions, CageStencils};
    let path = data_dir().join(format!("subdivision/{cage}.obj"));
    let mesh = tessera::io::obj::read_obj(&path).unwrap();
    let build = if loop_ { CageStencils::build_loop } else { CageStencils::build };
    let (set, stencils) = build(&mesh, &path, CageOptions::default()).unwrap();
    (mesh, set, stencils)
}

/// A deforming cage planned from the camera on the GPU (`GpuStencils::with_moving_bounds`), for
/// both schemes — regular, isolated, split into sub-faces, Loop. At the rest pose, after the
/// moving-bounds pass, the GPU's pixel-error plan equals the CPU's index for index (the pass
/// keeps the rest rows and a tree's culling box bit for bit). Moved, with the transition,
/// semi-uniform and uniform schemes: every patch the CPU draws for the moved set is drawn
/// (no patch culled by a stale box), the GPU's plan keeps every
/// drawn patch's bound, measured with the moved set's own bounds, under its tolerance from
/// the moved surface's box (but the patches the GPU reports failing at the cap), and its
/// output equals the CPU engine's with that plan on the moved set. The refusals: criteria
/// that read rows the pass does not move.
#[test]
fn moving_bounds_plan_a_deforming_cage_from_the_camera() {
    use glam::DVec3;
    use tessera::scheme::{Criterion, PlanOptions, Prepared, Scheme};
    use tessera_gpu::GpuStencils;
    let ctx = ctx();
    let (pixels, cap) = (0.5, 32);
    let mut moved_plans_differ = 0;
    for (cage, loop_) in [
        ("catmark_torus", false),
        ("catmark_torus_creases0", false),
        ("catmark_pyramid_creases0", false),
        ("loop_xord_interior", true),
    ] {
        let (mesh, set, stencils) = cage_with_stencils(cage, loop_);
        let prepared = Prepared::new(&set, true);
        let mut gpu = tessellator(&set);
        let on_gpu =
            GpuStencils::with_moving_bounds(ctx, &stencils, &set, &mut gpu, &prepared, &mesh.positions)
                .unwrap();
        let record_stencils = || {
            let mut encoder = ctx.device.create_command_encoder(&Default::default());
            on_gpu.record(&mut encoder);
            ctx.queue.submit([encoder.finish()]);
        };
        let (lo, hi) = set.bounds();
        let size = lo.distance(hi);
        for (c, camera) in cameras(&set, 3, 71).into_iter().enumerate() {
            let name = format!("{cage} camera {c}");
            // The rest pose through the pass: the CPU's plan, index for index.
            on_gpu.write_positions(ctx, &mesh.positions).unwrap();
            record_stencils();
            let mut counts = SweepCounts::default();
            let drawn = checked_frame(
                Scheme::Transition,
                tessera::scheme::ErrorBound::Hessian,
                &format!("{name} at rest"),
                &set,
                &prepared,
                &mut gpu,
                &camera,
                pixels,
                cap,
                &mut counts,
            );
            assert_eq!(counts.check_ties + counts.cull_ties, 0, "{name} at rest: {counts:?}");
            assert_gpu_equals_cpu_after_record(&format!("{name} at rest"), &set, &gpu, &drawn, &Transition);

            // Moved: a twist about z, a scaling by 1.15 and a jitter of up to 4 % of the size, per vertex and
            // camera.
            let moved: Vec<DVec3> = mesh
                .positions
                .iter()
                .enumerate()
                .map(|(i, p)| {
                    let (s, co) = (0.4 * (p.z - lo.z) / (hi.z - lo.z)).sin_cos();
                    let k = (i + 7 * c) as f64;
                    let jitter =
                        DVec3::new((1.7 * k).sin(), (2.3 * k).sin(), (3.1 * k).sin()) * (0.04 * size);
                    DVec3::new(co * p.x - s * p.y, s * p.x + co * p.y, p.z) * 1.15 + jitter
                })
                .collect();
            on_gpu.write_positions(ctx, &moved).unwrap();
            record_stencils();
            let mut moved_set = set.clone();
            stencils.apply(&moved, &mut moved_set).unwrap();
            let moved_prepared = Prepared::new(&moved_set, true);
            let views = moved_prepared.views(&moved_set);
            let view = camera.view();
            let options =
                PlanOptions { camera: Some(camera), cull: true, max_factor: cap, ..Default::default() };
            let criterion = Criterion::PixelError(pixels);
            for scheme in [Scheme::Transition, Scheme::SemiUniform { max_level: 5 }, Scheme::Uniform] {
                let name = format!("{name} moved, {scheme:?}");
                let screen = ScreenCriterion::new(scheme, criterion, cap);
                screen_frame(&mut gpu, &set, &prepared, &camera, screen);
                let report = gpu.read_screen_report(ctx).unwrap();
                let plan = gpu.read_plan(ctx).unwrap();
                if scheme == Scheme::Transition {
                    moved_plans_differ += usize::from(plan.segments != drawn.segments);
                }
                let exact = scheme.plan_prepared(&moved_set, &moved_prepared, &criterion, &options).unwrap();
                let mut scratch = tessera::pattern::LocalTessellation::default();
                let mut missed = 0;
                for (p, patch_view) in views.iter().enumerate() {
                    if !plan.is_visible(p) {
                        assert!(!exact.plan.is_visible(p), "{name}: patch {p} is culled, the CPU draws it");
                        continue;
                    }
                    let eps = patch_view.tolerance(&moved_set.patches[p], &view, pixels, false).unwrap();
                    let input = tessera::engine::layout::pattern_input(&moved_set, &plan, p);
                    let bound = tessera::criterion::tolerance::patch_bound(
                        &moved_prepared.hessians[p],
                        &input,
                        &exact.pattern,
                        &mut scratch,
                    );
                    missed += usize::from(bound > eps * (1.0 + 1e-4));
                }
                // The uniform scheme has no check: its one factor at the cap is its report.
                let capped = scheme == Scheme::Uniform && plan.segments.iter().any(|&s| s >= cap);
                let failing = if capped { missed } else { report.failing_patches as usize };
                assert!(
                    missed <= failing,
                    "{name}: {missed} patches miss their bound, the GPU reports {failing} failing"
                );
                assert_gpu_equals_cpu_after_record(&name, &moved_set, &gpu, &plan, &exact.pattern);
            }
        }
        if cage == "catmark_torus" {
            // What the pass does not move is refused.
            let camera = cameras(&set, 1, 5)[0];
            for (scheme, criterion) in [
                (
                    Scheme::Sd2 { warp: false },
                    Criterion::View {
                        criterion: tessera::criterion::view::ViewCriterion::Distance(
                            tessera::criterion::view::Mapping::Linear,
                        ),
                        fmin: 1.0,
                        fmax: 8.0,
                    },
                ),
                (
                    Scheme::Transition,
                    Criterion::View {
                        criterion: tessera::criterion::view::ViewCriterion::Silhouetteness,
                        fmin: 1.0,
                        fmax: 8.0,
                    },
                ),
            ] {
                let screen = ScreenCriterion::new(scheme, criterion, cap);
                let e = gpu.prepare_screen(ctx, &set, &prepared, &camera, screen).unwrap_err();
                assert!(
                    matches!(e, GpuError::Unsupported { .. }) && e.to_string().contains("moving cage"),
                    "{e}"
                );
            }
            // And the expansion bound, whose nets are uploaded at rest.
            let screen = ScreenCriterion {
                bound: tessera::scheme::ErrorBound::Expansion,
                ..ScreenCriterion::new(Scheme::Transition, Criterion::PixelError(pixels), cap)
            };
            let e = gpu.prepare_screen(ctx, &set, &prepared, &camera, screen).unwrap_err();
            assert!(
                matches!(e, GpuError::Unsupported { .. }) && e.to_string().contains("moving cage"),
                "{e}"
            );
        }
    }
    assert!(moved_plans_differ > 0, "moving the cages never changed a plan");
}

/// A deforming Catmull-Clark or Loop cage on the GPU (`GpuStencils`): each frame uploads the moved
/// cage vertices only, the stencil pass recomputes the control points and the isolated faces'
/// pieces, and the frame equals the CPU engine's on the set the CPU's stencils give for the
/// same vertices.
#[test]
fn stencils_deform_a_cage_on_the_gpu_as_on_the_cpu() {
    use glam::DVec3;
    use tessera::subdivision::CageOptions;
    use tessera_gpu::GpuStencils;
    let ctx = ctx();
    // A regular cage (control points only), one with creases (isolated quads: their trees'
    // leaf points) and one split into sub-faces (an isolated quad's quarters view one tree).
    // Loop cages: every triangle a tree (one leaf where regular), creased, and with
    // extraordinary vertices inside and on the boundary.
    for (cage, loop_) in [
        ("catmark_torus", false),
        ("catmark_torus_creases0", false),
        ("catmark_pyramid_creases0", false),
        ("loop_cube_creases0", true),
        ("loop_xord_interior", true),
        ("loop_xord_boundary", true),
    ] {
        let (mesh, mut set, stencils) = cage_with_stencils(cage, loop_);
        let mut gpu = tessellator(&set);
        let on_gpu = GpuStencils::new(ctx, &stencils, &set, &gpu).unwrap();
        let plan = Plan::uniform(&set, 5).unwrap();
        gpu.prepare(ctx, &set, &plan, &Uniform).unwrap();
        let (_, before) = cpu(&set, &plan, &Uniform);
        let (lo, hi) = set.bounds();
        for frame in 1..=3 {
            // A twist about z that grows frame by frame.
            let moved: Vec<DVec3> = mesh
                .positions
                .iter()
                .map(|p| {
                    let (s, c) = (0.4 * frame as f64 * p.z / (hi.z - lo.z)).sin_cos();
                    DVec3::new(c * p.x - s * p.y, s * p.x + c * p.y, p.z * (1.0 + 0.1 * frame as f64))
                })
                .collect();
            on_gpu.write_positions(ctx, &moved).unwrap();
            let mut encoder = ctx.device.create_command_encoder(&Default::default());
            on_gpu.record(&mut encoder);
            gpu.record(&mut encoder);
            ctx.queue.submit([encoder.finish()]);
            stencils.apply(&moved, &mut set).unwrap();
            assert_gpu_equals_cpu_after_record(&format!("{cage} frame {frame}"), &set, &gpu, &plan, &Uniform);
        }
        // Not vacuous: the surface did move.
        let after = gpu.read_mesh(ctx, &set).unwrap();
        assert_eq!(after.positions.len(), before.positions.len());
        let far = 0.01 * lo.distance(hi) as f32;
        assert!(
            after.positions.iter().zip(&before.positions).any(|(a, b)| (a[2] - b[2]).abs() > far),
            "{cage}"
        );
        if cage != "catmark_torus" {
            continue;
        }
        // Refusals: other vertex counts, NaN, a tessellator made for another set.
        let e = on_gpu.write_positions(ctx, &mesh.positions[1..]).unwrap_err();
        assert!(e.to_string().contains("positions for a cage of"), "{e}");
        let mut nan = mesh.positions.clone();
        nan[0].x = f64::NAN;
        assert!(on_gpu.write_positions(ctx, &nan).unwrap_err().to_string().contains("not finite"));
        let cube_path = data_dir().join("subdivision/catmark_cube.obj");
        let cube = tessera::io::obj::read_obj(&cube_path).unwrap();
        let cube_set =
            tessera::surface::SurfaceSet::from_subdivision_cage(&cube, &cube_path, CageOptions::default())
                .unwrap();
        let e = GpuStencils::new(ctx, &stencils, &set, &tessellator(&cube_set)).unwrap_err();
        assert!(e.to_string().contains("it was made for a set of"), "{e}");
    }
}
