//! One frame's GPU work: the trace (a whole round, or the bands a budget
//! allows, with a preview for a new accumulation), the meters (auto
//! exposure, error) and the display pass onto any colour target.

use super::display_stage::DisplayUniform;
use super::trace_stage::{FRAME_BYTES, FRAME_SLOTS, frame_stride};
use super::{DisplayTarget, MeteredFrom, Renderer, TraceWork, bind};
use crate::cpu_kernel::CpuScene;
use crate::gpu::context::GpuContext;
use crate::gpu::features::Feature;
use crate::gpu::pass_timer::{Pass, PassTimer};
use crate::gpu::pipelines::fullscreen_pipeline;
use crate::gpu::preview_ladder;
use crate::gpu::scene_gpu::{Frame, SAMPLE_SEED_STEP};
use crate::gpu::trace_bands::TraceBudget;
use crate::gpu::trace_pass::{BandPass, PassTimestamps, TracePipeline, cpu_samples_group};
use crate::gpu::{non_finite, scene_gpu};
use anyhow::Result;
use marbre_core::scene::{Metering, ToneMap};
use marbre_core::tile::Tile;
use std::sync::Arc;

impl Renderer {
    /// Traces the rest of the first round and waits for it, if none is
    /// complete yet (a preview may be on show): for screenshots, which
    /// must have the full resolution.
    pub fn complete_first_round(&mut self, ctx: &GpuContext) -> Result<()> {
        if self.accumulation.frames() > 0 {
            return Ok(());
        }
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        self.trace(ctx, &mut encoder, None);
        ctx.queue.submit([encoder.finish()]);
        ctx.device.poll(wgpu::PollType::wait_indefinitely())?;
        Ok(())
    }

    /// The fraction of the round under way already traced (0 between
    /// rounds): the panel's progress while a slow adapter traces in bands.
    pub fn round_progress(&self) -> f32 {
        self.accumulation.next_row() as f32 / self.render_size().1.max(1) as f32
    }

    pub fn resize(&mut self, ctx: &GpuContext, size: (u32, u32)) {
        let size = (size.0.max(1), size.1.max(1));
        if size != self.size {
            self.size = size;
            self.accumulation.resize(&ctx.device, size);
        }
    }

    /// Traces at a fraction of the resolution (while the camera moves).
    pub fn set_render_scale(&mut self, scale: f32) {
        let scale = scale.clamp(0.1, 1.0);
        if scale != self.render_scale {
            self.render_scale = scale;
            self.reset_accumulation();
        }
    }

    /// Makes the targets hold `tile` of an image of `image` (resized to
    /// the tile), traced with that image's camera and per-pixel samples,
    /// so that tiles assemble to its render (`render --tile`, and a large
    /// render traced a piece at a time). Restarts the accumulation; no
    /// pipeline is built.
    pub fn set_crop(&mut self, ctx: &GpuContext, tile: Tile, image: (u32, u32)) {
        if self.crop != Some((tile, image)) {
            self.crop = Some((tile, image));
            self.reset_accumulation();
        }
        self.resize(ctx, tile.size());
    }

    pub fn reset_accumulation(&mut self) {
        self.accumulation.reset();
    }

    /// Starts the accumulation again at sample `first` of the samples of
    /// animation frame `frame` (`frame_sequence::FRAME_SEED_STRIDE`
    /// apart): a sequence's frames each trace their own, a frame traced
    /// again traces the same ones, and a render of N samples from `first`
    /// traces exactly samples [first, first + N) of the frame's one long
    /// render (`render --sample-offset`).
    ///
    /// Sample s of round r is seeded by `s·φ + frame_index`
    /// (`shaders/trace.wgsl`, φ = `SAMPLE_SEED_STEP`) where the frame
    /// index grows by one a round; a long render's round r holds samples
    /// [r·n, (r + 1)·n) for n samples per frame. Starting at `first`, a
    /// multiple of n, the accumulation counts from 0 again, so the frame
    /// index takes `first·φ` for the samples before it and `first / n`
    /// for the rounds before it.
    pub fn restart_at_sample(&mut self, frame: u32, first: u32) {
        self.reset_accumulation();
        self.round_samples = None;
        let per_round = self.scene.render.samples_per_frame.max(1);
        self.frame_index = frame
            .wrapping_mul(crate::frame_sequence::FRAME_SEED_STRIDE)
            .wrapping_add(first / per_round)
            .wrapping_add(first.wrapping_mul(SAMPLE_SEED_STEP));
    }

    /// Makes the rounds that follow trace at most `samples` per pixel:
    /// fewer than the scene's samples per frame when the samples asked
    /// end inside a round (an exact `--spp`), which are the first ones of
    /// that round of the long render.
    pub fn limit_round_samples(&mut self, samples: u32) {
        let per_round = self.scene.render.samples_per_frame.max(1);
        self.round_samples = (samples < per_round).then_some(samples.max(1));
    }

    /// The samples per pixel the next round traces.
    fn samples_per_round(&self) -> u32 {
        self.round_samples
            .unwrap_or(self.scene.render.samples_per_frame.max(1))
    }

    /// Records one whole round: `samples_per_frame` more samples per pixel
    /// (or the rest of the round under way), timed by `timestamps` if
    /// given (the viewer's [`PassTimer`], the benchmarks' own query sets).
    pub fn trace(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        timestamps: Option<PassTimestamps<'_>>,
    ) -> TraceWork {
        self.trace_within(ctx, encoder, TraceBudget::Round, timestamps)
    }

    /// Records about `budget` of tracing (see [`crate::gpu::trace_bands::plan`]): the
    /// round under way continues where it stopped, and a round completed
    /// becomes the image. A new accumulation whose first round does not
    /// fit in the budget first shows previews ([`preview_ladder`]): the
    /// largest that fits at once, then finer ones, each twice the scale
    /// (at most the interactive scale): the window shows the edit at once
    /// and refines it, then the full resolution follows.
    pub fn trace_within(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        budget: TraceBudget,
        timestamps: Option<PassTimestamps<'_>>,
    ) -> TraceWork {
        if !self.scene.render.accumulate && self.accumulation.next_row() == 0 {
            // Each round starts anew; the previews were for the first.
            let previews = self.accumulation.previews();
            self.accumulation.reset();
            self.accumulation.set_previews(previews);
        }
        let plan = preview_ladder::plan(
            self.render_size(),
            self.accumulation.next_row(),
            budget,
            self.accumulation.previews(),
            self.scene.render.interactive_scale,
        );
        let mut work = TraceWork::default();
        let count = plan.passes.len();
        for (index, pass) in plan.passes.into_iter().enumerate() {
            let (size, rows) = (pass.size, pass.rows);
            if index > 0
                && pass.preview.is_none()
                && rows.start == 0
                && !self.scene.render.accumulate
            {
                // A later round of this call: it too starts anew.
                self.accumulation.reset();
                self.accumulation.set_previews(plan.previews);
            }
            // The pass's own first row: a whole round asked during a
            // preview starts at row 0 where the preview stood further on.
            if self.accumulation.samples() == 0 && rows.start == 0 {
                self.non_finite.clear(encoder);
            }
            self.record_band(ctx, encoder, size, rows.clone(), (index, count), timestamps);
            work.pixels += u64::from(size.0) * u64::from(rows.end - rows.start);
            if pass.preview.is_some() {
                // A preview draws the first round's samples at its own
                // size: the frame index (the seed) stays, so the image
                // that follows is the one a whole pass gives.
                if rows.end == size.1 {
                    self.accumulation.show_preview(size);
                } else {
                    self.accumulation.traced_to(rows.end);
                }
                continue;
            }
            self.accumulation.traced_to(rows.end);
            if rows.end == size.1 {
                self.accumulation.advance(self.samples_per_round(), size);
                self.frame_index = self.frame_index.wrapping_add(1);
                work.rounds += 1;
            }
        }
        if self.accumulation.frames() == 0 {
            self.accumulation.set_previews(plan.previews);
        }
        self.non_finite
            .record_readback(encoder, self.accumulation.generation());
        work
    }

    /// Records the pass of one band of rows of a round over a region of
    /// `size`: the frame uniform in its own slot, the bind groups of the
    /// accumulation's current sets.
    fn record_band(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        size: (u32, u32),
        rows: std::ops::Range<u32>,
        (index, count): (usize, usize),
        timestamps: Option<PassTimestamps<'_>>,
    ) {
        let mut uniform: Frame = scene_gpu::frame_uniform(
            &self.scene,
            size,
            self.crop,
            self.frame_index,
            self.accumulation.samples(),
        );
        uniform.env_distribution_size = self.bindings.env_distribution.1;
        let table = self.bindings.meshes.table();
        uniform.light_count = table.lights.len() as u32;
        uniform.light_total_power = table.total_power;
        uniform.triangle_count = self.bindings.meshes.stats().triangles as u32;
        uniform.samples_per_frame = self.samples_per_round();
        uniform.band_start = rows.start;
        uniform.band_end = rows.end;
        let stride = frame_stride(&ctx.device);
        let offset = self.trace.frame_slot * stride;
        self.trace.frame_slot = (self.trace.frame_slot + 1) % FRAME_SLOTS;
        ctx.queue.write_buffer(
            &self.trace.frame_buffer,
            offset,
            bytemuck::cast_slice(&[uniform; 2]),
        );
        let guides = self.trace.key.features.contains(Feature::DenoiseGuides);
        self.accumulation.set_guides(&ctx.device, guides);
        let [previous_albedo, previous_normal] = self.accumulation.previous_guide_views();
        let (previous_mean, previous_spread) = self.accumulation.latest_views();
        let frame = wgpu::BufferBinding {
            buffer: &self.trace.frame_buffer,
            offset: 0,
            size: wgpu::BufferSize::new(FRAME_BYTES),
        };
        let mut entries = vec![
            bind(0, wgpu::BindingResource::Buffer(frame)),
            bind(
                3,
                wgpu::BindingResource::TextureView(&self.bindings.env_view),
            ),
            bind(
                4,
                wgpu::BindingResource::Sampler(&self.bindings.env_sampler),
            ),
            bind(5, wgpu::BindingResource::TextureView(previous_mean)),
            bind(16, wgpu::BindingResource::TextureView(previous_spread)),
            bind(
                18,
                wgpu::BindingResource::TextureView(self.accumulation.latest_compensation_view()),
            ),
            bind(19, wgpu::BindingResource::TextureView(previous_albedo)),
            bind(20, wgpu::BindingResource::TextureView(previous_normal)),
            bind(6, self.bindings.perm_buffer.as_entire_binding()),
            bind(7, self.bindings.texture_param_buffer.as_entire_binding()),
            bind(
                8,
                wgpu::BindingResource::TextureView(&self.bindings.image_atlas_view),
            ),
            bind(11, self.bindings.env_distribution.0.as_entire_binding()),
            bind(
                non_finite::BINDING,
                self.non_finite.buffer().as_entire_binding(),
            ),
        ];
        entries.extend(self.bindings.geometry.entries());
        entries.extend(self.bindings.meshes.entries());
        let scene_group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("trace"),
            layout: &self.trace.layouts.scene,
            entries: &entries,
        });
        let outputs = matches!(self.trace.pipeline, TracePipeline::Compute(_)).then(|| {
            let entries: Vec<_> = (0u32..)
                .zip(self.accumulation.write_views())
                .map(|(i, view)| bind(i, wgpu::BindingResource::TextureView(view)))
                .collect();
            ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("trace outputs"),
                layout: self.trace.layouts.outputs(guides),
                entries: &entries,
            })
        });
        let cpu_samples = matches!(self.trace.pipeline, TracePipeline::Cpu(_)).then(|| {
            let scene = self.cpu_scene.get_or_insert_with(|| {
                Arc::new(CpuScene::new(
                    &self.scene,
                    self.bindings.meshes.geometry().clone(),
                    self.bindings.meshes.table(),
                ))
            });
            cpu_samples_group(
                &ctx.device,
                &ctx.queue,
                &self.trace.layouts,
                scene,
                &uniform,
            )
        });
        BandPass {
            pipeline: &self.trace.pipeline,
            scene: &scene_group,
            frame_offset: offset as u32,
            outputs: outputs.as_ref(),
            cpu_samples: cpu_samples.as_ref(),
            accumulation: &self.accumulation,
            width: size.0,
            rows,
            height: size.1,
            index,
            count,
        }
        .record(encoder, timestamps);
    }

    /// Records the auto-exposure metering of the latest mean, unless the
    /// result already comes from it.
    pub(super) fn meter(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        timer: Option<&PassTimer>,
    ) {
        let render_size = self.shown_size();
        let from = MeteredFrom {
            shown: self.accumulation.shown_count(),
            size: self.size,
            render_size,
        };
        if self.display.metered_from != Some(from) {
            self.display.auto_exposure.record(
                ctx,
                encoder,
                self.accumulation.latest_views().0,
                render_size,
                timer.and_then(|t| t.compute_pass(Pass::AutoExposure)),
            );
            self.display.metered_from = Some(from);
        }
    }

    /// Records the display pass: exposure and tone mapping of the latest mean
    /// into `viewport` of `target`. The rest of the target is left as is.
    /// With auto exposure the mean is metered first (a compute pass in the
    /// same encoder, its result read on the GPU).
    pub fn display(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        target: &DisplayTarget<'_>,
        timer: Option<&PassTimer>,
    ) -> Result<()> {
        let denoised = self.record_denoise(ctx, encoder)?;
        self.display_from(ctx, encoder, target, timer, denoised.as_ref())
    }

    /// [`Self::display`] of `source` instead of the latest mean: an image
    /// of the shown size made from it (the denoised accumulation), exposed
    /// and tone-mapped alike. Auto exposure still meters the mean.
    fn display_from(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        target: &DisplayTarget<'_>,
        timer: Option<&PassTimer>,
        source: Option<&wgpu::TextureView>,
    ) -> Result<()> {
        let DisplayTarget {
            view: target,
            format,
            viewport,
            load,
        } = *target;
        if !self.display.pipelines.contains_key(&format) {
            let p = fullscreen_pipeline(
                &ctx.device,
                "display",
                &self.display.module,
                &self.display.layout,
                "fs_display",
                &[format],
                &[],
            )?;
            self.display.pipelines.insert(format, p);
        }
        // A view's values are shown as they are (RenderSettings::shown_display).
        let shown = self.scene.render.shown_display();
        let auto_exposure = shown.auto_exposure;
        if auto_exposure {
            self.meter(ctx, encoder, timer);
        }
        let render_size = self.shown_size();
        let uniform = DisplayUniform {
            exposure_scale: shown.exposure.exp2(),
            tone_map: match shown.tone_map {
                ToneMap::Aces => 0,
                ToneMap::Reinhard => 1,
                ToneMap::Clamp => 2,
                ToneMap::Exponential => 3,
            },
            encode_srgb: u32::from(!format.is_srgb()),
            auto_exposure: match (auto_exposure, self.scene.render.display.metering) {
                (false, _) => 0,
                (true, Metering::Key) => 1,
                (true, Metering::MassalRms) => 2,
            },
            origin: [viewport.x, viewport.y],
            scale: [
                render_size.0 as f32 / viewport.width.max(1.0),
                render_size.1 as f32 / viewport.height.max(1.0),
            ],
            show_non_finite: u32::from(shown.show_non_finite),
            padding: 0,
        };
        ctx.queue
            .write_buffer(&self.display.buffer, 0, bytemuck::bytes_of(&uniform));
        let bind_group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("display"),
            layout: &self.display.layout,
            entries: &[
                bind(0, self.display.buffer.as_entire_binding()),
                bind(
                    1,
                    wgpu::BindingResource::TextureView(
                        source.unwrap_or(self.accumulation.latest_views().0),
                    ),
                ),
                bind(2, self.display.auto_exposure.result().as_entire_binding()),
                bind(
                    3,
                    wgpu::BindingResource::TextureView(self.accumulation.latest_views().1),
                ),
            ],
        });
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("display"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: target,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load,
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: timer.and_then(|t| t.render_pass(Pass::Display)),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_viewport(
            viewport.x,
            viewport.y,
            viewport.width,
            viewport.height,
            0.0,
            1.0,
        );
        pass.set_pipeline(&self.display.pipelines[&format]);
        pass.set_bind_group(0, &bind_group, &[]);
        pass.draw(0..3, 0..1);
        Ok(())
    }

    /// Starts the readbacks recorded in the encoder just submitted.
    pub fn after_submit(&self) {
        self.error_meter.after_submit();
        self.non_finite.after_submit();
        self.display.oidn.after_submit();
    }
}
