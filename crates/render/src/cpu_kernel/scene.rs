//! The scene as the CPU kernel reads it: the spheres, the ground and the
//! meshes' BVH (the very triangles and attributes uploaded for the GPU,
//! in BVH order), the light table, and each material either evaluated
//! once (no pattern anywhere in it: the common case of OBJ scenes, the
//! CPU kernel's specialisation) or kept as its texture trees, evaluated
//! at each hit by the CPU reference (`Material::value_at`).

use crate::gpu::features::{Feature, FeatureSet};
use crate::gpu::mesh_buffers::MeshGeometry;
use glam::{Vec2, Vec3};
use marbre_core::bsdf::Surface;
use marbre_core::lights::{LightSelection, LightTable, emitted_luminance};
use marbre_core::scene::{Ground, Material, Pattern, Property, Scene, Strategy, SurfacePoint};
use std::sync::Arc;

/// Why the CPU kernel cannot trace `scene`, or `Ok`: it traces spheres,
/// the ground and meshes, under the point light, area lights and a
/// constant sky, with the patterns a point determines (no noise, no
/// filtered pattern, no image, no bump, no environment map), recording
/// the lit image.
pub fn support(scene: &Scene) -> Result<(), String> {
    let patterns: Vec<&Pattern> = scene.materials().flat_map(Material::patterns).collect();
    let lacking = if !scene.cylinders.is_empty() {
        Some("cylinders")
    } else if !scene.polygons.is_empty() {
        Some("polygons")
    } else if scene.environment.source.is_map() {
        Some("an environment map")
    } else if scene.render.view != marbre_core::scene::View::Lit {
        Some("a view other than the lit image")
    } else if scene.materials().any(Material::has_bump) {
        Some("bump mapping")
    } else if patterns.iter().any(|p| matches!(p, Pattern::Image { .. })) {
        Some("image textures")
    } else if patterns
        .iter()
        .any(|p| p.noise().is_some() || p.info().filtered)
    {
        // The GPU kernels filter these over the ray cone's footprint (box-
        // filtered checkers, octaves clamped to the pixel); the CPU
        // reference evaluates them at points.
        Some("noise or filtered patterns")
    } else {
        None
    };
    match lacking {
        Some(what) => Err(format!("the CPU kernel does not trace {what}")),
        None => Ok(()),
    }
}

/// A material's clamped values at one point, as `surface_at` in
/// shaders/surface.wgsl leaves them.
#[derive(Clone, Copy)]
pub struct SurfaceValues {
    pub bsdf: Surface,
    pub opacity: f32,
    pub transmission: Vec3,
    pub emission: Vec3,
}

/// A material, specialised: its values once where nothing in it varies.
pub enum CpuMaterial {
    Constant(SurfaceValues),
    Textured(Box<Material>),
}

impl CpuMaterial {
    fn of(m: &Material, uniform_diffuse: bool) -> Self {
        if m.patterns()
            .iter()
            .all(|p| **p == marbre_core::scene::Pattern::Constant)
        {
            let at = SurfacePoint::new(Vec3::ZERO, Vec2::ZERO);
            CpuMaterial::Constant(values(m, &at, uniform_diffuse))
        } else {
            CpuMaterial::Textured(Box::new(m.clone()))
        }
    }

    pub fn at(&self, point: &SurfacePoint, uniform_diffuse: bool) -> SurfaceValues {
        match self {
            CpuMaterial::Constant(v) => *v,
            CpuMaterial::Textured(m) => values(m, point, uniform_diffuse),
        }
    }

    /// The emitted radiance alone (`surface_emission`).
    pub fn emission_at(&self, point: &SurfacePoint) -> Vec3 {
        match self {
            CpuMaterial::Constant(v) => v.emission,
            CpuMaterial::Textured(m) => m.value_at(Property::Emission, point).max(Vec3::ZERO),
        }
    }

    /// Whether every texture of it is a constant (its values are kept).
    pub fn is_constant(&self) -> bool {
        matches!(self, CpuMaterial::Constant(_))
    }
}

/// `surface_at`'s clamping of a material's values.
fn values(m: &Material, at: &SurfacePoint, uniform_diffuse: bool) -> SurfaceValues {
    let v = |p| m.value_at(p, at);
    let unit = |c: Vec3| c.clamp(Vec3::ZERO, Vec3::ONE);
    SurfaceValues {
        bsdf: Surface {
            diffuse: unit(v(Property::Diffuse)),
            specular: unit(v(Property::Specular)),
            alpha: Surface::alpha_for(v(Property::Roughness).x),
            mirror: v(Property::Mirror).x.clamp(0.0, 1.0),
            uniform_diffuse,
            diffuse_transmission: unit(v(Property::DiffuseTransmission)),
        },
        opacity: v(Property::Opacity).x.clamp(0.0, 1.0),
        transmission: unit(v(Property::Transmission)),
        emission: v(Property::Emission).max(Vec3::ZERO),
    }
}

#[derive(Clone, Copy)]
pub struct CpuSphere {
    pub center: Vec3,
    pub radius: f32,
}

/// Everything the CPU kernel reads of a scene besides the frame uniform.
pub struct CpuScene {
    pub spheres: Vec<CpuSphere>,
    pub ground: Option<Ground>,
    /// In `Scene::materials`' order, as the shader indexes them.
    pub materials: Vec<CpuMaterial>,
    /// Each material's mean emitted luminance (the light table's and
    /// `emitter_pdf`'s `emitted_luminance`).
    pub emitted: Vec<f32>,
    pub mesh: Arc<MeshGeometry>,
    pub lights: LightTable,
    pub strategy: Strategy,
    pub selection: LightSelection,
    /// The shader features the CPU kernel follows: whether any material
    /// may be less than opaque (`OPACITY`), may emit (`EMISSION`), and
    /// whether emitters are in the light table (`AREA_LIGHT`).
    pub opacity: bool,
    pub emission: bool,
    pub area_lights: bool,
}

impl CpuScene {
    /// `scene` with the meshes and light table the renderer built for it.
    pub fn new(scene: &Scene, mesh: Arc<MeshGeometry>, lights: &LightTable) -> Self {
        let transport = &scene.render.transport;
        let strategy = transport.effective_strategy();
        let uniform_diffuse = strategy == Strategy::Hemisphere;
        let features = FeatureSet::for_scene(scene);
        Self {
            spheres: scene
                .spheres
                .iter()
                .take(marbre_core::scene::MAX_SPHERES)
                .map(|s| CpuSphere {
                    center: s.center,
                    radius: s.radius,
                })
                .collect(),
            ground: scene.ground.clone(),
            materials: scene
                .materials()
                .map(|m| CpuMaterial::of(m, uniform_diffuse))
                .collect(),
            emitted: scene.materials().map(emitted_luminance).collect(),
            mesh,
            lights: lights.clone(),
            strategy,
            selection: transport.light_selection,
            opacity: features.contains(Feature::Opacity),
            emission: features.contains(Feature::Emission),
            area_lights: features.contains(Feature::AreaLight),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use marbre_core::noise::NoiseSettings;
    use marbre_core::scene::{Cylinder, EnvSource, Sphere, Texture, View};
    use std::path::PathBuf;

    fn lit_sphere() -> Scene {
        let mut scene = Scene {
            spheres: vec![Sphere::default()],
            ..Default::default()
        };
        scene.environment.source = EnvSource::Constant {
            radiance: Vec3::ONE,
        };
        scene
    }

    /// What the CPU kernel traces is said, and each thing it does not is
    /// named.
    #[test]
    fn support_names_what_the_cpu_kernel_does_not_trace() {
        assert_eq!(support(&lit_sphere()), Ok(()));
        let refused = |edit: &dyn Fn(&mut Scene), what: &str| {
            let mut scene = lit_sphere();
            edit(&mut scene);
            let why = support(&scene).unwrap_err();
            assert!(why.contains(what), "{why} (expected {what})");
        };
        refused(&|s| s.cylinders.push(Cylinder::default()), "cylinders");
        refused(
            &|s| {
                s.environment.source = EnvSource::LatLong {
                    path: PathBuf::from("sky.exr"),
                }
            },
            "environment map",
        );
        refused(&|s| s.render.view = View::Normal, "view");
        refused(
            &|s| {
                s.spheres[0].material.diffuse = Texture::blend(
                    Pattern::Fbm {
                        noise: NoiseSettings::default(),
                    },
                    Vec3::ZERO,
                    Vec3::ONE,
                )
            },
            "noise",
        );
        refused(
            &|s| {
                s.spheres[0].material.bump =
                    Texture::blend(Pattern::Checker { size: 0.5 }, 0.0, 1.0)
            },
            "bump",
        );
    }

    /// A material of constants is evaluated once; one with a pattern at
    /// each hit.
    #[test]
    fn constant_materials_are_evaluated_once() {
        let scene = lit_sphere();
        assert!(CpuMaterial::of(&scene.spheres[0].material, false).is_constant());
        let mut marble = scene.spheres[0].material.clone();
        marble.diffuse = Texture::blend(Pattern::Checker { size: 0.5 }, Vec3::ZERO, Vec3::ONE);
        assert!(!CpuMaterial::of(&marble, false).is_constant());
    }
}
