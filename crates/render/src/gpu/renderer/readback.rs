//! Reading results back: the accumulated radiance and spread, the
//! metered exposure, the error estimate, the non-finite counters and the
//! displayed image, synchronously for tests and tools, or polled without
//! stalling for the viewer.

use super::{DisplayTarget, Renderer, Viewport};
use crate::gpu::auto_exposure::Metered;
use crate::gpu::context::GpuContext;
use crate::gpu::error_meter;
use crate::gpu::error_meter::ErrorEstimate;
use crate::gpu::non_finite::NonFiniteCounts;
use crate::gpu::pass_timer::PassTimer;
use crate::gpu::readback::{read_texture, read_texture_async};
use anyhow::Result;

impl Renderer {
    /// The linear radiance of the traced region (the running mean), RGBA f32.
    pub fn read_radiance(&self, ctx: &GpuContext) -> Result<(u32, u32, Vec<[f32; 4]>)> {
        self.read_accumulated(ctx, self.accumulation.latest_mean_texture())
    }

    /// The spread of the frames' means about the mean, per pixel, as the
    /// trace pass keeps it (see [`super::error_meter`]).
    pub fn read_spread(&self, ctx: &GpuContext) -> Result<(u32, u32, Vec<[f32; 4]>)> {
        self.read_accumulated(ctx, self.accumulation.latest_spread_texture())
    }

    /// [`Renderer::read_radiance`] awaited: for a web page, which cannot
    /// wait for the GPU (`readback::read_texture_async`).
    pub async fn read_radiance_async(&self, ctx: &GpuContext) -> Result<(u32, u32, Vec<[f32; 4]>)> {
        let texture = self.accumulation.latest_mean_texture();
        let bytes = read_texture_async(&ctx.device, &ctx.queue, texture, 16).await?;
        Ok(self.shown_region(&bytes))
    }

    /// The traced region of one of the accumulation targets.
    pub(super) fn read_accumulated(
        &self,
        ctx: &GpuContext,
        texture: &wgpu::Texture,
    ) -> Result<(u32, u32, Vec<[f32; 4]>)> {
        let bytes = read_texture(&ctx.device, &ctx.queue, texture, 16)?;
        Ok(self.shown_region(&bytes))
    }

    /// The shown region's texels of a whole accumulation target's bytes.
    fn shown_region(&self, bytes: &[u8]) -> (u32, u32, Vec<[f32; 4]>) {
        let all: &[[f32; 4]] = bytemuck::cast_slice(bytes);
        let (rw, rh) = self.shown_size();
        let mut out = Vec::with_capacity((rw * rh) as usize);
        for y in 0..rh {
            let start = (y * self.size.0) as usize;
            out.extend_from_slice(&all[start..start + rw as usize]);
        }
        (rw, rh, out)
    }

    /// Meters the latest mean for auto exposure and reads the result back,
    /// waiting for the GPU (whether or not auto exposure is on): for tests
    /// and reports. The display pass reads the same result on the GPU.
    pub fn metering(&mut self, ctx: &GpuContext) -> Result<Metered> {
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        self.meter(ctx, &mut encoder, None);
        ctx.queue.submit([encoder.finish()]);
        self.display.auto_exposure.read(ctx)
    }

    /// Records the error meter on the latest frame (skip it before the
    /// second frame: one frame has no spread). The viewer calls it every
    /// frame, then [`Self::after_submit`], then collects with
    /// [`Self::poll_error`].
    pub fn meter_error(
        &self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        timer: Option<&PassTimer>,
    ) {
        if self.accumulation.frames() >= 2 {
            self.error_meter
                .record(ctx, encoder, &self.accumulated(), timer);
        }
    }

    /// What the error meter reads.
    fn accumulated(&self) -> error_meter::Accumulated<'_> {
        let (mean, spread) = self.accumulation.latest_views();
        error_meter::Accumulated {
            mean,
            spread,
            region: self.shown_size(),
            frames: self.accumulation.frames(),
            samples: self.accumulation.samples(),
            seconds: self.accumulation.elapsed().as_secs_f32(),
            generation: self.accumulation.generation(),
        }
    }

    /// The non-finite samples dropped by the current accumulation, from a
    /// finished readback (a frame or two old); `None` while none arrived
    /// or the one that did counted an earlier accumulation.
    pub fn poll_non_finite(&self) -> Option<NonFiniteCounts> {
        let (generation, counts) = self.non_finite.poll()?;
        (generation == self.accumulation.generation()).then_some(counts)
    }

    /// The non-finite samples dropped since the accumulation began, waiting
    /// for the GPU: for headless renders and tests.
    pub fn count_non_finite(&self, ctx: &GpuContext) -> Result<NonFiniteCounts> {
        self.non_finite.read(ctx)
    }

    /// The error estimate of a finished readback, once, a frame or two
    /// after it was recorded: it says which frame it measured.
    pub fn poll_error(&self) -> Option<ErrorEstimate> {
        self.error_meter.poll()
    }

    /// Meters the error of the latest frame and waits for it: for headless
    /// renders and tests. `None` before two frames.
    pub fn estimate_error(&self, ctx: &GpuContext) -> Result<Option<ErrorEstimate>> {
        self.error_meter.measure(ctx, &self.accumulated())
    }

    /// The displayed (tone-mapped, sRGB) image at the trace resolution;
    /// denoised, when denoising, from the latest round (OIDN waited for).
    pub fn read_display(&mut self, ctx: &GpuContext) -> Result<image::RgbaImage> {
        self.finish_denoise(ctx)?;
        let target = self.display_texture(ctx)?;
        let (w, h) = (target.width(), target.height());
        let bytes = read_texture(&ctx.device, &ctx.queue, &target, 4)?;
        image::RgbaImage::from_raw(w, h, bytes)
            .ok_or_else(|| anyhow::anyhow!("readback returned the wrong number of bytes"))
    }

    /// The displayed image (sRGB, RGBA8) and the linear mean (RGBA f32) of
    /// the shown region, drawn and copied now into textures of their own:
    /// a web page reads them back later, awaited
    /// (`readback::read_texture_async`), while the renderer goes on.
    pub fn snapshot(&mut self, ctx: &GpuContext) -> Result<(wgpu::Texture, wgpu::Texture)> {
        let display = self.display_texture(ctx)?;
        let (w, h) = (display.width(), display.height());
        let source = self.accumulation.latest_mean_texture();
        let mean = readback_texture(
            ctx,
            "mean snapshot",
            (w, h),
            source.format(),
            wgpu::TextureUsages::COPY_DST,
        );
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        encoder.copy_texture_to_texture(
            source.as_image_copy(),
            mean.as_image_copy(),
            wgpu::Extent3d {
                width: w,
                height: h,
                depth_or_array_layers: 1,
            },
        );
        ctx.queue.submit([encoder.finish()]);
        Ok((display, mean))
    }

    /// The display pass drawn into a new texture of the shown size.
    fn display_texture(&mut self, ctx: &GpuContext) -> Result<wgpu::Texture> {
        let (w, h) = self.shown_size();
        let format = wgpu::TextureFormat::Rgba8UnormSrgb;
        let target = readback_texture(
            ctx,
            "display readback",
            (w, h),
            format,
            wgpu::TextureUsages::RENDER_ATTACHMENT,
        );
        let view = target.create_view(&Default::default());
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        let display_target = DisplayTarget {
            view: &view,
            format,
            viewport: Viewport {
                x: 0.0,
                y: 0.0,
                width: w as f32,
                height: h as f32,
            },
            load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
        };
        self.display(ctx, &mut encoder, &display_target, None)?;
        ctx.queue.submit([encoder.finish()]);
        Ok(target)
    }
}

/// A 2D texture of `size` to be read back (`COPY_SRC`, and `usage`).
fn readback_texture(
    ctx: &GpuContext,
    label: &str,
    (width, height): (u32, u32),
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
) -> wgpu::Texture {
    ctx.device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: usage | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    })
}
