//! Per-pass GPU times of the uniform GPU engine on a patch model.
//!
//! `cargo run --release -p tessera-gpu --example gpu_frame -- MODEL.patches [FACTOR] [FRAMES]`
//!
//! Records FRAMES frames (default 10) at FACTOR (default 16) and prints, per pass, the median
//! of the timestamp-query times when the adapter has them; otherwise the median wall time of
//! a whole frame around `submit` + `poll(wait)`. Statistics are read back after each frame,
//! outside what a frame loop would do.

use std::time::Instant;
use tessera::criterion::Plan;
use tessera::surface::{BuildOptions, SurfaceSet};
use tessera_gpu::tessellator::{PassTimer, PASSES};
use tessera_gpu::{GpuContext, GpuTessellator};

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v[v.len() / 2]
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let path = args.get(1).ok_or("usage: gpu_frame MODEL.patches [FACTOR] [FRAMES]")?;
    let factor: u32 = args.get(2).map_or(Ok(16), |s| s.parse())?;
    let frames: usize = args.get(3).map_or(Ok(10), |s| s.parse())?;
    let file = tessera::io::patches::read_patches(std::path::Path::new(path))?;
    let set = SurfaceSet::from_patch_file(&file, BuildOptions::default());
    let ctx = GpuContext::new()?;
    println!("adapter: {} ({:?}, {})", ctx.info.name, ctx.info.backend, ctx.info.driver_info);
    let mut gpu = GpuTessellator::new(&ctx, &set)?;
    let plan = Plan::uniform(&set, factor)?;
    gpu.prepare(&ctx, &set, &plan, &tessera::pattern::uniform::Uniform)?;
    let timer = PassTimer::new(&ctx);
    let mut per_pass = vec![Vec::new(); PASSES.len()];
    let mut wall = Vec::new();
    for _ in 0..frames.max(1) {
        let start = Instant::now();
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        gpu.record_timed(&mut encoder, timer.as_ref());
        ctx.queue.submit([encoder.finish()]);
        ctx.wait()?;
        wall.push(start.elapsed().as_secs_f64() * 1e3);
        if let Some(t) = &timer {
            for (i, (_, ms)) in t.read(&ctx)?.into_iter().enumerate() {
                per_pass[i].push(ms);
            }
        }
    }
    let (overflow, vertices, triangles) = gpu.read_status(&ctx)?;
    println!(
        "{path}: {} patches, factor {factor}: {vertices} vertices, {triangles} triangles{}",
        set.patches.len(),
        if overflow { " (OVERFLOW)" } else { "" }
    );
    let frame = median(wall.clone());
    if timer.is_some() {
        let mut total = 0.0;
        for (name, times) in PASSES.iter().zip(per_pass) {
            let ms = median(times);
            total += ms;
            println!("  {name:<10} {ms:9.3} ms");
        }
        println!("  {:<10} {total:9.3} ms (GPU, sum of passes)", "total");
    } else {
        println!("  (no timestamp queries on this adapter: wall time of whole frames only)");
    }
    println!("  frame wall time (submit + wait), median of {}: {frame:.3} ms", wall.len());
    println!("  {:.3} Gtri/s by wall time", triangles as f64 / (frame * 1e-3) / 1e9);
    Ok(())
}
