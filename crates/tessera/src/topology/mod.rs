//! Topology: which patches share which boundary curves and corners.
//!
//! Patches are matched by *keys* computed from welded ids (see [`weld`]): a corner's key is its
//! welded vertex id, a boundary curve's key the welded ids of its control points (bicubic) or
//! of its end vertices (triangle meshes). Two patches share an edge exactly when their keys
//! agree, read forwards or backwards. Each edge gets a canonical orientation — the direction in
//! which its key is lexicographically smaller, so from the lower vertex id to the higher — and
//! every later decision about an edge (its sampling) is made in that orientation, from data
//! all its patches agree on. Boundary and non-manifold edges are counted, never rejected.

pub mod weld;

use crate::domain::Domain;
use std::collections::HashMap;

/// Marks an unused key slot (the fourth corner of a triangle, inner ids of a mesh edge).
pub const NONE: u32 = u32::MAX;

/// The keys of one patch, from which the topology is built.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PatchKeys {
    pub domain: Domain,
    /// Welded vertex id of each corner (`NONE` past the domain's corner count).
    pub corners: [u32; 4],
    /// Key of each boundary curve, read from corner `e` to corner `e+1`.
    pub edges: [[u32; 4]; 4],
    /// Which normal each corner uses; corners of one vertex with different keys get separate
    /// output vertices with the same position (split normals). 0 for surfaces whose normals
    /// come from their geometry.
    pub normals: [u32; 4],
}

/// One use of an edge by a patch.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct EdgeUse {
    pub patch: u32,
    /// Local edge index in the patch.
    pub local: u8,
    /// True when the patch runs along the edge against its canonical orientation.
    pub reversed: bool,
    /// Which normal variant of the edge this use takes (0 = the owner's).
    pub variant: u8,
}

/// A canonical edge (boundary curve) shared by one or more patches.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Edge {
    /// Key in canonical orientation.
    pub key: [u32; 4],
    /// Compacted vertex ids of the canonical start and end corners.
    pub ends: [u32; 2],
    /// The curve is a single point (all control points welded together): its samples all
    /// coincide with the corner, as at the teapot's lid apex.
    pub collapsed: bool,
    /// Range into [`Topology::uses`]; the first use is the edge's owner.
    pub uses: std::ops::Range<u32>,
    /// Number of normal variants (1 unless the edge is a crease with split normals).
    pub variants: u8,
}

/// Reference from a patch's local edge to its canonical edge.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct PatchEdge {
    pub edge: u32,
    pub reversed: bool,
    pub variant: u8,
    /// The canonical edge's `collapsed`, kept here too because every per-patch loop asks
    /// (reading it from `edges` is a cache miss per patch edge).
    pub collapsed: bool,
}

/// An output vertex at a corner: one per (vertex, normal key) pair.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CornerEntry {
    pub vertex: u32,
    /// The first patch corner that uses this entry; it evaluates the vertex.
    pub owner_patch: u32,
    pub owner_corner: u8,
    /// The entry of the same vertex that evaluates the position (positions are computed once
    /// per vertex and copied to split-normal entries).
    pub position_entry: u32,
}

/// Counts that describe an input's topology.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct TopologyReport {
    pub patches: usize,
    pub vertices: usize,
    pub edges: usize,
    pub boundary_edges: usize,
    pub nonmanifold_edges: usize,
    pub collapsed_edges: usize,
    /// Manifold edges whose two patches run along them in the same direction.
    pub inconsistently_oriented_edges: usize,
    pub euler_characteristic: i64,
}

impl TopologyReport {
    /// No boundary and no non-manifold edge.
    pub fn is_closed(&self) -> bool {
        self.boundary_edges == 0 && self.nonmanifold_edges == 0
    }
}

/// The shared-edge structure of a set of patches.
#[derive(Debug, Clone, Default)]
pub struct Topology {
    pub vertex_count: u32,
    pub edges: Vec<Edge>,
    pub uses: Vec<EdgeUse>,
    /// Per patch, per local edge.
    pub patch_edges: Vec<[PatchEdge; 4]>,
    /// Compacted vertex id of each patch corner.
    pub patch_corners: Vec<[u32; 4]>,
    /// Output corner entry of each patch corner.
    pub patch_corner_entries: Vec<[u32; 4]>,
    /// Each patch's domain, kept beside its edges: per-patch loops read it with them, and
    /// the patches themselves are large.
    pub patch_domains: Vec<Domain>,
    pub corner_entries: Vec<CornerEntry>,
    pub report: TopologyReport,
    /// `Some(domain)` when every patch has this domain and distinct corners (so no edge is
    /// collapsed and no pattern triangle degenerates): then patches with the same edge
    /// segments and interior factors have the same output counts, and a one-factor plan's
    /// layout is arithmetic (`engine::layout`). Decided once, here.
    pub one_shape: Option<Domain>,
    /// Per patch, its pinched corners ([`Topology::pinched_corners`]); empty when no patch
    /// has one.
    pub patch_pinched: Vec<[bool; 4]>,
    /// Where each edge's uses start in `uses` (and, last, their end): the edges' ranges are
    /// consecutive, and reading them here rather than from `edges` (36 bytes an edge) takes a
    /// frame's per-edge passes ([`Topology::edge_uses`]) one line in sixteen edges instead of
    /// one in two.
    use_starts: Vec<u32>,
    /// Each edge's rows of inner samples ([`Topology::edge_rows`]), one byte an edge for the
    /// same reason.
    edge_rows: Vec<u8>,
}

fn canonical(key: [u32; 4]) -> ([u32; 4], bool) {
    let rev = [key[3], key[2], key[1], key[0]];
    if rev < key {
        (rev, true)
    } else {
        (key, false)
    }
}

impl Topology {
    /// Which of patch `p`'s edges are boundary curves collapsed to a point (the pattern
    /// input's `collapsed`, in the patch's edge order). Whoever builds a patch's pattern to
    /// predict the engine's output (the error-bounded criteria) passes these too, or it
    /// predicts another triangulation. Cost: O(1).
    pub fn collapsed_sides(&self, p: usize) -> [bool; 4] {
        let mut collapsed = [false; 4];
        for (e, c) in collapsed.iter_mut().enumerate().take(self.patch_domains[p].corner_count()) {
            *c = self.patch_edges[p][e].collapsed;
        }
        collapsed
    }

    /// Which of patch `p`'s corners are pinched: both edges there are shared with one same
    /// other patch, and with no third — the two faces at an interior vertex of valence 2 (a
    /// subdivision cage can have one). The pattern input's `pinched`
    /// ([`crate::pattern::PatternInput::pinched`]), in the patch's corner order. Cost: O(1).
    pub fn pinched_corners(&self, p: usize) -> [bool; 4] {
        self.patch_pinched.get(p).copied().unwrap_or_default()
    }

    /// The other patch on patch `p`'s local edge `e` when exactly two patches share it and it
    /// is not collapsed.
    fn only_neighbour(&self, p: usize, e: usize) -> Option<u32> {
        let pe = self.patch_edges[p][e];
        match self.edge_uses(pe.edge as usize) {
            [x, y] if !pe.collapsed => Some(if x.patch == p as u32 { y.patch } else { x.patch }),
            _ => None,
        }
    }

    /// Builds the topology. Cost: O(P) hashing, P = number of patches.
    pub fn build(keys: &[PatchKeys]) -> Topology {
        let mut vertex_ids: HashMap<u32, u32> = HashMap::new();
        let mut patch_corners = Vec::with_capacity(keys.len());
        for k in keys {
            let mut c = [NONE; 4];
            for (i, slot) in c.iter_mut().enumerate().take(k.domain.corner_count()) {
                let next = vertex_ids.len() as u32;
                *slot = *vertex_ids.entry(k.corners[i]).or_insert(next);
            }
            patch_corners.push(c);
        }

        // Edges, with their uses gathered per canonical key.
        let mut edge_index: HashMap<[u32; 4], u32> = HashMap::new();
        let mut edge_uses: Vec<Vec<(u32, u8, bool)>> = Vec::new();
        let mut edge_keys: Vec<[u32; 4]> = Vec::new();
        let mut edge_ends: Vec<[u32; 2]> = Vec::new();
        for (p, k) in keys.iter().enumerate() {
            let n = k.domain.corner_count();
            for e in 0..n {
                let (key, reversed) = canonical(k.edges[e]);
                let id = *edge_index.entry(key).or_insert_with(|| {
                    edge_keys.push(key);
                    edge_uses.push(Vec::new());
                    let (a, b) = (patch_corners[p][e], patch_corners[p][(e + 1) % n]);
                    edge_ends.push(if reversed { [b, a] } else { [a, b] });
                    (edge_keys.len() - 1) as u32
                });
                edge_uses[id as usize].push((p as u32, e as u8, reversed));
            }
        }

        let mut edges = Vec::with_capacity(edge_keys.len());
        let mut uses = Vec::with_capacity(keys.len() * 4);
        let mut patch_edges = vec![[PatchEdge::default(); 4]; keys.len()];
        let mut report = TopologyReport { patches: keys.len(), ..Default::default() };
        for (id, list) in edge_uses.iter().enumerate() {
            let key = edge_keys[id];
            let collapsed = key.iter().all(|&x| x == key[0]);
            // Normal signature of a use: the normal keys at the canonical start and end.
            let signature = |&(p, e, rev): &(u32, u8, bool)| {
                let k = &keys[p as usize];
                let n = k.domain.corner_count();
                let (a, b) = (k.normals[e as usize], k.normals[(e as usize + 1) % n]);
                if rev {
                    (b, a)
                } else {
                    (a, b)
                }
            };
            let mut signatures: Vec<(u32, u32)> = Vec::new();
            let start = uses.len() as u32;
            for u in list {
                let s = signature(u);
                let variant = match signatures.iter().position(|&x| x == s) {
                    Some(v) => v,
                    None => {
                        signatures.push(s);
                        signatures.len() - 1
                    }
                };
                let variant = variant.min(u8::MAX as usize) as u8;
                uses.push(EdgeUse { patch: u.0, local: u.1, reversed: u.2, variant });
                patch_edges[u.0 as usize][u.1 as usize] =
                    PatchEdge { edge: id as u32, reversed: u.2, variant, collapsed };
            }
            if collapsed {
                report.collapsed_edges += 1;
            } else {
                report.edges += 1;
                match list.len() {
                    1 => report.boundary_edges += 1,
                    2 => {
                        if list[0].2 == list[1].2 {
                            report.inconsistently_oriented_edges += 1
                        }
                    }
                    _ => report.nonmanifold_edges += 1,
                }
            }
            edges.push(Edge {
                key,
                ends: edge_ends[id],
                collapsed,
                uses: start..uses.len() as u32,
                variants: signatures.len().min(u8::MAX as usize) as u8,
            });
        }

        // Corner entries: one per (vertex, normal key); the position is evaluated once per
        // vertex by the first entry of that vertex.
        let mut entry_index: HashMap<(u32, u32), u32> = HashMap::new();
        let mut first_entry_of_vertex: HashMap<u32, u32> = HashMap::new();
        let mut corner_entries = Vec::new();
        let mut patch_corner_entries = vec![[NONE; 4]; keys.len()];
        for (p, k) in keys.iter().enumerate() {
            for c in 0..k.domain.corner_count() {
                let v = patch_corners[p][c];
                let next = corner_entries.len() as u32;
                let id = *entry_index.entry((v, k.normals[c])).or_insert_with(|| {
                    let position_entry = *first_entry_of_vertex.entry(v).or_insert(next);
                    corner_entries.push(CornerEntry {
                        vertex: v,
                        owner_patch: p as u32,
                        owner_corner: c as u8,
                        position_entry,
                    });
                    next
                });
                patch_corner_entries[p][c] = id;
            }
        }

        report.vertices = vertex_ids.len();
        report.euler_characteristic = report.vertices as i64 - report.edges as i64 + report.patches as i64;
        let one_shape = keys.first().map(|k| k.domain).filter(|&d| {
            keys.iter().zip(&patch_corners).all(|(k, c)| {
                let c = &c[..d.corner_count()];
                k.domain == d && (0..c.len()).all(|i| !c[i + 1..].contains(&c[i]))
            }) && edges.iter().all(|e| !e.collapsed)
        });
        let mut topology = Topology {
            one_shape,
            vertex_count: vertex_ids.len() as u32,
            edges,
            uses,
            patch_edges,
            patch_corners,
            patch_corner_entries,
            patch_domains: keys.iter().map(|k| k.domain).collect(),
            corner_entries,
            report,
            patch_pinched: Vec::new(),
            use_starts: Vec::new(),
            edge_rows: Vec::new(),
        };
        topology.use_starts = topology.edges.iter().map(|e| e.uses.start).collect();
        topology.edge_rows =
            topology.edges.iter().map(|e| if e.collapsed { 0 } else { e.variants }).collect();
        topology.use_starts.push(topology.uses.len() as u32);
        debug_assert!(topology
            .edges
            .iter()
            .enumerate()
            .all(|(i, e)| e.uses.end == topology.use_starts[i + 1]));
        let pinched: Vec<[bool; 4]> = (0..keys.len())
            .map(|p| {
                let nc = topology.patch_domains[p].corner_count();
                std::array::from_fn(|c| {
                    c < nc && {
                        let here = topology.only_neighbour(p, c);
                        here.is_some()
                            && here != Some(p as u32)
                            && here == topology.only_neighbour(p, (c + nc - 1) % nc)
                    }
                })
            })
            .collect();
        if pinched.iter().any(|c| c.contains(&true)) {
            topology.patch_pinched = pinched;
        }
        topology
    }

    /// The uses of edge `e`; the first is the owner.
    pub fn edge_uses(&self, e: usize) -> &[EdgeUse] {
        &self.uses[self.use_starts[e] as usize..self.use_starts[e + 1] as usize]
    }

    /// How many rows of inner samples edge `e` has in the output: one per normal variant,
    /// none where its curve is a point (its samples are the corner). Cost: O(1).
    pub fn edge_rows(&self, e: usize) -> u32 {
        self.edge_rows[e] as u32
    }

    /// Whether a visible patch uses edge `e` (`visible[p] != 0`: a plan's visibility row).
    /// Without a branch per use: with culling on, about half the patches are culled in no
    /// predictable order, and `any`'s early exit mispredicted. Cost: O(uses of `e`).
    #[inline(always)]
    pub fn edge_seen(&self, e: usize, visible: &[u32]) -> bool {
        self.edge_uses(e).iter().fold(0, |seen, u| seen | visible[u.patch as usize]) != 0
    }

    /// The inner samples edge `e` adds to the output with `segments` segments: its rows
    /// ([`Topology::edge_rows`]) of `segments − 1`, none where no visible patch uses it
    /// (`seen`, [`Topology::edge_seen`]; nothing refers to them). The one rule of the layout's counts
    /// (`engine::layout`) and of the plan's (`criterion::resolve::edges_counted`). Segments
    /// ≤ `MAX_FACTOR` and ≤ 255 variants: a count fits u32. Cost: O(1).
    #[inline(always)]
    pub fn edge_samples(&self, e: usize, seen: bool, segments: u32) -> u32 {
        u32::from(seen) * (segments - 1) * self.edge_rows(e)
    }
}

/// Hand-broken inputs: each defect must be found exactly, so a lenient topology (matching
/// curves by end points only, or ignoring orientation) fails these.
#[cfg(test)]
mod tests {
    use crate::surface::{BuildOptions, Orientation, Patch, RationalBicubic, SurfaceSet};
    use glam::DVec3;

    /// A flat bicubic patch over `[x0, x1] × [y0, y1]` at height 0; `flip` reverses its `u`
    /// direction (and so its orientation).
    fn quad(x0: f64, x1: f64, y0: f64, y1: f64, flip: bool) -> Patch {
        let points = std::array::from_fn(|k| {
            let (i, j) = ((k / 4) as f64 / 3.0, (k % 4) as f64 / 3.0);
            let i = if flip { 1.0 - i } else { i };
            DVec3::new(x0 + (x1 - x0) * i, y0 + (y1 - y0) * j, 0.0)
        });
        Patch::Bicubic(RationalBicubic { points, weights: [1.0; 16] })
    }

    fn report(patches: Vec<Patch>) -> super::TopologyReport {
        let options = BuildOptions { orientation: Orientation::AsGiven, ..Default::default() };
        SurfaceSet::from_patches(patches, options).topology.report
    }

    #[test]
    fn two_patches_sharing_a_curve_have_one_shared_edge() {
        let r = report(vec![quad(0.0, 3.0, 0.0, 3.0, false), quad(3.0, 6.0, 0.0, 3.0, false)]);
        assert_eq!((r.edges, r.boundary_edges, r.nonmanifold_edges), (7, 6, 0), "{r:?}");
        assert_eq!(r.inconsistently_oriented_edges, 0);
    }

    #[test]
    fn a_crack_shares_nothing() {
        let r = report(vec![quad(0.0, 3.0, 0.0, 3.0, false), quad(3.001, 6.0, 0.0, 3.0, false)]);
        assert_eq!((r.edges, r.boundary_edges), (8, 8), "{r:?}");
    }

    #[test]
    fn a_t_junction_is_not_a_shared_curve() {
        // The tall patch's right curve spans both small patches' left curves.
        let r = report(vec![
            quad(0.0, 3.0, 0.0, 6.0, false),
            quad(3.0, 6.0, 0.0, 3.0, false),
            quad(3.0, 6.0, 3.0, 6.0, false),
        ]);
        assert_eq!((r.edges, r.boundary_edges, r.nonmanifold_edges), (11, 10, 0), "{r:?}");
    }

    #[test]
    fn a_flipped_patch_is_inconsistently_oriented() {
        let r = report(vec![quad(0.0, 3.0, 0.0, 3.0, false), quad(3.0, 6.0, 0.0, 3.0, true)]);
        assert_eq!((r.edges, r.boundary_edges), (7, 6), "{r:?}");
        assert_eq!(r.inconsistently_oriented_edges, 1, "{r:?}");
    }

    #[test]
    fn three_patches_on_a_curve_make_it_non_manifold() {
        // A fin: the third patch stands up from the shared curve x = 3.
        let fin = {
            let points = std::array::from_fn(|k| {
                let (i, j) = ((k / 4) as f64 / 3.0, (k % 4) as f64 / 3.0);
                DVec3::new(3.0, 3.0 * j, 3.0 * i)
            });
            Patch::Bicubic(RationalBicubic { points, weights: [1.0; 16] })
        };
        let r = report(vec![quad(0.0, 3.0, 0.0, 3.0, false), quad(3.0, 6.0, 0.0, 3.0, false), fin]);
        assert_eq!(r.nonmanifold_edges, 1, "{r:?}");
        assert!(!r.is_closed());
    }
}
