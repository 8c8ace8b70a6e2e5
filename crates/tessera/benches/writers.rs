//! Writers and the watertight check on the uniform factor-16 torus (torus_64x32, 1,048,576
//! triangles, 526,336 vertices): OBJ, PLY, STL and GLB into memory (a `Vec` reused between
//! iterations, so only formatting and copying are measured) and to a file on tmpfs
//! (`/dev/shm`, skipped where it does not exist), and [`verify::watertight`].
//!
//! Every figure is measured once in a 1-thread and once in a 2-thread rayon pool in the same
//! run (`threads_1/...`, `threads_2/...`), so the scaling is read off one report; criterion
//! reports the writers' throughput in bytes/s of output and the check's in triangles/s.
//!
//! `TESSERA_BENCH_LARGE=1` adds the check on the factor-54 torus (11,943,936 triangles), the
//! size where `tessera mesh --stats` used to spend seconds on it.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use std::path::{Path, PathBuf};
use std::time::Duration;
use tessera::criterion::Plan;
use tessera::engine::{tessellate, EngineOptions};
use tessera::mesh::Mesh;
use tessera::pattern::uniform::Uniform;
use tessera::surface::SurfaceSet;
use tessera::verify;

fn data_dir() -> PathBuf {
    std::env::var("TESSERA_DATA")
        .map(PathBuf::from)
        .unwrap_or_else(|_| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data"))
}

fn torus(factor: u32) -> Mesh {
    let path = data_dir().join("bench/torus_64x32.patches");
    let file = tessera::io::patches::read_patches(&path).expect("benchmark model");
    let set = SurfaceSet::from_patch_file(&file, Default::default());
    let plan = Plan::uniform(&set, factor).unwrap();
    tessellate(&set, &plan, &Uniform, EngineOptions::default()).unwrap()
}

type Writer = fn(&Mesh, &mut Vec<u8>) -> tessera::Result<()>;

const WRITERS: [(&str, Writer); 4] = [
    ("obj", |m, w| tessera::io::obj::write_obj(m, w)),
    ("ply", |m, w| tessera::io::ply::write_ply(m, w)),
    ("stl", |m, w| tessera::io::stl::write_stl(m, w)),
    ("glb", |m, w| tessera::io::glb::write_glb(m, w)),
];

fn pools() -> Vec<(usize, rayon::ThreadPool)> {
    [1, 2].map(|n| (n, rayon::ThreadPoolBuilder::new().num_threads(n).build().unwrap())).into()
}

fn writers(c: &mut Criterion) {
    let mesh = torus(16);
    let shm = Path::new("/dev/shm");
    let mut group = c.benchmark_group("write");
    group.sample_size(10).warm_up_time(Duration::from_secs(1)).measurement_time(Duration::from_secs(4));
    for (threads, pool) in pools() {
        for (name, write) in WRITERS {
            let mut out = Vec::new();
            write(&mesh, &mut out).unwrap();
            group.throughput(Throughput::Bytes(out.len() as u64));
            group.bench_function(format!("threads_{threads}/{name}/vec"), |b| {
                b.iter(|| {
                    pool.install(|| {
                        out.clear();
                        write(&mesh, &mut out).unwrap();
                    })
                })
            });
            if shm.is_dir() {
                let path = shm.join(format!("tessera-bench-{}.{name}", std::process::id()));
                group.bench_function(format!("threads_{threads}/{name}/file"), |b| {
                    b.iter(|| pool.install(|| tessera::io::write_mesh(&mesh, &path).unwrap()))
                });
                let _ = std::fs::remove_file(&path);
            }
        }
    }
    group.finish();
}

fn watertight(c: &mut Criterion) {
    let mut group = c.benchmark_group("watertight");
    group.sample_size(10).warm_up_time(Duration::from_secs(1)).measurement_time(Duration::from_secs(4));
    let large = std::env::var_os("TESSERA_BENCH_LARGE").is_some_and(|v| v == "1");
    let factors: &[u32] = if large { &[16, 54] } else { &[16] };
    for &factor in factors {
        let mesh = torus(factor);
        group.throughput(Throughput::Elements(mesh.triangle_count() as u64));
        for (threads, pool) in pools() {
            group.bench_function(format!("threads_{threads}/torus_factor_{factor}"), |b| {
                b.iter(|| pool.install(|| verify::watertight(&mesh)))
            });
        }
    }
    group.finish();
}

criterion_group!(benches, writers, watertight);
criterion_main!(benches);
