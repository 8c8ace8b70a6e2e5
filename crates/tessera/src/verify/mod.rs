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
}

fn position_key(p: [f32; 3]) -> [u32; 3] {
    // +0.0 makes -0.0 and 0.0 weld.
    p.map(|x| (x + 0.0).to_bits())
}

/// Welds positions by exact bits and counts boundary, non-manifold and misoriented edges.
/// Cost: O(T) hashing.
pub fn watertight(mesh: &Mesh) -> WatertightReport {
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
    report.edges = edges.len();
    for &(f, b) in edges.values() {
        match f + b {
            1 => report.boundary_edges += 1,
            2 if f == 2 || b == 2 => report.misoriented_edges += 1,
            2 => {}
            _ => report.nonmanifold_edges += 1,
        }
    }
    let faces = (report.triangles - report.collapsed_triangles) as i64;
    report.euler_characteristic = report.vertices as i64 - report.edges as i64 + faces;
    report
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
    let params = mesh
        .corner_params
        .as_ref()
        .ok_or_else(|| Error::InvalidArgument("the mesh has no per-corner patch parameters".into()))?;
    if params.len() != mesh.indices.len() || mesh.triangle_patch.len() != mesh.triangle_count() {
        return Err(Error::InvalidArgument("mesh parameter arrays have inconsistent lengths".into()));
    }
    if let Some(&p) = mesh.triangle_patch.iter().find(|&&p| p as usize >= set.patches.len()) {
        return Err(Error::InvalidArgument(format!(
            "triangle refers to patch {p}, but the surface has {} patches",
            set.patches.len()
        )));
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
