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
//! let buffers = gpu::MeshBuffers::upload(&ctx, &mesh, &[])?;
//! let image = gpu::render(&ctx, &buffers.geometries(), &camera, &RenderOptions::default(), 4)?;
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

use std::future::Future;
use std::path::Path;
use std::task::{Context, Poll, RawWaker, RawWakerVTable, Waker};

/// What rendering can fail at.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// A request the renderer cannot honour (size, sample count).
    #[error("{0}")]
    Invalid(String),
    /// An image size refused before anything of that size is allocated ([`check_image_size`]):
    /// a side past the adapter's texture limit, or targets past a memory cap.
    #[error("image size {width}x{height}: {reason}")]
    ImageTooLarge {
        /// Requested width in pixels.
        width: u32,
        /// Requested height in pixels.
        height: u32,
        /// Which limit it exceeds, with the figures.
        reason: String,
    },
    /// wgpu reported an error inside one of the renderer's error scopes ([`scoped`]). Errors
    /// outside any scope are recorded by the [`tessera_gpu::GpuContext`] and come back as
    /// [`RenderError::Gpu`] from its `wait` or `check_errors`.
    #[error("wgpu {kind} while {what}: {message}")]
    Wgpu {
        /// What the renderer was doing.
        what: String,
        /// Which kind of error.
        kind: WgpuErrorKind,
        /// wgpu's own description.
        message: String,
    },
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
    /// Reading a PNG file ([`Image::read_png`]).
    #[error("{path}: {reason}")]
    Read {
        /// The file.
        path: String,
        /// The I/O or decoder message.
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
        let fail = |e: &dyn std::fmt::Display| RenderError::Read {
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

/// The kind of a wgpu error ([`RenderError::Wgpu`]), as wgpu's error scopes filter them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WgpuErrorKind {
    /// The device could not allocate memory.
    OutOfMemory,
    /// A call broke wgpu's rules (a limit, a usage).
    Validation,
    /// The driver failed in some other way.
    Internal,
}

impl std::fmt::Display for WgpuErrorKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            WgpuErrorKind::OutOfMemory => "out-of-memory error",
            WgpuErrorKind::Validation => "validation error",
            WgpuErrorKind::Internal => "internal error",
        })
    }
}

impl RenderError {
    /// The typed form of a wgpu error met while doing `what`.
    pub fn from_wgpu(what: &str, error: &wgpu::Error) -> RenderError {
        let (kind, message) = match error {
            wgpu::Error::OutOfMemory { .. } => {
                (WgpuErrorKind::OutOfMemory, "the device has no memory left for it".to_string())
            }
            wgpu::Error::Validation { description, .. } => (WgpuErrorKind::Validation, description.clone()),
            wgpu::Error::Internal { description, .. } => (WgpuErrorKind::Internal, description.clone()),
        };
        RenderError::Wgpu { what: what.to_string(), kind, message: message.trim_end().to_string() }
    }
}

/// Polls a future that is ready at once. wgpu's native backend resolves error-scope futures
/// immediately, so no executor is needed (nor a dependency on one).
fn ready_now<F: Future>(future: F) -> Option<F::Output> {
    fn raw() -> RawWaker {
        fn clone(_: *const ()) -> RawWaker {
            raw()
        }
        fn noop(_: *const ()) {}
        static VTABLE: RawWakerVTable = RawWakerVTable::new(clone, noop, noop, noop);
        RawWaker::new(std::ptr::null(), &VTABLE)
    }
    // SAFETY: every function of the vtable ignores its (null) data pointer.
    let waker = unsafe { Waker::from_raw(raw()) };
    let mut cx = Context::from_waker(&waker);
    let mut future = std::pin::pin!(future);
    match future.as_mut().poll(&mut cx) {
        Poll::Ready(v) => Some(v),
        Poll::Pending => None,
    }
}

/// Runs `f` inside error scopes for out-of-memory, validation and internal errors on
/// `device`, so a failing wgpu call becomes [`RenderError::Wgpu`] (naming `what`) instead of
/// wgpu's panic. Scopes are per thread: `f` must make its wgpu calls on this one. Errors that
/// surface only when the GPU runs the work (none on wgpu's native validation) are not seen.
pub fn scoped<T>(device: &wgpu::Device, what: &str, f: impl FnOnce() -> T) -> Result<T, RenderError> {
    let oom = device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
    let validation = device.push_error_scope(wgpu::ErrorFilter::Validation);
    let internal = device.push_error_scope(wgpu::ErrorFilter::Internal);
    let out = f();
    // Popped innermost first, as wgpu requires.
    let errors = [internal.pop(), validation.pop(), oom.pop()].map(|f| ready_now(f).flatten());
    match errors.iter().flatten().next() {
        Some(e) => Err(RenderError::from_wgpu(what, e)),
        None => Ok(out),
    }
}

/// The most memory the targets of one picture or window may take together (colour,
/// multisampled colour, depth, the presented or read-back image): 4 GiB. wgpu does not report
/// how much the device has; past this a software adapter would take most of a machine's
/// memory, and a hardware one fails with out-of-memory.
pub const MAX_TARGET_BYTES: u64 = 4 << 30;

/// The most one target texture or read-back buffer may take: 2 GiB, the
/// `maxMemoryAllocationSize` of common Vulkan drivers (lavapipe's among them), which wgpu does
/// not report either: past it creation fails with out-of-memory even where the total fits.
pub const MAX_ALLOCATION_BYTES: u64 = 1 << 31;

/// What the targets of one image size take, from [`check_image_size`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TargetBytes {
    /// All of them together.
    pub total: u64,
    /// The largest single one.
    pub largest: u64,
}

/// Swap-chain images a window's surface may hold at once, counted by [`check_image_size`].
pub const SURFACE_IMAGES: u64 = 3;

/// How an image of some size is drawn, for [`check_image_size`].
#[derive(Debug, Clone, Copy)]
pub enum Drawing<'a> {
    /// An offscreen picture by the wgpu renderer ([`gpu::Targets`]) on a device with
    /// `limits`, `samples` samples per pixel (colour and depth multisampled, resolved into a
    /// single-sample image), read back through a buffer.
    Gpu {
        /// The device's limits ([`tessera_gpu::GpuContext::limits`]).
        limits: &'a wgpu::Limits,
        /// Samples per pixel.
        samples: u32,
    },
    /// A window drawn by the wgpu renderer: multisampled colour and depth resolved into the
    /// surface's images ([`SURFACE_IMAGES`]), and with `screenshot` one read-back.
    Window {
        /// The device's limits.
        limits: &'a wgpu::Limits,
        /// Samples per pixel.
        samples: u32,
        /// Whether a frame is read back.
        screenshot: bool,
    },
    /// By the CPU rasteriser ([`cpu::render`]): depth, colour and the 8-bit image.
    Cpu,
}

/// Checks that an image of `width × height` can be drawn as `drawing` says, before anything of
/// that size is allocated: each side from 1 to the adapter's `max_texture_dimension_2d` (the
/// CPU rasteriser: to [`cpu::MAX_SIDE`]), each target within [`MAX_ALLOCATION_BYTES`] (and the read-back
/// buffer within `max_buffer_size`), all of them within [`MAX_TARGET_BYTES`]. `tessera
/// render` and `tessera view` both call it, so they accept and refuse the same sizes.
/// Errors: [`RenderError::ImageTooLarge`] naming the limit. Cost: O(1).
pub fn check_image_size(width: u32, height: u32, drawing: Drawing<'_>) -> Result<TargetBytes, RenderError> {
    let refuse = |reason: String| RenderError::ImageTooLarge { width, height, reason };
    let (max_side, what) = match drawing {
        Drawing::Gpu { limits, .. } | Drawing::Window { limits, .. } => {
            (limits.max_texture_dimension_2d, "the adapter's max_texture_dimension_2d")
        }
        Drawing::Cpu => (cpu::MAX_SIDE, "the CPU rasteriser's limit"),
    };
    if width == 0 || height == 0 || width > max_side || height > max_side {
        return Err(refuse(format!("each side must be 1 to {max_side} pixels ({what})")));
    }
    let pixels = width as u64 * height as u64;
    // (what, bytes of one, how many).
    let mut parts: Vec<(&str, u64, u64)> = Vec::new();
    let (limits, samples, read_back) = match drawing {
        Drawing::Gpu { limits, samples } => (Some(limits), samples, true),
        Drawing::Window { limits, samples, screenshot } => (Some(limits), samples, screenshot),
        Drawing::Cpu => (None, 1, false),
    };
    match limits {
        Some(limits) => {
            // IMAGE_FORMAT, a surface's 8-bit formats and DEPTH_FORMAT: 4 bytes a sample.
            let samples = samples.max(1) as u64;
            if samples > 1 {
                parts.push(("the multisampled colour target", 4 * samples * pixels, 1));
            }
            parts.push(("the depth target", 4 * samples * pixels, 1));
            let images = if matches!(drawing, Drawing::Window { .. }) { SURFACE_IMAGES } else { 1 };
            parts.push(("the image", 4 * pixels, images));
            if read_back {
                let row = (4 * width as u64).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT as u64);
                let readback = row * height as u64;
                if readback > limits.max_buffer_size {
                    return Err(refuse(format!(
                        "its read-back buffer needs {} bytes, over the adapter's max_buffer_size of {}",
                        readback, limits.max_buffer_size
                    )));
                }
                parts.push(("the read-back buffer", readback, 1));
            }
        }
        None => {
            // Depth (f32) and colour (3 × f32) per pixel, then the RGBA image.
            parts.push(("the depth buffer", 4 * pixels, 1));
            parts.push(("the colour buffer", 12 * pixels, 1));
            parts.push(("the image", 4 * pixels, 1));
        }
    }
    let samples_note = if samples > 1 { format!(" at {samples} samples per pixel") } else { String::new() };
    // The first of equal ones: the multisampled colour before the depth target.
    let &(name, largest, _) = parts.iter().rev().max_by_key(|p| p.1).expect("at least one target");
    if largest > MAX_ALLOCATION_BYTES {
        return Err(refuse(format!(
            "{name}{samples_note} needs {largest} bytes, over the {MAX_ALLOCATION_BYTES}-byte cap on one \
             allocation (MAX_ALLOCATION_BYTES); use a smaller size{}",
            if samples_note.is_empty() { "" } else { " or fewer samples per pixel" }
        )));
    }
    let total: u64 = parts.iter().map(|p| p.1 * p.2).sum();
    if total > MAX_TARGET_BYTES {
        return Err(refuse(format!(
            "its targets{samples_note} need {total} bytes, over the {MAX_TARGET_BYTES}-byte cap on \
             render targets (MAX_TARGET_BYTES); use a smaller size{}",
            if samples_note.is_empty() { "" } else { " or fewer samples per pixel" }
        )));
    }
    Ok(TargetBytes { total, largest })
}
