//! Cubic Bézier triangles.

use super::{triangle_point, SurfaceDerivatives, SurfacePoint};
use glam::{DVec2, DVec3};

/// A cubic Bézier triangle `S(λ) = Σ_{i+j+k=3} 3!/(i!j!k!) λ0^i λ1^j λ2^k b_ijk` with
/// `λ = (1-u-v, u, v)`.
///
/// `points` are stored in the order of [`BezierTriangle::index`]:
/// `b300, b210, b201, b120, b111, b102, b030, b021, b012, b003`.
#[derive(Debug, Clone, PartialEq)]
pub struct BezierTriangle {
    pub points: [DVec3; 10],
}

/// `[1, λ, λ², λ³]` for each barycentric coordinate `λ = (1-u-v, u, v)`: the powers the
/// Bernstein terms read, computed once per point. Same bits as `powi` (`λ³` is `λ·λ²`), which
/// for a run-time exponent is a library call per term.
#[inline]
fn powers(uv: DVec2) -> [[f64; 4]; 3] {
    [1.0 - uv.x - uv.y, uv.x, uv.y].map(|x| {
        let x2 = x * x;
        [1.0, x, x2, x * x2]
    })
}

impl BezierTriangle {
    /// Storage index of `b_ijk` (`i + j + k = 3`; `i` is the exponent of `λ0 = 1-u-v`).
    #[inline]
    pub const fn index(i: usize, j: usize, _k: usize) -> usize {
        (3 - i) * (4 - i) / 2 + (3 - i - j)
    }

    /// Control point `b_ijk`.
    #[inline]
    pub fn b(&self, i: usize, j: usize, k: usize) -> DVec3 {
        self.points[Self::index(i, j, k)]
    }

    /// Position at `uv`. Cost: 10 control points.
    pub fn position(&self, uv: DVec2) -> DVec3 {
        let pw = powers(uv);
        let mut p = DVec3::ZERO;
        for i in 0..=3usize {
            for j in 0..=3 - i {
                let k = 3 - i - j;
                let c = multinomial3(i, j, k);
                p += self.b(i, j, k) * (c * pw[0][i] * pw[1][j] * pw[2][k]);
            }
        }
        p
    }

    /// Position and first derivatives: `S_u = 3 Σ (b_{i,j+1,k} − b_{i+1,j,k}) B²_ijk`, and
    /// likewise for `v` with `k`.
    pub fn derivatives(&self, uv: DVec2) -> SurfaceDerivatives {
        let pw = powers(uv);
        let mut du = DVec3::ZERO;
        let mut dv = DVec3::ZERO;
        for i in 0..=2usize {
            for j in 0..=2 - i {
                let k = 2 - i - j;
                let c = 3.0 * multinomial2(i, j, k) * pw[0][i] * pw[1][j] * pw[2][k];
                du += (self.b(i, j + 1, k) - self.b(i + 1, j, k)) * c;
                dv += (self.b(i, j, k + 1) - self.b(i + 1, j, k)) * c;
            }
        }
        SurfaceDerivatives { position: self.position(uv), du, dv }
    }

    /// Mixed second derivative `S_uv`.
    pub fn mixed_derivative(&self, uv: DVec2) -> DVec3 {
        let pw = powers(uv);
        let mut d = DVec3::ZERO;
        for (i, j, k) in [(1, 0, 0), (0, 1, 0), (0, 0, 1)] {
            let second = self.b(i, j + 1, k + 1) - self.b(i + 1, j, k + 1) - self.b(i + 1, j + 1, k)
                + self.b(i + 2, j, k);
            d += second * (6.0 * pw[0][i] * pw[1][j] * pw[2][k]);
        }
        d
    }

    /// Position and unit normal `S_u × S_v` (limit normal at collapsed edges).
    pub fn eval(&self, uv: DVec2) -> SurfacePoint {
        triangle_point(self.derivatives(uv), uv, || self.mixed_derivative(uv), |q| self.derivatives(q))
    }

    /// The same surface with `u` and `v` exchanged (`b_ijk → b_ikj`): opposite orientation,
    /// corners 1 and 2 swapped.
    pub fn swapped_uv(&self) -> Self {
        let mut out = self.clone();
        for i in 0..=3usize {
            for j in 0..=3 - i {
                let k = 3 - i - j;
                out.points[Self::index(i, k, j)] = self.b(i, j, k);
            }
        }
        out
    }
}

#[inline]
fn factorial(n: usize) -> f64 {
    [1.0, 1.0, 2.0, 6.0][n]
}

#[inline]
fn multinomial3(i: usize, j: usize, k: usize) -> f64 {
    6.0 / (factorial(i) * factorial(j) * factorial(k))
}

#[inline]
fn multinomial2(i: usize, j: usize, k: usize) -> f64 {
    2.0 / (factorial(i) * factorial(j) * factorial(k))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The power table gives the bits `powi` gives, so evaluation did not change with it.
    #[test]
    fn power_table_evaluation_equals_powi() {
        let t = BezierTriangle {
            points: std::array::from_fn(|k| {
                DVec3::new(k as f64 * 0.37, (k * k) as f64 * 0.11 - 1.0, 1.0 / (k + 1) as f64)
            }),
        };
        for a in 0..=40 {
            for b in 0..=40 - a {
                let uv = DVec2::new(a as f64 / 40.0 + 1e-3 * (b % 3) as f64, b as f64 / 40.0);
                let l = [1.0 - uv.x - uv.y, uv.x, uv.y];
                let mut p = DVec3::ZERO;
                for i in 0..=3usize {
                    for j in 0..=3 - i {
                        let k = 3 - i - j;
                        let c = multinomial3(i, j, k);
                        p += t.b(i, j, k)
                            * (c * l[0].powi(i as i32) * l[1].powi(j as i32) * l[2].powi(k as i32));
                    }
                }
                assert_eq!(t.position(uv), p, "{uv}");
            }
        }
    }
}
