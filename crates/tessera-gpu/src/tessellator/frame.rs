//! Recording a frame: the compute passes of [`PASSES`] into the caller's command encoder,
//! for the last prepared plan or the GPU's own planning, and the rounds of the a-posteriori
//! check within the factors pass. Nothing here reads back.

use super::pipelines::CheckPipelines;
use super::timer::begin_pass;
use super::{GpuTessellator, PassTimer};
use crate::shader;

/// The compute passes of a frame, in order ("cull" only with a culling camera,
/// [`GpuTessellator::set_cull_camera`]; "factors" only with factors from the camera,
/// [`GpuTessellator::prepare_screen`]).
pub const PASSES: [&str; 7] = ["cull", "factors", "count", "scan", "args", "vertices", "triangles"];

/// Rounds of the a-posteriori check a frame records (`check.wgsl`). The CPU's loop runs up
/// to 256 rounds but ends after a few: across every model in the shared data, 8 seeded
/// cameras at 0.25, 1 and 4 px and caps 16 and 64, the most it took was 34 (the spool at cap
/// 16, where patches at the cap miss their bound and each round moves the problem one patch
/// along the mesh; 41 on another camera in `tests/check.rs`). A round that is not needed
/// dispatches no work; a plan that needs more is reported
/// ([`ScreenReport::converged`](super::ScreenReport::converged)).
pub const DEFAULT_CHECK_ROUNDS: u32 = 64;

/// The most fix rounds a frame may record ([`GpuTessellator::set_check_rounds`]), as many as
/// the CPU's loop runs.
pub const MAX_CHECK_ROUNDS: u32 = 256;

impl GpuTessellator {
    /// Records the frame's passes for the last prepared plan into `encoder`. Reads nothing
    /// back. Precondition: [`GpuTessellator::prepare`] succeeded once (else nothing is
    /// recorded). Cost on the GPU: O(output) work in about a dozen dispatches.
    pub fn record(&self, encoder: &mut wgpu::CommandEncoder) {
        self.record_timed(encoder, None)
    }

    /// [`GpuTessellator::record`], each pass timed by `timer` (see [`PassTimer`]).
    pub fn record_timed(&self, encoder: &mut wgpu::CommandEncoder, timer: Option<&PassTimer>) {
        let Some(out) = &self.output else { return };
        let p = &self.pipelines;
        // Compiled by the `prepare` that chose the pattern.
        let Some(k) = p.of(self.pattern) else { return };
        let (e, patches, corners) = (self.set.edges, self.set.patches, self.set.corners);
        let grid = |n: u32| shader::grid(n.div_ceil(shader::WORKGROUP));
        {
            // Begun even without culling, so that every timestamp of the timer is written.
            let mut c = begin_pass(encoder, timer, 0);
            if self.camera.is_some() {
                c.set_pipeline(&p.cull);
                c.set_bind_group(0, &out.main, &[]);
                c.set_bind_group(1, &self.view.bind, &[]);
                let (x, y) = grid(patches);
                c.dispatch_workgroups(x, y, 1);
            }
        }
        let screen = self.screen.is_some() && self.camera.is_some();
        if screen {
            encoder.clear_buffer(&self.view.state, 0, None);
        }
        {
            let mut c = begin_pass(encoder, timer, 1);
            if screen {
                c.set_bind_group(0, &out.main, &[]);
                c.set_bind_group(1, &self.view.bind, &[]);
                if let Some(esc) = p.esc_plan_compiled().filter(|_| self.screen.is_some_and(|s| s.is_esc())) {
                    // ESC: levels, then edges, then grids (each pass reads the last's writes).
                    for (pipeline, n) in [(&esc.levels, patches), (&esc.edges, e), (&esc.grids, patches)] {
                        c.set_pipeline(pipeline);
                        let (x, y) = grid(n);
                        c.dispatch_workgroups(x, y, 1);
                    }
                } else if let Some((proposals, check)) = self.screen.and_then(|s| p.bound(s.bound)) {
                    // Compiled by the `prepare_screen` that chose the bound.
                    if self.screen.is_some_and(|s| s.reads_depths()) {
                        c.set_pipeline(&p.vertex_depths);
                        let (x, y) = grid(self.view.vertices);
                        c.dispatch_workgroups(x, y, 1);
                    }
                    c.set_pipeline(proposals);
                    let (x, y) = grid(patches);
                    c.dispatch_workgroups(x, y, 1);
                    c.set_pipeline(&p.edge_segments);
                    let (x, y) = grid(e);
                    c.dispatch_workgroups(x, y, 1);
                    if self.screen.is_some_and(|s| s.checked()) {
                        self.record_check(&mut c, check);
                    } else {
                        c.set_pipeline(&p.interiors);
                        let (x, y) = grid(e.max(patches));
                        c.dispatch_workgroups(x, y, 1);
                    }
                }
            }
        }
        {
            let mut c = begin_pass(encoder, timer, 2);
            c.set_pipeline(&k.count);
            c.set_bind_group(0, &out.main, &[]);
            let (x, y) = shader::grid((e + patches + 1).div_ceil(shader::WORKGROUP));
            c.dispatch_workgroups(x, y, 1);
        }
        {
            let mut c = begin_pass(encoder, timer, 3);
            self.vertex_scan.record(&p.scan, &mut c);
            self.triangle_scan.record(&p.scan, &mut c);
        }
        {
            let mut c = begin_pass(encoder, timer, 4);
            c.set_pipeline(&p.args);
            c.set_bind_group(0, &out.main, &[]);
            c.set_bind_group(1, &self.args, &[]);
            c.dispatch_workgroups(1, 1, 1);
        }
        {
            let mut c = begin_pass(encoder, timer, 5);
            c.set_bind_group(0, &out.main, &[]);
            // A set with subdivision patches evaluates them (compiled when it was prepared).
            let v = if self.set.has_trees {
                k.with_trees.get().expect("prepare compiles the tree passes of a set with trees")
            } else {
                &k.vertices
            };
            if corners > 0 {
                c.set_pipeline(&v.corners);
                let (x, y) = shader::grid(corners.div_ceil(shader::WORKGROUP));
                c.dispatch_workgroups(x, y, 1);
            }
            c.set_pipeline(&v.edge_vertices);
            c.dispatch_workgroups_indirect(&self.dispatch_args, 0);
            c.set_pipeline(&v.interior_vertices);
            c.dispatch_workgroups_indirect(&self.dispatch_args, 12);
        }
        {
            let mut c = begin_pass(encoder, timer, 6);
            c.set_bind_group(0, &out.main, &[]);
            // Per-triangle passes take the third dispatch, per-patch passes the fourth, which
            // the args pass zeroes on overflow. A pattern with a collapsed-corner pass writes
            // triangle by triangle, then the patches at a collapsed corner one by one.
            match &k.collapsed_triangles {
                Some(collapsed) => {
                    c.set_pipeline(&k.triangles);
                    c.dispatch_workgroups_indirect(&self.dispatch_args, 24);
                    if self.set.any_repeated_corner {
                        c.set_pipeline(collapsed);
                        c.dispatch_workgroups_indirect(&self.dispatch_args, 36);
                    }
                }
                None => {
                    c.set_pipeline(&k.triangles);
                    c.dispatch_workgroups_indirect(&self.dispatch_args, 36);
                }
            }
            // The strips (SD-2, ESC), when on: timed with the triangles.
            self.record_strips(&mut c, &out.main);
        }
        if let Some(t) = timer {
            encoder.resolve_query_set(&t.queries, 0..2 * PASSES.len() as u32, &t.resolved, 0);
        }
    }

    /// Records the a-posteriori check of a pixel-error transition plan into the factors pass
    /// (`check.wgsl`): the first check of every patch, then [`DEFAULT_CHECK_ROUNDS`] rounds whose
    /// passes the GPU sizes itself (no work once the rounds have ended). Groups 0 and 1 are
    /// bound by the caller.
    fn record_check(&self, c: &mut wgpu::ComputePass<'_>, k: &CheckPipelines) {
        let (x, y) = shader::grid(self.set.patches.div_ceil(shader::WORKGROUP));
        c.set_pipeline(&k.check);
        c.dispatch_workgroups(x, y, 1);
        let args = &self.view.round_args;
        // The decisions bind the dispatch arguments as storage (their group 1: the frame state
        // and the arguments); the passes they size read them as indirect arguments, with the
        // view group, which leaves them out.
        let decide = |c: &mut wgpu::ComputePass<'_>, pipeline: &wgpu::ComputePipeline| {
            c.set_pipeline(pipeline);
            c.set_bind_group(1, &self.view.rounds, &[]);
            c.dispatch_workgroups(1, 1, 1);
            c.set_bind_group(1, &self.view.bind, &[]);
        };
        for _ in 0..self.check_rounds {
            decide(c, &k.open);
            c.set_pipeline(&k.resolve);
            c.dispatch_workgroups_indirect(args, 12);
            decide(c, &k.close);
            c.set_pipeline(&k.check);
            c.dispatch_workgroups_indirect(args, 0);
        }
    }

    /// Sets how many fix rounds of the a-posteriori check every following frame records
    /// (default [`DEFAULT_CHECK_ROUNDS`]). A round that is not needed dispatches no work, but still
    /// costs its four dispatches (about 70 µs on lavapipe, a few µs on a hardware GPU), so a
    /// real-time loop whose scenes converge in fewer rounds may record fewer and watch
    /// [`ScreenReport::converged`](super::ScreenReport::converged) now and then (a read-back,
    /// on request); at most [`MAX_CHECK_ROUNDS`] (more are clamped to it). A frame whose plan
    /// needs more rounds is still crack-free; its failing patches miss their bound and are
    /// counted. Cost: none until the next frame.
    pub fn set_check_rounds(&mut self, rounds: u32) {
        self.check_rounds = rounds.min(MAX_CHECK_ROUNDS);
    }
}
