//! Building the trace pipeline off the render thread, so that after a
//! structural edit the old pipeline keeps rendering until the new one is
//! ready, and a build that fails leaves it in place.
//!
//! Where the time goes depends on the driver. A GPU driver compiles at
//! pipeline creation, which the worker thread does. llvmpipe (lavapipe)
//! compiles each shader at its first draw, on the device's queue, where it
//! would stall every frame behind it (measured: 80 ms to create the
//! default preset's pipeline, then about 1 s for the first draw with an
//! empty shader cache, 40 ms with a warm one). So on a CPU adapter the
//! worker first draws one pixel of the new scene on a second device: Mesa
//! stores the compiled shader in its disk cache, and the real device's
//! first draw then finds it there.

use crate::gpu::trace_pass::TracePipeline;
use crate::worker::{Worker, names};
use anyhow::{Result, anyhow};
use std::sync::{Arc, Condvar, Mutex, mpsc};
use std::time::Duration;
use web_time::Instant;

/// A built trace pipeline and the size of its WGSL.
pub struct BuiltPipeline {
    pub pipeline: TracePipeline,
    pub shader_bytes: usize,
    /// From the request to the pipeline being ready.
    pub took: Duration,
}

/// Work to do on the worker before a build: the renderer's warm-up, which
/// draws one pixel of the new scene on a second device (see the module's
/// doc). A closure, so that this module needs no renderer.
pub type WarmUp = Box<dyn FnOnce() -> Result<()> + Send>;

/// The work of one build: an optional warm-up, then creating the pipeline.
type BuildFn = Box<dyn FnOnce() -> Result<(TracePipeline, usize)> + Send>;

/// A build waiting for the worker, and where its result goes.
struct Job {
    warm_up: Option<WarmUp>,
    build: BuildFn,
    sender: mpsc::Sender<Result<BuiltPipeline>>,
    requested: Instant,
}

impl Job {
    fn run(self) {
        let result = (|| {
            if let Some(warm_up) = self.warm_up {
                warm_up()?;
            }
            let (pipeline, shader_bytes) = (self.build)()?;
            Ok(BuiltPipeline {
                pipeline,
                shader_bytes,
                took: self.requested.elapsed(),
            })
        })();
        // The renderer may have moved on to another build: then nobody
        // listens, and the result is dropped.
        let _ = self.sender.send(result);
    }
}

/// The next job for the worker, and whether its owner is gone.
#[derive(Default)]
struct Queue {
    next: Option<Job>,
    closed: bool,
}

/// One worker thread that builds trace pipelines one at a time, always the
/// latest request: a request made while another waits replaces it (that
/// one's result would be superseded anyway). A thread per request instead
/// piled up threads, each with its own allocator arena, during a slider
/// drag over a structural setting: the soak test measured RSS growing from
/// 265 MiB to 1.1 GiB in 300 frames.
pub struct PipelineBuilder {
    queue: Arc<(Mutex<Queue>, Condvar)>,
    /// The worker, once the first build starts; joined on drop.
    worker: Option<Worker>,
}

impl Default for PipelineBuilder {
    fn default() -> Self {
        Self {
            queue: Arc::new((Mutex::new(Queue::default()), Condvar::new())),
            worker: None,
        }
    }
}

impl PipelineBuilder {
    /// Queues a build with `build` (which creates the pipeline on the
    /// render device) after the optional warm-up, replacing any build not
    /// yet started.
    pub fn start(
        &mut self,
        warm_up: Option<WarmUp>,
        build: impl FnOnce() -> Result<(TracePipeline, usize)> + Send + 'static,
    ) -> PipelineBuild {
        let (sender, receiver) = mpsc::channel();
        let job = Job {
            warm_up,
            build: Box::new(build),
            sender,
            requested: Instant::now(),
        };
        // A web page has no thread to build on, and needs none: WebGPU
        // compiles a pipeline in the browser's GPU process, so creating it
        // does not hold the page (issue 34).
        if cfg!(target_arch = "wasm32") {
            job.run();
            return PipelineBuild { receiver };
        }
        let (lock, ready) = &*self.queue;
        lock.lock().unwrap_or_else(|e| e.into_inner()).next = Some(job);
        ready.notify_one();
        if self.worker.is_none() {
            let queue = self.queue.clone();
            // A thread that cannot start drops the job, whose build then
            // reports "dropped before it ran"; the next request tries again.
            match Worker::spawn(names::PIPELINE_BUILD, move || work(&queue)) {
                Ok(worker) => self.worker = Some(worker),
                Err(e) => {
                    log::warn!("cannot start the pipeline builder's thread: {e}");
                    lock.lock().unwrap_or_else(|e| e.into_inner()).next = None;
                }
            }
        }
        PipelineBuild { receiver }
    }
}

/// Drops a waiting build and waits for the one in progress (at most one
/// shader compile). Left running, a build could still be inside the
/// driver's compiler when the process exits and the compiler's global
/// state is destroyed: a 10,000-frame soak ended in LLVM aborting
/// ("Cannot select", signal 6) after its verdict.
impl Drop for PipelineBuilder {
    fn drop(&mut self) {
        let (lock, ready) = &*self.queue;
        {
            let mut queue = lock.lock().unwrap_or_else(|e| e.into_inner());
            queue.closed = true;
            queue.next = None;
        }
        ready.notify_one();
        self.worker = None;
    }
}

/// The worker: runs the latest job until the builder is dropped.
fn work(queue: &(Mutex<Queue>, Condvar)) {
    let (lock, ready) = queue;
    loop {
        let job = {
            let mut queue = lock.lock().unwrap_or_else(|e| e.into_inner());
            loop {
                if let Some(job) = queue.next.take() {
                    break job;
                }
                if queue.closed {
                    return;
                }
                queue = ready.wait(queue).unwrap_or_else(|e| e.into_inner());
            }
        };
        job.run();
    }
}

/// A trace pipeline being built on the builder's worker thread.
pub struct PipelineBuild {
    receiver: mpsc::Receiver<Result<BuiltPipeline>>,
}

impl PipelineBuild {
    /// The result, if the build has finished.
    pub fn poll(&self) -> Option<Result<BuiltPipeline>> {
        match self.receiver.try_recv() {
            Ok(result) => Some(result),
            Err(mpsc::TryRecvError::Empty) => None,
            Err(mpsc::TryRecvError::Disconnected) => {
                Some(Err(anyhow!("the shader build was dropped before it ran")))
            }
        }
    }

    /// Waits for the result.
    pub fn wait(&self) -> Result<BuiltPipeline> {
        self.receiver
            .recv()
            .map_err(|_| anyhow!("the shader build was dropped before it ran"))?
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A failed build reports its error through `poll` (the renderer then
    /// keeps its old pipeline); it never panics the render thread.
    fn result_of(build: &PipelineBuild) -> Result<BuiltPipeline> {
        loop {
            if let Some(result) = build.poll() {
                break result;
            }
            std::thread::sleep(Duration::from_millis(1));
        }
    }

    /// A failed build reports its error through `poll` (the renderer then
    /// keeps its old pipeline); it never panics the render thread.
    #[test]
    fn a_failed_build_reports_its_error() {
        let mut builder = PipelineBuilder::default();
        let build = builder.start(None, || Err(anyhow!("trace shader: no such function")));
        let message = format!("{:#}", result_of(&build).err().expect("the build failed"));
        assert!(message.contains("no such function"), "{message}");
    }

    /// Requests made while one build runs: only the latest runs after it,
    /// the ones in between are dropped unrun, and no thread is added.
    #[test]
    fn a_waiting_build_is_replaced_by_the_next_request() {
        let mut builder = PipelineBuilder::default();
        let (release, hold) = mpsc::channel::<()>();
        let first = builder.start(None, move || {
            hold.recv().ok();
            Err(anyhow!("first"))
        });
        // Let the worker take the first job before queueing the others.
        std::thread::sleep(Duration::from_millis(50));
        let ran = Arc::new(Mutex::new(Vec::new()));
        let job = |name: &'static str| {
            let ran = ran.clone();
            move || {
                ran.lock().unwrap().push(name);
                Err(anyhow!(name))
            }
        };
        let second = builder.start(None, job("second"));
        let third = builder.start(None, job("third"));
        release.send(()).unwrap();
        assert!(format!("{:#}", result_of(&first).err().unwrap()).contains("first"));
        assert!(format!("{:#}", result_of(&third).err().unwrap()).contains("third"));
        let dropped = format!("{:#}", result_of(&second).err().unwrap());
        assert!(dropped.contains("dropped before it ran"), "{dropped}");
        assert_eq!(*ran.lock().unwrap(), ["third"]);
    }

    /// Dropping the builder waits for the build in progress and drops the
    /// one waiting: nothing is left compiling when the process exits.
    #[test]
    fn dropping_the_builder_finishes_the_running_build_and_drops_the_waiting_one() {
        let mut builder = PipelineBuilder::default();
        let finished = Arc::new(Mutex::new(Vec::new()));
        let job = |name: &'static str, millis: u64| {
            let finished = finished.clone();
            move || {
                std::thread::sleep(Duration::from_millis(millis));
                finished.lock().unwrap().push(name);
                Err(anyhow!(name))
            }
        };
        let _running = builder.start(None, job("running", 300));
        std::thread::sleep(Duration::from_millis(50));
        let waiting = builder.start(None, job("waiting", 0));
        drop(builder);
        assert_eq!(*finished.lock().unwrap(), ["running"]);
        let dropped = format!("{:#}", result_of(&waiting).err().unwrap());
        assert!(dropped.contains("dropped before it ran"), "{dropped}");
    }
}
