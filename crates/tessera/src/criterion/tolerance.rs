//! Error-bounded plans: every visible patch gets an object-space tolerance `ε_p` (given
//! directly, or converted from pixels by [`super::screen`]), and the plan guarantees that the
//! mesh stays within `ε_p` of the surface on that patch (bounds in [`super::bounds`]).
//!
//! Crack-freeness: an edge's sampling is the *maximum* of what its visible patches ask for
//! (the CudaTess rule), computed once per edge here and read by every patch. Each patch's
//! proposal already covers the edge curve's own bound, so the maximum satisfies all of them.
//! Interior factors are private to a patch and may be raised freely.

use super::bounds::{self, HessianBound, TriangleErrors, TriangleShape};
use super::pattern_shapes::PatternShapes;
use super::resolve::{self, EdgeRule, InteriorRule};
use super::taylor::TaylorBound;
use super::{Plan, Prepared};
use crate::error::{Error, Result};
use crate::pattern::cache::LocalParams;
use crate::pattern::{LocalTessellation, Pattern, PatternInput};
use crate::surface::{Domain, Patch, SurfaceSet};
use rayon::prelude::*;
use std::sync::atomic::{AtomicU64, Ordering};

/// What an error-bounded plan achieved.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BoundReport {
    /// Patches culled (not tessellated).
    pub culled: usize,
    /// Visible patches whose guarantee the factor cap prevented.
    pub capped_patches: usize,
    /// Largest ratio of guaranteed bound to requested tolerance over visible patches
    /// (≤ 1 when every bound is met).
    pub worst_ratio: f64,
    /// Largest guaranteed object-space bound over visible patches.
    pub worst_bound: f64,
    /// Rounds that raised edges after the first check (patches whose strips missed the
    /// bound asking for finer edges; each change can move the problem to a neighbour).
    pub rounds: usize,
}

/// Parses a tolerance as a front end takes it: a distance in model units (`"0.002"`), or a
/// share of `diagonal` (the bounding-box diagonal) written with `%` (`"0.1%"`). The one rule
/// for both the command line's `--tolerance` and the Python package's `tolerance=`.
///
/// Errors: [`Error::InvalidParameter`] (name `tolerance`) for text that is not a finite
/// positive number. Cost: O(length of `text`).
pub fn parse_tolerance(text: &str, diagonal: f64) -> Result<f64> {
    let (number, relative) = match text.trim().strip_suffix('%') {
        Some(n) => (n, true),
        None => (text.trim(), false),
    };
    let invalid = |why: &str| Error::InvalidParameter { name: "tolerance", reason: format!("{text}: {why}") };
    let v: f64 = number.trim().parse().map_err(|_| invalid("not a number"))?;
    if !(v.is_finite() && v > 0.0) {
        return Err(invalid("must be a positive number"));
    }
    Ok(if relative { v / 100.0 * diagonal } else { v })
}

/// `1.0 / n as f64` for `n < 65`: the same correctly rounded quotients, read instead of
/// divided. The grid search divides three times and takes a root per column count, and the
/// proposals of a coarse frame try about four counts a patch.
static RECIPROCALS: [f64; 65] = {
    let mut r = [0.0; 65];
    let mut n = 1;
    while n < 65 {
        r[n] = 1.0 / n as f64;
        n += 1;
    }
    r
};

/// `1 / n`, from [`RECIPROCALS`] where it holds it (the same quotient: a division is exact
/// to the last bit wherever it is done).
#[inline]
fn reciprocal(n: u32) -> f64 {
    match RECIPROCALS.get(n as usize) {
        Some(&r) if n > 0 => r,
        _ => 1.0 / n as f64,
    }
}

/// The smallest grid `(nu, nv)` (fewest cells) whose cells meet Filip's bound
/// `(hu²·Muu + 2·hu·hv·Muv + hv²·Mvv)/8 ≤ ε`, with both factors ≤ `cap`; None if impossible.
fn quad_grid(m: &HessianBound, eps: f64, cap: u32) -> Option<(u32, u32)> {
    // The height `hv` that columns `nu` leave each row, None where `hu` alone exceeds the
    // budget.
    let height = |nu: u32| -> Option<f64> {
        let hu = reciprocal(nu);
        let (a, b, c) = (m.vv, 2.0 * m.uv * hu, m.uu * hu * hu - 8.0 * eps);
        if c > 0.0 {
            return None;
        }
        let hv = if a > 0.0 {
            (-b + (b * b - 4.0 * a * c).sqrt()) / (2.0 * a)
        } else if b > 0.0 {
            -c / b
        } else {
            1.0
        };
        // hu alone takes the whole budget (c = 0): no cell height is left.
        (hv > 0.0).then_some(hv)
    };
    // The rows `nv` that columns `nu` need.
    let rows = |hv: f64| -> u64 {
        if hv >= 1.0 {
            1
        } else {
            ceil(1.0 / hv) as u64
        }
    };
    // `rows` only shrinks as `nu` grows, so no grid of `nu` or more columns has fewer than
    // `nu · rows(cap)` cells: the search stops there (one row less, against rounding).
    let fewest_rows = rows(height(cap)?).saturating_sub(1).max(1);
    let mut best: Option<(u32, u32)> = None;
    // The cells of the continuous grid, `nu / hv`, a lower bound of `nu · rows`: as a function
    // of `nu` it falls to one minimum and rises after it (the cell area `hu · hv` on the
    // bound's ellipse rises to one maximum as `hu` shrinks, then falls). Once it rises and
    // is within a cell of the best grid, no later column count has fewer cells.
    let mut last_area = f64::INFINITY;
    for nu in 1..=cap {
        if best.is_some_and(|(bu, bv)| nu as u64 * fewest_rows >= bu as u64 * bv as u64) {
            break;
        }
        let Some(hv) = height(nu) else { continue };
        let area = nu as f64 / hv;
        if let Some((bu, bv)) = best {
            if area > last_area && area > (bu as u64 * bv as u64) as f64 - 1.0 + 1e-6 {
                break;
            }
        }
        last_area = area;
        let nv = rows(hv);
        if nv > cap as u64 {
            continue;
        }
        let nv = nv as u32;
        if best.is_none_or(|(bu, bv)| (nu as u64 * nv as u64) < (bu as u64 * bv as u64)) {
            best = Some((nu, nv));
        }
        if nv == 1 {
            break; // larger nu only adds cells
        }
    }
    best
}

/// `x.ceil()`, bit for bit, without the library call that `f64::ceil` is on the baseline
/// x86-64 target (no SSE4.1): the proposals take three or four per patch per frame, and the
/// call was 2.5 % of a frame of the killeroo herd. Positive `x` below 2⁶³ truncates exactly
/// through `i64`; everything else (zero, negatives, huge, infinite, NaN) takes `f64::ceil`.
/// Through `i64`, not `u64`: the baseline target converts between f64 and i64 in one
/// instruction each way and between f64 and u64 in a branchy sequence, and the proposals
/// of the Catmull-Clark torus at 0.5 px spent 2–3 % of the frame there.
#[inline]
fn ceil(x: f64) -> f64 {
    if x > 0.0 && x < 9.2e18 {
        let t = x as i64 as f64;
        if t < x {
            t + 1.0
        } else {
            t
        }
    } else {
        x.ceil()
    }
}

/// Smallest factor `n` whose uniform triangle grid meets the bound (`hu = hv = 1/n`).
fn uniform_factor(m: &HessianBound, eps: f64) -> f64 {
    at_least_one_root(m.uu + 2.0 * m.uv + m.vv, 8.0 * eps)
}

/// Segments a boundary curve needs on its own: `sqrt(M_edge / 8ε)` from the bound of its
/// four control points ([`curve_bounds`]) — data both neighbours share.
fn curve_factor(m_edge: f64, eps: f64) -> f64 {
    at_least_one_root(m_edge, 8.0 * eps)
}

/// `⌈√(m / d)⌉`, at least 1, bit for bit, without the division and the root where `m ≤ d`
/// and `d > 0`: the quotient is then at most 1 (division by a positive number rounds
/// monotonically, and `d / d = 1`), so the root is too (or NaN) and the result is 1. In a
/// distant view most patches need one segment an edge, and the proposals' divisions and
/// roots (five of each a patch) were what bounded that pass. Everything else, NaN included,
/// takes the whole expression.
#[inline]
fn at_least_one_root(m: f64, d: f64) -> f64 {
    if m <= d && d > 0.0 {
        1.0
    } else {
        ceil((m / d).sqrt()).max(1.0)
    }
}

/// The four control points (and weights) of a patch's boundary curve `local`, from corner
/// `local` to corner `local + 1`; `None` for a subdivision patch, whose boundary is
/// piecewise (a Loop patch's also quartic).
pub fn edge_control_points(patch: &Patch, local: usize) -> Option<([glam::DVec3; 4], [f64; 4])> {
    let idx = crate::surface::corner_and_edge_points(patch.domain()).1[local];
    let points = patch.control_points();
    match patch {
        Patch::Bicubic(b) => Some((idx.map(|i| points[i]), idx.map(|i| b.weights[i]))),
        Patch::BezierTriangle(_) | Patch::Pn(_) => Some((idx.map(|i| points[i]), [1.0; 4])),
        Patch::Subdivision(_) | Patch::Loop(_) => None,
    }
}

/// Guaranteed error bound of one patch under `input`, from its pattern's triangles.
pub fn patch_bound(
    m: &HessianBound,
    input: &PatternInput,
    pattern: &dyn Pattern,
    scratch: &mut LocalTessellation,
) -> f64 {
    pattern.build(input, scratch);
    built_pattern_bound(&m.triangle_errors(), input, scratch, &mut Vec::new())
}

/// Guaranteed error bound of one patch under `input` as the a-posteriori check of a plan
/// computes it: a pattern that is a grid ([`Pattern::grid_cells`]) bounded from its cells, a
/// core's cells ([`Pattern::core_cells`]) together and the other triangles one by one, each
/// the smaller of the second-derivative bound (`errors`) and, where given and the patch has
/// one, `taylor` (the bound a plan with [`crate::criterion::ErrorBound::Taylor`] or
/// [`crate::criterion::ErrorBound::Expansion`] takes: [`crate::criterion::Prepared::
/// bounds_for`]). What the GPU's check is compared against. Cost: one pattern build, and an
/// evaluation a cell or triangle with `taylor`.
pub fn checked_patch_bound(
    errors: &TriangleErrors,
    taylor: Option<&TaylorBound>,
    input: &PatternInput,
    pattern: &dyn Pattern,
    scratch: &mut LocalTessellation,
) -> f64 {
    let taylor = taylor.filter(|t| t.is_some()).map(|t| (t, input.domain));
    if let Some(cells) = pattern.grid_cells(input) {
        return grid_bound(errors, taylor, cells);
    }
    pattern.build(input, scratch);
    let mut boundary = Vec::new();
    crate::pattern::cache::boundary_params(input, &mut boundary);
    let params = LocalParams { boundary: &boundary, interior: &scratch.interior };
    let core = pattern.core_cells(input);
    core_params_bound(errors, taylor, core, after_core(core, &scratch.triangles), params)
}

/// [`patch_bound`] of a pattern already built for `input`; `params` is a buffer for the
/// parameters of its boundary vertices (computed once each, not once per triangle corner).
fn built_pattern_bound(
    m: &TriangleErrors,
    input: &PatternInput,
    built: &LocalTessellation,
    params: &mut Vec<glam::DVec2>,
) -> f64 {
    crate::pattern::cache::boundary_params(input, params);
    triangles_bound(
        m,
        None,
        &built.triangles,
        LocalParams { boundary: params, interior: &built.interior },
        0.0,
    )
}

/// The largest triangle error of `triangles` over `params`, and `at_least`: each triangle's
/// the smaller of its second-derivative bound and, where there is one, its Taylor bound
/// (both are valid).
fn triangles_bound(
    errors: &TriangleErrors,
    taylor: Option<&TaylorBound>,
    triangles: &[[u32; 3]],
    params: LocalParams<'_>,
    at_least: f64,
) -> f64 {
    let points = triangles.iter().map(|t| t.map(|l| params.get(l)));
    let Some(taylor) = taylor else {
        return shapes_bound(errors, points.map(TriangleShape::of), at_least);
    };
    // The running largest error skips what cannot raise it ([`TriangleErrors::exceeds`]);
    // the Taylor bound, dearer, is computed only for a triangle that would raise it.
    points.fold(at_least, |most, t| match errors.exceeds(t, most) {
        None => most,
        Some(e) => most.max(e.min(taylor.triangle_error_above(t, most))),
    })
}

/// The largest second-derivative bound of triangles of shapes `shapes`, and `at_least`. The
/// running largest skips what cannot raise it ([`TriangleErrors::shape_exceeds`]), so the
/// largest triangles first make the others cheap; the result is the same in any order.
#[inline]
pub(super) fn shapes_bound(
    errors: &TriangleErrors,
    shapes: impl IntoIterator<Item = TriangleShape>,
    at_least: f64,
) -> f64 {
    shapes.into_iter().fold(at_least, |most, s| errors.shape_exceeds(&s, most).map_or(most, |e| most.max(e)))
}

/// The triangles of a whole pattern after its `core` ([`Pattern::core_cells`]): all of them
/// where the count does not fit.
pub(super) fn after_core(core: Option<([u32; 2], u32)>, triangles: &[[u32; 3]]) -> &[[u32; 3]] {
    match core {
        Some((_, count)) if count as usize <= triangles.len() => &triangles[count as usize..],
        _ => triangles,
    }
}

/// The bound of the cells of `core` ([`Pattern::core_cells`]) together ([`grid_bound`]); 0
/// where there is none.
fn core_bound(
    errors: &TriangleErrors,
    taylor: Option<(&TaylorBound, Domain)>,
    core: Option<([u32; 2], u32)>,
) -> f64 {
    match core {
        Some((cells, count)) if count > 0 => grid_bound(errors, taylor, cells),
        _ => 0.0,
    }
}

/// The bound of a pattern whose triangles are a core of `core`'s cells
/// ([`Pattern::core_cells`]), bounded together by one cell's bound ([`grid_bound`]), and
/// `rest`, bounded one by one.
fn core_params_bound(
    errors: &TriangleErrors,
    taylor: Option<(&TaylorBound, Domain)>,
    core: Option<([u32; 2], u32)>,
    rest: &[[u32; 3]],
    params: LocalParams<'_>,
) -> f64 {
    triangles_bound(errors, taylor.map(|t| t.0), rest, params, core_bound(errors, taylor, core))
}

/// The bound of a pattern whose triangles are all halves of the cells of the `nu × nv` grid
/// ([`Pattern::grid_cells`]): the second-derivative bound of one of them,
/// `(0, 0), (1/nu, 0), (0, 1/nv)` (every such triangle has the same, as it depends only on
/// the differences of the corners), or, where the patch has a Taylor bound, the largest over
/// the grid's cells of the smaller of the two (a core grid's cells are among them). No
/// pattern is built. Cost: O(1), or one evaluation a cell with a Taylor bound.
fn grid_bound(m: &TriangleErrors, taylor: Option<(&TaylorBound, Domain)>, [nu, nv]: [u32; 2]) -> f64 {
    let hessian = m.cell_error(reciprocal(nu), reciprocal(nv));
    match taylor {
        Some((t, domain)) => t.grid_error_within(domain == Domain::Tri, [nu, nv], hessian),
        None => hessian,
    }
}

/// The largest grid (in cells) a Taylor proposal searches below: each step of the search
/// bounds a whole grid, so an absurd tolerance (grids of thousands of cells a side) keeps the
/// second-derivative bound's proposal, and only the check, which bounds each pattern once
/// after the output budget admitted it, takes the Taylor bound there.
const TAYLOR_SEARCH_CELLS: u64 = 1 << 16;

/// The grid with the fewest cells near `start` (the second-derivative bound's, which the
/// Taylor bound may not meet on coarse grids) whose bound meets `eps` (cell by cell the
/// smaller of the Taylor bound and `m`'s, as [`grid_bound`]). The
/// second-derivative bound's grid, scaled by the square root of the Taylor bound's slack there
/// (errors shrink like `h²`), gives a first grid `(nu1, nv1)` that meets it; then a staircase
/// walk over the column counts from `nu1/2` to `2·nu1`, each with the fewest rows that meet
/// it (rows only shrink as columns grow), keeps the grid with the fewest cells. `start`
/// itself where the Taylor bound does not meet `eps` there. A proposal only: the a-posteriori
/// check verifies the built pattern. Cost: about `2·nu1 + nv1` grid bounds of one
/// evaluation a cell; for a bound that samples its patch ([`TaylorBound::samples`]: a tree,
/// the sampled bound), whose every tested grid would be sampled whole, the scaled grid
/// alone, a few grid bounds.
fn taylor_quad_grid(t: &TaylorBound, m: &TriangleErrors, start: (u32, u32), eps: f64) -> (u32, u32) {
    let fits = |nu: u32, nv: u32| t.grid_fits(false, [nu, nv], eps, grid_bound(m, None, [nu, nv]));
    let (nu0, nv0) = start;
    if nu0 as u64 * nv0 as u64 > TAYLOR_SEARCH_CELLS {
        return start;
    }
    let at_start = grid_bound(m, Some((t, Domain::Quad)), [nu0, nv0]);
    if at_start > eps {
        return start;
    }
    let mut scale = (at_start / eps).sqrt();
    let (nu1, nv1) = loop {
        let n = |n0: u32| ((n0 as f64 * scale).ceil() as u32).clamp(1, n0);
        let (nu, nv) = (n(nu0), n(nv0));
        if (nu, nv) == start || fits(nu, nv) {
            break (nu, nv);
        }
        scale *= 1.05;
    };
    if t.samples() || !t.refines() {
        // Every grid a walk meets would be sampled whole (or, for the expansion bound, whose
        // every query must stay cheap: not searched): the scaled grid alone.
        return (nu1, nv1);
    }
    let cells = |g: (u32, u32)| g.0 as u64 * g.1 as u64;
    let mut best = (nu1, nv1);
    // The rows the walk's first column count needs: at most what beats the best (none where
    // even those do not meet the bound there).
    let first = (nu1 / 2).max(1);
    let mut rows = (cells(best) / first as u64).min(u32::MAX as u64) as u32;
    for nu in first..=nu1.saturating_mul(2) {
        if nu as u64 >= cells(best) {
            break; // one row of this many columns is no fewer cells
        }
        rows = rows.min((cells(best) / nu as u64) as u32);
        if rows == 0 || !fits(nu, rows) {
            continue;
        }
        while rows > 1 && fits(nu, rows - 1) {
            rows -= 1;
        }
        if cells((nu, rows)) < cells(best) {
            best = (nu, rows);
        }
    }
    best
}

/// The smallest uniform factor up to `start` whose `n × n` grid's Taylor bound meets `eps`
/// (bisection: the bound shrinks as `n` grows), `start` where none smaller does. A proposal
/// only, as [`taylor_quad_grid`]'s. Cost: about `log₂ start` grid bounds.
fn taylor_uniform_factor(t: &TaylorBound, m: &TriangleErrors, domain: Domain, start: f64, eps: f64) -> f64 {
    let fits = |n: u32| t.grid_fits(domain == Domain::Tri, [n, n], eps, grid_bound(m, None, [n, n]));
    let (mut lo, mut hi) = (1u32, start.max(1.0) as u32);
    if hi as u64 * hi as u64 > TAYLOR_SEARCH_CELLS {
        return start;
    }
    if !fits(hi) {
        return start;
    }
    while lo < hi {
        let mid = (lo + hi) / 2;
        if fits(mid) {
            hi = mid;
        } else {
            lo = mid + 1;
        }
    }
    hi as f64
}

/// Minimum segments for edges whose samples could otherwise coincide with another edge's:
/// two distinct curves between the same two corners need 2 (else both become the same chord),
/// a curve that starts and ends at one point needs 3.
pub fn minimum_segments(set: &SurfaceSet) -> Vec<u32> {
    let topo = &set.topology;
    let mut pairs: std::collections::HashMap<(u32, u32), u32> = Default::default();
    for e in topo.edges.iter().filter(|e| !e.collapsed) {
        let [a, b] = e.ends;
        *pairs.entry((a.min(b), a.max(b))).or_default() += 1;
    }
    topo.edges
        .iter()
        .map(|e| {
            let [a, b] = e.ends;
            if e.collapsed {
                1
            } else if a == b {
                3
            } else if pairs[&(a.min(b), a.max(b))] > 1 {
                2
            } else {
                1
            }
        })
        .collect()
}

/// Minimum interior factors `[u, v]` per patch, so that no two triangles of the output share
/// an edge by accident of coarse sampling:
/// - a quad whose opposite corners are also corners of another patch (the two halves of the
///   teacup's handle share all four) needs an interior vertex, or at factor 1 both could
///   triangulate with the same diagonal chord: 2 in both directions;
/// - a quad with a curve that starts and ends at one point (teapot_teasetorig's lid top)
///   needs 3 along that curve, or the core vertices next to its two ends coincide and both
///   ends, one vertex, connect to it twice.
pub fn minimum_interior(set: &SurfaceSet) -> Vec<[u32; 2]> {
    let mut pairs: std::collections::HashMap<(u32, u32), u32> = Default::default();
    let key = |a: u32, b: u32| (a.min(b), a.max(b));
    let corners = &set.topology.patch_corners;
    for (p, patch) in set.patches.iter().enumerate() {
        if patch.domain() == Domain::Quad {
            let c = corners[p];
            *pairs.entry(key(c[0], c[2])).or_default() += 1;
            *pairs.entry(key(c[1], c[3])).or_default() += 1;
        }
    }
    for e in &set.topology.edges {
        *pairs.entry(key(e.ends[0], e.ends[1])).or_default() += 1;
    }
    set.patches
        .iter()
        .enumerate()
        .map(|(p, patch)| {
            if patch.domain() != Domain::Quad {
                return [1, 1];
            }
            let c = corners[p];
            let shared = pairs[&key(c[0], c[2])] > 1 || pairs[&key(c[1], c[3])] > 1;
            let mut m = if shared { [2, 2] } else { [1, 1] };
            for l in 0..4 {
                let edge = &set.topology.edges[set.topology.patch_edges[p][l].edge as usize];
                if !edge.collapsed && edge.ends[0] == edge.ends[1] {
                    m[l % 2] = 3; // edges 0 and 2 run along u, 1 and 3 along v
                }
            }
            m
        })
        .collect()
}

/// One patch's a-posteriori result: its interior factors, its guaranteed bound, whether the
/// bound misses the tolerance, and its pattern's counts ([`Pattern::counts`]; zero for a
/// culled patch or a refused plan).
type Check = ([u32; 2], f64, bool, (u32, u32));

/// A patch's first pattern to check: its domain, edge segments and smallest interior.
type First = (Domain, [u32; 4], [u32; 2]);

/// The buffers of [`plan_limited`], kept from call to call so that a per-frame loop
/// allocates nothing once they have grown to the set's size.
#[derive(Debug, Default)]
pub(crate) struct Scratch {
    proposals: Vec<[f64; 4]>,
    /// Edges a round of raised proposals changed: `(edge, segments, factor)`.
    changed: Vec<(u32, u32, f32)>,
    results: Vec<Check>,
    rechecked: Vec<Check>,
    which: Vec<usize>,
    failing: Vec<usize>,
    firsts: Vec<First>,
    counts: Vec<u64>,
    per_patch: Vec<AtomicU64>,
    /// The first patterns of a round of checks, each distinct one built once; the later
    /// rounds' added to the first's.
    patterns: crate::pattern::cache::PatternCache,
    /// `patterns` holds the last plan's patterns, not yet handed to the engine
    /// ([`Scratch::take_patterns`]).
    patterns_fresh: bool,
    /// The last plan's pattern counts per patch ([`Scratch::plan_counts`]), valid while
    /// `counts_fresh`.
    plan_counts: Vec<(u32, u32)>,
    counts_fresh: bool,
    /// The last plan's inner samples per edge ([`Scratch::edge_counts`]), valid while
    /// `edge_counts_fresh`.
    edge_counts: Vec<u32>,
    edge_counts_fresh: bool,
    /// Per run of the last check ([`CHECK_RUN`] patches), how many missed their bound.
    misses: Vec<u32>,
}

impl Scratch {
    /// The patterns the last plan's check built, for the engine to write that plan with
    /// (most patches keep their first pattern, so the engine would build most of them again:
    /// on `catmark_rook` × 16 at half a pixel, 10,152 distinct patterns of 13 million
    /// triangles, built twice a frame). None when the check built none, or after the first
    /// call. The caller may leave other patterns in their place (its own, to be cleared by
    /// the next check).
    pub(crate) fn take_patterns(&mut self) -> Option<&mut crate::pattern::cache::PatternCache> {
        std::mem::take(&mut self.patterns_fresh).then_some(&mut self.patterns)
    }

    /// Marks the patterns and counts as no plan's: a plan made without the check must not
    /// hand the engine an earlier plan's.
    pub(crate) fn forget_patterns(&mut self) {
        self.patterns_fresh = false;
        self.counts_fresh = false;
        self.edge_counts_fresh = false;
    }

    /// The last plan's [`Pattern::counts`] of every patch (zero for culled ones), as its
    /// check found them with each patch's final pattern: the layout's per-patch counts,
    /// which it need not find again (issue 26's fusion of the check and the counts). None
    /// when the last plan was not made by the check.
    pub(crate) fn plan_counts(&self) -> Option<&[(u32, u32)]> {
        self.counts_fresh.then_some(&self.plan_counts[..])
    }

    /// The last plan's inner samples of every edge in the output
    /// ([`crate::topology::Topology::edge_samples`]), counted as its edges were resolved: the
    /// layout's per-edge counts, which it need not find again. None when the last plan was
    /// not made by the check, or had one interior for the whole mesh.
    pub(crate) fn edge_counts(&self) -> Option<&[u32]> {
        self.edge_counts_fresh.then_some(&self.edge_counts[..])
    }

    /// How many distinct patterns the check's table holds (0 when the last check built none).
    #[cfg(test)]
    pub(crate) fn held_patterns(&self) -> usize {
        self.patterns.distinct()
    }
}

/// Builds a plan that meets `eps[p]` on every patch with `Some` tolerance (`None` = culled),
/// for `pattern` with the scheme's `rule` and `interior` rule, factors capped at `max_factor`
/// (a power of two for [`EdgeRule::PowerOfTwo`]), for an output of at most `max_triangles`,
/// into `plan` (its buffers reused). With `taylor` (one per patch, [`TaylorBound::of`]) every
/// proposal and check also takes the Taylor bound, and a triangle's bound is the smaller. [`crate::scheme::Scheme::plan`] is the public door: it
/// pairs the pattern with its rules.
///
/// Before each round of a-posteriori checks (which build patterns), the output the current
/// factors give is counted, and a plan that would exceed the limit is refused with
/// [`Error::OutputTooLarge`] instead of building patterns of that size; a single patch whose
/// check would build more than `max_triangles` stops refining and counts as capped.
/// Cost: O(P) proposals from the prepared bounds plus one pattern build per patch and round
/// for the a-posteriori check, and O(P) pattern counts per round; no allocation once
/// `scratch` and `plan` have grown to the set.
#[allow(clippy::too_many_arguments)]
pub(crate) fn plan_limited(
    set: &SurfaceSet,
    prepared: &Prepared,
    eps: &[Option<f64>],
    rule: EdgeRule,
    interior: InteriorRule,
    pattern: &dyn Pattern,
    max_factor: u32,
    max_triangles: u64,
    taylor: Option<&[TaylorBound]>,
    scratch: &mut Scratch,
    plan: &mut Plan,
) -> Result<BoundReport> {
    let cap = max_factor.max(1);
    let topo = &set.topology;
    let patches = set.patches.len();
    let (computed_hessians, computed_curves);
    let hessians: &[HessianBound] = if prepared.hessians.len() == patches {
        &prepared.hessians
    } else {
        computed_hessians = set.patches.par_iter().map(bounds::hessian).collect::<Vec<_>>();
        &computed_hessians
    };
    let computed_errors;
    let errors: &[TriangleErrors] = if prepared.hessians.len() == patches {
        prepared.triangle_errors()
    } else {
        computed_errors = hessians.par_iter().map(|h| h.triangle_errors()).collect::<Vec<_>>();
        &computed_errors
    };
    let curves: &[[f64; 4]] = if prepared.curves.len() == patches {
        &prepared.curves
    } else {
        computed_curves = curve_bounds(set, hessians);
        &computed_curves
    };
    let mut report = BoundReport::default();
    let Scratch {
        proposals,
        changed,
        results,
        rechecked,
        which,
        failing,
        firsts,
        counts,
        per_patch,
        patterns,
        patterns_fresh,
        plan_counts,
        counts_fresh,
        edge_counts,
        edge_counts_fresh,
        misses,
    } = scratch;
    *patterns_fresh = false;
    *counts_fresh = false;
    *edge_counts_fresh = false;

    // Each visible patch's proposal per local edge, and the plan's visibility row (a pass of
    // its own, over the tolerances again, was 20–50 µs on the torus grid).
    proposals.resize(patches, [0.0; 4]);
    plan.visible.resize(patches, 0);
    super::rows::fill_pairs(
        proposals,
        &mut plan.visible,
        #[inline(always)]
        |p, out, visible| {
            *visible = u32::from(eps[p].is_some());
            // A culled patch wishes nothing, and says so by its sign ([`resolve::CULLED`]).
            let Some(e) = eps[p] else {
                *out = [resolve::CULLED; 4];
                return;
            };
            *out = [0.0; 4];
            let domain = set.topology.patch_domains[p];
            let m = &hessians[p];
            let taylor = taylor.map(|t| &t[p]).filter(|t| t.is_some());
            match (interior, domain) {
                (InteriorRule::Core, Domain::Quad) => {
                    let mut grid = quad_grid(m, e, cap).unwrap_or((cap, cap));
                    if let Some(t) = taylor {
                        grid = taylor_quad_grid(t, &errors[p], grid, e);
                    }
                    let (nu, nv) = grid;
                    *out = [nu as f64, nv as f64, nu as f64, nv as f64];
                }
                _ => {
                    let mut n = uniform_factor(m, e);
                    if let Some(t) = taylor {
                        n = taylor_uniform_factor(t, &errors[p], domain, n.min(cap as f64), e);
                    }
                    out[..domain.corner_count()].fill(n);
                }
            }
            for (l, o) in out.iter_mut().enumerate().take(domain.corner_count()) {
                *o = o.max(curve_factor(curves[p][l], e));
            }
        },
    );

    let caps = prepared.caps(cap as f64);
    let minimum_inner = &prepared.minimum_interior;
    plan.kind = crate::sampling::SamplingKind::Uniform;
    plan.depths.clear();
    plan.lattice_offsets.clear();
    plan.lattice.clear();
    // The layout's edge counts with the edges (one walk over their uses), except where one
    // interior is the whole mesh's.
    let counted = interior != InteriorRule::Global;
    if counted {
        let rows = (&mut plan.segments, &mut plan.factors, &mut *edge_counts);
        resolve::edges_counted(set, proposals, rule, &caps, &plan.visible, rows.0, rows.1, rows.2);
    } else {
        resolve::edges(set, proposals, rule, interior, &caps, &mut plan.segments, &mut plan.factors);
    }
    if per_patch.len() != patches {
        per_patch.clear();
        per_patch.extend((0..patches).map(|_| AtomicU64::new(0)));
    }
    let limit = Limit::new(pattern, max_triangles, per_patch);
    if !limit.unlimited() {
        // Only a limit reads them (`Limit::admit`, `Limit::reserve`).
        limit.per_patch.par_iter().for_each(|c| c.store(0, Ordering::Relaxed));
    }
    let mut check = |segments: &[u32],
                     proposals: &[[f64; 4]],
                     which: Patches<'_>,
                     (out, misses): (&mut Vec<Check>, &mut Vec<u32>),
                     keep| {
        let inputs = CheckInputs { set, eps, layout: interior, cap, minimum: minimum_inner, errors, taylor };
        let rows = (&mut *firsts, &mut *counts, &mut *patterns);
        check_patches(&inputs, &limit, proposals, segments, which, rows, keep, out, misses)
    };
    *patterns_fresh = check(&plan.segments, proposals, Patches::All(patches), (results, misses), false);
    // The failing patches: those of the first check's runs that missed, then after each
    // round those of the patches it checked again (every failing patch is among them, and
    // no other result changed). In patch order.
    failing.clear();
    for (run, _) in misses.iter().enumerate().filter(|&(_, &m)| m > 0) {
        let run = run * CHECK_RUN..((run + 1) * CHECK_RUN).min(patches);
        failing.extend(run.filter(|&p| results[p].2));
    }
    // A patch whose bound the interior alone cannot meet (its strip triangles follow coarse
    // edges) asks for finer edges; the maximum rule keeps them consistent. That can move the
    // problem to a neighbour, so repeat, re-checking only the patches whose edges changed.
    // Errors shrink as h², hence the square root.
    for _round in 0..256 {
        // (Sorted and distinct, all failing and as many as there are: every failing patch.)
        debug_assert!(
            failing.windows(2).all(|w| w[0] < w[1])
                && failing.iter().all(|&p| results[p].2)
                && failing.len() == results.iter().filter(|r| r.2).count()
        );
        if failing.is_empty() || interior == InteriorRule::Global {
            break;
        }
        for &p in failing.iter() {
            let (e, bound) = (eps[p].unwrap_or(f64::INFINITY), results[p].1);
            let grow = (bound / e).sqrt().max(1.2);
            for v in proposals[p].iter_mut() {
                *v = (*v * grow).ceil().min(cap as f64);
            }
        }
        // Only the failing patches' proposals changed: only their edges are resolved again.
        changed.clear();
        let now = (&plan.segments[..], &plan.factors[..]);
        resolve::update_edges(set, proposals, rule, &caps, failing, now, changed);
        // The patches to check again: the failing ones and every user of a changed edge.
        which.clear();
        which.extend_from_slice(failing);
        let mut any = false;
        for &(e, s, _) in changed.iter() {
            if plan.segments[e as usize] != s {
                any = true;
                which.extend(topo.edge_uses(e as usize).iter().map(|u| u.patch as usize));
            }
        }
        which.sort_unstable();
        which.dedup();
        if !any {
            break; // every failing patch is at the cap
        }
        for &(e, s, f) in changed.iter() {
            let e = e as usize;
            (plan.segments[e], plan.factors[e]) = (s, f);
            if counted {
                edge_counts[e] = topo.edge_samples(e, topo.edge_seen(e, &plan.visible), s);
            }
        }
        report.rounds += 1;
        check(&plan.segments, proposals, Patches::Listed(which), (rechecked, misses), true);
        for (i, &p) in which.iter().enumerate() {
            results[p] = rechecked[i];
        }
        failing.clear();
        failing.extend(which.iter().copied().filter(|&p| results[p].2));
    }
    limit.result()?;
    // The plan's interiors, the counts and the report's figures in one parallel pass (the
    // largest of bounds is the same in any order). Writing them in the check's runs instead,
    // while the results were at hand, made the check as much slower as this pass takes.
    plan.interior.resize(patches, [0; 2]);
    plan_counts.resize(patches, (0, 0));
    let rows = plan.interior.par_iter_mut().zip(plan_counts.par_iter_mut()).zip(results.par_iter()).zip(eps);
    let (worst_bound, worst_ratio, capped, culled) = rows
        .map(|(((interior, counts), r), e)| {
            (*interior, *counts) = (r.0, r.3);
            match e {
                Some(e) => (r.1, r.1 / e, usize::from(r.2), 0),
                None => (0.0, 0.0, 0, 1),
            }
        })
        .reduce(|| (0.0, 0.0, 0, 0), |a, b| (a.0.max(b.0), a.1.max(b.1), a.2 + b.2, a.3 + b.3));
    (report.worst_bound, report.worst_ratio) = (worst_bound, worst_ratio);
    (report.capped_patches, report.culled) = (capped, culled);
    // The check's inputs carry the segments as their factors: the engine's, except under a
    // fractional rule, whose patterns read the real factors.
    *counts_fresh = !matches!(rule, EdgeRule::Fractional(_));
    *edge_counts_fresh = counted;
    Ok(report)
}

/// The boundary curves' second-derivative bounds per patch and local edge
/// ([`bounds::curve_second_derivative`]), view-independent: a curve needs `sqrt(M / 8ε)` segments on its own.
/// A Loop patch's boundary is the sides of its quartic leaves along it (a regular patch: one
/// quartic curve; [`bounds::loop_tree_curve_bounds`]). `hessians` are the patches' own bounds
/// ([`bounds::hessian`], one per patch): a Catmull-Clark patch's piecewise boundary is
/// bounded by them, computed once rather than per edge.
/// Cost: O(P).
pub fn curve_bounds(set: &SurfaceSet, hessians: &[HessianBound]) -> Vec<[f64; 4]> {
    debug_assert_eq!(hessians.len(), set.patches.len());
    set.patches.par_iter().zip(hessians).map(|(patch, h)| patch_curve_bounds(patch, h)).collect()
}

/// [`curve_bounds`] of one patch, whose own bound is `h`. Cost: O(1) for a net, O(leaves)
/// for a Loop tree.
pub fn patch_curve_bounds(patch: &Patch, h: &HessianBound) -> [f64; 4] {
    match patch {
        // The quartic leaves (a regular patch's one) along each edge.
        Patch::Loop(tree) => {
            let [a, b, c] = bounds::loop_tree_curve_bounds(tree);
            return [a, b, c, 0.0];
        }
        // The cubic sides of the leaves along each edge.
        Patch::Subdivision(tree) => return bounds::tree_curve_bounds(tree),
        _ => {}
    }
    let mut out = [0.0; 4];
    for (l, o) in out.iter_mut().enumerate().take(patch.domain().corner_count()) {
        *o = match edge_control_points(patch, l) {
            Some((points, weights)) => bounds::curve_second_derivative(points, weights),
            // A piecewise boundary: the patch's own bound along the edge's direction
            // bounds the curve's second derivative. A quad's edges 0 and 2 run along
            // u; a triangle's edge 0 along u, edge 2 along v and edge 1 along
            // (−1, 1), where |S_uu − 2 S_uv + S_vv| ≤ uu + 2 uv + vv.
            None => match (patch.domain(), l) {
                (Domain::Quad, 0 | 2) | (Domain::Tri, 0) => h.uu,
                (Domain::Tri, 1) => h.uu + 2.0 * h.uv + h.vv,
                _ => h.vv,
            },
        };
    }
    out
}

/// The output budget of [`plan_limited`]: the triangles of each patch's latest checked
/// pattern, counted (O(1)) before the pattern is built, so that no check builds a pattern the
/// output could not hold.
struct Limit<'a> {
    pattern: &'a dyn Pattern,
    max_triangles: u64,
    used: AtomicU64,
    per_patch: &'a [AtomicU64],
    /// The total a refused check would have reached (0: none refused).
    exceeded: AtomicU64,
}

impl<'a> Limit<'a> {
    /// A budget over `per_patch` (one zeroed counter per patch).
    fn new(pattern: &'a dyn Pattern, max_triangles: u64, per_patch: &'a [AtomicU64]) -> Self {
        Limit { pattern, max_triangles, used: AtomicU64::new(0), per_patch, exceeded: AtomicU64::new(0) }
    }

    /// No limit: nothing to count (the default of a per-frame loop).
    fn unlimited(&self) -> bool {
        self.max_triangles == u64::MAX
    }

    /// Whether patch `p` may build a pattern of `input`; records its count if so.
    fn admit(&self, p: usize, input: &PatternInput) -> bool {
        if self.unlimited() {
            return true;
        }
        let t = self.pattern.counts(input).1 as u64;
        let previous = self.per_patch[p].load(Ordering::Relaxed);
        if t == previous {
            // Already counted (the first pattern, reserved with its neighbours): the shared
            // total would not change, and leaving it alone spares a contended atomic a patch.
            return true;
        }
        let update = self.used.fetch_update(Ordering::SeqCst, Ordering::SeqCst, |u| {
            let n = u - previous + t;
            (n <= self.max_triangles).then_some(n)
        });
        match update {
            Ok(_) => {
                self.per_patch[p].store(t, Ordering::Relaxed);
                true
            }
            Err(u) => {
                self.exceeded.fetch_max(u - previous + t, Ordering::SeqCst);
                false
            }
        }
    }

    /// [`Limit::admit`] for the patches of `which` at once (`counts[i]` the triangles of
    /// `which[i]`'s pattern, 0 for culled patches; not read without a limit), all or none:
    /// when their patterns together would exceed the limit, the whole total is what the
    /// refusal reports.
    fn reserve(&self, which: Patches<'_>, counts: &[u64]) -> bool {
        if self.unlimited() {
            return true;
        }
        let add: u64 = counts.iter().sum();
        let remove: u64 = (0..which.len()).map(|i| self.per_patch[which.at(i)].load(Ordering::Relaxed)).sum();
        let update = self.used.fetch_update(Ordering::SeqCst, Ordering::SeqCst, |u| {
            let n = u - remove + add;
            (n <= self.max_triangles).then_some(n)
        });
        match update {
            Ok(_) => {
                for (i, &t) in counts.iter().enumerate() {
                    self.per_patch[which.at(i)].store(t, Ordering::Relaxed);
                }
                true
            }
            Err(u) => {
                self.exceeded.fetch_max(u - remove + add, Ordering::SeqCst);
                false
            }
        }
    }

    fn result(&self) -> Result<()> {
        match self.exceeded.load(Ordering::SeqCst) {
            0 => Ok(()),
            triangles => Err(Error::OutputTooLarge {
                vertices: triangles / 2,
                triangles,
                bytes: crate::mesh::output_bytes(triangles / 2, triangles, false),
            }),
        }
    }
}

/// What [`check_patches`] reads that does not change between rounds.
struct CheckInputs<'a> {
    set: &'a SurfaceSet,
    eps: &'a [Option<f64>],
    layout: InteriorRule,
    cap: u32,
    minimum: &'a [[u32; 2]],
    errors: &'a [TriangleErrors],
    taylor: Option<&'a [TaylorBound]>,
}

/// The patches [`check_patches`] checks as one task (each asks its thread's pattern table
/// once), and counts the misses of.
const CHECK_RUN: usize = 64;

/// The patches a check runs over: every patch of the set in order (a plan's first check), or
/// a sorted list of them (a round's re-checks).
#[derive(Clone, Copy)]
enum Patches<'a> {
    All(usize),
    Listed(&'a [usize]),
}

impl Patches<'_> {
    fn len(self) -> usize {
        match self {
            Patches::All(n) => n,
            Patches::Listed(list) => list.len(),
        }
    }

    /// The `i`-th patch.
    #[inline(always)]
    fn at(self, i: usize) -> usize {
        match self {
            Patches::All(_) => i,
            Patches::Listed(list) => list[i],
        }
    }
}

/// Interior factors for every patch and the a-posteriori check: the interior is raised until
/// the pattern's own triangles meet the bound (interior vertices are private, so this never
/// opens a crack), growing like the square root of the excess since errors shrink as h².
/// Writes, for each patch of `which`, (interior, guaranteed bound, bound not met) into `out`
/// (`firsts` and `counts` are its buffers), and how many of each run of [`CHECK_RUN`]
/// patches of `which` miss their bound into `misses`. The first patterns go into `patterns`
/// (after the ones it holds, with `keep`); returns whether they did.
#[allow(clippy::too_many_arguments)]
fn check_patches(
    inputs: &CheckInputs<'_>,
    limit: &Limit,
    proposals: &[[f64; 4]],
    segments: &[u32],
    which: Patches<'_>,
    (firsts, counts, patterns): (&mut Vec<First>, &mut Vec<u64>, &mut crate::pattern::cache::PatternCache),
    keep: bool,
    out: &mut Vec<Check>,
    misses: &mut Vec<u32>,
) -> bool {
    let CheckInputs { set, eps, layout, cap, minimum, errors, taylor } = *inputs;
    let topo = &set.topology;
    // Only the global rule reads it (a pass over every edge on one thread).
    let global = match layout {
        InteriorRule::Global => segments.iter().copied().max().unwrap_or(1),
        _ => 1,
    };
    // The engine's input, collapsed edges included, so the bound is that of the output.
    let input_of = |p: usize, domain, segments, interior| PatternInput {
        collapsed: set.topology.collapsed_sides(p),
        pinched: set.topology.pinched_corners(p),
        ..PatternInput::new(domain, segments, interior)
    };
    // Each patch's first pattern: its edges and the smallest interior the layout gives it.
    let first = |p: usize| {
        let domain = set.topology.patch_domains[p];
        let nc = domain.corner_count();
        let mut seg = [1u32; 4];
        for (l, s) in seg.iter_mut().enumerate().take(nc) {
            *s = segments[topo.patch_edges[p][l].edge as usize];
        }
        let mut interior = match (layout, domain) {
            (InteriorRule::Global, _) => [global, global],
            (InteriorRule::Core, Domain::Quad) => {
                // The patch's own grid is enough for the core; CudaTess's min of the two
                // edges is never smaller, and neighbours' finer needs reach the core
                // through the transition strips instead of refining the whole patch.
                let own = |l: usize| (proposals[p][l].min(cap as f64) as u32).max(1);
                [own(0).min(seg[0].min(seg[2])), own(1).min(seg[1].min(seg[3]))]
            }
            (InteriorRule::Core, Domain::Tri) | (InteriorRule::Level | InteriorRule::MaxEdge, _) => {
                let n = seg[..nc].iter().copied().max().unwrap_or(1);
                [n, n]
            }
        };
        match layout {
            InteriorRule::Core | InteriorRule::MaxEdge => {
                interior = [interior[0].max(minimum[p][0]), interior[1].max(minimum[p][1])];
            }
            InteriorRule::Level => {
                let n = interior[0].max(minimum[p][0]).max(minimum[p][1]).next_power_of_two().min(cap);
                interior = [n, n];
            }
            InteriorRule::Global => {}
        }
        (domain, seg, interior)
    };
    let n = which.len();
    // Interiors only grow, so the first patterns' triangles are a lower bound of the output:
    // count them all before building any, and build nothing when they already exceed the limit.
    // (Found in a pass of their own: found in the check's runs instead, a run's at a time
    // before its checks, the check took as long: the loads of the edges' segments cost the
    // same wherever they are.)
    firsts.resize(n, (Domain::Quad, [1; 4], [1; 2]));
    if limit.unlimited() {
        // Nothing to count: no row of zeros (8 bytes a patch) written for nothing.
        super::rows::fill(
            firsts,
            #[inline(always)]
            |i, f| *f = first(which.at(i)),
        );
    } else {
        counts.resize(n, 0);
        super::rows::fill_pairs(
            firsts,
            counts,
            #[inline(always)]
            |i, f, c| {
                let p = which.at(i);
                *f = first(p);
                *c = match eps[p] {
                    Some(_) => limit.pattern.counts(&input_of(p, f.0, f.1, f.2)).1 as u64,
                    None => 0,
                };
            },
        );
    }
    let admitted = limit.reserve(which, counts);
    // The first patterns (admitted by the reservation above) are built once per distinct
    // input, with their local-vertex parameters: neighbours share inputs, and most patches
    // pass on their first pattern. Later rounds of a patch build on the thread instead.
    // Tiny patterns (a cell or two, as in a distant view) cost about what a lookup costs, and
    // the lookups run on one thread: there each task reuses its last pattern instead.
    let cells: u64 = firsts.par_iter().map(|f| f.2[0] as u64 * f.2[1] as u64).sum();
    let worth = cells >= crate::pattern::cache::MIN_TRIANGLES_PER_PATCH as u64 / 2 * n as u64;
    let filled = admitted && worth && !limit.pattern.depends_on_patch();
    if filled {
        let first_input = |i: usize| {
            let (p, (domain, seg, interior)) = (which.at(i), firsts[i]);
            eps[p].map(|_| input_of(p, domain, seg, interior))
        };
        if keep {
            patterns.extend_inputs(limit.pattern, n, first_input, true);
        } else {
            patterns.fill_inputs(limit.pattern, n, first_input, true);
        }
    } else if keep {
        patterns.forget_items();
    } else {
        patterns.clear();
    }
    let patterns = &*patterns;
    // Each thread's pattern buffers are kept from call to call (a per-frame loop then
    // allocates none here).
    let generation = crate::pattern::cache::next_generation();
    out.resize(n, ([1; 2], 0.0, false, (0, 0)));
    // One patch's check: its first pattern, then larger interiors until the bound is met,
    // the cap is reached or the bound stops shrinking. `table` is the thread's pattern-shape
    // table (`i` the patch's place in `which`).
    let check_one = |i: usize, p: usize, (domain, seg, first): First, table: &mut PatternShapes| -> Check {
        let mut interior = first;
        if !admitted {
            return (interior, f64::INFINITY, true, (0, 0));
        }
        let Some(e) = eps[p] else { return (interior, 0.0, false, (0, 0)) };
        let mut previous = f64::INFINITY;
        loop {
            let input = input_of(p, domain, seg, interior);
            if !limit.admit(p, &input) {
                // The output could not hold this pattern; the plan is refused at the end.
                return (interior, f64::INFINITY, true, (0, 0));
            }
            let taylor = taylor.map(|t| (&t[p], domain)).filter(|t| t.0.is_some());
            let cached = || patterns.params(i).filter(|_| interior == first);
            // A small or repeated pattern's data, kept per pattern: a grid's cells, or the
            // shapes of its triangles (not with a Taylor bound, which needs their places).
            let small = match taylor {
                Some(_) => None,
                None => table.get(generation, limit.pattern, &input, cached).map(|data| {
                    let bound = match data.grid {
                        Some(cells) => grid_bound(&errors[p], None, cells),
                        None => {
                            let core = core_bound(&errors[p], None, data.core);
                            shapes_bound(&errors[p], data.shapes.iter().copied(), core)
                        }
                    };
                    (bound, data.counts)
                }),
            };
            let counts = || small.map_or_else(|| limit.pattern.counts(&input), |s| s.1);
            let bound = match small {
                Some((bound, _)) => bound,
                None => {
                    match (limit.pattern.grid_cells(&input), cached()) {
                        // A pure grid (no strips): bounded from its cells, no build.
                        (Some(cells), _) => grid_bound(&errors[p], taylor, cells),
                        (None, Some((cached, params, _))) => {
                            let core = limit.pattern.core_cells(&input);
                            // The cache leaves out the triangles of a core grid.
                            let rest = match cached.core {
                                Some(_) => &cached.local.triangles[..],
                                None => after_core(core, &cached.local.triangles),
                            };
                            core_params_bound(&errors[p], taylor, core, rest, params)
                        }
                        // Neighbouring patches often share an input: the thread's last
                        // pattern is reused when it is the same.
                        (None, None) => crate::pattern::cache::with_recent_patterns(|recent| {
                            let slot = recent.get(generation, limit.pattern, &input, true);
                            let core = limit.pattern.core_cells(&input);
                            let rest = after_core(core, &slot.local.triangles);
                            core_params_bound(&errors[p], taylor, core, rest, slot.params())
                        }),
                    }
                }
            };
            if bound <= e * (1.0 + 1e-9) {
                return (interior, bound, false, counts());
            }
            // No progress means the worst triangles follow the edges, not the core.
            let stuck = bound >= previous * (1.0 - 1e-9);
            if layout == InteriorRule::Global || interior[0].max(interior[1]) >= cap || stuck {
                return (interior, bound, true, counts());
            }
            previous = bound;
            let grow = (bound / e).sqrt().max(1.05);
            interior = interior.map(|n| ((n as f64 * grow).ceil() as u32).clamp(n + 1, cap));
            if layout == InteriorRule::Level {
                interior = interior.map(|n| n.next_power_of_two().min(cap));
            }
        }
    };
    // In runs of patches, so that a run asks for its thread's pattern table once (a
    // thread-local borrow per patch was 2–3 % of the torus grid's frame). Short runs: the
    // torus's 2,048 patches at 0.001 % made 8 runs of 256 of unequal cost, and one thread
    // idled at the end (the runs' part 233 → 187 µs on two threads with runs of 64).
    const RUN: usize = CHECK_RUN;
    const ERRORS_LEAD: usize = 8;
    // How many patches of each run miss their bound: the rounds look for them only in the
    // runs that have some (a search of every patch's result was one thread's pass).
    misses.resize(n.div_ceil(RUN), 0);
    let runs = out.par_chunks_mut(RUN).zip(firsts.par_chunks(RUN)).zip(misses.par_iter_mut());
    runs.enumerate().for_each(|(run, ((outs, run_firsts), misses))| {
        let (start, len) = (run * RUN, outs.len());
        *misses = super::pattern_shapes::with_pattern_shapes(|table| {
            let mut missed = 0;
            for (k, (o, &f)) in outs.iter_mut().zip(run_firsts).enumerate() {
                // The bound's data of a patch a few ahead, asked for in time (96 bytes a
                // patch: the grid's 8.8 MB are past the core's own cache, and the patches
                // in view come in runs between culled ones, which the check skips).
                if k + ERRORS_LEAD < len {
                    if let Some(ahead) = errors.get(which.at(start + k + ERRORS_LEAD)) {
                        crate::surface::patch_tree::prefetch_slice(std::slice::from_ref(ahead));
                    }
                }
                *o = check_one(start + k, which.at(start + k), f, table);
                missed += u32::from(o.2);
            }
            missed
        });
    });
    filled
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tolerances_parse_as_distances_or_shares_of_the_diagonal() {
        assert_eq!(parse_tolerance("0.5", 10.0).unwrap(), 0.5);
        assert!((parse_tolerance("0.1%", 200.0).unwrap() - 0.2).abs() < 1e-15);
        assert!((parse_tolerance(" 2 % ", 50.0).unwrap() - 1.0).abs() < 1e-15);
        for bad in ["", "%", "x", "-1", "0", "nan", "inf", "1e400%"] {
            let e = parse_tolerance(bad, 1.0).unwrap_err();
            assert!(
                matches!(&e, Error::InvalidParameter { name: "tolerance", reason } if reason.starts_with(bad)),
                "{bad:?}: {e}"
            );
        }
    }

    /// The short cut for one segment gives the whole expression's bits: quotients just below,
    /// at and just above 1 (where rounding could land either side), zero, huge and tiny
    /// values, infinities and NaN; and the table's reciprocals are the divisions'.
    #[test]
    fn at_least_one_root_and_reciprocal_are_the_divisions_bit_for_bit() {
        let whole = |m: f64, d: f64| ceil((m / d).sqrt()).max(1.0);
        let mut values = vec![0.0, -0.0, 1e-300, 5e-324, 1e300, f64::MAX, f64::INFINITY, f64::NAN, -1.0];
        let mut x = 1e-12;
        while x < 1e12 {
            values.push(x);
            x *= 1.37;
        }
        let mut pairs = 0;
        for &d in &values {
            for &m in &values {
                assert_eq!(at_least_one_root(m, d).to_bits(), whole(m, d).to_bits(), "{m} / {d}");
                pairs += 1;
            }
            // Around m = d, a few ulps either way, and around the squares of 2 and 3 (for
            // positive finite centres, whose neighbours' bits are theirs ± k).
            for scale in [1.0, 4.0, 9.0] {
                let centre = d * scale;
                if !(centre > 0.0 && centre.is_finite()) {
                    continue;
                }
                for k in -4i64..=4 {
                    let m = f64::from_bits((centre.to_bits() as i64 + k).max(0) as u64);
                    assert_eq!(at_least_one_root(m, d).to_bits(), whole(m, d).to_bits(), "{m} / {d}");
                    pairs += 1;
                }
            }
        }
        assert!(pairs > 10_000);
        for n in 0..200u32 {
            assert_eq!(reciprocal(n).to_bits(), (1.0 / n as f64).to_bits(), "{n}");
        }
    }

    #[test]
    fn ceil_is_the_library_ceil_bit_for_bit() {
        let mut rng = crate::test_support::Lcg(11);
        let special = [
            0.0,
            -0.0,
            1.0,
            0.5,
            1e-300,
            4.9e-324,
            2f64.powi(52) - 0.5,
            2f64.powi(52),
            2f64.powi(53) + 2.0,
            1.8e19,
            1.79e19,
            9.2e18,
            9.19e18,
            2f64.powi(63),
            2f64.powi(63) - 1024.0,
            2f64.powi(64),
            -0.5,
            -3.0,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
            7.000000000000001,
        ];
        let random = (0..20_000).map(|_| {
            let r = rng.unit();
            10f64.powf(40.0 * rng.unit() - 20.0) * if r < 0.1 { -1.0 } else { 1.0 }
        });
        for x in special.into_iter().chain(random) {
            assert_eq!(ceil(x).to_bits(), x.ceil().to_bits(), "{x:e}");
        }
        for k in 0..5000u32 {
            let x = k as f64 / 7.0;
            assert_eq!(ceil(x).to_bits(), x.ceil().to_bits(), "{x}");
        }
    }

    #[test]
    fn quad_grid_meets_filip_with_few_cells() {
        let m = HessianBound { uu: 10.0, uv: 1.0, vv: 0.1 };
        let eps = 1e-3;
        let (nu, nv) = quad_grid(&m, eps, 1000).unwrap();
        let (hu, hv) = (1.0 / nu as f64, 1.0 / nv as f64);
        assert!((hu * hu * m.uu + 2.0 * hu * hv * m.uv + hv * hv * m.vv) / 8.0 <= eps);
        assert!(nu > nv, "anisotropic bounds give anisotropic grids: {nu}×{nv}");
        assert!(quad_grid(&m, eps, 3).is_none());
        let flat = HessianBound::default();
        assert_eq!(quad_grid(&flat, eps, 10), Some((1, 1)));
    }

    /// The search that stops early finds the grid that trying every column count finds (the
    /// search before it stopped early, kept here as the oracle), on bounds from flat to
    /// strongly anisotropic.
    #[test]
    fn quad_grid_stops_where_no_grid_can_be_smaller() {
        let every_column_count = |m: &HessianBound, eps: f64, cap: u32| {
            let mut best: Option<(u32, u32)> = None;
            for nu in 1..=cap {
                let hu = 1.0 / nu as f64;
                let (a, b, c) = (m.vv, 2.0 * m.uv * hu, m.uu * hu * hu - 8.0 * eps);
                if c > 0.0 {
                    continue;
                }
                let hv = if a > 0.0 {
                    (-b + (b * b - 4.0 * a * c).sqrt()) / (2.0 * a)
                } else if b > 0.0 {
                    -c / b
                } else {
                    1.0
                };
                if hv <= 0.0 {
                    continue;
                }
                let nv = if hv >= 1.0 { 1 } else { (1.0 / hv).ceil() as u64 };
                if nv > cap as u64 {
                    continue;
                }
                let nv = nv as u32;
                if best.is_none_or(|(bu, bv)| (nu as u64 * nv as u64) < (bu as u64 * bv as u64)) {
                    best = Some((nu, nv));
                }
                if nv == 1 {
                    break;
                }
            }
            best
        };
        let mut anisotropic = 0;
        let mut rng = crate::test_support::Lcg(7);
        let mut next = || rng.unit();
        for _ in 0..2000 {
            let scale = 10f64.powf(4.0 * next() - 2.0);
            let m = HessianBound {
                uu: scale * next(),
                uv: scale * next() * 0.3,
                vv: scale * next() * 10f64.powf(2.0 * next() - 1.0),
            };
            let eps = 10f64.powf(-4.0 * next());
            // The mixed term dominant too (the bound's quadratic form indefinite), and
            // caps past the continuous grid's minimum.
            let mixed = HessianBound { uv: scale * next() * 10f64.powf(2.0 * next()), ..m };
            for (m, cap) in [(m, 1), (m, 7), (m, 64), (m, 1000), (mixed, 64), (mixed, 1000)] {
                let m = &m;
                let found = quad_grid(m, eps, cap);
                assert_eq!(found, every_column_count(m, eps, cap), "{m:?} eps {eps} cap {cap}");
                anisotropic += usize::from(found.is_some_and(|(nu, nv)| nu > 1 && nv > 1 && nu != nv));
            }
        }
        assert!(anisotropic > 500, "the bounds reach real grids: {anisotropic}");
    }
}
