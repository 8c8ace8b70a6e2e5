//! Benchmark scenes built in code: many copies of one model in a grid, as the real-time
//! measurements use (45 copies of the 2,048-patch torus make the 92,160-patch scene; 11
//! copies of a mesh cage make a herd of PN triangles). Nothing here is stored on disk, so a
//! benchmark states its scene by the model and the number of copies.

use crate::io::obj::{ObjFace, ObjMesh};
use crate::io::patches::PatchFile;
use glam::DVec3;

/// Offsets of `copies` copies of a box `lo..hi` laid out in a near-square grid in the box's
/// two largest dimensions, a fifth of the box apart. Cost: O(copies).
pub fn grid_offsets(lo: DVec3, hi: DVec3, copies: usize) -> Vec<DVec3> {
    let size = (hi - lo).max(DVec3::splat(1e-9)) * 1.2;
    // The two largest axes of the box carry the grid, so flat models lie side by side.
    let mut axes = [0usize, 1, 2];
    axes.sort_by(|&a, &b| size[b].total_cmp(&size[a]));
    let columns = (copies as f64).sqrt().ceil().max(1.0) as usize;
    (0..copies)
        .map(|k| {
            let mut offset = DVec3::ZERO;
            offset[axes[0]] = (k % columns) as f64 * size[axes[0]];
            offset[axes[1]] = (k / columns) as f64 * size[axes[1]];
            offset
        })
        .collect()
}

fn point_bounds(points: &[DVec3]) -> (DVec3, DVec3) {
    points.iter().fold((DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)), |(lo, hi), &p| {
        (lo.min(p), hi.max(p))
    })
}

/// `copies` copies of a patch file in a grid ([`grid_offsets`]), each with its own control
/// points (copies share no edges). Cost: O(copies × file size).
pub fn patch_grid(file: &PatchFile, copies: usize) -> PatchFile {
    let (lo, hi) = point_bounds(&file.points);
    let mut out = PatchFile::default();
    for offset in grid_offsets(lo, hi, copies) {
        let base = out.points.len() as u32;
        out.patches.extend(file.patches.iter().map(|p| p.map(|i| i + base)));
        out.points.extend(file.points.iter().map(|&p| p + offset));
        out.weights.extend_from_slice(&file.weights);
        out.lines.extend_from_slice(&file.lines);
    }
    out
}

/// `copies` copies of a polygon mesh in a grid ([`grid_offsets`]). Cost: O(copies × mesh
/// size).
pub fn mesh_grid(mesh: &ObjMesh, copies: usize) -> ObjMesh {
    let (lo, hi) = point_bounds(&mesh.positions);
    let mut out = ObjMesh::default();
    for offset in grid_offsets(lo, hi, copies) {
        let (p0, n0) = (out.positions.len() as u32, out.normals.len() as u32);
        out.faces.extend(mesh.faces.iter().map(|f| ObjFace {
            positions: f.positions.iter().map(|&i| i + p0).collect(),
            normals: f.normals.as_ref().map(|n| n.iter().map(|&i| i + n0).collect()),
            line: f.line,
        }));
        out.positions.extend(mesh.positions.iter().map(|&p| p + offset));
        out.normals.extend_from_slice(&mesh.normals);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn copies_do_not_overlap_and_keep_the_model() {
        let file = PatchFile {
            patches: vec![std::array::from_fn(|k| k as u32)],
            points: (0..16).map(|k| DVec3::new((k % 4) as f64, (k / 4) as f64, 0.1 * k as f64)).collect(),
            weights: vec![1.0; 16],
            lines: vec![2],
        };
        let grid = patch_grid(&file, 5);
        assert_eq!(grid.patches.len(), 5);
        assert_eq!(grid.points.len(), 80);
        let boxes: Vec<_> = (0..5).map(|c| point_bounds(&grid.points[16 * c..16 * (c + 1)])).collect();
        for (a, &(alo, ahi)) in boxes.iter().enumerate() {
            assert!(((ahi - alo) - (hi_minus_lo(&file))).abs().max_element() < 1e-12);
            for &(blo, bhi) in &boxes[a + 1..] {
                let apart = (0..3).any(|i| ahi[i] < blo[i] || bhi[i] < alo[i]);
                assert!(apart, "copies overlap");
            }
        }
        assert_eq!(grid.patches[3][0], 48);
    }

    fn hi_minus_lo(file: &PatchFile) -> DVec3 {
        let (lo, hi) = point_bounds(&file.points);
        hi - lo
    }
}
