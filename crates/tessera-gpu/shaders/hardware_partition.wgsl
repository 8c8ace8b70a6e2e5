// The Direct3D 11 tessellator's 1-D edge partition, the GPU form of
// `tessera::sampling::hardware`: factor processing (clamping, rounding, parity), the 16.16
// fixed point and the place of every point of an edge; also the hull-shader side the
// resolver applies (`Partitioning::hull_factor`, `settled_factor`). Integer arithmetic in u32
// as the hardware's own: the CPU computes in i64, but no intermediate of a reachable
// partition passes 2³¹ (checked over every fixed-point factor of [1, 64], both parities), so
// the parameters are bit for bit the CPU's. Factors are finite here (WGSL may assume no NaN
// or infinity): `GpuTessellator::prepare` refuses other plans, and the factor pass makes
// finite ones.

// `Partitioning` as `Params::partitioning` holds it (values from `tessellator/pipelines.rs`).
const PARTITIONING_INTEGER: u32 = {{PARTITIONING_INTEGER}}u;
const PARTITIONING_POW2: u32 = {{PARTITIONING_POW2}}u;
const PARTITIONING_FRACTIONAL_ODD: u32 = {{PARTITIONING_FRACTIONAL_ODD}}u;
const PARTITIONING_FRACTIONAL_EVEN: u32 = {{PARTITIONING_FRACTIONAL_EVEN}}u;

// `sampling::hardware`'s fixed point: `FRACTION_BITS`, `ONE`, `HALF`, `ONE_THIRD`,
// `TWO_THIRDS`, `EPSILON`.
const FRACTION_BITS: u32 = 16u;
const FIXED_ONE: u32 = 65536u;
const FIXED_HALF: u32 = 32768u;
const FIXED_ONE_THIRD: u32 = 0x5555u;
const FIXED_TWO_THIRDS: u32 = 0xaaaau;
const FIXED_EPSILON: f32 = 1.0 / 65536.0;

// `sampling::hardware::OUTPUT_GAP`, the gap `settled_factor` keeps above a count boundary.
const OUTPUT_GAP: f32 = 1.0 / f32({{OUTPUT_GAP_INVERSE}});

// `Partitioning::range`: the factor range the hardware clamps to.
fn partitioning_range(mode: u32) -> vec2<f32> {
    switch mode {
        case PARTITIONING_FRACTIONAL_ODD: {
            return vec2<f32>(f32({{FRACTIONAL_ODD_LO}}), f32({{FRACTIONAL_ODD_HI}}));
        }
        case PARTITIONING_FRACTIONAL_EVEN: {
            return vec2<f32>(f32({{FRACTIONAL_EVEN_LO}}), f32({{FRACTIONAL_EVEN_HI}}));
        }
        default: { return vec2<f32>(f32({{INTEGER_LO}}), f32({{INTEGER_HI}})); }
    }
}

// `Partitioning::is_integer`.
fn partitioning_is_integer(mode: u32) -> bool {
    return mode == PARTITIONING_INTEGER || mode == PARTITIONING_POW2;
}

// `sampling::hardware::clamp` for a factor that is not NaN; integer partitionings round up.
fn clamp_factor(x: f32, lo: f32, hi: f32, mode: u32) -> f32 {
    let c = min(max(x, lo), hi);
    if (partitioning_is_integer(mode)) { return ceil(c); }
    return c;
}

// `sampling::hardware::to_fixed`: x · 2¹⁶ is exact in f32 (x < 2¹⁵), and WGSL's `round`
// rounds halves to even, as `f64::round_ties_even`.
fn to_fixed(x: f32) -> u32 {
    return u32(round(x * f32(FIXED_ONE)));
}

// `sampling::hardware::fixed_floor` and `fixed_ceil`.
fn fixed_floor(x: u32) -> u32 { return x & ~(FIXED_ONE - 1u); }

fn fixed_ceil(x: u32) -> u32 {
    if ((x & (FIXED_ONE - 1u)) != 0u) { return fixed_floor(x) + FIXED_ONE; }
    return x;
}

// `sampling::hardware::reciprocal`: 1/n in fixed point, rounded to nearest.
fn reciprocal(n: u32) -> u32 { return (FIXED_ONE + n / 2u) / n; }

// `sampling::hardware::remove_msb`: v without its most significant set bit.
fn remove_msb(v: u32) -> u32 {
    if (v == 0u) { return 0u; }
    return v & ~(1u << firstLeadingBit(v));
}

// `sampling::hardware::parity_odd`: the partitioning's parity, or for the integer ones the
// rounded factor's (an inside factor of 1 counts as even).
fn parity_odd(f: f32, mode: u32, inside: bool) -> bool {
    if (mode == PARTITIONING_FRACTIONAL_ODD) { return true; }
    if (mode == PARTITIONING_FRACTIONAL_EVEN) { return false; }
    let even = (u32(f) & 1u) == 0u || (inside && f == 1.0);
    return !even;
}

// `sampling::hardware::Axis`: the 1-D partition of one processed factor.
struct Axis {
    odd: bool,
    // h − ⌊h⌋ of the half factor h.
    half_fraction: u32,
    // ⌈h⌉: points on the half edge (for even, without the midpoint).
    half_points: u32,
    // The point split off on the floor partition.
    split_point: u32,
    inv_floor_segments: u32,
    inv_ceil_segments: u32,
    // Points on the whole edge, ends included.
    points: u32,
}

// `Axis::new`: the partition of fixed-point factor f with the given parity.
fn axis_new(f: u32, odd: bool) -> Axis {
    var half = (f + 1u) / 2u;
    // A factor of 1 with even parity behaves as odd here (its half is exactly ½).
    if (odd || half == FIXED_HALF) { half = half + FIXED_HALF; }
    let half_floor = fixed_floor(half);
    let half_ceil = fixed_ceil(half);
    let half_points = half_ceil >> FRACTION_BITS;
    var split_point: u32;
    if (half_ceil == half_floor) {
        split_point = half_points + 1u;
    } else if (odd) {
        if (half_floor == FIXED_ONE) {
            split_point = 0u;
        } else {
            split_point = (remove_msb((half_floor >> FRACTION_BITS) - 1u) << 1u) + 1u;
        }
    } else {
        split_point = (remove_msb(half_floor >> FRACTION_BITS) << 1u) + 1u;
    }
    let odd_less = select(0u, 1u, odd);
    let floor_segments = ((half_floor * 2u) >> FRACTION_BITS) - odd_less;
    let ceil_segments = ((half_ceil * 2u) >> FRACTION_BITS) - odd_less;
    var points: u32;
    if (odd) {
        points = (fixed_ceil(FIXED_HALF + (f + 1u) / 2u) * 2u) >> FRACTION_BITS;
    } else {
        points = ((fixed_ceil((f + 1u) / 2u) * 2u) >> FRACTION_BITS) + 1u;
    }
    return Axis(
        odd,
        half - half_floor,
        half_points,
        split_point,
        reciprocal(max(floor_segments, 1u)),
        reciprocal(max(ceil_segments, 1u)),
        points,
    );
}

// `Axis::edge`: the partition of an edge of real factor `factor` (clamped, rounded and
// converted as the hardware does).
fn axis_edge(factor: f32, mode: u32) -> Axis {
    let range = partitioning_range(mode);
    let f = clamp_factor(factor, range.x, range.y, mode);
    return axis_new(to_fixed(f), parity_odd(f, mode, false));
}

// `Axis::place`: point k (0 ≤ k < points) in fixed point. The point index on the half edge
// is never negative for tessera's factors (only an odd factor of exactly 1 with the inside
// minimum of 4 points would make it so, and such a patch is the minimum case, which has no
// rings).
fn axis_place(a: Axis, k: u32) -> u32 {
    var point = k;
    var flip = false;
    if (k >= a.half_points) {
        point = (a.half_points << 1u) - k - select(0u, 1u, a.odd);
        flip = true;
    }
    // The middle point is exactly ½; the blend below could not reproduce it.
    if (point == a.half_points) { return FIXED_HALF; }
    let on_ceil = point;
    if (point > a.split_point) { point = point - 1u; }
    let on_floor = point;
    var location = on_floor * a.inv_floor_segments * (FIXED_ONE - a.half_fraction)
        + on_ceil * a.inv_ceil_segments * a.half_fraction;
    location = (location + FIXED_HALF) >> FRACTION_BITS;
    if (flip) { return FIXED_ONE - location; }
    return location;
}

// `sampling::hardware::edge_segments`.
fn hardware_edge_segments(factor: f32, mode: u32) -> u32 {
    return axis_edge(factor, mode).points - 1u;
}

// `sampling::hardware::edge_param`: parameter k of an edge of real factor `factor`, exactly
// (a fixed-point value is exact in f32).
fn hardware_edge_param(factor: f32, mode: u32, k: u32) -> f32 {
    return f32(axis_place(axis_edge(factor, mode), k)) * (1.0 / f32(FIXED_ONE));
}

// `Partitioning::hull_factor`: pow2 rounds up to a power of two (at most 64), the others pass
// the factor through. The power is found by comparison, exact for every f32.
fn hull_factor(factor: f32, mode: u32) -> f32 {
    if (mode != PARTITIONING_POW2 || !(factor > 1.0)) { return factor; }
    let f = min(factor, 64.0);
    var power = 1.0;
    while (power < f) { power = power * 2.0; }
    return power;
}

// `sampling::hardware::settled_factor` with `OUTPUT_GAP`: a fractional factor less than the
// gap above the count boundary below it goes down to the boundary. `c − boundary` is exact
// in f32 (`c` lies within 2 of the integer `boundary`), so the test is the CPU's f64 one.
fn settled_factor(factor: f32, mode: u32) -> f32 {
    if (partitioning_is_integer(mode)) { return factor; }
    let range = partitioning_range(mode);
    let c = clamp_factor(factor, range.x, range.y, mode);
    let boundary = f32(hardware_edge_segments(c, mode)) - 2.0;
    if (boundary >= range.x && c - boundary < OUTPUT_GAP) { return boundary; }
    return c;
}
