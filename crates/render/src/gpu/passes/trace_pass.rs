//! Recording one band of a trace round with either kernel
//! ([`crate::gpu::kernel::Kernel`]): the fragment kernel draws the full-screen
//! triangle with a scissor around the band, the compute kernel dispatches
//! workgroups over it. Both read the scene through bind group 0 (its frame
//! uniform at a dynamic offset, so several passes in one submit each see
//! their own); the compute kernel writes the accumulation through group 1.

use crate::gpu::accumulation::{ACCUMULATION_FORMAT, Accumulation};
use crate::gpu::kernel::{Kernel, WORKGROUP};
use crate::gpu::pipelines::{checked, entry, fullscreen_pipeline, fullscreen_pipeline_with_layout};
use anyhow::Result;
use std::ops::Range;

/// `cpu_samples`' binding in group 1 of shaders/trace.wgsl.
pub const CPU_SAMPLES_BINDING: u32 = 5;

/// A built trace pipeline of any kernel.
pub enum TracePipeline {
    Fragment(wgpu::RenderPipeline),
    Compute(wgpu::ComputePipeline),
    /// The fragment kernel's pass built with `CPU_SAMPLES`: it folds the
    /// samples the CPU kernel traced (group 1) into the accumulation.
    Cpu(wgpu::RenderPipeline),
}

impl TracePipeline {
    pub fn kernel(&self) -> Kernel {
        match self {
            TracePipeline::Fragment(_) => Kernel::Fragment,
            TracePipeline::Compute(_) => Kernel::Compute,
            TracePipeline::Cpu(_) => Kernel::Cpu,
        }
    }

    /// `kernel`'s pipeline from the assembled trace module, its override
    /// constants set to `constants`.
    pub fn build(
        device: &wgpu::Device,
        layouts: &TraceLayouts,
        module: &wgpu::ShaderModule,
        kernel: Kernel,
        constants: &[(&str, f64)],
        guides: bool,
    ) -> Result<Self> {
        match kernel {
            Kernel::Fragment => Ok(TracePipeline::Fragment(fullscreen_pipeline(
                device,
                "trace",
                module,
                &layouts.scene,
                "fs_trace",
                &vec![ACCUMULATION_FORMAT; TraceLayouts::targets(guides)],
                constants,
            )?)),
            Kernel::Compute => {
                let needed = TraceLayouts::targets(guides) as u32;
                let limit = device.limits().max_storage_textures_per_shader_stage;
                anyhow::ensure!(
                    limit >= needed,
                    "the compute kernel cannot write the denoiser's guides on this adapter \
                     ({limit} storage textures a stage, {needed} needed): use the fragment kernel"
                );
                let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                    label: Some("trace (compute)"),
                    bind_group_layouts: &[Some(&layouts.scene), Some(layouts.outputs(guides))],
                    immediate_size: 0,
                });
                let pipeline = checked(device, "trace pipeline (compute)", || {
                    device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                        label: Some("trace (compute)"),
                        layout: Some(&layout),
                        module,
                        entry_point: Some("cs_trace"),
                        compilation_options: wgpu::PipelineCompilationOptions {
                            constants,
                            ..Default::default()
                        },
                        cache: None,
                    })
                })?;
                Ok(TracePipeline::Compute(pipeline))
            }
            Kernel::Cpu => {
                let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                    label: Some("trace (cpu samples)"),
                    bind_group_layouts: &[Some(&layouts.scene), Some(&layouts.cpu_samples)],
                    immediate_size: 0,
                });
                Ok(TracePipeline::Cpu(fullscreen_pipeline_with_layout(
                    device,
                    "trace (cpu samples)",
                    module,
                    &layout,
                    "fs_trace",
                    &vec![ACCUMULATION_FORMAT; TraceLayouts::targets(guides)],
                    constants,
                )?))
            }
        }
    }
}

/// The bind group layouts of the trace pipelines: the scene (both kernels)
/// and the compute kernel's storage-texture outputs, without and with the
/// denoiser's guides.
#[derive(Clone)]
pub struct TraceLayouts {
    pub scene: wgpu::BindGroupLayout,
    pub outputs: [wgpu::BindGroupLayout; 2],
    /// The CPU kernel's samples of a band (`cpu_samples`, binding 5).
    pub cpu_samples: wgpu::BindGroupLayout,
}

impl TraceLayouts {
    /// The targets a round writes: mean, spread and compensation, and the
    /// albedo and normal guides with `guides`.
    pub fn targets(guides: bool) -> usize {
        if guides { 5 } else { 3 }
    }

    /// The compute kernel's output layout with or without guides.
    pub fn outputs(&self, guides: bool) -> &wgpu::BindGroupLayout {
        &self.outputs[usize::from(guides)]
    }

    /// Both output layouts: 3 and 5 storage textures. A device allowed
    /// fewer than 5 a stage (WebGPU's default is 4) gets the 3-texture one
    /// for both: the compute kernel with guides is refused there before
    /// it is built ([`TracePipeline::build`]), and a layout over the limit
    /// would be a validation error at start-up.
    pub fn output_layouts(device: &wgpu::Device) -> [wgpu::BindGroupLayout; 2] {
        let limit = device.limits().max_storage_textures_per_shader_stage as usize;
        [false, true].map(|guides| {
            let targets = Self::targets(guides);
            let fits = targets <= limit;
            Self::output_layout(device, if fits { targets } else { Self::targets(false) })
        })
    }

    /// Group 1 of the CPU kernel's pass: the band's samples.
    pub fn cpu_samples_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
        device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("cpu samples"),
            entries: &[entry(
                CPU_SAMPLES_BINDING,
                wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Float { filterable: false },
                    view_dimension: wgpu::TextureViewDimension::D2Array,
                    multisampled: false,
                },
            )],
        })
    }

    fn output_layout(device: &wgpu::Device, count: usize) -> wgpu::BindGroupLayout {
        // The compute kernel's alone: a page's WebGPU counts storage
        // textures per stage (4 in a fragment stage), so none is declared
        // to the fragment stage that never writes them.
        let output = |binding| wgpu::BindGroupLayoutEntry {
            visibility: wgpu::ShaderStages::COMPUTE,
            ..entry(
                binding,
                wgpu::BindingType::StorageTexture {
                    access: wgpu::StorageTextureAccess::WriteOnly,
                    format: ACCUMULATION_FORMAT,
                    view_dimension: wgpu::TextureViewDimension::D2,
                },
            )
        };
        let entries: Vec<_> = (0..count as u32).map(output).collect();
        device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("trace outputs"),
            entries: &entries,
        })
    }
}

/// Timestamp writes for a pass that may be recorded as several: the
/// beginning goes on the first band, the end on the last.
#[derive(Clone, Copy)]
pub struct PassTimestamps<'a> {
    pub query_set: &'a wgpu::QuerySet,
    pub beginning: Option<u32>,
    pub end: Option<u32>,
}

impl<'a> PassTimestamps<'a> {
    /// The writes of band `index` out of `count`.
    fn for_band(self, index: usize, count: usize) -> Option<Self> {
        let beginning = self.beginning.filter(|_| index == 0);
        let end = self.end.filter(|_| index + 1 == count);
        (beginning.is_some() || end.is_some()).then_some(Self {
            beginning,
            end,
            ..self
        })
    }

    pub fn render(self) -> wgpu::RenderPassTimestampWrites<'a> {
        wgpu::RenderPassTimestampWrites {
            query_set: self.query_set,
            beginning_of_pass_write_index: self.beginning,
            end_of_pass_write_index: self.end,
        }
    }

    pub fn compute(self) -> wgpu::ComputePassTimestampWrites<'a> {
        wgpu::ComputePassTimestampWrites {
            query_set: self.query_set,
            beginning_of_pass_write_index: self.beginning,
            end_of_pass_write_index: self.end,
        }
    }
}

/// The CPU kernel's samples of a band, traced now and uploaded as the
/// group 1 of its pass: a layer each of `cpu_kernel::BLOCKS`. A texture of
/// its own per band: the bands of one submit each read their own samples,
/// and a `write_texture` lands before the whole submit, so one shared
/// texture would give every band the last band's.
pub fn cpu_samples_group(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    layouts: &TraceLayouts,
    scene: &crate::cpu_kernel::CpuScene,
    frame: &crate::gpu::scene_gpu::Frame,
) -> wgpu::BindGroup {
    let texels = crate::cpu_kernel::trace_band(scene, frame);
    let size = wgpu::Extent3d {
        width: frame.render_size[0] as u32,
        height: frame.band_end - frame.band_start,
        depth_or_array_layers: crate::cpu_kernel::BLOCKS,
    };
    let texture = device.create_texture(&wgpu::TextureDescriptor {
        label: Some("cpu samples"),
        size,
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: ACCUMULATION_FORMAT,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    queue.write_texture(
        texture.as_image_copy(),
        bytemuck::cast_slice(&texels),
        wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(size.width * 16),
            rows_per_image: Some(size.height),
        },
        size,
    );
    let view = texture.create_view(&wgpu::TextureViewDescriptor {
        dimension: Some(wgpu::TextureViewDimension::D2Array),
        ..Default::default()
    });
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("cpu samples"),
        layout: &layouts.cpu_samples,
        entries: &[wgpu::BindGroupEntry {
            binding: CPU_SAMPLES_BINDING,
            resource: wgpu::BindingResource::TextureView(&view),
        }],
    })
}

/// One band's pass: what it binds and where it stands among the call's.
pub struct BandPass<'a> {
    pub pipeline: &'a TracePipeline,
    pub scene: &'a wgpu::BindGroup,
    /// The frame uniform's offset in its ring buffer.
    pub frame_offset: u32,
    /// The compute kernel's outputs (the accumulation's write set).
    pub outputs: Option<&'a wgpu::BindGroup>,
    /// The CPU kernel's samples of this band.
    pub cpu_samples: Option<&'a wgpu::BindGroup>,
    pub accumulation: &'a Accumulation,
    /// The traced region's width and the rows of this band.
    pub width: u32,
    pub rows: Range<u32>,
    /// The region's height: the fragment kernel's viewport.
    pub height: u32,
    pub index: usize,
    pub count: usize,
}

impl BandPass<'_> {
    pub fn record(&self, encoder: &mut wgpu::CommandEncoder, timestamps: Option<PassTimestamps>) {
        let timestamps = timestamps.and_then(|t| t.for_band(self.index, self.count));
        let rows = self.rows.end - self.rows.start;
        match self.pipeline {
            TracePipeline::Fragment(pipeline) | TracePipeline::Cpu(pipeline) => {
                let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("trace"),
                    color_attachments: &self.accumulation.attachments(),
                    depth_stencil_attachment: None,
                    timestamp_writes: timestamps.map(PassTimestamps::render),
                    occlusion_query_set: None,
                    multiview_mask: None,
                });
                pass.set_viewport(0.0, 0.0, self.width as f32, self.height as f32, 0.0, 1.0);
                pass.set_scissor_rect(0, self.rows.start, self.width, rows);
                pass.set_pipeline(pipeline);
                pass.set_bind_group(0, self.scene, &[self.frame_offset]);
                if let Some(samples) = self.cpu_samples {
                    pass.set_bind_group(1, samples, &[]);
                }
                pass.draw(0..3, 0..1);
            }
            TracePipeline::Compute(pipeline) => {
                let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some("trace"),
                    timestamp_writes: timestamps.map(PassTimestamps::compute),
                });
                pass.set_pipeline(pipeline);
                pass.set_bind_group(0, self.scene, &[self.frame_offset]);
                pass.set_bind_group(1, self.outputs, &[]);
                pass.dispatch_workgroups(
                    self.width.div_ceil(WORKGROUP.0),
                    rows.div_ceil(WORKGROUP.1),
                    1,
                );
            }
        }
    }
}
