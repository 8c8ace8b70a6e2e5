//! The ESC criterion (paper 002, Concheiro et al., sections 2.2 and 3): a resolution level per
//! object from the camera, and the distance test of equation (9) on every candidate vertex of
//! every coarse-triangle edge. Its decisions feed the pattern [`crate::pattern::esc::Esc`],
//! whose module doc describes the coarse triangles, rows and strips.
//!
//! # Level
//!
//! The paper gives each *object* a level from the camera position. A level fixes the
//! candidate set of every edge (`3(L+1)` segments per patch boundary curve), so two patches
//! that share a curve must have the same level, or their candidates would not match. Here an
//! object is a connected component of the patch adjacency (patches joined through shared
//! boundary curves: one teacup of a scene of teacups — or its handle, which shares no curve
//! with the body), and all its patches get one level:
//!
//! `L = Lmax` while the eye is within `r = near_diagonals · d` of the component's bounding
//! box (`d` its diagonal), then one less per doubling of that distance:
//! `L = Lmax − ⌈log2(distance / r)⌉`, never below 1. [`EscOptions::level`] instead fixes one
//! level for every patch.
//!
//! # Distance test (equation (9))
//!
//! A candidate on a coarse edge from control point `P_a` to `P_b` at fraction `s` is inserted
//! when `|V_B − V_S| > ρ`: `V_B` the surface point at the candidate's parameters, `V_S` the
//! point `(1−s)·P_a + s·P_b` of the control mesh (the coarse triangles). `ρ` is
//! [`Threshold`]: a preset fraction of the component's bounding-box diagonal (scale-free) or
//! an absolute distance.
//!
//! # Consistency
//!
//! Each decision depends on one coarse edge's data only: its two control points and the
//! surface along it. A patch boundary curve is decided once per topology edge (from its owner
//! patch, in canonical orientation; on the boundary the patch's value depends only on the
//! curve's four control points) and the decision becomes the edge's
//! lattice row of the plan ([`crate::sampling::SamplingKind::Lattice`]), which every patch on
//! the curve reads; an inner cell edge or a
//! cell diagonal is decided once and stored in the patch's grid, which both its coarse
//! triangles read. So neighbours always agree, and the engine's once-per-edge evaluation
//! makes the mesh watertight bit for bit.
//!
//! # Collapsed curves
//!
//! A coarse triangle with an edge on a patch boundary curve collapsed to a point (the teapot
//! lid's apex, a spindle's poles) inserts every candidate of its three edges, whatever the
//! distance test says: it gets the complete pattern, which after the collapse is the uniform
//! pattern's fan at the point. The engine gives every sample of a collapsed curve the
//! corner's vertex, so there the candidates cost nothing, and there the test cannot decide
//! (surface and control mesh are both the point, so it never inserts). Sparser patterns break
//! the mesh once the curve is one point, which the pattern's tests show on two that the
//! fuzzer and those tests found: with the curve's candidates missing, a row kept by its other
//! extreme takes virtual vertices on the curve, one sample above it (the fill of an empty row
//! from the apex) and another below, so its first segment gets the same triangle on both
//! sides (a fold); with the curve's candidates present but none on the other two edges, the
//! two remaining edges join the same two vertices, the point and the far corner, and no row
//! vertex inside fits between them. Forcing the other two edges' candidates is consistent
//! like any decision: each is a decision of its coarse edge (for a boundary curve, forced
//! when any patch on the curve forces it), which the neighbouring coarse triangle reads as it
//! reads any inserted candidate.

use super::Plan;
use crate::camera::Camera;
use crate::error::{Error, Result};
use crate::pattern::esc::{segments_for_level, Esc, PatchGrid, MAX_LEVEL};
use crate::sampling::SamplingKind;
use crate::surface::{corner_and_edge_points, Domain, Patch, RationalBicubic, SurfaceSet};
use glam::{DVec2, DVec3};
use rayon::prelude::*;

/// The quality threshold `ρ` of the distance test.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Threshold {
    /// `ρ` = [`Threshold::HIGH_FRACTION`] of each component's bounding-box diagonal.
    High,
    /// `ρ` = [`Threshold::MEDIUM_FRACTION`] of each component's bounding-box diagonal.
    Medium,
    /// `ρ` in model units (`≥ 0`; 0 inserts every candidate that is off the control mesh).
    Absolute(f64),
}

impl Threshold {
    /// The high preset as a fraction of the diagonal. The paper gives no value of `ρ`; this
    /// one is calibrated on the Teacups scene (`examples/common/teacups.rs`, `Lmax = 3`) so that ESC
    /// keeps about the paper's share of the non-adaptive triangles (93.75% here, 93.62% in
    /// Table 1).
    pub const HIGH_FRACTION: f64 = 0.004;
    /// The medium preset, calibrated the same way (53.1% here, 51.96% in Table 1).
    pub const MEDIUM_FRACTION: f64 = 0.022;

    /// `ρ` for a component with bounding-box diagonal `diagonal`.
    pub fn rho(self, diagonal: f64) -> f64 {
        match self {
            Threshold::High => Self::HIGH_FRACTION * diagonal,
            Threshold::Medium => Self::MEDIUM_FRACTION * diagonal,
            Threshold::Absolute(r) => r,
        }
    }
}

/// ESC options.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EscOptions {
    /// `Lmax`, the level of the nearest objects (paper: 3). `0..=6`.
    pub max_level: u32,
    /// One level for every patch, ignoring the camera (`0..=6`).
    pub level: Option<u32>,
    /// The distance-test threshold.
    pub threshold: Threshold,
    /// Objects closer than this many of their own bounding-box diagonals get `Lmax`. The
    /// default, 12, makes the Teacups walk-through (`examples/common/teacups.rs`) average 97% of the
    /// all-`Lmax` triangle count, as the paper's Table 1 does (731.32k of 2,600 × 288).
    pub near_diagonals: f64,
}

impl Default for EscOptions {
    fn default() -> Self {
        EscOptions { max_level: 3, level: None, threshold: Threshold::Medium, near_diagonals: 12.0 }
    }
}

impl EscOptions {
    /// Checks the ranges.
    pub fn validate(&self) -> Result<()> {
        let bad = |reason: String| Err(Error::InvalidParameter { name: "esc", reason });
        if self.max_level > MAX_LEVEL {
            return bad(format!("max level {} is above {MAX_LEVEL}", self.max_level));
        }
        if let Some(l) = self.level.filter(|&l| l > MAX_LEVEL) {
            return bad(format!("level {l} is above {MAX_LEVEL}"));
        }
        if let Threshold::Absolute(r) = self.threshold {
            if !(r.is_finite() && r >= 0.0) {
                return bad(format!("threshold {r} must be a finite distance ≥ 0"));
            }
        }
        if !(self.near_diagonals.is_finite() && self.near_diagonals > 0.0) {
            return bad(format!("near distance {} must be positive", self.near_diagonals));
        }
        Ok(())
    }
}

/// The level of an object whose bounding box is `distance` away from the eye (0 inside),
/// with `reference = near_diagonals · diagonal`: `max_level` within the reference distance,
/// one less per doubling beyond, at least 1 (or `max_level` when that is 0).
pub fn level_for_distance(distance: f64, reference: f64, max_level: u32) -> u32 {
    // NaN distances (a degenerate box) count as near.
    if distance.is_nan() || distance <= reference || reference <= 0.0 {
        return max_level;
    }
    let drop = (distance / reference).log2().ceil();
    let drop = if drop.is_finite() { drop.min(max_level as f64) as u32 } else { max_level };
    max_level.saturating_sub(drop).max(max_level.min(1))
}

/// Connected components of the patch adjacency: component id per patch, and the count.
fn components(set: &SurfaceSet) -> (Vec<u32>, usize) {
    let n = set.patches.len();
    let mut parent: Vec<u32> = (0..n as u32).collect();
    fn find(parent: &mut [u32], mut x: u32) -> u32 {
        while parent[x as usize] != x {
            parent[x as usize] = parent[parent[x as usize] as usize];
            x = parent[x as usize];
        }
        x
    }
    for e in 0..set.topology.edges.len() {
        let uses = set.topology.edge_uses(e);
        for u in uses.iter().skip(1) {
            let (a, b) = (find(&mut parent, uses[0].patch), find(&mut parent, u.patch));
            if a != b {
                parent[a.max(b) as usize] = a.min(b);
            }
        }
    }
    let mut id = vec![u32::MAX; n];
    let mut count = 0;
    let out = (0..n as u32)
        .map(|p| {
            let r = find(&mut parent, p) as usize;
            if id[r] == u32::MAX {
                id[r] = count;
                count += 1;
            }
            id[r]
        })
        .collect();
    (out, count as usize)
}

fn bicubic(set: &SurfaceSet, p: usize) -> Result<&RationalBicubic> {
    match &set.patches[p] {
        Patch::Bicubic(b) => Ok(b),
        _ => Err(Error::unsupported(
            "<surface set>",
            0,
            format!("patch {p} is a triangle patch; ESC tessellates bicubic Bézier patches only"),
        )),
    }
}

/// Lattice point `kl` (`0..=3n`) along local edge `e` of a patch, in the edge's direction.
pub fn edge_lattice(e: usize, kl: u32, side: u32) -> (u32, u32) {
    match e {
        0 => (kl, 0),
        1 => (side, kl),
        2 => (side - kl, side),
        _ => (0, side - kl),
    }
}

fn lattice_uv(i: u32, j: u32, side: u32) -> DVec2 {
    DVec2::new(i as f64 / side as f64, j as f64 / side as f64)
}

/// Equation (9): is the candidate at `uv`, a fraction `s` from `a` to `b` on the control mesh,
/// further than `rho` from the surface?
fn far(patch: &RationalBicubic, uv: DVec2, a: DVec3, b: DVec3, s: f64, rho: f64) -> bool {
    patch.position(uv).distance(a * (1.0 - s) + b * s) > rho
}

/// Decides every candidate of patch `p` off the boundary: inner cell edges and diagonals
/// (the rows are filled afterwards, by [`PatchGrid::insert_rows`]). The boundary lattice
/// points are already set from the edge samplings.
fn decide_inner(patch: &RationalBicubic, grid: &mut PatchGrid, rho: f64) {
    let n = grid.n;
    let side = grid.side();
    let cp = |i: u32, j: u32| patch.point(i as usize, j as usize);
    for line in 1..3 {
        let at = line * n;
        for t in 0..side {
            if t % n == 0 {
                continue;
            }
            let (c, s) = (t / n, (t % n) as f64 / n as f64);
            // Vertical cell edge u = line/3 and horizontal cell edge v = line/3.
            let v = far(patch, lattice_uv(at, t, side), cp(line, c), cp(line, c + 1), s, rho);
            grid.set(at, t, v);
            let h = far(patch, lattice_uv(t, at, side), cp(c, line), cp(c + 1, line), s, rho);
            grid.set(t, at, h);
        }
    }
    for cj in 0..3 {
        for ci in 0..3 {
            for k in 1..n {
                let (i, j) = (ci * n + k, cj * n + k);
                let s = k as f64 / n as f64;
                let d = far(patch, lattice_uv(i, j, side), cp(ci, cj), cp(ci + 1, cj + 1), s, rho);
                grid.set(i, j, d);
            }
        }
    }
}

/// The candidates patch `p` inserts whatever the distance test says, as a grid (None when
/// there are none): every candidate of each coarse triangle with an edge on a boundary curve
/// collapsed to a point (module doc, "Collapsed curves"). Cost: O(n²) per such triangle.
fn forced_candidates(set: &SurfaceSet, p: usize, n: u32) -> Option<PatchGrid> {
    let topo = &set.topology;
    let collapsed: Vec<usize> =
        (0..4).filter(|&e| topo.edges[topo.patch_edges[p][e].edge as usize].collapsed).collect();
    if collapsed.is_empty() {
        return None;
    }
    let mut forced = PatchGrid::coarse(n);
    for t in 0..18 {
        if collapsed.iter().any(|&e| forced.coarse_triangle_on_edge(t, e)) {
            forced.fill_coarse_triangle(t);
        }
    }
    Some(forced)
}

/// ESC's objects: each patch's connected component of the patch adjacency, and each
/// component's control-point box `(lo, hi)` — what the level rule and `ρ` read
/// (view-independent: the GPU engine uploads the boxes once per set).
#[derive(Debug, Clone, PartialEq)]
pub struct Objects {
    /// The component of every patch.
    pub component: Vec<u32>,
    /// Every component's box.
    pub boxes: Vec<(DVec3, DVec3)>,
}

impl Objects {
    /// The objects of `set`. Cost: O(P + E) (a union-find over the edge uses).
    pub fn of(set: &SurfaceSet) -> Objects {
        let (component, count) = components(set);
        let mut boxes = vec![(DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)); count];
        for (p, patch) in set.patches.iter().enumerate() {
            let b = &mut boxes[component[p] as usize];
            for &c in patch.control_points() {
                *b = (b.0.min(c), b.1.max(c));
            }
        }
        Objects { component, boxes }
    }
}

/// Levels per patch from the camera (or the fixed level), and `ρ` per patch.
fn levels_and_thresholds(set: &SurfaceSet, camera: &Camera, options: &EscOptions) -> (Vec<u32>, Vec<f64>) {
    let Objects { component: comp, boxes } = Objects::of(set);
    let count = boxes.len();
    let lo: Vec<DVec3> = boxes.iter().map(|b| b.0).collect();
    let hi: Vec<DVec3> = boxes.iter().map(|b| b.1).collect();
    let level: Vec<u32> = (0..count)
        .map(|c| {
            options.level.unwrap_or_else(|| {
                let distance = (camera.eye.clamp(lo[c], hi[c]) - camera.eye).length();
                level_for_distance(
                    distance,
                    options.near_diagonals * lo[c].distance(hi[c]),
                    options.max_level,
                )
            })
        })
        .collect();
    let rho: Vec<f64> = (0..count).map(|c| options.threshold.rho(lo[c].distance(hi[c]))).collect();
    (comp.iter().map(|&c| level[c as usize]).collect(), comp.iter().map(|&c| rho[c as usize]).collect())
}

/// Builds the ESC plan and pattern for `set` seen from `camera`.
///
/// Preconditions: every patch is bicubic (else [`Error::Unsupported`]); `options` in range and
/// a valid camera (else [`Error::InvalidParameter`]). Returns the plan (explicit parameters
/// per topology edge: the inserted boundary candidates; interior factors `3n`; all patches
/// visible) and the pattern holding every patch's decisions; tessellate with both.
/// Cost: O(P · (3n+1)²) surface evaluations, parallel over patches.
pub fn plan(set: &SurfaceSet, camera: &Camera, options: &EscOptions) -> Result<(Plan, Esc)> {
    options.validate()?;
    if options.level.is_none() {
        camera.validate()?;
    }
    let patches: Vec<&RationalBicubic> =
        (0..set.patches.len()).map(|p| bicubic(set, p)).collect::<Result<_>>()?;
    let (levels, rho) = levels_and_thresholds(set, camera, options);
    let topo = &set.topology;
    let (_, edge_points) = corner_and_edge_points(Domain::Quad);
    let forced: Vec<Option<PatchGrid>> = (0..set.patches.len())
        .into_par_iter()
        .map(|p| forced_candidates(set, p, segments_for_level(levels[p])))
        .collect();

    // Boundary curves: one decision per topology edge, by its owner, in canonical order.
    let edges: Vec<Vec<bool>> = (0..topo.edges.len())
        .into_par_iter()
        .map(|e| {
            let owner = topo.edge_uses(e)[0];
            let p = owner.patch as usize;
            let n = segments_for_level(levels[p]);
            let side = 3 * n;
            let le = owner.local as usize;
            let cps = edge_points[le].map(|i| patches[p].points[i]);
            // Forced on the curve when forced in any patch on it (all share the level: one
            // component).
            let forced_in_a_use = |k: u32| {
                topo.edge_uses(e).iter().any(|u| {
                    forced[u.patch as usize].as_ref().is_some_and(|g| {
                        let (i, j) =
                            edge_lattice(u.local as usize, if u.reversed { side - k } else { k }, side);
                        g.get(i, j)
                    })
                })
            };
            (0..=side)
                .map(|k| {
                    let kl = if owner.reversed { side - k } else { k };
                    if kl % n == 0 || forced_in_a_use(k) {
                        return true; // a control-net vertex (a coarse-triangle corner) or forced
                    }
                    let (i, j) = edge_lattice(le, kl, side);
                    let (c, s) = ((kl / n) as usize, (kl % n) as f64 / n as f64);
                    far(patches[p], lattice_uv(i, j, side), cps[c], cps[c + 1], s, rho[p])
                })
                .collect()
        })
        .collect();

    let grids: Vec<PatchGrid> = (0..set.patches.len())
        .into_par_iter()
        .map(|p| {
            let n = segments_for_level(levels[p]);
            let side = 3 * n;
            let mut grid = PatchGrid::coarse(n);
            for (le, pe) in topo.patch_edges[p].iter().enumerate() {
                let flags = &edges[pe.edge as usize];
                for kl in 1..side {
                    let k = if pe.reversed { side - kl } else { kl };
                    let (i, j) = edge_lattice(le, kl, side);
                    grid.set(i, j, flags[k as usize]);
                }
            }
            decide_inner(patches[p], &mut grid, rho[p]);
            if let Some(f) = &forced[p] {
                for j in 0..=side {
                    for i in 0..=side {
                        if f.get(i, j) {
                            grid.set(i, j, true);
                        }
                    }
                }
            }
            grid.insert_rows();
            grid
        })
        .collect();

    // Each edge's inserted lattice points, as numerators over the lattice size `3n`.
    let mut plan = Plan {
        kind: SamplingKind::Lattice,
        segments: Vec::with_capacity(edges.len()),
        factors: Vec::with_capacity(edges.len()),
        depths: Vec::new(),
        lattice_offsets: Vec::with_capacity(edges.len()),
        lattice: Vec::new(),
        interior: levels.iter().map(|&l| [3 * segments_for_level(l); 2]).collect(),
        visible: vec![1; set.patches.len()],
    };
    for flags in &edges {
        plan.lattice_offsets.push(plan.lattice.len() as u32);
        let before = plan.lattice.len();
        plan.lattice.extend(flags.iter().enumerate().filter(|(_, &f)| f).map(|(k, _)| k as u32));
        plan.segments.push((plan.lattice.len() - before - 1) as u32);
        plan.factors.push((flags.len() - 1) as f32);
    }
    Ok((plan, Esc::new(grids)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::patches::parse_patches;
    use crate::pattern::esc::CoarseTriangle;
    use crate::pattern::{Pattern, PatternInput};
    use crate::surface::PnTriangle;
    use std::path::Path;

    fn flat_patch(bump: f64) -> SurfaceSet {
        let mut text = String::from("1\n1,2,3,4,5,6,7,8,9,10,11,12,13,14,15,16\n16\n");
        for i in 0..4 {
            for j in 0..4 {
                let z = if (i == 1 || i == 2) && (j == 1 || j == 2) { bump } else { 0.0 };
                text += &format!("{i},{j},{z}\n");
            }
        }
        SurfaceSet::from_patch_file(&parse_patches(&text, Path::new("<t>")).unwrap(), Default::default())
    }

    fn camera() -> Camera {
        Camera::framing(DVec3::ZERO, DVec3::splat(3.0), 640, 480)
    }

    #[test]
    fn levels_halve_with_distance() {
        assert_eq!(level_for_distance(0.0, 10.0, 3), 3);
        assert_eq!(level_for_distance(10.0, 10.0, 3), 3);
        assert_eq!(level_for_distance(15.0, 10.0, 3), 2);
        assert_eq!(level_for_distance(20.0, 10.0, 3), 2);
        assert_eq!(level_for_distance(30.0, 10.0, 3), 1);
        assert_eq!(level_for_distance(1e9, 10.0, 3), 1);
        assert_eq!(level_for_distance(1e9, 10.0, 0), 0);
    }

    #[test]
    fn a_flat_patch_keeps_only_the_coarse_triangles() {
        let set = flat_patch(0.0);
        for level in 0..=MAX_LEVEL {
            let options =
                EscOptions { level: Some(level), threshold: Threshold::Absolute(1e-9), ..Default::default() };
            let (plan, esc) = plan(&set, &camera(), &options).unwrap();
            assert_eq!(esc.triangles(0), 18, "level {level}");
            assert!(plan.segments.iter().all(|&s| s == 3));
        }
    }

    #[test]
    fn a_bump_inserts_interior_candidates_only() {
        // The inner control points are raised: the boundary curves are straight lines along
        // their control polygons, so only inner edges and diagonals can be far off.
        let set = flat_patch(1.0);
        let options =
            EscOptions { level: Some(2), threshold: Threshold::Absolute(1e-3), ..Default::default() };
        let (plan, esc) = plan(&set, &camera(), &options).unwrap();
        assert!(plan.segments.iter().all(|&s| s == 3));
        assert!(esc.triangles(0) > 18);
        let input = PatternInput { patch: 0, ..PatternInput::new(Domain::Quad, [3; 4], [9, 9]) };
        let (vi, t) = esc.counts(&input);
        let mut local = Default::default();
        esc.build(&input, &mut local);
        assert_eq!((local.interior.len() as u32, local.triangles.len() as u32), (vi, t));
        // A threshold above every distance inserts nothing.
        let all = EscOptions { threshold: Threshold::Absolute(1e9), ..options };
        assert_eq!(plan_triangles(&set, &all), 18);
    }

    fn plan_triangles(set: &SurfaceSet, options: &EscOptions) -> u32 {
        plan(set, &camera(), options).unwrap().1.triangles(0)
    }

    #[test]
    fn row_rule_matches_the_coarse_triangle_flags() {
        let set = flat_patch(1.0);
        let options =
            EscOptions { level: Some(3), threshold: Threshold::Absolute(0.05), ..Default::default() };
        let (_, esc) = plan(&set, &camera(), &options).unwrap();
        let g = esc.grid(0);
        for t in 0..18 {
            let c: CoarseTriangle = g.coarse_triangle(t);
            for k in 0..=c.n {
                for p in 0..=k {
                    let (i, j) = g.lattice(t, (k, p));
                    assert_eq!(g.get(i, j), c.present((k, p)), "t {t} {k},{p}");
                }
            }
        }
    }

    #[test]
    fn bad_inputs_are_typed_errors() {
        let set = flat_patch(0.0);
        let bad = |o: EscOptions| matches!(plan(&set, &camera(), &o), Err(Error::InvalidParameter { .. }));
        assert!(bad(EscOptions { max_level: 7, ..Default::default() }));
        assert!(bad(EscOptions { level: Some(9), ..Default::default() }));
        assert!(bad(EscOptions { threshold: Threshold::Absolute(-1.0), ..Default::default() }));
        assert!(bad(EscOptions { threshold: Threshold::Absolute(f64::NAN), ..Default::default() }));
        assert!(bad(EscOptions { near_diagonals: 0.0, ..Default::default() }));
        let p = [DVec3::ZERO, DVec3::X, DVec3::Y];
        let pn = PnTriangle::new(p, [DVec3::Z; 3]);
        let tri = SurfaceSet::from_patches(vec![Patch::Pn(pn)], Default::default());
        let err = plan(&tri, &camera(), &EscOptions::default());
        assert!(matches!(err, Err(Error::Unsupported { .. })), "{err:?}");
    }
}
