//! Split normals, welding, orientation and degenerate corners.

mod common;

use glam::{DVec3, Vec3};
use std::path::Path;
use tessera::criterion::Plan;
use tessera::engine::{tessellate, EngineOptions};
use tessera::mesh::Mesh;
use tessera::pattern::uniform::Uniform;
use tessera::surface::{BuildOptions, Orientation, SurfaceSet};
use tessera::topology::weld::Weld;
use tessera::verify;

fn mesh_of(set: &SurfaceSet, n: u32) -> Mesh {
    tessellate(set, &Plan::uniform(set, n).unwrap(), &Uniform, EngineOptions::default()).unwrap()
}

fn signed_volume(m: &Mesh) -> f64 {
    (0..m.triangle_count())
        .map(|t| {
            let [a, b, c] = m.triangle(t).map(|i| Vec3::from(m.positions[i as usize]).as_dvec3());
            a.dot(b.cross(c)) / 6.0
        })
        .sum()
}

/// A unit cube with one normal per face (`f a//n`): every vertex has three normals and every
/// edge is a crease.
const CUBE: &str = "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n\
vn 0 0 -1\nvn 0 0 1\nvn 0 -1 0\nvn 0 1 0\nvn -1 0 0\nvn 1 0 0\n\
f 1//1 3//1 2//1\nf 1//1 4//1 3//1\nf 5//2 6//2 7//2\nf 5//2 7//2 8//2\n\
f 1//3 2//3 6//3\nf 1//3 6//3 5//3\nf 4//4 8//4 7//4\nf 4//4 7//4 3//4\n\
f 1//5 5//5 8//5\nf 1//5 8//5 4//5\nf 2//6 3//6 7//6\nf 2//6 7//6 6//6\n";

#[test]
fn split_normals_keep_one_position_and_separate_normals() {
    let obj = tessera::io::obj::parse_obj(CUBE, Path::new("<cube>")).unwrap();
    let set = SurfaceSet::pn_from_mesh(&obj, Path::new("<cube>"), BuildOptions::default()).unwrap();
    assert!(set.topology.report.is_closed());
    assert_eq!(tessera::surface::split_normal_vertices(&set), 8);
    for n in [1u32, 2, 5] {
        let mesh = mesh_of(&set, n);
        let w = verify::watertight(&mesh);
        assert!(w.is_closed(), "n={n}: {w:?}");
        assert_eq!(w.euler_characteristic, 2);
        // Welded positions: 6 faces of an n-grid on a cube.
        assert_eq!(w.vertices, 6 * n as usize * n as usize + 2);
        assert!(mesh.vertex_count() > w.vertices, "split normals need separate vertices");
        for t in 0..mesh.triangle_count() {
            let [a, b, c] = mesh.triangle(t).map(|i| Vec3::from(mesh.positions[i as usize]).as_dvec3());
            let face = (b - a).cross(c - a).normalize();
            for i in mesh.triangle(t) {
                let p = Vec3::from(mesh.positions[i as usize]).as_dvec3();
                // Crease edges stay straight and flat faces stay flat: on the cube's surface.
                assert!((p.abs().max_element() - 1.0).abs() < 1e-6, "{p} off the cube");
                let nrm = Vec3::from(mesh.normals[i as usize]).as_dvec3();
                assert!(nrm.dot(face) > 0.999, "n={n}: vertex normal {nrm} is not the face normal {face}");
            }
        }
    }
}

#[test]
fn tolerance_welding_closes_cracks_that_exact_welding_keeps() {
    let path = common::model("patches/teapot.patches");
    let text = std::fs::read_to_string(&path).unwrap();
    // Nudge every point used by patch 1 only... by copying it: give the patch its own points,
    // moved by 1e-9, so it no longer shares curves with its neighbours by index or position.
    let mut file = tessera::io::patches::parse_patches(&text, &path).unwrap();
    let base = file.points.len() as u32;
    let own: Vec<u32> = file.patches[1].to_vec();
    for (k, &i) in own.iter().enumerate() {
        file.points.push(file.points[i as usize] + DVec3::splat(1e-9));
        file.weights.push(1.0);
        file.patches[1][k] = base + k as u32;
    }
    let original =
        SurfaceSet::from_patch_file(&tessera::io::patches::read_patches(&path).unwrap(), Default::default());
    let exact = SurfaceSet::from_patch_file(&file, Default::default());
    assert!(exact.topology.report.boundary_edges > original.topology.report.boundary_edges);
    let welded =
        SurfaceSet::from_patch_file(&file, BuildOptions { weld: Weld::Within(1e-6), ..Default::default() });
    assert_eq!(welded.topology.report, original.topology.report);
    assert!(welded.repairs.welded_points >= 16);
    let w = verify::watertight(&mesh_of(&welded, 4));
    assert_eq!(w.boundary_edges, 16 * 4);
}

#[test]
fn orientation_is_outward_by_default_and_can_be_flipped() {
    let path = common::model("patches/teapot.patches");
    let as_given =
        common::load_with(&path, BuildOptions { orientation: Orientation::AsGiven, ..Default::default() })
            .unwrap();
    let outward = common::load(&path).unwrap();
    let flipped = common::load_with(&path, BuildOptions { flip: true, ..Default::default() }).unwrap();
    // The data README: this file's dS/du × dS/dv points inward.
    assert!(signed_volume(&mesh_of(&as_given, 4)) < 0.0);
    assert!(signed_volume(&mesh_of(&outward, 4)) > 0.0);
    assert!(signed_volume(&mesh_of(&flipped, 4)) < 0.0);
    assert!(outward.repairs.flipped);
    // Every closed mesh model comes out with positive volume and normals agreeing with it.
    for rel in ["meshes/blob.obj", "meshes/spot.obj", "meshes/knot.obj", "bench/torus_64x32.patches"] {
        let set = common::load(&common::model(rel)).unwrap();
        let mesh = mesh_of(&set, 2);
        assert!(signed_volume(&mesh) > 0.0, "{rel}");
        let agree = (0..mesh.triangle_count())
            .filter(|&t| {
                let [a, b, c] = mesh.triangle(t).map(|i| Vec3::from(mesh.positions[i as usize]));
                let face = (b - a).cross(c - a);
                face.dot(Vec3::from(mesh.normals[mesh.triangle(t)[0] as usize])) > 0.0
            })
            .count();
        assert!(agree as f64 > 0.99 * mesh.triangle_count() as f64, "{rel}: normals disagree with winding");
    }
}

#[test]
fn collapsed_corners_get_the_limit_normal() {
    // The teapot's lid apex (0, 0, 3.15) and bottom centre (0, 0, 0) are collapsed curves.
    let set = common::load(&common::model("patches/teapot.patches")).unwrap();
    let mesh = mesh_of(&set, 6);
    for n in &mesh.normals {
        let n = Vec3::from(*n);
        assert!(n.is_finite() && (n.length() - 1.0).abs() < 1e-5, "normal {n}");
    }
    let find = |z: f32| {
        mesh.positions.iter().position(|p| p[0].abs() < 1e-6 && p[1].abs() < 1e-6 && (p[2] - z).abs() < 1e-4)
    };
    let apex = find(3.15).expect("apex vertex");
    let bottom = find(0.0).expect("bottom centre vertex");
    assert!(Vec3::from(mesh.normals[apex]).dot(Vec3::Z) > 0.9999, "apex {:?}", mesh.normals[apex]);
    assert!(Vec3::from(mesh.normals[bottom]).dot(-Vec3::Z) > 0.9999, "bottom {:?}", mesh.normals[bottom]);
    // Each collapsed point is one vertex: no other vertex sits there.
    assert_eq!(
        mesh.positions
            .iter()
            .filter(|p| Vec3::from(**p).distance(Vec3::from(mesh.positions[apex])) < 1e-6)
            .count(),
        1
    );
}

#[test]
fn degenerate_and_duplicate_faces_are_dropped_and_counted() {
    let text =
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 0 0 0\nf 1 2 3\nf 1 3 4\nf 1 4 2\nf 2 4 3\nf 1 5 2\nf 3 2 1\n";
    let obj = tessera::io::obj::parse_obj(text, Path::new("<tet>")).unwrap();
    let set = SurfaceSet::pn_from_mesh(&obj, Path::new("<tet>"), BuildOptions::default()).unwrap();
    assert_eq!(set.repairs.dropped_degenerate_faces, 1, "vertex 5 welds onto vertex 1");
    assert_eq!(set.repairs.dropped_duplicate_faces, 1);
    assert!(set.topology.report.is_closed());
    assert!(verify::watertight(&mesh_of(&set, 3)).is_closed());
    // Nothing usable left is an error, not a panic.
    let flat =
        tessera::io::obj::parse_obj("v 0 0 0\nv 0 0 0\nv 1 1 1\nf 1 2 3\n", Path::new("<flat>")).unwrap();
    let err = SurfaceSet::pn_from_mesh(&flat, Path::new("<flat>"), BuildOptions::default()).unwrap_err();
    assert!(matches!(err, tessera::Error::Unsupported { .. }), "{err}");
}

/// Subdivision patches handed to `SurfaceSet::from_patches` (say, taken from a set loaded
/// from a cage) have no one control net: they are welded by their limit surface's boundary
/// points. Every patch is kept and none panics (the hull's eight points were once read as a
/// net, past the end of the points); welded within a small distance, the neighbours find each
/// other as the cage's own topology has them where both sides' pieces are exact (a creased
/// cage's end caps agree with their neighbours only approximately: more edges there, never
/// a non-manifold one).
#[test]
fn subdivision_patches_weld_by_their_boundary_points() {
    use tessera::io::{LoadOptions, SurfaceKind};
    for (cage, surface, same) in [
        ("subdivision/catmark_torus.obj", SurfaceKind::CatmullClark, true),
        ("subdivision/catmark_cube.obj", SurfaceKind::CatmullClark, true),
        ("subdivision/catmark_torus_creases0.obj", SurfaceKind::CatmullClark, false),
        ("subdivision/loop_xord_interior.obj", SurfaceKind::Loop, true),
        ("subdivision/loop_triangle_edgecorner.obj", SurfaceKind::Loop, true),
    ] {
        let options = LoadOptions { surface, ..Default::default() };
        let set = tessera::io::load(&common::model(cage), options).unwrap();
        let (lo, hi) = set.bounds();
        let weld = Weld::Within(1e-9 * (hi - lo).length());
        let build = BuildOptions { weld, orientation: Orientation::AsGiven, ..Default::default() };
        let rebuilt = SurfaceSet::from_patches(set.patches.clone(), build);
        assert_eq!(rebuilt.patches.len(), set.patches.len(), "{cage}");
        let (a, b) = (&set.topology.report, &rebuilt.topology.report);
        let counts = |r: &tessera::topology::TopologyReport| (r.edges, r.boundary_edges, r.nonmanifold_edges);
        if same {
            assert_eq!(counts(b), counts(a), "{cage}");
        } else {
            assert!(
                b.edges >= a.edges && b.nonmanifold_edges == 0,
                "{cage}: {:?} against {:?}",
                counts(b),
                counts(a)
            );
        }
        let exact = SurfaceSet::from_patches(set.patches.clone(), BuildOptions::default());
        assert_eq!(exact.patches.len(), set.patches.len(), "{cage}");
    }
}
