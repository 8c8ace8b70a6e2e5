//! tessera's Loop limit surface against OpenSubdiv's own: every `loop_*` cage of the shared
//! data, uniform rates 1–8, face by face, compared with the points OpenSubdiv's Bfr prints
//! through `tools/osd-oracle` (`SCHEME_LOOP`, chosen by the file name), within 1e-6 of the
//! cage's bounding-box diagonal. Bfr's parameters of a triangle are the patch's own.

use common::osd::{cage_diagonal, run_oracle, run_oracle_with};
use tessera::io::obj::read_obj;
use tessera::subdivision::CageOptions;
use tessera::surface::{Orientation, SurfaceSet};

mod common;

fn loop_cages() -> Vec<std::path::PathBuf> {
    let mut cages: Vec<_> = std::fs::read_dir(tessera::test_support::data("subdivision"))
        .expect("the shared data's subdivision folder")
        .map(|e| e.unwrap().path())
        .filter(|p| p.file_name().unwrap().to_string_lossy().starts_with("loop_"))
        .collect();
    cages.sort();
    cages
}

/// A cage tessera refuses (its third shape has an edge of four triangles: non-manifold, which
/// tessera does not subdivide yet), with an error naming the face's line.
const NON_MANIFOLD: &str = "loop_val2_interior.obj";

#[test]
fn every_loop_face_agrees_with_bfr() {
    let mut worst_overall = (0.0f64, String::new());
    let mut report = Vec::new();
    let mut compared = 0;
    for path in loop_cages() {
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let mesh = read_obj(&path).unwrap();
        let options = CageOptions { orientation: Orientation::AsGiven, ..Default::default() };
        if name == NON_MANIFOLD {
            let e = SurfaceSet::from_loop_cage(&mesh, &path, options).unwrap_err();
            assert!(e.to_string().contains("non-manifold") && e.to_string().contains(":72:"), "{e}");
            continue;
        }
        let (worst, points) = compare_with_bfr(&path, 1..=8);
        compared += 1;
        if worst.0 > worst_overall.0 {
            worst_overall = (worst.0, format!("{name} {}", worst.1));
        }
        report.push(format!("{name}: {points} points, worst {:.2e} {}", worst.0, worst.1));
    }
    eprintln!("{}", report.join("\n"));
    eprintln!("worst of all: {:.3e} of the diagonal, {}", worst_overall.0, worst_overall.1);
    assert!(compared >= 11, "only {compared} Loop cages compared");
    assert!(worst_overall.0 < 1e-6, "worst {:.3e} at {}", worst_overall.0, worst_overall.1);
}

/// The largest distance (relative to the cage's diagonal) from tessera's limit point to Bfr's
/// over every face of the cage at `path` at each uniform rate of `rates`, where, and how many
/// points were compared. Asserts that the same faces have a limit surface.
fn compare_with_bfr(path: &std::path::Path, rates: std::ops::RangeInclusive<u32>) -> ((f64, String), usize) {
    let name = path.file_name().unwrap().to_string_lossy().into_owned();
    let mesh = read_obj(path).unwrap();
    let options = CageOptions { orientation: Orientation::AsGiven, ..Default::default() };
    let set = SurfaceSet::from_loop_cage(&mesh, path, options).unwrap_or_else(|e| panic!("{name}: {e}"));
    let patch_of: std::collections::HashMap<u32, usize> =
        set.origins.iter().enumerate().map(|(p, o)| (o.face, p)).collect();
    let diagonal = cage_diagonal(&mesh);
    let mut worst = (0.0f64, String::new());
    let mut points = 0;
    for rate in rates {
        let faces = run_oracle_with(path, rate, &["--scheme", "loop"]);
        assert_eq!(faces.len(), mesh.faces.len(), "{name}");
        for (f, face) in faces.iter().enumerate() {
            assert_eq!(
                patch_of.contains_key(&(f as u32)),
                face.limit,
                "{name} face {f}: has a limit surface"
            );
            for &(uv, expected) in &face.points {
                let p = patch_of[&(f as u32)];
                let d = (set.patches[p].position(uv) - expected).length() / diagonal;
                if d > worst.0 {
                    worst = (d, format!("face {f} rate {rate} at {uv}"));
                }
                points += 1;
            }
        }
    }
    (worst, points)
}

/// A real Loop cage, not made to test a feature: pbrt's `loopsubdiv` Killeroo control mesh
/// (8,316 triangles, open, nine pieces), every face at rates 1, 2 and 5.
#[test]
fn a_real_loop_cage_agrees_with_bfr() {
    let path = tessera::test_support::data("meshes/killeroo_cage.obj");
    let (worst, points) = compare_with_bfr(&path, 1..=2);
    let (worst5, points5) = compare_with_bfr(&path, 5..=5);
    let worst = if worst5.0 > worst.0 { worst5 } else { worst };
    eprintln!("killeroo_cage: {} points, worst {:.2e} {}", points + points5, worst.0, worst.1);
    // Every face has a limit surface: 3 + 6 + 21 points each.
    assert_eq!(points + points5, 8316 * 30);
    assert!(worst.0 < 1e-6, "worst {:.3e} at {}", worst.0, worst.1);
}

/// tessera's output itself, in f32: the uniform tessellation at factor N of every manifold
/// Loop cage has, vertex for vertex, Bfr's tessellation points at rate N (every patch is one
/// triangle over Bfr's own parameters) within 1e-5 of the diagonal, and as many vertices as
/// Bfr's distinct points.
#[test]
fn the_f32_output_is_bfrs_tessellation() {
    use glam::DVec3;
    use tessera::criterion::Plan;
    use tessera::engine::{tessellate, EngineOptions};
    use tessera::pattern::uniform::Uniform;
    let mut worst = (0.0f64, String::new());
    for path in loop_cages() {
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        if name == NON_MANIFOLD {
            continue;
        }
        let mesh = read_obj(&path).unwrap();
        let options = CageOptions { orientation: Orientation::AsGiven, ..Default::default() };
        let set = SurfaceSet::from_loop_cage(&mesh, &path, options).unwrap();
        let diagonal = cage_diagonal(&mesh);
        for n in [1u32, 2, 3, 5] {
            let faces = run_oracle(&path, n);
            let plan = Plan::uniform(&set, n).unwrap();
            let out = tessellate(&set, &plan, &Uniform, EngineOptions::default()).unwrap();
            let grid = |x: f64| (x * n as f64).round() as i64;
            let bfr: std::collections::HashMap<(u32, i64, i64), DVec3> = faces
                .iter()
                .enumerate()
                .flat_map(|(f, face)| {
                    face.points.iter().map(move |&(uv, p)| ((f as u32, grid(uv.x), grid(uv.y)), p))
                })
                .collect();
            for (v, q) in out.positions.iter().enumerate() {
                let face = set.origins[out.vertex_patch[v] as usize].face;
                let key = (face, grid(out.uvs[v][0] as f64), grid(out.uvs[v][1] as f64));
                let expected = *bfr
                    .get(&key)
                    .unwrap_or_else(|| panic!("{name} n={n}: output vertex {v} at {key:?} is no Bfr point"));
                let d = (DVec3::new(q[0] as f64, q[1] as f64, q[2] as f64) - expected).length() / diagonal;
                if d > worst.0 {
                    worst = (d, format!("{name} n={n} face {face}"));
                }
            }
            // Bfr writes a shared point once per face; the output once.
            let mut distinct: Vec<[i64; 3]> =
                bfr.values().map(|p| (*p / (1e-9 * diagonal)).round().as_i64vec3().to_array()).collect();
            distinct.sort_unstable();
            distinct.dedup();
            assert_eq!(
                out.positions.len(),
                distinct.len(),
                "{name} n={n}: vertices against Bfr's distinct points"
            );
        }
    }
    eprintln!("worst f32 output vertex: {:.3e} of the diagonal ({})", worst.0, worst.1);
    assert!(worst.0 < 1e-5, "worst {:.3e} at {}", worst.0, worst.1);
}
