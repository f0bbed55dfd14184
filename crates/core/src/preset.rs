//! Preset files: a [`Scene`] in RON, versioned, with precise errors.

use crate::atomic_write::write_atomic;
use crate::scene::text_property::with_text_reader;
use crate::scene::{ColorEncoding, Scene};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The format this build writes. Older files load through `#[serde(default)]`
/// on every struct; newer ones are refused rather than half-understood.
/// Version 2 lets a texture's `a` and `b` be textures themselves; a version
/// 1 file (values only) reads unchanged.
pub const FORMAT_VERSION: u32 = 2;

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Preset {
    pub format_version: u32,
    pub description: String,
    /// How the file writes its colours (`colors: Srgb`: display values, as
    /// the course documents give them); the scene in memory is linear.
    #[serde(skip_serializing_if = "is_linear")]
    pub colors: ColorEncoding,
    pub scene: Scene,
}

fn is_linear(c: &ColorEncoding) -> bool {
    *c == ColorEncoding::Linear
}

/// What a preset says about itself rather than about the scene: whoever
/// edits the scene keeps it, so that saving writes it back unchanged.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Header {
    pub description: String,
    pub colors: ColorEncoding,
}

impl Preset {
    pub fn header(&self) -> Header {
        Header {
            description: self.description.clone(),
            colors: self.colors,
        }
    }

    /// The preset holding `scene` with `header`.
    pub fn with_header(header: &Header, scene: Scene) -> Self {
        Self {
            description: header.description.clone(),
            colors: header.colors,
            scene,
            ..Self::default()
        }
    }
}

impl Default for Preset {
    fn default() -> Self {
        Self {
            format_version: FORMAT_VERSION,
            description: String::new(),
            colors: ColorEncoding::Linear,
            scene: Scene::default(),
        }
    }
}

#[derive(Debug, thiserror::Error)]
pub enum PresetError {
    #[error("{path}: cannot read: {cause}")]
    Read {
        path: PathBuf,
        /// Not a `#[source]`: the message already says it, and a chain
        /// would print it twice.
        cause: std::io::Error,
    },
    #[error("{path}: not UTF-8 text (byte {offset}); a preset is a RON text file")]
    NotText { path: PathBuf, offset: usize },
    #[error(
        "{path}: the file is empty; a preset is a RON text such as presets/default.ron, starting with `(`"
    )]
    Empty { path: PathBuf },
    #[error("{path}:{line}:{column}: {field}{message}")]
    Syntax {
        path: PathBuf,
        line: usize,
        column: usize,
        /// `in field `a.b.c`: `, or empty when the error is outside any field.
        field: String,
        message: String,
    },
    #[error(
        "{path}: format version {found} is newer than this build understands ({FORMAT_VERSION}); update marbre"
    )]
    FutureVersion { path: PathBuf, found: u32 },
    #[error("{path}: cannot save: {cause}")]
    Write {
        path: PathBuf,
        /// Not a `#[source]`: the message already says it, and a chain
        /// would print it twice.
        cause: std::io::Error,
    },
    #[error("{path}: {}", problems.join("; "))]
    Animation {
        path: PathBuf,
        problems: Vec<String>,
    },
    #[error("cannot serialise the scene: {0}")]
    Serialise(#[from] ron::Error),
}

/// A loaded preset and the notes about values clamped into range.
#[derive(Debug, Clone)]
pub struct Loaded {
    pub preset: Preset,
    pub notes: Vec<String>,
}

/// Parses preset text. `path` is used in messages and to resolve the relative
/// paths inside the file.
pub fn parse(text: &str, path: &Path) -> Result<Loaded, PresetError> {
    if text.trim().is_empty() {
        return Err(PresetError::Empty {
            path: path.to_owned(),
        });
    }
    let mut de =
        ron::Deserializer::from_str(text).map_err(|e| syntax_error(path, &e, String::new()))?;
    // Fields this build does not know (from a newer minor version, or a
    // typo) are skipped with a note rather than refused: the rest of the
    // file is still worth loading.
    let mut unknown = Vec::new();
    let mut note_unknown = |field: serde_ignored::Path| unknown.push(field_path(&field));
    let tracked = serde_ignored::Deserializer::new(&mut de, &mut note_unknown);
    let tx_colors = match declared_colors(text) {
        ColorEncoding::Linear => crate::tx::Colors::Linear,
        ColorEncoding::Srgb => crate::tx::Colors::AsTyped,
    };
    let parsed: Result<Preset, _> = with_text_reader(crate::tx::read_preset_property, || {
        crate::tx::with_preset_colors(tx_colors, || serde_path_to_error::deserialize(tracked))
    });
    let mut preset = match parsed {
        Ok(p) => p,
        Err(e) => {
            // serde_path_to_error writes a field it had not yet named as
            // `?` (the text ended before its name): the path stops at the
            // last field that was named.
            let field = e.path().to_string();
            let field = field.trim_end_matches(".?").trim_end_matches('?');
            let field = if field == "." || field.is_empty() {
                String::new()
            } else {
                format!("in field `{field}`: ")
            };
            let spanned = de.span_error(e.into_inner());
            return Err(syntax_error(path, &spanned, field));
        }
    };
    if let Err(e) = de.end() {
        return Err(syntax_error(path, &de.span_error(e), String::new()));
    }
    if preset.format_version > FORMAT_VERSION {
        return Err(PresetError::FutureVersion {
            path: path.to_owned(),
            found: preset.format_version,
        });
    }
    preset.format_version = FORMAT_VERSION;
    preset.colors.decode_scene(&mut preset.scene);
    // Relative paths resolve against the preset's folder, tidied so that
    // messages name `envmaps/x.exr`, not `bad/../envmaps/x.exr`.
    let folder = path.parent().unwrap_or(Path::new("."));
    let resolve = |file: &mut PathBuf| {
        if file.is_relative() {
            *file = crate::lexical_path::normalize(&folder.join(&*file));
        }
    };
    for env in preset.scene.environment.source.paths_mut() {
        resolve(env);
    }
    for_each_image_path(&mut preset.scene, &mut |image| resolve(image));
    for mesh in &mut preset.scene.meshes {
        resolve(&mut mesh.obj);
    }
    let mut notes: Vec<String> = unknown
        .into_iter()
        .map(|field| {
            format!(
                "{}: unknown field `{field}` ignored (misspelt, or from a newer marbre)",
                path.display()
            )
        })
        .collect();
    notes.extend(preset.scene.sanitize());
    if let Some(animation) = &preset.scene.animation {
        let problems = animation.problems(&preset.scene);
        if !problems.is_empty() {
            return Err(PresetError::Animation {
                path: path.to_owned(),
                problems,
            });
        }
    }
    Ok(Loaded { preset, notes })
}

/// The `colors` a preset's text declares, read ahead of the rest: TX text
/// inside the scene lowers its colours by it. Text that does not parse
/// says linear; the full parse then reports the error.
fn declared_colors(text: &str) -> ColorEncoding {
    #[derive(Deserialize)]
    struct Declared {
        #[serde(default)]
        colors: ColorEncoding,
    }
    ron::from_str::<Declared>(text).map_or(ColorEncoding::Linear, |d| d.colors)
}

/// A field's path as `serde_path_to_error` writes it in errors
/// (`scene.spheres[0].radius`), so that notes and errors read alike.
fn field_path(path: &serde_ignored::Path) -> String {
    use serde_ignored::Path as P;
    match path {
        P::Root => String::new(),
        P::Seq { parent, index } => format!("{}[{index}]", field_path(parent)),
        P::Map { parent, key } => match field_path(parent) {
            p if p.is_empty() => key.clone(),
            p => format!("{p}.{key}"),
        },
        P::Some { parent } | P::NewtypeStruct { parent } | P::NewtypeVariant { parent } => {
            field_path(parent)
        }
    }
}

fn syntax_error(path: &Path, e: &ron::error::SpannedError, field: String) -> PresetError {
    let message = match e.code {
        ron::Error::Eof => {
            "the file ends here, in the middle of the preset (truncated? compare with a saved \
             preset such as presets/default.ron)"
                .to_owned()
        }
        ref code => code.to_string(),
    };
    PresetError::Syntax {
        path: path.to_owned(),
        line: e.span.start.line,
        column: e.span.start.col,
        field,
        message,
    }
}

/// Reads and parses a preset file.
pub fn load(path: &Path) -> Result<Loaded, PresetError> {
    let bytes =
        crate::capped_read::read_capped(path, crate::capped_read::PRESET).map_err(|cause| {
            PresetError::Read {
                path: path.to_owned(),
                cause,
            }
        })?;
    parse_bytes(&bytes, path)
}

/// Parses the bytes of a preset file: [`parse`] after the UTF-8 check that
/// [`load`] makes, so the fuzz target and the regression tests reach it
/// without a file.
pub fn parse_bytes(bytes: &[u8], path: &Path) -> Result<Loaded, PresetError> {
    let text = std::str::from_utf8(bytes).map_err(|e| PresetError::NotText {
        path: path.to_owned(),
        offset: e.valid_up_to(),
    })?;
    parse(text, path)
}

/// Serialises a preset as it would be saved at `path`: paths inside it are
/// written relative to the file's folder, so a preset folder can be moved.
pub fn to_text(preset: &Preset, path: &Path) -> Result<String, PresetError> {
    let mut preset = preset.clone();
    preset.colors.encode_scene(&mut preset.scene);
    let dir = absolute(path.parent().unwrap_or(Path::new(".")));
    let mut relative = |file: &mut PathBuf| {
        if let Some(rel) = pathdiff::diff_paths(absolute(file), &dir) {
            *file = rel;
        }
    };
    for env in preset.scene.environment.source.paths_mut() {
        relative(env);
    }
    for_each_image_path(&mut preset.scene, &mut relative);
    for mesh in &mut preset.scene.meshes {
        relative(&mut mesh.obj);
    }
    let config = ron::ser::PrettyConfig::new()
        .depth_limit(8)
        .struct_names(false)
        .indentor("    ".to_string());
    Ok(ron::ser::to_string_pretty(&preset, config)? + "\n")
}

/// Calls `f` on the path of every image texture in the scene.
fn for_each_image_path(scene: &mut Scene, f: &mut dyn FnMut(&mut PathBuf)) {
    for material in scene.materials_mut() {
        material.visit_textures_mut(&mut |t| {
            if let Some(image) = &mut t.image {
                f(&mut image.path);
            }
        });
    }
}

/// Saves atomically: a crash mid-save never destroys the previous file.
pub fn save(preset: &Preset, path: &Path) -> Result<(), PresetError> {
    let text = to_text(preset, path)?;
    write_atomic(path, text.as_bytes()).map_err(|cause| PresetError::Write {
        path: path.to_owned(),
        cause,
    })
}

/// An absolute path with `.` and `..` resolved lexically, so relative paths
/// written into presets stay short (`canonicalize` would need the file).
fn absolute(p: &Path) -> PathBuf {
    use std::path::Component;
    let abs = std::path::absolute(p).unwrap_or_else(|_| p.to_owned());
    let mut out = PathBuf::new();
    for c in abs.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir => {
                out.pop();
            }
            other => out.push(other),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::EnvSource;

    /// An empty file and a truncated one say so, naming the last field
    /// reached (not `…camera.?` and "Unexpected end of RON").
    #[test]
    fn an_empty_or_truncated_preset_says_so() {
        let path = Path::new("p.ron");
        assert_eq!(
            parse(" \n", path).unwrap_err().to_string(),
            "p.ron: the file is empty; a preset is a RON text such as presets/default.ron, \
             starting with `(`"
        );
        let whole = to_text(&Preset::default(), path).unwrap();
        let line = whole.find("yaw_degrees").unwrap();
        let cut = &whole[..line + whole[line..].find('\n').unwrap() + 1];
        let message = parse(cut, path).unwrap_err().to_string();
        assert!(
            message.contains("in field `scene.camera`: the file ends here"),
            "{message}"
        );
        assert!(!message.contains(".?"), "{message}");
    }

    /// `/dev/zero` as a preset grew marbre to 24 GB; a FIFO blocked it.
    #[test]
    fn a_device_or_fifo_preset_is_refused_naming_it() {
        use crate::capped_read::test_support::{make_fifo, within_10_s};
        let dir = tempfile::tempdir().unwrap();
        let fifo = dir.path().join("pipe.ron");
        make_fifo(&fifo);
        for path in [std::path::PathBuf::from("/dev/zero"), fifo] {
            let shown = path.display().to_string();
            let error = within_10_s(move || load(&path).unwrap_err().to_string());
            assert!(
                error.contains(&shown) && error.contains("not a regular file"),
                "{error}"
            );
        }
    }

    #[test]
    fn round_trips_the_default_scene() {
        let p = Preset::default();
        let text = to_text(&p, Path::new("x.ron")).unwrap();
        let back = parse(&text, Path::new("x.ron")).unwrap();
        assert_eq!(back.preset, p);
    }

    #[test]
    fn a_bad_field_names_its_line_column_and_path() {
        let text =
            "(\n  format_version: 1,\n  scene: (\n    camera: (distance: \"far\"),\n  ),\n)\n";
        let err = parse(text, Path::new("bad.ron")).unwrap_err().to_string();
        assert!(err.starts_with("bad.ron:4:"), "{err}");
        assert!(err.contains("scene.camera.distance"), "{err}");
    }

    #[test]
    fn a_truncated_file_is_an_error_with_a_position() {
        let text = to_text(&Preset::default(), Path::new("x.ron")).unwrap();
        let cut = &text[..text.len() / 2];
        let err = parse(cut, Path::new("cut.ron")).unwrap_err();
        assert!(
            matches!(err, PresetError::Syntax { line, .. } if line > 1),
            "{err}"
        );
    }

    #[test]
    fn missing_fields_take_their_defaults() {
        let loaded = parse("(scene: (spheres: [(radius: 2.0)]))", Path::new("old.ron")).unwrap();
        assert_eq!(loaded.preset.scene.spheres[0].radius, 2.0);
        assert_eq!(loaded.preset.scene.spheres[0].name, "sphere");
    }

    /// Massal's marble and the linear progression round-trip, and a noise
    /// written before the progression existed reads as the geometric one.
    #[test]
    fn massal_marble_round_trips_and_old_noise_reads_geometric() {
        use crate::noise::{NoiseSettings, Progression};
        use crate::scene::Pattern;
        let text = "(scene: (spheres: [(material: (diffuse: (pattern: Marble(\
                    noise: (kind: Perlin, fractal: (octaves: 6.0, lacunarity: 2.0)), \
                    stripe_frequency: 7.0))))]))";
        let old = parse(text, Path::new("old.ron")).unwrap();
        let noise = old.preset.scene.spheres[0]
            .material
            .diffuse
            .pattern
            .noise()
            .copied();
        assert_eq!(noise.unwrap().fractal.progression, Progression::Geometric);

        let mut p = Preset::default();
        p.scene.spheres.push(Default::default());
        p.scene.spheres[0].material.diffuse.pattern = Pattern::MassalMarble {
            noise: NoiseSettings::massal(0.05),
            stripe_frequency: 0.05,
        };
        let text = to_text(&p, Path::new("x.ron")).unwrap();
        assert!(text.contains("MassalMarble("), "{text}");
        assert!(text.contains("progression: Linear"), "{text}");
        let back = parse(&text, Path::new("x.ron")).unwrap();
        assert_eq!(back.preset, p);
        assert!(back.notes.is_empty(), "{:?}", back.notes);
    }

    #[test]
    fn saved_env_paths_are_short_and_relative() {
        let mut p = Preset::default();
        p.scene.environment.source = EnvSource::LatLong {
            path: PathBuf::from("/data/presets/../envmaps/sky.exr"),
        };
        let text = to_text(&p, Path::new("/data/other/x.ron")).unwrap();
        assert!(text.contains("\"../envmaps/sky.exr\""), "{text}");
    }

    /// A preset in `bad/` naming `../envmaps/x.exr` points at
    /// `envmaps/x.exr`, and every message about the file says so.
    #[test]
    fn loaded_paths_are_tidied_by_their_text() {
        let text = "(scene: (environment: (source: LatLong(path: \"../envmaps/./x.exr\"))))";
        let loaded = parse(text, Path::new("bad/x.ron")).unwrap();
        assert_eq!(
            loaded.preset.scene.environment.source.paths(),
            [Path::new("envmaps/x.exr")]
        );
    }

    #[test]
    fn a_future_version_is_refused() {
        let err = parse("(format_version: 99)", Path::new("new.ron")).unwrap_err();
        assert!(matches!(err, PresetError::FutureVersion { found: 99, .. }));
    }

    #[test]
    fn unknown_fields_are_skipped_with_a_note_at_any_depth() {
        let text = "(format_version: 2, colour_grading: 3, \
                    scene: (camera: (distance: 7.0, zoom: 2.0), spheres: [(radius: 2.0, glow: 1)]))";
        let loaded = parse(text, Path::new("extra.ron")).unwrap();
        assert_eq!(loaded.preset.scene.camera.distance, 7.0);
        assert_eq!(
            loaded.notes,
            [
                "extra.ron: unknown field `colour_grading` ignored (misspelt, or from a newer marbre)",
                "extra.ron: unknown field `scene.camera.zoom` ignored (misspelt, or from a newer marbre)",
                "extra.ron: unknown field `scene.spheres[0].glow` ignored (misspelt, or from a newer marbre)",
            ]
        );
    }

    #[test]
    fn out_of_range_values_are_clamped_with_a_note() {
        let loaded = parse(
            "(scene: (render: (samples_per_frame: 1000)))",
            Path::new("x.ron"),
        )
        .unwrap();
        assert_eq!(loaded.preset.scene.render.samples_per_frame, 64);
        assert_eq!(loaded.notes.len(), 1);
    }
}
