//! Watertightness of the uniform engine on every model in the shared data folder.

mod common;

use std::collections::HashMap;

use tessera::criterion::Plan;
use tessera::engine::{tessellate, EngineOptions};
use tessera::pattern::uniform::Uniform;
use tessera::verify;

/// At factor 1 every curve becomes the straight edge between its corners, so distinct curves
/// with the same two corners (the two halves of the teacup's handle end, say) become one
/// output edge, and a curve that starts and ends at one point becomes no edge (its triangles
/// are dropped as collapsed). Returns (boundary, non-manifold, Euler characteristic) of that chord complex.
fn chord_topology(set: &tessera::surface::SurfaceSet) -> (usize, usize, i64) {
    let mut uses: HashMap<(u32, u32), usize> = HashMap::new();
    for (e, edge) in set.topology.edges.iter().enumerate() {
        let [a, b] = edge.ends;
        if a != b {
            *uses.entry((a.min(b), a.max(b))).or_default() += set.topology.edge_uses(e).len();
        }
    }
    let boundary = uses.values().filter(|&&u| u == 1).count();
    let nonmanifold = uses.values().filter(|&&u| u > 2).count();
    let t = set.topology.report;
    (boundary, nonmanifold, t.vertices as i64 - uses.len() as i64 + t.patches as i64)
}

/// Output boundary and non-manifold edges are exactly the input's free and non-manifold
/// curves refined n times, and the Euler characteristic is the input's.
#[test]
fn uniform_output_refines_the_input_topology_exactly() {
    for path in common::all_surface_models() {
        let set = common::load(&path).unwrap_or_else(|e| panic!("{e}"));
        let t = set.topology.report;
        let chords = chord_topology(&set);
        let name = path.file_name().unwrap().to_string_lossy();
        {
            let plan = Plan::uniform(&set, 1).unwrap();
            let mesh = tessellate(&set, &plan, &Uniform, EngineOptions::default()).unwrap();
            let w = verify::watertight(&mesh);
            assert_eq!((w.boundary_edges, w.nonmanifold_edges, w.euler_characteristic), chords, "{name} n=1");
        }
        // A free curve that starts and ends at one point (teapot_teasetorig's lid top) becomes,
        // at factor 2, two output edges between the same two vertices: one edge used twice.
        let free_loops = set
            .topology
            .edges
            .iter()
            .enumerate()
            .filter(|(e, edge)| {
                !edge.collapsed && edge.ends[0] == edge.ends[1] && set.topology.edge_uses(*e).len() == 1
            })
            .count();
        for n in [2u32, 3, 5, 8] {
            let plan = Plan::uniform(&set, n).unwrap();
            let mesh = tessellate(&set, &plan, &Uniform, EngineOptions::default()).unwrap();
            let w = verify::watertight(&mesh);
            let (loop_boundary, loop_euler) =
                if n == 2 { (2 * free_loops, free_loops as i64) } else { (0, 0) };
            assert_eq!(
                w.boundary_edges,
                t.boundary_edges * n as usize - loop_boundary,
                "{name} n={n}: boundary"
            );
            assert_eq!(w.nonmanifold_edges, t.nonmanifold_edges * n as usize, "{name} n={n}: non-manifold");
            assert_eq!(
                w.euler_characteristic,
                t.euler_characteristic + loop_euler,
                "{name} n={n}: Euler characteristic"
            );
            assert_eq!(w.collapsed_triangles, 0, "{name} n={n}: the engine drops collapsed triangles");
            if t.is_closed() {
                assert!(w.is_closed(), "{name} n={n}: closed input gave an open mesh");
            }
        }
    }
}

#[test]
fn torus_counts_are_exact() {
    let set = common::load(&common::model("bench/torus_64x32.patches")).unwrap();
    assert!(set.topology.report.is_closed());
    for n in [1u32, 2, 3, 4] {
        let plan = Plan::uniform(&set, n).unwrap();
        let mesh = tessellate(&set, &plan, &Uniform, EngineOptions::default()).unwrap();
        assert_eq!(mesh.triangle_count(), 2 * (n * n) as usize * 2048);
        assert_eq!(mesh.vertex_count(), (n * n) as usize * 2048);
        let w = verify::watertight(&mesh);
        assert!(w.is_closed());
        assert_eq!(w.euler_characteristic, 0, "a torus");
        assert_eq!(w.vertices, mesh.vertex_count(), "no two output vertices share a position");
    }
}

#[test]
fn teapot_topology_matches_the_data_readme() {
    // README: 52 curves shared by position, 16 free, 8 degenerate patch edges (two points).
    let set = common::load(&common::model("patches/teapot.patches")).unwrap();
    let t = set.topology.report;
    assert_eq!(t.boundary_edges, 16);
    assert_eq!(t.edges - t.boundary_edges, 52);
    assert_eq!(t.nonmanifold_edges, 0);
    assert_eq!(t.collapsed_edges, 2, "lid apex and bottom centre");
    let teacup = common::load(&common::model("patches/teacup.patches")).unwrap().topology.report;
    assert_eq!((teacup.boundary_edges, teacup.edges - teacup.boundary_edges), (12, 46));
}

#[test]
fn shared_vertices_are_evaluated_once() {
    // Every position occurs once in the output, except split-normal copies (none here):
    // neighbours index the same vertex instead of evaluating it again.
    for rel in ["patches/teapot.patches", "patches/teacup.patches", "meshes/blob.obj", "meshes/spot.obj"] {
        let set = common::load(&common::model(rel)).unwrap();
        let plan = Plan::uniform(&set, 4).unwrap();
        let mesh = tessellate(&set, &plan, &Uniform, EngineOptions::default()).unwrap();
        let w = verify::watertight(&mesh);
        assert_eq!(w.vertices, mesh.vertex_count(), "{rel}: duplicated vertex positions");
    }
}
