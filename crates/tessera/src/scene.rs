//! Benchmark scenes built in code: many copies of one model in a grid, as the real-time
//! measurements use (45 copies of the 2,048-patch torus make the 92,160-patch scene; 11
//! copies of a mesh cage make a herd of PN triangles). Nothing here is stored on disk, so a
//! benchmark states its scene by the model and the number of copies.
//!
//! No model of the shared data is rational, so the rational paths get theirs here too: any
//! patch model with weights that are a function of position ([`position_weights`]), and
//! the exact conics of revolution ([`sphere_octant`], [`cylinder`]).

use crate::camera::Camera;
use crate::io::patches::PatchFile;
use crate::surface::subdivision_tags::{Corner, Crease};
use crate::surface::RationalBicubic;
use crate::surface::{PolygonFace, PolygonMesh};
use glam::{DQuat, DVec2, DVec3};

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

/// `copies` copies of a polygon mesh in a grid ([`grid_offsets`]), copy by copy (copy `c`'s
/// faces are faces `c·F ..`); a subdivision cage's creases, corners and holes are copied with
/// their copy, its cage-wide rules kept once. Cost: O(copies × mesh size).
pub fn mesh_grid(mesh: &PolygonMesh, copies: usize) -> PolygonMesh {
    let (lo, hi) = point_bounds(&mesh.positions);
    let mut out = PolygonMesh { tags: mesh.tags.clone(), ..PolygonMesh::default() };
    out.tags.creases.clear();
    out.tags.corners.clear();
    out.tags.holes.clear();
    let (vertices, faces) = (mesh.positions.len() as u32, mesh.faces.len() as u32);
    for c in 0..copies as u32 {
        let t = &mesh.tags;
        out.tags.creases.extend(
            t.creases.iter().map(|k| Crease { vertices: k.vertices.map(|v| v + c * vertices), ..*k }),
        );
        out.tags.corners.extend(t.corners.iter().map(|k| Corner { vertex: k.vertex + c * vertices, ..*k }));
        out.tags.holes.extend(t.holes.iter().map(|&f| f + c * faces));
    }
    for offset in grid_offsets(lo, hi, copies) {
        let (p0, n0) = (out.positions.len() as u32, out.normals.len() as u32);
        out.faces.extend(mesh.faces.iter().map(|f| PolygonFace {
            positions: f.positions.iter().map(|&i| i + p0).collect(),
            normals: f.normals.as_ref().map(|n| n.iter().map(|&i| i + n0).collect()),
            line: f.line,
        }));
        out.positions.extend(mesh.positions.iter().map(|&p| p + offset));
        out.normals.extend_from_slice(&mesh.normals);
    }
    out
}

/// The patches of `file` made rational: each control point's weight is
/// `2^sin(8 (3x + 2y − z) / d)`, within `[0.5, 2]`, with `d` the points' bounding-box diagonal.
/// Being a function of position, a weight is the same wherever its point is shared (by index
/// or by position), so boundary curves stay shared and the model as watertight as the input;
/// it varies within a patch (on the 2,048-patch torus, by up to about 1.6×), so every patch
/// is genuinely rational. Cost: O(points).
pub fn position_weights(file: &PatchFile) -> PatchFile {
    let (lo, hi) = point_bounds(&file.points);
    let scale = 8.0 / lo.distance(hi).max(f64::MIN_POSITIVE);
    let weights = file.points.iter().map(|p| (scale * (3.0 * p.x + 2.0 * p.y - p.z)).sin().exp2()).collect();
    PatchFile { weights, ..file.clone() }
}

/// A quarter of the unit circle from `(1, 0)` to `(0, 1)`, exact: the rational quadratic with
/// weights `1, √½, 1` raised to degree 3. Returns the four control points and weights.
pub fn quarter_circle() -> ([DVec2; 4], [f64; 4]) {
    let (p, w) = ([DVec2::X, DVec2::ONE, DVec2::Y], [1.0, 0.5f64.sqrt(), 1.0]);
    let w1 = (w[0] + 2.0 * w[1]) / 3.0;
    let w2 = (2.0 * w[1] + w[2]) / 3.0;
    let q1 = (p[0] * w[0] + p[1] * (2.0 * w[1])) / (3.0 * w1);
    let q2 = (p[1] * (2.0 * w[1]) + p[2] * w[2]) / (3.0 * w2);
    ([p[0], q1, q2, p[2]], [w[0], w1, w2, w[2]])
}

/// The octant `x, y, z ≥ 0` of the unit sphere, exact, as a rational bicubic surface of
/// revolution: `u` turns around `z`, `v` climbs the meridian from the equator to the pole
/// (control row `j = 3` collapses to the pole). Cost: O(1).
pub fn sphere_octant() -> RationalBicubic {
    let (c, wc) = quarter_circle();
    let mut points = [DVec3::ZERO; 16];
    let mut weights = [0.0; 16];
    for i in 0..4 {
        for j in 0..4 {
            // Meridian point j: (radius, height) = (c[j].x, c[j].y).
            points[4 * i + j] = DVec3::new(c[i].x * c[j].x, c[i].y * c[j].x, c[j].y);
            weights[4 * i + j] = wc[i] * wc[j];
        }
    }
    RationalBicubic { points, weights }
}

/// The unit-radius cylinder around `z`, from `z = 0` to `z = height`, exact: four rational
/// quarter pieces (`u` around, `v` up) that share their seams by index, open at both ends.
/// Cost: O(1).
pub fn cylinder(height: f64) -> PatchFile {
    let (c, wc) = quarter_circle();
    let mut file = PatchFile::default();
    // Quarter q is the first turned by q right angles (exact: coordinates swap and negate).
    let turn = |q: usize, p: DVec2| match q {
        0 => p,
        1 => DVec2::new(-p.y, p.x),
        2 => -p,
        _ => DVec2::new(p.y, -p.x),
    };
    for q in 0..4 {
        for i in 0..3 {
            for j in 0..4 {
                let p = turn(q, c[i]);
                file.points.push(DVec3::new(p.x, p.y, j as f64 / 3.0 * height));
                file.weights.push(wc[i]);
            }
        }
    }
    // Point (q, i, j) is 12 q + 4 i + j; the end column i = 3 of a quarter is the next one's
    // first.
    let index = |q: usize, i: usize, j: usize| {
        let (q, i) = if i == 3 { ((q + 1) % 4, 0) } else { (q, i) };
        (12 * q + 4 * i + j) as u32
    };
    for q in 0..4 {
        file.patches.push(std::array::from_fn(|k| index(q, k / 4, k % 4)));
        // The line the patch would have in a written file.
        file.lines.push(q + 2);
    }
    file
}

/// A walk of `frames` cameras through a scene bounded by `lo..hi`: it starts at the framing
/// camera (the whole scene in view) and dollies in to
/// a third of the distance while orbiting 40° about the up axis, so that later frames see
/// fewer patches, nearer and larger. The frame and subdivision suites walk it; the
/// `cage_frame` example takes the subdivision suite's camera, frame 1 of 3. Cost: O(frames).
pub fn walk(lo: DVec3, hi: DVec3, frames: usize, width: u32, height: u32) -> Vec<Camera> {
    let start = Camera::framing(lo, hi, width, height);
    let offset = start.eye - start.target;
    let axis = start.up.normalize();
    (0..frames)
        .map(|f| {
            let t = if frames > 1 { f as f64 / (frames - 1) as f64 } else { 0.0 };
            let turn = DQuat::from_axis_angle(axis, 40f64.to_radians() * t);
            let distance = 1.0 - 0.66 * t;
            let eye = start.target + turn * offset * distance;
            Camera { eye, near: offset.length() * 1e-3, ..start }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn copies_of_a_cage_carry_its_tags() {
        let path = crate::test_support::data("subdivision/catmark_rook.obj");
        let mesh = crate::io::obj::read_obj(&path).unwrap();
        assert!(!mesh.tags.creases.is_empty(), "the rook has creases");
        let grid = mesh_grid(&mesh, 3);
        let (v, f) = (mesh.positions.len() as u32, mesh.faces.len());
        assert_eq!(grid.faces.len(), 3 * f);
        assert_eq!(grid.tags.creases.len(), 3 * mesh.tags.creases.len());
        assert_eq!(grid.tags.options, mesh.tags.options);
        for (c, copy) in grid.tags.creases.chunks(mesh.tags.creases.len()).enumerate() {
            for (k, crease) in copy.iter().zip(&mesh.tags.creases) {
                assert_eq!(k.vertices, crease.vertices.map(|i| i + c as u32 * v));
                assert_eq!(k.sharpness, crease.sharpness);
            }
        }
        // The copies are the same surface, moved: each copy's patches equal the first's.
        let one =
            crate::surface::SurfaceSet::from_subdivision_cage(&mesh, &path, Default::default()).unwrap();
        let three =
            crate::surface::SurfaceSet::from_subdivision_cage(&grid, &path, Default::default()).unwrap();
        assert_eq!(three.patches.len(), 3 * one.patches.len());
        let offset = grid.positions[v as usize] - mesh.positions[0];
        for (a, b) in one.patches.iter().zip(&three.patches[one.patches.len()..]) {
            let (pa, pb) = (a.position(DVec2::splat(0.3)), b.position(DVec2::splat(0.3)));
            assert!((pb - pa - offset).length() < 1e-9, "{pa} {pb}");
        }
    }

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
