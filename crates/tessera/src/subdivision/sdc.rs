//! OpenSubdiv's Catmull-Clark ("Catmark") refinement rules with creases, as pure functions
//! over one face's, edge's or vertex's neighbourhood: the masks that one level of refinement
//! applies, the rule that picks a vertex's mask, and how sharpness decays from a level to the
//! next. They follow OpenSubdiv 3.6.0's Sdc (`opensubdiv/sdc/scheme.h`,
//! `opensubdiv/sdc/catmarkScheme.h`, `opensubdiv/sdc/crease.cpp`) as Vtr calls it
//! (`opensubdiv/far/primvarRefiner.h`, `opensubdiv/vtr/refinement.cpp`), so that a mesh refined
//! with them agrees with OpenSubdiv's own refinement, and so with Bfr, which refines a face's
//! neighbourhood the same way.
//!
//! # Shared with Loop
//!
//! What OpenSubdiv writes once for every scheme (`opensubdiv/sdc/scheme.h`, `crease.cpp`)
//! is written once here too, and [`super::loop_sdc`] calls it: the rules, sharpness decay and
//! fractional weights, and the derivation of an edge's and a vertex's parent and child rules
//! with their crease and corner masks and the blending of the two. A scheme supplies only its
//! own smooth masks (Catmark's here, after `opensubdiv/sdc/catmarkScheme.h`; Loop's after
//! `opensubdiv/sdc/loopScheme.h`).
//!
//! # Arithmetic
//!
//! Sharpness is `f32` and everything derived from sharpness alone (child sharpness, the
//! fractional weight that blends two rules) is computed in `f32` in Sdc's order of
//! operations, so that the same sharpness decays to zero at the same level as in OpenSubdiv.
//! Mask weights and positions are `f64`, as in Bfr's `Far::PrimvarRefinerReal<double>`;
//! [`INFINITELY_SHARP`] and above is infinitely sharp and decays to exactly
//! [`INFINITELY_SHARP`].
//!
//! # What the caller prepares
//!
//! The masks take the sharpness a refinement level *stores*, which at the base level is the
//! cage's tags after Far has sharpened topology (`opensubdiv/far/topologyRefinerFactory.cpp`,
//! `prepareComponentTagsAndSharpness`): see [`base_edge_sharpness`] and
//! [`base_vertex_sharpness`]. Boundaries need no flag of their own: a boundary vertex is
//! recognised by its infinitely sharp boundary edges, exactly as in Sdc.
//!
//! # Ordering
//!
//! Catmark's refinement masks do not depend on the order of a vertex's edges or faces (the
//! smooth rule weighs them all alike and the crease rule picks its two edges by sharpness), so
//! any order will do as long as `edge_sharpness[i]` and `edge_ends[i]` describe the same
//! edge. Only the counts matter: see [`vertex_mask`].
//!
//! Cross-checked against OpenSubdiv 3.6.0's Sdc itself by the fixture
//! `crates/tessera/tests/fixtures/sdc/catmark_masks.txt` (`tools/osd-oracle/sdc_check.sh`).

use glam::DVec3;

use super::{BoundaryInterpolation, CreaseMethod, TriangleRule, INFINITELY_SHARP};

/// Sdc's name for sharpness 0; a sharpness at or below it is smooth.
const SMOOTH: f32 = 0.0;

/// Whether `s` makes an edge or vertex sharp at all (Sdc's `IsSharp`).
pub(crate) fn is_sharp(s: f32) -> bool {
    s > SMOOTH
}

/// Whether `s` is infinitely sharp (Sdc's `IsInfinite`).
fn is_infinite(s: f32) -> bool {
    s >= INFINITELY_SHARP
}

/// Whether `s` is sharp but decays (Sdc's `IsSemiSharp`).
fn is_semi_sharp(s: f32) -> bool {
    SMOOTH < s && s < INFINITELY_SHARP
}

/// Which Catmark mask a vertex's refinement uses (Sdc's `Crease::Rule`,
/// `opensubdiv/sdc/crease.h`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum VertexRule {
    /// No sharp edge and no vertex sharpness: the smooth Catmull-Clark mask.
    Smooth,
    /// Exactly one sharp edge: still the smooth mask (a crease ending in a smooth surface).
    Dart,
    /// Exactly two sharp edges: the crease mask along them.
    Crease,
    /// Three or more sharp edges, or a sharp vertex: the vertex stays where it is.
    Corner,
}

impl VertexRule {
    /// The rule of a vertex with this sharpness and this many sharp incident edges (Sdc's
    /// `DetermineVertexVertexRule` with a count, `opensubdiv/sdc/crease.cpp`). Vtr uses this
    /// form for the vertices it creates (`opensubdiv/vtr/refinement.cpp`,
    /// `reclassifySemisharpVertices`, with vertex sharpness 0 for vertices on edges).
    ///
    /// Cost: O(1).
    pub fn from_sharp_edge_count(vertex_sharpness: f32, sharp_edges: usize) -> Self {
        if is_sharp(vertex_sharpness) {
            return Self::Corner;
        }
        match sharp_edges {
            0 => Self::Smooth,
            1 => Self::Dart,
            2 => Self::Crease,
            _ => Self::Corner,
        }
    }

    /// Whether the vertex takes the smooth mask (smooth or dart).
    pub(crate) fn is_smooth(self) -> bool {
        matches!(self, Self::Smooth | Self::Dart)
    }
}

/// The rule of a vertex with sharpness `vertex_sharpness` whose incident edges have
/// `incident_edge_sharpness` (any order), as Sdc determines it
/// (`opensubdiv/sdc/crease.cpp`, `DetermineVertexVertexRule`): a sharp vertex is a corner,
/// otherwise the number of sharp (semi-sharp or infinitely sharp) edges decides, 0 smooth,
/// 1 dart, 2 crease, more corner.
///
/// Cost: O(edges).
pub fn vertex_rule(vertex_sharpness: f32, incident_edge_sharpness: &[f32]) -> VertexRule {
    let sharp = incident_edge_sharpness.iter().filter(|&&s| is_sharp(s)).count();
    VertexRule::from_sharp_edge_count(vertex_sharpness, sharp)
}

// ---------------------------------------------------------------------------------------
// Base-level sharpening (Far)
// ---------------------------------------------------------------------------------------

/// The sharpness a base-level (cage) edge refines with: its tag's sharpness (0 without a tag),
/// or infinitely sharp if it is a boundary edge (one face) or non-manifold (more than two
/// faces, or two faces that disagree on its direction). Far does this whatever the boundary
/// interpolation, even [`BoundaryInterpolation::None`]
/// (`opensubdiv/far/topologyRefinerFactory.cpp`, `prepareComponentTagsAndSharpness`).
///
/// Cost: O(1).
pub fn base_edge_sharpness(tagged: f32, boundary: bool, non_manifold: bool) -> f32 {
    if boundary || non_manifold {
        INFINITELY_SHARP
    } else {
        tagged
    }
}

/// What [`base_vertex_sharpness`] needs to know about a cage vertex's topology.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct BaseVertexTopology {
    /// Incident faces.
    pub faces: usize,
    /// Incident edges.
    pub edges: usize,
    /// Whether the vertex is non-manifold (Vtr's tag: more than one fan of faces, or
    /// non-manifold incident edges).
    pub non_manifold: bool,
    /// Incident edges that are non-manifold.
    pub non_manifold_edges: usize,
    /// Incident edges on the boundary (one face).
    pub boundary_edges: usize,
}

/// The sharpness a base-level (cage) vertex refines with: its tag's sharpness (0 without a
/// tag), made infinitely sharp by Far (`opensubdiv/far/topologyRefinerFactory.cpp`,
/// `prepareComponentTagsAndSharpness`) when
///
/// * it is a corner of the boundary (one face, two edges) and the boundary interpolation is
///   [`BoundaryInterpolation::EdgeAndCorner`], or
/// * it is non-manifold, unless it lies on an interior non-manifold crease (exactly two
///   non-manifold edges, no boundary edge, more faces than edges), which the infinitely sharp
///   non-manifold edges already make a crease.
///
/// Cost: O(1).
pub fn base_vertex_sharpness(
    tagged: f32,
    topology: BaseVertexTopology,
    boundary: BoundaryInterpolation,
) -> f32 {
    let t = topology;
    let corner = t.faces == 1 && t.edges == 2;
    if corner && boundary == BoundaryInterpolation::EdgeAndCorner {
        return INFINITELY_SHARP;
    }
    let interior_non_manifold_crease =
        t.non_manifold_edges == 2 && t.boundary_edges == 0 && t.faces > t.edges;
    if t.non_manifold && !interior_non_manifold_crease {
        return INFINITELY_SHARP;
    }
    tagged
}

// ---------------------------------------------------------------------------------------
// Child sharpness
// ---------------------------------------------------------------------------------------

/// Sharpness one level down by the uniform rule: 0 stays 0, infinitely sharp stays
/// [`INFINITELY_SHARP`] (a larger value becomes exactly it), anything else drops by one and
/// stops at 0 (Sdc's `SubdivideUniformSharpness`, `opensubdiv/sdc/crease.h`). This is also the
/// child sharpness of a *vertex* under both crease methods (`SubdivideVertexSharpness`), and
/// of an edge under [`CreaseMethod::Uniform`].
///
/// Cost: O(1).
pub fn subdivide_sharpness(sharpness: f32) -> f32 {
    if !is_sharp(sharpness) {
        SMOOTH
    } else if is_infinite(sharpness) {
        INFINITELY_SHARP
    } else if sharpness > 1.0 {
        sharpness - 1.0
    } else {
        SMOOTH
    }
}

/// The child sharpness of a vertex: [`subdivide_sharpness`] (Sdc's
/// `SubdivideVertexSharpness`, the same for both crease methods). Vertices that refinement
/// creates on edges and faces have sharpness 0.
///
/// Cost: O(1).
pub fn child_vertex_sharpness(vertex_sharpness: f32) -> f32 {
    subdivide_sharpness(vertex_sharpness)
}

/// Chaikin's view of one vertex's edges: the sum and count of the semi-sharp ones, from
/// which each edge's child sharpness follows without a buffer. Shared with the Loop rules
/// (`super::loop_sdc`), whose sharpness decays the same way.
#[derive(Clone, Copy)]
pub(crate) struct EdgesAtVertex {
    method: CreaseMethod,
    /// Incident edges.
    count: usize,
    /// Sum of the semi-sharp ones, accumulated in edge order as Sdc does.
    semi_sharp_sum: f32,
    /// How many are semi-sharp.
    semi_sharp: usize,
}

impl EdgesAtVertex {
    pub(crate) fn new(edge_sharpness: &[f32], method: CreaseMethod) -> Self {
        let mut at = Self { method, count: edge_sharpness.len(), semi_sharp_sum: 0.0, semi_sharp: 0 };
        if method == CreaseMethod::Chaikin {
            for &s in edge_sharpness.iter().filter(|&&s| is_semi_sharp(s)) {
                at.semi_sharp_sum += s;
                at.semi_sharp += 1;
            }
        }
        at
    }

    /// The child sharpness, at this vertex, of one of its edges of sharpness `s` (Sdc's
    /// `SubdivideEdgeSharpnessAtVertex`, `opensubdiv/sdc/crease.cpp`).
    pub(crate) fn child(&self, s: f32) -> f32 {
        if self.method == CreaseMethod::Uniform || self.count < 2 {
            return subdivide_sharpness(s);
        }
        if !is_sharp(s) {
            return SMOOTH;
        }
        if is_infinite(s) {
            return INFINITELY_SHARP;
        }
        let mut s = s;
        if self.semi_sharp > 1 {
            // Chaikin: three quarters of the edge's own sharpness, one quarter the average of
            // the other semi-sharp edges at this end.
            let others = (self.semi_sharp_sum - s) / (self.semi_sharp - 1) as f32;
            s = 0.75 * s + 0.25 * others;
        }
        s -= 1.0;
        if is_sharp(s) {
            s
        } else {
            SMOOTH
        }
    }
}

/// The sharpness of the child edge that a parent edge of sharpness `edge_sharpness` gives at
/// one of its ends, whose incident edges (the parent edge among them, any order) have
/// `edges_at_vertex` (Sdc's `SubdivideEdgeSharpnessAtVertex`, `opensubdiv/sdc/crease.cpp`, as
/// `opensubdiv/vtr/refinement.cpp` calls it for each child edge):
///
/// * [`CreaseMethod::Uniform`], or fewer than two edges at the vertex:
///   [`subdivide_sharpness`], the same at both ends;
/// * [`CreaseMethod::Chaikin`]: 0 and infinite stay; a semi-sharp edge becomes
///   ¾·s + ¼·(average of the *other* semi-sharp edges at this end) − 1, or just s − 1 if it is
///   the only semi-sharp one there, and stops at 0. The two child edges of one parent edge
///   can thus differ.
///
/// Cost: O(edges at the vertex).
pub fn child_edge_sharpness(edge_sharpness: f32, edges_at_vertex: &[f32], method: CreaseMethod) -> f32 {
    EdgesAtVertex::new(edges_at_vertex, method).child(edge_sharpness)
}

/// The child sharpness of every edge at one vertex: `child[i]` is
/// [`child_edge_sharpness`]`(parent[i], parent, method)`, the sharpness of the child edge of
/// edge `i` incident to the vertex's child (Sdc's `SubdivideEdgeSharpnessesAroundVertex`).
/// Infinitely sharp edges give exactly [`INFINITELY_SHARP`], as the child level stores them.
///
/// # Panics
///
/// If `child` is shorter than `parent`.
///
/// Cost: O(edges).
pub fn child_edge_sharpnesses_around_vertex(parent: &[f32], method: CreaseMethod, child: &mut [f32]) {
    let at = EdgesAtVertex::new(parent, method);
    for (c, &p) in child[..parent.len()].iter_mut().zip(parent) {
        *c = at.child(p);
    }
}

/// The weight of the parent rule's mask when a vertex's rule changes from the parent to its
/// child, i.e. when some sharpness decays to zero during this level (Sdc's
/// `ComputeFractionalWeightAtVertex`, `opensubdiv/sdc/crease.cpp`): the average of the
/// sharpness values that decay — the vertex's if it goes from sharp to smooth, and each
/// edge's that does (uniform: every sharp edge with sharpness ≤ 1; Chaikin: every sharp
/// edge whose child in `child_edges` is smooth) — clamped to 1; 0 when nothing decays.
/// The child rule's mask gets 1 − this weight.
///
/// `parent_edges[i]` and `child_edges[i]` are edge `i`'s sharpness and its child's at this
/// vertex ([`child_edge_sharpnesses_around_vertex`]); `child_edges` is only read for Chaikin.
///
/// Cost: O(edges), in `f32`.
pub fn fractional_weight_at_vertex(
    parent_vertex: f32,
    child_vertex: f32,
    parent_edges: &[f32],
    child_edges: &[f32],
    method: CreaseMethod,
) -> f32 {
    fractional_weight(parent_vertex, child_vertex, parent_edges, |i| child_edges[i], method)
}

/// [`fractional_weight_at_vertex`] with the child edges' sharpness computed on demand.
pub(crate) fn fractional_weight(
    parent_vertex: f32,
    child_vertex: f32,
    parent_edges: &[f32],
    child_edge: impl Fn(usize) -> f32,
    method: CreaseMethod,
) -> f32 {
    let mut count = 0usize;
    let mut sum = 0.0f32;
    if is_sharp(parent_vertex) && !is_sharp(child_vertex) {
        count = 1;
        sum = parent_vertex;
    }
    for (i, &p) in parent_edges.iter().enumerate() {
        let decays = match method {
            CreaseMethod::Uniform => is_sharp(p) && p <= 1.0,
            CreaseMethod::Chaikin => is_sharp(p) && !is_sharp(child_edge(i)),
        };
        if decays {
            sum += p;
            count += 1;
        }
    }
    if count == 0 {
        return 0.0;
    }
    (sum / count as f32).min(1.0)
}

// ---------------------------------------------------------------------------------------
// Face points
// ---------------------------------------------------------------------------------------

/// The weight of each corner in a face's face point: 1/`corners` (Sdc's
/// `ComputeFaceVertexMask`, `opensubdiv/sdc/scheme.h`).
///
/// Cost: O(1).
pub fn face_mask_weight(corners: usize) -> f64 {
    1.0 / corners as f64
}

/// A face's face point, the centroid of its corners (any number ≥ 1, in any order), summed
/// in corner order as Vtr does.
///
/// Cost: O(corners).
pub fn face_point(corners: &[DVec3]) -> DVec3 {
    let w = face_mask_weight(corners.len());
    corners.iter().fold(DVec3::ZERO, |acc, &p| acc + p * w)
}

// ---------------------------------------------------------------------------------------
// Edge points
// ---------------------------------------------------------------------------------------

/// The weight of Catmark's smooth-triangle rule for a triangle beside an edge
/// (`opensubdiv/sdc/catmarkScheme.h`, used with [`TriangleRule::Smooth`]).
const SMOOTH_TRIANGLE_EDGE_WEIGHT: f64 = 0.470;

/// An edge point's mask: the same weight for both of the edge's ends and the same weight for
/// each face beside it, applied to its face point (Catmark's edge masks have no other shape;
/// Loop's, [`super::loop_sdc::edge_mask`], apply it to each triangle's vertex opposite the
/// edge). The
/// weights sum to 1; with [`CreaseMethod::Chaikin`] they may leave [0, 1] (see
/// [`edge_mask`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EdgeMask {
    /// Weight of each end vertex.
    pub vertex: f64,
    /// Weight of each incident face's face point; 0 for the crease rule.
    pub face: f64,
    /// Incident faces the mask was made for.
    pub faces: usize,
}

impl EdgeMask {
    /// The edge point: `ends` are the edge's two vertices, `face_points` the face points of
    /// its faces (as many as the mask was made for, any order), summed as Vtr does (ends
    /// first).
    ///
    /// Cost: O(faces).
    pub fn apply(&self, ends: [DVec3; 2], face_points: &[DVec3]) -> DVec3 {
        debug_assert_eq!(face_points.len(), self.faces, "one face point per face of the edge");
        let mut p = ends[0] * self.vertex + ends[1] * self.vertex;
        if self.face != 0.0 {
            for &f in face_points {
                p += f * self.face;
            }
        }
        p
    }
}

/// The rule of the vertex that refinement puts on an edge of sharpness `sharpness` whose two
/// child edges get `child_sharpness` ([`child_edge_sharpness`] at either end), as Vtr tags it
/// (`opensubdiv/vtr/refinement.cpp`, `populateVertexTagsFromParentEdges` and
/// `reclassifySemisharpVertices`): smooth for a smooth edge, crease for an infinitely sharp
/// one, and for a semi-sharp one the rule of a vertex with as many sharp edges as child edges
/// stay sharp (none smooth, one dart, two crease).
///
/// In a sparse (adaptive) refinement a child vertex with only one of its two child edges
/// present is a crease if that edge is sharp and smooth otherwise; pass that rule to
/// [`edge_mask`] yourself.
///
/// Cost: O(1).
pub fn edge_child_rule(sharpness: f32, child_sharpness: [f32; 2]) -> VertexRule {
    if is_infinite(sharpness) {
        VertexRule::Crease
    } else if is_sharp(sharpness) {
        let sharp = child_sharpness.iter().filter(|&&s| is_sharp(s)).count();
        VertexRule::from_sharp_edge_count(SMOOTH, sharp)
    } else {
        VertexRule::Smooth
    }
}

/// The mask of the edge point of an edge with sharpness `sharpness` (as stored at this
/// level), whose faces have `face_sizes` corners (one entry per incident face, any order:
/// two for a manifold interior edge; one or more than two only for boundary and non-manifold
/// edges, which Far makes infinitely sharp), whose child vertex has rule `child_rule`
/// ([`edge_child_rule`]). This is Sdc's `ComputeEdgeVertexMask` (`opensubdiv/sdc/scheme.h`,
/// `opensubdiv/sdc/catmarkScheme.h`) with the rules Vtr gives it
/// (`opensubdiv/far/primvarRefiner.h`):
///
/// * smooth edge (sharpness 0): ¼ each end, ¼ each of two face points (½/faces for another
///   face count). With [`TriangleRule::Smooth`] and two faces of which one or both are
///   triangles, a triangle's side weighs 0.47 instead of ¼: both faces get the average
///   `f` of the two sides' weights and both ends ½·(1 − 2f);
/// * sharp edge whose child vertex is a crease: the midpoint, ½ each end;
/// * sharp edge whose child vertex is not (the sharpness decays to 0 on a child edge this
///   level): the smooth mask blended with the midpoint by the edge's sharpness `s`,
///   `s`·crease + (1 − `s`)·smooth. Vtr does not clamp `s` here: with Chaikin a sharpness
///   in [1, 4/3) can decay to 0 on a child edge, and the weights then leave [0, 1] exactly
///   as in OpenSubdiv.
///
/// Cost: O(faces).
pub fn edge_mask(
    sharpness: f32,
    child_rule: VertexRule,
    face_sizes: &[usize],
    triangles: TriangleRule,
) -> EdgeMask {
    edge_mask_with(sharpness, child_rule, smooth_edge_mask(face_sizes, triangles))
}

/// Sdc's `ComputeEdgeVertexMask` (`opensubdiv/sdc/scheme.h`), which every scheme shares, for
/// a scheme whose smooth edge mask is `smooth` (Sdc's `assignSmoothMaskForEdge`); the rules
/// are [`edge_mask`]'s (Catmark's, which calls it, as does [`super::loop_sdc::edge_mask`],
/// whose `face` weights are its triangles' opposite vertices).
///
/// Cost: O(1).
pub(crate) fn edge_mask_with(sharpness: f32, child_rule: VertexRule, smooth: EdgeMask) -> EdgeMask {
    if !is_sharp(sharpness) {
        return smooth;
    }
    if child_rule == VertexRule::Crease {
        return EdgeMask { vertex: 0.5, face: 0.0, faces: smooth.faces };
    }
    let parent = f64::from(sharpness);
    let child = 1.0 - parent;
    EdgeMask { vertex: parent * 0.5 + child * smooth.vertex, face: smooth.face * child, faces: smooth.faces }
}

/// Catmark's smooth edge mask (`opensubdiv/sdc/catmarkScheme.h`, `assignSmoothMaskForEdge`).
fn smooth_edge_mask(face_sizes: &[usize], triangles: TriangleRule) -> EdgeMask {
    let faces = face_sizes.len();
    let side = |size: usize| if size == 3 { SMOOTH_TRIANGLE_EDGE_WEIGHT } else { 0.25 };
    match face_sizes {
        &[a, b] if triangles == TriangleRule::Smooth && (a == 3 || b == 3) => {
            let face = 0.5 * (side(a) + side(b));
            EdgeMask { vertex: 0.5 * (1.0 - 2.0 * face), face, faces }
        }
        [_, _] => EdgeMask { vertex: 0.25, face: 0.25, faces },
        _ => EdgeMask { vertex: 0.25, face: 0.5 / faces as f64, faces },
    }
}

/// The neighbourhood of an edge, for [`edge_point`].
#[derive(Debug, Clone, Copy)]
pub struct EdgeNeighborhood<'a> {
    /// The edge's two vertices.
    pub ends: [DVec3; 2],
    /// Its sharpness at this level.
    pub sharpness: f32,
    /// The sharpness of its two child edges ([`child_edge_sharpness`] at either end).
    pub child_sharpness: [f32; 2],
    /// The face points of its faces, one per face, any order.
    pub face_points: &'a [DVec3],
    /// The corner counts of the same faces, in the same order.
    pub face_sizes: &'a [usize],
}

/// The edge point of an edge: [`edge_mask`] with the child rule from [`edge_child_rule`],
/// applied to the neighbourhood.
///
/// Cost: O(faces).
pub fn edge_point(edge: &EdgeNeighborhood<'_>, triangles: TriangleRule) -> DVec3 {
    let rule = edge_child_rule(edge.sharpness, edge.child_sharpness);
    edge_mask(edge.sharpness, rule, edge.face_sizes, triangles).apply(edge.ends, edge.face_points)
}

// ---------------------------------------------------------------------------------------
// Vertex points
// ---------------------------------------------------------------------------------------

/// A vertex point's mask, in the shape Catmark's vertex masks always have: a weight for the
/// vertex, one common weight for the far ends of its incident edges except possibly two
/// crease edges that weigh differently, and one common weight for the face points of its
/// incident faces. Weights refer to the order of the `edge_sharpness` given to
/// [`vertex_mask`]; they sum to 1.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VertexMask {
    /// Weight of the vertex itself.
    pub vertex: f64,
    /// Weight of the far end of every incident edge that is not one of [`Self::crease`].
    pub edge: f64,
    /// The two crease edges (indices into the incident edges, distinct) and the weight of
    /// each one's far end, when a crease rule takes part.
    pub crease: Option<([usize; 2], f64)>,
    /// Weight of every incident face's face point (0 unless a smooth rule takes part).
    pub face: f64,
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
    /// order given to [`vertex_mask`]), `face_points` the face points of its incident faces
    /// (any order). Summed as Vtr does, smallest weights first: faces, edges, the vertex.
    ///
    /// Cost: O(edges + faces).
    pub fn apply(&self, v: DVec3, edge_ends: &[DVec3], face_points: &[DVec3]) -> DVec3 {
        let mut p = DVec3::ZERO;
        if self.face != 0.0 {
            for &f in face_points {
                p += f * self.face;
            }
        }
        for (i, &e) in edge_ends.iter().enumerate() {
            p += e * self.edge_weight(i);
        }
        p + v * self.vertex
    }
}

/// Two crease edges (indices into a vertex's incident edges) and the weight of each.
type CreasePair = ([usize; 2], f64);

/// The two edges of a crease at a vertex of `valence` edges whose sharp edges are `sharp(i)`:
/// the first and the last sharp edge in the given order, as Sdc's `GetSharpEdgePairOfCrease`
/// (`opensubdiv/sdc/crease.h`) finds them (a crease has exactly two). `None` without a sharp
/// edge. Shared with the Loop rules, whose crease tangents depend on which end comes first.
///
/// Cost: O(edges).
pub(crate) fn sharp_edge_pair_of_crease(valence: usize, sharp: impl Fn(usize) -> bool) -> Option<[usize; 2]> {
    let first = (0..valence).find(|&i| sharp(i))?;
    let last = (0..valence).rev().find(|&i| sharp(i))?;
    Some([first, last])
}

/// A scheme's smooth vertex mask at one valence (Sdc's `assignSmoothMaskForVertex`), the only
/// part of a vertex mask that differs between Catmark and Loop: their crease and corner masks
/// and the derivation and blending of rules are the same ([`vertex_mask_with`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct SmoothVertexMask {
    /// Weight of the vertex itself.
    pub(crate) vertex: f64,
    /// Weight of the far end of each incident edge.
    pub(crate) edge: f64,
    /// Weight of each incident face's face point; `None` for a scheme whose vertex masks weigh
    /// no faces (Loop), which blends differently from a weight of 0.
    pub(crate) face: Option<f64>,
}

/// One rule's mask before blending; `None` edges or faces mean the mask has no such weights
/// (Sdc's sparse masks, which blend differently from weights of 0).
#[derive(Clone, Copy)]
struct RuleMask {
    vertex: f64,
    edges: Option<(f64, Option<CreasePair>)>,
    face: Option<f64>,
}

impl RuleMask {
    /// The mask for `rule` at a vertex of `valence` edges whose sharp edges are `sharp(i)`:
    /// the scheme's `smooth` mask, or the crease and corner masks that Catmark and Loop
    /// specialise alike (`opensubdiv/sdc/catmarkScheme.h`, `opensubdiv/sdc/loopScheme.h`,
    /// `assignCreaseMaskForVertex`; `opensubdiv/sdc/scheme.h`, `assignCornerMaskForVertex`).
    fn new(
        rule: VertexRule,
        valence: usize,
        sharp: impl Fn(usize) -> bool,
        smooth: &impl Fn(usize) -> SmoothVertexMask,
    ) -> Self {
        match rule {
            VertexRule::Smooth | VertexRule::Dart => {
                let m = smooth(valence);
                Self { vertex: m.vertex, edges: Some((m.edge, None)), face: m.face }
            }
            VertexRule::Crease => {
                let ends = sharp_edge_pair_of_crease(valence, sharp).unwrap_or([0, 0]);
                Self { vertex: 0.75, edges: Some((0.0, Some((ends, 0.125)))), face: None }
            }
            VertexRule::Corner => Self { vertex: 1.0, edges: None, face: None },
        }
    }

    /// The weight of edge `i`.
    fn edge(&self, i: usize) -> f64 {
        match self.edges {
            Some((_, Some((ends, w)))) if ends.contains(&i) => w,
            Some((w, _)) => w,
            None => 0.0,
        }
    }
}

/// Sdc's `ComputeVertexVertexMask` (`opensubdiv/sdc/scheme.h`), which every scheme shares, for
/// a scheme whose smooth mask at valence n is `smooth(n)`; the arguments and the rules are
/// [`vertex_mask`]'s (Catmark's, which calls it, as does [`super::loop_sdc::vertex_mask`]). A
/// scheme without face weights gets `face` 0.
///
/// # Panics
///
/// In debug builds, if a smooth rule meets `faces != edge_sharpness.len()`.
///
/// Cost: O(edges), no allocation, and `smooth` at most twice.
pub(crate) fn vertex_mask_with(
    vertex_sharpness: f32,
    edge_sharpness: &[f32],
    faces: usize,
    crease: CreaseMethod,
    smooth: impl Fn(usize) -> SmoothVertexMask,
) -> VertexMask {
    let n = edge_sharpness.len();
    let rule = vertex_rule(vertex_sharpness, edge_sharpness);
    // Neither scheme has a smooth rule for a boundary or non-manifold vertex (Sdc sizes the
    // smooth masks by the face count), and Far's sharpening never leaves one smooth.
    let smooth_ok = |r: VertexRule| {
        debug_assert!(
            !r.is_smooth() || faces == n,
            "the smooth rule needs as many faces as edges ({n} edges, {faces} faces)"
        );
    };
    let parent = RuleMask::new(rule, n, |i| is_sharp(edge_sharpness[i]), &smooth);
    let finish = |m: RuleMask, child_rule: VertexRule, parent_weight: f64| {
        let (edge, crease) = m.edges.unwrap_or((0.0, None));
        VertexMask {
            vertex: m.vertex,
            edge,
            crease,
            face: m.face.unwrap_or(0.0),
            rule,
            child_rule,
            parent_weight,
        }
    };
    let at = EdgesAtVertex::new(edge_sharpness, crease);
    let child_edge = |i: usize| at.child(edge_sharpness[i]);
    let child_vertex = child_vertex_sharpness(vertex_sharpness);
    let child_sharp = (0..n).filter(|&i| is_sharp(child_edge(i))).count();
    let child_rule = VertexRule::from_sharp_edge_count(child_vertex, child_sharp);
    // A smooth or dart parent keeps its mask whatever its child becomes (a dart's edge may
    // decay): Sdc returns before looking at the child.
    if rule.is_smooth() {
        smooth_ok(rule);
        return finish(parent, child_rule, 1.0);
    }
    if child_rule == rule {
        return finish(parent, child_rule, 1.0);
    }
    smooth_ok(child_rule);
    let child = RuleMask::new(child_rule, n, |i| is_sharp(child_edge(i)), &smooth);

    let pw = f64::from(fractional_weight(vertex_sharpness, child_vertex, edge_sharpness, child_edge, crease));
    let cw = 1.0 - pw;
    // Sdc blends weight by weight, and a kind of weight the parent mask lacks (a corner's
    // edges, a crease's faces) becomes the child's weight scaled by 1 − w. A blend always
    // has a child with edge weights (a vertex never gains sharp edges), and at most one crease
    // pair takes part: the parent's (a crease decaying to smooth) or the child's (a corner
    // decaying to a crease).
    let blend = |parent_has: bool, p: f64, c: f64| if parent_has { pw * p + cw * c } else { cw * c };
    let has_edges = parent.edges.is_some();
    let pair_of = |m: &RuleMask| m.edges.and_then(|(_, pair)| pair).map(|(ends, _)| ends);
    let crease_pair = pair_of(&child).or(pair_of(&parent));
    // The weight of an edge outside any pair, read from both masks at such an index.
    let generic = |m: &RuleMask| m.edges.map_or(0.0, |(w, _)| w);
    let mask = RuleMask {
        vertex: pw * parent.vertex + cw * child.vertex,
        edges: Some((
            blend(has_edges, generic(&parent), generic(&child)),
            crease_pair.map(|ends| (ends, blend(has_edges, parent.edge(ends[0]), child.edge(ends[0])))),
        )),
        face: child.face.map(|c| blend(parent.face.is_some(), parent.face.unwrap_or(0.0), c)),
    };
    finish(mask, child_rule, pw)
}

/// Catmark's smooth vertex mask (`opensubdiv/sdc/catmarkScheme.h`,
/// `assignSmoothMaskForVertex`): (n − 2)/n the vertex, 1/n² each edge end and each face point.
fn smooth_vertex_mask(valence: usize) -> SmoothVertexMask {
    let n = valence as f64;
    let w = 1.0 / (n * n);
    SmoothVertexMask { vertex: (n - 2.0) / n, edge: w, face: Some(w) }
}

/// The mask of the vertex point of a vertex with sharpness `vertex_sharpness` whose incident
/// edges have `edge_sharpness` (values stored at this level, see the module documentation),
/// with `faces` incident faces. This is Sdc's `ComputeVertexVertexMask`
/// (`opensubdiv/sdc/scheme.h`, `opensubdiv/sdc/catmarkScheme.h`), which derives the parent and
/// child rules as Vtr's tags do:
///
/// * the parent rule is [`vertex_rule`]; the child rule is the rule of the child vertex, with
///   [`child_vertex_sharpness`] and [`child_edge_sharpnesses_around_vertex`] by `crease`;
/// * smooth and dart: (n − 2)/n the vertex, 1/n² each edge end and each face point, n the
///   valence (requires `faces == edge_sharpness.len()`: Catmark has no smooth rule for a
///   boundary or non-manifold vertex, which Far's sharpening never leaves smooth);
/// * crease: ¾ the vertex, ⅛ the far end of each of the two sharp edges;
/// * corner: the vertex;
/// * where parent and child rules differ, w·parent + (1 − w)·child with w from
///   [`fractional_weight_at_vertex`] (a smooth or dart parent always keeps its mask).
///
/// Counts: for an interior manifold vertex `faces` equals the number of edges; for a manifold
/// boundary vertex it is one less (the first and last edge of its fan are boundary edges,
/// infinitely sharp); for a non-manifold vertex any count (its mask never weighs faces).
/// The order of `edge_sharpness` is the order of [`VertexMask::edge_weight`].
///
/// # Panics
///
/// In debug builds, if a smooth rule meets `faces != edge_sharpness.len()`.
///
/// Cost: O(edges), no allocation.
pub fn vertex_mask(
    vertex_sharpness: f32,
    edge_sharpness: &[f32],
    faces: usize,
    crease: CreaseMethod,
) -> VertexMask {
    vertex_mask_with(vertex_sharpness, edge_sharpness, faces, crease, smooth_vertex_mask)
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
    /// The face points of its incident faces, any order (count: see [`vertex_mask`]).
    pub face_points: &'a [DVec3],
}

/// The vertex point of a vertex: [`vertex_mask`] applied to the neighbourhood.
///
/// Cost: O(edges + faces), no allocation.
pub fn vertex_point(vertex: &VertexNeighborhood<'_>, crease: CreaseMethod) -> DVec3 {
    debug_assert_eq!(vertex.edge_ends.len(), vertex.edge_sharpness.len());
    vertex_mask(vertex.sharpness, vertex.edge_sharpness, vertex.face_points.len(), crease).apply(
        vertex.position,
        vertex.edge_ends,
        vertex.face_points,
    )
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;

    const INF: f32 = INFINITELY_SHARP;

    fn close(a: DVec3, b: DVec3) -> bool {
        (a - b).length() < 1e-12
    }

    /// Points around a vertex at the origin: far ends of `n` edges and `faces` face points,
    /// not in a plane so that every weight shows.
    fn ring(n: usize, faces: usize) -> (Vec<DVec3>, Vec<DVec3>) {
        let at = |k: usize, r: f64, z: f64| {
            let a = k as f64 * std::f64::consts::TAU / n as f64 + 0.3;
            DVec3::new(r * a.cos(), r * a.sin(), z + 0.1 * k as f64)
        };
        ((0..n).map(|k| at(k, 1.0, 0.2)).collect(), (0..faces).map(|k| at(k, 1.3, -0.4)).collect())
    }

    fn point(v: DVec3, ends: &[DVec3], faces: &[DVec3], vs: f32, es: &[f32], method: CreaseMethod) -> DVec3 {
        vertex_point(
            &VertexNeighborhood {
                position: v,
                sharpness: vs,
                edge_ends: ends,
                edge_sharpness: es,
                face_points: faces,
            },
            method,
        )
    }

    #[test]
    fn smooth_vertex_is_the_classic_catmull_clark_point() {
        for n in 3..=8 {
            let (ends, faces) = ring(n, n);
            let v = DVec3::new(0.1, -0.2, 0.5);
            let nf = n as f64;
            // Catmull and Clark: (Q + 2R + (n − 3)v)/n, Q the average face point, R the average
            // edge midpoint.
            let q = faces.iter().sum::<DVec3>() / nf;
            let r = ends.iter().map(|&e| (v + e) * 0.5).sum::<DVec3>() / nf;
            let classic = (q + 2.0 * r + (nf - 3.0) * v) / nf;
            let got = point(v, &ends, &faces, 0.0, &vec![0.0; n], CreaseMethod::Uniform);
            assert!(close(got, classic), "valence {n}: {got} vs {classic}");
            // A dart (one sharp edge) is still smooth.
            let mut es = vec![0.0; n];
            es[1] = 3.0;
            assert!(close(point(v, &ends, &faces, 0.0, &es, CreaseMethod::Uniform), classic));
            let m = vertex_mask(0.0, &es, n, CreaseMethod::Uniform);
            assert_eq!((m.rule, m.child_rule), (VertexRule::Dart, VertexRule::Dart));
        }
    }

    #[test]
    fn boundary_and_corner_vertices() {
        let (ends, faces) = ring(4, 3);
        let v = DVec3::new(0.0, 0.0, 1.0);
        let es = [INF, 0.0, 0.0, INF];
        let got = point(v, &ends, &faces, 0.0, &es, CreaseMethod::Uniform);
        assert!(close(got, (v * 6.0 + ends[0] + ends[3]) / 8.0));
        assert_eq!(vertex_mask(0.0, &es, 3, CreaseMethod::Uniform).rule, VertexRule::Crease);
        // Corner by vertex sharpness, and by three sharp edges.
        assert_eq!(point(v, &ends, &faces, INF, &es, CreaseMethod::Uniform), v);
        assert_eq!(point(v, &ends, &faces, 0.0, &[INF, 2.0, 0.0, INF], CreaseMethod::Chaikin), v);
        let (ends, faces) = ring(2, 1);
        assert_eq!(point(v, &ends, &faces, INF, &[INF, INF], CreaseMethod::Uniform), v);
        // A boundary corner left smooth by EdgeOnly is still a crease of its two edges.
        assert!(close(
            point(v, &ends, &faces, 0.0, &[INF, INF], CreaseMethod::Uniform),
            (v * 6.0 + ends[0] + ends[1]) / 8.0
        ));
    }

    #[test]
    fn vertex_rules() {
        assert_eq!(vertex_rule(0.0, &[0.0, 0.0, 0.0]), VertexRule::Smooth);
        assert_eq!(vertex_rule(0.0, &[0.0, 0.1, 0.0]), VertexRule::Dart);
        assert_eq!(vertex_rule(0.0, &[INF, 0.1, 0.0]), VertexRule::Crease);
        assert_eq!(vertex_rule(0.0, &[INF, 0.1, 0.3]), VertexRule::Corner);
        assert_eq!(vertex_rule(0.01, &[0.0, 0.0, 0.0]), VertexRule::Corner);
    }

    #[test]
    fn half_sharpness_blends_half_way() {
        let n = 5;
        let (ends, faces) = ring(n, n);
        let v = DVec3::new(0.3, 0.1, 0.7);
        let smooth = point(v, &ends, &faces, 0.0, &[0.0; 5], CreaseMethod::Uniform);
        // A vertex of sharpness 0.5: half corner, half smooth.
        for method in [CreaseMethod::Uniform, CreaseMethod::Chaikin] {
            let got = point(v, &ends, &faces, 0.5, &[0.0; 5], method);
            assert!(close(got, (v + smooth) * 0.5), "{method:?}");
        }
        // A crease of two 0.5 edges: half crease, half smooth.
        let es = [0.5, 0.0, 0.5, 0.0, 0.0];
        let crease = (v * 6.0 + ends[0] + ends[2]) / 8.0;
        for method in [CreaseMethod::Uniform, CreaseMethod::Chaikin] {
            let got = point(v, &ends, &faces, 0.0, &es, method);
            assert!(close(got, (crease + smooth) * 0.5), "{method:?}");
            let m = vertex_mask(0.0, &es, n, method);
            assert_eq!(
                (m.rule, m.child_rule, m.parent_weight),
                (VertexRule::Crease, VertexRule::Smooth, 0.5)
            );
        }
        // An edge of sharpness 0.5: half midpoint, half smooth edge point.
        let (a, b) = (DVec3::ZERO, DVec3::new(1.0, 0.0, 0.2));
        let fps = [DVec3::new(0.5, 1.0, 0.0), DVec3::new(0.5, -1.0, 0.3)];
        let edge = |s: f32| {
            let c = subdivide_sharpness(s);
            edge_point(
                &EdgeNeighborhood {
                    ends: [a, b],
                    sharpness: s,
                    child_sharpness: [c, c],
                    face_points: &fps,
                    face_sizes: &[4, 4],
                },
                TriangleRule::Catmark,
            )
        };
        let smooth_edge = (a + b + fps[0] + fps[1]) / 4.0;
        assert!(close(edge(0.0), smooth_edge));
        assert!(close(edge(0.5), ((a + b) * 0.5 + smooth_edge) * 0.5));
        assert!(close(edge(1.0), (a + b) * 0.5));
        assert!(close(edge(2.8), (a + b) * 0.5));
    }

    #[test]
    fn edge_masks_with_triangles() {
        let smooth = |sizes: &[usize]| edge_mask(0.0, VertexRule::Smooth, sizes, TriangleRule::Smooth);
        assert_eq!(smooth(&[4, 4]), EdgeMask { vertex: 0.25, face: 0.25, faces: 2 });
        let m = smooth(&[3, 4]);
        assert!((m.face - 0.36).abs() < 1e-15 && (m.vertex - 0.14).abs() < 1e-15);
        assert_eq!(smooth(&[4, 3]), m);
        let m = smooth(&[3, 3]);
        assert!((m.face - 0.47).abs() < 1e-15 && (m.vertex - 0.03).abs() < 1e-15);
        // Catmark's own rule ignores triangles.
        assert_eq!(edge_mask(0.0, VertexRule::Smooth, &[3, 3], TriangleRule::Catmark).vertex, 0.25);
        // A lone face or a non-manifold fan share ½ among the faces.
        assert_eq!(smooth(&[4]).face, 0.5);
        assert_eq!(smooth(&[3, 4, 3]).face, 0.5 / 3.0);
        assert_eq!(face_point(&[DVec3::X, DVec3::Y, DVec3::Z]), DVec3::splat(1.0 / 3.0));
    }

    #[test]
    fn chaikin_and_uniform_child_sharpness() {
        let at = [2.0, 1.0, 3.0, 0.0];
        let mut child = [0.0; 4];
        child_edge_sharpnesses_around_vertex(&at, CreaseMethod::Uniform, &mut child);
        assert_eq!(child, [1.0, 0.0, 2.0, 0.0]);
        child_edge_sharpnesses_around_vertex(&at, CreaseMethod::Chaikin, &mut child);
        // 2: ¾·2 + ¼·avg(1, 3) − 1; 1: ¾ + ¼·2.5 − 1; 3: ¾·3 + ¼·1.5 − 1.
        assert_eq!(child, [1.0, 0.375, 1.625, 0.0]);
        for (i, &s) in at.iter().enumerate() {
            assert_eq!(child_edge_sharpness(s, &at, CreaseMethod::Chaikin), child[i]);
        }
        // Two semi-sharp edges pull towards each other: 2 next to 0.5 keeps only 0.625 where
        // uniform decay would keep 1.
        let at = [2.0, 0.0, 0.5];
        child_edge_sharpnesses_around_vertex(&at, CreaseMethod::Chaikin, &mut child);
        assert_eq!(child[..3], [0.625, 0.0, 0.0]);
        // A single semi-sharp edge (infinite ones do not count) just decrements.
        assert_eq!(child_edge_sharpness(2.5, &[2.5, INF, 0.0], CreaseMethod::Chaikin), 1.5);
        // The two ends of one edge can disagree.
        let ends = [
            child_edge_sharpness(1.2, &[1.2, 0.2], CreaseMethod::Chaikin),
            child_edge_sharpness(1.2, &[1.2, 2.8], CreaseMethod::Chaikin),
        ];
        assert_eq!(ends[0], 0.0);
        assert!(ends[1] > 0.0);
        assert_eq!(edge_child_rule(1.2, ends), VertexRule::Dart);
    }

    /// Chaikin decaying an edge of sharpness 1.2 to 0 at one end only: OpenSubdiv's own
    /// refinement (Far::TopologyRefiner + PrimvarRefinerReal<double>, 4×3 grid of quads, the
    /// edge between grid vertices (1,1) and (2,1), sharpness 0.2 on the edge before it and 2.8
    /// on the edge after it) puts its edge point at z = 0.23499999642372127, the
    /// unclamped blend 1.2·crease − 0.2·smooth, not on the crease (0.25).
    #[test]
    fn chaikin_edge_blend_matches_far_refinement() {
        let p = |i: f64, j: f64| DVec3::new(i, j, 0.1 * i * i + 0.3 * j * j - 0.2 * i * j);
        let method = CreaseMethod::Chaikin;
        let child_sharpness = [
            child_edge_sharpness(1.2, &[1.2, 0.2, 0.0, 0.0], method),
            child_edge_sharpness(1.2, &[1.2, 2.8, 0.0, 0.0], method),
        ];
        let faces = [
            face_point(&[p(1.0, 0.0), p(2.0, 0.0), p(2.0, 1.0), p(1.0, 1.0)]),
            face_point(&[p(1.0, 1.0), p(2.0, 1.0), p(2.0, 2.0), p(1.0, 2.0)]),
        ];
        let hood = EdgeNeighborhood {
            ends: [p(1.0, 1.0), p(2.0, 1.0)],
            sharpness: 1.2,
            child_sharpness,
            face_points: &faces,
            face_sizes: &[4, 4],
        };
        let got = edge_point(&hood, TriangleRule::Catmark);
        assert!((got - DVec3::new(1.5, 1.0, 0.23499999642372127)).length() < 1e-15, "{got}");
    }

    #[test]
    fn infinitely_sharp_stays_infinite() {
        for s in [INF, 12.5, 1e6] {
            assert_eq!(subdivide_sharpness(s), INF);
            assert_eq!(child_vertex_sharpness(s), INF);
            for method in [CreaseMethod::Uniform, CreaseMethod::Chaikin] {
                assert_eq!(child_edge_sharpness(s, &[s, 0.7, 2.0, 0.0], method), INF);
            }
        }
        assert_eq!(subdivide_sharpness(9.99), 9.99 - 1.0);
        assert_eq!(subdivide_sharpness(0.0), 0.0);
        assert_eq!(subdivide_sharpness(1.0), 0.0);
        assert_eq!(edge_child_rule(INF, [INF, INF]), VertexRule::Crease);
        assert_eq!(edge_mask(INF, VertexRule::Crease, &[4, 4], TriangleRule::Catmark).vertex, 0.5);
    }

    #[test]
    fn base_level_sharpening() {
        assert_eq!(base_edge_sharpness(0.3, false, false), 0.3);
        assert_eq!(base_edge_sharpness(0.3, true, false), INF);
        assert_eq!(base_edge_sharpness(0.0, false, true), INF);
        let corner = BaseVertexTopology { faces: 1, edges: 2, boundary_edges: 2, ..Default::default() };
        assert_eq!(base_vertex_sharpness(0.0, corner, BoundaryInterpolation::EdgeOnly), 0.0);
        assert_eq!(base_vertex_sharpness(0.0, corner, BoundaryInterpolation::EdgeAndCorner), INF);
        let fin = BaseVertexTopology {
            faces: 5,
            edges: 4,
            non_manifold: true,
            non_manifold_edges: 2,
            boundary_edges: 0,
        };
        assert_eq!(base_vertex_sharpness(0.2, fin, BoundaryInterpolation::EdgeOnly), 0.2);
        let bowtie = BaseVertexTopology {
            faces: 2,
            edges: 4,
            non_manifold: true,
            non_manifold_edges: 0,
            boundary_edges: 4,
        };
        assert_eq!(base_vertex_sharpness(0.0, bowtie, BoundaryInterpolation::EdgeOnly), INF);
    }

    // ---- OpenSubdiv's own masks -----------------------------------------------------

    /// `tools/osd-oracle/sdc_check.cpp`'s output (see its header for the line format).
    const FIXTURE: &str = include_str!("../../tests/fixtures/sdc/catmark_masks.txt");

    /// The fixture's tolerance for weights: f32 rounding of sharpness-derived weights, though
    /// in practice the agreement is exact.
    const WEIGHT_TOLERANCE: f64 = 1e-6;

    /// A fixture line's words, read in order (the Loop fixture's lines use the same words).
    pub(crate) struct Tokens<'a>(pub(crate) std::str::SplitAsciiWhitespace<'a>);

    impl<'a> Tokens<'a> {
        pub(crate) fn word(&mut self) -> &'a str {
            self.0.next().expect("fixture line ends early")
        }
        pub(crate) fn expect(&mut self, w: &str) {
            assert_eq!(self.word(), w, "fixture format");
        }
        pub(crate) fn f32(&mut self) -> f32 {
            self.word().parse().unwrap()
        }
        pub(crate) fn f64(&mut self) -> f64 {
            self.word().parse().unwrap()
        }
        pub(crate) fn usize(&mut self) -> usize {
            self.word().parse().unwrap()
        }
        pub(crate) fn f32s(&mut self, n: usize) -> Vec<f32> {
            (0..n).map(|_| self.f32()).collect()
        }
        pub(crate) fn f64s(&mut self, n: usize) -> Vec<f64> {
            (0..n).map(|_| self.f64()).collect()
        }
        pub(crate) fn method(&mut self) -> CreaseMethod {
            match self.word() {
                "uniform" => CreaseMethod::Uniform,
                "chaikin" => CreaseMethod::Chaikin,
                w => panic!("crease method {w}"),
            }
        }
        pub(crate) fn rule(&mut self) -> VertexRule {
            match self.word() {
                "smooth" => VertexRule::Smooth,
                "dart" => VertexRule::Dart,
                "crease" => VertexRule::Crease,
                "corner" => VertexRule::Corner,
                w => panic!("rule {w}"),
            }
        }
    }

    /// Runs `check` on each data line of `fixture` with its kind (the first word), the words
    /// after it and the line, and makes sure that `check` reads every word.
    pub(crate) fn each_fixture_line(fixture: &str, mut check: impl FnMut(&str, &mut Tokens<'_>, &str)) {
        for line in fixture.lines().filter(|l| !l.starts_with('#') && !l.trim().is_empty()) {
            let mut t = Tokens(line.split_ascii_whitespace());
            let kind = t.word();
            check(kind, &mut t, line);
            assert!(t.0.next().is_none(), "fixture line longer than expected: {line}");
        }
    }

    #[derive(Default)]
    struct Agreement {
        vertices: usize,
        edges: usize,
        uniform: usize,
        /// Edges whose mask as Vtr asks for it differs from Sdc's with no rules given.
        vtr_only: usize,
        max_weight_diff: f64,
    }

    impl Agreement {
        fn weight(&mut self, ours: f64, theirs: f64, line: &str) {
            let d = (ours - theirs).abs();
            self.max_weight_diff = self.max_weight_diff.max(d);
            assert!(d <= WEIGHT_TOLERANCE, "weight {ours} vs OpenSubdiv's {theirs}: {line}");
        }
    }

    fn check_vertex(t: &mut Tokens<'_>, line: &str, agree: &mut Agreement) {
        let method = t.method();
        let (vs, n, nf) = (t.f32(), t.usize(), t.usize());
        let es = t.f32s(n);
        t.expect("rules");
        let (p_rule, c_rule) = (t.rule(), t.rule());
        t.expect("child");
        let cvs = t.f32();
        let around = t.f32s(n);
        t.expect("atvertex");
        let at = t.f32s(n);
        t.expect("w");
        let (wv, we, wf) = (t.f64(), t.f64s(n), t.f64s(nf));

        assert_eq!(vertex_rule(vs, &es), p_rule, "{line}");
        assert_eq!(child_vertex_sharpness(vs), cvs, "{line}");
        let mut child = vec![0.0; n];
        child_edge_sharpnesses_around_vertex(&es, method, &mut child);
        for i in 0..n {
            assert_eq!(child[i], at[i], "child edge {i}: {line}");
            assert_eq!(child_edge_sharpness(es[i], &es, method), at[i], "{line}");
            // Sdc's all-at-once form keeps an infinite value as given when nothing around is
            // semi-sharp; Vtr stores exactly INFINITELY_SHARP, as we do.
            assert!(around[i] == at[i] || (is_infinite(around[i]) && at[i] == INF), "{line}");
        }
        assert_eq!(vertex_rule(cvs, &child), c_rule, "{line}");

        let m = vertex_mask(vs, &es, nf, method);
        assert_eq!((m.rule, m.child_rule), (p_rule, c_rule), "{line}");
        agree.weight(m.vertex, wv, line);
        for (i, &w) in we.iter().enumerate() {
            agree.weight(m.edge_weight(i), w, line);
        }
        for &w in &wf {
            agree.weight(m.face, w, line);
        }
        agree.vertices += 1;
    }

    fn check_edge(t: &mut Tokens<'_>, line: &str, agree: &mut Agreement) {
        let method = t.method();
        let triangles = match t.word() {
            "catmark" => TriangleRule::Catmark,
            "smooth" => TriangleRule::Smooth,
            w => panic!("triangle rule {w}"),
        };
        let (s, nf) = (t.f32(), t.usize());
        let sizes: Vec<usize> = (0..nf).map(|_| t.usize()).collect();
        let theirs = read_edge_line(t, s, nf, method, line);
        let m = edge_mask(s, theirs.child_rule, &sizes, triangles);
        assert_eq!(m.faces, nf);
        for &w in &theirs.ends {
            agree.weight(m.vertex, w, line);
        }
        for &w in &theirs.faces {
            agree.weight(m.face, w, line);
        }
        agree.vtr_only += usize::from(theirs.vtr_only);
        agree.edges += 1;
    }

    /// OpenSubdiv's edge mask on an edge line: the child rule Vtr gives it, the weights of
    /// each end and each face in Vtr's mask, and whether Sdc's own mask (no rules given)
    /// differs from it.
    pub(crate) struct EdgeLine {
        pub(crate) child_rule: VertexRule,
        pub(crate) ends: Vec<f64>,
        pub(crate) faces: Vec<f64>,
        pub(crate) vtr_only: bool,
    }

    /// Reads an edge line from its child edges' sharpness on (the words both fixtures share)
    /// for an edge of sharpness `s` and `nf` faces, and checks our child sharpness at both
    /// ends and the child rule against OpenSubdiv's.
    pub(crate) fn read_edge_line(
        t: &mut Tokens<'_>,
        s: f32,
        nf: usize,
        method: CreaseMethod,
        line: &str,
    ) -> EdgeLine {
        t.expect("ring0");
        let k = t.usize();
        let ring0 = t.f32s(k);
        t.expect("ring1");
        let k = t.usize();
        let ring1 = t.f32s(k);
        t.expect("child");
        let child = [t.f32(), t.f32()];
        t.expect("crule");
        let child_rule = t.rule();
        t.expect("w");
        let (ends, faces) = (t.f64s(2), t.f64s(nf));
        t.expect("sdc");
        let (sdc_ends, sdc_faces) = (t.f64s(2), t.f64s(nf));

        let ours = [child_edge_sharpness(s, &ring0, method), child_edge_sharpness(s, &ring1, method)];
        assert_eq!(ours, child, "{line}");
        assert_eq!(edge_child_rule(s, ours), child_rule, "{line}");
        let vtr_only = (&ends, &faces) != (&sdc_ends, &sdc_faces);
        EdgeLine { child_rule, ends, faces, vtr_only }
    }

    #[test]
    fn masks_and_sharpness_agree_with_opensubdiv_sdc() {
        let mut agree = Agreement::default();
        each_fixture_line(FIXTURE, |kind, t, line| match kind {
            "vertex" => check_vertex(t, line, &mut agree),
            "edge" => check_edge(t, line, &mut agree),
            "uniform" => {
                let (s, c) = (t.f32(), t.f32());
                assert_eq!(subdivide_sharpness(s), c, "{line}");
                agree.uniform += 1;
            }
            w => panic!("unknown fixture line kind {w}"),
        });
        println!(
            "{} vertex masks, {} edge masks ({} where Vtr's rules differ from Sdc's own), {} uniform decrements; max weight difference {:e}",
            agree.vertices, agree.edges, agree.vtr_only, agree.uniform, agree.max_weight_diff
        );
        assert!(agree.vertices > 900 && agree.edges > 500 && agree.vtr_only > 0 && agree.uniform > 10);
    }
}
