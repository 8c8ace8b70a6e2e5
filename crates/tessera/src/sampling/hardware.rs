//! The hardware's 1-D edge partition: factor processing (clamping, rounding, parity), the
//! 16.16 fixed-point arithmetic and the placement of each point of an edge. Every engine reads
//! edge points through [`edge_segments`] and [`edge_param`], so neighbours agree bit for bit.

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
pub(crate) type Fixed = i64;
pub(crate) const FRACTION_BITS: u32 = 16;
pub(crate) const ONE: Fixed = 1 << FRACTION_BITS;
pub(crate) const HALF: Fixed = ONE >> 1;
pub(crate) const ONE_THIRD: Fixed = 0x5555;
pub(crate) const TWO_THIRDS: Fixed = 0xaaaa;
/// `2⁻¹⁶`, the smallest positive fixed-point fraction.
pub(crate) const EPSILON: f32 = 1.0 / 65536.0;

/// `x ≥ 0` (below 2¹⁵) to fixed point, rounding to nearest, ties to even, as the hardware's
/// float-to-fixed conversion does. Exact: `x · 2¹⁶` of an `f32` is exact in `f64`.
pub(crate) fn to_fixed(x: f32) -> Fixed {
    // Adding and removing 1.5 · 2⁵² rounds to an integer, ties to even (the default rounding
    // of every addition), for any |v| < 2⁵¹: `round_ties_even` itself is a libm call on
    // targets without SSE4.1, and every edge of a frame converts its factor a few times.
    const MAGIC: f64 = 1.5 * (1u64 << 52) as f64;
    let v = x as f64 * ONE as f64;
    if v.abs() < (1u64 << 51) as f64 {
        ((v + MAGIC) - MAGIC) as Fixed
    } else {
        v.round_ties_even() as Fixed
    }
}

/// Fixed point to `f64`, exactly.
pub(crate) fn to_f64(x: Fixed) -> f64 {
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
pub(crate) fn reciprocal(n: i64) -> Fixed {
    (ONE + n / 2) / n
}

/// `v` without its most significant set bit (0 for `v ≤ 0`).
pub(crate) fn remove_msb(v: i64) -> i64 {
    if v <= 0 {
        0
    } else {
        v & !(1 << (63 - v.leading_zeros()))
    }
}

/// The 1-D partition of one processed factor: what the hardware calls a tess-factor context,
/// with its parity.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Axis {
    pub(crate) odd: bool,
    /// `h − ⌊h⌋` of the half factor `h`.
    half_fraction: Fixed,
    /// `⌈h⌉`: points on the half edge (for even, without the midpoint).
    pub(crate) half_points: i64,
    /// The point that is split off on the floor partition (ignored when `h` is an integer).
    split_point: i64,
    inv_floor_segments: Fixed,
    inv_ceil_segments: Fixed,
    /// Points on the whole edge, ends included.
    pub(crate) points: i64,
}

impl Axis {
    /// The partition of fixed-point factor `f` with the given parity.
    pub(crate) fn new(f: Fixed, odd: bool) -> Axis {
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
        let points = Axis::point_count(f, odd);
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

    /// How many points the partition of fixed-point factor `f` with the given parity has
    /// (without the rest of [`Axis::new`]'s work: its two divisions).
    fn point_count(f: Fixed, odd: bool) -> i64 {
        if odd {
            (fixed_ceil(HALF + (f + 1) / 2) * 2) >> FRACTION_BITS
        } else {
            ((fixed_ceil((f + 1) / 2) * 2) >> FRACTION_BITS) + 1
        }
    }

    /// The processed factor of an edge: clamped, rounded and converted as the hardware does
    /// with an edge factor `> 0`, and its parity.
    fn edge_factor(factor: f64, partitioning: Partitioning) -> (Fixed, bool) {
        let (lo, hi) = partitioning.range();
        let f = clamp(factor as f32, lo, hi, partitioning);
        (to_fixed(f), parity_odd(f, partitioning, false))
    }

    /// The partition of an edge with real factor `factor` under `partitioning` (clamped,
    /// rounded and converted as the hardware does with an edge factor `> 0`).
    pub fn edge(factor: f64, partitioning: Partitioning) -> Axis {
        let (f, odd) = Axis::edge_factor(factor, partitioning);
        Axis::new(f, odd)
    }

    /// Number of segments.
    pub fn segments(&self) -> u32 {
        (self.points - 1) as u32
    }

    /// Point `k` (`0 ≤ k < points`) in fixed point.
    pub(crate) fn place(&self, k: i64) -> Fixed {
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
pub(crate) fn clamp(x: f32, lo: f32, hi: f32, partitioning: Partitioning) -> f32 {
    let c = if x.is_nan() { lo } else { x.max(lo).min(hi) };
    if partitioning.is_integer() {
        c.ceil()
    } else {
        c
    }
}

/// Parity of a processed factor: the mode's, or for integer modes the rounded value's (an
/// inside factor of 1 counts as even).
pub(crate) fn parity_odd(f: f32, partitioning: Partitioning, inside: bool) -> bool {
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
    let (f, odd) = Axis::edge_factor(factor, partitioning);
    (Axis::point_count(f, odd) - 1) as u32
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
