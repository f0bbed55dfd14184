//! The viewer's side of the preview swatches (`panel/swatches.rs` asks,
//! `marbre_render::gpu::swatch` renders): a worker thread owns the swatch
//! renderer and renders each batch of changed nodes there, waiting for the
//! GPU off the UI thread; the UI thread only takes finished batches and
//! uploads them as egui textures (`Context::load_texture`: 9 KiB per
//! swatch, cheaper to keep than a native texture registered per swatch
//! with its own bind group, and it never waits on the GPU).

use crate::panel::swatches::{SharedSwatchBook, SwatchRequest, install};
use anyhow::Result;
use marbre_core::scene::{Change, Scene};
use marbre_render::gpu::GpuContext;
use marbre_render::gpu::swatch::{MAX_BATCH, SWATCH_SIZE, SwatchPixels, SwatchRenderer, to_srgba8};
use marbre_render::worker::{Worker, names};
use std::sync::mpsc::{Receiver, Sender, TryRecvError, channel};
use web_time::Instant;

/// A batch the worker finished: what was asked, the swatches or why not,
/// and the milliseconds it took (pipeline build included).
struct Finished {
    requests: Vec<SwatchRequest>,
    swatches: Result<Vec<SwatchPixels>>,
    ms: f32,
}

pub struct Swatches {
    book: SharedSwatchBook,
    /// `None` once the worker has gone (its thread could not start).
    jobs: Option<Sender<Vec<SwatchRequest>>>,
    /// The thread that owns the swatch renderer (and a clone of the
    /// device); joined on drop, after `jobs` is closed.
    worker: Option<Worker>,
    finished: Receiver<Finished>,
    in_flight: bool,
    /// Changes the scene went through outside a frame's edits (a preset
    /// loaded, an undo), for the next [`Swatches::after_frame`].
    pending: Change,
    /// Set by `MARBRE_SWATCH_TIMES=1`: each batch's time is printed, and at
    /// the end the UI thread's time in [`Swatches::after_frame`] per frame
    /// (docs/PERFORMANCE.md's numbers).
    print_times: bool,
    /// The UI thread's seconds in `after_frame`, and its calls.
    ui_time: (f64, u64),
}

impl Drop for Swatches {
    /// Closes the job channel, so that the worker ends after the batch it
    /// is rendering, and joins it: the renderer, its device clone and maybe
    /// the last reference to the wgpu instance are dropped on that thread,
    /// which must be done before the process exits (`worker`'s doc).
    fn drop(&mut self) {
        self.jobs = None;
        self.worker = None;
        if self.print_times && self.ui_time.1 > 0 {
            eprintln!(
                "swatches: {:.3} ms per frame on the UI thread over {} frames",
                self.ui_time.0 * 1000.0 / self.ui_time.1 as f64,
                self.ui_time.1
            );
        }
    }
}

impl Swatches {
    /// Starts the worker on a clone of `ctx`'s device and puts a new book
    /// in `egui_ctx`, where the panels find it.
    pub fn new(ctx: &GpuContext, egui_ctx: &egui::Context) -> Self {
        let book = SharedSwatchBook::default();
        install(egui_ctx, book.clone());
        let (jobs, job_queue) = channel::<Vec<SwatchRequest>>();
        let (done, finished) = channel();
        let ctx = ctx.clone();
        let started = Worker::spawn(names::SWATCHES, move || {
            let mut renderer = SwatchRenderer::new(ctx);
            for requests in job_queue {
                let start = Instant::now();
                let textures: Vec<_> = requests.iter().map(|r| r.texture.clone()).collect();
                let swatches = match &mut renderer {
                    Ok(renderer) => renderer.render(&textures),
                    Err(e) => Err(anyhow::anyhow!("{e:#}")),
                };
                let ms = start.elapsed().as_secs_f32() * 1000.0;
                if done
                    .send(Finished {
                        requests,
                        swatches,
                        ms,
                    })
                    .is_err()
                {
                    break;
                }
            }
        });
        let worker = started
            .inspect_err(|e| log::warn!("swatch previews: cannot start the worker: {e}"))
            .ok();
        Self {
            book,
            jobs: worker.is_some().then_some(jobs),
            worker,
            finished,
            in_flight: false,
            print_times: std::env::var_os("MARBRE_SWATCH_TIMES").is_some(),
            pending: Change::empty(),
            ui_time: (0.0, 0),
        }
    }

    /// Notes a change made outside a frame's edits (a preset loaded, an
    /// undo): the next frame's change does not hold it.
    pub fn note(&mut self, change: Change) {
        self.pending |= change;
    }

    /// After the frame's edits, with what they changed: uploads a finished
    /// batch's swatches, lets the book read the subtrees `change` may have
    /// altered, sends the next nodes that changed if no batch is rendering,
    /// and ends the book's frame. Returns an error to show, if a batch
    /// failed.
    pub fn after_frame(
        &mut self,
        egui_ctx: &egui::Context,
        scene: &Scene,
        change: Change,
    ) -> Option<String> {
        let start = Instant::now();
        let change = change | std::mem::replace(&mut self.pending, Change::empty());
        let error = self.exchange(egui_ctx, scene, change);
        self.ui_time.0 += start.elapsed().as_secs_f64();
        self.ui_time.1 += 1;
        error
    }

    fn exchange(
        &mut self,
        egui_ctx: &egui::Context,
        scene: &Scene,
        change: Change,
    ) -> Option<String> {
        let mut error = None;
        match self.finished.try_recv() {
            Ok(done) => {
                self.in_flight = false;
                error = self.deliver(egui_ctx, done);
            }
            Err(TryRecvError::Disconnected) => self.jobs = None,
            Err(TryRecvError::Empty) => {}
        }
        let Ok(mut book) = self.book.lock() else {
            return error;
        };
        book.observe(scene, change);
        if !self.in_flight
            && let Some(jobs) = &self.jobs
        {
            let requests = book.take_requests(MAX_BATCH);
            if !requests.is_empty() {
                self.in_flight = jobs.send(requests).is_ok();
            }
        }
        book.end_frame();
        error
    }

    fn deliver(&self, egui_ctx: &egui::Context, done: Finished) -> Option<String> {
        if self.print_times {
            eprintln!("swatches: {} in {:.1} ms", done.requests.len(), done.ms);
        }
        let swatches = match done.swatches {
            Ok(swatches) => swatches,
            Err(e) => return Some(format!("swatch previews: {e:#}")),
        };
        let Ok(mut book) = self.book.lock() else {
            return None;
        };
        for (request, pixels) in done.requests.iter().zip(swatches) {
            let rgba: Vec<u8> = pixels
                .iter()
                .flat_map(|&p| {
                    let p = if request.scalar {
                        [p[0], p[0], p[0], p[3]]
                    } else {
                        p
                    };
                    to_srgba8(p)
                })
                .collect();
            let image = egui::ColorImage::from_rgba_unmultiplied([SWATCH_SIZE, SWATCH_SIZE], &rgba);
            let handle = egui_ctx.load_texture("swatch", image, egui::TextureOptions::LINEAR);
            book.deliver(&request.place, handle);
        }
        egui_ctx.request_repaint();
        None
    }
}
