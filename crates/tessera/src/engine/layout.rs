//! The output layout: counts → exclusive scan → where every vertex and triangle goes.
//!
//! **The numbering rule**, the one every writer (CPU generic, CPU fast evaluation, GPU) uses:
//!
//! 1. vertices `0 .. corners`: the topology's corner entries (`topology.corner_entries`, one
//!    per vertex and normal variant), evaluated by their owner patch;
//! 2. then, edge after edge in `topology.edges` order, each edge's inner samples
//!    `k = 1 .. segments − 1` in canonical orientation, normal variant after variant: sample
//!    `k` of variant `v` of edge `e` is `edge_offsets[e] + v·(segments − 1) + k − 1`. Collapsed
//!    edges, and edges whose patches are all culled, have none (every sample of a collapsed
//!    curve is its corner);
//! 3. then, patch after patch, the pattern's interior vertices in the pattern's order:
//!    interior vertex `j` of patch `p` is `interior_offsets[p] + j`;
//! 4. triangles patch after patch, each patch's in the pattern's order minus those that
//!    degenerate at a repeated corner: triangle `t` of patch `p` is `triangle_offsets[p] + t`.
//!
//! All offsets are prefix sums with one extra entry at the end, so the count of edge `e`,
//! patch `p` is `offsets[i + 1] − offsets[i]` and the totals are the last entries. Counts are
//! known before anything is evaluated, so every task writes its own disjoint range.
//!
//! **For the GPU engine.** `edge_offsets`, `interior_offsets` and `triangle_offsets` (u32) are
//! uploaded as they are, beside the plan's arrays; a write shader finds its ranges there and
//! numbers vertices with [`Layout::edge_vertex`]'s and [`Layout::interior_vertex`]'s formulas.

use super::{check_size, EngineOptions};
use crate::criterion::Plan;
use crate::error::Result;
use crate::pattern::{Pattern, PatternInput, Slot};
use crate::surface::SurfaceSet;
use rayon::prelude::*;

/// Where every vertex and triangle of one tessellation goes (see the module doc).
#[derive(Debug, Clone, Default)]
pub struct Layout {
    /// Number of corner entries: the first vertices.
    pub corners: u32,
    /// `E + 1` entries: the first vertex of each edge's inner samples.
    pub edge_offsets: Vec<u32>,
    /// `P + 1` entries: the first interior vertex of each patch.
    pub interior_offsets: Vec<u32>,
    /// `P + 1` entries: the first triangle of each patch.
    pub triangle_offsets: Vec<u32>,
    /// Pattern triangles left out because two of their corners are one vertex.
    pub collapsed_triangles: u64,
    /// Per patch: pattern interior vertices and triangles (before dropping collapsed ones),
    /// kept to reuse the allocation from call to call.
    counts: Vec<(u32, u32)>,
    /// Per patch: triangles kept.
    kept: Vec<u32>,
}

impl Layout {
    /// Total vertices.
    pub fn vertex_count(&self) -> usize {
        self.interior_offsets.last().copied().unwrap_or(self.corners) as usize
    }

    /// Total triangles.
    pub fn triangle_count(&self) -> usize {
        self.triangle_offsets.last().copied().unwrap_or(0) as usize
    }

    /// Vertex of canonical sample `k` (`1 ≤ k < segments`) of variant `variant` of edge `e`.
    #[inline]
    pub fn edge_vertex(&self, e: usize, variant: u32, segments: u32, k: u32) -> u32 {
        self.edge_offsets[e] + variant * (segments - 1) + k - 1
    }

    /// Vertex of interior vertex `j` of patch `p`.
    #[inline]
    pub fn interior_vertex(&self, p: usize, j: u32) -> u32 {
        self.interior_offsets[p] + j
    }

    /// Counts and scans the output of `pattern` on `set` following `plan` into `self`
    /// (reusing its buffers), refusing with [`crate::Error::OutputTooLarge`] an output beyond
    /// the limits of `options` before anything of its size exists, and with
    /// [`crate::Error::PlanMismatch`] a plan made for another set.
    ///
    /// Cost: O(E + P) plus one pattern count per visible patch; patches with a repeated corner
    /// (a collapsed curve) also build their pattern once to count what degenerates.
    pub fn build(
        &mut self,
        set: &SurfaceSet,
        plan: &Plan,
        pattern: &dyn Pattern,
        options: &EngineOptions,
    ) -> Result<()> {
        self.build_counted(set, plan, pattern, options, None, None)
    }

    /// [`Layout::build`] with the pattern counts of every patch given where the planner
    /// found them (`counts[p]`: [`Pattern::counts`] of patch `p`'s pattern input, zero for a
    /// culled patch; the a-posteriori check's, [`crate::criterion::PlanScratch::plan_counts`]),
    /// so that no patch's input is gathered and counted again, and likewise each edge's inner
    /// samples where the planner counted them (`edge_counts[e]`: `Topology::edge_samples` of edge `e`,
    /// [`crate::criterion::resolve::edges_counted`]).
    pub(crate) fn build_counted(
        &mut self,
        set: &SurfaceSet,
        plan: &Plan,
        pattern: &dyn Pattern,
        options: &EngineOptions,
        counts: Option<&[(u32, u32)]>,
        edge_counts: Option<&[u32]>,
    ) -> Result<()> {
        plan.check(set)?;
        let topo = &set.topology;
        self.corners = topo.corner_entries.len() as u32;
        if let (Some(_), Some(_), false) = (topo.one_shape, plan.one_factor(), pattern.depends_on_patch()) {
            return self.build_one_input(set, plan, pattern, options);
        }
        let counts = counts.filter(|c| c.len() == set.patches.len());
        self.build_general(
            set,
            plan,
            pattern,
            options,
            counts,
            edge_counts.filter(|c| c.len() == topo.edges.len()),
        )
    }

    /// [`Layout::build`] for any plan: a count per visible patch, then the scans.
    fn build_general(
        &mut self,
        set: &SurfaceSet,
        plan: &Plan,
        pattern: &dyn Pattern,
        options: &EngineOptions,
        counts: Option<&[(u32, u32)]>,
        given_edge_counts: Option<&[u32]>,
    ) -> Result<()> {
        let topo = &set.topology;
        // Edges: inner samples per variant ([`Topology::edge_samples`]), counted in parallel where the
        // planner did not count them, then scanned.
        let edges = topo.edges.len();
        self.edge_offsets.clear();
        self.edge_offsets.resize(edges + 1, 0);
        // Where nothing is culled every edge is seen: its uses are not read (one pass over
        // the visibility row instead of a search of each edge's uses).
        let all_visible = given_edge_counts.is_none() && plan.visible.iter().all(|&v| v != 0);
        let edge_counts = self.edge_offsets[..edges].par_iter_mut().enumerate().with_min_len(1024);
        let count_edges = || {
            edge_counts.for_each(|(e, count)| {
                let seen = all_visible || topo.edge_seen(e, &plan.visible);
                *count = topo.edge_samples(e, seen, plan.segments(e));
            })
        };
        // The patterns' counts (where the check did not leave them) beside the edges' counts:
        // one parallel pass for both, not two.
        let layout_counts = &mut self.counts;
        match (given_edge_counts, counts) {
            (Some(_), Some(_)) => {}
            (Some(_), None) => count_patterns(set, plan, pattern, layout_counts),
            (None, Some(_)) => count_edges(),
            (None, None) => {
                rayon::join(count_edges, || count_patterns(set, plan, pattern, layout_counts));
            }
        }
        debug_assert!(given_edge_counts.is_none_or(|given| (0..edges).all(|e| {
            given[e] == topo.edge_samples(e, topo.edge_seen(e, &plan.visible), plan.segments(e))
        })));
        // The scan: from the planner's counts where it gave them (read where they are, not
        // copied in first: 0.7 MB for the torus grid), else in place.
        let edge_offsets = &mut self.edge_offsets;
        let total = crate::cpu::multiversioned(
            #[inline(always)]
            || {
                let mut total = self.corners as u64;
                match given_edge_counts {
                    Some(given) => {
                        for (offset, &count) in edge_offsets.iter_mut().zip(given) {
                            *offset = total.min(u32::MAX as u64) as u32;
                            total += count as u64;
                        }
                        edge_offsets[edges] = total.min(u32::MAX as u64) as u32;
                    }
                    None => {
                        for offset in edge_offsets.iter_mut() {
                            let count = *offset as u64;
                            *offset = total.min(u32::MAX as u64) as u32;
                            total += count;
                        }
                    }
                }
                total
            },
        );
        // Pattern counts first, without building anything: a triangle count is an upper bound
        // (triangles collapsed at a repeated corner are dropped below), so an output that is
        // too large is refused here, before any pattern or buffer of its size exists.
        // The check's counts are read where they are (no copy); the layout counts only
        // without them.
        let counts: &[(u32, u32)] = match counts {
            Some(counts) => {
                debug_assert!((0..set.patches.len()).all(|p| {
                    counts[p]
                        == if plan.is_visible(p) {
                            pattern.counts(&pattern_input(set, plan, p))
                        } else {
                            (0, 0)
                        }
                }));
                counts
            }
            None => &self.counts,
        };
        let offsets = (&mut self.interior_offsets, &mut self.triangle_offsets);
        if topo.one_shape.is_some() {
            // No patch has a repeated corner: every triangle is kept, and the scan's totals
            // are the size check's (one walk over the counts, not two; the scan writes only
            // the offsets, nothing of the output's size).
            let (vertices, triangles) = crate::cpu::multiversioned(
                #[inline(always)]
                || scan_counts(total, counts.iter().copied(), offsets),
            );
            check_size(vertices, triangles, options)?;
            self.collapsed_triangles = 0;
            return Ok(());
        }
        let (interior, upper) =
            counts.iter().fold((0u64, 0u64), |(v, t), c| (v + c.0 as u64, t + c.1 as u64));
        check_size(total + interior, upper, options)?;
        let (_, triangles) = {
            let generation = super::next_generation();
            counts
                .par_iter()
                .enumerate()
                .map(|(p, &(_, t))| {
                    if t == 0 || !has_repeated_corner(set, p) {
                        return t;
                    }
                    let input = pattern_input(set, plan, p);
                    super::with_scratch(generation, |scratch| {
                        let triangles = &scratch.pattern(pattern, &input).triangles;
                        triangles.iter().filter(|tri| !degenerate_after_collapse(set, &input, p, tri)).count()
                            as u32
                    })
                })
                .collect_into_vec(&mut self.kept);
            scan_counts(total, counts.iter().zip(&self.kept).map(|(&(v, _), &t)| (v, t)), offsets)
        };
        self.collapsed_triangles = upper - triangles;
        Ok(())
    }
}

/// Every patch's pattern counts into `counts` (zero for culled patches). Neighbouring patches
/// often share an input: each task keeps its last count.
fn count_patterns(set: &SurfaceSet, plan: &Plan, pattern: &dyn Pattern, counts: &mut Vec<(u32, u32)>) {
    (0..set.patches.len())
        .into_par_iter()
        .map_init(
            || None,
            |last: &mut Option<(PatternInput, (u32, u32))>, p| {
                if !plan.is_visible(p) {
                    return (0, 0);
                }
                let input = PatternInput { patch: 0, ..pattern_input(set, plan, p) };
                match *last {
                    Some((seen, counts)) if seen == input && !pattern.depends_on_patch() => counts,
                    _ => {
                        let counts = pattern.counts(&PatternInput { patch: p as u32, ..input });
                        *last = Some((input, counts));
                        counts
                    }
                }
            },
        )
        .collect_into_vec(counts);
}

/// The patches' first interior vertex and first triangle (`P + 1` entries each, written
/// into `interior` and `triangles`, resized) from their `(vertices, triangles)`, the vertices
/// after `start`; returns the vertex and triangle totals. The offsets are right where the
/// totals fit `u32` (the caller's size check refuses the others). Cost: O(P), sequential.
#[inline(always)]
fn scan_counts(
    start: u64,
    counts: impl ExactSizeIterator<Item = (u32, u32)>,
    (interior, triangles): (&mut Vec<u32>, &mut Vec<u32>),
) -> (u64, u64) {
    // Written in place (no `push`, whose capacity test each time kept the loop from
    // running ahead).
    interior.resize(counts.len() + 1, 0);
    triangles.resize(counts.len() + 1, 0);
    let (mut v, mut t) = (start, 0u64);
    for ((vertices, kept), (first_vertex, first_triangle)) in
        counts.zip(interior.iter_mut().zip(triangles.iter_mut()))
    {
        (*first_vertex, *first_triangle) = (v as u32, t as u32);
        v += vertices as u64;
        t += kept as u64;
    }
    (*interior.last_mut().expect("P + 1 entries"), *triangles.last_mut().expect("P + 1 entries")) =
        (v as u32, t as u32);
    (v, t)
}

impl Layout {
    /// [`Layout::build`] where every patch has the same pattern input (one domain, distinct
    /// corners, a one-factor plan with every patch visible, a pattern that ignores the patch
    /// id): one count, and offsets by arithmetic — the same numbers the general build scans,
    /// without a pattern input per patch. Cost: O(E + P), one pattern count.
    fn build_one_input(
        &mut self,
        set: &SurfaceSet,
        plan: &Plan,
        pattern: &dyn Pattern,
        options: &EngineOptions,
    ) -> Result<()> {
        let topo = &set.topology;
        let patches = set.patches.len();
        let (vertices, triangles) = pattern.counts(&pattern_input(set, plan, 0));
        let inner = plan.segments(0) - 1;
        // Every edge is seen by a visible patch and none is collapsed.
        self.edge_offsets.clear();
        self.edge_offsets.reserve(topo.edges.len() + 1);
        let mut total = self.corners as u64;
        for edge in &topo.edges {
            self.edge_offsets.push(total.min(u32::MAX as u64) as u32);
            total += inner as u64 * edge.variants as u64;
        }
        self.edge_offsets.push(total.min(u32::MAX as u64) as u32);
        let all_triangles = triangles as u64 * patches as u64;
        check_size(total + vertices as u64 * patches as u64, all_triangles, options)?;
        // Both totals fit u32 now (check_size).
        let (base, vertices) = (total as u32, vertices);
        self.interior_offsets.clear();
        self.interior_offsets.extend((0..=patches as u32).map(|p| base + p * vertices));
        self.triangle_offsets.clear();
        self.triangle_offsets.extend((0..=patches as u32).map(|p| p * triangles));
        self.collapsed_triangles = 0;
        Ok(())
    }
}

/// What the pattern of patch `p` gets from the plan: its edges' segments and factors, its
/// interior factors and which of its edges are collapsed. Public so that the GPU engine
/// (tessera-gpu) sizes its output with the same pattern counts. Cost: O(1).
#[inline]
pub fn pattern_input(set: &SurfaceSet, plan: &Plan, p: usize) -> PatternInput {
    let domain = set.topology.patch_domains[p];
    let (mut segments, mut factors) = ([1; 4], [1.0; 4]);
    for (e, pe) in set.topology.patch_edges[p][..domain.corner_count()].iter().enumerate() {
        let edge = pe.edge as usize;
        segments[e] = plan.segments(edge);
        factors[e] = plan.factor(edge);
    }
    let collapsed = set.topology.collapsed_sides(p);
    let pinched = set.topology.pinched_corners(p);
    PatternInput {
        domain,
        segments,
        interior: plan.interior[p],
        factors,
        patch: p as u32,
        collapsed,
        pinched,
    }
}

/// True when two corners of the patch are the same vertex (a collapsed curve, or a curve that
/// starts and ends at one point): only then can a pattern triangle degenerate. Public so that
/// the GPU engine (tessera-gpu) flags the same patches for its collapsed-triangle path.
/// Cost: O(1).
pub fn has_repeated_corner(set: &SurfaceSet, p: usize) -> bool {
    let n = set.topology.patch_domains[p].corner_count();
    let c = &set.topology.patch_corners[p][..n];
    (0..n).any(|i| (i + 1..n).any(|j| c[i] == c[j]))
}

/// True when two corners of a pattern triangle of patch `p` land on the same output vertex
/// because they lie on a collapsed boundary curve (or at its ends). Decided from local indices
/// only, so the count pass and the write pass agree.
pub(crate) fn degenerate_after_collapse(
    set: &SurfaceSet,
    input: &PatternInput,
    p: usize,
    tri: &[u32; 3],
) -> bool {
    let topo = &set.topology;
    // Corners and samples of collapsed curves are identified by their vertex; every other
    // local index is a distinct vertex of its own.
    let id = |l: u32| -> (bool, u32) {
        match input.slot(l) {
            Slot::Corner(c) => (true, topo.patch_corner_entries[p][c]),
            Slot::Edge(e, _) if topo.patch_edges[p][e].collapsed => (true, topo.patch_corner_entries[p][e]),
            _ => (false, l),
        }
    };
    let [a, b, c] = tri.map(id);
    a == b || b == c || a == c
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pattern::transition::Transition;
    use crate::pattern::uniform::Uniform;
    use crate::surface::{Patch, RationalBicubic};
    use glam::DVec3;

    /// `count` flat patches in a row, each sharing its right curve with the next; with
    /// `apex`, the first patch's bottom curve collapses to a point.
    fn strip(count: usize, apex: bool) -> SurfaceSet {
        let patches = (0..count)
            .map(|p| {
                let points = std::array::from_fn(|k| {
                    let (i, j) = ((k / 4) as f64, (k % 4) as f64);
                    let x = if apex && p == 0 && j == 0.0 { 1.5 } else { p as f64 * 3.0 + i };
                    DVec3::new(x, j, 0.0)
                });
                Patch::Bicubic(RationalBicubic { points, weights: [1.0; 16] })
            })
            .collect();
        SurfaceSet::from_patches(patches, Default::default())
    }

    #[test]
    fn offsets_follow_the_numbering_rule() {
        let set = strip(3, false);
        let plan = Plan::uniform(&set, 4).unwrap();
        let mut layout = Layout::default();
        layout.build(&set, &plan, &Uniform, &EngineOptions::default()).unwrap();
        let (c, e, p) = (layout.corners as usize, set.topology.edges.len(), set.patches.len());
        assert_eq!(c, 8);
        assert_eq!(layout.edge_offsets.len(), e + 1);
        assert!(layout.edge_offsets.windows(2).all(|w| w[1] - w[0] == 3), "{:?}", layout.edge_offsets);
        assert_eq!(layout.edge_offsets[0] as usize, c);
        assert_eq!(layout.interior_offsets[0], layout.edge_offsets[e]);
        assert!(layout.interior_offsets.windows(2).all(|w| w[1] - w[0] == 9));
        assert!(layout.triangle_offsets.windows(2).all(|w| w[1] - w[0] == 32));
        assert_eq!(layout.vertex_count(), 8 + 3 * e + 9 * p);
        assert_eq!(layout.triangle_count(), 32 * p);
        assert_eq!(layout.edge_vertex(2, 0, 4, 1), layout.edge_offsets[2]);
        assert_eq!(layout.interior_vertex(1, 0), layout.interior_offsets[1]);
    }

    #[test]
    fn collapsed_curves_and_culled_patches_take_no_space() {
        let set = strip(2, true);
        assert_eq!(set.topology.report.collapsed_edges, 1);
        let mut plan = Plan::uniform(&set, 4).unwrap();
        let mut layout = Layout::default();
        layout.build(&set, &plan, &Transition, &EngineOptions::default()).unwrap();
        let collapsed = set.topology.edges.iter().position(|e| e.collapsed).unwrap();
        assert_eq!(
            layout.edge_offsets[collapsed + 1],
            layout.edge_offsets[collapsed],
            "no samples on a point"
        );
        assert!(layout.collapsed_triangles > 0, "triangles at the apex degenerate");
        let kept = (layout.triangle_offsets[1] - layout.triangle_offsets[0]) as u64;
        assert_eq!(
            kept + layout.collapsed_triangles,
            Transition.counts(&pattern_input(&set, &plan, 0)).1 as u64
        );
        // Culling the second patch leaves its own curves without vertices.
        plan.visible[1] = 0;
        layout.build(&set, &plan, &Transition, &EngineOptions::default()).unwrap();
        assert_eq!(layout.triangle_offsets[2], layout.triangle_offsets[1], "a culled patch has no triangles");
        for e in 0..set.topology.edges.len() {
            let only_culled = set.topology.edge_uses(e).iter().all(|u| u.patch == 1);
            if only_culled {
                assert_eq!(layout.edge_offsets[e + 1], layout.edge_offsets[e], "edge {e}");
            }
        }
    }

    /// The arithmetic layout of a one-factor plan gives the numbers the general count and scan
    /// give, on a set of each domain, for the uniform and the transition pattern.
    #[test]
    fn one_input_layouts_equal_the_general_build() {
        let path = crate::test_support::data("meshes/cow.obj");
        let mesh = crate::io::obj::read_obj(&path).unwrap();
        let cow = SurfaceSet::pn_from_mesh(&mesh, &path, Default::default()).unwrap();
        let options = EngineOptions::default();
        for set in [strip(5, false), cow] {
            assert!(set.topology.one_shape.is_some());
            for n in [1, 2, 7] {
                let plan = Plan::uniform(&set, n).unwrap();
                assert!(plan.one_factor().is_some());
                let patterns: [&dyn Pattern; 2] = [&Uniform, &Transition];
                for pattern in patterns {
                    let (mut fast, mut general) = (Layout::default(), Layout::default());
                    fast.build(&set, &plan, pattern, &options).unwrap();
                    general.corners = fast.corners;
                    general.build_general(&set, &plan, pattern, &options, None, None).unwrap();
                    assert_eq!(fast.edge_offsets, general.edge_offsets);
                    assert_eq!(fast.interior_offsets, general.interior_offsets);
                    assert_eq!(fast.triangle_offsets, general.triangle_offsets);
                    assert_eq!(fast.collapsed_triangles, general.collapsed_triangles);
                }
            }
        }
        // A collapsed curve makes the set two-shaped: the general build alone applies.
        assert!(strip(2, true).topology.one_shape.is_none());
        let small = EngineOptions { max_triangles: Some(100), ..Default::default() };
        let err = Layout::default().build(
            &strip(5, false),
            &Plan::uniform(&strip(5, false), 4).unwrap(),
            &Uniform,
            &small,
        );
        assert!(matches!(err, Err(crate::Error::OutputTooLarge { triangles: 160, .. })), "{err:?}");
    }

    #[test]
    fn a_plan_for_another_set_or_too_large_an_output_is_refused() {
        let set = strip(2, false);
        let other = strip(3, false);
        let plan = Plan::uniform(&other, 4).unwrap();
        let mut layout = Layout::default();
        let err = layout.build(&set, &plan, &Uniform, &EngineOptions::default()).unwrap_err();
        assert!(matches!(err, crate::Error::PlanMismatch { .. }), "{err}");
        let plan = Plan::uniform(&set, 64).unwrap();
        let small = EngineOptions { max_triangles: Some(1000), ..Default::default() };
        let err = layout.build(&set, &plan, &Uniform, &small).unwrap_err();
        assert!(matches!(err, crate::Error::OutputTooLarge { triangles: 16384, .. }), "{err}");
    }
}
