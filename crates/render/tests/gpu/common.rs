//! Helpers shared by the offscreen render tests.

use glam::{Vec2, Vec3};
use marbre_core::scene::{
    EnvSource, Ground, Material, OrbitCamera, Property, RenderSettings, Scene, Sphere,
    SurfacePoint, Texture,
};
use marbre_render::gpu::{GpuContext, Renderer};
use marbre_render::session::accumulate;

/// `scene` rendered at `size` with `spp` samples per pixel by each kernel
/// the adapter runs, checked to agree; the image.
pub fn render(ctx: &GpuContext, scene: &Scene, size: (u32, u32), spp: u32) -> Vec<[f32; 4]> {
    render_with(ctx, scene, size, spp, None)
}

pub fn render_with(
    ctx: &GpuContext,
    scene: &Scene,
    size: (u32, u32),
    spp: u32,
    features: Option<marbre_render::gpu::FeatureSet>,
) -> Vec<[f32; 4]> {
    // Every kernel traces the same accumulation: the caller's checks on the
    // returned image hold for each.
    let images: Vec<Vec<[f32; 4]>> = kernels(ctx)
        .into_iter()
        .map(|kernel| {
            let mut r = Renderer::with_kernel(ctx, scene, None, size, kernel).unwrap();
            r.set_feature_override(ctx, features.clone()).unwrap();
            accumulate(ctx, &mut r, spp, |_| {}).unwrap();
            let (w, h, pixels) = r.read_radiance(ctx).unwrap();
            assert_eq!((w, h), size);
            // The trace pass drops non-finite samples, so finite pixels
            // alone prove nothing: its counters must say it dropped none.
            let dropped = r.count_non_finite(ctx).unwrap();
            assert!(
                dropped.is_zero(),
                "{kernel}: non-finite samples dropped: {dropped:?}"
            );
            for p in &pixels {
                assert!(
                    p.iter().all(|c| c.is_finite()),
                    "{kernel}: non-finite pixel {p:?}"
                );
            }
            pixels
        })
        .collect();
    for other in &images[1..] {
        assert_kernels_agree(&images[0], other, "render");
    }
    images.into_iter().next().unwrap()
}

/// Every colour channel of `pixel` within `relative` of `expected`.
pub fn assert_channels_near(pixel: [f32; 4], expected: f32, relative: f32, what: &str) {
    for c in &pixel[..3] {
        assert!(
            (c - expected).abs() < relative * expected,
            "{what}: {pixel:?}, expected {expected}"
        );
    }
}

pub fn lambert(albedo: f32) -> Material {
    Material {
        diffuse: Texture::color(Vec3::splat(albedo)),
        specular: Texture::color(Vec3::ZERO),
        roughness: Texture::scalar(1.0),
        mirror: Texture::scalar(0.0),
        ..Material::default()
    }
}

/// Render settings whose textures are point sampled, as the CPU reference
/// (`Texture::eval`) samples them: no footprint filtering of checkers, no
/// clamping of octaves.
pub fn point_sampled() -> RenderSettings {
    RenderSettings {
        filter_checkers: false,
        clamp_octaves: false,
        ..RenderSettings::default()
    }
}

/// The camera ray through image point `at` (in pixels), as (origin, unit
/// direction): the shader's `camera_ray`, on the CPU.
pub fn camera_ray(scene: &Scene, (w, h): (u32, u32), at: Vec2) -> (Vec3, Vec3) {
    let frame = scene.camera.frame();
    let ndc = Vec2::new(at.x / w as f32 * 2.0 - 1.0, 1.0 - at.y / h as f32 * 2.0);
    let d = (frame.forward
        + ndc.x * frame.tan_half_fov * (w as f32 / h as f32) * frame.right
        + ndc.y * frame.tan_half_fov * frame.up)
        .normalize();
    (frame.position, d)
}

/// Where the camera ray through image point `at` (in pixels) meets the
/// ground y = 0.
pub fn ground_point(scene: &Scene, size: (u32, u32), at: Vec2) -> Vec3 {
    let (o, d) = camera_ray(scene, size, at);
    let p = o - o.y / d.y * d;
    Vec3::new(p.x, 0.0, p.z)
}

/// A Lambert ground with `diffuse` under a constant white environment of
/// radiance 1: each point reflects exactly its diffuse colour.
pub fn textured_ground_in_white_light(diffuse: Texture) -> Scene {
    let mut scene = Scene {
        ground: Some(Ground {
            height: 0.0,
            uv_frame: None,
            material: Material {
                diffuse,
                ..lambert(0.5)
            },
        }),
        render: point_sampled(),
        ..Scene::default()
    };
    scene.environment.source = EnvSource::Constant {
        radiance: Vec3::ONE,
    };
    scene
}

/// Checks that every pixel whose footprint lies in one region of
/// `reference` (its value at a 10×10 grid of image points over the pixel
/// agrees, and none misses) shows that value; more than `min_fraction` of
/// the pixels must qualify.
pub fn assert_pixels_match(
    pixels: &[[f32; 4]],
    (w, h): (u32, u32),
    min_fraction: f32,
    reference: impl Fn(Vec2) -> Option<Vec3>,
) {
    let mut checked = 0;
    for y in 0..h {
        for x in 0..w {
            // A 10×10 grid over the pixel: thin mortar lines must not slip
            // between the samples.
            let samples: Option<Vec<Vec3>> = (0..100)
                .map(|k| {
                    let (dx, dy) = ((k % 10) as f32 / 9.0, (k / 10) as f32 / 9.0);
                    reference(Vec2::new(x as f32 + dx, y as f32 + dy))
                })
                .collect();
            let Some(samples) = samples else {
                continue;
            };
            if samples.iter().any(|c| (*c - samples[0]).length() > 1e-6) {
                continue;
            }
            let got = pixels[(y * w + x) as usize];
            let expected = samples[0];
            for c in 0..3 {
                assert!(
                    (got[c] - expected[c]).abs() < 2e-3,
                    "pixel {x},{y}: rendered {got:?}, the CPU reference gives {expected}"
                );
            }
            checked += 1;
        }
    }
    assert!(
        checked as f32 > min_fraction * (w * h) as f32,
        "only {checked} pixels lie inside one region"
    );
}

/// [`assert_pixels_match`] on the ground, `reference` taking the ground
/// point and its (u, v) = (x, z).
pub fn assert_ground_matches(
    scene: &Scene,
    pixels: &[[f32; 4]],
    size: (u32, u32),
    min_fraction: f32,
    reference: impl Fn(Vec3, Vec2) -> Vec3,
) {
    assert_pixels_match(pixels, size, min_fraction, |at| {
        let p = ground_point(scene, size, at);
        Some(reference(p, Vec2::new(p.x, p.z)))
    });
}

/// Two diffuse spheres on a grey ground under a constant environment of
/// `radiance`: every pixel's radiance is proportional to it.
pub fn spheres_in_constant_light(radiance: f32) -> Scene {
    let mut scene = Scene {
        ground: Some(Ground {
            height: -1.0,
            uv_frame: None,
            material: lambert(0.3),
        }),
        ..Scene::default()
    };
    for (x, albedo) in [(-1.1, 0.8), (1.1, 0.1)] {
        scene.spheres.push(Sphere {
            name: format!("albedo {albedo}"),
            center: Vec3::new(x, 0.0, 0.0),
            radius: 1.0,
            material: lambert(albedo),
        });
    }
    scene.environment.source = EnvSource::Constant {
        radiance: Vec3::splat(radiance),
    };
    scene.camera = OrbitCamera {
        target: Vec3::ZERO,
        distance: 7.0,
        yaw_degrees: 0.0,
        pitch_degrees: 15.0,
        fov_degrees: 45.0,
        ..Default::default()
    };
    scene
}

/// The trace kernels `ctx`'s adapter runs, for tests that draw frames with
/// each (`Kernel::GPU` where the compute kernel is supported; a loud note
/// where it is not).
pub fn kernels(ctx: &GpuContext) -> Vec<marbre_render::gpu::Kernel> {
    match marbre_render::gpu::kernel::compute_support(ctx) {
        Ok(()) => marbre_render::gpu::Kernel::GPU.to_vec(),
        Err(why) => {
            eprintln!("NOTE: the compute kernel cannot run here ({why}): fragment only");
            vec![marbre_render::gpu::Kernel::Fragment]
        }
    }
}

/// The two kernels' images of the same accumulation agree to rounding
/// (`crates/render/tests/gpu/kernels.rs` finds them bit-identical on lavapipe; another
/// driver may contract or reorder float operations differently).
pub fn assert_kernels_agree(fragment: &[[f32; 4]], compute: &[[f32; 4]], what: &str) {
    assert_eq!(fragment.len(), compute.len(), "{what}");
    for (i, (f, c)) in fragment.iter().zip(compute).enumerate() {
        for k in 0..4 {
            let tolerance = 1e-5 * (1.0 + f[k].abs().max(c[k].abs()));
            assert!(
                f[k].to_bits() == c[k].to_bits() || (f[k] - c[k]).abs() <= tolerance,
                "{what}: pixel {i}, fragment {f:?}, compute {c:?}"
            );
        }
    }
}

/// The repository's root, where the presets are.
pub fn root() -> &'static std::path::Path {
    std::path::Path::new(crate::REPO)
}

/// Every `*.ron` in `presets/<folder>` (a path from the root), sorted.
pub fn presets_in(folder: &str) -> Vec<std::path::PathBuf> {
    let dir = root().join(folder);
    let mut out: Vec<std::path::PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.expect("a readable directory entry").path())
        .filter(|p| p.extension().is_some_and(|x| x == "ron"))
        .collect();
    out.sort();
    out
}

/// A mesh scene from triangles made in the test (no OBJ file), one
/// material; counter-clockwise faces are the front (and emit).
pub fn mesh_of(triangles: Vec<[Vec3; 3]>, material: Material) -> marbre_core::scene::Mesh {
    let count = triangles.len();
    marbre_core::scene::Mesh {
        name: "test mesh".into(),
        materials: vec![marbre_core::scene::MeshMaterial {
            name: "only".into(),
            material,
            from_file: None,
        }],
        geometry: marbre_core::scene::mesh::Geometry(std::sync::Arc::new(
            marbre_core::scene::TriangleMesh {
                positions: triangles,
                uvs: vec![[glam::Vec2::ZERO; 3]; count],
                materials: vec![0; count],
            },
        )),
        ..Default::default()
    }
}

/// A unit sphere at (0.4, 0.1, 0) wearing `diffuse` over a Lambert 0.5, in
/// white light, point sampled at 64 × 64 and 4 spp: every pixel the sphere
/// covers shows the CPU reference's diffuse at the point its camera ray
/// meets (`assert_pixels_match`'s tolerance for texel edges).
pub fn assert_sphere_shows_its_diffuse(ctx: &GpuContext, diffuse: Texture) {
    let center = Vec3::new(0.4, 0.1, 0.0);
    let sphere = Sphere {
        center,
        radius: 1.0,
        material: Material {
            diffuse,
            ..lambert(0.5)
        },
        ..Sphere::default()
    };
    let mut scene = Scene {
        spheres: vec![sphere.clone()],
        render: point_sampled(),
        camera: OrbitCamera {
            target: center,
            distance: 3.5,
            yaw_degrees: 30.0,
            pitch_degrees: 20.0,
            fov_degrees: 40.0,
            ..Default::default()
        },
        ..Scene::default()
    };
    scene.environment.source = EnvSource::Constant {
        radiance: Vec3::ONE,
    };
    let (w, h) = (64, 64);
    let pixels = render(ctx, &scene, (w, h), 4);
    assert_pixels_match(&pixels, (w, h), 0.15, |at| {
        let (o, d) = camera_ray(&scene, (w, h), at);
        let f = o - center;
        let b = f.dot(d);
        let disc = b * b - (f.length_squared() - 1.0);
        (disc > 0.0).then(|| {
            let p = o + (-b - disc.sqrt()) * d;
            let offset = p - center;
            let point = SurfacePoint {
                object: offset,
                world: p,
                uv: marbre_core::texture::sphere_uv(offset),
            };
            sphere.material.value_at(Property::Diffuse, &point)
        })
    });
}

/// The root-mean-square difference of two images' RGB, over every pixel
/// and channel.
pub fn rmse(a: &[[f32; 4]], b: &[[f32; 4]]) -> f64 {
    let sum: f64 = a
        .iter()
        .zip(b)
        .map(|(x, y)| (0..3).map(|c| f64::from(x[c] - y[c]).powi(2)).sum::<f64>())
        .sum();
    (sum / (3 * a.len()) as f64).sqrt()
}
