//! Welding of coincident points, so that patches whose neighbours do not share indices (as in
//! most patch files) still share their boundary curves.

use glam::DVec3;
use std::collections::HashMap;

/// How coincident points are merged.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Weld {
    /// Merge points with bit-identical coordinates (`-0.0` equals `0.0`). The default: it never
    /// merges points the author kept apart.
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

fn bits(p: DVec3, w: f64) -> [u64; 4] {
    // Adding 0.0 turns -0.0 into +0.0, so the two zeros hash alike.
    [(p.x + 0.0).to_bits(), (p.y + 0.0).to_bits(), (p.z + 0.0).to_bits(), (w + 0.0).to_bits()]
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
            let mut seen: HashMap<[u64; 4], u32> = HashMap::with_capacity(n);
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
    fn exact_weld_merges_bit_equal_points_and_signed_zeros() {
        let p = [DVec3::new(0.0, 1.0, 2.0), DVec3::new(-0.0, 1.0, 2.0), DVec3::new(0.0, 1.0, 2.0000001)];
        let w = weld(&p, &[1.0; 3], Weld::Exact);
        assert_eq!(w.ids, vec![0, 0, 2]);
        assert_eq!(w.merged, 1);
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
