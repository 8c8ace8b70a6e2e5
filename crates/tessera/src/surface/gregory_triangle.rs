//! Quartic Gregory triangles: OpenSubdiv's `GREGORY_TRIANGLE` patch (18 points), the end cap
//! of a Loop surface around an irregular vertex.
//!
//! The patch is a quartic Bézier triangle whose three interior points are each a rational
//! blend of two face points, so that the surface can match different cross-boundary
//! tangents along the two edges at a corner (`far/patchBasis.cpp`, `EvalBasisGregoryTri`;
//! point order of `far/patchDescriptor.h`'s `GREGORY_TRIANGLE` as built by
//! `far/loopPatchBuilder.cpp`). Evaluation follows OpenSubdiv's exactly: position from the
//! blended net, and first derivatives from the blended net's derivatives with the blend held
//! fixed. The rational blend's own derivatives are left out, as OpenSubdiv leaves them out
//! for triangles in every build (its `OPENSUBDIV_GREGORY_EVAL_TRUE_DERIVATIVES` switch only
//! concerns the quad Gregory patch), so off the edges these are not the exact derivatives of
//! the position; on the edges and at the corners they are.

use super::{triangle_point, QuarticTriangle, SurfaceDerivatives, SurfacePoint};
use glam::{DVec2, DVec3};
use std::ops::{Add, Div, Sub};

/// A quartic Gregory triangle in OpenSubdiv's `GREGORY_TRIANGLE` point order: per corner
/// `c = 0, 1, 2` five points `5c..5c+5` — the corner point `P`, the edge point `Ep` towards
/// the next corner, the edge point `Em` towards the previous one, and the face points `Fp`
/// (beside `Ep`) and `Fm` (beside `Em`) — then the three middle points of edges 0, 1, 2
/// (`15, 16, 17`).
///
/// As a quartic Bézier triangle ([`QuarticTriangle`], `λ = (1−u−v, u, v)`) the points are
/// `b400 = P0`, `b310 = Ep0`, `b301 = Em0`, `b040 = P1`, `b031 = Ep1`, `b130 = Em1`,
/// `b004 = P2`, `b103 = Ep2`, `b013 = Em2`, `b220`, `b022`, `b202` = the edge middles, and
/// the interior points blend the face points with weights that are 1 at the edge the face
/// point sits beside:
/// `b211 = (u·Fp0 + v·Fm0)/(u+v)`, `b121 = (v·Fp1 + w·Fm1)/(v+w)`,
/// `b112 = (w·Fp2 + u·Fm2)/(w+u)` with `w = 1−u−v`; at a corner, where its blend is 0/0,
/// an interior point is its `Fp` (OpenSubdiv's choice; its basis weight vanishes there).
#[derive(Debug, Clone, PartialEq)]
pub struct GregoryTriangle {
    pub points: [DVec3; 18],
}

/// Where each Gregory point sits in the quartic Bézier net, as `(i, j, k)`; `None` for the
/// face points, which enter through the blends.
const BEZIER_OF_GREGORY: [Option<(usize, usize, usize)>; 18] = [
    Some((4, 0, 0)),
    Some((3, 1, 0)),
    Some((3, 0, 1)),
    None,
    None,
    Some((0, 4, 0)),
    Some((0, 3, 1)),
    Some((1, 3, 0)),
    None,
    None,
    Some((0, 0, 4)),
    Some((1, 0, 3)),
    Some((0, 1, 3)),
    None,
    None,
    Some((2, 2, 0)),
    Some((0, 2, 2)),
    Some((2, 0, 2)),
];

impl GregoryTriangle {
    /// The rational weights `(of Fp, of Fm)` of each corner's face points at `uv`, computed
    /// as OpenSubdiv computes them (same operations, same 0/0 rule), so that the blended net
    /// matches its basis to rounding.
    pub fn blend_weights(uv: DVec2) -> [(f64, f64); 3] {
        Self::blend_weights_of(uv.x, uv.y)
    }

    /// [`GregoryTriangle::blend_weights`] at `(u, v)` in any float type (the f32 kernel's
    /// lanes take it too): the one home of the blend and its 0/0 rule.
    #[inline(always)]
    pub(crate) fn blend_weights_of<T>(u: T, v: T) -> [(T, T); 3]
    where
        T: Copy + PartialOrd + From<u8> + Add<Output = T> + Sub<Output = T> + Div<Output = T>,
    {
        let (zero, one) = (T::from(0), T::from(1));
        let w = one - u - v;
        let pair = |a: T, b: T| if a + b > zero { (a / (a + b), b / (a + b)) } else { (one, zero) };
        [pair(u, v), pair(v, w), pair(w, u)]
    }

    /// The quartic Bézier triangle that the patch is at `uv`: the fixed points in place and
    /// each interior point the blend of its face points at `uv`. Cost: 18 points.
    pub fn blended(&self, uv: DVec2) -> QuarticTriangle {
        self.blended_with(Self::blend_weights(uv))
    }

    /// The quartic Bézier triangle with the fixed points in place and each corner's interior
    /// point `weights[c].0 · Fp + weights[c].1 · Fm` (weights as
    /// [`GregoryTriangle::blend_weights`] gives them). Cost: 18 points.
    pub(crate) fn blended_with(&self, weights: [(f64, f64); 3]) -> QuarticTriangle {
        let p = &self.points;
        let mut points = [DVec3::ZERO; 15];
        for (g, at) in BEZIER_OF_GREGORY.iter().enumerate() {
            if let Some((i, j, k)) = *at {
                points[QuarticTriangle::index(i, j, k)] = p[g];
            }
        }
        for (&(fp, fm, (i, j, k)), (a, b)) in Self::INTERIOR.iter().zip(weights) {
            points[QuarticTriangle::index(i, j, k)] = p[fp] * a + p[fm] * b;
        }
        QuarticTriangle { points }
    }

    /// Per corner `c`: its face points `(Fp, Fm)` and where their blend stands in the quartic
    /// net, `(i, j, k)` (`b211`, `b121`, `b112`).
    pub(crate) const INTERIOR: [(usize, usize, (usize, usize, usize)); 3] =
        [(3, 4, (2, 1, 1)), (8, 9, (1, 2, 1)), (13, 14, (1, 1, 2))];

    /// Position at `uv` (the blended net's). Cost: one [`GregoryTriangle::blended`] and one
    /// quartic evaluation.
    pub fn position(&self, uv: DVec2) -> DVec3 {
        self.blended(uv).position(uv)
    }

    /// Position and first derivatives as OpenSubdiv evaluates them: those of the net
    /// blended at `uv`, the blend held fixed (module docs). Cost: one
    /// [`GregoryTriangle::blended`] and one [`QuarticTriangle::derivatives`].
    pub fn derivatives(&self, uv: DVec2) -> SurfaceDerivatives {
        self.blended(uv).derivatives(uv)
    }

    /// Position and unit normal `S_u × S_v` of [`GregoryTriangle::derivatives`] (limit normal
    /// where they are parallel).
    pub fn eval(&self, uv: DVec2) -> SurfacePoint {
        let net = self.blended(uv);
        triangle_point(net.derivatives(uv), uv, || net.mixed_derivative(uv), |q| self.derivatives(q))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::quartic_triangle::tests::{difference, fixture, random_points};
    use crate::test_support::Lcg;

    /// Position and derivatives equal OpenSubdiv's GREGORY_TRIANGLE basis weights applied to
    /// random points at every fixture point, corners and near-corner points included.
    #[test]
    fn matches_opensubdiv_basis() {
        let records = fixture();
        let mut rng = Lcg(0x6e_e6);
        let (mut count, mut worst) = (0, 0.0f64);
        for r in records.iter().filter(|r| r.loop_mask.is_none()) {
            for offset in [DVec3::ZERO, DVec3::new(-4.0, 1.0, 2.0)] {
                let points: [DVec3; 18] = random_points(&mut rng, offset);
                let scale = points.iter().map(|p| p.abs().max_element()).fold(0.0, f64::max);
                let g = GregoryTriangle { points };
                let d = difference(g.derivatives(r.uv), r, &points);
                assert!(d <= 1e-12 * scale, "at {}: differs by {d}", r.uv);
                assert_eq!(g.position(r.uv), g.derivatives(r.uv).position);
                worst = worst.max(d / scale);
            }
            count += 1;
        }
        assert_eq!(count, 37);
        eprintln!("GREGORY_TRIANGLE: worst relative difference {worst:e}");
    }

    /// With each pair of face points equal the patch is the plain quartic Bézier triangle,
    /// and its derivatives are then the exact ones.
    #[test]
    fn equal_face_points_give_the_bezier_triangle() {
        let mut rng = Lcg(9);
        let mut points: [DVec3; 18] = random_points(&mut rng, DVec3::ZERO);
        for c in 0..3 {
            points[5 * c + 4] = points[5 * c + 3];
        }
        let g = GregoryTriangle { points };
        let bezier = g.blended(DVec2::new(0.3, 0.3));
        for a in 0..=10 {
            for b in 0..=10 - a {
                let uv = DVec2::new(a as f64, b as f64) / 10.0;
                let (x, y) = (g.derivatives(uv), bezier.derivatives(uv));
                for (p, q) in [(x.position, y.position), (x.du, y.du), (x.dv, y.dv)] {
                    assert!((p - q).length() < 1e-14, "{uv}");
                }
            }
        }
    }

    /// Along each edge only the face point beside it counts: moving the other one of each
    /// pair changes nothing there (what lets the patch match both neighbours' tangents).
    #[test]
    fn each_edge_sees_only_its_own_face_points() {
        let mut rng = Lcg(10);
        let points: [DVec3; 18] = random_points(&mut rng, DVec3::ZERO);
        let g = GregoryTriangle { points };
        // Edge e and the face points off it: edge 0 (v = 0) is beside Fp0 and Fm1, so Fm0
        // and Fp1, Fp2, Fm2 may move; and so on around.
        let edges = [
            (DVec2::ZERO, DVec2::X, [4, 8, 13, 14]),
            (DVec2::X, DVec2::Y, [3, 4, 9, 13]),
            (DVec2::Y, DVec2::ZERO, [3, 8, 9, 14]),
        ];
        for (from, to, free) in edges {
            let mut moved = g.clone();
            for f in free {
                moved.points[f] += DVec3::new(1.0, -2.0, 3.0);
            }
            for n in 0..=16 {
                let uv = from.lerp(to, n as f64 / 16.0);
                assert!((g.position(uv) - moved.position(uv)).length() < 1e-14, "{uv}");
            }
        }
    }

    /// The normal is the unit cross product of the derivatives, at corners too.
    #[test]
    fn normals_are_unit_cross_products() {
        let mut rng = Lcg(11);
        let g = GregoryTriangle { points: random_points(&mut rng, DVec3::ZERO) };
        for uv in [DVec2::ZERO, DVec2::X, DVec2::Y, DVec2::new(0.25, 0.5)] {
            let d = g.derivatives(uv);
            let n = g.eval(uv).normal;
            assert!((n - d.du.cross(d.dv).normalize()).length() < 1e-14, "{uv}");
        }
    }
}
