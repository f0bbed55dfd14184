//! Timing a render frame by frame: the GPU's own time per frame from
//! timestamp queries where the adapter has them, else the wall-clock time
//! of each frame waited for. Either way every frame is waited for, so the
//! total is the time a user waits for that many samples.

use anyhow::{Context, Result};
use marbre_render::gpu::readback::read_buffer;
use marbre_render::gpu::{GpuContext, PassTimestamps, Renderer};
use std::time::Instant;

/// Frames whose timestamps share one query set and one readback: a
/// readback every this many frames rather than every frame.
const FRAMES_PER_READBACK: u32 = 64;

/// Where the time per frame comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TimerKind {
    GpuTimestamps,
    WallClock,
}

impl TimerKind {
    pub fn name(self) -> &'static str {
        match self {
            TimerKind::GpuTimestamps => "gpu-timestamps",
            TimerKind::WallClock => "wall-clock",
        }
    }
}

/// What a run of frames took.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrameTimes {
    /// The median frame, in milliseconds: a few frames stall on a shared
    /// machine for reasons unrelated to the shader.
    pub median_ms: f64,
    /// Wall-clock seconds of the whole run.
    pub seconds: f64,
}

pub struct FrameTimer {
    timestamps: Option<Timestamps>,
}

/// A query set with two timestamps a frame, and the buffers that bring them
/// back to the CPU.
struct Timestamps {
    queries: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    readback: wgpu::Buffer,
    /// Nanoseconds per tick.
    period: f64,
}

impl FrameTimer {
    pub fn new(ctx: &GpuContext) -> Self {
        Self {
            timestamps: ctx.timestamps.then(|| Timestamps::new(ctx)),
        }
    }

    pub fn kind(&self) -> TimerKind {
        match self.timestamps {
            Some(_) => TimerKind::GpuTimestamps,
            None => TimerKind::WallClock,
        }
    }

    /// Traces `frames` frames with `renderer`, waiting for each.
    pub fn run(
        &self,
        ctx: &GpuContext,
        renderer: &mut Renderer,
        frames: u32,
        mut progress: impl FnMut(u32),
    ) -> Result<FrameTimes> {
        let mut per_frame = Vec::with_capacity(frames as usize);
        let start = Instant::now();
        let mut done = 0;
        while done < frames {
            let batch = (frames - done).min(FRAMES_PER_READBACK);
            let mut wall = Vec::with_capacity(batch as usize);
            for i in 0..batch {
                let frame_start = Instant::now();
                let mut encoder = ctx.device.create_command_encoder(&Default::default());
                let writes = self.timestamps.as_ref().map(|t| t.writes(i));
                renderer.trace(ctx, &mut encoder, writes);
                ctx.queue.submit([encoder.finish()]);
                ctx.device
                    .poll(wgpu::PollType::wait_indefinitely())
                    .context("waiting for the GPU")?;
                wall.push(frame_start.elapsed().as_secs_f64() * 1000.0);
                progress(done + i + 1);
            }
            match &self.timestamps {
                Some(t) => per_frame.extend(t.read(ctx, batch)?),
                None => per_frame.extend(wall),
            }
            done += batch;
        }
        let seconds = start.elapsed().as_secs_f64();
        per_frame.sort_by(f64::total_cmp);
        Ok(FrameTimes {
            median_ms: per_frame.get(per_frame.len() / 2).copied().unwrap_or(0.0),
            seconds,
        })
    }
}

impl Timestamps {
    fn new(ctx: &GpuContext) -> Self {
        let count = 2 * FRAMES_PER_READBACK;
        let queries = ctx.device.create_query_set(&wgpu::QuerySetDescriptor {
            label: Some("bench frame timer"),
            ty: wgpu::QueryType::Timestamp,
            count,
        });
        let buffer = |usage| {
            ctx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("bench frame timer"),
                size: u64::from(count) * 8,
                usage,
                mapped_at_creation: false,
            })
        };
        Self {
            queries,
            resolve: buffer(wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC),
            readback: buffer(wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ),
            period: f64::from(ctx.queue.get_timestamp_period()),
        }
    }

    /// Frame `i` of a batch writes timestamps `2i` and `2i + 1`.
    fn writes(&self, i: u32) -> PassTimestamps<'_> {
        PassTimestamps {
            query_set: &self.queries,
            beginning: Some(2 * i),
            end: Some(2 * i + 1),
        }
    }

    /// The milliseconds of the batch's first `frames` frames.
    fn read(&self, ctx: &GpuContext, frames: u32) -> Result<Vec<f64>> {
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        encoder.resolve_query_set(&self.queries, 0..2 * frames, &self.resolve, 0);
        encoder.copy_buffer_to_buffer(&self.resolve, 0, &self.readback, 0, None);
        ctx.queue.submit([encoder.finish()]);
        let bytes = read_buffer(&ctx.device, &self.readback)?;
        // A copy: the bytes of a Vec<u8> need not be aligned for u64.
        let ticks: Vec<u64> = bytemuck::pod_collect_to_vec(&bytes);
        Ok(ticks
            .chunks_exact(2)
            .take(frames as usize)
            .map(|t| t[1].saturating_sub(t[0]) as f64 * self.period / 1e6)
            .collect())
    }
}
