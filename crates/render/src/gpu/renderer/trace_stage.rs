//! The trace stage: the pipeline drawing now and the key it was built
//! from, the builds of the next ones (`build.rs`), the kernel, and the ring
//! of frame uniforms the trace passes read.

use super::Renderer;
use super::build::{PendingScene, PipelineKey};
use super::scene_bindings::SceneBindings;
use crate::gpu::context::GpuContext;
use crate::gpu::features::FeatureSet;
use crate::gpu::kernel::Kernel;
use crate::gpu::non_finite;
use crate::gpu::pipeline_build::PipelineBuilder;
use crate::gpu::pipelines::{entry, float_texture, storage, uniform};
use crate::gpu::scene_gpu::Frame;
use crate::gpu::texture_codegen::ParamPlan;
use crate::gpu::trace_bands;
use crate::gpu::trace_pass::{TraceLayouts, TracePipeline};
use anyhow::Result;
use std::sync::Arc;
use std::time::Duration;

/// The trace pass's own state.
pub(super) struct TraceStage {
    /// A structural edit whose pipeline is being built.
    pub(super) pending: Option<PendingScene>,
    /// The worker thread that builds trace pipelines, latest request first.
    pub(super) builder: PipelineBuilder,
    /// The device that warms the shader cache for builds (CPU adapters).
    pub(super) warm_up: Option<Arc<GpuContext>>,
    pub(super) last_build: Option<Duration>,
    /// What the trace pipeline was built from: a scene whose key differs
    /// needs a new pipeline.
    pub(super) key: PipelineKey,
    /// Where each number of the key's texture code comes from.
    pub(super) texture_plan: ParamPlan,
    /// How many times texture code was generated since creation (a
    /// parameter edit must not add one).
    pub(super) code_generations: u64,
    /// When set, the shader is built with these features whatever the scene
    /// uses: `FeatureSet::all()` is the uber shader the benchmarks compare.
    pub(super) feature_override: Option<FeatureSet>,
    /// The kernel new pipelines are built for (the key holds the one
    /// drawing now).
    pub(super) kernel: Kernel,
    /// Whether the adapter runs the compute kernel (its targets are then
    /// storage textures too).
    pub(super) compute_supported: bool,
    pub(super) layouts: TraceLayouts,
    pub(super) pipeline: TracePipeline,
    /// Size of the trace module's WGSL, for the Stats panel.
    pub(super) shader_bytes: usize,
    /// A ring of [`FRAME_SLOTS`] frame uniforms, one per trace pass: the
    /// passes of one submit each read their own (a `write_buffer` lands
    /// before the whole submit, so one slot would give every pass the
    /// last pass's settings).
    pub(super) frame_buffer: wgpu::Buffer,
    /// The next slot of the ring to write.
    pub(super) frame_slot: u64,
}

/// Frame uniforms in the ring: more than the passes of one submit
/// ([`trace_bands::MAX_PASSES`] and the previews, a few).
pub(super) const FRAME_SLOTS: u64 = 2 * trace_bands::MAX_PASSES as u64;

/// The bytes of one frame-uniform slot: two copies of the settings (see
/// `frame_slots` in shaders/scene.wgsl).
pub(super) const FRAME_BYTES: u64 = 2 * std::mem::size_of::<Frame>() as u64;

impl TraceStage {
    /// The stage drawing `key` (built here, on this thread), its bind
    /// group 0 laid out as the frame ring and the scene's bindings.
    pub(super) fn new(
        ctx: &GpuContext,
        key: PipelineKey,
        kernel: Kernel,
        texture_plan: ParamPlan,
        compute_supported: bool,
    ) -> Result<Self> {
        let device = &ctx.device;
        let frame_entry = wgpu::BindGroupLayoutEntry {
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Uniform,
                has_dynamic_offset: true,
                min_binding_size: wgpu::BufferSize::new(FRAME_BYTES),
            },
            ..entry(0, uniform())
        };
        let mut entries = vec![
            // A slot of the frame ring, at a dynamic offset.
            frame_entry,
            entry(non_finite::BINDING, storage(false)),
        ];
        // The accumulation the pass reads back (`frame.rs` binds the
        // latest set): mean, spread, compensation, albedo and normal.
        entries.extend([5, 16, 18, 19, 20].map(|b| entry(b, float_texture(false))));
        entries.extend(SceneBindings::layout_entries());
        let layouts = TraceLayouts {
            scene: device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("trace"),
                entries: &entries,
            }),
            outputs: TraceLayouts::output_layouts(device),
            cpu_samples: TraceLayouts::cpu_samples_layout(device),
        };
        let (pipeline, shader_bytes) = Renderer::build_trace_pipeline(device, &layouts, &key)?;
        let frame_buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("frame ring"),
            size: FRAME_SLOTS * frame_stride(device),
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Ok(Self {
            pending: None,
            builder: PipelineBuilder::default(),
            warm_up: None,
            last_build: None,
            kernel,
            key,
            texture_plan,
            code_generations: 1,
            feature_override: None,
            compute_supported,
            layouts,
            pipeline,
            shader_bytes,
            frame_buffer,
            frame_slot: 0,
        })
    }
}

/// The bytes between frame-uniform slots: a slot rounded up to the
/// device's uniform offset alignment.
pub(super) fn frame_stride(device: &wgpu::Device) -> u64 {
    let align = u64::from(device.limits().min_uniform_buffer_offset_alignment);
    FRAME_BYTES.div_ceil(align) * align
}
