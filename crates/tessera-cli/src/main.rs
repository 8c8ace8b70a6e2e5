//! `tessera`: tessellate parametric surfaces into watertight triangle meshes.

mod bench;
mod gpu;
mod pattern_file;
mod plan;
mod render;
mod view;

use clap::{Args, Parser, Subcommand};
use indicatif::{ProgressBar, ProgressStyle};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::{Duration, Instant};
use tessera::criterion::Plan;
use tessera::engine::render_queues::{self, RenderQueues};
use tessera::engine::{self, TessellateOptions};
use tessera::io::glb::UriScope;
use tessera::io::LoadOptions;
use tessera::mesh::Mesh;
use tessera::pattern::semi_uniform::StaticPattern;
use tessera::pattern::uniform::Uniform;
use tessera::scheme::{Criterion, Scheme};
use tessera::surface::Domain;
use tessera::surface::{BuildOptions, Orientation, SurfaceSet};
use tessera::tessellator::{FrameTimings, Tessellator, TessellatorOptions};
use tessera::topology::weld::Weld;
use tessera::verify;

/// The Utah teapot, public domain, embedded for `tessera demo`.
const TEAPOT: &str = include_str!("../assets/teapot.patches");

#[derive(Parser)]
#[command(name = "tessera", version, about = "Crack-free tessellation of parametric surfaces", long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

// Parsed once per run, so the size of the `mesh` arguments does not matter.
#[allow(clippy::large_enum_variant)]
#[derive(Subcommand)]
enum Command {
    /// Tessellate a patch file (.patches, bicubic Bézier), a Bézier triangle file (.bezt) or a
    /// triangle mesh (.obj, .ply, .stl, .glb, .gltf, as PN triangles) into one watertight
    /// indexed mesh.
    Mesh(MeshArgs),
    /// Check a mesh: watertightness, triangle quality and, with --against, the input's
    /// topology and the approximation error.
    Check(CheckArgs),
    /// Tessellate the embedded Utah teapot, write teapot.obj and a picture of it (teapot.png)
    /// and print the report.
    Demo(DemoArgs),
    /// Draw the domain pattern of any scheme for given edge and inside factors, as an SVG
    /// picture or as JSON in the Direct3D 11 reference tessellator's conventions (points
    /// [u, v]; triangles in D3D's triangle_ccw order; edges in D3D's order: quad
    /// U==0,V==0,U==1,V==1, tri U==0,V==0,W==0).
    Pattern(pattern_file::PatternArgs),
    /// Benchmarks: speed per stage, triangles against measured error per scheme, camera
    /// walks of large scenes and the papers' tables; Markdown on stdout, CSV, JSON and SVG
    /// plots in --out.
    Bench(bench::BenchArgs),
    /// Draw a tessellation into a PNG picture (wgpu; the CPU rasteriser where there is no
    /// GPU adapter): shaded, optionally with the wireframe, coloured per patch or per level.
    Render(render::RenderArgs),
    /// Open a window (X11) that re-tessellates the model every frame from an orbit camera,
    /// with keys for the scheme, the pixel error, wireframe, level colours and culling.
    #[command(after_help = view::KEYS)]
    View(view::ViewArgs),
}

#[derive(Args)]
struct InputArgs {
    /// Merge control points / mesh vertices closer than EPS (default: only bit-identical
    /// positions are merged).
    #[arg(long, value_name = "EPS")]
    weld: Option<f64>,
    /// Reverse the orientation (front side) of every patch after auto-orientation.
    #[arg(long)]
    flip_normals: bool,
    /// Keep the input's orientation instead of orienting closed inputs outward.
    #[arg(long)]
    keep_orientation: bool,
    /// Let a .gltf's buffer URIs name files outside its folder (by default they must resolve,
    /// links followed, to regular files inside it).
    #[arg(long)]
    allow_outside_uris: bool,
}

#[derive(Args)]
struct MeshArgs {
    /// Input: .patches (Newell bicubic patch format), .bezt (cubic Bézier triangles) or a
    /// triangle mesh → PN triangles: .obj, .ply, .stl, .glb or .gltf.
    input: PathBuf,
    /// Output mesh; the format follows the extension: .obj, .ply, .stl or .glb.
    #[arg(short, long, value_name = "OUT")]
    output: Option<PathBuf>,
    #[command(flatten)]
    criterion: plan::CriterionArgs,
    /// Print one JSON object with counts, topology and timing on one stdout line.
    #[arg(long)]
    stats: bool,
    /// Tessellate R times (reusing the output buffers) and report the median time (--stats).
    #[arg(long, value_name = "R", default_value_t = 1)]
    repeat: u32,
    /// Refuse, before allocating anything, an output of more triangles than this. Default:
    /// what three quarters of the memory available now can hold.
    #[arg(long, value_name = "N")]
    max_triangles: Option<u64>,
    /// Also measure the approximation error against the exact surface (with --stats).
    #[arg(long)]
    measure_error: bool,
    /// Also produce triangle strips (schemes sd2 and esc): stored in .ply as a `tristrips`
    /// element; the other formats keep the decoded triangle list.
    #[arg(long)]
    strips: bool,
    /// Semi-uniform: also write the instanced form as JSON — the static patterns P^0..P^M
    /// (vertices u, v, tag: edge + snap offset, or 4 for unsnapped) and the render queues
    /// (per level: patch id and edge levels).
    #[arg(long, value_name = "JSON")]
    instanced: Option<PathBuf>,
    /// Engine: `cpu` (rayon) or `gpu` (tessera-gpu on wgpu: the uniform, transition,
    /// integer, pow2, fractional-odd and fractional-even schemes on every surface kind; with
    /// --cull and a pixel error (uniform, transition; --max-factor up to 64), silhouetteness,
    /// or a hardware scheme's --factor, the GPU plans the frame from the camera itself, else
    /// it draws the CPU's plan; --stats adds per-pass GPU times).
    #[arg(long, value_enum, default_value = "cpu")]
    engine: plan::EngineArg,
    /// Let -o name the input file itself (it is replaced once the new mesh is complete).
    #[arg(long)]
    force: bool,
    #[command(flatten)]
    input_args: InputArgs,
}

#[derive(Args)]
struct CheckArgs {
    /// Mesh to check: .obj, .ply, .stl or .glb.
    mesh: PathBuf,
    /// The input the mesh was made from: compares topology and, for .ply meshes written by
    /// tessera (they carry per-corner patch parameters), measures the error.
    #[arg(long, value_name = "IN")]
    against: Option<PathBuf>,
    #[command(flatten)]
    input_args: InputArgs,
}

#[derive(Args)]
struct DemoArgs {
    /// Where to write the teapot mesh.
    #[arg(short, long, default_value = "teapot.obj")]
    output: PathBuf,
    /// Uniform tessellation factor.
    #[arg(long, value_name = "N", default_value_t = 8)]
    factor: u32,
    /// Where to write the picture (adaptive at 0.5 px from the default camera, shaded with
    /// the wireframe). Default: beside the mesh, with the extension .png.
    #[arg(long, value_name = "PNG")]
    picture: Option<PathBuf>,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    if !matches!(cli.command, Command::View(_)) {
        quiet_wayland_probe();
    }
    let result = match cli.command {
        Command::Mesh(a) => run_mesh(a),
        Command::Check(a) => run_check(a),
        Command::Demo(a) => run_demo(a),
        Command::Pattern(a) => pattern_file::run(a).map(|()| ExitCode::SUCCESS),
        Command::Bench(a) => bench::run(a),
        Command::Render(a) => render::run(a),
        Command::View(a) => view::run(a),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}

/// On a machine without a desktop session (no `XDG_RUNTIME_DIR`, no `WAYLAND_DISPLAY`), the
/// Vulkan drivers' Wayland support probes for a compositor when wgpu creates its instance, and
/// libwayland prints `error: XDG_RUNTIME_DIR is invalid or not set in the environment.` —
/// the first thing a newcomer running `tessera demo` on a server would read. There is no
/// compositor to find, so the probe is pointed at an absolute socket path that does not exist
/// (libwayland then skips `XDG_RUNTIME_DIR` and fails quietly). Only for the headless
/// commands: the window of `tessera view` is X11 (winit is built without Wayland), and it
/// sets nothing. Called first thing in `main`, before any thread exists.
fn quiet_wayland_probe() {
    #[cfg(target_os = "linux")]
    if std::env::var_os("XDG_RUNTIME_DIR").is_none() && std::env::var_os("WAYLAND_DISPLAY").is_none() {
        std::env::set_var("WAYLAND_DISPLAY", "/nonexistent/tessera-headless-no-wayland");
    }
}

type CliResult = Result<ExitCode, Box<dyn std::error::Error>>;

/// A spinner on stderr for work that may take a while; hidden when stderr is not a terminal.
fn spinner(message: &str) -> ProgressBar {
    let pb = ProgressBar::new_spinner();
    pb.set_style(ProgressStyle::with_template("{spinner} {msg} [{elapsed}]").expect("static template"));
    pb.set_message(message.to_string());
    pb.enable_steady_tick(Duration::from_millis(120));
    pb
}

fn load_options(a: &InputArgs) -> Result<LoadOptions, Box<dyn std::error::Error>> {
    let weld = match a.weld {
        None => Weld::Exact,
        Some(eps) if eps.is_finite() && eps >= 0.0 => Weld::Within(eps),
        Some(eps) => return Err(format!("--weld {eps}: the distance must be finite and ≥ 0").into()),
    };
    let build = BuildOptions {
        weld,
        orientation: if a.keep_orientation { Orientation::AsGiven } else { Orientation::Outward },
        flip: a.flip_normals,
    };
    let uri_scope = if a.allow_outside_uris { UriScope::Anywhere } else { UriScope::ModelFolder };
    Ok(LoadOptions { build, uri_scope })
}

/// Loads a surface set by extension (`tessera::io::load`: .patches, .bezt, .obj, .ply, .stl,
/// .glb, .gltf).
fn load_surfaces(path: &Path, options: LoadOptions) -> Result<SurfaceSet, tessera::Error> {
    tessera::io::load(path, options)
}

/// Output buffers may use up to 3/4 of the memory available now (Linux `MemAvailable`), or
/// 8 GiB where that cannot be read, so an absurd factor is refused instead of thrashing.
fn memory_limit() -> u64 {
    let available = std::fs::read_to_string("/proc/meminfo").ok().and_then(|m| {
        let line = m.lines().find(|l| l.starts_with("MemAvailable:"))?;
        line.split_whitespace().nth(1)?.parse::<u64>().ok().map(|kib| kib * 1024)
    });
    available.map_or(8 << 30, |b| b / 4 * 3)
}

/// The engine limits for a run: the memory limit and the triangle limit (`--max-triangles`,
/// else what the memory limit holds at a typical vertex-to-triangle ratio of 1:2).
fn limits(max_triangles: Option<u64>, corner_params: bool) -> TessellateOptions {
    let memory = memory_limit();
    let per_two_triangles = tessera::mesh::output_bytes(1, 2, corner_params);
    TessellateOptions {
        corner_params,
        memory_limit: Some(memory),
        max_triangles: Some(max_triangles.unwrap_or(memory / per_two_triangles * 2)),
        strips: false,
    }
}

/// The CLI's line for an output the engine refused: the estimate, the memory, and which limit
/// (and flag) stopped it.
fn explain_limit(e: tessera::Error, options: &TessellateOptions) -> Box<dyn std::error::Error> {
    let tessera::Error::OutputTooLarge { vertices, triangles, bytes } = e else { return e.into() };
    let gib = |b: u64| b as f64 / (1u64 << 30) as f64;
    let max_triangles = options.max_triangles.unwrap_or(u64::MAX);
    let why = if triangles > max_triangles {
        format!("the limit is --max-triangles {max_triangles}: lower the factor or the criterion, or raise --max-triangles")
    } else if options.memory_limit.is_some_and(|m| bytes > m) {
        format!(
            "more than three quarters of the memory available ({:.1} GiB): lower the factor or the criterion",
            gib(options.memory_limit.unwrap_or(0))
        )
    } else {
        "beyond the 32-bit vertex index range: lower the factor or the criterion".to_string()
    };
    format!(
        "output too large: {vertices} vertices and {triangles} triangles would need {:.1} GiB; {why}",
        gib(bytes)
    )
    .into()
}

/// A ratio for a message: fixed-point when small, scientific when huge.
fn ratio(x: f64) -> String {
    if x.abs() < 1e4 {
        format!("{x:.2}")
    } else {
        format!("{x:.2e}")
    }
}

/// One line per kind of repair the input needed, on stderr, and the same as JSON for --stats.
fn report_repairs(set: &SurfaceSet, mesh: &Mesh) -> serde_json::Value {
    let r = &set.repairs;
    let lines = [
        (
            r.split_polygons,
            "input polygons split into triangles (fans from their first corner) for PN triangles",
        ),
        (r.skipped_primitives, "glTF primitives left out: POINTS or LINES, not surfaces"),
        (r.welded_points, "input points merged into coincident ones by welding"),
        (r.dropped_degenerate_faces, "input faces dropped: two of their corners are one vertex"),
        (r.dropped_duplicate_faces, "input faces dropped: exact duplicates of earlier faces"),
        (r.dropped_zero_area_faces, "input faces dropped: zero area (three collinear vertices)"),
        (r.dropped_collapsed_patches, "input patches dropped: all their control points are one point"),
        (
            mesh.collapsed_triangles,
            "triangles not emitted: they collapse where a boundary curve is a single point",
        ),
    ];
    for (n, what) in lines {
        if n > 0 {
            eprintln!("repair: {n} {what}");
        }
    }
    if r.flipped {
        eprintln!("repair: the orientation was reversed so that normals point outward");
    }
    serde_json::json!({
        "welded_points": r.welded_points,
        "dropped_degenerate_faces": r.dropped_degenerate_faces,
        "dropped_duplicate_faces": r.dropped_duplicate_faces,
        "dropped_zero_area_faces": r.dropped_zero_area_faces,
        "dropped_collapsed_patches": r.dropped_collapsed_patches,
        "split_polygons": r.split_polygons,
        "skipped_primitives": r.skipped_primitives,
        "collapsed_triangles": mesh.collapsed_triangles,
        "flipped": r.flipped,
    })
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v[v.len() / 2]
}

fn run_mesh(a: MeshArgs) -> CliResult {
    let options = load_options(&a.input_args)?;
    if a.repeat == 0 {
        return Err("--repeat 0: use 1 or more".into());
    }
    if a.max_triangles == Some(0) {
        return Err("--max-triangles 0: use 1 or more".into());
    }
    if let Some(out) = &a.output {
        tessera::io::check_output_path(out)?;
        if !a.force && same_file(out, &a.input) {
            return Err(format!(
                "-o {}: that is the input; write elsewhere, or add --force to replace it",
                out.display()
            )
            .into());
        }
    }
    let pb = spinner(&format!("reading {}", a.input.display()));
    let set = load_surfaces(&a.input, options)?;
    pb.set_message("choosing factors");
    let wants_params = a.measure_error
        || a.output.as_ref().is_some_and(|o| o.extension().is_some_and(|e| e.eq_ignore_ascii_case("ply")));
    let opts = TessellateOptions { strips: a.strips, ..limits(a.max_triangles, wants_params) };
    let max_triangles = opts.max_triangles.unwrap_or(u64::MAX);
    let chosen = plan::choose(&a.criterion, &set, max_triangles)?;
    if chosen.options.cull || !matches!(chosen.criterion, Criterion::Factor(_) | Criterion::Tolerance(_)) {
        plan::note_up_axis(a.criterion.camera.as_deref(), &a.input);
    }
    // Plan and engine errors alike: about a patch, they name the file; about size, they say
    // which limit.
    let explain = |e: tessera::Error| -> Box<dyn std::error::Error> {
        match e {
            tessera::Error::PatchKindNotAccepted { .. } => format!("{}: {e}", a.input.display()).into(),
            e => explain_limit(e, &opts),
        }
    };
    let start = Instant::now();
    let tess_options = TessellatorOptions { plan: chosen.options, engine: opts };
    let mut tess = Tessellator::new(&set, chosen.scheme, chosen.criterion, tess_options).map_err(explain)?;
    let prepare = start.elapsed();
    pb.set_message(format!("tessellating {} patches ({})", set.patches.len(), chosen.description));
    // Every repeat is a whole frame from the camera, criterion to last index, into buffers
    // reused from the last one, as an application re-tessellating every frame would: the
    // median then measures tessellation, not page faults.
    let mut frames = Vec::new();
    // The GPU engine takes the first frame's plan; only it repeats.
    let cpu_frames = if a.engine == plan::EngineArg::Gpu { 1 } else { a.repeat.max(1) };
    for frame in 0..cpu_frames {
        let layout = tess.plan_frame(chosen.options.camera.as_ref()).map_err(explain)?;
        if frame == 0 {
            announce_large_output(layout, &opts, a.output.as_deref());
        }
        tess.write_frame().map_err(explain)?;
        frames.push(tess.timings());
    }
    let plan = tess.plan().expect("a frame was planned");
    let report = tess.report().copied();
    if let Some(r) = &report {
        if r.capped_patches > 0 {
            // Semi-uniform's cap is its highest level, 2^M, not --max-factor.
            let (cap, flag) = if let Scheme::SemiUniform { max_level: m } = chosen.scheme {
                (format!("--max-level {m} (factor {})", a.criterion.max_factor.min(1 << m)), "--max-level")
            } else {
                (format!("--max-factor {}", a.criterion.max_factor), "--max-factor")
            };
            eprintln!(
                "warning: {cap} stopped the error bound on {} patches: the guaranteed bound there is up to {:.3e}, {}× the request; raise {flag}",
                r.capped_patches,
                r.worst_bound,
                ratio(r.worst_ratio)
            );
        }
    }
    if a.strips
        && a.output.as_ref().is_some_and(|o| !o.extension().is_some_and(|e| e.eq_ignore_ascii_case("ply")))
    {
        eprintln!("note: only .ply stores triangle strips; the output gets the decoded triangle list");
    }
    let queues = match &a.instanced {
        Some(path) => {
            let Scheme::SemiUniform { max_level } = chosen.scheme else {
                return Err("--instanced needs --scheme semi-uniform".into());
            };
            let queues = render_queues::build(&set, plan, max_level)?;
            write_instanced(path, &set, &queues)?;
            Some(queues)
        }
        None => None,
    };
    // --engine gpu: the tessellator's plan, tessellated again on the GPU and read back.
    let mut gpu_mesh = Mesh::default();
    let mut gpu_times = Vec::new();
    let mut gpu_run = None;
    if a.engine == plan::EngineArg::Gpu {
        if a.measure_error || a.strips {
            return Err(
                "--engine gpu gives no corner parameters or strips: leave out --measure-error and --strips"
                    .into(),
            );
        }
        let pattern = tess.pattern().expect("a frame was planned");
        let (cull, cap) = (chosen.options.cull, chosen.options.max_factor);
        let camera = chosen.options.camera;
        gpu_run = Some(match (camera, gpu::screen_criterion(chosen.scheme, &chosen.criterion, cull, cap)) {
            // The whole frame from the camera on the GPU (it equals the CPU's plan; tests/gpu.rs).
            (Some(camera), Some(screen)) => {
                gpu::tessellate_from_camera(&set, &camera, screen, a.repeat, &mut gpu_mesh, &mut gpu_times)?
            }
            _ => gpu::tessellate(&set, plan, pattern, a.repeat, &mut gpu_mesh, &mut gpu_times)?,
        });
    }
    if let Some(check) = gpu_run.as_ref().and_then(|r| r.screen).filter(|c| c.checked && !c.converged) {
        eprintln!(
            "warning: the GPU's a-posteriori check needed more than its {} fix rounds: {} patches miss the bound (the mesh is still crack-free)",
            check.rounds, check.failing_patches
        );
    }
    if let (Some(out), Some(_)) = (&a.output, &gpu_run) {
        if out.extension().is_some_and(|e| e.eq_ignore_ascii_case("ply")) {
            eprintln!(
                "note: the GPU engine gives no per-corner patch parameters: {} has no patch_uv, so `tessera check --against` cannot measure its error (--engine cpu writes them)",
                out.display()
            );
        }
    }
    let culled = plan.visible.iter().filter(|&&v| v == 0).count();
    // The numbering rule gives culled patches' corners (and their edges' normal variants)
    // vertices no triangle uses; what is written and counted holds only the used ones. The
    // GPU's mesh is ours to compact; the CPU's belongs to the tessellator.
    let compacted;
    let mesh = if gpu_run.is_some() {
        if culled > 0 {
            gpu_mesh.drop_unused_vertices();
        }
        &gpu_mesh
    } else if culled > 0 {
        let mut copy = tess.mesh().clone();
        copy.drop_unused_vertices();
        compacted = copy;
        &compacted
    } else {
        tess.mesh()
    };
    pb.finish_and_clear();
    let mut output_file = None;
    if let Some(out) = &a.output {
        let start = Instant::now();
        write_with_bar(mesh, out, opts.corner_params)?;
        output_file = Some(start.elapsed().as_secs_f64());
    }
    let repairs = report_repairs(&set, mesh);
    if a.output.is_none() && !a.stats {
        eprintln!(
            "tessellated {} patches into {} triangles and {} vertices; nothing written: give -o OUT to write the mesh, or --stats for the figures",
            set.patches.len(),
            mesh.triangle_count(),
            mesh.vertex_count()
        );
    }
    if culled > 0 {
        eprintln!(
            "note: --cull left out {culled} of {} patches (outside the view or facing away): the mesh is open there",
            set.patches.len()
        );
    }
    // Checked on every run: a mesh that is open, non-manifold or degenerate where the input
    // was not never leaves without a warning and exit status 1.
    let w = verify::watertight(mesh);
    let problems = output_problems(&set, &w, culled);
    if a.stats {
        let stage =
            |f: fn(&FrameTimings) -> Duration| median(frames.iter().map(|t| f(t).as_secs_f64()).collect());
        let seconds = if gpu_run.is_some() { median(gpu_times.clone()) } else { stage(FrameTimings::total) };
        let mut stats = serde_json::json!({
            "input": a.input.display().to_string(),
            "scheme": chosen.description,
            "culled_patches": culled,
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
                "prepare": prepare.as_secs_f64(),
                "criterion": stage(|t| t.criterion),
                "resolve": stage(|t| t.resolve),
                "layout": stage(|t| t.layout),
                "write": stage(|t| t.write),
                "write_vertices": stage(|t| t.write_vertices),
                "write_indices": stage(|t| t.write_indices),
                "output_file": output_file,
            },
            "repairs": repairs,
        });
        if let Some(r) = &report {
            stats["guaranteed_bound"] = r.worst_bound.into();
            stats["bound_met"] = (r.capped_patches == 0).into();
            stats["capped_patches"] = r.capped_patches.into();
        }
        if let Some(t) = chosen.tolerance {
            stats["tolerance"] = t.into();
        }
        if let Some(run) = &gpu_run {
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
        if let Some(q) = &queues {
            let sizes: Vec<usize> = (0..=q.max_level()).map(|m| q.level(m).len()).collect();
            stats["render_queues"] = sizes.into();
        }
        if a.measure_error {
            let e = verify::approximation_error(mesh, &set, 6)?;
            stats["max_error"] = e.max.into();
            stats["rms_error"] = e.rms.into();
        }
        stats["problems"] = problems.clone().into();
        println!("{stats}");
    }
    for p in &problems {
        eprintln!("warning: {p}");
    }
    Ok(if problems.is_empty() { ExitCode::SUCCESS } else { ExitCode::from(1) })
}

/// Whether `a` and `b` name one file (links and `..` resolved); false when either does not
/// exist.
fn same_file(a: &Path, b: &Path) -> bool {
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        _ => false,
    }
}

/// Outputs above this many triangles take more than about a second to write (tessellating
/// runs at 100–500 Mtri/s, formatting and writing a file at 50–500 MB/s): they are announced
/// with their size before the work starts.
const ANNOUNCED_TRIANGLES: u64 = 20_000_000;

/// Says on stderr, before the frame is written, how large a large output will be: its counts,
/// its memory and (with `-o`) about its file size, so a run that will take a while and a lot
/// of disk never starts without a word.
fn announce_large_output(
    layout: &tessera::engine::layout::Layout,
    opts: &TessellateOptions,
    out: Option<&Path>,
) {
    let (vertices, triangles) = (layout.vertex_count() as u64, layout.triangle_count() as u64);
    if triangles < ANNOUNCED_TRIANGLES {
        return;
    }
    let gib = |b: u64| b as f64 / (1u64 << 30) as f64;
    let memory = tessera::mesh::output_bytes(vertices, triangles, opts.corner_params);
    let file = out
        .and_then(|o| {
            let bytes = tessera::io::estimated_file_bytes(o, vertices, triangles, opts.corner_params)?;
            Some(format!(", about {:.1} GiB as {}", gib(bytes), o.display()))
        })
        .unwrap_or_default();
    eprintln!(
        "note: a large output: {triangles} triangles and {vertices} vertices, {:.1} GiB in memory{file}; this takes a while",
        gib(memory)
    );
}

/// Writes `mesh` to `out` with a progress bar in bytes (on a terminal; hidden otherwise).
fn write_with_bar(mesh: &Mesh, out: &Path, corner_params: bool) -> Result<(), tessera::Error> {
    let total = tessera::io::estimated_file_bytes(
        out,
        mesh.vertex_count() as u64,
        mesh.triangle_count() as u64,
        corner_params && mesh.corner_params.is_some(),
    )
    .unwrap_or(0);
    let bar = ProgressBar::new(total);
    bar.set_style(
        ProgressStyle::with_template("writing {msg} {wide_bar} {bytes}/~{total_bytes} [{elapsed}]")
            .expect("static template"),
    );
    bar.set_message(out.display().to_string());
    let written = tessera::io::write_mesh_with_progress(mesh, out, &mut |bytes| {
        // The OBJ estimate is a typical line length: never let the bar run past its end.
        bar.set_length(bar.length().unwrap_or(0).max(bytes));
        bar.set_position(bytes);
    });
    bar.finish_and_clear();
    written
}

/// What is wrong with the output that was not wrong with the input. Culled patches leave
/// holes by request, so with culling only the degeneracies count.
fn output_problems(set: &SurfaceSet, w: &verify::WatertightReport, culled: usize) -> Vec<String> {
    let t = set.topology.report;
    let mut problems = Vec::new();
    if w.degenerate_triangles() > 0 {
        problems.push(format!(
            "the mesh has {} degenerate triangles ({} with two corners at one position, {} of zero area)",
            w.degenerate_triangles(),
            w.collapsed_triangles,
            w.zero_area_triangles
        ));
    }
    // A non-manifold input curve legitimately gives non-manifold output edges, one per segment.
    if w.nonmanifold_edges > 0 && t.nonmanifold_edges == 0 {
        problems.push(format!(
            "the input is manifold but the mesh has {} non-manifold edges",
            w.nonmanifold_edges
        ));
    }
    if w.misoriented_edges > 0 && t.inconsistently_oriented_edges == 0 {
        problems.push(format!("the mesh has {} edges used twice in the same direction", w.misoriented_edges));
    }
    if culled == 0 {
        if t.boundary_edges == 0 && w.boundary_edges > 0 {
            problems
                .push(format!("the input is closed but the mesh has {} boundary edges", w.boundary_edges));
        }
        // Non-manifold inputs too: coincident copies of a patch weld into one surface.
        if w.euler_characteristic != t.euler_characteristic {
            problems.push(format!(
                "the mesh's Euler characteristic is {}, the input's {}: its topology changed (a pinch or a hole)",
                w.euler_characteristic, t.euler_characteristic
            ));
        }
    }
    problems
}

/// Writes the instanced form of a semi-uniform plan (see `--instanced`).
fn write_instanced(
    path: &Path,
    set: &SurfaceSet,
    queues: &RenderQueues,
) -> Result<(), Box<dyn std::error::Error>> {
    let max = queues.max_level();
    let mut domains = Vec::new();
    for (name, domain) in [("tri", Domain::Tri), ("quad", Domain::Quad)] {
        if !set.patches.iter().any(|p| p.domain() == domain) {
            continue;
        }
        let patterns: Vec<serde_json::Value> = StaticPattern::all(domain, max)
            .iter()
            .map(|p| {
                let vertices: Vec<[f32; 3]> = p
                    .vertices
                    .iter()
                    .map(|v| [v.uv[0], v.uv[1], v.edge.map_or(4.0, |e| e as f32 + v.offset)])
                    .collect();
                serde_json::json!({ "level": p.level, "vertices": vertices, "triangles": p.triangles })
            })
            .collect();
        domains.push((name, patterns));
    }
    let levels: Vec<serde_json::Value> = (0..=max)
        .map(|m| {
            let entries: Vec<[u32; 5]> = queues
                .level(m)
                .iter()
                .map(|e| {
                    let l = e.edge_levels.map(u32::from);
                    [e.patch, l[0], l[1], l[2], l[3]]
                })
                .collect();
            serde_json::json!({ "level": m, "entries": entries })
        })
        .collect();
    let mut json = serde_json::json!({ "max_level": max, "queues": levels });
    for (name, patterns) in domains {
        json[name] = patterns.into();
    }
    let text = serde_json::to_string(&json)?;
    std::fs::write(path, text).map_err(|e| format!("{}: {e}", path.display()))?;
    Ok(())
}

fn print_report(mesh: &Mesh, w: &verify::WatertightReport) {
    let q = verify::quality(mesh);
    println!("triangles            {}", w.triangles);
    println!("vertices (welded)    {}", w.vertices);
    println!("boundary edges       {}", w.boundary_edges);
    println!("non-manifold edges   {}", w.nonmanifold_edges);
    println!("misoriented edges    {}", w.misoriented_edges);
    println!(
        "degenerate triangles {} ({} collapsed, {} zero area)",
        w.degenerate_triangles(),
        w.collapsed_triangles,
        w.zero_area_triangles
    );
    println!("Euler characteristic {}", w.euler_characteristic);
    println!(
        "closed               {}",
        if w.is_closed() { "yes (no boundary or non-manifold edge)" } else { "no" }
    );
    println!("min angle            {:.2}°", q.min_angle);
    println!("under 10°            {:.2} %", 100.0 * q.share_below_10_degrees);
    let hist: Vec<String> = q.min_angle_histogram.iter().map(|c| c.to_string()).collect();
    println!("min-angle histogram  {} (5° bins from 0° to 60°)", hist.join(" "));
}

fn run_check(a: CheckArgs) -> CliResult {
    // Checked even without --against, so a bad option never passes unnoticed.
    let build = load_options(&a.input_args)?;
    let pb = spinner(&format!("reading {}", a.mesh.display()));
    let mesh = tessera::io::read_mesh(&a.mesh)?;
    let w = verify::watertight(&mesh);
    pb.finish_and_clear();
    println!("mesh                 {}", a.mesh.display());
    print_report(&mesh, &w);
    let Some(input) = &a.against else { return Ok(ExitCode::SUCCESS) };
    let set = load_surfaces(input, build)?;
    let t = set.topology.report;
    println!("input                {} ({} patches)", input.display(), t.patches);
    println!("input boundary edges {} (curves)", t.boundary_edges);
    println!("input non-manifold   {}", t.nonmanifold_edges);
    println!("input Euler char.    {}", t.euler_characteristic);
    // A mesh made from another input refers to patches the input does not have, or lies far
    // from its surface: say so instead of printing a meaningless error.
    let foreign = mesh.triangle_patch.iter().copied().max().is_some_and(|p| p as usize >= set.patches.len());
    if mesh.corner_params.is_some() && foreign {
        println!(
            "max error            not measured: the mesh refers to patch {} but {} has {} patches: it was not made from this input",
            mesh.triangle_patch.iter().max().unwrap(),
            input.display(),
            set.patches.len()
        );
        return Ok(ExitCode::from(1));
    } else if mesh.corner_params.is_some() {
        let e = verify::approximation_error(&mesh, &set, 6)?;
        println!("max error            {:.6e}", e.max);
        println!("rms error            {:.6e}", e.rms);
        let (lo, hi) = set.bounds();
        let diagonal = lo.distance(hi);
        if e.max > 0.05 * diagonal {
            println!(
                "note: the max error is {:.0}% of the input's bounding-box diagonal: the mesh was probably not made from {}",
                100.0 * e.max / diagonal,
                input.display()
            );
        }
    } else {
        println!("max error            not measured: {} carries no per-corner patch parameters (write .ply with tessera mesh --engine cpu)", a.mesh.display());
    }
    let mismatches = verify::topology_mismatches(&mesh, &w, &set);
    for m in &mismatches {
        println!("FAIL: {m}");
    }
    Ok(if mismatches.is_empty() { ExitCode::SUCCESS } else { ExitCode::from(1) })
}

fn run_demo(a: DemoArgs) -> CliResult {
    tessera::io::check_output_path(&a.output)?;
    let picture = a.picture.clone().unwrap_or_else(|| a.output.with_extension("png"));
    // The picture is PNG bytes: a name that promises another format is refused, as render does.
    if picture.extension().is_none_or(|e| !e.eq_ignore_ascii_case("png")) {
        return Err(format!(
            "--picture {}: the picture is written as PNG: give a .png name",
            picture.display()
        )
        .into());
    }
    let file = tessera::io::patches::parse_patches(TEAPOT, Path::new("<embedded teapot>"))?;
    let set = SurfaceSet::from_patch_file(&file, BuildOptions::default());
    let plan = Plan::uniform(&set, a.factor)?;
    let start = Instant::now();
    let opts = limits(None, true);
    let mesh = engine::tessellate(&set, &plan, &Uniform, opts).map_err(|e| explain_limit(e, &opts))?;
    let seconds = start.elapsed().as_secs_f64();
    tessera::io::write_mesh(&mesh, &a.output)?;
    let w = verify::watertight(&mesh);
    let e = verify::approximation_error(&mesh, &set, 6)?;
    // The verdict first, judged from the mesh's own open edges (see render::boundary_verdict).
    let verdict = render::boundary_verdict(&set, &plan, &Uniform, &mesh)?;
    println!("{}", verdict.sentence("the teapot"));
    println!("Utah teapot: {} bicubic patches, uniform factor {}", set.patches.len(), a.factor);
    println!("wrote                {}", a.output.display());
    match render::demo_picture(&set, &picture) {
        Ok(line) => println!("picture              {line}"),
        Err(err) => println!("picture              not drawn: {err}"),
    }
    println!("tessellation time    {:.3} ms", seconds * 1e3);
    print_report(&mesh, &w);
    let t = set.topology.report;
    println!("input boundary edges {} (curves: rim, lid, handle and spout ends)", t.boundary_edges);
    println!("input Euler char.    {}", t.euler_characteristic);
    let (lo, hi) = set.bounds();
    println!("max error            {:.6e} (bounding-box diagonal {:.3})", e.max, lo.distance(hi));
    println!("rms error            {:.6e}", e.rms);
    if !verdict.watertight() || w.euler_characteristic != t.euler_characteristic {
        println!(
            "crack-free           NO: the output has open edges inside the surface or a changed topology"
        );
        return Ok(ExitCode::from(1));
    }
    println!(
        "crack-free           yes: {} open edges, all on the {} free input curves; Euler characteristic {} as the input's",
        verdict.open_edges, verdict.free_curves, w.euler_characteristic
    );
    Ok(ExitCode::SUCCESS)
}
