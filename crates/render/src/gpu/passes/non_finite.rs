//! Counts of the samples the trace pass refused to accumulate because they
//! were NaN or infinite.
//!
//! `fs_trace` drops such a sample rather than let it poison a pixel's
//! running mean for good, so an image read back is finite by construction
//! and checking its pixels proves nothing. These counters are what does:
//! the shader adds every dropped sample (and every pixel that drops its
//! first) to a small storage buffer with atomics, and keeps each pixel's
//! own count in the alpha of the spread target for the magenta debug view
//! (`tonemap.wgsl`). A correct renderer keeps them at zero; the tests and
//! the Stats panel read them.

use crate::gpu::async_readback::AsyncReadback;
use crate::gpu::context::GpuContext;
use crate::gpu::readback::read_buffer;
use anyhow::Result;
use bytemuck::{Pod, Zeroable};
use std::cell::Cell;

/// The binding of the counters in the trace shader (`trace.wgsl`).
pub const BINDING: u32 = 17;

/// Non-finite samples dropped since the accumulation began.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Pod, Zeroable)]
pub struct NonFiniteCounts {
    /// Samples with a NaN in some channel.
    pub nan: u32,
    /// Samples with an infinite channel and no NaN.
    pub infinite: u32,
    /// Pixels that dropped at least one sample.
    pub pixels: u32,
}

impl NonFiniteCounts {
    pub fn is_zero(&self) -> bool {
        *self == Self::default()
    }
}

const SIZE: u64 = std::mem::size_of::<NonFiniteCounts>() as u64;

/// The GPU buffer of counters, cleared when an accumulation starts, and its
/// non-stalling readback for the viewer.
pub struct NonFiniteCounter {
    buffer: wgpu::Buffer,
    readback: AsyncReadback,
    /// The accumulation generation the readback in flight belongs to.
    readback_generation: Cell<u32>,
}

impl NonFiniteCounter {
    pub fn new(device: &wgpu::Device) -> Self {
        Self {
            buffer: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("non-finite counters"),
                size: SIZE,
                usage: wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::COPY_SRC
                    | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            readback: AsyncReadback::new(device, "non-finite counters readback", SIZE),
            readback_generation: Cell::new(0),
        }
    }

    pub fn buffer(&self) -> &wgpu::Buffer {
        &self.buffer
    }

    /// Zeroes the counters (recorded before the first frame of an
    /// accumulation, in the same encoder).
    pub fn clear(&self, encoder: &mut wgpu::CommandEncoder) {
        encoder.clear_buffer(&self.buffer, 0, None);
    }

    /// Records a copy of the counters for [`Self::poll`], unless one is
    /// still pending.
    pub fn record_readback(&self, encoder: &mut wgpu::CommandEncoder, generation: u32) {
        if self.readback.record_copy(encoder, &self.buffer) {
            self.readback_generation.set(generation);
        }
    }

    /// Starts mapping a copy recorded in the encoder just submitted.
    pub fn after_submit(&self) {
        self.readback.after_submit();
    }

    /// The counters of a finished readback, with the generation of the
    /// accumulation they count.
    pub fn poll(&self) -> Option<(u32, NonFiniteCounts)> {
        let bytes = self.readback.take()?;
        let counts = bytemuck::pod_read_unaligned(&bytes[..SIZE as usize]);
        Some((self.readback_generation.get(), counts))
    }

    /// The counters now, waiting for the GPU.
    pub fn read(&self, ctx: &GpuContext) -> Result<NonFiniteCounts> {
        let staging = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("non-finite counters staging"),
            size: SIZE,
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        encoder.copy_buffer_to_buffer(&self.buffer, 0, &staging, 0, SIZE);
        ctx.queue.submit([encoder.finish()]);
        let bytes = read_buffer(&ctx.device, &staging)?;
        Ok(bytemuck::pod_read_unaligned(&bytes[..SIZE as usize]))
    }
}
