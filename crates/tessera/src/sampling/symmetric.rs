//! The SD-2 cut (paper 001, Fig. 4) and its reverse projection: a 1-D partition, like the
//! hardware's ([`super::hardware`]), that every engine reads edges by.

use super::MAX_FACTOR;

/// Segments of an edge with real factor `factor` under the symmetric remainder: `⌈f⌉`,
/// with `f` clamped to `[1, MAX_FACTOR]` (NaN reads as 1). Cost: O(1).
pub fn symmetric_segments(factor: f64) -> u32 {
    clamp_factor(factor).ceil() as u32
}

fn clamp_factor(factor: f64) -> f64 {
    if factor.is_nan() {
        1.0
    } else {
        factor.clamp(1.0, MAX_FACTOR as f64)
    }
}

/// Point `k` (`0 ≤ k ≤ n`, `n = symmetric_segments(f)`) of the symmetric-remainder cut, in
/// `[0, 1]`. The second half is computed as the mirror of the first, `1 − param(n − k)`, so
/// the cut is symmetric to rounding and needs no direction. (Watertightness does not rest on
/// it: the engine evaluates each edge's samples once.) Cost: O(1).
pub fn symmetric_param(factor: f64, k: u32) -> f64 {
    let f = clamp_factor(factor);
    let n = f.ceil() as u32;
    if k == 0 {
        return 0.0;
    }
    if k >= n {
        return 1.0;
    }
    if 2 * k == n {
        return 0.5; // exact, so the mirror holds bit for bit
    }
    if 2 * k > n {
        return 1.0 - symmetric_param(f, n - k);
    }
    let remainder = f - (n - 1) as f64; // in (0, 1]; 1 for integer factors
    let shift = 0.5 * (1.0 - remainder) / f;
    k as f64 / f - shift
}

/// An edge parameter `t` (from the end with depth `za` to the end with depth `zb`) warped by
/// reverse projection: `t' = (t/zb) / ((1 − t)/za + t/zb)`. Depths must be positive (the
/// criterion clamps them to the near plane). Cost: O(1).
pub fn warped_param(t: f64, za: f64, zb: f64) -> f64 {
    if t <= 0.0 {
        return 0.0;
    }
    if t >= 1.0 {
        return 1.0;
    }
    let (a, b) = ((1.0 - t) / za, t / zb);
    b / (a + b)
}
