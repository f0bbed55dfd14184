//! The renderer's OIDN stage (`crate::denoiser`): when to denoise, the
//! read-back of the accumulation and its guides, and the uploaded result
//! the display pass shows.
//!
//! In the viewer nothing here waits: the copy is recorded in a frame's
//! encoder and mapped after its submit ([`OidnStage::after_submit`]); a
//! later frame hands the bytes to the OIDN thread; a later one still
//! uploads the result. Meanwhile the display shows the last denoised image
//! of the same accumulation, or the raw mean before the first. A denoise
//! is due at 1, 2, 4, 8… rounds (every few samples at first, ever rarer),
//! and once more when the accumulation settles (nothing traced between two
//! displays). `marbre render` and the tests denoise in place instead
//! ([`Renderer::finish_denoise`]).

use super::Renderer;
use crate::denoiser::{
    DenoiseReport, Done, GuidedImage, Job, OidnWorker, Running, device_for, oidn_for,
};
use crate::gpu::accumulation::ACCUMULATION_FORMAT;
use crate::gpu::context::GpuContext;
use anyhow::{Result, bail};
use marbre_core::scene::DenoiseQuality;
use marbre_oidn::Library;
use std::sync::Arc;
use std::sync::atomic::{AtomicU8, Ordering};
use web_time::Instant;

/// What a denoised image was filtered from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct DenoisedFrom {
    generation: u32,
    frames: u32,
    size: (u32, u32),
}

const IDLE: u8 = 0;
const RECORDED: u8 = 1;
const IN_FLIGHT: u8 = 2;
const MAPPED: u8 = 3;

/// The copy of the mean and both guides into one mappable buffer.
struct GuideReadback {
    buffer: wgpu::Buffer,
    state: Arc<AtomicU8>,
    from: DenoisedFrom,
    /// Bytes per row, padded to wgpu's copy alignment.
    row_bytes: u32,
}

#[derive(Default)]
pub(super) struct OidnStage {
    /// The last denoised image and what it was filtered from.
    image: Option<(wgpu::Texture, wgpu::TextureView, DenoisedFrom)>,
    readback: Option<GuideReadback>,
    worker: Option<OidnWorker<DenoisedFrom>>,
    /// For `finish_denoise`: a device on the calling thread.
    in_place: Option<marbre_oidn::Denoiser>,
    /// The accumulation, rounds and network of the last image sent to be
    /// denoised.
    requested: Option<(u32, u32, DenoiseQuality)>,
    /// The rounds seen by the previous display, for "settled".
    last_seen: Option<(u32, u32)>,
    /// OIDN's library, looked for once.
    library: Option<Result<Arc<Library>, String>>,
    /// Displays recorded since the image in flight was copied.
    frames_meanwhile: u32,
    pub(super) report: Option<DenoiseReport>,
}

impl OidnStage {
    /// Whether a round-`frames` image of accumulation `generation` is due:
    /// at 1, 2, 4, 8… rounds, when the accumulation has settled (the same
    /// rounds as at the last display, and no round under way: a slow
    /// adapter traces a round in bands over many displays), or for
    /// another network.
    fn due(
        &mut self,
        generation: u32,
        frames: u32,
        round_under_way: bool,
        quality: DenoiseQuality,
    ) -> bool {
        let settled = self.last_seen == Some((generation, frames)) && !round_under_way;
        self.last_seen = Some((generation, frames));
        if frames == 0 {
            return false;
        }
        match self.requested {
            Some((g, f, q)) if g == generation && q == quality => {
                f != frames && (frames >= 2 * f || settled)
            }
            _ => true,
        }
    }

    /// Starts mapping the copy recorded in the encoder just submitted.
    pub(super) fn after_submit(&self) {
        let Some(r) = &self.readback else { return };
        if r.state.load(Ordering::Acquire) != RECORDED {
            return;
        }
        r.state.store(IN_FLIGHT, Ordering::Release);
        let state = r.state.clone();
        r.buffer.map_async(wgpu::MapMode::Read, .., move |result| {
            state.store(
                if result.is_ok() { MAPPED } else { IDLE },
                Ordering::Release,
            );
        });
    }
}

impl Renderer {
    /// What denoises the display now, when it is denoising and the scene
    /// asks for OIDN: its library, or why the à-trous filter runs instead.
    pub(super) fn oidn_library(&mut self) -> Result<Arc<Library>, String> {
        let choice = self.scene.render.display.denoiser;
        self.display
            .oidn
            .library
            .get_or_insert_with(|| oidn_for(choice).map(|l| l.expect("asked for OIDN")))
            .clone()
    }

    /// What filters the display, and the last denoise's time: `None` when
    /// not denoising.
    pub fn denoise_report(&self) -> Option<&DenoiseReport> {
        self.denoises()
            .then_some(self.display.oidn.report.as_ref())
            .flatten()
    }

    /// What the display's denoised image would be filtered from now.
    fn denoise_source(&self) -> DenoisedFrom {
        DenoisedFrom {
            generation: self.accumulation.generation(),
            frames: self.accumulation.frames(),
            size: self.shown_size(),
        }
    }

    /// The viewer's step of OIDN, in a frame's encoder: collects what came
    /// back, starts what is due, and returns the view to show (the latest
    /// denoised image of this accumulation), if any.
    pub(super) fn record_oidn(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        library: Arc<Library>,
    ) -> Result<Option<wgpu::TextureView>> {
        let now = self.denoise_source();
        self.collect_oidn(ctx);
        if self.display.oidn.requested.is_some() {
            self.display.oidn.frames_meanwhile += 1;
        }
        let full_round = self.shown_size() == self.render_size();
        let round_under_way = self.accumulation.next_row() > 0;
        let stage = &mut self.display.oidn;
        let idle = stage
            .readback
            .as_ref()
            .is_none_or(|r| r.state.load(Ordering::Acquire) == IDLE)
            && stage.worker.as_ref().is_none_or(|w| !w.is_busy());
        let quality = self.scene.render.display.denoise_quality;
        if stage.due(now.generation, now.frames, round_under_way, quality) && full_round && idle {
            if stage.worker.is_none() {
                let device = device_for(ctx, &library);
                stage.worker = Some(OidnWorker::start(library, device)?);
                stage.report.get_or_insert_with(|| DenoiseReport {
                    running: Running::Oidn {
                        device,
                        version: None,
                        quality,
                    },
                    ..DenoiseReport::default()
                });
            }
            self.record_guide_copy(ctx, encoder, now);
            self.display.oidn.requested = Some((now.generation, now.frames, quality));
            self.display.oidn.frames_meanwhile = 0;
        }
        Ok(self.shown_oidn(now))
    }

    /// The denoised view to show for `now`: one of the same accumulation
    /// and size, however many rounds behind.
    fn shown_oidn(&self, now: DenoisedFrom) -> Option<wgpu::TextureView> {
        let (_, view, from) = self.display.oidn.image.as_ref()?;
        (from.generation == now.generation && from.size == now.size).then(|| view.clone())
    }

    /// Hands a mapped read-back of this accumulation to the OIDN thread
    /// (one of an older one is dropped), cancels a denoise gone stale (an
    /// edit restarted the accumulation), and shows a result that came
    /// back.
    fn collect_oidn(&mut self, ctx: &GpuContext) {
        let generation = self.accumulation.generation();
        let quality = self.scene.render.display.denoise_quality;
        let stage = &mut self.display.oidn;
        if let Some(r) = &stage.readback
            && r.state.load(Ordering::Acquire) == MAPPED
        {
            let image = r
                .buffer
                .get_mapped_range(..)
                .map(|bytes| guided_image(&bytes, r.from.size, r.row_bytes));
            r.buffer.unmap();
            r.state.store(IDLE, Ordering::Release);
            let tag = r.from;
            if let (Ok(image), Some(worker)) = (image, &mut stage.worker)
                && tag.generation == generation
            {
                worker.submit(Job {
                    tag,
                    image,
                    quality,
                });
            }
        }
        let stale = stage
            .requested
            .is_some_and(|(g, _, q)| g != generation || q != quality);
        if let Some(worker) = &stage.worker
            && worker.is_busy()
            && stale
        {
            worker.cancel();
        }
        if let Some(done) = stage.worker.as_mut().and_then(OidnWorker::take) {
            self.show_done(ctx, done);
        }
    }

    /// Uploads a finished denoise and reports it; a cancelled one is
    /// dropped, a failed one logged.
    fn show_done(&mut self, ctx: &GpuContext, done: Done<DenoisedFrom>) {
        let pixels = match done.pixels {
            Ok(pixels) => pixels,
            Err(_) if done.cancelled => return,
            Err(why) => {
                log::warn!("OIDN: {why}");
                return;
            }
        };
        let samples = done.tag.frames * self.scene.render.samples_per_frame;
        self.upload_denoised(ctx, done.tag, &pixels);
        let device = self
            .display
            .oidn
            .worker
            .as_ref()
            .map_or(marbre_oidn::DeviceKind::Cpu, OidnWorker::device);
        let stage = &mut self.display.oidn;
        let running = Running::Oidn {
            device,
            version: Some(done.version),
            quality: self.scene.render.display.denoise_quality,
        };
        let previous = stage.report.take().unwrap_or_default();
        stage.report =
            Some(previous.after_image(running, done.took, samples, Some(stage.frames_meanwhile)));
    }

    /// Records the copy of the mean and both guides of the shown region.
    fn record_guide_copy(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        from: DenoisedFrom,
    ) {
        let Some([albedo, normal]) = self.accumulation.latest_guide_textures() else {
            return;
        };
        let (w, h) = from.size;
        let row_bytes = (w * 16).div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT)
            * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
        let size = 3 * u64::from(row_bytes) * u64::from(h);
        let stage = &mut self.display.oidn;
        if stage
            .readback
            .as_ref()
            .is_none_or(|r| r.buffer.size() != size)
        {
            stage.readback = Some(GuideReadback {
                buffer: ctx.device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("OIDN read-back"),
                    size,
                    usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
                    mapped_at_creation: false,
                }),
                state: Arc::new(AtomicU8::new(IDLE)),
                from,
                row_bytes,
            });
        }
        let r = stage.readback.as_mut().expect("made above");
        r.from = from;
        r.row_bytes = row_bytes;
        let mean = self.accumulation.latest_mean_texture();
        for (i, texture) in [mean, albedo, normal].into_iter().enumerate() {
            encoder.copy_texture_to_buffer(
                texture.as_image_copy(),
                wgpu::TexelCopyBufferInfo {
                    buffer: &r.buffer,
                    layout: wgpu::TexelCopyBufferLayout {
                        offset: i as u64 * u64::from(row_bytes) * u64::from(h),
                        bytes_per_row: Some(row_bytes),
                        rows_per_image: Some(h),
                    },
                },
                wgpu::Extent3d {
                    width: w,
                    height: h,
                    depth_or_array_layers: 1,
                },
            );
        }
        r.state.store(RECORDED, Ordering::Release);
    }

    /// Denoises the latest image with OIDN now, on this thread, if the
    /// display denoises with OIDN and has not this image yet: for `marbre
    /// render`, the bench and tests, before [`Self::read_display`] or
    /// [`Self::read_denoised`]. Returns what filters the display (`None`
    /// when not denoising).
    pub fn finish_denoise(&mut self, ctx: &GpuContext) -> Result<Option<Running>> {
        if !self.denoises() {
            return Ok(None);
        }
        let library = match self.scene.render.display.denoiser {
            marbre_core::scene::Denoiser::Atrous => {
                return Ok(Some(Running::Atrous {
                    instead_of_oidn: None,
                }));
            }
            marbre_core::scene::Denoiser::Oidn => match self.oidn_library() {
                Ok(library) => library,
                Err(why) => {
                    return Ok(Some(Running::Atrous {
                        instead_of_oidn: Some(why),
                    }));
                }
            },
        };
        let now = self.denoise_source();
        let quality = self.scene.render.display.denoise_quality;
        let shown = |r: &Self| {
            r.display
                .oidn
                .image
                .as_ref()
                .is_some_and(|(_, _, f)| *f == now)
                && r.display
                    .oidn
                    .requested
                    .is_some_and(|(_, _, q)| q == quality)
        };
        if !shown(self) {
            self.denoise_now(ctx, library, now, quality)?;
        }
        Ok(self.display.oidn.report.as_ref().map(|r| r.running.clone()))
    }

    /// Denoises the latest image with OIDN, waited for: by the viewer's
    /// OIDN thread if it has one (its job under way finished first), so
    /// that no second device is made, else by a device on this thread.
    fn denoise_now(
        &mut self,
        ctx: &GpuContext,
        library: Arc<Library>,
        now: DenoisedFrom,
        quality: DenoiseQuality,
    ) -> Result<()> {
        let Some([albedo, normal]) = self.read_guides(ctx)? else {
            bail!("no guides to denoise with: the trace has not accumulated them");
        };
        let (w, h, mean) = self.read_radiance(ctx)?;
        let image = GuidedImage {
            size: (w, h),
            mean,
            albedo,
            normal,
        };
        self.display.oidn.requested = Some((now.generation, now.frames, quality));
        if let Some(worker) = &mut self.display.oidn.worker {
            let before = worker.wait();
            worker.submit(Job {
                tag: now,
                image,
                quality,
            });
            let after = worker.wait();
            for done in [before, after].into_iter().flatten() {
                self.show_done(ctx, done);
            }
            return Ok(());
        }
        let device = device_for(ctx, &library);
        let stage = &mut self.display.oidn;
        let oidn = match &mut stage.in_place {
            Some(d) => d,
            slot => slot.insert(marbre_oidn::Denoiser::new(library, device)?),
        };
        let start = Instant::now();
        let pixels = image.denoise(oidn, quality)?;
        let took = start.elapsed();
        let version = Some(oidn.version());
        self.upload_denoised(ctx, now, &pixels);
        let running = Running::Oidn {
            device,
            version,
            quality,
        };
        let samples = self.accumulation.samples();
        let previous = self.display.oidn.report.take().unwrap_or_default();
        self.display.oidn.report = Some(previous.after_image(running, took, samples, None));
        Ok(())
    }

    /// Puts a denoised image where the display pass reads it.
    fn upload_denoised(&mut self, ctx: &GpuContext, from: DenoisedFrom, pixels: &[[f32; 4]]) {
        let (w, h) = from.size;
        let stage = &mut self.display.oidn;
        let fits = stage
            .image
            .as_ref()
            .is_some_and(|(t, _, _)| (t.width(), t.height()) == (w, h));
        if !fits {
            let texture = ctx.device.create_texture(&wgpu::TextureDescriptor {
                label: Some("OIDN output"),
                size: wgpu::Extent3d {
                    width: w,
                    height: h,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: ACCUMULATION_FORMAT,
                usage: wgpu::TextureUsages::TEXTURE_BINDING
                    | wgpu::TextureUsages::COPY_DST
                    | wgpu::TextureUsages::COPY_SRC,
                view_formats: &[],
            });
            let view = texture.create_view(&Default::default());
            stage.image = Some((texture, view, from));
        }
        let (texture, _, tag) = stage.image.as_mut().expect("made above");
        *tag = from;
        ctx.queue.write_texture(
            texture.as_image_copy(),
            bytemuck::cast_slice(pixels),
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(w * 16),
                rows_per_image: Some(h),
            },
            wgpu::Extent3d {
                width: w,
                height: h,
                depth_or_array_layers: 1,
            },
        );
    }

    /// The OIDN output texture, when it holds the latest image.
    pub(super) fn oidn_texture_now(&self) -> Option<&wgpu::Texture> {
        let now = self.denoise_source();
        let (texture, _, from) = self.display.oidn.image.as_ref()?;
        (*from == now).then_some(texture)
    }
}

/// The mean and guides out of the read-back's bytes: three images of
/// `size`, one after the other, rows `row_bytes` apart.
fn guided_image(bytes: &[u8], size: (u32, u32), row_bytes: u32) -> GuidedImage {
    let (w, h) = (size.0 as usize, size.1 as usize);
    let plane = row_bytes as usize * h;
    let read = |i: usize| {
        let mut out = Vec::with_capacity(w * h);
        for y in 0..h {
            let start = i * plane + y * row_bytes as usize;
            out.extend(
                bytes[start..start + w * 16]
                    .chunks_exact(16)
                    .map(bytemuck::pod_read_unaligned::<[f32; 4]>),
            );
        }
        out
    };
    GuidedImage {
        size,
        mean: read(0),
        albedo: read(1),
        normal: read(2),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Asks `due` as the display does each frame and records a request
    /// when due, as `record_oidn` does.
    fn ask(stage: &mut OidnStage, generation: u32, frames: u32, under_way: bool) -> bool {
        let quality = DenoiseQuality::Balanced;
        let due = stage.due(generation, frames, under_way, quality);
        if due {
            stage.requested = Some((generation, frames, quality));
        }
        due
    }

    /// Due at the first round, then at twice the rounds last denoised,
    /// once more when the image settles, and at once for a new
    /// accumulation or another network; never while rounds are traced in
    /// bands at the same count.
    #[test]
    fn denoises_fall_due_at_doubling_rounds_and_when_settled() {
        let mut stage = OidnStage::default();
        assert!(!ask(&mut stage, 0, 0, true), "nothing traced yet");
        assert!(ask(&mut stage, 0, 1, true));
        assert!(!ask(&mut stage, 0, 1, true));
        assert!(ask(&mut stage, 0, 2, true), "twice the rounds");
        for _ in 0..5 {
            assert!(!ask(&mut stage, 0, 3, true), "round 4 under way in bands");
        }
        assert!(ask(&mut stage, 0, 4, false), "twice the rounds again");
        assert!(!ask(&mut stage, 0, 5, false), "a round just completed");
        assert!(
            ask(&mut stage, 0, 5, false),
            "settled: nothing traced since"
        );
        assert!(!ask(&mut stage, 0, 5, false), "already denoised");
        assert!(!ask(&mut stage, 0, 9, true));
        assert!(ask(&mut stage, 0, 10, true));
        assert!(ask(&mut stage, 1, 1, true), "a new accumulation");
        let quality = DenoiseQuality::High;
        assert!(stage.due(1, 1, true, quality), "another network");
    }
}
