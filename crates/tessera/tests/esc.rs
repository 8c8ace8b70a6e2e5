//! ESC (paper 002) acceptance: watertight output — bit-identical positions welded, no
//! boundary edges but the input's own open boundaries, no non-manifold edges — on every patch
//! model, at every level 1–5, for seeded random cameras, with both presets; and the strip
//! form decodes to the triangle list.
//!
//! A third, small absolute threshold makes the torus (where the presets insert nothing: its
//! patches are tiny next to its diagonal) insert candidates too.
//!
//! Split (to stay well under a minute in the test profile): for every (model, level,
//! threshold) one tessellation at the fixed level, plus the camera-driven levels (`Lmax` =
//! that level) of 50 seeded cameras. A camera only chooses the level of
//! each object (the distance test does not depend on it), so cameras that give a level
//! vector already checked give the same plan (asserted) and are not tessellated again.

mod common;
#[path = "../examples/common/teacups.rs"]
mod teacups;

use glam::DVec3;
use proptest::prelude::*;
use proptest::strategy::ValueTree;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};
use std::collections::HashMap;
use tessera::camera::Camera;
use tessera::criterion::esc::{self, EscOptions, Threshold};
use tessera::criterion::Plan;
use tessera::engine::{tessellate, EngineOptions};
use tessera::mesh::strips;
use tessera::pattern::esc::Esc;
use tessera::pattern::uniform::Uniform;
use tessera::surface::SurfaceSet;
use tessera::verify;

/// A camera outside the bounding sphere, looking near the centre.
fn random_camera(set: &SurfaceSet) -> impl Strategy<Value = Camera> {
    let (lo, hi) = set.bounds();
    let (centre, diag) = ((lo + hi) * 0.5, lo.distance(hi));
    ((-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64), 0.6..6.0f64, 20.0..90.0f64).prop_filter_map(
        "degenerate direction",
        move |(d, dist, fov)| {
            let dir = DVec3::new(d.0, d.1, d.2).try_normalize()?;
            let up = if dir.z.abs() < 0.9 { DVec3::Z } else { DVec3::Y };
            let cam = Camera {
                eye: centre + dir * dist * diag,
                target: centre,
                up,
                fov_y_degrees: fov,
                width: 1280,
                height: 1024,
                near: diag * 1e-3,
                far: diag * 20.0,
            };
            cam.validate().ok()?;
            Some(cam)
        },
    )
}

fn cameras(set: &SurfaceSet, count: usize) -> Vec<Camera> {
    let mut runner =
        TestRunner::new_with_rng(Config::default(), TestRng::deterministic_rng(RngAlgorithm::ChaCha));
    let strategy = random_camera(set);
    (0..count).map(|_| strategy.new_tree(&mut runner).unwrap().current()).collect()
}

/// Tessellates with the ESC plan and checks watertightness against the input's own topology
/// and the strip form against the list. Returns the triangle count.
fn check(set: &SurfaceSet, plan: &Plan, pattern: &Esc, open: (usize, usize), what: &str) -> usize {
    let options = EngineOptions { strips: true, corner_params: true, ..Default::default() };
    let mesh = tessellate(set, plan, pattern, options).unwrap_or_else(|e| panic!("{what}: {e}"));
    // Every triangle is counter-clockwise in its patch's domain: the pattern placed each
    // boundary vertex where the plan's edge sampling put it (no folds).
    let params = mesh.corner_params.as_ref().unwrap();
    for (t, c) in params.chunks(3).enumerate() {
        let area = (c[1][0] - c[0][0]) * (c[2][1] - c[0][1]) - (c[1][1] - c[0][1]) * (c[2][0] - c[0][0]);
        assert!(area > 0.0, "{what}: triangle {t} has domain area {area}: {c:?}");
    }
    // The pattern's boundary candidates are the plan's edge parameters, read in each patch's
    // own direction.
    for p in 0..set.patches.len() {
        let grid = pattern.grid(p);
        let side = grid.side() as f64;
        for e in 0..4 {
            let pe = set.topology.patch_edges[p][e];
            let edge = pe.edge as usize;
            let pts = grid.edge_points(e);
            assert_eq!(pts.len() + 1, plan.segments(edge) as usize, "{what}: patch {p} edge {e}");
            for (k, &(i, j)) in pts.iter().enumerate() {
                let t = plan.local_param(edge, k as u32 + 1, pe.reversed);
                let lattice = [i as f64 / side, j as f64 / side];
                let uv = tessera::surface::Domain::Quad.edge_point(e, t);
                assert!(
                    (uv.x - lattice[0]).abs() < 1e-12 && (uv.y - lattice[1]).abs() < 1e-12,
                    "{what}: patch {p} edge {e} sample {k}"
                );
            }
        }
    }
    // The input's own open boundary and non-manifold curves, cut at the inserted candidates.
    let topo = &set.topology;
    let (mut boundary, mut nonmanifold) = (0, 0);
    for (e, edge) in topo.edges.iter().enumerate() {
        if edge.collapsed {
            continue;
        }
        let s = plan.segments(e) as usize;
        match topo.edge_uses(e).len() {
            1 => boundary += s,
            2 => {}
            _ => nonmanifold += s,
        }
    }
    let w = verify::watertight(&mesh);
    assert_eq!(w.boundary_edges, boundary, "{what}: boundary edges {w:?}");
    assert_eq!(w.nonmanifold_edges, nonmanifold, "{what}: non-manifold edges {w:?}");
    assert_eq!((w.boundary_edges == 0, w.nonmanifold_edges == 0), (open.0 == 0, open.1 == 0), "{what}");
    assert_eq!(w.misoriented_edges, 0, "{what}");
    assert_eq!(w.collapsed_triangles, 0, "{what}");
    assert_eq!(w.euler_characteristic, topo.report.euler_characteristic, "{what}: Euler characteristic");
    let decoded = strips::decode(mesh.strips.as_ref().expect("strips requested"));
    let list: Vec<[u32; 3]> = mesh.indices.chunks(3).map(|c| [c[0], c[1], c[2]]).collect();
    assert!(decoded == list, "{what}: strips decode to {} triangles, list has {}", decoded.len(), list.len());
    mesh.triangle_count()
}

fn acceptance(rel: &str, camera_count: usize) {
    let set = common::load(&common::model(rel)).unwrap();
    let name = rel.to_string();
    // The uniform tessellation shows the input's own open boundary / non-manifold edges.
    let uniform = tessellate(&set, &Plan::uniform(&set, 2).unwrap(), &Uniform, Default::default()).unwrap();
    let u = verify::watertight(&uniform);
    let open = (u.boundary_edges, u.nonmanifold_edges);
    let cams = cameras(&set, camera_count);
    // Both presets, and a small absolute threshold: the presets are fractions of the whole
    // model's diagonal, which on the torus's 2,048 small patches inserts nothing.
    let (lo, hi) = set.bounds();
    let fine = Threshold::Absolute(2e-4 * lo.distance(hi));
    for threshold in [Threshold::High, Threshold::Medium, fine] {
        for level in 1..=5 {
            let fixed = EscOptions { max_level: level, level: Some(level), threshold, ..Default::default() };
            let (plan, pattern) = esc::plan(&set, &cams[0], &fixed).unwrap();
            let full = 18 * set.patches.len() * ((level + 1) * (level + 1)) as usize;
            let tris = check(&set, &plan, &pattern, open, &format!("{name} {threshold:?} L={level}"));
            assert!(tris <= full, "{name}: {tris} > {full}");
            // Camera-driven levels: near objects get Lmax, far ones less (a small reference
            // distance so the random distances reach several levels).
            let mut seen: HashMap<Vec<u32>, Plan> = HashMap::new();
            seen.insert(vec![level + 1; set.patches.len()], plan);
            for (c, camera) in cams.iter().enumerate() {
                let options = EscOptions { max_level: level, level: None, threshold, near_diagonals: 1.0 };
                let (plan, pattern) = esc::plan(&set, camera, &options).unwrap();
                let key: Vec<u32> = (0..set.patches.len()).map(|p| pattern.grid(p).n).collect();
                match seen.get(&key) {
                    Some(known) => assert_eq!(known, &plan, "{name}: same levels, different plan"),
                    None => {
                        check(
                            &set,
                            &plan,
                            &pattern,
                            open,
                            &format!("{name} {threshold:?} Lmax={level} camera {c}"),
                        );
                        seen.insert(key, plan);
                    }
                }
            }
        }
    }
}

#[test]
fn esc_is_watertight_on_the_teapot() {
    acceptance("patches/teapot.patches", 50);
}

#[test]
fn esc_is_watertight_on_the_teacup() {
    acceptance("patches/teacup.patches", 50);
}

#[test]
fn esc_is_watertight_on_the_teaset_teapot() {
    acceptance("patches/teapot_teasetorig.patches", 50);
}

#[test]
fn esc_is_watertight_on_the_torus() {
    acceptance("bench/torus_64x32.patches", 50);
}

/// The Teacups scene: 2,600 surfaces, 100 objects, and per-object levels that differ along
/// the walk; every frame is watertight and no cup shares a curve with another.
#[test]
fn teacups_scene_is_watertight_with_mixed_levels() {
    let cup = common::load(&common::model("patches/teacup.patches")).unwrap();
    let (scene, cameras) = teacups::teacups_scene(&cup).unwrap();
    assert_eq!(scene.patches.len(), 2600);
    assert_eq!(cameras.len(), teacups::TEACUPS_FRAMES);
    let uniform =
        tessellate(&scene, &Plan::uniform(&scene, 2).unwrap(), &Uniform, Default::default()).unwrap();
    let u = verify::watertight(&uniform);
    let options = EscOptions { threshold: Threshold::Medium, ..Default::default() };
    let (plan, pattern) = esc::plan(&scene, &cameras[0], &options).unwrap();
    let levels: std::collections::BTreeSet<u32> = (0..2600).map(|p| pattern.grid(p).n - 1).collect();
    assert!(levels.len() > 1, "the first frame should mix levels: {levels:?}");
    check(&scene, &plan, &pattern, (u.boundary_edges, u.nonmanifold_edges), "teacups frame 0");
    let counts = teacups::frame_counts(&scene, &cameras[..3], &options).unwrap();
    for c in counts {
        assert!(c.adaptive < c.non_adaptive && c.non_adaptive <= 2600 * 288, "{c:?}");
    }
}

#[test]
fn triangle_patches_are_refused() {
    let set = common::load(&common::model("meshes/blob.obj")).unwrap();
    let camera = Camera::framing(set.bounds().0, set.bounds().1, 640, 480);
    let err = esc::plan(&set, &camera, &EscOptions::default());
    assert!(matches!(err, Err(tessera::Error::Unsupported { .. })), "{err:?}");
}
