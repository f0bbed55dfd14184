//! Faults the GPU reports outside any error scope: a lost device (a driver
//! reset, a GPU removed, a timeout) and validation errors nothing caught.
//!
//! wgpu's default for an uncaptured error is to panic, which would take
//! the user's unsaved work with it; here each one is logged, counted (the
//! soak test fails on any) and its message kept for the panel. A lost
//! device is flagged for the viewer, which recreates the device and every
//! GPU resource from the scene model.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};

#[derive(Default)]
struct Shared {
    /// Why the device was lost, until the viewer takes it.
    lost: Mutex<Option<String>>,
    validation_errors: AtomicU64,
    /// Uncaptured errors not yet shown.
    messages: Mutex<Vec<String>>,
}

#[derive(Clone, Default)]
pub struct DeviceWatch(Arc<Shared>);

impl DeviceWatch {
    /// Installs the handlers on `device`; counts carry on from earlier
    /// devices (a recreated one keeps the same watch).
    pub fn attach(&self, device: &wgpu::Device) {
        let shared = self.0.clone();
        device.set_device_lost_callback(move |reason, message| {
            log::error!("GPU device lost ({reason:?}): {message}");
            *shared.lost.lock().unwrap_or_else(|e| e.into_inner()) =
                Some(format!("{reason:?}: {message}"));
        });
        let shared = self.0.clone();
        device.on_uncaptured_error(Arc::new(move |error: wgpu::Error| {
            log::error!("uncaptured GPU error: {error}");
            shared.validation_errors.fetch_add(1, Ordering::Relaxed);
            shared
                .messages
                .lock()
                .unwrap_or_else(|e| e.into_inner())
                .push(error.to_string());
        }));
    }

    /// Why the device was lost, once, if it was.
    pub fn take_lost(&self) -> Option<String> {
        self.0.lost.lock().unwrap_or_else(|e| e.into_inner()).take()
    }

    /// Uncaptured errors since the last call.
    pub fn take_messages(&self) -> Vec<String> {
        std::mem::take(&mut *self.0.messages.lock().unwrap_or_else(|e| e.into_inner()))
    }

    /// Uncaptured errors since the watch was made.
    pub fn validation_errors(&self) -> u64 {
        self.0.validation_errors.load(Ordering::Relaxed)
    }
}
