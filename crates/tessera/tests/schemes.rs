//! The view-dependent schemes of issue 4 — semi-uniform (paper 000), SD-2 (paper 001) and the
//! Direct3D 11 hardware partitionings (integer, pow2, fractional odd and even) — on every model and 30 seeded random cameras each:
//! watertight, SD-2 never three different factors, strips decode to the triangle list, and
//! the render queues of the instanced form agree with the compacted mesh.

mod common;

use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};
use std::collections::HashMap;
use tessera::camera::Camera;
use tessera::criterion::sd2;
use tessera::criterion::view::{Mapping, ViewCriterion};
use tessera::engine::render_queues;
use tessera::engine::{tessellate, EngineOptions};
use tessera::mesh::strips;
use tessera::mesh::Mesh;
use tessera::pattern::hardware::Partitioning;
use tessera::pattern::semi_uniform::StaticPattern;
use tessera::scheme::{Criterion, PlanOptions, Scheme, SchemePlan};
use tessera::surface::{Domain, SurfaceSet};
use tessera::Error;

/// Semi-uniform with the render queues' highest level.
const SEMI_UNIFORM: Scheme = Scheme::SemiUniform { max_level: 5 };

/// Plans through the library's front door, factors up to 64.
fn planned(set: &SurfaceSet, scheme: Scheme, criterion: Criterion, camera: Camera, cull: bool) -> SchemePlan {
    let options = PlanOptions { camera: Some(camera), cull, ..PlanOptions::default() };
    scheme.plan(set, &criterion, &options).unwrap()
}

/// A view criterion with factors in `[fmin, fmax]`.
fn view(kind: u8, fmin: f64, fmax: f64) -> Criterion {
    Criterion::View { criterion: view_criterion(kind), fmin, fmax }
}

/// The fast tier runs the scheme properties on [`common::fast_models`] with a few cameras; the
/// slow tier (`#[ignore]`d, run by `scripts/test`) on every model with 10 cameras each.
#[derive(Debug, Clone, Copy)]
enum Tier {
    Fast,
    Slow,
}

impl Tier {
    fn cameras(self) -> u32 {
        match self {
            Tier::Fast => 6,
            Tier::Slow => 10,
        }
    }

    /// `all`, or the fast models among them.
    fn models(self, all: Vec<std::path::PathBuf>) -> Vec<std::path::PathBuf> {
        match self {
            Tier::Slow => all,
            Tier::Fast => {
                let fast = common::fast_models();
                all.into_iter().filter(|p| fast.contains(p)).collect()
            }
        }
    }
}

fn name_of(path: &std::path::Path) -> String {
    path.file_name().unwrap().to_string_lossy().to_string()
}

/// Largest factor for a model: big meshes get small factors so the test stays fast; every
/// model still sees two different factors on every camera.
fn top_factor(set: &SurfaceSet) -> f64 {
    match set.patches.len() {
        n if n > 20_000 => 2.5,
        n if n > 5_000 => 5.0,
        _ => 8.0,
    }
}

/// Runs `check` on `cameras` seeded random cameras per model, with random extra inputs.
fn for_cameras<S: Strategy + Clone>(
    models: &[std::path::PathBuf],
    cameras: u32,
    extra: S,
    check: impl Fn(&SurfaceSet, &str, Camera, S::Value) -> Result<(), TestCaseError>,
) {
    for path in models {
        let set = common::load(path).unwrap();
        let name = name_of(path);
        let start = std::time::Instant::now();
        let mut runner = TestRunner::new_with_rng(
            Config { cases: cameras, failure_persistence: None, ..Config::default() },
            TestRng::deterministic_rng(RngAlgorithm::ChaCha),
        );
        runner
            .run(&(common::random_camera(&set), extra.clone()), |((camera, _px), x)| {
                check(&set, &name, camera, x)
            })
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        println!("{name}: {cameras} cameras in {:.1} s", start.elapsed().as_secs_f64());
    }
}

fn view_criterion(kind: u8) -> ViewCriterion {
    match kind % 4 {
        0 => ViewCriterion::Distance(Mapping::Linear),
        1 => ViewCriterion::Distance(Mapping::Quadratic),
        2 => ViewCriterion::Silhouetteness,
        _ => ViewCriterion::SilhouetteVertices,
    }
}

fn options(strips: bool) -> EngineOptions {
    EngineOptions { strips, ..Default::default() }
}

#[test]
fn semi_uniform_is_watertight_and_its_render_queues_match() {
    semi_uniform_is_watertight_and_its_render_queues_match_in(Tier::Fast);
}

#[test]
#[ignore = "slow tier (every model, 10 cameras): scripts/test runs it"]
fn semi_uniform_is_watertight_and_its_render_queues_match_on_every_model() {
    semi_uniform_is_watertight_and_its_render_queues_match_in(Tier::Slow);
}

fn semi_uniform_is_watertight_and_its_render_queues_match_in(tier: Tier) {
    let models = tier.models(common::all_surface_models());
    for_cameras(
        &models,
        tier.cameras(),
        (any::<u8>(), 0.0..1.0f64, any::<bool>()),
        |set, name, camera, (kind, lo, cull)| {
            let top = top_factor(set) as u32;
            let fmin = 1 + (lo * (top - 1) as f64) as u32;
            let SchemePlan { plan, pattern, .. } =
                planned(set, SEMI_UNIFORM, view(kind, fmin as f64, top as f64), camera, cull);
            let mesh = tessellate(set, &plan, &pattern, options(false)).unwrap();
            common::expect_topology(set, &plan, &mesh, name);
            let w = tessera::verify::watertight(&mesh);
            prop_assert_eq!(w.degenerate_triangles(), 0, "compacted mesh has degenerate triangles");
            // The render queues hold every visible patch once, at its level, with its edge levels.
            let queues = render_queues::build(set, &plan, 5).unwrap();
            let mut seen = vec![false; set.patches.len()];
            for m in 0..=queues.max_level() {
                let mut last = None;
                for e in queues.level(m) {
                    let p = e.patch as usize;
                    prop_assert!(plan.is_visible(p) && !seen[p]);
                    prop_assert!(last < Some(e.patch), "queue not sorted by patch id");
                    last = Some(e.patch);
                    seen[p] = true;
                    prop_assert_eq!(plan.interior[p][0], 1 << m);
                    for l in 0..set.patches[p].domain().corner_count() {
                        let s = plan.segments(set.topology.patch_edges[p][l].edge as usize);
                        prop_assert_eq!(1u32 << e.edge_levels[l], s);
                    }
                }
            }
            prop_assert!(
                seen.iter().zip(&plan.visible).all(|(&s, &v)| s == (v != 0)),
                "a visible patch is in no queue"
            );
            Ok(())
        },
    );
}

/// The instanced draw (static `P^m`, `φ` in the "vertex shader") gives, once its degenerate
/// triangles are dropped, exactly the compacted mesh's triangles, patch by patch.
#[test]
fn instanced_draw_equals_the_compacted_mesh() {
    let mut models = common::models_in("patches", "patches");
    models.extend(["meshes/helmet.obj", "meshes/spool.obj", "meshes/cow.obj"].map(common::model));
    let patterns = [StaticPattern::all(Domain::Tri, 5), StaticPattern::all(Domain::Quad, 5)];
    for path in &models {
        let set = common::load(path).unwrap();
        let name = name_of(path);
        let (lo, hi) = set.bounds();
        let camera = Camera::framing(lo, hi, 1280, 720);
        for kind in 0..4 {
            let SchemePlan { plan, pattern, .. } =
                planned(&set, SEMI_UNIFORM, view(kind, 1.0, 32.0), camera, kind % 2 == 0);
            let compact = tessellate(
                &set,
                &plan,
                &pattern,
                EngineOptions { corner_params: true, ..Default::default() },
            )
            .unwrap();
            let queues = render_queues::build(&set, &plan, 5).unwrap();
            let drawn = render_queues::draw(&set, &queues, &patterns);
            // Triangles of each patch as parameter triples (exact: dyadic f32 values).
            let key = |uv: [[f32; 2]; 3]| uv.map(|p| p.map(f32::to_bits));
            let mut expected: HashMap<u32, Vec<[[u32; 2]; 3]>> = HashMap::new();
            let params = compact.corner_params.as_ref().unwrap();
            for t in 0..compact.triangle_count() {
                let uv = [params[3 * t], params[3 * t + 1], params[3 * t + 2]];
                expected.entry(compact.triangle_patch[t]).or_default().push(key(uv));
            }
            let mut got: HashMap<u32, Vec<[[u32; 2]; 3]>> = HashMap::new();
            let mut degenerate = 0;
            for t in 0..drawn.triangle_count() {
                let uv = drawn.triangle(t).map(|i| drawn.uvs[i as usize]);
                if uv[0] == uv[1] || uv[1] == uv[2] || uv[0] == uv[2] {
                    degenerate += 1;
                    continue;
                }
                got.entry(drawn.triangle_patch[t]).or_default().push(key(uv));
            }
            for v in expected.values_mut().chain(got.values_mut()) {
                v.sort_unstable();
            }
            // Collapsed corners (the teapot's apex) drop triangles in the compacted mesh
            // that the instanced draw keeps with zero area; compare the rest.
            for (p, tris) in &got {
                let want = &expected[p];
                let kept: Vec<_> = tris.iter().filter(|t| want.binary_search(t).is_ok()).collect();
                assert_eq!(kept.len(), want.len(), "{name} kind {kind} patch {p}: triangles differ");
                let extra = tris.len() - kept.len();
                assert!(
                    extra == 0
                        || set.topology.patch_edges[*p as usize]
                            .iter()
                            .any(|e| set.topology.edges[e.edge as usize].collapsed),
                    "{name} patch {p}: {extra} extra triangles"
                );
            }
            assert_eq!(got.len(), expected.len(), "{name}: patches drawn");
            assert_eq!(drawn.triangle_count() - degenerate, got.values().map(Vec::len).sum::<usize>());
        }
    }
}

fn triangle_models() -> Vec<std::path::PathBuf> {
    let mut v = common::models_in("meshes", "obj");
    v.extend(common::models_in("awkward", "obj"));
    v
}

/// SD-2 on every triangle model: never three different factors in a triangle, watertight,
/// strips decode to exactly the triangle list, with and without the reverse-projection warp.
#[test]
fn sd2_is_two_different_watertight_and_strips_decode() {
    sd2_is_two_different_watertight_and_strips_decode_in(Tier::Fast);
}

#[test]
#[ignore = "slow tier (every model, 10 cameras): scripts/test runs it"]
fn sd2_is_two_different_watertight_and_strips_decode_on_every_model() {
    sd2_is_two_different_watertight_and_strips_decode_in(Tier::Slow);
}

fn sd2_is_two_different_watertight_and_strips_decode_in(tier: Tier) {
    let models = tier.models(triangle_models());
    let extra = (any::<bool>(), 0.0..1.0f64, 0.0..1.0f64, any::<bool>(), any::<bool>());
    for_cameras(&models, tier.cameras(), extra, |set, name, camera, (silhouette, a, b, warp, cull)| {
        let top = top_factor(set);
        let (fmin, fmax) = (1.0 + a * (top - 1.0), 1.0 + b * (top - 1.0));
        let (fmin, fmax) = (fmin.min(fmax), fmin.max(fmax));
        let kind = if silhouette { 3 } else { 0 };
        let SchemePlan { plan, pattern, .. } =
            planned(set, Scheme::Sd2 { warp }, view(kind, fmin, fmax), camera, cull);
        prop_assert_eq!(sd2::three_different(set, &plan), 0, "{}: three different factors", name);
        let mesh = tessellate(set, &plan, &pattern, options(true)).unwrap();
        common::expect_topology(set, &plan, &mesh, name);
        let decoded = strips::decode(mesh.strips.as_ref().unwrap());
        let list: Vec<[u32; 3]> = mesh.indices.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect();
        prop_assert!(
            decoded == list,
            "{}: strips decode to {} triangles, list has {}",
            name,
            decoded.len(),
            list.len()
        );
        Ok(())
    });
}

/// The hardware partitionings on every model: real factors from the view criteria, all four
/// modes, watertight.
#[test]
fn hardware_partitionings_are_watertight() {
    hardware_partitionings_are_watertight_in(Tier::Fast);
}

#[test]
#[ignore = "slow tier (every model, 10 cameras): scripts/test runs it"]
fn hardware_partitionings_are_watertight_on_every_model() {
    hardware_partitionings_are_watertight_in(Tier::Slow);
}

fn hardware_partitionings_are_watertight_in(tier: Tier) {
    let models = tier.models(common::all_surface_models());
    let extra = (any::<u8>(), 0.0..1.0f64, 0.0..1.0f64, 0..4usize, any::<bool>());
    for_cameras(&models, tier.cameras(), extra, |set, name, camera, (kind, a, b, mode, cull)| {
        let top = top_factor(set);
        let (fmin, fmax) = (1.0 + a * (top - 1.0), 1.0 + b * (top - 1.0));
        let criterion = view(kind, fmin.min(fmax), fmin.max(fmax));
        let partitioning = [
            Partitioning::Integer,
            Partitioning::Pow2,
            Partitioning::FractionalOdd,
            Partitioning::FractionalEven,
        ][mode];
        let SchemePlan { plan, pattern, .. } =
            planned(set, Scheme::Hardware(partitioning), criterion, camera, cull);
        let mesh = tessellate(set, &plan, &pattern, options(false)).unwrap();
        common::expect_topology(set, &plan, &mesh, name);
        Ok(())
    });
}

/// Strips survive a PLY round trip, and a strip-only PLY reads back as the decoded list.
#[test]
fn strips_round_trip_through_ply() {
    let set = common::load(&common::model("meshes/spool.obj")).unwrap();
    let (lo, hi) = set.bounds();
    let camera = Camera::framing(lo, hi, 800, 600);
    let SchemePlan { plan, pattern, .. } =
        planned(&set, Scheme::Sd2 { warp: false }, view(3, 1.0, 4.5), camera, false);
    let mesh: Mesh = tessellate(&set, &plan, &pattern, options(true)).unwrap();
    let dir = std::env::temp_dir().join(format!("tessera-strips-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("spool.ply");
    tessera::io::write_mesh(&mesh, &path).unwrap();
    let back = tessera::io::read_mesh(&path).unwrap();
    assert_eq!(back.strips, mesh.strips);
    assert_eq!(back.indices, mesh.indices);
    std::fs::remove_dir_all(&dir).ok();
    // A pattern without a strip form refuses strips instead of writing half of them.
    let dyadic = planned(&set, SEMI_UNIFORM, view(2, 1.0, 4.0), camera, false);
    let err = tessellate(&set, &dyadic.plan, &dyadic.pattern, options(true)).unwrap_err();
    assert!(matches!(err, Error::NoStripForm { pattern: "semi-uniform" }), "{err}");
}

/// SD-2 refuses quads with a clear error instead of tessellating them wrongly.
#[test]
fn sd2_refuses_quad_patches() {
    let set = common::load(&common::model("patches/teapot.patches")).unwrap();
    let (lo, hi) = set.bounds();
    let camera = Camera::framing(lo, hi, 800, 600);
    let options = PlanOptions { camera: Some(camera), ..PlanOptions::default() };
    let err = Scheme::Sd2 { warp: false }.plan(&set, &view(3, 1.0, 7.0), &options).unwrap_err();
    assert!(
        matches!(err, Error::PatchKindNotAccepted { scheme: "sd2", kind: "quad", patch: 0, .. }),
        "{err}"
    );
}
