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
        self.num_faces == 2 && !self.boundary
    }

    /// The ring length this corner's fan implies: `2·num_faces`, plus one on a boundary.
    pub fn expected_ring_len(&self) -> usize {
        2 * self.num_faces + usize::from(self.boundary)
    }

    /// Edges at the corner vertex within its fan (OpenSubdiv's corner "valence").
    fn valence(&self) -> usize {
        self.num_faces + usize::from(self.boundary)
    }

    /// A corner of a regular B-spline neighbourhood: four interior faces, or two on a boundary.
    fn is_regular(&self) -> bool {
        (self.num_faces << usize::from(self.boundary)) == 4 && !self.sharp
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
        for (i, c) in self.corners.iter().enumerate() {
            if c.num_faces == 0 || c.patch_face >= c.num_faces || (c.num_faces == 1 && !c.boundary) {
                return Err(GregorySourceError::BadFan { corner: i });
            }
            if c.ring.len() != c.expected_ring_len() {
                return Err(GregorySourceError::RingLength {
                    corner: i,
                    len: c.ring.len(),
                    expected: c.expected_ring_len(),
                });
            }
        }
        let layout = SourceLayout::new(&self.corners).ok_or(GregorySourceError::Layout)?;
        let mut seen: Vec<Option<DVec3>> = vec![None; layout.num_points];
        for (i, c) in self.corners.iter().enumerate() {
            seen[i] = Some(c.position);
        }
        for (i, c) in self.corners.iter().enumerate() {
            let indices = layout.ring_indices(&self.corners, i).ok_or(GregorySourceError::Layout)?;
            for (k, (&index, &p)) in indices.iter().zip(&c.ring).enumerate() {
                match seen[index] {
                    Some(q) if q != p => {
                        return Err(GregorySourceError::Mismatch { corner: i, ring_index: k })
                    }
                    _ => seen[index] = Some(p),
                }
            }
        }
        Ok(())
    }
}

/// OpenSubdiv's numbering of a source patch's distinct points (`SourcePatch::Finalize` and
/// `SourcePatch::GetCornerRingPoints`, `far/patchBuilder.cpp`): the 4 corners, then each
/// corner's ring points not shared with a neighbour. The numbering matters beyond
/// bookkeeping: an irregular face point keeps a ring point's contribution only if that point
/// already contributes to the corner and edge points it is built from, so which ring slots
/// are the *same* point decides the result (see `face_point`).
struct SourceLayout {
    num_points: usize,
    ring_sizes: [usize; 4],
    local_sizes: [usize; 4],
    local_offsets: [usize; 4],
    shares_prev: [bool; 4],
    shares_next: [bool; 4],
    val2: [bool; 4],
}

impl SourceLayout {
    /// Sizes the rings and numbers the local points; `None` if the fans do not fit.
    fn new(corners: &[GregoryCorner; 4]) -> Option<Self> {
        let val2 = corners.each_ref().map(GregoryCorner::is_val2_interior);
        let mut layout = SourceLayout {
            num_points: 4,
            ring_sizes: [0; 4],
            local_sizes: [0; 4],
            local_offsets: [0; 4],
            shares_prev: [false; 4],
            shares_next: [false; 4],
            val2,
        };
        for i in 0..4 {
            let (prev, next) = ((i + 3) % 4, (i + 1) % 4);
            let c = &corners[i];
            if c.valence() > 2 {
                // A ring shares its first point past the previous corner with that corner's
                // ring, and its last point before the next corner with the next one's, unless
                // a boundary (or a dart's sharp edge) separates them.
                let (share_prev, share_next) = if c.boundary {
                    (c.patch_face != c.num_faces - 1, c.patch_face != 0)
                } else if c.dart {
                    let (p, n) = (&corners[prev], &corners[next]);
                    let prev_on_dart_edge = p.boundary && p.patch_face == 0;
                    let next_on_dart_edge = n.boundary && n.patch_face + 1 == n.num_faces;
                    (!prev_on_dart_edge, !next_on_dart_edge)
                } else {
                    (true, true)
                };
                layout.shares_prev[i] = share_prev;
                layout.shares_next[i] = share_next;
                let ring = 2 * c.num_faces + usize::from(c.boundary);
                // A valence-2 neighbour puts the opposite corner into this ring a second time.
                let taken = 3
                    + usize::from(share_prev)
                    + usize::from(share_next)
                    + usize::from(val2[prev])
                    + usize::from(val2[next]);
                layout.ring_sizes[i] = ring;
                layout.local_sizes[i] = ring.checked_sub(taken)?;
            } else if c.num_faces == 1 {
                layout.ring_sizes[i] = 3;
                layout.local_sizes[i] = 0;
            } else {
                layout.ring_sizes[i] = 4;
                layout.local_sizes[i] = 1;
            }
            layout.local_offsets[i] = layout.num_points;
            layout.num_points += layout.local_sizes[i];
        }
        Some(layout)
    }

    /// The source-point indices of corner `i`'s ring, in ring order; `None` if the pieces do
    /// not add up to the ring's size.
    fn ring_indices(&self, corners: &[GregoryCorner; 4], i: usize) -> Option<Vec<usize>> {
        let (next, opp, prev) = ((i + 1) % 4, (i + 2) % 4, (i + 3) % 4);
        // Assembled as if the patch face were face 0: the other three corners, then the points
        // shared with the previous corner, the local points, those shared with the next one.
        let mut ring = vec![next, opp, prev];
        if self.val2[prev] {
            ring.push(opp);
        }
        if self.shares_prev[i] {
            ring.push(self.local_offsets[prev] + self.local_sizes[prev] - 1);
        }
        ring.extend(self.local_offsets[i]..self.local_offsets[i] + self.local_sizes[i]);
        if self.shares_next[i] {
            ring.push(self.local_offsets[next]);
        }
        if self.val2[next] {
            ring.push(opp);
        }
        if ring.len() != self.ring_sizes[i] {
            return None;
        }
        let rotation = (ring.len() - 2 * corners[i].patch_face) % ring.len();
        ring.rotate_left(rotation);
        Some(ring)
    }
}

/// A patch point as a combination of source points: (source index, weight), repeats allowed.
pub(super) type Stencil = Vec<(usize, f64)>;

/// How a corner's two edge points and two face points relate to the patch's boundary and to
/// its neighbours' regularity (the second pass of `GregoryConverter::Initialize`,
/// `far/catmarkPatchBuilder.cpp`; `GregoryTriConverter::Initialize`,
/// `far/loopPatchBuilder.cpp`, applies the same rule to triangles).
#[derive(Clone, Copy, Default)]
pub(super) struct FacePointFlags {
    /// Ep lies on a boundary edge (the patch face is the first of an open fan).
    pub ep_on_boundary: bool,
    /// Em lies on a boundary edge (the patch face is the last of an open fan).
    pub em_on_boundary: bool,
    /// Fp takes the regular (B-spline or box-spline) face point.
    pub fp_regular: bool,
    /// Fm takes the regular face point.
    pub fm_regular: bool,
    /// Fp is a copy of Fm.
    pub fp_copied: bool,
    /// Fm is a copy of Fp.
    pub fm_copied: bool,
}

impl FacePointFlags {
    /// The flags of a corner whose fan has `num_faces` faces, the patch face at `face_in_ring`,
    /// given whether the corner and its next and previous neighbours are regular.
    pub(super) fn new(boundary: bool, num_faces: usize, face_in_ring: usize, regular: [bool; 3]) -> Self {
        let [this, next, prev] = regular;
        let mut f = FacePointFlags {
            fp_regular: this && next,
            fm_regular: this && prev,
            ..FacePointFlags::default()
        };
        if boundary {
            f.ep_on_boundary = face_in_ring == 0;
            f.em_on_boundary = face_in_ring + 1 == num_faces;
            if num_faces > 1 {
                // Across a boundary edge the two face points of the corner coincide: the one
                // by the boundary copies the other (or both are regular).
                if f.ep_on_boundary {
                    f.fp_regular = f.fm_regular;
                    f.fp_copied = !f.fp_regular;
                }
                if f.em_on_boundary {
                    f.fm_regular = f.fp_regular;
                    f.fm_copied = !f.fm_regular;
                }
            } else {
                // A one-face corner takes the regular face points.
                f.fp_regular = true;
                f.fm_regular = true;
            }
        }
        f
    }
}

/// The irregular face point rule shared by quads (`d = 3`, `GregoryConverter`) and triangles
/// (`d = 4`, `GregoryTriConverter`): `(cos θ_far·P + (d − 2cos θ_near − cos θ_far)·E_near +
/// 2cos θ_near·E_far)/d` plus the `corrections` (source index, weight).
///
/// OpenSubdiv assembles the row over the union of the source points that P, E_near and E_far
/// use, and adds the corrections into that row only: a correction on a point outside the
/// union is dropped. So the result depends on which ring slots are the same source point,
/// which is why sources are numbered as OpenSubdiv numbers them. Cost: O(`num_points`).
#[allow(clippy::too_many_arguments)]
pub(super) fn blend_face_point(
    num_points: usize,
    d: f64,
    cos_near: f64,
    cos_far: f64,
    p: &Stencil,
    e_near: &Stencil,
    e_far: &Stencil,
    corrections: &[(usize, f64)],
) -> Stencil {
    let p_coeff = cos_far / d;
    let near_coeff = (d - 2.0 * cos_near - cos_far) / d;
    let far_coeff = 2.0 * cos_near / d;

    let mut row = vec![0.0; num_points];
    let mut used = vec![false; num_points];
    for (stencil, s) in [(p, p_coeff), (e_near, near_coeff), (e_far, far_coeff)] {
        for &(i, w) in stencil {
            row[i] += s * w;
            used[i] = true;
        }
    }
    for &(i, w) in corrections {
        row[i] += w;
    }
    (0..num_points).filter(|&i| used[i]).map(|i| (i, row[i])).collect()
}

/// What the converter needs of each corner (`GregoryConverter::CornerTopology`,
/// `far/catmarkPatchBuilder.cpp`), including how its face points relate to its neighbours.
#[derive(Clone, Copy, Default)]
struct CornerKind {
    boundary: bool,
    sharp: bool,
    regular: bool,
    valence: usize,
    num_faces: usize,
    face_in_ring: usize,
    cos_face_angle: f64,
    ep_on_boundary: bool,
    em_on_boundary: bool,
    fp_regular: bool,
    fm_regular: bool,
    fp_copied: bool,
    fm_copied: bool,
}

fn corner_kinds(corners: &[GregoryCorner; 4]) -> [CornerKind; 4] {
    let mut kinds = corners.each_ref().map(|c| {
        let regular = c.is_regular();
        // A regular corner's face angle is exactly a right angle (cos 0), not the rounded
        // cosine of π/2.
        let cos_face_angle = if regular {
            0.0
        } else {
            let sweep = if c.boundary { PI } else { 2.0 * PI };
            (sweep / c.num_faces as f64).cos()
        };
        CornerKind {
            boundary: c.boundary,
            sharp: c.sharp,
            regular,
            valence: c.valence(),
            num_faces: c.num_faces,
            face_in_ring: c.patch_face,
            cos_face_angle,
            ..CornerKind::default()
        }
    });
    let regular = kinds.map(|k| k.regular);
    for (i, k) in kinds.iter_mut().enumerate() {
        let f = FacePointFlags::new(
            k.boundary,
            k.num_faces,
            k.face_in_ring,
            [k.regular, regular[(i + 1) % 4], regular[(i + 3) % 4]],
        );
        k.ep_on_boundary = f.ep_on_boundary;
        k.em_on_boundary = f.em_on_boundary;
        k.fp_regular = f.fp_regular;
        k.fm_regular = f.fm_regular;
        k.fp_copied = f.fp_copied;
        k.fm_copied = f.fm_copied;
    }
    kinds
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

/// Limit-point and edge-point weights of a smooth boundary vertex with `valence` edges (one
/// more than its faces) over `[vertex, ring…]` (`CatmarkLimits::ComputeBoundaryPointWeights`,
/// `far/catmarkPatchBuilder.cpp`). The position is the boundary B-spline's; the edge points
/// along interior edges mix the boundary tangent with an interior tangent of angle π/faces.
fn boundary_weights(valence: usize, face_in_ring: usize) -> [Vec<f64>; 3] {
    let num_faces = valence - 1;
    let theta = PI / num_faces as f64;
    let width = 2 * valence;
    let last = width - 1;

    let mut p = vec![0.0; width];
    p[0] = 4.0 / 6.0;
    p[1] = 1.0 / 6.0;
    p[last] = 1.0 / 6.0;

    let mut tan = vec![0.0; width];
    {
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
    }

    // An edge point along an interior edge at angle `edge·θ` from the leading boundary edge.
    let interior_edge_point = |edge: usize| {
        let (sin_a, cos_a) = (theta * edge as f64).sin_cos();
        let mut e: Vec<f64> = tan.iter().map(|t| t * sin_a).collect();
        e[0] += p[0];
        e[1] += p[1] + (1.0 / 6.0) * cos_a;
        e[last] += p[last] + (-1.0 / 6.0) * cos_a;
        e
    };
    let ep = if face_in_ring == 0 {
        let mut e = vec![0.0; width];
        e[0] = 2.0 / 3.0;
        e[1] = 1.0 / 3.0;
        e
    } else {
        interior_edge_point(face_in_ring)
    };
    let em = if face_in_ring == num_faces - 1 {
        let mut e = vec![0.0; width];
        e[0] = 2.0 / 3.0;
        e[last] = 1.0 / 3.0;
        e
    } else {
        interior_edge_point((face_in_ring + 1) % valence)
    };
    [p, ep, em]
}

/// Weights over `[vertex, ring…]` as a stencil on source points.
pub(super) fn ring_stencil(corner: usize, ring: &[usize], weights: &[f64]) -> Stencil {
    std::iter::once(corner).chain(ring.iter().copied()).zip(weights.iter().copied()).collect()
}

/// P, Ep and Em of a corner whose neighbourhood is regular: the B-spline patch's Bézier points
/// (`GregoryConverter::assignRegularEdgePoints`, `far/catmarkPatchBuilder.cpp`).
fn regular_edge_points(c: usize, kind: &CornerKind, ring: &[usize]) -> [Stencil; 3] {
    if !kind.boundary {
        let r = |k: usize| ring[k];
        let p = vec![
            (c, 4.0 / 9.0),
            (r(0), 1.0 / 9.0),
            (r(2), 1.0 / 9.0),
            (r(4), 1.0 / 9.0),
            (r(6), 1.0 / 9.0),
            (r(1), 1.0 / 36.0),
            (r(3), 1.0 / 36.0),
            (r(5), 1.0 / 36.0),
            (r(7), 1.0 / 36.0),
        ];
        let f = kind.face_in_ring;
        let (e_p, e_m) = (2 * f, 2 * ((f + 1) % 4));
        let (o_p, o_m) = (2 * ((f + 2) % 4), 2 * ((f + 3) % 4));
        let ep = vec![
            (c, 4.0 / 9.0),
            (r(e_p), 2.0 / 9.0),
            (r(e_m), 1.0 / 9.0),
            (r(o_m), 1.0 / 9.0),
            (r(e_p + 1), 1.0 / 18.0),
            (r(o_m + 1), 1.0 / 18.0),
        ];
        let em = vec![
            (c, 4.0 / 9.0),
            (r(e_m), 2.0 / 9.0),
            (r(e_p), 1.0 / 9.0),
            (r(o_p), 1.0 / 9.0),
            (r(e_p + 1), 1.0 / 18.0),
            (r(e_m + 1), 1.0 / 18.0),
        ];
        [p, ep, em]
    } else {
        let p = vec![(c, 2.0 / 3.0), (ring[0], 1.0 / 6.0), (ring[4], 1.0 / 6.0)];
        let along = if kind.ep_on_boundary { ring[0] } else { ring[4] };
        let on_boundary = vec![(c, 2.0 / 3.0), (along, 1.0 / 3.0)];
        let interior = vec![
            (c, 4.0 / 9.0),
            (ring[2], 2.0 / 9.0),
            (ring[0], 1.0 / 9.0),
            (ring[4], 1.0 / 9.0),
            (ring[1], 1.0 / 18.0),
            (ring[3], 1.0 / 18.0),
        ];
        if kind.ep_on_boundary {
            [p, on_boundary, interior]
        } else {
            [p, interior, on_boundary]
        }
    }
}

/// P, Ep and Em of an irregular corner (`GregoryConverter::computeIrregularEdgePoints` and
/// the two functions it calls, `far/catmarkPatchBuilder.cpp`).
fn irregular_edge_points(c: usize, kind: &CornerKind, ring: &[usize]) -> [Stencil; 3] {
    let (next, prev) = ((c + 1) % 4, (c + 3) % 4);
    // OpenSubdiv's stated approximation for sharp and one-face corners: edge points a third
    // of the way along the patch's own edges.
    let third_along = |to: usize| vec![(c, 2.0 / 3.0), (to, 1.0 / 3.0)];
    if kind.sharp {
        [vec![(c, 1.0)], third_along(next), third_along(prev)]
    } else if !kind.boundary {
        let [p, ep, em] = interior_weights(kind.valence, kind.face_in_ring);
        [ring_stencil(c, ring, &p), ring_stencil(c, ring, &ep), ring_stencil(c, ring, &em)]
    } else if kind.num_faces > 1 {
        let [p, ep, em] = boundary_weights(kind.valence, kind.face_in_ring);
        let last = p.len() - 1;
        let (first_nb, last_nb) = (ring[0], ring[2 * (kind.valence - 1)]);
        let p = vec![(c, p[0]), (first_nb, p[1]), (last_nb, p[last])];
        let ep = if kind.ep_on_boundary {
            vec![(c, ep[0]), (first_nb, ep[1])]
        } else {
            ring_stencil(c, ring, &ep)
        };
        // (OpenSubdiv's loop for this row runs one entry past the ring; the stray entry lands
        // in the next row's first slot, which is always overwritten, so it has no effect.)
        let em = if kind.em_on_boundary {
            vec![(c, em[0]), (last_nb, em[last])]
        } else {
            ring_stencil(c, ring, &em)
        };
        [p, ep, em]
    } else {
        // A smooth one-face corner (edge-only boundary): the boundary B-spline's position.
        let p = vec![(c, 4.0 / 6.0), (next, 1.0 / 6.0), (prev, 1.0 / 6.0)];
        [p, third_along(next), third_along(prev)]
    }
}

/// An irregular face point next to the edge point `e_near` of corner `near`
/// (`GregoryConverter::computeIrregularFacePoint`, `far/catmarkPatchBuilder.cpp`):
/// [`blend_face_point`] with `d = 3` and a correction `±(1/9, 1/18)` on the four ring points
/// beside the interior edge `edge`.
///
/// A correction outside the union of P, E_near and E_far's points is dropped (see
/// [`blend_face_point`]). That can only happen when `near` is sharp (P is the vertex alone)
/// and `far` is sharp or a one-face corner — not a configuration adaptive refinement produces
/// at level ≥ 1, and so not covered by OpenSubdiv's fixture — but it is reproduced here by
/// index.
#[allow(clippy::too_many_arguments)]
fn face_point(
    kinds: &[CornerKind; 4],
    rings: &[Vec<usize>; 4],
    num_points: usize,
    near: usize,
    edge: usize,
    far: usize,
    p: &Stencil,
    e_near: &Stencil,
    e_far: &Stencil,
    sign: f64,
) -> Stencil {
    let valence = kinds[near].valence;
    let ring = &rings[near];
    let (e_prev, e_next) = ((edge + valence - 1) % valence, (edge + 1) % valence);
    let corrections = [
        (ring[2 * e_prev], -sign / 9.0),
        (ring[2 * e_prev + 1], -sign / 18.0),
        (ring[2 * edge + 1], sign / 18.0),
        (ring[2 * e_next], sign / 9.0),
    ];
    blend_face_point(
        num_points,
        3.0,
        kinds[near].cos_face_angle,
        kinds[far].cos_face_angle,
        p,
        e_near,
        e_far,
        &corrections,
    )
}

/// The 20 stencils of a source patch over its [`SourceLayout`] numbering, in the module's
/// point order (`GregoryConverter::Convert`, `far/catmarkPatchBuilder.cpp`).
fn gregory_stencils(corners: &[GregoryCorner; 4], layout: &SourceLayout) -> Option<[Stencil; 20]> {
    let kinds = corner_kinds(corners);
    let rings = [0, 1, 2, 3].map(|i| layout.ring_indices(corners, i));
    let rings = [rings[0].clone()?, rings[1].clone()?, rings[2].clone()?, rings[3].clone()?];
    let mut rows: [Stencil; 20] = Default::default();

    // Corner and edge points first: face points combine those of neighbouring corners.
    for c in 0..4 {
        let [p, ep, em] = if kinds[c].regular {
            regular_edge_points(c, &kinds[c], &rings[c])
        } else {
            irregular_edge_points(c, &kinds[c], &rings[c])
        };
        rows[5 * c] = p;
        rows[5 * c + 1] = ep;
        rows[5 * c + 2] = em;
    }
    for c in 0..4 {
        let k = &kinds[c];
        let (next, opp, prev) = ((c + 1) % 4, (c + 2) % 4, (c + 3) % 4);
        // The bilinear-weighted face point of a regular B-spline neighbourhood.
        let regular = || vec![(c, 4.0 / 9.0), (prev, 2.0 / 9.0), (next, 2.0 / 9.0), (opp, 1.0 / 9.0)];
        if k.fp_regular {
            rows[5 * c + 3] = regular();
        }
        if k.fm_regular {
            rows[5 * c + 4] = regular();
        }
        if !k.fp_regular && !k.fp_copied {
            rows[5 * c + 3] = face_point(
                &kinds,
                &rings,
                layout.num_points,
                c,
                k.face_in_ring,
                next,
                &rows[5 * c],
                &rows[5 * c + 1],
                &rows[5 * next + 2],
                1.0,
            );
        }
        if !k.fm_regular && !k.fm_copied {
            rows[5 * c + 4] = face_point(
                &kinds,
                &rings,
                layout.num_points,
                c,
                (k.face_in_ring + 1) % k.valence,
                prev,
                &rows[5 * c],
                &rows[5 * c + 2],
                &rows[5 * prev + 1],
                -1.0,
            );
        }
        if k.fp_copied {
            rows[5 * c + 3] = rows[5 * c + 4].clone();
        }
        if k.fm_copied {
            rows[5 * c + 4] = rows[5 * c + 3].clone();
        }
    }
    Some(rows)
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
        for c in corners {
            assert!(
                c.num_faces >= 1 && c.patch_face < c.num_faces && c.ring.len() == c.expected_ring_len(),
                "inconsistent Gregory source corner"
            );
        }
        let layout = SourceLayout::new(corners).expect("Gregory source corners do not fit together");
        let stencils = gregory_stencils(corners, &layout).expect("Gregory source rings do not fit");
        let mut source_points = vec![DVec3::ZERO; layout.num_points];
        for (i, c) in corners.iter().enumerate() {
            source_points[i] = c.position;
        }
        for (i, c) in corners.iter().enumerate() {
            let indices = layout.ring_indices(corners, i).expect("checked by gregory_stencils");
            for (&index, &p) in indices.iter().zip(&c.ring) {
                source_points[index] = p;
            }
        }
        let points = stencils.map(|s| s.iter().map(|&(i, w)| source_points[i] * w).sum());
        GregoryPatch { points }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
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

    /// splitmix64, for reproducible jitter.
    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> f64 {
            self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        }
        fn jitter(&mut self) -> DVec3 {
            DVec3::new(self.next(), self.next(), self.next()) * 0.3
        }
    }

    /// An `n × n` quad grid with jittered vertices, vertex `(i, j)` at index `j·(n+1) + i`.
    fn grid(n: usize, seed: u64) -> Mesh {
        let mut rng = Rng(seed);
        let id = |i: usize, j: usize| j * (n + 1) + i;
        let pos = (0..(n + 1) * (n + 1))
            .map(|k| DVec3::new((k % (n + 1)) as f64, (k / (n + 1)) as f64, 0.0) + rng.jitter())
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
            *p += rng.jitter();
        }
        (Mesh::new(pos, faces), g)
    }

    /// The uniform cubic B-spline curve of four points at `t`.
    fn bspline(p: [DVec3; 4], t: f64) -> DVec3 {
        let tc = 1.0 - t;
        let w = [
            tc * tc * tc,
            3.0 * t * t * t - 6.0 * t * t + 4.0,
            -3.0 * t * t * t + 3.0 * t * t + 3.0 * t + 1.0,
            t * t * t,
        ];
        (p[0] * w[0] + p[1] * w[1] + p[2] * w[2] + p[3] * w[3]) / 6.0
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
