//! The viewer's OIDN thread: denoising a 1080p image takes about a second
//! on two CPU cores, many frames, so the viewer hands the read-back image
//! to this thread and keeps drawing; the result comes back a few frames
//! later and is shown from then on.

use super::GuidedImage;
use marbre_core::scene::DenoiseQuality;
use marbre_oidn::{Denoiser, DeviceKind, Library, OidnError};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, Sender, TryRecvError, channel};
use std::thread::JoinHandle;
use std::time::Duration;
use web_time::Instant;

/// An image to denoise, tagged with what it was read from.
pub struct Job<Tag> {
    pub tag: Tag,
    pub image: GuidedImage,
    pub quality: DenoiseQuality,
}

/// A denoised image, or why not.
pub struct Done<Tag> {
    pub tag: Tag,
    pub size: (u32, u32),
    pub pixels: Result<Vec<[f32; 4]>, String>,
    /// Stopped by [`OidnWorker::cancel`] (then `pixels` is an error).
    pub cancelled: bool,
    /// The filter's wall time on the thread.
    pub took: Duration,
    pub version: String,
}

/// One background thread owning an OIDN device, fed one job at a time.
pub struct OidnWorker<Tag: Send + 'static> {
    jobs: Option<Sender<Job<Tag>>>,
    done: Receiver<Done<Tag>>,
    thread: Option<JoinHandle<()>>,
    busy: bool,
    device: DeviceKind,
    /// Shared with the thread's denoiser: set, its filter stops.
    cancel: Arc<AtomicBool>,
}

impl<Tag: Send + 'static> OidnWorker<Tag> {
    /// Starts the thread; its device is made there, on the first job.
    pub fn start(library: Arc<Library>, device: DeviceKind) -> std::io::Result<Self> {
        let (jobs, inbox) = channel::<Job<Tag>>();
        let (outbox, done) = channel();
        let cancel = Arc::new(AtomicBool::new(false));
        let flag = cancel.clone();
        let thread = std::thread::Builder::new()
            .name("oidn".to_owned())
            .spawn(move || {
                yield_to_the_renderer();
                let mut denoiser: Option<Denoiser> = None;
                for job in inbox {
                    let start = Instant::now();
                    let oidn = match &mut denoiser {
                        Some(d) => Ok(d),
                        slot => Denoiser::new(library.clone(), device).map(|mut d| {
                            d.share_cancel_flag(flag.clone());
                            slot.insert(d)
                        }),
                    };
                    let (result, version) = match oidn {
                        Ok(d) => (job.image.denoise(d, job.quality), d.version()),
                        Err(e) => (Err(e.into()), String::new()),
                    };
                    let cancelled = result
                        .as_ref()
                        .is_err_and(|e| e.downcast_ref::<OidnError>().is_some_and(|e| e.cancelled));
                    let done = Done {
                        tag: job.tag,
                        size: job.image.size,
                        pixels: result.map_err(|e| e.to_string()),
                        cancelled,
                        took: start.elapsed(),
                        version,
                    };
                    if outbox.send(done).is_err() {
                        break;
                    }
                }
            })?;
        Ok(Self {
            jobs: Some(jobs),
            done,
            thread: Some(thread),
            busy: false,
            device,
            cancel,
        })
    }

    pub fn device(&self) -> DeviceKind {
        self.device
    }

    /// Whether a job is under way (one at a time: the next waits for
    /// this one's result, so a slow filter never queues images up).
    pub fn is_busy(&self) -> bool {
        self.busy
    }

    /// Hands a job over; false (and the job dropped) while busy.
    pub fn submit(&mut self, job: Job<Tag>) -> bool {
        if self.busy {
            return false;
        }
        // Cleared here, not on the thread, so that a cancel between this
        // and the job's start still stops it.
        self.cancel.store(false, Ordering::Relaxed);
        let sent = self.jobs.as_ref().is_some_and(|s| s.send(job).is_ok());
        self.busy = sent;
        sent
    }

    /// The finished job, if one came back since the last call.
    pub fn take(&mut self) -> Option<Done<Tag>> {
        match self.done.try_recv() {
            Ok(done) => {
                self.busy = false;
                Some(done)
            }
            Err(TryRecvError::Empty) => None,
            Err(TryRecvError::Disconnected) => {
                self.busy = false;
                None
            }
        }
    }
}

/// Lowers this thread's scheduling priority (nice 10), before OIDN makes
/// its worker threads, which inherit it. On a CPU adapter (lavapipe) OIDN
/// and the trace share the cores: at equal priority OIDN's threads took
/// most of them, and a round of the Cornell box took 6.5 s instead of
/// 1.1 s while OIDN ran. The image being refined matters more than its
/// denoised preview, so OIDN gets what the trace leaves. (Linux's nice is
/// per thread; elsewhere the threads keep their priority.)
fn yield_to_the_renderer() {
    #[cfg(target_os = "linux")]
    {
        // SAFETY: gettid and setpriority on this thread only.
        let failed = unsafe {
            let tid = libc::gettid();
            libc::setpriority(libc::PRIO_PROCESS, tid as libc::id_t, 10) != 0
        };
        if failed {
            log::debug!(
                "OIDN thread: could not lower its priority: {}",
                std::io::Error::last_os_error()
            );
        }
    }
}

impl<Tag: Send + 'static> OidnWorker<Tag> {
    /// Stops the job under way at OIDN's next progress report; its result
    /// comes back cancelled.
    pub fn cancel(&self) {
        self.cancel.store(true, Ordering::Relaxed);
    }

    /// The job under way's result, waiting for it; `None` when idle.
    pub fn wait(&mut self) -> Option<Done<Tag>> {
        if !self.busy {
            return None;
        }
        self.busy = false;
        self.done.recv().ok()
    }
}

impl<Tag: Send + 'static> Drop for OidnWorker<Tag> {
    /// Cancels the job under way and waits for the thread, so that OIDN
    /// never runs while the process exits (issue 26's class of crash at
    /// exit) and closing the window does not wait out a denoise.
    fn drop(&mut self) {
        self.cancel();
        self.jobs = None;
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn job(size: (u32, u32), tag: u32) -> Job<u32> {
        let n = (size.0 * size.1) as usize;
        Job {
            tag,
            image: GuidedImage {
                size,
                mean: vec![[0.5, 0.5, 0.5, 1.0]; n],
                albedo: vec![[0.5, 0.5, 0.5, 1.0]; n],
                normal: vec![[0.5, 0.5, 1.0, 1.0]; n],
            },
            quality: DenoiseQuality::High,
        }
    }

    /// One job at a time; a cancelled one comes back cancelled, with no
    /// pixels, and the thread takes the next.
    #[test]
    fn a_cancelled_job_comes_back_cancelled_and_the_next_runs() {
        let test = "a_cancelled_job_comes_back_cancelled_and_the_next_runs";
        let Some(library) = marbre_oidn::library_or_skip(test) else {
            return;
        };
        let mut worker = OidnWorker::start(library, DeviceKind::Cpu).unwrap();
        assert!(worker.submit(job((1920, 1080), 1)));
        assert!(!worker.submit(job((8, 8), 2)), "a second job while busy");
        worker.cancel();
        let done = worker.wait().expect("the first job's result");
        assert_eq!(done.tag, 1);
        assert!(done.cancelled && done.pixels.is_err());
        assert!(worker.submit(job((32, 16), 3)));
        let done = worker.wait().unwrap();
        assert!(!done.cancelled);
        assert_eq!(done.pixels.unwrap().len(), 32 * 16);
        assert!(done.version.starts_with("2."), "{}", done.version);
    }
}
