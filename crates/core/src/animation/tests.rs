use super::*;
use crate::preset::{self, Preset, PresetError};
use crate::scene::{Change, Scene};
use std::path::{Path, PathBuf};

/// The presets (`.ron`) in `folder` of the repository's `presets/`.
fn presets_in(folder: &str) -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../presets")
        .join(folder);
    let mut files: Vec<PathBuf> = std::fs::read_dir(&root)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "ron"))
        .collect();
    files.sort();
    files
}

fn shipped_presets() -> Vec<PathBuf> {
    let files = presets_in("");
    assert!(files.len() >= 10, "{files:?}");
    files
}

/// A value unlike `value`: each component moved (an integer by 1).
fn moved(value: &[f32]) -> Vec<f32> {
    value.iter().map(|v| v + 1.0).collect()
}

/// Every number a shipped preset holds (but names and layout) can be
/// keyed: its path reads back its value, and a track on it written to a
/// preset, read again and traced at the second key's time sets it.
#[test]
fn every_animatable_path_resolves_and_round_trips_through_a_preset() {
    for file in shipped_presets() {
        let scene = preset::load(&file).unwrap().preset.scene;
        let params = scene.animatable_parameters();
        assert!(
            params.len() > 10,
            "{}: {} parameters",
            file.display(),
            params.len()
        );
        let mut animation = Animation {
            duration: 2.0,
            ..Animation::default()
        };
        for (path, value) in &params {
            assert_eq!(
                scene.parameter(path).as_ref(),
                Ok(value),
                "{}: {path}",
                file.display()
            );
            animation.insert_key(path, 0.0, value);
            animation.insert_key(path, 1.0, &moved(value));
        }
        let keyed = Scene {
            animation: Some(animation),
            ..scene.clone()
        };
        let text = preset::to_text(
            &Preset {
                scene: keyed.clone(),
                ..Preset::default()
            },
            &file,
        )
        .unwrap();
        let back = preset::parse(&text, &file).unwrap().preset.scene;
        assert_eq!(back.animation, keyed.animation, "{}", file.display());
        let start = back.at_time(0.0);
        let end = back.at_time(1.0);
        for (path, value) in &params {
            assert_eq!(start.parameter(path).as_ref(), Ok(value), "{path} at 0");
            assert_eq!(
                end.parameter(path).unwrap(),
                moved(value),
                "{}: {path} at 1",
                file.display()
            );
        }
    }
}

/// The panel's and the CLI's names for common parameters.
#[test]
fn parameters_are_named_as_the_preset_writes_them() {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../presets/default.ron");
    let scene = preset::load(&file).unwrap().preset.scene;
    let names: Vec<String> = scene
        .animatable_parameters()
        .iter()
        .map(|(p, _)| p.to_string())
        .collect();
    for expected in [
        "camera.fov_degrees",
        "camera.target",
        "spheres[\"marble\"].radius",
        "spheres[\"marble\"].material.diffuse.pattern.noise.fractal.frequency",
        "spheres[\"marble\"].material.diffuse.pattern.stripe_frequency",
        "spheres[\"marble\"].material.diffuse.ramp[1].position",
        "spheres[\"marble\"].material.diffuse.a",
        "environment.intensity",
        "render.exposure",
    ] {
        assert!(
            names.iter().any(|n| n == expected),
            "{expected} not in {names:#?}"
        );
    }
    let path =
        ParamPath::parse("spheres[\"marble\"].material.diffuse.pattern.noise.fractal.octaves")
            .unwrap();
    assert_eq!(scene.parameter(&path), Ok(vec![6.0]));
    let by_index = ParamPath::parse("spheres[0].radius").unwrap();
    assert_eq!(scene.parameter(&by_index), Ok(vec![0.9]));
}

/// A constant property, which a preset writes as its value
/// (`roughness: 0.15`), is named by its `a` as the panel's key button names
/// it: the CLI lists that name, a key on it writes the short form back,
/// and the same path keeps naming `a` once the property is a pattern.
/// `a` is no field of a plain vector.
#[test]
fn a_constant_written_as_its_value_is_named_by_its_a() {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../presets/default.ron");
    let mut scene = preset::load(&file).unwrap().preset.scene;
    let roughness = ParamPath::parse("spheres[\"marble\"].material.roughness.a").unwrap();
    assert_eq!(scene.parameter(&roughness), Ok(vec![0.15]));
    assert!(
        scene
            .animatable_parameters()
            .iter()
            .any(|(p, v)| *p == roughness && *v == [0.15]),
        "{roughness} is not listed"
    );
    scene.set_parameter(&roughness, &[0.25]).unwrap();
    let material = &scene.spheres[0].material;
    assert_eq!(
        material.roughness.as_constant(),
        Some(&crate::scene::Child::Scalar(0.25))
    );
    let written = ron::to_string(material).unwrap();
    assert!(written.contains("roughness:0.25"), "{written}");
    let specular = ParamPath::parse("spheres[0].material.specular.a").unwrap();
    assert_eq!(scene.parameter(&specular), Ok(vec![0.05; 3]));
    scene.spheres[0].material.roughness =
        crate::scene::Texture::blend(crate::scene::Pattern::Checker { size: 1.0 }, 0.5, 0.75);
    assert_eq!(scene.parameter(&roughness), Ok(vec![0.5]));
    let b = ParamPath::parse("spheres[\"marble\"].material.roughness.b").unwrap();
    assert_eq!(scene.parameter(&b), Ok(vec![0.75]));
    let not_a_texture = ParamPath::parse("camera.target.a").unwrap();
    assert!(scene.parameter(&not_a_texture).is_err());
}

/// The panel names a number by index (`spheres[0]`), the CLI and saved
/// tracks by name (`spheres["marble"]`): a key from the panel lands on the
/// track of the same number whichever way that track names it, a new
/// track is named by name, and both names translate into each other.
/// A path naming no number gets no key.
#[test]
fn a_key_finds_its_track_by_index_or_by_name() {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../presets/default.ron");
    let mut scene = preset::load(&file).unwrap().preset.scene;
    let by_index = ParamPath::parse("spheres[0].material.diffuse.ramp[1].position").unwrap();
    let by_name =
        ParamPath::parse("spheres[\"marble\"].material.diffuse.ramp[1].position").unwrap();
    assert_eq!(
        scene.parameter_name(&by_index, Naming::Names),
        Ok(by_name.clone())
    );
    assert_eq!(
        scene.parameter_name(&by_name, Naming::Indices),
        Ok(by_index.clone())
    );
    scene.insert_key(&by_index, 0.0, &[0.2]).unwrap();
    scene.insert_key(&by_name, 1.0, &[0.8]).unwrap();
    let tracks = &scene.animation.as_ref().unwrap().tracks;
    assert_eq!(tracks.len(), 1, "{tracks:?}");
    assert_eq!(tracks[0].path, by_name.to_string());
    assert_eq!(tracks[0].keys.len(), 2);
    // A track a person wrote by index keeps its name and gets the key.
    scene.animation.as_mut().unwrap().tracks[0].path = by_index.to_string();
    scene.insert_key(&by_name, 2.0, &[0.5]).unwrap();
    let tracks = &scene.animation.as_ref().unwrap().tracks;
    assert_eq!(tracks.len(), 1, "{tracks:?}");
    assert_eq!(tracks[0].path, by_index.to_string());
    assert_eq!(tracks[0].keys.len(), 3);
    let nowhere = ParamPath::parse("spheres[\"ghost\"].radius").unwrap();
    let e = scene.insert_key(&nowhere, 0.0, &[1.0]).unwrap_err();
    assert!(e.contains("ghost"), "{e}");
    assert_eq!(scene.animation.as_ref().unwrap().tracks.len(), 1);
}

fn keyed(path: &str, keys: &[(f32, f32)]) -> Scene {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../presets/default.ron");
    let mut scene = preset::load(&file).unwrap().preset.scene;
    let mut animation = Animation::default();
    for &(t, v) in keys {
        animation.insert_key(&ParamPath::parse(path).unwrap(), t, &[v]);
    }
    scene.animation = Some(animation);
    scene
}

/// A keyed noise number changes the traced scene's parameters only (no
/// code is generated again); a keyed camera moves the camera only; the
/// keys themselves are an animation edit.
#[test]
fn moments_of_a_scene_differ_in_numbers_only() {
    let noise = keyed(
        "spheres[\"marble\"].material.diffuse.pattern.noise.fractal.frequency",
        &[(0.0, 1.0), (2.0, 3.0)],
    );
    assert_eq!(
        noise.at_time(1.5).changes_from(&noise.at_time(0.5)),
        Change::MATERIAL_PARAMETERS
    );
    let camera = keyed("camera.yaw_degrees", &[(0.0, 0.0), (4.0, 360.0)]);
    assert_eq!(
        camera.at_time(1.0).changes_from(&camera.at_time(0.0)),
        Change::CAMERA
    );
    // Smooth: a quarter of the way in time is 0.156 25 of the turn.
    assert_eq!(camera.at_time(1.0).camera.yaw_degrees, 360.0 * 0.156_25);
    let mut edited = camera.clone();
    edited.animation.as_mut().unwrap().insert_key(
        &ParamPath::parse("camera.yaw_degrees").unwrap(),
        1.0,
        &[10.0],
    );
    assert_eq!(edited.changes_from(&camera), Change::ANIMATION);
}

fn parse_error(animation: &str) -> String {
    let text = format!(
        "(format_version: 2, scene: (spheres: [(name: \"ball\", center: (0.0, 1.0, 0.0), radius: 1.0)], animation: Some({animation})))"
    );
    match preset::parse(&text, Path::new("bad.ron")) {
        Err(e @ PresetError::Animation { .. }) => e.to_string(),
        other => panic!("{animation}: {other:?}"),
    }
}

/// Each bad animation is refused naming the file, the field and why.
#[test]
fn bad_animations_are_refused_naming_the_field() {
    for (animation, expected) in [
        (
            "(tracks: [(path: \"spheres[\\\"bal\\\"].radius\", keys: [(time: 0.0, value: 1.0)])])",
            "animation.tracks[0] (`spheres[\"bal\"].radius`): no sphere named \"bal\" (the scene's spheres: ball)",
        ),
        (
            "(tracks: [(path: \"spheres[0].radius\", keys: [(time: 1.0, value: 1.0), (time: 1.0, value: 2.0)])])",
            "keys[1].time: 1 does not come after the key before it (1)",
        ),
        (
            "(tracks: [(path: \"spheres[0].radius\", keys: [(time: 0.0, value: NaN)])])",
            "keys[0].value: NaN is not a finite number",
        ),
        (
            "(tracks: [(path: \"spheres[0].center\", keys: [(time: 0.0, value: 1.0)])])",
            "keys[0].value: 1 component(s) for a parameter of 3",
        ),
        (
            "(tracks: [(path: \"spheres[0].colour\", keys: [(time: 0.0, value: 1.0)])])",
            "no field `colour` here",
        ),
        ("(fps: 0.0)", "animation.fps: 0 is not a frame rate"),
        ("(duration: 0.0)", "animation.duration: 0 is not a length"),
    ] {
        let message = parse_error(animation);
        assert!(message.starts_with("bad.ron: "), "{message}");
        assert!(
            message.contains(expected),
            "{message}\nexpected: {expected}"
        );
    }
}

/// A preset without an animation writes none, and one written reads back
/// equal, its keys' interpolation and extrapolation included.
#[test]
fn presets_without_an_animation_read_and_write_as_before() {
    let text = preset::to_text(&Preset::default(), Path::new("a.ron")).unwrap();
    assert!(!text.contains("animation"), "{text}");
    let mut scene = keyed("camera.distance", &[(0.0, 5.0), (1.0, 6.0)]);
    let animation = scene.animation.as_mut().unwrap();
    animation.looping = true;
    animation.tracks[0].extrapolation = Extrapolation::Cycle;
    animation.tracks[0].keys[0].interpolation = Interpolation::Constant;
    animation.insert_key(
        &ParamPath::parse("camera.target").unwrap(),
        0.5,
        &[1.0, 2.0, 3.0],
    );
    let text = preset::to_text(
        &Preset {
            scene: scene.clone(),
            ..Preset::default()
        },
        Path::new("a.ron"),
    )
    .unwrap();
    assert!(text.contains("loop: true"), "{text}");
    let back = preset::parse(&text, Path::new("a.ron"))
        .unwrap()
        .preset
        .scene;
    assert_eq!(back.animation, scene.animation);
}

fn shipped_animations() -> Vec<PathBuf> {
    let files = presets_in("animated");
    assert_eq!(files.len(), 4, "{files:?}");
    files
}

/// The shipped animations load with nothing to note, move, and those that
/// loop meet their first frame at their end: the lava's evolving colour
/// bit for bit at points all over the sphere, the turntable's camera to
/// rounding (yaw 380° is 20°).
#[test]
fn shipped_animations_move_and_loops_meet_themselves() {
    for file in shipped_animations() {
        let loaded = preset::load(&file).unwrap_or_else(|e| panic!("{e}"));
        assert!(
            loaded.notes.is_empty(),
            "{}: {:?}",
            file.display(),
            loaded.notes
        );
        let scene = loaded.preset.scene;
        let animation = scene.animation.clone().expect("an animation");
        assert!(animation.problems(&scene).is_empty());
        assert!(scene.moves(), "{}", file.display());
        let (first, last) = (scene.at_time(0.0), scene.at_time(animation.duration));
        let half = scene.at_time(animation.duration / 2.0);
        let name = file.file_stem().unwrap().to_string_lossy().into_owned();
        let colour =
            |s: &Scene, p: glam::Vec3| s.spheres[0].material.diffuse.eval(p, glam::Vec2::ZERO);
        let points: Vec<glam::Vec3> = (0..64)
            .map(|i| {
                let a = i as f32 * 0.7;
                glam::Vec3::new(a.cos(), (i as f32 / 32.0) - 1.0, a.sin())
            })
            .collect();
        match name.as_str() {
            "lava_loop" => {
                for &p in &points {
                    assert_eq!(colour(&first, p), colour(&last, p), "{name} at {p}");
                }
                assert!(
                    points
                        .iter()
                        .any(|&p| colour(&first, p) != colour(&half, p))
                );
            }
            "studio_turntable" => {
                let (a, b) = (first.camera.frame(), last.camera.frame());
                assert!(a.position.distance(b.position) < 1e-4, "{a:?} {b:?}");
                assert!(
                    first
                        .camera
                        .frame()
                        .position
                        .distance(half.camera.frame().position)
                        > 1.0
                );
            }
            _ => assert!(first != half, "{name}: half way is the first frame"),
        }
    }
}
