//! The denoised preview: an edge-avoiding à-trous wavelet filter (Dammertz
//! et al. 2010) guided by the first hit's albedo and shading normal, with
//! SVGF's luminance-variance weight (Schied et al. 2017), run as a compute
//! pass (`denoise.wgsl`), and its CPU twin ([`denoise_cpu`]) for tests.
//!
//! It is the fallback where Intel Open Image Denoise's library is not
//! found (`crate::denoiser`), and the choice where a filter on the GPU,
//! with no read-back, matters more than OIDN's quality: it needs nothing
//! but wgpu and runs wherever the renderer does.
//!
//! The input is the accumulated mean with the variance of each pixel's
//! luminance in its alpha ([`filter_input`]: from the accumulation's spread
//! of frame means when there are two frames or more, else estimated over
//! the pixel's 3 × 3 neighbourhood); the guides are the albedo and normal
//! views (`scene::View`) accumulated over the same pixels
//! (`session::trace_guides`). Saved EXRs stay the raw accumulation unless
//! asked: the filter is biased (it trades noise for blur).

use crate::gpu::context::GpuContext;
use crate::gpu::features::FeatureSet;
use crate::gpu::pipelines::{checked, entry, float_texture, shader_module, uniform};
use crate::gpu::readback::read_texture;
use crate::gpu::shader_source::Program;
use anyhow::{Result, ensure};
use wgpu::util::DeviceExt;

/// The shader's workgroup (8 × 8 pixels).
const WORKGROUP: u32 = 8;

/// See `denoise.wgsl`: the clamps that keep every sum finite.
const COLOUR_LIMIT: f32 = 1e18;
const VARIANCE_LIMIT: f32 = 1e30;
const GUIDE_LIMIT: f32 = 16.0;
const LUMINANCE_EPSILON: f32 = 1e-6;

/// The filter's parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DenoiseSettings {
    /// Passes, the n-th with taps 2ⁿ pixels apart: five reach 62 pixels
    /// out, as in SVGF.
    pub iterations: u32,
    /// SVGF's σ_l: how many standard deviations of a pixel's noise a
    /// neighbour's luminance may differ by before it counts for little.
    pub sigma_luminance: f32,
    /// Dammertz's σ_n, on the normal guide as encoded (0.5 + 0.5·n):
    /// 0.2 weighs normals 23° apart by 1/e.
    pub sigma_normal: f32,
    /// Dammertz's σ for the albedo guide (reflectances in [0, 1], plus
    /// emission, so an emitter's edge stops the filter).
    pub sigma_albedo: f32,
}

impl Default for DenoiseSettings {
    fn default() -> Self {
        Self {
            iterations: 5,
            sigma_luminance: 4.0,
            sigma_normal: 0.2,
            sigma_albedo: 0.2,
        }
    }
}

/// An accumulation to filter and its guides, row by row, all of `size`.
#[derive(Debug, Clone, Copy)]
pub struct DenoiseImage<'a> {
    pub size: (u32, u32),
    /// The accumulated mean (linear radiance).
    pub mean: &'a [[f32; 4]],
    /// The spread of its frames' means (`gpu::accumulation`).
    pub spread: &'a [[f32; 4]],
    /// Frames averaged.
    pub frames: u32,
    /// The first hit's albedo (the albedo view).
    pub albedo: &'a [[f32; 4]],
    /// The first hit's shading normal as 0.5 + 0.5·n (the normal view).
    pub normal: &'a [[f32; 4]],
}

impl DenoiseImage<'_> {
    fn check(&self) -> Result<()> {
        let n = self.size.0 as usize * self.size.1 as usize;
        let lengths = [self.mean, self.spread, self.albedo, self.normal].map(<[_]>::len);
        ensure!(
            lengths.iter().all(|&l| l == n),
            "denoise: a {}×{} image needs {n} pixels of mean, spread, albedo and normal, got {lengths:?}",
            self.size.0,
            self.size.1,
        );
        Ok(())
    }
}

/// Rec. 709 luminance, as `common.wgsl` has it.
fn luminance(c: [f32; 3]) -> f32 {
    0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
}

/// The filter's input, the CPU twin of `cs_denoise_input`: the mean with
/// the variance of its luminance in alpha, from the spread of the frames'
/// means (`spread / (F − 1)` per channel, see [`crate::gpu::error_meter`]; the
/// channels taken as fully correlated) with two frames or more, else from
/// the luminances of the pixel's 3 × 3 neighbourhood.
pub fn filter_input(image: &DenoiseImage<'_>) -> Vec<[f32; 4]> {
    let (w, h) = (image.size.0 as i32, image.size.1 as i32);
    let index = |x: i32, y: i32| (y * w + x) as usize;
    let mut out = Vec::with_capacity((w * h) as usize);
    for y in 0..h {
        for x in 0..w {
            let variance = if image.frames >= 2 {
                let spread = clamped(image.spread[index(x, y)], VARIANCE_LIMIT)
                    .map(|v| v.clamp(0.0, VARIANCE_LIMIT));
                let l = luminance(spread.map(|v| (v / (image.frames - 1) as f32).sqrt()));
                l * l
            } else {
                let (mut sum, mut squares, mut n) = (0.0f32, 0.0f32, 0.0f32);
                for dy in -1..=1 {
                    for dx in -1..=1 {
                        let (qx, qy) = (x + dx, y + dy);
                        if qx >= 0 && qy >= 0 && qx < w && qy < h {
                            let l = luminance(clamped(image.mean[index(qx, qy)], COLOUR_LIMIT));
                            sum += l;
                            squares += l * l;
                            n += 1.0;
                        }
                    }
                }
                let mean = sum / n;
                (squares / n - mean * mean).max(0.0)
            };
            let m = clamped(image.mean[index(x, y)], COLOUR_LIMIT);
            out.push([m[0], m[1], m[2], variance]);
        }
    }
    out
}

fn finite_or_zero(x: f32) -> f32 {
    if x.is_finite() { x } else { 0.0 }
}

fn clamped(v: [f32; 4], limit: f32) -> [f32; 3] {
    [0, 1, 2].map(|c| finite_or_zero(v[c]).clamp(-limit, limit))
}

fn colour_at(image: &[[f32; 4]], i: usize) -> ([f32; 3], f32) {
    (
        clamped(image[i], COLOUR_LIMIT),
        finite_or_zero(image[i][3]).clamp(0.0, VARIANCE_LIMIT),
    )
}

fn b3(offset: i32) -> f32 {
    match offset.abs() {
        0 => 0.375,
        1 => 0.25,
        _ => 0.0625,
    }
}

fn guide_weight(a: [f32; 3], b: [f32; 3], sigma: f32) -> f32 {
    let d = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    (-(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) / (sigma * sigma)).exp()
}

/// One iteration with taps `step` pixels apart over `colour` (with its
/// variance in alpha): the CPU twin of `cs_denoise`, in the same order of
/// operations.
fn iterate(
    image: &DenoiseImage<'_>,
    colour: &[[f32; 4]],
    step: i32,
    settings: &DenoiseSettings,
) -> Vec<[f32; 4]> {
    let (w, h) = (image.size.0 as i32, image.size.1 as i32);
    let index = |x: i32, y: i32| (y * w + x) as usize;
    let inside = |x: i32, y: i32| x >= 0 && y >= 0 && x < w && y < h;
    let mut out = Vec::with_capacity((w * h) as usize);
    for y in 0..h {
        for x in 0..w {
            let (centre, _) = colour_at(colour, index(x, y));
            let albedo_p = clamped(image.albedo[index(x, y)], GUIDE_LIMIT);
            let normal_p = clamped(image.normal[index(x, y)], GUIDE_LIMIT);
            let luminance_p = luminance(centre);
            let (mut sum, mut weight) = (0.0f32, 0.0f32);
            for dy in -1..=1 {
                for dx in -1..=1 {
                    if inside(x + dx, y + dy) {
                        let wv = if dx == 0 { 1.0 } else { 0.5 } * if dy == 0 { 1.0 } else { 0.5 };
                        sum += wv * colour_at(colour, index(x + dx, y + dy)).1;
                        weight += wv;
                    }
                }
            }
            let scale = settings.sigma_luminance * (sum / weight).sqrt() + LUMINANCE_EPSILON;
            let (mut weight_sum, mut difference, mut variance_sum) = (0.0f32, [0.0f32; 3], 0.0f32);
            for dy in -2..=2 {
                for dx in -2..=2 {
                    let (qx, qy) = (x + dx * step, y + dy * step);
                    if !inside(qx, qy) {
                        continue;
                    }
                    let q = index(qx, qy);
                    let (colour, variance) = colour_at(colour, q);
                    let w_luminance = (-(luminance(colour) - luminance_p).abs() / scale).exp();
                    let w_albedo = guide_weight(
                        clamped(image.albedo[q], GUIDE_LIMIT),
                        albedo_p,
                        settings.sigma_albedo,
                    );
                    let w_normal = guide_weight(
                        clamped(image.normal[q], GUIDE_LIMIT),
                        normal_p,
                        settings.sigma_normal,
                    );
                    let wq = b3(dx) * b3(dy) * w_luminance * w_albedo * w_normal;
                    weight_sum += wq;
                    for c in 0..3 {
                        difference[c] += wq * (colour[c] - centre[c]);
                    }
                    variance_sum += wq * wq * variance;
                }
            }
            out.push([
                centre[0] + difference[0] / weight_sum,
                centre[1] + difference[1] / weight_sum,
                centre[2] + difference[2] / weight_sum,
                variance_sum / (weight_sum * weight_sum),
            ]);
        }
    }
    out
}

/// The filtered image on the CPU (alpha 1): the reference the GPU pass is
/// tested against.
pub fn denoise_cpu(image: &DenoiseImage<'_>, settings: &DenoiseSettings) -> Result<Vec<[f32; 4]>> {
    image.check()?;
    let mut colour = filter_input(image);
    for i in 0..settings.iterations {
        colour = iterate(image, &colour, 1 << i, settings);
    }
    Ok(opaque(colour))
}

fn opaque(mut image: Vec<[f32; 4]>) -> Vec<[f32; 4]> {
    for p in &mut image {
        p[3] = 1.0;
    }
    image
}

/// `DenoiseParams` in `denoise.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct DenoiseParams {
    size: [u32; 2],
    step: u32,
    frames: u32,
    sigma_luminance: f32,
    sigma_normal: f32,
    sigma_albedo: f32,
    pad: f32,
}

/// What the GPU filter reads: the accumulation's latest mean and spread,
/// the guides, over the shown region of `size` (from the top-left corner).
pub struct DenoiseSources<'a> {
    pub mean: &'a wgpu::TextureView,
    pub spread: &'a wgpu::TextureView,
    pub albedo: &'a wgpu::TextureView,
    pub normal: &'a wgpu::TextureView,
    pub frames: u32,
    pub size: (u32, u32),
}

/// Two images the iterations ping-pong between, of one size.
struct Targets {
    size: (u32, u32),
    textures: [wgpu::Texture; 2],
    views: [wgpu::TextureView; 2],
}

impl Targets {
    fn new(device: &wgpu::Device, size: (u32, u32)) -> Self {
        let usage = wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::STORAGE_BINDING
            | wgpu::TextureUsages::COPY_SRC;
        let textures = [0, 1].map(|i| {
            device.create_texture(&texture_descriptor(&format!("denoised {i}"), size, usage))
        });
        let views = textures
            .each_ref()
            .map(|t| t.create_view(&Default::default()));
        Self {
            size,
            textures,
            views,
        }
    }
}

/// The filter's compute pipelines (input, iteration), its targets and its
/// parameter buffers, kept between frames.
pub struct Denoiser {
    input: wgpu::ComputePipeline,
    iteration: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    targets: Option<Targets>,
    /// One per pass (the input's, then each iteration's): a submit holds
    /// them all.
    params: Vec<wgpu::Buffer>,
}

impl Denoiser {
    pub fn new(device: &wgpu::Device) -> Result<Self> {
        let entries = [
            entry(0, uniform()),
            entry(1, float_texture(false)),
            entry(2, float_texture(false)),
            entry(3, float_texture(false)),
            entry(
                4,
                wgpu::BindingType::StorageTexture {
                    access: wgpu::StorageTextureAccess::WriteOnly,
                    format: wgpu::TextureFormat::Rgba32Float,
                    view_dimension: wgpu::TextureViewDimension::D2,
                },
            ),
            entry(5, float_texture(false)),
        ];
        let module = shader_module(device, Program::Denoise, &FeatureSet::default(), "")?;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("denoise"),
            entries: &entries,
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("denoise"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = |entry_point: &str| {
            checked(device, &format!("denoise pipeline {entry_point}"), || {
                device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                    label: Some(entry_point),
                    layout: Some(&pipeline_layout),
                    module: &module,
                    entry_point: Some(entry_point),
                    compilation_options: Default::default(),
                    cache: None,
                })
            })
        };
        Ok(Self {
            input: pipeline("cs_denoise_input")?,
            iteration: pipeline("cs_denoise")?,
            layout,
            targets: None,
            params: Vec::new(),
        })
    }

    /// Records the filter of `sources` into `encoder`; the result is
    /// [`Self::output`] once submitted.
    pub fn record(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        sources: &DenoiseSources<'_>,
        settings: &DenoiseSettings,
    ) {
        let size = (sources.size.0.max(1), sources.size.1.max(1));
        let passes = settings.iterations as usize + 1;
        while self.params.len() < passes {
            self.params
                .push(ctx.device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("denoise parameters"),
                    size: std::mem::size_of::<DenoiseParams>() as u64,
                    usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                }));
        }
        let targets = match &mut self.targets {
            Some(t) if t.size == size => t,
            slot => slot.insert(Targets::new(&ctx.device, size)),
        };
        for pass_index in 0..passes {
            // Pass 0 reads the mean and writes target 0; iteration i reads
            // target i % 2 and writes the other.
            let (read, write, step) = if pass_index == 0 {
                (sources.mean, &targets.views[0], 0)
            } else {
                let i = pass_index - 1;
                (&targets.views[i % 2], &targets.views[1 - i % 2], 1u32 << i)
            };
            let params = DenoiseParams {
                size: [size.0, size.1],
                step,
                frames: sources.frames,
                sigma_luminance: settings.sigma_luminance,
                sigma_normal: settings.sigma_normal,
                sigma_albedo: settings.sigma_albedo,
                pad: 0.0,
            };
            ctx.queue
                .write_buffer(&self.params[pass_index], 0, bytemuck::bytes_of(&params));
            let texture = |binding, view| wgpu::BindGroupEntry {
                binding,
                resource: wgpu::BindingResource::TextureView(view),
            };
            let bind_group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("denoise"),
                layout: &self.layout,
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: self.params[pass_index].as_entire_binding(),
                    },
                    texture(1, read),
                    texture(2, sources.albedo),
                    texture(3, sources.normal),
                    texture(4, write),
                    texture(5, sources.spread),
                ],
            });
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("denoise"),
                timestamp_writes: None,
            });
            pass.set_pipeline(if pass_index == 0 {
                &self.input
            } else {
                &self.iteration
            });
            pass.set_bind_group(0, &bind_group, &[]);
            pass.dispatch_workgroups(size.0.div_ceil(WORKGROUP), size.1.div_ceil(WORKGROUP), 1);
        }
    }

    /// The texture and view the last [`Self::record`] with `settings`
    /// filters into (its alpha holds the variance, not coverage).
    pub fn output(
        &self,
        settings: &DenoiseSettings,
    ) -> Option<(&wgpu::Texture, &wgpu::TextureView)> {
        let i = (settings.iterations % 2) as usize;
        self.targets.as_ref().map(|t| (&t.textures[i], &t.views[i]))
    }

    /// Filters `image` on the GPU and reads the result back (alpha 1),
    /// waiting for it: for tests.
    pub fn denoise(
        &mut self,
        ctx: &GpuContext,
        image: &DenoiseImage<'_>,
        settings: &DenoiseSettings,
    ) -> Result<Vec<[f32; 4]>> {
        image.check()?;
        let size = image.size;
        let upload = |label: &str, pixels: &[[f32; 4]]| {
            ctx.device
                .create_texture_with_data(
                    &ctx.queue,
                    &texture_descriptor(label, size, wgpu::TextureUsages::TEXTURE_BINDING),
                    wgpu::util::TextureDataOrder::LayerMajor,
                    bytemuck::cast_slice(pixels),
                )
                .create_view(&Default::default())
        };
        let mean = upload("denoise mean", image.mean);
        let spread = upload("denoise spread", image.spread);
        let albedo = upload("denoise albedo", image.albedo);
        let normal = upload("denoise normal", image.normal);
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        let sources = DenoiseSources {
            mean: &mean,
            spread: &spread,
            albedo: &albedo,
            normal: &normal,
            frames: image.frames,
            size,
        };
        self.record(ctx, &mut encoder, &sources, settings);
        ctx.queue.submit([encoder.finish()]);
        let (texture, _) = self
            .output(settings)
            .ok_or_else(|| anyhow::anyhow!("denoise: no output was recorded"))?;
        let bytes = read_texture(&ctx.device, &ctx.queue, texture, 16)?;
        Ok(opaque(bytemuck::cast_slice(&bytes).to_vec()))
    }
}

fn texture_descriptor(
    label: &str,
    size: (u32, u32),
    usage: wgpu::TextureUsages,
) -> wgpu::TextureDescriptor<'_> {
    wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width: size.0.max(1),
            height: size.1.max(1),
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Rgba32Float,
        usage,
        view_formats: &[],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The filter's parameters have its WGSL twin's layout, as naga lays it out.
    #[test]
    fn the_parameters_have_their_wgsl_twins_layout() {
        use crate::gpu::twin_layout::{module_of, twin_layout};
        let module = &module_of(Program::Denoise, &FeatureSet::default(), "");
        twin_layout!(
            module,
            DenoiseParams,
            [
                size,
                step,
                frames,
                sigma_luminance,
                sigma_normal,
                sigma_albedo,
                pad
            ]
        );
    }

    fn flat(n: usize, v: [f32; 4]) -> Vec<[f32; 4]> {
        vec![v; n]
    }

    /// A noisy grey level of 0.5 ± 0.2, a hash for noise, deterministic.
    fn noisy(n: usize) -> Vec<[f32; 4]> {
        (0..n)
            .map(|i| {
                let h = ((i as u32).wrapping_mul(2_654_435_761) >> 8) as f32 / 16_777_216.0;
                let v = 0.5 + (h - 0.5) * 0.4;
                [v, v, v, 1.0]
            })
            .collect()
    }

    /// An image of `mean` whose frames spread by `spread` over 4 frames.
    fn image<'a>(
        size: (u32, u32),
        mean: &'a [[f32; 4]],
        spread: &'a [[f32; 4]],
        albedo: &'a [[f32; 4]],
        normal: &'a [[f32; 4]],
    ) -> DenoiseImage<'a> {
        DenoiseImage {
            size,
            mean,
            spread,
            frames: 4,
            albedo,
            normal,
        }
    }

    #[test]
    fn a_constant_image_stays_exactly_constant() {
        let size = (13, 9);
        let n = 13 * 9;
        let mean = flat(n, [0.3, 1.7, 12.0, 1.0]);
        let spread = flat(n, [0.2; 4]);
        // Guides that vary, so the weights differ from tap to tap.
        let albedo: Vec<[f32; 4]> = (0..n)
            .map(|i| [(i % 7) as f32 / 7.0, 0.5, 0.2, 1.0])
            .collect();
        let normal: Vec<[f32; 4]> = (0..n)
            .map(|i| [0.5, (i % 3) as f32 / 3.0, 1.0, 1.0])
            .collect();
        for frames in [1, 4] {
            let image = DenoiseImage {
                frames,
                ..image(size, &mean, &spread, &albedo, &normal)
            };
            for p in denoise_cpu(&image, &DenoiseSettings::default()).unwrap() {
                assert_eq!(p, [0.3, 1.7, 12.0, 1.0]);
            }
        }
    }

    #[test]
    fn degenerate_input_never_makes_nan_or_inf() {
        let size = (8, 8);
        let bad = [
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            -5.0,
            f32::MAX,
            -f32::MAX,
            1e30,
            0.0,
        ];
        let mean: Vec<[f32; 4]> = (0..64)
            .map(|i| [bad[i % 8], bad[(i / 8) % 8], 0.5, 1.0])
            .collect();
        let spread: Vec<[f32; 4]> = (0..64).map(|i| [bad[(i + 3) % 8]; 4]).collect();
        // Zero normals and black albedo, and non-finite guides.
        let albedo: Vec<[f32; 4]> = (0..64).map(|i| [0.0, bad[i % 8], 0.0, 0.0]).collect();
        let normal: Vec<[f32; 4]> = (0..64).map(|i| [bad[(i + 1) % 8], 0.0, 0.0, 0.0]).collect();
        for frames in [1, 2, 4] {
            let image = DenoiseImage {
                frames,
                ..image(size, &mean, &spread, &albedo, &normal)
            };
            for p in denoise_cpu(&image, &DenoiseSettings::default()).unwrap() {
                assert!(p.iter().all(|v| v.is_finite()), "{frames} frames: {p:?}");
            }
        }
    }

    /// Where the guides draw an edge (two albedos), the filter does not
    /// blend across it: each side keeps its own level.
    #[test]
    fn an_albedo_edge_is_kept() {
        let size = (16, 16);
        let n = 256;
        let left = |i: usize| i % 16 < 8;
        let mean: Vec<[f32; 4]> = noisy(n)
            .into_iter()
            .enumerate()
            .map(|(i, p)| {
                if left(i) {
                    p
                } else {
                    [p[0] * 0.1, p[1] * 0.1, p[2] * 0.1, 1.0]
                }
            })
            .collect();
        let spread: Vec<[f32; 4]> = (0..n)
            .map(|i| [if left(i) { 0.03 } else { 3e-4 }; 4])
            .collect();
        let albedo: Vec<[f32; 4]> = (0..n)
            .map(|i| if left(i) { [0.8; 4] } else { [0.08; 4] })
            .collect();
        let normal = flat(n, [0.5, 1.0, 0.5, 1.0]);
        let out = denoise_cpu(
            &image(size, &mean, &spread, &albedo, &normal),
            &DenoiseSettings::default(),
        )
        .unwrap();
        for (i, p) in out.iter().enumerate() {
            let expected = if left(i) { 0.5 } else { 0.05 };
            assert!(
                (p[0] - expected).abs() < 0.25 * expected,
                "pixel {i}: {p:?}"
            );
        }
    }

    /// Noise about a flat level shrinks: the spread of the filtered image
    /// is a fraction of the input's.
    #[test]
    fn noise_on_a_flat_surface_shrinks() {
        let size = (32, 32);
        let n = 1024;
        let mean = noisy(n);
        // The spread the noise has: (0.4²/12)·3 over 4 frames.
        let spread = flat(n, [0.04; 4]);
        let guide = flat(n, [0.5; 4]);
        let out = denoise_cpu(
            &image(size, &mean, &spread, &guide, &guide),
            &DenoiseSettings::default(),
        )
        .unwrap();
        let rms = |img: &[[f32; 4]]| {
            (img.iter().map(|p| (p[0] - 0.5).powi(2)).sum::<f32>() / img.len() as f32).sqrt()
        };
        assert!(
            rms(&out) < 0.25 * rms(&mean),
            "{} vs {}",
            rms(&out),
            rms(&mean)
        );
    }

    #[test]
    fn the_input_takes_the_variance_of_the_mean_from_the_spread() {
        // spread 0.09 per channel over 4 frames: variance of the mean 0.03,
        // σ √0.03 in every channel, luminance σ the same (weights sum to 1).
        let (mean, spread, guide) = ([[1.0, 2.0, 3.0, 1.0]], [[0.09; 4]], [[0.0; 4]]);
        let out = filter_input(&image((1, 1), &mean, &spread, &guide, &guide));
        assert!((out[0][3] - 0.03).abs() < 1e-6, "{out:?}");
        assert_eq!(&out[0][..3], &[1.0, 2.0, 3.0]);
    }

    #[test]
    fn the_input_of_one_frame_takes_the_variance_of_the_neighbourhood() {
        // A 2×1 image of luminances 0 and 1: each pixel sees both, variance 1/4.
        let mean = [[0.0; 4], [1.0, 1.0, 1.0, 1.0]];
        let (spread, guide) = ([[0.0; 4]; 2], [[0.0; 4]; 2]);
        let one_frame = DenoiseImage {
            frames: 1,
            ..image((2, 1), &mean, &spread, &guide, &guide)
        };
        let out = filter_input(&one_frame);
        assert!(
            (out[0][3] - 0.25).abs() < 1e-6 && (out[1][3] - 0.25).abs() < 1e-6,
            "{out:?}"
        );
    }

    #[test]
    fn mismatched_sizes_are_an_error_not_a_panic() {
        let one = [[0.0f32; 4]];
        let e = denoise_cpu(
            &image((2, 2), &one, &one, &one, &one),
            &DenoiseSettings::default(),
        )
        .unwrap_err();
        assert!(e.to_string().contains("2×2"), "{e}");
    }
}
