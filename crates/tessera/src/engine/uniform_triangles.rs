//! A specialisation of *writing*: frames in which every patch is a triangle with the same
//! pattern input — a triangle mesh's PN patches (or Bézier triangles) at one uniform factor —
//! written without the generic writer's per-patch bookkeeping.
//!
//! At factor 4 a PN patch has 16 triangles and 3 interior vertices, and the generic writer's
//! steps per patch and edge (the pattern input, the table from local to output vertices, each
//! edge's parameter list, the split of the output by the layout's offsets) cost more than
//! the triangles themselves. Here the pattern and each local edge's parameters are made once
//! per frame; every patch has the same share of the output, so the output splits by
//! arithmetic; and a patch's triangles map to output vertices by addition. Each local vertex
//! belongs to a *group* — a corner, one edge's inner samples, the interior — whose output
//! vertices are `base + step · k` for that patch (`step` is 0 for a corner, ±1 for an edge by
//! the patch's direction along it, 1 for the interior; [`super::layout`]'s numbering rule),
//! so the triangles map through seven (base, step) pairs made per patch, with no table of its
//! local vertices.
//!
//! This changes how the output is written, never what it is: the tests compare it with the
//! generic writer's index for index. Evaluation is [`PointBlocks`]' as elsewhere.

use super::edge_params::UniformEdgeParams;
use super::layout::{pattern_input, Layout};
use super::point_blocks::PointBlocks;
use super::{stream_store, Pass, PatchOut, VertexSlices};
use crate::criterion::Plan;
use crate::pattern::{LocalTessellation, Pattern, Slot};
use crate::surface::{Domain, SurfaceSet};

/// Groups of a triangle patch's local vertices: corners 0–2, the inner samples of edges 0–2
/// (`3 + e`); the interior (6, never coded: see `UniformTriangles::interior`) and one unused,
/// so that any code's group indexes the tables without a bounds check.
const GROUPS: usize = 8;

/// Bits of a local vertex's code that hold its group; the rest hold its index in the group.
const GROUP_BITS: u32 = GROUPS.trailing_zeros();

/// Patches below this many per task run as one: the work per patch is small.
const PATCHES_PER_TASK: usize = 256;

/// The writer's frame-independent eligibility and its tables for the current plan.
#[derive(Default)]
pub(crate) struct UniformTriangles {
    /// Every patch is a triangle with three distinct corners (so no triangle degenerates and
    /// no edge is collapsed): decided once per set.
    eligible: bool,
    /// The current plan is written here ([`UniformTriangles::retarget`]).
    active: bool,
    /// The plan's one factor.
    n: u32,
    /// The pattern every patch shares.
    local: LocalTessellation,
    /// Each local triangle's corners, flattened: an interior vertex's index in the interior,
    /// 0 for any other vertex (which `boundary` rewrites). A patch's indices are this plus its
    /// first interior vertex, a vectorized add, where decoding every corner's group took
    /// about 2.3 ns a triangle (`loop_xord_interior` × 725 at factor 16: 30 ms of a 275 ms
    /// frame on one thread).
    interior: Vec<u32>,
    /// The corners on the patch's boundary, as (place in the flattened triangles, code: group
    /// in the low [`GROUP_BITS`], index in the group above).
    boundary: Vec<(u32, u32)>,
    /// The parameters, in the domain of a patch whose local edge this is, of the edge's
    /// canonical samples, as the generic writer computes them.
    edges: UniformEdgeParams,
}

impl UniformTriangles {
    /// The writer for `set`, not yet active. Cost: O(1).
    pub(crate) fn for_set(set: &SurfaceSet) -> UniformTriangles {
        UniformTriangles {
            eligible: set.topology.one_shape == Some(Domain::Tri),
            ..UniformTriangles::default()
        }
    }

    /// Makes the tables for `plan` and `pattern` and says whether this writer applies: an
    /// eligible set, every patch visible, a uniform plan with one factor on every edge and one
    /// interior factor, a pattern that ignores the patch id. Cost: O(E + P) to check the plan
    /// (vectorized folds), plus one pattern build.
    pub(crate) fn retarget(&mut self, set: &SurfaceSet, plan: &Plan, pattern: &dyn Pattern) -> bool {
        self.active = false;
        if !self.eligible || pattern.depends_on_patch() {
            return false;
        }
        let Some((n, _)) = plan.one_factor() else { return false };
        let input = pattern_input(set, plan, 0);
        pattern.build(&input, &mut self.local);
        self.interior.clear();
        self.boundary.clear();
        for (at, &l) in self.local.triangles.as_flattened().iter().enumerate() {
            let code = match input.slot(l) {
                Slot::Interior(j) => {
                    self.interior.push(j);
                    continue;
                }
                Slot::Corner(c) => c as u32,
                Slot::Edge(e, k) => (3 + e as u32) | (k << GROUP_BITS),
            };
            self.interior.push(0);
            self.boundary.push((at as u32, code));
        }
        if self.edges.factor() != n {
            self.edges.fill(n);
        }
        self.n = n;
        self.active = true;
        true
    }

    /// Whether the current plan is written here.
    pub(crate) fn active(&self) -> bool {
        self.active
    }

    /// Stops writing until the next [`UniformTriangles::retarget`] (the plan changed).
    pub(crate) fn deactivate(&mut self) {
        self.active = false;
    }

    /// Evaluates the inner samples of edge `e` (precondition: [`UniformTriangles::active`],
    /// and the edge has one normal variant) with its owner patch, in canonical order.
    pub(crate) fn edge(&self, set: &SurfaceSet, points: &PointBlocks, e: usize, out: VertexSlices<'_>) {
        let owner = set.topology.edge_uses(e)[0];
        let uvs = self.edges.get(Domain::Tri, owner.local as usize, owner.reversed);
        points.eval(set, owner.patch as usize, &uvs[1..self.n as usize], out);
    }

    /// Pass `pass` of the interiors and triangles of `patches` into `out` (their share of the
    /// output, from the first's). Precondition: [`UniformTriangles::active`]; `layout` was
    /// built for the plan, without corner parameters. Cost: O(output), parallel.
    pub(super) fn patches(
        &self,
        set: &SurfaceSet,
        points: &PointBlocks,
        layout: &Layout,
        patches: std::ops::Range<usize>,
        mut out: PatchOut<'_>,
        pass: Pass,
    ) {
        debug_assert!(self.active && out.params.is_empty());
        // Every patch has the same share of the output; a pattern has at least one triangle.
        let (vertices, triangles) = (self.local.interior.len(), self.local.triangles.len());
        if patches.len() > PATCHES_PER_TASK {
            let mid = patches.start + patches.len() / 2;
            let left = out.take_front(mid - patches.start, vertices, triangles);
            rayon::join(
                || self.patches(set, points, layout, patches.start..mid, left, pass),
                || self.patches(set, points, layout, mid..patches.end, out, pass),
            );
            return;
        }
        let PatchOut { verts, idx, tp, .. } = out;
        match pass {
            Pass::Vertices { .. } if vertices > 0 => {
                for (i, p) in patches.enumerate() {
                    let r = i * vertices..(i + 1) * vertices;
                    let part = VertexSlices {
                        pos: &mut verts.pos[r.clone()],
                        nrm: &mut verts.nrm[r.clone()],
                        uv: &mut verts.uv[r.clone()],
                        patch: &mut verts.patch[r],
                    };
                    points.eval(set, p, &self.local.interior, part);
                }
            }
            Pass::Vertices { .. } => {}
            Pass::Indices { stream: false } => {
                let chunks = idx.chunks_exact_mut(3 * triangles).zip(tp.chunks_exact_mut(triangles));
                for (p, (idx, tp)) in patches.zip(chunks) {
                    self.triangles(set, layout, p, idx);
                    tp.fill(p as u32);
                }
            }
            Pass::Indices { stream: true } => {
                // Each patch's indices mapped in the thread's buffer, then streamed out once.
                super::with_index_buffer(|mapped| {
                    mapped.clear();
                    mapped.resize(3 * triangles, 0);
                    let chunks = idx.chunks_exact_mut(3 * triangles).zip(tp.chunks_exact_mut(triangles));
                    for (p, (idx, tp)) in patches.zip(chunks) {
                        self.triangles(set, layout, p, mapped);
                        stream_store::copy(idx, mapped);
                        stream_store::fill(tp, p as u32);
                    }
                });
                stream_store::fence();
            }
        }
    }

    /// Patch `p`'s triangles, mapped to output vertices through its groups' bases and steps.
    #[inline]
    fn triangles(&self, set: &SurfaceSet, layout: &Layout, p: usize, idx: &mut [u32]) {
        let topo = &set.topology;
        let n = self.n;
        let mut base = [0u32; GROUPS];
        let mut step = [0u32; GROUPS];
        base[..3].copy_from_slice(&topo.patch_corner_entries[p][..3]);
        for (e, pe) in topo.patch_edges[p][..3].iter().enumerate() {
            // Canonical sample kc of variant v is edge_offsets + v·(n − 1) + kc − 1, and the
            // patch's own sample k is kc = k, or n − k where the patch runs against the edge.
            let first = layout.edge_offsets[pe.edge as usize] + pe.variant as u32 * (n - 1);
            (base[3 + e], step[3 + e]) =
                if pe.reversed { (first + n - 1, u32::MAX) } else { (first.wrapping_sub(1), 1) };
        }
        let first = layout.interior_vertex(p, 0);
        idx.iter_mut().zip(&self.interior).for_each(|(o, &j)| *o = first + j);
        for &(at, c) in &self.boundary {
            let (g, k) = ((c % GROUPS as u32) as usize, c >> GROUP_BITS);
            // Wrapping: a step of u32::MAX is −1.
            idx[at as usize] = base[g].wrapping_add(step[g].wrapping_mul(k));
        }
    }
}

impl<'a> PatchOut<'a> {
    /// Splits off the output of the first `patches` patches, each `vertices` interior vertices
    /// and `triangles` triangles (no corner parameters).
    fn take_front(&mut self, patches: usize, vertices: usize, triangles: usize) -> PatchOut<'a> {
        let t = patches * triangles;
        PatchOut {
            verts: self.verts.take_front(patches * vertices),
            idx: super::take_front(&mut self.idx, 3 * t),
            tp: super::take_front(&mut self.tp, t),
            params: &mut [],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::fast_evaluator::FastEvaluator;
    use crate::engine::{write_with, EngineOptions};
    use crate::mesh::Mesh;
    use crate::pattern::uniform::Uniform;

    fn cow() -> SurfaceSet {
        let path = crate::test_support::data("meshes/cow.obj");
        let mesh = crate::io::obj::read_obj(&path).unwrap();
        SurfaceSet::pn_from_mesh(&mesh, &path, Default::default()).unwrap()
    }

    /// The writer takes uniform plans of triangle sets with every patch visible, and nothing
    /// else; the engine leaves it where corner parameters are asked for (and writes what the
    /// generic writer writes).
    #[test]
    fn the_writer_takes_only_uniform_triangle_plans() {
        let set = cow();
        let plan = Plan::uniform(&set, 4).unwrap();
        let mut writer = UniformTriangles::for_set(&set);
        assert!(writer.retarget(&set, &plan, &Uniform) && writer.active());
        let mut uneven = plan.clone();
        uneven.segments[3] = 5;
        assert!(!writer.retarget(&set, &uneven, &Uniform) && !writer.active());
        let mut culled = plan.clone();
        culled.visible[2] = 0;
        assert!(!writer.retarget(&set, &culled, &Uniform));
        let teapot =
            crate::io::patches::read_patches(&crate::test_support::data("patches/teapot.patches")).unwrap();
        let quads = SurfaceSet::from_patch_file(&teapot, Default::default());
        let quad_plan = Plan::uniform(&quads, 4).unwrap();
        assert!(!UniformTriangles::for_set(&quads).retarget(&quads, &quad_plan, &Uniform));

        let options = EngineOptions { corner_params: true, ..Default::default() };
        let mut layout = Layout::default();
        layout.build(&set, &plan, &Uniform, &options).unwrap();
        let mut fast = FastEvaluator::new(&set, &plan);
        fast.fill_patterns(&plan, &Uniform, layout.triangle_count() as u64, None);
        assert!(fast.triangles().active());
        let (mut mesh, mut reference) = (Mesh::default(), Mesh::default());
        write_with(&set, &plan, &Uniform, &layout, options, &mut mesh, Some(&fast)).unwrap();
        write_with(&set, &plan, &Uniform, &layout, options, &mut reference, None).unwrap();
        assert!(mesh.indices == reference.indices && mesh.corner_params == reference.corner_params);
        // A new plan turns the writer off until its pattern is seen.
        fast.retarget(&plan);
        assert!(!fast.triangles().active());
    }
}
