//! Animated subdivision cages (Catmull-Clark and Loop) on the GPU: the cage's stencils
//! ([`tessera::subdivision::CageStencils`]) uploaded once, and a pass that recomputes every
//! patch's points from the cage's vertices, so that a deforming cage re-tessellates each frame
//! with only its vertices uploaded (16 bytes a vertex).
//!
//! The rows are the library's ([`CageStencils::rows`], placed by
//! [`CageStencils::point_ranges`]): a regular Catmull-Clark face's 16 control points, and
//! every leaf point of an isolated face's tree or a Loop triangle's where [`crate::upload`]
//! packed it (each tree once, however many
//! patches view it). `stencils.wgsl` applies them in f32 as `SparseRows::apply_row` does in
//! f64. What the pass does not refresh: an isolated patch's 16 slots (the bounding box of its
//! pieces, which culling reads) and the view passes' per-patch bounds (culling's boxes and
//! normal cones, the screen criteria's second-derivative bounds), which
//! [`GpuTessellator::new`] prepared from the set as it was. A deforming cage is therefore
//! drawn from a plan that needs no bounds — a uniform factor or hardware factors planned on
//! the CPU ([`GpuTessellator::prepare`]), without a culling camera — until those bounds are
//! computed on the GPU too.

use glam::DVec3;

use crate::context::GpuContext;
use crate::error::Result;
use crate::shader::{self, Binding};
use crate::upload::{storage_buffer, CONTROL_POINTS};
use crate::GpuTessellator;
use tessera::subdivision::CageStencils;
use tessera::surface::{Patch, SurfaceSet};

/// The rows as the pass reads them.
struct Rows {
    /// Each row's first term, then the end of the last.
    starts: Vec<u32>,
    /// `(cage vertex, f32 weight bits)` per term.
    terms: Vec<[u32; 2]>,
    /// Each row's place in the control points.
    destinations: Vec<u32>,
}

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
    /// Uploads the rows of `set`'s points ([`CageStencils::point_ranges`]) for `tessellator`
    /// (made for `set`), each with the place in the tessellator's control points it refreshes.
    /// The cage's vertices start at the origin: write them ([`GpuStencils::write_positions`])
    /// before the first [`GpuStencils::record`].
    ///
    /// Errors: [`tessera::Error::InvalidParameter`] (as [`crate::GpuError::Tessera`]) when
    /// `set` is not the stencils' cage's, or `tessellator` was not made for `set`. Cost:
    /// O(terms) packing, one upload of 8 bytes a term and 4 a point, one WGSL compilation.
    pub fn new(
        ctx: &GpuContext,
        stencils: &CageStencils,
        set: &SurfaceSet,
        tessellator: &GpuTessellator,
    ) -> Result<GpuStencils> {
        let ranges = stencils.point_ranges(set)?;
        let (patches, tree_blocks) = tessellator.layout();
        let trees =
            set.patches.iter().filter(|p| matches!(p, Patch::Subdivision(_) | Patch::Loop(_))).count();
        if patches as usize != set.patches.len() || (trees > 0) == tree_blocks.is_empty() {
            return Err(tessera::Error::InvalidParameter {
                name: "tessellator",
                reason: format!(
                    "it was made for a set of {patches} patches and {} trees, not this one of {}",
                    tree_blocks.len(),
                    set.patches.len()
                ),
            }
            .into());
        }
        let all = stencils.rows();
        let mut rows = Rows { starts: vec![0], terms: Vec::new(), destinations: Vec::new() };
        let mut push = |r: usize, destination: usize| {
            let range = all.starts[r] as usize..all.starts[r + 1] as usize;
            let terms = all.vertices[range.clone()].iter().zip(&all.weights[range]);
            rows.terms.extend(terms.map(|(&v, &w)| [v, (w as f32).to_bits()]));
            rows.starts.push(rows.terms.len() as u32);
            rows.destinations.push(destination as u32);
        };
        for (p, patch) in set.patches.iter().enumerate() {
            if matches!(patch, Patch::Bicubic(_)) {
                ranges[p].clone().enumerate().for_each(|(k, r)| push(r, CONTROL_POINTS as usize * p + k));
            }
        }
        for &(p, block) in tree_blocks {
            let mut r = ranges[p].start;
            for (at, points) in crate::upload::leaf_offsets(&set.patches[p]) {
                for j in 0..points as usize {
                    push(r, (block + at + 1) as usize + j);
                    r += 1;
                }
            }
        }
        let device = &ctx.device;
        let count = rows.destinations.len() as u32;
        let uniform = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("stencil rows"),
            size: 16,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        ctx.queue.write_buffer(&uniform, 0, bytemuck::cast_slice(&[count, 0, 0, 0]));
        let starts = storage_buffer(device, "stencil starts", &rows.starts);
        let terms = storage_buffer(device, "stencil terms", &rows.terms);
        let destinations = storage_buffer(device, "stencil destinations", &rows.destinations);
        let positions = storage_buffer(device, "cage vertices", &vec![[0f32; 4]; stencils.vertex_count()]);
        let layout = shader::layout(
            device,
            &[Binding::Uniform, Binding::Read, Binding::Read, Binding::Read, Binding::Read, Binding::Write],
        );
        let module =
            shader::module(device, "stencils", &[shader::sources::THREADS, shader::sources::STENCILS], &[]);
        let pipeline = shader::pipeline(device, &module, "apply_stencils", &layout);
        let bind_group = shader::bind(
            device,
            &layout,
            &[&uniform, &starts, &terms, &destinations, &positions, tessellator.control_points()],
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

    /// Records the pass that recomputes the tessellator's points from the positions last
    /// written; record it before the frame ([`GpuTessellator::record`]) in the same or an
    /// earlier submission. Cost: one invocation per point, as many multiply-adds as its row
    /// has terms (16 for a regular face's control point, more near features).
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
