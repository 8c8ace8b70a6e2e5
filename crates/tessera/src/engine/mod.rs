//! The CPU engine: count → exclusive scan ([`layout`]) → parallel write (rayon).
//!
//! [`Layout::build`] counts every edge's and patch's output and scans the counts into
//! offsets with the one numbering rule (see [`layout`]); [`write()`] then fills the buffers,
//! each task its own disjoint slice. A shared edge's inner vertices are evaluated once, by the
//! edge's owner patch, and every patch on the edge indexes them: the mesh is watertight bit
//! for bit without welding. Split-normal variants copy the owner's position bits and take
//! their normal from a patch of their own variant.
//!
//! Two specialisations of evaluation change how positions are computed, never which vertices
//! and triangles there are (the tests compare each with the generic f64 evaluation):
//! bicubic patches (polynomial or rational) whose pattern interior is a uniform grid, and edges
//! of integer factors, are evaluated row by row (`uniform_quads`); every other point — any
//! scheme's pattern, any sampling, triangle patches — in blocks of f32 lanes
//! (`point_blocks`). Only rational patches whose weights span more than f32 keeps reliable
//! (`uniform_quads::MIN_WEIGHT_RATIO`) keep the generic evaluation throughout. Patterns that
//! repeat within a frame are built once (`pattern::cache`). One specialisation of writing: a
//! frame of triangle patches at one uniform factor (a mesh's PN triangles) skips the
//! per-patch bookkeeping and maps its triangles by addition (`uniform_triangles`).

use crate::criterion::Plan;
use crate::error::{Error, Result};
use crate::mesh::strips::RESTART;
use crate::mesh::{Mesh, MeshBuffers};
use crate::pattern::cache::{next_generation, Cached, PatternCache, RecentPatterns, MIN_TRIANGLES_PER_PATCH};
use crate::pattern::{LocalTessellation, Pattern, PatternInput, Slot};
use crate::surface::{Domain, Patch, SurfaceSet};
use glam::DVec2;
use rayon::prelude::*;
use stream_store::IndexWrites;

mod edge_params;
pub(crate) mod fast_evaluator;
pub mod layout;
pub(crate) mod point_blocks;
mod stream_store;
pub use stream_store::last_level_cache_bytes;
pub mod render_queues;
pub(crate) mod tree_points;
pub(crate) mod uniform_quads;
pub(crate) mod uniform_triangles;

pub use layout::Layout;

/// Engine options.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct EngineOptions {
    /// Fill [`Mesh::corner_params`] (needed to measure the approximation error).
    pub corner_params: bool,
    /// Refuse (with [`Error::OutputTooLarge`]) an output whose buffers would take more bytes
    /// than this, before allocating anything. `None`: no limit beyond the u32 index range.
    pub memory_limit: Option<u64>,
    /// Refuse (with [`Error::OutputTooLarge`]) an output of more triangles than this, before
    /// allocating anything. `None`: no limit.
    pub max_triangles: Option<u64>,
    /// Also fill [`Mesh::strips`], for patterns with a strip form ([`Pattern::strips`]);
    /// an error for the others.
    pub strips: bool,
}

impl EngineOptions {
    /// Limits for a run on this machine, the rule every front end (the command line, the
    /// Python package) applies: output buffers may take up to three quarters of the memory
    /// available now (Linux `MemAvailable`; 8 GiB where it cannot be read), and at most
    /// `max_triangles` triangles (None: what that memory holds at a typical vertex-to-triangle
    /// ratio of 1:2). So an absurd factor is refused before allocating instead of thrashing.
    /// Cost: one read of `/proc/meminfo`.
    pub fn within_available_memory(max_triangles: Option<u64>, corner_params: bool) -> EngineOptions {
        let available = std::fs::read_to_string("/proc/meminfo").ok().and_then(|m| {
            let line = m.lines().find(|l| l.starts_with("MemAvailable:"))?;
            line.split_whitespace().nth(1)?.parse::<u64>().ok().map(|kib| kib * 1024)
        });
        let memory = available.map_or(8 << 30, |b| b / 4 * 3);
        let per_two_triangles = crate::mesh::output_bytes(1, 2, corner_params);
        EngineOptions {
            corner_params,
            memory_limit: Some(memory),
            max_triangles: Some(max_triangles.unwrap_or(memory / per_two_triangles * 2)),
            strips: false,
        }
    }
}

/// Refuses an output of `vertices` and `triangles` that does not fit the u32 index range (the
/// layout's offsets are u32, as a GPU reads them), the address space or the limits in
/// `options`. Cost: O(1).
pub(crate) fn check_size(vertices: u64, triangles: u64, options: &EngineOptions) -> Result<()> {
    let bytes = crate::mesh::output_bytes(vertices, triangles, options.corner_params);
    if vertices > u32::MAX as u64
        || triangles > u32::MAX as u64
        || triangles.saturating_mul(3) > isize::MAX as u64 / 8
        || options.memory_limit.is_some_and(|limit| bytes > limit)
        || options.max_triangles.is_some_and(|limit| triangles > limit)
    {
        return Err(Error::OutputTooLarge { vertices, triangles, bytes });
    }
    Ok(())
}

/// Tessellates `set` with `pattern` following `plan`.
///
/// Preconditions: `plan` was made for `set` (else [`Error::PlanMismatch`]) and fits the
/// pattern's requirements ([`crate::scheme::Scheme::plan`] pairs them). Cost: O(output)
/// work, parallel over corners, edges and patches; memory O(output).
pub fn tessellate(
    set: &SurfaceSet,
    plan: &Plan,
    pattern: &dyn Pattern,
    options: EngineOptions,
) -> Result<Mesh> {
    let mut mesh = Mesh::default();
    tessellate_into(set, plan, pattern, options, &mut mesh)?;
    Ok(mesh)
}

/// [`tessellate`] into an existing mesh, whose buffers are reused: repeated calls then avoid
/// faulting in fresh memory. `out` is overwritten; on error its contents are unspecified.
pub fn tessellate_into(
    set: &SurfaceSet,
    plan: &Plan,
    pattern: &dyn Pattern,
    options: EngineOptions,
    out: &mut Mesh,
) -> Result<()> {
    let mut layout = Layout::default();
    layout.build(set, plan, pattern, &options)?;
    write(set, plan, pattern, &layout, options, out)
}

/// Writes the tessellation `layout` describes into `out`, reusing its buffers: the one writer
/// every CPU path uses. Vertices are evaluated by `fast_evaluator::FastEvaluator` where it
/// applies (f32 kernels: grids of bicubic patches, blocks of points elsewhere) and by the
/// generic f64 evaluation where it does not; the numbering, the triangles and every other
/// array do not depend on which.
///
/// Preconditions: `layout` was built for `set`, `plan` and `pattern`
/// ([`Layout::build`]). Cost: O(output), parallel.
pub fn write(
    set: &SurfaceSet,
    plan: &Plan,
    pattern: &dyn Pattern,
    layout: &Layout,
    options: EngineOptions,
    out: &mut Mesh,
) -> Result<()> {
    let mut fast = fast_evaluator::FastEvaluator::new(set, plan);
    fast.fill_patterns(plan, pattern, layout.triangle_count() as u64, None);
    write_with(set, plan, pattern, layout, options, out, Some(&fast)).map(|_| ())
}

/// Wall time of the two passes of [`write_with`].
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct WriteTimes {
    /// Corners, edge samples and patch interiors: every vertex record.
    pub vertices: std::time::Duration,
    /// Triangles (and strips, when asked for).
    pub indices: std::time::Duration,
}

/// [`write`] with the evaluator chosen by the caller (None: the generic f64 evaluation
/// everywhere), so that tests can compare the two.
///
/// Two passes, each parallel: every vertex record, then every triangle. A patch whose pattern
/// the frame's cache does not hold leaves its pattern's own triangles (local indices, those
/// that survive a collapsed corner) in its index range in the first pass, and the second maps
/// them in place; a cached pattern is read again instead. So no pattern is built twice, and
/// each pass's time is the stage `--stats` reports.
pub(crate) fn write_with(
    set: &SurfaceSet,
    plan: &Plan,
    pattern: &dyn Pattern,
    layout: &Layout,
    options: EngineOptions,
    out: &mut Mesh,
    fast: Option<&fast_evaluator::FastEvaluator<'_>>,
) -> Result<WriteTimes> {
    let start = std::time::Instant::now();
    let (vertices, triangles) = (layout.vertex_count(), layout.triangle_count());
    reuse(&mut out.positions, vertices, [0.0; 3]);
    reuse(&mut out.normals, vertices, [0.0; 3]);
    reuse(&mut out.uvs, vertices, [0.0; 2]);
    reuse(&mut out.vertex_patch, vertices, 0);
    reuse(&mut out.indices, 3 * triangles, 0);
    reuse(&mut out.triangle_patch, triangles, 0);
    let mut no_params = Vec::new();
    let params = if options.corner_params {
        let params = out.corner_params.get_or_insert_with(Vec::new);
        reuse(params, 3 * triangles, [0.0; 2]);
        params
    } else {
        out.corner_params = None;
        &mut no_params
    };
    out.collapsed_triangles = layout.collapsed_triangles as usize;
    let buffers = MeshBuffers {
        positions: &mut out.positions,
        normals: &mut out.normals,
        uvs: &mut out.uvs,
        vertex_patch: &mut out.vertex_patch,
        indices: &mut out.indices,
        triangle_patch: &mut out.triangle_patch,
    };
    let vertices_done =
        write_buffers(set, plan, pattern, layout, options.corner_params, buffers, params, fast);
    out.strips = if options.strips { Some(strips_of(set, plan, pattern, layout)?) } else { None };
    Ok(WriteTimes { vertices: vertices_done - start, indices: vertices_done.elapsed() })
}

/// [`write_with`] into a builder's own arrays (no corner parameters, no strips).
/// Errors: [`crate::Error::InvalidParameter`] when `out` does not hold exactly the layout's
/// counts. Cost: O(output), parallel.
pub(crate) fn write_into(
    set: &SurfaceSet,
    plan: &Plan,
    pattern: &dyn Pattern,
    layout: &Layout,
    out: MeshBuffers<'_>,
    fast: Option<&fast_evaluator::FastEvaluator<'_>>,
) -> Result<WriteTimes> {
    let (vertices, triangles) = (layout.vertex_count(), layout.triangle_count());
    if !out.fit(vertices, triangles) {
        return Err(crate::Error::InvalidParameter {
            name: "mesh builder buffers",
            reason: format!(
                "{} positions and {} indices lent for a frame of {vertices} vertices and {triangles} triangles",
                out.positions.len(),
                out.indices.len()
            ),
        });
    }
    let start = std::time::Instant::now();
    let vertices_done = write_buffers(set, plan, pattern, layout, false, out, &mut [], fast);
    Ok(WriteTimes { vertices: vertices_done - start, indices: vertices_done.elapsed() })
}

/// The two passes of [`write_with`] into arrays sized for `layout` (`out`, and `params`: three
/// corner parameters a triangle, or empty without them); returns when the vertex pass ended.
/// Preconditions: `out.fit(layout's counts)`. Cost: O(output), parallel.
#[allow(clippy::too_many_arguments)]
pub(crate) fn write_buffers(
    set: &SurfaceSet,
    plan: &Plan,
    pattern: &dyn Pattern,
    layout: &Layout,
    corner_params: bool,
    out: MeshBuffers<'_>,
    params: &mut [[f32; 2]],
    fast: Option<&fast_evaluator::FastEvaluator<'_>>,
) -> std::time::Instant {
    let topo = &set.topology;
    let MeshBuffers { positions, normals, uvs, vertex_patch, indices, triangle_patch } = out;
    let uniform = fast.filter(|f| f.triangles().active() && !corner_params);
    let bytes = std::mem::size_of_val(&*positions)
        + std::mem::size_of_val(&*normals)
        + std::mem::size_of_val(&*uvs)
        + std::mem::size_of_val(&*vertex_patch)
        + std::mem::size_of_val(&*indices)
        + std::mem::size_of_val(&*triangle_patch)
        + std::mem::size_of_val(&*params);
    let writes =
        stream_store::index_writes(bytes as u64, layout.triangle_count() as u64, set.patches.len() as u64);
    let stream = writes == IndexWrites::Streamed;
    let grain = task_grain(layout.triangle_count() as u64 + layout.vertex_count() as u64);
    let writer =
        Writer { set, plan, pattern, layout, fast, patterns: None, generation: next_generation(), grain };

    let mut all =
        VertexSlices { pos: &mut *positions, nrm: &mut *normals, uv: &mut *uvs, patch: &mut *vertex_patch };
    let corner_part = all.take_front(layout.corners as usize);
    let edge_part = all.take_front(layout.interior_offsets[0] as usize - layout.corners as usize);
    let patch_part =
        PatchOut { verts: all, idx: &mut *indices, tp: &mut *triangle_patch, params: &mut *params };
    // A pass over every patch, by the uniform triangle writer where it applies; the others
    // read the frame's patterns, filled first where that was left to the write (the corners
    // and edges, which do not read them, are written meanwhile).
    let patches_pass = |out: PatchOut<'_>, pass: Pass| {
        let patterns = fast.map(|f| f.frame_patterns(plan, pattern));
        let writer = Writer { patterns: patterns.as_deref().map(|p| p.cache()), ..writer };
        match uniform {
            Some(f) => f.triangles().patches(set, f.points(), layout, 0..set.patches.len(), out, pass),
            None => writer.patches(0..set.patches.len(), out, pass),
        }
    };
    rayon::join(
        || {
            write_corners(set, fast, corner_part);
            writer.edges(0..topo.edges.len(), edge_part);
        },
        || patches_pass(patch_part, Pass::Vertices { writes }),
    );
    // Within the cache and for small patterns, the vertex pass maps every patch's triangles
    // too (`Pass::Vertices`); the uniform triangle writer keeps its own two passes.
    let index_pass = writes != IndexWrites::WithVertices || uniform.is_some();
    // Split-normal entries take the position bits of their vertex's first entry. (A vertex
    // has one entry, or more where its normals split: without splits, no pass on the main
    // thread alone.)
    if topo.corner_entries.len() != topo.vertex_count as usize {
        for (i, entry) in topo.corner_entries.iter().enumerate() {
            if entry.position_entry as usize != i {
                positions[i] = positions[entry.position_entry as usize];
            }
        }
    }
    let vertices_done = std::time::Instant::now();

    let mut all =
        VertexSlices { pos: &mut *positions, nrm: &mut *normals, uv: &mut *uvs, patch: &mut *vertex_patch };
    all.take_front(layout.interior_offsets[0] as usize);
    let patch_part = PatchOut { verts: all, idx: indices, tp: triangle_patch, params };
    if index_pass {
        patches_pass(patch_part, Pass::Indices { stream });
    }
    vertices_done
}

/// Which of [`write_with`]'s passes a patch writer runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Pass {
    /// Interior vertices and their triangles, by the frame's [`IndexWrites`]: within the
    /// cache and for small patterns, every patch's triangles mapped to output vertices with
    /// their triangle patches, and no index pass follows; otherwise a pattern the cache holds
    /// leaves its triangles to the index pass, and one it does not hold maps them here (or,
    /// streamed, leaves its local indices for the index pass to map and stream out).
    ///
    /// Why map them here: the patch's pattern and numbers are at hand in this pass, and an
    /// index pass would find its input and its vertex numbers again (for a pattern built
    /// here, also read back what this pass wrote), and cost a parallel pass more. On frames
    /// of small patterns (the Catmull-Clark torus at 0.5 px, 13 triangles a patch) those
    /// per-patch steps were most of the index pass; on the cow's adaptive frames (5,804
    /// patches, all cached) a separate pass cost 3–5 % of the frame. Frames past the cache,
    /// or of large patterns, keep the two passes ([`IndexWrites::OwnPass`]).
    Vertices { writes: IndexWrites },
    /// Triangles and triangle patches; with `stream`, written by streaming stores (a frame
    /// well past the cache, [`IndexWrites::Streamed`]).
    Indices { stream: bool },
}

/// Makes `v` hold `len` elements, every one of which the writer then overwrites.
fn reuse<T: Copy>(v: &mut Vec<T>, len: usize, zero: T) {
    if v.capacity() < len {
        // A fresh zeroed allocation arrives as lazily zeroed pages: nothing is written here,
        // and the parallel pass faults the pages in; growing in place would first fill the
        // whole buffer on one thread.
        *v = Vec::new();
        *v = vec![zero; len];
    } else {
        // Only a grown tail is written here; a buffer of the right length is left as is.
        v.resize(len, zero);
    }
}

/// Parallel vertex buffers of one part of the output.
pub(crate) struct VertexSlices<'a> {
    pub pos: &'a mut [[f32; 3]],
    pub nrm: &'a mut [[f32; 3]],
    pub uv: &'a mut [[f32; 2]],
    pub patch: &'a mut [u32],
}

impl<'a> VertexSlices<'a> {
    /// Splits off the first `k` vertices.
    pub(crate) fn take_front(&mut self, k: usize) -> VertexSlices<'a> {
        VertexSlices {
            pos: take_front(&mut self.pos, k),
            nrm: take_front(&mut self.nrm, k),
            uv: take_front(&mut self.uv, k),
            patch: take_front(&mut self.patch, k),
        }
    }

    /// Vertices `r`, borrowed.
    #[inline(always)]
    fn range(&mut self, r: std::ops::Range<usize>) -> VertexSlices<'_> {
        VertexSlices {
            pos: &mut self.pos[r.clone()],
            nrm: &mut self.nrm[r.clone()],
            uv: &mut self.uv[r.clone()],
            patch: &mut self.patch[r],
        }
    }

    /// Vertex `k`: patch `patch` evaluated at `uv` (f64, rounded once).
    fn set(&mut self, k: usize, set: &SurfaceSet, patch: u32, uv: DVec2) {
        self.put(k, patch, uv, set.patches[patch as usize].eval(uv));
    }

    /// Vertex `k`: `p`, the point of patch `patch` at `uv` (rounded once).
    fn put(&mut self, k: usize, patch: u32, uv: DVec2, p: crate::surface::SurfacePoint) {
        self.pos[k] = p.position.as_vec3().to_array();
        self.nrm[k] = p.normal.as_vec3().to_array();
        self.uv[k] = uv.as_vec2().to_array();
        self.patch[k] = patch;
    }
}

/// Splits off the first `k` elements of `s`, leaving the rest in `s`.
pub(crate) fn take_front<'a, T>(s: &mut &'a mut [T], k: usize) -> &'a mut [T] {
    let (head, tail) = std::mem::take(s).split_at_mut(k);
    *s = tail;
    head
}

/// Every corner entry, evaluated at its owner's corner. Corners do not depend on the view or
/// the plan: with an evaluator they are evaluated once per set (and kernel) and copied in
/// every later frame.
fn write_corners(set: &SurfaceSet, fast: Option<&fast_evaluator::FastEvaluator<'_>>, out: VertexSlices<'_>) {
    match fast {
        Some(f) => f.corner_records().copy_to(out),
        None => evaluate_corners(set, None, out),
    }
}

/// The vertex records of every corner entry, kept from frame to frame.
#[derive(Debug, Default)]
pub(crate) struct CornerRecords {
    pos: Vec<[f32; 3]>,
    nrm: Vec<[f32; 3]>,
    uv: Vec<[f32; 2]>,
    patch: Vec<u32>,
}

impl CornerRecords {
    /// Every corner entry of `set`, evaluated as `fast` evaluates them. Cost: O(corners).
    pub(crate) fn evaluate(set: &SurfaceSet, fast: &fast_evaluator::FastEvaluator<'_>) -> CornerRecords {
        let n = set.topology.corner_entries.len();
        let mut records = CornerRecords {
            pos: vec![[0.0; 3]; n],
            nrm: vec![[0.0; 3]; n],
            uv: vec![[0.0; 2]; n],
            patch: vec![0; n],
        };
        let out = VertexSlices {
            pos: &mut records.pos,
            nrm: &mut records.nrm,
            uv: &mut records.uv,
            patch: &mut records.patch,
        };
        evaluate_corners(set, Some(fast), out);
        records
    }

    fn copy_to(&self, out: VertexSlices<'_>) {
        out.pos.copy_from_slice(&self.pos);
        out.nrm.copy_from_slice(&self.nrm);
        out.uv.copy_from_slice(&self.uv);
        out.patch.copy_from_slice(&self.patch);
    }
}

/// Evaluates every corner entry: on the grid kernels where they apply, by the closed form of
/// a PN corner or the generic evaluation elsewhere.
fn evaluate_corners(
    set: &SurfaceSet,
    fast: Option<&fast_evaluator::FastEvaluator<'_>>,
    mut out: VertexSlices<'_>,
) {
    if let Some(f) = fast.filter(|f| f.grid_corners()) {
        return f.corners(out);
    }
    let topo = &set.topology;
    for (i, e) in topo.corner_entries.iter().enumerate() {
        let (patch, c) = (&set.patches[e.owner_patch as usize], e.owner_corner as usize);
        match patch {
            // Mesh input has a corner per vertex: the closed form saves the sums.
            Patch::Pn(t) => {
                let q = t.corner(c);
                out.pos[i] = q.position.as_vec3().to_array();
                out.nrm[i] = q.normal.as_vec3().to_array();
                out.uv[i] = Domain::Tri.corner(c).as_vec2().to_array();
                out.patch[i] = e.owner_patch;
            }
            _ => out.set(i, set, e.owner_patch, patch.domain().corner(c)),
        }
    }
}

/// Appends the parameters, in the domain `d` of the patch of use `u`, of edge `e`'s inner
/// samples `k = 1 .. segments − 1` in canonical order: where that patch evaluates them. From
/// `fast`'s per-factor tables where it holds the edge's factor (the same values, without a
/// division and a placement per sample). Cost: O(segments).
#[inline]
fn push_edge_params(
    plan: &Plan,
    e: usize,
    d: Domain,
    u: &crate::topology::EdgeUse,
    fast: Option<&fast_evaluator::FastEvaluator<'_>>,
    uvs: &mut Vec<DVec2>,
) {
    match fast.and_then(|f| f.uniform_edge_params(plan.segments(e), d, u)) {
        Some(params) => uvs.extend_from_slice(params),
        None => uvs.extend(
            plan.inner_params(e)
                .map(|t| d.edge_point(u.local as usize, if u.reversed { 1.0 - t } else { t })),
        ),
    }
}

/// The inner samples of edge `e`, evaluated once per normal variant by a patch of that
/// variant (in blocks where `fast` is given, its parameters from its tables where they hold
/// them); variants after the first copy the first's position bits. `uvs` is scratch.
fn write_edge(
    set: &SurfaceSet,
    plan: &Plan,
    e: usize,
    out: VertexSlices<'_>,
    fast: Option<&fast_evaluator::FastEvaluator<'_>>,
    uvs: &mut Vec<DVec2>,
) {
    let topo = &set.topology;
    let inner = plan.segments(e) as usize - 1;
    let uses = topo.edge_uses(e);
    let VertexSlices { pos, nrm, uv, patch } = out;
    for variant in 0..topo.edges[e].variants as usize {
        let Some(u) = uses.iter().find(|u| u.variant as usize == variant) else { continue };
        let d = topo.patch_domains[u.patch as usize];
        uvs.clear();
        push_edge_params(plan, e, d, u, fast, uvs);
        let r = variant * inner..(variant + 1) * inner;
        let mut part = VertexSlices {
            pos: &mut pos[r.clone()],
            nrm: &mut nrm[r.clone()],
            uv: &mut uv[r.clone()],
            patch: &mut patch[r.clone()],
        };
        match fast {
            Some(f) => f.points().eval(set, u.patch as usize, uvs, part),
            None => {
                for (k, &q) in uvs.iter().enumerate() {
                    part.set(k, set, u.patch, q);
                }
            }
        }
        if variant > 0 {
            // Every variant's points lie where the first variant's do, bit for bit.
            pos.copy_within(0..inner, r.start);
        }
    }
}

/// Output work below this many triangles (or vertices) always runs as one task: smaller
/// tasks cost more to schedule than they save ([`task_grain`] sizes a frame's tasks).
const GRAIN: u32 = 2048;

/// A frame's tasks are about this share of a thread's part of the output ([`task_grain`]).
const TASKS_PER_THREAD: u64 = 64;

/// The largest task [`task_grain`] makes, in triangles and vertices.
const MAX_GRAIN: u64 = 32 * 1024;

/// The output work (triangles and vertices) below which a range of edges or patches runs as
/// one task: a sixty-fourth of each thread's part of the frame's `outputs`, within
/// [`GRAIN`]..=[`MAX_GRAIN`]. Why not a fixed size: a task of 2,048 outputs is a dozen cow
/// patches of small patterns but three patches of the torus at factor 16, whose frame then
/// ran 700 tasks a pass, and tasks of 8 k and 32 k made it 6 and 10 % faster on two
/// threads, while the cow's transition frame, at 32 k, had too few tasks to share and was
/// 4 % slower. Cost: O(1).
fn task_grain(outputs: u64) -> u32 {
    let threads = rayon::current_num_threads().max(1) as u64;
    (outputs / (TASKS_PER_THREAD * threads)).clamp(GRAIN as u64, MAX_GRAIN) as u32
}

/// How many edges ahead the writer asks for an owner's form (half as many patches: a
/// patch owns about two edges). The killeroo herd's vertex stage, one thread: 16.3 → 14.5 ms.
const FORM_LEAD: usize = 4;

/// What every write task reads.
struct Writer<'a> {
    set: &'a SurfaceSet,
    plan: &'a Plan,
    pattern: &'a dyn Pattern,
    layout: &'a Layout,
    fast: Option<&'a fast_evaluator::FastEvaluator<'a>>,
    /// The frame's distinct patterns, for the patch passes (the fast evaluator's, once
    /// filled).
    patterns: Option<&'a PatternCache>,
    /// This call's number, so that a thread's scratch built in an earlier call (for another
    /// pattern) is never taken for this one's.
    generation: u64,
    /// Output work below this runs as one task ([`task_grain`]).
    grain: u32,
}

/// The output of a range of patches: their interior vertices, indices, triangle patches and
/// (when asked for) corner parameters.
struct PatchOut<'a> {
    verts: VertexSlices<'a>,
    idx: &'a mut [u32],
    tp: &'a mut [u32],
    params: &'a mut [[f32; 2]],
}

impl Writer<'_> {
    /// The inner samples of `edges`, split in halves by output size and written in parallel
    /// (rayon's `join` allocates nothing, unlike collecting per-edge slices).
    fn edges(&self, edges: std::ops::Range<usize>, mut out: VertexSlices<'_>) {
        let offsets = &self.layout.edge_offsets;
        let size = offsets[edges.end] - offsets[edges.start];
        if edges.len() > 1 && size > self.grain {
            let mid = split_point(offsets, edges.clone());
            let left = out.split_off_front(mid, offsets, edges.start);
            rayon::join(|| self.edges(edges.start..mid, left), || self.edges(mid..edges.end, out));
            return;
        }
        // Most edges of a distant view have no inner sample: skipped without a split.
        let mut edges = edges;
        while let Some(e) = edges.next() {
            if offsets[e + 1] == offsets[e] {
                continue;
            }
            // The form of the owner a few edges ahead, asked for in time: a frame of many
            // small patterns reads its forms from memory (the killeroo herd's, 19 MB).
            if let Some(f) = self.fast.filter(|_| e + FORM_LEAD < self.set.topology.edges.len()) {
                f.points().prefetch_form(self.set.topology.edge_uses(e + FORM_LEAD)[0].patch as usize);
            }
            // The grid kernels' edges first: the runs below never take one (a tree's owner
            // has no grid form; an owner's run is of edges off the grid kernels), and asking
            // whether an edge starts a run was most of the time a coarse frame's edges took
            // beside their kernels.
            let inner = (offsets[e + 1] - offsets[e]) as usize;
            if let Some(f) = self.fast {
                // Two edges of one owner in one block where they fit, else the edge alone.
                if e + 1 < edges.end {
                    let next = (offsets[e + 2] - offsets[e + 1]) as usize;
                    if f.edge_pair(self.plan, e, [inner, next], &mut out) {
                        edges.start = e + 2;
                        continue;
                    }
                }
                if f.edge(self.plan, e, inner, &mut out) {
                    continue;
                }
            }
            if let Some(end) = self.tree_run(e, edges.end) {
                // Edges `e..end` are evaluated on their owners' trees, one stream of points.
                let part = out.take_front((offsets[end] - offsets[e]) as usize);
                self.tree_edge_run(e..end, part);
                edges.start = end;
                continue;
            }
            if let Some(end) = self.owner_run(e, edges.end) {
                // Edges `e..end` share their owner and lie one after the other in the output.
                let part = out.take_front((offsets[end] - offsets[e]) as usize);
                self.edge_run(e..end, part);
                edges.start = end;
                continue;
            }
            let part = out.take_front((offsets[e + 1] - offsets[e]) as usize);
            match self.fast {
                Some(f) if f.triangles().active() && self.set.topology.edges[e].variants == 1 => {
                    f.triangles().edge(self.set, f.points(), e, part)
                }
                fast => with_scratch(self.generation, |scratch| {
                    write_edge(self.set, self.plan, e, part, fast, &mut scratch.edge_params)
                }),
            }
        }
    }

    /// The end of the run of edges from `e` (before `end`) that [`Writer::tree_edge_run`]
    /// evaluates as one stream: edges with one normal variant whose owner evaluates their
    /// points one by one on its subdivision tree ([`PointBlocks::evaluates_on_tree`]), and
    /// edges without inner samples between them. None for fewer than two such edges.
    fn tree_run(&self, e: usize, end: usize) -> Option<usize> {
        let f = self.fast?;
        let (topo, offsets) = (&self.set.topology, &self.layout.edge_offsets);
        if f.triangles().active() || !f.points().any_tree() {
            return None;
        }
        // (An owner on its tree has no grid form, so the grid kernels never cover such an edge.)
        let on_tree = |x: usize| {
            let inner = (offsets[x + 1] - offsets[x]) as usize;
            topo.edges[x].variants == 1
                && f.points().evaluates_on_tree(self.set, topo.edge_uses(x)[0].patch as usize, inner)
        };
        if !on_tree(e) {
            return None;
        }
        let (mut last, mut count) = (e + 1, 1);
        for x in e + 1..end {
            if offsets[x + 1] == offsets[x] {
                continue;
            }
            if !on_tree(x) {
                break;
            }
            (last, count) = (x + 1, count + 1);
        }
        (count > 1).then_some(last)
    }

    /// The inner samples of `edges`, a run of [`Writer::tree_run`], evaluated by their owners
    /// as one stream into `out` (their samples, one edge after the other).
    fn tree_edge_run(&self, edges: std::ops::Range<usize>, out: VertexSlices<'_>) {
        let (set, plan) = (self.set, self.plan);
        let topo = &set.topology;
        with_scratch(self.generation, |scratch| {
            let (uvs, items) = (&mut scratch.edge_params, &mut scratch.tree_items);
            items.clear();
            let fast = self.fast.expect("tree_run checked the evaluator");
            for e in edges.filter(|&e| self.layout.edge_offsets[e + 1] > self.layout.edge_offsets[e]) {
                let owner = &topo.edge_uses(e)[0];
                uvs.clear();
                push_edge_params(plan, e, topo.patch_domains[owner.patch as usize], owner, Some(fast), uvs);
                items.extend(uvs.iter().map(|&uv| (owner.patch, uv)));
            }
            fast.points().eval_tree_stream(set, items, out);
        });
    }

    /// The end of the run of edges from `e` (before `end`) that [`Writer::edge_run`]
    /// evaluates in one call: edges owned by one patch whose form [`point_blocks`] evaluates in
    /// blocks, each with one normal variant and not on the grid kernels. None for a run of one
    /// edge (or none): the edge takes the usual path.
    ///
    /// Why: `Topology::build` numbers edges as their owners first meet them, patch by patch, so
    /// a patch's edges are neighbours in the output, and a coarse frame (a mesh's PN triangles
    /// at half a pixel) has mostly one or two inner samples an edge: one evaluation call per
    /// edge spent most of its block's lanes on padding and its setup on a point or two. Each
    /// lane is evaluated alone, so a point's bits do not depend on its neighbours in a block.
    fn owner_run(&self, e: usize, end: usize) -> Option<usize> {
        let f = self.fast?;
        let topo = &self.set.topology;
        let single = |e: usize| topo.edges[e].variants == 1 && !f.covers_edge(self.plan, e);
        if f.triangles().active() || !single(e) {
            return None;
        }
        let owner = topo.edge_uses(e)[0].patch;
        if !f.points().evaluates_in_blocks(owner as usize) {
            return None;
        }
        let run = (e + 1..end).take_while(|&x| topo.edge_uses(x)[0].patch == owner && single(x)).count();
        (run > 0).then_some(e + 1 + run)
    }

    /// The inner samples of `edges`, a run of [`Writer::owner_run`], evaluated in one call
    /// on their owner into `out` (their samples, one edge after the other).
    fn edge_run(&self, edges: std::ops::Range<usize>, out: VertexSlices<'_>) {
        let (set, plan) = (self.set, self.plan);
        let topo = &set.topology;
        let owner = topo.edge_uses(edges.start)[0].patch as usize;
        let d = topo.patch_domains[owner];
        with_scratch(self.generation, |scratch| {
            let uvs = &mut scratch.edge_params;
            uvs.clear();
            let fast = self.fast.expect("owner_run checked the evaluator");
            for e in edges.filter(|&e| self.layout.edge_offsets[e + 1] > self.layout.edge_offsets[e]) {
                push_edge_params(plan, e, d, &topo.edge_uses(e)[0], Some(fast), uvs);
            }
            fast.points().eval(set, owner, uvs, out);
        });
    }

    /// Pass `pass` of the interiors and triangles of `patches`, split like [`Writer::edges`].
    fn patches(&self, patches: std::ops::Range<usize>, mut out: PatchOut<'_>, pass: Pass) {
        let tris = &self.layout.triangle_offsets;
        let verts = &self.layout.interior_offsets;
        let size = (tris[patches.end] - tris[patches.start]) + (verts[patches.end] - verts[patches.start]);
        if patches.len() > 1 && size > self.grain {
            let mid = split_point(tris, patches.clone());
            let left = out.split_off_front(mid, self.layout, patches.start);
            rayon::join(
                || self.patches(patches.start..mid, left, pass),
                || self.patches(mid..patches.end, out, pass),
            );
            return;
        }
        // Each patch's part by its offsets from the first's (culled patches have none).
        let (t0, v0) = (tris[patches.start], verts[patches.start]);
        with_scratch(self.generation, |scratch| {
            for p in patches.filter(|&p| self.plan.is_visible(p)) {
                // As in `Writer::edges`.
                if let Some(f) = self.fast {
                    f.points().prefetch_form(p + FORM_LEAD / 2);
                }
                let t = (tris[p] - t0) as usize..(tris[p + 1] - t0) as usize;
                let v = (verts[p] - v0) as usize..(verts[p + 1] - v0) as usize;
                // The patch's part is cut from `out` by the callee: made here and passed by
                // value, its slices went through the stack in two widths, and reading them
                // back stalled on each patch (a coarse frame's patches loop spent about 4 %
                // of the frame on that one load).
                match pass {
                    Pass::Vertices { writes } => self.patch_vertices(p, &mut out, (v, t), scratch, writes),
                    Pass::Indices { stream } => self.patch_indices(p, &mut out, (v, t), scratch, stream),
                }
            }
        });
        if pass == (Pass::Indices { stream: true }) {
            // The task's streamed indices before its end is seen by the thread that joins it.
            stream_store::fence();
        }
    }

    /// Patch `p`'s pattern from the frame's cache, if it holds it (its input given patch
    /// `p`): without the triangles of its core grid, if it has one.
    fn cached(&self, p: usize) -> Option<(PatternInput, Cached<'_>)> {
        let cached = self.patterns.and_then(|c| c.get(p))?;
        Some((PatternInput { patch: p as u32, ..*cached.input }, cached))
    }

    /// Whether patch `p`'s triangles take the general form: some may drop out at a repeated
    /// corner, or parameters go along.
    fn general(&self, p: usize, params: &[[f32; 2]]) -> bool {
        !params.is_empty()
            || (self.set.topology.one_shape.is_none() && layout::has_repeated_corner(self.set, p))
    }

    /// The first pass for one visible patch: its pattern (cached, or built and reused from
    /// the last patch of the same input where the pattern allows), its interior vertices, its
    /// corner parameters, and — unless the second pass can read the pattern from the cache —
    /// its kept triangles: mapped to output vertices with their triangle patches, or with
    /// `stream` as local indices left in its index range for the second pass.
    fn patch_vertices(
        &self,
        p: usize,
        out: &mut PatchOut<'_>,
        (v, t): (std::ops::Range<usize>, std::ops::Range<usize>),
        scratch: &mut PatchScratch,
        writes: IndexWrites,
    ) {
        let stream = writes == IndexWrites::Streamed;
        let PatchOut { mut verts, idx, tp, params } = out.part(v, t);
        let (set, plan, layout) = (self.set, self.plan, self.layout);
        let general = self.general(p, params);
        // The triangles in the general form need the whole pattern, core included.
        let cached = self.cached(p).filter(|(_, c)| !general || c.core.is_none());
        let input = cached.map_or_else(|| layout::pattern_input(set, plan, p), |(input, _)| input);
        // A pattern built here found its interior grid with the build (a test of its
        // layout, which each patch would repeat); a cached one's is asked.
        let (local, interior, grid) = match cached {
            Some((_, c)) => (c.local, c.interior, None),
            None => {
                let built = scratch.patterns.get(self.generation, self.pattern, &input, false);
                (&built.local, &built.local.interior[..], Some(built.interior_grid))
            }
        };
        // A patch without interior vertices (most, in a distant view) asks no evaluator.
        let fast = self.fast.filter(|_| !interior.is_empty());
        let covers = |f: &fast_evaluator::FastEvaluator<'_>| {
            f.covers_grid(p, &input, || grid.unwrap_or_else(|| self.pattern.interior_grid(&input)))
        };
        match fast.map(|f| (f, covers(f))) {
            Some((f, Some(grid))) => f.interior(p, grid, verts),
            Some((f, None)) => {
                // A pattern's interior that is a grid (a core grid's points are) lets a tree
                // find its leaves' points by a walk instead of a search each.
                let grid = match cached.and_then(|(_, c)| c.core) {
                    Some(core) => Some(core.cells),
                    None => self.pattern.interior_grid(&input),
                };
                f.points().eval_grid(set, p, interior, grid, verts)
            }
            None => {
                for (k, &uv) in interior.iter().enumerate() {
                    verts.set(k, set, p as u32, uv);
                }
            }
        }
        if !params.is_empty() {
            let map = LocalMap { set, plan, layout, input, patch: p };
            map.param_table(interior, &mut scratch.param);
        }
        if let (Some((input, cached)), false) = (cached, general) {
            // Mapped here, while the patch's numbers are at hand, unless the frame's output
            // passes the cache: the index pass then maps them (and streams them out).
            if writes == IndexWrites::WithVertices {
                self.cached_indices(p, input, cached, idx, tp, scratch, false);
            }
            return;
        }
        if !stream && !general {
            // Every triangle kept as it is (no repeated corner, no parameters): mapped on the
            // way out, in one pass.
            debug_assert_eq!(idx.len(), 3 * local.triangles.len());
            let map = self.local_index_map(p, input, &mut scratch.vertex);
            for (out, tri) in idx.chunks_exact_mut(3).zip(&local.triangles) {
                out.copy_from_slice(&tri.map(&map));
            }
            tp.fill(p as u32);
            return;
        }
        let mut t = 0;
        for tri in &local.triangles {
            if general && layout::degenerate_after_collapse(set, &input, p, tri) {
                continue;
            }
            idx[3 * t..3 * t + 3].copy_from_slice(tri);
            if !params.is_empty() {
                for c in 0..3 {
                    params[3 * t + c] = scratch.param[tri[c] as usize];
                }
            }
            t += 1;
        }
        debug_assert_eq!(3 * t, idx.len());
        if !stream {
            self.map_local_indices(p, input, idx, &mut scratch.vertex);
            tp.fill(p as u32);
        }
    }

    /// Maps patch `p`'s triangles in `idx`, local indices of its pattern for `input`, to
    /// output vertices by the numbering rule: interior vertices are numbered in the same order
    /// locally and in the output, so each maps by one addition, and only boundary indices go
    /// through the patch's table (`table`, scratch).
    fn map_local_indices(&self, p: usize, input: PatternInput, idx: &mut [u32], table: &mut Vec<u32>) {
        let map = self.local_index_map(p, input, table);
        for l in idx.iter_mut() {
            *l = map(*l);
        }
    }

    /// The numbering rule of [`Writer::map_local_indices`] for patch `p` with `input`: the
    /// output vertex of each local index, its boundary vertices' through `table` (filled
    /// here).
    #[inline(always)]
    fn local_index_map<'t>(
        &self,
        p: usize,
        input: PatternInput,
        table: &'t mut Vec<u32>,
    ) -> impl Fn(u32) -> u32 + 't {
        let (set, plan, layout) = (self.set, self.plan, self.layout);
        LocalMap { set, plan, layout, input, patch: p }.vertex_table(0, table);
        let first = input.interior_base();
        let delta = layout.interior_vertex(p, 0).wrapping_sub(first);
        let table = &*table;
        move |l| if l >= first { l.wrapping_add(delta) } else { table[l as usize] }
    }

    /// The second pass for one visible patch: its triangles mapped to output vertices by the
    /// numbering rule. Interior vertices are numbered in the same order locally and in the
    /// output, so every index maps by one addition (vectorized) and only boundary indices go
    /// through the patch's table.
    fn patch_indices(
        &self,
        p: usize,
        out: &mut PatchOut<'_>,
        (v, t): (std::ops::Range<usize>, std::ops::Range<usize>),
        scratch: &mut PatchScratch,
        stream: bool,
    ) {
        let PatchOut { idx, tp, params, .. } = out.part(v, t);
        let (set, plan) = (self.set, self.plan);
        let cached = self.cached(p).filter(|_| !self.general(p, params));
        let Some((input, cached)) = cached else {
            if stream {
                // The first pass left the local indices here.
                let input = layout::pattern_input(set, plan, p);
                self.map_local_indices(p, input, idx, &mut scratch.vertex);
                stream_store::fill(tp, p as u32);
            }
            // Without streaming, the first pass mapped them (`Pass::Vertices`).
            return;
        };
        self.cached_indices(p, input, cached, idx, tp, scratch, stream);
    }

    /// Patch `p`'s triangles from its cached pattern (`input`, `cached`): mapped to output
    /// vertices by the numbering rule into `idx`, with their triangle patches into `tp`; with
    /// `stream`, mapped in the thread's buffer and streamed out.
    #[allow(clippy::too_many_arguments)]
    fn cached_indices(
        &self,
        p: usize,
        input: PatternInput,
        cached: Cached<'_>,
        idx: &mut [u32],
        tp: &mut [u32],
        scratch: &mut PatchScratch,
        stream: bool,
    ) {
        let (set, plan, layout) = (self.set, self.plan, self.layout);
        let map = LocalMap { set, plan, layout, input, patch: p };
        map.vertex_table(0, &mut scratch.vertex);
        let first = input.interior_base();
        let interior = layout.interior_vertex(p, 0);
        let delta = interior.wrapping_sub(first);
        // The core by its rule, then the cached triangles after it; the cache knows where
        // their boundary indices are.
        let table = &scratch.vertex[..];
        let (rest, core_triangles) = cached.after_core();
        let write = |out: &mut [u32]| {
            let (core_out, rest_out) = out.split_at_mut(3 * core_triangles as usize);
            if let Some(core) = cached.core {
                core.write(interior, |l| table[l as usize], core_out);
            }
            let rest = rest.as_flattened();
            rest_out.iter_mut().zip(rest).for_each(|(out, &l)| *out = l.wrapping_add(delta));
            for &i in cached.boundary {
                rest_out[i as usize] = table[rest[i as usize] as usize];
            }
        };
        if stream {
            // Mapped in the thread's buffer (in the cache), then streamed out once.
            let mapped = &mut scratch.indices;
            mapped.clear();
            mapped.resize(idx.len(), 0);
            write(mapped);
            stream_store::copy(idx, mapped);
        } else {
            write(idx);
        }
        if stream {
            stream_store::fill(tp, p as u32);
        } else {
            tp.fill(p as u32);
        }
    }
}

/// The index in `range` that splits the output between `offsets[range.start]` and
/// `offsets[range.end]` about in half (strictly inside the range).
fn split_point(offsets: &[u32], range: std::ops::Range<usize>) -> usize {
    let half = offsets[range.start] + (offsets[range.end] - offsets[range.start]) / 2;
    let k = offsets[range.start..range.end].partition_point(|&o| o <= half);
    (range.start + k.max(1)).min(range.end - 1).max(range.start + 1)
}

impl<'a> VertexSlices<'a> {
    /// Splits off the vertices of parts `start..end` (by `offsets`).
    fn split_off_front(&mut self, end: usize, offsets: &[u32], start: usize) -> VertexSlices<'a> {
        self.take_front((offsets[end] - offsets[start]) as usize)
    }
}

impl<'a> PatchOut<'a> {
    /// Vertices `v` and triangles `t` of this output, borrowed.
    #[inline(always)]
    fn part(&mut self, v: std::ops::Range<usize>, t: std::ops::Range<usize>) -> PatchOut<'_> {
        PatchOut {
            verts: self.verts.range(v),
            idx: &mut self.idx[3 * t.start..3 * t.end],
            tp: &mut self.tp[t.clone()],
            params: if self.params.is_empty() { &mut [] } else { &mut self.params[3 * t.start..3 * t.end] },
        }
    }

    /// Splits off the output of patches `start..end`.
    fn split_off_front(&mut self, end: usize, layout: &Layout, start: usize) -> PatchOut<'a> {
        let t = (layout.triangle_offsets[end] - layout.triangle_offsets[start]) as usize;
        PatchOut {
            verts: self.verts.split_off_front(end, &layout.interior_offsets, start),
            idx: take_front(&mut self.idx, 3 * t),
            tp: take_front(&mut self.tp, t),
            params: if self.params.is_empty() { &mut [] } else { take_front(&mut self.params, 3 * t) },
        }
    }
}

/// A thread's patterns and tables, kept from call to call so that a steady loop allocates
/// nothing. Patterns that do not depend on the patch (all but ESC's and the warped SD-2's)
/// are kept by input ([`RecentPatterns`]): an adaptive frame of small patterns has a few
/// hundred distinct inputs over tens of thousands of patches.
#[derive(Default)]
pub(crate) struct PatchScratch {
    patterns: RecentPatterns,
    generation: u64,
    vertex: Vec<u32>,
    /// A patch's output indices before they are streamed out ([`Writer::patch_indices`]).
    indices: Vec<u32>,
    param: Vec<[f32; 2]>,
    /// Parameters of an edge's inner samples.
    edge_params: Vec<glam::DVec2>,
    /// A run of edges' inner samples as (owner patch, parameters) ([`Writer::tree_edge_run`]).
    tree_items: Vec<(u32, glam::DVec2)>,
}

impl PatchScratch {
    /// `input`'s pattern, built unless this thread built it earlier in the same call.
    pub(crate) fn pattern(&mut self, pattern: &dyn Pattern, input: &PatternInput) -> &LocalTessellation {
        &self.patterns.get(self.generation, pattern, input, false).local
    }
}

thread_local! {
    static SCRATCH: std::cell::RefCell<PatchScratch> = std::cell::RefCell::new(PatchScratch::default());
}

/// Runs `f` with this thread's scratch for call `generation` (a fresh one if the thread's is
/// in use further up its stack, as when rayon runs another task inside a join).
pub(crate) fn with_scratch<R>(generation: u64, f: impl FnOnce(&mut PatchScratch) -> R) -> R {
    SCRATCH.with(|cell| match cell.try_borrow_mut() {
        Ok(mut scratch) => {
            scratch.generation = generation;
            f(&mut scratch)
        }
        Err(_) => f(&mut PatchScratch { generation, ..PatchScratch::default() }),
    })
}

/// Runs `f` with this thread's buffer for a patch's indices before they are streamed out
/// (a fresh one if the thread's scratch is in use further up its stack).
pub(crate) fn with_index_buffer<R>(f: impl FnOnce(&mut Vec<u32>) -> R) -> R {
    SCRATCH.with(|cell| match cell.try_borrow_mut() {
        Ok(mut scratch) => f(&mut scratch.indices),
        Err(_) => f(&mut Vec::new()),
    })
}

/// Fills `cache` for a frame: finds the distinct inputs of `plan`'s visible patches and
/// builds each once, or turns the cache off for this frame where it would not pay (patterns
/// that depend on the patch, or fewer than [`MIN_TRIANGLES_PER_PATCH`] triangles per visible patch: `triangles` is
/// the layout's count). Cost: one hash lookup per visible patch (sequential), then the
/// distinct builds (parallel); no allocation once the buffers have grown to the frame.
pub(crate) fn fill_pattern_cache(
    cache: &mut PatternCache,
    set: &SurfaceSet,
    plan: &Plan,
    pattern: &dyn Pattern,
    triangles: u64,
    keep: bool,
) {
    let visible = plan.visible.iter().filter(|&&v| v != 0).count() as u64;
    if pattern.depends_on_patch() || triangles < MIN_TRIANGLES_PER_PATCH as u64 * visible {
        cache.clear();
        return;
    }
    let input_of = |p: usize| plan.is_visible(p).then(|| layout::pattern_input(set, plan, p));
    if keep {
        cache.extend_inputs(pattern, set.patches.len(), input_of, false);
    } else {
        cache.fill_inputs(pattern, set.patches.len(), input_of, false);
    }
}

/// Where a patch's samples of one edge lie in the output ([`LocalMap::edge_samples`]).
#[derive(Clone, Copy)]
enum EdgeSamples {
    /// A collapsed curve: every sample is the corner's vertex.
    Corner(u32),
    /// Canonical samples `1..segments` from `first` on; the patch's sample `k` is canonical
    /// sample `segments − k` where it runs against the edge.
    Run { first: u32, segments: u32, reversed: bool },
}

impl EdgeSamples {
    /// The output vertex of the patch's sample `k` (`1 ≤ k < segments`).
    #[inline(always)]
    fn vertex(self, k: u32) -> u32 {
        match self {
            EdgeSamples::Corner(c) => c,
            EdgeSamples::Run { first, segments, reversed } => {
                first + if reversed { segments - k } else { k } - 1
            }
        }
    }
}

/// Per-patch mapping from local vertex indices to output vertices: the numbering rule of
/// [`layout`] applied to one patch.
struct LocalMap<'a> {
    set: &'a SurfaceSet,
    plan: &'a Plan,
    layout: &'a Layout,
    input: PatternInput,
    patch: usize,
}

impl LocalMap<'_> {
    fn corner_vertex(&self, c: usize) -> u32 {
        self.set.topology.patch_corner_entries[self.patch][c]
    }

    /// Output vertex of local index `l`. Cost: O(corner count).
    fn vertex(&self, l: u32) -> u32 {
        match self.input.slot(l) {
            Slot::Corner(c) => self.corner_vertex(c),
            Slot::Interior(j) => self.layout.interior_vertex(self.patch, j),
            Slot::Edge(e, k) => self.edge_vertex(e, k),
        }
    }

    /// Output vertex of the patch's own sample `k` of local edge `e`.
    fn edge_vertex(&self, e: usize, k: u32) -> u32 {
        self.edge_samples(e).vertex(k)
    }

    /// Where the samples of local edge `e` lie in the output, its entries read once (a
    /// patch's table reads every sample of an edge).
    #[inline(always)]
    fn edge_samples(&self, e: usize) -> EdgeSamples {
        let pe = self.set.topology.patch_edges[self.patch][e];
        if pe.collapsed {
            // Every sample of a collapsed curve is its single point: the corner.
            return EdgeSamples::Corner(self.corner_vertex(e));
        }
        let edge = pe.edge as usize;
        let segments = self.plan.segments(edge);
        let first = self.layout.edge_vertex(edge, pe.variant as u32, segments, 1);
        EdgeSamples::Run { first, segments, reversed: pe.reversed }
    }

    /// The output vertex of every local index, in local order. Cost: O(local vertices).
    fn vertex_table(&self, interior: usize, table: &mut Vec<u32>) {
        table.clear();
        let nc = self.input.domain.corner_count();
        table.extend((0..nc).map(|c| self.corner_vertex(c)));
        for e in 0..nc {
            // By the samples' kind, not a test per sample: small patterns are mostly edges.
            let inner = self.input.segments[e].saturating_sub(1);
            match self.edge_samples(e) {
                EdgeSamples::Corner(c) => table.extend(std::iter::repeat_n(c, inner as usize)),
                EdgeSamples::Run { first, reversed: false, .. } => table.extend(first..first + inner),
                EdgeSamples::Run { first, reversed: true, .. } => table.extend((first..first + inner).rev()),
            }
        }
        let base = self.layout.interior_vertex(self.patch, 0);
        table.extend((0..interior as u32).map(|j| base + j));
    }

    /// Parameters in this patch of every local index, in local order (f32 as stored).
    fn param_table(&self, interior: &[glam::DVec2], table: &mut Vec<[f32; 2]>) {
        table.clear();
        let d = self.input.domain;
        let nc = d.corner_count();
        table.extend((0..nc).map(|c| d.corner(c).as_vec2().to_array()));
        for e in 0..nc {
            let pe = self.set.topology.patch_edges[self.patch][e];
            table.extend((1..self.input.segments[e]).map(|k| {
                d.edge_point(e, self.plan.local_param(pe.edge as usize, k, pe.reversed)).as_vec2().to_array()
            }));
        }
        table.extend(interior.iter().map(|uv| uv.as_vec2().to_array()));
    }
}

/// The strip form of every visible patch, over output vertices, one [`RESTART`] between
/// patches. Triangles that degenerate at collapsed corners get a repeated index, so the
/// decoder drops them just as the list writer does.
fn strips_of(set: &SurfaceSet, plan: &Plan, pattern: &dyn Pattern, layout: &Layout) -> Result<Vec<u32>> {
    let per_patch: Vec<Option<Vec<u32>>> = (0..set.patches.len())
        .into_par_iter()
        .map(|p| {
            if !plan.is_visible(p) {
                return Some(Vec::new());
            }
            let input = layout::pattern_input(set, plan, p);
            let mut local = Vec::new();
            if !pattern.strips(&input, &mut local) {
                return None;
            }
            let map = LocalMap { set, plan, layout, input, patch: p };
            for l in &mut local {
                if *l != RESTART {
                    *l = map.vertex(*l);
                }
            }
            Some(local)
        })
        .collect();
    let mut out = Vec::new();
    for strips in per_patch {
        let Some(strips) = strips else {
            return Err(Error::NoStripForm { pattern: pattern.name() });
        };
        if strips.is_empty() {
            continue;
        }
        if !out.is_empty() {
            out.push(RESTART);
        }
        out.extend_from_slice(&strips);
    }
    Ok(out)
}

/// The per-corner patch parameters of this engine's output for `plan` under `pattern` (what
/// [`EngineOptions::corner_params`] fills, value for value), without evaluating a point: for
/// an engine whose triangles are this engine's index for index — the GPU engine's — so that
/// its output gets the parameters from the same rule (each patch's pattern, the plan's edge
/// sampling, the triangles a collapsed corner drops). Three per triangle, in triangle order.
///
/// Preconditions: `layout` is [`Layout::build`]'s for `plan` and `pattern` on `set`. Cost:
/// each visible patch's pattern built once (no evaluation), parallel; the output's size.
pub fn corner_params(set: &SurfaceSet, plan: &Plan, pattern: &dyn Pattern, layout: &Layout) -> Vec<[f32; 2]> {
    let generation = next_generation();
    let per_patch: Vec<Vec<[f32; 2]>> = (0..set.patches.len())
        .into_par_iter()
        .map(|p| {
            if !plan.is_visible(p) {
                return Vec::new();
            }
            with_scratch(generation, |scratch| {
                let input = layout::pattern_input(set, plan, p);
                let map = LocalMap { set, plan, layout, input, patch: p };
                let mut table = std::mem::take(&mut scratch.param);
                let local = scratch.pattern(pattern, &input);
                map.param_table(&local.interior, &mut table);
                let params = local
                    .triangles
                    .iter()
                    .filter(|tri| !layout::degenerate_after_collapse(set, &input, p, tri))
                    .flat_map(|tri| tri.map(|v| table[v as usize]))
                    .collect();
                scratch.param = table;
                params
            })
        })
        .collect();
    let params: Vec<[f32; 2]> = per_patch.concat();
    debug_assert_eq!(params.len(), 3 * layout.triangle_count());
    params
}

/// Number of triangles the uniform pattern gives a domain at factor `n` (for reports).
pub fn uniform_triangles(domain: Domain, n: u32) -> u64 {
    match domain {
        Domain::Quad => 2 * n as u64 * n as u64,
        Domain::Tri => n as u64 * n as u64,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pattern::transition::Transition;
    use crate::pattern::uniform::Uniform;

    fn teapot() -> SurfaceSet {
        let path = crate::test_support::data("patches/teapot.patches");
        SurfaceSet::from_patch_file(&crate::io::patches::read_patches(&path).unwrap(), Default::default())
    }

    fn cow() -> SurfaceSet {
        let path = crate::test_support::data("meshes/cow.obj");
        let mesh = crate::io::obj::read_obj(&path).unwrap();
        SurfaceSet::pn_from_mesh(&mesh, &path, Default::default()).unwrap()
    }

    /// Each visible patch's pattern under `plan`, mapped index by index by the numbering rule
    /// (`LocalMap::vertex`, the strip writer's mapping), minus the triangles that degenerate
    /// at a collapsed curve: an oracle for the writers' faster mappings.
    fn numbered(
        set: &SurfaceSet,
        plan: &Plan,
        pattern: &dyn Pattern,
        layout: &Layout,
    ) -> (Vec<u32>, Vec<u32>) {
        let (mut indices, mut patches) = (Vec::new(), Vec::new());
        let mut local = LocalTessellation::default();
        for p in (0..set.patches.len()).filter(|&p| plan.is_visible(p)) {
            let input = layout::pattern_input(set, plan, p);
            pattern.build(&input, &mut local);
            let map = LocalMap { set, plan, layout, input, patch: p };
            for tri in &local.triangles {
                if !layout::degenerate_after_collapse(set, &input, p, tri) {
                    indices.extend(tri.map(|l| map.vertex(l)));
                    patches.push(p as u32);
                }
            }
        }
        (indices, patches)
    }

    /// The two-pass writer's triangles are the numbering rule's ([`numbered`]) with the
    /// pattern cache on (fine patterns) and off (coarse ones, staged as local indices between
    /// the passes), with and without corner parameters, on a set with collapsed curves and on
    /// a PN mesh, some patches culled.
    #[test]
    fn triangles_follow_the_numbering_rule_index_by_index() {
        for set in [teapot(), cow()] {
            for (lowest, spread) in [(1, 4), (9, 6)] {
                let mut plan = Plan::uniform(&set, 1).unwrap();
                for (e, s) in plan.segments.iter_mut().enumerate() {
                    *s = lowest + (e as u32 * 7) % spread;
                }
                plan.factors = plan.segments.iter().map(|&s| s as f32).collect();
                for (p, (interior, visible)) in plan.interior.iter_mut().zip(&mut plan.visible).enumerate() {
                    *interior = [lowest + p as u32 % spread, lowest + (p as u32 / 3) % spread];
                    *visible = u32::from(p % 7 != 3);
                }
                for corner_params in [false, true] {
                    let options = EngineOptions { corner_params, ..Default::default() };
                    let mut layout = Layout::default();
                    layout.build(&set, &plan, &Transition, &options).unwrap();
                    let mut fast = fast_evaluator::FastEvaluator::new(&set, &plan);
                    fast.fill_patterns(&plan, &Transition, layout.triangle_count() as u64, None);
                    assert_eq!(
                        fast.patterns().distinct() > 0,
                        lowest > 1,
                        "the cache is on for fine patterns only"
                    );
                    let mut mesh = Mesh::default();
                    write_with(&set, &plan, &Transition, &layout, options, &mut mesh, Some(&fast)).unwrap();
                    let (indices, patches) = numbered(&set, &plan, &Transition, &layout);
                    assert_eq!(mesh.indices, indices, "lowest {lowest}, corner params {corner_params}");
                    assert_eq!(mesh.triangle_patch, patches);
                }
            }
        }
    }

    /// [`corner_params`] (no evaluation, for the GPU engine's output) equals what the engine
    /// writes with [`EngineOptions::corner_params`], bit for bit: collapsed corners (the
    /// teapot), a PN mesh, a Catmull-Clark cage with corners pinched at a valence-2 vertex
    /// (cut by the uniform pattern) and a Loop cage, uniform and transition plans with culled
    /// patches, the hardware's fractional partitioning.
    #[test]
    fn corner_params_without_evaluation_equal_the_engines() {
        use crate::io::{LoadOptions, SurfaceKind};
        use crate::sampling::hardware::Partitioning;
        use crate::scheme::{Criterion, PlanOptions, Scheme};
        let cage = |name: &str, surface| {
            let options = LoadOptions { surface, ..Default::default() };
            crate::io::load(&crate::test_support::data(&format!("subdivision/{name}.obj")), options).unwrap()
        };
        let sets = [
            teapot(),
            cow(),
            cage("catmark_val2_interior", SurfaceKind::CatmullClark),
            cage("loop_xord_boundary", SurfaceKind::Loop),
        ];
        let options = EngineOptions { corner_params: true, ..Default::default() };
        for set in &sets {
            let mut plan = Plan::uniform(set, 1).unwrap();
            for (e, s) in plan.segments.iter_mut().enumerate() {
                *s = 1 + (e as u32 * 7) % 5;
            }
            plan.factors = plan.segments.iter().map(|&s| s as f32).collect();
            for (p, (interior, visible)) in plan.interior.iter_mut().zip(&mut plan.visible).enumerate() {
                *interior = [1 + p as u32 % 4, 1 + (p as u32 / 3) % 4];
                *visible = u32::from(p % 7 != 3);
            }
            let uniform = Plan::uniform(set, 4).unwrap();
            let fractional = Scheme::Hardware(Partitioning::FractionalOdd)
                .plan(set, &Criterion::Factor(4.4), &PlanOptions::default())
                .unwrap();
            let cases: [(&Plan, &dyn Pattern); 3] =
                [(&uniform, &Uniform), (&plan, &Transition), (&fractional.plan, &fractional.pattern)];
            for (k, (plan, pattern)) in cases.into_iter().enumerate() {
                let mesh = tessellate(set, plan, pattern, options).unwrap();
                let mut layout = Layout::default();
                layout.build(set, plan, pattern, &options).unwrap();
                let params = corner_params(set, plan, pattern, &layout);
                let want = mesh.corner_params.as_ref().unwrap();
                assert_eq!(params.len(), want.len(), "case {k}");
                assert!(
                    params.iter().zip(want).all(|(a, b)| a.map(f32::to_bits) == b.map(f32::to_bits)),
                    "case {k}"
                );
            }
        }
    }

    /// A frame whose indices go out in their own pass, by plain or by streaming stores
    /// (`stream_store::IndexWrites`, forced here), is the frame whose vertex pass writes them,
    /// byte for byte: the uniform writers (the grid path on the
    /// teapot, triangles by addition on a PN mesh and on a Loop cage) and the general one
    /// (a transition plan of mixed factors: cached patterns and patterns staged between the
    /// passes, some patches culled). So is the frame without the pattern cache, whose
    /// patches map their triangles in the vertex pass (or, streamed, in the index pass), and
    /// the generic evaluation's triangles.
    #[test]
    fn streamed_and_uncached_frames_equal_plain_frames_byte_for_byte() {
        use crate::io::{LoadOptions, SurfaceKind};
        let cage = crate::test_support::data("subdivision/loop_xord_interior.obj");
        let loop_cage =
            crate::io::load(&cage, LoadOptions { surface: SurfaceKind::Loop, ..Default::default() });
        for set in [teapot(), cow(), loop_cage.unwrap()] {
            let mut mixed = Plan::uniform(&set, 1).unwrap();
            for (e, s) in mixed.segments.iter_mut().enumerate() {
                *s = 1 + (e as u32 * 7) % 9;
            }
            mixed.factors = mixed.segments.iter().map(|&s| s as f32).collect();
            for (p, (interior, visible)) in mixed.interior.iter_mut().zip(&mut mixed.visible).enumerate() {
                *interior = [1 + p as u32 % 9, 1 + (p as u32 / 3) % 9];
                *visible = u32::from(p % 7 != 3);
            }
            let uniform = Plan::uniform(&set, 6).unwrap();
            let cases: [(&Plan, &dyn Pattern); 2] = [(&uniform, &Uniform), (&mixed, &Transition)];
            for (k, (plan, pattern)) in cases.into_iter().enumerate() {
                let options = EngineOptions::default();
                let mut layout = Layout::default();
                layout.build(&set, plan, pattern, &options).unwrap();
                let mut fast = fast_evaluator::FastEvaluator::new(&set, plan);
                fast.fill_patterns(plan, pattern, layout.triangle_count() as u64, None);
                // Without the frame's pattern cache, every patch maps its triangles in the
                // vertex pass unless the frame streams (`Pass::Vertices`).
                let uncached = fast_evaluator::FastEvaluator::new(&set, plan);
                let frame = |writes: IndexWrites, fast: Option<&fast_evaluator::FastEvaluator<'_>>| {
                    stream_store::force_on_this_thread(Some(writes));
                    let mut mesh = Mesh::default();
                    write_with(&set, plan, pattern, &layout, options, &mut mesh, fast).unwrap();
                    stream_store::force_on_this_thread(None);
                    mesh
                };
                use IndexWrites::{OwnPass, Streamed, WithVertices};
                let plain = frame(WithVertices, Some(&fast));
                assert!(!plain.indices.is_empty(), "case {k}: a frame with triangles");
                let bits = |v: &[[f32; 3]]| v.iter().flat_map(|x| x.map(f32::to_bits)).collect::<Vec<_>>();
                for (other, what) in [
                    (frame(OwnPass, Some(&fast)), "index pass"),
                    (frame(Streamed, Some(&fast)), "streamed"),
                    (frame(WithVertices, Some(&uncached)), "uncached"),
                    (frame(OwnPass, Some(&uncached)), "uncached, index pass"),
                    (frame(Streamed, Some(&uncached)), "uncached, streamed"),
                ] {
                    assert_eq!(other.indices, plain.indices, "case {k}, {what}");
                    assert_eq!(other.triangle_patch, plain.triangle_patch, "case {k}, {what}");
                    assert_eq!(bits(&other.positions), bits(&plain.positions), "case {k}, {what}");
                    assert_eq!(bits(&other.normals), bits(&plain.normals), "case {k}, {what}");
                }
                // The generic evaluation (no fast evaluator) numbers and connects alike.
                for writes in [WithVertices, OwnPass, Streamed] {
                    let generic = frame(writes, None);
                    assert_eq!(generic.indices, plain.indices, "case {k}, generic, {writes:?}");
                    assert_eq!(generic.triangle_patch, plain.triangle_patch, "case {k}, generic");
                }
            }
        }
    }

    /// A uniform frame runs the uniform writers (triangles by addition on the PN mesh, the
    /// grid path on the teapot); their triangles are the numbering rule's too.
    #[test]
    fn uniform_frames_follow_the_numbering_rule() {
        for set in [cow(), teapot()] {
            let plan = Plan::uniform(&set, 5).unwrap();
            let mesh = tessellate(&set, &plan, &Uniform, EngineOptions::default()).unwrap();
            let mut layout = Layout::default();
            layout.build(&set, &plan, &Uniform, &EngineOptions::default()).unwrap();
            let (indices, patches) = numbered(&set, &plan, &Uniform, &layout);
            assert_eq!(mesh.indices, indices);
            assert_eq!(mesh.triangle_patch, patches);
        }
    }
}
