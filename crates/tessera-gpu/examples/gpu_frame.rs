//! Per-pass GPU times of the uniform GPU engine on a patch model.
//!
//! `cargo run --release -p tessera-gpu --example gpu_frame -- MODEL.patches [FACTOR] [FRAMES]
//! [--copies N] [--cull]`
//!
//! `--copies N` tessellates N copies of the model side by side in a square grid (45 copies of
//! `bench/torus_64x32.patches` are the 92,160-patch scene of the real-time CPU issue);
//! `--cull` makes the GPU cull for a 1280×1024 camera framing the whole scene.
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

/// `copies` copies of `set`'s patches in a square grid, 1.2 box sizes apart.
fn grid_of_copies(set: &SurfaceSet, copies: usize) -> SurfaceSet {
    let (lo, hi) = set.bounds();
    let step = (hi - lo) * 1.2;
    let side = (copies as f64).sqrt().ceil() as usize;
    let mut patches = Vec::with_capacity(copies * set.patches.len());
    for c in 0..copies {
        let offset = glam::DVec3::new((c % side) as f64 * step.x, (c / side) as f64 * step.y, 0.0);
        for patch in &set.patches {
            let mut patch = patch.clone();
            if let tessera::surface::Patch::Bicubic(b) = &mut patch {
                b.points.iter_mut().for_each(|p| *p += offset);
            }
            patches.push(patch);
        }
    }
    SurfaceSet::from_patches(patches, BuildOptions::default())
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args: Vec<String> = std::env::args().collect();
    let cull = args.iter().any(|a| a == "--cull");
    args.retain(|a| a != "--cull");
    let mut copies = 1usize;
    if let Some(i) = args.iter().position(|a| a == "--copies") {
        copies = args.get(i + 1).ok_or("--copies needs a number")?.parse()?;
        args.drain(i..i + 2);
    }
    let path = args.get(1).ok_or("usage: gpu_frame MODEL.patches [FACTOR] [FRAMES] [--copies N] [--cull]")?;
    let factor: u32 = args.get(2).map_or(Ok(16), |s| s.parse())?;
    let frames: usize = args.get(3).map_or(Ok(10), |s| s.parse())?;
    let file = tessera::io::patches::read_patches(std::path::Path::new(path))?;
    let one = SurfaceSet::from_patch_file(&file, BuildOptions::default());
    let set = if copies > 1 { grid_of_copies(&one, copies) } else { one };
    let ctx = GpuContext::new()?;
    println!("adapter: {} ({:?}, {})", ctx.info.name, ctx.info.backend, ctx.info.driver_info);
    let mut gpu = GpuTessellator::new(&ctx, &set)?;
    if cull {
        let (lo, hi) = set.bounds();
        gpu.set_cull_camera(&ctx, Some(&tessera::camera::Camera::framing(lo, hi, 1280, 1024)));
    }
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
        "{path} x{copies}: {} patches, factor {factor}{}: {vertices} vertices, {triangles} triangles{}",
        set.patches.len(),
        if cull { ", culled on the GPU" } else { "" },
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
