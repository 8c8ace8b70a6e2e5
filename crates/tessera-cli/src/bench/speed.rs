//! `speed`: uniform tessellation throughput per stage — torus_64x32 and the teapot at
//! factors 4/8/16/32 (and the torus at 64, an output far larger than any cache), PN
//! triangles on the three largest meshes — for each `--threads` count (rayon pools), each
//! row's output rate against the machine's measured fill bandwidth ([`super::memory`]), and
//! the GPU engine on the same plans when an adapter exists.

use super::memory;
use super::plot::{self, Axes, Series};
use super::table::{num, Cell, Table};
use super::{frames, median_p95, scenes, BenchResult, Ctx, StageSeries};
use tessera::camera::Camera;
use tessera::criterion::esc::Threshold;
use tessera::criterion::view::ViewCriterion;
use tessera::criterion::Plan;
use tessera::mesh::Mesh;
use tessera::pattern::hardware::Partitioning;
use tessera::pattern::uniform::Uniform;
use tessera::scheme::{Criterion, Scheme};
use tessera::tessellator::{Tessellator, TessellatorOptions};

/// One measured case: a model at a uniform factor.
struct Case {
    model: &'static str,
    factors: Vec<u32>,
    /// Factors the GPU rows repeat (lavapipe is slow on the largest outputs).
    gpu_factors: Vec<u32>,
}

fn cases(quick: bool) -> Vec<Case> {
    let case = |model, factors: &[u32], gpu: &[u32]| Case {
        model,
        factors: factors.to_vec(),
        gpu_factors: gpu.to_vec(),
    };
    if quick {
        return vec![
            case("bench/torus_64x32.patches", &[4, 8], &[]),
            case("patches/teapot.patches", &[4, 8], &[8]),
            case("meshes/spot.obj", &[4], &[]),
        ];
    }
    vec![
        // Factor 64: 16.8 M triangles, 0.6 GB of output, beyond every L3.
        case("bench/torus_64x32.patches", &[4, 8, 16, 32, 64], &[4, 8, 16]),
        case("patches/teapot.patches", &[4, 8, 16, 32], &[16]),
        // The three largest meshes of the shared folder (88.9k, 69.5k and 52k triangles).
        case("meshes/elephant_refined.obj", &[4], &[4]),
        case("meshes/bunny.obj", &[4], &[]),
        case("meshes/armadillo.obj", &[4], &[]),
    ]
}

pub fn run(ctx: &Ctx) -> BenchResult<Vec<Table>> {
    let runs = if ctx.quick { 3 } else { 15 };
    let cases = cases(ctx.quick);
    let cpu_steps: usize = cases.iter().map(|c| c.factors.len() * ctx.threads.len()).sum();
    let gpu_steps: usize = cases.iter().map(|c| c.gpu_factors.len()).sum();
    ctx.plan_steps((cpu_steps + gpu_steps) as u64);
    let adapter = if ctx.gpu { gpu_adapter(ctx) } else { None };
    // The fill rate of each pool, measured before the rows (a GiB: beyond any L3 today).
    let fill_bytes = if ctx.quick { 256 << 20 } else { 1 << 30 };
    ctx.plan_steps(ctx.threads.len() as u64);
    let mut fill = Vec::new();
    for &threads in &ctx.threads {
        ctx.step(&format!("speed: memory fill bandwidth, {threads} threads"));
        fill.push(ctx.on_threads(threads, || memory::fill_bandwidth(fill_bytes, 5))?);
    }

    let mut columns = vec!["model", "patches", "factor", "engine", "threads"];
    columns.extend(STAGE_COLUMNS);
    columns.extend(["output GB/s", "% of fill bandwidth"]);
    let mut table = Table::new("speed_uniform", "speed: uniform tessellation, medians per stage", &columns);
    let pass_columns: Vec<String> = ["model", "factor", "adapter"]
        .iter()
        .map(|c| c.to_string())
        .chain(tessera_gpu::tessellator::PASSES.iter().map(|p| format!("{p} ms")))
        .collect();
    let mut gpu_passes = Table::new(
        "speed_gpu_passes",
        "speed: GPU engine, median ms per compute pass (timestamp queries)",
        &pass_columns.iter().map(String::as_str).collect::<Vec<_>>(),
    );
    let mut curves: Vec<Series> = Vec::new();
    for case in &cases {
        let set = scenes::load(ctx, case.model)?;
        let name = short(case.model);
        for (&threads, &fill) in ctx.threads.iter().zip(&fill) {
            let mut curve = Series { name: format!("{name}, {threads} thr"), points: Vec::new() };
            for &factor in &case.factors {
                ctx.step(&format!("speed: {name} factor {factor}, {threads} threads"));
                let series = ctx.on_threads(threads, || {
                    let mut tess = Tessellator::new(
                        &set,
                        Scheme::Uniform,
                        Criterion::Factor(factor as f64),
                        TessellatorOptions::default(),
                    )?;
                    frames(&mut tess, &vec![None; runs], true)
                })??;
                let (cells, mtri) = stage_cells(&series);
                curve.points.push((factor as f64, mtri));
                let mut row: Vec<Cell> = vec![
                    name.clone().into(),
                    set.patches.len().into(),
                    (factor as usize).into(),
                    "cpu".into(),
                    threads.into(),
                ];
                row.extend(cells);
                let bytes =
                    tessera::mesh::output_bytes(series.vertices[0] as u64, series.triangles[0] as u64, false);
                let rate = bytes as f64 / median_p95(&series.total).0 / 1e6;
                row.extend([num(rate, 2), num(100.0 * rate / fill, 0)]);
                table.row(row);
            }
            curves.push(curve);
        }
        let Some(adapter) = &adapter else { continue };
        let mut curve = Series { name: format!("{name}, gpu"), points: Vec::new() };
        for &factor in &case.gpu_factors {
            ctx.step(&format!("speed: {name} factor {factor} on the GPU"));
            let plan = Plan::uniform(&set, factor)?;
            let mut mesh = Mesh::default();
            let mut times = Vec::new();
            let gpu = crate::gpu::tessellate(
                &set,
                &plan,
                &Uniform,
                crate::gpu::Output::TRIANGLES,
                runs as u32,
                &mut mesh,
                &mut times,
            )?;
            let wall: Vec<f64> = times.iter().map(|s| s * 1e3).collect();
            let (total, p95) = median_p95(&wall);
            let (tri, vert) = (mesh.triangle_count(), mesh.vertex_count());
            let mtri = tri as f64 / total / 1e3;
            curve.points.push((factor as f64, mtri));
            table.row(vec![
                name.clone().into(),
                set.patches.len().into(),
                (factor as usize).into(),
                format!("gpu ({adapter})").into(),
                Cell::None,
                tri.into(),
                vert.into(),
                Cell::None,
                Cell::None,
                Cell::None,
                Cell::None,
                Cell::None,
                num(total, 3),
                num(p95, 3),
                num(mtri, 1),
                num(total * 1e6 / vert as f64, 2),
                Cell::None,
                Cell::None,
            ]);
            if !gpu.passes_ms.is_empty() {
                let mut row: Vec<Cell> =
                    vec![name.clone().into(), (factor as usize).into(), adapter.clone().into()];
                row.extend(gpu.passes_ms.iter().map(|&(_, ms)| num(ms, 3)));
                gpu_passes.row(row);
            }
        }
        if !curve.points.is_empty() {
            curves.push(curve);
        }
    }
    let schemes = schemes_table(ctx, runs)?;
    table.note(format!(
        "Medians of {runs} frames after one warm-up frame, each a whole `Tessellator::frame` into reused buffers \
         (criterion → resolve → layout → write, the stages `tessera mesh --stats` reports); Mtri/s = triangles / \
         frame median; ns/vertex = frame median / vertices. CPU rows run in rayon pools of the given size."
    ));
    let l3 = tessera::engine::last_level_cache_bytes()
        .map_or("unknown (no sysfs)".to_string(), |b| format!("{} MiB", b >> 20));
    let rates: Vec<String> =
        ctx.threads.iter().zip(&fill).map(|(t, f)| format!("{f:.1} GB/s with {t} thread(s)")).collect();
    table.note(format!(
        "Memory: L3 {l3}; fill bandwidth {} (median of 5 in-process fills of a {} MiB buffer, `slice::fill` = \
         memset, one contiguous share a thread). Output GB/s = the frame's output bytes (36 a vertex: position, \
         normal, uv, patch; 16 a triangle: indices, patch) / frame median; a frame whose output exceeds the L3 \
         is bounded by the fill bandwidth, one that fits may exceed it.",
        rates.join(", "),
        fill_bytes >> 20
    ));
    match &adapter {
        Some(a) => table.note(format!(
            "GPU rows: tessera-gpu on {a}, the CPU's uniform plan; frame = submit to finished (wall clock, \
             medians of {runs}); the adapter is {}.",
            if a.contains("llvmpipe") {
                "Mesa's software rasteriser (lavapipe), for correctness, not speed"
            } else {
                "a hardware GPU"
            }
        )),
        None => table.note("GPU rows: none (no wgpu adapter, or --no-gpu)."),
    }
    let svg = ctx.out.join("speed_uniform.svg");
    plot::lines(
        &svg,
        &Axes {
            title: "uniform tessellation throughput",
            x: "factor",
            y: "Mtri/s (frame median)",
            log_x: true,
            log_y: false,
        },
        &curves,
    )?;
    let mut tables = vec![table, schemes];
    if !gpu_passes.rows.is_empty() {
        tables.push(gpu_passes);
    }
    Ok(tables)
}

/// Triangles, vertices, each stage's median, the frame's median and p95, Mtri/s and ns per
/// vertex of a series of frames (the columns after a row's labels), and the Mtri/s.
fn stage_cells(series: &StageSeries) -> (Vec<Cell>, f64) {
    let med = |v: &Vec<f64>| num(median_p95(v).0, 3);
    let (total, p95) = median_p95(&series.total);
    let (tri, vert) = (series.triangles[0], series.vertices[0]);
    let mtri = tri as f64 / total / 1e3;
    let cells = vec![
        tri.into(),
        vert.into(),
        med(&series.criterion),
        med(&series.resolve),
        med(&series.layout),
        med(&series.write_vertices),
        med(&series.write_indices),
        num(total, 3),
        num(p95, 3),
        num(mtri, 1),
        num(total * 1e6 / vert as f64, 2),
    ];
    (cells, mtri)
}

/// The columns after a row's labels ([`stage_cells`]).
const STAGE_COLUMNS: [&str; 11] = [
    "triangles",
    "vertices",
    "criterion ms",
    "resolve ms",
    "layout ms",
    "vertices ms",
    "indices ms",
    "frame ms",
    "frame p95 ms",
    "Mtri/s",
    "ns/vertex",
];

/// The adaptive and hardware schemes' engines: the cow with
/// silhouette factors 4:7 (transition, semi-uniform, SD-2), fractional-odd at factor 6.4,
/// the torus at a tolerance of 0.001 % of its diagonal, ESC on the teapot; the framing
/// camera at 1280×720 (`tessera mesh`'s default).
fn schemes_table(ctx: &Ctx, runs: usize) -> BenchResult<Table> {
    let mut columns = vec!["model", "scheme", "criterion", "threads"];
    columns.extend(STAGE_COLUMNS);
    let mut t = Table::new("speed_schemes", "speed: every scheme's engine, medians per stage", &columns);
    let silhouette = |criterion, fmin| Criterion::View { criterion, fmin, fmax: 7.0 };
    let cases: Vec<(&str, Scheme, Criterion, &str)> = vec![
        (
            "meshes/cow.obj",
            Scheme::Transition,
            silhouette(ViewCriterion::Silhouetteness, 4.0),
            "--silhouette 4:7",
        ),
        (
            "meshes/cow.obj",
            Scheme::SemiUniform { max_level: 5 },
            silhouette(ViewCriterion::Silhouetteness, 4.0),
            "--silhouette 4:7",
        ),
        (
            "meshes/cow.obj",
            Scheme::Sd2 { warp: false },
            silhouette(ViewCriterion::SilhouetteVertices, 4.0),
            "--silhouette 4:7",
        ),
        (
            "meshes/cow.obj",
            Scheme::Hardware(Partitioning::FractionalOdd),
            Criterion::Factor(6.4),
            "--factor 6.4",
        ),
        ("bench/torus_64x32.patches", Scheme::Transition, Criterion::Tolerance(0.0), "--tolerance 0.001%"),
        (
            "patches/teapot.patches",
            Scheme::Esc { max_level: 3 },
            Criterion::Esc { threshold: Threshold::Medium, level: None },
            "--quality medium",
        ),
    ];
    let cases = if ctx.quick { &cases[..1] } else { &cases[..] };
    ctx.plan_steps((cases.len() * ctx.threads.len()) as u64);
    for (rel, scheme, criterion, text) in cases {
        let set = scenes::load(ctx, rel)?;
        let (lo, hi) = set.bounds();
        let criterion = match criterion {
            Criterion::Tolerance(_) => Criterion::Tolerance(1e-5 * lo.distance(hi)),
            c => *c,
        };
        let camera = Some(Camera::framing(lo, hi, 1280, 720));
        for &threads in &ctx.threads {
            ctx.step(&format!("speed: {} {}, {threads} threads", short(rel), scheme.name()));
            let series = ctx.on_threads(threads, || {
                let mut tess = Tessellator::new(&set, *scheme, criterion, TessellatorOptions::default())?;
                frames(&mut tess, &vec![camera; runs], true)
            })??;
            let mut row: Vec<Cell> =
                vec![short(rel).into(), scheme.name().into(), (*text).into(), threads.into()];
            row.extend(stage_cells(&series).0);
            t.row(row);
        }
    }
    t.note(format!(
        "Medians of {runs} frames from the framing camera (1280×720), after a warm-up frame; criteria as \
         `tessera mesh` takes them (silhouetteness for transition and semi-uniform, vertex silhouettes for SD-2)."
    ));
    Ok(t)
}

/// The adapter's name when the GPU rows can run; otherwise a printed note and None (the bench
/// is not a test: a machine without a GPU gets CPU figures).
pub(super) fn gpu_adapter(ctx: &Ctx) -> Option<String> {
    match tessera_gpu::GpuContext::new() {
        Ok(gpu) => Some(gpu.info.name.clone()),
        Err(e) => {
            ctx.note(&format!("no GPU rows: {e}"));
            None
        }
    }
}

/// A model's file name without folder and extension.
pub fn short(rel: &str) -> String {
    let name = rel.rsplit('/').next().unwrap_or(rel);
    name.split('.').next().unwrap_or(name).to_string()
}
