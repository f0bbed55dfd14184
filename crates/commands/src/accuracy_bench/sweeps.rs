//! For each knob, the scenes it is swept on, its variants and the
//! reference each variant is measured against. One knob moves at a time;
//! everything else stays as the scene has it.

use super::knob::Knob;
use super::scale::Scale;
use super::scenes;
use anyhow::Result;
use marbre_core::envmap::EnvImage;
use marbre_core::lights::LightSelection;
use marbre_core::noise::HashKind;
use marbre_core::scene::{DenoiseQuality, Denoiser, Scene, Strategy};
use marbre_core::texture::{ImageFilter, ImageSet};
use marbre_render::gpu::FeatureSet;
use marbre_render::session::{LoadedScene, prepare_scene};
use std::path::Path;

/// One value of the knob: the scene rendered, the shader's features if not
/// the scene's own, whether the image measured is the denoised one (its
/// scene's display has `denoise` on), and the scene whose reference it is
/// measured against.
pub struct Variant {
    pub name: String,
    pub scene: Scene,
    pub features: Option<FeatureSet>,
    pub denoise: bool,
    pub reference: Scene,
}

/// A knob swept on one scene.
pub struct Sweep {
    pub knob: Knob,
    pub scene_name: String,
    pub env: Option<EnvImage>,
    pub images: ImageSet,
    pub variants: Vec<Variant>,
    pub spp: Vec<u32>,
    pub reference_spp: u32,
    /// The image's size: the scale's, or the denoise knob's own.
    pub size: (u32, u32),
}

impl Sweep {
    /// `variants` of `base`, each at the scale's variant counts.
    fn new(
        knob: Knob,
        scene_name: &str,
        base: LoadedScene,
        variants: Vec<Variant>,
        scale: &Scale,
    ) -> Self {
        Self {
            knob,
            scene_name: scene_name.into(),
            env: base.env,
            images: base.images,
            variants,
            spp: scale.variant_spp.clone(),
            reference_spp: scale.reference_spp,
            size: scale.size,
        }
    }
}

/// Named scenes, each with its shader specialised, all measured against
/// the reference of `reference`.
fn against(reference: &Scene, variants: Vec<(String, Scene)>) -> Vec<Variant> {
    variants
        .into_iter()
        .map(|(name, scene)| Variant {
            name,
            scene,
            features: None,
            denoise: false,
            reference: reference.clone(),
        })
        .collect()
}

/// `base` with `change` applied.
fn with(base: &Scene, change: impl FnOnce(&mut Scene)) -> Scene {
    let mut scene = base.clone();
    change(&mut scene);
    scene
}

/// The sweeps of `knob`. `root` holds `presets/` and `envmaps/`.
pub fn sweeps(knob: Knob, scale: &Scale, root: &Path) -> Result<Vec<Sweep>> {
    Ok(match knob {
        Knob::Spp => {
            let scene = scenes::matte_spheres(&root.join("envmaps").join("sky.exr"));
            let variants = against(&scene, vec![("path tracing".into(), scene.clone())]);
            let loaded = prepare_scene(scene, Vec::new())?;
            let mut sweep = Sweep::new(knob, "matte spheres under sky", loaded, variants, scale);
            sweep.spp = doublings(scale.max_spp);
            sweep.reference_spp = scale.spp_reference;
            vec![sweep]
        }
        Knob::Bounces => {
            let mut cornell = scenes::preset(root, "cornell")?;
            scenes::hide_the_ceiling(&mut cornell.scene);
            let base = cornell.scene.clone();
            let variants = scale
                .bounces
                .iter()
                .map(|&b| {
                    (
                        plural(b, "bounce"),
                        with(&base, |s| s.render.max_bounces = b),
                    )
                })
                .collect();
            let reference = with(&base, |s| s.render.max_bounces = 16);
            let variants = against(&reference, variants);
            vec![Sweep::new(
                knob,
                "cornell (light out of view)",
                cornell,
                variants,
                scale,
            )]
        }
        Knob::LightSelection => {
            let mut panels = scenes::preset(root, "two_panels")?;
            scenes::hide_the_panels(&mut panels.scene);
            let base = panels.scene.clone();
            let variants = LightSelection::ALL
                .iter()
                .map(|&rule| {
                    let scene = with(&base, |s| s.render.transport.light_selection = rule);
                    (rule.label().to_string(), scene)
                })
                .collect();
            let reference = with(&base, |s| {
                s.render.transport.light_selection = LightSelection::Power;
            });
            vec![Sweep::new(
                knob,
                "two_panels (panels out of view)",
                panels,
                against(&reference, variants),
                scale,
            )]
        }
        Knob::Strategy => {
            let base = scenes::glossy_two_lights();
            let variants = Strategy::ALL
                .iter()
                .map(|&strategy| {
                    let scene = with(&base, |s| s.render.transport.strategy = strategy);
                    (strategy.label().to_string(), scene)
                })
                .collect();
            let reference = with(&base, |s| s.render.transport.strategy = Strategy::MisPower);
            let loaded = prepare_scene(base, Vec::new())?;
            vec![Sweep::new(
                knob,
                "glossy",
                loaded,
                against(&reference, variants),
                scale,
            )]
        }
        Knob::EnvSampling => ["sky", "esplanade"]
            .iter()
            .map(|name| {
                let map = root.join("envmaps").join(format!("{name}.exr"));
                let base = scenes::environment_lit(&map);
                let variants = [("cosine (BSDF only)", false), ("importance", true)]
                    .iter()
                    .map(|&(label, on)| {
                        (
                            label.to_string(),
                            with(&base, |s| s.render.env_importance = on),
                        )
                    })
                    .collect();
                let reference = with(&base, |s| s.render.env_importance = true);
                let loaded = prepare_scene(base, Vec::new())?;
                Ok(Sweep::new(
                    knob,
                    name,
                    loaded,
                    against(&reference, variants),
                    scale,
                ))
            })
            .collect::<Result<_>>()?,
        Knob::FireflyClamp => {
            // The esplanade's sun found by BSDF sampling alone: fireflies.
            // Each clamp trades them for a darker image, measured against
            // the unclamped, importance-sampled reference.
            let map = root.join("envmaps").join("esplanade.exr");
            let base = with(&scenes::environment_lit(&map), |s| {
                s.render.env_importance = false;
            });
            let variants = [None, Some(1000.0), Some(100.0), Some(10.0), Some(1.0)]
                .iter()
                .map(|&clamp| {
                    let label = clamp.map_or("off".to_string(), |c: f32| format!("at {c}"));
                    (
                        label,
                        with(&base, |s| s.render.transport.sample_clamp = clamp),
                    )
                })
                .collect();
            let reference = with(&base, |s| s.render.env_importance = true);
            let loaded = prepare_scene(base, Vec::new())?;
            vec![Sweep::new(
                knob,
                "esplanade",
                loaded,
                against(&reference, variants),
                scale,
            )]
        }
        Knob::Octaves => {
            let variants = scale
                .octaves
                .iter()
                .map(|&n| {
                    (
                        plural(n, "octave"),
                        scenes::fbm_ground(n as f32, HashKind::Pcg),
                    )
                })
                .collect();
            let reference = scenes::fbm_ground(16.0, HashKind::Pcg);
            let loaded = prepare_scene(reference.clone(), Vec::new())?;
            vec![Sweep::new(
                knob,
                "fbm ground",
                loaded,
                against(&reference, variants),
                scale,
            )]
        }
        Knob::OctaveClamping => {
            let base = scenes::grazing("fBm")?;
            let variants = vec![
                ("point sampled".into(), base.clone()),
                (
                    "clamped".into(),
                    with(&base, |s| s.render.clamp_octaves = true),
                ),
            ];
            let loaded = prepare_scene(base.clone(), Vec::new())?;
            vec![Sweep::new(
                knob,
                "grazing fBm",
                loaded,
                against(&base, variants),
                scale,
            )]
        }
        Knob::Filtering => {
            let image = root.join("presets").join("images").join("uv_grid.png");
            let nearest = scenes::image_ground(&image, ImageFilter::Nearest);
            let images = [
                ("nearest", ImageFilter::Nearest),
                ("bilinear", ImageFilter::Bilinear),
                ("mipmapped (trilinear)", ImageFilter::Trilinear),
            ]
            .iter()
            .map(|&(label, filter)| (label.to_string(), scenes::image_ground(&image, filter)))
            .collect();
            let checker = scenes::grazing("2D checker")?;
            let checkers = vec![
                ("point sampled".into(), checker.clone()),
                (
                    "box filtered".into(),
                    with(&checker, |s| s.render.filter_checkers = true),
                ),
            ];
            vec![
                Sweep::new(
                    knob,
                    "grazing image",
                    prepare_scene(nearest.clone(), Vec::new())?,
                    against(&nearest, images),
                    scale,
                ),
                Sweep::new(
                    knob,
                    "grazing checker",
                    prepare_scene(checker.clone(), Vec::new())?,
                    against(&checker, checkers),
                    scale,
                ),
            ]
        }
        Knob::Hash => {
            let loaded = prepare_scene(scenes::fbm_ground(10.0, HashKind::Pcg), Vec::new())?;
            // The two hashes draw different noise, neither wrong: each is
            // measured against its own reference, and what differs is the
            // time to reach an error.
            let variants = HashKind::ALL
                .iter()
                .map(|&hash| {
                    let scene = scenes::fbm_ground(10.0, hash);
                    Variant {
                        name: hash.label().to_string(),
                        scene: scene.clone(),
                        features: None,
                        denoise: false,
                        reference: scene,
                    }
                })
                .collect();
            vec![Sweep::new(knob, "fbm ground", loaded, variants, scale)]
        }
        Knob::Shader => {
            let default = scenes::preset(root, "default")?;
            let scene = default.scene.clone();
            let mut variants = against(
                &scene,
                vec![
                    ("specialised".into(), scene.clone()),
                    ("uber".into(), scene.clone()),
                ],
            );
            variants[1].features = Some(FeatureSet::all());
            vec![Sweep::new(knob, "default", default, variants, scale)]
        }
        Knob::Denoise => ["default", "cornell", "tiles"]
            .into_iter()
            .map(|name| {
                let loaded = scenes::preset(root, name)?;
                let scene = loaded.scene.clone();
                let denoised = |denoiser: Denoiser| {
                    with(&scene, |s| {
                        let display = &mut s.render.display;
                        display.denoise = true;
                        display.denoiser = denoiser;
                        display.denoise_quality = DenoiseQuality::High;
                    })
                };
                let mut variants = against(
                    &scene,
                    vec![
                        ("raw".into(), scene.clone()),
                        ("à-trous".into(), denoised(Denoiser::Atrous)),
                        ("OIDN".into(), denoised(Denoiser::Oidn)),
                    ],
                );
                for v in &mut variants[1..] {
                    v.denoise = true;
                }
                let mut sweep = Sweep::new(knob, name, loaded, variants, scale);
                sweep.spp = scale.denoise_spp.clone();
                sweep.reference_spp = scale.denoise_reference_spp;
                sweep.size = scale.denoise_size;
                Ok(sweep)
            })
            .collect::<Result<_>>()?,
    })
}

/// "1 bounce", "2 bounces".
fn plural(n: u32, noun: &str) -> String {
    format!("{n} {noun}{}", if n == 1 { "" } else { "s" })
}

/// 1, 2, 4 … up to `max`.
fn doublings(max: u32) -> Vec<u32> {
    std::iter::successors(Some(1u32), |&n| n.checked_mul(2))
        .take_while(|&n| n <= max.max(1))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_spp_knob_doubles_up_to_its_maximum() {
        assert_eq!(doublings(1), [1]);
        assert_eq!(doublings(64), [1, 2, 4, 8, 16, 32, 64]);
        assert_eq!(doublings(100), [1, 2, 4, 8, 16, 32, 64]);
    }
}
