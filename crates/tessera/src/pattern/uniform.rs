//! The uniform pattern: one integer factor `n` on every edge and in the interior — the
//! baseline every adaptive scheme is compared with (methods A/B of paper 000).
//!
//! Quads: an `n × n` grid of cells, each split along the diagonal from `(i, j)` to
//! `(i+1, j+1)`: `2n²` triangles, `(n+1)²` vertices. Triangles: the `n`-fold barycentric
//! grid: `n²` triangles, `(n+1)(n+2)/2` vertices.

use super::{LocalTessellation, Pattern, PatternInput};
use crate::domain::Domain;
use glam::DVec2;

/// The uniform pattern. Precondition: all edges of a patch have `interior[0]` segments.
#[derive(Debug, Clone, Copy, Default)]
pub struct Uniform;

/// Local index of grid point `(i, j)` of a uniform quad with factor `n`.
#[inline]
pub fn quad_local(n: u32, i: u32, j: u32) -> u32 {
    let m = n - 1;
    match (i, j) {
        (0, 0) => 0,
        (i, 0) if i == n => 1,
        (i, j) if i == n && j == n => 2,
        (0, j) if j == n => 3,
        (i, 0) => 4 + (i - 1),
        (i, j) if i == n => 4 + m + (j - 1),
        (i, j) if j == n => 4 + 2 * m + (n - i - 1),
        (0, j) => 4 + 3 * m + (n - j - 1),
        (i, j) => 4 + 4 * m + (j - 1) * m + (i - 1),
    }
}

/// Local index of grid point `(i, j)` (`i + j ≤ n`) of a uniform triangle with factor `n`.
/// Interior rows `j = 1..n-2` hold `n − 1 − j` points each.
#[inline]
pub fn tri_local(n: u32, i: u32, j: u32) -> u32 {
    let m = n - 1;
    match (i, j) {
        (0, 0) => 0,
        (i, 0) if i == n => 1,
        (0, j) if j == n => 2,
        (i, 0) => 3 + (i - 1),
        (i, j) if i + j == n => 3 + m + (j - 1),
        (0, j) => 3 + 2 * m + (n - j - 1),
        (i, j) => {
            // Rows 1..j-1 before this one: Σ_{r=1}^{j-1} (n-1-r).
            let before = (j - 1) * (n - 1) - (j - 1) * j / 2;
            3 + 3 * m + before + (i - 1)
        }
    }
}

impl Pattern for Uniform {
    fn name(&self) -> &'static str {
        "uniform"
    }

    /// Quads: the `n × n` grid, built by `grid` row after row.
    fn interior_grid(&self, input: &PatternInput) -> Option<[u32; 2]> {
        (input.domain == Domain::Quad).then_some(input.interior)
    }

    /// Every cell is cut from its corner `(i, j)` to `(i + 1, j + 1)`, so the domain's
    /// diagonal from corner 0 to corner 2 is in the pattern.
    fn cut_through_corners_0_and_2(&self) -> bool {
        true
    }

    /// The `n`-grid, `n = interior[0]`, on both domains.
    fn grid_cells(&self, input: &PatternInput) -> Option<[u32; 2]> {
        let n = input.interior[0];
        Some([n, n])
    }

    fn counts(&self, input: &PatternInput) -> (u32, u32) {
        let n = input.interior[0];
        match input.domain {
            Domain::Quad => ((n - 1) * (n - 1), 2 * n * n),
            Domain::Tri => ((n.saturating_sub(1)) * (n.saturating_sub(2)) / 2, n * n),
        }
    }

    fn triangulate(&self, input: &PatternInput, out: &mut LocalTessellation) {
        let n = input.interior[0];
        let local = |i, j| match input.domain {
            Domain::Quad => quad_local(n, i, j),
            Domain::Tri => tri_local(n, i, j),
        };
        grid(input.domain, n, local, out, |t, tri| t.push(tri));
    }
}

/// Walks the uniform `n`-grid of a domain: pushes the interior parameters (rows of `j`, then
/// `i`) and hands every grid triangle, in a fixed order and counter-clockwise, to `emit` with
/// its corners mapped by `local(i, j)`. The uniform pattern emits them as they are; the
/// semi-uniform pattern maps boundary points through its snap first and drops collapsed ones.
pub(crate) fn grid(
    domain: Domain,
    n: u32,
    local: impl Fn(u32, u32) -> u32,
    out: &mut LocalTessellation,
    mut emit: impl FnMut(&mut Vec<[u32; 3]>, [u32; 3]),
) {
    out.interior.clear();
    out.triangles.clear();
    let step = 1.0 / n as f64;
    let tri = domain == Domain::Tri;
    for j in 1..n {
        let end = if tri { n.saturating_sub(j) } else { n };
        for i in 1..end {
            out.interior.push(DVec2::new(i as f64 * step, j as f64 * step));
        }
    }
    for j in 0..n {
        for i in 0..if tri { n - j } else { n } {
            let (a, b, d) = (local(i, j), local(i + 1, j), local(i, j + 1));
            if tri {
                emit(&mut out.triangles, [a, b, d]);
                if i + j + 2 <= n {
                    emit(&mut out.triangles, [b, local(i + 1, j + 1), d]);
                }
            } else {
                let c = local(i + 1, j + 1);
                emit(&mut out.triangles, [a, b, c]);
                emit(&mut out.triangles, [a, c, d]);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check(domain: Domain, n: u32) {
        let input = PatternInput::new(domain, [n; 4], [n, n]);
        let mut out = LocalTessellation::default();
        Uniform.build(&input, &mut out);
        let (vi, t) = Uniform.counts(&input);
        assert_eq!(out.interior.len() as u32, vi);
        assert_eq!(out.triangles.len() as u32, t);
        let total = input.interior_base() + vi;
        // Every local vertex is used, and every index is in range.
        let mut used = vec![false; total as usize];
        for tri in &out.triangles {
            for &v in tri {
                used[v as usize] = true;
            }
        }
        assert!(used.iter().all(|&u| u), "{domain:?} n={n}: unused local vertex");
        // Interior indices match interior parameters.
        let base = input.interior_base();
        let local = |i: u32, j: u32| match domain {
            Domain::Quad => quad_local(n, i, j),
            Domain::Tri => tri_local(n, i, j),
        };
        for j in 0..=n {
            for i in 0..=n {
                if domain == Domain::Tri && i + j > n {
                    continue;
                }
                let l = local(i, j);
                if l >= base {
                    let p = out.interior[(l - base) as usize];
                    assert!((p - DVec2::new(i as f64, j as f64) / n as f64).length() < 1e-12);
                }
            }
        }
    }

    #[test]
    fn uniform_counts_and_indices_are_consistent() {
        for n in [1, 2, 3, 4, 5, 8, 13] {
            check(Domain::Quad, n);
            check(Domain::Tri, n);
        }
    }
}
