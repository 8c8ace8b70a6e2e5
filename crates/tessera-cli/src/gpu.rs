//! `tessera mesh --engine gpu`: a frame tessellated by tessera-gpu and read back, with the
//! GPU's per-pass times for `--stats`. Where the GPU plans the frame itself from the camera
//! (what `tessera::scheme::validate` accepts for `Engine::GpuFromCamera`), it does: the whole
//! CudaTess frame on the GPU; otherwise it tessellates the plan the CPU chose.

use tessera::camera::Camera;
use tessera::criterion::Plan;
use tessera::mesh::Mesh;
use tessera::scheme::{validate, Criterion, Engine, PlanOptions, Prepared, Scheme, SchemePattern};
use tessera::surface::SurfaceSet;
use tessera_gpu::tessellator::{Capacity, PassTimer, ScreenCriterion, PASSES};
use tessera_gpu::{GpuContext, GpuError, GpuTessellator, ScreenReport};

/// What a GPU run gives back beside the mesh.
pub struct GpuRun {
    /// Median per-pass GPU times in ms (empty without timestamp queries).
    pub passes_ms: Vec<(&'static str, f64)>,
    /// The adapter's name.
    pub adapter: String,
    /// Set when the GPU planned the frame from the camera: its a-posteriori check's report.
    pub screen: Option<ScreenReport>,
    /// The patches the GPU culled, when it planned the frame (0 otherwise: the CPU's plan
    /// says).
    pub culled: usize,
}

/// The frame the GPU plans from the camera alone for `scheme` under `criterion` and
/// `options`, where it plans that request (`tessera::scheme::validate` for
/// [`Engine::GpuFromCamera`]: culling on, and a pairing `prepare_screen` takes).
pub fn screen_criterion(
    set: &SurfaceSet,
    scheme: Scheme,
    criterion: &Criterion,
    options: &PlanOptions,
) -> Option<ScreenCriterion> {
    validate(scheme, criterion, options, set, Engine::GpuFromCamera).ok()?;
    Some(ScreenCriterion {
        bound: options.bound,
        ..ScreenCriterion::new(scheme, *criterion, options.max_factor)
    })
}

/// Plans and tessellates the frame of `camera` on the GPU `repeat` times (frames, from the
/// camera alone: nothing goes to the GPU between them), reads the last one back into `mesh`
/// and returns the per-pass times and wall times (seconds, submit to finished) and the
/// check's report. With `strips`, the GPU writes the strips of SD-2 and ESC too
/// (`Mesh::strips`).
pub fn tessellate_from_camera(
    set: &SurfaceSet,
    camera: &Camera,
    screen: ScreenCriterion,
    output: Output,
    repeat: u32,
    mesh: &mut Mesh,
    times: &mut Vec<f64>,
) -> Result<GpuRun, GpuError> {
    let Output { strips, corner_params } = output;
    let ctx = GpuContext::new()?;
    let mut gpu = GpuTessellator::new(&ctx, set)?;
    let prepared = Prepared::new(set, true);
    // One frame, not a loop: room for the frame's likely size, grown to what it needs after
    // an overflow (one read-back), rather than buffers for the worst case a camera could
    // ask, which for a large set is the device's whole buffer limit.
    let screen = ScreenCriterion { capacity: screen.capacity.or(Some(FIRST_ROOM)), ..screen };
    gpu.prepare_screen(&ctx, set, &prepared, camera, screen)?;
    start_strips(&ctx, &mut gpu, strips)?;
    let mut run = frames(&ctx, &mut gpu, repeat, times)?;
    // The first room (triangles, then strips) too small: grown to what the frame needed.
    for _ in 0..2 {
        if !gpu.grow_if_overflowed(&ctx)? {
            break;
        }
        run = frames(&ctx, &mut gpu, repeat, times)?;
    }
    *mesh = gpu.read_mesh(&ctx, set)?;
    run.screen = Some(gpu.read_screen_report(&ctx)?);
    run.culled = gpu.read_visible(&ctx)?.iter().filter(|&&v| v == 0).count();
    if corner_params {
        // The plan the GPU drew and its pattern, for the CPU's rule of the parameters: ESC's
        // insertion grids read back, the warped SD-2's corner depths from the camera.
        let plan = gpu.read_plan(&ctx)?;
        let pattern = match screen.scheme {
            Scheme::Esc { .. } => SchemePattern::Esc(gpu.read_esc_pattern(&ctx)?),
            scheme => match scheme.fixed_pattern() {
                Some(pattern) => pattern,
                None => {
                    let options = PlanOptions {
                        camera: Some(*camera),
                        cull: true,
                        max_factor: screen.max_factor,
                        ..PlanOptions::default()
                    };
                    scheme.plan(set, &screen.criterion, &options)?.pattern
                }
            },
        };
        add_corner_params(set, &plan, &pattern, mesh)?;
    }
    Ok(run)
}

/// What a GPU frame's read-back holds beside its triangles.
#[derive(Debug, Clone, Copy)]
pub struct Output {
    /// The strips of SD-2 and ESC (`Mesh::strips`).
    pub strips: bool,
    /// The per-corner patch parameters (`Mesh::corner_params`, a `.ply`'s `patch_uv`).
    pub corner_params: bool,
}

impl Output {
    /// The triangles and vertices only.
    pub const TRIANGLES: Output = Output { strips: false, corner_params: false };
}

/// Gives `mesh`, the GPU's frame of `plan` under `pattern`, its per-corner patch parameters:
/// the GPU writes the CPU engine's triangles index for index, so the CPU's rule gives them
/// (`tessera::engine::corner_params`, no evaluation).
fn add_corner_params(
    set: &SurfaceSet,
    plan: &Plan,
    pattern: &dyn tessera::pattern::Pattern,
    mesh: &mut Mesh,
) -> Result<(), tessera::Error> {
    let mut layout = tessera::engine::layout::Layout::default();
    let options = tessera::engine::EngineOptions { corner_params: true, ..Default::default() };
    layout.build(set, plan, pattern, &options)?;
    mesh.corner_params = Some(tessera::engine::corner_params(set, plan, pattern, &layout));
    Ok(())
}

/// The output room a frame planned on the GPU starts with (`tessellate_from_camera`):
/// 4 M triangles, about 110 MB of vertex and index buffers.
const FIRST_ROOM: Capacity = Capacity { vertices: 2 << 20, triangles: 4 << 20 };

/// Records `repeat` frames of `gpu`'s prepared work, timing each; with more than one, after
/// an untimed warm-up frame (drivers compile pipelines and fault buffers in at first use).
fn frames(
    ctx: &GpuContext,
    gpu: &mut GpuTessellator,
    repeat: u32,
    times: &mut Vec<f64>,
) -> Result<GpuRun, GpuError> {
    times.clear();
    if repeat > 1 {
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        gpu.record(&mut encoder);
        ctx.queue.submit([encoder.finish()]);
        ctx.wait()?;
    }
    let timer = PassTimer::new(ctx);
    let mut per_pass = vec![Vec::new(); PASSES.len()];
    for _ in 0..repeat.max(1) {
        let start = std::time::Instant::now();
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        gpu.record_timed(&mut encoder, timer.as_ref());
        ctx.queue.submit([encoder.finish()]);
        ctx.wait()?;
        times.push(start.elapsed().as_secs_f64());
        if let Some(t) = &timer {
            for (i, (_, ms)) in t.read(ctx)?.into_iter().enumerate() {
                per_pass[i].push(ms);
            }
        }
    }
    let passes_ms = if timer.is_some() {
        PASSES.iter().zip(per_pass).map(|(&name, times)| (name, super::median(times))).collect()
    } else {
        Vec::new()
    };
    Ok(GpuRun { passes_ms, adapter: ctx.info.name.clone(), screen: None, culled: 0 })
}

/// Tessellates `plan` on the GPU `repeat` times (frames), reads the last one back into
/// `mesh` and returns the per-pass times and wall times (seconds, submit to finished). With
/// `strips`, the GPU writes the strips of SD-2 and ESC too (`Mesh::strips`).
pub fn tessellate(
    set: &SurfaceSet,
    plan: &Plan,
    pattern: &dyn tessera::pattern::Pattern,
    output: Output,
    repeat: u32,
    mesh: &mut Mesh,
    times: &mut Vec<f64>,
) -> Result<GpuRun, GpuError> {
    let Output { strips, corner_params } = output;
    let ctx = GpuContext::new()?;
    let mut gpu = GpuTessellator::new(&ctx, set)?;
    gpu.prepare(&ctx, set, plan, pattern)?;
    start_strips(&ctx, &mut gpu, strips)?;
    let mut run = frames(&ctx, &mut gpu, repeat, times)?;
    // The strips' first room too small (the triangles' is the plan's worst case): grown.
    if gpu.grow_if_overflowed(&ctx)? {
        run = frames(&ctx, &mut gpu, repeat, times)?;
    }
    *mesh = gpu.read_mesh(&ctx, set)?;
    if corner_params {
        add_corner_params(set, plan, pattern, mesh)?;
    }
    Ok(run)
}

/// Turns `gpu`'s strip output on when `strips` asks for it, with room for twice the
/// triangles it has room for (SD-2's strips take about one entry a triangle, ESC's more
/// where candidates are missing; a frame that needs more grows once).
fn start_strips(ctx: &GpuContext, gpu: &mut GpuTessellator, strips: bool) -> Result<(), GpuError> {
    if !strips {
        return Ok(());
    }
    let triangles = gpu.capacity().map_or(0, |c| c.triangles);
    gpu.set_strips(ctx, Some(2 * triangles + 1024))
}
