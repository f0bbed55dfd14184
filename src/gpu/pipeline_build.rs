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

use super::context::GpuContext;
use super::features::FeatureSet;
use super::renderer::Renderer;
use crate::scene::Scene;
use crate::texture::ImageSet;
use anyhow::{Result, anyhow};
use std::sync::{Arc, mpsc};
use std::time::{Duration, Instant};

/// A built trace pipeline and the size of its WGSL.
pub struct BuiltPipeline {
    pub pipeline: wgpu::RenderPipeline,
    pub shader_bytes: usize,
    /// From the request to the pipeline being ready.
    pub took: Duration,
}

/// What to draw once on a second device, so its compiled shader lands in
/// the driver's disk cache before the real device first draws it.
pub struct WarmUp {
    pub ctx: Arc<GpuContext>,
    pub scene: Scene,
    pub images: ImageSet,
    pub features: Option<FeatureSet>,
}

impl WarmUp {
    fn run(self) -> Result<()> {
        let ctx = &*self.ctx;
        let mut renderer = Renderer::new(ctx, &self.scene, None, (1, 1))?;
        renderer.set_feature_override(ctx, self.features)?;
        renderer.set_images(ctx, self.images)?;
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        renderer.trace(ctx, &mut encoder, None);
        ctx.queue.submit([encoder.finish()]);
        ctx.device.poll(wgpu::PollType::wait_indefinitely())?;
        Ok(())
    }
}

/// A trace pipeline being built on a worker thread.
pub struct PipelineBuild {
    receiver: mpsc::Receiver<Result<BuiltPipeline>>,
}

impl PipelineBuild {
    /// Starts building, with `build` (which creates the pipeline on the
    /// render device) after the optional warm-up.
    pub fn start(
        warm_up: Option<WarmUp>,
        build: impl FnOnce() -> Result<(wgpu::RenderPipeline, usize)> + Send + 'static,
    ) -> Self {
        let (sender, receiver) = mpsc::channel();
        let started = Instant::now();
        std::thread::spawn(move || {
            let result = (|| {
                if let Some(warm_up) = warm_up {
                    warm_up.run()?;
                }
                let (pipeline, shader_bytes) = build()?;
                Ok(BuiltPipeline {
                    pipeline,
                    shader_bytes,
                    took: started.elapsed(),
                })
            })();
            // The renderer may have moved on to another build: then nobody
            // listens, and the result is dropped.
            let _ = sender.send(result);
        });
        Self { receiver }
    }

    /// The result, if the build has finished.
    pub fn poll(&self) -> Option<Result<BuiltPipeline>> {
        match self.receiver.try_recv() {
            Ok(result) => Some(result),
            Err(mpsc::TryRecvError::Empty) => None,
            Err(mpsc::TryRecvError::Disconnected) => {
                Some(Err(anyhow!("the shader build thread stopped")))
            }
        }
    }

    /// Waits for the result.
    pub fn wait(&self) -> Result<BuiltPipeline> {
        self.receiver
            .recv()
            .map_err(|_| anyhow!("the shader build thread stopped"))?
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A failed build reports its error through `poll` (the renderer then
    /// keeps its old pipeline); it never panics the render thread.
    #[test]
    fn a_failed_build_reports_its_error() {
        let build = PipelineBuild::start(None, || Err(anyhow!("trace shader: no such function")));
        let result = loop {
            if let Some(result) = build.poll() {
                break result;
            }
            std::thread::sleep(Duration::from_millis(1));
        };
        let message = format!("{:#}", result.err().expect("the build failed"));
        assert!(message.contains("no such function"), "{message}");
    }
}
