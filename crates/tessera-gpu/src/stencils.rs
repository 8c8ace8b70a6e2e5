//! Animated Catmull-Clark cages on the GPU: the cage's stencils
//! ([`tessera::subdivision::CageStencils`]) uploaded once, and a pass that recomputes every
//! patch's control points from the cage's vertices, so that a deforming cage re-tessellates
//! each frame with only its vertices uploaded (16 bytes a vertex).
//!
//! The rows are the library's ([`CageStencils::bicubic_rows`]), applied by `stencils.wgsl`
//! in f32 as `SparseRows::apply_row` applies them in f64. What the pass does not refresh:
//! the view passes' per-patch bounds (culling's boxes and normal cones, the screen criteria's
//! second-derivative bounds), which [`GpuTessellator::new`] prepared from the set as it was.
//! A deforming cage is therefore drawn from a plan that needs no bounds — a uniform factor
//! or hardware factors planned on the CPU ([`GpuTessellator::prepare`]), without a culling
//! camera — until those bounds are computed on the GPU too.

use glam::DVec3;

use crate::context::GpuContext;
use crate::error::Result;
use crate::shader::{self, Binding};
use crate::upload::storage_buffer;
use crate::GpuTessellator;
use tessera::subdivision::CageStencils;
use tessera::surface::SurfaceSet;

/// A cage's stencils on the device, bound to one tessellator's control points.
#[derive(Debug)]
pub struct GpuStencils {
    rows: u32,
    vertex_count: usize,
    positions: wgpu::Buffer,
    pipeline: wgpu::ComputePipeline,
    bind_group: wgpu::BindGroup,
}

impl GpuStencils {
    /// Uploads the rows of `set`'s control points ([`CageStencils::bicubic_rows`]) for
    /// `tessellator` (made for `set`). The cage's vertices start at the origin: write them
    /// ([`GpuStencils::write_positions`]) before the first [`GpuStencils::record`].
    ///
    /// Errors: those of `bicubic_rows` (a set with isolated faces, whose pieces this pass does
    /// not move yet, or another cage's set), as [`crate::GpuError::Tessera`]. Cost: O(terms)
    /// packing, one upload of 8 bytes a term, one WGSL compilation.
    pub fn new(
        ctx: &GpuContext,
        stencils: &CageStencils,
        set: &SurfaceSet,
        tessellator: &GpuTessellator,
    ) -> Result<GpuStencils> {
        let rows = stencils.bicubic_rows(set)?;
        let terms: Vec<[u32; 2]> =
            rows.vertices.iter().zip(&rows.weights).map(|(&v, &w)| [v, (w as f32).to_bits()]).collect();
        let device = &ctx.device;
        let count = rows.len() as u32;
        let uniform = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("stencil rows"),
            size: 16,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        ctx.queue.write_buffer(&uniform, 0, bytemuck::cast_slice(&[count, 0, 0, 0]));
        let starts = storage_buffer(device, "stencil starts", &rows.starts);
        let terms = storage_buffer(device, "stencil terms", &terms);
        let positions = storage_buffer(device, "cage vertices", &vec![[0f32; 4]; stencils.vertex_count()]);
        let layout = shader::layout(
            device,
            &[Binding::Uniform, Binding::Read, Binding::Read, Binding::Read, Binding::Write],
        );
        let module =
            shader::module(device, "stencils", &[shader::sources::THREADS, shader::sources::STENCILS], &[]);
        let pipeline = shader::pipeline(device, &module, "apply_stencils", &layout);
        let bind_group = shader::bind(
            device,
            &layout,
            &[&uniform, &starts, &terms, &positions, tessellator.control_points()],
        );
        Ok(GpuStencils {
            rows: count,
            vertex_count: stencils.vertex_count(),
            positions,
            pipeline,
            bind_group,
        })
    }

    /// Uploads the cage's vertex positions for the next [`GpuStencils::record`] (as f32).
    ///
    /// Errors: [`tessera::Error::InvalidParameter`] (as [`crate::GpuError::Tessera`]) for
    /// another count of positions or a position that is not finite. Cost: one upload of 16
    /// bytes a vertex.
    pub fn write_positions(&self, ctx: &GpuContext, positions: &[DVec3]) -> Result<()> {
        tessera::subdivision::stencils::check_positions(positions, self.vertex_count)?;
        let packed: Vec<[f32; 4]> =
            positions.iter().map(|p| [p.x as f32, p.y as f32, p.z as f32, 1.0]).collect();
        ctx.queue.write_buffer(&self.positions, 0, bytemuck::cast_slice(&packed));
        Ok(())
    }

    /// Records the pass that recomputes the tessellator's control points from the positions
    /// last written; record it before the frame ([`GpuTessellator::record`]) in the same or
    /// an earlier submission. Cost: one invocation per control point, as many multiply-adds
    /// as its row has terms (16 for a regular face).
    pub fn record(&self, encoder: &mut wgpu::CommandEncoder) {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("apply stencils"),
            timestamp_writes: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &self.bind_group, &[]);
        let (x, y) = shader::grid(self.rows.div_ceil(shader::WORKGROUP));
        pass.dispatch_workgroups(x, y, 1);
    }
}
