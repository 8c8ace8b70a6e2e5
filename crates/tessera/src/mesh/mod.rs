//! Output mesh buffers. The readers and writers of every format are in [`crate::io`] (one
//! file per format).
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

/// The arrays of one frame's output, lent to the engine to write in parallel: exactly the
/// frame's vertex count for the vertex arrays, three indices and one patch a triangle
/// (`Mesh`'s layout, struct of arrays). A [`crate::tessellator::MeshBuilder`] with its own
/// arrays lends them through [`crate::tessellator::MeshBuilder::buffers`].
#[derive(Debug)]
pub struct MeshBuffers<'a> {
    /// Vertex positions.
    pub positions: &'a mut [[f32; 3]],
    /// Unit vertex normals.
    pub normals: &'a mut [[f32; 3]],
    /// Each vertex's parameters in its patch.
    pub uvs: &'a mut [[f32; 2]],
    /// The patch that evaluated each vertex.
    pub vertex_patch: &'a mut [u32],
    /// Three vertex indices a triangle.
    pub indices: &'a mut [u32],
    /// The patch of each triangle.
    pub triangle_patch: &'a mut [u32],
}

impl MeshBuffers<'_> {
    /// Whether the arrays hold exactly `vertices` vertices and `triangles` triangles.
    pub fn fit(&self, vertices: usize, triangles: usize) -> bool {
        [self.positions.len(), self.normals.len(), self.uvs.len(), self.vertex_patch.len()]
            .iter()
            .all(|&n| n == vertices)
            && self.indices.len() == 3 * triangles
            && self.triangle_patch.len() == triangles
    }
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

    /// Removes the vertices no triangle (and no strip) refers to, keeping the others in
    /// their order, and renumbers `indices` and `strips`; returns how many were removed.
    ///
    /// The engine's numbering rule gives every corner of the set a vertex and every edge a
    /// patch sees its samples (see [`crate::engine::layout`]), so a frame that culls patches
    /// keeps the corners (and normal variants) only culled patches use: harmless to a
    /// renderer, but a written file should hold only what it draws, and its vertex count
    /// should be what other tools count. Call this before writing a culled mesh.
    ///
    /// Preconditions: indices in range (strips' [`strips::RESTART`] markers aside).
    ///
    /// Cost: O(vertices + indices) time, one `u32` per vertex of scratch; nothing is moved
    /// when every vertex is used.
    pub fn drop_unused_vertices(&mut self) -> usize {
        let n = self.positions.len();
        let mut new_index = vec![u32::MAX; n];
        let strip_indices = self.strips.iter().flatten().filter(|&&i| i != strips::RESTART);
        for &i in self.indices.iter().chain(strip_indices) {
            new_index[i as usize] = 0;
        }
        let mut kept = 0u32;
        for slot in new_index.iter_mut().filter(|slot| **slot == 0) {
            *slot = kept;
            kept += 1;
        }
        let removed = n - kept as usize;
        if removed == 0 {
            return 0;
        }
        fn keep<T: Copy>(values: &mut Vec<T>, new_index: &[u32]) {
            let mut next = 0;
            for old in 0..values.len().min(new_index.len()) {
                if new_index[old] != u32::MAX {
                    values[next] = values[old];
                    next += 1;
                }
            }
            values.truncate(next);
        }
        keep(&mut self.positions, &new_index);
        keep(&mut self.normals, &new_index);
        keep(&mut self.uvs, &new_index);
        keep(&mut self.vertex_patch, &new_index);
        for i in self.indices.iter_mut() {
            *i = new_index[*i as usize];
        }
        for i in self.strips.iter_mut().flatten().filter(|i| **i != strips::RESTART) {
            *i = new_index[*i as usize];
        }
        removed
    }
}

/// Bytes a [`Mesh`] of `vertices` and `triangles` holds (its arrays, with `corner_params` its
/// per-corner patch parameters): what an engine allocates for that output. Cost: O(1).
pub fn output_bytes(vertices: u64, triangles: u64, corner_params: bool) -> u64 {
    let per_vertex = 12 + 12 + 8 + 4; // position, normal, uv, patch
    let per_triangle = 12 + 4 + if corner_params { 24 } else { 0 };
    vertices.saturating_mul(per_vertex).saturating_add(triangles.saturating_mul(per_triangle))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn drop_unused_vertices_keeps_order_attributes_and_strips() {
        let mut mesh = Mesh {
            positions: (0..6).map(|i| [i as f32, 0.0, 0.0]).collect(),
            normals: (0..6).map(|i| [0.0, i as f32, 1.0]).collect(),
            uvs: (0..6).map(|i| [i as f32, 1.0]).collect(),
            vertex_patch: vec![0, 1, 2, 3, 4, 5],
            indices: vec![1, 3, 4, 4, 3, 5],
            triangle_patch: vec![7, 8],
            strips: Some(vec![1, 3, 4, 5, strips::RESTART, 4, 3, 5]),
            ..Default::default()
        };
        assert_eq!(mesh.drop_unused_vertices(), 2);
        assert_eq!(mesh.positions, vec![[1.0, 0.0, 0.0], [3.0, 0.0, 0.0], [4.0, 0.0, 0.0], [5.0, 0.0, 0.0]]);
        assert_eq!(mesh.normals[1], [0.0, 3.0, 1.0]);
        assert_eq!(mesh.uvs[3], [5.0, 1.0]);
        assert_eq!(mesh.vertex_patch, vec![1, 3, 4, 5]);
        assert_eq!(mesh.indices, vec![0, 1, 2, 2, 1, 3]);
        assert_eq!(mesh.strips, Some(vec![0, 1, 2, 3, strips::RESTART, 2, 1, 3]));
        assert_eq!(mesh.triangle_patch, vec![7, 8]);
        let before = mesh.clone();
        assert_eq!(mesh.drop_unused_vertices(), 0);
        assert_eq!(mesh, before);
    }
}

pub mod strips;
