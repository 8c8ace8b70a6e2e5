//! The instanced semi-uniform path (paper 000, §4; methods E–H of its Table 1): the
//! per-level **render queues built on the GPU** by counting and an exclusive scan per level
//! ([`GpuRenderQueues`], `shaders/queues.wgsl`, the GPU form of
//! [`tessera::engine::render_queues::build`]), and [`InstancedDraw`]: the static patterns
//! `P^0 … P^M` in GPU buffers, each level's draw arguments written on the GPU, and one
//! instanced draw per level with the snap `φ` and the patch evaluation in the vertex shader
//! (Listing 1; `shaders/instanced.wgsl`, evaluating with the GPU engine's own
//! `bicubic.wgsl` and `bezier_triangle.wgsl`). Nothing is read back in a frame.
//! [`tessera::engine::render_queues::draw`] is the CPU reference of the draw.

use crate::RenderError;
use tessera::criterion::Plan;
use tessera::engine::render_queues::{QueueEntry, RenderQueues, MAX_LEVEL};
use tessera::surface::SurfaceSet;
use tessera_gpu::scan::{Scan, ScanPipelines};
use tessera_gpu::{readback, upload, GpuContext};

const SOURCE: &str = include_str!("../shaders/queues.wgsl");

/// Workgroup size of `queues.wgsl`.
const WORKGROUP: u32 = 64;

/// `queues.wgsl`'s `Params`.
#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Params {
    patches: u32,
    max_level: u32,
    stride: u32,
    slots: u32,
}

/// Render queues on the device for one set and highest level `M`: made once, rebuilt from
/// each frame's plan by [`GpuRenderQueues::record`].
#[derive(Debug)]
pub struct GpuRenderQueues {
    count: wgpu::ComputePipeline,
    scatter: wgpu::ComputePipeline,
    scan_pipelines: ScanPipelines,
    scan: Scan,
    bind: wgpu::BindGroup,
    segments: wgpu::Buffer,
    interior: wgpu::Buffer,
    visible: wgpu::Buffer,
    slots: wgpu::Buffer,
    entries: wgpu::Buffer,
    status: wgpu::Buffer,
    patches: u32,
    edges: u32,
    max_level: u32,
}

/// Workgroups for `threads` invocations, in two dimensions past the per-dimension limit
/// (`tessera_gpu::shader::grid`'s rule, with this shader's row width of 64 × x groups).
fn grid(threads: u32) -> (u32, u32) {
    tessera_gpu::shader::grid(threads.div_ceil(WORKGROUP))
}

impl GpuRenderQueues {
    /// Uploads `set`'s patch-edge rows and compiles the passes for levels `0..=max_level`.
    /// Errors: [`RenderError::Invalid`] for `max_level` past [`MAX_LEVEL`] or a set too
    /// large for 32-bit slots. Cost: two small shader compilations and the scan's scratch
    /// buffers, `(M + 1)(P + 1)` u32 slots and `2 P` u32 entries.
    pub fn new(ctx: &GpuContext, set: &SurfaceSet, max_level: u32) -> Result<GpuRenderQueues, RenderError> {
        if max_level > MAX_LEVEL {
            return Err(RenderError::Invalid(format!("render queues: level {max_level} beyond {MAX_LEVEL}")));
        }
        let device = &ctx.device;
        let patches = set.patches.len() as u32;
        let stride = patches as u64 + 1;
        let slots = stride * (max_level as u64 + 1);
        if slots > u32::MAX as u64 / 2 {
            return Err(RenderError::Invalid(format!("render queues: {patches} patches are too many")));
        }
        let topo = &set.topology;
        let mut edges = Vec::with_capacity(4 * patches as usize);
        for (p, row) in topo.patch_edges.iter().enumerate() {
            let n = topo.patch_domains[p].corner_count();
            edges.extend((0..4).map(|e| if e < n { row[e].edge } else { u32::MAX }));
        }
        use wgpu::BufferUsages as U;
        let buffer = |label: &str, bytes: u64, usage: U| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: bytes.max(16),
                usage,
                mapped_at_creation: false,
            })
        };
        let plan_usage = U::STORAGE | U::COPY_DST;
        let segments = buffer("queue segments", 4 * topo.edges.len() as u64, plan_usage);
        let interior = buffer("queue interior", 8 * patches as u64, plan_usage);
        let visible = buffer("queue visible", 4 * patches as u64, plan_usage);
        let slots_buffer = buffer("queue slots", 4 * slots, U::STORAGE | U::COPY_SRC);
        let entries = buffer("queue entries", 8 * patches as u64, U::STORAGE | U::COPY_SRC);
        let status = buffer("queue status", 16, U::STORAGE | U::COPY_SRC | U::COPY_DST);
        let patch_edges = upload::storage_buffer(device, "queue patch edges", &edges);
        let params = buffer("queue params", 16, U::UNIFORM | U::COPY_DST);
        let values = Params { patches, max_level, stride: stride as u32, slots: slots as u32 };
        ctx.queue.write_buffer(&params, 0, bytemuck::bytes_of(&values));
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("queues.wgsl"),
            source: wgpu::ShaderSource::Wgsl(SOURCE.into()),
        });
        use tessera_gpu::shader::{self, Binding::*};
        let layout = shader::layout(device, &[Uniform, Read, Read, Read, Read, Write, Write, Write]);
        let count = shader::pipeline(device, &module, "count", &layout);
        let scatter = shader::pipeline(device, &module, "scatter", &layout);
        let bind = shader::bind(
            device,
            &layout,
            &[&params, &segments, &interior, &visible, &patch_edges, &slots_buffer, &entries, &status],
        );
        let scan_pipelines = ScanPipelines::new(device);
        let scan = Scan::new(device, &scan_pipelines, &slots_buffer, slots as u32, 0);
        Ok(GpuRenderQueues {
            count,
            scatter,
            scan_pipelines,
            scan,
            bind,
            segments,
            interior,
            visible,
            slots: slots_buffer,
            entries,
            status,
            patches,
            edges: topo.edges.len() as u32,
            max_level,
        })
    }

    /// Uploads `plan` (a semi-uniform plan of the set, levels up to the queues' `M`) and
    /// records the count, scan and scatter passes into `encoder`. Reads nothing back.
    /// Errors: [`RenderError::Invalid`] for a plan of another size. Cost on the GPU:
    /// O((M + 1) · P) in about a dozen dispatches.
    pub fn record(
        &self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        plan: &Plan,
    ) -> Result<(), RenderError> {
        if plan.interior.len() != self.patches as usize || plan.segments.len() != self.edges as usize {
            return Err(RenderError::Invalid("render queues: a plan of another set".into()));
        }
        let q = &ctx.queue;
        q.write_buffer(&self.segments, 0, bytemuck::cast_slice(&plan.segments));
        q.write_buffer(&self.interior, 0, bytemuck::cast_slice(&plan.interior));
        q.write_buffer(&self.visible, 0, bytemuck::cast_slice(&plan.visible));
        q.write_buffer(&self.status, 0, &[0u8; 16]);
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("render queues"),
            timestamp_writes: None,
        });
        let slots = (self.patches + 1) * (self.max_level + 1);
        pass.set_pipeline(&self.count);
        pass.set_bind_group(0, &self.bind, &[]);
        let (x, y) = grid(slots);
        pass.dispatch_workgroups(x, y, 1);
        self.scan.record(&self.scan_pipelines, &mut pass);
        pass.set_pipeline(&self.scatter);
        pass.set_bind_group(0, &self.bind, &[]);
        let (x, y) = grid(self.patches);
        pass.dispatch_workgroups(x, y, 1);
        Ok(())
    }

    /// The queue entries buffer: two u32 per entry (patch, edge levels a byte each), level
    /// after level. Usages STORAGE, COPY_SRC.
    pub fn entries_buffer(&self) -> &wgpu::Buffer {
        &self.entries
    }

    /// The scanned slots: level `m`'s queue is `slots[m (P + 1)] .. slots[m (P + 1) + P]`.
    /// Usages STORAGE, COPY_SRC.
    pub fn slots_buffer(&self) -> &wgpu::Buffer {
        &self.slots
    }

    /// Reads the last recorded queues back as [`RenderQueues`]. For tests. Errors: a
    /// non-dyadic plan (the GPU's status flag), or a failed read-back. Cost: a queue wait and
    /// a copy of the slots and entries.
    pub fn read(&self, ctx: &GpuContext) -> Result<RenderQueues, RenderError> {
        let status: Vec<u32> = readback::read(ctx, &self.status, 1)?;
        if status[0] != 0 {
            return Err(RenderError::Invalid(
                "render queues: the plan is not dyadic (use the semi-uniform scheme)".into(),
            ));
        }
        let stride = self.patches as usize + 1;
        let slots: Vec<u32> = readback::read(ctx, &self.slots, stride * (self.max_level as usize + 1))?;
        let mut offsets: Vec<usize> =
            (0..=self.max_level as usize).map(|m| slots[m * stride] as usize).collect();
        offsets.push(slots[stride * (self.max_level as usize + 1) - 1] as usize);
        let total = *offsets.last().unwrap_or(&0);
        let raw: Vec<u32> = readback::read(ctx, &self.entries, 2 * total)?;
        let entries = raw
            .chunks_exact(2)
            .map(|e| QueueEntry { patch: e[0], edge_levels: e[1].to_le_bytes() })
            .collect();
        Ok(RenderQueues { entries, offsets })
    }
}

const INSTANCED: &str = include_str!("../shaders/instanced.wgsl");
const DRAW: &str = include_str!("../shaders/draw.wgsl");

/// Bytes per static-pattern vertex: u, v, t, snap offset (f32), edge (u32; 4 for none).
const PATTERN_STRIDE: u64 = 20;

/// `instanced.wgsl`'s `DrawLevel`, one per level.
#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct DrawLevel {
    level: u32,
    stride: u32,
    max_level: u32,
    vertices: u32,
    base_vertex: u32,
    _pad: [u32; 3],
}

/// The instanced semi-uniform draw: the static patterns `P^0 … P^M` of the set's domain in
/// vertex and index buffers, the render queues built on the GPU ([`GpuRenderQueues`]), each
/// level's `DrawIndexedIndirect` arguments written on the GPU from its queue, and one
/// instanced draw per level whose vertex shader snaps (φ) and evaluates the patch
/// (`shaders/instanced.wgsl`). Sets of one domain (all quads or all triangles).
#[derive(Debug)]
pub struct InstancedDraw {
    queues: GpuRenderQueues,
    set: tessera_gpu::upload::GpuSet,
    pattern_vertices: wgpu::Buffer,
    pattern_indices: wgpu::Buffer,
    /// Per level: vertices, index count, first index, base vertex.
    table: Vec<[u32; 4]>,
    level_args: wgpu::Buffer,
    levels: Vec<wgpu::Buffer>,
    frame: wgpu::Buffer,
    render: wgpu::RenderPipeline,
    args: wgpu::ComputePipeline,
    expand: wgpu::ComputePipeline,
    render_binds: (wgpu::BindGroup, Vec<wgpu::BindGroup>),
    args_binds: (wgpu::BindGroup, wgpu::BindGroup),
    max_level: u32,
    patterns: Vec<tessera::pattern::semi_uniform::StaticPattern>,
}

impl InstancedDraw {
    /// Uploads `set` (its control points and patch rows, `tessera_gpu::upload::GpuSet`) and
    /// the static patterns up to `max_level`, and compiles the pipelines for `format` targets
    /// with `samples` samples. Errors: [`RenderError::Invalid`] for a set mixing triangles
    /// and quads, a level past [`MAX_LEVEL`], or a sample count other than 1 or 4. Cost: the
    /// uploads (O(P + 4^M)) and three shader compilations.
    pub fn new(
        ctx: &GpuContext,
        set: &SurfaceSet,
        max_level: u32,
        format: wgpu::TextureFormat,
        samples: u32,
    ) -> Result<InstancedDraw, RenderError> {
        use tessera::surface::Domain;
        if samples != 1 && samples != 4 {
            return Err(RenderError::Invalid(format!("{samples} samples: use 1 or 4")));
        }
        let domain = set.patches.first().map_or(Domain::Quad, |p| p.domain());
        if set.patches.iter().any(|p| p.domain() != domain) {
            return Err(RenderError::Invalid("the instanced path draws sets of one domain".into()));
        }
        let queues = GpuRenderQueues::new(ctx, set, max_level)?;
        let device = &ctx.device;
        let gpu_set = tessera_gpu::upload::GpuSet::new(device, set)?;
        let patterns = tessera::pattern::semi_uniform::StaticPattern::all(domain, max_level);
        let (mut words, mut indices, mut table) = (Vec::<u32>::new(), Vec::<u32>::new(), Vec::new());
        for p in &patterns {
            let base = (words.len() / 5) as u32;
            table.push([p.vertices.len() as u32, 3 * p.triangles.len() as u32, indices.len() as u32, base]);
            for v in &p.vertices {
                words.extend([v.uv[0].to_bits(), v.uv[1].to_bits(), v.t.to_bits(), v.offset.to_bits()]);
                words.push(v.edge.map_or(4, u32::from));
            }
            indices.extend(p.triangles.iter().flatten());
        }
        use wgpu::util::DeviceExt;
        use wgpu::BufferUsages as U;
        let init = |label: &str, bytes: &[u8], usage| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents: bytes,
                usage,
            })
        };
        let pattern_vertices = init("static patterns", bytemuck::cast_slice(&words), U::VERTEX | U::STORAGE);
        let pattern_indices = init("static pattern indices", bytemuck::cast_slice(&indices), U::INDEX);
        let level_table: Vec<u32> = table.iter().flat_map(|t| [t[1], t[2], t[3]]).collect();
        let level_table = init("level table", bytemuck::cast_slice(&level_table), U::STORAGE);
        let level_args = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("level draw args"),
            size: 20 * (max_level as u64 + 1),
            usage: U::STORAGE | U::INDIRECT | U::COPY_SRC,
            mapped_at_creation: false,
        });
        let stride = set.patches.len() as u32 + 1;
        let levels: Vec<wgpu::Buffer> = (0..=max_level)
            .map(|m| {
                let [vertices, _, _, base_vertex] = table[m as usize];
                let d = DrawLevel { level: m, stride, max_level, vertices, base_vertex, _pad: [0; 3] };
                init("draw level", bytemuck::bytes_of(&d), U::UNIFORM)
            })
            .collect();
        let frame = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("instanced frame"),
            size: std::mem::size_of::<crate::gpu::FrameUniform>() as u64,
            usage: U::UNIFORM | U::COPY_DST,
            mapped_at_creation: false,
        });
        let source = tessera_gpu::shader::expand(
            // The GPU engine's patch evaluation, shared rather than copied (one rule).
            &[tessera_gpu::shader::evaluation_wgsl(gpu_set.has_trees).as_str(), DRAW, INSTANCED].concat(),
            &[
                ("CONTROL_POINTS", tessera_gpu::upload::CONTROL_POINTS),
                ("PATCH_ROW", tessera_gpu::upload::PATCH_ROW),
            ],
        );
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("instanced.wgsl"),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
        let render = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("instanced semi-uniform"),
            layout: None,
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_instanced"),
                compilation_options: Default::default(),
                buffers: &[Some(wgpu::VertexBufferLayout {
                    array_stride: PATTERN_STRIDE,
                    step_mode: wgpu::VertexStepMode::Vertex,
                    attributes: &wgpu::vertex_attr_array![0 => Float32x2, 1 => Float32x2, 2 => Uint32],
                })],
            },
            primitive: wgpu::PrimitiveState { cull_mode: None, ..Default::default() },
            depth_stencil: Some(crate::gpu::depth_state()),
            multisample: wgpu::MultisampleState { count: samples, ..Default::default() },
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs"),
                compilation_options: Default::default(),
                targets: &[Some(format.into())],
            }),
            multiview_mask: None,
            cache: None,
        });
        let compute = |entry: &str| {
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(entry),
                layout: None,
                module: &module,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                cache: None,
            })
        };
        let args = compute("write_level_args");
        let expand = compute("expand");
        let group = |layout: &wgpu::BindGroupLayout, entries: &[(u32, &wgpu::Buffer)]| {
            let entries: Vec<wgpu::BindGroupEntry> = entries
                .iter()
                .map(|&(binding, b)| wgpu::BindGroupEntry { binding, resource: b.as_entire_binding() })
                .collect();
            device.create_bind_group(&wgpu::BindGroupDescriptor { label: None, layout, entries: &entries })
        };
        let render_binds = (
            group(
                &render.get_bind_group_layout(0),
                &[
                    (0, &frame),
                    (6, &gpu_set.control_points),
                    (7, &gpu_set.patch_rows),
                    (8, queues.entries_buffer()),
                    (9, queues.slots_buffer()),
                ],
            ),
            levels.iter().map(|l| group(&render.get_bind_group_layout(1), &[(0, l)])).collect(),
        );
        let args_binds = (
            group(
                &args.get_bind_group_layout(0),
                &[(9, queues.slots_buffer()), (12, &level_table), (13, &level_args)],
            ),
            group(&args.get_bind_group_layout(1), &[(0, &levels[0])]),
        );
        Ok(InstancedDraw {
            queues,
            set: gpu_set,
            pattern_vertices,
            pattern_indices,
            table,
            level_args,
            levels,
            frame,
            render,
            args,
            expand,
            render_binds,
            args_binds,
            max_level,
            patterns,
        })
    }

    /// The render queues (for reading them back in tests).
    pub fn queues(&self) -> &GpuRenderQueues {
        &self.queues
    }

    /// The static patterns `P^0 … P^M` drawn.
    pub fn patterns(&self) -> &[tessera::pattern::semi_uniform::StaticPattern] {
        &self.patterns
    }

    /// Records a frame of `plan` (semi-uniform, levels up to `M`): the queues, the level
    /// arguments, then a render pass that clears the targets and draws every level with one
    /// `draw_indexed_indirect` (no wireframe on this path). Reads nothing back. Errors as
    /// [`GpuRenderQueues::record`].
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        plan: &Plan,
        camera: &tessera::camera::Camera,
        options: &crate::RenderOptions,
        target: &wgpu::TextureView,
        resolve: Option<&wgpu::TextureView>,
        depth: &wgpu::TextureView,
    ) -> Result<(), RenderError> {
        self.queues.record(ctx, encoder, plan)?;
        let options = crate::RenderOptions { wireframe: false, ..*options };
        let frame = crate::gpu::FrameUniform::new(camera, &options, true);
        ctx.queue.write_buffer(&self.frame, 0, bytemuck::bytes_of(&frame));
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("level args"),
                timestamp_writes: None,
            });
            pass.set_pipeline(&self.args);
            pass.set_bind_group(0, &self.args_binds.0, &[]);
            pass.set_bind_group(1, &self.args_binds.1, &[]);
            pass.dispatch_workgroups(1, 1, 1);
        }
        let mut pass =
            crate::gpu::begin_scene_pass(encoder, "instanced semi-uniform", target, resolve, depth);
        pass.set_pipeline(&self.render);
        pass.set_bind_group(0, &self.render_binds.0, &[]);
        pass.set_vertex_buffer(0, self.pattern_vertices.slice(..));
        pass.set_index_buffer(self.pattern_indices.slice(..), wgpu::IndexFormat::Uint32);
        for m in 0..=self.max_level {
            pass.set_bind_group(1, &self.render_binds.1[m as usize], &[]);
            pass.draw_indexed_indirect(&self.level_args, 20 * m as u64);
        }
        Ok(())
    }

    /// For tests: the positions the vertex shader computes for level `m`'s `instances`
    /// instances (the queue's length, e.g. from [`GpuRenderQueues::read`]) after the last
    /// recorded frame, instance after instance, through a compute pass that calls the vertex
    /// shader's own function. A read-back. Cost: a queue wait and the copy.
    pub fn expand_level(
        &self,
        ctx: &GpuContext,
        m: u32,
        instances: usize,
    ) -> Result<Vec<[f32; 3]>, RenderError> {
        let count = instances * self.table[m as usize][0] as usize;
        if count == 0 {
            return Ok(Vec::new());
        }
        let device = &ctx.device;
        let out = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("expanded"),
            size: 16 * count as u64,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let entries = [
            wgpu::BindGroupEntry { binding: 6, resource: self.set.control_points.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 7, resource: self.set.patch_rows.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 8, resource: self.queues.entries_buffer().as_entire_binding() },
            wgpu::BindGroupEntry { binding: 9, resource: self.queues.slots_buffer().as_entire_binding() },
            wgpu::BindGroupEntry { binding: 10, resource: self.pattern_vertices.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 11, resource: out.as_entire_binding() },
        ];
        let g0 = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: None,
            layout: &self.expand.get_bind_group_layout(0),
            entries: &entries,
        });
        let g1 = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: None,
            layout: &self.expand.get_bind_group_layout(1),
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: self.levels[m as usize].as_entire_binding(),
            }],
        });
        let mut encoder = device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            pass.set_pipeline(&self.expand);
            pass.set_bind_group(0, &g0, &[]);
            pass.set_bind_group(1, &g1, &[]);
            let (x, y) = grid(count as u32);
            pass.dispatch_workgroups(x, y, 1);
        }
        ctx.queue.submit([encoder.finish()]);
        let v: Vec<[f32; 4]> = readback::read(ctx, &out, count)?;
        Ok(v.into_iter().map(|p| [p[0], p[1], p[2]]).collect())
    }
}
