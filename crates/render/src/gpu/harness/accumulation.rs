//! Runs the trace pass's accumulation update (`shaders/accumulation.wgsl`)
//! over long streams of frames on the GPU, beside an uncompensated running
//! mean and a plain f32 sum, and the CPU twins of the streams, for the
//! long-accumulation tests: 1e5 frames and more in one dispatch, where the
//! renderer would need minutes.

use super::dispatch;
use crate::gpu::context::GpuContext;
use crate::gpu::features::FeatureSet;
use crate::gpu::pipelines::{buffer_entry, compute_pipeline, entry, storage, uniform};
use crate::gpu::shader_source::Program;
use anyhow::Result;
use bytemuck::{Pod, Zeroable};
use glam::UVec3;
use marbre_core::noise::hash::pcg3d;

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct AccumulationHarness {
    first_frame: u32,
    frames: u32,
    spp: u32,
    one: f32,
}

/// A stream's seed and state, as `Stream` in the shader.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct Stream {
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
/// of `frame_value` in `shaders/harness/accumulation.wgsl`.
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
    let states: Vec<Stream> = seeds
        .iter()
        .map(|&seed| Stream {
            seed,
            padding: [0; 3],
            values: [0.0; 4],
        })
        .collect();
    let streams = dispatch::upload(
        ctx,
        "streams",
        bytemuck::cast_slice(&states),
        wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
    )?;
    let mut encoder = device.create_command_encoder(&Default::default());
    for first_frame in (0..frames).step_by(CHUNK as usize) {
        let chunk = AccumulationHarness {
            first_frame,
            frames: CHUNK.min(frames - first_frame),
            spp,
            one: 1.0,
        };
        let uniform_buffer = dispatch::upload(
            ctx,
            "accumulation harness",
            bytemuck::bytes_of(&chunk),
            wgpu::BufferUsages::UNIFORM,
        )?;
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("accumulation harness"),
            layout: &layout,
            entries: &[buffer_entry(0, &uniform_buffer), buffer_entry(1, &streams)],
        });
        let groups = ((seeds.len() as u32).div_ceil(64), 1);
        dispatch::record(ctx, &mut encoder, &pipeline, &bind_group, groups)?;
    }
    let states: Vec<Stream> = dispatch::read_back(ctx, encoder, &streams)?;
    Ok(states
        .iter()
        .map(|s| LongAccumulation {
            compensated: s.values[0],
            plain: s.values[2],
            summed: s.values[3] / frames as f32,
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The harness uniform and a stream have its WGSL twin's layout, as naga lays it out.
    #[test]
    fn the_uniform_and_stream_have_their_wgsl_twins_layout() {
        use crate::gpu::twin_layout::{module_of, twin_layout};
        let module = &module_of(Program::AccumulationHarness, &FeatureSet::default(), "");
        twin_layout!(module, AccumulationHarness, [first_frame, frames, spp, one]);
        twin_layout!(module, Stream, [seed, values]);
    }
}
