//! Bicubic rational Bézier tensor-product patches.

use super::{robust_normal, SurfaceDerivatives, SurfacePoint};
use glam::{DVec2, DVec3};

/// A bicubic rational Bézier patch `S(u,v) = Σ w_ij P_ij B_i(u) B_j(v) / Σ w_ij B_i(u) B_j(v)`.
///
/// `points[4*i + j]` is `P_ij`: `i` runs along `u`, `j` along `v` (the order of the Newell
/// patch format). All weights must be finite and positive; with all weights 1 the patch is
/// polynomial and evaluation skips the division.
#[derive(Debug, Clone, PartialEq)]
pub struct RationalBicubic {
    pub points: [DVec3; 16],
    pub weights: [f64; 16],
}

/// Cubic Bernstein polynomials and their first two derivatives at `t`.
#[inline]
pub(crate) fn bernstein3(t: f64) -> ([f64; 4], [f64; 4], [f64; 4]) {
    let s = 1.0 - t;
    let b = [s * s * s, 3.0 * t * s * s, 3.0 * t * t * s, t * t * t];
    let d = [-3.0 * s * s, 3.0 * s * (s - 2.0 * t), 3.0 * t * (2.0 * s - t), 3.0 * t * t];
    let dd = [6.0 * s, 6.0 * (3.0 * t - 2.0), 6.0 * (1.0 - 3.0 * t), 6.0 * t];
    (b, d, dd)
}

/// Homogeneous sums needed for position, first derivatives and the mixed derivative.
struct Sums {
    h: DVec3,
    hu: DVec3,
    hv: DVec3,
    huv: DVec3,
    w: f64,
    wu: f64,
    wv: f64,
    wuv: f64,
}

impl RationalBicubic {
    /// A polynomial patch (all weights 1).
    pub fn polynomial(points: [DVec3; 16]) -> Self {
        RationalBicubic { points, weights: [1.0; 16] }
    }

    /// True when every weight is 1.
    pub fn is_polynomial(&self) -> bool {
        self.weights.iter().all(|&w| w == 1.0)
    }

    // Index loops mirror the double sum of the formula.
    #[allow(clippy::needless_range_loop)]
    fn sums(&self, uv: DVec2) -> Sums {
        let (bu, du, _) = bernstein3(uv.x);
        let (bv, dv, _) = bernstein3(uv.y);
        let mut s = Sums {
            h: DVec3::ZERO,
            hu: DVec3::ZERO,
            hv: DVec3::ZERO,
            huv: DVec3::ZERO,
            w: 0.0,
            wu: 0.0,
            wv: 0.0,
            wuv: 0.0,
        };
        for i in 0..4 {
            for j in 0..4 {
                let w = self.weights[4 * i + j];
                let p = self.points[4 * i + j] * w;
                let (a, b, c, d) = (bu[i] * bv[j], du[i] * bv[j], bu[i] * dv[j], du[i] * dv[j]);
                s.h += p * a;
                s.hu += p * b;
                s.hv += p * c;
                s.huv += p * d;
                s.w += w * a;
                s.wu += w * b;
                s.wv += w * c;
                s.wuv += w * d;
            }
        }
        s
    }

    /// Position at `uv`. Cost: 16 weighted control points.
    #[allow(clippy::needless_range_loop)]
    pub fn position(&self, uv: DVec2) -> DVec3 {
        let (bu, _, _) = bernstein3(uv.x);
        let (bv, _, _) = bernstein3(uv.y);
        let mut h = DVec3::ZERO;
        let mut w = 0.0;
        for i in 0..4 {
            for j in 0..4 {
                let k = 4 * i + j;
                let b = bu[i] * bv[j] * self.weights[k];
                h += self.points[k] * b;
                w += b;
            }
        }
        h / w
    }

    /// Position and first derivatives (quotient rule on the homogeneous form).
    pub fn derivatives(&self, uv: DVec2) -> SurfaceDerivatives {
        let s = self.sums(uv);
        let p = s.h / s.w;
        SurfaceDerivatives { position: p, du: (s.hu - p * s.wu) / s.w, dv: (s.hv - p * s.wv) / s.w }
    }

    /// Position and unit normal; the limit normal where a boundary curve collapsed to a point.
    pub fn eval(&self, uv: DVec2) -> SurfacePoint {
        let s = self.sums(uv);
        let p = s.h / s.w;
        let su = (s.hu - p * s.wu) / s.w;
        let sv = (s.hv - p * s.wv) / s.w;
        // S_uv from differentiating H = S·w twice: H_uv = S_uv w + S_u w_v + S_v w_u + S w_uv.
        let suv = || (s.huv - su * s.wv - sv * s.wu - p * s.wuv) / s.w;
        let inside = DVec2::new(0.5 - uv.x, 0.5 - uv.y);
        let normal = robust_normal(su, sv, uv, inside, suv, |q| {
            let d = self.derivatives(q);
            d.du.cross(d.dv)
        });
        SurfacePoint { position: p, normal }
    }

    /// The patch with `u` and `v` exchanged: the same surface with the opposite orientation.
    pub fn transposed(&self) -> Self {
        let mut out = self.clone();
        for i in 0..4 {
            for j in 0..4 {
                out.points[4 * j + i] = self.points[4 * i + j];
                out.weights[4 * j + i] = self.weights[4 * i + j];
            }
        }
        out
    }

    /// Control point `P_ij`.
    pub fn point(&self, i: usize, j: usize) -> DVec3 {
        self.points[4 * i + j]
    }
}
