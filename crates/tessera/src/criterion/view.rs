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
use crate::pattern::hardware::{settled_factor, OUTPUT_GAP};
use crate::sampling::{EdgeSampling, Spacing};
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

pub(crate) fn vertex_data(set: &SurfaceSet) -> Vec<(DVec3, DVec3)> {
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

/// The real factor of every edge under a view criterion, in `[fmin, fmax]` (reals,
/// `1 ≤ fmin ≤ fmax`), before rounding or minimums. Cost: O(V + E) evaluations.
pub fn edge_factors(
    set: &SurfaceSet,
    camera: &Camera,
    criterion: ViewCriterion,
    fmin: f64,
    fmax: f64,
) -> Vec<f64> {
    let (lo, hi) = (fmin.max(1.0), fmax.max(fmin.max(1.0)));
    let topo = &set.topology;
    let verts = vertex_data(set);
    let (_, _, forward) = camera.basis();
    let depth = |v: u32| (verts[v as usize].0 - camera.eye).dot(forward);
    let (dmin, dmax) = (0..topo.vertex_count)
        .map(depth)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), d| (a.min(d), b.max(d)));
    let span = (dmax - dmin).max(1e-300);
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
    (0..topo.edges.len()).map(|e| factor(e).clamp(lo, hi)).collect()
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
    let minimum = minimum_segments(set);
    let factors = edge_factors(set, camera, criterion, fmin as f64, fmax as f64);
    let mut segments: Vec<u32> =
        factors.iter().zip(&minimum).map(|(&f, &m)| (f.round() as u32).clamp(fmin, fmax).max(m)).collect();
    let min_interior = minimum_interior(set);
    if layout == Layout::Uniform {
        // One factor everywhere, edges and interiors alike (the uniform pattern's
        // precondition), at least what every patch's interior needs.
        let n = segments.iter().copied().chain(min_interior.iter().flatten().copied()).max().unwrap_or(1);
        segments.iter_mut().for_each(|s| *s = n);
        let interior = vec![[n, n]; set.patches.len()];
        let visible = set.patches.iter().map(|p| !(cull && screen::culled(p, camera))).collect();
        return Plan { edges: segments.into_iter().map(EdgeSampling::uniform).collect(), interior, visible };
    }
    if layout == Layout::Dyadic {
        // Levels, not factors, are interpolated (paper 000 / DRS08: level ⌈s·M⌉ for
        // silhouetteness s): the criterion's value t ∈ [0, 1] maps to the level
        // ⌈log2 fmin + t·(log2 fmax − log2 fmin)⌉, so half-way is half the levels, not a
        // factor of fmax/2 that rounds up to the top level.
        let top = crate::pattern::semi_uniform::MAX_LEVEL;
        let (lmin, lmax) = ((fmin as f64).log2(), (fmax as f64).log2());
        let span = (fmax - fmin) as f64;
        for (s, (&f, &m)) in segments.iter_mut().zip(factors.iter().zip(&minimum)) {
            let t = if span > 0.0 { ((f - fmin as f64) / span).clamp(0.0, 1.0) } else { 1.0 };
            let level = ((lmin + t * (lmax - lmin)) - 1e-9).ceil().clamp(0.0, top as f64) as u32;
            *s = (1u32 << level).max(m.next_power_of_two()).min(1 << top);
        }
    }
    let interior = (0..set.patches.len())
        .map(|p| {
            let domain = set.patches[p].domain();
            let s = |l: usize| segments[topo.patch_edges[p][l].edge as usize];
            match domain {
                // P^m with the patch level m = max of its edge levels (paper 000).
                _ if layout == Layout::Dyadic => {
                    let n = (0..domain.corner_count()).map(s).max().unwrap_or(1);
                    [n, n]
                }
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

/// A plan of real factors cut by a fractional rule (`spacing`): `factor` on every edge, or
/// the view criterion's factors in `[fmin, fmax]` (`None` for a fixed factor), never below
/// the topology's minimum segments. Crack-free as [`plan`]: each factor comes from the
/// edge's own data, and the fractional cuts are symmetric. Cost: O(V + E + P) evaluations.
pub fn fractional_plan(
    set: &SurfaceSet,
    camera: &Camera,
    factors: FractionalFactors,
    spacing: Spacing,
    cull: bool,
) -> Plan {
    let topo = &set.topology;
    let minimum = minimum_segments(set);
    let real = match factors {
        FractionalFactors::Fixed(f) => vec![f; topo.edges.len()],
        FractionalFactors::View { criterion, fmin, fmax } => edge_factors(set, camera, criterion, fmin, fmax),
    };
    let edges: Vec<EdgeSampling> = real
        .iter()
        .zip(&minimum)
        .map(|(&f, &m)| {
            let f = f.max(m as f64);
            let f = match spacing {
                // The hull-shader side: pow2 rounds up to a power of two; fractional factors
                // just above a count boundary settle to it, so no output segment falls below
                // f32 resolution (`pattern::hardware::OUTPUT_GAP`).
                Spacing::Hardware(p) => settled_factor(p.hull_factor(f), p, OUTPUT_GAP),
                Spacing::Symmetric => f,
            };
            EdgeSampling::Fractional { factor: f, spacing }
        })
        .collect();
    let interior = (0..set.patches.len())
        .map(|p| {
            let n = (0..set.patches[p].domain().corner_count())
                .map(|l| edges[topo.patch_edges[p][l].edge as usize].segments())
                .max()
                .unwrap_or(1);
            [n, n]
        })
        .collect();
    let visible = set.patches.iter().map(|p| !(cull && screen::culled(p, camera))).collect();
    Plan { edges, interior, visible }
}

/// Where the factors of [`fractional_plan`] come from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FractionalFactors {
    Fixed(f64),
    View { criterion: ViewCriterion, fmin: f64, fmax: f64 },
}
