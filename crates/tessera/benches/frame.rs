//! Whole real-time frames through the front door ([`Tessellator::frame`]: criterion,
//! resolve, layout, write into reused buffers), for the rows of the real-time table:
//!
//! - `torus_grid_92160/pixel_0.5`: 45 copies of the 2,048-patch torus in a grid
//!   ([`tessera::scene::patch_grid`]), seen whole at 1280×1024, transition scheme, half a
//!   pixel of guaranteed error, culling on;
//! - `killeroo_herd_91476/pixel_0.5`: 11 copies of the killeroo cage as PN triangles, the same
//!   criterion;
//! - `torus_64x32/uniform_16`: the one torus at uniform factor 16 (1,048,576 triangles);
//! - `torus_64x32/tolerance_0.001%`: the torus under a guaranteed object-space error of
//!   0.001 % of its diagonal (transition);
//! - `torus_64x32_rational/…`: the same two rows on the torus made rational (each control
//!   point's weight a function of its position, within [0.5, 2]:
//!   [`tessera::scene::position_weights`]), for the rational kernels beside the polynomial
//!   ones in the same run (the tolerance row has more triangles: a rational bound divides by
//!   the smallest weight);
//! - `cow/…`: the cow as PN triangles with paper 001's silhouette criteria (transition 4:7,
//!   semi-uniform 4:8) and the fractional-odd partitioning at factor 6.4;
//! - `{elephant_refined,bunny,armadillo}/pn_uniform_4`: PN triangles at uniform factor 4;
//! - Catmull-Clark cages (OpenSubdiv's Bfr defaults): `catmark_rook/uniform_8` (a cage with
//!   triangles, so sub-faces: Bfr's rate 16; creases isolate faces six levels deep, most
//!   leaves hold one point), `catmark_rook/pixel_0.5` (transition), and
//!   `catmark_cube_creases0/uniform_64` (few, shallow-enough leaves with many points each:
//!   the isolated faces' points grouped by leaf, `engine::tree_points`).
//!
//! The scenes are built in code from the shared models, not stored. Criterion reports
//! triangles per second; run with `RAYON_NUM_THREADS=1` and `=2` to compare thread counts.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use std::path::PathBuf;
use tessera::camera::Camera;
use tessera::pattern::hardware::Partitioning;
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
    let (lo, hi) = one.bounds();
    let tolerance = scheme::Criterion::Tolerance(1e-5 * lo.distance(hi));
    bench_frames(c, "torus_64x32/tolerance_0.001%", &one, Scheme::Transition, tolerance, false);
    drop(one);
    let rational = SurfaceSet::from_patch_file(&tessera::scene::position_weights(&torus), Default::default());
    let sixteen = scheme::Criterion::Factor(16.0);
    bench_frames(c, "torus_64x32_rational/uniform_16", &rational, Scheme::Uniform, sixteen, false);
    bench_frames(c, "torus_64x32_rational/tolerance_0.001%", &rational, Scheme::Transition, tolerance, false);
    drop(rational);

    let pn = |rel: &str| {
        let path = data_dir().join(rel);
        let mesh = tessera::io::obj::read_obj(&path).expect("benchmark model");
        SurfaceSet::pn_from_mesh(&mesh, &path, Default::default()).expect("benchmark model")
    };
    let cow = pn("meshes/cow.obj");
    let silhouette = |criterion, fmin, fmax| scheme::Criterion::View { criterion, fmin, fmax };
    // Each scheme's own silhouette criterion, as `tessera mesh --silhouette` picks it.
    let transition = Scheme::Transition;
    let vertices = silhouette(transition.default_silhouette(), 4.0, 7.0);
    bench_frames(c, "cow/transition_silhouette_4_7", &cow, transition, vertices, false);
    let semi_uniform = Scheme::SemiUniform { max_level: Scheme::DEFAULT_SEMI_UNIFORM_LEVEL };
    let semi = silhouette(semi_uniform.default_silhouette(), 4.0, 8.0);
    bench_frames(c, "cow/semi_uniform_silhouette_4_8", &cow, semi_uniform, semi, false);
    let odd = Scheme::Hardware(Partitioning::FractionalOdd);
    bench_frames(c, "cow/fractional_odd_6.4", &cow, odd, scheme::Criterion::Factor(6.4), false);
    drop(cow);
    for name in ["elephant_refined", "bunny", "armadillo"] {
        let set = pn(&format!("meshes/{name}.obj"));
        let four = scheme::Criterion::Factor(4.0);
        bench_frames(c, &format!("{name}/pn_uniform_4"), &set, Scheme::Uniform, four, false);
    }
    let cage = |rel: &str| {
        let path = data_dir().join(rel);
        let mesh = tessera::io::obj::read_obj(&path).expect("benchmark model");
        SurfaceSet::from_subdivision_cage(&mesh, &path, Default::default()).expect("benchmark model")
    };
    let rook = cage("subdivision/catmark_rook.obj");
    bench_frames(c, "catmark_rook/uniform_8", &rook, Scheme::Uniform, scheme::Criterion::Factor(8.0), false);
    bench_frames(c, "catmark_rook/pixel_0.5", &rook, Scheme::Transition, pixel, false);
    drop(rook);
    let cube = cage("subdivision/catmark_cube_creases0.obj");
    let sixty_four = scheme::Criterion::Factor(64.0);
    bench_frames(c, "catmark_cube_creases0/uniform_64", &cube, Scheme::Uniform, sixty_four, false);
}

criterion_group!(benches, frames);
criterion_main!(benches);
