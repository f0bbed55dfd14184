//! The backstop for GPU errors that no error scope caught.
//!
//! wgpu's default for such an error is to panic ("Handling wgpu errors as
//! fatal by default"): `marbre noise` on 20 million points died that way,
//! at a bind group larger than the device allows (issue 47). Every device
//! marbre creates gets [`UncapturedErrors::watch`] instead: each error is
//! logged and counted, and the work that may have raised one asks
//! [`UncapturedErrors::check`] before it trusts its results. Error scopes,
//! where code has them (pipeline creation, a final render's targets),
//! still catch their own errors first. The viewer replaces this handler
//! with its device watch's (`src/app/device_watch.rs`), which shows each
//! error in its panel.

use std::sync::{Arc, Mutex, PoisonError};

/// The uncaptured errors of one device since the last check: how many,
/// and the first one's message (only the first, so that a fault repeated
/// every frame costs no memory).
#[derive(Clone, Default)]
pub struct UncapturedErrors(Arc<Mutex<Unchecked>>);

#[derive(Default)]
struct Unchecked {
    count: u64,
    first: Option<String>,
}

impl UncapturedErrors {
    /// Installs the handler on `device`, replacing wgpu's panic.
    pub fn watch(device: &wgpu::Device) -> Self {
        let errors = Self::default();
        let kept = errors.clone();
        device.on_uncaptured_error(Arc::new(move |error: wgpu::Error| {
            log::error!("uncaptured GPU error: {error}");
            kept.record(error.to_string());
        }));
        errors
    }

    fn record(&self, message: String) {
        let mut unchecked = self.0.lock().unwrap_or_else(PoisonError::into_inner);
        unchecked.count += 1;
        unchecked.first.get_or_insert(message);
    }

    /// An error saying how many uncaptured errors arrived since the last
    /// check, and what the first one said; none if none did. Each error
    /// is reported by one check only.
    pub fn check(&self) -> anyhow::Result<()> {
        let unchecked = std::mem::take(&mut *self.0.lock().unwrap_or_else(PoisonError::into_inner));
        match unchecked.first {
            None => Ok(()),
            Some(first) => anyhow::bail!(
                "the GPU reported {} error(s); the first: {first}",
                unchecked.count
            ),
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::gpu::testing::gpu_or_skip;

    /// An invalid operation outside any error scope (a buffer both
    /// mappable for reading and a storage buffer) is a message from the
    /// next check, not wgpu's panic; each error is reported once.
    #[test]
    fn an_uncaptured_error_is_a_message_not_a_panic() {
        let Some(ctx) = gpu_or_skip("an_uncaptured_error_is_a_message_not_a_panic") else {
            return;
        };
        ctx.uncaptured.check().unwrap();
        for _ in 0..2 {
            let _invalid = ctx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("invalid on purpose"),
                size: 16,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::STORAGE,
                mapped_at_creation: false,
            });
        }
        let e = ctx.uncaptured.check().unwrap_err().to_string();
        assert!(
            e.starts_with("the GPU reported 2 error(s); the first: "),
            "{e}"
        );
        assert!(e.contains("invalid on purpose"), "{e}");
        ctx.uncaptured.check().unwrap();
    }
}
