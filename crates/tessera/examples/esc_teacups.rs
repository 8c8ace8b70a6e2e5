//! Reproduces the Teacups column of paper 002's Table 1 with the ESC scheme: 100 teacups
//! (2,600 bicubic surfaces), a 60-frame walk-through, `Lmax = 3`. Prints the non-adaptive
//! triangle count (uniform level-L patterns, `18 (L+1)²` per surface, averaged over frames),
//! the adaptive counts with the high and medium presets and their shares, and, for the middle
//! frame, the measured maximum error of each preset next to a uniform tessellation with about
//! the same number of triangles.
//!
//! `cargo run --release -p tessera --example esc_teacups [path/to/teacup.patches]`; the
//! default path is `$TESSERA_DATA/patches/teacup.patches`, else `../shared/data/...`.

#[path = "common/teacups.rs"]
mod teacups;

use std::path::PathBuf;
use tessera::criterion::esc::{self, EscOptions, Threshold};
use tessera::criterion::Plan;
use tessera::engine::{tessellate, TessellateOptions};
use tessera::io::patches::read_patches;
use tessera::pattern::uniform::Uniform;
use tessera::surface::SurfaceSet;
use tessera::verify;

fn main() -> tessera::Result<()> {
    let path = std::env::args().nth(1).map(PathBuf::from).unwrap_or_else(|| {
        let data = std::env::var("TESSERA_DATA")
            .map(PathBuf::from)
            .unwrap_or_else(|_| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data"));
        data.join("patches/teacup.patches")
    });
    let cup = SurfaceSet::from_patch_file(&read_patches(&path)?, Default::default());
    let (scene, cameras) = teacups::teacups_scene(&cup)?;
    let frames = cameras.len() as f64;
    println!("Teacups: {} input surfaces, {} frames, Lmax = 3", scene.patches.len(), cameras.len());

    let options = |threshold| EscOptions { max_level: 3, threshold, ..Default::default() };
    let high = teacups::frame_counts(&scene, &cameras, &options(Threshold::High))?;
    let medium = teacups::frame_counts(&scene, &cameras, &options(Threshold::Medium))?;
    let avg = |v: &[teacups::FrameCount], f: fn(&teacups::FrameCount) -> u64| {
        v.iter().map(f).sum::<u64>() as f64 / frames
    };
    let base = avg(&high, |c| c.non_adaptive);
    let (h, m) = (avg(&high, |c| c.adaptive), avg(&medium, |c| c.adaptive));
    println!("{:<22}{:>12}{:>10}   paper", "", "triangles", "share");
    println!("{:<22}{:>11.2}k{:>10}   731.32k", "non-adaptive", base / 1e3, "");
    println!("{:<22}{:>11.2}k{:>9.2}%   93.62%", "adaptive high", h / 1e3, 100.0 * h / base);
    println!("{:<22}{:>11.2}k{:>9.2}%   51.96%", "adaptive medium", m / 1e3, 100.0 * m / base);

    // Error of each preset against uniform tessellation with about as many triangles, at the
    // middle frame of the walk.
    let camera = &cameras[cameras.len() / 2];
    let params = TessellateOptions { corner_params: true, ..Default::default() };
    println!("\nmax error at frame {} (order-4 samples in every triangle; model units):", cameras.len() / 2);
    for (name, threshold) in [("high", Threshold::High), ("medium", Threshold::Medium)] {
        let (plan, pattern) = esc::plan(&scene, camera, &options(threshold))?;
        let mesh = tessellate(&scene, &plan, &pattern, params)?;
        let err = verify::approximation_error(&mesh, &scene, 4)?;
        let tris = mesh.triangle_count();
        // Uniform factor f gives 2 f² triangles per surface.
        let f = ((tris as f64 / (2.0 * scene.patches.len() as f64)).sqrt().round() as u32).max(1);
        let umesh = tessellate(&scene, &Plan::uniform(&scene, f)?, &Uniform, params)?;
        let uerr = verify::approximation_error(&umesh, &scene, 4)?;
        println!(
            "  {name:<7} ESC {:>8} triangles, max {:.3e} (rms {:.3e}) | uniform f={f:<2} {:>8} triangles, max {:.3e} (rms {:.3e})",
            tris,
            err.max,
            err.rms,
            umesh.triangle_count(),
            uerr.max,
            uerr.rms
        );
    }
    let full = tessellate(&scene, &Plan::uniform(&scene, 12)?, &Uniform, params)?;
    let ferr = verify::approximation_error(&full, &scene, 4)?;
    println!(
        "  (uniform f=12, the non-adaptive L=3 grid: {} triangles, max {:.3e})",
        full.triangle_count(),
        ferr.max
    );
    Ok(())
}
