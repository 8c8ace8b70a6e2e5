//! A per-frame loop allocates nothing once its buffers have grown: the same camera walk run
//! twice, the second time counted by a global allocator, for the error-bounded and the view
//! criteria with the integer, transition, semi-uniform and hardware schemes (SD-2 and ESC
//! still build a pattern object per frame), on the teapot and on the teapot made rational. Runs without the test harness
//! (`harness = false`) so that nothing else allocates while it counts, and in a one-thread
//! rayon pool so that which thread builds which pattern, and so which thread's buffers grow,
//! is the same in both walks.

use tessera::camera::Camera;
use tessera::criterion::view::{Mapping, ViewCriterion};
use tessera::pattern::hardware::Partitioning;
use tessera::scheme::{Criterion, PlanOptions, Scheme};
use tessera::surface::SurfaceSet;
use tessera::tessellator::{Tessellator, TessellatorOptions};

#[path = "../examples/common/counting.rs"]
mod counting;
use counting::{allocations, Counting};

#[global_allocator]
static GLOBAL: Counting = Counting;

/// The patch model at `relative`; `rational`: with weights a function of position
/// ([`tessera::scene::position_weights`]), for the rational kernels.
fn load(relative: &str, rational: bool) -> SurfaceSet {
    let data = std::env::var("TESSERA_DATA").map(std::path::PathBuf::from).unwrap_or_else(|_| {
        std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data")
    });
    let path = data.join(relative);
    let file = tessera::io::patches::read_patches(&path)
        .unwrap_or_else(|e| panic!("test model {}: {e} (set TESSERA_DATA)", path.display()));
    let file = if rational { tessera::scene::position_weights(&file) } else { file };
    SurfaceSet::from_patch_file(&file, Default::default())
}

/// Allocations of the second of two identical camera walks.
fn second_walk_allocations(set: &SurfaceSet, scheme: Scheme, criterion: Criterion, cull: bool) -> u64 {
    let options = TessellatorOptions {
        plan: PlanOptions { cull, ..PlanOptions::default() },
        ..TessellatorOptions::default()
    };
    let mut tess = Tessellator::new(set, scheme, criterion, options).expect("tessellator");
    let (lo, hi) = set.bounds();
    let (centre, radius) = ((lo + hi) * 0.5, lo.distance(hi) * 0.5);
    let mut counted = 0;
    let mut triangles = Vec::new();
    for walk in 0..2 {
        for frame in 0..16 {
            let a = frame as f64 / 16.0 * std::f64::consts::TAU;
            let mut camera = Camera::framing(lo, hi, 1280, 720);
            camera.eye = centre + glam::DVec3::new(a.cos(), 0.35, a.sin()) * radius * (4.0 + 2.0 * a.cos());
            let before = allocations();
            let mesh = tess.frame(Some(&camera)).expect("frame");
            if walk == 0 {
                triangles.push(mesh.triangle_count());
            } else {
                assert_eq!(mesh.triangle_count(), triangles[frame], "{scheme:?}: the walks differ");
                counted += allocations() - before;
            }
        }
    }
    // The frames really differ, so buffers were reused across different sizes.
    assert!(triangles.iter().min() < triangles.iter().max(), "{scheme:?}: every frame the same size");
    counted
}

fn view(criterion: ViewCriterion, fmin: f64, fmax: f64) -> Criterion {
    Criterion::View { criterion, fmin, fmax }
}

fn main() {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().expect("rayon pool");
    let teapots = [("teapot", false), ("teapot rational", true)]
        .map(|(name, r)| (name, load("patches/teapot.patches", r)));
    let cases = [
        (Scheme::Transition, Criterion::PixelError(1.0), false),
        (Scheme::Transition, Criterion::PixelError(0.5), true),
        (Scheme::SemiUniform { max_level: 6 }, Criterion::PixelError(1.0), true),
        (Scheme::Uniform, Criterion::PixelError(2.0), true),
        (Scheme::Transition, view(ViewCriterion::Silhouetteness, 1.0, 12.0), true),
        (Scheme::SemiUniform { max_level: 5 }, view(ViewCriterion::Silhouetteness, 1.0, 16.0), false),
        (Scheme::Transition, view(ViewCriterion::Distance(Mapping::Linear), 2.0, 10.0), true),
        (Scheme::Transition, view(ViewCriterion::SilhouetteVertices, 2.0, 9.0), false),
        (
            Scheme::Hardware(Partitioning::FractionalOdd),
            view(ViewCriterion::Distance(Mapping::Linear), 1.5, 9.5),
            true,
        ),
        (Scheme::Hardware(Partitioning::Integer), view(ViewCriterion::Silhouetteness, 1.0, 12.0), false),
    ];
    let mut failed = false;
    for (name, teapot) in &teapots {
        for (scheme, criterion, cull) in cases {
            let n = pool.install(|| second_walk_allocations(teapot, scheme, criterion, cull));
            println!("{name} {scheme:?} {criterion:?} cull {cull}: {n} allocations in the second walk");
            failed |= n != 0;
        }
    }
    assert!(!failed, "a per-frame loop allocated after its buffers had grown (see above)");
    println!("test allocations ... ok");
}
