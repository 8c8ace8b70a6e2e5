//! SD-2 edge factors from a level function (paper 001, §3.2).
//!
//! A level function `d` on the mesh vertices orders them; each edge gets the real factor
//! `f(s, e) = g(min(d(s), d(e)))`. In a triangle with vertex levels `d(a) ≤ d(b) ≤ d(c)`
//! both edges at `a` get `g(d(a))` and the third `g(d(b))`: never three different factors,
//! whatever `g`, which is all the [`Sd2`] pattern needs. The paper's two level functions are
//! implemented:
//! - the distance to the camera's eye plane (the vertex depth), mapped by the linear or
//!   quadratic `g` of [`Mapping`] onto `[fmax, fmin]` over the scene's depth range;
//! - the silhouette classification: a vertex is front-facing when `n·(eye − v) ≥ 0`; an edge
//!   whose ends differ is crossed by the silhouette and gets `fmax`, the others `fmin`. A
//!   triangle has 0 or 2 crossed edges, so again at most two factors.
//!
//! Crack-freeness: an edge's factor depends only on its two end vertices, which its patches
//! share, and the symmetric cut needs no direction.

use super::resolve::{self, Caps, EdgeRule, InteriorRule};
use super::screen;
use super::tolerance::{minimum_interior, minimum_segments};
use super::view::{vertex_data, Mapping};
use super::Plan;
use crate::camera::Camera;
use crate::error::{Error, Result};
use crate::pattern::sd2::Sd2;
use crate::sampling::MAX_FACTOR;
use crate::sampling::{SamplingKind, Spacing};
use crate::surface::{Domain, SurfaceSet};
use std::sync::Arc;

/// The level function of an SD-2 plan.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LevelFunction {
    /// Depth along the view direction, mapped by `g`.
    Distance(Mapping),
    /// Front/back classification of the vertices: crossed edges get `fmax`.
    Silhouette,
}

/// SD-2 options.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sd2Options {
    pub level: LevelFunction,
    /// Factor range, reals with `1 ≤ fmin ≤ fmax ≤ MAX_FACTOR`.
    pub fmin: f64,
    pub fmax: f64,
    /// Reverse-project the pattern with the vertex depths (§3.3).
    pub warp: bool,
    /// Cull patches outside the view or facing away.
    pub cull: bool,
}

/// Builds the SD-2 plan and its pattern. Errors for quad patches (SD-2 is defined for
/// triangles) and for a bad factor range. Cost: O(V + E + P) evaluations.
pub fn plan(set: &SurfaceSet, camera: &Camera, options: &Sd2Options) -> Result<(Plan, Sd2)> {
    if let Some(p) = set.patches.iter().position(|p| p.domain() != Domain::Tri) {
        return Err(Error::PatchKindNotAccepted {
            scheme: "sd2",
            kind: "quad",
            patch: p,
            hint: "SD-2 is defined for triangles (paper 001); use the semi-uniform, hardware or transition scheme",
        });
    }
    let (fmin, fmax) = (options.fmin, options.fmax);
    if !(fmin.is_finite() && fmax.is_finite() && 1.0 <= fmin && fmin <= fmax && fmax <= MAX_FACTOR as f64) {
        return Err(Error::FactorOutOfRange {
            scheme: "sd2",
            factor: if (1.0..=MAX_FACTOR as f64).contains(&fmin) { fmax } else { fmin },
            expected: format!("a range 1 ≤ FMIN ≤ FMAX ≤ {MAX_FACTOR}"),
        });
    }
    let topo = &set.topology;
    let verts = vertex_data(set);
    let (_, _, forward) = camera.basis();
    let depth = |v: u32| (verts[v as usize].0 - camera.eye).dot(forward);
    let vertex_factor: Vec<f64> = match options.level {
        LevelFunction::Distance(mapping) => {
            let depths: Vec<f64> = (0..topo.vertex_count).map(depth).collect();
            let (dmin, dmax) =
                depths.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &d| (a.min(d), b.max(d)));
            let span = (dmax - dmin).max(1e-300);
            depths
                .iter()
                .map(|&d| {
                    let f = match mapping {
                        Mapping::Linear => fmax * (dmax - d) / span + fmin * (d - dmin) / span,
                        Mapping::Quadratic => (fmax - fmin) / (span * span) * (d - dmax) * (d - dmax) + fmin,
                    };
                    f.clamp(fmin, fmax)
                })
                .collect()
        }
        LevelFunction::Silhouette => Vec::new(),
    };
    let front = |v: u32| verts[v as usize].1.dot(camera.eye - verts[v as usize].0) >= 0.0;
    // Near clamp for the warp: depths at or behind the eye would flip the projection.
    let near = camera.near.max(1e-9);
    let per_edge: Vec<f64> = topo
        .edges
        .iter()
        .map(|edge| {
            let [a, b] = edge.ends;
            match options.level {
                // g is monotone decreasing in d, so g(min(d(a), d(b))) = max(g(d(a)), g(d(b))).
                LevelFunction::Distance(_) => vertex_factor[a as usize].max(vertex_factor[b as usize]),
                LevelFunction::Silhouette => {
                    if front(a) != front(b) {
                        fmax
                    } else {
                        fmin
                    }
                }
            }
        })
        .collect();
    let minimum = minimum_segments(set);
    let minimum_interior = minimum_interior(set);
    let caps = Caps {
        max_factor: MAX_FACTOR as f64,
        minimum_segments: &minimum,
        minimum_interior: &minimum_interior,
    };
    let mut proposals = Vec::new();
    resolve::from_edge_factors(set, &per_edge, &mut proposals);
    let (mut segments, mut factors) = (Vec::new(), Vec::new());
    let rule = EdgeRule::Fractional(Spacing::Symmetric);
    resolve::edges(set, &proposals, rule, InteriorRule::MaxEdge, &caps, &mut segments, &mut factors);
    let mut interior = Vec::new();
    resolve::interiors(set, &segments, InteriorRule::MaxEdge, &caps, &mut interior);
    let (kind, depths) = if options.warp {
        let depths = topo.edges.iter().map(|edge| edge.ends.map(|v| depth(v).max(near) as f32)).collect();
        (SamplingKind::Warped, depths)
    } else {
        (SamplingKind::Fractional(Spacing::Symmetric), Vec::new())
    };
    let plan = Plan {
        kind,
        segments,
        factors,
        depths,
        lattice_offsets: Vec::new(),
        lattice: Vec::new(),
        interior,
        visible: screen::visibility(set, camera, options.cull),
    };
    let corner_depths = options.warp.then(|| {
        let depths: Vec<[f64; 3]> = (0..set.patches.len())
            .map(|p| {
                let c = &topo.patch_corners[p];
                // The f32 depths the edge rows hold, so the interior warp matches the edges'.
                [0, 1, 2].map(|i| depth(c[i]).max(near) as f32 as f64)
            })
            .collect();
        Arc::from(depths)
    });
    Ok((plan, Sd2 { corner_depths }))
}

/// Number of patches whose three edges carry three different factors (0 for every plan of
/// [`plan`]; the acceptance test checks it). Cost: O(P).
pub fn three_different(set: &SurfaceSet, plan: &Plan) -> usize {
    (0..set.patches.len())
        .filter(|&p| {
            let f = |l: usize| plan.factor(set.topology.patch_edges[p][l].edge as usize);
            let (a, b, c) = (f(0), f(1), f(2));
            a != b && b != c && a != c
        })
        .count()
}
