//! Acquiring a device: one adapter, its own limits requested, a typed error when there is none.

use std::sync::{Arc, Mutex};

use crate::error::{GpuError, Result};

/// The packages that give a Linux machine without a GPU a software Vulkan adapter
/// (lavapipe, reported as "llvmpipe"), named in [`GpuError::NoAdapter`].
pub const SOFTWARE_DRIVER_PACKAGES: &str = "apt-get install -y mesa-vulkan-drivers libvulkan1";

/// A wgpu device and its queue, with what the engine needs to know about the adapter.
#[derive(Debug)]
pub struct GpuContext {
    /// The device every buffer and pipeline of the engine is made on.
    pub device: wgpu::Device,
    /// Its queue.
    pub queue: wgpu::Queue,
    /// The adapter's name, driver and backend.
    pub info: wgpu::AdapterInfo,
    /// The limits the device was created with: the adapter's own (not WebGPU's defaults), so
    /// that storage bindings up to `max_storage_buffer_binding_size` may be used.
    pub limits: wgpu::Limits,
    /// Whether timestamp queries inside compute passes are available (for per-pass times).
    pub timestamps: bool,
    /// Errors wgpu reported outside any error scope, recorded by the handler
    /// [`GpuContext::for_adapter`] installs instead of wgpu's default one, which panics;
    /// [`GpuContext::wait`] turns the first into [`GpuError::Device`].
    errors: Arc<Mutex<Vec<String>>>,
}

impl GpuContext {
    /// Opens the first adapter wgpu finds (a high-performance one when there is a choice),
    /// with its own limits and, when it has them, timestamp queries.
    ///
    /// Errors: [`GpuError::NoAdapter`] (naming [`SOFTWARE_DRIVER_PACKAGES`]) when no adapter
    /// exists, [`GpuError::Device`] when the device cannot be created. Cost: driver start-up
    /// (tens of milliseconds on lavapipe); blocks the calling thread.
    pub fn new() -> Result<GpuContext> {
        pollster::block_on(Self::new_async())
    }

    /// [`GpuContext::new`], as a future.
    pub async fn new_async() -> Result<GpuContext> {
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        let options = wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            ..Default::default()
        };
        let adapter = instance
            .request_adapter(&options)
            .await
            .map_err(|e| GpuError::NoAdapter { reason: e.to_string() })?;
        Self::for_adapter(&adapter, "tessera-gpu").await
    }

    /// A device on `adapter` (labelled `label`) with the adapter's own limits and, when it
    /// has them, timestamp queries: what [`GpuContext::new`] makes, for a caller that chose
    /// the adapter itself (a window's surface must be compatible with it). wgpu errors raised
    /// outside an error scope are recorded, not panicked on, and reported by
    /// [`GpuContext::wait`].
    ///
    /// Errors: [`GpuError::Device`] when the device cannot be created. Cost: driver start-up.
    pub async fn for_adapter(adapter: &wgpu::Adapter, label: &str) -> Result<GpuContext> {
        let wanted = wgpu::Features::TIMESTAMP_QUERY | wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS;
        let features = adapter.features() & wanted;
        let limits = adapter.limits();
        let descriptor = wgpu::DeviceDescriptor {
            label: Some(label),
            required_features: features,
            required_limits: limits.clone(),
            ..Default::default()
        };
        let (device, queue) = adapter
            .request_device(&descriptor)
            .await
            .map_err(|e| GpuError::Device { reason: e.to_string() })?;
        let errors: Arc<Mutex<Vec<String>>> = Arc::default();
        let sink = errors.clone();
        device.on_uncaptured_error(Arc::new(move |e: wgpu::Error| {
            if let Ok(mut log) = sink.lock() {
                log.push(e.to_string().trim_end().to_string());
            }
        }));
        Ok(GpuContext {
            device,
            queue,
            info: adapter.get_info(),
            limits,
            timestamps: features.contains(wgpu::Features::TIMESTAMP_QUERY),
            errors,
        })
    }

    /// Err with the first wgpu error recorded outside an error scope since the last call
    /// (the rest dropped), as [`GpuError::Device`]. Cost: O(1).
    pub fn check_errors(&self) -> Result<()> {
        let mut log = self.errors.lock().unwrap_or_else(|p| p.into_inner());
        let first = log.drain(..).next();
        first.map_or(Ok(()), |reason| Err(GpuError::Device { reason }))
    }

    /// Waits until the queue has finished everything submitted so far. Cost: the GPU work.
    /// A wgpu error recorded since the last check (see [`GpuContext::check_errors`]) is
    /// returned as [`GpuError::Device`].
    pub fn wait(&self) -> Result<()> {
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map(|_| ())
            .map_err(|e| GpuError::Device { reason: e.to_string() })?;
        self.check_errors()
    }
}
