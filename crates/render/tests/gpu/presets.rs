//! The shipped presets (`presets/*.ron`) and the preset loader's errors.
//!
//! CPU-only, except `every_shipped_preset_renders_finite_and_not_black`,
//! which needs a GPU adapter and skips loudly without one (see
//! `marbre_render::gpu::testing`).

use crate::common::{presets_in, root};

use marbre_core::noise::{HashKind, NoiseKind, NoiseSettings};
use marbre_core::preset::{self, Preset, PresetError};
use marbre_core::scene::{EnvSource, Ground, Pattern, Scene, Sphere, Texture};
use marbre_core::texture::ImageSet;
use marbre_render::gpu::pipelines::validate;
use marbre_render::gpu::shader_source::{Program, assemble};
use marbre_render::gpu::testing::gpu_or_skip;
use marbre_render::gpu::texture_codegen::generate;
use marbre_render::gpu::{Feature, FeatureSet};
use marbre_render::session::{accumulate, load_scene, renderer_for};
use std::collections::BTreeSet;
use std::path::{Component, Path, PathBuf};

/// Every `presets/*.ron`.
fn shipped_presets() -> Vec<PathBuf> {
    presets_in("presets")
}

/// Every `presets/hard-cases/*.ron` (issue 6's adversarial scenes).
fn hard_case_presets() -> Vec<PathBuf> {
    presets_in("presets/hard-cases")
}

fn load(path: &Path) -> Preset {
    let loaded = preset::load(path).unwrap_or_else(|e| panic!("{e}"));
    assert!(
        loaded.notes.is_empty(),
        "{}: values clamped on load: {:?}",
        path.display(),
        loaded.notes
    );
    loaded.preset
}

/// The preset with its environment and image paths made absolute and their
/// `.` and `..` resolved (lexically: the folders a round trip passes through
/// need not exist), so two spellings of the same file (`presets/../envmaps/x.exr`,
/// `/tmp/x/../../work/main/envmaps/x.exr`) compare equal.
fn resolved(mut p: Preset) -> Preset {
    for path in p.scene.environment.source.paths_mut() {
        *path = existing_file(path);
    }
    for material in p.scene.materials_mut() {
        material.visit_textures_mut(&mut |t| {
            if let Some(image) = &mut t.image {
                image.path = existing_file(&image.path);
            }
        });
    }
    for mesh in &mut p.scene.meshes {
        mesh.obj = existing_file(&mesh.obj);
    }
    p
}

/// `path` made absolute with `.` and `..` resolved, checked to exist.
fn existing_file(path: &std::path::Path) -> PathBuf {
    let mut out = PathBuf::new();
    for c in std::path::absolute(path).unwrap().components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir => {
                out.pop();
            }
            c => out.push(c),
        }
    }
    assert!(
        out.is_file(),
        "{} (from {}) does not exist",
        out.display(),
        path.display()
    );
    out
}

fn bad(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/bad/presets")
        .join(name)
}

fn load_err(name: &str) -> (PresetError, String) {
    let path = bad(name);
    match preset::load(&path) {
        Ok(l) => panic!(
            "{} loaded, but it is broken: {:?}",
            path.display(),
            l.preset
        ),
        Err(e) => {
            let text = e.to_string();
            assert!(
                text.starts_with(&path.display().to_string()),
                "the message does not start with the file's path: {text}"
            );
            (e, text)
        }
    }
}

// ---------------------------------------------------------------------------
// Loading and round trips

#[test]
fn the_expected_presets_ship() {
    let names: BTreeSet<String> = shipped_presets()
        .iter()
        .map(|p| p.file_stem().unwrap().to_string_lossy().into_owned())
        .collect();
    for want in ["default", "marble", "rust", "turbulence", "planet"] {
        assert!(
            names.contains(want),
            "presets/{want}.ron is missing: {names:?}"
        );
    }
}

#[test]
fn every_shipped_preset_loads_without_notes() {
    for path in shipped_presets() {
        let p = load(&path);
        assert!(
            !p.description.is_empty(),
            "{}: no description",
            path.display()
        );
        assert!(
            !p.scene.spheres.is_empty() || !p.scene.meshes.is_empty(),
            "{}: neither spheres nor meshes",
            path.display()
        );
        // The environment map it names exists (load_scene would fail otherwise).
        if let EnvSource::LatLong { path: env } = &p.scene.environment.source {
            assert!(
                env.is_file(),
                "{}: {} does not exist",
                path.display(),
                env.display()
            );
        }
    }
}

/// Issue 20's list of features a user should find in a shipped preset
/// without building them: the lab's fract(sin) hash, a colour ramp, a
/// layer, a cube map, a mirror sphere and a coloured shadow (a see-through
/// surface with a tinted transmission).
#[test]
fn the_shipped_presets_show_every_feature() {
    let presets: Vec<Preset> = shipped_presets().iter().map(|p| load(p)).collect();
    let materials = || {
        presets
            .iter()
            .flat_map(|p| p.scene.materials().cloned().collect::<Vec<_>>())
    };
    let lab_hash = materials().any(|m| {
        m.patterns()
            .iter()
            .any(|p| p.noise().is_some_and(|n| n.hash == HashKind::Sin))
    });
    let ramp = materials().any(|m| m.all_textures().iter().any(|t| t.has_ramp()));
    let layers = materials().any(|m| !m.layers.is_empty());
    let cube_map = presets.iter().any(|p| {
        matches!(
            p.scene.environment.source,
            EnvSource::CubeCross { .. } | EnvSource::CubeFaces { .. }
        )
    });
    let mirror_sphere = presets.iter().any(|p| {
        p.scene
            .spheres
            .iter()
            .any(|s| s.material.mirror == Texture::scalar(1.0))
    });
    let coloured_shadow = materials().any(|m| {
        m.opacity.eval(glam::Vec3::ZERO, glam::Vec2::ZERO).x < 0.5
            && m.transmission != Texture::color(glam::Vec3::ONE)
    });
    assert!(lab_hash, "no shipped preset uses the lab's fract(sin) hash");
    assert!(ramp, "no shipped preset has a colour ramp");
    assert!(layers, "no shipped preset has a layered material");
    assert!(cube_map, "no shipped preset lights by a cube map");
    assert!(mirror_sphere, "no shipped preset has a mirror sphere");
    assert!(coloured_shadow, "no shipped preset casts a coloured shadow");
}

#[test]
fn every_shipped_preset_starts_with_a_comment_header() {
    for path in shipped_presets() {
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(
            text.starts_with("//"),
            "{}: no comment header",
            path.display()
        );
    }
}

#[test]
fn the_single_material_presets_use_distinct_environment_maps() {
    let mut seen = BTreeSet::new();
    for name in ["marble", "rust", "turbulence", "planet"] {
        let p = load(&root().join(format!("presets/{name}.ron")));
        let s = &p.scene;
        assert_eq!(s.spheres.len(), 1, "{name}: one sphere");
        assert_eq!(s.spheres[0].name, name);
        assert_eq!(
            s.spheres[0].center,
            glam::Vec3::new(0.0, 1.0, 0.0),
            "{name}"
        );
        assert_eq!(s.spheres[0].radius, 1.0, "{name}");
        assert_eq!(s.camera.target, glam::Vec3::new(0.0, 1.0, 0.0), "{name}");
        assert!(s.ground.is_some(), "{name}: a ground plane");
        assert!(s.point_light.is_some(), "{name}: a point light");
        let EnvSource::LatLong { path } = &s.environment.source else {
            panic!("{name}: not under an environment map");
        };
        let file = path.file_name().unwrap().to_string_lossy().into_owned();
        assert!(seen.insert(file.clone()), "{name}: {file} is used twice");
    }
}

#[test]
fn every_shipped_preset_round_trips_through_to_text() {
    for path in shipped_presets() {
        let original = load(&path);
        // Saved in place, and saved into another folder: the relative
        // environment path is rewritten, but names the same file.
        let elsewhere = std::env::temp_dir().join("marbre-presets-test/sub/copy.ron");
        for target in [path.clone(), elsewhere] {
            let text = preset::to_text(&original, &target).unwrap();
            let back = preset::parse(&text, &target).unwrap_or_else(|e| {
                panic!(
                    "{} re-read as {}: {e}\n{text}",
                    path.display(),
                    target.display()
                )
            });
            assert!(
                back.notes.is_empty(),
                "{}: {:?}",
                path.display(),
                back.notes
            );
            assert_eq!(
                resolved(back.preset),
                resolved(original.clone()),
                "{} changed in a round trip via {}",
                path.display(),
                target.display()
            );
        }
    }
}

#[test]
fn to_text_writes_the_environment_path_relative_to_the_preset() {
    for path in shipped_presets() {
        let original = load(&path);
        let text = preset::to_text(&original, &path).unwrap();
        if let EnvSource::LatLong { path: env } = &original.scene.environment.source {
            let name = env.file_name().unwrap().to_string_lossy();
            assert!(
                text.contains(&format!("\"../envmaps/{name}\"")),
                "{}: the saved text does not name ../envmaps/{name}:\n{text}",
                path.display()
            );
        }
    }
}

// ---------------------------------------------------------------------------
// Shader specialisation

/// Every program assembles and validates with naga for `features`, the
/// trace program with the texture code generated from `scene`.
fn assert_validates(features: &FeatureSet, scene: &Scene, what: &str) {
    let images = marbre_render::session::load_images(scene, &mut Vec::new()).unwrap();
    let textures = generate(scene, &images).unwrap();
    for program in [Program::Trace, Program::Display] {
        let source = assemble(program, features, &textures.wgsl)
            .unwrap_or_else(|e| panic!("{what}: {program:?} does not assemble: {e}"));
        if let Err(e) = validate(&source) {
            panic!(
                "{what}: {program:?} with {:?} is invalid WGSL:\n{e}",
                features.0
            );
        }
    }
}

#[test]
fn every_shipped_preset_specialisation_validates() {
    for path in shipped_presets() {
        let p = load(&path);
        let features = FeatureSet::for_scene(&p.scene);
        assert_validates(&features, &p.scene, &path.display().to_string());
    }
}

#[test]
fn the_uber_shader_validates() {
    assert_validates(&FeatureSet::all(), &Scene::default(), "the uber shader");
    for path in shipped_presets() {
        let p = load(&path);
        assert_validates(&FeatureSet::all(), &p.scene, &path.display().to_string());
    }
}

#[test]
fn the_empty_feature_set_validates() {
    assert_validates(
        &FeatureSet::default(),
        &Scene::default(),
        "the empty feature set",
    );
}

#[test]
fn every_single_feature_set_validates() {
    for f in Feature::all() {
        let set = FeatureSet([f].into_iter().collect());
        assert_validates(&set, &Scene::default(), &format!("{{{f:?}}}"));
    }
}

fn trace_source(scene: &Scene) -> String {
    let textures = generate(scene, &ImageSet::empty()).unwrap();
    assemble(
        Program::Trace,
        &FeatureSet::for_scene(scene),
        &textures.wgsl,
    )
    .unwrap()
}

fn noise(kind: NoiseKind) -> NoiseSettings {
    NoiseSettings {
        kind,
        hash: HashKind::Pcg,
        ..Default::default()
    }
}

/// A marble sphere on a ground plane, its noise of the given kind.
fn marble_scene(kind: NoiseKind) -> Scene {
    let mut sphere = Sphere::default();
    sphere.material.diffuse = Texture {
        pattern: Pattern::Marble {
            noise: noise(kind),
            stripe_frequency: 4.0,
        },
        ..Default::default()
    };
    Scene {
        spheres: vec![sphere],
        ground: Some(Ground::default()),
        ..Default::default()
    }
}

#[test]
fn specialisation_removes_code() {
    let uber = assemble(
        Program::Trace,
        &FeatureSet::all(),
        &generate(&Scene::default(), &ImageSet::empty())
            .unwrap()
            .wgsl,
    )
    .unwrap();
    assert!(
        uber.contains("fn perlin_noise"),
        "the uber shader has Perlin noise"
    );

    let default = load(&root().join("presets/default.ron"));
    let default_src = trace_source(&default.scene);
    assert!(
        default_src.len() < uber.len(),
        "the default preset's trace shader ({} bytes) is not shorter than the uber shader ({} bytes)",
        default_src.len(),
        uber.len()
    );

    // Without Perlin noise anywhere, none of its code is compiled in.
    let gradient = marble_scene(NoiseKind::Gradient);
    assert!(!FeatureSet::for_scene(&gradient).contains(Feature::NoisePerlin));
    let gradient_src = trace_source(&gradient);
    validate(&gradient_src).unwrap();
    assert!(
        !gradient_src.contains("perlin_noise"),
        "a scene without Perlin noise still has perlin_noise in its shader"
    );
    assert!(gradient_src.len() < uber.len());

    // The control: the same scene with Perlin noise has it.
    let perlin_src = trace_source(&marble_scene(NoiseKind::Perlin));
    validate(&perlin_src).unwrap();
    assert!(perlin_src.contains("fn perlin_noise"));

    // A shipped preset without Perlin noise (rust uses gradient noise only).
    let rust = load(&root().join("presets/rust.ron"));
    assert!(!FeatureSet::for_scene(&rust.scene).contains(Feature::NoisePerlin));
    assert!(!trace_source(&rust.scene).contains("perlin_noise"));
}

/// Each texture pattern's WGSL is in the trace shader only when the scene
/// uses that pattern.
#[test]
fn unused_patterns_leave_no_code() {
    let plain = load(&root().join("presets/rust.ron"));
    let plain_src = trace_source(&plain.scene);
    let bricks = load(&root().join("presets/brick_wood.ron"));
    let bricks_src = trace_source(&bricks.scene);
    for function in [
        "fn brick(",
        "fn wood_rings(",
        "fn checker_2d(",
        "fn cutout(",
    ] {
        assert!(!plain_src.contains(function), "rust has {function}");
    }
    for function in ["fn brick(", "fn wood_rings("] {
        assert!(bricks_src.contains(function), "brick_wood lacks {function}");
    }
    assert!(!bricks_src.contains("fn cutout("));
    // Only a pattern that reads (u, v) makes the hit compute it.
    assert!(!plain_src.contains("sphere_uv(dir)"));
    assert!(bricks_src.contains("sphere_uv(dir)"));
    // Only a scene with holes traces shadow rays through surfaces.
    let holes = load(&root().join("presets/cutouts.ron"));
    assert!(trace_source(&holes.scene).contains("fn transmittance("));
    assert!(!bricks_src.contains("fn transmittance("));
}

// ---------------------------------------------------------------------------
// Broken files

#[test]
fn a_truncated_preset_names_the_file_and_the_end() {
    let (e, text) = load_err("truncated.ron");
    // The file is 14 lines and stops after `(0.5, 0.5,` on the last one.
    assert!(
        matches!(
            e,
            PresetError::Syntax {
                line: 14,
                column: 62,
                ..
            }
        ),
        "{text}"
    );
    // Column 62 is the last character of the 62-character line.
    assert!(text.contains("truncated.ron:14:62: "), "{text}");
    assert!(
        text.contains("scene.spheres[0].material.diffuse.a[2]"),
        "{text}"
    );
}

#[test]
fn a_field_of_the_wrong_type_names_its_path_and_line() {
    let (e, text) = load_err("bad_field.ron");
    assert!(matches!(e, PresetError::Syntax { line: 10, .. }), "{text}");
    // RON's span starts at the blank before `"big"` (column 25).
    assert!(text.contains("bad_field.ron:10:24: "), "{text}");
    assert!(text.contains("scene.spheres[0].radius"), "{text}");
}

#[test]
fn an_unknown_pattern_names_its_path_and_line() {
    let (e, text) = load_err("unknown_variant.ron");
    assert!(matches!(e, PresetError::Syntax { line: 10, .. }), "{text}");
    // RON's span starts at the blank before `Plaid` (column 41).
    assert!(text.contains("unknown_variant.ron:10:40: "), "{text}");
    assert!(
        text.contains("scene.spheres[0].material.diffuse.pattern"),
        "{text}"
    );
    assert!(text.contains("Plaid"), "{text}");
}

#[test]
fn a_future_version_is_refused_by_name() {
    let (e, text) = load_err("future_version.ron");
    assert!(
        matches!(e, PresetError::FutureVersion { found: 99, .. }),
        "{text}"
    );
    assert!(text.contains("99"), "{text}");
}

#[test]
fn a_file_that_is_not_utf8_is_refused_with_the_offset() {
    let (e, text) = load_err("not_utf8.ron");
    // The first bad byte, 0xe9, is at offset 113.
    assert!(
        matches!(e, PresetError::NotText { offset: 113, .. }),
        "{text}"
    );
    assert!(text.contains("not UTF-8"), "{text}");
}

// ---------------------------------------------------------------------------
// GPU

#[test]
fn every_shipped_preset_renders_finite_and_not_black() {
    let Some(ctx) = gpu_or_skip("every_shipped_preset_renders_finite_and_not_black") else {
        return;
    };
    let size = (96, 54);
    let spp = 4;
    let mut report = Vec::new();
    for path in shipped_presets() {
        let loaded =
            load_scene(&path, None).unwrap_or_else(|e| panic!("{}: {e:#}", path.display()));
        let mut renderer = renderer_for(&ctx, &loaded, size)
            .unwrap_or_else(|e| panic!("{}: {e:#}", path.display()));
        accumulate(&ctx, &mut renderer, spp, |_| {}).unwrap();
        assert!(renderer.accumulated_samples() >= spp);
        let (w, h, pixels) = renderer.read_radiance(&ctx).unwrap();
        assert_eq!((w, h), size, "{}", path.display());
        assert_eq!(pixels.len(), (w * h) as usize, "{}", path.display());
        let dropped = renderer.count_non_finite(&ctx).unwrap();
        assert!(
            dropped.is_zero(),
            "{}: the trace pass dropped non-finite samples: {dropped:?}",
            path.display()
        );
        let non_finite: Vec<_> = pixels
            .iter()
            .enumerate()
            .filter(|(_, px)| !px.iter().all(|c| c.is_finite()))
            .take(5)
            .map(|(i, px)| (i as u32 % w, i as u32 / w, px.map(f32::to_bits)))
            .collect();
        assert!(
            non_finite.is_empty(),
            "{}: non-finite radiance at (x, y, bits) {non_finite:x?}",
            path.display()
        );
        let mean = pixels
            .iter()
            .map(|p| f64::from(0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]))
            .sum::<f64>()
            / pixels.len() as f64;
        report.push(format!("{}: mean luminance {mean:.4}", path.display()));
        assert!(
            mean > 0.01,
            "{}: the render is black (mean luminance {mean})",
            path.display()
        );
    }
    eprintln!(
        "{} ({}x{}, {spp} spp):\n{}",
        ctx.describe(),
        size.0,
        size.1,
        report.join("\n")
    );
}

/// The hard cases load (some on purpose with values the loader clamps, and
/// says so) and render without a single non-finite sample: the counters,
/// not the image, prove it, since the trace pass drops such samples.
#[test]
fn every_hard_case_preset_renders_without_a_non_finite_sample() {
    let Some(ctx) = gpu_or_skip("every_hard_case_preset_renders_without_a_non_finite_sample")
    else {
        return;
    };
    let presets = hard_case_presets();
    assert!(
        presets.len() >= 12,
        "one preset per case at least: {presets:?}"
    );
    for path in presets {
        let loaded =
            load_scene(&path, None).unwrap_or_else(|e| panic!("{}: {e:#}", path.display()));
        let mut renderer = renderer_for(&ctx, &loaded, (48, 32))
            .unwrap_or_else(|e| panic!("{}: {e:#}", path.display()));
        accumulate(&ctx, &mut renderer, 4, |_| {}).unwrap();
        let dropped = renderer.count_non_finite(&ctx).unwrap();
        assert!(
            dropped.is_zero(),
            "{}: the trace pass dropped non-finite samples: {dropped:?}",
            path.display()
        );
        let (_, _, pixels) = renderer.read_radiance(&ctx).unwrap();
        assert!(
            pixels.iter().all(|p| p.iter().all(|c| c.is_finite())),
            "{}: a non-finite pixel",
            path.display()
        );
    }
}
