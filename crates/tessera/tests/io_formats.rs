//! Every input and output format end to end: write → read gives the same mesh or surfaces,
//! glTF and Bézier-triangle inputs of closed models give closed outputs, and malformed files
//! give typed errors naming the file.

mod common;

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use glam::DVec3;
use tessera::criterion::Plan;
use tessera::engine::{self, EngineOptions};
use tessera::io::bezt::{self, BezierTriangleFile};
use tessera::io::{self, glb, patches};
use tessera::mesh::Mesh;
use tessera::pattern::uniform::Uniform;
use tessera::surface::{BuildOptions, Patch, SurfaceSet};
use tessera::{verify, Error};

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("tessera-io-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A closed model tessellated uniformly, with corner params: a mesh using every attribute.
fn tessellated(rel: &str, factor: u32) -> (SurfaceSet, Mesh) {
    let set = io::load(&common::model(rel), BuildOptions::default()).unwrap();
    let plan = Plan::uniform(&set, factor).unwrap();
    let opts = EngineOptions { corner_params: true, ..Default::default() };
    let mesh = engine::tessellate(&set, &plan, &Uniform, opts).unwrap();
    (set, mesh)
}

fn tessellate(set: &SurfaceSet, factor: u32) -> Mesh {
    let plan = Plan::uniform(set, factor).unwrap();
    engine::tessellate(set, &plan, &Uniform, EngineOptions::default()).unwrap()
}

/// The triangles as position triples, for formats that renumber vertices.
fn triangle_positions(mesh: &Mesh) -> Vec<[[f32; 3]; 3]> {
    (0..mesh.triangle_count()).map(|t| mesh.triangle(t).map(|i| mesh.positions[i as usize])).collect()
}

#[test]
fn every_mesh_format_round_trips() {
    let dir = scratch("round-trip");
    let (_, mesh) = tessellated("meshes/dragknob.obj", 3);
    // PLY and GLB keep everything.
    for name in ["m.ply", "m.glb"] {
        let path = dir.join(name);
        io::write_mesh(&mesh, &path).unwrap();
        assert_eq!(io::read_mesh(&path).unwrap(), mesh, "{name}");
    }
    // OBJ keeps positions (shortest round-trip text) and the triangles.
    let path = dir.join("m.obj");
    io::write_mesh(&mesh, &path).unwrap();
    let back = io::read_mesh(&path).unwrap();
    assert_eq!((&back.positions, &back.indices), (&mesh.positions, &mesh.indices));
    // STL keeps the triangles' positions; vertices are welded by position.
    let path = dir.join("m.stl");
    io::write_mesh(&mesh, &path).unwrap();
    let back = io::read_mesh(&path).unwrap();
    assert_eq!(triangle_positions(&back), triangle_positions(&mesh));
    assert_eq!(verify::watertight(&back).boundary_edges, 0);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn patch_files_round_trip_through_their_text() {
    for rel in ["patches/teapot.patches", "patches/teacup.patches"] {
        let file = patches::read_patches(&common::model(rel)).unwrap();
        let again = patches::parse_patches(&patches::to_patches_text(&file), Path::new("<text>")).unwrap();
        assert_eq!(
            (&again.patches, &again.points, &again.weights),
            (&file.patches, &file.points, &file.weights)
        );
    }
}

/// A closed model's PN triangles as cubic Bézier triangles with control points shared by
/// index (equal bits, one point): the `.bezt` file of a closed surface.
fn bezier_file_of(rel: &str) -> BezierTriangleFile {
    let set = io::load(&common::model(rel), BuildOptions::default()).unwrap();
    let mut ids: HashMap<[u64; 3], u32> = HashMap::new();
    let mut file = BezierTriangleFile { triangles: Vec::new(), points: Vec::new(), lines: Vec::new() };
    for p in &set.patches {
        let Patch::Pn(pn) = p else { panic!("{rel} gives PN triangles") };
        let idx = pn.geometry.points.map(|q: DVec3| {
            *ids.entry(q.to_array().map(f64::to_bits)).or_insert_with(|| {
                file.points.push(q);
                file.points.len() as u32 - 1
            })
        });
        file.triangles.push(idx);
        file.lines.push(0);
    }
    file
}

#[test]
fn bezier_triangles_of_a_closed_model_round_trip_and_tessellate_closed() {
    let dir = scratch("bezt");
    let file = bezier_file_of("meshes/blob.obj");
    let path = dir.join("blob.bezt");
    std::fs::write(&path, bezt::to_bezt_text(&file)).unwrap();
    let back = bezt::read_bezt(&path).unwrap();
    assert_eq!((&back.triangles, &back.points), (&file.triangles, &file.points));

    let set = io::load(&path, BuildOptions::default()).unwrap();
    assert_eq!(set.patches.len(), file.triangles.len());
    assert!(set.topology.report.is_closed(), "{:?}", set.topology.report);
    for factor in [1, 4] {
        let w = verify::watertight(&tessellate(&set, factor));
        assert!(w.is_closed(), "factor {factor}: {w:?}");
        assert_eq!(w.euler_characteristic, 2);
        assert_eq!(w.degenerate_triangles(), 0);
    }
    // The same surface as PN triangles: identical geometry, so identical vertices.
    let pn = io::load(&common::model("meshes/blob.obj"), BuildOptions::default()).unwrap();
    assert_eq!(tessellate(&set, 3).positions.len(), tessellate(&pn, 3).positions.len());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn gltf_of_a_closed_mesh_gives_a_closed_output() {
    let dir = scratch("gltf-closed");
    for rel in ["meshes/blob.obj", "meshes/helmet.obj"] {
        // The input mesh itself, converted with tessera's own GLB writer.
        let input = io::read_mesh(&common::model(rel)).unwrap();
        let path = dir.join("input.glb");
        io::write_mesh(&input, &path).unwrap();
        let from_glb = io::load(&path, BuildOptions::default()).unwrap();
        let from_obj = io::load(&common::model(rel), BuildOptions::default()).unwrap();
        assert_eq!(from_glb.patches.len(), from_obj.patches.len(), "{rel}");
        assert_eq!(from_glb.topology.report, from_obj.topology.report, "{rel}");
        let mesh = tessellate(&from_glb, 4);
        let w = verify::watertight(&mesh);
        assert!(w.is_closed(), "{rel}: {w:?}");
        assert_eq!(w.euler_characteristic, from_obj.topology.report.euler_characteristic, "{rel}");
        assert_eq!(mesh.positions.len(), tessellate(&from_obj, 4).positions.len(), "{rel}: as from the OBJ");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A `.gltf` text file with one triangle-pair mesh instanced by two nodes (one mirrored), its
/// buffer in `buffer.bin` (or, with `embed`, in a data: URI), normals included.
fn gltf_text(embed: bool) -> (String, Vec<u8>) {
    let mut bin = Vec::new();
    for p in [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]] {
        bin.extend(p.iter().flat_map(|c| c.to_le_bytes()));
    }
    for _ in 0..4 {
        bin.extend([0.0f32, 0.0, 1.0].iter().flat_map(|c| c.to_le_bytes()));
    }
    for i in [0u16, 1, 2, 0, 2, 3] {
        bin.extend(i.to_le_bytes());
    }
    let uri = if embed {
        format!("data:application/octet-stream;base64,{}", base64(&bin))
    } else {
        "buffer%2Ebin".to_string()
    };
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0,1]}}],
        "nodes":[{{"mesh":0,"translation":[10,0,0]}},{{"mesh":0,"scale":[-1,1,1]}}],
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0,"NORMAL":1}},"indices":2}}]}}],
        "buffers":[{{"byteLength":{},"uri":"{uri}"}}],
        "bufferViews":[{{"buffer":0,"byteLength":48}},{{"buffer":0,"byteOffset":48,"byteLength":48}},
                       {{"buffer":0,"byteOffset":96,"byteLength":12}}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}},
                     {{"bufferView":1,"componentType":5126,"count":4,"type":"VEC3"}},
                     {{"bufferView":2,"componentType":5123,"count":6,"type":"SCALAR"}}]}}"#,
        bin.len()
    );
    (json, bin)
}

fn base64(bytes: &[u8]) -> String {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for c in bytes.chunks(3) {
        let n = (u32::from(c[0]) << 16)
            | (u32::from(*c.get(1).unwrap_or(&0)) << 8)
            | u32::from(*c.get(2).unwrap_or(&0));
        for k in 0..4 {
            if k <= c.len() {
                out.push(A[(n >> (18 - 6 * k)) as usize & 63] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

#[test]
fn gltf_text_files_with_external_or_embedded_buffers_and_transforms() {
    let dir = scratch("gltf-text");
    for embed in [false, true] {
        let (json, bin) = gltf_text(embed);
        let path = dir.join("quad.gltf");
        std::fs::write(&path, json).unwrap();
        std::fs::write(dir.join("buffer.bin"), &bin).unwrap();
        let mesh = glb::read_gltf_triangles(&path, Default::default()).unwrap();
        assert_eq!(mesh.positions.len(), 8, "two instances of 4 vertices");
        assert_eq!(mesh.faces.len(), 4);
        // Node 0 is translated; node 1 mirrored in x, so its normals stay +z after the
        // inverse transpose and its winding is reversed to keep facing them.
        let xs: Vec<f64> = mesh.positions.iter().map(|p| p.x).collect();
        assert_eq!(xs.iter().filter(|&&x| x >= 10.0).count(), 4, "{xs:?}");
        assert_eq!(xs.iter().filter(|&&x| x <= 0.0).count(), 4, "{xs:?}");
        for face in &mesh.faces {
            let [a, b, c] = [0, 1, 2].map(|k| mesh.positions[face.positions[k] as usize]);
            let n = mesh.normals[face.normals.as_ref().unwrap()[0] as usize];
            assert!((b - a).cross(c - a).dot(n) > 0.0, "winding agrees with the normals");
        }
        let set = io::load(&path, BuildOptions::default()).unwrap();
        assert_eq!(set.patches.len(), 4);
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The file and reason of an error, failing on an untyped one.
fn located(e: Error) -> (PathBuf, String) {
    match e {
        Error::Parse { at, reason } | Error::Unsupported { at, reason } => (at.file, reason),
        Error::Io { path, source } => (path, source.to_string()),
        Error::Referenced { file, referenced, what, source } => {
            (file, format!("{what}: {}: {source}", referenced.display()))
        }
        other => panic!("expected an error naming the file, got {other:?}"),
    }
}

#[test]
fn malformed_inputs_give_typed_errors_naming_the_file() {
    let dir = scratch("malformed");
    let (json, bin) = gltf_text(false);
    std::fs::write(dir.join("buffer.bin"), &bin).unwrap();
    let cases: Vec<(&str, Vec<u8>, &str)> = vec![
        ("a.glb", b"glTF\x02\0\0\0".to_vec(), "invalid glTF"),
        ("b.gltf", b"{\"asset\":".to_vec(), "invalid glTF"),
        ("c.gltf", json.replace("\"count\":6", "\"count\":600").into_bytes(), "do not fit"),
        (
            "d.gltf",
            json.replace("\"count\":4,\"type\":\"VEC3\",\"min\"", "\"count\":0,\"type\":\"VEC3\",\"min\"")
                .into_bytes(),
            "count 0",
        ),
        (
            "e.gltf",
            json.replace("\"POSITION\":0", "\"POSITION\":9").into_bytes(),
            "POSITION refers to accessor 9",
        ),
        ("f.gltf", json.replace("\"nodes\":[0,1]", "\"nodes\":[0,0]").into_bytes(), "appears twice"),
        ("g.gltf", json.replace("buffer%2Ebin", "missing.bin").into_bytes(), "No such file"),
        ("h.gltf", json.replace("5123", "5126").into_bytes(), "expected one of"),
        (
            "q.gltf",
            json.replace("\"translation\":[10,0,0]", "\"rotation\":[0,0,0,0]").into_bytes(),
            "glTF rotations are unit quaternions",
        ),
        (
            "p.gltf",
            json.replace("\"translation\":[10,0,0]", "\"matrix\":[1,0,0,1,0,1,0,0,0,0,1,0,0,0,0,1]")
                .into_bytes(),
            "projective matrix",
        ),
        ("i.bezt", b"1\n1,2,3\n".to_vec(), "expected 10 comma-separated indices"),
        ("j.patches", b"1\n1,2\n".to_vec(), "expected 16 comma-separated indices"),
        ("k.obj", b"v 0 0 0\nf 1 2 3\n".to_vec(), "out of range"),
        (
            "l.ply",
            b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\n".to_vec(),
            "no property y",
        ),
        ("m.stl", b"solid x\nfacet\n".to_vec(), ""),
    ];
    for (name, bytes, needle) in cases {
        let path = dir.join(name);
        std::fs::write(&path, bytes).unwrap();
        let err = io::load(&path, BuildOptions::default()).unwrap_err();
        let message = err.to_string();
        let (file, reason) = located(err);
        assert_eq!(file, path, "{name}: {message}");
        assert!(message.contains(&path.display().to_string()), "{message}");
        if name == "g.gltf" {
            // A buffer's error names the buffer's file too.
            assert!(message.contains(&dir.join("missing.bin").display().to_string()), "{message}");
        }
        assert!(reason.contains(needle), "{name}: {reason:?} lacks {needle:?}");
    }
    let err = io::load(&dir.join("x.txt"), BuildOptions::default()).unwrap_err();
    assert!(
        matches!(&err, Error::UnknownFormat { supported, .. } if supported.contains(".bezt") && supported.contains(".gltf")),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn gltf_primitives_that_are_no_surface_are_counted_not_dropped_silently() {
    let dir = scratch("gltf-lines");
    let (json, bin) = gltf_text(false);
    std::fs::write(dir.join("buffer.bin"), &bin).unwrap();
    let with_lines = json.replace(
        "\"indices\":2}]",
        "\"indices\":2},{\"attributes\":{\"POSITION\":0},\"indices\":2,\"mode\":1}]",
    );
    assert_ne!(with_lines, json, "the edit did not apply");
    for (name, text, skipped) in [("plain.gltf", &json, 0), ("lines.gltf", &with_lines, 1)] {
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        // Two nodes instance the mesh: its LINES primitive counts once.
        let set = io::load(&path, BuildOptions::default()).unwrap();
        assert_eq!(set.repairs.skipped_primitives, skipped, "{name}");
        assert_eq!(set.patches.len(), 4, "{name}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
