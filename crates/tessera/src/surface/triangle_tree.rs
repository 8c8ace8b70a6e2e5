//! Piecewise patches of Loop subdivision surfaces: the leaves of a triangle's
//! feature-adaptive isolation (quartic Bézier pieces of the regular box splines and Gregory
//! triangle end caps) in a triangle quadtree, evaluated as OpenSubdiv's Bfr evaluates its
//! `PatchTree` for triangles (`bfr/patchTree.cpp`). Built by
//! [`crate::subdivision::loop_isolation`].
//!
//! **The quadtree.** A node covers a triangle of its square `origin + [0, size]²`: *upright*,
//! the lower-left half (corners `origin`, `origin + (size, 0)`, `origin + (0, size)`), or
//! *turned* by 180°, the upper-right half (its right-angle corner at `origin + (size, size)`).
//! Its children, by Bfr's quadrant numbers: 0, 1, 2 the triangles at its own corners 0, 1, 2
//! (upright for an upright node, turned for a turned one), and 3 the middle triangle, turned
//! the other way. A leaf's own parameters `st` are measured from its right-angle corner along
//! its legs, so a turned leaf's `st` run against the face's `uv` and its derivatives change
//! sign (`Far::PatchParam::NormalizeTriangle`, `Far::internal::EvaluatePatchBasis`).
//!
//! **Bfr's search, quirk included.** [`TriangleTree::find`] walks the nodes as
//! `bfr/patchTree.cpp` does, including where that walk differs from the geometry: Bfr's copy
//! of `transformUVToTriQuadrant` keeps its "turned" flag set when it takes the middle child of
//! a turned node (upright), where `far/patchMap.h`'s original clears it. A point whose path
//! takes the middle child twice and goes deeper is then sent to a neighbouring leaf, whose
//! polynomial is evaluated a little outside its triangle. The surfaces of neighbouring leaves
//! agree to the isolation's accuracy there, and tessera follows Bfr so that its points are
//! Bfr's (the oracle of issue 28); see `tools/osd-oracle/NOTES.md`, section 10.

use glam::{DVec2, DVec3};

use super::{GregoryTriangle, QuarticTriangle, SurfaceDerivatives};

/// One leaf of a triangle's patch tree.
#[derive(Debug, Clone, PartialEq)]
pub struct TriangleLeaf {
    /// The lower-left corner of the leaf's square.
    pub origin: DVec2,
    /// The square's side, `2^-level`.
    pub size: f64,
    /// The refinement level the leaf was made at (0: the face itself).
    pub level: u8,
    /// The leaf is the upper-right half of its square (module doc).
    pub turned: bool,
    pub patch: TriangleLeafPatch,
}

/// A leaf's square and turn ([`TriangleLeaf`]'s `origin`, `size`, `turned`) in 16 bytes. f32
/// holds them exactly: the origin's coordinates are multiples of the size, a power of two no
/// smaller than 2^-24 (isolation stops far above that depth).
#[derive(Debug, Clone, Copy, PartialEq)]
struct LeafFrame {
    origin: [f32; 2],
    size: f32,
    turned: bool,
}

impl LeafFrame {
    fn of(leaf: &TriangleLeaf) -> LeafFrame {
        let frame = LeafFrame {
            origin: [leaf.origin.x as f32, leaf.origin.y as f32],
            size: leaf.size as f32,
            turned: leaf.turned,
        };
        debug_assert_eq!(
            (DVec2::new(frame.origin[0].into(), frame.origin[1].into()), f64::from(frame.size)),
            (leaf.origin, leaf.size),
            "a leaf's square in f32 exactly"
        );
        frame
    }

    /// `uv` (the tree's own, not swapped) in the leaf's parameters, as
    /// `(uv - origin) / size` in f64 (from the upper-right corner where turned).
    #[inline(always)]
    fn st(&self, uv: DVec2) -> DVec2 {
        let origin = DVec2::new(self.origin[0].into(), self.origin[1].into());
        let size = f64::from(self.size);
        if self.turned {
            (origin + DVec2::splat(size) - uv) / size
        } else {
            (uv - origin) / size
        }
    }
}

/// The surface over a leaf.
#[derive(Debug, Clone, PartialEq)]
// Quartic leaves are nearly all the leaves: inline, so evaluating one reads one block.
#[allow(clippy::large_enum_variant)]
pub enum TriangleLeafPatch {
    /// A regular piece: its box spline as a quartic Bézier triangle.
    Quartic(QuarticTriangle),
    /// An end cap. Boxed: end caps are few, and inline every leaf would take their size.
    Gregory(Box<GregoryTriangle>),
}

impl TriangleLeafPatch {
    /// The piece's points: a quartic triangle's 15, or a Gregory triangle's 18.
    pub fn points(&self) -> &[DVec3] {
        match self {
            TriangleLeafPatch::Quartic(q) => &q.points,
            TriangleLeafPatch::Gregory(g) => &g.points,
        }
    }

    /// Position and derivatives with respect to the leaf's own parameters.
    fn derivatives(&self, st: DVec2) -> SurfaceDerivatives {
        match self {
            TriangleLeafPatch::Quartic(q) => q.derivatives(st),
            TriangleLeafPatch::Gregory(g) => g.derivatives(st),
        }
    }
}

/// A child slot of a node: another node or a leaf, by index.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum TriangleSlot {
    Node(u32),
    Leaf(u32),
}

/// The piecewise surface over one triangle of a Loop cage, with parameters in the triangle
/// `u, v ≥ 0, u + v ≤ 1`: the leaves of its isolation and the quadtree that finds the leaf of
/// a parameter point, as Bfr's `PatchTree` does.
#[derive(Debug, Clone, PartialEq)]
pub struct TriangleTree {
    leaves: std::sync::Arc<[TriangleLeaf]>,
    /// Each leaf's square and turn apart from its net, what [`TriangleTree::find`] reads:
    /// a tree's frames share a few cache lines, where the leaves' own fields sit one in each
    /// leaf's 400 bytes (a profile of `loop_xord_interior` at factor 16 had two thirds of
    /// the search's samples on that one load).
    frames: std::sync::Arc<[LeafFrame]>,
    nodes: std::sync::Arc<[[TriangleSlot; 4]]>,
    root: TriangleSlot,
    /// `u` and `v` are exchanged on the way in and out: the surface with the opposite
    /// orientation ([`TriangleTree::swapped`]).
    swapped: bool,
    /// The bounding box of the leaves' points (the surface lies in their convex hull).
    hull: [DVec3; 8],
}

impl TriangleTree {
    /// A tree of `leaves` with quadtree `nodes` under `root` (children by Bfr's quadrant
    /// numbers, module doc). Precondition: the leaves tile the unit triangle as the nodes
    /// say. Cost: O(leaves).
    pub(crate) fn from_parts(
        leaves: Vec<TriangleLeaf>,
        nodes: Vec<[TriangleSlot; 4]>,
        root: TriangleSlot,
    ) -> Self {
        let hull = super::box_corners(leaves.iter().flat_map(|l| l.patch.points()));
        let frames = leaves.iter().map(LeafFrame::of).collect();
        TriangleTree { leaves: leaves.into(), frames, nodes: nodes.into(), root, swapped: false, hull }
    }

    /// The leaves.
    pub fn leaves(&self) -> &[TriangleLeaf] {
        &self.leaves
    }

    /// The corners of the bounding box of every leaf's points: the surface lies in their
    /// convex hull.
    pub fn control_points(&self) -> &[DVec3] {
        &self.hull
    }

    /// The quadtree as plain rows, for an engine that walks it itself (the GPU's): the root
    /// slot and each node's four child slots by Bfr's quadrant numbers (module doc), a slot
    /// being a node index or [`LEAF_SLOT`](super::patch_tree::LEAF_SLOT) `|` a leaf index
    /// into [`TriangleTree::leaves`]. The walk must be [`TriangleTree::find`]'s, quirk
    /// included. Cost: O(nodes).
    pub fn quadtree(&self) -> (u32, Vec<[u32; 4]>) {
        let code = |s: TriangleSlot| match s {
            TriangleSlot::Node(n) => n,
            TriangleSlot::Leaf(l) => super::patch_tree::LEAF_SLOT | l,
        };
        (code(self.root), self.nodes.iter().map(|n| n.map(code)).collect())
    }

    /// An identity of the tree's leaves: equal for a tree and its [`TriangleTree::swapped`]
    /// copies, so that an engine stores them once.
    pub fn leaves_id(&self) -> usize {
        self.leaves.as_ptr() as usize
    }

    /// Appends every leaf's points to `out`, leaf by leaf (a quartic leaf's 15, a Gregory
    /// leaf's 18). Cost: O(leaves).
    pub fn leaf_points(&self, out: &mut Vec<DVec3>) {
        for leaf in self.leaves.iter() {
            out.extend_from_slice(leaf.patch.points());
        }
    }

    /// How many points [`TriangleTree::leaf_points`] appends.
    pub fn leaf_point_count(&self) -> usize {
        self.leaves.iter().map(|l| l.patch.points().len()).sum()
    }

    /// The same tree (nodes, leaves' places and kinds, [`TriangleTree::is_swapped`]) with leaf
    /// points `points`, in [`TriangleTree::leaf_points`] order, and their hull: the surface of
    /// a moved cage. Precondition: `points.len()` is [`TriangleTree::leaf_point_count`].
    /// Cost: O(leaves).
    pub fn with_leaf_points(&self, points: &[DVec3]) -> TriangleTree {
        assert_eq!(points.len(), self.leaf_point_count(), "one point per leaf point");
        let mut next = points.iter().copied();
        let mut take = || next.next().expect("counted above");
        let leaves: Vec<TriangleLeaf> = self
            .leaves
            .iter()
            .map(|leaf| TriangleLeaf {
                patch: match &leaf.patch {
                    TriangleLeafPatch::Quartic(_) => TriangleLeafPatch::Quartic(QuarticTriangle {
                        points: std::array::from_fn(|_| take()),
                    }),
                    TriangleLeafPatch::Gregory(_) => TriangleLeafPatch::Gregory(Box::new(GregoryTriangle {
                        points: std::array::from_fn(|_| take()),
                    })),
                },
                ..*leaf
            })
            .collect();
        TriangleTree {
            hull: super::box_corners(leaves.iter().flat_map(|l| l.patch.points())),
            leaves: leaves.into(),
            ..self.clone()
        }
    }

    /// Whether `u` and `v` are exchanged ([`TriangleTree::swapped`]).
    pub fn is_swapped(&self) -> bool {
        self.swapped
    }

    /// The same surface with `u` and `v` exchanged: the opposite orientation.
    pub fn swapped(&self) -> TriangleTree {
        TriangleTree { swapped: !self.swapped, ..self.clone() }
    }

    /// The leaf Bfr's search finds for `uv` (module doc: its quirk included), and `uv` in
    /// that leaf's own parameters. Points on a border between leaves go where Bfr's
    /// comparisons send them. Cost: O(depth). Inlined: a call per point took `loop_xord_interior`
    /// × 725's vertex stage 7 % longer at factor 16.
    #[inline(always)]
    pub fn find(&self, uv: DVec2) -> (usize, DVec2) {
        let uv = if self.swapped { DVec2::new(uv.y, uv.x) } else { uv };
        let (mut u, mut v) = (uv.x, uv.y);
        let mut slot = self.root;
        let mut median = 0.5;
        // Bfr's flag, which is not always the node's own orientation (module doc).
        let mut turned = false;
        let leaf = loop {
            match slot {
                TriangleSlot::Leaf(i) => break i as usize,
                TriangleSlot::Node(n) => {
                    let quadrant = if !turned {
                        if u >= median {
                            u -= median;
                            1
                        } else if v >= median {
                            v -= median;
                            2
                        } else if u + v >= median {
                            turned = true;
                            3
                        } else {
                            0
                        }
                    } else if u < median {
                        v -= median;
                        1
                    } else if v < median {
                        u -= median;
                        2
                    } else {
                        u -= median;
                        v -= median;
                        // Bfr keeps the flag here (module doc).
                        if u + v < median {
                            3
                        } else {
                            0
                        }
                    };
                    slot = self.nodes[n as usize][quadrant];
                    median *= 0.5;
                }
            }
        };
        (leaf, self.frames[leaf].st(uv))
    }

    /// Patch parameters `uv` in leaf `leaf`'s own parameters, by that leaf's affine map (also
    /// for a point outside it): the tree's exchange, then the leaf's square and turn.
    pub(crate) fn leaf_params(&self, leaf: usize, uv: DVec2) -> DVec2 {
        let uv = if self.swapped { DVec2::new(uv.y, uv.x) } else { uv };
        self.frames[leaf].st(uv)
    }

    /// [`TriangleTree::regular`]'s piece in the patch's own parameters (exchanged back where
    /// the tree is swapped): the quartic Bézier triangle that *is* the patch.
    pub fn regular_net(&self) -> Option<QuarticTriangle> {
        self.regular().map(|q| if self.swapped { q.swapped_uv() } else { q.clone() })
    }

    /// The one quartic piece of a regular triangle (a tree of one leaf over the whole
    /// triangle), in the leaf's own parameters: the patch's, exchanged where the tree
    /// [`TriangleTree::is_swapped`]. None for a tree of several leaves or an end cap.
    pub fn regular(&self) -> Option<&QuarticTriangle> {
        match (&self.root, &*self.leaves) {
            (TriangleSlot::Leaf(0), [leaf])
                if !leaf.turned && leaf.origin == DVec2::ZERO && leaf.size == 1.0 =>
            {
                match &leaf.patch {
                    TriangleLeafPatch::Quartic(q) => Some(q),
                    TriangleLeafPatch::Gregory(_) => None,
                }
            }
            _ => None,
        }
    }

    /// Starts loading the quadtree's nodes and the leaves' frames (a hint, as
    /// [`super::PatchTree`]'s nodes).
    #[inline(always)]
    pub(crate) fn prefetch_nodes(&self) {
        super::patch_tree::prefetch_slice(&self.nodes);
        super::patch_tree::prefetch_slice(&self.frames);
    }

    /// Starts loading leaf `leaf` (a hint).
    #[inline(always)]
    pub(crate) fn prefetch_leaf(&self, leaf: usize) {
        super::patch_tree::prefetch_slice(std::slice::from_ref(&self.leaves[leaf]));
    }

    /// Position and first derivatives with respect to the patch's `uv`. Cost: a tree walk and
    /// one leaf's evaluation.
    pub fn derivatives(&self, uv: DVec2) -> SurfaceDerivatives {
        let (leaf, st) = self.find(uv);
        self.found_derivatives(leaf, st)
    }

    /// [`TriangleTree::derivatives`] of the point [`TriangleTree::find`] placed at `st` in
    /// leaf `leaf`: the same values. Cost: one leaf's evaluation.
    pub(crate) fn found_derivatives(&self, leaf: usize, st: DVec2) -> SurfaceDerivatives {
        let leaf = &self.leaves[leaf];
        let d = leaf.patch.derivatives(st);
        let scale = if leaf.turned { -1.0 / leaf.size } else { 1.0 / leaf.size };
        let (du, dv) = (d.du * scale, d.dv * scale);
        if self.swapped {
            SurfaceDerivatives { position: d.position, du: dv, dv: du }
        } else {
            SurfaceDerivatives { position: d.position, du, dv }
        }
    }

    /// Position at `uv`.
    pub fn position(&self, uv: DVec2) -> DVec3 {
        self.derivatives(uv).position
    }
}
