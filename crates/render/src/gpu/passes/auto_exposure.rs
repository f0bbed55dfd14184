//! Auto exposure by Reinhard et al. 2002's key ("Photographic tone
//! reproduction for digital images"): the log-average luminance
//! L_avg = exp(mean(log(δ + L))) of the image, and the exposure
//! log2(key / L_avg) that brings it to middle grey. Beside it, Massal's
//! (his tutorial's annex I): the RMS luminance L_rms = √(Σ w_c · mean(c²))
//! and the scale −ln(0.6) / L_rms, which his `1 − exp(−x)` curve shows as
//! 0.4. One pass meters both; the display picks one
//! ([`marbre_core::scene::Metering`]).
//!
//! [`AutoExposure`] meters the accumulation target on the GPU
//! (`shaders/auto_exposure.wgsl`): one workgroup reads a grid of texels
//! spread over the traced region ([`crate::gpu::metering_grid`]) and reduces it,
//! and the result stays in a buffer that the display pass binds, so the
//! frame never waits for a readback. The free functions are its CPU twin.

use crate::gpu::context::GpuContext;
use crate::gpu::features::FeatureSet;
use crate::gpu::metering_grid::MeteringGrid;
use crate::gpu::pipelines::{compute_pipeline, entry, float_texture, storage, uniform};
use crate::gpu::readback::read_buffer;
use crate::gpu::shader_source::Program;
use anyhow::Result;
use bytemuck::{Pod, Zeroable};
use marbre_core::scene::Metering;
use wgpu::util::DeviceExt;

/// Reinhard's key: the scene's log-average maps to this middle grey.
pub const KEY: f32 = 0.18;
/// Added to every luminance before the log, so black does not give -∞.
pub const DELTA: f32 = 1e-4;
/// The automatic exposure is clamped to ±this many stops.
pub const MAX_STOPS: f32 = 20.0;
/// Massal's luminance weights of the mean squares (his code's: Rec. 709's
/// red, the precise green and blue).
pub const MASSAL_WEIGHTS: [f32; 3] = [0.2126, 0.715_16, 0.072_169];
/// Massal's target: exp(−scale · L_rms) = 0.6, so 1 − exp shows L_rms as 0.4.
pub const MASSAL_TARGET: f32 = 0.6;
/// Below this RMS luminance Massal keeps his default exposure (scale 1).
pub const MASSAL_MIN_RMS: f32 = 0.001;

/// What the metering pass writes (`Metered` in shaders/auto_exposure.wgsl
/// and shaders/tonemap.wgsl).
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
    /// Massal's RMS luminance √(Σ w_c · mean(c²)) over the same texels; 0
    /// with none.
    pub rms: f32,
    /// Massal's exposure in stops, log2(−ln 0.6 / rms) clamped to
    /// ±[`MAX_STOPS`]; 0 (his default, scale 1) at rms ≤ 0.001.
    pub rms_stops: f32,
    /// 2^rms_stops, the factor the display pass applies with his metering.
    pub rms_scale: f32,
    /// Keeps the struct a multiple of 16 bytes, as a uniform.
    pub padding: u32,
}

impl Metered {
    /// The exposures for a log-average and an RMS luminance met over
    /// `count` texels.
    pub fn from_averages(log_average: f32, rms: f32, count: u32) -> Self {
        let stops = exposure_stops(log_average);
        let rms_stops = massal_stops(rms);
        Self {
            log_average,
            stops,
            scale: stops.exp2(),
            count,
            rms,
            rms_stops,
            rms_scale: rms_stops.exp2(),
            padding: 0,
        }
    }

    /// What the display shows before anything was metered: exposure 0.
    fn neutral() -> Self {
        Self {
            log_average: KEY,
            stops: 0.0,
            scale: 1.0,
            count: 0,
            rms: 0.0,
            rms_stops: 0.0,
            rms_scale: 1.0,
            padding: 0,
        }
    }

    /// The metered exposure in stops the display applies with `metering`.
    pub fn stops_for(&self, metering: Metering) -> f32 {
        match metering {
            Metering::Key => self.stops,
            Metering::MassalRms => self.rms_stops,
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

/// Massal's exposure in stops for an RMS luminance: log2(−ln(0.6) / L_rms)
/// (his `exposure = logf(0.6f) / mediumLuminance`, negated as marbre
/// scales by a positive factor), clamped to ±[`MAX_STOPS`]; at L_rms ≤
/// 0.001 (or NaN) his default exposure −1, that is 0 stops.
pub fn massal_stops(rms: f32) -> f32 {
    if rms > MASSAL_MIN_RMS {
        (-MASSAL_TARGET.ln() / rms)
            .log2()
            .clamp(-MAX_STOPS, MAX_STOPS)
    } else {
        0.0
    }
}

/// Σ w_c · c² of a texel: its share of Massal's mean square.
fn massal_square(p: &[f32; 4]) -> f64 {
    (0..3)
        .map(|c| f64::from(MASSAL_WEIGHTS[c]) * f64::from(p[c]) * f64::from(p[c]))
        .sum()
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
    let (sum, squares, count) = pixels
        .iter()
        .filter_map(|p| Some((metered_luminance(p)?, massal_square(p))))
        .fold((0.0_f64, 0.0_f64, 0_u32), |(s, q, n), (l, square)| {
            (s + f64::from((DELTA + l).ln()), q + square, n + 1)
        });
    let (mean, mean_square) = if count == 0 {
        (f64::from(DELTA.ln()), 0.0)
    } else {
        (sum / f64::from(count), squares / f64::from(count))
    };
    Metered::from_averages(mean.exp() as f32, mean_square.sqrt() as f32, count)
}

/// Massal's RMS luminance √(Σ w_c · mean(c²)) over the pixels, skipping
/// those [`log_average_luminance`] skips; 0 with none left.
pub fn rms_luminance(pixels: &[[f32; 4]]) -> f32 {
    meter(pixels).rms
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
    use crate::gpu::shader_source::renderer_files;

    fn grey(l: f32) -> [f32; 4] {
        [l, l, l, 1.0]
    }

    fn rel(a: f32, b: f32) -> f32 {
        (a - b).abs() / b.abs()
    }

    /// The metered result and the metering grid have their WGSL twins'
    /// layouts, as naga lays them out.
    #[test]
    fn structs_have_their_wgsl_twins_layout() {
        use crate::gpu::twin_layout::{module_of, twin_layout};
        let module = &module_of(Program::AutoExposure, &FeatureSet::default(), "");
        twin_layout!(
            module,
            Metered,
            [
                log_average,
                stops,
                scale,
                count,
                rms,
                rms_stops,
                rms_scale,
                padding,
            ]
        );
        twin_layout!(module, MeteringGrid, [region, grid]);
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

    /// Massal's annex I transcribed: the mean of each channel's square
    /// over his grid, `mediumLuminance = sqrtf(0.2126f * red + 0.715160f *
    /// green + 0.072169f * blue)` and `exposure = logf(0.6f) /
    /// mediumLuminance` (−1 below 0.001), in f64 on a known image; then
    /// his curve `1 − exp(exposure · c)` of each pixel against marbre's
    /// scale and `1 − exp(−x)`.
    #[test]
    fn massal_rms_exposure_is_his_formula() {
        fn his_exposure(pixels: &[[f32; 4]]) -> f64 {
            let weight = 1.0 / pixels.len() as f64;
            let mut medium = [0.0_f64; 3];
            for p in pixels {
                for c in 0..3 {
                    medium[c] += weight * f64::from(p[c]) * f64::from(p[c]);
                }
            }
            let medium_luminance =
                (0.2126 * medium[0] + 0.715160 * medium[1] + 0.072169 * medium[2]).sqrt();
            if medium_luminance > 0.001 {
                0.6_f64.ln() / medium_luminance
            } else {
                -1.0
            }
        }
        // A 64 × 48 gradient with a bright corner: his RMS is pulled up by
        // the corner (squares), unlike the log-average.
        let pixels: Vec<[f32; 4]> = (0..64 * 48)
            .map(|i| {
                let (x, y) = ((i % 64) as f32 / 63.0, (i / 64) as f32 / 47.0);
                let corner = if x > 0.9 && y > 0.9 { 20.0 } else { 0.0 };
                [
                    0.05 + 2.0 * x + corner,
                    0.3 * y + corner,
                    0.1 + 0.5 * x * y,
                    1.0,
                ]
            })
            .collect();
        let m = meter(&pixels);
        let e = his_exposure(&pixels);
        assert!(e < 0.0, "{e}");
        assert!(
            rel(m.rms_scale, -e as f32) < 1e-5,
            "scale {} vs −e {}",
            m.rms_scale,
            -e
        );
        for p in pixels.iter().step_by(37) {
            for c in 0..3 {
                let his = 1.0 - (e * f64::from(p[c])).exp();
                let ours = 1.0 - (-(p[c] * m.rms_scale)).exp();
                assert!(
                    (f64::from(ours) - his).abs() < 1e-5,
                    "{p:?}: {ours} vs {his}"
                );
            }
        }
        // The two meterings differ on this image.
        assert!((m.rms_stops - m.stops).abs() > 0.5, "{m:?}");
        // A grey image of luminance L: RMS L, and L shows as 0.4.
        let grey_pixels = vec![grey(0.25); 10];
        let g = meter(&grey_pixels);
        let weights: f32 = MASSAL_WEIGHTS.iter().sum();
        assert!(rel(g.rms, 0.25 * weights.sqrt()) < 1e-6, "{g:?}");
        assert!(rel(1.0 - (-g.rms * g.rms_scale).exp(), 0.4) < 1e-5);
        // Below 0.001 his default −1: scale 1; black likewise.
        for l in [0.0, 5e-4] {
            let m = meter(&[grey(l); 4]);
            assert_eq!((m.rms_stops, m.rms_scale), (0.0, 1.0), "{l}: {m:?}");
            assert_eq!(his_exposure(&[grey(l); 4]), -1.0);
        }
        assert_eq!(massal_stops(f32::NAN), 0.0);
        assert_eq!(massal_stops(1e30), -MAX_STOPS);
        assert_eq!(meter(&[]).rms, 0.0);
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
        assert!(rel(a.rms, b.rms) < 1e-6, "{a:?} vs {b:?}");
        assert!(b.rms_scale.is_finite());
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
        let metering = declaration(renderer_files::AUTO_EXPOSURE.text);
        let display = declaration(renderer_files::TONEMAP.text);
        assert_eq!(metering, display);
        assert_eq!(metering.len() - 1, std::mem::size_of::<Metered>() / 4);
    }

    #[test]
    fn the_shader_constants_are_the_cpu_twins() {
        let source = renderer_files::AUTO_EXPOSURE.text;
        for line in [
            format!("const DELTA: f32 = {DELTA:e};"),
            format!("const KEY: f32 = {KEY};"),
            format!("const MAX_STOPS: f32 = {MAX_STOPS:.1};"),
            format!(
                "const MASSAL_WEIGHTS: vec3f = vec3f({}, {}, {});",
                MASSAL_WEIGHTS[0], MASSAL_WEIGHTS[1], MASSAL_WEIGHTS[2]
            ),
            format!("const MASSAL_TARGET: f32 = {MASSAL_TARGET};"),
            format!("const MASSAL_MIN_RMS: f32 = {MASSAL_MIN_RMS};"),
        ] {
            assert!(source.contains(&line), "shader lacks `{line}`");
        }
    }

    #[test]
    fn the_program_validates() {
        let source =
            crate::gpu::shader_source::assemble(Program::AutoExposure, &FeatureSet::default(), "")
                .unwrap();
        crate::gpu::pipelines::validate(&source).unwrap();
        let display =
            crate::gpu::shader_source::assemble(Program::Display, &FeatureSet::default(), "")
                .unwrap();
        crate::gpu::pipelines::validate(&display).unwrap();
    }
}
