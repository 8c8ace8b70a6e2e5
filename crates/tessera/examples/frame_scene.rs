//! One real-time frame of a large scene, repeated: 45 copies of the 2,048-patch torus in a
//! grid (92,160 bicubic patches), or 11 copies of the killeroo cage as PN triangles, seen
//! whole at 1280×1024 with a guaranteed error of half a pixel and culling on. Prints the
//! median frame time and each stage's median.
//!
//! `uniform16` instead runs the one torus at uniform factor 16 (1,048,576 triangles, 36 MB of
//! output), `uniform64` at factor 64 (16,777,216 triangles, 570 MB: far beyond any L3);
//! `uniformN` at any factor `N`.
//!
//! `cargo run --release -p tessera --example frame_scene [-- torus|killeroo|uniformN [FRAMES]]`

#[path = "common/stage_medians.rs"]
mod stage_medians;

use std::path::PathBuf;
use std::time::Instant;
use tessera::camera::Camera;
use tessera::scheme::{Criterion, PlanOptions, Scheme};
use tessera::surface::SurfaceSet;
use tessera::tessellator::{Tessellator, TessellatorOptions};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let which = std::env::args().nth(1).unwrap_or_else(|| "torus".into());
    let frames: usize = std::env::args().nth(2).map(|s| s.parse()).transpose()?.unwrap_or(21);
    let data = std::env::var("TESSERA_DATA")
        .map(PathBuf::from)
        .unwrap_or_else(|_| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data"));
    let start = Instant::now();
    let set = match which.as_str() {
        "torus" => {
            let file = tessera::io::patches::read_patches(&data.join("bench/torus_64x32.patches"))?;
            SurfaceSet::from_patch_file(&tessera::scene::patch_grid(&file, 45), Default::default())
        }
        "killeroo" => {
            let path = data.join("meshes/killeroo_cage.obj");
            let mesh = tessera::io::obj::read_obj(&path)?;
            SurfaceSet::pn_from_mesh(&tessera::scene::mesh_grid(&mesh, 11), &path, Default::default())?
        }
        uniform if uniform.strip_prefix("uniform").is_some_and(|f| f.parse::<u32>().is_ok()) => {
            let file = tessera::io::patches::read_patches(&data.join("bench/torus_64x32.patches"))?;
            SurfaceSet::from_patch_file(&file, Default::default())
        }
        other => {
            return Err(format!("unknown scene {other}: use torus, killeroo or uniformN (N a factor)").into())
        }
    };
    println!("{which}: {} patches, built in {:.0} ms", set.patches.len(), ms(start));
    let (lo, hi) = set.bounds();
    let camera = Camera::framing(lo, hi, 1280, 1024);
    let options = TessellatorOptions {
        plan: PlanOptions { cull: true, ..PlanOptions::default() },
        ..TessellatorOptions::default()
    };
    let start = Instant::now();
    let mut tess = if let Some(factor) = which.strip_prefix("uniform") {
        // The one torus at a uniform factor, no camera work.
        let options = TessellatorOptions::default();
        Tessellator::new(&set, Scheme::Uniform, Criterion::Factor(factor.parse()?), options)?
    } else {
        Tessellator::new(&set, Scheme::Transition, Criterion::PixelError(0.5), options)?
    };
    println!("prepared in {:.0} ms", ms(start));
    stage_medians::run(&mut tess, &camera, frames)
}

fn ms(since: Instant) -> f64 {
    since.elapsed().as_secs_f64() * 1000.0
}
