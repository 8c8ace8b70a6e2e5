//! `tessera mesh --engine gpu`: the plan the CPU chose, tessellated by tessera-gpu and read
//! back, with the GPU's per-pass times for `--stats`.

use tessera::criterion::Plan;
use tessera::mesh::Mesh;
use tessera::surface::SurfaceSet;
use tessera_gpu::tessellator::{PassTimer, PASSES};
use tessera_gpu::{GpuContext, GpuTessellator};

/// What a GPU run gives back beside the mesh.
pub struct GpuRun {
    /// Median per-pass GPU times in ms (empty without timestamp queries).
    pub passes_ms: Vec<(&'static str, f64)>,
    /// The adapter's name.
    pub adapter: String,
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
) -> Result<GpuRun, tessera_gpu::GpuError> {
    let ctx = GpuContext::new()?;
    let mut gpu = GpuTessellator::new(&ctx, set)?;
    gpu.prepare(&ctx, set, plan, pattern)?;
    let timer = PassTimer::new(&ctx);
    let mut per_pass = vec![Vec::new(); PASSES.len()];
    for _ in 0..repeat.max(1) {
        let start = std::time::Instant::now();
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        gpu.record_timed(&mut encoder, timer.as_ref());
        ctx.queue.submit([encoder.finish()]);
        ctx.wait()?;
        times.push(start.elapsed().as_secs_f64());
        if let Some(t) = &timer {
            for (i, (_, ms)) in t.read(&ctx)?.into_iter().enumerate() {
                per_pass[i].push(ms);
            }
        }
    }
    *mesh = gpu.read_mesh(&ctx, set)?;
    let passes_ms = if timer.is_some() {
        PASSES.iter().zip(per_pass).map(|(&name, times)| (name, super::median(times))).collect()
    } else {
        Vec::new()
    };
    Ok(GpuRun { passes_ms, adapter: ctx.info.name.clone() })
}
