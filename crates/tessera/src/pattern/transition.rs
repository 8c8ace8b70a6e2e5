//! The transition pattern of CudaTess (Schwarz & Stamminger, "Fast GPU-based Adaptive
//! Tessellation with CUDA", paper 003, §3 "Tessellation pattern" and Fig. 3 for quads, §4 and
//! Fig. 5 for triangles): a uniform core plus Bresenham-like transition strips along the edges
//! whose segment count differs from the core's factor.
//!
//! **Core.** Quads use an `Nu × Nv` grid at `(i/Nu, j/Nv)`, triangles the `N`-fold barycentric
//! grid at `(i/N, j/N)`, triangulated exactly as [`Uniform`](super::uniform::Uniform) does.
//! Where an edge has as many segments as the core factor along it, the grid meets that edge
//! directly and its grid points there *are* the edge's samples. Where the counts differ, the
//! grid's outermost row (column) on that side is dropped, and a *transition strip* joins the
//! edge's samples to the grid line one step inside. The interior vertices are always all the
//! grid points strictly inside the domain (dropping a boundary row removes only boundary
//! points), so the interior counts are those of the uniform pattern.
//!
//! **Strips.** The core left after dropping rows is a (possibly degenerate) rectangle, resp. a
//! triangle homothetic to the domain, so every strip lies between two *parallel* lines: the
//! domain edge and the core side facing it. Its ends are the segments from each domain corner
//! to the matching core corner ("mitres"); where the neighbouring side has no strip that mitre
//! is one segment of the neighbouring edge, so the boundary still matches its sampling. Two
//! strips meeting at a corner share the mitre, so they never overlap or fold. A strip is
//! triangulated by a Bresenham-like walk along both lines: each step emits one triangle, on
//! the next outer segment or on the next inner one, whichever has its midpoint first. An
//! integer error variable, initialised from the difference of the two counts, makes the
//! choice, so the apexes are spread evenly. Every triangle then has two vertices on one of the
//! parallel lines and one on the other, so its area is positive whatever the counts.
//!
//! **Two (or more) strips meeting.** The paper (§4) runs the walk from where two regions meet
//! with the core factor increased by one, skipping the first triangle (the one on the virtual
//! segment that extends the core line to the neighbouring domain edge). We implement that
//! modification in an equivalent form, for quads as well as triangles: at each end of a strip
//! whose neighbour also has a strip, the core line is extended by one *virtual* segment for
//! the walk's decisions only, so the decisions see the full grid row (as with a single strip)
//! instead of the shortened core line stretched over the whole edge. No triangle is emitted on
//! a virtual segment, so nothing needs skipping, and the walk can start at either end. Exact
//! ties of the decision (the next outer and inner segments centred on the same spot) are
//! broken by the shorter diagonal. Measured over every criterion-style configuration with
//! factors 1..=9 (quads: edges 0–2 in 1..=9, edge 3 in {1,3,5,9}), the virtual extension
//! raised the smallest angle of 976 of 2916 quads and lowered none, and raised it for 240 of
//! 729 triangles while lowering it for 29; the mean per-triangle minimum angle rose from
//! 39.2° to 40.1° (triangles) and 20.4° to 21.1° (quads, many with very uneven edges).
//!
//! **Raised core factors.** The core can lose at most one row per strip, so a quad needs
//! `Nu ≥` (strips on edges 1 and 3) and `Nv ≥` (strips on edges 0 and 2), a triangle
//! `N ≥` (number of strips). With a factor of 1 and strips on both opposite sides (or a
//! triangle factor below its strip count) the pattern raises the factor it uses internally
//! to that minimum (re-deciding which sides need strips, since an edge that matched the old
//! factor may not match the new one). This can only happen for inputs the paper's criterion
//! (minimum per direction for quads, maximum for triangles) never produces, or where
//! collapsed edges take strips (below), and it cannot
//! cause cracks: interior vertices belong to one patch, and edges keep their sampling. A core
//! of zero width (a line or a single point) is allowed; the strips then meet along it.
//!
//! **Collapsed edges.** Where an edge's curve is collapsed to a point
//! ([`PatternInput::collapsed`]: a pole, the teapot lid's apex), the engine makes every sample
//! of the edge that point's vertex and drops the triangles that degenerate. A strip on a
//! neighbouring edge whose core line ended on such an edge (the collapsed edge matching the
//! core factor, so without a strip, and the core reaching it) would end at a sample of the
//! edge, i.e. at the point: its last triangles would join the point to several samples of
//! the neighbouring edge, slivers lying along that edge's curve, and the patch across that
//! curve, seeing the same point at its end, emits them again the other way round
//! (non-manifold edges; found by fuzzing a spindle). So a collapsed edge next to a strip gets
//! a strip of its own, even where its segments match the core: the core then stops one row
//! short of it, the neighbouring strip ends at a core corner inside the domain, and the
//! collapsed edge's strip is a fan from the point over the core line (its triangles on outer
//! segments degenerate and are dropped), the same triangles the core's row next to the edge
//! gave. On a quad the core side facing that strip keeps at least one segment (raising the
//! factor along the edge to 3 if needed): a core line there would be the inner line of both
//! neighbouring strips, which could each put the point's triangle on its first segment, one
//! from each side, the same triangle after the collapse. The edge's own sampling is left as the plan made it: sampling a collapsed curve once
//! would also end such fans, but the criteria derive the core factors from the edges (the
//! minimum per direction), so the core next to the point would lose its resolution.
//!
//! **Pinched corners.** At a corner pinched at an interior vertex of valence 2
//! ([`PatternInput::pinched`]) the two edges are another patch's two edges too, so a triangle
//! with all three vertices on them would be that patch's as well. On a quad, corners 0 and 2
//! (where a subdivision cage's patches are turned to have them) never get one: the core's
//! cell there is cut through the corner, as the uniform grid's are, and a strip along one of
//! the two edges, with none along the other, has its inner line end on that other edge, so its
//! walk takes its step on the inner line first there (a strip starting at the corner) or
//! last (one ending there) — every triangle at the corner then has a vertex of the core line
//! inside. For that, and so that no core line lies on an edge (a core of zero width along
//! edge 0 would join corner 0 to corner 3 through strip 2), a quad pinched at corner 0 or 2
//! keeps a core of at least one segment each way, raising its factors where needed as for
//! collapsed edges. The engines that do not cut pinched corners after a pattern (the GPU's)
//! then draw such patches as the CPU does; corners 1 and 3 are left to
//! [`super::cut_pinched_corners`].
//!
//! The pattern assumes uniform edge samples (`t_k = k / segments`, `SamplingKind::Uniform`):
//! its triangles have positive area for those positions.

use super::{CoreGrid, LocalTessellation, Pattern, PatternInput};
use crate::domain::Domain;
use glam::DVec2;

/// The CudaTess transition pattern: uniform core plus Bresenham-like transition strips.
///
/// Preconditions: `segments[e] ≥ 1` on every edge and `interior` factors `≥ 1` (a 0 is read
/// as 1); edge samples are uniform. Any combination is accepted; the interior factors may be
/// raised internally (see the module documentation). When every edge's segments equal the
/// core factor along it, the output is the uniform grid, identical to
/// [`Uniform`](super::uniform::Uniform) when `Nu = Nv`.
#[derive(Debug, Clone, Copy, Default)]
pub struct Transition;

/// Index bases of one patch's local numbering (corners, edge samples, interior).
#[derive(Debug, Clone, Copy)]
struct Bases {
    edge: [u32; 4],
    interior: u32,
}

impl Bases {
    fn new(input: &PatternInput) -> Self {
        let nc = input.domain.corner_count();
        let mut edge = [0; 4];
        for (e, b) in edge.iter_mut().enumerate().take(nc) {
            *b = input.edge_base(e);
        }
        Bases { edge, interior: input.interior_base() }
    }
}

/// The core grid and strips of a quad patch.
#[derive(Debug, Clone, Copy)]
struct QuadLayout {
    nu: u32,
    nv: u32,
    strip: [bool; 4],
    // Core rectangle in grid indices: [i_lo, i_hi] × [j_lo, j_hi].
    i_lo: u32,
    i_hi: u32,
    j_lo: u32,
    j_hi: u32,
}

impl QuadLayout {
    fn new(input: &PatternInput) -> Self {
        let s = input.segments;
        let mut nu = input.interior[0].max(1);
        let mut nv = input.interior[1].max(1);
        // A pinched corner 0 or 2 keeps the core a segment wide each way (module doc,
        // "Pinched corners").
        let pinched = input.pinched[0] || input.pinched[2];
        // Raising a factor can create strips on the sides that matched the old one, which can
        // require raising the other factor; both only grow (to at most 3), so this ends.
        loop {
            let mut strip = [s[0] != nu, s[1] != nv, s[2] != nu, s[3] != nv];
            strips_at_collapsed_edges(&mut strip, &input.collapsed);
            // A strip on a collapsed edge needs a core side of at least one segment facing it
            // (module doc, "Collapsed edges"); so does every side at a pinched corner.
            let c = input.collapsed;
            let keep_u = pinched || (strip[0] && c[0]) || (strip[2] && c[2]);
            let keep_v = pinched || (strip[1] && c[1]) || (strip[3] && c[3]);
            let need_u = u32::from(strip[1]) + u32::from(strip[3]) + u32::from(keep_u);
            let need_v = u32::from(strip[0]) + u32::from(strip[2]) + u32::from(keep_v);
            if nu >= need_u && nv >= need_v {
                return QuadLayout {
                    nu,
                    nv,
                    strip,
                    i_lo: u32::from(strip[3]),
                    i_hi: nu - u32::from(strip[1]),
                    j_lo: u32::from(strip[0]),
                    j_hi: nv - u32::from(strip[2]),
                };
            }
            nu = nu.max(need_u);
            nv = nv.max(need_v);
        }
    }

    /// Segments of the core side facing edge `e`.
    fn inner_segments(&self, e: usize) -> u32 {
        if e % 2 == 0 {
            self.i_hi - self.i_lo
        } else {
            self.j_hi - self.j_lo
        }
    }

    /// Grid point `t` (`0 ≤ t ≤ inner_segments(e)`) of the core side facing edge `e`, in the
    /// edge's direction.
    fn inner(&self, e: usize, t: u32) -> (u32, u32) {
        match e {
            0 => (self.i_lo + t, self.j_lo),
            1 => (self.i_hi, self.j_lo + t),
            2 => (self.i_hi - t, self.j_hi),
            _ => (self.i_lo, self.j_hi - t),
        }
    }

    /// The core rectangle, numbered by the grid rule: a point on the domain boundary lies on
    /// a side without strip, whose samples are exactly the grid points there.
    fn core(&self, input: &PatternInput) -> CoreGrid {
        CoreGrid::new(input, [self.nu, self.nv], [self.i_lo, self.j_lo], [self.i_hi, self.j_hi])
    }

    fn counts(&self, input: &PatternInput) -> (u32, u32) {
        let core = 2 * (self.i_hi - self.i_lo) * (self.j_hi - self.j_lo);
        let strips: u32 =
            (0..4).filter(|&e| self.strip[e]).map(|e| input.segments[e] + self.inner_segments(e)).sum();
        ((self.nu - 1) * (self.nv - 1), core + strips)
    }

    /// The interior vertices and the core's cells unless `strips_only` (the core grid's
    /// points are then left to [`CoreGrid::interior_points`]), then the strips.
    fn build(&self, input: &PatternInput, out: &mut LocalTessellation, strips_only: bool) {
        // Same arithmetic as the uniform pattern so the all-matching case is bit-identical.
        let (su, sv) = (1.0 / self.nu as f64, 1.0 / self.nv as f64);
        if !strips_only {
            super::core_grid::grid_interior([self.nu, self.nv], &mut out.interior);
        }
        let core = self.core(input);
        let interior = input.interior_base();
        if !strips_only {
            let start = out.triangles.len();
            out.triangles.resize(start + core.triangle_count() as usize, [0; 3]);
            core.write(interior, |l| l, out.triangles[start..].as_flattened_mut());
        }
        for e in (0..4).filter(|&e| self.strip[e]) {
            let s = input.segments[e];
            let m = self.inner_segments(e);
            let ends = StripEnds {
                lead: u32::from(self.strip[(e + 3) % 4]),
                trail: u32::from(self.strip[(e + 1) % 4]),
                pinned: pinned_ends(&self.strip, &input.pinched, e),
            };
            walk(
                s,
                m,
                ends,
                |k| (input.boundary_vertex(e, k), Domain::Quad.edge_point(e, k as f64 / s as f64)),
                |t| {
                    let (i, j) = self.inner(e, t);
                    (core.local(interior, i, j), DVec2::new(i as f64 * su, j as f64 * sv))
                },
                &mut out.triangles,
            );
        }
    }
}

/// Which ends of the strip on quad edge `e` a pinched corner pins (module doc, "Pinched
/// corners"): `[start, end]`, the start at corner `e`, the end at corner `e + 1`. A corner
/// pins a strip's end where it is corner 0 or 2, pinched, and the other edge there has no
/// strip (so the strip's inner line ends on that edge). Cost: O(1).
fn pinned_ends(strip: &[bool; 4], pinched: &[bool; 4], e: usize) -> [bool; 2] {
    let (start, end) = (e, (e + 1) % 4);
    [start % 2 == 0 && pinched[start] && !strip[(e + 3) % 4], end % 2 == 0 && pinched[end] && !strip[end]]
}

/// Gives a strip to every collapsed edge next to an edge with a strip (module doc, "Collapsed
/// edges"), for the `N` edges of a domain (`strip.len()`; neighbours cyclic). Repeated until
/// nothing changes, as a new strip can be next to another collapsed edge. Cost: O(N²).
fn strips_at_collapsed_edges<const N: usize>(strip: &mut [bool; N], collapsed: &[bool; 4]) {
    // Most patches have no collapsed edge; the loop below was 2 % of a frame of the torus grid.
    if !collapsed.contains(&true) {
        return;
    }
    for _ in 0..N {
        for e in 0..N {
            if collapsed[e] && (strip[(e + 1) % N] || strip[(e + N - 1) % N]) {
                strip[e] = true;
            }
        }
    }
}

/// The core grid and strips of a triangle patch.
#[derive(Debug, Clone, Copy)]
struct TriLayout {
    n: u32,
    strip: [bool; 3],
    // Core triangle: grid points (i, j) with i ≥ i_lo, j ≥ j_lo, i + j ≤ i_lo + j_lo + m.
    i_lo: u32,
    j_lo: u32,
    m: u32,
}

impl TriLayout {
    fn new(input: &PatternInput) -> Self {
        let s = input.segments;
        let mut n = input.interior[0].max(1);
        // As for quads: raising can add strips, so iterate (n only grows, to at most 3).
        loop {
            let mut strip = [s[0] != n, s[1] != n, s[2] != n];
            strips_at_collapsed_edges(&mut strip, &input.collapsed);
            let need = strip.iter().map(|&x| u32::from(x)).sum::<u32>();
            if n >= need {
                let i_lo = u32::from(strip[2]);
                let j_lo = u32::from(strip[0]);
                return TriLayout { n, strip, i_lo, j_lo, m: n - need };
            }
            n = need;
        }
    }

    /// Grid point `t` (`0 ≤ t ≤ m`) of the core side facing edge `e`, in the edge's direction.
    fn inner(&self, e: usize, t: u32) -> (u32, u32) {
        match e {
            0 => (self.i_lo + t, self.j_lo),
            1 => (self.i_lo + self.m - t, self.j_lo + t),
            _ => (self.i_lo, self.j_lo + self.m - t),
        }
    }

    /// Local index of grid point `(i, j)`, `i + j ≤ n` (see [`QuadLayout::local`]).
    #[inline]
    fn local(&self, b: &Bases, i: u32, j: u32) -> u32 {
        let n = self.n;
        match (i, j) {
            (0, 0) => 0,
            (i, 0) if i == n => 1,
            (0, j) if j == n => 2,
            (i, 0) => b.edge[0] + i - 1,
            (i, j) if i + j == n => b.edge[1] + j - 1,
            (0, j) => b.edge[2] + (n - j) - 1,
            (i, j) => {
                // Interior rows 1..j-1 before this one hold n-1-r points each.
                let before = (j - 1) * (n - 1) - (j - 1) * j / 2;
                b.interior + before + (i - 1)
            }
        }
    }

    fn counts(&self, input: &PatternInput) -> (u32, u32) {
        let n = self.n;
        let strips: u32 = (0..3).filter(|&e| self.strip[e]).map(|e| input.segments[e] + self.m).sum();
        ((n - 1) * n.saturating_sub(2) / 2, self.m * self.m + strips)
    }

    fn build(&self, input: &PatternInput, out: &mut LocalTessellation) {
        let b = Bases::new(input);
        let n = self.n;
        let step = 1.0 / n as f64;
        for j in 1..n {
            for i in 1..n.saturating_sub(j) {
                out.interior.push(DVec2::new(i as f64 * step, j as f64 * step));
            }
        }
        let (i0, j0, m) = (self.i_lo, self.j_lo, self.m);
        // Same loop and vertex order as the uniform pattern, shifted to the core's corner.
        for j in 0..m {
            for i in 0..m - j {
                let a = self.local(&b, i0 + i, j0 + j);
                let bb = self.local(&b, i0 + i + 1, j0 + j);
                let d = self.local(&b, i0 + i, j0 + j + 1);
                out.triangles.push([a, bb, d]);
                if i + j + 2 <= m {
                    out.triangles.push([bb, self.local(&b, i0 + i + 1, j0 + j + 1), d]);
                }
            }
        }
        for e in (0..3).filter(|&e| self.strip[e]) {
            let s = input.segments[e];
            let ends = StripEnds {
                lead: u32::from(self.strip[(e + 2) % 3]),
                trail: u32::from(self.strip[(e + 1) % 3]),
                pinned: [false; 2],
            };
            walk(
                s,
                m,
                ends,
                |k| (input.boundary_vertex(e, k), Domain::Tri.edge_point(e, k as f64 / s as f64)),
                |t| {
                    let (i, j) = self.inner(e, t);
                    (self.local(&b, i, j), DVec2::new(i as f64 * step, j as f64 * step))
                },
                &mut out.triangles,
            );
        }
    }
}

/// What a strip's walk ([`walk`]) needs to know of its two ends: the virtual segments that
/// extend its inner line where the neighbouring edge has a strip too (`lead` at its start,
/// `trail` at its end), and the ends a pinched corner pins ([`pinned_ends`]).
#[derive(Debug, Clone, Copy)]
struct StripEnds {
    lead: u32,
    trail: u32,
    pinned: [bool; 2],
}

/// Triangulates the strip between an outer line of `s ≥ 1` segments (points `outer(0..=s)`)
/// and a parallel inner line of `m ≥ 0` segments (points `inner(0..=m)`), both listed in the
/// same direction with the inner line on the left (so the triangles are counter-clockwise).
/// Points are `(local index, domain position)`; positions only break ties.
///
/// Bresenham-like: the next triangle goes on whichever of the two next segments has its
/// midpoint first, measured along the inner line extended by `lead` virtual segments before
/// its start and `trail` after its end (the paper's two-region modification). With
/// `d = (2i+1)·span − (2j'+1)·s`, `span = m + lead + trail`, `j' = j + lead`, the outer
/// midpoint `(i+½)/s` comes first iff `d < 0`; `d` starts at `span − (2·lead+1)·s` (the
/// difference of the two counts when `lead = 0`) and changes by `+2·span` or `−2·s`. Ties
/// (`d = 0`) take the shorter diagonal. `pinned` (`[start, end]`, at most one, and then
/// `m ≥ 1`) forces the first step, or the last, onto the inner line, whatever `d` says
/// (module doc, "Pinched corners"); `d` moves as for any step. Emits `s + m` triangles, each
/// with two vertices on one line and one on the other, so positive area. Cost: O(s + m).
fn walk(
    s: u32,
    m: u32,
    StripEnds { lead, trail, pinned }: StripEnds,
    outer: impl Fn(u32) -> (u32, DVec2),
    inner: impl Fn(u32) -> (u32, DVec2),
    tris: &mut Vec<[u32; 3]>,
) {
    let span = i64::from(m) + i64::from(lead) + i64::from(trail);
    let s64 = i64::from(s);
    let mut d = span - (2 * i64::from(lead) + 1) * s64;
    let (mut i, mut j) = (0u32, 0u32);
    let (mut o0, mut o1) = (outer(0), outer(1));
    let (mut n0, mut n1) = (inner(0), if m > 0 { inner(1) } else { inner(0) });
    while i < s || j < m {
        // Once a side is used up the other's steps are forced; `d` is then left alone so it
        // stays within a few times the counts (no overflow for any u32 counts).
        let advance_outer = if j == m {
            true
        } else if i == s || (pinned[0] && i == 0 && j == 0) {
            false
        } else if pinned[1] && j + 1 == m {
            // The last inner step waits until the outer line is done.
            true
        } else if d != 0 {
            d < 0
        } else {
            // Tie: the next outer and inner segments are centred on the same position, so
            // either order spreads the apexes equally; cut their quad along the shorter
            // diagonal, which gives the better-shaped pair. Equal diagonals (up to rounding):
            // inner first in the first half, outer first in the second, so a symmetric strip
            // gets a symmetric triangulation.
            let via_outer = o1.1.distance_squared(n0.1);
            let via_inner = o0.1.distance_squared(n1.1);
            if (via_outer - via_inner).abs() > 1e-9 * via_outer.max(via_inner) {
                via_outer < via_inner
            } else {
                2 * i + 1 > s
            }
        };
        if advance_outer {
            tris.push([o0.0, o1.0, n0.0]);
            i += 1;
            if j < m && i < s {
                d += 2 * span;
            }
            o0 = o1;
            if i < s {
                o1 = outer(i + 1);
            }
        } else {
            tris.push([o0.0, n1.0, n0.0]);
            j += 1;
            if j < m && i < s {
                d -= 2 * s64;
            }
            n0 = n1;
            if j < m {
                n1 = inner(j + 1);
            }
        }
    }
}

impl Pattern for Transition {
    fn name(&self) -> &'static str {
        "transition"
    }

    /// At a pinched corner 0 or 2 every triangle keeps a vertex off the corner's two edges
    /// (module doc, "Pinched corners").
    fn cut_through_corners_0_and_2(&self) -> bool {
        true
    }

    /// Interior vertex and triangle counts; O(1).
    fn counts(&self, input: &PatternInput) -> (u32, u32) {
        match input.domain {
            Domain::Quad => QuadLayout::new(input).counts(input),
            Domain::Tri => TriLayout::new(input).counts(input),
        }
    }

    /// Builds the pattern; O(vertices + triangles), no allocation beyond `out`'s growth.
    fn triangulate(&self, input: &PatternInput, out: &mut LocalTessellation) {
        out.interior.clear();
        out.triangles.clear();
        match input.domain {
            Domain::Quad => QuadLayout::new(input).build(input, out, false),
            Domain::Tri => TriLayout::new(input).build(input, out),
        }
    }

    /// The core alone when no edge has a strip (every edge cut like the core along it): the
    /// uniform grid of the core factors.
    fn grid_cells(&self, input: &PatternInput) -> Option<[u32; 2]> {
        match input.domain {
            Domain::Quad => {
                let layout = QuadLayout::new(input);
                (layout.strip == [false; 4]).then_some([layout.nu, layout.nv])
            }
            Domain::Tri => {
                let layout = TriLayout::new(input);
                (layout.strip == [false; 3]).then_some([layout.n, layout.n])
            }
        }
    }

    /// The core's cells come first in [`Pattern::build`]: two triangles per cell of the core
    /// rectangle (quads), the `m²` triangles of the core triangle (triangles).
    fn core_cells(&self, input: &PatternInput) -> Option<([u32; 2], u32)> {
        // A pinched corner's cut may reach into the core: no promise then. Corners 0 and 2
        // need no cut (module doc, "Pinched corners").
        if input.pinched[1] || input.pinched[3] {
            return None;
        }
        match input.domain {
            Domain::Quad => {
                let l = QuadLayout::new(input);
                Some(([l.nu, l.nv], 2 * (l.i_hi - l.i_lo) * (l.j_hi - l.j_lo)))
            }
            Domain::Tri => {
                let l = TriLayout::new(input);
                Some(([l.n, l.n], l.m * l.m))
            }
        }
    }

    /// Quads: the core rectangle, where [`Transition::core_cells`] promises its cells.
    fn core_grid(&self, input: &PatternInput) -> Option<CoreGrid> {
        let unpinned = !input.pinched.iter().any(|&p| p);
        (input.domain == Domain::Quad && unpinned).then(|| QuadLayout::new(input).core(input))
    }

    /// The strips alone: neither the core's cells nor its grid's points.
    fn build_after_core(&self, input: &PatternInput, out: &mut LocalTessellation) {
        if self.core_grid(input).is_none() {
            return super::build_removing_core(self, input, out);
        }
        out.interior.clear();
        out.triangles.clear();
        QuadLayout::new(input).build(input, out, true);
    }

    /// Quads: the core's grid, `(i/nu, j/nv)` row after row over every interior point (the
    /// strips add no interior vertex), with the core factors as raised for the strips.
    fn interior_grid(&self, input: &PatternInput) -> Option<[u32; 2]> {
        match input.domain {
            Domain::Quad => {
                let layout = QuadLayout::new(input);
                Some([layout.nu, layout.nv])
            }
            Domain::Tri => None,
        }
    }
}

/// Domain parameters of every local vertex of `local` (built for `input`), assuming uniform
/// edge samples `t_k = k / segments[e]`.
fn local_params(input: &PatternInput, local: &LocalTessellation) -> Vec<DVec2> {
    input.local_positions(&local.interior, |e, k| k as f64 / input.segments[e] as f64)
}

/// Minimum angle statistics of `pattern` on `input`, in degrees, measured in the `(u, v)`
/// domain with uniform edge samples: `(smallest angle of any triangle, mean over triangles of
/// each triangle's smallest angle)`. A diagnostic for comparing patterns (uniform grids give
/// 45°). Preconditions: those of `pattern`; at least one triangle. Cost: one build plus
/// O(triangles).
pub fn min_angle_stats(pattern: &dyn Pattern, input: &PatternInput) -> (f64, f64) {
    let mut local = LocalTessellation::default();
    pattern.build(input, &mut local);
    let p = local_params(input, &local);
    let mut min = f64::INFINITY;
    let mut sum = 0.0;
    for t in &local.triangles {
        let [a, b, c] = t.map(|l| p[l as usize]);
        let angle = |o: DVec2, x: DVec2, y: DVec2| (x - o).angle_to(y - o).abs().to_degrees();
        let tri_min = angle(a, b, c).min(angle(b, c, a)).min(angle(c, a, b));
        min = min.min(tri_min);
        sum += tri_min;
    }
    (min, sum / local.triangles.len() as f64)
}

#[cfg(test)]
mod tests {
    use super::super::uniform::Uniform;
    use super::*;

    /// Checks every structural property of one configuration; returns the triangle count.
    fn check(input: &PatternInput) -> usize {
        let mut out = LocalTessellation::default();
        Transition.build(input, &mut out);
        let (vi, t) = Transition.counts(input);
        assert_eq!(out.interior.len() as u32, vi, "{input:?}: interior count");
        assert_eq!(out.triangles.len() as u32, t, "{input:?}: triangle count");
        let params = local_params(input, &out);
        super::super::assert_tiles(input, &out, &params, 1e-12);
        // The promised core cells come first and are halves of grid cells.
        let (cells, count) = Transition.core_cells(input).expect("transition promises its core");
        assert!(count <= t, "{input:?}: core of {count} triangles in {t}");
        for tri in &out.triangles[..count as usize] {
            assert!(
                half_cell(tri.map(|l| params[l as usize]), cells),
                "{input:?}: {tri:?} is no half cell of {cells:?}"
            );
        }
        if let Some(grid) = Transition.grid_cells(input) {
            assert_eq!((grid, count), (cells, t), "{input:?}: a pure grid is all core");
        }
        check_core_grid(input, &out, count);
        out.triangles.len()
    }

    /// The core grid's promise ([`Pattern::core_grid`]) on the pattern `out` built for `input`
    /// with `count` core cells: its rule gives the core's triangles, in the local numbering
    /// and mapped like an engine maps them, and [`Pattern::build_after_core`] the rest.
    fn check_core_grid(input: &PatternInput, out: &LocalTessellation, count: u32) {
        let mut rest = LocalTessellation::default();
        Transition.build_after_core(input, &mut rest);
        let Some(core) = Transition.core_grid(input) else {
            assert_eq!(rest.interior, out.interior, "{input:?}: no core, the whole interior");
            assert!(
                input.domain == Domain::Tri || input.pinched.contains(&true),
                "{input:?}: a quad has a core"
            );
            assert_eq!(rest.triangles, out.triangles, "{input:?}: no core, the whole pattern");
            return;
        };
        assert_eq!(core.triangle_count(), count, "{input:?}: core_cells counts the core grid");
        assert!(rest.interior.is_empty(), "{input:?}: the core grid's points left out");
        let mut points = Vec::new();
        core.interior_points(&mut points);
        assert_eq!(points, out.interior, "{input:?}: the interior is the core grid's points");
        let (core_triangles, after) = out.triangles.split_at(count as usize);
        assert_eq!(rest.triangles, after, "{input:?}: the triangles after the core");
        let mut flat = vec![0; 3 * count as usize];
        core.write(input.interior_base(), |l| l, &mut flat);
        assert_eq!(flat, core_triangles.as_flattened(), "{input:?}: the core by its rule");
        // As a writer maps them: interior vertices moved to 1000, boundary ones through a table.
        let first = input.interior_base();
        core.write(1000, |l| 5000 + l, &mut flat);
        let mapped: Vec<u32> = core_triangles
            .as_flattened()
            .iter()
            .map(|&l| if l < first { 5000 + l } else { 1000 + l - first })
            .collect();
        assert_eq!(flat, mapped, "{input:?}: the core mapped");
    }

    /// Whether `t` is a right triangle with legs `1/cells[0]` along u and `1/cells[1]` along v.
    fn half_cell(t: [DVec2; 3], cells: [u32; 2]) -> bool {
        let h = DVec2::new(1.0 / cells[0] as f64, 1.0 / cells[1] as f64);
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-12;
        (0..3).any(|c| {
            let (a, b) = (t[(c + 1) % 3] - t[c], t[(c + 2) % 3] - t[c]);
            let legs = |u: DVec2, v: DVec2| {
                close(u.x.abs(), h.x) && close(u.y, 0.0) && close(v.x, 0.0) && close(v.y.abs(), h.y)
            };
            legs(a, b) || legs(b, a)
        })
    }

    fn quad(segments: [u32; 4], interior: [u32; 2]) -> PatternInput {
        PatternInput::new(Domain::Quad, segments, interior)
    }

    fn tri(s: [u32; 3], n: u32) -> PatternInput {
        PatternInput::new(Domain::Tri, [s[0], s[1], s[2], 1], [n, n])
    }

    #[test]
    fn triangles_tile_the_domain_for_all_small_factors() {
        for s0 in 1..=9 {
            for s1 in 1..=9 {
                for s2 in 1..=9 {
                    for n in 1..=9 {
                        check(&tri([s0, s1, s2], n));
                    }
                }
            }
        }
    }

    #[test]
    fn quads_tile_the_domain_for_all_small_factors() {
        for s0 in 1..=9 {
            for s1 in 1..=9 {
                for s2 in 1..=9 {
                    for s3 in 1..=9 {
                        for nu in 1..=9 {
                            for nv in 1..=9 {
                                check(&quad([s0, s1, s2, s3], [nu, nv]));
                            }
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn large_factors_tile_the_domain() {
        let values = [1, 2, 3, 31, 63, 64, 65, 100];
        for &a in &values {
            for &b in &values {
                for &c in &values {
                    for &n in &[1, 2, 17, 64, 100] {
                        check(&tri([a, b, c], n));
                        for &d in &[1, 64] {
                            check(&quad([a, b, c, d], [n, 64]));
                            check(&quad([d, a, b, c], [64, n]));
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn criterion_style_factors_never_raise_the_core() {
        // With the paper's choice of core factors the core is used as given.
        for s in 1..=12u32 {
            for s2 in 1..=12 {
                for s3 in 1..=12 {
                    let t = tri([s, s2, s3], s.max(s2).max(s3));
                    assert_eq!(TriLayout::new(&t).n, t.interior[0]);
                    let q = quad([s, s2, s3, s], [s.min(s3), s2.min(s)]);
                    let l = QuadLayout::new(&q);
                    assert_eq!([l.nu, l.nv], q.interior);
                }
            }
        }
    }

    #[test]
    fn raises_the_core_only_when_needed() {
        // Strips on both sides of a factor-1 direction: raised to 2, a line core.
        let l = QuadLayout::new(&quad([1, 3, 1, 5], [1, 4]));
        assert_eq!((l.nu, l.nv), (2, 4));
        assert_eq!(l.strip, [true, true, true, true]);
        let l = TriLayout::new(&tri([2, 3, 1], 1));
        assert_eq!((l.n, l.m), (2, 0));
        let l = TriLayout::new(&tri([5, 3, 4], 2));
        assert_eq!((l.n, l.m), (3, 1));
        // All three strips at factor 2: raised to 3, a single core point at the centroid.
        let l = TriLayout::new(&tri([1, 1, 1], 2));
        assert_eq!((l.n, l.m), (3, 0));
    }

    #[test]
    fn matches_uniform_when_all_factors_agree() {
        for n in 1..=20 {
            for domain in [Domain::Quad, Domain::Tri] {
                let input = PatternInput::new(domain, [n; 4], [n, n]);
                assert_eq!(Transition.counts(&input), Uniform.counts(&input));
                let (mut a, mut b) = (LocalTessellation::default(), LocalTessellation::default());
                Transition.build(&input, &mut a);
                Uniform.build(&input, &mut b);
                assert_eq!(a, b, "{domain:?} n={n}");
            }
        }
        // A uniform rectangle grid (Nu ≠ Nv) has no strips and only grid triangles.
        let input = quad([3, 5, 3, 5], [3, 5]);
        assert_eq!(Transition.counts(&input), (8, 30));
        check(&input);
    }

    #[test]
    fn a_single_strip_changes_only_its_row() {
        // Core 4×4 with edge 0 at 7 segments: 3 core rows (24 triangles) + 7 + 4 in the strip.
        let input = quad([7, 4, 4, 4], [4, 4]);
        assert_eq!(Transition.counts(&input), (9, 24 + 11));
        // Triangle core 5 with edge 1 at 3: core of size 4 (16) + 3 + 4.
        let input = tri([5, 3, 5], 5);
        assert_eq!(Transition.counts(&input), (6, 16 + 7));
    }

    /// The patch after the engine's collapse of the edges in `collapsed`: local indices with
    /// every sample and the end corners of a collapsed edge replaced by one vertex,
    /// degenerate triangles dropped. (`input.collapsed` is what the pattern was told.)
    /// Returns `Err` when a surviving triangle lies on one boundary edge (all three vertices
    /// on its closure, and not just the patch's own boundary segments: the point and samples
    /// of a neighbouring edge, a sliver that the patch across that edge emits too), uses a
    /// directed edge twice, or the boundary is not the other edges' segments.
    fn check_collapsed(input: &PatternInput, collapsed: [bool; 4]) -> Result<(), String> {
        let nc = input.domain.corner_count();
        let mut out = LocalTessellation::default();
        Transition.build(input, &mut out);
        let (_, count) = Transition.counts(input);
        assert_eq!(out.triangles.len() as u32, count, "{input:?}: triangle count");
        super::super::assert_tiles(input, &out, &local_params(input, &out), 1e-12);
        check_core_grid(input, &out, Transition.core_cells(input).map_or(0, |c| c.1));
        // Corners joined by collapsed edges are one vertex (the smallest corner index).
        let mut corner: Vec<u32> = (0..nc as u32).collect();
        for _ in 0..nc {
            for e in (0..nc).filter(|&e| collapsed[e]) {
                let m = corner[e].min(corner[(e + 1) % nc]);
                let (a, b) = (corner[e], corner[(e + 1) % nc]);
                corner.iter_mut().filter(|c| **c == a || **c == b).for_each(|c| *c = m);
            }
        }
        let id = |l: u32| match input.slot(l) {
            super::super::Slot::Corner(c) => corner[c],
            super::super::Slot::Edge(e, _) if collapsed[e] => corner[e],
            _ => l,
        };
        let edge_ids = |e: usize| -> Vec<u32> {
            (0..=input.segments[e]).map(|k| id(input.boundary_vertex(e, k))).collect()
        };
        let tris: Vec<[u32; 3]> = out
            .triangles
            .iter()
            .map(|t| t.map(id))
            .filter(|t| t[0] != t[1] && t[1] != t[2] && t[0] != t[2])
            .collect();
        let segment = |a: u32, b: u32| {
            (0..nc)
                .filter(|&e| !collapsed[e])
                .any(|e| edge_ids(e).windows(2).any(|w| (w[0], w[1]) == (a, b) || (w[1], w[0]) == (a, b)))
        };
        for t in &tris {
            // All three on one curve, joined by a chord of it that is not one of its segments.
            let chord = (0..3).any(|k| !segment(t[k], t[(k + 1) % 3]));
            if let Some(e) = (0..nc).find(|&e| chord && t.iter().all(|v| edge_ids(e).contains(v))) {
                return Err(format!("triangle {t:?} lies on edge {e}"));
            }
        }
        let mut directed: Vec<(u32, u32)> =
            tris.iter().flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])]).collect();
        directed.sort_unstable();
        if let Some(w) = directed.windows(2).find(|w| w[0] == w[1]) {
            return Err(format!("directed edge {:?} twice", w[0]));
        }
        let mut boundary: Vec<(u32, u32)> =
            directed.iter().filter(|&&(a, b)| directed.binary_search(&(b, a)).is_err()).copied().collect();
        boundary.sort_unstable();
        let mut expected: Vec<(u32, u32)> = (0..nc)
            .filter(|&e| !collapsed[e])
            .flat_map(|e| edge_ids(e).windows(2).map(|w| (w[0], w[1])).collect::<Vec<_>>())
            .collect();
        expected.sort_unstable();
        if expected.len() == 2 {
            // Two vertices left on the boundary, joined both ways: the patch is a segment, and
            // no pattern can place a vertex inside it. Plans never ask for one: two curves
            // between the same two corners get at least 2 segments each
            // (`tolerance::minimum_segments`).
            return Ok(());
        }
        if boundary != expected {
            return Err(format!("boundary {boundary:?}, expected {expected:?}"));
        }
        Ok(())
    }

    /// The collapsed edges plans meet (one edge of a quad or a triangle, or two opposite edges
    /// of a quad: a spindle's patch), for small factors: the patch stays a fan at the point.
    /// Curves between the same two corners have at least 2 segments, as
    /// `tolerance::minimum_segments` gives them (with 1 each, no triangulation of the patch
    /// avoids slivers). The same inputs without the flag (the pattern not told) fail the check
    /// somewhere, as the spindle did (fuzz/regressions/engine/transition-fan-at-collapsed-edge).
    #[test]
    fn collapsed_edges_fan_without_slivers() {
        let mut unflagged_failures = 0;
        let mut run = |input: PatternInput| {
            check_collapsed(&input, input.collapsed).unwrap_or_else(|e| panic!("{input:?}: {e}"));
            let unflagged = PatternInput { collapsed: [false; 4], ..input };
            if check_collapsed(&unflagged, input.collapsed).is_err() {
                unflagged_failures += 1;
            }
        };
        let quads = [
            [true, false, false, false],
            [false, true, false, false],
            [true, false, true, false],
            [false, true, false, true],
        ];
        for c in quads {
            for s0 in 1..=5 {
                for s1 in 1..=5 {
                    for s2 in 1..=5 {
                        for s3 in 1..=5 {
                            let s = [s0, s1, s2, s3];
                            // Opposite collapsed edges: the other two join the same points.
                            if (0..4)
                                .any(|e| c[e] && c[(e + 2) % 4] && s[(e + 1) % 4].min(s[(e + 3) % 4]) < 2)
                            {
                                continue;
                            }
                            for nu in 1..=5 {
                                for nv in 1..=5 {
                                    run(PatternInput { collapsed: c, ..quad(s, [nu, nv]) });
                                }
                            }
                        }
                    }
                }
            }
        }
        for e in 0..3 {
            let mut c = [false; 4];
            c[e] = true;
            for s0 in 1..=6 {
                for s1 in 1..=6 {
                    for s2 in 1..=6 {
                        // The other two edges join the same two points.
                        if [s0, s1, s2].iter().enumerate().any(|(k, &s)| k != e && s < 2) {
                            continue;
                        }
                        for n in 1..=6 {
                            run(PatternInput { collapsed: c, ..tri([s0, s1, s2], n) });
                        }
                    }
                }
            }
        }
        assert!(unflagged_failures > 0, "the check cannot fail");
    }

    /// "Pinched corners": with corner 0, corner 2 or both marked pinched, the pattern itself
    /// keeps a vertex off the corner's two edges in every triangle there — no cut left for
    /// `cut_pinched_corners` (`build` is `triangulate`) — and still tiles the domain with its
    /// counts, over every quad input with edges and interiors of 1–6 segments. Without the
    /// marks the same inputs have such triangles (or the test would see nothing).
    #[test]
    fn pinched_corners_0_and_2_keep_a_vertex_off_their_edges() {
        let (mut chords_unmarked, mut raised) = (0, 0);
        let (mut plain, mut built) = (LocalTessellation::default(), LocalTessellation::default());
        for code in 0..6u32.pow(4) {
            let segments: [u32; 4] = std::array::from_fn(|e| 1 + (code / 6u32.pow(e as u32)) % 6);
            for interior in (1..=6).flat_map(|n| (1..=6).map(move |m| [n, m])) {
                for pinched in
                    [[true, false, false, false], [false, false, true, false], [true, false, true, false]]
                {
                    let unmarked = quad(segments, interior);
                    let input = PatternInput { pinched, ..unmarked };
                    let chord_at = |out: &LocalTessellation, c: usize| {
                        out.triangles.iter().any(crate::pattern::on_corner_edges(&input, c))
                    };
                    Transition.triangulate(&unmarked, &mut plain);
                    chords_unmarked += (0..4).filter(|&c| pinched[c] && chord_at(&plain, c)).count();
                    Transition.triangulate(&input, &mut built);
                    for c in (0..4).filter(|&c| pinched[c]) {
                        assert!(!chord_at(&built, c), "{input:?}: a triangle on corner {c}'s two edges");
                    }
                    assert_eq!(
                        Transition.counts(&input),
                        (built.interior.len() as u32, built.triangles.len() as u32),
                        "{input:?}"
                    );
                    raised += usize::from(built.interior.len() != plain.interior.len());
                    let mut cut = LocalTessellation::default();
                    Transition.build(&input, &mut cut);
                    assert_eq!(cut, built, "{input:?}: the cut found something left to do");
                    check_core_grid(&input, &cut, Transition.core_cells(&input).map_or(0, |c| c.1));
                    let mut p = Vec::new();
                    crate::pattern::cache::local_params(&input, &built, &mut p);
                    crate::pattern::assert_tiles(&input, &built, &p, 0.0);
                }
            }
        }
        assert!(chords_unmarked > 1000, "only {chords_unmarked} unmarked chords: the test sees too little");
        assert!(raised > 0, "no core factor raised for a pinned strip");
    }

    #[test]
    fn walk_spreads_apexes_evenly() {
        // 2 outer segments against 6 inner: the outer triangles fall at inner points 1 and 4
        // (midpoints 1/4 and 3/4 against inner midpoints k/6 + 1/12), i.e. symmetric.
        let mut tris = Vec::new();
        let outer = |i: u32| (100 + i, DVec2::new(i as f64 / 2.0, 0.0));
        let inner = |j: u32| (j, DVec2::new(j as f64 / 6.0, 1.0));
        walk(2, 6, StripEnds { lead: 0, trail: 0, pinned: [false; 2] }, outer, inner, &mut tris);
        let apexes: Vec<u32> = tris.iter().filter(|t| t[1] >= 100).map(|t| t[2]).collect();
        assert_eq!(apexes, vec![2, 4]);
        assert_eq!(tris.len(), 8);
    }

    #[test]
    fn reports_min_angles() {
        println!("min angle (deg) in the domain, [min, mean of per-triangle minima]");
        let configs: [(&str, PatternInput); 10] = [
            ("quad 8x8, uniform", quad([8; 4], [8, 8])),
            ("quad 8x8, edge0=16", quad([16, 8, 8, 8], [8, 8])),
            ("quad 8x8, edge0=16 edge1=12", quad([16, 12, 8, 8], [8, 8])),
            ("quad 8x8, edges 16,12,9,20", quad([16, 12, 9, 20], [8, 8])),
            ("quad 4x4, edges 9,5,7,6", quad([9, 5, 7, 6], [4, 4])),
            ("tri 8, uniform", tri([8; 3], 8)),
            ("tri 8, edge0=4", tri([4, 8, 8], 8)),
            ("tri 8, edge0=4 edge2=3", tri([4, 8, 3], 8)),
            ("tri 8, edges 4,5,3", tri([4, 5, 3], 8)),
            ("tri 16, edges 2,9,16", tri([2, 9, 16], 16)),
        ];
        for (name, input) in configs {
            let (min, mean) = min_angle_stats(&Transition, &input);
            // The uniform pattern at the core factor, the baseline the strips are added to.
            let n = input.interior[0];
            let uniform = PatternInput::new(input.domain, [n; 4], [n, n]);
            let (umin, umean) = min_angle_stats(&Uniform, &uniform);
            println!("{name:30} transition {min:6.2} {mean:6.2}   uniform {umin:6.2} {umean:6.2}");
            assert!(min > 0.0 && mean <= umean + 1e-9, "{name}: {min} {mean}");
        }
    }
}
