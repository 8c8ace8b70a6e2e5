//! Gregory basis patches: OpenSubdiv's end caps of Catmull-Clark surfaces, evaluated as
//! `Far::internal::EvalBasisGregory` (`far/patchBasis.cpp`) does. Their 20 points come from
//! [`crate::subdivision::gregory`] (OpenSubdiv's `GregoryConverter`).
//!
//! # Point order
//!
//! The 20 points are grouped by corner: for corner `i` (counter-clockwise, at parameters
//! (0,0), (1,0), (1,1), (0,1)), points `5i..5i+5` are `P` (the Bézier corner), `Ep` (the edge
//! point towards corner `i+1`), `Em` (towards corner `i−1`), `Fp` and `Fm` (the face points
//! next to `Ep` and `Em`). With `u` along corner 0 → 1 and `v` along corner 0 → 3, the Bézier
//! net's bottom row is `P0, Ep0, Em1, P1` and its left column `P0, Em0, Ep3, P3`.

use glam::DVec3;

/// A Gregory basis patch: 20 points (per corner `P, Ep, Em, Fp, Fm`, see the module
/// documentation) evaluated as OpenSubdiv's `EvalBasisGregory` does.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GregoryPatch {
    /// The points, `5·corner + {0: P, 1: Ep, 2: Em, 3: Fp, 4: Fm}`.
    pub points: [DVec3; 20],
}

impl GregoryPatch {
    /// The bicubic Bézier net at `(u, v)` (rows along `v`, columns along `u`): the boundary
    /// points fixed, each interior point its corner's face-point pair blended rationally
    /// (weight 1 on `Fm` where the blend is undefined, at the corner itself).
    pub(crate) fn bezier_net(&self, u: f64, v: f64) -> [[DVec3; 4]; 4] {
        let g = &self.points;
        let (uc, vc) = (1.0 - u, 1.0 - v);
        let inv = |d: f64| if d <= 0.0 { 1.0 } else { 1.0 / d };
        let blend = |w: f64, plus: usize| g[plus] * w + g[plus + 1] * (1.0 - w);
        let f0 = blend(u * inv(u + v), 3);
        let f1 = blend(v * inv(uc + v), 8);
        let f2 = blend(uc * inv(uc + vc), 13);
        let f3 = blend(vc * inv(u + vc), 18);
        self.net_with([f0, f1, f2, f3])
    }

    /// The Bézier net with each interior point its corner's `Fm` (every blend's weight on
    /// `Fp` zero), as `points[4*i + j]`, `i` along `u` (a `RationalBicubic`'s order): the
    /// patch at `(u, v)` is this net plus, at each corner's interior point, the blend's
    /// weight times `Fp − Fm`, which the second-derivative bound
    /// (`criterion::bounds::gregory_hessian`) and the f32 kernel read.
    pub(crate) fn minus_net(&self) -> [DVec3; 16] {
        let net = self.net_with(std::array::from_fn(|c| self.points[5 * c + 4]));
        std::array::from_fn(|k| net[k % 4][k / 4])
    }

    /// The net (rows along `v`, columns along `u`) with interior points `f`, corner by corner.
    fn net_with(&self, [f0, f1, f2, f3]: [DVec3; 4]) -> [[DVec3; 4]; 4] {
        let g = &self.points;
        [[g[0], g[1], g[7], g[5]], [g[2], f0, f1, g[6]], [g[16], f3, f2, g[12]], [g[15], g[17], g[11], g[10]]]
    }

    /// The surface point at `(u, v)` ∈ `[0,1]²`, `u` along corner 0 → 1 and `v` along
    /// corner 0 → 3. Cost: a 4×4 Bézier evaluation.
    pub fn position(&self, u: f64, v: f64) -> DVec3 {
        let net = self.bezier_net(u, v);
        let (bu, bv) = (bernstein(u).0, bernstein(v).0);
        tensor(&net, &bu, &bv)
    }

    /// Position and first partial derivatives `(P, ∂P/∂u, ∂P/∂v)` at `(u, v)`. The
    /// derivatives are OpenSubdiv's default approximation: those of the Bézier patch whose
    /// interior points are the blends at `(u, v)`, without differentiating the blend
    /// (`OPENSUBDIV_GREGORY_EVAL_TRUE_DERIVATIVES` off). They are exact where the face-point
    /// pairs coincide, and give the same normals' directions along the patch boundary.
    pub fn derivatives(&self, u: f64, v: f64) -> (DVec3, DVec3, DVec3) {
        let net = self.bezier_net(u, v);
        let (bu, du) = bernstein(u);
        let (bv, dv) = bernstein(v);
        (tensor(&net, &bu, &bv), tensor(&net, &du, &bv), tensor(&net, &bu, &dv))
    }
}

/// Cubic Bernstein polynomials at `t` and their derivatives.
fn bernstein(t: f64) -> ([f64; 4], [f64; 4]) {
    let tc = 1.0 - t;
    let (t2, tc2) = (t * t, tc * tc);
    let b = [tc2 * tc, 3.0 * tc2 * t, 3.0 * t2 * tc, t2 * t];
    let d = [-3.0 * tc2, 9.0 * t2 - 12.0 * t + 3.0, -9.0 * t2 + 6.0 * t, 3.0 * t2];
    (b, d)
}

/// `Σ wu[col]·wv[row]·net[row][col]`.
fn tensor(net: &[[DVec3; 4]; 4], wu: &[f64; 4], wv: &[f64; 4]) -> DVec3 {
    let mut sum = DVec3::ZERO;
    for (row, &wr) in net.iter().zip(wv) {
        for (&p, &wc) in row.iter().zip(wu) {
            sum += p * (wc * wr);
        }
    }
    sum
}
