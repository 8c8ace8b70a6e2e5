//! The OpenSubdiv oracle (`tools/osd-oracle/osd_oracle`, a C++ program linked against
//! OpenSubdiv that prints Bfr's limit points face by face; `scripts/test` builds it): running
//! it and reading what it prints, for the Catmull-Clark and Loop comparisons.

use std::path::{Path, PathBuf};
use std::process::Command;

use glam::{DVec2, DVec3};
use tessera::test_support::data;

/// The oracle binary: `$TESSERA_OSD_ORACLE`, else `tools/osd-oracle/osd_oracle`.
pub fn oracle() -> PathBuf {
    let path = std::env::var_os("TESSERA_OSD_ORACLE")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tools/osd-oracle/osd_oracle"));
    assert!(
        path.exists(),
        "the OpenSubdiv oracle {} is not built: install a C++ compiler and OpenSubdiv \
         (apt-get install -y g++ libosd-dev) and run tools/osd-oracle/build.sh (scripts/test does both checks)",
        path.display()
    );
    path
}

/// One face of the oracle's output.
pub struct OracleFace {
    pub regular: bool,
    pub limit: bool,
    /// `(u, v)` and the limit point there.
    pub points: Vec<(DVec2, DVec3)>,
}

/// The OpenSubdiv release the oracle was built against, from its header line.
pub fn oracle_version() -> [u32; 3] {
    static VERSION: std::sync::OnceLock<[u32; 3]> = std::sync::OnceLock::new();
    *VERSION.get_or_init(|| {
        let out = Command::new(oracle())
            .arg(data("subdivision/catmark_cube.obj"))
            .output()
            .expect("run the oracle");
        let text = String::from_utf8_lossy(&out.stdout);
        let header = text.lines().next().unwrap_or_default();
        let version = header.split_whitespace().skip_while(|w| *w != "opensubdiv").nth(1).unwrap_or("0.0.0");
        let v: Vec<u32> = version.split('.').map(|x| x.parse().unwrap_or(0)).collect();
        [v[0], v.get(1).copied().unwrap_or(0), v.get(2).copied().unwrap_or(0)]
    })
}

pub fn run_oracle(cage: &Path, rate: u32) -> Vec<OracleFace> {
    run_oracle_with(cage, rate, &[])
}

/// [`run_oracle`] with the oracle's options `args` (e.g. `["--scheme", "loop"]` for a Loop
/// cage whose name does not start with `loop_`).
pub fn run_oracle_with(cage: &Path, rate: u32, args: &[&str]) -> Vec<OracleFace> {
    let out =
        Command::new(oracle()).args(args).arg(cage).arg(rate.to_string()).output().expect("run the oracle");
    assert!(
        out.status.success(),
        "oracle failed on {}: {}",
        cage.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    parse_oracle(&String::from_utf8(out.stdout).unwrap())
}

pub fn parse_oracle(text: &str) -> Vec<OracleFace> {
    let mut faces: Vec<OracleFace> = Vec::new();
    for line in text.lines().filter(|l| !l.starts_with('#')) {
        let w: Vec<&str> = line.split_ascii_whitespace().collect();
        if w[0] == "face" {
            faces.push(OracleFace {
                regular: w[6] == "regular",
                limit: w[6] != "nolimit",
                points: Vec::new(),
            });
        } else {
            let n: Vec<f64> = w.iter().map(|x| x.parse().unwrap()).collect();
            faces.last_mut().unwrap().points.push((DVec2::new(n[0], n[1]), DVec3::new(n[2], n[3], n[4])));
        }
    }
    faces
}

/// The length of the cage's bounding-box diagonal (the unit the agreements are measured in).
pub fn cage_diagonal(mesh: &tessera::surface::PolygonMesh) -> f64 {
    let (lo, hi) = mesh
        .positions
        .iter()
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
    (hi - lo).length()
}
