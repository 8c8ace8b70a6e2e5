//! View-dependent heuristic criteria without an error guarantee: distance to the eye plane
//! (paper 001 section 3.2) and silhouettes (paper 001's vertex classification; the
//! silhouetteness of paper 000 / DRS08).
//!
//! Crack-freeness: each edge factor is a function of data both neighbours agree on — its two
//! end vertices (distance, classification) or the normals of all its patches at the edge
//! midpoint (silhouetteness) — computed once per edge.

use super::screen;
use super::tolerance::{minimum_interior, minimum_segments, Layout};
use super::Plan;
use crate::camera::Camera;
use crate::sampling::EdgeSampling;
use crate::surface::{Domain, SurfaceSet};
use glam::DVec3;

/// The mapping `g` from a level value to a factor (paper 001, section 3.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mapping {
    /// `g1(d) = fmax·(dmax − d)/(dmax − dmin) + fmin·(d − dmin)/(dmax − dmin)`.
    Linear,
    /// `g2(d) = (fmax − fmin)/(dmin − dmax)²·(d − dmax)² + fmin`.
    Quadratic,
}

/// A view-dependent edge criterion.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ViewCriterion {
    /// Edge factor `g(min(d(s), d(e)))`, `d` the depth of a corner vertex along the view.
    Distance(Mapping),
    /// Edge factor `fmax` where the two end vertices are classified differently
    /// (front-facing `n·(eye − v) ≥ 0` or not), `fmin` elsewhere (paper 001).
    SilhouetteVertices,
    /// Edge factor `fmin + s·(fmax − fmin)` with the silhouetteness `s` of DRS08:
    /// `s = 1` where the patches' normals at the edge midpoint face opposite ways from the
    /// eye, `s = 1 − (c·nL)(c·nR)/β` (clamped to [0, 1]) near it, `β = 1/4`.
    Silhouetteness,
}

fn vertex_data(set: &SurfaceSet) -> Vec<(DVec3, DVec3)> {
    // Position and normal of each vertex, from the first patch corner at it.
    let topo = &set.topology;
    let mut out = vec![(DVec3::ZERO, DVec3::Z); topo.vertex_count as usize];
    for e in topo.corner_entries.iter().rev() {
        let patch = &set.patches[e.owner_patch as usize];
        let p = patch.eval(patch.domain().corner(e.owner_corner as usize));
        out[e.vertex as usize] = (p.position, p.normal);
    }
    out
}

/// Builds a plan from a view criterion with factors in `[fmin, fmax]` (integers ≥ 1),
/// culling invisible patches when `cull`. Cost: O(P + E) evaluations.
pub fn plan(
    set: &SurfaceSet,
    camera: &Camera,
    criterion: ViewCriterion,
    fmin: u32,
    fmax: u32,
    layout: Layout,
    cull: bool,
) -> Plan {
    let (fmin, fmax) = (fmin.max(1), fmax.max(fmin.max(1)));
    let topo = &set.topology;
    let verts = vertex_data(set);
    let (_, _, forward) = camera.basis();
    let depth = |v: u32| (verts[v as usize].0 - camera.eye).dot(forward);
    let (dmin, dmax) = (0..topo.vertex_count)
        .map(depth)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), d| (a.min(d), b.max(d)));
    let span = (dmax - dmin).max(1e-300);
    let (lo, hi) = (fmin as f64, fmax as f64);
    let minimum = minimum_segments(set);
    let factor = |e: usize| -> f64 {
        let edge = &topo.edges[e];
        let [a, b] = edge.ends;
        match criterion {
            ViewCriterion::Distance(mapping) => {
                let d = depth(a).min(depth(b)).clamp(dmin, dmax);
                match mapping {
                    Mapping::Linear => hi * (dmax - d) / span + lo * (d - dmin) / span,
                    Mapping::Quadratic => (hi - lo) / (span * span) * (d - dmax) * (d - dmax) + lo,
                }
            }
            ViewCriterion::SilhouetteVertices => {
                let front = |v: u32| verts[v as usize].1.dot(camera.eye - verts[v as usize].0) >= 0.0;
                if front(a) != front(b) {
                    hi
                } else {
                    lo
                }
            }
            ViewCriterion::Silhouetteness => {
                let uses = topo.edge_uses(e);
                let normals: Vec<(DVec3, DVec3)> = uses
                    .iter()
                    .map(|u| {
                        let patch = &set.patches[u.patch as usize];
                        let p = patch.eval(patch.domain().edge_point(u.local as usize, 0.5));
                        (p.position, p.normal)
                    })
                    .collect();
                let mid = normals[0].0;
                let c = (mid - camera.eye).normalize_or_zero();
                let (nl, nr) = (normals[0].1, normals.last().map_or(normals[0].1, |n| n.1));
                let product = c.dot(nl) * c.dot(nr);
                let s = if product <= 0.0 { 1.0 } else { (1.0 - product / 0.25).clamp(0.0, 1.0) };
                lo + s * (hi - lo)
            }
        }
    };
    let mut segments: Vec<u32> =
        (0..topo.edges.len()).map(|e| (factor(e).round().clamp(lo, hi) as u32).max(minimum[e])).collect();
    if layout == Layout::Uniform {
        let n = segments.iter().copied().max().unwrap_or(1);
        segments.iter_mut().for_each(|s| *s = n);
    }
    if layout == Layout::Dyadic {
        let top = 1 << super::tolerance::MAX_DYADIC_LEVEL;
        segments.iter_mut().for_each(|s| *s = s.next_power_of_two().min(top));
    }
    let min_interior = minimum_interior(set);
    let interior = (0..set.patches.len())
        .map(|p| {
            let domain = set.patches[p].domain();
            let s = |l: usize| segments[topo.patch_edges[p][l].edge as usize];
            match domain {
                Domain::Quad => {
                    [s(0).min(s(2)).max(min_interior[p][0]), s(1).min(s(3)).max(min_interior[p][1])]
                }
                Domain::Tri => {
                    let n = s(0).max(s(1)).max(s(2));
                    [n, n]
                }
            }
        })
        .collect();
    let visible = set.patches.iter().map(|p| !(cull && screen::culled(p, camera))).collect();
    Plan { edges: segments.into_iter().map(EdgeSampling::uniform).collect(), interior, visible }
}
