//! The preset being edited: the file it lives in, and whether the scene on
//! screen has edits that file does not have yet.
//!
//! The camera is left out of that comparison, as it is of the undo history:
//! orbiting is looking, not editing, so it never asks "save changes?". A
//! camera saved on purpose goes in with the next Save.
//!
//! A scene opened from an OBJ file is a new preset that has no file yet:
//! its document's path is the OBJ (what it was opened from, watched for
//! outside edits, reopened at the next start), and Save never writes
//! there. It asks where instead, suggesting `<name>.ron` beside the OBJ
//! ([`Document::save_as_suggestion`]), as Blender's Save does for an
//! imported file never saved; [`Document::save`] refuses to write a preset
//! over an OBJ or MTL file whatever the route.

use marbre_core::capped_read::{self, read_capped_to_string};
use marbre_core::preset::{self, Header, Preset, PresetError};
use marbre_core::scene::{Change, Scene};
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
    /// Whether the scene had edits the file lacks, as of the last
    /// [`Document::observe`]: read every frame (the panel's mark, the
    /// autosave) without comparing scenes.
    unsaved: bool,
}

impl Document {
    pub fn new(path: &Path, header: Header, scene: &Scene) -> Self {
        Self {
            path: path.to_owned(),
            header,
            saved: scene.clone(),
            saved_text: read_capped_to_string(path, capped_read::PRESET).ok(),
            unsaved: false,
        }
    }

    /// The document of `path`, whose file holds `saved`, with `scene` on
    /// screen: edits recovered from a crashed run's autosave, unsaved from
    /// the first frame (the panel's mark, the autosave), not only once
    /// edited again. `Document::new` would count them saved.
    pub fn with_edits(path: &Path, header: Header, saved: &Scene, scene: &Scene) -> Self {
        let mut document = Self::new(path, header, saved);
        document.unsaved = document.is_dirty(scene);
        document
    }

    /// Follows the frame's `change` (from the scene of the frame before):
    /// only an edit can make the scene differ from the file, or, undone,
    /// the same again.
    pub fn observe(&mut self, scene: &Scene, change: Change) {
        if change.edits_document() {
            self.unsaved = self.is_dirty(scene);
        }
    }

    /// Whether the scene has edits the file lacks, as of the last
    /// [`Document::observe`] or save.
    pub fn unsaved(&self) -> bool {
        self.unsaved
    }

    /// Whether `scene` has edits the file does not have (camera aside), as
    /// of now: for the actions that may lose them (open, quit).
    pub fn is_dirty(&mut self, scene: &Scene) -> bool {
        self.saved.camera = scene.camera;
        *scene != self.saved
    }

    /// Whether the document is a preset file Save writes to; false for a
    /// scene opened from an OBJ file and not saved as a preset yet.
    pub fn has_preset_file(&self) -> bool {
        has_extension(&self.path, &["ron"])
    }

    /// Where Save as suggests writing: the preset itself, or for a scene
    /// opened from an OBJ file `<name>.ron` beside it.
    pub fn save_as_suggestion(&self) -> PathBuf {
        self.path.with_extension("ron")
    }

    /// Saves `scene` to `path` atomically; from then on the document is
    /// that file, clean. An OBJ or MTL file is never overwritten.
    pub fn save(&mut self, scene: &Scene, path: &Path) -> Result<(), PresetError> {
        if has_extension(path, &["obj", "mtl"]) {
            return Err(PresetError::Write {
                path: path.to_owned(),
                cause: std::io::Error::new(
                    std::io::ErrorKind::InvalidInput,
                    "a preset is never written over an OBJ or MTL file; save it as a .ron file",
                ),
            });
        }
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
        self.unsaved = false;
        Ok(())
    }

    /// The preset that saving `scene` writes.
    pub fn preset(&self, scene: &Scene) -> Preset {
        Preset::with_header(&self.header, scene.clone())
    }

    /// Whether the file on disk now differs from what this document last
    /// read or wrote there: an edit made outside the app.
    pub fn changed_on_disk(&self) -> bool {
        read_capped_to_string(&self.path, capped_read::PRESET).ok() != self.saved_text
    }
}

/// Whether `path` ends in one of `extensions` (lower case), in any case.
fn has_extension(path: &Path, extensions: &[&str]) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| extensions.contains(&e.to_ascii_lowercase().as_str()))
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

    /// Recovered edits are unsaved before any further edit, and a
    /// recovered scene the file already holds is not.
    #[test]
    fn recovered_edits_are_unsaved_from_the_start() {
        let saved = Scene::default();
        let mut recovered = saved.clone();
        recovered.render.display.exposure += 1.0;
        let path = Path::new("recovered.ron");
        let document = Document::with_edits(path, Header::default(), &saved, &recovered);
        assert!(document.unsaved());
        let mut moved = saved.clone();
        moved.camera.distance *= 2.0;
        let document = Document::with_edits(path, Header::default(), &saved, &moved);
        assert!(!document.unsaved(), "a camera alone is no edit");
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

    /// A scene opened from an OBJ file has no preset file: Save as
    /// suggests a .ron beside it, and no route writes over the OBJ.
    #[test]
    fn a_scene_opened_from_an_obj_never_overwrites_it() {
        let dir = tempfile::Builder::new()
            .prefix("document-obj")
            .tempdir()
            .unwrap();
        let obj = dir.path().join("Cube.OBJ");
        let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
        std::fs::write(&obj, text).unwrap();
        let scene = Scene::default();
        let mut document = Document::new(&obj, Header::default(), &scene);
        assert!(!document.has_preset_file());
        assert!(!document.is_dirty(&scene), "nothing to lose yet");
        assert_eq!(document.save_as_suggestion(), dir.path().join("Cube.ron"));
        let e = document.save(&scene, &obj).unwrap_err().to_string();
        assert!(e.contains("Cube.OBJ") && e.contains("never written"), "{e}");
        let mtl = dir.path().join("cube.mtl");
        assert!(document.save(&scene, &mtl).is_err());
        assert!(!mtl.exists());
        assert_eq!(std::fs::read_to_string(&obj).unwrap(), text);
        let preset = document.save_as_suggestion();
        document.save(&scene, &preset).unwrap();
        assert!(document.has_preset_file());
        assert_eq!(document.path, preset);
        assert_eq!(std::fs::read_to_string(&obj).unwrap(), text);
    }
}
