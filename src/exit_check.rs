//! The last thing `main` does: make sure no thread that holds GPU state is
//! still running (`marbre_render::worker::gpu_threads_alive`).
//!
//! Returning from `main` runs `exit`, which runs the drivers' and LLVM's
//! exit handlers and unloads their libraries; a thread still compiling a
//! shader or dropping a device then dies of SIGSEGV, at random, after the
//! work was done (issue 26). Every owner joins its workers and drops its
//! devices before this point; the check makes a mistake there a clear,
//! repeatable failure instead of a crash that one run in ten shows.
//!
//! It runs in debug builds (every test of the real binary) and wherever
//! `MARBRE_CHECK_EXIT=1` is set (`.ci/exit-stress` sets it on release
//! builds); `MARBRE_CHECK_EXIT=0` turns it off.

use marbre_render::worker::gpu_threads_alive;

/// The variable that turns the check on (1) or off (0).
pub const SWITCH: &str = "MARBRE_CHECK_EXIT";

/// Whether the check runs: the switch, else whether this is a debug build.
fn enabled() -> bool {
    match std::env::var(SWITCH).as_deref() {
        Ok("1") => true,
        Ok("0") => false,
        _ => cfg!(debug_assertions),
    }
}

/// An error naming the threads that hold GPU state and still run, where
/// the check is on; `Ok` where none does or the check is off.
pub fn check() -> Result<(), String> {
    if !enabled() {
        return Ok(());
    }
    let alive = gpu_threads_alive();
    if alive.is_empty() {
        Ok(())
    } else {
        Err(format!(
            "threads holding GPU state still running at exit: {} (a worker not joined, or a \
             device not dropped; see issue 26 and src/exit_check.rs)",
            alive.join(", ")
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use marbre_render::worker::{Worker, names};
    use std::sync::mpsc;
    use std::time::Duration;

    /// A worker still running fails the check by name (this is a debug
    /// build, where the check is on unless switched off); once it is
    /// joined, its name is gone from the error. Other tests of this binary
    /// may hold devices meanwhile, so only this worker's name is looked at.
    #[test]
    fn a_worker_alive_at_exit_is_named_and_a_joined_one_is_not() {
        // A release build checks only when switched on: nothing to see.
        if !cfg!(target_os = "linux")
            || !cfg!(debug_assertions)
            || std::env::var_os(SWITCH).is_some()
        {
            return;
        }
        let (started, wait_started) = mpsc::channel();
        let (release, wait) = mpsc::channel::<()>();
        let worker = Worker::spawn(names::KERNEL_TIMING, move || {
            // The thread takes its name as it starts: say when it has.
            started.send(()).unwrap();
            // Ends by itself too, should the test fail before releasing it.
            let _ = wait.recv_timeout(Duration::from_secs(30));
        })
        .unwrap();
        wait_started.recv().unwrap();
        let error = check().expect_err("a live kernel-timing worker passed the check");
        assert!(error.contains(names::KERNEL_TIMING), "{error}");
        drop(release);
        drop(worker);
        if let Err(error) = check() {
            assert!(!error.contains(names::KERNEL_TIMING), "{error}");
        }
    }
}
