//! Gregory-triangle end caps of Loop surfaces, as OpenSubdiv 3.6.0 builds them.
//!
//! Where feature-adaptive refinement of a Loop surface stops, OpenSubdiv replaces each leaf
//! triangle that is not a regular box-spline patch by a *Gregory triangle*
//! (`PatchDescriptor::GREGORY_TRIANGLE`, `far/patchDescriptor.h`): a quartic Bézier triangle
//! whose three interior points are each split into a pair of face points blended rationally.
//! Its 18 points are a fixed linear combination of the leaf's neighbourhood, the *source
//! patch*. This module computes that combination ([`gregory_triangle_points`], the counterpart
//! of `GregoryTriConverter` in `far/loopPatchBuilder.cpp`, with the source patch of
//! `Far::SourcePatch` in `far/patchBuilder.cpp`); it is the triangle sibling of
//! [`super::gregory`] and shares with it, as OpenSubdiv does, the source patch, the corner
//! topology and the assembly of corner, edge and face points (the private module
//! `gregory_shared`).
//!
//! OpenSubdiv first builds a cubic/quartic hybrid — corner and edge points from the Loop
//! limit position and tangents of each corner (`LoopLimits`, which uses the masks of
//! `Sdc::Scheme<SCHEME_LOOP>`, `sdc/loopScheme.h`, with its own tangent scale), face points
//! from those — then adds a mid-edge point per edge and raises the edge points to quartic
//! (`E ← ¼P + ¾E`). As with quads, the formulas are OpenSubdiv's, including its
//! approximations at sharp and one-face corners, not those of the literature; tessera must
//! reproduce OpenSubdiv's surface. All arithmetic is in `f64`.
//!
//! # Point order
//!
//! The triangle's corners 0, 1, 2 are counter-clockwise at parameters `(s, t)` = (0,0),
//! (1,0), (0,1). Points `5i..5i+5` belong to corner `i`:
//!
//! * `P`  — the corner point,
//! * `Ep` — the edge point on the edge from corner `i` to corner `i+1`,
//! * `Em` — the edge point on the edge from corner `i` to corner `i−1`,
//! * `Fp` — the face point next to `Ep`,
//! * `Fm` — the face point next to `Em`;
//!
//! and points 15, 16, 17 are the mid-edge points `M0`, `M1`, `M2` of the edges 0→1, 1→2 and
//! 2→0. With `b(i, j)` the quartic Bézier point at `(s, t) = (i/4, j/4)`, the net is
//!
//! ```text
//! b(0,4) = P2
//! b(0,3) = Ep2   b(1,3) = Em2
//! b(0,2) = M2    b(1,2) = F2    b(2,2) = M1
//! b(0,1) = Em0   b(1,1) = F0    b(2,1) = F1    b(3,1) = Ep1
//! b(0,0) = P0    b(1,0) = Ep0   b(2,0) = M0    b(3,0) = Em1   b(4,0) = P1
//! ```
//!
//! where, with `w = 1 − s − t`, `F0 = (s·Fp0 + t·Fm0)/(s + t)`, `F1 = (t·Fp1 + w·Fm1)/(t + w)`
//! and `F2 = (w·Fp2 + s·Fm2)/(w + s)` (`EvalBasisGregoryTri`, `far/patchBasis.cpp`; each pair
//! collapses to its first point where its denominator is 0).

use super::gregory::GregorySourceError;
use super::gregory_shared::{
    self, apply, checked_layout, corner_and_face_points, corner_fields, corner_kinds, CornerKind,
    SchemeCorner, SourceLayout, Stencil,
};
use glam::DVec3;
use std::f64::consts::PI;

/// One corner of a leaf triangle's source patch: the corner vertex, the fan of triangles
/// around it and its 1-ring, in OpenSubdiv's order (`Far::SourcePatch::Corner`,
/// `far/patchBuilder.h`).
///
/// # Faces and ring order
///
/// The triangles around the corner vertex `V` are numbered `0..num_faces` counter-clockwise.
/// Face `k`'s *leading edge* is `V → w` where `w` follows `V` in the face's own
/// counter-clockwise order; its trailing edge `V → u` (`u` precedes `V`) is face `k+1`'s
/// leading edge.
///
/// * Interior corner: face 0 may be any face of the fan (`patch_face` is relative to it).
/// * Boundary corner: face 0 is the face whose leading edge is a boundary edge, so the fan
///   runs from one boundary edge to the other.
/// * Corner span: where infinitely sharp edges cut the fan (and the vertex is not a dart),
///   OpenSubdiv keeps only the faces between the two sharp edges that enclose the patch face
///   (`GetIrregularPatchCornerSpans`, `far/patchBuilder.cpp`); the corner is then a boundary
///   corner over that span — face 0 the one after the leading sharp edge — even if the vertex
///   is interior, and `num_faces`, `patch_face` and the ring are the span's.
///
/// `ring` lists, for each face `k` in order, the far end of its leading edge; a boundary
/// corner appends the far end of the last face's trailing edge. So the ring has `num_faces`
/// points (interior) or `num_faces + 1` (boundary), and for the patch face `k = patch_face`
/// the points `ring[k]` and `ring[(k+1) mod len]` are the triangle's next and previous
/// corners. This is the order of `gatherTriRegularRingAroundVertex` and
/// `gatherRegularPartialRingAroundVertex` (`far/patchBuilder.cpp`) and of
/// `SourcePatch::GetCornerRingPoints`.
///
/// All faces involved must be triangles (true at every level ≥ 1 of Loop refinement).
#[derive(Debug, Clone, PartialEq)]
pub struct LoopCorner {
    /// The corner vertex.
    pub position: DVec3,
    /// Triangles in the corner's fan (its valence for an interior vertex, one less than its
    /// edge count on a boundary); ≥ 1, and ≥ 2 when not a boundary.
    pub num_faces: usize,
    /// Which face of the fan is the patch's triangle, `< num_faces`.
    pub patch_face: usize,
    /// The fan is open: the vertex is on the mesh boundary, or its span is cut by infinitely
    /// sharp edges (OpenSubdiv: `!VSpan::_periodic`, else `VTag::_boundary`).
    pub boundary: bool,
    /// The corner is treated as infinitely sharp, by the same rule as
    /// [`GregoryCorner::sharp`](super::gregory::GregoryCorner::sharp): tagged a corner
    /// (`VTag::_corner`); or else with infinitely sharp edges, not a dart, that do not form a
    /// simple crease; or else with no such edges and itself infinitely sharp.
    pub sharp: bool,
    /// The vertex is a dart (`Sdc::Crease::RULE_DART` with an infinitely sharp edge). It only
    /// affects which ring points the corner shares with its neighbours, not any formula.
    pub dart: bool,
    /// The 1-ring, in the order described above.
    pub ring: Vec<DVec3>,
}

impl LoopCorner {
    /// OpenSubdiv's valence-2 interior flag (`SourcePatch::Finalize`): two faces, no boundary.
    pub fn is_val2_interior(&self) -> bool {
        self.fan().is_val2_interior()
    }

    /// The ring length this corner's fan implies: `num_faces`, plus one on a boundary (which
    /// is also the corner's edge count, OpenSubdiv's "valence").
    pub fn expected_ring_len(&self) -> usize {
        self.implied_ring_len()
    }
}

/// The source patch of one leaf triangle: its three corners, counter-clockwise, corner `i` at
/// parameters (0,0), (1,0), (0,1) (OpenSubdiv's `Far::SourcePatch` with three corners).
#[derive(Debug, Clone, PartialEq)]
pub struct LoopGregorySource {
    /// The corners; see [`LoopCorner`] for the order of each ring.
    pub corners: [LoopCorner; 3],
}

impl LoopGregorySource {
    /// Checks that the corners describe one leaf triangle consistently: fan counts, ring
    /// lengths, that the fans fit together as OpenSubdiv numbers a triangle's source points,
    /// and that every point shared by two rings (or a ring and a corner) is the same point.
    /// Exact equality is required, as both copies come from the same mesh vertex. Errors are
    /// [`GregorySourceError`]s, the quad module's, as the failures are the same.
    ///
    /// Cost: linear in the total ring length. [`gregory_triangle_points`] assumes a source
    /// that passes this check; call it when filling sources from a new mesh walker.
    pub fn validate(&self) -> Result<(), GregorySourceError> {
        gregory_shared::validate(&self.corners)
    }
}

/// Limit position of a smooth interior Loop vertex of valence `n` over `[vertex, ring…]`
/// (`Sdc::Scheme<SCHEME_LOOP>::assignSmoothLimitMask`, `sdc/loopScheme.h`): ½ and 1/12 for
/// valence 6, else `1 − nβ` and β = 1/(n + 3/(8γ)), γ = (5/8 − (3/8 + ¼cos(2π/n))²)/n.
fn smooth_limit_weights(n: usize) -> (f64, f64) {
    if n == 6 {
        return (0.5, 1.0 / 12.0);
    }
    let nf = n as f64;
    let inv = 1.0 / nf;
    let cos_theta = (PI * 2.0 * inv).cos();
    let beta = 0.25 * cos_theta + 0.375;
    let gamma = (0.625 - beta * beta) * inv;
    let e = 1.0 / (nf + 3.0 / (8.0 * gamma));
    (1.0 - e * nf, e)
}

impl SchemeCorner for LoopCorner {
    const RING_POINTS_PER_FACE: usize = 1;
    const REGULAR_FACES: usize = 6;
    // A regular corner's face angle is taken as exactly π/3 (cos ½), not the rounded cosine.
    const REGULAR_COS_FACE_ANGLE: f64 = 0.5;
    const FACE_POINT_DENOMINATOR: f64 = 4.0;
    const KEEPS_ZERO_ENTRIES: bool = true;

    corner_fields!();

    /// Limit-point weights of a smooth interior vertex of valence `n` over `[vertex, ring…]`, and
    /// the cubic edge points along the patch face's leading (`ep`) and trailing (`em`) edges
    /// (`LoopLimits::ComputeInteriorPointWeights`, `far/loopPatchBuilder.cpp`). The tangent is
    /// Sdc's first limit tangent (`cos(2πi/n)` per edge, the exact regular mask at valence 6)
    /// scaled by `(3 + 2cos(2π/n))/(6n)` — the subdominant eigenvalue, a normalisation and the
    /// cubic's ⅓ — and rotated onto each edge.
    fn interior_weights(n: usize, face_in_ring: usize) -> [Vec<f64>; 3] {
        let nf = n as f64;
        let (vertex, edge) = smooth_limit_weights(n);
        let mut p = vec![edge; n + 1];
        p[0] = vertex;

        const REGULAR_TANGENT: [f64; 6] = [1.0, 0.5, -0.5, -1.0, -0.5, 0.5];
        let alpha = 2.0 * PI / nf;
        let theta = 2.0 * PI / nf;
        let tan_scale = (3.0 + 2.0 * theta.cos()) / (6.0 * nf);
        // The point along edge 0; the vertex has no tangent weight.
        let mut along = p.clone();
        for i in 0..n {
            let t = if n == 6 { REGULAR_TANGENT[i] } else { (alpha * i as f64).cos() };
            along[1 + i] = p[1 + i] + t * tan_scale;
        }
        let rotated = |edge: usize| {
            let mut e = vec![along[0]; n + 1];
            for k in 0..n {
                e[1 + k] = along[1 + (k + n - edge) % n];
            }
            e
        };
        let ep = rotated(face_in_ring);
        let em = rotated((face_in_ring + 1) % n);
        [p, ep, em]
    }

    /// The interior tangent of a smooth boundary vertex with `valence` edges over
    /// `[vertex, ring…]` (`LoopLimits::ComputeBoundaryPointWeights`,
    /// `far/loopPatchBuilder.cpp`): `1/24` of Sdc's crease cross tangent
    /// (`assignCreaseLimitTangentMasks`, `sdc/loopScheme.h`), the crease running along edges 0
    /// and valence − 1.
    fn boundary_tangent(valence: usize) -> Vec<f64> {
        let width = valence + 1;
        let last = valence;
        // (The converter never reaches the arms for 0 and 2 interior edges — a one-face corner
        // has its own rule and a smooth three-face one is regular — but they complete Sdc's
        // mask.)
        let mut cross = vec![0.0; width];
        let interior_edges = valence - 2;
        match interior_edges {
            0 => {
                cross[0] = -6.0;
                cross[1] = 3.0;
                cross[2] = 3.0;
            }
            1 => {
                cross[0] = -3.0;
                cross[2] = 3.0;
            }
            2 => {
                let root3 = 3.0f64.sqrt();
                let root3_by_2 = root3 * 0.5;
                cross[0] = -root3;
                cross[1] = -root3_by_2;
                cross[last] = -root3_by_2;
                cross[2] = root3;
                cross[3] = root3;
            }
            _ => {
                let theta = PI / (interior_edges + 1) as f64;
                let c = -3.0 * theta.sin();
                cross[1] = c;
                cross[last] = c;
                let e_coeff = -3.0 * 2.0 * (theta.cos() - 1.0);
                for i in 1..=interior_edges {
                    cross[1 + i] = e_coeff * (i as f64 * theta).sin();
                }
            }
        }
        cross.iter().map(|t| (1.0 / 24.0) * t).collect()
    }

    /// OpenSubdiv's test for an edge point on the *trailing* boundary edge compares the face
    /// index with the edge count and never holds, so that point also comes from the rotated
    /// tangent, at angle π: the same point as ⅔·v + ⅓·(last neighbour) up to rounding. It is
    /// reproduced as computed.
    fn em_on_trailing_edge(valence: usize, face_in_ring: usize) -> bool {
        face_in_ring == valence - 1
    }

    /// P and the cubic Ep, Em of a corner whose neighbourhood is regular: the box spline's
    /// (`GregoryTriConverter::assignRegularEdgePoints`, `far/loopPatchBuilder.cpp`). The entry
    /// order matters: [`promote_edge_point`] reweights these rows by position.
    fn regular_edge_points(c: usize, kind: &CornerKind, ring: &[usize]) -> [Stencil; 3] {
        if !kind.boundary {
            let mut p = vec![(c, 0.5)];
            p.extend(ring.iter().map(|&r| (r, 1.0 / 12.0)));
            const E_WEIGHTS: [f64; 6] = [7.0, 5.0, 1.0, -1.0, 1.0, 5.0];
            let along = |edge: usize| {
                let mut e = vec![(c, 0.5)];
                e.extend((0..6).map(|j| (ring[(edge + j) % 6], (1.0 / 36.0) * E_WEIGHTS[j])));
                e
            };
            let ep = along(kind.face_in_ring);
            let em = along((kind.face_in_ring + 1) % 6);
            [p, ep, em]
        } else {
            let (ep_b, em_b) = (kind.flags.ep_on_boundary, kind.flags.em_on_boundary);
            let p = vec![(c, 2.0 / 3.0), (ring[0], 1.0 / 6.0), (ring[3], 1.0 / 6.0)];
            // Along an interior edge the boundary's phantom points fold into ½, ⅙, ⅙, ⅙.
            let interior = |other_on_boundary: bool, first: usize| {
                let (near, far) = if other_on_boundary { (3 - first, first) } else { (first, 3 - first) };
                vec![
                    (c, 0.5),
                    (ring[1], 1.0 / 6.0),
                    (ring[2], 1.0 / 6.0),
                    (ring[near], 1.0 / 6.0),
                    (ring[far], 0.0),
                ]
            };
            let ep = if ep_b {
                vec![(c, 2.0 / 3.0), (ring[0], 1.0 / 3.0), (ring[3], 0.0)]
            } else {
                interior(em_b, 0)
            };
            let em = if em_b {
                vec![(c, 2.0 / 3.0), (ring[3], 1.0 / 3.0), (ring[0], 0.0)]
            } else {
                interior(ep_b, 3)
            };
            [p, ep, em]
        }
    }

    /// The regular face point of corner `c`, the same for Fp and Fm
    /// (`GregoryTriConverter::assignRegularFacePoints`, `far/loopPatchBuilder.cpp`).
    fn regular_face_point(c: usize, kind: &CornerKind, ring: &[usize]) -> Stencil {
        let (next, prev) = ((c + 1) % 3, (c + 2) % 3);
        if kind.num_faces == 1 {
            vec![(c, 0.5), (next, 0.25), (prev, 0.25)]
        } else if kind.flags.ep_on_boundary {
            vec![(c, 11.0 / 24.0), (ring[0], 7.0 / 24.0), (ring[1], 5.0 / 24.0), (ring[2], 1.0 / 24.0)]
        } else if kind.flags.em_on_boundary {
            vec![(c, 11.0 / 24.0), (ring[3], 7.0 / 24.0), (ring[2], 5.0 / 24.0), (ring[1], 1.0 / 24.0)]
        } else {
            let f = kind.face_in_ring;
            let (e_next, e_prev) = if kind.boundary { (0, 3) } else { ((f + 5) % 6, (f + 2) % 6) };
            vec![
                (c, 10.0 / 24.0),
                (prev, 0.25),
                (next, 0.25),
                (ring[e_prev], 1.0 / 24.0),
                (ring[e_next], 1.0 / 24.0),
            ]
        }
    }

    /// The irregular face point's correction (`GregoryTriConverter::computeIrregularFacePoint`,
    /// `far/loopPatchBuilder.cpp`): `±7/72` on the two ring points beside the interior edge, with
    /// `d = 4` in the shared blend (OpenSubdiv's stand-in for the published term built from the
    /// midpoints of the neighbouring edges and faces). Corrections outside the points of P and
    /// the two E are dropped, as [`blend_face_point`](gregory_shared::blend_face_point) says; two
    /// adjacent sharp corners do that (the fixture's unrefined cages with two corner tags).
    fn face_point_corrections(ring: &[usize], [e_prev, _, e_next]: [usize; 3], sign: f64) -> Stencil {
        let r = 0.25 * (7.0 / 18.0);
        vec![(ring[e_prev], -sign * r), (ring[e_next], sign * r)]
    }
}

/// The mid-edge point of edge `e` (corner `e` to `e+1`) of a regular pair of corners
/// (`GregoryTriConverter::assignRegularMidEdgePoint`, `far/loopPatchBuilder.cpp`): the
/// box spline's, or the edge's midpoint on a boundary edge.
fn regular_mid_edge_point(e: usize, kind: &CornerKind, ring: &[usize]) -> Stencil {
    let (c1, c2) = ((e + 1) % 3, (e + 2) % 3);
    if kind.flags.ep_on_boundary {
        vec![(e, 0.5), (c1, 0.5)]
    } else {
        let f = kind.face_in_ring;
        let opposite = if kind.boundary { f - 1 } else { (f + 5) % 6 };
        vec![(e, 1.0 / 3.0), (c1, 1.0 / 3.0), (c2, 1.0 / 6.0), (ring[opposite], 1.0 / 6.0)]
    }
}

/// Raises a cubic edge point of corner `kind` to the quartic boundary curve
/// (`GregoryTriConverter::promoteCubicEdgePointsToQuartic`, `far/loopPatchBuilder.cpp`):
/// `¼P + ¾E`, which OpenSubdiv writes out as exact 24ths, by position in the row, where the
/// row has a known form (on a smooth boundary edge, or a regular corner).
fn promote_edge_point(kind: &CornerKind, on_boundary: bool, p: &Stencil, e: &Stencil) -> Stencil {
    const ON_BOUNDARY: [f64; 3] = [16.0, 7.0, 1.0];
    const REGULAR_BOUNDARY: [f64; 5] = [13.0, 3.0, 3.0, 4.0, 1.0];
    const REGULAR_INTERIOR: [f64; 7] = [12.0, 4.0, 3.0, 1.0, 0.0, 1.0, 3.0];
    let table: Option<&[f64]> = if on_boundary && !kind.sharp {
        Some(&ON_BOUNDARY)
    } else if kind.regular {
        Some(if kind.boundary { &REGULAR_BOUNDARY } else { &REGULAR_INTERIOR })
    } else {
        None
    };
    match table {
        Some(t) => {
            debug_assert_eq!(t.len(), e.len());
            e.iter().zip(t).map(|(&(i, _), &w)| (i, w * (1.0 / 24.0))).collect()
        }
        None => p.iter().map(|&(i, w)| (i, 0.25 * w)).chain(e.iter().map(|&(i, w)| (i, 0.75 * w))).collect(),
    }
}

/// The 18 stencils of a source patch over its [`SourceLayout`] numbering, in the module's point
/// order (`GregoryTriConverter::Convert`, `far/loopPatchBuilder.cpp`): the shared corner, edge
/// and face points, then the triangle's own mid-edge points, and only then the edge points
/// raised to quartic, as the mid-edge points combine the cubic ones.
fn gregory_triangle_stencils(corners: &[LoopCorner; 3], layout: &SourceLayout<3>) -> Option<[Stencil; 18]> {
    let kinds = corner_kinds(corners);
    let rings = layout.rings(corners)?;
    let mut rows = corner_and_face_points::<LoopCorner, 3>(&kinds, &rings, layout.num_points);
    for e in 0..3 {
        let (k0, k1) = (&kinds[e], &kinds[(e + 1) % 3]);
        let boundary_edge = k0.flags.ep_on_boundary && k1.flags.em_on_boundary;
        // One side ends on a boundary and the other does not: the edge is a dart's sharp edge.
        let dart_edge = k0.flags.ep_on_boundary != k1.flags.em_on_boundary;
        let mid = if boundary_edge || (k0.regular && k1.regular && !dart_edge) {
            regular_mid_edge_point(e, k0, &rings[e])
        } else {
            let (e0, e1) = (&rows[5 * e + 1], &rows[5 * ((e + 1) % 3) + 2]);
            e0.iter().chain(e1).map(|&(i, w)| (i, 0.5 * w)).collect()
        };
        rows.push(mid);
    }
    for c in 0..3 {
        let k = &kinds[c];
        let ep = promote_edge_point(k, k.flags.ep_on_boundary, &rows[5 * c], &rows[5 * c + 1]);
        let em = promote_edge_point(k, k.flags.em_on_boundary, &rows[5 * c], &rows[5 * c + 2]);
        rows[5 * c + 1] = ep;
        rows[5 * c + 2] = em;
    }
    rows.try_into().ok()
}

/// The 18 points of a leaf triangle's Gregory triangle, in OpenSubdiv's `GREGORY_TRIANGLE`
/// order (see the module documentation), covering every case of OpenSubdiv's
/// `GregoryTriConverter`: regular, interior irregular, smooth boundary, sharp, smooth
/// one-face and valence-2 interior corners, in any combination. (OpenSubdiv's smaller matrix
/// for a single interior irregular corner only changes how its matrix is stored.)
///
/// Precondition: `source` passes [`LoopGregorySource::validate`]. Cost: O(r²) for total ring
/// length r (each face point is assembled densely over the source points), a few
/// microseconds for ordinary valences.
///
/// # Panics
/// If the fan counts or ring lengths are inconsistent, or the fans do not fit together
/// (inconsistent shared points are not detected here and give a wrong patch instead).
pub fn gregory_triangle_points(source: &LoopGregorySource) -> [DVec3; 18] {
    let corners = &source.corners;
    let layout = checked_layout(corners, "Loop Gregory");
    let stencils = gregory_triangle_stencils(corners, &layout).expect("Loop Gregory source rings do not fit");
    apply(&stencils, &gregory_shared::source_points(corners, &layout))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::subdivision::gregory_shared::{bspline, Rng};
    use std::collections::HashMap;

    /// One patch of `tools/osd-oracle/loop_gregory_check.cpp`'s fixture: the source patch's
    /// topology (rings as source-point indices) and OpenSubdiv's 18 matrix rows.
    struct OsdPatch {
        header: String,
        num_points: usize,
        /// (num_faces, patch_face, boundary, sharp, dart, ring indices) per corner.
        corners: Vec<(usize, usize, bool, bool, bool, Vec<usize>)>,
        rows: Vec<Vec<(usize, f64)>>,
    }

    impl OsdPatch {
        /// The source with the given positions of the source points.
        fn source(&self, points: &[DVec3]) -> LoopGregorySource {
            let corners = [0, 1, 2].map(|i| {
                let (num_faces, patch_face, boundary, sharp, dart, ring) = &self.corners[i];
                LoopCorner {
                    position: points[i],
                    num_faces: *num_faces,
                    patch_face: *patch_face,
                    boundary: *boundary,
                    sharp: *sharp,
                    dart: *dart,
                    ring: ring.iter().map(|&r| points[r]).collect(),
                }
            });
            LoopGregorySource { corners }
        }

        /// Seeded random source points, the source on them and tessera's 18 stencils for it,
        /// having checked that tessera numbers the source points as OpenSubdiv does.
        fn stencils(&self, seed: u64) -> (Vec<DVec3>, LoopGregorySource, [Stencil; 18]) {
            let points = random_points(self.num_points, seed);
            let source = self.source(&points);
            let layout = SourceLayout::new(&source.corners).unwrap();
            assert_eq!(layout.num_points, self.num_points, "{}", self.header);
            let rows = gregory_triangle_stencils(&source.corners, &layout).unwrap();
            (points, source, rows)
        }

        fn points(&self, points: &[DVec3]) -> Vec<DVec3> {
            self.rows.iter().map(|r| r.iter().map(|&(i, w)| points[i] * w).sum()).collect()
        }
    }

    fn fixture() -> Vec<OsdPatch> {
        let text = include_str!("../../tests/fixtures/gregory/osd_gregory_triangle.txt");
        let mut lines = text.lines().filter(|l| !l.starts_with('#')).peekable();
        let fields = |s: &str| s.split_whitespace().skip(1).map(str::to_owned).collect::<Vec<_>>();
        let mut patches = Vec::new();
        while let Some(header) = lines.next() {
            assert!(header.starts_with("patch "), "{header}");
            let num_points = fields(header)[3].parse().unwrap();
            let corners = (0..3)
                .map(|_| {
                    let c: Vec<usize> =
                        fields(lines.next().unwrap()).iter().map(|t| t.parse().unwrap()).collect();
                    let r: Vec<usize> =
                        fields(lines.next().unwrap()).iter().map(|t| t.parse().unwrap()).collect();
                    assert_eq!(r.len(), r[0] + 1);
                    (c[0], c[1], c[2] != 0, c[3] != 0, c[4] != 0, r[1..].to_vec())
                })
                .collect();
            let rows = (0..18)
                .map(|_| {
                    let r = fields(lines.next().unwrap());
                    assert_eq!(r.len(), 1 + 2 * r[0].parse::<usize>().unwrap());
                    r[1..].chunks(2).map(|e| (e[0].parse().unwrap(), e[1].parse().unwrap())).collect()
                })
                .collect();
            patches.push(OsdPatch { header: header.to_owned(), num_points, corners, rows });
        }
        patches
    }

    fn random_points(n: usize, seed: u64) -> Vec<DVec3> {
        let mut rng = Rng(seed);
        (0..n).map(|_| rng.point(2.0)).collect()
    }

    /// A stencil's weights summed per source point.
    fn by_column(stencil: &[(usize, f64)], n: usize) -> Vec<f64> {
        let mut w = vec![0.0; n];
        for &(i, x) in stencil {
            w[i] += x;
        }
        w
    }

    /// OpenSubdiv's Gregory triangles (`tools/osd-oracle/loop_gregory_check.sh`, OpenSubdiv
    /// 3.6.0's `Far::LoopPatchBuilder` under Bfr's options; 194 distinct source patches from
    /// interior valences 3–12, smooth boundary corners of 1, 2, 4 and 5 faces, sharp corners
    /// from corner tags and edge-and-corner boundaries, corner spans of creases, a dart,
    /// valence-2 interior corners, and unrefined cages with several irregular corners per
    /// triangle, among them a valence-3 corner in each position and adjacent sharp corners):
    /// for every patch and three seeded sets of source points, tessera's 18 points equal
    /// OpenSubdiv's matrix applied to them within 1e-12 of their scale.
    #[test]
    fn loop_gregory_matches_opensubdiv_matrices() {
        let patches = fixture();
        assert_eq!(patches.len(), 194);
        let mut worst = 0.0f64;
        for (k, patch) in patches.iter().enumerate() {
            for seed in 0..3 {
                let points = random_points(patch.num_points, 1000 * k as u64 + seed);
                let source = patch.source(&points);
                source.validate().unwrap_or_else(|e| panic!("{}: {e}", patch.header));
                let ours = gregory_triangle_points(&source);
                let theirs = patch.points(&points);
                let scale = points.iter().map(|p| p.abs().max_element()).fold(1.0, f64::max);
                for (i, (p, q)) in ours.iter().zip(&theirs).enumerate() {
                    let d = (*p - *q).abs().max_element() / scale;
                    assert!(d < 1e-12, "{}: point {i} differs by {d}", patch.header);
                    worst = worst.max(d);
                }
            }
        }
        assert!(worst < 1e-12, "{worst}");
    }

    /// The same comparison weight by weight: the source points are numbered as OpenSubdiv
    /// numbers them, so every column of every row must agree (this also catches a weight on a
    /// point whose random position happened to hide it).
    #[test]
    fn loop_gregory_weights_equal_opensubdiv_columns() {
        for patch in fixture() {
            let (_, _, rows) = patch.stencils(7);
            for (i, (ours, theirs)) in rows.iter().zip(&patch.rows).enumerate() {
                let (a, b) = (by_column(ours, patch.num_points), by_column(theirs, patch.num_points));
                for (j, (x, y)) in a.iter().zip(&b).enumerate() {
                    assert!((x - y).abs() < 1e-12, "{}: row {i} column {j}: {x} vs {y}", patch.header);
                }
            }
        }
    }

    /// Affine invariance: every point's weights sum to 1, for every fixture patch, and moving
    /// all source points moves every patch point by the same amount.
    #[test]
    fn loop_gregory_weights_sum_to_one() {
        for patch in fixture() {
            let (points, source, rows) = patch.stencils(11);
            for (i, row) in rows.iter().enumerate() {
                let sum: f64 = row.iter().map(|&(_, w)| w).sum();
                assert!((sum - 1.0).abs() < 1e-13, "{}: row {i} sums to {sum}", patch.header);
            }
            let shift = DVec3::new(3.0, -2.0, 0.5);
            let moved: Vec<DVec3> = points.iter().map(|&p| p + shift).collect();
            let (a, b) = (gregory_triangle_points(&source), gregory_triangle_points(&patch.source(&moved)));
            for (p, q) in a.iter().zip(&b) {
                assert!((*q - *p - shift).abs().max_element() < 1e-12, "{}", patch.header);
            }
        }
    }

    /// The regular three-direction lattice: vertex `(i, j)` of an `n × n` patch of lattice,
    /// triangles `(i,j), (i+1,j), (i,j+1)` and `(i+1,j), (i+1,j+1), (i,j+1)`.
    const DIRS: [(i64, i64); 6] = [(1, 0), (0, 1), (-1, 1), (-1, 0), (0, -1), (1, -1)];

    /// One step of Loop subdivision of a lattice function, on the lattice twice as fine
    /// (valid where all the coarse neighbours are present): vertex points `(1 − 6β)v + βΣ`
    /// with β = 1/16, edge points ⅜, ⅜, ⅛, ⅛.
    fn subdivide(f: &HashMap<(i64, i64), DVec3>) -> HashMap<(i64, i64), DVec3> {
        let mut g = HashMap::new();
        for (&(i, j), &v) in f {
            let ring: Option<DVec3> = DIRS.iter().map(|&(a, b)| f.get(&(i + a, j + b)).copied()).sum();
            if let Some(ring) = ring {
                g.insert((2 * i, 2 * j), v * (10.0 / 16.0) + ring / 16.0);
            }
            for &(a, b) in &DIRS[..3] {
                let q = (i + a, j + b);
                // The two vertices adjacent to both ends of the edge.
                let opposite: Vec<DVec3> = DIRS
                    .iter()
                    .map(|&(c, d)| (i + c, j + d))
                    .filter(|r| DIRS.iter().any(|&(c, d)| (q.0 + c, q.1 + d) == *r))
                    .filter_map(|r| f.get(&r).copied())
                    .collect();
                if let (Some(&w), 2) = (f.get(&q), opposite.len()) {
                    g.insert((2 * i + a, 2 * j + b), (v + w) * 0.375 + (opposite[0] + opposite[1]) * 0.125);
                }
            }
        }
        g
    }

    /// Evaluates the Gregory triangle at `(s, t)` away from the corners (module doc's net).
    fn evaluate(points: &[DVec3; 18], s: f64, t: f64) -> DVec3 {
        let w = 1.0 - s - t;
        let blend = |a: usize, b: usize, x: f64, y: f64| {
            if x + y > 0.0 {
                (points[a] * x + points[b] * y) / (x + y)
            } else {
                points[a]
            }
        };
        let net: HashMap<(usize, usize), DVec3> = [
            ((0, 0), points[0]),
            ((1, 0), points[1]),
            ((2, 0), points[15]),
            ((3, 0), points[7]),
            ((4, 0), points[5]),
            ((0, 1), points[2]),
            ((1, 1), blend(3, 4, s, t)),
            ((2, 1), blend(8, 9, t, w)),
            ((3, 1), points[6]),
            ((0, 2), points[17]),
            ((1, 2), blend(13, 14, w, s)),
            ((2, 2), points[16]),
            ((0, 3), points[11]),
            ((1, 3), points[12]),
            ((0, 4), points[10]),
        ]
        .into_iter()
        .collect();
        let fact = |n: usize| (1..=n).product::<usize>() as f64;
        net.iter()
            .map(|(&(i, j), &p)| {
                let k = 4 - i - j;
                p * (fact(4) / (fact(i) * fact(j) * fact(k))
                    * s.powi(i as i32)
                    * t.powi(j as i32)
                    * w.powi(k as i32))
            })
            .sum()
    }

    /// A triangle of a regular lattice, all of whose corners are regular, is a patch of the
    /// quartic box spline; OpenSubdiv would use its `LOOP` patch, but the Gregory triangle of
    /// the same neighbourhood must be the same quartic. Checked independently of any
    /// OpenSubdiv formula: at the 15 points `(i/4, j/4)` of the triangle — the vertices of two
    /// steps of Loop subdivision — the Gregory triangle equals their Loop limit positions
    /// (½ and 1/12 of the ring), and a quartic is determined by those 15 values.
    #[test]
    fn loop_gregory_regular_triangle_is_the_box_spline() {
        let mut rng = Rng(5);
        let mut f = HashMap::new();
        for i in -3..=4 {
            for j in -3..=4 {
                let p = DVec3::new(i as f64 + 0.5 * j as f64, j as f64 * 0.866, 0.0) + rng.point(2.0) * 0.15;
                f.insert((i, j), p);
            }
        }
        let fine = subdivide(&subdivide(&f));
        let limit = |i: i64, j: i64| {
            let ring: DVec3 = DIRS.iter().map(|&(a, b)| fine[&(i + a, j + b)]).sum();
            fine[&(i, j)] * 0.5 + ring / 12.0
        };
        // Each corner's fan starts at the face whose leading edge points along +i.
        let corner = |(i, j): (i64, i64), patch_face: usize| LoopCorner {
            position: f[&(i, j)],
            num_faces: 6,
            patch_face,
            boundary: false,
            sharp: false,
            dart: false,
            ring: DIRS.iter().map(|&(a, b)| f[&(i + a, j + b)]).collect(),
        };
        // Corner (0,0) is in the patch through its face 0, (1,0) through face 2, (0,1) face 4.
        let source = LoopGregorySource { corners: [corner((0, 0), 0), corner((1, 0), 2), corner((0, 1), 4)] };
        source.validate().unwrap();
        let points = gregory_triangle_points(&source);
        for i in 0..=4 {
            for j in 0..=4 - i {
                let (s, t) = (i as f64 / 4.0, j as f64 / 4.0);
                let d = (evaluate(&points, s, t) - limit(i, j)).length();
                assert!(d < 1e-12, "({s}, {t}): {d}");
            }
        }
        // The interior face points of a regular triangle coincide.
        for c in 0..3 {
            assert!((points[5 * c + 3] - points[5 * c + 4]).length() < 1e-15);
        }
    }

    /// Along a smooth irregular boundary edge the patch's edge is the boundary's cubic
    /// B-spline (as a quartic): the boundary rule does not depend on the interior.
    #[test]
    fn loop_gregory_boundary_edge_is_the_boundary_bspline() {
        let patches = fixture();
        let patch = patches
            .iter()
            .find(|p| {
                let c = &p.corners[0];
                c.2 && !c.3 && c.0 != 3 && c.0 > 1 && c.1 == 0
            })
            .expect("a smooth irregular boundary corner with the patch at its leading edge");
        let points = random_points(patch.num_points, 3);
        let source = patch.source(&points);
        let g = gregory_triangle_points(&source);
        // Boundary polygon: the corner's last boundary neighbour, the corner, then the next
        // corner; the patch edge 0 → 1 is the span between the corner and its neighbour.
        let c0 = &source.corners[0];
        let before = c0.ring[c0.num_faces];
        // The next corner is on the boundary too, the patch in its last face (the edge back
        // to corner 0 is its trailing boundary edge), so its first ring point continues the
        // boundary.
        let c1 = &source.corners[1];
        assert!(c1.boundary && c1.patch_face + 1 == c1.num_faces);
        let b = [before, c0.position, c1.position, c1.ring[0]];
        for k in 0..=8 {
            let s = k as f64 / 8.0;
            let d = (evaluate(&g, s, 0.0) - bspline(b, s)).length();
            assert!(d < 1e-12, "{}: s = {s}: {d}", patch.header);
        }
    }

    #[test]
    fn loop_gregory_interior_ring_start_does_not_matter() {
        let patch = fixture().into_iter().find(|p| p.corners[0].0 == 7 && !p.corners[0].2).unwrap();
        let points = random_points(patch.num_points, 9);
        let source = patch.source(&points);
        let mut rotated = source.clone();
        let c = &mut rotated.corners[0];
        c.ring.rotate_left(3);
        c.patch_face = (c.patch_face + c.num_faces - 3) % c.num_faces;
        rotated.validate().unwrap();
        let (a, b) = (gregory_triangle_points(&source), gregory_triangle_points(&rotated));
        for (p, q) in a.iter().zip(&b) {
            assert!((*p - *q).abs().max_element() < 1e-12);
        }
    }

    #[test]
    fn loop_gregory_validate_catches_bad_sources() {
        let patch = fixture().into_iter().find(|p| p.corners[1].0 == 6 && !p.corners[1].2).unwrap();
        let points = random_points(patch.num_points, 1);
        let mut source = patch.source(&points);
        source.corners[1].ring.reverse();
        assert!(matches!(source.validate(), Err(GregorySourceError::Mismatch { corner: 1, .. })));
        source.corners[1].ring.pop();
        assert!(matches!(source.validate(), Err(GregorySourceError::RingLength { corner: 1, .. })));
        let mut source = patch.source(&points);
        source.corners[2].patch_face = source.corners[2].num_faces;
        assert!(matches!(source.validate(), Err(GregorySourceError::BadFan { corner: 2 })));
        // Two triangles on the same three vertices, unrefined: OpenSubdiv cannot number its
        // source points (every ring repeats a corner), and neither can tessera.
        let p = [DVec3::X, DVec3::Y, DVec3::Z];
        let val2 = |i: usize| LoopCorner {
            position: p[i],
            num_faces: 2,
            patch_face: 0,
            boundary: false,
            sharp: false,
            dart: false,
            ring: vec![p[(i + 1) % 3], p[(i + 2) % 3]],
        };
        let pillow = LoopGregorySource { corners: [val2(0), val2(1), val2(2)] };
        assert_eq!(pillow.validate(), Err(GregorySourceError::Layout));
    }
}
