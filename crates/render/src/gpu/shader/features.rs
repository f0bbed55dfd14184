//! Which shader features a scene needs: the key of shader specialisation.

use marbre_core::noise::{HashKind, NoiseKind, NoiseSettings};
use marbre_core::scene::{
    EnvSource, Material, PATTERNS, Pattern, PatternKind, Scene, Texture, View,
};
use marbre_core::texture::ImageFilter;
use std::collections::BTreeSet;

/// One piece of shader code that can be compiled out.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Feature {
    Ground,
    Cylinder,
    Polygon,
    Mesh,
    PointLight,
    AreaLight,
    EnvMap,
    EnvSampling,
    EnvConstant,
    /// A pattern's code: its row of the pattern table (`PATTERNS`) says
    /// its define, whether it reads (u, v) and the texture library.
    Pattern(PatternKind),
    Bump,
    Footprint,
    Opacity,
    Emission,
    NoiseWarp,
    /// Evolving noise: the 4D noises and sums (issue 29).
    NoiseEvolve,
    NoiseGradient,
    NoisePerlin,
    HashPcg,
    HashSin,
    DenoiseGuides,
    /// The trace module of the CPU kernel: the samples come from the CPU
    /// (`cpu_samples`), the GPU folds them in. Added by the kernel, never
    /// by a scene (`Renderer::build_trace_pipeline`), so not in
    /// [`Feature::all`].
    CpuSamples,
}

impl Feature {
    /// The features that are not patterns.
    const OTHERS: [Feature; 20] = [
        Feature::Ground,
        Feature::Cylinder,
        Feature::Polygon,
        Feature::Mesh,
        Feature::PointLight,
        Feature::AreaLight,
        Feature::EnvMap,
        Feature::EnvSampling,
        Feature::EnvConstant,
        Feature::Bump,
        Feature::Footprint,
        Feature::Opacity,
        Feature::Emission,
        Feature::NoiseWarp,
        Feature::NoiseEvolve,
        Feature::NoiseGradient,
        Feature::NoisePerlin,
        Feature::HashPcg,
        Feature::HashSin,
        Feature::DenoiseGuides,
    ];

    /// Every feature: each pattern with code, and the others.
    pub fn all() -> impl Iterator<Item = Feature> {
        let patterns = PATTERNS
            .iter()
            .filter(|row| row.define.is_some())
            .map(|row| Feature::Pattern(row.kind));
        Self::OTHERS.into_iter().chain(patterns)
    }

    /// The name used by `#if` in the WGSL sources.
    pub fn define(self) -> &'static str {
        match self {
            Feature::Ground => "GROUND",
            Feature::Cylinder => "CYLINDER",
            Feature::Polygon => "POLYGON",
            Feature::Mesh => "MESH",
            Feature::PointLight => "POINT_LIGHT",
            Feature::AreaLight => "AREA_LIGHT",
            Feature::EnvMap => "ENV_MAP",
            Feature::EnvSampling => "ENV_SAMPLING",
            Feature::EnvConstant => "ENV_CONSTANT",
            Feature::Pattern(kind) => kind
                .info()
                .define
                .expect("a pattern feature is one with code"),
            Feature::Bump => "BUMP",
            Feature::Footprint => "FOOTPRINT",
            Feature::Opacity => "OPACITY",
            Feature::Emission => "EMISSION",
            Feature::NoiseWarp => "NOISE_WARP",
            Feature::NoiseEvolve => "NOISE_EVOLVE",
            Feature::NoiseGradient => "NOISE_GRADIENT",
            Feature::NoisePerlin => "NOISE_PERLIN",
            Feature::HashPcg => "HASH_PCG",
            Feature::HashSin => "HASH_SIN",
            Feature::DenoiseGuides => "DENOISE_GUIDES",
            Feature::CpuSamples => "CPU_SAMPLES",
        }
    }

    /// The image pattern's feature: it also binds the image atlas.
    pub const IMAGE: Feature = Feature::Pattern(PatternKind::Image);
}

/// The set of features a shader is built with. Two scenes with equal sets
/// share a pipeline; an edit that changes the set triggers a rebuild.
#[derive(Debug, Clone, PartialEq, Eq, Hash, Default)]
pub struct FeatureSet(pub BTreeSet<Feature>);

impl FeatureSet {
    /// Everything: the "uber shader" that renders any scene.
    pub fn all() -> Self {
        Self(Feature::all().collect())
    }

    pub fn contains(&self, f: Feature) -> bool {
        self.0.contains(&f)
    }

    /// The `#if` names: one per feature, plus `NOISE` when any noise kind
    /// is in (the code shared by every fractal sum) and `TEXTURE_UV` when a
    /// pattern reads the surface's (u, v).
    pub fn defines(&self) -> BTreeSet<&'static str> {
        let mut names: BTreeSet<_> = self.0.iter().map(|f| f.define()).collect();
        if self.contains(Feature::NoiseGradient) || self.contains(Feature::NoisePerlin) {
            names.insert("NOISE");
        }
        let reads_uv = |f: &Feature| match f {
            Feature::Pattern(kind) => kind.info().reads_uv,
            f => *f == Feature::Bump,
        };
        if self.0.iter().any(reads_uv) {
            names.insert("TEXTURE_UV");
        }
        // ∂p/∂u and ∂p/∂v: bump tilts the normal along them, footprints
        // convert a cone's width into (u, v) with them.
        if self.contains(Feature::Bump) || self.contains(Feature::Footprint) {
            names.insert("TANGENTS");
        }
        names
    }

    /// The features `scene` uses, and no others.
    pub fn for_scene(scene: &Scene) -> Self {
        let mut set = BTreeSet::new();
        if scene.ground.is_some() {
            set.insert(Feature::Ground);
        }
        if !scene.cylinders.is_empty() {
            set.insert(Feature::Cylinder);
        }
        if !scene.polygons.is_empty() {
            set.insert(Feature::Polygon);
        }
        if scene.triangle_count() > 0 {
            set.insert(Feature::Mesh);
        }
        if scene.point_light.is_some() {
            set.insert(Feature::PointLight);
        }
        if has_area_lights(scene) {
            set.insert(Feature::AreaLight);
        }
        match scene.environment.source {
            EnvSource::None => {}
            EnvSource::Constant { .. } => {
                set.insert(Feature::EnvConstant);
            }
            EnvSource::LatLong { .. }
            | EnvSource::CubeFaces { .. }
            | EnvSource::CubeCross { .. } => {
                set.insert(Feature::EnvMap);
                if scene.render.env_importance {
                    set.insert(Feature::EnvSampling);
                }
            }
        }
        // The denoiser's guides: accumulated only while it is shown, on
        // the lit image (a view is shown as it is).
        if scene.render.display.denoise && scene.render.view == View::Lit {
            set.insert(Feature::DenoiseGuides);
        }
        let patterns: Vec<&Pattern> = scene.materials().flat_map(|m| m.patterns()).collect();
        for pattern in &patterns {
            set.extend(pattern_features(pattern));
        }
        // The footprint serves filtered patterns, noise and mipmapped
        // images. Whether checkers are filtered and octaves clamped are
        // override constants of the same module (`RenderSwitches`), so
        // toggling them keeps it.
        let footprint_users = patterns.iter().any(|p| {
            p.info().filtered
                || p.noise().is_some()
                || matches!(
                    p,
                    Pattern::Image {
                        filter: ImageFilter::Trilinear,
                        ..
                    }
                )
        });
        if footprint_users {
            set.insert(Feature::Footprint);
        }
        for (used, feature) in [
            (Material::has_bump as fn(&Material) -> bool, Feature::Bump),
            (Material::has_opacity, Feature::Opacity),
            (Material::has_emission, Feature::Emission),
        ] {
            if scene.materials().any(used) {
                set.insert(feature);
            }
        }
        Self(set)
    }

    /// For the noise harness: exactly what evaluating `noise` needs.
    pub fn for_noise(noise: &NoiseSettings) -> Self {
        Self(noise_features(noise).into_iter().collect())
    }

    /// For the noise harness: [`FeatureSet::for_noise`] and the footprint
    /// rule for octaves.
    pub fn for_noise_harness(noise: &NoiseSettings) -> Self {
        let mut set = Self::for_noise(noise);
        set.0.insert(Feature::Footprint);
        set
    }

    /// For swatches: what evaluating `textures` alone needs (their
    /// patterns and noise), point sampled (no footprint).
    pub fn for_textures(textures: &[Texture]) -> Self {
        Self(
            textures
                .iter()
                .flat_map(Texture::patterns)
                .flat_map(pattern_features)
                .collect(),
        )
    }

    /// For the texture harness: every pattern of the texture library (and
    /// the 3D checker), and what the `noise` their turbulence uses needs.
    pub fn for_texture_library(noise: &NoiseSettings) -> Self {
        let mut set = Self::for_noise(noise);
        set.0.insert(Feature::Pattern(PatternKind::Checker));
        set.0.extend(
            PATTERNS
                .iter()
                .filter(|row| row.uses_library)
                .map(|row| Feature::Pattern(row.kind)),
        );
        set
    }
}

/// Whether an emissive sphere or triangle is in the scene: the light table
/// then holds area lights (`lights::LightTable`).
fn has_area_lights(scene: &Scene) -> bool {
    let emits = |m: &Material| marbre_core::lights::emitted_luminance(m) > 0.0;
    scene.spheres.iter().any(|s| emits(&s.material))
        || scene.meshes.iter().any(|mesh| {
            let emissive: Vec<bool> = mesh.materials.iter().map(|m| emits(&m.material)).collect();
            mesh.geometry
                .0
                .materials
                .iter()
                .any(|&m| emissive.get(m as usize).copied().unwrap_or(false))
        })
}

fn noise_features(noise: &NoiseSettings) -> Vec<Feature> {
    let mut out = match (noise.kind, noise.hash) {
        (NoiseKind::Perlin | NoiseKind::PerlinMassal, _) => vec![Feature::NoisePerlin],
        (NoiseKind::Gradient, HashKind::Pcg | HashKind::PcgTiled) => {
            vec![Feature::NoiseGradient, Feature::HashPcg]
        }
        (NoiseKind::Gradient, HashKind::Sin) => vec![Feature::NoiseGradient, Feature::HashSin],
    };
    if noise.fractal.distortion != 0.0 {
        out.push(Feature::NoiseWarp);
    }
    if noise.evolution.is_some() {
        out.push(Feature::NoiseEvolve);
    }
    out
}

fn pattern_features(p: &Pattern) -> Vec<Feature> {
    let mut out = match p.info().define {
        Some(_) => vec![Feature::Pattern(p.kind())],
        None => vec![],
    };
    if let Some(n) = p.noise() {
        out.extend(noise_features(n));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use marbre_core::noise::NoiseSettings;
    use marbre_core::scene::{Sphere, Texture};

    #[test]
    fn an_empty_scene_needs_nothing() {
        assert!(FeatureSet::for_scene(&Scene::default()).0.is_empty());
    }

    #[test]
    fn opacity_emission_and_warp_follow_the_materials() {
        let mut scene = Scene::default();
        scene.spheres.push(Sphere::default());
        assert!(FeatureSet::for_scene(&scene).0.is_empty());
        let m = &mut scene.spheres[0].material;
        m.opacity = Texture::scalar(0.5);
        m.emission = Texture::color(glam::Vec3::ONE);
        m.roughness = Texture::blend(
            Pattern::Ridged {
                noise: NoiseSettings {
                    fractal: marbre_core::noise::FractalParams {
                        distortion: 0.5,
                        ..Default::default()
                    },
                    ..Default::default()
                },
            },
            0.0,
            1.0,
        );
        let set = FeatureSet::for_scene(&scene);
        for f in [
            Feature::Opacity,
            Feature::Emission,
            Feature::Pattern(PatternKind::Ridged),
            Feature::NoiseWarp,
        ] {
            assert!(set.contains(f), "{f:?} missing from {set:?}");
        }
    }

    /// A marble needs its pattern, its noise, and the footprint its octaves
    /// are clamped by (on or off: an override constant).
    #[test]
    fn a_perlin_marble_needs_marble_perlin_and_the_footprint() {
        let mut scene = Scene::default();
        let mut sphere = Sphere::default();
        sphere.material.diffuse = Texture {
            pattern: Pattern::Marble {
                noise: NoiseSettings {
                    kind: NoiseKind::Perlin,
                    ..Default::default()
                },
                stripe_frequency: 3.0,
            },
            ..Default::default()
        };
        scene.spheres.push(sphere);
        scene.render.clamp_octaves = false;
        let set = FeatureSet::for_scene(&scene);
        assert_eq!(
            set.0,
            [
                Feature::Pattern(PatternKind::Marble),
                Feature::NoisePerlin,
                Feature::Footprint
            ]
            .into_iter()
            .collect()
        );
    }
}
