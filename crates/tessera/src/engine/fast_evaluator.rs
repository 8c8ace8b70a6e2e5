//! The CPU engine's fast evaluator: [`FastEvaluator`] evaluates every point the engine asks
//! for — on the grid kernels of [`super::uniform_quads`] where the plan and pattern allow
//! (bicubic patches, integer samplings, uniform interiors), on
//! [`super::point_blocks::PointBlocks`] elsewhere — and keeps the per-set tables (local
//! frames, Bernstein bases per factor, corner records, the frame's pattern cache) from frame
//! to frame.

use super::edge_params::UniformEdgeParams;
use super::point_blocks::{GridFormKey, GridPatch, PointBlocks, LANES};
use super::uniform_quads::{store, Basis, Block, EdgePairLanes, GridLanes, GridLine, Line, LocalPatch};
use super::uniform_triangles::UniformTriangles;
use super::{CornerRecords, VertexSlices};
use crate::cpu::has_avx2_fma;
use crate::criterion::Plan;
use crate::pattern::cache::PatternCache;
use crate::pattern::{Pattern, PatternInput};
use crate::sampling::SamplingKind;
use crate::surface::{Domain, SurfacePoint, SurfaceSet};
use crate::topology::EdgeUse;
use glam::DVec2;
use rayon::prelude::*;
use std::sync::{Mutex, MutexGuard, OnceLock};

/// The tables of one factor `n`: bases, grid parameters, edge parameters.
#[derive(Default)]
struct FactorTables {
    n: usize,
    basis: Basis,
    /// `(i / n)` as the uniform pattern computes interior parameters (`i · (1/n)`), in f64.
    grid: Vec<f64>,
    /// `grid` rounded to f32, the interior vertices' parameters.
    grid32: Vec<f32>,
    /// Per domain, local edge and reversed flag, the f64 parameters of canonical sample `k`
    /// in the owner's domain, as the generic engine evaluates edge vertices.
    edges: UniformEdgeParams,
    /// The quad's `edges` rounded to f32, the edge vertices' parameters.
    edge_uv32: [[Vec<[f32; 2]>; 2]; 4],
}

impl FactorTables {
    /// Fills the tables for factor `n` (≥ 1).
    fn fill(&mut self, n: u32) {
        let step = 1.0 / n as f64;
        let nu = n as usize;
        self.n = nu;
        self.basis.refill(nu);
        self.grid.clear();
        self.grid.extend((0..=nu).map(|i| i as f64 * step));
        self.grid32.clear();
        self.grid32.extend((0..=nu).map(|i| (i as f64 * step) as f32));
        self.edges.fill(n);
        for (e, by_direction32) in self.edge_uv32.iter_mut().enumerate() {
            for (rev, uvs32) in by_direction32.iter_mut().enumerate() {
                uvs32.clear();
                let uvs = self.edges.get(Domain::Quad, e, rev == 1);
                uvs32.extend(uvs.iter().map(|uv| uv.as_vec2().to_array()));
            }
        }
    }
}

/// What the grid kernels read of one edge, made once per set: its owner's use, and the
/// owner's grid form where the kernels can take the edge (one normal variant, not collapsed,
/// an owner with a grid form; None elsewhere). The frame's edge pass reads these 16 bytes an
/// edge in order, instead of the edge's record, its uses and the owner's entry in the
/// per-patch table, each asked twice (whether the kernels take it, then its owner): that loop
/// was about half of a coarse frame's edge work (the Catmull-Clark torus at 0.5 px, about
/// 24 ns an edge of 1.7 samples).
#[derive(Clone, Copy)]
struct GridEdge {
    owner: EdgeUse,
    form: Option<GridFormKey>,
}

/// Factors below this (both ways) may have [`GridLanes`]: a grid of at most [`LANES`]
/// interior points with at least two rows has factors of at most 5 along `u` and 9 along `v`.
const LANE_GRIDS: usize = 10;

/// Where the lanes of a pair of edges of factors `na`, `nb` (lines against them where
/// `flip_a`, `flip_b`) lie in [`FastEvaluator`]'s `edge_pairs`; None for factors without.
fn edge_pair_at((na, flip_a): (usize, bool), (nb, flip_b): (usize, bool)) -> Option<usize> {
    (na < LANE_GRIDS && nb < LANE_GRIDS)
        .then(|| (2 * na + usize::from(flip_a)) * 2 * LANE_GRIDS + 2 * nb + usize::from(flip_b))
}

/// Whether the line of the edge `owner` uses runs against the edge: the line runs with the
/// patch's grid index, so canonical sample `k` sits at line index `k`, or `n − k` where this
/// is true (edges 2 and 3 run against the grid, reversed edges against the patch).
fn runs_against(owner: EdgeUse) -> bool {
    owner.reversed ^ (owner.local >= 2)
}

/// The evaluator: everything its tasks share. It evaluates every point the engine asks for,
/// on the grid kernels of this module where the plan and pattern allow, on
/// [`PointBlocks`] elsewhere.
pub(crate) struct FastEvaluator<'a> {
    set: &'a SurfaceSet,
    /// `tables[n]` for every factor `n` a plan so far needed (`n == 0`: not filled yet);
    /// kept from plan to plan, so a frame loop refills nothing once its factors were seen.
    tables: Vec<FactorTables>,
    /// Every patch in its local frame; each is needed by several tasks (its corners, edges
    /// and rows), so it is made once.
    points: PointBlocks,
    /// The current plan's distinct patterns ([`FastEvaluator::fill_patterns`]), or the fill
    /// the write is to run ([`FastEvaluator::defer_patterns`]). Behind a lock only so that
    /// the write can fill the table on one side of its join while the other side evaluates
    /// corners and edges through this evaluator: locked twice a frame, never by two threads
    /// at once.
    patterns: Mutex<FramePatterns>,
    /// The writer of triangle meshes at one uniform factor, where the current plan is one
    /// ([`FastEvaluator::fill_patterns`]).
    triangles: UniformTriangles,
    /// The grid kernels apply to the current plan: integer samplings, and some patch a
    /// bicubic with a local form (polynomial, or rational within [`MIN_WEIGHT_RATIO`]);
    /// they take that patch's edges and interior ([`FastEvaluator::retarget`]).
    ///
    /// A set that mixes kinds (a Catmull-Clark cage: regular faces are bicubics, isolated
    /// ones trees) takes them on its bicubics, the others on [`PointBlocks`]: each vertex is
    /// still evaluated once, by its owner, so which kernel a patch takes cannot open a crack.
    /// Before, one patch without a grid form sent the whole set to [`PointBlocks`]: the
    /// rook's 1,728 regular faces (of 3,064 patches) were evaluated point by point.
    grid: bool,
    /// The grid kernels also take the corners: every patch has a grid form.
    grid_corners: bool,
    /// The current plan samples its edges uniformly: `tables` holds its factors' edge
    /// parameters ([`FastEvaluator::uniform_edge_params`]).
    uniform: bool,
    /// Run the kernels compiled for AVX2 and FMA. Only ever true where the CPU has both:
    /// the `unsafe` calls below rely on it.
    avx2_fma: bool,
    /// Per edge, its owner and the owner's grid form where the grid kernels can take the
    /// edge ([`GridEdge`]).
    grid_edges: Vec<GridEdge>,
    /// The lanes of each small grid `(nu, nv)` evaluated in one block ([`GridLanes`]), at
    /// `nu · LANE_GRIDS + nv`, made with the factors' tables.
    grid_lanes: Vec<Option<GridLanes>>,
    /// The lanes of each pair of edges evaluated in one block ([`EdgePairLanes`]), at
    /// [`edge_pair_at`] of their factors and directions, made with the factors' tables.
    edge_pairs: Vec<Option<EdgePairLanes>>,
    /// The largest factor `grid_lanes` and `edge_pairs` were made for.
    lanes_top: usize,
    /// Every corner entry's vertex record, evaluated on first use, without and with the grid
    /// kernels (which evaluate corners in their own way): 36 bytes a corner.
    corners: [OnceLock<CornerRecords>; 2],
}

/// A frame's distinct patterns, and the fill they wait for where it was deferred
/// ([`FastEvaluator::defer_patterns`]).
#[derive(Default)]
pub(crate) struct FramePatterns {
    cache: PatternCache,
    pending: Option<PendingFill>,
}

/// What [`super::fill_pattern_cache`] needs beside the plan and pattern.
#[derive(Clone, Copy)]
struct PendingFill {
    /// The layout's triangle count.
    triangles: u64,
    /// Keep the patterns the table holds (the check's, for this plan).
    keep: bool,
}

impl FramePatterns {
    /// Runs the pending fill, if any, for `plan` and `pattern`.
    fn fill(&mut self, set: &SurfaceSet, plan: &Plan, pattern: &dyn Pattern) {
        if let Some(PendingFill { triangles, keep }) = self.pending.take() {
            super::fill_pattern_cache(&mut self.cache, set, plan, pattern, triangles, keep);
        }
    }

    /// The table, once filled.
    pub(crate) fn cache(&self) -> &PatternCache {
        debug_assert!(self.pending.is_none());
        &self.cache
    }
}

impl<'a> FastEvaluator<'a> {
    /// The evaluator for `set` and `plan`. On bicubic patches (polynomial or rational) and
    /// integer plans it evaluates every corner, every edge of one normal variant and every
    /// patch interior its pattern promises to be a grid ([`Pattern::interior_grid`]) on grids;
    /// every other point (any surface kind) in [`PointBlocks`]. Cost: O(P) (each patch moved
    /// to its local frame).
    pub(crate) fn new(set: &'a SurfaceSet, plan: &Plan) -> FastEvaluator<'a> {
        Self::with_kernels(set, plan, has_avx2_fma())
    }

    /// [`FastEvaluator::new`] with the kernels chosen by the caller (`avx2_fma` is ignored
    /// where the CPU lacks either).
    pub(crate) fn with_kernels(set: &'a SurfaceSet, plan: &Plan, avx2_fma: bool) -> FastEvaluator<'a> {
        let mut f = Self::for_set(set, avx2_fma);
        f.retarget(plan);
        f
    }

    /// The evaluator's per-set part, prepared once: every patch in its local frame. Cost: O(P).
    pub(crate) fn for_set(set: &'a SurfaceSet, avx2_fma: bool) -> FastEvaluator<'a> {
        let points = PointBlocks::for_set(set, avx2_fma);
        let topo = &set.topology;
        let grid_edges = (0..topo.edges.len())
            .map(|e| {
                let (edge, owner) = (&topo.edges[e], topo.edge_uses(e)[0]);
                let single = edge.variants == 1 && !edge.collapsed;
                GridEdge { owner, form: points.grid_form_key(owner.patch as usize).filter(|_| single) }
            })
            .collect();
        FastEvaluator {
            set,
            tables: Vec::new(),
            points,
            grid_edges,
            grid_lanes: Vec::new(),
            edge_pairs: Vec::new(),
            lanes_top: 0,
            patterns: Mutex::default(),
            triangles: UniformTriangles::for_set(set),
            grid: false,
            grid_corners: false,
            uniform: false,
            avx2_fma: avx2_fma && has_avx2_fma(),
            corners: Default::default(),
        }
    }

    /// Every corner entry's vertex record as the current plan's kernels evaluate it, evaluated
    /// once per set and kernel. Cost: O(corners) the first time, then O(1).
    pub(crate) fn corner_records(&self) -> &CornerRecords {
        self.corners[usize::from(self.grid_corners)].get_or_init(|| CornerRecords::evaluate(self.set, self))
    }

    /// Makes the tables of every factor `plan` uses (edge segments, interior factors, and
    /// 1 to 3, which the transition pattern may raise a core to), and says whether the grid
    /// kernels apply to the plan (bicubic patches with a local form, integer samplings). Cost:
    /// O(E + P), plus O(n) for each factor not seen before.
    pub(crate) fn retarget(&mut self, plan: &Plan) -> bool {
        // Until `fill_patterns` sees the plan's pattern.
        self.triangles.deactivate();
        self.uniform = plan.kind == SamplingKind::Uniform;
        self.grid = self.uniform && self.points.any_bicubic();
        self.grid_corners = self.grid && self.points.all_bicubic();
        if !self.uniform {
            return false;
        }
        // Every factor up to the plan's largest (at most DENSE) gets its tables: a max is one
        // vectorized pass over the plan, where asking for each factor in turn cost a lookup
        // per edge and patch every frame; the tables of factors up to 64 take a few hundred
        // kilobytes. Larger factors (rare, and up to MAX_FACTOR) get tables only where used.
        const DENSE: usize = 64;
        // Folds rather than `Iterator::max`, which does not vectorize.
        let max_edge = plan.segments.iter().fold(1, |m, &s| m.max(s));
        let max_interior = plan.interior.iter().fold(1, |m, f| m.max(f[0]).max(f[1]));
        let max = max_edge.max(max_interior).max(3) as usize;
        if max >= self.tables.len() {
            self.tables.resize_with(max + 1, FactorTables::default);
        }
        for (n, tables) in self.tables.iter_mut().enumerate().take(max.min(DENSE) + 1).skip(1) {
            if tables.n != n {
                tables.fill(n as u32);
            }
        }
        if max > DENSE {
            for n in plan.segments.iter().copied().chain(plan.interior.iter().flatten().copied()) {
                let n = n as usize;
                if n > DENSE && self.tables[n].n != n {
                    self.tables[n].fill(n as u32);
                }
            }
        }
        if !self.grid {
            // The tables serve the edge parameters of any uniform plan; the lanes only the
            // grid kernels.
            return false;
        }
        let top = max.min(LANE_GRIDS - 1);
        if top > self.lanes_top {
            // Factors 1 to `top` all have tables now, and a grid's lanes depend on its factors
            // alone: made once, again only for a plan with larger factors than any before.
            self.lanes_top = top;
            self.grid_lanes = (0..LANE_GRIDS * LANE_GRIDS)
                .map(|at| {
                    let (nu, nv) = (at / LANE_GRIDS, at % LANE_GRIDS);
                    (nu <= top && nv <= top)
                        .then(|| GridLanes::new(&self.tables[nu].basis, &self.tables[nv].basis, nu, nv))
                        .flatten()
                })
                .collect();
            let edge = |at: usize| {
                let (n, flip) = (at / 2, at % 2 == 1);
                (n <= top).then(|| (&self.tables[n].basis, n, flip))
            };
            self.edge_pairs = (0..4 * LANE_GRIDS * LANE_GRIDS)
                .map(|at| EdgePairLanes::new(edge(at / (2 * LANE_GRIDS))?, edge(at % (2 * LANE_GRIDS))?))
                .collect();
        }
        true
    }

    /// Prepares the writer's per-frame patterns for `plan` and `pattern` (`triangles`: the
    /// layout's count): the one pattern of a uniform triangle plan ([`UniformTriangles`]), or
    /// else the distinct patterns ([`PatternCache::fill_inputs`]), for the writer to read
    /// instead of building one per patch. `built`: patterns already built for this plan and
    /// `pattern` (the a-posteriori check's), exchanged for the evaluator's own and only added
    /// to; [`FastEvaluator::return_patterns`] gives them back after the write, so that each
    /// table keeps its role (and its buffers' sizes) from frame to frame. Returns whether it
    /// took them. Precondition: [`FastEvaluator::retarget`] saw `plan`.
    pub(crate) fn fill_patterns(
        &mut self,
        plan: &Plan,
        pattern: &dyn Pattern,
        triangles: u64,
        built: Option<&mut PatternCache>,
    ) -> bool {
        let took = self.defer_patterns(plan, pattern, triangles, built);
        self.patterns.get_mut().unwrap_or_else(|e| e.into_inner()).fill(self.set, plan, pattern);
        took
    }

    /// [`FastEvaluator::fill_patterns`] with the distinct patterns left for the write to
    /// find, for the same `plan` and `pattern` ([`super::write_with`]): it does so beside its
    /// corners and edges, which do not read them. The table's fill, a hash lookup per
    /// visible patch, took a sixth of the cow's adaptive frames (5,804 patches, two
    /// threads) when it ran on one thread before the write.
    pub(crate) fn defer_patterns(
        &mut self,
        plan: &Plan,
        pattern: &dyn Pattern,
        triangles: u64,
        built: Option<&mut PatternCache>,
    ) -> bool {
        let patterns = self.patterns.get_mut().unwrap_or_else(|e| e.into_inner());
        patterns.pending = None;
        if self.triangles.retarget(self.set, plan, pattern) {
            patterns.cache.clear();
            return false;
        }
        let took = built.map(|built| std::mem::swap(&mut patterns.cache, built)).is_some();
        patterns.pending = Some(PendingFill { triangles, keep: took });
        took
    }

    /// Gives back the patterns [`FastEvaluator::fill_patterns`] took (`built`, holding the
    /// evaluator's own meanwhile), once the frame is written.
    pub(crate) fn return_patterns(&mut self, built: &mut PatternCache) {
        std::mem::swap(&mut self.patterns.get_mut().unwrap_or_else(|e| e.into_inner()).cache, built);
    }

    /// The current plan's distinct patterns, filled first where the fill was deferred (for
    /// `plan` and `pattern`: the plan and pattern the fill was asked for). Cost: the fill, or
    /// O(1); blocks while another thread holds them (none does but the write).
    pub(crate) fn frame_patterns(&self, plan: &Plan, pattern: &dyn Pattern) -> MutexGuard<'_, FramePatterns> {
        let mut patterns = self.patterns.lock().unwrap_or_else(|e| e.into_inner());
        patterns.fill(self.set, plan, pattern);
        patterns
    }

    /// The writer of uniform triangle plans.
    pub(crate) fn triangles(&self) -> &UniformTriangles {
        &self.triangles
    }

    /// The current plan's distinct patterns (filled: [`FastEvaluator::fill_patterns`]).
    #[cfg(test)]
    pub(crate) fn patterns(&mut self) -> &PatternCache {
        &self.patterns.get_mut().unwrap_or_else(|e| e.into_inner()).cache
    }

    /// Whether the grid kernels apply to the current plan (to some patches).
    #[cfg(test)]
    pub(crate) fn grid(&self) -> bool {
        self.grid
    }

    /// Whether the grid kernels take the current plan's corners ([`FastEvaluator::corners`]):
    /// every patch is a bicubic with a local form.
    pub(crate) fn grid_corners(&self) -> bool {
        self.grid_corners
    }

    /// The parameters of the inner samples `1 .. n − 1` of an edge of `n` segments of the
    /// current plan, in the domain `d` of the patch of use `u`, in canonical order (what
    /// `push_edge_params` computes), from the factor's tables; None where the plan does not
    /// sample uniformly or `n` has no tables. Cost: O(1).
    pub(crate) fn uniform_edge_params(&self, n: u32, d: Domain, u: &EdgeUse) -> Option<&[DVec2]> {
        let tables = self.tables.get(n as usize).filter(|t| self.uniform && t.edges.factor() == n)?;
        Some(&tables.edges.get(d, u.local as usize, u.reversed)[1..n as usize])
    }

    /// The evaluator of arbitrary parameter lists.
    pub(crate) fn points(&self) -> &PointBlocks {
        &self.points
    }

    /// The lanes of the grid `(nu, nv)`, where it is one [`GridLanes`] takes.
    fn grid_lanes(&self, nu: usize, nv: usize) -> Option<&GridLanes> {
        if nu >= LANE_GRIDS || nv >= LANE_GRIDS {
            return None;
        }
        self.grid_lanes.get(nu * LANE_GRIDS + nv)?.as_ref()
    }

    /// The tables of factor `n`, when made.
    fn factor(&self, n: usize) -> Option<&FactorTables> {
        self.tables.get(n).filter(|t| self.grid && t.n == n && n > 0)
    }

    /// Whether edge `e`'s samples are this evaluator's: a factor with tables, one normal
    /// variant, not collapsed, an owner with a grid form.
    pub(crate) fn covers_edge(&self, plan: &Plan, e: usize) -> bool {
        self.grid_edges[e].form.is_some() && self.factor(plan.segments(e) as usize).is_some()
    }

    /// [`FastEvaluator::covers_grid`] asking `pattern` for the grid.
    #[cfg(test)]
    pub(crate) fn covers_patch(
        &self,
        p: usize,
        pattern: &dyn Pattern,
        input: &PatternInput,
    ) -> Option<[u32; 2]> {
        self.covers_grid(p, input, || pattern.interior_grid(input))
    }

    /// The interior grid `[nu, nv]` of patch `p` with `input` when it is this evaluator's: a
    /// quad with a grid form whose pattern promises a grid (its [`Pattern::interior_grid`] of
    /// `input`, from `grid`, asked only of such a quad: a built pattern knows it) of factors
    /// with tables.
    pub(crate) fn covers_grid(
        &self,
        p: usize,
        input: &PatternInput,
        grid: impl FnOnce() -> Option<[u32; 2]>,
    ) -> Option<[u32; 2]> {
        if input.domain != Domain::Quad || self.points.grid_patch(p).is_none() {
            return None;
        }
        let grid = grid()?;
        (self.factor(grid[0] as usize).is_some() && self.factor(grid[1] as usize).is_some()).then_some(grid)
    }

    fn local(&self, p: usize) -> GridPatch<'_> {
        self.points.grid_patch(p).expect("the grid kernels run on bicubic patches with a local form only")
    }

    /// The generic f64 evaluation, for the rare points f32 cannot resolve.
    #[cold]
    #[inline(never)]
    fn exact(&self, p: usize, uv: DVec2) -> SurfacePoint {
        self.set.patches[p].eval(uv)
    }

    /// Evaluates every corner entry at its owner's corner.
    pub(crate) fn corners(&self, out: VertexSlices<'_>) {
        let topo = &self.set.topology;
        // Any factor's tables give the corners' bases (B(0) and B(1) exactly).
        let tables = self.factor(1).expect("retarget makes factor 1");
        let (basis, n) = (&tables.basis, 1);
        out.pos
            .par_iter_mut()
            .zip(out.nrm.par_iter_mut())
            .zip(out.uv.par_iter_mut())
            .zip(out.patch.par_iter_mut())
            .enumerate()
            .with_min_len(256)
            .for_each(|(i, (((pos, nrm), uv), vp))| {
                let entry = &topo.corner_entries[i];
                let (p, c) = (entry.owner_patch as usize, entry.owner_corner as usize);
                let (gi, gj) = [(0, 0), (n, 0), (n, n), (0, n)][c];
                let block = match self.local(p) {
                    GridPatch::Polynomial(l) => {
                        l.row(basis, gj).block::<false>(basis, gi, &l.origin, l.scale)
                    }
                    GridPatch::Rational(l) => l.row(basis, gj).block::<false>(basis, gi, &l.origin, l.scale),
                };
                let corner = Domain::Quad.corner(c);
                store(&block, 0, pos, nrm, || self.exact(p, corner));
                *uv = corner.as_vec2().to_array();
                *vp = p as u32;
            });
    }

    /// Evaluates the `inner` samples of edge `e` (the layout's count) with its owner patch, in
    /// canonical order, into the front of `out` (taken off it), where they are this
    /// evaluator's ([`FastEvaluator::covers_edge`]); says whether they were.
    pub(crate) fn edge(&self, plan: &Plan, e: usize, inner: usize, out: &mut VertexSlices<'_>) -> bool {
        let GridEdge { owner, form } = self.grid_edges[e];
        let n = plan.segments(e) as usize;
        let (Some(form), Some(tables)) = (form, self.factor(n)) else { return false };
        debug_assert_eq!(inner, n - 1, "an edge of one normal variant");
        let out = out.take_front(inner);
        if self.avx2_fma {
            #[cfg(target_arch = "x86_64")]
            // SAFETY: `avx2_fma` is only set where the CPU has AVX2 and FMA (`FastEvaluator::build`).
            unsafe {
                self.edge_avx2_fma(tables, owner, form, out)
            };
            #[cfg(target_arch = "x86_64")]
            return true;
        }
        self.edge_with::<false>(tables, owner, form, out);
        true
    }

    /// Evaluates the inner samples of edges `e` and `e + 1` (`inner` each: the layout's
    /// counts) in one block into the front of `out` (taken off it), where both are this
    /// evaluator's, one polynomial patch owns both, and their samples fill at most one block
    /// ([`EdgePairLanes`]); says whether it did. The bits are those of
    /// [`FastEvaluator::edge`] of each.
    pub(crate) fn edge_pair(
        &self,
        plan: &Plan,
        e: usize,
        inner: [usize; 2],
        out: &mut VertexSlices<'_>,
    ) -> bool {
        let (a, b) = (self.grid_edges[e], self.grid_edges[e + 1]);
        let (Some(form), Some(form_b)) = (a.form, b.form) else { return false };
        if form != form_b || form.rational || inner[0] == 0 || inner[1] == 0 {
            return false;
        }
        let n = [plan.segments(e) as usize, plan.segments(e + 1) as usize];
        let at = edge_pair_at((n[0], runs_against(a.owner)), (n[1], runs_against(b.owner)));
        let Some(lanes) = at.and_then(|at| self.edge_pairs.get(at)?.as_ref()) else { return false };
        let (Some(ta), Some(tb)) = (self.factor(n[0]), self.factor(n[1])) else { return false };
        debug_assert_eq!(inner, [n[0] - 1, n[1] - 1], "edges of one normal variant");
        let out = out.take_front(inner[0] + inner[1]);
        let edges = [(a.owner, ta), (b.owner, tb)];
        if self.avx2_fma {
            #[cfg(target_arch = "x86_64")]
            // SAFETY: `avx2_fma` is only set where the CPU has AVX2 and FMA (`FastEvaluator::build`).
            unsafe {
                self.edge_pair_avx2_fma(form, lanes, edges, out)
            };
            #[cfg(target_arch = "x86_64")]
            return true;
        }
        self.edge_pair_with::<false>(form, lanes, edges, out);
        true
    }

    /// [`FastEvaluator::edge_pair_with`] compiled for AVX2 and FMA (everything it calls is
    /// inlined).
    ///
    /// # Safety
    /// The CPU must support AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn edge_pair_avx2_fma(
        &self,
        form: GridFormKey,
        lanes: &EdgePairLanes,
        edges: [(EdgeUse, &FactorTables); 2],
        out: VertexSlices<'_>,
    ) {
        self.edge_pair_with::<true>(form, lanes, edges, out)
    }

    /// The inner samples of two edges of the polynomial patch `form`, one block.
    #[inline(always)]
    fn edge_pair_with<const FMA: bool>(
        &self,
        form: GridFormKey,
        lanes: &EdgePairLanes,
        edges: [(EdgeUse, &FactorTables); 2],
        out: VertexSlices<'_>,
    ) {
        let GridPatch::Polynomial(local) = self.points.grid_form(form) else {
            unreachable!("edge_pair takes polynomial patches")
        };
        let [(a, ta), (b, tb)] = edges;
        let block =
            local.edge_pair_block::<FMA>(lanes, &local.edge(a.local as usize), &local.edge(b.local as usize));
        let first = ta.n - 1;
        // Lane `l`'s edge tables, direction and canonical sample.
        let sample = |l: usize| match l < first {
            true => (ta, a, l + 1),
            false => (tb, b, l - first + 1),
        };
        let p = a.patch as usize;
        block.write::<FMA>(out.pos, out.nrm, |l| {
            let (t, u, k) = sample(l);
            self.exact(p, t.edges.get(Domain::Quad, u.local as usize, u.reversed)[k])
        });
        for (l, uv) in out.uv.iter_mut().enumerate() {
            let (t, u, k) = sample(l);
            *uv = t.edge_uv32[u.local as usize][u.reversed as usize][k];
        }
        out.patch.fill(p as u32);
    }

    /// [`FastEvaluator::edge_with`] compiled for AVX2 and FMA (everything it calls is inlined).
    ///
    /// # Safety
    /// The CPU must support AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn edge_avx2_fma(
        &self,
        tables: &FactorTables,
        owner: EdgeUse,
        form: GridFormKey,
        out: VertexSlices<'_>,
    ) {
        self.edge_with::<true>(tables, owner, form, out)
    }

    /// The inner samples of the edge of `owner`, whose grid form is `form`.
    #[inline(always)]
    fn edge_with<const FMA: bool>(
        &self,
        tables: &FactorTables,
        owner: EdgeUse,
        form: GridFormKey,
        out: VertexSlices<'_>,
    ) {
        match self.points.grid_form(form) {
            GridPatch::Polynomial(local) => self.edge_line::<FMA, 3>(tables, owner, local, out),
            GridPatch::Rational(local) => self.edge_line::<FMA, 4>(tables, owner, local, out),
        }
    }

    /// The inner samples of the edge of `owner`, evaluated on `local`, its patch.
    #[inline(always)]
    fn edge_line<const FMA: bool, const C: usize>(
        &self,
        tables: &FactorTables,
        owner: EdgeUse,
        local: &LocalPatch<C>,
        out: VertexSlices<'_>,
    ) where
        Line<C>: GridLine,
    {
        let (p, local_edge, rev) = (owner.patch as usize, owner.local as usize, owner.reversed);
        let (basis, n) = (&tables.basis, tables.n);
        let line = local.edge(local_edge);
        let flip = runs_against(owner);
        let uvs = tables.edges.get(Domain::Quad, local_edge, rev);
        let uvs32 = &tables.edge_uv32[local_edge][rev as usize];
        // Sample `k` goes to `k − 1`, lane `l` of a block from `t0` being sample `t0 + l`, or
        // `n − t0 − l` where the line runs against the edge. A block is stored whole where it
        // can be ([`Block::write_front`]: in order, or reversed when all eight lanes are
        // samples); lane by lane, a block's stores were about a third of the edge pass.
        let (pos, nrm) = (&mut out.pos[..n - 1], &mut out.nrm[..n - 1]);
        for t0 in (1..n).step_by(LANES) {
            let block: Block = line.block::<FMA>(basis, t0, &local.origin, local.scale);
            let count = LANES.min(n - t0);
            if !flip {
                let at = t0 - 1;
                block.write_front::<FMA>(&mut pos[at..], &mut nrm[at..], count, |l| {
                    self.exact(p, uvs[t0 + l])
                });
            } else if count == LANES {
                // Reversed lane `l` is sample `n − t0 − LANES + 1 + l`.
                let at = n - t0 - LANES;
                let exact = |l: usize| self.exact(p, uvs[at + 1 + l]);
                block.reversed().write_front::<FMA>(
                    &mut pos[at..at + LANES],
                    &mut nrm[at..at + LANES],
                    LANES,
                    exact,
                );
            } else {
                for l in 0..count {
                    let k = n - (t0 + l);
                    store(&block, l, &mut pos[k - 1], &mut nrm[k - 1], || self.exact(p, uvs[k]));
                }
            }
        }
        out.uv[..n - 1].copy_from_slice(&uvs32[1..n]);
        out.patch.fill(p as u32);
    }

    /// Evaluates the interior of patch `p` on the grid `[nu, nv]` (precondition: the grid
    /// [`FastEvaluator::covers_grid`] gave): the `(nu − 1)(nv − 1)` grid points, row after
    /// row.
    pub(crate) fn interior(&self, p: usize, grid: [u32; 2], out: VertexSlices<'_>) {
        let [tu, tv] = grid.map(|n| self.factor(n as usize).expect("covers_grid checked the factors"));
        if self.avx2_fma {
            #[cfg(target_arch = "x86_64")]
            // SAFETY: `avx2_fma` is only set where the CPU has AVX2 and FMA (`FastEvaluator::build`).
            return unsafe { self.interior_avx2_fma(p, tu, tv, out) };
        }
        self.interior_with::<false>(p, tu, tv, out)
    }

    /// [`FastEvaluator::interior_with`] compiled for AVX2 and FMA (everything it calls is
    /// inlined).
    ///
    /// # Safety
    /// The CPU must support AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn interior_avx2_fma(
        &self,
        p: usize,
        tu: &FactorTables,
        tv: &FactorTables,
        out: VertexSlices<'_>,
    ) {
        self.interior_with::<true>(p, tu, tv, out)
    }

    /// The body of [`FastEvaluator::interior`]. Inlined into both builds; so are the kernels
    /// it calls, which is what compiles them for AVX2 in the fast build (a kernel left out of
    /// line would be baseline code, and its `mul_add` a library call).
    #[inline(always)]
    fn interior_with<const FMA: bool>(
        &self,
        p: usize,
        tu: &FactorTables,
        tv: &FactorTables,
        mut out: VertexSlices<'_>,
    ) {
        let m = tu.n - 1;
        if let Some(lanes) = self.grid_lanes(tu.n, tv.n) {
            // The whole interior in one block (a small grid of two rows or more).
            debug_assert_eq!(out.pos.len(), m * (tv.n - 1));
            let block = match self.local(p) {
                GridPatch::Polynomial(local) => local.grid_block::<FMA>(lanes),
                GridPatch::Rational(local) => local.grid_block::<FMA>(lanes),
            };
            let point = |l: usize| (1 + l % m, 1 + l / m);
            block.write::<FMA>(out.pos, out.nrm, |l| {
                let (i, j) = point(l);
                self.exact(p, DVec2::new(tu.grid[i], tv.grid[j]))
            });
            for (l, uv) in out.uv.iter_mut().enumerate() {
                let (i, j) = point(l);
                *uv = [tu.grid32[i], tv.grid32[j]];
            }
            out.patch.fill(p as u32);
            return;
        }
        // Row after row, each given the rest of the interior: a row's last block may store
        // a whole block, spilling into the next row, which then overwrites it.
        match self.local(p) {
            GridPatch::Polynomial(local) => {
                for j in 1..tv.n {
                    self.interior_row::<FMA, 3>(p, local, tu, tv, j, &mut out, (j - 1) * m);
                }
            }
            GridPatch::Rational(local) => {
                for j in 1..tv.n {
                    self.interior_row::<FMA, 4>(p, local, tu, tv, j, &mut out, (j - 1) * m);
                }
            }
        }
    }

    /// Interior vertices `i = 1..nu` of grid row `j` (`1 ≤ j < nv`) of patch `p`: the row's
    /// curve from the `v` tables, its points from the `u` tables, written from `start` in the
    /// interior's `out` (points past the row may be overwritten: see
    /// [`Block::write_front`](super::uniform_quads::Block::write_front)).
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn interior_row<const FMA: bool, const C: usize>(
        &self,
        p: usize,
        local: &LocalPatch<C>,
        tu: &FactorTables,
        tv: &FactorTables,
        j: usize,
        out: &mut VertexSlices<'_>,
        start: usize,
    ) where
        Line<C>: GridLine,
    {
        let line = local.row(&tv.basis, j);
        let v = tv.grid[j];
        let m = tu.n - 1;
        for b in 0..m.div_ceil(LANES) {
            let t0 = 1 + b * LANES;
            let (k, count) = (start + b * LANES, LANES.min(m - b * LANES));
            let block = line.block::<FMA>(&tu.basis, t0, &local.origin, local.scale);
            block.write_front::<FMA>(&mut out.pos[k..], &mut out.nrm[k..], count, |l| {
                self.exact(p, DVec2::new(tu.grid[t0 + l], v))
            });
        }
        let v = tv.grid32[j];
        out.uv[start..start + m].iter_mut().zip(&tu.grid32[1..tu.n]).for_each(|(x, &u)| *x = [u, v]);
        out.patch[start..start + m].fill(p as u32);
    }
}
