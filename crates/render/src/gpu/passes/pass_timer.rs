//! GPU time of each pass of a frame, from timestamp queries, read back
//! without stalling ([`AsyncReadback`]): a frame's times arrive a frame or
//! two later, and frames that start while a readback is pending are simply
//! not timed. Each pass's time is smoothed, so the panel shows a steady
//! figure rather than one frame's jitter.

use crate::gpu::async_readback::AsyncReadback;
use crate::gpu::context::GpuContext;
use crate::gpu::trace_pass::PassTimestamps;
use std::cell::Cell;

/// The passes of a viewer frame, in the order they run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Pass {
    /// The path tracer: the samples of this frame.
    Trace,
    /// The error meter's reduction of the accumulated spread.
    ErrorMeter,
    /// Auto exposure's metering of the accumulated mean.
    AutoExposure,
    /// Exposure and tone mapping into the window.
    Display,
    /// The side panel.
    Ui,
}

impl Pass {
    pub const ALL: [Pass; 5] = [
        Pass::Trace,
        Pass::ErrorMeter,
        Pass::AutoExposure,
        Pass::Display,
        Pass::Ui,
    ];

    pub fn label(self) -> &'static str {
        match self {
            Pass::Trace => "trace",
            Pass::ErrorMeter => "error meter",
            Pass::AutoExposure => "auto exposure",
            Pass::Display => "display",
            Pass::Ui => "panel (egui)",
        }
    }

    fn index(self) -> usize {
        self as usize
    }
}

const PASSES: usize = Pass::ALL.len();
/// Each pass resolves into its own slot of the resolve buffer: resolve
/// offsets must be aligned to this, and passes that did not run this frame
/// have unwritten queries, which must not be resolved.
const SLOT_BYTES: u64 = wgpu::QUERY_RESOLVE_BUFFER_ALIGNMENT;
/// Weight of the newest frame in each pass's smoothed time.
const SMOOTHING: f32 = 0.2;

pub struct PassTimer {
    queries: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    readback: AsyncReadback,
    /// Nanoseconds per timestamp tick.
    period: f32,
    /// Whether this frame is timed (no readback was pending at its start).
    timing_this_frame: bool,
    /// The passes that wrote timestamps this frame, a bit each: a pass
    /// that runs twice (the display into a capture too) is timed once.
    written: Cell<u32>,
    /// `written` of the frame whose readback is in flight.
    in_flight: u32,
    smoothed_ms: [Option<f32>; PASSES],
    /// Each pass's latest measurement, until taken.
    fresh_ms: [Option<f32>; PASSES],
}

impl PassTimer {
    /// `None` where the adapter has no timestamp queries.
    pub fn new(ctx: &GpuContext) -> Option<Self> {
        if !ctx.timestamps {
            return None;
        }
        let count = 2 * PASSES as u32;
        let size = SLOT_BYTES * PASSES as u64;
        Some(Self {
            queries: ctx.device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("pass timer"),
                ty: wgpu::QueryType::Timestamp,
                count,
            }),
            resolve: ctx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("pass timer resolve"),
                size,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            }),
            readback: AsyncReadback::new(&ctx.device, "pass timer readback", size),
            period: ctx.queue.get_timestamp_period(),
            timing_this_frame: false,
            written: Cell::new(0),
            in_flight: 0,
            smoothed_ms: [None; PASSES],
            fresh_ms: [None; PASSES],
        })
    }

    /// Collects a finished readback, then decides whether this frame is
    /// timed.
    pub fn begin_frame(&mut self) {
        if let Some(bytes) = self.readback.take() {
            let ticks: &[u64] = bytemuck::cast_slice(&bytes);
            for pass in Pass::ALL {
                let i = pass.index();
                if self.in_flight & (1 << i) == 0 {
                    continue;
                }
                let slot = i * (SLOT_BYTES / 8) as usize;
                let dt = ticks[slot + 1].saturating_sub(ticks[slot]) as f64;
                let ms = (dt * f64::from(self.period) / 1e6) as f32;
                self.fresh_ms[i] = Some(ms);
                let smoothed = &mut self.smoothed_ms[i];
                *smoothed = Some(smoothed.map_or(ms, |s| s + SMOOTHING * (ms - s)));
            }
        }
        self.timing_this_frame = self.readback.is_idle();
        self.written.set(0);
    }

    /// Claims `pass`'s two queries for this frame: `None` if the frame is
    /// not timed or the pass already wrote them.
    fn claim(&self, pass: Pass) -> Option<(u32, u32)> {
        let bit = 1 << pass.index();
        if !self.timing_this_frame || self.written.get() & bit != 0 {
            return None;
        }
        self.written.set(self.written.get() | bit);
        let first = 2 * pass.index() as u32;
        Some((first, first + 1))
    }

    /// Whether this frame is timed: its passes' times arrive a frame or two
    /// later, through [`Self::take_fresh`].
    pub fn is_timing(&self) -> bool {
        self.timing_this_frame
    }

    /// The timestamp writes of `pass`, whichever kind of pass (or passes:
    /// the trace's bands) records it.
    pub fn timestamps(&self, pass: Pass) -> Option<PassTimestamps<'_>> {
        self.claim(pass).map(|(begin, end)| PassTimestamps {
            query_set: &self.queries,
            beginning: Some(begin),
            end: Some(end),
        })
    }

    /// The timestamp writes to put on a render pass.
    pub fn render_pass(&self, pass: Pass) -> Option<wgpu::RenderPassTimestampWrites<'_>> {
        self.timestamps(pass).map(PassTimestamps::render)
    }

    /// The timestamp writes to put on a compute pass.
    pub fn compute_pass(&self, pass: Pass) -> Option<wgpu::ComputePassTimestampWrites<'_>> {
        self.timestamps(pass).map(PassTimestamps::compute)
    }

    /// Records the resolve and the copy; call after the frame's last timed
    /// pass.
    pub fn resolve(&mut self, encoder: &mut wgpu::CommandEncoder) {
        let written = self.written.get();
        if !self.timing_this_frame || written == 0 {
            return;
        }
        for pass in Pass::ALL {
            if written & (1 << pass.index()) != 0 {
                let first = 2 * pass.index() as u32;
                encoder.resolve_query_set(
                    &self.queries,
                    first..first + 2,
                    &self.resolve,
                    SLOT_BYTES * pass.index() as u64,
                );
            }
        }
        if self.readback.record_copy(encoder, &self.resolve) {
            self.in_flight = written;
        }
    }

    /// Starts the readback; call after the submit.
    pub fn after_submit(&mut self) {
        self.readback.after_submit();
        self.timing_this_frame = false;
    }

    /// The smoothed GPU time of `pass` in milliseconds, once measured.
    pub fn ms(&self, pass: Pass) -> Option<f32> {
        self.smoothed_ms[pass.index()]
    }

    /// The latest measurement of `pass`, once: for statistics that must
    /// count each frame once (the smoothed figure lags behind a change).
    pub fn take_fresh(&mut self, pass: Pass) -> Option<f32> {
        self.fresh_ms[pass.index()].take()
    }

    /// Forgets a pass's time: for a pass that stopped running (auto
    /// exposure switched off), so the panel does not show a stale figure.
    pub fn forget(&mut self, pass: Pass) {
        self.smoothed_ms[pass.index()] = None;
    }
}
