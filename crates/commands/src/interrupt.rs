//! What a headless command does when SIGINT, SIGTERM or SIGHUP stops it:
//! the programs it runs (ffmpeg writing an animation) are ended and waited
//! for, the temporary of a save in progress (`.<name>.<pid>.tmp`, as large
//! as the image, or ffmpeg's video) is removed, then the process ends by
//! the signal, as it would have without a handler (a script sees the
//! signal in the exit status).
//!
//! The signal is taken on a thread of signal-hook's (the field's standard
//! crate for it), not in a signal handler, so removing files is allowed
//! there. The process then ends through the default action, not `exit`:
//! no exit handler runs while a render thread may still hold the GPU
//! driver (the shutdown that once crashed at exit).

use anyhow::{Context, Result};
use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
use signal_hook::iterator::Signals;

/// Starts the thread that ends the children and removes pending
/// temporaries when the process is told to stop. Called once by `main`
/// for the headless commands (the viewer keeps its own recovery).
pub fn remove_temporaries_on_signal() -> Result<()> {
    let mut signals =
        Signals::new([SIGINT, SIGTERM, SIGHUP]).context("installing the signal handlers")?;
    std::thread::Builder::new()
        .name("signals".into())
        .spawn(move || {
            if let Some(signal) = signals.forever().next() {
                // First: a child still running would write its temporary
                // again after it is removed.
                marbre_core::child_process::end_all();
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

    /// Set in the child process of the ffmpeg test below: the video to
    /// write.
    const CHILD_VIDEO: &str = "MARBRE_INTERRUPT_TEST_VIDEO";

    /// Not a test of its own: the child of the one below. It writes an
    /// MP4 through the real ffmpeg from frames that stop coming after the
    /// first, so that ffmpeg is running, its output begun, when the
    /// signal comes.
    #[test]
    #[ignore = "run by sigterm_during_an_animation_ends_ffmpeg_and_leaves_nothing"]
    fn child_stopped_while_ffmpeg_encodes() {
        let Some(video) = std::env::var_os(CHILD_VIDEO).map(PathBuf::from) else {
            return;
        };
        remove_temporaries_on_signal().unwrap();
        let frame = image::RgbaImage::from_pixel(16, 16, image::Rgba([200, 100, 50, 255]));
        let frames = std::iter::once(Ok(frame)).chain(std::iter::from_fn(|| {
            println!("encoding");
            std::thread::sleep(Duration::from_secs(600));
            None
        }));
        marbre_core::animated_image::save_through_ffmpeg(frames, 24.0, &video).unwrap();
    }

    /// The children of `pid` (every thread's), from /proc.
    fn children_of(pid: u32) -> Vec<u32> {
        let Ok(tasks) = std::fs::read_dir(format!("/proc/{pid}/task")) else {
            return Vec::new();
        };
        tasks
            .flatten()
            .filter_map(|t| std::fs::read_to_string(t.path().join("children")).ok())
            .flat_map(|s| {
                s.split_whitespace()
                    .filter_map(|p| p.parse().ok())
                    .collect::<Vec<u32>>()
            })
            .collect()
    }

    /// Whether `pid` is a process that still runs (not gone, not a
    /// zombie waiting for its parent).
    fn running(pid: u32) -> bool {
        std::fs::read_to_string(format!("/proc/{pid}/stat")).is_ok_and(|stat| {
            let state = stat.rsplit_once(')').map(|(_, rest)| rest.trim_start());
            !state.is_some_and(|s| s.starts_with('Z') || s.starts_with('X'))
        })
    }

    /// SIGTERM while ffmpeg encodes: ffmpeg is ended with the command (it
    /// used to outlive it by seconds, still writing), and neither the
    /// save's temporary nor anything in the temporary folder (ffmpeg's
    /// `out.mp4` used to stay there) is left. With the real ffmpeg;
    /// without it a loud skip (a failure under MARBRE_REQUIRE_GPU=1).
    #[test]
    fn sigterm_during_an_animation_ends_ffmpeg_and_leaves_nothing() {
        let has_ffmpeg = std::process::Command::new("ffmpeg")
            .arg("-version")
            .stdout(std::process::Stdio::null())
            .status()
            .is_ok_and(|s| s.success());
        if !has_ffmpeg {
            let banner = "SKIPPED sigterm_during_an_animation_ends_ffmpeg_and_leaves_nothing: \
                          ffmpeg is not installed (Debian package `ffmpeg`)";
            assert!(
                std::env::var("MARBRE_REQUIRE_GPU").as_deref() != Ok("1"),
                "{banner} (MARBRE_REQUIRE_GPU=1 turns the skip into a failure)"
            );
            eprintln!("\n{}\n{banner}\n{}\n", "!".repeat(72), "!".repeat(72));
            return;
        }
        let (folder, tmp) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
        let video = folder.path().join("x.mp4");
        let mut child = std::process::Command::new(std::env::current_exe().unwrap())
            .args([
                "--exact",
                "interrupt::tests::child_stopped_while_ffmpeg_encodes",
                "--ignored",
                "--nocapture",
            ])
            .env(CHILD_VIDEO, &video)
            .env("TMPDIR", tmp.path())
            .stdout(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        let stdout = std::io::BufReader::new(child.stdout.take().unwrap());
        let encoding = stdout
            .lines()
            .map_while(Result::ok)
            .any(|line| line.contains("encoding"));
        assert!(encoding, "the child never started ffmpeg");
        // The first frame is written to ffmpeg before the second is asked
        // for: ffmpeg is its child now, though perhaps not yet past its
        // exec (the frame waits in the pipe): until then the child has
        // its parent's name. Waited for, with a bound that fails loudly.
        let ffmpeg = children_of(child.id());
        assert_eq!(ffmpeg.len(), 1, "one child, ffmpeg: {ffmpeg:?}");
        let started = std::time::Instant::now();
        loop {
            let comm = std::fs::read_to_string(format!("/proc/{}/comm", ffmpeg[0])).unwrap();
            if comm.trim() == "ffmpeg" {
                break;
            }
            assert!(
                started.elapsed() < Duration::from_secs(300),
                "the child {} is still {comm:?}, not ffmpeg",
                ffmpeg[0]
            );
            std::thread::sleep(Duration::from_millis(10));
        }
        // SAFETY: kill(2) with the child's pid and a valid signal.
        unsafe { libc::kill(child.id() as i32, libc::SIGTERM) };
        let status = child.wait().unwrap();
        assert_eq!(status.signal(), Some(libc::SIGTERM), "{status:?}");
        assert!(!running(ffmpeg[0]), "ffmpeg {} outlived marbre", ffmpeg[0]);
        let left = |dir: &std::path::Path| -> Vec<_> {
            std::fs::read_dir(dir)
                .unwrap()
                .map(|e| e.unwrap().path())
                .collect()
        };
        assert!(left(folder.path()).is_empty(), "{:?}", left(folder.path()));
        assert!(left(tmp.path()).is_empty(), "{:?}", left(tmp.path()));
    }
}
