//! The wgpu renderer: one render pipeline (`shaders/draw.wgsl`) that draws a mesh from
//! storage buffers in [`tessera_gpu::VERTEX_LAYOUT`] — the GPU engine's own output buffers,
//! or a CPU mesh uploaded in the same layout ([`MeshBuffers`]) — with the draw count taken
//! from `DrawIndexedIndirect` arguments on the device, so a GPU-tessellated frame is drawn
//! without any read-back.
//!
//! Why vertex pulling instead of binding the vertex buffer: the anti-aliased wireframe needs
//! each corner's barycentric coordinate and the patch colours need each triangle's index;
//! WGSL has no barycentric built-in, and with shared (indexed) vertices a corner cannot
//! carry them. Pulling `indices[k]` for vertex invocation `k` gives both (`k % 3`, `k / 3`)
//! at the cost of one small compute pass (`shaders/args.wgsl`) that turns the indexed draw
//! arguments into plain ones.

use crate::shading::{self, ColorMode};
use crate::{Image, RenderError};
use std::borrow::Cow;
use tessera::camera::Camera;
use tessera::mesh::Mesh;
use tessera_gpu::GpuContext;
use wgpu::util::DeviceExt;

const DRAW: &str = include_str!("../shaders/draw.wgsl");
const ARGS: &str = include_str!("../shaders/args.wgsl");

/// The format of offscreen images: 8-bit RGBA, values written as the shader computes them
/// (see [`crate::shading`]).
pub const IMAGE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

/// The depth buffer's format.
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// What to draw and how, beside the geometry and the camera (whose viewport is the image
/// size).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RenderOptions {
    /// Overlay the triangle edges, anti-aliased.
    pub wireframe: bool,
    /// Base colours.
    pub color: ColorMode,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions { wireframe: true, color: ColorMode::Shaded }
    }
}

/// A triangle mesh on the device, as [`Renderer::record`] reads it: buffers with `STORAGE`
/// usage (the GPU engine's have it).
#[derive(Debug, Clone, Copy)]
pub struct Geometry<'a> {
    /// Vertices in [`tessera_gpu::VERTEX_LAYOUT`] (8 f32 each: position, normal, uv).
    pub vertices: &'a wgpu::Buffer,
    /// u32 triangle list.
    pub indices: &'a wgpu::Buffer,
    /// `DrawIndexedIndirect` arguments at offset 0 (20 bytes), e.g.
    /// [`tessera_gpu::GpuTessellator::indirect_buffer`].
    pub indexed_args: &'a wgpu::Buffer,
    /// Optional: the patch of each triangle (u32), for [`ColorMode::Patch`] and
    /// [`ColorMode::Level`]; without it every triangle counts as patch 0.
    pub triangle_patch: Option<&'a wgpu::Buffer>,
    /// Optional: each patch's level in [0, 1] (f32, [`crate::patch_levels`]), for
    /// [`ColorMode::Level`].
    pub patch_level: Option<&'a wgpu::Buffer>,
}

/// A CPU [`Mesh`] uploaded in the GPU engine's layout, with its own indexed draw arguments,
/// so that [`Renderer`] draws it exactly as it draws the GPU engine's output.
///
/// A mesh whose vertices or indices would exceed one storage binding
/// (`max_storage_buffer_binding_size`, or `max_buffer_size` where smaller) is uploaded in
/// parts: runs of consecutive triangles, each with the vertices it uses renumbered from 0, so
/// each part's buffers fit a binding wherever its triangles' vertices lie in the mesh. Drawn
/// in order in one pass ([`MeshBuffers::geometries`]), the parts give the picture of the whole
/// mesh pixel for pixel: the same triangles in the same order, the same per-triangle patches.
#[derive(Debug)]
pub struct MeshBuffers {
    parts: Vec<MeshPart>,
    patch_level: wgpu::Buffer,
}

/// One part of [`MeshBuffers`].
#[derive(Debug)]
struct MeshPart {
    vertices: wgpu::Buffer,
    indices: wgpu::Buffer,
    /// `[3 T, 1, 0, 0, 0]` for the part's T triangles.
    indexed_args: wgpu::Buffer,
    triangle_patch: wgpu::Buffer,
}

/// Bytes of one vertex in [`tessera_gpu::VERTEX_LAYOUT`].
const VERTEX_BYTES: u64 = 32;

/// One part of a split mesh, as [`split`] makes it: triangles `[first, end)`; for a mesh that
/// fits whole, no renumbering (`renumbered` is None).
struct SplitPart {
    first: usize,
    end: usize,
    /// The part's vertices (global numbers, in first use) and its indices into them.
    renumbered: Option<(Vec<u32>, Vec<u32>)>,
}

/// Splits `mesh` so that no part has more than `max_vertices` vertices or `max_triangles`
/// triangles. Greedy in triangle order, with a stamp per vertex reset for what each part
/// touched, so the whole split costs O(V + T).
fn split(mesh: &Mesh, max_vertices: usize, max_triangles: usize) -> Vec<SplitPart> {
    let (v, t) = (mesh.vertex_count(), mesh.triangle_count());
    if v <= max_vertices && t <= max_triangles {
        return vec![SplitPart { first: 0, end: t, renumbered: None }];
    }
    let mut local = vec![u32::MAX; v];
    let mut parts = Vec::new();
    let (mut used, mut indices): (Vec<u32>, Vec<u32>) = (Vec::new(), Vec::new());
    let mut first = 0;
    for tri in 0..t {
        let corners = mesh.triangle(tri);
        let fresh = (0..3)
            .filter(|&k| local[corners[k] as usize] == u32::MAX && !corners[..k].contains(&corners[k]))
            .count();
        if used.len() + fresh > max_vertices || tri - first >= max_triangles {
            for &g in &used {
                local[g as usize] = u32::MAX;
            }
            let renumbered = (std::mem::take(&mut used), std::mem::take(&mut indices));
            parts.push(SplitPart { first, end: tri, renumbered: Some(renumbered) });
            first = tri;
        }
        for c in corners {
            if local[c as usize] == u32::MAX {
                local[c as usize] = used.len() as u32;
                used.push(c);
            }
            indices.push(local[c as usize]);
        }
    }
    parts.push(SplitPart { first, end: t, renumbered: Some((used, indices)) });
    parts
}

impl MeshBuffers {
    /// Uploads `mesh` (interleaved into [`tessera_gpu::VERTEX_LAYOUT`]) and `patch_level`
    /// (one per patch; may be empty), in parts where the device's binding limits require it.
    /// Errors: [`RenderError::Wgpu`] when the device cannot hold the buffers (out of memory).
    /// Cost: O(V + T) packing (plus renumbering when split) and one upload.
    pub fn upload(ctx: &GpuContext, mesh: &Mesh, patch_level: &[f32]) -> Result<MeshBuffers, RenderError> {
        Self::upload_within(ctx, mesh, patch_level, u64::MAX)
    }

    /// [`MeshBuffers::upload`] with every buffer of a part at most `max_binding_bytes` (and
    /// within the device's limits): for tests of the split on small meshes, and callers that
    /// want smaller buffers. Errors: as [`MeshBuffers::upload`], and [`RenderError::Invalid`]
    /// for a cap below one triangle's vertices (96 bytes).
    pub fn upload_within(
        ctx: &GpuContext,
        mesh: &Mesh,
        patch_level: &[f32],
        max_binding_bytes: u64,
    ) -> Result<MeshBuffers, RenderError> {
        let limit =
            max_binding_bytes.min(ctx.limits.max_storage_buffer_binding_size).min(ctx.limits.max_buffer_size);
        if limit < 3 * VERTEX_BYTES {
            return Err(RenderError::Invalid(format!(
                "a binding of {limit} bytes cannot hold one triangle's vertices"
            )));
        }
        let max_vertices = usize::try_from(limit / VERTEX_BYTES).unwrap_or(usize::MAX);
        let max_triangles = usize::try_from(limit / 12).unwrap_or(usize::MAX);
        let parts = split(mesh, max_vertices, max_triangles);
        let storage = |label: &str, bytes: &[u8]| {
            // Zero-sized buffers cannot be bound: keep 16 bytes at least.
            let mut data = bytes.to_vec();
            data.resize(data.len().max(16), 0);
            ctx.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents: &data,
                usage: wgpu::BufferUsages::STORAGE,
            })
        };
        let vertex = |out: &mut Vec<f32>, i: usize| {
            out.extend_from_slice(&mesh.positions[i]);
            out.extend_from_slice(mesh.normals.get(i).unwrap_or(&[0.0; 3]));
            out.extend_from_slice(mesh.uvs.get(i).unwrap_or(&[0.0; 2]));
        };
        crate::scoped(&ctx.device, "uploading the mesh", || {
            let parts = parts
                .into_iter()
                .map(|SplitPart { first, end, renumbered }| {
                    let (interleaved, indices) = match renumbered {
                        None => {
                            let mut interleaved = Vec::with_capacity(8 * mesh.vertex_count());
                            (0..mesh.vertex_count()).for_each(|i| vertex(&mut interleaved, i));
                            (interleaved, Cow::Borrowed(&mesh.indices[..]))
                        }
                        Some((used, indices)) => {
                            let mut interleaved = Vec::with_capacity(8 * used.len());
                            used.iter().for_each(|&g| vertex(&mut interleaved, g as usize));
                            (interleaved, Cow::Owned(indices))
                        }
                    };
                    let patches = mesh.triangle_patch.get(first..end.min(mesh.triangle_patch.len()));
                    let args = [indices.len() as u32, 1, 0, 0, 0];
                    MeshPart {
                        vertices: storage("mesh vertices", bytemuck::cast_slice(&interleaved)),
                        indices: storage("mesh indices", bytemuck::cast_slice(&indices[..])),
                        indexed_args: storage("mesh draw args", bytemuck::cast_slice(&args)),
                        triangle_patch: storage(
                            "mesh triangle patches",
                            bytemuck::cast_slice(patches.unwrap_or(&[])),
                        ),
                    }
                })
                .collect();
            MeshBuffers {
                parts,
                patch_level: storage("mesh patch levels", bytemuck::cast_slice(patch_level)),
            }
        })
    }

    /// How many parts the mesh was uploaded in (1 unless it exceeded a binding).
    pub fn part_count(&self) -> usize {
        self.parts.len()
    }

    /// The parts as [`Geometry`], to draw together in this order ([`Renderer::record`]).
    pub fn geometries(&self) -> Vec<Geometry<'_>> {
        self.parts
            .iter()
            .map(|p| Geometry {
                vertices: &p.vertices,
                indices: &p.indices,
                indexed_args: &p.indexed_args,
                triangle_patch: Some(&p.triangle_patch),
                patch_level: Some(&self.patch_level),
            })
            .collect()
    }
}

/// `draw.wgsl`'s `Frame`.
#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct FrameUniform {
    view_proj: [f32; 16],
    eye: [f32; 4],
    light: [f32; 4],
    flags: [u32; 4],
}

impl FrameUniform {
    pub(crate) fn new(camera: &Camera, options: &RenderOptions, has_patches: bool) -> FrameUniform {
        let (r, u, f) = camera.basis();
        let light = shading::light_direction(r.as_vec3(), u.as_vec3(), f.as_vec3());
        let e = camera.eye.as_vec3();
        FrameUniform {
            view_proj: camera.view_projection().as_mat4().to_cols_array(),
            eye: [e.x, e.y, e.z, 1.0],
            light: [light.x, light.y, light.z, 0.0],
            flags: [options.color.code(), options.wireframe as u32, has_patches as u32, 0],
        }
    }
}

/// The renderer's pipelines for one colour format and sample count, and its small
/// per-draw buffers. Make it once; [`Renderer::record`] draws a frame.
#[derive(Debug)]
pub struct Renderer {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    args_pipeline: wgpu::ComputePipeline,
    args_layout: wgpu::BindGroupLayout,
    uniform: wgpu::Buffer,
    draw_args: wgpu::Buffer,
    draw_info: wgpu::Buffer,
    dummy: wgpu::Buffer,
    format: wgpu::TextureFormat,
    samples: u32,
}

fn entry(binding: u32, buffer: &wgpu::Buffer) -> wgpu::BindGroupEntry<'_> {
    wgpu::BindGroupEntry { binding, resource: buffer.as_entire_binding() }
}

fn storage_entry(
    binding: u32,
    visibility: wgpu::ShaderStages,
    read_only: bool,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

impl Renderer {
    /// Compiles the pipelines for colour targets of `format` with `samples` samples per pixel
    /// (1 or 4: the counts every WebGPU adapter supports for [`IMAGE_FORMAT`] and
    /// [`DEPTH_FORMAT`]). Errors: [`RenderError::Invalid`] for another count,
    /// [`RenderError::Wgpu`] when wgpu refuses the pipelines (e.g. a format that cannot be
    /// rendered to). Cost: two shader compilations (tens of ms on lavapipe).
    pub fn new(ctx: &GpuContext, format: wgpu::TextureFormat, samples: u32) -> Result<Renderer, RenderError> {
        if samples != 1 && samples != 4 {
            return Err(RenderError::Invalid(format!("--msaa {samples}: use 1 or 4 samples per pixel")));
        }
        crate::scoped(&ctx.device, "compiling the renderer's pipelines", || Self::make(ctx, format, samples))
    }

    fn make(ctx: &GpuContext, format: wgpu::TextureFormat, samples: u32) -> Renderer {
        let device = &ctx.device;
        let vf = wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::FRAGMENT;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("draw"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: vf,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
                storage_entry(1, wgpu::ShaderStages::VERTEX, true),
                storage_entry(2, wgpu::ShaderStages::VERTEX, true),
                storage_entry(3, wgpu::ShaderStages::VERTEX, true),
                storage_entry(4, wgpu::ShaderStages::VERTEX, true),
                storage_entry(5, wgpu::ShaderStages::VERTEX, true),
            ],
        });
        let args_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("draw args"),
            entries: &[
                storage_entry(0, wgpu::ShaderStages::COMPUTE, true),
                storage_entry(1, wgpu::ShaderStages::COMPUTE, false),
                storage_entry(2, wgpu::ShaderStages::COMPUTE, false),
            ],
        });
        let pipeline_layout = |l: &wgpu::BindGroupLayout| {
            device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: None,
                bind_group_layouts: &[Some(l)],
                immediate_size: 0,
            })
        };
        let draw = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("draw.wgsl"),
            source: wgpu::ShaderSource::Wgsl(DRAW.into()),
        });
        let args = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("args.wgsl"),
            source: wgpu::ShaderSource::Wgsl(ARGS.into()),
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("tessera draw"),
            layout: Some(&pipeline_layout(&layout)),
            vertex: wgpu::VertexState {
                module: &draw,
                entry_point: Some("vs"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            // Both sides: open models show their insides (shaded darker).
            primitive: wgpu::PrimitiveState { cull_mode: None, ..Default::default() },
            depth_stencil: Some(depth_state()),
            multisample: wgpu::MultisampleState { count: samples, ..Default::default() },
            fragment: Some(wgpu::FragmentState {
                module: &draw,
                entry_point: Some("fs"),
                compilation_options: Default::default(),
                targets: &[Some(format.into())],
            }),
            multiview_mask: None,
            cache: None,
        });
        let args_pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("tessera draw args"),
            layout: Some(&pipeline_layout(&args_layout)),
            module: &args,
            entry_point: Some("convert"),
            compilation_options: Default::default(),
            cache: None,
        });
        let buffer = |label: &str, size: u64, usage: wgpu::BufferUsages| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage,
                mapped_at_creation: false,
            })
        };
        use wgpu::BufferUsages as U;
        Renderer {
            pipeline,
            layout,
            args_pipeline,
            args_layout,
            uniform: buffer(
                "draw frame",
                std::mem::size_of::<FrameUniform>() as u64,
                U::UNIFORM | U::COPY_DST,
            ),
            draw_args: buffer("draw indirect", 16, U::STORAGE | U::INDIRECT),
            draw_info: buffer("draw info", 16, U::STORAGE),
            dummy: buffer("draw dummy", 16, U::STORAGE),
            format,
            samples,
        }
    }

    /// The colour format the pipeline draws to.
    pub fn format(&self) -> wgpu::TextureFormat {
        self.format
    }

    /// Samples per pixel.
    pub fn samples(&self) -> u32 {
        self.samples
    }

    /// Records one frame: the args pass, then a render pass that clears `target` to
    /// [`shading::BACKGROUND`] and draws `parts` in order (one mesh: one geometry, or the
    /// parts of [`MeshBuffers::geometries`]) seen from `camera` (its viewport should be the
    /// target's size). `target` is the colour attachment (multisampled when the renderer is,
    /// then resolved into `resolve`), `depth` a [`DEPTH_FORMAT`] view of the same size and
    /// sample count. Writes the frame uniform with `queue.write_buffer`, so one renderer draws
    /// one frame per submission. Reads nothing back. Errors: [`RenderError::Wgpu`] when wgpu
    /// refuses a binding (e.g. a buffer past the device's binding limit); nothing is recorded
    /// for a refused part.
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
        resolve: Option<&wgpu::TextureView>,
        depth: &wgpu::TextureView,
        parts: &[Geometry<'_>],
        camera: &Camera,
        options: &RenderOptions,
    ) -> Result<(), RenderError> {
        let device = &ctx.device;
        let has_patches = parts.iter().any(|g| g.triangle_patch.is_some());
        let frame = FrameUniform::new(camera, options, has_patches);
        ctx.queue.write_buffer(&self.uniform, 0, bytemuck::bytes_of(&frame));
        // One slot of draw arguments and draw info per part, at the storage offset alignment
        // (the renderer's own one-slot buffers when there is one part).
        let stride = (ctx.limits.min_storage_buffer_offset_alignment as u64).max(16);
        let slots = crate::scoped(device, "making the draw buffers", || {
            (parts.len() > 1).then(|| {
                let size = stride * parts.len() as u64;
                let make = |label, usage| {
                    device.create_buffer(&wgpu::BufferDescriptor {
                        label: Some(label),
                        size,
                        usage,
                        mapped_at_creation: false,
                    })
                };
                use wgpu::BufferUsages as U;
                (make("draw indirect parts", U::STORAGE | U::INDIRECT), make("draw info parts", U::STORAGE))
            })
        })?;
        let (draw_args, draw_info) = match &slots {
            Some((a, i)) => (a, i),
            None => (&self.draw_args, &self.draw_info),
        };
        let slot = |buffer, k: usize| wgpu::BufferBinding {
            buffer,
            offset: k as u64 * stride,
            size: wgpu::BufferSize::new(16),
        };
        let binds = crate::scoped(device, "binding the mesh", || {
            parts
                .iter()
                .enumerate()
                .map(|(k, geometry)| {
                    let args = device.create_bind_group(&wgpu::BindGroupDescriptor {
                        label: Some("draw args"),
                        layout: &self.args_layout,
                        entries: &[
                            entry(0, geometry.indexed_args),
                            wgpu::BindGroupEntry {
                                binding: 1,
                                resource: wgpu::BindingResource::Buffer(slot(draw_args, k)),
                            },
                            wgpu::BindGroupEntry {
                                binding: 2,
                                resource: wgpu::BindingResource::Buffer(slot(draw_info, k)),
                            },
                        ],
                    });
                    let draw = device.create_bind_group(&wgpu::BindGroupDescriptor {
                        label: Some("draw"),
                        layout: &self.layout,
                        entries: &[
                            entry(0, &self.uniform),
                            entry(1, geometry.vertices),
                            entry(2, geometry.indices),
                            entry(3, geometry.triangle_patch.unwrap_or(&self.dummy)),
                            entry(4, geometry.patch_level.unwrap_or(&self.dummy)),
                            wgpu::BindGroupEntry {
                                binding: 5,
                                resource: wgpu::BindingResource::Buffer(slot(draw_info, k)),
                            },
                        ],
                    });
                    (args, draw)
                })
                .collect::<Vec<_>>()
        })?;
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("draw args"),
                timestamp_writes: None,
            });
            pass.set_pipeline(&self.args_pipeline);
            for (args, _) in &binds {
                pass.set_bind_group(0, args, &[]);
                pass.dispatch_workgroups(1, 1, 1);
            }
        }
        let mut pass = begin_scene_pass(encoder, "tessera draw", target, resolve, depth);
        pass.set_pipeline(&self.pipeline);
        for (k, (_, draw)) in binds.iter().enumerate() {
            pass.set_bind_group(0, draw, &[]);
            pass.draw_indirect(draw_args, k as u64 * stride);
        }
        Ok(())
    }
}

/// Render targets of one size: the (multisampled) colour and depth textures and, with MSAA,
/// the single-sample texture they resolve into.
#[derive(Debug)]
pub struct Targets {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    colour: wgpu::Texture,
    resolve: Option<wgpu::Texture>,
    depth: wgpu::Texture,
}

impl Targets {
    /// Textures for `renderer` (its format and sample count) of `width × height`. Errors:
    /// [`RenderError::ImageTooLarge`] from [`crate::check_image_size`] (a side past the
    /// device's texture limit, targets past the memory caps), checked before anything is
    /// allocated; [`RenderError::Wgpu`] when the device still cannot make them. Cost: the
    /// allocation.
    pub fn new(
        ctx: &GpuContext,
        renderer: &Renderer,
        width: u32,
        height: u32,
    ) -> Result<Targets, RenderError> {
        let drawing = crate::Drawing::Gpu { limits: &ctx.limits, samples: renderer.samples };
        crate::check_image_size(width, height, drawing)?;
        crate::scoped(&ctx.device, "making the render targets", || Self::make(ctx, renderer, width, height))
    }

    fn make(ctx: &GpuContext, renderer: &Renderer, width: u32, height: u32) -> Targets {
        let texture = |label: &str, format, samples, usage| {
            ctx.device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
                mip_level_count: 1,
                sample_count: samples,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage,
                view_formats: &[],
            })
        };
        use wgpu::TextureUsages as U;
        let s = renderer.samples;
        let f = renderer.format;
        let (colour, resolve) = if s > 1 {
            (
                texture("colour msaa", f, s, U::RENDER_ATTACHMENT),
                Some(texture("colour", f, 1, U::RENDER_ATTACHMENT | U::COPY_SRC)),
            )
        } else {
            (texture("colour", f, 1, U::RENDER_ATTACHMENT | U::COPY_SRC), None)
        };
        Targets {
            width,
            height,
            colour,
            resolve,
            depth: texture("depth", DEPTH_FORMAT, s, U::RENDER_ATTACHMENT),
        }
    }

    /// Records `renderer`'s frame of `parts` into these targets (see [`Renderer::record`],
    /// and its errors).
    pub fn draw(
        &self,
        ctx: &GpuContext,
        renderer: &Renderer,
        encoder: &mut wgpu::CommandEncoder,
        parts: &[Geometry<'_>],
        camera: &Camera,
        options: &RenderOptions,
    ) -> Result<(), RenderError> {
        let view = |t: &wgpu::Texture| t.create_view(&Default::default());
        let colour = view(&self.colour);
        let resolve = self.resolve.as_ref().map(view);
        let depth = view(&self.depth);
        renderer.record(ctx, encoder, &colour, resolve.as_ref(), &depth, parts, camera, options)
    }

    /// Views of the colour attachment, the resolve target (with MSAA) and the depth buffer,
    /// for pipelines other than [`Renderer`]'s that draw into these targets.
    pub fn views(&self) -> (wgpu::TextureView, Option<wgpu::TextureView>, wgpu::TextureView) {
        let view = |t: &wgpu::Texture| t.create_view(&Default::default());
        (view(&self.colour), self.resolve.as_ref().map(view), view(&self.depth))
    }

    /// The single-sample image texture (the resolve target with MSAA).
    pub fn image_texture(&self) -> &wgpu::Texture {
        self.resolve.as_ref().unwrap_or(&self.colour)
    }

    /// Copies the image back to the CPU. A read-back: waits for the queue. Cost: see
    /// [`read_texture`].
    pub fn read(&self, ctx: &GpuContext) -> Result<Image, RenderError> {
        read_texture(ctx, self.image_texture())
    }
}

/// Copies a single-sample 8-bit RGBA or BGRA texture with `COPY_SRC` usage (an image target,
/// or a surface texture configured with it) back into an RGBA [`Image`]. A read-back: waits
/// for the queue. Errors: [`RenderError::Wgpu`] when the device cannot make the read-back
/// buffer or refuses the copy; [`RenderError::Gpu`] for a failed map. Cost: the copy of
/// `4 · width · height` bytes (rows padded to 256 bytes).
pub fn read_texture(ctx: &GpuContext, texture: &wgpu::Texture) -> Result<Image, RenderError> {
    let (width, height) = (texture.width(), texture.height());
    let row = (4 * width).div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
    let size = row as u64 * height as u64;
    let buffer = crate::scoped(&ctx.device, "reading the image back", || {
        let buffer = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("image read-back"),
            size,
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        copy_to(ctx, texture, &buffer, row);
        buffer
    })?;
    let bytes = tessera_gpu::readback::read_bytes(ctx, &buffer, size)?;
    let mut rgba = Vec::with_capacity(4 * (width * height) as usize);
    let bgra =
        matches!(texture.format(), wgpu::TextureFormat::Bgra8Unorm | wgpu::TextureFormat::Bgra8UnormSrgb);
    for y in 0..height as usize {
        let line = &bytes[y * row as usize..][..4 * width as usize];
        if bgra {
            for px in line.chunks_exact(4) {
                rgba.extend_from_slice(&[px[2], px[1], px[0], px[3]]);
            }
        } else {
            rgba.extend_from_slice(line);
        }
    }
    Ok(Image { width, height, rgba })
}

/// Records and submits the copy of `texture` into `buffer` (rows of `row` bytes).
fn copy_to(ctx: &GpuContext, texture: &wgpu::Texture, buffer: &wgpu::Buffer, row: u32) {
    let (width, height) = (texture.width(), texture.height());
    let mut encoder = ctx.device.create_command_encoder(&Default::default());
    encoder.copy_texture_to_buffer(
        wgpu::TexelCopyTextureInfo {
            texture,
            mip_level: 0,
            origin: wgpu::Origin3d::ZERO,
            aspect: wgpu::TextureAspect::All,
        },
        wgpu::TexelCopyBufferInfo {
            buffer,
            layout: wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(row), rows_per_image: None },
        },
        wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
    );
    ctx.queue.submit([encoder.finish()]);
}

/// Draws `parts` (one mesh: see [`Renderer::record`]) from `camera` (its viewport is the image
/// size) into a new image: a renderer, targets, one frame and a read-back. For one-off
/// pictures; a frame loop keeps a [`Renderer`] and [`Targets`]. Every wgpu call is in an
/// error scope: errors are [`RenderError`]s (the size checked first, see [`Targets::new`]),
/// never wgpu's panic. Cost: two shader compilations, the frame, the read-back.
pub fn render(
    ctx: &GpuContext,
    parts: &[Geometry<'_>],
    camera: &Camera,
    options: &RenderOptions,
    samples: u32,
) -> Result<Image, RenderError> {
    let drawing = crate::Drawing::Gpu { limits: &ctx.limits, samples };
    crate::check_image_size(camera.width, camera.height, drawing)?;
    let renderer = Renderer::new(ctx, IMAGE_FORMAT, samples)?;
    let targets = Targets::new(ctx, &renderer, camera.width, camera.height)?;
    crate::scoped(&ctx.device, "drawing the frame", || {
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        let drawn = targets.draw(ctx, &renderer, &mut encoder, parts, camera, options);
        ctx.queue.submit([encoder.finish()]);
        drawn
    })??;
    targets.read(ctx)
}

/// The render pass every picture is drawn in: colour cleared to the background (resolved into
/// `resolve` when multisampled), depth cleared to the far plane and discarded afterwards.
pub(crate) fn begin_scene_pass<'e>(
    encoder: &'e mut wgpu::CommandEncoder,
    label: &str,
    target: &wgpu::TextureView,
    resolve: Option<&wgpu::TextureView>,
    depth: &wgpu::TextureView,
) -> wgpu::RenderPass<'e> {
    let [r, g, b] = shading::BACKGROUND.map(f64::from);
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view: target,
            depth_slice: None,
            resolve_target: resolve,
            ops: wgpu::Operations {
                load: wgpu::LoadOp::Clear(wgpu::Color { r, g, b, a: 1.0 }),
                store: wgpu::StoreOp::Store,
            },
        })],
        depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
            view: depth,
            depth_ops: Some(wgpu::Operations {
                load: wgpu::LoadOp::Clear(1.0),
                store: wgpu::StoreOp::Discard,
            }),
            stencil_ops: None,
        }),
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    })
}

/// The depth test of every scene pipeline (the depth target of [`begin_scene_pass`]).
pub(crate) fn depth_state() -> wgpu::DepthStencilState {
    wgpu::DepthStencilState {
        format: DEPTH_FORMAT,
        depth_write_enabled: Some(true),
        depth_compare: Some(wgpu::CompareFunction::Less),
        stencil: Default::default(),
        bias: Default::default(),
    }
}
