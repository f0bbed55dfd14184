//! The progressive renderer: trace pass into a running-mean accumulation
//! target, display pass onto any colour target. It owns every GPU resource
//! derived from the scene and rebuilds only what an edit invalidates.
//!
//! Three jobs, one file each: `build` (what a scene needs, pipelines built
//! off the render thread and installed), `frame` (trace, meters, display)
//! and `readback` (results back to the CPU). This file holds the state they
//! share, its creation and what it reports.

mod build;
mod denoise;
mod frame;
mod readback;

use build::{PendingScene, PipelineKey, RenderSwitches};

use super::accumulation::Accumulation;
use super::auto_exposure::AutoExposure;
use super::context::GpuContext;
use super::denoise::Denoiser;
use super::error_meter::ErrorMeter;
use super::features::FeatureSet;
use super::geometry_buffers::GeometryBuffers;
use super::kernel::{self, Kernel};
use super::mesh_buffers::{MeshBuffers, MeshStats};
use super::non_finite::{self, NonFiniteCounter};
use super::pipeline_build::PipelineBuilder;
use super::pipelines::{
    entry, float_texture, permutation_table, shader_module, storage, uniform, upload_atlas,
    upload_rgba16f,
};
use super::scene_gpu::Frame;
use super::shader_source::{Program, sources_generation};
use super::texture_codegen;
use super::trace_bands::{self};
use super::trace_pass::{TraceLayouts, TracePipeline};
use anyhow::Result;
use bytemuck::{Pod, Zeroable};
use marbre_core::env_sampling::EnvDistribution;
use marbre_core::envmap::{self, EnvImage};
use marbre_core::scene::Scene;
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
    /// 0: manual exposure; 1: times the key's metered scale; 2: times
    /// Massal's RMS scale.
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
    /// Where each number of the key's texture code comes from.
    texture_plan: texture_codegen::ParamPlan,
    /// How many times texture code was generated since creation (a
    /// parameter edit must not add one).
    code_generations: u64,
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
    /// The denoiser, made the first time the display asks for it.
    denoiser: Option<Denoiser>,
    /// What the denoiser's output was filtered from.
    denoised_from: Option<MeteredFrom>,
    size: (u32, u32),
    render_scale: f32,
    frame_index: u32,
}

/// Frame uniforms in the ring: more than the passes of one submit
/// ([`trace_bands::MAX_PASSES`] and a preview).
const FRAME_SLOTS: u64 = 2 * trace_bands::MAX_PASSES as u64;

/// The bytes of one frame-uniform slot: two copies of the settings (see
/// `frame_slots` in shaders/scene.wgsl).
const FRAME_BYTES: u64 = 2 * std::mem::size_of::<Frame>() as u64;

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
                entry(19, float_texture(false)),
                entry(20, float_texture(false)),
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
        let texture_plan = textures.plan;
        let key = PipelineKey {
            features,
            code: textures.wgsl,
            switches: RenderSwitches::of(scene),
            sources: sources_generation(),
            kernel,
        };
        let trace_layouts = TraceLayouts {
            scene: trace_layout,
            outputs: TraceLayouts::output_layouts(device),
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
            texture_plan,
            code_generations: 1,
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
            denoiser: None,
            denoised_from: None,
            size,
            render_scale: 1.0,
            frame_index: 0,
        })
    }

    /// The kernel drawing now.
    pub fn kernel(&self) -> Kernel {
        self.trace_pipeline.kernel()
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

    /// How many times this renderer generated texture code, its first
    /// scene's included: structural edits and new images add one each,
    /// parameter edits none.
    pub fn code_generations(&self) -> u64 {
        self.code_generations
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

    /// The images the texture code reads.
    pub fn images(&self) -> &ImageSet {
        &self.images
    }

    /// Which accumulation the image holds: it changes at every reset.
    pub fn accumulation_generation(&self) -> u32 {
        self.accumulation.generation()
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The display uniform has its WGSL twin's layout, as naga lays it out.
    #[test]
    fn the_display_uniform_has_its_wgsl_twins_layout() {
        use crate::gpu::twin_layout::{module_of, twin_layout};
        let module = &module_of(Program::Display, &FeatureSet::default(), "");
        twin_layout!(
            module,
            DisplayUniform,
            [
                exposure_scale,
                tone_map,
                encode_srgb,
                auto_exposure,
                origin,
                scale,
                show_non_finite,
                padding
            ]
        );
    }
}
