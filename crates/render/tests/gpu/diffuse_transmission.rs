//! Diffuse transmission (N3D's TD) against closed forms: light arriving on
//! one side of a thin sheet leaves the other scattered by f = TD/π.

use crate::common::*;
use glam::Vec3;
use marbre_core::envmap::EnvImage;
use marbre_core::scene::{
    EnvSource, Material, OrbitCamera, PointLight, Polygon, Scene, Strategy, Texture,
};
use marbre_render::gpu::testing::gpu_or_skip;
use marbre_render::gpu::{GpuContext, Renderer};
use marbre_render::session::accumulate;
use std::f32::consts::PI;

/// A sheet of diffuse `diffuse`, diffuse transmission `td` and no specular.
fn sheet_material(diffuse: f32, td: f32) -> Material {
    Material {
        diffuse_transmission: Texture::color(Vec3::splat(td)),
        ..lambert(diffuse)
    }
}

/// A horizontal 4 × 4 square sheet at y = 0, seen from above.
fn sheet_scene(material: Material) -> Scene {
    Scene {
        polygons: vec![Polygon {
            vertices: vec![
                Vec3::new(-2.0, 0.0, -2.0),
                Vec3::new(-2.0, 0.0, 2.0),
                Vec3::new(2.0, 0.0, 2.0),
                Vec3::new(2.0, 0.0, -2.0),
            ],
            material,
            ..Polygon::default()
        }],
        camera: OrbitCamera {
            target: Vec3::ZERO,
            distance: 5.0,
            yaw_degrees: 0.0,
            pitch_degrees: 89.0,
            fov_degrees: 10.0,
            ..Default::default()
        },
        ..Scene::default()
    }
}

/// A point light of intensity I a height h under a sheet of transmission
/// TD, seen from above: the point over the light sends up
/// L = TD/π · I / h², the light it receives on its underside. The same sheet
/// with TD = 0 stays black there (nothing leaks through).
#[test]
fn a_point_light_behind_a_sheet_shines_through_as_the_closed_form() {
    let Some(ctx) = gpu_or_skip("a_point_light_behind_a_sheet_shines_through_as_the_closed_form")
    else {
        return;
    };
    let (td, intensity, height) = (0.6_f32, 20.0_f32, 2.0_f32);
    let (w, h) = (33, 33);
    let centre = |td: f32| {
        let mut scene = sheet_scene(sheet_material(0.3, td));
        scene.point_light = Some(PointLight {
            position: Vec3::new(0.0, -height, 0.0),
            color: Vec3::ONE,
            intensity,
        });
        let pixels = render(&ctx, &scene, (w, h), 16);
        pixels[(16 * w + 16) as usize]
    };
    let expected = td / PI * intensity / (height * height);
    // The pixel's footprint is ~0.03 units wide: cos⁴ falls under 0.1 %.
    assert_channels_near(centre(td), expected, 2e-3, "through the sheet");
    let opaque = centre(0.0);
    assert!(opaque[..3].iter().all(|&c| c == 0.0), "TD = 0: {opaque:?}");
}

/// `scene` under the lat-long `env`, by the fragment kernel.
fn render_in(ctx: &GpuContext, scene: &Scene, env: &EnvImage, size: (u32, u32)) -> Vec<[f32; 4]> {
    let mut r = Renderer::new(ctx, scene, Some(env), size).unwrap();
    accumulate(ctx, &mut r, 64, |_| {}).unwrap();
    assert!(r.count_non_finite(ctx).unwrap().is_zero());
    r.read_radiance(ctx).unwrap().2
}

/// A white furnace for the transmission lobe: a sheet of diffuse ρd and
/// transmission TD in light of radiance 1 from every direction reads
/// ρd + TD on the side the camera sees (the reflected half plus what
/// crosses from the other side), for a constant environment and for a
/// constant map found by light sampling, BSDF sampling and both with MIS
/// (the map's samples behind the sheet must be weighed with the
/// transmission lobe's pdf). Each mean over the sheet's pixels is within
/// four standard errors of the closed form.
#[test]
fn a_translucent_sheet_in_a_white_furnace_reads_diffuse_plus_transmission() {
    let Some(ctx) =
        gpu_or_skip("a_translucent_sheet_in_a_white_furnace_reads_diffuse_plus_transmission")
    else {
        return;
    };
    let (diffuse, td) = (0.3_f32, 0.5_f32);
    let expected = diffuse + td;
    let (w, h) = (24, 24);
    let check = |pixels: &[[f32; 4]], what: &str| {
        // The sheet fills the view; every pixel is one estimate.
        let values: Vec<f64> = pixels.iter().map(|p| f64::from(p[1])).collect();
        let n = values.len() as f64;
        let mean = values.iter().sum::<f64>() / n;
        let variance = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
        let se = (variance / n).sqrt();
        assert!(
            (mean - f64::from(expected)).abs() < 4.0 * se + 1e-4,
            "{what}: mean {mean} ± {se}, expected {expected}"
        );
        assert!(
            se > 0.0,
            "{what}: the lobes are chosen at random, so pixels vary"
        );
    };
    let mut scene = sheet_scene(sheet_material(diffuse, td));
    scene.environment.source = EnvSource::Constant {
        radiance: Vec3::ONE,
    };
    check(&render(&ctx, &scene, (w, h), 64), "constant environment");
    let env = marbre_core::envmap::constant(64, 32, [1.0, 1.0, 1.0]);
    scene.environment.source = EnvSource::LatLong {
        path: "map given directly".into(),
    };
    scene.render.env_importance = true;
    for strategy in [
        Strategy::Light,
        Strategy::Bsdf,
        Strategy::MisBalance,
        Strategy::MisPower,
    ] {
        scene.render.transport.strategy = strategy;
        check(
            &render_in(&ctx, &scene, &env, (w, h)),
            &format!("constant map, {strategy:?}"),
        );
    }
}

/// bsdf.wgsl's transmission lobe against its CPU twin (bsdf.rs): for a
/// surface with diffuse, GGX and TD lobes, the GPU's samples from the same
/// numbers (directions across the surface included) and its value and pdf
/// at directions over the whole sphere agree with the CPU's.
#[test]
fn the_transmission_lobe_on_the_gpu_matches_the_cpu_twin() {
    let Some(ctx) = gpu_or_skip("the_transmission_lobe_on_the_gpu_matches_the_cpu_twin") else {
        return;
    };
    use marbre_core::bsdf::{Surface, eval_bsdf, sample_bsdf};
    use marbre_render::gpu::harness::sampling::{BsdfSetup, SamplingHarness};
    let env = marbre_core::envmap::constant(4, 2, [0.0, 0.0, 0.0]);
    let harness = SamplingHarness::new(&ctx, &env, wgpu::FilterMode::Linear).unwrap();
    let n = Vec3::new(0.3, 0.9, 0.2).normalize();
    let setup = BsdfSetup {
        surface: Surface {
            diffuse: Vec3::new(0.3, 0.2, 0.1),
            specular: Vec3::splat(0.2),
            alpha: Surface::alpha_for(0.4),
            mirror: 0.1,
            diffuse_transmission: Vec3::new(0.4, 0.5, 0.6),
            uniform_diffuse: false,
        },
        n,
        wo: (n + 0.5 * n.any_orthonormal_vector()).normalize(),
    };
    let k = 16usize;
    let u: Vec<[f32; 4]> = (0..k * k * k * k)
        .map(|i| [0, 1, 2, 3].map(|d: u32| ((i / k.pow(d)) % k) as f32 / k as f32 + 0.5 / k as f32))
        .collect();
    let close = |a: Vec3, b: Vec3, tolerance: f32| {
        (a - b).abs().max_element() <= tolerance * b.abs().max_element().max(1.0)
    };
    let mut across = 0;
    for (u, gpu) in u
        .iter()
        .zip(harness.bsdf_samples(&ctx, &setup, &u).unwrap())
    {
        let cpu = sample_bsdf(&setup.surface, setup.n, setup.wo, *u);
        assert_eq!(gpu.valid, cpu.valid, "{u:?}: {gpu:?} vs {cpu:?}");
        assert!(close(gpu.wi, cpu.wi, 1e-4), "{u:?}: {gpu:?} vs {cpu:?}");
        if cpu.valid {
            assert!(
                close(gpu.weight, cpu.weight, 1e-3),
                "{u:?}: {gpu:?} vs {cpu:?}"
            );
            assert!(
                (gpu.pdf - cpu.pdf).abs() <= 1e-3 * cpu.pdf.max(1.0),
                "{u:?}: {gpu:?} vs {cpu:?}"
            );
            across += usize::from(cpu.wi.dot(n) < 0.0);
        }
    }
    assert!(
        across > u.len() / 5,
        "only {across} samples crossed the surface"
    );
    let directions: Vec<Vec3> = (0..2000)
        .map(|i| {
            let z = -1.0 + 2.0 * (i as f32 + 0.5) / 2000.0;
            let phi = i as f32 * 2.399_963;
            let r = (1.0 - z * z).sqrt();
            Vec3::new(r * phi.cos(), r * phi.sin(), z)
        })
        .collect();
    for (wi, gpu) in directions
        .iter()
        .zip(harness.bsdf_evals(&ctx, &setup, &directions).unwrap())
    {
        let cpu = eval_bsdf(&setup.surface, setup.n, setup.wo, *wi);
        assert!(
            close(gpu.f_cos, cpu.f_cos, 1e-3),
            "{wi}: {gpu:?} vs {cpu:?}"
        );
        assert!(
            (gpu.pdf - cpu.pdf).abs() <= 1e-3 * cpu.pdf.max(1.0),
            "{wi}: {gpu:?} vs {cpu:?}"
        );
    }
}
