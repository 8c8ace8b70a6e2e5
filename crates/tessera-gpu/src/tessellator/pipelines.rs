//! The frame's compiled pipelines: which WGSL files make which shader module ([`Pipelines::new`],
//! the table of each [`GpuPattern`]'s parts), the constants substituted into them
//! ([`constants`]), the bind group layouts, and `common.wgsl`'s uniform [`Params`].

use super::screen::{
    BOUND_EXPANSION, BOUND_HESSIAN, CRITERION_DISTANCE_LINEAR, CRITERION_DISTANCE_QUADRATIC, CRITERION_ESC,
    CRITERION_FIXED, CRITERION_PIXEL_ERROR, CRITERION_SILHOUETTENESS, CRITERION_VERTEX_SILHOUETTE,
    EDGE_RULE_HARDWARE, EDGE_RULE_INTEGER, EDGE_RULE_POWER_OF_TWO, EDGE_RULE_SYMMETRIC, EDGE_VIEW_ROW,
    ESC_THRESHOLD_ABSOLUTE, EXPANSION_BICUBIC, EXPANSION_TRIANGLE, INTERIOR_CORE, INTERIOR_GLOBAL,
    INTERIOR_LEVEL, INTERIOR_MAX_EDGE, PATCH_VIEW_ROW, ROUND_ARGS_BINDING, STATE_BINDING, VERTEX_VIEW_ROW,
};
use super::VERTEX_FLOATS;
use crate::context::GpuContext;
use crate::error::{GpuError, Result};
use crate::scan::ScanPipelines;
use crate::shader::sources::*;
use crate::shader::{self, Binding};
use crate::upload;
use tessera::pattern::esc::Esc;
use tessera::pattern::hardware::{Hardware, Partitioning};
use tessera::pattern::sd2::Sd2;
use tessera::pattern::semi_uniform::SemiUniform;
use tessera::pattern::transition::Transition;
use tessera::pattern::uniform::Uniform;
use tessera::pattern::Pattern;
use tessera::sampling::{SamplingKind, Spacing};

/// Storage buffers in group 0 (all of `common.wgsl`'s but the uniform).
const MAIN_STORAGE: u32 = 12;
/// Storage buffers in group 1 of the args pass (its outputs).
const ARGS_STORAGE: u32 = 3;
/// Storage buffers in group 1 of the view passes (`view.wgsl`).
const VIEW_STORAGE: u32 = 4;
/// Storage buffers in group 1 of the strip passes (`strips.wgsl`: offsets, indices, state,
/// and the frame's status).
const STRIP_STORAGE: u32 = 4;
/// Storage buffers in group 1 of the check rounds' decisions (the frame state and the rounds'
/// dispatch arguments, at the frame state's binding and one of their own).
const ROUND_STORAGE: u32 = 2;

/// Storage buffers per shader stage a frame needs: group 0's and the largest group 1. Within
/// 16, what most adapters give (not the WebGPU default of 8, which no GPU engine of this
/// shape fits: the prepared set, the plan, the layout and the outputs are 12 on their own).
pub const STORAGE_BUFFERS: u32 =
    MAIN_STORAGE + max_u32(ARGS_STORAGE, max_u32(VIEW_STORAGE, max_u32(ROUND_STORAGE, STRIP_STORAGE)));

const fn max_u32(a: u32, b: u32) -> u32 {
    if a > b {
        a
    } else {
        b
    }
}

/// The most invocations a patch in the semi-uniform triangle pass (`Params::blocks`), each
/// writing a block of the patch's grid rows. Four keeps one invocation within lavapipe's loop
/// limit at the top level (64 rows of 512 triangles) while idle invocations stay few: a
/// frame's patches mostly have one or two rows.
pub const ROW_BLOCKS: u32 = 4;

/// The largest ESC lattice side `3n`, at [`tessera::pattern::esc::MAX_LEVEL`] (`esc.wgsl`'s
/// private rows hold one more).
pub(crate) const ESC_MAX_SIDE: u32 =
    3 * tessera::pattern::esc::segments_for_level(tessera::pattern::esc::MAX_LEVEL);

/// Words a patch of an ESC insertion grid takes in the segments buffer: `(3n + 1)²` bits at
/// the largest level.
pub(crate) const ESC_GRID_WORDS: u32 = ((ESC_MAX_SIDE + 1) * (ESC_MAX_SIDE + 1)).div_ceil(32);

/// The Direct3D 11 partitionings, in the order of their codes ([`partitioning_code`]).
const PARTITIONINGS: [Partitioning; 4] =
    [Partitioning::Integer, Partitioning::Pow2, Partitioning::FractionalOdd, Partitioning::FractionalEven];

/// The CPU's SD-2 pattern without the reverse projection (for counts: the warp moves points,
/// not counts).
static SD2_PATTERN: Sd2 = Sd2 { corner_depths: None };

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
        ("VERTEX_VIEW_ROW", VERTEX_VIEW_ROW as u32),
        ("INTERIOR_GLOBAL", INTERIOR_GLOBAL),
        ("INTERIOR_CORE", INTERIOR_CORE),
        ("INTERIOR_MAX_EDGE", INTERIOR_MAX_EDGE),
        ("INTERIOR_LEVEL", INTERIOR_LEVEL),
        ("CRITERION_PIXEL_ERROR", CRITERION_PIXEL_ERROR),
        ("CRITERION_SILHOUETTENESS", CRITERION_SILHOUETTENESS),
        ("CRITERION_FIXED", CRITERION_FIXED),
        ("CRITERION_DISTANCE_LINEAR", CRITERION_DISTANCE_LINEAR),
        ("CRITERION_DISTANCE_QUADRATIC", CRITERION_DISTANCE_QUADRATIC),
        ("CRITERION_VERTEX_SILHOUETTE", CRITERION_VERTEX_SILHOUETTE),
        ("CRITERION_ESC", CRITERION_ESC),
        ("ESC_THRESHOLD_ABSOLUTE", ESC_THRESHOLD_ABSOLUTE),
        ("EDGE_RULE_INTEGER", EDGE_RULE_INTEGER),
        ("EDGE_RULE_HARDWARE", EDGE_RULE_HARDWARE),
        ("EDGE_RULE_POWER_OF_TWO", EDGE_RULE_POWER_OF_TWO),
        ("EDGE_RULE_SYMMETRIC", EDGE_RULE_SYMMETRIC),
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
        ("ESC_MAX_SIDE", ESC_MAX_SIDE),
        ("ESC_GRID_WORDS", ESC_GRID_WORDS),
        ("EXPANSION_WALK_CELLS", tessera::criterion::taylor::EXPANSION_WALK_CELLS as u32),
        ("HULL_WHEN_BITS", (tessera::criterion::taylor::HULL_WHEN as f32).to_bits()),
        ("BOUND_HESSIAN", BOUND_HESSIAN),
        ("BOUND_EXPANSION", BOUND_EXPANSION),
        ("EXPANSION_BICUBIC", EXPANSION_BICUBIC),
        ("EXPANSION_TRIANGLE", EXPANSION_TRIANGLE),
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
    /// [`tessera::pattern::semi_uniform::SemiUniform`] (paper 000, compacted) on quads and
    /// triangles: one invocation per row of a patch's grid (`semi_uniform.wgsl`).
    SemiUniform,
    /// [`tessera::pattern::sd2::Sd2`] (paper 001) on triangles, with or without the reverse
    /// projection: one invocation per triangle (`sd2.wgsl`).
    Sd2,
    /// [`tessera::pattern::esc::Esc`] (paper 002) on bicubic patches, from the insertion
    /// grids of the pattern the plan came with: one invocation per patch walks its 18
    /// coarse triangles' strips (`esc.wgsl`).
    Esc,
}

impl GpuPattern {
    /// The GPU form of `pattern`, by its name; None for patterns not on the GPU.
    pub fn of(pattern: &dyn Pattern) -> Option<GpuPattern> {
        match pattern.name() {
            n if n == Uniform.name() => Some(GpuPattern::Uniform),
            n if n == Transition.name() => Some(GpuPattern::Transition),
            n if n == SemiUniform.name() => Some(GpuPattern::SemiUniform),
            n if n == Sd2::default().name() => Some(GpuPattern::Sd2),
            n if n == Esc::default().name() => Some(GpuPattern::Esc),
            n => PARTITIONINGS
                .into_iter()
                .find(|&p| Hardware { partitioning: p }.name() == n)
                .map(GpuPattern::Hardware),
        }
    }

    /// The CPU pattern this draws (for counts read back, [`GpuTessellator::read_mesh`]);
    /// None for ESC, whose pattern holds per-patch decisions.
    pub(super) fn cpu_pattern(self) -> Option<&'static dyn Pattern> {
        match self {
            GpuPattern::Uniform => Some(&Uniform),
            GpuPattern::Transition => Some(&Transition),
            GpuPattern::Hardware(p) => Some(&HARDWARE_PATTERNS[partitioning_code(p) as usize]),
            GpuPattern::SemiUniform => Some(&SemiUniform),
            GpuPattern::Sd2 => Some(&SD2_PATTERN),
            GpuPattern::Esc => None,
        }
    }

    /// The sampling kind of the plans the pattern draws: the hardware's own spacing, the
    /// symmetric remainder for SD-2, equal steps for the integer patterns.
    pub(super) fn sampling_kind(self) -> SamplingKind {
        match self {
            GpuPattern::Hardware(p) => SamplingKind::Fractional(Spacing::Hardware(p)),
            GpuPattern::Sd2 => SamplingKind::Fractional(Spacing::Symmetric),
            GpuPattern::Esc => SamplingKind::Lattice,
            GpuPattern::Uniform | GpuPattern::Transition | GpuPattern::SemiUniform => SamplingKind::Uniform,
        }
    }

    /// `Params::partitioning`: the partitioning's code, 0 for the integer patterns.
    pub(super) fn partitioning_code(self) -> u32 {
        match self {
            GpuPattern::Hardware(p) => partitioning_code(p),
            _ => 0,
        }
    }
}

/// How one pattern's pipelines are built: the WGSL files of its modules, the functions of
/// those files that the shared passes call (substituted for `count.wgsl`'s,
/// `write_vertices.wgsl`'s and `grid_vertices.wgsl`'s `{{NAME}}`), and its triangle passes'
/// entry points. A module whose parts lack a function named here fails to compile; none
/// calls another pattern's function by concatenation order.
struct PatternShaders {
    /// The count pass's module, and the triangle passes' where `triangles` is None.
    count: (&'static str, &'static [&'static str]),
    /// The vertex passes' module.
    vertices: (&'static str, &'static [&'static str]),
    /// The triangle passes' own module, if they have one.
    triangles: Option<(&'static str, &'static [&'static str])>,
    /// `{{PATCH_COUNTS}}` (`count.wgsl`): a visible patch's interior vertices and kept
    /// triangles; `{{EDGE_PARAM}}` and `{{INTERIOR_POINT}}` (`write_vertices.wgsl`): where the
    /// pattern puts edge samples and interior vertices; `{{INTERIOR_GRID}}`
    /// (`grid_vertices.wgsl`, for the patterns on a grid): the interior grid's factors.
    functions: &'static [(&'static str, &'static str)],
    /// The entry point of the triangle pass.
    write_triangles: &'static str,
    /// The entry point of the uniform pattern's second triangle pass, for the patches at a
    /// collapsed corner.
    write_collapsed_triangles: Option<&'static str>,
}

/// The uniform pattern: one module per pass kind.
const UNIFORM_SHADERS: PatternShaders = PatternShaders {
    count: ("count uniform", &[COMMON, UNIFORM_GRID, COUNT_UNIFORM, COUNT]),
    vertices: (
        "vertices uniform",
        &[COMMON, BICUBIC, NO_TREE, BEZIER_TRIANGLE, UNIFORM_GRID, GRID_VERTICES, WRITE_VERTICES],
    ),
    triangles: Some(("triangles uniform", &[COMMON, UNIFORM_GRID, WRITE_TRIANGLES_UNIFORM])),
    functions: &[
        ("PATCH_COUNTS", "uniform_patch_counts"),
        ("INTERIOR_GRID", "uniform_interior_grid"),
        ("EDGE_PARAM", "grid_edge_param"),
        ("INTERIOR_POINT", "grid_interior_point"),
    ],
    write_triangles: "write_uniform_triangles",
    write_collapsed_triangles: Some("write_uniform_collapsed_triangles"),
};

/// The transition pattern: counts and triangles in one module.
const TRANSITION_SHADERS: PatternShaders = PatternShaders {
    count: ("transition", &[COMMON, LOCAL, BOUNDS, NO_EXPANSION, TRANSITION, COUNT]),
    vertices: (
        "vertices transition",
        &[
            COMMON,
            BICUBIC,
            NO_TREE,
            BEZIER_TRIANGLE,
            LOCAL,
            BOUNDS,
            NO_EXPANSION,
            TRANSITION,
            GRID_VERTICES,
            WRITE_VERTICES,
        ],
    ),
    triangles: None,
    functions: &[
        ("PATCH_COUNTS", "transition_patch_counts"),
        ("INTERIOR_GRID", "transition_interior_grid"),
        ("EDGE_PARAM", "grid_edge_param"),
        ("INTERIOR_POINT", "grid_interior_point"),
    ],
    write_triangles: "write_transition_triangles",
    write_collapsed_triangles: None,
};

/// The Direct3D 11 patterns (every partitioning: `Params::partitioning` tells them apart):
/// counts and triangles in one module.
const HARDWARE_SHADERS: PatternShaders = PatternShaders {
    count: ("hardware", &[COMMON, HARDWARE_PARTITION, LOCAL, HARDWARE, COUNT]),
    vertices: (
        "vertices hardware",
        &[COMMON, BICUBIC, NO_TREE, BEZIER_TRIANGLE, HARDWARE_PARTITION, LOCAL, HARDWARE, WRITE_VERTICES],
    ),
    triangles: None,
    functions: &[
        ("PATCH_COUNTS", "hardware_patch_counts"),
        ("EDGE_PARAM", "hardware_plan_edge_param"),
        ("INTERIOR_POINT", "hardware_interior_point"),
    ],
    write_triangles: "write_hardware_triangles",
    write_collapsed_triangles: None,
};

/// The semi-uniform pattern: counts and triangles in one module, the interior on the uniform
/// grid of the patch level.
const SEMI_UNIFORM_SHADERS: PatternShaders = PatternShaders {
    count: ("semi-uniform", &[COMMON, UNIFORM_GRID, LOCAL, SEMI_UNIFORM, COUNT]),
    vertices: (
        "vertices semi-uniform",
        &[
            COMMON,
            BICUBIC,
            NO_TREE,
            BEZIER_TRIANGLE,
            UNIFORM_GRID,
            LOCAL,
            SEMI_UNIFORM,
            GRID_VERTICES,
            WRITE_VERTICES,
        ],
    ),
    triangles: None,
    functions: &[
        ("PATCH_COUNTS", "semi_uniform_patch_counts"),
        // The uniform grid of the patch level: its interior points never move.
        ("INTERIOR_GRID", "uniform_interior_grid"),
        ("EDGE_PARAM", "grid_edge_param"),
        ("INTERIOR_POINT", "grid_interior_point"),
    ],
    write_triangles: "write_semi_uniform_triangles",
    write_collapsed_triangles: None,
};

/// The SD-2 pattern: counts and triangles in one module; triangles one invocation each, then
/// the patches at a collapsed corner one invocation each.
const SD2_SHADERS: PatternShaders = PatternShaders {
    count: ("sd2", &[COMMON, LOCAL, SD2, COUNT]),
    vertices: ("vertices sd2", &[COMMON, BICUBIC, NO_TREE, BEZIER_TRIANGLE, LOCAL, SD2, WRITE_VERTICES]),
    triangles: None,
    functions: &[
        ("PATCH_COUNTS", "sd2_patch_counts"),
        ("EDGE_PARAM", "sd2_edge_param"),
        ("INTERIOR_POINT", "sd2_interior_point"),
    ],
    write_triangles: "write_sd2_triangles",
    write_collapsed_triangles: Some("write_sd2_collapsed_triangles"),
};

/// The ESC pattern: counts and triangles in one module, one invocation a patch.
const ESC_SHADERS: PatternShaders = PatternShaders {
    count: ("esc", &[COMMON, LOCAL, ESC, COUNT]),
    vertices: ("vertices esc", &[COMMON, BICUBIC, NO_TREE, BEZIER_TRIANGLE, LOCAL, ESC, WRITE_VERTICES]),
    triangles: None,
    functions: &[
        ("PATCH_COUNTS", "esc_patch_counts"),
        ("EDGE_PARAM", "esc_edge_param"),
        ("INTERIOR_POINT", "esc_interior_point"),
    ],
    write_triangles: "write_esc_triangles",
    write_collapsed_triangles: None,
};

impl PatternShaders {
    /// Compiles the pattern's modules and makes its pipelines with group 0 laid out by
    /// `layout`. Cost: two or three WGSL compilations.
    fn pipelines(&self, device: &wgpu::Device, layout: &wgpu::PipelineLayout) -> PatternPipelines {
        let module = |(label, parts): (&str, &[&str])| {
            shader::module_with_functions(device, label, parts, &constants(), self.functions)
        };
        let count = module(self.count);
        let triangles = self.triangles.map(module);
        let triangles = triangles.as_ref().unwrap_or(&count);
        let make = |module: &wgpu::ShaderModule, entry: &str| compute_pipeline(device, layout, module, entry);
        PatternPipelines {
            count: make(&count, "count"),
            vertices: self.vertex_pipelines(device, layout, false),
            with_trees: std::sync::OnceLock::new(),
            triangles: make(triangles, self.write_triangles),
            collapsed_triangles: self.write_collapsed_triangles.map(|entry| make(triangles, entry)),
        }
    }

    /// The vertex passes' pipelines, evaluating subdivision patches (`tree.wgsl`) or not
    /// (`no_tree.wgsl` in its place). Cost: one WGSL compilation.
    fn vertex_pipelines(
        &self,
        device: &wgpu::Device,
        layout: &wgpu::PipelineLayout,
        trees: bool,
    ) -> VertexPipelines {
        let (label, parts) = self.vertices;
        let parts: Vec<&str> = parts.iter().map(|&p| if trees && p == NO_TREE { TREE } else { p }).collect();
        let label = if trees { format!("{label} with trees") } else { label.to_string() };
        let module = shader::module_with_functions(device, &label, &parts, &constants(), self.functions);
        let make = |entry: &str| compute_pipeline(device, layout, &module, entry);
        VertexPipelines {
            corners: make("write_corners"),
            edge_vertices: make("write_edge_vertices"),
            interior_vertices: make("write_interior_vertices"),
        }
    }
}

/// The vertex passes' pipelines: corners, edge samples, interior vertices.
#[derive(Debug)]
pub(super) struct VertexPipelines {
    pub(super) corners: wgpu::ComputePipeline,
    pub(super) edge_vertices: wgpu::ComputePipeline,
    pub(super) interior_vertices: wgpu::ComputePipeline,
}

/// The pattern-specific pipelines: counts, vertex writes (the interior grid is the
/// pattern's), triangle writes.
#[derive(Debug)]
pub(super) struct PatternPipelines {
    pub(super) count: wgpu::ComputePipeline,
    /// The vertex passes for sets without subdivision patches.
    pub(super) vertices: VertexPipelines,
    /// The vertex passes that also evaluate subdivision patches, compiled on first use
    /// ([`Pipelines::with_trees`]): the tree walk makes lavapipe's compilation several times
    /// slower, and most sets have no trees.
    pub(super) with_trees: std::sync::OnceLock<VertexPipelines>,
    /// Uniform: one invocation per triangle (indirect), then the collapsed-corner patches.
    /// Transition and hardware: one invocation per patch.
    pub(super) triangles: wgpu::ComputePipeline,
    pub(super) collapsed_triangles: Option<wgpu::ComputePipeline>,
}

/// Every compiled pipeline of a frame, independent of the set: made once per device
/// ([`Pipelines::new`]) and shared by any number of tessellators
/// ([`GpuTessellator::with_pipelines`](super::GpuTessellator::with_pipelines)).
#[derive(Debug)]
pub struct Pipelines {
    pub(super) main_layout: wgpu::BindGroupLayout,
    pub(super) args_layout: wgpu::BindGroupLayout,
    pub(super) view_layout: wgpu::BindGroupLayout,
    pub(super) cull: wgpu::ComputePipeline,
    pub(super) vertex_depths: wgpu::ComputePipeline,
    pub(super) patch_proposals: wgpu::ComputePipeline,
    pub(super) edge_segments: wgpu::ComputePipeline,
    pub(super) interiors: wgpu::ComputePipeline,
    pub(super) check: CheckPipelines,
    pub(super) rounds_layout: wgpu::BindGroupLayout,
    pub(super) scan: ScanPipelines,
    pub(super) args: wgpu::ComputePipeline,
    uniform: PatternPipelines,
    transition: PatternPipelines,
    /// The hardware pattern's, compiled on first use ([`Pipelines::hardware`]): a frame of
    /// the integer patterns does not wait for them.
    hardware: std::sync::OnceLock<PatternPipelines>,
    /// The semi-uniform pattern's, compiled on first use ([`Pipelines::compile`]).
    semi_uniform: std::sync::OnceLock<PatternPipelines>,
    /// The SD-2 pattern's, compiled on first use ([`Pipelines::compile`]).
    sd2: std::sync::OnceLock<PatternPipelines>,
    /// The ESC pattern's, compiled on first use ([`Pipelines::compile`]).
    esc: std::sync::OnceLock<PatternPipelines>,
    /// ESC's planning passes from the camera (`esc_plan.wgsl`), compiled on first use
    /// ([`Pipelines::esc_plan`]).
    esc_plan: std::sync::OnceLock<EscPlanPipelines>,
    view_pipeline_layout: wgpu::PipelineLayout,
    /// Group 1 of the strip passes (`strips.wgsl`).
    pub(super) strips_layout: wgpu::BindGroupLayout,
    strips_pipeline_layout: wgpu::PipelineLayout,
    /// The strip passes of SD-2 and of ESC, compiled on first use ([`Pipelines::strips`]).
    sd2_strips: std::sync::OnceLock<StripPipelines>,
    esc_strips: std::sync::OnceLock<StripPipelines>,
    /// The proposals and check of frames planned with the expansion bound, compiled on
    /// first use ([`Pipelines::expansion`]).
    expansion: std::sync::OnceLock<BoundPipelines>,
    main_pipeline_layout: wgpu::PipelineLayout,
    rounds_pipeline_layout: wgpu::PipelineLayout,
}

/// The factors module's parts, with the expansion bound (`EXPANSION`) or without it
/// (`NO_EXPANSION`).
fn factors_parts(expansion: &'static str) -> [&'static str; 7] {
    [COMMON, VIEW, CULL, HARDWARE_PARTITION, BOUNDS, expansion, FACTORS]
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
        let strips_layout = shader::layout(device, &[Write; STRIP_STORAGE as usize]);
        let with_strips = pipeline_layout(&[Some(&main_layout), Some(&strips_layout)]);
        let make = |layout: &wgpu::PipelineLayout, module: &wgpu::ShaderModule, entry: &str| {
            compute_pipeline(device, layout, module, entry)
        };
        let args = module(device, "args", &[COMMON, INDIRECT_ARGS]);
        let cull = module(device, "cull", &[COMMON, VIEW, CULL]);
        let factors = module(device, "factors", &factors_parts(NO_EXPANSION));
        let uniform = UNIFORM_SHADERS.pipelines(device, &one);
        let transition = TRANSITION_SHADERS.pipelines(device, &one);
        let check = CheckPipelines::new(device, &with_view, &with_rounds, NO_EXPANSION);
        Pipelines {
            check,
            rounds_layout,
            cull: make(&with_view, &cull, "cull"),
            vertex_depths: make(&with_view, &factors, "vertex_depths"),
            patch_proposals: make(&with_view, &factors, "patch_proposals"),
            edge_segments: make(&with_view, &factors, "edge_segments"),
            interiors: make(&with_view, &factors, "interiors"),
            scan: ScanPipelines::new(device),
            args: make(&two, &args, "write_args"),
            uniform,
            transition,
            hardware: std::sync::OnceLock::new(),
            semi_uniform: std::sync::OnceLock::new(),
            sd2: std::sync::OnceLock::new(),
            esc: std::sync::OnceLock::new(),
            esc_plan: std::sync::OnceLock::new(),
            main_pipeline_layout: one,
            view_pipeline_layout: with_view,
            strips_layout,
            strips_pipeline_layout: with_strips,
            sd2_strips: std::sync::OnceLock::new(),
            esc_strips: std::sync::OnceLock::new(),
            expansion: std::sync::OnceLock::new(),
            rounds_pipeline_layout: with_rounds,
            main_layout,
            args_layout,
            view_layout,
        }
    }

    /// The proposals and the check of frames planned with the expansion bound
    /// (`expansion.wgsl`, [`tessera::criterion::ErrorBound::Expansion`]), compiled on the
    /// first call. Cost: the first call two WGSL compilations (lavapipe's first expansion
    /// frame took 10 s on a cold shader cache); later calls nothing.
    pub(super) fn expansion(&self, device: &wgpu::Device) -> &BoundPipelines {
        self.expansion.get_or_init(|| {
            let factors = module(device, "factors with the expansion bound", &factors_parts(EXPANSION));
            BoundPipelines {
                patch_proposals: compute_pipeline(
                    device,
                    &self.view_pipeline_layout,
                    &factors,
                    "patch_proposals",
                ),
                check: CheckPipelines::new(
                    device,
                    &self.view_pipeline_layout,
                    &self.rounds_pipeline_layout,
                    EXPANSION,
                ),
            }
        })
    }

    /// The proposals and the check a frame planned with `bound` (`Screen::bound`) records:
    /// the second-derivative bound's, or the expansion bound's once [`Pipelines::expansion`]
    /// compiled them (None before).
    pub(super) fn bound(&self, bound: u32) -> Option<(&wgpu::ComputePipeline, &CheckPipelines)> {
        if bound == BOUND_EXPANSION {
            return self.expansion.get().map(|b| (&b.patch_proposals, &b.check));
        }
        Some((&self.patch_proposals, &self.check))
    }

    /// The hardware pattern's pipelines (`hardware.wgsl`), compiled on the first call.
    /// Cost: the first call two WGSL compilations (lavapipe finishes them at their first
    /// dispatch: about 5 s, once per device); later calls nothing.
    pub(super) fn hardware(&self, device: &wgpu::Device) -> &PatternPipelines {
        self.hardware.get_or_init(|| {
            // One set for every partitioning: the shaders read `Params::partitioning`.
            HARDWARE_SHADERS.pipelines(device, &self.main_pipeline_layout)
        })
    }

    /// The pipelines a frame of `pattern` needs, compiled now if they are compiled on first
    /// use (the hardware, semi-uniform and SD-2 patterns'). Cost: the first call per pattern
    /// two WGSL compilations; later calls nothing.
    pub(super) fn compile(&self, device: &wgpu::Device, pattern: GpuPattern) {
        let layout = &self.main_pipeline_layout;
        match pattern {
            GpuPattern::Hardware(_) => {
                self.hardware(device);
            }
            GpuPattern::SemiUniform => {
                self.semi_uniform.get_or_init(|| SEMI_UNIFORM_SHADERS.pipelines(device, layout));
            }
            GpuPattern::Sd2 => {
                self.sd2.get_or_init(|| SD2_SHADERS.pipelines(device, layout));
            }
            GpuPattern::Esc => {
                self.esc.get_or_init(|| ESC_SHADERS.pipelines(device, layout));
            }
            GpuPattern::Uniform | GpuPattern::Transition => {}
        }
    }

    /// Compiles the vertex passes that evaluate subdivision patches for `pattern` (whose own
    /// pipelines exist: [`Pipelines::hardware`] first for a hardware pattern). Cost: the
    /// first call per pattern one WGSL compilation; later calls nothing.
    pub(super) fn with_trees(&self, device: &wgpu::Device, pattern: GpuPattern) {
        let shaders = match pattern {
            GpuPattern::Uniform => &UNIFORM_SHADERS,
            GpuPattern::Transition => &TRANSITION_SHADERS,
            GpuPattern::Hardware(_) => &HARDWARE_SHADERS,
            GpuPattern::SemiUniform => &SEMI_UNIFORM_SHADERS,
            GpuPattern::Sd2 => &SD2_SHADERS,
            GpuPattern::Esc => &ESC_SHADERS,
        };
        if let Some(p) = self.of(pattern) {
            p.with_trees.get_or_init(|| shaders.vertex_pipelines(device, &self.main_pipeline_layout, true));
        }
    }

    /// ESC's planning passes (`esc_plan.wgsl`), compiled now the first time. Cost: the first
    /// call one WGSL compilation; later calls nothing.
    pub(super) fn esc_plan(&self, device: &wgpu::Device) -> &EscPlanPipelines {
        self.esc_plan.get_or_init(|| {
            let parts = [COMMON, BICUBIC, NO_TREE, BEZIER_TRIANGLE, VIEW, LOCAL, ESC, ESC_PLAN];
            let m = module(device, "esc plan", &parts);
            let make = |entry: &str| compute_pipeline(device, &self.view_pipeline_layout, &m, entry);
            EscPlanPipelines {
                levels: make("esc_levels"),
                edges: make("esc_edges"),
                grids: make("esc_grids"),
            }
        })
    }

    /// The strip passes of `pattern` (`strips.wgsl` with the pattern's walk), compiled now
    /// the first time; None for a pattern without a strip form. Cost: the first call per
    /// pattern one WGSL compilation.
    pub(super) fn strips(&self, device: &wgpu::Device, pattern: GpuPattern) -> Option<&StripPipelines> {
        let walk = super::strips::walk_of(pattern)?;
        let cell = if pattern == GpuPattern::Sd2 { &self.sd2_strips } else { &self.esc_strips };
        Some(cell.get_or_init(|| {
            let parts = [COMMON, LOCAL, SD2, ESC, STRIPS];
            let m = shader::module_with_functions(
                device,
                "strips",
                &parts,
                &constants(),
                &[("PATCH_STRIPS", walk)],
            );
            let make = |entry: &str| compute_pipeline(device, &self.strips_pipeline_layout, &m, entry);
            StripPipelines {
                count: make("count_strips"),
                args: make("strip_args"),
                write: make("write_strips"),
            }
        }))
    }

    /// The strip passes of `pattern`, once [`Pipelines::strips`] compiled them.
    pub(super) fn strips_compiled(&self, pattern: GpuPattern) -> Option<&StripPipelines> {
        match pattern {
            GpuPattern::Sd2 => self.sd2_strips.get(),
            GpuPattern::Esc => self.esc_strips.get(),
            _ => None,
        }
    }

    /// ESC's planning passes, once [`Pipelines::esc_plan`] compiled them.
    pub(super) fn esc_plan_compiled(&self) -> Option<&EscPlanPipelines> {
        self.esc_plan.get()
    }

    /// The pipelines of `pattern`; None for the hardware pattern before
    /// [`Pipelines::hardware`] compiled them.
    pub(super) fn of(&self, pattern: GpuPattern) -> Option<&PatternPipelines> {
        match pattern {
            GpuPattern::Uniform => Some(&self.uniform),
            GpuPattern::Transition => Some(&self.transition),
            GpuPattern::Hardware(_) => self.hardware.get(),
            GpuPattern::SemiUniform => self.semi_uniform.get(),
            GpuPattern::Sd2 => self.sd2.get(),
            GpuPattern::Esc => self.esc.get(),
        }
    }
}

/// The strip passes of one pattern (`strips.wgsl`): counts, the draw's arguments, writes.
#[derive(Debug)]
pub(super) struct StripPipelines {
    pub(super) count: wgpu::ComputePipeline,
    pub(super) args: wgpu::ComputePipeline,
    pub(super) write: wgpu::ComputePipeline,
}

/// ESC's planning passes from the camera (`esc_plan.wgsl`): each object's level, each edge's
/// candidates, each patch's insertion grid.
#[derive(Debug)]
pub(super) struct EscPlanPipelines {
    pub(super) levels: wgpu::ComputePipeline,
    pub(super) edges: wgpu::ComputePipeline,
    pub(super) grids: wgpu::ComputePipeline,
}

/// The a-posteriori check's pipelines (`check.wgsl`): the check (the first of every patch,
/// and each round's re-check), and per round the opening decision, the resolve and the
/// closing decision.
#[derive(Debug)]
pub(super) struct CheckPipelines {
    pub(super) check: wgpu::ComputePipeline,
    pub(super) open: wgpu::ComputePipeline,
    pub(super) resolve: wgpu::ComputePipeline,
    pub(super) close: wgpu::ComputePipeline,
}

impl CheckPipelines {
    /// Compiles `check.wgsl` with `expansion.wgsl` or its stand-in (`expansion`). Cost: one
    /// WGSL compilation.
    fn new(
        device: &wgpu::Device,
        with_view: &wgpu::PipelineLayout,
        with_rounds: &wgpu::PipelineLayout,
        expansion: &'static str,
    ) -> CheckPipelines {
        let parts = [
            COMMON,
            VIEW,
            CULL,
            HARDWARE_PARTITION,
            FACTORS,
            LOCAL,
            BOUNDS,
            expansion,
            TRANSITION,
            UNIFORM_GRID,
            SEMI_UNIFORM,
            CHECK,
        ];
        let label = if expansion == EXPANSION { "check with the expansion bound" } else { "check" };
        let m = module(device, label, &parts);
        let make = |layout: &wgpu::PipelineLayout, entry: &str| compute_pipeline(device, layout, &m, entry);
        CheckPipelines {
            check: make(with_view, "check_patches"),
            open: make(with_rounds, "round_open"),
            resolve: make(with_view, "round_resolve"),
            close: make(with_rounds, "round_close"),
        }
    }
}

/// The passes whose code depends on the error bound (`Screen::bound`): the proposals and the
/// a-posteriori check.
#[derive(Debug)]
pub(super) struct BoundPipelines {
    pub(super) patch_proposals: wgpu::ComputePipeline,
    pub(super) check: CheckPipelines,
}

/// `common.wgsl`'s `Params` (member for member: the contract test, `contract.rs`, checks the offsets).
#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct Params {
    pub(crate) edges: u32,
    pub(crate) patches: u32,
    pub(crate) corners: u32,
    pub(crate) vertex_capacity: u32,
    pub(crate) triangle_capacity: u32,
    pub(crate) partitioning: u32,
    pub(crate) blocks: u32,
    pub(crate) warped: u32,
}

#[cfg(test)]
mod tests {
    use super::*;

    const ROWS: [(&str, &PatternShaders); 6] = [
        ("uniform", &UNIFORM_SHADERS),
        ("transition", &TRANSITION_SHADERS),
        ("hardware", &HARDWARE_SHADERS),
        ("semi-uniform", &SEMI_UNIFORM_SHADERS),
        ("sd2", &SD2_SHADERS),
        ("esc", &ESC_SHADERS),
    ];

    /// The modules of `row` (count, vertices, triangles), expanded with `functions` as
    /// [`PatternShaders::pipelines`] expands them, parsed by naga.
    fn parse(
        row: &PatternShaders,
        functions: &[(&str, &str)],
    ) -> Vec<std::result::Result<naga::Module, String>> {
        let modules = [Some(row.count), Some(row.vertices), row.triangles];
        modules
            .into_iter()
            .flatten()
            .map(|(_, parts)| {
                let text = shader::source(parts, &constants(), functions);
                naga::front::wgsl::parse_str(&text).map_err(|e| format!("{e}"))
            })
            .collect()
    }

    /// The vertex modules with the tree walk in place of its stand-in, as
    /// [`PatternShaders::vertex_pipelines`] makes them for a set with subdivision patches.
    #[test]
    fn every_vertex_module_compiles_with_trees() {
        for (name, row) in ROWS {
            let (_, parts) = row.vertices;
            assert!(parts.contains(&NO_TREE), "{name}: the vertex module evaluates patches");
            let parts: Vec<&str> = parts.iter().map(|&p| if p == NO_TREE { TREE } else { p }).collect();
            let text = shader::source(&parts, &constants(), row.functions);
            let module = naga::front::wgsl::parse_str(&text).unwrap_or_else(|e| panic!("{name}: {e}"));
            assert!(
                module.functions.iter().any(|(_, f)| f.name.as_deref() == Some("tree_derivatives")),
                "{name}"
            );
        }
    }

    #[test]
    fn every_pattern_row_compiles_with_its_entry_points() {
        for (name, row) in ROWS {
            let modules: Vec<naga::Module> = parse(row, row.functions)
                .into_iter()
                .map(|m| m.unwrap_or_else(|e| panic!("{name}: {e}")))
                .collect();
            let has = |m: &naga::Module, entry: &str| m.entry_points.iter().any(|e| e.name == entry);
            let triangles = modules.last().expect("a row has modules");
            assert!(has(&modules[0], "count"), "{name}");
            for entry in ["write_corners", "write_edge_vertices", "write_interior_vertices"] {
                assert!(has(&modules[1], entry), "{name}: {entry}");
            }
            let triangles = if row.triangles.is_some() { triangles } else { &modules[0] };
            for entry in std::iter::once(row.write_triangles).chain(row.write_collapsed_triangles) {
                assert!(has(triangles, entry), "{name}: {entry}");
            }
        }
    }

    #[test]
    fn a_pattern_row_with_another_patterns_function_fails_to_compile() {
        for (name, row) in ROWS {
            for (other, other_row) in ROWS {
                for &(placeholder, theirs) in other_row.functions {
                    let Some(&(_, ours)) = row.functions.iter().find(|(n, _)| *n == placeholder) else {
                        continue;
                    };
                    if ours == theirs {
                        continue; // shared by both patterns (the grid patterns' vertex places)
                    }
                    let functions: Vec<(&str, &str)> = row
                        .functions
                        .iter()
                        .map(|&(n, f)| if n == placeholder { (n, theirs) } else { (n, f) })
                        .collect();
                    assert!(
                        parse(row, &functions).iter().any(|m| m.is_err()),
                        "{name}'s modules compiled with {other}'s {placeholder} ({theirs})"
                    );
                }
            }
        }
    }
}
