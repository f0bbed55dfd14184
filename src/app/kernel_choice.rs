//! Which trace kernel the viewer runs (`gpu::kernel`): the one the user
//! named (`--kernel`, the Render panel's Kernel switch), or for `auto` the
//! fastest here. `auto` times the kernels once (the CPU kernel where it
//! traces the scene), on the first scene, on a worker thread with its own device (the window keeps
//! drawing), and remembers the winner per adapter in the settings file, so
//! the next start uses it at once.

use super::settings::Settings;
use anyhow::Result;
use marbre_render::gpu::kernel::{self, compute_support};
use marbre_render::gpu::{GpuContext, Kernel, KernelChoice};
use marbre_render::session::{KernelTimings, LoadedScene, time_kernels};
use marbre_render::worker::{Worker, names};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;

/// The kernel stored for `adapter`: `Ok(None)` if none is, `Err` with a
/// note if the stored value is not a kernel's name (it is then ignored).
pub fn stored(settings: &Settings, adapter: &str) -> Result<Option<Kernel>, String> {
    match settings.kernels.get(adapter) {
        None => Ok(None),
        Some(name) => Kernel::parse(name).map(Some).ok_or_else(|| {
            format!(
                "settings: the kernel stored for {adapter} is `{name}`, not a kernel's name; \
                 ignored, timing the kernels again"
            )
        }),
    }
}

/// Stores the faster kernel of `timings` for `adapter` and returns it.
pub fn remember(settings: &mut Settings, adapter: &str, timings: &KernelTimings) -> Kernel {
    let kernel = timings.faster();
    settings
        .kernels
        .insert(adapter.to_owned(), kernel.name().to_owned());
    kernel
}

/// The user's choice and what came of it.
pub struct KernelChooser {
    choice: KernelChoice,
    /// The adapter, as the settings file keys it.
    adapter: String,
    /// `auto` timing both kernels on a worker.
    timing: Option<Timing>,
    /// Timings a new choice cancelled, still finishing their current step:
    /// joined once finished, or when the chooser goes.
    cancelled: Vec<Timing>,
    /// Whether `auto` still has to time (no stored choice yet).
    needs_timing: bool,
    /// Why the kernel runs, for the Stats panel.
    reason: String,
}

impl KernelChooser {
    /// The chooser for `choice` on `ctx`'s adapter, the kernel to start
    /// with, and a note for the panel (an ignored stored value, or the
    /// compute kernel unsupported). `--kernel compute` where it cannot run
    /// is an error.
    pub fn new(
        choice: KernelChoice,
        ctx: &GpuContext,
        settings: &Settings,
    ) -> Result<(Self, Kernel, Vec<String>)> {
        let adapter = ctx.describe();
        let mut notes = Vec::new();
        let mut chooser = Self {
            choice,
            adapter,
            timing: None,
            cancelled: Vec::new(),
            needs_timing: false,
            reason: String::new(),
        };
        let kernel = chooser.resolve(ctx, settings, &mut notes)?;
        Ok((chooser, kernel, notes))
    }

    /// The kernel the current choice gives now (timing may follow).
    fn resolve(
        &mut self,
        ctx: &GpuContext,
        settings: &Settings,
        notes: &mut Vec<String>,
    ) -> Result<Kernel> {
        self.needs_timing = false;
        let kernel = kernel::resolve(ctx, self.choice)?;
        self.reason = match (self.choice, compute_support(ctx)) {
            (KernelChoice::Auto, Err(why)) => {
                let note = format!("compute kernel unavailable ({why}): tracing in fragment");
                notes.push(note.clone());
                note
            }
            (KernelChoice::Auto, Ok(())) => match stored(settings, &self.adapter) {
                Ok(Some(stored)) => {
                    self.reason = format!("auto: {stored}, stored for this adapter");
                    return Ok(stored);
                }
                Ok(None) => {
                    self.needs_timing = true;
                    "auto: timing the kernels on the first scene".to_owned()
                }
                Err(note) => {
                    notes.push(note);
                    self.needs_timing = true;
                    "auto: timing the kernels on the first scene".to_owned()
                }
            },
            _ => "chosen".to_owned(),
        };
        Ok(kernel)
    }

    pub fn choice(&self) -> KernelChoice {
        self.choice
    }

    /// Why the current kernel runs, for the Stats panel.
    pub fn reason(&self) -> &str {
        &self.reason
    }

    /// A new choice from the panel: the kernel to switch to, and notes.
    /// `auto` uses the stored kernel, or times again.
    pub fn choose(
        &mut self,
        choice: KernelChoice,
        ctx: &GpuContext,
        settings: &Settings,
    ) -> Result<(Kernel, Vec<String>)> {
        let previous = self.choice;
        self.choice = choice;
        self.cancelled.retain(|t| !t.worker.is_finished());
        if let Some(timing) = self.timing.take() {
            timing.cancel.store(true, Ordering::Relaxed);
            self.cancelled.push(timing);
        }
        let mut notes = Vec::new();
        match self.resolve(ctx, settings, &mut notes) {
            Ok(kernel) => Ok((kernel, notes)),
            Err(e) => {
                self.choice = previous;
                let mut ignored = Vec::new();
                self.resolve(ctx, settings, &mut ignored)?;
                Err(e)
            }
        }
    }

    /// For `auto` without a stored kernel: times both kernels on `loaded`
    /// at `size` on a worker thread with a second device.
    pub fn time_if_needed(&mut self, ctx: &GpuContext, loaded: &LoadedScene, size: (u32, u32)) {
        if !self.needs_timing || self.timing.is_some() {
            return;
        }
        self.needs_timing = false;
        let (sender, receiver) = mpsc::channel();
        let sibling = match ctx.sibling() {
            Ok(sibling) => sibling,
            Err(e) => {
                self.reason = format!("auto: could not time the kernels ({e:#})");
                return;
            }
        };
        let loaded = loaded.clone();
        let cancel = Arc::new(AtomicBool::new(false));
        let worker_cancel = cancel.clone();
        match Worker::spawn(names::KERNEL_TIMING, move || {
            let _ = sender.send(time_kernels(&sibling, &loaded, size, &worker_cancel));
        }) {
            Ok(worker) => {
                self.timing = Some(Timing {
                    result: receiver,
                    cancel,
                    worker,
                })
            }
            Err(e) => self.reason = format!("auto: could not time the kernels ({e})"),
        }
    }

    /// The kernel `auto` picked, once its timing is done (stored in
    /// `settings` for this adapter); a failed timing keeps the current
    /// kernel and says why.
    pub fn poll(&mut self, settings: &mut Settings) -> Option<Result<Kernel>> {
        let result = self.timing.as_ref()?.result.try_recv().ok()?;
        self.timing = None;
        Some(match result {
            Ok(timings) => {
                let kernel = remember(settings, &self.adapter, &timings);
                self.reason = format!("auto: {kernel} is faster ({timings})");
                Ok(kernel)
            }
            Err(e) => {
                self.reason = format!("auto: timing the kernels failed ({e:#})");
                Err(e)
            }
        })
    }
}

/// `auto`'s timing on its worker: the result to come, and the flag that
/// stops it between steps.
struct Timing {
    result: mpsc::Receiver<Result<KernelTimings>>,
    cancel: Arc<AtomicBool>,
    /// Joined as the timing drops, after its `Drop` has set the flag.
    worker: Worker,
}

impl Drop for Timing {
    /// Stops the timing at its next step; the worker is joined next.
    fn drop(&mut self) {
        self.cancel.store(true, Ordering::Relaxed);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn timings(fragment_ms: f64, compute_ms: f64) -> KernelTimings {
        KernelTimings {
            fragment_ms,
            compute_ms: Some(compute_ms),
            cpu_ms: None,
            size: (320, 180),
        }
    }

    /// The injected timings decide, and the winner is stored for the
    /// adapter that was timed only.
    #[test]
    fn auto_remembers_the_faster_kernel_per_adapter() {
        let mut settings = Settings::default();
        assert_eq!(
            remember(&mut settings, "gpu A", &timings(9.0, 2.0)),
            Kernel::Compute
        );
        assert_eq!(
            remember(&mut settings, "gpu B", &timings(3.0, 4.0)),
            Kernel::Fragment
        );
        assert_eq!(stored(&settings, "gpu A"), Ok(Some(Kernel::Compute)));
        assert_eq!(stored(&settings, "gpu B"), Ok(Some(Kernel::Fragment)));
        assert_eq!(stored(&settings, "gpu C"), Ok(None));
    }

    /// A stored choice is read back after a restart (the settings file).
    #[test]
    fn a_stored_choice_survives_a_restart() {
        let dir = tempfile::Builder::new()
            .prefix("kernel-choice-restart")
            .tempdir()
            .unwrap();
        let mut settings = Settings::default();
        remember(&mut settings, "llvmpipe (Vulkan)", &timings(5.0, 7.0));
        settings.save(dir.path()).unwrap();
        let (loaded, note) = Settings::load(dir.path());
        assert_eq!(note, None);
        assert_eq!(
            stored(&loaded, "llvmpipe (Vulkan)"),
            Ok(Some(Kernel::Fragment))
        );
    }

    /// A hand-edited value that names no kernel is ignored with a note
    /// naming it; the rest of the settings stay.
    #[test]
    fn an_invalid_stored_kernel_is_ignored_with_a_note() {
        let dir = tempfile::Builder::new()
            .prefix("kernel-choice-invalid")
            .tempdir()
            .unwrap();
        std::fs::write(
            dir.path().join("settings.ron"),
            r#"(recent_files: ["/p/a.ron"], kernels: {"gpu A": "warp-drive"})"#,
        )
        .unwrap();
        let (settings, note) = Settings::load(dir.path());
        assert_eq!(note, None);
        assert_eq!(settings.recent_files.len(), 1);
        let why = stored(&settings, "gpu A").unwrap_err();
        assert!(
            why.contains("warp-drive") && why.contains("ignored"),
            "{why}"
        );
    }
}
