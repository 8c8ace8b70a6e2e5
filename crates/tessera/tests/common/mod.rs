//! Shared helpers for the integration tests: where the models are, and loading them.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use tessera::surface::{BuildOptions, SurfaceSet};

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

/// Every patch model and every triangle-mesh model (the quad cages are polygon meshes and
/// are covered by the error tests).
pub fn all_surface_models() -> Vec<PathBuf> {
    let mut v = models_in("patches", "patches");
    v.extend(models_in("bench", "patches"));
    v.extend(models_in("meshes", "obj"));
    v.extend(models_in("awkward", "obj"));
    v
}
