//! The fuzz targets (`fuzz/`, cargo-fuzz) in the normal test suite: every input saved under
//! `fuzz/regressions/<target>/` is replayed, and each target's check runs on a short seeded
//! sample of arbitrary bytes and of byte-level mutations of real files. The checks are the
//! very functions the fuzz targets call ([`tessera::fuzzing`]), so a crash the fuzzer found
//! fails here until it is fixed, and stays fixed.

mod common;

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};

use proptest::collection::vec;
use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};
use tessera::criterion::esc::Threshold;
use tessera::criterion::view::{Mapping, ViewCriterion};
use tessera::engine::EngineOptions;
use tessera::fuzzing::{self, Criterion, EngineCase, EngineOutcome, Scheme, Shape};
use tessera::io::glb::write_glb;
use tessera::io::ply::write_ply;
use tessera::io::stl::write_stl;
use tessera::mesh::Mesh;

/// The engine check as a parser-style check, for the table below.
fn check_engine(data: &[u8]) {
    fuzzing::check_engine(data);
}

/// A fuzz target's check: returns when tessera behaved, panics on a finding.
type Check = fn(&[u8]);

/// Each fuzz target's name (its `fuzz_targets/<name>.rs` and `fuzz/regressions/<name>/`) and
/// the check it runs.
const TARGETS: [(&str, Check); 10] = [
    ("obj", fuzzing::check_obj),
    ("patches", fuzzing::check_patches),
    ("bezt", fuzzing::check_bezt),
    ("gltf", fuzzing::check_gltf),
    ("gltf_folder", fuzzing::check_gltf_folder),
    ("ply", fuzzing::check_ply),
    ("stl", fuzzing::check_stl),
    ("glb", fuzzing::check_glb),
    ("camera", fuzzing::check_camera),
    ("engine", check_engine),
];

fn check_of(target: &str) -> Check {
    TARGETS.iter().find(|(name, _)| *name == target).map(|(_, check)| *check).expect("a fuzz target")
}

fn regressions_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fuzz/regressions")
}

#[test]
fn every_saved_fuzz_finding_stays_fixed() {
    let mut failures = Vec::new();
    let mut replayed = 0;
    for (target, check) in TARGETS {
        // A target without findings has no folder.
        let Ok(entries) = std::fs::read_dir(regressions_dir().join(target)) else { continue };
        let mut files: Vec<PathBuf> = entries.map(|e| e.expect("a readable folder").path()).collect();
        files.sort();
        for path in files.iter().filter(|p| p.is_file()) {
            let data = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            replayed += 1;
            if let Err(panic) = catch_unwind(AssertUnwindSafe(|| check(&data))) {
                let why = panic
                    .downcast_ref::<String>()
                    .cloned()
                    .or_else(|| panic.downcast_ref::<&str>().map(|s| s.to_string()))
                    .unwrap_or_default();
                // The engine's own panics do not print the case its bytes decode to.
                let case = match target {
                    "engine" => format!("\n{:#?}", fuzzing::decode_engine_case(&data)),
                    _ => String::new(),
                };
                failures.push(format!("{}: {why}{case}", path.display()));
            }
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {replayed} saved fuzz inputs fail:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

/// Findings reported but not fixed yet live in `fuzz/regressions/open/<target>/`: each must
/// still fail its check, so the bug stays documented by a test that notices the day it is
/// fixed (then move the file to `fuzz/regressions/<target>/`, where it must pass).
#[test]
fn open_fuzz_findings_still_reproduce() {
    let mut fixed = Vec::new();
    for (target, check) in TARGETS {
        let Ok(entries) = std::fs::read_dir(regressions_dir().join("open").join(target)) else { continue };
        for path in entries.map(|e| e.expect("a readable folder").path()).filter(|p| p.is_file()) {
            let data = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            if catch_unwind(AssertUnwindSafe(|| check(&data))).is_ok() {
                fixed.push(path.display().to_string());
            }
        }
    }
    assert!(
        fixed.is_empty(),
        "these open findings pass now: move them to fuzz/regressions/<target>/: {fixed:?}"
    );
}

/// Runs `check` on `cases` values of `strategy` from a ChaCha generator seeded by `name`, so
/// every run sees the same inputs; proptest shrinks a failing one before reporting it.
fn run_seeded<S: Strategy>(name: &str, cases: u32, strategy: S, check: impl Fn(&S::Value)) {
    let config =
        Config { cases, failure_persistence: None, rng_algorithm: RngAlgorithm::ChaCha, ..Config::default() };
    let mut seed = [0x5eu8; 32];
    for (k, b) in name.bytes().enumerate() {
        seed[k % 32] ^= b;
    }
    let mut runner = TestRunner::new_with_rng(config, TestRng::from_seed(RngAlgorithm::ChaCha, &seed));
    if let Err(e) = runner.run(&strategy, |value| {
        check(&value);
        Ok(())
    }) {
        panic!("{name}: {e}");
    }
}

#[test]
fn parser_checks_survive_arbitrary_bytes() {
    for (target, check) in TARGETS.iter().filter(|(name, _)| *name != "engine") {
        run_seeded(target, 64, vec(any::<u8>(), 0..512), |data| check(data));
    }
}

/// One byte-level edit, as a mutating fuzzer makes them.
#[derive(Debug, Clone, Copy)]
enum Edit {
    Overwrite(usize, u8),
    Insert(usize, u8),
    Delete(usize),
    /// Copies up to 16 bytes from the first position to the second.
    Copy(usize, usize),
    Truncate(usize),
}

fn edits() -> impl Strategy<Value = Vec<Edit>> {
    // Positions are reduced modulo the length at the time of the edit; small ones are
    // favoured because headers, where parsers branch most, come first.
    let position = prop_oneof![0..64usize, any::<usize>()];
    let edit = prop_oneof![
        4 => (position.clone(), any::<u8>()).prop_map(|(p, b)| Edit::Overwrite(p, b)),
        2 => (position.clone(), any::<u8>()).prop_map(|(p, b)| Edit::Insert(p, b)),
        2 => position.clone().prop_map(Edit::Delete),
        1 => (position.clone(), position.clone()).prop_map(|(a, b)| Edit::Copy(a, b)),
        1 => position.prop_map(Edit::Truncate),
    ];
    vec(edit, 1..8)
}

fn mutated(original: &[u8], edits: &[Edit]) -> Vec<u8> {
    let mut data = original.to_vec();
    for &edit in edits {
        let len = data.len().max(1);
        match edit {
            Edit::Overwrite(p, b) if !data.is_empty() => data[p % len] = b,
            Edit::Insert(p, b) => data.insert(p % (data.len() + 1), b),
            Edit::Delete(p) if !data.is_empty() => {
                data.remove(p % len);
            }
            Edit::Copy(from, to) if !data.is_empty() => {
                let from = from % len;
                let chunk: Vec<u8> = data[from..(from + 16).min(data.len())].to_vec();
                let to = to % len;
                let end = (to + chunk.len()).min(data.len());
                data[to..end].copy_from_slice(&chunk[..end - to]);
            }
            Edit::Truncate(p) => data.truncate(p % len),
            _ => {}
        }
    }
    data
}

/// Runs a target's check on the file itself and on mutations of it.
fn check_mutations(target: &str, name: &str, original: &[u8], cases: u32) {
    let check = check_of(target);
    check(original);
    run_seeded(&format!("{target} {name}"), cases, edits(), |e| check(&mutated(original, e)));
}

fn model_bytes(rel: &str) -> Vec<u8> {
    let path = common::model(rel);
    std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// A real triangle mesh as the mesh readers return it, for writing it in their formats.
fn real_mesh(rel: &str) -> Mesh {
    let path = common::model(rel);
    let obj = tessera::io::obj::read_obj(&path).unwrap_or_else(|e| panic!("{e}"));
    let triangles = obj.triangles(&path).unwrap_or_else(|e| panic!("{e}"));
    let n = obj.positions.len();
    Mesh {
        positions: obj.positions.iter().map(|p| p.as_vec3().to_array()).collect(),
        normals: vec![[0.0, 0.0, 1.0]; n],
        uvs: (0..n).map(|i| [i as f32 / n as f32, 0.5]).collect(),
        vertex_patch: (0..n as u32).map(|i| i % 7).collect(),
        indices: triangles.iter().flatten().copied().collect(),
        triangle_patch: (0..triangles.len() as u32).map(|t| t % 5).collect(),
        ..Mesh::default()
    }
}

fn written(write: impl FnOnce(&mut Vec<u8>) -> tessera::Result<()>) -> Vec<u8> {
    let mut out = Vec::new();
    write(&mut out).unwrap_or_else(|e| panic!("{e}"));
    out
}

const ASCII_PLY: &str = "ply
format ascii 1.0
comment a unit square as two triangles and a quad fan
element vertex 4
property float x
property float y
property float z
property float nx
property float ny
property float nz
property float u
property float v
element face 2
property list uchar int vertex_indices
property uint patch
end_header
0 0 0 0 0 1 0 0
1 0 0 0 0 1 1 0
1 1 0 0 0 1 1 1
0 1 0 0 0 1 0 1
3 0 1 2 0
4 0 1 2 3 1
";

const ASCII_STL: &str = "solid square
facet normal 0 0 1
outer loop
vertex 0 0 0
vertex 1 0 0
vertex 1 1 0
endloop
endfacet
facet normal 0 0 1
outer loop
vertex 0 0 0
vertex 1 1 0
vertex 0 1 0
endloop
endfacet
endsolid square
";

/// Two flat cubic Bézier triangles sharing the edge (3,0,0)-(0,3,0).
const FLAT_BEZT: &str = "2
1,2,3,4,5,6,7,8,9,10
7,11,8,12,13,9,14,15,16,10
16
0,0,0
1,0,0
0,1,0
2,0,0
1,1,0
0,2,0
3,0,0
2,1,0
1,2,0
0,3,0
3,1,0
2,2,0
1,3,0
3,3,0
2,3,0
3,2,0
";

/// The buffer URIs the `gltf_folder` seeds name: each file of the hostile folder, a path
/// out of it, a device and an absolute path.
const GLTF_FOLDER_URIS: [&str; 11] = [
    "ok.bin",
    "short.bin",
    "empty.bin",
    "big.bin",
    "sub",
    "zero.bin",
    "out.bin",
    "loop.bin",
    "../outside.bin",
    "/dev/zero",
    "/etc/passwd",
];

#[test]
fn parser_checks_survive_mutated_real_files() {
    check_mutations("obj", "catmark_cube", &model_bytes("cages/catmark_cube.obj"), 64);
    // OpenSubdiv's tag lines (creases, corners, holes, boundary rule).
    check_mutations("obj", "hole_test2", &model_bytes("subdivision/catmark_hole_test2.obj"), 48);
    // A creased triangle cage: its mutations take the Loop rules' paths too.
    check_mutations("obj", "loop_cube_creases0", &model_bytes("subdivision/loop_cube_creases0.obj"), 48);
    check_mutations("obj", "dragknob", &model_bytes("meshes/dragknob.obj"), 32);
    check_mutations("patches", "teapot", &model_bytes("patches/teapot.patches"), 48);
    check_mutations("patches", "teacup", &model_bytes("patches/teacup.patches"), 16);
    let mesh = real_mesh("meshes/dragknob.obj");
    check_mutations("ply", "dragknob", &written(|out| write_ply(&mesh, out)), 48);
    check_mutations("ply", "ascii", ASCII_PLY.as_bytes(), 48);
    check_mutations("stl", "dragknob", &written(|out| write_stl(&mesh, out)), 48);
    check_mutations("stl", "ascii", ASCII_STL.as_bytes(), 48);
    check_mutations("glb", "dragknob", &written(|out| write_glb(&mesh, out)), 64);
    check_mutations("gltf", "dragknob", &written(|out| write_glb(&mesh, out)), 64);
    check_mutations("bezt", "flat", FLAT_BEZT.as_bytes(), 48);
    for uri in GLTF_FOLDER_URIS {
        check_mutations("gltf_folder", uri, fuzzing::one_triangle_gltf(uri).as_bytes(), 12);
    }
    let spec = "eye=10,-4.5,2,target=0,0.25,0,up=0,0,1,fov=30,size=640x480,near=0.5,far=100";
    check_mutations("camera", "full spec", spec.as_bytes(), 64);
    check_mutations("camera", "one key", b"fov=30", 32);
}

#[test]
fn engine_check_holds_on_small_random_inputs() {
    // (tessellated, checked watertight); proptest calls the check exactly `cases` times when
    // every case passes.
    let counts = std::cell::Cell::new((0usize, 0usize));
    run_seeded("engine", 320, vec(any::<u8>(), 0..160), |data| {
        let (tessellated, watertight) = counts.get();
        if let EngineOutcome::Tessellated { checked_watertight } = fuzzing::check_engine(data) {
            counts.set((tessellated + 1, watertight + usize::from(checked_watertight)));
        }
    });
    let (tessellated, watertight) = counts.get();
    // Guards against a decoder change that makes the sample vacuous.
    assert!(
        tessellated >= 120 && watertight >= 60,
        "{tessellated} tessellated, {watertight} checked watertight"
    );
}

/// Two bicubic patches that share all four boundary curves: a closed, consistently oriented
/// pillow (top bulging up, bottom down), like two halves of a handle.
const PILLOW: &str = "\
    2\n\
    1,2,3,4,5,6,7,8,9,10,11,12,13,14,15,16\n\
    1,5,9,13,2,17,18,14,3,19,20,15,4,8,12,16\n\
    20\n\
    -6,-6,0\n\
    -6,-2,0\n\
    -6,2,0\n\
    -6,6,0\n\
    -2,-6,0\n\
    -2,-2,3\n\
    -2,2,3\n\
    -2,6,0\n\
    2,-6,0\n\
    2,-2,3\n\
    2,2,3\n\
    2,6,0\n\
    6,-6,0\n\
    6,-2,0\n\
    6,2,0\n\
    6,6,0\n\
    -2,-2,-3\n\
    2,-2,-3\n\
    -2,2,-3\n\
    2,2,-3\n\
";

/// The first engine finding, kept independent of how `decode_engine_case` reads bytes:
/// `--scheme uniform --distance 1:1` (or `--silhouette`) on a pillow. `view::plan` with
/// `Layout::Uniform` raised the interior to `minimum_interior` (2, because the two patches
/// share their diagonals' corners) but left the edges at 1 segment, breaking the uniform
/// pattern's precondition; the engine then wrote indices past the vertices (the OBJ writer
/// refused the mesh) or, with corner parameters (PLY, GLB), panicked. Fixed: uniform view
/// plans keep edges and interiors equal.
#[test]
fn uniform_scheme_with_a_view_criterion_on_a_pillow() {
    let case = EngineCase {
        shape: Shape::RandomPatches,
        text: PILLOW.into(),
        dropped: None,
        build: Default::default(),
        camera: None,
        scheme: Scheme::Uniform,
        criterion: Criterion::View(ViewCriterion::Distance(Mapping::Linear), 1.0, 1.0),
        max_level: 0,
        variant: false,
        esc_threshold: Threshold::Medium,
        options: EngineOptions { corner_params: true, ..Default::default() },
    };
    fuzzing::run_engine_case(&case);
}
