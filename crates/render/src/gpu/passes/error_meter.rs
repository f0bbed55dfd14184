//! How far the accumulated image probably is from the converged one,
//! estimated from the image alone: what the Quality panel plots, and what
//! `marbre render --target-error` stops at.
//!
//! The trace pass keeps, per pixel and channel, the running mean and the
//! spread of its frames' means about it (`shaders/trace.wgsl`, weighted
//! Welford). After F frames of equal samples per frame, spread / (F − 1) is
//! an unbiased estimate of the variance of the pixel's mean, which is its
//! expected squared error. Averaged over the pixels it estimates the MSE
//! against the converged image; relative to mean² + 0.01 it estimates the
//! benchmarks' relMSE. Unlike an error against a reference, it cannot see
//! bias (too few bounces, clamping), and like every variance estimate it
//! misses the fireflies no frame has met yet.
//!
//! [`ErrorMeter`] sums a grid of texels on the GPU
//! (`shaders/error_meter.wgsl`) and reads the sums back without stalling;
//! [`estimate`] is its CPU twin.

use crate::gpu::async_readback::AsyncReadback;
use crate::gpu::context::GpuContext;
use crate::gpu::features::FeatureSet;
use crate::gpu::metering_grid::{MeteringGrid, grid_pixels};
use crate::gpu::pass_timer::{Pass, PassTimer};
use crate::gpu::pipelines::{compute_pipeline, entry, float_texture, storage, uniform};
use crate::gpu::readback::read_buffer;
use crate::gpu::shader_source::Program;
use anyhow::Result;
use bytemuck::{Pod, Zeroable};

/// Added to mean² in the relative error, so that black pixels are judged
/// absolutely (the relMSE of Rousselle et al., as the benchmarks use).
pub const REL_EPSILON: f64 = 0.01;

/// The error of an accumulated image, estimated from its own spread.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ErrorEstimate {
    /// Root of the mean, over pixels and channels, of the variance of the
    /// pixel's mean: the RMSE expected against the converged image.
    pub rmse: f64,
    /// Root of the mean of that variance over mean² + 0.01: √relMSE.
    pub relative: f64,
    /// Frames and samples per pixel accumulated when it was measured.
    pub frames: u32,
    pub samples: u32,
    /// Seconds from the accumulation's first frame to the one measured.
    pub seconds: f64,
    /// Which accumulation it measured: a readback that arrives after a
    /// reset belongs to the previous one.
    pub generation: u32,
}

impl ErrorEstimate {
    /// The estimate from summed spreads over `channels` channels after
    /// `frames` frames; `None` before two frames (one frame has no spread)
    /// or with nothing metered.
    fn from_sums(sums: &ErrorSums) -> Option<Self> {
        if sums.frames < 2 || sums.channels == 0 {
            return None;
        }
        let scale = 1.0 / (f64::from(sums.channels) * f64::from(sums.frames - 1));
        Some(Self {
            rmse: (f64::from(sums.spread) * scale).sqrt(),
            relative: (f64::from(sums.relative_spread) * scale).sqrt(),
            frames: sums.frames,
            samples: sums.samples,
            seconds: f64::from(sums.seconds),
            generation: sums.generation,
        })
    }

    /// Seconds still needed, after the frame measured, to reach `target`
    /// relative error: Monte Carlo error falls as 1/√time, so the target is
    /// reached at seconds · (error / target)².
    pub fn seconds_to(&self, target: f64) -> f64 {
        if self.relative <= target {
            return 0.0;
        }
        self.seconds * ((self.relative / target).powi(2) - 1.0)
    }
}

/// `ErrorParams` in the shader.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct ErrorParams {
    grid: MeteringGrid,
    frames: u32,
    samples: u32,
    seconds: f32,
    generation: u32,
}

/// `ErrorSums` in the shader.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
struct ErrorSums {
    spread: f32,
    relative_spread: f32,
    channels: u32,
    frames: u32,
    samples: u32,
    seconds: f32,
    generation: u32,
}

/// The CPU twin of the GPU meter: the estimate from the accumulated `mean`
/// and `spread` images (row-major, `size`) after `frames` frames and
/// `samples` samples per pixel, over the same grid of texels.
pub fn estimate(
    mean: &[[f32; 4]],
    spread: &[[f32; 4]],
    size: (u32, u32),
    frames: u32,
    samples: u32,
) -> Option<ErrorEstimate> {
    let finite = |p: &[f32; 4]| p[..3].iter().all(|v| v.is_finite());
    let (mut sum, mut relative, mut channels) = (0.0_f64, 0.0_f64, 0_u32);
    for (m, s) in grid_pixels(mean, size)
        .iter()
        .zip(&grid_pixels(spread, size))
    {
        if !finite(m) || !finite(s) {
            continue;
        }
        for c in 0..3 {
            let v = f64::from(s[c].max(0.0));
            sum += v;
            relative += v / (f64::from(m[c]).powi(2) + REL_EPSILON);
            channels += 1;
        }
    }
    ErrorEstimate::from_sums(&ErrorSums {
        spread: sum as f32,
        relative_spread: relative as f32,
        channels,
        frames,
        samples,
        seconds: 0.0,
        generation: 0,
    })
}

/// The metering pass, its result buffer and the readback of that result.
pub struct ErrorMeter {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    params: wgpu::Buffer,
    result: wgpu::Buffer,
    readback: AsyncReadback,
}

/// What [`ErrorMeter::record`] meters: the accumulation's latest mean and
/// spread, over the traced region, after so many frames and samples.
pub struct Accumulated<'a> {
    pub mean: &'a wgpu::TextureView,
    pub spread: &'a wgpu::TextureView,
    pub region: (u32, u32),
    pub frames: u32,
    pub samples: u32,
    pub seconds: f32,
    pub generation: u32,
}

impl ErrorMeter {
    pub fn new(device: &wgpu::Device) -> Result<Self> {
        let (pipeline, layout) = compute_pipeline(
            device,
            Program::ErrorMeter,
            &FeatureSet::default(),
            &[
                entry(0, uniform()),
                entry(1, float_texture(false)),
                entry(2, float_texture(false)),
                entry(3, storage(false)),
            ],
            "cs_error",
        )?;
        let buffer = |label, size, usage| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage,
                mapped_at_creation: false,
            })
        };
        let sums_size = std::mem::size_of::<ErrorSums>() as u64;
        Ok(Self {
            pipeline,
            layout,
            params: buffer(
                "error meter parameters",
                std::mem::size_of::<ErrorParams>() as u64,
                wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            ),
            result: buffer(
                "error sums",
                sums_size,
                wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            ),
            readback: AsyncReadback::new(device, "error sums readback", sums_size),
        })
    }

    /// Records the metering of `accumulated` and the copy of its result
    /// for [`Self::poll`]; nothing while a readback is pending, as its
    /// result could not be read. The parameters go through
    /// `queue.write_buffer`: one meter per submission.
    pub fn record(
        &self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        accumulated: &Accumulated<'_>,
        timer: Option<&PassTimer>,
    ) {
        if !self.readback.is_idle() {
            return;
        }
        self.record_pass(ctx, encoder, accumulated, timer);
        self.readback.record_copy(encoder, &self.result);
    }

    /// Records the metering pass alone.
    fn record_pass(
        &self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        accumulated: &Accumulated<'_>,
        timer: Option<&PassTimer>,
    ) {
        let params = ErrorParams {
            grid: MeteringGrid::over(accumulated.region),
            frames: accumulated.frames,
            samples: accumulated.samples,
            seconds: accumulated.seconds,
            generation: accumulated.generation,
        };
        ctx.queue
            .write_buffer(&self.params, 0, bytemuck::bytes_of(&params));
        let bind_group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("error meter"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: self.params.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(accumulated.mean),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: wgpu::BindingResource::TextureView(accumulated.spread),
                },
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: self.result.as_entire_binding(),
                },
            ],
        });
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("error meter"),
                timestamp_writes: timer.and_then(|t| t.compute_pass(Pass::ErrorMeter)),
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &bind_group, &[]);
            pass.dispatch_workgroups(1, 1, 1);
        }
    }

    /// Starts mapping the copy recorded in the encoder just submitted.
    pub fn after_submit(&self) {
        self.readback.after_submit();
    }

    /// The estimate of a finished readback, once (`None` meanwhile, and for
    /// fewer than two frames).
    pub fn poll(&self) -> Option<ErrorEstimate> {
        let bytes = self.readback.take()?;
        ErrorEstimate::from_sums(&bytemuck::pod_read_unaligned(&bytes))
    }

    /// Meters `accumulated` and reads the result back, waiting for the GPU:
    /// for headless renders and tests, never for a frame.
    pub fn measure(
        &self,
        ctx: &GpuContext,
        accumulated: &Accumulated<'_>,
    ) -> Result<Option<ErrorEstimate>> {
        let size = std::mem::size_of::<ErrorSums>() as u64;
        let staging = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("error sums readback"),
            size,
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        self.record_pass(ctx, &mut encoder, accumulated, None);
        encoder.copy_buffer_to_buffer(&self.result, 0, &staging, 0, size);
        ctx.queue.submit([encoder.finish()]);
        let bytes = read_buffer(&ctx.device, &staging)?;
        Ok(ErrorEstimate::from_sums(&bytemuck::pod_read_unaligned(
            &bytes,
        )))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The parameters and sums have their WGSL twins' layouts, as naga
    /// lays them out.
    #[test]
    fn structs_have_their_wgsl_twins_layout() {
        use crate::gpu::twin_layout::{module_of, twin_layout};
        let module = &module_of(Program::ErrorMeter, &FeatureSet::default(), "");
        twin_layout!(
            module,
            ErrorParams,
            [grid, frames, samples, seconds, generation,]
        );
        twin_layout!(
            module,
            ErrorSums,
            [
                spread,
                relative_spread,
                channels,
                frames,
                samples,
                seconds,
                generation,
            ]
        );
    }

    #[test]
    fn one_frame_has_no_estimate_and_two_do() {
        let mean = vec![[0.5_f32; 4]; 4];
        let spread = vec![[0.01_f32; 4]; 4];
        assert_eq!(estimate(&mean, &spread, (2, 2), 1, 1), None);
        let e = estimate(&mean, &spread, (2, 2), 2, 2).unwrap();
        // spread / (F - 1) = 0.01: RMSE 0.1, relative 0.1 / √(0.25 + 0.01).
        assert!((e.rmse - 0.1).abs() < 1e-6, "{e:?}");
        assert!((e.relative - 0.1 / 0.26_f64.sqrt()).abs() < 1e-6, "{e:?}");
        let later = estimate(&mean, &spread, (2, 2), 5, 5).unwrap();
        assert!((later.rmse - 0.05).abs() < 1e-6, "{later:?}");
    }

    #[test]
    fn non_finite_texels_are_left_out() {
        let mean = vec![[0.5, 0.5, 0.5, 1.0], [f32::NAN, 0.5, 0.5, 1.0]];
        let spread = vec![[0.04, 0.04, 0.04, 1.0], [0.04, f32::INFINITY, 0.0, 1.0]];
        let e = estimate(&mean, &spread, (2, 1), 2, 2).unwrap();
        assert!((e.rmse - 0.2).abs() < 1e-6, "{e:?}");
        let all_bad = vec![[f32::NAN; 4]; 2];
        assert_eq!(estimate(&all_bad, &spread, (2, 1), 3, 3), None);
    }

    /// The Welford update of trace.wgsl, on the CPU: fed frames of known
    /// variance, spread / (F - 1) estimates the variance of the mean.
    #[test]
    fn the_welford_spread_estimates_the_variance_of_the_mean() {
        let frames = 2000;
        let mut state = 12345_u32;
        let mut uniform = || {
            state = state.wrapping_mul(747796405).wrapping_add(2891336453);
            f64::from(state >> 8) / f64::from(1_u32 << 24)
        };
        let (mut mean, mut spread, mut n) = (0.0_f64, 0.0_f64, 0.0_f64);
        let spp = 4.0;
        for _ in 0..frames {
            // A frame's mean of 4 uniform samples: variance 1/12/4.
            let x = (0..4).map(|_| uniform()).sum::<f64>() / spp;
            let w = spp / (n + spp);
            let new_mean = mean + (x - mean) * w;
            spread += ((x - mean) * (x - new_mean) - spread) * w;
            mean = new_mean;
            n += spp;
        }
        let variance_of_mean = spread / f64::from(frames - 1);
        let expected = 1.0 / 12.0 / n;
        let ratio = variance_of_mean / expected;
        assert!((0.85..1.15).contains(&ratio), "ratio {ratio}");
    }

    #[test]
    fn the_time_to_a_target_follows_the_inverse_square_root_law() {
        let e = ErrorEstimate {
            rmse: 0.04,
            relative: 0.04,
            frames: 10,
            samples: 10,
            seconds: 5.0,
            generation: 0,
        };
        // Halving the error takes four times as long: three more times.
        assert!((e.seconds_to(0.02) - 15.0).abs() < 1e-9);
        assert_eq!(e.seconds_to(0.05), 0.0);
    }

    #[test]
    fn the_program_validates_and_its_structs_match() {
        let source =
            crate::gpu::shader_source::assemble(Program::ErrorMeter, &FeatureSet::default(), "")
                .unwrap();
        crate::gpu::pipelines::validate(&source).unwrap();
        assert_eq!(std::mem::size_of::<ErrorParams>(), 32);
        assert_eq!(std::mem::size_of::<ErrorSums>(), 28);
        let constant = format!("const REL_EPSILON: f32 = {REL_EPSILON};");
        assert!(source.contains(&constant), "shader lacks `{constant}`");
    }
}
