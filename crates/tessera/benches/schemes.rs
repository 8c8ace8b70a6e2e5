//! Every view-dependent scheme on the same inputs, so their costs can be compared in one run:
//! the cow (5,804 PN triangles) with the silhouette criterion of paper 001 (`f_max = 7`) or a
//! real factor, and the teapot (32 bicubic patches) with ESC. Each benchmark measures the
//! criterion (plan) and the engine separately. Criterion reports triangles per second.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use std::path::PathBuf;
use tessera::camera::Camera;
use tessera::criterion::esc::Threshold;
use tessera::criterion::view::ViewCriterion;
use tessera::criterion::Plan;
use tessera::engine::{tessellate, EngineOptions};
use tessera::pattern::hardware::Partitioning;
use tessera::pattern::Pattern;
use tessera::scheme::{self, PlanOptions, Scheme, SchemePlan};
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
    let triangles = tessellate(set, plan, pattern, EngineOptions::default()).unwrap().triangle_count();
    let mut g = c.benchmark_group(group);
    g.sample_size(20);
    g.throughput(Throughput::Elements(triangles as u64));
    g.bench_function(format!("{name}/engine"), |b| {
        b.iter(|| tessellate(set, plan, pattern, EngineOptions::default()).unwrap())
    });
    g.finish();
}

fn schemes(c: &mut Criterion) {
    let cow = load("meshes/cow.obj");
    let (lo, hi) = cow.bounds();
    let camera = Camera::framing(lo, hi, 1280, 720);
    let options = PlanOptions { camera: Some(camera), ..PlanOptions::default() };
    let plan = |set: &SurfaceSet, scheme: Scheme, criterion: scheme::Criterion| -> SchemePlan {
        scheme.plan(set, &criterion, &options).unwrap()
    };
    let silhouette = |criterion, fmin, fmax| scheme::Criterion::View { criterion, fmin, fmax };
    let vertices = silhouette(ViewCriterion::SilhouetteVertices, 4.0, 7.0);

    let p = plan(&cow, Scheme::Transition, vertices);
    bench_engine(c, "cow_silhouette_4_7", "transition", &cow, &p.plan, &p.pattern);
    let p =
        plan(&cow, Scheme::SemiUniform { max_level: 3 }, silhouette(ViewCriterion::Silhouetteness, 1.0, 8.0));
    bench_engine(c, "cow_silhouette_1_8", "semi_uniform_m3", &cow, &p.plan, &p.pattern);

    let sd2 = Scheme::Sd2 { warp: false };
    c.bench_function("cow_silhouette_4_7/sd2/plan", |b| b.iter(|| plan(&cow, sd2, vertices)));
    let p = plan(&cow, sd2, vertices);
    bench_engine(c, "cow_silhouette_4_7", "sd2", &cow, &p.plan, &p.pattern);

    for partitioning in [Partitioning::Integer, Partitioning::FractionalOdd, Partitioning::FractionalEven] {
        let p = plan(&cow, Scheme::Hardware(partitioning), scheme::Criterion::Factor(6.4));
        bench_engine(c, "cow_factor_6_4", partitioning.name(), &cow, &p.plan, &p.pattern);
    }

    let teapot = load("patches/teapot.patches");
    let (lo, hi) = teapot.bounds();
    let options = PlanOptions { camera: Some(Camera::framing(lo, hi, 1280, 720)), ..PlanOptions::default() };
    let esc = Scheme::Esc { max_level: Scheme::DEFAULT_ESC_LEVEL };
    for (name, threshold) in [("high", Threshold::High), ("medium", Threshold::Medium)] {
        let criterion = scheme::Criterion::Esc { threshold, level: None };
        c.bench_function(&format!("teapot_esc/{name}/plan"), |b| {
            b.iter(|| esc.plan(&teapot, &criterion, &options).unwrap())
        });
        let p = esc.plan(&teapot, &criterion, &options).unwrap();
        bench_engine(c, "teapot_esc", name, &teapot, &p.plan, &p.pattern);
    }
}

criterion_group!(benches, schemes);
criterion_main!(benches);
