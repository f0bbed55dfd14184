//! The viewer's OIDN thread: denoising a 1080p image takes about a second
//! on two CPU cores, many frames, so the viewer hands the read-back image
//! to this thread and keeps drawing; the result comes back a few frames
//! later and is shown from then on.

use super::GuidedImage;
use marbre_core::scene::DenoiseQuality;
use marbre_oidn::{Denoiser, DeviceKind, Library};
use std::sync::Arc;
use std::sync::mpsc::{Receiver, Sender, TryRecvError, channel};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

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
}

impl<Tag: Send + 'static> OidnWorker<Tag> {
    /// Starts the thread; its device is made there, on the first job.
    pub fn start(library: Arc<Library>, device: DeviceKind) -> std::io::Result<Self> {
        let (jobs, inbox) = channel::<Job<Tag>>();
        let (outbox, done) = channel();
        let thread = std::thread::Builder::new()
            .name("oidn".to_owned())
            .spawn(move || {
                let mut denoiser: Option<Denoiser> = None;
                for job in inbox {
                    let start = Instant::now();
                    let oidn = match &mut denoiser {
                        Some(d) => Ok(d),
                        slot => Denoiser::new(library.clone(), device).map(|d| slot.insert(d)),
                    };
                    let (pixels, version) = match oidn {
                        Ok(d) => (
                            job.image.denoise(d, job.quality).map_err(|e| e.to_string()),
                            d.version(),
                        ),
                        Err(e) => (Err(e.to_string()), String::new()),
                    };
                    let done = Done {
                        tag: job.tag,
                        size: job.image.size,
                        pixels,
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

impl<Tag: Send + 'static> Drop for OidnWorker<Tag> {
    /// Waits for the job under way, so that OIDN never runs while the
    /// process exits (issue 26's class of crash at exit).
    fn drop(&mut self) {
        self.jobs = None;
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}
