//! The checks behind the cargo-fuzz targets in `fuzz/` and the `fuzz_regressions` test.
//!
//! They live in the library, not in `fuzz/`, so that `cargo test` replays a crash the fuzzer
//! found with exactly the code that found it, and so that neither copy can drift. Not part of
//! the public API.
//!
//! Every `check_*` function takes arbitrary bytes and returns normally when tessera behaved:
//! it refused the input with an [`Error`](crate::Error), or it produced a result that passes
//! the check's invariants. A panic, tessera's own or a failed invariant here, is a finding.

use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::Path;

use glam::DVec3;

use crate::camera::Camera;
use crate::criterion::esc::Threshold;
use crate::criterion::view::{Mapping, ViewCriterion};
use crate::criterion::Plan;
use crate::engine::{self, TessellateOptions};
use crate::error::Result;
use crate::io::bezt;
use crate::io::glb::{self, parse_glb, write_glb};
use crate::io::obj;
use crate::io::obj::write_obj;
use crate::io::patches;
use crate::io::ply::{parse_ply, write_ply};
use crate::io::stl::{parse_stl, write_stl};
use crate::mesh::strips;
use crate::mesh::Mesh;
use crate::pattern::hardware::Partitioning;
use crate::pattern::transition::Transition;
use crate::pattern::uniform::Uniform;
use crate::pattern::Pattern;
use crate::surface::PolygonMesh;
use crate::surface::{BuildOptions, Orientation, SurfaceSet};
use crate::topology::weld::Weld;
use crate::verify;

/// The file name the checks give the parsers, for their error messages.
const LABEL: &str = "<fuzz>";

fn label() -> &'static Path {
    Path::new(LABEL)
}

/// Largest input the parser checks also push through the surface builders and the engine:
/// beyond it a run would spend its time in the engine rather than in the parser.
const ENGINE_PATCH_LIMIT: usize = 64;

/// Checks the OBJ reader: [`obj::parse_obj`] on the bytes (decoded as `read_obj` does, with
/// invalid UTF-8 replaced). A parsed mesh must keep its documented invariants, must build PN
/// triangles or refuse them with an error, and, as a triangle list, must survive
/// [`write_obj`] → [`obj::parse_obj`] with the same positions and triangles.
pub fn check_obj(data: &[u8]) {
    let text = String::from_utf8_lossy(data);
    let Ok(mesh) = obj::parse_obj(&text, label()) else { return };
    assert_obj_invariants(&mesh);
    let Ok(triangles) = mesh.triangles(label()) else { return };
    if triangles.len() <= 4 * ENGINE_PATCH_LIMIT {
        if let Ok(set) = SurfaceSet::pn_from_mesh(&mesh, label(), BuildOptions::default()) {
            tessellate_small(&set);
        }
    }
    let list = triangle_mesh(&mesh.positions, &triangles);
    // Coordinates past the f32 range are refused by the writer; nothing to compare then.
    let Some(bytes) = written(&list, |m, out| write_obj(m, out)) else { return };
    let text = String::from_utf8(bytes).expect("write_obj writes UTF-8");
    let again = obj::parse_obj(&text, label())
        .unwrap_or_else(|e| panic!("the output of write_obj does not parse: {e}\n{text}"));
    let again_triangles = again.triangles(label()).expect("write_obj writes triangles");
    assert_eq!(again_triangles, triangles, "write_obj → parse_obj changed the triangles");
    let as_f32 = |p: &[DVec3]| p.iter().map(|p| p.as_vec3().to_array()).collect::<Vec<_>>();
    assert_eq!(as_f32(&again.positions), list.positions, "write_obj → parse_obj changed the positions");
}

fn assert_obj_invariants(mesh: &PolygonMesh) {
    assert!(!mesh.faces.is_empty(), "parse_obj returned a mesh without faces");
    assert!(mesh.positions.iter().all(|p| p.is_finite()), "parse_obj returned a non-finite position");
    assert!(mesh.normals.iter().all(|n| n.is_finite()), "parse_obj returned a non-finite normal");
    for face in &mesh.faces {
        assert!(face.positions.len() >= 3, "line {}: face with {} corners", face.line, face.positions.len());
        assert!(
            face.positions.iter().all(|&i| (i as usize) < mesh.positions.len()),
            "line {}: position index out of range",
            face.line
        );
        if let Some(normals) = &face.normals {
            assert_eq!(normals.len(), face.positions.len(), "line {}: one normal per corner", face.line);
            assert!(
                normals.iter().all(|&i| (i as usize) < mesh.normals.len()),
                "line {}: normal index out of range",
                face.line
            );
        }
    }
}

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

/// Checks the Newell patch reader: [`patches::parse_patches`] on the bytes. A parsed file
/// must keep its documented invariants and read back identically from the Newell text of its
/// own values; small files must also build a surface set and tessellate (or refuse with an
/// error).
pub fn check_patches(data: &[u8]) {
    let text = String::from_utf8_lossy(data);
    let Ok(file) = patches::parse_patches(&text, label()) else { return };
    assert!(!file.patches.is_empty(), "parse_patches returned a file without patches");
    assert_eq!(file.weights.len(), file.points.len(), "one weight per point");
    assert_eq!(file.lines.len(), file.patches.len(), "one line per patch");
    assert!(file.points.iter().all(|p| p.is_finite()), "parse_patches returned a non-finite point");
    assert!(file.weights.iter().all(|&w| w.is_finite() && w > 0.0), "parse_patches returned a bad weight");
    assert!(
        file.patches.iter().flatten().all(|&i| (i as usize) < file.points.len()),
        "parse_patches returned an index out of range"
    );
    let text = patches::to_patches_text(&file);
    let again = patches::parse_patches(&text, label())
        .unwrap_or_else(|e| panic!("the Newell text of a parsed file does not parse: {e}\n{text}"));
    assert_eq!(
        (&again.patches, &again.points, &again.weights),
        (&file.patches, &file.points, &file.weights),
        "parse → Newell text → parse changed the file"
    );
    if file.patches.len() <= ENGINE_PATCH_LIMIT {
        tessellate_small(&SurfaceSet::from_patch_file(&file, BuildOptions::default()));
    }
}

/// Checks the Bézier triangle reader: [`bezt::parse_bezt`] on the bytes (invalid UTF-8
/// replaced). A parsed file must keep its invariants, read back identically from its own
/// text ([`bezt::to_bezt_text`]), and small files must build and tessellate.
pub fn check_bezt(data: &[u8]) {
    let text = String::from_utf8_lossy(data);
    let Ok(file) = bezt::parse_bezt(&text, label()) else { return };
    assert!(!file.triangles.is_empty(), "parse_bezt returned a file without triangles");
    assert_eq!(file.lines.len(), file.triangles.len(), "one line per triangle");
    assert!(file.points.iter().all(|p| p.is_finite()), "parse_bezt returned a non-finite point");
    assert!(
        file.triangles.iter().flatten().all(|&i| (i as usize) < file.points.len()),
        "parse_bezt returned an index out of range"
    );
    let text = bezt::to_bezt_text(&file);
    let again = bezt::parse_bezt(&text, label())
        .unwrap_or_else(|e| panic!("the text of a parsed .bezt file does not parse: {e}\n{text}"));
    assert_eq!(
        (&again.triangles, &again.points),
        (&file.triangles, &file.points),
        "parse → text → parse changed the file"
    );
    if file.triangles.len() <= ENGINE_PATCH_LIMIT {
        tessellate_small(&SurfaceSet::from_bezier_triangle_file(&file, BuildOptions::default()));
    }
}

/// Checks the outside-glTF reader: [`glb::parse_gltf_triangles`] on the bytes (no folder, so
/// only the GLB's own buffer and `data:` URIs). A parsed mesh must have its indices in range
/// and finite numbers, and must build PN triangles or refuse them with an error.
pub fn check_gltf(data: &[u8]) {
    let Ok(mesh) = glb::parse_gltf_triangles(data, label(), None, Default::default()) else { return };
    assert_obj_invariants(&mesh);
    if let Ok(set) = SurfaceSet::pn_from_mesh(&mesh, label(), BuildOptions::default()) {
        if set.patches.len() <= ENGINE_PATCH_LIMIT {
            tessellate_small(&set);
        }
    }
}

/// The hostile folder [`check_gltf_folder`] reads buffers from, made once per process: in
/// `model/`, a valid one-triangle buffer `ok.bin` (44 bytes), `short.bin` (4 bytes),
/// `empty.bin`, `big.bin` (the valid buffer, then sparse up to 256 MiB), a folder `sub`, and
/// on Unix links to `/dev/zero`, to a file outside `model/`, and to themselves.
fn hostile_folder() -> &'static Path {
    static FOLDER: std::sync::OnceLock<std::path::PathBuf> = std::sync::OnceLock::new();
    FOLDER.get_or_init(|| {
        let root = std::env::temp_dir().join(format!("tessera-fuzz-gltf-{}", std::process::id()));
        let model = root.join("model");
        std::fs::create_dir_all(model.join("sub")).expect("a temporary folder");
        let ok = one_triangle_buffer();
        let write =
            |name: &str, bytes: &[u8]| std::fs::write(model.join(name), bytes).expect("a temporary file");
        write("ok.bin", &ok);
        write("short.bin", &ok[..4]);
        write("empty.bin", &[]);
        write("big.bin", &ok);
        std::fs::OpenOptions::new()
            .write(true)
            .open(model.join("big.bin"))
            .and_then(|f| f.set_len(256 << 20))
            .expect("a sparse file");
        std::fs::write(root.join("outside.bin"), &ok).expect("a temporary file");
        #[cfg(unix)]
        for (link, target) in
            [("zero.bin", "/dev/zero"), ("out.bin", "../outside.bin"), ("loop.bin", "loop.bin")]
        {
            let _ = std::os::unix::fs::symlink(target, model.join(link));
        }
        model
    })
}

/// Three positions and three `u16` indices (one padding index): a one-triangle buffer of 44
/// bytes, positions at 0 and indices at 36.
pub fn one_triangle_buffer() -> Vec<u8> {
    let mut bin = Vec::new();
    for p in [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] {
        bin.extend(p.iter().flat_map(|c| c.to_le_bytes()));
    }
    for i in [0u16, 1, 2, 0] {
        bin.extend(i.to_le_bytes());
    }
    bin
}

/// A `.gltf` whose one triangle's buffer (of `byteLength` 44, as
/// [`one_triangle_buffer`]) is `uri`: the seed [`check_gltf_folder`]'s inputs mutate.
pub fn one_triangle_gltf(uri: &str) -> String {
    format!(
        r#"{{"asset":{{"version":"2.0"}},"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}}],"buffers":[{{"byteLength":44,"uri":"{uri}"}}],"bufferViews":[{{"buffer":0,"byteLength":36}},{{"buffer":0,"byteOffset":36,"byteLength":6}}],"accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}},{{"bufferView":1,"componentType":5123,"count":3,"type":"SCALAR"}}]}}"#
    )
}

/// Checks the outside-glTF reader on a `.gltf` file (the bytes) inside a folder of hostile
/// buffer files (`hostile_folder`: short, empty, sparse-huge, a folder, links to a device,
/// outside the folder and to themselves), read with [`glb::read_gltf_triangles`] under the
/// default [`UriScope`](glb::UriScope): it must refuse or parse, never panic, hang on a
/// device, or read past a buffer's `byteLength`. A parsed mesh must pass the same invariants
/// as [`check_gltf`]'s.
pub fn check_gltf_folder(data: &[u8]) {
    // A file per thread, so parallel tests do not read each other's half-written inputs.
    let path = hostile_folder()
        .join(format!("input-{:?}.gltf", std::thread::current().id()).replace(['(', ')'], ""));
    std::fs::write(&path, data).expect("a temporary file");
    let read = glb::read_gltf_triangles(&path, glb::UriScope::ModelFolder);
    let _ = std::fs::remove_file(&path);
    let Ok(mesh) = read else { return };
    assert_obj_invariants(&mesh);
    if let Ok(set) = SurfaceSet::pn_from_mesh(&mesh, label(), BuildOptions::default()) {
        if set.patches.len() <= ENGINE_PATCH_LIMIT {
            tessellate_small(&set);
        }
    }
}

/// Uniform factor 2 through the engine's fast path and factor 3 through the generic path:
/// enough to reach every patch and edge of an arbitrary parsed input, little enough to keep
/// the parser targets fast.
fn tessellate_small(set: &SurfaceSet) {
    let patterns: [(u32, &dyn Pattern); 2] = [(2, &Uniform), (3, &Transition)];
    for (factor, pattern) in patterns {
        let Ok(plan) = Plan::uniform(set, factor) else { continue };
        if let Ok(mesh) = engine::tessellate(set, &plan, pattern, TessellateOptions::default()) {
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

/// Checks the PLY reader: [`parse_ply`] on the bytes; a parsed mesh must be consistent and
/// survive [`write_ply`] → [`parse_ply`] unchanged.
pub fn check_ply(data: &[u8]) {
    check_mesh_reader(data, "PLY", parse_ply, |m, out| write_ply(m, out));
}

/// Checks the STL reader: [`parse_stl`] on the bytes; a parsed mesh must be consistent and
/// survive [`write_stl`] → [`parse_stl`] unchanged (the reader welds corners in order of
/// first appearance, so writing its own output back reproduces it exactly).
pub fn check_stl(data: &[u8]) {
    check_mesh_reader(data, "STL", parse_stl, |m, out| write_stl(m, out));
}

/// Checks the GLB reader: [`parse_glb`] on the bytes; a parsed mesh must be consistent and
/// survive [`write_glb`] → [`parse_glb`] unchanged (a mesh without triangles loses its
/// vertices, as `write_glb` documents).
pub fn check_glb(data: &[u8]) {
    check_mesh_reader(data, "GLB", parse_glb, |m, out| write_glb(m, out));
}

fn check_mesh_reader(
    data: &[u8],
    format: &str,
    parse: fn(&[u8], &Path) -> Result<Mesh>,
    write: fn(&Mesh, &mut Vec<u8>) -> Result<()>,
) {
    let Ok(mesh) = parse(data, label()) else { return };
    assert_mesh_consistent(&mesh, format);
    assert!(mesh.strips.is_none(), "{format}: a reader returned strips");
    let Some(bytes) = written(&mesh, write) else { return };
    let again = parse(&bytes, label())
        .unwrap_or_else(|e| panic!("{format}: the writer's output does not parse: {e}"));
    if mesh.triangle_count() == 0 && format == "GLB" {
        assert_eq!(again.triangle_count(), 0, "{format}: triangles appeared in a round trip");
    } else {
        assert!(again == mesh, "{format}: write → parse changed the mesh:\n{mesh:?}\n{again:?}");
    }
}

/// The camera [`check_camera`] parses against: the framing camera of the unit cube at the
/// CLI's default viewport.
pub fn default_camera() -> Camera {
    Camera::framing(DVec3::ZERO, DVec3::ONE, 1280, 720)
}

/// Checks `--camera` parsing: [`Camera::parse`] on the bytes (invalid UTF-8 replaced). A
/// parsed camera must validate, project without panicking, and read back identically from
/// a spec that names every key.
pub fn check_camera(data: &[u8]) {
    let text = String::from_utf8_lossy(data);
    let Ok(camera) = Camera::parse(&text, &default_camera()) else { return };
    if let Err(e) = camera.validate() {
        panic!("Camera::parse({text:?}) returned a camera that does not validate: {e}");
    }
    let _ = camera.project(DVec3::ZERO);
    let _ = camera.sees(DVec3::ONE);
    let spec = camera_spec(&camera);
    let again = Camera::parse(&spec, &default_camera())
        .unwrap_or_else(|e| panic!("the full spec {spec:?} of a parsed camera does not parse: {e}"));
    assert_eq!(again, camera, "parse({text:?}) → spec {spec:?} → parse changed the camera");
}

/// A `--camera` spec naming every key; `{:?}` prints the shortest text that reads back to the
/// same `f64`.
fn camera_spec(c: &Camera) -> String {
    format!(
        "eye={:?},{:?},{:?},target={:?},{:?},{:?},up={:?},{:?},{:?},fov={:?},size={}x{},near={:?},far={:?}",
        c.eye.x,
        c.eye.y,
        c.eye.z,
        c.target.x,
        c.target.y,
        c.target.z,
        c.up.x,
        c.up.y,
        c.up.z,
        c.fov_y_degrees,
        c.width,
        c.height,
        c.near,
        c.far
    )
}

// =============================================================================================
// The engine

/// A reader of fuzz bytes as small decisions; past the end every value is 0, so every input,
/// even an empty one, decodes to a case.
struct Decisions<'a> {
    data: &'a [u8],
    pos: usize,
}

impl Decisions<'_> {
    fn byte(&mut self) -> u8 {
        let b = self.data.get(self.pos).copied().unwrap_or(0);
        self.pos += 1;
        b
    }

    /// A value in `0..n` (`n ≥ 1`): one byte for small ranges, so that short inputs still
    /// make many decisions, two for larger ones.
    fn below(&mut self, n: u32) -> u32 {
        let v = if n <= 256 {
            u32::from(self.byte())
        } else {
            u32::from(self.byte()) | u32::from(self.byte()) << 8
        };
        v % n
    }

    /// An integer in `lo..=hi`.
    fn int_in(&mut self, lo: i32, hi: i32) -> i32 {
        lo + self.below((hi - lo + 1) as u32) as i32
    }

    /// True about once in `n` times.
    fn one_in(&mut self, n: u32) -> bool {
        self.below(n) == 0
    }

    /// A real factor in `[lo, hi]`: mostly spread evenly, sometimes one of the values where
    /// rounding and partitioning rules change (integers, and just above or below them).
    fn factor(&mut self, lo: f64, hi: f64) -> f64 {
        const AWKWARD: [f64; 12] = [1.0, 1.0001, 1.5, 1.9999, 2.0, 2.0001, 2.5, 3.0, 4.0, 7.5, 15.9999, 16.0];
        let f = if self.one_in(3) {
            AWKWARD[self.below(AWKWARD.len() as u32) as usize]
        } else {
            lo + (hi - lo) * f64::from(self.below(1025)) / 1024.0
        };
        f.clamp(lo, hi)
    }
}

/// The surfaces an engine case is built from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Shape {
    /// Six bicubic patches on the faces of a cube.
    CubePatches,
    /// Four bicubic patches around an axis, each with both ends collapsed to a pole (the
    /// teapot lid's degenerate rows).
    Spindle,
    /// Nine bicubic patches on a 3 × 3 torus.
    Torus,
    /// An octahedron of PN triangles.
    Octahedron,
    /// A cube of PN triangles, each face split along a chosen diagonal.
    CubeMesh,
    /// A tetrahedron of PN triangles.
    Tetrahedron,
    /// 1 to 8 bicubic patches indexing a pool of up to 16 grid points: any topology.
    RandomPatches,
    /// 1 to 12 triangles indexing a pool of up to 10 grid points: any topology.
    RandomMesh,
}

impl Shape {
    const ALL: [Shape; 8] = [
        Shape::CubePatches,
        Shape::Spindle,
        Shape::Torus,
        Shape::Octahedron,
        Shape::CubeMesh,
        Shape::Tetrahedron,
        Shape::RandomPatches,
        Shape::RandomMesh,
    ];

    /// Closed and consistently oriented by construction, with every patch corner distinct
    /// from its neighbours' other corners: the shapes whose output must be watertight. The
    /// random shapes are not held to it, because after welding output positions by bits,
    /// two patches with the same corners (or coincident sheets) legitimately share
    /// triangles at low factors; they are checked for panics and consistency only.
    fn is_watertight_by_construction(self) -> bool {
        !matches!(self, Shape::RandomPatches | Shape::RandomMesh)
    }
}

/// A tessellation scheme, as `--scheme` names them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scheme {
    Uniform,
    Transition,
    SemiUniform,
    Sd2,
    Hardware(Partitioning),
    Esc,
}

/// How an engine case chooses its factors (the CLI's criterion flags).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Criterion {
    /// `--factor`.
    Factor(f64),
    /// `--tolerance`, as a share of the bounding-box diagonal.
    Tolerance(f64),
    /// `--pixel-error`.
    PixelError(f64),
    /// `--distance` or `--silhouette`: FMIN:FMAX.
    View(ViewCriterion, f64, f64),
}

/// One decoded engine case, kept whole so a failure can print everything that led to it.
#[derive(Debug, Clone)]
pub struct EngineCase {
    /// What the input was generated as.
    pub shape: Shape,
    /// The generated input, Newell patch text or OBJ text.
    pub text: String,
    /// A patch or face left out, which opens a closed shape.
    pub dropped: Option<usize>,
    /// Welding and orientation for the surface builder.
    pub build: BuildOptions,
    /// The `--camera` spec, None for the default framing camera.
    pub camera: Option<String>,
    pub scheme: Scheme,
    pub criterion: Criterion,
    /// Semi-uniform's `--max-level`, ESC's `Lmax`.
    pub max_level: u32,
    /// SD-2's `--warp`; ESC: a fixed `--level` (the max level) instead of the camera's.
    pub variant: bool,
    /// ESC's distance-test threshold (`--quality`, `--threshold`).
    pub esc_threshold: Threshold,
    /// Corner parameters, strips and the memory limit asked of the engine.
    pub options: TessellateOptions,
}

/// What [`check_engine`] did with its input, so that tests can see they are not vacuous.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EngineOutcome {
    /// The surface builder, the criterion or the engine refused the case with an error.
    Refused,
    /// The engine produced a consistent mesh; `checked_watertight` when the input was closed
    /// by construction and the output was verified watertight.
    Tessellated { checked_watertight: bool },
}

/// Factors the engine cases stay within, so a case costs microseconds, not seconds.
const MAX_CASE_FACTOR: u32 = 16;

/// Checks the engine: decodes the bytes into an [`EngineCase`] (a small surface set, a
/// scheme with its criterion and factors ≤ 16, a camera; culling off) and builds the plan the
/// way the CLI does. The engine must produce a consistent mesh or an error, strips must
/// decode to the triangle list, and when the shape is closed by construction its topology
/// must say so and the output must have no boundary and no non-manifold edge.
pub fn check_engine(data: &[u8]) -> EngineOutcome {
    let case = decode_engine_case(data);
    run_engine_case(&case)
}

/// Decodes fuzz bytes into an engine case; every input gives one.
pub fn decode_engine_case(data: &[u8]) -> EngineCase {
    let mut d = Decisions { data, pos: 0 };
    let shape = Shape::ALL[d.below(Shape::ALL.len() as u32) as usize];
    let closed_shape = shape.is_watertight_by_construction();
    let dropped = (d.one_in(8) && closed_shape).then(|| d.below(12) as usize);
    let weld = match d.below(4) {
        // Lattice points are at least 2 apart, so this tolerance never merges two of them.
        0 => Weld::Within(0.25),
        1 => Weld::Off,
        _ => Weld::Exact,
    };
    let orientation = if d.one_in(2) { Orientation::Outward } else { Orientation::AsGiven };
    let build = BuildOptions { weld, orientation, flip: d.one_in(4), ..Default::default() };
    let camera = (!d.one_in(3)).then(|| {
        let mut spec = format!(
            "eye={},{},{},target={},{},{},fov={},size={}x{}",
            d.int_in(-40, 40),
            d.int_in(-40, 40),
            d.int_in(-40, 40),
            d.int_in(-3, 3),
            d.int_in(-3, 3),
            d.int_in(-3, 3),
            d.int_in(1, 179),
            d.int_in(1, 2048),
            d.int_in(1, 2048)
        );
        if d.one_in(4) {
            let _ = write!(spec, ",up={},{},{}", d.int_in(-1, 1), d.int_in(-1, 1), d.int_in(-1, 1));
        }
        spec
    });
    let scheme = match d.below(9) {
        0 => Scheme::Uniform,
        1 => Scheme::Transition,
        2 => Scheme::SemiUniform,
        3 => Scheme::Sd2,
        4 => Scheme::Hardware(Partitioning::Integer),
        5 => Scheme::Hardware(Partitioning::Pow2),
        6 => Scheme::Hardware(Partitioning::FractionalOdd),
        7 => Scheme::Hardware(Partitioning::FractionalEven),
        _ => Scheme::Esc,
    };
    let max_level = d.below(5);
    let view_criterion = match d.below(4) {
        0 => ViewCriterion::Distance(Mapping::Linear),
        1 => ViewCriterion::Distance(Mapping::Quadratic),
        2 => ViewCriterion::SilhouetteVertices,
        _ => ViewCriterion::Silhouetteness,
    };
    let top = f64::from(MAX_CASE_FACTOR);
    let criterion = match d.below(4) {
        0 => {
            let (a, b) = (d.factor(1.0, top), d.factor(1.0, top));
            Criterion::View(view_criterion, a.min(b), a.max(b))
        }
        1 => Criterion::Tolerance([0.001, 0.005, 0.02, 0.1][d.below(4) as usize]),
        2 => Criterion::PixelError([0.25, 1.0, 4.0, 32.0][d.below(4) as usize]),
        _ => Criterion::Factor(d.factor(1.0, top)),
    };
    let esc_threshold = match d.below(3) {
        0 => Threshold::High,
        1 => Threshold::Medium,
        _ => Threshold::Absolute(f64::from(d.below(8)) * 0.25),
    };
    let variant = d.one_in(2);
    // Asking a pattern without a strip form for strips is an error, so ask mostly the two
    // patterns that have one.
    let strips = if matches!(scheme, Scheme::Sd2 | Scheme::Esc) { d.one_in(2) } else { d.one_in(8) };
    let options = TessellateOptions {
        corner_params: d.one_in(2),
        memory_limit: Some(1 << 26),
        strips,
        ..TessellateOptions::default()
    };
    // The geometry comes last: it takes most of the bytes, and an input that runs out while
    // jittering points has still chosen its scheme.
    let text = match shape {
        Shape::CubePatches => cube_patches(&mut d, dropped),
        Shape::Spindle => spindle(&mut d, dropped),
        Shape::Torus => torus(&mut d, dropped),
        Shape::Octahedron | Shape::CubeMesh | Shape::Tetrahedron => closed_mesh(&mut d, shape, dropped),
        Shape::RandomPatches => random_patches(&mut d),
        Shape::RandomMesh => random_mesh(&mut d),
    };
    EngineCase {
        shape,
        text,
        dropped,
        build,
        camera,
        scheme,
        criterion,
        max_level,
        variant,
        esc_threshold,
        options,
    }
}

/// A lattice coordinate moved by up to ±1 (lattice points are 4 apart, so moved points never
/// meet).
fn jitter(d: &mut Decisions, v: i32) -> i32 {
    v + d.int_in(-1, 1)
}

/// Control points in the Newell format, with a weight column when `rational`.
fn newell(patches: &[[usize; 16]], points: &[[i32; 3]], weights: Option<&[i32]>) -> String {
    let mut text = format!("{}\n", patches.len());
    for p in patches {
        let indices: Vec<String> = p.iter().map(|i| (i + 1).to_string()).collect();
        text += &indices.join(",");
        text.push('\n');
    }
    let _ = writeln!(text, "{}", points.len());
    for (k, p) in points.iter().enumerate() {
        match weights {
            Some(w) => _ = writeln!(text, "{},{},{},{}", p[0], p[1], p[2], w[k]),
            None => _ = writeln!(text, "{},{},{}", p[0], p[1], p[2]),
        }
    }
    text
}

/// Weights 1 to 3 per point for about a third of the cases (rational patches), else none.
fn weights(d: &mut Decisions, count: usize) -> Option<Vec<i32>> {
    d.one_in(3).then(|| (0..count).map(|_| d.int_in(1, 3)).collect())
}

/// Indexes points by a key, adding each new key's point once, so patches that name the same
/// key share the control point (and their boundary curves by index).
struct PointPool<K> {
    ids: HashMap<K, usize>,
    points: Vec<[i32; 3]>,
}

impl<K: std::hash::Hash + Eq> PointPool<K> {
    fn new() -> Self {
        PointPool { ids: HashMap::new(), points: Vec::new() }
    }

    fn id(&mut self, key: K, point: impl FnOnce() -> [i32; 3]) -> usize {
        let next = self.points.len();
        *self.ids.entry(key).or_insert_with(|| {
            self.points.push(point());
            next
        })
    }
}

fn drop_patch(patches: &mut Vec<[usize; 16]>, dropped: Option<usize>) {
    if let Some(k) = dropped {
        patches.remove(k % patches.len());
    }
}

/// Six patches on the faces of the cube `[-6, 6]³`: face `P[i][j]` on the 4 × 4 lattice of
/// its face, oriented outward; inner points bulge out by up to 3 or in by 1 (never far enough
/// to meet another face's points).
fn cube_patches(d: &mut Decisions, dropped: Option<usize>) -> String {
    let mut pool = PointPool::new();
    let mut patches = Vec::new();
    for axis in 0..3usize {
        for side in [0i32, 3] {
            let outward = if side == 0 { -1 } else { 1 };
            let bulge = d.int_in(-1, 3) * outward;
            let mut patch = [0; 16];
            for i in 0..4i32 {
                for j in 0..4i32 {
                    // The cyclic axes after `axis` make `e1 × e2` point along +axis, so rows
                    // run along e1 on the far side and along e2 on the near side.
                    let (a, b) = if side == 3 { (i, j) } else { (j, i) };
                    let mut lattice = [0i32; 3];
                    lattice[axis] = side;
                    lattice[(axis + 1) % 3] = a;
                    lattice[(axis + 2) % 3] = b;
                    let inner = (1..3).contains(&i) && (1..3).contains(&j);
                    // Boundary points are shared with the neighbouring faces; inner ones not.
                    let key = (lattice, if inner { axis as i32 } else { -1 });
                    patch[(4 * i + j) as usize] = pool.id(key, || {
                        let mut p = lattice.map(|c| jitter(d, 4 * c - 6));
                        if inner {
                            p[axis] += bulge;
                        }
                        p
                    });
                }
            }
            patches.push(patch);
        }
    }
    drop_patch(&mut patches, dropped);
    let w = weights(d, pool.points.len());
    newell(&patches, &pool.points, w.as_deref())
}

/// Four patches around the z axis: row 0 of every patch is the south pole, row 3 the north
/// pole (collapsed edges), rows 1 and 2 walk one side of two square rings.
fn spindle(d: &mut Decisions, dropped: Option<usize>) -> String {
    // The 12 points on the boundary of the square [-6, 6]², 4 apart, counter-clockwise.
    let ring: Vec<[i32; 2]> = (0..12)
        .map(|m| {
            let (side, t) = (m / 3, m % 3);
            let s = -6 + 4 * t;
            match side {
                0 => [s, -6],
                1 => [6, s],
                2 => [-s, 6],
                _ => [-6, -s],
            }
        })
        .collect();
    let mut points = Vec::new();
    points.push([jitter(d, 0), jitter(d, 0), -12 + d.int_in(-2, 2)]);
    points.push([jitter(d, 0), jitter(d, 0), 12 + d.int_in(-2, 2)]);
    for z in [-4, 4] {
        let scale = d.int_in(1, 2);
        for p in &ring {
            points.push([jitter(d, scale * p[0]), jitter(d, scale * p[1]), jitter(d, z)]);
        }
    }
    let mut patches = Vec::new();
    for k in 0..4 {
        let mut patch = [0; 16];
        for t in 0..4 {
            let m = (3 * k + t) % 12;
            patch[t] = 0;
            patch[4 + t] = 2 + m;
            patch[8 + t] = 14 + m;
            patch[12 + t] = 1;
        }
        patches.push(patch);
    }
    drop_patch(&mut patches, dropped);
    let w = weights(d, points.len());
    newell(&patches, &points, w.as_deref())
}

/// Nine patches on a 3 × 3 torus (tube radius 12 around a circle of radius 32, rounded to
/// integers): a closed surface of genus 1 whose patches each meet four others.
fn torus(d: &mut Decisions, dropped: Option<usize>) -> String {
    let mut points = Vec::new();
    for a in 0..9 {
        for b in 0..9 {
            let (theta, phi) =
                (a as f64 * std::f64::consts::TAU / 9.0, b as f64 * std::f64::consts::TAU / 9.0);
            let r = 32.0 + 12.0 * phi.cos();
            let p = [r * theta.cos(), r * theta.sin(), 12.0 * phi.sin()];
            points.push(p.map(|c| jitter(d, c.round() as i32)));
        }
    }
    let mut patches = Vec::new();
    for pa in 0..3 {
        for pb in 0..3 {
            let mut patch = [0; 16];
            for i in 0..4 {
                for j in 0..4 {
                    patch[4 * i + j] = ((3 * pa + i) % 9) * 9 + (3 * pb + j) % 9;
                }
            }
            patches.push(patch);
        }
    }
    drop_patch(&mut patches, dropped);
    let w = weights(d, points.len());
    newell(&patches, &points, w.as_deref())
}

/// A closed triangle mesh on jittered integer vertices, counter-clockwise outward, as OBJ:
/// without normals, with one normal per vertex, or with one per face corner (split normals
/// and creases). Normals are small integer vectors, zero allowed.
fn closed_mesh(d: &mut Decisions, shape: Shape, dropped: Option<usize>) -> String {
    let (corners, mut faces): (Vec<[i32; 3]>, Vec<[usize; 3]>) = match shape {
        Shape::Octahedron => (
            vec![[6, 0, 0], [-6, 0, 0], [0, 6, 0], [0, -6, 0], [0, 0, 6], [0, 0, -6]],
            vec![[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]],
        ),
        Shape::Tetrahedron => (
            vec![[6, 6, 6], [6, -6, -6], [-6, 6, -6], [-6, -6, 6]],
            vec![[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]],
        ),
        _ => {
            let corners = (0..8).map(|k| [k & 1, (k >> 1) & 1, (k >> 2) & 1].map(|c| 12 * c - 6)).collect();
            // Each face counter-clockwise seen from outside.
            let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
            let mut faces = Vec::new();
            for q in quads {
                if d.one_in(2) {
                    faces.extend([[q[0], q[1], q[2]], [q[0], q[2], q[3]]]);
                } else {
                    faces.extend([[q[0], q[1], q[3]], [q[1], q[2], q[3]]]);
                }
            }
            (corners, faces)
        }
    };
    if let Some(k) = dropped {
        faces.remove(k % faces.len());
    }
    let mut text = String::new();
    for c in &corners {
        let p = c.map(|v| v + d.int_in(-2, 2));
        let _ = writeln!(text, "v {} {} {}", p[0], p[1], p[2]);
    }
    let normal_mode = d.below(3);
    let normal_count = match normal_mode {
        0 => 0,
        1 => corners.len(),
        _ => 4,
    };
    for _ in 0..normal_count {
        let _ = writeln!(text, "vn {} {} {}", d.int_in(-2, 2), d.int_in(-2, 2), d.int_in(-2, 2));
    }
    for f in &faces {
        text += "f";
        for &v in f {
            match normal_mode {
                0 => _ = write!(text, " {}", v + 1),
                1 => _ = write!(text, " {}//{}", v + 1, v + 1),
                _ => _ = write!(text, " {}//{}", v + 1, d.below(4) + 1),
            }
        }
        text.push('\n');
    }
    text
}

/// 1 to 8 patches, each of whose 16 control points is any of a pool of 1 to 16 points on the
/// grid `[-2, 2]³`: collapsed, repeated, non-manifold and self-sharing patches.
fn random_patches(d: &mut Decisions) -> String {
    let pool: Vec<[i32; 3]> = (0..1 + d.below(16)).map(|_| [0; 3].map(|_| d.int_in(-2, 2))).collect();
    let patches: Vec<[usize; 16]> =
        (0..1 + d.below(8)).map(|_| [0; 16].map(|_| d.below(pool.len() as u32) as usize)).collect();
    let w = weights(d, pool.len());
    newell(&patches, &pool, w.as_deref())
}

/// 1 to 12 triangles over a pool of 3 to 10 points on the grid `[-2, 2]³`.
fn random_mesh(d: &mut Decisions) -> String {
    let count = 3 + d.below(8);
    let mut text = String::new();
    for _ in 0..count {
        let _ = writeln!(text, "v {} {} {}", d.int_in(-2, 2), d.int_in(-2, 2), d.int_in(-2, 2));
    }
    for _ in 0..1 + d.below(12) {
        let _ = writeln!(text, "f {} {} {}", d.below(count) + 1, d.below(count) + 1, d.below(count) + 1);
    }
    text
}

/// True for the shapes generated as OBJ triangle meshes (PN triangles), false for patches.
fn is_mesh_shape(shape: Shape) -> bool {
    matches!(shape, Shape::Octahedron | Shape::CubeMesh | Shape::Tetrahedron | Shape::RandomMesh)
}

/// Builds the case's surface set, or None when the builder refuses it.
fn build_set(case: &EngineCase) -> Option<SurfaceSet> {
    if is_mesh_shape(case.shape) {
        let mesh = obj::parse_obj(&case.text, label())
            .unwrap_or_else(|e| panic!("generated OBJ does not parse: {e}\n{}", case.text));
        SurfaceSet::pn_from_mesh(&mesh, label(), case.build).ok()
    } else {
        let file = patches::parse_patches(&case.text, label())
            .unwrap_or_else(|e| panic!("generated patches do not parse: {e}\n{}", case.text));
        Some(SurfaceSet::from_patch_file(&file, case.build))
    }
}

/// The plan and pattern for a case, through [`crate::scheme::Scheme::plan`] as the CLI makes
/// them without `--cull`; None where the library refuses the combination or the criterion
/// errs.
fn plan_case(case: &EngineCase, set: &SurfaceSet, camera: &Camera) -> Option<(Plan, Box<dyn Pattern>)> {
    use crate::scheme::{self, PlanOptions};
    let top = f64::from(MAX_CASE_FACTOR);
    let library_scheme = match case.scheme {
        Scheme::Uniform => scheme::Scheme::Uniform,
        Scheme::Transition => scheme::Scheme::Transition,
        Scheme::SemiUniform => scheme::Scheme::SemiUniform { max_level: case.max_level },
        Scheme::Sd2 => scheme::Scheme::Sd2 { warp: case.variant },
        Scheme::Hardware(p) => scheme::Scheme::Hardware(p),
        Scheme::Esc => scheme::Scheme::Esc { max_level: case.max_level.min(3) },
    };
    let integer = matches!(case.scheme, Scheme::Uniform | Scheme::Transition | Scheme::SemiUniform);
    let criterion = match (case.scheme, case.criterion) {
        (Scheme::Esc, _) => scheme::Criterion::Esc {
            threshold: case.esc_threshold,
            level: case.variant.then_some(case.max_level.min(3)),
        },
        // Integer factors only; semi-uniform also needs a power of two.
        (Scheme::SemiUniform, Criterion::Factor(f)) => scheme::Criterion::Factor(f64::from(
            1u32 << (f.round() as u32).max(1).ilog2().min(case.max_level),
        )),
        (_, Criterion::Factor(f)) if integer => scheme::Criterion::Factor(f.round()),
        (Scheme::Hardware(p), Criterion::Factor(f)) => {
            scheme::Criterion::Factor(f.min(top.min(f64::from(p.range().1))))
        }
        (_, Criterion::Factor(f)) => scheme::Criterion::Factor(f),
        (_, Criterion::Tolerance(share)) => {
            let (lo, hi) = set.bounds();
            scheme::Criterion::Tolerance(share * lo.distance(hi))
        }
        (_, Criterion::PixelError(px)) => scheme::Criterion::PixelError(px),
        // The CLI's integer FMIN:FMAX for the integer schemes.
        (_, Criterion::View(criterion, fmin, fmax)) if integer => {
            scheme::Criterion::View { criterion, fmin: fmin.round(), fmax: fmax.round() }
        }
        (_, Criterion::View(criterion, fmin, fmax)) => scheme::Criterion::View { criterion, fmin, fmax },
    };
    let options =
        PlanOptions { camera: Some(*camera), max_factor: MAX_CASE_FACTOR, ..PlanOptions::default() };
    let planned = library_scheme.plan(set, &criterion, &options).ok()?;
    Some((planned.plan, Box::new(planned.pattern)))
}

/// Runs a decoded case through the builder, the criterion and the engine, asserting what
/// [`check_engine`] documents.
pub fn run_engine_case(case: &EngineCase) -> EngineOutcome {
    let Some(set) = build_set(case) else { return EngineOutcome::Refused };
    // `from_patch_file` hands the builder every patch's own 16 points, so without welding no
    // two patches share a curve (`Weld::Off` matches by index only where the builder gets
    // indices: meshes).
    let unshared = case.build.weld == Weld::Off && !is_mesh_shape(case.shape);
    let strict = case.shape.is_watertight_by_construction() && case.dropped.is_none() && !unshared;
    let report = set.topology.report;
    if strict {
        assert!(
            report.is_closed() && report.inconsistently_oriented_edges == 0,
            "a closed, consistently oriented input has topology {report:?}\n{case:#?}"
        );
    }
    let (lo, hi) = set.bounds();
    let default = Camera::framing(lo, hi, 1280, 720);
    // A spec the parser refuses would stop the CLI; the default camera keeps the case useful.
    let camera = case.camera.as_deref().and_then(|s| Camera::parse(s, &default).ok()).unwrap_or(default);
    let Some((plan, pattern)) = plan_case(case, &set, &camera) else { return EngineOutcome::Refused };
    if case.scheme == Scheme::Uniform {
        // The engine trusts the precondition; fuzz/regressions/engine/uniform-* broke it.
        if let Some(why) = uniform_precondition_broken(&set, &plan) {
            panic!("{why}\n{case:#?}");
        }
    }
    assert!(plan.visible.iter().all(|&v| v != 0), "a plan made without culling hides patches\n{case:#?}");
    let Ok(mesh) = engine::tessellate(&set, &plan, pattern.as_ref(), case.options) else {
        return EngineOutcome::Refused;
    };
    assert_mesh_consistent(&mesh, "engine");
    if case.options.corner_params {
        assert!(mesh.corner_params.is_some(), "corner parameters asked for and not filled\n{case:#?}");
    }
    if let Some(strips) = &mesh.strips {
        let nondegenerate = |t: &[u32; 3]| t[0] != t[1] && t[1] != t[2] && t[0] != t[2];
        let listed: Vec<[u32; 3]> =
            (0..mesh.triangle_count()).map(|t| mesh.triangle(t)).filter(nondegenerate).collect();
        let decoded: Vec<[u32; 3]> = strips::decode(strips).into_iter().filter(nondegenerate).collect();
        assert_eq!(
            canonical_triangles(decoded),
            canonical_triangles(listed),
            "the strips do not decode to the triangle list\n{case:#?}"
        );
    }
    let watertight = verify::watertight(&mesh);
    if strict && !(watertight.boundary_edges == 0 && watertight.nonmanifold_edges == 0) {
        panic!("closed input, output not watertight: {watertight:?}\ninput topology {report:?}\n{case:#?}");
    }
    EngineOutcome::Tessellated { checked_watertight: strict }
}

/// Why a plan breaks the [`Uniform`] pattern's precondition (every edge of a patch has
/// `interior[0]` segments), or None. The engine trusts it: a plan that breaks it gives local
/// indices past the patch's vertices (wrong indices in the mesh, or an index panic when
/// corner parameters are asked for).
fn uniform_precondition_broken(set: &SurfaceSet, plan: &Plan) -> Option<String> {
    (0..set.patches.len()).find_map(|p| {
        let corners = set.patches[p].domain().corner_count();
        let segments: Vec<u32> =
            (0..corners).map(|l| plan.segments(set.topology.patch_edges[p][l].edge as usize)).collect();
        let n = plan.interior[p][0];
        segments.iter().any(|&s| s != n).then(|| {
            format!(
                "the plan gives patch {p} interior factors {:?} but edge segments {segments:?}; the \
                 uniform pattern needs every edge at interior[0]",
                plan.interior[p]
            )
        })
    })
}

/// Triangles rotated to start at their smallest index (winding kept), sorted: equal lists
/// hold the same oriented triangles in any order.
fn canonical_triangles(mut triangles: Vec<[u32; 3]>) -> Vec<[u32; 3]> {
    for t in &mut triangles {
        let k = (0..3).min_by_key(|&k| t[k]).unwrap_or(0);
        t.rotate_left(k);
    }
    triangles.sort_unstable();
    triangles
}
