//! Helpers the render tests share: the shared data folder and the seeded camera ring.

use std::path::{Path, PathBuf};
use tessera::camera::Camera;

/// A file of the shared data folder (`TESSERA_DATA`, else `../shared/data` beside the checkout).
pub fn data(rel: &str) -> PathBuf {
    let base = std::env::var("TESSERA_DATA")
        .map(PathBuf::from)
        .unwrap_or_else(|_| Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data"));
    let p = base.join(rel);
    assert!(p.exists(), "{} missing: set TESSERA_DATA to the shared data folder", p.display());
    p
}

/// Ten cameras about the model: round it, at heights and distances that change the levels.
pub fn cameras(lo: glam::DVec3, hi: glam::DVec3) -> Vec<Camera> {
    let framing = Camera::framing(lo, hi, 640, 480);
    let radius = lo.distance(hi) * 0.5;
    (0..10)
        .map(|k| {
            let angle = k as f64 * 0.7;
            let zoom = [0.45, 0.7, 1.0, 1.6, 3.0][k % 5];
            let offset = glam::DQuat::from_axis_angle(framing.up, angle) * (framing.eye - framing.target);
            let eye = framing.target + offset * zoom + framing.up * radius * (k as f64 * 0.13 - 0.5);
            let d = eye.distance(framing.target);
            Camera { eye, near: (d - radius).max(d * 1e-3), far: d + 2.0 * radius, ..framing }
        })
        .collect()
}
