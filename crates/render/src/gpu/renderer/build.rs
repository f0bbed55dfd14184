//! Deciding what to build for a scene and installing it: the pipeline key
//! (features, generated texture code, override constants, shader sources,
//! kernel), builds on the worker thread, and writing an installed scene
//! into the buffers. What to do is read from the edit's [`Change`],
//! worked out once by the caller: a parameter edit fills the texture
//! numbers from the code's [`ParamPlan`] and never generates code; only a
//! structural one generates it, and only a new key builds a pipeline.

use super::Renderer;
use crate::gpu::context::GpuContext;
use crate::gpu::features::{Feature, FeatureSet};
use crate::gpu::kernel;
use crate::gpu::kernel::Kernel;
use crate::gpu::mesh_buffers::{MeshBuffers, PreparedGeometry};
use crate::gpu::pipeline_build::{BuiltPipeline, PipelineBuild, WarmUp};
use crate::gpu::pipelines::{compile_wgsl, validate};
use crate::gpu::shader_source::{Program, assemble, sources_generation};
use crate::gpu::texture_codegen::{self, ParamPlan};
use crate::gpu::trace_pass::{TraceLayouts, TracePipeline};
use anyhow::Result;
use marbre_core::envmap::EnvImage;
use marbre_core::scene::{Change, Scene};
use marbre_core::texture::ImageSet;
use std::sync::Arc;
use std::time::Duration;

impl Renderer {
    /// The trace pipeline of the key's kernel, and the size of its WGSL.
    pub(super) fn build_trace_pipeline(
        device: &wgpu::Device,
        layouts: &TraceLayouts,
        key: &PipelineKey,
    ) -> Result<(TracePipeline, usize)> {
        let mut features = key.features.clone();
        if key.kernel == Kernel::Cpu {
            features.0.insert(Feature::CpuSamples);
        }
        let source = assemble(Program::Trace, &features, &key.code)?;
        let bytes = source.len();
        let module = compile_wgsl(device, Program::Trace, source)?;
        let pipeline = TracePipeline::build(
            device,
            layouts,
            &module,
            key.kernel,
            &key.switches.constants(),
            key.features.contains(Feature::DenoiseGuides),
        )?;
        Ok((pipeline, bytes))
    }

    /// Traces with `kernel` from now on, waiting for its pipeline (for
    /// headless renders and tests); an error, leaving the current kernel,
    /// if the adapter cannot run it.
    pub fn set_kernel(&mut self, ctx: &GpuContext, kernel: Kernel) -> Result<()> {
        self.choose_kernel(ctx, kernel)?;
        let scene = self.scene.clone();
        self.set_scene(ctx, &scene)
    }

    /// Traces with `kernel` once its pipeline is built, without waiting
    /// (the viewer's Kernel switch): the current one draws until then.
    pub fn request_kernel(&mut self, ctx: &GpuContext, kernel: Kernel) -> Result<()> {
        self.choose_kernel(ctx, kernel)?;
        self.rebuild(ctx)
    }

    /// The scene last requested: the build's under way, else the one
    /// drawing. The viewer works out each frame's [`Change`] against it.
    pub fn requested_scene(&self) -> &Scene {
        self.trace
            .pending
            .as_ref()
            .map_or(&self.scene, |p| &p.target.scene)
    }

    /// Builds the pipeline again, without waiting, if what its key reads
    /// besides the scene changed (the shader files `marbre --dev`
    /// reloads).
    pub fn rebuild(&mut self, ctx: &GpuContext) -> Result<()> {
        let scene = self.requested_scene().clone();
        self.start_scene(ctx, &scene, Change::empty(), true)
    }

    fn choose_kernel(&mut self, ctx: &GpuContext, kernel: Kernel) -> Result<()> {
        if kernel == Kernel::Compute && !self.trace.compute_supported {
            kernel::resolve(ctx, kernel::KernelChoice::Compute)?;
        }
        self.trace.kernel = kernel;
        Ok(())
    }

    /// Geometry prepared off the render thread for the next scene set
    /// (see [`PreparedGeometry`]): that scene's BVH is not built again.
    pub fn provide_geometry(&mut self, prepared: PreparedGeometry) {
        self.bindings.meshes.provide(prepared);
    }

    /// Applies an edited scene and waits for any shader it needs: for
    /// headless renders and tests. If the build fails, the previous pipeline
    /// and scene stay and the error is returned.
    pub fn set_scene(&mut self, ctx: &GpuContext, scene: &Scene) -> Result<()> {
        let change = scene.changes_from(self.requested_scene());
        // Waiting here, the first draw may as well compile on this device:
        // no warm-up.
        self.start_scene(ctx, scene, change, false)?;
        match self.trace.pending.take() {
            Some(mut pending) => {
                let built = pending.build.wait()?;
                self.install(ctx, built, &mut pending);
                Ok(())
            }
            None => Ok(()),
        }
    }

    /// Applies an edited scene without waiting: for the viewer, which
    /// says what changed since the scene it last requested (`change`, from
    /// [`Scene::changes_from`]). Parameter edits only rewrite buffers and
    /// show at the next frame. An edit that changes the feature set or the
    /// texture trees' structure starts a pipeline build on a worker thread;
    /// until [`Renderer::poll_build`] reports it done, the old pipeline
    /// keeps rendering the old scene (with the new camera). A later edit of
    /// the same structure joins that build.
    pub fn request_scene(&mut self, ctx: &GpuContext, scene: &Scene, change: Change) -> Result<()> {
        if change.is_empty() {
            return Ok(());
        }
        self.start_scene(ctx, scene, change, true)
    }

    /// [`Renderer::request_scene`], warming the driver's shader cache on a
    /// second device first if `warm_up` (and the adapter compiles at draw).
    fn start_scene(
        &mut self,
        ctx: &GpuContext,
        scene: &Scene,
        change: Change,
        warm_up: bool,
    ) -> Result<()> {
        if change.contains(Change::GEOMETRY) {
            MeshBuffers::check_fits(&ctx.device.limits(), scene)?;
        }
        let features = self
            .trace
            .feature_override
            .clone()
            .unwrap_or_else(|| FeatureSet::for_scene(scene));
        let switches = RenderSwitches::of(scene);
        let (textures, params) = self.texture_numbers(scene, change)?;
        let latest = self
            .trace
            .pending
            .as_ref()
            .map_or(&self.trace.key, |p| &p.key);
        let same_pipeline = textures
            .as_ref()
            .is_none_or(|(wgsl, _)| *wgsl == latest.code)
            && features == latest.features
            && switches == latest.switches
            && self.trace.kernel.for_scene(scene) == latest.kernel
            && sources_generation() == latest.sources;
        let target = Target {
            scene: scene.clone(),
            params,
            change,
        };
        if same_pipeline {
            match &mut self.trace.pending {
                Some(pending) => {
                    pending.target.join(target);
                    self.follow_camera(scene, change);
                }
                None => self.apply(ctx, target),
            }
            return Ok(());
        }
        let (code, plan) = match textures {
            Some(textures) => textures,
            None => (latest.code.clone(), self.latest_plan().clone()),
        };
        let key = PipelineKey {
            features,
            code,
            switches,
            sources: sources_generation(),
            kernel: self.trace.kernel.for_scene(scene),
        };
        if key == self.trace.key {
            // Back to the pipeline in place (an edit undone while its build
            // ran): the scene differs from the installed one by more than
            // this edit, so everything is written.
            self.trace.pending = None;
            self.apply(
                ctx,
                Target {
                    change: Change::all(),
                    ..target
                },
            );
            return Ok(());
        }
        if let Some(pending) = &mut self.trace.pending
            && pending.key == key
        {
            pending.target.join(target);
            self.follow_camera(scene, change);
            return Ok(());
        }
        let warm_context = if warm_up {
            self.warm_up_context(ctx)
        } else {
            None
        };
        let warm_up = warm_context.map(|warm| {
            let warm_up = ShaderWarmUp {
                ctx: warm,
                scene: scene.clone(),
                images: self.bindings.images.clone(),
                features: self.trace.feature_override.clone(),
                kernel: self.trace.kernel,
            };
            Box::new(move || warm_up.run()) as WarmUp
        });
        let (device, layouts) = (ctx.device.clone(), self.trace.layouts.clone());
        let build_key = key.clone();
        let build = self.trace.builder.start(warm_up, move || {
            Self::build_trace_pipeline(&device, &layouts, &build_key)
        });
        self.trace.pending = Some(PendingScene {
            build,
            key,
            plan,
            target,
        });
        self.follow_camera(scene, change);
        Ok(())
    }

    /// The plan of the latest requested texture code: the build's under
    /// way, else the one drawing.
    fn latest_plan(&self) -> &ParamPlan {
        self.trace
            .pending
            .as_ref()
            .map_or(&self.trace.texture_plan, |p| &p.plan)
    }

    /// The texture code (with its plan) and numbers `scene` needs after
    /// `change`: all generated for a structural edit; for a parameter edit
    /// only the numbers, filled by the plan of the code in place; neither
    /// for an edit away from the materials.
    fn texture_numbers(&mut self, scene: &Scene, change: Change) -> Result<TextureNumbers> {
        if !change.regenerates_code() && change.contains(Change::MATERIAL_PARAMETERS) {
            if let Some(params) = self.latest_plan().evaluate(scene, &self.bindings.images) {
                return Ok((None, Some(params)));
            }
            // The change was worked out against another scene than the
            // plan's (a caller's slip): generating is always right.
            log::warn!("a parameter edit did not fit the texture code in place; generating it");
        } else if !change.regenerates_code() {
            return Ok((None, None));
        }
        let textures = texture_codegen::generate(scene, &self.bindings.images)?;
        self.trace.code_generations += 1;
        Ok((Some((textures.wgsl, textures.plan)), Some(textures.params)))
    }

    /// Whether a pipeline build is under way.
    pub fn is_building(&self) -> bool {
        self.trace.pending.is_some()
    }

    /// Installs a finished build and its scene. Returns how long the build
    /// took, or why it failed (the old pipeline and scene then stay); None
    /// while nothing has finished.
    pub fn poll_build(&mut self, ctx: &GpuContext) -> Option<Result<Duration>> {
        let result = self.trace.pending.as_ref()?.build.poll()?;
        let mut pending = self.trace.pending.take()?;
        Some(result.map(|built| {
            let took = built.took;
            self.install(ctx, built, &mut pending);
            took
        }))
    }

    /// How long the last pipeline build took, from the edit to the new
    /// pipeline (the Stats panel shows it).
    pub fn last_build(&self) -> Option<Duration> {
        self.trace.last_build
    }

    fn install(&mut self, ctx: &GpuContext, built: BuiltPipeline, pending: &mut PendingScene) {
        self.trace.pipeline = built.pipeline;
        self.trace.shader_bytes = built.shader_bytes;
        self.trace.last_build = Some(built.took);
        // Another kernel for the same code traces the same image (the same
        // samples into the same targets): the samples so far stay, as for
        // any edit that keeps the image (the viewer's auto kernel choice
        // lands a few seconds after the first image).
        let same_image = self.trace.key.traces_as(&pending.key);
        self.trace.key = std::mem::take(&mut pending.key);
        self.trace.texture_plan = std::mem::take(&mut pending.plan);
        let scene = std::mem::take(&mut pending.target.scene);
        // The installed scene may be several edits behind: everything is
        // written. A new pipeline otherwise draws a new image even for the
        // same scene (a feature compiled out): the samples of the old one
        // must go.
        let change = if same_image {
            // A round half traced by the other kernel is traced again
            // whole by this one. The edits that waited for the build are
            // the target's change, joined as they came: the scenes are
            // not compared again.
            self.accumulation.restart_round();
            pending.target.change
        } else {
            self.reset_accumulation();
            Change::all()
        };
        let target = Target {
            scene,
            params: pending.target.params.take(),
            change,
        };
        self.apply(ctx, target);
    }

    /// Writes a scene whose pipeline is in place into the buffers its
    /// change touches. (The frame uniform, which holds the camera, the
    /// lights and the render settings, is written at each trace.)
    fn apply(&mut self, ctx: &GpuContext, target: Target) {
        if let Some(params) = &target.params {
            self.bindings.write_texture_params(ctx, params);
        }
        let (scene, change) = (&target.scene, target.change);
        if change
            .intersects(Change::GEOMETRY | Change::MATERIAL_PARAMETERS | Change::MATERIAL_STRUCTURE)
        {
            self.bindings.geometry.write(&ctx.queue, scene);
        }
        self.bindings.meshes.update(&ctx.device, scene, change);
        self.cpu_scene = None;
        // Display-only edits (exposure, auto exposure, tone map, the debug
        // view) keep the samples.
        if change.resets_accumulation() {
            self.reset_accumulation();
        }
        self.scene = target.scene;
    }

    /// While a build is pending the old scene is drawn, but seen from the
    /// new camera: orbiting stays live.
    fn follow_camera(&mut self, scene: &Scene, change: Change) {
        if change.contains(Change::CAMERA) {
            self.scene.camera = scene.camera;
            self.reset_accumulation();
        }
    }

    /// The second device that warms the driver's shader cache, on CPU
    /// adapters only (created at the first build; None if it cannot be).
    fn warm_up_context(&mut self, ctx: &GpuContext) -> Option<Arc<GpuContext>> {
        if !ctx.is_cpu() {
            return None;
        }
        if self.trace.warm_up.is_none() {
            self.trace.warm_up = ctx.sibling().ok().map(Arc::new);
        }
        self.trace.warm_up.clone()
    }

    /// Builds the shader with `features` instead of the scene's own set
    /// (`None` goes back to specialising per scene).
    pub fn set_feature_override(
        &mut self,
        ctx: &GpuContext,
        features: Option<FeatureSet>,
    ) -> Result<()> {
        self.trace.feature_override = features;
        let scene = self.scene.clone();
        self.set_scene(ctx, &scene)
    }

    /// Builds the shader with `features` instead of the scene's own set,
    /// without waiting (the viewer's feature-cost toggles). The set is
    /// checked first: a feature the texture code calls cannot be left out,
    /// and the error says so while the current shader stays.
    pub fn request_feature_override(
        &mut self,
        ctx: &GpuContext,
        features: Option<FeatureSet>,
    ) -> Result<()> {
        let code = self
            .trace
            .pending
            .as_ref()
            .map_or(&self.trace.key.code, |p| &p.key.code);
        if let Some(set) = &features {
            let source = assemble(Program::Trace, set, code)?;
            validate(&source).map_err(|e| {
                anyhow::anyhow!("this scene's shader cannot be built with those features: {e}")
            })?;
        }
        self.trace.feature_override = features;
        self.rebuild(ctx)
    }

    /// Goes back to specialising per scene at the next scene request,
    /// without building anything now (the caller is about to request a
    /// scene whose features changed).
    pub fn forget_feature_override(&mut self) {
        self.trace.feature_override = None;
    }

    /// Replaces the images the scene's image textures read (loaded by
    /// `ImageSet::load`): uploads their atlas and regenerates the texture
    /// code, which holds where each image lies. A pending build is finished
    /// first (its code assumed the old images).
    pub fn set_images(&mut self, ctx: &GpuContext, images: ImageSet) -> Result<()> {
        if let Some(mut pending) = self.trace.pending.take() {
            let built = pending.build.wait()?;
            self.install(ctx, built, &mut pending);
        }
        let textures = texture_codegen::generate(&self.scene, &images)?;
        self.trace.code_generations += 1;
        self.trace.texture_plan = textures.plan;
        if textures.wgsl != self.trace.key.code {
            let key = PipelineKey {
                code: textures.wgsl,
                ..self.trace.key.clone()
            };
            (self.trace.pipeline, self.trace.shader_bytes) =
                Self::build_trace_pipeline(&ctx.device, &self.trace.layouts, &key)?;
            self.trace.key = key;
        }
        self.bindings.write_texture_params(ctx, &textures.params);
        self.bindings.set_images(ctx, images);
        self.reset_accumulation();
        Ok(())
    }

    /// Replaces the environment image (None: a black 1×1 placeholder). One
    /// larger than the GPU's textures is downscaled to fit (as
    /// `session::load_environment` does with a note), never refused.
    pub fn set_environment(&mut self, ctx: &GpuContext, env: Option<&EnvImage>) {
        self.bindings.set_environment(ctx, env);
        self.reset_accumulation();
    }
}

/// What an edit needs of the texture code: the code generated anew with
/// its plan (structural edits), and the numbers to write (parameter edits
/// too); None where it needs nothing new.
type TextureNumbers = (Option<(String, ParamPlan)>, Option<Vec<[f32; 4]>>);

/// A scene to write into the buffers once its pipeline is in place: the
/// texture parameters if they changed, and what changed.
pub(super) struct Target {
    pub(super) scene: Scene,
    pub(super) params: Option<Vec<[f32; 4]>>,
    pub(super) change: Change,
}

impl Target {
    /// A later edit waiting for the same pipeline: its scene, its numbers
    /// (or those already waiting), both changes.
    fn join(&mut self, later: Target) {
        self.params = later.params.or(self.params.take());
        self.change |= later.change;
        self.scene = later.scene;
    }
}

/// What a trace pipeline is built from: two scenes with equal keys share
/// one. The features and texture code make the module; the switches are
/// its override constants.
#[derive(Debug, Clone, PartialEq, Default)]
pub(super) struct PipelineKey {
    pub(super) features: FeatureSet,
    pub(super) code: String,
    pub(super) switches: RenderSwitches,
    /// The shader files' generation (`marbre --dev` reloads them).
    pub(super) sources: u64,
    pub(super) kernel: Kernel,
}

impl PipelineKey {
    /// Whether a pipeline of `other` traces what one of `self` does: the
    /// same code, features, switches and sources, whatever the kernel.
    pub(super) fn traces_as(&self, other: &PipelineKey) -> bool {
        let PipelineKey {
            features,
            code,
            switches,
            sources,
            kernel: _,
        } = self;
        *features == other.features
            && *code == other.code
            && *switches == other.switches
            && *sources == other.sources
    }
}

/// The render settings the trace shader reads as override constants
/// (declared in shaders/textures.wgsl).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(super) struct RenderSwitches {
    pub(super) filter_checkers: bool,
    pub(super) clamp_octaves: bool,
}

impl RenderSwitches {
    pub(super) fn of(scene: &Scene) -> Self {
        Self {
            filter_checkers: scene.render.filter_checkers,
            clamp_octaves: scene.render.clamp_octaves,
        }
    }

    fn constants(self) -> [(&'static str, f64); 2] {
        [
            ("filter_checkers", f64::from(u8::from(self.filter_checkers))),
            ("clamp_octaves", f64::from(u8::from(self.clamp_octaves))),
        ]
    }
}

/// A pipeline build under way, with the key it is built for.
pub(super) struct PendingScene {
    pub(super) build: PipelineBuild,
    pub(super) key: PipelineKey,
    /// Where the numbers of the key's texture code come from.
    pub(super) plan: ParamPlan,
    pub(super) target: Target,
}

/// What to draw once on a second device, so its compiled shader lands in
/// the driver's disk cache before the real device first draws it
/// (`pipeline_build` runs it on its worker before the build).
pub(super) struct ShaderWarmUp {
    pub(super) ctx: Arc<GpuContext>,
    pub(super) scene: Scene,
    pub(super) images: ImageSet,
    pub(super) features: Option<FeatureSet>,
    /// The kernel being built: each compiles its own entry point.
    pub(super) kernel: Kernel,
}

impl ShaderWarmUp {
    fn run(self) -> Result<()> {
        let ctx = &*self.ctx;
        let mut renderer = Renderer::with_kernel(ctx, &self.scene, None, (1, 1), self.kernel)?;
        renderer.set_feature_override(ctx, self.features)?;
        renderer.set_images(ctx, self.images)?;
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        renderer.trace(ctx, &mut encoder, None);
        ctx.queue.submit([encoder.finish()]);
        ctx.device.poll(wgpu::PollType::wait_indefinitely())?;
        Ok(())
    }
}
