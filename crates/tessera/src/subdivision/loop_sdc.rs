//! OpenSubdiv's Loop refinement and limit rules with creases, as pure functions over one
//! edge's or vertex's neighbourhood: the masks that one level of Loop refinement applies to a
//! triangle mesh, and the masks that take a vertex to its limit position and two limit
//! tangents. They follow OpenSubdiv 3.6.0's Sdc (`opensubdiv/sdc/loopScheme.h` for the
//! masks, `opensubdiv/sdc/scheme.h` for how rules pick and blend them,
//! `opensubdiv/sdc/crease.h`/`crease.cpp` for the rules themselves) as Far calls it
//! (`opensubdiv/far/primvarRefiner.h`), so that a triangle mesh refined with them agrees with
//! OpenSubdiv's own Loop refinement.
//!
//! Everything that does not depend on the scheme — the vertex rule a sharpness gives
//! ([`VertexRule`]), how sharpness decays from a level to the next, the fractional weight
//! that blends a parent rule's mask with its child's, the rule of an edge's child vertex
//! ([`edge_child_rule`]), the base level's sharpening of boundaries and non-manifold
//! features, and, as in Sdc's `Scheme<>` template, the derivation of a mask's parent and
//! child rules with their crease and corner masks and the blending of the two — is
//! Catmark's and lives in [`super::sdc`]; this module supplies Loop's smooth weights to it.
//!
//! # Arithmetic
//!
//! As in [`super::sdc`]: sharpness is `f32` and what derives from it alone is computed in
//! `f32` in Sdc's order; mask weights are `f64`, as in `Far::PrimvarRefinerReal<double>`.
//! Loop's irregular weights involve `cos` and `sin`; they are evaluated in `f64` with the
//! same operations in the same order as Sdc's, so that with the platform's C library (which
//! both Rust's and C++'s `cos`/`sin` call) the weights agree with OpenSubdiv's to the bit.
//! The regular valence 6 takes Sdc's special cases (⅝ and 1/16, ½ and 1/12, tangent weights
//! of exact halves and √3/2). For the position weights the general formula happens to give
//! the same `f64` values; for the tangents it does not (`cos` 60° rounds to
//! 0.5000000000000001).
//!
//! # What the caller prepares
//!
//! The refinement masks take the sharpness a refinement level *stores*, at the base level the
//! cage's tags after Far's sharpening ([`super::sdc::base_edge_sharpness`],
//! [`super::sdc::base_vertex_sharpness`]): a boundary vertex is recognised by its
//! infinitely sharp boundary edges, and a non-manifold vertex is a corner or (on an interior
//! non-manifold crease) a crease, never smooth. Faces are triangles: an edge's "faces" are
//! the triangles beside it, and the smooth edge mask weighs the vertex of each that is
//! opposite the edge (Far's reading of Sdc's Loop face weights; Sdc's other reading, face
//! centres, is not Far's and is not offered here).
//!
//! # Ordering
//!
//! The refinement masks do not depend on the order of a vertex's edges (the smooth rule
//! weighs all alike and the crease rule finds its two edges by sharpness), as long as
//! `edge_sharpness[i]` and `edge_ends[i]` describe the same edge. The **limit tangent masks
//! do**: they take a vertex's incident edges in Vtr's order (`opensubdiv/vtr/level.cpp`,
//! `orderVertexFacesAndEdges`):
//!
//! * counter-clockwise around the vertex, seen from the side its triangles face (the side
//!   their counter-clockwise corners face), so that triangle `i` lies between edges `i` and
//!   `i + 1`;
//! * an interior vertex may start at any edge: the first tangent points along edge 0;
//! * a boundary vertex starts at its *leading* boundary edge, the one that leaves the vertex
//!   in its triangle's corner order, and ends at the trailing one, so that its triangles are
//!   `0..edges − 1` and the first tangent points along the leading edge;
//! * at a crease (two sharp edges, first `c0` and last `c1` in this order, as Sdc's
//!   `GetSharpEdgePairOfCrease` picks them), the first tangent runs along the crease towards
//!   edge `c0`, and the second crosses the triangles of the counter-clockwise span from `c0`
//!   to `c1` (the edges strictly between them), pointing into it. For a boundary vertex that
//!   span is its whole fan and `c0 = 0`;
//! * at a corner, the first tangent points along edge 0 and the second along edge 1.
//!
//! The second tangent is oriented so that the normal is tangent 1 × tangent 2. Tangent
//! magnitudes are OpenSubdiv's: unscaled at a smooth vertex, scaled at creases and corners
//! to roughly match (see [`limit_masks`]).
//!
//! Cross-checked against OpenSubdiv 3.6.0's Sdc itself by the fixture
//! `crates/tessera/tests/fixtures/sdc/loop_masks.txt` (`tools/osd-oracle/loop_sdc_check.sh`).

use std::f64::consts::PI;

use glam::DVec3;

use super::sdc::{edge_mask_with, is_sharp, sharp_edge_pair_of_crease, vertex_mask_with, SmoothVertexMask};

/// Loop's edge masks have Catmark's shape, one weight for both ends and one for every
/// triangle beside the edge; for Loop that weight is the vertex opposite the edge in each
/// triangle (`EdgeMask::face`, applied to those vertices), where Catmark's is its face point.
pub use super::sdc::{edge_child_rule, EdgeMask, VertexRule};
use super::CreaseMethod;

/// The valence of a regular Loop vertex, whose masks Sdc special-cases with exact fractions.
pub const REGULAR_VALENCE: usize = 6;

/// √3 as the nearest `f64`, the scale of the regular tangent masks (sin 60° = √3/2).
const ROOT3: f64 = 1.7320508075688772;

// ---------------------------------------------------------------------------------------
// Edge points
// ---------------------------------------------------------------------------------------

/// The mask of the edge point of an edge with sharpness `sharpness` (as stored at this
/// level) and `faces` incident triangles (two for a manifold interior edge; one or more than
/// two only for boundary and non-manifold edges, which Far makes infinitely sharp; at least
/// one), whose child vertex has rule `child_rule` ([`edge_child_rule`]). This is Sdc's
/// `ComputeEdgeVertexMask` (`opensubdiv/sdc/scheme.h`, `opensubdiv/sdc/loopScheme.h`) with
/// the rules Far gives it (`opensubdiv/far/primvarRefiner.h`):
///
/// * smooth edge (sharpness 0): ⅜ each end, ⅛ each of the two opposite vertices; with
///   another triangle count the opposite vertices share the same ¼ (⅛·2/faces each);
/// * sharp edge whose child vertex is a crease: the midpoint, ½ each end;
/// * sharp edge whose child vertex is not (its sharpness decays to 0 on a child edge this
///   level): `s`·crease + (1 − `s`)·smooth with the edge's sharpness `s`, unclamped as in
///   Vtr, so that with Chaikin a sharpness in [1, 4/3) gives weights outside [0, 1] exactly
///   as in OpenSubdiv.
///
/// Cost: O(1).
pub fn edge_mask(sharpness: f32, child_rule: VertexRule, faces: usize) -> EdgeMask {
    debug_assert!(faces > 0 || is_sharp(sharpness), "a smooth edge needs a triangle");
    // The non-manifold case keeps the ratio of the ends' weight to the triangles' total.
    let opposite = if faces == 2 { 0.125 } else { 0.125 * (2.0 / faces as f64) };
    edge_mask_with(sharpness, child_rule, EdgeMask { vertex: 0.375, face: opposite, faces })
}

/// The neighbourhood of an edge, for [`edge_point`].
#[derive(Debug, Clone, Copy)]
pub struct EdgeNeighborhood<'a> {
    /// The edge's two vertices.
    pub ends: [DVec3; 2],
    /// Its sharpness at this level.
    pub sharpness: f32,
    /// The sharpness of its two child edges ([`super::sdc::child_edge_sharpness`] at either
    /// end).
    pub child_sharpness: [f32; 2],
    /// The vertex opposite the edge in each of its triangles, any order.
    pub opposite: &'a [DVec3],
}

/// The edge point of an edge: [`edge_mask`] with the child rule from [`edge_child_rule`],
/// applied to the neighbourhood.
///
/// Cost: O(faces).
pub fn edge_point(edge: &EdgeNeighborhood<'_>) -> DVec3 {
    let rule = edge_child_rule(edge.sharpness, edge.child_sharpness);
    edge_mask(edge.sharpness, rule, edge.opposite.len()).apply(edge.ends, edge.opposite)
}

// ---------------------------------------------------------------------------------------
// Vertex points
// ---------------------------------------------------------------------------------------

/// Loop's smooth vertex-point weights at a vertex of `valence` edges, `(vertex, each edge
/// end)`, as Sdc computes them (`opensubdiv/sdc/loopScheme.h`, `assignSmoothMaskForVertex`,
/// after Hbr): exactly ⅝ and 1/16 at valence 6, otherwise Loop's original
/// β = (⅝ − (⅜ + ¼·cos(2π/n))²)/n for each edge end and 1 − n·β for the vertex (3/16 and
/// 7/16 at valence 3). Any valence ≥ 1.
///
/// Cost: O(1), one `cos` for an irregular valence.
pub fn smooth_vertex_weights(valence: usize) -> (f64, f64) {
    if valence == REGULAR_VALENCE {
        return (0.625, 0.0625);
    }
    let edge = loop_beta(valence);
    (1.0 - edge * valence as f64, edge)
}

/// Loop's β for an irregular `valence`, in Sdc's order of operations.
fn loop_beta(valence: usize) -> f64 {
    let n = valence as f64;
    let inv = 1.0 / n;
    let beta = 0.25 * (PI * 2.0 * inv).cos() + 0.375;
    (0.625 - beta * beta) * inv
}

/// A vertex point's mask, in the shape Loop's vertex masks always have: a weight for the
/// vertex and one common weight for the far ends of its incident edges, except possibly two
/// crease edges that weigh differently (no face weights: Loop's vertex masks have none).
/// Weights refer to the order of the `edge_sharpness` given to [`vertex_mask`]; they sum
/// to 1.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VertexMask {
    /// Weight of the vertex itself.
    pub vertex: f64,
    /// Weight of the far end of every incident edge that is not one of [`Self::crease`].
    pub edge: f64,
    /// The two crease edges (indices into the incident edges, distinct) and the weight of
    /// each one's far end, when a crease rule takes part.
    pub crease: Option<([usize; 2], f64)>,
    /// The parent vertex's rule.
    pub rule: VertexRule,
    /// The child vertex's rule; where it differs from [`Self::rule`] and the parent is a
    /// crease or corner, the two masks are blended.
    pub child_rule: VertexRule,
    /// The parent rule's share of the blend (1 where the rules agree).
    pub parent_weight: f64,
}

impl VertexMask {
    /// The weight of the far end of incident edge `i`.
    ///
    /// Cost: O(1).
    pub fn edge_weight(&self, i: usize) -> f64 {
        match self.crease {
            Some((ends, w)) if ends.contains(&i) => w,
            _ => self.edge,
        }
    }

    /// The vertex point: `v` the vertex, `edge_ends[i]` the far end of incident edge `i` (the
    /// order given to [`vertex_mask`]), summed as Far does, edges first.
    ///
    /// Cost: O(edges).
    pub fn apply(&self, v: DVec3, edge_ends: &[DVec3]) -> DVec3 {
        let mut p = DVec3::ZERO;
        for (i, &e) in edge_ends.iter().enumerate() {
            p += e * self.edge_weight(i);
        }
        p + v * self.vertex
    }
}

/// The mask of the vertex point of a vertex with sharpness `vertex_sharpness` whose incident
/// edges have `edge_sharpness` (values stored at this level, see the module documentation),
/// with `faces` incident triangles. This is Sdc's `ComputeVertexVertexMask`
/// (`opensubdiv/sdc/scheme.h`, `opensubdiv/sdc/loopScheme.h`), which derives the parent and
/// child rules as Vtr's tags do:
///
/// * the parent rule is [`super::sdc::vertex_rule`]; the child rule is the rule of the child vertex, with
///   the child sharpness of [`super::sdc`] ([`super::sdc::child_vertex_sharpness`],
///   [`super::sdc::child_edge_sharpnesses_around_vertex`] by `crease`);
/// * smooth and dart: [`smooth_vertex_weights`] for the valence (requires
///   `faces == edge_sharpness.len()`: Sdc sizes Loop's smooth mask by the triangle count,
///   and a boundary or non-manifold vertex is never smooth after Far's sharpening);
/// * crease: ¾ the vertex, ⅛ the far end of each of the two sharp edges;
/// * corner: the vertex;
/// * where parent and child rules differ, w·parent + (1 − w)·child with w from
///   [`super::sdc::fractional_weight_at_vertex`] (a smooth or dart parent always keeps its
///   mask).
///
/// The order of `edge_sharpness` is the order of [`VertexMask::edge_weight`]; any order will
/// do.
///
/// # Panics
///
/// In debug builds, if a smooth rule meets `faces != edge_sharpness.len()`.
///
/// Cost: O(edges), no allocation, one `cos` where an irregular smooth rule takes part.
pub fn vertex_mask(
    vertex_sharpness: f32,
    edge_sharpness: &[f32],
    faces: usize,
    crease: CreaseMethod,
) -> VertexMask {
    let smooth = |valence| {
        let (vertex, edge) = smooth_vertex_weights(valence);
        SmoothVertexMask { vertex, edge, face: None }
    };
    // Loop's masks weigh no faces, so the shared mask's face weight is always 0.
    let m = vertex_mask_with(vertex_sharpness, edge_sharpness, faces, crease, smooth);
    VertexMask {
        vertex: m.vertex,
        edge: m.edge,
        crease: m.crease,
        rule: m.rule,
        child_rule: m.child_rule,
        parent_weight: m.parent_weight,
    }
}

/// The neighbourhood of a vertex, for [`vertex_point`].
#[derive(Debug, Clone, Copy)]
pub struct VertexNeighborhood<'a> {
    /// The vertex.
    pub position: DVec3,
    /// Its sharpness at this level.
    pub sharpness: f32,
    /// The far end of each incident edge.
    pub edge_ends: &'a [DVec3],
    /// The sharpness of the same edges, in the same order.
    pub edge_sharpness: &'a [f32],
    /// Its incident triangles (as many as edges for an interior vertex, one fewer on a
    /// boundary).
    pub faces: usize,
}

/// The vertex point of a vertex: [`vertex_mask`] applied to the neighbourhood.
///
/// Cost: O(edges), no allocation.
pub fn vertex_point(vertex: &VertexNeighborhood<'_>, crease: CreaseMethod) -> DVec3 {
    debug_assert_eq!(vertex.edge_ends.len(), vertex.edge_sharpness.len());
    vertex_mask(vertex.sharpness, vertex.edge_sharpness, vertex.faces, crease)
        .apply(vertex.position, vertex.edge_ends)
}

// ---------------------------------------------------------------------------------------
// Limit masks
// ---------------------------------------------------------------------------------------

/// Loop's smooth limit-position weights at a vertex of `valence` edges, `(vertex, each edge
/// end)`, as Sdc computes them (`opensubdiv/sdc/loopScheme.h`, `assignSmoothLimitMask`):
/// exactly ½ and 1/12 at valence 6, otherwise 1/(n + 3/(8β)) for each edge end, with
/// [`smooth_vertex_weights`]'s β, and 1 − n times that for the vertex. Any valence ≥ 1.
///
/// Cost: O(1), one `cos` for an irregular valence.
pub fn smooth_limit_weights(valence: usize) -> (f64, f64) {
    if valence == REGULAR_VALENCE {
        return (0.5, 1.0 / 12.0);
    }
    let n = valence as f64;
    let edge = 1.0 / (n + 3.0 / (8.0 * loop_beta(valence)));
    (1.0 - edge * n, edge)
}

/// A limit mask: a weight for the vertex and one for the far end of each incident edge, in
/// the order given to [`limit_masks`] (a corner's position mask, which has no edge weights
/// in Sdc, has zeros). Position masks sum to 1, tangent masks to 0.
#[derive(Debug, Clone, PartialEq)]
pub struct LimitMask {
    /// Weight of the vertex itself.
    pub vertex: f64,
    /// Weight of the far end of each incident edge.
    pub edges: Vec<f64>,
}

impl LimitMask {
    fn zero(valence: usize) -> Self {
        Self { vertex: 0.0, edges: vec![0.0; valence] }
    }

    /// The mask applied to `v` and the far ends `edge_ends` of its edges (in the mask's
    /// order), summed as Far does, edges first.
    ///
    /// Cost: O(edges).
    pub fn apply(&self, v: DVec3, edge_ends: &[DVec3]) -> DVec3 {
        debug_assert_eq!(edge_ends.len(), self.edges.len(), "one far end per edge of the mask");
        let mut p = DVec3::ZERO;
        for (&e, &w) in edge_ends.iter().zip(&self.edges) {
            p += e * w;
        }
        p + v * self.vertex
    }
}

/// A vertex's limit position mask and its two limit tangent masks (see [`limit_masks`]).
#[derive(Debug, Clone, PartialEq)]
pub struct LimitMasks {
    /// The limit position.
    pub position: LimitMask,
    /// The first tangent, along edge 0 (smooth, corner) or the crease towards its first edge.
    pub tangent1: LimitMask,
    /// The second tangent, such that tangent 1 × tangent 2 is the normal.
    pub tangent2: LimitMask,
}

/// The edges of a crease for a limit mask of rule crease.
fn crease_ends(edge_sharpness: &[f32]) -> [usize; 2] {
    sharp_edge_pair_of_crease(edge_sharpness.len(), |i| is_sharp(edge_sharpness[i]))
        .expect("the crease rule needs a sharp edge")
}

/// The limit position mask of a vertex whose incident edges have `edge_sharpness`, with
/// `faces` incident triangles, under `rule` (Sdc's `ComputeVertexLimitMask`,
/// `opensubdiv/sdc/scheme.h`, `opensubdiv/sdc/loopScheme.h`):
///
/// * smooth and dart: [`smooth_limit_weights`] (requires `faces == edge_sharpness.len()`);
/// * crease: ⅔ the vertex, ⅙ the far end of each of the two sharp edges, the limit of the
///   cubic B-spline that the crease refines to, whatever the valence;
/// * corner: the vertex.
///
/// The rule is the caller's, as in Sdc: Far passes the vertex's rule at the last level it
/// refined to, where semi-sharp features may not have decayed yet and the limit is neither
/// the smooth nor the sharp one; the rule decides. Any edge order will do.
///
/// # Panics
///
/// If `rule` is [`VertexRule::Crease`] and no edge is sharp; in debug builds, if a smooth
/// rule meets `faces != edge_sharpness.len()`.
///
/// Cost: O(edges), one allocation, one `cos` for an irregular smooth vertex.
pub fn limit_position_mask(rule: VertexRule, edge_sharpness: &[f32], faces: usize) -> LimitMask {
    let n = edge_sharpness.len();
    let mut m = LimitMask::zero(n);
    match rule {
        VertexRule::Smooth | VertexRule::Dart => {
            debug_assert_eq!(faces, n, "the smooth Loop limit needs as many triangles as edges");
            let (vertex, edge) = smooth_limit_weights(n);
            m.vertex = vertex;
            m.edges.fill(edge);
        }
        VertexRule::Crease => {
            m.vertex = 4.0 / 6.0;
            for i in crease_ends(edge_sharpness) {
                m.edges[i] = 1.0 / 6.0;
            }
        }
        VertexRule::Corner => m.vertex = 1.0,
    }
    m
}

/// The limit position and limit tangent masks of a vertex whose incident edges, in Vtr's
/// counter-clockwise order (see the module documentation), have `edge_sharpness`, with
/// `faces` incident triangles, under `rule` (Sdc's `ComputeVertexLimitMask` with tangents,
/// `opensubdiv/sdc/scheme.h`, `opensubdiv/sdc/loopScheme.h`). The position mask is
/// [`limit_position_mask`]'s; the tangents, for n edges:
///
/// * smooth and dart: tangent 1 weighs edge i by cos(2πi/n), tangent 2 by sin(2πi/n), the
///   vertex 0 (at valence 6 exactly ±1, ±½ and ±√3/2);
/// * crease, with crease edges `c0 < c1` and k = c1 − c0 − 1 edges strictly between them:
///   tangent 1 is 3/2·(edge `c0` − edge `c1`); tangent 2 weighs only the vertex and edges
///   `c0..=c1`:
///   - k = 0: 3 each crease edge, −6 the vertex;
///   - k = 1: 3 the middle edge, −3 the vertex;
///   - k = 2 (the regular boundary): −√3/2 each crease edge, √3 each middle edge, −√3 the
///     vertex;
///   - k > 2: with θ = π/(k + 1), −3·sin θ each crease edge, −6·(cos θ − 1)·sin(iθ) the
///     i-th edge after `c0`, 0 the vertex (the published formula turned to point into the
///     span, and scaled by 3);
/// * corner: tangent 1 is 3·(edge 0 − vertex), tangent 2 is 3·(edge 1 − vertex).
///
/// A vertex of one edge (only a non-manifold cage has one, and Far makes it a corner) has no
/// tangent plane, and its tangent masks are whatever the formulas give, as in OpenSubdiv: they
/// do not sum to 0. A corner's tangent 2 there has no place for its edge weight and drops it
/// (OpenSubdiv writes it past the vertex's edges), leaving −3 the vertex.
///
/// The scale factors are OpenSubdiv's, chosen to give tangents of similar magnitude over a
/// regular mesh at interior, boundary and corner vertices alike.
///
/// # Panics
///
/// As [`limit_position_mask`].
///
/// Cost: O(edges), three allocations; `cos` and `sin` per edge at an irregular smooth vertex
/// or a crease with more than two edges between its ends.
pub fn limit_masks(rule: VertexRule, edge_sharpness: &[f32], faces: usize) -> LimitMasks {
    let n = edge_sharpness.len();
    let position = limit_position_mask(rule, edge_sharpness, faces);
    let (mut t1, mut t2) = (LimitMask::zero(n), LimitMask::zero(n));
    match rule {
        VertexRule::Smooth | VertexRule::Dart => {
            if n == REGULAR_VALENCE {
                let h = 0.5 * ROOT3;
                t1.edges.copy_from_slice(&[1.0, 0.5, -0.5, -1.0, -0.5, 0.5]);
                t2.edges.copy_from_slice(&[0.0, h, h, 0.0, -h, -h]);
            } else {
                let alpha = 2.0 * PI / n as f64;
                for i in 0..n {
                    let a = alpha * i as f64;
                    t1.edges[i] = a.cos();
                    t2.edges[i] = a.sin();
                }
            }
        }
        VertexRule::Crease => {
            let [c0, c1] = crease_ends(edge_sharpness);
            t1.edges[c0] = 1.5;
            t1.edges[c1] = -1.5;
            let between = c1 - c0 - 1;
            match between {
                0 => {
                    t2.vertex = -6.0;
                    t2.edges[c0] = 3.0;
                    t2.edges[c1] = 3.0;
                }
                1 => {
                    t2.vertex = -3.0;
                    t2.edges[c0 + 1] = 3.0;
                }
                2 => {
                    t2.vertex = -ROOT3;
                    t2.edges[c0] = -0.5 * ROOT3;
                    t2.edges[c1] = -0.5 * ROOT3;
                    t2.edges[c0 + 1] = ROOT3;
                    t2.edges[c0 + 2] = ROOT3;
                }
                k => {
                    let theta = PI / (k + 1) as f64;
                    t2.edges[c0] = -3.0 * theta.sin();
                    t2.edges[c1] = t2.edges[c0];
                    let scale = -6.0 * (theta.cos() - 1.0);
                    for i in 1..=k {
                        t2.edges[c0 + i] = scale * (i as f64 * theta).sin();
                    }
                }
            }
        }
        VertexRule::Corner => {
            t1.vertex = -3.0;
            t2.vertex = -3.0;
            if let Some(w) = t1.edges.get_mut(0) {
                *w = 3.0;
            }
            if let Some(w) = t2.edges.get_mut(1) {
                *w = 3.0;
            }
        }
    }
    LimitMasks { position, tangent1: t1, tangent2: t2 }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::subdivision::sdc::child_edge_sharpness;
    use crate::subdivision::sdc::tests::{each_fixture_line, read_edge_line, Tokens};
    use crate::subdivision::INFINITELY_SHARP;

    const INF: f32 = INFINITELY_SHARP;

    #[test]
    fn regular_smooth_masks_are_the_textbook_fractions() {
        // Valence 6: ⅝ and 1/16 refining, ½ and 1/12 at the limit.
        assert_eq!(smooth_vertex_weights(6), (0.625, 0.0625));
        assert_eq!(smooth_limit_weights(6), (0.5, 1.0 / 12.0));
        let m = vertex_mask(0.0, &[0.0; 6], 6, CreaseMethod::Uniform);
        assert_eq!((m.vertex, m.crease, m.rule), (0.625, None, VertexRule::Smooth));
        assert!((0..6).all(|i| m.edge_weight(i) == 0.0625));
        // Valence 3: Loop's β is 3/16 (cos 120° = −½ makes the bracket ¼).
        let (v, e) = smooth_vertex_weights(3);
        assert!((e - 3.0 / 16.0).abs() < 1e-16 && (v - 7.0 / 16.0).abs() < 1e-16, "{v} {e}");
        // The general formula gives the special case's β at valence 6 to the bit; the
        // tangents' special case is the one that matters.
        assert_eq!(loop_beta(6), 0.0625);
        let t = limit_masks(VertexRule::Smooth, &[0.0; 6], 6);
        assert_eq!(t.tangent1.edges, [1.0, 0.5, -0.5, -1.0, -0.5, 0.5]);
        assert_ne!((std::f64::consts::PI / 3.0).cos(), 0.5);
    }

    #[test]
    fn crease_and_corner_vertex_masks() {
        // A boundary vertex: ¾ itself, ⅛ each boundary neighbour.
        let m = vertex_mask(0.0, &[INF, 0.0, 0.0, INF], 3, CreaseMethod::Uniform);
        assert_eq!((m.rule, m.child_rule), (VertexRule::Crease, VertexRule::Crease));
        assert_eq!((m.vertex, m.edge, m.crease), (0.75, 0.0, Some(([0, 3], 0.125))));
        // An interior crease through edges 1 and 4.
        let m = vertex_mask(0.0, &[0.0, 3.0, 0.0, 0.0, INF, 0.0], 6, CreaseMethod::Chaikin);
        assert_eq!((m.vertex, m.edge, m.crease), (0.75, 0.0, Some(([1, 4], 0.125))));
        // Corners: a sharp vertex, three sharp edges.
        let p = DVec3::new(0.3, -1.0, 2.0);
        let ends = [DVec3::X, DVec3::Y, DVec3::Z, DVec3::ONE];
        let corner = vertex_mask(INF, &[INF, 0.0, 0.0, INF], 3, CreaseMethod::Uniform);
        assert_eq!(corner.apply(p, &ends), p);
        let corner = vertex_mask(0.0, &[INF, 2.0, 0.0, INF], 3, CreaseMethod::Uniform);
        assert_eq!(corner.rule, VertexRule::Corner);
        assert_eq!(corner.apply(p, &ends), p);
    }

    #[test]
    fn edge_masks() {
        // Smooth: ⅜ ⅜ ⅛ ⅛.
        assert_eq!(edge_mask(0.0, VertexRule::Smooth, 2), EdgeMask { vertex: 0.375, face: 0.125, faces: 2 });
        // Sharp: the midpoint.
        assert_eq!(edge_mask(INF, VertexRule::Crease, 1), EdgeMask { vertex: 0.5, face: 0.0, faces: 1 });
        // Non-manifold: the opposite vertices share ¼.
        assert_eq!(edge_mask(0.0, VertexRule::Smooth, 4).face, 0.0625);
        // Half sharp: half way between the two.
        let (a, b) = (DVec3::ZERO, DVec3::new(1.0, 0.0, 0.2));
        let opp = [DVec3::new(0.5, 1.0, 0.0), DVec3::new(0.5, -1.0, 0.3)];
        let point = |s: f32| {
            let c = child_edge_sharpness(s, &[s, 0.0], CreaseMethod::Uniform);
            edge_point(&EdgeNeighborhood {
                ends: [a, b],
                sharpness: s,
                child_sharpness: [c, c],
                opposite: &opp,
            })
        };
        let smooth = (a + b) * 0.375 + (opp[0] + opp[1]) * 0.125;
        let mid = (a + b) * 0.5;
        assert!((point(0.0) - smooth).length() < 1e-15);
        assert!((point(0.5) - (smooth + mid) * 0.5).length() < 1e-15);
        assert_eq!(point(1.0), mid);
        assert_eq!(point(3.5), mid);
    }

    #[test]
    fn fractional_sharpness_blends_vertex_masks() {
        // A crease of two 0.5 edges decays this level: half crease, half smooth.
        let es = [0.5, 0.0, 0.0, 0.5, 0.0];
        let (sv, se) = smooth_vertex_weights(5);
        for method in [CreaseMethod::Uniform, CreaseMethod::Chaikin] {
            let m = vertex_mask(0.0, &es, 5, method);
            assert_eq!(
                (m.rule, m.child_rule, m.parent_weight),
                (VertexRule::Crease, VertexRule::Smooth, 0.5)
            );
            assert_eq!(m.vertex, 0.5 * 0.75 + 0.5 * sv);
            assert_eq!(m.crease, Some(([0, 3], 0.5 * 0.125 + 0.5 * se)));
            assert_eq!(m.edge, 0.5 * se);
        }
        // A boundary corner of sharpness 0.25 becomes a crease: ¼ corner, ¾ crease.
        let m = vertex_mask(0.25, &[INF, 0.0, INF], 2, CreaseMethod::Uniform);
        assert_eq!((m.rule, m.child_rule), (VertexRule::Corner, VertexRule::Crease));
        assert_eq!((m.vertex, m.edge, m.crease), (0.25 + 0.75 * 0.75, 0.0, Some(([0, 2], 0.75 * 0.125))));
    }

    #[test]
    fn limit_masks_by_rule() {
        let m = limit_masks(VertexRule::Smooth, &[0.0; 6], 6);
        assert_eq!(m.position.vertex, 0.5);
        assert!(m.position.edges.iter().all(|&w| w == 1.0 / 12.0));
        // A boundary vertex: the B-spline limit ⅙ ⅔ ⅙, tangent 1 along the leading edge.
        let m = limit_masks(VertexRule::Crease, &[INF, 0.0, 0.0, INF], 3);
        assert_eq!(m.position.vertex, 4.0 / 6.0);
        assert_eq!(m.position.edges, [1.0 / 6.0, 0.0, 0.0, 1.0 / 6.0]);
        assert_eq!(m.tangent1.edges, [1.5, 0.0, 0.0, -1.5]);
        // Corner: the vertex; tangents along edges 0 and 1.
        let m = limit_masks(VertexRule::Corner, &[INF, INF], 1);
        assert_eq!(m.position, LimitMask { vertex: 1.0, edges: vec![0.0, 0.0] });
        assert_eq!(m.tangent1, LimitMask { vertex: -3.0, edges: vec![3.0, 0.0] });
        assert_eq!(m.tangent2, LimitMask { vertex: -3.0, edges: vec![0.0, 3.0] });
    }

    /// Points around a vertex at `c`: `n` neighbours on a wavy ring, so that every weight shows.
    fn ring(n: usize) -> Vec<DVec3> {
        (0..n)
            .map(|k| {
                let a = k as f64 * std::f64::consts::TAU / n as f64 + 0.3;
                DVec3::new(a.cos() * (1.0 + 0.1 * k as f64), a.sin(), 0.2 + 0.3 * (2.0 * a).sin())
            })
            .collect()
    }

    /// The limit position mask is where refinement converges: the one-ring of a smooth
    /// vertex refines into a one-ring of the same valence (vertex mask at the centre, smooth
    /// edge masks on its edges, whose opposite vertices are the ring neighbours), so
    /// iterating it carries the centre to the limit the mask predicts. Likewise a boundary
    /// vertex's crease masks converge to the ⅙ ⅔ ⅙ of the B-spline the boundary becomes.
    #[test]
    fn limit_position_is_where_refinement_converges() {
        for n in 3..=12 {
            let (mut c, mut p) = (DVec3::new(0.1, 0.2, 0.9), ring(n));
            let limit = limit_masks(VertexRule::Smooth, &vec![0.0; n], n).position.apply(c, &p);
            let vm = vertex_mask(0.0, &vec![0.0; n], n, CreaseMethod::Uniform);
            let em = edge_mask(0.0, VertexRule::Smooth, 2);
            for _ in 0..200 {
                let next: Vec<DVec3> =
                    (0..n).map(|i| em.apply([c, p[i]], &[p[(i + n - 1) % n], p[(i + 1) % n]])).collect();
                c = vm.apply(c, &p);
                p = next;
            }
            assert!((c - limit).length() < 1e-13, "valence {n}: {c} vs {limit}");
        }
        // A boundary polyline a, v, b refined by the crease rules.
        let (mut a, mut v, mut b) =
            (DVec3::new(-1.0, 0.3, 0.0), DVec3::new(0.0, 0.9, 0.4), DVec3::new(1.2, 0.0, 0.1));
        let es = [INF, 0.0, 0.0, INF];
        let limit =
            limit_position_mask(VertexRule::Crease, &es, 3).apply(v, &[a, DVec3::ZERO, DVec3::ZERO, b]);
        let vm = vertex_mask(0.0, &es, 3, CreaseMethod::Uniform);
        let em = edge_mask(INF, VertexRule::Crease, 1);
        for _ in 0..200 {
            let na = em.apply([v, a], &[DVec3::ZERO]);
            let nb = em.apply([v, b], &[DVec3::ZERO]);
            v = vm.apply(v, &[a, DVec3::ZERO, DVec3::ZERO, b]);
            (a, b) = (na, nb);
        }
        assert!((v - limit).length() < 1e-13, "{v} vs {limit}");
    }

    /// The tangents span the tangent plane the right way round: on a flat one-ring in the
    /// xy-plane, counter-clockwise seen from +z, both tangents lie in the plane, tangent 1
    /// leans towards edge 0 (or the crease's first edge) and tangent 1 × tangent 2 is +z.
    #[test]
    fn tangents_are_oriented_by_the_edge_order() {
        let flat = |n: usize, span: f64| -> Vec<DVec3> {
            (0..n).map(|k| DVec3::new((span * k as f64).cos(), (span * k as f64).sin(), 0.0)).collect()
        };
        let check = |m: &LimitMasks, ends: &[DVec3], first: DVec3, what: &str| {
            let v = DVec3::ZERO;
            let (t1, t2) = (m.tangent1.apply(v, ends), m.tangent2.apply(v, ends));
            assert!(t1.z.abs() < 1e-14 && t2.z.abs() < 1e-14, "{what}: {t1} {t2}");
            assert!(t1.dot(first) > 0.0, "{what}: tangent 1 {t1} away from {first}");
            assert!(t1.cross(t2).z > 1e-3, "{what}: {t1} × {t2}");
        };
        for n in 3..=12 {
            let ends = flat(n, std::f64::consts::TAU / n as f64);
            check(&limit_masks(VertexRule::Smooth, &vec![0.0; n], n), &ends, ends[0], &format!("smooth {n}"));
            // A boundary vertex of n edges over a half disc.
            let ends = flat(n, std::f64::consts::PI / (n - 1) as f64);
            let mut es = vec![0.0; n];
            (es[0], es[n - 1]) = (INF, INF);
            check(&limit_masks(VertexRule::Crease, &es, n - 1), &ends, ends[0], &format!("boundary {n}"));
            // A corner of n edges over a quarter disc.
            let ends = flat(n, std::f64::consts::FRAC_PI_2 / (n - 1) as f64);
            check(&limit_masks(VertexRule::Corner, &es, n - 1), &ends, ends[0], &format!("corner {n}"));
        }
    }

    // ---- OpenSubdiv's own masks -----------------------------------------------------

    /// `tools/osd-oracle/loop_sdc_check.cpp`'s output (see its header for the line format).
    const FIXTURE: &str = include_str!("../../tests/fixtures/sdc/loop_masks.txt");

    /// The largest difference allowed between a weight and OpenSubdiv's where `cos` or `sin`
    /// takes part: another platform's C library may round them differently from the one that
    /// made the fixture (on glibc every weight agrees to the bit). Weights made of fractions
    /// and sharpness alone must agree to the bit.
    const WEIGHT_TOLERANCE: f64 = 1e-15;

    /// The Loop fixture's one kind of word that the Catmark fixture lacks.
    trait MaskTokens {
        /// A labelled mask: `LABEL V E[n]`.
        fn mask(&mut self, label: &str, n: usize) -> LimitMask;
    }

    impl MaskTokens for Tokens<'_> {
        fn mask(&mut self, label: &str, n: usize) -> LimitMask {
            self.expect(label);
            LimitMask { vertex: self.f64(), edges: self.f64s(n) }
        }
    }

    #[derive(Default)]
    struct Agreement {
        vertices: usize,
        edges: usize,
        limits: usize,
        /// Edges whose mask as Vtr asks for it differs from Sdc's with no rules given.
        vtr_only: usize,
        weights: usize,
        /// Weights that differ from OpenSubdiv's at all (within the tolerance).
        inexact: usize,
        max_weight_diff: f64,
    }

    impl Agreement {
        /// Compares a weight, to the bit unless `trig` (`cos` or `sin` took part).
        fn weight(&mut self, ours: f64, theirs: f64, trig: bool, line: &str) {
            let d = (ours - theirs).abs();
            self.weights += 1;
            self.inexact += usize::from(ours.to_bits() != theirs.to_bits());
            self.max_weight_diff = self.max_weight_diff.max(d);
            if trig {
                assert!(d <= WEIGHT_TOLERANCE, "weight {ours:e} vs OpenSubdiv's {theirs:e}: {line}");
            } else {
                assert_eq!(
                    ours.to_bits(),
                    theirs.to_bits(),
                    "weight {ours:e} vs OpenSubdiv's {theirs:e}: {line}"
                );
            }
        }
        fn mask(&mut self, ours: &LimitMask, theirs: &LimitMask, trig: bool, line: &str) {
            assert_eq!(ours.edges.len(), theirs.edges.len(), "{line}");
            self.weight(ours.vertex, theirs.vertex, trig, line);
            for (&a, &b) in ours.edges.iter().zip(&theirs.edges) {
                self.weight(a, b, trig, line);
            }
        }
    }

    fn check_vertex(t: &mut Tokens<'_>, line: &str, agree: &mut Agreement) {
        let method = t.method();
        let (vs, n, nf) = (t.f32(), t.usize(), t.usize());
        let es = t.f32s(n);
        t.expect("rules");
        let (p_rule, c_rule) = (t.rule(), t.rule());
        let theirs = t.mask("w", n);

        let m = vertex_mask(vs, &es, nf, method);
        assert_eq!((m.rule, m.child_rule), (p_rule, c_rule), "{line}");
        let ours = LimitMask { vertex: m.vertex, edges: (0..n).map(|i| m.edge_weight(i)).collect() };
        let smooth_part = m.rule.is_smooth() || m.child_rule.is_smooth();
        agree.mask(&ours, &theirs, smooth_part && n != REGULAR_VALENCE, line);
        agree.vertices += 1;
    }

    fn check_limit(t: &mut Tokens<'_>, line: &str, agree: &mut Agreement) {
        let rule = t.rule();
        let (n, nf) = (t.usize(), t.usize());
        let es = t.f32s(n);
        let (pos, tan1, tan2) = (t.mask("pos", n), t.mask("tan1", n), t.mask("tan2", n));
        let ours = limit_masks(rule, &es, nf);
        assert_eq!(ours.position, limit_position_mask(rule, &es, nf));
        let trig = match rule {
            VertexRule::Smooth | VertexRule::Dart => n != REGULAR_VALENCE,
            VertexRule::Crease => {
                let [c0, c1] = crease_ends(&es);
                c1 - c0 - 1 > 2
            }
            VertexRule::Corner => false,
        };
        agree.mask(&ours.position, &pos, trig && rule.is_smooth(), line);
        agree.mask(&ours.tangent1, &tan1, trig && rule.is_smooth(), line);
        agree.mask(&ours.tangent2, &tan2, trig, line);
        agree.limits += 1;
    }

    fn check_edge(t: &mut Tokens<'_>, line: &str, agree: &mut Agreement) {
        let method = t.method();
        let (s, nf) = (t.f32(), t.usize());
        let theirs = read_edge_line(t, s, nf, method, line);
        let m = edge_mask(s, theirs.child_rule, nf);
        assert_eq!(m.faces, nf);
        for &w in &theirs.ends {
            agree.weight(m.vertex, w, false, line);
        }
        for &w in &theirs.faces {
            agree.weight(m.face, w, false, line);
        }
        agree.vtr_only += usize::from(theirs.vtr_only);
        agree.edges += 1;
    }

    #[test]
    fn loop_sdc_masks_agree_with_opensubdiv() {
        let mut agree = Agreement::default();
        each_fixture_line(FIXTURE, |kind, t, line| match kind {
            "vertex" => check_vertex(t, line, &mut agree),
            "limit" => check_limit(t, line, &mut agree),
            "edge" => check_edge(t, line, &mut agree),
            w => panic!("unknown fixture line kind {w}"),
        });
        println!(
            "{} vertex masks, {} limit mask triples, {} edge masks ({} where Vtr's rules differ from Sdc's own); {} weights, {} not bit-exact, max difference {:e}",
            agree.vertices,
            agree.limits,
            agree.edges,
            agree.vtr_only,
            agree.weights,
            agree.inexact,
            agree.max_weight_diff
        );
        assert!(agree.vertices > 1000 && agree.limits > 1000 && agree.edges > 150 && agree.vtr_only > 0);
    }

    /// Affine invariance: every refinement and limit position mask sums to 1 and every
    /// tangent mask to 0, for every neighbourhood of the fixture and a sweep of valences.
    #[test]
    fn loop_sdc_masks_are_affine() {
        let sum = |m: &LimitMask| m.vertex + m.edges.iter().sum::<f64>();
        let check = |vs: f32, es: &[f32], nf: usize, method: CreaseMethod, what: &str| {
            let n = es.len();
            let m = vertex_mask(vs, es, nf, method);
            let total = m.vertex + (0..n).map(|i| m.edge_weight(i)).sum::<f64>();
            assert!((total - 1.0).abs() < 1e-14, "vertex mask sums to {total}: {what}");
            for rule in [m.rule, m.child_rule] {
                let l = limit_masks(rule, es, nf);
                assert!((sum(&l.position) - 1.0).abs() < 1e-14, "{rule:?} position: {what}");
                // A vertex of one edge has no tangent plane (see limit_masks).
                if n >= 2 {
                    assert!(sum(&l.tangent1).abs() < 1e-13, "{rule:?} tangent 1 {l:?}: {what}");
                    assert!(sum(&l.tangent2).abs() < 1e-13, "{rule:?} tangent 2 {l:?}: {what}");
                }
            }
        };
        let mut cases = 0;
        for line in FIXTURE.lines().filter(|l| l.starts_with("vertex ")) {
            let mut t = Tokens(line.split_ascii_whitespace());
            t.expect("vertex");
            let method = t.method();
            let (vs, n, nf) = (t.f32(), t.usize(), t.usize());
            check(vs, &t.f32s(n), nf, method, line);
            cases += 1;
        }
        for line in FIXTURE.lines().filter(|l| l.starts_with("edge ")) {
            let mut t = Tokens(line.split_ascii_whitespace());
            t.expect("edge");
            t.method();
            let (s, nf) = (t.f32(), t.usize());
            for rule in [VertexRule::Smooth, VertexRule::Dart, VertexRule::Crease] {
                let m = edge_mask(s, rule, nf);
                let total = 2.0 * m.vertex + nf as f64 * m.face;
                assert!((total - 1.0).abs() < 1e-14, "edge mask sums to {total}: {line}");
            }
            cases += 1;
        }
        for n in 1..=40 {
            for method in [CreaseMethod::Uniform, CreaseMethod::Chaikin] {
                check(0.0, &vec![0.0; n], n, method, &format!("smooth valence {n}"));
                if n >= 2 {
                    let mut es = vec![0.0; n];
                    (es[0], es[n - 1]) = (INF, INF);
                    check(0.0, &es, n - 1, method, &format!("boundary valence {n}"));
                    check(0.7, &es, n - 1, method, &format!("semi-sharp boundary corner valence {n}"));
                    let mut es = vec![0.0; n];
                    (es[n / 3], es[n - 1 - n / 4]) = (0.6, 1.4);
                    check(0.0, &es, n, method, &format!("semi-sharp crease valence {n}"));
                }
                cases += 1;
            }
        }
        assert!(cases > 1500, "{cases}");
    }
}
