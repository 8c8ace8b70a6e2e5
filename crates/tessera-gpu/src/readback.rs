//! Reading GPU buffers back: for tests, statistics on request and the command-line tool,
//! never for the frame path (nothing in [`crate::GpuTessellator::record`] calls this module;
//! it is the crate's only user of `map_async`).

use crate::context::GpuContext;
use crate::error::{GpuError, Result};

/// Copies the first `bytes` bytes of `buffer` (which needs `COPY_SRC` usage) into a fresh
/// staging buffer, waits for the queue and returns them. `bytes` is rounded up to a multiple
/// of 4 for the copy and truncated back. Cost: one submission, a full queue wait and a copy
/// of `bytes`.
pub fn read_bytes(ctx: &GpuContext, buffer: &wgpu::Buffer, bytes: u64) -> Result<Vec<u8>> {
    if bytes == 0 {
        return Ok(Vec::new());
    }
    let size = bytes.div_ceil(4) * 4;
    let staging = ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("read-back staging"),
        size,
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let mut encoder = ctx.device.create_command_encoder(&Default::default());
    encoder.copy_buffer_to_buffer(buffer, 0, &staging, 0, size);
    ctx.queue.submit([encoder.finish()]);
    let (tx, rx) = std::sync::mpsc::channel();
    staging.map_async(wgpu::MapMode::Read, .., move |r| {
        let _ = tx.send(r);
    });
    ctx.wait()?;
    rx.recv()
        .map_err(|e| GpuError::Device { reason: format!("read-back callback lost: {e}") })?
        .map_err(|e| GpuError::Device { reason: format!("read-back map failed: {e}") })?;
    let view = staging.get_mapped_range(..).map_err(|e| GpuError::Device { reason: format!("{e:?}") })?;
    let mut out = view.to_vec();
    drop(view);
    staging.unmap();
    out.truncate(bytes as usize);
    Ok(out)
}

/// The first `count` elements of `buffer` as `T`. Cost: as [`read_bytes`].
pub fn read<T: bytemuck::Pod>(ctx: &GpuContext, buffer: &wgpu::Buffer, count: usize) -> Result<Vec<T>> {
    let bytes = read_bytes(ctx, buffer, (count * std::mem::size_of::<T>()) as u64)?;
    Ok(bytemuck::pod_collect_to_vec(&bytes))
}
