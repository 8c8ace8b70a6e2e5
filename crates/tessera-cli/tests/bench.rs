//! `tessera bench --quick`: every suite's tables have their rows, the CSV, JSON and SVG files
//! exist and parse, and the triangle counts are the same on a second run.

mod common;

use common::{data, scratch, tessera, text};
use serde_json::Value;
use std::collections::BTreeMap;
use std::path::Path;

/// Rows every quick run must have, per table: (table, column, values that must appear).
const EXPECTED_ROWS: [(&str, &str, &[&str]); 13] = [
    ("speed_uniform", "model", &["torus_64x32", "teapot", "spot"]),
    ("speed_schemes", "scheme", &["transition"]),
    ("adaptive_ratio", "model", &["teapot", "teacup", "helmet"]),
    (
        "adaptive_equal_error",
        "scheme",
        &["uniform", "transition", "semi-uniform", "sd2", "fractional-odd", "esc"],
    ),
    ("frame_walk", "scene", &["torus grid", "killeroo herd", "teacups"]),
    ("frame_first", "scene", &["torus grid", "killeroo herd", "teacups"]),
    ("frame_gpu", "scene", &["torus grid", "killeroo herd"]),
    (
        "paper000_table1",
        "method",
        &[
            "A/B uniform 2^M, per frame",
            "D semi-uniform, compacted",
            "E–H semi-uniform, instanced (render queues)",
        ],
    ),
    ("paper001_tables12", "method", &["uniform f = 7", "SD-2 1:7, strips", "transition 4:7 (stitching)"]),
    ("paper002_table1", "row", &["input surfaces", "non-adaptive", "adaptive high", "adaptive medium"]),
    ("paper003_table1", "scene", &["teapot", "torus_64x32", "teacups", "torus grid"]),
    ("paper003_table2", "scene", &["elephant", "elephant_refined", "killeroo herd"]),
    (
        "subdivision_bfr",
        "model",
        &["catmark_torus", "catmark_torus_creases0", "catmark_pyramid_creases0", "loop_cube_creases0"],
    ),
];

/// OpenSubdiv's Bfr benchmark, which `scripts/test` builds (as the oracle tests' program).
fn bfr_bench() -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tools/osd-oracle/bfr_bench");
    assert!(
        path.is_file(),
        "{} is not built: install g++ and libosd-dev and run tools/osd-oracle/bfr_bench.sh (scripts/test does)",
        path.display()
    );
    path.to_str().unwrap().to_string()
}

/// Every table of every suite's JSON, by name.
fn tables(out: &Path) -> BTreeMap<String, Value> {
    let mut all = BTreeMap::new();
    for suite in ["speed", "adaptive", "frame", "paper", "subdivision"] {
        let path = out.join(format!("{suite}.json"));
        let json: Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap())
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        assert_eq!(json["suite"], suite);
        assert!(json["machine"]["cores"].as_u64().unwrap() >= 1);
        for t in json["tables"].as_array().unwrap() {
            all.insert(t["name"].as_str().unwrap().to_string(), t.clone());
        }
    }
    all
}

/// Every triangle count of every CPU table and row, keyed by table, row and column: what
/// must not change from run to run. The GPU's rows and tables are left out (the second run
/// is made without them: on lavapipe they are most of a quick run).
fn triangle_counts(tables: &BTreeMap<String, Value>) -> Vec<(String, usize, String, Value)> {
    let mut counts = Vec::new();
    for (name, t) in tables.iter().filter(|(name, _)| !name.contains("gpu")) {
        let gpu_row = |row: &&Value| {
            row.as_object().unwrap().values().any(|v| v.as_str().is_some_and(|s| s.starts_with("gpu")))
        };
        for (i, row) in t["rows"].as_array().unwrap().iter().filter(|r| !gpu_row(r)).enumerate() {
            for (column, value) in row.as_object().unwrap() {
                // Times ("… ms") vary; counts must not.
                if column.contains("triangles") && !column.ends_with(" ms") {
                    counts.push((name.clone(), i, column.clone(), value.clone()));
                }
            }
        }
    }
    counts
}

fn run(dir: &Path, out: &str, extra: &[&str]) -> String {
    let data = data("");
    let bfr = bfr_bench();
    let args = ["bench", "--quick", "--out", out, "--data", data.to_str().unwrap(), "--bfr", &bfr];
    let o = tessera(&[&args[..], extra].concat(), dir);
    assert!(o.status.success(), "bench failed: {}", text(&o.stderr));
    text(&o.stdout)
}

#[test]
fn quick_bench_writes_every_table_and_counts_repeat() {
    let dir = scratch("bench");
    let start = std::time::Instant::now();
    let stdout = run(&dir, "a", &[]);
    println!("first quick run: {:.1} s", start.elapsed().as_secs_f64());
    let out = dir.join("a");
    let first = tables(&out);

    for (name, column, values) in EXPECTED_ROWS {
        let t = first.get(name).unwrap_or_else(|| panic!("table {name} missing"));
        let rows = t["rows"].as_array().unwrap();
        for v in values {
            assert!(rows.iter().any(|r| r[column] == *v), "{name}: no row with {column} = {v}");
        }
        // Printed tables are on stdout with their title.
        if name != "adaptive_equal_error" {
            assert!(stdout.contains(&format!("### {}", t["title"].as_str().unwrap())), "{name} not printed");
        }
        // The CSV has a header and one line per row, as many fields as columns (no field
        // here holds a quoted newline).
        let csv = std::fs::read_to_string(out.join(format!("{name}.csv"))).unwrap();
        let lines: Vec<&str> = csv.lines().collect();
        assert_eq!(lines.len(), rows.len() + 1, "{name}.csv");
        assert_eq!(lines[0].split(',').count(), t["columns"].as_array().unwrap().len(), "{name}.csv header");
    }

    // Figures that follow from the inputs alone: uniform factor 4 on the 2,048-patch torus
    // is 2 · 4² triangles a patch; the teacups scene has 100 × 26 surfaces.
    let speed = first["speed_uniform"]["rows"].as_array().unwrap();
    let torus4 = speed.iter().find(|r| r["model"] == "torus_64x32" && r["factor"] == 4).unwrap();
    assert_eq!(torus4["triangles"], 2048 * 2 * 16);
    // Every CPU row's output rate against the machine's measured fill bandwidth: the frame's
    // output bytes (36 a vertex, 16 a triangle) over its time, and a share of the fill rate.
    for r in speed.iter().filter(|r| r["engine"] == "cpu") {
        let (rate, share) = (r["output GB/s"].as_f64().unwrap(), r["% of fill bandwidth"].as_f64().unwrap());
        let bytes = 36.0 * r["vertices"].as_f64().unwrap() + 16.0 * r["triangles"].as_f64().unwrap();
        let expected = bytes / r["frame ms"].as_f64().unwrap() / 1e6;
        assert!((rate - expected).abs() <= 0.02 * expected + 0.01, "{r}: {rate} GB/s, expected {expected}");
        assert!(share > 0.0 && share.is_finite(), "{r}");
    }
    // OpenSubdiv's Bfr at rate 16 makes exactly tessera's uniform triangles (factor 16 on
    // whole quads); at 0.5 px it tessellated the cages with the rates of tessera's plan.
    for r in first["subdivision_bfr"]["rows"].as_array().unwrap() {
        assert!(r["Bfr Mtri/s"].as_f64().unwrap() > 0.0, "{r}");
        if r["tessellation"].as_str().unwrap().starts_with("uniform") {
            assert_eq!(r["tessera triangles"], r["Bfr triangles"], "{r}");
        }
    }
    let torus16 = first["subdivision_bfr"]["rows"]
        .as_array()
        .unwrap()
        .iter()
        .find(|r| r["model"] == "catmark_torus")
        .unwrap();
    assert_eq!(torus16["tessera triangles"], 16 * 32 * 2 * 16 * 16);
    let teacups = &first["paper002_table1"]["rows"][0];
    assert_eq!(teacups["Teacups here"], 2600);
    // At 0.1 % of the diagonal the transition scheme needs clearly fewer triangles than
    // uniform on the teapot (the adaptive tests' equal-error comparison).
    let ratio = first["adaptive_ratio"]["rows"].as_array().unwrap();
    let teapot = ratio.iter().find(|r| r["model"] == "teapot" && r["target / diagonal"] == "1e-3").unwrap();
    let share = teapot["transition"].as_f64().unwrap();
    assert!(share > 30.0 && share < 70.0, "teapot transition at 1e-3: {share} % of uniform");
    // A scheme that met a target has a figure in the ratio table, whether or not uniform
    // met it too (a share of uniform's, or its own count), and the fewest-triangles column
    // names only schemes with a figure.
    for e in first["adaptive_equal_error"]["rows"].as_array().unwrap() {
        if e["scheme"] == "uniform" || e["triangles"].is_null() {
            continue;
        }
        let row = ratio
            .iter()
            .find(|r| r["model"] == e["model"] && r["target / diagonal"] == e["target / diagonal"])
            .unwrap();
        let scheme = e["scheme"].as_str().unwrap();
        assert!(!row[scheme].is_null(), "adaptive_ratio {row}: {scheme} met the target but shows no figure");
        for winner in row["fewest triangles"].as_str().unwrap_or("").split(" = ").filter(|w| !w.is_empty()) {
            assert!(!row[winner].is_null() || winner == "uniform", "{row}: winner {winner} has no figure");
        }
    }

    // Plots: SVG documents with drawn lines.
    for svg in [
        "speed_uniform.svg",
        "adaptive_teapot.svg",
        "adaptive_teacup.svg",
        "adaptive_helmet.svg",
        "frame_torus_grid_ms.svg",
        "frame_teacups_triangles.svg",
    ] {
        let s = std::fs::read_to_string(out.join(svg)).unwrap_or_else(|e| panic!("{svg}: {e}"));
        assert!(
            s.trim_start().starts_with("<svg") && s.trim_end().ends_with("</svg>"),
            "{svg} is not an SVG document"
        );
        assert!(s.contains("<polyline") || s.contains("<path"), "{svg} has no line");
    }

    let start = std::time::Instant::now();
    run(&dir, "b", &["--no-gpu"]);
    println!("second quick run: {:.1} s", start.elapsed().as_secs_f64());
    let second = tables(&dir.join("b"));
    let (a, b) = (triangle_counts(&first), triangle_counts(&second));
    assert!(a.len() > 50, "only {} triangle counts", a.len());
    let differ: Vec<_> = a.iter().zip(&b).filter(|(x, y)| x != y).take(5).collect();
    assert!(a.len() == b.len() && differ.is_empty(), "triangle counts differ between two runs: {differ:?}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_bench_options_are_refused_clearly() {
    let dir = scratch("bench-bad");
    let o = tessera(&["bench", "--threads", "0", "--out", "x"], &dir);
    assert_eq!(o.status.code(), Some(2));
    assert!(text(&o.stderr).contains("--threads"), "{}", text(&o.stderr));
    let o = tessera(&["bench", "--quick", "--data", "no/such/folder", "--out", "x"], &dir);
    assert_eq!(o.status.code(), Some(2));
    assert!(text(&o.stderr).contains("no/such/folder"), "{}", text(&o.stderr));
    let _ = std::fs::remove_dir_all(&dir);
}
