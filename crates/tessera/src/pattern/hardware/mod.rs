//! The Direct3D 11 hardware tessellator's patterns: `integer`, `pow2`, `fractional_odd` and
//! `fractional_even` partitioning of triangle and quad domains, point for point and triangle
//! for triangle what a Direct3D 11 or Vulkan GPU's fixed-function tessellator emits.
//!
//! **Why exact.** Users porting hull/domain-shader code to compute expect the mesh their
//! hardware made, and every such GPU follows the D3D11 reference tessellator. This module is
//! written from that tessellator's documented behaviour and checked against its output on 200
//! random factor sets (`../shared/data/reference/d3d11_tessellator.json`, test
//! `tests/hardware_reference.rs`); it is structured our own way (rings as point cycles rather
//! than index patching).
//!
//! **Factors.** Edge factors are clamped to the partitioning's range (`integer`/`pow2`
//! `[1, 64]`, `fractional_odd` `[1, 63]`, `fractional_even` `[2, 64]`; NaN reads as the
//! minimum), rounded up for `integer`/`pow2`, then converted to 16.16 fixed point; the
//! hardware makes no `pow2` distinction (rounding to powers of two is the hull shader's job,
//! done by tessera's criterion). An edge factor `≤ 0` culls the patch. Inside factors get the
//! same treatment, except that `fractional_odd` raises an inside factor of 1 to `1 + 2⁻¹⁶`
//! when any factor exceeds 1, so the patch gets a "picture frame" of interior points.
//! `integer` picks each factor's parity from its rounded value (an inside factor of 1 counts
//! as even); the fractional partitionings use their own parity everywhere.
//!
//! **1-D partition** ([`Axis`]). A factor `f` with parity cuts `[0, 1]` symmetrically; half the
//! factor, `h = f/2` (plus ½ for odd), lies between `⌊h⌋` and `⌈h⌉`, and each point of the half
//! edge is the blend, by `h − ⌊h⌋`, of its place in the uniform partitions with `2⌊h⌋` and
//! `2⌈h⌉` segments (less one for odd). Which point is the new one on the floor partition is
//! decided by a bit-pattern rule (the "ruler function"): the split point is
//! `2·removeMSB(⌊h⌋ − [odd]) + 1`. The other half mirrors the first exactly (`1 − x` in fixed
//! point), so an edge's points depend only on its factor and partitioning: two patches
//! sharing an edge get the same points whichever way they run along it.
//!
//! **Rings.** The outer ring is the four (three) edges' points, clockwise in Direct3D's
//! picture (v down); inner rings follow, each from the inside factors with the factor reduced
//! by two per ring; an even inside partition ends in a degenerate ring (a row of points, or
//! the centre point). The band between the outer ring and ring 1 is stitched by the
//! ruler-function transition (the final-point-position table in `stitch.rs`), inner bands by trapezoids with mirrored
//! diagonals, and what is left in the middle by a strip of quads (quads) or one triangle.
//!
//! **Orientation.** Triangles here are counter-clockwise in the `(u, v)` plane, tessera's
//! convention — Direct3D's `triangle_cw` output order; its `triangle_ccw` is the reverse.
//!
//! **Costs.** [`edge_segments`] and [`edge_param`] are O(1); counting (`Pattern::counts`) is O(rings); building
//! ([`tessellate`]) is linear in the output.

use super::{LocalTessellation, Pattern, PatternInput};
use crate::domain::Domain;
use crate::sampling::hardware::{
    clamp, parity_odd, to_f64, to_fixed, Fixed, EPSILON, FRACTION_BITS, HALF, ONE, ONE_THIRD, TWO_THIRDS,
};
use glam::DVec2;
use std::cell::RefCell;
use stitch::{Diagonals, Emit};

mod stitch;
#[cfg(test)]
mod tests;

pub use crate::sampling::hardware::{
    edge_param, edge_segments, settled_factor, Axis, Partitioning, OUTPUT_GAP,
};

/// Factors processed for one patch.
#[derive(Debug, Clone, Copy)]
struct Processed {
    domain: Domain,
    /// All factors 1 (integer and odd modes): the bare domain, 2 (1) triangles.
    minimum: bool,
    /// Edge partitions in Direct3D's edge order (quad `U==0, V==0, U==1, V==1`; tri
    /// `U==0, V==0, W==0`).
    outer: [Axis; 4],
    /// Inside partitions (quad `U, V`; tri `[inside, inside]`), at least 4 points (odd) or 3
    /// (even).
    inside: [Axis; 2],
}

impl Processed {
    /// `None` when an edge factor is not positive (Direct3D culls the patch).
    fn new(domain: Domain, partitioning: Partitioning, edges: [f32; 4], inside: [f32; 2]) -> Option<Self> {
        let n = domain.corner_count();
        let edges = &edges[..n];
        let inside = &inside[..if domain == Domain::Quad { 2 } else { 1 }];
        // Not `f <= 0`: a NaN factor culls the patch too, as in the hardware.
        if edges.iter().any(|f| f.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater)) {
            return None;
        }
        let (lo, hi) = partitioning.range();
        let mut e = [0f32; 4];
        for (k, &f) in edges.iter().enumerate() {
            e[k] = clamp(f, lo, hi, partitioning);
        }
        let e = &e[..n];
        let frame_threshold = 1.0 + EPSILON / 2.0;
        // Quads also look at the raw inside factors; triangles have only one.
        let frame = partitioning == Partitioning::FractionalOdd
            && (e.iter().any(|&f| f > frame_threshold)
                || (domain == Domain::Quad && inside.iter().any(|&f| f > frame_threshold)));
        let inside_lo = if frame { 1.0 + EPSILON } else { lo };
        let mut i = [0f32; 2];
        for (k, &f) in inside.iter().enumerate() {
            i[k] = clamp(f, inside_lo, hi, partitioning);
        }
        let i = &i[..inside.len()];
        let minimum = (partitioning.is_integer() || partitioning == Partitioning::FractionalOdd)
            && e.iter().chain(i).all(|&f| to_fixed(f) == ONE);
        let mut outer = [Axis::new(ONE, true); 4];
        for k in 0..n {
            outer[k] = Axis::new(to_fixed(e[k]), parity_odd(e[k], partitioning, false));
        }
        let inner: [Axis; 2] = std::array::from_fn(|k| {
            let j = k.min(i.len() - 1);
            let mut a = Axis::new(to_fixed(i[j]), parity_odd(i[j], partitioning, true));
            // Fewer points would leave no interior: the transition regions degenerate instead.
            a.points = a.points.max(if a.odd { 4 } else { 3 });
            a
        });
        Some(Processed { domain, minimum, outer, inside: inner })
    }

    fn outer_points(&self) -> i64 {
        (0..self.domain.corner_count()).map(|e| self.outer[e].points - 1).sum()
    }

    /// Number of points and triangles. Cost: O(rings).
    fn counts(&self) -> (u32, u32) {
        let nc = self.domain.corner_count();
        if self.minimum {
            return (nc as u32, nc as u32 - 2);
        }
        let outer = self.outer_points();
        match self.domain {
            Domain::Quad => {
                let n = [self.inside[0].points, self.inside[1].points];
                let interior = (n[0] - 2) * (n[1] - 2);
                let rings = ((n[0] + 1) >> 1).min((n[1] + 1) >> 1);
                // Side e of ring r has n[axis(e)] − 2r points; axis(e) = (e + 1) & 1.
                let side = |e: usize, r: i64| n[(e + 1) & 1] - 2 * r;
                let mut tris = 0;
                for r in 1..rings {
                    for e in 0..4 {
                        let out = if r == 1 { self.outer[e].points } else { side(e, r - 1) };
                        tris += side(e, r) + out - 2;
                    }
                }
                if let Some((quads, ..)) = self.centre_strip() {
                    tris += 2 * quads;
                }
                ((outer + interior) as u32, tris as u32)
            }
            Domain::Tri => {
                let n = self.inside[0].points;
                let k = (n >> 1) - 1;
                let interior = if self.inside[0].odd { 3 * (k * (k + 1) - k) } else { 3 * k * (k + 1) + 1 };
                let rings = (n + 1) >> 1;
                let mut tris = 0;
                for r in 1..rings {
                    for e in 0..3 {
                        let out = if r == 1 { self.outer[e].points } else { n - 2 * (r - 1) };
                        tris += n - 2 * r + out - 2;
                    }
                }
                if self.inside[0].odd {
                    tris += 1;
                }
                ((outer + interior) as u32, tris as u32)
            }
        }
    }

    /// The strip of quads left in the middle of a quad whose smaller inside partition is odd:
    /// `(quads, horizontal)` — along u when the u partition has more points.
    fn centre_strip(&self) -> Option<(i64, bool)> {
        let [u, v] = self.inside;
        if u.points > v.points && v.odd {
            Some((((u.points >> 1) - (v.points >> 1)) * 2 + if u.odd { 1 } else { 2 }, true))
        } else if v.points >= u.points && u.odd {
            Some((((v.points >> 1) - (u.points >> 1)) * 2 + if v.odd { 1 } else { 2 }, false))
        } else {
            None
        }
    }
}

/// One ring of points as a cycle, split into sides that share their end points. Most rings
/// are a run of consecutive point indices, kept as `start..start + len` without a vector.
#[derive(Debug, Clone, Default)]
struct Ring {
    start: u32,
    len: u32,
    /// The cycle when it is not a run of consecutive indices (the degenerate ring).
    cycle: Vec<u32>,
    side_points: [u32; 4],
}

impl Ring {
    /// Empties the ring, keeping its cycle's allocation.
    fn reset(&mut self) {
        self.start = 0;
        self.len = 0;
        self.cycle.clear();
        self.side_points = [0; 4];
    }

    /// Makes the ring the explicit cycle `points` (the degenerate ring).
    fn set_cycle(&mut self, points: &[u32], side_points: [u32; 4]) {
        self.reset();
        self.cycle.extend_from_slice(points);
        self.len = points.len() as u32;
        self.side_points = side_points;
    }

    /// Appends point `id` to the cycle.
    fn push(&mut self, id: u32) {
        if self.cycle.is_empty() && (self.len == 0 || id == self.start + self.len) {
            if self.len == 0 {
                self.start = id;
            }
        } else {
            if self.cycle.is_empty() {
                self.cycle.extend(self.start..self.start + self.len);
            }
            self.cycle.push(id);
        }
        self.len += 1;
    }

    /// Point `i` of the cycle (wrapping).
    fn point(&self, i: u32) -> u32 {
        let i = i % self.len;
        if self.cycle.is_empty() {
            self.start + i
        } else {
            self.cycle[i as usize]
        }
    }

    /// The points of side `e` into `out` (the last side wraps to the first point).
    fn side_into(&self, e: usize, out: &mut Vec<u32>) {
        let offset: u32 = self.side_points[..e].iter().map(|n| n - 1).sum();
        out.clear();
        out.extend((0..self.side_points[e]).map(|j| self.point(offset + j)));
    }
}

/// The rings of one tessellation and the stitching's side buffers, kept per thread so that
/// tessellating a patch allocates nothing once they have grown.
#[derive(Default)]
struct Rings {
    rings: Vec<Ring>,
    used: usize,
    outer: Vec<u32>,
    inner: Vec<u32>,
    line: Vec<u32>,
}

impl Rings {
    /// The next ring, empty.
    fn next(&mut self) -> &mut Ring {
        if self.used == self.rings.len() {
            self.rings.push(Ring::default());
        }
        self.used += 1;
        let ring = &mut self.rings[self.used - 1];
        ring.reset();
        ring
    }
}

thread_local! {
    static RINGS: std::cell::RefCell<Rings> = std::cell::RefCell::default();
}

/// The Direct3D 11 tessellation of one domain.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct HardwareTessellation {
    /// Domain points `(u, v)` in the hardware's output order (tri: `w = 1 − u − v`).
    pub points: Vec<DVec2>,
    /// Triangles, counter-clockwise in `(u, v)`, in the hardware's output order.
    pub triangles: Vec<[u32; 3]>,
    /// The band each triangle belongs to: 1 the transition from the outer edges, `r` the band
    /// between rings `r − 1` and `r`, and one more than the last ring for the centre.
    pub regions: Vec<u32>,
    /// Points on each edge (ends included), in Direct3D's edge order.
    pub edge_points: [u32; 4],
}

/// The Direct3D 11 tessellation of `domain` for edge factors in Direct3D's edge order (quad
/// `[U==0, V==0, U==1, V==1]`, tri `[U==0, V==0, W==0]`; entries past the edge count are
/// ignored) and inside factors (quad `[U, V]`, tri `[inside]`), given as the hardware gets them
/// (no reduction). `None` when an edge factor is not positive or is NaN-free and `≤ 0` —
/// Direct3D culls such a patch. Cost: linear in the output.
pub fn tessellate(
    domain: Domain,
    partitioning: Partitioning,
    edges: [f32; 4],
    inside: [f32; 2],
) -> Option<HardwareTessellation> {
    let mut out = HardwareTessellation::default();
    tessellate_into(domain, partitioning, edges, inside, &mut out).then_some(out)
}

/// [`tessellate`] into `out`, reusing its buffers; false (and `out` emptied) when the hardware
/// culls the patch. Cost: linear in the output, no allocation once `out` has grown.
pub fn tessellate_into(
    domain: Domain,
    partitioning: Partitioning,
    edges: [f32; 4],
    inside: [f32; 2],
    out: &mut HardwareTessellation,
) -> bool {
    out.points.clear();
    out.triangles.clear();
    out.regions.clear();
    out.edge_points = [0; 4];
    let Some(pre) = Processed::new(domain, partitioning, edges, inside) else { return false };
    for e in 0..domain.corner_count() {
        out.edge_points[e] = pre.outer[e].points as u32;
    }
    if pre.minimum {
        match domain {
            Domain::Quad => {
                out.points.extend([DVec2::ZERO, DVec2::X, DVec2::ONE, DVec2::Y]);
                let mut emit = Emit { out, region: 1 };
                emit.tri(0, 1, 3);
                emit.tri(1, 2, 3);
            }
            Domain::Tri => {
                out.points.extend([DVec2::Y, DVec2::ZERO, DVec2::X]);
                Emit { out, region: 1 }.tri(0, 1, 2);
            }
        }
        return true;
    }
    let (points, triangles) = pre.counts();
    out.points.reserve(points as usize);
    out.triangles.reserve(triangles as usize);
    RINGS.with_borrow_mut(|rings| {
        rings.used = 0;
        match domain {
            Domain::Quad => quad(&pre, out, rings),
            Domain::Tri => tri(&pre, out, rings),
        }
    });
    debug_assert_eq!((out.points.len() as u32, out.triangles.len() as u32), (points, triangles));
    true
}

fn push(out: &mut HardwareTessellation, u: Fixed, v: Fixed) -> u32 {
    out.points.push(DVec2::new(to_f64(u), to_f64(v)));
    out.points.len() as u32 - 1
}

/// The outer ring: each edge's points but its last, clockwise in Direct3D's picture.
fn outer_ring(
    pre: &Processed,
    out: &mut HardwareTessellation,
    ring: &mut Ring,
    point: impl Fn(usize, Fixed) -> (Fixed, Fixed),
) {
    for e in 0..pre.domain.corner_count() {
        let axis = &pre.outer[e];
        let end = axis.points - 1;
        for p in 0..end {
            let q = if reversed(pre.domain, e) { end - p } else { p };
            let (u, v) = point(e, axis.place(q));
            ring.push(push(out, u, v));
        }
        ring.side_points[e] = axis.points as u32;
    }
}

/// Whether edge `e`'s points run against its 1-D partition (the outer ring and the rings are
/// written clockwise in Direct3D's picture).
fn reversed(domain: Domain, e: usize) -> bool {
    match domain {
        Domain::Quad => !(e == 1 || e == 2),
        Domain::Tri => e % 2 == 0,
    }
}

/// Stitches the band between each pair of consecutive rings, side by side: the ruler-function
/// transition from the outer edges to ring 1 (`inside(e)` is the partition along side `e`),
/// trapezoids with mirrored diagonals further in.
fn stitch_bands<'a>(
    pre: &'a Processed,
    rings: &mut Rings,
    band_rings: usize,
    inside: impl Fn(usize) -> &'a Axis,
    out: &mut HardwareTessellation,
) {
    debug_assert_eq!(band_rings, rings.used);
    let Rings { rings, outer, inner, .. } = rings;
    for r in 1..band_rings {
        let mut emit = Emit { out, region: r as u32 };
        for e in 0..pre.domain.corner_count() {
            rings[r - 1].side_into(e, outer);
            rings[r].side_into(e, inner);
            if r == 1 {
                emit.transition(inner, inside(e), outer, &pre.outer[e]);
            } else {
                emit.regular(true, Diagonals::Mirrored, inner, outer);
            }
        }
    }
}

fn quad(pre: &Processed, out: &mut HardwareTessellation, rings: &mut Rings) {
    let [iu, iv] = pre.inside;
    let n = [iu.points, iv.points];
    outer_ring(pre, out, rings.next(), |e, x| match e {
        0 => (0, x),
        1 => (x, 0),
        2 => (ONE, x),
        _ => (x, ONE),
    });
    // Inner rings; side e runs along axis (e + 1) & 1 at a fixed coordinate of the other.
    let point_rings = n[0].min(n[1]) >> 1;
    for r in 1..point_rings {
        let end = [n[0] - 1 - r, n[1] - 1 - r];
        let ring = rings.next();
        for e in 0..4 {
            let (across, along) = (e & 1, (e + 1) & 1);
            let perp_point = if e < 2 { r } else { end[across] };
            let perp = pre.inside[across].place(perp_point);
            for p in r..end[along] {
                let q = if e == 1 || e == 2 { p } else { end[along] - (p - r) };
                let x = pre.inside[along].place(q);
                let id = if along == 1 { push(out, perp, x) } else { push(out, x, perp) };
                ring.push(id);
            }
            ring.side_points[e] = (n[along] - 2 * r) as u32;
        }
    }
    // An even inside partition ends in a degenerate ring: a row (or column, or one point)
    // through the middle, its sides running along it and back.
    let r = point_rings;
    let line = &mut rings.line;
    line.clear();
    let degenerate = if n[0] > n[1] && !iv.odd {
        line.extend((r..=n[0] - 1 - r).map(|p| push(out, iu.place(p), HALF)));
        let m = line.len() as u32;
        Some([1, m, 1, m])
    } else if n[1] >= n[0] && !iu.odd {
        line.extend((r..=n[1] - 1 - r).rev().map(|p| push(out, HALF, iv.place(p))));
        let m = line.len() as u32;
        Some([m, 1, m, 1])
    } else {
        None
    };
    if let Some(side_points) = degenerate {
        // The cycle: along the line and back (the inner buffer holds it).
        let m = line.len();
        let cycle = &mut rings.inner;
        cycle.clear();
        cycle.extend_from_slice(line);
        if m > 1 {
            cycle.extend(line[1..m - 1].iter().rev());
        }
        let side_points = if m == 1 { [1; 4] } else { side_points };
        let cycle = std::mem::take(cycle);
        rings.next().set_cycle(&cycle, side_points);
        rings.inner = cycle;
    }
    let band_rings = ((n[0] + 1) >> 1).min((n[1] + 1) >> 1) as usize;
    stitch_bands(pre, rings, band_rings, |e| &pre.inside[(e + 1) & 1], out);
    // A strip of quads in the middle when the smaller inside partition is odd.
    if let Some((quads, horizontal)) = pre.centre_strip() {
        let Rings { rings, used, outer, inner, .. } = rings;
        let last = &rings[*used - 1];
        let mut emit = Emit { out, region: band_rings as u32 };
        let (a, b) = if horizontal { (1, 3) } else { (0, 2) };
        last.side_into(a, outer);
        last.side_into(b, inner);
        inner.reverse();
        debug_assert_eq!(inner.len() as i64, quads + 1);
        let diagonals = if !horizontal && iv.odd {
            Diagonals::InsideToOutsideExceptMiddle
        } else {
            Diagonals::InsideToOutside
        };
        emit.regular(false, diagonals, inner, outer);
    }
}

fn tri(pre: &Processed, out: &mut HardwareTessellation, rings: &mut Rings) {
    let axis = pre.inside[0];
    let n = axis.points;
    outer_ring(pre, out, rings.next(), |e, x| match e {
        0 => (0, x),
        1 => (x, 0),
        _ => (x, ONE - x),
    });
    for r in 1..n >> 1 {
        let end = n - 1 - r;
        // The ring's distance from each side, scaled to barycentric size (2/3 of the 1-D
        // position), and the along-side parameters pushed in by half of it.
        let perp = (axis.place(r) * TWO_THIRDS + HALF) >> FRACTION_BITS;
        let shift = (perp + 1) / 2;
        let ring = rings.next();
        for e in 0..3 {
            for p in r..end {
                let q = if e % 2 == 1 { p } else { end - (p - r) };
                let x = axis.place(q) - shift;
                let id = match e {
                    0 => push(out, perp, x),
                    1 => push(out, x, perp),
                    _ => push(out, x, ONE - x - perp),
                };
                ring.push(id);
            }
            ring.side_points[e] = (n - 2 * r) as u32;
        }
    }
    if !axis.odd {
        let centre = push(out, ONE_THIRD, ONE_THIRD);
        rings.next().set_cycle(&[centre], [1; 4]);
    }
    let band_rings = ((n + 1) >> 1) as usize;
    stitch_bands(pre, rings, band_rings, |_| &axis, out);
    if axis.odd {
        let last = &rings.rings[band_rings - 1];
        Emit { out, region: band_rings as u32 }.tri(last.point(0), last.point(1), last.point(2));
    }
}

/// Direct3D's edge order from tessera's: quad `U==0, V==0, U==1, V==1` are tessera's edges
/// 3, 0, 1, 2; tri `U==0, V==0, W==0` are edges 2, 0, 1 (with `(u, v)` the same in both).
pub fn d3d_edge(domain: Domain, tessera_edge: usize) -> usize {
    match domain {
        Domain::Quad => (tessera_edge + 1) % 4,
        Domain::Tri => (tessera_edge + 1) % 3,
    }
}

/// Tessera's edge of Direct3D edge `d`, and whether tessera runs along it against the 1-D
/// partition's direction (so that 1-D point `q` is tessera's point `segments − q`).
fn tessera_edge(domain: Domain, d: usize) -> (usize, bool) {
    match domain {
        // Edges 0 (v = 0) and 1 (u = 1) run with u and v; 2 and 3 against them.
        Domain::Quad => {
            let e = (d + 3) % 4;
            (e, e >= 2)
        }
        // Edge 0 (v = 0) runs with u; edge 1 (from (1,0) to (0,1)) with v = 1 − u against
        // the partition of u; edge 2 (u = 0, from (0,1) to (0,0)) against v.
        Domain::Tri => {
            let e = (d + 2) % 3;
            (e, e >= 1)
        }
    }
}

/// The hardware pattern, fed by tessera's criteria.
///
/// Preconditions: every edge's `input.segments[e]` is [`edge_segments`] of `input.factors[e]`
/// (the engine guarantees it for [`crate::sampling::Spacing::Hardware`] samplings);
/// `input.interior` is ignored: the inside factors come from the edge factors by Direct3D's
/// `max` reduction (triangle: the largest edge factor; quad: inside-u the larger of the two
/// edges along u, inside-v likewise; for `fractional_odd` quads each raised to at least the
/// other's, capped at 3, so that no ring lies on the boundary). Cost: linear in the output.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Hardware {
    pub partitioning: Partitioning,
}

impl Hardware {
    /// Direct3D edge and inside factors of a patch, in Direct3D's order.
    fn factors(&self, input: &PatternInput) -> ([f32; 4], [f32; 2]) {
        let d = input.domain;
        let mut edges = [1.0f32; 4];
        for e in 0..d.corner_count() {
            edges[d3d_edge(d, e)] = input.factors[e] as f32;
        }
        let mut inside = match d {
            Domain::Quad => [edges[1].max(edges[3]), edges[0].max(edges[2])],
            Domain::Tri => [edges[0].max(edges[1]).max(edges[2]); 2],
        };
        // fractional_odd with an inside factor of 1 beside a larger one: the hardware forces a
        // "picture frame" of factor 1 + 2⁻¹⁶, whose ring lies exactly on the boundary, and its
        // transition then emits zero-area triangles along the edges — fins on a shared curve,
        // emitted by both neighbours (found by fuzzing). Like HLSL's rule for small odd inside
        // factors, raise it to the other one, at most 3; the edges are untouched, so
        // neighbours still agree.
        if d == Domain::Quad && self.partitioning == Partitioning::FractionalOdd {
            let [u, v] = inside;
            inside = [u.max(v.min(3.0)), v.max(u.min(3.0))];
        }
        (edges, inside)
    }

    fn processed(&self, input: &PatternInput) -> Processed {
        let (edges, inside) = self.factors(input);
        // Tessera's factors are at least 1, so the hardware never culls here.
        Processed::new(input.domain, self.partitioning, edges, inside).expect("edge factors are positive")
    }
}

impl Pattern for Hardware {
    /// The partitioning's Direct3D name (`fractional_odd`, ...).
    fn name(&self) -> &'static str {
        self.partitioning.name()
    }

    /// Direct3D's quad pattern joins each ring of points to the next ring inside it, so every
    /// triangle at a corner has a vertex on the first inner ring, which lies strictly inside
    /// the domain (an inside factor of 1 beside a larger one makes it a segment across the
    /// middle, still inside). Only where both inside factors are 1 is there no inner ring:
    /// the quad is then two triangles, split along the diagonal from corner 0 to corner 2
    /// (tessera's numbering). So a patch pinched at corners 0 and 2 needs no cut, and the
    /// GPU, which does not run [`crate::pattern::cut_pinched_corners`], draws it as the CPU
    /// does. Checked for every partitioning over every integer factor 1–8 on each edge and
    /// thousands of real ones (`tests::corners_0_and_2_keep_a_vertex_off_their_edges`).
    fn cut_through_corners_0_and_2(&self) -> bool {
        true
    }

    /// O(rings).
    fn counts(&self, input: &PatternInput) -> (u32, u32) {
        let pre = self.processed(input);
        let (points, triangles) = pre.counts();
        (points - pre.outer_points() as u32, triangles)
    }

    fn triangulate(&self, input: &PatternInput, out: &mut LocalTessellation) {
        out.interior.clear();
        out.triangles.clear();
        let d = input.domain;
        let (edges, inside) = self.factors(input);
        // One scratch per thread: the engine builds many patches on each.
        thread_local! {
            static SCRATCH: RefCell<(HardwareTessellation, Vec<u32>)> = RefCell::default();
        }
        SCRATCH.with_borrow_mut(|(hw, local)| {
            let positive = tessellate_into(d, self.partitioning, edges, inside, hw);
            assert!(positive, "edge factors are positive");
            debug_assert!(
                (0..d.corner_count()).all(|e| input.segments[e] + 1 == hw.edge_points[d3d_edge(d, e)]),
                "hardware pattern: segments do not match factors: {input:?}"
            );
            // Local index of every hardware point: the outer ring's points are tessera's
            // boundary points, the rest interior in the hardware's order.
            local.clear();
            for dd in 0..d.corner_count() {
                let (e, against) = tessera_edge(d, dd);
                let end = hw.edge_points[dd] - 1;
                for p in 0..end {
                    let q = if reversed(d, dd) { end - p } else { p };
                    let k = if against { end - q } else { q };
                    local.push(input.boundary_vertex(e, k));
                }
            }
            let outer = local.len();
            let base = input.interior_base();
            local.extend((0..(hw.points.len() - outer) as u32).map(|j| base + j));
            out.interior.extend_from_slice(&hw.points[outer..]);
            out.triangles.extend(hw.triangles.iter().map(|t| t.map(|v| local[v as usize])));
        });
    }
}
