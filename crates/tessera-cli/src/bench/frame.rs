//! `frame`: per-frame re-tessellation along camera walks of scenes at the papers' scale —
//! the 92,160-patch torus grid and the killeroo herd (≈ 91k PN patches) at a guaranteed half
//! pixel with culling, and paper 002's 100 teacups with ESC.

use super::plot::{self, Axes, Series};
use super::table::{num, Table};
use super::{frames, median_p95, scenes, BenchResult, Ctx, StageSeries};
use tessera::camera::Camera;
use tessera::criterion::esc::Threshold;
use tessera::criterion::view::{Mapping, ViewCriterion};
use tessera::scheme::{Criterion, PlanOptions, Scheme};
use tessera::surface::SurfaceSet;
use tessera::tessellator::{Tessellator, TessellatorOptions};

/// A scene with its walk and what draws it.
pub struct Scene {
    pub name: &'static str,
    pub set: SurfaceSet,
    pub scheme: Scheme,
    pub criterion: Criterion,
    pub cull: bool,
    pub cameras: Vec<Camera>,
}

impl Scene {
    pub fn describe(&self) -> String {
        self.describe_as(self.scheme, &self.criterion)
    }

    /// [`Scene::describe`] with `scheme` and `criterion` in place of the scene's.
    pub fn describe_as(&self, scheme: Scheme, criterion: &Criterion) -> String {
        let what = match *criterion {
            Criterion::PixelError(px) => format!("{px} px"),
            Criterion::Esc { threshold: Threshold::Medium, .. } => "medium quality".into(),
            Criterion::Esc { threshold: Threshold::High, .. } => "high quality".into(),
            Criterion::View { fmin, fmax, .. } => format!("{} {fmin}–{fmax}", criterion.name()),
            _ => "-".into(),
        };
        format!("{} {what}{}", scheme.name(), if self.cull { ", cull" } else { "" })
    }

    /// The tessellator options of the scene (culling as set, factors up to 64).
    pub fn options(&self) -> TessellatorOptions {
        TessellatorOptions {
            plan: PlanOptions { cull: self.cull, ..PlanOptions::default() },
            ..Default::default()
        }
    }

    /// Frames of the scene for `cameras` on `threads` threads (a fresh tessellator, one
    /// warm-up frame).
    pub fn run(&self, ctx: &Ctx, threads: usize, cameras: &[Camera]) -> BenchResult<StageSeries> {
        let cameras: Vec<Option<Camera>> = cameras.iter().copied().map(Some).collect();
        let series = ctx.on_threads(threads, || {
            let mut tess = Tessellator::new(&self.set, self.scheme, self.criterion, self.options())?;
            frames(&mut tess, &cameras, true)
        })??;
        Ok(series)
    }
}

/// The three scenes (reduced with `--quick`: 4 torus copies, 2 killeroos, 5 frames).
pub fn scenes(ctx: &Ctx) -> BenchResult<Vec<Scene>> {
    let (torus_copies, killeroos, walk) = if ctx.quick { (4, 2, 5) } else { (45, 11, 60) };
    let mut out = Vec::new();
    for (name, set) in [
        ("torus grid", scenes::torus_grid(ctx, torus_copies)?),
        ("killeroo herd", scenes::killeroo_herd(ctx, killeroos)?),
    ] {
        let (lo, hi) = set.bounds();
        let cameras = scenes::walk(lo, hi, walk, 1280, 1024);
        out.push(Scene {
            name,
            set,
            scheme: Scheme::Transition,
            criterion: Criterion::PixelError(0.5),
            cull: true,
            cameras,
        });
    }
    let (set, mut cameras) = scenes::teacups(ctx)?;
    cameras.truncate(walk);
    out.push(Scene {
        name: "teacups",
        set,
        scheme: Scheme::Esc { max_level: 3 },
        criterion: Criterion::Esc { threshold: Threshold::Medium, level: None },
        cull: false,
        cameras,
    });
    Ok(out)
}

pub fn run(ctx: &Ctx) -> BenchResult<Vec<Table>> {
    let repeats = if ctx.quick { 2 } else { 9 };
    ctx.plan_steps(3 + 3 * 2 * ctx.threads.len() as u64);
    let mut walk = Table::new(
        "frame_walk",
        "frame: camera walks, ms per stage over the walk (median / p95)",
        &[
            "scene",
            "patches",
            "scheme",
            "threads",
            "frames",
            "triangles min",
            "triangles median",
            "triangles max",
            "criterion ms",
            "resolve ms",
            "layout ms",
            "write ms",
            "frame ms",
            "frame p95 ms",
            "Mtri/s",
        ],
    );
    let mut first = Table::new(
        "frame_first",
        "frame: the walk's first frame (the whole scene in view, 1280×1024), repeated",
        &[
            "scene",
            "patches",
            "scheme",
            "threads",
            "triangles",
            "culled",
            "criterion ms",
            "resolve ms",
            "layout ms",
            "vertices ms",
            "indices ms",
            "frame ms",
            "Mtri/s",
        ],
    );
    ctx.step("frame: building the scenes");
    let all = scenes(ctx)?;
    for scene in &all {
        let slug = scene.name.replace(' ', "_");
        let mut ms_lines = Vec::new();
        let mut tri_line = None;
        for &threads in &ctx.threads {
            ctx.step(&format!("frame: {} walk, {threads} threads", scene.name));
            let s = scene.run(ctx, threads, &scene.cameras)?;
            let med = |v: &Vec<f64>| median_p95(v).0;
            let fmt = |v: &Vec<f64>| {
                let (m, p) = median_p95(v);
                format!("{m:.2} / {p:.2}")
            };
            let mut tris = s.triangles.clone();
            tris.sort_unstable();
            let (total, p95) = median_p95(&s.total);
            walk.row(vec![
                scene.name.into(),
                scene.set.patches.len().into(),
                scene.describe().into(),
                threads.into(),
                s.total.len().into(),
                tris[0].into(),
                tris[tris.len() / 2].into(),
                tris[tris.len() - 1].into(),
                fmt(&s.criterion).into(),
                fmt(&s.resolve).into(),
                fmt(&s.layout).into(),
                fmt(&s.write).into(),
                num(total, 2),
                num(p95, 2),
                num(tris[tris.len() / 2] as f64 / med(&s.total) / 1e3, 1),
            ]);
            let points = |v: &Vec<f64>| v.iter().enumerate().map(|(i, &y)| (i as f64, y)).collect();
            ms_lines.push(Series { name: format!("frame, {threads} thr"), points: points(&s.total) });
            if threads == *ctx.threads.iter().max().unwrap_or(&1) {
                for (stage, v) in s.stages().into_iter().take(4) {
                    ms_lines.push(Series { name: format!("{stage}, {threads} thr"), points: points(v) });
                }
                tri_line = Some(Series {
                    name: "triangles".into(),
                    points: s.triangles.iter().enumerate().map(|(i, &t)| (i as f64, t as f64)).collect(),
                });
            }

            ctx.step(&format!("frame: {} first frame, {threads} threads", scene.name));
            let camera = scene.cameras[0];
            let s = scene.run(ctx, threads, &vec![camera; repeats])?;
            first.row(vec![
                scene.name.into(),
                scene.set.patches.len().into(),
                scene.describe().into(),
                threads.into(),
                s.triangles[0].into(),
                s.culled[0].into(),
                num(med(&s.criterion), 2),
                num(med(&s.resolve), 2),
                num(med(&s.layout), 2),
                num(med(&s.write_vertices), 2),
                num(med(&s.write_indices), 2),
                num(med(&s.total), 2),
                num(s.triangles[0] as f64 / med(&s.total) / 1e3, 1),
            ]);
        }
        let title = format!("{}: ms per frame along the walk", scene.name);
        plot::lines(
            &ctx.out.join(format!("frame_{slug}_ms.svg")),
            &Axes { title: &title, x: "frame", y: "ms", log_x: false, log_y: false },
            &ms_lines,
        )?;
        let title = format!("{}: triangles per frame along the walk", scene.name);
        plot::lines(
            &ctx.out.join(format!("frame_{slug}_triangles.svg")),
            &Axes { title: &title, x: "frame", y: "triangles", log_x: false, log_y: false },
            &tri_line.into_iter().collect::<Vec<_>>(),
        )?;
    }
    walk.note(
        "Each frame is a whole `Tessellator::frame` from that frame's camera (criterion → resolve → layout → write) \
         into buffers reused from the last frame; stage cells are median / p95 over the walk. The torus grid is 45 \
         copies of bench/torus_64x32.patches (92,160 patches), the herd 11 copies of meshes/killeroo_cage.obj as PN \
         triangles; their walks start at the framing camera (whole scene in view) and dolly in to a third of the \
         distance while orbiting 40°. Teacups: paper 002's scene and walk (1280×1024), ESC with Lmax = 3.",
    );
    first.note(format!("Medians of {repeats} frames at the walk's first camera after a warm-up frame: the scenes' single-frame figures."));
    let mut tables = vec![walk, first];
    if ctx.gpu {
        if let Some(table) = gpu_first_frames(ctx, &all, repeats)? {
            tables.push(table);
        }
    }
    Ok(tables)
}

/// The first frames of the scenes the GPU plans itself (the torus grid and the herd: the
/// transition scheme's pixel error, and the same with the semi-uniform scheme; on the herd's
/// triangles SD-2 with the distance level function too), from the camera alone on the GPU —
/// culling, factors, the a-posteriori check, counts, scans and writes — with the GPU's
/// per-pass times; None (and a note) without an adapter.
fn gpu_first_frames(ctx: &Ctx, scenes: &[Scene], repeats: usize) -> BenchResult<Option<Table>> {
    let Some(adapter) = super::speed::gpu_adapter(ctx) else { return Ok(None) };
    let semi_uniform = Scheme::SemiUniform { max_level: Scheme::DEFAULT_SEMI_UNIFORM_LEVEL };
    let distance =
        Criterion::View { criterion: ViewCriterion::Distance(Mapping::Linear), fmin: 1.0, fmax: 4.0 };
    let screens: Vec<_> = scenes
        .iter()
        .flat_map(|scene| {
            let mut variants = vec![(scene.scheme, scene.criterion)];
            if scene.scheme == Scheme::Transition {
                variants.push((semi_uniform, scene.criterion));
                variants.push((Scheme::Sd2 { warp: false }, distance));
            }
            variants.into_iter().map(move |(scheme, criterion)| (scene, scheme, criterion))
        })
        .filter_map(|(scene, scheme, criterion)| {
            let options = scene.options().plan;
            // SD-2 only where every patch is a triangle (validate refuses it elsewhere).
            crate::gpu::screen_criterion(&scene.set, scheme, &criterion, &options)
                .map(|s| (scene, scheme, criterion, s))
        })
        .collect();
    // ESC also drawn on the GPU from the CPU's plan and insertion grids: the same triangles,
    // the GPU frame alone timed.
    let mut frames: Vec<(&Scene, String, GpuFrame)> = screens
        .into_iter()
        .map(|(scene, scheme, criterion, screen)| {
            let label = format!("{}, planned on the GPU", scene.describe_as(scheme, &criterion));
            (scene, label, GpuFrame::FromCamera(screen))
        })
        .collect();
    for scene in scenes.iter().filter(|s| matches!(s.scheme, Scheme::Esc { .. })) {
        let options = PlanOptions { camera: Some(scene.cameras[0]), ..scene.options().plan };
        let planned = scene.scheme.plan(&scene.set, &scene.criterion, &options)?;
        let label = format!("{}, planned on the CPU (not timed)", scene.describe());
        frames.push((scene, label, GpuFrame::FromPlan(Box::new(planned))));
    }
    ctx.plan_steps(frames.len() as u64);
    let passes = tessera_gpu::tessellator::PASSES;
    let mut columns: Vec<String> =
        ["scene", "patches", "scheme", "triangles", "fix rounds", "capped patches"]
            .map(String::from)
            .to_vec();
    columns.extend(passes.iter().map(|p| format!("{p} ms")));
    columns.extend(["GPU ms", "frame ms"].map(String::from));
    let names: Vec<&str> = columns.iter().map(String::as_str).collect();
    let title = format!("frame: the walk's first frame planned and tessellated on the GPU ({adapter})");
    let mut table = Table::new("frame_gpu", &title, &names);
    let mut refused = Vec::new();
    for (scene, label, frame) in frames {
        ctx.step(&format!("frame: {} first frame on the GPU, {label}", scene.name));
        let (mut mesh, mut times) = (tessera::mesh::Mesh::default(), Vec::new());
        let (set, camera, repeat) = (&scene.set, &scene.cameras[0], repeats as u32);
        let run = match &frame {
            GpuFrame::FromCamera(screen) => crate::gpu::tessellate_from_camera(
                set,
                camera,
                *screen,
                crate::gpu::Output::TRIANGLES,
                repeat,
                &mut mesh,
                &mut times,
            ),
            GpuFrame::FromPlan(p) => crate::gpu::tessellate(
                set,
                &p.plan,
                &p.pattern,
                crate::gpu::Output::TRIANGLES,
                repeat,
                &mut mesh,
                &mut times,
            ),
        };
        // A frame this adapter cannot hold is said in the table's note, not fatal to the suite.
        let run = match run {
            Ok(run) => run,
            Err(e) => {
                refused.push(format!("{} ({label}): {e}", scene.name));
                continue;
            }
        };
        let check = |f: fn(&tessera_gpu::tessellator::ScreenReport) -> u32| {
            run.screen.as_ref().map_or("-".into(), |c| (f(c) as usize).into())
        };
        let mut row: Vec<super::table::Cell> = vec![
            scene.name.into(),
            scene.set.patches.len().into(),
            label.into(),
            mesh.triangle_count().into(),
            check(|c| c.rounds),
            check(|c| c.failing_patches),
        ];
        row.extend(timing_cells(&run, &times));
        table.row(row);
    }
    table.note(format!(
        "Medians of {repeats} frames at the walk's first camera (1280×1024), each a whole GPU frame from the camera: \
         the plan never comes back to the CPU. Per-pass times from timestamp queries; frame = submit to finished \
         (wall clock). The teacups' ESC frame is planned on the GPU (each object's level, the distance \
         tests, the insertion grids: the factors pass) and, in its second row, on the CPU and drawn on the GPU \
         from that plan and its grids (the GPU frame alone timed). The software \
         driver (lavapipe) is for correctness, not speed.{}",
        refused.iter().map(|r| format!(" Not drawn on this adapter: {r}.")).collect::<String>()
    ));
    Ok(Some(table))
}

/// A GPU frame's cells after the scene's: each pass's median ms ("-" without timestamp
/// queries), their sum, and the median wall-clock frame (submit to finished).
fn timing_cells(run: &crate::gpu::GpuRun, times: &[f64]) -> Vec<super::table::Cell> {
    let mut cells: Vec<super::table::Cell> = Vec::new();
    if run.passes_ms.is_empty() {
        cells.extend(tessera_gpu::tessellator::PASSES.iter().map(|_| "-".into()));
        cells.push("-".into());
    } else {
        cells.extend(run.passes_ms.iter().map(|&(_, ms)| num(ms, 2)));
        cells.push(num(run.passes_ms.iter().map(|&(_, ms)| ms).sum(), 2));
    }
    cells.push(num(median_p95(times).0 * 1e3, 2));
    cells
}

/// How a GPU row's frame is planned: on the GPU from the camera, or on the CPU (the plan and
/// its pattern uploaded).
enum GpuFrame {
    FromCamera(tessera_gpu::tessellator::ScreenCriterion),
    FromPlan(Box<tessera::scheme::SchemePlan>),
}
