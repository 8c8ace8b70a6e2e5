//! The tessera GPU engine: the CPU engine's count → scan → write pipeline (paper 003,
//! CudaTess) as wgpu compute passes, reading the **same plan and layout rule** as the CPU.
//!
//! What the GPU reads is the CPU library's own data, uploaded as it is: the
//! [`tessera::criterion::Plan`]'s arrays (segments, interior factors, visibility) byte for
//! byte, and the topology's edge-use, patch-edge and corner-entry arrays packed into u32
//! rows ([`upload`]). Where a shader computes something the CPU also computes (counts per
//! edge and patch, the offsets of [`tessera::engine::Layout`], edge parameters), its comment
//! names the Rust function it is the GPU form of, and the tests compare the two on every
//! model.
//!
//! Start with [`GpuContext::new`] (an adapter, with the adapter's own limits), then
//! [`GpuTessellator`]. Nothing in the frame path reads back from the GPU; [`readback`] is
//! for tests and the command-line tool.
//!
//! ```no_run
//! use tessera::criterion::Plan;
//! use tessera::pattern::uniform::Uniform;
//! use tessera_gpu::{GpuContext, GpuTessellator};
//!
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! let file = tessera::io::patches::read_patches(std::path::Path::new("teapot.patches"))?;
//! let set = tessera::surface::SurfaceSet::from_patch_file(&file, Default::default());
//! let ctx = GpuContext::new()?; // fails with the packages to install when there is no adapter
//! let mut gpu = GpuTessellator::new(&ctx, &set)?; // uploads the set once
//! gpu.prepare(&ctx, &set, &Plan::uniform(&set, 16)?, &Uniform)?; // sizes the output
//! let mut encoder = ctx.device.create_command_encoder(&Default::default());
//! gpu.record(&mut encoder); // the frame: compute passes only, nothing read back
//! // … a render pass binds gpu.vertex_buffer() (tessera_gpu::VERTEX_LAYOUT) and
//! // gpu.index_buffer() (u32) and calls draw_indexed_indirect(gpu.indirect_buffer(), 0).
//! ctx.queue.submit([encoder.finish()]);
//! let mesh = gpu.read_mesh(&ctx, &set)?; // read-back, for tests and tools only
//! assert!(mesh.triangle_count() > 0);
//! # Ok(())
//! # }
//! ```

#![warn(missing_docs)]

pub mod context;
/// The CPU↔GPU contract test (the uniform and state structs against their WGSL).
#[cfg(test)]
mod contract;
pub mod error;
pub mod readback;
pub mod scan;
pub mod shader;
pub mod stencils;
pub mod tessellator;
pub mod upload;

pub use context::{GpuContext, SOFTWARE_DRIVER_PACKAGES};
pub use error::{GpuError, Result};
pub use stencils::GpuStencils;
pub use tessellator::{GpuTessellator, ScreenReport, VERTEX_LAYOUT};
