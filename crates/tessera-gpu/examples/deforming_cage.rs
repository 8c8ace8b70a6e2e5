//! An animated subdivision cage (Catmull-Clark or Loop) on the GPU: the cage's stencils are
//! made and uploaded once; each frame uploads only the moved cage vertices, the stencil pass recomputes the
//! patches' control points on the GPU, and the same command buffer tessellates them.
//!
//! `cargo run --release -p tessera-gpu --example deforming_cage -- [CAGE.obj] [FRAMES]
//! [PIXELSpx|FACTOR] [OUT_DIR] [catmull-clark|loop]` (defaults: `$TESSERA_DATA/subdivision/catmark_torus.obj`,
//! 60 frames, `0.5px`, `frames/`, Catmull-Clark; a Loop cage is a triangle cage such as
//! `subdivision/loop_xord_interior.obj`). With a pixel error (`0.5px`) every frame is planned
//! on the GPU from a camera framing the cage — culling, the transition scheme's edge factors
//! and its a-posteriori check — on bounds that move with the cage
//! (`GpuStencils::with_moving_bounds`); with a number, every frame is the uniform grid of that
//! factor. The cage bends and breathes over the frames; each frame's mesh is
//! read back and written as `OUT_DIR/cage_NNN.ply` (a headless app's stand-in for drawing
//! it: the vertex and index buffers are the engine's own, as `tessera-render`'s examples
//! draw them), and a line per frame gives the vertices uploaded and the GPU time of the
//! stencil pass and the frame together (submit to idle, read-back excluded).
//!
//! Any manifold cage moves, creases and extraordinary vertices included: the stencil pass
//! recomputes regular faces' control points and isolated faces' pieces alike
//! (`subdivision/catmark_rook.obj` takes a while to make its stencils: each isolated face is
//! probed to isolation level 6).

use std::path::{Path, PathBuf};
use std::time::Instant;

use glam::DVec3;
use tessera::camera::Camera;
use tessera::criterion::Plan;
use tessera::pattern::transition::Transition;
use tessera::pattern::uniform::Uniform;
use tessera::pattern::Pattern;
use tessera::scheme::{Criterion, Prepared, Scheme};
use tessera::subdivision::{CageOptions, CageStencils};
use tessera_gpu::tessellator::ScreenCriterion;
use tessera_gpu::{GpuContext, GpuStencils, GpuTessellator};

/// How each frame is tessellated.
enum Tessellation {
    /// The uniform grid of this factor, planned once on the CPU.
    Factor(u32),
    /// The transition scheme at this pixel error, planned on the GPU every frame.
    Pixels(f64),
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let data =
        std::env::var_os("TESSERA_DATA").map_or_else(|| PathBuf::from("../shared/data"), PathBuf::from);
    let cage_path = args.get(1).map_or_else(|| data.join("subdivision/catmark_torus.obj"), PathBuf::from);
    let frames: usize = args.get(2).map_or(Ok(60), |s| s.parse())?;
    let tessellation = match args.get(3).map(String::as_str) {
        None => Tessellation::Pixels(0.5),
        Some(s) if s.ends_with("px") => Tessellation::Pixels(s.trim_end_matches("px").parse()?),
        Some(s) => Tessellation::Factor(s.parse()?),
    };
    let out = PathBuf::from(args.get(4).map_or("frames", String::as_str));
    let build = match args.get(5).map_or("catmull-clark", String::as_str) {
        "catmull-clark" => CageStencils::build,
        "loop" => CageStencils::build_loop,
        other => return Err(format!("unknown surface {other:?}: catmull-clark or loop").into()),
    };
    std::fs::create_dir_all(&out)?;

    let mesh = tessera::io::obj::read_obj(&cage_path)?;
    let start = Instant::now();
    let (mut set, stencils) = build(&mesh, &cage_path, CageOptions::default())?;
    println!(
        "{}: {} faces, {} patches, stencils of {} terms made in {:.1} ms",
        cage_path.display(),
        mesh.faces.len(),
        set.patches.len(),
        stencils.rows().vertices.len(),
        start.elapsed().as_secs_f64() * 1e3
    );
    let ctx = GpuContext::new()?;
    println!("adapter: {} ({:?})", ctx.info.name, ctx.info.backend);
    let mut gpu = GpuTessellator::new(&ctx, &set)?;
    let (lo, hi) = set.bounds();
    let (moving, pattern): (GpuStencils, &dyn Pattern) = match tessellation {
        Tessellation::Factor(factor) => {
            // A uniform plan needs no per-patch bounds: the stencil pass alone moves the cage.
            let moving = GpuStencils::new(&ctx, &stencils, &set, &gpu)?;
            gpu.prepare(&ctx, &set, &Plan::uniform(&set, factor)?, &Uniform)?;
            (moving, &Uniform)
        }
        Tessellation::Pixels(pixels) => {
            let prepared = Prepared::new(&set, true);
            let moving =
                GpuStencils::with_moving_bounds(&ctx, &stencils, &set, &mut gpu, &prepared, &mesh.positions)?;
            // The rest cage's box grown by the breathing (15 %) and the bend.
            let pad = (hi - lo) * 0.3;
            let camera = Camera::framing(lo - pad, hi + pad, 1280, 1024);
            let criterion = Criterion::PixelError(pixels);
            let screen = ScreenCriterion::new(Scheme::Transition, criterion, 32);
            gpu.prepare_screen(&ctx, &set, &prepared, &camera, screen)?;
            (moving, &Transition)
        }
    };

    let (centre, size) = ((lo + hi) * 0.5, (hi - lo).max_element());
    for frame in 0..frames {
        let t = frame as f64 / frames.max(1) as f64 * std::f64::consts::TAU;
        let positions: Vec<DVec3> = mesh.positions.iter().map(|&p| deform(p, centre, size, t)).collect();
        let start = Instant::now();
        moving.write_positions(&ctx, &positions)?;
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        moving.record(&mut encoder);
        gpu.record(&mut encoder);
        ctx.queue.submit([encoder.finish()]);
        ctx.wait()?;
        let gpu_ms = start.elapsed().as_secs_f64() * 1e3;
        // A frame that needed more room than the output had drew nothing: grown, drawn again.
        while gpu.grow_if_overflowed(&ctx)? {
            let mut encoder = ctx.device.create_command_encoder(&Default::default());
            moving.record(&mut encoder);
            gpu.record(&mut encoder);
            ctx.queue.submit([encoder.finish()]);
        }
        let drawn = gpu.read_mesh(&ctx, &set)?;
        let path = out.join(format!("cage_{frame:03}.ply"));
        tessera::io::write_mesh(&drawn, &path)?;
        println!(
            "frame {frame:3}: {} vertices uploaded, {} triangles in {gpu_ms:.2} ms -> {}",
            positions.len(),
            drawn.triangle_count(),
            path.display()
        );
        // The CPU's stencils give the same surface (a check a real loop would leave out).
        if frame == frames - 1 {
            stencils.apply(&positions, &mut set)?;
            let plan = gpu.read_plan(&ctx)?;
            let cpu = tessera::engine::tessellate(&set, &plan, pattern, Default::default())?;
            let worst = cpu
                .positions
                .iter()
                .zip(&drawn.positions)
                .map(|(a, b)| (0..3).map(|k| (a[k] - b[k]).abs()).fold(0.0f32, f32::max))
                .fold(0.0f32, f32::max);
            println!("last frame against the CPU engine: largest coordinate difference {worst:.2e}");
        }
    }
    check_written(&out, frames)?;
    Ok(())
}

/// The cage at time `t`: bent about the vertical axis through `centre` and breathing.
fn deform(p: DVec3, centre: DVec3, size: f64, t: f64) -> DVec3 {
    let q = p - centre;
    let bend = 0.6 * t.sin() * q.y / size;
    let (s, c) = bend.sin_cos();
    let breathe = 1.0 + 0.15 * (2.0 * t).sin();
    centre + DVec3::new((c * q.x - s * q.z) * breathe, q.y, (s * q.x + c * q.z) * breathe)
}

/// Every frame's file is there (a failed write stops the run before this).
fn check_written(out: &Path, frames: usize) -> Result<(), Box<dyn std::error::Error>> {
    let written = (0..frames).filter(|f| out.join(format!("cage_{f:03}.ply")).is_file()).count();
    println!("{written} frames written to {}", out.display());
    if written != frames {
        return Err(format!("{} of {frames} frames missing", frames - written).into());
    }
    Ok(())
}
