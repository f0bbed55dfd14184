//! The one hook through which a script drives the viewer frame by frame:
//! before each frame's UI it may edit the scene or ask for an action, and
//! after each presented frame it sees the frame and says whether the run
//! goes on. `marbre soak` is such a script (`soak::SoakDriver`); the viewer
//! knows nothing else about it.

use anyhow::Result;
use marbre_core::scene::Scene;
use marbre_render::gpu::GpuContext;
use std::path::PathBuf;

/// What a script asks of the viewer before a frame, besides its edit of
/// the scene.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ScriptAction {
    Nothing,
    /// Load this preset through the viewer's own load path.
    LoadPreset(PathBuf),
    /// Destroy the device (`device.destroy()`) and recover from the loss.
    LoseDevice,
    /// Start a render in the background, as the Render dialog's Render
    /// does: `spp` samples per pixel at `size`, written to `output`.
    StartRender {
        size: (u32, u32),
        spp: u32,
        output: PathBuf,
    },
}

/// What the viewer shows a script after presenting a frame.
pub struct Presented<'a> {
    /// The frame's number, from 0.
    pub frame: u64,
    pub ctx: &'a GpuContext,
    /// The wgpu validation errors the viewer's uncaptured-error handler
    /// has seen so far.
    pub validation_errors: u64,
}

/// A script driving the viewer.
pub trait FrameScript {
    /// Once per frame, before the UI runs: edits `scene` in place, or asks
    /// for an action. An edit the renderer refuses is put back by the
    /// viewer, as any refused panel edit is.
    fn before_frame(&mut self, frame: u64, scene: &mut Scene) -> ScriptAction;

    /// Once per presented frame: whether the run goes on; an error ends it
    /// and fails it.
    fn after_present(&mut self, presented: Presented<'_>) -> Result<bool>;
}
