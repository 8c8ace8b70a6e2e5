//! A subdivision cage's adjacency: faces, edges and the faces around every vertex in order,
//! with the sharpness OpenSubdiv gives each edge and vertex.
//!
//! Everything the limit surface needs to know about a face's neighbourhood is read here, the
//! way OpenSubdiv's `Vtr` level orders it (`vtr/level.cpp`): the faces around a vertex run
//! counter-clockwise seen from the front, and at a boundary vertex they start with the face
//! whose *leading* edge (from the vertex to the next corner of that face) is the boundary.
//! Face `k`'s trailing edge (from its previous corner into the vertex) is face `k + 1`'s
//! leading edge.
//!
//! Boundary edges are made infinitely sharp, and under
//! [`BoundaryInterpolation::EdgeAndCorner`] boundary vertices of one face become infinitely
//! sharp corners, as `Far::TopologyRefinerFactory` prepares a cage
//! (`far/topologyRefinerFactory.cpp`). Under [`BoundaryInterpolation::None`] every face at a
//! boundary vertex whose boundary edges are not all sharp has no limit surface (it is made a
//! hole), also as there.

use std::path::Path;

use glam::DVec3;

use super::{BoundaryInterpolation, SubdivisionOptions, INFINITELY_SHARP};
use crate::error::{Error, Result};
use crate::pattern::cache::WordMap;
use crate::surface::PolygonMesh;

/// No face on this side of an edge.
pub const NO_FACE: u32 = u32::MAX;

/// One face at a vertex: the face and which of its corners the vertex is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FaceCorner {
    pub face: u32,
    pub corner: u32,
}

/// A cage with its adjacency, checked to be a manifold OpenSubdiv accepts.
#[derive(Debug, Clone)]
pub struct Cage {
    /// Vertex positions.
    pub points: Vec<DVec3>,
    /// `face_vertices[face_start[f]..face_start[f + 1]]` are face `f`'s corners in order.
    face_start: Vec<u32>,
    face_vertices: Vec<u32>,
    /// The edge from each face corner to the next corner, parallel to `face_vertices`.
    face_edges: Vec<u32>,
    /// Edge end vertices, in the order the first face using the edge runs along it.
    edges: Vec<[u32; 2]>,
    /// The face running along the edge as stored (`[0]`) and the face running against it
    /// (`[1]`, [`NO_FACE`] at a boundary).
    edge_faces: Vec<[u32; 2]>,
    /// The faces around each vertex, counter-clockwise, from the leading boundary edge's face
    /// at a boundary vertex.
    vertex_faces: Vec<Vec<FaceCorner>>,
    /// Edge sharpness after the boundary rule (boundary edges infinitely sharp unless the
    /// rule is `None`).
    pub edge_sharpness: Vec<f32>,
    /// Vertex sharpness after the boundary rule.
    pub vertex_sharpness: Vec<f32>,
    /// Faces without a limit surface: tagged holes, and the boundary faces `None` removes.
    pub holes: Vec<bool>,
    /// The cage-wide rules.
    pub options: SubdivisionOptions,
    /// Each face's line in its file, for errors.
    face_lines: Vec<usize>,
}

impl Cage {
    /// Builds the adjacency of `mesh` with its tags.
    ///
    /// # Errors
    ///
    /// [`Error::Unsupported`] naming `file` and the face's line for what tessera does not
    /// subdivide yet: an edge used by more than two faces or twice in one direction
    /// (non-manifold or inconsistently oriented), a vertex whose faces form more than one fan,
    /// a face that uses a vertex twice.
    ///
    /// Cost: O(corners) time and memory, one hash map of the edges.
    pub fn new(mesh: &PolygonMesh, file: &Path) -> Result<Cage> {
        let mut face_start = Vec::with_capacity(mesh.faces.len() + 1);
        let mut face_vertices = Vec::new();
        face_start.push(0);
        for face in &mesh.faces {
            for (k, &v) in face.positions.iter().enumerate() {
                if face.positions[..k].contains(&v) {
                    return Err(Error::unsupported(
                        file,
                        face.line,
                        format!(
                            "face uses vertex {} twice; a subdivision cage's faces need distinct corners",
                            v + 1
                        ),
                    ));
                }
            }
            face_vertices.extend_from_slice(&face.positions);
            face_start.push(face_vertices.len() as u32);
        }
        let face_lines: Vec<usize> = mesh.faces.iter().map(|f| f.line).collect();
        let mut cage =
            Cage::with_topology(mesh.positions.clone(), face_start, face_vertices, face_lines, None, file)?;
        cage.options = mesh.tags.options;
        cage.apply_tags(mesh);
        Ok(cage)
    }

    /// A piece of a refined cage (the neighbourhood of a face at some level): the same
    /// adjacency, with sharpness given and only the vertices marked `complete` having all
    /// their faces (the others' order around them is not needed and not checked).
    ///
    /// Preconditions: faces with distinct corners, consistently oriented, manifold at the
    /// complete vertices; `edge_sharpness(a, b)` gives the sharpness of the edge between
    /// vertices `a` and `b`. Cost: O(corners).
    pub(crate) fn local(
        points: Vec<DVec3>,
        face_start: Vec<u32>,
        face_vertices: Vec<u32>,
        complete: &[bool],
        edge_sharpness: impl Fn(u32, u32) -> f32,
        vertex_sharpness: Vec<f32>,
        options: SubdivisionOptions,
    ) -> Cage {
        let lines = vec![0; face_start.len() - 1];
        let mut cage =
            Cage::with_topology(points, face_start, face_vertices, lines, Some(complete), Path::new(""))
                .expect("a refined neighbourhood is manifold where it is complete");
        cage.edge_sharpness = cage.edges.iter().map(|&[a, b]| edge_sharpness(a, b)).collect();
        cage.vertex_sharpness = vertex_sharpness;
        cage.options = options;
        cage
    }

    /// The adjacency of faces given by their corners; `complete` (for a local piece) says
    /// which vertices have all their faces, and only those are checked and ordered.
    fn with_topology(
        points: Vec<DVec3>,
        face_start: Vec<u32>,
        face_vertices: Vec<u32>,
        face_lines: Vec<usize>,
        complete: Option<&[bool]>,
        file: &Path,
    ) -> Result<Cage> {
        let faces = face_start.len() - 1;
        // Edges, each with the face along it and the face against it.
        let mut edge_of: WordMap<(u32, u32), u32> = Default::default();
        let mut edges: Vec<[u32; 2]> = Vec::new();
        let mut edge_faces: Vec<[u32; 2]> = Vec::new();
        let mut face_edges = vec![0u32; face_vertices.len()];
        for f in 0..faces {
            let (s, e) = (face_start[f] as usize, face_start[f + 1] as usize);
            let n = e - s;
            for k in 0..n {
                let (a, b) = (face_vertices[s + k], face_vertices[s + (k + 1) % n]);
                let id = *edge_of.entry((a.min(b), a.max(b))).or_insert_with(|| {
                    edges.push([a, b]);
                    edge_faces.push([NO_FACE, NO_FACE]);
                    (edges.len() - 1) as u32
                });
                let side = usize::from(edges[id as usize] != [a, b]);
                let slot = &mut edge_faces[id as usize][side];
                if *slot != NO_FACE {
                    let why = if side == 0 && edge_faces[id as usize][1] == NO_FACE {
                        "runs along edge {a}-{b} in the same direction as another face (the faces are not \
                         consistently oriented)"
                    } else {
                        "is the third face at edge {a}-{b} (a non-manifold edge)"
                    };
                    let why = why.replace("{a}", &(a + 1).to_string()).replace("{b}", &(b + 1).to_string());
                    return Err(Error::unsupported(
                        file,
                        face_lines[f],
                        format!("face {why}; tessera does not subdivide non-manifold cages yet"),
                    ));
                }
                *slot = f as u32;
                face_edges[s + k] = id;
            }
        }
        let vertices = points.len();
        let mut cage = Cage {
            points,
            face_start,
            face_vertices,
            face_edges,
            edges,
            edge_faces,
            vertex_faces: Vec::new(),
            edge_sharpness: Vec::new(),
            vertex_sharpness: vec![0.0; vertices],
            holes: vec![false; faces],
            options: SubdivisionOptions::default(),
            face_lines,
        };
        cage.vertex_faces = cage.order_vertex_faces(complete, file)?;
        Ok(cage)
    }

    /// The faces around every vertex in Vtr's order (see the module doc).
    fn order_vertex_faces(&self, complete: Option<&[bool]>, file: &Path) -> Result<Vec<Vec<FaceCorner>>> {
        let mut incident: Vec<Vec<FaceCorner>> = vec![Vec::new(); self.points.len()];
        for f in 0..self.face_count() {
            for (c, &v) in self.face(f).iter().enumerate() {
                incident[v as usize].push(FaceCorner { face: f as u32, corner: c as u32 });
            }
        }
        let mut ordered = Vec::with_capacity(incident.len());
        for (v, around) in incident.into_iter().enumerate() {
            if around.is_empty() || complete.is_some_and(|c| !c[v]) {
                ordered.push(around);
                continue;
            }
            // Start at the face whose leading edge is a boundary, if any.
            let start =
                around.iter().position(|fc| self.is_boundary_edge(self.leading_edge(*fc))).unwrap_or(0);
            let mut fan = vec![around[start]];
            loop {
                let last = *fan.last().unwrap();
                let Some(next) = self.across(last.face, self.trailing_edge(last)) else { break };
                if next == fan[0].face {
                    break;
                }
                let corner = self.face(next as usize).iter().position(|&x| x as usize == v).unwrap() as u32;
                fan.push(FaceCorner { face: next, corner });
                if fan.len() > around.len() {
                    break;
                }
            }
            if fan.len() != around.len() {
                let f = around[0].face as usize;
                return Err(Error::unsupported(
                    file,
                    self.face_lines[f],
                    format!(
                        "vertex {} has {} faces in more than one fan (a non-manifold vertex); \
                         tessera does not subdivide non-manifold cages yet",
                        v + 1,
                        around.len()
                    ),
                ));
            }
            ordered.push(fan);
        }
        Ok(ordered)
    }

    /// Sharpness, holes and the boundary rule, as Far prepares them.
    fn apply_tags(&mut self, mesh: &PolygonMesh) {
        let mut sharpness = vec![0.0f32; self.edges.len()];
        let mut edge_of: WordMap<(u32, u32), usize> = Default::default();
        for (e, &[a, b]) in self.edges.iter().enumerate() {
            edge_of.insert((a.min(b), a.max(b)), e);
        }
        for c in &mesh.tags.creases {
            let [a, b] = c.vertices;
            if let Some(&e) = edge_of.get(&(a.min(b), a.max(b))) {
                sharpness[e] = c.sharpness;
            }
        }
        for c in &mesh.tags.corners {
            self.vertex_sharpness[c.vertex as usize] = c.sharpness;
        }
        for &f in &mesh.tags.holes {
            self.holes[f as usize] = true;
        }
        let boundary = self.options.boundary;
        for (e, s) in sharpness.iter_mut().enumerate() {
            if self.is_boundary_edge(e as u32) && boundary != BoundaryInterpolation::None {
                *s = INFINITELY_SHARP;
            }
        }
        self.edge_sharpness = sharpness;
        for v in 0..self.points.len() {
            if !self.is_boundary_vertex(v) {
                continue;
            }
            match boundary {
                BoundaryInterpolation::EdgeAndCorner if self.vertex_faces[v].len() == 1 => {
                    self.vertex_sharpness[v] = INFINITELY_SHARP;
                }
                BoundaryInterpolation::None => {
                    let edges = self.vertex_edges(v);
                    let sharp = [edges[0], *edges.last().unwrap()]
                        .iter()
                        .all(|&e| self.edge_sharpness[e as usize] >= INFINITELY_SHARP);
                    if !sharp {
                        for fc in &self.vertex_faces[v] {
                            self.holes[fc.face as usize] = true;
                        }
                    }
                }
                _ => {}
            }
        }
    }

    /// Number of faces.
    pub fn face_count(&self) -> usize {
        self.face_start.len() - 1
    }

    /// Number of edges.
    pub fn edge_count(&self) -> usize {
        self.edges.len()
    }

    /// Face `f`'s corners in order.
    pub fn face(&self, f: usize) -> &[u32] {
        &self.face_vertices[self.face_start[f] as usize..self.face_start[f + 1] as usize]
    }

    /// The edges of face `f`: edge `k` runs from corner `k` to corner `k + 1`.
    pub fn face_edges(&self, f: usize) -> &[u32] {
        &self.face_edges[self.face_start[f] as usize..self.face_start[f + 1] as usize]
    }

    /// Edge `e`'s end vertices.
    pub fn edge(&self, e: u32) -> [u32; 2] {
        self.edges[e as usize]
    }

    /// Face `f`'s line in its file.
    pub fn face_line(&self, f: usize) -> usize {
        self.face_lines[f]
    }

    /// The faces of edge `e` (one at a boundary, else two).
    pub fn edge_faces(&self, e: u32) -> Vec<u32> {
        self.edge_faces[e as usize].iter().copied().filter(|&f| f != NO_FACE).collect()
    }

    /// The edge between vertices `a` and `b`, if any. Cost: O(faces around `a`).
    pub fn edge_between(&self, a: u32, b: u32) -> Option<u32> {
        self.vertex_faces[a as usize]
            .iter()
            .flat_map(|fc| [self.leading_edge(*fc), self.trailing_edge(*fc)])
            .find(|&e| {
                let [x, y] = self.edges[e as usize];
                (x, y) == (a, b) || (x, y) == (b, a)
            })
    }

    /// The sharpness of the edge between `a` and `b` (0 where there is none).
    pub fn edge_sharpness_between(&self, a: u32, b: u32) -> f32 {
        self.edge_between(a, b).map_or(0.0, |e| self.edge_sharpness[e as usize])
    }

    /// Whether edge `e` has a face on one side only.
    pub fn is_boundary_edge(&self, e: u32) -> bool {
        self.edge_faces[e as usize][1] == NO_FACE
    }

    /// Whether vertex `v` is on the boundary.
    pub fn is_boundary_vertex(&self, v: usize) -> bool {
        self.vertex_faces[v].first().is_some_and(|&fc| self.is_boundary_edge(self.leading_edge(fc)))
    }

    /// The faces around vertex `v` in order (module doc).
    pub fn vertex_faces(&self, v: usize) -> &[FaceCorner] {
        &self.vertex_faces[v]
    }

    /// The edges around vertex `v` in order: edge `k` is face `k`'s leading edge; a boundary
    /// vertex has one more, the last face's trailing edge.
    pub fn vertex_edges(&self, v: usize) -> Vec<u32> {
        let faces = &self.vertex_faces[v];
        let mut edges: Vec<u32> = faces.iter().map(|&fc| self.leading_edge(fc)).collect();
        if self.is_boundary_vertex(v) {
            edges.push(self.trailing_edge(*faces.last().unwrap()));
        }
        edges
    }

    /// The edge from a face's corner to its next corner.
    pub fn leading_edge(&self, fc: FaceCorner) -> u32 {
        self.face_edges(fc.face as usize)[fc.corner as usize]
    }

    /// The edge from a face's previous corner into this corner.
    pub fn trailing_edge(&self, fc: FaceCorner) -> u32 {
        let edges = self.face_edges(fc.face as usize);
        edges[(fc.corner as usize + edges.len() - 1) % edges.len()]
    }

    /// The face on the other side of edge `e` from face `f`, if any.
    pub fn across(&self, f: u32, e: u32) -> Option<u32> {
        let [a, b] = self.edge_faces[e as usize];
        let other = if a == f { b } else { a };
        (other != NO_FACE).then_some(other)
    }

    /// Whether face `f` is, by itself, one regular bicubic B-spline patch as Bfr decides it
    /// (`bfr/faceSurface.cpp`, `isRegular`): a quad with a limit surface whose corners' faces
    /// are all quads, with no sharp edge but boundary ones and no semi-sharp vertex, every
    /// corner of four faces inside, two faces on the boundary, or one face where it is an
    /// infinitely sharp corner. Cost: O(faces around its corners).
    pub fn is_regular_face(&self, f: usize) -> bool {
        let corners = self.face(f);
        if corners.len() != 4 || self.holes[f] {
            return false;
        }
        for &v in corners {
            let v = v as usize;
            let faces = &self.vertex_faces[v];
            if faces.iter().any(|fc| self.face(fc.face as usize).len() != 4) {
                return false;
            }
            let interior_sharp = self
                .vertex_edges(v)
                .iter()
                .any(|&e| !self.is_boundary_edge(e) && self.edge_sharpness[e as usize] > 0.0);
            let s = self.vertex_sharpness[v];
            if interior_sharp || (s > 0.0 && s < INFINITELY_SHARP) {
                return false;
            }
            let wanted = if s >= INFINITELY_SHARP {
                1
            } else if self.is_boundary_vertex(v) {
                2
            } else {
                4
            };
            if faces.len() != wanted {
                return false;
            }
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::obj::parse_obj;

    fn cage(text: &str) -> Result<Cage> {
        let mesh = parse_obj(text, Path::new("cage.obj"))?;
        Cage::new(&mesh, Path::new("cage.obj"))
    }

    /// A 3×3 grid of quads, vertices numbered row by row (1-based in the text).
    const GRID: &str = "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 3 0 0\nv 0 1 0\nv 1 1 0\nv 2 1 0\nv 3 1 0\n\
        v 0 2 0\nv 1 2 0\nv 2 2 0\nv 3 2 0\nv 0 3 0\nv 1 3 0\nv 2 3 0\nv 3 3 0\n\
        f 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 5 6 10 9\nf 6 7 11 10\nf 7 8 12 11\n\
        f 9 10 14 13\nf 10 11 15 14\nf 11 12 16 15\n";

    #[test]
    fn faces_around_a_vertex_run_counter_clockwise_from_the_boundary() {
        let c = cage(GRID).unwrap();
        // Interior vertex 5 (0-based; (1,1)): faces 0, 1, 4, 3 counter-clockwise; which comes
        // first is the first incident face, the order is what matters.
        let faces: Vec<u32> = c.vertex_faces(5).iter().map(|fc| fc.face).collect();
        assert_eq!(faces, [0, 1, 4, 3]);
        assert!(!c.is_boundary_vertex(5));
        // Boundary vertex 1 ((1,0)): face 1 leads along the boundary edge 1→2, then face 0.
        let faces: Vec<u32> = c.vertex_faces(1).iter().map(|fc| fc.face).collect();
        assert_eq!(faces, [1, 0]);
        let edges: Vec<[u32; 2]> = c.vertex_edges(1).iter().map(|&e| c.edge(e)).collect();
        assert_eq!(edges, [[1, 2], [1, 5], [0, 1]]);
        assert_eq!(c.edge_sharpness[c.vertex_edges(1)[0] as usize], INFINITELY_SHARP);
        assert_eq!(c.edge_sharpness[c.vertex_edges(1)[1] as usize], 0.0);
    }

    #[test]
    fn regular_faces_are_those_bfr_calls_regular() {
        // Edge-only boundaries (the default): the corner faces have a smooth valence-1 corner.
        let c = cage(GRID).unwrap();
        let regular: Vec<bool> = (0..9).map(|f| c.is_regular_face(f)).collect();
        assert_eq!(regular, [false, true, false, true, true, true, false, true, false]);
        // Edge-and-corner: those corners are sharp, so every face is regular.
        let c = cage(&format!("{GRID}t interpolateboundary 1/0/0 1\n")).unwrap();
        assert!((0..9).all(|f| c.is_regular_face(f)));
        // A crease through the middle makes the faces at its ends irregular.
        let c = cage(&format!("{GRID}t interpolateboundary 1/0/0 1\nt crease 2/1/0 5 6 1.5\n")).unwrap();
        let regular: Vec<bool> = (0..9).map(|f| c.is_regular_face(f)).collect();
        assert_eq!(regular, [false, false, false, false, false, false, true, true, true]);
        // A semi-sharp corner: the four faces around it.
        let c = cage(&format!("{GRID}t interpolateboundary 1/0/0 1\nt corner 1/1/0 5 2\n")).unwrap();
        let regular: Vec<bool> = (0..9).map(|f| c.is_regular_face(f)).collect();
        assert_eq!(regular, [false, false, true, false, false, true, true, true, true]);
    }

    #[test]
    fn boundary_rule_none_removes_the_faces_at_smooth_boundaries() {
        let c = cage(&format!("{GRID}t interpolateboundary 1/0/0 0\n")).unwrap();
        assert_eq!(c.holes, [true, true, true, true, false, true, true, true, true]);
        assert_eq!(c.edge_sharpness.iter().filter(|&&s| s > 0.0).count(), 0);
    }

    #[test]
    fn non_manifold_and_misoriented_cages_are_refused_at_their_face() {
        let fin = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 1 0 1\nv 0 0 1\nv 0 0 -1\n\
            f 1 2 3 4\nf 2 1 6 5\nf 2 1 7\n";
        let e = cage(fin).unwrap_err().to_string();
        assert!(e.contains("cage.obj:10: face is the third face at edge 2-1"), "{e}");
        let flipped = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 2 1 0\nf 1 2 3 4\nf 2 3 6 5\n";
        let e = cage(flipped).unwrap_err().to_string();
        assert!(e.contains("cage.obj:8: face runs along edge 2-3 in the same direction"), "{e}");
        let bowtie = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv -1 0 0\nv -1 -1 0\nf 1 2 3\nf 1 4 5\n";
        let e = cage(bowtie).unwrap_err().to_string();
        assert!(e.contains("vertex 1 has 2 faces in more than one fan"), "{e}");
    }
}
