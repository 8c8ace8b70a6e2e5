//! Verification: watertightness, approximation error against the exact surface, triangle
//! quality. The same code serves the tests, `tessera check` and the benchmarks.

use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::surface::SurfaceSet;
use glam::{DVec2, DVec3, Vec3};
use rayon::prelude::*;
use std::collections::HashMap;
use std::sync::atomic::{AtomicBool, AtomicU32, Ordering::Relaxed};

/// What is wrong with an output mesh that was not wrong with its input (`input`, the set's
/// [`crate::topology::TopologyReport`]): degenerate triangles; non-manifold or misoriented
/// edges where the input had none; and, unless `culled` patches were left out on purpose,
/// boundary edges on a closed input or another Euler characteristic. One sentence per
/// problem, empty when the output is sound — the rule behind `tessera mesh`'s warnings and
/// exit status 1, and the Python package's `report["problems"]`. Cost: O(1).
pub fn output_problems(
    input: &crate::topology::TopologyReport,
    w: &WatertightReport,
    culled: usize,
) -> Vec<String> {
    let t = input;
    let mut problems = Vec::new();
    if w.degenerate_triangles() > 0 {
        problems.push(format!(
            "the mesh has {} degenerate triangles ({} with two corners at one position, {} of zero area)",
            w.degenerate_triangles(),
            w.collapsed_triangles,
            w.zero_area_triangles
        ));
    }
    // A non-manifold input curve legitimately gives non-manifold output edges, one per segment.
    if w.nonmanifold_edges > 0 && t.nonmanifold_edges == 0 {
        problems.push(format!(
            "the input is manifold but the mesh has {} non-manifold edges",
            w.nonmanifold_edges
        ));
    }
    if w.misoriented_edges > 0 && t.inconsistently_oriented_edges == 0 {
        problems.push(format!("the mesh has {} edges used twice in the same direction", w.misoriented_edges));
    }
    if culled == 0 {
        if t.boundary_edges == 0 && w.boundary_edges > 0 {
            problems
                .push(format!("the input is closed but the mesh has {} boundary edges", w.boundary_edges));
        }
        // Non-manifold inputs too: coincident copies of a patch weld into one surface.
        if w.euler_characteristic != t.euler_characteristic {
            problems.push(format!(
                "the mesh's Euler characteristic is {}, the input's {}: its topology changed (a pinch or a hole)",
                w.euler_characteristic, t.euler_characteristic
            ));
        }
    }
    problems
}

/// Topological soundness of a mesh after welding bit-identical positions.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct WatertightReport {
    /// Distinct positions used by at least one triangle.
    pub vertices: usize,
    pub triangles: usize,
    /// Triangles with two corners at the same position (skipped for the edge counts).
    pub collapsed_triangles: usize,
    /// Triangles with three distinct positions but zero area.
    pub zero_area_triangles: usize,
    /// Distinct undirected edges.
    pub edges: usize,
    /// Edges used by one triangle.
    pub boundary_edges: usize,
    /// Edges used by more than two triangles.
    pub nonmanifold_edges: usize,
    /// Edges used twice in the same direction (inconsistent winding).
    pub misoriented_edges: usize,
    /// `V − E + F` over the non-collapsed triangles.
    pub euler_characteristic: i64,
}

impl WatertightReport {
    /// No boundary and no non-manifold edge.
    pub fn is_closed(&self) -> bool {
        self.boundary_edges == 0 && self.nonmanifold_edges == 0
    }

    /// Triangles that are collapsed or have zero area.
    pub fn degenerate_triangles(&self) -> usize {
        self.collapsed_triangles + self.zero_area_triangles
    }

    /// Counts one undirected edge used `forward` times one way and `backward` times the other.
    fn count_edge(&mut self, forward: u32, backward: u32) {
        self.edges += 1;
        match forward + backward {
            1 => self.boundary_edges += 1,
            2 if forward == 2 || backward == 2 => self.misoriented_edges += 1,
            2 => {}
            _ => self.nonmanifold_edges += 1,
        }
    }

    /// The Euler characteristic, once vertices, edges and triangles are counted.
    fn finish(mut self) -> Self {
        let faces = (self.triangles - self.collapsed_triangles) as i64;
        self.euler_characteristic = self.vertices as i64 - self.edges as i64 + faces;
        self
    }
}

fn position_key(p: [f32; 3]) -> [u32; 3] {
    // +0.0 makes -0.0 and 0.0 weld.
    p.map(|x| (x + 0.0).to_bits())
}

/// Welds positions by exact bits and counts boundary, non-manifold and misoriented edges.
///
/// Positions weld when their bits are equal (`-0.0` and `0.0` count as one). A triangle with
/// two corners at one welded position is collapsed and left out of the edge counts; the
/// others give their three sides, and each undirected side is one edge.
///
/// How, and why so: both steps are partitioned hashing and sorting, each part small enough to
/// stay in a core's cache, so that the work is parallel and the memory traffic is a few
/// sequential passes over the mesh rather than one cache miss per vertex or side.
/// - Weld: every position goes, by a hash of its bits, to one of about `V / 2048` parts
///   (copied with its index, 16 bytes); each part is welded with a small open-addressing
///   table, every vertex taking the smallest index at its position as its id (so only
///   duplicates write an id out of order).
/// - Edges: every side of a non-collapsed triangle becomes a 64-bit key (its smaller welded
///   end, its larger end and its direction), stored in the part of its smaller end (4,096
///   vertices a part, in index order); each part is sorted on its own (a counting sort on the
///   smaller end, then each end's few sides), so an edge's uses are one run of keys. The parts are filled in two passes (count, then place) without locks,
///   per fixed chunk of triangles.
///
/// The counts do not depend on the thread count. Preconditions: indices in range (as every
/// reader and the engine produce); fewer than 2³¹ vertices, beyond which the hash-map version
/// runs. Memory beside the mesh: 4 bytes per vertex (the welded ids), 1 byte per vertex (used
/// flags), 16 bytes per vertex during the weld (freed before the edges), and 24 bytes per
/// triangle (the side keys); about half of the mesh's own memory for a typical tessellation
/// with normals and uvs. Cost: O(V + T) expected work plus sorts of cache-sized parts,
/// parallel on the rayon threads.
pub fn watertight(mesh: &Mesh) -> WatertightReport {
    let n = mesh.positions.len();
    if n >= 1 << 31 {
        return watertight_hashed(mesh);
    }
    let welded = weld(&mesh.positions);
    let t_count = mesh.triangle_count();
    let used: Vec<AtomicBool> = (0..n).into_par_iter().map(|_| AtomicBool::new(false)).collect();

    let parts = n.div_ceil(1 << PART_BITS).max(1);
    let chunk = EDGE_CHUNK.max(t_count.div_ceil(MAX_CHUNKS));
    let chunks = t_count.div_ceil(chunk);
    let triangles_of = |c: usize| &mesh.indices[3 * c * chunk..3 * ((c + 1) * chunk).min(t_count)];
    // Pass 1, per chunk of triangles: the degenerate counts, the used vertices, and how many
    // sides each part gets from the chunk.
    let counted: Vec<(usize, usize, Vec<u32>)> = (0..chunks)
        .into_par_iter()
        .map(|c| {
            let (mut collapsed, mut zero_area) = (0, 0);
            let mut per_part = vec![0u32; parts];
            for corners in triangles_of(c).chunks_exact(3) {
                let Some((ends, sides)) = side_keys(&welded, corners) else {
                    collapsed += 1;
                    continue;
                };
                // Spelled out rather than an array `map`: that version went through the stack
                // and stalled on every triangle.
                let p0 = Vec3::from(mesh.positions[corners[0] as usize]).as_dvec3();
                let p1 = Vec3::from(mesh.positions[corners[1] as usize]).as_dvec3();
                let p2 = Vec3::from(mesh.positions[corners[2] as usize]).as_dvec3();
                zero_area += usize::from((p1 - p0).cross(p2 - p0) == DVec3::ZERO);
                for v in ends {
                    used[v as usize].store(true, Relaxed);
                }
                for (part, _) in sides {
                    per_part[part] += 1;
                }
            }
            (collapsed, zero_area, per_part)
        })
        .collect();

    // Where each chunk's sides of each part go: parts in order, chunks in order within a part.
    let mut part_start = vec![0usize; parts + 1];
    for p in 0..parts {
        part_start[p + 1] = part_start[p] + counted.iter().map(|(_, _, h)| h[p] as usize).sum::<usize>();
    }
    let mut keys = vec![0u64; part_start[parts]];
    // One slice per (chunk, part), cut off the key array in order: the passes below write and
    // read disjoint pieces without locks or unsafe code.
    let mut pieces: Vec<Vec<&mut [u64]>> = (0..chunks).map(|_| Vec::with_capacity(parts)).collect();
    let mut rest: &mut [u64] = &mut keys;
    for p in 0..parts {
        for (c, (_, _, h)) in counted.iter().enumerate() {
            let (piece, tail) = std::mem::take(&mut rest).split_at_mut(h[p] as usize);
            pieces[c].push(piece);
            rest = tail;
        }
    }
    // Pass 2: place the keys.
    pieces.par_iter_mut().enumerate().for_each(|(c, pieces)| {
        let mut fill = vec![0usize; parts];
        for corners in triangles_of(c).chunks_exact(3) {
            if let Some((_, sides)) = side_keys(&welded, corners) {
                for (part, key) in sides {
                    pieces[part][fill[part]] = key;
                    fill[part] += 1;
                }
            }
        }
    });
    drop(pieces);
    drop(welded);

    let mut report = WatertightReport { triangles: t_count, ..Default::default() };
    for (collapsed, zero_area, _) in &counted {
        report.collapsed_triangles += collapsed;
        report.zero_area_triangles += zero_area;
    }
    drop(counted);
    // Pass 3, per part: sort, then count each run of one edge's uses.
    let mut part_keys: Vec<&mut [u64]> = Vec::with_capacity(parts);
    let mut rest: &mut [u64] = &mut keys;
    for p in 0..parts {
        let (piece, tail) = std::mem::take(&mut rest).split_at_mut(part_start[p + 1] - part_start[p]);
        part_keys.push(piece);
        rest = tail;
    }
    let edges = part_keys
        .into_par_iter()
        .map_init(
            || (vec![0u32; (1 << PART_BITS) + 1], vec![0u32; (1 << PART_BITS) + 1], Vec::new()),
            |(starts, next, by_lo), keys| {
                // A counting sort by the smaller end (in cache: one part), then each end's few
                // sides (about six) sorted on their own: several times faster than sorting
                // the part's keys whole.
                starts.fill(0);
                for &k in keys.iter() {
                    starts[(k >> 32) as usize + 1] += 1;
                }
                for lo in 0..1 << PART_BITS {
                    starts[lo + 1] += starts[lo];
                }
                by_lo.clear();
                by_lo.resize(keys.len(), 0u32);
                next.copy_from_slice(starts);
                for &k in keys.iter() {
                    let slot = &mut next[(k >> 32) as usize];
                    // The larger end and the direction.
                    by_lo[*slot as usize] = k as u32;
                    *slot += 1;
                }
                let mut r = WatertightReport::default();
                for lo in 0..1 << PART_BITS {
                    let sides = &mut by_lo[starts[lo] as usize..starts[lo + 1] as usize];
                    sides.sort_unstable();
                    for run in sides.chunk_by(|a, b| a >> 1 == b >> 1) {
                        let backward = run.iter().filter(|&&k| k & 1 == 1).count() as u32;
                        r.count_edge(run.len() as u32 - backward, backward);
                    }
                }
                r
            },
        )
        .reduce(WatertightReport::default, |a, b| WatertightReport {
            edges: a.edges + b.edges,
            boundary_edges: a.boundary_edges + b.boundary_edges,
            nonmanifold_edges: a.nonmanifold_edges + b.nonmanifold_edges,
            misoriented_edges: a.misoriented_edges + b.misoriented_edges,
            ..a
        });
    report.edges = edges.edges;
    report.boundary_edges = edges.boundary_edges;
    report.nonmanifold_edges = edges.nonmanifold_edges;
    report.misoriented_edges = edges.misoriented_edges;
    report.vertices = used.par_iter().filter(|u| u.load(Relaxed)).count();
    report.finish()
}

/// Sides go to part `smaller end >> PART_BITS`, so a part's keys hold the smaller end
/// relative to the part (PART_BITS bits), the larger end and the direction.
const PART_BITS: u32 = 12;

/// A triangle's three sides as (part, key).
type TriangleSides = [(usize, u64); 3];

/// The welded ends of the triangle with `corners`, and its three sides as (part, key) for
/// [`watertight`]; `None` when two ends are one (a collapsed triangle).
#[inline(always)]
fn side_keys(welded: &[AtomicU32], corners: &[u32]) -> Option<([u32; 3], TriangleSides)> {
    let v = [corners[0], corners[1], corners[2]].map(|i| welded[i as usize].load(Relaxed));
    if v[0] == v[1] || v[1] == v[2] || v[0] == v[2] {
        return None;
    }
    #[inline(always)]
    fn side(a: u32, b: u32) -> (usize, u64) {
        let (lo, hi) = (a.min(b), a.max(b));
        let key = (u64::from(lo & ((1 << PART_BITS) - 1)) << 32) | (u64::from(hi) << 1) | u64::from(a > b);
        ((lo >> PART_BITS) as usize, key)
    }
    Some((v, [side(v[0], v[1]), side(v[1], v[2]), side(v[2], v[0])]))
}

/// Triangles (or vertices) per chunk of the partitioned passes: enough that a chunk's count
/// of each part is worth its array, few enough chunks that the (chunk, part) table stays small.
const EDGE_CHUNK: usize = 1 << 16;
const MAX_CHUNKS: usize = 64;

/// A position's bits with its index, `[x, y, z, index]`, as the weld's parts hold them: an
/// array, so that a vector of them starts zeroed by the allocator.
type Keyed = [u32; 4];

/// A 64-bit hash of position bits: multiply-xorshift (splitmix64's finaliser), whose top bits
/// choose the part and low bits the slot; well spread for the regular grids of a tessellation.
fn hash_key(k: [u32; 3]) -> u64 {
    let mut h =
        (u64::from(k[0]) | u64::from(k[1]) << 32) ^ u64::from(k[2]).wrapping_mul(0x9e37_79b9_7f4a_7c15);
    h ^= h >> 30;
    h = h.wrapping_mul(0xbf58_476d_1ce4_e5b9);
    h ^= h >> 27;
    h = h.wrapping_mul(0x94d0_49bb_1331_11eb);
    h ^ (h >> 31)
}

/// For each vertex, the smallest index of a vertex with the same position bits, as relaxed
/// atomics: the parts write the ids of scattered vertices in parallel, and a relaxed store or
/// load is a plain one. See [`watertight`] for the method. Preconditions: fewer than 2³¹
/// positions.
fn weld(positions: &[[f32; 3]]) -> Vec<AtomicU32> {
    let n = positions.len();
    // Parts of 8–16 K positions: their tables (64–128 KiB) stay in cache, and few enough
    // parts that scattering the positions into them writes few streams at a time.
    let part_bits = (n / 16384).max(1).next_power_of_two().trailing_zeros();
    let parts = 1usize << part_bits;
    let part_of = |h: u64| if part_bits == 0 { 0 } else { (h >> (64 - part_bits)) as usize };
    let chunk = EDGE_CHUNK.max(n.div_ceil(MAX_CHUNKS));
    let chunks = n.div_ceil(chunk);
    let counts: Vec<Vec<u32>> = (0..chunks)
        .into_par_iter()
        .map(|c| {
            let mut h = vec![0u32; parts];
            for p in &positions[c * chunk..((c + 1) * chunk).min(n)] {
                h[part_of(hash_key(position_key(*p)))] += 1;
            }
            h
        })
        .collect();
    // Zeroed by the allocator (lazily, page by page), not written here first.
    let mut entries: Vec<Keyed> = vec![[0; 4]; n];
    let mut part_len = vec![0usize; parts];
    let mut pieces: Vec<Vec<&mut [Keyed]>> = (0..chunks).map(|_| Vec::with_capacity(parts)).collect();
    let mut rest: &mut [Keyed] = &mut entries;
    for p in 0..parts {
        for (c, h) in counts.iter().enumerate() {
            let (piece, tail) = std::mem::take(&mut rest).split_at_mut(h[p] as usize);
            pieces[c].push(piece);
            part_len[p] += h[p] as usize;
            rest = tail;
        }
    }
    drop(counts);
    // Chunks in index order, so each part lists its vertices in increasing index: the first
    // one seen at a position is the smallest index there.
    pieces.par_iter_mut().enumerate().for_each(|(c, pieces)| {
        let mut fill = vec![0usize; parts];
        let range = c * chunk..((c + 1) * chunk).min(n);
        for (i, &position) in positions[range.clone()].iter().enumerate().map(|(k, p)| (range.start + k, p)) {
            let key = position_key(position);
            let p = part_of(hash_key(key));
            pieces[p][fill[p]] = [key[0], key[1], key[2], i as u32];
            fill[p] += 1;
        }
    });
    drop(pieces);
    // Every vertex its own id to begin with, so that only duplicates are stored below: one
    // scattered store per duplicate, not per vertex.
    let welded: Vec<AtomicU32> = (0..n as u32).into_par_iter().map(AtomicU32::new).collect();
    let mut part_entries: Vec<&[Keyed]> = Vec::with_capacity(parts);
    let mut rest: &[Keyed] = &entries;
    for len in part_len {
        let (piece, tail) = rest.split_at(len);
        part_entries.push(piece);
        rest = tail;
    }
    part_entries.into_par_iter().for_each_init(Vec::new, |table: &mut Vec<u32>, part| {
        // Open addressing, linear probing, at most half full; slots hold an entry's place
        // in the part (u32::MAX: empty).
        let size = (2 * part.len()).next_power_of_two().max(2);
        table.clear();
        table.resize(size, u32::MAX);
        let mask = size - 1;
        for (k, e) in part.iter().enumerate() {
            let (key, index) = ([e[0], e[1], e[2]], e[3]);
            let mut slot = hash_key(key) as usize & mask;
            let first = loop {
                match table[slot] {
                    u32::MAX => {
                        table[slot] = k as u32;
                        break index;
                    }
                    other if part[other as usize][..3] == key => break part[other as usize][3],
                    _ => slot = (slot + 1) & mask,
                }
            };
            if first != index {
                welded[index as usize].store(first, Relaxed);
            }
        }
    });
    welded
}

/// Every vertex's id after welding bit-identical positions, numbered in first-seen order, and
/// the number of distinct positions. Cost: O(V) hashing, on one thread.
fn weld_hashed(mesh: &Mesh) -> (Vec<u32>, usize) {
    let mut ids: HashMap<[u32; 3], u32> = HashMap::with_capacity(mesh.positions.len());
    let welded = mesh
        .positions
        .iter()
        .map(|&p| {
            let next = ids.len() as u32;
            *ids.entry(position_key(p)).or_insert(next)
        })
        .collect();
    (welded, ids.len())
}

/// [`watertight`] with hash maps: for meshes of 2³¹ vertices or more, which the packed
/// keys of the parallel version cannot hold, and as the tests' reference.
/// Cost: O(T) hashing.
fn watertight_hashed(mesh: &Mesh) -> WatertightReport {
    let (welded, distinct) = weld_hashed(mesh);
    let mut report = WatertightReport { triangles: mesh.triangle_count(), ..Default::default() };
    // Directed edge counts: (a, b) with a < b → (forward, backward).
    let mut edges: HashMap<(u32, u32), (u32, u32)> = HashMap::with_capacity(mesh.indices.len());
    let mut used = vec![false; distinct];
    for t in 0..mesh.triangle_count() {
        let v = mesh.triangle(t).map(|i| welded[i as usize]);
        if v[0] == v[1] || v[1] == v[2] || v[0] == v[2] {
            report.collapsed_triangles += 1;
            continue;
        }
        let p = mesh.triangle(t).map(|i| Vec3::from(mesh.positions[i as usize]).as_dvec3());
        if (p[1] - p[0]).cross(p[2] - p[0]) == DVec3::ZERO {
            report.zero_area_triangles += 1;
        }
        for c in 0..3 {
            used[v[c] as usize] = true;
            let (a, b) = (v[c], v[(c + 1) % 3]);
            let entry = edges.entry((a.min(b), a.max(b))).or_default();
            if a < b {
                entry.0 += 1
            } else {
                entry.1 += 1
            }
        }
    }
    report.vertices = used.iter().filter(|&&u| u).count();
    for &(f, b) in edges.values() {
        report.count_edge(f, b);
    }
    report.finish()
}

/// Distance between the mesh and the exact surface.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ErrorReport {
    /// Largest distance between a point of a triangle and the surface point at the same
    /// parameters.
    pub max: f64,
    /// Root mean square over all sample points.
    pub rms: f64,
    /// Triangle where the maximum was found.
    pub max_triangle: usize,
    /// Number of sample points.
    pub samples: usize,
}

/// One way a mesh's topology differs from the input it is checked against.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum TopologyMismatch {
    /// A triangle names a patch the input does not have.
    ForeignPatch {
        patch: u32,
        input_patches: usize,
    },
    /// The mesh carries patch ids, but of a different number of patches than the input has.
    PatchCount {
        mesh: usize,
        input: usize,
    },
    /// The input is closed, the mesh open or non-manifold.
    Opened,
    /// The input is manifold, the mesh has non-manifold edges.
    NonManifold {
        edges: usize,
    },
    EulerCharacteristic {
        mesh: i64,
        input: i64,
    },
    /// Connected components (pieces joined at a vertex count as one).
    Components {
        mesh: usize,
        input: usize,
    },
    /// Boundary loops: the connected pieces of the boundary edges (of the free curves).
    BoundaryLoops {
        mesh: usize,
        input: usize,
    },
}

impl std::fmt::Display for TopologyMismatch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            TopologyMismatch::ForeignPatch { patch, input_patches } => write!(
                f,
                "the mesh refers to patch {patch} but the input has {input_patches} patches: it was not made from this input"
            ),
            TopologyMismatch::PatchCount { mesh, input } => {
                write!(f, "the mesh has triangles of {mesh} patches, the input has {input} patches")
            }
            TopologyMismatch::Opened => write!(f, "the input is closed but the mesh is open or non-manifold"),
            TopologyMismatch::NonManifold { edges } => {
                write!(f, "the input is manifold but the mesh has {edges} non-manifold edges")
            }
            TopologyMismatch::EulerCharacteristic { mesh, input } => {
                write!(f, "the mesh's Euler characteristic is {mesh}, the input's {input}")
            }
            TopologyMismatch::Components { mesh, input } => {
                write!(f, "the mesh has {mesh} connected components, the input {input}")
            }
            TopologyMismatch::BoundaryLoops { mesh, input } => {
                write!(f, "the mesh has {mesh} boundary loops, the input {input}")
            }
        }
    }
}

/// Union-find with path halving; the components are counted over the elements marked used.
struct Components {
    parent: Vec<u32>,
    used: Vec<bool>,
}

impl Components {
    fn new(n: usize) -> Self {
        Components { parent: (0..n as u32).collect(), used: vec![false; n] }
    }

    fn root(&mut self, mut x: u32) -> u32 {
        while self.parent[x as usize] != x {
            let grand = self.parent[self.parent[x as usize] as usize];
            self.parent[x as usize] = grand;
            x = grand;
        }
        x
    }

    fn join(&mut self, a: u32, b: u32) {
        self.used[a as usize] = true;
        self.used[b as usize] = true;
        let (a, b) = (self.root(a), self.root(b));
        self.parent[a.max(b) as usize] = a.min(b);
    }

    fn count(&mut self) -> usize {
        (0..self.parent.len() as u32).filter(|&x| self.used[x as usize] && self.root(x) == x).count()
    }
}

/// Connected components and boundary loops of `mesh` after welding bit-identical positions
/// (as [`watertight`] does); a boundary edge is a side of one non-collapsed triangle.
/// Cost: O(V + T) hashing, on one thread (`tessera check` calls it once).
pub fn mesh_components_and_boundary_loops(mesh: &Mesh) -> (usize, usize) {
    let (welded, distinct) = weld_hashed(mesh);
    let mut pieces = Components::new(distinct);
    let mut sides: HashMap<(u32, u32), u32> = HashMap::with_capacity(mesh.indices.len());
    for corners in mesh.indices.chunks_exact(3) {
        let [a, b, c] = [0, 1, 2].map(|k| welded[corners[k] as usize]);
        pieces.join(a, b);
        pieces.join(b, c);
        if a == b || b == c || a == c {
            continue;
        }
        for (x, y) in [(a, b), (b, c), (c, a)] {
            *sides.entry((x.min(y), x.max(y))).or_insert(0) += 1;
        }
    }
    let mut loops = Components::new(distinct);
    for (&(x, y), _) in sides.iter().filter(|(_, &n)| n == 1) {
        loops.join(x, y);
    }
    (pieces.count(), loops.count())
}

/// Connected components and boundary loops of `set`'s input topology, counted as
/// [`mesh_components_and_boundary_loops`] counts them on a mesh: patches joined at their corners,
/// and the free (single-use, not collapsed) curves joined at their ends.
pub fn input_components_and_boundary_loops(set: &SurfaceSet) -> (usize, usize) {
    let topo = &set.topology;
    let n = topo.vertex_count as usize;
    let mut pieces = Components::new(n);
    for (corners, domain) in topo.patch_corners.iter().zip(&topo.patch_domains) {
        let c = &corners[..domain.corner_count()];
        for k in 0..c.len() {
            pieces.join(c[k], c[(k + 1) % c.len()]);
        }
    }
    let mut loops = Components::new(n);
    for (e, edge) in topo.edges.iter().enumerate() {
        if !edge.collapsed && topo.edge_uses(e).len() == 1 {
            loops.join(edge.ends[0], edge.ends[1]);
        }
    }
    (pieces.count(), loops.count())
}

/// Every way `mesh` (with its [`watertight`] report `w`) differs in topology from `set`, the
/// input it is said to come from: patch ids it does not have or a different number of them
/// (where the mesh carries patch ids: any nonzero one), a closed or manifold input made open
/// or non-manifold, the Euler characteristic, the connected components and the boundary
/// loops. Empty when the mesh has the input's topology. Cost: that of
/// [`mesh_components_and_boundary_loops`].
pub fn topology_mismatches(mesh: &Mesh, w: &WatertightReport, set: &SurfaceSet) -> Vec<TopologyMismatch> {
    let t = set.topology.report;
    let mut found = Vec::new();
    if let Some(&patch) = mesh.triangle_patch.iter().max() {
        if patch as usize >= t.patches {
            found.push(TopologyMismatch::ForeignPatch { patch, input_patches: t.patches });
        } else if patch > 0 {
            let mut seen = vec![false; t.patches];
            mesh.triangle_patch.iter().for_each(|&p| seen[p as usize] = true);
            let used = seen.iter().filter(|&&s| s).count();
            if used != t.patches {
                found.push(TopologyMismatch::PatchCount { mesh: used, input: t.patches });
            }
        }
    }
    if t.is_closed() && !w.is_closed() {
        found.push(TopologyMismatch::Opened);
    } else if t.nonmanifold_edges == 0 && w.nonmanifold_edges > 0 {
        found.push(TopologyMismatch::NonManifold { edges: w.nonmanifold_edges });
    }
    if w.euler_characteristic != t.euler_characteristic {
        found.push(TopologyMismatch::EulerCharacteristic {
            mesh: w.euler_characteristic,
            input: t.euler_characteristic,
        });
    }
    let (mesh_pieces, mesh_loops) = mesh_components_and_boundary_loops(mesh);
    let (input_pieces, input_loops) = input_components_and_boundary_loops(set);
    if mesh_pieces != input_pieces {
        found.push(TopologyMismatch::Components { mesh: mesh_pieces, input: input_pieces });
    }
    if mesh_loops != input_loops {
        found.push(TopologyMismatch::BoundaryLoops { mesh: mesh_loops, input: input_loops });
    }
    found
}

/// Measures the approximation error: inside every triangle, at the points of an order-`order`
/// barycentric grid (vertices excluded, `order ≥ 2`), the distance between the triangle's
/// linear interpolation and the exact surface of the triangle's patch at the interpolated
/// parameters. Preconditions: `mesh.corner_params` is filled (ask the engine for it) and
/// `mesh.triangle_patch` refers to `set`. Cost: O(T · order²) surface evaluations, parallel.
pub fn approximation_error(mesh: &Mesh, set: &SurfaceSet, order: u32) -> Result<ErrorReport> {
    let params = mesh.corner_params.as_ref().ok_or_else(|| Error::InvalidParameter {
        name: "mesh",
        reason: "it has no per-corner patch parameters (ask the engine for them)".into(),
    })?;
    if params.len() != mesh.indices.len() || mesh.triangle_patch.len() != mesh.triangle_count() {
        return Err(Error::InvalidParameter {
            name: "mesh",
            reason: "its parameter arrays have inconsistent lengths".into(),
        });
    }
    if let Some(&p) = mesh.triangle_patch.iter().find(|&&p| p as usize >= set.patches.len()) {
        return Err(Error::PlanMismatch {
            what: format!(
                "a triangle refers to patch {p}, but the surface has {} patches",
                set.patches.len()
            ),
        });
    }
    let order = order.max(2);
    // Sample points strictly inside or on the edges, excluding the three vertices.
    let mut bary = Vec::new();
    for i in 0..=order {
        for j in 0..=order - i {
            let k = order - i - j;
            if i == order || j == order || k == order {
                continue;
            }
            bary.push(DVec3::new(i as f64, j as f64, k as f64) / order as f64);
        }
    }
    // Fixed blocks summed in order: rayon's own reduction splits by work stealing, so the
    // floating-point sum (and the RMS) would change in its last bits from run to run.
    const BLOCK: usize = 1024;
    let blocks: Vec<(f64, usize, f64)> = (0..mesh.triangle_count().div_ceil(BLOCK))
        .into_par_iter()
        .map(|block| {
            let mut worst = (0.0f64, block * BLOCK);
            let mut sum2 = 0.0;
            for t in block * BLOCK..((block + 1) * BLOCK).min(mesh.triangle_count()) {
                let patch = &set.patches[mesh.triangle_patch[t] as usize];
                let x = mesh.triangle(t).map(|i| Vec3::from(mesh.positions[i as usize]).as_dvec3());
                let uv = [0, 1, 2].map(|c| DVec2::from(params[3 * t + c].map(f64::from)));
                for b in &bary {
                    let linear = x[0] * b.x + x[1] * b.y + x[2] * b.z;
                    let q = uv[0] * b.x + uv[1] * b.y + uv[2] * b.z;
                    let d = linear.distance(patch.position(q));
                    if d > worst.0 {
                        worst = (d, t);
                    }
                    sum2 += d * d;
                }
            }
            (worst.0, worst.1, sum2)
        })
        .collect();
    let (max, max_triangle, sum2) = blocks.into_iter().fold((0.0, 0, 0.0), |a, b| {
        let (m, t) = if b.0 > a.0 { (b.0, b.1) } else { (a.0, a.1) };
        (m, t, a.2 + b.2)
    });
    let samples = bary.len() * mesh.triangle_count();
    Ok(ErrorReport {
        max,
        rms: if samples > 0 { (sum2 / samples as f64).sqrt() } else { 0.0 },
        max_triangle,
        samples,
    })
}

/// Triangle shape statistics.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct QualityReport {
    /// Histogram of each triangle's smallest angle in 5° bins: `[0,5), [5,10), … [55,60]`.
    pub min_angle_histogram: [u64; 12],
    /// Smallest angle in the mesh, degrees.
    pub min_angle: f64,
    /// Share of triangles whose smallest angle is under 10°.
    pub share_below_10_degrees: f64,
    /// Largest ratio of longest edge to shortest altitude · 2/√3 (1 for equilateral).
    pub max_aspect_ratio: f64,
}

/// Angle and aspect statistics over all triangles (collapsed ones count as 0°). Cost: O(T).
pub fn quality(mesh: &Mesh) -> QualityReport {
    let mut r = QualityReport { min_angle: 180.0, ..Default::default() };
    let mut below = 0u64;
    for t in 0..mesh.triangle_count() {
        let p = mesh.triangle(t).map(|i| Vec3::from(mesh.positions[i as usize]).as_dvec3());
        let mut smallest = 180.0f64;
        let mut longest = 0.0f64;
        for c in 0..3 {
            let a = p[(c + 1) % 3] - p[c];
            let b = p[(c + 2) % 3] - p[c];
            longest = longest.max(a.length());
            let angle = match (a.try_normalize(), b.try_normalize()) {
                (Some(a), Some(b)) => a.dot(b).clamp(-1.0, 1.0).acos().to_degrees(),
                _ => 0.0,
            };
            smallest = smallest.min(angle);
        }
        let area2 = (p[1] - p[0]).cross(p[2] - p[0]).length();
        let aspect = if area2 > 0.0 {
            // longest / (2·area/longest) normalised so an equilateral triangle gives 1.
            longest * longest / area2 * (3f64.sqrt() / 2.0)
        } else {
            f64::INFINITY
        };
        r.max_aspect_ratio = r.max_aspect_ratio.max(aspect);
        r.min_angle = r.min_angle.min(smallest);
        let bin = ((smallest / 5.0) as usize).min(11);
        r.min_angle_histogram[bin] += 1;
        if smallest < 10.0 {
            below += 1;
        }
    }
    if mesh.triangle_count() == 0 {
        r.min_angle = 0.0;
    } else {
        r.share_below_10_degrees = below as f64 / mesh.triangle_count() as f64;
    }
    r
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mesh(positions: &[[f32; 3]], triangles: &[[u32; 3]]) -> Mesh {
        let n = positions.len();
        Mesh {
            positions: positions.to_vec(),
            normals: vec![[0.0, 0.0, 1.0]; n],
            uvs: vec![[0.0; 2]; n],
            vertex_patch: vec![0; n],
            indices: triangles.iter().flatten().copied().collect(),
            triangle_patch: vec![0; triangles.len()],
            ..Default::default()
        }
    }

    /// An octahedron, closed and consistently oriented (outward).
    fn octahedron() -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
        let p = vec![
            [1.0, 0.0, 0.0],
            [-1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, -1.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.0, 0.0, -1.0],
        ];
        let t = vec![[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]];
        (p, t)
    }

    #[test]
    fn a_closed_mesh_is_closed() {
        let (p, t) = octahedron();
        let w = watertight(&mesh(&p, &t));
        assert!(w.is_closed());
        assert_eq!((w.vertices, w.edges, w.euler_characteristic, w.misoriented_edges), (6, 12, 2, 0));
        assert_eq!(w, watertight_hashed(&mesh(&p, &t)));
    }

    #[test]
    fn a_crack_is_two_boundary_edges() {
        // Vertex 4 duplicated at a slightly different position for two of its triangles.
        let (mut p, mut t) = octahedron();
        p.push([0.0, 0.0, 1.0 + 1e-6]);
        t[0] = [0, 2, 6];
        t[1] = [2, 1, 6];
        let w = watertight(&mesh(&p, &t));
        assert_eq!(w.boundary_edges, 4, "{w:?}");
        assert!(!w.is_closed());
        // The same split at the same position bits welds back: no crack.
        p[6] = [0.0, 0.0, 1.0];
        assert!(watertight(&mesh(&p, &t)).is_closed());
    }

    #[test]
    fn a_t_junction_leaves_boundary_edges() {
        // Split edge 0-2 of one triangle at its midpoint only on one side.
        let (mut p, mut t) = octahedron();
        p.push([0.5, 0.5, 0.0]);
        t[0] = [0, 6, 4];
        t.push([6, 2, 4]);
        let w = watertight(&mesh(&p, &t));
        assert_eq!(w.boundary_edges, 3, "the long edge on one side, two halves on the other: {w:?}");
    }

    #[test]
    fn a_flipped_triangle_is_misoriented() {
        let (p, mut t) = octahedron();
        t[3].swap(1, 2);
        let w = watertight(&mesh(&p, &t));
        assert_eq!(w.misoriented_edges, 3, "{w:?}");
        assert_eq!(w.boundary_edges, 0);
    }

    #[test]
    fn a_third_triangle_on_an_edge_is_non_manifold() {
        let (mut p, mut t) = octahedron();
        p.push([0.5, 0.5, 0.5]);
        t.push([0, 2, 6]);
        let w = watertight(&mesh(&p, &t));
        assert_eq!(w.nonmanifold_edges, 1, "{w:?}");
        assert_eq!(w.boundary_edges, 2);
    }

    #[test]
    fn degenerate_triangles_are_counted() {
        let (mut p, mut t) = octahedron();
        p.extend([[3.0, 0.0, 0.0], [4.0, 0.0, 0.0], [5.0, 0.0, 0.0]]);
        t.push([6, 7, 8]); // zero area
        t.push([0, 0, 2]); // collapsed
        let w = watertight(&mesh(&p, &t));
        assert_eq!((w.zero_area_triangles, w.collapsed_triangles), (1, 1), "{w:?}");
    }

    /// The sort-based [`watertight`] that tessera used before the partitioned one (commit
    /// 35bba34), kept as a second reference: one global sort of (position bits, index) to
    /// weld, one global sort of all side keys. Memory: 32 bytes per vertex and 56 per triangle.
    fn watertight_sorted(mesh: &Mesh) -> WatertightReport {
        let n = mesh.positions.len();
        if n >= 1 << 31 {
            return super::watertight_hashed(mesh);
        }
        // Weld: sort (position bits, index); equal bits form one run, numbered in sorted order.
        let mut order: Vec<(u128, u32)> = mesh
            .positions
            .par_iter()
            .enumerate()
            .map(|(i, &p)| {
                let [x, y, z] = position_key(p);
                (((x as u128) << 64) | ((y as u128) << 32) | z as u128, i as u32)
            })
            .collect();
        order.par_sort_unstable();
        let mut welded = vec![0u32; n];
        let mut distinct = 0u32;
        for k in 0..n {
            if k > 0 && order[k].0 != order[k - 1].0 {
                distinct += 1;
            }
            welded[order[k].1 as usize] = distinct;
        }
        drop(order);

        let mut report = WatertightReport { triangles: mesh.triangle_count(), ..Default::default() };
        // Per triangle: collapsed, zero area, and its three sides as keys
        // `min << 33 | max << 1 | (min is the second end)`.
        let per_triangle: Vec<(bool, bool, [u64; 3])> = mesh
            .indices
            .par_chunks_exact(3)
            .map(|t| {
                let v = [t[0], t[1], t[2]].map(|i| welded[i as usize]);
                if v[0] == v[1] || v[1] == v[2] || v[0] == v[2] {
                    return (true, false, [0; 3]);
                }
                let p = [t[0], t[1], t[2]].map(|i| Vec3::from(mesh.positions[i as usize]).as_dvec3());
                let zero = (p[1] - p[0]).cross(p[2] - p[0]) == DVec3::ZERO;
                let side = |c: usize| {
                    let (a, b) = (v[c] as u64, v[(c + 1) % 3] as u64);
                    (a.min(b) << 33) | (a.max(b) << 1) | u64::from(a > b)
                };
                (false, zero, [side(0), side(1), side(2)])
            })
            .collect();
        let mut used = vec![false; n];
        let mut sides = Vec::with_capacity(3 * per_triangle.len());
        for (t, &(collapsed, zero, keys)) in per_triangle.iter().enumerate() {
            if collapsed {
                report.collapsed_triangles += 1;
                continue;
            }
            report.zero_area_triangles += usize::from(zero);
            for i in &mesh.indices[3 * t..3 * t + 3] {
                used[welded[*i as usize] as usize] = true;
            }
            sides.extend_from_slice(&keys);
        }
        drop(per_triangle);
        sides.par_sort_unstable();
        report.vertices = used.iter().filter(|&&u| u).count();
        let mut k = 0;
        while k < sides.len() {
            let edge = sides[k] >> 1;
            let (mut forward, mut backward) = (0, 0);
            while k < sides.len() && sides[k] >> 1 == edge {
                if sides[k] & 1 == 0 {
                    forward += 1;
                } else {
                    backward += 1;
                }
                k += 1;
            }
            report.count_edge(forward, backward);
        }
        report.finish()
    }

    /// The three implementations agree, and the partitioned one gives the same report with 1
    /// and with 2 threads.
    #[track_caller]
    fn assert_all_agree(m: &Mesh, what: &str) -> WatertightReport {
        let expected = watertight_hashed(m);
        assert_eq!(watertight_sorted(m), expected, "{what}: old sorted vs hashed");
        for threads in [1, 2] {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            assert_eq!(pool.install(|| watertight(m)), expected, "{what}, {threads} threads");
        }
        expected
    }

    /// Models with boundaries, non-manifold edges, unwelded duplicates, repeated corners and
    /// holes, read as meshes to check.
    #[test]
    fn implementations_agree_on_the_shared_meshes() {
        use crate::test_support::data;
        let cases = [
            ("meshes/bunny.obj", false),
            ("meshes/spot.obj", true),
            ("awkward/elephant_with_holes.obj", false),
            ("awkward/teapot_tri_nonmanifold.obj", false),
            ("awkward/teapot_unwelded.obj", false),
            ("meshes/bunny_res4.obj", false),
            ("meshes/dragon_res4.obj", false),
        ];
        for (rel, closed) in cases {
            let m = crate::io::read_mesh(&data(rel)).unwrap();
            let w = assert_all_agree(&m, rel);
            assert_eq!(w.is_closed(), closed, "{rel}: {w:?}");
        }
        // Not vacuous: the awkward files have what their names say.
        let w = watertight(&crate::io::read_mesh(&data("meshes/dragon_res4.obj")).unwrap());
        assert!(w.nonmanifold_edges > 0, "{w:?}");
        let w = watertight(&crate::io::read_mesh(&data("awkward/teapot_tri_nonmanifold.obj")).unwrap());
        assert!(w.collapsed_triangles == 32 && w.boundary_edges == 64, "the README's counts: {w:?}");
        let w = watertight(&crate::io::read_mesh(&data("awkward/elephant_with_holes.obj")).unwrap());
        assert!(w.boundary_edges > 0, "{w:?}");
    }

    /// The measured error is the same number, to the last bit, whatever the thread count and
    /// however rayon splits the work (the CLI and the Python package compare it exactly).
    #[test]
    fn approximation_error_does_not_depend_on_the_threads() {
        use crate::criterion::Plan;
        use crate::engine::{tessellate, EngineOptions};
        use crate::io::patches::read_patches;
        use crate::pattern::uniform::Uniform;
        use crate::test_support::data;
        let patches = read_patches(&data("patches/teacup.patches")).unwrap();
        let set = SurfaceSet::from_patch_file(&patches, Default::default());
        let plan = Plan::uniform(&set, 24).unwrap();
        let options = EngineOptions { corner_params: true, ..Default::default() };
        let mesh = tessellate(&set, &plan, &Uniform, options).unwrap();
        assert!(mesh.triangle_count() > 4 * 1024, "several blocks: {}", mesh.triangle_count());
        let measure = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| approximation_error(&mesh, &set, 5).unwrap())
        };
        let one = measure(1);
        for threads in [2, 3, 7] {
            let other = measure(threads);
            assert_eq!(
                (one.max.to_bits(), one.rms.to_bits(), one.max_triangle),
                (other.max.to_bits(), other.rms.to_bits(), other.max_triangle),
                "{threads} threads"
            );
        }
    }

    /// A tessellation large enough for several chunks and parts (262,144 triangles), whole
    /// and with hand-made breaks; and the teapot, whose lid apex gives collapsed triangles.
    #[test]
    fn implementations_agree_on_broken_tessellations() {
        use crate::criterion::Plan;
        use crate::engine::{tessellate, EngineOptions};
        use crate::io::patches::read_patches;
        use crate::pattern::uniform::Uniform;
        use crate::test_support::data;
        let tessellation = |rel: &str, factor: u32| {
            let set = SurfaceSet::from_patch_file(&read_patches(&data(rel)).unwrap(), Default::default());
            let plan = Plan::uniform(&set, factor).unwrap();
            tessellate(&set, &plan, &Uniform, EngineOptions::default()).unwrap()
        };
        let teapot = tessellation("patches/teapot.patches", 6);
        assert_all_agree(&teapot, "teapot");

        let torus = tessellation("bench/torus_64x32.patches", 8);
        assert_eq!(torus.triangle_count(), 262_144);
        let whole = assert_all_agree(&torus, "torus");
        assert!(whole.is_closed() && whole.misoriented_edges == 0, "{whole:?}");
        assert_eq!(whole.euler_characteristic, 0);

        let t = torus.triangle_count();
        let mut broken = torus.clone();
        // A crack: a copy of every 97th triangle's first corner, nudged by one ulp.
        for k in (0..t).step_by(97) {
            let i = broken.indices[3 * k] as usize;
            let mut p = broken.positions[i];
            p[0] = f32::from_bits(p[0].to_bits() + 1);
            broken.positions.push(p);
            broken.indices[3 * k] = broken.positions.len() as u32 - 1;
        }
        // The same without the nudge welds back: unwelded duplicates, no crack.
        let mut duplicated = torus.clone();
        for k in (0..t).step_by(89) {
            let i = duplicated.indices[3 * k + 1] as usize;
            duplicated.positions.push(duplicated.positions[i]);
            duplicated.indices[3 * k + 1] = duplicated.positions.len() as u32 - 1;
        }
        // Flipped triangles, a hole, a collapsed triangle, zero-area triangles and triangles
        // stacked on existing edges (non-manifold).
        let mut mixed = torus.clone();
        for k in (0..t).step_by(1000) {
            mixed.indices.swap(3 * k, 3 * k + 1);
        }
        mixed.indices.drain(3 * 5000..3 * 5010);
        mixed.indices.extend([0, 0, 1]);
        for k in (0..t).step_by(5003) {
            mixed.indices.extend(torus.triangle(k));
        }
        let n = mixed.positions.len() as u32;
        mixed.positions.extend([
            [9.0, 0.0, 0.0],
            [10.0, 0.0, 0.0],
            [11.0, 0.0, 0.0],
            [-0.0, 5.0, 5.0],
            [0.0, 5.0, 5.0],
        ]);
        mixed.indices.extend([n, n + 1, n + 2, n + 3, n + 4, n]);
        for m in [&mut broken, &mut duplicated, &mut mixed] {
            let n = m.positions.len();
            m.normals.resize(n, [0.0; 3]);
            m.uvs.resize(n, [0.0; 2]);
            m.vertex_patch.resize(n, 0);
            m.triangle_patch.resize(m.indices.len() / 3, 0);
        }
        let w = assert_all_agree(&broken, "cracked torus");
        // At least the two sides at each nudged corner: its triangle alone uses them.
        assert!(w.boundary_edges >= 2 * t.div_ceil(97), "{w:?}");
        assert_eq!(assert_all_agree(&duplicated, "duplicated torus"), whole);
        let w = assert_all_agree(&mixed, "mixed torus");
        assert!(w.misoriented_edges > 0 && w.boundary_edges > 0 && w.nonmanifold_edges > 0, "{w:?}");
        assert_eq!(w.collapsed_triangles, 2, "{w:?}");
        assert_eq!(w.zero_area_triangles, 1, "{w:?}");
    }

    #[test]
    fn sorting_and_hashing_agree_on_random_meshes() {
        use proptest::prelude::RngExt;
        use proptest::test_runner::{RngAlgorithm, TestRng};
        let mut rng = TestRng::from_seed(RngAlgorithm::ChaCha, &[3; 32]);
        for _ in 0..200 {
            let n = rng.random_range(3..40u32);
            // Few distinct positions, so welding, duplicates and non-manifold edges all occur.
            let p: Vec<[f32; 3]> =
                (0..n).map(|_| [rng.random_range(0..4) as f32, rng.random_range(0..3) as f32, 0.5]).collect();
            let t: Vec<[u32; 3]> = (0..rng.random_range(1..60))
                .map(|_| [rng.random_range(0..n), rng.random_range(0..n), rng.random_range(0..n)])
                .collect();
            let m = mesh(&p, &t);
            assert_all_agree(&m, "random");
        }
    }
}
