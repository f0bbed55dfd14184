//! Intel Open Image Denoise (OIDN), the denoiser of Blender, Karma, V-Ray
//! and Mitsuba's users, loaded at run time.
//!
//! Why not the `oidn` crate: it links `libOpenImageDenoise` when marbre is
//! built, so a machine without the library could not build the viewer at
//! all, and the README's two commands must work on any fresh machine. Here
//! the library is opened with `libloading` when a denoise is first asked
//! for ([`Library::shared`]), from `MARBRE_OIDN_DIR`, the system's library
//! path, or a `pip install pyoidn` location ([`library`]); when it is not
//! found, the caller falls back to its own filter and says why.
//!
//! The C API used is OIDN 2's (`oidn.h`), a dozen functions
//! ([`api::Api`]). [`Denoiser`] runs the "RT" filter as OIDN's
//! documentation recommends for a path tracer's preview and final frames:
//! HDR colour guided by albedo and normal, the guides first filtered
//! themselves ("prefiltering", then `cleanAux`), with every input made
//! finite first ([`sanitise`]).

mod api;
mod border;
mod denoiser;
pub mod library;
pub mod sanitise;

pub use denoiser::{Denoiser, DeviceKind, Guides, Images, Quality};
pub use library::{Library, NotFound};

/// What went wrong inside OIDN: the call and the device's own message.
#[derive(Debug, thiserror::Error)]
#[error("OIDN {call}: {message}")]
pub struct OidnError {
    pub call: &'static str,
    pub message: String,
    /// Stopped by its cancel flag ([`Denoiser::cancel_flag`]), not failed.
    pub cancelled: bool,
}

impl OidnError {
    pub(crate) fn new(call: &'static str, message: String) -> Self {
        Self {
            call,
            message,
            cancelled: false,
        }
    }

    pub(crate) fn cancelled() -> Self {
        Self {
            call: "oidnExecuteFilter",
            message: "cancelled".to_owned(),
            cancelled: true,
        }
    }
}

/// For tests that need OIDN: the library, or a loud skip where it is not
/// installed, which `MARBRE_REQUIRE_GPU=1` (set by `.ci/run`, which
/// installs the pyoidn wheel) turns into a failure, as the GPU tests do.
pub fn library_or_skip(test: &str) -> Option<std::sync::Arc<Library>> {
    match Library::shared() {
        Ok(lib) => Some(lib),
        Err(why) => {
            if std::env::var("MARBRE_REQUIRE_GPU").is_ok_and(|v| !v.is_empty() && v != "0") {
                panic!("{test} needs OIDN and MARBRE_REQUIRE_GPU is set: {why}");
            }
            eprintln!(
                "\n!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!\n\
                 !! SKIPPED {test}: {why}\n\
                 !! (set MARBRE_REQUIRE_GPU=1 to make this a failure)\n\
                 !!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!!\n"
            );
            None
        }
    }
}
