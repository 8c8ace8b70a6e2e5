//! `subdivision`: Catmull-Clark and Loop cages against OpenSubdiv's Bfr, the reference —
//! uniform tessellation at Bfr's rate 16 and adaptive tessellation at half a pixel, on cages
//! copied past 50,000 faces (`catmark_torus`, all regular; `catmark_rook`, triangles and
//! semi-sharp creases; `loop_xord_interior`, Loop with extraordinary vertices next to every
//! face; `killeroo_cage`, pbrt's Loop control mesh of a scanned figure, mostly regular), per
//! thread count.
//!
//! Bfr's figures come from `tools/osd-oracle/bfr_bench` (a C++ program linked against
//! OpenSubdiv, built by `tools/osd-oracle/bfr_bench.sh`; tessera does not link OpenSubdiv),
//! run on the same cage with the same copies: `--rate 16` for the uniform rows, and for the
//! adaptive rows the rates tessera's own plan chose, face by face and edge by edge
//! ([`face_rates`]), so both tessellate the same edges into the same segments. Without the
//! program the tessera columns are still measured and a note says how to build it.
//!
//! The two alternate, round by round (a tessera frame, then a call of `bfr_bench` with one
//! warm-up pass and one timed pass), and each side's median over the rounds is reported: on
//! a shared host whose speed moved by up to half from one minute to the next, a ratio of
//! tessera's frames to Bfr's passes timed a minute later read anywhere from 2.3× to 4.1× on
//! one machine in one evening.

use super::table::{num, Cell, Table};
use super::{frames, median_p95, scenes, BenchResult, Ctx, StageSeries};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use tessera::criterion::Plan;
use tessera::scheme::{Criterion, PlanOptions, Scheme};
use tessera::subdivision::CageOptions;
use tessera::surface::{PolygonMesh, SurfaceSet};
use tessera::tessellator::{Tessellator, TessellatorOptions};

/// One cage and how many copies of it the suite tessellates.
struct Case {
    model: &'static str,
    copies: usize,
    /// A Loop cage (else Catmull-Clark).
    loop_: bool,
}

fn cases(quick: bool) -> Vec<Case> {
    if quick {
        return vec![
            Case { model: "subdivision/catmark_torus.obj", copies: 16, loop_: false },
            Case { model: "subdivision/catmark_torus_creases0.obj", copies: 4, loop_: false },
            // Triangles and a quad, so split into sub-faces, with creases.
            Case { model: "subdivision/catmark_pyramid_creases0.obj", copies: 16, loop_: false },
            // Loop, semi-sharp creases.
            Case { model: "subdivision/loop_cube_creases0.obj", copies: 16, loop_: true },
        ];
    }
    vec![
        // 32 faces × 1,563 = 50,016 and 777 × 65 = 50,505: the "≥ 50k faces".
        Case { model: "subdivision/catmark_torus.obj", copies: 1563, loop_: false },
        Case { model: "subdivision/catmark_rook.obj", copies: 65, loop_: false },
        // Loop (issue 28): 69 triangles with extraordinary vertices × 725 = 50,025.
        Case { model: "subdivision/loop_xord_interior.obj", copies: 725, loop_: true },
        // A real Loop cage (pbrt's `loopsubdiv` Killeroo): 8,316 triangles × 7 = 58,212.
        Case { model: "meshes/killeroo_cage.obj", copies: 7, loop_: true },
    ]
}

/// Bfr's uniform rate; tessera's factor is this on whole quads and half of it on sub-faces
/// (a face split into sub-faces has each of its edges cut into two halves).
const BFR_RATE: u32 = 16;

/// The program that measures Bfr: `--bfr`, else `tools/osd-oracle/bfr_bench` under the
/// current folder when it is there.
pub fn bfr_program(given: Option<&Path>) -> Option<PathBuf> {
    match given {
        Some(p) => Some(p.to_path_buf()),
        None => Some(PathBuf::from("tools/osd-oracle/bfr_bench")).filter(|p| p.is_file()),
    }
}

pub fn run(ctx: &Ctx, bfr: Option<&Path>) -> BenchResult<Vec<Table>> {
    let runs = if ctx.quick { 3 } else { 5 };
    let bfr = bfr_program(bfr);
    if bfr.is_none() {
        ctx.note(
            "no Bfr columns: build tools/osd-oracle/bfr_bench (tools/osd-oracle/bfr_bench.sh, needs g++ and \
             libosd-dev) and run from the repository root, or give --bfr PATH",
        );
    }
    let cases = cases(ctx.quick);
    ctx.plan_steps((cases.len() * 2 * ctx.threads.len()) as u64);
    let mut table = Table::new(
        "subdivision_bfr",
        "subdivision: Catmull-Clark cages, tessera against OpenSubdiv's Bfr",
        &[
            "model",
            "faces",
            "tessellation",
            "threads",
            "tessera triangles",
            "tessera ms",
            "tessera Mtri/s",
            "Bfr triangles",
            "Bfr ms",
            "Bfr Mtri/s",
            "tessera / Bfr",
            "tessera Mtri/s given the plan",
            "given the plan / Bfr",
            "tessera's dominant stage",
        ],
    );
    let mut loads = Vec::new();
    for case in &cases {
        let path = ctx.model(case.model)?;
        let name = super::speed::short(case.model);
        ctx.step(&format!("subdivision: loading {name} × {}", case.copies));
        let start = std::time::Instant::now();
        let mesh = tessera::scene::mesh_grid(&tessera::io::obj::read_obj(&path)?, case.copies);
        let set = if case.loop_ {
            SurfaceSet::from_loop_cage(&mesh, &path, CageOptions::default())?
        } else {
            SurfaceSet::from_subdivision_cage(&mesh, &path, CageOptions::default())?
        };
        loads.push(format!("{name} × {}: {:.1} s", case.copies, start.elapsed().as_secs_f64()));
        let split = set.origins.iter().any(|o| o.is_subface);
        let factor = if split { BFR_RATE / 2 } else { BFR_RATE };
        let (lo, hi) = set.bounds();
        // Halfway along the frame suite's walk: the near copies large, the far ones small.
        let camera = scenes::walk(lo, hi, 3, 1280, 1024)[1];
        let rates_file = ctx.out.join(format!("subdivision_{name}_rates.txt"));
        for adaptive in [false, true] {
            let (scheme, criterion, what) = if adaptive {
                (Scheme::Transition, Criterion::PixelError(0.5), "transition 0.5 px".to_string())
            } else {
                (Scheme::Uniform, Criterion::Factor(factor as f64), format!("uniform, Bfr rate {BFR_RATE}"))
            };
            for &threads in &ctx.threads {
                ctx.step(&format!("subdivision: {name} {what}, {threads} threads"));
                let options = TessellatorOptions {
                    plan: PlanOptions { cull: false, ..PlanOptions::default() },
                    ..Default::default()
                };
                let mut tess = Tessellator::new(&set, scheme, criterion, options)?;
                let scheme_args =
                    ["--scheme".to_string(), if case.loop_ { "loop" } else { "catmark" }.into()];
                let mut rate_args = ["--rate".to_string(), BFR_RATE.to_string()];
                // Rounds that alternate the two, so that both sample the same moments of a
                // shared host (whose speed moved by up to half from minute to minute while
                // one ran its passes after the other's).
                let mut series = StageSeries::default();
                let mut bfr_passes = Vec::new();
                for round in 0..runs {
                    let (frames, rates) = ctx.on_threads(threads, || -> BenchResult<_> {
                        // A fresh pool: one frame warms its threads, then one is timed.
                        let frames = frames(&mut tess, &[Some(camera)], true)?;
                        let plan = tess.plan().ok_or("the frame left no plan")?;
                        Ok((frames, (adaptive && round == 0).then(|| face_rates(&set, plan, &mesh))))
                    })??;
                    series.append(frames);
                    if let Some(rates) = rates {
                        std::fs::write(&rates_file, rates?)
                            .map_err(|e| format!("{}: {e}", rates_file.display()))?;
                        rate_args = ["--adaptive-rates".into(), rates_file.display().to_string()];
                    }
                    if let Some(program) = &bfr {
                        let args = [rate_args.clone(), scheme_args.clone()].concat();
                        bfr_passes.push(run_bfr(program, &path, case.copies, threads, &args)?);
                    }
                }
                let bfr_row = BfrRun::median(&bfr_passes);
                table.row(row(&name, mesh.faces.len(), &what, threads, &series, bfr_row.as_ref()));
            }
        }
    }
    table.note(format!(
        "{runs} rounds a row, each a tessera frame then a Bfr pass, so that both sample the same moments of a \
         shared host. tessera: in each round a warm-up frame, then one timed `Tessellator::frame` into reused \
         buffers (criterion to last index, positions and normals in f32); the median of the {runs}; the cage \
         copied with `tessera::scene::mesh_grid` and loaded once ({}). Bfr: `tools/osd-oracle/bfr_bench` \
         (`Bfr::Surface<double>`, default options; each pass builds every face's surface with its topology \
         cache, tessellates with `Bfr::Tessellation`, evaluates position and normal at every point and writes \
         the facets), in each round a warm-up pass, then one timed pass; the median of the {runs}, the same \
         copies. Uniform: \
         Bfr's rate 16, tessera's factor 16 on whole quads and 8 on the sub-faces of a cage split into them. \
         Adaptive: tessera's transition scheme at 0.5 px from one camera (halfway along the frame suite's walk, \
         no culling); Bfr gets the rates of tessera's plan for every edge of every face. \
         \"Given the plan\": tessera's frame without its planning stages (criterion and resolve: the rates from \
         the camera, which Bfr is handed), i.e. layout and writes: tessellating at given rates, as a Bfr pass \
         does (a Bfr pass also builds each face's surface from the cage, which tessera did once, at load).",
        loads.join(", ")
    ));
    Ok(vec![table])
}

/// One row: tessera's series and Bfr's figures (when measured).
fn row(
    name: &str,
    faces: usize,
    what: &str,
    threads: usize,
    series: &StageSeries,
    bfr: Option<&BfrRun>,
) -> Vec<Cell> {
    let (ms, _) = median_p95(&series.total);
    let triangles = series.triangles[0];
    let mtri = triangles as f64 / ms / 1e3;
    // What Bfr is timed on: tessellating at given rates. tessera's frame also plans them
    // (criterion and resolve); without those stages, frame by frame:
    let given: Vec<f64> = (0..series.total.len())
        .map(|f| series.layout[f] + series.write_vertices[f] + series.write_indices[f])
        .collect();
    let given_mtri = triangles as f64 / median_p95(&given).0 / 1e3;
    let stages = [
        ("criterion", &series.criterion),
        ("resolve", &series.resolve),
        ("layout", &series.layout),
        ("write_vertices", &series.write_vertices),
        ("write_indices", &series.write_indices),
    ];
    let (stage, stage_ms) = stages
        .iter()
        .map(|(s, v)| (*s, median_p95(v).0))
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .expect("five stages");
    let mut cells: Vec<Cell> = vec![
        name.into(),
        faces.into(),
        what.into(),
        threads.into(),
        triangles.into(),
        num(ms, 1),
        num(mtri, 1),
    ];
    match bfr {
        Some(b) => cells.extend([
            b.triangles.into(),
            num(b.ms, 1),
            num(b.mtri_per_s, 1),
            num(mtri / b.mtri_per_s, 2),
            num(given_mtri, 1),
            num(given_mtri / b.mtri_per_s, 2),
        ]),
        None => {
            cells.extend([Cell::None, Cell::None, Cell::None, Cell::None, num(given_mtri, 1), Cell::None])
        }
    }
    cells.push(format!("{stage} {stage_ms:.1} of {ms:.1} ms").into());
    cells
}

/// Bfr's triangles and time: of one timed pass, or the median of a row's rounds.
struct BfrRun {
    triangles: usize,
    ms: f64,
    mtri_per_s: f64,
}

impl BfrRun {
    /// The median pass of `passes` (by time), None if there are none.
    fn median(passes: &[BfrRun]) -> Option<BfrRun> {
        let mut times: Vec<f64> = passes.iter().map(|b| b.ms).collect();
        times.sort_by(f64::total_cmp);
        let ms = *times.get(times.len() / 2)?;
        let triangles = passes[0].triangles;
        Some(BfrRun { triangles, ms, mtri_per_s: triangles as f64 / ms / 1e3 })
    }
}

/// Bfr's passes in one call of `bfr_bench`: the first warms it (its allocations, its caches
/// of the cage), the second is timed.
const BFR_PASSES: usize = 2;

/// Runs `bfr_bench` on `copies` copies of `cage` with `threads` threads for [`BFR_PASSES`]
/// passes; its last pass's figures.
fn run_bfr(
    program: &Path,
    cage: &Path,
    copies: usize,
    threads: usize,
    args: &[String],
) -> BenchResult<BfrRun> {
    let out = std::process::Command::new(program)
        .args([
            "--threads",
            &threads.to_string(),
            "--copies",
            &copies.to_string(),
            "--repeat",
            &BFR_PASSES.to_string(),
        ])
        .args(args)
        .arg(cage)
        .output()
        .map_err(|e| format!("{}: {e}", program.display()))?;
    let stdout = String::from_utf8_lossy(&out.stdout);
    if !out.status.success() {
        return Err(format!(
            "{} failed ({}): {}",
            program.display(),
            out.status,
            String::from_utf8_lossy(&out.stderr).trim()
        )
        .into());
    }
    parse_bfr(&stdout)
        .ok_or_else(|| format!("{}: no result line in its output:\n{stdout}", program.display()).into())
}

/// The last pass's `repeat R ms M triangles T … mtri_per_s X` line, of a run that reached
/// its closing `bfr_bench faces …` line.
fn parse_bfr(stdout: &str) -> Option<BfrRun> {
    stdout.lines().rev().find(|l| l.starts_with("bfr_bench "))?;
    let line = stdout.lines().rev().find(|l| l.starts_with("repeat "))?;
    let words: Vec<&str> = line.split_whitespace().collect();
    let value = |key: &str| words.windows(2).find(|w| w[0] == key).map(|w| w[1]);
    Some(BfrRun {
        triangles: value("triangles")?.parse().ok()?,
        ms: value("ms")?.parse().ok()?,
        mtri_per_s: value("mtri_per_s")?.parse().ok()?,
    })
}

/// The rates file `bfr_bench --adaptive-rates` reads: one line per face of `mesh` (the cage
/// `set` was built from), the segments `plan` gives each of the face's edges, in the face's
/// own vertex order; `1` for a face without a limit surface (Bfr skips those).
///
/// An edge of a face that is split into sub-faces is two sub-face edges, one on each side of
/// its midpoint: its rate is the sum of theirs. The patches' corner keys say which is which
/// (cage vertices are keys `0..V`, edge midpoints and face centres come after). Every edge is
/// read from both of its faces, and both must agree: a check that the mapping from patches to
/// faces is right, since the plan gives a shared edge one sampling.
///
/// # Errors
/// A face edge no patch edge lies on, or two faces that disagree on an edge's rate (either
/// would be a bug in the mapping or the set).
pub fn face_rates(set: &SurfaceSet, plan: &Plan, mesh: &PolygonMesh) -> Result<String, String> {
    let vertices = mesh.positions.len() as u32;
    let pair = |a: u32, b: u32| (a.min(b), a.max(b));
    // Per face: whole edges by vertex pair; halves by midpoint key, with their cage vertices.
    let mut whole: Vec<HashMap<(u32, u32), u32>> = vec![HashMap::new(); mesh.faces.len()];
    let mut halves: Vec<HashMap<u32, (u32, Vec<u32>)>> = vec![HashMap::new(); mesh.faces.len()];
    for (p, origin) in set.origins.iter().enumerate() {
        let f = origin.face as usize;
        let corners = set.keys[p].corners;
        let n = set.keys[p].domain.corner_count();
        for k in 0..n {
            let (a, b) = (corners[k], corners[(k + 1) % n]);
            let segments = plan.segments(set.topology.patch_edges[p][k].edge as usize);
            match (a < vertices, b < vertices) {
                (true, true) => {
                    whole[f].insert(pair(a, b), segments);
                }
                (true, false) | (false, true) => {
                    let (vertex, mid) = if a < vertices { (a, b) } else { (b, a) };
                    let half = halves[f].entry(mid).or_default();
                    half.0 += segments;
                    half.1.push(vertex);
                }
                (false, false) => {}
            }
        }
    }
    let mut shared: HashMap<(u32, u32), u32> = HashMap::new();
    let mut out = String::new();
    for (f, face) in mesh.faces.iter().enumerate() {
        if whole[f].is_empty() && halves[f].is_empty() {
            out.push_str("1\n");
            continue;
        }
        let v = &face.positions;
        let mut line = Vec::with_capacity(v.len());
        for i in 0..v.len() {
            let edge = pair(v[i], v[(i + 1) % v.len()]);
            let rate = whole[f].get(&edge).copied().or_else(|| {
                halves[f]
                    .values()
                    .find(|(_, ends)| ends.len() == 2 && pair(ends[0], ends[1]) == edge)
                    .map(|h| h.0)
            });
            let rate = rate.ok_or_else(|| format!("face {f}: no patch edge lies on its edge {edge:?}"))?;
            if let Some(&other) = shared.get(&edge) {
                if other != rate {
                    return Err(format!(
                        "edge {edge:?}: rate {rate} from face {f}, {other} from its neighbour"
                    ));
                }
            }
            shared.insert(edge, rate);
            line.push(rate.to_string());
        }
        out.push_str(&line.join(" "));
        out.push('\n');
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bfr_bench_result_lines_parse_to_the_last_pass() {
        let out = "# bfr_bench opensubdiv 3.5.0 …\n\
                   repeat 0 ms 12.5 triangles 16384 points 9 nolimit 0 failed 0 mtri_per_s 1.3\n\
                   repeat 1 ms 1.25 triangles 16384 points 9 nolimit 0 failed 0 mtri_per_s 13.1\n\
                   bfr_bench faces 32 triangles 16384 points 8320 threads 2 rate 16 setup_ms 0.2 median_ms 6.9 mtri_per_s 2.4\n";
        let run = parse_bfr(out).unwrap();
        assert_eq!(run.triangles, 16384);
        assert_eq!(run.ms, 1.25);
        assert_eq!(run.mtri_per_s, 13.1);
        // A run cut short (no closing line) has no figures.
        assert!(parse_bfr("repeat 0 ms 1 triangles 8 mtri_per_s 1\n").is_none());
    }

    #[test]
    fn a_rows_bfr_figures_are_its_median_pass() {
        let pass = |ms: f64| BfrRun { triangles: 1000, ms, mtri_per_s: 1.0 / ms };
        let row = BfrRun::median(&[pass(3.0), pass(1.0), pass(5.0), pass(2.0), pass(4.0)]).unwrap();
        assert_eq!(row.ms, 3.0);
        assert_eq!(row.mtri_per_s, 1000.0 / 3.0 / 1e3);
        assert!(BfrRun::median(&[]).is_none());
    }
}
