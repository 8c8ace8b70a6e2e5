//! Edge samplings: the ordered parameters at which a shared boundary curve is cut.
//!
//! A sampling is always stated in the edge's canonical orientation (see `topology`); a patch
//! that runs along the edge the other way reads it mirrored (`t → 1 − t`, index `k → n − k`).
//! Because every patch of an edge reads the same sampling and the engine evaluates each edge
//! vertex once, neighbours meet exactly.
//!
//! A [`crate::criterion::Plan`] stores samplings as plain per-edge arrays (segments, `f32`
//! factors, depths, lattice points); [`SamplingKind`] says how they turn into parameters, and
//! [`param`] is that rule, the one every engine calls.

/// Largest uniform factor accepted: past it a single patch would need more than 2³² indices.
pub const MAX_FACTOR: u32 = 16_384;

/// How a plan's per-edge arrays give the parameters of an edge. One kind per plan.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum SamplingKind {
    /// `segments` equal steps: parameters `k / segments`.
    Uniform,
    /// A real factor `factor ≥ 1` cut by a fractional rule. Every rule here is symmetric
    /// about the edge midpoint (`param(n − k) = 1 − param(k)`), so the sampling needs no
    /// direction: both neighbours get the same points whichever way they run.
    Fractional(Spacing),
    /// The SD-2 symmetric cut of `factor`, reverse-projected with the depths of the edge's
    /// canonical start and end vertices (`pattern::sd2::warped_param`). The warp depends
    /// only on the edge's own ends, so both neighbours get the same points.
    Warped,
    /// Points of a lattice (ESC): point `k` is `lattice[k] / factor`, the numerators listed
    /// in the plan, increasing from 0 to `factor`.
    Lattice,
}

/// How a real factor cuts an edge.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Spacing {
    /// SD-2 (paper 001, Fig. 4): `⌈f⌉` segments, the inner ones `1/f` long, the remainder
    /// shared equally by the first and the last.
    Symmetric,
    /// The Direct3D 11 hardware tessellator's edge partition (`pattern::hardware`): integer,
    /// pow2, fractional_odd or fractional_even, in its 16.16 fixed point.
    Hardware(Partitioning),
}

/// One edge's row of a plan: what [`param`] reads.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EdgeRow<'a> {
    pub segments: u32,
    pub factor: f32,
    /// Depths of the canonical start and end (warped samplings only).
    pub depths: [f32; 2],
    /// Lattice numerators, `segments + 1` of them (lattice samplings only).
    pub lattice: &'a [u32],
}

/// The `k`-th parameter (`0 ≤ k ≤ segments`) of an edge in canonical orientation: the one
/// rule every engine reads edge points by. Cost: O(1).
#[inline]
pub fn param(kind: SamplingKind, row: &EdgeRow<'_>, k: u32) -> f64 {
    match kind {
        SamplingKind::Uniform => uniform_param(row.segments, k),
        SamplingKind::Fractional(spacing) => spacing_param(row.factor as f64, spacing, k),
        SamplingKind::Warped => {
            let t = symmetric_param(row.factor as f64, k);
            warped_param(t, row.depths[0] as f64, row.depths[1] as f64)
        }
        SamplingKind::Lattice => {
            if k == row.segments {
                1.0
            } else {
                row.lattice[k as usize] as f64 / row.factor as f64
            }
        }
    }
}

/// [`param`] of every `k` in `ks`, in order: the same values bit for bit, with what they
/// share found once (a hardware partition of the factor, which [`param`] finds anew for
/// each `k`). For a writer that reads an edge's samples in a row. Cost: O(1) + O(1) per `k`.
#[inline]
pub fn params<'a>(
    kind: SamplingKind,
    row: &EdgeRow<'a>,
    ks: std::ops::Range<u32>,
) -> impl Iterator<Item = f64> + 'a {
    let row = *row;
    let axis = match kind {
        SamplingKind::Fractional(Spacing::Hardware(p)) => Some(hardware::Axis::edge(row.factor as f64, p)),
        _ => None,
    };
    ks.map(move |k| match &axis {
        Some(axis) => axis.param(k),
        None => param(kind, &row, k),
    })
}

/// Parameter `k` of `segments` equal steps: `k / segments`, exactly 1 at the end. Cost: O(1).
#[inline]
pub fn uniform_param(segments: u32, k: u32) -> f64 {
    if k == segments {
        1.0
    } else {
        k as f64 / segments as f64
    }
}

/// Segments of a real factor under `spacing`.
pub fn spacing_segments(factor: f64, spacing: Spacing) -> u32 {
    match spacing {
        Spacing::Symmetric => symmetric_segments(factor),
        Spacing::Hardware(p) => hardware::edge_segments(factor, p),
    }
}

/// Parameter `k` (`0 ≤ k ≤ segments`) of a real factor under `spacing`.
pub fn spacing_param(factor: f64, spacing: Spacing, k: u32) -> f64 {
    match spacing {
        Spacing::Symmetric => symmetric_param(factor, k),
        Spacing::Hardware(p) => hardware::edge_param(factor, p, k),
    }
}

pub mod hardware;
mod symmetric;

pub use hardware::Partitioning;
pub use symmetric::{symmetric_param, symmetric_segments, warped_param};

#[cfg(test)]
mod tests {
    use super::*;

    /// `params` is `param` for every `k`, bit for bit, on every kind and across each
    /// partitioning's factor range (the writer reads edges through `params`, the other
    /// engines through `param`).
    #[test]
    fn params_in_a_row_are_param_of_each_k() {
        let lattice: Vec<u32> = (0..=40).map(|k| k * k).collect();
        let mut kinds = vec![SamplingKind::Uniform, SamplingKind::Warped, SamplingKind::Lattice];
        kinds.push(SamplingKind::Fractional(Spacing::Symmetric));
        for p in [
            Partitioning::Integer,
            Partitioning::Pow2,
            Partitioning::FractionalOdd,
            Partitioning::FractionalEven,
        ] {
            kinds.push(SamplingKind::Fractional(Spacing::Hardware(p)));
        }
        let mut checked = 0;
        for kind in kinds {
            for step in 0..=250 {
                let factor = 1.0 + step as f32 * 0.127;
                let segments = match kind {
                    SamplingKind::Fractional(spacing) => spacing_segments(factor as f64, spacing),
                    SamplingKind::Lattice => (step % 40 + 1) as u32,
                    _ => factor.ceil() as u32,
                };
                let factor =
                    if kind == SamplingKind::Lattice { (segments * segments) as f32 } else { factor };
                let row = EdgeRow { segments, factor, depths: [0.7, 1.9], lattice: &lattice };
                let one_by_one: Vec<u64> = (0..=segments).map(|k| param(kind, &row, k).to_bits()).collect();
                let in_a_row: Vec<u64> = params(kind, &row, 0..segments + 1).map(f64::to_bits).collect();
                assert_eq!(in_a_row, one_by_one, "{kind:?}, factor {factor}");
                checked += one_by_one.len();
            }
        }
        assert!(checked > 8 * 251 * 2);
    }

    /// The fixed-point conversion rounds to nearest, ties to even, as `round_ties_even`
    /// does: on exact ties (odd multiples of 2⁻¹⁷), beside them and across the factors'
    /// range.
    #[test]
    fn to_fixed_rounds_ties_to_even() {
        let mut ties = 0;
        for n in (0..(80u32 << 17)).step_by(7) {
            let x = n as f32 / 131072.0;
            for x in [x, f32::from_bits(x.to_bits().wrapping_sub(1)), f32::from_bits(x.to_bits() + 1)] {
                let expected = (x as f64 * 65536.0).round_ties_even() as i64;
                assert_eq!(hardware::to_fixed(x), expected, "{x}");
            }
            ties += usize::from(n % 2 == 1);
        }
        assert!(ties > 1 << 19);
    }
}
