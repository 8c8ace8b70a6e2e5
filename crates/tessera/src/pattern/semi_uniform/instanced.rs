//! The static patterns `P^m` of the semi-uniform scheme's instanced form (paper 000, §4) and
//! the snap `φ` as a vertex shader applies it: the pattern side of
//! [`crate::engine::render_queues`], which holds the per-level queues and the reference draw.
//!
//! **Static patterns.** `P^m` holds the `2^m` grid of the domain, triangulated as the
//! uniform pattern does, in grid order. Like the paper's `gl_Vertex.w` (Listing 1), every
//! vertex carries a tag: the edge it lies on (corners and interior points are not snapped,
//! since `σ_p` keeps corners), its parameter `t` along that edge in the patch's direction,
//! and the tie offset: `½` from the midpoint on, `½ − ε` before it, so that
//! `⌊2^p·t + offset⌋ / 2^p` is `σ_p(t)` of equation (1) without a branch.

use super::MAX_LEVEL;
use crate::domain::Domain;
use glam::DVec2;

/// `ε` of the tie offset `½ − ε`. Grid parameters are multiples of `2^-MAX_LEVEL`, so
/// `2^p·t + ½` is either an integer (a tie) or at least `2^-MAX_LEVEL` past one; any smaller
/// `ε` turns ties down and changes nothing else.
const TIE_EPSILON: f32 = 1.0 / (4 << MAX_LEVEL) as f32;

/// One vertex of a static pattern.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PatternVertex {
    /// Domain parameters before snapping.
    pub uv: [f32; 2],
    /// The edge the vertex lies on, or `None` for corners and interior vertices.
    pub edge: Option<u8>,
    /// Parameter along `edge` in the patch's own edge direction (0 when `edge` is `None`).
    pub t: f32,
    /// `½` or `½ − ε`: the tie-breaking offset of the snap.
    pub offset: f32,
}

/// The static pattern `P^m` of one domain: `2^m` segments per side, uniform triangulation.
#[derive(Debug, Clone, PartialEq)]
pub struct StaticPattern {
    pub domain: Domain,
    pub level: u32,
    pub vertices: Vec<PatternVertex>,
    /// Counter-clockwise triangles over `vertices`.
    pub triangles: Vec<[u32; 3]>,
}

impl StaticPattern {
    /// Builds `P^m` for `domain`. Precondition: `m ≤ MAX_LEVEL`. Cost: O(4^m).
    pub fn new(domain: Domain, m: u32) -> StaticPattern {
        assert!(m <= MAX_LEVEL, "static pattern level {m} beyond {MAX_LEVEL}");
        let n = 1u32 << m;
        let tri = domain == Domain::Tri;
        let row = |j: u32| if tri { n - j + 1 } else { n + 1 };
        let mut first = Vec::with_capacity(n as usize + 2);
        let mut vertices = Vec::new();
        for j in 0..=n {
            first.push(vertices.len() as u32);
            for i in 0..row(j) {
                vertices.push(pattern_vertex(domain, n, i, j));
            }
        }
        let id = |i: u32, j: u32| first[j as usize] + i;
        let mut triangles = Vec::new();
        for j in 0..n {
            for i in 0..if tri { n - j } else { n } {
                let (a, b, d) = (id(i, j), id(i + 1, j), id(i, j + 1));
                if tri {
                    triangles.push([a, b, d]);
                    if i + j + 2 <= n {
                        triangles.push([b, id(i + 1, j + 1), d]);
                    }
                } else {
                    let c = id(i + 1, j + 1);
                    triangles.push([a, b, c]);
                    triangles.push([a, c, d]);
                }
            }
        }
        StaticPattern { domain, level: m, vertices, triangles }
    }

    /// The `M + 1` patterns `P^0 … P^M` of a domain. Cost: O(4^M).
    pub fn all(domain: Domain, max_level: u32) -> Vec<StaticPattern> {
        (0..=max_level).map(|m| StaticPattern::new(domain, m)).collect()
    }
}

fn pattern_vertex(domain: Domain, n: u32, i: u32, j: u32) -> PatternVertex {
    let uv = [i as f32 / n as f32, j as f32 / n as f32];
    // Which edge, and the grid index along it in the patch's direction.
    let on_edge = match domain {
        Domain::Tri => match (i, j) {
            _ if (i == 0 || i == n) && j == 0 || (i == 0 && j == n) => None,
            (i, 0) => Some((0, i)),
            (i, j) if i + j == n => Some((1, j)),
            (0, j) => Some((2, n - j)),
            _ => None,
        },
        Domain::Quad => match (i, j) {
            _ if (i == 0 || i == n) && (j == 0 || j == n) => None,
            (i, 0) => Some((0, i)),
            (i, j) if i == n => Some((1, j)),
            (i, j) if j == n => Some((2, n - i)),
            (0, j) => Some((3, n - j)),
            _ => None,
        },
    };
    match on_edge {
        Some((e, k)) => PatternVertex {
            uv,
            edge: Some(e),
            t: k as f32 / n as f32,
            offset: if 2 * k >= n { 0.5 } else { 0.5 - TIE_EPSILON },
        },
        None => PatternVertex { uv, edge: None, t: 0.0, offset: 0.5 },
    }
}

/// `φ` as the vertex shader applies it: the domain point a pattern vertex goes to for a
/// patch whose edges have the given levels. Cost: O(1).
pub fn snap(domain: Domain, v: &PatternVertex, edge_levels: [u8; 4]) -> DVec2 {
    match v.edge {
        None => DVec2::new(v.uv[0] as f64, v.uv[1] as f64),
        Some(e) => {
            let s = (1u32 << edge_levels[e as usize]) as f32;
            let t = (s * v.t + v.offset).floor() / s;
            domain.edge_point(e as usize, t as f64)
        }
    }
}
