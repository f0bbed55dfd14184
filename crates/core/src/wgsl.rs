//! A WGSL file kept beside the Rust module that is its CPU twin: the
//! module declares `pub const WGSL: WgslFile = wgsl_file!("…")`, and the
//! renderer's shader table (`marbre_render::gpu::shader_source`) lists
//! those constants. The text is embedded at build time; the path lets
//! compiler errors name the file and `marbre --dev` read the edited copy.

/// One WGSL source file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct WgslFile {
    /// Its path from the repository's root (`crates/core/src/noise/hash.wgsl`):
    /// what shader errors name.
    pub name: &'static str,
    /// Its absolute path on the machine that built marbre, which `--dev`
    /// reads.
    pub source_path: &'static str,
    /// Its text as built in.
    pub text: &'static str,
}

/// The [`WgslFile`] at `$path`, a path from the repository's root. Every
/// marbre crate sits two folders below that root (`crates/<name>`), which
/// is how the path is found from the calling crate's manifest.
#[macro_export]
macro_rules! wgsl_file {
    ($path:literal) => {
        $crate::wgsl::WgslFile {
            name: $path,
            source_path: concat!(env!("CARGO_MANIFEST_DIR"), "/../../", $path),
            text: include_str!(concat!(env!("CARGO_MANIFEST_DIR"), "/../../", $path)),
        }
    };
}
