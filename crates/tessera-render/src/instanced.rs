//! The instanced semi-uniform path (paper 000, §4), first part: the per-level **render
//! queues built on the GPU** by counting and an exclusive scan per level
//! (`shaders/queues.wgsl`, the GPU form of [`tessera::engine::render_queues::build`]), from
//! a semi-uniform plan, with no read-back.
//!
//! Not done yet: the static patterns `P^0 … P^M` in GPU buffers and the one instanced draw
//! per level with the snap `φ` and the patch evaluation in the vertex shader (Listing 1);
//! [`tessera::engine::render_queues::draw`] is the CPU reference they will be tested
//! against.

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
        let mut pass =
            encoder.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("render queues"), timestamp_writes: None });
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
        let mut offsets: Vec<usize> = (0..=self.max_level as usize).map(|m| slots[m * stride] as usize).collect();
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
