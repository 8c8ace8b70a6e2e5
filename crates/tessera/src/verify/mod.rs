//! Verification: watertightness, approximation error against the exact surface, triangle
//! quality. The same code serves the tests, `tessera check` and the benchmarks.

use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::surface::SurfaceSet;
use glam::{DVec2, DVec3, Vec3};
use rayon::prelude::*;
use std::collections::HashMap;

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
/// Parallel and sort-based (a hash map per edge is several times slower and larger): the
/// positions are sorted to weld them, then every triangle side becomes one packed 64-bit key
/// (the two welded ends and the direction) and the keys are sorted, so each edge's uses are
/// one run. Memory: 24 bytes per vertex and 24 per triangle beside the mesh. Cost:
/// O(V log V + T log T) work, parallel.
pub fn watertight(mesh: &Mesh) -> WatertightReport {
    let n = mesh.positions.len();
    if n >= 1 << 31 {
        return watertight_hashed(mesh);
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

/// [`watertight`] with hash maps: for meshes of 2³¹ vertices or more, which the packed
/// sort keys of the parallel version cannot hold, and as the tests' reference.
/// Cost: O(T) hashing.
fn watertight_hashed(mesh: &Mesh) -> WatertightReport {
    let mut ids: HashMap<[u32; 3], u32> = HashMap::with_capacity(mesh.positions.len());
    let welded: Vec<u32> = mesh
        .positions
        .iter()
        .map(|&p| {
            let next = ids.len() as u32;
            *ids.entry(position_key(p)).or_insert(next)
        })
        .collect();
    let mut report = WatertightReport { triangles: mesh.triangle_count(), ..Default::default() };
    // Directed edge counts: (a, b) with a < b → (forward, backward).
    let mut edges: HashMap<(u32, u32), (u32, u32)> = HashMap::with_capacity(mesh.indices.len());
    let mut used = vec![false; ids.len()];
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
    let (max, max_triangle, sum2) = (0..mesh.triangle_count())
        .into_par_iter()
        .map(|t| {
            let patch = &set.patches[mesh.triangle_patch[t] as usize];
            let x = mesh.triangle(t).map(|i| Vec3::from(mesh.positions[i as usize]).as_dvec3());
            let uv = [0, 1, 2].map(|c| DVec2::from(params[3 * t + c].map(f64::from)));
            let mut worst = 0.0f64;
            let mut sum2 = 0.0;
            for b in &bary {
                let linear = x[0] * b.x + x[1] * b.y + x[2] * b.z;
                let q = uv[0] * b.x + uv[1] * b.y + uv[2] * b.z;
                let d = linear.distance(patch.position(q));
                worst = worst.max(d);
                sum2 += d * d;
            }
            (worst, t, sum2)
        })
        .reduce(
            || (0.0, 0, 0.0),
            |a, b| {
                let (m, t) = if b.0 > a.0 { (b.0, b.1) } else { (a.0, a.1) };
                (m, t, a.2 + b.2)
            },
        );
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
            assert_eq!(watertight(&m), watertight_hashed(&m));
        }
    }
}
