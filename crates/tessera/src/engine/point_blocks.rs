//! A specialisation of *evaluation*: any list of parameters on one patch, evaluated
//! [`LANES`] points at a time in f32, for bicubic patches (polynomial or rational), cubic
//! and quartic Bézier triangles (a regular Loop patch is one quartic), Gregory triangles (Loop's
//! end caps, for `tree_points`) and PN triangles.
//!
//! Where [`super::uniform_quads`] exploits a grid (a row reduced to a curve once), this
//! evaluator takes parameters as a pattern or an edge sampling chose them — transition strips,
//! snapped dyadic points, fractional samplings, SD-2 and ESC patterns, triangle domains — so
//! every scheme and surface kind leaves the generic f64 evaluation. It computes the Bernstein
//! bases of each lane's own parameters, then sums the control points in structure-of-arrays
//! form, which the compiler vectorizes.
//!
//! **Same frame, same fallbacks as the grid path.** A patch is moved to a local frame (control
//! points minus their bounding-box centre, divided by a power of two, [`local_frame`]) and
//! rounded to f32 there, so f32 carries the patch's own detail at full relative precision.
//! Where a normal would lose its direction in f32 (derivatives nearly parallel or very short,
//! or a PN normal field that nearly vanishes) the point takes the generic f64 evaluation. The
//! parameters written (`uvs`) and the patch ids are the generic path's own, so only positions
//! and normals differ, by rounding.
//!
//! **Rational bicubic patches** are evaluated in homogeneous form: the numerator `H = Σ w p B B`
//! and the weight `W = Σ w B B` as a fourth component of the same sums, then the quotient
//! ([`rational_quotient`], which says how the normal avoids a division and why the polynomial
//! reliability rule holds for it unchanged).
//!
//! **Watertight as before**: this changes how a point is computed, never which patch computes
//! it; every shared vertex is still evaluated once, by its owner.

use super::tree_points::{catmark_leaf, eval_sparse, loop_leaf, CatmarkLeaf, LoopLeaf, FORM_LEVEL};
use super::uniform_quads::LocalPatch;
use super::VertexSlices;
use crate::cpu::has_avx2_fma;
use crate::surface::patch_tree::PatchTree;
use crate::surface::{BezierTriangle, GregoryPatch, GregoryTriangle, Patch, SurfacePoint, SurfaceSet};
use glam::{DVec2, DVec3};
use rayon::prelude::*;

/// Points evaluated together: 8 f32 lanes fill one AVX register (two SSE registers).
pub(crate) const LANES: usize = 8;

/// Below this squared sine of the angle between `∂S/∂u` and `∂S/∂v`, the f32 cross product
/// no longer gives the normal to about 1e-5, and the point is evaluated in f64.
pub(crate) const MIN_SIN2: f32 = 1e-4;

/// Below this squared length of `∂S/∂u` or `∂S/∂v` in the local frame (where the control
/// points lie within `[-1, 1]³`, so a derivative's f32 rounding is about 1e-6), the
/// derivative's direction is no longer good to 1e-5, and the point is evaluated in f64: near a
/// pole of the control net (teapot_teasetorig's lid) a derivative nearly vanishes while the
/// angle between the two stays wide.
pub(crate) const MIN_DERIVATIVE2: f32 = 0.04;

/// [`MIN_DERIVATIVE2`] for the leaves of Catmull-Clark trees ([`leaf_block`],
/// [`gregory_quad_block`]). Why lower: a leaf isolated next to a crease is often thin, its
/// derivative across it a tenth of the frame or less. With 0.04, one point in twenty of the
/// rook × 16 at 0.5 px (360,000 a frame, nearly all with `min(|S_u|², |S_v|²)` in
/// `[0.01, 0.04)`) fell to the f64 path, a search and an evaluation each. The f32 sums err
/// by about `3·10⁻⁷` of the frame, so a derivative of 0.1 keeps its direction to a few
/// `10⁻⁶`. Measured over every view of the rook and `catmark_cube_creases0` at a 41 × 41
/// grid (4.5 million normals, both builds), the worst normal was 4.8e-6 from the f64 one
/// with 0.04, 0.01 or 0.0025 alike. The bicubic patches keep 0.04, so that their outputs
/// stay byte for byte what they were.
pub(crate) const MIN_LEAF_DERIVATIVE2: f32 = 0.01;

/// Below this squared length of a PN triangle's quadratic normal field (whose coefficients are
/// unit vectors, so its f32 rounding is about 1e-7), the normalised f32 field is no longer good
/// to 1e-6, and the point is evaluated in f64.
const MIN_PN_NORMAL2: f32 = 0.01;

/// The local frame of a patch: `P = origin + scale · p` with `p` within `[-1, 1]³`, `scale` a
/// power of two (so dividing by it is exact).
pub(crate) fn local_frame(points: &[DVec3]) -> (DVec3, f64) {
    let (lo, hi) =
        points.iter().fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &q| (lo.min(q), hi.max(q)));
    ((lo + hi) * 0.5, power_of_two_above(((hi - lo) * 0.5).max_element()))
}

/// A power of two above `x` (and at most `2x`), kept well inside f32's range; 1 for 0.
pub(crate) fn power_of_two_above(x: f64) -> f64 {
    if x <= 0.0 || !x.is_finite() {
        return 1.0;
    }
    // 2^e ≤ x < 2^(e+1) for the unbiased exponent e of a normal x.
    let e = ((x.to_bits() >> 52) & 0x7ff) as i64 - 1023;
    f64::from_bits((((e + 1).clamp(-100, 100) + 1023) as u64) << 52)
}

/// `q` moved to the frame `(origin, scale)` and rounded to f32.
fn to_local(q: DVec3, origin: DVec3, scale: f64) -> [f32; 3] {
    ((q - origin) * (1.0 / scale)).as_vec3().to_array()
}

/// The exponents `(i, j, k)`, `i + j + k = d`, of the `N = (d + 1)(d + 2) / 2` monomials
/// `λ0^i λ1^j λ2^k` of degree `d`, in [`BezierTriangle::index`] order (`i`, then `j`,
/// descending), which is also [`crate::surface::QuarticTriangle::index`]'s.
const fn exponents<const N: usize>() -> [(usize, usize, usize); N] {
    let d = degree(N);
    let mut out = [(0, 0, 0); N];
    let (mut m, mut i) = (0, d + 1);
    while i > 0 {
        i -= 1;
        let mut j = d - i + 1;
        while j > 0 {
            j -= 1;
            out[m] = (i, j, d - i - j);
            m += 1;
        }
    }
    out
}

/// The degree of a Bézier triangle with `n` control points.
const fn degree(n: usize) -> usize {
    let mut d = 0;
    while (d + 1) * (d + 2) / 2 < n {
        d += 1;
    }
    assert!((d + 1) * (d + 2) / 2 == n, "not a triangular number of points");
    d
}

/// The PN normal field's monomials, in the order of [`crate::surface::PnTriangle::normals`]:
/// `λ0², λ1², λ2², λ0λ1, λ1λ2, λ0λ2`.
const PN_NORMAL: [(usize, usize, usize); 6] =
    [(2, 0, 0), (0, 2, 0), (0, 0, 2), (1, 1, 0), (0, 1, 1), (1, 0, 1)];

const fn factorial(n: usize) -> f64 {
    [1.0, 1.0, 2.0, 6.0, 24.0][n]
}

/// The storage index of `b_ijk` (`i + j + k = d`) in [`exponents`] order: the rule of
/// [`BezierTriangle::index`] at any degree.
const fn index(d: usize, i: usize, j: usize) -> usize {
    (d - i) * (d - i + 1) / 2 + (d - i - j)
}

/// `d!/(i!j!k!)` of each control point of degree `d`, in [`exponents`] order.
const fn multinomials<const N: usize>() -> [f64; N] {
    let e = exponents::<N>();
    let mut out = [0.0; N];
    let mut m = 0;
    while m < N {
        let (i, j, k) = e[m];
        out[m] = factorial(i + j + k) / (factorial(i) * factorial(j) * factorial(k));
        m += 1;
    }
    out
}

/// The derivatives' control points of a Bézier triangle of degree `d` (`N` points): for each
/// `(i, j, k)` of degree `d − 1` in [`exponents`] order, where `b_{i+1,j,k}`, `b_{i,j+1,k}`
/// and `b_{i,j,k+1}` stand in the net, and `d · (d−1)!/(i!j!k!)`, so that
/// `∂S/∂u = Σ c (b_{i,j+1,k} − b_{i+1,j,k}) λ0^i λ1^j λ2^k`, and `∂S/∂v` with `b_{i,j,k+1}`.
const fn differences<const N: usize, const M: usize>() -> [(usize, usize, usize, f64); M] {
    let d = degree(N);
    assert!(degree(M) + 1 == d, "the derivatives' degree is one less");
    let (e, c) = (exponents::<M>(), multinomials::<M>());
    let mut out = [(0, 0, 0, 0.0); M];
    let mut m = 0;
    while m < M {
        let (i, j, _) = e[m];
        out[m] = (index(d, i + 1, j), index(d, i, j + 1), index(d, i, j), d as f64 * c[m]);
        m += 1;
    }
    out
}

/// `(m, cu, cv)` for each monomial of the derivatives that an interior point enters
/// ([`point_differences`]).
type PointDifferences = [(usize, f64, f64); 3];

/// Where a lone control point `at` of a Bézier triangle of degree `d` (`N` points) enters
/// the derivatives: for each monomial `m` of degree `d − 1` ([`exponents`] order) that it
/// enters, `(m, cu, cv)` with `∂S/∂u = Σ cu · λ^m` and `∂S/∂v = Σ cv · λ^m` for that point at
/// 1 and the others at 0 ([`differences`] read backwards). An interior point enters three
/// monomials, which the precondition asks.
const fn point_differences<const N: usize, const M: usize>(at: usize) -> PointDifferences {
    let table = differences::<N, M>();
    let mut out = [(0, 0.0, 0.0); 3];
    let (mut m, mut n) = (0, 0);
    while m < M {
        let (base, at_u, at_v, c) = table[m];
        let minus = if base == at { c } else { 0.0 };
        let cu = if at_u == at { c } else { 0.0 } - minus;
        let cv = if at_v == at { c } else { 0.0 } - minus;
        if cu != 0.0 || cv != 0.0 {
            out[n] = (m, cu, cv);
            n += 1;
        }
        m += 1;
    }
    assert!(n == 3, "an interior point enters three monomials");
    out
}

/// Per corner of a Gregory triangle ([`GregoryTriangle::INTERIOR`]): where its interior point
/// stands in the quartic net, its multinomial `4!/(i!j!k!)`, and its [`point_differences`].
const fn gregory_interior() -> [(usize, f64, PointDifferences); 3] {
    let mut out = [(0, 0.0, [(0, 0.0, 0.0); 3]); 3];
    let mut c = 0;
    while c < 3 {
        let (_, _, (i, j, _)) = GregoryTriangle::INTERIOR[c];
        let at = index(4, i, j);
        out[c] = (at, multinomials::<15>()[at], point_differences::<15, 10>(at));
        c += 1;
    }
    out
}

/// A Bézier triangle of degree `d` (`N` control points; `M` those of degree `d − 1`: cubic
/// `<10, 6>`, quartic `<15, 10>`) in its local frame, with the multinomial coefficients folded
/// into the control points so that each sum is over bare monomials.
pub(crate) struct LocalTriangle<const N: usize = 10, const M: usize = 6> {
    origin: [f32; 3],
    scale: f32,
    /// `pos[c][m] = d!/(i!j!k!) · b_ijk`, component `c`, `m` in [`exponents`] order.
    pos: [[f32; N]; 3],
    /// `du[c][m] = d · (d−1)!/(i!j!k!) · (b_{i,j+1,k} − b_{i+1,j,k})`, `m` in [`exponents`]
    /// order of degree `d − 1`.
    du: [[f32; M]; 3],
    /// Likewise with `b_{i,j,k+1}`.
    dv: [[f32; M]; 3],
}

/// A quartic Bézier triangle in its local frame: Loop's regular pieces.
pub(crate) type LocalQuartic = LocalTriangle<15, 10>;

/// A PN triangle in its local frame: its cubic's positions as [`LocalTriangle`]'s, and its
/// quadratic normal field in place of the derivatives, which it never reads. 208 bytes
/// where the triangle's form with both took 356: a frame of many small patterns (the
/// killeroo herd: 91,476 forms, past the cache) reads each form in two passes.
pub(crate) struct LocalPn {
    origin: [f32; 3],
    scale: f32,
    /// As [`LocalTriangle`]'s.
    pos: [[f32; 10]; 3],
    /// The normal field's coefficients `[c][m]`, `m` in [`PN_NORMAL`] order.
    field: [[f32; 6]; 3],
}

/// A Gregory patch (Catmull-Clark's end caps, [`GregoryPatch`]) in its local frame, the
/// frame of all its 20 points: the bicubic net with each interior point its corner's `Fm`,
/// and each corner's `Fp − Fm`. A lane's blended net is that bicubic plus `w · (Fp − Fm)` at
/// each interior point, `w` the lane's rational weight of `Fp` (as
/// [`GregoryPatch::derivatives`] blends); the kernel is linear in the net, so it adds each
/// interior point's basis (and its derivatives, the blend held fixed as OpenSubdiv holds it)
/// times that, per lane ([`gregory_quad_block`]).
pub(crate) struct LocalGregoryQuad {
    net: LocalPatch,
    /// `(Fp − Fm) / scale` of each corner, rounded to f32: `[corner][component]`.
    spread: [[f32; 3]; 4],
}

/// Where each corner's blended point sits in a Gregory patch's bicubic net, `(i, j)` with `i`
/// along `u` (as [`GregoryPatch::bezier_net`] puts them).
const GREGORY_QUAD_INTERIOR: [(usize, usize); 4] = [(1, 1), (2, 1), (2, 2), (1, 2)];

impl LocalGregoryQuad {
    /// Cost: O(20), like [`LocalPatch::from_net`].
    #[inline(always)]
    pub(crate) fn new(g: &GregoryPatch) -> Self {
        let frame = local_frame(&g.points);
        // Corner `c`'s `Fp` and `Fm` are its points 3 and 4 (`crate::surface::gregory_patch`).
        let p = &g.points;
        let spread: [[f32; 3]; 4] =
            std::array::from_fn(|c| ((p[5 * c + 3] - p[5 * c + 4]) * (1.0 / frame.1)).as_vec3().to_array());
        LocalGregoryQuad { net: LocalPatch::in_frame(&g.minus_net(), frame, |_| 1.0), spread }
    }
}

/// A Gregory triangle (Loop's end caps, [`GregoryTriangle`]) in its local frame, the frame
/// of all its 18 points: the quartic net with each interior point its corner's `Fp`, and each
/// corner's `Fm − Fp`. The blended net of a lane is that quartic plus `g · (Fm − Fp)` at each
/// interior point, `g` the lane's weight of `Fm` ([`GregoryTriangle::blend_weights_of`]); the
/// kernel is linear in the net, so it adds each interior point's basis (and its derivatives,
/// the blend held fixed as OpenSubdiv holds it) times that, per lane ([`gregory_block`]).
pub(crate) struct LocalGregory {
    net: LocalQuartic,
    /// `(Fm − Fp) / scale` of each corner, rounded to f32: `[corner][component]`.
    spread: [[f32; 3]; 3],
}

impl LocalGregory {
    /// Cost: O(18), like [`LocalTriangle::from_net`].
    #[inline(always)]
    pub(crate) fn new(g: &GregoryTriangle) -> Self {
        let (origin, scale) = local_frame(&g.points);
        let net = LocalQuartic::in_frame(&g.blended_with([(1.0, 0.0); 3]).points, (origin, scale));
        let spread = GregoryTriangle::INTERIOR
            .map(|(fp, fm, _)| ((g.points[fm] - g.points[fp]) * (1.0 / scale)).as_vec3().to_array());
        LocalGregory { net, spread }
    }
}

impl<const N: usize, const M: usize> LocalTriangle<N, M> {
    /// The Bézier triangle of degree `d` with control points `net` in [`exponents`] order.
    /// Cost: O(N), every index and coefficient a constant. Inlined: the grouped leaves
    /// (`tree_points`) make one a group, in their caller's instructions, where it was a
    /// quarter of `loop_xord_interior`'s vertex time at factor 16 with the indices and
    /// coefficients computed.
    #[inline(always)]
    pub(crate) fn from_net(net: &[DVec3; N]) -> Self {
        Self::in_frame(net, local_frame(net))
    }

    /// [`LocalTriangle::from_net`] in the frame `(origin, scale)` ([`local_frame`] of the net,
    /// or of points around it).
    #[inline(always)]
    fn in_frame(net: &[DVec3; N], (origin, scale): (DVec3, f64)) -> Self {
        let inv = 1.0 / scale;
        let mut local = LocalTriangle {
            origin: origin.as_vec3().to_array(),
            scale: scale as f32,
            pos: [[0.0; N]; 3],
            du: [[0.0; M]; 3],
            dv: [[0.0; M]; 3],
        };
        let coefficients = const { multinomials::<N>() };
        for (m, (&q, &c)) in net.iter().zip(&coefficients).enumerate() {
            let q = to_local(q, origin, scale).map(|x| x * c as f32);
            (0..3).for_each(|a| local.pos[a][m] = q[a]);
        }
        for (m, &(at, at_u, at_v, c)) in const { differences::<N, M>() }.iter().enumerate() {
            let c = c * inv;
            // Differences in f64 before rounding: the derivative keeps its relative precision
            // where neighbouring control points nearly coincide.
            let du = ((net[at_u] - net[at]) * c).as_vec3().to_array();
            let dv = ((net[at_v] - net[at]) * c).as_vec3().to_array();
            for a in 0..3 {
                local.du[a][m] = du[a];
                local.dv[a][m] = dv[a];
            }
        }
        local
    }
}

impl LocalPn {
    /// The PN triangle of geometry `t` and normal field `normals`, its positions as
    /// [`LocalTriangle::from_net`] makes them. Cost: O(1).
    fn new(t: &BezierTriangle, normals: &[DVec3; 6]) -> LocalPn {
        let LocalTriangle { origin, scale, pos, .. } = LocalTriangle::<10, 6>::from_net(&t.points);
        let mut field = [[0.0; 6]; 3];
        for (m, n) in normals.iter().enumerate() {
            let n = n.as_vec3().to_array();
            (0..3).for_each(|a| field[a][m] = n[a]);
        }
        LocalPn { origin, scale, pos, field }
    }
}

/// Which form a patch was prepared in, and its index among the forms of that kind
/// ([`PointBlocks`]' vectors). Eight bytes, so that the per-patch table stays in cache and
/// each kind's forms lie densely in patch order: a frame's passes stream them.
#[derive(Clone, Copy)]
enum Local {
    Bicubic(u32),
    Rational(u32),
    Triangle(u32),
    Pn(u32),
    /// A regular Loop patch (one quartic piece).
    Quartic(u32),
    /// An irregular Loop patch: its tree's leaves start there in [`PointBlocks`]' `loop_leaves`.
    LoopTree(u32),
    /// A Catmull-Clark tree: the f32 forms of its first `coarse` leaves
    /// ([`super::tree_points::FORM_LEVEL`]) start at `first` in [`PointBlocks`]' `tree_forms`
    /// (shared by the views of one tree).
    CatmarkTree {
        first: u32,
        coarse: u8,
    },
    /// A rational bicubic whose weights span more than f32 carries
    /// ([`super::uniform_quads::MIN_WEIGHT_RATIO`]): the generic f64 evaluation.
    Generic,
}

/// A patch's local form, borrowed.
#[derive(Clone, Copy)]
enum FormRef<'a> {
    Bicubic(&'a LocalPatch),
    Rational(&'a LocalPatch<4>),
    Triangle(&'a LocalTriangle),
    Pn(&'a LocalPn),
    Quartic(&'a LocalQuartic),
}

/// A patch's local form while a set is prepared.
enum Form {
    Bicubic(LocalPatch),
    Rational(LocalPatch<4>),
    Triangle(LocalTriangle),
    Pn(LocalPn),
    Quartic(LocalQuartic),
    /// A Loop tree whose leaves' forms the set keeps (made after every patch's form, into
    /// their place in [`PointBlocks`]' vector).
    LoopTree,
    /// A Catmull-Clark tree (its coarse leaves' forms made after every patch's form).
    CatmarkTree,
    Generic,
}

/// A bicubic patch in the form the grid kernels take.
#[derive(Clone, Copy)]
pub(crate) enum GridPatch<'a> {
    Polynomial(&'a LocalPatch),
    Rational(&'a LocalPatch<4>),
}

/// Where a patch's local bicubic form lies among [`PointBlocks`]' forms.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct GridFormKey {
    pub rational: bool,
    pub index: u32,
}

/// Every patch of a set in its local frame, made once per set: a table of eight bytes a
/// patch and each kind's forms in patch order. Cost: O(P) to build, 200–400 bytes a patch
/// (an isolated Loop patch: 476 bytes a leaf of its tree).
pub(crate) struct PointBlocks {
    locals: Vec<Local>,
    bicubics: Vec<LocalPatch>,
    rationals: Vec<LocalPatch<4>>,
    triangles: Vec<LocalTriangle>,
    pns: Vec<LocalPn>,
    quartics: Vec<LocalQuartic>,
    /// Every leaf of each irregular Loop patch's tree, in its local frame, the trees in patch
    /// order: made once per set rather than once for every list of points that reaches a leaf
    /// (the interior's, each owned edge's).
    loop_leaves: Vec<LoopLeaf>,
    /// The coarse leaves of each Catmull-Clark tree in f32 ([`super::tree_points::coarse_form`]),
    /// once per tree, the trees in the order of their first view.
    tree_forms: Vec<CatmarkLeaf>,
    /// Every local is a bicubic with a local form ([`PointBlocks::all_bicubic`]), decided
    /// once: the locals are large, and a walk over them costs a frame a pass over memory.
    all_bicubic: bool,
    /// Some local is ([`PointBlocks::any_bicubic`]), decided once as `all_bicubic` is.
    any_bicubic: bool,
    /// Some patch is a Catmull-Clark tree ([`PointBlocks::evaluates_on_tree`]).
    any_tree: bool,
    /// Run the kernels compiled for AVX2 and FMA. Only ever true where the CPU has both:
    /// the `unsafe` calls below rely on it.
    avx2_fma: bool,
}

/// `L` points of one patch in structure-of-arrays form.
pub(crate) struct Block<const L: usize> {
    pub(crate) pos: [[f32; L]; 3],
    pub(crate) nrm: [[f32; L]; 3],
    /// Positive where the f32 normal is reliable; elsewhere (zero, negative or NaN) the point
    /// must be evaluated in f64.
    pub(crate) margin: [f32; L],
}

impl<const L: usize> Block<L> {
    /// Lane `l`'s position and normal where its f32 normal is reliable; else those of the
    /// generic f64 evaluation of patch `p` of `set` at `uv` (the lane's parameters).
    #[inline(always)]
    pub(crate) fn lane_or_exact(
        &self,
        l: usize,
        set: &SurfaceSet,
        p: usize,
        uv: DVec2,
    ) -> ([f32; 3], [f32; 3]) {
        if self.margin[l] > 0.0 {
            (
                [self.pos[0][l], self.pos[1][l], self.pos[2][l]],
                [self.nrm[0][l], self.nrm[1][l], self.nrm[2][l]],
            )
        } else {
            let q = exact(set, p, uv);
            (q.position.as_vec3().to_array(), q.normal.as_vec3().to_array())
        }
    }
}

/// `a · b + c`, fused in the kernels compiled for FMA (elsewhere `mul_add` would be a slow
/// library call). Fusing changes only the rounding.
#[inline(always)]
pub(crate) fn madd<const FMA: bool>(a: f32, b: f32, c: f32) -> f32 {
    if FMA {
        a.mul_add(b, c)
    } else {
        a * b + c
    }
}

/// Cubic Bernstein polynomials and their derivatives of each lane's `t`.
#[inline(always)]
fn bernstein_lanes<const L: usize>(t: &[f32; L]) -> ([[f32; L]; 4], [[f32; L]; 4]) {
    let mut b = [[0f32; L]; 4];
    let mut d = [[0f32; L]; 4];
    for l in 0..L {
        let (t, s) = (t[l], 1.0 - t[l]);
        b[0][l] = s * s * s;
        b[1][l] = 3.0 * t * s * s;
        b[2][l] = 3.0 * t * t * s;
        b[3][l] = t * t * t;
        d[0][l] = -3.0 * s * s;
        d[1][l] = 3.0 * s * (s - 2.0 * t);
        d[2][l] = 3.0 * t * (2.0 * s - t);
        d[3][l] = 3.0 * t * t;
    }
    (b, d)
}

/// Normals `a × c`, normalised, and the reliability margin of each lane ([`MIN_SIN2`],
/// [`MIN_DERIVATIVE2`]), for both evaluators.
#[inline(always)]
pub(crate) fn cross_normals<const L: usize>(
    a: &[[f32; L]; 3],
    c: &[[f32; L]; 3],
) -> ([[f32; L]; 3], [f32; L]) {
    cross_normals_above(a, c, MIN_DERIVATIVE2)
}

/// [`cross_normals`] with the shortest good derivative's square `min_derivative2`.
#[inline(always)]
fn cross_normals_above<const L: usize>(
    a: &[[f32; L]; 3],
    c: &[[f32; L]; 3],
    min_derivative2: f32,
) -> ([[f32; L]; 3], [f32; L]) {
    let ([ax, ay, az], [cx, cy, cz]) = (a, c);
    let mut nrm = [[0f32; L]; 3];
    let mut margin = [0f32; L];
    {
        let [nx, ny, nz] = &mut nrm;
        for l in 0..L {
            nx[l] = ay[l] * cz[l] - az[l] * cy[l];
            ny[l] = az[l] * cx[l] - ax[l] * cz[l];
            nz[l] = ax[l] * cy[l] - ay[l] * cx[l];
        }
    }
    let [nx, ny, nz] = &mut nrm;
    for l in 0..L {
        let n2 = nx[l] * nx[l] + ny[l] * ny[l] + nz[l] * nz[l];
        let a2 = ax[l] * ax[l] + ay[l] * ay[l] + az[l] * az[l];
        let c2 = cx[l] * cx[l] + cy[l] * cy[l] + cz[l] * cz[l];
        let long = a2 >= min_derivative2 && c2 >= min_derivative2;
        margin[l] = if long { n2 - MIN_SIN2 * (a2 * c2) } else { -1.0 };
        let inv = 1.0 / n2.sqrt();
        nx[l] *= inv;
        ny[l] *= inv;
        nz[l] *= inv;
    }
    (nrm, margin)
}

/// Moves local positions back to the model: `origin + scale · p`.
#[inline(always)]
pub(crate) fn to_model<const FMA: bool, const L: usize>(
    pos: &mut [[f32; L]; 3],
    origin: &[f32; 3],
    scale: f32,
) {
    for (row, &origin) in pos.iter_mut().zip(origin) {
        for x in row {
            *x = madd::<FMA>(scale, *x, origin);
        }
    }
}

/// The tensor-product sums of each lane's `(u, v)` over the control points `by_v` (see
/// [`LocalPatch`]): per component, the value and its `u` and `v` derivatives.
// Index loops mirror the sums over control points (and vectorize over lanes).
#[allow(clippy::needless_range_loop)]
#[inline(always)]
fn tensor_sums<const FMA: bool, const L: usize, const C: usize>(
    by_v: &[[[f32; 4]; 4]; C],
    u: &[f32; L],
    v: &[f32; L],
) -> [[[f32; L]; C]; 3] {
    let (bu, du) = bernstein_lanes(u);
    let (bv, dv) = bernstein_lanes(v);
    let mut pos = [[0f32; L]; C];
    let mut su = [[0f32; L]; C];
    let mut sv = [[0f32; L]; C];
    for c in 0..C {
        for i in 0..4 {
            // The curve of constant u's control point i and its v-derivative's, per lane.
            let mut ci = [0f32; L];
            let mut di = [0f32; L];
            for j in 0..4 {
                let q = by_v[c][j][i];
                for l in 0..L {
                    ci[l] = madd::<FMA>(bv[j][l], q, ci[l]);
                    di[l] = madd::<FMA>(dv[j][l], q, di[l]);
                }
            }
            for l in 0..L {
                pos[c][l] = madd::<FMA>(bu[i][l], ci[l], pos[c][l]);
                su[c][l] = madd::<FMA>(du[i][l], ci[l], su[c][l]);
                sv[c][l] = madd::<FMA>(bu[i][l], di[l], sv[c][l]);
            }
        }
    }
    [pos, su, sv]
}

/// A polynomial bicubic at each lane's `(u, v)`.
#[inline(always)]
pub(crate) fn bicubic_block<const FMA: bool, const L: usize>(
    patch: &LocalPatch,
    u: &[f32; L],
    v: &[f32; L],
) -> Block<L> {
    bicubic_block_above::<FMA, L>(patch, u, v, MIN_DERIVATIVE2)
}

/// A bicubic leaf of a Catmull-Clark tree at each lane's `(u, v)` ([`MIN_LEAF_DERIVATIVE2`]).
#[inline(always)]
pub(crate) fn leaf_block<const FMA: bool, const L: usize>(
    patch: &LocalPatch,
    u: &[f32; L],
    v: &[f32; L],
) -> Block<L> {
    bicubic_block_above::<FMA, L>(patch, u, v, MIN_LEAF_DERIVATIVE2)
}

/// [`bicubic_block`] with the shortest good derivative's square `min_derivative2`.
#[inline(always)]
fn bicubic_block_above<const FMA: bool, const L: usize>(
    patch: &LocalPatch,
    u: &[f32; L],
    v: &[f32; L],
    min_derivative2: f32,
) -> Block<L> {
    let [mut pos, su, sv] = tensor_sums::<FMA, L, 3>(&patch.by_v, u, v);
    let (nrm, margin) = cross_normals_above(&su, &sv, min_derivative2);
    to_model::<FMA, L>(&mut pos, &patch.origin, patch.scale);
    Block { pos, nrm, margin }
}

/// A rational surface's position `S = H / W` and its derivatives multiplied by the weight,
/// `W·S_u = H_u − W_u·S` and `W·S_v = H_v − W_v·S`, of each lane, from the homogeneous
/// sums `h = (H, W)` and their derivatives `hu`, `hv` (weights scaled so that the largest is
/// 1, as [`LocalPatch::rational`] stores them).
///
/// Why this form of the quotient rule: `W > 0`, so `W·S_u × W·S_v` points along the normal
/// `S_u × S_v`, and needs no division beyond the one reciprocal the position takes, and three
/// multiply-adds per derivative. The textbook `(H_u W − H W_u) / W²` needs a second division
/// (or, left undivided, scales with `W²`, so that a small weight would sink a derivative's
/// square toward f32's underflow); the homogeneous cross-product form
/// `W (H_u × H_v) − W_v (H_u × H) − W_u (H × H_v)` takes three cross products.
///
/// Why the polynomial reliability rule ([`cross_normals`]) holds for it unchanged: each f32 sum
/// errs by a few units of 1 (the control points lie within `[-1, 1]³` and the weights within
/// `(0, 1]`), whatever the weights, so `W·S_u` errs by a bounded *absolute* amount, as a
/// polynomial `S_u` does; a direction is then good where `|W·S_u|² ≥ MIN_DERIVATIVE2` and the
/// angle is wide. A weight tiny relative to the others needs no rule of its own at a point:
/// where it dominates, `W` is small and so is `W·S_u` (unless the surface moves fast there,
/// which is as precise), and the point falls back to f64. (A patch whose weights span more
/// than [`super::uniform_quads::MIN_WEIGHT_RATIO`] keeps f64 throughout, for a reason of its
/// own given there.)
#[inline(always)]
pub(crate) fn rational_quotient<const FMA: bool, const L: usize>(
    h: &[[f32; L]; 4],
    hu: &[[f32; L]; 4],
    hv: &[[f32; L]; 4],
) -> [[[f32; L]; 3]; 3] {
    let mut pos = [[0f32; L]; 3];
    let mut su = [[0f32; L]; 3];
    let mut sv = [[0f32; L]; 3];
    let mut inv = [0f32; L];
    for l in 0..L {
        inv[l] = 1.0 / h[3][l];
    }
    for c in 0..3 {
        for l in 0..L {
            let p = h[c][l] * inv[l];
            pos[c][l] = p;
            su[c][l] = madd::<FMA>(-hu[3][l], p, hu[c][l]);
            sv[c][l] = madd::<FMA>(-hv[3][l], p, hv[c][l]);
        }
    }
    [pos, su, sv]
}

/// A rational bicubic at each lane's `(u, v)`.
#[inline(always)]
fn rational_block<const FMA: bool, const L: usize>(
    patch: &LocalPatch<4>,
    u: &[f32; L],
    v: &[f32; L],
) -> Block<L> {
    let [h, hu, hv] = tensor_sums::<FMA, L, 4>(&patch.by_v, u, v);
    let [mut pos, su, sv] = rational_quotient::<FMA, L>(&h, &hu, &hv);
    let (nrm, margin) = cross_normals(&su, &sv);
    to_model::<FMA, L>(&mut pos, &patch.origin, patch.scale);
    Block { pos, nrm, margin }
}

/// The monomials `λ0^i λ1^j λ2^k` of each lane for the exponents `table`.
#[inline(always)]
fn monomials<const L: usize, const M: usize>(
    powers: &[[[f32; L]; 5]; 3],
    table: &[(usize, usize, usize); M],
) -> [[f32; L]; M] {
    let mut out = [[0f32; L]; M];
    for (m, &(i, j, k)) in table.iter().enumerate() {
        for l in 0..L {
            out[m][l] = powers[0][i][l] * powers[1][j][l] * powers[2][k][l];
        }
    }
    out
}

/// `Σ_m coefficients[c][m] · basis[m]` per component and lane.
#[inline(always)]
fn combine<const FMA: bool, const L: usize, const M: usize>(
    coefficients: &[[f32; M]; 3],
    basis: &[[f32; L]; M],
) -> [[f32; L]; 3] {
    let mut out = [[0f32; L]; 3];
    for (c, row) in out.iter_mut().enumerate() {
        for (m, b) in basis.iter().enumerate() {
            let q = coefficients[c][m];
            for l in 0..L {
                row[l] = madd::<FMA>(b[l], q, row[l]);
            }
        }
    }
    out
}

/// `powers[a][e][l] = λa^e` of lane `l`, `λ = (1 − u − v, u, v)`, for `e` up to `d` (≤ 4).
#[inline(always)]
fn lambda_powers<const L: usize>(d: usize, u: &[f32; L], v: &[f32; L]) -> [[[f32; L]; 5]; 3] {
    let mut powers = [[[1f32; L]; 5]; 3];
    for l in 0..L {
        let lambda = [1.0 - u[l] - v[l], u[l], v[l]];
        for a in 0..3 {
            let x = lambda[a];
            for e in 1..=d {
                powers[a][e][l] = powers[a][e - 1][l] * x;
            }
        }
    }
    powers
}

/// A Bézier triangle's `∂S/∂u` and `∂S/∂v` (local frame) of each lane, from its
/// [`lambda_powers`].
#[inline(always)]
fn derivative_sums<const FMA: bool, const L: usize, const N: usize, const M: usize>(
    t: &LocalTriangle<N, M>,
    powers: &[[[f32; L]; 5]; 3],
) -> [[[f32; L]; 3]; 2] {
    let lower = monomials(powers, &const { exponents::<M>() });
    [combine::<FMA, L, M>(&t.du, &lower), combine::<FMA, L, M>(&t.dv, &lower)]
}

/// A Gregory patch at each lane's `(u, v)` ([`LocalGregoryQuad`]): the bicubic kernel's sums
/// of the net with the `Fm`s, plus each corner's interior basis times the lane's blend weight
/// of `Fp` times `Fp − Fm`; normal and reliability as a bicubic leaf's ([`leaf_block`]).
// Index loops over lanes (they vectorize).
#[allow(clippy::needless_range_loop)]
#[inline(always)]
pub(crate) fn gregory_quad_block<const FMA: bool, const L: usize>(
    g: &LocalGregoryQuad,
    u: &[f32; L],
    v: &[f32; L],
) -> Block<L> {
    let [mut pos, mut su, mut sv] = tensor_sums::<FMA, L, 3>(&g.net.by_v, u, v);
    let (bu, du) = bernstein_lanes(u);
    let (bv, dv) = bernstein_lanes(v);
    for l in 0..L {
        let (x, y) = (u[l], v[l]);
        let (xc, yc) = (1.0 - x, 1.0 - y);
        // `GregoryPatch::bezier_net`'s weights, 0 at a corner itself.
        let ratio = |a: f32, d: f32| if d <= 0.0 { a } else { a / d };
        let w = [ratio(x, x + y), ratio(y, xc + y), ratio(xc, xc + yc), ratio(yc, x + yc)];
        for (c, (i, j)) in GREGORY_QUAD_INTERIOR.into_iter().enumerate() {
            let (b, bdu, bdv) = (bu[i][l] * bv[j][l], du[i][l] * bv[j][l], bu[i][l] * dv[j][l]);
            for a in 0..3 {
                let d = w[c] * g.spread[c][a];
                pos[a][l] = madd::<FMA>(b, d, pos[a][l]);
                su[a][l] = madd::<FMA>(bdu, d, su[a][l]);
                sv[a][l] = madd::<FMA>(bdv, d, sv[a][l]);
            }
        }
    }
    let (nrm, margin) = cross_normals_above(&su, &sv, MIN_LEAF_DERIVATIVE2);
    to_model::<FMA, L>(&mut pos, &g.net.origin, g.net.scale);
    Block { pos, nrm, margin }
}

/// A Gregory triangle at each lane's `(u, v)` ([`LocalGregory`]): the quartic kernel's sums
/// of the net with the `Fp`s, plus each corner's interior basis times the lane's blend
/// weight of `Fm` times `Fm − Fp`; normal and reliability as every triangle's.
// Index loops over lanes (they vectorize).
#[allow(clippy::needless_range_loop)]
#[inline(always)]
pub(crate) fn gregory_block<const FMA: bool, const L: usize>(
    g: &LocalGregory,
    u: &[f32; L],
    v: &[f32; L],
) -> Block<L> {
    let powers = lambda_powers::<L>(4, u, v);
    let basis = monomials(&powers, &const { exponents::<15>() });
    let mut pos = combine::<FMA, L, 15>(&g.net.pos, &basis);
    let [mut su, mut sv] = derivative_sums::<FMA, L, 15, 10>(&g.net, &powers);
    let lower = monomials(&powers, &const { exponents::<10>() });
    let mut weights = [[0f32; L]; 3];
    for l in 0..L {
        let w = GregoryTriangle::blend_weights_of(u[l], v[l]);
        (0..3).for_each(|c| weights[c][l] = w[c].1);
    }
    for (c, &(at, coefficient, enters)) in const { gregory_interior() }.iter().enumerate() {
        for l in 0..L {
            let g_l = weights[c][l];
            let b = coefficient as f32 * basis[at][l] * g_l;
            let (mut bu, mut bv) = (0f32, 0f32);
            for &(m, cu, cv) in &enters {
                bu = madd::<FMA>(cu as f32, lower[m][l], bu);
                bv = madd::<FMA>(cv as f32, lower[m][l], bv);
            }
            let (bu, bv) = (bu * g_l, bv * g_l);
            for a in 0..3 {
                let d = g.spread[c][a];
                pos[a][l] = madd::<FMA>(b, d, pos[a][l]);
                su[a][l] = madd::<FMA>(bu, d, su[a][l]);
                sv[a][l] = madd::<FMA>(bv, d, sv[a][l]);
            }
        }
    }
    let (nrm, margin) = cross_normals(&su, &sv);
    to_model::<FMA, L>(&mut pos, &g.net.origin, g.net.scale);
    Block { pos, nrm, margin }
}

/// A Bézier triangle (cubic, quartic) at each lane's `(u, v)`: normals from the derivatives.
#[inline(always)]
pub(crate) fn triangle_block<const FMA: bool, const L: usize, const N: usize, const M: usize>(
    t: &LocalTriangle<N, M>,
    u: &[f32; L],
    v: &[f32; L],
) -> Block<L> {
    let (mut pos, powers) = triangle_positions::<FMA, L, N>(&t.pos, u, v);
    let [su, sv] = derivative_sums::<FMA, L, N, M>(t, &powers);
    let (nrm, margin) = cross_normals(&su, &sv);
    to_model::<FMA, L>(&mut pos, &t.origin, t.scale);
    Block { pos, nrm, margin }
}

/// A PN triangle at each lane's `(u, v)`: normals from its quadratic field, normalised.
#[inline(always)]
pub(crate) fn pn_block<const FMA: bool, const L: usize>(t: &LocalPn, u: &[f32; L], v: &[f32; L]) -> Block<L> {
    let (mut pos, powers) = triangle_positions::<FMA, L, 10>(&t.pos, u, v);
    let mut nrm = combine::<FMA, L, 6>(&t.field, &monomials(&powers, &PN_NORMAL));
    let mut margin = [0f32; L];
    let [nx, ny, nz] = &mut nrm;
    for l in 0..L {
        let n2 = nx[l] * nx[l] + ny[l] * ny[l] + nz[l] * nz[l];
        margin[l] = n2 - MIN_PN_NORMAL2;
        let inv = 1.0 / n2.sqrt();
        nx[l] *= inv;
        ny[l] *= inv;
        nz[l] *= inv;
    }
    to_model::<FMA, L>(&mut pos, &t.origin, t.scale);
    Block { pos, nrm, margin }
}

/// The local positions of a triangle form of `N` control points `pos` at each lane's
/// `(u, v)`, from the monomials of the lanes' [`lambda_powers`], and those powers (for the
/// normals): the rule [`triangle_block`] and [`pn_block`] share. (Not a function taking the
/// normals as a closure: a closure is compiled for the AVX2 and FMA of its caller only where
/// it is inlined, and on Loop's trees it was not, making every `mul_add` a library call.)
#[inline(always)]
fn triangle_positions<const FMA: bool, const L: usize, const N: usize>(
    pos: &[[f32; N]; 3],
    u: &[f32; L],
    v: &[f32; L],
) -> ([[f32; L]; 3], [[[f32; L]; 5]; 3]) {
    let powers = lambda_powers::<L>(const { degree(N) }, u, v);
    (combine::<FMA, L, N>(pos, &monomials(&powers, &const { exponents::<N>() })), powers)
}

/// The most memory [`PointBlocks`] gives the leaf forms of Loop's trees (1 GiB: 2.2 million
/// leaves, an all-isolated cage of some 170,000 triangles). A set whose forms would take more
/// keeps none: a group of points then makes its leaf's form, as Catmull-Clark's trees do
/// ([`super::tree_points::eval`] without stored forms; one or two points of a leaf in f64), so
/// the set costs its trees alone, and its vertex stage 1.6–1.8× more time (`loop_xord_interior`
/// × 200, one thread, with this at 0). A constant, not a share of the memory available, so
/// that a set's output does not depend on the machine.
const LOOP_FORMS_BUDGET: usize = 1 << 30;

impl PointBlocks {
    /// Every patch of `set` in its local frame. Cost: O(P), parallel.
    pub(crate) fn for_set(set: &SurfaceSet, avx2_fma: bool) -> PointBlocks {
        Self::for_set_within(set, avx2_fma, LOOP_FORMS_BUDGET)
    }

    /// [`PointBlocks::for_set`] with `loop_budget` bytes for Loop's leaf forms
    /// ([`LOOP_FORMS_BUDGET`]).
    pub(super) fn for_set_within(set: &SurfaceSet, avx2_fma: bool, loop_budget: usize) -> PointBlocks {
        let tree_leaves: usize = set
            .patches
            .iter()
            .map(|p| match p {
                Patch::Loop(t) if t.regular().is_none() => t.leaves().len(),
                _ => 0,
            })
            .sum();
        let store_loop_leaves = tree_leaves.saturating_mul(std::mem::size_of::<LoopLeaf>()) <= loop_budget;
        let forms = set
            .patches
            .par_iter()
            .with_min_len(64)
            .map(|p| match p {
                Patch::Bicubic(b) if b.is_polynomial() => Form::Bicubic(LocalPatch::new(b)),
                Patch::Bicubic(b) => LocalPatch::rational(b).map_or(Form::Generic, Form::Rational),
                Patch::BezierTriangle(t) => Form::Triangle(LocalTriangle::from_net(&t.points)),
                Patch::Pn(t) => Form::Pn(LocalPn::new(&t.geometry, &t.normals)),
                // A regular Loop triangle is one quartic piece, in the patch's parameters.
                Patch::Loop(t) => match t.regular_net() {
                    Some(q) => Form::Quartic(LocalQuartic::from_net(&q.points)),
                    None if store_loop_leaves => Form::LoopTree,
                    None => Form::Generic,
                },
                // Piecewise (isolated) patches: their points one by one, their coarse leaves'
                // in f32, or grouped by leaf (`tree_points`).
                Patch::Subdivision(_) => Form::CatmarkTree,
            })
            .collect::<Vec<_>>();
        let mut blocks = PointBlocks {
            locals: Vec::with_capacity(forms.len()),
            bicubics: Vec::new(),
            rationals: Vec::new(),
            triangles: Vec::new(),
            pns: Vec::new(),
            quartics: Vec::new(),
            loop_leaves: Vec::new(),
            tree_forms: Vec::new(),
            all_bicubic: false,
            any_bicubic: false,
            any_tree: set.patches.iter().any(|p| matches!(p, Patch::Subdivision(_))),
            avx2_fma: avx2_fma && has_avx2_fma(),
        };
        // Each stored tree's first leaf and patch, in patch order.
        let (mut trees, mut stored) = (Vec::new(), 0usize);
        // Each Catmull-Clark tree's first form and first view, in order; where each tree's
        // forms start, by the tree's identity.
        let (mut catmark, mut forms_made) = (Vec::new(), 0usize);
        let mut catmark_first = std::collections::HashMap::new();
        for (p, form) in forms.into_iter().enumerate() {
            let local = match form {
                Form::Bicubic(b) => Local::Bicubic(push(&mut blocks.bicubics, b)),
                Form::Rational(r) => Local::Rational(push(&mut blocks.rationals, r)),
                Form::Triangle(t) => Local::Triangle(push(&mut blocks.triangles, t)),
                Form::Pn(t) => Local::Pn(push(&mut blocks.pns, t)),
                Form::Quartic(t) => Local::Quartic(push(&mut blocks.quartics, t)),
                Form::LoopTree => {
                    let Patch::Loop(tree) = &set.patches[p] else { unreachable!("a Loop patch's form") };
                    trees.push((stored, p));
                    let first = stored as u32;
                    stored += tree.leaves().len();
                    Local::LoopTree(first)
                }
                Form::CatmarkTree => {
                    let Patch::Subdivision(tree) = &set.patches[p] else { unreachable!("a tree's form") };
                    let coarse = tree.coarse_leaves(FORM_LEVEL);
                    let first = *catmark_first.entry(tree.leaves_id()).or_insert_with(|| {
                        catmark.push((forms_made, p));
                        forms_made += coarse;
                        forms_made - coarse
                    });
                    let coarse = u8::try_from(coarse).expect("at most 64 leaves of levels ≤ 3 tile a square");
                    Local::CatmarkTree { first: first as u32, coarse }
                }
                Form::Generic => Local::Generic,
            };
            blocks.locals.push(local);
        }
        blocks.loop_leaves = leaf_forms(stored, &trees, |p, leaf| {
            let Patch::Loop(tree) = &set.patches[p] else { unreachable!("a Loop patch's form") };
            loop_leaf(tree, leaf)
        });
        blocks.tree_forms = leaf_forms(forms_made, &catmark, |p, leaf| {
            let Patch::Subdivision(tree) = &set.patches[p] else { unreachable!("a tree's form") };
            catmark_leaf(tree, leaf)
        });
        let grid_form = |l: &Local| matches!(l, Local::Bicubic(_) | Local::Rational(_));
        blocks.all_bicubic = blocks.locals.iter().all(grid_form);
        blocks.any_bicubic = blocks.locals.iter().any(grid_form);
        blocks
    }

    /// How many Loop leaf forms the set keeps ([`LOOP_FORMS_BUDGET`]).
    #[cfg(test)]
    pub(super) fn stored_loop_leaves(&self) -> usize {
        self.loop_leaves.len()
    }

    /// Patch `p`'s local bicubic form, where it is a bicubic that has one.
    pub(crate) fn grid_patch(&self, p: usize) -> Option<GridPatch<'_>> {
        match self.form(p)? {
            FormRef::Bicubic(local) => Some(GridPatch::Polynomial(local)),
            FormRef::Rational(local) => Some(GridPatch::Rational(local)),
            FormRef::Triangle(_) | FormRef::Pn(_) | FormRef::Quartic(_) => None,
        }
    }

    /// Where patch `p`'s local bicubic form lies, where it is a bicubic that has one: a key
    /// for [`PointBlocks::grid_form`], which reads the form without asking the per-patch
    /// table again.
    pub(crate) fn grid_form_key(&self, p: usize) -> Option<GridFormKey> {
        match self.locals[p] {
            Local::Bicubic(i) => Some(GridFormKey { rational: false, index: i }),
            Local::Rational(i) => Some(GridFormKey { rational: true, index: i }),
            _ => None,
        }
    }

    /// The local bicubic form at `key` ([`PointBlocks::grid_form_key`]).
    #[inline(always)]
    pub(crate) fn grid_form(&self, key: GridFormKey) -> GridPatch<'_> {
        match key.rational {
            false => GridPatch::Polynomial(&self.bicubics[key.index as usize]),
            true => GridPatch::Rational(&self.rationals[key.index as usize]),
        }
    }

    /// Patch `p`'s local form; None for a patch on the generic evaluation.
    fn form(&self, p: usize) -> Option<FormRef<'_>> {
        Some(match self.locals[p] {
            Local::Bicubic(i) => FormRef::Bicubic(&self.bicubics[i as usize]),
            Local::Rational(i) => FormRef::Rational(&self.rationals[i as usize]),
            Local::Triangle(i) => FormRef::Triangle(&self.triangles[i as usize]),
            Local::Pn(i) => FormRef::Pn(&self.pns[i as usize]),
            Local::Quartic(i) => FormRef::Quartic(&self.quartics[i as usize]),
            Local::LoopTree(_) | Local::CatmarkTree { .. } | Local::Generic => return None,
        })
    }

    /// Asks for patch `p`'s form to be brought into the cache, a few patches before it is
    /// evaluated: a hint, which changes no value. Only a cubic triangle's form (PN, Bézier;
    /// Loop's quartics measured no different with it): a bicubic's points come from the
    /// grid kernels' own forms, and on the torus grid asking for its form here made the
    /// vertex stage 14 % slower. Nothing where `p` is out of range or has no such form.
    /// Cost: O(1), up to five prefetches (a cubic Bézier triangle's form is 280 bytes, a PN
    /// triangle's 208).
    #[inline(always)]
    pub(crate) fn prefetch_form(&self, p: usize) {
        use crate::surface::patch_tree::prefetch_slice;
        if self.triangles.is_empty() && self.pns.is_empty() {
            return;
        }
        match self.locals.get(p) {
            Some(Local::Pn(i)) => prefetch_slice(std::slice::from_ref(&self.pns[*i as usize])),
            Some(Local::Triangle(i)) => prefetch_slice(std::slice::from_ref(&self.triangles[*i as usize])),
            _ => {}
        }
    }

    /// Whether patch `p` is evaluated in blocks of lanes, each lane on its own (so a point's
    /// value does not depend on the points evaluated with it): every form but the generic
    /// evaluation and the subdivision trees, whose points are grouped by leaf.
    pub(crate) fn evaluates_in_blocks(&self, p: usize) -> bool {
        self.form(p).is_some()
    }

    /// Whether every patch is a bicubic with a local form, polynomial or rational (where the
    /// grid evaluator also takes the corners).
    pub(crate) fn all_bicubic(&self) -> bool {
        self.all_bicubic
    }

    /// Whether some patch is a bicubic with a local form (the grid kernels can serve it).
    pub(crate) fn any_bicubic(&self) -> bool {
        self.any_bicubic
    }

    /// Evaluates patch `p` of `set` at `uvs` into `out` (one vertex each: position, normal,
    /// parameters as f32, patch id), as [`VertexSlices::set`] does point by point.
    /// Preconditions: `out` holds `uvs.len()` vertices; `self` was made for `set`. Cost: about
    /// a tenth of the generic evaluation per point (less for PN triangles), no allocation.
    pub(crate) fn eval(&self, set: &SurfaceSet, p: usize, uvs: &[DVec2], out: VertexSlices<'_>) {
        self.eval_grid(set, p, uvs, None, out)
    }

    /// [`PointBlocks::eval`] where `uvs` may be the interior points of a `grid`
    /// ([`crate::pattern::core_grid::grid_interior`]'s order): a Catmull-Clark tree then finds
    /// its leaves' points by walking its quadtree with the grid
    /// ([`crate::surface::PatchTree::grid_leaves`]). The same values as `eval`.
    /// Preconditions: `eval`'s, and with `grid`, `uvs` is that grid's interior.
    pub(crate) fn eval_grid(
        &self,
        set: &SurfaceSet,
        p: usize,
        uvs: &[DVec2],
        grid: Option<[u32; 2]>,
        out: VertexSlices<'_>,
    ) {
        if self.avx2_fma {
            #[cfg(target_arch = "x86_64")]
            // SAFETY: `avx2_fma` is only set where the CPU has AVX2 and FMA (`PointBlocks::for_set`).
            return unsafe { self.eval_avx2_fma(set, p, uvs, grid, out) };
        }
        self.eval_with::<false>(set, p, uvs, grid, out)
    }

    /// Whether some patch is a Catmull-Clark tree.
    pub(crate) fn any_tree(&self) -> bool {
        self.any_tree
    }

    /// Whether [`PointBlocks::eval`] takes `points` points of patch `p` of `set` one by one on
    /// its subdivision tree ([`super::tree_points::eval_sparse`]): a Catmull-Clark tree too
    /// sparse for [`super::tree_points::eval`]'s groups. Such points may be evaluated in a stream
    /// with other patches' ([`PointBlocks::eval_tree_stream`]), with the same values.
    /// Cost: O(1).
    pub(crate) fn evaluates_on_tree(&self, set: &SurfaceSet, p: usize, points: usize) -> bool {
        if !self.any_tree {
            return false;
        }
        match (&set.patches[p], self.locals[p]) {
            (Patch::Subdivision(tree), Local::CatmarkTree { .. }) => {
                !super::tree_points::worth_grouping(&**tree, points)
            }
            _ => false,
        }
    }

    /// Evaluates a stream of points on several patches, `items[k] = (patch, uv)`, into `out`
    /// (vertex `k` each), with the values [`PointBlocks::eval`] gives each patch's points.
    /// Why: the engine's edges have a few points each, each edge on its owner's tree, and
    /// evaluated edge by edge every edge started with none of its leaves' loads in flight
    /// ([`super::tree_points::eval_sparse`] looks ahead across them).
    /// Preconditions: every patch [`PointBlocks::evaluates_on_tree`] for its points (each
    /// edge's count); `out` holds `items.len()` vertices. Cost: as many points of
    /// [`super::tree_points::eval_sparse`], no allocation.
    pub(crate) fn eval_tree_stream(&self, set: &SurfaceSet, items: &[(u32, DVec2)], out: VertexSlices<'_>) {
        if self.avx2_fma {
            #[cfg(target_arch = "x86_64")]
            // SAFETY: `avx2_fma` is only set where the CPU has AVX2 and FMA (`PointBlocks::for_set`).
            return unsafe { self.eval_tree_stream_avx2_fma(set, items, out) };
        }
        self.eval_tree_stream_with::<false>(set, items, out)
    }

    /// [`PointBlocks::eval_tree_stream_with`] compiled for AVX2 and FMA.
    ///
    /// # Safety
    /// The CPU must support AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn eval_tree_stream_avx2_fma(
        &self,
        set: &SurfaceSet,
        items: &[(u32, DVec2)],
        out: VertexSlices<'_>,
    ) {
        self.eval_tree_stream_with::<true>(set, items, out)
    }

    #[inline(always)]
    fn eval_tree_stream_with<const FMA: bool>(
        &self,
        set: &SurfaceSet,
        items: &[(u32, DVec2)],
        out: VertexSlices<'_>,
    ) {
        eval_sparse::<FMA>(
            set,
            items.len(),
            |k| {
                let (p, uv) = items[k];
                let (tree, forms) = self.tree(set, p as usize);
                (p, tree, forms, uv)
            },
            out,
        )
    }

    /// Patch `p`'s Catmull-Clark tree and its coarse leaves' forms ([`eval_sparse`]).
    /// Precondition: `p` is a Catmull-Clark tree.
    #[inline(always)]
    fn tree<'s>(&'s self, set: &'s SurfaceSet, p: usize) -> (&'s PatchTree, &'s [CatmarkLeaf]) {
        match (&set.patches[p], self.locals[p]) {
            (Patch::Subdivision(tree), Local::CatmarkTree { first, coarse }) => {
                let first = first as usize;
                (&**tree, &self.tree_forms[first..first + usize::from(coarse)])
            }
            _ => unreachable!("the precondition: a Catmull-Clark tree"),
        }
    }

    /// [`PointBlocks::eval_with`] compiled for AVX2 and FMA (everything it calls is inlined).
    ///
    /// # Safety
    /// The CPU must support AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn eval_avx2_fma(
        &self,
        set: &SurfaceSet,
        p: usize,
        uvs: &[DVec2],
        grid: Option<[u32; 2]>,
        out: VertexSlices<'_>,
    ) {
        self.eval_with::<true>(set, p, uvs, grid, out)
    }

    #[inline(always)]
    fn eval_with<const FMA: bool>(
        &self,
        set: &SurfaceSet,
        p: usize,
        uvs: &[DVec2],
        grid: Option<[u32; 2]>,
        out: VertexSlices<'_>,
    ) {
        if let Local::Generic | Local::LoopTree(_) | Local::CatmarkTree { .. } = self.locals[p] {
            use super::tree_points::{eval as grouped, worth_grouping};
            match (&set.patches[p], self.locals[p]) {
                (Patch::Subdivision(tree), _) if worth_grouping(&**tree, uvs.len()) => {
                    let (tree, forms) = self.tree(set, p);
                    return grouped::<FMA, _>(set, p, tree, Some(forms), uvs, grid, out);
                }
                (Patch::Subdivision(_), _) => {
                    let (tree, forms) = self.tree(set, p);
                    return eval_sparse::<FMA>(set, uvs.len(), |k| (p as u32, tree, forms, uvs[k]), out);
                }
                (Patch::Loop(tree), Local::LoopTree(first)) if worth_grouping(&**tree, uvs.len()) => {
                    let first = first as usize;
                    let leaves = &self.loop_leaves[first..first + tree.leaves().len()];
                    return grouped::<FMA, _>(set, p, &**tree, Some(leaves), uvs, grid, out);
                }
                // A set past the budget for stored forms (`LOOP_FORMS_BUDGET`).
                (Patch::Loop(tree), Local::Generic) if worth_grouping(&**tree, uvs.len()) => {
                    return grouped::<FMA, _>(set, p, &**tree, None, uvs, grid, out);
                }
                _ => {}
            }
        }
        if matches!(self.locals[p], Local::Generic | Local::LoopTree(_)) {
            // In f64 as the generic evaluation, compiled here for the wider instructions
            // (Rust never fuses a multiply and an add by itself, so the values are the same).
            let mut out = out;
            set.patches[p].eval_each(uvs, |k, point| out.put(k, p as u32, uvs[k], point));
            return;
        }
        // Short lists (the inner samples of a coarse edge, a small interior) in half-width
        // blocks, so that fewer lanes are spent on padding.
        if uvs.len() <= LANES / 2 {
            self.blocks::<FMA, { LANES / 2 }>(set, p, uvs, out)
        } else {
            self.blocks::<FMA, LANES>(set, p, uvs, out)
        }
    }

    #[inline(always)]
    fn blocks<const FMA: bool, const L: usize>(
        &self,
        set: &SurfaceSet,
        p: usize,
        uvs: &[DVec2],
        out: VertexSlices<'_>,
    ) {
        // The patch's form, looked up once for all its blocks.
        let form = self.form(p).expect("generic patches are handled by the caller");
        let chunks = uvs.chunks(L).zip(out.pos.chunks_mut(L).zip(out.nrm.chunks_mut(L)));
        for (uv, (pos, nrm)) in chunks {
            // Spare lanes repeat the last point: a real point, so its margin is meaningful.
            let mut u = [0f32; L];
            let mut v = [0f32; L];
            for l in 0..L {
                let q = uv[l.min(uv.len() - 1)];
                u[l] = q.x as f32;
                v[l] = q.y as f32;
            }
            let block = match form {
                FormRef::Bicubic(b) => bicubic_block::<FMA, L>(b, &u, &v),
                FormRef::Rational(r) => rational_block::<FMA, L>(r, &u, &v),
                FormRef::Triangle(t) => triangle_block::<FMA, L, 10, 6>(t, &u, &v),
                FormRef::Pn(t) => pn_block::<FMA, L>(t, &u, &v),
                FormRef::Quartic(t) => triangle_block::<FMA, L, 15, 10>(t, &u, &v),
            };
            for (l, (pos, nrm)) in pos.iter_mut().zip(nrm).enumerate() {
                (*pos, *nrm) = block.lane_or_exact(l, set, p, uv[l]);
            }
        }
        out.uv.iter_mut().zip(uvs).for_each(|(x, uv)| *x = uv.as_vec2().to_array());
        out.patch.fill(p as u32);
    }
}

/// `count` leaf forms, form `i` made by `make(p, leaf)` for the tree of `starts` it falls in
/// (`starts`: each tree's first form and a patch on it, in order), in parallel, straight into
/// place: per-patch vectors moved into one held every form twice at the peak.
fn leaf_forms<T: Send>(
    count: usize,
    starts: &[(usize, usize)],
    make: impl Fn(usize, usize) -> T + Sync,
) -> Vec<T> {
    (0..count)
        .into_par_iter()
        .with_min_len(256)
        .map(|i| {
            let (first, p) = starts[starts.partition_point(|&(first, _)| first <= i) - 1];
            make(p, i - first)
        })
        .collect()
}

/// Appends `x` to `v` and returns its index.
fn push<T>(v: &mut Vec<T>, x: T) -> u32 {
    v.push(x);
    (v.len() - 1) as u32
}

/// The generic f64 evaluation, for the rare points f32 cannot resolve.
#[cold]
#[inline(never)]
fn exact(set: &SurfaceSet, p: usize, uv: DVec2) -> SurfacePoint {
    set.patches[p].eval(uv)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn power_of_two_above_brackets_its_argument() {
        for x in [1e-30, 0.3, 0.5, 1.0, 3.0, 1024.0, 1e30] {
            let p = power_of_two_above(x);
            assert!(x < p && p <= 2.0 * x, "{x} → {p}");
            assert_eq!(p.to_bits() & ((1 << 52) - 1), 0, "{p} is a power of two");
        }
        assert_eq!(power_of_two_above(0.0), 1.0);
    }

    /// Each kernel against the surface's own f64 evaluation at scattered parameters (not a
    /// grid, not the pattern's), every lane count, both kernel builds.
    #[test]
    fn blocks_match_the_f64_evaluation_at_scattered_points() {
        use crate::surface::{PnTriangle, RationalBicubic};
        let tri = BezierTriangle {
            points: std::array::from_fn(|k| {
                DVec3::new(10.0 + k as f64 * 0.37, (k * k) as f64 * 0.11 - 1.0, 1.0 / (k + 1) as f64)
            }),
        };
        let corners = [DVec3::new(100.0, 0.0, 0.0), DVec3::new(101.0, 0.0, 0.2), DVec3::new(100.0, 1.0, 0.1)];
        let normals = [DVec3::new(0.1, 0.0, 1.0), DVec3::new(-0.2, 0.1, 1.0), DVec3::new(0.0, 0.3, 1.0)]
            .map(|n| n.normalize());
        let mut grid = [DVec3::ZERO; 16];
        for (k, q) in grid.iter_mut().enumerate() {
            let (i, j) = ((k / 4) as f64, (k % 4) as f64);
            *q = DVec3::new(i - 5e3, j, 0.3 * (i * j).sin());
        }
        // Rational: weights within [0.5, 2] varying across the patch; one inner weight, then a
        // corner's, a hundredth of the others (W·S_u nearly vanishes near it, so the points
        // there test the fallback); weights spanning more than MIN_WEIGHT_RATIO (the generic
        // path throughout); the exact sphere octant, whose pole row collapses.
        let rational = |weight: &dyn Fn(usize) -> f64| {
            Patch::Bicubic(RationalBicubic { points: grid, weights: std::array::from_fn(weight) })
        };
        let patches = vec![
            Patch::BezierTriangle(tri),
            Patch::Pn(PnTriangle::new(corners, normals)),
            Patch::Bicubic(RationalBicubic::polynomial(grid)),
            rational(&|k| (k as f64 * 0.9).sin().exp2()),
            rational(&|k| if k == 5 { 0.02 } else { 1.0 + 0.1 * k as f64 }),
            rational(&|k| if k == 0 { 0.02 } else { 1.0 + 0.1 * k as f64 }),
            rational(&|k| if k == 10 { 1e-3 } else { 1.0 }),
            Patch::Bicubic(crate::scene::sphere_octant()),
        ];
        let options = crate::surface::BuildOptions {
            orientation: crate::surface::Orientation::AsGiven,
            ..Default::default()
        };
        let set = SurfaceSet::from_patches(patches, options);
        let (mut from_kernels, mut rational_points) = (0, 0);
        for avx2_fma in [false, true] {
            let blocks = PointBlocks::for_set(&set, avx2_fma);
            assert!(matches!(blocks.locals[6], Local::Generic), "weights spanning 1000×");
            for (p, patch) in set.patches.iter().enumerate() {
                for count in [1, 3, 4, 5, 7, 8, 9, 23] {
                    let uvs: Vec<DVec2> = (0..count)
                        .map(|k| {
                            let (a, b) = ((k as f64 * 0.618).fract(), (k as f64 * 0.377 + 0.1).fract());
                            if patch.domain() == crate::domain::Domain::Tri {
                                DVec2::new(a, b * (1.0 - a))
                            } else {
                                DVec2::new(a, b)
                            }
                        })
                        .collect();
                    let (mut pos, mut nrm) = (vec![[0f32; 3]; count], vec![[0f32; 3]; count]);
                    let (mut uv, mut id) = (vec![[0f32; 2]; count], vec![0u32; count]);
                    let out = VertexSlices { pos: &mut pos, nrm: &mut nrm, uv: &mut uv, patch: &mut id };
                    blocks.eval(&set, p, &uvs, out);
                    let (_, size) = local_frame(patch.control_points());
                    for k in 0..count {
                        let q = patch.eval(uvs[k]);
                        let dp = (glam::Vec3::from(pos[k]).as_dvec3() - q.position).length();
                        let dn = (glam::Vec3::from(nrm[k]).as_dvec3() - q.normal).length();
                        assert!(
                            dp <= 1e-6 * size * 2.0 + 1e-7 * q.position.length(),
                            "patch {p} {k}: {dp:e}"
                        );
                        assert!(dn <= 1e-5, "patch {p} point {k}: normal off by {dn:e}");
                        assert_eq!(uv[k], uvs[k].as_vec2().to_array());
                        assert_eq!(id[k], p as u32);
                        if matches!(blocks.locals[p], Local::Rational(_)) {
                            rational_points += 1;
                            let exact = q.normal.as_vec3().to_array();
                            from_kernels += usize::from(nrm[k] != exact);
                        }
                    }
                }
            }
        }
        // The rational kernels ran (rounding differs from the f64 path's), not the fallback
        // everywhere.
        assert!(from_kernels * 2 > rational_points, "{from_kernels} of {rational_points} from the kernels");
    }

    /// The rational kernel on random nets whose weights span up to [`MIN_WEIGHT_RATIO`]:
    /// every point it keeps (margin positive) within 1e-5 of the f64 normal, and most kept.
    #[test]
    fn rational_kernels_hold_the_normal_bound_on_random_nets() {
        use crate::engine::uniform_quads::MIN_WEIGHT_RATIO;
        use crate::surface::RationalBicubic;
        let mut rng = crate::test_support::Lcg(0x2545_f491_4f6c_dd1d);
        let mut random = move || rng.unit53();
        let (mut kept, mut total) = (0, 0);
        for span in [1.0, 2.0, 4.0, 8.0, 1.0 / MIN_WEIGHT_RATIO] {
            for _ in 0..1000 {
                // A wavy near-grid net far from the origin; weights within [1/span, 1].
                let points = std::array::from_fn(|k| {
                    let (i, j) = ((k / 4) as f64, (k % 4) as f64);
                    DVec3::new(i + 0.4 * random(), j + 0.4 * random(), 0.8 * random()) * 3.0 + 100.0
                });
                let weights = std::array::from_fn(|_| span.powf(-random()));
                let patch = RationalBicubic { points, weights };
                let local = LocalPatch::rational(&patch).expect("weights within the ratio");
                let (u, v) =
                    (std::array::from_fn(|_| random() as f32), std::array::from_fn(|_| random() as f32));
                for fma in [false, true] {
                    let block = if fma && has_avx2_fma() {
                        // SAFETY: the CPU has AVX2 and FMA.
                        unsafe { rational_block_avx2_fma(&local, &u, &v) }
                    } else {
                        rational_block::<false, LANES>(&local, &u, &v)
                    };
                    for l in 0..LANES {
                        total += 1;
                        if block.margin[l] > 0.0 {
                            kept += 1;
                            let q = patch.eval(DVec2::new(u[l] as f64, v[l] as f64));
                            let n = DVec3::new(
                                block.nrm[0][l] as f64,
                                block.nrm[1][l] as f64,
                                block.nrm[2][l] as f64,
                            );
                            let p = DVec3::new(
                                block.pos[0][l] as f64,
                                block.pos[1][l] as f64,
                                block.pos[2][l] as f64,
                            );
                            let dn = (n - q.normal).length();
                            assert!(dn <= 1e-5, "span {span}: normal off by {dn:e}");
                            // As the scattered points: 1e-6 of the patch, and the output's rounding.
                            let bound = 2e-6 * local_frame(&patch.points).1 + 1e-7 * q.position.length();
                            assert!(p.distance(q.position) <= bound, "span {span}: {p} vs {}", q.position);
                        }
                    }
                }
            }
        }
        assert!(kept * 2 > total, "only {kept} of {total} points kept by the kernel");
    }

    /// [`rational_block`] compiled for AVX2 and FMA.
    ///
    /// # Safety
    /// The CPU must support AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn rational_block_avx2_fma(
        patch: &LocalPatch<4>,
        u: &[f32; LANES],
        v: &[f32; LANES],
    ) -> Block<LANES> {
        rational_block::<true, LANES>(patch, u, v)
    }

    /// Every scheme on every surface kind: the engine with the block evaluator writes the
    /// generic engine's mesh index for index, parameter for parameter, positions within 1e-6
    /// of the bounding-box diagonal and normals within 1e-5.
    #[test]
    fn every_scheme_and_surface_kind_matches_the_generic_engine() {
        use crate::criterion::view::{Mapping, ViewCriterion};
        use crate::engine::{EngineOptions, Layout};
        use crate::sampling::Partitioning;
        use crate::scheme::{Criterion, PlanOptions, Scheme};
        let view = |criterion, fmin, fmax| Criterion::View { criterion, fmin, fmax };
        let data = crate::test_support::data;
        let patches = |name: &str, rational: bool| {
            let file = crate::io::patches::read_patches(&data(name)).unwrap();
            let file = if rational { crate::scene::position_weights(&file) } else { file };
            SurfaceSet::from_patch_file(&file, Default::default())
        };
        let teapot = patches("patches/teapot.patches", false);
        let pn = |name: &str| {
            let mesh = crate::io::obj::read_obj(&data(name)).unwrap();
            SurfaceSet::pn_from_mesh(&mesh, &data(name), Default::default()).unwrap()
        };
        let cow = pn("meshes/cow.obj");
        // The cow with every seventh face flat-shaded: split normals at their vertices and
        // creases (edges of two normal variants) around them.
        let creased = {
            let path = data("meshes/cow.obj");
            let mut mesh = crate::io::obj::read_obj(&path).unwrap();
            for face in mesh.faces.iter_mut().step_by(7) {
                let [a, b, c] = [0, 1, 2].map(|k| mesh.positions[face.positions[k] as usize]);
                mesh.normals.push((b - a).cross(c - a).normalize());
                face.normals = Some(vec![mesh.normals.len() as u32 - 1; face.positions.len()]);
            }
            SurfaceSet::pn_from_mesh(&mesh, &path, Default::default()).unwrap()
        };
        assert!(creased.topology.edges.iter().any(|e| e.variants > 1));
        // The cow's PN geometry as plain Bézier triangles: normals from the derivatives.
        let mut bezier = cow.clone();
        for patch in &mut bezier.patches {
            if let Patch::Pn(t) = patch {
                *patch = Patch::BezierTriangle(t.geometry.clone());
            }
        }
        // Rational: weights a function of position (shared curves keep theirs), and the exact
        // sphere octant and cylinder.
        let sphere = SurfaceSet::from_patches(
            vec![Patch::Bicubic(crate::scene::sphere_octant())],
            crate::surface::BuildOptions::default(),
        );
        let cylinder = SurfaceSet::from_patch_file(&crate::scene::cylinder(2.0), Default::default());
        let models = [
            ("teapot", teapot),
            ("cow PN", cow),
            ("cow Bézier", bezier),
            ("spot PN", pn("meshes/spot.obj")),
            ("cow PN creased", creased),
            ("teapot rational", patches("patches/teapot.patches", true)),
            ("torus rational", patches("bench/torus_64x32.patches", true)),
            ("sphere octant", sphere),
            ("cylinder", cylinder),
        ];
        let rational = |set: &SurfaceSet| {
            set.patches.iter().all(|p| matches!(p, Patch::Bicubic(b) if !b.is_polynomial()))
        };
        assert!(models[5..].iter().all(|(_, set)| rational(set)));
        let cases = [
            (Scheme::Uniform, Criterion::Factor(4.0)),
            (Scheme::Uniform, Criterion::Factor(5.0)),
            (Scheme::Transition, Criterion::PixelError(0.7)),
            (Scheme::SemiUniform { max_level: 5 }, Criterion::PixelError(1.0)),
            (Scheme::Sd2 { warp: false }, Criterion::Factor(5.3)),
            (Scheme::Sd2 { warp: true }, view(ViewCriterion::Distance(Mapping::Linear), 2.0, 9.0)),
            (Scheme::Hardware(Partitioning::FractionalOdd), Criterion::Factor(6.4)),
            (Scheme::Hardware(Partitioning::FractionalEven), view(ViewCriterion::Silhouetteness, 2.0, 7.5)),
            (
                Scheme::Hardware(Partitioning::Integer),
                view(ViewCriterion::Distance(Mapping::Linear), 1.0, 8.0),
            ),
            (
                Scheme::Esc { max_level: 4 },
                Criterion::Esc { threshold: crate::criterion::esc::Threshold::High, level: Some(3) },
            ),
        ];
        let (mut compared, mut cached, mut uniform_triangles) = (0, 0, 0);
        for (name, set) in &models {
            let (lo, hi) = set.bounds();
            let size = lo.distance(hi);
            let mut camera = crate::camera::Camera::framing(lo, hi, 1280, 720);
            camera.eye = camera.target + (camera.eye - camera.target) * 0.6;
            for (scheme, criterion) in &cases {
                let options = PlanOptions { camera: Some(camera), ..PlanOptions::default() };
                let planned = match scheme.plan(set, criterion, &options) {
                    Ok(planned) => planned,
                    Err(e) => {
                        eprintln!("{name} {scheme:?} {criterion:?}: {e}");
                        continue;
                    }
                };
                let (plan, pattern) = (&planned.plan, &planned.pattern);
                let opts = EngineOptions::default();
                let mut layout = Layout::default();
                layout.build(set, plan, pattern, &opts).unwrap();
                for avx2_fma in [false, true] {
                    let mut evaluator =
                        super::super::fast_evaluator::FastEvaluator::with_kernels(set, plan, avx2_fma);
                    // The frame's distinct patterns, built once (where they pay), read by the
                    // writer instead of its per-patch builds, which the reference makes.
                    evaluator.fill_patterns(plan, pattern, layout.triangle_count() as u64, None);
                    cached += usize::from(evaluator.patterns().distinct() > 0);
                    uniform_triangles += usize::from(evaluator.triangles().active());
                    let what = format!("{name} {scheme:?} {criterion:?} avx2_fma={avx2_fma}");
                    assert_fast_equals_generic(&what, set, plan, pattern, &layout, &evaluator, size, true);
                }
                compared += 1;
            }
        }
        // SD-2 skips the five quad models, ESC the four triangle ones; the rest run everywhere.
        assert!(cached >= 10, "the pattern cache served only {cached} cases");
        assert_eq!(compared, 9 * 10 - 5 * 2 - 4, "only {compared} model × scheme cases planned");
        // The uniform triangle writer wrote both uniform cases of the four triangle models
        // (creases among them: their edges take the generic edge writer), with both kernels,
        // and nothing else.
        assert_eq!(uniform_triangles, 4 * 2 * 2, "the uniform triangle writer ran {uniform_triangles} times");
    }

    /// The fast paths' output of `plan` (through `evaluator`) against the generic engine's:
    /// indices, uvs and vertex patches identical, positions within 1e-6 of `size` (the
    /// diagonal), normals within 1e-5, the same boundary edges; with `kernels_ran`, more
    /// than a quarter of the normals differ from the f64 path's in their rounding (so the
    /// f32 kernels, not their f64 fallback, made them). Returns the two meshes (fast,
    /// generic).
    #[allow(clippy::too_many_arguments)]
    fn assert_fast_equals_generic(
        what: &str,
        set: &SurfaceSet,
        plan: &crate::criterion::Plan,
        pattern: &dyn crate::pattern::Pattern,
        layout: &crate::engine::Layout,
        evaluator: &super::super::fast_evaluator::FastEvaluator<'_>,
        size: f64,
        kernels_ran: bool,
    ) -> (crate::mesh::Mesh, crate::mesh::Mesh) {
        use crate::engine::{write_with, EngineOptions};
        use crate::mesh::Mesh;
        let opts = EngineOptions::default();
        let mut mesh = Mesh::default();
        write_with(set, plan, pattern, layout, opts, &mut mesh, Some(evaluator)).unwrap();
        let mut reference = Mesh::default();
        write_with(set, plan, pattern, layout, opts, &mut reference, None).unwrap();
        assert_eq!(mesh.indices, reference.indices, "{what}");
        assert_eq!(mesh.uvs, reference.uvs, "{what}");
        assert_eq!(mesh.vertex_patch, reference.vertex_patch, "{what}");
        let diff = |a: &[[f32; 3]], b: &[[f32; 3]]| {
            a.iter()
                .zip(b)
                .map(|(a, b)| (glam::Vec3::from(*a) - glam::Vec3::from(*b)).length() as f64)
                .fold(0.0, f64::max)
        };
        let dp = diff(&mesh.positions, &reference.positions) / size;
        let dn = diff(&mesh.normals, &reference.normals);
        assert!(dp <= 1e-6, "{what}: positions differ by {dp:e} of the diagonal");
        assert!(dn <= 1e-5, "{what}: normals differ by {dn:e}");
        if kernels_ran {
            // The f32 kernels ran (rounding differs from the f64 path's somewhere), rather
            // than the f64 fallback everywhere. Corners are written in closed form with the
            // f64 path's bits, so only the edge and interior vertices count.
            let changed = mesh.normals.iter().zip(&reference.normals).filter(|(a, b)| a != b).count();
            let evaluated = mesh.normals.len() - layout.corners as usize;
            assert!(
                changed * 4 > evaluated,
                "{what}: only {changed} of {evaluated} normals from the kernels"
            );
        }
        let w = crate::verify::watertight(&mesh);
        let r = crate::verify::watertight(&reference);
        assert_eq!(w.boundary_edges, r.boundary_edges, "{what}");
        (mesh, reference)
    }

    /// A stream of points on many trees ([`PointBlocks::eval_tree_stream`], the engine's runs
    /// of edges) gives every point the bits its own patch's evaluation gives it, its
    /// parameters and its patch: edge-like runs of seven points and a few interior points,
    /// patch after patch, on four cages, with both instruction sets.
    #[test]
    fn tree_streams_give_each_patchs_points_bit_for_bit() {
        let cages = ["catmark_rook", "catmark_cube_creases0", "catmark_xord_boundary", "catmark_nonquads"];
        let mut streamed = 0;
        for name in cages {
            let path = crate::test_support::data(&format!("subdivision/{name}.obj"));
            let set = SurfaceSet::from_subdivision_cage(
                &crate::io::obj::read_obj(&path).unwrap(),
                &path,
                Default::default(),
            )
            .unwrap();
            for avx2_fma in [false, has_avx2_fma()] {
                let blocks = PointBlocks::for_set(&set, avx2_fma);
                let (mut items, mut lists) = (Vec::new(), Vec::new());
                for p in 0..set.patches.len() {
                    let e = p % 4;
                    let mut uvs: Vec<DVec2> =
                        (1..8).map(|k| crate::surface::Domain::Quad.edge_point(e, k as f64 / 8.0)).collect();
                    if p % 3 == 0 {
                        uvs.extend([DVec2::new(0.3, 0.6), DVec2::new(0.5, 0.5), DVec2::new(0.75, 0.5)]);
                    }
                    if blocks.evaluates_on_tree(&set, p, uvs.len()) {
                        items.extend(uvs.iter().map(|&uv| (p as u32, uv)));
                        lists.push((p, uvs));
                    }
                }
                assert!(lists.len() >= 4, "{name}: {} patches on sparse trees", lists.len());
                let n = items.len();
                let (mut pos, mut nrm, mut uv, mut patch) =
                    (vec![[0f32; 3]; n], vec![[0f32; 3]; n], vec![[0f32; 2]; n], vec![0u32; n]);
                let out = VertexSlices { pos: &mut pos, nrm: &mut nrm, uv: &mut uv, patch: &mut patch };
                blocks.eval_tree_stream(&set, &items, out);
                let mut k = 0;
                for (p, uvs) in &lists {
                    let m = uvs.len();
                    let (mut pos1, mut nrm1, mut uv1, mut patch1) =
                        (vec![[0f32; 3]; m], vec![[0f32; 3]; m], vec![[0f32; 2]; m], vec![0u32; m]);
                    let out =
                        VertexSlices { pos: &mut pos1, nrm: &mut nrm1, uv: &mut uv1, patch: &mut patch1 };
                    blocks.eval(&set, *p, uvs, out);
                    let bits = |v: &[[f32; 3]]| v.iter().map(|a| a.map(f32::to_bits)).collect::<Vec<_>>();
                    let what = format!("{name} patch {p} avx2_fma={avx2_fma}");
                    assert_eq!(bits(&pos[k..k + m]), bits(&pos1), "{what}: positions");
                    assert_eq!(bits(&nrm[k..k + m]), bits(&nrm1), "{what}: normals");
                    assert_eq!(&uv[k..k + m], &uv1[..], "{what}: parameters");
                    assert_eq!(&patch[k..k + m], &patch1[..], "{what}: patches");
                    k += m;
                }
                streamed += n;
            }
        }
        assert!(streamed > 5000, "only {streamed} points streamed");
    }

    /// Subdivision cages: the grouped leaf kernels (`tree_points`, for dense points) and the
    /// f64 path they fall back to, with both instruction sets, against the generic engine on
    /// every cage of `subdivision/`, Catmull-Clark's and Loop's (whose regular triangles take
    /// the quartic kernel whole) — uniform at a factor where the isolated faces' points are
    /// dense next to their leaves, and transition at a pixel error, whose factors mix both
    /// paths. On the denser factor, the kernels must have made some normals.
    #[test]
    fn subdivision_cages_match_the_generic_engine() {
        use crate::engine::{EngineOptions, Layout};
        use crate::scheme::{Criterion, PlanOptions, Scheme};
        let cages = crate::test_support::data_files("subdivision", &["catmark", "loop_"]);
        let cages: Vec<_> = cages.into_iter().filter(|p| p.extension().is_some_and(|x| x == "obj")).collect();
        assert!(cages.len() >= 40, "{cages:?}");
        let (mut compared, mut grouped, mut loop_cages) = (0, 0, 0);
        let piecewise = |p: &Patch| matches!(p, Patch::Subdivision(_) | Patch::Loop(_));
        for path in &cages {
            let mesh = crate::io::obj::read_obj(path).unwrap();
            let is_loop = path.file_name().is_some_and(|n| n.to_string_lossy().starts_with("loop_"));
            let built = if is_loop {
                SurfaceSet::from_loop_cage(&mesh, path, Default::default())
            } else {
                SurfaceSet::from_subdivision_cage(&mesh, path, Default::default())
            };
            // A few cages are refused (non-manifold ones; `tests/catmull_clark.rs` checks why).
            let Ok(set) = built else {
                continue;
            };
            loop_cages += usize::from(is_loop);
            let trees = set.patches.iter().any(piecewise);
            let (lo, hi) = set.bounds();
            let mut camera = crate::camera::Camera::framing(lo, hi, 1280, 720);
            camera.eye = camera.target + (camera.eye - camera.target) * 0.6;
            for (scheme, criterion) in
                [(Scheme::Uniform, Criterion::Factor(24.0)), (Scheme::Transition, Criterion::PixelError(1.0))]
            {
                let options = PlanOptions { camera: Some(camera), max_factor: 32, ..PlanOptions::default() };
                let planned = scheme.plan(&set, &criterion, &options).unwrap();
                let (plan, pattern) = (&planned.plan, &planned.pattern);
                let mut layout = Layout::default();
                layout.build(&set, plan, pattern, &EngineOptions::default()).unwrap();
                for avx2_fma in [false, true] {
                    let mut evaluator =
                        super::super::fast_evaluator::FastEvaluator::with_kernels(&set, plan, avx2_fma);
                    evaluator.fill_patterns(plan, pattern, layout.triangle_count() as u64, None);
                    let what = format!("{} {scheme:?} {criterion:?} avx2_fma={avx2_fma}", path.display());
                    let size = lo.distance(hi);
                    let (fast, generic) = assert_fast_equals_generic(
                        &what, &set, plan, pattern, &layout, &evaluator, size, false,
                    );
                    if trees && matches!(scheme, Scheme::Uniform) {
                        // Isolated faces' normals from the kernels: some differ in their rounding.
                        let from_trees = |k: usize| piecewise(&set.patches[fast.vertex_patch[k] as usize]);
                        grouped += usize::from(
                            (0..fast.normals.len())
                                .any(|k| from_trees(k) && fast.normals[k] != generic.normals[k]),
                        );
                    }
                }
                compared += 1;
            }
        }
        assert!(compared >= 40 * 2, "only {compared} cage runs compared");
        assert!(loop_cages >= 10, "only {loop_cages} Loop cages");
        assert!(
            grouped >= 40,
            "the leaf kernels changed isolated faces' normals on only {grouped} cage runs"
        );
    }

    #[test]
    #[ignore = "slow tier: every model of the shared data × every scheme, fast paths against the generic engine"]
    fn fast_paths_equal_the_generic_engine_on_every_model_and_scheme() {
        use crate::criterion::view::{Mapping, ViewCriterion};
        use crate::engine::{EngineOptions, Layout};
        use crate::sampling::Partitioning;
        use crate::scheme::{Criterion, PlanOptions, Scheme};
        let data = crate::test_support::data;
        let view = |criterion, fmin, fmax| Criterion::View { criterion, fmin, fmax };
        let mut models = Vec::new();
        // Every patch model and every triangle mesh (bench/ also holds the torus as a quad
        // mesh, for comparisons with subdivision libraries; tessera reads triangles only).
        for (folder, ext) in
            [("patches", "patches"), ("bench", "patches"), ("meshes", "obj"), ("awkward", "obj")]
        {
            let mut names: Vec<_> = std::fs::read_dir(data(folder))
                .unwrap()
                .map(|e| e.unwrap().path())
                .filter(|p| p.extension().is_some_and(|x| x == ext))
                .collect();
            names.sort();
            models.extend(names);
        }
        assert!(models.len() >= 20, "{models:?}");
        let cases = [
            (Scheme::Uniform, Criterion::Factor(3.0)),
            (Scheme::Transition, Criterion::PixelError(1.5)),
            (Scheme::SemiUniform { max_level: 4 }, Criterion::PixelError(2.0)),
            (Scheme::Sd2 { warp: true }, view(ViewCriterion::Distance(Mapping::Linear), 1.5, 6.0)),
            (Scheme::Hardware(Partitioning::FractionalOdd), Criterion::Factor(3.4)),
            (Scheme::Hardware(Partitioning::FractionalEven), view(ViewCriterion::Silhouetteness, 2.0, 5.5)),
            (Scheme::Hardware(Partitioning::Pow2), view(ViewCriterion::Distance(Mapping::Linear), 1.0, 6.0)),
            (
                Scheme::Esc { max_level: 3 },
                Criterion::Esc { threshold: crate::criterion::esc::Threshold::Medium, level: None },
            ),
        ];
        let (mut compared, mut refused) = (0, 0);
        for path in &models {
            let set = match crate::io::load(path, crate::io::LoadOptions::default()) {
                Ok(set) => set,
                Err(e) => panic!("{}: {e}", path.display()),
            };
            let (lo, hi) = set.bounds();
            let camera = crate::camera::Camera::framing(lo, hi, 1280, 720);
            for (scheme, criterion) in &cases {
                let options = PlanOptions { camera: Some(camera), ..PlanOptions::default() };
                let what = format!("{} {scheme:?} {criterion:?}", path.display());
                // Schemes refuse patch kinds they do not take (SD-2 quads, ESC triangles).
                let Ok(planned) = scheme.plan(&set, criterion, &options) else {
                    refused += 1;
                    continue;
                };
                let (plan, pattern) = (&planned.plan, &planned.pattern);
                let mut layout = Layout::default();
                layout.build(&set, plan, pattern, &EngineOptions::default()).unwrap();
                let mut evaluator = super::super::fast_evaluator::FastEvaluator::new(&set, plan);
                evaluator.fill_patterns(plan, pattern, layout.triangle_count() as u64, None);
                // A few hundred evaluated points can fall mostly on the f64 fallback.
                let kernels = layout.interior_offsets[set.patches.len()] - layout.corners > 2_000;
                assert_fast_equals_generic(
                    &what,
                    &set,
                    plan,
                    pattern,
                    &layout,
                    &evaluator,
                    lo.distance(hi),
                    kernels,
                );
                compared += 1;
            }
        }
        eprintln!("{compared} model × scheme cases compared, {refused} refused by their scheme");
        assert!(compared >= models.len() * 6, "only {compared} cases compared");
    }
}
