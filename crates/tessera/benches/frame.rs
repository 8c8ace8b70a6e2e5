//! Whole real-time frames through the front door ([`Tessellator::frame`]: criterion,
//! resolve, layout, write into reused buffers), for the rows of the real-time table:
//!
//! - `torus_grid_92160/pixel_0.5`: 45 copies of the 2,048-patch torus in a grid
//!   ([`tessera::scene::patch_grid`]), seen whole at 1280×1024, transition scheme, half a
//!   pixel of guaranteed error, culling on;
//! - `killeroo_herd_91476/pixel_0.5`: 11 copies of the killeroo cage as PN triangles, the same
//!   criterion;
//! - `torus_64x32/uniform_16`: the one torus at uniform factor 16 (1,048,576 triangles).
//!
//! The scenes are built in code from the shared models, not stored. Criterion reports
//! triangles per second; run with `RAYON_NUM_THREADS=1` and `=2` to compare thread counts.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use std::path::PathBuf;
use tessera::camera::Camera;
use tessera::scheme::{self, PlanOptions, Scheme};
use tessera::surface::SurfaceSet;
use tessera::tessellator::{Tessellator, TessellatorOptions};

fn data_dir() -> PathBuf {
    std::env::var("TESSERA_DATA")
        .map(PathBuf::from)
        .unwrap_or_else(|_| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data"))
}

fn bench_frames(
    c: &mut Criterion,
    name: &str,
    set: &SurfaceSet,
    scheme: Scheme,
    criterion: scheme::Criterion,
    cull: bool,
) {
    let (lo, hi) = set.bounds();
    let camera = Camera::framing(lo, hi, 1280, 1024);
    let options = TessellatorOptions {
        plan: PlanOptions { cull, ..PlanOptions::default() },
        ..TessellatorOptions::default()
    };
    let mut tess = Tessellator::new(set, scheme, criterion, options).expect("benchmark tessellator");
    let triangles = tess.frame(Some(&camera)).expect("benchmark frame").triangle_count();
    let mut group = c.benchmark_group("frame");
    group.sample_size(20);
    group.throughput(Throughput::Elements(triangles as u64));
    group.bench_function(name, |b| b.iter(|| tess.frame(Some(&camera)).unwrap().triangle_count()));
    group.finish();
}

fn frames(c: &mut Criterion) {
    let torus = tessera::io::patches::read_patches(&data_dir().join("bench/torus_64x32.patches"))
        .expect("benchmark model");
    let grid = SurfaceSet::from_patch_file(&tessera::scene::patch_grid(&torus, 45), Default::default());
    let pixel = scheme::Criterion::PixelError(0.5);
    bench_frames(c, "torus_grid_92160/pixel_0.5", &grid, Scheme::Transition, pixel, true);
    drop(grid);

    let path = data_dir().join("meshes/killeroo_cage.obj");
    let cage = tessera::io::obj::read_obj(&path).expect("benchmark model");
    let herd = SurfaceSet::pn_from_mesh(&tessera::scene::mesh_grid(&cage, 11), &path, Default::default())
        .expect("benchmark model");
    bench_frames(c, "killeroo_herd_91476/pixel_0.5", &herd, Scheme::Transition, pixel, true);
    drop(herd);

    let one = SurfaceSet::from_patch_file(&torus, Default::default());
    bench_frames(c, "torus_64x32/uniform_16", &one, Scheme::Uniform, scheme::Criterion::Factor(16.0), false);
}

criterion_group!(benches, frames);
criterion_main!(benches);
