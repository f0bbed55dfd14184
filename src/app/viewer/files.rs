//! Files in and out of the viewer: presets, OBJ files (each opened as a
//! new scene) and environment maps (typed, dropped, picked in a dialog or
//! from the recent list), saves, hot reload, and the answers to the
//! prompts that guard unsaved edits.
//!
//! Every load builds the new scene aside and installs it only if all of it
//! loaded, so a bad file leaves the scene on screen as it was and says why
//! in the panel.

use super::{StartupLoad, Viewer};
use crate::app::document::Document;
use crate::app::file_dialogs::{self, DialogPurpose, OpenDialog, dialogs_available};
use crate::app::file_watch::{FileWatch, is_same_file};
use crate::app::history::History;
use crate::app::prompts::{Answer, Prompt};
use crate::app::recovery;
use crate::app::scene_loader::{FileKind, ReadyScene, SceneKind, SceneLoad};
use crate::app::share_link;
use crate::panel::save_as::SaveAs;
use anyhow::{Context as _, Result};
use marbre_core::envmap;
use marbre_core::preset::{self, Header};
use marbre_core::scene::{EnvSource, LdrImages, OrbitCamera, Scene};
use marbre_core::texture::ImageSet;
use marbre_render::gpu::shader_source;
use marbre_render::session::{load_environment, load_images, load_scene, max_texture_side};
use std::path::{Path, PathBuf};

impl Viewer {
    /// A file dropped on the window or picked from the recent list: a
    /// `.ron` is a preset, an `.obj` a new scene around the mesh, anything
    /// else an environment map ([`FileKind`]).
    pub(super) fn load_dropped(&mut self, path: &Path) {
        match FileKind::of(path) {
            FileKind::Preset | FileKind::Obj => self.request_load_preset(path),
            FileKind::Environment => self.load_environment(path),
        }
    }

    /// Loads `path` (a preset, or an OBJ file as a new scene), first
    /// asking what to do with unsaved edits.
    pub(super) fn request_load_preset(&mut self, path: &Path) {
        if self.edits.document.is_dirty(&self.scene) {
            self.edits.prompt = Some(Prompt::LoadPreset(path.to_owned()));
        } else {
            self.load_preset(path);
        }
    }

    /// Starts loading the preset (or OBJ file) at `path` on a worker
    /// thread; the scene on screen stays until it has all loaded
    /// ([`Viewer::poll_loading`]).
    pub(super) fn load_preset(&mut self, path: &Path) {
        self.start_loading(path, None);
    }

    /// Starts a load; `keep_view` is the camera to keep if the file's own
    /// camera is the one the preset had (a reload after an outside edit).
    fn start_loading(&mut self, path: &Path, keep_view: Option<KeepView>) {
        let (w, h) = self.renderer.size();
        let kind = scene_kind(path, w as f32 / h.max(1) as f32);
        let load = SceneLoad::start(path, kind, None, max_texture_side(&self.ctx));
        self.incoming.loading = Some((load, keep_view));
    }

    /// Starts loading the preset the window opens on, with the command
    /// line's `--env`; until it is in, input is held ([`StartupLoad`]).
    pub(super) fn start_startup_load(&mut self, path: &Path, may_fall_back: bool) {
        let env = self.options.env.as_deref();
        let kind = scene_kind(path, super::startup_aspect(&self.window));
        let load = SceneLoad::start(path, kind, env, max_texture_side(&self.ctx));
        self.incoming.loading = Some((load, None));
        self.panel.preset_path = path.display().to_string();
        let startup = self
            .incoming
            .startup
            .get_or_insert_with(StartupLoad::default);
        startup.may_fall_back = may_fall_back;
    }

    /// Installs a finished load, or says why it failed (the scene on
    /// screen then stays as it was); shows the progress meanwhile. Only a
    /// start-up load with nothing to fall back to fails the viewer, as a
    /// preset named on the command line that does not load always has.
    pub(super) fn poll_loading(&mut self) -> Result<()> {
        let Some((load, _)) = &self.incoming.loading else {
            self.panel.progress = None;
            return Ok(());
        };
        let Some(result) = load.poll() else {
            let (stage, fraction) = load.progress();
            self.panel.progress = Some((format!("{}: {stage}", load.path().display()), fraction));
            return Ok(());
        };
        let (load, keep_view) = self.incoming.loading.take().expect("a load is under way");
        self.panel.progress = None;
        // A reload after an outside edit is the same document, not an open.
        let opened = keep_view.is_none();
        let installed = result.and_then(|ready| self.install_loaded(load.path(), ready, keep_view));
        if installed.is_ok() && opened {
            self.offer_recovery();
        }
        match (installed, self.incoming.startup.as_ref()) {
            (Ok(()), None) => Ok(()),
            // Undo starts at the loaded scene, not at the placeholder.
            (Ok(()), Some(_)) => {
                self.edits.history = History::new(&self.scene);
                Ok(())
            }
            (Err(e), None) => {
                let document = self.edits.document.save_as_suggestion();
                self.panel.load_failed(format!("{e:#}"), &document);
                Ok(())
            }
            // The last session's preset no longer loads: say why, and
            // start on the default one rather than not at all.
            (Err(e), Some(startup)) if startup.may_fall_back => {
                self.panel
                    .error(format!("{e:#}; opening the default preset instead"));
                self.start_startup_load(&super::default_preset(), false);
                Ok(())
            }
            (Err(e), Some(_)) => Err(e),
        }
    }

    /// Handles the input held while the start-up scene loaded, in order,
    /// once the scene is in (installing it builds its shader, waiting):
    /// then it is what the window shows, and an F12 pressed meanwhile saves
    /// it rather than the placeholder.
    pub(super) fn release_held_input(&mut self) -> Result<()> {
        if self.incoming.loading.is_some() {
            return Ok(());
        }
        let Some(startup) = self.incoming.startup.take() else {
            return Ok(());
        };
        log::info!(
            "the start-up scene is in: {} held input events handled now",
            startup.held_events.len()
        );
        for event in &startup.held_events {
            self.handle_event(event)?;
        }
        Ok(())
    }

    fn install_loaded(
        &mut self,
        path: &Path,
        ready: ReadyScene,
        keep_view: Option<KeepView>,
    ) -> Result<()> {
        let loaded = ready.loaded;
        self.renderer.provide_geometry(ready.geometry);
        self.kernels
            .time_if_needed(&self.ctx, &loaded, self.renderer.size());
        self.apply_scene(
            loaded.scene.clone(),
            loaded.env.as_ref(),
            Some(loaded.images.clone()),
        )
        .with_context(|| path.display().to_string())?;
        if let Some(keep) = keep_view
            && self.scene.camera == keep.preset_camera
        {
            self.scene.camera = keep.camera;
        }
        self.edits.preset_camera = loaded.scene.camera;
        self.edits.document = Document::new(path, scene_header(path), &self.scene);
        if let EnvSource::LatLong { path } = &self.scene.environment.source {
            self.panel.env_path = path.display().to_string();
        }
        self.panel.info(format!("loaded {}", path.display()));
        if self.edits.document.has_preset_file() {
            self.panel.preset_path = path.display().to_string();
        } else {
            // The path field holds where Save as writes, as Save suggests.
            let suggestion = self.edits.document.save_as_suggestion();
            self.panel.preset_path = suggestion.display().to_string();
            self.panel.info(format!(
                "{} is a new preset, not saved yet: Save asks where (suggesting {}); the \
                 OBJ file is never written",
                path.display(),
                suggestion.display()
            ));
        }
        for note in loaded.notes {
            self.panel.info(note);
        }
        self.opened(path);
        self.start_watching();
        Ok(())
    }

    /// Remembers `path` in the recent files, and a preset or OBJ file as
    /// the one to open next time (saved at once, so a crash keeps them).
    pub(super) fn opened(&mut self, path: &Path) {
        self.settings.remember(path);
        if FileKind::of(path) != FileKind::Environment {
            self.settings.last_preset = self.settings.recent_files.first().cloned();
        }
        self.save_settings();
    }

    pub(super) fn load_environment(&mut self, path: &Path) {
        let ldr = self.scene.environment.ldr_images;
        self.load_environment_source(
            EnvSource::LatLong {
                path: path.to_owned(),
            },
            ldr,
        );
    }

    /// Loads a lat-long or cube map (a cube resampled to lat-long), its 8-
    /// and 16-bit files read as `ldr` says, and installs it with `source`;
    /// on failure the scene stays as it was.
    pub(super) fn load_environment_source(&mut self, source: EnvSource, ldr: LdrImages) {
        let what = source
            .paths()
            .iter()
            .map(|p| p.display().to_string())
            .collect::<Vec<_>>()
            .join(", ");
        match load_environment(&source, ldr, max_texture_side(&self.ctx)) {
            Ok(Some(l)) => {
                let mut scene = self.scene.clone();
                scene.environment.source = source;
                scene.environment.ldr_images = ldr;
                if let Err(e) = self.apply_scene(scene, Some(&l.image), None) {
                    self.panel.error(format!("{what}: {e:#}"));
                    return;
                }
                if let EnvSource::LatLong { path } = &self.scene.environment.source {
                    self.panel.env_path = path.display().to_string();
                    let path = path.clone();
                    self.opened(&path);
                }
                self.panel.info(format!("environment {what}"));
                for note in l.notes {
                    self.panel.info(note);
                }
            }
            Ok(None) => {}
            Err(e) => self.panel.error(format!("{e:#}")),
        }
    }

    /// Installs a whole new scene and environment, and its images if given;
    /// on failure nothing changes. The scene reaches the renderer here, not
    /// through the frame's change, so the history and the document are
    /// told here: a preset or a map loaded is one undoable edit.
    pub(super) fn apply_scene(
        &mut self,
        scene: Scene,
        env: Option<&envmap::EnvImage>,
        images: Option<ImageSet>,
    ) -> Result<()> {
        let change = scene.changes_from(&self.scene);
        self.renderer.set_scene(&self.ctx, &scene)?;
        if let Some(images) = images {
            self.renderer.set_images(&self.ctx, images)?;
        }
        self.renderer.set_environment(&self.ctx, env);
        self.scene = scene;
        self.edits.history.observe(&self.scene, change, false);
        self.edits.document.observe(&self.scene, change);
        self.swatches.note(change);
        Ok(())
    }

    /// Loads the images an edit added or changed (a new image node, a typed
    /// path), reporting unreadable files; the renderer shows placeholders
    /// for those.
    pub(super) fn reload_images_if_needed(&mut self) {
        if self.scene.image_sources() == self.renderer.images().sources() {
            return;
        }
        let mut notes = Vec::new();
        let result = load_images(&self.scene, &mut notes)
            .and_then(|images| self.renderer.set_images(&self.ctx, images));
        for note in notes {
            self.panel.error(note);
        }
        if let Err(e) = result {
            self.panel.error(format!("{e:#}"));
        }
    }

    /// Save: to the preset file; a scene opened from an OBJ file has none
    /// yet, so Save asks where (the dialog, or the typed path where none
    /// can open) and returns false: whatever waited on the save (a load,
    /// quitting) waits for the user to save and ask again.
    pub(super) fn save_document(&mut self) -> bool {
        if self.edits.document.has_preset_file() {
            let path = self.edits.document.path.clone();
            return self.save_preset(&path);
        }
        self.panel.preset_path = self
            .edits
            .document
            .save_as_suggestion()
            .display()
            .to_string();
        self.panel.info(format!(
            "{} is not a preset: choose where to save the scene as one",
            self.edits.document.path.display()
        ));
        self.open_dialog(DialogPurpose::SavePresetAs);
        false
    }

    /// Save as to a path the user typed: a file already there (another
    /// preset, or the original) is replaced only once the user confirms,
    /// as a native dialog asks.
    pub(super) fn request_save_as(&mut self, path: &Path) {
        if path.as_os_str().is_empty() {
            self.panel.error("Save as: type the path to save to first");
        } else if marbre_core::capped_read::is_file(path) {
            self.edits.prompt = Some(Prompt::Replace(path.to_owned()));
        } else {
            self.save_preset(path);
        }
    }

    /// Puts the scene in the page's address as a link (`app::share_link`);
    /// a scene too large for one is offered as a preset file instead.
    pub(super) fn share_link(&mut self) {
        let preset = self.edits.document.preset(&self.scene);
        let text = match preset::to_text(&preset, Path::new(share_link::SHARED_PRESET_PATH)) {
            Ok(text) => text,
            Err(e) => {
                self.panel.error(format!("cannot share the scene: {e}"));
                return;
            }
        };
        match share_link::encode(&text).map_err(|e| e.to_string()) {
            Ok(fragment) => match file_dialogs::publish_link(&fragment) {
                Ok(url) => self.panel.info(format!(
                    "the link to this scene ({} characters) is in the address bar, and copied where the browser allows: {url}",
                    url.len()
                )),
                Err(e) => self.panel.error(format!("cannot share the scene: {e}")),
            },
            Err(too_large) => {
                self.panel.error(too_large);
                let name = self.edits.document.save_as_suggestion();
                let name = name.file_name().map_or_else(|| "scene.ron".into(), PathBuf::from);
                file_dialogs::offer_download(&name, text.as_bytes());
            }
        }
    }

    /// Saves the scene to `path` (atomically); returns whether it saved.
    /// The document is that file from then on, and a Save as dialog
    /// waiting for its path is done.
    pub(super) fn save_preset(&mut self, path: &Path) -> bool {
        match self.edits.document.save(&self.scene, path) {
            Ok(()) => {
                file_dialogs::deliver_saved(path);
                self.panel.save_as = None;
                self.panel.preset_path = path.display().to_string();
                self.panel.info(format!("saved {}", path.display()));
                self.opened(path);
                self.start_watching();
                true
            }
            Err(e) => {
                self.panel.error(e.to_string());
                false
            }
        }
    }

    /// Opens a native file dialog; where none can open, points the user
    /// to the typed path and to drag and drop instead, and Save as asks
    /// for its path in a dialog of its own (`panel::save_as`): the path
    /// fields' Enter opens what they name, which is no way to save.
    pub(super) fn open_dialog(&mut self, purpose: DialogPurpose) {
        if self.incoming.dialog.is_some() {
            return;
        }
        if !dialogs_available() {
            let suggestion = self.edits.document.save_as_suggestion();
            match purpose {
                DialogPurpose::SavePresetAs => {
                    self.panel.info(
                        "no file dialog here (no desktop portal, no zenity): type where to \
                         save in Save as and press Enter",
                    );
                    self.panel.save_as = Some(SaveAs::new(suggestion.display().to_string()));
                }
                DialogPurpose::OpenPreset | DialogPurpose::OpenEnvironment => {
                    self.panel.info(
                        "no file dialog here (no desktop portal, no zenity): type the path in \
                         the field and press Enter, or drop the file on the window",
                    );
                    if purpose == DialogPurpose::OpenEnvironment {
                        self.panel.focus_env_path = true;
                    } else {
                        self.panel.focus_preset_path = true;
                    }
                }
            }
            return;
        }
        let start = match purpose {
            DialogPurpose::OpenEnvironment => self.settings.recent_files.first().cloned(),
            DialogPurpose::OpenPreset => Some(self.edits.document.path.clone()),
            DialogPurpose::SavePresetAs => Some(self.edits.document.save_as_suggestion()),
        };
        self.incoming.dialog = Some(OpenDialog::open(purpose, start));
    }

    /// Acts on a dialog that has closed.
    pub(super) fn poll_dialog(&mut self) {
        let Some((purpose, chosen)) = self.incoming.dialog.as_ref().and_then(OpenDialog::poll)
        else {
            return;
        };
        self.incoming.dialog = None;
        let Some(path) = chosen else {
            return;
        };
        match purpose {
            DialogPurpose::OpenPreset => self.request_load_preset(&path),
            DialogPurpose::SavePresetAs => {
                self.save_preset(&path);
            }
            DialogPurpose::OpenEnvironment => self.load_environment(&path),
        }
    }

    /// Carries out what the user answered to the open prompt.
    pub(super) fn answer_prompt(&mut self, answer: Answer) {
        let Some(prompt) = self.edits.prompt.take() else {
            return;
        };
        match (prompt, answer) {
            (_, Answer::Cancel) | (Prompt::ReloadFromDisk, Answer::SaveFirst) => {}
            (Prompt::LoadPreset(next), Answer::SaveFirst) => {
                if self.save_document() {
                    self.load_preset(&next);
                }
            }
            (Prompt::LoadPreset(next), Answer::Proceed) => self.load_preset(&next),
            (Prompt::Quit, Answer::SaveFirst) => {
                if self.save_document() {
                    self.quit();
                }
            }
            (Prompt::Quit, Answer::Proceed) => self.quit(),
            (Prompt::ReloadFromDisk, Answer::Proceed) => self.reload_from_disk(),
            (Prompt::Replace(path), Answer::Proceed) => {
                self.save_preset(&path);
            }
            // The scene back, it is copied to this process's own
            // recovery file before the crashed run's is removed, then
            // autosaved as any unsaved edits.
            (Prompt::Recover(offer), Answer::Proceed) => {
                if self.recover(&offer) && self.autosave_recovered(&offer) {
                    recovery::discard(&offer);
                }
            }
            (Prompt::Recover(offer), Answer::Discard) => recovery::discard(&offer),
            (Prompt::Recover(_) | Prompt::Replace(_), Answer::SaveFirst) => {}
            (_, Answer::Discard) => {}
        }
    }

    /// Offers the autosave that a run which did not end cleanly left of
    /// the document just opened, if there is one (the newest), unless
    /// another question is waiting: it is offered again at the next open.
    fn offer_recovery(&mut self) {
        if self.edits.prompt.is_some() {
            return;
        }
        let Some(dir) = &self.config_dir else {
            return;
        };
        if let Some(offer) = recovery::offer_for(dir, &self.edits.document.path) {
            self.edits.prompt = Some(Prompt::Recover(offer));
        }
    }

    /// Reopens the scene a crashed run autosaved, as unsaved edits of the
    /// preset it came from. False (with the reason in the panel) if the
    /// file could not be read back: it is kept, to be offered again.
    fn recover(&mut self, offer: &recovery::RecoveryOffer) -> bool {
        let max_side = max_texture_side(&self.ctx);
        let loaded = match load_scene(&offer.preset, None).map(|l| l.fit_environment(max_side)) {
            Ok(loaded) => loaded,
            Err(e) => {
                self.panel.error(format!("cannot recover: {e:#}"));
                return false;
            }
        };
        if let Err(e) = self.apply_scene(
            loaded.scene.clone(),
            loaded.env.as_ref(),
            Some(loaded.images.clone()),
        ) {
            self.panel.error(format!("cannot recover: {e:#}"));
            return false;
        }
        // The document is the original preset (Save writes there), compared
        // with what that file holds, so the recovered edits show unsaved.
        let original = preset::load(&offer.source).ok();
        let header = original
            .as_ref()
            .map(|l| l.preset.header())
            .unwrap_or_default();
        let saved = original.map_or_else(Scene::default, |l| l.preset.scene);
        self.edits.document = Document::with_edits(&offer.source, header, &saved, &self.scene);
        self.panel.preset_path = offer.source.display().to_string();
        self.panel.info(format!(
            "recovered the unsaved changes to {} from {}",
            offer.source.display(),
            offer.saved_at
        ));
        self.start_watching();
        true
    }

    /// Writes the unsaved edits just recovered from `offer` to this
    /// process's recovery file at once. False (with the reason in the
    /// panel) if that failed: `offer`'s file must then stay, the only copy
    /// on disk.
    fn autosave_recovered(&mut self, offer: &recovery::RecoveryOffer) -> bool {
        let document = &self.edits.document;
        let Some(autosave) = self.edits.autosave.as_mut().filter(|_| document.unsaved()) else {
            return true;
        };
        match autosave.write_now(&document.path, document.preset(&self.scene)) {
            Ok(()) => true,
            Err(e) => {
                self.panel.error(format!(
                    "autosave failed: {e:#}; {} keeps the recovered changes",
                    offer.preset.display()
                ));
                false
            }
        }
    }

    /// Watches the preset's folder, and the WGSL sources in `--dev` mode.
    pub(super) fn start_watching(&mut self) {
        if self.incoming.watch.is_none() {
            match FileWatch::new() {
                Ok(watch) => self.incoming.watch = Some(watch),
                Err(e) => self.panel.error(format!("hot reload is off: {e:#}")),
            }
        }
        if let Some(watch) = &mut self.incoming.watch
            && let Err(e) = watch.watch_folder_of(&self.edits.document.path)
        {
            self.panel.error(format!("hot reload is off: {e:#}"));
        }
        if self.options.dev && self.incoming.shader_watch.is_none() {
            let shaders = dev_shader_dir();
            let watch = FileWatch::new().and_then(|mut w| {
                for folder in shader_source::DEV_SOURCE_FOLDERS {
                    w.watch_tree(&shaders.join(folder))?;
                }
                Ok(w)
            });
            match watch {
                Ok(watch) => {
                    self.incoming.shader_watch = Some(watch);
                    self.panel.info(format!(
                        "--dev: editing a shader in {} rebuilds the trace pipeline",
                        shaders.display()
                    ));
                    // The source tree may differ from what was built in.
                    self.reload_shaders();
                }
                Err(e) => self.panel.error(format!("shader hot reload is off: {e:#}")),
            }
        }
    }

    /// Acts on files changed outside the app: the preset reloads (or asks,
    /// with unsaved edits); a shader in `--dev` mode rebuilds the pipeline,
    /// a failed build keeping the old one and showing why.
    pub(super) fn poll_file_watch(&mut self) {
        let preset_changed = self.incoming.watch.as_ref().is_some_and(|w| {
            w.changed()
                .iter()
                .any(|p| is_same_file(p, &self.edits.document.path))
        });
        if preset_changed && self.edits.document.changed_on_disk() {
            if self.edits.document.is_dirty(&self.scene) {
                if self.edits.prompt.is_none() {
                    self.edits.prompt = Some(Prompt::ReloadFromDisk);
                }
            } else {
                self.reload_from_disk();
            }
        }
        let shaders_changed = self.incoming.shader_watch.as_ref().is_some_and(|w| {
            w.changed()
                .iter()
                .any(|p| p.extension().is_some_and(|e| e == "wgsl"))
        });
        if shaders_changed {
            self.reload_shaders();
        }
    }

    /// Loads the preset file again after an outside edit, keeping the
    /// user's view unless the edit moved the camera.
    fn reload_from_disk(&mut self) {
        let keep = KeepView {
            camera: self.scene.camera,
            preset_camera: self.edits.preset_camera,
        };
        let path = self.edits.document.path.clone();
        self.start_loading(&path, Some(keep));
    }

    fn reload_shaders(&mut self) {
        let dir = dev_shader_dir();
        match shader_source::load_dev_sources() {
            Ok(None) => {}
            Ok(Some(generation)) => {
                self.panel.info(format!(
                    "shaders reloaded from {} (#{generation})",
                    dir.display()
                ));
                if let Err(e) = self.renderer.rebuild(&self.ctx) {
                    self.panel.error(format!("{e:#}"));
                }
            }
            Err(e) => self.panel.error(format!("cannot reload shaders: {e:#}")),
        }
    }
}

/// The message naming an autosave of a preset other than the one opened
/// at start-up: where it will be offered, or, its preset gone, the
/// autosave itself to open.
pub(super) fn recovery_note(offer: &recovery::RecoveryOffer) -> String {
    let left = format!(
        "a run that did not close cleanly left unsaved changes to {}, autosaved at {}",
        offer.source.display(),
        offer.saved_at
    );
    if offer.source.exists() {
        format!("{left}: open it to recover them")
    } else {
        format!(
            "{left}; that file is gone: open {} to see them",
            offer.preset.display()
        )
    }
}

/// How `path` loads as a scene: an `.obj` alone, framed for an image of
/// width / height `aspect`; anything else as a preset.
fn scene_kind(path: &Path, aspect: f32) -> SceneKind {
    match FileKind::of(path) {
        FileKind::Obj => SceneKind::Obj { aspect },
        FileKind::Preset | FileKind::Environment => SceneKind::Preset,
    }
}

/// The header a document keeps for the preset it may be saved as: the
/// preset's own, or for an OBJ file where it came from, its colours linear
/// as the MTL file's are.
pub(super) fn scene_header(path: &Path) -> Header {
    match FileKind::of(path) {
        FileKind::Obj => Header {
            description: format!(
                "Opened from {}",
                path.file_name().unwrap_or_default().to_string_lossy()
            ),
            ..Header::default()
        },
        FileKind::Preset | FileKind::Environment => preset::load(path)
            .map(|l| l.preset.header())
            .unwrap_or_default(),
    }
}

/// The source tree whose `shaders/` and `crates/` hold every WGSL file
/// `--dev` reads (resolved, so that messages name it plainly).
fn dev_shader_dir() -> PathBuf {
    let dir = PathBuf::from(shader_source::DEV_SOURCE_ROOT);
    dir.canonicalize().unwrap_or(dir)
}

/// The view to keep across a reload, unless the file moved the camera.
#[derive(Debug, Clone, Copy)]
pub(super) struct KeepView {
    /// The user's camera now.
    camera: OrbitCamera,
    /// The camera the preset had when loaded.
    preset_camera: OrbitCamera,
}
