//! The Render dialog's render, running in the background: a snapshot of
//! the scene taken when Render is pressed, traced on its own thread with a
//! second device on the window's adapter (`GpuContext::sibling`) through
//! `final_render::render_to_file`, the function `marbre render` runs.
//!
//! A device of its own, not the window's: the render waits for the GPU
//! after every frame (`session::trace_frame`), which on the window's
//! device would wait for the window's work too, and the window's queue
//! would hold the render's long submits in front of its frames. The
//! window's trace goes on meanwhile; the two share the GPU (or, on
//! lavapipe, the CPU's cores), each frame of the window still within its
//! budget, which the frame budget learns from the trace's own times.

use anyhow::Result;
use marbre_core::scene::Scene;
use marbre_core::texture::ImageSet;
use marbre_render::final_render::{
    FinalRender, Outcome, Progress, RenderObserver, render_to_file, snapshot,
};
use marbre_render::gpu::GpuContext;
use marbre_render::worker::{Worker, names};
use std::ops::ControlFlow;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;

/// What the render thread sends the window.
enum Event {
    Note(String),
    Stage(String),
    Progress(Progress),
    Done(Result<Outcome>),
}

/// What the window learns from a render this frame.
#[derive(Debug)]
pub enum Update {
    /// A line for the messages: the kernel, the error reached, the exposure.
    Note(String),
    /// The render ended: written, cancelled, or failed (the error names the
    /// file where it is about the file).
    Finished(Result<Outcome, String>),
}

/// A render under way.
pub struct RenderJob {
    pub job: FinalRender,
    cancel: Arc<AtomicBool>,
    events: mpsc::Receiver<Event>,
    progress: Option<Progress>,
    /// What it prepares before its first sample.
    stage: String,
    /// When it started: the log says how long it prepared.
    started: web_time::Instant,
    /// The render's thread, with its own device: joined on drop, after the
    /// cancel flag is set (it then stops after its current frame). Held
    /// only to be dropped.
    _worker: Worker,
}

impl Drop for RenderJob {
    /// A render still going when the window closes is cancelled (nothing
    /// is written) and waited for, so that its device is dropped before
    /// the process exits.
    fn drop(&mut self) {
        self.cancel();
    }
}

impl RenderJob {
    /// Starts rendering `scene` (with the `images` the window loaded for
    /// it) as `job` says, on a thread with a second device on `ctx`'s
    /// adapter.
    pub fn start(
        ctx: &GpuContext,
        scene: Scene,
        images: ImageSet,
        job: FinalRender,
    ) -> Result<Self> {
        let device = ctx.sibling()?;
        let cancel = Arc::new(AtomicBool::new(false));
        let (sender, events) = mpsc::channel();
        let mut observer = Sender {
            sender: sender.clone(),
            cancel: cancel.clone(),
        };
        let thread_job = job.clone();
        let worker = Worker::spawn(names::RENDER_JOB, move || {
            observer.stage("reading the scene's environment map");
            let result = snapshot(scene, images)
                .and_then(|loaded| render_to_file(&device, loaded, &thread_job, &mut observer));
            let _ = sender.send(Event::Done(result));
        })?;
        Ok(Self {
            job,
            cancel,
            events,
            progress: None,
            stage: "starting a device".to_owned(),
            started: web_time::Instant::now(),
            _worker: worker,
        })
    }

    /// Asks the render to stop after its current frame; nothing is
    /// written.
    pub fn cancel(&self) {
        self.cancel.store(true, Ordering::Relaxed);
    }

    /// The latest progress reported.
    pub fn progress(&self) -> Option<Progress> {
        self.progress
    }

    /// What the render prepares, until its first progress.
    pub fn stage(&self) -> &str {
        &self.stage
    }

    /// What arrived since the last call; `Finished` comes last, once.
    pub fn poll(&mut self) -> Vec<Update> {
        let mut updates = Vec::new();
        loop {
            match self.events.try_recv() {
                Ok(Event::Note(line)) => updates.push(Update::Note(line)),
                Ok(Event::Stage(what)) => self.stage = what,
                Ok(Event::Progress(p)) => {
                    if self.progress.is_none() {
                        eprintln!(
                            "render: first round of {} traced {:.1} s after the start",
                            self.job.output.display(),
                            self.started.elapsed().as_secs_f64()
                        );
                    }
                    self.progress = Some(p);
                }
                Ok(Event::Done(result)) => {
                    updates.push(Update::Finished(result.map_err(|e| format!("{e:#}"))));
                    return updates;
                }
                Err(mpsc::TryRecvError::Empty) => return updates,
                // The thread ended without a word: it panicked.
                Err(mpsc::TryRecvError::Disconnected) => {
                    updates.push(Update::Finished(Err(format!(
                        "the render of {} stopped unexpectedly",
                        self.job.output.display()
                    ))));
                    return updates;
                }
            }
        }
    }
}

/// The render thread's observer: forwards notes and progress, and answers
/// with the cancel flag.
struct Sender {
    sender: mpsc::Sender<Event>,
    cancel: Arc<AtomicBool>,
}

impl RenderObserver for Sender {
    fn note(&mut self, line: &str) {
        let _ = self.sender.send(Event::Note(line.to_owned()));
    }

    fn stage(&mut self, what: &str) {
        let _ = self.sender.send(Event::Stage(what.to_owned()));
    }

    fn progress(&mut self, progress: &Progress) -> ControlFlow<()> {
        let _ = self.sender.send(Event::Progress(*progress));
        if self.cancel.load(Ordering::Relaxed) {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    }
}
