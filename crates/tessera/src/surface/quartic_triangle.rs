//! Quartic Bézier triangles, and the exact conversion of OpenSubdiv's regular Loop patch (the
//! 12-point quartic box-spline triangle, `PatchDescriptor::LOOP`) into one.
//!
//! A regular Loop patch is a piece of a three-direction quartic box spline, a polynomial of
//! degree 4 over the triangle, so it has an exact quartic Bézier form; converting once lets
//! evaluation, bounds and subdivision share the Bézier machinery. The box-spline points are in
//! OpenSubdiv's order (`far/patchBasis.cpp`, `EvalBasisBoxSplineTri`): three rows of a
//! triangular grid, the patch being the triangle of points 4, 5, 8,
//!
//! ```text
//!         10----11
//!        /  \  /  \
//!       7----8-----9
//!      / \  / \  /  \
//!     3---4-----5----6
//!      \  / \  / \  /
//!       0----1----2
//! ```
//!
//! and a patch on a boundary names its missing points with the triangle boundary mask of
//! `far/patchParam.h` (`PatchParam::GetBoundary`, encoded by `far/patchBuilder.cpp`). The
//! parameterisation is tessera's and OpenSubdiv's alike: `λ = (1−u−v, u, v)`, corner 0 at
//! `(0,0)`, corner 1 at `(1,0)`, corner 2 at `(0,1)` (`far/patchBasis.cpp`'s triangle notes).

use super::{triangle_point, BezierTriangle, SurfaceDerivatives, SurfacePoint};
use glam::{DVec2, DVec3};

/// A quartic Bézier triangle `S(λ) = Σ_{i+j+k=4} 4!/(i!j!k!) λ0^i λ1^j λ2^k b_ijk` with
/// `λ = (1-u-v, u, v)`.
///
/// `points` are stored in the order of [`QuarticTriangle::index`] (as [`BezierTriangle`]'s):
/// `b400, b310, b301, b220, b211, b202, b130, b121, b112, b103, b040, b031, b022, b013, b004`.
#[derive(Debug, Clone, PartialEq)]
pub struct QuarticTriangle {
    pub points: [DVec3; 15],
}

/// `[1, λ, λ², λ³, λ⁴]` for each barycentric coordinate `λ = (1-u-v, u, v)`.
#[inline]
fn powers(uv: DVec2) -> [[f64; 5]; 3] {
    [1.0 - uv.x - uv.y, uv.x, uv.y].map(|x| {
        let x2 = x * x;
        [1.0, x, x2, x * x2, x2 * x2]
    })
}

/// `n!/(i!j!k!)` for `i + j + k = n ≤ 4`.
#[inline]
fn multinomial(i: usize, j: usize, k: usize) -> f64 {
    const FACTORIAL: [f64; 5] = [1.0, 1.0, 2.0, 6.0, 24.0];
    FACTORIAL[i + j + k] / (FACTORIAL[i] * FACTORIAL[j] * FACTORIAL[k])
}

/// The degree-`n` Bernstein polynomial `B^n_ijk` at the point whose powers are `pw`
/// (`k = n − i − j`).
#[inline]
fn bernstein(pw: &[[f64; 5]; 3], i: usize, j: usize, k: usize) -> f64 {
    multinomial(i, j, k) * pw[0][i] * pw[1][j] * pw[2][k]
}

/// The Bézier points of the 12 box-spline basis functions, times 24: row `b` holds the
/// weights of the 12 box-spline points in Bézier point `b` (storage order of
/// [`QuarticTriangle::index`]); every row sums to 24.
///
/// Derived in exact rational arithmetic: each box-spline basis function is the quartic
/// polynomial in `(u, v)` whose monomial coefficients `far/patchBasis.cpp` tabulates; its
/// Bézier coefficients are the solution of the 15×15 interpolation system of the quartic
/// Bernstein basis at the 15 points `(j/4, k/4)`, `j + k ≤ 4` (unique, as the Bernstein
/// polynomials are a basis), checked against the polynomials at further random rational
/// points. All of them came out as integers over 24. The corner rows are the Loop limit
/// masks (`(12·centre + 2·Σ ring)/24` at a regular vertex); the fixture test checks the whole
/// table against OpenSubdiv's own basis at many points.
const BOX_SPLINE_TO_BEZIER_24: [[i8; 12]; 15] = [
    [2, 2, 0, 2, 12, 2, 0, 2, 2, 0, 0, 0], // b400 (corner 0, point 4)
    [1, 3, 0, 0, 12, 4, 0, 1, 3, 0, 0, 0], // b310
    [0, 1, 0, 1, 12, 3, 0, 3, 4, 0, 0, 0], // b301
    [0, 4, 0, 0, 8, 8, 0, 0, 4, 0, 0, 0],  // b220
    [0, 1, 0, 0, 10, 6, 0, 1, 6, 0, 0, 0], // b211
    [0, 0, 0, 0, 8, 4, 0, 4, 8, 0, 0, 0],  // b202
    [0, 3, 1, 0, 4, 12, 0, 0, 3, 1, 0, 0], // b130
    [0, 1, 0, 0, 6, 10, 0, 0, 6, 1, 0, 0], // b121
    [0, 0, 0, 0, 6, 6, 0, 1, 10, 1, 0, 0], // b112
    [0, 0, 0, 0, 4, 3, 0, 3, 12, 1, 1, 0], // b103
    [0, 2, 2, 0, 2, 12, 2, 0, 2, 2, 0, 0], // b040 (corner 1, point 5)
    [0, 1, 0, 0, 3, 12, 1, 0, 4, 3, 0, 0], // b031
    [0, 0, 0, 0, 4, 8, 0, 0, 8, 4, 0, 0],  // b022
    [0, 0, 0, 0, 3, 4, 0, 1, 12, 3, 0, 1], // b013
    [0, 0, 0, 0, 2, 2, 0, 2, 12, 2, 2, 2], // b004 (corner 2, point 8)
];

/// A box-spline point that a boundary makes a phantom, as the reflection
/// `phantom = plus[0] + plus[1] − minus` of real points (point indices of the 12).
#[derive(Clone, Copy)]
struct Phantom {
    phantom: usize,
    plus: [usize; 2],
    minus: usize,
}

const fn phantom(phantom: usize, a: usize, b: usize, minus: usize) -> Phantom {
    Phantom { phantom, plus: [a, b], minus }
}

/// The phantom points of a boundary mask, in the order OpenSubdiv moves their weights onto
/// the real points (`far/patchBasis.cpp`, `adjustBoxSplineTriBoundaryWeights`): the three
/// points beyond each boundary edge (edges 0, 1, 2), then the two beyond each boundary vertex
/// (vertices 0, 1, 2).
///
/// The mask is the 5-bit triangle encoding of `far/patchParam.h`: the upper two bits say how
/// to read the lower three — 0 (and 3): edge bits, 1: vertex bits, 2: edge bits, each with
/// its opposite vertex as a boundary vertex too. A phantom beyond an edge is the reflection of
/// an interior point through the boundary, except at an end of the edge whose other edge is
/// also a boundary, where the corner's own point is reflected instead.
fn phantoms(mask: u8) -> Vec<Phantom> {
    let (upper, lower) = ((mask >> 3) & 3, mask & 7);
    let (edges, vertices) = match upper {
        1 => (0, lower),
        2 => (lower, ((lower & 1) << 2) | (lower >> 1)),
        _ => (lower, 0),
    };
    let edge = |e: u8| edges & (1 << e) != 0;
    let vertex = |v: u8| vertices & (1 << v) != 0;
    let mut out = Vec::new();
    if edge(0) {
        out.push(if edge(2) { phantom(0, 4, 4, 8) } else { phantom(0, 4, 3, 7) });
        out.push(phantom(1, 4, 5, 8));
        out.push(if edge(1) { phantom(2, 5, 5, 8) } else { phantom(2, 5, 6, 9) });
    }
    if edge(1) {
        out.push(if edge(0) { phantom(6, 5, 5, 4) } else { phantom(6, 5, 2, 1) });
        out.push(phantom(9, 5, 8, 4));
        out.push(if edge(2) { phantom(11, 8, 8, 4) } else { phantom(11, 8, 10, 7) });
    }
    if edge(2) {
        out.push(if edge(1) { phantom(10, 8, 8, 5) } else { phantom(10, 8, 11, 9) });
        out.push(phantom(7, 8, 4, 5));
        out.push(if edge(0) { phantom(3, 4, 4, 5) } else { phantom(3, 4, 0, 1) });
    }
    if vertex(0) {
        out.extend([phantom(3, 4, 7, 8), phantom(0, 4, 1, 5)]);
    }
    if vertex(1) {
        out.extend([phantom(2, 5, 1, 4), phantom(6, 5, 9, 8)]);
    }
    if vertex(2) {
        out.extend([phantom(11, 8, 9, 5), phantom(10, 8, 7, 4)]);
    }
    out
}

impl QuarticTriangle {
    /// The exponents `(i, j, k)`, `i + j + k = 2`, of the quadratic Bernstein terms of the
    /// second derivatives, in the order of [`QuarticTriangle::second_differences`].
    pub const QUADRATIC_TERMS: [(usize, usize, usize); 6] =
        [(2, 0, 0), (1, 1, 0), (1, 0, 1), (0, 2, 0), (0, 1, 1), (0, 0, 2)];

    /// Storage index of `b_ijk` (`i + j + k = 4`; `i` is the exponent of `λ0 = 1-u-v`).
    #[inline]
    pub const fn index(i: usize, j: usize, _k: usize) -> usize {
        (4 - i) * (5 - i) / 2 + (4 - i - j)
    }

    /// Control point `b_ijk`.
    #[inline]
    pub fn b(&self, i: usize, j: usize, k: usize) -> DVec3 {
        self.points[Self::index(i, j, k)]
    }

    /// The same surface with `u` and `v` exchanged (`b_ijk ↔ b_ikj`): the opposite
    /// orientation. Cost: 15 copies.
    pub fn swapped_uv(&self) -> Self {
        let mut out = self.clone();
        for i in 0..=4usize {
            for j in 0..=4 - i {
                out.points[Self::index(i, 4 - i - j, j)] = self.b(i, j, 4 - i - j);
            }
        }
        out
    }

    /// The five control points of boundary curve `e` (from corner `e` to corner `e + 1`,
    /// corners `(0, 0)`, `(1, 0)`, `(0, 1)`): a quartic Bézier curve in the edge's own
    /// parameter. Cost: 5 copies.
    pub fn edge_points(&self, e: usize) -> [DVec3; 5] {
        std::array::from_fn(|t| match e {
            0 => self.b(4 - t, t, 0),
            1 => self.b(0, 4 - t, t),
            _ => self.b(t, 0, 4 - t),
        })
    }

    /// The quartic Bézier form of OpenSubdiv's regular Loop patch with the 12 box-spline
    /// points `points` in OpenSubdiv's order (module docs) and no boundary: the same
    /// polynomial, so it evaluates as `EvalBasisBoxSplineTri`'s weights do, to rounding.
    /// Cost: 15 × 12 multiply-adds.
    pub fn from_box_spline(points: &[DVec3; 12]) -> QuarticTriangle {
        QuarticTriangle {
            points: BOX_SPLINE_TO_BEZIER_24.map(|row| {
                let sum = row.iter().zip(points).fold(DVec3::ZERO, |s, (&c, p)| s + *p * c as f64);
                sum / 24.0
            }),
        }
    }

    /// [`QuarticTriangle::from_box_spline`] for a Loop patch with OpenSubdiv's triangle
    /// boundary mask `boundary_mask` (`PatchParam::GetBoundary`, 5 bits): the surface
    /// OpenSubdiv evaluates for that mask, whose missing points are phantoms, each a
    /// reflection of real points (`far/patchBasis.cpp`, `adjustBoxSplineTriBoundaryWeights`).
    /// The phantoms' entries of `points` are ignored, whatever they hold.
    ///
    /// Every mask value below 32 is read as OpenSubdiv reads it. Far builds 18 of them:
    /// 0, edge masks 1–7, vertex masks 8 + (1–7) and edge-with-opposite-vertex masks
    /// 16 + (1, 2, 4); the others (upper bits 3, or upper bits 2 with several edges) are
    /// evaluated as `adjustBoxSplineTriBoundaryWeights` would.
    ///
    /// # Panics
    /// If `boundary_mask ≥ 32`.
    ///
    /// Cost: at most 15 reflections of points, then [`QuarticTriangle::from_box_spline`].
    pub fn from_box_spline_with_boundary(points: &[DVec3; 12], boundary_mask: u8) -> QuarticTriangle {
        assert!(boundary_mask < 32, "a triangle boundary mask has 5 bits, not {boundary_mask:#x}");
        let mut resolved = *points;
        // OpenSubdiv moves phantom weights onto real points in this order, and a later rule
        // may move weight an earlier one put on its phantom; for the points that means
        // substituting in the reverse order, so each phantom is expressed by points already
        // resolved.
        for rule in phantoms(boundary_mask).iter().rev() {
            resolved[rule.phantom] = resolved[rule.plus[0]] + resolved[rule.plus[1]] - resolved[rule.minus];
        }
        Self::from_box_spline(&resolved)
    }

    /// The cubic triangle `t` raised to degree 4 (the same surface):
    /// `b⁴_ijk = (i·b³_{i−1,j,k} + j·b³_{i,j−1,k} + k·b³_{i,j,k−1}) / 4`. Cost: 15 points.
    pub fn from_cubic(t: &BezierTriangle) -> QuarticTriangle {
        let mut points = [DVec3::ZERO; 15];
        for i in 0..=4usize {
            for j in 0..=4 - i {
                let k = 4 - i - j;
                let mut p = DVec3::ZERO;
                if i > 0 {
                    p += t.b(i - 1, j, k) * i as f64;
                }
                if j > 0 {
                    p += t.b(i, j - 1, k) * j as f64;
                }
                if k > 0 {
                    p += t.b(i, j, k - 1) * k as f64;
                }
                points[Self::index(i, j, k)] = p / 4.0;
            }
        }
        QuarticTriangle { points }
    }

    /// Position at `uv`. Cost: 15 control points.
    pub fn position(&self, uv: DVec2) -> DVec3 {
        let pw = powers(uv);
        let mut p = DVec3::ZERO;
        for i in 0..=4usize {
            for j in 0..=4 - i {
                let k = 4 - i - j;
                p += self.b(i, j, k) * bernstein(&pw, i, j, k);
            }
        }
        p
    }

    /// Position and first derivatives: `S_u = 4 Σ_{i+j+k=3} (b_{i,j+1,k} − b_{i+1,j,k}) B³_ijk`,
    /// and likewise for `v` with `k`. Cost: about two [`QuarticTriangle::position`].
    pub fn derivatives(&self, uv: DVec2) -> SurfaceDerivatives {
        let pw = powers(uv);
        let mut du = DVec3::ZERO;
        let mut dv = DVec3::ZERO;
        for i in 0..=3usize {
            for j in 0..=3 - i {
                let k = 3 - i - j;
                let c = 4.0 * bernstein(&pw, i, j, k);
                du += (self.b(i, j + 1, k) - self.b(i + 1, j, k)) * c;
                dv += (self.b(i, j, k + 1) - self.b(i + 1, j, k)) * c;
            }
        }
        SurfaceDerivatives { position: self.position(uv), du, dv }
    }

    /// Second derivatives `(S_uu, S_uv, S_vv)` at `uv`: `12 Σ_{i+j+k=2} Δ b · B²_ijk` with the
    /// second differences of [`QuarticTriangle::second_differences`]. Cost: 6 terms each.
    pub fn second_derivatives(&self, uv: DVec2) -> (DVec3, DVec3, DVec3) {
        let pw = powers(uv);
        let (mut uu, mut uv_, mut vv) = (DVec3::ZERO, DVec3::ZERO, DVec3::ZERO);
        for (n, [duu, duv, dvv]) in self.second_differences().into_iter().enumerate() {
            let (i, j, k) = Self::QUADRATIC_TERMS[n];
            let c = 12.0 * bernstein(&pw, i, j, k);
            uu += duu * c;
            uv_ += duv * c;
            vv += dvv * c;
        }
        (uu, uv_, vv)
    }

    /// Mixed second derivative `S_uv` at `uv`.
    pub fn mixed_derivative(&self, uv: DVec2) -> DVec3 {
        self.second_derivatives(uv).1
    }

    /// The second differences of the net in the parameter directions, one `[uu, uv, vv]` per
    /// quadratic term `(i, j, k)` of [`QuarticTriangle::QUADRATIC_TERMS`]:
    /// `b_{i,j+2,k} − 2b_{i+1,j+1,k} + b_{i+2,j,k}`,
    /// `b_{i,j+1,k+1} − b_{i+1,j,k+1} − b_{i+1,j+1,k} + b_{i+2,j,k}` and
    /// `b_{i,j,k+2} − 2b_{i+1,j,k+1} + b_{i+2,j,k}`: `12×` them are the Bézier points of the
    /// quadratic triangles `S_uu`, `S_uv`, `S_vv`.
    pub fn second_differences(&self) -> [[DVec3; 3]; 6] {
        Self::QUADRATIC_TERMS.map(|(i, j, k)| {
            let b = |di: usize, dj: usize, dk: usize| self.b(i + di, j + dj, k + dk);
            [
                b(0, 2, 0) - 2.0 * b(1, 1, 0) + b(2, 0, 0),
                b(0, 1, 1) - b(1, 0, 1) - b(1, 1, 0) + b(2, 0, 0),
                b(0, 0, 2) - 2.0 * b(1, 0, 1) + b(2, 0, 0),
            ]
        })
    }

    /// Position and unit normal `S_u × S_v` (limit normal at collapsed edges).
    pub fn eval(&self, uv: DVec2) -> SurfacePoint {
        triangle_point(self.derivatives(uv), uv, || self.mixed_derivative(uv), |q| self.derivatives(q))
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::test_support::Lcg;

    /// One evaluation of OpenSubdiv's basis from the fixture.
    pub(crate) struct BasisRecord {
        /// `None` for GREGORY_TRIANGLE, else LOOP with this boundary mask.
        pub loop_mask: Option<u8>,
        pub uv: DVec2,
        pub p: Vec<f64>,
        pub du: Vec<f64>,
        pub dv: Vec<f64>,
    }

    /// The weights `tools/osd-oracle/tri_basis_check.sh` printed from OpenSubdiv 3.6.0's
    /// `Far::internal::EvaluatePatchBasisNormalized<double>`.
    pub(crate) fn fixture() -> Vec<BasisRecord> {
        let text = include_str!("../../tests/fixtures/loop/tri_basis.txt");
        let mut lines = text.lines().filter(|l| !l.starts_with('#'));
        let mut out = Vec::new();
        let nums = |line: &str, tag: &str| -> Vec<f64> {
            let mut it = line.split_whitespace();
            assert_eq!(it.next(), Some(tag), "{line}");
            it.map(|t| t.parse::<f64>().unwrap()).collect()
        };
        while let Some(header) = lines.next() {
            let words: Vec<&str> = header.split_whitespace().collect();
            let (loop_mask, u, v) = match words[..] {
                ["loop", m, u, v] => (Some(m.parse().unwrap()), u, v),
                ["gregory", u, v] => (None, u, v),
                _ => panic!("unexpected fixture line {header:?}"),
            };
            let uv = DVec2::new(u.parse().unwrap(), v.parse().unwrap());
            let n = if loop_mask.is_some() { 12 } else { 18 };
            let [p, du, dv] = ["p", "du", "dv"].map(|tag| nums(lines.next().unwrap(), tag));
            assert!(p.len() == n && du.len() == n && dv.len() == n, "{header}");
            out.push(BasisRecord { loop_mask, uv, p, du, dv });
        }
        out
    }

    /// `n` seeded pseudo-random points in `[−1, 1]³` shifted by `offset`.
    pub(crate) fn random_points<const N: usize>(rng: &mut Lcg, offset: DVec3) -> [DVec3; N] {
        std::array::from_fn(|_| {
            DVec3::new(rng.unit53(), rng.unit53(), rng.unit53()) * 2.0 - DVec3::ONE + offset
        })
    }

    /// `swapped_uv` is the same surface with `u` and `v` exchanged; `edge_points(e)` are the
    /// control points of the boundary curve from corner `e` to corner `e + 1` (the curve they
    /// define is the surface there); and the quartic curve bound holds along each edge
    /// (second differences of the surface there, `|C''(t)|`, never above it).
    #[test]
    fn swapped_nets_and_edge_curves_are_the_surfaces() {
        let mut rng = Lcg(31);
        let corners = [DVec2::ZERO, DVec2::X, DVec2::Y];
        for _ in 0..200 {
            let q = QuarticTriangle { points: random_points::<15>(&mut rng, DVec3::ZERO) };
            let s = q.swapped_uv();
            for _ in 0..10 {
                let (u, v) = (rng.unit53(), rng.unit53());
                let uv = if u + v <= 1.0 { DVec2::new(u, v) } else { DVec2::new(1.0 - u, 1.0 - v) };
                assert!(s.position(uv).distance(q.position(DVec2::new(uv.y, uv.x))) < 1e-12);
            }
            assert_eq!(s.swapped_uv(), q);
            for e in 0..3 {
                let p = q.edge_points(e);
                let bound = crate::criterion::bounds::quartic_curve_second_derivative(p);
                let (a, b) = (corners[e], corners[(e + 1) % 3]);
                let at = |t: f64| q.position(a + (b - a) * t);
                for k in 0..=16 {
                    let t = k as f64 / 16.0;
                    // The curve of `p` in Bernstein form, against the surface on the edge.
                    let s = 1.0 - t;
                    let w = [
                        s * s * s * s,
                        4.0 * t * s * s * s,
                        6.0 * t * t * s * s,
                        4.0 * t * t * t * s,
                        t * t * t * t,
                    ];
                    let curve = (0..5).fold(DVec3::ZERO, |c, i| c + p[i] * w[i]);
                    assert!(curve.distance(at(t)) < 1e-12, "edge {e} at {t}");
                    let h = 1e-3;
                    if t > h && t < 1.0 - h {
                        let second = (at(t + h) - 2.0 * at(t) + at(t - h)) / (h * h);
                        assert!(
                            second.length() <= bound * (1.0 + 1e-6) + 1e-6,
                            "edge {e}: {second} > {bound}"
                        );
                    }
                }
            }
        }
    }

    /// `Σ wᵢ Pᵢ`: how OpenSubdiv evaluates a patch from its basis weights.
    pub(crate) fn weighted(w: &[f64], points: &[DVec3]) -> DVec3 {
        w.iter().zip(points).fold(DVec3::ZERO, |s, (w, p)| s + *p * *w)
    }

    /// Largest coordinate difference between tessera's evaluation and OpenSubdiv's weights.
    pub(crate) fn difference(ours: SurfaceDerivatives, r: &BasisRecord, points: &[DVec3]) -> f64 {
        [(ours.position, &r.p), (ours.du, &r.du), (ours.dv, &r.dv)]
            .iter()
            .map(|(a, w)| (*a - weighted(w, points)).abs().max_element())
            .fold(0.0, f64::max)
    }

    /// The Bézier form of the box spline, under every boundary mask, evaluates (position and
    /// both derivatives) as OpenSubdiv's LOOP basis weights do at every fixture point, for
    /// random nets whose phantom points are random too (so that ignoring them is tested).
    #[test]
    fn box_spline_conversion_matches_opensubdiv_under_every_mask() {
        let records = fixture();
        let mut rng = Lcg(0x10_0b);
        let mut masks = [0usize; 32];
        let mut worst = 0.0f64;
        for r in records.iter().filter(|r| r.loop_mask.is_some()) {
            let mask = r.loop_mask.unwrap();
            masks[mask as usize] += 1;
            for offset in [DVec3::ZERO, DVec3::new(3.0, -2.0, 5.0)] {
                let points: [DVec3; 12] = random_points(&mut rng, offset);
                let scale = points.iter().map(|p| p.abs().max_element()).fold(0.0, f64::max);
                let t = QuarticTriangle::from_box_spline_with_boundary(&points, mask);
                let d = difference(t.derivatives(r.uv), r, &points);
                assert!(d <= 1e-12 * scale, "mask {mask} at {}: differs by {d}", r.uv);
                assert!((t.position(r.uv) - t.derivatives(r.uv).position).abs().max_element() == 0.0);
                if mask == 0 {
                    assert_eq!(t, QuarticTriangle::from_box_spline(&points));
                }
                worst = worst.max(d / scale);
            }
        }
        assert!(masks.iter().all(|&n| n > 0), "a mask missing from the fixture: {masks:?}");
        assert_eq!(masks.iter().sum::<usize>(), 347);
        eprintln!("LOOP: worst relative difference {worst:e}");
    }

    /// Each mask makes phantoms of the points OpenSubdiv's boundary edges and vertices lose (edge 0: 0, 1, 2;
    /// edge 1: 6, 9, 11; edge 2: 10, 7, 3; vertex 0: 3, 0; vertex 1: 2, 6; vertex 2: 11, 10).
    #[test]
    fn boundary_masks_make_the_expected_phantoms() {
        let expect = |mask: u8, mut want: Vec<usize>| {
            let mut got: Vec<usize> = phantoms(mask).iter().map(|r| r.phantom).collect();
            got.sort_unstable();
            got.dedup();
            want.sort_unstable();
            assert_eq!(got, want, "mask {mask}");
        };
        expect(0, vec![]);
        expect(1, vec![0, 1, 2]);
        expect(2, vec![6, 9, 11]);
        expect(4, vec![10, 7, 3]);
        expect(7, vec![0, 1, 2, 3, 6, 7, 9, 10, 11]);
        expect(8 + 1, vec![3, 0]);
        expect(8 + 6, vec![2, 6, 11, 10]);
        expect(16 + 1, vec![0, 1, 2, 11, 10]);
        expect(16 + 2, vec![6, 9, 11, 3, 0]);
        expect(16 + 4, vec![10, 7, 3, 2, 6]);
    }

    /// A cubic triangle raised to degree 4 is the same surface: equal positions, first and
    /// mixed second derivatives.
    #[test]
    fn degree_elevation_keeps_the_surface() {
        let mut rng = Lcg(4);
        for _ in 0..20 {
            let cubic = BezierTriangle { points: random_points(&mut rng, DVec3::ZERO) };
            let quartic = QuarticTriangle::from_cubic(&cubic);
            for a in 0..=12 {
                for b in 0..=12 - a {
                    let uv = DVec2::new(a as f64, b as f64) / 12.0;
                    let (c, q) = (cubic.derivatives(uv), quartic.derivatives(uv));
                    for (x, y) in [(c.position, q.position), (c.du, q.du), (c.dv, q.dv)] {
                        assert!((x - y).length() < 1e-13, "{uv}: {x} against {y}");
                    }
                    let (x, y) = (cubic.mixed_derivative(uv), quartic.mixed_derivative(uv));
                    assert!((x - y).length() < 1e-12, "{uv}: {x} against {y}");
                }
            }
        }
    }

    /// The derivatives are those of the position (central differences, exact for the cubic
    /// part of a quartic up to `h²·S⁗/6`), and the second those of the first.
    #[test]
    fn derivatives_are_the_positions_derivatives() {
        let mut rng = Lcg(5);
        let h = 1e-4;
        for _ in 0..20 {
            let t = QuarticTriangle { points: random_points(&mut rng, DVec3::ZERO) };
            for _ in 0..20 {
                let uv = DVec2::new(rng.unit(), rng.unit()) * 0.5 + DVec2::splat(0.1);
                let (du, dv) = (DVec2::new(h, 0.0), DVec2::new(0.0, h));
                let d = t.derivatives(uv);
                let central = |f: &dyn Fn(DVec2) -> DVec3, e: DVec2| (f(uv + e) - f(uv - e)) / (2.0 * h);
                assert!((central(&|q| t.position(q), du) - d.du).length() < 1e-6);
                assert!((central(&|q| t.position(q), dv) - d.dv).length() < 1e-6);
                let (uu, uv_, vv) = t.second_derivatives(uv);
                assert!((central(&|q| t.derivatives(q).du, du) - uu).length() < 1e-6);
                assert!((central(&|q| t.derivatives(q).du, dv) - uv_).length() < 1e-6);
                assert!((central(&|q| t.derivatives(q).dv, du) - uv_).length() < 1e-6);
                assert!((central(&|q| t.derivatives(q).dv, dv) - vv).length() < 1e-6);
            }
        }
    }

    /// Corners interpolate the corner points, and the normal is the unit cross product.
    #[test]
    fn corners_and_normals() {
        let mut rng = Lcg(6);
        let t = QuarticTriangle { points: random_points(&mut rng, DVec3::ZERO) };
        assert_eq!(t.position(DVec2::ZERO), t.b(4, 0, 0));
        assert_eq!(t.position(DVec2::X), t.b(0, 4, 0));
        assert_eq!(t.position(DVec2::Y), t.b(0, 0, 4));
        let uv = DVec2::new(0.2, 0.3);
        let d = t.derivatives(uv);
        let n = t.eval(uv).normal;
        assert!((n - d.du.cross(d.dv).normalize()).length() < 1e-15);
    }
}
