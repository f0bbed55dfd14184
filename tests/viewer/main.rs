//! The viewer's tests under Xvfb: the window (`window`), a user's session
//! driven end to end (`e2e_window`), OBJ files opened as scenes
//! (`obj_window`) and the soak (`soak`), each running the `marbre` binary
//! on lavapipe. `xvfb` starts the display and drives it.

/// The repository's root: the presets and the test data.
const REPO: &str = env!("CARGO_MANIFEST_DIR");

mod e2e_window;
mod obj_window;
mod render_window;
mod soak;
mod window;
mod xvfb;
