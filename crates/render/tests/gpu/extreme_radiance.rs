//! Extreme radiance stays finite and unbiased: the esplanade map (a sun of
//! ~3e4 and negative texels down to about −3.9e3 in the file) and an
//! emitter of 1e6, each lighting a Lambert ground whose radiance is known
//! in closed form. The firefly clamp stays off. Needs a GPU adapter (skips
//! loudly without one, see `marbre_render::gpu::testing`).

use crate::common;

use crate::common::{camera_ray, lambert};
use glam::{Vec2, Vec3};
use marbre_core::envmap::{self, EnvImage};
use marbre_core::scene::{EnvSource, Ground, Material, OrbitCamera, Scene, Sphere, Texture};
use marbre_render::gpu::testing::gpu_or_skip;
use marbre_render::gpu::{GpuContext, Renderer};
use marbre_render::session::accumulate;
use std::f64::consts::PI;
use std::path::Path;

const ALBEDO: f32 = 0.5;
/// Samples per pixel of the emitter test.
const SPP: u32 = 32;

/// Renders `spp` samples per pixel with each kernel, checks that no sample
/// was dropped, every pixel is finite and the kernels agree, and returns
/// the image.
fn render(
    ctx: &GpuContext,
    scene: &Scene,
    env: Option<&EnvImage>,
    size: (u32, u32),
    spp: u32,
) -> Vec<[f32; 4]> {
    let images: Vec<Vec<[f32; 4]>> = common::kernels(ctx)
        .into_iter()
        .map(|kernel| {
            let mut r = Renderer::with_kernel(ctx, scene, env, size, kernel).unwrap();
            accumulate(ctx, &mut r, spp, |_| {}).unwrap();
            let dropped = r.count_non_finite(ctx).unwrap();
            assert!(
                dropped.is_zero(),
                "{kernel}: non-finite samples: {dropped:?}"
            );
            let (_, _, pixels) = r.read_radiance(ctx).unwrap();
            assert!(
                pixels.iter().all(|p| p.iter().all(|c| c.is_finite())),
                "{kernel}"
            );
            pixels
        })
        .collect();
    for other in &images[1..] {
        common::assert_kernels_agree(&images[0], other, "extreme radiance");
    }
    images.into_iter().next().unwrap()
}

fn esplanade() -> EnvImage {
    let path = Path::new(crate::REPO).join("envmaps/esplanade.exr");
    let loaded = envmap::load(&path).unwrap();
    // The shipped maps had their negative texels set to 0 once (issue 21):
    // a shipped map loads without a note about the user's data.
    assert!(
        !loaded.notes.iter().any(|n| n.contains("negative")),
        "a shipped map still has negative texels: {:?}",
        loaded.notes
    );
    loaded.image
}

/// The irradiance on an upward-facing plane under `env`, per channel, in
/// f64: each texel's radiance times ∫ cos θ dω over its cell, in closed
/// form. With y = cos θ the up component, dω = dφ dy, so a cell spanning
/// Δφ and y₀..y₁ (clipped to the upper hemisphere) gives Δφ (y₁² − y₀²)/2.
/// Row j spans v = 1 − (j+1)/H .. 1 − j/H (`envmap::uv_to_texel_uv`), and
/// y = −cos(πv) (`envmap::direction_to_uv`).
fn irradiance_from_above(env: &EnvImage) -> [f64; 3] {
    let (w, h) = (env.width, env.height);
    let d_phi = 2.0 * PI / f64::from(w);
    let mut e = [0.0f64; 3];
    for j in 0..h {
        let y_at = |v: f64| (-(PI * v).cos()).max(0.0);
        let y0 = y_at(1.0 - f64::from(j + 1) / f64::from(h));
        let y1 = y_at(1.0 - f64::from(j) / f64::from(h));
        let weight = d_phi * (y1 * y1 - y0 * y0) / 2.0;
        if weight == 0.0 {
            continue;
        }
        for i in 0..w {
            let texel = env.texel(i, j);
            for c in 0..3 {
                e[c] += weight * f64::from(texel[c]);
            }
        }
    }
    e
}

/// Every pixel's radiance has the same expectation (an infinite plane under
/// a distant map): the image mean must match it within Monte Carlo error
/// of all the pixels' samples together, plus the half-float texture's
/// rounding and bilinear filtering (0.5 %).
#[test]
fn a_ground_under_the_esplanade_sun_gets_the_closed_form_radiance() {
    let Some(ctx) = gpu_or_skip("a_ground_under_the_esplanade_sun_gets_the_closed_form_radiance")
    else {
        return;
    };
    let env = esplanade();
    assert!(
        env.max_value() > 20_000.0,
        "the sun is kept at full strength, not clamped: {}",
        env.max_value()
    );
    let mut scene = Scene {
        ground: Some(Ground {
            height: 0.0,
            uv_frame: None,
            material: lambert(ALBEDO),
        }),
        camera: OrbitCamera {
            target: Vec3::ZERO,
            distance: 5.0,
            yaw_degrees: 0.0,
            pitch_degrees: 89.0,
            fov_degrees: 30.0,
            ..Default::default()
        },
        ..Scene::default()
    };
    scene.environment.source = EnvSource::LatLong {
        path: "esplanade, given directly".into(),
    };
    scene.render.max_bounces = 1;
    scene.render.samples_per_frame = 16;
    let (size, spp) = ((24, 24), 64);
    let pixels = render(&ctx, &scene, Some(&env), size, spp);
    let e = irradiance_from_above(&env);
    let n = pixels.len() as f64;
    for c in 0..3 {
        let expected = f64::from(ALBEDO) / PI * e[c];
        let values: Vec<f64> = pixels.iter().map(|p| f64::from(p[c])).collect();
        let mean = values.iter().sum::<f64>() / n;
        // The spread of pixel means about the image mean estimates the
        // variance of one pixel's mean; the image mean's is that over n.
        let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
        let tolerance = 4.0 * (var / n).sqrt() + 0.005 * expected;
        println!(
            "channel {c}: image mean {mean:.4}, closed form {expected:.4}, tolerance {tolerance:.4}"
        );
        assert!(
            (mean - expected).abs() < tolerance,
            "channel {c}: image mean {mean}, closed form {expected} (tolerance {tolerance})"
        );
    }
}

/// A sphere of radius r and radiance L, its centre at distance d from a
/// ground point at height h above it, gives that point irradiance
/// π L (r/d)² cos θ = π L r² h / d³ (exact while the sphere is wholly above
/// the horizon), so a Lambert ground of albedo a has radiance a L r² h / d³.
#[test]
fn an_emitter_of_a_million_lights_the_ground_as_the_closed_form_says() {
    let Some(ctx) =
        gpu_or_skip("an_emitter_of_a_million_lights_the_ground_as_the_closed_form_says")
    else {
        return;
    };
    let (radiance, radius, height) = (1.0e6f32, 0.01f32, 1.0f32);
    let light = Vec3::new(0.0, height, 0.0);
    let mut scene = Scene {
        ground: Some(Ground {
            height: 0.0,
            uv_frame: None,
            material: lambert(ALBEDO),
        }),
        camera: OrbitCamera {
            target: Vec3::ZERO,
            distance: 6.0,
            yaw_degrees: 0.0,
            pitch_degrees: 60.0,
            fov_degrees: 40.0,
            ..Default::default()
        },
        ..Scene::default()
    };
    scene.spheres.push(Sphere {
        name: "tiny bright emitter".into(),
        center: light,
        radius,
        material: Material {
            emission: Texture::color(Vec3::ONE),
            emission_strength: radiance,
            ..lambert(0.0)
        },
    });
    scene.environment.source = EnvSource::Constant {
        radiance: Vec3::ZERO,
    };
    scene.render.max_bounces = 1;
    scene.render.samples_per_frame = 8;
    let size = (32, 24);
    let pixels = render(&ctx, &scene, None, size, SPP);
    let closed_form = |p: Vec3| {
        let d = (light - p).length();
        ALBEDO * radiance * radius * radius * height / (d * d * d)
    };
    let mut checked = 0;
    for y in 0..size.1 {
        for x in 0..size.0 {
            // The closed form over an 8×8 grid of the pixel (the jittered
            // samples' footprint), for ground pixels only. Its spread over
            // the pixel is the anti-aliasing's own noise: the pixel mean
            // of SPP jittered samples may stray 4 σ/√SPP from it (light
            // sampling of so small a sphere adds next to nothing), plus
            // 1 % for the f32 cone.
            let mut values = Vec::with_capacity(64);
            for k in 0..64 {
                let at = Vec2::new(
                    x as f32 + (k % 8) as f32 / 8.0 + 1.0 / 16.0,
                    y as f32 + (k / 8) as f32 / 8.0 + 1.0 / 16.0,
                );
                let (o, d) = camera_ray(&scene, size, at);
                let t = -o.y / d.y;
                // Skip rays that miss the ground or pass near the emitter.
                if t <= 0.0 || ray_passes_near(o, d, t, light) {
                    break;
                }
                values.push(f64::from(closed_form(o + t * d)));
            }
            if values.len() < 64 {
                continue;
            }
            let expected = values.iter().sum::<f64>() / 64.0;
            let sigma = (values.iter().map(|v| (v - expected).powi(2)).sum::<f64>() / 64.0).sqrt();
            let tolerance = 4.0 * sigma / f64::from(SPP).sqrt() + 0.01 * expected;
            let got = pixels[(y * size.0 + x) as usize];
            for c in &got[..3] {
                assert!(
                    (f64::from(*c) - expected).abs() < tolerance,
                    "pixel {x},{y}: {got:?}, closed form {expected} (tolerance {tolerance})"
                );
            }
            checked += 1;
        }
    }
    assert!(checked > 300, "only {checked} ground pixels checked");
}

/// Whether the ray o + s d, 0 < s < t, passes within 0.05 of `c` (where the
/// emitter would hide the ground).
fn ray_passes_near(o: Vec3, d: Vec3, t: f32, c: Vec3) -> bool {
    let s = (c - o).dot(d).clamp(0.0, t);
    (o + s * d - c).length() < 0.05
}
