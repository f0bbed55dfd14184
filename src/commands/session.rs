//! Loading a preset and its environment into a ready renderer: shared by the
//! viewer, `render` and `bench`, so they all see the same scene.

use crate::envmap::{self, EnvImage};
use crate::gpu::{GpuContext, Renderer};
use crate::preset;
use crate::scene::{EnvSource, Scene};
use anyhow::{Context, Result};
use std::path::{Path, PathBuf};

/// The preset the viewer opens when none is named.
pub const DEFAULT_PRESET: &str = "presets/default.ron";

/// A preset's scene, with `--env` applied, and its loaded environment image.
pub struct LoadedScene {
    pub scene: Scene,
    pub env: Option<EnvImage>,
    /// Clamped values and sanitised pixels, for the user to see.
    pub notes: Vec<String>,
}

pub fn load_scene(preset_path: &Path, env_override: Option<&Path>) -> Result<LoadedScene> {
    let loaded = preset::load(preset_path)?;
    let mut scene = loaded.preset.scene;
    let mut notes = loaded.notes;
    if let Some(env) = env_override {
        scene.environment.source = EnvSource::LatLong {
            path: env.to_owned(),
        };
    }
    let env = match &scene.environment.source {
        EnvSource::LatLong { path } => {
            let l = envmap::load(path)?;
            notes.extend(l.notes);
            Some(l.image)
        }
        _ => None,
    };
    Ok(LoadedScene { scene, env, notes })
}

/// `path`, or the default preset.
pub fn preset_or_default(path: Option<&Path>) -> PathBuf {
    path.map_or_else(|| PathBuf::from(DEFAULT_PRESET), Path::to_owned)
}

/// Traces `spp` samples per pixel (in frames of the preset's samples per frame)
/// and waits for the GPU; `progress` is called after each frame.
pub fn accumulate(
    ctx: &GpuContext,
    renderer: &mut Renderer,
    spp: u32,
    mut progress: impl FnMut(u32),
) -> Result<()> {
    while renderer.accumulated_samples() < spp {
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        renderer.trace(ctx, &mut encoder, None);
        ctx.queue.submit([encoder.finish()]);
        ctx.device
            .poll(wgpu::PollType::wait_indefinitely())
            .context("waiting for the GPU")?;
        progress(renderer.accumulated_samples());
    }
    Ok(())
}
