//! `tessera bench`: the project's figures from one command — throughput per stage (`speed`),
//! triangles against measured error per scheme (`adaptive`), camera walk-throughs of large
//! scenes (`frame`) and the papers' tables beside the papers' own figures (`paper`).
//!
//! Every suite fills [`table::Table`]s: printed as Markdown on stdout, written as CSV and, per
//! suite, one JSON file to `--out`, with SVG plots beside them ([`plot`]). Triangle counts are
//! deterministic (fixed models, seeded cameras, fixed walks); times are medians.

mod adaptive;
mod frame;
mod memory;
mod paper;
mod plot;
mod scenes;
mod speed;
mod subdivision;
mod table;

use clap::{Args, ValueEnum};
use indicatif::{ProgressBar, ProgressStyle};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::{Duration, Instant};
use table::Table;
use tessera::camera::Camera;
use tessera::tessellator::{FrameTimings, Tessellator};

/// The suites, in the order they run.
#[derive(Clone, Copy, PartialEq, Eq, Debug, ValueEnum)]
pub enum Suite {
    /// Uniform factors 4/8/16/32 (torus_64x32, teapot) and PN triangles on the three largest
    /// meshes: per-stage medians, Mtri/s and ns per vertex, per thread count; GPU rows when
    /// an adapter exists.
    Speed,
    /// Triangles against measured max error for every scheme on each patch model and three
    /// meshes, and the ratio to uniform at equal measured error; one SVG per model.
    Adaptive,
    /// 60-frame camera walks through the 92,160-patch torus grid, the killeroo herd (PN) and
    /// the 100 teacups: ms per stage (median, p95) and triangles per frame, with plots.
    Frame,
    /// Papers 000 (Table 1), 001 (Tables 1–2), 002 (Table 1) and 003 (Tables 1–2) beside the
    /// papers' own figures.
    Paper,
    /// Catmull-Clark and Loop cages copied past 50,000 faces (the regular torus, the creased
    /// rook, Loop's extraordinary vertices):
    /// uniform at Bfr's rate 16 and adaptive at 0.5 px, beside OpenSubdiv's Bfr on the same
    /// cage and rates when `tools/osd-oracle/bfr_bench` is built (--bfr).
    Subdivision,
}

impl Suite {
    fn name(self) -> &'static str {
        match self {
            Suite::Speed => "speed",
            Suite::Adaptive => "adaptive",
            Suite::Frame => "frame",
            Suite::Paper => "paper",
            Suite::Subdivision => "subdivision",
        }
    }
}

#[derive(Args)]
pub struct BenchArgs {
    /// Suite to run (repeat the flag for several; default: all five).
    #[arg(long = "suite", value_enum, value_name = "S")]
    suites: Vec<Suite>,
    /// Folder for the CSV, JSON and SVG files (created if missing).
    #[arg(long, value_name = "DIR", default_value = "bench-out")]
    out: PathBuf,
    /// Reduced sizes (fewer factors, runs, frames, copies): every suite in well under a
    /// minute. Triangle counts stay deterministic, but differ from the full run's.
    #[arg(long)]
    quick: bool,
    /// Thread counts of the CPU rows (rayon pools), comma-separated.
    #[arg(long, value_name = "N,..", value_delimiter = ',', default_value = "1,2")]
    threads: Vec<usize>,
    /// The shared model folder (default: $TESSERA_DATA, else ../shared/data).
    #[arg(long, value_name = "DIR")]
    data: Option<PathBuf>,
    /// Leave out the GPU rows even when a wgpu adapter exists.
    #[arg(long)]
    no_gpu: bool,
    /// OpenSubdiv's Bfr benchmark for the subdivision suite's Bfr columns (built by
    /// tools/osd-oracle/bfr_bench.sh; default: tools/osd-oracle/bfr_bench when it exists).
    #[arg(long, value_name = "PATH")]
    bfr: Option<PathBuf>,
}

/// What every suite gets: options, the model folder, the progress bar.
pub struct Ctx {
    quick: bool,
    threads: Vec<usize>,
    data: PathBuf,
    gpu: bool,
    out: PathBuf,
    pb: ProgressBar,
}

impl Ctx {
    /// A model of the shared folder, with a clear error when it is missing.
    fn model(&self, rel: &str) -> Result<PathBuf, String> {
        let p = self.data.join(rel);
        if p.exists() {
            Ok(p)
        } else {
            Err(format!(
                "{}: missing; give the shared model folder with --data DIR or TESSERA_DATA",
                p.display()
            ))
        }
    }

    /// Announces `n` more steps of work on the progress bar.
    fn plan_steps(&self, n: u64) {
        self.pb.inc_length(n);
    }

    /// One step done; `what` is the next step's description.
    fn step(&self, what: &str) {
        self.pb.inc(1);
        self.pb.set_message(what.to_string());
    }

    /// A note for the reader, printed above the progress bar (stderr).
    fn note(&self, text: &str) {
        self.pb.suspend(|| eprintln!("note: {text}"));
    }

    /// Runs `f` on a rayon pool of `threads` threads (the CPU rows' thread counts).
    fn on_threads<T: Send>(&self, threads: usize, f: impl FnOnce() -> T + Send) -> Result<T, String> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .map_err(|e| format!("a pool of {threads} threads: {e}"))?;
        Ok(pool.install(f))
    }
}

/// Errors cross the rayon pools, so they are `Send + Sync`.
pub type BenchResult<T> = Result<T, Box<dyn std::error::Error + Send + Sync>>;

/// `tessera bench`.
pub fn run(a: BenchArgs) -> Result<ExitCode, Box<dyn std::error::Error>> {
    run_suites(a).map_err(|e| e as Box<dyn std::error::Error>)
}

fn run_suites(a: BenchArgs) -> BenchResult<ExitCode> {
    if a.threads.is_empty() || a.threads.contains(&0) {
        return Err("--threads: give thread counts of 1 or more, e.g. 1,2".into());
    }
    let data = a.data.clone().unwrap_or_else(|| {
        std::env::var("TESSERA_DATA").map(PathBuf::from).unwrap_or_else(|_| PathBuf::from("../shared/data"))
    });
    if !data.is_dir() {
        return Err(format!(
            "{}: no model folder there; give the shared model folder with --data DIR or TESSERA_DATA",
            data.display()
        )
        .into());
    }
    std::fs::create_dir_all(&a.out).map_err(|e| format!("{}: {e}", a.out.display()))?;
    let mut suites = a.suites.clone();
    if suites.is_empty() {
        suites = vec![Suite::Speed, Suite::Adaptive, Suite::Frame, Suite::Paper, Suite::Subdivision];
    }
    suites.dedup();
    let pb = ProgressBar::new(0);
    pb.set_style(
        ProgressStyle::with_template("{bar:30} {pos}/{len} [{elapsed}] {msg}").expect("static template"),
    );
    pb.enable_steady_tick(Duration::from_millis(200));
    let ctx =
        Ctx { quick: a.quick, threads: a.threads.clone(), data, gpu: !a.no_gpu, out: a.out.clone(), pb };
    let machine = machine();
    println!("# tessera bench{}\n", if ctx.quick { " --quick" } else { "" });
    println!("machine: {}\n", machine_line(&machine));
    for suite in suites {
        let start = Instant::now();
        let tables = match suite {
            Suite::Speed => speed::run(&ctx)?,
            Suite::Adaptive => adaptive::run(&ctx)?,
            Suite::Frame => frame::run(&ctx)?,
            Suite::Paper => paper::run(&ctx)?,
            Suite::Subdivision => subdivision::run(&ctx, a.bfr.as_deref())?,
        };
        let seconds = start.elapsed().as_secs_f64();
        ctx.pb.suspend(|| {
            for t in tables.iter().filter(|t| t.print) {
                print!("{}", t.markdown());
            }
        });
        write_suite(&ctx.out, suite.name(), &tables, &machine, seconds, ctx.quick)?;
        ctx.pb.suspend(|| eprintln!("{} suite: {seconds:.1} s", suite.name()));
    }
    ctx.pb.finish_and_clear();
    println!("files in {}", a.out.display());
    Ok(ExitCode::SUCCESS)
}

/// The CSV of each table and the suite's JSON (machine, run time, every table).
fn write_suite(
    out: &Path,
    suite: &str,
    tables: &[Table],
    machine: &serde_json::Value,
    seconds: f64,
    quick: bool,
) -> BenchResult<()> {
    for t in tables {
        let path = out.join(format!("{}.csv", t.name));
        std::fs::write(&path, t.csv()).map_err(|e| format!("{}: {e}", path.display()))?;
    }
    let json = serde_json::json!({
        "suite": suite,
        "quick": quick,
        "seconds": seconds,
        "machine": machine,
        "tables": tables.iter().map(Table::json).collect::<Vec<_>>(),
    });
    let path = out.join(format!("{suite}.json"));
    std::fs::write(&path, serde_json::to_string_pretty(&json)?)
        .map_err(|e| format!("{}: {e}", path.display()))?;
    Ok(())
}

/// The CPU model, core count and load average (Linux; "unknown" elsewhere), so that a figure
/// says what it was measured on and whether the machine was busy.
fn machine() -> serde_json::Value {
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|c| {
            c.lines()
                .find(|l| l.starts_with("model name"))
                .map(|l| l.split(':').nth(1).unwrap_or("").trim().to_string())
        })
        .unwrap_or_else(|| "unknown".into());
    let cores = std::thread::available_parallelism().map_or(0, |n| n.get());
    let load = std::fs::read_to_string("/proc/loadavg")
        .ok()
        .and_then(|l| l.split_whitespace().next().and_then(|x| x.parse::<f64>().ok()));
    let l3 = tessera::engine::last_level_cache_bytes();
    serde_json::json!({ "cpu": cpu, "cores": cores, "l3_bytes": l3, "load_1min_at_start": load })
}

fn machine_line(m: &serde_json::Value) -> String {
    let load = m["load_1min_at_start"].as_f64().map_or("unknown".into(), |l| format!("{l:.2}"));
    let l3 = m["l3_bytes"].as_u64().map_or("L3 size unknown".into(), |b| format!("L3 {} MiB", b >> 20));
    format!(
        "{}, {} cores available, {l3}, 1-minute load average {load} at the start",
        m["cpu"].as_str().unwrap_or("?"),
        m["cores"]
    )
}

/// Median and 95th percentile (nearest rank) of a sample; zeros for an empty one.
pub fn median_p95(v: &[f64]) -> (f64, f64) {
    if v.is_empty() {
        return (0.0, 0.0);
    }
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    let p95 = s[((0.95 * s.len() as f64).ceil() as usize).clamp(1, s.len()) - 1];
    (crate::median(s), p95)
}

/// Per-stage times of a series of frames, in ms.
#[derive(Default, Clone)]
pub struct StageSeries {
    pub criterion: Vec<f64>,
    pub resolve: Vec<f64>,
    pub layout: Vec<f64>,
    pub write: Vec<f64>,
    pub write_vertices: Vec<f64>,
    pub write_indices: Vec<f64>,
    pub total: Vec<f64>,
    pub triangles: Vec<usize>,
    pub vertices: Vec<usize>,
    /// Patches the plan left out (culling).
    pub culled: Vec<usize>,
}

impl StageSeries {
    fn push(&mut self, t: FrameTimings, triangles: usize, vertices: usize) {
        let ms = |d: Duration| d.as_secs_f64() * 1e3;
        self.criterion.push(ms(t.criterion));
        self.resolve.push(ms(t.resolve));
        self.layout.push(ms(t.layout));
        self.write.push(ms(t.write));
        self.write_vertices.push(ms(t.write_vertices));
        self.write_indices.push(ms(t.write_indices));
        self.total.push(ms(t.total()));
        self.triangles.push(triangles);
        self.vertices.push(vertices);
    }

    /// Appends `other`'s frames after this series' own.
    pub fn append(&mut self, mut other: StageSeries) {
        self.criterion.append(&mut other.criterion);
        self.resolve.append(&mut other.resolve);
        self.layout.append(&mut other.layout);
        self.write.append(&mut other.write);
        self.write_vertices.append(&mut other.write_vertices);
        self.write_indices.append(&mut other.write_indices);
        self.total.append(&mut other.total);
        self.triangles.append(&mut other.triangles);
        self.vertices.append(&mut other.vertices);
        self.culled.append(&mut other.culled);
    }

    /// The stages with their names, in pipeline order, then the whole frame.
    fn stages(&self) -> [(&'static str, &Vec<f64>); 5] {
        [
            ("criterion", &self.criterion),
            ("resolve", &self.resolve),
            ("layout", &self.layout),
            ("write", &self.write),
            ("total", &self.total),
        ]
    }
}

/// Frames of `tess` for each camera in `cameras` (None: one camera-less frame per run,
/// `runs` times), after one warm-up frame that grows the buffers, with each stage's time
/// ([`Tessellator::timings`], the same figures `tessera mesh --stats` reports).
pub fn frames(
    tess: &mut Tessellator<'_>,
    cameras: &[Option<Camera>],
    warm_up: bool,
) -> tessera::Result<StageSeries> {
    let mut series = StageSeries::default();
    if warm_up {
        if let Some(c) = cameras.first() {
            tess.frame(c.as_ref())?;
        }
    }
    for c in cameras {
        let mesh = tess.frame(c.as_ref())?;
        let (t, v) = (mesh.triangle_count(), mesh.vertex_count());
        series.push(tess.timings(), t, v);
        series.culled.push(tess.plan().map_or(0, tessera::criterion::Plan::culled_count));
    }
    Ok(series)
}

/// An integer with its thousands separated by commas (Markdown cells).
pub fn thousands(n: u64) -> String {
    let s = n.to_string();
    let mut out = String::new();
    for (i, c) in s.chars().enumerate() {
        if i > 0 && (s.len() - i) % 3 == 0 {
            out.push(',');
        }
        out.push(c);
    }
    out
}
