//! Runs the shader's noise and mapping functions in a compute pass, so the
//! real WGSL can be checked against the CPU reference and queried from the
//! command line (`marbre noise`).

use super::context::GpuContext;
use super::features::FeatureSet;
use super::pipelines::{checked, entry, permutation_table, shader_module, storage, uniform};
use super::readback::read_buffer;
use super::scene_gpu::NoiseParamsGpu;
use super::shader_source::Program;
use crate::noise::NoiseSettings;
use anyhow::Result;
use bytemuck::{Pod, Zeroable};
use glam::{Vec2, Vec3};
use wgpu::util::DeviceExt;

/// What the harness evaluates at each point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Evaluate {
    Noise,
    Fbm,
    Turbulence,
    Marble {
        stripe_frequency: f32,
    },
    /// The lat-long mapping of a direction.
    EnvUv,
    /// The environment rotation applied to a direction, in radians.
    RotateY {
        angle: f32,
    },
}

impl Evaluate {
    fn mode_and_param(self) -> (u32, f32) {
        match self {
            Evaluate::Noise => (0, 0.0),
            Evaluate::Fbm => (1, 0.0),
            Evaluate::Turbulence => (2, 0.0),
            Evaluate::Marble { stripe_frequency } => (3, stripe_frequency),
            Evaluate::EnvUv => (4, 0.0),
            Evaluate::RotateY { angle } => (5, angle),
        }
    }
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct HarnessUniform {
    noise: NoiseParamsGpu,
    mode: u32,
    count: u32,
    param: f32,
    _pad1: f32,
}

/// Evaluates `what` at every point on the GPU; one vec4 of results each
/// (x for scalars, xy for uv, xyz for directions).
pub fn evaluate(
    ctx: &GpuContext,
    noise: &NoiseSettings,
    what: Evaluate,
    points: &[Vec3],
) -> Result<Vec<[f32; 4]>> {
    if points.is_empty() {
        return Ok(Vec::new());
    }
    let device = &ctx.device;
    let features = FeatureSet::for_noise(noise.kind, noise.hash);
    let module = shader_module(device, Program::NoiseHarness, &features)?;
    let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("noise harness"),
        entries: &[
            entry(0, uniform()),
            entry(1, storage(true)),
            entry(2, storage(false)),
            entry(6, uniform()),
        ],
    });
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("noise harness"),
        bind_group_layouts: &[Some(&layout)],
        immediate_size: 0,
    });
    let pipeline = checked(device, "noise harness pipeline", || {
        device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("noise harness"),
            layout: Some(&pipeline_layout),
            module: &module,
            entry_point: Some("cs_evaluate"),
            compilation_options: Default::default(),
            cache: None,
        })
    })?;
    let (mode, param) = what.mode_and_param();
    let params = HarnessUniform {
        noise: NoiseParamsGpu::new(noise, false),
        mode,
        count: points.len() as u32,
        param,
        _pad1: 0.0,
    };
    let init = |label: &str, contents: &[u8], usage| {
        device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some(label),
            contents,
            usage,
        })
    };
    let inputs: Vec<[f32; 4]> = points.iter().map(|p| [p.x, p.y, p.z, 0.0]).collect();
    let uniform_buffer = init(
        "harness",
        bytemuck::bytes_of(&params),
        wgpu::BufferUsages::UNIFORM,
    );
    let input_buffer = init(
        "points",
        bytemuck::cast_slice(&inputs),
        wgpu::BufferUsages::STORAGE,
    );
    let perm_buffer = init(
        "permutation",
        bytemuck::cast_slice(&permutation_table()),
        wgpu::BufferUsages::UNIFORM,
    );
    let size = (inputs.len() * 16) as u64;
    let output_buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("results"),
        size,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let readback = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("results readback"),
        size,
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("noise harness"),
        layout: &layout,
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: uniform_buffer.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: input_buffer.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 2,
                resource: output_buffer.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 6,
                resource: perm_buffer.as_entire_binding(),
            },
        ],
    });
    let mut encoder = device.create_command_encoder(&Default::default());
    {
        let mut pass = encoder.begin_compute_pass(&Default::default());
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &bind_group, &[]);
        pass.dispatch_workgroups((points.len() as u32).div_ceil(64), 1, 1);
    }
    encoder.copy_buffer_to_buffer(&output_buffer, 0, &readback, 0, size);
    ctx.queue.submit([encoder.finish()]);
    let bytes = read_buffer(device, &readback)?;
    Ok(bytemuck::cast_slice(&bytes).to_vec())
}

/// Scalar results (the x component).
pub fn evaluate_scalar(
    ctx: &GpuContext,
    noise: &NoiseSettings,
    what: Evaluate,
    points: &[Vec3],
) -> Result<Vec<f32>> {
    Ok(evaluate(ctx, noise, what, points)?
        .iter()
        .map(|r| r[0])
        .collect())
}

/// The GPU's lat-long uv for each direction.
pub fn env_uv(ctx: &GpuContext, directions: &[Vec3]) -> Result<Vec<Vec2>> {
    Ok(
        evaluate(ctx, &NoiseSettings::default(), Evaluate::EnvUv, directions)?
            .iter()
            .map(|r| Vec2::new(r[0], r[1]))
            .collect(),
    )
}
