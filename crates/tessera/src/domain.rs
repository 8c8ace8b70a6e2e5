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

    /// Parameters of corner `i` (`i` below [`Domain::corner_count`]).
    #[inline]
    pub fn corner(self, i: usize) -> DVec2 {
        // A match rather than indexing an array literal: the array would be built on the stack
        // per call, and this runs once per edge sample in the engine.
        match (self, i) {
            (_, 0) => DVec2::ZERO,
            (_, 1) => DVec2::X,
            (Domain::Tri, 2) | (Domain::Quad, 3) => DVec2::Y,
            (Domain::Quad, 2) => DVec2::ONE,
            _ => panic!("corner {i} of a {self:?} domain"),
        }
    }

    /// Parameters of the point at `t ∈ [0,1]` along edge `e` (from corner `e` to `e+1`).
    #[inline]
    pub fn edge_point(self, e: usize, t: f64) -> DVec2 {
        let a = self.corner(e);
        let b = self.corner(if e + 1 == self.corner_count() { 0 } else { e + 1 });
        // Written as a convex combination so t=0 and t=1 give the corners exactly.
        a * (1.0 - t) + b * t
    }
}
