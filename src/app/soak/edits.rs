//! The soak's random scene edits: what a user could do with the panel,
//! drawn from a seeded generator.
//!
//! Every value stays within the range of the control that sets it, and an
//! edit to a material is kept only if the material still passes
//! `Material::sanitize` unchanged (no note, no clamp): an edit the scene
//! model would have to correct (a fifth distinct noise, a texture nested
//! too deep) is dropped, so the renderer only ever sees scenes a user could
//! have made. Knobs that mostly cost time (samples per frame, bounces) are
//! drawn from the cheap end of their sliders: a soak is about what frames
//! leave behind, not about slow frames.

use super::rng::Pcg32;
use glam::{Vec2, Vec3};
use marbre_core::noise::{FractalParams, HashKind, NoiseKind, Progression};
use marbre_core::scene::{
    Child, EnvSource, MAX_MATERIALS, MAX_SPHERES, Material, Metering, Pattern, PatternKind,
    RenderSettings, Scene, Sphere, Texture, ToneMap,
};

/// The structural edits: each changes what the shader is built from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Structural {
    /// A texture switched to another pattern.
    Pattern,
    /// A noise switched to the other lattice noise or another hash.
    Noise,
    /// A value nested into a texture, or a nested texture flattened.
    Nesting,
    /// The environment switched between a constant and the preset's map.
    Environment,
    /// A sphere added, or the one the soak added removed.
    Sphere,
}

impl Structural {
    pub const ALL: [Structural; 5] = [
        Structural::Pattern,
        Structural::Noise,
        Structural::Nesting,
        Structural::Environment,
        Structural::Sphere,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Structural::Pattern => "pattern",
            Structural::Noise => "noise kind/hash",
            Structural::Nesting => "nesting",
            Structural::Environment => "environment source",
            Structural::Sphere => "sphere added/removed",
        }
    }
}

/// The name of the sphere the soak adds, so that it removes only its own.
const SOAK_SPHERE: &str = "soak sphere";

/// Changes one value somewhere in the scene, as a slider drag would; false
/// when the drawn edit would not have survived sanitising (nothing changed).
pub fn parameter_edit(rng: &mut Pcg32, scene: &mut Scene) -> bool {
    match rng.below(6) {
        0 => edit_material(rng, scene, |rng, m| {
            edit_random_texture(rng, m, edit_value_child);
        }),
        1 => edit_material(rng, scene, |rng, m| {
            edit_random_texture(rng, m, |rng, t| edit_pattern_parameter(rng, &mut t.pattern));
        }),
        2 => edit_material(rng, scene, |rng, m| {
            let range = Material::BUMP_HEIGHT_DRAG_RANGE;
            m.bump_height = rng.range(-range, range);
        }),
        3 => {
            edit_render_settings(rng, &mut scene.render);
            true
        }
        4 => {
            let camera = &mut scene.camera;
            match rng.below(3) {
                0 => camera.yaw_degrees = rng.range(0.0, 360.0),
                1 => camera.pitch_degrees = rng.range(-89.0, 89.0),
                _ => camera.fov_degrees = rng.range(10.0, 120.0),
            }
            true
        }
        _ => {
            let env = &mut scene.environment;
            if rng.chance(0.5) {
                env.rotation_degrees = rng.range(-180.0, 180.0);
            } else {
                env.intensity = rng.log_range(0.01, 100.0);
            }
            true
        }
    }
}

/// One structural edit of the drawn kind; false when it could not be made
/// on this scene (no room for a sphere, an edit sanitising would undo).
/// `env_map` is the preset's environment map, remembered while the soak
/// shows a constant instead.
pub fn structural_edit(
    rng: &mut Pcg32,
    kind: Structural,
    scene: &mut Scene,
    env_map: &mut Option<EnvSource>,
) -> bool {
    match kind {
        Structural::Pattern => edit_material(rng, scene, |rng, m| {
            edit_random_texture(rng, m, switch_pattern);
        }),
        Structural::Noise => edit_material(rng, scene, |rng, m| {
            let mut noisy = 0;
            m.visit_textures_mut(&mut |t| noisy += usize::from(t.pattern.noise().is_some()));
            if noisy == 0 {
                // Nothing to switch yet: bring a noise in.
                edit_random_texture(rng, m, |_, t| {
                    t.pattern = t.pattern.with_kind(PatternKind::Fbm)
                });
                return;
            }
            let mut k = rng.below(noisy);
            let (flip_kind, hash) = (rng.chance(0.5), rng.below(HashKind::ALL.len()));
            m.visit_textures_mut(&mut |t| {
                if let Some(noise) = t.pattern.noise_mut() {
                    if k == 0 {
                        if flip_kind {
                            noise.kind = match noise.kind {
                                NoiseKind::Gradient => NoiseKind::Perlin,
                                NoiseKind::Perlin => NoiseKind::PerlinMassal,
                                NoiseKind::PerlinMassal => NoiseKind::Gradient,
                            };
                        } else {
                            noise.kind = NoiseKind::Gradient;
                            noise.hash = HashKind::ALL[hash];
                        }
                    }
                    k = k.wrapping_sub(1);
                }
            });
        }),
        Structural::Nesting => edit_material(rng, scene, |rng, m| {
            edit_random_texture(rng, m, nest_or_flatten);
        }),
        Structural::Environment => {
            switch_environment(rng, scene, env_map);
            true
        }
        Structural::Sphere => add_or_remove_sphere(rng, scene),
    }
}

fn material_is_sanitized(material: &Material) -> bool {
    let mut copy = material.clone();
    let mut notes = Vec::new();
    copy.sanitize("soak", &mut notes);
    notes.is_empty() && copy == *material
}

/// Applies `edit` to a copy of a random material and keeps the copy if it
/// changed and is still sanitised; false otherwise.
fn edit_material(
    rng: &mut Pcg32,
    scene: &mut Scene,
    edit: impl FnOnce(&mut Pcg32, &mut Material),
) -> bool {
    let k = rng.below(scene.materials().count());
    let Some(material) = scene.materials_mut().nth(k) else {
        return false;
    };
    let mut edited = material.clone();
    edit(rng, &mut edited);
    if edited == *material || !material_is_sanitized(&edited) {
        return false;
    }
    *material = edited;
    true
}

/// Applies `edit` to one texture of the material (nested ones included),
/// each equally likely.
fn edit_random_texture(
    rng: &mut Pcg32,
    material: &mut Material,
    edit: impl FnOnce(&mut Pcg32, &mut Texture),
) {
    let mut count = 0;
    material.visit_textures_mut(&mut |_| count += 1);
    let mut k = rng.below(count);
    let mut edit = Some(edit);
    material.visit_textures_mut(&mut |t| {
        if k == 0
            && let Some(edit) = edit.take()
        {
            edit(rng, t);
        }
        k = k.wrapping_sub(1);
    });
}

/// A value child (`a` or `b`) set anywhere in [0, 1], as its slider or
/// colour picker would; a texture whose children are both textures is
/// left alone.
fn edit_value_child(rng: &mut Pcg32, texture: &mut Texture) {
    let first = rng.chance(0.5);
    let (chosen, other) = if first {
        (&mut texture.a, &mut texture.b)
    } else {
        (&mut texture.b, &mut texture.a)
    };
    let child = if matches!(chosen, Child::Texture(_)) {
        other
    } else {
        chosen
    };
    match child {
        Child::Scalar(v) => *v = rng.unit(),
        Child::Color(c) => *c = Vec3::new(rng.unit(), rng.unit(), rng.unit()),
        Child::Texture(_) => {}
    }
}

/// One parameter of the pattern, over its slider's range
/// (`panel::material_editor`).
fn edit_pattern_parameter(rng: &mut Pcg32, pattern: &mut Pattern) {
    if let Some(noise) = pattern.noise_mut()
        && rng.chance(0.5)
    {
        edit_fractal(rng, &mut noise.fractal);
        return;
    }
    match pattern {
        Pattern::Checker { size } => *size = rng.log_range(0.01, 10.0),
        Pattern::Marble {
            stripe_frequency, ..
        }
        | Pattern::MassalMarble {
            stripe_frequency, ..
        } => *stripe_frequency = rng.range(0.0, 32.0),
        Pattern::Checker2d { size, phase } => {
            *size = Vec2::new(rng.log_range(0.01, 4.0), rng.log_range(0.01, 4.0));
            *phase = rng.unit();
        }
        Pattern::Brick {
            size,
            mortar,
            row_offset,
        } => match rng.below(3) {
            0 => *size = Vec2::new(rng.log_range(0.01, 4.0), rng.log_range(0.01, 4.0)),
            1 => *mortar = rng.range(0.0, 0.2),
            _ => *row_offset = rng.unit(),
        },
        Pattern::Tile {
            mortar_half_width,
            bevel,
        } => {
            *mortar_half_width = rng.range(0.0, 0.5);
            *bevel = rng.range(0.0, 0.5);
        }
        Pattern::Waves {
            frequency,
            direction,
        } => {
            *frequency = rng.range(0.0, 64.0);
            *direction = Vec2::from_angle(rng.range(-180.0, 180.0).to_radians());
        }
        Pattern::Cutout { sides, radius } => {
            *sides = rng.below(13) as u32;
            *radius = rng.range(0.0, 0.71);
        }
        Pattern::Wood {
            ring_width,
            turbulence_amount,
            ..
        } => {
            *ring_width = rng.log_range(0.01, 1.0);
            *turbulence_amount = rng.range(0.0, 2.0);
        }
        Pattern::Veins {
            frequency,
            turbulence_amount,
            ..
        } => {
            *frequency = rng.range(0.0, 32.0);
            *turbulence_amount = rng.range(0.0, 40.0);
        }
        Pattern::Fbm { noise } | Pattern::Turbulence { noise } | Pattern::Ridged { noise } => {
            edit_fractal(rng, &mut noise.fractal)
        }
        Pattern::Constant | Pattern::Mix | Pattern::Image { .. } | Pattern::Diagonal => {}
    }
}

/// One knob of a fractal sum over its slider's drag range.
fn edit_fractal(rng: &mut Pcg32, f: &mut FractalParams) {
    match rng.below(7) {
        0 => {
            f.octaves = rng.range(
                *FractalParams::OCTAVES.start(),
                *FractalParams::OCTAVES.end(),
            )
        }
        1 => f.frequency = rng.log_range(0.01, 100.0),
        2 => f.amplitude = rng.range(0.0, 2.0),
        3 => {
            f.persistence = rng.range(
                *FractalParams::PERSISTENCE.start(),
                *FractalParams::PERSISTENCE.end(),
            )
        }
        4 => f.lacunarity = rng.range(1.0, 4.0),
        5 => f.progression = Progression::ALL[rng.below(Progression::ALL.len())],
        _ => f.distortion = rng.range(0.0, 4.0),
    }
}

/// One render setting; samples per frame and bounces from the cheap end
/// of their sliders (see the module's comment).
fn edit_render_settings(rng: &mut Pcg32, render: &mut RenderSettings) {
    let stops = RenderSettings::MAX_EXPOSURE_STOPS;
    match rng.below(7) {
        0 => render.display.exposure = rng.range(-stops, stops),
        1 => render.display.tone_map = ToneMap::ALL[rng.below(ToneMap::ALL.len())],
        2 => render.samples_per_frame = 1 + rng.below(4) as u32,
        3 => render.max_bounces = 1 + rng.below(6) as u32,
        4 => render.display.auto_exposure = !render.display.auto_exposure,
        5 => render.display.metering = Metering::ALL[rng.below(Metering::ALL.len())],
        _ => render.interactive_scale = rng.range(0.1, 1.0),
    }
}

/// The pattern dropdown: another pattern (never the image one), keeping
/// the noise settings as the panel does; a mix gets the factor it needs,
/// and any other pattern loses it.
fn switch_pattern(rng: &mut Pcg32, texture: &mut Texture) {
    // The panel's list without the image pattern, which needs a file.
    let kinds: Vec<PatternKind> = PatternKind::all()
        .filter(|&k| k != PatternKind::Image)
        .collect();
    texture.pattern = texture.pattern.with_kind(kinds[rng.below(kinds.len())]);
    texture.factor = match texture.pattern {
        Pattern::Mix => Some(Box::new(Texture::scalar(rng.unit()))),
        _ => None,
    };
}

/// The "texture" tick box of a value: a value becomes a 2D checker of
/// itself (what the panel nests), a nested texture becomes its value at
/// the origin.
fn nest_or_flatten(rng: &mut Pcg32, texture: &mut Texture) {
    let child = if rng.chance(0.5) {
        &mut texture.a
    } else {
        &mut texture.b
    };
    *child = match &*child {
        Child::Texture(t) => {
            let c = t.eval(Vec3::ZERO, Vec2::ZERO);
            if c.x == c.y && c.y == c.z {
                Child::Scalar(c.x)
            } else {
                Child::Color(c)
            }
        }
        value => Child::Texture(Box::new(Texture::blend(
            Pattern::Checker2d {
                size: Vec2::splat(0.5),
                phase: 0.0,
            },
            value.clone(),
            value.clone(),
        ))),
    };
}

/// A map becomes a constant sky (the map is remembered); a constant or
/// black sky becomes the remembered map, or, with none, the other of
/// constant and black.
fn switch_environment(rng: &mut Pcg32, scene: &mut Scene, env_map: &mut Option<EnvSource>) {
    let source = &mut scene.environment.source;
    *source = if source.is_map() {
        *env_map = Some(source.clone());
        EnvSource::Constant {
            radiance: Vec3::splat(rng.range(0.2, 1.0)),
        }
    } else if let Some(map) = env_map.clone() {
        map
    } else if matches!(source, EnvSource::None) {
        EnvSource::Constant {
            radiance: Vec3::splat(rng.range(0.2, 1.0)),
        }
    } else {
        EnvSource::None
    };
}

/// Removes the soak's sphere if the scene has it, else adds one where
/// there is room for a sphere and its material.
fn add_or_remove_sphere(rng: &mut Pcg32, scene: &mut Scene) -> bool {
    if let Some(i) = scene.spheres.iter().position(|s| s.name == SOAK_SPHERE) {
        scene.spheres.remove(i);
        return true;
    }
    if scene.spheres.len() >= MAX_SPHERES || scene.materials().count() >= MAX_MATERIALS {
        return false;
    }
    let material = Material {
        diffuse: Texture::color(Vec3::new(rng.unit(), rng.unit(), rng.unit())),
        ..Material::default()
    };
    scene.spheres.push(Sphere {
        name: SOAK_SPHERE.into(),
        center: Vec3::new(
            rng.range(-3.0, 3.0),
            rng.range(0.3, 2.0),
            rng.range(-3.0, 3.0),
        ),
        radius: rng.range(0.2, 1.0),
        material,
    });
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use marbre_core::noise::NoiseSettings;
    use marbre_core::scene::Property;

    /// Gives the first `n` properties each its own noise (a distinct
    /// frequency: a distinct signal).
    fn noises(material: &mut Material, n: usize) {
        for (i, &property) in Property::ALL.iter().take(n).enumerate() {
            let mut noise = NoiseSettings::default();
            noise.fractal.frequency = 1.0 + i as f32;
            *material.texture_mut(property) = Texture::blend(Pattern::Fbm { noise }, 0.2, 0.8);
        }
    }

    /// A material reads at most four distinct noises: an edit bringing in
    /// a fifth is dropped and the scene left as it was; four are kept.
    #[test]
    fn an_edit_that_sanitising_would_undo_is_dropped() {
        let mut scene = Scene {
            spheres: vec![Sphere::default()],
            ..Default::default()
        };
        let before = scene.clone();
        let mut rng = Pcg32::new(1);
        assert!(!edit_material(&mut rng, &mut scene, |_, m| noises(m, 5)));
        assert_eq!(scene, before);
        assert!(edit_material(&mut rng, &mut scene, |_, m| noises(m, 4)));
        let material = &scene.spheres[0].material;
        let fbm = material
            .patterns()
            .into_iter()
            .filter(|p| matches!(p, Pattern::Fbm { .. }));
        assert_eq!(fbm.count(), 4);
    }

    /// The soak adds a sphere of its own and then removes that one, never
    /// a preset's.
    #[test]
    fn the_soak_removes_only_its_own_sphere() {
        let mut scene = Scene {
            spheres: vec![Sphere::default()],
            ..Default::default()
        };
        let mut rng = Pcg32::new(3);
        assert!(add_or_remove_sphere(&mut rng, &mut scene));
        assert_eq!(scene.spheres.len(), 2);
        assert_eq!(scene.spheres[1].name, SOAK_SPHERE);
        assert!(add_or_remove_sphere(&mut rng, &mut scene));
        assert_eq!(scene.spheres, [Sphere::default()]);
    }

    /// Map → constant → the same map again.
    #[test]
    fn the_environment_comes_back_to_the_presets_map() {
        let map = EnvSource::LatLong {
            path: "sky.exr".into(),
        };
        let mut scene = Scene::default();
        scene.environment.source = map.clone();
        let (mut rng, mut remembered) = (Pcg32::new(4), None);
        switch_environment(&mut rng, &mut scene, &mut remembered);
        assert!(matches!(
            scene.environment.source,
            EnvSource::Constant { .. }
        ));
        switch_environment(&mut rng, &mut scene, &mut remembered);
        assert_eq!(scene.environment.source, map);
    }
}
