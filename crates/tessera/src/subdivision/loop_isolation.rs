//! Feature-adaptive isolation of one triangle of a Loop cage, as OpenSubdiv's Bfr does it:
//! the triangle's neighbourhood is refined with Loop's rules towards its irregular features,
//! and the pieces become quartic box-spline patches where the refined mesh is regular and
//! Gregory triangles where refinement stops (`bfr/patchTreeBuilder.cpp`,
//! `far/topologyRefiner.cpp`, `far/patchBuilder.cpp`, `far/loopPatchBuilder.cpp`).
//!
//! The tags, the features that call for another level and the regularity of a leaf are
//! Catmull-Clark's ([`super::isolation`], with `Scheme::Loop`'s regular valences: 6 faces
//! around an interior vertex, 3 at a boundary); the depths are the same
//! [`IsolationLevels`]. What is Loop's own is here: the 1-to-4 split of a triangle (three
//! corner children and the middle one, turned), the box spline's twelve points around a
//! regular leaf with their boundary mask, and the source patch of a Gregory triangle.
//!
//! As for quads, a local mesh carries the whole isolation: refining a triangle `f` needs the
//! points of its corners (whose rings are in the neighbourhood), of the edges at its corners
//! and of the faces across its edges; the children of the triangles around `f`'s corners, at
//! those corners, and the middle children of the triangles across `f`'s edges are exactly
//! the neighbourhoods of `f`'s four children.

use glam::{DVec2, DVec3};

use super::cage::{Cage, FaceCorner};
use super::isolation::{
    child_sharpness, corner_fan, face_has_features, is_infinite, is_patch_regular, neighbourhood, vertex_tag,
    IsolationLevels, Scheme, MAX_ISOLATION_LEVEL,
};
use super::loop_gregory::{gregory_triangle_points, LoopCorner, LoopGregorySource};
use super::loop_sdc::{self, EdgeNeighborhood, VertexNeighborhood};
use crate::pattern::cache::WordMap;
use crate::surface::triangle_tree::{TriangleLeaf, TriangleLeafPatch, TriangleSlot, TriangleTree};
use crate::surface::{GregoryTriangle, QuarticTriangle};

/// Builds the patch tree of triangle `face` of `cage` (a Loop cage: every face a triangle).
///
/// Precondition: the face has a limit surface (not a hole). Cost: a local refinement of a
/// few dozen triangles per level, for as many levels as its features need.
pub fn isolate_triangle(cage: &Cage, face: usize, levels: IsolationLevels) -> TriangleTree {
    let (local, root) = neighbourhood(cage, face);
    let sharp = levels.sharp.clamp(1, MAX_ISOLATION_LEVEL);
    let levels = IsolationLevels { smooth: levels.smooth.clamp(1, sharp), sharp };
    let mut out = Builder::default();
    let slot = node(&local, root, 0, (DVec2::ZERO, 1.0, false), levels, &mut out);
    TriangleTree::from_parts(out.leaves, out.nodes, slot)
}

#[derive(Default)]
struct Builder {
    leaves: Vec<TriangleLeaf>,
    nodes: Vec<[TriangleSlot; 4]>,
}

/// The subtree of triangle `f` of `mesh` at `level`, covering the triangle `at` (its square's
/// lower-left corner, side and whether it is turned, as [`TriangleLeaf`] says).
fn node(
    mesh: &Cage,
    f: usize,
    level: u8,
    at: (DVec2, f64, bool),
    levels: IsolationLevels,
    out: &mut Builder,
) -> TriangleSlot {
    let (origin, size, turned) = at;
    // Far's level `i` is made with the full feature set while `i` ≤ the smooth depth, with
    // the reduced one after; refining `f` makes level `level + 1`.
    let more = level < levels.sharp && face_has_features(mesh, f, level, level < levels.smooth, Scheme::Loop);
    if !more {
        let patch = if is_patch_regular(mesh, f, level, false, Scheme::Loop) {
            let mask = boundary_mask(mesh, f);
            let points = box_spline_points(mesh, f, mask);
            TriangleLeafPatch::Quartic(QuarticTriangle::from_box_spline_with_boundary(&points, mask))
        } else {
            let points = gregory_triangle_points(&gregory_source(mesh, f));
            TriangleLeafPatch::Gregory(Box::new(GregoryTriangle { points }))
        };
        out.leaves.push(TriangleLeaf { origin, size, level, turned, patch });
        return TriangleSlot::Leaf((out.leaves.len() - 1) as u32);
    }
    let (child, children) = refine(mesh, f);
    let index = out.nodes.len();
    out.nodes.push([TriangleSlot::Leaf(0); 4]);
    let half = size * 0.5;
    // Bfr's quadrants (module doc of `triangle_tree`): the corner children keep the node's
    // orientation, the middle one takes the other.
    let places = if turned {
        [
            (origin + DVec2::splat(half), half, true),
            (origin + DVec2::new(0.0, half), half, true),
            (origin + DVec2::new(half, 0.0), half, true),
            (origin + DVec2::splat(half), half, false),
        ]
    } else {
        [
            (origin, half, false),
            (origin + DVec2::new(half, 0.0), half, false),
            (origin + DVec2::new(0.0, half), half, false),
            (origin, half, true),
        ]
    };
    for (q, &c) in children.iter().enumerate() {
        let slot = node(&child, c, level + 1, places[q], levels, out);
        out.nodes[index][q] = slot;
    }
    TriangleSlot::Node(index as u32)
}

/// `PatchBuilder::GetRegularPatchBoundaryMask` for a triangle: the edges (bit `k` for edge
/// `k`, from corner `k` to `k + 1`) and corners that are on the boundary or infinitely sharp
/// edges, packed as OpenSubdiv packs them (`encodeTriBoundaryMask`): 3 lower bits of edges,
/// or of corners when no edge is (upper bits 1), or edges with every corner (upper bits 2);
/// 0 when no corner has an infinitely sharp edge.
fn boundary_mask(mesh: &Cage, f: usize) -> u8 {
    let corners = mesh.face(f);
    let tags: Vec<_> = corners.iter().map(|&v| vertex_tag(mesh, v as usize, Scheme::Loop)).collect();
    if !tags.iter().any(|t| t.inf_sharp_edges) {
        return 0;
    }
    let singular = |e: u32| mesh.is_boundary_edge(e) || is_infinite(mesh.edge_sharpness[e as usize]);
    let e_bits =
        mesh.face_edges(f).iter().enumerate().fold(0u8, |m, (k, &e)| m | (u8::from(singular(e)) << k));
    let v_bits =
        tags.iter().enumerate().fold(0u8, |m, (k, t)| m | (u8::from(t.boundary || t.inf_sharp_edges) << k));
    let (upper, lower) = match (e_bits, v_bits) {
        (_, 0) => (0, e_bits),
        (0, v) => (1, v),
        (1 | 2 | 4, 7) => (2, e_bits),
        (e, _) => (0, e),
    };
    if upper == 0 && lower == 0 {
        return 0;
    }
    (upper << 3) | lower
}

/// The twelve points of the box spline over regular triangle `f`, in OpenSubdiv's `LOOP`
/// order (`PatchBuilder::getTriRegularPatchPoints`): per corner `i`, the corner itself and
/// three points of the triangles around it beyond `f`. Points beyond a boundary (which
/// `mask`'s basis gives no weight, see [`QuarticTriangle::from_box_spline_with_boundary`])
/// are filled with `f`'s corner 0, as Far fills them. Precondition: `f` is regular
/// ([`is_patch_regular`]), so an interior corner has six triangles.
fn box_spline_points(mesh: &Cage, f: usize, mask: u8) -> [DVec3; 12] {
    // Where each corner's own point and its three outer points go.
    const PER_CORNER: [[usize; 4]; 3] = [[4, 7, 3, 0], [5, 1, 2, 6], [8, 9, 11, 10]];
    let corners = mesh.face(f);
    let (e_mask, v_mask) = decode_mask(mask);
    let filler = mesh.points[corners[0] as usize];
    let mut out = [filler; 12];
    // Corner `k` of the triangle `fc.face` away from the vertex `fc` is at (`fc.corner + k`).
    let point = |fc: FaceCorner, k: usize| {
        let face = mesh.face(fc.face as usize);
        mesh.points[face[(fc.corner as usize + k) % 3] as usize]
    };
    for (i, &v) in corners.iter().enumerate() {
        let slots = PER_CORNER[i];
        let fan = mesh.vertex_faces(v as usize);
        let n = fan.len();
        let at = fan.iter().position(|fc| fc.face as usize == f).expect("the face is at its corner");
        let interior = mask == 0 || v_mask & (1 << i) == 0;
        let leading = e_mask & (1 << i) != 0;
        let trailing = e_mask & (1 << ((i + 2) % 3)) != 0;
        let outer: [Option<DVec3>; 3] = if interior {
            let (f2, f3) = (fan[(at + 2) % 6], fan[(at + 3) % 6]);
            [Some(point(f2, 1)), Some(point(f3, 1)), Some(point(f3, 2))]
        } else if leading && trailing {
            [None, None, None]
        } else if leading {
            let f2 = fan[(at + 2) % n];
            [Some(point(f2, 1)), Some(point(f2, 2)), None]
        } else if trailing {
            let f0 = fan[(at + n - 2) % n];
            [None, None, Some(point(f0, 1))]
        } else {
            let f2 = fan[(at + 1) % n];
            [Some(point(f2, 2)), None, None]
        };
        for (k, p) in outer.iter().enumerate() {
            if let Some(p) = p {
                out[slots[k + 1]] = *p;
            }
        }
        out[slots[0]] = mesh.points[v as usize];
    }
    out
}

/// The edge and corner bits of a packed triangle boundary mask (`decodeTriBoundaryMask`).
fn decode_mask(mask: u8) -> (u8, u8) {
    const CORNERS_OF_EDGES: [u8; 8] = [0, 3, 6, 7, 5, 7, 7, 7];
    let (lower, upper) = (mask & 7, (mask >> 3) & 3);
    match upper {
        0 => (lower, CORNERS_OF_EDGES[lower as usize]),
        1 => (0, lower),
        _ => (lower, 7),
    }
}

/// The source patch of a leaf for its Gregory triangle (`PatchBuilder::GetIrregularPatchCornerSpans`
/// and `assembleIrregularSourcePatch`, `far/patchBuilder.cpp`), as [`super::isolation`]'s
/// `gregory_source` does for quads.
fn gregory_source(mesh: &Cage, f: usize) -> LoopGregorySource {
    let corners: [LoopCorner; 3] = std::array::from_fn(|i| {
        let v = mesh.face(f)[i] as usize;
        let fan = corner_fan(mesh, f, i, Scheme::Loop);
        LoopCorner {
            position: mesh.points[v],
            num_faces: fan.faces.len(),
            patch_face: fan.patch_face,
            boundary: fan.boundary,
            sharp: fan.sharp,
            dart: fan.dart,
            ring: fan.ring(mesh),
        }
    });
    LoopGregorySource { corners }
}

/// One level of Loop refinement around triangle `f` of `mesh` (module doc): the child mesh
/// and `f`'s four children in Bfr's quadrant order — the corner children at `f`'s corners
/// 0, 1, 2, each listing its corners so that its parameters run as `f`'s, and the middle
/// child, whose corners start at the midpoint of `f`'s edge 1 (its right-angle corner in
/// the turned parameters).
fn refine(mesh: &Cage, f: usize) -> (Cage, Vec<usize>) {
    let options = mesh.options;
    #[derive(Clone, Copy, PartialEq, Eq, Hash)]
    enum Parent {
        Vertex(u32),
        Edge(u32),
    }
    let mut index: WordMap<Parent, u32> = Default::default();
    let mut parents: Vec<Parent> = Vec::new();
    let mut id = |p: Parent| -> u32 {
        *index.entry(p).or_insert_with(|| {
            parents.push(p);
            (parents.len() - 1) as u32
        })
    };
    let corners = mesh.face(f).to_vec();
    let f_edges = mesh.face_edges(f).to_vec();
    let mut face_start = vec![0u32];
    let mut face_vertices: Vec<u32> = Vec::new();
    let push = |tri: [u32; 3], face_vertices: &mut Vec<u32>, face_start: &mut Vec<u32>| {
        face_vertices.extend_from_slice(&tri);
        face_start.push(face_vertices.len() as u32);
        face_start.len() - 2
    };
    // f's children first, in quadrant order, each starting where its parameters do.
    let v: Vec<u32> = corners.iter().map(|&c| id(Parent::Vertex(c))).collect();
    let e: Vec<u32> = f_edges.iter().map(|&x| id(Parent::Edge(x))).collect();
    let children = vec![
        push([v[0], e[0], e[2]], &mut face_vertices, &mut face_start),
        push([e[0], v[1], e[1]], &mut face_vertices, &mut face_start),
        push([e[2], e[1], v[2]], &mut face_vertices, &mut face_start),
        push([e[1], e[2], e[0]], &mut face_vertices, &mut face_start),
    ];
    // The corner children of the triangles around f's corners, at those corners, and the
    // middle children of the triangles across f's edges.
    let mut seen: WordMap<(u32, u32), ()> = Default::default();
    for c in 0..3 {
        seen.insert((f as u32, c), ());
    }
    for &c in &corners {
        for &fc in mesh.vertex_faces(c as usize) {
            if seen.insert((fc.face, fc.corner), ()).is_some() {
                continue;
            }
            let tri = [
                id(Parent::Vertex(c)),
                id(Parent::Edge(mesh.leading_edge(fc))),
                id(Parent::Edge(mesh.trailing_edge(fc))),
            ];
            push(tri, &mut face_vertices, &mut face_start);
        }
    }
    for &x in &f_edges {
        if let Some(g) = mesh.across(f as u32, x) {
            let edges = mesh.face_edges(g as usize);
            let tri = [id(Parent::Edge(edges[0])), id(Parent::Edge(edges[1])), id(Parent::Edge(edges[2]))];
            push(tri, &mut face_vertices, &mut face_start);
        }
    }

    let mut points = Vec::with_capacity(parents.len());
    let mut vertex_sharpness = Vec::with_capacity(parents.len());
    let mut complete = Vec::with_capacity(parents.len());
    for &p in &parents {
        match p {
            Parent::Edge(x) => {
                points.push(edge_point(mesh, x));
                vertex_sharpness.push(0.0);
                complete.push(f_edges.contains(&x));
            }
            Parent::Vertex(c) => {
                points.push(vertex_point(mesh, c as usize));
                vertex_sharpness.push(super::sdc::child_vertex_sharpness(mesh.vertex_sharpness[c as usize]));
                complete.push(true);
            }
        }
    }
    // Child edge sharpness: the halves of a parent edge get Sdc's child sharpness at their
    // end; edges inside a parent triangle are smooth.
    let sharpness_of = |a: u32, b: u32| -> f32 {
        match (parents[a as usize], parents[b as usize]) {
            (Parent::Vertex(c), Parent::Edge(x)) | (Parent::Edge(x), Parent::Vertex(c)) => {
                child_sharpness(mesh, x, c)
            }
            _ => 0.0,
        }
    };
    let child =
        Cage::local(points, face_start, face_vertices, &complete, sharpness_of, vertex_sharpness, options);
    (child, children)
}

/// Loop's edge point of edge `x` (its triangles are in `mesh`).
fn edge_point(mesh: &Cage, x: u32) -> DVec3 {
    let [a, b] = mesh.edge(x);
    let opposite: Vec<DVec3> = mesh
        .edge_faces(x)
        .iter()
        .map(|&g| {
            let q = mesh.face(g as usize);
            let far = q.iter().find(|&&w| w != a && w != b).expect("a triangle has a third corner");
            mesh.points[*far as usize]
        })
        .collect();
    loop_sdc::edge_point(&EdgeNeighborhood {
        ends: [mesh.points[a as usize], mesh.points[b as usize]],
        sharpness: mesh.edge_sharpness[x as usize],
        child_sharpness: [child_sharpness(mesh, x, a), child_sharpness(mesh, x, b)],
        opposite: &opposite,
    })
}

/// Loop's vertex point of complete vertex `v`.
fn vertex_point(mesh: &Cage, v: usize) -> DVec3 {
    let edges = mesh.vertex_edges(v);
    let ends: Vec<DVec3> = edges
        .iter()
        .map(|&x| {
            let [a, b] = mesh.edge(x);
            mesh.points[if a as usize == v { b } else { a } as usize]
        })
        .collect();
    let sharpness: Vec<f32> = edges.iter().map(|&x| mesh.edge_sharpness[x as usize]).collect();
    loop_sdc::vertex_point(
        &VertexNeighborhood {
            position: mesh.points[v],
            sharpness: mesh.vertex_sharpness[v],
            edge_ends: &ends,
            edge_sharpness: &sharpness,
            faces: mesh.vertex_faces(v).len(),
        },
        mesh.options.crease_method,
    )
}
