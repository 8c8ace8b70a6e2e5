//! A line or two of text over a frame (the viewer's statistics): a tiny 5×7 bitmap font
//! looked up in a fragment shader (`shaders/overlay.wgsl`), so no texture, sampler or font
//! crate is needed. Upper-case ASCII, digits and common punctuation; lower case is drawn as
//! upper case and anything else as a space.

use tessera_gpu::GpuContext;

/// Glyphs for ASCII 32 (space) to 95 (`_`), five columns each, bit 0 the top row (the
/// classic 5×7 LCD font).
#[rustfmt::skip]
pub const FONT: [[u8; 5]; 64] = [
    [0x00, 0x00, 0x00, 0x00, 0x00], [0x00, 0x00, 0x5F, 0x00, 0x00], [0x00, 0x07, 0x00, 0x07, 0x00],
    [0x14, 0x7F, 0x14, 0x7F, 0x14], [0x24, 0x2A, 0x7F, 0x2A, 0x12], [0x23, 0x13, 0x08, 0x64, 0x62],
    [0x36, 0x49, 0x56, 0x20, 0x50], [0x00, 0x08, 0x07, 0x03, 0x00], [0x00, 0x1C, 0x22, 0x41, 0x00],
    [0x00, 0x41, 0x22, 0x1C, 0x00], [0x2A, 0x1C, 0x7F, 0x1C, 0x2A], [0x08, 0x08, 0x3E, 0x08, 0x08],
    [0x00, 0x80, 0x70, 0x30, 0x00], [0x08, 0x08, 0x08, 0x08, 0x08], [0x00, 0x00, 0x60, 0x60, 0x00],
    [0x20, 0x10, 0x08, 0x04, 0x02], [0x3E, 0x51, 0x49, 0x45, 0x3E], [0x00, 0x42, 0x7F, 0x40, 0x00],
    [0x72, 0x49, 0x49, 0x49, 0x46], [0x21, 0x41, 0x49, 0x4D, 0x33], [0x18, 0x14, 0x12, 0x7F, 0x10],
    [0x27, 0x45, 0x45, 0x45, 0x39], [0x3C, 0x4A, 0x49, 0x49, 0x31], [0x41, 0x21, 0x11, 0x09, 0x07],
    [0x36, 0x49, 0x49, 0x49, 0x36], [0x46, 0x49, 0x49, 0x29, 0x1E], [0x00, 0x00, 0x14, 0x00, 0x00],
    [0x00, 0x40, 0x34, 0x00, 0x00], [0x00, 0x08, 0x14, 0x22, 0x41], [0x14, 0x14, 0x14, 0x14, 0x14],
    [0x00, 0x41, 0x22, 0x14, 0x08], [0x02, 0x01, 0x59, 0x09, 0x06], [0x3E, 0x41, 0x5D, 0x59, 0x4E],
    [0x7C, 0x12, 0x11, 0x12, 0x7C], [0x7F, 0x49, 0x49, 0x49, 0x36], [0x3E, 0x41, 0x41, 0x41, 0x22],
    [0x7F, 0x41, 0x41, 0x41, 0x3E], [0x7F, 0x49, 0x49, 0x49, 0x41], [0x7F, 0x09, 0x09, 0x09, 0x01],
    [0x3E, 0x41, 0x41, 0x51, 0x73], [0x7F, 0x08, 0x08, 0x08, 0x7F], [0x00, 0x41, 0x7F, 0x41, 0x00],
    [0x20, 0x40, 0x41, 0x3F, 0x01], [0x7F, 0x08, 0x14, 0x22, 0x41], [0x7F, 0x40, 0x40, 0x40, 0x40],
    [0x7F, 0x02, 0x1C, 0x02, 0x7F], [0x7F, 0x04, 0x08, 0x10, 0x7F], [0x3E, 0x41, 0x41, 0x41, 0x3E],
    [0x7F, 0x09, 0x09, 0x09, 0x06], [0x3E, 0x41, 0x51, 0x21, 0x5E], [0x7F, 0x09, 0x19, 0x29, 0x46],
    [0x26, 0x49, 0x49, 0x49, 0x32], [0x03, 0x01, 0x7F, 0x01, 0x03], [0x3F, 0x40, 0x40, 0x40, 0x3F],
    [0x1F, 0x20, 0x40, 0x20, 0x1F], [0x3F, 0x40, 0x38, 0x40, 0x3F], [0x63, 0x14, 0x08, 0x14, 0x63],
    [0x03, 0x04, 0x78, 0x04, 0x03], [0x61, 0x59, 0x49, 0x4D, 0x43], [0x00, 0x7F, 0x41, 0x41, 0x00],
    [0x02, 0x04, 0x08, 0x10, 0x20], [0x00, 0x41, 0x41, 0x7F, 0x00], [0x04, 0x02, 0x01, 0x02, 0x04],
    [0x40, 0x40, 0x40, 0x40, 0x40],
];

/// Most characters per line and lines drawn.
pub const MAX_COLUMNS: usize = 160;
/// Most lines.
pub const MAX_LINES: usize = 4;

/// The glyph index of a character (see [`FONT`]).
pub fn glyph(c: char) -> u32 {
    let c = c.to_ascii_uppercase();
    if (' '..='_').contains(&c) {
        c as u32 - 32
    } else {
        0
    }
}

/// The text pipeline and its buffers, for one colour format (single-sampled targets).
#[derive(Debug)]
pub struct Overlay {
    pipeline: wgpu::RenderPipeline,
    uniform: wgpu::Buffer,
    chars: wgpu::Buffer,
    bind: wgpu::BindGroup,
}

impl Overlay {
    /// Compiles the pipeline and uploads the font. Cost: one small shader compilation.
    pub fn new(ctx: &GpuContext, format: wgpu::TextureFormat) -> Overlay {
        use wgpu::util::DeviceExt;
        let device = &ctx.device;
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("overlay.wgsl"),
            source: wgpu::ShaderSource::Wgsl(include_str!("../shaders/overlay.wgsl").into()),
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("overlay"),
            layout: None,
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: Default::default(),
            depth_stencil: None,
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs"),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState {
                    format,
                    blend: Some(wgpu::BlendState::ALPHA_BLENDING),
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            multiview_mask: None,
            cache: None,
        });
        let font: Vec<u32> = FONT.iter().flatten().map(|&c| c as u32).collect();
        let font = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("font"),
            contents: bytemuck::cast_slice(&font),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let uniform = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("overlay text"),
            size: 32,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let chars = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("overlay chars"),
            size: 4 * (MAX_COLUMNS * MAX_LINES) as u64,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("overlay"),
            layout: &pipeline.get_bind_group_layout(0),
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: uniform.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: chars.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 2, resource: font.as_entire_binding() },
            ],
        });
        Overlay { pipeline, uniform, chars, bind }
    }

    /// Records a pass that draws `lines` (at most [`MAX_LINES`] of [`MAX_COLUMNS`]
    /// characters; longer ones are cut) at pixel `(x, y)` of `target`, glyph pixels `scale`
    /// screen pixels wide, over what is there. Cost: a few hundred bytes uploaded.
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
        lines: &[&str],
        x: u32,
        y: u32,
        scale: u32,
    ) {
        let lines = &lines[..lines.len().min(MAX_LINES)];
        let columns = lines.iter().map(|l| l.chars().count()).max().unwrap_or(0).min(MAX_COLUMNS);
        let mut codes = vec![0u32; columns * lines.len()];
        for (r, line) in lines.iter().enumerate() {
            for (c, ch) in line.chars().take(columns).enumerate() {
                codes[r * columns + c] = glyph(ch);
            }
        }
        if !codes.is_empty() {
            ctx.queue.write_buffer(&self.chars, 0, bytemuck::cast_slice(&codes));
        }
        let layout = [x, y, scale, columns as u32, lines.len() as u32, 0, 0, 0];
        ctx.queue.write_buffer(&self.uniform, 0, bytemuck::cast_slice(&layout));
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("overlay"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: target,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &self.bind, &[]);
        pass.draw(0..3, 0..1);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn glyphs_cover_the_statistics_line() {
        assert_eq!(glyph(' '), 0);
        assert_eq!(glyph('a'), glyph('A'));
        assert_eq!(FONT[glyph('0') as usize], [0x3E, 0x51, 0x49, 0x45, 0x3E]);
        assert_eq!(glyph('~'), 0);
        assert_eq!(FONT.len(), ('_' as usize) - 31);
    }
}
