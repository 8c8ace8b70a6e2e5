//! `tessera pattern`: the domain pattern of any scheme for given factors, as an SVG picture or
//! as JSON in the conventions of the Direct3D 11 reference file
//! (`../shared/data/reference/d3d11_tessellator.json`): points as `[u, v]`, triangles as index
//! triples in Direct3D's `triangle_ccw` order (negative signed area in the `(u, v)` plane),
//! edge factors in Direct3D's order (quad `U==0, V==0, U==1, V==1`; tri `U==0, V==0, W==0`).

use crate::plan::SchemeArg;
use clap::{Args, ValueEnum};
use std::fmt::Write as _;
use std::path::PathBuf;
use tessera::mesh::strips::{decode, RESTART};
use tessera::pattern::esc::{Esc, PatchGrid, MAX_LEVEL as ESC_MAX_LEVEL};
use tessera::pattern::hardware::{self, d3d_edge, Partitioning};
use tessera::pattern::sd2::Sd2;
use tessera::pattern::semi_uniform::SemiUniform;
use tessera::pattern::transition::Transition;
use tessera::pattern::uniform::Uniform;
use tessera::pattern::{LocalTessellation, Pattern, PatternInput};
use tessera::scheme::Scheme;
use tessera::surface::Domain;

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum DomainArg {
    Tri,
    Quad,
}

#[derive(Args)]
pub struct PatternArgs {
    /// The scheme whose pattern to draw.
    #[arg(long, value_enum)]
    scheme: SchemeArg,
    /// The domain: a triangle (u, v ≥ 0, u + v ≤ 1; w = 1 − u − v) or the unit square.
    #[arg(long, value_enum)]
    domain: DomainArg,
    /// Edge factors in Direct3D's order: quad U==0,V==0,U==1,V==1 (the edges u = 0, v = 0,
    /// u = 1, v = 1); tri U==0,V==0,W==0. Integers for uniform and transition, powers of two
    /// for semi-uniform, real factors for sd2 and the hardware schemes (pow2 as the hardware
    /// takes them: rounded up to integers; rounding to powers of two is the hull shader's
    /// part, which `tessera mesh` does). Not used by esc.
    #[arg(long, value_name = "F0,F1,F2[,F3]", value_delimiter = ',')]
    edges: Vec<f64>,
    /// Inside factors: quad U,V; tri one. Hardware schemes take them as the hardware does;
    /// transition as its core factors. Default: Direct3D's max reduction of the edge factors.
    #[arg(long, value_name = "I0[,I1]", value_delimiter = ',')]
    inside: Vec<f64>,
    /// esc: the level L, 0 to 6 (L + 1 segments per coarse edge; 0: the 18 coarse triangles).
    #[arg(long, value_name = "L", default_value_t = 2)]
    level: u32,
    /// esc: the insertion mask, a string of 0s and 1s applied in turn to the candidates on the
    /// coarse edges (lattice points in rows of increasing v, then u), repeated as needed;
    /// rows are then filled by the paper's row rule. "1" inserts every candidate.
    #[arg(long, value_name = "BITS", default_value = "10")]
    mask: String,
    /// Output: .svg (a picture: triangles coloured by the ring or strip that made them) or
    /// .json.
    #[arg(short, long, value_name = "OUT")]
    output: PathBuf,
}

/// A pattern laid out for drawing: every point, every triangle (counter-clockwise in
/// `(u, v)`), and the region (ring, band or strip) of each triangle.
pub struct DomainPattern {
    pub domain: Domain,
    pub points: Vec<[f64; 2]>,
    pub triangles: Vec<[u32; 3]>,
    pub regions: Vec<u32>,
    /// What made the regions, for the picture's legend.
    pub region_kind: &'static str,
    pub edge_factors: Vec<f64>,
    pub inside_factors: Vec<f64>,
}

type CmdResult<T> = Result<T, Box<dyn std::error::Error>>;

fn domain_of(d: DomainArg) -> Domain {
    match d {
        DomainArg::Tri => Domain::Tri,
        DomainArg::Quad => Domain::Quad,
    }
}

/// The largest factor `tessera pattern` draws (the hardware's top; larger patterns are no
/// longer readable as pictures).
const MAX_PATTERN_FACTOR: f64 = 64.0;

/// Checks the factor lists against the domain and the scheme's needs.
fn check_factors(a: &PatternArgs, domain: Domain) -> CmdResult<()> {
    let n = domain.corner_count();
    if a.scheme != SchemeArg::Esc && a.edges.len() != n {
        return Err(format!(
            "--edges: a {} needs {n} edge factors (Direct3D's order: {}), got {}",
            if n == 4 { "quad" } else { "triangle" },
            if n == 4 { "U==0,V==0,U==1,V==1" } else { "U==0,V==0,W==0" },
            a.edges.len()
        )
        .into());
    }
    let inside_n = if domain == Domain::Quad { 2 } else { 1 };
    if !a.inside.is_empty() && a.inside.len() != inside_n {
        return Err(format!(
            "--inside: a {} takes {inside_n} inside factor(s), got {}",
            name(domain),
            a.inside.len()
        )
        .into());
    }
    for &f in a.edges.iter().chain(&a.inside) {
        let hardware = partitioning(a.scheme).is_some();
        // The hardware takes any positive factor and clamps it; the others need at least 1.
        let lo_ok = if hardware { f > 0.0 } else { f >= 1.0 };
        if !(f.is_finite() && lo_ok && f <= MAX_PATTERN_FACTOR) {
            return Err(format!(
                "factor {f}: use a number {} to {MAX_PATTERN_FACTOR}",
                if hardware {
                    "above 0 (the hardware culls a patch with a factor ≤ 0) and up"
                } else {
                    "from 1"
                }
            )
            .into());
        }
    }
    Ok(())
}

fn name(domain: Domain) -> &'static str {
    match domain {
        Domain::Tri => "triangle",
        Domain::Quad => "quad",
    }
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
fn integer(f: f64, scheme: &str) -> CmdResult<u32> {
    if f.fract() != 0.0 {
        return Err(format!("factor {f}: --scheme {scheme} takes integer factors").into());
    }
    Ok(f as u32)
}

/// Builds the pattern of `a`. Cost: linear in the pattern.
pub fn build(a: &PatternArgs) -> CmdResult<DomainPattern> {
    let domain = domain_of(a.domain);
    check_factors(a, domain)?;
    let inside = if a.inside.is_empty() && a.scheme != SchemeArg::Esc {
        max_reduction(domain, &a.edges)
    } else {
        a.inside.clone()
    };
    if let Some(p) = partitioning(a.scheme) {
        return Ok(hardware_pattern(a, domain, p, inside));
    }
    // Tessera's patterns: edge e of tessera's numbering is Direct3D edge d3d_edge(e).
    let nc = domain.corner_count();
    let edge = |e: usize| a.edges[d3d_edge(domain, e)];
    let scheme = a.scheme.name();
    let mut out = LocalTessellation::default();
    let mut strips = Vec::new();
    let (input, params, has_strips): (PatternInput, Vec<Vec<f64>>, bool) = match a.scheme {
        SchemeArg::Uniform | SchemeArg::Transition | SchemeArg::SemiUniform => {
            let mut segments = [1u32; 4];
            for (e, s) in segments.iter_mut().enumerate().take(nc) {
                *s = integer(edge(e), scheme)?;
            }
            let top = segments[..nc].iter().copied().max().unwrap_or(1);
            let interior = match a.scheme {
                SchemeArg::Uniform => {
                    if segments[..nc].iter().any(|&s| s != top) || inside.iter().any(|&f| f != top as f64) {
                        return Err("--scheme uniform takes one factor on every edge and inside: use \
                                    --scheme transition for different factors"
                            .into());
                    }
                    [top, top]
                }
                SchemeArg::SemiUniform => {
                    if segments[..nc].iter().any(|s| !s.is_power_of_two()) {
                        return Err(
                            "--scheme semi-uniform takes powers of two (1, 2, 4, …) as edge factors".into()
                        );
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
            let pattern: &dyn Pattern = match a.scheme {
                SchemeArg::Uniform => &Uniform,
                SchemeArg::SemiUniform => &SemiUniform,
                _ => &Transition,
            };
            pattern.build(&input, &mut out);
            (input, params, false)
        }
        SchemeArg::Sd2 => {
            if domain != Domain::Tri {
                return Err("--scheme sd2 is defined on triangles: use --domain tri".into());
            }
            let mut factors = [1.0; 4];
            for (e, f) in factors.iter_mut().enumerate().take(nc) {
                *f = edge(e);
            }
            let input = PatternInput {
                domain,
                segments: factors.map(tessera::sampling::symmetric_segments),
                interior: [1, 1],
                factors,
                patch: 0,
                collapsed: [false; 4],
            };
            let params = (0..nc)
                .map(|e| {
                    (0..=input.segments[e])
                        .map(|k| tessera::sampling::symmetric_param(factors[e], k))
                        .collect()
                })
                .collect();
            let pattern = Sd2 { corner_depths: None };
            pattern.build(&input, &mut out);
            let has = pattern.strips(&input, &mut strips);
            (input, params, has)
        }
        SchemeArg::Esc => {
            if domain != Domain::Quad {
                return Err("--scheme esc is defined on bicubic (quad) patches: use --domain quad".into());
            }
            // Level 0 is the 18 coarse triangles alone, as `tessera mesh --level 0` draws them.
            if a.level > ESC_MAX_LEVEL {
                return Err(format!("--level {}: use 0 to {ESC_MAX_LEVEL}", a.level).into());
            }
            if a.mask.is_empty() || !a.mask.chars().all(|c| c == '0' || c == '1') {
                return Err(format!("--mask {:?}: use a string of 0s and 1s", a.mask).into());
            }
            let grid = esc_grid(a.level + 1, a.mask.as_bytes());
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
        _ => unreachable!("hardware schemes are handled above"),
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
    let edge_factors = if a.scheme == SchemeArg::Esc {
        // Direct3D's edge order of tessera's edges' segment counts.
        let mut f = vec![0.0; nc];
        for e in 0..nc {
            f[d3d_edge(domain, e)] = input.segments[e] as f64;
        }
        f
    } else {
        a.edges.clone()
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

/// The hardware tessellator's own output, in its own point order.
fn hardware_pattern(a: &PatternArgs, domain: Domain, p: Partitioning, inside: Vec<f64>) -> DomainPattern {
    let mut edges = [0.0f32; 4];
    for (k, &f) in a.edges.iter().enumerate() {
        edges[k] = f as f32;
    }
    let ins = [inside[0] as f32, *inside.get(1).unwrap_or(&inside[0]) as f32];
    let hw = hardware::tessellate(domain, p, edges, ins).expect("factors were checked positive");
    DomainPattern {
        domain,
        points: hw.points.iter().map(|q| [q.x, q.y]).collect(),
        triangles: hw.triangles,
        regions: hw.regions,
        region_kind: "ring",
        edge_factors: a.edges.clone(),
        inside_factors: inside,
    }
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

/// The JSON form: the reference file's case layout.
pub fn to_json(a: &PatternArgs, p: &DomainPattern) -> serde_json::Value {
    let mut case = serde_json::json!({
        "scheme": a.scheme.name(),
        "domain": match p.domain { Domain::Tri => "tri", Domain::Quad => "quad" },
        "edge_factors": p.edge_factors,
        "inside_factors": p.inside_factors,
        "points": p.points,
        // Direct3D's triangle_ccw: the reverse of tessera's counter-clockwise order.
        "triangles": p.triangles.iter().map(|t| [t[0], t[2], t[1]]).collect::<Vec<_>>(),
        "regions": p.regions,
    });
    if let Some(part) = partitioning(a.scheme) {
        let name = match part {
            Partitioning::Integer => "integer",
            Partitioning::Pow2 => "pow2",
            Partitioning::FractionalOdd => "odd",
            Partitioning::FractionalEven => "even",
        };
        case["partitioning"] = name.into();
    }
    case
}

/// The SVG form: the domain drawn with v up, triangles filled by region, edges and points on
/// top, and a caption with the scheme, factors and counts.
pub fn to_svg(a: &PatternArgs, p: &DomainPattern) -> String {
    const SIZE: f64 = 640.0;
    const MARGIN: f64 = 24.0;
    const CAPTION: f64 = 56.0;
    // Caption lines start just below the domain.
    let scale = SIZE - 2.0 * MARGIN;
    let xy = |q: [f64; 2]| (MARGIN + q[0] * scale, MARGIN + (1.0 - q[1]) * scale);
    // Colour-blind-safe hues (Okabe–Ito), lightened for fills.
    const PALETTE: [&str; 8] =
        ["#e69f00", "#56b4e9", "#009e73", "#f0e442", "#0072b2", "#d55e00", "#cc79a7", "#999999"];
    let mut s = String::new();
    let height = SIZE + CAPTION;
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{SIZE}" height="{height}" viewBox="0 0 {SIZE} {height}">"#
    );
    let _ = writeln!(s, r##"<rect width="100%" height="100%" fill="#ffffff"/>"##);
    for (t, &r) in p.triangles.iter().zip(&p.regions) {
        let pts: Vec<String> = t
            .iter()
            .map(|&v| {
                let (x, y) = xy(p.points[v as usize]);
                format!("{x:.2},{y:.2}")
            })
            .collect();
        let _ = writeln!(
            s,
            r##"<polygon points="{}" fill="{}" fill-opacity="0.45" stroke="#222222" stroke-width="0.8" stroke-linejoin="round"/>"##,
            pts.join(" "),
            PALETTE[r as usize % PALETTE.len()]
        );
    }
    for &q in &p.points {
        let (x, y) = xy(q);
        let _ = writeln!(s, r##"<circle cx="{x:.2}" cy="{y:.2}" r="2.2" fill="#000000"/>"##);
    }
    let factors = |f: &[f64]| f.iter().map(|x| format!("{x}")).collect::<Vec<_>>().join(", ");
    let scheme = a.scheme.name();
    let order = match p.domain {
        Domain::Quad => "U==0, V==0, U==1, V==1",
        Domain::Tri => "U==0, V==0, W==0",
    };
    let inside = if p.inside_factors.is_empty() {
        String::new()
    } else {
        format!(", inside [{}]", factors(&p.inside_factors))
    };
    let lines = [
        (
            15,
            "#000000",
            format!(
                "{scheme} on a {}: {} points, {} triangles",
                name(p.domain),
                p.points.len(),
                p.triangles.len()
            ),
        ),
        (13, "#222222", format!("edges [{}] ({order}){inside}", factors(&p.edge_factors))),
        (12, "#555555", format!("fill colour = {}; u to the right, v up", p.region_kind)),
    ];
    for (k, (size, colour, text)) in lines.iter().enumerate() {
        let _ = writeln!(
            s,
            r##"<text x="{MARGIN}" y="{:.0}" font-family="sans-serif" font-size="{size}" fill="{colour}">{text}</text>"##,
            SIZE - 4.0 + 20.0 * k as f64
        );
    }
    s.push_str("</svg>\n");
    s
}

/// Runs `tessera pattern`.
pub fn run(a: PatternArgs) -> CmdResult<()> {
    let ext = a.output.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    if !matches!(ext.as_deref(), Some("svg" | "json")) {
        return Err(format!("{}: the output must end in .svg or .json", a.output.display()).into());
    }
    let p = build(&a)?;
    let text = if ext.as_deref() == Some("svg") {
        to_svg(&a, &p)
    } else {
        serde_json::to_string(&to_json(&a, &p))? + "\n"
    };
    std::fs::write(&a.output, text).map_err(|e| format!("{}: {e}", a.output.display()))?;
    eprintln!(
        "{}: {} {} pattern, {} points, {} triangles",
        a.output.display(),
        a.scheme.name(),
        name(p.domain),
        p.points.len(),
        p.triangles.len()
    );
    Ok(())
}

/// The hardware tessellator's partitioning of a scheme, if it is one of the four.
fn partitioning(scheme: SchemeArg) -> Option<tessera::pattern::hardware::Partitioning> {
    match scheme.scheme(None, false) {
        Scheme::Hardware(p) => Some(p),
        _ => None,
    }
}
