//! The render queues built on the GPU (`tessera_render::instanced`) equal the CPU's
//! (`tessera::engine::render_queues::build`) on every patch model and three meshes, ten
//! cameras each (half of them culling). Needs a GPU adapter (lavapipe in CI); without one it
//! fails naming the packages.

mod common;

use common::{cameras, data};
use tessera::engine::render_queues;
use tessera::scheme::{Criterion, PlanOptions, Scheme};
use tessera_gpu::GpuContext;
use tessera_render::instanced::GpuRenderQueues;

#[test]
fn gpu_render_queues_equal_the_cpu_queues() {
    let ctx = GpuContext::new().unwrap_or_else(|e| panic!("{e}"));
    let models = [
        "patches/teapot.patches",
        "patches/teacup.patches",
        "patches/teapot_teasetorig.patches",
        "bench/torus_64x32.patches",
        "meshes/blob.obj",
        "meshes/spool.obj",
        "meshes/bunny_res4.obj",
    ];
    let max_level = 5;
    let scheme = Scheme::SemiUniform { max_level };
    for model in models {
        let set = tessera::io::load(&data(model), tessera::io::LoadOptions::default()).unwrap();
        let queues = GpuRenderQueues::new(&ctx, &set, max_level).unwrap();
        let (lo, hi) = set.bounds();
        let mut levels_seen = [false; 6];
        let mut culled_seen = false;
        for (k, camera) in cameras(lo, hi).into_iter().enumerate() {
            let options = PlanOptions { camera: Some(camera), cull: k % 2 == 1, ..Default::default() };
            let planned = scheme.plan(&set, &Criterion::PixelError(1.0), &options).unwrap();
            let cpu = render_queues::build(&set, &planned.plan, max_level).unwrap();
            let mut encoder = ctx.device.create_command_encoder(&Default::default());
            queues.record(&ctx, &mut encoder, &planned.plan).unwrap();
            ctx.queue.submit([encoder.finish()]);
            let gpu = queues.read(&ctx).unwrap();
            assert_eq!(gpu.offsets, cpu.offsets, "{model}, camera {k}: level ranges");
            assert_eq!(gpu.entries, cpu.entries, "{model}, camera {k}: entries");
            for m in 0..=max_level {
                levels_seen[m as usize] |= !cpu.level(m).is_empty();
            }
            culled_seen |= cpu.entries.len() < set.patches.len();
        }
        // The cameras exercise several levels and culling, or the comparison proves little.
        assert!(levels_seen.iter().filter(|&&s| s).count() >= 2, "{model}: levels {levels_seen:?}");
        assert!(culled_seen, "{model}: no camera culled a patch");
    }
}

#[test]
fn a_plan_that_is_not_dyadic_is_refused() {
    let ctx = GpuContext::new().unwrap_or_else(|e| panic!("{e}"));
    let set =
        tessera::io::load(&data("patches/teapot.patches"), tessera::io::LoadOptions::default()).unwrap();
    let queues = GpuRenderQueues::new(&ctx, &set, 5).unwrap();
    let plan = tessera::criterion::Plan::uniform(&set, 3).unwrap();
    let mut encoder = ctx.device.create_command_encoder(&Default::default());
    queues.record(&ctx, &mut encoder, &plan).unwrap();
    ctx.queue.submit([encoder.finish()]);
    assert!(render_queues::build(&set, &plan, 5).is_err());
    assert!(queues.read(&ctx).is_err());
    assert!(GpuRenderQueues::new(&ctx, &set, 99).is_err());
}
