//! A bake written to disk, the image and its sidecar (`<image>.mapping.ron`):
//! shared by `marbre bake` and the viewer's Bake… buttons, so both write
//! the same files.

use crate::gpu::GpuContext;
use crate::gpu::bake::bake;
use anyhow::Result;
use marbre_core::bake::{
    BakeMapping, BakeProperty, ObjectRef, TEXEL_CONVENTION, UvSurface, check_output, check_size,
    color_space, encode_image,
};
use marbre_core::scene::Scene;
use marbre_core::texture::ImageSet;
use std::path::PathBuf;

/// What to bake and where.
#[derive(Debug, Clone, PartialEq)]
pub struct BakeRequest {
    pub object: ObjectRef,
    pub property: BakeProperty,
    /// Texels a side.
    pub size: u32,
    /// A .png or .exr file in an existing folder.
    pub output: PathBuf,
    /// The preset the scene came from, for the sidecar.
    pub preset: String,
}

/// Bakes `request` from `scene` (with its loaded `images`) on `ctx` and
/// writes the image and its sidecar; returns what the sidecar says. Bad
/// sizes and outputs are refused before any GPU work.
pub fn bake_to_file(
    ctx: &GpuContext,
    scene: &Scene,
    images: &ImageSet,
    request: &BakeRequest,
) -> Result<BakeMapping> {
    let BakeRequest {
        object,
        property,
        size,
        output,
        preset,
    } = request;
    check_size(*size)?;
    let format = check_output(output)?;
    let surface = UvSurface::new(scene, *object, *size)?;
    let texels = bake(ctx, scene, images, &surface, *property, *size)?;
    let image_bytes = encode_image(format, *property, *size, &texels)?;
    let bump_height = (*property == BakeProperty::Bump).then(|| {
        scene
            .materials()
            .nth(object.first_material(scene) as usize)
            .map_or(0.0, |m| m.bump_height)
    });
    let mapping = BakeMapping {
        preset: preset.clone(),
        object: object.name(scene),
        primitive: object.kind().into(),
        uv_mapping: surface.description.clone(),
        texels: TEXEL_CONVENTION.into(),
        property: property.name().into(),
        size: *size,
        color_space: color_space(*property, format).into(),
        bump_height,
    };
    mapping.write_with_image(output, &image_bytes)?;
    Ok(mapping)
}
