//! The prepared set on the GPU: control points and the topology's arrays, uploaded once.
//!
//! The topology's rows are the CPU's own (`tessera::topology::Topology`), packed into u32 so
//! that WGSL can read them; nothing is recomputed. Row formats (the WGSL accessors in
//! `shaders/common.wgsl` read exactly these):
//!
//! - **patch row** ([`PATCH_ROW`] u32): `[0..4]` canonical edge of each local edge
//!   (`patch_edges[p][e].edge`); `[4..8]` flags of each local edge: bit 0 reversed, bit 1 the
//!   edge is collapsed, bit 2 the corner it starts at is pinched
//!   (`Topology::pinched_corners`), bits 8..16 the normal variant; `[8..12]` corner entry of each corner
//!   (`patch_corner_entries`); `[12]` bit 0 [`tessera::engine::layout::has_repeated_corner`],
//!   bit 1 a triangle domain, bit 2 a PN triangle (normals in the control-point slots), bit 3
//!   a Catmull-Clark subdivision patch (a tree of pieces), bit 4 a Loop subdivision patch (a
//!   triangle tree; bit 1 set too); `[13]` a subdivision patch's view record in the control
//!   points (`pack_trees`); the rest 0. Triangles fill three of the four edge and corner slots.
//! - **edge row** ([`EDGE_ROW`] u32): first use, end of uses (`edges[e].uses`), variants,
//!   collapsed.
//! - **edge use** ([`USE_ROW`] u32): patch; local edge | reversed << 8 | variant << 16.
//! - **corner row** ([`CORNER_ROW`] u32): owner patch and corner (the normal), then the patch
//!   and corner of its `position_entry`'s owner (the position: split-normal entries take the
//!   position bits of their vertex's first entry, as on the CPU).
//! - **control points**: 16 `vec4<f32>` per patch: a bicubic's `(x, y, z, w)` in
//!   `points[4 i + j]` order (`i` along `u`); a Bézier triangle's 10 points
//!   (`BezierTriangle::index` order, `w = 1`), then a PN triangle's six normals (`w = 0`); a
//!   subdivision patch's bounding-box corners, twice. After every patch's 16, the subdivision
//!   patches' view records and trees (`pack_trees`).

use crate::error::Result;
use tessera::surface::{Patch, SurfaceSet};
use wgpu::util::DeviceExt;

/// u32 per patch row.
pub const PATCH_ROW: u32 = 16;
/// u32 per edge row.
pub const EDGE_ROW: u32 = 4;
/// u32 per edge use.
pub const USE_ROW: u32 = 2;
/// u32 per corner row.
pub const CORNER_ROW: u32 = 4;
/// Control-point slots per patch.
pub const CONTROL_POINTS: u32 = 16;

/// The packed rows of a set, on the CPU (what [`GpuSet::new`] uploads).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PackedSet {
    /// [`PATCH_ROW`] u32 per patch.
    pub patch_rows: Vec<u32>,
    /// [`EDGE_ROW`] u32 per edge.
    pub edge_rows: Vec<u32>,
    /// [`USE_ROW`] u32 per edge use.
    pub uses: Vec<u32>,
    /// [`CORNER_ROW`] u32 per corner entry.
    pub corner_rows: Vec<u32>,
    /// [`CONTROL_POINTS`] `[x, y, z, w]` per patch.
    pub control_points: Vec<[f32; 4]>,
    /// Whether any patch has a repeated corner (then the collapsed-triangle pass runs).
    pub any_repeated_corner: bool,
    /// Whether any patch is a subdivision patch (then the vertex passes walk trees).
    pub has_trees: bool,
    /// Each packed tree: the first patch that views it and its block's first row in the
    /// control points (laid out as the module's documentation says).
    pub tree_blocks: Vec<(usize, u32)>,
}

impl PackedSet {
    /// Packs `set`'s topology and control points. Cost: O(P + E).
    pub fn new(set: &SurfaceSet) -> Result<PackedSet> {
        let topo = &set.topology;
        let mut packed = PackedSet::default();
        let mut trees = Vec::new();
        for (p, patch) in set.patches.iter().enumerate() {
            let mut row = [0u32; PATCH_ROW as usize];
            let corners = patch.domain().corner_count();
            let pinched = topo.pinched_corners(p);
            for e in 0..corners {
                let pe = topo.patch_edges[p][e];
                row[e] = pe.edge;
                let collapsed = topo.edges[pe.edge as usize].collapsed;
                row[4 + e] = pe.reversed as u32
                    | (collapsed as u32) << 1
                    | (pinched[e] as u32) << 2
                    | (pe.variant as u32) << 8;
                row[8 + e] = topo.patch_corner_entries[p][e];
            }
            let repeated = tessera::engine::layout::has_repeated_corner(set, p);
            packed.any_repeated_corner |= repeated;
            let point = |q: &glam::DVec3, w: f64| [q.x as f32, q.y as f32, q.z as f32, w as f32];
            let (tri, pn, tree) = match patch {
                Patch::Subdivision(_) | Patch::Loop(_) => {
                    // The box around its pieces twice (what culling reads: a triangle's first
                    // ten slots hold all eight corners too); the pieces themselves follow all
                    // patches ([`pack_trees`]).
                    let hull = patch.control_points();
                    packed.control_points.extend(hull.iter().chain(hull).map(|q| point(q, 1.0)));
                    trees.push(p);
                    let tri = matches!(patch, Patch::Loop(_));
                    (tri, false, true)
                }
                Patch::Bicubic(b) => {
                    packed.control_points.extend(b.points.iter().zip(&b.weights).map(|(q, &w)| point(q, w)));
                    (false, false, false)
                }
                Patch::BezierTriangle(t) => {
                    packed.control_points.extend(t.points.iter().map(|q| point(q, 1.0)));
                    packed.control_points.extend([[0.0; 4]; 6]);
                    (true, false, false)
                }
                Patch::Pn(t) => {
                    packed.control_points.extend(t.geometry.points.iter().map(|q| point(q, 1.0)));
                    packed.control_points.extend(t.normals.iter().map(|n| point(n, 0.0)));
                    (true, true, false)
                }
            };
            let loop_tree = tri && tree;
            row[12] = repeated as u32
                | (tri as u32) << 1
                | (pn as u32) << 2
                | (tree as u32 & !tri as u32) << 3
                | (loop_tree as u32) << 4;
            packed.patch_rows.extend_from_slice(&row);
        }
        pack_trees(set, &trees, &mut packed);
        packed.has_trees = !trees.is_empty();
        for edge in &topo.edges {
            packed.edge_rows.extend_from_slice(&[
                edge.uses.start,
                edge.uses.end,
                edge.variants as u32,
                edge.collapsed as u32,
            ]);
        }
        for u in &topo.uses {
            packed.uses.extend_from_slice(&[
                u.patch,
                u.local as u32 | (u.reversed as u32) << 8 | (u.variant as u32) << 16,
            ]);
        }
        for entry in &topo.corner_entries {
            let position = &topo.corner_entries[entry.position_entry as usize];
            packed.corner_rows.extend_from_slice(&[
                entry.owner_patch,
                entry.owner_corner as u32,
                position.owner_patch,
                position.owner_corner as u32,
            ]);
        }
        Ok(packed)
    }
}

/// Appends the subdivision patches' pieces to the control points (after every patch's 16
/// slots) and points their patch rows at them (`row[13]`), as `tree.wgsl` reads them:
///
/// - per patch in `trees`, a **view record** `(origin.x, origin.y, size, bits)`: for a
///   Catmull-Clark patch the square of the tree it covers
///   ([`tessera::surface::PatchTree::view_square`]) and `bits` (f32 bits) = transposed |
///   rotation << 1 | the tree block's index << 3; for a Loop patch `(0, 0, 1, bits)` with
///   `bits` = swapped | the block's index << 3 ([`tessera::surface::TriangleTree::is_swapped`]);
/// - per tree (views of one tree share it), a **block**: a header whose `x` bits are the root
///   slot, then each node's four child slots (bits), then each leaf: `(origin.x, origin.y,
///   size, kind bits)` and its points (`w = 1`): a Catmull-Clark leaf's 16 or 20 (kind 0
///   Bézier, 1 Gregory), a Loop leaf's 15 or 18 (kind bit 0 Gregory triangle, bit 1 turned).
///   A slot is a node index or `LEAF_SLOT |` the leaf's offset in the block.
fn pack_trees(set: &SurfaceSet, trees: &[usize], packed: &mut PackedSet) {
    use tessera::surface::patch_tree::LEAF_SLOT;
    let bits = |u: u32| f32::from_bits(u);
    let records = packed.control_points.len();
    packed.control_points.resize(records + trees.len(), [0.0; 4]);
    let mut blocks: std::collections::HashMap<usize, u32> = Default::default();
    for (k, &p) in trees.iter().enumerate() {
        let tree = PackedTree::of(&set.patches[p]);
        let block = *blocks.entry(tree.leaves_id()).or_insert_with(|| {
            let block = packed.control_points.len() as u32;
            packed.tree_blocks.push((p, block));
            let (root, nodes) = tree.quadtree();
            let leaf_at = offsets(nodes.len(), tree.leaf_point_counts());
            let slot = |s: u32| {
                if s & LEAF_SLOT != 0 {
                    LEAF_SLOT | leaf_at[(s & !LEAF_SLOT) as usize].0
                } else {
                    s
                }
            };
            let out = &mut packed.control_points;
            out.push([bits(slot(root)), 0.0, 0.0, 0.0]);
            out.extend(nodes.iter().map(|n| n.map(|s| bits(slot(s)))));
            tree.push_leaves(out);
            block
        });
        packed.control_points[records + k] = tree.view_record(block);
        packed.patch_rows[p * PATCH_ROW as usize + 13] = (records + k) as u32;
    }
}

/// A Catmull-Clark or Loop patch's tree, as [`pack_trees`] lays it out.
enum PackedTree<'a> {
    CatmullClark(&'a tessera::surface::PatchTree),
    Loop(&'a tessera::surface::TriangleTree),
}

impl<'a> PackedTree<'a> {
    fn of(patch: &'a Patch) -> PackedTree<'a> {
        match patch {
            Patch::Subdivision(t) => PackedTree::CatmullClark(t),
            Patch::Loop(t) => PackedTree::Loop(t),
            _ => unreachable!("trees are subdivision patches"),
        }
    }

    fn leaves_id(&self) -> usize {
        match self {
            PackedTree::CatmullClark(t) => t.leaves_id(),
            PackedTree::Loop(t) => t.leaves_id(),
        }
    }

    fn quadtree(&self) -> (u32, Vec<[u32; 4]>) {
        match self {
            PackedTree::CatmullClark(t) => t.quadtree(),
            PackedTree::Loop(t) => t.quadtree(),
        }
    }

    /// How many points each leaf has, leaf by leaf.
    fn leaf_point_counts(&self) -> Vec<usize> {
        match self {
            PackedTree::CatmullClark(t) => t.leaves().iter().map(|l| l.patch.points().len()).collect(),
            PackedTree::Loop(t) => t.leaves().iter().map(|l| l.patch.points().len()).collect(),
        }
    }

    /// Each leaf's record and points ([`pack_trees`]).
    fn push_leaves(&self, out: &mut Vec<[f32; 4]>) {
        use tessera::surface::patch_tree::LeafPatch;
        use tessera::surface::triangle_tree::TriangleLeafPatch;
        let bits = |u: u32| f32::from_bits(u);
        let mut leaf = |origin: glam::DVec2, size: f64, kind: u32, points: &[glam::DVec3]| {
            out.push([origin.x as f32, origin.y as f32, size as f32, bits(kind)]);
            out.extend(points.iter().map(|q| [q.x as f32, q.y as f32, q.z as f32, 1.0]));
        };
        match self {
            PackedTree::CatmullClark(t) => t.leaves().iter().for_each(|l| {
                let kind = u32::from(matches!(l.patch, LeafPatch::Gregory(_)));
                leaf(l.origin, l.size, kind, l.patch.points())
            }),
            PackedTree::Loop(t) => t.leaves().iter().for_each(|l| {
                let kind =
                    u32::from(matches!(l.patch, TriangleLeafPatch::Gregory(_))) | u32::from(l.turned) << 1;
                leaf(l.origin, l.size, kind, l.patch.points())
            }),
        }
    }

    /// The patch's view record ([`pack_trees`]) for its tree's block at `block`.
    fn view_record(&self, block: u32) -> [f32; 4] {
        match self {
            PackedTree::CatmullClark(t) => {
                let (origin, size) = t.view_square();
                let view = t.is_transposed() as u32 | u32::from(t.rotation()) << 1 | block << 3;
                [origin.x as f32, origin.y as f32, size as f32, f32::from_bits(view)]
            }
            PackedTree::Loop(t) => [0.0, 0.0, 1.0, f32::from_bits(t.is_swapped() as u32 | block << 3)],
        }
    }
}

/// Where each leaf of `patch`'s tree (a Catmull-Clark or Loop patch) starts in its block
/// ([`pack_trees`]), after the header and the nodes, and how many points follow its record.
/// Cost: O(nodes + leaves).
pub(crate) fn leaf_offsets(patch: &Patch) -> Vec<(u32, u32)> {
    let tree = PackedTree::of(patch);
    offsets(tree.quadtree().1.len(), tree.leaf_point_counts())
}

/// [`leaf_offsets`] of a tree of `nodes` nodes whose leaves have `points` points each.
fn offsets(nodes: usize, points: Vec<usize>) -> Vec<(u32, u32)> {
    let mut at = 1 + nodes as u32;
    points
        .into_iter()
        .map(|n| {
            let start = at;
            at += 1 + n as u32;
            (start, n as u32)
        })
        .collect()
}

/// The set's buffers on the device (read-only storage), uploaded once.
#[derive(Debug)]
pub struct GpuSet {
    /// Patches `P`.
    pub patches: u32,
    /// Canonical edges `E`.
    pub edges: u32,
    /// Corner entries: the first output vertices.
    pub corners: u32,
    /// Whether any patch has a repeated corner.
    pub any_repeated_corner: bool,
    /// Whether any patch is a subdivision patch.
    pub has_trees: bool,
    /// The packed trees ([`PackedSet::tree_blocks`]).
    pub tree_blocks: Vec<(usize, u32)>,
    /// Control points.
    pub control_points: wgpu::Buffer,
    /// Patch rows.
    pub patch_rows: wgpu::Buffer,
    /// Edge rows.
    pub edge_rows: wgpu::Buffer,
    /// Edge uses.
    pub uses: wgpu::Buffer,
    /// Corner rows.
    pub corner_rows: wgpu::Buffer,
}

/// A storage buffer (usages STORAGE, COPY_DST, COPY_SRC) holding `data`, at least 4 bytes
/// (empty buffers cannot be bound). Cost: one upload.
pub fn storage_buffer<T: bytemuck::Pod>(device: &wgpu::Device, label: &str, data: &[T]) -> wgpu::Buffer {
    let bytes: &[u8] = bytemuck::cast_slice(data);
    let padded;
    let contents = if bytes.len() < 4 {
        padded = [0u8; 4];
        &padded[..]
    } else {
        bytes
    };
    device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(label),
        contents,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC,
    })
}

impl GpuSet {
    /// Packs and uploads `set`. Errors as [`PackedSet::new`]. Cost: O(P + E) and one upload
    /// of about 300 bytes per patch.
    pub fn new(device: &wgpu::Device, set: &SurfaceSet) -> Result<GpuSet> {
        let packed = PackedSet::new(set)?;
        Ok(GpuSet {
            patches: set.patches.len() as u32,
            edges: set.topology.edges.len() as u32,
            corners: set.topology.corner_entries.len() as u32,
            any_repeated_corner: packed.any_repeated_corner,
            has_trees: packed.has_trees,
            tree_blocks: packed.tree_blocks.clone(),
            control_points: storage_buffer(device, "control points", &packed.control_points),
            patch_rows: storage_buffer(device, "patch rows", &packed.patch_rows),
            edge_rows: storage_buffer(device, "edge rows", &packed.edge_rows),
            uses: storage_buffer(device, "edge uses", &packed.uses),
            corner_rows: storage_buffer(device, "corner rows", &packed.corner_rows),
        })
    }
}
