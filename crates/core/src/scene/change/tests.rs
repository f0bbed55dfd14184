//! One test per class of edit, on the default preset as the panel edits
//! it: each names the class it expects by hand, not by calling the code it
//! checks.

use super::*;
use crate::scene::Pattern;
use glam::Vec3;
use std::path::Path;

fn default_scene() -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../presets/default.ron");
    crate::preset::load(&path).unwrap().preset.scene
}

/// The scene after `edit`, and what changed.
fn edited(edit: impl FnOnce(&mut Scene)) -> Change {
    let old = default_scene();
    let mut new = old.clone();
    edit(&mut new);
    new.changes_from(&old)
}

/// The first noise pattern of the scene's first material that has one.
fn first_noise(scene: &mut Scene, edit: impl FnOnce(&mut crate::noise::NoiseSettings)) {
    let mut edit = Some(edit);
    for material in scene.materials_mut() {
        material.visit_textures_mut(&mut |t| {
            if let Some(noise) = t.pattern.noise_mut()
                && let Some(edit) = edit.take()
            {
                edit(noise);
            }
        });
    }
    assert!(edit.is_none(), "the default preset has a noise pattern");
}

#[test]
fn the_same_scene_changed_nothing() {
    assert_eq!(edited(|_| {}), Change::empty());
}

/// The projection is the camera's: switching to orthographic restarts
/// the image through the frame uniform, no new shader.
#[test]
fn a_projection_switch_is_a_camera_change_without_new_code() {
    let change = edited(|s| s.camera.projection = crate::scene::Projection::Orthographic);
    assert_eq!(change, Change::CAMERA);
    assert!(change.resets_accumulation());
    assert!(!change.regenerates_code());
}

#[test]
fn a_camera_move_resets_the_image_but_is_no_edit() {
    let change = edited(|s| s.camera.yaw_degrees += 10.0);
    assert_eq!(change, Change::CAMERA);
    assert!(change.resets_accumulation());
    assert!(!change.edits_document());
    assert!(!change.regenerates_code());
}

#[test]
fn an_exposure_edit_keeps_the_samples() {
    let change = edited(|s| s.render.display.exposure += 1.0);
    assert_eq!(change, Change::DISPLAY);
    assert!(!change.resets_accumulation());
    assert!(change.edits_document());
}

#[test]
fn an_octave_drag_is_a_parameter_edit() {
    let change = edited(|s| first_noise(s, |n| n.fractal.octaves += 0.35));
    assert_eq!(change, Change::MATERIAL_PARAMETERS);
    assert!(change.resets_accumulation());
    assert!(!change.regenerates_code());
}

/// Turning a noise's evolution on or off changes its code (the 4D sum);
/// its w, speed, drift and the moment traced are numbers.
#[test]
fn evolving_noise_is_structure_and_its_moment_a_parameter() {
    use crate::noise::Evolution;
    let on = edited(|s| first_noise(s, |n| n.evolution = Some(Evolution::default())));
    assert_eq!(on, Change::MATERIAL_STRUCTURE);
    let evolving = |edit: fn(&mut Evolution)| {
        let mut old = default_scene();
        first_noise(&mut old, |n| n.evolution = Some(Evolution::default()));
        let mut new = old.clone();
        first_noise(&mut new, |n| edit(n.evolution.as_mut().expect("evolving")));
        new.changes_from(&old)
    };
    let edits: [fn(&mut Evolution); 5] = [
        |e| e.at(1.5, None),
        |e| e.at(0.5, Some(2.0)),
        |e| e.w += 0.25,
        |e| e.speed = 2.0,
        |e| e.drift = Vec3::X,
    ];
    for edit in edits {
        let change = evolving(edit);
        assert_eq!(change, Change::MATERIAL_PARAMETERS);
        assert!(!change.regenerates_code());
    }
}

#[test]
fn a_colour_is_a_parameter_edit() {
    let change = edited(|s| {
        let m = s.spheres[0].material.clone();
        s.spheres[0].material.specular = Texture::color(Vec3::new(0.2, 0.1, 0.05));
        assert!(
            m.specular.as_constant().is_some(),
            "the first sphere's specular is a constant in the preset"
        );
    });
    assert_eq!(change, Change::MATERIAL_PARAMETERS);
}

#[test]
fn another_pattern_kind_regenerates_the_code() {
    let change = edited(|s| {
        s.spheres[0].material.specular =
            Texture::blend(Pattern::Checker { size: 0.5 }, Vec3::ZERO, Vec3::ONE)
    });
    assert_eq!(change, Change::MATERIAL_STRUCTURE);
    assert!(change.regenerates_code());
}

/// Two fBm textures with the same noise share one fractal sum in the
/// generated code; made different, each reads its own: a number that
/// changes the code's shape.
#[test]
fn parting_two_shared_noise_sums_regenerates_the_code() {
    let fbm = |frequency: f32| {
        let mut noise = crate::noise::NoiseSettings::default();
        noise.fractal.frequency = frequency;
        Texture::blend(Pattern::Fbm { noise }, Vec3::ZERO, Vec3::ONE)
    };
    let mut old = Scene::default();
    old.spheres.push(Sphere::default());
    old.spheres[0].material.diffuse = fbm(2.0);
    old.spheres[0].material.specular = fbm(2.0);
    let mut new = old.clone();
    new.spheres[0].material.specular = fbm(3.0);
    assert_eq!(new.changes_from(&old), Change::MATERIAL_STRUCTURE);
    // Both moved alike, they still share one sum: parameters alone.
    new.spheres[0].material.diffuse = fbm(3.0);
    assert_eq!(new.changes_from(&old), Change::MATERIAL_PARAMETERS);
}

#[test]
fn a_moved_sphere_is_geometry_alone() {
    assert_eq!(edited(|s| s.spheres[0].center.x += 0.5), Change::GEOMETRY);
}

#[test]
fn an_added_sphere_adds_geometry_and_a_material() {
    let change = edited(|s| s.spheres.push(Sphere::default()));
    assert!(change.contains(Change::GEOMETRY | Change::MATERIAL_STRUCTURE));
    assert!(change.regenerates_code());
}

#[test]
fn a_name_or_a_saved_view_is_saved_but_not_traced() {
    for change in [
        edited(|s| s.spheres[0].name.push('!')),
        edited(Scene::save_view),
    ] {
        assert_eq!(change, Change::ANNOTATIONS);
        assert!(!change.resets_accumulation());
        assert!(change.edits_document());
    }
}

#[test]
fn lights_environment_and_render_settings_have_their_classes() {
    assert_eq!(
        edited(|s| s.point_light = None),
        Change::LIGHTS,
        "the default preset has a point light"
    );
    assert_eq!(
        edited(|s| s.environment.intensity *= 2.0),
        Change::ENVIRONMENT
    );
    assert_eq!(edited(|s| s.render.max_bounces += 1), Change::RENDER);
}

/// Several edits at once (a preset loaded over another, an undo across a
/// gesture) set each class they touch.
#[test]
fn edits_together_set_each_class() {
    let change = edited(|s| {
        s.camera.distance *= 1.5;
        s.render.display.exposure -= 1.0;
        first_noise(s, |n| n.fractal.lacunarity = 2.5);
    });
    assert_eq!(
        change,
        Change::CAMERA | Change::DISPLAY | Change::MATERIAL_PARAMETERS
    );
}
