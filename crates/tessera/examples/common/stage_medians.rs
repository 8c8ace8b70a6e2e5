//! The frame loop of the profiling examples: `frames` frames from one camera, then the median
//! frame and each stage's median, printed on one line. Shared by `examples/frame_scene.rs`
//! and `examples/cage_frame.rs` (`#[path]`).

use tessera::camera::Camera;
use tessera::tessellator::Tessellator;

/// Runs `frames` frames of `tess` from `camera` and prints the triangle count, the median
/// frame and the median of each stage (criterion, resolve, layout, vertices, indices).
pub fn run(
    tess: &mut Tessellator<'_>,
    camera: &Camera,
    frames: usize,
) -> Result<(), Box<dyn std::error::Error>> {
    let mut stages: [Vec<f64>; 6] = Default::default();
    let mut walls = Vec::with_capacity(frames);
    let mut triangles = 0;
    for _ in 0..frames {
        let start = std::time::Instant::now();
        triangles = tess.frame(Some(camera))?.triangle_count();
        walls.push(start.elapsed().as_secs_f64() * 1000.0);
        let t = tess.timings();
        for (s, d) in stages.iter_mut().zip([
            t.criterion,
            t.resolve,
            t.layout,
            t.write_vertices,
            t.write_indices,
            t.total(),
        ]) {
            s.push(d.as_secs_f64() * 1000.0);
        }
    }
    let median = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let [c, r, l, v, i, total] = stages.each_mut().map(median);
    // The wall clock of `frame` as a caller sees it (the stages' sum leaves out the hand-over
    // to the pool's worker, `Tessellator::frame`).
    let wall = median(&mut walls);
    println!(
        "{triangles} triangles; median frame {total:.2} ms over {frames} frames on {} threads: \
         criterion {c:.2}, resolve {r:.2}, layout {l:.2}, write vertices {v:.2}, write indices {i:.2} ms; \
         median wall {wall:.2} ms",
        rayon::current_num_threads()
    );
    Ok(())
}
