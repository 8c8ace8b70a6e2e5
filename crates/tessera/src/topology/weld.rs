//! Welding of coincident points, so that patches whose neighbours do not share indices (as in
//! most patch files) still share their boundary curves.

use glam::DVec3;
use std::collections::HashMap;

/// How coincident points are merged.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Weld {
    /// Merge points whose coordinates (and weights) are identical at `f32` precision, the
    /// precision of the output (`-0.0` equals `0.0`). The default: it merges only points that
    /// would become one output position anyway — a boundary curve shorter than `f32` can
    /// resolve then collapses to a point (and is handled as one) instead of giving degenerate
    /// triangles and a pinched mesh. A curve within one `f32` step whose points straddle a
    /// rounding boundary collapses too ([`collapse_unresolved_curves`], also after `Within`).
    #[default]
    Exact,
    /// Merge points closer than this distance (per axis grid cells, then Euclidean test); each
    /// merged point takes the coordinates of the first point of its cluster, so the curves of
    /// both neighbours become identical.
    Within(f64),
    /// Match by index only.
    Off,
}

/// Result of welding: `ids[i]` is the representative of point `i` (the smallest index of its
/// cluster), and how many points were moved onto another.
#[derive(Debug, Clone, PartialEq)]
pub struct Welded {
    pub ids: Vec<u32>,
    pub merged: usize,
}

fn bits(p: DVec3, w: f64) -> [u32; 4] {
    // Adding 0.0 turns -0.0 into +0.0, so the two zeros hash alike.
    [p.x, p.y, p.z, w].map(|x| (x as f32 + 0.0).to_bits())
}

/// Welds `points` (with their `weights`; points of different weight never merge).
/// Preconditions: finite coordinates; `weights.len() == points.len()`. Cost: O(n) expected.
pub fn weld(points: &[DVec3], weights: &[f64], mode: Weld) -> Welded {
    let n = points.len();
    let mut ids: Vec<u32> = (0..n as u32).collect();
    let mut merged = 0;
    match mode {
        Weld::Off => {}
        Weld::Exact => {
            let mut seen: HashMap<[u32; 4], u32> = HashMap::with_capacity(n);
            for i in 0..n {
                let r = *seen.entry(bits(points[i], weights[i])).or_insert(i as u32);
                if r != i as u32 {
                    merged += 1;
                }
                ids[i] = r;
            }
        }
        Weld::Within(eps) => {
            let eps = eps.max(f64::MIN_POSITIVE);
            let cell = |p: DVec3| (p / eps).floor().as_i64vec3();
            let mut grid: HashMap<glam::I64Vec3, Vec<u32>> = HashMap::with_capacity(n);
            for i in 0..n {
                let c = cell(points[i]);
                let mut found = None;
                'search: for dz in -1..=1 {
                    for dy in -1..=1 {
                        for dx in -1..=1 {
                            if let Some(list) = grid.get(&(c + glam::I64Vec3::new(dx, dy, dz))) {
                                for &r in list {
                                    if weights[r as usize] == weights[i]
                                        && points[r as usize].distance(points[i]) <= eps
                                    {
                                        found = Some(r);
                                        break 'search;
                                    }
                                }
                            }
                        }
                    }
                }
                match found {
                    Some(r) => {
                        ids[i] = r;
                        merged += 1;
                    }
                    None => grid.entry(c).or_default().push(i as u32),
                }
            }
        }
    }
    Welded { ids, merged }
}

/// The spacing of `f32` values at `x`: how far apart two coordinates near `x` must be for the
/// output to tell them apart.
fn f32_step(x: f64) -> f64 {
    let f = (x.abs() as f32).min(f32::MAX);
    if f == f32::MAX {
        return f64::INFINITY;
    }
    // The neighbouring float by its bits (the crate's minimum Rust has no `next_up`).
    f64::from(f32::from_bits(f.to_bits() + 1)) - f64::from(f)
}

/// Whether `f32` cannot resolve a curve with these control points: on every axis they lie
/// within one `f32` step (at their largest coordinate) of each other. The exact weld merges
/// such points only when they round to the same floats; when they straddle a rounding
/// boundary they stay apart, and the curve's samples then land on one or two floats per axis
/// in no particular order, so the mesh pinches or folds there. Such a curve is a point.
pub fn unresolved_at_f32(curve: [DVec3; 4]) -> bool {
    (0..3).all(|axis| {
        let (mut lo, mut hi, mut big) = (f64::INFINITY, f64::NEG_INFINITY, 0.0f64);
        for p in curve {
            lo = lo.min(p[axis]);
            hi = hi.max(p[axis]);
            big = big.max(p[axis].abs());
        }
        hi - lo <= f32_step(big)
    })
}

/// Merges the control points of every curve [`unresolved_at_f32`] into one point, so the
/// topology sees the curve as collapsed (as it does a curve whose points weld exactly) and
/// every engine and scheme emits one vertex for it. `curves` gives each curve's four control
/// points as indices into `points` and `ids`; `ids` is a weld's result and stays one: every
/// point's id is the smallest index of its (now larger) cluster. Returns how many more points
/// were merged into another.
///
/// The one place for this rule: it runs where the weld does, before the topology is built,
/// so nothing downstream needs to know about it. Inputs without such curves are untouched.
/// Cost: O(curves) plus O(n) when a curve was merged.
pub fn collapse_unresolved_curves(
    points: &[DVec3],
    curves: impl IntoIterator<Item = [usize; 4]>,
    ids: &mut [u32],
) -> usize {
    // Union-find over the weld's representatives, touched ones only; the root of a set is its
    // smallest representative, so the result keeps the weld's "smallest index" rule.
    let mut parent: HashMap<u32, u32> = HashMap::new();
    fn root(parent: &HashMap<u32, u32>, mut x: u32) -> u32 {
        while let Some(&p) = parent.get(&x) {
            if p == x {
                break;
            }
            x = p;
        }
        x
    }
    for curve in curves {
        let reps = curve.map(|i| ids[i]);
        if reps.iter().all(|&r| r == reps[0]) || !unresolved_at_f32(curve.map(|i| points[i])) {
            continue;
        }
        let roots = reps.map(|r| root(&parent, r));
        let min = *roots.iter().min().expect("four roots");
        for r in roots {
            parent.insert(r, min);
        }
        parent.entry(min).or_insert(min);
    }
    if parent.is_empty() {
        return 0;
    }
    let mut merged = 0;
    for id in ids.iter_mut() {
        let r = root(&parent, *id);
        if r != *id {
            *id = r;
            merged += 1;
        }
    }
    merged
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_weld_merges_points_equal_at_f32_precision_and_signed_zeros() {
        let p = [
            DVec3::new(0.0, 1.0, 2.0),
            DVec3::new(-0.0, 1.0, 2.0),
            // 1e-8 apart: one f32 position, so one point.
            DVec3::new(0.0, 1.0, 2.00000001),
            // 1e-6 apart: four f32 steps, kept apart.
            DVec3::new(0.0, 1.0, 2.000001),
        ];
        let w = weld(&p, &[1.0; 4], Weld::Exact);
        assert_eq!(w.ids, vec![0, 0, 0, 3]);
        assert_eq!(w.merged, 2);
    }

    #[test]
    fn tolerance_weld_merges_close_points_only() {
        let p = [DVec3::ZERO, DVec3::new(1e-7, 0.0, 0.0), DVec3::new(1e-3, 0.0, 0.0)];
        let w = weld(&p, &[1.0; 3], Weld::Within(1e-6));
        assert_eq!(w.ids, vec![0, 0, 2]);
        let w = weld(&p, &[1.0, 2.0, 1.0], Weld::Within(1e-6));
        assert_eq!(w.ids, vec![0, 1, 2], "different weights never merge");
    }

    #[test]
    fn a_curve_within_one_f32_step_collapses_and_a_longer_one_does_not() {
        // At 1000 the f32 step is 2^-14 ≈ 6.1e-5; these points straddle the rounding boundary
        // half a step above 1000, so the exact weld keeps them apart.
        let step = 1.0 / 16384.0;
        let base = DVec3::splat(1000.0 + step / 2.0);
        let mut p: Vec<DVec3> = (0..4).map(|k| base + DVec3::splat((k as f64 - 1.5) * step / 4.0)).collect();
        p.extend((0..4).map(|k| base + DVec3::new(1.0, 0.0, 0.0) + DVec3::splat(k as f64 * 3.0 * step)));
        let mut w = weld(&p, &[1.0; 8], Weld::Exact);
        assert_ne!(w.ids[0], w.ids[3], "the exact weld alone keeps the short curve's ends apart");
        let before = w.ids.clone();
        let merged = collapse_unresolved_curves(&p, [[0, 1, 2, 3], [4, 5, 6, 7]], &mut w.ids);
        assert_eq!(&w.ids[..4], &[0; 4], "one point, the smallest index");
        assert_eq!(&w.ids[4..], &[4, 5, 6, 7], "three steps apart: resolved, kept");
        assert_eq!(merged, before.iter().zip(&w.ids).filter(|(a, b)| a != b).count());
        assert_eq!(collapse_unresolved_curves(&p, [[0, 1, 2, 3]], &mut w.ids), 0, "already one point");
    }
}
