//! The scenes that show what procedural anti-aliasing is worth: a Lambert
//! ground under a white constant environment, seen at a grazing angle. Each
//! point reflects exactly its albedo (every bounce escapes), so the only
//! error left in one sample per pixel is the texture's own aliasing. Shared
//! by `marbre bench-presets`, `marbre bench` and the tests.

use crate::noise::{FractalParams, NoiseSettings};
use crate::scene::{EnvSource, Ground, Material, OrbitCamera, Pattern, Scene, Texture};
use glam::{Vec2, Vec3};

/// The textures the anti-aliasing table and test measure: a 2D checker, a
/// 3D checker (box-filtered) and a 10-octave fBm (octaves clamped).
pub fn textures() -> Vec<(&'static str, Texture)> {
    let dark = Vec3::splat(0.1);
    let light = Vec3::splat(0.9);
    let noise = NoiseSettings {
        fractal: FractalParams {
            octaves: 10.0,
            frequency: 2.0,
            amplitude: 1.2,
            ..Default::default()
        },
        ..Default::default()
    };
    vec![
        (
            "2D checker",
            Texture::blend(
                Pattern::Checker2d {
                    size: Vec2::splat(0.25),
                    phase: 0.0,
                },
                dark,
                light,
            ),
        ),
        (
            "3D checker",
            Texture::blend(Pattern::Checker { size: 0.25 }, dark, light),
        ),
        ("fBm", Texture::blend(Pattern::Fbm { noise }, dark, light)),
    ]
}

/// `diffuse` on a Lambert ground in white light, seen 8° from grazing, with
/// footprint filtering off (the reference and the point-sampled image).
pub fn grazing_ground(diffuse: Texture) -> Scene {
    let mut scene = Scene {
        ground: Some(Ground {
            height: 0.0,
            uv_frame: None,
            material: Material {
                diffuse,
                specular: Texture::color(Vec3::ZERO),
                roughness: Texture::scalar(1.0),
                ..Material::default()
            },
        }),
        camera: OrbitCamera {
            target: Vec3::new(0.0, 0.5, 0.0),
            distance: 3.0,
            yaw_degrees: 0.0,
            pitch_degrees: 8.0,
            fov_degrees: 30.0,
            ..Default::default()
        },
        ..Scene::default()
    };
    scene.render.filter_checkers = false;
    scene.render.clamp_octaves = false;
    // The error measured is the texture's aliasing: no Russian roulette
    // noise on top.
    scene.render.transport.russian_roulette_from = 0;
    scene.environment.source = EnvSource::Constant {
        radiance: Vec3::ONE,
    };
    scene
}
