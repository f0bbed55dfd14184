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
    pollster::block_on(read_bands(
        device,
        queue,
        texture,
        bytes_per_texel,
        band_bytes,
    ))
}

/// [`read_texture`] awaited rather than waited for: a web page cannot
/// block on the GPU (the browser maps the buffer on its own event loop),
/// so it awaits this (issue 34).
pub async fn read_texture_async(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    texture: &wgpu::Texture,
    bytes_per_texel: u32,
) -> Result<Vec<u8>> {
    read_bands(device, queue, texture, bytes_per_texel, BAND_BYTES).await
}

async fn read_bands(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    texture: &wgpu::Texture,
    bytes_per_texel: u32,
    band_bytes: u64,
) -> Result<Vec<u8>> {
    let bands = Bands::new(device, texture, bytes_per_texel, band_bytes);
    let mut out = Vec::with_capacity(bands.row as usize * texture.height() as usize);
    for top in bands.tops() {
        let rows = bands.copy(device, queue, texture, top);
        bands.append(
            &read_buffer_async(device, &bands.buffer).await?,
            rows,
            &mut out,
        );
    }
    Ok(out)
}

/// A texture read in bands of rows through one bounded buffer.
struct Bands {
    buffer: wgpu::Buffer,
    /// Bytes of a row, tight and as copied (padded to wgpu's alignment).
    row: u32,
    padded: u32,
    band_rows: u32,
    height: u32,
}

impl Bands {
    fn new(
        device: &wgpu::Device,
        texture: &wgpu::Texture,
        bytes_per_texel: u32,
        band_bytes: u64,
    ) -> Self {
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
        Self {
            buffer,
            row,
            padded,
            band_rows,
            height: h,
        }
    }

    /// The first row of each band.
    fn tops(&self) -> impl Iterator<Item = u32> + use<> {
        (0..self.height).step_by(self.band_rows as usize)
    }

    /// Copies the band from row `top` into the buffer; returns its rows.
    fn copy(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        texture: &wgpu::Texture,
        top: u32,
    ) -> u32 {
        let rows = self.band_rows.min(self.height - top);
        let mut encoder = device.create_command_encoder(&Default::default());
        encoder.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo {
                texture,
                mip_level: 0,
                origin: wgpu::Origin3d { x: 0, y: top, z: 0 },
                aspect: wgpu::TextureAspect::All,
            },
            wgpu::TexelCopyBufferInfo {
                buffer: &self.buffer,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(self.padded),
                    rows_per_image: Some(rows),
                },
            },
            wgpu::Extent3d {
                width: texture.width(),
                height: rows,
                depth_or_array_layers: 1,
            },
        );
        queue.submit([encoder.finish()]);
        rows
    }

    /// Appends the band's `rows` rows of `bytes`, without their padding.
    fn append(&self, bytes: &[u8], rows: u32, out: &mut Vec<u8>) {
        for r in 0..rows as usize {
            let start = r * self.padded as usize;
            out.extend_from_slice(&bytes[start..start + self.row as usize]);
        }
    }
}

/// Maps a MAP_READ buffer and copies its contents out, waiting for the GPU.
/// (The awaited version's own wait does the waiting natively: its future
/// is ready when blocked on.)
pub fn read_buffer(device: &wgpu::Device, buffer: &wgpu::Buffer) -> Result<Vec<u8>> {
    pollster::block_on(read_buffer_async(device, buffer))
}

/// [`read_buffer`] awaited, for a web page: the map's callback completes
/// a one-shot future.
pub async fn read_buffer_async(device: &wgpu::Device, buffer: &wgpu::Buffer) -> Result<Vec<u8>> {
    let mapped = MapFuture::default();
    let done = mapped.0.clone();
    buffer.map_async(wgpu::MapMode::Read, .., move |r| {
        let mut state = done.lock().unwrap_or_else(|e| e.into_inner());
        state.0 = Some(r);
        if let Some(waker) = state.1.take() {
            waker.wake();
        }
    });
    // Native wgpu runs the callback only when polled, and this wait does
    // (the future is then ready); in a page the wait returns at once and
    // the browser runs the callback on its own loop.
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| anyhow!("waiting for the GPU failed: {e}"))?;
    mapped
        .await
        .map_err(|e| anyhow!("mapping a readback buffer failed: {e}"))?;
    let bytes = buffer
        .get_mapped_range(..)
        .map_err(|e| anyhow!("reading a mapped buffer failed: {e}"))?
        .to_vec();
    buffer.unmap();
    Ok(bytes)
}

/// The outcome of a `map_async`, and who waits for it. (No async runtime
/// is a dependency: this one-shot is all the readback needs.)
type MapState = (
    Option<Result<(), wgpu::BufferAsyncError>>,
    Option<std::task::Waker>,
);

#[derive(Default)]
struct MapFuture(std::sync::Arc<std::sync::Mutex<MapState>>);

impl std::future::Future for MapFuture {
    type Output = Result<(), wgpu::BufferAsyncError>;

    fn poll(
        self: std::pin::Pin<&mut Self>,
        cx: &mut std::task::Context<'_>,
    ) -> std::task::Poll<Self::Output> {
        let mut state = self.0.lock().unwrap_or_else(|e| e.into_inner());
        match state.0.take() {
            Some(result) => std::task::Poll::Ready(result),
            None => {
                state.1 = Some(cx.waker().clone());
                std::task::Poll::Pending
            }
        }
    }
}
