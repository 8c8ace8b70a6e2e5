//! The Taylor bound: a triangle's linear-interpolation error from the patch's second
//! derivatives *at* the triangle, plus a bound on its third derivatives.
//!
//! [`super::bounds`] bounds the error over a triangle by the largest second derivative
//! anywhere on the patch, each of `S_uu`, `S_uv`, `S_vv` in norm on its own. That is three
//! sources of slack: the largest derivative is not where most triangles are; `S_uu`, `S_uv`
//! and `S_vv` reach their largest norms at different places; and a cell's error along its
//! diagonal, `|S_uu·hu² ∓ 2·S_uv·hu·hv + S_vv·hv²|/8`, is a norm of a sum, not a sum of norms.
//! This bound keeps the vectors together and takes them where the triangle is.
//!
//! **What is proven.** Let `T` be a parameter triangle with corners `c_0, c_1, c_2`, `L` the
//! linear interpolant of `S` at them, `g` a point of the convex region where the bounds below
//! hold with `T` inside it, and `H = D²S(g)` (the vectors `A = S_uu(g)`, `B = S_uv(g)`,
//! `C = S_vv(g)`). Taylor's theorem with the integral remainder gives
//! `S(x) = S(g) + DS(g)(x − g) + ½·H[x − g]² + R(x)` with
//! `|R(x)| ≤ f₃(x − g)/6`, `f₃(δ) = t₀|δu|³ + 3t₁|δu|²|δv| + 3t₂|δu||δv|² + t₃|δv|³`, where
//! `t₀..t₃` bound `|S_uuu|, |S_uuv|, |S_uvv|, |S_vvv|` on the region (the segment from `g` to
//! `x` stays in it). Linear interpolation reproduces the affine part, so
//! `S − L = (Q − L_Q) + (R − L_R)` with `Q = ½·H[x − g]²`:
//! - `Q − L_Q` is a quadratic vanishing at the corners; such a quadratic is fixed by its
//!   values at the edge midpoints, and along edge `i` (opposite corner `i`, vector `e_i`) it is
//!   the chord error of a parabola: `−(e_iᵀ H e_i)/8 · 4λ_jλ_k`. So
//!   `Q − L_Q = −Σ m_i φ_i` with `m_i = e_iᵀ H e_i / 8` (vectors) and `φ_i = 4λ_jλ_k ≥ 0`,
//!   and `|Q − L_Q| ≤ Σ |m_i| φ_i ≤ max over T of Σ |m_i| φ_i` ([`bubble_max`], in closed form).
//!   On the edges this is exact; inside it is exact when the `m_i` are parallel.
//! - `|R(x) − L_R(x)| ≤ |R(x)| + Σ λ_k |R(c_k)| ≤ f₃(Δ)/3`, with `Δ` the largest `|δu|`,
//!   `|δv|` from `g` to a corner (`f₃` grows with each, and `T` lies in that box about `g`).
//!
//! So `|S − L| ≤ bubble_max(|m_0|, |m_1|, |m_2|) + f₃(Δ)/3` on `T`. As triangles shrink the
//! remainder vanishes like `h³` against the `h²` of the rest, and the bound tends to the exact
//! error of the triangle where the `m_i` are parallel (the usual case: the normal components
//! dominate). It assumes nothing beyond the bounds `t_k` on the region, which come from the
//! control net (the convex-hull property of the third derivatives' Bézier forms).
//!
//! **Refinement.** On coarse triangles the remainder, taken with the patch's largest third
//! derivatives, dominates; two refinements bound them closer, and every query takes the
//! smallest valid bound:
//! - a cubic triangle's error `S − L` is itself a cubic: its Bézier control points over four
//!   midpoint sub-triangles bound it (convex hull, [`cubic_error_hull`]);
//! - a bicubic's triangle is cut into the `n²` leaves of its `n`-lattice
//!   ([`TaylorBound::split_error`]): on each leaf `S − L` is the leaf's own interpolation error
//!   (its Taylor bound, `1/n²` of the whole's) plus an affine function, bounded by the exact
//!   `|S − L|` at the leaf's corners. So the bound is the error sampled on the lattice plus a
//!   small margin, and tends to the truth as `n` grows.
//!
//! Refining costs about twenty evaluations, so a walk refines only a triangle whose plain
//! bound could change its answer (`grid_fits`: above the tolerance; a
//! pattern's largest bound: above the largest so far).
//!
//! **Which patches.** Polynomial bicubics (`S_uu`, `S_uv`, `S_vv` are Bézier patches of
//! degrees (1,3), (2,2), (3,1); the third derivatives of degrees (0,3), (1,2), (2,1), (3,0)),
//! cubic Bézier triangles and PN triangles (second derivatives linear, third constant: the
//! bound is exact up to the triangle inequality inside), regular Loop patches (one quartic
//! piece: second derivatives quadratic, third linear, refined by the lattice split as a
//! bicubic is), and the trees of Catmull-Clark and isolated Loop patches through their
//! Bézier (bicubic, quartic) leaves: a triangle or cell inside one leaf takes that leaf's
//! bound (linear interpolation's error does not change under the affine map to the leaf's
//! parameters). Everything else — rational bicubics, a tree's triangles across
//! leaves (the surface is only piecewise smooth there) or on Gregory end caps — takes the
//! *sampled* bound: the lattice refinement with the patch's second-derivative bound in place
//! of the expansion, so the sampled error plus `1/n²` of that bound (`n` = 8 here, against
//! 4 for an expansion's split: `SAMPLED_LATTICE`). It is as valid as the
//! second-derivative bound and only as tight as its margin allows: where that bound is
//! loose (a Loop patch's covers its Gregory triangles' interior blends, a Catmull-Clark
//! patch's its Gregory caps') the finer lattice makes up for much of it. Every caller takes the smaller of this bound and the second-derivative bound,
//! each valid, triangle by triangle (a grid: cell by cell,
//! `grid_error_within`).

use super::bounds::{hessian, max_norm, TriangleErrors};
use crate::surface::patch_tree::{LeafPatch, PatchTree};
use crate::surface::triangle_tree::TriangleLeafPatch;
use crate::surface::{BezierTriangle, Patch, QuarticTriangle, TriangleTree};
use glam::{DVec2, DVec3};

/// One patch's Taylor bound: the field of its second derivatives and bounds on its third.
/// Cost of an error query: one evaluation of the second derivatives (25 Bernstein terms for
/// a bicubic, 9 for a triangle) and a 3 × 3 closed form.
#[derive(Debug, Clone, PartialEq)]
pub struct TaylorBound {
    field: SecondDerivatives,
    /// Bounds on `|S_uuu|`, `|S_uuv|`, `|S_uvv|`, `|S_vvv|` over the domain.
    third: [f64; 4],
    /// Whether queries may refine by sampling the patch (the lattice splits): false for
    /// [`TaylorBound::expansion`].
    refines: bool,
    /// For [`TaylorBound::expansion`] of a bicubic: its third derivatives' nets, which bound
    /// them near each expansion point ([`TaylorBound::remainder_at`]).
    local: Option<Box<ThirdDerivatives>>,
}

/// A polynomial bicubic's third derivatives as Bézier nets of its third differences
/// (`S_uuu = 6 Σ Δ³_u b·B³(v)`, `S_uuv = 18 Σ Δ²_uΔ_v b·B¹(u)B²(v)`, `S_uvv`, `S_vvv` their
/// mirrors) and bounds on their derivatives, the fourth derivatives `S_uuuv` (`18·|Δ³_uΔ_v
/// b|`), `S_uuvv` (`36·|Δ²_uΔ²_v b|`) and `S_uvvv`, the largest control vector each.
#[derive(Debug, Clone, PartialEq)]
struct ThirdDerivatives {
    uuu: [DVec3; 4],
    uuv: [[DVec3; 3]; 2],
    uvv: [[DVec3; 2]; 3],
    vvv: [DVec3; 4],
    fourth: [f64; 3],
}

impl ThirdDerivatives {
    /// The nets of the third differences (`[j]`, `[i][j]` and `[i]` as [`bicubic`] lists
    /// them), and the fourth derivatives' bounds from their differences.
    fn new(uuu: [DVec3; 4], uuv: [[DVec3; 3]; 2], uvv: [[DVec3; 2]; 3], vvv: [DVec3; 4]) -> ThirdDerivatives {
        let fourth = [
            18.0 * max_norm((0..3).map(|j| uuu[j + 1] - uuu[j])),
            36.0 * max_norm((0..2).flat_map(|i| (0..2).map(move |j| uuv[i][j + 1] - uuv[i][j]))),
            18.0 * max_norm((0..3).map(|i| vvv[i + 1] - vvv[i])),
        ];
        ThirdDerivatives { uuu, uuv, uvv, vvv, fourth }
    }

    /// Bounds on `|S_uuu|`, `|S_uuv|`, `|S_uvv|`, `|S_vvv|` over the box `g ± delta`: each at
    /// `g` plus its derivatives' bounds times the box's half-sides (`S_uuu` depends on `v`
    /// alone, `S_vvv` on `u`).
    fn near(&self, g: DVec2, delta: DVec2) -> [f64; 4] {
        let (u1, u2, u3) = (bernstein(1, g.x), bernstein(2, g.x), bernstein(3, g.x));
        let (v1, v2, v3) = (bernstein(1, g.y), bernstein(2, g.y), bernstein(3, g.y));
        let sum = |w: &[f64], p: &[DVec3]| p.iter().zip(w).fold(DVec3::ZERO, |a, (p, w)| a + *p * *w);
        let uuu = 6.0 * sum(&v3, &self.uuu);
        let vvv = 6.0 * sum(&u3, &self.vvv);
        let uuv = 18.0 * (sum(&v2, &self.uuv[0]) * u1[0] + sum(&v2, &self.uuv[1]) * u1[1]);
        let uvv = 18.0 * (0..3).fold(DVec3::ZERO, |a, i| a + sum(&v1, &self.uvv[i]) * u2[i]);
        let [m31, m22, m13] = self.fourth;
        let (du, dv) = (delta.x.abs(), delta.y.abs());
        [
            uuu.length() + m31 * dv,
            uuv.length() + m31 * du + m22 * dv,
            uvv.length() + m22 * du + m13 * dv,
            vvv.length() + m13 * du,
        ]
    }
}

// The variants differ in size (600 bytes against 216), but a set's bounds live in one
// vector, read per triangle: boxing the large one would add an allocation a patch and a
// pointer chase a query to save memory only on triangle meshes.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, PartialEq)]
enum SecondDerivatives {
    /// No Taylor bound for this patch kind: every error is infinite.
    None,
    /// Bézier nets of `S_uu` (2 × 4, `[i][j]` with `i` along u), `S_uv` (3 × 3), `S_vv` (4 × 2).
    /// With the patch's own points (`[i][j]`, `i` along u), for [`TaylorBound::split_error`].
    Bicubic { uu: [[DVec3; 4]; 2], uv: [[DVec3; 3]; 3], vv: [[DVec3; 2]; 4], points: [[DVec3; 4]; 4] },
    /// `[S_uu, S_uv, S_vv]` at the corners `(0,0)`, `(1,0)`, `(0,1)`, linear in between, and
    /// the cubic's own control points (for [`cubic_error_hull`]).
    Triangle { corners: [[DVec3; 3]; 3], net: [DVec3; 10] },
    /// A quartic Bézier triangle in the patch's parameters (a regular Loop patch: one box
    /// spline piece): `S_uu`, `S_uv`, `S_vv` are quadratic triangles, the third derivatives
    /// linear ones.
    Quartic { net: QuarticTriangle },
    /// A Catmull-Clark patch tree or an isolated Loop patch's triangle tree, and each of its
    /// leaves' bounds in the leaf's own parameters (a Bézier leaf's as a bicubic's, a
    /// quartic leaf's as [`SecondDerivatives::Quartic`]; a Gregory end cap has none). A query is
    /// answered by the one Bézier leaf that holds all its points (the error of linear
    /// interpolation does not depend on an affine change of parameters), else by `whole`,
    /// the tree's [`SecondDerivatives::Sampled`] bound: the surface is only piecewise smooth
    /// across leaves, where one expansion point would not do.
    Tree { tree: Pieces, leaves: std::sync::Arc<[TaylorBound]>, whole: Box<TaylorBound> },
    /// Any other patch (a rational bicubic, a whole subdivision tree): the
    /// patch's second-derivative bound `m` (valid over any triangle of its domain) takes the
    /// place of the Taylor expansion, and the lattice refinement
    /// ([`TaylorBound::split_error`]) samples the patch's own points: the sampled error plus
    /// `1/n²` of the second-derivative bound.
    Sampled { patch: Patch, m: TriangleErrors },
}

/// The leaves of a piecewise patch, and where a point of the patch lies in them.
#[derive(Debug, Clone, PartialEq)]
enum Pieces {
    /// A Catmull-Clark patch tree: square leaves.
    Quad(PatchTree),
    /// An isolated Loop patch: triangular leaves.
    Tri(TriangleTree),
}

impl Pieces {
    /// The leaf Bfr's search finds for `x` (patch parameters) and `x` in its parameters.
    fn find(&self, x: DVec2) -> (usize, DVec2) {
        match self {
            Pieces::Quad(tree) => {
                let (i, st, _) = tree.find(x);
                (i, st)
            }
            Pieces::Tri(tree) => tree.find(x),
        }
    }

    /// Patch parameters `x` in leaf `i`'s parameters, by the leaf's affine map.
    fn leaf_params(&self, i: usize, x: DVec2) -> DVec2 {
        match self {
            Pieces::Quad(tree) => {
                let leaf = &tree.leaves()[i];
                (tree.tree_uv(x) - leaf.origin) / leaf.size
            }
            Pieces::Tri(tree) => tree.leaf_params(i, x),
        }
    }

    /// Whether leaf parameters `st` lie in the leaf's closed domain (square or triangle).
    fn in_leaf(&self, st: DVec2) -> bool {
        st.min_element() >= 0.0
            && match self {
                Pieces::Quad(_) => st.max_element() <= 1.0,
                Pieces::Tri(_) => st.x + st.y <= 1.0,
            }
    }
}

impl TaylorBound {
    /// No bound: [`TaylorBound::triangle_error`] is infinite.
    pub const NONE: TaylorBound =
        TaylorBound { field: SecondDerivatives::None, third: [0.0; 4], refines: true, local: None };

    /// The bound of `patch`: a Taylor expansion for the polynomial kinds (and a
    /// Catmull-Clark tree's Bézier leaves), the sampled refinement of the second-derivative
    /// bound for the others. Cost: O(control points).
    pub fn of(patch: &Patch) -> TaylorBound {
        TaylorBound::with_errors(patch, None)
    }

    /// [`TaylorBound::of`] with the patch's second-derivative bound already at hand
    /// (`errors`, [`crate::criterion::Prepared::triangle_errors`]), which the sampled bound
    /// takes as its margin; None computes it where it is needed.
    pub(crate) fn with_errors(patch: &Patch, errors: Option<&TriangleErrors>) -> TaylorBound {
        let sampled = |patch: &Patch| TaylorBound {
            field: SecondDerivatives::Sampled {
                patch: patch.clone(),
                m: errors.copied().unwrap_or_else(|| hessian(patch).triangle_errors()),
            },
            third: [0.0; 4],
            refines: true,
            local: None,
        };
        match patch {
            Patch::Bicubic(b) if b.is_polynomial() => bicubic(&b.points),
            Patch::BezierTriangle(t) => triangle(t),
            Patch::Pn(pn) => triangle(&pn.geometry),
            // A regular Loop patch is one quartic piece; an isolated one a tree of quartic
            // leaves and Gregory triangles, answered as a Catmull-Clark tree is.
            Patch::Loop(tree) => match tree.regular_net() {
                Some(q) => quartic(&q),
                None => {
                    let leaves = tree.leaves().iter().map(|leaf| match &leaf.patch {
                        TriangleLeafPatch::Quartic(q) => quartic(q),
                        TriangleLeafPatch::Gregory(_) => TaylorBound::NONE,
                    });
                    TaylorBound::tree(Pieces::Tri((**tree).clone()), leaves, sampled(patch))
                }
            },
            Patch::Subdivision(tree) => {
                let leaves = tree.leaves().iter().map(|leaf| match &leaf.patch {
                    LeafPatch::Bezier(points) => bicubic(points),
                    LeafPatch::Gregory(_) => TaylorBound::NONE,
                });
                TaylorBound::tree(Pieces::Quad((**tree).clone()), leaves, sampled(patch))
            }
            _ => sampled(patch),
        }
    }

    /// A piecewise patch's bound: its leaves' (in the leaves' order), `whole` where none
    /// answers.
    fn tree(pieces: Pieces, leaves: impl Iterator<Item = TaylorBound>, whole: TaylorBound) -> TaylorBound {
        let (leaves, whole) = (leaves.collect(), Box::new(whole));
        TaylorBound {
            field: SecondDerivatives::Tree { tree: pieces, leaves, whole },
            third: [0.0; 4],
            refines: true,
            local: None,
        }
    }

    /// The expansion bound of `patch` ([`crate::criterion::ErrorBound::Expansion`]): the
    /// Taylor expansion of a polynomial bicubic, a cubic Bézier triangle or a PN triangle,
    /// with a cubic's control-point hull, and nothing that samples the patch — no lattice
    /// splits, so a grid's bound is a walk over its cells, one evaluation a cell, and beyond
    /// [`EXPANSION_WALK_CELLS`] cells the second-derivative nets' bound of every cell at once
    /// ([`TaylorBound::nets_grid_error`]). Every other kind has none ([`TaylorBound::NONE`]:
    /// its plans keep the second-derivative bound). This is the part of the Taylor bound whose
    /// every query has a fixed, small cost, which an a-posteriori check on the GPU could
    /// compute. A bicubic's remainder takes third-derivative bounds near each expansion point
    /// (`TaylorBound::remainder_at`). Cost: O(control points).
    pub fn expansion(patch: &Patch) -> TaylorBound {
        let (bound, local) = match ExpansionNet::of(patch) {
            Some(ExpansionNet::Bicubic(points)) => {
                let (bound, third) = bicubic_with_third(points);
                (bound, Some(Box::new(third)))
            }
            Some(ExpansionNet::Triangle(t)) => (triangle(t), None),
            None => return TaylorBound::NONE,
        };
        TaylorBound { refines: false, local, ..bound }
    }

    /// Whether queries refine by sampling the patch (false for [`TaylorBound::expansion`]).
    pub(crate) fn refines(&self) -> bool {
        self.refines
    }

    /// For a tree: the Bézier leaf whose closed square holds all of `points` (patch
    /// parameters), with the points in that leaf's own parameters; None where no one leaf
    /// with a bound does.
    fn leaf_of<const K: usize>(&self, points: [DVec2; K]) -> Option<(&TaylorBound, [DVec2; K])> {
        let SecondDerivatives::Tree { tree, leaves, .. } = &self.field else { return None };
        let centre = points.iter().fold(DVec2::ZERO, |a, &p| a + p) / K as f64;
        let (i, _) = tree.find(centre);
        let local = points.map(|p| tree.leaf_params(i, p));
        let inside = local.iter().all(|&q| tree.in_leaf(q));
        (inside && leaves[i].is_some()).then_some((&leaves[i], local))
    }

    /// For a tree: the leaf holding the axis-aligned cell `origin + [0, hu] × [0, hv]` and
    /// the cell in its parameters (origin and sides: a turned or transposed view turns the
    /// cell, which stays axis-aligned).
    fn leaf_cell(&self, origin: DVec2, hu: f64, hv: f64) -> Option<(&TaylorBound, DVec2, f64, f64)> {
        let corners =
            [origin, origin + DVec2::new(hu, 0.0), origin + DVec2::new(0.0, hv), origin + DVec2::new(hu, hv)];
        let (leaf, local) = self.leaf_of(corners)?;
        let lo = local.iter().fold(DVec2::splat(f64::INFINITY), |a, &q| a.min(q));
        let hi = local.iter().fold(DVec2::splat(f64::NEG_INFINITY), |a, &q| a.max(q));
        Some((leaf, lo, hi.x - lo.x, hi.y - lo.y))
    }

    /// Whether this bound covers its patch (else every error is infinite).
    pub fn is_some(&self) -> bool {
        !matches!(self.field, SecondDerivatives::None)
    }

    /// Whether a query may sample the patch (a tree, or the sampled refinement): each
    /// refined cell then costs tens of evaluations, so a proposal searches fewer grids
    /// (`tolerance::taylor_quad_grid`).
    pub(crate) fn samples(&self) -> bool {
        matches!(self.field, SecondDerivatives::Tree { .. } | SecondDerivatives::Sampled { .. })
    }

    /// `[S_uu, S_uv, S_vv]` at `x` (a tree: of the leaf holding `x`, zero on an end cap;
    /// zero for the sampled bound, which has no expansion). Preconditions: `x` in the
    /// patch's domain.
    pub fn second_derivatives(&self, x: DVec2) -> [DVec3; 3] {
        match &self.field {
            SecondDerivatives::None => [DVec3::ZERO; 3],
            SecondDerivatives::Sampled { .. } => [DVec3::ZERO; 3],
            SecondDerivatives::Tree { tree, leaves, .. } => {
                let (i, st) = tree.find(x);
                // The chain rule through the affine map to the leaf's parameters, whose
                // linear part takes the patch's unit steps to `ju`, `jv`.
                let step = |d: DVec2| tree.leaf_params(i, d) - tree.leaf_params(i, DVec2::ZERO);
                let (ju, jv) = (step(DVec2::X), step(DVec2::Y));
                let [uu, uv, vv] = leaves[i].second_derivatives(st);
                let h =
                    |a: DVec2, b: DVec2| uu * (a.x * b.x) + uv * (a.x * b.y + a.y * b.x) + vv * (a.y * b.y);
                [h(ju, ju), h(ju, jv), h(jv, jv)]
            }
            SecondDerivatives::Bicubic { uu, uv, vv, .. } => [net_at(uu, x), net_at(uv, x), net_at(vv, x)],
            SecondDerivatives::Triangle { corners, .. } => {
                let l = [1.0 - x.x - x.y, x.x, x.y];
                std::array::from_fn(|k| corners[0][k] * l[0] + corners[1][k] * l[1] + corners[2][k] * l[2])
            }
            SecondDerivatives::Quartic { net } => {
                let (uu, uv, vv) = net.second_derivatives(x);
                [uu, uv, vv]
            }
        }
    }

    /// `f₃(Δ)/3`: the remainder's share of the bound over a triangle within `delta` of its
    /// expansion point (per parameter), with the third-derivative bounds of the whole patch.
    fn remainder(&self, delta: DVec2) -> f64 {
        remainder_with(self.third, delta)
    }

    /// [`TaylorBound::remainder`] about `g`: for an expansion bound of a bicubic, whose
    /// lattice split does not take the remainder's slack away, each third derivative bounded
    /// on the box `g ± delta` (which holds every segment from `g` to the triangle) where that
    /// is smaller than the patch's bound (teapot at 0.5 px: 15,443 → 14,681 triangles; the
    /// full Taylor bound's plans do not move, at four times the planning).
    fn remainder_at(&self, g: DVec2, delta: DVec2) -> f64 {
        match &self.local {
            Some(local) => {
                let near = local.near(g, delta);
                remainder_with(std::array::from_fn(|k| near[k].min(self.third[k])), delta)
            }
            None => self.remainder(delta),
        }
    }

    /// The surface point at `x` (for [`TaylorBound::split_error`]).
    fn position(&self, x: DVec2) -> DVec3 {
        match &self.field {
            SecondDerivatives::None | SecondDerivatives::Tree { .. } => DVec3::ZERO,
            SecondDerivatives::Sampled { patch, .. } => patch.position(x),
            SecondDerivatives::Bicubic { points, .. } => net_at(points, x),
            SecondDerivatives::Triangle { net, .. } => BezierTriangle { points: *net }.position(x),
            SecondDerivatives::Quartic { net } => net.position(x),
        }
    }

    /// Guaranteed bound on `|S − L|` over the parameter triangle `t` (module doc), expanded
    /// about its centroid, and the smaller of that and a refined bound:
    /// [`cubic_error_hull`] for a cubic, [`TaylorBound::split_error`] for a bicubic.
    /// Infinite for [`TaylorBound::NONE`]. Preconditions: `t` in the patch's domain.
    /// Cost: one evaluation of the second derivatives and the refinement's (about twenty).
    pub fn triangle_error(&self, t: [DVec2; 3]) -> f64 {
        self.triangle_error_above(t, 0.0)
    }

    /// [`TaylorBound::triangle_error`] where only a value above `floor` matters: a triangle
    /// whose plain Taylor bound is at most `floor` keeps it, without the dearer refinement
    /// (which could only lower it), so `max(floor, ·)` of the two is the same. This is what
    /// makes the refinements affordable: a pattern's check refines only the triangles that
    /// could raise its largest bound, a proposal's test only those above the tolerance.
    pub(crate) fn triangle_error_above(&self, t: [DVec2; 3], floor: f64) -> f64 {
        if let SecondDerivatives::Tree { whole, .. } = &self.field {
            return match self.leaf_of(t) {
                Some((leaf, t)) => leaf.triangle_error_above(t, floor),
                None => whole.triangle_error_above(t, floor),
            };
        }
        let (quadratic, remainder) = self.taylor_parts(t);
        if quadratic + remainder <= floor {
            return quadratic + remainder;
        }
        match &self.field {
            // The error's own control points are tight on a cubic's large triangles; on small
            // ones the expansion is, and the hull (four blossom nets) would not win.
            SecondDerivatives::Triangle { net, .. } if remainder > HULL_WHEN * quadratic => {
                (quadratic + remainder).min(cubic_error_hull(net, t))
            }
            SecondDerivatives::Bicubic { .. }
            | SecondDerivatives::Quartic { .. }
            | SecondDerivatives::Sampled { .. }
                if self.refines =>
            {
                (quadratic + remainder).min(self.split_error(t))
            }
            _ => quadratic + remainder,
        }
    }

    /// The bound over `t` from the `n²` leaves of its `n`-lattice (`n` = 4):
    /// on a leaf `T'`, `S − L = (S − L_T') + (L_T' − L)`, the first bounded by the Taylor
    /// bound of `T'` (its quadratic part `1/n²` of `t`'s, its remainder `1/n³`), the second
    /// affine, so at most its largest value at `T'`'s corners, which is `|S − L|` there,
    /// evaluated at the lattice points (zero at `t`'s corners). The bound is the sampled
    /// error at the lattice plus at most a leaf's own bound, so it tends to the true error as
    /// `n` grows. Splitting a leaf again would be looser: its corner terms would be measured
    /// against the leaf's interpolant and added to `t`'s. Cost: `n²` Taylor bounds and
    /// `(n + 1)(n + 2)/2` positions.
    pub fn split_error(&self, t: [DVec2; 3]) -> f64 {
        if let SecondDerivatives::Tree { whole, .. } = &self.field {
            return match self.leaf_of(t) {
                Some((leaf, t)) => leaf.split_error(t),
                None => whole.split_error(t),
            };
        }
        let n = self.lattice();
        let at = t.map(|x| self.position(x));
        // |S − L| at lattice point (i, j): barycentric (n − i − j, i, j)/n.
        let mut error = [[0.0f64; MAX_LATTICE + 1]; MAX_LATTICE + 1];
        let weights = |i: usize, j: usize| {
            let (a, b) = (i as f64 / n as f64, j as f64 / n as f64);
            [1.0 - a - b, a, b]
        };
        let point = |i: usize, j: usize| {
            let [w0, w1, w2] = weights(i, j);
            t[0] * w0 + t[1] * w1 + t[2] * w2
        };
        for (i, row) in error.iter_mut().enumerate().take(n + 1) {
            for (j, e) in row.iter_mut().enumerate().take(n + 1 - i) {
                let corner = (i == 0 && j == 0) || i == n || j == n;
                if !corner {
                    let [w0, w1, w2] = weights(i, j);
                    *e = (self.position(point(i, j)) - (at[0] * w0 + at[1] * w1 + at[2] * w2)).length();
                }
            }
        }
        let leaf = |c: [(usize, usize); 3]| {
            let (quadratic, remainder) = self.taylor_parts(c.map(|(i, j)| point(i, j)));
            quadratic + remainder + c.iter().map(|&(i, j)| error[i][j]).fold(0.0, f64::max)
        };
        let mut worst = 0.0f64;
        for i in 0..n {
            for j in 0..n - i {
                worst = worst.max(leaf([(i, j), (i + 1, j), (i, j + 1)]));
                if i + j + 1 < n {
                    worst = worst.max(leaf([(i + 1, j), (i + 1, j + 1), (i, j + 1)]));
                }
            }
        }
        worst
    }

    /// The quadratic part and the remainder of the Taylor bound over `t` about its centroid
    /// (module doc); infinite for [`TaylorBound::NONE`].
    fn taylor_parts(&self, t: [DVec2; 3]) -> (f64, f64) {
        match &self.field {
            // A tree's leaves answer for it (they hold the third-derivative bounds).
            SecondDerivatives::None | SecondDerivatives::Tree { .. } => return (f64::INFINITY, 0.0),
            SecondDerivatives::Sampled { m, .. } => return (m.error(t), 0.0),
            _ => {}
        }
        let g = (t[0] + t[1] + t[2]) / 3.0;
        let [a, b, c] = self.second_derivatives(g);
        let m = |i: usize| {
            let e = t[(i + 2) % 3] - t[(i + 1) % 3];
            (a * (e.x * e.x) + b * (2.0 * e.x * e.y) + c * (e.y * e.y)).length() / 8.0
        };
        let delta = t.iter().fold(DVec2::ZERO, |d, p| d.max((*p - g).abs()));
        (bubble_max([m(0), m(1), m(2)]), self.remainder_at(g, delta))
    }

    /// The bound over both halves of the grid cell of sides `hu`, `hv` centred at `centre`,
    /// whichever diagonal splits it: one evaluation, at the centre, serves both triangles and
    /// both diagonals. Cost: one evaluation of the second derivatives.
    pub fn cell_error(&self, centre: DVec2, hu: f64, hv: f64) -> f64 {
        match &self.field {
            SecondDerivatives::None => return f64::INFINITY,
            SecondDerivatives::Tree { whole, .. } => {
                return match self.leaf_cell(centre - DVec2::new(hu, hv) / 2.0, hu, hv) {
                    Some((leaf, o, hu, hv)) => leaf.cell_error(o + DVec2::new(hu, hv) / 2.0, hu, hv),
                    None => whole.cell_error(centre, hu, hv),
                };
            }
            // Every cell of a size has the same second-derivative bound, either diagonal.
            SecondDerivatives::Sampled { m, .. } => return m.cell_error(hu, hv),
            _ => {}
        }
        let [a, b, c] = self.second_derivatives(centre);
        let (a, b, c) = (a * (hu * hu), b * (2.0 * hu * hv), c * (hv * hv));
        let (legs_u, legs_v) = (a.length() / 8.0, c.length() / 8.0);
        let diagonal = ((a + c - b).length().max((a + c + b).length())) / 8.0;
        bubble_max([diagonal, legs_u, legs_v]) + self.remainder_at(centre, DVec2::new(hu, hv) / 2.0)
    }

    /// [`TaylorBound::split_error`] of each of the four halves a grid cell can have (either
    /// diagonal), from one `n × n` lattice of sub-cells ([`TaylorBound::lattice`]) shared by
    /// all four: a half's leaves are halves of the sub-cells it meets, each bounded by the
    /// sub-cell's [`TaylorBound::cell_error`] plus the largest `|S − L_half|` at the leaf's
    /// corners, which are the sub-cell's corners inside the half. Cost: `(n + 1)²`
    /// positions and `n²` evaluations of the second derivatives, against four times
    /// [`TaylorBound::split_error`]'s.
    fn cell_split_error(&self, origin: DVec2, hu: f64, hv: f64) -> f64 {
        if let SecondDerivatives::Tree { whole, .. } = &self.field {
            return match self.leaf_cell(origin, hu, hv) {
                Some((leaf, o, hu, hv)) => leaf.cell_split_error(o, hu, hv),
                None => whole.cell_split_error(origin, hu, hv),
            };
        }
        let n = self.lattice();
        let point = |i: usize, j: usize| origin + DVec2::new(hu * i as f64, hv * j as f64) / n as f64;
        let mut at = [[DVec3::ZERO; MAX_LATTICE + 1]; MAX_LATTICE + 1];
        for (i, row) in at.iter_mut().enumerate().take(n + 1) {
            for (j, p) in row.iter_mut().enumerate().take(n + 1) {
                *p = self.position(point(i, j));
            }
        }
        // A sampled bound's sub-cells all have the same bound: a half's is then that plus the
        // largest error at its lattice points (each a leaf corner inside it).
        let uniform = match &self.field {
            SecondDerivatives::Sampled { m, .. } => Some(m.cell_error(hu / n as f64, hv / n as f64)),
            _ => None,
        };
        let mut sub = [[0.0f64; MAX_LATTICE]; MAX_LATTICE];
        for (i, row) in sub.iter_mut().enumerate().take(n).filter(|_| uniform.is_none()) {
            for (j, e) in row.iter_mut().enumerate().take(n) {
                *e = self.cell_error(
                    point(i, j) + DVec2::new(hu, hv) / (2 * n) as f64,
                    hu / n as f64,
                    hv / n as f64,
                );
            }
        }
        let (a, b, c, d) = (at[0][0], at[n][0], at[0][n], at[n][n]);
        // Each half in the lattice's integer coordinates: whether (i, j) lies in it (an
        // `n`-lattice), and its linear interpolant there (x = i/n, y = j/n).
        type Half = (fn(usize, usize, usize) -> bool, fn([DVec3; 4], f64, f64) -> DVec3);
        let halves: [Half; 4] = [
            (|i, j, n| i + j <= n, |[a, b, c, _], x, y| a * (1.0 - x - y) + b * x + c * y),
            (|i, j, n| i + j >= n, |[_, b, c, d], x, y| b * (1.0 - y) + c * (1.0 - x) + d * (x + y - 1.0)),
            (|i, j, _| i >= j, |[a, b, _, d], x, y| a * (1.0 - x) + b * (x - y) + d * y),
            (|i, j, _| j >= i, |[a, _, c, d], x, y| a * (1.0 - y) + c * (y - x) + d * x),
        ];
        let mut worst = 0.0f64;
        for (inside, linear) in halves {
            let mut error = [[0.0f64; MAX_LATTICE + 1]; MAX_LATTICE + 1];
            for (i, row) in error.iter_mut().enumerate().take(n + 1) {
                for (j, e) in row.iter_mut().enumerate().take(n + 1) {
                    if inside(i, j, n) {
                        let l = linear([a, b, c, d], i as f64 / n as f64, j as f64 / n as f64);
                        *e = (at[i][j] - l).length();
                    }
                }
            }
            if let Some(sub) = uniform {
                worst = worst.max(sub + error.as_flattened().iter().fold(0.0f64, |a, &e| a.max(e)));
                continue;
            }
            for (i, row) in sub.iter().enumerate().take(n) {
                for (j, own) in row.iter().enumerate().take(n) {
                    let corners = [(i, j), (i + 1, j), (i, j + 1), (i + 1, j + 1)];
                    let (count, corner) = corners
                        .into_iter()
                        .filter(|&(ci, cj)| inside(ci, cj, n))
                        .fold((0, 0.0f64), |(k, e), (ci, cj)| (k + 1, e.max(error[ci][cj])));
                    // A sub-cell meets the half in a leaf where three of its corners lie in
                    // it (the half's sides run along sub-cell sides and diagonals); with
                    // fewer, in a side or a point that its neighbours' leaves hold.
                    if count >= 3 {
                        worst = worst.max(own + corner);
                    }
                }
            }
        }
        worst
    }

    /// A bound over every triangle of the `nu × nv` grid at once (as
    /// [`TaylorBound::grid_error`]), from the second derivatives' Bézier nets rather than
    /// their values at each cell: each cell's bound ([`TaylorBound::cell_error`]) is
    /// `bubble_max(|m_d|, |m_u|, |m_v|)` plus the remainder, with `m_u = S_uu·hu²/8`,
    /// `m_v = S_vv·hv²/8` and `m_d = (S_uu·hu² ∓ 2·S_uv·hu·hv + S_vv·hv²)/8` at the cell's
    /// centre. Each is a polynomial in the position — a bicubic's three nets, degree-elevated
    /// to one 4 × 4 net; a cubic triangle's linear field, whose net is its corners — so its
    /// norm is at most the largest norm of its control points (convex hull), and `bubble_max`
    /// grows with each argument: the bound of the largest control points holds for every
    /// cell. Tighter than the second-derivative bound (the three terms stay vectors, summed
    /// before their norm), looser than the walk (one net for all cells). Infinite for other
    /// kinds. Cost: 16 control points (3 for a triangle), whatever the grid.
    pub fn nets_grid_error(&self, triangle_domain: bool, [nu, nv]: [u32; 2]) -> f64 {
        let (hu, hv) = (1.0 / nu as f64, 1.0 / nv as f64);
        let (mut legs_u, mut legs_v, mut diagonal) = (0.0f64, 0.0f64, 0.0f64);
        let mut take = |[a, b, c]: [DVec3; 3]| {
            let (a, b, c) = (a * (hu * hu), b * (2.0 * hu * hv), c * (hv * hv));
            legs_u = legs_u.max(a.length());
            legs_v = legs_v.max(c.length());
            // A triangle's grid splits every cell along `u + v = const`; a quad's either way.
            let rising = if triangle_domain { 0.0 } else { (a + c + b).length() };
            diagonal = diagonal.max((a + c - b).length().max(rising));
        };
        match &self.field {
            SecondDerivatives::Bicubic { uu, uv, vv, .. } => {
                let uu: [[DVec3; 4]; 4] = elevate_u(&elevate_u::<2, 4, 3>(uu));
                let uv: [[DVec3; 4]; 4] = elevate_v(&elevate_u::<3, 3, 4>(uv));
                let vv: [[DVec3; 4]; 4] = elevate_v(&elevate_v::<4, 2, 3>(vv));
                for i in 0..4 {
                    for j in 0..4 {
                        take([uu[i][j], uv[i][j], vv[i][j]]);
                    }
                }
            }
            SecondDerivatives::Triangle { corners, .. } => corners.iter().for_each(|&c| take(c)),
            _ => return f64::INFINITY,
        }
        bubble_max([diagonal, legs_u, legs_v].map(|m| m / 8.0)) + self.remainder(DVec2::new(hu, hv) / 2.0)
    }

    /// The lattice of [`TaylorBound::split_error`] and [`TaylorBound::cell_split_error`]:
    /// [`SAMPLED_LATTICE`] for the sampled bound, [`SPLIT_LATTICE`] for an expansion.
    fn lattice(&self) -> usize {
        match self.field {
            SecondDerivatives::Sampled { .. } => SAMPLED_LATTICE,
            _ => SPLIT_LATTICE,
        }
    }

    /// The bound over every triangle of the `nu × nv` grid of the unit square, whichever way
    /// its cells are split. On a triangle domain (`nu = nv = n`) the grid is the barycentric
    /// lattice the patterns build (`pattern::uniform::grid`, the transition pattern's core):
    /// cells split along `u + v = const`, the cells on the diagonal `u + v = 1` keeping their
    /// lower half. Cost: one evaluation per cell (two per triangle-domain cell), and a
    /// refinement for each cell that raises the largest bound so far.
    pub fn grid_error(&self, triangle_domain: bool, n: [u32; 2]) -> f64 {
        self.grid_error_above(triangle_domain, n, 0.0, f64::INFINITY, f64::INFINITY)
    }

    /// [`TaylorBound::grid_error`] with each cell's bound at most `cap` (another valid bound
    /// of every cell, the second-derivative bound's): where a tree's cell straddles leaves,
    /// the cap answers for that cell alone.
    pub(crate) fn grid_error_within(&self, triangle_domain: bool, n: [u32; 2], cap: f64) -> f64 {
        self.grid_error_above(triangle_domain, n, 0.0, f64::INFINITY, cap)
    }

    /// Whether [`TaylorBound::grid_error_within`] `cap` is at most `eps`, cheaper: only cells
    /// whose plain bound exceeds `eps` are refined, and the walk stops at the first that
    /// still does.
    pub(crate) fn grid_fits(&self, triangle_domain: bool, n: [u32; 2], eps: f64, cap: f64) -> bool {
        self.grid_error_above(triangle_domain, n, eps, eps, cap) <= eps
    }

    /// `max(floor, grid_error_within(cap))`, refining (hull, split) only the cells whose
    /// plain bound exceeds the largest so far, and returning early, with some value above
    /// `stop`, once the largest exceeds it.
    fn grid_error_above(
        &self,
        triangle_domain: bool,
        [nu, nv]: [u32; 2],
        floor: f64,
        stop: f64,
        cap: f64,
    ) -> f64 {
        if !self.is_some() {
            return floor.max(cap);
        }
        debug_assert!(!triangle_domain || nu == nv, "a triangle's grids are n × n");
        let (hu, hv) = (1.0 / nu as f64, 1.0 / nv as f64);
        let mut worst = floor;
        let full = nu as u64 * nv as u64;
        if !self.refines && full > EXPANSION_WALK_CELLS {
            return worst.max(self.nets_grid_error(triangle_domain, [nu, nv]).min(cap));
        }
        for i in 0..nu {
            for j in 0..nv {
                // `(i + di)/nu + (j + dj)/nv` against `full / full = 1`, in integers.
                let beyond = |di: u64, dj: u64| (i as u64 + di) * nv as u64 + (j as u64 + dj) * nu as u64;
                if triangle_domain && beyond(0, 0) >= full {
                    continue; // the cell lies beyond the diagonal
                }
                let o = DVec2::new(i as f64 * hu, j as f64 * hv);
                let [a, b, c, d] =
                    [o, o + DVec2::new(hu, 0.0), o + DVec2::new(0.0, hv), o + DVec2::new(hu, hv)];
                let error = if !triangle_domain {
                    let cell = self.cell_error((a + d) / 2.0, hu, hv).min(cap);
                    if cell > worst && self.refines {
                        cell.min(self.cell_split_error(o, hu, hv))
                    } else {
                        cell
                    }
                } else if beyond(1, 1) > full {
                    // On the diagonal: the lower half alone.
                    self.triangle_error_above([a, b, c], worst).min(cap)
                } else {
                    let lower = self.triangle_error_above([a, b, c], worst).min(cap);
                    lower.max(self.triangle_error_above([b, d, c], worst.max(lower)).min(cap))
                };
                worst = worst.max(error);
                if worst > stop {
                    return worst;
                }
            }
        }
        worst
    }
}

/// The largest value over a triangle of `Σ a_i·4λ_jλ_k` (`a_i ≥ 0`, `{i, j, k} = {0, 1, 2}`):
/// on the edges `max a_i` (at a midpoint); inside, the critical point of the quadratic, which
/// Lagrange's condition puts at `λ_i ∝ a_i·(a_0 + a_1 + a_2 − 2a_i)` and which lies inside
/// only when every factor is positive. The maximum over the triangle is the larger of the
/// two. Cost: O(1).
pub fn bubble_max(a: [f64; 3]) -> f64 {
    let edges = a[0].max(a[1]).max(a[2]);
    let s = a[0] + a[1] + a[2];
    let l = a.map(|ai| ai * (s - 2.0 * ai));
    let total = l[0] + l[1] + l[2];
    if l.iter().all(|&x| x > 0.0) && total > 0.0 {
        let l = l.map(|x| x / total);
        let inside = 4.0 * (a[0] * l[1] * l[2] + a[1] * l[2] * l[0] + a[2] * l[0] * l[1]);
        edges.max(inside)
    } else {
        edges
    }
}

/// The control net a patch's expansion bound is computed from ([`TaylorBound::expansion`]):
/// the rule of which patches have one, for every engine (the GPU uploads these nets for its
/// expansion bound).
#[derive(Debug, Clone, Copy)]
pub enum ExpansionNet<'a> {
    /// A polynomial bicubic's 16 points, `4i + j` with `i` along u.
    Bicubic(&'a [DVec3; 16]),
    /// A cubic Bézier triangle, or a PN triangle's geometry: 10 points at
    /// [`BezierTriangle::index`].
    Triangle(&'a BezierTriangle),
}

impl ExpansionNet<'_> {
    /// `patch`'s net; None for every patch without an expansion bound (rational bicubics,
    /// subdivision and Loop patches). Cost: O(1), a bicubic's weights checked.
    pub fn of(patch: &Patch) -> Option<ExpansionNet<'_>> {
        match patch {
            Patch::Bicubic(b) if b.is_polynomial() => Some(ExpansionNet::Bicubic(&b.points)),
            Patch::BezierTriangle(t) => Some(ExpansionNet::Triangle(t)),
            Patch::Pn(pn) => Some(ExpansionNet::Triangle(&pn.geometry)),
            _ => None,
        }
    }

    /// The net's points in storage order (16 or 10).
    pub fn points(&self) -> &[DVec3] {
        match self {
            ExpansionNet::Bicubic(points) => &points[..],
            ExpansionNet::Triangle(t) => &t.points[..],
        }
    }
}

/// Where a cubic triangle's remainder exceeds this share of its quadratic part, its error is
/// also bounded by its control points ([`cubic_error_hull`]): below it the hull changed no
/// plan of the mesh models (1 %, 0.1 %, 0.01 %) and doubled the planning time.
pub const HULL_WHEN: f64 = 0.05;

/// The lattice of [`TaylorBound::split_error`] for a Taylor expansion: `n` parts a side,
/// `n²` leaves. Its leaves' own bounds are an expansion's, a sixteenth of the whole's and
/// close to the truth, so a finer lattice gains little: 8 cut the teapot's triangles at 0.1 %
/// by 4 % for 3.5 times the planning.
const SPLIT_LATTICE: usize = 4;

/// The lattice of the sampled bound ([`SecondDerivatives::Sampled`]), whose leaves' margin is
/// the patch's second-derivative bound, `1/n²` of it: that bound is loose where the sampled
/// bound serves (a Catmull-Clark tree's Gregory end caps, whose interior blends weigh in it
/// at every corner; rational weights), so the margin is cut four times further. At 0.1 %
/// with 4 against 8: `catmark_cube` 5,804 → 4,328 triangles, `catmark_helmet` 35,682 →
/// 27,354 (planning 1.5–3 times longer).
const SAMPLED_LATTICE: usize = 8;

/// The largest lattice, which sizes the refinements' buffers.
const MAX_LATTICE: usize = 8;

/// A bound on `|S − L|` over the parameter triangle `t` of the cubic Bézier triangle with
/// points `net`, `L` the linear interpolant at `t`'s corners: `S − L` is a cubic vanishing at
/// the corners; on each of `t`'s four midpoint sub-triangles its Bézier control points are the
/// blossom of `S` at the sub-triangle's corners less `L` at their Greville points, and the
/// largest of their norms bounds it there (convex hull). The split makes the hull tight to a
/// few per cent on the coarse triangles it serves (one triangle a patch: 0.94 of the measured
/// error on `spot`'s PN triangles, against 0.35 for the second-derivative bound).
/// Cost: four blossom nets (about 200 point combinations).
pub fn cubic_error_hull(net: &[DVec3; 10], t: [DVec2; 3]) -> f64 {
    let bary = |x: DVec2| DVec3::new(1.0 - x.x - x.y, x.x, x.y);
    let m = [(t[1] + t[2]) / 2.0, (t[2] + t[0]) / 2.0, (t[0] + t[1]) / 2.0];
    let surface = BezierTriangle { points: *net };
    let at = t.map(|x| surface.position(x));
    // L is affine: at a midpoint, the mean of its ends.
    let l_mid = [(at[1] + at[2]) / 2.0, (at[2] + at[0]) / 2.0, (at[0] + at[1]) / 2.0];
    let subs = [
        ([t[0], m[2], m[1]], [at[0], l_mid[2], l_mid[1]]),
        ([m[2], t[1], m[0]], [l_mid[2], at[1], l_mid[0]]),
        ([m[1], m[0], t[2]], [l_mid[1], l_mid[0], at[2]]),
        ([m[0], m[1], m[2]], [l_mid[0], l_mid[1], l_mid[2]]),
    ];
    let mut worst = 0.0f64;
    for (corners, l) in subs {
        let points = sub_net(net, corners.map(bary));
        for i in 0..=3usize {
            for j in 0..=3 - i {
                let k = 3 - i - j;
                // Exponents (i, j, k) of the sub-triangle's corners 0, 1, 2.
                let linear = (l[0] * i as f64 + l[1] * j as f64 + l[2] * k as f64) / 3.0;
                worst = worst.max((points[BezierTriangle::index(i, j, k)] - linear).length());
            }
        }
    }
    worst
}

/// Index of `(i, j)` (`i + j ≤ d`) in a degree-`d` net listed by `i`, then `j`.
const fn net_index(d: usize, i: usize, j: usize) -> usize {
    i * (d + 1) - i * i.saturating_sub(1) / 2 + j
}

/// One de Casteljau step of a degree-`d` triangle net (listed as [`net_index`], `(i, j)` the
/// exponents of `λ0` and `u`) at the barycentric point `p = (λ0, u, v)`: the degree `d − 1`
/// net, into `out`.
fn casteljau_step<const IN: usize, const OUT: usize>(
    d: usize,
    net: &[DVec3; IN],
    p: DVec3,
    out: &mut [DVec3; OUT],
) {
    for i in 0..d {
        for j in 0..d - i {
            // (i, j, k) of degree d − 1 reads (i+1, j, k), (i, j+1, k), (i, j, k+1) of degree d.
            out[net_index(d - 1, i, j)] = net[net_index(d, i + 1, j)] * p.x
                + net[net_index(d, i, j + 1)] * p.y
                + net[net_index(d, i, j)] * p.z;
        }
    }
}

/// The control points, in [`BezierTriangle::index`] order, of the cubic Bézier triangle `net`
/// over the sub-triangle with barycentric corners `p`: the blossom `f(p0^i, p1^j, p2^k)` for
/// each `(i, j, k)`, its de Casteljau levels shared (3 + 6 + 10 steps).
// The levels are written in place: built by `std::array::from_fn`, their arrays were at times
// moved through memory, which took 40 % of a PN mesh's planning (the bunny at 0.01 %).
fn sub_net(net: &[DVec3; 10], p: [DVec3; 3]) -> [DVec3; 10] {
    let mut listed = [DVec3::ZERO; 10];
    for (n, slot) in listed.iter_mut().enumerate() {
        let i = [0, 0, 0, 0, 1, 1, 1, 2, 2, 3][n];
        let j = n - net_index(3, i, 0);
        *slot = net[BezierTriangle::index(i, j, 3 - i - j)];
    }
    let mut one = [[DVec3::ZERO; 6]; 3];
    for (a, level) in one.iter_mut().enumerate() {
        casteljau_step(3, &listed, p[a], level);
    }
    // Level two for a ≤ b (the blossom is symmetric), level three for a ≤ b ≤ c.
    let mut two = [[[DVec3::ZERO; 3]; 3]; 3];
    for (a, row) in two.iter_mut().enumerate() {
        for (b, level) in row.iter_mut().enumerate() {
            casteljau_step(2, &one[a.min(b)], p[a.max(b)], level);
        }
    }
    let mut out = [DVec3::ZERO; 10];
    for i in 0..=3usize {
        for j in 0..=3 - i {
            let k = 3 - i - j;
            // The multiset {0^i, 1^j, 2^k}, sorted.
            let arg = |slot: usize| {
                if slot < i {
                    0
                } else if slot < i + j {
                    1
                } else {
                    2
                }
            };
            let mut last = [DVec3::ZERO; 1];
            casteljau_step(1, &two[arg(0)][arg(1)], p[arg(2)], &mut last);
            out[BezierTriangle::index(i, j, k)] = last[0];
        }
    }
    out
}

/// The largest grid (in cells) whose cells [`TaylorBound::expansion`]'s grid bound walks one
/// by one; a larger one takes [`TaylorBound::nets_grid_error`]. The walk keeps the plans'
/// every gain at 0.1 % (teapot, teacup, spot, cow: the same triangles as an unlimited walk;
/// 256 cells cost the teapot 3 %) and bounds a check's work a step: a 32 × 32 core.
pub const EXPANSION_WALK_CELLS: u64 = 1024;

/// A tensor net `M × N` raised one degree along u (the first index): the same polynomial,
/// `P'_i = (i/M)·P_{i−1} + (1 − i/M)·P_i`.
fn elevate_u<const M: usize, const N: usize, const M1: usize>(net: &[[DVec3; N]; M]) -> [[DVec3; N]; M1] {
    debug_assert_eq!(M1, M + 1);
    std::array::from_fn(|i| {
        let t = i as f64 / M as f64;
        std::array::from_fn(|j| {
            let lower = if i > 0 { net[i - 1][j] * t } else { DVec3::ZERO };
            let upper = if i < M { net[i][j] * (1.0 - t) } else { DVec3::ZERO };
            lower + upper
        })
    })
}

/// A tensor net `M × N` raised one degree along v (the second index), as [`elevate_u`].
fn elevate_v<const M: usize, const N: usize, const N1: usize>(net: &[[DVec3; N]; M]) -> [[DVec3; N1]; M] {
    debug_assert_eq!(N1, N + 1);
    std::array::from_fn(|i| {
        std::array::from_fn(|j| {
            let t = j as f64 / N as f64;
            let lower = if j > 0 { net[i][j - 1] * t } else { DVec3::ZERO };
            let upper = if j < N { net[i][j] * (1.0 - t) } else { DVec3::ZERO };
            lower + upper
        })
    })
}

/// `f₃(Δ)/3` with third-derivative bounds `t` (module doc).
fn remainder_with(t: [f64; 4], delta: DVec2) -> f64 {
    let (a, b) = (delta.x.abs(), delta.y.abs());
    let [t0, t1, t2, t3] = t;
    (t0 * a * a * a + 3.0 * t1 * a * a * b + 3.0 * t2 * a * b * b + t3 * b * b * b) / 3.0
}

/// Bernstein weights of degree `n ≤ 3` at `t`.
fn bernstein(n: usize, t: f64) -> [f64; 4] {
    let s = 1.0 - t;
    match n {
        0 => [1.0, 0.0, 0.0, 0.0],
        1 => [s, t, 0.0, 0.0],
        2 => [s * s, 2.0 * s * t, t * t, 0.0],
        _ => [s * s * s, 3.0 * s * s * t, 3.0 * s * t * t, t * t * t],
    }
}

/// A tensor Bézier patch with `M × N` points (`net[i][j]`, `i` along u) at `x`.
fn net_at<const M: usize, const N: usize>(net: &[[DVec3; N]; M], x: DVec2) -> DVec3 {
    let (bu, bv) = (bernstein(M - 1, x.x), bernstein(N - 1, x.y));
    let mut out = DVec3::ZERO;
    for (i, row) in net.iter().enumerate() {
        let mut r = DVec3::ZERO;
        for (j, p) in row.iter().enumerate() {
            r += *p * bv[j];
        }
        out += r * bu[i];
    }
    out
}

/// A polynomial bicubic's second-derivative nets (`6·Δ²_u b`, `9·ΔuΔv b`, `6·Δ²_v b`) and
/// third-derivative bounds: `S_uuu = 6 Σ Δ³_u b·B³(v)`, `S_uuv = 18 Σ Δ²_uΔ_v b·B¹(u)B²(v)`,
/// and their mirrors, each at most its largest coefficient.
fn bicubic(points: &[DVec3; 16]) -> TaylorBound {
    bicubic_with_third(points).0
}

/// [`bicubic`] and the nets of its third derivatives ([`ThirdDerivatives`]), whose largest
/// control vectors are its third-derivative bounds.
fn bicubic_with_third(points: &[DVec3; 16]) -> (TaylorBound, ThirdDerivatives) {
    let b = |i: usize, j: usize| points[4 * i + j];
    let du = |i: usize, j: usize| b(i + 1, j) - b(i, j);
    let duu = |i: usize, j: usize| du(i + 1, j) - du(i, j);
    let duv = |i: usize, j: usize| du(i, j + 1) - du(i, j);
    let dvv = |i: usize, j: usize| b(i, j + 2) - 2.0 * b(i, j + 1) + b(i, j);
    let uu: [[DVec3; 4]; 2] = std::array::from_fn(|i| std::array::from_fn(|j| duu(i, j) * 6.0));
    let uv: [[DVec3; 3]; 3] = std::array::from_fn(|i| std::array::from_fn(|j| duv(i, j) * 9.0));
    let vv: [[DVec3; 2]; 4] = std::array::from_fn(|i| std::array::from_fn(|j| dvv(i, j) * 6.0));
    let third = ThirdDerivatives::new(
        std::array::from_fn(|j| duu(1, j) - duu(0, j)),
        std::array::from_fn(|i| std::array::from_fn(|j| duu(i, j + 1) - duu(i, j))),
        std::array::from_fn(|i| std::array::from_fn(|j| dvv(i + 1, j) - dvv(i, j))),
        std::array::from_fn(|i| dvv(i, 1) - dvv(i, 0)),
    );
    let uuu = max_norm(third.uuu.iter().map(|&d| d * 6.0));
    let uuv = max_norm(third.uuv.iter().flatten().map(|&d| d * 18.0));
    let uvv = max_norm(third.uvv.iter().flatten().map(|&d| d * 18.0));
    let vvv = max_norm(third.vvv.iter().map(|&d| d * 6.0));
    let bound = TaylorBound {
        field: SecondDerivatives::Bicubic {
            uu,
            uv,
            vv,
            points: std::array::from_fn(|i| std::array::from_fn(|j| b(i, j))),
        },
        third: [uuu, uuv, uvv, vvv],
        refines: true,
        local: None,
    };
    (bound, third)
}

/// A cubic Bézier triangle's second derivatives at its corners and its (constant) third
/// derivatives. With `b(i, j, k)` (`i` the exponent of `λ0 = 1 − u − v`, `j` of `u`, `k` of
/// `v`), `∂/∂u` is the difference `E_j − E_i` and `∂/∂v` is `E_k − E_i`: so
/// `S_uu = 6 Σ (E_j − E_i)² b · B¹` and `S_uuu = 6 (E_j − E_i)³ b_000`, and so on.
fn triangle(t: &BezierTriangle) -> TaylorBound {
    let b = |i: usize, j: usize, k: usize| t.b(i, j, k);
    // The difference operators applied at base (i, j, k) of degree 3 − order.
    let d_uu = |i, j, k| b(i, j + 2, k) - 2.0 * b(i + 1, j + 1, k) + b(i + 2, j, k);
    let d_uv = |i, j, k| b(i, j + 1, k + 1) - b(i + 1, j, k + 1) - b(i + 1, j + 1, k) + b(i + 2, j, k);
    let d_vv = |i, j, k| b(i, j, k + 2) - 2.0 * b(i + 1, j, k + 1) + b(i + 2, j, k);
    let corners = [(1, 0, 0), (0, 1, 0), (0, 0, 1)]
        .map(|(i, j, k)| [d_uu(i, j, k), d_uv(i, j, k), d_vv(i, j, k)].map(|d| d * 6.0));
    // Third differences: one more (E_j − E_i) or (E_k − E_i) on the second ones.
    let uuu = d_uu(0, 1, 0) - d_uu(1, 0, 0);
    let uuv = d_uu(0, 0, 1) - d_uu(1, 0, 0);
    let uvv = d_vv(0, 1, 0) - d_vv(1, 0, 0);
    let vvv = d_vv(0, 0, 1) - d_vv(1, 0, 0);
    TaylorBound {
        field: SecondDerivatives::Triangle { corners, net: t.points },
        third: [uuu, uuv, uvv, vvv].map(|d| 6.0 * d.length()),
        refines: true,
        local: None,
    }
}

/// A quartic Bézier triangle's bound: its second derivatives are the quadratic triangles
/// `12 Σ Δ² b · B²` ([`QuarticTriangle::second_derivatives`]); its third derivatives the
/// linear ones `24 Σ Δ³ b · B¹`, whose largest control vector bounds each (convex hull), the
/// third differences being one more `E_j − E_i` (along u) or `E_k − E_i` (along v) on the
/// second ones, as for the cubic ([`triangle`]).
fn quartic(q: &QuarticTriangle) -> TaylorBound {
    let b = |i: usize, j: usize, k: usize| q.b(i, j, k);
    // The second differences at base (i, j, k), i + j + k = 2.
    let d_uu = |i, j, k| b(i, j + 2, k) - 2.0 * b(i + 1, j + 1, k) + b(i + 2, j, k);
    let d_vv = |i, j, k| b(i, j, k + 2) - 2.0 * b(i + 1, j, k + 1) + b(i + 2, j, k);
    let linear = [(1, 0, 0), (0, 1, 0), (0, 0, 1)];
    let third = |f: &dyn Fn(usize, usize, usize) -> DVec3| {
        24.0 * max_norm(linear.iter().map(|&(i, j, k)| f(i, j, k)))
    };
    let uuu = third(&|i, j, k| d_uu(i, j + 1, k) - d_uu(i + 1, j, k));
    let uuv = third(&|i, j, k| d_uu(i, j, k + 1) - d_uu(i + 1, j, k));
    let uvv = third(&|i, j, k| d_vv(i, j + 1, k) - d_vv(i + 1, j, k));
    let vvv = third(&|i, j, k| d_vv(i, j, k + 1) - d_vv(i + 1, j, k));
    TaylorBound {
        field: SecondDerivatives::Quartic { net: q.clone() },
        third: [uuu, uuv, uvv, vvv],
        refines: true,
        local: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::RationalBicubic;
    use crate::test_support::Lcg;

    fn second_by_differences(p: &Patch, x: DVec2) -> [DVec3; 3] {
        let h = 1e-4;
        let f = |dx: f64, dy: f64| p.position(x + DVec2::new(dx, dy));
        [
            (f(h, 0.0) - 2.0 * f(0.0, 0.0) + f(-h, 0.0)) / (h * h),
            (f(h, h) - f(h, -h) - f(-h, h) + f(-h, -h)) / (4.0 * h * h),
            (f(0.0, h) - 2.0 * f(0.0, 0.0) + f(0.0, -h)) / (h * h),
        ]
    }

    fn random_net(rng: &mut Lcg) -> Vec<DVec3> {
        (0..16).map(|_| DVec3::new(rng.unit(), rng.unit(), rng.unit()) * 2.0 - DVec3::ONE).collect()
    }

    /// A tree answers a triangle from the one Bézier leaf that holds it, in that leaf's
    /// parameters: small triangles of trees without end caps nearly all find theirs (their
    /// leaves are at least 1/64 across), and the leaf's bound then equals the one computed
    /// from the leaf's own triangle.
    #[test]
    fn a_tree_answers_from_the_leaf_that_holds_the_triangle() {
        let mut rng = Lcg(11);
        let (mut tried, mut found) = (0, 0);
        // Whole quads, turned sub-faces of n-gons and quadrants of quads with creases.
        let cages = ["catmark_torus_creases0.obj", "catmark_nonquads.obj", "catmark_tent_creases0.obj"];
        let sets = cages.map(|cage| {
            let path = crate::test_support::data(&format!("subdivision/{cage}"));
            let surface = crate::io::SurfaceKind::CatmullClark;
            crate::io::load(&path, crate::io::LoadOptions { surface, ..Default::default() }).unwrap()
        });
        for patch in sets.iter().flat_map(|set| &set.patches) {
            let Patch::Subdivision(tree) = patch else { continue };
            if tree.leaves().iter().any(|l| matches!(l.patch, LeafPatch::Gregory(_))) {
                continue;
            }
            let bound = TaylorBound::of(patch);
            for _ in 0..20 {
                let c = DVec2::new(0.01 + 0.98 * rng.unit(), 0.01 + 0.98 * rng.unit());
                let t = [c, c + DVec2::new(0.004, 0.0), c + DVec2::new(0.0, 0.004)];
                tried += 1;
                let Some((leaf, local)) = bound.leaf_of(t) else { continue };
                found += 1;
                // The leaf's point at the local parameters is the patch's at the corner.
                for (q, l) in t.iter().zip(local) {
                    assert!(l.min_element() >= 0.0 && l.max_element() <= 1.0);
                    assert!(leaf.position(l).distance(patch.position(*q)) < 1e-12, "{q} → {l}");
                }
                assert_eq!(bound.triangle_error(t), leaf.triangle_error(local));
            }
        }
        assert!(tried > 0 && found * 10 >= tried * 9, "{found} of {tried} small triangles inside one leaf");
    }

    /// The second-derivative fields equal the surfaces' own, measured by central differences.
    #[test]
    fn second_derivatives_are_the_surfaces() {
        let mut rng = Lcg(3);
        for _ in 0..20 {
            let net = random_net(&mut rng);
            let bicubic = Patch::Bicubic(RationalBicubic::polynomial(std::array::from_fn(|k| net[k])));
            let tri = Patch::BezierTriangle(BezierTriangle { points: std::array::from_fn(|k| net[k]) });
            for p in [bicubic, tri] {
                let taylor = TaylorBound::of(&p);
                for _ in 0..20 {
                    let x = DVec2::new(0.1 + 0.4 * rng.unit(), 0.1 + 0.4 * rng.unit());
                    let (got, want) = (taylor.second_derivatives(x), second_by_differences(&p, x));
                    for k in 0..3 {
                        assert!(
                            got[k].distance(want[k]) < 1e-5 * (1.0 + want[k].length()),
                            "{k}: {got:?} {want:?}"
                        );
                    }
                }
            }
        }
    }

    /// The blossom at one point three times is the surface there; the hull bounds the error.
    #[test]
    fn the_blossom_is_the_surface_on_its_diagonal_and_the_hull_bounds_the_error() {
        let mut rng = Lcg(5);
        for _ in 0..50 {
            let net = random_net(&mut rng);
            let t = BezierTriangle { points: std::array::from_fn(|k| net[k]) };
            let x = DVec2::new(0.6 * rng.unit(), 0.4 * rng.unit());
            let b = DVec3::new(1.0 - x.x - x.y, x.x, x.y);
            let at_x = sub_net(&t.points, [b; 3]);
            assert!(at_x.iter().all(|q| q.distance(t.position(x)) < 1e-12), "{at_x:?}");
            let whole = [DVec3::X, DVec3::Y, DVec3::Z];
            assert_eq!(sub_net(&t.points, whole), t.points, "the whole triangle's net is its own");
            let tri = [DVec2::ZERO, DVec2::new(0.5, 0.1), DVec2::new(0.2, 0.6)];
            let corners = tri.map(|q| t.position(q));
            let mut measured = 0.0f64;
            for i in 0..=30 {
                for j in 0..=30 - i {
                    let (a, c) = (i as f64 / 30.0, j as f64 / 30.0);
                    let q = tri[0] * (1.0 - a - c) + tri[1] * a + tri[2] * c;
                    let l = corners[0] * (1.0 - a - c) + corners[1] * a + corners[2] * c;
                    measured = measured.max(t.position(q).distance(l));
                }
            }
            let hull = cubic_error_hull(&t.points, tri);
            assert!(measured <= hull * (1.0 + 1e-12) && hull <= 1.5 * measured, "{measured} {hull}");
        }
    }

    /// The third derivatives' nets are the surface's (central differences of its second
    /// derivatives), and their bounds near a point hold at every point of the box.
    #[test]
    fn third_derivatives_near_a_point_bound_them_on_the_box() {
        let mut rng = Lcg(31);
        for _ in 0..20 {
            let net = random_net(&mut rng);
            let points: [DVec3; 16] = std::array::from_fn(|k| net[k]);
            let patch = Patch::Bicubic(RationalBicubic::polynomial(points));
            let (taylor, third) = (TaylorBound::of(&patch), bicubic_with_third(&points).1);
            for _ in 0..10 {
                let x = DVec2::new(0.1 + 0.8 * rng.unit(), 0.1 + 0.8 * rng.unit());
                let h = 1e-5;
                let d = |dx: DVec2| {
                    let (p, m) = (taylor.second_derivatives(x + dx), taylor.second_derivatives(x - dx));
                    [0, 1, 2].map(|k| (p[k] - m[k]) / (2.0 * h))
                };
                let (du, dv) = (d(DVec2::new(h, 0.0)), d(DVec2::new(0.0, h)));
                // S_uuu, S_uuv (= ∂_v S_uu), S_uvv (= ∂_u S_vv), S_vvv.
                let want = [du[0].length(), dv[0].length(), du[2].length(), dv[2].length()];
                let got = third.near(x, DVec2::ZERO);
                for k in 0..4 {
                    assert!((got[k] - want[k]).abs() <= 1e-5 * (1.0 + want[k]), "{k}: {got:?} {want:?}");
                }
                let g = DVec2::new(rng.unit(), rng.unit());
                let delta = DVec2::new(0.3 * rng.unit(), 0.3 * rng.unit());
                let box_bound = third.near(g, delta);
                let y = (g + (DVec2::new(rng.unit(), rng.unit()) * 2.0 - DVec2::ONE) * delta)
                    .clamp(DVec2::ZERO, DVec2::ONE);
                let at_y = third.near(y, DVec2::ZERO);
                for k in 0..4 {
                    assert!(at_y[k] <= box_bound[k] * (1.0 + 1e-12) + 1e-12, "{k}: {at_y:?} {box_bound:?}");
                }
            }
        }
    }

    /// Degree elevation keeps a net's polynomial.
    #[test]
    fn elevated_nets_are_the_same_polynomials() {
        let mut rng = Lcg(17);
        let net = random_net(&mut rng);
        let uu: [[DVec3; 4]; 2] = std::array::from_fn(|i| std::array::from_fn(|j| net[4 * i + j]));
        let raised: [[DVec3; 4]; 3] = elevate_u(&uu);
        let vv: [[DVec3; 2]; 4] = std::array::from_fn(|i| std::array::from_fn(|j| net[2 * i + j]));
        let raised_v: [[DVec3; 3]; 4] = elevate_v(&vv);
        for _ in 0..20 {
            let x = DVec2::new(rng.unit(), rng.unit());
            assert!(net_at(&uu, x).distance(net_at(&raised, x)) < 1e-12);
            assert!(net_at(&vv, x).distance(net_at(&raised_v, x)) < 1e-12);
        }
    }

    /// The largest `|S − L|` over the triangles every grid of `n` cells can have (a quad's
    /// cells split either way; a triangle's lattice halves), sampled densely.
    fn measured_grid_error(p: &Patch, triangle_domain: bool, [nu, nv]: [u32; 2]) -> f64 {
        let (hu, hv) = (1.0 / nu as f64, 1.0 / nv as f64);
        let mut worst = 0.0f64;
        for i in 0..nu {
            for j in 0..nv {
                let o = DVec2::new(i as f64 * hu, j as f64 * hv);
                let [a, b, c, d] =
                    [o, o + DVec2::new(hu, 0.0), o + DVec2::new(0.0, hv), o + DVec2::new(hu, hv)];
                let halves: Vec<[DVec2; 3]> = if triangle_domain {
                    if i + j >= nu {
                        continue;
                    }
                    let mut h = vec![[a, b, c]];
                    if i + j + 1 < nu {
                        h.push([b, d, c]);
                    }
                    h
                } else {
                    vec![[a, b, c], [b, d, c], [a, b, d], [a, d, c]]
                };
                for t in halves {
                    let at = t.map(|q| p.position(q));
                    let n = 12;
                    for k in 0..=n {
                        for l in 0..=n - k {
                            let (x, y) = (k as f64 / n as f64, l as f64 / n as f64);
                            let q = t[0] * (1.0 - x - y) + t[1] * x + t[2] * y;
                            let linear = at[0] * (1.0 - x - y) + at[1] * x + at[2] * y;
                            worst = worst.max(p.position(q).distance(linear));
                        }
                    }
                }
            }
        }
        worst
    }

    /// The nets' bound of a whole grid holds when the grid's error is sampled, on random
    /// bicubics and cubic triangles and grids from one cell to many, thin ones included;
    /// and it is never below the bound of the walk over the quad's cells, which takes each
    /// cell's own second derivatives.
    #[test]
    fn the_nets_bound_every_cell_of_a_grid() {
        let mut rng = Lcg(23);
        let (mut worst_share, mut checked) = (0.0f64, 0);
        for _ in 0..40 {
            let net = random_net(&mut rng);
            let bicubic = Patch::Bicubic(RationalBicubic::polynomial(std::array::from_fn(|k| net[k])));
            let tri = Patch::BezierTriangle(BezierTriangle { points: std::array::from_fn(|k| net[k]) });
            for (p, triangle_domain) in [(bicubic, false), (tri, true)] {
                let bound = TaylorBound::expansion(&p);
                assert!(bound.is_some() && !bound.refines());
                for n in [[1, 1], [2, 2], [3, 1], [1, 4], [5, 5], [8, 3]] {
                    let n = if triangle_domain { [n[0], n[0]] } else { n };
                    let nets = bound.nets_grid_error(triangle_domain, n);
                    let measured = measured_grid_error(&p, triangle_domain, n);
                    assert!(measured <= nets * (1.0 + 1e-9), "{n:?}: measured {measured} > {nets}");
                    if !triangle_domain {
                        let walk = bound.grid_error(false, n);
                        assert!(walk <= nets * (1.0 + 1e-9), "{n:?}: walk {walk} > nets {nets}");
                    }
                    worst_share = worst_share.max(measured / nets);
                    checked += 1;
                }
            }
        }
        // Not vacuous: on some grid the measured error comes close to the bound.
        assert!(checked == 480 && worst_share > 0.5, "at most {worst_share:.3} of the bound measured");
    }

    /// Past [`EXPANSION_WALK_CELLS`] an expansion's grid bound is the nets' bound; below it,
    /// the walk's; the full Taylor bound always walks.
    #[test]
    fn an_expansion_walks_small_grids_only() {
        let mut rng = Lcg(29);
        let net = random_net(&mut rng);
        let p = Patch::Bicubic(RationalBicubic::polynomial(std::array::from_fn(|k| net[k])));
        let (expansion, full) = (TaylorBound::expansion(&p), TaylorBound::of(&p));
        let large = [40, 40];
        const { assert!(40 * 40 > EXPANSION_WALK_CELLS) };
        assert_eq!(expansion.grid_error(false, large), expansion.nets_grid_error(false, large));
        assert!(full.grid_error(false, large) < expansion.nets_grid_error(false, large));
        let small = [30, 30];
        assert!(expansion.grid_error(false, small) < expansion.nets_grid_error(false, small));
        // Other kinds have no expansion bound.
        let rational = Patch::Bicubic(RationalBicubic {
            points: std::array::from_fn(|k| net[k]),
            weights: std::array::from_fn(|k| 1.0 + 0.1 * k as f64),
        });
        assert!(!TaylorBound::expansion(&rational).is_some());
    }

    #[test]
    fn bubble_max_is_the_maximum_over_the_triangle() {
        let mut rng = Lcg(11);
        for _ in 0..500 {
            let a = [rng.unit(), rng.unit(), rng.unit()].map(|x| if x < 0.1 { 0.0 } else { x });
            let mut sampled = 0.0f64;
            let n = 200;
            for i in 0..=n {
                for j in 0..=n - i {
                    let (l0, l1) = (i as f64 / n as f64, j as f64 / n as f64);
                    let l2 = 1.0 - l0 - l1;
                    sampled = sampled.max(4.0 * (a[0] * l1 * l2 + a[1] * l2 * l0 + a[2] * l0 * l1));
                }
            }
            let exact = bubble_max(a);
            assert!(
                exact >= sampled - 1e-12 && exact <= sampled * (1.0 + 1e-3) + 1e-12,
                "{a:?}: {exact} vs {sampled}"
            );
        }
    }
}
