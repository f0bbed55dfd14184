//! The lab's fixed light points (`scene::LightPoints`, exercises 3 and 4):
//! the centroid mode against the closed form of a point at the centroid,
//! and the fixed set's error, which is structure the frames never average
//! away rather than noise.

use crate::common::*;
use glam::{Vec2, Vec3};
use marbre_core::scene::{
    Ground, Integrator, LightPoints, Material, OrbitCamera, Scene, Sphere, Texture,
};
use marbre_render::gpu::testing::gpu_or_skip;
use marbre_render::gpu::{GpuContext, Renderer};
use marbre_render::session::accumulate;

/// The emitting triangle's radiance.
const LE: f32 = 5.0;
/// The ground's albedo.
const RHO: f32 = 0.5;

/// A Lambert ground lit by emitting `triangles` (facing down), seen from
/// above at 60°, direct light only, no environment.
fn lit_ground(triangles: Vec<[Vec3; 3]>, points: LightPoints) -> Scene {
    let mut scene = Scene {
        ground: Some(Ground {
            height: 0.0,
            material: lambert(RHO),
            ..Ground::default()
        }),
        meshes: vec![mesh_of(
            triangles,
            Material {
                emission: Texture::color(Vec3::splat(LE)),
                ..lambert(0.0)
            },
        )],
        camera: OrbitCamera {
            target: Vec3::ZERO,
            distance: 6.0,
            pitch_degrees: 60.0,
            ..OrbitCamera::default()
        },
        ..Scene::default()
    };
    scene.render.transport.integrator = Integrator::Direct;
    scene.render.transport.light_points = points;
    scene
}

/// Exercise 3 with one emitting triangle (area A, normal −y, centroid c at
/// height h = 2): each light sample is c itself, weighted by A, so the
/// ground at p reads (ρ/π) Le A cos θl cos θp / |c − p|² = (ρ/π) Le A h² /
/// |c − p|⁴: a point light at the centroid whose intensity is the
/// triangle's, Le A cos θl. Checked at every ground pixel the triangle
/// does not hide, averaged over a 4 × 4 grid in the pixel as the jitter
/// averages it: within 0.5 % plus 4 standard deviations of the jitter's
/// mean (the closed form's spread over the pixel, over √spp).
#[test]
fn the_centroid_mode_is_a_point_light_at_the_centroid() {
    let Some(ctx) = gpu_or_skip("the_centroid_mode_is_a_point_light_at_the_centroid") else {
        return;
    };
    let h = 2.0;
    let tri = [
        Vec3::new(-0.5, h, -0.3),
        Vec3::new(0.5, h, -0.3),
        Vec3::new(0.0, h, 0.6),
    ];
    let area = 0.5 * (tri[1] - tri[0]).cross(tri[2] - tri[0]).length();
    let c = (tri[0] + tri[1] + tri[2]) / 3.0;
    let scene = lit_ground(vec![tri], LightPoints::Centroid);
    let size = (40, 30);
    let spp = 64;
    let pixels = render(&ctx, &scene, size, spp);
    // Whether the camera ray through `at` crosses the triangle's plane
    // inside its bounding box (so may be hidden by it): such pixels are
    // left out.
    let near_triangle = |at: Vec2| {
        let (o, d) = camera_ray(&scene, size, at);
        let q = o + (h - o.y) / d.y * d;
        q.x.abs() < 0.6 && (-0.4..0.7).contains(&q.z)
    };
    let closed_form = |p: Vec3| {
        let d2 = (c - p).length_squared();
        RHO / std::f32::consts::PI * LE * area * h * h / (d2 * d2)
    };
    let mut checked = 0;
    for y in 0..size.1 {
        for x in 0..size.0 {
            let corners = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)];
            if corners
                .iter()
                .any(|&(i, j)| near_triangle(Vec2::new(x as f32 + i, y as f32 + j)))
            {
                continue;
            }
            let values: Vec<f32> = (0..16)
                .map(|k| {
                    let at = Vec2::new(
                        x as f32 + ((k % 4) as f32 + 0.5) / 4.0,
                        y as f32 + ((k / 4) as f32 + 0.5) / 4.0,
                    );
                    closed_form(ground_point(&scene, size, at))
                })
                .collect();
            let expected = values.iter().sum::<f32>() / 16.0;
            let spread = values.iter().map(|v| (v - expected).powi(2)).sum::<f32>() / 16.0;
            let jitter = 4.0 * (spread / spp as f32).sqrt();
            let p = pixels[(y * size.0 + x) as usize];
            for c in 0..3 {
                assert!(
                    (p[c] - expected).abs() < 0.005 * expected + jitter,
                    "pixel ({x}, {y}): {p:?}, expected {expected} ± {jitter}"
                );
            }
            checked += 1;
        }
    }
    assert!(checked > 800, "only {checked} ground pixels checked");
}

/// The mean squared difference of two images over channels, and the
/// renderer's own estimate of its image's noise (the variance of each
/// pixel's mean from the spread of its frames), both as RMSE.
fn error_and_noise(
    ctx: &GpuContext,
    scene: &Scene,
    reference: &[[f32; 4]],
    size: (u32, u32),
    spp: u32,
) -> (f64, f64) {
    let mut r = Renderer::new(ctx, scene, None, size).unwrap();
    accumulate(ctx, &mut r, spp, |_| {}).unwrap();
    let (_, _, pixels) = r.read_radiance(ctx).unwrap();
    let sum: f64 = pixels
        .iter()
        .zip(reference)
        .map(|(a, b)| (0..3).map(|c| f64::from(a[c] - b[c]).powi(2)).sum::<f64>())
        .sum();
    let error = (sum / (3 * pixels.len()) as f64).sqrt();
    (error, r.estimate_error(ctx).unwrap().unwrap().rmse)
}

/// Exercise 4's wrong image: a square light (two triangles) above the
/// ground, a sphere casting a shadow, 4 light samples a shading point.
/// With the same 4 points for every pixel and frame, frames differ only
/// by their jitter: the renderer's noise estimate is a small part of the
/// actual error against the converged image (a 2048-sample render of
/// random points), the rest being bands and stepped shadows that do not
/// average away. With random points the same estimate accounts for the
/// error.
#[test]
fn the_fixed_set_error_is_structure_not_noise() {
    let Some(ctx) = gpu_or_skip("the_fixed_set_error_is_structure_not_noise") else {
        return;
    };
    let h = 1.5;
    // Facing down: (c − a) × (b − a) points to −y.
    let [a, b, c, d] =
        [(-0.6, -0.6), (-0.6, 0.6), (0.6, 0.6), (0.6, -0.6)].map(|(x, z)| Vec3::new(x, h, z));
    let mut scene = lit_ground(vec![[a, c, b], [a, d, c]], LightPoints::Random);
    scene.spheres.push(Sphere {
        center: Vec3::new(0.3, 0.4, 0.5),
        radius: 0.4,
        material: lambert(0.5),
        ..Sphere::default()
    });
    scene.render.transport.light_samples = 4;
    let size = (32, 24);
    let mut reference = Renderer::new(&ctx, &scene, None, size).unwrap();
    accumulate(&ctx, &mut reference, 2048, |_| {}).unwrap();
    let (_, _, reference) = reference.read_radiance(&ctx).unwrap();
    let (random_error, random_noise) = error_and_noise(&ctx, &scene, &reference, size, 64);
    scene.render.transport.light_points = LightPoints::FixedSet;
    let (fixed_error, fixed_noise) = error_and_noise(&ctx, &scene, &reference, size, 64);
    eprintln!(
        "64 spp RMSE against the reference (noise estimate): random {random_error:.5} \
         ({random_noise:.5}), fixed set {fixed_error:.5} ({fixed_noise:.5})"
    );
    assert!(
        fixed_noise < 0.3 * fixed_error,
        "fixed set: noise {fixed_noise} of an error {fixed_error}"
    );
    assert!(
        random_error < 1.5 * random_noise,
        "random: noise {random_noise} of an error {random_error}"
    );
    assert!(fixed_error > 2.0 * random_error);
}
