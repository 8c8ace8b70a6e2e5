//! [`GpuTessellator`]: the prepared set on the device once, a plan per frame, the frame's
//! passes recorded into the caller's command encoder.
//!
//! The passes of a frame, each one compute pass (named in [`PASSES`], timed by
//! [`PassTimer`] when the adapter has timestamp queries):
//!
//! 0. **cull** (`cull.wgsl`, with a culling camera) and **factors** (`factors.wgsl`, after
//!    [`GpuTessellator::prepare_screen`]): the visibility row and the plan's segments, real
//!    factors and interior factors from the camera alone, from view-independent rows
//!    uploaded once; for the transition and semi-uniform schemes' pixel error also the a-posteriori check
//!    (`check.wgsl`, `bounds.wgsl`): every patch bounds its pattern's triangles, and rounds
//!    that size themselves on the GPU raise interiors and edges until the bounds hold; for
//!    ESC its own planning passes (`esc_plan.wgsl`: levels per object, distance tests,
//!    insertion grids);
//! 1. **count** (`count_uniform.wgsl`, `transition.wgsl`, `semi_uniform.wgsl`, `sd2.wgsl`,
//!    `esc.wgsl`, `hardware.wgsl`): per edge and per
//!    patch, the counts `tessera::engine::Layout::build` scans, in place in the offset
//!    buffers;
//! 2. **scan** (`scan.wgsl`): exclusive scans turning them into the layout's offsets — the
//!    vertex scan over `E + P + 1` entries starting at the corner count (edge offsets, then
//!    interior offsets), the triangle scan over `P + 1`;
//! 3. **args** (`indirect_args.wgsl`): one invocation writes the write passes' dispatch
//!    arguments and the `DrawIndexedIndirect` arguments from the totals;
//! 4. **vertices** (`write_vertices.wgsl`): corners, edge samples (once per shared edge),
//!    interior vertices;
//! 5. **triangles**: indices — uniform (`write_triangles_uniform.wgsl`) and SD-2
//!    (`sd2.wgsl`) one invocation per triangle (then the patches at a collapsed corner one
//!    invocation each); transition (`transition.wgsl`) one invocation per patch walking its
//!    core and strips in the CPU's order; semi-uniform (`semi_uniform.wgsl`) up to
//!    [`ROW_BLOCKS`] invocations per patch, each a block of its dyadic grid's rows; the
//!    Direct3D 11 partitionings (`hardware.wgsl`) one
//!    invocation per patch walking its rings and stitches in the CPU's order (parallel over
//!    patches only: the next step is a per-triangle form); ESC (`esc.wgsl`) one invocation
//!    per patch walking its coarse triangles' strips; then, when strips are on
//!    ([`GpuTessellator::set_strips`]), SD-2's and ESC's strips (`strips.wgsl`: count, scan,
//!    arguments, write).
//!
//! **No read-back in the frame path, by construction**: [`GpuTessellator::record`] only
//! records compute passes; the buffers it writes are read by the GPU (indirect dispatch and
//! draw). The only `map_async` of the crate is in [`crate::readback`], which
//! [`GpuTessellator::read_mesh`], [`GpuTessellator::read_layout`] and
//! [`PassTimer::read`] use on request.
//!
//! The engine's parts, one file each: [`Pipelines`] and [`GpuPattern`] (`pipelines.rs`:
//! which shader files make which pipeline), [`Capacity`] and the output buffers' growth
//! (`capacity.rs`), recording the passes (`frame.rs`), planning from the camera
//! ([`ScreenCriterion`], `screen.rs`), what the check achieved ([`ScreenReport`],
//! `report.rs`) and [`PassTimer`] (`timer.rs`). This file holds [`GpuTessellator`] itself:
//! its buffers, the uploads of a plan and the read-backs.

use crate::context::GpuContext;
use crate::error::{GpuError, Result};
use crate::readback;
use crate::scan::Scan;
use crate::shader;
use crate::upload::GpuSet;
use tessera::camera::Camera;
use tessera::criterion::Plan;
use tessera::mesh::Mesh;
use tessera::pattern::hardware::Partitioning;
use tessera::pattern::Pattern;
use tessera::sampling::SamplingKind;
use tessera::surface::SurfaceSet;

mod capacity;
mod esc;
mod frame;
mod pipelines;
mod report;
mod screen;
mod strips;
mod timer;

pub use capacity::Capacity;
pub use frame::{DEFAULT_CHECK_ROUNDS, MAX_CHECK_ROUNDS, PASSES};
pub use pipelines::{GpuPattern, Pipelines, ROW_BLOCKS, STORAGE_BUFFERS};
pub use report::ScreenReport;
pub use screen::{ScreenCriterion, CHECK_MAX_FACTOR};
pub use timer::PassTimer;

pub(crate) use pipelines::Params;
pub(crate) use screen::PATCH_VIEW_ROW;
// For the contract test (`crate::contract`), which checks them against the WGSL.
#[cfg(test)]
pub(crate) use {
    pipelines::constants,
    report::{CheckRow, FrameState},
    screen::ViewUniform,
};

use screen::{Screen, ViewBuffers};

/// f32 per output vertex: position (3), normal (3), uv (2).
pub const VERTEX_FLOATS: u32 = 8;

/// Bytes per output vertex.
pub const VERTEX_STRIDE: u64 = 4 * VERTEX_FLOATS as u64;

/// The vertex buffer's layout for a render pipeline: position at location 0, normal at 1, uv
/// at 2 (all f32), [`VERTEX_STRIDE`] bytes a vertex. Indices are u32.
pub const VERTEX_LAYOUT: wgpu::VertexBufferLayout<'static> = wgpu::VertexBufferLayout {
    array_stride: VERTEX_STRIDE,
    step_mode: wgpu::VertexStepMode::Vertex,
    attributes: &wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32x2],
};

/// Checks a hardware plan against what the factor processing on the GPU (and the CPU
/// pattern) assumes: every factor a finite positive number (WGSL may assume no NaN or
/// infinity; the CPU pattern refuses a factor that is not positive), every edge cut into
/// [`tessera::pattern::hardware::edge_segments`] of its factor (the CPU pattern's
/// precondition). Cost: O(E).
fn check_hardware_plan(plan: &Plan, partitioning: Partitioning) -> Result<()> {
    for (e, (&s, &f)) in plan.segments.iter().zip(&plan.factors).enumerate() {
        if !(f.is_finite() && f > 0.0) {
            return Err(GpuError::Unsupported {
                what: format!("edge {e}'s factor {f} (the hardware patterns take finite positive factors)"),
            });
        }
        let cut = tessera::pattern::hardware::edge_segments(f as f64, partitioning);
        if s != cut {
            return Err(tessera::Error::PlanMismatch {
                what: format!(
                    "edge {e}: {s} segments for the factor {f}, which {} cuts into {cut}",
                    partitioning.name()
                ),
            }
            .into());
        }
    }
    Ok(())
}

/// The semi-uniform pattern's preconditions on `plan` (`tessera::pattern::semi_uniform::
/// SemiUniform`, [`tessera::pattern::semi_uniform::check_input`]) for every visible patch
/// (every patch with `all_visible`, when the GPU culls and may draw a patch the plan left
/// out), which the shaders rely on; returns the largest patch level `n` (the most rows of a
/// patch). Errors: [`tessera::Error::PlanMismatch`] naming the first patch that breaks one.
/// Cost: O(P).
fn check_semi_uniform_plan(set: &SurfaceSet, plan: &Plan, all_visible: bool) -> Result<u32> {
    let mut rows = 1;
    for p in (0..set.patches.len()).filter(|&p| all_visible || plan.is_visible(p)) {
        let input = tessera::engine::layout::pattern_input(set, plan, p);
        if let Err(why) = tessera::pattern::semi_uniform::check_input(&input) {
            return Err(tessera::Error::PlanMismatch { what: format!("patch {p}: {why}") }.into());
        }
        rows = rows.max(input.interior[0]);
    }
    Ok(rows)
}

/// Buffers whose size depends on the output capacity, and their bind groups.
#[derive(Debug)]
struct Output {
    capacity: Capacity,
    vertices: wgpu::Buffer,
    indices: wgpu::Buffer,
    main: wgpu::BindGroup,
}

/// The GPU engine for one surface set: uploads the set once, then tessellates a plan per
/// frame into device buffers that a render pipeline binds directly (see the module doc for
/// the passes).
///
/// Supported on every patch kind (bicubic, Bézier triangles, PN triangles, subdivision
/// patches): [`SamplingKind::Uniform`] plans for the uniform pattern (every edge of a visible
/// patch cut into its interior factor, as `Scheme::Uniform` plans are), the transition pattern
/// (any per-edge segments and core factors, as `Scheme::Transition` plans) and the
/// semi-uniform pattern (powers of two, as `Scheme::SemiUniform` plans); and
/// `SamplingKind::Fractional(Spacing::Hardware(p))` plans for the Direct3D 11 pattern of
/// partitioning `p` (real per-edge factors, as `Scheme::Hardware(p)` plans). On triangles,
/// SD-2 plans (`SamplingKind::Fractional(Spacing::Symmetric)`, or `Warped`); on bicubic
/// patches, ESC plans (`SamplingKind::Lattice`, with the pattern's insertion grids). Anything
/// else is refused with [`GpuError::Unsupported`].
#[derive(Debug)]
pub struct GpuTessellator {
    set: GpuSet,
    pipelines: std::sync::Arc<Pipelines>,
    params: wgpu::Buffer,
    segments: wgpu::Buffer,
    interior: wgpu::Buffer,
    visible: wgpu::Buffer,
    vertex_offsets: wgpu::Buffer,
    triangle_offsets: wgpu::Buffer,
    vertex_scan: Scan,
    triangle_scan: Scan,
    draw_args: wgpu::Buffer,
    dispatch_args: wgpu::Buffer,
    status: wgpu::Buffer,
    args: wgpu::BindGroup,
    output: Option<Output>,
    /// The last prepared plan's pattern.
    pattern: GpuPattern,
    /// The view passes' buffers and bind group (`view.wgsl`).
    view: ViewBuffers,
    /// The camera the GPU culls for (and, with `screen`, plans for), if any.
    camera: Option<Camera>,
    /// The pixel-error criterion, when the GPU computes the factors from the camera.
    screen: Option<Screen>,
    /// The largest buffer the device binds or allocates.
    buffer_limit: u64,
    /// Fix rounds of the a-posteriori check a frame records ([`DEFAULT_CHECK_ROUNDS`] unless set).
    check_rounds: u32,
    /// Whether the adapter's shader compiler stops long loops ([`loop_limited`]).
    loop_limited: bool,
    /// Whether the SD-2 plan is reverse-projected (`Params::warped`).
    warped: bool,
    /// The semi-uniform pattern's largest patch level in the plan (its cap when the GPU plans):
    /// the most rows a patch has, which bounds `Params::blocks`.
    rows: u32,
    /// An ESC plan's pattern triangles per patch (the read-back's count of triangles left out
    /// at collapsed curves: the ESC pattern is not the plan's alone).
    esc_triangles: Option<Vec<u32>>,
    /// The strip output, when on ([`GpuTessellator::set_strips`]).
    strips: Option<strips::StripBuffers>,
}

/// The loop iterations one invocation gets in all on Mesa's llvmpipe (lavapipe): its compiler
/// ends every loop of an invocation once their iterations add up to this (a guard against
/// endless loops), whatever the shader says.
pub const LOOP_LIMIT: u32 = 65_535;

/// The largest transition factor whose pattern one invocation walks within [`LOOP_LIMIT`]
/// (`n² + 9n` iterations at factor `n`, with room to spare).
pub const LOOP_LIMITED_TRANSITION_FACTOR: u32 = 240;

/// Whether `info` is an adapter that limits loops to [`LOOP_LIMIT`] iterations an invocation:
/// Mesa's software drivers (llvmpipe, which lavapipe is). Hardware drivers run loops to the
/// end.
pub fn loop_limited(info: &wgpu::AdapterInfo) -> bool {
    info.name.contains("llvmpipe") || info.driver.contains("llvmpipe")
}

fn buffer(device: &wgpu::Device, label: &str, size: u64, usage: wgpu::BufferUsages) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: size.max(4),
        usage,
        mapped_at_creation: false,
    })
}

impl GpuTessellator {
    /// Uploads `set` (see [`crate::upload`]) and compiles the frame's pipelines.
    ///
    /// Errors: [`GpuError::Unsupported`] for an adapter with fewer than [`STORAGE_BUFFERS`]
    /// storage buffers per shader stage (checked before any pipeline is made). Cost: O(P + E)
    /// packing, one upload, and [`Pipelines::new`]'s compilations (a second or more on
    /// lavapipe; [`GpuTessellator::with_pipelines`] shares them instead).
    pub fn new(ctx: &GpuContext, set: &SurfaceSet) -> Result<GpuTessellator> {
        Pipelines::check_limits(ctx)?;
        Self::with_pipelines(ctx, set, std::sync::Arc::new(Pipelines::new(&ctx.device)))
    }

    /// [`GpuTessellator::new`] with pipelines compiled before on the same device. Errors as
    /// `new`. Cost: O(P + E) packing and one upload.
    pub fn with_pipelines(
        ctx: &GpuContext,
        set: &SurfaceSet,
        pipelines: std::sync::Arc<Pipelines>,
    ) -> Result<GpuTessellator> {
        Pipelines::check_limits(ctx)?;
        let device = &ctx.device;
        let gpu_set = GpuSet::new(device, set)?;
        let (e, p) = (gpu_set.edges as u64, gpu_set.patches as u64);
        use wgpu::BufferUsages as U;
        let plan_usage = U::STORAGE | U::COPY_DST | U::COPY_SRC;
        let layout_usage = U::STORAGE | U::COPY_SRC;
        let vertex_offsets = buffer(device, "vertex offsets", 4 * (e + p + 1), layout_usage);
        let triangle_offsets = buffer(device, "triangle offsets", 4 * (p + 1), layout_usage);
        let vertex_scan =
            Scan::new(device, &pipelines.scan, &vertex_offsets, (e + p + 1) as u32, gpu_set.corners);
        let triangle_scan = Scan::new(device, &pipelines.scan, &triangle_offsets, (p + 1) as u32, 0);
        let draw_args = buffer(device, "draw indexed indirect", 20, U::STORAGE | U::INDIRECT | U::COPY_SRC);
        let dispatch_args = buffer(device, "write dispatches", 48, U::STORAGE | U::INDIRECT);
        let status = buffer(device, "status", 16, U::STORAGE | U::COPY_SRC);
        let args = shader::bind(device, &pipelines.args_layout, &[&draw_args, &dispatch_args, &status]);
        let view = ViewBuffers::new(device, &pipelines.view_layout, &pipelines.rounds_layout, set);
        Ok(GpuTessellator {
            params: buffer(device, "params", std::mem::size_of::<Params>() as u64, U::UNIFORM | U::COPY_DST),
            // The plan's segments, then its factors (`common.wgsl`'s `edge_factor`), then its
            // depths (`sd2.wgsl`'s `edge_depths`, warped plans).
            segments: buffer(device, "segments, factors and depths", 16 * e, plan_usage),
            interior: buffer(device, "interior", 8 * p, plan_usage),
            visible: buffer(device, "visible", 4 * p, plan_usage),
            vertex_offsets,
            triangle_offsets,
            vertex_scan,
            triangle_scan,
            draw_args,
            dispatch_args,
            status,
            args,
            output: None,
            pattern: GpuPattern::Uniform,
            view,
            camera: None,
            screen: None,
            buffer_limit: ctx.limits.max_buffer_size.min(ctx.limits.max_storage_buffer_binding_size),
            check_rounds: DEFAULT_CHECK_ROUNDS,
            loop_limited: loop_limited(&ctx.info),
            rows: 1,
            warped: false,
            esc_triangles: None,
            strips: None,
            set: gpu_set,
            pipelines,
        })
    }

    /// Uploads `plan` (made for `pattern`: the uniform, the transition, the semi-uniform, a
    /// hardware, the SD-2 or the ESC pattern)
    /// for the next [`GpuTessellator::record`] (ending [`GpuTessellator::prepare_screen`]'s
    /// own planning), growing the output buffers to its worst case ([`Capacity::of_plan`])
    /// when they are too small.
    ///
    /// Preconditions: `plan` was made for `set`, the set given to [`GpuTessellator::new`].
    /// Errors: [`tessera::Error::PlanMismatch`] for a plan of another set, or a hardware plan
    /// whose segments are not its factors' (`tessera::pattern::hardware::edge_segments`, the
    /// CPU pattern's precondition); [`GpuError::Unsupported`] for another pattern, a plan
    /// that is not uniform per patch (uniform pattern), a sampling kind that is not the
    /// pattern's ([`SamplingKind::Uniform`] for the integer patterns,
    /// `SamplingKind::Fractional(Spacing::Hardware(p))` of the pattern's own partitioning for
    /// a hardware pattern), a factor that is not a finite positive number, or a patch with a
    /// corner pinched at a cage's valence-2 vertex that the pattern would not cut as the CPU
    /// does (`tessera::scheme::pinched_beyond_the_gpu`);
    /// [`GpuError::OutputTooLarge`] when the worst case exceeds the u32 index range or the
    /// device's buffer limits (nothing is dropped). Cost: O(E + P) and an upload of the plan's
    /// arrays (16 bytes a patch, 8 an edge); a reallocation when the output grows; on the
    /// first hardware plan, the compilation of its pipelines.
    pub fn prepare(
        &mut self,
        ctx: &GpuContext,
        set: &SurfaceSet,
        plan: &Plan,
        pattern: &dyn Pattern,
    ) -> Result<()> {
        plan.check(set)?;
        let Some(kind) = GpuPattern::of(pattern) else {
            return Err(GpuError::Unsupported {
                what: format!(
                    "the {} pattern (uniform, transition, semi-uniform, SD-2, ESC and the Direct3D 11 partitionings integer, \
                     pow2, fractional_odd and fractional_even are on the GPU)",
                    pattern.name()
                ),
            });
        };
        if set.patches.len() as u32 != self.set.patches || set.topology.edges.len() as u32 != self.set.edges {
            return Err(
                tessera::Error::PlanMismatch { what: "a set other than the tessellator's".into() }.into()
            );
        }
        if let Some(p) = tessera::scheme::pinched_beyond_the_gpu(set, pattern.cut_through_corners_0_and_2()) {
            return Err(GpuError::Unsupported { what: tessera::scheme::pinched_on_gpu(p) });
        }
        // The per-patch patterns the GPU draws: SD-2's reverse projection, whose corner depths
        // are the plan's edge depths at the patch's corners (`sd2.wgsl`), and ESC, whose
        // insertion grids are uploaded with the plan (`esc.wgsl`).
        let warped = kind == GpuPattern::Sd2 && plan.kind == SamplingKind::Warped;
        if pattern.depends_on_patch() && !warped && kind != GpuPattern::Esc {
            return Err(GpuError::Unsupported {
                what: format!("the {} pattern with per-patch data", pattern.name()),
            });
        }
        let expected_kind = if warped { SamplingKind::Warped } else { kind.sampling_kind() };
        if plan.kind != expected_kind {
            return Err(GpuError::Unsupported {
                what: format!("{:?} samplings with the {} pattern", plan.kind, pattern.name()),
            });
        }
        if let GpuPattern::Hardware(p) = kind {
            check_hardware_plan(plan, p)?;
        }
        let rows = if kind == GpuPattern::SemiUniform {
            check_semi_uniform_plan(set, plan, self.camera.is_some())?
        } else {
            1
        };
        if kind == GpuPattern::Sd2 {
            self.check_sd2_plan(set, plan)?;
        }
        let esc = if kind == GpuPattern::Esc {
            if self.camera.is_some() {
                return Err(GpuError::Unsupported {
                    what: "ESC with a culling camera (ESC culls nothing; prepare without one)".into(),
                });
            }
            Some(esc::pack(set, plan, pattern)?)
        } else {
            None
        };
        for (p, &[n, _]) in plan.interior.iter().enumerate() {
            let edges = &set.topology.patch_edges[p][..set.patches[p].domain().corner_count()];
            if kind == GpuPattern::Uniform
                && (self.camera.is_some() || plan.is_visible(p))
                && edges.iter().any(|pe| plan.segments[pe.edge as usize] != n)
            {
                return Err(GpuError::Unsupported {
                    what: format!(
                        "patch {p}: edges cut unlike its interior (only the uniform pattern is on the GPU)"
                    ),
                });
            }
        }
        if kind == GpuPattern::Transition {
            let largest = plan.segments.iter().chain(plan.interior.iter().flatten()).copied().max();
            self.check_loop_budget(largest.unwrap_or(1))?;
        }
        let capacity = Capacity::of_plan(set, plan, pattern, self.camera.is_some());
        self.reserve(ctx, capacity)?;
        self.pipelines.compile(&ctx.device, kind);
        if self.strips.is_some() {
            self.pipelines.strips(&ctx.device, kind);
        }
        if self.set.has_trees {
            self.pipelines.with_trees(&ctx.device, kind);
        }
        self.screen = None;
        self.pattern = kind;
        self.rows = rows;
        if esc.is_some() {
            self.reserve_esc_grids(ctx);
        }
        let queue = &ctx.queue;
        queue.write_buffer(&self.segments, 0, bytemuck::cast_slice(&plan.segments));
        queue.write_buffer(&self.segments, 4 * self.set.edges as u64, bytemuck::cast_slice(&plan.factors));
        if warped {
            queue.write_buffer(&self.segments, 8 * self.set.edges as u64, bytemuck::cast_slice(&plan.depths));
        }
        self.warped = warped;
        if let Some(esc) = &esc {
            let e = self.set.edges as u64;
            queue.write_buffer(&self.segments, 8 * e, bytemuck::cast_slice(&esc.masks));
            queue.write_buffer(&self.segments, 16 * e, bytemuck::cast_slice(&esc.grids));
        }
        self.esc_triangles = esc.map(|esc| esc.triangles);
        queue.write_buffer(&self.interior, 0, bytemuck::cast_slice(&plan.interior));
        queue.write_buffer(&self.visible, 0, bytemuck::cast_slice(&plan.visible));
        self.write_params(ctx);
        Ok(())
    }

    /// The SD-2 pattern's preconditions on `plan` (`tessera::pattern::sd2::Sd2`), which the
    /// shaders rely on: every edge's segments those of its factor's symmetric cut
    /// ([`tessera::sampling::symmetric_segments`], the sampling the plan's kind names), every
    /// visible patch (every patch when the GPU culls) with at most two different factors (the CPU pattern falls back to the
    /// transition pattern for three; the SD-2 criterion never makes them), and on an adapter
    /// that stops loops ([`loop_limited`]) no patch at a collapsed corner, whose triangles
    /// one invocation walks, past [`LOOP_LIMIT`] triangles. Errors:
    /// [`tessera::Error::PlanMismatch`] or [`GpuError::Unsupported`] naming the edge or patch.
    /// Cost: O(E + P).
    fn check_sd2_plan(&self, set: &SurfaceSet, plan: &Plan) -> Result<()> {
        for (e, (&s, &f)) in plan.segments.iter().zip(&plan.factors).enumerate() {
            let cut = tessera::sampling::symmetric_segments(f as f64);
            let depths = plan.depths.get(e).copied().unwrap_or([1.0; 2]);
            if !depths.iter().all(|&z| z.is_finite() && z > 0.0) {
                return Err(tessera::Error::PlanMismatch {
                    what: format!("edge {e}: the depths {depths:?} (a warped plan's are positive)"),
                }
                .into());
            }
            if !(f.is_finite() && f >= 1.0) || s != cut {
                return Err(tessera::Error::PlanMismatch {
                    what: format!("edge {e}: {s} segments for the factor {f}, which SD-2 cuts into {cut}"),
                }
                .into());
            }
        }
        let all_visible = self.camera.is_some();
        for p in (0..set.patches.len()).filter(|&p| all_visible || plan.is_visible(p)) {
            let input = tessera::engine::layout::pattern_input(set, plan, p);
            let f = input.factors;
            if input.domain != tessera::surface::Domain::Tri || (f[0] != f[1] && f[1] != f[2] && f[2] != f[0])
            {
                return Err(GpuError::Unsupported {
                    what: format!(
                        "patch {p} with the SD-2 pattern: a quad or three different factors {:?} (SD-2 takes \
                         triangles with at most two)",
                        &f[..input.domain.corner_count()]
                    ),
                });
            }
            let triangles = tessera::pattern::sd2::Sd2::default().counts(&input).1;
            if self.loop_limited
                && tessera::engine::layout::has_repeated_corner(set, p)
                && triangles > LOOP_LIMIT
            {
                return Err(GpuError::Unsupported {
                    what: format!(
                        "patch {p}'s {triangles} SD-2 triangles at a collapsed corner on this adapter: its shader \
                         compiler stops every loop of an invocation after {LOOP_LIMIT} iterations (use lower factors \
                         or a hardware GPU)"
                    ),
                });
            }
        }
        Ok(())
    }

    /// Refuses transition factors past [`LOOP_LIMITED_TRANSITION_FACTOR`] on an adapter that
    /// stops loops ([`loop_limited`]): one invocation walks a patch's whole transition pattern
    /// (about `n² + 9n` loop iterations at factor `n`), and such a driver would silently
    /// leave the rest of the pattern unwritten. Cost: O(1).
    fn check_loop_budget(&self, largest_factor: u32) -> Result<()> {
        if self.loop_limited && largest_factor > LOOP_LIMITED_TRANSITION_FACTOR {
            return Err(GpuError::Unsupported {
                what: format!(
                    "transition factors up to {largest_factor} on this adapter: its shader compiler stops \
                     every loop of an invocation after {LOOP_LIMIT} iterations in all, which a patch past \
                     factor {LOOP_LIMITED_TRANSITION_FACTOR} needs (use a lower --max-factor or a hardware GPU)"
                ),
            });
        }
        Ok(())
    }

    /// The control points the frame reads ([`crate::upload`]'s layout): what a pass that
    /// moves the surface ([`crate::GpuStencils`]) writes.
    pub(crate) fn control_points(&self) -> &wgpu::Buffer {
        &self.set.control_points
    }

    /// How many patches the tessellator was made for, and where their trees' blocks are in
    /// [`GpuTessellator::control_points`] ([`crate::upload::PackedSet::tree_blocks`]).
    pub(crate) fn layout(&self) -> (u32, &[(usize, u32)]) {
        (self.set.patches, &self.set.tree_blocks)
    }

    /// Reads the plan the last frame drew back from the device: the uploaded one, or the
    /// GPU's own after [`GpuTessellator::prepare_screen`] (segments, interior factors and
    /// visibility; for the hardware patterns the real factors and the
    /// `SamplingKind::Fractional` kind, for the others `factors` are the segments). For
    /// tests and statistics. Cost: a queue wait.
    pub fn read_plan(&self, ctx: &GpuContext) -> Result<Plan> {
        let (e, p) = (self.set.edges as usize, self.set.patches as usize);
        let rows: Vec<u32> = readback::read(ctx, &self.segments, 4 * e)?;
        let interior: Vec<[u32; 2]> = readback::read(ctx, &self.interior, p)?;
        let mut plan = Plan::integer(rows[..e].to_vec(), interior, p);
        plan.kind = if self.warped { SamplingKind::Warped } else { self.pattern.sampling_kind() };
        if plan.kind != SamplingKind::Uniform {
            plan.factors = rows[e..2 * e].iter().map(|&bits| f32::from_bits(bits)).collect();
        }
        if self.warped {
            let depth = |k: usize| f32::from_bits(rows[2 * e + k]);
            plan.depths = (0..e).map(|i| [depth(2 * i), depth(2 * i + 1)]).collect();
        }
        if plan.kind == SamplingKind::Lattice {
            // ESC: each edge's numerators from its lattice mask (`esc.wgsl`).
            for &mask in &rows[2 * e..3 * e] {
                plan.lattice_offsets.push(plan.lattice.len() as u32);
                plan.lattice.extend((0..32).filter(|k| mask >> k & 1 != 0));
            }
        }
        plan.visible = self.read_visible(ctx)?;
        Ok(plan)
    }

    /// Reads an ESC frame's insertion grids back as the CPU's pattern (with
    /// [`GpuTessellator::read_plan`], what the CPU engine draws for comparison). Errors:
    /// [`GpuError::Unsupported`] when the last frame was not ESC's. Cost: a queue wait and
    /// O(P · (3n + 1)²).
    pub fn read_esc_pattern(&self, ctx: &GpuContext) -> Result<tessera::pattern::esc::Esc> {
        if self.pattern != GpuPattern::Esc {
            return Err(GpuError::Unsupported {
                what: "reading ESC grids of a frame of another pattern".into(),
            });
        }
        let (e, p) = (self.set.edges as usize, self.set.patches as usize);
        let words = pipelines::ESC_GRID_WORDS as usize;
        let rows: Vec<u32> = readback::read(ctx, &self.segments, 4 * e + words * p)?;
        let interior: Vec<[u32; 2]> = readback::read(ctx, &self.interior, p)?;
        Ok(esc::unpack(&rows[4 * e..], &interior))
    }

    /// Reads the plan's visibility row back (the GPU's, when it culls). For tests. Cost: a
    /// queue wait.
    pub fn read_visible(&self, ctx: &GpuContext) -> Result<Vec<u32>> {
        readback::read(ctx, &self.visible, self.set.patches as usize)
    }

    /// The vertex buffer ([`VERTEX_LAYOUT`]); usages VERTEX, STORAGE, COPY_SRC. None before
    /// the first [`GpuTessellator::prepare`]. It may be replaced by a larger one when a
    /// later plan needs more room.
    pub fn vertex_buffer(&self) -> Option<&wgpu::Buffer> {
        self.output.as_ref().map(|o| &o.vertices)
    }

    /// The u32 index buffer, a triangle list; usages INDEX, STORAGE, COPY_SRC.
    pub fn index_buffer(&self) -> Option<&wgpu::Buffer> {
        self.output.as_ref().map(|o| &o.indices)
    }

    /// `DrawIndexedIndirectArgs` (20 bytes at offset 0) for
    /// `RenderPass::draw_indexed_indirect`; usages INDIRECT, STORAGE, COPY_SRC.
    pub fn indirect_buffer(&self) -> &wgpu::Buffer {
        &self.draw_args
    }

    /// The output capacity, once prepared.
    pub fn capacity(&self) -> Option<Capacity> {
        self.output.as_ref().map(|o| o.capacity)
    }

    /// Reads the frame's status back: `(overflowed, vertices, triangles)`. For tests and
    /// statistics. Cost: a queue wait.
    pub fn read_status(&self, ctx: &GpuContext) -> Result<(bool, u32, u32)> {
        let s: Vec<u32> = readback::read(ctx, &self.status, 4)?;
        Ok((s[0] != 0, s[1], s[2]))
    }

    /// Reads the GPU's layout back as `(edge_offsets, interior_offsets, triangle_offsets)`,
    /// to compare with [`tessera::engine::Layout`]. Cost: a queue wait.
    pub fn read_layout(&self, ctx: &GpuContext) -> Result<(Vec<u32>, Vec<u32>, Vec<u32>)> {
        let (e, p) = (self.set.edges as usize, self.set.patches as usize);
        let v: Vec<u32> = readback::read(ctx, &self.vertex_offsets, e + p + 1)?;
        let t: Vec<u32> = readback::read(ctx, &self.triangle_offsets, p + 1)?;
        Ok((v[..=e].to_vec(), v[e..].to_vec(), t))
    }

    /// Reads the frame's mesh back into a [`Mesh`] (positions, normals, uvs, indices, the
    /// patch of every triangle and vertex derived from the layout). For tests and the
    /// command-line tool, never for a frame loop. Errors with [`GpuError::OutputTooLarge`] if
    /// the frame overflowed. Cost: a queue wait and a copy of the whole output.
    pub fn read_mesh(&self, ctx: &GpuContext, set: &SurfaceSet) -> Result<Mesh> {
        let (overflow, vertices, triangles) = self.read_status(ctx)?;
        let Some(out) = &self.output else { return Ok(Mesh::default()) };
        if overflow {
            return Err(GpuError::OutputTooLarge {
                vertices: vertices as u64,
                triangles: triangles as u64,
                bytes: vertices as u64 * VERTEX_STRIDE,
                limit: out.capacity.vertices * VERTEX_STRIDE,
            });
        }
        let raw: Vec<f32> = readback::read(ctx, &out.vertices, vertices as usize * VERTEX_FLOATS as usize)?;
        let indices: Vec<u32> = readback::read(ctx, &out.indices, 3 * triangles as usize)?;
        let (edge_offsets, interior_offsets, triangle_offsets) = self.read_layout(ctx)?;
        let mut mesh = Mesh { indices, ..Default::default() };
        for v in raw.chunks_exact(VERTEX_FLOATS as usize) {
            mesh.positions.push([v[0], v[1], v[2]]);
            mesh.normals.push([v[3], v[4], v[5]]);
            mesh.uvs.push([v[6], v[7]]);
        }
        // Which patch evaluated each vertex and owns each triangle: the layout's ranges.
        let topo = &set.topology;
        mesh.vertex_patch = topo.corner_entries.iter().map(|c| c.owner_patch).collect();
        for (e, w) in edge_offsets.windows(2).enumerate() {
            let uses = topo.edge_uses(e);
            for k in 0..w[1] - w[0] {
                let inner = (w[1] - w[0]) / topo.edges[e].variants.max(1) as u32;
                let variant = k / inner.max(1);
                let u = uses.iter().find(|u| u.variant as u32 == variant).unwrap_or(&uses[0]);
                mesh.vertex_patch.push(u.patch);
            }
        }
        for (p, w) in interior_offsets.windows(2).enumerate() {
            mesh.vertex_patch.extend(std::iter::repeat_n(p as u32, (w[1] - w[0]) as usize));
        }
        for (p, w) in triangle_offsets.windows(2).enumerate() {
            mesh.triangle_patch.extend(std::iter::repeat_n(p as u32, (w[1] - w[0]) as usize));
        }
        // The pattern's triangles left out at collapsed curves, as `Layout` reports them.
        let plan = self.read_plan(ctx)?;
        // ESC planned on the GPU: its pattern is the grids it made.
        let read_back: Vec<u32>;
        let esc_triangles: &[u32] = match (&self.esc_triangles, self.pattern) {
            (Some(t), _) => t,
            (None, GpuPattern::Esc) => {
                let esc = self.read_esc_pattern(ctx)?;
                read_back = (0..set.patches.len()).map(|p| esc.triangles(p)).collect();
                &read_back
            }
            (None, _) => &[],
        };
        let pattern_triangles = |p: usize| match self.pattern.cpu_pattern() {
            Some(kind) => kind.counts(&tessera::engine::layout::pattern_input(set, &plan, p)).1 as u64,
            None => esc_triangles[p] as u64,
        };
        let pattern: u64 =
            (0..set.patches.len()).filter(|&p| plan.is_visible(p)).map(pattern_triangles).sum();
        mesh.collapsed_triangles = (pattern - triangles as u64) as usize;
        mesh.strips = self.read_strips(ctx)?;
        Ok(mesh)
    }
}
