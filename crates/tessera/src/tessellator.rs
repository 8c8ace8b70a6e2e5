//! The front door: a [`Tessellator`] prepares a surface set once for a scheme and a criterion,
//! then re-tessellates it per frame — from a camera, or once for a tolerance — into buffers it
//! reuses.
//!
//! ```
//! use tessera::scheme::{Criterion, Scheme};
//! use tessera::tessellator::{Tessellator, TessellatorOptions};
//! use tessera::camera::Camera;
//! use tessera::surface::SurfaceSet;
//! # use tessera::io::patches::parse_patches;
//! # let mut text = String::from("1\n1,2,3,4,5,6,7,8,9,10,11,12,13,14,15,16\n16\n");
//! # for i in 0..4 { for j in 0..4 { text += &format!("{i},{j},{}\n", (i * j) as f64 * 0.1); } }
//! # let set = SurfaceSet::from_patch_file(&parse_patches(&text, "<doc>".as_ref())?, Default::default());
//!
//! // Prepared once: topology minimums and the patches' error bounds.
//! let mut tess = Tessellator::new(&set, Scheme::Transition, Criterion::PixelError(0.5), TessellatorOptions::default())?;
//! let (lo, hi) = set.bounds();
//! for frame in 0..3 {
//!     let mut camera = Camera::framing(lo, hi, 1280, 720);
//!     camera.eye.x += frame as f64;
//!     let mesh = tess.frame(Some(&camera))?; // reuses last frame's buffers
//!     assert!(mesh.triangle_count() > 0);
//! }
//! assert!(tess.report().unwrap().worst_ratio <= 1.0); // the pixel error is guaranteed
//! # Ok::<(), tessera::Error>(())
//! ```
//!
//! Output goes through [`MeshBuilder`]: [`Tessellator::frame`] hands out the tessellator's own
//! [`Mesh`] (a struct of arrays, zero copies); [`Tessellator::frame_into`] writes straight into
//! a builder's arrays when it lends them ([`MeshBuilder::buffers`]: a `Mesh`, separate vertex
//! streams), or streams the frame to any other builder, such as an application's interleaved
//! vertex buffer with its own index type.

use crate::camera::Camera;
use crate::criterion::tolerance::BoundReport;
use crate::criterion::Plan;
use crate::engine::fast_evaluator::FastEvaluator;
use crate::engine::{self, EngineOptions, Layout};
use crate::error::Result;
use crate::mesh::{Mesh, MeshBuffers};
use crate::scheme::{validate, Criterion, Engine, PlanOptions, PlanScratch, Prepared, Scheme, SchemePlan};
use std::time::{Duration, Instant};

/// Wall time of each stage of a frame ([`Tessellator::timings`]).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct FrameTimings {
    /// Per-patch view work: culling and the pixel → object-space tolerances.
    pub criterion: Duration,
    /// Proposals, the edge resolve and the error checks: the rest of the plan.
    pub resolve: Duration,
    /// The output layout (counts and offsets).
    pub layout: Duration,
    /// Vertex and index writes: `write_vertices + write_indices`, within timer resolution.
    pub write: Duration,
    /// The write's first pass: every vertex record (corners, edge samples, interiors), and
    /// the triangles of the patches whose pattern the frame's cache does not hold (unless the
    /// frame streams its indices): their pattern is at hand there.
    pub write_vertices: Duration,
    /// The write's second pass: the other triangles (and the strips, when asked for). Near
    /// zero on a frame of small patterns, whose first pass wrote every triangle.
    pub write_indices: Duration,
}

impl FrameTimings {
    /// The whole frame, criterion to last index.
    pub fn total(&self) -> Duration {
        self.criterion + self.resolve + self.layout + self.write
    }
}
use crate::surface::SurfaceSet;

/// Receives a tessellation, vertex after vertex, then triangle after triangle.
///
/// [`Mesh`] is one implementation. An application implements it for its own layout —
/// interleaved vertices, `u16` indices, a mapped GPU buffer — and clears rather than frees
/// between frames, so that a frame that fits the last one's capacity allocates nothing.
pub trait MeshBuilder {
    /// Called once per frame, first, with the exact sizes that follow.
    fn begin(&mut self, vertices: usize, triangles: usize);
    /// Vertex `i` of the frame, for `i = 0, 1, …` in order: position, unit normal, the
    /// parameters in `patch` that evaluated it.
    fn vertex(&mut self, position: [f32; 3], normal: [f32; 3], uv: [f32; 2], patch: u32);
    /// The next triangle: vertex indices (counter-clockwise seen from the normal side) and
    /// its patch.
    fn triangle(&mut self, indices: [u32; 3], patch: u32);
    /// Called once per frame, last.
    fn end(&mut self) {}
    /// Arrays of exactly `vertices` and `triangles` entries ([`MeshBuffers`], `Mesh`'s
    /// struct-of-arrays layout) that the engine may write the frame into directly, in
    /// parallel and with no copy, instead of streaming it through [`MeshBuilder::vertex`] and
    /// [`MeshBuilder::triangle`]: a builder whose vertex attributes live in arrays of their
    /// own (a `Mesh`, separate GPU vertex streams) lends them here, after
    /// [`MeshBuilder::begin`]. None (the default) streams. Frames with corner parameters or
    /// strips ([`EngineOptions`]) always stream.
    fn buffers(&mut self, vertices: usize, triangles: usize) -> Option<MeshBuffers<'_>> {
        let _ = (vertices, triangles);
        None
    }
}

impl MeshBuilder for Mesh {
    fn begin(&mut self, vertices: usize, triangles: usize) {
        for v in [&mut self.positions, &mut self.normals] {
            v.clear();
            v.reserve(vertices);
        }
        self.uvs.clear();
        self.uvs.reserve(vertices);
        self.vertex_patch.clear();
        self.vertex_patch.reserve(vertices);
        self.indices.clear();
        self.indices.reserve(3 * triangles);
        self.triangle_patch.clear();
        self.triangle_patch.reserve(triangles);
        self.corner_params = None;
        self.strips = None;
        self.collapsed_triangles = 0;
    }
    fn vertex(&mut self, position: [f32; 3], normal: [f32; 3], uv: [f32; 2], patch: u32) {
        self.positions.push(position);
        self.normals.push(normal);
        self.uvs.push(uv);
        self.vertex_patch.push(patch);
    }
    fn triangle(&mut self, indices: [u32; 3], patch: u32) {
        self.indices.extend_from_slice(&indices);
        self.triangle_patch.push(patch);
    }
    fn buffers(&mut self, vertices: usize, triangles: usize) -> Option<MeshBuffers<'_>> {
        self.positions.resize(vertices, [0.0; 3]);
        self.normals.resize(vertices, [0.0; 3]);
        self.uvs.resize(vertices, [0.0; 2]);
        self.vertex_patch.resize(vertices, 0);
        self.indices.resize(3 * triangles, 0);
        self.triangle_patch.resize(triangles, 0);
        Some(MeshBuffers {
            positions: &mut self.positions,
            normals: &mut self.normals,
            uvs: &mut self.uvs,
            vertex_patch: &mut self.vertex_patch,
            indices: &mut self.indices,
            triangle_patch: &mut self.triangle_patch,
        })
    }
}

/// Options of a [`Tessellator`].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct TessellatorOptions {
    /// Everything about planning; `plan.camera` is the camera of the frames called without
    /// one (a frame's own camera replaces it).
    pub plan: PlanOptions,
    /// The engine's options (size limits, corner parameters, strips).
    pub engine: EngineOptions,
}

/// A surface set prepared for one scheme and criterion, re-tessellated per frame into reused
/// buffers. See the [module documentation](self) for an example.
pub struct Tessellator<'a> {
    set: &'a SurfaceSet,
    scheme: Scheme,
    criterion: Criterion,
    options: TessellatorOptions,
    prepared: Prepared,
    layout: Layout,
    /// The last frame's plan, valid when `planned_ok`; its buffers are reused.
    planned: SchemePlan,
    planned_ok: bool,
    /// A frame was planned and laid out and not written yet.
    laid_out: bool,
    scratch: PlanScratch,
    timings: FrameTimings,
    /// The planning stages' times of the frame being planned, until it is written.
    pending: FrameTimings,
    mesh: Mesh,
    /// The vectorized evaluation's per-set tables, kept from frame to frame.
    fast: FastEvaluator<'a>,
}

impl<'a> Tessellator<'a> {
    /// Prepares `set` for `scheme` under `criterion`: checks the request
    /// ([`crate::scheme::validate`]: the pairing, the ranges, the surface kinds; its typed
    /// errors) and computes what does not
    /// depend on the view — the topology's minimum samplings and, for error-bounded
    /// criteria, every patch's second-derivative bound — and the vectorized evaluation's
    /// control-point tables. Cost: O(P) bound computations.
    pub fn new(
        set: &'a SurfaceSet,
        scheme: Scheme,
        criterion: Criterion,
        options: TessellatorOptions,
    ) -> Result<Tessellator<'a>> {
        validate(scheme, &criterion, &options.plan, set, Engine::Cpu)?;
        let prepared = Prepared::for_criterion(set, &criterion);
        let fast = FastEvaluator::for_set(set, true);
        Ok(Tessellator {
            set,
            scheme,
            criterion,
            options,
            prepared,
            layout: Layout::default(),
            planned: SchemePlan::default(),
            planned_ok: false,
            laid_out: false,
            scratch: PlanScratch::default(),
            timings: FrameTimings::default(),
            pending: FrameTimings::default(),
            mesh: Mesh::default(),
            fast,
        })
    }

    /// Makes the next frames draw `scheme` under `criterion` and `plan`, keeping what was
    /// prepared for the set (the error bounds are computed on the first criterion that needs
    /// them): as an interactive viewer changes the scheme or the pixel error. Checks the
    /// request as [`Tessellator::new`] does; on error the tessellator is unchanged. Cost:
    /// O(1), or O(P) bound computations the first time they are needed.
    pub fn reconfigure(&mut self, scheme: Scheme, criterion: Criterion, plan: PlanOptions) -> Result<()> {
        validate(scheme, &criterion, &plan, self.set, Engine::Cpu)?;
        if criterion.needs_bounds() && self.prepared.hessians.len() != self.set.patches.len() {
            self.prepared = Prepared::for_criterion(self.set, &criterion);
        }
        (self.scheme, self.criterion, self.options.plan) = (scheme, criterion, plan);
        self.planned_ok = false;
        self.laid_out = false;
        Ok(())
    }

    /// Tessellates one frame seen from `camera` (None: [`TessellatorOptions`]'s `plan.camera`,
    /// or no camera for criteria and options that need none) into the tessellator's own buffers, reused from the last frame, and returns
    /// them: [`Tessellator::plan_frame`] then [`Tessellator::write_frame`]. Cost: the plan's
    /// (see [`Scheme::plan`]) plus O(output), parallel.
    pub fn frame(&mut self, camera: Option<&Camera>) -> Result<&Mesh> {
        on_pool(|| {
            self.plan_here(camera)?;
            self.write_mesh_here()
        })?;
        Ok(&self.mesh)
    }

    /// The first half of [`Tessellator::frame`]: plans the frame from `camera` and lays out
    /// its output, so a caller knows the exact vertex and triangle counts (and can say how
    /// long the write will take, or refuse it) before anything of the output's size exists.
    /// Cost: the plan's plus the layout's (O(E + P)).
    pub fn plan_frame(&mut self, camera: Option<&Camera>) -> Result<&Layout> {
        on_pool(|| self.plan_here(camera))?;
        Ok(&self.layout)
    }

    /// [`Tessellator::plan_frame`] on the calling thread.
    fn plan_here(&mut self, camera: Option<&Camera>) -> Result<()> {
        let options =
            PlanOptions { camera: camera.copied().or(self.options.plan.camera), ..self.options.plan };
        let start = Instant::now();
        self.planned_ok = false;
        self.laid_out = false;
        self.scheme.plan_into(
            self.set,
            &self.prepared,
            &self.criterion,
            &options,
            &mut self.scratch,
            &mut self.planned,
        )?;
        self.planned_ok = true;
        let planned = &self.planned;
        let (criterion, resolve) = self.scratch.stage_times();
        let planning = start.elapsed();
        let start = Instant::now();
        let (counts, edge_counts) = (self.scratch.plan_counts(), self.scratch.edge_counts());
        let (plan, pattern, options) = (&planned.plan, &planned.pattern, &self.options.engine);
        self.layout.build_counted(self.set, plan, pattern, options, counts, edge_counts)?;
        self.laid_out = true;
        self.pending = FrameTimings {
            criterion,
            // Whatever planning did besides the criterion counts as resolving.
            resolve: planning.saturating_sub(criterion).max(resolve),
            layout: start.elapsed(),
            ..FrameTimings::default()
        };
        // A frame planned for another engine to draw reports its planning stages.
        self.timings = self.pending;
        Ok(())
    }

    /// The second half of [`Tessellator::frame`]: writes the frame that
    /// [`Tessellator::plan_frame`] laid out into the tessellator's buffers and returns them.
    ///
    /// Errors: [`crate::Error::PlanMismatch`] when no frame was planned and laid out since the
    /// last write; the engine's otherwise. Cost: O(output), parallel.
    pub fn write_frame(&mut self) -> Result<&Mesh> {
        on_pool(|| self.write_mesh_here())?;
        Ok(&self.mesh)
    }

    /// [`Tessellator::write_frame`] on the calling thread.
    fn write_mesh_here(&mut self) -> Result<()> {
        let mut mesh = std::mem::take(&mut self.mesh);
        let written = self.write_planned_here(Output::Mesh(&mut mesh));
        self.mesh = mesh;
        written
    }

    /// Writes the frame [`Tessellator::plan_frame`] laid out into `out`. Cost: O(output),
    /// parallel.
    fn write_planned(&mut self, out: Output<'_>) -> Result<()> {
        on_pool(|| self.write_planned_here(out))
    }

    /// [`Tessellator::write_planned`] on the calling thread.
    fn write_planned_here(&mut self, out: Output<'_>) -> Result<()> {
        if !std::mem::take(&mut self.laid_out) {
            return Err(crate::Error::PlanMismatch { what: "write_frame without a planned frame".into() });
        }
        let start = Instant::now();
        let planned = &self.planned;
        self.fast.retarget(&planned.plan);
        // The check's patterns, where it built them for this plan: the engine adds its own.
        let mut built = self.scratch.check_patterns();
        let triangles = self.layout.triangle_count() as u64;
        // The distinct patterns are found by the write, beside its edges.
        let took = self.fast.defer_patterns(&planned.plan, &planned.pattern, triangles, built.as_deref_mut());
        let filled = start.elapsed();
        let fast = Some(&self.fast);
        let (plan, pattern, layout_ref) = (&planned.plan, &planned.pattern, &self.layout);
        let written = match out {
            Output::Mesh(mesh) => {
                engine::write_with(self.set, plan, pattern, layout_ref, self.options.engine, mesh, fast)
            }
            Output::Buffers(buffers) => {
                engine::write_into(self.set, plan, pattern, layout_ref, buffers, fast)
            }
        };
        if let (true, Some(built)) = (took, built) {
            self.fast.return_patterns(built);
        }
        let written = written?;
        self.timings = FrameTimings {
            // The pattern cache's fill runs in the vertex pass (beside the edges), and counts
            // with it.
            write_vertices: filled + written.vertices,
            write_indices: written.indices,
            write: start.elapsed(),
            ..self.pending
        };
        Ok(())
    }

    /// The last frame's pattern (None before the first frame).
    pub fn pattern(&self) -> Option<&crate::scheme::SchemePattern> {
        self.planned_ok.then_some(&self.planned.pattern)
    }

    /// The last frame's mesh (empty before the first frame).
    pub fn mesh(&self) -> &Mesh {
        &self.mesh
    }

    /// How long each stage of the last successful frame took (after
    /// [`Tessellator::plan_frame`] alone, its planning stages, the write's zero).
    pub fn timings(&self) -> FrameTimings {
        self.timings
    }

    /// The last frame's mesh, handed over with the tessellator's other buffers dropped: for
    /// a caller done with frames. Cost: O(1).
    pub fn into_mesh(self) -> Mesh {
        self.mesh
    }

    /// The last frame's mesh, handed over and replaced by an empty one: for a caller that
    /// keeps each frame (the Python package's arrays own their buffers), at the price of the
    /// next frame allocating its buffers anew. Cost: O(1).
    pub fn take_mesh(&mut self) -> Mesh {
        std::mem::take(&mut self.mesh)
    }

    /// [`Tessellator::frame`], handed to `builder`: a builder that lends its arrays
    /// ([`MeshBuilder::buffers`]) receives the engine's parallel writes directly (the
    /// tessellator's own mesh left as it was); any other receives the frame streamed, vertex
    /// after vertex, then triangle after triangle, from the tessellator's mesh. Cost: that of
    /// `frame`, plus one pass over the output when streamed.
    pub fn frame_into(&mut self, camera: Option<&Camera>, builder: &mut impl MeshBuilder) -> Result<()> {
        let layout = self.plan_frame(camera)?;
        let (vertices, triangles) = (layout.vertex_count(), layout.triangle_count());
        let engine = self.options.engine;
        if !engine.corner_params && !engine.strips {
            builder.begin(vertices, triangles);
            if let Some(buffers) = builder.buffers(vertices, triangles) {
                self.write_planned(Output::Buffers(buffers))?;
                builder.end();
                return Ok(());
            }
            let mesh = self.write_frame()?;
            return stream(mesh, builder, false);
        }
        let mesh = self.write_frame()?;
        stream(mesh, builder, true)
    }

    /// The last frame's plan (None before the first frame).
    pub fn plan(&self) -> Option<&Plan> {
        self.planned_ok.then_some(&self.planned.plan)
    }

    /// The last frame's guarantee report, for error-bounded criteria.
    pub fn report(&self) -> Option<&BoundReport> {
        self.planned.report.as_ref().filter(|_| self.planned_ok)
    }

    /// The last frame's output layout (offsets by edge and patch; see [`engine::layout`]).
    pub fn layout(&self) -> &Layout {
        &self.layout
    }

    /// The scheme this tessellator draws.
    pub fn scheme(&self) -> Scheme {
        self.scheme
    }
}

/// Where [`Tessellator::write_planned`] writes.
enum Output<'m> {
    /// A `Mesh`, sized, with corner parameters and strips where the options ask for them.
    Mesh(&'m mut Mesh),
    /// A builder's lent arrays.
    Buffers(MeshBuffers<'m>),
}

/// Streams `mesh` to `builder` (`begin` first when `begin`; the caller called it otherwise).
fn stream(mesh: &Mesh, builder: &mut impl MeshBuilder, begin: bool) -> Result<()> {
    if begin {
        builder.begin(mesh.vertex_count(), mesh.triangle_count());
    }
    for i in 0..mesh.vertex_count() {
        builder.vertex(mesh.positions[i], mesh.normals[i], mesh.uvs[i], mesh.vertex_patch[i]);
    }
    for t in 0..mesh.triangle_count() {
        builder.triangle(mesh.triangle(t), mesh.triangle_patch[t]);
    }
    builder.end();
    Ok(())
}

/// Runs `f` on a worker of the current rayon pool: the calling thread where it is one (a
/// caller inside `ThreadPool::install`), else a worker of the global pool while the caller
/// waits. Why: a frame is a dozen parallel passes. Started from outside the pool, each pass
/// wakes a worker and puts the caller to sleep until it is done, two context switches a
/// pass; from a worker, a pass hands its halves to the others through the pool's queues,
/// and only the frame's start and end cross threads. On two cores that was a sixth of the
/// 0.001 % torus's 3 ms frame on one thread, an eighth on two.
fn on_pool<R: Send>(f: impl FnOnce() -> R + Send) -> R {
    rayon::scope(|_| f())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn teapot() -> SurfaceSet {
        let path = crate::test_support::data("patches/teapot.patches");
        SurfaceSet::from_patch_file(
            &crate::io::patches::read_patches(&path).expect("test model"),
            Default::default(),
        )
    }

    /// A fresh transition plan of `set` for `criterion` from `camera`, and its mesh.
    fn fresh_transition(set: &SurfaceSet, criterion: &Criterion, camera: Camera) -> (SchemePlan, Mesh) {
        let options = PlanOptions { camera: Some(camera), ..PlanOptions::default() };
        let planned = Scheme::Transition.plan(set, criterion, &options).unwrap();
        let fresh = engine::tessellate(set, &planned.plan, &planned.pattern, Default::default()).unwrap();
        (planned, fresh)
    }

    /// Frames through the tessellator equal a fresh plan and tessellation per camera, with
    /// buffers reused from frame to frame, and a builder receives the same mesh.
    #[test]
    fn frames_equal_fresh_tessellations() {
        let set = teapot();
        let (lo, hi) = set.bounds();
        let criterion = Criterion::PixelError(2.0);
        let mut tess =
            Tessellator::new(&set, Scheme::Transition, criterion, TessellatorOptions::default()).unwrap();
        let mut built = Mesh::default();
        for k in 0..4 {
            let mut camera = Camera::framing(lo, hi, 640, 480);
            camera.eye = camera.target + (camera.eye - camera.target) * (1.0 + 0.7 * k as f64);
            let (planned, fresh) = fresh_transition(&set, &criterion, camera);
            let mesh = tess.frame(Some(&camera)).unwrap();
            assert_eq!(*mesh, fresh, "frame {k}");
            tess.frame_into(Some(&camera), &mut built).unwrap();
            assert_eq!(built.positions, fresh.positions, "frame {k}: builder");
            assert_eq!(built.indices, fresh.indices, "frame {k}: builder");
            assert_eq!(built.triangle_patch, fresh.triangle_patch, "frame {k}: builder");
            assert_eq!(tess.plan(), Some(&planned.plan));
            assert_eq!(tess.layout().triangle_count(), fresh.triangle_count());
        }
        // Farther cameras need fewer triangles: the frames really differ.
        assert!(tess.report().unwrap().worst_ratio <= 1.0);
    }

    /// Frames fine enough that the a-posteriori check builds its patterns into a table, which
    /// the engine then writes with (adding the inputs the check did not meet): the same
    /// meshes as fresh tessellations, frame after frame, and the table really taken.
    #[test]
    fn frames_written_with_the_checks_patterns_equal_fresh_tessellations() {
        let set = teapot();
        let (lo, hi) = set.bounds();
        let criterion = Criterion::PixelError(0.25);
        let mut tess =
            Tessellator::new(&set, Scheme::Transition, criterion, TessellatorOptions::default()).unwrap();
        let mut taken = 0;
        for k in 0..5 {
            let mut camera = Camera::framing(lo, hi, 1280, 960);
            camera.eye = camera.target + (camera.eye - camera.target) * (0.5 + 0.3 * k as f64);
            let (_, fresh) = fresh_transition(&set, &criterion, camera);
            let mesh = tess.frame(Some(&camera)).unwrap();
            assert_eq!(*mesh, fresh, "frame {k}");
            // The check's table is given back after the write, holding its patterns and the
            // engine's; a check that built none leaves it empty.
            taken += usize::from(tess.scratch.tolerance.held_patterns() > 0);
        }
        assert!(taken >= 3, "the engine took the check's patterns in {taken} frames of 5");
    }

    /// The layout takes each patch's pattern counts from the a-posteriori check: they are
    /// the counts of the pattern the engine writes for it (its final input, after the rounds
    /// that raised edges, zero where culled), on a walk's frames of the teapot and of a
    /// Catmull-Clark cage, with and without culling, and under the Taylor bound (whose
    /// patterns the check does not keep, and whose frames here take rounds). Likewise each
    /// edge's inner samples, counted as the plan resolved its edges: a row per normal variant
    /// of its final segments where a visible patch uses it and its curve is not a point
    /// (the teapot's lid apex), none otherwise.
    #[test]
    fn the_checks_pattern_counts_are_those_of_the_written_patterns() {
        use crate::criterion::ErrorBound;
        use crate::pattern::Pattern;
        let path = crate::test_support::data("subdivision/catmark_torus.obj");
        let obj = crate::scene::mesh_grid(&crate::io::obj::read_obj(&path).expect("test cage"), 16);
        let cage = SurfaceSet::from_subdivision_cage(&obj, &path, Default::default()).expect("cage");
        let (mut rounds, mut culled, mut checked) = (0, 0, 0);
        let (mut unseen, mut collapsed, mut inner) = (0, 0, 0);
        let cases = [(false, ErrorBound::Hessian), (true, ErrorBound::Hessian), (true, ErrorBound::Taylor)];
        for (set, (cull, bound)) in [teapot(), cage].iter().flat_map(|set| cases.map(|c| (set, c))) {
            let (lo, hi) = set.bounds();
            let plan = PlanOptions { cull, bound, ..PlanOptions::default() };
            let options = TessellatorOptions { plan, ..TessellatorOptions::default() };
            let mut tess =
                Tessellator::new(set, Scheme::Transition, Criterion::PixelError(0.5), options).unwrap();
            for (k, camera) in crate::scene::walk(lo, hi, 4, 1280, 1024).into_iter().enumerate() {
                tess.plan_frame(Some(&camera)).unwrap();
                let counts = tess.scratch.plan_counts().expect("the check counted every patch");
                let (plan, pattern) = (&tess.planned.plan, &tess.planned.pattern);
                for (p, &c) in counts.iter().enumerate() {
                    let expected = match plan.is_visible(p) {
                        true => pattern.counts(&engine::layout::pattern_input(set, plan, p)),
                        false => (0, 0),
                    };
                    assert_eq!(c, expected, "patch {p}, frame {k}, cull {cull}, {bound:?}");
                    culled += usize::from(!plan.is_visible(p));
                    checked += 1;
                }
                let edge_counts = tess.scratch.edge_counts().expect("the check counted every edge");
                assert_eq!(edge_counts.len(), set.topology.edges.len());
                for (e, (&c, edge)) in edge_counts.iter().zip(&set.topology.edges).enumerate() {
                    let seen = set.topology.edge_uses(e).iter().any(|u| plan.is_visible(u.patch as usize));
                    let expected = match seen && !edge.collapsed {
                        true => (plan.segments(e) - 1) * edge.variants as u32,
                        false => 0,
                    };
                    assert_eq!(c, expected, "edge {e}, frame {k}, cull {cull}, {bound:?}");
                    unseen += usize::from(!seen && plan.segments(e) > 1);
                    collapsed += usize::from(seen && edge.collapsed && plan.segments(e) > 1);
                    inner += usize::from(c > 0);
                }
                rounds += tess.report().unwrap().rounds;
            }
        }
        assert!(rounds > 0 && culled > 0, "{rounds} rounds, {culled} culled of {checked}");
        // Edges whose segments alone would have counted samples: unseen, and collapsed.
        assert!(unseen > 0 && collapsed > 0 && inner > 0, "{unseen} unseen, {collapsed} collapsed, {inner}");
    }

    #[test]
    fn a_criterion_the_scheme_refuses_is_refused_up_front() {
        let set = teapot();
        let hardware = Scheme::Hardware(crate::sampling::Partitioning::FractionalOdd);
        let err = Tessellator::new(&set, hardware, Criterion::Tolerance(0.1), TessellatorOptions::default());
        assert!(matches!(err, Err(crate::Error::CriterionNotAccepted { .. })));
        let mut tess = Tessellator::new(
            &set,
            Scheme::Transition,
            Criterion::PixelError(1.0),
            TessellatorOptions::default(),
        )
        .unwrap();
        assert!(matches!(tess.frame(None), Err(crate::Error::NeedsCamera { .. })));
    }
    /// A builder that is not a `Mesh`: it receives the frame streamed, in the numbering of
    /// the tessellator's own mesh.
    #[derive(Default)]
    struct Interleaved {
        vertices: Vec<[f32; 8]>,
        triangles: Vec<[u32; 4]>,
        begun: Option<(usize, usize)>,
    }

    impl MeshBuilder for Interleaved {
        fn begin(&mut self, vertices: usize, triangles: usize) {
            self.vertices.clear();
            self.triangles.clear();
            self.begun = Some((vertices, triangles));
        }
        fn vertex(&mut self, p: [f32; 3], n: [f32; 3], uv: [f32; 2], _patch: u32) {
            self.vertices.push([p[0], p[1], p[2], n[0], n[1], n[2], uv[0], uv[1]]);
        }
        fn triangle(&mut self, t: [u32; 3], patch: u32) {
            self.triangles.push([t[0], t[1], t[2], patch]);
        }
    }

    #[test]
    fn a_streaming_builder_and_a_reconfigured_tessellator_get_the_same_frames() {
        let set = teapot();
        let (lo, hi) = set.bounds();
        let camera = Camera::framing(lo, hi, 640, 480);
        // The options' camera is the camera of frames given none.
        let plan = PlanOptions { camera: Some(camera), ..PlanOptions::default() };
        let options = TessellatorOptions { plan, ..TessellatorOptions::default() };
        let mut tess = Tessellator::new(&set, Scheme::Uniform, Criterion::Factor(3.0), options).unwrap();
        let mut streamed = Interleaved::default();
        tess.frame_into(None, &mut streamed).unwrap();
        let mesh = tess.frame(None).unwrap().clone();
        assert_eq!(streamed.begun, Some((mesh.vertex_count(), mesh.triangle_count())));
        for (i, v) in streamed.vertices.iter().enumerate() {
            assert_eq!(v[..3], mesh.positions[i], "vertex {i}");
            assert_eq!(v[6..], mesh.uvs[i], "vertex {i}");
        }
        let t = mesh.triangle_count() - 1;
        assert_eq!(streamed.triangles[t][..3], mesh.triangle(t));
        // Reconfigured for a pixel error: the frames of a fresh tessellator, from the options'
        // camera.
        let criterion = Criterion::PixelError(1.0);
        tess.reconfigure(Scheme::Transition, criterion, plan).unwrap();
        let fresh = Tessellator::new(&set, Scheme::Transition, criterion, options)
            .unwrap()
            .frame(None)
            .unwrap()
            .clone();
        assert_eq!(*tess.frame(None).unwrap(), fresh);
        assert!(tess.report().unwrap().worst_ratio <= 1.0);
        // A request the scheme refuses leaves the tessellator as it was.
        let odd = Scheme::Hardware(crate::sampling::Partitioning::FractionalOdd);
        assert!(matches!(
            tess.reconfigure(odd, criterion, plan),
            Err(crate::Error::CriterionNotAccepted { .. })
        ));
        assert_eq!(tess.scheme(), Scheme::Transition);
    }
}
