//! How a preset writes its colours: as linear reflectances (what the
//! renderer multiplies light by) or as display values, sRGB-encoded, the way
//! the course documents and colour pickers write them (the texture report's
//! brown wood `0.54 0.27 0.0742` is a display colour: read as linear it
//! shows orange-cream).
//!
//! In memory every colour is linear; a preset marked [`ColorEncoding::Srgb`]
//! is decoded once when read and encoded again when written, so its numbers
//! stay the ones its author typed. Only colours are converted: the colour
//! properties' trees (their values, greys and ramp stops, not the scalar
//! factors and masks inside them) and the point light's colour. Radiance
//! (an environment's constant, emission strengths) is physical and stays.

use super::{Child, Material, Property, Scene, Texture};
use glam::Vec3;
use serde::{Deserialize, Serialize};

/// How the colours of a preset file are written. Files without the field
/// are linear: what every preset before it meant.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum ColorEncoding {
    #[default]
    Linear,
    /// sRGB-encoded display values, decoded with the exact sRGB EOTF.
    Srgb,
}

impl ColorEncoding {
    /// The linear colour a value written in this encoding means.
    pub fn decode(self, c: Vec3) -> Vec3 {
        match self {
            ColorEncoding::Linear => c,
            ColorEncoding::Srgb => c.map(srgb_decode),
        }
    }

    /// How a linear colour is written in this encoding.
    pub fn encode(self, c: Vec3) -> Vec3 {
        match self {
            ColorEncoding::Linear => c,
            ColorEncoding::Srgb => c.map(srgb_encode),
        }
    }

    /// Rewrites every colour of `scene` from this encoding to linear.
    pub fn decode_scene(self, scene: &mut Scene) {
        if self != ColorEncoding::Linear {
            map_scene_colors(scene, &|c| self.decode(c));
        }
    }

    /// Rewrites every colour of `scene` from linear to this encoding.
    pub fn encode_scene(self, scene: &mut Scene) {
        if self != ColorEncoding::Linear {
            map_scene_colors(scene, &|c| self.encode(c));
        }
    }
}

/// The sRGB EOTF (IEC 61966-2-1), computed in f64 so that a typed value
/// decodes to its linear value to f32 precision. Mirrored for negative
/// values and continued past 1 (emission colours), so that it stays
/// invertible everywhere.
pub fn srgb_decode(c: f32) -> f32 {
    let x = f64::from(c).abs();
    let linear = if x <= 0.04045 {
        x / 12.92
    } else {
        ((x + 0.055) / 1.055).powf(2.4)
    };
    (linear.copysign(f64::from(c))) as f32
}

/// The inverse of [`srgb_decode`].
pub fn srgb_encode(c: f32) -> f32 {
    let x = f64::from(c).abs();
    let encoded = if x <= 0.0031308 {
        x * 12.92
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    };
    (encoded.copysign(f64::from(c))) as f32
}

fn map_scene_colors(scene: &mut Scene, f: &dyn Fn(Vec3) -> Vec3) {
    for material in scene.materials_mut() {
        map_material_colors(material, f);
    }
    for mesh in &mut scene.meshes {
        for m in &mut mesh.materials {
            // The file's material is compared with the edited one to decide
            // whether the preset stores an override: both must be in the
            // same encoding.
            if let Some(from_file) = &mut m.from_file {
                map_material_colors(from_file, f);
            }
        }
    }
    if let Some(light) = &mut scene.point_light {
        light.color = f(light.color);
    }
}

/// Maps the colour properties of a material and of its layers.
pub fn map_material_colors(material: &mut Material, f: &dyn Fn(Vec3) -> Vec3) {
    for property in Property::ALL.into_iter().filter(|p| p.is_color()) {
        map_texture_colors(material.texture_mut(property), f);
        for layer in &mut material.layers {
            if let Some(texture) = layer.slot_mut(property) {
                map_texture_colors(texture, f);
            }
        }
    }
}

/// Maps the colours of a colour texture: its children's values (a scalar
/// child is a grey) and its ramp stops, through nested textures; a mix's
/// factor is a scalar and is left alone.
fn map_texture_colors(texture: &mut Texture, f: &dyn Fn(Vec3) -> Vec3) {
    for child in [&mut texture.a, &mut texture.b] {
        match child {
            Child::Scalar(v) => *v = f(Vec3::splat(*v)).x,
            Child::Color(c) => *c = f(*c),
            Child::Texture(t) => map_texture_colors(t, f),
        }
    }
    for stop in &mut texture.ramp {
        stop.color = f(stop.color);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Layer, Pattern, PointLight, Sphere};

    /// The sRGB EOTF written from IEC 61966-2-1 in f64, independently.
    fn eotf(v: f64) -> f64 {
        if v <= 0.04045 {
            v / 12.92
        } else {
            ((v + 0.055) / 1.055).powf(2.4)
        }
    }

    #[test]
    fn decoding_matches_the_standard_and_encoding_inverts_it() {
        for v in [0.0, 0.02, 0.04045, 0.0742, 0.27, 0.5, 0.54, 1.0, 3.0] {
            let d = srgb_decode(v as f32) as f64;
            assert!((d - eotf(v)).abs() < 1e-7 * eotf(v).max(1.0), "{v}: {d}");
            assert!((srgb_encode(d as f32) - v as f32).abs() < 1e-6, "{v}");
        }
        assert_eq!(srgb_decode(0.5), -srgb_decode(-0.5));
        assert!((srgb_decode(0.5) - 0.214_041_14).abs() < 1e-7);
    }

    fn scene() -> Scene {
        let mut material = Material {
            diffuse: Texture::blend(
                Pattern::Checker { size: 1.0 },
                Vec3::new(0.54, 0.27, 0.0742),
                Texture::mix(Texture::scalar(0.5), 0.5, Vec3::ONE),
            ),
            roughness: Texture::scalar(0.5),
            ..Material::default()
        };
        material.layers.push(Layer {
            mask: Texture::scalar(0.5),
            emission: Some(Texture::color(Vec3::splat(0.5))),
            ..Layer::default()
        });
        Scene {
            spheres: vec![Sphere {
                material,
                ..Sphere::default()
            }],
            point_light: Some(PointLight {
                color: Vec3::splat(0.5),
                ..PointLight::default()
            }),
            ..Scene::default()
        }
    }

    #[test]
    fn srgb_decodes_colours_and_greys_but_not_scalars_factors_or_masks() {
        let mut s = scene();
        ColorEncoding::Srgb.decode_scene(&mut s);
        let m = &s.spheres[0].material;
        let half = srgb_decode(0.5);
        assert_eq!(
            m.diffuse.a,
            Child::Color(Vec3::new(
                srgb_decode(0.54),
                srgb_decode(0.27),
                srgb_decode(0.0742)
            ))
        );
        let Child::Texture(mix) = &m.diffuse.b else {
            panic!()
        };
        assert_eq!(mix.a, Child::Scalar(half));
        assert_eq!(mix.factor.as_deref(), Some(&Texture::scalar(0.5)));
        assert_eq!(m.roughness, Texture::scalar(0.5));
        assert_eq!(m.layers[0].mask, Texture::scalar(0.5));
        assert_eq!(
            m.layers[0].emission,
            Some(Texture::color(Vec3::splat(half)))
        );
        assert_eq!(s.point_light.unwrap().color, Vec3::splat(half));
    }

    #[test]
    fn linear_leaves_the_scene_and_srgb_round_trips() {
        let mut s = scene();
        ColorEncoding::Linear.decode_scene(&mut s);
        assert_eq!(s, scene());
        ColorEncoding::Srgb.decode_scene(&mut s);
        assert_ne!(s, scene());
        ColorEncoding::Srgb.encode_scene(&mut s);
        let original = scene();
        let (Child::Color(a), Child::Color(b)) = (
            &s.spheres[0].material.diffuse.a,
            &original.spheres[0].material.diffuse.a,
        ) else {
            panic!()
        };
        assert!((*a - *b).abs().max_element() < 1e-6);
    }
}
