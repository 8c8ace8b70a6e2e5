//! `tessera pattern`: the domain pattern of any scheme for given factors, as an SVG picture or
//! as JSON in the conventions of the Direct3D 11 reference file
//! (`../shared/data/reference/d3d11_tessellator.json`): points as `[u, v]`, triangles as index
//! triples in Direct3D's `triangle_ccw` order (negative signed area in the `(u, v)` plane),
//! edge factors in Direct3D's order (quad `U==0, V==0, U==1, V==1`; tri `U==0, V==0, W==0`).

use crate::plan::SchemeArg;
use clap::{Args, ValueEnum};
use std::fmt::Write as _;
use std::path::PathBuf;
use tessera::pattern::hardware::Partitioning;
use tessera::scheme::domain_pattern::{self, domain_name as name, DomainPattern, PatternRequest};
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

type CmdResult<T> = Result<T, Box<dyn std::error::Error>>;

fn domain_of(d: DomainArg) -> Domain {
    match d {
        DomainArg::Tri => Domain::Tri,
        DomainArg::Quad => Domain::Quad,
    }
}

/// Builds the pattern of `a` (the library's [`domain_pattern::build`]; its refusals name the
/// argument). Cost: linear in the pattern.
pub fn build(a: &PatternArgs) -> CmdResult<DomainPattern> {
    let request = PatternRequest {
        scheme: a.scheme.scheme(None, false),
        domain: domain_of(a.domain),
        edges: &a.edges,
        inside: &a.inside,
        level: a.level,
        mask: &a.mask,
    };
    domain_pattern::build(&request).map_err(|e| match e {
        tessera::Error::InvalidParameter { reason, .. } => reason.into(),
        e => e.into(),
    })
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
