//! The seed papers' own patterns on the GPU engine against the CPU engine, on lavapipe in CI:
//! semi-uniform (paper 000, compacted: `tessera::pattern::semi_uniform`) from the CPU's own
//! plans, arbitrary power-of-two plans and the camera, on bicubic patches, PN and Bézier
//! triangles and Catmull-Clark cages (collapsed curves, pinched corners and isolated faces
//! included); SD-2 (paper 001: `tessera::pattern::sd2`) from the CPU's plans on triangle
//! meshes. Every expected value comes from the CPU library, never from the GPU itself.
//!
//! No adapter is a failure, not a skip: the message names the packages to install.

mod common;

use common::*;
use tessera::criterion::view::{Mapping, ViewCriterion};
use tessera::criterion::Plan;
use tessera::io::{LoadOptions, SurfaceKind};
use tessera::pattern::semi_uniform::SemiUniform;
use tessera::scheme::{Criterion, PlanOptions, Scheme};
use tessera::surface::SurfaceSet;
use tessera_gpu::tessellator::ScreenCriterion;
use tessera_gpu::GpuError;

/// A semi-uniform plan with every edge at a random level up to `top` and every patch one
/// level above its finest edge or at it (within `top`); `cull` culls every third patch.
fn random_plan(set: &SurfaceSet, rng: &mut Lcg, top: u32, cull: bool) -> Plan {
    let segments: Vec<u32> = (0..set.topology.edges.len()).map(|_| 1 << (rng.next() % (top + 1))).collect();
    let interior = (0..set.patches.len())
        .map(|p| {
            let corners = set.topology.patch_domains[p].corner_count();
            let edges = &set.topology.patch_edges[p][..corners];
            let finest = edges.iter().map(|pe| segments[pe.edge as usize]).max().unwrap_or(1);
            let n = (finest << (rng.next() % 2)).min(1 << top).max(finest);
            [n, n]
        })
        .collect();
    let mut plan = Plan::integer(segments, interior, set.patches.len());
    if cull {
        plan.visible.iter_mut().step_by(3).for_each(|v| *v = 0);
    }
    plan
}

/// The CPU's own semi-uniform plans for an object-space tolerance (edges at their own levels,
/// patches at their finest edge's, raised by the a-posteriori check), then `rounds` random
/// plans up to level `top`: the GPU's frame equals the CPU engine's index for index. Returns
/// whether a tolerance plan had edges at different levels (snapping at work).
fn semi_uniform_equals_the_cpu(
    name: &str,
    set: &SurfaceSet,
    tolerances: &[f64],
    rounds: u32,
    top: u32,
) -> bool {
    let mut gpu = tessellator(set);
    let scheme = Scheme::SemiUniform { max_level: 5 };
    let mut varied = false;
    for &rel in tolerances {
        let criterion = Criterion::Tolerance(rel * diagonal(set));
        let planned = scheme.plan(set, &criterion, &PlanOptions::default()).unwrap();
        let levels: std::collections::BTreeSet<u32> = planned.plan.segments.iter().copied().collect();
        varied |= levels.len() > 1;
        assert_pattern_equals_cpu(
            &format!("{name} tolerance {rel}"),
            set,
            &mut gpu,
            &planned.plan,
            &SemiUniform,
        );
    }
    let mut rng = Lcg(u64::from(top) * 7919 + set.patches.len() as u64);
    for round in 0..rounds {
        let plan = random_plan(set, &mut rng, top, round % 2 == 1);
        assert_pattern_equals_cpu(
            &format!("{name} random round {round}"),
            set,
            &mut gpu,
            &plan,
            &SemiUniform,
        );
    }
    varied
}

#[test]
fn semi_uniform_equals_the_cpu_engine_on_every_patch_model() {
    let mut varied = 0;
    for model in patch_models() {
        let set = load(&model);
        let (tolerances, rounds): (&[f64], u32) =
            if set.patches.len() > 500 { (&[1e-3], 1) } else { (&[1e-2, 1e-3], 4) };
        varied += u32::from(semi_uniform_equals_the_cpu(&model, &set, tolerances, rounds, 4));
    }
    assert!(varied >= 2, "only {varied} models planned with edges at different levels");
}

#[test]
fn semi_uniform_on_triangles_equals_the_cpu_engine() {
    for model in ["meshes/blob.obj", "awkward/teapot_tri_nonmanifold.obj"] {
        let pn = load(model);
        assert!(semi_uniform_equals_the_cpu(&format!("{model} as PN triangles"), &pn, &[1e-2, 1e-3], 3, 4));
        let bezier = as_bezier_triangles(&pn);
        semi_uniform_equals_the_cpu(&format!("{model} as Bézier triangles"), &bezier, &[1e-3], 2, 4);
    }
}

/// Catmull-Clark cages: isolated faces (trees), n-gons, holes, creases, and corners pinched at
/// a valence-2 vertex, which the semi-uniform grid cuts as the uniform one does (through
/// corners 0 and 2), so the GPU draws them too.
#[test]
fn semi_uniform_on_subdivision_cages_equals_the_cpu_engine() {
    let options = LoadOptions { surface: SurfaceKind::CatmullClark, ..Default::default() };
    let mut pinched = 0;
    for cage in ["catmark_val2_interior", "catmark_hole_test1", "catmark_nonquads", "catmark_torus_creases0"]
    {
        let path = tessera::test_support::data(&format!("subdivision/{cage}.obj"));
        let set = tessera::io::load(&path, options).unwrap();
        pinched += set.topology.patch_pinched.iter().filter(|c| c.iter().any(|&x| x)).count();
        // Random plans snap on every cage; the tolerance plans of the small ones may not.
        semi_uniform_equals_the_cpu(cage, &set, &[1e-2, 1e-3], 2, 3);
    }
    assert!(pinched > 0, "no pinched corner among the cages");
}

/// The highest level, 8: 2 · 256² triangles a quad, more than one lavapipe invocation may
/// loop over (65,535 iterations), so this holds only because each row has its own invocation.
#[test]
fn semi_uniform_at_the_highest_level_equals_the_cpu_engine() {
    let set = load("patches/teapot.patches");
    let mut gpu = tessellator(&set);
    let top = tessera::pattern::semi_uniform::MAX_LEVEL;
    let mut plan = random_plan(&set, &mut Lcg(8), top, false);
    // A third of the patches at the top level whatever their edges (the rest as drawn), so
    // that rows of 512 triangles and patches of 2¹⁷ are drawn next to coarse neighbours.
    for p in (0..set.patches.len()).step_by(3) {
        plan.interior[p] = [1 << top; 2];
    }
    assert_pattern_equals_cpu("teapot at level 8", &set, &mut gpu, &plan, &SemiUniform);
}

#[test]
fn a_plan_outside_the_patterns_preconditions_is_refused_by_name() {
    let set = load("patches/teacup.patches");
    let mut gpu = tessellator(&set);
    let ctx = ctx();
    let not_dyadic = Plan::uniform(&set, 3).unwrap();
    let e = gpu.prepare(ctx, &set, &not_dyadic, &SemiUniform).unwrap_err();
    assert!(matches!(&e, GpuError::Tessera(tessera::Error::PlanMismatch { .. })), "{e:?}");
    assert!(e.to_string().contains("power of two"), "{e}");
    let mut finer_edge = Plan::uniform(&set, 4).unwrap();
    finer_edge.interior[5] = [2, 2];
    let e = gpu.prepare(ctx, &set, &finer_edge, &SemiUniform).unwrap_err().to_string();
    assert!(e.contains("patch 5") && e.contains("up to the patch level 2"), "{e}");
    // Culled patches are not drawn, so their interiors do not matter...
    finer_edge.visible[5] = 0;
    assert_pattern_equals_cpu("teacup, the odd patch culled", &set, &mut gpu, &finer_edge, &SemiUniform);
    // ...unless the GPU culls for a camera of its own, and may draw it.
    gpu.set_cull_camera(ctx, Some(&cameras(&set, 1, 3)[0]));
    let e = gpu.prepare(ctx, &set, &finer_edge, &SemiUniform).unwrap_err().to_string();
    assert!(e.contains("patch 5"), "{e}");
}

/// The semi-uniform pixel-error frame planned on the GPU from the camera alone (culling, the
/// edges' levels, the a-posteriori check raising levels and, round by round, edges) against
/// `Scheme::SemiUniform`'s plan on the CPU ([`checked_frame`]), and each frame's output
/// against the CPU engine's for the plan the GPU drew: patches, a mesh and a cage, fine and
/// coarse pixel errors, under a low cap where patches at the cap miss their bound. The
/// semi-uniform check needs no fix rounds on the shared data (a patch's level is at least
/// its finest edge, and each edge at least its patches' own uniform factor, so only the cap
/// stops a bound, and raising edges then changes nothing: over every model with at most
/// 20,000 patches, 6 cameras, 0.25–8 px and caps 4–32, the CPU ran none); their passes are
/// the transition check's, tested there, and the frames here check the count, zero, too.
#[test]
fn pixel_error_semi_uniform_planned_on_the_gpu_equals_the_cpu_plan() {
    let scheme = Scheme::SemiUniform { max_level: 5 };
    let options = LoadOptions { surface: SurfaceKind::CatmullClark, ..Default::default() };
    let cage = |name: &str| {
        tessera::io::load(&tessera::test_support::data(&format!("subdivision/{name}.obj")), options).unwrap()
    };
    let models = [
        ("patches/teapot.patches", load("patches/teapot.patches")),
        ("meshes/spool.obj", load("meshes/spool.obj")),
        ("catmark_torus_creases0", cage("catmark_torus_creases0")),
        // Pinched corners, which the semi-uniform grid draws on the GPU.
        ("catmark_val2_interior", cage("catmark_val2_interior")),
    ];
    let mut counts = SweepCounts::default();
    let (mut levels, mut most_rounds) = (std::collections::BTreeSet::new(), 0);
    for (model, set) in &models {
        let prepared = tessera::scheme::Prepared::new(set, true);
        let mut gpu = tessellator(set);
        for (c, camera) in cameras(set, 3, 17).into_iter().enumerate() {
            for (pixels, cap) in [(0.5, 8), (4.0, 32)] {
                let name = format!("{model} camera {c} {pixels} px cap {cap}");
                let plan = checked_frame(
                    scheme,
                    tessera::scheme::ErrorBound::Hessian,
                    &name,
                    set,
                    &prepared,
                    &mut gpu,
                    &camera,
                    pixels,
                    cap,
                    &mut counts,
                );
                most_rounds = most_rounds.max(gpu.read_screen_report(ctx()).unwrap().rounds);
                levels.extend(
                    (0..set.patches.len()).filter(|&p| plan.is_visible(p)).map(|p| plan.interior[p][0]),
                );
                assert_gpu_equals_cpu_after_record(&name, set, &gpu, &plan, &SemiUniform);
                counts.frames += 1;
            }
        }
    }
    eprintln!("{counts:?}, most fix rounds {most_rounds}, patch levels {levels:?}");
    assert_eq!(counts.check_ties, 0, "{counts:?}");
    assert!(counts.culled > 0, "nothing culled: {counts:?}");
    assert!(levels.len() >= 4, "patch levels {levels:?}: too few to test the check");
}

/// Semi-uniform silhouetteness from the camera alone (factors 1 to 16 taken between levels,
/// cap 16): the GPU's plan equals `Scheme::SemiUniform`'s on the CPU — each edge's level but
/// for counted rounding ties (an edge whose real level lies within 1e-4 of a whole number,
/// one level off), the patch levels those of `resolve::interiors` on the GPU's edges, the
/// culled set but for `near_cull_tie`s — and the frame's output equals the CPU engine's for
/// the plan drawn.
#[test]
fn silhouetteness_semi_uniform_planned_on_the_gpu_equals_the_cpu_plan() {
    use tessera::criterion::resolve::InteriorRule;
    let ctx = ctx();
    let scheme = Scheme::SemiUniform { max_level: 5 };
    let (cap, fmin, fmax) = (16, 1.0, 16.0);
    let criterion = Criterion::View { criterion: ViewCriterion::Silhouetteness, fmin, fmax };
    let (mut frames, mut edges, mut ties, mut mixed) = (0, 0, 0, 0);
    for model in ["patches/teapot.patches", "patches/teacup.patches", "meshes/blob.obj"] {
        let set = load(model);
        let prepared = tessera::scheme::Prepared::new(&set, true);
        let mut gpu = tessellator(&set);
        for (c, camera) in cameras(&set, 3, 23).into_iter().enumerate() {
            let name = format!("{model} camera {c} silhouetteness");
            let options =
                PlanOptions { camera: Some(camera), cull: true, max_factor: cap, ..Default::default() };
            let cpu = scheme.plan_prepared(&set, &prepared, &criterion, &options).unwrap().plan;
            let screen = ScreenCriterion::new(scheme, criterion, cap);
            screen_frame(&mut gpu, &set, &prepared, &camera, screen);
            let drawn = gpu.read_plan(ctx).unwrap();
            check_culling(&name, &set, &gpu, &cpu.visible, &camera, &mut SweepCounts::default());
            let real = tessera::criterion::view::edge_factors(
                &set,
                &camera,
                ViewCriterion::Silhouetteness,
                fmin,
                fmax,
            );
            for e in (0..cpu.segments.len()).filter(|&e| drawn.segments[e] != cpu.segments[e]) {
                // The CPU's level of the edge, before rounding up (`view::plan_into`).
                let level = fmin.log2() + (real[e] - fmin) / (fmax - fmin) * (fmax.log2() - fmin.log2());
                let (a, b) = (drawn.segments[e].min(cpu.segments[e]), drawn.segments[e].max(cpu.segments[e]));
                assert!(
                    (level - level.round()).abs() <= 1e-4 && b == 2 * a,
                    "{name}: edge {e} has {} segments, the CPU's {} (level {level})",
                    drawn.segments[e],
                    cpu.segments[e]
                );
                ties += 1;
            }
            assert_interiors_follow_the_edges(&name, &set, &prepared, &drawn, InteriorRule::Level, cap);
            mixed += usize::from(drawn.segments.iter().any(|&s| s != drawn.segments[0]));
            edges += cpu.segments.len();
            frames += 1;
            assert_gpu_equals_cpu_after_record(&name, &set, &gpu, &drawn, &SemiUniform);
        }
    }
    eprintln!("semi-uniform silhouetteness: {frames} frames, {edges} edges, {ties} rounding ties, {mixed} with mixed levels");
    assert!(mixed * 2 >= frames, "too few frames with two levels: {mixed} of {frames}");
    assert!(1000 * ties <= edges, "{ties} rounding ties in {edges} edges");
}

/// SD-2 (paper 001) from the CPU's plans on triangle meshes, PN and cubic Bézier triangles:
/// the level function of the distance (linear and quadratic mappings) and of the vertex
/// silhouettes on three cameras each, the first also reverse-projected (`--warp`), and fixed
/// real factors; the GPU's frame equals the CPU engine's index for index (the symmetric cut,
/// the warp and the parallel × radial interior in f32, within 1e-5 of the diagonal). Each plan has at most two different factors per triangle
/// (the criterion's promise, checked here on every visible patch) and several factors in all.
#[test]
fn sd2_equals_the_cpu_engine_on_triangle_meshes() {
    let scheme = Scheme::Sd2 { warp: false };
    let criteria = [
        Criterion::View { criterion: ViewCriterion::Distance(Mapping::Linear), fmin: 1.0, fmax: 9.5 },
        Criterion::View { criterion: ViewCriterion::Distance(Mapping::Quadratic), fmin: 2.0, fmax: 7.25 },
        Criterion::View { criterion: ViewCriterion::SilhouetteVertices, fmin: 1.5, fmax: 12.0 },
    ];
    for model in ["meshes/blob.obj", "awkward/teapot_tri_nonmanifold.obj", "meshes/spool.obj"] {
        let pn = load(model);
        for (kind, set) in [("PN", &pn), ("Bézier", &as_bezier_triangles(&pn))] {
            let mut gpu = tessellator(set);
            let mut factors = std::collections::BTreeSet::new();
            for (c, camera) in cameras(set, 3, 41).into_iter().enumerate() {
                let warped = (Scheme::Sd2 { warp: true }, &criteria[0]);
                for (k, (scheme, criterion)) in
                    criteria.iter().map(|c| (scheme, c)).chain([warped]).enumerate()
                {
                    let name = format!("{model} as {kind} triangles, camera {c}, criterion {k}");
                    let options = PlanOptions { camera: Some(camera), ..Default::default() };
                    let planned = scheme.plan(set, criterion, &options).unwrap();
                    let plan = &planned.plan;
                    for p in (0..set.patches.len()).filter(|&p| plan.is_visible(p)) {
                        let f = tessera::engine::layout::pattern_input(set, plan, p).factors;
                        assert!(
                            f[0] == f[1] || f[1] == f[2] || f[2] == f[0],
                            "{name}: patch {p} 3-different {f:?}"
                        );
                    }
                    factors.extend(plan.factors.iter().map(|f| f.to_bits()));
                    assert_pattern_equals_cpu(&name, set, &mut gpu, plan, &planned.pattern);
                }
            }
            let planned = scheme.plan(set, &Criterion::Factor(4.6), &PlanOptions::default()).unwrap();
            assert_pattern_equals_cpu(
                &format!("{model} factor 4.6"),
                set,
                &mut gpu,
                &planned.plan,
                &planned.pattern,
            );
            assert!(factors.len() >= 6, "{model}: factors {factors:?}, too few to test the cut");
        }
    }
}

/// SD-2 on Loop cages (every triangle a tree of quartic and Gregory triangles): silhouette
/// vertices from two cameras and a fixed real factor, index for index as on the CPU.
#[test]
fn sd2_equals_the_cpu_engine_on_loop_cages() {
    let options = LoadOptions { surface: SurfaceKind::Loop, ..Default::default() };
    let scheme = Scheme::Sd2 { warp: false };
    let criterion = Criterion::View { criterion: ViewCriterion::SilhouetteVertices, fmin: 1.5, fmax: 12.0 };
    for cage in ["loop_cube_creases0", "loop_xord_boundary", "loop_pole8"] {
        let set =
            tessera::io::load(&tessera::test_support::data(&format!("subdivision/{cage}.obj")), options)
                .unwrap();
        let mut gpu = tessellator(&set);
        for (c, camera) in cameras(&set, 2, 43).into_iter().enumerate() {
            let options = PlanOptions { camera: Some(camera), ..Default::default() };
            let planned = scheme.plan(&set, &criterion, &options).unwrap();
            let name = format!("{cage} camera {c} silhouette vertices");
            assert_pattern_equals_cpu(&name, &set, &mut gpu, &planned.plan, &planned.pattern);
        }
        let planned = scheme.plan(&set, &Criterion::Factor(4.6), &PlanOptions::default()).unwrap();
        assert_pattern_equals_cpu(
            &format!("{cage} factor 4.6"),
            &set,
            &mut gpu,
            &planned.plan,
            &planned.pattern,
        );
    }
}

/// What the GPU does not draw for SD-2 is refused by name, never drawn wrong: a plan with
/// three different factors on a triangle (which the CPU pattern draws as a transition
/// fallback), and a warped plan with a depth that is not positive.
#[test]
fn sd2_plans_the_gpu_cannot_draw_are_refused() {
    let set = load("meshes/blob.obj");
    let mut gpu = tessellator(&set);
    let ctx = ctx();
    let camera = cameras(&set, 1, 5)[0];
    let options = PlanOptions { camera: Some(camera), ..Default::default() };
    let mut warped = Scheme::Sd2 { warp: true }.plan(&set, &Criterion::Factor(3.0), &options).unwrap();
    warped.plan.depths[7][1] = 0.0;
    let e = gpu.prepare(ctx, &set, &warped.plan, &warped.pattern).unwrap_err().to_string();
    assert!(e.contains("edge 7") && e.contains("depths"), "{e}");
    let mut plan = Scheme::Sd2 { warp: false }.plan(&set, &Criterion::Factor(3.0), &options).unwrap().plan;
    let edges = set.topology.patch_edges[0];
    for (l, f) in [(1, 4.5f32), (2, 5.5)] {
        let e = edges[l].edge as usize;
        plan.factors[e] = f;
        plan.segments[e] = tessera::sampling::symmetric_segments(f as f64);
    }
    let e = gpu.prepare(ctx, &set, &plan, &tessera::pattern::sd2::Sd2::default()).unwrap_err().to_string();
    assert!(e.contains("three different factors"), "{e}");
}

/// SD-2 planned on the GPU from the camera alone ([`sd2_frame_from_the_camera`]) with paper
/// 001's level functions (the distance's linear and quadratic mappings, the vertex
/// silhouettes), a fixed factor, and the reverse projection with the first, on three meshes
/// and three cameras each.
#[test]
fn sd2_planned_on_the_gpu_equals_the_cpu_plan() {
    let criteria = [
        Criterion::View { criterion: ViewCriterion::Distance(Mapping::Linear), fmin: 1.0, fmax: 9.5 },
        Criterion::View { criterion: ViewCriterion::Distance(Mapping::Quadratic), fmin: 2.0, fmax: 7.25 },
        Criterion::View { criterion: ViewCriterion::SilhouetteVertices, fmin: 1.5, fmax: 12.0 },
        Criterion::Factor(3.3),
    ];
    let mut counts = SweepCounts::default();
    for model in ["meshes/blob.obj", "meshes/spool.obj", "awkward/teapot_tri_nonmanifold.obj"] {
        let set = load(model);
        let prepared = tessera::scheme::Prepared::new(&set, true);
        let mut gpu = tessellator(&set);
        for (c, camera) in cameras(&set, 3, 61).into_iter().enumerate() {
            let plain = criteria.iter().map(|&c| (false, c));
            for (k, (warp, criterion)) in plain.chain([(true, criteria[0])]).enumerate() {
                let name = format!("{model} camera {c} criterion {k}");
                let max_factor = PlanOptions::default().max_factor;
                let frame = Sd2Frame { warp, criterion, max_factor };
                sd2_frame_from_the_camera(&name, &set, &prepared, &mut gpu, &camera, frame, &mut counts);
            }
        }
    }
    eprintln!("sd2 from the camera: {counts:?}");
    assert!(counts.culled > 0, "nothing culled");
    assert!(100 * counts.factor_ties <= counts.frames, "{counts:?}");
}

/// ESC (paper 002) drawn on the GPU from the CPU's plan and insertion grids equals the CPU
/// engine index for index on every patch model: fixed levels 0–6 (6 is `MAX_LEVEL`, the
/// largest lattice the shader holds) with the three kinds of threshold, and levels per object
/// from three cameras. The teapots' lids and bottoms have collapsed curves, whose coarse
/// triangles ESC fills and whose degenerate triangles the engine leaves out.
#[test]
fn esc_equals_the_cpu_engine_on_every_patch_model() {
    use tessera::criterion::esc::Threshold;
    let scheme = Scheme::Esc { max_level: 3 };
    let mut virtual_vertices = 0;
    for model in patch_models() {
        let set = load(&model);
        let mut gpu = tessellator(&set);
        let d = diagonal(&set);
        let fixed = [
            (0, Threshold::High),
            (1, Threshold::Medium),
            (2, Threshold::Absolute(0.0)),
            (3, Threshold::High),
            (4, Threshold::Absolute(2e-3 * d)),
            (6, Threshold::Medium),
        ];
        let mut cases: Vec<(Option<u32>, Threshold, Option<tessera::camera::Camera>)> =
            fixed.into_iter().map(|(l, t)| (Some(l), t, None)).collect();
        cases.extend(cameras(&set, 3, 17).into_iter().map(|c| (None, Threshold::Medium, Some(c))));
        for (level, threshold, camera) in cases {
            let name =
                format!("{model}, level {level:?}, threshold {threshold:?}, camera {}", camera.is_some());
            let options = PlanOptions { camera, ..Default::default() };
            let planned = scheme.plan(&set, &Criterion::Esc { threshold, level }, &options).unwrap();
            // A plan whose patterns are all complete would not test the virtual vertices.
            let full: u64 = planned.plan.interior.iter().map(|&[s, _]| 2 * s as u64 * s as u64).sum();
            let drawn = tessera::engine::tessellate(&set, &planned.plan, &planned.pattern, Default::default())
                .unwrap()
                .triangle_count() as u64;
            virtual_vertices += u32::from(drawn < full);
            assert_pattern_equals_cpu(&name, &set, &mut gpu, &planned.plan, &planned.pattern);
        }
    }
    assert!(virtual_vertices >= 10, "only {virtual_vertices} frames left candidates out");
}

/// What the GPU does not draw for ESC is refused by name, never drawn wrong: a plan with
/// another pattern, an ESC pattern whose grid disagrees with the plan's edge samples, and a
/// plan of the wrong sampling kind.
#[test]
fn esc_plans_the_gpu_cannot_draw_are_refused() {
    use tessera::criterion::esc::Threshold;
    let set = load("patches/teacup.patches");
    let mut gpu = tessellator(&set);
    let ctx = ctx();
    let criterion = Criterion::Esc { threshold: Threshold::Medium, level: Some(2) };
    let planned = Scheme::Esc { max_level: 3 }.plan(&set, &criterion, &PlanOptions::default()).unwrap();
    let e = gpu.prepare(ctx, &set, &planned.plan, &SemiUniform).unwrap_err().to_string();
    assert!(e.contains("Lattice"), "{e}");
    // Drop one inserted candidate from an edge's samples: the grid still has it.
    let mut plan = planned.plan.clone();
    let e0 = (0..plan.segments.len()).find(|&e| plan.segments[e] > 3).expect("an edge with a candidate");
    let start = plan.lattice_offsets[e0] as usize;
    let dropped = (1..plan.segments[e0] as usize).find(|&k| plan.lattice[start + k] % 3 != 0).unwrap();
    plan.lattice.remove(start + dropped);
    plan.segments[e0] -= 1;
    for offset in &mut plan.lattice_offsets[e0 + 1..] {
        *offset -= 1;
    }
    let e = gpu.prepare(ctx, &set, &plan, &planned.pattern).unwrap_err().to_string();
    assert!(e.contains("disagree"), "{e}");
    let uniform = Plan::uniform(&set, 6).unwrap();
    let e = gpu.prepare(ctx, &set, &uniform, &planned.pattern).unwrap_err().to_string();
    assert!(e.contains("Uniform samplings"), "{e}");
}

/// ESC planned on the GPU from the camera alone (`esc_plan.wgsl`: each object's level, the
/// distance test on every candidate, the candidates forced at collapsed curves, the grids)
/// equals the CPU's plan on every patch model — the levels exactly, every patch's grid up to
/// f32 ties of the distance test (a patch whose grid differs must have a candidate within
/// 1e-5 of the diagonal of its threshold) — and the frame equals the CPU engine's on the
/// GPU's own plan and grids, index for index.
#[test]
fn esc_planned_on_the_gpu_equals_the_cpu_plan() {
    use tessera::criterion::esc::Threshold;
    let (mut frames, mut differing) = (0, 0);
    for model in patch_models() {
        let set = load(&model);
        let prepared = tessera::scheme::Prepared::new(&set, true);
        let mut gpu = tessellator(&set);
        let d = diagonal(&set);
        let by_camera = |threshold| Criterion::Esc { threshold, level: None };
        let near = cameras(&set, 4, 23);
        // The level rule needs eyes past the objects' near distance (12 diagonals): the
        // second and third cameras again, 18 and 30 diagonals from the target.
        let far = |c: tessera::camera::Camera, diagonals: f64| tessera::camera::Camera {
            eye: c.target + (c.eye - c.target).normalize() * diagonals * d,
            far: c.far.max(2.0 * diagonals * d),
            ..c
        };
        let cases = [
            (near[0], by_camera(Threshold::Medium)),
            (near[1], by_camera(Threshold::High)),
            (far(near[1], 18.0), by_camera(Threshold::Medium)),
            (far(near[2], 30.0), by_camera(Threshold::High)),
            (near[2], Criterion::Esc { threshold: Threshold::Absolute(2e-3 * d), level: Some(2) }),
            (near[3], Criterion::Esc { threshold: Threshold::Medium, level: Some(6) }),
        ];
        let mut levels = std::collections::BTreeSet::new();
        for (c, (camera, criterion)) in cases.into_iter().enumerate() {
            let name = format!("{model} camera {c} {criterion:?}");
            let plan = esc_frame_from_the_camera(
                &name,
                &set,
                &prepared,
                &mut gpu,
                &camera,
                criterion,
                &mut differing,
            );
            levels.extend(plan.interior.iter().map(|l| l[0]));
            frames += 1;
        }
        eprintln!("{model}: levels {levels:?}");
        assert!(levels.len() >= 4, "{model}: levels {levels:?}, too few to test the level rule");
    }
    eprintln!("{differing} patches differ in {frames} frames");
    assert!(differing <= frames, "{differing} patches differ in {frames} frames");
}

/// The GPU's strips (`strips.wgsl`) equal the CPU engine's `Mesh::strips` entry for entry,
/// and decode to the GPU's own triangle list: SD-2 (from CPU plans, with the warp, and from
/// the camera) and ESC (from a CPU plan and from the camera), on models with collapsed
/// curves (the teapot's lid and bottom, the spool) whose degenerate strip triangles decode
/// to nothing. The strips start with one entry of room, overflow, grow and are redrawn.
#[test]
fn strips_written_on_the_gpu_equal_the_cpu_engines() {
    use tessera::criterion::esc::Threshold;
    use tessera::engine::EngineOptions;
    let ctx = ctx();
    let check = |name: &str,
                 set: &SurfaceSet,
                 gpu: &mut tessera_gpu::GpuTessellator,
                 plan: &Plan,
                 pattern: &dyn tessera::pattern::Pattern| {
        gpu.set_strips(ctx, Some(1)).unwrap();
        let grown = record_until_complete(gpu, name);
        assert!(grown >= 1, "{name}: one entry of room and no overflow");
        let got = gpu.read_mesh(ctx, set).unwrap();
        let options = EngineOptions { strips: true, ..EngineOptions::default() };
        let want = tessera::engine::tessellate(set, plan, pattern, options).unwrap();
        let (g, w) = (got.strips.as_ref().unwrap(), want.strips.as_ref().unwrap());
        assert!(!w.is_empty(), "{name}: no strips");
        if let Some(i) = (0..g.len().min(w.len())).find(|&i| g[i] != w[i]) {
            panic!(
                "{name}: strip entry {i} is {}, the CPU's {} ({} and {} entries)",
                g[i],
                w[i],
                g.len(),
                w.len()
            );
        }
        assert_eq!(g.len(), w.len(), "{name}: strip entries");
        let decoded: Vec<[u32; 3]> = tessera::mesh::strips::decode(g);
        let list: Vec<[u32; 3]> = (0..got.triangle_count()).map(|t| got.triangle(t)).collect();
        assert_eq!(decoded, list, "{name}: the strips decode to the triangle list");
        gpu.set_strips(ctx, None).unwrap();
    };
    for model in ["meshes/spool.obj", "meshes/blob.obj"] {
        let set = load(model);
        let mut gpu = tessellator(&set);
        let camera = cameras(&set, 1, 7)[0];
        for warp in [false, true] {
            let scheme = Scheme::Sd2 { warp };
            let criterion =
                Criterion::View { criterion: ViewCriterion::Distance(Mapping::Linear), fmin: 1.0, fmax: 6.5 };
            let options = PlanOptions { camera: Some(camera), ..Default::default() };
            let planned = scheme.plan(&set, &criterion, &options).unwrap();
            gpu.prepare(ctx, &set, &planned.plan, &planned.pattern).unwrap();
            check(&format!("{model} sd2 warp {warp}"), &set, &mut gpu, &planned.plan, &planned.pattern);
        }
        let prepared = tessera::scheme::Prepared::new(&set, true);
        let criterion =
            Criterion::View { criterion: ViewCriterion::SilhouetteVertices, fmin: 1.5, fmax: 7.0 };
        let screen = ScreenCriterion::new(Scheme::Sd2 { warp: false }, criterion, 8);
        gpu.prepare_screen(ctx, &set, &prepared, &camera, screen).unwrap();
        record_frame(&gpu);
        let plan = gpu.read_plan(ctx).unwrap();
        check(
            &format!("{model} sd2 from the camera"),
            &set,
            &mut gpu,
            &plan,
            &tessera::pattern::sd2::Sd2::default(),
        );
    }
    for model in ["patches/teapot.patches", "patches/teacup.patches"] {
        let set = load(model);
        let mut gpu = tessellator(&set);
        let camera = cameras(&set, 1, 9)[0];
        let criterion = Criterion::Esc { threshold: Threshold::Medium, level: None };
        let scheme = Scheme::Esc { max_level: 4 };
        let options = PlanOptions { camera: Some(camera), ..Default::default() };
        let planned = scheme.plan(&set, &criterion, &options).unwrap();
        gpu.prepare(ctx, &set, &planned.plan, &planned.pattern).unwrap();
        check(&format!("{model} esc"), &set, &mut gpu, &planned.plan, &planned.pattern);
        let prepared = tessera::scheme::Prepared::new(&set, true);
        let screen = ScreenCriterion::new(scheme, criterion, 64);
        gpu.prepare_screen(ctx, &set, &prepared, &camera, screen).unwrap();
        record_frame(&gpu);
        let plan = gpu.read_plan(ctx).unwrap();
        let esc = gpu.read_esc_pattern(ctx).unwrap();
        check(&format!("{model} esc from the camera"), &set, &mut gpu, &plan, &esc);
    }
}
