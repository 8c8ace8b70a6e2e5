//! A specialisation of *evaluation*: bicubic patches, polynomial or rational, on a uniform
//! grid, evaluated row by row in f32 with tabulated Bernstein bases, vectorized.
//!
//! The engine ([`super::write`]) decides every vertex and triangle with the one numbering rule
//! of [`super::layout`]; this module only computes positions and normals, faster, for the
//! vertices where it applies: every corner entry, the inner samples of edges cut into the
//! plan's factor `n`, and the interior of patches whose pattern promises a uniform `n × n` grid
//! ([`crate::pattern::Pattern::interior_grid`]). Parameters (`uvs`) and patch ids are the
//! generic evaluation's own f64 formulas rounded the same way, so only positions and normals
//! differ, by rounding.
//!
//! **Watertight by construction, as in the generic path.** Each corner and each edge sample is
//! evaluated once, by its owner patch, and every patch on it refers to it by index; no
//! position is ever computed twice, so neighbours meet bit for bit.
//!
//! **Positions and normals.** The Bernstein basis of the `n + 1` parameters `i / n` is the
//! same for every patch, so it is tabulated once. A patch is moved to a local frame (its
//! control points minus their bounding box centre, divided by a power of two) and rounded to
//! f32 there: f32 then carries the patch's own detail at full relative precision, whatever the
//! model's size or offset, and the final `origin + scale · local` only adds rounding at the
//! output's own magnitude. A row (or, for edges along `v`, a column) is reduced to a cubic
//! curve and its cross derivative once; its points are then evaluated [`LANES`] at a time in
//! structure-of-arrays form, which the compiler vectorizes. Where the derivatives are nearly
//! parallel (a pole, or a pinched corner), f32 would lose the normal's direction, so such
//! points take the generic f64 evaluation instead (`point_blocks::cross_normals`, one rule for
//! both evaluators).
//!
//! **Rational patches** carry their weight as a fourth component of the same sums (a row is
//! then a rational cubic in homogeneous form), and the quotient follows
//! (`point_blocks::rational_quotient`, shared with the point evaluator). The sums are written
//! once for both forms (generic over the component count), but a polynomial patch keeps its
//! three-component kernel: running it through the rational one (weights 1) measured 1.2–1.35×
//! slower (torus, factor 16, 1 thread: median 6.2 ms against 4.65 ms, and 5.07 ms before the
//! rational kernels existed, interleaved runs of `tessera mesh --stats --repeat 31`).
//!
//! **Kernels.** The evaluation kernels are written once, generic over whether multiply-adds
//! are fused, and compiled twice: for the baseline target (SSE2 on x86-64) and, on x86-64 CPUs
//! that have them, for AVX2 and FMA, chosen at run time. Calling the AVX2 build is the
//! module's only `unsafe`.

use super::point_blocks::{
    cross_normals, local_frame, madd, rational_quotient, to_model, LANES, MIN_DERIVATIVE2, MIN_SIN2,
};
use crate::sampling::uniform_param;
use crate::surface::{RationalBicubic, SurfacePoint};
use glam::DVec3;

/// Cubic Bernstein polynomials and their derivatives at `t`, in f64 (rounded once to f32 by
/// the caller).
fn bernstein3(t: f64) -> ([f64; 4], [f64; 4]) {
    let s = 1.0 - t;
    let b = [s * s * s, 3.0 * t * s * s, 3.0 * t * t * s, t * t * t];
    let d = [-3.0 * s * s, 3.0 * s * (s - 2.0 * t), 3.0 * t * (2.0 * s - t), 3.0 * t * t];
    (b, d)
}

/// `B_k(i / n)` and `B_k'(i / n)` for `i = 0..=n`, padded by [`LANES`] copies of the values at
/// `n`, so that a block of lanes may start at any `i ≤ n` and its spare lanes hold a real point
/// (whose result is ignored, but which does not spoil [`Block::all_ok`]).
#[derive(Default)]
pub(super) struct Basis {
    b: [Vec<f32>; 4],
    d: [Vec<f32>; 4],
    /// `at[i] = ([B_k(i / n)], [B_k'(i / n)])`, for setting up lines.
    at: Vec<([f32; 4], [f32; 4])>,
}

impl Basis {
    /// Refills the tables for factor `n`, reusing their allocations.
    pub(super) fn refill(&mut self, n: usize) {
        let len = n + 1 + LANES;
        for v in self.b.iter_mut().chain(self.d.iter_mut()) {
            v.clear();
            v.resize(len, 0.0);
        }
        for i in 0..len {
            // The edge sampling's parameters: exactly 1 at the end.
            let (b, d) = bernstein3(uniform_param(n as u32, i.min(n) as u32));
            for k in 0..4 {
                self.b[k][i] = b[k] as f32;
                self.d[k][i] = d[k] as f32;
            }
        }
        self.at.clear();
        let (b, d) = (&self.b, &self.d);
        self.at.extend((0..=n).map(|i| (b.each_ref().map(|b| b[i]), d.each_ref().map(|d| d[i]))));
    }
}

/// One patch in a local frame ([`local_frame`]): `P = origin + scale · p`, with `p` within
/// `[-1, 1]³`. `C = 3` for a polynomial patch; `C = 4` for a rational one, in homogeneous form
/// (see [`LocalPatch::rational`]).
pub(crate) struct LocalPatch<const C: usize = 3> {
    pub(crate) origin: [f32; 3],
    pub(crate) scale: f32,
    /// `by_v[c][j][i]`: component `c` of `p_ij` (`i` along `u`, `j` along `v`), so that a
    /// row's curve, a sum over `j`, is a sum of 4-vectors over `i`. Rational: components 0 to
    /// 2 of `w_ij p_ij`, component 3 the weight `w_ij`.
    pub(crate) by_v: [[[f32; 4]; 4]; C],
}

/// Below this ratio of a rational patch's smallest weight to its largest, the patch keeps the
/// generic f64 evaluation. Not for the rounding of the rational kernels, which stays that of
/// the polynomial ones whatever the weights (see `point_blocks::rational_quotient`), but
/// because extreme weights crowd the parametrisation: more points get nearly parallel
/// derivatives, where the f32 cross product errs by up to about 1e-5 ([`MIN_SIN2`]). On
/// random wavy nets (128,000 points each), the worst normal error of the points the kernel
/// kept was 6.8e-7 with weights spanning 16×, 1.9e-6 at 256×, 1.0e-5 at 4,096× and 2.9e-5 at
/// 2^18×. Rational patches in practice (conics, spheres, CAD surfaces) span far less.
pub(crate) const MIN_WEIGHT_RATIO: f64 = 1.0 / 256.0;

impl LocalPatch {
    /// The polynomial bicubic `patch` (weights ignored) in its local frame.
    pub(crate) fn new(patch: &RationalBicubic) -> LocalPatch {
        LocalPatch::with_weights(&patch.points, |_| 1.0)
    }

    /// The polynomial Bézier net `points` (`points[4*i + j]`, `i` along `u`, as a
    /// [`RationalBicubic`]'s) in its local frame.
    #[inline(always)]
    pub(crate) fn from_net(points: &[DVec3; 16]) -> LocalPatch {
        LocalPatch::with_weights(points, |_| 1.0)
    }
}

impl LocalPatch<4> {
    /// The rational bicubic `patch` in its local frame and homogeneous form `(w p, w)`, the
    /// weights divided by the largest (which changes no point of the surface), so that every
    /// sum's rounding is relative to 1; None where the smallest weight is below
    /// [`MIN_WEIGHT_RATIO`] of the largest.
    pub(crate) fn rational(patch: &RationalBicubic) -> Option<LocalPatch<4>> {
        let (lo, hi) =
            patch.weights.iter().fold((f64::INFINITY, 0f64), |(lo, hi), &w| (lo.min(w), hi.max(w)));
        (lo >= hi * MIN_WEIGHT_RATIO)
            .then(|| LocalPatch::with_weights(&patch.points, |k| patch.weights[k] / hi))
    }
}

impl<const C: usize> LocalPatch<C> {
    /// `patch` in its local frame; where `C = 4`, homogeneous with the weights `weight(k)` of
    /// its control points `k`.
    #[inline(always)]
    fn with_weights(points: &[DVec3; 16], weight: impl Fn(usize) -> f64) -> LocalPatch<C> {
        LocalPatch::in_frame(points, local_frame(points), weight)
    }

    /// [`LocalPatch::with_weights`] in the frame `(origin, scale)` ([`local_frame`] of the
    /// net, or of points around it).
    #[inline(always)]
    pub(crate) fn in_frame(
        points: &[DVec3; 16],
        (origin, scale): (DVec3, f64),
        weight: impl Fn(usize) -> f64,
    ) -> LocalPatch<C> {
        // Exact: a power of two.
        let inv = 1.0 / scale;
        let mut local =
            LocalPatch { origin: origin.as_vec3().to_array(), scale: scale as f32, by_v: [[[0.0; 4]; 4]; C] };
        for (k, &q) in points.iter().enumerate() {
            let (i, j) = (k / 4, k % 4);
            let w = if C == 4 { weight(k) } else { 1.0 };
            let q = ((q - origin) * (inv * w)).as_vec3().to_array();
            for (c, &x) in q.iter().enumerate() {
                local.by_v[c][j][i] = x;
            }
            if C == 4 {
                local.by_v[C - 1][j][i] = w as f32;
            }
        }
        local
    }

    /// The curve `v = j / n`: its control points `c_i = Σ_j p_ij B_j(v)` and the cross
    /// derivative's `d_i = Σ_j p_ij B_j'(v)`.
    #[inline(always)]
    pub(super) fn row(&self, basis: &Basis, j: usize) -> Line<C> {
        Line::new(&self.by_v, basis, j, false)
    }

    /// The curve `u = i / n`, likewise (along `v`, cross derivative `∂/∂u`).
    #[cfg(test)]
    // Index loops mirror `Line::new`'s sums.
    #[allow(clippy::needless_range_loop)]
    pub(super) fn column(&self, basis: &Basis, i: usize) -> Line<C> {
        // `Line::new` of the transposed net, each sum in the same order (so the same bits),
        // as a dot product of a row of `by_v` instead of a transposed copy first: a coarse
        // frame's edges are half columns, and the transposition went through the stack (the
        // Catmull-Clark torus at 0.5 px: the vertex stage 15.5 → 14.2 ms, one thread; the
        // k-outer loop of `Line::new` over the strided net measured 1.5 % slower on uniform
        // factor 16).
        let mut line = Line { c: [[0.0; 4]; C], d: [[0.0; 4]; C], column: true };
        let (b, d) = &basis.at[i];
        for c in 0..C {
            for t in 0..4 {
                let q = &self.by_v[c][t];
                for k in 0..4 {
                    line.c[c][t] += q[k] * b[k];
                    line.d[c][t] += q[k] * d[k];
                }
            }
        }
        line
    }
}

/// A grid line of a patch as a cubic Bézier curve in the local frame (homogeneous where
/// `C = 4`), with the control points of its cross derivative.
pub(super) struct Line<const C: usize> {
    /// `c[component][k]`.
    c: [[f32; 4]; C],
    d: [[f32; 4]; C],
    /// True for a line of constant `u`: the derivative along it is `∂/∂v`.
    column: bool,
}

/// [`LANES`] consecutive points of a line, in structure-of-arrays form.
pub(super) struct Block {
    pos: [[f32; LANES]; 3],
    nrm: [[f32; LANES]; 3],
    /// Positive where the f32 normal is reliable; elsewhere (zero, negative or NaN) the point
    /// must be evaluated in f64.
    margin: [f32; LANES],
}

impl Block {
    #[inline(always)]
    fn ok(&self, l: usize) -> bool {
        self.margin[l] > 0.0
    }

    /// The block with its lanes in reverse order.
    #[inline(always)]
    pub(super) fn reversed(&self) -> Block {
        let flip = |mut lanes: [f32; LANES]| {
            lanes.reverse();
            lanes
        };
        Block { pos: self.pos.map(flip), nrm: self.nrm.map(flip), margin: flip(self.margin) }
    }

    /// Every lane is reliable (branch-free, so that it vectorizes).
    #[inline(always)]
    fn all_ok(&self) -> bool {
        self.margin.iter().fold(true, |all, &m| all & (m > 0.0))
    }

    /// Writes lanes `0..pos.len()`, taking `exact(l)` where a lane is unreliable. `AVX`: the
    /// caller is compiled for AVX (the kernels' fast build), so a whole block may be stored
    /// by [`store_points`].
    #[inline(always)]
    pub(super) fn write<const AVX: bool>(
        &self,
        pos: &mut [[f32; 3]],
        nrm: &mut [[f32; 3]],
        exact: impl Fn(usize) -> SurfacePoint,
    ) {
        let count = pos.len();
        self.write_front::<AVX>(pos, nrm, count, exact)
    }

    /// Writes lanes `0..count` to the front of `pos` and `nrm`, taking `exact(l)` where a
    /// lane is unreliable. Where every lane is reliable and the slices hold [`LANES`] points,
    /// the whole block is stored ([`store_points`], `AVX` only): the points past `count` then
    /// hold the spare lanes' values, which the caller must overwrite (a grid row's next
    /// row does).
    #[inline(always)]
    pub(super) fn write_front<const AVX: bool>(
        &self,
        pos: &mut [[f32; 3]],
        nrm: &mut [[f32; 3]],
        count: usize,
        exact: impl Fn(usize) -> SurfacePoint,
    ) {
        let all_ok = self.all_ok();
        #[cfg(target_arch = "x86_64")]
        if AVX && all_ok {
            if let (Some((pos, _)), Some((nrm, _))) =
                (pos.split_first_chunk_mut::<LANES>(), nrm.split_first_chunk_mut::<LANES>())
            {
                // SAFETY: `AVX` is only set in code compiled for AVX2 and FMA, which only
                // runs where the CPU has them (`cpu::has_avx2_fma`).
                unsafe {
                    store_points(&self.pos, pos.as_flattened_mut().try_into().expect("LANES points"));
                    store_points(&self.nrm, nrm.as_flattened_mut().try_into().expect("LANES points"));
                }
                return;
            }
        }
        let (pos, nrm) = (&mut pos[..count], &mut nrm[..count]);
        if all_ok {
            for (l, (pos, nrm)) in pos.iter_mut().zip(nrm).enumerate() {
                *pos = [self.pos[0][l], self.pos[1][l], self.pos[2][l]];
                *nrm = [self.nrm[0][l], self.nrm[1][l], self.nrm[2][l]];
            }
        } else {
            for (l, (pos, nrm)) in pos.iter_mut().zip(nrm).enumerate() {
                store(self, l, pos, nrm, || exact(l));
            }
        }
    }
}

/// Stores a whole block's component lanes (`c[component][lane]`) as its eight points
/// `x₀ y₀ z₀ x₁ …`, interleaved in registers: six unpacks, three shuffles and three lane
/// swaps, then three vector stores. Lane by lane a block's points were 24 single stores,
/// most of them lane extracts, and a uniform frame's grid rows are nearly all whole blocks;
/// the compiler's own interleaving of the same array (`array::from_fn`) went through single
/// inserts and made the vertex stage slower.
///
/// # Safety
/// The CPU must support AVX.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
#[inline]
unsafe fn store_points(c: &[[f32; LANES]; 3], out: &mut [f32; 3 * LANES]) {
    use std::arch::x86_64::*;
    const _: () = assert!(LANES == 8, "one AVX register of f32 lanes");
    let (x, y, z) =
        (_mm256_loadu_ps(c[0].as_ptr()), _mm256_loadu_ps(c[1].as_ptr()), _mm256_loadu_ps(c[2].as_ptr()));
    // Within each 128-bit half (points 0–3, and 4–7 alike): x0 y0 x1 y1, x2 y2 x3 y3, …
    let (xy_lo, xy_hi) = (_mm256_unpacklo_ps(x, y), _mm256_unpackhi_ps(x, y));
    let (yz_lo, yz_hi) = (_mm256_unpacklo_ps(y, z), _mm256_unpackhi_ps(y, z));
    let (zx_lo, zx_hi) = (_mm256_unpacklo_ps(z, x), _mm256_unpackhi_ps(z, x));
    // The half's twelve values: x0 y0 z0 x1 | y1 z1 x2 y2 | z2 x3 y3 z3.
    let a = _mm256_shuffle_ps::<0b11_00_01_00>(xy_lo, zx_lo);
    let b = _mm256_shuffle_ps::<0b01_00_11_10>(yz_lo, xy_hi);
    let d = _mm256_shuffle_ps::<0b11_10_11_00>(zx_hi, yz_hi);
    // Points 0–3 (the low halves) before points 4–7 (the high ones).
    let out = out.as_mut_ptr();
    _mm256_storeu_ps(out, _mm256_permute2f128_ps::<0x20>(a, b));
    _mm256_storeu_ps(out.add(8), _mm256_permute2f128_ps::<0x30>(d, a));
    _mm256_storeu_ps(out.add(16), _mm256_permute2f128_ps::<0x31>(b, d));
}

impl<const C: usize> Line<C> {
    /// The line at grid index `s` across `q`'s first axis (see [`LocalPatch`]).
    // Index loops mirror the sum `Σ_k q_kt B_k` (and vectorize over `t`).
    #[allow(clippy::needless_range_loop)]
    #[inline(always)]
    fn new(q: &[[[f32; 4]; 4]; C], basis: &Basis, s: usize, column: bool) -> Line<C> {
        let mut line = Line { c: [[0.0; 4]; C], d: [[0.0; 4]; C], column };
        let (b, d) = &basis.at[s];
        for c in 0..C {
            for k in 0..4 {
                let (b, d) = (b[k], d[k]);
                for t in 0..4 {
                    line.c[c][t] += q[c][k][t] * b;
                    line.d[c][t] += q[c][k][t] * d;
                }
            }
        }
        line
    }

    /// Points `t0 .. t0 + LANES` of the grid along the line (past `n`, copies of point `n`),
    /// each component's value and its derivatives along and across the line.
    #[inline(always)]
    fn sums<const FMA: bool>(&self, basis: &Basis, t0: usize) -> [[[f32; LANES]; C]; 3] {
        let mut pos = [[0f32; LANES]; C];
        let mut along = [[0f32; LANES]; C];
        let mut across = [[0f32; LANES]; C];
        for k in 0..4 {
            let b: &[f32; LANES] = basis.b[k][t0..t0 + LANES].try_into().unwrap();
            let d: &[f32; LANES] = basis.d[k][t0..t0 + LANES].try_into().unwrap();
            for c in 0..C {
                let (ck, dk) = (self.c[c][k], self.d[c][k]);
                for l in 0..LANES {
                    pos[c][l] = madd::<FMA>(b[l], ck, pos[c][l]);
                    along[c][l] = madd::<FMA>(d[l], ck, along[c][l]);
                    across[c][l] = madd::<FMA>(b[l], dk, across[c][l]);
                }
            }
        }
        [pos, along, across]
    }
}

/// The grid kernel of one form of patch: polynomial (`Line<3>`) or rational (`Line<4>`).
pub(super) trait GridLine {
    /// Each lane's sums: component values and derivatives along and across its line.
    type Sums;
    /// Points `t0 .. t0 + LANES` of the grid along the line (past `n`, copies of point `n`),
    /// in the model's frame.
    fn block<const FMA: bool>(&self, basis: &Basis, t0: usize, origin: &[f32; 3], scale: f32) -> Block;
    /// The points of lanes whose sums are `sums`, on rows (`column` false) or columns: what
    /// [`GridLine::block`] does after the sums, lane by lane.
    fn finish<const FMA: bool>(sums: Self::Sums, column: bool, origin: &[f32; 3], scale: f32) -> Block;
}

impl GridLine for Line<3> {
    type Sums = [[[f32; LANES]; 3]; 3];

    #[inline(always)]
    fn block<const FMA: bool>(&self, basis: &Basis, t0: usize, origin: &[f32; 3], scale: f32) -> Block {
        Self::finish::<FMA>(self.sums::<FMA>(basis, t0), self.column, origin, scale)
    }

    #[inline(always)]
    fn finish<const FMA: bool>(sums: Self::Sums, column: bool, origin: &[f32; 3], scale: f32) -> Block {
        Self::finish_signed::<FMA>(sums, [if column { -1.0 } else { 1.0 }; LANES], origin, scale)
    }
}

impl Line<3> {
    /// [`GridLine::finish`] with each lane's orientation: `sign[l]` is −1 where lane `l` lies
    /// on a column, 1 on a row.
    #[inline(always)]
    fn finish_signed<const FMA: bool>(
        [mut pos, along, across]: [[[f32; LANES]; 3]; 3],
        sign: [f32; LANES],
        origin: &[f32; 3],
        scale: f32,
    ) -> Block {
        // ∂S/∂u × ∂S/∂v: along × across on a row, across × along on a column (the same
        // product, negated). Written as whole-array lane loops, one quantity at a time, so
        // that each becomes SIMD code. The reliability rule is `point_blocks::cross_normals`'s;
        // calling that function here measured 1.4× slower in this kernel (torus, factor 16), so
        // the loops stay inline.
        let ([ax, ay, az], [cx, cy, cz]) = (along, across);
        let mut nrm = [[0f32; LANES]; 3];
        let [nx, ny, nz] = &mut nrm;
        let mut margin = [0f32; LANES];
        for l in 0..LANES {
            nx[l] = ay[l] * cz[l] - az[l] * cy[l];
            ny[l] = az[l] * cx[l] - ax[l] * cz[l];
            nz[l] = ax[l] * cy[l] - ay[l] * cx[l];
        }
        for l in 0..LANES {
            let n2 = nx[l] * nx[l] + ny[l] * ny[l] + nz[l] * nz[l];
            let a2 = ax[l] * ax[l] + ay[l] * ay[l] + az[l] * az[l];
            let c2 = cx[l] * cx[l] + cy[l] * cy[l] + cz[l] * cz[l];
            // |a × c|² = |a|²|c|² sin²: the angle between the derivatives, scale-free; and
            // neither derivative so short that rounding turns it.
            let long = a2 >= MIN_DERIVATIVE2 && c2 >= MIN_DERIVATIVE2;
            margin[l] = if long { n2 - MIN_SIN2 * (a2 * c2) } else { -1.0 };
            let inv = sign[l] / n2.sqrt();
            nx[l] *= inv;
            ny[l] *= inv;
            nz[l] *= inv;
        }
        to_model::<FMA, LANES>(&mut pos, origin, scale);
        Block { pos, nrm, margin }
    }
}

impl GridLine for Line<4> {
    type Sums = [[[f32; LANES]; 4]; 3];

    #[inline(always)]
    fn block<const FMA: bool>(&self, basis: &Basis, t0: usize, origin: &[f32; 3], scale: f32) -> Block {
        Self::finish::<FMA>(self.sums::<FMA>(basis, t0), self.column, origin, scale)
    }

    #[inline(always)]
    fn finish<const FMA: bool>(
        [h, h_along, h_across]: Self::Sums,
        column: bool,
        origin: &[f32; 3],
        scale: f32,
    ) -> Block {
        let [mut pos, along, across] = rational_quotient::<FMA, LANES>(&h, &h_along, &h_across);
        // ∂S/∂u × ∂S/∂v: along × across on a row, across × along on a column.
        let (nrm, margin) =
            if column { cross_normals(&across, &along) } else { cross_normals(&along, &across) };
        to_model::<FMA, LANES>(&mut pos, origin, scale);
        Block { pos, nrm, margin }
    }
}

/// The interior of a small grid of factors `(nu, nv)`, `nv ≥ 3`, at most [`LANES`] points, in
/// one block: lane `l` is grid point `(1 + l % (nu − 1), 1 + l / (nu − 1))`, the interior's
/// order. Each lane holds the basis values of its own point: along `v` to form its row's
/// curve, along `u` to evaluate it.
///
/// Why: a coarse frame's grids have one to three points a row (the Catmull-Clark torus at
/// 0.5 px: 2×3, 2×4, 3×3), and a block of lanes a row spent most of its lanes on padding and
/// its setup on a point or two. The rows' curves are formed in the lanes by the operations
/// [`LocalPatch::row`] does, each lane on its own, so every point keeps its bits.
pub(super) struct GridLanes {
    /// `bv[k][l] = B_k(v_l)`, `dv[k][l] = B_k'(v_l)`, likewise `bu`, `du` along `u`.
    bv: [[f32; LANES]; 4],
    dv: [[f32; LANES]; 4],
    bu: [[f32; LANES]; 4],
    du: [[f32; LANES]; 4],
}

impl GridLanes {
    /// The lanes of the grid `(nu, nv)` from the factors' bases; None unless `nv ≥ 3` and the
    /// grid has at least one and at most [`LANES`] interior points. Lanes past the last point
    /// repeat it (a real point, which does not spoil [`Block::all_ok`]).
    pub(super) fn new(u: &Basis, v: &Basis, nu: usize, nv: usize) -> Option<GridLanes> {
        let m = nu.checked_sub(1)?;
        let count = m * nv.checked_sub(1)?;
        if nv < 3 || m == 0 || count > LANES {
            return None;
        }
        let mut lanes = GridLanes {
            bv: [[0.0; LANES]; 4],
            dv: [[0.0; LANES]; 4],
            bu: [[0.0; LANES]; 4],
            du: [[0.0; LANES]; 4],
        };
        for l in 0..LANES {
            let p = l.min(count - 1);
            let (i, j) = (1 + p % m, 1 + p / m);
            for k in 0..4 {
                lanes.bv[k][l] = v.b[k][j];
                lanes.dv[k][l] = v.d[k][j];
                lanes.bu[k][l] = u.b[k][i];
                lanes.du[k][l] = u.d[k][i];
            }
        }
        Some(lanes)
    }
}

impl<const C: usize> LocalPatch<C> {
    /// The interior points of the grid `lanes` describes ([`GridLanes`]), in the model's
    /// frame: lane for lane the bits of [`LocalPatch::row`] of the point's row and
    /// [`GridLine::block`] at its column. Cost: one block, and the rows' curves formed in the
    /// lanes (4·4·C multiplications and additions each way).
    // Index loops mirror `Line::new`'s and `Line::sums`'s (and vectorize over the lanes).
    #[allow(clippy::needless_range_loop)]
    #[inline(always)]
    pub(super) fn grid_block<const FMA: bool>(&self, lanes: &GridLanes) -> Block
    where
        Line<C>: GridLine<Sums = [[[f32; LANES]; C]; 3]>,
    {
        // Each lane's row curve, as `Line::new` sums it: over `k` from 0.0, a product then a
        // sum each (never fused).
        let mut c = [[[0f32; LANES]; 4]; C];
        let mut d = [[[0f32; LANES]; 4]; C];
        for comp in 0..C {
            for k in 0..4 {
                let (b, db) = (&lanes.bv[k], &lanes.dv[k]);
                for t in 0..4 {
                    let q = self.by_v[comp][k][t];
                    for l in 0..LANES {
                        c[comp][t][l] += q * b[l];
                        d[comp][t][l] += q * db[l];
                    }
                }
            }
        }
        // Each lane's point on its curve, as `Line::sums` sums it.
        let mut pos = [[0f32; LANES]; C];
        let mut along = [[0f32; LANES]; C];
        let mut across = [[0f32; LANES]; C];
        for k in 0..4 {
            let (b, db) = (&lanes.bu[k], &lanes.du[k]);
            for comp in 0..C {
                let (ck, dk) = (&c[comp][k], &d[comp][k]);
                for l in 0..LANES {
                    pos[comp][l] = madd::<FMA>(b[l], ck[l], pos[comp][l]);
                    along[comp][l] = madd::<FMA>(db[l], ck[l], along[comp][l]);
                    across[comp][l] = madd::<FMA>(b[l], dk[l], across[comp][l]);
                }
            }
        }
        Line::<C>::finish::<FMA>([pos, along, across], false, &self.origin, self.scale)
    }
}

/// The inner samples of two edges of one polynomial patch in one block: lanes `0..first` the
/// first edge's samples `k = 1..n_a` in order, then the second's. Each lane holds the basis
/// values of its point along its own edge's line (`t = k`, or `n − k` where the line runs
/// against the edge), and takes its line's coefficients.
///
/// Why: a coarse frame's edges have one to three inner samples (the Catmull-Clark torus at
/// 0.5 px: 1.7 an edge), and a block an edge spent most of its lanes on padding; a patch
/// owns its edges one after another, so two of them fill one block. The basis values are
/// tables made once per pair of factors and directions: stored lane by lane for each edge
/// (`LineLanes`, `docs/BENCHMARKS.md`), the reads waited on the stores.
pub(super) struct EdgePairLanes {
    b: [[f32; LANES]; 4],
    d: [[f32; LANES]; 4],
    /// The first edge's lanes.
    first: usize,
}

impl EdgePairLanes {
    /// The lanes of an edge of factor `na` (its line against it where `flip_a`) and one of
    /// factor `nb`, from the factors' bases; None unless each has an inner sample and the two
    /// have at most [`LANES`]. Lanes past the last sample repeat it.
    pub(super) fn new(
        (a, na, flip_a): (&Basis, usize, bool),
        (b, nb, flip_b): (&Basis, usize, bool),
    ) -> Option<EdgePairLanes> {
        let (ca, cb) = (na.checked_sub(1)?, nb.checked_sub(1)?);
        if ca == 0 || cb == 0 || ca + cb > LANES {
            return None;
        }
        let mut lanes = EdgePairLanes { b: [[0.0; LANES]; 4], d: [[0.0; LANES]; 4], first: ca };
        for l in 0..LANES {
            let q = l.min(ca + cb - 1);
            let (basis, n, flip, k) =
                if q < ca { (a, na, flip_a, q + 1) } else { (b, nb, flip_b, q - ca + 1) };
            let t = if flip { n - k } else { k };
            for i in 0..4 {
                lanes.b[i][l] = basis.b[i][t];
                lanes.d[i][l] = basis.d[i][t];
            }
        }
        Some(lanes)
    }
}

impl LocalPatch<3> {
    /// The samples of the lines `a` and `b` of this patch in the lanes `lanes` describes
    /// ([`EdgePairLanes`]), in the model's frame: lane for lane the bits of
    /// [`GridLine::block`] of the lane's own line. Cost: one block, and each coefficient
    /// chosen per lane.
    // Index loops mirror `Line::sums`'s (and vectorize over the lanes).
    #[allow(clippy::needless_range_loop)]
    #[inline(always)]
    pub(super) fn edge_pair_block<const FMA: bool>(
        &self,
        lanes: &EdgePairLanes,
        a: &Line<3>,
        b: &Line<3>,
    ) -> Block {
        let first = lanes.first;
        let pick =
            |x: f32, y: f32| -> [f32; LANES] { std::array::from_fn(|l| if l < first { x } else { y }) };
        let mut pos = [[0f32; LANES]; 3];
        let mut along = [[0f32; LANES]; 3];
        let mut across = [[0f32; LANES]; 3];
        for k in 0..4 {
            let (bk, dk) = (&lanes.b[k], &lanes.d[k]);
            for comp in 0..3 {
                let (ck, ek) = (pick(a.c[comp][k], b.c[comp][k]), pick(a.d[comp][k], b.d[comp][k]));
                for l in 0..LANES {
                    pos[comp][l] = madd::<FMA>(bk[l], ck[l], pos[comp][l]);
                    along[comp][l] = madd::<FMA>(dk[l], ck[l], along[comp][l]);
                    across[comp][l] = madd::<FMA>(bk[l], ek[l], across[comp][l]);
                }
            }
        }
        let sign = |line: &Line<3>| if line.column { -1.0 } else { 1.0 };
        let signs = pick(sign(a), sign(b));
        Line::<3>::finish_signed::<FMA>([pos, along, across], signs, &self.origin, self.scale)
    }
}

/// Writes lane `l` of `block`, or the f64 evaluation `exact()` where the lane is unreliable.
#[inline(always)]
pub(super) fn store(
    block: &Block,
    l: usize,
    pos: &mut [f32; 3],
    nrm: &mut [f32; 3],
    exact: impl FnOnce() -> SurfacePoint,
) {
    if block.ok(l) {
        *pos = [block.pos[0][l], block.pos[1][l], block.pos[2][l]];
        *nrm = [block.nrm[0][l], block.nrm[1][l], block.nrm[2][l]];
    } else {
        let q = exact();
        *pos = q.position.as_vec3().to_array();
        *nrm = q.normal.as_vec3().to_array();
    }
}

/// The grid line that local edge `e` of a patch runs along, as (row or column, index): the
/// general rule, which [`LocalPatch::edge`] computes without the basis.
#[cfg(test)]
fn edge_line<const C: usize>(patch: &LocalPatch<C>, basis: &Basis, n: usize, e: usize) -> Line<C> {
    match e {
        0 => patch.row(basis, 0),
        1 => patch.column(basis, n),
        2 => patch.row(basis, n),
        _ => patch.column(basis, 0),
    }
}

impl<const C: usize> LocalPatch<C> {
    /// The line of local edge `e` (0: `v = 0`, 1: `u = 1`, 2: `v = 1`, 3: `u = 0`), the bits
    /// of [`LocalPatch::row`] or [`LocalPatch::column`] at the end of any factor's basis,
    /// whose Bernstein values there are 0 and 1 and derivatives 0 and ±3: only the two nonzero
    /// terms of each sum are formed, in the same order from the same `0.0` (a sum that starts
    /// at `+0.0` is never `−0.0`, so the zero terms it skips could not change it). An edge has
    /// one or two inner samples on a coarse frame, and its line's sixteen-term sums were a
    /// visible part of the edge pass. Cost: 4·C additions and multiplications each way.
    #[inline(always)]
    pub(super) fn edge(&self, e: usize) -> Line<C> {
        let mut line = Line { c: [[0.0; 4]; C], d: [[0.0; 4]; C], column: e % 2 == 1 };
        // The net's end at the edge (`k = 0` or 3) and the next row or column inward.
        let (end, inner, sign) = if e == 0 || e == 3 { (0, 1, -3.0) } else { (3, 2, 3.0) };
        for c in 0..C {
            for t in 0..4 {
                let q = |k: usize| if e % 2 == 0 { self.by_v[c][k][t] } else { self.by_v[c][t][k] };
                line.c[c][t] = 0.0 + q(end);
                // B'(0) = (−3, 3, 0, 0) and B'(1) = (0, 0, −3, 3): the sum runs k upward.
                line.d[c][t] = if end == 0 {
                    (0.0 + q(end) * sign) + q(inner) * -sign
                } else {
                    (0.0 + q(inner) * -sign) + q(end) * sign
                };
            }
        }
        line
    }
}

#[cfg(test)]
mod tests {
    use super::super::fast_evaluator::FastEvaluator;
    use super::*;

    /// An edge's line without the basis is the general rule's, bit for bit, for every
    /// factor, on polynomial and rational nets with zeros of both signs among their points.
    #[test]
    fn edge_lines_are_the_rows_and_columns_at_the_ends_bit_for_bit() {
        fn bits<const C: usize>(l: &Line<C>) -> Vec<u32> {
            l.c.iter().chain(&l.d).flatten().map(|x| x.to_bits()).chain([l.column as u32]).collect()
        }
        fn check<const C: usize>(patch: &LocalPatch<C>, basis: &mut Basis) {
            for n in [1, 2, 3, 7, 16, 64] {
                basis.refill(n);
                for e in 0..4 {
                    assert_eq!(
                        bits(&patch.edge(e)),
                        bits(&edge_line(patch, basis, n, e)),
                        "n = {n}, edge {e}"
                    );
                }
            }
        }
        let mut rng = crate::test_support::Lcg(5);
        let mut basis = Basis::default();
        for round in 0..200 {
            let (polynomial, rational) = random_nets(&mut rng, round % 2 == 0);
            check(&polynomial, &mut basis);
            check(&rational, &mut basis);
        }
    }

    /// Two edges' samples in one block ([`LocalPatch::edge_pair_block`]) are, lane for lane,
    /// each edge's own block along its line, bit for bit (normals of columns negated as the
    /// lines' own blocks negate them, zeros included): every pair of local edges, factors and
    /// directions [`EdgePairLanes`] takes (and it takes no other), with and without fused
    /// multiply-adds, on nets with zeros of both signs.
    #[test]
    fn an_edge_pairs_block_is_its_edges_bit_for_bit() {
        fn check<const FMA: bool>(patch: &LocalPatch<3>, bases: &[Basis]) -> usize {
            let mut pairs = 0;
            for (na, nb) in (1..bases.len()).flat_map(|a| (1..bases.len()).map(move |b| (a, b))) {
                for (flip_a, flip_b) in [(false, false), (false, true), (true, false), (true, true)] {
                    let Some(lanes) = EdgePairLanes::new((&bases[na], na, flip_a), (&bases[nb], nb, flip_b))
                    else {
                        assert!(na < 2 || nb < 2 || na + nb - 2 > LANES, "({na}, {nb})");
                        continue;
                    };
                    pairs += 1;
                    for (ea, eb) in (0..4).flat_map(|a| (0..4).map(move |b| (a, b))) {
                        let (la, lb) = (patch.edge(ea), patch.edge(eb));
                        let block = patch.edge_pair_block::<FMA>(&lanes, &la, &lb);
                        let lanes_of = [(&la, na, flip_a, 0), (&lb, nb, flip_b, na - 1)];
                        for (line, n, flip, first) in lanes_of {
                            for k in 1..n {
                                let t = if flip { n - k } else { k };
                                let own = line.block::<FMA>(&bases[n], t, &patch.origin, patch.scale);
                                let l = first + k - 1;
                                assert_eq!(
                                    block_bits(&block, l),
                                    block_bits(&own, 0),
                                    "({na}, {nb}), edges ({ea}, {eb}), lane {l}"
                                );
                            }
                        }
                    }
                }
            }
            pairs
        }
        let bases = bases_up_to(10);
        let mut rng = crate::test_support::Lcg(13);
        for round in 0..20 {
            let (polynomial, _) = random_nets(&mut rng, round % 2 == 0);
            // Factor pairs with 2 to 8 samples in all, each in four directions.
            assert_eq!(check::<false>(&polynomial, &bases), 4 * 28);
            assert_eq!(check::<true>(&polynomial, &bases), 4 * 28);
        }
    }

    /// A whole block stored through the AVX interleaving ([`store_points`]) writes the bits
    /// that lane-by-lane stores write, and a block that is not whole (or has an unreliable
    /// lane) is written lane by lane either way, nothing past its points.
    #[test]
    fn whole_blocks_store_the_points_that_lane_stores_store() {
        let avx = crate::cpu::has_avx2_fma();
        #[cfg(target_arch = "x86_64")]
        assert!(avx, "the x86-64 machines tessera is tested on have AVX2 and FMA");
        // Distinct bits in every slot, with a negative zero, a subnormal and an infinity.
        let value = |c: usize, l: usize, k: f32| match (c, l) {
            (0, 0) => -0.0,
            (1, 3) => f32::from_bits(7),
            (2, 7) => f32::INFINITY,
            _ => k * (1.0 + c as f32) + l as f32 * 0.125,
        };
        let mut block = Block {
            pos: std::array::from_fn(|c| std::array::from_fn(|l| value(c, l, 1.5))),
            nrm: std::array::from_fn(|c| std::array::from_fn(|l| value(c, l, -2.25))),
            margin: [1.0; LANES],
        };
        let exact = |l: usize| SurfacePoint {
            position: glam::DVec3::splat(100.0 + l as f64),
            normal: glam::DVec3::Z,
        };
        let bits = |v: &[[f32; 3]]| v.iter().flatten().map(|x| x.to_bits()).collect::<Vec<_>>();
        for unreliable in [None, Some(5)] {
            block.margin = std::array::from_fn(|l| if Some(l) == unreliable { 0.0 } else { 1.0 });
            for n in 1..=LANES {
                let mut written = [[[9.0f32; 3]; LANES + 1]; 4];
                let [lane_pos, lane_nrm, avx_pos, avx_nrm] = &mut written;
                block.write::<false>(&mut lane_pos[..n], &mut lane_nrm[..n], exact);
                if avx {
                    block.write::<true>(&mut avx_pos[..n], &mut avx_nrm[..n], exact);
                } else {
                    // Not x86-64: only the lane stores exist.
                    avx_pos[..n].copy_from_slice(&lane_pos[..n]);
                    avx_nrm[..n].copy_from_slice(&lane_nrm[..n]);
                }
                let what = format!("{n} points, unreliable lane {unreliable:?}");
                assert_eq!(bits(&written[0]), bits(&written[2]), "positions: {what}");
                assert_eq!(bits(&written[1]), bits(&written[3]), "normals: {what}");
                for (l, (p, q)) in written[0].iter().zip(&written[1]).enumerate().take(n) {
                    let expected = match Some(l) == unreliable {
                        true => ([100.0 + l as f32; 3], [0.0, 0.0, 1.0]),
                        false => (
                            std::array::from_fn(|c| block.pos[c][l]),
                            std::array::from_fn(|c| block.nrm[c][l]),
                        ),
                    };
                    assert_eq!(bits(&[*p, *q]), bits(&[expected.0, expected.1]), "lane {l}: {what}");
                }
                assert!(
                    written.iter().all(|w| w[n..].iter().flatten().all(|&x| x == 9.0)),
                    "past the points: {what}"
                );
                // Given room for a whole block, `write_front` writes the same first `n`
                // points; a whole block's spare lanes land after them, and nothing past it.
                let mut room = [[[9.0f32; 3]; LANES + 1]; 2];
                let [front_pos, front_nrm] = &mut room;
                block.write_front::<true>(front_pos, front_nrm, n, exact);
                assert_eq!(bits(&room[0][..n]), bits(&written[0][..n]), "front positions: {what}");
                assert_eq!(bits(&room[1][..n]), bits(&written[1][..n]), "front normals: {what}");
                let whole = avx && unreliable.is_none();
                for l in n..LANES {
                    let expected = match whole {
                        true => std::array::from_fn(|c| block.pos[c][l]),
                        false => [9.0; 3],
                    };
                    assert_eq!(bits(&room[0][l..=l]), bits(&[expected]), "spare lane {l}: {what}");
                }
                assert!(room.iter().all(|w| w[LANES] == [9.0; 3]), "past the block: {what}");
            }
        }
    }

    /// The bits of lane `l` of `block`: position, normal, margin.
    fn block_bits(block: &Block, l: usize) -> [u32; 7] {
        let (p, n) = (&block.pos, &block.nrm);
        [p[0][l], p[1][l], p[2][l], n[0][l], n[1][l], n[2][l], block.margin[l]].map(f32::to_bits)
    }

    /// The bases of factors 0 to `n` (factor 0's as factor 1's, so that `bases[n]` is
    /// factor `n`'s).
    fn bases_up_to(n: usize) -> Vec<Basis> {
        (0..=n)
            .map(|n| {
                let mut b = Basis::default();
                b.refill(n.max(1));
                b
            })
            .collect()
    }

    /// A random net in `[-1, 1]³` as a polynomial patch (with `zeros`, zeros of both signs
    /// among its points, where sums from `0.0` decide the sign) and, weighted in `[0.5, 1.5]`,
    /// as a rational one.
    fn random_nets(rng: &mut crate::test_support::Lcg, zeros: bool) -> (LocalPatch<3>, LocalPatch<4>) {
        let mut net = [DVec3::ZERO; 16];
        for q in net.iter_mut() {
            *q = DVec3::new(rng.unit(), rng.unit(), rng.unit()) * 2.0 - 1.0;
        }
        let mut polynomial = LocalPatch::from_net(&net);
        if zeros {
            for (k, x) in polynomial.by_v.iter_mut().flatten().flatten().enumerate() {
                match k % 5 {
                    0 => *x = 0.0,
                    1 => *x = -0.0,
                    _ => {}
                }
            }
        }
        let weights: [f64; 16] = std::array::from_fn(|_| 0.5 + rng.unit());
        (polynomial, LocalPatch::<4>::in_frame(&net, local_frame(&net), |k| weights[k]))
    }
    /// A small grid's interior in one block ([`LocalPatch::grid_block`]) is, lane for lane,
    /// the row-by-row kernel's (its row's line, then a block along it), bit for bit: on
    /// polynomial and rational nets with zeros of both signs, with and without fused
    /// multiply-adds, for every grid [`GridLanes`] takes (and it takes no other).
    #[test]
    fn a_small_grids_block_is_its_rows_bit_for_bit() {
        fn check<const C: usize, const FMA: bool>(patch: &LocalPatch<C>, bases: &[Basis]) -> usize
        where
            Line<C>: GridLine<Sums = [[[f32; LANES]; C]; 3]>,
        {
            let mut grids = 0;
            for nu in 1..bases.len() {
                for nv in 1..bases.len() {
                    let (u, v) = (&bases[nu], &bases[nv]);
                    let Some(lanes) = GridLanes::new(u, v, nu, nv) else {
                        assert!(nv < 3 || nu < 2 || (nu - 1) * (nv - 1) > LANES, "({nu}, {nv})");
                        continue;
                    };
                    grids += 1;
                    let block = patch.grid_block::<FMA>(&lanes);
                    let m = nu - 1;
                    for l in 0..m * (nv - 1) {
                        let (i, j) = (1 + l % m, 1 + l / m);
                        let row = patch.row(v, j).block::<FMA>(u, i, &patch.origin, patch.scale);
                        assert_eq!(
                            block_bits(&block, l),
                            block_bits(&row, 0),
                            "({nu}, {nv}), point ({i}, {j})"
                        );
                    }
                }
            }
            grids
        }
        let bases = bases_up_to(11);
        let mut rng = crate::test_support::Lcg(9);
        for round in 0..100 {
            let (polynomial, rational) = random_nets(&mut rng, round % 2 == 0);
            // (2, 3) to (2, 9), (3, 3) to (3, 5), (4, 3), (5, 3).
            assert_eq!(check::<3, false>(&polynomial, &bases), 12);
            assert_eq!(check::<3, true>(&polynomial, &bases), 12);
            assert_eq!(check::<4, false>(&rational, &bases), 12);
            assert_eq!(check::<4, true>(&rational, &bases), 12);
        }
    }

    use crate::criterion::Plan;
    use crate::engine::{write_with, EngineOptions, Layout};
    use crate::mesh::Mesh;
    use crate::pattern::uniform::Uniform;
    use crate::pattern::PatternInput;
    use crate::sampling::SamplingKind;
    use crate::surface::{BuildOptions, Domain, Orientation, Patch, SurfaceSet};
    use crate::verify;
    use glam::DVec3;

    fn load(name: &str) -> SurfaceSet {
        let file = crate::io::patches::read_patches(&crate::test_support::data(name)).expect("test model");
        SurfaceSet::from_patch_file(&file, Default::default())
    }

    /// The model made rational, each control point weighted by a function of its position
    /// within [0.5, 2] ([`crate::scene::position_weights`]), so that shared curves stay
    /// shared.
    fn load_rational(name: &str) -> SurfaceSet {
        let file = crate::io::patches::read_patches(&crate::test_support::data(name)).expect("test model");
        let set = SurfaceSet::from_patch_file(&crate::scene::position_weights(&file), Default::default());
        assert!(set.patches.iter().all(|p| matches!(p, Patch::Bicubic(b) if !b.is_polynomial())));
        set
    }

    /// The exact rational models: the sphere octant and the four-piece cylinder.
    fn exact_rational() -> [(&'static str, SurfaceSet); 2] {
        let octant = vec![Patch::Bicubic(crate::scene::sphere_octant())];
        [
            ("sphere octant", SurfaceSet::from_patches(octant, BuildOptions::default())),
            ("cylinder", SurfaceSet::from_patch_file(&crate::scene::cylinder(2.0), Default::default())),
        ]
    }

    /// Both builds of the kernels where the CPU has AVX2 and FMA, else the baseline twice.
    const KERNELS: [bool; 2] = [false, true];

    /// The engine's writer with the evaluator, with the chosen kernels.
    fn fast(set: &SurfaceSet, plan: &Plan, options: EngineOptions, out: &mut Mesh, avx2_fma: bool) {
        let mut layout = Layout::default();
        layout.build(set, plan, &Uniform, &options).expect("layout");
        let evaluator = FastEvaluator::with_kernels(set, plan, avx2_fma);
        assert!(evaluator.grid(), "the grid kernels apply");
        write_with(set, plan, &Uniform, &layout, options, out, Some(&evaluator)).expect("fast evaluation");
    }

    /// The engine's writer with the generic f64 evaluation everywhere.
    fn generic(set: &SurfaceSet, plan: &Plan, options: EngineOptions) -> Mesh {
        let mut layout = Layout::default();
        layout.build(set, plan, &Uniform, &options).expect("layout");
        let mut mesh = Mesh::default();
        write_with(set, plan, &Uniform, &layout, options, &mut mesh, None).expect("generic evaluation");
        mesh
    }

    /// Layout, topology and parameters equal; positions within 1e-6 of the bounding-box diagonal and
    /// normals within 1e-5.
    fn assert_same_mesh(fast: &Mesh, generic: &Mesh, what: &str) {
        assert_eq!(fast.indices, generic.indices, "{what}: indices");
        assert_eq!(fast.triangle_patch, generic.triangle_patch, "{what}: triangle_patch");
        assert_eq!(fast.vertex_patch, generic.vertex_patch, "{what}: vertex_patch");
        assert_eq!(fast.uvs, generic.uvs, "{what}: uvs");
        assert_eq!(fast.corner_params, generic.corner_params, "{what}: corner_params");
        assert_eq!(fast.positions.len(), generic.positions.len(), "{what}: vertex count");
        assert_eq!(fast.normals.len(), generic.normals.len(), "{what}: normal count");
        let dvec = |p: &[f32; 3]| glam::Vec3::from(*p).as_dvec3();
        let (lo, hi) = generic
            .positions
            .iter()
            .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| (lo.min(dvec(p)), hi.max(dvec(p))));
        let size = (hi - lo).length();
        let max_diff = |a: &[[f32; 3]], b: &[[f32; 3]]| {
            a.iter().zip(b).map(|(a, b)| (dvec(a) - dvec(b)).length()).fold(0.0, f64::max)
        };
        let dp = max_diff(&fast.positions, &generic.positions) / size;
        let dn = max_diff(&fast.normals, &generic.normals);
        assert!(dp <= 1e-6, "{what}: positions differ by {dp:e} of the bounding-box diagonal");
        assert!(dn <= 1e-5, "{what}: normals differ by {dn:e}");
        // The f32 kernels ran (rounding differs from the f64 path's somewhere), rather than
        // the f64 fallback everywhere. Not on a handful of vertices, whose normals f32 may
        // hold exactly either way (the sphere octant's corners at factor 1).
        let changed = fast.normals.iter().zip(&generic.normals).filter(|(a, b)| a != b).count();
        if fast.normals.len() >= 64 {
            assert!(changed * 4 > fast.normals.len(), "{what}: only {changed} normals from the kernels");
        }
    }

    /// Adaptive plans (edge and interior factors varying from patch to patch, transition
    /// strips, semi-uniform snapping, collapsed curves, culled patches): the evaluator covers
    /// every grid interior and uniform edge, and the mesh is the generic one index for index.
    #[test]
    fn fast_path_matches_the_generic_engine_on_adaptive_plans() {
        use crate::scheme::{Criterion, PlanOptions, Scheme};
        let mut adaptive = 0;
        // Every bicubic model of the shared data.
        let models = [
            "bench/torus_64x32.patches",
            "patches/teacup.patches",
            "patches/teapot.patches",
            "patches/teapot_teasetorig.patches",
        ];
        // And the torus and the teapot made rational.
        let sets = models
            .iter()
            .map(|&m| (m.to_string(), load(m)))
            .chain(models.iter().step_by(2).map(|&m| (format!("{m} rational"), load_rational(m))));
        for (model, set) in sets {
            let (lo, hi) = set.bounds();
            for (k, (scheme, criterion, cull)) in [
                (Scheme::Transition, Criterion::PixelError(0.7), false),
                (Scheme::Transition, Criterion::Tolerance(0.002 * lo.distance(hi)), false),
                (Scheme::Transition, Criterion::PixelError(1.5), true),
                (Scheme::SemiUniform { max_level: 5 }, Criterion::PixelError(1.0), false),
            ]
            .into_iter()
            .enumerate()
            {
                let mut camera = crate::camera::Camera::framing(lo, hi, 1280, 720);
                camera.eye = camera.target + (camera.eye - camera.target) * (0.3 + 0.25 * k as f64);
                let options = PlanOptions { camera: Some(camera), cull, ..PlanOptions::default() };
                let planned = scheme.plan(&set, &criterion, &options).expect("plan");
                let (plan, pattern) = (&planned.plan, &planned.pattern);
                let distinct: std::collections::BTreeSet<u32> = plan.segments.iter().copied().collect();
                adaptive += usize::from(distinct.len() > 2);
                for avx2_fma in KERNELS {
                    let opts = EngineOptions::default();
                    let mut layout = Layout::default();
                    layout.build(&set, plan, pattern, &opts).expect("layout");
                    let evaluator = FastEvaluator::with_kernels(&set, plan, avx2_fma);
                    let covered = (0..set.patches.len())
                        .filter(|&p| {
                            let input = crate::engine::layout::pattern_input(&set, plan, p);
                            evaluator.covers_patch(p, pattern, &input).is_some()
                        })
                        .count();
                    assert_eq!(covered, set.patches.len(), "{model}: every quad interior is a grid");
                    let mut mesh = Mesh::default();
                    write_with(&set, plan, pattern, &layout, opts, &mut mesh, Some(&evaluator)).unwrap();
                    let mut reference = Mesh::default();
                    write_with(&set, plan, pattern, &layout, opts, &mut reference, None).unwrap();
                    let what = format!("{model} {scheme:?} {criterion:?} cull={cull} avx2_fma={avx2_fma}");
                    assert_same_mesh(&mesh, &reference, &what);
                }
            }
        }
        // Most plans mix several factors (the torus under a tolerance is uniform by symmetry).
        assert!(adaptive >= 15, "only {adaptive} of 24 plans use more than two edge factors");
    }

    /// Catmull-Clark cages mix regular faces (bicubics, on the grid kernels) with isolated
    /// faces (trees, on [`PointBlocks`](super::super::point_blocks::PointBlocks)): every
    /// bicubic's interior and every uniform edge a bicubic owns are the kernels', nothing
    /// else is, and the mesh is the generic one index for index, uniform and adaptive.
    #[test]
    fn fast_path_matches_the_generic_engine_on_mixed_cages() {
        use crate::scheme::{Criterion, PlanOptions, Scheme};
        for cage in ["subdivision/catmark_pawn.obj", "subdivision/catmark_torus_creases0.obj"] {
            let path = crate::test_support::data(cage);
            let obj = crate::io::obj::read_obj(&path).expect("test cage");
            let set = SurfaceSet::from_subdivision_cage(&obj, &path, Default::default()).expect("cage");
            let bicubic = |p: usize| matches!(set.patches[p], Patch::Bicubic(_));
            let regular = (0..set.patches.len()).filter(|&p| bicubic(p)).count();
            assert!(regular > 0 && regular < set.patches.len(), "{cage}: a mixed set");
            let (lo, hi) = set.bounds();
            let camera = crate::camera::Camera::framing(lo, hi, 1280, 720);
            let options = PlanOptions { camera: Some(camera), ..PlanOptions::default() };
            let adaptive =
                Scheme::Transition.plan(&set, &Criterion::PixelError(0.5), &options).expect("plan");
            let plans: [(&str, Plan, &dyn crate::pattern::Pattern); 3] = [
                ("uniform 5", Plan::uniform(&set, 5).unwrap(), &Uniform),
                ("uniform 16", Plan::uniform(&set, 16).unwrap(), &Uniform),
                ("transition 0.5 px", adaptive.plan.clone(), &adaptive.pattern),
            ];
            for (what, plan, pattern) in plans {
                for avx2_fma in KERNELS {
                    let f = FastEvaluator::with_kernels(&set, &plan, avx2_fma);
                    assert!(f.grid() && !f.grid_corners(), "{cage} {what}");
                    for p in 0..set.patches.len() {
                        let input = crate::engine::layout::pattern_input(&set, &plan, p);
                        let grid = pattern.interior_grid(&input).is_some();
                        assert_eq!(
                            f.covers_patch(p, pattern, &input).is_some(),
                            grid && bicubic(p),
                            "{cage} {what}"
                        );
                    }
                    let topo = &set.topology;
                    for e in (0..topo.edges.len())
                        .filter(|&e| topo.edges[e].variants == 1 && !topo.edges[e].collapsed)
                    {
                        assert_eq!(f.covers_edge(&plan, e), bicubic(topo.edge_uses(e)[0].patch as usize));
                    }
                    let opts = EngineOptions::default();
                    let mut layout = Layout::default();
                    layout.build(&set, &plan, pattern, &opts).expect("layout");
                    let mut mesh = Mesh::default();
                    write_with(&set, &plan, pattern, &layout, opts, &mut mesh, Some(&f)).unwrap();
                    let mut reference = Mesh::default();
                    write_with(&set, &plan, pattern, &layout, opts, &mut reference, None).unwrap();
                    assert_same_mesh(&mesh, &reference, &format!("{cage} {what} avx2_fma={avx2_fma}"));
                }
            }
        }
    }

    #[test]
    fn fast_path_matches_the_generic_engine() {
        let torus = "bench/torus_64x32.patches";
        let models = [(torus.to_string(), load(torus)), ("teacup".into(), load("patches/teacup.patches"))]
            .into_iter()
            .chain([(format!("{torus} rational"), load_rational(torus))])
            .chain(exact_rational().map(|(name, set)| (name.to_string(), set)));
        for (model, set) in models {
            for avx2_fma in KERNELS {
                // One mesh for every call: each call must overwrite the previous, larger or
                // smaller, result completely.
                let mut mesh = Mesh::default();
                for n in [1, 2, 3, 7, 16, 2] {
                    let plan = Plan::uniform(&set, n).unwrap();
                    for corner_params in [false, true] {
                        let options = EngineOptions { corner_params, ..Default::default() };
                        fast(&set, &plan, options, &mut mesh, avx2_fma);
                        let what = format!("{model} n={n} corner_params={corner_params} avx2_fma={avx2_fma}");
                        assert_same_mesh(&mesh, &generic(&set, &plan, options), &what);
                    }
                }
            }
        }
    }

    /// Where the derivatives are parallel, f32 cannot give the normal: the point must take
    /// the f64 evaluation, and come out as the generic path's bits exactly.
    #[test]
    fn degenerate_points_take_the_exact_evaluation() {
        // A curved patch whose control points P00 and P10 coincide: ∂S/∂u vanishes at corner
        // (0, 0), though no boundary curve collapses and no corner repeats.
        let mut points = [DVec3::ZERO; 16];
        for i in 0..4 {
            for j in 0..4 {
                points[4 * i + j] = DVec3::new(i as f64, j as f64, 0.1 * (i * j) as f64);
            }
        }
        points[4] = points[0];
        let options = BuildOptions { orientation: Orientation::AsGiven, ..Default::default() };
        let set =
            SurfaceSet::from_patches(vec![Patch::Bicubic(RationalBicubic::polynomial(points))], options);
        for avx2_fma in KERNELS {
            for n in [1, 4, 9] {
                let plan = Plan::uniform(&set, n).unwrap();
                let mut mesh = Mesh::default();
                fast(&set, &plan, EngineOptions::default(), &mut mesh, avx2_fma);
                let reference = generic(&set, &plan, EngineOptions::default());
                assert_same_mesh(&mesh, &reference, &format!("pinched corner n={n} avx2_fma={avx2_fma}"));
                let corner = set.topology.patch_corner_entries[0][0] as usize;
                assert_eq!(mesh.normals[corner], reference.normals[corner], "n={n}: the limit normal");
                assert_eq!(mesh.positions[corner], reference.positions[corner], "n={n}");
            }
        }
    }

    #[test]
    fn fast_path_keeps_the_torus_closed() {
        let torus = "bench/torus_64x32.patches";
        for (set, avx2_fma) in
            [load(torus), load_rational(torus)].iter().flat_map(|s| KERNELS.map(|k| (s, k)))
        {
            for n in [1, 2, 5, 16] {
                let plan = Plan::uniform(set, n).unwrap();
                let mut mesh = Mesh::default();
                fast(set, &plan, EngineOptions::default(), &mut mesh, avx2_fma);
                let w = verify::watertight(&mesh);
                assert!(w.is_closed(), "n={n}: {w:?}");
                assert_eq!(w.degenerate_triangles(), 0, "n={n}");
                assert_eq!(w.euler_characteristic, 0, "n={n}");
                assert_eq!(w.vertices, mesh.vertex_count(), "n={n}: every vertex is distinct and used");
            }
        }
    }

    /// Collapsed curves and culled patches change the layout, not the evaluation: the
    /// evaluator still covers the rest, and the mesh is the generic one.
    #[test]
    fn evaluation_matches_around_collapsed_curves_and_culled_patches() {
        let teapot = load("patches/teapot.patches");
        assert!(teapot.topology.edges.iter().any(|e| e.collapsed));
        let set = load("bench/torus_64x32.patches");
        let mut culled = Plan::uniform(&set, 4).unwrap();
        culled.visible[3] = 0;
        for avx2_fma in KERNELS {
            for corner_params in [false, true] {
                let options = EngineOptions { corner_params, ..Default::default() };
                let mut mesh = Mesh::default();
                let plan = Plan::uniform(&teapot, 5).unwrap();
                fast(&teapot, &plan, options, &mut mesh, avx2_fma);
                assert!(mesh.collapsed_triangles > 0);
                assert_same_mesh(&mesh, &generic(&teapot, &plan, options), "teapot n=5");
                fast(&set, &culled, options, &mut mesh, avx2_fma);
                assert_same_mesh(&mesh, &generic(&set, &culled, options), "torus, one patch culled");
            }
        }
    }

    #[test]
    fn the_evaluator_covers_only_what_it_can_evaluate() {
        let set = load("bench/torus_64x32.patches");
        let plan = Plan::uniform(&set, 4).unwrap();
        let f = FastEvaluator::new(&set, &plan);
        assert!(f.grid(), "a uniform polynomial bicubic plan");
        let mut other = plan.clone();
        other.segments[7] = 5;
        assert!(f.covers_edge(&plan, 7) && !f.covers_edge(&other, 7), "5 has no tables yet");
        let input = |interior| PatternInput::new(Domain::Quad, [4; 4], interior);
        assert_eq!(f.covers_patch(0, &Uniform, &input([4, 4])), Some([4, 4]));
        assert_eq!(f.covers_patch(0, &Uniform, &input([5, 5])), None, "a factor without tables");
        let tri = PatternInput::new(Domain::Tri, [4; 4], [4, 4]);
        assert_eq!(f.covers_patch(0, &Uniform, &tri), None, "triangles are not bicubic");
        let mut fractional = plan.clone();
        fractional.kind = SamplingKind::Fractional(crate::sampling::Spacing::Symmetric);
        assert!(!FastEvaluator::new(&set, &fractional).grid());
        assert!(!FastEvaluator::new(&set, &fractional).covers_edge(&fractional, 7));
        // Rational patches have grid kernels of their own, unless their weights span more
        // than f32 keeps reliable.
        let mut rational = set.clone();
        if let Patch::Bicubic(b) = &mut rational.patches[5] {
            b.weights[5] = 2.0;
        }
        assert!(FastEvaluator::new(&rational, &plan).grid_corners());
        if let Patch::Bicubic(b) = &mut rational.patches[5] {
            b.weights[6] = 2.0 * MIN_WEIGHT_RATIO * 0.99;
        }
        // That patch alone leaves the kernels: its interior and the edges it owns; the
        // corners, which the kernels take all or none of, too.
        let f = FastEvaluator::new(&rational, &plan);
        assert!(f.grid() && !f.grid_corners());
        assert_eq!(f.covers_patch(5, &Uniform, &input([4, 4])), None);
        assert_eq!(f.covers_patch(4, &Uniform, &input([4, 4])), Some([4, 4]));
        let topo = &rational.topology;
        let owner = |e: usize| topo.edge_uses(e)[0].patch as usize;
        assert!((0..topo.edges.len()).all(|e| f.covers_edge(&plan, e) == (owner(e) != 5)));
    }
}
