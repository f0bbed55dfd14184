//! The plumbing every compute harness shares: inputs uploaded, an output
//! buffer the shader writes, one pass recorded, and the output read back.
//! A harness only says what its bindings are and what its results mean.
//!
//! A harness's buffers and dispatches are sized by its input, so each is
//! checked against the device's limits before wgpu is asked for it: one
//! over a limit is an error naming the limit, where wgpu would have raised
//! a validation error (issue 47: `marbre noise` on 20 million points).
//! Harnesses whose inputs can be that large split them first
//! (`points::batch_points`).

use crate::gpu::context::GpuContext;
use crate::gpu::readback::read_buffer;
use anyhow::{Context as _, Result, ensure};
use wgpu::util::DeviceExt;

/// A buffer holding `contents`, bound as `usage` (uniform or storage).
pub fn upload(
    ctx: &GpuContext,
    label: &str,
    contents: &[u8],
    usage: wgpu::BufferUsages,
) -> Result<wgpu::Buffer> {
    check_size(&ctx.device.limits(), label, contents.len() as u64, usage)?;
    Ok(ctx
        .device
        .create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some(label),
            contents,
            usage,
        }))
}

/// A storage buffer of `size` bytes the shader writes and [`read_back`]
/// reads.
pub fn output(ctx: &GpuContext, label: &str, size: u64) -> Result<wgpu::Buffer> {
    let usage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC;
    check_size(&ctx.device.limits(), label, size, usage)?;
    Ok(ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size,
        usage,
        mapped_at_creation: false,
    }))
}

/// Refuses a buffer `label` of `size` bytes bound as `usage` if `limits`
/// do not allow a buffer, or a binding of its kind, that large.
pub fn check_size(
    limits: &wgpu::Limits,
    label: &str,
    size: u64,
    usage: wgpu::BufferUsages,
) -> Result<()> {
    let binding = if usage.contains(wgpu::BufferUsages::STORAGE) {
        Some((
            "max_storage_buffer_binding_size",
            limits.max_storage_buffer_binding_size,
        ))
    } else if usage.contains(wgpu::BufferUsages::UNIFORM) {
        Some((
            "max_uniform_buffer_binding_size",
            limits.max_uniform_buffer_binding_size,
        ))
    } else {
        None
    };
    for (limit, max) in std::iter::once(("max_buffer_size", limits.max_buffer_size)).chain(binding)
    {
        ensure!(
            size <= max,
            "the `{label}` buffer would take {size} bytes, more than this GPU's {limit} of {max}"
        );
    }
    Ok(())
}

/// Records one compute pass of `pipeline` with `bind_group` over `groups`
/// (x, y) workgroups; refused if either is over the device's
/// `max_compute_workgroups_per_dimension`.
pub fn record(
    ctx: &GpuContext,
    encoder: &mut wgpu::CommandEncoder,
    pipeline: &wgpu::ComputePipeline,
    bind_group: &wgpu::BindGroup,
    groups: (u32, u32),
) -> Result<()> {
    let max = ctx.device.limits().max_compute_workgroups_per_dimension;
    ensure!(
        groups.0 <= max && groups.1 <= max,
        "a dispatch of {} × {} workgroups is more than this GPU's \
         max_compute_workgroups_per_dimension of {max}",
        groups.0,
        groups.1
    );
    let mut pass = encoder.begin_compute_pass(&Default::default());
    pass.set_pipeline(pipeline);
    pass.set_bind_group(0, bind_group, &[]);
    pass.dispatch_workgroups(groups.0, groups.1, 1);
    Ok(())
}

/// Submits the work in `encoder` followed by a copy of `buffer` (an
/// [`output`] or any buffer with `COPY_SRC`), waits for it, and returns the
/// buffer's contents as `T`s; an error instead if the device reported one
/// that no scope caught (the results would not be the shader's).
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
    let bytes = read_buffer(&ctx.device, &readback);
    // The GPU's own error first: it says why a read-back failed.
    ctx.uncaptured
        .check()
        .context("a compute harness's work failed")?;
    Ok(bytemuck::cast_slice(&bytes?).to_vec())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A buffer over a limit is refused by the limit's name and value, as
    /// 20 million points for `marbre noise` were (320 MB against WebGPU's
    /// 128 MiB bindings); one within every limit passes.
    #[test]
    fn a_buffer_over_a_limit_is_refused_naming_it() {
        let limits = wgpu::Limits::default();
        let storage = wgpu::BufferUsages::STORAGE;
        let e = check_size(&limits, "points", 320_000_000, storage).unwrap_err();
        assert_eq!(
            e.to_string(),
            "the `points` buffer would take 320000000 bytes, more than this GPU's \
             max_buffer_size of 268435456"
        );
        let e = check_size(&limits, "points", 200_000_000, storage).unwrap_err();
        assert!(
            e.to_string()
                .ends_with("max_storage_buffer_binding_size of 134217728"),
            "{e}"
        );
        let e = check_size(&limits, "frame", 70_000, wgpu::BufferUsages::UNIFORM).unwrap_err();
        assert!(
            e.to_string()
                .ends_with("max_uniform_buffer_binding_size of 65536"),
            "{e}"
        );
        check_size(&limits, "points", 128 << 20, storage).unwrap();
        check_size(&limits, "readback", 256 << 20, wgpu::BufferUsages::MAP_READ).unwrap();
    }
}
