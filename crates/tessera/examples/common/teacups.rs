//! The Teacups scene of paper 002's Table 1 and its walk-through, shared by the ESC tests and
//! `tessera bench` (its `paper` and `frame` suites; `#[path]`-included by both): a scene for
//! measurements, not part of the library.

#![allow(dead_code)] // each includer uses its part

use glam::DVec3;
use tessera::camera::Camera;
use tessera::criterion::esc::{self, EscOptions};
use tessera::surface::{BuildOptions, Patch, SurfaceSet};
use tessera::{Error, Result};

/// Triangle counts of one frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct FrameCount {
    /// The non-adaptive tessellation at the same levels: `18 (L+1)²` per surface.
    pub non_adaptive: u64,
    /// The ESC output (pattern triangles, before dropping those collapsed at degenerate
    /// patch corners, for both counts alike).
    pub adaptive: u64,
}

/// ESC triangle counts for every camera of a walk-through. Preconditions as [`esc::plan`].
/// Cost: one [`esc::plan`] per camera.
pub fn frame_counts(set: &SurfaceSet, cameras: &[Camera], options: &EscOptions) -> Result<Vec<FrameCount>> {
    cameras
        .iter()
        .map(|camera| {
            let (_, esc) = esc::plan(set, camera, options)?;
            let mut count = FrameCount::default();
            for p in 0..set.patches.len() {
                let n = esc.grid(p).n as u64;
                count.non_adaptive += 18 * n * n;
                count.adaptive += esc.triangles(p) as u64;
            }
            Ok(count)
        })
        .collect()
}

/// Cups per side of [`teacups_scene`] (10 × 10 = 100, as in the paper's Teacups scene).
pub const TEACUPS_PER_SIDE: usize = 10;
/// Frames of the [`teacups_scene`] walk-through.
pub const TEACUPS_FRAMES: usize = 60;

/// The Teacups scene of the paper's Table 1: 100 copies of `cup` (a y-up model such as
/// `patches/teacup.patches`, 26 surfaces → 2,600) on a 10 × 10 grid in the `xz` plane, one
/// and a half cup widths apart, and a deterministic walk-through: 60 cameras (1280 × 1024, as
/// in the paper) that enter the grid at one side at a little above cup height, wind through
/// it along a gentle S curve and leave at the other side, looking ahead and slightly down.
/// Errors for a cup with non-bicubic patches or no extent. Cost: O(100 · cup patches).
pub fn teacups_scene(cup: &SurfaceSet) -> Result<(SurfaceSet, Vec<Camera>)> {
    if let Some(p) = cup.patches.iter().position(|p| !matches!(p, Patch::Bicubic(_))) {
        return Err(Error::unsupported("<teacup>", 0, format!("patch {p} is not a bicubic patch")));
    }
    let (lo, hi) = cup.bounds();
    let size = hi - lo;
    if !(size.x > 0.0 && size.y > 0.0 && size.z > 0.0 && size.is_finite()) {
        return Err(Error::InvalidParameter {
            name: "teacups scene",
            reason: "the cup has no extent".into(),
        });
    }
    let spacing = 1.5 * size.x.max(size.z);
    let mut patches = Vec::with_capacity(cup.patches.len() * TEACUPS_PER_SIDE * TEACUPS_PER_SIDE);
    for gz in 0..TEACUPS_PER_SIDE {
        for gx in 0..TEACUPS_PER_SIDE {
            let offset = DVec3::new(gx as f64 * spacing, 0.0, gz as f64 * spacing);
            for p in &cup.patches {
                if let Patch::Bicubic(b) = p {
                    let mut b = b.clone();
                    for q in &mut b.points {
                        *q += offset;
                    }
                    patches.push(Patch::Bicubic(b));
                }
            }
        }
    }
    let set = SurfaceSet::from_patches(patches, BuildOptions::default());
    let centre = (lo + hi) * 0.5;
    let extent = spacing * (TEACUPS_PER_SIDE - 1) as f64;
    let eye_at = |t: f64| {
        DVec3::new(
            centre.x - spacing + (extent + 2.0 * spacing) * t,
            hi.y + 0.6 * size.y,
            centre.z + extent * (0.5 + 0.25 * (2.0 * std::f64::consts::PI * t).sin()),
        )
    };
    let cameras = (0..TEACUPS_FRAMES)
        .map(|f| {
            let t = f as f64 / (TEACUPS_FRAMES - 1) as f64;
            let eye = eye_at(t);
            let ahead = eye_at(t + 0.05);
            Camera {
                eye,
                target: ahead - DVec3::Y * size.y,
                up: DVec3::Y,
                fov_y_degrees: 60.0,
                width: 1280,
                height: 1024,
                near: size.y * 0.01,
                far: extent * 4.0,
            }
        })
        .collect();
    Ok((set, cameras))
}
