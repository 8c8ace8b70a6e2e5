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
//! ruler-function transition ([`FINAL_POINT_POSITION`]), inner bands by trapezoids with mirrored
//! diagonals, and what is left in the middle by a strip of quads (quads) or one triangle.
//!
//! **Orientation.** Triangles here are counter-clockwise in the `(u, v)` plane, tessera's
//! convention — Direct3D's `triangle_cw` output order; its `triangle_ccw` is the reverse.
//!
//! **Costs.** [`edge_segments`] and [`edge_param`] are O(1); [`counts`] is O(rings); building
//! ([`tessellate`]) is linear in the output.

use super::{LocalTessellation, Pattern, PatternInput};
use crate::surface::Domain;
use glam::DVec2;

/// A Direct3D 11 partitioning mode.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Partitioning {
    /// Factors rounded up to integers, each with its own parity; uniform edge points.
    Integer,
    /// As `Integer` in the hardware; tessera's criteria round factors up to powers of two.
    Pow2,
    /// Real factors in `[1, 63]`, odd segment counts, points move continuously.
    FractionalOdd,
    /// Real factors in `[2, 64]`, even segment counts, points move continuously.
    FractionalEven,
}

impl Partitioning {
    /// The factor range the hardware clamps to.
    pub fn range(self) -> (f32, f32) {
        match self {
            Partitioning::Integer | Partitioning::Pow2 => (1.0, 64.0),
            Partitioning::FractionalOdd => (1.0, 63.0),
            Partitioning::FractionalEven => (2.0, 64.0),
        }
    }

    /// True for the partitionings that round factors up to integers.
    pub fn is_integer(self) -> bool {
        matches!(self, Partitioning::Integer | Partitioning::Pow2)
    }

    /// The name Direct3D / HLSL gives the mode.
    pub fn name(self) -> &'static str {
        match self {
            Partitioning::Integer => "integer",
            Partitioning::Pow2 => "pow2",
            Partitioning::FractionalOdd => "fractional_odd",
            Partitioning::FractionalEven => "fractional_even",
        }
    }

    /// The factor the hull-shader side hands to the hardware: `pow2` rounds up to a power of
    /// two (clamped to 64), the others pass `factor` through. Cost: O(1).
    pub fn hull_factor(self, factor: f64) -> f64 {
        match self {
            Partitioning::Pow2 if factor > 1.0 => factor.min(64.0).log2().ceil().exp2(),
            _ => factor,
        }
    }
}

/// 16.16 fixed point, held in 64 bits so no intermediate product overflows (the hardware's
/// 32-bit unsigned arithmetic never wraps on these ranges, so the results are the same).
type Fixed = i64;
const FRACTION_BITS: u32 = 16;
const ONE: Fixed = 1 << FRACTION_BITS;
const HALF: Fixed = ONE >> 1;
const ONE_THIRD: Fixed = 0x5555;
const TWO_THIRDS: Fixed = 0xaaaa;
/// `2⁻¹⁶`, the smallest positive fixed-point fraction.
const EPSILON: f32 = 1.0 / 65536.0;

/// `x ≥ 0` (below 2¹⁵) to fixed point, rounding to nearest, ties to even, as the hardware's
/// float-to-fixed conversion does. Exact: `x · 2¹⁶` of an `f32` is exact in `f64`.
fn to_fixed(x: f32) -> Fixed {
    (x as f64 * ONE as f64).round_ties_even() as Fixed
}

/// Fixed point to `f64`, exactly.
fn to_f64(x: Fixed) -> f64 {
    x as f64 / ONE as f64
}

fn fixed_floor(x: Fixed) -> Fixed {
    x & !(ONE - 1)
}

fn fixed_ceil(x: Fixed) -> Fixed {
    if x & (ONE - 1) != 0 {
        fixed_floor(x) + ONE
    } else {
        x
    }
}

/// `1/n` in fixed point, rounded to nearest: the hardware's reciprocal table (`1 ≤ n ≤ 64`;
/// no `65536/n` is a tie in that range).
fn reciprocal(n: i64) -> Fixed {
    (ONE + n / 2) / n
}

/// `v` without its most significant set bit (0 for `v ≤ 0`).
fn remove_msb(v: i64) -> i64 {
    if v <= 0 {
        0
    } else {
        v & !(1 << (63 - v.leading_zeros()))
    }
}

/// Where vertex `i` of the half edge ends up at the largest factor, in ruler-function split
/// order: the transition stitch advances on a row when the row has a point at that position.
/// It covers half edges of up to 32 points (odd factors up to 65, even up to 64).
const FINAL_POINT_POSITION: [i32; 33] = [
    0, 32, 16, 8, 17, 4, 18, 9, 19, 2, 20, 10, 21, 5, 22, 11, 23, 1, 24, 12, 25, 6, 26, 13, 27, 3, 28, 14,
    29, 7, 30, 15, 31,
];

/// The 1-D partition of one processed factor: what the hardware calls a tess-factor context,
/// with its parity.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Axis {
    odd: bool,
    /// `h − ⌊h⌋` of the half factor `h`.
    half_fraction: Fixed,
    /// `⌈h⌉`: points on the half edge (for even, without the midpoint).
    half_points: i64,
    /// The point that is split off on the floor partition (ignored when `h` is an integer).
    split_point: i64,
    inv_floor_segments: Fixed,
    inv_ceil_segments: Fixed,
    /// Points on the whole edge, ends included.
    points: i64,
}

impl Axis {
    /// The partition of fixed-point factor `f` with the given parity.
    fn new(f: Fixed, odd: bool) -> Axis {
        let mut half = (f + 1) / 2;
        // A factor of 1 with even parity behaves as odd here (its half is exactly ½).
        if odd || half == HALF {
            half += HALF;
        }
        let floor = fixed_floor(half);
        let ceil = fixed_ceil(half);
        let half_points = ceil >> FRACTION_BITS;
        let split_point = if ceil == floor {
            half_points + 1
        } else if odd {
            if floor == ONE {
                0
            } else {
                (remove_msb((floor >> FRACTION_BITS) - 1) << 1) + 1
            }
        } else {
            (remove_msb(floor >> FRACTION_BITS) << 1) + 1
        };
        let odd_less = i64::from(odd);
        let floor_segments = ((floor * 2) >> FRACTION_BITS) - odd_less;
        let ceil_segments = ((ceil * 2) >> FRACTION_BITS) - odd_less;
        let points = if odd {
            (fixed_ceil(HALF + (f + 1) / 2) * 2) >> FRACTION_BITS
        } else {
            ((fixed_ceil((f + 1) / 2) * 2) >> FRACTION_BITS) + 1
        };
        Axis {
            odd,
            half_fraction: half - floor,
            half_points,
            split_point,
            inv_floor_segments: reciprocal(floor_segments.max(1)),
            inv_ceil_segments: reciprocal(ceil_segments.max(1)),
            points,
        }
    }

    /// The partition of an edge with real factor `factor` under `partitioning` (clamped,
    /// rounded and converted as the hardware does with an edge factor `> 0`).
    pub fn edge(factor: f64, partitioning: Partitioning) -> Axis {
        let (lo, hi) = partitioning.range();
        let f = clamp(factor as f32, lo, hi, partitioning);
        Axis::new(to_fixed(f), parity_odd(f, partitioning, false))
    }

    /// Number of segments.
    pub fn segments(&self) -> u32 {
        (self.points - 1) as u32
    }

    /// Point `k` (`0 ≤ k < points`) in fixed point.
    fn place(&self, k: i64) -> Fixed {
        let (mut point, flip) = if k >= self.half_points {
            ((self.half_points << 1) - k - i64::from(self.odd), true)
        } else {
            (k, false)
        };
        // The middle point is exactly ½; the blend below could not reproduce it.
        if point == self.half_points {
            return HALF;
        }
        let on_ceil = point;
        if point > self.split_point {
            point -= 1;
        }
        let on_floor = point;
        let location = on_floor * self.inv_floor_segments * (ONE - self.half_fraction)
            + on_ceil * self.inv_ceil_segments * self.half_fraction;
        let location = (location + HALF) >> FRACTION_BITS;
        if flip {
            ONE - location
        } else {
            location
        }
    }

    /// Point `k` (`0 ≤ k ≤ segments`) as a parameter in `[0, 1]`; exact, and symmetric bit
    /// for bit: `param(n − k) == 1 − param(k)`.
    pub fn param(&self, k: u32) -> f64 {
        to_f64(self.place(k as i64))
    }
}

/// The hardware clamp: NaN gives `lo`; integer partitionings round up.
fn clamp(x: f32, lo: f32, hi: f32, partitioning: Partitioning) -> f32 {
    let c = if x.is_nan() { lo } else { x.max(lo).min(hi) };
    if partitioning.is_integer() {
        c.ceil()
    } else {
        c
    }
}

/// Parity of a processed factor: the mode's, or for integer modes the rounded value's (an
/// inside factor of 1 counts as even).
fn parity_odd(f: f32, partitioning: Partitioning, inside: bool) -> bool {
    match partitioning {
        Partitioning::FractionalOdd => true,
        Partitioning::FractionalEven => false,
        Partitioning::Integer | Partitioning::Pow2 => {
            let even = (f as i64) & 1 == 0 || (inside && f == 1.0);
            !even
        }
    }
}

/// Segments of an edge with real factor `factor`. Cost: O(1).
pub fn edge_segments(factor: f64, partitioning: Partitioning) -> u32 {
    Axis::edge(factor, partitioning).segments()
}

/// Parameter of point `k` of an edge with real factor `factor`. Cost: O(1).
pub fn edge_param(factor: f64, partitioning: Partitioning, k: u32) -> f64 {
    Axis::edge(factor, partitioning).param(k)
}

/// `factor` lowered to the count boundary below it when it lies less than `gap` above it
/// (fractional modes only). The hardware is continuous there, but a factor just above a
/// boundary makes segments far below `f32` resolution of a patch, and two output vertices
/// would weld into one; settled factors keep every segment at least about `gap / 128` of an
/// edge long, at the price of points being born split by that much instead of by 0. Cost: O(1).
pub fn settled_factor(factor: f64, partitioning: Partitioning, gap: f64) -> f64 {
    if partitioning.is_integer() {
        return factor;
    }
    let (lo, hi) = partitioning.range();
    let f = clamp(factor as f32, lo, hi, partitioning) as f64;
    let boundary = edge_segments(f, partitioning) as f64 - 2.0;
    if boundary >= lo as f64 && f - boundary < gap {
        boundary
    } else {
        f
    }
}

/// The gap the criteria keep above each count boundary (see [`settled_factor`]).
pub const OUTPUT_GAP: f64 = 1.0 / 64.0;

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
        if edges.iter().any(|f| !(*f > 0.0)) {
            return None;
        }
        let (lo, hi) = partitioning.range();
        let e: Vec<f32> = edges.iter().map(|&f| clamp(f, lo, hi, partitioning)).collect();
        let frame_threshold = 1.0 + EPSILON / 2.0;
        // Quads also look at the raw inside factors; triangles have only one.
        let frame = partitioning == Partitioning::FractionalOdd
            && (e.iter().any(|&f| f > frame_threshold)
                || (domain == Domain::Quad && inside.iter().any(|&f| f > frame_threshold)));
        let inside_lo = if frame { 1.0 + EPSILON } else { lo };
        let i: Vec<f32> = inside.iter().map(|&f| clamp(f, inside_lo, hi, partitioning)).collect();
        let e_fixed: Vec<Fixed> = e.iter().map(|&f| to_fixed(f)).collect();
        let i_fixed: Vec<Fixed> = i.iter().map(|&f| to_fixed(f)).collect();
        let minimum = (partitioning.is_integer() || partitioning == Partitioning::FractionalOdd)
            && e_fixed.iter().chain(&i_fixed).all(|&f| f == ONE);
        let mut outer = [Axis::new(ONE, true); 4];
        for k in 0..n {
            outer[k] = Axis::new(e_fixed[k], parity_odd(e[k], partitioning, false));
        }
        let mut inner = [Axis::new(ONE, true); 2];
        for k in 0..2 {
            let j = k.min(i.len() - 1);
            let mut a = Axis::new(i_fixed[j], parity_odd(i[j], partitioning, true));
            // Fewer points would leave no interior: the transition regions degenerate instead.
            a.points = a.points.max(if a.odd { 4 } else { 3 });
            inner[k] = a;
        }
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

/// One ring of points as a cycle, split into sides that share their end points.
#[derive(Debug, Clone, Default)]
struct Ring {
    points: Vec<u32>,
    side_points: [u32; 4],
}

impl Ring {
    /// Point `j` of side `e`, following the cycle (the last side wraps to the first point).
    fn at(&self, e: usize, j: u32) -> u32 {
        let offset: u32 = self.side_points[..e].iter().map(|n| n - 1).sum();
        self.points[((offset + j) as usize) % self.points.len()]
    }

    fn side(&self, e: usize) -> Vec<u32> {
        (0..self.side_points[e]).map(|j| self.at(e, j)).collect()
    }
}

/// How the diagonals of a regular band run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Diagonals {
    InsideToOutside,
    InsideToOutsideExceptMiddle,
    Mirrored,
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

/// Accumulates triangles.
struct Emit<'a> {
    out: &'a mut HardwareTessellation,
    region: u32,
}

impl Emit<'_> {
    /// A triangle given in Direct3D's clockwise order (v down), which is counter-clockwise in
    /// the `(u, v)` plane.
    fn tri(&mut self, a: u32, b: u32, c: u32) {
        self.out.triangles.push([a, b, c]);
        self.out.regions.push(self.region);
    }

    /// The band between an outer row and an inner row whose factors may differ: the
    /// ruler-function transition, walked from both ends towards the middle.
    fn transition(&mut self, inner: &[u32], inner_axis: &Axis, outer: &[u32], outer_axis: &Axis) {
        let inner_half = inner_axis.half_points - i64::from(inner_axis.odd);
        let outer_half = outer_axis.half_points - i64::from(outer_axis.odd);
        let (mut o, mut i) = (0usize, 0usize);
        let advance_outer = |e: &mut Self, o: &mut usize, i: usize| {
            e.tri(outer[*o], outer[*o + 1], inner[i]);
            *o += 1;
        };
        let advance_inner = |e: &mut Self, o: usize, i: &mut usize| {
            e.tri(inner[*i], outer[o], inner[*i + 1]);
            *i += 1;
        };
        if (FINAL_POINT_POSITION[0] as i64) < outer_half {
            advance_outer(self, &mut o, i);
        }
        for &position in &FINAL_POINT_POSITION[1..] {
            let position = position as i64;
            if position < inner_half {
                advance_inner(self, o, &mut i);
            }
            if position < outer_half {
                advance_outer(self, &mut o, i);
            }
        }
        if inner_axis.odd != outer_axis.odd || inner_axis.odd {
            if inner_axis.odd == outer_axis.odd {
                // Both odd: a quad in the middle.
                self.tri(inner[i], outer[o], inner[i + 1]);
                self.tri(inner[i + 1], outer[o], outer[o + 1]);
                i += 1;
                o += 1;
            } else if !inner_axis.odd {
                // A triangle pointing inside.
                self.tri(inner[i], outer[o], outer[o + 1]);
                o += 1;
            } else {
                // A triangle pointing outside.
                self.tri(inner[i], outer[o], inner[i + 1]);
                i += 1;
            }
        }
        for &position in FINAL_POINT_POSITION[1..].iter().rev() {
            let position = position as i64;
            if position < outer_half {
                advance_outer(self, &mut o, i);
            }
            if position < inner_half {
                advance_inner(self, o, &mut i);
            }
        }
        if (FINAL_POINT_POSITION[0] as i64) < outer_half {
            advance_outer(self, &mut o, i);
        }
        debug_assert_eq!((o + 1, i + 1), (outer.len(), inner.len()), "transition did not reach the row ends");
    }

    /// A band between rows whose point counts differ by 2 (`trapezoid`: one triangle at each
    /// end) or are equal (a strip of quads).
    fn regular(&mut self, trapezoid: bool, diagonals: Diagonals, inner: &[u32], outer: &[u32]) {
        let n = inner.len();
        let (mut o, mut i) = (0usize, 0usize);
        if trapezoid {
            self.tri(outer[o], outer[o + 1], inner[i]);
            o += 1;
        }
        // Diagonal from the inner point to the next outer point, or the other way.
        let forward = |e: &mut Self, o: usize, i: usize| {
            e.tri(outer[o], outer[o + 1], inner[i]);
            e.tri(inner[i], outer[o + 1], inner[i + 1]);
        };
        let backward = |e: &mut Self, o: usize, i: usize| {
            e.tri(outer[o], inner[i + 1], inner[i]);
            e.tri(outer[o], outer[o + 1], inner[i + 1]);
        };
        match diagonals {
            Diagonals::InsideToOutside => {
                for _ in 0..n.saturating_sub(1) {
                    self.tri(inner[i], outer[o], outer[o + 1]);
                    self.tri(inner[i], outer[o + 1], inner[i + 1]);
                    i += 1;
                    o += 1;
                }
            }
            Diagonals::InsideToOutsideExceptMiddle => {
                let first = (n / 2).saturating_sub(1);
                for _ in 0..first {
                    forward(self, o, i);
                    i += 1;
                    o += 1;
                }
                backward(self, o, i);
                i += 1;
                o += 1;
                for _ in first + 2..n {
                    forward(self, o, i);
                    i += 1;
                    o += 1;
                }
            }
            Diagonals::Mirrored => {
                for p in 0..n.saturating_sub(1) {
                    if p < n / 2 {
                        backward(self, o, i);
                    } else {
                        self.tri(inner[i], outer[o], outer[o + 1]);
                        self.tri(inner[i], outer[o + 1], inner[i + 1]);
                    }
                    i += 1;
                    o += 1;
                }
            }
        }
        if trapezoid {
            self.tri(outer[o], outer[o + 1], inner[i]);
        }
    }
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
    let pre = Processed::new(domain, partitioning, edges, inside)?;
    let mut out = HardwareTessellation::default();
    for e in 0..domain.corner_count() {
        out.edge_points[e] = pre.outer[e].points as u32;
    }
    if pre.minimum {
        match domain {
            Domain::Quad => {
                out.points.extend([DVec2::ZERO, DVec2::X, DVec2::ONE, DVec2::Y]);
                let mut emit = Emit { out: &mut out, region: 1 };
                emit.tri(0, 1, 3);
                emit.tri(1, 2, 3);
            }
            Domain::Tri => {
                out.points.extend([DVec2::Y, DVec2::ZERO, DVec2::X]);
                Emit { out: &mut out, region: 1 }.tri(0, 1, 2);
            }
        }
        return Some(out);
    }
    let (points, triangles) = pre.counts();
    out.points.reserve(points as usize);
    out.triangles.reserve(triangles as usize);
    match domain {
        Domain::Quad => quad(&pre, &mut out),
        Domain::Tri => tri(&pre, &mut out),
    }
    debug_assert_eq!((out.points.len() as u32, out.triangles.len() as u32), (points, triangles));
    Some(out)
}

fn push(out: &mut HardwareTessellation, u: Fixed, v: Fixed) -> u32 {
    out.points.push(DVec2::new(to_f64(u), to_f64(v)));
    out.points.len() as u32 - 1
}

/// The outer ring: each edge's points but its last, clockwise in Direct3D's picture.
fn outer_ring(
    pre: &Processed,
    out: &mut HardwareTessellation,
    point: impl Fn(usize, Fixed) -> (Fixed, Fixed),
) -> Ring {
    let mut ring = Ring::default();
    for e in 0..pre.domain.corner_count() {
        let axis = &pre.outer[e];
        let end = axis.points - 1;
        for p in 0..end {
            let q = if reversed(pre.domain, e) { end - p } else { p };
            let (u, v) = point(e, axis.place(q));
            ring.points.push(push(out, u, v));
        }
        ring.side_points[e] = axis.points as u32;
    }
    ring
}

/// Whether edge `e`'s points run against its 1-D partition (the outer ring and the rings are
/// written clockwise in Direct3D's picture).
fn reversed(domain: Domain, e: usize) -> bool {
    match domain {
        Domain::Quad => !(e == 1 || e == 2),
        Domain::Tri => e % 2 == 0,
    }
}

fn quad(pre: &Processed, out: &mut HardwareTessellation) {
    let [iu, iv] = pre.inside;
    let n = [iu.points, iv.points];
    let mut rings = vec![outer_ring(pre, out, |e, x| match e {
        0 => (0, x),
        1 => (x, 0),
        2 => (ONE, x),
        _ => (x, ONE),
    })];
    // Inner rings; side e runs along axis (e + 1) & 1 at a fixed coordinate of the other.
    let point_rings = n[0].min(n[1]) >> 1;
    for r in 1..point_rings {
        let end = [n[0] - 1 - r, n[1] - 1 - r];
        let mut ring = Ring::default();
        for e in 0..4 {
            let (across, along) = (e & 1, (e + 1) & 1);
            let perp_point = if e < 2 { r } else { end[across] };
            let perp = pre.inside[across].place(perp_point);
            for p in r..end[along] {
                let q = if e == 1 || e == 2 { p } else { end[along] - (p - r) };
                let x = pre.inside[along].place(q);
                let id = if along == 1 { push(out, perp, x) } else { push(out, x, perp) };
                ring.points.push(id);
            }
            ring.side_points[e] = (n[along] - 2 * r) as u32;
        }
        rings.push(ring);
    }
    // An even inside partition ends in a degenerate ring: a row (or column, or one point)
    // through the middle, its sides running along it and back.
    let degenerate = if n[0] > n[1] && !iv.odd {
        let r = point_rings;
        let row: Vec<u32> = (r..=n[0] - 1 - r).map(|p| push(out, iu.place(p), HALF)).collect();
        let m = row.len() as u32;
        Some((row, [1, m, 1, m]))
    } else if n[1] >= n[0] && !iu.odd {
        let r = point_rings;
        let column: Vec<u32> = (r..=n[1] - 1 - r).rev().map(|p| push(out, HALF, iv.place(p))).collect();
        let m = column.len() as u32;
        Some((column, [m, 1, m, 1]))
    } else {
        None
    };
    if let Some((line, side_points)) = degenerate {
        let mut points = line.clone();
        if line.len() > 1 {
            points.extend(line[1..line.len() - 1].iter().rev());
        }
        rings.push(Ring { points, side_points: if line.len() == 1 { [1; 4] } else { side_points } });
    }
    let band_rings = ((n[0] + 1) >> 1).min((n[1] + 1) >> 1) as usize;
    debug_assert_eq!(band_rings, rings.len());
    for r in 1..band_rings {
        let mut emit = Emit { out, region: r as u32 };
        for e in 0..4 {
            let (outer, inner) = (rings[r - 1].side(e), rings[r].side(e));
            if r == 1 {
                emit.transition(&inner, &pre.inside[(e + 1) & 1], &outer, &pre.outer[e]);
            } else {
                emit.regular(true, Diagonals::Mirrored, &inner, &outer);
            }
        }
    }
    // A strip of quads in the middle when the smaller inside partition is odd.
    if let Some((quads, horizontal)) = pre.centre_strip() {
        let last = rings.last().expect("at least the outer ring");
        let mut emit = Emit { out, region: band_rings as u32 };
        if horizontal {
            let (outer, mut inner) = (last.side(1), last.side(3));
            inner.reverse();
            debug_assert_eq!(inner.len() as i64, quads + 1);
            emit.regular(false, Diagonals::InsideToOutside, &inner, &outer);
        } else {
            let (outer, mut inner) = (last.side(0), last.side(2));
            inner.reverse();
            debug_assert_eq!(inner.len() as i64, quads + 1);
            let diagonals =
                if iv.odd { Diagonals::InsideToOutsideExceptMiddle } else { Diagonals::InsideToOutside };
            emit.regular(false, diagonals, &inner, &outer);
        }
    }
}

fn tri(pre: &Processed, out: &mut HardwareTessellation) {
    let axis = pre.inside[0];
    let n = axis.points;
    let mut rings = vec![outer_ring(pre, out, |e, x| match e {
        0 => (0, x),
        1 => (x, 0),
        _ => (x, ONE - x),
    })];
    for r in 1..n >> 1 {
        let end = n - 1 - r;
        // The ring's distance from each side, scaled to barycentric size (2/3 of the 1-D
        // position), and the along-side parameters pushed in by half of it.
        let perp = (axis.place(r) * TWO_THIRDS + HALF) >> FRACTION_BITS;
        let shift = (perp + 1) / 2;
        let mut ring = Ring::default();
        for e in 0..3 {
            for p in r..end {
                let q = if e % 2 == 1 { p } else { end - (p - r) };
                let x = axis.place(q) - shift;
                let id = match e {
                    0 => push(out, perp, x),
                    1 => push(out, x, perp),
                    _ => push(out, x, ONE - x - perp),
                };
                ring.points.push(id);
            }
            ring.side_points[e] = (n - 2 * r) as u32;
        }
        rings.push(ring);
    }
    if !axis.odd {
        let centre = push(out, ONE_THIRD, ONE_THIRD);
        rings.push(Ring { points: vec![centre], side_points: [1; 4] });
    }
    let band_rings = ((n + 1) >> 1) as usize;
    debug_assert_eq!(band_rings, rings.len());
    for r in 1..band_rings {
        let mut emit = Emit { out, region: r as u32 };
        for e in 0..3 {
            let (outer, inner) = (rings[r - 1].side(e), rings[r].side(e));
            if r == 1 {
                emit.transition(&inner, &axis, &outer, &pre.outer[e]);
            } else {
                emit.regular(true, Diagonals::Mirrored, &inner, &outer);
            }
        }
    }
    if axis.odd {
        let last = &rings[band_rings - 1].points;
        Emit { out, region: band_rings as u32 }.tri(last[0], last[1], last[2]);
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
/// edges along u, inside-v likewise). Cost: linear in the output.
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
        let inside = match d {
            Domain::Quad => [edges[1].max(edges[3]), edges[0].max(edges[2])],
            Domain::Tri => [edges[0].max(edges[1]).max(edges[2]); 2],
        };
        (edges, inside)
    }

    fn processed(&self, input: &PatternInput) -> Processed {
        let (edges, inside) = self.factors(input);
        // Tessera's factors are at least 1, so the hardware never culls here.
        Processed::new(input.domain, self.partitioning, edges, inside).expect("edge factors are positive")
    }
}

impl Pattern for Hardware {
    /// O(rings).
    fn counts(&self, input: &PatternInput) -> (u32, u32) {
        let pre = self.processed(input);
        let (points, triangles) = pre.counts();
        (points - pre.outer_points() as u32, triangles)
    }

    fn build(&self, input: &PatternInput, out: &mut LocalTessellation) {
        out.interior.clear();
        out.triangles.clear();
        let d = input.domain;
        let (edges, inside) = self.factors(input);
        let hw = tessellate(d, self.partitioning, edges, inside).expect("edge factors are positive");
        debug_assert!(
            (0..d.corner_count()).all(|e| input.segments[e] + 1 == hw.edge_points[d3d_edge(d, e)]),
            "hardware pattern: segments do not match factors: {input:?}"
        );
        // Local index of every hardware point: the outer ring's points are tessera's boundary
        // points, the rest interior in the hardware's order.
        let mut local = Vec::with_capacity(hw.points.len());
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
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pattern::assert_tiles;

    const ALL: [Partitioning; 4] = [
        Partitioning::Integer,
        Partitioning::Pow2,
        Partitioning::FractionalOdd,
        Partitioning::FractionalEven,
    ];

    #[test]
    fn reciprocals_are_the_hardware_table() {
        // Spot checks of the published 16.16 table, including the rounded-up entries.
        let table =
            [(1, 0x10000), (3, 0x5555), (6, 0x2aab), (7, 0x2492), (10, 0x199a), (63, 0x410), (64, 0x400)];
        for (n, want) in table {
            assert_eq!(reciprocal(n), want, "1/{n}");
        }
    }

    #[test]
    fn the_published_examples() {
        // Issue 15's figures: even F = 3 gives 0, .375, .5, .625, 1.
        let a = Axis::edge(3.0, Partitioning::FractionalEven);
        let p: Vec<f64> = (0..=a.segments()).map(|k| a.param(k)).collect();
        assert_eq!(p, [0.0, 0.375, 0.5, 0.625, 1.0]);
        // Odd F = 5.3: segment lengths × F of 1.0145, 0.1136, 1.0145, 1.0146, 1.0145, 0.1136, 1.0145.
        let a = Axis::edge(5.3, Partitioning::FractionalOdd);
        let want = [1.0145, 0.1136, 1.0145, 1.0146, 1.0145, 0.1136, 1.0145];
        assert_eq!(a.segments(), 7);
        for k in 0..7 {
            let len = (a.param(k + 1) - a.param(k)) * 5.3;
            assert!((len - want[k as usize]).abs() < 2e-4, "segment {k}: {len}");
        }
    }

    #[test]
    fn edge_partitions_are_symmetric_and_increasing() {
        for partitioning in ALL {
            for i in 0..=7000 {
                let f = 0.01 * i as f64;
                let a = Axis::edge(f, partitioning);
                let n = a.segments();
                assert_eq!(a.param(0), 0.0);
                assert_eq!(a.param(n), 1.0);
                for k in 0..=n {
                    assert_eq!(
                        a.param(n - k).to_bits(),
                        (1.0 - a.param(k)).to_bits(),
                        "{partitioning:?} {f} {k}"
                    );
                    if k < n {
                        assert!(a.param(k + 1) >= a.param(k), "{partitioning:?} {f} {k}");
                    }
                }
                let (lo, hi) = partitioning.range();
                let fc = (f as f32).clamp(lo, hi) as f64;
                match partitioning {
                    Partitioning::Integer | Partitioning::Pow2 => assert_eq!(n, fc.ceil() as u32),
                    Partitioning::FractionalOdd => assert!(n % 2 == 1 && n as f64 >= fc - 1e-4),
                    Partitioning::FractionalEven => assert!(n % 2 == 0 && n as f64 >= fc - 1e-4),
                }
            }
        }
    }

    fn input(domain: Domain, partitioning: Partitioning, factors: [f64; 4]) -> PatternInput {
        PatternInput {
            domain,
            segments: factors.map(|f| edge_segments(f, partitioning)),
            interior: [1, 1],
            factors,
            patch: 0,
        }
    }

    /// xorshift64*, so failures reproduce.
    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> f64 {
            self.0 ^= self.0 >> 12;
            self.0 ^= self.0 << 25;
            self.0 ^= self.0 >> 27;
            (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
        }
        /// A factor in [1, 66]: often an integer or a small one; settled as the criteria do.
        fn factor(&mut self, partitioning: Partitioning) -> f64 {
            let x = 1.0 + 65.0 * self.next();
            let f = match (self.next() * 5.0) as u32 {
                0 => x.round(),
                1 => 1.0 + 4.0 * self.next(),
                _ => x,
            };
            settled_factor(partitioning.hull_factor(f), partitioning, OUTPUT_GAP)
        }
    }

    #[test]
    fn tiles_the_domain_for_many_factor_combinations() {
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
        let mut out = LocalTessellation::default();
        for partitioning in ALL {
            for domain in [Domain::Tri, Domain::Quad] {
                for case in 0..600 {
                    let factors = if case < 64 {
                        [1.0 + case as f64; 4]
                    } else {
                        [0; 4].map(|_| rng.factor(partitioning))
                    };
                    let pattern = Hardware { partitioning };
                    let input = input(domain, partitioning, factors);
                    pattern.build(&input, &mut out);
                    assert_eq!(
                        pattern.counts(&input),
                        (out.interior.len() as u32, out.triangles.len() as u32),
                        "{partitioning:?} {input:?}"
                    );
                    let p = input.local_positions(&out.interior, |e, k| {
                        crate::sampling::EdgeSampling::Fractional {
                            factor: input.factors[e],
                            spacing: crate::sampling::Spacing::Hardware(partitioning),
                        }
                        .local_param(k, false)
                    });
                    assert_tiles(&input, &out, &p, 0.0);
                }
            }
        }
    }

    #[test]
    fn boundary_points_are_the_edge_samplings() {
        // The hardware's own outer-ring points equal the local positions the engine gives the
        // boundary vertices, bit for bit, for every edge direction.
        let mut rng = Rng(7);
        let mut out = LocalTessellation::default();
        for partitioning in ALL {
            for domain in [Domain::Tri, Domain::Quad] {
                for _ in 0..200 {
                    let factors = [0; 4].map(|_| rng.factor(partitioning));
                    let input = input(domain, partitioning, factors);
                    let pattern = Hardware { partitioning };
                    pattern.build(&input, &mut out);
                    let (edges, inside) = pattern.factors(&input);
                    let hw = tessellate(domain, partitioning, edges, inside).unwrap();
                    let p = input
                        .local_positions(&out.interior, |e, k| edge_param(input.factors[e], partitioning, k));
                    let mut hw_tris: Vec<[DVec2; 3]> =
                        hw.triangles.iter().map(|t| t.map(|v| hw.points[v as usize])).collect();
                    let mut local_tris: Vec<[DVec2; 3]> =
                        out.triangles.iter().map(|t| t.map(|v| p[v as usize])).collect();
                    let key = |t: &[DVec2; 3]| t.map(|q| (q.x.to_bits(), q.y.to_bits()));
                    hw_tris.sort_by_key(key);
                    local_tris.sort_by_key(key);
                    assert_eq!(hw_tris, local_tris, "{partitioning:?} {input:?}");
                }
            }
        }
    }

    /// Largest distance from a point of `a` to its nearest point of `b` (a grid of buckets
    /// of side `cell`, searched one bucket around; farther points count as `cell`).
    fn one_sided_hausdorff(a: &[DVec2], b: &[DVec2], cell: f64) -> f64 {
        use std::collections::HashMap;
        let key = |p: DVec2| ((p.x / cell).floor() as i64, (p.y / cell).floor() as i64);
        let mut grid: HashMap<(i64, i64), Vec<DVec2>> = HashMap::new();
        for &q in b {
            grid.entry(key(q)).or_default().push(q);
        }
        a.iter()
            .map(|&p| {
                let (i, j) = key(p);
                let mut best = cell;
                for di in -1..=1 {
                    for dj in -1..=1 {
                        for q in grid.get(&(i + di, j + dj)).into_iter().flatten() {
                            best = best.min(p.distance(*q));
                        }
                    }
                }
                best
            })
            .fold(0.0, f64::max)
    }

    /// The fractional modes move points continuously with the factor: sweeping every factor
    /// of a patch from 1 to 64 in steps of `STEP`, a point that keeps its index moves at most
    /// `C · STEP` (plus one fixed-point step), and when points are born or die every point of
    /// either tessellation lies that close to one of the other. Measured: no point moves more
    /// than 0.245 × the factor step (asserted: 0.5).
    #[test]
    fn fractional_modes_are_continuous() {
        const STEP: f64 = 4e-3;
        const C: f64 = 0.5;
        let quantum = 2.0 / 65536.0;
        let mut worst: f64 = 0.0;
        for partitioning in [Partitioning::FractionalOdd, Partitioning::FractionalEven] {
            for domain in [Domain::Tri, Domain::Quad] {
                let configs: [fn(f32) -> [f32; 4]; 3] =
                    [|f| [f; 4], |f| [f, 1.0 + f / 2.0, f, 2.0], |f| [1.0 + f / 3.0, f, 0.5 * f + 1.0, f]];
                for config in configs {
                    let at = |f: f64| {
                        let edges = config(f as f32);
                        let inside = match domain {
                            Domain::Quad => [edges[1].max(edges[3]), edges[0].max(edges[2])],
                            Domain::Tri => [edges[0].max(edges[1]).max(edges[2]); 2],
                        };
                        tessellate(domain, partitioning, edges, inside).unwrap().points
                    };
                    let mut old = at(1.0);
                    let steps = (63.0 / STEP) as u32;
                    for s in 1..=steps {
                        let new = at(1.0 + s as f64 * STEP);
                        let moved = if new.len() == old.len() {
                            new.iter().zip(&old).map(|(a, b)| a.distance(*b)).fold(0.0, f64::max)
                        } else {
                            let cell = 4.0 * C * STEP;
                            one_sided_hausdorff(&new, &old, cell).max(one_sided_hausdorff(&old, &new, cell))
                        };
                        assert!(
                            moved <= C * STEP + quantum,
                            "{partitioning:?} {domain:?}: a point moved {moved} at factor step {s}"
                        );
                        worst = worst.max((moved - quantum).max(0.0) / STEP);
                        old = new;
                    }
                }
            }
        }
        eprintln!("fractional continuity: largest move {worst:.3} × the factor step");
    }

    #[test]
    fn culls_on_non_positive_factors() {
        for f in [0.0, -1.0, f32::NAN] {
            assert!(tessellate(Domain::Quad, Partitioning::Integer, [f, 2.0, 2.0, 2.0], [2.0, 2.0]).is_none());
            assert!(tessellate(Domain::Tri, Partitioning::FractionalOdd, [2.0, f, 2.0, 0.0], [2.0, 0.0])
                .is_none());
        }
    }

    #[test]
    fn pow2_hull_factors_are_powers_of_two() {
        for (f, want) in
            [(0.5, 0.5), (1.0, 1.0), (1.1, 2.0), (3.0, 4.0), (4.0, 4.0), (33.0, 64.0), (100.0, 64.0)]
        {
            assert_eq!(Partitioning::Pow2.hull_factor(f), want, "{f}");
        }
    }
}
