//! The instanced semi-uniform draw (`tessera_render::instanced::InstancedDraw`) against the
//! CPU: its vertex shader's points equal `render_queues::draw` (the CPU form of the same
//! instanced draw), its non-degenerate triangles are as many as the compacted mesh's, and its
//! picture covers what the compacted mesh covers. Bicubic patches and PN triangles. Needs a
//! GPU adapter (lavapipe in CI).

mod common;

use common::{cameras, data};
use tessera::camera::Camera;
use tessera::engine::render_queues;
use tessera::pattern::semi_uniform::StaticPattern;
use tessera::scheme::{Criterion, PlanOptions, Scheme};
use tessera::surface::Domain;
use tessera_gpu::GpuContext;
use tessera_render::instanced::InstancedDraw;
use tessera_render::{gpu, RenderOptions};

/// Triangles whose three corners are distinct points (at a tolerance far below the mesh's
/// scale: snapped corners that meet are evaluated at the same domain point).
fn non_degenerate(positions: &[[f32; 3]], triangles: impl Iterator<Item = [usize; 3]>, eps: f32) -> usize {
    let far = |a: [f32; 3], b: [f32; 3]| (0..3).map(|i| (a[i] - b[i]).abs()).fold(0.0, f32::max) > eps;
    triangles
        .filter(|t| {
            let [a, b, c] = t.map(|i| positions[i]);
            far(a, b) && far(b, c) && far(c, a)
        })
        .count()
}

#[test]
fn instanced_draw_equals_the_cpu_instanced_form_and_the_compacted_mesh() {
    let ctx = GpuContext::new().unwrap_or_else(|e| panic!("{e}"));
    let max_level = 5;
    let scheme = Scheme::SemiUniform { max_level };
    for model in ["patches/teapot.patches", "patches/teacup.patches", "meshes/blob.obj", "meshes/spool.obj"] {
        let set = tessera::io::load(&data(model), tessera::io::LoadOptions::default()).unwrap();
        let (lo, hi) = set.bounds();
        let diagonal = lo.distance(hi) as f32;
        let draw = InstancedDraw::new(&ctx, &set, max_level, gpu::IMAGE_FORMAT, 1).unwrap();
        let domain = set.patches[0].domain();
        let patterns: [Vec<StaticPattern>; 2] =
            [StaticPattern::all(Domain::Tri, max_level), StaticPattern::all(Domain::Quad, max_level)];
        let renderer = gpu::Renderer::new(&ctx, gpu::IMAGE_FORMAT, 1).unwrap();
        for (k, pixel_error) in [(0, 2.0), (1, 0.7), (2, 0.35)] {
            let camera = Camera::framing(lo, hi, 256, 256);
            let options = PlanOptions { camera: Some(camera), cull: k == 1, ..Default::default() };
            let planned = scheme.plan(&set, &Criterion::PixelError(pixel_error), &options).unwrap();
            let cpu_queues = render_queues::build(&set, &planned.plan, max_level).unwrap();
            // The frame: queues, level arguments and the instanced draws, into 256² targets.
            let targets = gpu::Targets::new(&ctx, &renderer, 256, 256).unwrap();
            let (colour, resolve, depth) = targets.views();
            let look = RenderOptions { wireframe: false, color: tessera_render::ColorMode::Shaded };
            let mut encoder = ctx.device.create_command_encoder(&Default::default());
            draw.record(&ctx, &mut encoder, &planned.plan, &camera, &look, &colour, resolve.as_ref(), &depth)
                .unwrap();
            ctx.queue.submit([encoder.finish()]);
            let instanced_image = targets.read(&ctx).unwrap();
            let gpu_queues = draw.queues().read(&ctx).unwrap();
            assert_eq!(gpu_queues, cpu_queues, "{model}: queues");
            // The vertex shader's points, level by level, against the CPU's instanced draw.
            let mut points = Vec::new();
            for m in 0..=max_level {
                points.extend(draw.expand_level(&ctx, m, gpu_queues.level(m).len()).unwrap());
            }
            let reference = render_queues::draw(&set, &cpu_queues, &patterns);
            assert_eq!(points.len(), reference.positions.len(), "{model}: vertices");
            let worst = points
                .iter()
                .zip(&reference.positions)
                .map(|(a, b)| (0..3).map(|i| (a[i] - b[i]).abs()).fold(0.0, f32::max))
                .fold(0.0, f32::max);
            assert!(worst <= 1e-5 * diagonal, "{model}: points differ by {worst} (diagonal {diagonal})");
            // Non-degenerate triangles against the compacted mesh of the same plan.
            let mut triangles = Vec::new();
            let mut base = 0usize;
            for m in 0..=max_level {
                let p = &draw.patterns()[m as usize];
                for _ in 0..gpu_queues.level(m).len() {
                    triangles.extend(p.triangles.iter().map(|t| t.map(|i| base + i as usize)));
                    base += p.vertices.len();
                }
            }
            let drawn = non_degenerate(&points, triangles.into_iter(), 1e-6 * diagonal);
            let mesh = tessera::engine::tessellate(&set, &planned.plan, &planned.pattern, Default::default())
                .unwrap();
            assert_eq!(drawn, mesh.triangle_count(), "{model}: non-degenerate drawn triangles");
            // The picture covers what the compacted mesh covers.
            let buffers = gpu::MeshBuffers::upload(&ctx, &mesh, &[]).unwrap();
            let compacted = gpu::render(&ctx, &buffers.geometries(), &camera, &look, 1).unwrap();
            let (a, b) = (instanced_image.covered_pixels(), compacted.covered_pixels());
            eprintln!(
                "{model} ({domain:?}), {pixel_error} px: {} instances, {drawn} triangles, {a} vs {b} covered pixels",
                cpu_queues.entries.len()
            );
            assert!(b > 2000 && (a as f64 - b as f64).abs() <= 0.01 * b as f64, "{model}: {a} vs {b} pixels");
        }
    }
}

#[test]
fn instanced_triangles_equal_the_compacted_mesh_on_every_model_and_ten_cameras() {
    let ctx = GpuContext::new().unwrap_or_else(|e| panic!("{e}"));
    let max_level = 5;
    let scheme = Scheme::SemiUniform { max_level };
    let models = [
        "patches/teapot.patches",
        "patches/teacup.patches",
        "patches/teapot_teasetorig.patches",
        "bench/torus_64x32.patches",
        "meshes/blob.obj",
        "meshes/spool.obj",
        "meshes/bunny_res4.obj",
    ];
    let renderer = gpu::Renderer::new(&ctx, gpu::IMAGE_FORMAT, 1).unwrap();
    let targets = gpu::Targets::new(&ctx, &renderer, 64, 64).unwrap();
    let (colour, resolve, depth) = targets.views();
    let look = RenderOptions::default();
    for model in models {
        let set = tessera::io::load(&data(model), tessera::io::LoadOptions::default()).unwrap();
        let (lo, hi) = set.bounds();
        let eps = 1e-6 * lo.distance(hi) as f32;
        let draw = InstancedDraw::new(&ctx, &set, max_level, gpu::IMAGE_FORMAT, 1).unwrap();
        for (k, camera) in cameras(lo, hi).into_iter().enumerate() {
            let options = PlanOptions { camera: Some(camera), cull: k % 2 == 1, ..Default::default() };
            let planned = scheme.plan(&set, &Criterion::PixelError(1.0), &options).unwrap();
            let mut encoder = ctx.device.create_command_encoder(&Default::default());
            draw.record(&ctx, &mut encoder, &planned.plan, &camera, &look, &colour, resolve.as_ref(), &depth)
                .unwrap();
            ctx.queue.submit([encoder.finish()]);
            let queues = draw.queues().read(&ctx).unwrap();
            let mut drawn = 0;
            for m in 0..=max_level {
                let points = draw.expand_level(&ctx, m, queues.level(m).len()).unwrap();
                let p = &draw.patterns()[m as usize];
                let per = p.vertices.len();
                let triangles = (0..queues.level(m).len())
                    .flat_map(|i| p.triangles.iter().map(move |t| t.map(|v| i * per + v as usize)));
                drawn += non_degenerate(&points, triangles, eps);
            }
            let mesh = tessera::engine::tessellate(&set, &planned.plan, &planned.pattern, Default::default())
                .unwrap();
            assert_eq!(drawn, mesh.triangle_count(), "{model}, camera {k}: non-degenerate drawn triangles");
        }
    }
}
