//! The plan against the generator, on every shipped preset: the numbers it
//! fills are the ones generating the code again would give, before and
//! after every number of every material moves.

use super::*;
use crate::gpu::texture_codegen::generate;
use crate::session::load_scene;
use marbre_core::scene::{Change, Pattern};
use std::path::Path;

/// Every shipped preset, with its images loaded.
fn shipped() -> Vec<(String, Scene, ImageSet)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../presets");
    let mut out = Vec::new();
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "ron") {
            let loaded = load_scene(&path, None).unwrap();
            out.push((path.display().to_string(), loaded.scene, loaded.images));
        }
    }
    assert!(
        out.len() >= 10,
        "{} presets in {}",
        out.len(),
        dir.display()
    );
    out
}

/// Moves every number a material's textures hold and none of their
/// structure: constants, noise sums (all alike, so that shared sums stay
/// shared), mapping transforms, ramp stops, math steps, emission.
fn move_every_number(scene: &mut Scene) {
    for material in scene.materials_mut() {
        material.emission_strength *= 1.25;
        material.visit_textures_mut(&mut |t| {
            for child in [&mut t.a, &mut t.b] {
                match child {
                    Child::Scalar(v) => *v = 0.5 * *v + 0.1,
                    Child::Color(c) => *c = 0.5 * *c + glam::Vec3::splat(0.1),
                    Child::Texture(_) => {}
                }
            }
            if let Some(noise) = t.pattern.noise_mut() {
                noise.fractal.octaves += 0.5;
                noise.fractal.frequency *= 1.5;
            }
            match &mut t.pattern {
                Pattern::Checker { size } => *size *= 2.0,
                Pattern::Checker2d { phase, .. } => *phase += 0.25,
                Pattern::Brick { mortar, .. } => *mortar *= 0.5,
                Pattern::Waves { frequency, .. } => *frequency += 1.0,
                _ => {}
            }
            if let Some(mapping) = &mut t.mapping {
                mapping.transform.translate += glam::Vec3::new(0.1, 0.2, 0.3);
            }
            for stop in &mut t.ramp {
                stop.color *= 0.5;
            }
            for op in &mut t.ops {
                if let marbre_core::scene::MathOp::Scale(f) = op {
                    *f *= 2.0;
                }
            }
        });
    }
}

#[test]
fn the_plan_fills_what_the_generator_fills_for_every_preset() {
    for (name, scene, images) in shipped() {
        let generated = generate(&scene, &images).unwrap();
        assert_eq!(
            generated.plan.evaluate(&scene, &images).as_ref(),
            Some(&generated.params),
            "{name}"
        );
    }
}

/// The edit path of a slider: classified as a parameter edit, its numbers
/// filled by the old code's plan are those of generating anew, and the
/// code generated anew is the old code.
#[test]
fn after_a_parameter_edit_the_old_plan_fills_the_new_numbers() {
    for (name, scene, images) in shipped() {
        let before = generate(&scene, &images).unwrap();
        let mut edited = scene.clone();
        move_every_number(&mut edited);
        let change = edited.changes_from(&scene);
        assert!(
            !change.regenerates_code(),
            "{name}: moving numbers was classified {change:?}"
        );
        let after = generate(&edited, &images).unwrap();
        assert_eq!(after.wgsl, before.wgsl, "{name}: the code changed");
        assert_eq!(
            before.plan.evaluate(&edited, &images).as_ref(),
            Some(&after.params),
            "{name}"
        );
        if edited != scene && scene.materials().next().is_some() {
            assert!(
                change.contains(Change::MATERIAL_PARAMETERS),
                "{name}: {change:?}"
            );
        }
    }
}

/// A plan read against a scene whose structure it does not describe says
/// so instead of filling numbers from the wrong nodes.
#[test]
fn a_plan_refuses_another_structure() {
    let mut scene = Scene::default();
    scene.spheres.push(marbre_core::scene::Sphere::default());
    scene.spheres[0].material.diffuse = Texture::blend(
        Pattern::Checker { size: 0.5 },
        Texture::blend(
            Pattern::Checker { size: 0.1 },
            glam::Vec3::ZERO,
            glam::Vec3::ONE,
        ),
        glam::Vec3::ONE,
    );
    let images = ImageSet::empty();
    let plan = generate(&scene, &images).unwrap().plan;
    let mut flat = scene.clone();
    flat.spheres[0].material.diffuse = Texture::color(glam::Vec3::ONE);
    assert_eq!(plan.evaluate(&flat, &images), None);
    flat.spheres.clear();
    assert_eq!(plan.evaluate(&flat, &images), None);
}

/// Evolving noise (issue 29) on every shipped preset that reads noise:
/// without an evolution the trace module holds none of the 4D code (the
/// code of before, so the images are bit for bit those of before); turning
/// evolution on adds the NOISE_EVOLVE feature and leaves the generated
/// texture code alone; and the scene's time moving (w, the loop's period,
/// the drift) is a parameter edit: the same code, the same pipeline's
/// features, other numbers in the material uniform.
#[test]
fn evolving_noise_moves_in_time_by_its_numbers_alone() {
    use crate::gpu::features::{Feature, FeatureSet};
    use crate::gpu::scene_gpu;
    use crate::gpu::shader_source::{Program, assemble};
    use marbre_core::noise::Evolution;
    let mut checked = 0;
    for (name, scene, images) in shipped() {
        if !scene.materials().any(|m| !m.signals().is_empty()) {
            continue;
        }
        checked += 1;
        let features = FeatureSet::for_scene(&scene);
        assert!(!features.contains(Feature::NoiseEvolve), "{name}");
        let today = generate(&scene, &images).unwrap();
        let module = assemble(Program::Trace, &features, &today.wgsl).unwrap();
        for four_d in ["fn pcg4d", "noise4(", "NOISE_EVOLVES: u32", "fn octave_w"] {
            assert!(
                !module.contains(four_d),
                "{name}: {four_d} in a still scene's shader"
            );
        }
        let at = |t: f32, looping: Option<f32>| {
            let mut s = scene.clone();
            for m in s.materials_mut() {
                m.for_each_noise_mut(&mut |n| {
                    let mut e = Evolution {
                        w: 0.5,
                        speed: 0.8,
                        drift: glam::Vec3::new(0.3, 0.0, -0.2),
                        ..Evolution::default()
                    };
                    e.at(t, looping);
                    n.evolution = Some(e);
                });
            }
            s
        };
        let start = at(0.0, None);
        let evolving_features = FeatureSet::for_scene(&start);
        assert!(evolving_features.contains(Feature::NoiseEvolve), "{name}");
        let first = generate(&start, &images).unwrap();
        assert_eq!(
            first.wgsl, today.wgsl,
            "{name}: evolution changed the texture code"
        );
        for later in [at(1.25, None), at(1.25, Some(4.0))] {
            let change = later.changes_from(&start);
            assert!(
                change.contains(Change::MATERIAL_PARAMETERS) && !change.regenerates_code(),
                "{name}: {change:?}"
            );
            assert_eq!(FeatureSet::for_scene(&later), evolving_features, "{name}");
            let next = generate(&later, &images).unwrap();
            assert_eq!(next.wgsl, first.wgsl, "{name}");
            assert_eq!(
                first.plan.evaluate(&later, &images).as_ref(),
                Some(&next.params)
            );
            assert_ne!(
                bytemuck::cast_slice::<_, u8>(&scene_gpu::materials(&later)),
                bytemuck::cast_slice::<_, u8>(&scene_gpu::materials(&start)),
                "{name}: the moment reached no number"
            );
        }
    }
    assert!(checked >= 3, "only {checked} presets read noise");
}
