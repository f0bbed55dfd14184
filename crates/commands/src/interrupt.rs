//! What a headless command does when SIGINT, SIGTERM or SIGHUP stops it:
//! the temporary of a save in progress (`.<name>.<pid>.tmp`, as large as
//! the image) is removed, then the process ends by the signal, as it would
//! have without a handler (a script sees the signal in the exit status).
//!
//! The signal is taken on a thread of signal-hook's (the field's standard
//! crate for it), not in a signal handler, so removing files is allowed
//! there. The process then ends through the default action, not `exit`:
//! no exit handler runs while a render thread may still hold the GPU
//! driver (the shutdown that once crashed at exit).

use anyhow::{Context, Result};
use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
use signal_hook::iterator::Signals;

/// Starts the thread that removes pending temporaries when the process is
/// told to stop. Called once by `main` for the headless commands (the
/// viewer keeps its own recovery).
pub fn remove_temporaries_on_signal() -> Result<()> {
    let mut signals =
        Signals::new([SIGINT, SIGTERM, SIGHUP]).context("installing the signal handlers")?;
    std::thread::Builder::new()
        .name("signals".into())
        .spawn(move || {
            if let Some(signal) = signals.forever().next() {
                marbre_core::atomic_write::remove_pending_temporaries();
                let _ = signal_hook::low_level::emulate_default_handler(signal);
            }
        })
        .context("starting the signal thread")?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::BufRead;
    use std::os::unix::process::ExitStatusExt;
    use std::path::PathBuf;
    use std::time::Duration;

    /// Set in the child process the test below starts: the folder to save
    /// in.
    const CHILD_FOLDER: &str = "MARBRE_INTERRUPT_TEST_FOLDER";

    /// Not a test of its own: the child of the one below. A save into
    /// its folder blocks on a FIFO put where the save's temporary goes
    /// (opening a FIFO to write waits for a reader), so that the process
    /// is stopped in the middle of a save.
    #[test]
    #[ignore = "run by a_save_stopped_by_sigterm_leaves_no_temporary"]
    fn child_stopped_while_saving() {
        let Some(folder) = std::env::var_os(CHILD_FOLDER).map(PathBuf::from) else {
            return;
        };
        remove_temporaries_on_signal().unwrap();
        let temporary = folder.join(format!(".out.exr.{}.tmp", std::process::id()));
        let made = std::process::Command::new("mkfifo")
            .arg(&temporary)
            .status()
            .unwrap();
        assert!(made.success());
        let output = folder.join("out.exr");
        std::thread::spawn(move || marbre_core::atomic_write::write_atomic(&output, b"image"));
        // The save lists its temporary before opening it.
        std::thread::sleep(Duration::from_millis(300));
        println!("saving");
        std::thread::sleep(Duration::from_secs(30));
    }

    /// SIGTERM in the middle of a save: the temporary is gone, no output
    /// was written, and the process ended by the signal.
    #[test]
    fn a_save_stopped_by_sigterm_leaves_no_temporary() {
        let folder = tempfile::tempdir().unwrap();
        let mut child = std::process::Command::new(std::env::current_exe().unwrap())
            .args([
                "--exact",
                "interrupt::tests::child_stopped_while_saving",
                "--ignored",
                "--nocapture",
            ])
            .env(CHILD_FOLDER, folder.path())
            .stdout(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        let stdout = std::io::BufReader::new(child.stdout.take().unwrap());
        let saving = stdout
            .lines()
            .map_while(Result::ok)
            .any(|line| line.contains("saving"));
        assert!(saving, "the child never started its save");
        let names = || -> Vec<String> {
            std::fs::read_dir(folder.path())
                .unwrap()
                .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
                .collect()
        };
        assert_eq!(names().len(), 1, "the temporary is there: {:?}", names());
        // SAFETY: kill(2) with the child's pid and a valid signal.
        unsafe { libc::kill(child.id() as i32, libc::SIGTERM) };
        let status = child.wait().unwrap();
        assert_eq!(status.signal(), Some(libc::SIGTERM), "{status:?}");
        assert!(names().is_empty(), "left behind: {:?}", names());
    }
}
