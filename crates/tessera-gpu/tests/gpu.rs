//! The GPU engine against the CPU engine, on lavapipe in CI. Every expected value comes from
//! the CPU library (`tessera::engine`) or a CPU scan, never from the GPU itself.
//!
//! No adapter is a failure, not a skip: the message names the packages to install.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;
use tessera::criterion::Plan;
use tessera::engine::{self, Layout, TessellateOptions};
use tessera::mesh::Mesh;
use tessera::pattern::uniform::Uniform;
use tessera::pattern::Pattern;
use tessera::surface::{BuildOptions, SurfaceSet};
use tessera_gpu::scan::{Scan, ScanPipelines};
use tessera_gpu::{readback, GpuContext, GpuError, GpuTessellator};

/// One device for the whole binary (creating one per test costs time on lavapipe).
fn ctx() -> &'static GpuContext {
    static CTX: OnceLock<GpuContext> = OnceLock::new();
    CTX.get_or_init(|| match GpuContext::new() {
        Ok(c) => c,
        Err(e) => panic!("{e}"),
    })
}

fn data_dir() -> PathBuf {
    std::env::var_os("TESSERA_DATA")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data"))
}

fn load(rel: &str) -> SurfaceSet {
    let path = data_dir().join(rel);
    assert!(
        path.exists(),
        "test model {} not found: set TESSERA_DATA to the shared data folder",
        path.display()
    );
    if rel.ends_with(".obj") {
        let mesh = tessera::io::obj::read_obj(&path).unwrap();
        return SurfaceSet::pn_from_mesh(&mesh, &path, BuildOptions::default()).unwrap();
    }
    let file = tessera::io::patches::read_patches(&path).unwrap();
    SurfaceSet::from_patch_file(&file, BuildOptions::default())
}

/// Every triangle-mesh model (PN triangles) of the shared data, smallest first.
fn mesh_models() -> Vec<String> {
    let mut models = Vec::new();
    for sub in ["meshes", "awkward"] {
        for entry in
            std::fs::read_dir(data_dir().join(sub)).unwrap_or_else(|e| panic!("cannot list {sub}: {e}"))
        {
            let entry = entry.unwrap();
            let name = entry.file_name().to_string_lossy().into_owned();
            if name.ends_with(".obj") {
                models.push((entry.metadata().unwrap().len(), format!("{sub}/{name}")));
            }
        }
    }
    models.sort();
    assert!(models.len() >= 10, "{models:?}");
    models.into_iter().map(|(_, m)| m).collect()
}

/// Every `.patches` model of the shared data (the small ones and the bench torus).
fn patch_models() -> Vec<String> {
    let mut models = Vec::new();
    for sub in ["patches", "bench"] {
        let mut names: Vec<String> = std::fs::read_dir(data_dir().join(sub))
            .unwrap_or_else(|e| panic!("cannot list {sub}: {e}"))
            .filter_map(|e| e.ok())
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .filter(|n| n.ends_with(".patches"))
            .map(|n| format!("{sub}/{n}"))
            .collect();
        names.sort();
        models.extend(names);
    }
    assert!(models.len() >= 4, "{models:?}");
    models
}

/// Tiny LCG: the tests' pseudo-random inputs, seeded.
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> u32 {
        self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (self.0 >> 33) as u32
    }
}

#[test]
fn no_adapter_error_names_the_packages() {
    let e = GpuError::NoAdapter { reason: "none".into() };
    assert!(e.to_string().contains("apt-get install -y mesa-vulkan-drivers libvulkan1"), "{e}");
}

#[test]
fn scan_of_any_length_equals_a_cpu_scan() {
    let ctx = ctx();
    let pipelines = ScanPipelines::new(&ctx.device);
    let mut rng = Lcg(12);
    for len in [0u32, 1, 255, 256, 257, 65_535, 1_000_003, (1 << 24) + 3] {
        let base = rng.next() % 1000;
        let input: Vec<u32> = (0..len).map(|_| rng.next() % 16).collect();
        let mut expected = Vec::with_capacity(len as usize);
        let mut sum = base;
        for &x in &input {
            expected.push(sum);
            sum += x;
        }
        let buffer = tessera_gpu::upload::storage_buffer(&ctx.device, "scan test", &input);
        let scan = Scan::new(&ctx.device, &pipelines, &buffer, len, base);
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            scan.record(&pipelines, &mut pass);
        }
        ctx.queue.submit([encoder.finish()]);
        let got: Vec<u32> = readback::read(ctx, &buffer, len as usize).unwrap();
        if let Some(i) = (0..len as usize).find(|&i| got[i] != expected[i]) {
            panic!("length {len}: element {i} is {} instead of {}", got[i], expected[i]);
        }
    }
}

/// The CPU engine's layout and mesh for `plan`.
fn cpu(set: &SurfaceSet, plan: &Plan, pattern: &dyn Pattern) -> (Layout, Mesh) {
    let mut layout = Layout::default();
    layout.build(set, plan, pattern, &TessellateOptions::default()).unwrap();
    let mesh = engine::tessellate(set, plan, pattern, TessellateOptions::default()).unwrap();
    (layout, mesh)
}

fn diagonal(set: &SurfaceSet) -> f64 {
    let (lo, hi) = set.bounds();
    (hi - lo).length()
}

/// The GPU output of `plan` equals the CPU's: the layout's offsets, the triangles (the same
/// numbering, so index for index), positions within 1e-5 of the diagonal, normals within a
/// few degrees (a small step off a collapsed corner), the same watertightness report.
fn assert_gpu_equals_cpu(name: &str, set: &SurfaceSet, gpu: &mut GpuTessellator, plan: &Plan) {
    assert_pattern_equals_cpu(name, set, gpu, plan, &Uniform);
}

/// [`assert_gpu_equals_cpu`] for `pattern`.
fn assert_pattern_equals_cpu(
    name: &str,
    set: &SurfaceSet,
    gpu: &mut GpuTessellator,
    plan: &Plan,
    pattern: &dyn Pattern,
) {
    let ctx = ctx();
    gpu.prepare(ctx, set, plan, pattern).unwrap();
    let mut encoder = ctx.device.create_command_encoder(&Default::default());
    gpu.record(&mut encoder);
    ctx.queue.submit([encoder.finish()]);
    assert_gpu_equals_cpu_after_record(name, set, gpu, plan, pattern);
}

/// The checks of [`assert_gpu_equals_cpu`] on a frame already recorded and submitted.
fn assert_gpu_equals_cpu_after_record(
    name: &str,
    set: &SurfaceSet,
    gpu: &GpuTessellator,
    plan: &Plan,
    pattern: &dyn Pattern,
) {
    let ctx = ctx();
    let (overflow, _, _) = gpu.read_status(ctx).unwrap();
    assert!(!overflow, "{name}: the frame overflowed");
    let (layout, want) = cpu(set, plan, pattern);
    let (edge_offsets, interior_offsets, triangle_offsets) = gpu.read_layout(ctx).unwrap();
    assert_eq!(edge_offsets, layout.edge_offsets, "{name}: edge offsets");
    assert_eq!(interior_offsets, layout.interior_offsets, "{name}: interior offsets");
    assert_eq!(triangle_offsets, layout.triangle_offsets, "{name}: triangle offsets");
    let got = gpu.read_mesh(ctx, set).unwrap();
    assert_eq!(got.triangle_count(), want.triangle_count(), "{name}: triangles");
    assert_eq!(got.vertex_count(), want.vertex_count(), "{name}: vertices");
    // Same numbering rule: the index buffers are equal as they are, so canonically ordered too.
    if let Some(t) = (0..want.triangle_count()).find(|&t| got.triangle(t) != want.triangle(t)) {
        panic!("{name}: triangle {t} is {:?}, the CPU's {:?}", got.triangle(t), want.triangle(t));
    }
    let tolerance = 1e-5 * diagonal(set);
    for (v, (g, w)) in got.positions.iter().zip(&want.positions).enumerate() {
        let d = ((g[0] - w[0]) as f64).hypot((g[1] - w[1]) as f64).hypot((g[2] - w[2]) as f64);
        assert!(d <= tolerance, "{name}: vertex {v} at {g:?}, the CPU's {w:?} ({d} > {tolerance})");
    }
    for (v, (g, w)) in got.normals.iter().zip(&want.normals).enumerate() {
        let dot = g[0] * w[0] + g[1] * w[1] + g[2] * w[2];
        assert!(dot > 0.99, "{name}: normal {v} is {g:?}, the CPU's {w:?}");
    }
    assert_eq!(got.vertex_patch, want.vertex_patch, "{name}: vertex patches");
    assert_eq!(got.triangle_patch, want.triangle_patch, "{name}: triangle patches");
    assert_eq!(got.collapsed_triangles, want.collapsed_triangles, "{name}: collapsed triangles");
    let (g, w) = (tessera::verify::watertight(&got), tessera::verify::watertight(&want));
    assert_eq!(
        (g.boundary_edges, g.nonmanifold_edges, g.misoriented_edges, g.euler_characteristic),
        (w.boundary_edges, w.nonmanifold_edges, w.misoriented_edges, w.euler_characteristic),
        "{name}: watertightness {g:?} vs the CPU's {w:?}"
    );
}

#[test]
fn uniform_tessellation_equals_the_cpu_engine_on_every_patch_model() {
    for model in patch_models() {
        let set = load(&model);
        let mut gpu = GpuTessellator::new(ctx(), &set).unwrap();
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
        let mut gpu = GpuTessellator::new(ctx(), &set).unwrap();
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
        let mut gpu = GpuTessellator::new(ctx(), &set).unwrap();
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
        let mut gpu = GpuTessellator::new(ctx(), &set).unwrap();
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
        let mut gpu = GpuTessellator::new(ctx(), &set).unwrap();
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
/// the box, some far), looking near the centre, narrow and wide fields of view.
fn cameras(set: &SurfaceSet, count: usize, seed: u64) -> Vec<tessera::camera::Camera> {
    use glam::DVec3;
    let (lo, hi) = set.bounds();
    let centre = (lo + hi) * 0.5;
    let radius = (hi - lo).length() * 0.5;
    let mut rng = Lcg(seed);
    let mut unit = || rng.next() as f64 / (1u64 << 31) as f64;
    (0..count)
        .map(|_| {
            let z = 2.0 * unit() - 1.0;
            let phi = std::f64::consts::TAU * unit();
            let r = (1.0 - z * z).sqrt();
            let direction = DVec3::new(r * phi.cos(), r * phi.sin(), z);
            let distance = radius * (0.6 + 2.4 * unit());
            let target = centre + (DVec3::new(unit(), unit(), unit()) - 0.5) * radius * 0.8;
            let up = if direction.z.abs() < 0.9 { DVec3::Z } else { DVec3::Y };
            tessera::camera::Camera {
                eye: centre + direction * distance,
                target,
                up,
                fov_y_degrees: 20.0 + 60.0 * unit(),
                width: 640,
                height: 480,
                near: radius * 0.01,
                far: radius * 10.0,
            }
        })
        .collect()
}

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
        let mut gpu = GpuTessellator::new(ctx, &set).unwrap();
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
            let mut encoder = ctx.device.create_command_encoder(&Default::default());
            gpu.record(&mut encoder);
            ctx.queue.submit([encoder.finish()]);
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
    let ctx = ctx();
    let set = load("patches/teacup.patches");
    let mut gpu = GpuTessellator::new(ctx, &set).unwrap();
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
        let mut gpu = GpuTessellator::new(ctx(), &set).unwrap();
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
        let mut gpu = GpuTessellator::new(ctx(), &set).unwrap();
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
        let pn = load(model);
        let patches = pn
            .patches
            .iter()
            .map(|p| match p {
                tessera::surface::Patch::Pn(t) => tessera::surface::Patch::BezierTriangle(t.geometry.clone()),
                other => other.clone(),
            })
            .collect();
        let set = SurfaceSet::from_patches(patches, BuildOptions::default());
        let mut gpu = GpuTessellator::new(ctx(), &set).unwrap();
        for n in [1, 3, 6] {
            let plan = Plan::uniform(&set, n).unwrap();
            assert_gpu_equals_cpu(&format!("{model} as Bézier triangles, n={n}"), &set, &mut gpu, &plan);
        }
    }
}

/// `set` with its PN triangles replaced by their cubic Bézier geometry (normals then come
/// from the derivatives).
fn as_bezier_triangles(pn: &SurfaceSet) -> SurfaceSet {
    let patches = pn
        .patches
        .iter()
        .map(|p| match p {
            tessera::surface::Patch::Pn(t) => tessera::surface::Patch::BezierTriangle(t.geometry.clone()),
            other => other.clone(),
        })
        .collect();
    SurfaceSet::from_patches(patches, BuildOptions::default())
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
            let mut gpu = GpuTessellator::new(ctx(), &set).unwrap();
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
