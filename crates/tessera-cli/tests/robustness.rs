//! Issue 10, "never silently wrong": each case here came out wrong with exit status 0 and
//! nothing on stderr (or crashed) before; now it is refused with a clear line, repaired and
//! reported, or warned about with exit status 1.

mod common;

use common::{data, scratch, tessera, text};
use std::path::{Path, PathBuf};

fn run(args: &[&str], dir: &Path) -> (Option<i32>, String, String) {
    let out = tessera(args, dir);
    let err = text(&out.stderr);
    assert!(!err.contains("panicked"), "{args:?}: {err}");
    (out.status.code(), text(&out.stdout), err)
}

fn stats(stdout: &str) -> serde_json::Value {
    serde_json::from_str(stdout.trim()).unwrap_or_else(|e| panic!("not one JSON line ({e}): {stdout}"))
}

/// A Newell patch file of `patches` (16 one-based indices each) over `points`.
fn patch_file(dir: &Path, name: &str, patches: &[[usize; 16]], points: &[[f64; 3]]) -> PathBuf {
    let mut t = format!("{}\n", patches.len());
    for p in patches {
        t += &p.iter().map(|i| i.to_string()).collect::<Vec<_>>().join(",");
        t += "\n";
    }
    t += &format!("{}\n", points.len());
    for p in points {
        t += &format!("{:.17e},{:.17e},{:.17e}\n", p[0], p[1], p[2]);
    }
    let path = dir.join(name);
    std::fs::write(&path, t).unwrap();
    path
}

fn flat_grid(offset: [f64; 3]) -> Vec<[f64; 3]> {
    (0..16).map(|k| [offset[0] + (k / 4) as f64, offset[1] + (k % 4) as f64, offset[2]]).collect()
}

/// Item 1: absurd factors inside the advertised range are refused at once, with the
/// estimate, the memory it needs and the flag — before any pattern or buffer of that size.
#[test]
fn absurd_outputs_are_refused_before_allocating() {
    let dir = scratch("size");
    let teapot = data("patches/teapot.patches");
    let t = teapot.to_str().unwrap();
    for args in [
        vec!["mesh", t, "--factor", "16384", "-o", "x.obj"],
        vec!["mesh", t, "--tolerance", "1e-30", "--max-factor", "16384", "-o", "x.obj"],
        vec!["mesh", t, "--pixel-error", "1e-9", "--max-factor", "16384"],
        vec!["mesh", t, "--factor", "64", "--max-triangles", "1000"],
    ] {
        let (code, _, err) = run(&args, &dir);
        assert_eq!(code, Some(2), "{args:?}: {err}");
        assert!(
            err.contains("output too large") && err.contains("GiB") && err.contains("--max-triangles"),
            "{err}"
        );
        assert!(!dir.join("x.obj").exists(), "{args:?} wrote a file");
    }
    let (code, ..) = run(&["mesh", t, "--factor", "8", "--max-triangles", "1000000"], &dir);
    assert_eq!(code, Some(0));
}

/// Item 3: a patch collapsed to a point is dropped and reported; a weld that collapses the
/// whole model is an error; a zero-area input triangle is dropped and reported.
#[test]
fn degenerate_geometry_is_repaired_or_refused() {
    let dir = scratch("degenerate");
    let mut points = flat_grid([0.0; 3]);
    points.extend(std::iter::repeat_n([10.0, 10.0, 10.0], 16));
    let first: [usize; 16] = std::array::from_fn(|k| k + 1);
    let second: [usize; 16] = std::array::from_fn(|k| k + 17);
    let file = patch_file(&dir, "collapsed.patches", &[first, second], &points);
    let (code, out, err) = run(&["mesh", file.to_str().unwrap(), "--factor", "8", "--stats"], &dir);
    assert_eq!(code, Some(0), "{err}");
    assert!(err.contains("repair: 1 input patches dropped: all their control points are one point"), "{err}");
    let v = stats(&out);
    assert_eq!(v["degenerate_triangles"], 0);
    assert_eq!(v["patches"], 1);
    assert_eq!(v["repairs"]["dropped_collapsed_patches"], 1);

    let teapot = data("patches/teapot.patches");
    let (code, _, err) = run(&["mesh", teapot.to_str().unwrap(), "--weld", "100", "--factor", "4"], &dir);
    assert_eq!(code, Some(2));
    assert!(err.contains("no usable patch") && err.contains("welding within 100"), "{err}");
    // A weld that collapses part of the model: the broken output is written, but not silently.
    let (code, _, err) = run(&["mesh", teapot.to_str().unwrap(), "--weld", "0.5", "--factor", "4"], &dir);
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("warning: the mesh has") && err.contains("degenerate triangles"), "{err}");

    // An octahedron plus an isolated zero-area triangle.
    let mut obj = String::new();
    for v in ["1 0 0", "-1 0 0", "0 1 0", "0 -1 0", "0 0 1", "0 0 -1", "3 0 0", "4 0 0", "5 0 0"] {
        obj += &format!("v {v}\n");
    }
    for f in ["1 3 5", "3 2 5", "2 4 5", "4 1 5", "3 1 6", "2 3 6", "4 2 6", "1 4 6", "7 8 9"] {
        obj += &format!("f {f}\n");
    }
    let path = dir.join("zero_area.obj");
    std::fs::write(&path, obj).unwrap();
    let (code, out, err) = run(&["mesh", path.to_str().unwrap(), "--factor", "8", "--stats"], &dir);
    assert_eq!(code, Some(0), "{err}");
    assert!(err.contains("repair: 1 input faces dropped: zero area"), "{err}");
    let v = stats(&out);
    assert_eq!((v["boundary_edges"].as_u64(), v["nonmanifold_edges"].as_u64()), (Some(0), Some(0)), "{v}");
    assert_eq!((v["degenerate_triangles"].as_u64(), v["euler_characteristic"].as_i64()), (Some(0), Some(2)));
}

/// Item 4: a free curve shorter than f32 can resolve (duplicated control points at its ends)
/// used to give degenerate triangles and a pinch at factors ≥ 2; welding at the output's
/// precision collapses it to a point, which the engine handles.
#[test]
fn a_nearly_collapsed_curve_does_not_pinch() {
    let dir = scratch("pinch");
    let mut points = flat_grid([1.0, 1.0, 0.0]);
    let e = 1e-9;
    points[0] = [1.0, 1.0, 0.0];
    points[4] = [1.0, 1.0, 0.0];
    points[8] = [1.0 + e, 1.0, 0.0];
    points[12] = [1.0 + e, 1.0, 0.0];
    let one: [usize; 16] = std::array::from_fn(|k| k + 1);
    let file = patch_file(&dir, "tiny_curve.patches", &[one], &points);
    for factor in ["2", "4", "8"] {
        let (code, out, err) = run(&["mesh", file.to_str().unwrap(), "--factor", factor, "--stats"], &dir);
        assert_eq!(code, Some(0), "factor {factor}: {err}");
        let v = stats(&out);
        assert_eq!(v["degenerate_triangles"], 0, "factor {factor}: {v}");
        assert_eq!(v["euler_characteristic"], v["input_euler_characteristic"], "factor {factor}: {v}");
    }
}

/// Item 5: repairs reach the user: one stderr line per kind, and a `repairs` object in --stats.
#[test]
fn repairs_are_reported() {
    let dir = scratch("repairs");
    let (code, out, err) = run(
        &["mesh", data("awkward/teapot_tri_nonmanifold.obj").to_str().unwrap(), "--factor", "2", "--stats"],
        &dir,
    );
    assert!(code.is_some());
    let v = stats(&out);
    let dropped = v["repairs"]["dropped_degenerate_faces"].as_u64().unwrap();
    assert_eq!(dropped, 32, "the file's 32 pole triangles repeat a vertex: {v}");
    assert!(err.contains("repair: 32 input faces dropped: two of their corners are one vertex"), "{err}");
    let (_, out, err) =
        run(&["mesh", data("patches/teapot.patches").to_str().unwrap(), "--factor", "4", "--stats"], &dir);
    let v = stats(&out);
    let collapsed = v["repairs"]["collapsed_triangles"].as_u64().unwrap();
    assert!(collapsed > 0, "the lid apex collapses triangles: {v}");
    assert!(err.contains(&format!("repair: {collapsed} triangles not emitted")), "{err}");
}

/// Item 6: the smaller points.
#[test]
fn small_points_are_clear() {
    let dir = scratch("small");
    let teapot = data("patches/teapot.patches");
    let t = teapot.to_str().unwrap();
    // `mesh IN` without -o says what it did and that nothing was written.
    let (code, out, err) = run(&["mesh", t, "--factor", "2"], &dir);
    assert_eq!(code, Some(0));
    assert!(out.is_empty() && err.contains("nothing written: give -o OUT"), "{err}");
    // Nonsense options are refused.
    for (args, needle) in [
        (vec!["mesh", t, "--repeat", "0"], "--repeat 0"),
        (vec!["check", t, "--weld=-1"], "--weld -1"),
        (vec!["check", "x.xyz"], ".obj, .ply, .stl, .glb"),
        (
            vec!["mesh", data("meshes/spot.obj").to_str().unwrap(), "--scheme", "esc"],
            "spot.obj: the esc scheme does not tessellate triangle patches",
        ),
    ] {
        let (code, _, err) = run(&args, &dir);
        assert_eq!(code, Some(2), "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
    }
    // A huge ratio is printed in scientific notation, and semi-uniform's cap names --max-level.
    let (_, _, err) =
        run(&["mesh", t, "--tolerance", "1e-12", "--scheme", "semi-uniform", "--max-level", "2"], &dir);
    assert!(err.contains("--max-level 2") && err.contains("raise --max-level"), "{err}");
    let ratio = err
        .split("up to ")
        .nth(1)
        .and_then(|r| r.split(", ").nth(1))
        .and_then(|r| r.split('×').next())
        .unwrap_or_default()
        .to_string();
    assert!(ratio.contains('e') && ratio.len() < 20, "ratio {ratio:?} in {err}");
    // `check --against` another model says the inputs do not match instead of an error figure.
    let (code, ..) = run(&["mesh", t, "--factor", "2", "-o", "pot.ply"], &dir);
    assert_eq!(code, Some(0));
    let cup = data("patches/teacup.patches");
    let (code, out, _) = run(&["check", "pot.ply", "--against", cup.to_str().unwrap()], &dir);
    assert_eq!(code, Some(1), "{out}");
    assert!(out.contains("not made from this input"), "{out}");
}
