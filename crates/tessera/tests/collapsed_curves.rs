//! Free curves that `f32` cannot resolve (issue 9, item 9): a cone whose apex ring is under one
//! `f32` step across, far from the origin, and a patch with one edge of that size. The exact
//! weld leaves such a curve's points apart where they straddle a rounding boundary; the
//! curve's samples then fall on one or two floats per axis and the mesh pinched (Euler 1
//! against the input's 0 for the cone). The rule in `topology::weld` makes the curve a point,
//! so every scheme keeps the input's topology.

mod common;

use glam::DVec3;
use tessera::engine::{tessellate, EngineOptions};
use tessera::pattern::hardware::Partitioning;
use tessera::scheme::{Criterion, PlanOptions, Scheme, SchemePlan};
use tessera::surface::{BuildOptions, Orientation, Patch, RationalBicubic, SurfaceSet};
use tessera::verify;

/// Far enough from the origin that `f32` steps are coarse: 2^-14 ≈ 6.1e-5 at 1000.
const OFFSET: f64 = 1000.0;

/// The cubic Bézier arc of radius `r` from angle `a0` to `a1` at height `z`, shifted by
/// [`OFFSET`] on every axis.
fn arc(r: f64, a0: f64, a1: f64, z: f64) -> [DVec3; 4] {
    let k = 4.0 / 3.0 * ((a1 - a0) / 4.0).tan();
    // Exact at multiples of a right angle, so neighbouring patches' seams weld.
    let round = |x: f64| (x * 1e12).round() / 1e12;
    let (p0, p3) = (DVec3::new(r * a0.cos(), r * a0.sin(), 0.0), DVec3::new(r * a1.cos(), r * a1.sin(), 0.0));
    let p1 = p0 + k * DVec3::new(-p0.y, p0.x, 0.0);
    let p2 = p3 + k * DVec3::new(p3.y, -p3.x, 0.0);
    [p0, p1, p2, p3].map(|p| DVec3::new(round(p.x), round(p.y), z) + DVec3::splat(OFFSET))
}

/// Four patches round an axis, from a ring of radius `apex` at height 1 down to a ring of
/// radius 1 at height 0: an annulus (Euler 0) while the apex ring is a curve.
fn cone(apex: f64) -> Vec<Patch> {
    (0..4)
        .map(|s| {
            let (a0, a1) =
                (std::f64::consts::FRAC_PI_2 * s as f64, std::f64::consts::FRAC_PI_2 * (s + 1) as f64);
            let rows: [[DVec3; 4]; 4] = std::array::from_fn(|i| {
                let t = i as f64 / 3.0;
                arc(apex + (1.0 - apex) * t, a0, a1, 1.0 - t)
            });
            Patch::Bicubic(RationalBicubic::polynomial(std::array::from_fn(|k| rows[k / 4][k % 4])))
        })
        .collect()
}

/// One patch whose curve `u = 0` is `length` long, centred half an `f32` step above
/// [`OFFSET`] on x (so its points round to two floats), fanning out to a unit edge at `u = 1`.
fn wedge(length: f64) -> Vec<Patch> {
    let step = 1.0 / 16384.0;
    let points = std::array::from_fn(|k| {
        let (t, s) = ((k / 4) as f64 / 3.0, (k % 4) as f64 / 3.0);
        let width = length + (1.0 - length) * t;
        DVec3::new(step / 2.0 + (s - 0.5) * width, t, 0.2 * s * (1.0 - s) * t) + DVec3::splat(OFFSET)
    });
    vec![Patch::Bicubic(RationalBicubic::polynomial(points))]
}

fn set_of(patches: Vec<Patch>) -> SurfaceSet {
    SurfaceSet::from_patches(
        patches,
        BuildOptions { orientation: Orientation::AsGiven, ..Default::default() },
    )
}

/// Every scheme the issue names, each with a factor it takes.
fn schemes() -> Vec<(Scheme, Criterion)> {
    let mut all = vec![
        (Scheme::Uniform, Criterion::Factor(8.0)),
        (Scheme::Transition, Criterion::Factor(8.0)),
        (Scheme::SemiUniform { max_level: 5 }, Criterion::Factor(8.0)),
        (Scheme::Uniform, Criterion::Tolerance(1e-3)),
        (Scheme::Transition, Criterion::Tolerance(1e-3)),
    ];
    for (partitioning, factor) in [
        (Partitioning::Integer, 7.0),
        (Partitioning::Pow2, 8.0),
        (Partitioning::FractionalOdd, 5.3),
        (Partitioning::FractionalEven, 5.3),
    ] {
        all.push((Scheme::Hardware(partitioning), Criterion::Factor(factor)));
    }
    all
}

/// Tessellates `set` with every scheme and checks the output has the input's topology: its
/// boundary edges exactly the free curves' segments, no collapsed or zero-area triangle, and
/// the input's Euler characteristic.
fn keeps_topology(set: &SurfaceSet, name: &str) {
    for (scheme, criterion) in schemes() {
        let label = format!("{name}, {scheme:?}, {criterion:?}");
        let SchemePlan { plan, pattern, .. } = scheme.plan(set, &criterion, &PlanOptions::default()).unwrap();
        let mesh = tessellate(set, &plan, &pattern, EngineOptions::default()).unwrap();
        common::expect_topology(set, &plan, &mesh, &label);
        let w = verify::watertight(&mesh);
        assert_eq!(w.degenerate_triangles(), 0, "{label}: {w:?}");
        assert_eq!(w.euler_characteristic, set.topology.report.euler_characteristic, "{label}");
    }
}

#[test]
fn a_cone_with_an_apex_ring_under_one_f32_step_keeps_its_topology() {
    // 4e-5 across the axes, under the step of 6.1e-5: before, the ring stayed four curves
    // (an annulus, Euler 0) and every scheme's mesh closed it with a pinch (Euler 1).
    let set = set_of(cone(4e-5));
    let t = set.topology.report;
    // All four ring curves have one key now: one collapsed edge.
    assert_eq!(t.collapsed_edges, 1, "the apex ring is one point: {t:?}");
    assert_eq!((t.boundary_edges, t.euler_characteristic), (4, 1), "a disk with an apex: {t:?}");
    keeps_topology(&set, "cone 4e-5");
}

#[test]
fn a_patch_with_an_edge_under_one_f32_step_keeps_its_topology() {
    let set = set_of(wedge(4e-5));
    let t = set.topology.report;
    assert_eq!((t.collapsed_edges, t.boundary_edges, t.euler_characteristic), (1, 3, 1), "{t:?}");
    keeps_topology(&set, "wedge 4e-5");
}

#[test]
fn curves_f32_resolves_stay_curves() {
    // Well above the step: the rule leaves the apex ring and the short edge alone.
    for (name, set) in [("cone 1e-2", set_of(cone(1e-2))), ("wedge 1e-2", set_of(wedge(1e-2)))] {
        let t = set.topology.report;
        assert_eq!(t.collapsed_edges, 0, "{name}: {t:?}");
        assert_eq!(set.repairs.welded_points, if name.starts_with("cone") { 16 } else { 0 }, "{name}");
        keeps_topology(&set, name);
    }
}
