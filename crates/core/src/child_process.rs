//! The programs marbre runs (ffmpeg) are listed while they run, so that a
//! command stopped by SIGINT, SIGTERM or SIGHUP ends them before it ends
//! itself ([`end_all`]): otherwise ffmpeg outlives it, still writing.
//!
//! A child is waited for only under its lock, and only once it has ended
//! (its stderr closed), so that [`end_all`] never signals a process id
//! already reaped and perhaps reused by another process.

use std::io::Read;
use std::process::{Child, ChildStderr, ChildStdin, Command, ExitStatus};
use std::sync::{Arc, Mutex, PoisonError};

type Shared = Arc<Mutex<Child>>;

/// The children running now, by any thread.
static RUNNING: Mutex<Vec<Shared>> = Mutex::new(Vec::new());

/// A running child, listed until it is waited for or dropped (a dropped
/// one is killed first: no child outlives the work it was started for).
pub struct Tracked {
    child: Shared,
    waited: bool,
}

/// Starts `command` and lists it.
pub fn spawn(command: &mut Command) -> std::io::Result<Tracked> {
    let child = Arc::new(Mutex::new(command.spawn()?));
    RUNNING
        .lock()
        .unwrap_or_else(PoisonError::into_inner)
        .push(child.clone());
    Ok(Tracked {
        child,
        waited: false,
    })
}

impl Tracked {
    /// The child's stdin, if piped (taken once).
    pub fn take_stdin(&self) -> Option<ChildStdin> {
        self.lock().stdin.take()
    }

    /// The child's stderr, if piped (taken once).
    pub fn take_stderr(&self) -> Option<ChildStderr> {
        self.lock().stderr.take()
    }

    /// Reads `stderr` to its end (the child ends, or closes it), then
    /// waits for the child: its status and what it wrote on stderr.
    pub fn wait_after(
        mut self,
        stderr: Option<ChildStderr>,
    ) -> std::io::Result<(ExitStatus, String)> {
        let mut text = Vec::new();
        if let Some(mut stderr) = stderr {
            stderr.read_to_end(&mut text)?;
        }
        let status = self.lock().wait()?;
        self.waited = true;
        Ok((status, String::from_utf8_lossy(&text).into_owned()))
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Child> {
        self.child.lock().unwrap_or_else(PoisonError::into_inner)
    }
}

impl Drop for Tracked {
    fn drop(&mut self) {
        if !self.waited {
            let mut child = self.lock();
            let _ = child.kill();
            let _ = child.wait();
        }
        RUNNING
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .retain(|c| !Arc::ptr_eq(c, &self.child));
    }
}

/// Kills every listed child (SIGKILL: its output is thrown away, so
/// ffmpeg's own SIGTERM handling, which finishes the file, is not wanted)
/// and waits until each has ended. Returns how many were running.
pub fn end_all() -> usize {
    let running = RUNNING.lock().unwrap_or_else(PoisonError::into_inner);
    running
        .iter()
        .filter(|child| {
            let mut child = child.lock().unwrap_or_else(PoisonError::into_inner);
            // A child already waited for is not signalled (std keeps its
            // status), so a reused pid is never hit.
            let was_running = matches!(child.try_wait(), Ok(None));
            let _ = child.kill();
            let _ = child.wait();
            was_running
        })
        .count()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::process::Stdio;

    /// A child given up (its `Tracked` dropped, as on an error) is killed
    /// and reaped, and no longer listed. (`end_all` itself is tested in a
    /// process of its own, `marbre-commands`' interrupt tests: here it
    /// would kill the ffmpeg of another test.)
    #[test]
    fn a_child_given_up_is_killed_and_unlisted() {
        let tracked = spawn(Command::new("sleep").arg("600").stdin(Stdio::null())).unwrap();
        let pid = tracked.lock().id();
        assert!(std::path::Path::new(&format!("/proc/{pid}")).exists());
        drop(tracked);
        assert!(!std::path::Path::new(&format!("/proc/{pid}")).exists());
        let running = RUNNING.lock().unwrap_or_else(PoisonError::into_inner);
        assert!(
            !running
                .iter()
                .any(|c| c.lock().unwrap_or_else(PoisonError::into_inner).id() == pid)
        );
    }
}
