//! SD-2, the semi-uniform 2-different pattern of Amresh & Fünfzig (paper 001, §3.3, Figs. 3
//! and 4), for triangle domains with at most two different edge factors.
//!
//! **Pattern.** Two edges of the triangle carry the same factor `fs`; they meet at the *tip*
//! corner. The third, the *diff* edge, carries `fd`. A bundle of lines parallel to the diff
//! edge cuts the two same edges at the `fs` samples, and a bundle of radial lines runs from
//! the tip to the `fd` samples of the diff edge. Their intersections are the vertices: row
//! `i` (`0 = tip … ns = diff edge`) at fraction `r_i` of the way from the tip, radial line
//! `j` through diff-edge sample `s_j`. Each radial sector is one triangle strip from the tip
//! outwards (`tip, R1₁, R2₁, R1₂, R2₂, …`, Fig. 4): `2·ns − 1` triangles, so a patch has
//! `nd·(2·ns − 1)` triangles and `(ns − 1)(nd − 1)` interior vertices. Every triangle has
//! two vertices on one line of a bundle and one on the next, so none folds over.
//!
//! **Fractional factors, symmetric remainder (Fig. 4).** A real factor `f ≥ 1` cuts an edge
//! into `n = ⌈f⌉` segments: the inner `n − 2` are `1/f` long and the rest, `1 − (n − 2)/f`,
//! is shared equally by the first and the last, so the cut is symmetric about the edge
//! midpoint and needs no direction (neighbours agree however they run along it). The paper's
//! pseudo code writes the shift as `(k + 1 − inc)/f` with `inc = ½(1/f − (f − ⌊f⌋)/f)`,
//! which mixes parameter and index units and for integer `f` does not reach the far corner;
//! the prose ("shrinking the first segment and augmenting the last by the half fractional
//! remainder") gives `(k + 1)/f − inc` with the remainder `f − (n − 1) ∈ (0, 1]`, which is
//! what we use. With it, integer factors give the uniform cut. As `f` crosses an integer `m`
//! upwards a new segment appears and every inner point shifts by up to `1/(2m)`: the SD-2
//! cut is continuous in `f` except at integers. (`hardware`'s fractional modes are the continuous ones.)
//!
//! **Reverse projection (§3.3, after Munkberg et al.).** Optionally, the pattern's
//! barycentric coordinates `b` are warped to `b'_i = (b_i/z_i) / Σ_k (b_k/z_k)` with the
//! corner depths `z_i`, so the pattern is uniform on screen rather than in the domain. The
//! warp is projective, so lines stay lines and no triangle folds. On an edge it depends only
//! on the edge's two end depths, so the criterion can warp the edge samplings identically
//! for both neighbours ([`crate::sampling::warped_param`]); the pattern warps its interior points itself from
//! the per-patch corner depths it holds.
//!
//! **Three different factors** never come from the SD-2 criterion, which derives factors
//! from a level function. Should an input still have them, the pattern falls back to the
//! CudaTess [`Transition`] pattern with the largest factor inside, which keeps the mesh
//! closed (edges keep their samplings) but is not SD-2.
//!
//! Cost: O(output) per patch; strips and list come from one walk.

use super::transition::Transition;
use super::{LocalTessellation, Pattern, PatternInput};
use crate::domain::Domain;
use crate::mesh::strips::RESTART;
use glam::{DVec2, DVec3};
use std::sync::Arc;

use crate::sampling::symmetric_param;

/// The SD-2 pattern.
///
/// Preconditions: triangle domains (quads are refused by the criterion; given one, the
/// pattern falls back to [`Transition`]); `segments[e] = crate::sampling::symmetric_segments(factors[e])`.
/// With `corner_depths`, entry `p` holds patch `p`'s corner depths (all > 0) and the
/// interior is reverse-projected; the edge samplings must then be warped the same way.
#[derive(Debug, Clone, Default)]
pub struct Sd2 {
    pub corner_depths: Option<Arc<[[f64; 3]]>>,
}

/// Which edge is the diff edge, or `None` for three different factors.
fn diff_edge(f: &[f64; 4]) -> Option<usize> {
    // All equal counts as "edges 1 and 2 agree": any edge may then be the diff edge.
    if f[1] == f[2] {
        Some(0)
    } else if f[2] == f[0] {
        Some(1)
    } else if f[0] == f[1] {
        Some(2)
    } else {
        None
    }
}

/// The layout of one SD-2 triangle.
struct Layout {
    /// Diff edge `d` (corner `d` → `d + 1`); the tip is corner `d + 2`.
    d: usize,
    ns: u32,
    nd: u32,
    fs: f64,
    fd: f64,
    input: PatternInput,
    interior_base: u32,
}

impl Layout {
    fn new(input: &PatternInput) -> Option<Layout> {
        if input.domain != Domain::Tri {
            return None;
        }
        let d = diff_edge(&input.factors)?;
        let same = (d + 1) % 3;
        Some(Layout {
            d,
            ns: input.segments[same],
            nd: input.segments[d],
            fs: input.factors[same],
            fd: input.factors[d],
            input: *input,
            interior_base: input.interior_base(),
        })
    }

    /// Local index of the vertex on row `i` (from the tip) and radial line `j`.
    fn vertex(&self, i: u32, j: u32) -> u32 {
        let (d, ns, nd) = (self.d, self.ns, self.nd);
        if i == 0 {
            return ((d + 2) % 3) as u32;
        }
        if i == ns {
            return self.input.boundary_vertex(d, j); // diff edge runs corner d → d+1 with j
        }
        if j == 0 {
            // Edge d+2 runs from the tip to corner d: its sample i is row i.
            return self.input.boundary_vertex((d + 2) % 3, i);
        }
        if j == nd {
            // Edge d+1 runs from corner d+1 to the tip: row i is its sample ns − i.
            return self.input.boundary_vertex((d + 1) % 3, ns - i);
        }
        self.interior_base + (i - 1) * (nd - 1) + (j - 1)
    }
}

/// Barycentric weights `(corner 0, 1, 2)` of a domain point of the triangle.
fn barycentric(p: DVec2) -> DVec3 {
    DVec3::new(1.0 - p.x - p.y, p.x, p.y)
}

impl Sd2 {
    fn warp(&self, patch: u32, p: DVec2) -> DVec2 {
        let Some(depths) = &self.corner_depths else { return p };
        let z = depths[patch as usize];
        let b = barycentric(p);
        let w = DVec3::new(b.x / z[0], b.y / z[1], b.z / z[2]);
        let s = w.x + w.y + w.z;
        DVec2::new(w.y / s, w.z / s)
    }

    /// Emits the strips (local indices) of every radial sector through `emit`, one call per
    /// strip vertex, with `None` between strips.
    fn walk(layout: &Layout, mut emit: impl FnMut(Option<u32>)) {
        for j in 0..layout.nd {
            if j > 0 {
                emit(None);
            }
            emit(Some(layout.vertex(0, 0)));
            for i in 1..=layout.ns {
                emit(Some(layout.vertex(i, j)));
                emit(Some(layout.vertex(i, j + 1)));
            }
        }
    }
}

impl Pattern for Sd2 {
    fn name(&self) -> &'static str {
        "sd2"
    }

    fn depends_on_patch(&self) -> bool {
        self.corner_depths.is_some() // the warp reads the patch's corner depths
    }

    fn counts(&self, input: &PatternInput) -> (u32, u32) {
        match Layout::new(input) {
            Some(l) => ((l.ns - 1) * (l.nd - 1), l.nd * (2 * l.ns - 1)),
            None => Transition.counts(&fallback(input)),
        }
    }

    fn triangulate(&self, input: &PatternInput, out: &mut LocalTessellation) {
        out.interior.clear();
        out.triangles.clear();
        let Some(l) = Layout::new(input) else {
            Transition.triangulate(&fallback(input), out);
            return;
        };
        let d = l.d;
        let tip = Domain::Tri.corner((d + 2) % 3);
        let (a, b) = (Domain::Tri.corner(d), Domain::Tri.corner((d + 1) % 3));
        for i in 1..l.ns {
            let r = symmetric_param(l.fs, i);
            for j in 1..l.nd {
                let s = symmetric_param(l.fd, j);
                let on_diff = a * (1.0 - s) + b * s;
                let p = tip * (1.0 - r) + on_diff * r;
                out.interior.push(self.warp(input.patch, p));
            }
        }
        // The list is the decoded strips, in strip order.
        let mut strip = Vec::with_capacity(2 * l.ns as usize + 1);
        let flush = |strip: &mut Vec<u32>, out: &mut LocalTessellation| {
            for (k, w) in strip.windows(3).enumerate() {
                out.triangles.push(if k % 2 == 0 { [w[0], w[1], w[2]] } else { [w[1], w[0], w[2]] });
            }
            strip.clear();
        };
        Self::walk(&l, |v| match v {
            Some(v) => strip.push(v),
            None => flush(&mut strip, out),
        });
        flush(&mut strip, out);
    }

    fn strips(&self, input: &PatternInput, out: &mut Vec<u32>) -> bool {
        let Some(l) = Layout::new(input) else { return false };
        Self::walk(&l, |v| out.push(v.unwrap_or(RESTART)));
        true
    }
}

/// The input the [`Transition`] fallback gets: the largest factor inside.
fn fallback(input: &PatternInput) -> PatternInput {
    let n = input.segments[..input.domain.corner_count()].iter().copied().max().unwrap_or(1);
    PatternInput { interior: [n, n], ..*input }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::strips::decode;
    use crate::sampling::{symmetric_segments, warped_param};

    fn input(f: [f64; 3]) -> PatternInput {
        let segments = [symmetric_segments(f[0]), symmetric_segments(f[1]), symmetric_segments(f[2]), 1];
        PatternInput {
            domain: Domain::Tri,
            segments,
            interior: [1, 1],
            factors: [f[0], f[1], f[2], 1.0],
            patch: 0,
            collapsed: [false; 4],
            pinched: [false; 4],
        }
    }

    /// Domain position of every local index (edge samples from the symmetric cut).
    fn positions(input: &PatternInput, local: &LocalTessellation, warp: Option<[f64; 3]>) -> Vec<DVec2> {
        input.local_positions(&local.interior, |e, k| {
            let t = symmetric_param(input.factors[e], k);
            warp.map_or(t, |z| warped_param(t, z[e], z[(e + 1) % 3]))
        })
    }

    fn assert_tiles(input: &PatternInput, local: &LocalTessellation, pos: &[DVec2]) {
        crate::pattern::assert_tiles(input, local, pos, 0.0);
    }

    #[test]
    fn symmetric_cut_is_symmetric_monotone_and_uniform_for_integers() {
        for step in 0..=2000 {
            let f = 1.0 + step as f64 * 0.0317;
            let n = symmetric_segments(f);
            assert_eq!(symmetric_param(f, 0), 0.0);
            assert_eq!(symmetric_param(f, n), 1.0);
            for k in 0..=n {
                let mirrored = 1.0 - symmetric_param(f, k);
                assert!((symmetric_param(f, n - k) - mirrored).abs() <= 1e-15, "f {f} k {k}");
                if k > 0 {
                    let seg = symmetric_param(f, k) - symmetric_param(f, k - 1);
                    assert!(seg > 0.0, "f {f}: segment {k} is {seg}");
                    if k > 1 && k < n {
                        assert!((seg - 1.0 / f).abs() < 1e-12, "inner segments are 1/f");
                    }
                }
            }
            let (first, last) = (symmetric_param(f, 1), 1.0 - symmetric_param(f, n - 1));
            assert!((first - last).abs() < 1e-15, "remainder shared equally");
        }
        for n in 1..=20u32 {
            for k in 0..=n {
                assert!((symmetric_param(n as f64, k) - k as f64 / n as f64).abs() < 1e-15);
            }
        }
        // Bad factors do not panic.
        assert_eq!(symmetric_segments(f64::NAN), 1);
        assert_eq!(symmetric_segments(-3.0), 1);
        assert_eq!(symmetric_segments(1e300), crate::sampling::MAX_FACTOR);
    }

    #[test]
    fn paper_examples_have_the_expected_counts() {
        // Fig. 3: fu = fv = 3, fw = 3 and fu = fv = 3, fw = 5; 2.5 everywhere.
        for (f, tris) in [([3.0, 3.0, 3.0], 15), ([5.0, 3.0, 3.0], 25), ([2.5, 2.5, 2.5], 15)] {
            let inp = input(f);
            let mut local = LocalTessellation::default();
            Sd2::default().build(&inp, &mut local);
            assert_eq!(local.triangles.len(), tris, "{f:?}");
            assert_eq!(Sd2::default().counts(&inp), (local.interior.len() as u32, tris as u32));
        }
    }

    #[test]
    fn tiles_the_triangle_for_every_two_different_assignment() {
        let sd2 = Sd2::default();
        let mut local = LocalTessellation::default();
        let factors = [1.0, 1.4, 2.0, 2.5, 3.0, 3.99, 4.0, 5.2, 7.0, 11.5];
        for &a in &factors {
            for &b in &factors {
                for d in 0..3 {
                    let mut f = [a; 3];
                    f[d] = b;
                    let inp = input(f);
                    sd2.build(&inp, &mut local);
                    let (vi, t) = sd2.counts(&inp);
                    assert_eq!((vi as usize, t as usize), (local.interior.len(), local.triangles.len()));
                    assert_tiles(&inp, &local, &positions(&inp, &local, None));
                    let mut strips = Vec::new();
                    assert!(sd2.strips(&inp, &mut strips));
                    assert_eq!(decode(&strips), local.triangles, "strips decode to the list");
                }
            }
        }
    }

    #[test]
    fn reverse_projection_keeps_a_valid_tiling() {
        let depths = [[1.0, 4.0, 2.0], [10.0, 1.5, 3.0], [0.2, 0.2, 5.0]];
        for z in depths {
            let sd2 = Sd2 { corner_depths: Some(Arc::from(vec![z])) };
            for f in [[3.0, 7.0, 7.0], [2.5, 2.5, 6.3], [4.0, 4.0, 4.0]] {
                let inp = input(f);
                let mut local = LocalTessellation::default();
                sd2.build(&inp, &mut local);
                assert_tiles(&inp, &local, &positions(&inp, &local, Some(z)));
            }
        }
        // The warp moves points towards the nearer corner.
        assert!(warped_param(0.5, 1.0, 4.0) < 0.5);
        assert_eq!(warped_param(0.5, 2.0, 2.0), 0.5);
    }

    #[test]
    fn three_different_factors_fall_back_to_a_closed_pattern() {
        let inp = input([2.0, 3.0, 5.0]);
        let mut local = LocalTessellation::default();
        Sd2::default().build(&inp, &mut local);
        let (vi, t) = Sd2::default().counts(&inp);
        assert_eq!((vi as usize, t as usize), (local.interior.len(), local.triangles.len()));
        assert_tiles(&inp, &local, &positions(&inp, &local, None));
        assert!(!Sd2::default().strips(&inp, &mut Vec::new()));
    }
}
