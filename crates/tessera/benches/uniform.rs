//! Uniform factor 16 on the 64×32 bicubic torus (1,048,576 triangles). Criterion reports
//! the throughput in triangles per second (elements/s).
//!
//! `reuse`: one output mesh for every iteration ([`tessellate_into`]), the steady state of an
//! application that re-tessellates; `fresh`: a new mesh each time ([`tessellate`]), which also
//! pays for faulting in new memory.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use std::path::PathBuf;
use tessera::criterion::Plan;
use tessera::engine::{tessellate, tessellate_into, EngineOptions};
use tessera::mesh::Mesh;
use tessera::pattern::uniform::Uniform;
use tessera::surface::SurfaceSet;

fn data_dir() -> PathBuf {
    std::env::var("TESSERA_DATA")
        .map(PathBuf::from)
        .unwrap_or_else(|_| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data"))
}

fn uniform_torus(c: &mut Criterion) {
    let path = data_dir().join("bench/torus_64x32.patches");
    let file = tessera::io::patches::read_patches(&path).expect("benchmark model");
    let set = SurfaceSet::from_patch_file(&file, Default::default());
    let mut group = c.benchmark_group("uniform");
    group.sample_size(20);
    for n in [4u32, 16] {
        let plan = Plan::uniform(&set, n).unwrap();
        let triangles = 2 * (n * n) as u64 * set.patches.len() as u64;
        group.throughput(Throughput::Elements(triangles));
        let mut mesh = Mesh::default();
        group.bench_function(format!("torus_64x32/factor_{n}/reuse"), |b| {
            b.iter(|| tessellate_into(&set, &plan, &Uniform, EngineOptions::default(), &mut mesh).unwrap())
        });
        group.bench_function(format!("torus_64x32/factor_{n}/fresh"), |b| {
            b.iter(|| tessellate(&set, &plan, &Uniform, EngineOptions::default()).unwrap())
        });
    }
    group.finish();
}

criterion_group!(benches, uniform_torus);
criterion_main!(benches);
