//! Runs the shader's sampling functions (`shaders/harness/sampling.wgsl`):
//! environment sampling and its pdf, the environment lookup, BSDF sampling
//! and evaluation, and the MIS weights, on inputs given from the CPU. The
//! chi² and stability tests feed the GPU's own samples and densities to
//! the same checks as the CPU twins (`env_sampling`, `bsdf`, `mis`).

use super::dispatch;
use crate::gpu::context::GpuContext;
use crate::gpu::features::{Feature, FeatureSet};
use crate::gpu::pipelines::{
    buffer_entry, compute_pipeline, entry, float_texture, storage, uniform, upload_rgba16f,
};
use crate::gpu::shader_source::Program;
use anyhow::Result;
use bytemuck::{Pod, Zeroable};
use glam::{Vec2, Vec3};
use marbre_core::bsdf::{BsdfEval, BsdfSample, Surface};
use marbre_core::env_sampling::EnvDistribution;
use marbre_core::envmap::EnvImage;
use marbre_core::scene::Strategy;
use wgpu::util::DeviceExt;

/// `SamplingFrame` in the shader.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable, Default)]
struct SamplingFrame {
    env_constant: [f32; 3],
    env_intensity: f32,
    env_distribution_size: [u32; 2],
    env_rotation: f32,
    env_kind: u32,
    strategy: u32,
    mode: u32,
    count: u32,
    alpha: f32,
    diffuse: [f32; 3],
    mirror: f32,
    specular: [f32; 3],
    /// 1: the surface samples its diffuse lobe uniformly.
    uniform_diffuse: u32,
    normal: [f32; 3],
    _pad1: f32,
    wo: [f32; 3],
    _pad2: f32,
    diffuse_transmission: [f32; 3],
    _pad3: f32,
}

/// What the harness runs (the shader's `MODE_*`).
#[derive(Debug, Clone, Copy)]
enum Mode {
    EnvSample = 0,
    EnvPdf = 1,
    EnvRadiance = 2,
    BsdfSample = 3,
    BsdfEval = 4,
    Mis = 5,
}

/// The BSDF a run samples or evaluates: a surface seen along `wo` about
/// the shading normal `n`.
#[derive(Debug, Clone, Copy)]
pub struct BsdfSetup {
    pub surface: Surface,
    pub n: Vec3,
    pub wo: Vec3,
}

/// `mis.wgsl`'s weights for one pair of densities (a: light, b: BSDF).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MisWeights {
    /// `mis_heuristic(a, b)` and `mis_heuristic(b, a)`.
    pub heuristic: [f32; 2],
    /// `light_sample_weight(a, b)`.
    pub light: f32,
    /// `bsdf_sample_weight(b, a)`.
    pub bsdf: f32,
}

/// A compiled harness bound to one environment map (a black texel for the
/// BSDF and MIS modes), looked up through a sampler with `filter`, repeat
/// in u and clamped in v as the renderer's.
pub struct SamplingHarness {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    env_view: wgpu::TextureView,
    env_sampler: wgpu::Sampler,
    distribution: wgpu::Buffer,
    distribution_size: [u32; 2],
}

impl SamplingHarness {
    pub fn new(ctx: &GpuContext, env: &EnvImage, filter: wgpu::FilterMode) -> Result<Self> {
        let device = &ctx.device;
        let (pipeline, layout) = compute_pipeline(
            device,
            Program::SamplingHarness,
            &FeatureSet([Feature::EnvMap].into_iter().collect()),
            &[
                entry(0, uniform()),
                entry(1, storage(true)),
                entry(2, storage(false)),
                entry(3, float_texture(true)),
                entry(
                    4,
                    wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                ),
                entry(11, storage(true)),
            ],
            "cs_evaluate",
        )?;
        let env_view = upload_rgba16f(
            ctx,
            "harness environment",
            (env.width, env.height),
            bytemuck::cast_slice(&env.to_rgba16f()),
        );
        let env_sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("harness environment"),
            address_mode_u: wgpu::AddressMode::Repeat,
            address_mode_v: wgpu::AddressMode::ClampToEdge,
            mag_filter: filter,
            min_filter: filter,
            ..Default::default()
        });
        let cdfs = EnvDistribution::new(env);
        let distribution = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("harness environment distribution"),
            contents: bytemuck::cast_slice(&cdfs.gpu_data()),
            usage: wgpu::BufferUsages::STORAGE,
        });
        Ok(Self {
            pipeline,
            layout,
            env_view,
            env_sampler,
            distribution,
            distribution_size: [cdfs.width, cdfs.height],
        })
    }

    /// A harness without an environment map, for the BSDF and MIS modes.
    pub fn without_env(ctx: &GpuContext) -> Result<Self> {
        Self::new(
            ctx,
            &EnvImage::constant(1, 1, [0.0; 3]),
            wgpu::FilterMode::Nearest,
        )
    }

    fn env_frame(&self, mode: Mode, rotation_degrees: f32) -> SamplingFrame {
        SamplingFrame {
            env_intensity: 1.0,
            env_distribution_size: self.distribution_size,
            env_rotation: rotation_degrees.to_radians(),
            env_kind: 2,
            mode: mode as u32,
            ..Default::default()
        }
    }

    fn bsdf_frame(mode: Mode, setup: &BsdfSetup) -> SamplingFrame {
        let s = &setup.surface;
        SamplingFrame {
            mode: mode as u32,
            alpha: s.alpha,
            diffuse: s.diffuse.into(),
            mirror: s.mirror,
            specular: s.specular.into(),
            uniform_diffuse: u32::from(s.uniform_diffuse),
            normal: setup.n.into(),
            wo: setup.wo.into(),
            diffuse_transmission: s.diffuse_transmission.into(),
            ..Default::default()
        }
    }

    /// `sample_env(u.x, u.y)` for each `u`: the direction and its pdf.
    pub fn env_samples(
        &self,
        ctx: &GpuContext,
        rotation_degrees: f32,
        u: &[Vec2],
    ) -> Result<Vec<(Vec3, f32)>> {
        let inputs: Vec<[f32; 4]> = u.iter().map(|u| [u.x, u.y, 0.0, 0.0]).collect();
        let frame = self.env_frame(Mode::EnvSample, rotation_degrees);
        Ok(self
            .run(ctx, frame, &inputs)?
            .iter()
            .map(|[a, _]| (Vec3::new(a[0], a[1], a[2]), a[3]))
            .collect())
    }

    /// `env_pdf(d)` and the lat-long uv `env_uv` gives the rotated `d`.
    pub fn env_pdfs(
        &self,
        ctx: &GpuContext,
        rotation_degrees: f32,
        directions: &[Vec3],
    ) -> Result<Vec<(f32, Vec2)>> {
        let frame = self.env_frame(Mode::EnvPdf, rotation_degrees);
        Ok(self
            .run(ctx, frame, &points(directions))?
            .iter()
            .map(|[a, _]| (a[0], Vec2::new(a[1], a[2])))
            .collect())
    }

    /// `environment(d)`: the map's radiance through the sampler.
    pub fn env_radiance(
        &self,
        ctx: &GpuContext,
        rotation_degrees: f32,
        directions: &[Vec3],
    ) -> Result<Vec<Vec3>> {
        let frame = self.env_frame(Mode::EnvRadiance, rotation_degrees);
        Ok(self
            .run(ctx, frame, &points(directions))?
            .iter()
            .map(|[a, _]| Vec3::new(a[0], a[1], a[2]))
            .collect())
    }

    /// `sample_bsdf_with(u)` for each `u`.
    pub fn bsdf_samples(
        &self,
        ctx: &GpuContext,
        setup: &BsdfSetup,
        u: &[[f32; 4]],
    ) -> Result<Vec<BsdfSample>> {
        let frame = Self::bsdf_frame(Mode::BsdfSample, setup);
        Ok(self
            .run(ctx, frame, u)?
            .iter()
            .map(|[a, b]| BsdfSample {
                wi: Vec3::new(a[0], a[1], a[2]),
                weight: Vec3::new(b[0], b[1], b[2]),
                valid: b[3] != 0.0,
                pdf: a[3],
            })
            .collect())
    }

    /// `eval_bsdf(wi)` for each direction.
    pub fn bsdf_evals(
        &self,
        ctx: &GpuContext,
        setup: &BsdfSetup,
        directions: &[Vec3],
    ) -> Result<Vec<BsdfEval>> {
        let frame = Self::bsdf_frame(Mode::BsdfEval, setup);
        Ok(self
            .run(ctx, frame, &points(directions))?
            .iter()
            .map(|[a, _]| BsdfEval {
                f_cos: Vec3::new(a[0], a[1], a[2]),
                pdf: a[3],
            })
            .collect())
    }

    /// The MIS weights of each (light pdf, BSDF pdf) pair under `strategy`.
    pub fn mis_weights(
        &self,
        ctx: &GpuContext,
        strategy: Strategy,
        pairs: &[(f32, f32)],
    ) -> Result<Vec<MisWeights>> {
        let frame = SamplingFrame {
            mode: Mode::Mis as u32,
            strategy: strategy.id(),
            ..Default::default()
        };
        let inputs: Vec<[f32; 4]> = pairs.iter().map(|&(a, b)| [a, b, 0.0, 0.0]).collect();
        Ok(self
            .run(ctx, frame, &inputs)?
            .iter()
            .map(|[a, _]| MisWeights {
                heuristic: [a[0], a[1]],
                light: a[2],
                bsdf: a[3],
            })
            .collect())
    }

    /// One dispatch over `inputs`: two vec4 of results each.
    fn run(
        &self,
        ctx: &GpuContext,
        mut frame: SamplingFrame,
        inputs: &[[f32; 4]],
    ) -> Result<Vec<[[f32; 4]; 2]>> {
        if inputs.is_empty() {
            return Ok(Vec::new());
        }
        frame.count = inputs.len() as u32;
        let device = &ctx.device;
        let init =
            |label: &str, contents: &[u8], usage| dispatch::upload(ctx, label, contents, usage);
        let frame_buffer = init(
            "sampling frame",
            bytemuck::bytes_of(&frame),
            wgpu::BufferUsages::UNIFORM,
        )?;
        let input_buffer = init(
            "sampling inputs",
            bytemuck::cast_slice(inputs),
            wgpu::BufferUsages::STORAGE,
        )?;
        let output_buffer = dispatch::output(ctx, "sampling results", (inputs.len() * 32) as u64)?;
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("sampling harness"),
            layout: &self.layout,
            entries: &[
                buffer_entry(0, &frame_buffer),
                buffer_entry(1, &input_buffer),
                buffer_entry(2, &output_buffer),
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: wgpu::BindingResource::TextureView(&self.env_view),
                },
                wgpu::BindGroupEntry {
                    binding: 4,
                    resource: wgpu::BindingResource::Sampler(&self.env_sampler),
                },
                buffer_entry(11, &self.distribution),
            ],
        });
        let mut encoder = device.create_command_encoder(&Default::default());
        let groups = ((inputs.len() as u32).div_ceil(64), 1);
        dispatch::record(ctx, &mut encoder, &self.pipeline, &bind_group, groups)?;
        dispatch::read_back(ctx, encoder, &output_buffer)
    }
}

fn points(directions: &[Vec3]) -> Vec<[f32; 4]> {
    directions.iter().map(|d| [d.x, d.y, d.z, 0.0]).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The harness frame has its WGSL twin's layout, as naga lays it out.
    #[test]
    fn the_frame_has_its_wgsl_twins_layout() {
        use crate::gpu::twin_layout::{module_of, twin_layout};
        let module = &module_of(
            Program::SamplingHarness,
            &FeatureSet([Feature::EnvMap].into_iter().collect()),
            "",
        );
        twin_layout!(
            module,
            SamplingFrame,
            [
                env_constant,
                env_intensity,
                env_distribution_size,
                env_rotation,
                env_kind,
                strategy,
                mode,
                count,
                alpha,
                diffuse,
                mirror,
                specular,
                uniform_diffuse,
                normal,
                wo,
                diffuse_transmission
            ]
        );
    }
}
