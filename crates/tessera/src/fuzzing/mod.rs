//! The checks behind the cargo-fuzz targets in `fuzz/` and the `fuzz_regressions` test.
//!
//! They live in the library, not in `fuzz/`, so that `cargo test` replays a crash the fuzzer
//! found with exactly the code that found it, and so that neither copy can drift. Not part of
//! the public API: compiled only with the `fuzzing` feature, which `fuzz/` and this crate's
//! own tests (through its dev-dependency on itself) turn on.
//!
//! Every `check_*` function takes arbitrary bytes and returns normally when tessera behaved:
//! it refused the input with an [`Error`](crate::Error), or it produced a result that passes
//! the check's invariants. A panic, tessera's own or a failed invariant here, is a finding.
//!
//! The checks fall in three files: `parsers` (the readers, the writers' round trips and
//! `--camera`), `engine_case` (an engine case from the bytes, run and checked) and `shapes`
//! (the surfaces an engine case is generated from).

use std::path::Path;

use glam::DVec3;

use crate::criterion::Plan;
use crate::engine::{self, EngineOptions};
use crate::error::Result;
use crate::mesh::Mesh;
use crate::pattern::transition::Transition;
use crate::pattern::uniform::Uniform;
use crate::pattern::Pattern;
use crate::surface::SurfaceSet;
use crate::verify;

mod engine_case;
mod parsers;
mod shapes;

pub use engine_case::*;
pub use parsers::*;
pub use shapes::Shape;

/// The file name the checks give the parsers, for their error messages.
const LABEL: &str = "<fuzz>";

fn label() -> &'static Path {
    Path::new(LABEL)
}

/// Largest input the parser checks also push through the surface builders and the engine:
/// beyond it a run would spend its time in the engine rather than in the parser.
const ENGINE_PATCH_LIMIT: usize = 64;

/// A mesh holding only positions and triangles, the other attributes filled as the readers
/// fill them, so that every writer accepts it.
fn triangle_mesh(positions: &[DVec3], triangles: &[[u32; 3]]) -> Mesh {
    let n = positions.len();
    Mesh {
        positions: positions.iter().map(|p| p.as_vec3().to_array()).collect(),
        normals: vec![[0.0; 3]; n],
        uvs: vec![[0.0; 2]; n],
        vertex_patch: vec![0; n],
        indices: triangles.iter().flatten().copied().collect(),
        triangle_patch: vec![0; triangles.len()],
        ..Mesh::default()
    }
}

/// The bytes a writer produces, or None when it refuses the mesh (a refusal is the writer's
/// documented answer to values its format cannot hold, not a finding).
fn written(mesh: &Mesh, write: impl FnOnce(&Mesh, &mut Vec<u8>) -> Result<()>) -> Option<Vec<u8>> {
    let mut out = Vec::new();
    write(mesh, &mut out).ok().map(|()| out)
}

/// Uniform factor 2 through the engine's fast path and factor 3 through the generic path:
/// enough to reach every patch and edge of an arbitrary parsed input, little enough to keep
/// the parser targets fast.
fn tessellate_small(set: &SurfaceSet) {
    let patterns: [(u32, &dyn Pattern); 2] = [(2, &Uniform), (3, &Transition)];
    for (factor, pattern) in patterns {
        let Ok(plan) = Plan::uniform(set, factor) else { continue };
        if let Ok(mesh) = engine::tessellate(set, &plan, pattern, EngineOptions::default()) {
            assert_mesh_consistent(&mesh, "engine");
            let _ = verify::watertight(&mesh);
        }
    }
}

/// The invariants every [`Mesh`] that tessera hands out keeps: one attribute per vertex, one
/// patch per triangle, indices in range, finite numbers.
fn assert_mesh_consistent(mesh: &Mesh, source: &str) {
    let n = mesh.positions.len();
    assert_eq!(mesh.normals.len(), n, "{source}: one normal per position");
    assert_eq!(mesh.uvs.len(), n, "{source}: one uv per position");
    assert_eq!(mesh.vertex_patch.len(), n, "{source}: one patch per position");
    assert_eq!(mesh.indices.len() % 3, 0, "{source}: indices are triangles");
    assert_eq!(mesh.triangle_patch.len(), mesh.triangle_count(), "{source}: one patch per triangle");
    assert!(mesh.indices.iter().all(|&i| (i as usize) < n), "{source}: index out of range");
    if let Some(params) = &mesh.corner_params {
        assert_eq!(params.len(), mesh.indices.len(), "{source}: one corner parameter per index");
    }
    let finite = |v: &[f32]| v.iter().all(|x| x.is_finite());
    assert!(mesh.positions.iter().all(|p| finite(p)), "{source}: non-finite position");
    assert!(mesh.normals.iter().all(|p| finite(p)), "{source}: non-finite normal");
    assert!(mesh.uvs.iter().all(|p| finite(p)), "{source}: non-finite uv");
}
