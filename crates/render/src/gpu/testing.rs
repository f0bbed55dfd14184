//! Support for tests that need a GPU: find an adapter or skip loudly.
//!
//! Where no adapter exists (a machine without Vulkan or GL), GPU tests print a
//! banner and pass as skipped. CI sets `MARBRE_REQUIRE_GPU=1`, which turns the
//! skip into a failure, so a broken driver install can never pass silently.

use super::context::GpuContext;

pub const REQUIRE_GPU_VAR: &str = "MARBRE_REQUIRE_GPU";

pub fn gpu_required() -> bool {
    std::env::var(REQUIRE_GPU_VAR).is_ok_and(|v| !v.is_empty() && v != "0")
}

/// Prints the skip banner, or panics when a skip is not allowed.
pub fn skip(test: &str, why: &str) {
    let banner = format!(
        "\n!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!\n\
         !! SKIPPED {test}: {why}\n\
         !! (set {REQUIRE_GPU_VAR}=1 to make this a failure)\n\
         !!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!\n"
    );
    if gpu_required() {
        panic!("{test} needs a GPU or display and {REQUIRE_GPU_VAR} is set: {why}");
    }
    eprintln!("{banner}");
}

/// A headless device, or `None` after a loud skip.
pub fn gpu_or_skip(test: &str) -> Option<GpuContext> {
    match GpuContext::headless() {
        Ok(ctx) => Some(ctx),
        Err(e) => {
            skip(test, &format!("no GPU adapter: {e:#}"));
            None
        }
    }
}
