//! The parameters of a uniform edge's samples in its patch's domain, tabulated once per
//! factor: what the writer's per-edge rule (`push_edge_params`: [`crate::criterion::Plan::param`]
//! of a uniform plan, `k / n`, placed on the patch's local edge by [`Domain::edge_point`])
//! computes, the same bits, without a division and a placement per sample.
//!
//! Why: on the cow's adaptive frames (5,804 PN triangles, edges of 4 to 7 segments) that rule
//! was a third of the edge pass, which was a third of the frame.

use crate::domain::Domain;
use crate::sampling::uniform_param;
use glam::DVec2;

/// For one factor `n`, each domain's local edges in both directions: `[local][reversed][k]`
/// for the canonical samples `k = 0 ..= n`.
#[derive(Default)]
pub(crate) struct UniformEdgeParams {
    n: u32,
    quad: [[Vec<DVec2>; 2]; 4],
    tri: [[Vec<DVec2>; 2]; 3],
}

impl UniformEdgeParams {
    /// Fills the tables for factor `n` (≥ 1). Cost: O(n).
    pub(crate) fn fill(&mut self, n: u32) {
        self.n = n;
        let (quad, tri) = (self.quad.iter_mut().enumerate(), self.tri.iter_mut().enumerate());
        let edges = quad.map(|(e, t)| (Domain::Quad, e, t)).chain(tri.map(|(e, t)| (Domain::Tri, e, t)));
        for (d, e, by_direction) in edges {
            for (reversed, uvs) in by_direction.iter_mut().enumerate() {
                uvs.clear();
                uvs.extend((0..=n).map(|k| {
                    let t = uniform_param(n, k);
                    d.edge_point(e, if reversed == 1 { 1.0 - t } else { t })
                }));
            }
        }
    }

    /// The factor the tables hold (0: none yet).
    pub(crate) fn factor(&self) -> u32 {
        self.n
    }

    /// The parameters of samples `0 ..= n` of an edge that is local edge `local` of a patch
    /// on `d`, running against the edge's canonical direction where `reversed`.
    #[inline]
    pub(crate) fn get(&self, d: Domain, local: usize, reversed: bool) -> &[DVec2] {
        match d {
            Domain::Quad => &self.quad[local][reversed as usize],
            Domain::Tri => &self.tri[local][reversed as usize],
        }
    }
}
