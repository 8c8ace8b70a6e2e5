//! `paper`: the papers' tables, measured here, beside the papers' own figures, with a column
//! saying what differs. Paper 000 Table 1 (uniform against semi-uniform, compacted against
//! instanced), paper 001 Tables 1–2 (uniform f = 7, SD-2, a stitching pattern), paper 002
//! Table 1 (Teacups, ESC), paper 003 Tables 1–2 (scene statistics, per-stage breakdown).
//!
//! The papers' figures below are typed from the text extractions in `shared/papers/`; where
//! an extraction garbled a table header, the note under the table says how the columns were
//! read.

use super::frame::Scene;
use super::speed::short;
use super::table::{num, Cell, Table};
use super::{median_p95, scenes, BenchResult, Ctx};
use std::time::Instant;
use tessera::camera::Camera;
use tessera::criterion::esc::{EscOptions, Threshold};
use tessera::criterion::view::ViewCriterion;
use tessera::criterion::Plan;
use tessera::engine::{render_queues, tessellate, EngineOptions};
use tessera::pattern::semi_uniform::StaticPattern;
use tessera::pattern::uniform::Uniform;
use tessera::scheme::{Criterion, Scheme};
use tessera::surface::{Domain, SurfaceSet};
use tessera::tessellator::{Tessellator, TessellatorOptions};
use tessera::verify;

pub fn run(ctx: &Ctx) -> BenchResult<Vec<Table>> {
    ctx.plan_steps(4);
    let threads = *ctx.threads.iter().max().unwrap_or(&1);
    let mut tables = Vec::new();
    ctx.step("paper: 000 Table 1 (semi-uniform)");
    tables.push(paper000(ctx, threads)?);
    ctx.step("paper: 001 Tables 1-2 (SD-2)");
    tables.push(paper001(ctx, threads)?);
    ctx.step("paper: 002 Table 1 (Teacups, ESC)");
    tables.extend(paper002(ctx)?);
    ctx.step("paper: 003 Tables 1-2 (CudaTess)");
    tables.extend(paper003(ctx, threads)?);
    Ok(tables)
}

/// Paper 000 (Dyken et al.) Table 1's triangle counts for the meshes of about our sizes:
/// (base triangles, M, uniform, adaptive).
const PAPER000: [(&str, u32, &str, &str); 6] = [
    ("1.0k", 3, "64k", "42k"),
    ("1.0k", 5, "1,024k", "595k"),
    ("1.5k", 3, "98k", "31k"),
    ("1.5k", 5, "1,573k", "412k"),
    ("6.1k", 3, "393k", "71k"),
    ("6.1k", 5, "6,291k", "876k"),
];

fn paper000(ctx: &Ctx, threads: usize) -> BenchResult<Table> {
    let mut t = Table::new(
        "paper000_table1",
        "paper 000 (semi-uniform), Table 1: uniform level M against semi-uniform, compacted and instanced",
        &[
            "mesh",
            "base tri",
            "M",
            "method",
            "triangles",
            "ms / frame",
            "Mtri/s",
            "paper base",
            "paper triangles",
            "what differs",
        ],
    );
    let (models, levels, views): (&[&str], &[u32], usize) = if ctx.quick {
        (&["meshes/helmet.obj"], &[3], 4)
    } else {
        (&["meshes/helmet.obj", "meshes/spool.obj", "meshes/cow.obj"], &[3, 5], 20)
    };
    for (k, rel) in models.iter().enumerate() {
        let set = scenes::load(ctx, rel)?;
        let cameras = scenes::random_cameras(&set, views);
        let base = set.patches.len();
        for &m in levels {
            // helmet, spool, cow ↔ the paper's meshes of 1.0k, 1.5k and 6.1k triangles.
            let paper = PAPER000.get(2 * k + (m == 5) as usize).filter(|p| p.1 == m);
            let (pbase, puni, pada) = paper.map_or(("—", "—", "—"), |p| (p.0, p.2, p.3));
            let top = 1u32 << m;
            // B: uniform level M re-tessellated every frame (A, the same triangles stored once
            // in a static buffer, costs nothing per frame on the CPU).
            let uniform = Scene {
                name: "uniform",
                set: set.clone(),
                scheme: Scheme::Uniform,
                criterion: Criterion::Factor(top as f64),
                cull: false,
                cameras: Vec::new(),
            };
            let s = uniform.run(ctx, threads, &[cameras[0]; 5])?;
            let ms = median_p95(&s.total).0;
            t.row(vec![
                short(rel).into(),
                base.into(),
                (m as usize).into(),
                "A/B uniform 2^M, per frame".into(),
                s.triangles[0].into(),
                num(ms, 2),
                num(s.triangles[0] as f64 / ms / 1e3, 1),
                pbase.into(),
                puni.into(),
                "CPU tessellation into buffers; paper: GPU rendering (GeForce 7800/8800 GT), so its fps are not compared".into(),
            ]);
            // D: semi-uniform, silhouetteness, the compacted mesh, averaged over the views.
            let scheme = Scheme::SemiUniform { max_level: m };
            let criterion =
                Criterion::View { criterion: ViewCriterion::Silhouetteness, fmin: 1.0, fmax: top as f64 };
            let semi =
                Scene { name: "semi", set: set.clone(), scheme, criterion, cull: false, cameras: Vec::new() };
            let s = semi.run(ctx, threads, &cameras)?;
            let mean = s.triangles.iter().sum::<usize>() as f64 / s.triangles.len() as f64;
            let ms = median_p95(&s.total).0;
            t.row(vec![
                short(rel).into(),
                base.into(),
                (m as usize).into(),
                "D semi-uniform, compacted".into(),
                (mean.round() as u64).into(),
                num(ms, 2),
                num(mean / ms / 1e3, 1),
                pbase.into(),
                pada.into(),
                format!("mean over {views} seeded views at 1.5 diagonals (paper: randomly varied viewpoint); mesh of similar size").into(),
            ]);
            // E–H: the instanced form — render queues per level, drawn from the static
            // patterns P^0..P^M; the per-frame CPU work is the queue build.
            let patterns = StaticPattern::all(Domain::Tri, m);
            let (mut build_ms, mut instanced) = (Vec::new(), 0u64);
            ctx.on_threads(threads, || -> BenchResult<()> {
                let mut tess = Tessellator::new(&set, scheme, criterion, TessellatorOptions::default())?;
                for c in &cameras {
                    tess.frame(Some(c))?;
                    let plan = tess.plan().expect("a frame was planned");
                    let start = Instant::now();
                    let q = render_queues::build(&set, plan, m)?;
                    build_ms.push(start.elapsed().as_secs_f64() * 1e3);
                    instanced += (0..=m)
                        .map(|l| (q.level(l).len() * patterns[l as usize].triangles.len()) as u64)
                        .sum::<u64>();
                }
                Ok(())
            })??;
            let mean = instanced as f64 / cameras.len() as f64;
            let ms = median_p95(&build_ms).0;
            t.row(vec![
                short(rel).into(),
                base.into(),
                (m as usize).into(),
                "E–H semi-uniform, instanced (render queues)".into(),
                (mean.round() as u64).into(),
                num(ms, 3),
                Cell::None,
                pbase.into(),
                pada.into(),
                "queue build only (count + scan on the CPU, as E/F); the GPU draw of P^m instances is not measured".into(),
            ]);
        }
    }
    t.note(format!(
        "PN triangles, silhouetteness criterion, levels 0..M, nothing culled, {threads} threads. ms: median frame \
         (A/B, D) or render-queue build (E–H, whose triangles are drawn by the GPU: no Mtri/s here); Mtri/s: triangles / frame. Methods C (hanging nodes) and I (geometry \
         shader) have no CPU counterpart. Paper figures from its Table 1 (meshes of 1.0k, 1.5k and 6.1k \
         triangles); instanced triangles count every P^m triangle, degenerate ones included, as the GPU draws them."
    ));
    Ok(t)
}

/// Paper 001 (SD-2) Tables 1–2: model, base triangles, then per method (uniform f = 7, SD-2,
/// stitch) primitives and fps with strips (Table 1) and without (Table 2).
/// One method's figures in paper 001: primitives, fps with strips, fps without.
type Paper001Method = (u32, f64, f64);

const PAPER001: [(&str, u32, [Paper001Method; 3]); 3] = [
    ("Sphere", 320, [(15680, 121.0, 60.0), (12952, 153.0, 65.0), (12184, 122.0, 65.0)]),
    ("Violin Case", 2120, [(103880, 19.5, 7.5), (83932, 24.5, 16.0), (75446, 19.9, 16.0)]),
    ("Cow", 5804, [(284396, 7.0, 3.2), (222586, 9.5, 4.0), (200383, 7.4, 4.0)]),
];

fn paper001(ctx: &Ctx, threads: usize) -> BenchResult<Table> {
    let mut t = Table::new(
        "paper001_tables12",
        "paper 001 (SD-2), Tables 1–2: silhouette refinement, f_max = 7",
        &[
            "mesh",
            "base tri",
            "method",
            "triangles",
            "strip indices",
            "ms / frame",
            "paper model",
            "paper base",
            "paper primitives",
            "paper fps strips / lists",
            "what differs",
        ],
    );
    let (models, fmins): (&[&str], &[u32]) = if ctx.quick {
        (&["meshes/helmet.obj"], &[1, 4])
    } else {
        (&["meshes/helmet.obj", "meshes/spool.obj", "meshes/cow.obj"], &[1, 2, 3, 4, 5])
    };
    let repeats = if ctx.quick { 3 } else { 9 };
    for (k, rel) in models.iter().enumerate() {
        let set = scenes::load(ctx, rel)?;
        let (lo, hi) = set.bounds();
        let camera = Camera::framing(lo, hi, 1280, 720);
        let (pname, pbase, pfig) = PAPER001[k];
        let differs = if pname == "Cow" {
            "same cow (5,804 triangles); CPU tessellation, not GPU geometry-shader rendering; the paper's view and f_min are not given"
        } else {
            "a mesh of another size; CPU tessellation, not GPU geometry-shader rendering"
        };
        let mut methods: Vec<(String, Scheme, Criterion, usize)> =
            vec![("uniform f = 7".into(), Scheme::Uniform, Criterion::Factor(7.0), 0)];
        for &f in fmins {
            let criterion =
                Criterion::View { criterion: ViewCriterion::SilhouetteVertices, fmin: f as f64, fmax: 7.0 };
            methods.push((format!("SD-2 {f}:7, strips"), Scheme::Sd2 { warp: false }, criterion, 1));
        }
        let criterion =
            Criterion::View { criterion: ViewCriterion::SilhouetteVertices, fmin: 4.0, fmax: 7.0 };
        methods.push(("transition 4:7 (stitching)".into(), Scheme::Transition, criterion, 2));
        for (name, scheme, criterion, paper) in methods {
            let strips = matches!(scheme, Scheme::Sd2 { .. });
            let (tri, strip, ms) = ctx.on_threads(threads, || -> BenchResult<_> {
                let mut options = TessellatorOptions::default();
                options.engine.strips = strips;
                let mut tess = Tessellator::new(&set, scheme, criterion, options)?;
                let mut times = Vec::new();
                for _ in 0..repeats {
                    tess.frame(Some(&camera))?;
                    times.push(tess.timings().total().as_secs_f64() * 1e3);
                }
                let mesh = tess.mesh();
                Ok((mesh.triangle_count(), mesh.strips.as_ref().map(|s| s.len()), median_p95(&times).0))
            })??;
            let (pp, fs, fl) = pfig[paper];
            t.row(vec![
                short(rel).into(),
                set.patches.len().into(),
                name.into(),
                tri.into(),
                strip.into(),
                num(ms, 2),
                pname.into(),
                (pbase as usize).into(),
                (pp as usize).into(),
                format!("{fs} / {fl}").into(),
                differs.into(),
            ]);
        }
    }
    t.note(format!(
        "PN triangles, the framing camera (1280×720), vertex classification of silhouettes; SD-2 for f_min = \
         {fmins:?} (the paper does not state f_min); its stitching method is compared with tessera's transition \
         pattern at 4:7. strip indices: SD-2's triangle strips (restart markers included). ms: median of {repeats} \
         frames on {threads} threads. Paper: Table 1 with strips, Table 2 without, fps on its GPU."
    ));
    Ok(t)
}

fn paper002(ctx: &Ctx) -> BenchResult<Vec<Table>> {
    let (scene, mut cameras) = scenes::teacups(ctx)?;
    if ctx.quick {
        cameras.truncate(10);
    }
    let options = |threshold| EscOptions { max_level: 3, threshold, ..Default::default() };
    let high = scenes::teacups::frame_counts(&scene, &cameras, &options(Threshold::High))?;
    let medium = scenes::teacups::frame_counts(&scene, &cameras, &options(Threshold::Medium))?;
    let frames = cameras.len() as f64;
    let avg = |v: &[scenes::teacups::FrameCount], f: fn(&scenes::teacups::FrameCount) -> u64| {
        v.iter().map(f).sum::<u64>() as f64 / frames
    };
    let base = avg(&high, |c| c.non_adaptive);
    let (h, m) = (avg(&high, |c| c.adaptive), avg(&medium, |c| c.adaptive));
    let mut t = Table::new(
        "paper002_table1",
        "paper 002 (ESC), Table 1: triangles (thousands, Lmax = 3) on the Teacups scene",
        &["row", "Teacups here", "share", "paper Teacups", "paper share", "paper Elephants", "what differs"],
    );
    let k = |x: f64| num(x / 1e3, 2);
    let pct = |x: f64| num(100.0 * x / base, 2);
    t.row(vec![
        "input surfaces".into(),
        scene.patches.len().into(),
        Cell::None,
        "2,600".into(),
        Cell::None,
        "8,110".into(),
        "teacup.patches × 100 on a 10 × 10 grid; the Elephants scene (bicubic elephants) is not in the shared data".into(),
    ]);
    t.row(vec![
        "non-adaptive".into(),
        k(base),
        Cell::None,
        "731.32".into(),
        Cell::None,
        "2,280.94".into(),
        format!("average over {} frames of our walk (paper: its own walk-through)", cameras.len()).into(),
    ]);
    t.row(vec![
        "adaptive high".into(),
        k(h),
        pct(h),
        "684.67".into(),
        "93.62".into(),
        "1,941.03 (85.10 %)".into(),
        "ρ = 0.4 % of each cup's diagonal (the paper gives no value; calibrated on this scene)".into(),
    ]);
    t.row(vec![
        "adaptive medium".into(),
        k(m),
        pct(m),
        "379.98".into(),
        "51.96".into(),
        "1,155.70 (50.68 %)".into(),
        "ρ = 2.2 % of the diagonal (calibrated likewise)".into(),
    ]);
    t.note("Pattern triangles per frame, averaged over the walk (1280×1024, 60 cameras; 10 with --quick); non-adaptive: 18 (L+1)² per surface at the camera's levels.");

    // Measured error of each preset at the middle frame, against uniform with about as many
    // triangles: what the paper shows as pictures (its Figs. 7–8).
    let mut e = Table::new(
        "paper002_error",
        "paper 002 (ESC): measured max error at the walk's middle frame, against uniform with about as many triangles",
        &["tessellation", "triangles", "max error", "rms error", "max error / diagonal"],
    );
    let camera = &cameras[cameras.len() / 2];
    let params = EngineOptions { corner_params: true, ..Default::default() };
    let cup_diagonal = {
        let cup = scenes::load(ctx, "patches/teacup.patches")?;
        let (a, b) = cup.bounds();
        a.distance(b)
    };
    let mut measure = |name: String, mesh: tessera::mesh::Mesh| -> BenchResult<()> {
        let err = verify::approximation_error(&mesh, &scene, 4)?;
        e.row(vec![
            name.into(),
            mesh.triangle_count().into(),
            num(err.max, 5),
            num(err.rms, 5),
            num(err.max / cup_diagonal, 6),
        ]);
        Ok(())
    };
    // --quick: the medium preset only (the high one's meshes are the largest here).
    let presets: &[(&str, Threshold)] = if ctx.quick {
        &[("medium", Threshold::Medium)]
    } else {
        &[("high", Threshold::High), ("medium", Threshold::Medium)]
    };
    for &(name, threshold) in presets {
        let (plan, pattern) = tessera::criterion::esc::plan(&scene, camera, &options(threshold))?;
        let mesh = tessellate(&scene, &plan, &pattern, params)?;
        // Uniform factor f gives 2 f² triangles per surface.
        let f = ((mesh.triangle_count() as f64 / (2.0 * scene.patches.len() as f64)).sqrt().round() as u32)
            .max(1);
        measure(format!("ESC {name}"), mesh)?;
        let uniform = tessellate(&scene, &Plan::uniform(&scene, f)?, &Uniform, params)?;
        measure(format!("uniform f = {f} (about as many triangles as ESC {name})"), uniform)?;
    }
    e.note("Order-4 barycentric samples in every triangle (tessera::verify::approximation_error); diagonal: one teacup's bounding-box diagonal.");
    Ok(vec![t, e])
}

/// A paper 003 row: scene, patches, the three counts as extracted, fps, and the per-stage
/// times as extracted.
struct Paper003 {
    scene: &'static str,
    patches: &'static str,
    counts: &'static str,
    fps: &'static str,
    stages: &'static str,
}

fn paper003(ctx: &Ctx, threads: usize) -> BenchResult<Vec<Table>> {
    let repeats = if ctx.quick { 3 } else { 9 };
    let (copies, herd) = if ctx.quick { (4, 2) } else { (45, 11) };
    let p = |scene, patches, counts, fps, stages| Paper003 { scene, patches, counts, fps, stages };
    let bicubic: Vec<(&str, SurfaceSet, Paper003)> = vec![
        (
            "teapot",
            scenes::load(ctx, "patches/teapot.patches")?,
            p("Teatable", "332", "41,372 / 25,798 / 55,316", "206.5 Hz", "0.39 / 0.09 / 2.40 (1.40) / 0.56"),
        ),
        (
            "torus_64x32",
            scenes::load(ctx, "bench/torus_64x32.patches")?,
            p(
                "Killeroo",
                "11,532",
                "100,930 / 110,515 / 213,709",
                "156.2 Hz",
                "0.82 / 0.16 / 3.32 (2.04) / 0.61",
            ),
        ),
        (
            "teacups",
            scenes::teacups(ctx)?.0,
            p(
                "Spheres",
                "32,000",
                "402,000 / 393,600 / 675,600",
                "98.4 Hz",
                "1.62 / 0.20 / 4.54 (3.54) / 0.96",
            ),
        ),
        (
            "torus grid",
            scenes::torus_grid(ctx, copies)?,
            p(
                "Killeroo herd",
                "92,256",
                "345,751 / 514,753 / 827,389",
                "48.1 Hz",
                "4.18 / 0.42 / 12.22 (7.38) / 1.19",
            ),
        ),
    ];
    let pn: Vec<(&str, SurfaceSet, Paper003)> = vec![
        (
            "elephant",
            scenes::load(ctx, "meshes/elephant.obj")?,
            p(
                "Elephant",
                "21,540",
                "79,208 / 116,399 / 257,894",
                "230 Hz",
                "0.91 (0.43) / 0.26 / 1.49 / 0.68",
            ),
        ),
        (
            "elephant_refined",
            scenes::load(ctx, "meshes/elephant_refined.obj")?,
            p(
                "Star field",
                "41,496",
                "1,050,688 / 864,928 / 2,547,040",
                "60.1 Hz",
                "1.41 (0.47) / 0.33 / 6.81 / 2.57",
            ),
        ),
        (
            "killeroo herd",
            scenes::killeroo_herd(ctx, herd)?,
            p(
                "Model zoo",
                "80,578",
                "160,200 / 311,469 / 548,730",
                "109 Hz",
                "2.42 (0.65) / 0.50 / 3.33 / 0.93",
            ),
        ),
    ];
    let mut out = Vec::new();
    for (which, rows, stages_note) in [
        ("1", bicubic, "paper stages (ms): factors / scan / vertices (with forward differencing) / indices"),
        ("2", pn, "paper stages (ms): factors (with precomputed bounds) / scan / vertices / indices"),
    ] {
        let kind = if which == "1" { "bicubic patches" } else { "PN triangles" };
        let mut t = Table::new(
            &format!("paper003_table{which}"),
            &format!(
                "paper 003 (CudaTess), Table {which}: {kind} — scene statistics and per-stage breakdown"
            ),
            &[
                "scene",
                "patches",
                "triangles",
                "vertices",
                "indices",
                "culled",
                "criterion ms",
                "resolve ms",
                "layout ms",
                "vertices ms",
                "indices ms",
                "frame ms",
                "paper scene",
                "paper patches",
                "paper counts",
                "paper fps",
                "paper stages ms",
                "what differs",
            ],
        );
        for (name, set, paper) in rows {
            let (lo, hi) = set.bounds();
            let camera = Camera::framing(lo, hi, 1024, 768);
            let scene = Scene {
                name: "paper 003",
                set,
                scheme: Scheme::Transition,
                criterion: Criterion::PixelError(0.5),
                cull: true,
                cameras: Vec::new(),
            };
            let s = scene.run(ctx, threads, &vec![camera; repeats])?;
            let med = |v: &Vec<f64>| num(median_p95(v).0, 2);
            t.row(vec![
                name.into(),
                scene.set.patches.len().into(),
                s.triangles[0].into(),
                s.vertices[0].into(),
                (3 * s.triangles[0]).into(),
                s.culled[0].into(),
                med(&s.criterion),
                med(&s.resolve),
                med(&s.layout),
                med(&s.write_vertices),
                med(&s.write_indices),
                med(&s.total),
                paper.scene.into(),
                paper.patches.into(),
                paper.counts.into(),
                paper.fps.into(),
                paper.stages.into(),
                format!("other models of about the paper's patch count; {threads} CPU threads, not a GeForce 8800 GTS; the paper's fps include rendering").into(),
            ]);
        }
        t.note(format!(
            "tessera: transition pattern, 0.5 px guaranteed screen-space error, 1024×768 framing camera, culling on \
             (the paper's settings), median of {repeats} frames on {threads} threads. Stages map as criterion ≈ \
             factors (culling, bounds → factors), resolve ≈ consistent edge factors, layout ≈ counts + scan, vertices \
             and indices are the write's two passes. Paper columns as extracted (the header is garbled in the text extraction): \
             'paper counts' are its three count columns in order (triangles / vertices / indices by the header); \
             {stages_note} — the labels were read by checking that the stages plus the render-only rate add up to \
             the frame rate."
        ));
        out.push(t);
    }
    Ok(out)
}
