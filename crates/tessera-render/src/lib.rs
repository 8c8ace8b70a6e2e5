//! Pictures of tessera meshes: an offscreen wgpu renderer ([`gpu`]) that draws the GPU
//! engine's buffers or a CPU [`tessera::mesh::Mesh`] with the same pipeline, a CPU fallback
//! rasteriser ([`cpu`]) for machines without any GPU adapter, one shading rule for both
//! ([`shading`]), and PNG output ([`Image::write_png`]).
//!
//! The camera is the library's [`tessera::camera::Camera`]: its
//! [`view_projection`](tessera::camera::Camera::view_projection) is the renderer's, so a
//! picture shows exactly what the screen-space criteria measured.
//!
//! ```no_run
//! use tessera::camera::Camera;
//! use tessera_render::{gpu, RenderOptions};
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! # let (set, mesh): (tessera::surface::SurfaceSet, tessera::mesh::Mesh) = todo!();
//! let (lo, hi) = set.bounds();
//! let camera = Camera::framing(lo, hi, 640, 360);
//! let ctx = tessera_gpu::GpuContext::new()?;
//! let buffers = gpu::MeshBuffers::upload(&ctx, &mesh, &[]);
//! let image = gpu::render(&ctx, &buffers.geometry(), &camera, &RenderOptions::default(), 4)?;
//! image.write_png(std::path::Path::new("mesh.png"))?;
//! # Ok(())
//! # }
//! ```

#![warn(missing_docs)]

pub mod cpu;
pub mod gpu;
pub mod instanced;
pub mod overlay;
pub mod shading;

pub use gpu::{Geometry, MeshBuffers, RenderOptions, Renderer, Targets};
pub use shading::ColorMode;

use std::path::Path;

/// What rendering can fail at.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// A request the renderer cannot honour (size, sample count).
    #[error("{0}")]
    Invalid(String),
    /// The GPU: no adapter, a lost device, a failed read-back.
    #[error(transparent)]
    Gpu(#[from] tessera_gpu::GpuError),
    /// Writing the PNG file.
    #[error("{path}: {reason}")]
    Write {
        /// The file.
        path: String,
        /// The I/O or encoder message.
        reason: String,
    },
}

/// An 8-bit RGBA image, rows top to bottom.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Image {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `4 · width · height` bytes.
    pub rgba: Vec<u8>,
}

impl Image {
    /// Pixels that are not the background ([`shading::BACKGROUND`]): the covered ones (no
    /// surface pixel is the background colour). Cost: O(pixels).
    pub fn covered_pixels(&self) -> usize {
        let bg = shading::BACKGROUND.map(|v| (v * 255.0).round() as u8);
        self.rgba.chunks_exact(4).filter(|p| p[..3] != bg).count()
    }

    /// Pixels whose colour differs from `other`'s by more than `tolerance` in some channel
    /// (images of the same size; pixels past the smaller one count as differing).
    pub fn differing_pixels(&self, other: &Image, tolerance: u8) -> usize {
        let n = self.rgba.len().max(other.rgba.len()) / 4;
        let same = self
            .rgba
            .chunks_exact(4)
            .zip(other.rgba.chunks_exact(4))
            .filter(|(a, b)| a.iter().zip(b.iter()).all(|(x, y)| x.abs_diff(*y) <= tolerance))
            .count();
        n - same
    }

    /// Writes the image as an 8-bit RGB PNG (the background is opaque). Errors:
    /// [`RenderError::Write`]. Cost: deflate of the pixels.
    pub fn write_png(&self, path: &Path) -> Result<(), RenderError> {
        let fail = |e: &dyn std::fmt::Display| RenderError::Write {
            path: path.display().to_string(),
            reason: e.to_string(),
        };
        let file = std::fs::File::create(path).map_err(|e| fail(&e))?;
        let mut encoder = png::Encoder::new(std::io::BufWriter::new(file), self.width, self.height);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        let mut writer = encoder.write_header().map_err(|e| fail(&e))?;
        let rgb: Vec<u8> = self.rgba.chunks_exact(4).flat_map(|p| [p[0], p[1], p[2]]).collect();
        writer.write_image_data(&rgb).map_err(|e| fail(&e))?;
        writer.finish().map_err(|e| fail(&e))
    }

    /// Reads an 8-bit RGB or RGBA PNG (as [`Image::write_png`] writes). For tests and tools.
    pub fn read_png(path: &Path) -> Result<Image, RenderError> {
        let fail = |e: &dyn std::fmt::Display| RenderError::Write {
            path: path.display().to_string(),
            reason: e.to_string(),
        };
        let file = std::fs::File::open(path).map_err(|e| fail(&e))?;
        let mut reader =
            png::Decoder::new(std::io::BufReader::new(file)).read_info().map_err(|e| fail(&e))?;
        let mut buf = vec![0; reader.output_buffer_size().unwrap_or(0)];
        let info = reader.next_frame(&mut buf).map_err(|e| fail(&e))?;
        let data = &buf[..info.buffer_size()];
        let rgba = match (info.color_type, info.bit_depth) {
            (png::ColorType::Rgb, png::BitDepth::Eight) => {
                data.chunks_exact(3).flat_map(|p| [p[0], p[1], p[2], 255]).collect()
            }
            (png::ColorType::Rgba, png::BitDepth::Eight) => data.to_vec(),
            other => {
                return Err(fail(&format!("unsupported PNG layout {other:?} (8-bit RGB or RGBA expected)")))
            }
        };
        Ok(Image { width: info.width, height: info.height, rgba })
    }
}

/// Each patch's level in [0, 1] for [`ColorMode::Level`]: `log2` of its interior factor (the
/// larger of the plan's two) over `log2(max_factor)`. Cost: O(P).
pub fn patch_levels(plan: &tessera::criterion::Plan, max_factor: u32) -> Vec<f32> {
    let top = (max_factor.max(2) as f32).log2();
    plan.interior.iter().map(|&[a, b]| (a.max(b).max(1) as f32).log2() / top).collect()
}

/// The patch of every triangle from the GPU engine's triangle offsets (P + 1 entries,
/// [`tessera_gpu::GpuTessellator::read_layout`]'s third array). Cost: O(T).
pub fn triangle_patches(triangle_offsets: &[u32]) -> Vec<u32> {
    let mut out = Vec::with_capacity(triangle_offsets.last().copied().unwrap_or(0) as usize);
    for (p, w) in triangle_offsets.windows(2).enumerate() {
        out.extend(std::iter::repeat_n(p as u32, w[1].saturating_sub(w[0]) as usize));
    }
    out
}
