//! Assembles a WGSL module for one program and one [`FeatureSet`] from the
//! WGSL files, each kept beside its CPU twin (`marbre_core::noise::perlin`
//! and `perlin.wgsl`, …) or, for the renderer's own passes, in
//! `shaders/`.

use crate::gpu::features::{Feature, FeatureSet};
use crate::gpu::preprocess::{PreprocessError, preprocess};

/// The renderer's own WGSL, in the repository's `shaders/`: the trace and
/// display passes and what only they use, the compute passes (metering,
/// error, denoise, bake, swatch) and, in `shaders/harness/`, the test
/// harnesses' entry points. Listed here, not in the passes' modules, so
/// that the passes import this table and it imports none of them.
pub(crate) mod renderer_files {
    use marbre_core::wgsl::WgslFile;
    use marbre_core::wgsl_file;

    pub const COMMON: WgslFile = wgsl_file!("shaders/common.wgsl");
    pub const FULLSCREEN: WgslFile = wgsl_file!("shaders/fullscreen.wgsl");
    pub const SCENE: WgslFile = wgsl_file!("shaders/scene.wgsl");
    pub const TEXTURES: WgslFile = wgsl_file!("shaders/textures.wgsl");
    pub const INTERSECT: WgslFile = wgsl_file!("shaders/intersect.wgsl");
    pub const RANDOM: WgslFile = wgsl_file!("shaders/random.wgsl");
    pub const SURFACE: WgslFile = wgsl_file!("shaders/surface.wgsl");
    pub const ENV_LOOKUP: WgslFile = wgsl_file!("shaders/env_lookup.wgsl");
    pub const BUMP_MAPPING: WgslFile = wgsl_file!("shaders/bump_mapping.wgsl");
    pub const VIEW: WgslFile = wgsl_file!("shaders/view.wgsl");
    pub const TRACE: WgslFile = wgsl_file!("shaders/trace.wgsl");
    pub const TONEMAP: WgslFile = wgsl_file!("shaders/tonemap.wgsl");
    pub const ACCUMULATION: WgslFile = wgsl_file!("shaders/accumulation.wgsl");
    pub const METERING_GRID: WgslFile = wgsl_file!("shaders/metering_grid.wgsl");
    pub const AUTO_EXPOSURE: WgslFile = wgsl_file!("shaders/auto_exposure.wgsl");
    pub const ERROR_METER: WgslFile = wgsl_file!("shaders/error_meter.wgsl");
    pub const DENOISE: WgslFile = wgsl_file!("shaders/denoise.wgsl");
    pub const BAKE: WgslFile = wgsl_file!("shaders/bake.wgsl");
    pub const SWATCH: WgslFile = wgsl_file!("shaders/swatch.wgsl");
    pub const HARNESS_ACCUMULATION: WgslFile = wgsl_file!("shaders/harness/accumulation.wgsl");
    pub const HARNESS_NOISE: WgslFile = wgsl_file!("shaders/harness/noise.wgsl");
    pub const HARNESS_TEXTURE: WgslFile = wgsl_file!("shaders/harness/texture.wgsl");
    pub const HARNESS_BVH: WgslFile = wgsl_file!("shaders/harness/bvh.wgsl");
    pub const HARNESS_GEOMETRY: WgslFile = wgsl_file!("shaders/harness/geometry.wgsl");
    pub const HARNESS_SAMPLING: WgslFile = wgsl_file!("shaders/harness/sampling.wgsl");
}

use marbre_core::wgsl::WgslFile;
use marbre_core::{accel, bsdf, env_sampling, envmap, geometry, lights, mis, noise, texture};
use renderer_files as r;

/// Every WGSL file, each named by the module it belongs to: the CPU twin
/// beside which it lives, or the renderer's own files. `--dev` reloads
/// them all and the benchmark references are keyed by their text.
const SOURCES: &[WgslFile] = &[
    r::COMMON,
    r::FULLSCREEN,
    noise::hash::WGSL,
    noise::gradient::WGSL,
    noise::perlin::WGSL,
    noise::fractal::WGSL,
    envmap::WGSL,
    r::SCENE,
    r::TEXTURES,
    r::INTERSECT,
    r::RANDOM,
    bsdf::WGSL,
    r::SURFACE,
    r::ENV_LOOKUP,
    r::VIEW,
    r::TRACE,
    r::ACCUMULATION,
    r::HARNESS_ACCUMULATION,
    r::TONEMAP,
    r::METERING_GRID,
    r::AUTO_EXPOSURE,
    r::ERROR_METER,
    r::DENOISE,
    r::HARNESS_NOISE,
    texture::PATTERNS_WGSL,
    r::BUMP_MAPPING,
    texture::SHADING_WGSL,
    texture::mapping::WGSL,
    r::HARNESS_TEXTURE,
    texture::image::WGSL,
    env_sampling::WGSL,
    mis::WGSL,
    lights::WGSL,
    accel::traverse::WGSL,
    r::HARNESS_BVH,
    geometry::sphere::WGSL,
    geometry::ray_offset::WGSL,
    texture::bump::WGSL,
    r::HARNESS_GEOMETRY,
    r::HARNESS_SAMPLING,
    r::BAKE,
    r::SWATCH,
];

/// The repository's root, from which every file of [`SOURCES`] is named.
pub const DEV_SOURCE_ROOT: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../..");

/// The folders under [`DEV_SOURCE_ROOT`] that hold the WGSL, which
/// `marbre --dev` watches for edits: the renderer's own and the CPU twins'.
pub const DEV_SOURCE_FOLDERS: [&str; 2] = ["shaders", "crates"];

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Program {
    /// The path tracer's fragment pass.
    Trace,
    /// Exposure and tone mapping to the screen or an image.
    Display,
    /// The compute pass that meters the image's log-average luminance.
    AutoExposure,
    /// The compute pass that estimates the image's error from its spread.
    ErrorMeter,
    /// One iteration of the denoiser's edge-avoiding à-trous filter.
    Denoise,
    /// The compute pass that evaluates noise at given points.
    NoiseHarness,
    /// The compute pass that evaluates the texture library's patterns.
    TextureHarness,
    /// The compute pass that sends rays through a triangle mesh's BVH.
    BvhHarness,
    /// The compute pass that runs the accumulation update over long
    /// streams of frames.
    AccumulationHarness,
    /// The compute pass that runs the ray geometry (sphere distance, ray
    /// offset, shading normal) on given inputs.
    GeometryHarness,
    /// The compute pass that runs the BSDF, environment and MIS sampling
    /// functions on given inputs.
    SamplingHarness,
    /// The compute pass that evaluates a scene's generated texture code at
    /// given surface points (`marbre bake`).
    Bake,
    /// The compute pass that evaluates texture nodes alone over a swatch
    /// (the panel's previews), from generated texture code.
    Swatch,
}

impl Program {
    pub const ALL: [Program; 13] = [
        Program::Trace,
        Program::Display,
        Program::AutoExposure,
        Program::ErrorMeter,
        Program::Denoise,
        Program::NoiseHarness,
        Program::TextureHarness,
        Program::BvhHarness,
        Program::AccumulationHarness,
        Program::GeometryHarness,
        Program::SamplingHarness,
        Program::Bake,
        Program::Swatch,
    ];

    /// The files this program is made of, in order, for a feature set.
    fn files(self, features: &FeatureSet) -> Vec<WgslFile> {
        let noise = |out: &mut Vec<WgslFile>| {
            out.push(noise::hash::WGSL);
            if features.contains(Feature::NoiseGradient) {
                out.push(noise::gradient::WGSL);
            }
            if features.contains(Feature::NoisePerlin) {
                out.push(noise::perlin::WGSL);
            }
            out.push(noise::fractal::WGSL);
            out.push(envmap::WGSL);
        };
        // The scene and its generated texture code's library, which the
        // trace, swatches and bakes all evaluate.
        let texture_code = |out: &mut Vec<WgslFile>| {
            noise(out);
            out.extend([r::SCENE, texture::PATTERNS_WGSL, texture::mapping::WGSL]);
            if features.contains(Feature::IMAGE) {
                out.push(texture::image::WGSL);
            }
        };
        let mut out = vec![r::COMMON];
        match self {
            Program::Trace => {
                texture_code(&mut out);
                out.push(r::TEXTURES);
                if features.contains(Feature::Mesh) {
                    out.push(accel::traverse::WGSL);
                }
                out.extend([
                    geometry::sphere::WGSL,
                    geometry::ray_offset::WGSL,
                    r::INTERSECT,
                    r::RANDOM,
                    bsdf::WGSL,
                    r::SURFACE,
                    r::ENV_LOOKUP,
                    mis::WGSL,
                ]);
                if features.contains(Feature::PointLight) || features.contains(Feature::AreaLight) {
                    out.push(lights::WGSL);
                }
                if features.contains(Feature::EnvSampling) {
                    out.push(env_sampling::WGSL);
                }
                out.extend([r::FULLSCREEN, r::ACCUMULATION, r::VIEW, r::TRACE]);
                if features.contains(Feature::Bump) {
                    out.extend([texture::SHADING_WGSL, texture::bump::WGSL, r::BUMP_MAPPING]);
                }
            }
            Program::Display => out = vec![r::FULLSCREEN, r::TONEMAP],
            Program::AutoExposure => out.extend([r::METERING_GRID, r::AUTO_EXPOSURE]),
            Program::ErrorMeter => out.extend([r::METERING_GRID, r::ERROR_METER]),
            Program::Denoise => out.push(r::DENOISE),
            Program::NoiseHarness => {
                noise(&mut out);
                out.push(r::HARNESS_NOISE);
            }
            Program::TextureHarness => {
                noise(&mut out);
                out.extend([
                    texture::PATTERNS_WGSL,
                    texture::SHADING_WGSL,
                    texture::mapping::WGSL,
                    texture::image::WGSL,
                    r::HARNESS_TEXTURE,
                ]);
            }
            Program::Swatch => {
                texture_code(&mut out);
                out.extend([r::TEXTURES, geometry::sphere::WGSL, r::INTERSECT, r::SWATCH]);
            }
            Program::BvhHarness => out.extend([accel::traverse::WGSL, r::HARNESS_BVH]),
            Program::AccumulationHarness => {
                out.extend([noise::hash::WGSL, r::ACCUMULATION, r::HARNESS_ACCUMULATION])
            }
            Program::GeometryHarness => out.extend([
                texture::SHADING_WGSL,
                geometry::sphere::WGSL,
                geometry::ray_offset::WGSL,
                texture::bump::WGSL,
                r::HARNESS_GEOMETRY,
            ]),
            Program::SamplingHarness => out.extend([
                noise::hash::WGSL,
                r::RANDOM,
                envmap::WGSL,
                bsdf::WGSL,
                r::ENV_LOOKUP,
                mis::WGSL,
                env_sampling::WGSL,
                r::HARNESS_SAMPLING,
            ]),
            Program::Bake => {
                texture_code(&mut out);
                out.push(r::TEXTURES);
                if features.contains(Feature::Mesh) {
                    out.push(accel::traverse::WGSL);
                }
                // `Hit`, which textures.wgsl's footprint reads.
                out.extend([geometry::sphere::WGSL, r::INTERSECT, r::BAKE]);
            }
        }
        out
    }
}

/// WGSL read from a folder at run time (`marbre --dev`), replacing the
/// embedded copies until the process ends, so an edited shader can be
/// tried without rebuilding marbre.
struct DevSources {
    files: Vec<(&'static str, String)>,
    /// Counts the loads: a pipeline built from older text is stale.
    generation: u64,
}

static DEV_SOURCES: std::sync::RwLock<Option<DevSources>> = std::sync::RwLock::new(None);

/// Reads every shader file from the source tree (each from its
/// `source_path`), to be used instead of the embedded copies from now on;
/// returns the new generation, or `None` when the text is what was loaded
/// last (reading the files is itself a file event to a watcher). On error
/// nothing changes.
pub fn load_dev_sources() -> anyhow::Result<Option<u64>> {
    let mut files = Vec::with_capacity(SOURCES.len());
    for file in SOURCES {
        let text = std::fs::read_to_string(file.source_path)
            .map_err(|e| anyhow::anyhow!("{}: {e}", file.name))?;
        files.push((file.name, text));
    }
    let mut dev = DEV_SOURCES.write().unwrap_or_else(|e| e.into_inner());
    if dev.as_ref().is_some_and(|d| d.files == files) {
        return Ok(None);
    }
    let generation = dev.as_ref().map_or(1, |d| d.generation + 1);
    *dev = Some(DevSources { files, generation });
    Ok(Some(generation))
}

/// Which sources [`assemble`] reads: 0 for the embedded ones, else the
/// count of [`load_dev_sources`] calls. Part of a pipeline's key.
pub fn sources_generation() -> u64 {
    let dev = DEV_SOURCES.read().unwrap_or_else(|e| e.into_inner());
    dev.as_ref().map_or(0, |d| d.generation)
}

/// The text of `file`: the dev copy if loaded, else embedded.
fn source_text(file: &WgslFile) -> String {
    let dev = DEV_SOURCES.read().unwrap_or_else(|e| e.into_inner());
    let dev_text = dev
        .as_ref()
        .and_then(|d| d.files.iter().find(|(n, _)| *n == file.name))
        .map(|(_, text)| text.clone());
    dev_text.unwrap_or_else(|| file.text.to_owned())
}

/// A hash of every WGSL source in use: results cached on disk (benchmark
/// references) are keyed by it, so a shader change invalidates them.
pub fn sources_fingerprint() -> u64 {
    use std::hash::{Hash, Hasher};
    let mut hasher = std::collections::hash_map::DefaultHasher::new();
    for file in SOURCES {
        file.name.hash(&mut hasher);
        source_text(file).hash(&mut hasher);
    }
    hasher.finish()
}

/// The WGSL text of `program` specialised for `features`. The trace and
/// bake and swatch programs also take generated texture code
/// ([`crate::gpu::texture_codegen::generate`]); the others ignore it.
pub fn assemble(
    program: Program,
    features: &FeatureSet,
    generated_textures: &str,
) -> Result<String, PreprocessError> {
    let defines = features.defines();
    let mut module = String::new();
    for file in program.files(features) {
        module.push_str(&format!("{SECTION_HEADER}{}\n", file.name));
        module.push_str(&preprocess(&source_text(&file), file.name, &defines)?);
    }
    if matches!(program, Program::Trace | Program::Bake | Program::Swatch) {
        module.push_str(&format!("{SECTION_HEADER}generated textures\n"));
        module.push_str(generated_textures);
    }
    Ok(module)
}

/// The line [`assemble`] puts before each file's text, followed by its name.
const SECTION_HEADER: &str = "// ---- ";

/// Where line `line` (1-based) of an [`assemble`]d module comes from: the
/// file's name and its own line number. Preprocessing keeps every line
/// (a dropped one is left empty), so the offset from the file's header is
/// its line in the file. None before the first header or past the end.
pub fn source_position(module: &str, line: u32) -> Option<(String, u32)> {
    let mut section = None;
    for (index, text) in module.lines().enumerate().take(line as usize) {
        if let Some(name) = text.strip_prefix(SECTION_HEADER) {
            section = Some((name.to_owned(), index as u32 + 1));
        }
        if index as u32 + 1 == line {
            return section.map(|(name, header)| (name, line - header));
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `--dev` reads each file from its `source_path`: in the source tree
    /// it holds the embedded text, and every file a program uses is in the
    /// table that `--dev` reloads, once.
    #[test]
    fn every_source_is_found_in_the_tree_and_listed_once() {
        let root = std::path::Path::new(DEV_SOURCE_ROOT);
        for file in SOURCES {
            let on_disk = std::fs::read_to_string(file.source_path)
                .unwrap_or_else(|e| panic!("{}: {e}", file.source_path));
            assert!(
                on_disk == file.text,
                "{} differs from the copy built in",
                file.name
            );
            assert!(
                root.join(file.name).is_file(),
                "{} is not under the repository",
                file.name
            );
            assert!(
                DEV_SOURCE_FOLDERS
                    .iter()
                    .any(|folder| file.name.starts_with(&format!("{folder}/"))),
                "{} is in no folder `--dev` watches",
                file.name
            );
        }
        let mut names: Vec<&str> = SOURCES.iter().map(|f| f.name).collect();
        names.sort();
        names.dedup();
        assert_eq!(names.len(), SOURCES.len(), "a file is listed twice");
        for program in Program::ALL {
            for file in program.files(&FeatureSet::all()) {
                assert!(
                    SOURCES.contains(&file),
                    "{program:?} uses {} unlisted",
                    file.name
                );
            }
        }
    }

    #[test]
    fn a_module_line_maps_back_to_its_file_and_line() {
        let module = assemble(Program::Trace, &FeatureSet::all(), "fn generated() {}\n").unwrap();
        let module_line = module
            .lines()
            .position(|l| l.starts_with("fn fs_trace("))
            .unwrap() as u32
            + 1;
        let file_line = source_text(&r::TRACE)
            .lines()
            .position(|l| l.starts_with("fn fs_trace("))
            .unwrap() as u32
            + 1;
        assert_eq!(
            source_position(&module, module_line),
            Some(("shaders/trace.wgsl".to_owned(), file_line))
        );
        let last = module.lines().count() as u32;
        assert_eq!(
            source_position(&module, last),
            Some(("generated textures".to_owned(), 1))
        );
        assert_eq!(source_position(&module, last + 1), None);
        assert_eq!(source_position("fn f() {}\n", 1), None, "no header");
    }
}
