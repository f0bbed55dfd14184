//! The display stage: the pass that turns the accumulation into an image
//! on any colour target (exposure, tone map, encoding), its uniform, the
//! auto-exposure metering it reads and the denoisers (`denoise.rs`, and
//! OIDN's `oidn_stage.rs`).

use super::oidn_stage::OidnStage;
use crate::gpu::auto_exposure::AutoExposure;
use crate::gpu::denoise::Denoiser;
use crate::gpu::features::FeatureSet;
use crate::gpu::pipelines::{entry, float_texture, shader_module, uniform};
use crate::gpu::shader_source::Program;
use anyhow::Result;
use bytemuck::{Pod, Zeroable};
use std::collections::HashMap;
use wgpu::util::DeviceExt;

pub(super) struct DisplayStage {
    pub(super) layout: wgpu::BindGroupLayout,
    /// One pipeline per target format, made on first use.
    pub(super) pipelines: HashMap<wgpu::TextureFormat, wgpu::RenderPipeline>,
    pub(super) module: wgpu::ShaderModule,
    pub(super) buffer: wgpu::Buffer,
    /// Meters the accumulation for auto exposure; the display pass reads
    /// its result buffer.
    pub(super) auto_exposure: AutoExposure,
    /// What the auto-exposure result was metered from: the display of one
    /// frame on two targets meters once.
    pub(super) metered_from: Option<MeteredFrom>,
    /// The denoiser, made the first time the display asks for it.
    pub(super) denoiser: Option<Denoiser>,
    /// What the denoiser's output was filtered from.
    pub(super) denoised_from: Option<MeteredFrom>,
    /// OIDN: its read-back, thread and output.
    pub(super) oidn: OidnStage,
}

impl DisplayStage {
    pub(super) fn new(device: &wgpu::Device) -> Result<Self> {
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("display"),
            entries: &[
                entry(0, uniform()),
                entry(1, float_texture(false)),
                entry(2, uniform()),
                entry(3, float_texture(false)),
            ],
        });
        let buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("display"),
            contents: bytemuck::bytes_of(&DisplayUniform::zeroed()),
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        });
        Ok(Self {
            layout,
            pipelines: HashMap::new(),
            module: shader_module(device, Program::Display, &FeatureSet::default(), "")?,
            buffer,
            auto_exposure: AutoExposure::new(device)?,
            metered_from: None,
            denoiser: None,
            denoised_from: None,
            oidn: OidnStage::default(),
        })
    }
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub(super) struct DisplayUniform {
    pub(super) exposure_scale: f32,
    pub(super) tone_map: u32,
    pub(super) encode_srgb: u32,
    /// 0: manual exposure; 1: times the key's metered scale; 2: times
    /// Massal's RMS scale.
    pub(super) auto_exposure: u32,
    pub(super) origin: [f32; 2],
    pub(super) scale: [f32; 2],
    /// 1: paint the pixels that dropped a non-finite sample magenta.
    pub(super) show_non_finite: u32,
    pub(super) padding: u32,
}

/// The accumulation an auto-exposure metering read: the frame that wrote
/// it, the targets' size and the traced region.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct MeteredFrom {
    /// Counts the images shown (rounds and previews).
    pub(super) shown: u32,
    pub(super) size: (u32, u32),
    pub(super) render_size: (u32, u32),
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
