//! Worker threads that hold GPU or driver state, always joined.
//!
//! A thread left running when the process exits keeps working while
//! `exit` runs the drivers' and LLVM's exit handlers and unloads their
//! libraries: on lavapipe, a kernel timing still compiling a shader in
//! LLVM, or a swatch worker dropping the last reference to the wgpu
//! instance (and so tearing down EGL) while `_dl_fini` ran, ended the
//! viewer in SIGSEGV after its last frame (issue 26; docs/TESTING.md,
//! "Exit paths"). So every thread that may touch a device is a [`Worker`]:
//! named, so that [`gpu_threads_alive`] can tell it from the rest, and
//! joined when its owner drops it, after the owner has asked it to stop
//! (each owner's `Drop` sets its cancel flag or closes its job channel
//! first).

use std::io;
use std::thread::JoinHandle;

/// The names of the threads that touch a device, the ones [`Worker`]s take
/// (at most 15 bytes: Linux keeps no more of a thread's name).
pub mod names {
    pub const PIPELINE_BUILD: &str = "pipeline-build";
    pub const SWATCHES: &str = "swatches";
    pub const KERNEL_TIMING: &str = "kernel-timing";
    pub const RENDER_JOB: &str = "render-job";
    pub const BAKE: &str = "bake";
    /// Every name above.
    pub const ALL: [&str; 5] = [PIPELINE_BUILD, SWATCHES, KERNEL_TIMING, RENDER_JOB, BAKE];
}

/// A named thread joined on drop.
pub struct Worker {
    handle: Option<JoinHandle<()>>,
}

impl Worker {
    /// Starts `work` on a thread called `name` (one of [`names`]).
    pub fn spawn(name: &'static str, work: impl FnOnce() + Send + 'static) -> io::Result<Self> {
        debug_assert!(names::ALL.contains(&name), "{name} is not in worker::names");
        let handle = std::thread::Builder::new()
            .name(name.to_owned())
            .spawn(work)?;
        Ok(Self {
            handle: Some(handle),
        })
    }

    /// Whether the thread has returned (joining it then does not wait).
    pub fn is_finished(&self) -> bool {
        self.handle.as_ref().is_none_or(JoinHandle::is_finished)
    }
}

impl Drop for Worker {
    /// Waits for the thread. A panic in it was already printed by the
    /// panic hook, and its owner sees a closed channel: nothing to add.
    fn drop(&mut self) {
        if let Some(handle) = self.handle.take() {
            let _ = handle.join();
        }
    }
}

/// The threads of this process that hold GPU state, by name: the workers
/// above, and lavapipe's rasteriser threads (`llvmpipe-N`, which live as
/// long as a device on it). Empty once every device is dropped and every
/// worker joined; checked before the process exits (`MARBRE_CHECK_EXIT`,
/// `src/exit_check.rs`). Linux only: elsewhere nothing is listed.
pub fn gpu_threads_alive() -> Vec<String> {
    let Ok(tasks) = std::fs::read_dir("/proc/self/task") else {
        return Vec::new();
    };
    let mut alive: Vec<String> = tasks
        .filter_map(|task| std::fs::read_to_string(task.ok()?.path().join("comm")).ok())
        .map(|name| name.trim_end().to_owned())
        .filter(|name| names::ALL.contains(&name.as_str()) || name.starts_with("llvmpipe-"))
        .collect();
    alive.sort();
    alive
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::mpsc;
    use std::time::Duration;

    /// Dropping a worker waits for its thread: what the thread does last
    /// has happened when the drop returns, and its name is gone from the
    /// live threads.
    #[test]
    fn dropping_a_worker_joins_its_thread() {
        let (started, wait_started) = mpsc::channel();
        let (finished, was_finished) = mpsc::channel();
        let worker = Worker::spawn(names::BAKE, move || {
            started.send(()).unwrap();
            std::thread::sleep(Duration::from_millis(200));
            finished.send(()).unwrap();
        })
        .unwrap();
        wait_started.recv().unwrap();
        if cfg!(target_os = "linux") {
            assert!(gpu_threads_alive().contains(&names::BAKE.to_owned()));
        }
        assert!(!worker.is_finished());
        drop(worker);
        assert_eq!(was_finished.try_recv(), Ok(()), "the drop returned first");
        assert!(!gpu_threads_alive().contains(&names::BAKE.to_owned()));
    }
}
