//! Stitching the band between two rows of points, as the hardware does: the ruler-function
//! transition between rows of any two factors, and regular bands with the hardware's diagonals.

use super::HardwareTessellation;
use crate::sampling::hardware::Axis;

/// Where vertex `i` of the half edge ends up at the largest factor, in ruler-function split
/// order: the transition stitch advances on a row when the row has a point at that position.
/// It covers half edges of up to 32 points (odd factors up to 65, even up to 64).
const FINAL_POINT_POSITION: [i32; 33] = [
    0, 32, 16, 8, 17, 4, 18, 9, 19, 2, 20, 10, 21, 5, 22, 11, 23, 1, 24, 12, 25, 6, 26, 13, 27, 3, 28, 14,
    29, 7, 30, 15, 31,
];

/// How the diagonals of a regular band run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Diagonals {
    InsideToOutside,
    InsideToOutsideExceptMiddle,
    Mirrored,
}

/// Accumulates triangles.
pub(super) struct Emit<'a> {
    pub(super) out: &'a mut HardwareTessellation,
    pub(super) region: u32,
}

impl Emit<'_> {
    /// A triangle given in Direct3D's clockwise order (v down), which is counter-clockwise in
    /// the `(u, v)` plane.
    pub(super) fn tri(&mut self, a: u32, b: u32, c: u32) {
        self.out.triangles.push([a, b, c]);
        self.out.regions.push(self.region);
    }

    /// The band between an outer row and an inner row whose factors may differ: the
    /// ruler-function transition, walked from both ends towards the middle.
    pub(super) fn transition(&mut self, inner: &[u32], inner_axis: &Axis, outer: &[u32], outer_axis: &Axis) {
        let inner_half = inner_axis.half_points - i64::from(inner_axis.odd);
        let outer_half = outer_axis.half_points - i64::from(outer_axis.odd);
        let (mut o, mut i) = (0usize, 0usize);
        let advance_outer = |e: &mut Self, o: &mut usize, i: usize| {
            e.tri(outer[*o], outer[*o + 1], inner[i]);
            *o += 1;
        };
        let advance_inner = |e: &mut Self, o: usize, i: &mut usize| {
            e.tri(inner[*i], outer[o], inner[*i + 1]);
            *i += 1;
        };
        if (FINAL_POINT_POSITION[0] as i64) < outer_half {
            advance_outer(self, &mut o, i);
        }
        for &position in &FINAL_POINT_POSITION[1..] {
            let position = position as i64;
            if position < inner_half {
                advance_inner(self, o, &mut i);
            }
            if position < outer_half {
                advance_outer(self, &mut o, i);
            }
        }
        if inner_axis.odd != outer_axis.odd || inner_axis.odd {
            if inner_axis.odd == outer_axis.odd {
                // Both odd: a quad in the middle.
                self.tri(inner[i], outer[o], inner[i + 1]);
                self.tri(inner[i + 1], outer[o], outer[o + 1]);
                i += 1;
                o += 1;
            } else if !inner_axis.odd {
                // A triangle pointing inside.
                self.tri(inner[i], outer[o], outer[o + 1]);
                o += 1;
            } else {
                // A triangle pointing outside.
                self.tri(inner[i], outer[o], inner[i + 1]);
                i += 1;
            }
        }
        for &position in FINAL_POINT_POSITION[1..].iter().rev() {
            let position = position as i64;
            if position < outer_half {
                advance_outer(self, &mut o, i);
            }
            if position < inner_half {
                advance_inner(self, o, &mut i);
            }
        }
        if (FINAL_POINT_POSITION[0] as i64) < outer_half {
            advance_outer(self, &mut o, i);
        }
        debug_assert_eq!((o + 1, i + 1), (outer.len(), inner.len()), "transition did not reach the row ends");
    }

    /// A band between rows whose point counts differ by 2 (`trapezoid`: one triangle at each
    /// end) or are equal (a strip of quads).
    pub(super) fn regular(&mut self, trapezoid: bool, diagonals: Diagonals, inner: &[u32], outer: &[u32]) {
        let n = inner.len();
        let (mut o, mut i) = (0usize, 0usize);
        if trapezoid {
            self.tri(outer[o], outer[o + 1], inner[i]);
            o += 1;
        }
        // Diagonal from the inner point to the next outer point, or the other way.
        let forward = |e: &mut Self, o: usize, i: usize| {
            e.tri(outer[o], outer[o + 1], inner[i]);
            e.tri(inner[i], outer[o + 1], inner[i + 1]);
        };
        let backward = |e: &mut Self, o: usize, i: usize| {
            e.tri(outer[o], inner[i + 1], inner[i]);
            e.tri(outer[o], outer[o + 1], inner[i + 1]);
        };
        match diagonals {
            Diagonals::InsideToOutside => {
                for _ in 0..n.saturating_sub(1) {
                    self.tri(inner[i], outer[o], outer[o + 1]);
                    self.tri(inner[i], outer[o + 1], inner[i + 1]);
                    i += 1;
                    o += 1;
                }
            }
            Diagonals::InsideToOutsideExceptMiddle => {
                let first = (n / 2).saturating_sub(1);
                for _ in 0..first {
                    forward(self, o, i);
                    i += 1;
                    o += 1;
                }
                backward(self, o, i);
                i += 1;
                o += 1;
                for _ in first + 2..n {
                    forward(self, o, i);
                    i += 1;
                    o += 1;
                }
            }
            Diagonals::Mirrored => {
                for p in 0..n.saturating_sub(1) {
                    if p < n / 2 {
                        backward(self, o, i);
                    } else {
                        self.tri(inner[i], outer[o], outer[o + 1]);
                        self.tri(inner[i], outer[o + 1], inner[i + 1]);
                    }
                    i += 1;
                    o += 1;
                }
            }
        }
        if trapezoid {
            self.tri(outer[o], outer[o + 1], inner[i]);
        }
    }
}
