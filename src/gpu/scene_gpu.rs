//! The scene flattened into the std140/std430 structs of `shaders/scene.wgsl`.

use crate::noise::{HashKind, NoiseKind};
use crate::scene::{ColorTexture, EnvSource, Material, Pattern, ScalarTexture, Scene};
use bytemuck::{Pod, Zeroable};

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct FrameUniform {
    pub cam_pos: [f32; 3],
    pub tan_half_fov: f32,
    pub cam_right: [f32; 3],
    pub aspect: f32,
    pub cam_up: [f32; 3],
    pub frame_index: u32,
    pub cam_forward: [f32; 3],
    pub accumulated: u32,
    pub light_pos: [f32; 3],
    pub env_intensity: f32,
    pub light_power: [f32; 3],
    pub env_rotation: f32,
    pub env_constant: [f32; 3],
    pub background_visible: u32,
    pub ground_height: f32,
    pub sphere_count: u32,
    pub samples_per_frame: u32,
    pub max_bounces: u32,
    pub render_size: [f32; 2],
    pub env_kind: u32,
    pub has_ground: u32,
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, Default)]
pub struct TextureGpu {
    pub kind: u32,
    pub noise_kind: u32,
    pub hash: u32,
    pub octaves: f32,
    pub frequency: f32,
    pub amplitude: f32,
    pub persistence: f32,
    pub lacunarity: f32,
    pub param: f32,
    pub _pad: [f32; 3],
    pub a: [f32; 4],
    pub b: [f32; 4],
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, Default)]
pub struct MaterialGpu {
    pub diffuse: TextureGpu,
    pub specular: TextureGpu,
    pub roughness: TextureGpu,
    pub mirror: f32,
    pub _pad: [f32; 3],
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, Default)]
pub struct SphereGpu {
    pub center: [f32; 3],
    pub radius: f32,
}

pub fn noise_kind_id(k: NoiseKind) -> u32 {
    match k {
        NoiseKind::Gradient => 0,
        NoiseKind::Perlin => 1,
    }
}

pub fn hash_id(h: HashKind) -> u32 {
    match h {
        HashKind::Pcg => 0,
        HashKind::Sin => 1,
    }
}

fn texture(pattern: &Pattern, a: [f32; 3], b: [f32; 3]) -> TextureGpu {
    let mut t = TextureGpu {
        kind: pattern.index() as u32,
        a: [a[0], a[1], a[2], 0.0],
        b: [b[0], b[1], b[2], 0.0],
        ..Default::default()
    };
    if let Some(n) = pattern.noise() {
        t.noise_kind = noise_kind_id(n.kind);
        t.hash = hash_id(n.hash);
        t.octaves = n.fractal.octaves;
        t.frequency = n.fractal.frequency;
        t.amplitude = n.fractal.amplitude;
        t.persistence = n.fractal.persistence;
        t.lacunarity = n.fractal.lacunarity;
    }
    t.param = match *pattern {
        Pattern::Checker { size } => size,
        Pattern::Marble {
            stripe_frequency, ..
        } => stripe_frequency,
        _ => 0.0,
    };
    t
}

fn color(c: &ColorTexture) -> TextureGpu {
    texture(&c.pattern, c.a.to_array(), c.b.to_array())
}

fn scalar(s: &ScalarTexture) -> TextureGpu {
    texture(&s.pattern, [s.a; 3], [s.b; 3])
}

pub fn material(m: &Material) -> MaterialGpu {
    MaterialGpu {
        diffuse: color(&m.diffuse),
        specular: color(&m.specular),
        roughness: scalar(&m.roughness),
        mirror: m.mirror,
        _pad: [0.0; 3],
    }
}

/// Materials in the order the shader indexes them; never empty, because a
/// storage binding may not be.
pub fn materials(scene: &Scene) -> Vec<MaterialGpu> {
    let mut out: Vec<_> = scene.materials().map(material).collect();
    if out.is_empty() {
        out.push(MaterialGpu::default());
    }
    out
}

/// Spheres, padded to one element when there are none.
pub fn spheres(scene: &Scene) -> Vec<SphereGpu> {
    let mut out: Vec<_> = scene
        .spheres
        .iter()
        .map(|s| SphereGpu {
            center: s.center.to_array(),
            radius: s.radius,
        })
        .collect();
    if out.is_empty() {
        out.push(SphereGpu::default());
    }
    out
}

/// Per-frame values: camera, lights, counters.
pub fn frame_uniform(
    scene: &Scene,
    render_size: (u32, u32),
    frame_index: u32,
    accumulated: u32,
) -> FrameUniform {
    let cam = scene.camera.frame();
    let (w, h) = (render_size.0.max(1) as f32, render_size.1.max(1) as f32);
    // No light: zero power, so an uber shader that compiles the light in adds nothing.
    let (light_pos, light_power) = scene
        .point_light
        .as_ref()
        .map_or(([0.0; 3], [0.0; 3]), |l| {
            (l.position.to_array(), (l.color * l.intensity).to_array())
        });
    let env = &scene.environment;
    let env_constant = match env.source {
        EnvSource::Constant { radiance } => radiance.to_array(),
        _ => [0.0; 3],
    };
    FrameUniform {
        cam_pos: cam.position.to_array(),
        tan_half_fov: cam.tan_half_fov,
        cam_right: cam.right.to_array(),
        aspect: w / h,
        cam_up: cam.up.to_array(),
        frame_index,
        cam_forward: cam.forward.to_array(),
        accumulated,
        light_pos,
        env_intensity: env.intensity,
        light_power,
        env_rotation: env.rotation_degrees.to_radians(),
        env_constant,
        background_visible: u32::from(env.background_visible),
        ground_height: scene.ground.as_ref().map_or(0.0, |g| g.height),
        sphere_count: scene.spheres.len() as u32,
        samples_per_frame: scene.render.samples_per_frame.max(1),
        max_bounces: scene.render.max_bounces.max(1),
        render_size: [w, h],
        env_kind: match env.source {
            EnvSource::None => 0,
            EnvSource::Constant { .. } => 1,
            EnvSource::LatLong { .. } => 2,
        },
        has_ground: u32::from(scene.ground.is_some()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn struct_sizes_match_the_wgsl_layout() {
        // Sizes computed by hand from shaders/scene.wgsl's alignment rules.
        assert_eq!(std::mem::size_of::<FrameUniform>(), 144);
        assert_eq!(std::mem::size_of::<TextureGpu>(), 80);
        assert_eq!(std::mem::size_of::<MaterialGpu>(), 256);
        assert_eq!(std::mem::size_of::<SphereGpu>(), 16);
    }
}
