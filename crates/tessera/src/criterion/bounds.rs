//! Bounds on second derivatives, and the approximation-error bounds built on them.
//!
//! For a triangle `T` in the parameter domain and the linear interpolant `L` of the surface at
//! its corners, `|S − L| ≤ Λ·R²/2` everywhere on `T`, where `R` is the radius of the smallest
//! disc containing `T` and `Λ` bounds every second directional derivative `|dᵀ·D²S·d|`,
//! `|d| = 1`. (Proof: with `c` the disc's centre, `e = w·(S − L) − Λ/2·(R² − |x − c|²)` is
//! convex for every unit vector `w` and `≤ 0` at the corners, hence on `T`.) With
//! `|S_uu| ≤ Muu`, `|S_uv| ≤ Muv`, `|S_vv| ≤ Mvv`, `Λ` is the largest eigenvalue of
//! `[[Muu, Muv], [Muv, Mvv]]`. Measuring the domain in the scaled coordinates
//! `(a·u, b·v)` makes the bound direction-aware; with `(a, b) = (√Muu, √Mvv)` and grid cells
//! with `√Muu·hu = √Mvv·hv` it equals the bound of Filip, Magedson & Markot (1986):
//! `(hu²·Muu + 2·hu·hv·Muv + hv²·Mvv)/8`.
//!
//! `Muu`, `Muv`, `Mvv` come from the control net: `m(m−1)·max|Δ²b|` and `m·n·max|ΔuΔv b|` for
//! polynomial patches; rational patches bound the homogeneous numerator and the weight
//! separately and divide by the smallest weight (in the spirit of Zheng & Sederberg 2000; the
//! quotient-rule expansion is in [`bicubic_hessian`]).

use crate::surface::{BezierTriangle, Patch, QuarticTriangle, RationalBicubic};
use glam::{DVec2, DVec3};

/// Bounds on the second partial derivatives of a patch over its whole domain.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct HessianBound {
    pub uu: f64,
    pub uv: f64,
    pub vv: f64,
}

impl HessianBound {
    /// Largest eigenvalue of `[[uu, uv], [uv, vv]]`: a bound on every unit second directional
    /// derivative.
    pub fn lambda(&self) -> f64 {
        let (a, b, c) = (self.uu, self.uv, self.vv);
        0.5 * ((a + c) + ((a - c) * (a - c) + 4.0 * b * b).sqrt())
    }

    /// Guaranteed bound on `|S − L|` over the parameter triangle `t`: the smallest of the bounds
    /// for three scalings of the domain (each is valid; `(√Muu, √Mvv)` matches Filip's bound on
    /// grid cells whose sides follow `√Muu·hu = √Mvv·hv`). Cost: O(1); a loop over many
    /// triangles of one patch takes [`HessianBound::triangle_errors`] instead.
    pub fn triangle_error(&self, t: [DVec2; 3]) -> f64 {
        self.triangle_errors().error(t)
    }

    /// [`HessianBound::triangle_error`] with what depends only on the bound computed once.
    pub fn triangle_errors(&self) -> TriangleErrors {
        let tiny = 1e-300 + 1e-12 * (self.uu + self.uv + self.vv);
        let scales = [
            DVec2::new((self.uu + tiny).sqrt(), (self.vv + tiny).sqrt()),
            DVec2::new((self.uu + self.uv + tiny).sqrt(), (self.vv + self.uv + tiny).sqrt()),
            DVec2::ONE,
        ];
        let lambdas = scales.map(|s| {
            HessianBound { uu: self.uu / (s.x * s.x), uv: self.uv / (s.x * s.y), vv: self.vv / (s.y * s.y) }
                .lambda()
        });
        TriangleErrors { bound: *self, scales: scales.map(|s| s * s), lambdas }
    }

    /// Filip's bound `(hu²·Muu + 2·hu·hv·Muv + hv²·Mvv)/8` for a right triangle whose legs
    /// `(hu, hv)` follow the `u` and `v` axes (the half cells of a grid: [`axis_legs`]).
    #[inline(always)]
    fn filip_error(&self, (hu, hv): (f64, f64)) -> f64 {
        (hu * hu * self.uu + 2.0 * hu * hv * self.uv + hv * hv * self.vv) / 8.0
    }
}

/// The legs `(|hu|, |hv|)` of a right triangle whose legs run along the `u` and `v` axes (the
/// half cells of a grid, where Filip's bound applies); None for other triangles.
fn axis_legs(t: [DVec2; 3]) -> Option<(f64, f64)> {
    // Parameters computed as k/n along an edge and as i·(1/n) inside differ in the last
    // bits; a skew of 1e-12 of the side changes the bound by less than that.
    let flat = |x: f64, side: f64| x.abs() <= 1e-12 * side.abs();
    for c in 0..3 {
        let (a, b) = (t[(c + 1) % 3] - t[c], t[(c + 2) % 3] - t[c]);
        if flat(a.y, a.x) && flat(b.x, b.y) {
            return Some((a.x.abs(), b.y.abs()));
        }
        if flat(a.x, a.y) && flat(b.y, b.x) {
            return Some((b.x.abs(), a.y.abs()));
        }
    }
    None
}

/// What the bound of a parameter triangle reads of the triangle, whatever the patch
/// ([`TriangleErrors::shape_exceeds`]): its sides' squared extents along `u` and `v`, its
/// area and, for a grid's half cell, its legs. A pattern's triangles are the same on every
/// patch, so the a-posteriori check keeps their shapes with the pattern (for small
/// patterns) and bounds each patch's pattern from them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TriangleShape {
    /// Each side's `(du², dv²)`: its squared length in the scaled coordinates `(a·u, b·v)`
    /// is `du²·a² + dv²·b²`.
    sides: [DVec2; 3],
    /// The doubled area in `(u, v)`, squared (times `a²·b²` in the scaled coordinates).
    doubled_area_squared: f64,
    /// [`axis_legs`].
    legs: Option<(f64, f64)>,
}

impl TriangleShape {
    /// The shape of parameter triangle `t`. Cost: O(1).
    #[inline(always)]
    pub fn of(t: [DVec2; 3]) -> Self {
        let side = |p: DVec2, q: DVec2| (q - p) * (q - p);
        let doubled_area = (t[1] - t[0]).perp_dot(t[2] - t[0]);
        TriangleShape {
            sides: [side(t[1], t[2]), side(t[2], t[0]), side(t[0], t[1])],
            doubled_area_squared: doubled_area * doubled_area,
            legs: axis_legs(t),
        }
    }

    /// The squared radius of its smallest enclosing disc in the coordinates `(a·u, b·v)`,
    /// for `scale_squared = (a², b²)`.
    #[inline(always)]
    fn enclosing_radius_squared(&self, scale_squared: DVec2) -> f64 {
        let s = self.sides.map(|d| d.dot(scale_squared));
        let area = self.doubled_area_squared * (scale_squared.x * scale_squared.y);
        enclosing_radius_squared(s, area)
    }

    /// Its longest side, squared, unscaled: the pattern's check bounds its largest
    /// triangles first, so the others stop at their first bound.
    pub fn longest_side_squared(&self) -> f64 {
        self.sides.iter().map(|d| d.x + d.y).fold(0.0, f64::max)
    }
}

/// [`HessianBound::triangle_error`] for one bound and many triangles: the scalings and their
/// eigenvalues computed once ([`HessianBound::triangle_errors`]). Gives the same bits as
/// `triangle_error`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TriangleErrors {
    bound: HessianBound,
    /// The three scalings' `(a², b²)`.
    scales: [DVec2; 3],
    /// Largest eigenvalue of the bound in each scaling's coordinates.
    lambdas: [f64; 3],
}

impl TriangleErrors {
    /// The bound over parameter triangle `t`. Cost: three enclosing discs.
    // Always: the a-posteriori check calls it once per triangle of every checked pattern.
    // With a plain `#[inline]`, LLVM stopped inlining it into `tolerance::params_bound` after
    // unrelated engine code changed, and the resolve stage of the torus at a 0.001 %
    // tolerance grew by 8 % (9.3 → 10.1 ms, 1 thread).
    #[inline(always)]
    pub fn error(&self, t: [DVec2; 3]) -> f64 {
        // Every error exceeds −∞ (it is a minimum of bounds ≥ 0), so nothing stops early.
        self.exceeds(t, f64::NEG_INFINITY).unwrap_or(f64::NEG_INFINITY)
    }
}

impl TriangleErrors {
    /// [`TriangleErrors::error`] of `t` where it exceeds `at_least`, else None: the largest
    /// error over many triangles ([`crate::criterion::tolerance`]'s a-posteriori check) needs
    /// no more. [`TriangleErrors::shape_exceeds`] of `t`'s shape. Cost: O(1).
    #[inline(always)]
    pub fn exceeds(&self, t: [DVec2; 3], at_least: f64) -> Option<f64> {
        self.shape_exceeds(&TriangleShape::of(t), at_least)
    }

    /// The error of a triangle of shape `shape` where it exceeds `at_least`, else None. The
    /// cheaper bounds go first, and a triangle stops as soon as one of them is at most
    /// `at_least` (the error is their minimum); [`TriangleErrors::error`] is this with no
    /// threshold. Cost: three enclosing discs at most, from squared lengths (no root).
    #[inline(always)]
    pub fn shape_exceeds(&self, shape: &TriangleShape, at_least: f64) -> Option<f64> {
        let axis = shape.legs.map(|legs| self.bound.filip_error(legs));
        if axis.is_some_and(|a| a <= at_least) {
            return None;
        }
        let mut general = f64::INFINITY;
        for (s, lambda) in self.scales.iter().zip(self.lambdas) {
            // The bound with the domain measured in coordinates `(a·u, b·v)`.
            general = general.min(lambda * shape.enclosing_radius_squared(*s) / 2.0);
            if general <= at_least {
                return None;
            }
        }
        let error = general.min(axis.unwrap_or(f64::INFINITY));
        (error > at_least).then_some(error)
    }

    /// [`TriangleErrors::error`] of a half cell of a grid — a right triangle with legs `hu`
    /// along `u` and `hv` along `v` — in closed form: its smallest enclosing disc in every
    /// scaling is the one on its hypotenuse, and Filip's bound applies. Equal to `error` on
    /// such a triangle up to rounding (the a-posteriori check's margin is 1e-9 of the bound;
    /// this differs in the last bits), without the three square roots. Cost: O(1).
    #[inline]
    pub fn cell_error(&self, hu: f64, hv: f64) -> f64 {
        let mut general = f64::INFINITY;
        for (s, lambda) in self.scales.iter().zip(self.lambdas) {
            // λ·r²/2 with r² = (a²·hu² + b²·hv²)/4.
            general = general.min(lambda * (s.x * hu * hu + s.y * hv * hv) / 8.0);
        }
        general.min(self.bound.filip_error((hu, hv)))
    }
}

/// Radius of the smallest disc containing a triangle: half the longest side when the triangle
/// is right or obtuse, else its circumradius.
pub fn enclosing_radius(t: [DVec2; 3]) -> f64 {
    TriangleShape::of(t).enclosing_radius_squared(DVec2::ONE).sqrt()
}

/// The squared radius of the smallest disc containing a triangle whose squared sides are `s`
/// and whose doubled area, squared, is `doubled_area_squared`: a quarter of the longest side's
/// square when the triangle is right or obtuse, else the circumradius's, `s₀·s₁·s₂ / 4A²`
/// (`A` the doubled area). No square root: the bound needs the square. Where that quotient
/// is not a number (an area that underflowed: a flat patch's scalings are about 1e-150),
/// `f64::MAX`: any value is a valid bound there, as the bound takes the smallest of its
/// scalings', and a zero eigenvalue times it is still zero.
#[inline(always)]
fn enclosing_radius_squared(s: [f64; 3], doubled_area_squared: f64) -> f64 {
    let longest = s[0].max(s[1]).max(s[2]);
    if 2.0 * longest >= s[0] + s[1] + s[2] {
        return longest / 4.0;
    }
    let r2 = s[0] * s[1] * s[2] / (4.0 * doubled_area_squared);
    if r2.is_finite() {
        r2
    } else {
        f64::MAX
    }
}

/// The largest norm of `it`'s vectors (0 for none): a Bézier form's bound by its points.
pub(crate) fn max_norm(it: impl Iterator<Item = DVec3>) -> f64 {
    it.map(|v| v.length()).fold(0.0, f64::max)
}

/// Second-derivative bounds of a bicubic (rational) patch.
///
/// With `H = Σ w_ij (P_ij − c) B B` (`c` the control points' bounding-box centre, which makes
/// `r = max|P_ij − c|` small) and `S − c = H/w`: `S_u = (H_u − (S−c)·w_u)/w`,
/// `S_uu = (H_uu − 2·S_u·w_u − (S−c)·w_uu)/w`, `S_uv = (H_uv − S_u·w_v − S_v·w_u − (S−c)·w_uv)/w`;
/// each term is bounded through the control-net differences of `H` and `w` and `w ≥ min w_ij`.
/// For polynomial patches this is exactly `6·max|Δ²b|`, `9·max|ΔuΔv b|`.
pub fn bicubic_hessian(p: &RationalBicubic) -> HessianBound {
    let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
    for q in &p.points {
        lo = lo.min(*q);
        hi = hi.max(*q);
    }
    let c = (lo + hi) * 0.5;
    let h = |i: usize, j: usize| (p.points[4 * i + j] - c) * p.weights[4 * i + j];
    let w = |i: usize, j: usize| p.weights[4 * i + j];
    let r = max_norm(p.points.iter().map(|q| *q - c));
    let wmin = p.weights.iter().copied().fold(f64::INFINITY, f64::min);

    let pairs = |f: &dyn Fn(usize, usize) -> f64| -> f64 {
        let mut m = 0.0f64;
        for i in 0..4 {
            for j in 0..4 {
                m = m.max(f(i, j));
            }
        }
        m
    };
    let d1u_h = 3.0 * pairs(&|i, j| if i < 3 { (h(i + 1, j) - h(i, j)).length() } else { 0.0 });
    let d1v_h = 3.0 * pairs(&|i, j| if j < 3 { (h(i, j + 1) - h(i, j)).length() } else { 0.0 });
    let d2u_h =
        6.0 * pairs(&|i, j| if i < 2 { (h(i + 2, j) - 2.0 * h(i + 1, j) + h(i, j)).length() } else { 0.0 });
    let d2v_h =
        6.0 * pairs(&|i, j| if j < 2 { (h(i, j + 2) - 2.0 * h(i, j + 1) + h(i, j)).length() } else { 0.0 });
    let duv_h = 9.0
        * pairs(&|i, j| {
            if i < 3 && j < 3 {
                (h(i + 1, j + 1) - h(i + 1, j) - h(i, j + 1) + h(i, j)).length()
            } else {
                0.0
            }
        });
    if p.is_polynomial() {
        return polynomial_bicubic_hessian(p);
    }
    let w1u = 3.0 * pairs(&|i, j| if i < 3 { (w(i + 1, j) - w(i, j)).abs() } else { 0.0 });
    let w1v = 3.0 * pairs(&|i, j| if j < 3 { (w(i, j + 1) - w(i, j)).abs() } else { 0.0 });
    let w2u =
        6.0 * pairs(&|i, j| if i < 2 { (w(i + 2, j) - 2.0 * w(i + 1, j) + w(i, j)).abs() } else { 0.0 });
    let w2v =
        6.0 * pairs(&|i, j| if j < 2 { (w(i, j + 2) - 2.0 * w(i, j + 1) + w(i, j)).abs() } else { 0.0 });
    let wuv = 9.0
        * pairs(&|i, j| {
            if i < 3 && j < 3 {
                (w(i + 1, j + 1) - w(i + 1, j) - w(i, j + 1) + w(i, j)).abs()
            } else {
                0.0
            }
        });
    let gu = (d1u_h + r * w1u) / wmin;
    let gv = (d1v_h + r * w1v) / wmin;
    HessianBound {
        uu: (d2u_h + 2.0 * gu * w1u + r * w2u) / wmin,
        uv: (duv_h + gu * w1v + gv * w1u + r * wuv) / wmin,
        vv: (d2v_h + 2.0 * gv * w1v + r * w2v) / wmin,
    }
}

/// Sub-intervals a bound is refined over: each second derivative of a polynomial bicubic is
/// itself a Bézier patch (degrees (1,3), (2,2), (3,1)); the control points of its pieces over
/// a `SPLIT × SPLIT` grid of sub-rectangles bound it more tightly than its own net, and
/// converge to its true maximum as the pieces shrink.
const SPLIT: usize = 4;

/// De Casteljau split of a Bézier curve at `t`: the control points of `[0, t]` and `[t, 1]`.
fn split<const N: usize>(c: [DVec3; N], t: f64) -> ([DVec3; N], [DVec3; N]) {
    let (mut left, mut right) = ([DVec3::ZERO; N], [DVec3::ZERO; N]);
    let mut level = c;
    for r in 0..N {
        left[r] = level[0];
        right[N - 1 - r] = level[N - 1 - r];
        for i in 0..N - 1 - r {
            level[i] = level[i] * (1.0 - t) + level[i + 1] * t;
        }
    }
    (left, right)
}

/// Control points of the piece of a Bézier curve over `[a, b] ⊂ [0, 1]`.
fn sub_curve<const N: usize>(c: [DVec3; N], a: f64, b: f64) -> [DVec3; N] {
    let right = split(c, a).1;
    let t = if a < 1.0 { ((b - a) / (1.0 - a)).clamp(0.0, 1.0) } else { 0.0 };
    split(right, t).0
}

/// Largest control-point norm over the `SPLIT × SPLIT` pieces of a tensor Bézier patch with
/// `M × N` control points `net[i][j]` (`i` along u).
#[allow(clippy::needless_range_loop)] // i indexes the second axis of cols
fn split_max<const M: usize, const N: usize>(net: [[DVec3; N]; M]) -> f64 {
    let mut worst = 0.0f64;
    for pu in 0..SPLIT {
        let (ua, ub) = (pu as f64 / SPLIT as f64, (pu + 1) as f64 / SPLIT as f64);
        // Rows restricted in u: for each column j, the curve over i.
        let mut cols = [[DVec3::ZERO; M]; N];
        for (j, col) in cols.iter_mut().enumerate() {
            *col = sub_curve(std::array::from_fn(|i| net[i][j]), ua, ub);
        }
        for pv in 0..SPLIT {
            let (va, vb) = (pv as f64 / SPLIT as f64, (pv + 1) as f64 / SPLIT as f64);
            for i in 0..M {
                let row: [DVec3; N] = sub_curve(std::array::from_fn(|j| cols[j][i]), va, vb);
                worst = row.iter().map(|p| p.length()).fold(worst, f64::max);
            }
        }
    }
    worst
}

/// Tight second-derivative bounds of a polynomial bicubic: the nets of `S_uu`
/// (`6·Δ²_u b`, 2×4), `S_uv` (`9·ΔuΔv b`, 3×3) and `S_vv` (`6·Δ²_v b`, 4×2), each bounded
/// over `SPLIT × SPLIT` pieces.
fn polynomial_bicubic_hessian(p: &RationalBicubic) -> HessianBound {
    let b = |i: usize, j: usize| p.points[4 * i + j];
    let uu: [[DVec3; 4]; 2] =
        std::array::from_fn(|i| std::array::from_fn(|j| (b(i + 2, j) - 2.0 * b(i + 1, j) + b(i, j)) * 6.0));
    let vv: [[DVec3; 2]; 4] =
        std::array::from_fn(|i| std::array::from_fn(|j| (b(i, j + 2) - 2.0 * b(i, j + 1) + b(i, j)) * 6.0));
    let uv: [[DVec3; 3]; 3] = std::array::from_fn(|i| {
        std::array::from_fn(|j| (b(i + 1, j + 1) - b(i + 1, j) - b(i, j + 1) + b(i, j)) * 9.0)
    });
    HessianBound { uu: split_max(uu), uv: split_max(uv), vv: split_max(vv) }
}

/// Second-derivative bounds of a cubic Bézier triangle in its `(u, v)` parameters:
/// `S_uu = 6 Σ (b_{i,j+2,k} − 2b_{i+1,j+1,k} + b_{i+2,j,k}) B¹`, likewise for `vv` and `uv`.
pub fn triangle_hessian(t: &BezierTriangle) -> HessianBound {
    let mut m = HessianBound::default();
    for (i, j, k) in [(1, 0, 0), (0, 1, 0), (0, 0, 1)] {
        let b = |di: usize, dj: usize, dk: usize| t.b(i + di, j + dj, k + dk);
        m.uu = m.uu.max(6.0 * (b(0, 2, 0) - 2.0 * b(1, 1, 0) + b(2, 0, 0)).length());
        m.vv = m.vv.max(6.0 * (b(0, 0, 2) - 2.0 * b(1, 0, 1) + b(2, 0, 0)).length());
        m.uv = m.uv.max(6.0 * (b(0, 1, 1) - b(1, 0, 1) - b(1, 1, 0) + b(2, 0, 0)).length());
    }
    m
}

/// Second-derivative bounds of a quartic Bézier triangle in its `(u, v)` parameters, over the
/// whole triangle. Cost: 6 × 3 second differences.
///
/// Derivation: differentiating the Bernstein form twice along the parameter directions
/// (`∂/∂u` moves weight from `λ0` to `λ1`, `∂/∂v` from `λ0` to `λ2`) gives quadratic Bézier
/// triangles, `S_uu = 4·3 Σ_{i+j+k=2} (b_{i,j+2,k} − 2b_{i+1,j+1,k} + b_{i+2,j,k}) B²_ijk`,
/// `S_uv = 12 Σ (b_{i,j+1,k+1} − b_{i+1,j,k+1} − b_{i+1,j+1,k} + b_{i+2,j,k}) B²_ijk` and
/// `S_vv` likewise with `k` ([`QuarticTriangle::second_differences`]). On the triangle the
/// `B²_ijk` are non-negative and sum to 1, so each derivative is a convex combination of its
/// six Bézier points and its norm is at most their largest: `n(n−1)·max|Δ²b|` with `n = 4`.
/// The bound is attained wherever a derivative's largest point is a corner point (at that
/// corner), e.g. for every quadratic surface raised to degree 4.
pub fn quartic_triangle_hessian(t: &QuarticTriangle) -> HessianBound {
    let mut m = HessianBound::default();
    for [uu, uv, vv] in t.second_differences() {
        m.uu = m.uu.max(12.0 * uu.length());
        m.uv = m.uv.max(12.0 * uv.length());
        m.vv = m.vv.max(12.0 * vv.length());
    }
    m
}

/// Second-derivative bounds of any patch (PN triangles: their cubic geometry).
pub fn hessian(p: &Patch) -> HessianBound {
    match p {
        Patch::Bicubic(b) => bicubic_hessian(b),
        Patch::BezierTriangle(t) => triangle_hessian(t),
        Patch::Pn(pn) => triangle_hessian(&pn.geometry),
        Patch::Subdivision(t) => tree_hessian(t),
        Patch::Loop(t) => loop_tree_hessian(t),
    }
}

/// Second-derivative bounds of a subdivision patch: the largest of its leaves', each in the
/// tree's parameters (a leaf of size `h` scales second derivatives by `1/h²`).
///
/// What this proves: a bound on the second derivatives of every piece, i.e. of the surface
/// wherever it is twice differentiable. The error bound built on it also needs the pieces
/// to meet with continuous tangents, which B-spline leaves do (they are pieces of one
/// B-spline surface) and Gregory end caps do only approximately, as in OpenSubdiv; the
/// property tests measure the error against the bound on every cage.
pub fn tree_hessian(t: &crate::surface::PatchTree) -> HessianBound {
    let mut m = HessianBound::default();
    for (leaf, _, size) in t.visible_leaves() {
        let h = leaf_hessian(&leaf.patch);
        let s = 1.0 / (size * size);
        m.uu = m.uu.max(h.uu * s);
        m.uv = m.uv.max(h.uv * s);
        m.vv = m.vv.max(h.vv * s);
    }
    // A quarter turn or a transposition exchanges the parameters' roles.
    if t.is_transposed() != (t.rotation() % 2 == 1) {
        std::mem::swap(&mut m.uu, &mut m.vv);
    }
    m
}

/// Second-derivative bounds of one leaf of a Catmull-Clark tree, in the leaf's parameters.
fn leaf_hessian(leaf: &crate::surface::patch_tree::LeafPatch) -> HessianBound {
    use crate::surface::patch_tree::LeafPatch;
    match leaf {
        LeafPatch::Bezier(points) => bicubic_hessian(&RationalBicubic::polynomial(*points)),
        LeafPatch::Gregory(g) => gregory_hessian(g),
    }
}

/// Second-derivative bounds of a Catmull-Clark patch's four boundary curves (patch edges 0
/// to 3, each in its own parameter): the largest over the leaves with a side on the edge of
/// that side's cubic ([`curve_second_derivative`] of its four points), times `1/h²` for a
/// leaf of side `h` in the patch's parameters. A Gregory end cap's sides are cubics too:
/// each corner's rational blend carries the factor `B₁(u)B₁(v)`, which vanishes on the
/// boundary, so a side is the Bézier curve of the four boundary points along it.
///
/// Why not [`tree_hessian`] along the edge's direction: that bounds every leaf, the
/// Gregory caps' interior blends (`18·|Fp − Fm|` a corner) among them, where a boundary
/// curve only meets the leaves along it. On `catmark_cube` (every face capped at every
/// corner) the whole patch's bound asked each edge for 26 segments at 0.1 %, where the
/// Taylor bound's grid needs 21. Cost: O(leaves).
pub fn tree_curve_bounds(t: &crate::surface::PatchTree) -> [f64; 4] {
    use crate::surface::patch_tree::{rotate, LeafPatch};
    use glam::DVec2;
    // The side of the view's square `w ∈ [0,1]²` (0: w.y = 0, 1: w.x = 1, 2: w.y = 1,
    // 3: w.x = 0) that patch edge `l` maps to: `w` is the patch's parameter transposed and
    // turned (`PatchTree::tree_uv`, before the view's square).
    let side_of = |l: usize| {
        let uv = crate::domain::Domain::Quad.edge_point(l, 0.5);
        let uv = if t.is_transposed() { DVec2::new(uv.y, uv.x) } else { uv };
        let w = rotate(uv, t.rotation());
        if w.y == 0.0 {
            0
        } else if w.x == 1.0 {
            1
        } else if w.y == 1.0 {
            2
        } else {
            3
        }
    };
    let mut by_side = [0.0f64; 4];
    for (leaf, origin, size) in t.visible_leaves() {
        let net: [[DVec3; 4]; 4] = match &leaf.patch {
            // `points[4*i + j]`, `i` along u: as rows along v, columns along u.
            LeafPatch::Bezier(p) => std::array::from_fn(|j| std::array::from_fn(|i| p[4 * i + j])),
            LeafPatch::Gregory(g) => g.bezier_net(0.5, 0.5),
        };
        let (lo, hi) = (origin, origin + DVec2::splat(size));
        // Per side of the view's square: the leaf's own side on it, or the side crossing the
        // leaf (a quarter's view of a larger leaf), and the leaf's points along its own side.
        let sides = [
            (lo.y == 0.0, lo.y < 0.0 && 0.0 < hi.y, [net[0][0], net[0][1], net[0][2], net[0][3]]),
            (hi.x == 1.0, lo.x < 1.0 && 1.0 < hi.x, [net[0][3], net[1][3], net[2][3], net[3][3]]),
            (hi.y == 1.0, lo.y < 1.0 && 1.0 < hi.y, [net[3][0], net[3][1], net[3][2], net[3][3]]),
            (lo.x == 0.0, lo.x < 0.0 && 0.0 < hi.x, [net[0][0], net[1][0], net[2][0], net[3][0]]),
        ];
        for (k, (on, crosses, points)) in sides.into_iter().enumerate() {
            let along = if on {
                curve_second_derivative(points, [1.0; 4])
            } else if crosses {
                // An iso-curve inside the leaf, bounded by its second derivative along it.
                let m = leaf_hessian(&leaf.patch);
                if k % 2 == 0 {
                    m.uu
                } else {
                    m.vv
                }
            } else {
                continue;
            };
            by_side[k] = by_side[k].max(along / (size * size));
        }
    }
    std::array::from_fn(|l| by_side[side_of(l)])
}

/// Second-derivative bounds of a Gregory patch.
///
/// The patch is the bicubic `S⁻` whose interior points are each corner's `Fm`, plus, per
/// corner `c`, `h_c(u,v)·(Fp_c − Fm_c)` where `h_c` is the corner's Bernstein product times
/// its rational blend (corner 0: `B₁(u)B₁(v)·v/(u+v)`; the others are the same function
/// reflected). So `|S_uu| ≤ |S⁻_uu| + Σ sup|∂uu h_c|·|Fp_c − Fm_c|`, likewise for `uv`, `vv`.
/// For `h = B₁(u)B₁(v)·v/(u+v)` the suprema are 18 (`uu`), 9 (`uv`) and 18 (`vv`): near the
/// corner `h ≈ 9uv²/(u+v)`, whose second derivatives `−2v³/(u+v)³`,
/// `3v²/(u+v)² − 2v³/(u+v)³` and `2u³/(u+v)³` tend to −2, 1 and 2 there (times 9), and a
/// 1500² sample of the closed forms over the square stays below them (17.6, 8.7, 16.5).
/// The other corners' functions are reflections of it (corner 2's also exchanges `u` and
/// `v`), and the `uu` and `vv` constants are equal, so one set serves all four.
pub fn gregory_hessian(g: &crate::surface::GregoryPatch) -> HessianBound {
    let p = &g.points;
    let mut m = bicubic_hessian(&RationalBicubic::polynomial(g.minus_net()));
    for c in 0..4 {
        let d = (p[5 * c + 3] - p[5 * c + 4]).length();
        m.uu += 18.0 * d;
        m.uv += 9.0 * d;
        m.vv += 18.0 * d;
    }
    m
}

/// Second-derivative bounds of a Loop patch: the largest of its leaves', each in the tree's
/// parameters. A leaf of side `h` scales second derivatives by `1/h²`, and a turned leaf's
/// parameters run against the tree's on both axes, which leaves second derivatives as they
/// are; a swapped tree exchanges `u` and `v`. What this proves is what [`tree_hessian`]
/// proves for Catmull-Clark trees: a bound on every piece, whose pieces meet with continuous
/// tangents where they are box splines and approximately at Gregory triangles.
pub fn loop_tree_hessian(t: &crate::surface::TriangleTree) -> HessianBound {
    use crate::surface::triangle_tree::TriangleLeafPatch;
    let mut m = HessianBound::default();
    for leaf in t.leaves() {
        let h = match &leaf.patch {
            TriangleLeafPatch::Quartic(q) => quartic_triangle_hessian(q),
            TriangleLeafPatch::Gregory(g) => gregory_triangle_hessian(g),
        };
        let s = 1.0 / (leaf.size * leaf.size);
        m.uu = m.uu.max(h.uu * s);
        m.uv = m.uv.max(h.uv * s);
        m.vv = m.vv.max(h.vv * s);
    }
    if t.is_swapped() {
        std::mem::swap(&mut m.uu, &mut m.vv);
    }
    m
}

/// Second-derivative bounds of a Loop patch's three boundary curves (patch edges 0, 1, 2,
/// each in its own parameter; a regular patch is a tree of one leaf, the whole triangle,
/// whose sides are its boundary): the largest over the leaves with a side on the edge
/// of the leaf's second derivative along it — by that side's five points
/// ([`quartic_curve_second_derivative`]), for a quartic leaf and for a Gregory triangle alike
/// (its blends vanish on its sides) — times `1/h²` for a leaf of side `h`.
/// [`loop_tree_hessian`] takes every leaf, the Gregory triangles' interior blends among them,
/// for every edge; before 2026-12-05 a Gregory triangle's side took that bound along it,
/// several times too large. A turned leaf can
/// only lie along the hypotenuse; a swapped tree's edges 0 and 2 are the patch's 2 and 0.
/// Cost: O(leaves).
pub fn loop_tree_curve_bounds(t: &crate::surface::TriangleTree) -> [f64; 3] {
    use crate::surface::triangle_tree::TriangleLeafPatch;
    let mut out = [0.0f64; 3];
    for leaf in t.leaves() {
        let (o, h) = (leaf.origin, leaf.size);
        // The leaf's corners st = (0,0), (1,0), (0,1) in the tree's parameters.
        let corners = if leaf.turned {
            [o + glam::DVec2::splat(h), o + glam::DVec2::new(0.0, h), o + glam::DVec2::new(h, 0.0)]
        } else {
            [o, o + glam::DVec2::new(h, 0.0), o + glam::DVec2::new(0.0, h)]
        };
        let on = |e: usize, p: glam::DVec2| match e {
            0 => p.y == 0.0,
            1 => p.x + p.y == 1.0,
            _ => p.x == 0.0,
        };
        for (e, bound) in out.iter_mut().enumerate() {
            // The leaf's side on tree edge e: its local side `side` (corner `side` to `side + 1`).
            let Some(side) = (0..3).find(|&c| on(e, corners[c]) && on(e, corners[(c + 1) % 3])) else {
                continue;
            };
            let along = match &leaf.patch {
                TriangleLeafPatch::Quartic(q) => quartic_curve_second_derivative(q.edge_points(side)),
                // A Gregory triangle's interior blends carry `w²st`, `s²tw`, `st²w`, which
                // vanish on its sides: a side is the quartic of its boundary points.
                TriangleLeafPatch::Gregory(g) => {
                    quartic_curve_second_derivative(g.blended(glam::DVec2::splat(0.25)).edge_points(side))
                }
            };
            *bound = bound.max(along / (h * h));
        }
    }
    if t.is_swapped() {
        out.swap(0, 2);
    }
    out
}

/// Second-derivative bounds of a Gregory triangle ([`crate::surface::GregoryTriangle`]).
///
/// The patch is the quartic triangle `S⁻` whose three interior points are the corners' `Fm`,
/// plus, per corner `c`, `h_c(s,t)·(Fp_c − Fm_c)` where `h_c` is the interior point's
/// Bernstein polynomial times its rational blend: `12·w²st·s/(s+t)` at corner 0,
/// `12·s²tw·t/(t+w)` at corner 1, `12·st²w·w/(w+s)` at corner 2 (`w = 1 − s − t`). So
/// `|S_ss| ≤ |S⁻_ss| + Σ sup|∂ss h_c|·|Fp_c − Fm_c|`, likewise for `st` and `tt`. The suprema
/// are approached at each blend's singular corner, where the second derivatives (homogeneous
/// of degree 0 there) depend on the direction only: (24, 12, 24) for corner 0,
/// (24, 36, 48) for corner 1 and (48, 24, 24) for corner 2 (`ss`, `st`, `tt`; corner 0's is
/// the quads' `9·(2, 1, 2)` with 12 for 9, the others are the same function in turned
/// coordinates). Sampled on 20,001 rays at 10⁻⁶ from each singular corner they reach these
/// values to 5·10⁻⁶, and on a 1200² grid of the triangle they stay below them.
pub fn gregory_triangle_hessian(g: &crate::surface::GregoryTriangle) -> HessianBound {
    use crate::surface::QuarticTriangle;
    let p = &g.points;
    // The net with Fm inside: b(1,1), b(2,1), b(1,2) in (s, t) steps (the Gregory
    // triangle's module doc), exponents (w, s, t) for `QuarticTriangle::index`.
    let mut minus = g.blended(glam::DVec2::splat(0.25));
    for (c, (i, j, k)) in [(2, 1, 1), (1, 2, 1), (1, 1, 2)].into_iter().enumerate() {
        minus.points[QuarticTriangle::index(i, j, k)] = p[5 * c + 4];
    }
    let mut m = quartic_triangle_hessian(&minus);
    for (c, [uu, uv, vv]) in
        [[24.0, 12.0, 24.0], [24.0, 36.0, 48.0], [48.0, 24.0, 24.0]].into_iter().enumerate()
    {
        let d = (p[5 * c + 3] - p[5 * c + 4]).length();
        m.uu += uu * d;
        m.uv += uv * d;
        m.vv += vv * d;
    }
    m
}

/// Bound on the second derivative of a cubic (rational) curve from its own four control
/// points and weights — the data both patches of an edge agree on.
pub fn curve_second_derivative(points: [DVec3; 4], weights: [f64; 4]) -> f64 {
    let c = (points.iter().fold(DVec3::splat(f64::INFINITY), |a, &b| a.min(b))
        + points.iter().fold(DVec3::splat(f64::NEG_INFINITY), |a, &b| a.max(b)))
        * 0.5;
    let h = points.map(|p| p - c);
    let hw: Vec<DVec3> = h.iter().zip(weights).map(|(p, w)| *p * w).collect();
    let d2 = 6.0 * max_norm((0..2).map(|i| hw[i + 2] - 2.0 * hw[i + 1] + hw[i]));
    if weights.iter().all(|&w| w == 1.0) {
        return d2;
    }
    let r = max_norm(h.iter().copied());
    let wmin = weights.iter().copied().fold(f64::INFINITY, f64::min);
    let d1 = 3.0 * max_norm((0..3).map(|i| hw[i + 1] - hw[i]));
    let w1 = 3.0 * (0..3).map(|i| (weights[i + 1] - weights[i]).abs()).fold(0.0, f64::max);
    let w2 =
        6.0 * (0..2).map(|i| (weights[i + 2] - 2.0 * weights[i + 1] + weights[i]).abs()).fold(0.0, f64::max);
    let g = (d1 + r * w1) / wmin;
    (d2 + 2.0 * g * w1 + r * w2) / wmin
}

/// Bound on the second derivative of a quartic curve (a regular Loop patch's boundary,
/// [`crate::surface::QuarticTriangle::edge_points`]) from its five control points: its second
/// derivative is the quadratic Bézier curve `12 Σ Δ²p · B²`, inside the hull of its points.
pub fn quartic_curve_second_derivative(points: [DVec3; 5]) -> f64 {
    12.0 * max_norm((0..3).map(|i| points[i + 2] - 2.0 * points[i + 1] + points[i]))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The closed form of a half cell's bound is the general bound of that triangle (both
    /// orientations of the cell's diagonal), to rounding, on bounds and cells of every shape.
    #[test]
    fn cell_error_is_the_triangle_error_of_a_half_cell() {
        let mut rng = crate::test_support::Lcg(11);
        let mut next = || rng.unit();
        for _ in 0..5000 {
            let scale = 10f64.powf(6.0 * next() - 3.0);
            let m = HessianBound { uu: scale * next(), uv: scale * next() * next(), vv: scale * next() };
            let errors = m.triangle_errors();
            let (nu, nv) = (1 + (next() * 64.0) as u32, 1 + (next() * 64.0) as u32);
            let (hu, hv) = (1.0 / nu as f64, 1.0 / nv as f64);
            let (i, j) = ((next() * nu as f64).floor() * hu, (next() * nv as f64).floor() * hv);
            let corner = DVec2::new(i, j);
            let (du, dv) = (DVec2::new(hu, 0.0), DVec2::new(0.0, hv));
            let closed = errors.cell_error(hu, hv);
            for t in [[corner, corner + du, corner + du + dv], [corner, corner + du + dv, corner + dv]] {
                let general = errors.error(t);
                assert!(
                    (closed - general).abs() <= 1e-12 * general,
                    "{m:?} {nu}×{nv}: {closed} against {general}"
                );
            }
        }
    }

    #[test]
    fn split_bounds_are_valid_and_tighter() {
        // A wavy polynomial patch: the refined bound is still ≥ every sampled |S_uu|, |S_vv|,
        // |S_uv| (by finite differences) and no looser than the plain net bound.
        let mut pts = [DVec3::ZERO; 16];
        for i in 0..4 {
            for j in 0..4 {
                let (x, y) = (i as f64, j as f64);
                pts[4 * i + j] = DVec3::new(x, y, ((x * 1.7).sin() + (y * 2.3).cos()) * (1.0 + x * y * 0.3));
            }
        }
        let p = RationalBicubic::polynomial(pts);
        let tight = polynomial_bicubic_hessian(&p);
        let b = |i: usize, j: usize| p.points[4 * i + j];
        let mut loose = 0.0f64;
        for i in 0..2 {
            for j in 0..4 {
                loose = loose.max(6.0 * (b(i + 2, j) - 2.0 * b(i + 1, j) + b(i, j)).length());
            }
        }
        assert!(tight.uu <= loose + 1e-12);
        let h = 1e-4;
        for k in 0..=20 {
            for l in 0..=20 {
                let (u, v) = (0.05 + 0.9 * k as f64 / 20.0, 0.05 + 0.9 * l as f64 / 20.0);
                let at = |du: f64, dv: f64| p.position(DVec2::new(u + du, v + dv));
                let suu = (at(h, 0.0) - 2.0 * at(0.0, 0.0) + at(-h, 0.0)) / (h * h);
                let svv = (at(0.0, h) - 2.0 * at(0.0, 0.0) + at(0.0, -h)) / (h * h);
                let suv = (at(h, h) - at(h, -h) - at(-h, h) + at(-h, -h)) / (4.0 * h * h);
                assert!(suu.length() <= tight.uu * (1.0 + 1e-4) + 1e-6);
                assert!(svv.length() <= tight.vv * (1.0 + 1e-4) + 1e-6);
                assert!(suv.length() <= tight.uv * (1.0 + 1e-4) + 1e-6);
            }
        }
    }

    /// The quartic triangle's bound holds at every sampled point of random nets (exact second
    /// derivatives, and central differences of the position as an independent check), and is
    /// attained by a quadratic surface raised to degree 4, so its factor is not too large.
    #[test]
    fn quartic_triangle_hessian_bounds_the_second_derivatives() {
        let mut rng = crate::test_support::Lcg(12);
        let mut ratio = 0.0f64;
        for _ in 0..200 {
            let scale = 10f64.powf(4.0 * rng.unit() - 2.0);
            let t = QuarticTriangle {
                points: std::array::from_fn(|_| {
                    (DVec3::new(rng.unit53(), rng.unit53(), rng.unit53()) * 2.0 - DVec3::ONE) * scale
                }),
            };
            let m = quartic_triangle_hessian(&t);
            let h = 1e-3;
            for a in 0..=24 {
                for b in 0..=24 - a {
                    let uv = DVec2::new(a as f64, b as f64) / 24.0;
                    let (uu, uv_, vv) = t.second_derivatives(uv);
                    let slack = 1.0 + 1e-12;
                    assert!(uu.length() <= m.uu * slack, "{uv}: |S_uu| {} > {}", uu.length(), m.uu);
                    assert!(uv_.length() <= m.uv * slack, "{uv}: |S_uv| {} > {}", uv_.length(), m.uv);
                    assert!(vv.length() <= m.vv * slack, "{uv}: |S_vv| {} > {}", vv.length(), m.vv);
                    ratio = ratio.max(uu.length() / m.uu).max(vv.length() / m.vv);
                    // Differences of the position (out of the triangle by up to h, where the
                    // polynomial is still defined): error h²/12·|S_uuuu|, |S_uuuu| ≤ 4!·16·max|b|.
                    let at = |du: f64, dv: f64| t.position(uv + DVec2::new(du, dv));
                    let fd_uu = (at(h, 0.0) - 2.0 * at(0.0, 0.0) + at(-h, 0.0)) / (h * h);
                    let fd_uv = (at(h, h) - at(h, -h) - at(-h, h) + at(-h, -h)) / (4.0 * h * h);
                    let fd_vv = (at(0.0, h) - 2.0 * at(0.0, 0.0) + at(0.0, -h)) / (h * h);
                    let tolerance = 1e-3 * scale;
                    assert!(fd_uu.length() <= m.uu + tolerance, "{uv}");
                    assert!(fd_uv.length() <= m.uv + tolerance, "{uv}");
                    assert!(fd_vv.length() <= m.vv + tolerance, "{uv}");
                }
            }
        }
        // Random nets come near the bound (a corner's point is often the largest).
        assert!(ratio > 0.999, "{ratio}");
        // S = (u², uv, v²) written as a quartic: S_uu = (2,0,0), S_uv = (0,1,0), S_vv = (0,0,2).
        // Its Bézier points are the polar forms at the corners: with j arguments at corner 1
        // and k at corner 2, u² → j(j−1)/12, uv → jk/12, v² → k(k−1)/12.
        let mut quadratic = QuarticTriangle { points: [DVec3::ZERO; 15] };
        for i in 0..=4usize {
            for j in 0..=4 - i {
                let k = 4 - i - j;
                let (j, k, n) = (j as f64, k as f64, QuarticTriangle::index(i, j, k));
                quadratic.points[n] = DVec3::new(j * (j - 1.0), j * k, k * (k - 1.0)) / 12.0;
            }
        }
        let uv = DVec2::new(0.2, 0.3);
        let p = quadratic.position(uv);
        assert!((p - DVec3::new(uv.x * uv.x, uv.x * uv.y, uv.y * uv.y)).length() < 1e-15, "{p}");
        let (uu, uv_, vv) = quadratic.second_derivatives(uv);
        assert!((uu - DVec3::new(2.0, 0.0, 0.0)).length() < 1e-12, "{uu}");
        assert!((uv_ - DVec3::new(0.0, 1.0, 0.0)).length() < 1e-12, "{uv_}");
        assert!((vv - DVec3::new(0.0, 0.0, 2.0)).length() < 1e-12, "{vv}");
        let m = quartic_triangle_hessian(&quadratic);
        assert!(
            (m.uu - 2.0).abs() < 1e-12 && (m.uv - 1.0).abs() < 1e-12 && (m.vv - 2.0).abs() < 1e-12,
            "{m:?}"
        );
    }

    #[test]
    fn enclosing_radius_of_right_and_equilateral_triangles() {
        let right = [DVec2::ZERO, DVec2::X, DVec2::Y];
        assert!((enclosing_radius(right) - 2f64.sqrt() / 2.0).abs() < 1e-12);
        let eq = [DVec2::ZERO, DVec2::X, DVec2::new(0.5, 3f64.sqrt() / 2.0)];
        assert!((enclosing_radius(eq) - 1.0 / 3f64.sqrt()).abs() < 1e-12);
        let obtuse = [DVec2::ZERO, DVec2::new(2.0, 0.0), DVec2::new(1.0, 0.1)];
        assert!((enclosing_radius(obtuse) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn error_is_the_smallest_bound_and_exceeds_gives_it_exactly_where_it_passes_the_threshold() {
        // A small seeded generator: triangles of every shape (slivers, right triangles along
        // the axes, obtuse ones) and thresholds below, at and above their errors.
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let (mut above, mut below) = (0, 0);
        for k in 0..4000 {
            let m = HessianBound { uu: 10.0 * next(), uv: 3.0 * next(), vv: 10.0 * next() }.triangle_errors();
            let mut t = [0; 3].map(|_| DVec2::new(next(), next()));
            if k % 4 == 0 {
                // A grid half cell, whose axis-aligned bound applies.
                let (h, w) = (next() * 0.2 + 0.01, next() * 0.2 + 0.01);
                t = [t[0], t[0] + DVec2::new(h, 0.0), t[0] + DVec2::new(0.0, w)];
            }
            let error = m.error(t);
            // The bound written out from the points: the smallest of the three scalings'
            // (each the smallest enclosing disc of the scaled points, by its side lengths
            // and circumradius) and, on a half cell, Filip's.
            let disc = |t: [DVec2; 3]| {
                let sides = [t[1] - t[2], t[2] - t[0], t[0] - t[1]].map(|d| d.length());
                let longest = sides[0].max(sides[1]).max(sides[2]);
                if 2.0 * longest * longest >= sides.iter().map(|l| l * l).sum::<f64>() {
                    longest / 2.0
                } else {
                    sides[0] * sides[1] * sides[2] / (2.0 * (t[1] - t[0]).perp_dot(t[2] - t[0]).abs())
                }
            };
            let scaled = m.scales.iter().zip(m.lambdas).map(|(squares, lambda)| {
                let s = DVec2::new(squares.x.sqrt(), squares.y.sqrt());
                let r = disc(t.map(|p| p * s));
                lambda * r * r / 2.0
            });
            let b = m.bound;
            let filip = |(hu, hv): (f64, f64)| (hu * hu * b.uu + 2.0 * hu * hv * b.uv + hv * hv * b.vv) / 8.0;
            let half_cell = (k % 4 == 0).then(|| filip(((t[1] - t[0]).x.abs(), (t[2] - t[0]).y.abs())));
            let reference = scaled.fold(f64::INFINITY, f64::min).min(half_cell.unwrap_or(f64::INFINITY));
            assert!(
                (error - reference).abs() <= 1e-12 * reference,
                "triangle {k}: {error} against {reference}"
            );
            for at_least in [0.0, error * 0.5, error, error * (1.0 - 1e-15), error * 2.0] {
                match m.exceeds(t, at_least) {
                    Some(e) => {
                        assert_eq!(e.to_bits(), error.to_bits(), "triangle {k}");
                        assert!(error > at_least);
                        above += 1;
                    }
                    None => {
                        assert!(error <= at_least, "triangle {k}: {error} > {at_least} but none given");
                        below += 1;
                    }
                }
            }
        }
        assert!(above > 1000 && below > 1000, "{above} above, {below} below");
    }

    #[test]
    fn grid_cell_bound_equals_filip() {
        let m = HessianBound { uu: 3.0, uv: 1.0, vv: 0.5 };
        let (hu, hv) = (0.1, 0.25);
        let tri = [DVec2::ZERO, DVec2::new(hu, 0.0), DVec2::new(hu, hv)];
        let filip = (hu * hu * m.uu + 2.0 * hu * hv * m.uv + hv * hv * m.vv) / 8.0;
        let ours = m.triangle_error(tri);
        // Never tighter than Filip's (which is sharp for such cells), and close to it.
        assert!(ours >= filip * (1.0 - 1e-12) && ours <= 1.5 * filip, "{ours} vs {filip}");
        // Equal to Filip's when the cell follows √Muu·hu = √Mvv·hv.
        let hv = hu * (m.uu / m.vv).sqrt();
        let tri = [DVec2::ZERO, DVec2::new(hu, 0.0), DVec2::new(hu, hv)];
        let filip = (hu * hu * m.uu + 2.0 * hu * hv * m.uv + hv * hv * m.vv) / 8.0;
        assert!((m.triangle_error(tri) - filip).abs() < 1e-12 * filip);
    }
}
