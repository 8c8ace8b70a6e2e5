//! Gregory-basis end caps of Catmull-Clark surfaces, as OpenSubdiv 3.6.0 builds and evaluates
//! them.
//!
//! Where feature-adaptive refinement stops (the isolation level), OpenSubdiv's Bfr replaces
//! each leaf quad that is not a regular B-spline patch by a *Gregory basis patch*: a bicubic
//! Bézier patch whose four interior points are each split into a pair of face points blended
//! rationally. Its 20 points are a fixed linear combination of the leaf's neighbourhood, the
//! *source patch*. This module computes that combination ([`GregoryPatch::new`], the
//! counterpart of `Far::GregoryConverter` in `far/catmarkPatchBuilder.cpp`) and evaluates the
//! patch ([`GregoryPatch::position`], [`GregoryPatch::derivatives`], the counterpart of
//! `Far::internal::EvalBasisGregory` in `far/patchBasis.cpp`).
//!
//! The formulas are OpenSubdiv's, which differ from the published ones (Loop, Schaefer, Ni and
//! Castaño 2009) in the tangent scale, the face points and several approximations at sharp and
//! single-face corners; tessera must reproduce OpenSubdiv's surface, not the paper's. All
//! arithmetic is in `f64`, as Bfr's double-precision evaluation does.
//!
//! # Point order
//!
//! The 20 points are grouped by corner: for corner `i` (counter-clockwise, at parameters
//! (0,0), (1,0), (1,1), (0,1)), points `5i..5i+5` are
//!
//! * `P`  — the corner point (the Bézier corner),
//! * `Ep` — the edge point on the edge leaving corner `i` towards corner `i+1`,
//! * `Em` — the edge point on the edge leaving corner `i` towards corner `i−1`,
//! * `Fp` — the face point next to `Ep`,
//! * `Fm` — the face point next to `Em`.
//!
//! So with `u` along corner 0 → 1 and `v` along corner 0 → 3, the Bézier net's bottom row is
//! `P0, Ep0, Em1, P1` and its left column `P0, Em0, Ep3, P3`.

use super::gregory_shared::{
    self, apply, checked_layout, corner_and_face_points, corner_fields, corner_kinds, CornerKind,
    SchemeCorner, SourceLayout, Stencil,
};
pub use crate::surface::GregoryPatch;
use glam::DVec3;
use std::f64::consts::PI;

/// One corner of a leaf quad's source patch: the corner vertex, the fan of faces around it and
/// its 1-ring, in OpenSubdiv's order (`Far::SourcePatch::Corner`, `far/patchBuilder.h`).
///
/// # Faces and ring order
///
/// The faces around the corner vertex `V` are numbered `0..num_faces` counter-clockwise (the
/// direction from the patch's `u` edge to its `v` edge). Face `k`'s *leading edge* is the edge
/// `V → w` where `w` follows `V` in the face's own counter-clockwise vertex order; its trailing
/// edge (towards the vertex preceding `V` in the face) is face `k+1`'s leading edge.
///
/// * Interior corner: face 0 may be any face of the fan (`patch_face` is relative to it).
/// * Boundary corner: face 0 is the face whose leading edge is a boundary edge, so the fan
///   runs from one boundary edge to the other. A corner whose fan is cut by infinitely sharp
///   edges (OpenSubdiv's *corner span*) is a boundary corner over the span: its faces are
///   those between the two sharp edges enclosing the patch face, face 0 the one after the
///   leading sharp edge.
///
/// `ring` then lists, for each face `k` in order, two points: the far end of its leading
/// edge, then its vertex opposite `V` (the diagonal). A boundary corner appends the far end
/// of the last face's trailing edge. So the ring has `2·num_faces` points (interior) or
/// `2·num_faces + 1` (boundary), and for the patch face `k = patch_face` the points
/// `ring[2k]`, `ring[2k+1]`, `ring[(2k+2) mod len]` are the patch's next, opposite and
/// previous corners. This is the order of `Vtr::internal::Level::gatherQuadRegularRingAroundVertex`
/// (`vtr/level.cpp`) and of `SourcePatch::GetCornerRingPoints` (`far/patchBuilder.cpp`).
///
/// All faces involved must be quads (true at every level ≥ 1 of Catmull-Clark refinement).
#[derive(Debug, Clone, PartialEq)]
pub struct GregoryCorner {
    /// The corner vertex.
    pub position: DVec3,
    /// Faces in the corner's fan (its valence for an interior vertex, one less than its edge
    /// count on a boundary); ≥ 1, and ≥ 2 when not a boundary.
    pub num_faces: usize,
    /// Which face of the fan is the patch's face, `< num_faces`.
    pub patch_face: usize,
    /// The fan is open: the vertex is on the mesh boundary, or its span is cut by
    /// infinitely sharp edges (OpenSubdiv: `!VSpan::_periodic`, else `VTag::_boundary`).
    pub boundary: bool,
    /// The corner is treated as infinitely sharp. With Bfr's options
    /// (`far/patchBuilder.cpp`, `GetIrregularPatchCornerSpans`): the vertex is tagged a corner
    /// (`VTag::_corner`: infinitely sharp and topologically a corner, e.g. a one-face boundary
    /// vertex under "edge and corner"); or else it has infinitely sharp edges, is not a dart,
    /// and those edges do not form a simple crease; or else it has no such edges and is itself
    /// infinitely sharp.
    pub sharp: bool,
    /// The vertex is a dart (`Sdc::Crease::RULE_DART` with an infinitely sharp edge). It only
    /// affects which ring points the corner shares with its neighbours, not any formula.
    pub dart: bool,
    /// The 1-ring, in the order described above.
    pub ring: Vec<DVec3>,
}

impl GregoryCorner {
    /// OpenSubdiv's valence-2 interior flag (`SourcePatch::Finalize`): two faces, no boundary.
    pub fn is_val2_interior(&self) -> bool {
        self.fan().is_val2_interior()
    }

    /// The ring length this corner's fan implies: `2·num_faces`, plus one on a boundary.
    pub fn expected_ring_len(&self) -> usize {
        self.implied_ring_len()
    }
}

/// The source patch of one leaf quad: its four corners, counter-clockwise, corner `i` at
/// parameters (0,0), (1,0), (1,1), (0,1) (OpenSubdiv's `Far::SourcePatch`).
#[derive(Debug, Clone, PartialEq)]
pub struct GregorySource {
    /// The corners; see [`GregoryCorner`] for the order of each ring.
    pub corners: [GregoryCorner; 4],
}

/// A way in which a source patch — a leaf quad's [`GregorySource`] or a leaf triangle's
/// [`LoopGregorySource`](super::loop_gregory::LoopGregorySource) — does not describe its leaf
/// consistently.
#[derive(Debug, Clone, PartialEq)]
pub enum GregorySourceError {
    /// A corner's fan counts are impossible (no faces, a patch face out of range, or an
    /// interior fan of one face).
    BadFan {
        /// The corner.
        corner: usize,
    },
    /// A corner's ring does not have the number of points its fan implies
    /// ([`GregoryCorner::expected_ring_len`], `LoopCorner::expected_ring_len`).
    RingLength {
        /// The corner.
        corner: usize,
        /// The ring's length.
        len: usize,
        /// The length its fan implies.
        expected: usize,
    },
    /// The corners' fans do not fit together as OpenSubdiv pieces a source patch (for
    /// instance two adjacent valence-2 interior corners).
    Layout,
    /// A ring point disagrees with the same source point given by another corner (or, for a
    /// patch corner, with that corner's position): the ring is probably rotated or reversed.
    Mismatch {
        /// The corner whose ring disagrees.
        corner: usize,
        /// The index in its ring.
        ring_index: usize,
    },
}

impl std::fmt::Display for GregorySourceError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::BadFan { corner } => write!(f, "corner {corner}: impossible face counts"),
            Self::RingLength { corner, len, expected } => {
                write!(f, "corner {corner}: ring of {len} points, expected {expected}")
            }
            Self::Layout => write!(f, "corner fans do not fit together as a source patch"),
            Self::Mismatch { corner, ring_index } => write!(
                f,
                "corner {corner}: ring point {ring_index} differs from the same point seen from \
                 another corner"
            ),
        }
    }
}

impl std::error::Error for GregorySourceError {}

impl GregorySource {
    /// Checks that the corners describe one leaf quad consistently: fan counts, ring lengths,
    /// and that every point shared by two rings (or a ring and a corner) is the same point.
    /// Exact equality is required, as both copies come from the same mesh vertex.
    ///
    /// Cost: linear in the total ring length. [`GregoryPatch::new`] assumes a source that
    /// passes this check; call it when filling sources from a new mesh walker.
    pub fn validate(&self) -> Result<(), GregorySourceError> {
        gregory_shared::validate(&self.corners)
    }
}

/// The scale of the limit tangents at an interior vertex of valence `n`, from the eigenvalues
/// of Catmull-Clark's subdivision matrix (`CatmarkLimits::computeCoefficient`,
/// `far/catmarkPatchBuilder.cpp`). OpenSubdiv tabulates valences below 30; the table is kept
/// verbatim because its entries, not the closed form, define the patch points.
fn tangent_scale(n: usize) -> f64 {
    // OpenSubdiv's digits, so that the table can be compared with its source at a glance; they
    // round to the same f64 values as the shorter forms clippy would suggest.
    #[allow(clippy::excessive_precision)]
    const TABLE: [f64; 30] = [
        0.0,
        0.0,
        0.0,
        8.1281572906372312e-01,
        0.5,
        3.6364406329142801e-01,
        2.8751379706077085e-01,
        2.3868786685851678e-01,
        2.0454364190756097e-01,
        1.7922903958061159e-01,
        1.5965737079986253e-01,
        1.4404233443011302e-01,
        1.3127568415883017e-01,
        1.2063172212675841e-01,
        1.1161437506676930e-01,
        1.0387245516114274e-01,
        9.7150019090724835e-02,
        9.1255917505950648e-02,
        8.6044378511602668e-02,
        8.1402211336798411e-02,
        7.7240129516184072e-02,
        7.3486719751997026e-02,
        7.0084157479797987e-02,
        6.6985104030725440e-02,
        6.4150420569810074e-02,
        6.1547457638637268e-02,
        5.9148757447233989e-02,
        5.6931056818776957e-02,
        5.4874512279256417e-02,
        5.2962091433796134e-02,
    ];
    if n < TABLE.len() {
        return TABLE[n];
    }
    let inv = 1.0 / n as f64;
    let c = (2.0 * PI * inv).cos();
    16.0 * inv / ((c + 5.0) + ((c + 9.0) * (c + 1.0)).sqrt())
}

impl SchemeCorner for GregoryCorner {
    const RING_POINTS_PER_FACE: usize = 2;
    const REGULAR_FACES: usize = 4;
    // A regular corner's face angle is exactly a right angle (cos 0), not the rounded cosine
    // of π/2.
    const REGULAR_COS_FACE_ANGLE: f64 = 0.0;
    const FACE_POINT_DENOMINATOR: f64 = 3.0;
    const KEEPS_ZERO_ENTRIES: bool = false;

    corner_fields!();

    /// Limit-point weights of an interior vertex of valence `n` over `[vertex, ring…]`, and the
    /// edge points `P + tangent` along the patch face's leading (`ep`) and trailing (`em`) edges
    /// (`CatmarkLimits::ComputeInteriorPointWeights`, `far/catmarkPatchBuilder.cpp`). OpenSubdiv's
    /// tangent is not Sdc's: each edge's weight gathers three cosine terms and the scale is
    /// [`tangent_scale`]`·½/(n+5)`.
    fn interior_weights(n: usize, face_in_ring: usize) -> [Vec<f64>; 3] {
        let nf = n as f64;
        let inv_n = 1.0 / nf;
        let inv_n5 = 1.0 / (nf + 5.0);
        let p_coeff = inv_n * inv_n5;
        let tan_coeff = tangent_scale(n) * 0.5 * inv_n5;
        let face_angle = 2.0 * PI * inv_n;

        let width = 1 + 2 * n;
        let mut p = vec![0.0; width];
        // Tangent weights over the ring only (the vertex itself has none).
        let mut tan = vec![0.0; 2 * n];
        p[0] = nf * inv_n5;
        for i in 0..n {
            p[1 + 2 * i] = p_coeff * 4.0;
            p[2 + 2 * i] = p_coeff;
            let (prev, next) = ((i + n - 1) % n, (i + 1) % n);
            let c = tan_coeff * (face_angle * i as f64).cos();
            tan[2 * prev] += c * 2.0;
            tan[2 * prev + 1] += c;
            tan[2 * i] += c * 4.0;
            tan[2 * i + 1] += c;
            tan[2 * next] += c * 2.0;
        }
        // The tangent computed for edge 0 is rotated onto the patch face's two edges.
        let ep_shift = 2 * ((n - face_in_ring) % n);
        let em_shift = 2 * ((2 * n - face_in_ring - 1) % n);
        let mut ep = p.clone();
        let mut em = p.clone();
        for k in 0..2 * n {
            ep[1 + k] += tan[(k + ep_shift) % (2 * n)];
            em[1 + k] += tan[(k + em_shift) % (2 * n)];
        }
        [p, ep, em]
    }

    /// The interior tangent of a smooth boundary vertex with `valence` edges over
    /// `[vertex, ring…]` (`CatmarkLimits::ComputeBoundaryPointWeights`,
    /// `far/catmarkPatchBuilder.cpp`): OpenSubdiv's own eigenvector-based mask, not Sdc's.
    fn boundary_tangent(valence: usize) -> Vec<f64> {
        let num_faces = valence - 1;
        let theta = PI / num_faces as f64;
        let width = 2 * valence;
        let last = width - 1;
        let mut tan = vec![0.0; width];
        let k = num_faces as f64;
        let (s, c) = theta.sin_cos();
        let div3 = 1.0 / 3.0;
        let div3kc = 1.0 / (3.0 * k + c);
        let gamma = -4.0 * s * div3kc;
        let alpha_0k = -((1.0 + 2.0 * c) * (1.0 + c).sqrt()) * div3kc / (1.0 - c).sqrt();
        let beta_0 = s * div3kc;
        tan[0] = gamma * div3;
        tan[1] = alpha_0k * div3;
        tan[2] = beta_0 * div3;
        tan[last] = alpha_0k * div3;
        for i in 1..valence - 1 {
            let sin_i = (theta * i as f64).sin();
            let sin_i1 = (theta * (i + 1) as f64).sin();
            tan[1 + 2 * i] = 4.0 * sin_i * div3kc * div3;
            tan[2 + 2 * i] = (sin_i + sin_i1) * div3kc * div3;
        }
        tan
    }

    fn em_on_trailing_edge(valence: usize, face_in_ring: usize) -> bool {
        face_in_ring == valence - 2
    }

    /// P, Ep and Em of a corner whose neighbourhood is regular: the B-spline patch's Bézier points
    /// (`GregoryConverter::assignRegularEdgePoints`, `far/catmarkPatchBuilder.cpp`).
    fn regular_edge_points(c: usize, kind: &CornerKind, ring: &[usize]) -> [Stencil; 3] {
        // An edge point along an interior edge, `ring[along]`'s: 2/9 on that end, 1/9 on the
        // ends of the edges beside it, 1/18 on the diagonals beside it. Ep and Em are its
        // mirror images, and a boundary corner's interior edge point is the same row.
        let edge_point = |along: usize, beside: [usize; 2], diagonals: [usize; 2]| {
            vec![
                (c, 4.0 / 9.0),
                (ring[along], 2.0 / 9.0),
                (ring[beside[0]], 1.0 / 9.0),
                (ring[beside[1]], 1.0 / 9.0),
                (ring[diagonals[0]], 1.0 / 18.0),
                (ring[diagonals[1]], 1.0 / 18.0),
            ]
        };
        if !kind.boundary {
            let mut p = vec![(c, 4.0 / 9.0)];
            p.extend([0, 2, 4, 6].map(|k| (ring[k], 1.0 / 9.0)));
            p.extend([1, 3, 5, 7].map(|k| (ring[k], 1.0 / 36.0)));
            let f = kind.face_in_ring;
            let (e_p, e_m) = (2 * f, 2 * ((f + 1) % 4));
            let (o_p, o_m) = (2 * ((f + 2) % 4), 2 * ((f + 3) % 4));
            let ep = edge_point(e_p, [e_m, o_m], [e_p + 1, o_m + 1]);
            let em = edge_point(e_m, [e_p, o_p], [e_p + 1, e_m + 1]);
            [p, ep, em]
        } else {
            let p = vec![(c, 2.0 / 3.0), (ring[0], 1.0 / 6.0), (ring[4], 1.0 / 6.0)];
            let along = if kind.flags.ep_on_boundary { ring[0] } else { ring[4] };
            let on_boundary = vec![(c, 2.0 / 3.0), (along, 1.0 / 3.0)];
            let interior = edge_point(2, [0, 4], [1, 3]);
            if kind.flags.ep_on_boundary {
                [p, on_boundary, interior]
            } else {
                [p, interior, on_boundary]
            }
        }
    }

    /// The regular face point of corner `c`, the same for Fp and Fm: the bilinear-weighted one of
    /// a B-spline neighbourhood (`GregoryConverter::assignRegularFacePoints`).
    fn regular_face_point(c: usize, _: &CornerKind, _: &[usize]) -> Stencil {
        let (next, opp, prev) = ((c + 1) % 4, (c + 2) % 4, (c + 3) % 4);
        vec![(c, 4.0 / 9.0), (prev, 2.0 / 9.0), (next, 2.0 / 9.0), (opp, 1.0 / 9.0)]
    }

    /// The irregular face point's correction (`GregoryConverter::computeIrregularFacePoint`,
    /// `far/catmarkPatchBuilder.cpp`): `±(1/9, 1/18)` on the four ring points beside the interior
    /// edge `edge`, with `d = 3` in the shared blend.
    ///
    /// A correction outside the union of P, E_near and E_far's points is dropped (see
    /// [`blend_face_point`](gregory_shared::blend_face_point)). That can only happen when `near`
    /// is sharp (P is the vertex alone) and `far` is sharp or a one-face corner — not a
    /// configuration adaptive refinement produces at level ≥ 1, and so not covered by
    /// OpenSubdiv's fixture — but it is reproduced here by index.
    fn face_point_corrections(ring: &[usize], [e_prev, edge, e_next]: [usize; 3], sign: f64) -> Stencil {
        vec![
            (ring[2 * e_prev], -sign / 9.0),
            (ring[2 * e_prev + 1], -sign / 18.0),
            (ring[2 * edge + 1], sign / 18.0),
            (ring[2 * e_next], sign / 9.0),
        ]
    }
}

/// The 20 stencils of a source patch over its [`SourceLayout`] numbering, in the module's
/// point order (`GregoryConverter::Convert`, `far/catmarkPatchBuilder.cpp`): the shared
/// corner, edge and face points are the whole patch.
fn gregory_stencils(corners: &[GregoryCorner; 4], layout: &SourceLayout<4>) -> Option<[Stencil; 20]> {
    let rings = layout.rings(corners)?;
    corner_and_face_points::<GregoryCorner, 4>(&corner_kinds(corners), &rings, layout.num_points)
        .try_into()
        .ok()
}

/// The 20 points of a leaf's Gregory basis patch, in OpenSubdiv's order (see the module
/// documentation). Shorthand for `GregoryPatch::new(source).points`.
///
/// # Panics
/// If the source is inconsistent (see [`GregorySource::validate`]; inconsistent shared points
/// are not detected here and give a wrong patch instead).
pub fn gregory_points(source: &GregorySource) -> [DVec3; 20] {
    GregoryPatch::new(source).points
}

impl GregoryPatch {
    /// Computes the end cap of a leaf quad from its source patch, covering every case of
    /// OpenSubdiv's `GregoryConverter`: regular, interior irregular, smooth boundary, sharp,
    /// smooth one-face and valence-2 interior corners. (OpenSubdiv's faster matrix layout for
    /// a single interior irregular corner only changes how its matrix is stored, not its
    /// values, so there is one path here.)
    ///
    /// Precondition: `source` passes [`GregorySource::validate`]. Cost: O(r²) for total ring
    /// length r (each face point is assembled densely over the source points), a few
    /// microseconds for ordinary valences.
    ///
    /// # Panics
    /// If the fan counts or ring lengths are inconsistent.
    pub fn new(source: &GregorySource) -> Self {
        let corners = &source.corners;
        let layout = checked_layout(corners, "Gregory");
        let stencils = gregory_stencils(corners, &layout).expect("Gregory source rings do not fit");
        let points = gregory_shared::source_points(corners, &layout);
        GregoryPatch { points: apply(&stencils, &points) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::subdivision::gregory_shared::{bspline, Rng};
    use std::collections::HashMap;

    /// A quad mesh with consistently counter-clockwise faces, for filling sources the way a
    /// half-edge walker would.
    struct Mesh {
        pos: Vec<DVec3>,
        faces: Vec<[usize; 4]>,
        sharp: Vec<bool>,
        /// Directed edge `a → b` (in a face's own order) to that face.
        edge_face: HashMap<(usize, usize), usize>,
    }

    impl Mesh {
        fn new(pos: Vec<DVec3>, faces: Vec<[usize; 4]>) -> Self {
            let mut edge_face = HashMap::new();
            for (f, q) in faces.iter().enumerate() {
                for k in 0..4 {
                    assert!(edge_face.insert((q[k], q[(k + 1) % 4]), f).is_none(), "non-manifold");
                }
            }
            let sharp = vec![false; pos.len()];
            Mesh { pos, faces, sharp, edge_face }
        }

        fn local(&self, f: usize, v: usize) -> usize {
            self.faces[f].iter().position(|&w| w == v).unwrap()
        }

        /// The faces around `v` counter-clockwise (from the leading boundary edge if any) and
        /// whether the fan is open.
        fn fan(&self, v: usize) -> (Vec<usize>, bool) {
            let around: Vec<usize> = (0..self.faces.len()).filter(|&f| self.faces[f].contains(&v)).collect();
            let leading = |f: usize| self.faces[f][(self.local(f, v) + 1) % 4];
            let start = around.iter().copied().find(|&f| !self.edge_face.contains_key(&(leading(f), v)));
            let boundary = start.is_some();
            let start = start.unwrap_or(around[0]);
            let mut fan = vec![start];
            loop {
                let f = *fan.last().unwrap();
                let trailing = self.faces[f][(self.local(f, v) + 3) % 4];
                match self.edge_face.get(&(v, trailing)) {
                    Some(&g) if g != start => fan.push(g),
                    _ => break,
                }
            }
            assert_eq!(fan.len(), around.len());
            (fan, boundary)
        }

        fn source(&self, f: usize) -> GregorySource {
            let corners = [0, 1, 2, 3].map(|i| {
                let v = self.faces[f][i];
                let (fan, boundary) = self.fan(v);
                let mut ring = Vec::new();
                for &g in &fan {
                    let k = self.local(g, v);
                    ring.push(self.pos[self.faces[g][(k + 1) % 4]]);
                    ring.push(self.pos[self.faces[g][(k + 2) % 4]]);
                }
                if boundary {
                    let g = *fan.last().unwrap();
                    ring.push(self.pos[self.faces[g][(self.local(g, v) + 3) % 4]]);
                }
                GregoryCorner {
                    position: self.pos[v],
                    num_faces: fan.len(),
                    patch_face: fan.iter().position(|&g| g == f).unwrap(),
                    boundary,
                    sharp: self.sharp[v],
                    dart: false,
                    ring,
                }
            });
            let source = GregorySource { corners };
            source.validate().unwrap();
            source
        }

        fn face_with(&self, corners: [usize; 4]) -> usize {
            self.faces.iter().position(|q| *q == corners).unwrap()
        }
    }

    /// An `n × n` quad grid with jittered vertices, vertex `(i, j)` at index `j·(n+1) + i`.
    fn grid(n: usize, seed: u64) -> Mesh {
        let mut rng = Rng(seed);
        let id = |i: usize, j: usize| j * (n + 1) + i;
        let pos = (0..(n + 1) * (n + 1))
            .map(|k| DVec3::new((k % (n + 1)) as f64, (k / (n + 1)) as f64, 0.0) + rng.point(0.3))
            .collect();
        let mut faces = Vec::new();
        for j in 0..n {
            for i in 0..n {
                faces.push([id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        Mesh::new(pos, faces)
    }

    /// `n` sectors of `k × k` quads around a centre vertex (index 0): closed (centre of
    /// valence `n`) or open (a boundary centre with `n` faces). Returns the mesh and
    /// `g(sector, a, b)`, the vertex `a` steps along the sector's first spoke and `b` along
    /// its second.
    fn fan_mesh(
        n: usize,
        k: usize,
        closed: bool,
        seed: u64,
    ) -> (Mesh, impl Fn(usize, usize, usize) -> usize) {
        let spokes = if closed { n } else { n + 1 };
        let spoke = move |j: usize, a: usize| 1 + j * k + (a - 1);
        let inner = move |j: usize, a: usize, b: usize| 1 + spokes * k + j * k * k + (a - 1) * k + (b - 1);
        let g = move |j: usize, a: usize, b: usize| match (a, b) {
            (0, 0) => 0,
            (_, 0) => spoke(j, a),
            (0, _) => spoke((j + 1) % spokes, b),
            _ => inner(j, a, b),
        };
        let count = 1 + spokes * k + n * k * k;
        let step = if closed { 2.0 * PI / n as f64 } else { PI / n as f64 };
        let dir = |j: usize| DVec3::new((step * j as f64).cos(), (step * j as f64).sin(), 0.0);
        let mut rng = Rng(seed);
        let mut pos = vec![DVec3::ZERO; count];
        let mut faces = Vec::new();
        for j in 0..n {
            for a in 0..=k {
                for b in 0..=k {
                    pos[g(j, a, b)] = dir(j) * a as f64 + dir(j + 1) * b as f64;
                }
            }
            for a in 0..k {
                for b in 0..k {
                    faces.push([g(j, a, b), g(j, a + 1, b), g(j, a + 1, b + 1), g(j, a, b + 1)]);
                }
            }
        }
        for p in &mut pos {
            *p += rng.point(0.3);
        }
        (Mesh::new(pos, faces), g)
    }

    fn samples() -> impl Iterator<Item = (f64, f64)> {
        (0..=8).flat_map(|i| (0..=8).map(move |j| (i as f64 / 8.0, j as f64 / 8.0)))
    }

    fn close(a: DVec3, b: DVec3, tol: f64) -> bool {
        (a - b).abs().max_element() <= tol
    }

    #[test]
    fn regular_interior_patch_is_the_bspline_patch() {
        let mesh = grid(7, 11);
        let id = |i: usize, j: usize| j * 8 + i;
        let (i0, j0) = (3, 3);
        let face = mesh.face_with([id(i0, j0), id(i0 + 1, j0), id(i0 + 1, j0 + 1), id(i0, j0 + 1)]);
        let patch = GregoryPatch::new(&mesh.source(face));
        let cv = |c: usize, r: usize| mesh.pos[id(i0 + c - 1, j0 + r - 1)];
        for (u, v) in samples() {
            let rows = [0, 1, 2, 3].map(|r| bspline([0, 1, 2, 3].map(|c| cv(c, r)), u));
            let expected = bspline(rows, v);
            let h = 1e-6;
            let du = (patch.position(u + h, v) - patch.position(u - h, v)) / (2.0 * h);
            let (p, pu, _) = patch.derivatives(u, v);
            assert!(close(patch.position(u, v), expected, 1e-12), "({u}, {v})");
            assert!(close(p, expected, 1e-12));
            assert!(close(pu, du, 1e-7), "du at ({u}, {v})");
        }
    }

    #[test]
    fn interior_corner_point_is_the_catmull_clark_limit() {
        for n in [3, 5, 6] {
            let (mesh, g) = fan_mesh(n, 2, true, 5 + n as u64);
            let face = mesh.face_with([g(0, 0, 0), g(0, 1, 0), g(0, 1, 1), g(0, 0, 1)]);
            let points = gregory_points(&mesh.source(face));
            let nf = n as f64;
            let edges: DVec3 = (0..n).map(|j| mesh.pos[g(j, 1, 0)]).sum();
            let diagonals: DVec3 = (0..n).map(|j| mesh.pos[g(j, 1, 1)]).sum();
            let limit = mesh.pos[0] * (nf / (nf + 5.0))
                + edges * (4.0 / (nf * (nf + 5.0)))
                + diagonals * (1.0 / (nf * (nf + 5.0)));
            assert!(close(points[0], limit, 1e-12), "valence {n}");
        }
    }

    #[test]
    fn interior_ring_start_does_not_matter() {
        let (mesh, g) = fan_mesh(5, 2, true, 3);
        let face = mesh.face_with([g(2, 0, 0), g(2, 1, 0), g(2, 1, 1), g(2, 0, 1)]);
        let source = mesh.source(face);
        let mut rotated = source.clone();
        let c = &mut rotated.corners[0];
        c.ring.rotate_left(2);
        c.patch_face = (c.patch_face + c.num_faces - 1) % c.num_faces;
        let (a, b) = (gregory_points(&source), gregory_points(&rotated));
        for (p, q) in a.iter().zip(&b) {
            assert!(close(*p, *q, 1e-12));
        }
    }

    /// Max distance between two patches along a shared edge, given how each parametrises it.
    fn edge_gap(
        a: &GregoryPatch,
        ea: impl Fn(f64) -> (f64, f64),
        b: &GregoryPatch,
        eb: impl Fn(f64) -> (f64, f64),
    ) -> f64 {
        (0..=32)
            .map(|i| {
                let t = i as f64 / 32.0;
                let ((ua, va), (ub, vb)) = (ea(t), eb(t));
                (a.position(ua, va) - b.position(ub, vb)).length()
            })
            .fold(0.0, f64::max)
    }

    #[test]
    fn adjacent_patches_share_their_edge_curves() {
        for (n, closed) in [(5, true), (3, true), (3, false), (6, false)] {
            let (mesh, g) = fan_mesh(n, 3, closed, 17 + n as u64);
            let patch = |j: usize, a: usize, b: usize| {
                let f = mesh.face_with([g(j, a, b), g(j, a + 1, b), g(j, a + 1, b + 1), g(j, a, b + 1)]);
                GregoryPatch::new(&mesh.source(f))
            };
            // Two patches at the extraordinary vertex across the spoke between sectors 0 and 1:
            // the first's v edge at u = 0 is the second's u edge at v = 0.
            let (a, b) = (patch(0, 0, 0), patch(1, 0, 0));
            assert!(edge_gap(&a, |t| (0.0, t), &b, |t| (t, 0.0)) < 1e-12, "n = {n}, spoke");
            // The patch at the extraordinary vertex and its regular neighbour along the spoke.
            let c = patch(0, 1, 0);
            assert!(edge_gap(&a, |t| (1.0, t), &c, |t| (0.0, t)) < 1e-12, "n = {n}, outward");
        }
    }

    #[test]
    fn boundary_curves_follow_the_boundary_rule() {
        // (sectors, centre sharp): a smooth irregular boundary vertex, a sharp corner of three
        // faces, a smooth one-face corner (edge-only boundary) and a sharp one (edge and corner).
        for (n, sharp) in [(3, false), (3, true), (1, false), (1, true), (2, true)] {
            let (mut mesh, g) = fan_mesh(n, 3, false, 23 + n as u64);
            mesh.sharp[0] = sharp;
            let f = mesh.face_with([g(0, 0, 0), g(0, 1, 0), g(0, 1, 1), g(0, 0, 1)]);
            let patch = GregoryPatch::new(&mesh.source(f));
            let p = |v: usize| mesh.pos[v];
            let centre = p(0);
            // The boundary polygon through the centre, from its last spoke to its first.
            let before = if sharp { centre * 2.0 - p(g(0, 1, 0)) } else { p(g(n - 1, 0, 1)) };
            let curve = [before, centre, p(g(0, 1, 0)), p(g(0, 2, 0))];
            for i in 0..=16 {
                let t = i as f64 / 16.0;
                assert!(
                    close(patch.position(t, 0.0), bspline(curve, t), 1e-12),
                    "n = {n}, sharp {sharp}, t = {t}"
                );
            }
            // The same along the last spoke, on the last sector's v edge.
            let f = mesh.face_with([g(n - 1, 0, 0), g(n - 1, 1, 0), g(n - 1, 1, 1), g(n - 1, 0, 1)]);
            let patch = GregoryPatch::new(&mesh.source(f));
            let after = if sharp { centre * 2.0 - p(g(n - 1, 0, 1)) } else { p(g(0, 1, 0)) };
            let curve = [after, centre, p(g(n - 1, 0, 1)), p(g(n - 1, 0, 2))];
            for i in 0..=16 {
                let t = i as f64 / 16.0;
                assert!(
                    close(patch.position(0.0, t), bspline(curve, t), 1e-12),
                    "n = {n}, sharp {sharp}, v = {t}"
                );
            }
        }
    }

    /// OpenSubdiv's own Gregory patches: source patches and 20 points printed by
    /// `tools/osd-oracle/gregory_check.cpp` (run `tools/osd-oracle/gregory_check.sh`, which
    /// links OpenSubdiv 3.6.0 built from source and writes this fixture) for cages covering
    /// valence 3 and 5 interior corners, smooth boundary corners of 2 and 3 faces, smooth and
    /// sharp one-face corners, sharp interior and boundary corners, a dart with its crease and
    /// valence-2 interior corners, at isolation level 2.
    #[test]
    fn matches_opensubdiv() {
        let text = include_str!("../../tests/fixtures/gregory/osd_gregory.txt");
        let mut lines = text.lines().peekable();
        let nums =
            |s: &str| s.split_whitespace().skip(1).map(|t| t.parse::<f64>().unwrap()).collect::<Vec<_>>();
        let (mut count, mut worst) = (0, 0.0f64);
        while let Some(header) = lines.next() {
            assert!(header.starts_with("patch "), "{header}");
            let corners = [0, 1, 2, 3].map(|_| {
                let c = nums(lines.next().unwrap());
                let r = nums(lines.next().unwrap());
                let ring: Vec<DVec3> = r[1..].chunks(3).map(|p| DVec3::new(p[0], p[1], p[2])).collect();
                assert_eq!(ring.len(), r[0] as usize);
                GregoryCorner {
                    position: DVec3::new(c[5], c[6], c[7]),
                    num_faces: c[0] as usize,
                    patch_face: c[1] as usize,
                    boundary: c[2] != 0.0,
                    sharp: c[3] != 0.0,
                    dart: c[4] != 0.0,
                    ring,
                }
            });
            let source = GregorySource { corners };
            source.validate().unwrap_or_else(|e| panic!("{header}: {e}"));
            let ours = gregory_points(&source);
            for (i, p) in ours.iter().enumerate() {
                let q = nums(lines.next().unwrap());
                let d = (*p - DVec3::new(q[0], q[1], q[2])).abs().max_element();
                assert!(d < 1e-12, "{header}: point {i} differs by {d}");
                worst = worst.max(d);
            }
            let patch = GregoryPatch::new(&source);
            while lines.peek().is_some_and(|l| l.starts_with("eval ")) {
                let e = nums(lines.next().unwrap());
                let v = |k: usize| DVec3::new(e[k], e[k + 1], e[k + 2]);
                let (p, du, dv) = patch.derivatives(e[0], e[1]);
                let d = [(p, v(2)), (du, v(5)), (dv, v(8)), (patch.position(e[0], e[1]), v(2))]
                    .iter()
                    .map(|(a, b)| (*a - *b).abs().max_element())
                    .fold(0.0, f64::max);
                assert!(d < 1e-12, "{header}: evaluation at ({}, {}) differs by {d}", e[0], e[1]);
                worst = worst.max(d);
            }
            count += 1;
        }
        assert_eq!(count, 88);
        assert!(worst < 1e-12, "{worst}");
    }

    #[test]
    fn validate_catches_a_reversed_ring() {
        let (mesh, g) = fan_mesh(5, 2, true, 1);
        let f = mesh.face_with([g(0, 0, 0), g(0, 1, 0), g(0, 1, 1), g(0, 0, 1)]);
        let mut source = mesh.source(f);
        source.corners[1].ring.reverse();
        assert!(matches!(source.validate(), Err(GregorySourceError::Mismatch { .. })));
        source.corners[1].ring.pop();
        assert!(matches!(source.validate(), Err(GregorySourceError::RingLength { corner: 1, .. })));
    }
}
