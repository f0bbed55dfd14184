//! Assembles a WGSL module for one program and one [`FeatureSet`] from the
//! WGSL files, each kept beside its CPU twin (`marbre_core::noise::perlin`
//! and `perlin.wgsl`, …) or, for the renderer's own passes, in
//! `shaders/`. A program names its root file (its entry points); every file
//! says what it needs with `#import` lines ([`preprocess`]), so the table
//! below only registers files and the module is the root's imports,
//! followed depth first.

use crate::gpu::features::FeatureSet;
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

    /// The file holding this program's entry points; it and the files it
    /// imports, transitively, make the program.
    fn root(self) -> WgslFile {
        match self {
            Program::Trace => r::TRACE,
            Program::Display => r::TONEMAP,
            Program::AutoExposure => r::AUTO_EXPOSURE,
            Program::ErrorMeter => r::ERROR_METER,
            Program::Denoise => r::DENOISE,
            Program::NoiseHarness => r::HARNESS_NOISE,
            Program::TextureHarness => r::HARNESS_TEXTURE,
            Program::BvhHarness => r::HARNESS_BVH,
            Program::AccumulationHarness => r::HARNESS_ACCUMULATION,
            Program::GeometryHarness => r::HARNESS_GEOMETRY,
            Program::SamplingHarness => r::HARNESS_SAMPLING,
            Program::Bake => r::BAKE,
            Program::Swatch => r::SWATCH,
        }
    }

    /// Whether generated texture code completes this program (its root
    /// calls what [`crate::gpu::texture_codegen`] writes).
    fn takes_generated_textures(self) -> bool {
        matches!(self, Program::Trace | Program::Bake | Program::Swatch)
    }
}

/// The files `root` needs under `defines`, preprocessed: each import before
/// the file importing it, depth first in the order the imports are written,
/// each file once.
fn files_from(
    root: WgslFile,
    defines: &std::collections::BTreeSet<&str>,
) -> Result<Vec<(WgslFile, String)>, PreprocessError> {
    fn visit(
        file: WgslFile,
        defines: &std::collections::BTreeSet<&str>,
        open: &mut Vec<&'static str>,
        done: &mut Vec<(WgslFile, String)>,
    ) -> Result<(), PreprocessError> {
        if done.iter().any(|(f, _)| f.name == file.name) {
            return Ok(());
        }
        if let Some(at) = open.iter().position(|name| *name == file.name) {
            let mut chain: Vec<String> = open[at..].iter().map(|n| n.to_string()).collect();
            chain.push(file.name.to_owned());
            return Err(PreprocessError::ImportCycle {
                file: file.name.to_owned(),
                chain,
            });
        }
        let out = preprocess(&source_text(&file), file.name, defines)?;
        open.push(file.name);
        for (name, line) in &out.imports {
            let Some(import) = SOURCES.iter().find(|f| f.name == name) else {
                return Err(PreprocessError::UnknownImport {
                    file: file.name.to_owned(),
                    line: *line,
                    name: name.clone(),
                });
            };
            visit(*import, defines, open, done)?;
        }
        open.pop();
        done.push((file, out.text));
        Ok(())
    }
    let mut done = Vec::new();
    visit(root, defines, &mut Vec::new(), &mut done)?;
    Ok(done)
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
    let mut module = String::new();
    for (file, text) in files_from(program.root(), &features.defines())? {
        module.push_str(&format!("{SECTION_HEADER}{}\n", file.name));
        module.push_str(&text);
    }
    if program.takes_generated_textures() {
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
        let defines = FeatureSet::all().defines();
        let mut reached = std::collections::BTreeSet::new();
        for program in Program::ALL {
            for (file, _) in files_from(program.root(), &defines).unwrap() {
                reached.insert(file.name);
            }
        }
        for file in SOURCES {
            assert!(
                reached.contains(file.name),
                "{} is imported by no program",
                file.name
            );
        }
    }

    /// The module of `program` from its files but `skip`.
    fn module_without(
        program: Program,
        features: &FeatureSet,
        generated: &str,
        skip: &str,
    ) -> String {
        let mut module = String::new();
        for (file, text) in files_from(program.root(), &features.defines()).unwrap() {
            if file.name != skip {
                module.push_str(&text);
            }
        }
        if program.takes_generated_textures() {
            module.push_str(generated);
        }
        module
    }

    /// Texture code that calls every pattern of the table, the image one
    /// reading a (missing, so placeholder) image: the surface textures of a
    /// scene with a sphere per pattern, or the swatches of those textures.
    fn every_pattern_texture_code(program: Program) -> String {
        use marbre_core::scene::{Pattern, PatternKind, Scene, Sphere, Texture};
        use marbre_core::texture::ImageSource;
        let textures: Vec<Texture> = PatternKind::all()
            .map(|kind| Texture {
                image: (kind == PatternKind::Image).then(|| ImageSource {
                    path: "missing.png".into(),
                    color_space: Default::default(),
                }),
                ..Texture::blend(Pattern::fresh(kind, None), 0.0, 1.0)
            })
            .collect();
        let scene = Scene {
            spheres: textures
                .iter()
                .map(|texture| {
                    let mut sphere = Sphere::default();
                    sphere.material.diffuse = texture.clone();
                    sphere
                })
                .collect(),
            ..Scene::default()
        };
        let images = crate::session::load_images(&scene, &mut Vec::new()).unwrap();
        let code = match program {
            Program::Swatch => crate::gpu::texture_codegen::generate_swatches(&textures, &images),
            _ => crate::gpu::texture_codegen::generate(&scene, &images),
        };
        code.unwrap().wgsl
    }

    /// The imports are what each program needs, no less and no more: with
    /// every feature on and texture code that calls every pattern, each
    /// program validates, and leaving out any file but one holding entry
    /// points (the root, or `fullscreen.wgsl`'s vertex stage, which the
    /// pipeline names from Rust) breaks it: something left refers to what
    /// the file declares.
    #[test]
    fn every_program_takes_the_files_it_needs_and_no_other() {
        let features = FeatureSet::all();
        let mut unneeded = Vec::new();
        for program in Program::ALL {
            let generated = every_pattern_texture_code(program);
            let whole = module_without(program, &features, &generated, "");
            if let Err(e) = crate::gpu::pipelines::validate(&whole) {
                panic!("{program:?} is invalid:\n{e}");
            }
            for (file, text) in files_from(program.root(), &features.defines()).unwrap() {
                if ["@vertex", "@fragment", "@compute"]
                    .iter()
                    .any(|stage| text.contains(stage))
                {
                    continue;
                }
                let without = module_without(program, &features, &generated, file.name);
                if crate::gpu::pipelines::validate(&without).is_ok() {
                    unneeded.push(format!("{program:?}: {}", file.name));
                }
            }
        }
        assert!(
            unneeded.is_empty(),
            "these validate without the file, so nothing needs it:\n{}",
            unneeded.join("\n")
        );
    }

    #[test]
    fn an_unknown_import_and_a_cycle_are_named() {
        let defines = Default::default();
        let missing = WgslFile {
            name: "shaders/missing_import.wgsl",
            source_path: "",
            text: "fn f() {}\n#import shaders/nowhere.wgsl\n",
        };
        assert_eq!(
            files_from(missing, &defines).unwrap_err().to_string(),
            "shaders/missing_import.wgsl:2: `#import shaders/nowhere.wgsl` names no WGSL file marbre has"
        );
        let looping = WgslFile {
            name: "shaders/common.wgsl",
            source_path: "",
            text: "#import shaders/fullscreen.wgsl\n#import shaders/common.wgsl\n",
        };
        assert!(matches!(
            files_from(looping, &defines),
            Err(PreprocessError::ImportCycle { .. })
        ));
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
