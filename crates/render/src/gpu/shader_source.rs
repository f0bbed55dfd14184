//! Assembles a WGSL module from the files in `shaders/` for one program and
//! one [`FeatureSet`].

use super::features::{Feature, FeatureSet};
use super::preprocess::{PreprocessError, preprocess};

/// The source tree's `shaders/` folder, which `marbre --dev` reads and
/// watches instead of the embedded copies.
pub const SHADER_DIR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/shaders");

/// The WGSL sources, embedded at build time so the binary is self-contained.
const SOURCES: &[(&str, &str)] = &[
    ("common.wgsl", include_str!("../../shaders/common.wgsl")),
    (
        "fullscreen.wgsl",
        include_str!("../../shaders/fullscreen.wgsl"),
    ),
    ("hash.wgsl", include_str!("../../shaders/hash.wgsl")),
    (
        "noise_gradient.wgsl",
        include_str!("../../shaders/noise_gradient.wgsl"),
    ),
    (
        "noise_perlin.wgsl",
        include_str!("../../shaders/noise_perlin.wgsl"),
    ),
    ("fractal.wgsl", include_str!("../../shaders/fractal.wgsl")),
    (
        "env_mapping.wgsl",
        include_str!("../../shaders/env_mapping.wgsl"),
    ),
    ("scene.wgsl", include_str!("../../shaders/scene.wgsl")),
    ("textures.wgsl", include_str!("../../shaders/textures.wgsl")),
    (
        "intersect.wgsl",
        include_str!("../../shaders/intersect.wgsl"),
    ),
    ("random.wgsl", include_str!("../../shaders/random.wgsl")),
    ("bsdf.wgsl", include_str!("../../shaders/bsdf.wgsl")),
    ("surface.wgsl", include_str!("../../shaders/surface.wgsl")),
    (
        "env_lookup.wgsl",
        include_str!("../../shaders/env_lookup.wgsl"),
    ),
    ("trace.wgsl", include_str!("../../shaders/trace.wgsl")),
    (
        "accumulate.wgsl",
        include_str!("../../shaders/accumulate.wgsl"),
    ),
    (
        "accumulation_harness.wgsl",
        include_str!("../../shaders/accumulation_harness.wgsl"),
    ),
    ("tonemap.wgsl", include_str!("../../shaders/tonemap.wgsl")),
    (
        "metering_grid.wgsl",
        include_str!("../../shaders/metering_grid.wgsl"),
    ),
    (
        "auto_exposure.wgsl",
        include_str!("../../shaders/auto_exposure.wgsl"),
    ),
    (
        "error_meter.wgsl",
        include_str!("../../shaders/error_meter.wgsl"),
    ),
    (
        "noise_harness.wgsl",
        include_str!("../../shaders/noise_harness.wgsl"),
    ),
    (
        "texture_patterns.wgsl",
        include_str!("../../shaders/texture_patterns.wgsl"),
    ),
    ("bump.wgsl", include_str!("../../shaders/bump.wgsl")),
    (
        "texture_shading.wgsl",
        include_str!("../../shaders/texture_shading.wgsl"),
    ),
    (
        "texture_mapping.wgsl",
        include_str!("../../shaders/texture_mapping.wgsl"),
    ),
    (
        "texture_harness.wgsl",
        include_str!("../../shaders/texture_harness.wgsl"),
    ),
    (
        "texture_image.wgsl",
        include_str!("../../shaders/texture_image.wgsl"),
    ),
    (
        "env_sampling.wgsl",
        include_str!("../../shaders/env_sampling.wgsl"),
    ),
    ("mis.wgsl", include_str!("../../shaders/mis.wgsl")),
    ("lights.wgsl", include_str!("../../shaders/lights.wgsl")),
    ("bvh.wgsl", include_str!("../../shaders/bvh.wgsl")),
    (
        "bvh_harness.wgsl",
        include_str!("../../shaders/bvh_harness.wgsl"),
    ),
    (
        "ray_geometry.wgsl",
        include_str!("../../shaders/ray_geometry.wgsl"),
    ),
    (
        "shading_normal.wgsl",
        include_str!("../../shaders/shading_normal.wgsl"),
    ),
    (
        "geometry_harness.wgsl",
        include_str!("../../shaders/geometry_harness.wgsl"),
    ),
    (
        "sampling_harness.wgsl",
        include_str!("../../shaders/sampling_harness.wgsl"),
    ),
];

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
}

impl Program {
    pub const ALL: [Program; 10] = [
        Program::Trace,
        Program::Display,
        Program::AutoExposure,
        Program::ErrorMeter,
        Program::NoiseHarness,
        Program::TextureHarness,
        Program::BvhHarness,
        Program::AccumulationHarness,
        Program::GeometryHarness,
        Program::SamplingHarness,
    ];

    /// The files this program is made of, in order, for a feature set.
    fn files(self, features: &FeatureSet) -> Vec<&'static str> {
        let noise = |out: &mut Vec<&'static str>| {
            out.push("hash.wgsl");
            if features.contains(Feature::NoiseGradient) {
                out.push("noise_gradient.wgsl");
            }
            if features.contains(Feature::NoisePerlin) {
                out.push("noise_perlin.wgsl");
            }
            out.push("fractal.wgsl");
            out.push("env_mapping.wgsl");
        };
        let mut out = vec!["common.wgsl"];
        match self {
            Program::Trace => {
                noise(&mut out);
                out.extend([
                    "scene.wgsl",
                    "texture_patterns.wgsl",
                    "texture_mapping.wgsl",
                ]);
                if features.contains(Feature::Image) {
                    out.push("texture_image.wgsl");
                }
                out.push("textures.wgsl");
                if features.contains(Feature::Mesh) {
                    out.push("bvh.wgsl");
                }
                out.extend([
                    "ray_geometry.wgsl",
                    "intersect.wgsl",
                    "random.wgsl",
                    "bsdf.wgsl",
                    "surface.wgsl",
                    "env_lookup.wgsl",
                    "mis.wgsl",
                ]);
                if features.contains(Feature::PointLight) || features.contains(Feature::AreaLight) {
                    out.push("lights.wgsl");
                }
                if features.contains(Feature::EnvSampling) {
                    out.push("env_sampling.wgsl");
                }
                out.extend(["fullscreen.wgsl", "accumulate.wgsl", "trace.wgsl"]);
                if features.contains(Feature::Bump) {
                    out.extend(["texture_shading.wgsl", "shading_normal.wgsl", "bump.wgsl"]);
                }
            }
            Program::Display => out = vec!["fullscreen.wgsl", "tonemap.wgsl"],
            Program::AutoExposure => out.extend(["metering_grid.wgsl", "auto_exposure.wgsl"]),
            Program::ErrorMeter => out.extend(["metering_grid.wgsl", "error_meter.wgsl"]),
            Program::NoiseHarness => {
                noise(&mut out);
                out.push("noise_harness.wgsl");
            }
            Program::TextureHarness => {
                noise(&mut out);
                out.extend([
                    "texture_patterns.wgsl",
                    "texture_shading.wgsl",
                    "texture_mapping.wgsl",
                    "texture_image.wgsl",
                    "texture_harness.wgsl",
                ]);
            }
            Program::BvhHarness => out.extend(["bvh.wgsl", "bvh_harness.wgsl"]),
            Program::AccumulationHarness => {
                out.extend(["hash.wgsl", "accumulate.wgsl", "accumulation_harness.wgsl"])
            }
            Program::GeometryHarness => out.extend([
                "texture_shading.wgsl",
                "ray_geometry.wgsl",
                "shading_normal.wgsl",
                "geometry_harness.wgsl",
            ]),
            Program::SamplingHarness => out.extend([
                "hash.wgsl",
                "random.wgsl",
                "env_mapping.wgsl",
                "bsdf.wgsl",
                "env_lookup.wgsl",
                "mis.wgsl",
                "env_sampling.wgsl",
                "sampling_harness.wgsl",
            ]),
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

/// Reads every shader file from `dir` (the repository's `shaders/`), to be
/// used instead of the embedded copies from now on; returns the new
/// generation, or `None` when the text is what was loaded last (reading
/// the files is itself a file event to a watcher). On error nothing
/// changes.
pub fn load_dev_sources(dir: &std::path::Path) -> anyhow::Result<Option<u64>> {
    let mut files = Vec::with_capacity(SOURCES.len());
    for (name, _) in SOURCES {
        let path = dir.join(name);
        let text = std::fs::read_to_string(&path)
            .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
        files.push((*name, text));
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

/// The text of shader file `name`: the dev copy if loaded, else embedded.
fn source_text(name: &str) -> String {
    let dev = DEV_SOURCES.read().unwrap_or_else(|e| e.into_inner());
    let dev_text = dev
        .as_ref()
        .and_then(|d| d.files.iter().find(|(n, _)| *n == name))
        .map(|(_, text)| text.clone());
    dev_text.unwrap_or_else(|| {
        let (_, text) = SOURCES
            .iter()
            .find(|(n, _)| *n == name)
            .expect("every listed file is embedded");
        (*text).to_owned()
    })
}

/// A hash of every WGSL source in use: results cached on disk (benchmark
/// references) are keyed by it, so a shader change invalidates them.
pub fn sources_fingerprint() -> u64 {
    use std::hash::{Hash, Hasher};
    let mut hasher = std::collections::hash_map::DefaultHasher::new();
    for (name, _) in SOURCES {
        name.hash(&mut hasher);
        source_text(name).hash(&mut hasher);
    }
    hasher.finish()
}

/// The WGSL text of `program` specialised for `features`. The trace program
/// also takes the scene's generated texture code
/// ([`super::texture_codegen::generate`]); the others ignore it.
pub fn assemble(
    program: Program,
    features: &FeatureSet,
    generated_textures: &str,
) -> Result<String, PreprocessError> {
    let defines = features.defines();
    let mut module = String::new();
    for name in program.files(features) {
        module.push_str(&format!("{SECTION_HEADER}{name}\n"));
        module.push_str(&preprocess(&source_text(name), name, &defines)?);
    }
    if program == Program::Trace {
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

    #[test]
    fn a_module_line_maps_back_to_its_file_and_line() {
        let module = assemble(Program::Trace, &FeatureSet::all(), "fn generated() {}\n").unwrap();
        let module_line = module
            .lines()
            .position(|l| l.starts_with("fn fs_trace("))
            .unwrap() as u32
            + 1;
        let file_line = source_text("trace.wgsl")
            .lines()
            .position(|l| l.starts_with("fn fs_trace("))
            .unwrap() as u32
            + 1;
        assert_eq!(
            source_position(&module, module_line),
            Some(("trace.wgsl".to_owned(), file_line))
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
