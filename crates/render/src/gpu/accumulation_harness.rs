//! Runs the trace pass's accumulation update (`shaders/accumulate.wgsl`)
//! over long streams of frames on the GPU, beside an uncompensated running
//! mean and a plain f32 sum, and the CPU twins of the streams, for the
//! long-accumulation tests: 1e5 frames and more in one dispatch, where the
//! renderer would need minutes.

use super::context::GpuContext;
use super::features::FeatureSet;
use super::pipelines::{buffer_entry, compute_pipeline, entry, storage, uniform};
use super::readback::read_buffer;
use super::shader_source::Program;
use anyhow::Result;
use bytemuck::{Pod, Zeroable};
use glam::UVec3;
use marbre_core::noise::hash::pcg3d;
use wgpu::util::DeviceExt;

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct HarnessUniform {
    first_frame: u32,
    frames: u32,
    spp: u32,
    one: f32,
}

/// A stream's seed and state, as `Stream` in the shader.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct StreamState {
    seed: u32,
    padding: [u32; 3],
    values: [f32; 4],
}

/// Frames per dispatch: under lavapipe's 65535 passes of a shader's loops.
const CHUNK: u32 = 50_000;

/// One stream's mean after all its frames, three ways.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LongAccumulation {
    /// The trace pass's Kahan-compensated running mean.
    pub compensated: f32,
    /// A running mean without compensation.
    pub plain: f32,
    /// A plain f32 sum of the frames, divided by their count.
    pub summed: f32,
}

/// The value of frame `frame_index` of stream `seed`: an HDR pixel, mostly
/// 0.01 and one frame in ~1000 (16777 in 2^24) a firefly of 1000. The twin
/// of `frame_value` in `shaders/accumulation_harness.wgsl`.
pub fn frame_value(seed: u32, frame_index: u32) -> f32 {
    let h = pcg3d(UVec3::new(seed, frame_index, 0)).x >> 8;
    if h < 16777 { 1000.0 } else { 0.01 }
}

/// The exact mean of a stream's first `frames` frames, in f64 (every frame
/// weighs the same).
pub fn exact_mean(seed: u32, frames: u32) -> f64 {
    (0..frames)
        .map(|f| f64::from(frame_value(seed, f)))
        .sum::<f64>()
        / f64::from(frames)
}

/// The CPU twin: the same three accumulations of stream `seed` in f32, in
/// the shader's order of operations.
pub fn accumulate_on_cpu(seed: u32, frames: u32, spp: u32) -> LongAccumulation {
    let (mut mean, mut compensation, mut plain, mut sum) = (0.0f32, 0.0f32, 0.0f32, 0.0f32);
    for f in 0..frames {
        let x = frame_value(seed, f);
        let w = spp as f32 / ((f * spp) as f32 + spp as f32);
        let y = (x - mean) * w - compensation;
        let t = mean + y;
        compensation = (t - mean) - y;
        mean = t;
        plain += (x - plain) * w;
        sum += x;
    }
    LongAccumulation {
        compensated: mean,
        plain,
        summed: sum / frames as f32,
    }
}

/// Accumulates `frames` frames of `spp` samples for each stream seed, in
/// chunks of [`CHUNK`] frames (one dispatch each, in one submission).
pub fn run(
    ctx: &GpuContext,
    seeds: &[u32],
    frames: u32,
    spp: u32,
) -> Result<Vec<LongAccumulation>> {
    let device = &ctx.device;
    let (pipeline, layout) = compute_pipeline(
        device,
        Program::AccumulationHarness,
        &FeatureSet::default(),
        &[entry(0, uniform()), entry(1, storage(false))],
        "cs_accumulate",
    )?;
    let states: Vec<StreamState> = seeds
        .iter()
        .map(|&seed| StreamState {
            seed,
            padding: [0; 3],
            values: [0.0; 4],
        })
        .collect();
    let streams = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("streams"),
        contents: bytemuck::cast_slice(&states),
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
    });
    let mut encoder = device.create_command_encoder(&Default::default());
    for first_frame in (0..frames).step_by(CHUNK as usize) {
        let chunk = HarnessUniform {
            first_frame,
            frames: CHUNK.min(frames - first_frame),
            spp,
            one: 1.0,
        };
        let uniform_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("accumulation harness"),
            contents: bytemuck::bytes_of(&chunk),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("accumulation harness"),
            layout: &layout,
            entries: &[buffer_entry(0, &uniform_buffer), buffer_entry(1, &streams)],
        });
        let mut pass = encoder.begin_compute_pass(&Default::default());
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &bind_group, &[]);
        pass.dispatch_workgroups((seeds.len() as u32).div_ceil(64), 1, 1);
    }
    let size = std::mem::size_of_val(states.as_slice()) as u64;
    let readback = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("streams readback"),
        size,
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    encoder.copy_buffer_to_buffer(&streams, 0, &readback, 0, size);
    ctx.queue.submit([encoder.finish()]);
    let bytes = read_buffer(device, &readback)?;
    let states: &[StreamState] = bytemuck::cast_slice(&bytes);
    Ok(states
        .iter()
        .map(|s| LongAccumulation {
            compensated: s.values[0],
            plain: s.values[2],
            summed: s.values[3] / frames as f32,
        })
        .collect())
}
