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
    /// triangles and a pinched mesh.
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
}
