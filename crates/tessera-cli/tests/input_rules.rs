//! One rule for every input format, and inputs refused with the reason rather than misread:
//! as PN triangles, polygons are split into triangles the same way for OBJ and PLY and
//! reported as a repair; an OBJ with polygons is a subdivision cage by default.

mod common;

use common::{data, scratch, tessera, text};

/// A unit cube of six quads (outward), as OBJ and as ASCII PLY.
fn cube(dir: &std::path::Path) -> (String, String) {
    let v = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]];
    let f = [[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]];
    let mut obj = String::new();
    let mut ply = String::from(
        "ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\nproperty float y\nproperty float z\n\
         element face 6\nproperty list uchar int vertex_indices\nend_header\n",
    );
    for p in v {
        obj += &format!("v {} {} {}\n", p[0], p[1], p[2]);
        ply += &format!("{} {} {}\n", p[0], p[1], p[2]);
    }
    for q in f {
        obj += &format!("f {} {} {} {}\n", q[0] + 1, q[1] + 1, q[2] + 1, q[3] + 1);
        ply += &format!("4 {} {} {} {}\n", q[0], q[1], q[2], q[3]);
    }
    std::fs::write(dir.join("cube.obj"), obj).unwrap();
    std::fs::write(dir.join("cube.ply"), ply).unwrap();
    ("cube.obj".into(), "cube.ply".into())
}

#[test]
fn polygons_are_split_alike_in_obj_and_ply_and_reported() {
    let dir = scratch("polygon-rule");
    let (obj, ply) = cube(&dir);
    let mut results = Vec::new();
    for input in [&obj, &ply] {
        let out =
            tessera(&["mesh", input, "--surface", "pn", "--factor", "3", "--stats", "-o", "out.ply"], &dir);
        assert!(out.status.success(), "{input}: {}", text(&out.stderr));
        let stderr = text(&out.stderr);
        assert!(
            stderr.contains("repair: 6 input polygons split into triangles"),
            "{input}: no repair line: {stderr}"
        );
        let v: serde_json::Value = serde_json::from_str(text(&out.stdout).trim()).unwrap();
        assert_eq!(v["repairs"]["split_polygons"], 6, "{input}");
        assert_eq!(v["patches"], 12, "{input}");
        assert_eq!(v["boundary_edges"], 0, "{input}: the split cube is not closed");
        results.push((
            v["triangles"].clone(),
            v["vertices"].clone(),
            std::fs::read(dir.join("out.ply")).unwrap(),
        ));
    }
    assert_eq!(results[0], results[1], "OBJ and PLY quads gave different meshes");
    // The checker reads OBJ polygons by the same rule.
    let check = tessera(&["check", &obj], &dir);
    assert!(check.status.success(), "{}", text(&check.stderr));
    assert!(text(&check.stdout).contains("boundary edges       0"), "{}", text(&check.stdout));
    // `--surface auto` (the default): the OBJ's quads are a Catmull-Clark cage, said on stderr;
    // the PLY's polygons, which its reader fans, stay PN triangles; asking for Catmull-Clark on
    // them is refused with the reason rather than subdividing the fans.
    let out = tessera(&["mesh", &obj, "--factor", "3", "--stats"], &dir);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(text(&out.stderr).contains("Catmull-Clark limit surface (6 patches"), "{}", text(&out.stderr));
    let v: serde_json::Value = serde_json::from_str(text(&out.stdout).trim()).unwrap();
    assert_eq!((v["patches"].as_u64(), v["boundary_edges"].as_u64()), (Some(6), Some(0)));
    let out = tessera(&["mesh", &ply, "--factor", "3", "--stats"], &dir);
    assert!(text(&out.stderr).contains("repair: 6 input polygons split"), "{}", text(&out.stderr));
    let out = tessera(&["mesh", &ply, "--surface", "catmull-clark"], &dir);
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains("give the cage as .obj"), "{}", text(&out.stderr));
    // Loop subdivides triangles only: the quads are refused, naming the face's line.
    let out = tessera(&["mesh", &obj, "--surface", "loop"], &dir);
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains("Loop subdivision needs triangles"), "{}", text(&out.stderr));
    assert!(text(&out.stderr).contains("cube.obj:9:"), "{}", text(&out.stderr));
}

/// A subdivision cage's tag lines are read (a bad one is an error naming its line) and, as PN
/// triangles do not use them, reported as not used.
#[test]
fn opensubdiv_tags_are_read_and_reported_unused_by_pn_triangles() {
    let dir = scratch("cage-tags");
    // catmark_cube_creases1: 12 crease lines and an interpolateboundary line.
    let cage = data("subdivision/catmark_cube_creases1.obj");
    let out = tessera(&["mesh", cage.to_str().unwrap(), "--surface", "pn", "--factor", "2", "--stats"], &dir);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(text(&out.stderr).contains("repair: 13 OpenSubdiv tag lines"), "{}", text(&out.stderr));
    let v: serde_json::Value = serde_json::from_str(text(&out.stdout).trim()).unwrap();
    assert_eq!(v["repairs"]["ignored_tag_lines"], 13);
    // As the Catmull-Clark cage it is, the tags shape the surface: nothing is reported unused.
    let out = tessera(&["mesh", cage.to_str().unwrap(), "--factor", "2", "--stats"], &dir);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(!text(&out.stderr).contains("tag lines"), "{}", text(&out.stderr));
    let v: serde_json::Value = serde_json::from_str(text(&out.stdout).trim()).unwrap();
    assert_eq!(v["repairs"]["ignored_tag_lines"], 0);
    // A crease between two vertices that share no edge: refused, naming the line.
    let mut bad = std::fs::read_to_string(&cage).unwrap();
    if !bad.ends_with('\n') {
        bad.push('\n');
    }
    bad.push_str("t crease 2/1/0 0 7 2.0\n");
    std::fs::write(dir.join("bad.obj"), &bad).unwrap();
    let refused = tessera(&["mesh", "bad.obj", "--factor", "2"], &dir);
    assert_eq!(refused.status.code(), Some(2));
    let line = bad.lines().count();
    let expected = format!("bad.obj:{line}: tag `crease` names vertices 0 and 7, which share no face edge");
    assert!(text(&refused.stderr).contains(&expected), "{}", text(&refused.stderr));
}

#[test]
fn the_default_camera_takes_the_formats_up_axis_and_says_so() {
    let dir = scratch("up-axis");
    for (model, note) in [
        ("meshes/spot.obj", "note: the camera takes +Y as up (the usual OBJ convention)"),
        ("patches/teapot.patches", "note: the camera takes +Z as up"),
    ] {
        let input = data(model);
        let out = tessera(&["mesh", input.to_str().unwrap(), "--pixel-error", "4"], &dir);
        assert!(out.status.success(), "{model}: {}", text(&out.stderr));
        assert!(text(&out.stderr).contains(note), "{model}: {}", text(&out.stderr));
        // A camera with its own up says nothing; a factor needs no camera.
        for args in [&["--pixel-error", "4", "--camera", "up=0,0,1"][..], &["--factor", "2"][..]] {
            let out = tessera(&[&["mesh", input.to_str().unwrap()][..], args].concat(), &dir);
            assert!(!text(&out.stderr).contains("as up"), "{model} {args:?}: {}", text(&out.stderr));
        }
    }
}

#[test]
fn small_inconsistencies_are_gone() {
    let dir = scratch("small-inconsistencies");
    // demo's picture is PNG, so a .jpg name is refused as render refuses it.
    let out = tessera(&["demo", "--picture", "p.jpg"], &dir);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out.stderr));
    assert!(text(&out.stderr).contains("give a .png name"), "{}", text(&out.stderr));
    assert!(!dir.join("p.jpg").exists());
    // ESC level 0 (the 18 coarse triangles) is a pattern as it is a mesh level.
    let out =
        tessera(&["pattern", "--scheme", "esc", "--domain", "quad", "--level", "0", "-o", "e.json"], &dir);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("e.json")).unwrap()).unwrap();
    assert_eq!(json["triangles"].as_array().unwrap().len(), 18);
    let out =
        tessera(&["pattern", "--scheme", "esc", "--domain", "quad", "--level", "7", "-o", "e.json"], &dir);
    assert!(text(&out.stderr).contains("use 0 to 6"), "{}", text(&out.stderr));
    // A folder is no file "without an extension".
    std::fs::create_dir_all(dir.join("models")).unwrap();
    let out = tessera(&["mesh", "models"], &dir);
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains("is a folder, not an input file"), "{}", text(&out.stderr));
    // An index too long for any integer type is out of range, not "not an integer".
    std::fs::write(dir.join("big.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99999999999999999999\n").unwrap();
    let out = tessera(&["mesh", "big.obj"], &dir);
    assert!(text(&out.stderr).contains("big.obj:4"), "{}", text(&out.stderr));
    assert!(text(&out.stderr).contains("out of range"), "{}", text(&out.stderr));
}

/// A `.ply` from the GPU engine carries the per-corner patch parameters (`patch_uv`) the CPU
/// engine writes, so `tessera check --against` measures its error as the CPU's: the same
/// report, a CPU plan drawn on the GPU and a frame planned on the GPU from the camera.
#[test]
fn gpu_ply_output_carries_the_cpus_corner_parameters() {
    let dir = scratch("gpu-ply");
    let input = data("patches/teapot.patches");
    let input = input.to_str().unwrap();
    let cases: [&[&str]; 2] =
        [&["--factor", "2"], &["--scheme", "transition", "--pixel-error", "2", "--cull"]];
    for case in cases {
        let mut reports = Vec::new();
        for engine in ["cpu", "gpu"] {
            let out = tessera(&[&["mesh", input, "--engine", engine, "-o", "m.ply"], case].concat(), &dir);
            assert!(out.status.success(), "{}", text(&out.stderr));
            assert!(!text(&out.stderr).contains("patch_uv"), "{}", text(&out.stderr));
            // (A culled frame fails the check's topology comparison, as it should: the same
            // way on both engines.)
            let check = tessera(&["check", "m.ply", "--against", input], &dir);
            let report = format!("{:?}\n{}", check.status.code(), text(&check.stdout));
            assert!(report.contains("max error"), "{report}");
            reports.push(report);
        }
        // Equal but for the errors' last digits (the GPU's positions are its own f32
        // evaluations, within 1e-5 of the diagonal of the CPU's).
        let error = |r: &str, key: &str| -> f64 {
            let line = r.lines().find(|l| l.starts_with(key)).unwrap();
            line[key.len()..].trim().parse().unwrap()
        };
        fn rest(r: &str) -> Vec<&str> {
            r.lines().filter(|l| !l.contains(" error ")).collect()
        }
        assert_eq!(rest(&reports[0]), rest(&reports[1]), "{case:?}");
        for key in ["max error", "rms error"] {
            let (c, g) = (error(&reports[0], key), error(&reports[1], key));
            assert!(c > 0.0 && (g - c).abs() <= 1e-3 * c, "{case:?}: {key} {g} on the GPU, {c} on the CPU");
        }
    }
}

/// `tessera check --against CAGE` measures a tessellation of a subdivision cage against the
/// cage's limit surface, and the error is within the bound `--stats` guaranteed.
#[test]
fn check_measures_a_cage_tessellation_against_its_limit_surface() {
    let dir = scratch("cage-check");
    let cage = data("subdivision/catmark_cube.obj");
    let cage = cage.to_str().unwrap();
    let out = tessera(&["mesh", cage, "--tolerance", "0.1%", "--stats", "-o", "cube.ply"], &dir);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let v: serde_json::Value = serde_json::from_str(text(&out.stdout).trim()).unwrap();
    let bound = v["guaranteed_bound"].as_f64().expect("a tolerance run reports its bound");
    assert_eq!(v["problems"].as_array().map(|p| p.len()), Some(0), "{v}");
    let check = tessera(&["check", "cube.ply", "--against", cage], &dir);
    assert!(check.status.success(), "{}", text(&check.stdout));
    let report = text(&check.stdout);
    let max = report
        .lines()
        .find(|l| l.starts_with("max error"))
        .and_then(|l| l.split_whitespace().last())
        .and_then(|x| x.parse::<f64>().ok())
        .unwrap_or_else(|| panic!("no max error line in {report}"));
    assert!(max > 0.0 && max <= bound, "measured {max} against the bound {bound}");
}
