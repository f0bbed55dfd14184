//! The scenes the sweeps measure, beyond the shipped presets: each built so
//! that the knob swept is what decides the error.

use anyhow::{Context, Result};
use glam::Vec3;
use marbre_core::aa_scenes;
use marbre_core::noise::{FractalParams, HashKind, NoiseSettings};
use marbre_core::scene::{
    EnvSource, Ground, Integrator, Material, OrbitCamera, Pattern, Scene, Sphere, Texture,
};
use marbre_core::texture::{ImageFilter, ImageSource, ImageWrap};
use marbre_render::session::{LoadedScene, load_scene};
use std::path::Path;

/// A shipped preset, with its environment, meshes and images loaded.
pub fn preset(root: &Path, name: &str) -> Result<LoadedScene> {
    load_scene(&root.join("presets").join(format!("{name}.ron")), None)
}

/// Frames the Cornell box below its ceiling light. Seen, the light's edge
/// pixels (radiance 17 or 0 depending on where a sample lands) hold most of
/// the squared error and hide every other change.
pub fn hide_the_ceiling(cornell: &mut Scene) {
    cornell.camera.target = Vec3::new(0.0, 0.8, 0.0);
    cornell.camera.fov_degrees = 30.0;
}

/// Frames the room the two panels light, the panels out of view, as the
/// lab's exercise 6 measures light selection. The preset shows both
/// panels (issue 31); seen, their edges hold most of the squared error,
/// which the light selection does not change, and hide its gain.
pub fn hide_the_panels(panels: &mut Scene) {
    panels.camera.target = Vec3::new(0.0, 0.5, -1.2);
    panels.camera.distance = 3.1;
    panels.camera.yaw_degrees = 0.0;
    panels.camera.pitch_degrees = 15.0;
    panels.camera.fov_degrees = 50.0;
}

fn lambert(albedo: f32) -> Material {
    Material {
        diffuse: Texture::color(Vec3::splat(albedo)),
        specular: Texture::color(Vec3::ZERO),
        roughness: Texture::scalar(1.0),
        ..Material::default()
    }
}

fn emitter(radiance: Vec3) -> Material {
    Material {
        emission: Texture::color(radiance),
        ..lambert(0.0)
    }
}

/// Veach's case for multiple importance sampling: a glossy ground lit by a
/// tiny bright sphere and a large dim one, direct light only. Light
/// sampling is noisy where the large light meets the polished lobe, BSDF
/// sampling where the tiny light meets the rough diffuse part.
pub fn glossy_two_lights() -> Scene {
    let mut scene = Scene {
        spheres: vec![
            Sphere {
                name: "small bright light".into(),
                center: Vec3::new(-1.5, 2.0, 0.0),
                radius: 0.1,
                material: emitter(Vec3::new(200.0, 180.0, 150.0)),
            },
            Sphere {
                name: "large dim light".into(),
                center: Vec3::new(2.0, 2.5, -1.0),
                radius: 1.0,
                material: emitter(Vec3::splat(2.0)),
            },
        ],
        ground: Some(Ground {
            height: 0.0,
            uv_frame: None,
            material: Material {
                diffuse: Texture::color(Vec3::splat(0.05)),
                specular: Texture::color(Vec3::splat(0.9)),
                roughness: Texture::scalar(0.25),
                ..Material::default()
            },
        }),
        point_light: None,
        camera: OrbitCamera {
            target: Vec3::ZERO,
            distance: 5.0,
            pitch_degrees: 30.0,
            yaw_degrees: 10.0,
            ..OrbitCamera::default()
        },
        ..Scene::default()
    };
    scene.render.transport.integrator = Integrator::Direct;
    scene
}

/// A polished metal sphere and a matte one on a matte ground, lit only by
/// the lat-long map `env`: what finds the map's bright spots (the sun) is
/// the whole error.
pub fn environment_lit(env: &Path) -> Scene {
    let mut scene = Scene {
        spheres: vec![
            Sphere {
                name: "metal".into(),
                center: Vec3::new(-1.1, 1.0, 0.0),
                radius: 1.0,
                material: Material {
                    diffuse: Texture::color(Vec3::splat(0.02)),
                    specular: Texture::color(Vec3::splat(0.9)),
                    roughness: Texture::scalar(0.3),
                    ..Material::default()
                },
            },
            Sphere {
                name: "matte".into(),
                center: Vec3::new(1.1, 1.0, 0.0),
                radius: 1.0,
                material: lambert(0.7),
            },
        ],
        ground: Some(Ground {
            height: 0.0,
            uv_frame: None,
            material: lambert(0.5),
        }),
        point_light: None,
        camera: OrbitCamera {
            target: Vec3::new(0.0, 0.9, 0.0),
            distance: 6.0,
            pitch_degrees: 20.0,
            ..OrbitCamera::default()
        },
        ..Scene::default()
    };
    scene.environment.source = EnvSource::LatLong {
        path: env.to_owned(),
    };
    scene.render.max_bounces = 2;
    scene
}

/// Two matte spheres on a matte ground under the lat-long map `env`, paths
/// of 3 bounces: every estimate is bounded (no glossy lobe meets a small
/// bright light), so the error follows the central limit theorem from the
/// first samples, which a convergence rate needs.
pub fn matte_spheres(env: &Path) -> Scene {
    let mut scene = environment_lit(env);
    scene.spheres[0].name = "matte, light".into();
    scene.spheres[0].material = lambert(0.8);
    scene.render.max_bounces = 3;
    scene
}

/// A fractal Brownian motion of `octaves` octaves of gradient noise hashed
/// by `hash`, as the colour of a Lambert ground in white light seen from
/// 25°: the only error left is the texture's (see [`aa_scenes`]), point
/// sampled (octaves not clamped).
pub fn fbm_ground(octaves: f32, hash: HashKind) -> Scene {
    let noise = NoiseSettings {
        hash,
        fractal: FractalParams {
            octaves,
            frequency: 2.0,
            amplitude: 1.2,
            ..Default::default()
        },
        ..Default::default()
    };
    let texture = Texture::blend(Pattern::Fbm { noise }, Vec3::splat(0.1), Vec3::splat(0.9));
    let mut scene = aa_scenes::grazing_ground(texture);
    scene.camera.pitch_degrees = 25.0;
    scene
}

/// The aliasing case of [`aa_scenes`]: `name`'s texture on the grazing
/// ground, point sampled.
pub fn grazing(name: &str) -> Result<Scene> {
    aa_scenes::textures()
        .into_iter()
        .find(|(n, _)| *n == name)
        .map(|(_, texture)| aa_scenes::grazing_ground(texture))
        .with_context(|| format!("no grazing-ground texture named {name}"))
}

/// `image` tiled once per unit on the grazing ground, read with `filter`:
/// far away hundreds of texels fall in one pixel.
pub fn image_ground(image: &Path, filter: ImageFilter) -> Scene {
    let texture = Texture {
        image: Some(ImageSource {
            path: image.to_owned(),
            color_space: Default::default(),
        }),
        ..Texture::blend(
            Pattern::Image {
                filter,
                wrap: ImageWrap::Repeat,
            },
            Vec3::ZERO,
            Vec3::ONE,
        )
    };
    aa_scenes::grazing_ground(texture)
}
