//! Copies a texture back to the CPU, for screenshots, renders and tests.

use anyhow::{Result, anyhow};

/// Reads every texel of a 2D texture of `bytes_per_texel` bytes each, rows
/// tightly packed in the result.
pub fn read_texture(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    texture: &wgpu::Texture,
    bytes_per_texel: u32,
) -> Result<Vec<u8>> {
    let (w, h) = (texture.width(), texture.height());
    let row = w * bytes_per_texel;
    let padded =
        row.div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
    let buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback"),
        size: u64::from(padded) * u64::from(h),
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let mut encoder = device.create_command_encoder(&Default::default());
    encoder.copy_texture_to_buffer(
        texture.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer: &buffer,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(padded),
                rows_per_image: Some(h),
            },
        },
        texture.size(),
    );
    queue.submit([encoder.finish()]);
    read_buffer(device, &buffer).map(|bytes| {
        let mut out = Vec::with_capacity((row * h) as usize);
        for r in 0..h as usize {
            let start = r * padded as usize;
            out.extend_from_slice(&bytes[start..start + row as usize]);
        }
        out
    })
}

/// Maps a MAP_READ buffer and copies its contents out, waiting for the GPU.
pub fn read_buffer(device: &wgpu::Device, buffer: &wgpu::Buffer) -> Result<Vec<u8>> {
    let (tx, rx) = std::sync::mpsc::channel();
    buffer.map_async(wgpu::MapMode::Read, .., move |r| {
        let _ = tx.send(r);
    });
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| anyhow!("waiting for the GPU failed: {e}"))?;
    rx.recv()?
        .map_err(|e| anyhow!("mapping a readback buffer failed: {e}"))?;
    let bytes = buffer
        .get_mapped_range(..)
        .map_err(|e| anyhow!("reading a mapped buffer failed: {e}"))?
        .to_vec();
    buffer.unmap();
    Ok(bytes)
}
