//! Edge samplings: the ordered parameters at which a shared boundary curve is cut.
//!
//! A sampling is always stated in the edge's canonical orientation (see `topology`); a patch
//! that runs along the edge the other way reads it mirrored (`t → 1 − t`, index `k → n − k`).
//! Because every patch of an edge reads the same sampling and the engine evaluates each edge
//! vertex once, neighbours meet exactly.

use std::sync::Arc;

/// The parameters on one edge, in `[0, 1]`, endpoints included.
#[derive(Debug, Clone, PartialEq)]
pub enum EdgeSampling {
    /// `segments` equal steps: parameters `k / segments`.
    Uniform { segments: u32 },
    /// Explicit increasing parameters, starting with 0 and ending with 1.
    Params(Arc<[f64]>),
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
