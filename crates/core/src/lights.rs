//! The scene's lights as one table to choose from: the point light, and
//! every emissive sphere and triangle (area lights). The environment is
//! sampled on its own (`env_sampling`).
//!
//! A shading point draws one entry per light sample, either uniformly or in
//! proportion to its power (the lab's exercise 6: two panels of equal power,
//! one small and bright, one large and dim made of many triangles; picking
//! triangles uniformly starves the bright one). The table holds the
//! cumulative distribution of power, searched by bisection on the GPU
//! (`crates/core/src/lights.wgsl`).

use crate::scene::{Material, PointLight, Property, Scene, SurfacePoint};
use crate::texture::luminance;
use bytemuck::{Pod, Zeroable};
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// How a light sample picks its light: a scene setting, kept with the
/// other transport settings.
pub use crate::scene::transport::LightSelection;

/// The shader code this module is the CPU twin of (or, for a harness, runs).
pub const WGSL: crate::wgsl::WgslFile = crate::wgsl_file!("crates/core/src/lights.wgsl");

/// `Light` of `shaders/scene.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, Default, PartialEq)]
pub struct Light {
    /// [`LightKind`] as a number.
    pub kind: u32,
    /// The sphere's index, or the triangle's in the GPU triangle array.
    pub primitive: u32,
    /// The chance, choosing by power, of this light or one before it.
    pub cdf: f32,
    /// Emitted power (luminance flux, watts-like).
    pub power: f32,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u32)]
pub enum LightKind {
    Point = 0,
    Sphere = 1,
    Triangle = 2,
}

/// The lights of a scene and their power distribution.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LightTable {
    pub lights: Vec<Light>,
    pub total_power: f32,
    /// Emitters left out (zero area, no power), each named.
    pub notes: Vec<String>,
}

/// A triangle the renderer draws, with the index of its material in
/// [`Scene::materials`]: the light table reads emissive ones.
#[derive(Debug, Clone, Copy)]
pub struct EmitterTriangle {
    pub vertices: [Vec3; 3],
    pub material: u32,
}

/// Points spread over the unit cube and the unit square, where a textured
/// emission is averaged.
const AVERAGE_POINTS: u32 = 64;

/// The mean luminance a material emits: exact for a constant emission, an
/// average over fixed points for a textured one. The light table's power
/// and the density an emitter hit by a BSDF ray reports both come from
/// this one number, so multiple importance sampling stays consistent.
pub fn emitted_luminance(m: &Material) -> f32 {
    if !m.has_emission() {
        return 0.0;
    }
    let sum: f32 = (0..AVERAGE_POINTS)
        .map(|k| {
            // An R3 sequence (Roberts 2018): even cover in 3D and 2D.
            let t = k as f32 + 0.5;
            let p = Vec3::new(
                (t * 0.819_172_5).fract(),
                (t * 0.671_043_5).fract(),
                (t * 0.549_700_5).fract(),
            ) * 2.0
                - 1.0;
            let uv = Vec2::new((t * 0.754_877_7).fract(), (t * 0.569_840_3).fract());
            luminance(
                m.value_at(Property::Emission, &SurfacePoint::new(p, uv))
                    .max(Vec3::ZERO),
            )
        })
        .sum();
    let mean = sum / AVERAGE_POINTS as f32;
    if mean.is_finite() { mean } else { 0.0 }
}

impl LightTable {
    /// The table of `scene`'s lights; `triangles` are the scene's triangles
    /// in the order the GPU holds them.
    pub fn build(scene: &Scene, triangles: &[EmitterTriangle]) -> Self {
        let mut table = LightTable::default();
        let emitted: Vec<f32> = scene.materials().map(emitted_luminance).collect();
        if let Some(light) = &scene.point_light {
            table.push(LightKind::Point, 0, light.power(), "the point light");
        }
        for (i, sphere) in scene
            .spheres
            .iter()
            .enumerate()
            .take(crate::scene::MAX_SPHERES)
        {
            let l = emitted[i];
            if l > 0.0 {
                // The shaders sample a sphere through r²: a subnormal one is
                // 0 where the GPU flushes it, and so is the sphere's area.
                let r2 = sphere.radius * sphere.radius;
                let area = if r2.is_normal() { 4.0 * PI * r2 } else { 0.0 };
                table.push(
                    LightKind::Sphere,
                    i as u32,
                    PI * l * area,
                    &format!("sphere `{}`", sphere.name),
                );
            }
        }
        let mut zero_area = 0usize;
        for (i, t) in triangles.iter().enumerate() {
            let l = emitted.get(t.material as usize).copied().unwrap_or(0.0);
            if l > 0.0 {
                let area = triangle_area(&t.vertices);
                // A subnormal area is zero where the GPU flushes it.
                if area.is_normal() {
                    table.lights.push(Light {
                        kind: LightKind::Triangle as u32,
                        primitive: i as u32,
                        cdf: 0.0,
                        power: PI * l * area,
                    });
                } else {
                    zero_area += 1;
                }
            }
        }
        if zero_area > 0 {
            table.notes.push(format!(
                "{zero_area} emissive triangles with zero area are not lights (no point can be sampled on them)"
            ));
        }
        table.finish();
        table
    }

    /// Adds a light of `power`, or a note where it has none to sample:
    /// zero, subnormal (GPUs flush it to zero) or not finite.
    fn push(&mut self, kind: LightKind, primitive: u32, power: f32, what: &str) {
        if power.is_normal() && power > 0.0 {
            self.lights.push(Light {
                kind: kind as u32,
                primitive,
                cdf: 0.0,
                power,
            });
        } else {
            self.notes
                .push(format!("{what} gives no light: left out of light sampling"));
        }
    }

    /// Fills the cumulative distribution, summed in f64 so that a million
    /// small triangles after a bright one keep their share; the last entry
    /// is exactly 1.
    fn finish(&mut self) {
        let total: f64 = self.lights.iter().map(|l| f64::from(l.power)).sum();
        self.total_power = total as f32;
        let mut running = 0.0f64;
        for l in &mut self.lights {
            running += f64::from(l.power);
            l.cdf = (running / total) as f32;
        }
        if let Some(last) = self.lights.last_mut() {
            last.cdf = 1.0;
        }
    }

    /// The chance of choosing light `index` (the CPU twin of `light_pmf`).
    pub fn pmf(&self, index: usize, selection: LightSelection) -> f32 {
        match selection {
            LightSelection::Uniform => 1.0 / self.lights.len() as f32,
            LightSelection::Power => self.lights[index].power / self.total_power,
        }
    }

    /// The light a uniform number `u` in [0, 1) picks (the CPU twin of
    /// `choose_light`): the first whose cdf exceeds u, by bisection.
    pub fn choose(&self, u: f32, selection: LightSelection) -> usize {
        let n = self.lights.len();
        match selection {
            LightSelection::Uniform => ((u * n as f32) as usize).min(n - 1),
            LightSelection::Power => self.lights.partition_point(|l| l.cdf <= u).min(n - 1),
        }
    }
}

impl PointLight {
    /// The power the light table gives the light: 4π times the luminance
    /// of its intensity.
    pub fn power(&self) -> f32 {
        4.0 * PI * luminance(self.color * self.intensity)
    }

    /// A light the table would leave out for a value that is no number
    /// (a NaN or infinite position, colour or intensity, or a power past
    /// f32) is fixed at load with a note, as every other value no control
    /// produces: the table dropped it, and its note reached no one.
    pub fn sanitize(&mut self, notes: &mut Vec<String>) {
        if !self.position.is_finite() {
            notes.push(format!(
                "point light: non-finite position {} set to 0",
                self.position
            ));
            self.position = Vec3::ZERO;
        }
        if !self.color.is_finite() {
            notes.push(format!(
                "point light: non-finite colour {} set to 0 (no light)",
                self.color
            ));
            self.color = Vec3::ZERO;
        }
        if !self.intensity.is_finite() {
            notes.push(format!(
                "point light: non-finite intensity {} set to 0 (no light)",
                self.intensity
            ));
            self.intensity = 0.0;
        }
        if !self.power().is_finite() {
            notes.push(format!(
                "point light: intensity {} times colour {} is past f32's range: intensity set \
                 to 0 (no light)",
                self.intensity, self.color
            ));
            self.intensity = 0.0;
        }
    }
}

pub fn triangle_area(v: &[Vec3; 3]) -> f32 {
    0.5 * (v[1] - v[0]).cross(v[2] - v[0]).length()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Sphere, Texture};

    fn emitter(radiance: f32) -> Material {
        Material {
            emission: Texture::color(Vec3::splat(radiance)),
            ..Material::default()
        }
    }

    /// Two emitters of equal power, one small and bright, one large and
    /// dim: by power they are chosen equally often, whatever their sizes.
    #[test]
    fn power_selection_follows_power_not_size() {
        let scene = Scene {
            spheres: vec![
                Sphere {
                    radius: 0.1,
                    material: emitter(100.0),
                    ..Sphere::default()
                },
                Sphere {
                    radius: 1.0,
                    material: emitter(1.0),
                    ..Sphere::default()
                },
                Sphere::default(),
            ],
            ..Scene::default()
        };
        let table = LightTable::build(&scene, &[]);
        assert_eq!(table.lights.len(), 2, "the plain sphere is no light");
        assert!((table.pmf(0, LightSelection::Power) - 0.5).abs() < 1e-5);
        assert_eq!(table.pmf(1, LightSelection::Uniform), 0.5);
        let n = 10_000;
        let first = (0..n)
            .filter(|k| table.choose((*k as f32 + 0.5) / n as f32, LightSelection::Power) == 0)
            .count();
        assert!((first as f32 / n as f32 - 0.5).abs() < 1e-3, "{first}");
    }

    /// Zero-area emitters never enter the table (their pdf would divide by
    /// zero) and are reported.
    #[test]
    fn zero_area_emitters_are_left_out_with_a_note() {
        let scene = Scene {
            spheres: vec![Sphere {
                material: emitter(1.0),
                ..Sphere::default()
            }],
            ..Scene::default()
        };
        let flat = EmitterTriangle {
            vertices: [Vec3::ZERO, Vec3::X, Vec3::X * 2.0],
            material: 0,
        };
        let table = LightTable::build(&scene, &[flat]);
        assert_eq!(table.lights.len(), 1);
        assert!(table.notes[0].contains("zero area"), "{:?}", table.notes);
    }

    /// Emitters too small for f32 (a sphere of radius 1e-19, whose r² is
    /// subnormal; a triangle of 1e-20 on a side) count as zero-area: the
    /// GPU flushes such values to 0, where a pdf would divide by them.
    #[test]
    fn emitters_of_subnormal_area_are_left_out_with_a_note() {
        let scene = Scene {
            spheres: vec![Sphere {
                radius: 1e-19,
                material: emitter(1.0),
                ..Sphere::default()
            }],
            ..Scene::default()
        };
        let tiny = EmitterTriangle {
            vertices: [Vec3::ZERO, Vec3::X * 1e-20, Vec3::Y * 1e-20],
            material: 0,
        };
        let table = LightTable::build(&scene, &[tiny]);
        assert!(table.lights.is_empty(), "{:?}", table.lights);
        assert_eq!(table.notes.len(), 2, "{:?}", table.notes);
    }

    /// A point light of an infinite or NaN value, or whose power is past
    /// f32, is fixed at load with a note (the table left it out, and its
    /// note was shown nowhere); a plain one is kept and noted nowhere.
    #[test]
    fn a_point_light_of_no_number_is_noted_at_load() {
        let light = |position: Vec3, color: Vec3, intensity: f32| Scene {
            point_light: Some(PointLight {
                position,
                color,
                intensity,
            }),
            ..Scene::default()
        };
        let cases = [
            (
                light(Vec3::ONE, Vec3::ONE, f32::INFINITY),
                "non-finite intensity inf",
            ),
            (
                light(Vec3::ONE, Vec3::ONE, f32::NAN),
                "non-finite intensity NaN",
            ),
            (
                light(Vec3::ONE, Vec3::new(1.0, f32::NAN, 1.0), 1.0),
                "non-finite colour",
            ),
            (
                light(Vec3::splat(f32::INFINITY), Vec3::ONE, 1.0),
                "non-finite position",
            ),
            (light(Vec3::ONE, Vec3::ONE, 3e38), "past f32's range"),
        ];
        for (mut scene, expected) in cases {
            let notes = scene.sanitize();
            assert!(
                notes
                    .iter()
                    .any(|n| n.starts_with("point light: ") && n.contains(expected)),
                "{expected}: {notes:?}"
            );
            let light = scene.point_light.as_ref().unwrap();
            assert!(light.position.is_finite() && light.power().is_finite());
            assert_eq!(
                LightTable::build(&scene, &[]).lights.len(),
                usize::from(light.power() > 0.0)
            );
        }
        let mut plain = light(Vec3::ONE, Vec3::ONE, 40.0);
        assert_eq!(plain.sanitize(), Vec::<String>::new());
        assert_eq!(LightTable::build(&plain, &[]).lights.len(), 1);
    }

    /// The pmf sums to one in both modes, and bisection inverts the cdf.
    #[test]
    fn choice_matches_the_pmf() {
        let triangles: Vec<EmitterTriangle> = (1..=5)
            .map(|k| EmitterTriangle {
                vertices: [Vec3::ZERO, Vec3::X * k as f32, Vec3::Y],
                material: 0,
            })
            .collect();
        // Material 0, the sphere's, is the triangles' too.
        let scene = Scene {
            spheres: vec![Sphere {
                material: emitter(2.0),
                ..Sphere::default()
            }],
            ..Scene::default()
        };
        let table = LightTable::build(&scene, &triangles);
        assert_eq!(table.lights.len(), 6);
        for selection in LightSelection::ALL {
            let sum: f32 = (0..6).map(|i| table.pmf(i, selection)).sum();
            assert!((sum - 1.0).abs() < 1e-5);
            let n = 60_000;
            let mut counts = [0usize; 6];
            for k in 0..n {
                counts[table.choose((k as f32 + 0.5) / n as f32, selection)] += 1;
            }
            for (i, c) in counts.iter().enumerate() {
                let expected = table.pmf(i, selection);
                assert!(
                    (*c as f32 / n as f32 - expected).abs() < 1e-3,
                    "{selection:?} {i}"
                );
            }
        }
    }
}
