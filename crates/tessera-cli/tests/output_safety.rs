//! What `tessera mesh` writes is what it says: culled output holds only the vertices its
//! triangles use (CPU and GPU engine alike) and `--stats` counts those; the input is never
//! overwritten by accident; a file appears whole or not at all; a large output is announced
//! with its size before the work.

mod common;

use common::{data, scratch, tessera, text};
use std::path::Path;

fn stats(out: &std::process::Output) -> serde_json::Value {
    assert!(out.status.success(), "{}", text(&out.stderr));
    serde_json::from_str(text(&out.stdout).trim()).unwrap_or_else(|e| panic!("{e}: {}", text(&out.stdout)))
}

/// The vertex count of the mesh file at `path` and how many of its vertices the triangles
/// use.
fn ply_vertex_use(path: &Path) -> (usize, usize) {
    let mesh = tessera::io::read_mesh(path).unwrap_or_else(|e| panic!("{e}"));
    let mut used = vec![false; mesh.vertex_count()];
    for &i in &mesh.indices {
        used[i as usize] = true;
    }
    (mesh.vertex_count(), used.iter().filter(|&&u| u).count())
}

#[test]
fn culled_output_holds_only_used_vertices_and_stats_count_them() {
    let dir = scratch("culled-vertices");
    for (model, engine) in [
        ("bench/torus_64x32.patches", "cpu"),
        ("meshes/spot.obj", "cpu"),
        ("bench/torus_64x32.patches", "gpu"),
    ] {
        let input = data(model);
        let out = tessera(
            &[
                "mesh",
                input.to_str().unwrap(),
                "--pixel-error",
                "0.5",
                "--cull",
                "--engine",
                engine,
                "-o",
                "c.ply",
                "--stats",
            ],
            &dir,
        );
        let v = stats(&out);
        assert!(v["culled_patches"].as_u64().unwrap() > 0, "{model}: nothing culled, the test tests nothing");
        let (vertices, used) = ply_vertex_use(&dir.join("c.ply"));
        assert_eq!(used, vertices, "{model} on {engine}: {} of {vertices} vertices unused", vertices - used);
        assert_eq!(
            v["vertices"].as_u64().unwrap() as usize,
            vertices,
            "{model} on {engine}: --stats vertices"
        );
    }
}

#[test]
fn the_input_is_not_overwritten_without_force() {
    let dir = scratch("own-input");
    let input = dir.join("m.obj");
    std::fs::copy(data("meshes/blob.obj"), &input).unwrap();
    let before = std::fs::read(&input).unwrap();
    for output in ["m.obj", "./m.obj", "../own-input-same/../m.obj"] {
        let out = tessera(&["mesh", "m.obj", "-o", output, "--factor", "2"], &dir);
        if output.contains("same") {
            // A path through a folder that does not exist is not the input.
            continue;
        }
        assert_eq!(out.status.code(), Some(2), "-o {output}: {}", text(&out.stderr));
        assert!(text(&out.stderr).contains("that is the input"), "{}", text(&out.stderr));
        assert_eq!(std::fs::read(&input).unwrap(), before, "-o {output} changed the input");
    }
    #[cfg(unix)]
    {
        std::os::unix::fs::symlink(&input, dir.join("link.obj")).unwrap();
        let out = tessera(&["mesh", "m.obj", "-o", "link.obj", "--factor", "2"], &dir);
        assert_eq!(out.status.code(), Some(2), "a link to the input: {}", text(&out.stderr));
    }
    let out = tessera(&["mesh", "m.obj", "-o", "m.obj", "--factor", "2", "--force"], &dir);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let after = std::fs::read(&input).unwrap();
    assert_ne!(after, before, "--force wrote nothing");
    assert!(text(&after).contains("g patch_"), "the input was not replaced by the tessellation");
}

#[test]
fn a_write_replaces_the_file_whole_and_leaves_nothing_else() {
    let dir = scratch("atomic-write");
    let input = data("patches/teapot.patches");
    std::fs::write(dir.join("t.ply"), b"old contents").unwrap();
    let out = tessera(&["mesh", input.to_str().unwrap(), "-o", "t.ply", "--factor", "4"], &dir);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names, vec!["t.ply".to_string()], "a temporary file was left behind: {names:?}");
    assert!(std::fs::read(dir.join("t.ply")).unwrap().starts_with(b"ply\n"));
    // A folder in the output's place: the finished file cannot replace it; the folder and
    // its contents stay, and no temporary file is left.
    std::fs::create_dir(dir.join("d.ply")).unwrap();
    std::fs::write(dir.join("d.ply/keep"), b"x").unwrap();
    let out = tessera(&["mesh", input.to_str().unwrap(), "-o", "d.ply", "--factor", "4"], &dir);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out.stderr));
    assert!(text(&out.stderr).contains("d.ply"), "{}", text(&out.stderr));
    assert!(dir.join("d.ply/keep").exists());
    let names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names.len(), 2, "a temporary file was left behind: {names:?}");
}

#[test]
fn a_large_output_is_announced_with_its_size_before_the_work() {
    let dir = scratch("announce");
    let input = data("bench/torus_64x32.patches");
    // 2048 patches × 2 × 72² = 21.2 M triangles: over the announcement threshold (not
    // written: the note comes before the write either way).
    let out = tessera(&["mesh", input.to_str().unwrap(), "--factor", "72"], &dir);
    let stderr = text(&out.stderr);
    assert!(stderr.contains("note: a large output: 21233664 triangles"), "{stderr}");
    assert!(stderr.contains("GiB in memory"), "{stderr}");
    let small = tessera(&["mesh", input.to_str().unwrap(), "--factor", "4"], &dir);
    assert!(!text(&small.stderr).contains("a large output"), "{}", text(&small.stderr));
}
