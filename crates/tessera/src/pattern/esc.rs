//! ESC: the free adaptive tessellation of bicubic Bézier patches of paper 002 (Concheiro et
//! al., "Free Adaptive Tessellation Strategy of Bézier Surfaces", section 3), as a pattern.
//! The decisions (which candidate vertices are inserted) are taken by the criterion
//! [`crate::criterion::esc`]; this module turns them into triangle strips with the paper's
//! virtual-vertex rules and decodes those strips into the triangle list.
//!
//! # Geometry
//!
//! The 4×4 control net of a patch has 3×3 cells; cell `(i, j)` covers
//! `[i/3, (i+1)/3] × [j/3, (j+1)/3]` of the domain and is split along the diagonal from
//! `(i/3, j/3)` to `((i+1)/3, (j+1)/3)` (the diagonal the uniform pattern uses, so that with
//! every candidate inserted ESC gives exactly the uniform grid of factor `3n`) into two
//! *coarse triangles*: 18 per patch. A patch at level `L` samples every coarse edge with
//! `n = L + 1` candidate segments ([`segments_for_level`]); all candidates of a patch form the
//! lattice `(I/N, J/N)`, `N = 3n`.
//!
//! Level and segments: the paper's Fig. 3 shows the patterns of `L = 0..3`, its Table 1 counts
//! `16 · 18` triangles per surface at `Lmax = 3`, and its Fig. 5 example (`v1 … v10`) is the
//! `L = 2` pattern: `n = L + 1` segments per coarse edge, `n²` triangles per coarse triangle.
//!
//! # Rows
//!
//! Each coarse triangle has an *apex* `A` (its right-angle corner: `(i+1, j)` for the lower
//! triangle, `(i, j+1)` for the upper one) and a *base* `BC` (the cell diagonal). Its
//! candidates lie on rows parallel to the base: row `k = 0..n` holds `k + 1` vertices
//! `r_k[p] = A + (k−p)/n·(B−A) + p/n·(C−A)`; `r_k[0]` lies on the *left* edge `AB` (a cell
//! edge), `r_k[k]` on the *right* edge `AC` (the other cell edge), row `n` is the base.
//! `(A, C, B)` is counter-clockwise in the domain, which makes the strips below decode to
//! counter-clockwise triangles.
//!
//! # Insertion (paper section 3, decided by the criterion)
//!
//! Coarse-triangle corners are always present. Every inner candidate of a coarse edge is
//! tested on its own (the distance test, equation (9)); an inserted vertex of the left or
//! right edge inserts the interior of its whole row ("if a vertex is inserted in the edge, the
//! insertion is also performed along the row"). A row with one extreme missing keeps its
//! interior; a row with both extremes missing is empty. Base vertices have no row of their own
//! beyond the base, so each is inserted or not.
//!
//! # Reconstruction (paper section 3, Fig. 5, equation (10))
//!
//! The strips are those of the non-adaptive pattern, one per pair of consecutive rows,
//! `TS_k = r_k[0] r_{k−1}[0] r_k[1] r_{k−1}[1] … r_{k−1}[k−1] r_k[k]`, updated by:
//!
//! 1. *Missing vertex* / 2. *group of missing vertices*: a missing vertex on a coarse edge is
//!    replaced by a virtual vertex (VV), the nearest present vertex on the same edge; on a tie
//!    the one in the lower row (further from the apex; on the base, the one nearer `B`).
//! 3. *Replicated vertices*: `v v` becomes `v`.
//! 4. *Alternating rows*: a strip alternates lower-row and upper-row vertices; where two
//!    consecutive entries `vj vk` come from the same side (a vertex of row `≥ b` counts as
//!    lower, of row `≤ a` as upper), `vi vj vk` becomes `vi vj vi vk`. At the start of a strip,
//!    where there is no `vi`, the first entry is repeated instead.
//!
//! Empty rows: for consecutive non-empty rows `a < b − 1`, the strip `TS_a+1` … is dropped and
//! in `TS_b` the upper vacancies are filled from row `a`: uniformly replicated when that row
//! is complete (Fig. 5b), and with its virtual vertex used only once when it has a missing
//! extreme (Fig. 5c). Strips that draw nothing after the rules are dropped.
//!
//! # Consistency
//!
//! A vertex on a coarse edge is decided from that edge's data only (the criterion tests it
//! once per edge; patch boundary curves once per topology edge), and each coarse triangle
//! triangulates its own side with all present vertices of its edges as boundary vertices, so
//! two coarse triangles on one edge — of one patch, or of two patches — meet without
//! T-junctions. Which vertex a VV points to is a choice inside one coarse triangle and does
//! not need to agree with the neighbour.

use super::{LocalTessellation, Pattern, PatternInput};
use crate::mesh::strips::{decode_into, RESTART};
use glam::DVec2;

/// Largest level the pattern supports (`n = 7` segments per coarse edge).
pub const MAX_LEVEL: u32 = 6;

/// Candidate segments per coarse-triangle edge at level `level` (paper Fig. 3: `L + 1`).
pub const fn segments_for_level(level: u32) -> u32 {
    level + 1
}

/// A candidate of one coarse triangle's pattern: `(row k, position p)`, `0 ≤ p ≤ k ≤ n`.
pub type RowVertex = (u32, u32);

/// Which candidates of one coarse triangle are inserted, as the rows rules need them.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CoarseTriangle {
    /// Segments per edge (`n ≥ 1`).
    pub n: u32,
    /// `left[k]`: `r_k[0]` (edge `AB`) is inserted; `left[0]` and `left[n]` are corners.
    pub left: Vec<bool>,
    /// `right[k]`: `r_k[k]` (edge `AC`) is inserted.
    pub right: Vec<bool>,
    /// `base[p]`: `r_n[p]` (edge `BC`) is inserted.
    pub base: Vec<bool>,
}

impl CoarseTriangle {
    /// The complete (non-adaptive) pattern with `n` segments per edge.
    pub fn full(n: u32) -> Self {
        let v = vec![true; n as usize + 1];
        CoarseTriangle { n, left: v.clone(), right: v.clone(), base: v }
    }

    /// True when candidate `(k, p)` is inserted: corners always; edge candidates as decided;
    /// a row's interior when either of its extremes is inserted.
    pub fn present(&self, (k, p): RowVertex) -> bool {
        let n = self.n;
        if k == 0 || (k == n && (p == 0 || p == n)) {
            true
        } else if k == n {
            self.base[p as usize]
        } else if p == 0 {
            self.left[k as usize]
        } else if p == k {
            self.right[k as usize]
        } else {
            self.row_present(k)
        }
    }

    /// True when row `k` holds any vertex.
    pub fn row_present(&self, k: u32) -> bool {
        k == 0 || k == self.n || self.left[k as usize] || self.right[k as usize]
    }

    /// The vertex standing for `(k, p)`: itself when inserted, else its virtual vertex (rules
    /// 1 and 2: the nearest inserted vertex on the same coarse edge, ties to the lower row).
    /// Only edge candidates can be missing in a non-empty row.
    fn stand_in(&self, v: RowVertex) -> (RowVertex, bool) {
        if self.present(v) {
            return (v, false);
        }
        let (k, p) = v;
        let n = self.n;
        if k == n {
            // Base: nearest along the base, ties towards B (p = 0). Corners are present.
            for d in 1..=n {
                if p >= d && self.base[(p - d) as usize] {
                    return ((n, p - d), true);
                }
                if p + d <= n && self.base[(p + d) as usize] {
                    return ((n, p + d), true);
                }
            }
            unreachable!("the base corners are always present");
        }
        let flags = if p == 0 { &self.left } else { &self.right };
        let at = |r: u32| if p == 0 { (r, 0) } else { (r, r) };
        for d in 1..=n {
            // Lower row first: the tie rule.
            if k + d <= n && (k + d == n || flags[(k + d) as usize]) {
                return (at(k + d), true);
            }
            if k >= d && (k == d || flags[(k - d) as usize]) {
                return (at(k - d), true);
            }
        }
        unreachable!("the apex and the base corners are always present")
    }

    /// The triangle strips of this coarse triangle, over row vertices, by the paper's rules
    /// (module doc). Cost: O(n²).
    pub fn strips(&self) -> Vec<Vec<RowVertex>> {
        let n = self.n;
        let mut out = Vec::new();
        let mut a = 0;
        for b in 1..=n {
            if !self.row_present(b) {
                continue; // an empty row: its strip is dropped, the next one spans it
            }
            // Entries of TS_b in order, each with "is on the upper side".
            let mut entries: Vec<RowVertex> = Vec::with_capacity(2 * b as usize + 1);
            let upper = self.upper_fill(a, b);
            for i in 0..=b {
                entries.push(self.stand_in((b, i)).0);
                if i < b {
                    entries.push(upper[i as usize]);
                }
            }
            let strip = alternate(&entries, |v| v.0 <= a);
            if strip.len() >= 3 && strip.windows(3).any(|w| w[0] != w[1] && w[1] != w[2] && w[0] != w[2]) {
                out.push(strip);
            }
            a = b;
        }
        out
    }

    /// The `b` upper vacancies of `TS_b` when the previous non-empty row is `a`: row `b − 1`'s
    /// vertices when `a = b − 1`, else row `a` spread uniformly, its virtual vertex used once.
    fn upper_fill(&self, a: u32, b: u32) -> Vec<RowVertex> {
        let row: Vec<(RowVertex, bool)> = (0..=a).map(|p| self.stand_in((a, p))).collect();
        if a + 1 == b {
            return row.into_iter().map(|r| r.0).collect();
        }
        // Counts per entry: one per VV, the rest spread as evenly as possible (earlier
        // entries take the extra ones: Fig. 5b fills v2 v2 v3).
        let vv = row.iter().filter(|r| r.1).count() as u32;
        let (spread, real) = (b - vv, row.len() as u32 - vv);
        let mut fill = Vec::with_capacity(b as usize);
        let mut q = 0;
        for &(v, is_vv) in &row {
            let count = if is_vv {
                1
            } else {
                let c = (q + 1) * spread / real + u32::from((q + 1) * spread % real != 0)
                    - (q * spread / real + u32::from(q * spread % real != 0));
                q += 1;
                c
            };
            fill.extend(std::iter::repeat_n(v, count as usize));
        }
        debug_assert_eq!(fill.len(), b as usize);
        fill
    }
}

/// Rules 3 and 4 on one strip: drops repeated consecutive entries and restores the
/// lower/upper alternation (lower entries at even positions) by repeating the entry before
/// the last one, so every triangle keeps its corners and its winding.
fn alternate<T: Copy + PartialEq>(entries: &[T], is_upper: impl Fn(T) -> bool) -> Vec<T> {
    let mut out: Vec<T> = Vec::with_capacity(entries.len() + 4);
    for &v in entries {
        if out.last() == Some(&v) {
            continue; // rule 3
        }
        let want_odd = is_upper(v);
        if (out.len() % 2 == 1) != want_odd {
            // Rule 4: `vi vj vk` with `vj`, `vk` on one side becomes `vi vj vi vk`.
            match out.len() {
                0 => out.push(v),
                1 => out.push(out[0]),
                len => out.push(out[len - 2]),
            }
        }
        out.push(v);
    }
    out
}

/// Which candidates of one patch are inserted: the lattice `(I, J)`, `0 ≤ I, J ≤ 3n`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PatchGrid {
    /// Candidate segments per coarse edge.
    pub n: u32,
    present: Vec<bool>,
}

impl PatchGrid {
    /// A grid with only the 16 coarse vertices inserted. Precondition: `n ≥ 1`.
    pub fn coarse(n: u32) -> Self {
        let side = 3 * n + 1;
        let mut present = vec![false; (side * side) as usize];
        for j in 0..4 {
            for i in 0..4 {
                present[(j * n * side + i * n) as usize] = true;
            }
        }
        PatchGrid { n, present }
    }

    /// Lattice points per side minus one (`3n`).
    pub fn side(&self) -> u32 {
        3 * self.n
    }

    /// Is lattice point `(i, j)` inserted?
    pub fn get(&self, i: u32, j: u32) -> bool {
        self.present[(j * (self.side() + 1) + i) as usize]
    }

    /// Sets lattice point `(i, j)`.
    pub fn set(&mut self, i: u32, j: u32, value: bool) {
        let side = self.side() + 1;
        self.present[(j * side + i) as usize] = value;
    }

    /// Lattice point of row vertex `(k, p)` of the coarse triangle `t` (`0..18`: cell
    /// `c = t / 2` at `(c % 3, c / 3)`, lower triangle for even `t`).
    pub fn lattice(&self, t: u32, (k, p): RowVertex) -> (u32, u32) {
        let n = self.n;
        let (ci, cj) = ((t / 2) % 3, (t / 2) / 3);
        if t % 2 == 0 {
            // Apex (i+1, j); B = (i, j) along −I; C = (i+1, j+1) along +J.
            ((ci + 1) * n - (k - p), cj * n + p)
        } else {
            // Apex (i, j+1); B = (i+1, j+1) along +I; C = (i, j) along −J.
            (ci * n + (k - p), (cj + 1) * n - p)
        }
    }

    /// The insertion flags of coarse triangle `t`, read from the grid.
    pub fn coarse_triangle(&self, t: u32) -> CoarseTriangle {
        let n = self.n;
        let at = |v| {
            let (i, j) = self.lattice(t, v);
            self.get(i, j)
        };
        CoarseTriangle {
            n,
            left: (0..=n).map(|k| at((k, 0))).collect(),
            right: (0..=n).map(|k| at((k, k))).collect(),
            base: (0..=n).map(|p| at((n, p))).collect(),
        }
    }

    /// Fills the interior of every row with an inserted extreme (the row rule), for all 18
    /// coarse triangles. Call after every coarse-edge candidate is decided.
    pub fn insert_rows(&mut self) {
        let n = self.n;
        for t in 0..18 {
            for k in 2..n {
                let row = self.get_rv(t, (k, 0)) || self.get_rv(t, (k, k));
                for p in 1..k {
                    let (i, j) = self.lattice(t, (k, p));
                    self.set(i, j, row);
                }
            }
        }
    }

    /// True when an edge of coarse triangle `t` lies on patch edge `e` (edge 0: `J = 0`,
    /// 1: `I = 3n`, 2: `J = 3n`, 3: `I = 0`). Only the left edge `AB` or the right edge `AC`
    /// can: the base is a cell diagonal.
    pub fn coarse_triangle_on_edge(&self, t: u32, e: usize) -> bool {
        let (n, s) = (self.n, self.side());
        let on = |(i, j): (u32, u32)| match e {
            0 => j == 0,
            1 => i == s,
            2 => j == s,
            _ => i == 0,
        };
        let a = on(self.lattice(t, (0, 0)));
        a && (on(self.lattice(t, (n, 0))) || on(self.lattice(t, (n, n))))
    }

    /// Inserts every candidate of coarse triangle `t`: its edges and its rows.
    pub fn fill_coarse_triangle(&mut self, t: u32) {
        for k in 0..=self.n {
            for p in 0..=k {
                let (i, j) = self.lattice(t, (k, p));
                self.set(i, j, true);
            }
        }
    }

    fn get_rv(&self, t: u32, v: RowVertex) -> bool {
        let (i, j) = self.lattice(t, v);
        self.get(i, j)
    }

    /// Number of inserted candidates on each patch edge, corners excluded, in the patch's
    /// own edge direction (edge 0: `J = 0`, 1: `I = 3n`, 2: `J = 3n`, 3: `I = 0`).
    pub fn edge_points(&self, e: usize) -> Vec<(u32, u32)> {
        let s = self.side();
        let pts: Vec<(u32, u32)> = match e {
            0 => (1..s).map(|i| (i, 0)).collect(),
            1 => (1..s).map(|j| (s, j)).collect(),
            2 => (1..s).map(|i| (s - i, s)).collect(),
            _ => (1..s).map(|j| (0, s - j)).collect(),
        };
        pts.into_iter().filter(|&(i, j)| self.get(i, j)).collect()
    }
}

/// One patch's ready-made output: local index of every lattice point, interior parameters,
/// and the strips over local indices.
#[derive(Debug, Clone, Default, PartialEq)]
struct PatchLayout {
    interior: Vec<DVec2>,
    strips: Vec<u32>,
    triangles: u32,
}

fn layout(grid: &PatchGrid) -> PatchLayout {
    let s = grid.side();
    let side = (s + 1) as usize;
    let mut local = vec![u32::MAX; side * side];
    let idx = |i: u32, j: u32| j as usize * side + i as usize;
    local[idx(0, 0)] = 0;
    local[idx(s, 0)] = 1;
    local[idx(s, s)] = 2;
    local[idx(0, s)] = 3;
    let mut next = 4;
    for e in 0..4 {
        for (i, j) in grid.edge_points(e) {
            local[idx(i, j)] = next;
            next += 1;
        }
    }
    let mut interior = Vec::new();
    for j in 1..s {
        for i in 1..s {
            if grid.get(i, j) {
                local[idx(i, j)] = next;
                next += 1;
                interior.push(DVec2::new(i as f64 / s as f64, j as f64 / s as f64));
            }
        }
    }
    let mut strips = Vec::new();
    for t in 0..18 {
        for strip in grid.coarse_triangle(t).strips() {
            if !strips.is_empty() {
                strips.push(RESTART);
            }
            strips.extend(strip.iter().map(|&v| {
                let (i, j) = grid.lattice(t, v);
                local[idx(i, j)]
            }));
        }
    }
    let triangles = crate::mesh::strips::decoded_count(&strips) as u32;
    PatchLayout { interior, strips, triangles }
}

/// The ESC pattern: per-patch insertion decisions made by [`crate::criterion::esc::plan`].
///
/// Precondition for [`Pattern::build`]: the [`PatternInput::patch`] indexes the grids this
/// pattern was made with, and the plan's edge samplings are the ones made with it (the
/// criterion returns both together).
#[derive(Debug, Clone, Default)]
pub struct Esc {
    layouts: Vec<PatchLayout>,
    grids: Vec<PatchGrid>,
}

impl Esc {
    /// Builds the pattern from one grid per patch (coarse-edge candidates decided, rows
    /// filled by [`PatchGrid::insert_rows`]). Cost: O(inserted candidates), parallel.
    pub fn new(grids: Vec<PatchGrid>) -> Self {
        use rayon::prelude::*;
        let layouts = grids.par_iter().map(layout).collect();
        Esc { layouts, grids }
    }

    /// How many patches the pattern holds grids for.
    pub fn patches(&self) -> usize {
        self.grids.len()
    }

    /// The insertion grid of patch `p`.
    pub fn grid(&self, p: usize) -> &PatchGrid {
        &self.grids[p]
    }

    /// Triangles of patch `p` (before the engine drops those collapsed at degenerate corners).
    pub fn triangles(&self, p: usize) -> u32 {
        self.layouts[p].triangles
    }

    fn patch(&self, input: &PatternInput) -> &PatchLayout {
        &self.layouts[input.patch as usize]
    }
}

impl Pattern for Esc {
    fn name(&self) -> &'static str {
        "esc"
    }

    fn depends_on_patch(&self) -> bool {
        true // each patch's own insertion grid
    }

    fn as_any(&self) -> Option<&dyn std::any::Any> {
        Some(self)
    }

    fn counts(&self, input: &PatternInput) -> (u32, u32) {
        let l = self.patch(input);
        (l.interior.len() as u32, l.triangles)
    }

    fn triangulate(&self, input: &PatternInput, out: &mut LocalTessellation) {
        let l = self.patch(input);
        debug_assert!((0..4).all(|e| {
            input.segments[e] as usize == self.grids[input.patch as usize].edge_points(e).len() + 1
        }));
        out.interior.clear();
        out.interior.extend_from_slice(&l.interior);
        out.triangles.clear();
        decode_into(&l.strips, &mut out.triangles);
    }

    fn strips(&self, input: &PatternInput, out: &mut Vec<u32>) -> bool {
        out.extend_from_slice(&self.patch(input).strips);
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::strips::decode;
    use std::collections::HashMap;

    /// The paper's numbering: `v1` the apex, then row by row from the left edge.
    fn v(r: RowVertex) -> u32 {
        r.0 * (r.0 + 1) / 2 + r.1 + 1
    }

    fn named(strips: &[Vec<RowVertex>]) -> Vec<Vec<u32>> {
        strips.iter().map(|s| s.iter().map(|&r| v(r)).collect()).collect()
    }

    /// Row vertex in lattice coordinates of a reference triangle with `(A, C, B)`
    /// counter-clockwise: `A = (n, 0)`, `B = (0, 0)`, `C = (n, n)` (the lower coarse triangle).
    fn xy(n: u32, (k, p): RowVertex) -> (i64, i64) {
        (n as i64 - (k - p) as i64, p as i64)
    }

    fn area2(n: u32, t: [RowVertex; 3]) -> i64 {
        let [a, b, c] = t.map(|r| xy(n, r));
        (b.0 - a.0) * (c.1 - a.1) - (b.1 - a.1) * (c.0 - a.0)
    }

    /// Triangles as row vertices, decoded from the strips with the crate's decoder.
    fn triangles(strips: &[Vec<RowVertex>]) -> Vec<[RowVertex; 3]> {
        let mut ids: Vec<RowVertex> = Vec::new();
        let mut flat = Vec::new();
        for s in strips {
            if !flat.is_empty() {
                flat.push(RESTART);
            }
            for r in s {
                let i = ids.iter().position(|x| x == r).unwrap_or_else(|| {
                    ids.push(*r);
                    ids.len() - 1
                });
                flat.push(i as u32);
            }
        }
        decode(&flat).into_iter().map(|t| t.map(|i| ids[i as usize])).collect()
    }

    /// The triangles tile the coarse triangle: all counter-clockwise with positive area,
    /// areas summing to the whole, every present vertex used and no missing one, every
    /// interior edge used once each way, and boundary edges exactly the segments between
    /// consecutive present vertices of each coarse edge.
    fn check_tiling(c: &CoarseTriangle) -> Result<(), String> {
        let n = c.n;
        let tris = triangles(&c.strips());
        let mut sum = 0;
        let mut directed: HashMap<(RowVertex, RowVertex), u32> = HashMap::new();
        for t in &tris {
            let a = area2(n, *t);
            if a <= 0 {
                return Err(format!("triangle {t:?} has area {a}"));
            }
            sum += a;
            for r in t {
                if !c.present(*r) {
                    return Err(format!("missing vertex {r:?} used"));
                }
            }
            for e in 0..3 {
                *directed.entry((t[e], t[(e + 1) % 3])).or_default() += 1;
            }
        }
        if sum != (n * n) as i64 {
            return Err(format!("areas sum to {sum}, expected {}", n * n));
        }
        for k in 0..=n {
            for p in 0..=k {
                if c.present((k, p)) && !tris.iter().any(|t| t.contains(&(k, p))) {
                    return Err(format!("present vertex {:?} unused", (k, p)));
                }
            }
        }
        // Expected boundary: the present vertices of each edge, consecutive pairs, in the
        // counter-clockwise direction A → C → B → A.
        let chain = |pts: Vec<RowVertex>| -> Vec<(RowVertex, RowVertex)> {
            let pts: Vec<RowVertex> = pts.into_iter().filter(|&r| c.present(r)).collect();
            pts.windows(2).map(|w| (w[0], w[1])).collect()
        };
        let mut boundary = chain((0..=n).map(|k| (k, k)).collect());
        boundary.extend(chain((0..=n).rev().map(|p| (n, p)).collect()));
        boundary.extend(chain((0..=n).rev().map(|k| (k, 0)).collect()));
        for (&(a, b), &count) in &directed {
            let back = directed.get(&(b, a)).copied().unwrap_or(0);
            let on_boundary = boundary.contains(&(a, b));
            if count != 1 || (back != 1) != on_boundary {
                return Err(format!("edge {a:?}→{b:?}: {count} forward, {back} back"));
            }
        }
        for e in &boundary {
            if !directed.contains_key(e) {
                return Err(format!("boundary segment {e:?} not covered"));
            }
        }
        Ok(())
    }

    #[test]
    fn fig5_non_adaptive_strips_are_equation_10() {
        let c = CoarseTriangle::full(3);
        assert_eq!(named(&c.strips()), vec![vec![2, 1, 3], vec![4, 2, 5, 3, 6], vec![7, 4, 8, 5, 9, 6, 10]]);
        check_tiling(&c).unwrap();
        assert_eq!(triangles(&c.strips()).len(), 9);
    }

    #[test]
    fn fig5a_missing_vertex_uses_a_virtual_vertex() {
        // v6 = r_2[2] on the right edge is not inserted: VV = v10 (same edge, next row).
        let mut c = CoarseTriangle::full(3);
        c.right[2] = false;
        let strips = c.strips();
        assert_eq!(named(&strips), vec![vec![2, 1, 3], vec![4, 2, 5, 3, 10], vec![7, 4, 8, 5, 9, 5, 10]]);
        let tris: Vec<Vec<u32>> =
            triangles(&strips).iter().map(|t| t.iter().map(|&r| v(r)).collect()).collect();
        assert_eq!(
            tris,
            vec![
                vec![2, 1, 3],
                vec![4, 2, 5],
                vec![5, 2, 3],
                vec![5, 3, 10],
                vec![7, 4, 8],
                vec![8, 4, 5],
                vec![8, 5, 9],
                vec![9, 5, 10]
            ]
        );
        check_tiling(&c).unwrap();
    }

    #[test]
    fn fig5b_missing_row_below_a_complete_row() {
        // Row {v4, v5, v6} not inserted: TS2 is dropped, TS3's vacancies take v2 v2 v3.
        let mut c = CoarseTriangle::full(3);
        c.left[2] = false;
        c.right[2] = false;
        assert_eq!(named(&c.strips()), vec![vec![2, 1, 3], vec![7, 2, 8, 2, 9, 3, 10]]);
        check_tiling(&c).unwrap();
        let tris: Vec<Vec<u32>> =
            triangles(&c.strips()).iter().map(|t| t.iter().map(|&r| v(r)).collect()).collect();
        assert_eq!(tris, vec![vec![2, 1, 3], vec![7, 2, 8], vec![8, 2, 9], vec![9, 2, 3], vec![9, 3, 10]]);
    }

    #[test]
    fn fig5c_missing_row_below_a_row_with_a_virtual_vertex() {
        // Also v2 missing: its VV v1 fills one vacancy only, v3 the other two; TS1 draws
        // nothing and is dropped.
        let mut c = CoarseTriangle::full(3);
        c.left[2] = false;
        c.right[2] = false;
        c.left[1] = false;
        assert_eq!(named(&c.strips()), vec![vec![7, 1, 8, 3, 9, 3, 10]]);
        let tris: Vec<Vec<u32>> =
            triangles(&c.strips()).iter().map(|t| t.iter().map(|&r| v(r)).collect()).collect();
        assert_eq!(tris, vec![vec![7, 1, 8], vec![8, 1, 3], vec![8, 3, 9], vec![9, 3, 10]]);
        check_tiling(&c).unwrap();
    }

    /// Every insertion pattern for `n ≤ 5` (all 2^(3(n−1)) edge decisions) tiles the
    /// coarse triangle.
    #[test]
    fn every_insertion_pattern_tiles_the_coarse_triangle() {
        for n in 1..=5u32 {
            let m = (n - 1) as usize;
            for bits in 0u32..1 << (3 * m) {
                let mut c = CoarseTriangle::full(n);
                for k in 1..n as usize {
                    c.left[k] = bits >> (k - 1) & 1 == 1;
                    c.right[k] = bits >> (m + k - 1) & 1 == 1;
                    c.base[k] = bits >> (2 * m + k - 1) & 1 == 1;
                }
                check_tiling(&c).unwrap_or_else(|e| panic!("n={n} bits={bits:b}: {e}"));
            }
        }
    }

    /// Which edge of a coarse triangle lies on a patch boundary curve collapsed to a point: the
    /// left edge `AB` (patch edges 0 and 2) or the right edge `AC` (patch edges 1 and 3).
    #[derive(Debug, Clone, Copy)]
    enum Collapsed {
        Left,
        Right,
    }

    /// The triangulation stays a disk after the collapsed edge becomes one point (the engine
    /// gives every sample of such a curve the corner's vertex and drops the triangles that
    /// degenerate): no directed edge twice, no triangle twice, Euler characteristic 1, and the
    /// boundary exactly the other two edges' present vertices, both ending at the point.
    fn check_collapsed(c: &CoarseTriangle, side: Collapsed) -> Result<(), String> {
        const POINT: RowVertex = (u32::MAX, u32::MAX);
        let n = c.n;
        let on = |(k, p): RowVertex| match side {
            Collapsed::Left => p == 0,
            Collapsed::Right => p == k,
        };
        let map = |v: RowVertex| if on(v) { POINT } else { v };
        let tris: Vec<[RowVertex; 3]> = triangles(&c.strips())
            .into_iter()
            .map(|t| t.map(map))
            .filter(|t| t[0] != t[1] && t[1] != t[2] && t[0] != t[2])
            .collect();
        let mut sets: Vec<[RowVertex; 3]> = tris
            .iter()
            .map(|t| {
                let mut s = *t;
                s.sort_unstable();
                s
            })
            .collect();
        sets.sort_unstable();
        if let Some(w) = sets.windows(2).find(|w| w[0] == w[1]) {
            return Err(format!("triangle {:?} twice", w[0]));
        }
        let mut directed: HashMap<(RowVertex, RowVertex), u32> = HashMap::new();
        for t in &tris {
            for e in 0..3 {
                *directed.entry((t[e], t[(e + 1) % 3])).or_default() += 1;
            }
        }
        if let Some(((a, b), _)) = directed.iter().find(|(_, &count)| count > 1) {
            return Err(format!("edge {a:?}→{b:?} used twice"));
        }
        // Counter-clockwise A → C → B → A, over present vertices, after the collapse.
        let mut ring: Vec<RowVertex> = (0..=n).map(|k| (k, k)).collect();
        ring.extend((0..n).rev().map(|p| (n, p)));
        ring.extend((0..n).rev().map(|k| (k, 0)));
        let ring: Vec<RowVertex> = ring.into_iter().filter(|&v| c.present(v)).map(map).collect();
        let mut expected: Vec<(RowVertex, RowVertex)> =
            ring.windows(2).filter(|w| w[0] != w[1]).map(|w| (w[0], w[1])).collect();
        if expected.len() == 2 {
            // Only one vertex off the point on the boundary: the coarse triangle is a segment.
            return if tris.is_empty() { Ok(()) } else { Err(format!("{tris:?} in a segment")) };
        }
        expected.sort_unstable();
        let mut boundary: Vec<(RowVertex, RowVertex)> =
            directed.keys().filter(|&&(a, b)| !directed.contains_key(&(b, a))).copied().collect();
        boundary.sort_unstable();
        if boundary != expected {
            return Err(format!("boundary {boundary:?}, expected {expected:?}"));
        }
        let mut vertices: Vec<RowVertex> = tris.iter().flatten().copied().collect();
        vertices.sort_unstable();
        vertices.dedup();
        let edges = directed.keys().filter(|&&(a, b)| a < b || !directed.contains_key(&(b, a))).count();
        let euler = vertices.len() as i64 - edges as i64 + tris.len() as i64;
        if euler != 1 {
            return Err(format!("Euler characteristic {euler}, not a disk"));
        }
        Ok(())
    }

    /// Next to a curve collapsed to a point the criterion inserts every candidate of the coarse
    /// triangle (criterion::esc, "Collapsed curves"): the complete pattern stays a disk after
    /// the collapse, at every level and on either edge that can lie on a patch boundary.
    #[test]
    fn a_complete_coarse_triangle_stays_a_disk_at_a_collapsed_edge() {
        for side in [Collapsed::Left, Collapsed::Right] {
            for n in 1..=MAX_LEVEL + 1 {
                let c = CoarseTriangle::full(n);
                check_collapsed(&c, side).unwrap_or_else(|e| panic!("{side:?} n={n}: {e}"));
            }
        }
    }

    /// Why the whole coarse triangle: sparser patterns that tile the domain break once the
    /// edge is one point. First the fold the fuzzer found (fuzz/regressions/engine/
    /// esc-fold-at-collapsed-edge): none of the collapsed edge's candidates, rows 1 and 2
    /// empty, row 3 kept by its right extreme, no base candidate; row 3's first segment gets
    /// a triangle to the apex above and one to `B` below, the same triangle after the
    /// collapse. Then every candidate of the collapsed edge (so complete rows) but none on
    /// the other two: those join the point and `C` twice, and row 2's vertex inside gets the
    /// triangle between them on both sides.
    #[test]
    fn sparser_patterns_fold_at_a_collapsed_edge() {
        let mut c = CoarseTriangle::full(4);
        c.left = vec![true, false, false, false, true];
        c.right = vec![true, false, false, true, true];
        c.base = vec![true, false, false, false, true];
        check_tiling(&c).unwrap();
        let err = check_collapsed(&c, Collapsed::Left).unwrap_err();
        assert!(err.contains("twice"), "{err}");
        let mut c = CoarseTriangle::full(3);
        c.right = vec![true, false, false, true];
        c.base = vec![true, false, false, true];
        check_tiling(&c).unwrap();
        let err = check_collapsed(&c, Collapsed::Left).unwrap_err();
        assert!(err.contains("twice"), "{err}");
    }

    #[test]
    fn three_coarse_triangles_lie_on_each_patch_edge() {
        for n in 1..=4 {
            let g = &PatchGrid::coarse(n);
            for e in 0..4 {
                let on: Vec<u32> = (0..18).filter(|&t| g.coarse_triangle_on_edge(t, e)).collect();
                // Their edges on the patch edge cover its 3n lattice segments.
                let mut points: Vec<(u32, u32)> = on
                    .iter()
                    .flat_map(|&t| (0..=n).flat_map(move |k| [(k, 0), (k, k)]).map(move |v| g.lattice(t, v)))
                    .filter(|&(i, j)| match e {
                        0 => j == 0,
                        1 => i == 3 * n,
                        2 => j == 3 * n,
                        _ => i == 0,
                    })
                    .collect();
                points.sort_unstable();
                points.dedup();
                assert_eq!((on.len(), points.len() as u32), (3, 3 * n + 1), "n={n} e={e}: {on:?}");
            }
        }
    }

    /// Levels 5 and 6 (n = 6, 7): a deterministic pseudo-random sample of patterns.
    #[test]
    fn sampled_insertion_patterns_tile_at_high_levels() {
        let mut rng = crate::test_support::Lcg(0x9e37_79b9_7f4a_7c15);
        let mut next = || rng.next();
        for n in 6..=7u32 {
            for _ in 0..3000 {
                let mut c = CoarseTriangle::full(n);
                let density = next() % 4; // from sparse to dense
                for k in 1..n as usize {
                    c.left[k] = next() % 4 < density;
                    c.right[k] = next() % 4 < density;
                    c.base[k] = next() % 4 < density;
                }
                check_tiling(&c).unwrap_or_else(|e| panic!("n={n} {c:?}: {e}"));
            }
        }
    }

    #[test]
    fn full_grid_is_the_uniform_triangulation() {
        for n in 1..=4 {
            let side = 3 * n;
            let mut g = PatchGrid::coarse(n);
            for j in 0..=side {
                for i in 0..=side {
                    g.set(i, j, true);
                }
            }
            let esc = Esc::new(vec![g]);
            let input = PatternInput::new(crate::domain::Domain::Quad, [side; 4], [side; 2]);
            let mut out = LocalTessellation::default();
            esc.build(&input, &mut out);
            assert_eq!(esc.counts(&input), ((side - 1) * (side - 1), 2 * side * side));
            assert_eq!(out.triangles.len() as u32, 2 * side * side);
            let mut strips = Vec::new();
            assert!(esc.strips(&input, &mut strips));
            assert_eq!(decode(&strips), out.triangles);
        }
    }

    #[test]
    fn coarse_grid_gives_18_triangles_and_rows_follow_their_extremes() {
        let mut g = PatchGrid::coarse(3);
        g.insert_rows();
        let esc = Esc::new(vec![g.clone()]);
        assert_eq!(esc.triangles(0), 18);
        // One left-edge candidate of the lower triangle of cell (1, 1): its row fills.
        let (i, j) = g.lattice(8, (2, 0));
        g.set(i, j, true);
        g.insert_rows();
        let (ii, jj) = g.lattice(8, (2, 1));
        assert!(g.get(ii, jj));
        let (ci, cj) = g.lattice(8, (1, 0));
        assert!(!g.get(ci, cj));
    }
}
