//! The progressive renderer: trace pass into a running-mean accumulation
//! target, display pass onto any colour target. It owns every GPU resource
//! derived from the scene and rebuilds only what an edit invalidates.
//!
//! Built from parts that each own their resources (as kajiya's renderer
//! is): `trace_stage` (the pipeline, its builds, the frame ring),
//! `scene_bindings` (the scene's buffers and textures of bind group 0) and
//! `display_stage` (tone mapping, metering, the denoiser), with the
//! accumulation, the error meter and the non-finite counters. Three jobs,
//! one file each, drive them: `build` (what a scene needs, pipelines built
//! off the render thread and installed), `frame` (trace, meters, display)
//! and `readback` (results back to the CPU). This file holds the renderer,
//! its creation and what it reports.

mod build;
mod denoise;
mod display_stage;
mod frame;
mod oidn_stage;
mod readback;
mod scene_bindings;
mod trace_stage;

use build::{PipelineKey, RenderSwitches};
use display_stage::{DisplayStage, MeteredFrom};
use scene_bindings::SceneBindings;
use trace_stage::TraceStage;

use super::accumulation::Accumulation;
use super::context::GpuContext;
use super::error_meter::ErrorMeter;
use super::features::FeatureSet;
use super::kernel::{self, Kernel};
use super::mesh_buffers::MeshStats;
use super::non_finite::NonFiniteCounter;
use super::shader_source::sources_generation;
use super::texture_codegen;
use anyhow::Result;
use marbre_core::envmap::EnvImage;
use marbre_core::scene::Scene;
use marbre_core::texture::ImageSet;
use std::time::Duration;

/// Where the image goes in a target: a rectangle in target pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Viewport {
    pub x: f32,
    pub y: f32,
    pub width: f32,
    pub height: f32,
}

/// Where [`Renderer::display`] draws: a view of a colour target, its
/// format, the rectangle the image goes in, and what the rest starts as.
#[derive(Clone, Copy)]
pub struct DisplayTarget<'a> {
    pub view: &'a wgpu::TextureView,
    pub format: wgpu::TextureFormat,
    pub viewport: Viewport,
    pub load: wgpu::LoadOp<wgpu::Color>,
}

pub struct Renderer {
    scene: Scene,
    /// What the trace pass draws with: its pipeline, the builds of the
    /// next ones and the ring of frame uniforms.
    trace: TraceStage,
    /// The scene's buffers and textures in bind group 0.
    bindings: SceneBindings,
    /// What turns the accumulation into an image: tone mapping, metering
    /// and the denoiser.
    display: DisplayStage,
    accumulation: Accumulation,
    /// Estimates the accumulated image's error from its spread.
    error_meter: ErrorMeter,
    /// Counts the samples the trace pass dropped for being NaN or infinite.
    non_finite: NonFiniteCounter,
    size: (u32, u32),
    /// The tile of a larger image the targets hold, and its size
    /// ([`Renderer::set_crop`]).
    crop: Option<(marbre_core::tile::Tile, (u32, u32))>,
    render_scale: f32,
    frame_index: u32,
    /// The samples per pixel of the rounds that follow when fewer than
    /// the scene's per frame: the last round of an exact `--spp`.
    round_samples: Option<u32>,
    /// The scene as the CPU kernel reads it, made at its first band after
    /// each write of the scene (`apply`).
    cpu_scene: Option<std::sync::Arc<crate::cpu_kernel::CpuScene>>,
}

/// What one trace call did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct TraceWork {
    /// Pixels traced, a preview's included.
    pub pixels: u64,
    /// Rounds completed (each adds `samples_per_frame` samples per pixel).
    pub rounds: u32,
}

impl Renderer {
    /// A renderer tracing with the fragment kernel, which every adapter
    /// runs.
    pub fn new(
        ctx: &GpuContext,
        scene: &Scene,
        env: Option<&EnvImage>,
        size: (u32, u32),
    ) -> Result<Self> {
        Self::with_kernel(ctx, scene, env, size, Kernel::Fragment)
    }

    /// A renderer tracing with `kernel`; an error if the adapter cannot run
    /// it ([`kernel::compute_support`]).
    pub fn with_kernel(
        ctx: &GpuContext,
        scene: &Scene,
        env: Option<&EnvImage>,
        size: (u32, u32),
        kernel: Kernel,
    ) -> Result<Self> {
        super::mesh_buffers::MeshBuffers::check_fits(&ctx.device.limits(), scene)?;
        let compute_supported = kernel::compute_support(ctx).is_ok();
        if kernel == Kernel::Compute {
            kernel::resolve(ctx, kernel::KernelChoice::Compute)?;
        }
        let images = ImageSet::empty();
        let textures = texture_codegen::generate(scene, &images)?;
        let key = PipelineKey {
            features: FeatureSet::for_scene(scene),
            code: textures.wgsl,
            switches: RenderSwitches::of(scene),
            sources: sources_generation(),
            kernel: kernel.for_scene(scene),
        };
        Ok(Self {
            scene: scene.clone(),
            trace: TraceStage::new(ctx, key, kernel, textures.plan, compute_supported)?,
            bindings: SceneBindings::new(ctx, scene, env, images, &textures.params),
            display: DisplayStage::new(&ctx.device)?,
            accumulation: Accumulation::new(&ctx.device, size, compute_supported),
            error_meter: ErrorMeter::new(&ctx.device)?,
            non_finite: NonFiniteCounter::new(&ctx.device),
            size,
            crop: None,
            render_scale: 1.0,
            frame_index: 0,
            round_samples: None,
            cpu_scene: None,
        })
    }

    /// The kernel drawing now.
    pub fn kernel(&self) -> Kernel {
        self.trace.pipeline.kernel()
    }

    /// The kernel asked for: the one drawing, except where the CPU kernel
    /// was asked for and the fragment kernel stands in for a scene it does
    /// not trace (`Kernel::for_scene`).
    pub fn requested_kernel(&self) -> Kernel {
        self.trace.kernel
    }

    /// Triangles, BVH nodes, lights and the last BVH build time.
    pub fn mesh_stats(&self) -> MeshStats {
        self.bindings.meshes.stats()
    }

    /// Notes on emitters left out of the light table.
    pub fn light_notes(&self) -> &[String] {
        &self.bindings.meshes.table().notes
    }

    /// Size of the trace shader's assembled WGSL.
    pub fn trace_shader_bytes(&self) -> usize {
        self.trace.shader_bytes
    }

    pub fn features(&self) -> &FeatureSet {
        &self.trace.key.features
    }

    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// How many times this renderer generated texture code, its first
    /// scene's included: structural edits and new images add one each,
    /// parameter edits none.
    pub fn code_generations(&self) -> u64 {
        self.trace.code_generations
    }

    /// Samples per pixel averaged so far.
    pub fn accumulated_samples(&self) -> u32 {
        self.accumulation.samples()
    }

    /// Frames averaged so far (the error estimate needs two).
    pub fn accumulated_frames(&self) -> u32 {
        self.accumulation.frames()
    }

    /// Time since the first frame of the current accumulation.
    pub fn accumulation_time(&self) -> Duration {
        self.accumulation.elapsed()
    }

    pub fn size(&self) -> (u32, u32) {
        self.size
    }

    /// The size actually traced: the target size times the render scale.
    pub fn render_size(&self) -> (u32, u32) {
        crate::gpu::preview_ladder::scaled(self.size, self.render_scale)
    }

    /// The size of the image on show: the last complete round's traced
    /// region, or its preview's (smaller) while the first round of an
    /// accumulation is under way.
    pub fn shown_size(&self) -> (u32, u32) {
        self.accumulation.shown_size()
    }

    /// Images made so far (complete rounds and previews), wrapping: what
    /// the display shows changes exactly when this does.
    pub fn images_made(&self) -> u32 {
        self.accumulation.shown_count()
    }

    /// The images the texture code reads.
    pub fn images(&self) -> &ImageSet {
        &self.bindings.images
    }

    /// Which accumulation the image holds: it changes at every reset.
    pub fn accumulation_generation(&self) -> u32 {
        self.accumulation.generation()
    }
}

fn bind(binding: u32, resource: wgpu::BindingResource<'_>) -> wgpu::BindGroupEntry<'_> {
    wgpu::BindGroupEntry { binding, resource }
}
