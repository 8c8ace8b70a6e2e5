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
use rayon::prelude::*;

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

/// Position and normal of each topology vertex, from the first patch corner at it:
/// view-independent, kept by [`super::Prepared::vertex_data`]. Cost: O(V) evaluations.
pub fn vertex_data(set: &SurfaceSet) -> Vec<(DVec3, DVec3)> {
    let topo = &set.topology;
    let mut out = vec![(DVec3::ZERO, DVec3::Z); topo.vertex_count as usize];
    for e in topo.corner_entries.iter().rev() {
        let patch = &set.patches[e.owner_patch as usize];
        let p = patch.eval(patch.domain().corner(e.owner_corner as usize));
        out[e.vertex as usize] = (p.position, p.normal);
    }
    out
}

/// Per edge, the position and normal at the midpoint as its first and its last patch see
/// them (silhouetteness reads both): view-independent, kept by
/// [`super::Prepared::edge_midpoints`]. Cost: O(E) evaluations, parallel.
pub(crate) fn edge_midpoints(set: &SurfaceSet) -> Vec<[(DVec3, DVec3); 2]> {
    use rayon::prelude::*;
    let topo = &set.topology;
    (0..topo.edges.len())
        .into_par_iter()
        .map(|e| {
            let at = |u: &crate::topology::EdgeUse| {
                let patch = &set.patches[u.patch as usize];
                let p = patch.eval(patch.domain().edge_point(u.local as usize, 0.5));
                (p.position, p.normal)
            };
            let uses = topo.edge_uses(e);
            [at(&uses[0]), at(uses.last().unwrap_or(&uses[0]))]
        })
        .collect()
}

/// The real factor of every edge under a view criterion, in `[fmin, fmax]` (reals,
/// `1 ≤ fmin ≤ fmax`), before rounding or minimums. Cost: O(V + E) evaluations; a per-frame
/// loop prepares them once ([`super::Prepared`]) and plans with [`crate::scheme::Scheme::plan_into`].
pub fn edge_factors(
    set: &SurfaceSet,
    camera: &Camera,
    criterion: ViewCriterion,
    fmin: f64,
    fmax: f64,
) -> Vec<f64> {
    let prepared = super::Prepared::default();
    let mut out = Vec::new();
    edge_factors_into(set, &prepared, camera, criterion, fmin, fmax, &mut out);
    out
}

/// [`edge_factors`] from `prepared`'s vertex and midpoint data (made on first use), into
/// `out`. Precondition: `prepared` belongs to `set` (or is empty). Cost: O(V + E).
fn edge_factors_into(
    set: &SurfaceSet,
    prepared: &super::Prepared,
    camera: &Camera,
    criterion: ViewCriterion,
    fmin: f64,
    fmax: f64,
    out: &mut Vec<f64>,
) {
    let (lo, hi) = (fmin.max(1.0), fmax.max(fmin.max(1.0)));
    let topo = &set.topology;
    let verts = prepared.vertex_data(set);
    let (_, _, forward) = camera.basis();
    let depth = |v: u32| (verts[v as usize].0 - camera.eye).dot(forward);
    // In parallel, as every per-vertex and per-edge loop of a view plan: on two threads the
    // sequential loops left the second core idle through a tenth of the cow's frame (the
    // same values in any order: a minimum, a maximum, one factor per edge).
    let (dmin, dmax) = (0..topo.vertex_count)
        .into_par_iter()
        .with_min_len(PAR_MIN)
        .map(depth)
        .fold(|| (f64::INFINITY, f64::NEG_INFINITY), |(a, b), d| (a.min(d), b.max(d)))
        .reduce(|| (f64::INFINITY, f64::NEG_INFINITY), |(a, b), (c, d)| (a.min(c), b.max(d)));
    let span = (dmax - dmin).max(1e-300);
    let midpoints = match criterion {
        ViewCriterion::Silhouetteness => prepared.edge_midpoints(set),
        _ => &[],
    };
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
                let [(mid, nl), (_, nr)] = midpoints[e];
                let c = (mid - camera.eye).normalize_or_zero();
                let product = c.dot(nl) * c.dot(nr);
                let s = if product <= 0.0 { 1.0 } else { (1.0 - product / 0.25).clamp(0.0, 1.0) };
                lo + s * (hi - lo)
            }
        }
    };
    out.resize(topo.edges.len(), 0.0);
    out.par_iter_mut().enumerate().with_min_len(PAR_MIN).for_each(|(e, f)| *f = factor(e).clamp(lo, hi));
}

/// The fewest items a task of a view plan's parallel loops takes.
const PAR_MIN: usize = 1024;

/// Where the edge factors of a view plan come from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum EdgeFactors {
    /// One factor on every edge.
    Fixed(f64),
    /// A view criterion's factors in `[fmin, fmax]`.
    View { criterion: ViewCriterion, fmin: f64, fmax: f64 },
}

/// Builds a plan from per-edge factors — fixed, or a view criterion's in `[fmin, fmax]` —
/// resolved by `rule` and `interior` within `caps`, culling invisible patches when `cull`,
/// into `plan` (its buffers and `scratch`'s reused: no allocation once they have grown).
/// For [`EdgeRule::PowerOfTwo`] the criterion's value is interpolated between the levels of
/// `fmin` and `fmax`, not between the factors (paper 000 / DRS08: level `⌈s·M⌉` for
/// silhouetteness `s`), so half-way is half the levels, not a factor of `fmax/2` that rounds
/// up to the top level. Crack-free: each factor comes from the edge's own data.
/// Cost: O(V + E + P), the view-independent evaluations prepared once in `prepared`.
#[allow(clippy::too_many_arguments)]
pub(crate) fn plan_into(
    set: &SurfaceSet,
    prepared: &super::Prepared,
    camera: &Camera,
    factors: EdgeFactors,
    rule: EdgeRule,
    interior: InteriorRule,
    caps: &Caps<'_>,
    cull: bool,
    scratch: &mut super::PlanScratch,
    plan: &mut Plan,
) {
    let per_edge = &mut scratch.per_edge;
    match factors {
        EdgeFactors::Fixed(f) => {
            per_edge.clear();
            per_edge.resize(set.topology.edges.len(), f);
        }
        EdgeFactors::View { criterion, fmin, fmax } => {
            edge_factors_into(set, prepared, camera, criterion, fmin, fmax, per_edge);
            if rule == EdgeRule::PowerOfTwo {
                let (fmin, fmax) = (fmin.max(1.0), fmax.max(fmin.max(1.0)));
                let (lmin, lmax) = (fmin.log2(), fmax.log2());
                let span = fmax - fmin;
                per_edge.par_iter_mut().with_min_len(PAR_MIN).for_each(|f| {
                    let t = if span > 0.0 { ((*f - fmin) / span).clamp(0.0, 1.0) } else { 1.0 };
                    *f = (lmin + t * (lmax - lmin)).exp2();
                });
            }
        }
    }
    resolve::from_edge_factors(set, per_edge, &mut scratch.proposals);
    resolve::edges(set, &scratch.proposals, rule, interior, caps, &mut plan.segments, &mut plan.factors);
    resolve::interiors(set, &plan.segments, interior, caps, &mut plan.interior);
    plan.kind = match rule {
        EdgeRule::Fractional(spacing) => SamplingKind::Fractional(spacing),
        EdgeRule::Integer | EdgeRule::PowerOfTwo => SamplingKind::Uniform,
    };
    plan.depths.clear();
    plan.lattice_offsets.clear();
    plan.lattice.clear();
    screen::visibility_into(
        set,
        if cull { prepared.views(set) } else { &[] },
        &camera.view(),
        cull,
        &mut plan.visible,
    );
}
