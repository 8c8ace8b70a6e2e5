//! [`GpuTessellator`]: the prepared set on the device once, a plan per frame, the frame's
//! passes recorded into the caller's command encoder.
//!
//! The passes of a frame, each one compute pass (named in [`PASSES`], timed by
//! [`PassTimer`] when the adapter has timestamp queries):
//!
//! 0. **cull** (`cull.wgsl`, with a culling camera) and **factors** (`factors.wgsl`, after
//!    [`GpuTessellator::prepare_screen`]): the visibility row and the plan's segments, real
//!    factors and interior factors from the camera alone, from view-independent rows
//!    uploaded once; for the transition scheme's pixel error also the a-posteriori check
//!    (`check.wgsl`, `bounds.wgsl`): every patch bounds its pattern's triangles, and rounds
//!    that size themselves on the GPU raise interiors and edges until the bounds hold;
//! 1. **count** (`count_uniform.wgsl`, `transition.wgsl`, `hardware.wgsl`): per edge and per
//!    patch, the counts `tessera::engine::Layout::build` scans, in place in the offset
//!    buffers;
//! 2. **scan** (`scan.wgsl`): exclusive scans turning them into the layout's offsets — the
//!    vertex scan over `E + P + 1` entries starting at the corner count (edge offsets, then
//!    interior offsets), the triangle scan over `P + 1`;
//! 3. **args** (`indirect_args.wgsl`): one invocation writes the write passes' dispatch
//!    arguments and the `DrawIndexedIndirect` arguments from the totals;
//! 4. **vertices** (`write_vertices.wgsl`): corners, edge samples (once per shared edge),
//!    interior vertices;
//! 5. **triangles**: indices — uniform (`write_triangles_uniform.wgsl`) one invocation per
//!    triangle; transition (`transition.wgsl`) one invocation per patch walking its core
//!    and strips in the CPU's order; the Direct3D 11 partitionings (`hardware.wgsl`) one
//!    invocation per patch walking its rings and stitches in the CPU's order (parallel over
//!    patches only: the next step is a per-triangle form).
//!
//! **No read-back in the frame path, by construction**: [`GpuTessellator::record`] only
//! records compute passes; the buffers it writes are read by the GPU (indirect dispatch and
//! draw). The only `map_async` of the crate is in [`crate::readback`], which
//! [`GpuTessellator::read_mesh`], [`GpuTessellator::read_layout`] and
//! [`PassTimer::read`] use on request.

use crate::context::GpuContext;
use crate::error::{GpuError, Result};
use crate::readback;
use crate::scan::{Scan, ScanPipelines};
use crate::shader::{self, Binding};
use crate::upload::{self, GpuSet};
use tessera::camera::Camera;
use tessera::criterion::view::ViewCriterion;
use tessera::criterion::Plan;
use tessera::mesh::Mesh;
use tessera::pattern::hardware::{Hardware, Partitioning};
use tessera::pattern::transition::Transition;
use tessera::pattern::uniform::Uniform;
use tessera::pattern::Pattern;
use tessera::sampling::{SamplingKind, Spacing};
use tessera::scheme::{Criterion, Prepared, Scheme};
use tessera::surface::SurfaceSet;

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

/// The compute passes of a frame, in order ("cull" only with a culling camera,
/// [`GpuTessellator::set_cull_camera`]; "factors" only with factors from the camera,
/// [`GpuTessellator::prepare_screen`]).
pub const PASSES: [&str; 7] = ["cull", "factors", "count", "scan", "args", "vertices", "triangles"];

/// The CPU↔GPU contract test (the uniform structs against their WGSL).
#[cfg(test)]
#[path = "contract.rs"]
mod contract;

const COMMON: &str = include_str!("../shaders/common.wgsl");
const BICUBIC: &str = include_str!("../shaders/bicubic.wgsl");
const BEZIER_TRIANGLE: &str = include_str!("../shaders/bezier_triangle.wgsl");
const UNIFORM_GRID: &str = include_str!("../shaders/uniform_grid.wgsl");
const COUNT: &str = include_str!("../shaders/count.wgsl");
const COUNT_UNIFORM: &str = include_str!("../shaders/count_uniform.wgsl");
const WRITE_VERTICES: &str = include_str!("../shaders/write_vertices.wgsl");
const WRITE_TRIANGLES_UNIFORM: &str = include_str!("../shaders/write_triangles_uniform.wgsl");
const INDIRECT_ARGS: &str = include_str!("../shaders/indirect_args.wgsl");
const CULL: &str = include_str!("../shaders/cull.wgsl");
const VIEW: &str = include_str!("../shaders/view.wgsl");
const FACTORS: &str = include_str!("../shaders/factors.wgsl");
const TRANSITION: &str = include_str!("../shaders/transition.wgsl");
const BOUNDS: &str = include_str!("../shaders/bounds.wgsl");
const CHECK: &str = include_str!("../shaders/check.wgsl");
const LOCAL: &str = include_str!("../shaders/local.wgsl");
const GRID_VERTICES: &str = include_str!("../shaders/grid_vertices.wgsl");
const HARDWARE_PARTITION: &str = include_str!("../shaders/hardware_partition.wgsl");
const HARDWARE: &str = include_str!("../shaders/hardware.wgsl");

/// Storage buffers in group 0 (all of `common.wgsl`'s but the uniform).
const MAIN_STORAGE: u32 = 12;
/// Storage buffers in group 1 of the args pass (its outputs).
const ARGS_STORAGE: u32 = 3;
/// Storage buffers in group 1 of the view passes (`view.wgsl`).
const VIEW_STORAGE: u32 = 4;
/// Storage buffers in group 1 of the check rounds' decisions (the frame state and the rounds'
/// dispatch arguments, at the frame state's binding and one of their own).
const ROUND_STORAGE: u32 = 2;
/// `view.wgsl`'s binding of the frame state, and `check.wgsl`'s of the rounds' arguments.
const STATE_BINDING: u32 = 3;
const ROUND_ARGS_BINDING: u32 = 5;

/// Storage buffers per shader stage a frame needs: group 0's and the largest group 1. Within
/// 16, what most adapters give (not the WebGPU default of 8, which no GPU engine of this
/// shape fits: the prepared set, the plan, the layout and the outputs are 12 on their own).
pub const STORAGE_BUFFERS: u32 = MAIN_STORAGE + max_u32(ARGS_STORAGE, max_u32(VIEW_STORAGE, ROUND_STORAGE));

const fn max_u32(a: u32, b: u32) -> u32 {
    if a > b {
        a
    } else {
        b
    }
}
/// Rounds of the a-posteriori check a frame records (`check.wgsl`). The CPU's loop runs up
/// to 256 rounds but ends after a few: across every model in the shared data, 8 seeded
/// cameras at 0.25, 1 and 4 px and caps 16 and 64, the most it took was 34 (the spool at cap
/// 16, where patches at the cap miss their bound and each round moves the problem one patch
/// along the mesh; 41 on another camera in `tests/check.rs`). A round that is not needed
/// dispatches no work; a plan that needs more is reported ([`ScreenReport::converged`]).
pub const DEFAULT_CHECK_ROUNDS: u32 = 64;

/// The largest factor cap of a frame whose a-posteriori check runs on the GPU (the CPU's
/// default cap). Its shaders rely on it: a check walks strips of at most 2 · 64 steps, so the
/// loops of one invocation stay well within the 65,535 iterations lavapipe allows an
/// invocation in all (about 21,000 at the worst: 39 interior steps of four strips), and
/// `bounds.wgsl`'s test for sides along an axis tells exact arithmetic's answer in f32 only
/// while factors are at most 64.
pub const CHECK_MAX_FACTOR: u32 = 64;

/// The most fix rounds a frame may record ([`GpuTessellator::set_check_rounds`]), as many as
/// the CPU's loop runs.
pub const MAX_CHECK_ROUNDS: u32 = 256;
/// `vec4<f32>` per patch in the view passes' patch rows ([`patch_view_rows`]).
const PATCH_VIEW_ROW: u32 = 8;

/// The Direct3D 11 partitionings, in the order of their codes ([`partitioning_code`]).
const PARTITIONINGS: [Partitioning; 4] =
    [Partitioning::Integer, Partitioning::Pow2, Partitioning::FractionalOdd, Partitioning::FractionalEven];

/// The CPU pattern of each partitioning, in the same order.
static HARDWARE_PATTERNS: [Hardware; 4] = [
    Hardware { partitioning: PARTITIONINGS[0] },
    Hardware { partitioning: PARTITIONINGS[1] },
    Hardware { partitioning: PARTITIONINGS[2] },
    Hardware { partitioning: PARTITIONINGS[3] },
];

/// `Params::partitioning`'s code of `p` (`hardware_partition.wgsl`'s PARTITIONING_*).
fn partitioning_code(p: Partitioning) -> u32 {
    PARTITIONINGS.iter().position(|&q| q == p).expect("every partitioning is listed") as u32
}

/// Constants the tessellation shaders share with this crate (and with the CPU library: the
/// partitionings' ranges and the settling gap are `tessera::sampling::hardware`'s own).
pub(crate) fn constants() -> Vec<(&'static str, u32)> {
    let range = |p: Partitioning, hi: bool| {
        let (lo, top) = p.range();
        let x = if hi { top } else { lo };
        debug_assert_eq!(x.fract(), 0.0, "the hardware's factor ranges end on integers");
        x as u32
    };
    let gap_inverse = 1.0 / tessera::sampling::hardware::OUTPUT_GAP;
    debug_assert_eq!(gap_inverse.fract(), 0.0, "the settling gap is 1/n");
    vec![
        ("PATCH_ROW", upload::PATCH_ROW),
        ("EDGE_ROW", upload::EDGE_ROW),
        ("USE_ROW", upload::USE_ROW),
        ("CORNER_ROW", upload::CORNER_ROW),
        ("CONTROL_POINTS", upload::CONTROL_POINTS),
        ("VERTEX_FLOATS", VERTEX_FLOATS),
        ("PATCH_VIEW_ROW", PATCH_VIEW_ROW),
        ("EDGE_VIEW_ROW", EDGE_VIEW_ROW as u32),
        ("INTERIOR_GLOBAL", INTERIOR_GLOBAL),
        ("INTERIOR_CORE", INTERIOR_CORE),
        ("INTERIOR_MAX_EDGE", INTERIOR_MAX_EDGE),
        ("CRITERION_PIXEL_ERROR", CRITERION_PIXEL_ERROR),
        ("CRITERION_SILHOUETTENESS", CRITERION_SILHOUETTENESS),
        ("CRITERION_FIXED", CRITERION_FIXED),
        ("EDGE_RULE_INTEGER", EDGE_RULE_INTEGER),
        ("EDGE_RULE_HARDWARE", EDGE_RULE_HARDWARE),
        ("PARTITIONING_INTEGER", partitioning_code(Partitioning::Integer)),
        ("PARTITIONING_POW2", partitioning_code(Partitioning::Pow2)),
        ("PARTITIONING_FRACTIONAL_ODD", partitioning_code(Partitioning::FractionalOdd)),
        ("PARTITIONING_FRACTIONAL_EVEN", partitioning_code(Partitioning::FractionalEven)),
        ("INTEGER_LO", range(Partitioning::Integer, false)),
        ("INTEGER_HI", range(Partitioning::Integer, true)),
        ("FRACTIONAL_ODD_LO", range(Partitioning::FractionalOdd, false)),
        ("FRACTIONAL_ODD_HI", range(Partitioning::FractionalOdd, true)),
        ("FRACTIONAL_EVEN_LO", range(Partitioning::FractionalEven, false)),
        ("FRACTIONAL_EVEN_HI", range(Partitioning::FractionalEven, true)),
        ("OUTPUT_GAP_INVERSE", gap_inverse as u32),
    ]
}

fn module(device: &wgpu::Device, label: &str, parts: &[&str]) -> wgpu::ShaderModule {
    shader::module(device, label, parts, &constants())
}

/// The patterns the GPU draws.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GpuPattern {
    /// [`tessera::pattern::uniform::Uniform`]: one invocation per output triangle.
    Uniform,
    /// [`tessera::pattern::transition::Transition`] on quads and triangles (CudaTess): one
    /// invocation per patch builds its core and strips serially.
    Transition,
    /// [`tessera::pattern::hardware::Hardware`], the Direct3D 11 tessellator with one of its
    /// partitionings (`integer`, `pow2`, `fractional_odd`, `fractional_even`) on quads and
    /// triangles: one invocation per patch walks its rings and stitches serially.
    Hardware(Partitioning),
}

impl GpuPattern {
    /// The GPU form of `pattern`, by its name; None for patterns not on the GPU.
    pub fn of(pattern: &dyn Pattern) -> Option<GpuPattern> {
        match pattern.name() {
            n if n == Uniform.name() => Some(GpuPattern::Uniform),
            n if n == Transition.name() => Some(GpuPattern::Transition),
            n => PARTITIONINGS
                .into_iter()
                .find(|&p| Hardware { partitioning: p }.name() == n)
                .map(GpuPattern::Hardware),
        }
    }

    /// The CPU pattern this draws (for counts read back, [`GpuTessellator::read_mesh`]).
    fn cpu_pattern(self) -> &'static dyn Pattern {
        match self {
            GpuPattern::Uniform => &Uniform,
            GpuPattern::Transition => &Transition,
            GpuPattern::Hardware(p) => &HARDWARE_PATTERNS[partitioning_code(p) as usize],
        }
    }

    /// `Params::partitioning`: the partitioning's code, 0 for the integer patterns.
    fn partitioning_code(self) -> u32 {
        match self {
            GpuPattern::Hardware(p) => partitioning_code(p),
            _ => 0,
        }
    }
}

/// The pattern-specific pipelines: counts, vertex writes (the interior grid is the
/// pattern's), triangle writes.
#[derive(Debug)]
struct PatternPipelines {
    count: wgpu::ComputePipeline,
    corners: wgpu::ComputePipeline,
    edge_vertices: wgpu::ComputePipeline,
    interior_vertices: wgpu::ComputePipeline,
    /// Uniform: one invocation per triangle (indirect), then the collapsed-corner patches.
    /// Transition and hardware: one invocation per patch.
    triangles: wgpu::ComputePipeline,
    collapsed_triangles: Option<wgpu::ComputePipeline>,
}

/// Every compiled pipeline of a frame, independent of the set: made once per device
/// ([`Pipelines::new`]) and shared by any number of tessellators
/// ([`GpuTessellator::with_pipelines`]).
#[derive(Debug)]
pub struct Pipelines {
    main_layout: wgpu::BindGroupLayout,
    args_layout: wgpu::BindGroupLayout,
    view_layout: wgpu::BindGroupLayout,
    cull: wgpu::ComputePipeline,
    patch_proposals: wgpu::ComputePipeline,
    edge_segments: wgpu::ComputePipeline,
    interiors: wgpu::ComputePipeline,
    check: CheckPipelines,
    rounds_layout: wgpu::BindGroupLayout,
    scan: ScanPipelines,
    args: wgpu::ComputePipeline,
    uniform: PatternPipelines,
    transition: PatternPipelines,
    /// The hardware pattern's, compiled on first use ([`Pipelines::hardware`]): a frame of
    /// the integer patterns does not wait for them.
    hardware: std::sync::OnceLock<PatternPipelines>,
    main_pipeline_layout: wgpu::PipelineLayout,
}

fn compute_pipeline(
    device: &wgpu::Device,
    layout: &wgpu::PipelineLayout,
    module: &wgpu::ShaderModule,
    entry: &str,
) -> wgpu::ComputePipeline {
    device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(entry),
        layout: Some(layout),
        module,
        entry_point: Some(entry),
        compilation_options: Default::default(),
        cache: None,
    })
}

impl Pipelines {
    /// Whether `ctx`'s device can make the pipelines: [`GpuError::Unsupported`] for fewer
    /// than [`STORAGE_BUFFERS`] storage buffers per shader stage. [`Pipelines::new`] on such
    /// a device would fail wgpu's validation (a panic under wgpu's default error handler), so
    /// call this first. Cost: O(1).
    pub fn check_limits(ctx: &GpuContext) -> Result<()> {
        let have = ctx.limits.max_storage_buffers_per_shader_stage;
        if have < STORAGE_BUFFERS {
            return Err(GpuError::Unsupported {
                what: format!(
                    "an adapter with {have} storage buffers per shader stage ({STORAGE_BUFFERS} needed)"
                ),
            });
        }
        Ok(())
    }

    /// Compiles every shader of the frame on `device`. Cost: about a dozen WGSL compilations
    /// (a second or more on lavapipe).
    pub fn new(device: &wgpu::Device) -> Pipelines {
        use Binding::*;
        let mut main = vec![Uniform];
        main.extend(std::iter::repeat_n(Write, MAIN_STORAGE as usize));
        let main_layout = shader::layout(device, &main);
        let args_layout = shader::layout(device, &[Write; ARGS_STORAGE as usize]);
        let mut view = vec![Uniform];
        view.extend(std::iter::repeat_n(Write, VIEW_STORAGE as usize));
        let view_layout = shader::layout(device, &view);
        let rounds_layout = shader::layout_at(device, &[(STATE_BINDING, Write), (ROUND_ARGS_BINDING, Write)]);
        let pipeline_layout = |layouts: &[Option<&wgpu::BindGroupLayout>]| {
            device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: None,
                bind_group_layouts: layouts,
                immediate_size: 0,
            })
        };
        let one = pipeline_layout(&[Some(&main_layout)]);
        let two = pipeline_layout(&[Some(&main_layout), Some(&args_layout)]);
        let with_view = pipeline_layout(&[Some(&main_layout), Some(&view_layout)]);
        let with_rounds = pipeline_layout(&[Some(&main_layout), Some(&rounds_layout)]);
        let make = |layout: &wgpu::PipelineLayout, module: &wgpu::ShaderModule, entry: &str| {
            compute_pipeline(device, layout, module, entry)
        };
        let args = module(device, "args", &[COMMON, INDIRECT_ARGS]);
        let cull = module(device, "cull", &[COMMON, VIEW, CULL]);
        let factors = module(device, "factors", &[COMMON, VIEW, CULL, HARDWARE_PARTITION, FACTORS]);
        let uniform = {
            let count = module(device, "count uniform", &[COMMON, UNIFORM_GRID, COUNT_UNIFORM, COUNT]);
            let vertices = module(
                device,
                "vertices uniform",
                &[COMMON, BICUBIC, BEZIER_TRIANGLE, UNIFORM_GRID, GRID_VERTICES, WRITE_VERTICES],
            );
            let triangles =
                module(device, "triangles uniform", &[COMMON, UNIFORM_GRID, WRITE_TRIANGLES_UNIFORM]);
            PatternPipelines {
                count: make(&one, &count, "count"),
                corners: make(&one, &vertices, "write_corners"),
                edge_vertices: make(&one, &vertices, "write_edge_vertices"),
                interior_vertices: make(&one, &vertices, "write_interior_vertices"),
                triangles: make(&one, &triangles, "write_triangles"),
                collapsed_triangles: Some(make(&one, &triangles, "write_collapsed_patch_triangles")),
            }
        };
        let transition = {
            let pattern = module(device, "transition", &[COMMON, LOCAL, BOUNDS, TRANSITION, COUNT]);
            let vertices = module(
                device,
                "vertices transition",
                &[COMMON, BICUBIC, BEZIER_TRIANGLE, LOCAL, BOUNDS, TRANSITION, GRID_VERTICES, WRITE_VERTICES],
            );
            PatternPipelines {
                count: make(&one, &pattern, "count"),
                corners: make(&one, &vertices, "write_corners"),
                edge_vertices: make(&one, &vertices, "write_edge_vertices"),
                interior_vertices: make(&one, &vertices, "write_interior_vertices"),
                triangles: make(&one, &pattern, "write_patch_triangles"),
                collapsed_triangles: None,
            }
        };
        let check = {
            let parts = [COMMON, VIEW, CULL, HARDWARE_PARTITION, FACTORS, LOCAL, BOUNDS, TRANSITION, CHECK];
            let m = module(device, "check", &parts);
            CheckPipelines {
                check_all: make(&with_view, &m, "check_all"),
                open: make(&with_rounds, &m, "round_open"),
                resolve: make(&with_view, &m, "round_resolve"),
                close: make(&with_rounds, &m, "round_close"),
                recheck: make(&with_view, &m, "round_check"),
            }
        };
        Pipelines {
            check,
            rounds_layout,
            cull: make(&with_view, &cull, "cull"),
            patch_proposals: make(&with_view, &factors, "patch_proposals"),
            edge_segments: make(&with_view, &factors, "edge_segments"),
            interiors: make(&with_view, &factors, "interiors"),
            scan: ScanPipelines::new(device),
            args: make(&two, &args, "write_args"),
            uniform,
            transition,
            hardware: std::sync::OnceLock::new(),
            main_pipeline_layout: one,
            main_layout,
            args_layout,
            view_layout,
        }
    }

    /// The hardware pattern's pipelines (`hardware.wgsl`), compiled on the first call.
    /// Cost: the first call two WGSL compilations (lavapipe finishes them at their first
    /// dispatch: about 5 s, once per device); later calls nothing.
    fn hardware(&self, device: &wgpu::Device) -> &PatternPipelines {
        self.hardware.get_or_init(|| {
            let make = |module: &wgpu::ShaderModule, entry: &str| {
                compute_pipeline(device, &self.main_pipeline_layout, module, entry)
            };
            let pattern = module(device, "hardware", &[COMMON, HARDWARE_PARTITION, LOCAL, HARDWARE, COUNT]);
            let vertices = module(
                device,
                "vertices hardware",
                &[COMMON, BICUBIC, BEZIER_TRIANGLE, HARDWARE_PARTITION, LOCAL, HARDWARE, WRITE_VERTICES],
            );
            PatternPipelines {
                count: make(&pattern, "count"),
                corners: make(&vertices, "write_corners"),
                edge_vertices: make(&vertices, "write_edge_vertices"),
                interior_vertices: make(&vertices, "write_interior_vertices"),
                triangles: make(&pattern, "write_patch_triangles"),
                collapsed_triangles: None,
            }
        })
    }

    /// The pipelines of `pattern`; None for the hardware pattern before
    /// [`Pipelines::hardware`] compiled them.
    fn of(&self, pattern: GpuPattern) -> Option<&PatternPipelines> {
        match pattern {
            GpuPattern::Uniform => Some(&self.uniform),
            GpuPattern::Transition => Some(&self.transition),
            GpuPattern::Hardware(_) => self.hardware.get(),
        }
    }
}

/// The a-posteriori check's pipelines (`check.wgsl`): the first check, then per round the
/// opening decision, the resolve, the closing decision and the re-check.
#[derive(Debug)]
struct CheckPipelines {
    check_all: wgpu::ComputePipeline,
    open: wgpu::ComputePipeline,
    resolve: wgpu::ComputePipeline,
    close: wgpu::ComputePipeline,
    recheck: wgpu::ComputePipeline,
}

/// `common.wgsl`'s `Params` (member for member: `contract::tests` checks the offsets).
#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct Params {
    edges: u32,
    patches: u32,
    corners: u32,
    vertex_capacity: u32,
    triangle_capacity: u32,
    partitioning: u32,
    _pad: [u32; 2],
}

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
/// Supported now, on every patch kind (bicubic, Bézier triangles, PN triangles):
/// [`SamplingKind::Uniform`] plans for the uniform pattern (every edge of a visible patch cut
/// into its interior factor, as `Scheme::Uniform` plans are) and the transition pattern (any
/// per-edge segments and core factors, as `Scheme::Transition` plans); and
/// `SamplingKind::Fractional(Spacing::Hardware(p))` plans for the Direct3D 11 pattern of
/// partitioning `p` (real per-edge factors, as `Scheme::Hardware(p)` plans). Anything else is
/// refused with [`GpuError::Unsupported`].
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
            // The plan's segments, then its factors (`common.wgsl`'s `edge_factor`).
            segments: buffer(device, "segments and factors", 8 * e, plan_usage),
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
            set: gpu_set,
            pipelines,
        })
    }

    /// Uploads `plan` (made for `pattern`: the uniform, the transition or a hardware pattern)
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
    /// a hardware pattern) or a factor that is not a finite positive number;
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
                    "the {} pattern (uniform, transition and the Direct3D 11 partitionings integer, \
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
        let expected_kind = match kind {
            GpuPattern::Hardware(p) => SamplingKind::Fractional(Spacing::Hardware(p)),
            _ => SamplingKind::Uniform,
        };
        if plan.kind != expected_kind {
            return Err(GpuError::Unsupported {
                what: format!("{:?} samplings with the {} pattern", plan.kind, pattern.name()),
            });
        }
        if let GpuPattern::Hardware(p) = kind {
            check_hardware_plan(plan, p)?;
        }
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
        if let GpuPattern::Hardware(_) = kind {
            self.pipelines.hardware(&ctx.device);
        }
        self.screen = None;
        self.pattern = kind;
        let queue = &ctx.queue;
        queue.write_buffer(&self.segments, 0, bytemuck::cast_slice(&plan.segments));
        queue.write_buffer(&self.segments, 4 * self.set.edges as u64, bytemuck::cast_slice(&plan.factors));
        queue.write_buffer(&self.interior, 0, bytemuck::cast_slice(&plan.interior));
        queue.write_buffer(&self.visible, 0, bytemuck::cast_slice(&plan.visible));
        self.write_params(ctx);
        Ok(())
    }

    /// Makes every following frame plan itself on the GPU from the camera alone: culling
    /// for `camera` (`cull.wgsl`), then the factors of `criterion` (`factors.wgsl`: per
    /// patch its proposals — for a pixel error the object-space tolerance of
    /// `screen::PatchView::tolerance` and the proposals from `prepared`'s bounds, for
    /// silhouetteness its edges' factors from `prepared`'s edge midpoints — per edge the
    /// maximum over its patches through the topology's edge uses, the cap and the minimum
    /// segments, then the scheme's interior rule), as `scheme.plan_prepared(set, prepared,
    /// &criterion, &PlanOptions { camera, cull: true, max_factor, .. })` plans on the CPU.
    /// Later cameras go to [`GpuTessellator::set_cull_camera`] (a 112-byte upload a frame);
    /// the plan never comes back to the CPU ([`GpuTessellator::read_plan`] reads it for
    /// tests).
    ///
    /// On the GPU: [`Criterion::PixelError`] with [`Scheme::Uniform`] (the global factor:
    /// the largest over the visible patches) or [`Scheme::Transition`] (CudaTess: per-edge
    /// factors and the a-posteriori check of `check.wgsl`, which raises interiors and, round
    /// by round, edges until every visible patch's bound holds; see
    /// [`GpuTessellator::read_screen_report`]); [`Criterion::View`] with
    /// [`ViewCriterion::Silhouetteness`] with [`Scheme::Uniform`] or [`Scheme::Transition`]
    /// (per-edge factors, CudaTess's core rule) or a [`Scheme::Hardware`] partitioning (real
    /// per-edge factors by `EdgeRule::Fractional`: the cap, the minimum segments, the hull
    /// shader's pow2 rounding and `settled_factor`; Direct3D's `max` inside reduction in the
    /// pattern); and [`Criterion::Factor`] with a [`Scheme::Hardware`] partitioning (one real
    /// factor, resolved the same way, with the GPU's culling). A silhouetteness strictly
    /// between 0 and 1 is computed in f32 from f32 copies of the CPU's data, so such an edge's
    /// real factor may differ from the CPU's in its last bits (`factors.wgsl`). The distance
    /// and vertex-silhouette criteria are planned on the CPU (their plans draw on the GPU
    /// through [`GpuTessellator::prepare`]). The output is sized for the worst case, every
    /// patch at the cap (or at the largest minimum when that is higher), within the device's
    /// buffer limits, or as `criterion.capacity` says; a frame that needs more draws nothing
    /// and is reported ([`GpuTessellator::grow_if_overflowed`]).
    ///
    /// Preconditions: `prepared` was made for `set` with bounds (`Prepared::new(set, true)`).
    /// Errors: [`GpuError::Unsupported`] for another scheme or criterion or a `prepared`
    /// without bounds; [`tessera::Error::InvalidParameter`] for a pixel error that is not a
    /// positive number, a factor range that is not `1 ≤ FMIN ≤ FMAX` (in integers for the
    /// integer schemes), or a `max_factor` outside `1..=MAX_FACTOR`, and
    /// [`tessera::Error::FactorOutOfRange`] for a fixed factor outside `1..=cap` (the checks
    /// of [`Scheme::plan`]);
    /// [`GpuError::Unsupported`] too for the transition scheme's pixel error with a
    /// `max_factor` above [`CHECK_MAX_FACTOR`];
    /// [`GpuError::OutputTooLarge`] when the worst case passes the u32 range of the scans,
    /// or as [`GpuTessellator::reserve`]. Cost: the first call O(E + P) cone computations,
    /// the edge midpoints' evaluations when `prepared` has none yet, and an upload of 128
    /// bytes a patch and 52 an edge; later calls (another camera, criterion or cap) O(P)
    /// pattern counts for the capacity and a 112-byte upload.
    pub fn prepare_screen(
        &mut self,
        ctx: &GpuContext,
        set: &SurfaceSet,
        prepared: &Prepared,
        camera: &Camera,
        criterion: ScreenCriterion,
    ) -> Result<()> {
        let ScreenCriterion { scheme, criterion, max_factor, capacity } = criterion;
        let unsupported = || {
            Err(GpuError::Unsupported {
                what: format!("{} with the {} scheme planned on the GPU", criterion.name(), scheme.name()),
            })
        };
        let invalid = |name: &'static str, reason: String| {
            Err(GpuError::from(tessera::Error::InvalidParameter { name, reason }))
        };
        if max_factor == 0 || max_factor > tessera::criterion::MAX_FACTOR {
            return invalid(
                "max factor",
                format!("{max_factor}: use 1 to {}", tessera::criterion::MAX_FACTOR),
            );
        }
        // The scheme's own cap and `max_factor`, as `Scheme::plan_into` caps (the hardware's
        // range for its partitionings).
        let cap = scheme.factor_cap().min(max_factor as f64);
        let hardware = match scheme {
            Scheme::Hardware(p) => Some(p),
            _ => None,
        };
        let (kind, pixels, lo, hi) = match (scheme, criterion) {
            (Scheme::Uniform | Scheme::Transition, Criterion::PixelError(px)) => {
                if !(px.is_finite() && px > 0.0) {
                    return invalid("pixel error", format!("{px}: must be a positive number"));
                }
                (CRITERION_PIXEL_ERROR, px, 1.0, 1.0)
            }
            (
                Scheme::Uniform | Scheme::Transition | Scheme::Hardware(_),
                Criterion::View { criterion: ViewCriterion::Silhouetteness, fmin, fmax },
            ) => {
                // Real factors for the hardware schemes, integers for the others.
                let integer = hardware.is_none();
                let valid = |f: f64| f.is_finite() && f >= 1.0 && (!integer || f.fract() == 0.0);
                if !(valid(fmin) && valid(fmax) && fmin <= fmax) {
                    let what = if integer { "integers" } else { "numbers" };
                    return invalid("factor range", format!("{fmin}:{fmax}: use {what} 1 ≤ FMIN ≤ FMAX"));
                }
                // As `Scheme::plan_into` and `view::edge_factors_into` bound the range.
                let fmax = fmax.min(cap);
                let lo = fmin.min(fmax).max(1.0);
                (CRITERION_SILHOUETTENESS, 1.0, lo, fmax.max(lo))
            }
            (Scheme::Hardware(p), Criterion::Factor(f)) => {
                if !(f.is_finite() && f >= 1.0 && f <= cap) {
                    return Err(tessera::Error::FactorOutOfRange {
                        scheme: scheme.name(),
                        factor: f,
                        expected: format!(
                            "a number from 1 to {cap} (the {} range and the max factor)",
                            p.name()
                        ),
                    }
                    .into());
                }
                (CRITERION_FIXED, 1.0, f, f)
            }
            _ => return unsupported(),
        };
        let interior = match scheme {
            Scheme::Uniform => INTERIOR_GLOBAL,
            Scheme::Hardware(_) => INTERIOR_MAX_EDGE,
            _ => INTERIOR_CORE,
        };
        if scheme == Scheme::Transition {
            self.check_loop_budget(max_factor)?;
        }
        if kind == CRITERION_PIXEL_ERROR && interior == INTERIOR_CORE && max_factor > CHECK_MAX_FACTOR {
            return Err(GpuError::Unsupported {
                what: format!(
                    "the a-posteriori check on the GPU with a factor cap of {max_factor} (it takes caps up \
                     to {CHECK_MAX_FACTOR}; plan this frame on the CPU)"
                ),
            });
        }
        let patches = set.patches.len();
        if patches as u32 != self.set.patches || set.topology.edges.len() as u32 != self.set.edges {
            return Err(
                tessera::Error::PlanMismatch { what: "a set other than the tessellator's".into() }.into()
            );
        }
        if prepared.hessians.len() != patches
            || prepared.curves.len() != patches
            || prepared.minimum_segments.len() != set.topology.edges.len()
            || prepared.minimum_interior.len() != patches
        {
            return Err(GpuError::Unsupported {
                what: "a Prepared without the error bounds (make it with Prepared::new(set, true))".into(),
            });
        }
        // The largest global factor a frame can reach: the cap, or a minimum above it.
        let minimum = prepared.minimum_segments.iter().chain(prepared.minimum_interior.iter().flatten());
        let worst = minimum.copied().fold(max_factor, u32::max);
        let mut worst_case = Capacity::of_plan(set, &Plan::uniform(set, worst)?, &Uniform, true);
        if interior == INTERIOR_CORE {
            // `Transition::counts` with every factor at most w = max(worst, 3) (cores are
            // raised to 3 at most): 2·nu·nv core triangles plus s + m a strip, at most
            // 2w² + 8w a patch, the uniform pattern's 2w² and 8w more; no more vertices.
            let w = worst.max(3) as u64;
            worst_case = Capacity::of_plan(set, &Plan::uniform(set, w as u32)?, &Uniform, true);
            worst_case.triangles += 8 * w * patches as u64;
        }
        if let Some(p) = hardware {
            worst_case = hardware_worst_case(set, prepared, p, cap);
        }
        let worst = worst_case;
        // The scans count in u32: a set whose worst frame could pass that range is refused
        // here, before any frame could wrap.
        if worst.vertices > u32::MAX as u64 || worst.triangles > u32::MAX as u64 / 3 {
            return Err(GpuError::OutputTooLarge {
                vertices: worst.vertices,
                triangles: worst.triangles,
                bytes: (worst.vertices * VERTEX_STRIDE).max(worst.triangles * 12),
                limit: self.buffer_limit,
            });
        }
        // Past the buffer limits, the frames that need more overflow and are reported; the
        // ones that fit draw completely.
        let (most_vertices, most_triangles) = self.most();
        let capacity = capacity.unwrap_or(Capacity {
            vertices: worst.vertices.min(most_vertices),
            triangles: worst.triangles.min(most_triangles),
        });
        self.reserve(ctx, capacity)?;
        let queue = &ctx.queue;
        if !self.view.bounds_uploaded {
            // View-independent and the same for every `Prepared` of the set: uploaded once.
            let rows = patch_view_rows(set, Some(prepared));
            queue.write_buffer(&self.view.patch_views, 0, bytemuck::cast_slice(&rows));
            self.view.bounds_uploaded = true;
        }
        let edge_rule = if hardware.is_some() { EDGE_RULE_HARDWARE } else { EDGE_RULE_INTEGER };
        self.screen = Some(Screen { criterion: kind, pixels, lo, hi, cap, interior, edge_rule });
        self.pattern = match scheme {
            Scheme::Uniform => GpuPattern::Uniform,
            Scheme::Hardware(p) => {
                self.pipelines.hardware(&ctx.device);
                GpuPattern::Hardware(p)
            }
            _ => GpuPattern::Transition,
        };
        self.write_params(ctx);
        self.set_cull_camera(ctx, Some(camera));
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

    /// The largest output the device's limits allow: `(vertices, triangles)`.
    fn most(&self) -> (u64, u64) {
        let vertices = (self.buffer_limit / VERTEX_STRIDE).min(u32::MAX as u64);
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
            return Ok(false);
        }
        // The counts are the scans' totals, exact unless they wrapped past u32 (then the
        // need is beyond the index range anyway).
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
        let s = &self.set;
        let main = shader::bind(
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
                &vertices,
                &indices,
            ],
        );
        self.output = Some(Output { capacity, vertices, indices, main });
        self.write_params(ctx);
        Ok(())
    }

    /// Writes `common.wgsl`'s `Params` for the output capacity and the pattern. Cost: a
    /// 32-byte upload.
    fn write_params(&self, ctx: &GpuContext) {
        let capacity = self.capacity().unwrap_or_default();
        let params = Params {
            edges: self.set.edges,
            patches: self.set.patches,
            corners: self.set.corners,
            vertex_capacity: capacity.vertices as u32,
            triangle_capacity: capacity.triangles as u32,
            partitioning: self.pattern.partitioning_code(),
            _pad: [0; 2],
        };
        ctx.queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&params));
    }

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
                c.set_pipeline(&p.patch_proposals);
                let (x, y) = grid(patches);
                c.dispatch_workgroups(x, y, 1);
                c.set_pipeline(&p.edge_segments);
                let (x, y) = grid(e);
                c.dispatch_workgroups(x, y, 1);
                if self.screen.is_some_and(|s| s.checked()) {
                    self.record_check(&mut c);
                } else {
                    c.set_pipeline(&p.interiors);
                    let (x, y) = grid(e.max(patches));
                    c.dispatch_workgroups(x, y, 1);
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
            if corners > 0 {
                c.set_pipeline(&k.corners);
                let (x, y) = shader::grid(corners.div_ceil(shader::WORKGROUP));
                c.dispatch_workgroups(x, y, 1);
            }
            c.set_pipeline(&k.edge_vertices);
            c.dispatch_workgroups_indirect(&self.dispatch_args, 0);
            c.set_pipeline(&k.interior_vertices);
            c.dispatch_workgroups_indirect(&self.dispatch_args, 12);
        }
        {
            let mut c = begin_pass(encoder, timer, 6);
            c.set_bind_group(0, &out.main, &[]);
            // Per-patch passes take the fourth dispatch, which the args pass zeroes on overflow.
            match (&k.collapsed_triangles, self.pattern) {
                (Some(collapsed), GpuPattern::Uniform) => {
                    c.set_pipeline(&k.triangles);
                    c.dispatch_workgroups_indirect(&self.dispatch_args, 24);
                    if self.set.any_repeated_corner {
                        c.set_pipeline(collapsed);
                        c.dispatch_workgroups_indirect(&self.dispatch_args, 36);
                    }
                }
                _ => {
                    c.set_pipeline(&k.triangles);
                    c.dispatch_workgroups_indirect(&self.dispatch_args, 36);
                }
            }
        }
        if let Some(t) = timer {
            encoder.resolve_query_set(&t.queries, 0..2 * PASSES.len() as u32, &t.resolved, 0);
        }
    }

    /// Records the a-posteriori check of a pixel-error transition plan into the factors pass
    /// (`check.wgsl`): the first check of every patch, then [`DEFAULT_CHECK_ROUNDS`] rounds whose
    /// passes the GPU sizes itself (no work once the rounds have ended). Groups 0 and 1 are
    /// bound by the caller.
    fn record_check(&self, c: &mut wgpu::ComputePass<'_>) {
        let k = &self.pipelines.check;
        let (x, y) = shader::grid(self.set.patches.div_ceil(shader::WORKGROUP));
        c.set_pipeline(&k.check_all);
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
            c.set_pipeline(&k.recheck);
            c.dispatch_workgroups_indirect(args, 0);
        }
    }

    /// Sets how many fix rounds of the a-posteriori check every following frame records
    /// (default [`DEFAULT_CHECK_ROUNDS`]). A round that is not needed dispatches no work, but still
    /// costs its four dispatches (about 70 µs on lavapipe, a few µs on a hardware GPU), so a
    /// real-time loop whose scenes converge in fewer rounds may record fewer and watch
    /// [`ScreenReport::converged`] now and then (a read-back, on request); at most
    /// [`MAX_CHECK_ROUNDS`] (more are clamped to it). A frame whose plan
    /// needs more rounds is still crack-free; its failing patches miss their bound and are
    /// counted. Cost: none until the next frame.
    pub fn set_check_rounds(&mut self, rounds: u32) {
        self.check_rounds = rounds.min(MAX_CHECK_ROUNDS);
    }

    /// Reads the last frame's a-posteriori check back (after
    /// [`GpuTessellator::prepare_screen`] with a pixel error and the transition scheme; the
    /// other frames report no rounds and no failing patch): for statistics and tests, never
    /// in a frame loop. Cost: a queue wait.
    pub fn read_screen_report(&self, ctx: &GpuContext) -> Result<ScreenReport> {
        let state: Vec<u32> = readback::read(ctx, &self.view.state, 8)?;
        let checked = self.screen.is_some_and(|s| s.checked()) && self.camera.is_some();
        if !checked {
            return Ok(ScreenReport { checked: false, rounds: 0, failing_patches: 0, converged: true });
        }
        // Done, or nothing left failing (the next round would have found that and ended).
        let converged = state[3] != 0 || state[1] == 0;
        Ok(ScreenReport { checked: true, rounds: state[4], failing_patches: state[1], converged })
    }

    /// Reads the check's guaranteed bound per patch back (0 for culled patches; meaningful
    /// after a checked frame, see [`GpuTessellator::read_screen_report`]). For tests. Cost:
    /// a queue wait.
    pub fn read_check_bounds(&self, ctx: &GpuContext) -> Result<Vec<f32>> {
        let rows: Vec<[f32; 4]> = readback::read(ctx, &self.view.checks, self.set.patches as usize)?;
        Ok(rows.iter().map(|r| r[1]).collect())
    }

    /// Makes the GPU cull (frustum and normal cone, `cull.wgsl`) for `camera` in every
    /// following frame, writing the plan's visibility row on the device (the plan's own row
    /// is then ignored), and, after [`GpuTessellator::prepare_screen`], plan the factors for
    /// it; None goes back to the plan's row (and ends the GPU's own planning). The output
    /// capacity then covers every patch. Cost: a 112-byte upload.
    pub fn set_cull_camera(&mut self, ctx: &GpuContext, camera: Option<&Camera>) {
        let Some(camera) = camera else {
            self.camera = None;
            self.screen = None;
            return;
        };
        self.camera = Some(*camera);
        let view = camera.view();
        let v4 = |v: glam::DVec3| [v.x as f32, v.y as f32, v.z as f32, 0.0];
        let s = self.screen.unwrap_or(Screen {
            criterion: CRITERION_PIXEL_ERROR,
            pixels: 1.0,
            lo: 1.0,
            hi: 1.0,
            cap: 1.0,
            interior: INTERIOR_GLOBAL,
            edge_rule: EDGE_RULE_INTEGER,
        });
        let t = view.half_tangents;
        let uniform = ViewUniform {
            eye: v4(view.eye),
            right: v4(view.right),
            up: v4(view.up),
            forward: v4(view.forward),
            near: view.near as f32,
            far: view.far as f32,
            tan_x: t.x as f32,
            tan_y: t.y as f32,
            focal: view.focal_pixels as f32,
            pixels: s.pixels as f32,
            cap: s.cap as f32,
            interior_rule: s.interior,
            criterion: s.criterion,
            lo: s.lo as f32,
            hi: s.hi as f32,
            edge_rule: s.edge_rule,
        };
        ctx.queue.write_buffer(&self.view.uniform, 0, bytemuck::bytes_of(&uniform));
    }

    /// Reads the plan the last frame drew back from the device: the uploaded one, or the
    /// GPU's own after [`GpuTessellator::prepare_screen`] (segments, interior factors and
    /// visibility; for the hardware patterns the real factors and the
    /// `SamplingKind::Fractional` kind, for the others `factors` are the segments). For
    /// tests and statistics. Cost: a queue wait.
    pub fn read_plan(&self, ctx: &GpuContext) -> Result<Plan> {
        let (e, p) = (self.set.edges as usize, self.set.patches as usize);
        let rows: Vec<u32> = readback::read(ctx, &self.segments, 2 * e)?;
        let interior: Vec<[u32; 2]> = readback::read(ctx, &self.interior, p)?;
        let mut plan = Plan::integer(rows[..e].to_vec(), interior, p);
        if let GpuPattern::Hardware(partitioning) = self.pattern {
            plan.kind = SamplingKind::Fractional(Spacing::Hardware(partitioning));
            plan.factors = rows[e..].iter().map(|&bits| f32::from_bits(bits)).collect();
        }
        plan.visible = self.read_visible(ctx)?;
        Ok(plan)
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
        let kind = self.pattern.cpu_pattern();
        let pattern: u64 = (0..set.patches.len())
            .filter(|&p| plan.is_visible(p))
            .map(|p| kind.counts(&tessera::engine::layout::pattern_input(set, &plan, p)).1 as u64)
            .sum();
        mesh.collapsed_triangles = (pattern - triangles as u64) as usize;
        Ok(mesh)
    }
}

/// What [`GpuTessellator::prepare_screen`] plans on the GPU: `scheme` under `criterion`
/// with `PlanOptions::max_factor = max_factor`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScreenCriterion {
    /// The scheme: [`Scheme::Uniform`], [`Scheme::Transition`] or [`Scheme::Hardware`].
    pub scheme: Scheme,
    /// [`Criterion::PixelError`] (uniform and transition schemes), [`Criterion::View`] with
    /// [`ViewCriterion::Silhouetteness`], or [`Criterion::Factor`] (hardware schemes).
    pub criterion: Criterion,
    /// The factor cap, `1..=MAX_FACTOR`.
    pub max_factor: u32,
    /// The output room to start with: None for the worst case (every patch at the cap),
    /// clamped to the device's buffer limits; a smaller one saves memory, and a frame that
    /// needs more overflows (drawing nothing) until [`GpuTessellator::grow_if_overflowed`]
    /// grows it.
    pub capacity: Option<Capacity>,
}

/// `view.wgsl`'s `View` uniform (member for member: `contract::tests` checks the offsets):
/// the camera's basis and frustum, and the screen criterion of the frame.
#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct ViewUniform {
    eye: [f32; 4],
    right: [f32; 4],
    up: [f32; 4],
    forward: [f32; 4],
    near: f32,
    far: f32,
    tan_x: f32,
    tan_y: f32,
    focal: f32,
    pixels: f32,
    cap: f32,
    interior_rule: u32,
    criterion: u32,
    lo: f32,
    hi: f32,
    edge_rule: u32,
}

/// `view.wgsl`'s interior rules, criteria and edge rules (substituted into it by
/// [`constants`], so they are typed here only).
const INTERIOR_GLOBAL: u32 = 0;
const INTERIOR_CORE: u32 = 1;
const INTERIOR_MAX_EDGE: u32 = 2;
const CRITERION_PIXEL_ERROR: u32 = 0;
const CRITERION_SILHOUETTENESS: u32 = 1;
const CRITERION_FIXED: u32 = 2;
const EDGE_RULE_INTEGER: u32 = 0;
const EDGE_RULE_HARDWARE: u32 = 1;
/// `vec4<f32>` per edge after the patch rows ([`patch_view_rows`]).
const EDGE_VIEW_ROW: usize = 3;

/// The criterion of [`GpuTessellator::prepare_screen`], as `view.wgsl` reads it.
#[derive(Debug, Clone, Copy)]
struct Screen {
    criterion: u32,
    pixels: f64,
    lo: f64,
    hi: f64,
    /// The factor cap (`Scheme`'s own and `max_factor`).
    cap: f64,
    interior: u32,
    edge_rule: u32,
}

impl Screen {
    /// Whether the frame's interiors come from the a-posteriori check (a pixel error with
    /// the transition scheme's core rule).
    fn checked(&self) -> bool {
        self.criterion == CRITERION_PIXEL_ERROR && self.interior == INTERIOR_CORE
    }
}

/// What the a-posteriori check of a pixel-error transition frame achieved
/// ([`GpuTessellator::read_screen_report`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ScreenReport {
    /// Whether the frame had an a-posteriori check on the GPU (a pixel error with the
    /// transition scheme, planned by [`GpuTessellator::prepare_screen`]); the other fields are
    /// 0, 0 and true otherwise.
    pub checked: bool,
    /// Fix rounds run after the first check (the CPU's loop iterations that changed edges).
    pub rounds: u32,
    /// Visible patches whose bound the plan misses: at the factor cap, as
    /// `tolerance::PlanReport::capped_patches` counts them on the CPU, or left failing when
    /// the rounds did not converge.
    pub failing_patches: u32,
    /// Whether the rounds ended within the recorded ones ([`DEFAULT_CHECK_ROUNDS`], or as
    /// [`GpuTessellator::set_check_rounds`] set) as the CPU's would (no failing patch, or a
    /// round that changed no edge). When false the plan is still crack-free, but the failing
    /// patches' bounds are missed.
    pub converged: bool,
}

/// The view passes' buffers (`view.wgsl`'s group 1) and their bind group.
#[derive(Debug)]
struct ViewBuffers {
    uniform: wgpu::Buffer,
    patch_views: wgpu::Buffer,
    /// `view.wgsl`'s `FrameState`.
    state: wgpu::Buffer,
    /// The check rows (`view.wgsl`'s `CheckRow`, per patch).
    checks: wgpu::Buffer,
    bind: wgpu::BindGroup,
    /// The check rounds' dispatch arguments (`check.wgsl`'s `round_args`) and their bind
    /// group (group 2 of the rounds' decisions).
    round_args: wgpu::Buffer,
    rounds: wgpu::BindGroup,
    /// Whether the bounds and edge rows of [`GpuTessellator::prepare_screen`] are on the
    /// device.
    bounds_uploaded: bool,
}

impl ViewBuffers {
    /// The buffers for `set`, the culling rows filled (the bounds come with
    /// [`GpuTessellator::prepare_screen`]). Cost: O(P) cone computations, one upload.
    fn new(
        device: &wgpu::Device,
        layout: &wgpu::BindGroupLayout,
        rounds_layout: &wgpu::BindGroupLayout,
        set: &SurfaceSet,
    ) -> ViewBuffers {
        use wgpu::BufferUsages as U;
        let patches = set.patches.len() as u64;
        let uniform =
            buffer(device, "view", std::mem::size_of::<ViewUniform>() as u64, U::UNIFORM | U::COPY_DST);
        let patch_views = upload::storage_buffer(device, "patch views", &patch_view_rows(set, None));
        let proposals = buffer(device, "proposals", 16 * patches, U::STORAGE);
        let state = buffer(device, "frame state", 32, U::STORAGE | U::COPY_DST | U::COPY_SRC);
        let checks = buffer(device, "check rows", 16 * patches, U::STORAGE | U::COPY_SRC);
        let bind = shader::bind(device, layout, &[&uniform, &patch_views, &proposals, &state, &checks]);
        let round_args = buffer(device, "check round dispatches", 24, U::STORAGE | U::INDIRECT);
        let rounds = shader::bind_at(
            device,
            rounds_layout,
            &[(STATE_BINDING, &state), (ROUND_ARGS_BINDING, &round_args)],
        );
        ViewBuffers { uniform, patch_views, state, checks, bind, round_args, rounds, bounds_uploaded: false }
    }
}

/// Per patch, [`PATCH_VIEW_ROW`] `vec4<f32>` (`view.wgsl`): from
/// [`tessera::criterion::screen::PatchView`] the normal cone (axis, half-angle α), the
/// bounding sphere of the control points about their mean (`screen::back_facing`'s),
/// `(sin α, cos α, has cone, 0)`, the control-point box's lo and hi; then from `prepared`
/// (zero without it) the second-derivative bound `(uu, uv, vv, 0)`, the four boundary
/// curves' bounds and the minimum interior factors; after the patches, [`EDGE_VIEW_ROW`]
/// per edge from `Prepared::edge_midpoints` (the midpoint as its first patch sees it, with
/// the edge's `Prepared::minimum_segments` in w; the normals of its first and last patch).
/// View-independent: computed once. Cost: O(P) cone
/// computations, the midpoints' evaluations when `prepared` has none yet.
fn patch_view_rows(set: &SurfaceSet, prepared: Option<&Prepared>) -> Vec<[f32; 4]> {
    let v4 = |v: glam::DVec3, w: f64| [v.x as f32, v.y as f32, v.z as f32, w as f32];
    let mut out = Vec::with_capacity(PATCH_VIEW_ROW as usize * set.patches.len());
    for (p, patch) in set.patches.iter().enumerate() {
        let view = tessera::criterion::screen::PatchView::new(patch);
        let (axis, alpha) = view.cone.unwrap_or((glam::DVec3::Z, 0.0));
        out.push(v4(axis, alpha));
        out.push(v4(view.centre, view.radius));
        out.push([alpha.sin() as f32, alpha.cos() as f32, view.cone.is_some() as u32 as f32, 0.0]);
        out.push(v4(view.lo, 0.0));
        out.push(v4(view.hi, 0.0));
        match prepared {
            Some(prepared) => {
                let m = &prepared.hessians[p];
                out.push([m.uu as f32, m.uv as f32, m.vv as f32, 0.0]);
                out.push(prepared.curves[p].map(|c| c as f32));
                let [u, v] = prepared.minimum_interior[p];
                out.push([u as f32, v as f32, 0.0, 0.0]);
            }
            None => out.extend([[0.0; 4]; 3]),
        }
    }
    let edges = set.topology.edges.len();
    match prepared {
        Some(prepared) => {
            let minimum = &prepared.minimum_segments;
            for (e, [(mid, nl), (_, nr)]) in prepared.edge_midpoints(set).iter().enumerate() {
                out.extend([v4(*mid, minimum[e] as f64), v4(*nl, 0.0), v4(*nr, 0.0)]);
            }
        }
        None => out.resize(out.len() + EDGE_VIEW_ROW * edges, [0.0; 4]),
    }
    out
}

/// Begins compute pass `index` of [`PASSES`], timed by `timer` if given.
fn begin_pass<'e>(
    encoder: &'e mut wgpu::CommandEncoder,
    timer: Option<&PassTimer>,
    index: usize,
) -> wgpu::ComputePass<'e> {
    encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
        label: Some(PASSES[index]),
        timestamp_writes: timer.map(|t| wgpu::ComputePassTimestampWrites {
            query_set: &t.queries,
            beginning_of_pass_write_index: Some(2 * index as u32),
            end_of_pass_write_index: Some(2 * index as u32 + 1),
        }),
    })
}

/// Timestamp queries around each of the frame's [`PASSES`], where the adapter has them
/// ([`GpuContext::timestamps`]).
#[derive(Debug)]
pub struct PassTimer {
    queries: wgpu::QuerySet,
    resolved: wgpu::Buffer,
    period_ns: f32,
}

impl PassTimer {
    /// A timer for one frame's passes, or None when the adapter has no timestamp queries.
    /// Cost: a query set and a 80-byte buffer.
    pub fn new(ctx: &GpuContext) -> Option<PassTimer> {
        if !ctx.timestamps {
            return None;
        }
        let count = 2 * PASSES.len() as u32;
        let queries = ctx.device.create_query_set(&wgpu::QuerySetDescriptor {
            label: Some("pass timestamps"),
            ty: wgpu::QueryType::Timestamp,
            count,
        });
        let resolved = buffer(
            &ctx.device,
            "resolved timestamps",
            8 * count as u64,
            wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
        );
        Some(PassTimer { queries, resolved, period_ns: ctx.queue.get_timestamp_period() })
    }

    /// The last recorded frame's time per pass, in milliseconds, in [`PASSES`] order. Reads
    /// back (a queue wait): statistics on request only.
    pub fn read(&self, ctx: &GpuContext) -> Result<Vec<(&'static str, f64)>> {
        let ticks: Vec<u64> = readback::read(ctx, &self.resolved, 2 * PASSES.len())?;
        Ok(PASSES
            .iter()
            .enumerate()
            .map(|(i, &name)| {
                let dt = ticks[2 * i + 1].saturating_sub(ticks[2 * i]);
                (name, dt as f64 * self.period_ns as f64 * 1e-6)
            })
            .collect())
    }
}
