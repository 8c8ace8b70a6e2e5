//! The semi-uniform pattern (Dyken, Reimers & Seland, "Semi-uniform adaptive patch
//! tessellation", paper 000, §3 and Listing 1): a patch of level `m` is tessellated by the
//! uniform dyadic pattern `P^m` (`2^m` segments per side), and every *boundary* vertex of
//! `P^m` is moved by the snap function `φ` to the nearest point of its edge's own, coarser
//! dyadic sampling. Interior vertices never move, so the pattern is "uniform in the interior";
//! triangles whose snapped corners coincide collapse and are dropped.
//!
//! **Levels.** Every edge `e` has a level `p_e` with `segments[e] = 2^{p_e}`, and the patch
//! level is `m = log2(interior[0])`; the paper takes `m = max_e p_e` (the engine's choice), but
//! any `m ≥ max_e p_e` works, so that is all we require.
//!
//! **Snap function.** Equation (1) of the paper maps `t ∈ [0, 1]` to a nearest `p`-dyadic number,
//! `σ_p(t) = ⌈2^p t − ½⌉ / 2^p` for `t < ½` and `⌊2^p t + ½⌋ / 2^p` otherwise, i.e. ties go
//! towards 0 below the midpoint and towards 1 from it on: towards the nearer corner. Then
//! `φ(u) = u` for interior points and `φ(u) = (σ_{p_i}(u_0), σ_{p_i}(u_1), σ_{p_i}(u_2))` for a
//! point on edge `i`. Like Listing 1 we snap a single coordinate: the edge parameter `t` in the
//! patch's own edge direction (`φ(u) = edge_point(e, σ_{p_e}(t))`), which keeps `φ(u)` on the
//! edge by construction. The symmetry `σ_p(t) + σ_p(1 − t) = 1` makes the result independent of
//! the direction the edge is walked in, so the neighbour across the edge, which walks it
//! backwards, snaps to the same points: that is what makes the tessellation crack-free. On the
//! `2^m` grid this symmetry holds for every `p ≤ m` and every grid `t` *except* `t = ½` with
//! `p = 0`, where no 0-dyadic number can be the answer for both `t` and `1 − t` (the paper's
//! claim "for any integer `p`" misses this case). There the edge has a single segment, so the
//! boundary is the same whichever corner the midpoint snaps to, and we keep the formula's
//! choice (corner `e + 1`).
//!
//! **Compaction.** Since `σ` is monotone, snapping collapses some boundary segments of `P^m`
//! to points and never reorders boundary vertices, so the triangles that stay non-degenerate
//! keep their orientation and tile the domain (the paper's argument; tested exhaustively for
//! small levels below). We drop the degenerate ones, so the output is a proper triangulation
//! over the local numbering of [`super`]: corners, each edge's samples at the edge's own
//! level, then the `P^m` interior vertices in the order [`Uniform`](super::uniform::Uniform)
//! uses. Being a triangulated disk, it has `2I + B − 2` triangles for `I` interior and
//! `B = Σ segments[e]` boundary vertices, which is how [`Pattern::counts`] counts without
//! building. With all levels equal to `m` nothing moves and the output is the uniform pattern
//! at `2^m`, triangle for triangle.

mod instanced;

pub use instanced::{snap, PatternVertex, StaticPattern};

use super::{LocalTessellation, Pattern, PatternInput};
use crate::domain::Domain;

/// Highest level `M` of the semi-uniform pattern and its static patterns `P^0…P^M`: edge
/// factors up to `2^8 = 256` (paper 000 uses `M ≤ 8`). The one cap every user of the scheme
/// reads.
pub const MAX_LEVEL: u32 = 8;

/// The semi-uniform pattern for triangles and quads.
///
/// Preconditions ([`check_input`], asserted in debug builds): every `segments[e]` is a power of two, and
/// `interior[0]` (for quads also `interior[1]`, which must equal it) is a power of two at least
/// as large as every `segments[e]`. The paper's choice is `interior[0] = max_e segments[e]`.
/// Edge samples are uniform (`t_k = k / segments[e]`).
#[derive(Debug, Clone, Copy, Default)]
pub struct SemiUniform;

/// `σ_p(t)` of equation (1) of paper 000 for a real `t ∈ [0, 1]`: the nearest `p`-dyadic number
/// to `t`, ties broken towards the nearer of 0 and 1.
pub fn sigma(p: u32, t: f64) -> f64 {
    let s = (1u64 << p) as f64;
    if t < 0.5 {
        (s * t - 0.5).ceil() / s
    } else {
        (s * t + 0.5).floor() / s
    }
}

/// Integer form of [`sigma`] on the `2^m` grid: for `t = k / 2^m` (`k ≤ 2^m`, `p ≤ m`) returns
/// `K` with `σ_p(t) = K / 2^p`. Exact, so the pattern never depends on float rounding.
pub fn snap_index(p: u32, m: u32, k: u32) -> u32 {
    debug_assert!(p <= m && m < 32, "snap_index: need p ≤ m < 32 (p={p}, m={m})");
    debug_assert!(u64::from(k) <= 1u64 << m, "snap_index: k={k} beyond 2^{m}");
    let (k, n, s) = (u64::from(k), 1u64 << m, 1u64 << (m - p));
    let (q, r) = (k / s, k % s);
    // Round to nearest; a tie (remainder exactly half a step) goes towards 0 below the
    // midpoint of the edge and towards 1 from it on, as in equation (1).
    let up = 2 * r > s || (2 * r == s && 2 * k >= n);
    (q + u64::from(up)) as u32
}

/// The pattern's preconditions on `input`, checked: every edge's segments a power of two, the
/// interior `[n, n]` (triangles: `n` in `interior[0]`) with `n` a power of two at least as
/// large as every edge's segments and at most `2^MAX_LEVEL`. The GPU engine, whose shaders
/// assume them, checks a plan with it; the CPU pattern asserts it in debug builds. Errors: the
/// first broken one, said. Cost: O(1).
pub fn check_input(input: &PatternInput) -> Result<(), String> {
    let n = input.interior[0];
    let top = 1u32 << MAX_LEVEL;
    if !n.is_power_of_two() || n > top {
        return Err(format!("the semi-uniform patch level {n} is not a power of two up to {top}"));
    }
    if input.domain == Domain::Quad && input.interior[1] != n {
        return Err(format!("semi-uniform quads need equal interior factors, not {:?}", input.interior));
    }
    let nc = input.domain.corner_count();
    if let Some(e) = (0..nc).find(|&e| !input.segments[e].is_power_of_two() || input.segments[e] > n) {
        return Err(format!(
            "edge {e}'s {} segments are not a power of two up to the patch level {n}",
            input.segments[e]
        ));
    }
    Ok(())
}

/// The level `p` with `2^p = x`.
fn level(x: u32) -> u32 {
    debug_assert!(x.is_power_of_two(), "semi-uniform: {x} is not a power of two");
    x.trailing_zeros()
}

/// What a grid point of `P^m` is before snapping.
enum GridPoint {
    Corner(usize),
    /// Edge `e`, grid index `k` (`0 < k < n`) in the patch's own edge direction.
    Edge(usize, u32),
    /// Interior vertex number `j` (same order as the uniform pattern).
    Interior(u32),
}

/// The local numbering of one patch and the snap, shared by `counts`, `build` and the tests.
struct Layout {
    domain: Domain,
    /// Grid factor `n = 2^m`.
    n: u32,
    m: u32,
    /// Level of each edge.
    p: [u32; 4],
    segments: [u32; 4],
    edge_base: [u32; 4],
    interior_base: u32,
}

impl Layout {
    fn new(input: &PatternInput) -> Self {
        debug_assert!(check_input(input).is_ok(), "{:?}: {input:?}", check_input(input));
        let nc = input.domain.corner_count();
        let n = input.interior[0];
        let m = level(n);
        let mut p = [0; 4];
        let mut edge_base = [0; 4];
        for e in 0..nc {
            p[e] = level(input.segments[e]);
            edge_base[e] = input.edge_base(e);
        }
        Layout {
            domain: input.domain,
            n,
            m,
            p,
            segments: input.segments,
            edge_base,
            interior_base: input.interior_base(),
        }
    }

    fn interior_count(&self) -> u32 {
        let n = self.n;
        match self.domain {
            Domain::Tri => (n.saturating_sub(1)) * (n.saturating_sub(2)) / 2,
            Domain::Quad => (n - 1) * (n - 1),
        }
    }

    /// Classifies grid point `(i, j)` (grid units, `0 ≤ i, j ≤ n`, `i + j ≤ n` for triangles).
    fn classify(&self, i: u32, j: u32) -> GridPoint {
        let n = self.n;
        match self.domain {
            Domain::Tri => match (i, j) {
                (0, 0) => GridPoint::Corner(0),
                (i, 0) if i == n => GridPoint::Corner(1),
                (0, j) if j == n => GridPoint::Corner(2),
                (i, 0) => GridPoint::Edge(0, i),
                (i, j) if i + j == n => GridPoint::Edge(1, j),
                (0, j) => GridPoint::Edge(2, n - j),
                (i, j) => {
                    // Rows 1..j-1 before this one hold n-1-r points each.
                    let before = (j - 1) * (n - 1) - (j - 1) * j / 2;
                    GridPoint::Interior(before + i - 1)
                }
            },
            Domain::Quad => match (i, j) {
                (0, 0) => GridPoint::Corner(0),
                (i, 0) if i == n => GridPoint::Corner(1),
                (i, j) if i == n && j == n => GridPoint::Corner(2),
                (0, j) if j == n => GridPoint::Corner(3),
                (i, 0) => GridPoint::Edge(0, i),
                (i, j) if i == n => GridPoint::Edge(1, j),
                (i, j) if j == n => GridPoint::Edge(2, n - i),
                (0, j) => GridPoint::Edge(3, n - j),
                (i, j) => GridPoint::Interior((j - 1) * (n - 1) + (i - 1)),
            },
        }
    }

    /// Local index of `φ` applied to grid point `(i, j)`.
    fn local(&self, i: u32, j: u32) -> u32 {
        match self.classify(i, j) {
            GridPoint::Corner(c) => c as u32,
            GridPoint::Edge(e, k) => {
                let s = snap_index(self.p[e], self.m, k);
                if s == 0 {
                    e as u32
                } else if s == self.segments[e] {
                    ((e + 1) % self.domain.corner_count()) as u32
                } else {
                    self.edge_base[e] + s - 1
                }
            }
            GridPoint::Interior(j) => self.interior_base + j,
        }
    }
}

/// Pushes `[a, b, c]` unless two of its corners coincide after snapping.
#[inline]
fn push(out: &mut Vec<[u32; 3]>, a: u32, b: u32, c: u32) {
    if a != b && b != c && c != a {
        out.push([a, b, c]);
    }
}

impl Pattern for SemiUniform {
    fn name(&self) -> &'static str {
        "semi-uniform"
    }

    /// Quads: the interior of `P^m` is the `n × n` grid (`uniform::grid`); only boundary
    /// points snap.
    fn interior_grid(&self, input: &PatternInput) -> Option<[u32; 2]> {
        (input.domain == Domain::Quad).then(|| [Layout::new(input).n; 2])
    }

    /// The uniform grid's cells, cut from corner 0 to corner 2: a triangle at either corner
    /// keeps the grid's vertex next to it inside the patch (for `n ≥ 2`; at `n = 1` the
    /// diagonal itself), wherever the boundary points snap. The GPU tests draw the valence-2
    /// cage's pinched patches at random levels as the CPU does.
    fn cut_through_corners_0_and_2(&self) -> bool {
        true
    }

    fn counts(&self, input: &PatternInput) -> (u32, u32) {
        let layout = Layout::new(input);
        let nc = input.domain.corner_count();
        let interior = layout.interior_count();
        // A triangulated disk with I interior and B boundary vertices has 2I + B - 2
        // triangles (Euler); the tests check `build` agrees.
        let boundary: u32 = input.segments[..nc].iter().sum();
        (interior, 2 * interior + boundary - 2)
    }

    fn triangulate(&self, input: &PatternInput, out: &mut LocalTessellation) {
        let layout = Layout::new(input);
        // The same grid and triangle order as the uniform pattern, with every vertex mapped
        // through φ; only the boundary vertices can move.
        crate::pattern::uniform::grid(
            input.domain,
            layout.n,
            |i, j| layout.local(i, j),
            out,
            |t, [a, b, c]| push(t, a, b, c),
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pattern::uniform::Uniform;
    use glam::DVec2;

    fn input(domain: Domain, p: [u32; 4], m: u32) -> PatternInput {
        PatternInput::new(domain, p.map(|p| 1 << p), [1 << m, 1 << m])
    }

    /// Domain parameters of every local vertex.
    fn params(input: &PatternInput, out: &LocalTessellation) -> Vec<DVec2> {
        input.local_positions(&out.interior, |e, k| k as f64 / input.segments[e] as f64)
    }

    /// Checks that the output tiles the domain and matches the edges' samplings; returns the
    /// triangle count.
    fn check(input: &PatternInput) -> usize {
        let mut out = LocalTessellation::default();
        SemiUniform.build(input, &mut out);
        let (vi, t) = SemiUniform.counts(input);
        assert_eq!(out.interior.len() as u32, vi, "{input:?}");
        assert_eq!(out.triangles.len() as u32, t, "{input:?}");
        // Grid triangles have area ≥ 1/(2n²), so anything near 0 is degenerate.
        crate::pattern::assert_tiles(input, &out, &params(input, &out), 5e-10);
        out.triangles.len()
    }

    #[test]
    fn sigma_matches_equation_1_and_its_integer_form() {
        assert_eq!(sigma(1, 0.2), 0.0);
        assert_eq!(sigma(1, 0.3), 0.5);
        assert_eq!(sigma(2, 0.125), 0.0); // tie below ½ → towards 0
        assert_eq!(sigma(2, 0.875), 1.0); // tie above ½ → towards 1
        assert_eq!(sigma(2, 0.375), 0.25);
        assert_eq!(sigma(2, 0.625), 0.75);
        for m in 0..=8 {
            for p in 0..=m {
                for k in 0..=1u32 << m {
                    let t = k as f64 / (1u64 << m) as f64;
                    let s = snap_index(p, m, k);
                    assert_eq!(s as f64 / (1u64 << p) as f64, sigma(p, t), "p={p} m={m} k={k}");
                    // A nearest p-dyadic point: at most half a level-p step away.
                    let step = 1u32 << (m - p);
                    assert!(2 * (s * step).abs_diff(k) <= step, "p={p} m={m} k={k}");
                }
            }
        }
    }

    #[test]
    fn sigma_is_symmetric_keeps_corners_and_is_monotone() {
        for m in 0..=8u32 {
            let n = 1u32 << m;
            for p in 0..=m {
                // σ_p(i) = i for the corners.
                assert_eq!(snap_index(p, m, 0), 0);
                assert_eq!(snap_index(p, m, n), 1 << p);
                let mut prev = 0;
                for k in 0..=n {
                    let s = snap_index(p, m, k);
                    assert!(s >= prev, "p={p} m={m} k={k}: not monotone");
                    prev = s;
                    // σ_p(t) + σ_p(1 − t) = 1, except the unavoidable midpoint tie at p = 0.
                    if p == 0 && 2 * k == n {
                        continue;
                    }
                    assert_eq!(s + snap_index(p, m, n - k), 1 << p, "p={p} m={m} k={k}");
                }
                // Level-p points stay where they are.
                for kp in 0..=1u32 << p {
                    assert_eq!(snap_index(p, m, kp << (m - p)), kp);
                }
            }
        }
        // The exception: both halves of a level-0 edge's midpoint go to corner e+1.
        assert_eq!(snap_index(0, 3, 4), 1);
    }

    #[test]
    fn phi_keeps_interior_points_and_corners_and_snaps_edges_to_their_level() {
        for domain in [Domain::Tri, Domain::Quad] {
            let m = 4;
            let p = [0, 2, 3, 1];
            let inp = input(domain, p, m);
            let layout = Layout::new(&inp);
            let n = 1u32 << m;
            let mut out = LocalTessellation::default();
            SemiUniform.build(&inp, &mut out);
            let uv = params(&inp, &out);
            for j in 0..=n {
                for i in 0..=n {
                    if domain == Domain::Tri && i + j > n {
                        continue;
                    }
                    let at = DVec2::new(i as f64, j as f64) / n as f64;
                    let l = layout.local(i, j);
                    let snapped = uv[l as usize];
                    match layout.classify(i, j) {
                        GridPoint::Corner(_) | GridPoint::Interior(_) => {
                            assert!((snapped - at).length() < 1e-15, "{domain:?} ({i},{j})")
                        }
                        GridPoint::Edge(e, k) => {
                            // On the same edge, at a level-p_e dyadic point, and the nearest.
                            let seg = inp.segments[e] as f64;
                            let t = snap_index(p[e], m, k) as f64 / seg;
                            assert_eq!(t * seg, (t * seg).round());
                            assert!((snapped - domain.edge_point(e, t)).length() < 1e-15);
                            assert!((t - k as f64 / n as f64).abs() <= 0.5 / seg + 1e-15);
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn triangles_tile_the_domain_for_all_levels_up_to_5() {
        for m in 0..=5 {
            for p0 in 0..=m {
                for p1 in 0..=m {
                    for p2 in 0..=m {
                        check(&input(Domain::Tri, [p0, p1, p2, 0], m));
                    }
                }
            }
        }
    }

    #[test]
    fn quads_tile_the_domain_for_all_levels_up_to_4() {
        for m in 0..=4u32 {
            for code in 0..(m + 1).pow(4) {
                let p = [0, 1, 2, 3].map(|e| code / (m + 1).pow(e) % (m + 1));
                check(&input(Domain::Quad, p, m));
            }
        }
    }

    #[test]
    fn mixed_levels_at_higher_patch_levels_tile_the_domain() {
        for m in [6, 7] {
            for p in [[0, m, 3, 1], [m, m, 0, 2], [1, 0, m, 5], [0, 0, 0, 0]] {
                check(&input(Domain::Tri, p, m));
                check(&input(Domain::Quad, p, m));
            }
        }
    }

    #[test]
    fn equal_levels_give_the_uniform_pattern() {
        for domain in [Domain::Tri, Domain::Quad] {
            for m in 0..=6 {
                let inp = input(domain, [m; 4], m);
                let (mut a, mut b) = (LocalTessellation::default(), LocalTessellation::default());
                SemiUniform.build(&inp, &mut a);
                Uniform.build(&inp, &mut b);
                assert_eq!(a, b, "{domain:?} m={m}");
                assert_eq!(SemiUniform.counts(&inp), Uniform.counts(&inp));
            }
        }
    }

    #[test]
    fn coarse_edges_collapse_their_strip() {
        // All edges at level 0 on a level-1 triangle: the midpoints snap to corners and the
        // single remaining triangle, the former middle one, is the domain itself (its corners
        // come from the midpoints of edges 0, 1, 2, which snap to corners 1, 2, 0).
        let inp = input(Domain::Tri, [0; 4], 1);
        let mut out = LocalTessellation::default();
        SemiUniform.build(&inp, &mut out);
        assert_eq!(out.triangles, vec![[1, 2, 0]]);
        // One coarse edge on a level-2 triangle removes 2 of the 16 triangles (the snapped
        // strip along edge 0 loses one triangle per collapsed segment).
        let inp = input(Domain::Tri, [1, 2, 2, 0], 2);
        assert_eq!(check(&inp), 14);
    }
}
