//! The material editor's Bake… buttons: a bake of the scene as it is in
//! the viewer (edits included), written beside the preset as
//! `<preset>-<object>-<property>.png|.exr` at [`BAKE_SIZE`] texels a side,
//! on a worker thread with its own headless device (through the same
//! `bake_file` as `marbre bake`), so the frame never waits for it.

use crate::panel::BAKE_SIZE;
use marbre_core::bake::{BakeProperty, ObjectRef};
use marbre_core::scene::Scene;
use marbre_core::texture::ImageSet;
use marbre_render::bake_file::{BakeRequest, bake_to_file};
use marbre_render::gpu::GpuContext;
use marbre_render::worker::{Worker, names};
use std::path::{Path, PathBuf};
use std::sync::mpsc::{Receiver, channel};

/// Where a bake of `object`'s `property` goes, beside `preset`: named
/// after the preset, the object and the property, `.png` for colours and
/// `.exr` for data.
pub fn output_beside(preset: &Path, object_name: &str, property: BakeProperty) -> PathBuf {
    let stem = preset
        .file_stem()
        .map_or_else(|| "scene".into(), |s| s.to_string_lossy());
    // A name from the preset may hold characters a file name cannot.
    let object: String = object_name
        .chars()
        .map(|c| {
            if c.is_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect();
    preset.with_file_name(format!(
        "{stem}-{object}-{}.{}",
        property.name(),
        property.default_extension()
    ))
}

/// Bakes running in the background; each reports one message when done.
/// Dropping them waits for those still running: each has a device of its
/// own, which must be gone before the process exits (`worker`'s doc).
#[derive(Default)]
pub struct Bakes {
    running: Vec<(Receiver<Result<String, String>>, Worker)>,
}

impl Bakes {
    /// Starts a bake of `object`'s `property` from a copy of `scene`; an
    /// error if its thread cannot start.
    pub fn start(
        &mut self,
        scene: &Scene,
        images: &ImageSet,
        preset: &Path,
        object: ObjectRef,
        property: BakeProperty,
    ) -> Result<(), String> {
        let request = BakeRequest {
            object,
            property,
            size: BAKE_SIZE,
            output: output_beside(preset, &object.name(scene), property),
            preset: preset.display().to_string(),
        };
        let (scene, images) = (scene.clone(), images.clone());
        let (send, receive) = channel();
        let output = request.output.clone();
        let started = Worker::spawn(names::BAKE, move || {
            let result = GpuContext::headless()
                .and_then(|ctx| bake_to_file(&ctx, &scene, &images, &request))
                .map(|m| {
                    format!(
                        "baked {} of {} “{}” to {}",
                        m.property,
                        m.primitive,
                        m.object,
                        request.output.display()
                    )
                })
                .map_err(|e| format!("bake: {e:#}"));
            let _ = send.send(result);
        });
        let worker = started
            .map_err(|e| format!("bake of {}: cannot start its thread: {e}", output.display()))?;
        self.running.push((receive, worker));
        Ok(())
    }

    /// The messages of the bakes finished since the last call.
    pub fn finished(&mut self) -> Vec<Result<String, String>> {
        let mut done = Vec::new();
        self.running.retain(|(r, _)| match r.try_recv() {
            Ok(result) => {
                done.push(result);
                false
            }
            Err(std::sync::mpsc::TryRecvError::Empty) => true,
            Err(std::sync::mpsc::TryRecvError::Disconnected) => false,
        });
        done
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_bake_goes_beside_the_preset_named_after_it() {
        let path = output_beside(
            Path::new("/p/presets/default.ron"),
            "big marble/2",
            BakeProperty::Diffuse,
        );
        assert_eq!(
            path,
            Path::new("/p/presets/default-big_marble_2-diffuse.png")
        );
        let path = output_beside(Path::new("a.ron"), "ground", BakeProperty::Bump);
        assert_eq!(
            path,
            Path::new("ground").with_file_name("a-ground-bump.exr")
        );
    }
}
