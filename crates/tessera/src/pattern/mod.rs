//! Tessellation patterns: the triangulation of one patch's domain, given how its edges are
//! sampled. Patterns never evaluate surfaces; one pattern serves every surface kind and both
//! engines.
//!
//! Local vertex numbering, shared by every pattern: corners first (`0..corner_count`), then
//! the inner samples of edge 0, edge 1, … in the patch's own edge direction (corner `e` →
//! `e+1`), then the pattern's interior vertices. Triangles are counter-clockwise in the
//! `(u, v)` domain.

pub(crate) mod cache;
pub mod core_grid;
pub mod esc;
pub mod hardware;
pub mod sd2;
pub mod semi_uniform;
pub mod transition;
pub mod uniform;

pub use core_grid::CoreGrid;

use crate::domain::Domain;
use glam::DVec2;

/// What a pattern needs to know about a patch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PatternInput {
    pub domain: Domain,
    /// Segments on each edge (`segments[e] ≥ 1`; entries past the corner count are ignored).
    pub segments: [u32; 4],
    /// Interior factors along u and v (triangles use `interior[0]`).
    pub interior: [u32; 2],
    /// The real (possibly fractional) factor of each edge, for the fractional patterns
    /// (`sd2`, `hardware`); equal to `segments` as `f64` for integer samplings.
    pub factors: [f64; 4],
    /// The patch's index in its set, for patterns that hold per-patch decisions (`esc`).
    pub patch: u32,
    /// Edges whose boundary curve is collapsed to a point (entries past the corner count are
    /// ignored). The engine gives every sample of such an edge the vertex of the edge's first
    /// corner and drops the triangles that degenerate, so a pattern's triangles there must
    /// still form a fan at the point once its samples are one vertex; [`transition`] reads
    /// this to keep its strips from fanning over a neighbouring edge.
    pub collapsed: [bool; 4],
    /// Corners whose two edges are both shared with one other patch (an interior vertex of
    /// valence 2: a subdivision cage can have them). There both patches would cut the corner
    /// along the same chord, between the first samples of the two edges, and give the same
    /// triangle twice; [`Pattern::build`] cuts such a corner's cell through the corner instead
    /// ([`cut_pinched_corners`]). Entries past the corner count are ignored.
    pub pinched: [bool; 4],
}

impl PatternInput {
    /// An integer input: `factors` equal to `segments`, patch 0, no collapsed edge.
    pub fn new(domain: Domain, segments: [u32; 4], interior: [u32; 2]) -> Self {
        PatternInput {
            domain,
            segments,
            interior,
            factors: segments.map(f64::from),
            patch: 0,
            collapsed: [false; 4],
            pinched: [false; 4],
        }
    }

    /// Index of the first local vertex of edge `e`'s inner samples.
    pub fn edge_base(&self, e: usize) -> u32 {
        let n = self.domain.corner_count();
        n as u32 + self.segments[..e].iter().map(|s| s - 1).sum::<u32>()
    }

    /// Index of the first interior vertex.
    pub fn interior_base(&self) -> u32 {
        self.edge_base(self.domain.corner_count())
    }

    /// Local index of boundary point `k` (`0 ≤ k ≤ segments[e]`) of edge `e`, counted in the
    /// patch's own direction: corner `e`, an inner sample, or corner `e + 1`. Cost: O(1).
    pub fn boundary_vertex(&self, e: usize, k: u32) -> u32 {
        let nc = self.domain.corner_count();
        if k == 0 {
            e as u32
        } else if k == self.segments[e] {
            ((e + 1) % nc) as u32
        } else {
            self.edge_base(e) + k - 1
        }
    }

    /// Domain position of every local vertex: corners, edge `e`'s inner samples at parameter
    /// `edge_t(e, k)` along the edge, then `interior`. For tests and diagnostics. Cost: O(V).
    pub fn local_positions(&self, interior: &[DVec2], edge_t: impl Fn(usize, u32) -> f64) -> Vec<DVec2> {
        let d = self.domain;
        let nc = d.corner_count();
        let mut p: Vec<DVec2> = (0..nc).map(|c| d.corner(c)).collect();
        for e in 0..nc {
            p.extend((1..self.segments[e]).map(|k| d.edge_point(e, edge_t(e, k))));
        }
        p.extend_from_slice(interior);
        p
    }
}

/// What a local vertex index refers to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Slot {
    /// Corner `c`.
    Corner(usize),
    /// Inner sample `k` (`1 ≤ k < segments`) of edge `e`, counted in the patch's own direction.
    Edge(usize, u32),
    /// Interior vertex `j` of the pattern.
    Interior(u32),
}

impl PatternInput {
    /// Decodes a local vertex index. Cost: O(corner count).
    pub fn slot(&self, l: u32) -> Slot {
        let nc = self.domain.corner_count();
        if (l as usize) < nc {
            return Slot::Corner(l as usize);
        }
        let mut base = nc as u32;
        for e in 0..nc {
            let inner = self.segments[e] - 1;
            if l < base + inner {
                return Slot::Edge(e, l - base + 1);
            }
            base += inner;
        }
        Slot::Interior(l - base)
    }
}

/// Interior parameters and triangles of one patch, over local vertex indices.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LocalTessellation {
    pub interior: Vec<DVec2>,
    pub triangles: Vec<[u32; 3]>,
}

/// A tessellation pattern.
pub trait Pattern: Sync {
    /// Number of interior vertices and of triangles. Must agree with [`Pattern::build`].
    fn counts(&self, input: &PatternInput) -> (u32, u32);

    /// Writes the pattern's interior parameters and triangles into `out` (cleared first):
    /// what each pattern implements. Callers call [`Pattern::build`].
    fn triangulate(&self, input: &PatternInput, out: &mut LocalTessellation);

    /// Writes interior parameters and triangles into `out` (cleared first): the pattern's
    /// [`Pattern::triangulate`], with the cells of [`PatternInput::pinched`] corners cut
    /// through the corner ([`cut_pinched_corners`]; counts unchanged). The one call every
    /// engine and check makes, so that all of them see one triangulation; patterns implement
    /// `triangulate` and keep this method as it is.
    fn build(&self, input: &PatternInput, out: &mut LocalTessellation) {
        self.triangulate(input, out);
        if input.pinched.iter().any(|&p| p) {
            cut_pinched_corners(input, out);
        }
    }

    /// A short name for messages (`uniform`, `transition`, ...).
    fn name(&self) -> &'static str {
        "given"
    }

    /// `Some([nu, nv])` when the interior vertices [`Pattern::build`] gives for `input` are
    /// exactly the grid points `(i·(1/nu), j·(1/nv))`, `0 < i < nu`, `0 < j < nv`, row after
    /// row (`j` outer): a promise an evaluator may use to evaluate them row by row
    /// (`engine`'s vectorized bicubic evaluation). None (the default) promises nothing.
    fn interior_grid(&self, _input: &PatternInput) -> Option<[u32; 2]> {
        None
    }

    /// `Some([nu, nv])` when every triangle [`Pattern::build`] gives for `input` is half a
    /// cell of the `nu × nv` grid of the domain: a right triangle with legs `1/nu` along `u`
    /// and `1/nv` along `v` (triangle domains: `nu = nv = n`, the `n`-fold grid). Every
    /// triangle then has the same error bound, so a bound over the pattern is that of one
    /// cell's triangle (the a-posteriori check of `criterion::tolerance` takes it instead of
    /// building the pattern). None (the default) promises nothing. Cost: O(1).
    fn grid_cells(&self, _input: &PatternInput) -> Option<[u32; 2]> {
        None
    }

    /// `Some((cells, count))` when the first `count` triangles [`Pattern::build`] gives for
    /// `input` are halves of cells of the `cells[0] × cells[1]` grid, as in
    /// [`Pattern::grid_cells`] (a core grid before transition strips): they share one error
    /// bound, and the a-posteriori check bounds only the triangles after them one by one.
    /// None (the default) promises nothing. Cost: O(1).
    fn core_cells(&self, _input: &PatternInput) -> Option<([u32; 2], u32)> {
        None
    }

    /// `Some(core)` when the first [`CoreGrid::triangle_count`] triangles [`Pattern::build`]
    /// gives for `input` are exactly `core`'s ([`CoreGrid::write`] with the input's interior
    /// base and local indices) and its interior vertices are the grid's: an engine may then
    /// write the core by the rule and keep only the rest of the pattern
    /// ([`Pattern::build_after_core`]). `core_cells`, where both are given, counts the same
    /// cells. None (the default) promises nothing. Cost: O(1).
    fn core_grid(&self, _input: &PatternInput) -> Option<CoreGrid> {
        None
    }

    /// [`Pattern::build`] without what [`Pattern::core_grid`] gives by rule: where it gives a
    /// core, the triangles after the core and no interior vertices (they are the core grid's
    /// points, [`CoreGrid::interior_points`]); where it gives none, the whole pattern. The
    /// default builds the whole pattern and removes the core; a pattern with a core overrides
    /// it to skip building it. Cost: O(triangles after the core) for an override.
    ///
    /// Why the interior goes too: a fine adaptive frame's distinct patterns differ mostly in
    /// their strips, and their interiors were most of what a frame's cache held. The rook × 16
    /// at 0.5 px has 10,152 distinct patterns with 6.2 M interior points (100 MB), and 1,671
    /// distinct grids with 1.9 M; the check's stage took 75 → 63 ms (one thread).
    fn build_after_core(&self, input: &PatternInput, out: &mut LocalTessellation) {
        build_removing_core(self, input, out)
    }

    /// True when, at each of a quad's corners 0 and 2 that the input marks pinched, every
    /// triangle [`Pattern::triangulate`] makes has a vertex off the corner's two edges (cells
    /// of a grid cut from corner 0 to corner 2 do at any such corner; the transition pattern
    /// reads the marks), so a patch pinched at those corners needs no cut
    /// ([`cut_pinched_corners`] finds nothing to do): an engine that does not run the cut (the
    /// GPU's, `scheme::pinched_beyond_the_gpu`) still draws such a patch as the CPU does.
    /// False (the default) promises nothing. Cost: O(1).
    fn cut_through_corners_0_and_2(&self) -> bool {
        false
    }

    /// True when [`Pattern::build`] depends on `input.patch` (patterns holding per-patch
    /// decisions); false lets the engine reuse one build for every patch with the same
    /// input otherwise.
    fn depends_on_patch(&self) -> bool {
        false
    }

    /// The pattern itself as [`std::any::Any`], for an engine that draws a pattern with
    /// per-patch decisions from the pattern's own data (the GPU engine reads ESC's insertion
    /// grids, [`crate::pattern::esc::Esc::grid`]). None (the default) for the patterns whose
    /// output follows from the plan alone.
    fn as_any(&self) -> Option<&dyn std::any::Any> {
        None
    }

    /// Appends the pattern's triangles as triangle strips over local indices, strips
    /// separated by [`crate::mesh::strips::RESTART`], and returns true; a pattern without a
    /// strip form returns false and appends nothing. Contract: decoding the strips
    /// ([`crate::mesh::strips::decode`], which drops triangles with a repeated index) gives
    /// exactly [`Pattern::build`]'s triangles, in order, with the same winding.
    fn strips(&self, _input: &PatternInput, _out: &mut Vec<u32>) -> bool {
        false
    }
}

/// The default [`Pattern::build_after_core`]: the whole pattern, its core removed.
pub fn build_removing_core<P: Pattern + ?Sized>(
    pattern: &P,
    input: &PatternInput,
    out: &mut LocalTessellation,
) {
    pattern.build(input, out);
    if let Some(core) = pattern.core_grid(input) {
        out.triangles.drain(..core.triangle_count() as usize);
        out.interior.clear();
    }
}

/// At a pinched corner `c` ([`PatternInput::pinched`]) the two edges there are the other
/// patch's two edges too, so a triangle whose three vertices all lie on them — typically the
/// chord triangle `(c, a, b)` between the corner and the first samples of its edges — would be
/// the other patch's triangle as well (the same three vertices): the mesh would cover it
/// twice. Where a pattern made such a triangle, edges are put in along the domain's diagonal
/// from `c` to the opposite corner (through the vertices on it, by Sloan's edge insertion:
/// flipping the edges that cross each piece) until none is left. Every triangle with a vertex
/// on each of the two edges would cross that diagonal, and one with all three on one edge
/// is flat, so once the diagonal is in, each triangle at the corner has a vertex inside the
/// patch and the two patches share only the edges' segments, as neighbours do. A flip turns
/// the quad of two triangles on its other diagonal and is made only where both new triangles
/// are positively oriented in the domain. Counts, the boundary and the triangles off the
/// diagonal stay the pattern's; on a grid the diagonal runs through cell corners and each
/// flip keeps both halves halves of their cell ([`Pattern::grid_cells`] holds). Quads only:
/// two triangles sharing two edges share all three corners (a duplicate face, removed on
/// input), so a triangle domain has no pinched corner to cut. Cost: O(triangles) per flip, a
/// few flips per pinched corner.
pub fn cut_pinched_corners(input: &PatternInput, out: &mut LocalTessellation) {
    if input.domain != Domain::Quad {
        return;
    }
    let mut positions = Vec::new();
    for c in 0..4 {
        if !input.pinched[c] {
            continue;
        }
        let shared = on_corner_edges(input, c);
        if !out.triangles.iter().any(&shared) {
            continue;
        }
        if positions.is_empty() {
            cache::local_params(input, out, &mut positions);
        }
        // The diagonal's vertices from the corner on: those strictly inside it, then the
        // opposite corner.
        let (from, to) = (positions[c], positions[(c + 2) % 4]);
        let along = |q: DVec2| (q - from).dot(to - from) / (to - from).length_squared();
        let mut waypoints: Vec<u32> = (0..positions.len() as u32)
            .filter(|&k| {
                let q = positions[k as usize];
                (to - from).perp_dot(q - from).abs() <= 1e-12 && along(q) > 1e-12 && along(q) < 1.0 - 1e-12
            })
            .collect();
        waypoints.sort_by(|&i, &j| along(positions[i as usize]).total_cmp(&along(positions[j as usize])));
        waypoints.push(((c + 2) % 4) as u32);
        let mut at = c as u32;
        for w in waypoints {
            insert_edge(out, &positions, at, w);
            at = w;
            if !out.triangles.iter().any(&shared) {
                break;
            }
        }
    }
}

/// Whether a triangle (local indices) has all three vertices on the two edges at corner `c`
/// (edges `c` and `c − 1`, their far corners included): what a pinched corner must not keep
/// ([`cut_pinched_corners`]; [`Pattern::cut_through_corners_0_and_2`]'s promise). Cost:
/// O(samples of the two edges) to make, and a call.
pub(crate) fn on_corner_edges(input: &PatternInput, c: usize) -> impl Fn(&[u32; 3]) -> bool {
    let nc = input.domain.corner_count();
    let prev = (c + nc - 1) % nc;
    let on_edges: Vec<u32> = (0..=input.segments[c])
        .map(|k| input.boundary_vertex(c, k))
        .chain((0..=input.segments[prev]).map(|k| input.boundary_vertex(prev, k)))
        .collect();
    move |t| t.iter().all(|v| on_edges.contains(v))
}

/// Flips edges crossing the segment `c v` until the triangulation has the edge `c v`:
/// Sloan's edge insertion — the crossing edges in a queue; one whose quad is convex is
/// flipped, and its new diagonal, if it still crosses, goes to the back of the queue, as does
/// an edge whose quad is not convex yet. It stops early (the triangulation valid as it is)
/// after a bounded number of tries. Cost: O(triangles) per try, O(k²) tries for k crossing
/// edges.
fn insert_edge(out: &mut LocalTessellation, positions: &[DVec2], c: u32, v: u32) {
    let (pc, pv) = (positions[c as usize], positions[v as usize]);
    let crosses = |p: u32, q: u32| {
        let (pp, pq) = (positions[p as usize], positions[q as usize]);
        let (sp, sq) = ((pv - pc).perp_dot(pp - pc), (pv - pc).perp_dot(pq - pc));
        let (sc, sv) = ((pq - pp).perp_dot(pc - pp), (pq - pp).perp_dot(pv - pp));
        sp * sq < 0.0 && sc * sv < 0.0
    };
    let mut queue: std::collections::VecDeque<(u32, u32)> = out
        .triangles
        .iter()
        .flat_map(|t| (0..3).map(move |r| (t[r], t[(r + 1) % 3])))
        .filter(|&(p, q)| p < q && crosses(p, q))
        .collect();
    let limit = 4 * (queue.len() + 1) * (queue.len() + 1);
    for _ in 0..limit {
        let Some((p, q)) = queue.pop_front() else { return };
        if find_edge(&out.triangles, p, q).is_none() {
            continue; // flipped away already
        }
        match flip(out, positions, p, q) {
            Some((r, s)) if crosses(r, s) => queue.push_back((r, s)),
            Some(_) => {}
            None => queue.push_back((p, q)),
        }
    }
}

/// The triangle that runs the edge from `p` to `q`.
fn find_edge(triangles: &[[u32; 3]], p: u32, q: u32) -> Option<usize> {
    triangles.iter().position(|t| (0..3).any(|r| t[r] == p && t[(r + 1) % 3] == q))
}

/// The vertex of `t` that is neither `p` nor `q`.
fn third(t: [u32; 3], p: u32, q: u32) -> u32 {
    t.into_iter().find(|&v| v != p && v != q).expect("a triangle has three corners")
}

/// Flips the inner edge `p q` (the triangles running `p → q` and `q → p`) to the quad's other
/// diagonal when both new triangles are positively oriented at `positions`, and returns that
/// diagonal; None (and nothing changed) otherwise.
fn flip(out: &mut LocalTessellation, positions: &[DVec2], p: u32, q: u32) -> Option<(u32, u32)> {
    let (i, j) = (find_edge(&out.triangles, p, q)?, find_edge(&out.triangles, q, p)?);
    let (r, s) = (third(out.triangles[i], p, q), third(out.triangles[j], q, p));
    let area = |t: [u32; 3]| {
        let [u, v, w] = t.map(|k| positions[k as usize]);
        (v - u).perp_dot(w - u)
    };
    // The quad runs p, s, q, r counter-clockwise; its other diagonal is r s.
    let (first, second) = ([r, p, s], [s, q, r]);
    if area(first) > 0.0 && area(second) > 0.0 {
        out.triangles[i] = first;
        out.triangles[j] = second;
        return Some((r, s));
    }
    None
}

/// The check every pattern's tests share: `out` is a valid conforming triangulation of the
/// domain given the vertex positions `p` (from [`PatternInput::local_positions`]) — indices
/// in range, every vertex used, interior vertices strictly inside, every triangle of signed
/// area above `min_area`, areas summing to the domain's, each directed edge used once, and
/// the edges without a reversed twin exactly the boundary segments in counter-clockwise
/// order. Positive orientation plus that boundary means every point of the domain is covered
/// exactly once: no fold-over, no gap, no T-junction.
#[cfg(test)]
pub(crate) fn assert_tiles(input: &PatternInput, out: &LocalTessellation, p: &[DVec2], min_area: f64) {
    let total = p.len();
    assert_eq!(total as u32, input.interior_base() + out.interior.len() as u32, "{input:?}: vertex count");
    for q in &out.interior {
        let inside = match input.domain {
            Domain::Quad => q.x > 0.0 && q.x < 1.0 && q.y > 0.0 && q.y < 1.0,
            Domain::Tri => q.x > 0.0 && q.y > 0.0 && q.x + q.y < 1.0,
        };
        assert!(inside, "{input:?}: interior vertex {q} not strictly inside");
    }
    let mut used = vec![false; total];
    let mut area = 0.0;
    for tri in &out.triangles {
        for &v in tri {
            assert!((v as usize) < total, "{input:?}: index {v} out of range");
            used[v as usize] = true;
        }
        let [a, b, c] = tri.map(|v| p[v as usize]);
        let s = (b - a).perp_dot(c - a) / 2.0;
        assert!(s > min_area, "{input:?}: triangle {tri:?} has signed area {s}");
        area += s;
    }
    assert!(used.iter().all(|&u| u), "{input:?}: unused local vertex");
    let domain_area = match input.domain {
        Domain::Quad => 1.0,
        Domain::Tri => 0.5,
    };
    assert!((area - domain_area).abs() < 1e-9, "{input:?}: area {area}");
    let mut directed: Vec<(u32, u32)> =
        out.triangles.iter().flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])]).collect();
    directed.sort_unstable();
    assert!(directed.windows(2).all(|w| w[0] != w[1]), "{input:?}: repeated directed edge");
    let mut boundary: Vec<(u32, u32)> =
        directed.iter().filter(|&&(a, b)| directed.binary_search(&(b, a)).is_err()).copied().collect();
    boundary.sort_unstable();
    let mut expected: Vec<(u32, u32)> = (0..input.domain.corner_count())
        .flat_map(|e| {
            (0..input.segments[e])
                .map(move |k| (input.boundary_vertex(e, k), input.boundary_vertex(e, k + 1)))
        })
        .collect();
    expected.sort_unstable();
    assert_eq!(boundary, expected, "{input:?}: boundary does not match the edge sampling");
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slots_follow_the_local_numbering() {
        let input = PatternInput::new(Domain::Quad, [2, 3, 1, 5], [4, 4]);
        let mut expected = vec![Slot::Corner(0), Slot::Corner(1), Slot::Corner(2), Slot::Corner(3)];
        for e in 0..4 {
            assert_eq!(input.edge_base(e) as usize, expected.len());
            for k in 1..input.segments[e] {
                expected.push(Slot::Edge(e, k));
            }
        }
        assert_eq!(input.interior_base() as usize, expected.len());
        expected.push(Slot::Interior(0));
        expected.push(Slot::Interior(1));
        for (l, s) in expected.iter().enumerate() {
            assert_eq!(input.slot(l as u32), *s, "local {l}");
        }
    }

    /// At a pinched corner no pattern leaves the chord triangle between the first samples of
    /// the corner's two edges, and the cut keeps a tiling of the domain with the pattern's own
    /// counts: every pattern an isolated subdivision face can be drawn with, over the factors
    /// and corners that matter (each edge 1–4 segments, interiors 1–5 each way, every corner).
    #[test]
    fn pinched_corners_are_cut_through_the_corner() {
        use crate::pattern::hardware::{Hardware, Partitioning};
        // The fractional partitionings run through tests/catmull_clark.rs on a cage with a
        // valence-2 vertex (their segments follow from real factors).
        let patterns: [&dyn Pattern; 4] = [
            &uniform::Uniform,
            &transition::Transition,
            &semi_uniform::SemiUniform,
            &Hardware { partitioning: Partitioning::Integer },
        ];
        let mut cut = 0;
        for pattern in patterns {
            // Quads: the patches of a subdivision cage, the only surfaces with pinched corners
            // (two triangles sharing two edges share all three corners: a duplicate face).
            {
                let domain = Domain::Quad;
                let nc = domain.corner_count();
                for code in 0..4u32.pow(nc as u32) {
                    let segments: [u32; 4] =
                        std::array::from_fn(|e| if e < nc { 1 + (code >> (2 * e)) % 4 } else { 1 });
                    let top = *segments.iter().max().unwrap();
                    let interiors: Vec<[u32; 2]> = match pattern.name() {
                        "uniform" if segments[..nc].iter().any(|&s| s != top) => continue,
                        "uniform" => vec![[top, top]],
                        "semi-uniform" if segments[..nc].iter().any(|s| !s.is_power_of_two()) => continue,
                        "semi-uniform" => vec![[top, top]],
                        _ => (1..=5).flat_map(|n| (1..=5).map(move |m| [n, m])).collect(),
                    };
                    for interior in interiors {
                        for c in 0..nc {
                            let mut input = PatternInput::new(domain, segments, interior);
                            input.pinched[c] = true;
                            let mut plain = LocalTessellation::default();
                            pattern.triangulate(&input, &mut plain);
                            let mut out = LocalTessellation::default();
                            pattern.build(&input, &mut out);
                            assert_eq!(
                                pattern.counts(&input),
                                (out.interior.len() as u32, out.triangles.len() as u32),
                                "{} {input:?}",
                                pattern.name()
                            );
                            let prev = (c + nc - 1) % nc;
                            let a = input.boundary_vertex(c, 1);
                            let b = input.boundary_vertex(prev, input.segments[prev] - 1);
                            let chord =
                                |t: &[u32; 3]| t.contains(&(c as u32)) && t.contains(&a) && t.contains(&b);
                            assert!(
                                !out.triangles.iter().any(chord),
                                "{} {input:?}: a triangle on the corner's two edges stayed",
                                pattern.name()
                            );
                            cut += usize::from(plain.triangles.iter().any(chord));
                            let mut p = Vec::new();
                            cache::local_params(&input, &out, &mut p);
                            assert_tiles(&input, &out, &p, 0.0);
                        }
                    }
                }
            }
        }
        assert!(cut > 100, "only {cut} inputs had a chord to cut: the test sees too little");
    }
}
