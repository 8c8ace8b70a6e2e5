//! Regular faces: the 16 control points of a face's bicubic B-spline patch, with the phantom
//! points OpenSubdiv puts beyond a boundary, and their exact conversion to a Bézier net.
//!
//! A quad whose corners are regular (four faces inside, two on the boundary, one at a sharp
//! corner) is, in the limit, one uniform bicubic B-spline patch over the 4×4 grid of the
//! vertices around it. Where the grid leaves the cage (a boundary), Bfr does not store the
//! missing row or column but evaluates as if each missing point were `2·P_adjacent − P_next`
//! (`far/patchBasis.cpp`, `adjustBSplineBoundaryWeights`); that extrapolation is what makes the
//! boundary curve follow Catmull-Clark's boundary (crease) rule. The points are substituted
//! here instead, which is the same linear map.
//!
//! The B-spline → Bézier change of basis is exact (the cubic B-spline segment is a cubic
//! polynomial); doing it once per patch lets every Bézier criterion, bound and engine use
//! the patch unchanged.

use glam::DVec3;

use super::cage::{Cage, FaceCorner};

/// The B-spline grid of a regular face: `grid[row][col]`, `col` along the face's first edge
/// (corner 0 → 1, the patch's `u`), `row` along its last edge reversed (corner 0 → 3, `v`);
/// the face's corners 0, 1, 2, 3 are at `[1][1]`, `[1][2]`, `[2][2]`, `[2][1]`.
pub type BSplineGrid = [[DVec3; 4]; 4];

/// The B-spline grid of face `f`, phantom points filled in beyond boundary edges.
///
/// Precondition: [`Cage::is_regular_face`]`(f)`. Cost: O(16).
pub fn regular_face_grid(cage: &Cage, f: usize) -> BSplineGrid {
    let mut mask = 0;
    for (k, &e) in cage.face_edges(f).iter().enumerate() {
        mask |= u8::from(cage.is_boundary_edge(e)) << k;
    }
    grid(cage, f, mask)
}

/// The B-spline grid of a quad `f` whose corners are regular within the part of their ring
/// on `f`'s side of the edges in `mask` (bit `k`: edge `k` is a boundary or infinitely
/// sharp): the points around it, and phantom points beyond the edges in `mask`.
///
/// Precondition: `f` is a regular patch in Far's sense with that boundary mask (its corners'
/// rings, where not masked, are those of a regular grid). Cost: O(16).
pub(crate) fn grid(cage: &Cage, f: usize, mask: u8) -> BSplineGrid {
    // Each corner's position in the grid and the grid directions of its leading edge (to the
    // next corner) and trailing edge (to the previous corner), as (col, row).
    const AT: [(i32, i32); 4] = [(1, 1), (2, 1), (2, 2), (1, 2)];
    const LEADING: [(i32, i32); 4] = [(1, 0), (0, 1), (-1, 0), (0, -1)];
    let mut grid: [[Option<DVec3>; 4]; 4] = [[None; 4]; 4];
    let corners = cage.face(f);
    for (i, &v) in corners.iter().enumerate() {
        let (c, l) = (AT[i], LEADING[i]);
        let t = LEADING[(i + 3) % 4];
        let t = (-t.0, -t.1);
        let mut put = |d: (i32, i32), p: u32| {
            let (col, row) = (c.0 + d.0, c.1 + d.1);
            grid[row as usize][col as usize] = Some(cage.points[p as usize]);
        };
        put((0, 0), v);
        let fan = cage.vertex_faces(v as usize);
        let k = fan.iter().position(|fc| fc.face as usize == f).expect("the face is at its corner");
        let n = fan.len();
        let interior = !cage.is_boundary_vertex(v as usize);
        // The faces after this one counter-clockwise (across its trailing edge, then the
        // opposite one, then across its leading edge), where the cage has them; each is
        // read from the corner as [corner, leading, diagonal, trailing].
        // (Around a corner of another valence the patch is regular only within a span of one
        // or two faces between sharp edges, and the opposite quadrant is masked.)
        let step = |s: usize| -> Option<FaceCorner> { (interior || k + s < n).then(|| fan[(k + s) % n]) };
        let before = (k > 0 || interior).then(|| fan[(k + n - 1) % n]);
        let quads = [
            (step(1), [(t.0, t.1), (t.0 - l.0, t.1 - l.1), (-l.0, -l.1)]),
            (step(2).filter(|_| interior && n == 4), [(-l.0, -l.1), (-l.0 - t.0, -l.1 - t.1), (-t.0, -t.1)]),
            (before, [(-t.0, -t.1), (l.0 - t.0, l.1 - t.1), (l.0, l.1)]),
        ];
        for (face, offsets) in quads {
            let Some(fc) = face else { continue };
            let q = cage.face(fc.face as usize);
            for (s, d) in offsets.iter().enumerate() {
                put(*d, q[(fc.corner as usize + 1 + s) % 4]);
            }
        }
    }
    fill_phantoms(&mut grid, mask);
    grid.map(|row| row.map(|p| p.expect("a regular face's grid is complete after the phantoms")))
}

/// Replaces the row or column beyond each boundary edge (bit `k` of `mask` for patch edge
/// `k`: 0 is row 0, 1 column 3, 2 row 3, 3 column 0) by `2·P_adjacent − P_next`, across the
/// whole line. The edges are taken in the order 3, 2, 1, 0: the point form of the weight
/// adjustments `adjustBSplineBoundaryWeights` makes in the order 0, 1, 2, 3, so a corner
/// point beyond two boundary edges comes out as Bfr's, and a point beyond one edge is
/// extrapolated across that edge only (from the real points of its line).
fn fill_phantoms(grid: &mut [[Option<DVec3>; 4]; 4], mask: u8) {
    let extrapolate = |a: Option<DVec3>, b: Option<DVec3>| Some(2.0 * a? - b?);
    for edge in [3, 2, 1, 0] {
        if mask & (1 << edge) == 0 {
            continue;
        }
        // (Rows and columns by turns: an index loop reads plainest.)
        #[allow(clippy::needless_range_loop)]
        for i in 0..4 {
            match edge {
                0 => grid[0][i] = extrapolate(grid[1][i], grid[2][i]),
                1 => grid[i][3] = extrapolate(grid[i][2], grid[i][1]),
                2 => grid[3][i] = extrapolate(grid[2][i], grid[1][i]),
                _ => grid[i][0] = extrapolate(grid[i][1], grid[i][2]),
            }
        }
    }
}

/// The uniform cubic B-spline segment's control points in the Bézier basis: `b = M·p`.
const TO_BEZIER: [[f64; 4]; 4] = [
    [1.0 / 6.0, 4.0 / 6.0, 1.0 / 6.0, 0.0],
    [0.0, 4.0 / 6.0, 2.0 / 6.0, 0.0],
    [0.0, 2.0 / 6.0, 4.0 / 6.0, 0.0],
    [0.0, 1.0 / 6.0, 4.0 / 6.0, 1.0 / 6.0],
];

/// The same surface as a bicubic Bézier net, in [`crate::surface::RationalBicubic`]'s order
/// (`points[4*i + j]`, `i` along `u`, `j` along `v`). Cost: 2 × 64 multiply-adds.
pub fn to_bezier(grid: &BSplineGrid) -> [DVec3; 16] {
    // Rows first (along u), then columns (along v).
    let mut rows = [[DVec3::ZERO; 4]; 4];
    for r in 0..4 {
        for (i, m) in TO_BEZIER.iter().enumerate() {
            rows[r][i] = (0..4).map(|j| grid[r][j] * m[j]).sum();
        }
    }
    let mut out = [DVec3::ZERO; 16];
    for i in 0..4 {
        for (j, m) in TO_BEZIER.iter().enumerate() {
            out[4 * i + j] = (0..4).map(|r| rows[r][i] * m[r]).sum();
        }
    }
    out
}

/// The B-spline patch at `(u, v)` evaluated directly (cubic B-spline basis), for tests.
#[cfg(test)]
pub(crate) fn eval_bspline(grid: &BSplineGrid, u: f64, v: f64) -> DVec3 {
    let basis = |t: f64| {
        let s = 1.0 - t;
        [
            s * s * s / 6.0,
            (3.0 * t * t * t - 6.0 * t * t + 4.0) / 6.0,
            (-3.0 * t * t * t + 3.0 * t * t + 3.0 * t + 1.0) / 6.0,
            t * t * t / 6.0,
        ]
    };
    let (bu, bv) = (basis(u), basis(v));
    let mut p = DVec3::ZERO;
    for r in 0..4 {
        for c in 0..4 {
            p += grid[r][c] * (bv[r] * bu[c]);
        }
    }
    p
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::RationalBicubic;
    use glam::DVec2;

    #[test]
    fn the_bezier_net_is_the_same_surface() {
        let mut rng = crate::test_support::Lcg(7);
        let grid: BSplineGrid = std::array::from_fn(|_| {
            std::array::from_fn(|_| DVec3::new(rng.unit53(), rng.unit53(), rng.unit53()))
        });
        let patch = RationalBicubic::polynomial(to_bezier(&grid));
        for k in 0..50 {
            let (u, v) = (rng.unit53(), rng.unit53());
            let d = (patch.position(DVec2::new(u, v)) - eval_bspline(&grid, u, v)).length();
            assert!(d < 1e-14, "sample {k}: {d}");
        }
    }
}
