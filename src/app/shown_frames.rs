//! The test hook the window tests wait on (issue 47): with
//! `MARBRE_TEST_SHOWN_FRAMES` naming a file, the viewer writes there how
//! many frames it has shown, after each one.
//!
//! A frame shown after an input event has read it (egui reads input once
//! a frame, and input makes the next frame shown, `present_schedule`), so
//! a test that waits for two more shown frames after a key or a mouse move
//! knows the viewer has handled it, however slow the machine: the window
//! tests once slept a fixed second between a drag's steps, which a loaded
//! machine's slower frames outran.

use std::path::PathBuf;

/// Where the count goes, if a test asked for it.
pub struct ShownFramesFile(Option<PathBuf>);

impl ShownFramesFile {
    /// The file `MARBRE_TEST_SHOWN_FRAMES` names, if it is set.
    pub fn from_env() -> Self {
        Self(std::env::var_os("MARBRE_TEST_SHOWN_FRAMES").map(PathBuf::from))
    }

    /// Writes `shown` whole: to a sibling first, then renamed over the
    /// file, so a test never reads half a number. A failure is the test's
    /// to notice (its wait times out, naming the file); the viewer goes on.
    pub fn publish(&self, shown: u64) {
        let Some(path) = &self.0 else {
            return;
        };
        let mut partial = path.clone().into_os_string();
        partial.push(".partial");
        if std::fs::write(&partial, shown.to_string()).is_ok() {
            let _ = std::fs::rename(&partial, path);
        }
    }
}
