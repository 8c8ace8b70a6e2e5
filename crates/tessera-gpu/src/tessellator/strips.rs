//! Triangle strips written by the GPU (`strips.wgsl`) for the patterns with a strip form —
//! SD-2's radial sectors and ESC's virtual-vertex strips — equal to the CPU engine's
//! `Mesh::strips` entry for entry: a count pass (each visible patch's strip length), a scan,
//! a one-invocation pass for the strip draw's indirect arguments, and a write pass, recorded
//! after the triangles when [`GpuTessellator::set_strips`] turned them on. Their buffers are
//! group 1 of those passes, so the frame stays within 16 storage buffers.

use super::{buffer, GpuPattern, GpuTessellator};
use crate::context::GpuContext;
use crate::error::{GpuError, Result};
use crate::readback;
use crate::scan::Scan;
use crate::shader;

/// u32 of the strip state (`strips.wgsl`'s `StripState`): the draw's
/// `DrawIndexedIndirect`, then overflow, entries and capacity.
const STATE_WORDS: u64 = 8;

/// The strip output's buffers and their bind group.
#[derive(Debug)]
pub(super) struct StripBuffers {
    /// Each patch's count, then offset: read only through `bind` and `scan`.
    _offsets: wgpu::Buffer,
    indices: wgpu::Buffer,
    state: wgpu::Buffer,
    scan: Scan,
    pub(super) bind: wgpu::BindGroup,
    capacity: u64,
}

impl StripBuffers {
    pub(super) fn scan(&self) -> &Scan {
        &self.scan
    }
}

/// The strip walk of `pattern` (`strips.wgsl`'s `{{PATCH_STRIPS}}`), None for a pattern
/// without a strip form.
pub(super) fn walk_of(pattern: GpuPattern) -> Option<&'static str> {
    match pattern {
        GpuPattern::Sd2 => Some("sd2_strips"),
        GpuPattern::Esc => Some("esc_strips"),
        _ => None,
    }
}

impl GpuTessellator {
    /// Turns the strip output on with room for `entries` strip indices (`Some`), or off
    /// (`None`). While on, every frame of a pattern with a strip form (SD-2, ESC) also writes
    /// its strips ([`GpuTessellator::strip_buffers`], [`GpuTessellator::read_strips`]); a
    /// frame whose strips need more room draws no strips and reports it
    /// ([`GpuTessellator::grow_if_overflowed`] grows them). Errors:
    /// [`GpuError::OutputTooLarge`] past the device's buffer limits. Cost: a reallocation.
    pub fn set_strips(&mut self, ctx: &GpuContext, entries: Option<u64>) -> Result<()> {
        let Some(entries) = entries else {
            self.strips = None;
            return Ok(());
        };
        let entries = entries.max(1);
        if entries * 4 > self.buffer_limit || entries > u32::MAX as u64 {
            return Err(GpuError::OutputTooLarge {
                vertices: 0,
                triangles: 0,
                bytes: entries * 4,
                limit: self.buffer_limit,
            });
        }
        let device = &ctx.device;
        use wgpu::BufferUsages as U;
        let patches = self.set.patches as u64;
        let offsets = buffer(device, "strip offsets", 4 * (patches + 1), U::STORAGE);
        let indices = buffer(device, "strip indices", 4 * entries, U::STORAGE | U::INDEX | U::COPY_SRC);
        let state = buffer(
            device,
            "strip state",
            4 * STATE_WORDS,
            U::STORAGE | U::INDIRECT | U::COPY_SRC | U::COPY_DST,
        );
        let mut words = [0u32; STATE_WORDS as usize];
        words[7] = entries as u32;
        ctx.queue.write_buffer(&state, 0, bytemuck::cast_slice(&words));
        let scan = Scan::new(device, &self.pipelines.scan, &offsets, (patches + 1) as u32, 0);
        let bind =
            shader::bind(device, &self.pipelines.strips_layout, &[&offsets, &indices, &state, &self.status]);
        self.strips = Some(StripBuffers { _offsets: offsets, indices, state, scan, bind, capacity: entries });
        if walk_of(self.pattern).is_some() {
            self.pipelines.strips(device, self.pattern);
        }
        Ok(())
    }

    /// The strip output for a render pipeline with `PrimitiveTopology::TriangleStrip` and
    /// `IndexFormat::Uint32` strip restarts: the index buffer and its `DrawIndexedIndirect`
    /// arguments (20 bytes at offset 0; the draw starts at index 1). None while strips are off.
    pub fn strip_buffers(&self) -> Option<(&wgpu::Buffer, &wgpu::Buffer)> {
        self.strips.as_ref().map(|s| (&s.indices, &s.state))
    }

    /// Reads the last frame's strips back, as `Mesh::strips` holds them (RESTART between
    /// strips); None while strips are off. Errors: [`tessera::Error::NoStripForm`] for a
    /// pattern without one (as the CPU engine refuses it), [`GpuError::OutputTooLarge`] when
    /// they overflowed their room. Cost: a queue wait and a copy of the strips.
    pub fn read_strips(&self, ctx: &GpuContext) -> Result<Option<Vec<u32>>> {
        let Some(s) = &self.strips else { return Ok(None) };
        if walk_of(self.pattern).is_none() {
            let pattern = self.pattern.cpu_pattern().map_or("esc", |p| p.name());
            return Err(tessera::Error::NoStripForm { pattern }.into());
        }
        let state: Vec<u32> = readback::read(ctx, &s.state, STATE_WORDS as usize)?;
        let (overflow, entries) = (state[5] != 0, state[6] as u64);
        if overflow {
            return Err(GpuError::OutputTooLarge {
                vertices: 0,
                triangles: 0,
                bytes: 4 * entries,
                limit: 4 * s.capacity,
            });
        }
        if entries == 0 {
            return Ok(Some(Vec::new()));
        }
        let all: Vec<u32> = readback::read(ctx, &s.indices, entries as usize)?;
        Ok(Some(all[1..].to_vec()))
    }

    /// Whether the last frame's strips overflowed; if so, their room grows to what they
    /// needed (with a quarter more). Errors as [`GpuTessellator::set_strips`]. Cost: a queue
    /// wait; a reallocation when they grow.
    pub(super) fn grow_strips_if_overflowed(&mut self, ctx: &GpuContext) -> Result<bool> {
        let Some(s) = self.strips.as_ref().filter(|_| walk_of(self.pattern).is_some()) else {
            return Ok(false);
        };
        let state: Vec<u32> = readback::read(ctx, &s.state, STATE_WORDS as usize)?;
        if state[5] == 0 {
            return Ok(false);
        }
        let need = (state[6] as u64).max(s.capacity);
        self.set_strips(ctx, Some(need.saturating_mul(5).div_ceil(4)))?;
        Ok(true)
    }

    /// Records the strip passes (count, scan, arguments, write) into `c`, when strips are on
    /// and the pattern has them. Reads nothing back.
    pub(super) fn record_strips(&self, c: &mut wgpu::ComputePass<'_>, main: &wgpu::BindGroup) {
        let (Some(s), Some(k)) = (&self.strips, self.pipelines.strips_compiled(self.pattern)) else { return };
        let grid = |n: u32| shader::grid(n.div_ceil(shader::WORKGROUP));
        c.set_bind_group(0, main, &[]);
        c.set_bind_group(1, &s.bind, &[]);
        c.set_pipeline(&k.count);
        let (x, y) = grid(self.set.patches + 1);
        c.dispatch_workgroups(x, y, 1);
        s.scan().record(&self.pipelines.scan, c);
        c.set_bind_group(0, main, &[]);
        c.set_bind_group(1, &s.bind, &[]);
        c.set_pipeline(&k.args);
        c.dispatch_workgroups(1, 1, 1);
        c.set_pipeline(&k.write);
        let (x, y) = grid(self.set.patches);
        c.dispatch_workgroups(x, y, 1);
    }
}
