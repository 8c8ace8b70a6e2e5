//! The polygon mesh every mesh reader returns (OBJ, PLY, glTF) and the one rule that turns
//! its polygons into triangles.

use std::path::Path;

use glam::DVec3;

use super::subdivision_tags::SubdivisionTags;
use crate::error::{Error, Result};
use crate::mesh::Mesh;

/// One polygon of an input mesh.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PolygonFace {
    /// Corner positions, 0-based into [`PolygonMesh::positions`], in file order; at least 3.
    pub positions: Vec<u32>,
    /// Corner normals, 0-based into [`PolygonMesh::normals`], same length as `positions`;
    /// `None` unless every corner of the face names a normal.
    pub normals: Option<Vec<u32>>,
    /// 1-based line of the face in its file (an OBJ `f` statement's first line when it is
    /// continued; the element's line for PLY); 0 where the format has no lines.
    pub line: usize,
}

/// A polygon mesh as every mesh reader returns it (OBJ, PLY, glTF): the input of PN triangles
/// and of `tessera check`. Every face index is in range.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PolygonMesh {
    /// Vertex positions (`v`), all finite, in file order.
    pub positions: Vec<DVec3>,
    /// Vertex normals (`vn`), all finite, in file order, as written (not normalised).
    pub normals: Vec<DVec3>,
    /// Faces (`f`), in file order; never empty after a successful parse.
    pub faces: Vec<PolygonFace>,
    /// Primitives of a glTF input that are no surface (`POINTS`, `LINES`) and were left out;
    /// 0 for every other format.
    pub skipped_primitives: usize,
    /// OpenSubdiv's tag lines of an OBJ subdivision cage (creases, corners, holes, boundary
    /// rule), checked against the faces; empty for every other input.
    pub tags: SubdivisionTags,
}

impl PolygonMesh {
    /// The faces as position triangles, for inputs that must be triangle meshes
    /// (PN triangles).
    ///
    /// `file` names the source in the error.
    ///
    /// # Errors
    ///
    /// [`Error::Unsupported`] at the line of the first face that is not a triangle
    /// ("face has N vertices; ...").
    ///
    /// Cost: O(faces).
    pub fn triangles(&self, file: &Path) -> Result<Vec<[u32; 3]>> {
        let mut out = Vec::with_capacity(self.faces.len());
        for face in &self.faces {
            match *face.positions.as_slice() {
                [a, b, c] => out.push([a, b, c]),
                ref other => {
                    return Err(Error::unsupported(
                        file,
                        face.line,
                        format!(
                            "face has {} vertices; PN triangles need triangles \
                             (triangulate the mesh first)",
                            other.len()
                        ),
                    ));
                }
            }
        }
        Ok(out)
    }
}

/// The triangles a polygon of `n ≥ 3` corners is split into, as corner numbers: the fan
/// `(0, k, k + 1)` from its first corner, which keeps the polygon's orientation and is exact
/// for the convex (and planar) polygons mesh writers emit. The one rule every reader applies
/// to polygons ([`PolygonMesh::split_polygons`] for OBJ, the PLY reader).
pub(crate) fn fan(n: usize) -> impl Iterator<Item = [usize; 3]> {
    (1..n.saturating_sub(1)).map(|k| [0, k, k + 1])
}

impl PolygonMesh {
    /// Splits every face of more than three corners into triangles (a fan from its first
    /// corner, corner normals alike, each keeping the face's line) and returns how many faces
    /// were split: the input of PN triangles, which need triangles, gets every format's
    /// polygons the same way, reported as a repair.
    ///
    /// Cost: O(corners); nothing moves when every face is a triangle.
    pub fn split_polygons(&mut self) -> usize {
        let split = self.faces.iter().filter(|f| f.positions.len() > 3).count();
        if split == 0 {
            return 0;
        }
        let faces = std::mem::take(&mut self.faces);
        for face in faces {
            let pick = |c: &[u32], t: [usize; 3]| t.map(|k| c[k]).to_vec();
            for t in fan(face.positions.len()) {
                self.faces.push(PolygonFace {
                    positions: pick(&face.positions, t),
                    normals: face.normals.as_deref().map(|n| pick(n, t)),
                    line: face.line,
                });
            }
        }
        split
    }

    /// The mesh as a triangle [`Mesh`] (for checking, not tessellating): positions rounded to
    /// `f32`, zero normals and uvs, patch 0 everywhere, polygons split as
    /// [`PolygonMesh::split_polygons`] does (as the PLY reader splits them).
    ///
    /// # Errors
    ///
    /// None today (kept a `Result` for the readers' uniform signature).
    ///
    /// Cost: O(vertices + faces).
    pub fn to_mesh(&self, file: &Path) -> Result<Mesh> {
        let mut split = self.clone();
        split.split_polygons();
        let tris = split.triangles(file)?;
        let n = self.positions.len();
        Ok(Mesh {
            positions: self.positions.iter().map(|p| p.as_vec3().to_array()).collect(),
            normals: vec![[0.0; 3]; n],
            uvs: vec![[0.0; 2]; n],
            vertex_patch: vec![0; n],
            indices: tris.iter().flatten().copied().collect(),
            triangle_patch: vec![0; tris.len()],
            ..Default::default()
        })
    }

    /// A triangle [`Mesh`] as an OBJ-like polygon mesh, the input of
    /// [`SurfaceSet::pn_from_mesh`](crate::surface::SurfaceSet::pn_from_mesh): every vertex
    /// keeps its position, and its normal when the mesh has any non-zero normal (a mesh read
    /// from a file without normals has all zero ones, which count as none). Faces get line 0.
    ///
    /// Preconditions: a consistent mesh (indices in range), as every reader returns.
    ///
    /// Cost: O(vertices + triangles).
    pub fn from_mesh(mesh: &Mesh) -> PolygonMesh {
        let has_normals = mesh.normals.iter().any(|n| n.iter().any(|&c| c != 0.0));
        let faces = mesh
            .indices
            .chunks_exact(3)
            .map(|t| PolygonFace { positions: t.to_vec(), normals: has_normals.then(|| t.to_vec()), line: 0 })
            .collect();
        PolygonMesh {
            positions: mesh.positions.iter().map(|p| DVec3::from(p.map(f64::from))).collect(),
            normals: if has_normals {
                mesh.normals.iter().map(|n| DVec3::from(n.map(f64::from))).collect()
            } else {
                Vec::new()
            },
            faces,
            skipped_primitives: 0,
            tags: SubdivisionTags::default(),
        }
    }
}
