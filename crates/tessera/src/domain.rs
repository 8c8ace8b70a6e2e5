//! Parameter domains. A [`Domain::Quad`] is `[0,1]²` with corners `c0=(0,0)`, `c1=(1,0)`,
//! `c2=(1,1)`, `c3=(0,1)`; a [`Domain::Tri`] is the triangle `u,v ≥ 0, u+v ≤ 1` with corners
//! `c0=(0,0)`, `c1=(1,0)`, `c2=(0,1)` (barycentric `(1-u-v, u, v)`). In both, corners run
//! counter-clockwise and edge `i` goes from corner `i` to corner `i+1`.
//!
//! A module of its own so that patterns, which only ever see the domain, do not depend on the
//! surfaces (the OpenSubdiv Bfr separation).

use glam::DVec2;

/// The parameter domain of a patch.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Domain {
    /// Triangle `u,v ≥ 0, u+v ≤ 1`; 3 corners, 3 edges.
    Tri,
    /// Unit square; 4 corners, 4 edges.
    Quad,
}

impl Domain {
    /// Number of corners (and of edges).
    pub fn corner_count(self) -> usize {
        match self {
            Domain::Tri => 3,
            Domain::Quad => 4,
        }
    }

    /// Parameters of corner `i`.
    pub fn corner(self, i: usize) -> DVec2 {
        match self {
            Domain::Tri => [DVec2::ZERO, DVec2::X, DVec2::Y][i],
            Domain::Quad => [DVec2::ZERO, DVec2::X, DVec2::ONE, DVec2::Y][i],
        }
    }

    /// Parameters of the point at `t ∈ [0,1]` along edge `e` (from corner `e` to `e+1`).
    pub fn edge_point(self, e: usize, t: f64) -> DVec2 {
        let n = self.corner_count();
        let a = self.corner(e);
        let b = self.corner((e + 1) % n);
        // Written as a convex combination so t=0 and t=1 give the corners exactly.
        a * (1.0 - t) + b * t
    }
}
