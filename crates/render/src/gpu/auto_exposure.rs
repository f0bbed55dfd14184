//! Auto exposure by Reinhard et al. 2002's key ("Photographic tone
//! reproduction for digital images"): the log-average luminance
//! L_avg = exp(mean(log(δ + L))) of the image, and the exposure
//! log2(key / L_avg) that brings it to middle grey.
//!
//! [`AutoExposure`] meters the accumulation target on the GPU
//! (`crates/render/src/gpu/auto_exposure.wgsl`): one workgroup reads a grid of texels
//! spread over the traced region ([`super::metering_grid`]) and reduces it,
//! and the result stays in a buffer that the display pass binds, so the
//! frame never waits for a readback. The free functions are its CPU twin.

use super::context::GpuContext;
use super::features::FeatureSet;
use super::metering_grid::MeteringGrid;
use super::pipelines::{compute_pipeline, entry, float_texture, storage, uniform};
use super::readback::read_buffer;
use super::shader_source::Program;
use anyhow::Result;
use bytemuck::{Pod, Zeroable};
use wgpu::util::DeviceExt;

/// The shader code this module is the CPU twin of (or, for a harness, runs).
pub const WGSL: marbre_core::wgsl::WgslFile =
    marbre_core::wgsl_file!("crates/render/src/gpu/auto_exposure.wgsl");

/// Reinhard's key: the scene's log-average maps to this middle grey.
pub const KEY: f32 = 0.18;
/// Added to every luminance before the log, so black does not give -∞.
pub const DELTA: f32 = 1e-4;
/// The automatic exposure is clamped to ±this many stops.
pub const MAX_STOPS: f32 = 20.0;

/// What the metering pass writes (`Metered` in crates/render/src/gpu/auto_exposure.wgsl
/// and crates/render/shaders/tonemap.wgsl).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct Metered {
    /// exp(mean(log(δ + L))) over the texels that counted; δ with none.
    pub log_average: f32,
    /// The automatic exposure, log2(key / L_avg), clamped to ±[`MAX_STOPS`].
    pub stops: f32,
    /// 2^stops, the factor the display pass applies (times 2^compensation).
    pub scale: f32,
    /// Texels that counted: finite, none of their channels negative.
    pub count: u32,
}

impl Metered {
    /// The exposure for a log-average luminance met over `count` texels.
    pub fn from_log_average(log_average: f32, count: u32) -> Self {
        let stops = exposure_stops(log_average);
        Self {
            log_average,
            stops,
            scale: stops.exp2(),
            count,
        }
    }

    /// What the display shows before anything was metered: exposure 0.
    fn neutral() -> Self {
        Self {
            log_average: KEY,
            stops: 0.0,
            scale: 1.0,
            count: 0,
        }
    }
}

/// The automatic exposure in stops for a log-average luminance:
/// log2(key / L_avg), clamped to ±[`MAX_STOPS`] (a black or non-finite
/// average still gives a bounded, finite exposure).
pub fn exposure_stops(log_average: f32) -> f32 {
    let stops = (KEY / log_average).log2();
    if stops.is_nan() {
        0.0
    } else {
        stops.clamp(-MAX_STOPS, MAX_STOPS)
    }
}

/// Rec. 709 luminance of a texel if it counts: every channel finite and
/// non-negative, and the luminance itself finite.
fn metered_luminance(p: &[f32; 4]) -> Option<f32> {
    let c = [p[0], p[1], p[2]];
    if c.iter().any(|v| !v.is_finite() || *v < 0.0) {
        return None;
    }
    let l = marbre_core::texture::luminance(glam::Vec3::from(c));
    l.is_finite().then_some(l)
}

/// The CPU twin of the metering pass over every pixel given.
pub fn meter(pixels: &[[f32; 4]]) -> Metered {
    let (sum, count) = pixels
        .iter()
        .filter_map(metered_luminance)
        .fold((0.0_f64, 0_u32), |(s, n), l| {
            (s + f64::from((DELTA + l).ln()), n + 1)
        });
    let mean = if count == 0 {
        f64::from(DELTA.ln())
    } else {
        sum / f64::from(count)
    };
    Metered::from_log_average(mean.exp() as f32, count)
}

/// Reinhard's log-average luminance exp(mean(log(δ + L))) over the pixels
/// (Rec. 709 luminance, δ = [`DELTA`]). Non-finite pixels and pixels with a
/// negative channel are skipped; with none left the result is δ (black).
pub fn log_average_luminance(pixels: &[[f32; 4]]) -> f32 {
    meter(pixels).log_average
}

/// The metering pass and the buffer it leaves its [`Metered`] in.
pub struct AutoExposure {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    params: wgpu::Buffer,
    result: wgpu::Buffer,
}

impl AutoExposure {
    pub fn new(device: &wgpu::Device) -> Result<Self> {
        let (pipeline, layout) = compute_pipeline(
            device,
            Program::AutoExposure,
            &FeatureSet::default(),
            &[
                entry(0, uniform()),
                entry(1, float_texture(false)),
                entry(2, storage(false)),
            ],
            "cs_meter",
        )?;
        let params = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("metering"),
            size: std::mem::size_of::<MeteringGrid>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let result = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("metered exposure"),
            contents: bytemuck::bytes_of(&Metered::neutral()),
            usage: wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::UNIFORM
                | wgpu::BufferUsages::COPY_SRC,
        });
        Ok(Self {
            pipeline,
            layout,
            params,
            result,
        })
    }

    /// Records the metering of the `region` (texels from the origin) of
    /// `radiance`, an Rgba32Float view. The region goes through
    /// `queue.write_buffer`, so one submission meters one region.
    pub fn record(
        &self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        radiance: &wgpu::TextureView,
        region: (u32, u32),
        timestamp_writes: Option<wgpu::ComputePassTimestampWrites<'_>>,
    ) {
        let uniform = MeteringGrid::over(region);
        ctx.queue
            .write_buffer(&self.params, 0, bytemuck::bytes_of(&uniform));
        let bind_group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("auto exposure"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: self.params.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(radiance),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: self.result.as_entire_binding(),
                },
            ],
        });
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("auto exposure"),
            timestamp_writes,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &bind_group, &[]);
        pass.dispatch_workgroups(1, 1, 1);
    }

    /// The buffer holding the latest [`Metered`] (bound as a uniform by the
    /// display pass).
    pub fn result(&self) -> &wgpu::Buffer {
        &self.result
    }

    /// Reads the latest [`Metered`] back, waiting for the GPU: for tests and
    /// reports, never for a frame.
    pub fn read(&self, ctx: &GpuContext) -> Result<Metered> {
        let size = std::mem::size_of::<Metered>() as u64;
        let staging = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("metered readback"),
            size,
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        encoder.copy_buffer_to_buffer(&self.result, 0, &staging, 0, size);
        ctx.queue.submit([encoder.finish()]);
        let bytes = read_buffer(&ctx.device, &staging)?;
        Ok(bytemuck::pod_read_unaligned(&bytes))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grey(l: f32) -> [f32; 4] {
        [l, l, l, 1.0]
    }

    fn rel(a: f32, b: f32) -> f32 {
        (a - b).abs() / b.abs()
    }

    #[test]
    fn log_average_of_a_constant_image_is_its_luminance() {
        for l in [0.0, 0.05, 0.18, 1.0, 50.0, 1e4] {
            let pixels = vec![grey(l); 37];
            let got = log_average_luminance(&pixels);
            // δ is added inside the log: exp(log(δ + L)) = δ + L.
            assert!(rel(got, DELTA + l) < 1e-6, "{l}: {got}");
            if l >= 0.05 {
                assert!(rel(got, l) < 3e-3, "{l}: {got}");
            }
        }
        // A coloured constant reads its Rec. 709 luminance.
        let c = [2.0, 0.5, 0.25, 1.0];
        let l = 0.2126 * 2.0 + 0.7152 * 0.5 + 0.0722 * 0.25;
        assert!(rel(log_average_luminance(&[c; 5]), DELTA + l) < 1e-6);
    }

    #[test]
    fn log_average_of_two_halves_is_their_geometric_mean() {
        for (l1, l2) in [(0.01, 100.0), (0.5, 2.0), (0.0, 1.0), (3.0, 3.0)] {
            let mut pixels = vec![grey(l1); 64];
            pixels.extend(vec![grey(l2); 64]);
            let got = log_average_luminance(&pixels);
            let expected = ((DELTA + l1) * (DELTA + l2)).sqrt();
            assert!(rel(got, expected) < 1e-6, "{l1}, {l2}: {got} vs {expected}");
        }
        // Not the arithmetic mean: the log-average is pulled to the dark half.
        let mut pixels = vec![grey(0.01); 8];
        pixels.extend(vec![grey(100.0); 8]);
        assert!(log_average_luminance(&pixels) < 1.01);
    }

    #[test]
    fn non_finite_and_negative_pixels_are_skipped() {
        let clean = [grey(0.2), grey(0.8), [0.1, 0.3, 0.05, 1.0]];
        let mut dirty = clean.to_vec();
        dirty.extend([
            [f32::NAN, 0.5, 0.5, 1.0],
            [0.5, f32::INFINITY, 0.5, 1.0],
            grey(f32::NEG_INFINITY),
            [-1.0, 0.5, 0.5, 1.0],
            grey(-0.3),
        ]);
        dirty.rotate_left(4);
        let (a, b) = (meter(&clean), meter(&dirty));
        assert_eq!(a.count, 3);
        assert_eq!(b.count, 3);
        assert!(rel(a.log_average, b.log_average) < 1e-6, "{a:?} vs {b:?}");
        assert!(b.log_average.is_finite() && b.scale.is_finite());
    }

    #[test]
    fn black_or_empty_images_give_a_finite_bounded_exposure() {
        for pixels in [vec![grey(0.0); 16], vec![grey(f32::NAN); 4], vec![]] {
            let m = meter(&pixels);
            assert!(rel(m.log_average, DELTA) < 1e-6, "{m:?}");
            assert!(rel(m.stops, (KEY / DELTA).log2()) < 1e-5, "{m:?}");
            assert!(m.scale.is_finite() && m.stops.abs() <= MAX_STOPS);
        }
        assert_eq!(exposure_stops(1e-30), MAX_STOPS);
        assert_eq!(exposure_stops(1e30), -MAX_STOPS);
        assert_eq!(exposure_stops(0.0), MAX_STOPS);
        assert_eq!(exposure_stops(f32::NAN), 0.0);
        assert!(exposure_stops(KEY).abs() < 1e-6);
        // A middle-grey image needs no exposure; one 4× brighter needs -2.
        assert!(meter(&[grey(KEY - DELTA); 3]).stops.abs() < 1e-5);
        assert!((meter(&[grey(4.0 * KEY - DELTA); 3]).stops + 2.0).abs() < 1e-5);
    }

    /// The display pass reads the metering pass's output through its own
    /// declaration of `Metered`: the two must agree, field for field.
    #[test]
    fn both_shaders_declare_the_same_metered_struct() {
        let declaration = |source: &str| {
            let start = source.find("struct Metered {").expect("declared");
            let end = start + source[start..].find('}').unwrap();
            source[start..end]
                .lines()
                .map(|l| l.split("//").next().unwrap().trim().to_owned())
                .filter(|l| !l.is_empty())
                .collect::<Vec<_>>()
        };
        let metering = declaration(WGSL.text);
        let display = declaration(include_str!("../../shaders/tonemap.wgsl"));
        assert_eq!(metering, display);
        assert_eq!(metering.len() - 1, std::mem::size_of::<Metered>() / 4);
    }

    #[test]
    fn the_shader_constants_are_the_cpu_twins() {
        let source = WGSL.text;
        for line in [
            format!("const DELTA: f32 = {DELTA:e};"),
            format!("const KEY: f32 = {KEY};"),
            format!("const MAX_STOPS: f32 = {MAX_STOPS:.1};"),
        ] {
            assert!(source.contains(&line), "shader lacks `{line}`");
        }
    }

    #[test]
    fn the_program_validates() {
        let source = super::super::shader_source::assemble(
            Program::AutoExposure,
            &FeatureSet::default(),
            "",
        )
        .unwrap();
        super::super::pipelines::validate(&source).unwrap();
        let display =
            super::super::shader_source::assemble(Program::Display, &FeatureSet::default(), "")
                .unwrap();
        super::super::pipelines::validate(&display).unwrap();
    }
}
