//! Embedding tessera in a wgpu application: what a wgpu (or bevy render-graph) user copies.
//!
//! `cargo run --release -p tessera-render --example gpu_frames -- [MODEL.patches] [FRAMES]
//! [OUT_DIR]` (defaults: `$TESSERA_DATA/patches/teapot.patches`, 8 frames, `frames/`).
//!
//! The model and its view-independent bounds are uploaded to the GPU engine once, with the
//! criterion: a 1-pixel screen-space error, the transition scheme (CudaTess). Every frame the
//! CPU only hands the engine the camera orbiting the model (a 112-byte upload); the GPU culls
//! the patches, computes every edge's factor from the camera, checks the patterns' error
//! bounds, counts, scans and writes vertices and indices into its own buffers, and the
//! application's own render pipeline (`embed.wgsl`) binds those buffers as vertex and index
//! buffers and draws them with `draw_indexed_indirect` from the engine's indirect buffer.
//! Tessellation and draw are one command buffer; nothing is read back except the finished
//! picture, written as `OUT_DIR/frame_NNN.png` (a headless app's stand-in for presenting it),
//! and the triangle count printed beside it.

use std::path::{Path, PathBuf};
use tessera::camera::Camera;
use tessera::scheme::{Criterion, Prepared, Scheme};
use tessera_gpu::tessellator::ScreenCriterion;
use tessera_gpu::{GpuContext, GpuTessellator, VERTEX_LAYOUT};
use wgpu::util::DeviceExt;

const WIDTH: u32 = 640;
const HEIGHT: u32 = 360;
const COLOR: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;
const DEPTH: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let model = args.get(1).map(PathBuf::from).unwrap_or_else(|| {
        let data = std::env::var("TESSERA_DATA").unwrap_or_else(|_| "../shared/data".into());
        Path::new(&data).join("patches/teapot.patches")
    });
    let frames: u32 = args.get(2).map_or(Ok(8), |s| s.parse())?;
    let out_dir = PathBuf::from(args.get(3).map_or("frames", String::as_str));
    std::fs::create_dir_all(&out_dir)?;

    // Once: the model, the GPU engine with the model uploaded, the view-independent bounds
    // and the criterion (the output sized for its worst case, every factor at the cap).
    let set = tessera::io::load(&model, tessera::io::LoadOptions::default())?;
    let ctx = GpuContext::new()?; // a typed error naming the driver packages when there is no adapter
    let mut engine = GpuTessellator::new(&ctx, &set)?;
    let prepared = Prepared::new(&set, true);
    let (lo, hi) = set.bounds();
    let framing = Camera::framing(lo, hi, WIDTH, HEIGHT);
    let criterion = ScreenCriterion::new(Scheme::Transition, Criterion::PixelError(1.0), 64);
    engine.prepare_screen(&ctx, &set, &prepared, &framing, criterion)?;

    // Once: the application's pipeline, reading the engine's vertex layout.
    let device = &ctx.device;
    let shader = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("embed.wgsl"),
        source: wgpu::ShaderSource::Wgsl(include_str!("embed.wgsl").into()),
    });
    let view_buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("view"),
        size: 80,
        usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("draw tessera output"),
        layout: None,
        vertex: wgpu::VertexState {
            module: &shader,
            entry_point: Some("vs"),
            compilation_options: Default::default(),
            buffers: &[Some(VERTEX_LAYOUT)],
        },
        primitive: wgpu::PrimitiveState::default(),
        depth_stencil: Some(wgpu::DepthStencilState {
            format: DEPTH,
            depth_write_enabled: Some(true),
            depth_compare: Some(wgpu::CompareFunction::Less),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module: &shader,
            entry_point: Some("fs"),
            compilation_options: Default::default(),
            targets: &[Some(COLOR.into())],
        }),
        multiview_mask: None,
        cache: None,
    });
    let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("view"),
        layout: &pipeline.get_bind_group_layout(0),
        entries: &[wgpu::BindGroupEntry { binding: 0, resource: view_buffer.as_entire_binding() }],
    });
    let texture = |format, usage| {
        device.create_texture(&wgpu::TextureDescriptor {
            label: None,
            size: wgpu::Extent3d { width: WIDTH, height: HEIGHT, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage,
            view_formats: &[],
        })
    };
    let colour = texture(COLOR, wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC);
    let depth = texture(DEPTH, wgpu::TextureUsages::RENDER_ATTACHMENT);
    let (colour_view, depth_view) =
        (colour.create_view(&Default::default()), depth.create_view(&Default::default()));
    let row = (4 * WIDTH).div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
    let picture = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("picture"),
        contents: &vec![0; (row * HEIGHT) as usize],
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC,
    });

    for frame in 0..frames {
        // The moving camera: an orbit about the model's vertical axis, closing in.
        let angle = frame as f64 / frames.max(1) as f64 * std::f64::consts::TAU;
        let offset = framing.eye - framing.target;
        let rotated = glam::DQuat::from_axis_angle(framing.up, angle) * offset;
        let eye = framing.target + rotated * (1.0 - 0.3 * frame as f64 / frames as f64);
        // The near plane follows the eye, so that the closer views keep the whole model.
        let (distance, radius) = (eye.distance(framing.target), lo.distance(hi) * 0.5);
        let near = (distance - radius).max(distance * 1e-3);
        let camera = Camera { eye, near, ..framing };

        // Per frame, CPU: only the camera, for the engine and for the application's draw ...
        engine.set_cull_camera(&ctx, Some(&camera));
        let (r, u, f) = camera.basis();
        let light = (-f + 0.45 * u - 0.35 * r).normalize().as_vec3();
        let mut view = camera.view_projection().as_mat4().to_cols_array().to_vec();
        view.extend([light.x, light.y, light.z, 0.0]);
        ctx.queue.write_buffer(&view_buffer, 0, bytemuck::cast_slice(&view));

        // ... and one command buffer: the engine's compute passes, then the draw.
        let mut encoder = device.create_command_encoder(&Default::default());
        engine.record(&mut encoder);
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("draw"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &colour_view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::WHITE),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &depth_view,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(1.0),
                        store: wgpu::StoreOp::Discard,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            let (Some(vertices), Some(indices)) = (engine.vertex_buffer(), engine.index_buffer()) else {
                unreachable!("prepare_screen made the output buffers")
            };
            pass.set_pipeline(&pipeline);
            pass.set_bind_group(0, &bind, &[]);
            pass.set_vertex_buffer(0, vertices.slice(..));
            pass.set_index_buffer(indices.slice(..), wgpu::IndexFormat::Uint32);
            pass.draw_indexed_indirect(engine.indirect_buffer(), 0);
        }
        encoder.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo {
                texture: &colour,
                mip_level: 0,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            wgpu::TexelCopyBufferInfo {
                buffer: &picture,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(row),
                    rows_per_image: None,
                },
            },
            wgpu::Extent3d { width: WIDTH, height: HEIGHT, depth_or_array_layers: 1 },
        );
        ctx.queue.submit([encoder.finish()]);

        // A headless app's "present": the picture read back and written as PNG.
        let bytes = tessera_gpu::readback::read_bytes(&ctx, &picture, (row * HEIGHT) as u64)?;
        let rgba =
            bytes.chunks_exact(row as usize).flat_map(|line| &line[..4 * WIDTH as usize]).copied().collect();
        let path = out_dir.join(format!("frame_{frame:03}.png"));
        tessera_render::Image { width: WIDTH, height: HEIGHT, rgba }.write_png(&path)?;
        let (_, _, triangles) = engine.read_status(&ctx)?; // statistics only, for this printout
        println!("{}: {triangles} triangles", path.display());
    }
    Ok(())
}
