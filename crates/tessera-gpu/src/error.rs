//! The GPU engine's errors.

use crate::context::SOFTWARE_DRIVER_PACKAGES;

/// Everything the GPU engine can refuse or fail at.
#[derive(Debug, thiserror::Error)]
pub enum GpuError {
    /// No wgpu adapter exists on this machine.
    #[error(
        "no GPU adapter found ({reason}); on a machine without a GPU install the software Vulkan \
         driver: `{SOFTWARE_DRIVER_PACKAGES}` (Debian/Ubuntu)"
    )]
    NoAdapter {
        /// wgpu's own message.
        reason: String,
    },
    /// The adapter refused to create a device, or the device was lost.
    #[error("GPU device error: {reason}")]
    Device {
        /// wgpu's own message.
        reason: String,
    },
    /// The worst-case output of a frame does not fit what the device can bind or allocate:
    /// refused before anything of that size is made, never truncated.
    #[error(
        "GPU output too large: up to {vertices} vertices and {triangles} triangles need a \
         {bytes}-byte buffer, over the device's limit of {limit} bytes"
    )]
    OutputTooLarge {
        /// Worst-case vertices.
        vertices: u64,
        /// Worst-case triangles.
        triangles: u64,
        /// Bytes of the largest buffer needed.
        bytes: u64,
        /// The device limit it exceeds (`min(max_buffer_size, max_storage_buffer_binding_size)`).
        limit: u64,
    },
    /// The GPU engine does not do this (yet): the scheme, the surface kind or the plan kind.
    #[error("the GPU engine does not support {what}")]
    Unsupported {
        /// What was asked.
        what: String,
    },
    /// The CPU library refused the input (a plan for another set, an out-of-range factor).
    #[error(transparent)]
    Tessera(#[from] tessera::Error),
}

/// The GPU engine's result type.
pub type Result<T> = std::result::Result<T, GpuError>;
