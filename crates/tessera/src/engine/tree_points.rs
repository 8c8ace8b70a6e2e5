//! A specialisation of *evaluation* for the piecewise patches of subdivision surfaces
//! (Catmull-Clark's [`PatchTree`], Loop's [`TriangleTree`]: [`LeafTree`]): a patch's points
//! grouped by the leaf that holds them, and every group of a Bézier leaf (bicubic, quartic
//! triangle) evaluated in f32, [`LANES`] points at a time, by the same kernel as a whole
//! bicubic patch or Bézier triangle ([`super::point_blocks`]).
//!
//! **Why by leaf.** Evaluated point by point in f64, a tree's point cost 60–100 ns on the
//! machine this was written on (a regular face's about 5 ns), even where the leaves fit in
//! the cache: the point's own leaf lookup, Bernstein weights, sixteen-point sums and normal.
//! A leaf holds several points of a pattern wherever the tree is shallower than the
//! tessellation is fine: at Bfr's rate 16 on `catmark_rook`, three quarters of the points of
//! its isolated faces share their leaf with three others or more, over half with fifteen
//! others or more. Such a group pays once for moving its leaf's net to a local frame and
//! rounding it to f32, then takes the bicubic kernel's price per point. A point alone in its
//! leaf (a deep tree's), or in a Catmull-Clark end cap (a Gregory patch), keeps the f64
//! evaluation. Loop's trees are the same story with quartic triangles for bicubics
//! (`loop_xord_interior` at rate 16: f64 point by point took 91–97 % of the frame), and their
//! end caps, Gregory triangles, take the quartic kernel too, with each lane's blend of the
//! face points added ([`super::point_blocks::gregory_block`]).
//!
//! **Sparse trees** ([`eval_sparse`]): where a view's points are too few for its leaves to
//! be worth sorting, they are taken in their list's order, and those in a tree's coarse
//! leaves (levels 1–3, [`FORM_LEVEL`], whose f32 forms the set keeps once) go to the kernel
//! in blocks of consecutive points of one leaf; the rest take the f64 path.
//!
//! **Same frame, same fallbacks.** The leaf's net is moved to the leaf's own local frame
//! ([`super::point_blocks::local_frame`]), so f32 carries the leaf's detail at full relative
//! precision however deep the leaf; the reliability rule of the normals
//! ([`super::point_blocks::cross_normals`]) applies unchanged, a point failing it takes the f64
//! evaluation (whose normal rule is the patch's own: [`crate::surface::subdivision_point`],
//! [`crate::surface::triangle_point`]). The normal of a leaf's derivatives is the patch's up to
//! its sign: the view's derivatives are the leaf's scaled by a positive factor and turned by
//! quarter turns (which keep their cross product), a turned Loop leaf's both negated (which
//! keeps it too), and exchanged where the view is transposed or the triangle swapped (which
//! reverses it).
//!
//! **Watertight as before**: which patch evaluates a point and at which parameters is
//! unchanged; only how its position and normal are rounded.

use std::cell::RefCell;

use glam::DVec2;

use super::point_blocks::{
    gregory_block, gregory_quad_block, leaf_block, triangle_block, Block, LocalGregory, LocalGregoryQuad,
    LocalQuartic, LANES,
};
use super::uniform_quads::LocalPatch;
use super::VertexSlices;
use crate::surface::patch_tree::{prefetch_slice, prefetch_slice_to_l2, LeafPatch, LeafSquare, PatchTree};
use crate::surface::triangle_tree::TriangleLeafPatch;
use crate::surface::{loop_point, subdivision_point, SurfacePoint, SurfaceSet, TriangleTree};

/// A point of the patch's list and where [`LeafTree::find`] put it.
#[derive(Clone, Copy)]
pub(super) struct Found {
    leaf: u32,
    k: u32,
    st: DVec2,
    /// The leaf's side where the tree's search gives it ([`PatchTree::find`]); else unused.
    size: f64,
}

/// A piecewise patch whose points [`eval`] groups by leaf: what differs between Catmull-Clark's
/// trees and Loop's. Everything is inlined into [`eval`] (and so compiled for its caller's
/// instructions).
pub(super) trait LeafTree {
    /// A Bézier leaf's net in its local frame, as [`LeafTree::block`] takes it.
    type Local;
    /// Points per leaf of the view, on average, from which grouping pays ([`worth_grouping`]).
    const MIN_DENSITY: f64;
    /// The fewest points of one leaf evaluated as a group where [`eval`] makes the leaf's
    /// form; fewer take the f64 evaluation, where moving the net to its frame would cost more
    /// than it saves.
    const MIN_GROUP: usize;
    /// How many leaves the tree has.
    fn leaf_count(&self) -> usize;
    /// The share of the tree's domain the patch covers (a view of a quadrant: a quarter).
    fn view_area(&self) -> f64;
    /// What a search keeps from point to point ([`PatchTree::find_near`]'s last leaf).
    type Near: Default;
    /// The leaf of `uv` and `uv` in its parameters, as [`Found`] holds them (`k` unset);
    /// `near` is the last search's.
    fn find(&self, uv: DVec2, near: &mut Self::Near) -> Found;
    /// Puts the interior points `uvs` of the `cells` grid into `grouped`, each leaf's points
    /// together, as [`LeafTree::find`] would place them, and returns true; false (the
    /// default), leaving `grouped` as it is, where the tree has no walk for a grid.
    fn group_grid(
        &self,
        _uvs: &[DVec2],
        _cells: [u32; 2],
        _lines: &mut [Vec<f64>; 2],
        _grouped: &mut Vec<Found>,
    ) -> bool {
        false
    }
    /// Starts loading the quadtree's nodes (a hint).
    fn prefetch_nodes(&self) {}
    /// Starts loading what evaluating `leaf` at `st` reads (a hint).
    fn prefetch_leaf(&self, _leaf: usize, _st: DVec2) {}
    /// Leaf `leaf`'s net in its local frame.
    fn local(&self, leaf: usize) -> Self::Local;
    /// The leaf at each lane's parameters, its normal the leaf's own.
    fn block<const FMA: bool, const L: usize>(local: &Self::Local, u: &[f32; L], v: &[f32; L]) -> Block<L>;
    /// Whether the patch's normal is the opposite of its leaves' (module doc).
    fn reverses_normal(&self) -> bool;
    /// The point `f` in f64, as the generic evaluation of the patch at `uv` gives it.
    /// With `FMA`, the CPU has AVX2 and FMA.
    fn single<const FMA: bool>(&self, f: &Found, uv: DVec2) -> SurfacePoint;
    /// The point `f` as [`LeafTree::single`] rounds it to the output, where the tree keeps
    /// it ([`crate::surface::patch_tree::CornerPoint`]).
    fn stored_point(&self, _f: &Found) -> Option<([f32; 3], [f32; 3])> {
        None
    }
}

impl LeafTree for PatchTree {
    type Local = CatmarkLeaf;
    type Near = LeafSquare;
    /// Below it most groups would be single points, which pay for finding and grouping on
    /// top of their f64 evaluation and lose [`PatchTree::derivatives_each`]'s look-ahead.
    /// Measured on one thread: grouping every list made `catmark_rook` at rate 16 (creases
    /// isolate its faces six levels deep) 25–45 % slower; with this rule it is unchanged, and
    /// `catmark_cube_creases0` at factor 64 (points dense next to its leaves) a third faster.
    const MIN_DENSITY: f64 = 4.0;
    const MIN_GROUP: usize = 2;

    #[inline(always)]
    fn leaf_count(&self) -> usize {
        self.leaves().len()
    }

    #[inline(always)]
    fn view_area(&self) -> f64 {
        let (_, view) = self.view_square();
        view * view
    }

    #[inline(always)]
    fn find(&self, uv: DVec2, near: &mut LeafSquare) -> Found {
        let (leaf, st, size) = PatchTree::find_near(self, uv, near);
        Found { leaf: leaf as u32, k: 0, st, size }
    }

    #[inline(always)]
    fn group_grid(
        &self,
        uvs: &[DVec2],
        cells: [u32; 2],
        lines: &mut [Vec<f64>; 2],
        grouped: &mut Vec<Found>,
    ) -> bool {
        self.grid_leaves(uvs, cells, lines, |leaf, k, st, size| {
            grouped.push(Found { leaf: leaf as u32, k: k as u32, st, size });
        });
        true
    }

    #[inline(always)]
    fn prefetch_nodes(&self) {
        PatchTree::prefetch_nodes(self);
    }

    #[inline(always)]
    fn prefetch_leaf(&self, leaf: usize, st: DVec2) {
        PatchTree::prefetch_leaf(self, leaf, st);
    }

    #[inline(always)]
    fn local(&self, leaf: usize) -> CatmarkLeaf {
        catmark_leaf(self, leaf)
    }

    #[inline(always)]
    fn block<const FMA: bool, const L: usize>(local: &CatmarkLeaf, u: &[f32; L], v: &[f32; L]) -> Block<L> {
        local.block::<FMA, L>(u, v)
    }

    #[inline(always)]
    fn reverses_normal(&self) -> bool {
        self.is_transposed()
    }

    #[inline(always)]
    fn stored_point(&self, f: &Found) -> Option<([f32; 3], [f32; 3])> {
        self.corner_point(f.leaf as usize, f.st)
    }

    #[inline(always)]
    fn single<const FMA: bool>(&self, f: &Found, uv: DVec2) -> SurfacePoint {
        #[cfg(target_arch = "x86_64")]
        if FMA {
            // SAFETY: `FMA` is only set for a CPU with AVX2 and FMA (the caller's precondition).
            let d = unsafe { self.found_derivatives_avx(f.leaf as usize, f.st, f.size) };
            return subdivision_point(self, uv, d);
        }
        subdivision_point(self, uv, self.found_derivatives(f.leaf as usize, f.st, f.size))
    }
}

/// A Catmull-Clark leaf in its local frame: a bicubic piece or a Gregory end cap.
pub(super) enum CatmarkLeaf {
    Bicubic(LocalPatch),
    Gregory(LocalGregoryQuad),
}

impl CatmarkLeaf {
    /// The leaf at each lane's `(u, v)` (its own parameters).
    #[inline(always)]
    fn block<const FMA: bool, const L: usize>(&self, u: &[f32; L], v: &[f32; L]) -> Block<L> {
        match self {
            CatmarkLeaf::Bicubic(net) => leaf_block::<FMA, L>(net, u, v),
            CatmarkLeaf::Gregory(g) => gregory_quad_block::<FMA, L>(g, u, v),
        }
    }
}

/// Leaf `leaf` of `tree` in its local frame ([`LeafTree::local`]; the coarse leaves'
/// [`super::point_blocks::PointBlocks`] keeps per set, [`FORM_LEVEL`]). Cost: O(1).
#[inline(always)]
pub(super) fn catmark_leaf(tree: &PatchTree, leaf: usize) -> CatmarkLeaf {
    match &tree.leaves()[leaf].patch {
        LeafPatch::Bezier(net) => CatmarkLeaf::Bicubic(LocalPatch::from_net(net)),
        LeafPatch::Gregory(g) => CatmarkLeaf::Gregory(LocalGregoryQuad::new(g)),
    }
}

/// A Loop leaf in its local frame: a quartic piece or a Gregory end cap.
pub(super) enum LoopLeaf {
    Quartic(LocalQuartic),
    Gregory(LocalGregory),
}

/// Leaf `leaf` of `tree` in its local frame ([`LeafTree::local`]): what
/// [`super::point_blocks::PointBlocks`] keeps per leaf of a set for [`eval`]. Cost: O(1).
pub(super) fn loop_leaf(tree: &TriangleTree, leaf: usize) -> LoopLeaf {
    match &tree.leaves()[leaf].patch {
        TriangleLeafPatch::Quartic(q) => LoopLeaf::Quartic(LocalQuartic::from_net(&q.points)),
        TriangleLeafPatch::Gregory(g) => LoopLeaf::Gregory(LocalGregory::new(g)),
    }
}

impl LeafTree for TriangleTree {
    type Local = LoopLeaf;
    type Near = ();
    /// Every list: Loop's f64 path has no look-ahead to lose, and finding a point's leaf is
    /// its cost whichever way. An edge's inner samples (a few leaves along it, but fewer points
    /// than the density rule asks of the whole tree) were a third of `loop_xord_interior`'s
    /// vertex time at factor 32 before this.
    const MIN_DENSITY: f64 = 0.0;
    /// Timed one leaf at a time (`loop_xord_interior`'s leaves, optimized test build, no
    /// AVX2): moving a quartic leaf's net to its frame took about 115 ns, a Gregory leaf's
    /// 165, a block of 4 lanes 60 and 80 ns, against 80 and 113 ns a point in f64, so a
    /// group of two costs more in f32 (175 against 160 ns, 245 against 225) and one of three
    /// less.
    const MIN_GROUP: usize = 3;

    #[inline(always)]
    fn leaf_count(&self) -> usize {
        self.leaves().len()
    }

    #[inline(always)]
    fn view_area(&self) -> f64 {
        1.0
    }

    #[inline(always)]
    fn find(&self, uv: DVec2, _: &mut ()) -> Found {
        let (leaf, st) = TriangleTree::find(self, uv);
        Found { leaf: leaf as u32, k: 0, st, size: 0.0 }
    }

    #[inline(always)]
    fn prefetch_nodes(&self) {
        TriangleTree::prefetch_nodes(self);
    }

    #[inline(always)]
    fn prefetch_leaf(&self, leaf: usize, _st: DVec2) {
        TriangleTree::prefetch_leaf(self, leaf);
    }

    #[inline(always)]
    fn local(&self, leaf: usize) -> LoopLeaf {
        loop_leaf(self, leaf)
    }

    #[inline(always)]
    fn block<const FMA: bool, const L: usize>(local: &LoopLeaf, u: &[f32; L], v: &[f32; L]) -> Block<L> {
        match local {
            LoopLeaf::Quartic(q) => triangle_block::<FMA, L, 15, 10>(q, u, v),
            LoopLeaf::Gregory(g) => gregory_block::<FMA, L>(g, u, v),
        }
    }

    #[inline(always)]
    fn reverses_normal(&self) -> bool {
        self.is_swapped()
    }

    #[inline(always)]
    fn single<const FMA: bool>(&self, f: &Found, uv: DVec2) -> SurfacePoint {
        loop_point(self, uv, self.found_derivatives(f.leaf as usize, f.st))
    }
}

/// A patch's points by leaf: the scratch of [`eval`], reused from patch to patch (a frame's
/// loop allocates nothing once it has grown).
#[derive(Default)]
struct Scratch {
    /// The points in the list's order.
    found: Vec<Found>,
    /// Per leaf of the tree, how many points it holds, then where its group starts.
    starts: Vec<u32>,
    /// The points grouped by leaf (a counting sort of `found`: O(points + leaves), where a
    /// comparison sort took a third of a fine tessellation's time).
    grouped: Vec<Found>,
    /// A grid's lines in the tree's coordinates ([`PatchTree::grid_leaves`]).
    lines: [Vec<f64>; 2],
}

thread_local! {
    static SCRATCH: RefCell<Scratch> = RefCell::new(Scratch::default());
}

/// Whether [`eval`] is the faster way to evaluate `points` points of `tree`: they are dense
/// next to the leaves the view covers ([`LeafTree::MIN_DENSITY`], estimated from the tree's
/// leaf count and the view's share of the tree's domain), and at least a group. Cost: O(1).
#[inline(always)]
pub(super) fn worth_grouping<T: LeafTree>(tree: &T, points: usize) -> bool {
    points >= T::MIN_GROUP && points as f64 >= T::MIN_DENSITY * tree.leaf_count() as f64 * tree.view_area()
}

/// Evaluates patch `p` of `set`, the piecewise patch `tree`, at `uvs` into `out`, as
/// [`VertexSlices::put`] does point by point, the leaves' local forms taken from `locals`
/// where given (the first `locals.len()` leaves', in leaf order), else
/// made for each group. With `grid`, `uvs` are that grid's interior points, grouped by a walk
/// of the tree where it has one ([`LeafTree::group_grid`]). Preconditions:
/// `set.patches[p]` is `tree`; `out` holds `uvs.len()` vertices; with `FMA`, the CPU has AVX2
/// and FMA. Cost: a leaf lookup per point and a sort of the points by leaf (O(n + leaves), or
/// O(n log n) for fewer points than leaves), or the grid's walk (O(nodes holding points +
/// n)); per group, moving its net to f32 once (unless
/// `locals` holds it) and the kernel's price per point; per single point, the f64 evaluation.
/// No allocation once the thread's scratch has grown.
#[inline(always)]
pub(super) fn eval<const FMA: bool, T: LeafTree>(
    set: &SurfaceSet,
    p: usize,
    tree: &T,
    locals: Option<&[T::Local]>,
    uvs: &[DVec2],
    grid: Option<[u32; 2]>,
    mut out: VertexSlices<'_>,
) {
    // Taken out of the thread's slot and put back, not borrowed in a closure: a closure would
    // not be compiled for the caller's AVX2 and FMA.
    let mut scratch = SCRATCH.take();
    let Scratch { found, starts, grouped, lines } = &mut scratch;
    grouped.clear();
    tree.prefetch_nodes();
    if grid.is_some_and(|cells| tree.group_grid(uvs, cells, lines, grouped)) {
        // What each group will read, loading while the groups before it are evaluated.
        for group in grouped.chunk_by(|a, b| a.leaf == b.leaf) {
            prefetch_group(tree, locals, &group[0]);
        }
    } else {
        search_and_sort(tree, locals, uvs, found, starts, grouped);
    }
    let flip = tree.reverses_normal();
    for group in grouped.chunk_by(|a, b| a.leaf == b.leaf) {
        let leaf = group[0].leaf as usize;
        let made;
        let local = match locals.and_then(|l| l.get(leaf)) {
            // A leaf's form already made: the kernel costs a lone point less than f64 does.
            Some(local) => Some(local),
            _ if group.len() < T::MIN_GROUP => None,
            None => {
                made = tree.local(leaf);
                Some(&made)
            }
        };
        match local {
            Some(local) if group.len() <= LANES / 2 => {
                blocks::<FMA, { LANES / 2 }, T>(set, p, local, flip, group, uvs, &mut out);
            }
            Some(local) => blocks::<FMA, LANES, T>(set, p, local, flip, group, uvs, &mut out),
            None => {
                for f in group {
                    let k = f.k as usize;
                    if let Some((position, normal)) = tree.stored_point(f) {
                        (out.pos[k], out.nrm[k]) = (position, normal);
                        continue;
                    }
                    let q = tree.single::<FMA>(f, uvs[k]);
                    out.pos[k] = q.position.as_vec3().to_array();
                    out.nrm[k] = q.normal.as_vec3().to_array();
                }
            }
        }
    }
    SCRATCH.set(scratch);
    out.uv.iter_mut().zip(uvs).for_each(|(x, uv)| *x = uv.as_vec2().to_array());
    out.patch.fill(p as u32);
}

/// Starts loading what the group of `f`'s leaf will read: the leaf's stored form where
/// `locals` has it, else its net (a hint).
#[inline(always)]
fn prefetch_group<T: LeafTree>(tree: &T, locals: Option<&[T::Local]>, f: &Found) {
    match locals.and_then(|l| l.get(f.leaf as usize)) {
        Some(local) => prefetch_slice_to_l2(std::slice::from_ref(local)),
        None => tree.prefetch_leaf(f.leaf as usize, f.st),
    }
}

/// Finds the leaf of each of `uvs` ([`LeafTree::find`], into `found` in the list's order) and
/// sorts them by leaf into `grouped`, empty on entry (`starts`: a counting sort's counters),
/// starting to load what each group will read. Cost: a leaf lookup per point, and
/// O(n + leaves), or O(n log n) for fewer points than leaves.
#[inline(always)]
fn search_and_sort<T: LeafTree>(
    tree: &T,
    locals: Option<&[T::Local]>,
    uvs: &[DVec2],
    found: &mut Vec<Found>,
    starts: &mut Vec<u32>,
    grouped: &mut Vec<Found>,
) {
    found.clear();
    let mut last = u32::MAX;
    let mut near = T::Near::default();
    for (k, &uv) in uvs.iter().enumerate() {
        let f = Found { k: k as u32, ..tree.find(uv, &mut near) };
        if f.leaf != last {
            prefetch_group(tree, locals, &f);
            last = f.leaf;
        }
        found.push(f);
    }
    let leaf_count = tree.leaf_count();
    if found.len() < leaf_count {
        // Fewer points than leaves: a comparison sort, O(n log n), costs less than a pass
        // over every leaf's counter.
        grouped.extend_from_slice(found);
        grouped.sort_unstable_by_key(|f| (f.leaf, f.k));
    } else {
        // A counting sort, O(points + leaves); each leaf's points stay in the list's order.
        starts.clear();
        starts.resize(leaf_count + 1, 0);
        for f in found.iter() {
            starts[f.leaf as usize + 1] += 1;
        }
        for l in 1..starts.len() {
            starts[l] += starts[l - 1];
        }
        grouped.resize(found.len(), Found { leaf: 0, k: 0, st: DVec2::ZERO, size: 0.0 });
        for f in found.iter() {
            let at = &mut starts[f.leaf as usize];
            grouped[*at as usize] = *f;
            *at += 1;
        }
    }
}

/// The points of `group` (one leaf, whose net is `local`) in blocks of `L` lanes.
#[inline(always)]
fn blocks<const FMA: bool, const L: usize, T: LeafTree>(
    set: &SurfaceSet,
    p: usize,
    local: &T::Local,
    flip: bool,
    group: &[Found],
    uvs: &[DVec2],
    out: &mut VertexSlices<'_>,
) {
    for chunk in group.chunks(L) {
        // Spare lanes repeat the last point: a real point, so its margin is meaningful.
        let mut u = [0f32; L];
        let mut v = [0f32; L];
        for l in 0..L {
            let st = chunk[l.min(chunk.len() - 1)].st;
            u[l] = st.x as f32;
            v[l] = st.y as f32;
        }
        let block = T::block::<FMA, L>(local, &u, &v);
        for (l, f) in chunk.iter().enumerate() {
            let k = f.k as usize;
            let (pos, nrm) = block.lane_or_exact(l, set, p, uvs[k]);
            // The kernel's normal is the leaf's; the f64 fallback's is already the view's.
            let turn = flip && block.margin[l] > 0.0;
            out.pos[k] = pos;
            out.nrm[k] = if turn { nrm.map(|x| -x) } else { nrm };
        }
    }
}

/// The finest level of a Catmull-Clark tree's leaves that [`super::point_blocks::PointBlocks`]
/// keeps in f32 ([`catmark_leaf`]; [`PatchTree::coarse_leaves`]), for [`eval_sparse`].
///
/// **Why these.** A deep tree is sparse as a whole (most of its leaves are small and hold no
/// point) while its few coarse leaves hold most of its points: at Bfr's rate 16 on
/// `catmark_rook`, 61,000 of the 77,000 points a copy evaluates one by one lie in leaves of
/// levels 1–3 (4 to 48 points a leaf), against 16,000 in the 97,000 leaves of levels 4–6 (a
/// point in six leaves). Kept in f32 those points take the bicubic kernel, several at a
/// time, without the f64 path's per-point sums, and without the cost of moving a net to its
/// frame for every list that meets it (a level of 4 measured no faster). **Memory:** the
/// leaves tile the tree's square, so at most 64 are of levels ≤ 3; 208 bytes each, about
/// half a leaf's own 424 (the rook copied 65 times: 422,000 forms, 88 MB beside its trees'
/// 3 GB).
pub(crate) const FORM_LEVEL: u8 = 3;

/// Points of one leaf's f32 form waiting to be evaluated together ([`eval_sparse`]).
struct Pending<'t> {
    form: Option<&'t CatmarkLeaf>,
    p: u32,
    flip: bool,
    count: usize,
    k: [u32; LANES],
    st: [DVec2; LANES],
    uv: [DVec2; LANES],
}

impl Pending<'_> {
    /// Evaluates the waiting points into `out` and empties the block.
    #[inline(always)]
    fn flush<const FMA: bool>(&mut self, set: &SurfaceSet, out: &mut VertexSlices<'_>) {
        if self.count <= LANES / 2 {
            self.lanes::<FMA, { LANES / 2 }>(set, out);
        } else {
            self.lanes::<FMA, LANES>(set, out);
        }
        self.count = 0;
    }

    #[inline(always)]
    fn lanes<const FMA: bool, const L: usize>(&self, set: &SurfaceSet, out: &mut VertexSlices<'_>) {
        let Some(form) = self.form else { return };
        // Spare lanes repeat the last point: a real point, so its margin is meaningful.
        let (mut u, mut v) = ([0f32; L], [0f32; L]);
        for l in 0..L {
            let st = self.st[l.min(self.count - 1)];
            (u[l], v[l]) = (st.x as f32, st.y as f32);
        }
        let block = form.block::<FMA, L>(&u, &v);
        for l in 0..self.count {
            let k = self.k[l] as usize;
            let (pos, nrm) = block.lane_or_exact(l, set, self.p as usize, self.uv[l]);
            // The kernel's normal is the leaf's; the f64 fallback's is already the view's.
            let turn = self.flip && block.margin[l] > 0.0;
            out.pos[k] = pos;
            out.nrm[k] = if turn { nrm.map(|x| -x) } else { nrm };
            out.uv[k] = self.uv[l].as_vec2().to_array();
            out.patch[k] = self.p;
        }
    }
}

/// Evaluates a stream of points on Catmull-Clark trees, `item(k) = (patch, view, forms, uv)`
/// (the patch's tree, [`catmark_leaf`] of each of its tree's first leaves, the point), into
/// `out` (vertex `k` each: position, normal, parameters, patch id). Each point on its own
/// rule, whatever the points around it, so that a point's value does not depend on the list
/// it comes in (the engine's edges are evaluated as one stream or patch by patch): a point at
/// its leaf's corner 0 from the leaf's [`crate::surface::patch_tree::CornerPoint`]; a point
/// of a leaf with a form by the f32 bicubic kernel, consecutive points of one leaf in one
/// block; every other in f64 ([`PatchTree::found_derivatives_avx`]). The leaves are found
/// and asked for ahead ([`crate::surface::patch_tree::Lookahead`]). Preconditions: `out`
/// holds `n` vertices; with `FMA`, the CPU has AVX2 and FMA. Cost: per point a leaf search
/// (none in the last point's leaf), then a record's read, a kernel lane, or the f64
/// evaluation; no allocation.
#[inline(always)]
pub(super) fn eval_sparse<'t, const FMA: bool>(
    set: &'t SurfaceSet,
    n: usize,
    item: impl Fn(usize) -> (u32, &'t PatchTree, &'t [CatmarkLeaf], DVec2),
    mut out: VertexSlices<'_>,
) {
    use crate::surface::patch_tree::{Lookahead, AHEAD};
    let empty = || Pending {
        form: None,
        p: 0,
        flip: false,
        count: 0,
        k: [0; LANES],
        st: [DVec2::ZERO; LANES],
        uv: [DVec2::ZERO; LANES],
    };
    let mut pending: [Pending; OPEN_BLOCKS] = std::array::from_fn(|_| empty());
    let mut next_slot = 0;
    let mut ahead = Lookahead::default();
    let stream = |k: usize| {
        let (_, view, _, uv) = item(k);
        (view, uv)
    };
    let prefetch = |k: usize, view: &PatchTree, leaf: usize, st: DVec2| match item(k).2.get(leaf) {
        Some(form) if st != DVec2::ZERO => prefetch_slice(std::slice::from_ref(form)),
        _ => view.prefetch_point(leaf, st, true),
    };
    for start in (0..n).step_by(AHEAD) {
        for (i, f) in ahead.find(start, n, stream, prefetch).iter().flatten().enumerate() {
            let k = start + i;
            let (view, uv, leaf, st) = (f.view, f.uv, f.leaf, f.st);
            let (p, _, forms, _) = item(k);
            if let Some((position, normal)) = view.corner_point(leaf, st) {
                (out.pos[k], out.nrm[k]) = (position, normal);
            } else if let Some(form) = forms.get(leaf) {
                let open = pending
                    .iter()
                    .position(|b| b.count > 0 && b.p == p && b.form.is_some_and(|f| std::ptr::eq(f, form)));
                let slot = match open {
                    Some(slot) => slot,
                    None => {
                        let slot = pending.iter().position(|b| b.count == 0).unwrap_or(next_slot);
                        next_slot = (slot + 1) % OPEN_BLOCKS;
                        slot
                    }
                };
                let block = &mut pending[slot];
                if block.count > 0 && open.is_none() {
                    block.flush::<FMA>(set, &mut out);
                }
                if block.count == 0 {
                    (block.form, block.p, block.flip) = (Some(form), p, view.is_transposed());
                }
                let at = block.count;
                (block.k[at], block.st[at], block.uv[at]) = (k as u32, st, uv);
                block.count += 1;
                if block.count == LANES {
                    block.flush::<FMA>(set, &mut out);
                }
                continue;
            } else {
                #[cfg(target_arch = "x86_64")]
                let d = if FMA {
                    // SAFETY: `FMA` is only set for a CPU with AVX2 and FMA (the caller's precondition).
                    unsafe { view.found_derivatives_avx(leaf, st, f.size) }
                } else {
                    view.found_derivatives(leaf, st, f.size)
                };
                #[cfg(not(target_arch = "x86_64"))]
                let d = view.found_derivatives(leaf, st, f.size);
                let q = subdivision_point(view, uv, d);
                (out.pos[k], out.nrm[k]) = (q.position.as_vec3().to_array(), q.normal.as_vec3().to_array());
            }
            out.uv[k] = uv.as_vec2().to_array();
            out.patch[k] = p;
        }
    }
    for block in &mut pending {
        if block.count > 0 {
            block.flush::<FMA>(set, &mut out);
        }
    }
}

/// How many leaves' blocks [`eval_sparse`] keeps open at once: a pattern's points come row by
/// row, so a leaf's points are a run of each of several rows, between other leaves' runs.
/// (One open block measured the same on the rook within the host's noise; four fill the
/// blocks of a leaf that several rows cross.)
const OPEN_BLOCKS: usize = 4;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cpu::has_avx2_fma;
    use crate::engine::point_blocks::PointBlocks;
    use crate::surface::Patch;
    use glam::Vec3;

    /// `eval(fma, out)` (patch `p` of `set` at `uvs`, with the AVX2 and FMA kernels or without;
    /// only the builds the CPU has) against the generic f64 evaluation point by point:
    /// positions within 1e-6 of `size`, normals within 1e-5 (the f32 kernels' promise),
    /// parameters and patch ids exact. Returns, per point, how many of the builds made its
    /// normal in the kernels (it differs from the f64 path's in its rounding).
    fn assert_matches_f64(
        what: &str,
        set: &SurfaceSet,
        p: usize,
        uvs: &[DVec2],
        size: f32,
        eval: impl Fn(bool, VertexSlices<'_>),
    ) -> Vec<usize> {
        let mut kernels = vec![0; uvs.len()];
        for fma in [false, true] {
            if fma && !has_avx2_fma() {
                continue;
            }
            let m = uvs.len();
            let (mut pos, mut nrm, mut uv, mut patch) =
                (vec![[0f32; 3]; m], vec![[0f32; 3]; m], vec![[0f32; 2]; m], vec![0u32; m]);
            eval(fma, VertexSlices { pos: &mut pos, nrm: &mut nrm, uv: &mut uv, patch: &mut patch });
            for (k, &at) in uvs.iter().enumerate() {
                let q = set.patches[p].eval(at);
                let what = format!("{what} fma {fma} at {at:?}");
                let dp = (Vec3::from(pos[k]) - q.position.as_vec3()).length() / size;
                let dn = (Vec3::from(nrm[k]) - q.normal.as_vec3()).length();
                assert!(dp <= 1e-6, "{what}: position off by {dp:e} of the size");
                assert!(dn <= 1e-5, "{what}: normal off by {dn:e}");
                assert_eq!(uv[k], at.as_vec2().to_array(), "{what}");
                assert_eq!(patch[k], p as u32, "{what}");
                kernels[k] += usize::from(nrm[k] != q.normal.as_vec3().to_array());
            }
        }
        kernels
    }

    /// That `kernels` (summed over the builds, [`assert_matches_f64`]) is more than half of
    /// `points`, which are more than `fewest`: most of those points' normals came from the
    /// kernels, and the test saw enough of them.
    fn assert_mostly_kernels(what: &str, kernels: usize, points: usize, fewest: usize) {
        assert!(points > fewest, "only {points} points in {what}");
        assert!(kernels * 2 > points, "only {kernels} of {points} normals from the kernels in {what}");
    }

    /// [`eval`] with the kernels `fma` says (the engine's two builds).
    fn eval_either<T: LeafTree>(
        fma: bool,
        set: &SurfaceSet,
        p: usize,
        tree: &T,
        uvs: &[DVec2],
        out: VertexSlices<'_>,
    ) {
        if fma {
            #[cfg(target_arch = "x86_64")]
            // SAFETY: the callers ask for these kernels only where the CPU has AVX2 and FMA.
            unsafe {
                eval_avx2_fma(set, p, tree, uvs, out)
            };
        } else {
            eval::<false, T>(set, p, tree, None, uvs, None, out);
        }
    }

    /// A pattern's interior grid grouped by the tree's walk ([`LeafTree::group_grid`]) gives
    /// every vertex the bits the search and sort give it, through [`PointBlocks`] as the
    /// engine calls it (the coarse leaves' stored forms included): on isolated faces of the
    /// creased cube and of the rook (end caps, creases, deep leaves), views of each (turned,
    /// transposed), grids whose lines meet the leaves' borders and grids whose lines do not,
    /// with both builds' kernels.
    #[test]
    fn grid_groups_give_the_searched_vertices_bit_for_bit() {
        let mut compared = 0;
        for cage in ["subdivision/catmark_cube_creases0.obj", "subdivision/catmark_rook.obj"] {
            let path = crate::test_support::data(cage);
            let mesh = crate::io::obj::read_obj(&path).unwrap();
            let mut set = SurfaceSet::from_subdivision_cage(&mesh, &path, Default::default()).unwrap();
            let trees: Vec<(usize, PatchTree)> = (set.patches.iter().enumerate())
                .filter_map(|(p, patch)| match patch {
                    Patch::Subdivision(t) => Some((p, (**t).clone())),
                    _ => None,
                })
                .take(12)
                .collect();
            assert!(!trees.is_empty(), "{cage}: isolated faces");
            for (p, tree) in trees {
                let views = [tree.clone(), tree.transposed(), tree.rotated(1), tree.rotated(2).transposed()];
                for view in views {
                    set.patches[p] = Patch::Subdivision(Box::new(view.clone()));
                    let blocks = [false, true].map(|fma| PointBlocks::for_set(&set, fma && has_avx2_fma()));
                    for cells in [[8, 8], [16, 16], [13, 7], [5, 29], [2, 3]] {
                        let mut uvs = Vec::new();
                        crate::pattern::core_grid::grid_interior(cells, &mut uvs);
                        for fma in [false, true] {
                            if fma && !has_avx2_fma() {
                                continue;
                            }
                            let run = |grid: Option<[u32; 2]>| {
                                let m = uvs.len();
                                let (mut pos, mut nrm, mut uv, mut patch) = (
                                    vec![[0f32; 3]; m],
                                    vec![[0f32; 3]; m],
                                    vec![[0f32; 2]; m],
                                    vec![0u32; m],
                                );
                                let out = VertexSlices {
                                    pos: &mut pos,
                                    nrm: &mut nrm,
                                    uv: &mut uv,
                                    patch: &mut patch,
                                };
                                blocks[usize::from(fma)].eval_grid(&set, p, &uvs, grid, out);
                                let bits = |v: &[[f32; 3]]| {
                                    v.iter().flatten().map(|x| x.to_bits()).collect::<Vec<_>>()
                                };
                                (bits(&pos), bits(&nrm), uv, patch)
                            };
                            assert!(run(Some(cells)) == run(None), "{cage} patch {p} {cells:?} fma {fma}");
                            if worth_grouping(&view, uvs.len()) {
                                compared += uvs.len();
                            }
                        }
                    }
                }
            }
        }
        assert!(compared > 10_000, "only {compared} grouped points compared");
    }

    /// Every view of an isolated face's tree (turned, transposed, a quarter) evaluated by
    /// [`eval`] at dense points — groups of every size, single points, end caps — against
    /// the generic f64 evaluation point by point ([`assert_matches_f64`]).
    #[test]
    fn grouped_points_match_the_f64_evaluation_on_every_view() {
        let path = crate::test_support::data("subdivision/catmark_cube_creases0.obj");
        let mesh = crate::io::obj::read_obj(&path).unwrap();
        let mut set = SurfaceSet::from_subdivision_cage(&mesh, &path, Default::default()).unwrap();
        let p =
            set.patches.iter().position(|p| matches!(p, Patch::Subdivision(_))).expect("an isolated face");
        let Patch::Subdivision(tree) = set.patches[p].clone() else { unreachable!() };
        assert!(tree.leaves().iter().any(|l| matches!(l.patch, LeafPatch::Gregory(_))), "an end cap");
        let views = [
            (*tree).clone(),
            tree.transposed(),
            tree.rotated(1),
            tree.rotated(3).transposed(),
            tree.quadrant(2),
            tree.quadrant(1).rotated(2).transposed(),
        ];
        let n = 40;
        let uvs: Vec<DVec2> =
            (0..=n).flat_map(|j| (0..=n).map(move |i| DVec2::new(i as f64, j as f64) / n as f64)).collect();
        let (lo, hi) = set.bounds();
        let size = lo.distance(hi) as f32;
        let (mut kernels, mut cap_points, mut cap_kernels) = (0, 0, 0);
        for (v, view) in views.iter().enumerate() {
            set.patches[p] = Patch::Subdivision(Box::new(view.clone()));
            assert!(worth_grouping(view, uvs.len()), "view {v}: dense enough to group");
            let made = assert_matches_f64(&format!("view {v}"), &set, p, &uvs, size, |fma, out| {
                eval_either(fma, &set, p, view, &uvs, out)
            });
            kernels += made.iter().sum::<usize>();
            for (k, &at) in uvs.iter().enumerate() {
                if matches!(view.leaves()[view.find(at).0].patch, LeafPatch::Gregory(_)) {
                    cap_points += 1;
                    cap_kernels += made[k];
                }
            }
        }
        assert!(kernels * 4 > uvs.len() * views.len(), "only {kernels} normals from the kernels");
        // The end caps' points take their kernel too (all but a group's lone points).
        assert_mostly_kernels("end caps", cap_kernels, cap_points, 100);
    }

    /// Every isolated view of every Catmull-Clark cage that builds, at Bfr's rate 8 grid and
    /// a scattered set of points, through [`PointBlocks`] as the engine calls it where the view
    /// is too sparse to group ([`eval_sparse`]): every point within the f32 kernels' promise
    /// of the generic f64 evaluation ([`assert_matches_f64`]); every point outside the coarse
    /// leaves' forms ([`FORM_LEVEL`]) bit for bit the f64 path's
    /// ([`PatchTree::outputs_each`]); and most of those inside them from the kernels. The
    /// trees' leaves come coarsest first, so the forms are the leaves' first ones.
    #[test]
    fn sparse_points_match_the_f64_evaluation_on_every_catmark_cage() {
        let cages = crate::test_support::data_files("subdivision", &["catmark_"]);
        let n = 8;
        let mut uvs: Vec<DVec2> =
            (0..=n).flat_map(|j| (0..=n).map(move |i| DVec2::new(i as f64, j as f64) / n as f64)).collect();
        let mut seed = 7u64;
        uvs.extend((0..40).map(|_| {
            let mut next = || {
                seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                (seed >> 11) as f64 / (1u64 << 53) as f64
            };
            DVec2::new(next(), next())
        }));
        let (mut sparse_views, mut coarse_points, mut coarse_kernels, mut fine_points) = (0, 0, 0, 0);
        let (mut cap_points, mut cap_kernels) = (0, 0);
        for path in &cages {
            let mesh = crate::io::obj::read_obj(path).unwrap();
            let Ok(set) = SurfaceSet::from_subdivision_cage(&mesh, path, Default::default()) else {
                continue;
            };
            let (lo, hi) = set.bounds();
            let size = lo.distance(hi) as f32;
            let blocks = [false, true].map(|fma| PointBlocks::for_set(&set, fma));
            for (p, patch) in set.patches.iter().enumerate() {
                let Patch::Subdivision(view) = patch else { continue };
                let levels: Vec<u8> = view.leaves().iter().map(|l| l.level).collect();
                assert!(levels.is_sorted(), "{}: leaves coarsest first", path.display());
                if !blocks[0].evaluates_on_tree(&set, p, uvs.len()) {
                    continue;
                }
                sparse_views += 1;
                let what = format!("{} patch {p}", path.display());
                let made = assert_matches_f64(&what, &set, p, &uvs, size, |fma, out| {
                    blocks[usize::from(fma)].eval(&set, p, &uvs, out)
                });
                let mut f64_path = vec![None; uvs.len()];
                view.outputs_each(&uvs, |k, position, normal| f64_path[k] = Some((position, normal)));
                let coarse = view.coarse_leaves(FORM_LEVEL);
                let m = uvs.len();
                let (mut pos, mut nrm, mut uv, mut ids) =
                    (vec![[0f32; 3]; m], vec![[0f32; 3]; m], vec![[0f32; 2]; m], vec![0u32; m]);
                blocks[0].eval(
                    &set,
                    p,
                    &uvs,
                    VertexSlices { pos: &mut pos, nrm: &mut nrm, uv: &mut uv, patch: &mut ids },
                );
                for (k, &at) in uvs.iter().enumerate() {
                    let (leaf, st, _) = view.find(at);
                    let stored = view.corner_point(leaf, st).is_some();
                    let end_cap = matches!(view.leaves()[leaf].patch, LeafPatch::Gregory(_));
                    if leaf < coarse && !stored {
                        coarse_points += 1;
                        coarse_kernels += made[k];
                        if end_cap {
                            cap_points += 1;
                            cap_kernels += made[k];
                        }
                    } else {
                        fine_points += 1;
                        assert_eq!(
                            Some((pos[k], nrm[k])),
                            f64_path[k],
                            "{what} at {at:?}: the f64 path's bits"
                        );
                    }
                }
            }
        }
        eprintln!(
            "{sparse_views} sparse views: {coarse_points} points in coarse leaves ({coarse_kernels} normals from \
             the kernels, both builds; {cap_points} in end caps, {cap_kernels}), {fine_points} others"
        );
        assert_mostly_kernels("coarse end caps", cap_kernels, cap_points, 100);
        assert!(sparse_views >= 100, "only {sparse_views} sparse views");
        assert!(fine_points > 1000, "only {fine_points} points outside the coarse leaves");
        assert_mostly_kernels("coarse leaves", coarse_kernels, coarse_points, 0);
    }

    /// The grouped path as the engine calls it, with the set's stored forms of the coarse
    /// leaves ([`PointBlocks`]; end caps among them): every
    /// isolated view of two creased cages at a dense grid, against the generic f64 evaluation
    /// ([`assert_matches_f64`]), most normals from the kernels.
    #[test]
    fn grouped_points_with_stored_forms_match_the_f64_evaluation() {
        let n = 40;
        let uvs: Vec<DVec2> =
            (0..=n).flat_map(|j| (0..=n).map(move |i| DVec2::new(i as f64, j as f64) / n as f64)).collect();
        let (mut views, mut points, mut kernels) = (0, 0, 0);
        for cage in ["subdivision/catmark_cube_creases0.obj", "subdivision/catmark_rook.obj"] {
            let path = crate::test_support::data(cage);
            let mesh = crate::io::obj::read_obj(&path).unwrap();
            let set = SurfaceSet::from_subdivision_cage(&mesh, &path, Default::default()).unwrap();
            let (lo, hi) = set.bounds();
            let size = lo.distance(hi) as f32;
            let blocks = [false, true].map(|fma| PointBlocks::for_set(&set, fma));
            for (p, patch) in set.patches.iter().enumerate().step_by(7) {
                let Patch::Subdivision(view) = patch else { continue };
                if !worth_grouping(&**view, uvs.len()) {
                    continue;
                }
                views += 1;
                let made =
                    assert_matches_f64(&format!("{cage} patch {p}"), &set, p, &uvs, size, |fma, out| {
                        blocks[usize::from(fma)].eval(&set, p, &uvs, out)
                    });
                points += 2 * uvs.len();
                kernels += made.iter().sum::<usize>();
            }
        }
        assert!(views >= 50, "only {views} dense views");
        assert!(kernels * 2 > points, "only {kernels} of {points} normals from the kernels");
    }

    /// Every Loop patch of every manifold `loop_*` cage, as built and swapped (the opposite
    /// orientation), at dense points of its triangle, through [`PointBlocks`] as the engine
    /// calls it: the trees through [`eval`] with the set's leaf forms (quartic and Gregory
    /// leaves grouped, lone points in f64), the regular triangles as one quartic, against the generic f64 evaluation point by point
    /// ([`assert_matches_f64`]). Most normals must come from the kernels, on trees and regular
    /// triangles alike, and on the Gregory leaves' points of the trees too.
    #[test]
    fn loop_points_match_the_f64_evaluation_on_every_cage() {
        let cages = crate::test_support::data_files("subdivision", &["loop_"]);
        let n = 24;
        let uvs: Vec<DVec2> = (0..=n)
            .flat_map(|j| (0..=n - j).map(move |i| DVec2::new(i as f64, j as f64) / n as f64))
            .collect();
        let (mut cages_read, mut end_caps) = (0, 0);
        // [trees, regular triangles, the trees' Gregory leaves]: points compared, normals from
        // the kernels (of both builds, where the CPU has them).
        let (mut points, mut kernels) = ([0; 3], [0; 3]);
        for path in &cages {
            let mesh = crate::io::obj::read_obj(path).unwrap();
            // The non-manifold cage is refused (`tests/loop_oracle.rs` checks why).
            let Ok(built) = SurfaceSet::from_loop_cage(&mesh, path, Default::default()) else { continue };
            cages_read += 1;
            let (lo, hi) = built.bounds();
            let size = lo.distance(hi) as f32;
            let mut swapped = built.clone();
            swapped.patches.iter_mut().for_each(|p| *p = p.flipped());
            for (s, set) in [built, swapped].iter().enumerate() {
                let blocks = [false, true].map(|fma| PointBlocks::for_set(set, fma));
                for (p, patch) in set.patches.iter().enumerate() {
                    let Patch::Loop(tree) = patch else { panic!("{}: a Loop cage's patch", path.display()) };
                    let what = format!("{} patch {p} swapped {}", path.display(), s == 1);
                    let regular = tree.regular().is_some();
                    if !regular {
                        end_caps += tree
                            .leaves()
                            .iter()
                            .filter(|l| matches!(l.patch, TriangleLeafPatch::Gregory(_)))
                            .count();
                    }
                    let made = assert_matches_f64(&what, set, p, &uvs, size, |fma, out| {
                        blocks[usize::from(fma)].eval(set, p, &uvs, out)
                    });
                    points[usize::from(regular)] += uvs.len();
                    kernels[usize::from(regular)] += made.iter().sum::<usize>();
                    if !regular {
                        for (&uv, made) in uvs.iter().zip(&made) {
                            let (leaf, _) = tree.find(uv);
                            if matches!(tree.leaves()[leaf].patch, TriangleLeafPatch::Gregory(_)) {
                                points[2] += 1;
                                kernels[2] += made;
                            }
                        }
                    }
                }
            }
        }
        assert!(cages_read >= 10, "only {cages_read} Loop cages read");
        assert!(end_caps > 0, "no Gregory leaves among the trees");
        let kinds = ["trees", "regular triangles", "the trees' Gregory leaves"];
        for (kind, (k, n)) in kinds.iter().zip(kernels.iter().zip(points)) {
            eprintln!("{kind}: {n} points, {k} normals from the kernels (both builds)");
            assert!(*k * 2 > n, "{kind}: only {k} of {n} normals from the kernels");
        }
    }

    /// A Loop set past the budget for stored leaf forms (here a budget of 0) keeps none, and
    /// its trees' points are grouped with each group's form made for it (one or two points of
    /// a leaf in f64): still the f64 evaluation's points within the kernels' promise, most
    /// normals from the kernels.
    #[test]
    fn loop_points_without_stored_forms_match_the_f64_evaluation() {
        let path = crate::test_support::data("subdivision/loop_xord_interior.obj");
        let mesh = crate::io::obj::read_obj(&path).unwrap();
        let set = SurfaceSet::from_loop_cage(&mesh, &path, Default::default()).unwrap();
        let n = 24;
        let uvs: Vec<DVec2> = (0..=n)
            .flat_map(|j| (0..=n - j).map(move |i| DVec2::new(i as f64, j as f64) / n as f64))
            .collect();
        let (lo, hi) = set.bounds();
        let size = lo.distance(hi) as f32;
        let blocks = [false, true].map(|fma| PointBlocks::for_set_within(&set, fma, 0));
        assert!(PointBlocks::for_set(&set, false).stored_loop_leaves() > 0, "forms kept within the budget");
        let (mut points, mut kernels) = (0, 0);
        for (p, patch) in set.patches.iter().enumerate() {
            let Patch::Loop(tree) = patch else { panic!("a Loop cage's patch") };
            if tree.regular().is_some() {
                continue;
            }
            assert!(blocks.iter().all(|b| b.stored_loop_leaves() == 0), "a form stored past the budget");
            let made = assert_matches_f64(&format!("patch {p}"), &set, p, &uvs, size, |fma, out| {
                blocks[usize::from(fma)].eval(&set, p, &uvs, out)
            });
            points += uvs.len();
            kernels += made.iter().sum::<usize>();
        }
        assert!(points > 0, "no tree among the patches");
        assert!(kernels * 2 > points, "only {kernels} of {points} normals from the kernels");
    }

    /// [`eval`] compiled for AVX2 and FMA, as the engine calls it.
    ///
    /// # Safety
    /// The CPU must support AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn eval_avx2_fma<T: LeafTree>(
        set: &SurfaceSet,
        p: usize,
        tree: &T,
        uvs: &[DVec2],
        out: VertexSlices<'_>,
    ) {
        eval::<true, T>(set, p, tree, None, uvs, None, out)
    }
}
