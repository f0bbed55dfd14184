//! OIDN itself, on images whose answer is known.

use marbre_oidn::{Denoiser, DeviceKind, Guides, Images, Quality, library_or_skip};

fn cpu(test: &str) -> Option<Denoiser> {
    let lib = library_or_skip(test)?;
    Some(Denoiser::new(lib, DeviceKind::Cpu).expect("OIDN's CPU device"))
}

/// A flat grey wall, its guides flat too: nothing to remove. The image's
/// mean stays within 1e-3, and every pixel, at the edges too, within 0.4 %
/// (the fast network: 2e-3 and 1 %): OIDN's network itself ripples by up
/// to 0.5 % on a flat image (its `oidnDenoise` alike), and without the
/// mirrored borders its outer 16 pixels came back 5 % (high) to 17 %
/// (fast) off.
#[test]
fn a_constant_image_stays_constant() {
    let Some(mut oidn) = cpu("a_constant_image_stays_constant") else {
        return;
    };
    let (w, h) = (96, 64);
    let n = w * h;
    for value in [0.5f32, 3.0] {
        let colour = vec![[value; 3]; n];
        let albedo = vec![[0.5; 3]; n];
        let normal = vec![[0.0, 0.0, 1.0]; n];
        for quality in [Quality::High, Quality::Balanced, Quality::Fast] {
            let out = oidn
                .denoise(
                    &Images {
                        size: (w as u32, h as u32),
                        colour: &colour,
                        guides: Some(Guides {
                            albedo: &albedo,
                            normal: &normal,
                        }),
                    },
                    quality,
                )
                .unwrap();
            let relative = |v: f32| (v / value - 1.0).abs();
            let mean = out.iter().flatten().sum::<f32>() / (3 * n) as f32;
            let (mean_tolerance, pixel_tolerance) = match quality {
                Quality::Fast => (2e-3, 1e-2),
                _ => (1e-3, 4e-3),
            };
            assert!(
                relative(mean) < mean_tolerance,
                "{quality:?}, {value}: mean {mean}"
            );
            let (worst, at) = out
                .iter()
                .enumerate()
                .map(|(i, p)| (relative(p[0]).max(relative(p[1])).max(relative(p[2])), i))
                .fold((0.0f32, 0), |a, b| if b.0 > a.0 { b } else { a });
            assert!(
                worst < pixel_tolerance,
                "{quality:?}, {value}: pixel ({}, {}) off by {worst}",
                at % w,
                at / w
            );
        }
    }
}

/// NaN, ±Inf, negative and huge pixels in the colour and both guides:
/// every output pixel is finite and non-negative.
#[test]
fn bad_values_give_finite_output() {
    let Some(mut oidn) = cpu("bad_values_give_finite_output") else {
        return;
    };
    let size = (32, 32);
    let bad = [
        f32::NAN,
        f32::INFINITY,
        f32::NEG_INFINITY,
        -5.0,
        1e30,
        f32::MAX,
    ];
    let colour: Vec<[f32; 3]> = (0..1024)
        .map(|i| [bad[i % 6], 0.5, bad[(i / 7) % 6]])
        .collect();
    let albedo: Vec<[f32; 3]> = (0..1024).map(|i| [bad[(i / 3) % 6], 0.5, 0.5]).collect();
    let normal: Vec<[f32; 3]> = (0..1024).map(|i| [0.0, bad[(i / 5) % 6], 1.0]).collect();
    for guides in [
        Some(Guides {
            albedo: &albedo,
            normal: &normal,
        }),
        None,
    ] {
        let out = oidn
            .denoise(
                &Images {
                    size,
                    colour: &colour,
                    guides,
                },
                Quality::High,
            )
            .unwrap();
        assert!(
            out.iter().flatten().all(|v| v.is_finite() && *v >= 0.0),
            "guided: {}",
            guides.is_some()
        );
    }
}

/// A smooth ramp with white noise of known spread: the denoised image is
/// far closer to the ramp than the noisy one (the noise's RMSE is 0.1).
#[test]
fn noise_on_a_ramp_is_removed() {
    let Some(mut oidn) = cpu("noise_on_a_ramp_is_removed") else {
        return;
    };
    let (w, h) = (128usize, 96usize);
    let truth: Vec<[f32; 3]> = (0..w * h)
        .map(|i| [0.2 + 0.6 * (i % w) as f32 / w as f32; 3])
        .collect();
    // A fixed xorshift stream: uniform noise of spread 0.1·√3.
    let mut state = 0x9e37_79b9u32;
    let mut uniform = move || {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        state as f32 / u32::MAX as f32 - 0.5
    };
    let noisy: Vec<[f32; 3]> = truth
        .iter()
        .map(|t| {
            let e = uniform() * 0.1 * 12f32.sqrt();
            [t[0] + e, t[1] + e, t[2] + e]
        })
        .collect();
    let albedo = vec![[0.8; 3]; w * h];
    let normal = vec![[0.0, 0.0, 1.0]; w * h];
    let out = oidn
        .denoise(
            &Images {
                size: (w as u32, h as u32),
                colour: &noisy,
                guides: Some(Guides {
                    albedo: &albedo,
                    normal: &normal,
                }),
            },
            Quality::High,
        )
        .unwrap();
    let rmse = |image: &[[f32; 3]]| {
        let sum: f64 = image
            .iter()
            .zip(&truth)
            .map(|(a, b)| f64::from(a[0] - b[0]).powi(2))
            .sum();
        (sum / image.len() as f64).sqrt()
    };
    let (before, after) = (rmse(&noisy), rmse(&out));
    assert!((before - 0.1).abs() < 0.01, "noise RMSE {before}");
    assert!(after < 0.3 * before, "RMSE {before} → {after}");
}

/// A guide of another length is refused with the sizes, not read past.
#[test]
fn mismatched_lengths_are_refused() {
    let Some(mut oidn) = cpu("mismatched_lengths_are_refused") else {
        return;
    };
    let colour = vec![[0.5; 3]; 16];
    let short = vec![[0.5; 3]; 15];
    let err = oidn
        .denoise(
            &Images {
                size: (4, 4),
                colour: &colour,
                guides: Some(Guides {
                    albedo: &short,
                    normal: &colour,
                }),
            },
            Quality::Fast,
        )
        .unwrap_err();
    assert!(err.to_string().contains("4×4"), "{err}");
}

/// The device says what it is.
#[test]
fn the_device_reports_its_version() {
    let Some(oidn) = cpu("the_device_reports_its_version") else {
        return;
    };
    assert_eq!(oidn.kind(), DeviceKind::Cpu);
    assert!(oidn.version().starts_with("2."), "{}", oidn.version());
}

/// The cancel flag stops a denoise (set before it, as a window closing
/// does while one runs) with a "cancelled" error, not a failure; cleared,
/// the same denoiser runs again.
#[test]
fn the_cancel_flag_stops_a_denoise() {
    let Some(mut oidn) = cpu("the_cancel_flag_stops_a_denoise") else {
        return;
    };
    let colour = vec![[0.5; 3]; 64 * 64];
    let images = Images {
        size: (64, 64),
        colour: &colour,
        guides: None,
    };
    let flag = oidn.cancel_flag();
    flag.store(true, std::sync::atomic::Ordering::Relaxed);
    let err = oidn.denoise(&images, Quality::Fast).unwrap_err();
    assert!(err.cancelled, "{err}");
    flag.store(false, std::sync::atomic::Ordering::Relaxed);
    assert_eq!(oidn.denoise(&images, Quality::Fast).unwrap().len(), 64 * 64);
}
