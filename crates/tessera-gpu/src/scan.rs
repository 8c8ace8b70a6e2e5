//! Exclusive scan of any length on the GPU: reduce-then-scan over several dispatches.
//!
//! A level of `len` elements is cut into blocks of [`SCAN_BLOCK`]; `reduce` writes each
//! block's total, the totals (a level `SCAN_BLOCK` times shorter) are scanned the same way,
//! and `scan_blocks` scans every block in workgroup memory and adds its block's prefix. Two
//! levels cover 2²⁰ elements, three 2³⁰. Only workgroup memory and barriers are used, so it
//! runs on every adapter (subgroup operations would be a faster optional path). The shader is
//! `shaders/scan.wgsl`.

use crate::shader;
use wgpu::util::DeviceExt;

/// Invocations per scan workgroup.
pub const SCAN_WORKGROUP: u32 = 256;
/// Elements each invocation scans sequentially.
pub const SCAN_ITEMS: u32 = 4;
/// Elements per block (one workgroup).
pub const SCAN_BLOCK: u32 = SCAN_WORKGROUP * SCAN_ITEMS;

const SOURCE: &str = include_str!("../shaders/scan.wgsl");

/// The two scan pipelines, compiled once per device.
#[derive(Debug)]
pub struct ScanPipelines {
    layout: wgpu::BindGroupLayout,
    reduce: wgpu::ComputePipeline,
    scan: wgpu::ComputePipeline,
}

impl ScanPipelines {
    /// Compiles `shaders/scan.wgsl`. Cost: one shader compilation.
    pub fn new(device: &wgpu::Device) -> ScanPipelines {
        use shader::Binding::*;
        let module = shader::module(device, "scan", &[SOURCE], &[]);
        let layout = shader::layout(device, &[Uniform, Write, Write]);
        ScanPipelines {
            reduce: shader::pipeline(device, &module, "reduce", &layout),
            scan: shader::pipeline(device, &module, "scan_blocks", &layout),
            layout,
        }
    }
}

/// One level of the scan: its elements, their block count and its bind groups.
#[derive(Debug)]
struct Level {
    blocks: u32,
    /// Binds the level's parameters, its elements and its block sums (the next level's
    /// elements), which the bind group keeps alive.
    bind: wgpu::BindGroup,
}

/// An in-place exclusive scan of the first `len` u32 of one buffer, with `base` added:
/// `data[i] ← base + Σ_{j<i} data[j]`. Made once for a buffer and length (the scratch levels
/// are allocated here), recorded any number of times.
#[derive(Debug)]
pub struct Scan {
    levels: Vec<Level>,
}

impl Scan {
    /// Prepares the scan of `data[..len]`. `data` needs `STORAGE` usage and at least `len`
    /// elements. Cost: one scratch buffer of `⌈len / SCAN_BLOCK⌉` u32 per level, a few small
    /// uniform buffers.
    pub fn new(
        device: &wgpu::Device,
        pipelines: &ScanPipelines,
        data: &wgpu::Buffer,
        len: u32,
        base: u32,
    ) -> Scan {
        let mut levels = Vec::new();
        let (mut buffer, mut len, mut base) = (data.clone(), len, base);
        while len > 0 {
            let blocks = len.div_ceil(SCAN_BLOCK);
            let sums = (blocks > 1).then(|| {
                device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("scan block sums"),
                    size: 4 * blocks as u64,
                    usage: wgpu::BufferUsages::STORAGE,
                    mapped_at_creation: false,
                })
            });
            let params = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("scan params"),
                contents: bytemuck::cast_slice(&[len, base, blocks.min(2) - 1, 0]),
                usage: wgpu::BufferUsages::UNIFORM,
            });
            // The last level reads no prefixes; its `sums` binding is a stand-in.
            let stand_in;
            let sums_binding = match &sums {
                Some(s) => s,
                None => {
                    stand_in = device.create_buffer(&wgpu::BufferDescriptor {
                        label: Some("scan stand-in"),
                        size: 4,
                        usage: wgpu::BufferUsages::STORAGE,
                        mapped_at_creation: false,
                    });
                    &stand_in
                }
            };
            let bind = shader::bind(device, &pipelines.layout, &[&params, &buffer, sums_binding]);
            let next = sums.clone();
            levels.push(Level { blocks, bind });
            match next {
                Some(s) => {
                    buffer = s;
                    len = blocks;
                    base = 0;
                }
                None => break,
            }
        }
        Scan { levels }
    }

    /// Records the scan into `pass`: a reduce per level going down, a block scan per level
    /// coming back up. Cost: `2L − 1` dispatches, O(len) work.
    pub fn record(&self, pipelines: &ScanPipelines, pass: &mut wgpu::ComputePass<'_>) {
        let last = self.levels.len().saturating_sub(1);
        for level in &self.levels[..last] {
            let (x, y) = shader::grid(level.blocks);
            pass.set_pipeline(&pipelines.reduce);
            pass.set_bind_group(0, &level.bind, &[]);
            pass.dispatch_workgroups(x, y, 1);
        }
        for level in self.levels.iter().rev() {
            let (x, y) = shader::grid(level.blocks);
            pass.set_pipeline(&pipelines.scan);
            pass.set_bind_group(0, &level.bind, &[]);
            pass.dispatch_workgroups(x, y, 1);
        }
    }

    /// Number of dispatches [`Scan::record`] records.
    pub fn dispatches(&self) -> usize {
        (2 * self.levels.len()).saturating_sub(1)
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn levels_nest() {
        // 2^24 + 3 elements: 16,385 blocks, then 17, then 1.
        let n = (1u32 << 24) + 3;
        let l1 = n.div_ceil(super::SCAN_BLOCK);
        assert_eq!(l1, 16_385);
        assert_eq!(l1.div_ceil(super::SCAN_BLOCK), 17);
    }
}
