//! The images a scene's textures read: loaded once, packed into the atlas
//! the GPU samples, and sampled the same way on the CPU for the reference.

use super::image::{
    ColorSpace, ImageAtlas, ImageFilter, ImageLevel, ImageWrap, MipImage, load_image,
};
use glam::{Vec2, Vec4};
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// An image file and how its integer codes decode.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct ImageSource {
    pub path: PathBuf,
    #[serde(default)]
    pub color_space: ColorSpace,
}

/// The loaded images of a scene, in the order of [`ImageSet::sources`].
#[derive(Debug, Clone, PartialEq)]
pub struct ImageSet {
    sources: Vec<ImageSource>,
    atlas: ImageAtlas,
    /// The files that could not be read, shown as placeholders.
    placeholders: Vec<PathBuf>,
}

impl Default for ImageSet {
    fn default() -> Self {
        Self::empty()
    }
}

impl ImageSet {
    /// No images: a one-texel atlas.
    pub fn empty() -> Self {
        Self {
            sources: Vec::new(),
            atlas: ImageAtlas::pack(&[], 1).expect("an empty atlas fits"),
            placeholders: Vec::new(),
        }
    }

    /// Loads every source, packed into an atlas no larger than `max_side`
    /// (the GPU's `max_texture_dimension_2d`). A file that cannot be read
    /// becomes an obvious magenta-and-black placeholder and a note naming it
    /// and the cause, so the scene still renders; resampling and repairs
    /// are noted too. Only an atlas too large for the GPU is an error.
    pub fn load(
        sources: &[ImageSource],
        max_side: u32,
        notes: &mut Vec<String>,
    ) -> Result<Self, super::image::AtlasTooLarge> {
        let mut placeholders = Vec::new();
        let images: Vec<MipImage> = sources
            .iter()
            .map(
                |source| match load_image(&source.path, source.color_space) {
                    Ok(loaded) => {
                        notes.extend(loaded.notes);
                        loaded.image
                    }
                    Err(e) => {
                        notes.push(format!("{e}; showing a placeholder"));
                        placeholders.push(source.path.clone());
                        placeholder()
                    }
                },
            )
            .collect();
        let refs: Vec<&MipImage> = images.iter().collect();
        Ok(Self {
            sources: sources.to_vec(),
            atlas: ImageAtlas::pack(&refs, max_side)?,
            placeholders,
        })
    }

    /// The files that could not be read and show as placeholders (a
    /// command line render refuses them unless told otherwise).
    pub fn placeholders(&self) -> &[PathBuf] {
        &self.placeholders
    }

    pub fn sources(&self) -> &[ImageSource] {
        &self.sources
    }

    pub fn atlas(&self) -> &ImageAtlas {
        &self.atlas
    }

    /// The shader's `rect` of `source`, if it is loaded.
    pub fn rect(&self, source: &ImageSource) -> Option<[f32; 4]> {
        let i = self.sources.iter().position(|s| s == source)?;
        Some(self.atlas.entries[i].params())
    }

    /// `source` sampled as the shader samples it; None if not loaded.
    pub fn sample(
        &self,
        source: &ImageSource,
        uv: Vec2,
        filter: ImageFilter,
        wrap: ImageWrap,
        lod: f32,
    ) -> Option<Vec4> {
        let i = self.sources.iter().position(|s| s == source)?;
        Some(self.atlas.sample(i, uv, filter, wrap, lod))
    }
}

/// An 8×8 magenta and black checker: no real texture looks like it.
fn placeholder() -> MipImage {
    let texels = (0..64)
        .map(|k| {
            if (k % 8 + k / 8) % 2 == 0 {
                [1.0, 0.0, 1.0, 1.0]
            } else {
                [0.0, 0.0, 0.0, 1.0]
            }
        })
        .collect();
    MipImage::new(ImageLevel {
        width: 8,
        height: 8,
        texels,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn shipped() -> ImageSource {
        ImageSource {
            path: PathBuf::from(crate::REPO).join("presets/images/uv_grid.png"),
            color_space: ColorSpace::Srgb,
        }
    }

    /// A missing file gives a note naming it and the magenta placeholder;
    /// the other images load as usual.
    #[test]
    fn a_missing_image_becomes_a_named_placeholder() {
        let missing = ImageSource {
            path: PathBuf::from("nowhere/lost.png"),
            color_space: ColorSpace::Srgb,
        };
        let mut notes = Vec::new();
        let set = ImageSet::load(&[shipped(), missing.clone()], 8192, &mut notes).unwrap();
        assert_eq!(notes.len(), 1, "{notes:?}");
        assert!(notes[0].contains("lost.png") && notes[0].contains("placeholder"));
        let corner = set
            .sample(
                &missing,
                Vec2::new(0.01, 0.99),
                ImageFilter::Nearest,
                ImageWrap::Repeat,
                0.0,
            )
            .unwrap();
        assert_eq!(corner, Vec4::new(1.0, 0.0, 1.0, 1.0));
        assert_eq!(
            set.rect(&shipped()).map(|r| [r[2], r[3]]),
            Some([256.0, 256.0])
        );
        assert_eq!(
            set.rect(&ImageSource {
                color_space: ColorSpace::Linear,
                ..shipped()
            }),
            None
        );
    }
}
