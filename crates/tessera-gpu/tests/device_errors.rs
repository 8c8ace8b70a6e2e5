//! A wgpu error outside any error scope is recorded and returned by `GpuContext::wait` as
//! `GpuError::Device`, never wgpu's default handler's panic.

use tessera_gpu::{GpuContext, GpuError};

#[test]
fn an_uncaptured_wgpu_error_is_a_typed_error_not_a_panic() {
    let ctx = GpuContext::new().unwrap_or_else(|e| panic!("{e}"));
    // MAP_READ may only go with COPY_DST: creating this buffer is a validation error.
    let _bad = ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("invalid usage"),
        size: 16,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::STORAGE,
        mapped_at_creation: false,
    });
    match ctx.wait() {
        Err(GpuError::Device { reason }) => assert!(reason.contains("invalid usage"), "{reason}"),
        other => panic!("expected a device error naming the buffer, got {other:?}"),
    }
    // Reported once: the device is usable again and the next wait is clean.
    ctx.wait().expect("the error was reported already");
}
