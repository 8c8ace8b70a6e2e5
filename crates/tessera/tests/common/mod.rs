//! Shared helpers for the integration tests: where the models are, and loading them.
#![allow(dead_code)]

pub mod osd;

use glam::DVec3;
use proptest::prelude::*;
use std::path::{Path, PathBuf};
use tessera::camera::Camera;
use tessera::criterion::Plan;
use tessera::mesh::Mesh;
use tessera::surface::{BuildOptions, SurfaceSet};
use tessera::verify;

/// The shared model folder: `$TESSERA_DATA`, else `../shared/data` beside the checkout.
pub fn data_dir() -> PathBuf {
    if let Ok(d) = std::env::var("TESSERA_DATA") {
        return PathBuf::from(d);
    }
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data")
}

/// A model path; panics with a clear message when the data folder is missing.
pub fn model(rel: &str) -> PathBuf {
    let p = data_dir().join(rel);
    assert!(p.exists(), "test model {} not found: set TESSERA_DATA to the shared data folder", p.display());
    p
}

/// Every file with the extension in a data subfolder, sorted.
pub fn models_in(sub: &str, ext: &str) -> Vec<PathBuf> {
    let dir = data_dir().join(sub);
    let mut v: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("cannot list {}: {e}", dir.display()))
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == ext))
        .collect();
    v.sort();
    assert!(!v.is_empty(), "no .{ext} models in {}", dir.display());
    v
}

/// Loads a patch file or a triangle mesh (as PN triangles).
pub fn load(path: &Path) -> tessera::Result<SurfaceSet> {
    load_with(path, BuildOptions::default())
}

pub fn load_with(path: &Path, options: BuildOptions) -> tessera::Result<SurfaceSet> {
    if path.extension().is_some_and(|e| e == "obj") {
        let m = tessera::io::obj::read_obj(path)?;
        SurfaceSet::pn_from_mesh(&m, path, options)
    } else {
        let f = tessera::io::patches::read_patches(path)?;
        Ok(SurfaceSet::from_patch_file(&f, options))
    }
}

/// The fast tier's models, for the property tests that the slow tier (`#[ignore]`d, run by
/// `scripts/test`) runs on [`all_surface_models`]: the teapot (bicubic, a lid apex collapsed
/// to a point, an open rim), the teacup (a handle whose halves share all four corners), spot
/// (a closed PN-triangle mesh) and a non-manifold PN mesh.
pub fn fast_models() -> Vec<PathBuf> {
    [
        "patches/teapot.patches",
        "patches/teacup.patches",
        "meshes/spot.obj",
        "awkward/teapot_tri_nonmanifold.obj",
    ]
    .map(model)
    .to_vec()
}

/// Every patch model and every triangle-mesh model (the quad cages are polygon meshes and
/// are covered by the error tests).
pub fn all_surface_models() -> Vec<PathBuf> {
    let mut v = models_in("patches", "patches");
    v.extend(models_in("bench", "patches"));
    v.extend(models_in("meshes", "obj"));
    v.extend(models_in("awkward", "obj"));
    v
}

/// The topology the output must have: an edge used by exactly one visible patch contributes
/// its segments as boundary edges, one used by more than two as non-manifold edges.
pub fn expect_topology(set: &SurfaceSet, plan: &Plan, mesh: &Mesh, name: &str) {
    let topo = &set.topology;
    let (mut boundary, mut nonmanifold) = (0, 0);
    for (e, edge) in topo.edges.iter().enumerate() {
        if edge.collapsed {
            continue;
        }
        let visible = topo.edge_uses(e).iter().filter(|u| plan.is_visible(u.patch as usize)).count();
        let s = plan.segments(e) as usize;
        match visible {
            1 => boundary += s,
            0 | 2 => {}
            _ => nonmanifold += s,
        }
    }
    let w = verify::watertight(mesh);
    assert_eq!(w.boundary_edges, boundary, "{name}: boundary edges ({w:?})");
    assert_eq!(w.nonmanifold_edges, nonmanifold, "{name}: non-manifold edges ({w:?})");
    assert_eq!(w.collapsed_triangles, 0, "{name}");
    if plan.visible.iter().all(|&v| v != 0) {
        assert_eq!(w.euler_characteristic, topo.report.euler_characteristic, "{name}: Euler characteristic");
    }
}

/// A random camera outside the model's bounding sphere, and a pixel tolerance.
pub fn random_camera(set: &SurfaceSet) -> impl Strategy<Value = (Camera, f64)> {
    let (lo, hi) = set.bounds();
    let (centre, diag) = ((lo + hi) * 0.5, lo.distance(hi));
    (
        (-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64),
        0.6..3.0f64, // outside the bounding sphere: the eye never touches the surface
        (-0.3..0.3f64, -0.3..0.3f64, -0.3..0.3f64),
        15.0..90.0f64,
        (160u32..1920, 120u32..1080),
        0.5..4.0f64,
    )
        .prop_filter_map("degenerate direction", move |(d, dist, off, fov, (w, h), px)| {
            let dir = DVec3::new(d.0, d.1, d.2).try_normalize()?;
            let eye = centre + dir * dist * diag;
            let target = centre + DVec3::new(off.0, off.1, off.2) * diag;
            let up = if dir.cross(DVec3::Z).length() > 0.1 { DVec3::Z } else { DVec3::Y };
            let cam = Camera {
                eye,
                target,
                up,
                fov_y_degrees: fov,
                width: w,
                height: h,
                near: diag * 1e-3,
                far: diag * 10.0,
            };
            cam.validate().ok()?;
            Some((cam, px))
        })
}
