//! Per-pass GPU times of the GPU engine on a patch model.
//!
//! `cargo run --release -p tessera-gpu --example gpu_frame -- MODEL.patches [FACTOR] [FRAMES]
//! [--copies N] [--cull] [--pixel-error PX [--max-factor N] [--transition [--cpu-plan]]]
//! [--silhouetteness FMAX] [--hardware PARTITIONING]`
//!
//! `--copies N` tessellates N copies of the model in a grid (`tessera::scene::patch_grid`;
//! 45 copies of `bench/torus_64x32.patches` are the 92,160-patch scene of the real-time CPU
//! issue); `--cull` makes the GPU cull for a 1280×1024 camera framing the whole scene.
//! By default the frame is the uniform pattern at FACTOR (default 16) from a CPU plan.
//! `--pixel-error PX` plans the frame on the GPU from that camera alone (culling and the
//! uniform scheme's pixel-error factor within `--max-factor`, default 16:
//! `GpuTessellator::prepare_screen`); with `--transition` the transition scheme's
//! (CudaTess's per-edge factors and the a-posteriori check, on the GPU); with `--cpu-plan`
//! too, the CPU plans the transition scheme for PX once instead, and the GPU culls and draws
//! it every frame.
//! `--silhouetteness FMAX` plans the transition scheme on the GPU from the camera alone
//! (culling, silhouetteness factors in 1..=FMAX, the core rule).
//! `--hardware PARTITIONING` (`integer`, `pow2`, `fractional_odd`, `fractional_even`) draws
//! the Direct3D 11 pattern instead: by default `Scheme::Hardware`'s CPU plan of the real
//! FACTOR (e.g. 15.3), drawn (and with `--cull` culled) by the GPU; with `--silhouetteness
//! FMAX` planned on the GPU from the camera (real factors 1 to FMAX).
//! Records FRAMES frames (default 10) and prints, per pass, the median of the
//! timestamp-query times when the adapter has them; otherwise the median wall time of a
//! whole frame around `submit` + `poll(wait)`. Statistics are read back after each frame,
//! outside what a frame loop would do.

use std::time::Instant;
use tessera::criterion::Plan;
use tessera::pattern::hardware::Partitioning;
use tessera::scheme::{Criterion, PlanOptions, Prepared, Scheme};
use tessera::surface::{BuildOptions, SurfaceSet};
use tessera_gpu::tessellator::{PassTimer, ScreenCriterion, PASSES};
use tessera_gpu::{GpuContext, GpuTessellator};

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v[v.len() / 2]
}

/// Removes `--name VALUE` from `args` and parses VALUE.
fn option<T: std::str::FromStr>(args: &mut Vec<String>, name: &str) -> Result<Option<T>, String> {
    let Some(i) = args.iter().position(|a| a == name) else { return Ok(None) };
    let value = args.get(i + 1).ok_or(format!("{name} needs a value"))?;
    let parsed = value.parse().map_err(|_| format!("{name}: cannot read {value}"))?;
    args.drain(i..i + 2);
    Ok(Some(parsed))
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args: Vec<String> = std::env::args().collect();
    let flag = |args: &mut Vec<String>, name: &str| {
        let found = args.iter().any(|a| a == name);
        args.retain(|a| a != name);
        found
    };
    let cull = flag(&mut args, "--cull");
    let transition = flag(&mut args, "--transition");
    let cpu_plan = flag(&mut args, "--cpu-plan");
    let copies: usize = option(&mut args, "--copies")?.unwrap_or(1);
    let pixels: Option<f64> = option(&mut args, "--pixel-error")?;
    let max_factor: u32 = option(&mut args, "--max-factor")?.unwrap_or(16);
    let silhouetteness: Option<f64> = option(&mut args, "--silhouetteness")?;
    let hardware: Option<String> = option(&mut args, "--hardware")?;
    let usage = "usage: gpu_frame MODEL.patches [FACTOR] [FRAMES] [--copies N] [--cull] \
                 [--pixel-error PX [--max-factor N] [--transition [--cpu-plan]]] [--silhouetteness FMAX] \
                 [--hardware integer|pow2|fractional_odd|fractional_even]";
    let path = args.get(1).ok_or(usage)?;
    let factor: f64 = args.get(2).map_or(Ok(16.0), |s| s.parse())?;
    let partitioning = match hardware.as_deref().map(|h| h.replace('-', "_")) {
        None => None,
        Some(name) => Some(
            [
                Partitioning::Integer,
                Partitioning::Pow2,
                Partitioning::FractionalOdd,
                Partitioning::FractionalEven,
            ]
            .into_iter()
            .find(|p| p.name() == name)
            .ok_or(format!("--hardware {name}: use integer, pow2, fractional_odd or fractional_even"))?,
        ),
    };
    let frames: usize = args.get(3).map_or(Ok(10), |s| s.parse())?;
    let file = tessera::io::patches::read_patches(std::path::Path::new(path))?;
    let file = if copies > 1 { tessera::scene::patch_grid(&file, copies) } else { file };
    let set = SurfaceSet::from_patch_file(&file, BuildOptions::default());
    let (lo, hi) = set.bounds();
    let camera = tessera::camera::Camera::framing(lo, hi, 1280, 1024);
    let ctx = GpuContext::new()?;
    println!("adapter: {} ({:?}, {})", ctx.info.name, ctx.info.backend, ctx.info.driver_info);
    let mut gpu = GpuTessellator::new(&ctx, &set)?;
    if cull {
        gpu.set_cull_camera(&ctx, Some(&camera));
    }
    let what = match (pixels, transition && cpu_plan) {
        _ if partitioning.is_some() && pixels.is_some() => {
            return Err(
                "--hardware takes a factor or --silhouetteness: the hardware schemes have no pixel error"
                    .into(),
            );
        }
        _ if partitioning.is_some() => {
            let p = partitioning.expect("checked");
            let scheme = Scheme::Hardware(p);
            if let Some(fmax) = silhouetteness {
                let prepared = Prepared::new(&set, true);
                let criterion = Criterion::View {
                    criterion: tessera::criterion::view::ViewCriterion::Silhouetteness,
                    fmin: 1.0,
                    fmax,
                };
                let cap = scheme.factor_cap().min(fmax.ceil()) as u32;
                let screen = ScreenCriterion::new(scheme, criterion, cap);
                gpu.prepare_screen(&ctx, &set, &prepared, &camera, screen)?;
                format!(
                    "{}, silhouetteness factors 1 to {fmax} planned on the GPU, culled on the GPU",
                    p.name()
                )
            } else {
                let planned = scheme.plan(&set, &Criterion::Factor(factor), &PlanOptions::default())?;
                gpu.prepare(&ctx, &set, &planned.plan, &planned.pattern)?;
                format!("{} factor {factor}{}", p.name(), if cull { ", culled on the GPU" } else { "" })
            }
        }
        _ if silhouetteness.is_some() => {
            let fmax = silhouetteness.unwrap_or(1.0).round().max(1.0) as u32;
            let prepared = Prepared::new(&set, true);
            let criterion = Criterion::View {
                criterion: tessera::criterion::view::ViewCriterion::Silhouetteness,
                fmin: 1.0,
                fmax: fmax as f64,
            };
            let screen = ScreenCriterion::new(Scheme::Transition, criterion, fmax);
            gpu.prepare_screen(&ctx, &set, &prepared, &camera, screen)?;
            format!("transition, silhouetteness factors 1 to {fmax} planned on the GPU, culled on the GPU")
        }
        (Some(px), false) => {
            let prepared = Prepared::new(&set, true);
            let scheme = if transition { Scheme::Transition } else { Scheme::Uniform };
            let screen = ScreenCriterion::new(scheme, Criterion::PixelError(px), max_factor);
            gpu.prepare_screen(&ctx, &set, &prepared, &camera, screen)?;
            format!("{}, {px} px and cap {max_factor} planned on the GPU, culled on the GPU", scheme.name())
        }
        (Some(px), true) => {
            let options = PlanOptions { camera: Some(camera), cull: true, max_factor, ..Default::default() };
            let planned = Scheme::Transition.plan(&set, &Criterion::PixelError(px), &options)?;
            let mut plan = planned.plan;
            plan.visible.fill(1);
            gpu.set_cull_camera(&ctx, Some(&camera));
            gpu.prepare(&ctx, &set, &plan, &planned.pattern)?;
            format!("transition, {px} px and cap {max_factor} planned once on the CPU, culled on the GPU")
        }
        (None, _) => {
            if factor.fract() != 0.0 || factor < 1.0 {
                return Err(format!(
                    "factor {factor}: the uniform pattern takes an integer (real factors: --hardware)"
                )
                .into());
            }
            let factor = factor as u32;
            gpu.prepare(&ctx, &set, &Plan::uniform(&set, factor)?, &tessera::pattern::uniform::Uniform)?;
            format!("uniform factor {factor}{}", if cull { ", culled on the GPU" } else { "" })
        }
    };
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
        "{path} x{copies}: {} patches, {what}: {vertices} vertices, {triangles} triangles{}",
        set.patches.len(),
        if overflow { " (OVERFLOW)" } else { "" }
    );
    let report = gpu.read_screen_report(&ctx)?;
    if report.rounds > 0 || report.failing_patches > 0 || !report.converged {
        println!(
            "  a-posteriori check: {} fix rounds, {} patches at the cap{}",
            report.rounds,
            report.failing_patches,
            if report.converged { "" } else { " (rounds NOT converged)" }
        );
    }
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
