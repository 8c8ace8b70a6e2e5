//! A specialisation of *evaluation* for the piecewise patches of subdivision surfaces
//! ([`PatchTree`]): a patch's points grouped by the leaf that holds them, and every group of
//! a Bézier leaf evaluated as one bicubic in f32, [`LANES`] points at a time, by the same
//! kernel as a whole bicubic patch ([`super::point_blocks`]).
//!
//! **Why by leaf.** Evaluated point by point in f64, a tree's point cost 60–100 ns on the
//! machine this was written on (a regular face's about 5 ns), even where the leaves fit in
//! the cache: the point's own leaf lookup, Bernstein weights, sixteen-point sums and normal.
//! A leaf holds several points of a pattern wherever the tree is shallower than the
//! tessellation is fine: at Bfr's rate 16 on `catmark_rook`, three quarters of the points of
//! its isolated faces share their leaf with three others or more, over half with fifteen
//! others or more. Such a group pays once for moving its leaf's net to a local frame and
//! rounding it to f32, then takes the bicubic kernel's price per point. A point alone in its
//! leaf (a deep tree's, or an end cap's) keeps the f64 evaluation.
//!
//! **Same frame, same fallbacks.** The leaf's net is moved to the leaf's own local frame
//! ([`super::point_blocks::local_frame`]), so f32 carries the leaf's detail at full relative
//! precision however deep the leaf; the reliability rule of the normals
//! ([`super::point_blocks::cross_normals`]) applies unchanged, a point failing it takes the f64
//! evaluation. The normal of a leaf's derivatives is the patch's up to its sign: the view's
//! derivatives are the leaf's scaled by a positive factor and turned by quarter turns (which
//! keep their cross product), and exchanged where the view is transposed (which reverses it).
//!
//! **Watertight as before**: which patch evaluates a point and at which parameters is
//! unchanged; only how its position and normal are rounded.

use std::cell::RefCell;

use glam::DVec2;

use super::point_blocks::{bicubic_block, LANES};
use super::uniform_quads::LocalPatch;
use super::VertexSlices;
use crate::surface::patch_tree::{LeafPatch, PatchTree};
use crate::surface::{subdivision_point, SurfaceSet};

/// The fewest points of one leaf evaluated as a group; fewer take the f64 evaluation, where
/// moving the net to its frame would cost more than it saves.
const MIN_GROUP: usize = 2;

/// A point of the patch's list and where [`PatchTree::find`] put it.
#[derive(Clone, Copy)]
struct Found {
    leaf: u32,
    k: u32,
    st: DVec2,
    size: f64,
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
}

thread_local! {
    static SCRATCH: RefCell<Scratch> = RefCell::new(Scratch::default());
}

/// Points per leaf of the view, on average, from which grouping pays. Below it most groups
/// would be single points, which pay for finding and grouping on top of their f64
/// evaluation and lose [`PatchTree::derivatives_each`]'s look-ahead. Measured on one
/// thread: grouping every list made `catmark_rook` at rate 16 (creases isolate its faces six
/// levels deep) 25–45 % slower; with this rule it is unchanged, and `catmark_cube_creases0`
/// at factor 64 (points dense next to its leaves) a third faster.
const MIN_DENSITY: f64 = 4.0;

/// Whether [`eval`] is the faster way to evaluate `points` points of `tree`: they are dense
/// next to the leaves the view covers (estimated from the tree's leaf count and the view's
/// share of the tree's square). Cost: O(1).
#[inline(always)]
pub(super) fn worth_grouping(tree: &PatchTree, points: usize) -> bool {
    let (_, view) = tree.view_square();
    points as f64 >= MIN_DENSITY * tree.leaves().len() as f64 * view * view
}

/// Evaluates patch `p` of `set`, the piecewise patch `tree`, at `uvs` into `out`, as
/// [`VertexSlices::put`] does point by point. Preconditions: `set.patches[p]` is `tree`;
/// `out` holds `uvs.len()` vertices; with `FMA`, the CPU has AVX2 and FMA. Cost: a leaf
/// lookup per point and a sort of the points by leaf (O(n + leaves), or O(n log n) for fewer
/// points than leaves); per group, moving its net to f32 once and the bicubic kernel's
/// price per point; per single point, the f64 evaluation. No allocation once the thread's
/// scratch has grown.
#[inline(always)]
pub(super) fn eval<const FMA: bool>(
    set: &SurfaceSet,
    p: usize,
    tree: &PatchTree,
    uvs: &[DVec2],
    mut out: VertexSlices<'_>,
) {
    // Taken out of the thread's slot and put back, not borrowed in a closure: a closure would
    // not be compiled for the caller's AVX2 and FMA.
    let mut scratch = SCRATCH.take();
    let Scratch { found, starts, grouped } = &mut scratch;
    found.clear();
    tree.prefetch_nodes();
    let mut last = u32::MAX;
    for (k, &uv) in uvs.iter().enumerate() {
        let (leaf, st, size) = tree.find(uv);
        let leaf = leaf as u32;
        if leaf != last {
            tree.prefetch_leaf(leaf as usize, st);
            last = leaf;
        }
        found.push(Found { leaf, k: k as u32, st, size });
    }
    grouped.clear();
    let leaf_count = tree.leaves().len();
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
    let flip = tree.is_transposed();
    let leaves = tree.leaves();
    for group in grouped.chunk_by(|a, b| a.leaf == b.leaf) {
        match &leaves[group[0].leaf as usize].patch {
            LeafPatch::Bezier(net) if group.len() >= MIN_GROUP => {
                let local = LocalPatch::from_net(net);
                if group.len() <= LANES / 2 {
                    blocks::<FMA, { LANES / 2 }>(set, p, &local, flip, group, uvs, &mut out);
                } else {
                    blocks::<FMA, LANES>(set, p, &local, flip, group, uvs, &mut out);
                }
            }
            _ => {
                for f in group {
                    let k = f.k as usize;
                    let d = single::<FMA>(tree, f);
                    let q = subdivision_point(tree, uvs[k], d);
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

/// One point's derivatives in f64, as [`PatchTree::derivatives`] gives them.
#[inline(always)]
fn single<const FMA: bool>(tree: &PatchTree, f: &Found) -> (glam::DVec3, glam::DVec3, glam::DVec3) {
    #[cfg(target_arch = "x86_64")]
    if FMA {
        // SAFETY: `FMA` is only set for a CPU with AVX2 and FMA (the caller's precondition).
        return unsafe { tree.found_derivatives_avx(f.leaf as usize, f.st, f.size) };
    }
    tree.found_derivatives(f.leaf as usize, f.st, f.size)
}

/// The points of `group` (one leaf, whose net is `local`) in blocks of `L` lanes.
#[inline(always)]
fn blocks<const FMA: bool, const L: usize>(
    set: &SurfaceSet,
    p: usize,
    local: &LocalPatch,
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
        let block = bicubic_block::<FMA, L>(local, &u, &v);
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::point_blocks::has_avx2_fma;
    use crate::surface::Patch;
    use glam::Vec3;

    /// Every view of an isolated face's tree (turned, transposed, a quarter) evaluated by
    /// [`eval`] at dense points — groups of every size, single points, end caps — against
    /// the generic f64 evaluation point by point: positions within 1e-6 of the patch's size,
    /// normals within 1e-5 (the f32 kernels' promise), parameters and patch ids exact.
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
        let mut kernels = 0;
        for (v, view) in views.iter().enumerate() {
            set.patches[p] = Patch::Subdivision(Box::new(view.clone()));
            assert!(worth_grouping(view, uvs.len()), "view {v}: dense enough to group");
            for fma in [false, true] {
                if fma && !has_avx2_fma() {
                    continue;
                }
                let m = uvs.len();
                let (mut pos, mut nrm, mut uv, mut patch) =
                    (vec![[0f32; 3]; m], vec![[0f32; 3]; m], vec![[0f32; 2]; m], vec![0u32; m]);
                let out = VertexSlices { pos: &mut pos, nrm: &mut nrm, uv: &mut uv, patch: &mut patch };
                if fma {
                    #[cfg(target_arch = "x86_64")]
                    // SAFETY: the CPU has AVX2 and FMA (checked above).
                    unsafe {
                        eval_avx2_fma(&set, p, view, &uvs, out)
                    };
                } else {
                    eval::<false>(&set, p, view, &uvs, out);
                }
                for (k, &at) in uvs.iter().enumerate() {
                    let q = set.patches[p].eval(at);
                    let what = format!("view {v} fma {fma} at {at:?}");
                    let dp = (Vec3::from(pos[k]) - q.position.as_vec3()).length() / size;
                    let dn = (Vec3::from(nrm[k]) - q.normal.as_vec3()).length();
                    assert!(dp <= 1e-6, "{what}: position off by {dp:e} of the size");
                    assert!(dn <= 1e-5, "{what}: normal off by {dn:e}");
                    assert_eq!(uv[k], at.as_vec2().to_array(), "{what}");
                    assert_eq!(patch[k], p as u32, "{what}");
                    kernels += usize::from(nrm[k] != q.normal.as_vec3().to_array());
                }
            }
        }
        assert!(kernels * 4 > uvs.len() * views.len(), "only {kernels} normals from the kernels");
    }

    /// [`eval`] compiled for AVX2 and FMA, as the engine calls it.
    ///
    /// # Safety
    /// The CPU must support AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn eval_avx2_fma(
        set: &SurfaceSet,
        p: usize,
        tree: &PatchTree,
        uvs: &[DVec2],
        out: VertexSlices<'_>,
    ) {
        eval::<true>(set, p, tree, uvs, out)
    }
}
