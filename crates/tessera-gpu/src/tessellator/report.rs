//! What a frame planned on the GPU reports back on request: [`ScreenReport`], read from the
//! view passes' frame state ([`FrameState`], laid out once here and in `view.wgsl`) and check
//! rows ([`CheckRow`]).

use super::GpuTessellator;
use crate::context::GpuContext;
use crate::error::Result;
use crate::readback;

/// What the a-posteriori check of a pixel-error transition or semi-uniform frame achieved
/// ([`GpuTessellator::read_screen_report`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ScreenReport {
    /// Whether the frame had an a-posteriori check on the GPU (a pixel error with the
    /// transition or semi-uniform scheme, planned by [`GpuTessellator::prepare_screen`]); the other fields are
    /// 0, 0 and true otherwise.
    pub checked: bool,
    /// Fix rounds run after the first check (the CPU's loop iterations that changed edges).
    pub rounds: u32,
    /// Visible patches whose bound the plan misses: at the factor cap, as
    /// `tolerance::BoundReport::capped_patches` counts them on the CPU, or left failing when
    /// the rounds did not converge.
    pub failing_patches: u32,
    /// Whether the rounds ended within the recorded ones
    /// ([`DEFAULT_CHECK_ROUNDS`](super::DEFAULT_CHECK_ROUNDS), or as
    /// [`GpuTessellator::set_check_rounds`] set) as the CPU's would (no failing patch, or a
    /// round that changed no edge). When false the plan is still crack-free, but the failing
    /// patches' bounds are missed.
    pub converged: bool,
}

/// `view.wgsl`'s `FrameState` (member for member: the contract test checks the offsets): the
/// frame's planning state, written by `factors.wgsl` and `check.wgsl`, zeroed before the
/// factor passes.
#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct FrameState {
    /// The frame's global factor (`InteriorRule::Global`).
    pub(crate) global_factor: u32,
    /// Patches whose bound the last check missed.
    pub(crate) failing: u32,
    /// Whether the last resolve changed an edge.
    pub(crate) changed: u32,
    /// Whether the rounds ended (1).
    pub(crate) done: u32,
    /// Fix rounds run after the first check.
    pub(crate) rounds: u32,
    /// The frame's vertex depths (SD-2's distance level function), as ordered bits: the
    /// largest, and the complement of the smallest.
    pub(crate) depth_far: u32,
    pub(crate) depth_near_complement: u32,
    pub(crate) _pad: u32,
}

/// `view.wgsl`'s `CheckRow`, one per patch (the contract test checks the offsets): the
/// a-posteriori check's object-space tolerance, the last check's guaranteed bound, its flags
/// and the re-check mark.
#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct CheckRow {
    pub(crate) eps: f32,
    pub(crate) bound: f32,
    pub(crate) flags: u32,
    pub(crate) marked: u32,
}

impl GpuTessellator {
    /// Reads the last frame's a-posteriori check back (after
    /// [`GpuTessellator::prepare_screen`] with a pixel error and the transition or semi-uniform scheme; the
    /// other frames report no rounds and no failing patch): for statistics and tests, never
    /// in a frame loop. Cost: a queue wait.
    pub fn read_screen_report(&self, ctx: &GpuContext) -> Result<ScreenReport> {
        let state: FrameState = readback::read(ctx, &self.view.state, 1)?[0];
        let checked = self.screen.is_some_and(|s| s.checked()) && self.camera.is_some();
        if !checked {
            return Ok(ScreenReport { checked: false, rounds: 0, failing_patches: 0, converged: true });
        }
        // Done, or nothing left failing (the next round would have found that and ended).
        let converged = state.done != 0 || state.failing == 0;
        Ok(ScreenReport { checked: true, rounds: state.rounds, failing_patches: state.failing, converged })
    }

    /// Reads the check's guaranteed bound per patch back (0 for culled patches; meaningful
    /// after a checked frame, see [`GpuTessellator::read_screen_report`]). For tests. Cost:
    /// a queue wait.
    pub fn read_check_bounds(&self, ctx: &GpuContext) -> Result<Vec<f32>> {
        let rows: Vec<CheckRow> = readback::read(ctx, &self.view.checks, self.set.patches as usize)?;
        Ok(rows.iter().map(|r| r.bound).collect())
    }
}
