//! `tessera mesh --engine gpu`: a frame tessellated by tessera-gpu and read back, with the
//! GPU's per-pass times for `--stats`. Where the GPU plans the frame itself from the camera
//! (culling on, a criterion and scheme `GpuTessellator::prepare_screen` takes), it does:
//! the whole CudaTess frame on the GPU; otherwise it tessellates the plan the CPU chose.

use tessera::camera::Camera;
use tessera::criterion::view::ViewCriterion;
use tessera::criterion::Plan;
use tessera::mesh::Mesh;
use tessera::scheme::{Criterion, Prepared, Scheme};
use tessera::surface::SurfaceSet;
use tessera_gpu::tessellator::{PassTimer, ScreenCriterion, PASSES};
use tessera_gpu::{GpuContext, GpuError, GpuTessellator, ScreenReport};

/// What a GPU run gives back beside the mesh.
pub struct GpuRun {
    /// Median per-pass GPU times in ms (empty without timestamp queries).
    pub passes_ms: Vec<(&'static str, f64)>,
    /// The adapter's name.
    pub adapter: String,
    /// Set when the GPU planned the frame from the camera: its a-posteriori check's report.
    pub screen: Option<ScreenReport>,
}

/// The frame the GPU plans from `camera` alone for `scheme` under `criterion`, if it can:
/// culling on (the GPU always culls what it plans) and a pairing `prepare_screen` takes (a
/// pixel error with the uniform or transition scheme, silhouetteness with those or a hardware
/// partitioning, a fixed real factor with a hardware partitioning).
pub fn screen_criterion(
    scheme: Scheme,
    criterion: &Criterion,
    cull: bool,
    max_factor: u32,
) -> Option<ScreenCriterion> {
    let on_gpu = matches!(
        (scheme, criterion),
        (Scheme::Uniform | Scheme::Transition, Criterion::PixelError(_))
            | (
                Scheme::Uniform | Scheme::Transition | Scheme::Hardware(_),
                Criterion::View { criterion: ViewCriterion::Silhouetteness, .. }
            )
            | (Scheme::Hardware(_), Criterion::Factor(_))
    );
    // The GPU's a-posteriori check takes caps up to CHECK_MAX_FACTOR; the CPU plans the rest.
    let checked = scheme == Scheme::Transition && matches!(criterion, Criterion::PixelError(_));
    let within = !checked || max_factor <= tessera_gpu::tessellator::CHECK_MAX_FACTOR;
    (cull && on_gpu && within).then_some(ScreenCriterion {
        scheme,
        criterion: *criterion,
        max_factor,
        capacity: None,
    })
}

/// Plans and tessellates the frame of `camera` on the GPU `repeat` times (frames, from the
/// camera alone: nothing goes to the GPU between them), reads the last one back into `mesh`
/// and returns the per-pass times and wall times (seconds, submit to finished) and the
/// check's report.
pub fn tessellate_from_camera(
    set: &SurfaceSet,
    camera: &Camera,
    screen: ScreenCriterion,
    repeat: u32,
    mesh: &mut Mesh,
    times: &mut Vec<f64>,
) -> Result<GpuRun, GpuError> {
    let ctx = GpuContext::new()?;
    let mut gpu = GpuTessellator::new(&ctx, set)?;
    let prepared = Prepared::new(set, true);
    gpu.prepare_screen(&ctx, set, &prepared, camera, screen)?;
    let mut run = frames(&ctx, &mut gpu, repeat, times)?;
    if gpu.grow_if_overflowed(&ctx)? {
        // Sized within the device's limits below the worst case: grown to what it needed.
        run = frames(&ctx, &mut gpu, repeat, times)?;
    }
    *mesh = gpu.read_mesh(&ctx, set)?;
    run.screen = Some(gpu.read_screen_report(&ctx)?);
    Ok(run)
}

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
    Ok(GpuRun { passes_ms, adapter: ctx.info.name.clone(), screen: None })
}

/// Tessellates `plan` on the GPU `repeat` times (frames), reads the last one back into
/// `mesh` and returns the per-pass times and wall times (seconds, submit to finished).
pub fn tessellate(
    set: &SurfaceSet,
    plan: &Plan,
    pattern: &dyn tessera::pattern::Pattern,
    repeat: u32,
    mesh: &mut Mesh,
    times: &mut Vec<f64>,
) -> Result<GpuRun, GpuError> {
    let ctx = GpuContext::new()?;
    let mut gpu = GpuTessellator::new(&ctx, set)?;
    gpu.prepare(&ctx, set, plan, pattern)?;
    let run = frames(&ctx, &mut gpu, repeat, times)?;
    *mesh = gpu.read_mesh(&ctx, set)?;
    Ok(run)
}
