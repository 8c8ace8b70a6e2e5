//! Every view-dependent scheme on the same inputs, so their costs can be compared in one run:
//! the cow (5,804 PN triangles) with the silhouette criterion of paper 001 (`f_max = 7`) or a
//! real factor, and the teapot (32 bicubic patches) with ESC. Each benchmark measures the
//! criterion (plan) and the engine separately. Criterion reports triangles per second.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use std::path::PathBuf;
use tessera::camera::Camera;
use tessera::criterion::esc::{self, EscOptions, Threshold};
use tessera::criterion::sd2::{self, LevelFunction, Sd2Options};
use tessera::criterion::tolerance::Layout;
use tessera::criterion::view::{self, FractionalFactors, ViewCriterion};
use tessera::criterion::Plan;
use tessera::engine::{tessellate, TessellateOptions};
use tessera::pattern::hardware::{Hardware, Partitioning};
use tessera::pattern::semi_uniform::SemiUniform;
use tessera::pattern::transition::Transition;
use tessera::pattern::Pattern;
use tessera::sampling::Spacing;
use tessera::surface::SurfaceSet;

fn data_dir() -> PathBuf {
    std::env::var("TESSERA_DATA")
        .map(PathBuf::from)
        .unwrap_or_else(|_| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data"))
}

fn load(rel: &str) -> SurfaceSet {
    let path = data_dir().join(rel);
    if path.extension().is_some_and(|e| e == "obj") {
        let mesh = tessera::io::obj::read_obj(&path).expect("benchmark model");
        SurfaceSet::pn_from_mesh(&mesh, &path, Default::default()).expect("benchmark model")
    } else {
        let file = tessera::io::patches::read_patches(&path).expect("benchmark model");
        SurfaceSet::from_patch_file(&file, Default::default())
    }
}

fn bench_engine(
    c: &mut Criterion,
    group: &str,
    name: &str,
    set: &SurfaceSet,
    plan: &Plan,
    pattern: &dyn Pattern,
) {
    let triangles = tessellate(set, plan, pattern, TessellateOptions::default()).unwrap().triangle_count();
    let mut g = c.benchmark_group(group);
    g.sample_size(20);
    g.throughput(Throughput::Elements(triangles as u64));
    g.bench_function(format!("{name}/engine"), |b| {
        b.iter(|| tessellate(set, plan, pattern, TessellateOptions::default()).unwrap())
    });
    g.finish();
}

fn schemes(c: &mut Criterion) {
    let cow = load("meshes/cow.obj");
    let (lo, hi) = cow.bounds();
    let camera = Camera::framing(lo, hi, 1280, 720);
    let silhouette = ViewCriterion::SilhouetteVertices;

    let plan = view::plan(&cow, &camera, silhouette, 4, 7, Layout::Transition, false);
    bench_engine(c, "cow_silhouette_4_7", "transition", &cow, &plan, &Transition);
    let plan = view::plan(&cow, &camera, ViewCriterion::Silhouetteness, 1, 8, Layout::Dyadic, false);
    bench_engine(c, "cow_silhouette_1_8", "semi_uniform_m3", &cow, &plan, &SemiUniform);

    let options =
        Sd2Options { level: LevelFunction::Silhouette, fmin: 4.0, fmax: 7.0, warp: false, cull: false };
    c.bench_function("cow_silhouette_4_7/sd2/plan", |b| {
        b.iter(|| sd2::plan(&cow, &camera, &options).unwrap())
    });
    let (plan, pattern) = sd2::plan(&cow, &camera, &options).unwrap();
    bench_engine(c, "cow_silhouette_4_7", "sd2", &cow, &plan, &pattern);

    let factors = FractionalFactors::Fixed(6.4);
    for partitioning in [Partitioning::Integer, Partitioning::FractionalOdd, Partitioning::FractionalEven] {
        let plan = view::fractional_plan(&cow, &camera, factors, Spacing::Hardware(partitioning), false);
        bench_engine(c, "cow_factor_6_4", partitioning.name(), &cow, &plan, &Hardware { partitioning });
    }

    let teapot = load("patches/teapot.patches");
    let (lo, hi) = teapot.bounds();
    let camera = Camera::framing(lo, hi, 1280, 720);
    for (name, threshold) in [("high", Threshold::High), ("medium", Threshold::Medium)] {
        let options = EscOptions { threshold, ..Default::default() };
        c.bench_function(&format!("teapot_esc/{name}/plan"), |b| {
            b.iter(|| esc::plan(&teapot, &camera, &options).unwrap())
        });
        let (plan, pattern) = esc::plan(&teapot, &camera, &options).unwrap();
        bench_engine(c, "teapot_esc", name, &teapot, &plan, &pattern);
    }
}

criterion_group!(benches, schemes);
criterion_main!(benches);
