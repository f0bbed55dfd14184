//! The viewer's tests under Xvfb: the window (`window`), a user's session
//! driven end to end (`e2e_window`), the node editor (`node_window`), OBJ files opened as scenes
//! (`obj_window`), the guards on the user's work (`work_at_risk`) and the
//! soak (`soak`), each running the `marbre` binary
//! on lavapipe. `xvfb` starts the display and drives it. `render_cli` runs
//! `marbre render` (no window) for what it says on stderr.

/// The repository's root: the presets and the test data.
const REPO: &str = env!("CARGO_MANIFEST_DIR");

mod denoise_window;
mod e2e_window;
mod node_window;
mod obj_window;
mod render_cli;
mod render_window;
mod soak;
mod timeline_window;
mod window;
mod work_at_risk;
mod xvfb;
