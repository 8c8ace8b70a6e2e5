//! The output's room: [`Capacity`], the worst cases a frame is sized for before it runs, and
//! the output buffers' growth ([`GpuTessellator::reserve`],
//! [`GpuTessellator::grow_if_overflowed`]).

use super::pipelines::ESC_GRID_WORDS;
use super::screen::{Screen, INTERIOR_CORE};
use super::{buffer, GpuPattern, GpuTessellator, Output, Params, ROW_BLOCKS, VERTEX_STRIDE};
use crate::context::GpuContext;
use crate::error::{GpuError, Result};
use crate::shader;
use tessera::criterion::Plan;
use tessera::pattern::hardware::{Hardware, Partitioning};
use tessera::pattern::uniform::Uniform;
use tessera::pattern::Pattern;
use tessera::sampling::{SamplingKind, Spacing};
use tessera::scheme::Prepared;
use tessera::surface::SurfaceSet;

/// The worst-case output of a plan, known before the frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Capacity {
    /// Vertices the output buffers hold.
    pub vertices: u64,
    /// Triangles the output buffers hold.
    pub triangles: u64,
}

impl Capacity {
    /// The bound of `plan` on `set` under `pattern`: every corner entry,
    /// `(s − 1) · variants` per edge, and the pattern's own counts
    /// ([`Pattern::counts`] of [`tessera::engine::layout::pattern_input`]) per visible patch
    /// (per patch with `all_visible`, when the GPU decides visibility), triangles that may
    /// degenerate at collapsed curves included. Cost: O(E + P) pattern counts.
    pub fn of_plan(set: &SurfaceSet, plan: &Plan, pattern: &dyn Pattern, all_visible: bool) -> Capacity {
        let topo = &set.topology;
        let mut vertices = topo.corner_entries.len() as u64;
        for (e, edge) in topo.edges.iter().enumerate() {
            vertices += (plan.segments[e] as u64 - 1) * edge.variants as u64;
        }
        let mut triangles = 0;
        for p in 0..set.patches.len() {
            if all_visible || plan.is_visible(p) {
                let (v, t) = pattern.counts(&tessera::engine::layout::pattern_input(set, plan, p));
                vertices += v as u64;
                triangles += t as u64;
            }
        }
        Capacity { vertices, triangles }
    }
}

/// The largest output a hardware frame planned on the GPU can have: every edge at the largest
/// factor `resolve::edges` can give it — the cap, or the largest minimum when that is higher,
/// through the hull shader's rounding (`Partitioning::hull_factor`), within the
/// partitioning's range — drawn by [`Hardware`] ([`Capacity::of_plan`], every patch visible).
///
/// An upper bound because the pattern's output grows with its factors: an edge's segments
/// grow with its factor, the interior points with the inside factors (the largest edge
/// factors), and a triangulation of the domain with B boundary and I interior points has
/// `B + 2I − 2` triangles (the test `the_hardware_worst_case_bounds_every_frame` checks this
/// on random factors). Cost: O(E + P) pattern counts.
fn hardware_worst_case(
    set: &SurfaceSet,
    prepared: &Prepared,
    partitioning: Partitioning,
    cap: f64,
) -> Capacity {
    let minimum = prepared.minimum_segments.iter().copied().max().unwrap_or(1) as f64;
    let factor = partitioning.hull_factor(cap.max(minimum)).min(partitioning.range().1 as f64);
    Capacity::of_plan(
        set,
        &hardware_uniform_plan(set, partitioning, factor),
        &Hardware { partitioning },
        true,
    )
}

/// The largest output a frame planned on the GPU by `screen` can have
/// ([`GpuTessellator::prepare_screen`]): every patch at the cap `max_factor`, or at the
/// largest of `prepared`'s minimums when that is higher; for the transition scheme's core
/// rule its strips' triangles too; for a hardware partitioning [`hardware_worst_case`]; for
/// SD-2 its own pattern with every edge at that factor (`nd (2 ns − 1)` triangles grow with
/// both counts, so no two-factor plan within it has more); for ESC every patch's complete
/// pattern at the highest level the frame can give (its `3n`-grid: every candidate
/// inserted is the uniform pattern of factor `3n`, and leaving candidates out only removes
/// vertices and triangles).
/// Errors as [`Plan::uniform`]. Cost: O(E + P) pattern counts.
pub(super) fn screen_worst_case(
    set: &SurfaceSet,
    prepared: &Prepared,
    screen: &Screen,
    pattern: GpuPattern,
    max_factor: u32,
) -> Result<Capacity> {
    let patches = set.patches.len();
    if pattern == GpuPattern::Esc {
        let level = if screen.lo >= 0.0 { screen.lo } else { screen.hi } as u32;
        let side = 3 * tessera::pattern::esc::segments_for_level(level);
        return Ok(Capacity::of_plan(set, &Plan::uniform(set, side)?, &Uniform, true));
    }
    // The largest global factor a frame can reach: the cap, or a minimum above it.
    let minimum = prepared.minimum_segments.iter().chain(prepared.minimum_interior.iter().flatten());
    let worst = minimum.copied().fold(max_factor, u32::max);
    let mut worst_case = Capacity::of_plan(set, &Plan::uniform(set, worst)?, &Uniform, true);
    if screen.interior == INTERIOR_CORE {
        // `Transition::counts` with every factor at most w = max(worst, 3) (cores are
        // raised to 3 at most): 2·nu·nv core triangles plus s + m a strip, at most
        // 2w² + 8w a patch, the uniform pattern's 2w² and 8w more; no more vertices.
        let w = worst.max(3) as u64;
        worst_case = Capacity::of_plan(set, &Plan::uniform(set, w as u32)?, &Uniform, true);
        worst_case.triangles += 8 * w * patches as u64;
    }
    match pattern {
        GpuPattern::Hardware(p) => worst_case = hardware_worst_case(set, prepared, p, screen.cap),
        GpuPattern::Sd2 => {
            let mut plan = Plan::uniform(set, worst)?;
            plan.kind = SamplingKind::Fractional(Spacing::Symmetric);
            worst_case = Capacity::of_plan(set, &plan, &tessera::pattern::sd2::Sd2::default(), true);
        }
        GpuPattern::Uniform | GpuPattern::Esc | GpuPattern::Transition | GpuPattern::SemiUniform => {}
    }
    Ok(worst_case)
}

/// The hardware plan with `factor` on every edge, every patch visible. Cost: O(E + P).
fn hardware_uniform_plan(set: &SurfaceSet, partitioning: Partitioning, factor: f64) -> Plan {
    let segments = tessera::pattern::hardware::edge_segments(factor, partitioning);
    let (edges, patches) = (set.topology.edges.len(), set.patches.len());
    Plan {
        kind: SamplingKind::Fractional(Spacing::Hardware(partitioning)),
        segments: vec![segments; edges],
        factors: vec![factor as f32; edges],
        depths: Vec::new(),
        lattice_offsets: Vec::new(),
        lattice: Vec::new(),
        interior: vec![[segments, segments]; patches],
        visible: vec![1; patches],
    }
}

impl GpuTessellator {
    /// The largest output the device's limits allow: `(vertices, triangles)`. Below the u32
    /// range: a saturated scan total (`u32::MAX`, `shaders/scan.wgsl`) always overflows.
    pub(super) fn most(&self) -> (u64, u64) {
        let vertices = (self.buffer_limit / VERTEX_STRIDE).min(u32::MAX as u64 - 1);
        let triangles = (self.buffer_limit / 12).min(u32::MAX as u64 / 3);
        (vertices, triangles)
    }

    /// After a submitted frame: reads its status back and, when it overflowed (a frame
    /// that needs more room than the buffers have draws nothing at all, never part of the
    /// mesh), grows the output to what it needed and returns `Ok(true)`: record and submit
    /// the frame again. `Ok(false)`: the frame was complete. A loop sized for the worst case
    /// ([`GpuTessellator::prepare`], or [`GpuTessellator::prepare_screen`] within the
    /// device's limits) never needs this; with a smaller start it is the grow-and-rerun
    /// path, a read-back each time it is called.
    ///
    /// Errors: [`GpuError::OutputTooLarge`] when the frame needs more than the device's
    /// buffer limits or the u32 index range (its output is then empty and reported, no
    /// patch dropped silently). Cost: a queue wait; a reallocation when it grows.
    pub fn grow_if_overflowed(&mut self, ctx: &GpuContext) -> Result<bool> {
        let (overflow, vertices, triangles) = self.read_status(ctx)?;
        if !overflow {
            return self.grow_strips_if_overflowed(ctx);
        }
        // The counts are the scans' totals, exact unless they saturated at u32::MAX (then
        // the need is beyond the index range anyway, and refused below).
        let need = Capacity { vertices: vertices as u64, triangles: triangles as u64 };
        let have = self.capacity().unwrap_or_default();
        let (most_vertices, most_triangles) = self.most();
        if need.vertices > most_vertices || need.triangles > most_triangles {
            return Err(GpuError::OutputTooLarge {
                vertices: need.vertices,
                triangles: need.triangles,
                bytes: (need.vertices * VERTEX_STRIDE).max(need.triangles * 12),
                limit: self.buffer_limit,
            });
        }
        // Grow with some room, so that a camera moving on does not grow every frame.
        let grown = |need: u64, have: u64, most: u64| need.max(have).saturating_mul(5).div_ceil(4).min(most);
        let capacity = Capacity {
            vertices: grown(need.vertices, have.vertices, most_vertices),
            triangles: grown(need.triangles, have.triangles, most_triangles),
        };
        self.reserve(ctx, capacity)?;
        Ok(true)
    }

    /// Sizes the output of frames planned on the GPU whose largest output is `worst`:
    /// `capacity` (at most `worst`), or `worst` within the device's buffer limits (past them
    /// the frames that need more overflow and are reported; the ones that fit draw
    /// completely). A worst case
    /// past the u32 range is no reason to refuse: the scans saturate there, so a frame that
    /// large overflows and is reported, and the frames a camera actually asks for draw.
    /// Errors as [`GpuTessellator::reserve`]. Cost: as `reserve`.
    pub(super) fn reserve_screen(
        &mut self,
        ctx: &GpuContext,
        worst: Capacity,
        capacity: Option<Capacity>,
    ) -> Result<()> {
        let (most_vertices, most_triangles) = self.most();
        // Never more than the worst case: no frame of these needs it.
        let capacity = capacity.unwrap_or(Capacity { vertices: most_vertices, triangles: most_triangles });
        let capacity = Capacity {
            vertices: capacity.vertices.min(worst.vertices),
            triangles: capacity.triangles.min(worst.triangles),
        };
        self.reserve(ctx, capacity)
    }

    /// Makes the output buffers hold at least `capacity`. Errors with
    /// [`GpuError::OutputTooLarge`] past the device's limits. Cost: a reallocation and new
    /// bind groups when they grow; nothing otherwise.
    pub fn reserve(&mut self, ctx: &GpuContext, capacity: Capacity) -> Result<()> {
        if self.output.as_ref().is_some_and(|o| {
            o.capacity.vertices >= capacity.vertices && o.capacity.triangles >= capacity.triangles
        }) {
            return Ok(());
        }
        let vertex_bytes = capacity.vertices * VERTEX_STRIDE;
        let index_bytes = capacity.triangles * 12;
        let too_large = capacity.vertices > u32::MAX as u64
            || capacity.triangles > u32::MAX as u64 / 3
            || vertex_bytes.max(index_bytes) > self.buffer_limit;
        if too_large {
            return Err(GpuError::OutputTooLarge {
                vertices: capacity.vertices,
                triangles: capacity.triangles,
                bytes: vertex_bytes.max(index_bytes),
                limit: self.buffer_limit,
            });
        }
        let device = &ctx.device;
        use wgpu::BufferUsages as U;
        let usage = U::STORAGE | U::COPY_SRC;
        let vertices = buffer(device, "tessera vertices", vertex_bytes, usage | U::VERTEX);
        let indices = buffer(device, "tessera indices", index_bytes, usage | U::INDEX);
        let main = self.bind_main(device, &vertices, &indices);
        self.output = Some(Output { capacity, vertices, indices, main });
        self.write_params(ctx);
        Ok(())
    }

    /// Group 0 of every tessellation pass, over the output buffers `vertices` and `indices`.
    fn bind_main(
        &self,
        device: &wgpu::Device,
        vertices: &wgpu::Buffer,
        indices: &wgpu::Buffer,
    ) -> wgpu::BindGroup {
        let s = &self.set;
        shader::bind(
            device,
            &self.pipelines.main_layout,
            &[
                &self.params,
                &s.control_points,
                &s.patch_rows,
                &s.edge_rows,
                &s.uses,
                &s.corner_rows,
                &self.segments,
                &self.interior,
                &self.visible,
                &self.vertex_offsets,
                &self.triangle_offsets,
                vertices,
                indices,
            ],
        )
    }

    /// Makes the segments buffer hold the ESC pattern's insertion grids after the plan's
    /// rows (`esc.wgsl`), binding the larger buffer. Cost: a reallocation and a bind group
    /// the first time; nothing after.
    pub(super) fn reserve_esc_grids(&mut self, ctx: &GpuContext) {
        let (e, p) = (self.set.edges as u64, self.set.patches as u64);
        let bytes = 16 * e + 4 * ESC_GRID_WORDS as u64 * p;
        if self.segments.size() >= bytes {
            return;
        }
        use wgpu::BufferUsages as U;
        self.segments = buffer(
            &ctx.device,
            "segments, factors, lattice masks and ESC grids",
            bytes,
            U::STORAGE | U::COPY_DST | U::COPY_SRC,
        );
        if let Some(out) = &self.output {
            let main = self.bind_main(&ctx.device, &out.vertices, &out.indices);
            if let Some(out) = &mut self.output {
                out.main = main;
            }
        }
    }

    /// Writes `common.wgsl`'s `Params` for the output capacity and the pattern. Cost: a
    /// 32-byte upload.
    pub(super) fn write_params(&self, ctx: &GpuContext) {
        let capacity = self.capacity().unwrap_or_default();
        let params = Params {
            edges: self.set.edges,
            patches: self.set.patches,
            corners: self.set.corners,
            vertex_capacity: capacity.vertices as u32,
            triangle_capacity: capacity.triangles as u32,
            partitioning: self.pattern.partitioning_code(),
            blocks: if self.pattern == GpuPattern::SemiUniform { self.rows.min(ROW_BLOCKS) } else { 1 },
            warped: u32::from(self.warped),
        };
        ctx.queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&params));
    }
}
