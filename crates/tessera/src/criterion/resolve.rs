//! The one resolver: criteria propose, this decides.
//!
//! Every criterion states, for each use of an edge (a patch side), the real factor it would
//! like ([`Proposals`]). [`edges`] turns those into the plan's per-edge rows with one rule:
//! the **maximum** over the patches sharing the edge (the CudaTess consistency rule: each
//! patch's proposal already covers what it needs, so the maximum satisfies all of them),
//! then the scheme's [`EdgeRule`], then the caps and the topology's minimum segments.
//! [`interiors`] then gives every patch its interior factors by the scheme's
//! [`InteriorRule`]. Both read only data every patch agrees on, so the plan is crack-free by
//! construction, and every engine (CPU or GPU) reads the same rows.

use crate::pattern::hardware::{settled_factor, OUTPUT_GAP};
use crate::sampling::{spacing_segments, Spacing};
use crate::surface::{Domain, SurfaceSet};
use rayon::prelude::*;

/// What each patch proposes for its local edges (`[0..corner_count]`; 0 or less = no wish).
pub type Proposals = [f64; 4];

/// The proposal of a culled patch where a plan counts its edges with them
/// ([`edges_counted`]): below every real proposal, so that an edge's largest proposal tells
/// whether a visible patch uses it, and no wish ([`edge`] takes the largest of 0 and the
/// proposals).
pub(crate) const CULLED: f64 = -1.0;

/// How a resolved real factor becomes an edge sampling.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EdgeRule {
    /// Whole segments: the factor rounded to the nearest integer.
    Integer,
    /// Powers of two (semi-uniform's edge levels): the factor's level rounded up.
    PowerOfTwo,
    /// A real factor cut by `spacing`. The hardware spacings first round as the hull shader
    /// does (pow2 to a power of two) and settle factors just above a count boundary onto it
    /// (`pattern::hardware::settled_factor`), so no output segment falls below `f32`
    /// resolution.
    Fractional(Spacing),
}

/// How interior factors follow from a patch's edges.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InteriorRule {
    /// One factor for the whole mesh, edges included (the uniform pattern's precondition).
    Global,
    /// CudaTess's core: a quad takes the smaller segments of the two edges along each
    /// direction, a triangle its largest edge; transition strips reach finer edges.
    Core,
    /// Semi-uniform's patch level: the largest edge, a power of two.
    Level,
    /// The hardware tessellator's `max` reduction of the edge factors (also SD-2's).
    MaxEdge,
}

/// Limits every resolved edge obeys.
#[derive(Debug, Clone, Copy)]
pub struct Caps<'a> {
    /// Largest factor; a power of two for [`EdgeRule::PowerOfTwo`].
    pub max_factor: f64,
    /// Minimum segments per edge ([`super::tolerance::minimum_segments`]).
    pub minimum_segments: &'a [u32],
    /// Minimum interior factors per patch ([`super::tolerance::minimum_interior`]).
    pub minimum_interior: &'a [[u32; 2]],
}

/// `x.round() as u32` for `0 ≤ x < 2³²` (half away from zero), without the library call that
/// `f64::round` is on the baseline x86-64 target: once per edge per frame, it was a visible
/// part of resolving a large frame.
#[inline]
fn round_factor(x: f64) -> u32 {
    let t = x as u32;
    t.saturating_add(u32::from(x - t as f64 >= 0.5))
}

/// Edge `e`'s segments and factor: the maximum of its uses' proposals, capped, raised to
/// the edge's minimum and rounded by `rule` — the one rule [`edges`] and [`update_edges`]
/// apply. Cost: O(uses of `e`).
#[inline(always)]
fn edge(set: &SurfaceSet, proposals: &[Proposals], rule: EdgeRule, caps: &Caps<'_>, e: usize) -> (u32, f32) {
    let wanted = set
        .topology
        .edge_uses(e)
        .iter()
        .map(|u| proposals[u.patch as usize][u.local as usize])
        .fold(0.0, f64::max);
    settle(wanted, rule, caps, e)
}

/// [`edge`] and the edge's inner samples in the output ([`crate::topology::Topology::edge_samples`]), seen
/// where a patch of `visible` uses it: one walk over its uses for both.
#[inline(always)]
fn counted_edge(
    set: &SurfaceSet,
    proposals: &[Proposals],
    visible: &[u32],
    rule: EdgeRule,
    caps: &Caps<'_>,
    e: usize,
) -> (u32, f32, u32) {
    let uses = set.topology.edge_uses(e);
    let wanted = uses.iter().map(|u| proposals[u.patch as usize][u.local as usize]).fold(CULLED, f64::max);
    // The largest of 0 and the proposals, as `edge` finds it.
    let (s, f) = settle(wanted.max(0.0), rule, caps, e);
    let topo = &set.topology;
    // A proposal of 0 or more comes from a visible patch. Only an edge without one (culled
    // all round, or proposed NaN) that would have inner samples asks the visibility row:
    // rarely, so that branch is predicted, where asking for every culled edge mispredicted
    // (culled and visible edges alternate in no order).
    let ask = (wanted < 0.0) & (topo.edge_samples(e, true, s) != 0);
    let seen = if ask { topo.edge_seen(e, visible) } else { wanted >= 0.0 };
    (s, f, topo.edge_samples(e, seen, s))
}

/// The rest of [`edge`] from the largest proposal, `wanted`.
#[inline(always)]
fn settle(wanted: f64, rule: EdgeRule, caps: &Caps<'_>, e: usize) -> (u32, f32) {
    let cap = caps.max_factor.max(1.0);
    let wanted = wanted.min(cap);
    let minimum = caps.minimum_segments[e].max(1);
    match rule {
        EdgeRule::Integer => {
            let s = round_factor(wanted).max(minimum);
            (s, s as f32)
        }
        EdgeRule::PowerOfTwo => {
            // Level ⌈log2 f⌉, with a margin for factors that are powers of two up to
            // rounding (the view criteria interpolate levels, not factors).
            let level = (wanted.max(1.0).log2() - 1e-9).ceil().max(0.0) as u32;
            let s = (1u32 << level.min(31)).max(minimum).next_power_of_two().min(cap as u32);
            (s, s as f32)
        }
        EdgeRule::Fractional(spacing) => {
            let f = wanted.max(minimum as f64);
            let f = match spacing {
                Spacing::Hardware(p) => settled_factor(p.hull_factor(f), p, OUTPUT_GAP),
                Spacing::Symmetric => f,
            };
            // Segments follow from the stored f32 factor, the one every engine reads.
            let f = f as f32;
            (spacing_segments(f as f64, spacing), f)
        }
    }
}

/// [`edges`] again after the proposals of `patches` changed (and no other's), for a rule
/// other than [`InteriorRule::Global`]: only their edges are resolved again, and those whose
/// segments or factor changed are appended to `changed` (as `(edge, segments, factor)`, each
/// edge once, in edge order) while `segments` and `factors` are left as they were. Applying
/// them gives what [`edges`] gives from the new proposals, as no other edge reads a changed
/// proposal. Cost: O(edges of `patches`), sequential.
pub fn update_edges(
    set: &SurfaceSet,
    proposals: &[Proposals],
    rule: EdgeRule,
    caps: &Caps<'_>,
    patches: &[usize],
    (segments, factors): (&[u32], &[f32]),
    changed: &mut Vec<(u32, u32, f32)>,
) {
    let topo = &set.topology;
    let first = changed.len();
    for &p in patches {
        for pe in &topo.patch_edges[p][..topo.patch_domains[p].corner_count()] {
            let e = pe.edge as usize;
            let (s, f) = edge(set, proposals, rule, caps, e);
            if s != segments[e] || f.to_bits() != factors[e].to_bits() {
                changed.push((e as u32, s, f));
            }
        }
    }
    changed[first..].sort_unstable_by_key(|c| c.0);
    let mut kept = first;
    for i in first..changed.len() {
        if kept == first || changed[kept - 1].0 != changed[i].0 {
            changed[kept] = changed[i];
            kept += 1;
        }
    }
    changed.truncate(kept);
}

/// Resolves per-use proposals into per-edge segments and factors (written into `segments`
/// and `factors`, cleared first). Cost: O(E) plus the edge uses, parallel.
pub fn edges(
    set: &SurfaceSet,
    proposals: &[Proposals],
    rule: EdgeRule,
    interior: InteriorRule,
    caps: &Caps<'_>,
    segments: &mut Vec<u32>,
    factors: &mut Vec<f32>,
) {
    let topo = &set.topology;
    let edges = topo.edges.len();
    // Every entry is written below: no clearing pass first (on the main thread alone).
    segments.resize(edges, 0);
    factors.resize(edges, 0.0);
    // Every edge on its own: parallel, in runs large enough to outweigh the scheduling, each
    // a plain loop with the rule's arm chosen once (`edge` inlined into each arm; called per
    // edge, with the rule matched inside, it was a tenth of the torus grid's frame).
    fn resolve_all(segments: &mut [u32], factors: &mut [f32], resolve: impl Fn(usize) -> (u32, f32) + Sync) {
        const RUN: usize = 4096;
        segments.par_chunks_mut(RUN).zip(factors.par_chunks_mut(RUN)).enumerate().for_each(|(c, (s, f))| {
            for (i, (s, f)) in s.iter_mut().zip(f).enumerate() {
                (*s, *f) = resolve(c * RUN + i);
            }
        })
    }
    match rule {
        EdgeRule::Integer => {
            resolve_all(segments, factors, |e| edge(set, proposals, EdgeRule::Integer, caps, e))
        }
        EdgeRule::PowerOfTwo => {
            resolve_all(segments, factors, |e| edge(set, proposals, EdgeRule::PowerOfTwo, caps, e))
        }
        EdgeRule::Fractional(_) => resolve_all(segments, factors, |e| edge(set, proposals, rule, caps, e)),
    }
    if interior == InteriorRule::Global {
        let n = segments
            .iter()
            .copied()
            .chain(caps.minimum_interior.iter().flatten().copied())
            .max()
            .unwrap_or(1);
        segments.iter_mut().for_each(|s| *s = n);
        factors.iter_mut().for_each(|f| *f = n as f32);
    }
}

/// [`edges`] for an interior rule other than [`InteriorRule::Global`], with each edge's inner
/// samples in the output written into `counts` (resized) as the layout counts them
/// ([`crate::topology::Topology::edge_samples`]; an edge is seen where a patch `p` with `visible[p] != 0` uses
/// it). The layout then reads them (`engine::layout::Layout::build_counted`)
/// instead of walking every edge's uses a second time in a pass of its own. Cost: O(E) plus
/// the edge uses, parallel.
#[allow(clippy::too_many_arguments)]
pub(crate) fn edges_counted(
    set: &SurfaceSet,
    proposals: &[Proposals],
    rule: EdgeRule,
    caps: &Caps<'_>,
    visible: &[u32],
    segments: &mut Vec<u32>,
    factors: &mut Vec<f32>,
    counts: &mut Vec<u32>,
) {
    let edges = set.topology.edges.len();
    segments.resize(edges, 0);
    factors.resize(edges, 0.0);
    counts.resize(edges, 0);
    // As in `edges`, the rule's arm chosen once.
    fn resolve_all(
        (segments, factors, counts): (&mut [u32], &mut [f32], &mut [u32]),
        resolve: impl Fn(usize) -> (u32, f32, u32) + Sync,
    ) {
        const RUN: usize = 4096;
        let runs =
            segments.par_chunks_mut(RUN).zip(factors.par_chunks_mut(RUN)).zip(counts.par_chunks_mut(RUN));
        runs.enumerate().for_each(|(c, ((s, f), n))| run(c * RUN, s, f, n, &resolve))
    }
    // A function of its own: its rows, arguments, are known to the compiler not to overlap
    // the data `resolve` reads, which it then keeps in registers instead of reading the
    // pointers to it again for every edge.
    #[inline(never)]
    fn run(
        first: usize,
        s: &mut [u32],
        f: &mut [f32],
        n: &mut [u32],
        resolve: &impl Fn(usize) -> (u32, f32, u32),
    ) {
        for (i, ((s, f), n)) in s.iter_mut().zip(f).zip(n).enumerate() {
            (*s, *f, *n) = resolve(first + i);
        }
    }
    let rows = (&mut segments[..], &mut factors[..], &mut counts[..]);
    let edge = |rule, e| counted_edge(set, proposals, visible, rule, caps, e);
    match rule {
        EdgeRule::Integer => resolve_all(rows, |e| edge(EdgeRule::Integer, e)),
        EdgeRule::PowerOfTwo => resolve_all(rows, |e| edge(EdgeRule::PowerOfTwo, e)),
        EdgeRule::Fractional(_) => resolve_all(rows, |e| edge(rule, e)),
    }
}

/// Interior factors of every patch from its edges' segments by `rule` (into `out`, resized to
/// one row a patch). Cost: O(P), parallel.
pub fn interiors(
    set: &SurfaceSet,
    segments: &[u32],
    rule: InteriorRule,
    caps: &Caps<'_>,
    out: &mut Vec<[u32; 2]>,
) {
    let topo = &set.topology;
    // In parallel, each element once (`resize` keeps a row of the right length as it is).
    out.resize(set.patches.len(), [0; 2]);
    out.par_iter_mut().enumerate().with_min_len(1024).for_each(|(p, out)| {
        let domain = set.topology.patch_domains[p];
        let s = |l: usize| segments[topo.patch_edges[p][l].edge as usize];
        let largest = (0..domain.corner_count()).map(s).max().unwrap_or(1);
        let minimum = caps.minimum_interior[p];
        *out = match (rule, domain) {
            (InteriorRule::Global, _) => [largest, largest],
            (InteriorRule::Core, Domain::Quad) => {
                [s(0).min(s(2)).max(minimum[0]), s(1).min(s(3)).max(minimum[1])]
            }
            (InteriorRule::Core, Domain::Tri) | (InteriorRule::MaxEdge, _) => [largest, largest],
            (InteriorRule::Level, _) => {
                let n =
                    largest.max(minimum[0]).max(minimum[1]).next_power_of_two().min(caps.max_factor as u32);
                [n, n]
            }
        };
    });
}

/// Per-use proposals from one factor per edge (criteria that judge an edge by its own data,
/// such as the view criteria): every use of edge `e` proposes `per_edge[e]`. Cost: O(P),
/// parallel.
pub fn from_edge_factors(set: &SurfaceSet, per_edge: &[f64], out: &mut Vec<Proposals>) {
    let topo = &set.topology;
    out.resize(set.patches.len(), [0.0; 4]);
    out.par_iter_mut().enumerate().with_min_len(1024).for_each(|(p, row)| {
        *row = [0.0; 4];
        for (l, r) in row.iter_mut().enumerate().take(set.topology.patch_domains[p].corner_count()) {
            *r = per_edge[topo.patch_edges[p][l].edge as usize];
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::{Patch, RationalBicubic};
    use glam::DVec3;

    #[test]
    fn round_factor_is_the_library_rounding() {
        let halves = (0..2000).map(|k| k as f64 * 0.5);
        let near = (0..2000).flat_map(|k| {
            let x = k as f64 * 0.5;
            // The neighbouring doubles (the crate's minimum Rust has no next_up/next_down).
            [f64::from_bits(x.to_bits().saturating_sub(u64::from(x > 0.0))), f64::from_bits(x.to_bits() + 1)]
        });
        let odd = [0.0, 0.49999999999999994, 1e-300, 64.0, 4294967294.5, 4294967295.0, 1e12, f64::MAX];
        for x in halves.chain(near).chain(odd) {
            assert_eq!(round_factor(x), x.round() as u32, "{x:e}");
        }
    }

    /// Two flat bicubic patches side by side, sharing the curve `x = 3`.
    fn pair() -> SurfaceSet {
        let quad = |x0: f64| {
            Patch::Bicubic(RationalBicubic {
                points: std::array::from_fn(|k| DVec3::new(x0 + (k / 4) as f64, (k % 4) as f64, 0.0)),
                weights: [1.0; 16],
            })
        };
        SurfaceSet::from_patches(vec![quad(0.0), quad(3.0)], Default::default())
    }

    fn shared_edge(set: &SurfaceSet) -> usize {
        (0..set.topology.edges.len()).find(|&e| set.topology.edge_uses(e).len() == 2).expect("a shared curve")
    }

    fn resolve(
        set: &SurfaceSet,
        proposals: &[Proposals],
        rule: EdgeRule,
        interior: InteriorRule,
        cap: f64,
    ) -> (Vec<u32>, Vec<f32>) {
        let minimum = vec![1; set.topology.edges.len()];
        let minimum_interior = vec![[1, 1]; set.patches.len()];
        let caps = Caps { max_factor: cap, minimum_segments: &minimum, minimum_interior: &minimum_interior };
        let (mut s, mut f) = (Vec::new(), Vec::new());
        edges(set, proposals, rule, interior, &caps, &mut s, &mut f);
        (s, f)
    }

    #[test]
    fn an_edge_takes_the_maximum_of_its_patches_proposals() {
        let set = pair();
        let shared = shared_edge(&set);
        let (s, _) = resolve(&set, &[[2.0; 4], [5.0; 4]], EdgeRule::Integer, InteriorRule::Core, 64.0);
        assert_eq!(s[shared], 5);
        for u in set.topology.edge_uses(shared) {
            assert_eq!(set.topology.patch_edges[u.patch as usize][u.local as usize].edge as usize, shared);
        }
        // Every other edge has one patch, and keeps its proposal.
        for (e, &n) in s.iter().enumerate().filter(|&(e, _)| e != shared) {
            let owner = set.topology.edge_uses(e)[0].patch;
            assert_eq!(n, if owner == 0 { 2 } else { 5 }, "edge {e}");
        }
        // Order of the patches does not matter.
        let (t, _) = resolve(&set, &[[5.0; 4], [2.0; 4]], EdgeRule::Integer, InteriorRule::Core, 64.0);
        assert_eq!(t[shared], 5);
    }

    #[test]
    fn rules_round_and_cap() {
        let set = pair();
        let shared = shared_edge(&set);
        let (s, _) = resolve(&set, &[[3.0; 4], [1.0; 4]], EdgeRule::PowerOfTwo, InteriorRule::Level, 64.0);
        assert_eq!(s[shared], 4, "3 rounds up to the next level");
        let (s, _) = resolve(&set, &[[9.0; 4], [1.0; 4]], EdgeRule::PowerOfTwo, InteriorRule::Level, 8.0);
        assert_eq!(s[shared], 8, "the cap stops the level");
        let (s, _) = resolve(&set, &[[2.6; 4], [1.0; 4]], EdgeRule::Integer, InteriorRule::Core, 64.0);
        assert_eq!(s[shared], 3, "integer factors round to the nearest");
        let (s, _) = resolve(&set, &[[100.0; 4], [1.0; 4]], EdgeRule::Integer, InteriorRule::Core, 10.0);
        assert_eq!(s[shared], 10);
        let odd = Spacing::Hardware(crate::sampling::Partitioning::FractionalOdd);
        let (s, f) =
            resolve(&set, &[[2.5; 4], [1.0; 4]], EdgeRule::Fractional(odd), InteriorRule::MaxEdge, 64.0);
        assert_eq!((s[shared], f[shared]), (spacing_segments(2.5, odd), 2.5));
    }

    /// Raising some patches' proposals and resolving only their edges again
    /// (`update_edges`, as a round of the a-posteriori check does) gives, once applied, what
    /// resolving every edge gives, under every edge rule; and it lists only edges that changed.
    #[test]
    fn updating_the_raised_patches_edges_equals_resolving_every_edge() {
        let path = crate::test_support::data("meshes/cow.obj");
        let mesh = crate::io::obj::read_obj(&path).unwrap();
        let set = SurfaceSet::pn_from_mesh(&mesh, &path, Default::default()).unwrap();
        let (edge_count, patch_count) = (set.topology.edges.len(), set.patches.len());
        let mut rng = crate::test_support::Lcg(5);
        let minimum: Vec<u32> = (0..edge_count).map(|_| 1 + (rng.below(4) == 0) as u32 * 2).collect();
        let minimum_interior = vec![[1, 1]; patch_count];
        let caps = Caps { max_factor: 24.0, minimum_segments: &minimum, minimum_interior: &minimum_interior };
        let odd = Spacing::Hardware(crate::sampling::Partitioning::FractionalOdd);
        let rules = [EdgeRule::Integer, EdgeRule::PowerOfTwo, EdgeRule::Fractional(odd)];
        let mut changed_edges = 0;
        for (round, rule) in rules.into_iter().cycle().take(12).enumerate() {
            let mut proposals: Vec<Proposals> =
                (0..patch_count).map(|_| std::array::from_fn(|_| 1.0 + 12.0 * rng.unit())).collect();
            let (mut segments, mut factors) = (Vec::new(), Vec::new());
            edges(&set, &proposals, rule, InteriorRule::MaxEdge, &caps, &mut segments, &mut factors);
            let raised: Vec<usize> =
                (0..patch_count).filter(|_| rng.below(10 + 40 * (round % 2)) == 0).collect();
            for &p in &raised {
                proposals[p] = proposals[p].map(|v| (v * (1.2 + 3.0 * rng.unit())).ceil().min(24.0));
            }
            let mut changed = Vec::new();
            update_edges(&set, &proposals, rule, &caps, &raised, (&segments, &factors), &mut changed);
            let (mut expected_s, mut expected_f) = (Vec::new(), Vec::new());
            edges(&set, &proposals, rule, InteriorRule::MaxEdge, &caps, &mut expected_s, &mut expected_f);
            assert!(changed.windows(2).all(|w| w[0].0 < w[1].0), "each edge once, in order");
            for &(e, s, f) in &changed {
                let e = e as usize;
                assert!(s != segments[e] || f != factors[e], "edge {e} is listed but did not change");
                (segments[e], factors[e]) = (s, f);
            }
            changed_edges += changed.len();
            assert_eq!(segments, expected_s, "{rule:?}");
            assert_eq!(
                factors.iter().map(|f| f.to_bits()).collect::<Vec<_>>(),
                expected_f.iter().map(|f| f.to_bits()).collect::<Vec<_>>(),
                "{rule:?}"
            );
        }
        assert!(changed_edges > 1000, "the raises change edges: {changed_edges}");
    }

    /// Resolving with the layout's counts (`edges_counted`, culled patches proposing
    /// [`CULLED`]) gives the segments and factors `edges` gives (culled patches proposing
    /// nothing), and each edge's inner samples: a row per variant of its segments where a
    /// visible patch uses it, none otherwise — also where only culled patches use an edge
    /// whose minimum is 3 segments, and where a visible patch proposes NaN.
    #[test]
    fn counting_edges_with_their_resolution_gives_the_layouts_counts() {
        let path = crate::test_support::data("meshes/cow.obj");
        let mesh = crate::io::obj::read_obj(&path).unwrap();
        let set = SurfaceSet::pn_from_mesh(&mesh, &path, Default::default()).unwrap();
        let topo = &set.topology;
        let (edge_count, patch_count) = (topo.edges.len(), set.patches.len());
        let mut rng = crate::test_support::Lcg(11);
        let minimum: Vec<u32> = (0..edge_count).map(|_| 1 + (rng.below(3) == 0) as u32 * 2).collect();
        let minimum_interior = vec![[1, 1]; patch_count];
        let caps = Caps { max_factor: 24.0, minimum_segments: &minimum, minimum_interior: &minimum_interior };
        let odd = Spacing::Hardware(crate::sampling::Partitioning::FractionalOdd);
        let (mut unseen_with_minimum, mut nan, mut counted) = (0, 0, 0);
        for rule in [EdgeRule::Integer, EdgeRule::PowerOfTwo, EdgeRule::Fractional(odd)] {
            let visible: Vec<u32> = (0..patch_count).map(|_| u32::from(rng.below(2) == 0)).collect();
            let wishes: Vec<Proposals> = (0..patch_count)
                .map(|_| {
                    std::array::from_fn(|_| if rng.below(50) == 0 { f64::NAN } else { 12.0 * rng.unit() })
                })
                .collect();
            let proposals_of = |culled: f64| -> Vec<Proposals> {
                wishes.iter().zip(&visible).map(|(&w, &v)| if v != 0 { w } else { [culled; 4] }).collect()
            };
            let (mut expected_s, mut expected_f) = (Vec::new(), Vec::new());
            edges(
                &set,
                &proposals_of(0.0),
                rule,
                InteriorRule::Core,
                &caps,
                &mut expected_s,
                &mut expected_f,
            );
            let (mut s, mut f, mut counts) = (Vec::new(), Vec::new(), Vec::new());
            edges_counted(&set, &proposals_of(CULLED), rule, &caps, &visible, &mut s, &mut f, &mut counts);
            assert_eq!(s, expected_s, "{rule:?}");
            let bits = |f: &[f32]| f.iter().map(|f| f.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&f), bits(&expected_f), "{rule:?}");
            for (e, edge) in topo.edges.iter().enumerate() {
                let uses = topo.edge_uses(e);
                let seen = uses.iter().any(|u| visible[u.patch as usize] != 0);
                let expected = if seen && !edge.collapsed { (s[e] - 1) * edge.variants as u32 } else { 0 };
                assert_eq!(counts[e], expected, "edge {e}, {rule:?}");
                unseen_with_minimum += usize::from(!seen && s[e] > 1);
                let proposed = |u: &crate::topology::EdgeUse| wishes[u.patch as usize][u.local as usize];
                nan += usize::from(
                    seen && uses.iter().all(|u| visible[u.patch as usize] == 0 || proposed(u).is_nan()),
                );
                counted += usize::from(counts[e] > 0);
            }
        }
        assert!(
            unseen_with_minimum > 100 && nan > 0 && counted > 1000,
            "{unseen_with_minimum} {nan} {counted}"
        );
    }

    #[test]
    fn the_global_rule_gives_every_edge_the_largest() {
        let set = pair();
        let (s, f) = resolve(&set, &[[2.0; 4], [5.0; 4]], EdgeRule::Integer, InteriorRule::Global, 64.0);
        assert!(s.iter().all(|&n| n == 5) && f.iter().all(|&x| x == 5.0), "{s:?}");
    }

    #[test]
    fn minimums_hold_and_interiors_follow_the_rule() {
        let set = pair();
        let minimum = vec![3; set.topology.edges.len()];
        let minimum_interior = vec![[1, 1]; set.patches.len()];
        let caps = Caps { max_factor: 64.0, minimum_segments: &minimum, minimum_interior: &minimum_interior };
        let (mut s, mut f) = (Vec::new(), Vec::new());
        edges(&set, &[[1.0; 4], [1.0; 4]], EdgeRule::Integer, InteriorRule::Core, &caps, &mut s, &mut f);
        assert!(s.iter().all(|&n| n == 3));
        // Core: each direction takes the smaller of its two opposite edges.
        let topo = &set.topology;
        s[topo.patch_edges[0][0].edge as usize] = 7;
        let mut interior = Vec::new();
        interiors(&set, &s, InteriorRule::Core, &caps, &mut interior);
        assert_eq!(interior[0], [3, 3]);
        interiors(&set, &s, InteriorRule::MaxEdge, &caps, &mut interior);
        assert_eq!(interior[0], [7, 7]);
        interiors(&set, &s, InteriorRule::Level, &caps, &mut interior);
        assert_eq!(interior[0], [8, 8]);
    }
}
