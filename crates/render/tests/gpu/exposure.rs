//! Auto exposure: the GPU's metering against its CPU twin, and what the
//! display pass (screen, PNG) makes of it.

use crate::common::*;
use glam::Vec3;
use marbre_core::scene::{Metering, PointLight, Scene, ToneMap};
use marbre_render::gpu::auto_exposure::{
    AutoExposure, DELTA, KEY, exposure_stops, log_average_luminance, massal_stops, meter,
    rms_luminance,
};
use marbre_render::gpu::metering_grid::grid_pixels;
use marbre_render::gpu::testing::gpu_or_skip;
use marbre_render::gpu::{GpuContext, Renderer};
use marbre_render::session::accumulate;
use wgpu::util::DeviceExt;

/// `scene` traced at `spp` from a fresh renderer (so two scenes see the same
/// random numbers).
fn traced(ctx: &GpuContext, scene: &Scene, size: (u32, u32), spp: u32) -> Renderer {
    let mut r = Renderer::new(ctx, scene, None, size).unwrap();
    accumulate(ctx, &mut r, spp, |_| {}).unwrap();
    r
}

/// The largest difference between two displayed images, in 8-bit levels.
fn max_difference(a: &image::RgbaImage, b: &image::RgbaImage) -> u8 {
    a.as_raw()
        .iter()
        .zip(b.as_raw())
        .map(|(x, y)| x.abs_diff(*y))
        .max()
        .unwrap()
}

/// An environment 1000× brighter makes every radiance 1000× larger; auto
/// exposure divides it out again, so the two display alike. Without it they
/// do not (the premise).
#[test]
fn auto_exposure_displays_dim_and_bright_light_alike() {
    let Some(ctx) = gpu_or_skip("auto_exposure_displays_dim_and_bright_light_alike") else {
        return;
    };
    let size = (48, 32);
    let mut shown = Vec::new();
    for auto_exposure in [false, true] {
        let images: Vec<image::RgbaImage> = [0.05, 50.0]
            .map(|radiance| {
                let mut scene = spheres_in_constant_light(radiance);
                scene.render.display.auto_exposure = auto_exposure;
                traced(&ctx, &scene, size, 4).read_display(&ctx).unwrap()
            })
            .into();
        shown.push(max_difference(&images[0], &images[1]));
        if auto_exposure {
            // Not a black or white image: the metering found the mid-tones.
            let rgb: Vec<f32> = images[1]
                .pixels()
                .flat_map(|p| p.0[..3].iter().map(|&v| f32::from(v)))
                .collect();
            let mean = rgb.iter().sum::<f32>() / rgb.len() as f32;
            assert!((60.0..220.0).contains(&mean), "mean level {mean}");
        }
    }
    let [manual, auto] = shown[..] else {
        unreachable!()
    };
    assert!(
        manual > 100,
        "manual exposure: the premise fails ({manual})"
    );
    // δ = 1e-4 against radiances of 5e-3 and more: under 2% of a stop.
    assert!(auto <= 2, "auto exposure: images differ by {auto} levels");
}

/// The metering pass reads every texel of an image up to 256 on a side (a
/// centred strided grid beyond) and agrees with the CPU twin on the
/// rendered radiance.
#[test]
fn gpu_log_average_matches_the_cpu_twin() {
    let Some(ctx) = gpu_or_skip("gpu_log_average_matches_the_cpu_twin") else {
        return;
    };
    let mut scene = spheres_in_constant_light(0.2);
    // A light makes a wide range of luminances (and noise) to average.
    scene.point_light = Some(PointLight {
        position: Vec3::new(0.0, 3.0, 2.0),
        color: Vec3::new(1.0, 0.9, 0.7),
        intensity: 40.0,
    });
    scene.render.display.auto_exposure = true;
    for (size, strided) in [((64, 40), false), ((300, 270), true)] {
        let mut r = traced(&ctx, &scene, size, 2);
        let gpu = r.metering(&ctx).unwrap();
        let (w, h, pixels) = r.read_radiance(&ctx).unwrap();
        assert_eq!((w, h), size);
        let metered = grid_pixels(&pixels, size);
        let cpu = log_average_luminance(&metered);
        if !strided {
            assert_eq!(metered, pixels);
            assert_eq!(cpu, log_average_luminance(&pixels));
        }
        assert_eq!(gpu.count as usize, metered.len(), "{size:?}");
        let relative = (gpu.log_average - cpu).abs() / cpu;
        assert!(
            relative < 1e-3,
            "{size:?}: GPU {} vs CPU {cpu}",
            gpu.log_average
        );
        assert!((gpu.stops - exposure_stops(cpu)).abs() < 2e-3, "{gpu:?}");
        assert!((gpu.scale - gpu.stops.exp2()).abs() < 1e-4 * gpu.scale);
        // The grid stands for the whole image.
        let whole = log_average_luminance(&pixels);
        assert!((cpu - whole).abs() < 0.05 * whole, "{cpu} vs {whole}");
        // Massal's RMS luminance and exposure from the same texels.
        let rms = rms_luminance(&metered);
        assert!(
            (gpu.rms - rms).abs() < 1e-4 * rms,
            "{size:?}: {gpu:?} vs {rms}"
        );
        assert!((gpu.rms_stops - massal_stops(rms)).abs() < 2e-4, "{gpu:?}");
        assert!((gpu.rms_scale - gpu.rms_stops.exp2()).abs() < 1e-4 * gpu.rms_scale);
        assert!(
            (gpu.rms_stops - gpu.stops).abs() > 0.1,
            "the two differ: {gpu:?}"
        );
    }
}

/// The metering pass on a texture of chosen values: NaN, ±Inf and negative
/// texels are skipped, the region is honoured, and black gives a bounded
/// exposure.
#[test]
fn metering_skips_non_finite_and_negative_texels() {
    let Some(ctx) = gpu_or_skip("metering_skips_non_finite_and_negative_texels") else {
        return;
    };
    let (w, h) = (20_u32, 10_u32);
    let clean: Vec<[f32; 4]> = (0..w * h)
        .map(|i| {
            let t = i as f32 / (w * h) as f32;
            [0.02 + 3.0 * t, 0.5 * t * t, 1.0 - t, 1.0]
        })
        .collect();
    let mut dirty = clean.clone();
    let bad = [
        [f32::NAN, 0.5, 0.5, 1.0],
        [0.5, f32::INFINITY, 0.5, 1.0],
        [0.5, 0.5, f32::NEG_INFINITY, 1.0],
        [-1.0, 0.5, 0.5, 1.0],
        [0.2, -1e-3, 0.5, 1.0],
        [f32::NAN; 4],
    ];
    let bad_at = [3, 17, 44, 90, 101, 150];
    for (i, p) in bad_at.iter().zip(bad) {
        dirty[*i] = p;
    }
    let expected: Vec<[f32; 4]> = dirty
        .iter()
        .enumerate()
        .filter(|(i, _)| !bad_at.contains(i))
        .map(|(_, p)| *p)
        .collect();
    let metering = AutoExposure::new(&ctx.device).unwrap();
    let run = |pixels: &[[f32; 4]], region: (u32, u32)| {
        let texture = ctx.device.create_texture_with_data(
            &ctx.queue,
            &wgpu::TextureDescriptor {
                label: Some("test radiance"),
                size: wgpu::Extent3d {
                    width: w,
                    height: h,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: wgpu::TextureFormat::Rgba32Float,
                usage: wgpu::TextureUsages::TEXTURE_BINDING,
                view_formats: &[],
            },
            wgpu::util::TextureDataOrder::LayerMajor,
            bytemuck::cast_slice(pixels),
        );
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        metering.record(
            &ctx,
            &mut encoder,
            &texture.create_view(&Default::default()),
            region,
            None,
        );
        ctx.queue.submit([encoder.finish()]);
        metering.read(&ctx).unwrap()
    };
    let near = |a: f32, b: f32| (a - b).abs() <= 1e-4 * b.abs();

    let got = run(&dirty, (w, h));
    assert_eq!(got.count as usize, expected.len());
    assert!(got.log_average.is_finite() && got.scale.is_finite());
    let cpu = meter(&dirty);
    assert_eq!(cpu, meter(&expected));
    assert!(near(got.log_average, cpu.log_average), "{got:?} vs {cpu:?}");
    assert!((got.stops - cpu.stops).abs() < 1e-3, "{got:?} vs {cpu:?}");
    // Massal's RMS over the same known texels: his sum of weighted squares.
    let his_rms = (expected
        .iter()
        .map(|p| {
            0.2126 * p[0] as f64 * p[0] as f64
                + 0.715160 * p[1] as f64 * p[1] as f64
                + 0.072169 * p[2] as f64 * p[2] as f64
        })
        .sum::<f64>()
        / expected.len() as f64)
        .sqrt() as f32;
    assert!(near(got.rms, his_rms), "{got:?} vs {his_rms}");
    assert!(near(got.rms_scale, -(0.6_f32.ln()) / his_rms), "{got:?}");

    // A region: the top-left 13×7 texels only.
    let region = (13, 7);
    let sub: Vec<[f32; 4]> = (0..region.1)
        .flat_map(|y| (0..region.0).map(move |x| (x, y)))
        .map(|(x, y)| dirty[(y * w + x) as usize])
        .collect();
    let got = run(&dirty, region);
    let cpu = meter(&sub);
    assert_eq!(got.count, cpu.count);
    assert!(near(got.log_average, cpu.log_average), "{got:?} vs {cpu:?}");

    // Black, and nothing usable at all: L_avg = δ, a finite exposure.
    let black_stops = (KEY / DELTA).log2();
    for pixels in [
        vec![[0.0; 4]; (w * h) as usize],
        vec![[f32::NAN; 4]; (w * h) as usize],
    ] {
        let got = run(&pixels, (w, h));
        assert!(near(got.log_average, DELTA), "{got:?}");
        assert!((got.stops - black_stops).abs() < 1e-3, "{got:?}");
        assert!(got.scale.is_finite());
        // Massal's default exposure below an RMS of 0.001: scale 1.
        assert_eq!((got.rms, got.rms_stops, got.rms_scale), (0.0, 0.0, 1.0));
    }
}

/// What the display pass shows (the PNG of `marbre render` and of F12, and
/// the screen) is the radiance scaled by 2^(metered stops + compensation),
/// tone mapped: checked against the CPU with Reinhard's x / (1 + x).
#[test]
fn displayed_pixels_are_the_radiance_at_the_metered_exposure() {
    let Some(ctx) = gpu_or_skip("displayed_pixels_are_the_radiance_at_the_metered_exposure") else {
        return;
    };
    let size = (40, 30);
    for compensation in [0.0, 1.5] {
        let mut scene = spheres_in_constant_light(3.0);
        scene.render.display.auto_exposure = true;
        scene.render.display.exposure = compensation;
        scene.render.display.tone_map = ToneMap::Reinhard;
        let mut r = traced(&ctx, &scene, size, 2);
        let shown = r.read_display(&ctx).unwrap();
        let (_, _, pixels) = r.read_radiance(&ctx).unwrap();
        let stops = exposure_stops(log_average_luminance(&pixels));
        // Bright light: the automatic exposure darkens.
        assert!(stops < -2.0, "{stops}");
        let scale = (stops + compensation).exp2();
        let encode = |c: f32| {
            let c = c.max(0.0) * scale;
            let c = c / (1.0 + c);
            let s = if c <= 0.003_130_8 {
                c * 12.92
            } else {
                1.055 * c.powf(1.0 / 2.4) - 0.055
            };
            s * 255.0
        };
        for (p, q) in pixels.iter().zip(shown.pixels()) {
            for c in 0..3 {
                let expected = encode(p[c]);
                assert!(
                    (f32::from(q[c]) - expected).abs() <= 1.0,
                    "compensation {compensation}: radiance {p:?} shows {q:?}, expected {expected}"
                );
            }
        }
    }
}

/// Massal's auto exposure with his curve is his whole display: each
/// pixel shows 1 − exp(e · c) with e = ln(0.6) / L_rms, L_rms metered by
/// the GPU and recomputed here from the radiance (sRGB encoded, within one
/// 8-bit level); and switching the metering is display-only.
#[test]
fn massal_auto_exposure_shows_his_exposure_curve() {
    let Some(ctx) = gpu_or_skip("massal_auto_exposure_shows_his_exposure_curve") else {
        return;
    };
    let size = (40, 30);
    let mut scene = spheres_in_constant_light(3.0);
    scene.render.display.auto_exposure = true;
    scene.render.display.metering = Metering::MassalRms;
    scene.render.display.tone_map = ToneMap::Exponential;
    let mut r = traced(&ctx, &scene, size, 2);
    let shown = r.read_display(&ctx).unwrap();
    let (_, _, pixels) = r.read_radiance(&ctx).unwrap();
    let weights = [0.2126_f64, 0.715160, 0.072169];
    let mean_square: f64 = pixels
        .iter()
        .map(|p| {
            (0..3)
                .map(|c| weights[c] * f64::from(p[c]).powi(2))
                .sum::<f64>()
        })
        .sum::<f64>()
        / pixels.len() as f64;
    let e = 0.6_f64.ln() / mean_square.sqrt();
    let encode = |c: f32| {
        let c = (1.0 - (e * f64::from(c.max(0.0))).exp()) as f32;
        let s = if c <= 0.003_130_8 {
            c * 12.92
        } else {
            1.055 * c.powf(1.0 / 2.4) - 0.055
        };
        s * 255.0
    };
    for (p, q) in pixels.iter().zip(shown.pixels()) {
        for c in 0..3 {
            let expected = encode(p[c]);
            assert!(
                (f32::from(q[c]) - expected).abs() <= 1.0,
                "radiance {p:?} shows {q:?}, expected {expected} (e = {e})"
            );
        }
    }
    scene.render.display.metering = Metering::Key;
    r.set_scene(&ctx, &scene).unwrap();
    assert_eq!(r.accumulated_samples(), 2);
    let by_key = r.read_display(&ctx).unwrap();
    assert!(max_difference(&shown, &by_key) > 10, "the metering shows");
}

/// Toggling auto exposure and moving the exposure are display-only: the
/// accumulated samples stay (and a traced edit does restart them).
#[test]
fn exposure_edits_keep_the_samples() {
    let Some(ctx) = gpu_or_skip("exposure_edits_keep_the_samples") else {
        return;
    };
    let scene = spheres_in_constant_light(1.0);
    let mut r = traced(&ctx, &scene, (16, 16), 3);
    let before = r.read_display(&ctx).unwrap();
    let mut edited = scene.clone();
    edited.render.display.auto_exposure = true;
    edited.render.display.exposure = -1.0;
    r.set_scene(&ctx, &edited).unwrap();
    assert_eq!(r.accumulated_samples(), 3);
    let after = r.read_display(&ctx).unwrap();
    assert!(max_difference(&before, &after) > 10, "the edit shows");
    edited.render.display.auto_exposure = false;
    r.set_scene(&ctx, &edited).unwrap();
    assert_eq!(r.accumulated_samples(), 3);
    edited.render.max_bounces += 1;
    r.set_scene(&ctx, &edited).unwrap();
    assert_eq!(r.accumulated_samples(), 0);
}

/// Every tone curve on the display pass against its formula on the CPU,
/// at a manual exposure: ACES (Narkowicz's fit), Reinhard, clamp and
/// Massal's 1 − exp(−x).
#[test]
fn each_tone_map_shows_its_curve() {
    let Some(ctx) = gpu_or_skip("each_tone_map_shows_its_curve") else {
        return;
    };
    let stops = 0.5_f32;
    let curve = |tone_map: ToneMap, x: f32| match tone_map {
        ToneMap::Aces => ((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14)).clamp(0.0, 1.0),
        ToneMap::Reinhard => x / (1.0 + x),
        ToneMap::Clamp => x.clamp(0.0, 1.0),
        ToneMap::Exponential => 1.0 - (-x).exp(),
    };
    let srgb = |c: f32| {
        let s = if c <= 0.003_130_8 {
            c * 12.92
        } else {
            1.055 * c.powf(1.0 / 2.4) - 0.055
        };
        s * 255.0
    };
    let mut scene = spheres_in_constant_light(1.0);
    scene.render.display.exposure = stops;
    let mut r = traced(&ctx, &scene, (24, 18), 2);
    let (_, _, pixels) = r.read_radiance(&ctx).unwrap();
    let mut shown_by = Vec::new();
    for tone_map in ToneMap::ALL {
        scene.render.display.tone_map = tone_map;
        r.set_scene(&ctx, &scene).unwrap();
        let shown = r.read_display(&ctx).unwrap();
        for (p, q) in pixels.iter().zip(shown.pixels()) {
            for c in 0..3 {
                let expected = srgb(curve(tone_map, p[c].max(0.0) * stops.exp2()));
                assert!(
                    (f32::from(q[c]) - expected).abs() <= 1.0,
                    "{tone_map:?}: radiance {p:?} shows {q:?}, expected {expected}"
                );
            }
        }
        shown_by.push(shown);
    }
    // The curves differ where the image is bright enough to tell them apart.
    assert!(max_difference(&shown_by[1], &shown_by[3]) > 5);
}
