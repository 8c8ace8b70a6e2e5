//! One frame of a subdivision cage copied into a grid, repeated, as `tessera bench --suite
//! subdivision` runs it (Catmull-Clark, or Loop for a `loop_` cage): uniform at Bfr's rate 16
//! (factor 8 where the cage's faces are split into sub-faces), or the transition scheme at
//! 0.5 px from the camera halfway along the frame suite's walk. Prints the isolated faces'
//! trees (leaves by level), the median frame and each stage's median: one case of the suite
//! without the rest, for profiling (`perf record -D MS` past the load).
//!
//! `cargo run --release -p tessera --example cage_frame -- CAGE COPIES [uniform|adaptive] [FRAMES]`
//! (`CAGE` relative to `$TESSERA_DATA`, e.g. `subdivision/catmark_rook.obj`; threads from
//! `RAYON_NUM_THREADS`).

#[path = "common/stage_medians.rs"]
mod stage_medians;

use std::path::PathBuf;
use std::time::Instant;

use tessera::scheme::{Criterion, PlanOptions, Scheme};
use tessera::subdivision::CageOptions;
use tessera::surface::patch_tree::LeafPatch;
use tessera::surface::{Patch, SurfaceSet};
use tessera::tessellator::{Tessellator, TessellatorOptions};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let usage = "usage: cage_frame CAGE COPIES [uniform|adaptive] [FRAMES]";
    let cage = args.next().ok_or(usage)?;
    let copies: usize = args.next().ok_or(usage)?.parse()?;
    let adaptive = match args.next().as_deref() {
        None | Some("uniform") => false,
        Some("adaptive") => true,
        Some(other) => return Err(format!("{other}: {usage}").into()),
    };
    let frames: usize = args.next().map(|s| s.parse()).transpose()?.unwrap_or(11);
    let data = std::env::var("TESSERA_DATA")
        .map(PathBuf::from)
        .unwrap_or_else(|_| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data"));
    let path = data.join(&cage);
    let start = Instant::now();
    let mesh = tessera::scene::mesh_grid(&tessera::io::obj::read_obj(&path)?, copies);
    let is_loop = path.file_name().is_some_and(|n| n.to_string_lossy().starts_with("loop_"));
    let set = if is_loop {
        SurfaceSet::from_loop_cage(&mesh, &path, CageOptions::default())?
    } else {
        SurfaceSet::from_subdivision_cage(&mesh, &path, CageOptions::default())?
    };
    println!("{cage} × {copies}: {} patches, built in {:.0} ms", set.patches.len(), ms(start));
    print_trees(&set);
    let split = set.origins.iter().any(|o| o.is_subface);
    let (scheme, criterion) = if adaptive {
        (Scheme::Transition, Criterion::PixelError(0.5))
    } else {
        (Scheme::Uniform, Criterion::Factor(if split { 8.0 } else { 16.0 }))
    };
    // The subdivision suite's camera: halfway along the frame suite's walk.
    let (lo, hi) = set.bounds();
    let camera = tessera::scene::walk(lo, hi, 3, 1280, 1024)[1];
    let options = TessellatorOptions {
        plan: PlanOptions { cull: false, ..PlanOptions::default() },
        ..TessellatorOptions::default()
    };
    let mut tess = Tessellator::new(&set, scheme, criterion, options)?;
    stage_medians::run(&mut tess, &camera, frames)
}

/// A Catmull-Clark cage's isolated faces' trees (each once, however many views share it):
/// how many, their leaves by level and their Gregory end caps, what a frame's vertex stage
/// walks through.
fn print_trees(set: &SurfaceSet) {
    let mut seen = std::collections::HashSet::new();
    let (mut views, mut leaves, mut gregory, mut by_level) = (0, 0, 0, [0usize; 16]);
    for patch in &set.patches {
        let Patch::Subdivision(tree) = patch else { continue };
        views += 1;
        if !seen.insert(tree.leaves_id()) {
            continue;
        }
        leaves += tree.leaves().len();
        for leaf in tree.leaves() {
            by_level[usize::from(leaf.level).min(15)] += 1;
            gregory += usize::from(matches!(leaf.patch, LeafPatch::Gregory(_)));
        }
    }
    if views == 0 {
        return;
    }
    let deepest = by_level.iter().rposition(|&n| n > 0).unwrap_or(0);
    println!(
        "{views} patches on {} isolated trees: {leaves} leaves ({gregory} Gregory), by level {:?}",
        seen.len(),
        &by_level[..=deepest]
    );
}

fn ms(since: Instant) -> f64 {
    since.elapsed().as_secs_f64() * 1000.0
}
