//! The core of a quad pattern as a rule instead of a list: a rectangle of cells of the
//! `nu × nv` grid, triangulated cell by cell in a fixed order, its vertices numbered by the
//! grid rule of the local numbering. A pattern that promises one ([`super::Pattern::core_grid`],
//! the transition pattern's core) needs no list of the core's triangles: its builder and an
//! engine's index writer both run [`CoreGrid::write`], the one loop that numbers them, with
//! local indices or with output indices. A fine adaptive pattern is mostly core (the rook's
//! distinct transition patterns at 0.5 px: 13 M triangles, a few hundred thousand in strips),
//! so a frame's pattern cache then holds the strips alone.

use super::PatternInput;
use glam::DVec2;

/// The cells `lo[0]..hi[0]` × `lo[1]..hi[1]` of a quad's `cells[0] × cells[1]` grid, each cell
/// `(i, j)` split along its diagonal from `(i, j)` to `(i + 1, j + 1)` into
/// `[(i, j), (i+1, j), (i+1, j+1)]` and `[(i, j), (i+1, j+1), (i, j+1)]`, cells row after row
/// (`j` outer), counter-clockwise. Grid point `(i, j)` is local vertex
/// `interior + (j − 1)·(nu − 1) + (i − 1)` strictly inside the domain; on the boundary it is
/// the corner or edge sample there, which requires the edges the rectangle reaches to have
/// as many segments as the grid along them (as where a pattern puts no strip).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CoreGrid {
    /// `[nu, nv]`.
    pub cells: [u32; 2],
    /// The rectangle's first cell.
    pub lo: [u32; 2],
    /// One past the rectangle's last cell (`lo ≤ hi ≤ cells`).
    pub hi: [u32; 2],
    /// Local index of each edge's first inner sample ([`PatternInput::edge_base`]).
    edge: [u32; 4],
}

impl CoreGrid {
    /// Appends the interior points of the core's grid, which a pattern with a core grid has
    /// for its interior vertices ([`super::Pattern::core_grid`]): [`grid_interior`] of
    /// `cells`. Cost: O(points).
    pub fn interior_points(&self, out: &mut Vec<DVec2>) {
        grid_interior(self.cells, out);
    }

    /// The rectangle `lo..hi` of the `cells` grid of quad `input`. Cost: O(1).
    pub fn new(input: &PatternInput, cells: [u32; 2], lo: [u32; 2], hi: [u32; 2]) -> Self {
        debug_assert!(lo[0] <= hi[0] && hi[0] <= cells[0] && lo[1] <= hi[1] && hi[1] <= cells[1]);
        CoreGrid { cells, lo, hi, edge: std::array::from_fn(|e| input.edge_base(e)) }
    }

    /// The rectangle's triangles: two a cell.
    pub fn triangle_count(&self) -> u32 {
        2 * (self.hi[0] - self.lo[0]) * (self.hi[1] - self.lo[1])
    }

    /// Vertex of grid point `(i, j)`: the interior rule from `interior`, a boundary point's
    /// local index through `boundary`.
    #[inline]
    fn index(&self, interior: u32, boundary: &impl Fn(u32) -> u32, i: u32, j: u32) -> u32 {
        let [nu, nv] = self.cells;
        let local = match (i, j) {
            (0, 0) => 0,
            (i, 0) if i == nu => 1,
            (i, j) if i == nu && j == nv => 2,
            (0, j) if j == nv => 3,
            (i, 0) => self.edge[0] + i - 1,
            (i, j) if i == nu => self.edge[1] + j - 1,
            (i, j) if j == nv => self.edge[2] + (nu - i) - 1,
            (0, j) => self.edge[3] + (nv - j) - 1,
            (i, j) => return interior + (j - 1) * (nu - 1) + (i - 1),
        };
        boundary(local)
    }

    /// Vertex of grid point `(i, j)` in the local numbering ([`CoreGrid::write`] with the
    /// pattern's own `interior` base and no mapping).
    pub fn local(&self, interior: u32, i: u32, j: u32) -> u32 {
        self.index(interior, &|l| l, i, j)
    }

    /// Writes the rectangle's triangles, flat (`out.len() = 3 · triangle_count()`), with
    /// interior grid point `(1, 1)` numbered `interior` and the others after it by the grid
    /// rule, and each boundary point's local index `l` written as `boundary(l)`. With the
    /// pattern's own interior base and `|l| l`, the pattern's local triangles; with a patch's
    /// first output interior vertex and its boundary table, its output indices. Cost: O(cells);
    /// a cell off the boundary by additions.
    pub fn write(&self, interior: u32, boundary: impl Fn(u32) -> u32, out: &mut [u32]) {
        let [nu, nv] = self.cells;
        let ([i_lo, j_lo], [i_hi, j_hi]) = (self.lo, self.hi);
        debug_assert_eq!(out.len(), 3 * self.triangle_count() as usize);
        // The columns `a..b` whose cells have interior corners only, on a row off the
        // boundary; the columns before and after them take the general rule.
        let a = i_lo.max(1).min(i_hi);
        let b = i_hi.min(nu.saturating_sub(1)).max(a);
        // The next cell's place in `out`.
        let mut at = 0;
        fn cell(out: &mut [u32], at: &mut usize, [a, b, c, d]: [u32; 4]) {
            out[*at..*at + 6].copy_from_slice(&[a, b, c, a, c, d]);
            *at += 6;
        }
        // Four inner cells of a row in one go: cell `k` of the four (its first corner `a + k`)
        // is `[a + k, a + k + 1, a + k + nu, a + k, a + k + nu, a + k + nu − 1]`, the first
        // corner plus a constant per place ([`GroupOffsets`]).
        const GROUP: usize = 4;
        let offsets = GroupOffsets::new(nu);
        // A column's two points of row `j`, by the general rule.
        let side = |i: u32, j: u32| {
            [self.index(interior, &boundary, i, j), self.index(interior, &boundary, i, j + 1)]
        };
        for j in j_lo..j_hi {
            let inner_row = j > 0 && j + 1 < nv;
            let (fast_lo, fast_hi) = if inner_row { (a, b) } else { (i_hi, i_hi) };
            // Left of the fast columns, then right of them, by the rule; each column's points
            // numbered once (a cell's right side is the next one's left).
            let mut left = side(i_lo, j);
            for i in i_lo..fast_lo {
                let right = side(i + 1, j);
                cell(out, &mut at, [left[0], right[0], right[1], left[1]]);
                left = right;
            }
            let row = interior.wrapping_add(j.wrapping_sub(1).wrapping_mul(nu - 1));
            let mut i = fast_lo;
            while i + GROUP as u32 <= fast_hi {
                let a = row.wrapping_add(i - 1);
                offsets.write(a, (&mut out[at..at + 6 * GROUP]).try_into().expect("four cells"));
                at += 6 * GROUP;
                i += GROUP as u32;
            }
            for i in i..fast_hi {
                let a = row.wrapping_add(i - 1);
                cell(
                    out,
                    &mut at,
                    [a, a.wrapping_add(1), a.wrapping_add(nu), a.wrapping_add(nu).wrapping_sub(1)],
                );
            }
            if fast_hi < i_hi {
                left = side(fast_hi, j);
            }
            for i in fast_hi..i_hi {
                let right = side(i + 1, j);
                cell(out, &mut at, [left[0], right[0], right[1], left[1]]);
                left = right;
            }
        }
    }
}

/// The indices of four inner cells of a row of an `nu`-column grid less their first corner
/// ([`CoreGrid::write`]), as four vectors of four. Why by hand: written plainly the compiler
/// folds the constants into 24 scalar stores a group (it did: six a cell cost about a sixth
/// of the index writes of a fine adaptive frame), where SSE2 (every x86-64) stores six
/// vectors.
struct GroupOffsets {
    lanes: [[u32; 4]; 6],
}

impl GroupOffsets {
    fn new(nu: u32) -> Self {
        let place = [0, 1, nu, 0, nu, nu.wrapping_sub(1)];
        GroupOffsets {
            lanes: std::array::from_fn(|q| {
                std::array::from_fn(|l| ((4 * q + l) / 6) as u32 + place[(4 * q + l) % 6])
            }),
        }
    }

    /// Writes the four cells whose first corner is `a` (wrapping, as the scalar rule).
    #[inline(always)]
    fn write(&self, a: u32, out: &mut [u32; 24]) {
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::x86_64::{
                __m128i, _mm_add_epi32, _mm_loadu_si128, _mm_set1_epi32, _mm_storeu_si128,
            };
            // SAFETY (each block): SSE2 is part of every x86-64; `lanes` holds four u32 and
            // `out[4q..4q + 4]` lies inside `out` (24 elements), loaded and stored unaligned.
            let base = unsafe { _mm_set1_epi32(a as i32) };
            for (q, lanes) in self.lanes.iter().enumerate() {
                unsafe {
                    let d = _mm_loadu_si128(lanes.as_ptr().cast::<__m128i>());
                    _mm_storeu_si128(out.as_mut_ptr().add(4 * q).cast::<__m128i>(), _mm_add_epi32(base, d));
                }
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        for (o, d) in out.iter_mut().zip(self.lanes.as_flattened()) {
            *o = a.wrapping_add(*d);
        }
    }
}

/// Appends the points `(i·(1/nu), j·(1/nv))` strictly inside the domain of the `nu × nv`
/// grid (`cells`), row after row (`j` outer): the interior vertices of a quad pattern that
/// is a grid inside its strips ([`super::Pattern::interior_grid`]), computed by one rule
/// wherever they are needed so that they agree bit for bit. Cost: O(points).
pub fn grid_interior([nu, nv]: [u32; 2], out: &mut Vec<DVec2>) {
    let (su, sv) = (1.0 / nu as f64, 1.0 / nv as f64);
    out.reserve((nu.saturating_sub(1) as usize) * (nv.saturating_sub(1) as usize));
    for j in 1..nv {
        for i in 1..nu {
            out.push(DVec2::new(i as f64 * su, j as f64 * sv));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::domain::Domain;

    /// The rectangle's triangles as the type documents them, cell by cell, each point by
    /// [`CoreGrid::index`]: the oracle of [`CoreGrid::write`]'s faster loops.
    fn by_the_rule(core: &CoreGrid, interior: u32, boundary: &impl Fn(u32) -> u32) -> Vec<u32> {
        let point = |i, j| core.index(interior, boundary, i, j);
        let mut out = Vec::new();
        for j in core.lo[1]..core.hi[1] {
            for i in core.lo[0]..core.hi[0] {
                let [a, b, c, d] = [point(i, j), point(i + 1, j), point(i + 1, j + 1), point(i, j + 1)];
                out.extend([a, b, c, a, c, d]);
            }
        }
        out
    }

    /// Random rectangles of grids from 1×1 to 80×75 (the fast groups of four, the columns
    /// left and right of them, whole rows on the boundary), with the pattern's own numbering
    /// and a writer's mapping: the vertices the rule gives, cell for cell.
    #[test]
    fn write_gives_every_cell_the_rules_vertices() {
        let mut rng = crate::test_support::Lcg(11);
        let mut cases = 0;
        for (nu, nv) in [(1, 1), (1, 4), (4, 1), (2, 3), (5, 5), (9, 14), (13, 8), (40, 3), (70, 75), (80, 6)]
        {
            for _ in 0..12 {
                let mut pick = |n: u32| (rng.unit() * (n + 1) as f64) as u32 % (n + 1);
                let (i0, i1) = (pick(nu), pick(nu));
                let (j0, j1) = (pick(nv), pick(nv));
                let input = PatternInput::new(Domain::Quad, [nu, nv, nu, nv], [nu, nv]);
                let core =
                    CoreGrid::new(&input, [nu, nv], [i0.min(i1), j0.min(j1)], [i0.max(i1), j0.max(j1)]);
                let interior = input.interior_base();
                let mut out = vec![0; 3 * core.triangle_count() as usize];
                core.write(interior, |l| l, &mut out);
                assert_eq!(out, by_the_rule(&core, interior, &|l| l), "{core:?}");
                let mapped = |l: u32| 7000 + 3 * l;
                core.write(123_456, mapped, &mut out);
                assert_eq!(out, by_the_rule(&core, 123_456, &mapped), "{core:?} mapped");
                cases += 1;
            }
        }
        assert_eq!(cases, 120);
    }
}
