//! `tessera`: tessellate parametric surfaces into watertight triangle meshes.

mod bench;
mod gpu;
mod mesh_command;
mod pattern_file;
mod plan;
mod render;
mod view;

use clap::{Args, Parser, Subcommand};
use indicatif::{ProgressBar, ProgressStyle};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::{Duration, Instant};
use tessera::engine::render_queues::RenderQueues;
use tessera::engine::EngineOptions;
use tessera::io::glb::UriScope;
use tessera::io::{LoadOptions, SurfaceKind};
use tessera::mesh::Mesh;
use tessera::pattern::semi_uniform::StaticPattern;
use tessera::pattern::uniform::Uniform;
use tessera::scheme::{Criterion, Scheme};
use tessera::subdivision::isolation::IsolationLevels;
use tessera::surface::Domain;
use tessera::surface::{BuildOptions, Orientation, SurfaceSet};
use tessera::tessellator::{Tessellator, TessellatorOptions};
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
    Mesh(mesh_command::MeshArgs),
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
pub struct InputArgs {
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
    /// The surface a mesh input stands for. `auto`: the Catmull-Clark limit surface of an
    /// OBJ with any face that is not a triangle (a subdivision cage, with OpenSubdiv's tags),
    /// PN triangles for everything else. `loop`: the Loop limit surface of a triangle cage.
    #[arg(long, value_enum, default_value_t = SurfaceArg::Auto)]
    surface: SurfaceArg,
    /// How many levels subdivision cages isolate smooth features (extraordinary vertices,
    /// smooth boundary corners) before Gregory end caps; 2 is OpenSubdiv Bfr's default, more
    /// comes closer to the exact limit surface.
    #[arg(long, value_name = "LEVELS", default_value_t = 2, value_parser = clap::value_parser!(u8).range(1..=10))]
    isolation_smooth: u8,
    /// How many levels subdivision cages isolate sharp features (semi-sharp creases and
    /// corners); 6 is OpenSubdiv Bfr's default.
    #[arg(long, value_name = "LEVELS", default_value_t = 6, value_parser = clap::value_parser!(u8).range(1..=10))]
    isolation_sharp: u8,
}

/// `--surface`.
#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum SurfaceArg {
    Auto,
    Pn,
    CatmullClark,
    Loop,
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
        Command::Mesh(a) => mesh_command::run(a),
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
    let surface = match a.surface {
        SurfaceArg::Auto => SurfaceKind::Auto,
        SurfaceArg::Pn => SurfaceKind::Pn,
        SurfaceArg::CatmullClark => SurfaceKind::CatmullClark,
        SurfaceArg::Loop => SurfaceKind::Loop,
    };
    let isolation = IsolationLevels { smooth: a.isolation_smooth, sharp: a.isolation_sharp };
    Ok(LoadOptions { build, uri_scope, surface, isolation })
}

/// Loads a surface set by extension (`tessera::io::load`: .patches, .bezt, .obj, .ply, .stl,
/// .glb, .gltf), saying on stderr when `--surface auto` took a cage's Catmull-Clark surface.
fn load_surfaces(path: &Path, options: LoadOptions) -> Result<SurfaceSet, tessera::Error> {
    let set = tessera::io::load(path, options)?;
    if options.surface == SurfaceKind::Auto && !set.origins.is_empty() {
        eprintln!(
            "note: {}: faces that are not triangles, so this is a subdivision cage: tessellating its \
             Catmull-Clark limit surface ({} patches; --surface pn for PN triangles)",
            path.display(),
            set.patches.len()
        );
    }
    Ok(set)
}

/// The engine limits for a run (the library's rule,
/// [`EngineOptions::within_available_memory`]).
fn limits(max_triangles: Option<u64>, corner_params: bool) -> EngineOptions {
    EngineOptions::within_available_memory(max_triangles, corner_params)
}

/// The CLI's line for an output the engine refused: the estimate, the memory, and which limit
/// (and flag) stopped it.
fn explain_limit(e: tessera::Error, options: &EngineOptions) -> Box<dyn std::error::Error> {
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

/// One line per kind of repair the input needed, on stderr, and the same as JSON for --stats
/// (the library's list, [`tessera::surface::Repairs::counted`]).
fn report_repairs(set: &SurfaceSet, mesh: &Mesh) -> serde_json::Value {
    let r = &set.repairs;
    let mut json = serde_json::Map::new();
    for (key, n, what) in r.counted(mesh.collapsed_triangles) {
        if n > 0 {
            eprintln!("repair: {n} {what}");
        }
        json.insert(key.to_string(), n.into());
    }
    if r.flipped {
        eprintln!("repair: the orientation was reversed so that normals point outward");
    }
    json.insert("flipped".to_string(), r.flipped.into());
    json.into()
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v[v.len() / 2]
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
fn announce_large_output(layout: &tessera::engine::layout::Layout, opts: &EngineOptions, out: Option<&Path>) {
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

/// What is wrong with the output that was not wrong with the input
/// ([`verify::output_problems`]).
fn output_problems(set: &SurfaceSet, w: &verify::WatertightReport, culled: usize) -> Vec<String> {
    verify::output_problems(&set.topology.report, w, culled)
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
    let start = Instant::now();
    let opts = limits(None, true);
    let options = TessellatorOptions { engine: opts, ..Default::default() };
    let criterion = Criterion::Factor(a.factor as f64);
    let explain = |e| explain_limit(e, &opts);
    let mut tess = Tessellator::new(&set, Scheme::Uniform, criterion, options).map_err(explain)?;
    tess.frame(None).map_err(explain)?;
    let seconds = start.elapsed().as_secs_f64();
    let plan = tess.plan().expect("a frame was planned").clone();
    let mesh = tess.into_mesh();
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
