//! Criteria: decide how finely each shared edge and each patch interior is sampled.
//!
//! A criterion's output is a [`Plan`]: one [`EdgeSampling`] per canonical edge of the
//! topology and interior factors per patch. Crack-freeness rests on one rule: the sampling of
//! an edge is decided once, from data all its patches agree on, and every patch reads it.

pub mod bounds;
pub mod esc;
pub mod screen;
pub mod sd2;
pub mod tolerance;
pub mod view;

use crate::error::{Error, Result};
use crate::sampling::EdgeSampling;
use crate::surface::SurfaceSet;

pub use crate::sampling::MAX_FACTOR;

/// Samplings for every edge and interior factors for every patch.
#[derive(Debug, Clone, PartialEq)]
pub struct Plan {
    /// One per `topology.edges` entry, in canonical orientation.
    pub edges: Vec<EdgeSampling>,
    /// Interior factors per patch (`[u, v]`; triangles use the first).
    pub interior: Vec<[u32; 2]>,
    /// Patches to tessellate; culled patches emit nothing (their edges with visible
    /// neighbours are still sampled as those neighbours need).
    pub visible: Vec<bool>,
}

impl Plan {
    /// The uniform plan: factor `n` everywhere. Errors for `n = 0` or `n > MAX_FACTOR`.
    pub fn uniform(set: &SurfaceSet, n: u32) -> Result<Plan> {
        if n == 0 || n > MAX_FACTOR {
            return Err(Error::InvalidArgument(format!(
                "factor {n} is out of range: use an integer from 1 to {MAX_FACTOR}"
            )));
        }
        Ok(Plan {
            edges: vec![EdgeSampling::uniform(n); set.topology.edges.len()],
            interior: vec![[n, n]; set.patches.len()],
            visible: vec![true; set.patches.len()],
        })
    }
}
