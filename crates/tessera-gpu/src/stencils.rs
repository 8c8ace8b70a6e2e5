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
//! f64.
//!
//! A cage planned from the camera (culling, a pixel error) also needs each patch's view
//! bounds — its box and sphere, normal cone, second-derivative and boundary-curve bounds —
//! for the moved surface. [`GpuStencils::with_moving_bounds`] keeps the rest cage's and, per
//! patch, what each cage vertex's displacement can add to them beyond the affine map that
//! best follows the patch's vertices ([`tessera::subdivision::moving_bounds`], where the rule
//! is proven); a second pass,
//! `moving_bounds.wgsl`, adds them up each frame from the same uploaded vertices (and
//! rewrites an isolated patch's 16 slots, the box of its pieces that culling reads). The
//! bounds are conservative and loosen as the cage moves away from its rest pose: the frame
//! keeps its pixel-error guarantee with more triangles than a set rebuilt at the pose would
//! get. Made with [`GpuStencils::new`], the bounds stay the rest cage's, so a deforming cage
//! is then drawn from a plan that needs none (a uniform factor or hardware factors planned
//! on the CPU, [`GpuTessellator::prepare`], without a culling camera).

use glam::DVec3;

use crate::context::GpuContext;
use crate::error::Result;
use crate::shader::{self, Binding};
use crate::tessellator::PATCH_VIEW_ROW;
use crate::upload::{storage_buffer, CONTROL_POINTS};
use crate::GpuTessellator;
use tessera::scheme::Prepared;
use tessera::subdivision::moving_bounds::MovingBounds;
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
    moving: Option<MovingPass>,
}

/// The view rows of a patch the moving-bounds pass keeps from the rest cage: cone, sphere,
/// trigonometry, box (2), second-derivative bound, boundary curves.
const REST_ROWS: u32 = 7;

/// `moving_bounds.wgsl`, bound to a tessellator's view rows and control points.
#[derive(Debug)]
struct MovingPass {
    patches: u32,
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
        let uniform = count_uniform(device, "stencil rows", count);
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
            moving: None,
        })
    }

    /// [`GpuStencils::new`], and every frame's view bounds moved with the cage (module doc):
    /// `tessellator` can then plan from the camera ([`GpuTessellator::prepare_screen`] with a
    /// pixel error and the uniform, transition or semi-uniform scheme, or culling alone) on
    /// the moved cage. `rest` are the cage vertices `set` was built from and `prepared` its
    /// bounds (`Prepared::new(set, true)`, the one given to `prepare_screen`); the rows are
    /// uploaded now, so the first frame may come before any position is written.
    ///
    /// Errors: as [`GpuStencils::new`]; [`tessera::Error::InvalidParameter`] for `rest` of
    /// another count or not finite; as [`GpuTessellator::prepare_screen`] for a `prepared`
    /// without bounds. Later, `prepare_screen` refuses the criteria that read what the pass
    /// does not move (silhouetteness, SD-2, ESC) with [`crate::GpuError::Unsupported`]. Cost:
    /// [`MovingBounds::new`] (a bound per patch and neighbourhood vertex, parallel, once per
    /// topology), an upload of 32 bytes a term and 112 a patch, one WGSL compilation.
    pub fn with_moving_bounds(
        ctx: &GpuContext,
        stencils: &CageStencils,
        set: &SurfaceSet,
        tessellator: &mut GpuTessellator,
        prepared: &Prepared,
        rest: &[DVec3],
    ) -> Result<GpuStencils> {
        let mut out = Self::new(ctx, stencils, set, tessellator)?;
        tessera::subdivision::stencils::check_positions(rest, out.vertex_count)?;
        let bounds = MovingBounds::new(stencils, set)?;
        let rows = tessellator.moving_view_rows(ctx, set, prepared)?;
        let (per_patch, kept) = (PATCH_VIEW_ROW as usize, REST_ROWS as usize);
        let mut rest_rows = Vec::with_capacity(kept * set.patches.len());
        for (p, patch) in set.patches.iter().enumerate() {
            let first = rest_rows.len();
            rest_rows.extend_from_slice(&rows[per_patch * p..per_patch * p + kept]);
            // Row 2's w (0 in the view rows) marks a tree, whose 16 slots hold its box.
            rest_rows[first + 2][3] =
                f32::from(u8::from(matches!(patch, Patch::Subdivision(_) | Patch::Loop(_))));
        }
        let terms: Vec<[f32; 4]> = bounds
            .terms
            .iter()
            .flat_map(|t| [[t[0], t[1], t[2], t[3]], [t[4], t[5], t[6], t[7]]].map(|r| r.map(|x| x as f32)))
            .collect();
        let rest_cage: Vec<[f32; 4]> =
            rest.iter().map(|p| [p.x as f32, p.y as f32, p.z as f32, 1.0]).collect();
        let device = &ctx.device;
        let patches = set.patches.len() as u32;
        let uniform = count_uniform(device, "moving bounds", patches);
        let starts = storage_buffer(device, "moving bounds starts", &bounds.starts);
        let vertices = storage_buffer(device, "moving bounds vertices", &bounds.vertices);
        // A set without terms (every face a hole) still binds one term: `storage_buffer`'s
        // padding is 4 bytes, and the shader's array holds 16-byte rows.
        let terms = storage_buffer(
            device,
            "moving bounds terms",
            &if terms.is_empty() { vec![[0f32; 4]; 2] } else { terms },
        );
        let rest_rows = storage_buffer(device, "moving bounds rest rows", &rest_rows);
        let rest_cage = storage_buffer(device, "rest cage vertices", &rest_cage);
        let layout = shader::layout(
            device,
            &[
                Binding::Uniform,
                Binding::Read,
                Binding::Read,
                Binding::Read,
                Binding::Read,
                Binding::Read,
                Binding::Read,
                Binding::Write,
                Binding::Write,
            ],
        );
        let module = shader::module(
            device,
            "moving bounds",
            &[shader::sources::THREADS, shader::sources::MOVING_BOUNDS],
            &[
                ("REST_ROWS", REST_ROWS),
                ("PATCH_VIEW_ROW", PATCH_VIEW_ROW),
                ("CONTROL_POINTS", CONTROL_POINTS),
            ],
        );
        let pipeline = shader::pipeline(device, &module, "apply_moving_bounds", &layout);
        let bind_group = shader::bind(
            device,
            &layout,
            &[
                &uniform,
                &starts,
                &vertices,
                &terms,
                &rest_rows,
                &rest_cage,
                &out.positions,
                tessellator.patch_views(),
                tessellator.control_points(),
            ],
        );
        // The moved positions start at the rest pose (the rows as uploaded).
        out.write_positions(ctx, rest)?;
        out.moving = Some(MovingPass { patches, pipeline, bind_group });
        Ok(out)
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
        if let Some(moving) = &self.moving {
            pass.set_pipeline(&moving.pipeline);
            pass.set_bind_group(0, &moving.bind_group, &[]);
            let (x, y) = shader::grid(moving.patches.div_ceil(shader::WORKGROUP));
            pass.dispatch_workgroups(x, y, 1);
        }
    }
}

/// A uniform buffer holding `count` (`vec4<u32>`'s first lane): a pass's element count.
fn count_uniform(device: &wgpu::Device, label: &str, count: u32) -> wgpu::Buffer {
    use wgpu::util::DeviceExt;
    device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(label),
        contents: bytemuck::cast_slice(&[count, 0, 0, 0]),
        usage: wgpu::BufferUsages::UNIFORM,
    })
}
