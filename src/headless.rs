//! Quiet start-up for the commands with no window (`render`, `noise`, the
//! benches).
//!
//! Mesa's Vulkan `device_select` layer, loaded implicitly with every Vulkan
//! instance, looks for the Wayland compositor's GPU to list it first, as
//! soon as the instance enables `VK_KHR_wayland_surface` (wgpu always does).
//! Where `XDG_RUNTIME_DIR` is unset or invalid, libwayland then prints
//! `error: XDG_RUNTIME_DIR is invalid or not set in the environment.`
//! twice on every command, though nothing failed. A command with no window
//! has no compositor to match and picks its adapter itself, so the layer is
//! turned off there (`NODEVICE_SELECT=1`), unless the user steers it
//! (`MESA_VK_DEVICE_SELECT`) or already set the variable. No error of the
//! command or of the driver is hidden: only that layer's probe is skipped.

/// The layer's own switch.
const SWITCH: &str = "NODEVICE_SELECT";

/// Whether the probe would print its error, and the user left the layer to
/// its default: `xdg_runtime_dir` not a folder, no device chosen through
/// the layer, the switch not set either way.
fn should_skip_probe(
    xdg_runtime_dir: Option<&std::ffi::OsStr>,
    device_select: Option<&std::ffi::OsStr>,
    switch: Option<&std::ffi::OsStr>,
) -> bool {
    let runtime_dir_usable =
        xdg_runtime_dir.is_some_and(|dir| !dir.is_empty() && std::path::Path::new(dir).is_dir());
    !runtime_dir_usable && device_select.is_none() && switch.is_none()
}

/// Turns the layer's probe off where it would only print noise. Call it
/// first thing in `main`, before any thread exists (it sets a variable of
/// the process environment).
pub fn quiet_device_select() {
    let var = std::env::var_os;
    if should_skip_probe(
        var("XDG_RUNTIME_DIR").as_deref(),
        var("MESA_VK_DEVICE_SELECT").as_deref(),
        var(SWITCH).as_deref(),
    ) {
        // SAFETY: called from `main` before any other thread is started,
        // so nothing reads the environment meanwhile.
        unsafe { std::env::set_var(SWITCH, "1") };
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::ffi::OsStr;

    #[test]
    fn the_probe_is_skipped_only_where_it_would_fail_and_nobody_chose() {
        let tmp = std::env::temp_dir();
        let some = |s: &'static str| Some(OsStr::new(s));
        assert!(should_skip_probe(None, None, None));
        assert!(should_skip_probe(some(""), None, None));
        assert!(should_skip_probe(some("/no/such/runtime/dir"), None, None));
        assert!(!should_skip_probe(Some(tmp.as_os_str()), None, None));
        assert!(!should_skip_probe(None, some("1002:73bf"), None));
        assert!(!should_skip_probe(None, None, some("0")));
    }
}
