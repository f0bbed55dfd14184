//! Loading a preset, or an OBJ file alone, on a worker thread, so that the
//! window keeps drawing (the old scene, and a progress bar) while a big OBJ
//! is parsed and its BVH built.
//!
//! The worker does everything that needs no GPU: the preset, the
//! environment map (fitted to the GPU's largest texture), the meshes, the
//! images, and the BVH ([`PreparedGeometry`]). The viewer then installs the
//! result on the render thread in one go, or shows why it failed.

use marbre_render::gpu::mesh_buffers::PreparedGeometry;
use marbre_render::session::{LoadStage, LoadedScene, load_obj_reporting, load_scene_reporting};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, mpsc};

/// What a file opened in the viewer is, by its extension (any case):
/// `.ron` a preset, `.obj` a mesh that becomes a new scene, anything else
/// an environment map.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FileKind {
    Preset,
    Obj,
    Environment,
}

impl FileKind {
    pub fn of(path: &Path) -> FileKind {
        let extension = path.extension().map(|e| e.to_ascii_lowercase());
        match extension.as_ref().and_then(|e| e.to_str()) {
            Some("ron") => FileKind::Preset,
            Some("obj") => FileKind::Obj,
            _ => FileKind::Environment,
        }
    }
}

/// A scene file to load: a preset, or an OBJ file alone, framed for an
/// image of width / height `aspect` (`marbre_core::obj_scene`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SceneKind {
    Preset,
    Obj { aspect: f32 },
}

/// Loads `path` as `kind` says, with `env_override` in place of its
/// environment if given, calling `report` as each stage starts.
pub fn load_reporting(
    path: &Path,
    kind: SceneKind,
    env_override: Option<&Path>,
    report: &mut dyn FnMut(LoadStage),
) -> anyhow::Result<LoadedScene> {
    match kind {
        SceneKind::Preset => load_scene_reporting(path, env_override, report),
        SceneKind::Obj { aspect } => load_obj_reporting(path, aspect, env_override, report),
    }
}

/// The test hook of a slow load: while the file `MARBRE_TEST_HOLD_LOADS`
/// names exists, a load waits before reading its meshes, as on a slow disk
/// or network share. The window test of a slow start-up holds a load so;
/// it once used a FIFO as the OBJ, which inputs now refuse (only regular
/// files are read, so that a FIFO can never hang a load).
fn hold_while_asked() {
    let Some(hold) = std::env::var_os("MARBRE_TEST_HOLD_LOADS") else {
        return;
    };
    while Path::new(&hold).exists() {
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
}

/// A loaded scene with its BVH already built.
pub struct ReadyScene {
    pub loaded: LoadedScene,
    pub geometry: PreparedGeometry,
}

/// The stage a worker is at: 0..LoadStage::COUNT for the loading stages,
/// then the BVH.
const BVH_STAGE: usize = LoadStage::COUNT;

pub struct SceneLoad {
    path: PathBuf,
    stage: Arc<AtomicUsize>,
    receiver: mpsc::Receiver<anyhow::Result<ReadyScene>>,
}

impl SceneLoad {
    /// Starts loading `path` as `kind`, with `env_override` (the command
    /// line's `--env`) in place of the scene's environment if given; the
    /// environment is fitted to `max_side`.
    pub fn start(path: &Path, kind: SceneKind, env_override: Option<&Path>, max_side: u32) -> Self {
        let (sender, receiver) = mpsc::channel();
        let stage = Arc::new(AtomicUsize::new(0));
        let (worker_path, worker_stage) = (path.to_owned(), stage.clone());
        let worker_env = env_override.map(Path::to_owned);
        let work = move || {
            let result = load_reporting(&worker_path, kind, worker_env.as_deref(), &mut |s| {
                worker_stage.store(s.index(), Ordering::Relaxed);
                if s == LoadStage::Meshes {
                    hold_while_asked();
                }
            })
            .map(|loaded| {
                let loaded = loaded.fit_environment(max_side);
                worker_stage.store(BVH_STAGE, Ordering::Relaxed);
                let geometry = PreparedGeometry::of(&loaded.scene);
                ReadyScene { loaded, geometry }
            });
            // The viewer may have given up on this load: then nobody listens.
            let _ = sender.send(result);
        };
        // A web page has no thread to load on: the files are in its memory
        // already (`marbre_core::page_files`), and the load runs in place.
        if cfg!(target_arch = "wasm32") {
            work();
        } else {
            std::thread::spawn(work);
        }
        Self {
            path: path.to_owned(),
            stage,
            receiver,
        }
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    /// What the worker is doing, and the fraction of the stages done.
    pub fn progress(&self) -> (&'static str, f32) {
        let stage = self.stage.load(Ordering::Relaxed);
        let label = match stage {
            0 => LoadStage::Preset.label(),
            1 => LoadStage::Environment.label(),
            2 => LoadStage::Meshes.label(),
            3 => LoadStage::Images.label(),
            _ => "building the BVH",
        };
        (label, stage as f32 / (BVH_STAGE + 1) as f32)
    }

    /// The result once the worker is done.
    pub fn poll(&self) -> Option<anyhow::Result<ReadyScene>> {
        match self.receiver.try_recv() {
            Ok(result) => Some(result),
            Err(mpsc::TryRecvError::Empty) => None,
            Err(mpsc::TryRecvError::Disconnected) => Some(Err(anyhow::anyhow!(
                "{}: the loading thread stopped",
                self.path.display()
            ))),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use marbre_core::scene::EnvSource;

    fn wait(load: SceneLoad) -> anyhow::Result<ReadyScene> {
        load.receiver.recv().expect("the worker sends a result")
    }

    #[test]
    fn loads_a_preset_with_its_meshes_off_the_thread() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("presets/cornell.ron");
        let ready =
            wait(SceneLoad::start(&path, SceneKind::Preset, None, 8192)).expect("cornell loads");
        assert!(ready.loaded.scene.triangle_count() > 0);
    }

    #[test]
    fn the_command_lines_environment_replaces_the_presets() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        let env = root.join("envmaps/sky.exr");
        let load = SceneLoad::start(
            &root.join("presets/cornell.ron"),
            SceneKind::Preset,
            Some(&env),
            8192,
        );
        let ready = wait(load).expect("cornell loads");
        assert_eq!(
            ready.loaded.scene.environment.source,
            EnvSource::LatLong { path: env }
        );
        assert!(ready.loaded.env.is_some(), "the map itself is loaded");
    }

    #[test]
    fn files_are_told_apart_by_their_extension_in_any_case() {
        for (name, kind) in [
            ("a/scene.ron", FileKind::Preset),
            ("a/scene.RON", FileKind::Preset),
            ("CornellBox-Original.obj", FileKind::Obj),
            ("teapot.OBJ", FileKind::Obj),
            ("sky.exr", FileKind::Environment),
            ("obj", FileKind::Environment),
        ] {
            assert_eq!(FileKind::of(Path::new(name)), kind, "{name}");
        }
    }

    /// An OBJ file loads off the thread as a scene of its own: the mesh
    /// with its triangles and the BVH ready.
    #[test]
    fn loads_an_obj_file_alone_off_the_thread() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("presets/scenes/cornell-box/CornellBox-Original.obj");
        let load = SceneLoad::start(&path, SceneKind::Obj { aspect: 1.5 }, None, 8192);
        let ready = wait(load).expect("the Cornell box loads");
        let scene = &ready.loaded.scene;
        assert_eq!(scene.meshes.len(), 1);
        assert_eq!(scene.meshes[0].obj, path);
        assert_eq!(scene.triangle_count(), 36);
        assert_eq!(scene.point_light, None, "its Ke lamp lights it");
    }

    #[test]
    fn a_broken_obj_reports_the_file_and_the_cause() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("broken.obj");
        std::fs::write(&path, "v 0 0 0\nf 1 2\n").unwrap();
        let load = SceneLoad::start(&path, SceneKind::Obj { aspect: 1.0 }, None, 8192);
        let error = format!("{:#}", wait(load).err().expect("fails"));
        assert!(
            error.contains("broken.obj:2") && error.contains("`f 1 2`"),
            "{error}"
        );
    }

    #[test]
    fn a_broken_preset_reports_the_file() {
        let path = Path::new("no/such/preset.ron");
        let error = wait(SceneLoad::start(path, SceneKind::Preset, None, 8192))
            .err()
            .expect("fails");
        assert!(
            format!("{error:#}").contains("no/such/preset.ron"),
            "{error:#}"
        );
    }
}
