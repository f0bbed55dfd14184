//! Copies a texture back to the CPU, for screenshots, renders and tests.

use anyhow::{Result, anyhow};

/// The most bytes one band of [`read_texture`] copies at a time: a whole
/// 16384² float image is 4 GiB, over the largest buffer some GPUs allow
/// (an H200's is 4 GiB less 2 MiB), so large images come back in bands
/// of rows through one bounded buffer.
const BAND_BYTES: u64 = 256 << 20;

/// Reads every texel of a 2D texture of `bytes_per_texel` bytes each, rows
/// tightly packed in the result, in bands of rows of at most
/// [`BAND_BYTES`].
pub fn read_texture(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    texture: &wgpu::Texture,
    bytes_per_texel: u32,
) -> Result<Vec<u8>> {
    read_texture_in_bands(device, queue, texture, bytes_per_texel, BAND_BYTES)
}

/// [`read_texture`] with bands of at most `band_bytes` (at least one row):
/// what tests use to make bands of a few rows.
pub fn read_texture_in_bands(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    texture: &wgpu::Texture,
    bytes_per_texel: u32,
    band_bytes: u64,
) -> Result<Vec<u8>> {
    let (w, h) = (texture.width(), texture.height());
    let row = w * bytes_per_texel;
    let padded =
        row.div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
    let band_rows = (band_bytes / u64::from(padded)).clamp(1, u64::from(h)) as u32;
    let buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback"),
        size: u64::from(padded) * u64::from(band_rows),
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let mut out = Vec::with_capacity(row as usize * h as usize);
    for top in (0..h).step_by(band_rows as usize) {
        let rows = band_rows.min(h - top);
        let mut encoder = device.create_command_encoder(&Default::default());
        encoder.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo {
                texture,
                mip_level: 0,
                origin: wgpu::Origin3d { x: 0, y: top, z: 0 },
                aspect: wgpu::TextureAspect::All,
            },
            wgpu::TexelCopyBufferInfo {
                buffer: &buffer,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(padded),
                    rows_per_image: Some(rows),
                },
            },
            wgpu::Extent3d {
                width: w,
                height: rows,
                depth_or_array_layers: 1,
            },
        );
        queue.submit([encoder.finish()]);
        let bytes = read_buffer(device, &buffer)?;
        for r in 0..rows as usize {
            let start = r * padded as usize;
            out.extend_from_slice(&bytes[start..start + row as usize]);
        }
    }
    Ok(out)
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
