//! Topology checks that stay quiet no more (issue 9, item 9): stacked copies of one patch (a
//! non-manifold input whose copies weld into one surface) change the Euler characteristic and
//! `tessera mesh` says so; `tessera check --against` another model says how the topology
//! differs, with exit status 1.

mod common;

use common::{data, scratch, tessera, text};
use std::path::Path;

/// A `.patches` file of `copies` copies of one bicubic patch (a bump over the unit square).
fn copies(dir: &Path, copies: usize) -> String {
    let mut s = format!("{copies}\n");
    let line: Vec<String> = (1..=16).map(|i| i.to_string()).collect();
    s += &format!("{}\n", line.join(",")).repeat(copies);
    s += "16\n";
    for i in 0..4 {
        for j in 0..4 {
            let z = if (1..3).contains(&i) && (1..3).contains(&j) { "0.3" } else { "0" };
            s += &format!("{i},{j},{z}\n");
        }
    }
    let name = format!("copies{copies}.patches");
    std::fs::write(dir.join(&name), s).unwrap();
    name
}

/// Two unit patches side by side, sharing their curve at x = 1, or (`apart`) with a gap.
fn pair(dir: &Path, name: &str, apart: bool) -> String {
    let x0 = if apart { 2.0 } else { 1.0 };
    let mut s =
        "2\n1,2,3,4,5,6,7,8,9,10,11,12,13,14,15,16\n17,18,19,20,21,22,23,24,25,26,27,28,29,30,31,32\n32\n"
            .to_string();
    for x in [0.0, x0] {
        for i in 0..4 {
            for j in 0..4 {
                s += &format!("{},{},0\n", x + i as f64 / 3.0, j as f64 / 3.0);
            }
        }
    }
    std::fs::write(dir.join(name), s).unwrap();
    name.to_string()
}

#[test]
fn stacked_copies_of_a_patch_are_reported_as_a_changed_topology() {
    let dir = scratch("stacked-copies");
    // Three copies are the fewest that make every curve non-manifold, which used to turn the
    // Euler comparison off (300,000 copies gave 38,399,873 against 300,000, silently).
    for n in [3, 40] {
        let input = copies(&dir, n);
        let out = tessera(&["mesh", &input, "--factor", "8", "-o", "c.ply", "--stats"], &dir);
        let (stdout, stderr) = (text(&out.stdout), text(&out.stderr));
        assert_eq!(out.status.code(), Some(1), "{n} copies: {stdout}{stderr}");
        assert!(stderr.contains("warning: the mesh's Euler characteristic is"), "{n} copies: {stderr}");
        let problems = stdout.split("\"problems\":[").nth(1).unwrap_or_default();
        assert!(problems.starts_with("\"the mesh's Euler characteristic"), "{n} copies: {stdout}");
    }
    let input = copies(&dir, 1);
    let out = tessera(&["mesh", &input, "--factor", "8", "-o", "c.ply", "--stats"], &dir);
    assert_eq!(out.status.code(), Some(0), "one patch: {}", text(&out.stderr));
    assert!(text(&out.stdout).contains("\"problems\":[]"), "{}", text(&out.stdout));
}

#[test]
fn check_against_another_model_fails_and_says_why() {
    let dir = scratch("check-against");
    let spot = data("meshes/spot.obj");
    let bunny = data("meshes/bunny_closed.obj");
    let out = tessera(&["mesh", spot.to_str().unwrap(), "--factor", "1", "-o", "spot.glb"], &dir);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    // Both closed, genus 0, one piece: only the patch ids tell them apart (a .glb carries no
    // corner parameters, so no error is measured either).
    let out = tessera(&["check", "spot.glb", "--against", bunny.to_str().unwrap()], &dir);
    let stdout = text(&out.stdout);
    assert_eq!(out.status.code(), Some(1), "{stdout}");
    assert!(
        stdout.contains("FAIL: the mesh refers to patch 5855 but the input has 3674 patches"),
        "{stdout}"
    );
    let out = tessera(&["check", "spot.glb", "--against", spot.to_str().unwrap()], &dir);
    let stdout = text(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "its own input: {stdout}");
    assert!(!stdout.contains("FAIL"), "{stdout}");
}

#[test]
fn check_reports_every_topology_difference_with_exit_1() {
    let dir = scratch("check-pieces");
    let (joined, apart) = (pair(&dir, "joined.patches", false), pair(&dir, "apart.patches", true));
    let out = tessera(&["mesh", &apart, "--factor", "4", "-o", "apart.glb"], &dir);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    // The same two patch ids, both open: the counts differ.
    let out = tessera(&["check", "apart.glb", "--against", &joined], &dir);
    let stdout = text(&out.stdout);
    assert_eq!(out.status.code(), Some(1), "{stdout}");
    for line in [
        "FAIL: the mesh's Euler characteristic is 2, the input's 1",
        "FAIL: the mesh has 2 connected components, the input 1",
        "FAIL: the mesh has 2 boundary loops, the input 1",
    ] {
        assert!(stdout.contains(line), "{line:?} missing in {stdout}");
    }
    let out = tessera(&["check", "apart.glb", "--against", &apart], &dir);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stdout));
}
