//! GPU time of the trace pass, from timestamp queries, read back without
//! stalling: a frame's result arrives a frame or two later, and frames that
//! start while a readback is pending are simply not timed.

use super::context::GpuContext;
use std::sync::Arc;
use std::sync::atomic::{AtomicU8, Ordering};

const IDLE: u8 = 0;
const IN_FLIGHT: u8 = 1;
const MAPPED: u8 = 2;

pub struct PassTimer {
    queries: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    readback: wgpu::Buffer,
    /// Nanoseconds per timestamp tick.
    period: f32,
    state: Arc<AtomicU8>,
    /// Whether the pass recorded this frame carries timestamp writes.
    timing_this_frame: bool,
    last_ms: Option<f32>,
}

impl PassTimer {
    /// `None` where the adapter has no timestamp queries.
    pub fn new(ctx: &GpuContext) -> Option<Self> {
        if !ctx.timestamps {
            return None;
        }
        let queries = ctx.device.create_query_set(&wgpu::QuerySetDescriptor {
            label: Some("trace pass timer"),
            ty: wgpu::QueryType::Timestamp,
            count: 2,
        });
        let buffer = |usage| {
            ctx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("trace pass timer"),
                size: 16,
                usage,
                mapped_at_creation: false,
            })
        };
        Some(Self {
            queries,
            resolve: buffer(wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC),
            readback: buffer(wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ),
            period: ctx.queue.get_timestamp_period(),
            state: Arc::new(AtomicU8::new(IDLE)),
            timing_this_frame: false,
            last_ms: None,
        })
    }

    /// Collects a finished readback, then says whether this frame is timed.
    /// Returns the timestamp writes to put on the pass, if it is.
    pub fn begin_frame(&mut self) -> Option<wgpu::RenderPassTimestampWrites<'_>> {
        if self.state.load(Ordering::Acquire) == MAPPED {
            if let Ok(view) = self.readback.get_mapped_range(..) {
                let ticks: &[u64] = bytemuck::cast_slice(&view);
                let dt = ticks[1].saturating_sub(ticks[0]) as f64 * f64::from(self.period);
                self.last_ms = Some((dt / 1e6) as f32);
            }
            self.readback.unmap();
            self.state.store(IDLE, Ordering::Release);
        }
        self.timing_this_frame = self.state.load(Ordering::Acquire) == IDLE;
        self.timing_this_frame
            .then_some(wgpu::RenderPassTimestampWrites {
                query_set: &self.queries,
                beginning_of_pass_write_index: Some(0),
                end_of_pass_write_index: Some(1),
            })
    }

    /// Records the resolve and copy; call after the timed pass.
    pub fn resolve(&self, encoder: &mut wgpu::CommandEncoder) {
        if self.timing_this_frame {
            encoder.resolve_query_set(&self.queries, 0..2, &self.resolve, 0);
            encoder.copy_buffer_to_buffer(&self.resolve, 0, &self.readback, 0, 16);
        }
    }

    /// Starts the readback; call after the submit.
    pub fn after_submit(&mut self) {
        if self.timing_this_frame {
            self.state.store(IN_FLIGHT, Ordering::Release);
            let state = self.state.clone();
            self.readback.map_async(wgpu::MapMode::Read, .., move |r| {
                state.store(if r.is_ok() { MAPPED } else { IDLE }, Ordering::Release);
            });
            self.timing_this_frame = false;
        }
    }

    /// The latest measured trace-pass time in milliseconds.
    pub fn last_ms(&self) -> Option<f32> {
        self.last_ms
    }
}
