//! The preset being edited: the file it lives in, and whether the scene on
//! screen has edits that file does not have yet.
//!
//! The camera is left out of that comparison, as it is of the undo history:
//! orbiting is looking, not editing, so it never asks "save changes?". A
//! camera saved on purpose goes in with the next Save.

use marbre_core::preset::{self, Header, Preset, PresetError};
use marbre_core::scene::Scene;
use std::path::{Path, PathBuf};

pub struct Document {
    /// The preset file: Save writes here.
    pub path: PathBuf,
    /// The preset's description and colour encoding, kept so that saving
    /// does not lose them.
    pub header: Header,
    /// The scene as last loaded or saved; its camera is set to the one it
    /// is compared with, so that only the rest counts.
    saved: Scene,
    /// The text last written to or read from `path`: a change the file
    /// watcher reports with this content is our own save, not an outside
    /// edit.
    saved_text: Option<String>,
}

impl Document {
    pub fn new(path: &Path, header: Header, scene: &Scene) -> Self {
        Self {
            path: path.to_owned(),
            header,
            saved: scene.clone(),
            saved_text: std::fs::read_to_string(path).ok(),
        }
    }

    /// Whether `scene` has edits the file does not have (camera aside).
    /// Called every frame: nothing is cloned.
    pub fn is_dirty(&mut self, scene: &Scene) -> bool {
        self.saved.camera = scene.camera;
        *scene != self.saved
    }

    /// Saves `scene` to `path` atomically; from then on the document is
    /// that file, clean.
    pub fn save(&mut self, scene: &Scene, path: &Path) -> Result<(), PresetError> {
        let preset = self.preset(scene);
        let text = preset::to_text(&preset, path)?;
        marbre_core::atomic_write::write_atomic(path, text.as_bytes()).map_err(|cause| {
            PresetError::Write {
                path: path.to_owned(),
                cause,
            }
        })?;
        self.path = path.to_owned();
        self.saved = scene.clone();
        self.saved_text = Some(text);
        Ok(())
    }

    /// The preset that saving `scene` writes.
    pub fn preset(&self, scene: &Scene) -> Preset {
        Preset::with_header(&self.header, scene.clone())
    }

    /// Whether the file on disk now differs from what this document last
    /// read or wrote there: an edit made outside the app.
    pub fn changed_on_disk(&self) -> bool {
        std::fs::read_to_string(&self.path).ok() != self.saved_text
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use marbre_core::scene::ColorEncoding;

    #[test]
    fn an_edit_makes_it_dirty_and_a_camera_move_does_not() {
        let scene = Scene::default();
        let mut document = Document::new(Path::new("unsaved.ron"), Header::default(), &scene);
        let mut moved = scene.clone();
        moved.camera.distance *= 2.0;
        assert!(!document.is_dirty(&moved));
        let mut edited = moved.clone();
        edited.render.display.exposure += 1.0;
        assert!(document.is_dirty(&edited));
        assert!(!document.is_dirty(&moved), "undoing the edit cleans it");
    }

    #[test]
    fn saving_cleans_it_and_its_own_save_is_not_an_outside_change() {
        let dir = tempfile::Builder::new()
            .prefix("document-save")
            .tempdir()
            .unwrap();
        let path = dir.path().join("scene.ron");
        let mut scene = Scene::default();
        scene.point_light = Some(marbre_core::scene::PointLight {
            color: glam::Vec3::new(0.5, 0.25, 1.0),
            ..Default::default()
        });
        let header = Header {
            description: "a test".into(),
            colors: ColorEncoding::Srgb,
        };
        let mut document = Document::new(&path, header, &scene);
        let mut edited = scene.clone();
        edited.render.display.exposure = 2.0;
        assert!(document.is_dirty(&edited));
        document.save(&edited, &path).unwrap();
        assert!(!document.is_dirty(&edited));
        assert!(!document.changed_on_disk());
        let loaded = preset::load(&path).unwrap().preset;
        assert_eq!(loaded.description, "a test");
        assert_eq!(
            loaded.colors,
            ColorEncoding::Srgb,
            "the file keeps its encoding"
        );
        let light = loaded.scene.point_light.unwrap().color;
        assert!(
            (light - glam::Vec3::new(0.5, 0.25, 1.0))
                .abs()
                .max_element()
                < 1e-6
        );
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(
            text.contains("color: (0.735357, 0.537"),
            "written as sRGB: {text}"
        );
        assert_eq!(loaded.scene.render.display.exposure, 2.0);
        std::fs::write(&path, "(description: \"edited outside\")").unwrap();
        assert!(document.changed_on_disk());
    }
}
