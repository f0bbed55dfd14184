//! The progressive renderer: trace pass into a running-mean accumulation
//! target, display pass onto any colour target. It owns every GPU resource
//! derived from the scene and rebuilds only what an edit invalidates.

use super::accumulation::Accumulation;
use super::auto_exposure::{AutoExposure, Metered};
use super::context::GpuContext;
use super::error_meter::{self, ErrorEstimate, ErrorMeter};
use super::features::FeatureSet;
use super::geometry_buffers::GeometryBuffers;
use super::kernel::{self, Kernel};
use super::mesh_buffers::{MeshBuffers, MeshStats, PreparedGeometry};
use super::non_finite::{self, NonFiniteCounter, NonFiniteCounts};
use super::pass_timer::{Pass, PassTimer};
use super::pipeline_build::{BuiltPipeline, PipelineBuild, PipelineBuilder, WarmUp};
use super::pipelines::{
    compile_wgsl, entry, float_texture, fullscreen_pipeline, permutation_table, shader_module,
    storage, uniform, upload_atlas, upload_rgba16f, validate,
};
use super::readback::read_texture;
use super::scene_gpu::{self, FrameUniform};
use super::shader_source::{Program, assemble, sources_generation};
use super::texture_codegen;
use super::trace_bands::{self, TraceBudget};
use super::trace_pass::{BandPass, PassTimestamps, TraceLayouts, TracePipeline};
use anyhow::Result;
use bytemuck::{Pod, Zeroable};
use marbre_core::env_sampling::EnvDistribution;
use marbre_core::envmap::{self, EnvImage};
use marbre_core::scene::{Scene, ToneMap};
use marbre_core::texture::ImageSet;
use std::collections::HashMap;
use std::sync::Arc;
use std::time::Duration;
use wgpu::util::DeviceExt;

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct DisplayUniform {
    exposure_scale: f32,
    tone_map: u32,
    encode_srgb: u32,
    auto_exposure: u32,
    origin: [f32; 2],
    scale: [f32; 2],
    /// 1: paint the pixels that dropped a non-finite sample magenta.
    show_non_finite: u32,
    padding: u32,
}

/// The accumulation an auto-exposure metering read: the frame that wrote
/// it, the targets' size and the traced region.
#[derive(Clone, Copy, Debug, PartialEq)]
struct MeteredFrom {
    /// Counts the images shown (rounds and previews).
    shown: u32,
    size: (u32, u32),
    render_size: (u32, u32),
}

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

/// A scene waiting for its pipeline: what to write into the buffers once
/// the pipeline is in place (the texture parameters if they changed).
struct Target {
    scene: Scene,
    params: Option<Vec<[f32; 4]>>,
}

/// What a trace pipeline is built from: two scenes with equal keys share
/// one. The features and texture code make the module; the switches are
/// its override constants.
#[derive(Debug, Clone, PartialEq, Default)]
struct PipelineKey {
    features: FeatureSet,
    code: String,
    switches: RenderSwitches,
    /// The shader files' generation (`marbre --dev` reloads them).
    sources: u64,
    kernel: Kernel,
}

/// The render settings the trace shader reads as override constants
/// (declared in shaders/textures.wgsl).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
struct RenderSwitches {
    filter_checkers: bool,
    clamp_octaves: bool,
}

impl RenderSwitches {
    fn of(scene: &Scene) -> Self {
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
struct PendingScene {
    build: PipelineBuild,
    key: PipelineKey,
    target: Target,
}

pub struct Renderer {
    scene: Scene,
    /// A structural edit whose pipeline is being built.
    pending: Option<PendingScene>,
    /// The worker thread that builds trace pipelines, latest request first.
    builder: PipelineBuilder,
    /// The device that warms the shader cache for builds (CPU adapters).
    warm_up: Option<Arc<GpuContext>>,
    last_build: Option<Duration>,
    /// What the trace pipeline was built from: a scene whose key differs
    /// needs a new pipeline.
    key: PipelineKey,
    /// When set, the shader is built with these features whatever the scene
    /// uses: `FeatureSet::all()` is the uber shader the benchmarks compare.
    feature_override: Option<FeatureSet>,
    /// The kernel new pipelines are built for (the key holds the one
    /// drawing now).
    kernel: Kernel,
    /// Whether the adapter runs the compute kernel (its targets are then
    /// storage textures too).
    compute_supported: bool,
    trace_layouts: TraceLayouts,
    trace_pipeline: TracePipeline,
    display_layout: wgpu::BindGroupLayout,
    display_pipelines: HashMap<wgpu::TextureFormat, wgpu::RenderPipeline>,
    display_module: wgpu::ShaderModule,
    /// A ring of [`FRAME_SLOTS`] frame uniforms, one per trace pass: the
    /// passes of one submit each read their own (a `write_buffer` lands
    /// before the whole submit, so one slot would give every pass the
    /// last pass's settings).
    frame_buffer: wgpu::Buffer,
    /// The next slot of the ring to write.
    frame_slot: u64,
    display_buffer: wgpu::Buffer,
    /// Meters the accumulation for auto exposure; the display pass reads
    /// its result buffer.
    auto_exposure: AutoExposure,
    /// What the auto-exposure result was metered from: the display of one
    /// frame on two targets meters once.
    metered_from: Option<MeteredFrom>,
    geometry: GeometryBuffers,
    /// Triangles, their BVH and the light table.
    meshes: MeshBuffers,
    perm_buffer: wgpu::Buffer,
    texture_param_buffer: wgpu::Buffer,
    /// Size of the trace module's WGSL, for the Stats panel.
    trace_shader_bytes: usize,
    env_view: wgpu::TextureView,
    env_sampler: wgpu::Sampler,
    /// The environment's importance-sampling CDFs and their size in cells.
    env_distribution: (wgpu::Buffer, [u32; 2]),
    /// The images the texture code reads, and their atlas on the GPU.
    images: ImageSet,
    image_atlas_view: wgpu::TextureView,
    accumulation: Accumulation,
    /// Estimates the accumulated image's error from its spread.
    error_meter: ErrorMeter,
    /// Counts the samples the trace pass dropped for being NaN or infinite.
    non_finite: NonFiniteCounter,
    size: (u32, u32),
    render_scale: f32,
    frame_index: u32,
}

/// Frame uniforms in the ring: more than the passes of one submit
/// ([`trace_bands::MAX_PASSES`] and a preview).
const FRAME_SLOTS: u64 = 2 * trace_bands::MAX_PASSES as u64;

/// The bytes of one frame-uniform slot: two copies of the settings (see
/// `frame_slots` in shaders/scene.wgsl).
const FRAME_BYTES: u64 = 2 * std::mem::size_of::<FrameUniform>() as u64;

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
        let device = &ctx.device;
        let compute_supported = kernel::compute_support(ctx).is_ok();
        if kernel == Kernel::Compute {
            kernel::resolve(ctx, kernel::KernelChoice::Compute)?;
        }
        let features = FeatureSet::for_scene(scene);
        let frame_entry = wgpu::BindGroupLayoutEntry {
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Uniform,
                has_dynamic_offset: true,
                min_binding_size: wgpu::BufferSize::new(FRAME_BYTES),
            },
            ..entry(0, uniform())
        };
        let trace_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("trace"),
            entries: &[
                // A slot of the frame ring, at a dynamic offset.
                frame_entry,
                entry(GeometryBuffers::BINDINGS[0], uniform()),
                entry(GeometryBuffers::BINDINGS[1], uniform()),
                entry(GeometryBuffers::BINDINGS[2], uniform()),
                entry(GeometryBuffers::BINDINGS[3], uniform()),
                entry(3, float_texture(true)),
                entry(
                    4,
                    wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                ),
                entry(5, float_texture(false)),
                entry(6, uniform()),
                entry(7, uniform()),
                entry(8, float_texture(false)),
                entry(11, storage(true)),
                entry(16, float_texture(false)),
                entry(18, float_texture(false)),
                entry(non_finite::BINDING, storage(false)),
                entry(MeshBuffers::BINDINGS[0], storage(true)),
                entry(MeshBuffers::BINDINGS[1], storage(true)),
                entry(MeshBuffers::BINDINGS[2], storage(true)),
                entry(MeshBuffers::BINDINGS[3], storage(true)),
            ],
        });
        let display_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("display"),
            entries: &[
                entry(0, uniform()),
                entry(1, float_texture(false)),
                entry(2, uniform()),
                entry(3, float_texture(false)),
            ],
        });
        let images = ImageSet::empty();
        let textures = texture_codegen::generate(scene, &images)?;
        let key = PipelineKey {
            features,
            code: textures.wgsl,
            switches: RenderSwitches::of(scene),
            sources: sources_generation(),
            kernel,
        };
        let trace_layouts = TraceLayouts {
            scene: trace_layout,
            outputs: TraceLayouts::outputs(device),
        };
        let (trace_pipeline, trace_shader_bytes) =
            Self::build_trace_pipeline(&ctx.device, &trace_layouts, &key)?;
        let display_module = shader_module(device, Program::Display, &FeatureSet::default(), "")?;
        let auto_exposure = AutoExposure::new(device)?;
        let buffer = |label: &str, contents: &[u8], usage: wgpu::BufferUsages| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage: usage | wgpu::BufferUsages::COPY_DST,
            })
        };
        let frame_buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("frame ring"),
            size: FRAME_SLOTS * frame_stride(device),
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let display_buffer = buffer(
            "display",
            bytemuck::bytes_of(&DisplayUniform::zeroed()),
            wgpu::BufferUsages::UNIFORM,
        );
        let geometry = GeometryBuffers::new(device, scene);
        let meshes = MeshBuffers::new(device, scene);
        let perm_buffer = buffer(
            "permutation",
            bytemuck::cast_slice(&permutation_table()),
            wgpu::BufferUsages::UNIFORM,
        );
        let texture_param_buffer = buffer(
            "texture parameters",
            bytemuck::cast_slice(&textures.params),
            wgpu::BufferUsages::UNIFORM,
        );
        let env_sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("environment"),
            // Repeat in u: bilinear filtering wraps across the u = 0/1 seam.
            address_mode_u: wgpu::AddressMode::Repeat,
            address_mode_v: wgpu::AddressMode::ClampToEdge,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        let env = env.map(|e| envmap::fit_within(e, ctx.device.limits().max_texture_dimension_2d));
        let env_view = upload_env(ctx, env.as_deref());
        let env_distribution = upload_env_distribution(ctx, env.as_deref());
        let image_atlas_view = upload_atlas(ctx, images.atlas());
        let accumulation = Accumulation::new(device, size, compute_supported);
        let error_meter = ErrorMeter::new(device)?;
        let non_finite = NonFiniteCounter::new(device);
        Ok(Self {
            scene: scene.clone(),
            pending: None,
            builder: PipelineBuilder::default(),
            warm_up: None,
            last_build: None,
            key,
            feature_override: None,
            kernel,
            compute_supported,
            trace_layouts,
            trace_pipeline,
            display_layout,
            display_pipelines: HashMap::new(),
            display_module,
            frame_buffer,
            frame_slot: 0,
            display_buffer,
            auto_exposure,
            metered_from: None,
            geometry,
            meshes,
            perm_buffer,
            texture_param_buffer,
            trace_shader_bytes,
            env_view,
            env_sampler,
            env_distribution,
            images,
            image_atlas_view,
            accumulation,
            error_meter,
            non_finite,
            size,
            render_scale: 1.0,
            frame_index: 0,
        })
    }

    /// The trace pipeline of the key's kernel, and the size of its WGSL.
    fn build_trace_pipeline(
        device: &wgpu::Device,
        layouts: &TraceLayouts,
        key: &PipelineKey,
    ) -> Result<(TracePipeline, usize)> {
        let source = assemble(Program::Trace, &key.features, &key.code)?;
        let bytes = source.len();
        let module = compile_wgsl(device, Program::Trace, source)?;
        let pipeline = TracePipeline::build(
            device,
            layouts,
            &module,
            key.kernel,
            &key.switches.constants(),
        )?;
        Ok((pipeline, bytes))
    }

    /// The kernel drawing now.
    pub fn kernel(&self) -> Kernel {
        self.trace_pipeline.kernel()
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
        let scene = self.latest_requested_scene();
        self.start_scene(ctx, &scene, true)
    }

    /// The scene of the build under way, else the one drawing.
    fn latest_requested_scene(&self) -> Scene {
        self.pending
            .as_ref()
            .map_or(&self.scene, |p| &p.target.scene)
            .clone()
    }

    fn choose_kernel(&mut self, ctx: &GpuContext, kernel: Kernel) -> Result<()> {
        if kernel == Kernel::Compute && !self.compute_supported {
            kernel::resolve(ctx, kernel::KernelChoice::Compute)?;
        }
        self.kernel = kernel;
        Ok(())
    }

    /// Triangles, BVH nodes, lights and the last BVH build time.
    pub fn mesh_stats(&self) -> MeshStats {
        self.meshes.stats()
    }

    /// Notes on emitters left out of the light table.
    pub fn light_notes(&self) -> &[String] {
        &self.meshes.table().notes
    }

    /// Size of the trace shader's assembled WGSL.
    pub fn trace_shader_bytes(&self) -> usize {
        self.trace_shader_bytes
    }

    pub fn features(&self) -> &FeatureSet {
        &self.key.features
    }

    pub fn scene(&self) -> &Scene {
        &self.scene
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
        scaled(self.size, self.render_scale)
    }

    /// The size of the image on show: the last complete round's traced
    /// region, or its preview's (smaller) while the first round of an
    /// accumulation is under way.
    pub fn shown_size(&self) -> (u32, u32) {
        self.accumulation.shown_size()
    }

    /// Traces the rest of the first round and waits for it, if none is
    /// complete yet (a preview may be on show): for screenshots, which
    /// must have the full resolution.
    pub fn complete_first_round(&mut self, ctx: &GpuContext) -> Result<()> {
        if self.accumulation.frames() > 0 {
            return Ok(());
        }
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        self.trace(ctx, &mut encoder, None);
        ctx.queue.submit([encoder.finish()]);
        ctx.device.poll(wgpu::PollType::wait_indefinitely())?;
        Ok(())
    }

    /// The fraction of the round under way already traced (0 between
    /// rounds): the panel's progress while a slow adapter traces in bands.
    pub fn round_progress(&self) -> f32 {
        self.accumulation.next_row() as f32 / self.render_size().1.max(1) as f32
    }

    /// Geometry prepared off the render thread for the next scene set
    /// (see [`PreparedGeometry`]): that scene's BVH is not built again.
    pub fn provide_geometry(&mut self, prepared: PreparedGeometry) {
        self.meshes.provide(prepared);
    }

    /// Applies an edited scene and waits for any shader it needs: for
    /// headless renders and tests. If the build fails, the previous pipeline
    /// and scene stay and the error is returned.
    pub fn set_scene(&mut self, ctx: &GpuContext, scene: &Scene) -> Result<()> {
        // Waiting here, the first draw may as well compile on this device:
        // no warm-up.
        self.start_scene(ctx, scene, false)?;
        match self.pending.take() {
            Some(mut pending) => {
                let built = pending.build.wait()?;
                self.install(ctx, built, &mut pending);
                Ok(())
            }
            None => Ok(()),
        }
    }

    /// Applies an edited scene without waiting: for the viewer. Parameter
    /// edits only rewrite buffers and show at the next frame. An edit that
    /// changes the feature set or the texture trees' structure starts a
    /// pipeline build on a worker thread; until [`Renderer::poll_build`]
    /// reports it done, the old pipeline keeps rendering the old scene (with
    /// the new camera). A later edit of the same structure joins that build.
    pub fn request_scene(&mut self, ctx: &GpuContext, scene: &Scene) -> Result<()> {
        self.start_scene(ctx, scene, true)
    }

    /// [`Renderer::request_scene`], warming the driver's shader cache on a
    /// second device first if `warm_up` (and the adapter compiles at draw).
    fn start_scene(&mut self, ctx: &GpuContext, scene: &Scene, warm_up: bool) -> Result<()> {
        let features = self
            .feature_override
            .clone()
            .unwrap_or_else(|| FeatureSet::for_scene(scene));
        let target_scene = self
            .pending
            .as_ref()
            .map_or(&self.scene, |p| &p.target.scene);
        // Camera and light edits (every frame of a drag) leave the textures
        // alone: regenerate them only when a material changed.
        let textures = if target_scene.materials().eq(scene.materials()) {
            None
        } else {
            Some(texture_codegen::generate(scene, &self.images)?)
        };
        let target = Target {
            scene: scene.clone(),
            params: textures.as_ref().map(|t| t.params.clone()),
        };
        let code = match (&textures, &self.pending) {
            (Some(t), _) => t.wgsl.clone(),
            (None, Some(p)) => p.key.code.clone(),
            (None, None) => self.key.code.clone(),
        };
        let key = PipelineKey {
            features,
            code,
            switches: RenderSwitches::of(scene),
            sources: sources_generation(),
            kernel: self.kernel,
        };
        if key == self.key {
            self.pending = None;
            self.apply(ctx, target);
            return Ok(());
        }
        if let Some(pending) = &mut self.pending
            && pending.key == key
        {
            // Keep the parameters of a regenerated tree, or those already
            // waiting.
            let params = target.params.or(pending.target.params.take());
            pending.target = Target { params, ..target };
            self.follow_camera(scene);
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
                images: self.images.clone(),
                features: self.feature_override.clone(),
                kernel: self.kernel,
            };
            Box::new(move || warm_up.run()) as WarmUp
        });
        let (device, layouts) = (ctx.device.clone(), self.trace_layouts.clone());
        let build_key = key.clone();
        let build = self.builder.start(warm_up, move || {
            Self::build_trace_pipeline(&device, &layouts, &build_key)
        });
        self.pending = Some(PendingScene { build, key, target });
        self.follow_camera(scene);
        Ok(())
    }

    /// Whether a pipeline build is under way.
    pub fn is_building(&self) -> bool {
        self.pending.is_some()
    }

    /// Installs a finished build and its scene. Returns how long the build
    /// took, or why it failed (the old pipeline and scene then stay); None
    /// while nothing has finished.
    pub fn poll_build(&mut self, ctx: &GpuContext) -> Option<Result<Duration>> {
        let result = self.pending.as_ref()?.build.poll()?;
        let mut pending = self.pending.take()?;
        Some(result.map(|built| {
            let took = built.took;
            self.install(ctx, built, &mut pending);
            took
        }))
    }

    /// How long the last pipeline build took, from the edit to the new
    /// pipeline (the Stats panel shows it).
    pub fn last_build(&self) -> Option<Duration> {
        self.last_build
    }

    fn install(&mut self, ctx: &GpuContext, built: BuiltPipeline, pending: &mut PendingScene) {
        self.trace_pipeline = built.pipeline;
        self.trace_shader_bytes = built.shader_bytes;
        self.last_build = Some(built.took);
        self.key = std::mem::take(&mut pending.key);
        let target = Target {
            scene: std::mem::take(&mut pending.target.scene),
            params: pending.target.params.take(),
        };
        // A new pipeline draws a new image even for the same scene (a
        // feature compiled out): the samples of the old one must go.
        self.reset_accumulation();
        self.apply(ctx, target);
    }

    /// Writes a scene whose pipeline is in place into the buffers.
    fn apply(&mut self, ctx: &GpuContext, target: Target) {
        if let Some(params) = &target.params {
            ctx.queue
                .write_buffer(&self.texture_param_buffer, 0, bytemuck::cast_slice(params));
        }
        let scene = &target.scene;
        self.geometry.write(&ctx.queue, scene);
        self.meshes.update(&ctx.device, scene);
        // Display-only edits (exposure, tone map) keep the samples.
        let mut traced_before = self.scene.clone();
        let mut traced_now = scene.clone();
        traced_before.render.exposure = 0.0;
        traced_now.render.exposure = 0.0;
        // So does auto exposure: it meters the samples, it does not trace.
        traced_before.render.auto_exposure = false;
        traced_now.render.auto_exposure = false;
        traced_before.render.tone_map = ToneMap::default();
        traced_now.render.tone_map = ToneMap::default();
        traced_before.render.show_non_finite = false;
        traced_now.render.show_non_finite = false;
        if traced_before != traced_now {
            self.reset_accumulation();
        }
        self.scene = target.scene;
    }

    /// While a build is pending the old scene is drawn, but seen from the
    /// new camera: orbiting stays live.
    fn follow_camera(&mut self, scene: &Scene) {
        if self.scene.camera != scene.camera {
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
        if self.warm_up.is_none() {
            self.warm_up = ctx.sibling().ok().map(Arc::new);
        }
        self.warm_up.clone()
    }

    /// Builds the shader with `features` instead of the scene's own set
    /// (`None` goes back to specialising per scene).
    pub fn set_feature_override(
        &mut self,
        ctx: &GpuContext,
        features: Option<FeatureSet>,
    ) -> Result<()> {
        self.feature_override = features;
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
            .pending
            .as_ref()
            .map_or(&self.key.code, |p| &p.key.code);
        if let Some(set) = &features {
            let source = assemble(Program::Trace, set, code)?;
            validate(&source).map_err(|e| {
                anyhow::anyhow!("this scene's shader cannot be built with those features: {e}")
            })?;
        }
        self.feature_override = features;
        let scene = self.latest_requested_scene();
        self.start_scene(ctx, &scene, true)
    }

    /// Goes back to specialising per scene at the next scene request,
    /// without building anything now (the caller is about to request a
    /// scene whose features changed).
    pub fn forget_feature_override(&mut self) {
        self.feature_override = None;
    }

    /// The images the texture code reads.
    pub fn images(&self) -> &ImageSet {
        &self.images
    }

    /// Replaces the images the scene's image textures read (loaded by
    /// `ImageSet::load`): uploads their atlas and regenerates the texture
    /// code, which holds where each image lies. A pending build is finished
    /// first (its code assumed the old images).
    pub fn set_images(&mut self, ctx: &GpuContext, images: ImageSet) -> Result<()> {
        if let Some(mut pending) = self.pending.take() {
            let built = pending.build.wait()?;
            self.install(ctx, built, &mut pending);
        }
        let textures = texture_codegen::generate(&self.scene, &images)?;
        if textures.wgsl != self.key.code {
            let key = PipelineKey {
                code: textures.wgsl,
                ..self.key.clone()
            };
            (self.trace_pipeline, self.trace_shader_bytes) =
                Self::build_trace_pipeline(&ctx.device, &self.trace_layouts, &key)?;
            self.key = key;
        }
        ctx.queue.write_buffer(
            &self.texture_param_buffer,
            0,
            bytemuck::cast_slice(&textures.params),
        );
        self.image_atlas_view = upload_atlas(ctx, images.atlas());
        self.images = images;
        self.reset_accumulation();
        Ok(())
    }

    /// Replaces the environment image (None: a black 1×1 placeholder). One
    /// larger than the GPU's textures is downscaled to fit (as
    /// `session::load_environment` does with a note), never refused.
    pub fn set_environment(&mut self, ctx: &GpuContext, env: Option<&EnvImage>) {
        let env = env.map(|e| envmap::fit_within(e, ctx.device.limits().max_texture_dimension_2d));
        self.env_view = upload_env(ctx, env.as_deref());
        self.env_distribution = upload_env_distribution(ctx, env.as_deref());
        self.reset_accumulation();
    }

    pub fn resize(&mut self, ctx: &GpuContext, size: (u32, u32)) {
        let size = (size.0.max(1), size.1.max(1));
        if size != self.size {
            self.size = size;
            self.accumulation = Accumulation::new(&ctx.device, size, self.compute_supported);
            self.reset_accumulation();
        }
    }

    /// Traces at a fraction of the resolution (while the camera moves).
    pub fn set_render_scale(&mut self, scale: f32) {
        let scale = scale.clamp(0.1, 1.0);
        if scale != self.render_scale {
            self.render_scale = scale;
            self.reset_accumulation();
        }
    }

    pub fn reset_accumulation(&mut self) {
        self.accumulation.reset();
    }

    /// Records one whole round: `samples_per_frame` more samples per pixel
    /// (or the rest of the round under way), timed by `timestamps` if
    /// given (the viewer's [`PassTimer`], the benchmarks' own query sets).
    pub fn trace(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        timestamps: Option<PassTimestamps<'_>>,
    ) -> TraceWork {
        self.trace_within(ctx, encoder, TraceBudget::Round, timestamps)
    }

    /// Records about `budget` of tracing (see [`trace_bands::plan`]): the
    /// round under way continues where it stopped, and a round completed
    /// becomes the image. A new accumulation whose first round does not
    /// fit in the budget first traces a preview whole, at the size that
    /// fits (at most the interactive scale): the window shows the edit at
    /// once, at a reduced resolution, then the full one.
    pub fn trace_within(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        budget: TraceBudget,
        timestamps: Option<PassTimestamps<'_>>,
    ) -> TraceWork {
        if !self.scene.render.accumulate && self.accumulation.next_row() == 0 {
            // Each round starts anew; the preview was for the first.
            let previewed = !self.accumulation.wants_preview();
            self.accumulation.reset();
            if previewed {
                self.accumulation.skip_preview();
            }
        }
        let full = self.render_size();
        // Each pass: the region's size, the band's rows, whether a preview.
        let mut passes: Vec<((u32, u32), std::ops::Range<u32>, bool)> = Vec::new();
        let mut budget = budget;
        if let TraceBudget::Pixels(pixels) = budget
            && self.accumulation.wants_preview()
        {
            let round = u64::from(full.0) * u64::from(full.1);
            if round > pixels {
                let scale = ((pixels as f64 / round as f64).sqrt() as f32)
                    .min(self.scene.render.interactive_scale);
                let size = scaled(full, scale);
                passes.push((size, 0..size.1, true));
                budget = TraceBudget::Pixels(pixels.saturating_sub(pixel_count(size)));
            } else {
                self.accumulation.skip_preview();
            }
        }
        let bands = trace_bands::plan(full.0, full.1, self.accumulation.next_row(), budget);
        passes.extend(bands.into_iter().map(|rows| (full, rows, false)));
        let mut work = TraceWork::default();
        let count = passes.len();
        for (index, (size, rows, preview)) in passes.into_iter().enumerate() {
            if index > 0 && !preview && rows.start == 0 && !self.scene.render.accumulate {
                // A later round of this call: it too starts anew.
                self.accumulation.reset();
                self.accumulation.skip_preview();
            }
            if self.accumulation.samples() == 0 && self.accumulation.next_row() == 0 {
                self.non_finite.clear(encoder);
            }
            self.record_band(ctx, encoder, size, rows.clone(), (index, count), timestamps);
            work.pixels += u64::from(size.0) * u64::from(rows.end - rows.start);
            if preview {
                // The preview draws the first round's samples at its own
                // size: the frame index (the seed) stays, so the image
                // that follows is the one a whole pass gives.
                self.accumulation.show_preview(size);
                continue;
            }
            self.accumulation.traced_to(rows.end);
            if rows.end == size.1 {
                self.accumulation
                    .advance(self.scene.render.samples_per_frame.max(1), size);
                self.frame_index = self.frame_index.wrapping_add(1);
                work.rounds += 1;
            }
        }
        self.non_finite
            .record_readback(encoder, self.accumulation.generation());
        work
    }

    /// Records the pass of one band of rows of a round over a region of
    /// `size`: the frame uniform in its own slot, the bind groups of the
    /// accumulation's current sets.
    fn record_band(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        size: (u32, u32),
        rows: std::ops::Range<u32>,
        (index, count): (usize, usize),
        timestamps: Option<PassTimestamps<'_>>,
    ) {
        let mut uniform: FrameUniform = scene_gpu::frame_uniform(
            &self.scene,
            size,
            self.frame_index,
            self.accumulation.samples(),
        );
        uniform.env_distribution_size = self.env_distribution.1;
        let table = self.meshes.table();
        uniform.light_count = table.lights.len() as u32;
        uniform.light_total_power = table.total_power;
        uniform.triangle_count = self.meshes.stats().triangles as u32;
        uniform.band_start = rows.start;
        uniform.band_end = rows.end;
        let stride = frame_stride(&ctx.device);
        let offset = self.frame_slot * stride;
        self.frame_slot = (self.frame_slot + 1) % FRAME_SLOTS;
        ctx.queue.write_buffer(
            &self.frame_buffer,
            offset,
            bytemuck::cast_slice(&[uniform; 2]),
        );
        let (previous_mean, previous_spread) = self.accumulation.latest_views();
        let frame = wgpu::BufferBinding {
            buffer: &self.frame_buffer,
            offset: 0,
            size: wgpu::BufferSize::new(FRAME_BYTES),
        };
        let mut entries = vec![
            bind(0, wgpu::BindingResource::Buffer(frame)),
            bind(3, wgpu::BindingResource::TextureView(&self.env_view)),
            bind(4, wgpu::BindingResource::Sampler(&self.env_sampler)),
            bind(5, wgpu::BindingResource::TextureView(previous_mean)),
            bind(16, wgpu::BindingResource::TextureView(previous_spread)),
            bind(
                18,
                wgpu::BindingResource::TextureView(self.accumulation.latest_compensation_view()),
            ),
            bind(6, self.perm_buffer.as_entire_binding()),
            bind(7, self.texture_param_buffer.as_entire_binding()),
            bind(
                8,
                wgpu::BindingResource::TextureView(&self.image_atlas_view),
            ),
            bind(11, self.env_distribution.0.as_entire_binding()),
            bind(
                non_finite::BINDING,
                self.non_finite.buffer().as_entire_binding(),
            ),
        ];
        entries.extend(self.geometry.entries());
        entries.extend(self.meshes.entries());
        let scene_group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("trace"),
            layout: &self.trace_layouts.scene,
            entries: &entries,
        });
        let outputs = matches!(self.trace_pipeline, TracePipeline::Compute(_)).then(|| {
            let views = self.accumulation.write_views();
            ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("trace outputs"),
                layout: &self.trace_layouts.outputs,
                entries: &[
                    bind(0, wgpu::BindingResource::TextureView(views[0])),
                    bind(1, wgpu::BindingResource::TextureView(views[1])),
                    bind(2, wgpu::BindingResource::TextureView(views[2])),
                ],
            })
        });
        BandPass {
            pipeline: &self.trace_pipeline,
            scene: &scene_group,
            frame_offset: offset as u32,
            outputs: outputs.as_ref(),
            accumulation: &self.accumulation,
            width: size.0,
            rows,
            height: size.1,
            index,
            count,
        }
        .record(encoder, timestamps);
    }

    /// Records the auto-exposure metering of the latest mean, unless the
    /// result already comes from it.
    fn meter(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        timer: Option<&PassTimer>,
    ) {
        let render_size = self.shown_size();
        let from = MeteredFrom {
            shown: self.accumulation.shown_count(),
            size: self.size,
            render_size,
        };
        if self.metered_from != Some(from) {
            self.auto_exposure.record(
                ctx,
                encoder,
                self.accumulation.latest_views().0,
                render_size,
                timer.and_then(|t| t.compute_pass(Pass::AutoExposure)),
            );
            self.metered_from = Some(from);
        }
    }

    /// Records the display pass: exposure and tone mapping of the latest mean
    /// into `viewport` of `target`. The rest of the target is left as is.
    /// With auto exposure the mean is metered first (a compute pass in the
    /// same encoder, its result read on the GPU).
    pub fn display(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        target: &DisplayTarget<'_>,
        timer: Option<&PassTimer>,
    ) -> Result<()> {
        let DisplayTarget {
            view: target,
            format,
            viewport,
            load,
        } = *target;
        if !self.display_pipelines.contains_key(&format) {
            let p = fullscreen_pipeline(
                &ctx.device,
                "display",
                &self.display_module,
                &self.display_layout,
                "fs_display",
                &[format],
                &[],
            )?;
            self.display_pipelines.insert(format, p);
        }
        let auto_exposure = self.scene.render.auto_exposure;
        if auto_exposure {
            self.meter(ctx, encoder, timer);
        }
        let render_size = self.shown_size();
        let uniform = DisplayUniform {
            exposure_scale: self.scene.render.exposure.exp2(),
            tone_map: match self.scene.render.tone_map {
                ToneMap::Aces => 0,
                ToneMap::Reinhard => 1,
                ToneMap::Clamp => 2,
            },
            encode_srgb: u32::from(!format.is_srgb()),
            auto_exposure: u32::from(auto_exposure),
            origin: [viewport.x, viewport.y],
            scale: [
                render_size.0 as f32 / viewport.width.max(1.0),
                render_size.1 as f32 / viewport.height.max(1.0),
            ],
            show_non_finite: u32::from(self.scene.render.show_non_finite),
            padding: 0,
        };
        ctx.queue
            .write_buffer(&self.display_buffer, 0, bytemuck::bytes_of(&uniform));
        let bind_group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("display"),
            layout: &self.display_layout,
            entries: &[
                bind(0, self.display_buffer.as_entire_binding()),
                bind(
                    1,
                    wgpu::BindingResource::TextureView(self.accumulation.latest_views().0),
                ),
                bind(2, self.auto_exposure.result().as_entire_binding()),
                bind(
                    3,
                    wgpu::BindingResource::TextureView(self.accumulation.latest_views().1),
                ),
            ],
        });
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("display"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: target,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load,
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: timer.and_then(|t| t.render_pass(Pass::Display)),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_viewport(
            viewport.x,
            viewport.y,
            viewport.width,
            viewport.height,
            0.0,
            1.0,
        );
        pass.set_pipeline(&self.display_pipelines[&format]);
        pass.set_bind_group(0, &bind_group, &[]);
        pass.draw(0..3, 0..1);
        Ok(())
    }

    /// The linear radiance of the traced region (the running mean), RGBA f32.
    pub fn read_radiance(&self, ctx: &GpuContext) -> Result<(u32, u32, Vec<[f32; 4]>)> {
        self.read_accumulated(ctx, self.accumulation.latest_mean_texture())
    }

    /// The spread of the frames' means about the mean, per pixel, as the
    /// trace pass keeps it (see [`super::error_meter`]).
    pub fn read_spread(&self, ctx: &GpuContext) -> Result<(u32, u32, Vec<[f32; 4]>)> {
        self.read_accumulated(ctx, self.accumulation.latest_spread_texture())
    }

    /// The traced region of one of the accumulation targets.
    fn read_accumulated(
        &self,
        ctx: &GpuContext,
        texture: &wgpu::Texture,
    ) -> Result<(u32, u32, Vec<[f32; 4]>)> {
        let bytes = read_texture(&ctx.device, &ctx.queue, texture, 16)?;
        let all: &[[f32; 4]] = bytemuck::cast_slice(&bytes);
        let (rw, rh) = self.shown_size();
        let mut out = Vec::with_capacity((rw * rh) as usize);
        for y in 0..rh {
            let start = (y * self.size.0) as usize;
            out.extend_from_slice(&all[start..start + rw as usize]);
        }
        Ok((rw, rh, out))
    }

    /// Meters the latest mean for auto exposure and reads the result back,
    /// waiting for the GPU (whether or not auto exposure is on): for tests
    /// and reports. The display pass reads the same result on the GPU.
    pub fn metering(&mut self, ctx: &GpuContext) -> Result<Metered> {
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        self.meter(ctx, &mut encoder, None);
        ctx.queue.submit([encoder.finish()]);
        self.auto_exposure.read(ctx)
    }

    /// Records the error meter on the latest frame (skip it before the
    /// second frame: one frame has no spread). The viewer calls it every
    /// frame, then [`Self::after_submit`], then collects with
    /// [`Self::poll_error`].
    pub fn meter_error(
        &self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        timer: Option<&PassTimer>,
    ) {
        if self.accumulation.frames() >= 2 {
            self.error_meter
                .record(ctx, encoder, &self.accumulated(), timer);
        }
    }

    /// What the error meter reads.
    fn accumulated(&self) -> error_meter::Accumulated<'_> {
        let (mean, spread) = self.accumulation.latest_views();
        error_meter::Accumulated {
            mean,
            spread,
            region: self.shown_size(),
            frames: self.accumulation.frames(),
            samples: self.accumulation.samples(),
            seconds: self.accumulation.elapsed().as_secs_f32(),
            generation: self.accumulation.generation(),
        }
    }

    /// Which accumulation the image holds: it changes at every reset.
    pub fn accumulation_generation(&self) -> u32 {
        self.accumulation.generation()
    }

    /// Starts the readbacks recorded in the encoder just submitted.
    pub fn after_submit(&self) {
        self.error_meter.after_submit();
        self.non_finite.after_submit();
    }

    /// The non-finite samples dropped by the current accumulation, from a
    /// finished readback (a frame or two old); `None` while none arrived
    /// or the one that did counted an earlier accumulation.
    pub fn poll_non_finite(&self) -> Option<NonFiniteCounts> {
        let (generation, counts) = self.non_finite.poll()?;
        (generation == self.accumulation.generation()).then_some(counts)
    }

    /// The non-finite samples dropped since the accumulation began, waiting
    /// for the GPU: for headless renders and tests.
    pub fn count_non_finite(&self, ctx: &GpuContext) -> Result<NonFiniteCounts> {
        self.non_finite.read(ctx)
    }

    /// The error estimate of a finished readback, once, a frame or two
    /// after it was recorded: it says which frame it measured.
    pub fn poll_error(&self) -> Option<ErrorEstimate> {
        self.error_meter.poll()
    }

    /// Meters the error of the latest frame and waits for it: for headless
    /// renders and tests. `None` before two frames.
    pub fn estimate_error(&self, ctx: &GpuContext) -> Result<Option<ErrorEstimate>> {
        self.error_meter.measure(ctx, &self.accumulated())
    }

    /// The displayed (tone-mapped, sRGB) image at the trace resolution.
    pub fn read_display(&mut self, ctx: &GpuContext) -> Result<image::RgbaImage> {
        let (w, h) = self.shown_size();
        let format = wgpu::TextureFormat::Rgba8UnormSrgb;
        let target = ctx.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("display readback"),
            size: wgpu::Extent3d {
                width: w,
                height: h,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let view = target.create_view(&Default::default());
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        let display_target = DisplayTarget {
            view: &view,
            format,
            viewport: Viewport {
                x: 0.0,
                y: 0.0,
                width: w as f32,
                height: h as f32,
            },
            load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
        };
        self.display(ctx, &mut encoder, &display_target, None)?;
        ctx.queue.submit([encoder.finish()]);
        let bytes = read_texture(&ctx.device, &ctx.queue, &target, 4)?;
        image::RgbaImage::from_raw(w, h, bytes)
            .ok_or_else(|| anyhow::anyhow!("readback returned the wrong number of bytes"))
    }
}

/// The bytes between frame-uniform slots: a slot rounded up to the
/// device's uniform offset alignment.
fn frame_stride(device: &wgpu::Device) -> u64 {
    let align = u64::from(device.limits().min_uniform_buffer_offset_alignment);
    FRAME_BYTES.div_ceil(align) * align
}

/// `size` scaled by `scale`, at least one pixel a side.
fn scaled(size: (u32, u32), scale: f32) -> (u32, u32) {
    let s = |v: u32| ((v as f32 * scale).ceil() as u32).clamp(1, v.max(1));
    (s(size.0), s(size.1))
}

fn pixel_count(size: (u32, u32)) -> u64 {
    u64::from(size.0) * u64::from(size.1)
}

/// What to draw once on a second device, so its compiled shader lands in
/// the driver's disk cache before the real device first draws it
/// (`pipeline_build` runs it on its worker before the build).
struct ShaderWarmUp {
    ctx: Arc<GpuContext>,
    scene: Scene,
    images: ImageSet,
    features: Option<FeatureSet>,
    /// The kernel being built: each compiles its own entry point.
    kernel: Kernel,
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

fn bind(binding: u32, resource: wgpu::BindingResource<'_>) -> wgpu::BindGroupEntry<'_> {
    wgpu::BindGroupEntry { binding, resource }
}

/// What the renderer binds without an environment map: one black texel.
fn no_env() -> EnvImage {
    marbre_core::envmap::constant(1, 1, [0.0; 3])
}

/// The environment's importance-sampling CDFs (`env_sampling.wgsl`) and
/// their size in cells; a 1×1 uniform distribution without a map.
fn upload_env_distribution(ctx: &GpuContext, env: Option<&EnvImage>) -> (wgpu::Buffer, [u32; 2]) {
    let distribution = EnvDistribution::new(env.unwrap_or(&no_env()));
    let buffer = ctx
        .device
        .create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("environment distribution"),
            contents: bytemuck::cast_slice(&distribution.gpu_data()),
            usage: wgpu::BufferUsages::STORAGE,
        });
    (buffer, [distribution.width, distribution.height])
}

/// Uploads an environment map as Rgba16Float (the sanitised values fit).
fn upload_env(ctx: &GpuContext, env: Option<&EnvImage>) -> wgpu::TextureView {
    let black = no_env();
    let image = env.unwrap_or(&black);
    upload_rgba16f(
        ctx,
        "environment",
        (image.width, image.height),
        bytemuck::cast_slice(&image.to_rgba16f()),
    )
}
