//! Bakes a material property on the GPU (`marbre bake`, the viewer's
//! Bake… buttons): the scene's generated texture code
//! ([`texture_codegen::generate`], the same the trace pass runs) evaluated
//! at each texel's surface point (`marbre_core::bake::UvSurface`), through
//! the harnesses' plumbing (`harness::dispatch`). Its CPU oracle is
//! `marbre_core::bake::reference`.

use crate::gpu::context::GpuContext;
use crate::gpu::features::FeatureSet;
use crate::gpu::harness::dispatch;
use crate::gpu::pipelines::{
    buffer_entry, compute_pipeline_with, entry, float_texture, permutation_table, storage, uniform,
    upload_atlas,
};
use crate::gpu::scene_gpu;
use crate::gpu::shader_source::Program;
use crate::gpu::texture_codegen;
use anyhow::Result;
use bytemuck::{Pod, Zeroable};
use marbre_core::bake::{self, BakeProperty, UvSurface};
use marbre_core::scene::Scene;
use marbre_core::texture::ImageSet;

/// Texels evaluated per dispatch: 48 MiB of points, within every
/// adapter's storage-binding limit (128 MiB) and 16,384 workgroups.
const CHUNK: usize = 1 << 20;

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct BakeSettings {
    count: u32,
    property: u32,
    _pad: [u32; 2],
}

/// `BakeTexel` of bake.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct BakeTexel {
    p: [f32; 3],
    material: u32,
    pw: [f32; 3],
    _pad0: u32,
    uv: [f32; 2],
    _pad1: [f32; 2],
}

impl From<&bake::BakeTexel> for BakeTexel {
    fn from(t: &bake::BakeTexel) -> Self {
        Self {
            p: t.point.object.into(),
            material: t.material,
            pw: t.point.world.into(),
            uv: t.point.uv.into(),
            ..Zeroable::zeroed()
        }
    }
}

/// The case of bake.wgsl's switch that reads `property`.
fn property_id(property: BakeProperty) -> u32 {
    match property {
        BakeProperty::Diffuse => 0,
        BakeProperty::Specular => 1,
        BakeProperty::Roughness => 2,
        BakeProperty::Bump => 3,
        BakeProperty::Opacity => 4,
        BakeProperty::Emission => 5,
    }
}

/// `property` over `surface`'s `size` × `size` texels of `scene` (whose
/// images are `images`): linear RGBA per texel, row 0 at the top, unclamped
/// (the bump unscaled by `bump_height`); texels off the surface (between a
/// mesh's triangles in uv) are transparent black.
pub fn bake(
    ctx: &GpuContext,
    scene: &Scene,
    images: &ImageSet,
    surface: &UvSurface,
    property: BakeProperty,
    size: u32,
) -> Result<Vec<[f32; 4]>> {
    let device = &ctx.device;
    let generated = texture_codegen::generate(scene, images)?;
    let (pipeline, layout) = compute_pipeline_with(
        device,
        Program::Bake,
        &FeatureSet::for_scene(scene),
        &generated.wgsl,
        &[
            entry(2, uniform()),
            entry(6, uniform()),
            entry(7, uniform()),
            entry(8, float_texture(false)),
            entry(17, uniform()),
            entry(18, storage(true)),
            entry(19, storage(false)),
        ],
        "cs_bake",
    )?;
    let init = |label: &str, contents: &[u8], usage| dispatch::upload(ctx, label, contents, usage);
    let materials = init(
        "materials",
        bytemuck::cast_slice(&scene_gpu::materials(scene)),
        wgpu::BufferUsages::UNIFORM,
    )?;
    let permutation = init(
        "permutation",
        bytemuck::cast_slice(&permutation_table()),
        wgpu::BufferUsages::UNIFORM,
    )?;
    let params = init(
        "texture params",
        bytemuck::cast_slice(&generated.params),
        wgpu::BufferUsages::UNIFORM,
    )?;
    let atlas = upload_atlas(ctx, images.atlas());

    let count = size as usize * size as usize;
    let mut out = vec![[0.0; 4]; count];
    let mut first = 0;
    while first < count {
        let last = (first + CHUNK).min(count);
        let (indices, texels): (Vec<usize>, Vec<BakeTexel>) = (first..last)
            .filter_map(|i| surface.texel(i, size).map(|t| (i, BakeTexel::from(&t))))
            .unzip();
        first = last;
        if texels.is_empty() {
            continue;
        }
        let settings = BakeSettings {
            count: texels.len() as u32,
            property: property_id(property),
            _pad: [0; 2],
        };
        let settings = init(
            "bake settings",
            bytemuck::bytes_of(&settings),
            wgpu::BufferUsages::UNIFORM,
        )?;
        let points = init(
            "bake texels",
            bytemuck::cast_slice(&texels),
            wgpu::BufferUsages::STORAGE,
        )?;
        let values = dispatch::output(ctx, "bake values", (texels.len() * 16) as u64)?;
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("bake"),
            layout: &layout,
            entries: &[
                buffer_entry(2, &materials),
                buffer_entry(6, &permutation),
                buffer_entry(7, &params),
                wgpu::BindGroupEntry {
                    binding: 8,
                    resource: wgpu::BindingResource::TextureView(&atlas),
                },
                buffer_entry(17, &settings),
                buffer_entry(18, &points),
                buffer_entry(19, &values),
            ],
        });
        let mut encoder = device.create_command_encoder(&Default::default());
        let groups = ((texels.len() as u32).div_ceil(64), 1);
        dispatch::record(ctx, &mut encoder, &pipeline, &bind_group, groups)?;
        let results: Vec<[f32; 4]> = dispatch::read_back(ctx, encoder, &values)?;
        for (i, v) in indices.into_iter().zip(results) {
            out[i] = v;
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The bake's settings and texels have its WGSL twin's layout, as naga lays it out.
    #[test]
    fn the_settings_and_texels_have_their_wgsl_twins_layout() {
        use crate::gpu::twin_layout::{module_of, twin_layout};
        let module = &module_of(
            Program::Bake,
            &FeatureSet::default(),
            &texture_codegen::generate(&Scene::default(), &ImageSet::empty())
                .unwrap()
                .wgsl,
        );
        twin_layout!(module, BakeSettings, [count, property]);
        twin_layout!(module, BakeTexel, [p, material, pw, uv]);
    }
}
