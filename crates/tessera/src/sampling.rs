//! Edge samplings: the ordered parameters at which a shared boundary curve is cut.
//!
//! A sampling is always stated in the edge's canonical orientation (see `topology`); a patch
//! that runs along the edge the other way reads it mirrored (`t → 1 − t`, index `k → n − k`).
//! Because every patch of an edge reads the same sampling and the engine evaluates each edge
//! vertex once, neighbours meet exactly.

use std::sync::Arc;

/// Largest uniform factor accepted: past it a single patch would need more than 2³² indices.
pub const MAX_FACTOR: u32 = 16_384;

/// The parameters on one edge, in `[0, 1]`, endpoints included.
#[derive(Debug, Clone, PartialEq)]
pub enum EdgeSampling {
    /// `segments` equal steps: parameters `k / segments`.
    Uniform { segments: u32 },
    /// Explicit increasing parameters, starting with 0 and ending with 1.
    Params(Arc<[f64]>),
    /// A real factor `factor ≥ 1` cut by a fractional rule. Every rule here is symmetric
    /// about the edge midpoint (`param(n − k) = 1 − param(k)`), so the sampling needs no
    /// direction: both neighbours get the same points whichever way they run.
    Fractional { factor: f64, spacing: Spacing },
    /// The SD-2 symmetric cut of `factor`, reverse-projected with the depths of the edge's
    /// canonical start and end vertices (`pattern::sd2::warped_param`). The warp depends
    /// only on the edge's own ends, so both neighbours get the same points.
    Warped { factor: f64, depths: [f64; 2] },
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

impl EdgeSampling {
    /// Uniform sampling with `segments ≥ 1` steps.
    pub fn uniform(segments: u32) -> Self {
        EdgeSampling::Uniform { segments: segments.max(1) }
    }

    /// Number of segments (points minus one).
    pub fn segments(&self) -> u32 {
        match self {
            EdgeSampling::Uniform { segments } => *segments,
            EdgeSampling::Params(p) => p.len().saturating_sub(1) as u32,
            EdgeSampling::Fractional { factor, spacing } => spacing_segments(*factor, *spacing),
            EdgeSampling::Warped { factor, .. } => crate::pattern::sd2::symmetric_segments(*factor),
        }
    }

    /// The real factor: the segment count for integer samplings.
    pub fn factor(&self) -> f64 {
        match self {
            EdgeSampling::Fractional { factor, .. } | EdgeSampling::Warped { factor, .. } => *factor,
            other => other.segments() as f64,
        }
    }

    /// The `k`-th parameter in canonical orientation, `0 ≤ k ≤ segments`.
    #[inline]
    pub fn param(&self, k: u32) -> f64 {
        match self {
            EdgeSampling::Uniform { segments } => {
                if k == *segments {
                    1.0
                } else {
                    k as f64 / *segments as f64
                }
            }
            EdgeSampling::Params(p) => p[k as usize],
            EdgeSampling::Fractional { factor, spacing } => spacing_param(*factor, *spacing, k),
            EdgeSampling::Warped { factor, depths } => {
                let t = crate::pattern::sd2::symmetric_param(*factor, k);
                crate::pattern::sd2::warped_param(t, depths[0], depths[1])
            }
        }
    }

    /// The `k`-th parameter as seen by a patch that runs along the edge reversed or not.
    #[inline]
    pub fn local_param(&self, k: u32, reversed: bool) -> f64 {
        if reversed {
            1.0 - self.param(self.segments() - k)
        } else {
            self.param(k)
        }
    }
}

/// Segments of a real factor under `spacing`.
pub fn spacing_segments(factor: f64, spacing: Spacing) -> u32 {
    match spacing {
        Spacing::Symmetric => crate::pattern::sd2::symmetric_segments(factor),
        Spacing::Hardware(p) => crate::pattern::hardware::edge_segments(factor, p),
    }
}

/// Parameter `k` (`0 ≤ k ≤ segments`) of a real factor under `spacing`.
pub fn spacing_param(factor: f64, spacing: Spacing, k: u32) -> f64 {
    match spacing {
        Spacing::Symmetric => crate::pattern::sd2::symmetric_param(factor, k),
        Spacing::Hardware(p) => crate::pattern::hardware::edge_param(factor, p, k),
    }
}

pub use crate::pattern::hardware::Partitioning;
