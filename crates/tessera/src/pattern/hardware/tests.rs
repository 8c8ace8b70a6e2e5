//! Tests of the hardware patterns; the comparison with the Direct3D 11 reference file is
//! `tests/hardware_reference.rs`.

use super::*;
use crate::pattern::assert_tiles;
use crate::sampling::hardware::reciprocal;
use proptest::prelude::RngExt;
use proptest::test_runner::{RngAlgorithm, TestRng};

const ALL: [Partitioning; 4] =
    [Partitioning::Integer, Partitioning::Pow2, Partitioning::FractionalOdd, Partitioning::FractionalEven];

#[test]
fn reciprocals_are_the_hardware_table() {
    // Spot checks of the published 16.16 table, including the rounded-up entries.
    let table = [(1, 0x10000), (3, 0x5555), (6, 0x2aab), (7, 0x2492), (10, 0x199a), (63, 0x410), (64, 0x400)];
    for (n, want) in table {
        assert_eq!(reciprocal(n), want, "1/{n}");
    }
}

#[test]
fn the_published_examples() {
    // Issue 15's figures: even F = 3 gives 0, .375, .5, .625, 1.
    let a = Axis::edge(3.0, Partitioning::FractionalEven);
    let p: Vec<f64> = (0..=a.segments()).map(|k| a.param(k)).collect();
    assert_eq!(p, [0.0, 0.375, 0.5, 0.625, 1.0]);
    // Odd F = 5.3: segment lengths × F of 1.0145, 0.1136, 1.0145, 1.0146, 1.0145, 0.1136, 1.0145.
    let a = Axis::edge(5.3, Partitioning::FractionalOdd);
    let want = [1.0145, 0.1136, 1.0145, 1.0146, 1.0145, 0.1136, 1.0145];
    assert_eq!(a.segments(), 7);
    for k in 0..7 {
        let len = (a.param(k + 1) - a.param(k)) * 5.3;
        assert!((len - want[k as usize]).abs() < 2e-4, "segment {k}: {len}");
    }
}

#[test]
fn edge_partitions_are_symmetric_and_increasing() {
    for partitioning in ALL {
        for i in 0..=7000 {
            let f = 0.01 * i as f64;
            let a = Axis::edge(f, partitioning);
            let n = a.segments();
            assert_eq!(a.param(0), 0.0);
            assert_eq!(a.param(n), 1.0);
            for k in 0..=n {
                assert_eq!(
                    a.param(n - k).to_bits(),
                    (1.0 - a.param(k)).to_bits(),
                    "{partitioning:?} {f} {k}"
                );
                if k < n {
                    assert!(a.param(k + 1) >= a.param(k), "{partitioning:?} {f} {k}");
                }
            }
            let (lo, hi) = partitioning.range();
            let fc = (f as f32).clamp(lo, hi) as f64;
            match partitioning {
                Partitioning::Integer | Partitioning::Pow2 => assert_eq!(n, fc.ceil() as u32),
                Partitioning::FractionalOdd => assert!(n % 2 == 1 && n as f64 >= fc - 1e-4),
                Partitioning::FractionalEven => assert!(n % 2 == 0 && n as f64 >= fc - 1e-4),
            }
        }
    }
}

fn input(domain: Domain, partitioning: Partitioning, factors: [f64; 4]) -> PatternInput {
    PatternInput {
        domain,
        segments: factors.map(|f| edge_segments(f, partitioning)),
        interior: [1, 1],
        factors,
        patch: 0,
        collapsed: [false; 4],
        pinched: [false; 4],
    }
}

/// Seeded factors, so failures reproduce.
struct Factors(TestRng);
impl Factors {
    fn new(seed: u8) -> Self {
        Factors(TestRng::from_seed(RngAlgorithm::ChaCha, &[seed; 32]))
    }
    fn next(&mut self) -> f64 {
        self.0.random::<f64>()
    }
    /// A factor in [1, 66]: often an integer or a small one; settled as the criteria do.
    fn factor(&mut self, partitioning: Partitioning) -> f64 {
        let x = 1.0 + 65.0 * self.next();
        let f = match (self.next() * 5.0) as u32 {
            0 => x.round(),
            1 => 1.0 + 4.0 * self.next(),
            _ => x,
        };
        settled_factor(partitioning.hull_factor(f), partitioning, OUTPUT_GAP)
    }
}

#[test]
fn tiles_the_domain_for_many_factor_combinations() {
    let mut rng = Factors::new(1);
    let mut out = LocalTessellation::default();
    for partitioning in ALL {
        for domain in [Domain::Tri, Domain::Quad] {
            for case in 0..600 {
                let factors =
                    if case < 64 { [1.0 + case as f64; 4] } else { [0; 4].map(|_| rng.factor(partitioning)) };
                let pattern = Hardware { partitioning };
                let input = input(domain, partitioning, factors);
                pattern.build(&input, &mut out);
                assert_eq!(
                    pattern.counts(&input),
                    (out.interior.len() as u32, out.triangles.len() as u32),
                    "{partitioning:?} {input:?}"
                );
                let spacing = crate::sampling::Spacing::Hardware(partitioning);
                let p = input.local_positions(&out.interior, |e, k| {
                    crate::sampling::spacing_param(input.factors[e], spacing, k)
                });
                assert_tiles(&input, &out, &p, 0.0);
            }
        }
    }
}

#[test]
fn boundary_points_are_the_edge_samplings() {
    // The hardware's own outer-ring points equal the local positions the engine gives the
    // boundary vertices, bit for bit, for every edge direction.
    let mut rng = Factors::new(7);
    let mut out = LocalTessellation::default();
    for partitioning in ALL {
        for domain in [Domain::Tri, Domain::Quad] {
            for _ in 0..200 {
                let factors = [0; 4].map(|_| rng.factor(partitioning));
                let input = input(domain, partitioning, factors);
                let pattern = Hardware { partitioning };
                pattern.build(&input, &mut out);
                let (edges, inside) = pattern.factors(&input);
                let hw = tessellate(domain, partitioning, edges, inside).unwrap();
                let p = input
                    .local_positions(&out.interior, |e, k| edge_param(input.factors[e], partitioning, k));
                let mut hw_tris: Vec<[DVec2; 3]> =
                    hw.triangles.iter().map(|t| t.map(|v| hw.points[v as usize])).collect();
                let mut local_tris: Vec<[DVec2; 3]> =
                    out.triangles.iter().map(|t| t.map(|v| p[v as usize])).collect();
                let key = |t: &[DVec2; 3]| t.map(|q| (q.x.to_bits(), q.y.to_bits()));
                hw_tris.sort_by_key(key);
                local_tris.sort_by_key(key);
                assert_eq!(hw_tris, local_tris, "{partitioning:?} {input:?}");
            }
        }
    }
}

/// Largest distance from a point of `a` to its nearest point of `b` (a grid of buckets
/// of side `cell`, searched one bucket around; farther points count as `cell`).
fn one_sided_hausdorff(a: &[DVec2], b: &[DVec2], cell: f64) -> f64 {
    use std::collections::HashMap;
    let key = |p: DVec2| ((p.x / cell).floor() as i64, (p.y / cell).floor() as i64);
    let mut grid: HashMap<(i64, i64), Vec<DVec2>> = HashMap::new();
    for &q in b {
        grid.entry(key(q)).or_default().push(q);
    }
    a.iter()
        .map(|&p| {
            let (i, j) = key(p);
            let mut best = cell;
            for di in -1..=1 {
                for dj in -1..=1 {
                    for q in grid.get(&(i + di, j + dj)).into_iter().flatten() {
                        best = best.min(p.distance(*q));
                    }
                }
            }
            best
        })
        .fold(0.0, f64::max)
}

/// The fractional modes move points continuously with the factor: sweeping every factor
/// of a patch from 1 to 64 in steps of `STEP`, a point that keeps its index moves at most
/// `C · STEP` (plus one fixed-point step), and when points are born or die every point of
/// either tessellation lies that close to one of the other. Measured: no point moves more
/// than 0.245 × the factor step (asserted: 0.5).
#[test]
fn fractional_modes_are_continuous() {
    const STEP: f64 = 4e-3;
    const C: f64 = 0.5;
    let quantum = 2.0 / 65536.0;
    let mut worst: f64 = 0.0;
    for partitioning in [Partitioning::FractionalOdd, Partitioning::FractionalEven] {
        for domain in [Domain::Tri, Domain::Quad] {
            let configs: [fn(f32) -> [f32; 4]; 3] =
                [|f| [f; 4], |f| [f, 1.0 + f / 2.0, f, 2.0], |f| [1.0 + f / 3.0, f, 0.5 * f + 1.0, f]];
            for config in configs {
                let at = |f: f64| {
                    let edges = config(f as f32);
                    let inside = match domain {
                        Domain::Quad => [edges[1].max(edges[3]), edges[0].max(edges[2])],
                        Domain::Tri => [edges[0].max(edges[1]).max(edges[2]); 2],
                    };
                    tessellate(domain, partitioning, edges, inside).unwrap().points
                };
                let mut old = at(1.0);
                let steps = (63.0 / STEP) as u32;
                for s in 1..=steps {
                    let new = at(1.0 + s as f64 * STEP);
                    let moved = if new.len() == old.len() {
                        new.iter().zip(&old).map(|(a, b)| a.distance(*b)).fold(0.0, f64::max)
                    } else {
                        let cell = 4.0 * C * STEP;
                        one_sided_hausdorff(&new, &old, cell).max(one_sided_hausdorff(&old, &new, cell))
                    };
                    assert!(
                        moved <= C * STEP + quantum,
                        "{partitioning:?} {domain:?}: a point moved {moved} at factor step {s}"
                    );
                    worst = worst.max((moved - quantum).max(0.0) / STEP);
                    old = new;
                }
            }
        }
    }
    eprintln!("fractional continuity: largest move {worst:.3} × the factor step");
}

#[test]
fn culls_on_non_positive_factors() {
    for f in [0.0, -1.0, f32::NAN] {
        assert!(tessellate(Domain::Quad, Partitioning::Integer, [f, 2.0, 2.0, 2.0], [2.0, 2.0]).is_none());
        assert!(
            tessellate(Domain::Tri, Partitioning::FractionalOdd, [2.0, f, 2.0, 0.0], [2.0, 0.0]).is_none()
        );
    }
}

#[test]
fn pow2_hull_factors_are_powers_of_two() {
    for (f, want) in [(0.5, 0.5), (1.0, 1.0), (1.1, 2.0), (3.0, 4.0), (4.0, 4.0), (33.0, 64.0), (100.0, 64.0)]
    {
        assert_eq!(Partitioning::Pow2.hull_factor(f), want, "{f}");
    }
}

/// [`Hardware`]'s promise ([`Pattern::cut_through_corners_0_and_2`]): no triangle at corner
/// 0 or 2 of a quad has all three vertices on the corner's two edges, so a patch pinched
/// there needs no cut. Every partitioning, every integer factor 1–8 on each edge, and
/// thousands of real ones (half of them small, where the inner ring degenerates). The same
/// check at corners 1 and 3 must find the chord of the two-triangle quad, or it sees nothing.
#[test]
fn corners_0_and_2_keep_a_vertex_off_their_edges() {
    let mut rng = Factors::new(9);
    let mut out = LocalTessellation::default();
    let mut chords_at_1_and_3 = 0;
    for partitioning in ALL {
        let pattern = Hardware { partitioning };
        assert!(pattern.cut_through_corners_0_and_2());
        let settle = |f: f64| settled_factor(partitioning.hull_factor(f), partitioning, OUTPUT_GAP);
        let mut cases: Vec<[f64; 4]> = (0..8u32.pow(4))
            .map(|code| std::array::from_fn(|e| 1.0 + ((code >> (3 * e)) % 8) as f64))
            .collect();
        for case in 0..3000 {
            cases.push(std::array::from_fn(|_| {
                if case % 2 == 0 {
                    rng.factor(partitioning)
                } else {
                    1.0 + 3.0 * rng.next()
                }
            }));
        }
        for factors in cases {
            let input = input(Domain::Quad, partitioning, factors.map(settle));
            pattern.build(&input, &mut out);
            for c in 0..4 {
                let chord = out.triangles.iter().any(crate::pattern::on_corner_edges(&input, c));
                if c % 2 == 1 {
                    chords_at_1_and_3 += usize::from(chord);
                } else {
                    assert!(!chord, "{partitioning:?} {input:?}: a triangle on corner {c}'s two edges");
                }
            }
        }
    }
    assert!(chords_at_1_and_3 > 0, "no chord at corners 1 and 3: the check sees nothing");
}
