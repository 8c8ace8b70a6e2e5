//! The measured approximation error of uniform tessellation falls as O(1/n²).

mod common;

use tessera::criterion::Plan;
use tessera::engine::{tessellate, EngineOptions};
use tessera::pattern::uniform::Uniform;
use tessera::verify;

fn max_error(set: &tessera::surface::SurfaceSet, n: u32) -> f64 {
    let plan = Plan::uniform(set, n).unwrap();
    let mesh = tessellate(set, &plan, &Uniform, EngineOptions { corner_params: true, ..Default::default() })
        .unwrap();
    verify::approximation_error(&mesh, set, 6).unwrap().max
}

#[test]
fn teapot_error_quarters_when_the_factor_doubles() {
    let set = common::load(&common::model("patches/teapot.patches")).unwrap();
    for n in [4u32, 8, 16] {
        let (a, b) = (max_error(&set, n), max_error(&set, 2 * n));
        let ratio = b / a;
        assert!((0.2..=0.3).contains(&ratio), "n={n}: error {a:.3e} → {b:.3e}, ratio {ratio:.3}");
    }
}

#[test]
fn pn_error_converges_too() {
    let set = common::load(&common::model("meshes/blob.obj")).unwrap();
    let (a, b) = (max_error(&set, 8), max_error(&set, 16));
    assert!((0.2..=0.3).contains(&(b / a)), "blob: {a:.3e} → {b:.3e}");
}

#[test]
fn error_is_zero_at_the_vertices_and_small_for_flat_patches() {
    // A flat bilinear-like patch is reproduced exactly by any tessellation.
    let mut text = String::from("1\n1,2,3,4,5,6,7,8,9,10,11,12,13,14,15,16\n16\n");
    for i in 0..4 {
        for j in 0..4 {
            text += &format!("{},{},0\n", i as f64 / 3.0, j as f64 / 3.0 * 2.0);
        }
    }
    let file = tessera::io::patches::parse_patches(&text, std::path::Path::new("<flat>")).unwrap();
    let set = tessera::surface::SurfaceSet::from_patch_file(&file, Default::default());
    assert!(max_error(&set, 3) < 1e-6);
}
