//! [`PassTimer`]: timestamp queries around each of the frame's passes, read back on request.

use super::{buffer, PASSES};
use crate::context::GpuContext;
use crate::error::Result;
use crate::readback;

/// Begins compute pass `index` of [`PASSES`], timed by `timer` if given.
pub(super) fn begin_pass<'e>(
    encoder: &'e mut wgpu::CommandEncoder,
    timer: Option<&PassTimer>,
    index: usize,
) -> wgpu::ComputePass<'e> {
    encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
        label: Some(PASSES[index]),
        timestamp_writes: timer.map(|t| wgpu::ComputePassTimestampWrites {
            query_set: &t.queries,
            beginning_of_pass_write_index: Some(2 * index as u32),
            end_of_pass_write_index: Some(2 * index as u32 + 1),
        }),
    })
}

/// Timestamp queries around each of the frame's [`PASSES`], where the adapter has them
/// ([`GpuContext::timestamps`]).
#[derive(Debug)]
pub struct PassTimer {
    pub(super) queries: wgpu::QuerySet,
    pub(super) resolved: wgpu::Buffer,
    period_ns: f32,
}

impl PassTimer {
    /// A timer for one frame's passes, or None when the adapter has no timestamp queries.
    /// Cost: a query set and a 80-byte buffer.
    pub fn new(ctx: &GpuContext) -> Option<PassTimer> {
        if !ctx.timestamps {
            return None;
        }
        let count = 2 * PASSES.len() as u32;
        let queries = ctx.device.create_query_set(&wgpu::QuerySetDescriptor {
            label: Some("pass timestamps"),
            ty: wgpu::QueryType::Timestamp,
            count,
        });
        let resolved = buffer(
            &ctx.device,
            "resolved timestamps",
            8 * count as u64,
            wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
        );
        Some(PassTimer { queries, resolved, period_ns: ctx.queue.get_timestamp_period() })
    }

    /// The last recorded frame's time per pass, in milliseconds, in [`PASSES`] order. Reads
    /// back (a queue wait): statistics on request only.
    pub fn read(&self, ctx: &GpuContext) -> Result<Vec<(&'static str, f64)>> {
        let ticks: Vec<u64> = readback::read(ctx, &self.resolved, 2 * PASSES.len())?;
        Ok(PASSES
            .iter()
            .enumerate()
            .map(|(i, &name)| {
                let dt = ticks[2 * i + 1].saturating_sub(ticks[2 * i]);
                (name, dt as f64 * self.period_ns as f64 * 1e-6)
            })
            .collect())
    }
}
