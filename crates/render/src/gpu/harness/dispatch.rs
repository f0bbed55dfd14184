//! The plumbing every compute harness shares: inputs uploaded, an output
//! buffer the shader writes, one pass recorded, and the output read back.
//! A harness only says what its bindings are and what its results mean.

use crate::gpu::context::GpuContext;
use crate::gpu::readback::read_buffer;
use anyhow::Result;
use wgpu::util::DeviceExt;

/// A buffer holding `contents`, bound as `usage` (uniform or storage).
pub fn upload(
    ctx: &GpuContext,
    label: &str,
    contents: &[u8],
    usage: wgpu::BufferUsages,
) -> wgpu::Buffer {
    ctx.device
        .create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some(label),
            contents,
            usage,
        })
}

/// A storage buffer of `size` bytes the shader writes and [`read_back`]
/// reads.
pub fn output(ctx: &GpuContext, label: &str, size: u64) -> wgpu::Buffer {
    ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    })
}

/// Records one compute pass of `pipeline` with `bind_group` over `groups`
/// (x, y) workgroups.
pub fn record(
    encoder: &mut wgpu::CommandEncoder,
    pipeline: &wgpu::ComputePipeline,
    bind_group: &wgpu::BindGroup,
    groups: (u32, u32),
) {
    let mut pass = encoder.begin_compute_pass(&Default::default());
    pass.set_pipeline(pipeline);
    pass.set_bind_group(0, bind_group, &[]);
    pass.dispatch_workgroups(groups.0, groups.1, 1);
}

/// Submits the work in `encoder` followed by a copy of `buffer` (an
/// [`output`] or any buffer with `COPY_SRC`), waits for it, and returns the
/// buffer's contents as `T`s.
pub fn read_back<T: bytemuck::Pod>(
    ctx: &GpuContext,
    mut encoder: wgpu::CommandEncoder,
    buffer: &wgpu::Buffer,
) -> Result<Vec<T>> {
    let readback = ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("harness readback"),
        size: buffer.size(),
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    encoder.copy_buffer_to_buffer(buffer, 0, &readback, 0, buffer.size());
    ctx.queue.submit([encoder.finish()]);
    let bytes = read_buffer(&ctx.device, &readback)?;
    Ok(bytemuck::cast_slice(&bytes).to_vec())
}
