//! The scene flattened into the std140/std430 structs of `shaders/scene.wgsl`.

use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use marbre_core::lights::LightSelection;
use marbre_core::noise::{
    Evolution, FractalShape, HashKind, NoiseKind, NoiseSettings, Progression,
};
use marbre_core::scene::pattern::MAX_SIGNALS;
use marbre_core::scene::primitives::MAX_POLYGON_VERTICES;
use marbre_core::scene::{
    self as model, EnvSource, Ground, Integrator, MAX_CYLINDERS, MAX_POLYGONS, MAX_SPHERES,
    MappingSpace, Scene,
};
use marbre_core::tile::Tile;

/// The step between the seeds of consecutive samples of a pixel: the
/// golden-ratio constant `shaders/trace.wgsl` multiplies the sample's
/// number by (`(accumulated + k) · φ + frame_index`), which the renderer's
/// restarts and the CPU kernel's seeds follow too.
pub const SAMPLE_SEED_STEP: u32 = 0x9E37_79B9;

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct Frame {
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
    pub cylinder_count: u32,
    pub polygon_count: u32,
    /// The angle a pixel subtends at the camera: the spread of ray cones.
    pub pixel_spread: f32,
    /// Non-zero: sample the environment map by its luminance (MIS).
    pub env_sampling: u32,
    /// Cells of the environment's sampling distribution (width, height).
    pub env_distribution_size: [u32; 2],
    /// The light table's length, how it is sampled (0 uniform, 1 by power)
    /// and its total power.
    pub light_count: u32,
    pub light_selection: u32,
    pub light_total_power: f32,
    pub light_samples: u32,
    /// `scene::Strategy::id`.
    pub strategy: u32,
    pub russian_roulette_from: u32,
    pub triangle_count: u32,
    /// Always 1.0, but a uniform: see `compensated_mean_update` in
    /// `shaders/accumulation.wgsl`.
    pub opaque_one: f32,
    /// The firefly clamp on a sample's largest channel; 0: off.
    pub sample_clamp: f32,
    /// The rows `band_start..band_end` a trace pass covers (the compute
    /// kernel reads them; the fragment kernel's scissor matches).
    pub band_start: u32,
    pub band_end: u32,
    /// `scene::View::id`: what each sample records.
    pub view: u32,
    /// `scene::LightPoints::id`: where light samples lie on their light.
    pub light_points: u32,
    /// The depth view's d in t / (t + d): the camera's distance to its
    /// target.
    pub depth_scale: f32,
    /// The ground's (u, v) frame (`Ground::frame`; world x, z without one).
    pub ground_uv_origin: [f32; 3],
    /// An orthographic camera's half-height in scene units
    /// (`CameraFrame::ortho_half_height`); 0 for perspective. In the
    /// padding after the ground's origin.
    pub ortho_half_height: f32,
    pub ground_uv_u: [f32; 3],
    pub _pad_ground1: f32,
    pub ground_uv_v: [f32; 3],
    pub _pad_ground2: f32,
    /// The crop of a larger image the targets hold (`Crop`): its origin
    /// and the whole image's size, which the camera and the seeds follow.
    pub crop_origin: [u32; 2],
    pub image_size: [f32; 2],
}

/// `NoiseParams` of `crates/core/src/noise/fractal.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, Default, PartialEq)]
pub struct NoiseParams {
    pub kind: u32,
    pub hash: u32,
    pub octaves: f32,
    pub frequency: f32,
    pub amplitude: f32,
    pub persistence: f32,
    pub lacunarity: f32,
    /// [`FractalShape::id`]: fBm, turbulence or ridged.
    pub shape: u32,
    pub distortion: f32,
    /// Bits: [`NoiseParams::LINEAR`] (the octaves' progression),
    /// [`NoiseParams::WORLD`] (the signal's mapping reads world
    /// coordinates), [`NoiseParams::EVOLVES`], and from bit 8 on an
    /// evolving signal's w period while looping (0: none). Packed, not a
    /// field each: 160 materials of 4 signals fill the 64 KiB uniform.
    pub flags: u32,
    /// How much the signal's mapping enlarges a footprint.
    pub footprint_scale: f32,
    /// An evolving signal's w at the moment traced.
    pub w: f32,
}

impl NoiseParams {
    pub const LINEAR: u32 = 1;
    pub const WORLD: u32 = 2;
    pub const EVOLVES: u32 = 4;
    const PERIOD_SHIFT: u32 = 8;

    pub fn new(n: &NoiseSettings, shape: FractalShape) -> Self {
        let f = &n.fractal;
        let linear = match f.progression {
            Progression::Geometric => 0,
            Progression::Linear => Self::LINEAR,
        };
        let evolution = n.evolution.map_or(0, |e| {
            Self::EVOLVES | e.w_period.unwrap_or(0).min(Evolution::MAX_PERIOD) << Self::PERIOD_SHIFT
        });
        Self {
            kind: noise_kind_id(n.kind),
            hash: if n.kind == NoiseKind::PerlinMassal {
                MASSAL_GRADIENTS
            } else {
                hash_id(n.hash)
            },
            octaves: f.octaves,
            frequency: f.frequency,
            amplitude: f.amplitude,
            persistence: f.persistence,
            lacunarity: f.lacunarity,
            shape: shape.id(),
            distortion: f.distortion,
            flags: linear | evolution,
            footprint_scale: 1.0,
            w: n.evolution.map_or(0.0, |e| e.w_now()),
        }
    }
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, Default)]
pub struct Material {
    pub signals: [NoiseParams; MAX_SIGNALS],
    /// Each signal's mapping as three affine rows (identity without one).
    pub signal_rows: [[f32; 4]; 3 * MAX_SIGNALS],
    pub signal_count: u32,
    /// Signals before this index are gradient noise, from it on Perlin.
    pub first_perlin: u32,
    pub bump_height: f32,
    /// The mean emitted luminance ([`marbre_core::lights::emitted_luminance`]):
    /// above 0, the spheres and triangles of this material are lights, and
    /// an emitter hit by a BSDF ray finds its light-sampling density from it.
    pub emitted_luminance: f32,
}

/// `Cylinder` of `shaders/scene.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, Default)]
pub struct Cylinder {
    pub base: [f32; 3],
    pub radius: f32,
    pub height: f32,
    pub _pad: [f32; 3],
}

/// `Polygon` of `shaders/scene.wgsl`: vertices, plane and (u, v) frame.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, Default)]
pub struct Polygon {
    pub vertices: [[f32; 4]; MAX_POLYGON_VERTICES],
    pub normal: [f32; 3],
    pub vertex_count: u32,
    pub uv_origin: [f32; 4],
    pub uv_u: [f32; 4],
    pub uv_v: [f32; 4],
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, Default)]
pub struct Sphere {
    pub center: [f32; 3],
    pub radius: f32,
}

pub fn noise_kind_id(k: NoiseKind) -> u32 {
    match k {
        NoiseKind::Gradient => 0,
        // One octave loop for both Perlin kinds; `hash` tells the tables
        // apart (MASSAL_GRADIENTS).
        NoiseKind::Perlin | NoiseKind::PerlinMassal => 1,
    }
}

/// The `hash` a Perlin signal with Massal's gradient table carries (Perlin's
/// noise has no other use for it): `perlin_noise`'s `massal` in WGSL.
pub const MASSAL_GRADIENTS: u32 = 3;

pub fn hash_id(h: HashKind) -> u32 {
    match h {
        HashKind::Pcg => 0,
        HashKind::Sin => 1,
        HashKind::PcgTiled => 2,
    }
}

/// A material's noise signals (its textures' distinct fractal sums,
/// deduplicated so that rust's diffuse and specular colours share one
/// evaluation per hit, gradient noise first) and its bump height. The
/// textures themselves are generated code (`texture_codegen`).
pub fn material(m: &model::Material) -> Material {
    let signals = m.signals();
    let mut out = Material {
        signal_count: signals.len() as u32,
        first_perlin: signals
            .iter()
            .position(|s| s.noise.kind != NoiseKind::Gradient)
            .unwrap_or(signals.len()) as u32,
        bump_height: m.bump_height,
        emitted_luminance: marbre_core::lights::emitted_luminance(m),
        ..Default::default()
    };
    for (k, signal) in signals.iter().enumerate() {
        out.signals[k] = NoiseParams::new(&signal.noise, signal.shape);
        let mapping = signal.mapping.unwrap_or_default();
        if mapping.space == MappingSpace::World {
            out.signals[k].flags |= NoiseParams::WORLD;
        }
        out.signals[k].footprint_scale = mapping.footprint_scale()[2];
        out.signal_rows[3 * k..3 * k + 3].copy_from_slice(&signal.rows());
    }
    out
}

/// Materials in the order the shader indexes them, padded to the uniform
/// array's length.
pub fn materials(scene: &Scene) -> Vec<Material> {
    let mut out: Vec<_> = scene.materials().map(material).collect();
    out.resize(MAX_MATERIALS, Material::default());
    out
}

/// Entries of the `materials` uniform array: every primitive's, the
/// ground's and the meshes'.
pub use marbre_core::scene::MAX_MATERIALS;

/// Cylinders, padded to the uniform array's length.
pub fn cylinders(scene: &Scene) -> Vec<Cylinder> {
    let mut out: Vec<_> = scene
        .cylinders
        .iter()
        .take(MAX_CYLINDERS)
        .map(|c| Cylinder {
            base: c.base.to_array(),
            radius: c.radius,
            height: c.height,
            _pad: [0.0; 3],
        })
        .collect();
    out.resize(MAX_CYLINDERS, Cylinder::default());
    out
}

/// Polygons (those `Scene::sanitize` kept: convex, flat), padded to the
/// uniform array's length.
pub fn polygons(scene: &Scene) -> Vec<Polygon> {
    let mut out: Vec<_> = scene
        .polygons
        .iter()
        .take(MAX_POLYGONS)
        .map(|p| {
            let mut gpu = Polygon {
                normal: p.normal().unwrap_or(Vec3::Y).to_array(),
                vertex_count: p.vertices.len().min(MAX_POLYGON_VERTICES) as u32,
                ..Default::default()
            };
            for (slot, v) in gpu.vertices.iter_mut().zip(&p.vertices) {
                *slot = v.extend(0.0).to_array();
            }
            if let Some(frame) = p.frame() {
                gpu.uv_origin = frame.origin.extend(0.0).to_array();
                gpu.uv_u = frame.u_axis.extend(0.0).to_array();
                gpu.uv_v = frame.v_axis.extend(0.0).to_array();
            }
            gpu
        })
        .collect();
    out.resize(MAX_POLYGONS, Polygon::default());
    out
}

/// Spheres, padded to the uniform array's length.
pub fn spheres(scene: &Scene) -> Vec<Sphere> {
    let mut out: Vec<_> = scene
        .spheres
        .iter()
        .map(|s| Sphere {
            center: s.center.to_array(),
            radius: s.radius,
        })
        .take(MAX_SPHERES)
        .collect();
    out.resize(MAX_SPHERES, Sphere::default());
    out
}

/// Per-frame values: camera, lights, counters. `crop`: the tile of a
/// larger image the targets of `render_size` hold, and that image's size
/// (`Renderer::set_crop`); the camera's aspect and the rays' spread follow
/// the whole image.
pub fn frame_uniform(
    scene: &Scene,
    render_size: (u32, u32),
    crop: Option<(Tile, (u32, u32))>,
    frame_index: u32,
    accumulated: u32,
) -> Frame {
    let cam = scene.camera.frame();
    let (w, h) = (render_size.0.max(1) as f32, render_size.1.max(1) as f32);
    let (crop_origin, image_size) = crop.map_or(([0; 2], [w, h]), |(tile, image)| {
        (
            [tile.x0, tile.y0],
            [image.0.max(1) as f32, image.1.max(1) as f32],
        )
    });
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
    let ground_frame = scene
        .ground
        .as_ref()
        .map_or_else(|| Ground::default().frame(), Ground::frame);
    Frame {
        cam_pos: cam.position.to_array(),
        tan_half_fov: cam.tan_half_fov,
        cam_right: cam.right.to_array(),
        aspect: image_size[0] / image_size[1],
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
        sphere_count: scene.spheres.len().min(MAX_SPHERES) as u32,
        samples_per_frame: scene.render.samples_per_frame.max(1),
        // The direct integrator is a path of one bounce: what it reaches
        // adds only its emission or the environment.
        max_bounces: match scene.render.transport.integrator {
            Integrator::Direct => 1,
            Integrator::Path => scene.render.max_bounces.max(1),
        },
        render_size: [w, h],
        env_kind: match env.source {
            EnvSource::None => 0,
            EnvSource::Constant { .. } => 1,
            // A cube map reaches the GPU resampled to lat-long.
            EnvSource::LatLong { .. }
            | EnvSource::CubeFaces { .. }
            | EnvSource::CubeCross { .. } => 2,
        },
        has_ground: u32::from(scene.ground.is_some()),
        cylinder_count: scene.cylinders.len().min(MAX_CYLINDERS) as u32,
        polygon_count: scene.polygons.len().min(MAX_POLYGONS) as u32,
        // Parallel rays do not spread: an orthographic cone keeps the
        // width a pixel has on the camera's plane (trace.wgsl).
        pixel_spread: if cam.ortho_half_height > 0.0 {
            0.0
        } else {
            2.0 * cam.tan_half_fov / image_size[1]
        },
        env_sampling: u32::from(env.source.is_map() && scene.render.env_importance),
        // Filled in by the renderer, which holds the distribution and the
        // light table.
        env_distribution_size: [0; 2],
        light_count: 0,
        light_selection: match scene.render.transport.light_selection {
            LightSelection::Uniform => 0,
            LightSelection::Power => 1,
        },
        light_total_power: 0.0,
        light_samples: scene.render.transport.light_samples.max(1),
        strategy: scene.render.transport.effective_strategy().id(),
        russian_roulette_from: scene.render.transport.russian_roulette_from,
        triangle_count: 0,
        opaque_one: 1.0,
        sample_clamp: scene.render.transport.sample_clamp.unwrap_or(0.0),
        band_start: 0,
        band_end: render_size.1.max(1),
        view: scene.render.view.id(),
        light_points: scene.render.transport.light_points.id(),
        depth_scale: scene.camera.distance.max(f32::MIN_POSITIVE),
        ground_uv_origin: ground_frame.origin.to_array(),
        ortho_half_height: cam.ortho_half_height,
        ground_uv_u: ground_frame.u_axis.to_array(),
        _pad_ground1: 0.0,
        ground_uv_v: ground_frame.v_axis.to_array(),
        _pad_ground2: 0.0,
        crop_origin,
        image_size,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;
    use marbre_core::scene::{Pattern, Texture};

    /// The uber trace shader, parsed: every struct and global it may hold.
    fn trace_module() -> naga::Module {
        let generated = crate::gpu::texture_codegen::generate(
            &Scene::default(),
            &marbre_core::texture::ImageSet::empty(),
        )
        .unwrap();
        let source = crate::gpu::shader_source::assemble(
            crate::gpu::shader_source::Program::Trace,
            &crate::gpu::features::FeatureSet::all(),
            &generated.wgsl,
        )
        .unwrap();
        naga::front::wgsl::parse_str(&source).unwrap()
    }

    /// Each struct uploaded to the trace shader (the scene's, the light
    /// table's, the meshes') has its WGSL twin's layout, as naga lays the
    /// WGSL out (no size computed by hand).
    #[test]
    fn structs_have_their_wgsl_twins_layout() {
        use crate::gpu::twin_layout::twin_layout;
        let module = &trace_module();
        twin_layout!(
            module,
            Frame,
            [
                cam_pos,
                tan_half_fov,
                cam_right,
                aspect,
                cam_up,
                frame_index,
                cam_forward,
                accumulated,
                light_pos,
                env_intensity,
                light_power,
                env_rotation,
                env_constant,
                background_visible,
                ground_height,
                sphere_count,
                samples_per_frame,
                max_bounces,
                render_size,
                env_kind,
                has_ground,
                cylinder_count,
                polygon_count,
                pixel_spread,
                env_sampling,
                env_distribution_size,
                light_count,
                light_selection,
                light_total_power,
                light_samples,
                strategy,
                russian_roulette_from,
                triangle_count,
                opaque_one,
                sample_clamp,
                band_start,
                band_end,
                view,
                light_points,
                depth_scale,
                ground_uv_origin,
                ortho_half_height,
                ground_uv_u,
                ground_uv_v,
                crop_origin,
                image_size,
            ]
        );
        twin_layout!(
            module,
            NoiseParams,
            [
                kind,
                hash,
                octaves,
                frequency,
                amplitude,
                persistence,
                lacunarity,
                shape,
                distortion,
                flags,
                footprint_scale,
                w,
            ]
        );
        twin_layout!(
            module,
            Material,
            [
                signals,
                signal_rows,
                signal_count,
                first_perlin,
                bump_height,
                emitted_luminance,
            ]
        );
        twin_layout!(module, Cylinder, [base, radius, height]);
        twin_layout!(
            module,
            Polygon,
            [vertices, normal, vertex_count, uv_origin, uv_u, uv_v,]
        );
        twin_layout!(module, Sphere, [center, radius]);
        use crate::gpu::mesh_buffers::TriangleAttributes;
        use marbre_core::accel::{BvhNode, TriangleVerts};
        use marbre_core::lights::Light;
        twin_layout!(module, Light, [kind, primitive, cdf, power]);
        twin_layout!(module, TriangleAttributes, [uv01, uv2, material,]);
        twin_layout!(module, BvhNode, [min, a, max, count]);
        twin_layout!(module, TriangleVerts, [v0, v1, v2]);
    }

    /// The element count of a uniform array global in the trace shader.
    fn wgsl_array_len(name: &str) -> u32 {
        let module = trace_module();
        let (_, global) = module
            .global_variables
            .iter()
            .find(|(_, g)| g.name.as_deref() == Some(name))
            .unwrap();
        match module.types[global.ty].inner {
            naga::TypeInner::Array {
                size: naga::ArraySize::Constant(n),
                ..
            } => n.get(),
            ref other => panic!("{name} is {other:?}"),
        }
    }

    #[test]
    fn uniform_arrays_hold_what_the_cpu_uploads() {
        let scene = Scene::default();
        assert_eq!(wgsl_array_len("spheres") as usize, spheres(&scene).len());
        assert_eq!(
            wgsl_array_len("materials") as usize,
            materials(&scene).len()
        );
        assert_eq!(spheres(&scene).len(), MAX_SPHERES);
        assert_eq!(
            wgsl_array_len("cylinders") as usize,
            cylinders(&scene).len()
        );
        assert_eq!(wgsl_array_len("polygons") as usize, polygons(&scene).len());
        assert_eq!(
            wgsl_array_len("texture_params") as usize,
            crate::gpu::texture_codegen::generate(&scene, &marbre_core::texture::ImageSet::empty())
                .unwrap()
                .params
                .len()
        );
    }

    fn fbm_texture(noise: NoiseSettings) -> Texture {
        Texture::blend(Pattern::Fbm { noise }, Vec3::ZERO, Vec3::ONE)
    }

    #[test]
    fn textures_reading_the_same_sum_share_one_signal() {
        let noise = NoiseSettings::default();
        let mut m = model::Material {
            diffuse: fbm_texture(noise),
            specular: fbm_texture(noise),
            ..Default::default()
        };
        m.roughness.pattern = Pattern::Turbulence { noise };
        let gpu = material(&m);
        // fBm once for both colours; turbulence, |noise|, is another sum.
        assert_eq!(gpu.signal_count, 2);
        assert_eq!(gpu.signals[0].shape, FractalShape::Signed.id());
        assert_eq!(gpu.signals[1].shape, FractalShape::Absolute.id());
    }

    #[test]
    fn perlin_signals_come_after_gradient_ones() {
        let perlin = NoiseSettings {
            kind: NoiseKind::Perlin,
            ..Default::default()
        };
        let m = model::Material {
            diffuse: fbm_texture(perlin),
            specular: fbm_texture(NoiseSettings::default()),
            ..Default::default()
        };
        let gpu = material(&m);
        assert_eq!((gpu.signal_count, gpu.first_perlin), (2, 1));
        assert_eq!(gpu.signals[0].kind, 0);
        assert_eq!(gpu.signals[1].kind, 1);
    }

    /// Nested textures add their sums; past the limit, `Scene::sanitize`
    /// turns the extra patterns constant.
    #[test]
    fn nested_sums_count_up_to_the_limit() {
        let at = |frequency| NoiseSettings {
            fractal: marbre_core::noise::FractalParams {
                frequency,
                ..Default::default()
            },
            ..Default::default()
        };
        let nested = Texture::blend(
            Pattern::Fbm { noise: at(1.0) },
            fbm_texture(at(2.0)),
            fbm_texture(at(3.0)),
        );
        let mut m = model::Material {
            diffuse: nested,
            specular: fbm_texture(at(4.0)),
            roughness: fbm_texture(at(5.0)),
            ..Default::default()
        };
        let mut notes = Vec::new();
        m.sanitize("test", &mut notes);
        assert_eq!(notes.len(), 1, "{notes:?}");
        assert_eq!(m.roughness.pattern, Pattern::Constant);
        let gpu = material(&m);
        assert_eq!(gpu.signal_count, MAX_SIGNALS as u32);
        assert_eq!(gpu.signals[3].frequency, 4.0);
    }
}
