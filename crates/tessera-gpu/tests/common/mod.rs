//! Helpers shared by the GPU test files: the one device and pipeline set per binary, the
//! shared data, seeded cameras, and the comparison of a GPU frame with the CPU engine's.
//! Every expected value comes from the CPU library, never from the GPU itself.

#![allow(dead_code)] // each test binary uses a part

use std::path::{Path, PathBuf};
use std::sync::OnceLock;
use tessera::criterion::Plan;
use tessera::engine::{self, EngineOptions, Layout};
use tessera::mesh::Mesh;
use tessera::pattern::uniform::Uniform;
use tessera::pattern::Pattern;
use tessera::surface::{BuildOptions, SurfaceSet};
use tessera_gpu::tessellator::Pipelines;
use tessera_gpu::{GpuContext, GpuTessellator};

/// One device for the whole binary (creating one per test costs time on lavapipe).
pub fn ctx() -> &'static GpuContext {
    static CTX: OnceLock<GpuContext> = OnceLock::new();
    CTX.get_or_init(|| match GpuContext::new() {
        Ok(c) => c,
        Err(e) => panic!("{e}"),
    })
}

/// One compiled pipeline set for the whole binary (a dozen WGSL compilations, seconds on
/// lavapipe).
pub fn pipelines() -> std::sync::Arc<Pipelines> {
    static PIPELINES: OnceLock<std::sync::Arc<Pipelines>> = OnceLock::new();
    PIPELINES.get_or_init(|| std::sync::Arc::new(Pipelines::new(&ctx().device))).clone()
}

/// A tessellator for `set` on the shared device and pipelines.
pub fn tessellator(set: &SurfaceSet) -> GpuTessellator {
    GpuTessellator::with_pipelines(ctx(), set, pipelines()).unwrap()
}

pub fn data_dir() -> PathBuf {
    std::env::var_os("TESSERA_DATA")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data"))
}

pub fn load(rel: &str) -> SurfaceSet {
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
pub fn mesh_models() -> Vec<String> {
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
pub fn patch_models() -> Vec<String> {
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

/// The tests' pseudo-random inputs, seeded: the library tests' generator.
pub use tessera::test_support::Lcg;

/// The CPU engine's layout and mesh for `plan`.
pub fn cpu(set: &SurfaceSet, plan: &Plan, pattern: &dyn Pattern) -> (Layout, Mesh) {
    let mut layout = Layout::default();
    layout.build(set, plan, pattern, &EngineOptions::default()).unwrap();
    let mesh = engine::tessellate(set, plan, pattern, EngineOptions::default()).unwrap();
    (layout, mesh)
}

pub fn diagonal(set: &SurfaceSet) -> f64 {
    let (lo, hi) = set.bounds();
    (hi - lo).length()
}

/// The GPU output of `plan` equals the CPU's: the layout's offsets, the triangles (the same
/// numbering, so index for index), positions within 1e-5 of the diagonal, normals within a
/// few degrees (a small step off a collapsed corner), the same watertightness report.
pub fn assert_gpu_equals_cpu(name: &str, set: &SurfaceSet, gpu: &mut GpuTessellator, plan: &Plan) {
    assert_pattern_equals_cpu(name, set, gpu, plan, &Uniform);
}

/// [`assert_gpu_equals_cpu`] for `pattern`.
pub fn assert_pattern_equals_cpu(
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
pub fn assert_gpu_equals_cpu_after_record(
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
        // Where the surface's first derivatives are parallel (a Loop boundary vertex of one
        // triangle: its two edges leave along one tangent), the normal is a limit: the CPU
        // takes it 1e-6 inside in f64, the GPU in f32 a step of 1e-4 or more inside, within
        // about 20° of it (measured up to 19.4° on pbrt's Killeroo cage).
        let degenerate = || {
            let p = want.vertex_patch[v] as usize;
            let uv = glam::DVec2::new(want.uvs[v][0] as f64, want.uvs[v][1] as f64);
            let d = set.patches[p].derivatives(uv);
            let scale = d.du.length_squared().max(d.dv.length_squared());
            d.du.cross(d.dv).length_squared() <= 1e-20 * scale * scale
        };
        assert!(dot > 0.99 || (dot > 0.94 && degenerate()), "{name}: normal {v} is {g:?}, the CPU's {w:?}");
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

/// the box, some far), looking near the centre, narrow and wide fields of view.
pub fn cameras(set: &SurfaceSet, count: usize, seed: u64) -> Vec<tessera::camera::Camera> {
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

/// Whether patch `p`'s culling for `camera` is within rounding of the other answer, so
/// that the GPU (f32) and the CPU (f64) may decide it differently: a frustum plane that
/// every control point but one is beyond, that one within 1e-5 of the scene's size of it
/// (`screen::PatchView::culled`'s control-point test), or the normal-cone test
/// (`screen::PatchView::back_facing`) within 1e-5 of its bound. Only explains differences;
/// the expected culled set is always the CPU's.
pub fn near_cull_tie(set: &SurfaceSet, p: usize, camera: &tessera::camera::Camera) -> bool {
    let view = camera.view();
    let patch = &set.patches[p];
    let scale = 1e-5 * (diagonal(set) + (camera.eye - set.bounds().0).length());
    let t = view.half_tangents;
    let (nx, ny) = ((1.0 + t.x * t.x).sqrt(), (1.0 + t.y * t.y).sqrt());
    // Signed distances, positive outside; a plane culls when every point is outside.
    let plane = |k: usize, c: glam::DVec3| match k {
        0 => view.near - c.z,
        1 => c.z - view.far,
        2 => (c.x - t.x * c.z) / nx,
        3 => (-c.x - t.x * c.z) / nx,
        4 => (c.y - t.y * c.z) / ny,
        _ => (-c.y - t.y * c.z) / ny,
    };
    let frustum_tie = (0..6).any(|k| {
        let least =
            patch.control_points().iter().map(|&q| plane(k, view.to_camera(q))).fold(f64::INFINITY, f64::min);
        least.abs() <= scale
    });
    let pv = tessera::criterion::screen::PatchView::new(patch);
    let cone_tie = pv.cone.is_some_and(|(axis, alpha)| {
        let to_eye = camera.eye - pv.centre;
        let dist = to_eye.length();
        let sin_b = (pv.radius / dist).min(1.0);
        let beta = sin_b.asin();
        let gamma = axis.dot(to_eye / dist).clamp(-1.0, 1.0).acos();
        (gamma - (std::f64::consts::FRAC_PI_2 + alpha + beta)).abs() <= 1e-5
            || (alpha + beta - std::f64::consts::FRAC_PI_2).abs() <= 1e-5
    });
    frustum_tie || cone_tie
}

/// Per-sweep tallies, reported at the end.
#[derive(Debug, Default)]
pub struct SweepCounts {
    pub frames: usize,
    pub culled: usize,
    /// Patches the GPU culled unlike the CPU, each a [`near_cull_tie`].
    pub cull_ties: usize,
    /// Uniform frames whose GPU factor, and transition edges whose GPU segments, differ from
    /// the CPU's at a rounding boundary.
    pub factor_ties: usize,
    /// Uniform frames whose factor the cap did not decide.
    pub below_cap: usize,
    /// Transition frames with more than one edge factor.
    pub strips: usize,
    /// Pixel-error transition frames (planned on the GPU with the a-posteriori check) whose
    /// plan differs from the CPU's with the same culled set. f32 rounding at a decision's
    /// boundary could cause one; the sweeps have seen none and allow none (the GPU plan's
    /// bounds are verified in f64 all the same).
    pub check_ties: usize,
    /// Pixel-error transition frames that needed fix rounds after the first check.
    pub check_rounds: usize,
    /// Patches whose ESC grid planned on the GPU differs from the CPU's at an f32 tie of the
    /// distance test ([`esc_frame_from_the_camera`]).
    pub esc_ties: usize,
}

/// The GPU's culled set against the CPU plan's: equal but for [`near_cull_tie`]s, which
/// are counted. Returns the GPU's row.
pub fn check_culling(
    name: &str,
    set: &SurfaceSet,
    gpu: &GpuTessellator,
    cpu_visible: &[u32],
    camera: &tessera::camera::Camera,
    counts: &mut SweepCounts,
) -> Vec<u32> {
    let visible = gpu.read_visible(ctx()).unwrap();
    let differ: Vec<usize> = (0..visible.len()).filter(|&p| visible[p] != cpu_visible[p]).collect();
    for &p in &differ {
        assert!(near_cull_tie(set, p, camera), "{name}: patch {p} culled unlike the CPU, and not at a tie");
    }
    counts.cull_ties += differ.len();
    counts.culled += cpu_visible.iter().filter(|&&v| v == 0).count();
    visible
}

pub fn all_models() -> Vec<String> {
    let mut models = patch_models();
    models.extend(mesh_models());
    models
}

/// `scheme`'s pixel-error frame for `camera` (the transition or the semi-uniform scheme) with
/// the error bound `bound`, planned on the GPU from the camera alone (culling, per-edge
/// factors, the a-posteriori check of `check.wgsl`) and recorded, against `scheme`'s plan on
/// the CPU with the same options:
///
/// - the culled set equals the CPU's but for counted [`near_cull_tie`]s ([`check_culling`]);
/// - the rounds converged within `DEFAULT_CHECK_ROUNDS`;
/// - every visible patch's bound from the GPU's check is the CPU library's on the GPU's plan
///   (`tolerance::checked_patch_bound`, f64) within 1e-4 relative (1e-3 with the expansion
///   bound), and the patch meets its tolerance
///   by the CPU's bound but for at most the patches the GPU reports failing (at the cap, as
///   the CPU reports them);
/// - with the same culled set, the plan (segments, interior factors), the fix rounds and the
///   capped patches equal the CPU's; a plan that differs is a counted `check_ties` frame.
///
/// Returns the GPU's plan, for comparing its output with the CPU engine's.
#[allow(clippy::too_many_arguments)]
pub fn checked_frame(
    scheme: tessera::scheme::Scheme,
    bound: tessera::scheme::ErrorBound,
    name: &str,
    set: &SurfaceSet,
    prepared: &tessera::scheme::Prepared,
    gpu: &mut GpuTessellator,
    camera: &tessera::camera::Camera,
    pixels: f64,
    cap: u32,
    counts: &mut SweepCounts,
) -> Plan {
    use tessera::scheme::{Criterion, PlanOptions};
    let ctx = ctx();
    let criterion = Criterion::PixelError(pixels);
    let options =
        PlanOptions { camera: Some(*camera), cull: true, max_factor: cap, bound, ..Default::default() };
    let cpu = scheme.plan_prepared(set, prepared, &criterion, &options).unwrap();
    let cpu_report = cpu.report.unwrap();
    let screen = tessera_gpu::tessellator::ScreenCriterion {
        bound,
        ..tessera_gpu::tessellator::ScreenCriterion::new(scheme, criterion, cap)
    };
    screen_frame(gpu, set, prepared, camera, screen);
    let visible = check_culling(name, set, gpu, &cpu.plan.visible, camera, counts);
    let drawn = gpu.read_plan(ctx).unwrap();
    assert_eq!(drawn.visible, visible);
    let report = gpu.read_screen_report(ctx).unwrap();
    assert!(report.converged, "{name}: the check's rounds did not converge ({report:?})");
    let view = camera.view();
    let views = prepared.views(set);
    let mut scratch = tessera::pattern::LocalTessellation::default();
    let gpu_bounds = gpu.read_check_bounds(ctx).unwrap();
    let missed = (0..set.patches.len())
        .filter(|&p| drawn.is_visible(p))
        .filter(|&p| {
            let eps = views[p].tolerance(&set.patches[p], &view, pixels, false).unwrap();
            let input = tessera::engine::layout::pattern_input(set, &drawn, p);
            let taylor = prepared.bounds_for(set, bound).map(|t| &t[p]);
            let errors = &prepared.triangle_errors()[p];
            let certified = tessera::criterion::tolerance::checked_patch_bound(
                errors,
                taylor,
                &input,
                &cpu.pattern,
                &mut scratch,
            );
            // The GPU's bound is the same bound over the same triangles, in f32. The
            // expansion bound's second differences of f32 control points lose more: a small
            // PN triangle's points are a thousand times its second differences.
            let gpu_bound = gpu_bounds[p] as f64;
            let close = if taylor.is_some() { 1e-3 } else { 1e-4 };
            assert!(
                (gpu_bound - certified).abs() <= close * certified + 1e-30,
                "{name}: patch {p}'s bound is {gpu_bound:e} on the GPU, {certified:e} on the CPU"
            );
            certified > eps * (1.0 + 1e-4)
        })
        .count();
    assert!(
        missed <= report.failing_patches as usize,
        "{name}: {missed} patches miss their bound, the GPU reports {}",
        report.failing_patches
    );
    if visible == cpu.plan.visible {
        if drawn.segments == cpu.plan.segments && drawn.interior == cpu.plan.interior {
            assert_eq!(report.rounds as usize, cpu_report.rounds, "{name}: fix rounds");
            assert_eq!(report.failing_patches as usize, cpu_report.capped_patches, "{name}: capped patches");
        } else {
            counts.check_ties += 1;
            eprintln!("{name}: the GPU's check decided unlike the CPU's");
        }
    }
    counts.check_rounds += (report.rounds > 0) as usize;
    drawn
}

/// Asserts that `plan`'s interior factors are those `rule` gives its segments within the cap
/// (`resolve::interiors`): what the GPU's interiors pass computes from the edges it planned.
pub fn assert_interiors_follow_the_edges(
    name: &str,
    set: &SurfaceSet,
    prepared: &tessera::scheme::Prepared,
    plan: &Plan,
    rule: tessera::criterion::resolve::InteriorRule,
    cap: u32,
) {
    let mut interior = Vec::new();
    tessera::criterion::resolve::interiors(
        set,
        &plan.segments,
        rule,
        &prepared.caps(cap as f64),
        &mut interior,
    );
    assert_eq!(plan.interior, interior, "{name}: interior factors");
}

/// An SD-2 frame from the camera: the level function or fixed factor, the warp, the cap.
#[derive(Debug, Clone, Copy)]
pub struct Sd2Frame {
    pub warp: bool,
    pub criterion: tessera::scheme::Criterion,
    pub max_factor: u32,
}

/// SD-2 planned on the GPU from `camera` alone (paper 001's level functions: the vertex
/// depths' range reduced on the GPU and mapped linearly or quadratically, or the vertices'
/// front/back classification; culling; the symmetric cut of each edge's real factor; with the
/// warp the edge depths) against `Scheme::Sd2`'s plan on the CPU: the culled set but for
/// [`near_cull_tie`]s, every real factor and depth within 1e-5 relative (f32 depths against
/// f64), the segments equal but where the CPU's factor lies within that of a whole number
/// (counted in `factor_ties`, one off), the interiors the largest edge's, never three
/// different factors in a triangle of the GPU's plan; then the frame's output equals the CPU
/// engine's for the plan drawn (the CPU's pattern: with the warp its corner depths are the
/// CPU's, within f32 rounding of the GPU's).
pub fn sd2_frame_from_the_camera(
    name: &str,
    set: &SurfaceSet,
    prepared: &tessera::scheme::Prepared,
    gpu: &mut GpuTessellator,
    camera: &tessera::camera::Camera,
    frame: Sd2Frame,
    counts: &mut SweepCounts,
) {
    use tessera::scheme::{PlanOptions, Scheme};
    let Sd2Frame { warp, criterion, max_factor } = frame;
    let scheme = Scheme::Sd2 { warp };
    let options = PlanOptions { camera: Some(*camera), cull: true, max_factor, ..Default::default() };
    let planned = scheme.plan_prepared(set, prepared, &criterion, &options).unwrap();
    let cpu = &planned.plan;
    let screen = tessera_gpu::tessellator::ScreenCriterion::new(scheme, criterion, max_factor);
    screen_frame(gpu, set, prepared, camera, screen);
    let drawn = gpu.read_plan(ctx()).unwrap();
    check_culling(name, set, gpu, &cpu.visible, camera, counts);
    let close = |got: f64, want: f64| (got - want).abs() <= 1e-5 * want;
    for e in 0..cpu.segments.len() {
        let (want, got) = (cpu.factors[e] as f64, drawn.factors[e] as f64);
        assert!(close(got, want), "{name}: edge {e} factor {got}, the CPU's {want}");
        if drawn.segments[e] != cpu.segments[e] {
            let tie = close(want.round(), want) && drawn.segments[e].abs_diff(cpu.segments[e]) == 1;
            assert!(
                tie,
                "{name}: edge {e} has {} segments, the CPU's {}",
                drawn.segments[e], cpu.segments[e]
            );
            counts.factor_ties += 1;
        }
    }
    assert_eq!(drawn.kind, cpu.kind, "{name}");
    assert_eq!(drawn.depths.len(), cpu.depths.len(), "{name}");
    for (e, (got, want)) in drawn.depths.iter().zip(&cpu.depths).enumerate() {
        let both = got.iter().zip(want).all(|(&g, &w)| close(g as f64, w as f64));
        assert!(both, "{name}: edge {e} depths {got:?}, the CPU's {want:?}");
    }
    assert_eq!(tessera::criterion::sd2::three_different(set, &drawn), 0, "{name}");
    let rule = tessera::criterion::resolve::InteriorRule::MaxEdge;
    assert_interiors_follow_the_edges(name, set, prepared, &drawn, rule, max_factor);
    assert_gpu_equals_cpu_after_record(name, set, gpu, &drawn, &planned.pattern);
    counts.frames += 1;
}

/// How far candidate `(i, j)` of bicubic patch `p` (a lattice point on a coarse edge, not a
/// coarse vertex) is from deciding the other way: `|V_B − V_S| − ρ` (equation (9)), or None
/// for a point inside a coarse triangle (decided by its row, not tested).
fn esc_margin(set: &SurfaceSet, p: usize, side: u32, (i, j): (u32, u32), rho: f64) -> Option<f64> {
    let tessera::surface::Patch::Bicubic(b) = &set.patches[p] else { return None };
    let n = side / 3;
    // The coarse edge through (i, j): a vertical or horizontal cell edge, or a cell diagonal,
    // from coarse vertex a; s the fraction along it.
    let (a, c, s) = if i % n == 0 && j % n != 0 {
        ((i, j / n * n), (i, j / n * n + n), j % n)
    } else if j % n == 0 && i % n != 0 {
        ((i / n * n, j), (i / n * n + n, j), i % n)
    } else if i % n == j % n && i % n != 0 {
        ((i / n * n, j / n * n), (i / n * n + n, j / n * n + n), i % n)
    } else {
        return None;
    };
    let s = s as f64 / n as f64;
    let point = |(x, y): (u32, u32)| b.point((x / n) as usize, (y / n) as usize);
    let mesh = point(a) * (1.0 - s) + point(c) * s;
    let uv = glam::DVec2::new(i as f64 / side as f64, j as f64 / side as f64);
    Some(b.position(uv).distance(mesh) - rho)
}

/// ESC planned on the GPU from `camera` alone (`esc_plan.wgsl`: each object's level, the
/// distance test on every candidate, the candidates forced at collapsed curves, the grids)
/// against `Scheme::Esc`'s plan on the CPU: the levels exactly, every patch's grid equal but
/// for f32 ties of the distance test (a patch whose grid differs must have a candidate within
/// 1e-5 of the diagonal of its threshold; counted in `differing`); then the frame equals the
/// CPU engine's on the GPU's own plan and grids, index for index. Returns the GPU's plan.
pub fn esc_frame_from_the_camera(
    name: &str,
    set: &SurfaceSet,
    prepared: &tessera::scheme::Prepared,
    gpu: &mut GpuTessellator,
    camera: &tessera::camera::Camera,
    criterion: tessera::scheme::Criterion,
    differing: &mut usize,
) -> Plan {
    use tessera::scheme::{Criterion, PlanOptions, Scheme, SchemePattern};
    let ctx = ctx();
    let scheme = Scheme::Esc { max_level: 3 };
    let screen = tessera_gpu::tessellator::ScreenCriterion::new(scheme, criterion, 64);
    screen_frame(gpu, set, prepared, camera, screen);
    let plan = gpu.read_plan(ctx).unwrap();
    let esc = gpu.read_esc_pattern(ctx).unwrap();
    let options = PlanOptions { camera: Some(*camera), ..Default::default() };
    let cpu = scheme.plan(set, &criterion, &options).unwrap();
    assert_eq!(plan.interior, cpu.plan.interior, "{name}: levels");
    let (Criterion::Esc { threshold, .. }, SchemePattern::Esc(cpu_esc)) = (criterion, &cpu.pattern) else {
        unreachable!("ESC's criterion and pattern")
    };
    let objects = tessera::criterion::esc::Objects::of(set);
    let d = diagonal(set);
    for p in 0..set.patches.len() {
        let (g, w) = (esc.grid(p), cpu_esc.grid(p));
        if g == w {
            continue;
        }
        *differing += 1;
        let side = g.side();
        let (lo, hi) = objects.boxes[objects.component[p] as usize];
        let rho = threshold.rho(lo.distance(hi));
        let margin = (0..=side)
            .flat_map(|j| (0..=side).map(move |i| (i, j)))
            .filter_map(|ij| esc_margin(set, p, side, ij, rho))
            .map(f64::abs)
            .fold(f64::INFINITY, f64::min);
        assert!(margin <= 1e-5 * d, "{name}: patch {p}'s grid differs with no tie (margin {margin})");
    }
    assert_gpu_equals_cpu_after_record(name, set, gpu, &plan, &esc);
    plan
}

/// Records one frame of `gpu`'s prepared work and submits it.
pub fn record_frame(gpu: &GpuTessellator) {
    let ctx = ctx();
    let mut encoder = ctx.device.create_command_encoder(&Default::default());
    gpu.record(&mut encoder);
    ctx.queue.submit([encoder.finish()]);
}

/// Plans `screen` on the GPU from `camera` (`prepare_screen`) and records that frame.
pub fn screen_frame(
    gpu: &mut GpuTessellator,
    set: &SurfaceSet,
    prepared: &tessera::scheme::Prepared,
    camera: &tessera::camera::Camera,
    screen: tessera_gpu::tessellator::ScreenCriterion,
) {
    gpu.prepare_screen(ctx(), set, prepared, camera, screen).unwrap();
    record_frame(gpu);
}

/// `set` with its PN triangles replaced by their cubic Bézier geometry (normals then come
/// from the derivatives).
pub fn as_bezier_triangles(pn: &SurfaceSet) -> SurfaceSet {
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

/// Records `gpu`'s frame until it fits: after an overflow, `grow_if_overflowed` grows the
/// output and the frame is recorded again (at most twice). Returns how often it grew.
pub fn record_until_complete(gpu: &mut GpuTessellator, name: &str) -> u32 {
    let mut grown = 0;
    loop {
        record_frame(gpu);
        if !gpu.grow_if_overflowed(ctx()).unwrap() {
            return grown;
        }
        grown += 1;
        assert!(grown <= 2, "{name}: still overflowing after {grown} growths");
    }
}

/// A camera inside the model's box looking at its centre: close patches drive a fine
/// pixel error to the cap.
pub fn close_camera(set: &SurfaceSet) -> tessera::camera::Camera {
    let (lo, hi) = set.bounds();
    let centre = (lo + hi) * 0.5;
    let radius = (hi - lo).length() * 0.5;
    tessera::camera::Camera {
        eye: centre + glam::DVec3::new(0.3, -0.5, 0.4) * radius,
        target: centre,
        up: glam::DVec3::Z,
        fov_y_degrees: 70.0,
        width: 1280,
        height: 1024,
        near: radius * 1e-3,
        far: radius * 10.0,
    }
}

/// Every model (`all_models`), split into those up to 1.5 MB and the three meshes past it
/// (over 40,000 patches), which the slow sweeps run with fewer cameras: `(rest, large)`.
pub fn models_by_size() -> (Vec<String>, Vec<String>) {
    let (large, rest): (Vec<String>, Vec<String>) = all_models()
        .into_iter()
        .partition(|m| std::fs::metadata(data_dir().join(m)).unwrap().len() > 1_500_000);
    (rest, large)
}

impl SweepCounts {
    /// Adds the tallies of `other`, another part of the same sweep.
    pub fn add(&mut self, other: &SweepCounts) {
        self.frames += other.frames;
        self.culled += other.culled;
        self.cull_ties += other.cull_ties;
        self.factor_ties += other.factor_ties;
        self.below_cap += other.below_cap;
        self.strips += other.strips;
        self.check_ties += other.check_ties;
        self.check_rounds += other.check_rounds;
        self.esc_ties += other.esc_ties;
    }
}
