//! Loading the WGSL sources: shared constants are substituted from their Rust definitions, so
//! no number is typed twice.

/// Invocations per workgroup of the element-parallel passes (count, write, cull).
pub const WORKGROUP: u32 = 64;

/// Most workgroups in one dispatch dimension (WebGPU's and wgpu's default limit); larger
/// dispatches are laid out in two dimensions ([`grid`]).
pub const MAX_GROUPS_PER_DIMENSION: u32 = 65_535;

/// The WGSL sources of the crate, as written (placeholders unexpanded). Most are the engine's
/// own; the patch evaluations are public so that other crates' shaders evaluate patches by
/// the same rule instead of a copy ([`evaluation_wgsl`]).
pub mod sources {
    /// `threads.wgsl`: `thread_index`, the invocation numbering of [`super::grid`]'s dispatches.
    pub(crate) const THREADS: &str = include_str!("../shaders/threads.wgsl");
    /// `common.wgsl` after [`THREADS`]: the engine's bindings, constants and row accessors.
    pub(crate) const COMMON: &str = concat!(
        include_str!("../shaders/threads.wgsl"),
        include_str!("../shaders/common.wgsl"),
        include_str!("../shaders/triangle_net.wgsl"),
    );
    /// `triangle_net.wgsl`: `tri_point(p, i, j)`, a cubic Bézier triangle's control point
    /// (part of `common.wgsl`'s modules; [`crate::shader::evaluation_wgsl`] brings its own).
    pub const TRIANGLE_NET: &str = include_str!("../shaders/triangle_net.wgsl");
    pub(crate) const STENCILS: &str = include_str!("../shaders/stencils.wgsl");
    pub(crate) const MOVING_BOUNDS: &str = include_str!("../shaders/moving_bounds.wgsl");
    /// `bicubic.wgsl`: `bicubic_eval(p, uv)`, patch `p`'s position and normal as
    /// `tessera::surface::RationalBicubic::eval` computes them, from the `control_points`
    /// rows ([`crate::upload`]).
    pub const BICUBIC: &str = include_str!("../shaders/bicubic.wgsl");
    /// `bezier_triangle.wgsl`: `triangle_eval` and `pn_eval` (cubic Bézier triangles, PN
    /// triangles) and `eval_patch(p, uv)`, which picks the evaluation by the patch row's kind
    /// bits. Needs [`BICUBIC`] and [`TRIANGLE_NET`] before it.
    pub const BEZIER_TRIANGLE: &str = include_str!("../shaders/bezier_triangle.wgsl");
    /// `tree.wgsl`: `tree_eval(p, uv)`, a Catmull-Clark subdivision patch's position and
    /// normal as `tessera::surface::Patch::eval` computes them (the quadtree walked to the
    /// piece, Bézier pieces and Gregory end caps), from `upload::pack_trees`' blocks. Needs
    /// [`BICUBIC`] before it.
    pub const TREE: &str = include_str!("../shaders/tree.wgsl");
    /// `no_tree.wgsl`: [`TREE`]'s functions for a set without subdivision patches (never
    /// taken), which keeps the tree walk out of its pipelines.
    pub const NO_TREE: &str = include_str!("../shaders/no_tree.wgsl");
    pub(crate) const UNIFORM_GRID: &str = include_str!("../shaders/uniform_grid.wgsl");
    pub(crate) const COUNT: &str = include_str!("../shaders/count.wgsl");
    pub(crate) const COUNT_UNIFORM: &str = include_str!("../shaders/count_uniform.wgsl");
    pub(crate) const WRITE_VERTICES: &str = include_str!("../shaders/write_vertices.wgsl");
    pub(crate) const WRITE_TRIANGLES_UNIFORM: &str = include_str!("../shaders/write_triangles_uniform.wgsl");
    pub(crate) const INDIRECT_ARGS: &str = include_str!("../shaders/indirect_args.wgsl");
    pub(crate) const CULL: &str = include_str!("../shaders/cull.wgsl");
    pub(crate) const VIEW: &str = include_str!("../shaders/view.wgsl");
    pub(crate) const FACTORS: &str = include_str!("../shaders/factors.wgsl");
    pub(crate) const TRANSITION: &str = include_str!("../shaders/transition.wgsl");
    pub(crate) const BOUNDS: &str = include_str!("../shaders/bounds.wgsl");
    /// `expansion.wgsl` after `expansion_type.wgsl`: the expansion bound.
    pub(crate) const EXPANSION: &str =
        concat!(include_str!("../shaders/expansion_type.wgsl"), include_str!("../shaders/expansion.wgsl"));
    /// Its stand-in for the frames planned without it: the same type, no bound.
    pub(crate) const NO_EXPANSION: &str = concat!(
        include_str!("../shaders/expansion_type.wgsl"),
        include_str!("../shaders/no_expansion.wgsl"),
    );
    pub(crate) const CHECK: &str = include_str!("../shaders/check.wgsl");
    pub(crate) const LOCAL: &str = include_str!("../shaders/local.wgsl");
    pub(crate) const GRID_VERTICES: &str = include_str!("../shaders/grid_vertices.wgsl");
    pub(crate) const HARDWARE_PARTITION: &str = include_str!("../shaders/hardware_partition.wgsl");
    pub(crate) const HARDWARE: &str = include_str!("../shaders/hardware.wgsl");
    pub(crate) const SEMI_UNIFORM: &str = include_str!("../shaders/semi_uniform.wgsl");
    pub(crate) const SD2: &str = include_str!("../shaders/sd2.wgsl");
    /// The ESC pattern (`tessera::pattern::esc::Esc`): counts, vertex places, triangles.
    pub(crate) const ESC: &str = include_str!("../shaders/esc.wgsl");
    /// ESC planned from the camera: levels, distance tests, insertion grids.
    pub(crate) const ESC_PLAN: &str = include_str!("../shaders/esc_plan.wgsl");
    /// The strips of the patterns with a strip form (SD-2, ESC).
    pub(crate) const STRIPS: &str = include_str!("../shaders/strips.wgsl");
}

/// The patch evaluation of every patch kind, `eval_patch(p, uv)` ([`sources::BICUBIC`],
/// [`sources::TREE`] or, for a set without subdivision patches, [`sources::NO_TREE`], then
/// [`sources::TRIANGLE_NET`] and [`sources::BEZIER_TRIANGLE`]), for a shader that draws the engine's patches by the engine's
/// own evaluation rather than a copy. The shader that includes it declares what `common.wgsl`
/// declares for it: the `control_points` array, the constant `CONTROL_POINTS`
/// ([`crate::upload::CONTROL_POINTS`]), the `patch_rows` array with the constant `PATCH_ROW`,
/// and the patch-row accessors `patch_is_tri` and `patch_has_pn_normals`.
pub fn evaluation_wgsl(with_trees: bool) -> String {
    let trees = if with_trees { sources::TREE } else { sources::NO_TREE };
    [sources::BICUBIC, trees, sources::TRIANGLE_NET, sources::BEZIER_TRIANGLE].concat()
}

/// `source` with every `{{NAME}}` replaced by its value from `constants`.
///
/// Panics when a placeholder is left unreplaced: a shader and its Rust constants out of step
/// is a bug of this crate, found by the first test that loads it. Cost: O(source length).
pub fn expand(source: &str, constants: &[(&str, u32)]) -> String {
    let mut text = source.to_string();
    for (name, value) in constants {
        text = text.replace(&format!("{{{{{name}}}}}"), &value.to_string());
    }
    if let Some(at) = text.find("{{") {
        let end = text[at..].find("}}").map_or(text.len(), |e| at + e + 2);
        panic!("shader placeholder {} has no value", &text[at..end]);
    }
    text
}

/// The constants every shader may use.
pub fn common_constants() -> Vec<(&'static str, u32)> {
    vec![
        ("WORKGROUP", WORKGROUP),
        ("MAX_GROUPS_PER_DIMENSION", MAX_GROUPS_PER_DIMENSION),
        ("SCAN_WORKGROUP", crate::scan::SCAN_WORKGROUP),
        ("SCAN_ITEMS", crate::scan::SCAN_ITEMS),
    ]
}

/// A shader module from the concatenation of `parts` (WGSL has no include), expanded with
/// [`common_constants`] and `extra`. Cost: one WGSL compilation.
pub fn module(
    device: &wgpu::Device,
    label: &str,
    parts: &[&str],
    extra: &[(&str, u32)],
) -> wgpu::ShaderModule {
    module_with_functions(device, label, parts, extra, &[])
}

/// [`module`] with every `{{NAME}}` of `functions` replaced by the WGSL function it names: a
/// file shared by several patterns calls the pattern's own function through a placeholder,
/// so which one it calls is chosen by the caller, and a module missing that function fails
/// to compile instead of calling whichever one its parts happen to define. Cost: one WGSL
/// compilation.
pub fn module_with_functions(
    device: &wgpu::Device,
    label: &str,
    parts: &[&str],
    extra: &[(&str, u32)],
    functions: &[(&str, &str)],
) -> wgpu::ShaderModule {
    let text = source(parts, extra, functions);
    device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(label),
        source: wgpu::ShaderSource::Wgsl(text.into()),
    })
}

/// The text of [`module_with_functions`]'s module: `parts` concatenated, each `{{NAME}}` of
/// `functions` replaced by its function, then expanded with [`common_constants`] and `extra`.
/// Panics as [`expand`]. Cost: O(source length).
pub fn source(parts: &[&str], extra: &[(&str, u32)], functions: &[(&str, &str)]) -> String {
    let mut constants = common_constants();
    constants.extend_from_slice(extra);
    let mut text = parts.concat();
    for (name, function) in functions {
        text = text.replace(&format!("{{{{{name}}}}}"), function);
    }
    expand(&text, &constants)
}

/// How a shader reads one binding of group 0.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Binding {
    /// `var<uniform>`.
    Uniform,
    /// `var<storage, read>`.
    Read,
    /// `var<storage, read_write>`.
    Write,
}

/// The bind group layout of group 0 with `bindings` at 0, 1, 2, … (compute stage). Explicit
/// layouts, unlike derived ones, are shared by every pipeline made with them.
pub fn layout(device: &wgpu::Device, bindings: &[Binding]) -> wgpu::BindGroupLayout {
    let numbered: Vec<(u32, Binding)> = bindings.iter().enumerate().map(|(i, &b)| (i as u32, b)).collect();
    layout_at(device, &numbered)
}

/// A bind group layout with each binding at the number given (compute stage): a pass that
/// needs only some of a group's variables binds just those, by their numbers in the shader.
pub fn layout_at(device: &wgpu::Device, bindings: &[(u32, Binding)]) -> wgpu::BindGroupLayout {
    let entries: Vec<wgpu::BindGroupLayoutEntry> = bindings
        .iter()
        .map(|&(binding, b)| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty: match b {
                    Binding::Uniform => wgpu::BufferBindingType::Uniform,
                    Binding::Read => wgpu::BufferBindingType::Storage { read_only: true },
                    Binding::Write => wgpu::BufferBindingType::Storage { read_only: false },
                },
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        })
        .collect();
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: None, entries: &entries })
}

/// A compute pipeline for `entry` of `module` with group 0 laid out by `layout`.
pub fn pipeline(
    device: &wgpu::Device,
    module: &wgpu::ShaderModule,
    entry: &str,
    layout: &wgpu::BindGroupLayout,
) -> wgpu::ComputePipeline {
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(entry),
        bind_group_layouts: &[Some(layout)],
        immediate_size: 0,
    });
    device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(entry),
        layout: Some(&pipeline_layout),
        module,
        entry_point: Some(entry),
        compilation_options: Default::default(),
        cache: None,
    })
}

/// Workgroups `(x, y)` covering `groups` workgroups with at most
/// [`MAX_GROUPS_PER_DIMENSION`] per dimension; shaders number them `y · x_count + x` and
/// skip those past the end. The GPU form of this rule is `grid` in `indirect_args.wgsl`.
pub fn grid(groups: u32) -> (u32, u32) {
    if groups <= MAX_GROUPS_PER_DIMENSION {
        (groups, 1)
    } else {
        (MAX_GROUPS_PER_DIMENSION, groups.div_ceil(MAX_GROUPS_PER_DIMENSION))
    }
}

/// A bind group of `layout` with `buffers` at bindings 0, 1, 2, … in order.
pub fn bind(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    buffers: &[&wgpu::Buffer],
) -> wgpu::BindGroup {
    let numbered: Vec<(u32, &wgpu::Buffer)> =
        buffers.iter().enumerate().map(|(i, &b)| (i as u32, b)).collect();
    bind_at(device, layout, &numbered)
}

/// A bind group of `layout` (made by [`layout_at`]) with each buffer at the binding given.
pub fn bind_at(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    buffers: &[(u32, &wgpu::Buffer)],
) -> wgpu::BindGroup {
    let entries: Vec<wgpu::BindGroupEntry> = buffers
        .iter()
        .map(|&(binding, b)| wgpu::BindGroupEntry { binding, resource: b.as_entire_binding() })
        .collect();
    device.create_bind_group(&wgpu::BindGroupDescriptor { label: None, layout, entries: &entries })
}
