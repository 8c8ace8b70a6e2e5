//! Piecewise patches of subdivision surfaces: the leaves of a face's feature-adaptive
//! isolation (bicubic Bézier pieces and Gregory end caps) in a quadtree, evaluated as
//! OpenSubdiv's Bfr evaluates its `PatchTree` (`bfr/patchTree.cpp`), and where each patch of a
//! cage's set comes from ([`PatchOrigin`]). They are built by [`crate::subdivision`].

use glam::{DVec2, DVec3};

use super::GregoryPatch;

/// The quarters of a quad's parameter square, by their lower-left corner: the children at
/// corners 0, 1, 2, 3.
pub const QUADRANTS: [glam::DVec2; 4] = [
    glam::DVec2::new(0.0, 0.0),
    glam::DVec2::new(0.5, 0.0),
    glam::DVec2::new(0.5, 0.5),
    glam::DVec2::new(0.0, 0.5),
];

/// Where a patch of a set built from a cage comes from
/// ([`crate::surface::SurfaceSet::origins`]).
///
/// A cage of quads gets one patch per face, over the face's own parameters. A cage with any
/// other face gets one patch per corner *sub-face* of every face (the faces of one level of
/// subdivision), because a face that is not a quad is parameterised by its sub-faces
/// (OpenSubdiv's `QUAD_SUBFACES`) and its neighbours must then meet it edge for edge; a
/// quad's sub-faces are the quarters of its square.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PatchOrigin {
    /// The cage face (0-based, file order).
    pub face: u32,
    /// The corner sub-face (0 for a whole quad).
    pub subface: u16,
    /// The face's corner count.
    pub corners: u16,
    /// Whether the patch is a sub-face (else the whole quad).
    pub is_subface: bool,
    /// Quarter turns from the patch's parameters to the sub-face's (or face's): the patch's
    /// corner 0 is the sub-face's corner `rotation` ([`PatchOrigin::subface_st`]).
    pub rotation: u8,
}

impl PatchOrigin {
    /// How many sub-face tiles a row of a `corners`-sided face's parameter domain holds in
    /// Bfr's `QUAD_SUBFACES` parameterisation (`bfr/parameterization.cpp`): sub-face `i`'s
    /// tile has its origin at `(i mod D, i div D)`.
    pub fn tiles_per_row(corners: usize) -> usize {
        match corners {
            0..=4 => 2,
            5..=9 => 3,
            k => 1 + ((k - 1) as f64).sqrt().floor() as usize,
        }
    }

    /// Bfr's face parameters of the point `st` ∈ `[0,1]²` of this patch: a whole quad's
    /// are its own; a quad's quarter `q` covers [`QUADRANTS`]`[q]` + `[0,½]²`, `u` and `v`
    /// as the face's; another face's sub-face `i` covers the half-size square at its tile's
    /// origin, `s` along edge `i`, `t` back along edge `i−1`.
    pub fn face_uv(&self, st: glam::DVec2) -> glam::DVec2 {
        let st = self.subface_st(st);
        let i = self.subface as usize;
        if !self.is_subface {
            st
        } else if self.corners == 4 {
            QUADRANTS[i] + st * 0.5
        } else {
            let d = Self::tiles_per_row(self.corners as usize);
            glam::DVec2::new((i % d) as f64, (i / d) as f64) + st * 0.5
        }
    }

    /// The sub-face's (or whole face's) own parameters of the patch point `st`: `st` turned by
    /// [`PatchOrigin::rotation`].
    pub fn subface_st(&self, st: glam::DVec2) -> glam::DVec2 {
        rotate(st, self.rotation)
    }

    /// The patch point of the sub-face's parameters `sub_st` (the inverse of
    /// [`PatchOrigin::subface_st`]).
    pub fn patch_st(&self, sub_st: glam::DVec2) -> glam::DVec2 {
        rotate(sub_st, (4 - self.rotation) % 4)
    }

    /// Which patch of face `face` (`corners` corners, split into sub-faces or not) holds
    /// Bfr's face parameters `uv`, and where in its `[0,1]²` (the inverse of
    /// [`PatchOrigin::face_uv`] for an unturned patch — its `rotation` is 0, and the patch
    /// point of a turned patch is [`PatchOrigin::patch_st`] of the returned parameters; a point
    /// on a border between sub-faces goes to the upper or right one).
    pub fn from_face_uv(
        face: u32,
        corners: usize,
        is_subface: bool,
        uv: glam::DVec2,
    ) -> (PatchOrigin, glam::DVec2) {
        let at = |subface: usize| PatchOrigin {
            face,
            subface: subface as u16,
            corners: corners as u16,
            is_subface,
            rotation: 0,
        };
        if !is_subface {
            return (at(0), uv);
        }
        if corners == 4 {
            let q = match (uv.x >= 0.5, uv.y >= 0.5) {
                (false, false) => 0,
                (true, false) => 1,
                (true, true) => 2,
                (false, true) => 3,
            };
            return (at(q), (uv - QUADRANTS[q]) * 2.0);
        }
        let d = Self::tiles_per_row(corners);
        let (tx, ty) = (uv.x.floor().max(0.0) as usize, uv.y.floor().max(0.0) as usize);
        let subface = (tx + d * ty).min(corners - 1);
        let origin = glam::DVec2::new((subface % d) as f64, (subface / d) as f64);
        (at(subface), (uv - origin) * 2.0)
    }
}

/// The flag of a leaf slot in [`PatchTree::quadtree`] (the rest of the slot is the leaf's index).
pub const LEAF_SLOT: u32 = 1 << 31;

/// One leaf of a face's patch tree: a square `origin + [0, size]²` of the face's (or
/// sub-face's) domain and the patch over it.
#[derive(Debug, Clone, PartialEq)]
pub struct Leaf {
    pub origin: DVec2,
    /// `2^-level`.
    pub size: f64,
    /// The refinement level the leaf was made at (0: the face itself).
    pub level: u8,
    pub patch: LeafPatch,
}

/// The surface over a leaf.
#[derive(Debug, Clone, PartialEq)]
// Bézier leaves are nearly all the leaves: inline, so evaluating one reads one block.
#[allow(clippy::large_enum_variant)]
pub enum LeafPatch {
    /// A regular piece: its B-spline patch as a Bézier net (`points[4*i + j]`, `i` along `u`).
    Bezier([DVec3; 16]),
    /// An end cap. Boxed: end caps are few (at the isolation limit only), and inline they
    /// would make every leaf a Gregory patch's size, a quarter more memory to stream in a
    /// frame.
    Gregory(Box<GregoryPatch>),
}

impl LeafPatch {
    /// The piece's points: a Bézier net's 16 (`points[4*i + j]`), or a Gregory patch's 20.
    pub fn points(&self) -> &[DVec3] {
        match self {
            LeafPatch::Bezier(p) => p,
            LeafPatch::Gregory(g) => &g.points,
        }
    }
}

/// The leaves and the quadtree of a face's isolation, shared by its views.
#[derive(Debug, PartialEq)]
struct TreeData {
    leaves: Vec<Leaf>,
    nodes: Vec<[Slot; 4]>,
    root: Slot,
    /// Each leaf's output point at its own corner 0 ([`CornerPoint`]), in leaf order.
    corners: Vec<CornerPoint>,
}

impl TreeData {
    /// The tree of `leaves` under `root`, its leaves put in order of level (coarsest first,
    /// otherwise as given) and the nodes' leaf slots renumbered to match. Why: the coarse
    /// leaves are a prefix, so a reader that keeps something for every leaf up to a level (the
    /// engine's f32 forms, [`PatchTree::coarse_leaves`]) finds it at the leaf's own index.
    fn new(leaves: Vec<Leaf>, mut nodes: Vec<[Slot; 4]>, mut root: Slot) -> TreeData {
        let mut order: Vec<u32> = (0..leaves.len() as u32).collect();
        order.sort_by_key(|&i| leaves[i as usize].level);
        let leaves = if order.iter().enumerate().all(|(at, &i)| at == i as usize) {
            leaves
        } else {
            let mut place = vec![0u32; leaves.len()];
            for (at, &i) in order.iter().enumerate() {
                place[i as usize] = at as u32;
            }
            let renumber = |slot: &mut Slot| {
                if let Slot::Leaf(i) = slot {
                    *i = place[*i as usize];
                }
            };
            nodes.iter_mut().flatten().for_each(renumber);
            renumber(&mut root);
            let mut old: Vec<Option<Leaf>> = leaves.into_iter().map(Some).collect();
            order.iter().map(|&i| old[i as usize].take().expect("a permutation")).collect()
        };
        let corners = leaves.iter().map(CornerPoint::of).collect();
        TreeData { leaves, nodes, root, corners }
    }
}

/// A leaf's surface point at its corner 0 (`st = (0, 0)`) as the engine writes it: the
/// position and unit normal rounded to `f32`, the normal that of the tree's own orientation.
///
/// **Why.** At a dyadic rate (Bfr's rate 16, or 8 on sub-faces) the samples of a deeply
/// isolated face fall on the corners of its leaves: a step of the rate-16 grid is four leaves
/// of level 6, and the search puts a point on a corner in the leaf above and to the right,
/// at that leaf's corner 0. Evaluating it reads the leaf's first rows (three of the leaf's
/// seven cache lines), then sums them and makes the normal, about 55 ns a point on
/// `catmark_rook`, most of it waiting for the leaf's lines. This record is one aligned line's
/// half. **Exact:** a view's derivatives are the leaf's scaled by a power of two
/// (`view_size / size`), turned by quarter turns and exchanged where the view is transposed,
/// so its normal `normalize(S_u × S_v)` is the leaf's own bit for bit, negated where the
/// view is transposed (a power-of-two scaling of a cross product and its length rounds
/// alike; [`robust_normal`](super::robust_normal)'s test is invariant too), and the position
/// is the leaf's value there: the output is the evaluation's to the bit. A point whose
/// normal takes the robust fallback (parallel derivatives, which depends on the view's
/// parameters) or that lies on a Gregory end cap is not stored.
#[derive(Debug, Clone, Copy, PartialEq)]
#[repr(C, align(32))]
pub(crate) struct CornerPoint {
    pub(crate) position: [f32; 3],
    pub(crate) normal: [f32; 3],
    /// 1 where the record holds the point; 0 where the point is evaluated.
    stored: u32,
}

impl CornerPoint {
    /// `leaf`'s record, from the same sums [`PatchTree::derivatives`] takes there.
    fn of(leaf: &Leaf) -> CornerPoint {
        let none = CornerPoint { position: [0.0; 3], normal: [0.0; 3], stored: 0 };
        let LeafPatch::Bezier(net) = &leaf.patch else { return none };
        let (p, du, dv) = bezier_derivatives(net, DVec2::ZERO);
        let n = du.cross(dv);
        let scale = du.length_squared().max(dv.length_squared());
        // `robust_normal`'s test for its first answer, `n.normalize()`.
        if !(n.length_squared() > 1e-20 * scale * scale && n.is_finite()) {
            return none;
        }
        CornerPoint {
            position: p.as_vec3().to_array(),
            normal: n.normalize().as_vec3().to_array(),
            stored: 1,
        }
    }

    /// The record's point where it holds one, the normal negated for a transposed view.
    #[inline(always)]
    pub(crate) fn point(&self, transposed: bool) -> Option<([f32; 3], [f32; 3])> {
        let n = self.normal;
        (self.stored != 0).then_some((self.position, if transposed { n.map(|x| -x) } else { n }))
    }
}

/// A leaf and its square in the tree's parameters, and the nodes the walk to it passed
/// ([`PatchTree::find_near`]); the default is empty, so that the first search walks from
/// the root.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct LeafSquare {
    leaf: usize,
    origin: DVec2,
    size: f64,
    /// The walk's nodes from the root, `(node, origin, side)` ([`PATH_DEPTH`] at most), and
    /// how many of them are kept.
    path: [(u32, DVec2, f64); PATH_DEPTH],
    depth: usize,
}

/// How many levels of a walk's path [`LeafSquare`] keeps: a deeper tree's walks resume from
/// this level at the deepest.
const PATH_DEPTH: usize = 8;

/// Child slots of a quadtree node, by quadrant: `[u low v low, u high v low, u high v high,
/// u low v high]`; a child is a node (`Node(i)`) or a leaf (`Leaf(i)`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Slot {
    Node(u32),
    Leaf(u32),
}

/// The piecewise surface over one face (a quad) or one corner sub-face (of any other face),
/// with parameters in `[0,1]²`: the leaves of its isolation and the quadtree that finds the
/// leaf of a parameter point, as Bfr's `PatchTree` does.
///
/// Cloning is cheap: the leaves are shared (the quarters of one face, [`PatchTree::quadrant`],
/// are views of one tree).
#[derive(Debug, Clone, PartialEq)]
pub struct PatchTree {
    data: std::sync::Arc<TreeData>,
    /// The corners of the bounding box of the visible leaves' points: the surface lies in
    /// their convex hull ([`PatchTree::control_points`]).
    hull: [DVec3; 8],
    /// `u` and `v` are exchanged on the way in and out (the surface with the opposite
    /// orientation, [`PatchTree::transposed`]).
    transposed: bool,
    /// Quarter turns between the patch's parameters and the tree's: the patch's corner 0 is
    /// the tree's corner `rotation` ([`PatchTree::rotated`]).
    rotation: u8,
    /// The square of the tree's domain this patch covers, `view_origin + [0, view_size]²`
    /// ([`PatchTree::quadrant`]).
    view_origin: DVec2,
    view_size: f64,
}

impl PatchTree {
    /// A tree of `leaves` with quadtree `nodes` under `root` (children by quadrant, see
    /// [`PatchTree::locate`]). Precondition: the leaves tile `[0,1]²` as the nodes say.
    pub(crate) fn from_parts(leaves: Vec<Leaf>, nodes: Vec<[Slot; 4]>, root: Slot) -> PatchTree {
        let mut tree = PatchTree {
            data: std::sync::Arc::new(TreeData::new(leaves, nodes, root)),
            hull: [DVec3::ZERO; 8],
            transposed: false,
            rotation: 0,
            view_origin: DVec2::ZERO,
            view_size: 1.0,
        };
        tree.hull = tree.visible_hull();
        tree
    }

    /// The leaves of the whole tree (of every view of it), in order of level, coarsest first.
    pub fn leaves(&self) -> &[Leaf] {
        &self.data.leaves
    }

    /// How many leaves are of level `level` or coarser: the first ones of
    /// [`PatchTree::leaves`]. Cost: O(log leaves).
    pub fn coarse_leaves(&self, level: u8) -> usize {
        self.data.leaves.partition_point(|leaf| leaf.level <= level)
    }

    /// Appends the points of every leaf of the tree (of every view of it) to `out`, leaf by
    /// leaf: a Bézier leaf's 16, a Gregory leaf's 20. Cost: O(leaves).
    pub fn leaf_points(&self, out: &mut Vec<DVec3>) {
        for leaf in &self.data.leaves {
            out.extend_from_slice(leaf.patch.points());
        }
    }

    /// How many points [`PatchTree::leaf_points`] appends.
    pub fn leaf_point_count(&self) -> usize {
        self.data.leaves.iter().map(|l| l.patch.points().len()).sum()
    }

    /// The same view (transposition, rotation, square) of a tree with the same nodes and
    /// leaves whose points are `points`, in [`PatchTree::leaf_points`] order: the surface of
    /// a moved cage. Precondition: `points.len()` is [`PatchTree::leaf_point_count`].
    /// Cost: O(leaves).
    pub fn with_leaf_points(&self, points: &[DVec3]) -> PatchTree {
        assert_eq!(points.len(), self.leaf_point_count(), "one point per leaf point");
        let mut next = points.iter().copied();
        let mut take = || next.next().expect("counted above");
        let leaves = self
            .data
            .leaves
            .iter()
            .map(|leaf| Leaf {
                patch: match &leaf.patch {
                    LeafPatch::Bezier(_) => LeafPatch::Bezier(std::array::from_fn(|_| take())),
                    LeafPatch::Gregory(_) => {
                        LeafPatch::Gregory(Box::new(GregoryPatch { points: std::array::from_fn(|_| take()) }))
                    }
                },
                ..*leaf
            })
            .collect();
        let data = TreeData::new(leaves, self.data.nodes.clone(), self.data.root);
        self.with_data(std::sync::Arc::new(data))
    }

    /// This view of `other`'s tree (which has this one's structure, e.g. made by
    /// [`PatchTree::with_leaf_points`] from another view of this tree): the quarters of a
    /// moved face share one tree as the original quarters did. Cost: O(leaves).
    pub fn with_tree_of(&self, other: &PatchTree) -> PatchTree {
        self.with_data(other.data.clone())
    }

    fn with_data(&self, data: std::sync::Arc<TreeData>) -> PatchTree {
        let mut tree = PatchTree { data, ..self.clone() };
        tree.hull = tree.visible_hull();
        tree
    }

    /// The bounding box corners of the visible leaves' points.
    fn visible_hull(&self) -> [DVec3; 8] {
        super::box_corners(self.visible_leaves().flat_map(|(leaf, _, _)| leaf.patch.points()))
    }

    /// The leaf holding `uv`, with `uv` in the leaf's own `[0,1]²`. Points on a border
    /// between leaves go to the upper (right) one, as `searchQuadtree` does; the surface is
    /// continuous there. Cost: O(depth).
    pub fn locate(&self, uv: DVec2) -> (&Leaf, DVec2) {
        let (i, st, _) = self.find(uv);
        (&self.data.leaves[i], st)
    }

    /// [`PatchTree::locate`] as a leaf index, reading only the quadtree's nodes: a leaf's
    /// square is the cell the walk ends in (dyadic, so exact), so its data is not touched
    /// here and a caller can start loading it before it is needed
    /// ([`PatchTree::derivatives_each`]).
    pub(crate) fn find(&self, uv: DVec2) -> (usize, DVec2, f64) {
        let uv = self.tree_uv(uv);
        let (leaf, origin, size) = self.leaf_square(uv);
        (leaf, (uv - origin) / size, size)
    }

    /// [`PatchTree::find`], the same values, without walking the quadtree where `uv` lies in
    /// `near`'s leaf (the last found), which then becomes the leaf found. Why: a pattern's
    /// points come row by row, and a coarse leaf of a deep tree holds a run of each row
    /// (`catmark_rook` at Bfr's rate 16: over half its isolated faces' points follow a point
    /// of their own leaf), where a walk is a chain of dependent loads. The square is
    /// half-open as the walk's comparisons make it, so the leaf and `st` are the walk's, bit
    /// for bit. Cost: O(1) in `near`'s leaf, else O(depth).
    #[inline(always)]
    pub(crate) fn find_near(&self, uv: DVec2, near: &mut LeafSquare) -> (usize, DVec2, f64) {
        let t = self.tree_uv(uv);
        if !inside(t, near.origin, near.size) {
            self.walk_near(t, near);
        }
        (near.leaf, (t - near.origin) / near.size, near.size)
    }

    /// Every leaf of the view holding points of a grid's interior, with its points:
    /// `each(leaf, k, st, size)` for each point `uvs[k]`, with the leaf, `st` and `size` that
    /// [`PatchTree::find_near`] gives it, bit for bit; one leaf's points one after the other,
    /// in the list's order. `uvs` must be the interior points of the `cells` grid, row after
    /// row ([`crate::pattern::core_grid::grid_interior`]).
    ///
    /// Why: a pattern's interior is a grid, and a grid meets a quadtree's dyadic squares in
    /// rectangles. The walk goes down the quadtree once with the ranges of the grid's columns
    /// and rows in each node's square, each split at the node's middle by the walk's own
    /// comparison, so a leaf gets all its points at once: no search per point and no sort of
    /// the points by leaf. The view's map to the tree's square (a transposition, quarter
    /// turns, the view's square) moves each axis of the grid to one axis of the tree, each
    /// coordinate a monotone function of one grid index, so each split is a contiguous range.
    /// Cost: O(nodes holding points + points); the leaves' data is not touched.
    pub(crate) fn grid_leaves(
        &self,
        uvs: &[DVec2],
        [nu, nv]: [u32; 2],
        lines: &mut [Vec<f64>; 2],
        mut each: impl FnMut(usize, usize, DVec2, f64),
    ) {
        let (cols, rows) = (nu.saturating_sub(1) as usize, nv.saturating_sub(1) as usize);
        assert_eq!(uvs.len(), cols * rows, "the interior of a {nu} × {nv} grid");
        if uvs.is_empty() {
            return;
        }
        // The tree's x follows the view's v where the view is transposed or turned an odd
        // number of quarters (each quarter turn exchanges the axes), else its u.
        let swapped = self.transposed != (self.rotation % 2 == 1);
        // Per tree axis, the grid lines' coordinates (a column's from the first row, a row's
        // from the first column: the same for the whole line), ascending, and whether the
        // grid index runs against them.
        let column = |i: usize| self.tree_uv(uvs[i]);
        let row = |j: usize| self.tree_uv(uvs[j * cols]);
        let [xs, ys] = lines;
        xs.clear();
        ys.clear();
        if swapped {
            xs.extend((0..rows).map(|j| row(j).x));
            ys.extend((0..cols).map(|i| column(i).y));
        } else {
            xs.extend((0..cols).map(|i| column(i).x));
            ys.extend((0..rows).map(|j| row(j).y));
        }
        let falls = |line: &mut Vec<f64>| {
            let falls = line.len() > 1 && line[0] > line[line.len() - 1];
            if falls {
                line.reverse();
            }
            falls
        };
        let falling = [falls(xs), falls(ys)];
        let axes = Axes { xs, ys, falling, swapped, cols };
        axes.visit(&self.data, self.data.root, DVec2::ZERO, 1.0, 0..xs.len(), 0..ys.len(), &mut each);
    }

    /// The walk of [`PatchTree::leaf_square`] for `uv`, resumed from the deepest node of
    /// `near`'s path whose square holds `uv`, leaving the leaf found, its square and its path
    /// in `near`. Why: the next point of a row lies in a neighbour of the last leaf, mostly
    /// under the same parent or grandparent, and a walk is a chain of dependent loads, each
    /// level a branch no predictor learns. The same leaf and square as the walk from the root,
    /// bit for bit: a node's square is half-open as the walk's comparisons make it (a point
    /// on the domain's upper border, which the root's closed square holds, resumes from
    /// higher up), and the squares are dyadic, so exact. Cost: O(depth).
    #[inline(always)]
    fn walk_near(&self, uv: DVec2, near: &mut LeafSquare) {
        let mut depth = near.depth;
        while depth > 0 && !inside(uv, near.path[depth - 1].1, near.path[depth - 1].2) {
            depth -= 1;
        }
        let (mut slot, mut origin, mut size) = match depth {
            0 => (self.data.root, DVec2::ZERO, 1.0),
            _ => {
                depth -= 1;
                let (node, origin, size) = near.path[depth];
                (Slot::Node(node), origin, size)
            }
        };
        loop {
            match slot {
                Slot::Leaf(i) => {
                    (near.leaf, near.origin, near.size) = (i as usize, origin, size);
                    near.depth = depth.min(PATH_DEPTH);
                    return;
                }
                Slot::Node(n) => {
                    if depth < PATH_DEPTH {
                        near.path[depth] = (n, origin, size);
                    }
                    depth += 1;
                    slot = self.data.nodes[n as usize][quadrant_step(uv, &mut origin, &mut size)];
                }
            }
        }
    }

    /// The leaf holding the tree's point `uv` (as [`PatchTree::find`] places it) and its
    /// square, `(leaf, origin, size)`, from the quadtree's nodes alone. Cost: O(depth).
    #[inline(always)]
    fn leaf_square(&self, uv: DVec2) -> (usize, DVec2, f64) {
        // The walk from the root: an empty path.
        let mut near = LeafSquare::default();
        self.walk_near(uv, &mut near);
        debug_assert!({
            let leaf = &self.data.leaves[near.leaf];
            leaf.origin == near.origin && leaf.size == near.size
        });
        (near.leaf, near.origin, near.size)
    }

    /// The tree's parameters of this view's point `uv` (an affine map: transposition,
    /// rotation, then the view's square).
    pub(crate) fn tree_uv(&self, uv: DVec2) -> DVec2 {
        let uv = if self.transposed { DVec2::new(uv.y, uv.x) } else { uv };
        self.view_origin + rotate(uv, self.rotation) * self.view_size
    }

    /// The surface point at `uv` ∈ `[0,1]²`. Cost: O(depth) and one patch evaluation.
    pub fn position(&self, uv: DVec2) -> DVec3 {
        let (leaf, st) = self.locate(uv);
        match &leaf.patch {
            LeafPatch::Bezier(p) => bezier_position(p, st),
            LeafPatch::Gregory(g) => g.position(st.x, st.y),
        }
    }

    /// Position and first derivatives with respect to the tree's `uv` at `uv` (Gregory
    /// leaves: OpenSubdiv's approximate derivatives, see [`GregoryPatch::derivatives`]).
    pub fn derivatives(&self, uv: DVec2) -> (DVec3, DVec3, DVec3) {
        let (leaf, st, size) = self.find(uv);
        self.leaf_derivatives(&self.data.leaves[leaf], st, size)
    }

    /// [`PatchTree::derivatives`] at each of `uvs`, handed to `each(k, derivatives)` in
    /// order, with the same values. Why a batch: a tessellation's points mostly fall in
    /// different leaves (at factor 8 a grid step is 8 of the deepest leaves), and profiles
    /// show the load of each point's leaf (a few hundred bytes) stalling. So the leaves of
    /// eight points are found from the quadtree first and their loads started, then
    /// evaluated. (On the noisy 2-core machine this was written on, the prefetch alone gave
    /// no gain that stood out of the noise; the batch as a whole, inlined into the engines'
    /// AVX2 path, did.) Cost: as many [`PatchTree::derivatives`].
    #[inline(always)]
    pub fn derivatives_each(&self, uvs: &[DVec2], mut each: impl FnMut(usize, (DVec3, DVec3, DVec3))) {
        found_ahead(
            uvs.len(),
            |k| (self, uvs[k]),
            |_, view, leaf, st| view.prefetch_point(leaf, st, false),
            |k, _, _, leaf, st, size| each(k, self.leaf_derivatives(&self.data.leaves[leaf], st, size)),
        );
    }

    /// Starts loading what the engine reads for the point at `st` in `leaf`: with `corners`
    /// and at the leaf's corner 0 its [`CornerPoint`], else the leaf's net (a hint).
    #[inline(always)]
    pub(crate) fn prefetch_point(&self, leaf: usize, st: DVec2, corners: bool) {
        if corners && st == DVec2::ZERO {
            prefetch_at::<TO_L1>((&self.data.corners[leaf] as *const CornerPoint).cast());
        } else {
            prefetch(&self.data.leaves[leaf], st);
        }
    }

    /// The f64 output at each of `uvs` (positions and unit normals rounded to `f32`, as
    /// [`subdivision_point`](super::subdivision_point) of [`PatchTree::derivatives_each`]
    /// gives them, bit for bit): a point at a leaf's corner 0 read from the leaf's
    /// [`CornerPoint`] where it holds one, every other evaluated. What the engine gives a
    /// point outside the leaves it keeps in f32 (`engine::tree_points::eval_sparse`).
    #[cfg(test)]
    pub(crate) fn outputs_each(&self, uvs: &[DVec2], each: impl FnMut(usize, [f32; 3], [f32; 3])) {
        // SAFETY: without AVX, nothing is required of the CPU.
        unsafe { outputs_with::<false>(uvs.len(), |k| (self, uvs[k]), each) }
    }

    /// [`PatchTree::outputs_each`] compiled for AVX, as the engine's AVX2 path evaluates
    /// (`found_derivatives_avx`, inlined into its caller): the same values.
    ///
    /// # Safety
    /// The CPU must support AVX.
    #[cfg(all(test, target_arch = "x86_64"))]
    #[inline(always)]
    pub(crate) unsafe fn outputs_each_avx(&self, uvs: &[DVec2], each: impl FnMut(usize, [f32; 3], [f32; 3])) {
        // SAFETY: the caller's precondition.
        unsafe { outputs_with::<true>(uvs.len(), |k| (self, uvs[k]), each) }
    }

    /// The output at `st` of `leaf` (as [`PatchTree::find`] gives them) from the leaf's
    /// [`CornerPoint`], where `st` is its corner 0 and the record holds the point.
    #[inline(always)]
    pub(crate) fn corner_point(&self, leaf: usize, st: DVec2) -> Option<([f32; 3], [f32; 3])> {
        if st != DVec2::ZERO {
            return None;
        }
        self.data.corners[leaf].point(self.transposed)
    }

    /// [`PatchTree::derivatives`] of the point [`PatchTree::find`] placed at `st` in leaf
    /// `leaf` (of side `size`), for callers compiled for AVX (the engine's AVX2 path): the
    /// Bézier sums are inlined into the caller, so their results stay in registers. Through a
    /// call, profiles showed the caller stalling on reading back the callee's wide stores (a
    /// fifth of the evaluation's samples). The same values.
    ///
    /// # Safety
    /// The CPU must support AVX.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    pub(crate) unsafe fn found_derivatives_avx(
        &self,
        leaf: usize,
        st: DVec2,
        size: f64,
    ) -> (DVec3, DVec3, DVec3) {
        // SAFETY: the caller's precondition.
        unsafe { self.leaf_derivatives_with::<true>(&self.data.leaves[leaf], st, size) }
    }

    /// [`PatchTree::found_derivatives_avx`] for any CPU: the same values.
    #[inline(always)]
    pub(crate) fn found_derivatives(&self, leaf: usize, st: DVec2, size: f64) -> (DVec3, DVec3, DVec3) {
        self.leaf_derivatives(&self.data.leaves[leaf], st, size)
    }

    /// Starts loading what evaluating leaf `leaf` at `st` reads (a hint, as in
    /// [`PatchTree::derivatives_each`]).
    #[inline(always)]
    pub(crate) fn prefetch_leaf(&self, leaf: usize, st: DVec2) {
        prefetch(&self.data.leaves[leaf], st);
    }

    /// Starts loading the quadtree's nodes (a hint, as in [`PatchTree::derivatives_each`]).
    #[inline(always)]
    pub(crate) fn prefetch_nodes(&self) {
        prefetch_slice(&self.data.nodes);
    }

    /// Position and derivatives with respect to the view's `uv` at `st` in `leaf`, whose
    /// side is `size` (as [`PatchTree::find`] says, so that the leaf's own field, in
    /// another cache line than its points, is not read).
    #[inline(always)]
    fn leaf_derivatives(&self, leaf: &Leaf, st: DVec2, size: f64) -> (DVec3, DVec3, DVec3) {
        // SAFETY: without AVX, nothing is required of the CPU.
        unsafe { self.leaf_derivatives_with::<false>(leaf, st, size) }
    }

    /// # Safety
    /// With `AVX`, the CPU must support AVX.
    #[inline(always)]
    unsafe fn leaf_derivatives_with<const AVX: bool>(
        &self,
        leaf: &Leaf,
        st: DVec2,
        size: f64,
    ) -> (DVec3, DVec3, DVec3) {
        let (p, du, dv) = match &leaf.patch {
            #[cfg(target_arch = "x86_64")]
            // SAFETY: the caller's precondition.
            LeafPatch::Bezier(b) if AVX => unsafe { bezier_sums_avx(b, st) },
            LeafPatch::Bezier(b) => bezier_derivatives(b, st),
            LeafPatch::Gregory(g) => g.derivatives(st.x, st.y),
        };
        let (mut du, mut dv) = (du * (self.view_size / size), dv * (self.view_size / size));
        // Back through the rotation: with (u, v) = (1 − v', u'), ∂/∂u' = ∂/∂v, ∂/∂v' = −∂/∂u.
        for _ in 0..self.rotation {
            (du, dv) = (dv, -du);
        }
        if self.transposed {
            (p, dv, du)
        } else {
            (p, du, dv)
        }
    }

    /// The same surface with `u` and `v` exchanged (the opposite orientation).
    pub fn transposed(&self) -> PatchTree {
        PatchTree { transposed: !self.transposed, ..self.clone() }
    }

    /// The same surface with its parameters turned by `quarters` quarter turns: the new
    /// patch's corner 0 is this one's corner `quarters` (mod 4), the orientation unchanged.
    /// Precondition: not transposed.
    pub fn rotated(&self, quarters: u8) -> PatchTree {
        PatchTree { rotation: (self.rotation + quarters) % 4, ..self.clone() }
    }

    /// The quarter `q` of the patch (quadrants as [`QUADRANTS`]) as a
    /// patch of its own over `[0,1]²`, `u` and `v` running as the whole's.
    /// Precondition: not transposed.
    pub fn quadrant(&self, q: usize) -> PatchTree {
        let size = self.view_size * 0.5;
        let mut view = PatchTree {
            view_origin: self.view_origin + QUADRANTS[q] * self.view_size,
            view_size: size,
            ..self.clone()
        };
        view.hull = view.visible_hull();
        view
    }

    /// The leaves this patch covers, each with its square in the patch's own parameters
    /// (origin, size) — before any transposition.
    pub fn visible_leaves(&self) -> impl Iterator<Item = (&Leaf, DVec2, f64)> + '_ {
        let (o, s) = (self.view_origin, self.view_size);
        self.data
            .leaves
            .iter()
            .filter(move |l| {
                l.origin.x < o.x + s
                    && l.origin.x + l.size > o.x
                    && l.origin.y < o.y + s
                    && l.origin.y + l.size > o.y
            })
            .map(move |l| (l, (l.origin - o) / s, l.size / s))
    }

    /// Whether [`PatchTree::transposed`] was applied an odd number of times: leaf
    /// parameters are then the tree's with `u` and `v` exchanged.
    pub fn is_transposed(&self) -> bool {
        self.transposed
    }

    /// The quarter turns of [`PatchTree::rotated`] (0 to 3).
    pub fn rotation(&self) -> u8 {
        self.rotation
    }

    /// The eight corners of the box around the visible leaves' control points: the surface
    /// lies in their convex hull (Bézier and Gregory patches are convex combinations of their
    /// points), which is what hulls and boxes need; not a control net.
    pub fn control_points(&self) -> &[DVec3] {
        &self.hull
    }

    /// The square of the tree's domain this patch covers, `origin + [0, size]²`
    /// ([`PatchTree::quadrant`]), as `(origin, size)`.
    pub fn view_square(&self) -> (DVec2, f64) {
        (self.view_origin, self.view_size)
    }

    /// The quadtree as an engine that walks it itself reads it (the GPU's): the root slot and
    /// the nodes' child slots by quadrant (as [`PatchTree::locate`] numbers them), each slot a
    /// node index, or [`LEAF_SLOT`] `|` a leaf index into [`PatchTree::leaves`].
    /// Cost: O(nodes).
    pub fn quadtree(&self) -> (u32, Vec<[u32; 4]>) {
        let code = |s: Slot| match s {
            Slot::Node(n) => n,
            Slot::Leaf(l) => LEAF_SLOT | l,
        };
        (code(self.data.root), self.data.nodes.iter().map(|n| n.map(code)).collect())
    }

    /// An identity of the tree's leaves: equal for the views of one tree ([`PatchTree::quadrant`],
    /// [`PatchTree::rotated`], [`PatchTree::transposed`]), so that an engine stores them once.
    pub fn leaves_id(&self) -> usize {
        std::sync::Arc::as_ptr(&self.data) as usize
    }

    /// The tree's deepest leaf level.
    pub fn depth(&self) -> u8 {
        self.data.leaves.iter().map(|l| l.level).max().unwrap_or(0)
    }
}

/// `each(k, view, uv, leaf, st, size)` for each point `k < n` of a stream of points on trees,
/// `item(k) = (view, uv)`, in order, as [`PatchTree::find`] places them: the points found
/// [`AHEAD`] at a time, and `prefetch(k, view, leaf, st)` called for each (to ask for what
/// evaluating it reads) before any of them is evaluated.
/// Why ahead: a tessellation's points mostly fall in different leaves (at factor 8 a grid
/// step is 8 of the deepest leaves), and profiles show the load of each point's leaf (a few
/// hundred bytes) stalling ([`PatchTree::derivatives_each`]). Why a stream of trees: the
/// engine's edges, a few points each on different trees, would start every edge with no
/// load in flight (`engine::tree_points::eval_sparse`, through [`Lookahead`]).
#[inline(always)]
fn found_ahead<'t>(
    n: usize,
    item: impl Fn(usize) -> (&'t PatchTree, DVec2),
    prefetch: impl Fn(usize, &'t PatchTree, usize, DVec2),
    mut each: impl FnMut(usize, &'t PatchTree, DVec2, usize, DVec2, f64),
) {
    let mut ahead = Lookahead::default();
    for start in (0..n).step_by(AHEAD) {
        for (i, f) in ahead.find(start, n, &item, &prefetch).iter().flatten().enumerate() {
            each(start + i, f.view, f.uv, f.leaf, f.st, f.size);
        }
    }
}

/// A point of a stream on trees and where [`PatchTree::find`] places it ([`Lookahead`]).
#[derive(Clone, Copy)]
pub(crate) struct FoundPoint<'t> {
    pub(crate) view: &'t PatchTree,
    pub(crate) uv: DVec2,
    pub(crate) leaf: usize,
    pub(crate) st: DVec2,
    pub(crate) size: f64,
}

/// [`found_ahead`]'s search, for a caller that evaluates the points in its own loop (whose
/// body, inlined there, is compiled for the caller's instructions, where a closure's body
/// may not be): the next [`AHEAD`] points of a stream at a time, each asked for before any
/// is returned. Keeps the last tree and leaf found ([`PatchTree::find_near`]).
pub(crate) struct Lookahead<'t> {
    tree: *const TreeData,
    near: LeafSquare,
    found: [Option<FoundPoint<'t>>; AHEAD],
}

impl Default for Lookahead<'_> {
    fn default() -> Self {
        Lookahead { tree: std::ptr::null(), near: LeafSquare::default(), found: [None; AHEAD] }
    }
}

impl<'t> Lookahead<'t> {
    /// Points `start..` (at most [`AHEAD`], up to `n`) of the stream `item(k) = (view, uv)`,
    /// found, `prefetch(k, view, leaf, st)` called for each before they are returned (all
    /// `Some`).
    #[inline(always)]
    pub(crate) fn find(
        &mut self,
        start: usize,
        n: usize,
        item: impl Fn(usize) -> (&'t PatchTree, DVec2),
        prefetch: impl Fn(usize, &'t PatchTree, usize, DVec2),
    ) -> &[Option<FoundPoint<'t>>] {
        let count = AHEAD.min(n - start);
        for i in 0..count {
            let (view, uv) = item(start + i);
            if !std::ptr::eq(self.tree, &*view.data) {
                self.tree = &*view.data;
                self.near = LeafSquare::default();
                prefetch_slice(&view.data.nodes);
            }
            let (leaf, st, size) = view.find_near(uv, &mut self.near);
            prefetch(start + i, view, leaf, st);
            self.found[i] = Some(FoundPoint { view, uv, leaf, st, size });
        }
        &self.found[..count]
    }
}

/// # Safety
/// With `AVX`, the CPU must support AVX.
#[cfg(test)]
#[inline(always)]
unsafe fn outputs_with<'t, const AVX: bool>(
    n: usize,
    item: impl Fn(usize) -> (&'t PatchTree, DVec2),
    mut each: impl FnMut(usize, [f32; 3], [f32; 3]),
) {
    found_ahead(
        n,
        item,
        |_, view, leaf, st| view.prefetch_point(leaf, st, true),
        |k, view, uv, leaf, st, size| {
            if let Some((position, normal)) = view.corner_point(leaf, st) {
                return each(k, position, normal);
            }
            // SAFETY: passed on from the caller.
            let d = unsafe { view.leaf_derivatives_with::<AVX>(&view.data.leaves[leaf], st, size) };
            let q = super::subdivision_point(view, uv, d);
            each(k, q.position.as_vec3().to_array(), q.normal.as_vec3().to_array());
        },
    );
}

/// A grid's lines in the tree's coordinates, for [`PatchTree::grid_leaves`].
struct Axes<'a> {
    /// The lines along the tree's x and y, ascending.
    xs: &'a [f64],
    ys: &'a [f64],
    /// Per tree axis, whether the grid's index runs against the ascending order.
    falling: [bool; 2],
    /// Whether the tree's x follows the grid's rows (`j`) rather than its columns (`i`).
    swapped: bool,
    /// The grid's interior columns (points per row).
    cols: usize,
}

impl Axes<'_> {
    /// The points in `slot`'s square `origin + [0, size)²` whose tree coordinates are at
    /// positions `x` of `xs` and `y` of `ys`, leaf by leaf. A node's square splits at its
    /// middle as [`quadrant_step`] splits it (`≥` the middle goes up or right), so each
    /// point reaches the leaf the walk reaches, with the same square.
    #[allow(clippy::too_many_arguments)] // one recursion's state
    fn visit(
        &self,
        data: &TreeData,
        slot: Slot,
        origin: DVec2,
        size: f64,
        x: std::ops::Range<usize>,
        y: std::ops::Range<usize>,
        each: &mut impl FnMut(usize, usize, DVec2, f64),
    ) {
        if x.is_empty() || y.is_empty() {
            return;
        }
        let n = match slot {
            Slot::Leaf(leaf) => return self.leaf(leaf as usize, origin, size, x, y, each),
            Slot::Node(n) => n as usize,
        };
        let half = size * 0.5;
        let (mx, my) = (origin.x + half, origin.y + half);
        let xm = x.start + self.xs[x.clone()].partition_point(|&t| t < mx);
        let ym = y.start + self.ys[y.clone()].partition_point(|&t| t < my);
        // The children by quadrant ([`QUADRANTS`], corners at `origin + half` exactly as the
        // walk moves them: the squares are dyadic).
        for (&child, corner) in data.nodes[n].iter().zip(QUADRANTS) {
            let xq = if corner.x == 0.0 { x.start..xm } else { xm..x.end };
            let yq = if corner.y == 0.0 { y.start..ym } else { ym..y.end };
            self.visit(data, child, origin + corner * size, half, xq, yq, each);
        }
    }

    /// A leaf's points (positions `x`, `y` of the tree's lines), in the grid's row order.
    fn leaf(
        &self,
        leaf: usize,
        origin: DVec2,
        size: f64,
        x: std::ops::Range<usize>,
        y: std::ops::Range<usize>,
        each: &mut impl FnMut(usize, usize, DVec2, f64),
    ) {
        // Grid indices of a range of positions, and each index's position.
        let indices = |r: &std::ops::Range<usize>, len: usize, falling: bool| {
            if falling {
                len - r.end..len - r.start
            } else {
                r.clone()
            }
        };
        let position =
            |index: usize, len: usize, falling: bool| if falling { len - 1 - index } else { index };
        let (nx, ny) = (self.xs.len(), self.ys.len());
        let (gx, gy) = (indices(&x, nx, self.falling[0]), indices(&y, ny, self.falling[1]));
        let (columns, rows) = if self.swapped { (gy, gx) } else { (gx, gy) };
        for j in rows {
            for i in columns.clone() {
                let (a, b) = if self.swapped { (j, i) } else { (i, j) };
                let t = DVec2::new(
                    self.xs[position(a, nx, self.falling[0])],
                    self.ys[position(b, ny, self.falling[1])],
                );
                each(leaf, j * self.cols + i, (t - origin) / size, size);
            }
        }
    }
}

/// One step of the quadtree's walk for `uv` from a node's square `origin + [0, size]²`: the
/// child quadrant that holds it (see [`Slot`]: a point on a border goes up and to the right),
/// `origin` and `size` moved to that child's square. The one rule of every walk.
#[inline(always)]
fn quadrant_step(uv: DVec2, origin: &mut DVec2, size: &mut f64) -> usize {
    *size *= 0.5;
    let (right, up) = (uv.x >= origin.x + *size, uv.y >= origin.y + *size);
    *origin += DVec2::new(f64::from(u8::from(right)), f64::from(u8::from(up))) * *size;
    match (right, up) {
        (false, false) => 0,
        (true, false) => 1,
        (true, true) => 2,
        (false, true) => 3,
    }
}

/// Whether `t` lies in the half-open square `origin + [0, size)²`.
#[inline(always)]
fn inside(t: DVec2, origin: DVec2, size: f64) -> bool {
    t.x >= origin.x && t.y >= origin.y && t.x < origin.x + size && t.y < origin.y + size
}

/// `uv` turned by `quarters` quarter turns about the square's centre, `(u, v) → (1 − v, u)`
/// each: the point of the unturned square that the turned one's `uv` is.
pub fn rotate(uv: DVec2, quarters: u8) -> DVec2 {
    let mut p = uv;
    for _ in 0..quarters % 4 {
        p = DVec2::new(1.0 - p.y, p.x);
    }
    p
}

/// Points whose leaves [`PatchTree::derivatives_each`] looks up before evaluating any: a few
/// loads in flight, few enough that their leaves (eight of 424 bytes) stay in L1.
pub(crate) const AHEAD: usize = 8;

/// Starts loading what evaluating `leaf` at `st` reads into the cache (a hint: no effect
/// on results): its tag and, for a Bézier leaf, the rows of the net that [`live`] keeps.
/// Where a Bézier net lies inside a leaf is Rust's choice of layout, so it is asked of a
/// leaf at run time (a constant once compiled).
#[inline(always)]
fn prefetch(leaf: &Leaf, st: DVec2) {
    #[cfg(target_arch = "x86_64")]
    {
        let start = (leaf as *const Leaf).cast::<i8>();
        let line = |offset: usize| prefetch_at::<TO_L1>(start.wrapping_add(offset));
        line(0);
        let point = std::mem::size_of::<DVec3>();
        let rows = live(st.x);
        let (first, last) =
            (bezier_offset() + 4 * rows.start * point, bezier_offset() + 4 * rows.end * point);
        for offset in (first..last.min(std::mem::size_of::<Leaf>())).step_by(64) {
            line(offset);
        }
        line(last.min(std::mem::size_of::<Leaf>()) - 1);
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = (leaf, st);
}

/// Starts loading `items` (up to [`NODE_LINES`] cache lines of them). Made for a tree's
/// quadtree nodes: every point's walk reads several, one after the other, so a node not in
/// the cache stalls the walk, where a tree's nodes together are a few kilobytes that stream
/// in at once. Profiles of a cage larger than the cache showed the walks' node loads as the
/// largest stalls; on `rook × 16` (700 MB of leaves) at factor 8 this made the frame 8–10 %
/// faster. Also Loop's trees' nodes, leaf frames and leaves ([`crate::surface::TriangleTree`]).
#[inline(always)]
pub(crate) fn prefetch_slice<T>(items: &[T]) {
    prefetch_lines::<TO_L1, T>(items);
}

/// [`prefetch_slice`] into the second-level cache only: for data asked for well before it is
/// read, many lines at a time. The stored leaf forms a group of points reads
/// (`engine::tree_points`: 476 bytes, 8 lines, a Loop leaf) are asked for as the leaf search
/// meets them, a dozen forms a patch within a few hundred nanoseconds; into L1 those requests
/// filled its miss buffers, and the search itself waited for them (a fifth of the vertex
/// stage of `loop_xord_interior` × 200 in a profile without the kernels). Into L2 the search
/// goes on, and a group finds its form one level down: the vertex stage 6–7 % faster at
/// factor 16 and at half a pixel (one thread, measured alternating with the L1 hint).
#[inline(always)]
pub(crate) fn prefetch_slice_to_l2<T>(items: &[T]) {
    prefetch_lines::<TO_L2, T>(items);
}

/// The cache levels a prefetch fills, numbered as `_mm_prefetch`'s hints: every level
/// (`_MM_HINT_T0`), or the second level and below (`_MM_HINT_T1`).
const TO_L1: i32 = 3;
const TO_L2: i32 = 2;
#[cfg(target_arch = "x86_64")]
const _: () = assert!(TO_L1 == std::arch::x86_64::_MM_HINT_T0 && TO_L2 == std::arch::x86_64::_MM_HINT_T1);

/// The lines of `items` (up to [`NODE_LINES`]) asked for with the hint `HINT`.
#[inline(always)]
fn prefetch_lines<const HINT: i32, T>(items: &[T]) {
    let bytes = std::mem::size_of_val(items).min(64 * NODE_LINES);
    let start = items.as_ptr().cast::<i8>();
    for offset in (0..bytes).step_by(64) {
        prefetch_at::<HINT>(start.wrapping_add(offset));
    }
}

/// Asks for the cache line holding `at` with the hint `HINT` (a hint: a prefetch never
/// faults, whatever the address, and changes nothing but the cache; elsewhere than x86-64,
/// nothing).
#[inline(always)]
fn prefetch_at<const HINT: i32>(at: *const i8) {
    // SAFETY: see above; nothing is read or written through `at`.
    #[cfg(target_arch = "x86_64")]
    unsafe {
        std::arch::x86_64::_mm_prefetch::<HINT>(at)
    };
    #[cfg(not(target_arch = "x86_64"))]
    let _ = at;
}

/// The most lines [`prefetch_slice`] asks for (4 KiB: the nodes of a deep tree).
const NODE_LINES: usize = 64;

/// Where a Bézier leaf's net starts, in bytes from the leaf's address.
#[inline(always)]
fn bezier_offset() -> usize {
    let leaf = Leaf { origin: DVec2::ZERO, size: 1.0, level: 0, patch: LeafPatch::Bezier([DVec3::ZERO; 16]) };
    match &leaf.patch {
        LeafPatch::Bezier(points) => points.as_ptr() as usize - (&leaf as *const Leaf as usize),
        LeafPatch::Gregory(_) => 0,
    }
}

/// A polynomial bicubic Bézier net's position and first derivatives at `st` (the leaves'
/// nets are polynomial: no weights to divide by, and nothing copied).
#[inline(always)]
fn bezier_derivatives(points: &[DVec3; 16], st: DVec2) -> (DVec3, DVec3, DVec3) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx") {
        // SAFETY: the CPU has AVX (checked above).
        return unsafe { bezier_derivatives_avx(points, st) };
    }
    bezier_derivatives_scalar(points, st)
}

/// [`bezier_derivatives`] with a point's three coordinates in one AVX register: the same
/// multiplications and additions in the same order (no fused multiply-adds), so the same
/// values bit for bit, in about a third of the instructions (glam's `DVec3` is scalar).
///
/// # Safety
/// The CPU must support AVX.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
unsafe fn bezier_derivatives_avx(points: &[DVec3; 16], st: DVec2) -> (DVec3, DVec3, DVec3) {
    // SAFETY: this function is compiled for AVX, so the sums are too.
    unsafe { bezier_sums_avx(points, st) }
}

/// The body of [`bezier_derivatives_avx`], to be inlined into functions compiled for AVX
/// ([`PatchTree::found_derivatives_avx`]); elsewhere its intrinsics would be calls.
///
/// # Safety
/// The CPU must support AVX.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn bezier_sums_avx(points: &[DVec3; 16], st: DVec2) -> (DVec3, DVec3, DVec3) {
    use std::arch::x86_64::*;
    let (bu, du, _) = super::bicubic::bernstein3(st.x);
    let (bv, dv, _) = super::bicubic::bernstein3(st.y);
    // `DVec3` is `#[repr(C)]` x, y, z: point k's coordinates are doubles 3k..3k+3.
    let base = points.as_ptr().cast::<f64>();
    let load = |k: usize| {
        if k < 15 {
            // The fourth double is the next point's x, inside the array; it is multiplied
            // and added into lane 3, which is never read.
            // SAFETY: doubles 3k..3k+4 lie in the 48 of `points` for k < 15.
            unsafe { _mm256_loadu_pd(base.add(3 * k)) }
        } else {
            // SAFETY: the mask reads doubles 45..48 only, the last point.
            unsafe { _mm256_maskload_pd(base.add(3 * k), _mm256_set_epi64x(0, -1, -1, -1)) }
        }
    };
    let (mut p, mut pu, mut pv) = (_mm256_setzero_pd(), _mm256_setzero_pd(), _mm256_setzero_pd());
    // Only the rows and columns whose weights can be nonzero ([`live`]): the terms left out
    // are products with exact zeros, so the sums are the full sums' values.
    let (rows, columns) = (live(st.x), live(st.y));
    for i in rows {
        let (mut c, mut cv) = (_mm256_setzero_pd(), _mm256_setzero_pd());
        for j in columns.clone() {
            let q = load(4 * i + j);
            c = _mm256_add_pd(c, _mm256_mul_pd(q, _mm256_set1_pd(bv[j])));
            cv = _mm256_add_pd(cv, _mm256_mul_pd(q, _mm256_set1_pd(dv[j])));
        }
        p = _mm256_add_pd(p, _mm256_mul_pd(c, _mm256_set1_pd(bu[i])));
        pu = _mm256_add_pd(pu, _mm256_mul_pd(c, _mm256_set1_pd(du[i])));
        pv = _mm256_add_pd(pv, _mm256_mul_pd(cv, _mm256_set1_pd(bu[i])));
    }
    let vec3 = |r: __m256d| {
        let mut a = [0.0; 4];
        // SAFETY: `a` holds four doubles.
        unsafe { _mm256_storeu_pd(a.as_mut_ptr(), r) };
        DVec3::new(a[0], a[1], a[2])
    };
    (vec3(p), vec3(pu), vec3(pv))
}

/// The indices of the cubic Bernstein polynomials whose value or derivative can be nonzero
/// at `t`: at an end of the interval only the two nearest (the others and their
/// derivatives are exactly 0 there, see [`super::bicubic::bernstein3`]). Why it matters:
/// at a dyadic rate most points of a deep tree fall on leaf corners (a factor-8 grid step is
/// eight leaves of level 6), where a net's sums read 4 of its 16 points, so a leaf costs
/// three cache lines instead of seven. Leaving the zero terms out leaves every nonzero sum
/// unchanged (a sum that is zero may change the sign of that zero).
#[inline(always)]
fn live(t: f64) -> std::ops::Range<usize> {
    if t == 0.0 {
        0..2
    } else if t == 1.0 {
        2..4
    } else {
        0..4
    }
}

/// [`bezier_derivatives`] one coordinate at a time.
#[inline(always)]
fn bezier_derivatives_scalar(points: &[DVec3; 16], st: DVec2) -> (DVec3, DVec3, DVec3) {
    let (bu, du, _) = super::bicubic::bernstein3(st.x);
    let (bv, dv, _) = super::bicubic::bernstein3(st.y);
    let (mut p, mut pu, mut pv) = (DVec3::ZERO, DVec3::ZERO, DVec3::ZERO);
    for i in 0..4 {
        // The column of the net along v for this u index, reduced in v first.
        let (mut c, mut cv) = (DVec3::ZERO, DVec3::ZERO);
        for j in 0..4 {
            let q = points[4 * i + j];
            c += q * bv[j];
            cv += q * dv[j];
        }
        p += c * bu[i];
        pu += c * du[i];
        pv += cv * bu[i];
    }
    (p, pu, pv)
}

/// A polynomial bicubic Bézier net at `st`.
fn bezier_position(points: &[DVec3; 16], st: DVec2) -> DVec3 {
    let b = |t: f64| {
        let s = 1.0 - t;
        [s * s * s, 3.0 * t * s * s, 3.0 * t * t * s, t * t * t]
    };
    let (bu, bv) = (b(st.x), b(st.y));
    let mut p = DVec3::ZERO;
    for i in 0..4 {
        for j in 0..4 {
            p += points[4 * i + j] * (bu[i] * bv[j]);
        }
    }
    p
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Deterministic points in `[-1, 1]³` from a seed (a 64-bit LCG).
    fn points<const N: usize>(seed: &mut u64) -> [DVec3; N] {
        let mut next = || {
            *seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (*seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        std::array::from_fn(|_| DVec3::new(next(), next(), next()))
    }

    /// A tree two levels deep: three Bézier leaves at level 1, and the fourth quadrant split
    /// into three Bézier leaves and a Gregory end cap.
    fn tree() -> PatchTree {
        let mut seed = 7;
        let mut leaves = Vec::new();
        let mut leaf = |origin: DVec2, size: f64, level: u8, gregory: bool, seed: &mut u64| {
            let patch = if gregory {
                LeafPatch::Gregory(Box::new(GregoryPatch { points: points(seed) }))
            } else {
                LeafPatch::Bezier(points(seed))
            };
            leaves.push(Leaf { origin, size, level, patch });
            Slot::Leaf(leaves.len() as u32 - 1)
        };
        let quarter = |q: usize| QUADRANTS[q];
        let top: [Slot; 4] = std::array::from_fn(|q| {
            if q == 2 {
                Slot::Node(1)
            } else {
                leaf(quarter(q), 0.5, 1, false, &mut seed)
            }
        });
        let deep: [Slot; 4] =
            std::array::from_fn(|q| leaf(DVec2::splat(0.5) + quarter(q) * 0.5, 0.25, 2, q == 1, &mut seed));
        PatchTree::from_parts(leaves, vec![top, deep], Slot::Node(0))
    }

    #[test]
    fn derivatives_each_gives_every_views_derivatives_bit_for_bit() {
        let tree = tree();
        let views =
            [tree.clone(), tree.transposed(), tree.rotated(3), tree.quadrant(2), tree.quadrant(1).rotated(1)];
        // Leaf borders (multiples of 1/4), the domain's edges and points between.
        let uvs: Vec<DVec2> =
            (0..=12).flat_map(|i| (0..=12).map(move |j| DVec2::new(i as f64, j as f64) / 12.0)).collect();
        let mut gregory_points = 0;
        let bits = |(p, du, dv): (DVec3, DVec3, DVec3)| [p, du, dv].map(|v| v.to_array().map(f64::to_bits));
        for view in &views {
            let mut seen = vec![false; uvs.len()];
            view.derivatives_each(&uvs, |k, got| {
                assert!(!seen[k], "point {k} handed over twice");
                seen[k] = true;
                assert_eq!(bits(got), bits(view.derivatives(uvs[k])), "at {:?}", uvs[k]);
            });
            assert!(seen.iter().all(|&s| s), "every point handed over");
            // The engines' AVX path (`outputs_each_avx`) is checked against the evaluation
            // by `corner_records_give_every_views_points_bit_for_bit`.
            gregory_points +=
                uvs.iter().filter(|&&uv| matches!(view.locate(uv).0.patch, LeafPatch::Gregory(_))).count();
        }
        assert!(gregory_points > 0, "the views reach the Gregory leaf");
    }

    #[test]
    fn find_near_places_every_point_as_the_walk_does() {
        let tree = tree();
        let views =
            [tree.clone(), tree.transposed(), tree.rotated(1), tree.quadrant(2), tree.quadrant(1).rotated(3)];
        // Leaf borders (multiples of 1/4, the domain's edges) and points between, row by row
        // (where the last leaf is met again), column by column, and scattered.
        let grid = |i: usize, j: usize| DVec2::new(i as f64, j as f64) / 12.0;
        let rows: Vec<DVec2> = (0..=12).flat_map(|j| (0..=12).map(move |i| grid(i, j))).collect();
        let columns: Vec<DVec2> = rows.iter().map(|uv| DVec2::new(uv.y, uv.x)).collect();
        let mut seed = 3u64;
        let scattered: Vec<DVec2> = (0..500)
            .map(|_| {
                let [p] = points::<1>(&mut seed);
                // Some of them on the borders: quarters of the domain.
                let snap = |x: f64| if x > 0.5 { (x * 4.0).round() / 4.0 } else { x.abs() };
                DVec2::new(snap(p.x), snap(p.y.abs()))
            })
            .collect();
        let bits =
            |(leaf, st, size): (usize, DVec2, f64)| (leaf, st.to_array().map(f64::to_bits), size.to_bits());
        let mut walks_saved = 0;
        for view in &views {
            for uvs in [&rows, &columns, &scattered] {
                let mut near = LeafSquare::default();
                for &uv in uvs {
                    let before = near;
                    assert_eq!(bits(view.find_near(uv, &mut near)), bits(view.find(uv)), "at {uv:?}");
                    walks_saved += usize::from(before.size > 0.0 && before.leaf == near.leaf);
                }
            }
        }
        assert!(walks_saved > 1000, "the last leaf is used ({walks_saved} points)");
    }

    /// The grid's walk places every interior point of a grid as the walk does, bit for bit,
    /// each leaf's points together and in the list's order, on views turned, transposed
    /// and quartered, and on grids whose lines fall on the leaves' borders and between.
    #[test]
    fn grid_leaves_place_every_point_as_the_walk_does() {
        let tree = tree();
        let views = [
            tree.clone(),
            tree.transposed(),
            tree.rotated(1),
            tree.rotated(2),
            tree.rotated(3),
            tree.transposed().rotated(1),
            tree.transposed().rotated(2),
            tree.quadrant(2),
            tree.quadrant(1).rotated(3),
            tree.quadrant(3).quadrant(0).transposed(),
        ];
        let grids = [[2, 2], [2, 9], [4, 4], [8, 8], [16, 8], [12, 12], [5, 7], [13, 3], [33, 17], [1, 6]];
        let bits =
            |(leaf, st, size): (usize, DVec2, f64)| (leaf, st.to_array().map(f64::to_bits), size.to_bits());
        let mut multi = 0;
        for view in &views {
            for cells in grids {
                let mut uvs = Vec::new();
                crate::pattern::core_grid::grid_interior(cells, &mut uvs);
                let mut seen = vec![false; uvs.len()];
                let mut runs: Vec<(usize, Vec<usize>)> = Vec::new();
                let mut lines = [Vec::new(), Vec::new()];
                view.grid_leaves(&uvs, cells, &mut lines, |leaf, k, st, size| {
                    assert!(!std::mem::replace(&mut seen[k], true), "{cells:?}: point {k} twice");
                    assert_eq!(bits((leaf, st, size)), bits(view.find(uvs[k])), "{cells:?}: point {k}");
                    match runs.last_mut() {
                        Some((l, ks)) if *l == leaf => ks.push(k),
                        _ => runs.push((leaf, vec![k])),
                    }
                });
                assert!(seen.iter().all(|&s| s), "{cells:?}: every point");
                let mut leaves: Vec<usize> = runs.iter().map(|r| r.0).collect();
                leaves.sort_unstable();
                leaves.dedup();
                assert_eq!(leaves.len(), runs.len(), "{cells:?}: a leaf's points together");
                for (_, ks) in &runs {
                    assert!(ks.windows(2).all(|w| w[0] < w[1]), "{cells:?}: in the list's order");
                    multi += usize::from(ks.len() > 1);
                }
            }
        }
        assert!(multi > 100, "leaves hold several points ({multi})");
    }

    /// `view`'s outputs at `uvs` by [`PatchTree::outputs_each`] (and its AVX build where the
    /// CPU has AVX) against the evaluation rounded to `f32`, bit for bit; returns how many
    /// points a [`CornerPoint`] gave.
    fn assert_outputs_are_the_evaluation(what: &str, view: &PatchTree, uvs: &[DVec2]) -> usize {
        let bits = |(p, n): ([f32; 3], [f32; 3])| (p.map(f32::to_bits), n.map(f32::to_bits));
        let expected: Vec<_> = uvs
            .iter()
            .map(|&uv| {
                let q = crate::surface::subdivision_point(view, uv, view.derivatives(uv));
                bits((q.position.as_vec3().to_array(), q.normal.as_vec3().to_array()))
            })
            .collect();
        let check = |got: &[Option<([f32; 3], [f32; 3])>], build: &str| {
            for (k, g) in got.iter().enumerate() {
                let g = g.unwrap_or_else(|| panic!("{what}, {build}: point {k} not handed over"));
                assert_eq!(bits(g), expected[k], "{what}, {build}: point {k} at {:?}", uvs[k]);
            }
        };
        let mut got = vec![None; uvs.len()];
        view.outputs_each(uvs, |k, p, n| {
            assert!(got[k].is_none(), "point {k} handed over twice");
            got[k] = Some((p, n));
        });
        check(&got, "scalar");
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx") {
            let mut got = vec![None; uvs.len()];
            // SAFETY: AVX is present (checked above).
            unsafe { view.outputs_each_avx(uvs, |k, p, n| got[k] = Some((p, n))) };
            check(&got, "AVX");
        }
        uvs.iter()
            .filter(|&&uv| {
                let (leaf, st, _) = view.find(uv);
                view.corner_point(leaf, st).is_some()
            })
            .count()
    }

    #[test]
    fn corner_records_give_every_views_points_bit_for_bit() {
        let tree = tree();
        let views = [
            tree.clone(),
            tree.transposed(),
            tree.rotated(1),
            tree.rotated(3).transposed(),
            tree.quadrant(2),
            tree.quadrant(1).rotated(2).transposed(),
        ];
        // Leaf corners (multiples of 1/4), the domain's edges and points between.
        let uvs: Vec<DVec2> =
            (0..=12).flat_map(|i| (0..=12).map(move |j| DVec2::new(i as f64, j as f64) / 12.0)).collect();
        let stored: usize = views
            .iter()
            .enumerate()
            .map(|(v, view)| assert_outputs_are_the_evaluation(&format!("view {v}"), view, &uvs))
            .sum();
        assert!(stored >= views.len() * 4, "only {stored} points from the records");
    }

    #[test]
    fn corner_records_give_every_cages_points_bit_for_bit() {
        // Creases (deep trees, Gregory end caps), n-gons (sub-face views, turned and
        // transposed), boundaries.
        let cages = [
            "catmark_rook",
            "catmark_cube_creases0",
            "catmark_pole8",
            "catmark_nonquads",
            "catmark_xord_boundary",
        ];
        let (mut all_stored, mut all_points) = (0, 0);
        for name in cages {
            let path = crate::test_support::data(&format!("subdivision/{name}.obj"));
            let mesh = crate::io::obj::read_obj(&path).expect("test cage");
            let set = crate::surface::SurfaceSet::from_subdivision_cage(&mesh, &path, Default::default())
                .expect("test cage");
            let (mut stored, mut points) = (0, 0);
            for (p, patch) in set.patches.iter().enumerate() {
                let crate::surface::Patch::Subdivision(view) = patch else { continue };
                // Bfr's rate 16 (8 on sub-faces: the same points of the face) and 5.
                for n in [16, 8, 5] {
                    let uvs: Vec<DVec2> = (0..=n)
                        .flat_map(|j| (0..=n).map(move |i| DVec2::new(i as f64, j as f64) / n as f64))
                        .collect();
                    stored +=
                        assert_outputs_are_the_evaluation(&format!("{name} patch {p} at {n}"), view, &uvs);
                    points += uvs.len();
                }
            }
            assert!(points > 0, "{name}: no isolated face");
            println!("{name}: {stored} of {points} points from the records");
            (all_stored, all_points) = (all_stored + stored, all_points + points);
        }
        assert!(all_stored * 10 > all_points, "only {all_stored} of {all_points} points from the records");
    }

    #[test]
    fn a_leaf_is_a_bezier_net_and_a_small_header() {
        // The frame streams leaves: an end cap's 20 points must not set every leaf's size.
        let size = std::mem::size_of::<Leaf>();
        println!("a leaf takes {size} bytes");
        assert!(size <= 16 * 24 + 40, "a leaf takes {size} bytes");
    }

    #[test]
    fn the_avx_sums_are_the_scalar_sums_bit_for_bit() {
        if !cfg!(target_arch = "x86_64") {
            return;
        }
        #[cfg(target_arch = "x86_64")]
        {
            assert!(
                std::arch::is_x86_feature_detected!("avx"),
                "this test needs an x86-64 processor with AVX (every one since 2011)"
            );
            let mut seed = 11;
            for k in 0..200 {
                let net: [DVec3; 16] = points(&mut seed);
                // Scaled and offset as real nets are (and with spread exponents).
                let net = net.map(|p| p * 10f64.powi(k % 7 - 3) + DVec3::splat(f64::from(k)));
                let st = DVec2::new(f64::from(k % 13) / 12.0, f64::from((k * 7) % 11) / 10.0);
                // SAFETY: AVX is present (asserted above).
                let avx = unsafe { bezier_derivatives_avx(&net, st) };
                let scalar = bezier_derivatives_scalar(&net, st);
                let bits =
                    |(p, du, dv): (DVec3, DVec3, DVec3)| [p, du, dv].map(|v| v.to_array().map(f64::to_bits));
                assert_eq!(bits(avx), bits(scalar), "net {k} at {st:?}");
            }
        }
    }
}
