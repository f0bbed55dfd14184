//! A small GPU-to-CPU copy read without stalling the frame: the copy is
//! recorded into a frame's encoder, mapped after that frame's submit, and
//! picked up a frame or two later. While one readback is in flight, frames
//! record no other: measurements of those frames are simply skipped.

use std::sync::Arc;
use std::sync::atomic::{AtomicU8, Ordering};

const IDLE: u8 = 0;
/// The copy is recorded in an encoder not yet submitted.
const RECORDED: u8 = 1;
const IN_FLIGHT: u8 = 2;
const MAPPED: u8 = 3;

pub struct AsyncReadback {
    buffer: wgpu::Buffer,
    state: Arc<AtomicU8>,
}

impl AsyncReadback {
    pub fn new(device: &wgpu::Device, label: &str, size: u64) -> Self {
        Self {
            buffer: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
                mapped_at_creation: false,
            }),
            state: Arc::new(AtomicU8::new(IDLE)),
        }
    }

    /// Whether a copy may be recorded now (none is pending).
    pub fn is_idle(&self) -> bool {
        self.state.load(Ordering::Acquire) == IDLE
    }

    /// Records a copy of `source` (from its start, the readback's size) if
    /// none is pending; returns whether it did.
    pub fn record_copy(&self, encoder: &mut wgpu::CommandEncoder, source: &wgpu::Buffer) -> bool {
        if !self.is_idle() {
            return false;
        }
        encoder.copy_buffer_to_buffer(source, 0, &self.buffer, 0, self.buffer.size());
        self.state.store(RECORDED, Ordering::Release);
        true
    }

    /// Starts mapping a copy recorded in the encoder just submitted.
    pub fn after_submit(&self) {
        if self.state.load(Ordering::Acquire) != RECORDED {
            return;
        }
        self.state.store(IN_FLIGHT, Ordering::Release);
        let state = self.state.clone();
        self.buffer.map_async(wgpu::MapMode::Read, .., move |r| {
            state.store(if r.is_ok() { MAPPED } else { IDLE }, Ordering::Release);
        });
    }

    /// The bytes of a finished readback, once; the readback is then free
    /// for the next copy.
    pub fn take(&self) -> Option<Vec<u8>> {
        if self.state.load(Ordering::Acquire) != MAPPED {
            return None;
        }
        let bytes = self
            .buffer
            .get_mapped_range(..)
            .ok()
            .map(|view| view.to_vec());
        self.buffer.unmap();
        self.state.store(IDLE, Ordering::Release);
        bytes
    }
}
