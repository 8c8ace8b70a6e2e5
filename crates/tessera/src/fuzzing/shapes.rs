//! The surfaces an engine case is generated from: closed patch and mesh shapes on an integer
//! lattice, jittered, and random ones of any topology, read off the fuzz bytes.

use std::collections::HashMap;
use std::fmt::Write as _;

/// A reader of fuzz bytes as small decisions; past the end every value is 0, so every input,
/// even an empty one, decodes to a case.
pub(super) struct Decisions<'a> {
    data: &'a [u8],
    pos: usize,
}

impl<'a> Decisions<'a> {
    pub(super) fn new(data: &'a [u8]) -> Self {
        Decisions { data, pos: 0 }
    }

    fn byte(&mut self) -> u8 {
        let b = self.data.get(self.pos).copied().unwrap_or(0);
        self.pos += 1;
        b
    }

    /// A value in `0..n` (`n ≥ 1`): one byte for small ranges, so that short inputs still
    /// make many decisions, two for larger ones.
    pub(super) fn below(&mut self, n: u32) -> u32 {
        let v = if n <= 256 {
            u32::from(self.byte())
        } else {
            u32::from(self.byte()) | u32::from(self.byte()) << 8
        };
        v % n
    }

    /// An integer in `lo..=hi`.
    pub(super) fn int_in(&mut self, lo: i32, hi: i32) -> i32 {
        lo + self.below((hi - lo + 1) as u32) as i32
    }

    /// True about once in `n` times.
    pub(super) fn one_in(&mut self, n: u32) -> bool {
        self.below(n) == 0
    }

    /// A real factor in `[lo, hi]`: mostly spread evenly, sometimes one of the values where
    /// rounding and partitioning rules change (integers, and just above or below them).
    pub(super) fn factor(&mut self, lo: f64, hi: f64) -> f64 {
        const AWKWARD: [f64; 12] = [1.0, 1.0001, 1.5, 1.9999, 2.0, 2.0001, 2.5, 3.0, 4.0, 7.5, 15.9999, 16.0];
        let f = if self.one_in(3) {
            AWKWARD[self.below(AWKWARD.len() as u32) as usize]
        } else {
            lo + (hi - lo) * f64::from(self.below(1025)) / 1024.0
        };
        f.clamp(lo, hi)
    }
}

/// The surfaces an engine case is built from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Shape {
    /// Six bicubic patches on the faces of a cube.
    CubePatches,
    /// Four bicubic patches around an axis, each with both ends collapsed to a pole (the
    /// teapot lid's degenerate rows).
    Spindle,
    /// Nine bicubic patches on a 3 × 3 torus.
    Torus,
    /// An octahedron of PN triangles.
    Octahedron,
    /// A cube of PN triangles, each face split along a chosen diagonal.
    CubeMesh,
    /// A tetrahedron of PN triangles.
    Tetrahedron,
    /// 1 to 8 bicubic patches indexing a pool of up to 16 grid points: any topology.
    RandomPatches,
    /// 1 to 12 triangles indexing a pool of up to 10 grid points: any topology.
    RandomMesh,
}

impl Shape {
    pub(super) const ALL: [Shape; 8] = [
        Shape::CubePatches,
        Shape::Spindle,
        Shape::Torus,
        Shape::Octahedron,
        Shape::CubeMesh,
        Shape::Tetrahedron,
        Shape::RandomPatches,
        Shape::RandomMesh,
    ];

    /// Closed and consistently oriented by construction, with every patch corner distinct
    /// from its neighbours' other corners: the shapes whose output must be watertight. The
    /// random shapes are not held to it, because after welding output positions by bits,
    /// two patches with the same corners (or coincident sheets) legitimately share
    /// triangles at low factors; they are checked for panics and consistency only.
    pub(super) fn is_watertight_by_construction(self) -> bool {
        !matches!(self, Shape::RandomPatches | Shape::RandomMesh)
    }
}

/// A lattice coordinate moved by up to ±1 (lattice points are 4 apart, so moved points never
/// meet).
fn jitter(d: &mut Decisions, v: i32) -> i32 {
    v + d.int_in(-1, 1)
}

/// Control points in the Newell format, with a weight column when `rational`.
fn newell(patches: &[[usize; 16]], points: &[[i32; 3]], weights: Option<&[i32]>) -> String {
    let mut text = format!("{}\n", patches.len());
    for p in patches {
        let indices: Vec<String> = p.iter().map(|i| (i + 1).to_string()).collect();
        text += &indices.join(",");
        text.push('\n');
    }
    let _ = writeln!(text, "{}", points.len());
    for (k, p) in points.iter().enumerate() {
        match weights {
            Some(w) => _ = writeln!(text, "{},{},{},{}", p[0], p[1], p[2], w[k]),
            None => _ = writeln!(text, "{},{},{}", p[0], p[1], p[2]),
        }
    }
    text
}

/// Weights 1 to 3 per point for about a third of the cases (rational patches), else none.
fn weights(d: &mut Decisions, count: usize) -> Option<Vec<i32>> {
    d.one_in(3).then(|| (0..count).map(|_| d.int_in(1, 3)).collect())
}

/// Indexes points by a key, adding each new key's point once, so patches that name the same
/// key share the control point (and their boundary curves by index).
struct PointPool<K> {
    ids: HashMap<K, usize>,
    points: Vec<[i32; 3]>,
}

impl<K: std::hash::Hash + Eq> PointPool<K> {
    fn new() -> Self {
        PointPool { ids: HashMap::new(), points: Vec::new() }
    }

    fn id(&mut self, key: K, point: impl FnOnce() -> [i32; 3]) -> usize {
        let next = self.points.len();
        *self.ids.entry(key).or_insert_with(|| {
            self.points.push(point());
            next
        })
    }
}

fn drop_patch(patches: &mut Vec<[usize; 16]>, dropped: Option<usize>) {
    if let Some(k) = dropped {
        patches.remove(k % patches.len());
    }
}

/// Six patches on the faces of the cube `[-6, 6]³`: face `P[i][j]` on the 4 × 4 lattice of
/// its face, oriented outward; inner points bulge out by up to 3 or in by 1 (never far enough
/// to meet another face's points).
pub(super) fn cube_patches(d: &mut Decisions, dropped: Option<usize>) -> String {
    let mut pool = PointPool::new();
    let mut patches = Vec::new();
    for axis in 0..3usize {
        for side in [0i32, 3] {
            let outward = if side == 0 { -1 } else { 1 };
            let bulge = d.int_in(-1, 3) * outward;
            let mut patch = [0; 16];
            for i in 0..4i32 {
                for j in 0..4i32 {
                    // The cyclic axes after `axis` make `e1 × e2` point along +axis, so rows
                    // run along e1 on the far side and along e2 on the near side.
                    let (a, b) = if side == 3 { (i, j) } else { (j, i) };
                    let mut lattice = [0i32; 3];
                    lattice[axis] = side;
                    lattice[(axis + 1) % 3] = a;
                    lattice[(axis + 2) % 3] = b;
                    let inner = (1..3).contains(&i) && (1..3).contains(&j);
                    // Boundary points are shared with the neighbouring faces; inner ones not.
                    let key = (lattice, if inner { axis as i32 } else { -1 });
                    patch[(4 * i + j) as usize] = pool.id(key, || {
                        let mut p = lattice.map(|c| jitter(d, 4 * c - 6));
                        if inner {
                            p[axis] += bulge;
                        }
                        p
                    });
                }
            }
            patches.push(patch);
        }
    }
    drop_patch(&mut patches, dropped);
    let w = weights(d, pool.points.len());
    newell(&patches, &pool.points, w.as_deref())
}

/// Four patches around the z axis: row 0 of every patch is the south pole, row 3 the north
/// pole (collapsed edges), rows 1 and 2 walk one side of two square rings.
pub(super) fn spindle(d: &mut Decisions, dropped: Option<usize>) -> String {
    // The 12 points on the boundary of the square [-6, 6]², 4 apart, counter-clockwise.
    let ring: Vec<[i32; 2]> = (0..12)
        .map(|m| {
            let (side, t) = (m / 3, m % 3);
            let s = -6 + 4 * t;
            match side {
                0 => [s, -6],
                1 => [6, s],
                2 => [-s, 6],
                _ => [-6, -s],
            }
        })
        .collect();
    let mut points = Vec::new();
    points.push([jitter(d, 0), jitter(d, 0), -12 + d.int_in(-2, 2)]);
    points.push([jitter(d, 0), jitter(d, 0), 12 + d.int_in(-2, 2)]);
    for z in [-4, 4] {
        let scale = d.int_in(1, 2);
        for p in &ring {
            points.push([jitter(d, scale * p[0]), jitter(d, scale * p[1]), jitter(d, z)]);
        }
    }
    let mut patches = Vec::new();
    for k in 0..4 {
        let mut patch = [0; 16];
        for t in 0..4 {
            let m = (3 * k + t) % 12;
            patch[t] = 0;
            patch[4 + t] = 2 + m;
            patch[8 + t] = 14 + m;
            patch[12 + t] = 1;
        }
        patches.push(patch);
    }
    drop_patch(&mut patches, dropped);
    let w = weights(d, points.len());
    newell(&patches, &points, w.as_deref())
}

/// Nine patches on a 3 × 3 torus (tube radius 12 around a circle of radius 32, rounded to
/// integers): a closed surface of genus 1 whose patches each meet four others.
pub(super) fn torus(d: &mut Decisions, dropped: Option<usize>) -> String {
    let mut points = Vec::new();
    for a in 0..9 {
        for b in 0..9 {
            let (theta, phi) =
                (a as f64 * std::f64::consts::TAU / 9.0, b as f64 * std::f64::consts::TAU / 9.0);
            let r = 32.0 + 12.0 * phi.cos();
            let p = [r * theta.cos(), r * theta.sin(), 12.0 * phi.sin()];
            points.push(p.map(|c| jitter(d, c.round() as i32)));
        }
    }
    let mut patches = Vec::new();
    for pa in 0..3 {
        for pb in 0..3 {
            let mut patch = [0; 16];
            for i in 0..4 {
                for j in 0..4 {
                    patch[4 * i + j] = ((3 * pa + i) % 9) * 9 + (3 * pb + j) % 9;
                }
            }
            patches.push(patch);
        }
    }
    drop_patch(&mut patches, dropped);
    let w = weights(d, points.len());
    newell(&patches, &points, w.as_deref())
}

/// A closed triangle mesh on jittered integer vertices, counter-clockwise outward, as OBJ:
/// without normals, with one normal per vertex, or with one per face corner (split normals
/// and creases). Normals are small integer vectors, zero allowed.
pub(super) fn closed_mesh(d: &mut Decisions, shape: Shape, dropped: Option<usize>) -> String {
    let (corners, mut faces): (Vec<[i32; 3]>, Vec<[usize; 3]>) = match shape {
        Shape::Octahedron => (
            vec![[6, 0, 0], [-6, 0, 0], [0, 6, 0], [0, -6, 0], [0, 0, 6], [0, 0, -6]],
            vec![[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]],
        ),
        Shape::Tetrahedron => (
            vec![[6, 6, 6], [6, -6, -6], [-6, 6, -6], [-6, -6, 6]],
            vec![[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]],
        ),
        _ => {
            let corners = (0..8).map(|k| [k & 1, (k >> 1) & 1, (k >> 2) & 1].map(|c| 12 * c - 6)).collect();
            // Each face counter-clockwise seen from outside.
            let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
            let mut faces = Vec::new();
            for q in quads {
                if d.one_in(2) {
                    faces.extend([[q[0], q[1], q[2]], [q[0], q[2], q[3]]]);
                } else {
                    faces.extend([[q[0], q[1], q[3]], [q[1], q[2], q[3]]]);
                }
            }
            (corners, faces)
        }
    };
    if let Some(k) = dropped {
        faces.remove(k % faces.len());
    }
    let mut text = String::new();
    for c in &corners {
        let p = c.map(|v| v + d.int_in(-2, 2));
        let _ = writeln!(text, "v {} {} {}", p[0], p[1], p[2]);
    }
    let normal_mode = d.below(3);
    let normal_count = match normal_mode {
        0 => 0,
        1 => corners.len(),
        _ => 4,
    };
    for _ in 0..normal_count {
        let _ = writeln!(text, "vn {} {} {}", d.int_in(-2, 2), d.int_in(-2, 2), d.int_in(-2, 2));
    }
    for f in &faces {
        text += "f";
        for &v in f {
            match normal_mode {
                0 => _ = write!(text, " {}", v + 1),
                1 => _ = write!(text, " {}//{}", v + 1, v + 1),
                _ => _ = write!(text, " {}//{}", v + 1, d.below(4) + 1),
            }
        }
        text.push('\n');
    }
    text
}

/// 1 to 8 patches, each of whose 16 control points is any of a pool of 1 to 16 points on the
/// grid `[-2, 2]³`: collapsed, repeated, non-manifold and self-sharing patches.
pub(super) fn random_patches(d: &mut Decisions) -> String {
    let pool: Vec<[i32; 3]> = (0..1 + d.below(16)).map(|_| [0; 3].map(|_| d.int_in(-2, 2))).collect();
    let patches: Vec<[usize; 16]> =
        (0..1 + d.below(8)).map(|_| [0; 16].map(|_| d.below(pool.len() as u32) as usize)).collect();
    let w = weights(d, pool.len());
    newell(&patches, &pool, w.as_deref())
}

/// 1 to 12 triangles over a pool of 3 to 10 points on the grid `[-2, 2]³`.
pub(super) fn random_mesh(d: &mut Decisions) -> String {
    let count = 3 + d.below(8);
    let mut text = String::new();
    for _ in 0..count {
        let _ = writeln!(text, "v {} {} {}", d.int_in(-2, 2), d.int_in(-2, 2), d.int_in(-2, 2));
    }
    for _ in 0..1 + d.below(12) {
        let _ = writeln!(text, "f {} {} {}", d.below(count) + 1, d.below(count) + 1, d.below(count) + 1);
    }
    text
}

/// True for the shapes generated as OBJ triangle meshes (PN triangles), false for patches.
pub(super) fn is_mesh_shape(shape: Shape) -> bool {
    matches!(shape, Shape::Octahedron | Shape::CubeMesh | Shape::Tetrahedron | Shape::RandomMesh)
}
