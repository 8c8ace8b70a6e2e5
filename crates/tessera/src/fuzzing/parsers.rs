//! The parser checks: each reader on arbitrary bytes, its output's invariants and the
//! writers' round trips, and `--camera` parsing.

use std::path::Path;

use glam::DVec3;

use crate::camera::Camera;
use crate::error::Result;
use crate::io::bezt;
use crate::io::glb::{self, parse_glb, write_glb};
use crate::io::obj;
use crate::io::obj::write_obj;
use crate::io::patches;
use crate::io::ply::{parse_ply, write_ply};
use crate::io::stl::{parse_stl, write_stl};
use crate::mesh::Mesh;
use crate::surface::PolygonMesh;
use crate::surface::{BuildOptions, SurfaceSet};

use super::*;

/// Checks the OBJ reader: [`obj::parse_obj`] on the bytes (decoded as `read_obj` does, with
/// invalid UTF-8 replaced). A parsed mesh must keep its documented invariants, must build its
/// Catmull-Clark and Loop surfaces (a cage with tags) and PN triangles or refuse them with an
/// error, and, as a triangle list, must survive [`write_obj`] → [`obj::parse_obj`] with the
/// same positions and triangles.
pub fn check_obj(data: &[u8]) {
    let text = String::from_utf8_lossy(data);
    let Ok(mesh) = obj::parse_obj(&text, label()) else { return };
    assert_obj_invariants(&mesh);
    if mesh.faces.len() <= ENGINE_PATCH_LIMIT {
        let options = crate::subdivision::CageOptions::default();
        if let Ok(set) = SurfaceSet::from_subdivision_cage(&mesh, label(), options) {
            tessellate_small(&set);
        }
        // The same cage under Loop's rules (refused, not a panic, where a face is not a
        // triangle).
        if let Ok(set) = SurfaceSet::from_loop_cage(&mesh, label(), options) {
            tessellate_small(&set);
        }
    }
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
    // Tags are checked against the cage: every index in range, every sharpness ≥ 0.
    let tags = &mesh.tags;
    let vertices = mesh.positions.len();
    for c in &tags.creases {
        assert!(
            c.vertices.iter().all(|&v| (v as usize) < vertices),
            "line {}: crease vertex out of range",
            c.line
        );
        assert!(
            c.sharpness.is_finite() && c.sharpness >= 0.0,
            "line {}: crease sharpness {}",
            c.line,
            c.sharpness
        );
    }
    for c in &tags.corners {
        assert!((c.vertex as usize) < vertices, "line {}: corner vertex out of range", c.line);
        assert!(
            c.sharpness.is_finite() && c.sharpness >= 0.0,
            "line {}: corner sharpness {}",
            c.line,
            c.sharpness
        );
    }
    assert!(tags.holes.iter().all(|&f| (f as usize) < mesh.faces.len()), "hole face out of range");
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
