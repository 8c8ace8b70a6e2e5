//! `tessera mesh`: one frame of a surface set — drawn by the CPU engine through the
//! [`Tessellator`], or by the GPU engine (planned on the CPU, or from the camera on the GPU
//! itself) — written, checked and reported.

use crate::plan::{self, Chosen, EngineArg};
use crate::{gpu, CliResult, InputArgs};
use clap::Args;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::{Duration, Instant};
use tessera::criterion::tolerance::BoundReport;
use tessera::engine::render_queues::{self, RenderQueues};
use tessera::engine::EngineOptions;
use tessera::mesh::Mesh;
use tessera::scheme::{validate, Criterion, Engine, Scheme};
use tessera::surface::SurfaceSet;
use tessera::tessellator::{FrameTimings, Tessellator, TessellatorOptions};
use tessera::verify;

#[derive(Args)]
pub struct MeshArgs {
    /// Input: .patches (Newell bicubic patch format), .bezt (cubic Bézier triangles) or a
    /// triangle mesh → PN triangles: .obj, .ply, .stl, .glb or .gltf.
    pub input: PathBuf,
    /// Output mesh; the format follows the extension: .obj, .ply, .stl or .glb.
    #[arg(short, long, value_name = "OUT")]
    pub output: Option<PathBuf>,
    #[command(flatten)]
    pub criterion: plan::CriterionArgs,
    /// Print one JSON object with counts, topology and timing on one stdout line.
    #[arg(long)]
    pub stats: bool,
    /// Tessellate R times (reusing the output buffers) and report the median time (--stats).
    #[arg(long, value_name = "R", default_value_t = 1)]
    pub repeat: u32,
    /// Refuse, before allocating anything, an output of more triangles than this. Default:
    /// what three quarters of the memory available now can hold.
    #[arg(long, value_name = "N")]
    pub max_triangles: Option<u64>,
    /// Also measure the approximation error against the exact surface (with --stats).
    #[arg(long)]
    pub measure_error: bool,
    /// Also produce triangle strips (schemes sd2 and esc): stored in .ply as a `tristrips`
    /// element; the other formats keep the decoded triangle list.
    #[arg(long)]
    pub strips: bool,
    /// Semi-uniform: also write the instanced form as JSON — the static patterns P^0..P^M
    /// (vertices u, v, tag: edge + snap offset, or 4 for unsnapped) and the render queues
    /// (per level: patch id and edge levels).
    #[arg(long, value_name = "JSON")]
    pub instanced: Option<PathBuf>,
    /// Engine: `cpu` (rayon) or `gpu` (tessera-gpu on wgpu: the uniform, transition,
    /// semi-uniform, integer, pow2, fractional-odd and fractional-even schemes on every
    /// surface kind, SD-2 on triangles; with --cull and a pixel error
    /// (uniform, transition, semi-uniform; --max-factor up to 64), silhouetteness, a hardware
    /// scheme's --factor or SD-2's --distance, --silhouette or --factor, the GPU plans the
    /// frame from the camera itself, else it draws the CPU's plan; --stats adds per-pass GPU
    /// times).
    #[arg(long, value_enum, default_value = "cpu")]
    pub engine: plan::EngineArg,
    /// Let -o name the input file itself (it is replaced once the new mesh is complete).
    #[arg(long)]
    pub force: bool,
    #[command(flatten)]
    pub input_args: InputArgs,
}

/// One frame, whichever engine drew it.
struct Drawn {
    mesh: Mesh,
    /// Patches the plan left out (`--cull`).
    culled: usize,
    /// The CPU plan's guarantee report, for the error-bounded criteria planned on the CPU.
    report: Option<BoundReport>,
    /// The CPU's stage times per frame (planning only, when the GPU drew the frame; none
    /// when the GPU also planned it).
    frames: Vec<FrameTimings>,
    /// Preparing the set for the CPU's plans (once per set).
    prepare: Duration,
    /// The semi-uniform render queues of `--instanced`.
    queues: Option<RenderQueues>,
    /// The GPU's run and its frames' wall times (seconds), for `--engine gpu`.
    gpu: Option<(gpu::GpuRun, Vec<f64>)>,
}

/// What a frame's errors become on the command line: about a patch, they name the file;
/// about size, they say which limit.
type Explain<'a> = &'a dyn Fn(tessera::Error) -> Box<dyn std::error::Error>;

pub fn run(a: MeshArgs) -> CliResult {
    check_flags(&a)?;
    let options = crate::load_options(&a.input_args)?;
    let pb = crate::spinner(&format!("reading {}", a.input.display()));
    let set = crate::load_surfaces(&a.input, options)?;
    pb.set_message("choosing factors");
    let wants_params = a.measure_error
        || a.output.as_ref().is_some_and(|o| o.extension().is_some_and(|e| e.eq_ignore_ascii_case("ply")));
    let opts = EngineOptions { strips: a.strips, ..crate::limits(a.max_triangles, wants_params) };
    let chosen = plan::choose(&a.criterion, &set, opts.max_triangles.unwrap_or(u64::MAX))?;
    if chosen.options.cull || !matches!(chosen.criterion, Criterion::Factor(_) | Criterion::Tolerance(_)) {
        plan::note_up_axis(a.criterion.camera.as_deref(), &a.input);
    }
    if a.instanced.is_some() && !matches!(chosen.scheme, Scheme::SemiUniform { .. }) {
        return Err("--instanced needs --scheme semi-uniform".into());
    }
    let explain = |e: tessera::Error| -> Box<dyn std::error::Error> {
        match e {
            tessera::Error::PatchKindNotAccepted { .. } => format!("{}: {e}", a.input.display()).into(),
            e => crate::explain_limit(e, &opts),
        }
    };
    pb.set_message(format!("tessellating {} patches ({})", set.patches.len(), chosen.description));
    let mut drawn = match a.engine {
        EngineArg::Cpu => draw_on_cpu(&a, &set, &chosen, opts, &explain)?,
        EngineArg::Gpu => draw_on_gpu(&a, &set, &chosen, opts, &explain)?,
    };
    warn_capped(&a, &set, &chosen, drawn.report.as_ref());
    if a.strips
        && a.output.as_ref().is_some_and(|o| !o.extension().is_some_and(|e| e.eq_ignore_ascii_case("ply")))
    {
        eprintln!("note: only .ply stores triangle strips; the output gets the decoded triangle list");
    }
    if let Some((run, _)) = &drawn.gpu {
        if let Some(check) = run.screen.filter(|c| c.checked && !c.converged) {
            eprintln!(
                "warning: the GPU's a-posteriori check needed more than its {} fix rounds: {} patches miss the bound (the mesh is still crack-free)",
                check.rounds, check.failing_patches
            );
        }
    }
    // The numbering rule gives culled patches' corners (and their edges' normal variants)
    // vertices no triangle uses; what is written and counted holds only the used ones.
    if drawn.culled > 0 {
        drawn.mesh.drop_unused_vertices();
    }
    pb.finish_and_clear();
    let mut output_file = None;
    if let Some(out) = &a.output {
        let start = Instant::now();
        crate::write_with_bar(&drawn.mesh, out, opts.corner_params)?;
        output_file = Some(start.elapsed().as_secs_f64());
    }
    let mesh = &drawn.mesh;
    let repairs = crate::report_repairs(&set, mesh);
    if a.output.is_none() && !a.stats {
        eprintln!(
            "tessellated {} patches into {} triangles and {} vertices; nothing written: give -o OUT to write the mesh, or --stats for the figures",
            set.patches.len(),
            mesh.triangle_count(),
            mesh.vertex_count()
        );
    }
    if drawn.culled > 0 {
        eprintln!(
            "note: --cull left out {} of {} patches (outside the view or facing away): the mesh is open there",
            drawn.culled,
            set.patches.len()
        );
    }
    // Checked on every run: a mesh that is open, non-manifold or degenerate where the input
    // was not never leaves without a warning and exit status 1.
    let w = verify::watertight(mesh);
    let problems = crate::output_problems(&set, &w, drawn.culled);
    if a.stats {
        let mut stats = stats_json(&a, &set, &chosen, &drawn, &w, output_file)?;
        stats["repairs"] = repairs;
        stats["problems"] = problems.clone().into();
        println!("{stats}");
    }
    for p in &problems {
        eprintln!("warning: {p}");
    }
    Ok(if problems.is_empty() { ExitCode::SUCCESS } else { ExitCode::from(1) })
}

/// The flags' own rules, checked before anything is read.
fn check_flags(a: &MeshArgs) -> Result<(), Box<dyn std::error::Error>> {
    if a.repeat == 0 {
        return Err("--repeat 0: use 1 or more".into());
    }
    if a.max_triangles == Some(0) {
        return Err("--max-triangles 0: use 1 or more".into());
    }
    if let Some(out) = &a.output {
        tessera::io::check_output_path(out)?;
        if !a.force && crate::same_file(out, &a.input) {
            return Err(format!(
                "-o {}: that is the input; write elsewhere, or add --force to replace it",
                out.display()
            )
            .into());
        }
    }
    Ok(())
}

/// The CPU engine: `--repeat` whole frames from the camera, criterion to last index, into
/// buffers reused from the last one, as an application re-tessellating every frame would
/// (the median then measures tessellation, not page faults).
fn draw_on_cpu(
    a: &MeshArgs,
    set: &SurfaceSet,
    chosen: &Chosen,
    opts: EngineOptions,
    explain: Explain<'_>,
) -> Result<Drawn, Box<dyn std::error::Error>> {
    let start = Instant::now();
    let options = TessellatorOptions { plan: chosen.options, engine: opts };
    let mut tess = Tessellator::new(set, chosen.scheme, chosen.criterion, options).map_err(explain)?;
    let prepare = start.elapsed();
    let mut frames = Vec::new();
    for frame in 0..a.repeat.max(1) {
        let layout = tess.plan_frame(None).map_err(explain)?;
        if frame == 0 {
            crate::announce_large_output(layout, &opts, a.output.as_deref());
        }
        tess.write_frame().map_err(explain)?;
        frames.push(tess.timings());
    }
    let plan = tess.plan().expect("a frame was planned");
    let culled = plan.culled_count();
    let queues = match (&a.instanced, chosen.scheme) {
        (Some(path), Scheme::SemiUniform { max_level }) => {
            let queues = render_queues::build(set, plan, max_level)?;
            crate::write_instanced(path, set, &queues)?;
            Some(queues)
        }
        _ => None,
    };
    let report = tess.report().copied();
    Ok(Drawn { mesh: tess.into_mesh(), culled, report, frames, prepare, queues, gpu: None })
}

/// The GPU engine: the frame planned from the camera on the GPU where it plans that request
/// (`validate` with [`Engine::GpuFromCamera`]), else planned on the CPU (no CPU write) and
/// drawn on the GPU; `--repeat` GPU frames, the last read back.
fn draw_on_gpu(
    a: &MeshArgs,
    set: &SurfaceSet,
    chosen: &Chosen,
    opts: EngineOptions,
    explain: Explain<'_>,
) -> Result<Drawn, Box<dyn std::error::Error>> {
    let (scheme, criterion, options) = (chosen.scheme, chosen.criterion, chosen.options);
    validate(scheme, &criterion, &options, set, Engine::Gpu).map_err(explain)?;
    let mut mesh = Mesh::default();
    let mut times = Vec::new();
    let output = gpu::Output { strips: a.strips, corner_params: opts.corner_params };
    let from_camera = options.camera.zip(gpu::screen_criterion(set, scheme, &criterion, &options));
    if let Some((camera, screen)) = from_camera {
        let run = gpu::tessellate_from_camera(set, &camera, screen, output, a.repeat, &mut mesh, &mut times)?;
        let culled = run.culled;
        let gpu = Some((run, times));
        return Ok(Drawn {
            mesh,
            culled,
            report: None,
            frames: Vec::new(),
            prepare: Duration::ZERO,
            queues: None,
            gpu,
        });
    }
    let start = Instant::now();
    let tess_options = TessellatorOptions { plan: options, engine: opts };
    let mut tess = Tessellator::new(set, scheme, criterion, tess_options).map_err(explain)?;
    let prepare = start.elapsed();
    let layout = tess.plan_frame(None).map_err(explain)?;
    crate::announce_large_output(layout, &opts, a.output.as_deref());
    let (plan, pattern) =
        (tess.plan().expect("a frame was planned"), tess.pattern().expect("a frame was planned"));
    let run = gpu::tessellate(set, plan, pattern, output, a.repeat, &mut mesh, &mut times)?;
    let culled = plan.culled_count();
    let frames = vec![tess.timings()];
    Ok(Drawn {
        mesh,
        culled,
        report: tess.report().copied(),
        frames,
        prepare,
        queues: None,
        gpu: Some((run, times)),
    })
}

/// Says where `--max-factor` (or semi-uniform's highest level) stopped an error bound.
fn warn_capped(a: &MeshArgs, set: &SurfaceSet, chosen: &Chosen, report: Option<&BoundReport>) {
    let Some(r) = report.filter(|r| r.capped_patches > 0) else { return };
    let Ok(accepted) = validate(chosen.scheme, &chosen.criterion, &chosen.options, set, Engine::Cpu) else {
        return;
    };
    let flag =
        if matches!(chosen.scheme, Scheme::SemiUniform { .. }) { "--max-level" } else { "--max-factor" };
    let cap = match chosen.scheme {
        Scheme::SemiUniform { max_level } => format!("--max-level {max_level} (factor {})", accepted.cap),
        _ => format!("--max-factor {}", a.criterion.max_factor),
    };
    eprintln!(
        "warning: {cap} stopped the error bound on {} patches: the guaranteed bound there is up to {:.3e}, {}× the request; raise {flag}",
        r.capped_patches,
        r.worst_bound,
        crate::ratio(r.worst_ratio)
    );
}

/// The `--stats` line (without `repairs` and `problems`, which the caller adds).
fn stats_json(
    a: &MeshArgs,
    set: &SurfaceSet,
    chosen: &Chosen,
    drawn: &Drawn,
    w: &verify::WatertightReport,
    output_file: Option<f64>,
) -> Result<serde_json::Value, Box<dyn std::error::Error>> {
    let mesh = &drawn.mesh;
    let frames = &drawn.frames;
    // Medians over the frames; None where no CPU frame ran the stage.
    let stage = |f: fn(&FrameTimings) -> Duration| -> Option<f64> {
        (!frames.is_empty()).then(|| crate::median(frames.iter().map(|t| f(t).as_secs_f64()).collect()))
    };
    let cpu_wrote = drawn.gpu.is_none();
    let written = |f: fn(&FrameTimings) -> Duration| if cpu_wrote { stage(f) } else { None };
    let seconds = match &drawn.gpu {
        Some((_, times)) => crate::median(times.clone()),
        None => stage(FrameTimings::total).unwrap_or(0.0),
    };
    let mut stats = serde_json::json!({
        "input": a.input.display().to_string(),
        "scheme": chosen.description,
        "culled_patches": drawn.culled,
        "patches": set.patches.len(),
        "triangles": mesh.triangle_count(),
        "vertices": mesh.vertex_count(),
        "boundary_edges": w.boundary_edges,
        "nonmanifold_edges": w.nonmanifold_edges,
        "degenerate_triangles": w.degenerate_triangles(),
        "euler_characteristic": w.euler_characteristic,
        "input_euler_characteristic": set.topology.report.euler_characteristic,
        "input_boundary_edges": set.topology.report.boundary_edges,
        "input_nonmanifold_edges": set.topology.report.nonmanifold_edges,
        "seconds": seconds,
        "repeat": a.repeat.max(1),
        "mtri_per_s": mesh.triangle_count() as f64 / seconds / 1e6,
        "threads": rayon::current_num_threads(),
        // Medians over the repeats; `seconds` is their whole frame. `prepare` (once per
        // set) and `output_file` (once) are not part of it.
        "stages": {
            "prepare": drawn.prepare.as_secs_f64(),
            "criterion": stage(|t| t.criterion),
            "resolve": stage(|t| t.resolve),
            "layout": stage(|t| t.layout),
            "write": written(|t| t.write),
            "write_vertices": written(|t| t.write_vertices),
            "write_indices": written(|t| t.write_indices),
            "output_file": output_file,
        },
    });
    if let Some(r) = &drawn.report {
        stats["guaranteed_bound"] = r.worst_bound.into();
        stats["bound_met"] = (r.capped_patches == 0).into();
        stats["capped_patches"] = r.capped_patches.into();
    }
    if let Some(t) = chosen.tolerance {
        stats["tolerance"] = t.into();
    }
    if let Some((run, _)) = &drawn.gpu {
        stats["engine"] = "gpu".into();
        stats["adapter"] = run.adapter.clone().into();
        stats["planned_on"] = if run.screen.is_some() { "gpu" } else { "cpu" }.into();
        if let Some(check) = run.screen.filter(|c| c.checked) {
            stats["gpu_check_rounds"] = check.rounds.into();
            stats["gpu_check_converged"] = check.converged.into();
            stats["gpu_capped_patches"] = check.failing_patches.into();
        }
        stats["gpu_pass_ms"] = run
            .passes_ms
            .iter()
            .map(|&(n, ms)| (n.to_string(), ms.into()))
            .collect::<serde_json::Map<_, _>>()
            .into();
    }
    if let Some(strips) = &mesh.strips {
        stats["strip_indices"] = strips.len().into();
        stats["strips"] =
            (strips.iter().filter(|&&i| i == tessera::mesh::strips::RESTART).count() + 1).into();
    }
    if let Some(q) = &drawn.queues {
        let sizes: Vec<usize> = (0..=q.max_level()).map(|m| q.level(m).len()).collect();
        stats["render_queues"] = sizes.into();
    }
    if a.measure_error {
        let e = verify::approximation_error(mesh, set, 6)?;
        stats["max_error"] = e.max.into();
        stats["rms_error"] = e.rms.into();
    }
    Ok(stats)
}
