//! View-dependent heuristic criteria without an error guarantee: distance to the eye plane
//! (paper 001 section 3.2) and silhouettes (paper 001's vertex classification; the
//! silhouetteness of paper 000 / DRS08).
//!
//! Crack-freeness: each edge factor is a function of data both neighbours agree on — its two
//! end vertices (distance, classification) or the normals of all its patches at the edge
//! midpoint (silhouetteness) — computed once per edge.

use super::resolve::{self, Caps, EdgeRule, InteriorRule};
use super::screen;
use super::Plan;
use crate::camera::Camera;
use crate::sampling::SamplingKind;
use crate::surface::SurfaceSet;
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

/// Where the edge factors of a view plan come from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum EdgeFactors {
    /// One factor on every edge.
    Fixed(f64),
    /// A view criterion's factors in `[fmin, fmax]`.
    View { criterion: ViewCriterion, fmin: f64, fmax: f64 },
}

/// Builds a plan from per-edge factors — fixed, or a view criterion's in `[fmin, fmax]` —
/// resolved by `rule` and `interior` within `caps`, culling invisible patches when `cull`.
/// For [`EdgeRule::PowerOfTwo`] the criterion's value is interpolated between the levels of
/// `fmin` and `fmax`, not between the factors (paper 000 / DRS08: level `⌈s·M⌉` for
/// silhouetteness `s`), so half-way is half the levels, not a factor of `fmax/2` that rounds
/// up to the top level. Crack-free: each factor comes from the edge's own data.
/// Cost: O(V + E + P) evaluations.
pub(crate) fn plan(
    set: &SurfaceSet,
    camera: &Camera,
    factors: EdgeFactors,
    rule: EdgeRule,
    interior: InteriorRule,
    caps: &Caps<'_>,
    cull: bool,
) -> Plan {
    let per_edge: Vec<f64> = match factors {
        EdgeFactors::Fixed(f) => vec![f; set.topology.edges.len()],
        EdgeFactors::View { criterion, fmin, fmax } => {
            let factors = edge_factors(set, camera, criterion, fmin, fmax);
            if rule != EdgeRule::PowerOfTwo {
                factors
            } else {
                let (fmin, fmax) = (fmin.max(1.0), fmax.max(fmin.max(1.0)));
                let (lmin, lmax) = (fmin.log2(), fmax.log2());
                let span = fmax - fmin;
                factors
                    .iter()
                    .map(|&f| {
                        let t = if span > 0.0 { ((f - fmin) / span).clamp(0.0, 1.0) } else { 1.0 };
                        (lmin + t * (lmax - lmin)).exp2()
                    })
                    .collect()
            }
        }
    };
    let mut proposals = Vec::new();
    resolve::from_edge_factors(set, &per_edge, &mut proposals);
    let (mut segments, mut edge_factors) = (Vec::new(), Vec::new());
    resolve::edges(set, &proposals, rule, interior, caps, &mut segments, &mut edge_factors);
    let mut interiors = Vec::new();
    resolve::interiors(set, &segments, interior, caps, &mut interiors);
    let kind = match rule {
        EdgeRule::Fractional(spacing) => SamplingKind::Fractional(spacing),
        EdgeRule::Integer | EdgeRule::PowerOfTwo => SamplingKind::Uniform,
    };
    Plan {
        kind,
        segments,
        factors: edge_factors,
        depths: Vec::new(),
        lattice_offsets: Vec::new(),
        lattice: Vec::new(),
        interior: interiors,
        visible: screen::visibility(set, camera, cull),
    }
}
