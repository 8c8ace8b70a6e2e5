//! What the Catmull-Clark ([`super::gregory`]) and Loop ([`super::loop_gregory`]) Gregory
//! converters share, because OpenSubdiv shares it:
//!
//! * the source patch: one class, `Far::SourcePatch` (`far/patchBuilder.cpp`), numbers the
//!   source points of quads and triangles alike ([`SourceLayout`]), so validation and the
//!   gathering of source points are one routine here;
//! * the corner topology and face-point flags, which `GregoryConverter::Initialize`
//!   (`far/catmarkPatchBuilder.cpp`) and `GregoryTriConverter::Initialize`
//!   (`far/loopPatchBuilder.cpp`) compute line for line alike but for the regular valence
//!   ([`corner_kinds`], [`FacePointFlags`]);
//! * the order in which both `Convert`s assemble corner, edge and face points, the dispatch of
//!   `computeIrregularEdgePoints` (the sharp corner's approximation is the same in both), the
//!   boundary vertex's position and edge points around its tangent (`ComputeBoundaryPointWeights`
//!   of `CatmarkLimits` and `LoopLimits`) and the irregular face point's blend
//!   ([`corner_and_face_points`], [`blend_face_point`]).
//!
//! What differs between the two files stays with each converter, behind [`SchemeCorner`]: the
//! limit masks and tangents (Catmull-Clark's eigenvalue table against Loop's Sdc masks), the
//! test for an edge point on the trailing boundary edge (Loop's never holds), the regular
//! points (B-spline against box spline), the face-point corrections and, for triangles only,
//! the mid-edge points and the promotion to quartic.

use super::gregory::GregorySourceError;
use glam::DVec3;
use std::f64::consts::PI;

/// A patch point as a combination of source points: (source index, weight), repeats allowed.
pub(super) type Stencil = Vec<(usize, f64)>;

/// The topology of one corner's fan, the fields of `SourcePatch::Corner` that the shared rules
/// read.
#[derive(Clone, Copy)]
pub(super) struct Fan {
    pub num_faces: usize,
    pub patch_face: usize,
    pub boundary: bool,
    pub sharp: bool,
    pub dart: bool,
}

impl Fan {
    /// Edges at the corner vertex within its fan (OpenSubdiv's corner "valence").
    pub(super) fn valence(self) -> usize {
        self.num_faces + usize::from(self.boundary)
    }

    /// OpenSubdiv's valence-2 interior flag (`SourcePatch::Finalize`): two faces, no boundary.
    pub(super) fn is_val2_interior(self) -> bool {
        self.num_faces == 2 && !self.boundary
    }

    /// Face counts a source patch can have: at least one face, the patch face among them, and
    /// two or more faces around an interior vertex.
    fn is_possible(self) -> bool {
        self.num_faces > 0 && self.patch_face < self.num_faces && (self.num_faces > 1 || self.boundary)
    }
}

/// A corner type of one subdivision scheme ([`GregoryCorner`](super::gregory::GregoryCorner),
/// [`LoopCorner`](super::loop_gregory::LoopCorner)) with the rules of its converter that are
/// its own. The shared code is generic over the corner count `N` (4 or 3) as well.
pub(super) trait SchemeCorner: Sized {
    /// Ring points each face of the fan adds: a quad its leading edge's far end and its
    /// diagonal, a triangle only the far end.
    const RING_POINTS_PER_FACE: usize;
    /// Faces around a regular interior vertex (half as many on a regular boundary).
    const REGULAR_FACES: usize;
    /// The cosine of a regular corner's face angle, taken exactly rather than rounded.
    const REGULAR_COS_FACE_ANGLE: f64;
    /// The `d` of [`blend_face_point`].
    const FACE_POINT_DENOMINATOR: f64;
    /// Whether the cubic edge rows of irregular boundary and one-face corners keep their
    /// zero-weight entries. Loop's converter writes rows of a fixed size, which its quartic
    /// promotion reweights by position; Catmull-Clark's leaves the zeros out. The difference
    /// is not cosmetic: an entry, even of weight 0, lets a face-point correction on that
    /// point survive (see [`blend_face_point`]).
    const KEEPS_ZERO_ENTRIES: bool;

    fn fan(&self) -> Fan;
    fn position(&self) -> DVec3;
    fn ring(&self) -> &[DVec3];

    /// Limit-point weights of a smooth interior vertex over `[vertex, ring…]` and the edge
    /// points along the patch face's leading and trailing edges. The two implementations have
    /// the same outline (a limit position plus a tangent rotated onto each edge) but not the
    /// same rule — `CatmarkLimits` gathers three cosine terms per edge under a tabulated
    /// eigenvalue scale, `LoopLimits` takes Sdc's first tangent with an exact valence-6 mask —
    /// so only the outline's callers are shared, not the weights.
    fn interior_weights(valence: usize, face_in_ring: usize) -> [Vec<f64>; 3];
    /// The interior tangent of a smooth boundary vertex with `valence` edges over
    /// `[vertex, ring…]`, as [`boundary_weights`] mixes it into the edge points.
    fn boundary_tangent(valence: usize) -> Vec<f64>;
    /// `ComputeBoundaryPointWeights`'s test for an Em on the trailing boundary edge.
    fn em_on_trailing_edge(valence: usize, face_in_ring: usize) -> bool;
    /// P, Ep and Em of a corner whose neighbourhood is regular.
    fn regular_edge_points(c: usize, kind: &CornerKind, ring: &[usize]) -> [Stencil; 3];
    /// The regular face point of corner `c` (the same for Fp and Fm).
    fn regular_face_point(c: usize, kind: &CornerKind, ring: &[usize]) -> Stencil;
    /// The irregular face point's correction on the ring points beside the interior edge
    /// `edge` of a corner's `ring`, given as `[e_prev, edge, e_next]` with its neighbours.
    fn face_point_corrections(ring: &[usize], edges: [usize; 3], sign: f64) -> Stencil;

    /// The ring length this corner's fan implies.
    fn implied_ring_len(&self) -> usize {
        let fan = self.fan();
        Self::RING_POINTS_PER_FACE * fan.num_faces + usize::from(fan.boundary)
    }
}

/// The accessors of [`SchemeCorner`] for a corner struct with the fields `position`,
/// `num_faces`, `patch_face`, `boundary`, `sharp`, `dart` and `ring`, which both corner types
/// have by design.
macro_rules! corner_fields {
    () => {
        fn fan(&self) -> super::gregory_shared::Fan {
            super::gregory_shared::Fan {
                num_faces: self.num_faces,
                patch_face: self.patch_face,
                boundary: self.boundary,
                sharp: self.sharp,
                dart: self.dart,
            }
        }

        fn position(&self) -> glam::DVec3 {
            self.position
        }

        fn ring(&self) -> &[glam::DVec3] {
            &self.ring
        }
    };
}
pub(super) use corner_fields;

/// Checks that the corners describe one leaf consistently: fan counts, ring lengths, that the
/// fans fit together as OpenSubdiv numbers the source points, and that every point shared by
/// two rings (or a ring and a corner) is the same point. Exact equality is required, as both
/// copies come from the same mesh vertex. Cost: linear in the total ring length.
pub(super) fn validate<C: SchemeCorner, const N: usize>(corners: &[C; N]) -> Result<(), GregorySourceError> {
    for (i, c) in corners.iter().enumerate() {
        if !c.fan().is_possible() {
            return Err(GregorySourceError::BadFan { corner: i });
        }
        if c.ring().len() != c.implied_ring_len() {
            return Err(GregorySourceError::RingLength {
                corner: i,
                len: c.ring().len(),
                expected: c.implied_ring_len(),
            });
        }
    }
    let layout = SourceLayout::new(corners).ok_or(GregorySourceError::Layout)?;
    let mut seen: Vec<Option<DVec3>> = vec![None; layout.num_points];
    for (i, c) in corners.iter().enumerate() {
        seen[i] = Some(c.position());
    }
    for (i, c) in corners.iter().enumerate() {
        let indices = layout.ring_indices(corners, i).ok_or(GregorySourceError::Layout)?;
        for (k, (&index, &p)) in indices.iter().zip(c.ring()).enumerate() {
            match seen[index] {
                Some(q) if q != p => return Err(GregorySourceError::Mismatch { corner: i, ring_index: k }),
                _ => seen[index] = Some(p),
            }
        }
    }
    Ok(())
}

/// The layout of a source the converters are about to use, panicking (with `what` for the
/// scheme) where [`validate`] would fail on fan counts, ring lengths or layout.
pub(super) fn checked_layout<C: SchemeCorner, const N: usize>(
    corners: &[C; N],
    what: &str,
) -> SourceLayout<N> {
    for c in corners {
        let f = c.fan();
        // Unlike `validate`, an interior fan of one face is let through, as before the
        // converters shared this check.
        assert!(
            f.num_faces >= 1 && f.patch_face < f.num_faces && c.ring().len() == c.implied_ring_len(),
            "inconsistent {what} source corner"
        );
    }
    SourceLayout::new(corners).unwrap_or_else(|| panic!("{what} source corners do not fit together"))
}

/// The source points of a consistent source, in [`SourceLayout`] numbering.
pub(super) fn source_points<C: SchemeCorner, const N: usize>(
    corners: &[C; N],
    layout: &SourceLayout<N>,
) -> Vec<DVec3> {
    let mut points = vec![DVec3::ZERO; layout.num_points];
    for (i, c) in corners.iter().enumerate() {
        points[i] = c.position();
    }
    for (i, c) in corners.iter().enumerate() {
        let indices = layout.ring_indices(corners, i).expect("checked by the converter");
        for (&index, &p) in indices.iter().zip(c.ring()) {
            points[index] = p;
        }
    }
    points
}

/// OpenSubdiv's numbering of a source patch's distinct points (`SourcePatch::Finalize` and
/// `SourcePatch::GetCornerRingPoints`, `far/patchBuilder.cpp`, one routine for quads and
/// triangles): the `N` corners, then each corner's ring points not shared with a neighbour.
/// The numbering matters beyond bookkeeping: an irregular face point keeps a ring point's
/// contribution only if that point already contributes to the corner and edge points it is
/// built from, so which ring slots are the *same* point decides the result (see
/// [`blend_face_point`]).
pub(super) struct SourceLayout<const N: usize> {
    pub num_points: usize,
    ring_sizes: [usize; N],
    local_sizes: [usize; N],
    local_offsets: [usize; N],
    shares_prev: [bool; N],
    shares_next: [bool; N],
    val2: [bool; N],
}

impl<const N: usize> SourceLayout<N> {
    const IS_QUAD: bool = N == 4;

    /// Sizes the rings and numbers the local points; `None` if the fans do not fit.
    pub(super) fn new<C: SchemeCorner>(corners: &[C; N]) -> Option<Self> {
        let fans = corners.each_ref().map(C::fan);
        let val2 = fans.map(Fan::is_val2_interior);
        let mut layout = SourceLayout {
            num_points: N,
            ring_sizes: [0; N],
            local_sizes: [0; N],
            local_offsets: [0; N],
            shares_prev: [false; N],
            shares_next: [false; N],
            val2,
        };
        for i in 0..N {
            let (prev, next) = ((i + N - 1) % N, (i + 1) % N);
            let c = fans[i];
            let ring = C::RING_POINTS_PER_FACE * c.num_faces + usize::from(c.boundary);
            if c.valence() > 2 {
                // A ring shares its first point past the previous corner with that corner's
                // ring, and its last point before the next corner with the next one's, unless
                // a boundary (or a dart's sharp edge) separates them. A triangle's ring never
                // shares its first point: OpenSubdiv keeps the local points asymmetric.
                let (share_prev, share_next) = if c.boundary {
                    (c.patch_face != c.num_faces - 1, c.patch_face != 0)
                } else if c.dart {
                    let (p, n) = (fans[prev], fans[next]);
                    let prev_on_dart_edge = p.boundary && p.patch_face == 0;
                    let next_on_dart_edge = n.boundary && n.patch_face + 1 == n.num_faces;
                    (!prev_on_dart_edge, !next_on_dart_edge)
                } else {
                    (true, true)
                };
                let share_prev = share_prev && Self::IS_QUAD;
                layout.shares_prev[i] = share_prev;
                layout.shares_next[i] = share_next;
                // A valence-2 neighbour puts another corner into this ring a second time (for
                // a triangle, only the previous neighbour does).
                let taken = (N - 1)
                    + usize::from(share_prev)
                    + usize::from(share_next)
                    + usize::from(val2[prev])
                    + usize::from(val2[next] && Self::IS_QUAD);
                layout.ring_sizes[i] = ring;
                layout.local_sizes[i] = ring.checked_sub(taken)?;
            } else if c.num_faces == 1 {
                // A one-face corner's ring is the other corners.
                layout.ring_sizes[i] = N - 1;
                layout.local_sizes[i] = 0;
            } else {
                // A valence-2 interior corner's ring is the other corners and, for a quad, the
                // diagonal of its other face.
                layout.ring_sizes[i] = ring;
                layout.local_sizes[i] = ring - (N - 1);
            }
            layout.local_offsets[i] = layout.num_points;
            layout.num_points += layout.local_sizes[i];
        }
        Some(layout)
    }

    /// The source-point indices of corner `i`'s ring, in ring order; `None` if the pieces do
    /// not add up to the ring's size.
    pub(super) fn ring_indices<C: SchemeCorner>(&self, corners: &[C; N], i: usize) -> Option<Vec<usize>> {
        let (next, prev) = ((i + 1) % N, (i + N - 1) % N);
        let opp = (i + 2) % N;
        // Assembled as if the patch face were face 0: the other corners, then the points
        // shared with the previous corner, the local points, those shared with the next one.
        let mut ring = vec![next];
        if Self::IS_QUAD {
            ring.push(opp);
        }
        ring.push(prev);
        if self.val2[prev] {
            ring.push(if Self::IS_QUAD { opp } else { next });
        }
        if self.shares_prev[i] {
            ring.push(self.local_offsets[prev] + self.local_sizes[prev] - 1);
        }
        ring.extend(self.local_offsets[i]..self.local_offsets[i] + self.local_sizes[i]);
        if Self::IS_QUAD {
            if self.shares_next[i] {
                ring.push(self.local_offsets[next]);
            }
            if self.val2[next] {
                ring.push(opp);
            }
        } else if self.shares_next[i] {
            if self.val2[next] {
                ring.push(prev);
            } else if self.local_sizes[next] == 0 {
                // The next corner has no points of its own (valence 3): the vertex across
                // the edge is also across its other edge, so it is the previous corner's first.
                if self.local_sizes[prev] == 0 {
                    return None;
                }
                ring.push(self.local_offsets[prev]);
            } else {
                ring.push(self.local_offsets[next]);
            }
        }
        if ring.len() != self.ring_sizes[i] {
            return None;
        }
        let rotation = (ring.len() - C::RING_POINTS_PER_FACE * corners[i].fan().patch_face) % ring.len();
        ring.rotate_left(rotation);
        Some(ring)
    }

    /// Every corner's [`ring_indices`](Self::ring_indices).
    pub(super) fn rings<C: SchemeCorner>(&self, corners: &[C; N]) -> Option<[Vec<usize>; N]> {
        let rings: Vec<Vec<usize>> = (0..N).map(|i| self.ring_indices(corners, i)).collect::<Option<_>>()?;
        rings.try_into().ok()
    }
}

/// How a corner's two edge points and two face points relate to the patch's boundary and to
/// its neighbours' regularity (the second pass of `GregoryConverter::Initialize`,
/// `far/catmarkPatchBuilder.cpp`, and of `GregoryTriConverter::Initialize`,
/// `far/loopPatchBuilder.cpp`).
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
    fn new(boundary: bool, num_faces: usize, face_in_ring: usize, regular: [bool; 3]) -> Self {
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

/// What the converters need of each corner (`CornerTopology` of `GregoryConverter` and of
/// `GregoryTriConverter`), including how its face points relate to its neighbours.
#[derive(Clone, Copy)]
pub(super) struct CornerKind {
    pub boundary: bool,
    pub sharp: bool,
    pub regular: bool,
    pub valence: usize,
    pub num_faces: usize,
    pub face_in_ring: usize,
    pub cos_face_angle: f64,
    pub flags: FacePointFlags,
}

/// The [`CornerKind`]s of a source's corners (`Initialize` of either converter).
pub(super) fn corner_kinds<C: SchemeCorner, const N: usize>(corners: &[C; N]) -> [CornerKind; N] {
    let fans = corners.each_ref().map(C::fan);
    let regular = fans.map(|f| (f.num_faces << usize::from(f.boundary)) == C::REGULAR_FACES && !f.sharp);
    std::array::from_fn(|i| {
        let f = fans[i];
        let cos_face_angle = if regular[i] {
            C::REGULAR_COS_FACE_ANGLE
        } else {
            let sweep = if f.boundary { PI } else { 2.0 * PI };
            (sweep / f.num_faces as f64).cos()
        };
        CornerKind {
            boundary: f.boundary,
            sharp: f.sharp,
            regular: regular[i],
            valence: f.valence(),
            num_faces: f.num_faces,
            face_in_ring: f.patch_face,
            cos_face_angle,
            flags: FacePointFlags::new(
                f.boundary,
                f.num_faces,
                f.patch_face,
                [regular[i], regular[(i + 1) % N], regular[(i + N - 1) % N]],
            ),
        }
    })
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

/// Weights over `[vertex, ring…]` as a stencil on source points.
pub(super) fn ring_stencil(corner: usize, ring: &[usize], weights: &[f64]) -> Stencil {
    std::iter::once(corner).chain(ring.iter().copied()).zip(weights.iter().copied()).collect()
}

/// Limit-point and edge-point weights of a smooth boundary vertex with `valence` edges (one
/// more than its faces) over `[vertex, ring…]` (`ComputeBoundaryPointWeights` of
/// `CatmarkLimits` and of `LoopLimits`, which differ only in the tangent and the trailing-edge
/// test): the boundary B-spline's position (⅙, ⅔, ⅙), and an edge point along an interior edge
/// at angle `a` from the leading boundary edge mixes `cos a` times the boundary tangent (±⅙ on
/// the two boundary neighbours) with `sin a` times the scheme's interior tangent.
fn boundary_weights<C: SchemeCorner>(valence: usize, face_in_ring: usize) -> [Vec<f64>; 3] {
    let tangent = C::boundary_tangent(valence);
    let width = tangent.len();
    let last = width - 1;
    let mut p = vec![0.0; width];
    p[0] = 4.0 / 6.0;
    p[1] = 1.0 / 6.0;
    p[last] = 1.0 / 6.0;

    let face_angle = PI / (valence - 1) as f64;
    let interior_edge_point = |edge: usize| {
        let angle = face_angle * edge as f64;
        let (sin_a, cos_a) = (angle.sin(), angle.cos());
        let mut e: Vec<f64> = tangent.iter().map(|t| t * sin_a).collect();
        e[0] += p[0];
        e[1] += p[1] + (1.0 / 6.0) * cos_a;
        e[last] += p[last] + (-1.0 / 6.0) * cos_a;
        e
    };
    let on_boundary = |end: usize| {
        let mut e = vec![0.0; width];
        e[0] = 2.0 / 3.0;
        e[end] = 1.0 / 3.0;
        e
    };
    let ep = if face_in_ring == 0 { on_boundary(1) } else { interior_edge_point(face_in_ring) };
    let em = if C::em_on_trailing_edge(valence, face_in_ring) {
        on_boundary(last)
    } else {
        interior_edge_point((face_in_ring + 1) % valence)
    };
    [p, ep, em]
}

/// P, Ep and Em of an irregular corner (`computeIrregularEdgePoints` of either converter,
/// whose branches are the same; the limit weights they call are the scheme's).
fn irregular_edge_points<C: SchemeCorner, const N: usize>(
    c: usize,
    kind: &CornerKind,
    ring: &[usize],
) -> [Stencil; 3] {
    let (next, prev) = ((c + 1) % N, (c + N - 1) % N);
    let zero = |row: &mut Stencil, i: usize| {
        if C::KEEPS_ZERO_ENTRIES {
            row.push((i, 0.0));
        }
    };
    if kind.sharp {
        // OpenSubdiv's stated approximation: edge points a third of the way along the
        // patch's own edges.
        [vec![(c, 1.0)], vec![(c, 2.0 / 3.0), (next, 1.0 / 3.0)], vec![(c, 2.0 / 3.0), (prev, 1.0 / 3.0)]]
    } else if !kind.boundary {
        let [p, ep, em] = C::interior_weights(kind.valence, kind.face_in_ring);
        [ring_stencil(c, ring, &p), ring_stencil(c, ring, &ep), ring_stencil(c, ring, &em)]
    } else if kind.num_faces > 1 {
        let [p, ep, em] = boundary_weights::<C>(kind.valence, kind.face_in_ring);
        let last = p.len() - 1;
        let (first_nb, last_nb) = (ring[0], ring[last - 1]);
        let p = vec![(c, p[0]), (first_nb, p[1]), (last_nb, p[last])];
        let ep = if kind.flags.ep_on_boundary {
            let mut row = vec![(c, ep[0]), (first_nb, ep[1])];
            zero(&mut row, last_nb);
            row
        } else {
            ring_stencil(c, ring, &ep)
        };
        // (Catmull-Clark's loop for this row runs one entry past the ring; the stray entry
        // lands in the next row's first slot, which is always overwritten, so it has no
        // effect.)
        let em = if kind.flags.em_on_boundary {
            let mut row = vec![(c, em[0]), (last_nb, em[last])];
            zero(&mut row, first_nb);
            row
        } else {
            ring_stencil(c, ring, &em)
        };
        [p, ep, em]
    } else {
        // A smooth one-face corner (edge-only boundary): the boundary B-spline's position and
        // the sharp corner's edge points.
        let mut ep = vec![(c, 2.0 / 3.0), (next, 1.0 / 3.0)];
        zero(&mut ep, prev);
        let mut em = vec![(c, 2.0 / 3.0), (prev, 1.0 / 3.0)];
        zero(&mut em, next);
        [vec![(c, 4.0 / 6.0), (next, 1.0 / 6.0), (prev, 1.0 / 6.0)], ep, em]
    }
}

/// The `5N` corner, edge and face points, corner `i`'s at `5i..5i+5` (P, Ep, Em, Fp, Fm), in
/// the order both `Convert`s compute them: corner and edge points first, as face points
/// combine those of neighbouring corners. Triangles then add their mid-edge points and raise
/// the edge points to quartic.
pub(super) fn corner_and_face_points<C: SchemeCorner, const N: usize>(
    kinds: &[CornerKind; N],
    rings: &[Vec<usize>; N],
    num_points: usize,
) -> Vec<Stencil> {
    let mut rows = vec![Stencil::new(); 5 * N];
    for c in 0..N {
        let [p, ep, em] = if kinds[c].regular {
            C::regular_edge_points(c, &kinds[c], &rings[c])
        } else {
            irregular_edge_points::<C, N>(c, &kinds[c], &rings[c])
        };
        rows[5 * c] = p;
        rows[5 * c + 1] = ep;
        rows[5 * c + 2] = em;
    }
    // The irregular face point next to the edge point `e_near` of corner `near`, whose
    // interior edge `edge` it lies beside (`computeIrregularFacePoint`).
    let face_point =
        |rows: &[Stencil], near: usize, edge: usize, far: usize, e_near: usize, e_far: usize, sign: f64| {
            let kind = &kinds[near];
            let (e_prev, e_next) = ((edge + kind.valence - 1) % kind.valence, (edge + 1) % kind.valence);
            let corrections = C::face_point_corrections(&rings[near], [e_prev, edge, e_next], sign);
            blend_face_point(
                num_points,
                C::FACE_POINT_DENOMINATOR,
                kind.cos_face_angle,
                kinds[far].cos_face_angle,
                &rows[5 * near],
                &rows[e_near],
                &rows[e_far],
                &corrections,
            )
        };
    for c in 0..N {
        let k = &kinds[c];
        let f = k.flags;
        let (next, prev) = ((c + 1) % N, (c + N - 1) % N);
        if f.fp_regular {
            rows[5 * c + 3] = C::regular_face_point(c, k, &rings[c]);
        }
        if f.fm_regular {
            rows[5 * c + 4] = C::regular_face_point(c, k, &rings[c]);
        }
        if !f.fp_regular && !f.fp_copied {
            rows[5 * c + 3] = face_point(&rows, c, k.face_in_ring, next, 5 * c + 1, 5 * next + 2, 1.0);
        }
        if !f.fm_regular && !f.fm_copied {
            let edge = (k.face_in_ring + 1) % k.valence;
            rows[5 * c + 4] = face_point(&rows, c, edge, prev, 5 * c + 2, 5 * prev + 1, -1.0);
        }
        if f.fp_copied {
            rows[5 * c + 3] = rows[5 * c + 4].clone();
        }
        if f.fm_copied {
            rows[5 * c + 4] = rows[5 * c + 3].clone();
        }
    }
    rows
}

/// The points of a patch: each stencil applied to the source points.
pub(super) fn apply<const M: usize>(stencils: &[Stencil; M], points: &[DVec3]) -> [DVec3; M] {
    stencils.each_ref().map(|s| s.iter().map(|&(i, w)| points[i] * w).sum())
}

/// splitmix64, for reproducible test points in both converters' tests.
#[cfg(test)]
pub(super) struct Rng(pub u64);

#[cfg(test)]
impl Rng {
    /// Uniform in [−½, ½).
    pub(super) fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    }

    /// A point with coordinates uniform in [−scale/2, scale/2).
    pub(super) fn point(&mut self, scale: f64) -> DVec3 {
        DVec3::new(self.next(), self.next(), self.next()) * scale
    }
}

/// The uniform cubic B-spline curve of four points at `t`, which both converters' boundary
/// curves must follow.
#[cfg(test)]
pub(super) fn bspline(p: [DVec3; 4], t: f64) -> DVec3 {
    let tc = 1.0 - t;
    let w = [
        tc * tc * tc,
        3.0 * t * t * t - 6.0 * t * t + 4.0,
        -3.0 * t * t * t + 3.0 * t * t + 3.0 * t + 1.0,
        t * t * t,
    ];
    (p[0] * w[0] + p[1] * w[1] + p[2] * w[2] + p[3] * w[3]) / 6.0
}
