//! Per-level timings of the instanced semi-uniform draw (paper 000, methods E–H of Table 1):
//! for each level m, every patch of the model at level m (the semi-uniform scheme at factor
//! 2^m, so one queue holds every patch), the whole GPU frame — render queues (count, scan,
//! scatter), level arguments, the instanced draws — timed as wall time of submit to
//! finished, median of FRAMES frames; then an adaptive frame (silhouetteness, as the paper).
//!
//! `cargo run --release -p tessera-render --example instanced_levels -- [MODEL] [FRAMES]`
//! (default `$TESSERA_DATA/meshes/spool.obj` as PN triangles, 20 frames; 1280x720, MSAA 1).

use std::path::{Path, PathBuf};
use std::time::Instant;
use tessera::camera::Camera;
use tessera::criterion::view::ViewCriterion;
use tessera::scheme::{Criterion, PlanOptions, Scheme};
use tessera_render::instanced::InstancedDraw;
use tessera_render::{gpu, RenderOptions};

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v[v.len() / 2]
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let model = args.get(1).map(PathBuf::from).unwrap_or_else(|| {
        let data = std::env::var("TESSERA_DATA").unwrap_or_else(|_| "../shared/data".into());
        Path::new(&data).join("meshes/spool.obj")
    });
    let frames: usize = args.get(2).map_or(Ok(20), |s| s.parse())?;
    let max_level = 5;
    let set = tessera::io::load(&model, tessera::io::LoadOptions::default())?;
    let (lo, hi) = set.bounds();
    let camera = Camera::framing(lo, hi, 1280, 720);
    let ctx = tessera_gpu::GpuContext::new()?;
    let draw = InstancedDraw::new(&ctx, &set, max_level, gpu::IMAGE_FORMAT, 1)?;
    let renderer = gpu::Renderer::new(&ctx, gpu::IMAGE_FORMAT, 1)?;
    let targets = gpu::Targets::new(&ctx, &renderer, 1280, 720)?;
    let (colour, resolve, depth) = targets.views();
    let look = RenderOptions { wireframe: false, color: tessera_render::ColorMode::Level };
    let scheme = Scheme::SemiUniform { max_level };
    println!("{}: {} patches, adapter {}, 1280x720", model.display(), set.patches.len(), ctx.info.name);
    let run = |criterion: Criterion, what: String| -> Result<(), Box<dyn std::error::Error>> {
        let options = PlanOptions { camera: Some(camera), ..Default::default() };
        let planned = scheme.plan(&set, &criterion, &options)?;
        let mut times = Vec::new();
        for _ in 0..frames.max(1) {
            let start = Instant::now();
            let mut encoder = ctx.device.create_command_encoder(&Default::default());
            draw.record(
                &ctx,
                &mut encoder,
                &planned.plan,
                &camera,
                &look,
                &colour,
                resolve.as_ref(),
                &depth,
            )?;
            ctx.queue.submit([encoder.finish()]);
            ctx.wait()?;
            times.push(start.elapsed().as_secs_f64() * 1e3);
        }
        let queues = draw.queues().read(&ctx)?;
        let triangles: usize = (0..=max_level)
            .map(|m| queues.level(m).len() * draw.patterns()[m as usize].triangles.len())
            .sum();
        let ms = median(times);
        println!(
            "  {what:<28} {:>8} triangles drawn  {ms:8.2} ms  {:8.1} Mtri/s  ({} fps)",
            triangles,
            triangles as f64 / ms / 1e3,
            (1e3 / ms).round()
        );
        Ok(())
    };
    for m in 0..=max_level {
        run(Criterion::Factor((1u32 << m) as f64), format!("level {m} (every patch)"))?;
    }
    let silhouette = Criterion::View { criterion: ViewCriterion::Silhouetteness, fmin: 1.0, fmax: 32.0 };
    run(silhouette, "adaptive (silhouetteness)".into())?;
    Ok(())
}
