//! Output mesh buffers. The readers and writers of every format are in [`crate::io`] (one
//! file per format); the old paths `mesh::read_mesh`, `mesh::write_mesh`, `mesh::read::*` and
//! `mesh::write::*` are re-exports of them.
//!
//! The engine writes one indexed triangle mesh. Vertices shared by several patches carry the
//! patch id and (u, v) of the patch that evaluated them (the edge's or corner's *owner*).
//! Where a triangle needs the parameters of its corners in its own patch (error measurement),
//! the engine fills [`Mesh::corner_params`] on request.

/// One indexed triangle mesh, in plain buffers (meshoptimizer style).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Mesh {
    /// Vertex positions.
    pub positions: Vec<[f32; 3]>,
    /// Unit vertex normals, one per position.
    pub normals: Vec<[f32; 3]>,
    /// Parameters of each vertex in the patch given by `vertex_patch`.
    pub uvs: Vec<[f32; 2]>,
    /// The patch that evaluated each vertex.
    pub vertex_patch: Vec<u32>,
    /// Triangle list, counter-clockwise seen from the normal side; 3 indices a triangle.
    pub indices: Vec<u32>,
    /// The patch each triangle belongs to.
    pub triangle_patch: Vec<u32>,
    /// Optional: for every triangle corner (parallel to `indices`), its parameters in the
    /// triangle's own patch. Filled by the engine when asked; needed to measure the
    /// approximation error against the exact surface.
    pub corner_params: Option<Vec<[f32; 2]>>,
    /// Optional: the same triangles as triangle strips ([`strips`]), when asked for and
    /// the scheme has a strip form. `indices` always holds the decoded list, so a writer
    /// that cannot store strips loses nothing.
    pub strips: Option<Vec<u32>>,
    /// Pattern triangles the engine did not emit because two of their corners are one vertex
    /// (at a boundary curve collapsed to a point, such as the teapot's lid apex): a
    /// documented repair, reported by the CLI.
    pub collapsed_triangles: usize,
}

impl Mesh {
    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }

    /// Number of vertices.
    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    /// The vertex indices of triangle `t`.
    pub fn triangle(&self, t: usize) -> [u32; 3] {
        [self.indices[3 * t], self.indices[3 * t + 1], self.indices[3 * t + 2]]
    }
}

pub mod strips;

pub use crate::io::{check_output_path, read_mesh, write_mesh};

/// The mesh readers, now in [`crate::io`]; re-exported so the old paths keep working.
pub mod read {
    pub use crate::io::glb::parse_glb;
    pub use crate::io::ply::parse_ply;
    pub use crate::io::read_mesh;
    pub use crate::io::stl::parse_stl;
}

/// The mesh writers, now in [`crate::io`]; re-exported so the old paths keep working.
pub mod write {
    pub use crate::io::glb::write_glb;
    pub use crate::io::obj::write_obj;
    pub use crate::io::ply::write_ply;
    pub use crate::io::stl::write_stl;
    pub use crate::io::{check_output_path, write_mesh};
}
