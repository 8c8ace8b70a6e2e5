//! A real-time loop through the front door: the teapot, prepared once, re-tessellated for 60
//! frames of a camera walk (one orbit, closing in and backing off) at a guaranteed screen-space
//! error of 1 pixel, into an application's own interleaved vertex buffer, twice over. Prints
//! each frame's time, triangle count and the heap allocations the frame made (counted by this
//! example's global allocator), then the medians.
//!
//! Buffers grow while frames grow (the first orbit: a frame larger than every earlier one
//! may grow the output, plan and pattern buffers); after that a frame allocates nothing. The
//! loop runs inside a rayon pool (`install`), as a render thread of a real application would
//! be one: rayon's queue for work injected from *outside* its pool allocates a small block
//! every 63 injections, which would show here as one allocation every few frames.
//!
//! `cargo run --release -p tessera --example frame_loop [-- PATCHES_OR_OBJ]`

use std::path::PathBuf;
use std::time::Instant;
use tessera::camera::Camera;
use tessera::scheme::{Criterion, Scheme};
use tessera::surface::SurfaceSet;
use tessera::tessellator::{MeshBuilder, Tessellator, TessellatorOptions};

#[path = "common/counting.rs"]
mod counting;
use counting::{allocations as allocated, Counting};

#[global_allocator]
static GLOBAL: Counting = Counting;

/// An application's vertex: what a renderer uploads.
#[derive(Clone, Copy)]
#[allow(dead_code)] // the fields are the GPU's, not read here
struct Vertex {
    position: [f32; 3],
    normal: [f32; 3],
}

/// Interleaved vertices and `u32` indices, cleared (not freed) every frame.
#[derive(Default)]
struct Interleaved {
    vertices: Vec<Vertex>,
    indices: Vec<u32>,
}

impl MeshBuilder for Interleaved {
    fn begin(&mut self, vertices: usize, triangles: usize) {
        self.vertices.clear();
        self.vertices.reserve(vertices);
        self.indices.clear();
        self.indices.reserve(3 * triangles);
    }
    fn vertex(&mut self, position: [f32; 3], normal: [f32; 3], _uv: [f32; 2], _patch: u32) {
        self.vertices.push(Vertex { position, normal });
    }
    fn triangle(&mut self, indices: [u32; 3], _patch: u32) {
        self.indices.extend_from_slice(&indices);
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args().nth(1).map(PathBuf::from).unwrap_or_else(|| {
        let data = std::env::var("TESSERA_DATA")
            .map(PathBuf::from)
            .unwrap_or_else(|_| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data"));
        data.join("patches/teapot.patches")
    });
    let set = if path.extension().is_some_and(|e| e == "obj") {
        let mesh = tessera::io::obj::read_obj(&path)?;
        SurfaceSet::pn_from_mesh(&mesh, &path, Default::default())?
    } else {
        SurfaceSet::from_patch_file(&tessera::io::patches::read_patches(&path)?, Default::default())
    };
    let (lo, hi) = set.bounds();
    let (centre, radius) = ((lo + hi) * 0.5, lo.distance(hi) * 0.5);

    let start = Instant::now();
    let mut tess = Tessellator::new(
        &set,
        Scheme::Transition,
        Criterion::PixelError(1.0),
        TessellatorOptions::default(),
    )?;
    println!("{}: {} patches, prepared in {:.1} ms", path.display(), set.patches.len(), ms(start));

    let mut out = Interleaved::default();
    let pool = rayon::ThreadPoolBuilder::new().build()?;
    let threads = pool.current_num_threads();
    let (mut times, mut allocations) = (Vec::with_capacity(120), Vec::with_capacity(120));
    println!("{:>5} {:>9} {:>10} {:>11}", "frame", "ms", "triangles", "allocations");
    pool.install(|| -> Result<(), tessera::Error> {
        for frame in 0..120 {
            let a = (frame % 60) as f64 / 60.0 * std::f64::consts::TAU;
            // One orbit, the distance swinging between 2.5 and 6 radii.
            let distance = radius * (4.25 + 1.75 * (2.0 * a).cos());
            let mut camera = Camera::framing(lo, hi, 1280, 720);
            camera.eye = centre + glam::DVec3::new(a.cos(), 0.35, a.sin()) * distance;
            camera.target = centre;
            let before = allocated();
            let t = Instant::now();
            tess.frame_into(Some(&camera), &mut out)?;
            times.push(ms(t));
            allocations.push(allocated() - before);
            println!(
                "{frame:>5} {:>9.2} {:>10} {:>11}",
                times[frame],
                out.indices.len() / 3,
                allocations[frame]
            );
        }
        Ok(())
    })?;
    let median = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let growing: u64 = allocations[1..60].iter().sum();
    let second: u64 = allocations[60..].iter().sum();
    println!(
        "median frame {:.2} ms on {threads} threads; allocations: first frame {}, the rest of the first \
         orbit {growing} (buffers growing), the second orbit {second}",
        median(&mut times),
        allocations[0],
    );
    Ok(())
}

fn ms(since: Instant) -> f64 {
    since.elapsed().as_secs_f64() * 1000.0
}
