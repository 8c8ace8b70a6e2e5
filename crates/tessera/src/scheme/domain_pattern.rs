//! One scheme's pattern on one bare domain, for given edge and inside factors: every point,
//! every triangle and the region (ring, band or strip) that made each triangle. What
//! `tessera pattern` draws and the Python package's `tessera.pattern` returns; no surface is
//! evaluated.
//!
//! Factors come in the conventions of the Direct3D 11 reference tessellator, so that a
//! pattern can be compared with the hardware's: edge factors in Direct3D's order (quad
//! `U==0, V==0, U==1, V==1`; tri `U==0, V==0, W==0`), inside factors quad `U, V` or tri one
//! (default: Direct3D's max reduction of the edge factors).
//!
//! ```
//! use tessera::scheme::domain_pattern::{build, PatternRequest};
//! use tessera::scheme::Scheme;
//! use tessera::surface::Domain;
//!
//! let p = build(&PatternRequest::new(Scheme::Transition, Domain::Quad, &[5.0, 4.0, 7.0, 3.0]))?;
//! assert_eq!(p.points.len(), 37);
//! assert!(p.triangles.len() > 0);
//! # Ok::<(), tessera::Error>(())
//! ```

use super::Scheme;
use crate::domain::Domain;
use crate::error::{Error, Result};
use crate::mesh::strips::{decode, RESTART};
use crate::pattern::esc::{Esc, PatchGrid, MAX_LEVEL as ESC_MAX_LEVEL};
use crate::pattern::hardware::{self, d3d_edge};
use crate::pattern::sd2::Sd2;
use crate::pattern::semi_uniform::SemiUniform;
use crate::pattern::transition::Transition;
use crate::pattern::uniform::Uniform;
use crate::pattern::{LocalTessellation, Pattern, PatternInput};

/// The largest factor a domain pattern is built for (the hardware's top; larger patterns are
/// no longer readable as pictures).
pub const MAX_PATTERN_FACTOR: f64 = 64.0;

/// What to build: a scheme's pattern on a domain for given factors.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PatternRequest<'a> {
    pub scheme: Scheme,
    pub domain: Domain,
    /// Edge factors in Direct3D's order (see the module documentation): integers for uniform
    /// and transition, powers of two for semi-uniform, reals for SD-2 and the hardware
    /// schemes (pow2 as the hardware takes them, rounded up to integers). Not used by ESC.
    pub edges: &'a [f64],
    /// Inside factors (quad two, tri one); empty: Direct3D's max reduction of `edges`.
    /// Hardware schemes take them as the hardware does, transition as its core factors.
    pub inside: &'a [f64],
    /// ESC: the level `L`, 0 to 6 (`L + 1` segments per coarse edge; 0 is the 18 coarse
    /// triangles).
    pub level: u32,
    /// ESC: the insertion mask, `0`s and `1`s applied in turn to the candidates on the coarse
    /// edges (lattice points in rows of increasing v, then u), repeated as needed; rows are
    /// then filled by the paper's row rule. `"1"` inserts every candidate.
    pub mask: &'a str,
}

impl<'a> PatternRequest<'a> {
    /// A request with the default inside factors, ESC level 2 and mask `"10"`.
    pub fn new(scheme: Scheme, domain: Domain, edges: &'a [f64]) -> Self {
        PatternRequest { scheme, domain, edges, inside: &[], level: 2, mask: "10" }
    }
}

/// A pattern laid out on its domain.
#[derive(Debug, Clone, PartialEq)]
pub struct DomainPattern {
    pub domain: Domain,
    /// `(u, v)` of every point.
    pub points: Vec<[f64; 2]>,
    /// Point indices, counter-clockwise in `(u, v)`.
    pub triangles: Vec<[u32; 3]>,
    /// The region of each triangle: the hardware's ring, the transition pattern's boundary
    /// band (1) against its core (0), or the strip of a strip-making pattern.
    pub regions: Vec<u32>,
    /// What made the regions: `"ring"`, `"boundary band"` or `"strip"`.
    pub region_kind: &'static str,
    /// The edge factors used, Direct3D's order (ESC: its edges' segment counts).
    pub edge_factors: Vec<f64>,
    /// The inside factors used.
    pub inside_factors: Vec<f64>,
}

fn invalid(reason: String) -> Error {
    Error::InvalidParameter { name: "pattern", reason }
}

/// The domain's name in messages.
pub fn domain_name(domain: Domain) -> &'static str {
    match domain {
        Domain::Tri => "triangle",
        Domain::Quad => "quad",
    }
}

/// Checks the factor lists against the domain and the scheme's needs.
fn check_factors(r: &PatternRequest<'_>) -> Result<()> {
    let domain = r.domain;
    let n = domain.corner_count();
    let esc = matches!(r.scheme, Scheme::Esc { .. });
    if !esc && r.edges.len() != n {
        return Err(invalid(format!(
            "edges: a {} needs {n} edge factors (Direct3D's order: {}), got {}",
            domain_name(domain),
            if n == 4 { "U==0,V==0,U==1,V==1" } else { "U==0,V==0,W==0" },
            r.edges.len()
        )));
    }
    let inside_n = if domain == Domain::Quad { 2 } else { 1 };
    if !r.inside.is_empty() && r.inside.len() != inside_n {
        return Err(invalid(format!(
            "inside: a {} takes {inside_n} inside factor(s), got {}",
            domain_name(domain),
            r.inside.len()
        )));
    }
    let hardware = matches!(r.scheme, Scheme::Hardware(_));
    for &f in r.edges.iter().chain(r.inside) {
        // The hardware takes any positive factor and clamps it; the others need at least 1.
        let lo_ok = if hardware { f > 0.0 } else { f >= 1.0 };
        if !(f.is_finite() && lo_ok && f <= MAX_PATTERN_FACTOR) {
            return Err(invalid(format!(
                "factor {f}: use a number {} to {MAX_PATTERN_FACTOR}",
                if hardware {
                    "above 0 (the hardware culls a patch with a factor ≤ 0) and up"
                } else {
                    "from 1"
                }
            )));
        }
    }
    Ok(())
}

/// Direct3D's max reduction: quad inside-u from the edges along u (`V==0`, `V==1`), inside-v
/// from `U==0`, `U==1`; tri the largest edge factor.
fn max_reduction(domain: Domain, edges: &[f64]) -> Vec<f64> {
    match domain {
        Domain::Quad => vec![edges[1].max(edges[3]), edges[0].max(edges[2])],
        Domain::Tri => vec![edges.iter().copied().fold(1.0, f64::max)],
    }
}

/// An integer factor, or an error naming the scheme.
fn integer(f: f64, scheme: &str) -> Result<u32> {
    if f.fract() != 0.0 {
        return Err(invalid(format!("factor {f}: the {scheme} scheme takes integer factors")));
    }
    Ok(f as u32)
}

/// Builds the pattern `r` asks for.
///
/// Errors: [`Error::InvalidParameter`] (name `pattern`) for factor lists that do not fit the
/// domain or the scheme (a uniform pattern with different factors, semi-uniform factors that
/// are not powers of two, SD-2 on a quad, ESC on a triangle, a factor outside 1–64 or, for the
/// hardware, ≤ 0). Cost: linear in the pattern.
pub fn build(r: &PatternRequest<'_>) -> Result<DomainPattern> {
    let domain = r.domain;
    check_factors(r)?;
    let esc = matches!(r.scheme, Scheme::Esc { .. });
    let inside = if r.inside.is_empty() && !esc { max_reduction(domain, r.edges) } else { r.inside.to_vec() };
    if let Scheme::Hardware(p) = r.scheme {
        let mut edges = [0.0f32; 4];
        for (k, &f) in r.edges.iter().enumerate() {
            edges[k] = f as f32;
        }
        let ins = [inside[0] as f32, *inside.get(1).unwrap_or(&inside[0]) as f32];
        let hw = hardware::tessellate(domain, p, edges, ins)
            .ok_or_else(|| invalid("the hardware culls a patch with a factor ≤ 0".into()))?;
        return Ok(DomainPattern {
            domain,
            points: hw.points.iter().map(|q| [q.x, q.y]).collect(),
            triangles: hw.triangles,
            regions: hw.regions,
            region_kind: "ring",
            edge_factors: r.edges.to_vec(),
            inside_factors: inside,
        });
    }
    // Tessera's patterns: edge e of tessera's numbering is Direct3D edge d3d_edge(e).
    let nc = domain.corner_count();
    let edge = |e: usize| r.edges[d3d_edge(domain, e)];
    let scheme = r.scheme.name();
    let mut out = LocalTessellation::default();
    let mut strips = Vec::new();
    let (input, params, has_strips): (PatternInput, Vec<Vec<f64>>, bool) = match r.scheme {
        Scheme::Uniform | Scheme::Transition | Scheme::SemiUniform { .. } => {
            let mut segments = [1u32; 4];
            for (e, s) in segments.iter_mut().enumerate().take(nc) {
                *s = integer(edge(e), scheme)?;
            }
            let top = segments[..nc].iter().copied().max().unwrap_or(1);
            let interior = match r.scheme {
                Scheme::Uniform => {
                    if segments[..nc].iter().any(|&s| s != top) || inside.iter().any(|&f| f != top as f64) {
                        return Err(invalid(
                            "the uniform scheme takes one factor on every edge and inside: use the \
                             transition scheme for different factors"
                                .into(),
                        ));
                    }
                    [top, top]
                }
                Scheme::SemiUniform { .. } => {
                    if segments[..nc].iter().any(|s| !s.is_power_of_two()) {
                        return Err(invalid(
                            "the semi-uniform scheme takes powers of two (1, 2, 4, …) as edge factors".into(),
                        ));
                    }
                    // The paper's pattern P^m of the patch level m = max edge level.
                    [top, top]
                }
                _ => {
                    let i0 = integer(inside[0], scheme)?;
                    [i0, integer(*inside.get(1).unwrap_or(&inside[0]), scheme)?]
                }
            };
            let input = PatternInput::new(domain, segments, interior);
            let params =
                (0..nc).map(|e| (0..=segments[e]).map(|k| k as f64 / segments[e] as f64).collect()).collect();
            let pattern: &dyn Pattern = match r.scheme {
                Scheme::Uniform => &Uniform,
                Scheme::SemiUniform { .. } => &SemiUniform,
                _ => &Transition,
            };
            pattern.build(&input, &mut out);
            (input, params, false)
        }
        Scheme::Sd2 { .. } => {
            if domain != Domain::Tri {
                return Err(invalid("the sd2 scheme is defined on triangles: use the tri domain".into()));
            }
            let mut factors = [1.0; 4];
            for (e, f) in factors.iter_mut().enumerate().take(nc) {
                *f = edge(e);
            }
            let input = PatternInput {
                domain,
                segments: factors.map(crate::sampling::symmetric_segments),
                interior: [1, 1],
                factors,
                patch: 0,
                collapsed: [false; 4],
                pinched: [false; 4],
            };
            let params = (0..nc)
                .map(|e| {
                    (0..=input.segments[e]).map(|k| crate::sampling::symmetric_param(factors[e], k)).collect()
                })
                .collect();
            let pattern = Sd2 { corner_depths: None };
            pattern.build(&input, &mut out);
            let has = pattern.strips(&input, &mut strips);
            (input, params, has)
        }
        Scheme::Esc { .. } => {
            if domain != Domain::Quad {
                return Err(invalid(
                    "the esc scheme is defined on bicubic (quad) patches: use the quad domain".into(),
                ));
            }
            // Level 0 is the 18 coarse triangles alone, as `tessera mesh --level 0` draws them.
            if r.level > ESC_MAX_LEVEL {
                return Err(invalid(format!("level {}: use 0 to {ESC_MAX_LEVEL}", r.level)));
            }
            if r.mask.is_empty() || !r.mask.chars().all(|c| c == '0' || c == '1') {
                return Err(invalid(format!("mask {:?}: use a string of 0s and 1s", r.mask)));
            }
            let grid = esc_grid(r.level + 1, r.mask.as_bytes());
            let side = grid.side() as f64;
            let mut segments = [1u32; 4];
            let mut params = Vec::new();
            for (e, s) in segments.iter_mut().enumerate() {
                let pts = grid.edge_points(e);
                *s = pts.len() as u32 + 1;
                // Position along edge e in the patch's direction (corner e → e + 1).
                let t = |(i, j): (u32, u32)| match e {
                    0 => i as f64 / side,
                    1 => j as f64 / side,
                    2 => 1.0 - i as f64 / side,
                    _ => 1.0 - j as f64 / side,
                };
                let mut p = vec![0.0];
                p.extend(pts.into_iter().map(t));
                p.push(1.0);
                params.push(p);
            }
            let input = PatternInput::new(domain, segments, [1, 1]);
            let pattern = Esc::new(vec![grid]);
            pattern.build(&input, &mut out);
            let has = pattern.strips(&input, &mut strips);
            (input, params, has)
        }
        Scheme::Hardware(_) => unreachable!("hardware schemes are handled above"),
    };
    let points = input
        .local_positions(&out.interior, |e, k| params[e][k as usize])
        .iter()
        .map(|p| [p.x, p.y])
        .collect();
    let (regions, region_kind) = if has_strips {
        (strip_regions(&strips), "strip")
    } else {
        // The band next to the boundary (what a transition pattern adapts) against the core.
        let boundary = input.interior_base();
        (out.triangles.iter().map(|t| u32::from(t.iter().any(|&v| v < boundary))).collect(), "boundary band")
    };
    let edge_factors = if esc {
        // Direct3D's edge order of tessera's edges' segment counts.
        let mut f = vec![0.0; nc];
        for e in 0..nc {
            f[d3d_edge(domain, e)] = input.segments[e] as f64;
        }
        f
    } else {
        r.edges.to_vec()
    };
    Ok(DomainPattern {
        domain,
        points,
        triangles: out.triangles,
        regions,
        region_kind,
        edge_factors,
        inside_factors: inside,
    })
}

/// An ESC grid with `n` segments per coarse edge and the coarse-edge candidates inserted by
/// `mask` in turn (rows of increasing J, then I), rows filled by the row rule.
fn esc_grid(n: u32, mask: &[u8]) -> PatchGrid {
    let mut grid = PatchGrid::coarse(n);
    let side = grid.side();
    let mut next = 0usize;
    for j in 0..=side {
        for i in 0..=side {
            let coarse_vertex = i % n == 0 && j % n == 0;
            // Cell lines and the cell diagonals (from (ci·n, cj·n) to ((ci+1)·n, (cj+1)·n)).
            let on_coarse_edge = i % n == 0 || j % n == 0 || (i % n == j % n && i / n < 3 && j / n < 3);
            if on_coarse_edge && !coarse_vertex {
                grid.set(i, j, mask[next % mask.len()] == b'1');
                next += 1;
            }
        }
    }
    grid.insert_rows();
    grid
}

/// The strip each decoded triangle comes from.
fn strip_regions(strips: &[u32]) -> Vec<u32> {
    strips
        .split(|&v| v == RESTART)
        .filter(|s| !s.is_empty())
        .enumerate()
        .flat_map(|(k, s)| std::iter::repeat_n(k as u32, decode(s).len()))
        .collect()
}
