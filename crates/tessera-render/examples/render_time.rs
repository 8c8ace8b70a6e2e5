//! How long a picture takes: the renderer's steady-state frame (pipelines and targets made
//! once) and the CPU fallback rasteriser, on a model tessellated once.
//!
//! `cargo run --release -p tessera-render --example render_time -- [MODEL] [WxH] [PIXEL_ERROR]
//! [FRAMES]` (defaults: `$TESSERA_DATA/patches/teapot.patches`, 1280x720, 0.5, 20). Prints
//! the medians of: the draw alone (submit to finished, MSAA 4, shaded with the wireframe),
//! the draw with the image read back, and the CPU rasteriser.

use std::path::{Path, PathBuf};
use std::time::Instant;
use tessera::camera::Camera;
use tessera::scheme::{Criterion, PlanOptions, Scheme};
use tessera::tessellator::{Tessellator, TessellatorOptions};
use tessera_render::{gpu, RenderOptions};

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v[v.len() / 2]
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let model = args.get(1).map(PathBuf::from).unwrap_or_else(|| {
        let data = std::env::var("TESSERA_DATA").unwrap_or_else(|_| "../shared/data".into());
        Path::new(&data).join("patches/teapot.patches")
    });
    let (w, h) = args
        .get(2)
        .and_then(|s| s.split_once('x'))
        .map_or(Ok((1280, 720)), |(w, h)| Ok::<_, std::num::ParseIntError>((w.parse()?, h.parse()?)))?;
    let pixel_error: f64 = args.get(3).map_or(Ok(0.5), |s| s.parse())?;
    let frames: usize = args.get(4).map_or(Ok(20), |s| s.parse())?;
    let set = tessera::io::load(&model, tessera::io::LoadOptions::default())?;
    let (lo, hi) = set.bounds();
    let camera = Camera::framing(lo, hi, w, h);
    let criterion = Criterion::PixelError(pixel_error);
    let options = TessellatorOptions {
        plan: PlanOptions { camera: Some(camera), ..Default::default() },
        engine: Default::default(),
    };
    let mut tess = Tessellator::new(&set, Scheme::default_for(&criterion), criterion, options)?;
    let mesh = tess.frame(Some(&camera))?.clone();
    let ctx = tessera_gpu::GpuContext::new()?;
    let buffers = gpu::MeshBuffers::upload(&ctx, &mesh, &[])?;
    let renderer = gpu::Renderer::new(&ctx, gpu::IMAGE_FORMAT, 4)?;
    let targets = gpu::Targets::new(&ctx, &renderer, w, h)?;
    let look = RenderOptions { wireframe: true, color: tessera_render::ColorMode::Shaded };
    let (mut draw, mut with_read, mut cpu) = (Vec::new(), Vec::new(), Vec::new());
    for _ in 0..frames.max(1) {
        let start = Instant::now();
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        targets.draw(&ctx, &renderer, &mut encoder, &buffers.geometries(), &camera, &look)?;
        ctx.queue.submit([encoder.finish()]);
        ctx.wait()?;
        draw.push(start.elapsed().as_secs_f64() * 1e3);
        let image = targets.read(&ctx)?;
        with_read.push(start.elapsed().as_secs_f64() * 1e3);
        assert!(image.covered_pixels() > 0);
        let start = Instant::now();
        let _ = tessera_render::cpu::render(&mesh, &camera, &look, &[]);
        cpu.push(start.elapsed().as_secs_f64() * 1e3);
    }
    println!(
        "{}: {} triangles at {w}x{h} ({pixel_error} px), adapter {}",
        model.display(),
        mesh.triangle_count(),
        ctx.info.name
    );
    println!(
        "  wgpu draw (MSAA 4, wireframe), submit to finished: {:.1} ms (median of {frames})",
        median(draw)
    );
    println!("  wgpu draw + image read-back:                     {:.1} ms", median(with_read));
    println!("  CPU fallback rasteriser (1 sample):              {:.1} ms", median(cpu));
    Ok(())
}
