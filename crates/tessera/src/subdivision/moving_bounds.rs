//! How far a patch's view bounds can move when its cage's vertices move: what lets a
//! deforming cage be planned from the camera (pixel error, culling) without rebuilding its
//! bounds, e.g. on the GPU, where only the moved vertices are uploaded each frame.
//!
//! **What is proven.** For fixed topology and tags, a face's surface `S(X)` is linear in the
//! cage's points `X` ([`super::stencils`]), and so are its control points. Let `X₀` be the
//! cage the set was built from and `D = X − X₀`, so `S(X) = S(X₀) + S(D)`, with
//! `S(D) = Σⱼ φⱼ dⱼ`: `φⱼ` the scalar surface of a cage that is zero except a unit
//! coordinate on vertex `j`, `dⱼ` vertex `j`'s displacement. Each second-derivative bound the
//! criteria read (`uu`, `uv`, `vv`: suprema of `|S_uu|`, `|S_uv|`, `|S_vv|`; a boundary
//! curve's `sup |C''|`) is a supremum of Euclidean norms of a linear map of the surface: a
//! seminorm `N`, so `N(S(X)) ≤ N(S(X₀)) + Σⱼ |dⱼ| N(φⱼ x̂)` (the triangle inequality, and
//! `N(φⱼ d) = |d| N(φⱼ x̂)` since the norm is Euclidean). `N(S(X₀))` is bounded by the bound
//! the set already has, and `N(φⱼ x̂)` by the same bound function applied to the probe
//! patch `φⱼ x̂` — the patch whose points are vertex `j`'s stencil weights on x
//! ([`CageStencils::rows`]). So no bound rule is written a second time: the terms are
//! [`crate::criterion::bounds::hessian`] and
//! [`crate::criterion::tolerance::patch_curve_bounds`] of probes.
//!
//! **An affine motion is nearly free.** The limit surface is affine invariant (a face's
//! weights sum to one): for `Y = A(X₀ − c₀) + c`, `S(Y) = A(S(X₀) − c₀) + c`. Write the
//! moved cage as `X = Y + R`, so `S(X) = A(S(X₀) − c₀) + c + S(R)`. A seminorm of
//! derivatives is zero on a constant and `N(A S) ≤ ‖A‖₂ N(S)`, so
//! `N(S(X)) ≤ ‖A‖₂ N(S(X₀)) + Σⱼ |rⱼ| N(φⱼ x̂)`: any `A` and `c` are valid, and the better
//! they fit the motion the smaller the residuals `rⱼ`. Per patch, over the vertices it reads:
//! `c₀` their rest centroid, `c = c₀ + t` with `t` their mean displacement, and `A = I + M`
//! with `M` the least-squares fit of the displacements' variation, `M = D Xᵀ (X Xᵀ + λI)⁻¹`
//! (`X` the rest vertices less `c₀`, `D` the displacements less `t`, `λ` a millionth of the
//! trace, so a flat neighbourhood still has an inverse). A rigid motion leaves residuals of
//! rounding only and `‖A‖₂ = 1`; a scaling by `s`, `‖A‖₂ = s`. `‖A‖₂` is bounded by the
//! square root of the largest Gershgorin row sum of `AᵀA` (exact for rotations and
//! similarities).
//!
//! A control point moves to `A(Pᵢ − c₀) + c + Σⱼ wᵢⱼ rⱼ`, so it lies within
//! `δ = Σⱼ |rⱼ| maxᵢ |wᵢⱼ|` (`wᵢⱼ` its stencil weights) of its rest place mapped by the
//! affine part: the patch's **growth**. The box of the rest box's corners mapped so, grown by
//! `δ` on every side, and the rest sphere mapped (centre mapped, radius times `‖A‖₂`) with
//! its radius plus `δ`, hold the moved points (and the surface, inside their hull). A normal
//! cone does not move by a bounded amount this way, so a patch that moved at all has none
//! (it is not culled as back-facing).
//!
//! **The rule**, one per patch ([`MovingBounds::moved`]): the affine fit, the rest box and
//! sphere mapped by it, and each rest bound times `‖A‖₂` plus `Σⱼ |rⱼ| tⱼ` for the patch's
//! terms `tⱼ = (growth, uu, uv, vv, curve₀..₃)`, the growth widening the box and sphere. The
//! bounds loosen as the cage moves away from `X₀` in ways no affine map follows; a caller
//! that wants them tight again rebuilds the set (and the terms' rest) at the new pose.

use glam::{DMat3, DVec3};
use rayon::prelude::*;

use super::stencils::CageStencils;
use crate::criterion::{bounds, tolerance};
use crate::error::Result;
use crate::surface::SurfaceSet;

/// What one cage vertex's unit displacement does to a patch's bounds: the growth of its
/// control points, then `uu`, `uv`, `vv`, then its four boundary curves' bounds.
pub type MovingTerm = [f64; 8];

/// Per patch of a cage's set, its [`MovingTerm`] for each cage vertex that moves it (module
/// doc).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct MovingBounds {
    /// Patch `p`'s terms are `starts[p]..starts[p + 1]`; one more entry than patches.
    pub starts: Vec<u32>,
    /// Each term's cage vertex (0-based, the cage file's order).
    pub vertices: Vec<u32>,
    /// Each term.
    pub terms: Vec<MovingTerm>,
}

impl MovingBounds {
    /// The terms of every patch of `set`, the set `stencils` were built with (or one
    /// [`CageStencils::apply`] moved: the terms do not depend on the points).
    ///
    /// Errors: [`crate::Error::InvalidParameter`] when `set` is not the stencils' cage's.
    /// Cost: per patch and vertex of its neighbourhood, a probe patch (a copy of an isolated
    /// face's tree) and its bounds: about the neighbourhood's size (16–40 vertices) times a
    /// bound per patch, parallel, once per topology.
    pub fn new(stencils: &CageStencils, set: &SurfaceSet) -> Result<MovingBounds> {
        let ranges = stencils.point_ranges(set)?;
        let rows = stencils.rows();
        let per_patch: Vec<Vec<(u32, MovingTerm)>> = (0..set.patches.len())
            .into_par_iter()
            .map(|p| {
                // Each vertex's weights on the patch's points.
                let range = ranges[p].clone();
                let mut weights: Vec<(u32, usize, f64)> = Vec::new();
                for (i, r) in range.clone().enumerate() {
                    let terms = rows.starts[r] as usize..rows.starts[r + 1] as usize;
                    weights.extend(terms.map(|k| (rows.vertices[k], i, rows.weights[k])));
                }
                weights.sort_unstable_by_key(|&(v, i, _)| (v, i));
                let mut points = vec![DVec3::ZERO; range.len()];
                weights
                    .chunk_by(|a, b| a.0 == b.0)
                    .map(|of_vertex| {
                        points.fill(DVec3::ZERO);
                        for &(_, i, w) in of_vertex {
                            points[i].x += w;
                        }
                        let growth = points.iter().map(|q| q.x.abs()).fold(0.0, f64::max);
                        let probe = stencils.with_points(&set.patches[p], &set.origins[p], &points);
                        let h = bounds::hessian(&probe);
                        let c = tolerance::patch_curve_bounds(&probe, &h);
                        (of_vertex[0].0, [growth, h.uu, h.uv, h.vv, c[0], c[1], c[2], c[3]])
                    })
                    .collect()
            })
            .collect();
        let mut out = MovingBounds { starts: vec![0], ..Default::default() };
        for terms in per_patch {
            for (v, t) in terms {
                out.vertices.push(v);
                out.terms.push(t);
            }
            out.starts.push(out.vertices.len() as u32);
        }
        Ok(out)
    }

    /// How many patches.
    pub fn patch_count(&self) -> usize {
        self.starts.len().saturating_sub(1)
    }

    /// Patch `p`'s move for the cage moved from `rest` to `moved` (module doc: the affine
    /// fit, its stretch and the residuals' sums). Preconditions: `p` is a patch; both slices
    /// index every vertex of the terms. Cost: O(the patch's terms).
    pub fn moved(&self, p: usize, rest: &[DVec3], moved: &[DVec3]) -> PatchMove {
        let range = self.starts[p] as usize..self.starts[p + 1] as usize;
        let vertices = &self.vertices[range.clone()];
        let n = vertices.len().max(1) as f64;
        let d = |v: u32| moved[v as usize] - rest[v as usize];
        let from = vertices.iter().map(|&v| rest[v as usize]).sum::<DVec3>() / n;
        let t = vertices.iter().map(|&v| d(v)).sum::<DVec3>() / n;
        // Σ x xᵀ and Σ (d − t) xᵀ, x the rest vertex less the centroid.
        let (mut xx, mut dx) = (DMat3::ZERO, DMat3::ZERO);
        for &v in vertices {
            let x = rest[v as usize] - from;
            xx += outer(x, x);
            dx += outer(d(v) - t, x);
        }
        let lambda = 1e-6 * (xx.x_axis.x + xx.y_axis.y + xx.z_axis.z) + f64::MIN_POSITIVE;
        let m = dx * (xx + DMat3::from_diagonal(DVec3::splat(lambda))).inverse();
        let m = if m.is_finite() { m } else { DMat3::ZERO };
        let mut increments = [0f64; 8];
        for (&v, term) in vertices.iter().zip(&self.terms[range]) {
            let r = (d(v) - t - m * (rest[v as usize] - from)).length();
            for (s, x) in increments.iter_mut().zip(term) {
                *s += r * x;
            }
        }
        PatchMove { m, from, t, stretch: stretch(DMat3::IDENTITY + m), increments }
    }
}

/// `a bᵀ`.
fn outer(a: DVec3, b: DVec3) -> DMat3 {
    DMat3::from_cols(a * b.x, a * b.y, a * b.z)
}

/// An upper bound of `‖a‖₂`: the square root of the largest Gershgorin row sum of `aᵀa` (its
/// eigenvalues' bound; exact for a rotation or a similarity).
fn stretch(a: DMat3) -> f64 {
    let b = a.transpose() * a;
    let rows = b.transpose();
    [rows.x_axis, rows.y_axis, rows.z_axis].iter().map(|r| r.abs().element_sum()).fold(0.0, f64::max).sqrt()
}

/// How a patch's bounds move with its cage ([`MovingBounds::moved`], module doc): the affine
/// part `x ↦ x + t + m (x − from)`, its stretch, and the residuals' sums.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PatchMove {
    /// The affine part's `A − I`.
    pub m: DMat3,
    /// The rest centroid of the patch's vertices.
    pub from: DVec3,
    /// Their mean displacement.
    pub t: DVec3,
    /// An upper bound of `‖A‖₂`.
    pub stretch: f64,
    /// `Σⱼ |rⱼ| tⱼ`: the growth, then the amounts added to `uu`, `uv`, `vv` and the curves'
    /// bounds after scaling them by the stretch.
    pub increments: MovingTerm,
}

impl PatchMove {
    /// Where the affine part takes the rest point `x`.
    pub fn map(&self, x: DVec3) -> DVec3 {
        x + self.t + self.m * (x - self.from)
    }

    /// The box and sphere that hold the moved control points, from the rest ones (`lo`, `hi`,
    /// `centre`, `radius`): the mapped box's corners' box and the mapped sphere, grown by the
    /// growth.
    pub fn moved_box_and_sphere(
        &self,
        lo: DVec3,
        hi: DVec3,
        centre: DVec3,
        radius: f64,
    ) -> (DVec3, DVec3, DVec3, f64) {
        let g = self.increments[0];
        let (mut mlo, mut mhi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        for k in 0..8 {
            let corner = DVec3::new(
                if k & 1 == 0 { lo.x } else { hi.x },
                if k & 2 == 0 { lo.y } else { hi.y },
                if k & 4 == 0 { lo.z } else { hi.z },
            );
            let q = self.map(corner);
            mlo = mlo.min(q);
            mhi = mhi.max(q);
        }
        (mlo - g, mhi + g, self.map(centre), self.stretch * radius + g)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::criterion::screen::PatchView;
    use crate::subdivision::CageOptions;

    /// On cages of both schemes — regular, creased (isolated trees with Gregory end caps),
    /// split into sub-faces, Loop — moved by a twist, a shift and a random jitter: the moved
    /// set's own bounds (the same functions on the moved patches) never exceed the rest bounds
    /// plus the increments, and every moved control point lies in the rest box moved by the
    /// patch's translation and grown by its growth, and within the moved rest sphere's radius
    /// plus it. Not vacuous: many bounds grow past their rest.
    #[test]
    fn moved_bounds_stay_under_the_rest_bounds_plus_the_increments() {
        type Build = fn(
            &crate::surface::PolygonMesh,
            &std::path::Path,
            CageOptions,
        ) -> Result<(SurfaceSet, CageStencils)>;
        let catmull_clark: Build = CageStencils::build;
        let loop_: Build = CageStencils::build_loop;
        let mut grew = 0;
        for (cage, build) in [
            ("catmark_torus", catmull_clark),
            ("catmark_cube_creases0", catmull_clark),
            ("catmark_pyramid_creases0", catmull_clark),
            ("loop_cube_creases0", loop_),
            ("loop_xord_interior", loop_),
        ] {
            let path = crate::test_support::data(&format!("subdivision/{cage}.obj"));
            let mesh = crate::io::obj::read_obj(&path).unwrap();
            let (rest_set, stencils) = build(&mesh, &path, CageOptions::default()).unwrap();
            let terms = MovingBounds::new(&stencils, &rest_set).unwrap();
            assert_eq!(terms.patch_count(), rest_set.patches.len());
            let rest_h: Vec<_> = rest_set.patches.iter().map(bounds::hessian).collect();
            let rest_c = tolerance::curve_bounds(&rest_set, &rest_h);
            let (lo, hi) = rest_set.bounds();
            let size = lo.distance(hi);
            let mut seed = 0x9e37_79b9_7f4a_7c15u64;
            let mut random = move || {
                seed ^= seed << 13;
                seed ^= seed >> 7;
                seed ^= seed << 17;
                (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
            };
            let moved: Vec<DVec3> = mesh
                .positions
                .iter()
                .map(|p| {
                    let (s, c) = (0.5 * (p.z - lo.z) / (hi.z - lo.z)).sin_cos();
                    let jitter = DVec3::new(random(), random(), random()) * (0.05 * size);
                    DVec3::new(c * p.x - s * p.y, s * p.x + c * p.y, p.z) * 1.25
                        + jitter
                        + DVec3::new(0.3, -0.2, 0.1) * size
                })
                .collect();
            let mut set = rest_set.clone();
            stencils.apply(&moved, &mut set).unwrap();
            let ranges = stencils.point_ranges(&set).unwrap();
            for p in 0..set.patches.len() {
                let what = format!("{cage} patch {p}");
                let motion = terms.moved(p, &mesh.positions, &moved);
                let (inc, k2) = (motion.increments, motion.stretch);
                let slack = |x: f64| x * (1.0 + 1e-9) + 1e-12 * size;
                let h = bounds::hessian(&set.patches[p]);
                for (k, (got, rest)) in
                    [(h.uu, rest_h[p].uu), (h.uv, rest_h[p].uv), (h.vv, rest_h[p].vv)].into_iter().enumerate()
                {
                    assert!(
                        got <= slack(k2 * rest + inc[1 + k]),
                        "{what}: second derivative {k}: {got} > {rest} + {}",
                        inc[1 + k]
                    );
                    grew += usize::from(got > rest * (1.0 + 1e-6));
                }
                let c = tolerance::patch_curve_bounds(&set.patches[p], &h);
                for l in 0..4 {
                    assert!(c[l] <= slack(k2 * rest_c[p][l] + inc[4 + l]), "{what}: curve {l}");
                }
                // Every point of the patch's range (a tree's: all its leaves') moves at most
                // the growth; the moved hull (a net, or a tree's visible leaves' box) stays in
                // the grown box, and a net in the grown sphere.
                let view = PatchView::new(&rest_set.patches[p]);
                let g = slack(inc[0]);
                for r in ranges[p].clone() {
                    let (q, rest) =
                        (stencils.rows().apply_row(r, &moved), stencils.rows().apply_row(r, &mesh.positions));
                    assert!(
                        q.distance(motion.map(rest)) <= g,
                        "{what}: a point moved {} > growth {g}",
                        q.distance(motion.map(rest))
                    );
                }
                let (lo, hi, centre, radius) =
                    motion.moved_box_and_sphere(view.lo, view.hi, view.centre, view.radius);
                let pad = 1e-12 * size;
                for q in set.patches[p].control_points() {
                    assert!(
                        (lo - pad).cmple(*q).all() && q.cmple(hi + pad).all(),
                        "{what}: outside the moved box"
                    );
                    if matches!(set.patches[p], crate::surface::Patch::Bicubic(_)) {
                        assert!(q.distance(centre) <= radius + pad, "{what}: outside the moved sphere");
                    }
                }
            }
        }
        assert!(grew > 100, "the twist and jitter should raise many bounds, raised {grew}");
    }
}
