//! The course scenes as the documents show them (issue 31, point 3): each
//! shipped preset rendered through the real display pass and measured where
//! the documents say what should be seen: TP05's marble veins dark and thin,
//! bare metal that reflects the sky, the report's BRIQUE in its CD1, typed
//! colours shown as typed, both of the lab's two panels in frame at a fixed
//! exposure, the studio without a black band, the default ground crisp.

use glam::{Vec2, Vec3};
use marbre_core::scene::{Scene, View};
use marbre_render::gpu::GpuContext;
use marbre_render::gpu::testing::gpu_or_skip;
use marbre_render::session::{accumulate, load_scene, renderer_for};
use std::path::Path;

/// A shipped preset rendered with `spp` samples at `size` and shown as its
/// display settings say (exposure, tone map, sRGB): the image a user sees.
fn shown(ctx: &GpuContext, preset: &str, size: (u32, u32), spp: u32) -> (Scene, image::RgbaImage) {
    shown_as(ctx, preset, size, spp, View::Lit)
}

/// [`shown`] with each sample recording `view` instead of the preset's.
fn shown_as(
    ctx: &GpuContext,
    preset: &str,
    size: (u32, u32),
    spp: u32,
    view: View,
) -> (Scene, image::RgbaImage) {
    let mut loaded = load_scene(&Path::new(crate::REPO).join(preset), None).unwrap();
    loaded.scene.render.view = view;
    let mut renderer = renderer_for(ctx, &loaded, size).unwrap();
    accumulate(ctx, &mut renderer, spp, |_| {}).unwrap();
    let image = renderer.read_display(ctx).unwrap();
    (loaded.scene, image)
}

/// Rec. 709 luminance of a pixel's encoded values, 0–255.
fn luminance(p: &image::Rgba<u8>) -> f32 {
    0.2126 * f32::from(p[0]) + 0.7152 * f32::from(p[1]) + 0.0722 * f32::from(p[2])
}

/// Where the scene's camera images the point `p`, in pixels, and its depth.
fn project(scene: &Scene, (w, h): (u32, u32), p: Vec3) -> (Vec2, f32) {
    let f = scene.camera.frame();
    let d = p - f.position;
    let z = d.dot(f.forward);
    let aspect = w as f32 / h as f32;
    let x = d.dot(f.right) / z / (f.tan_half_fov * aspect);
    let y = d.dot(f.up) / z / f.tan_half_fov;
    (
        Vec2::new((x + 1.0) * 0.5 * w as f32, (1.0 - y) * 0.5 * h as f32),
        z,
    )
}

/// The pixels well inside the image of the sphere (`fill` of its apparent
/// radius), each with its offset from the disc's centre in radii.
fn disc<'a>(
    scene: &Scene,
    image: &'a image::RgbaImage,
    centre: Vec3,
    radius: f32,
    fill: f32,
) -> Vec<(Vec2, &'a image::Rgba<u8>)> {
    let size = image.dimensions();
    let (c, z) = project(scene, size, centre);
    let r = radius / z / scene.camera.frame().tan_half_fov * size.1 as f32 * 0.5;
    image
        .enumerate_pixels()
        .filter_map(|(x, y, p)| {
            let offset = (Vec2::new(x as f32 + 0.5, y as f32 + 0.5) - c) / r;
            (offset.length() < fill).then_some((offset, p))
        })
        .collect()
}

/// The sRGB EOTF (IEC 61966-2-1): an encoded value's linear light.
fn eotf(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// The value at fraction `q` of the sorted `values`.
fn quantile(values: &mut [f32], q: f32) -> f32 {
    values.sort_by(f32::total_cmp);
    values[((values.len() - 1) as f32 * q).round() as usize]
}

/// TP05's marble: white stone crossed by dark, thin veins. Over the
/// sphere, between 5 % and 25 % of the pixels are dark (luminance < 80),
/// the darkest 5 % are nearly black and the median is the white stone.
/// The old preset's two-colour blend drew soft grey smudges: 3 % dark
/// pixels, its darkest 5 % at 93.
#[test]
fn marble_veins_are_dark_and_thin() {
    let Some(ctx) = gpu_or_skip("marble_veins_are_dark_and_thin") else {
        return;
    };
    let (scene, image) = shown(&ctx, "presets/marble.ron", (256, 144), 16);
    let mut l: Vec<f32> = disc(&scene, &image, Vec3::new(0.0, 1.0, 0.0), 1.0, 0.8)
        .iter()
        .map(|(_, p)| luminance(p))
        .collect();
    let dark = l.iter().filter(|&&v| v < 80.0).count() as f32 / l.len() as f32;
    let p5 = quantile(&mut l, 0.05);
    let median = quantile(&mut l, 0.5);
    assert!((0.05..0.25).contains(&dark), "dark fraction {dark}");
    assert!(p5 < 70.0, "darkest 5 % at {p5}");
    assert!(median > 170.0, "median {median}");
}

/// The rust's bare metal is metal: it mirrors the sky, so where the
/// sphere faces up the grey (not orange) pixels are blue like the sky,
/// not the near-white of a diffuse paint. The old preset's rough, diffuse
/// "metal" showed (233, 234, 236) there.
#[test]
fn rust_bare_metal_mirrors_the_sky_rather_than_reading_as_white_paint() {
    let Some(ctx) =
        gpu_or_skip("rust_bare_metal_mirrors_the_sky_rather_than_reading_as_white_paint")
    else {
        return;
    };
    let (scene, image) = shown(&ctx, "presets/rust.ron", (256, 144), 32);
    let metal: Vec<_> = disc(&scene, &image, Vec3::new(0.0, 1.0, 0.0), 1.0, 0.8)
        .into_iter()
        .filter(|(offset, p)| offset.y < 0.0 && p[2] >= p[0])
        .map(|(_, p)| *p)
        .collect();
    assert!(metal.len() > 100, "{} bare metal pixels", metal.len());
    let n = metal.len() as f32;
    let blue_over_red = metal
        .iter()
        .map(|p| f32::from(p[2]) - f32::from(p[0]))
        .sum::<f32>()
        / n;
    let mean = metal.iter().map(luminance).sum::<f32>() / n;
    assert!(blue_over_red > 12.0, "blue − red {blue_over_red}");
    assert!(mean < 215.0, "mean luminance {mean}");
}

/// The report's BRIQUE (brique00): bricks of TURBULENCE CD1 0.54 0.11
/// 0.38 at FREQ 14 in a grey mortar. On the polygon the bricks show CD1's
/// hue (their albedo's blue/red and green/red, in linear light, CD1's
/// 0.47 and 0.05) and are not black: the old renderer faded the turbulence to
/// 0 wherever the footprint dropped its octaves, and the bricks read
/// black.
#[test]
fn brique_bricks_show_the_reports_cd1() {
    let Some(ctx) = gpu_or_skip("brique_bricks_show_the_reports_cd1") else {
        return;
    };
    // The gallery's size.
    let size = (256, 192);
    let (scene, image) = shown(&ctx, "presets/report/brique00.ron", size, 16);
    // The polygon's upper part (x in [-1.2, 1.2], y in [1.6, 2.6] at z =
    // -1.2), above the sphere and the cylinder.
    let (lo, _) = project(&scene, size, Vec3::new(-1.2, 2.6, -1.2));
    let (hi, _) = project(&scene, size, Vec3::new(1.2, 1.6, -1.2));
    let mut bricks = Vec::new();
    let (mut all, mut covered) = (0, 0);
    for y in lo.y.ceil() as u32..hi.y.floor() as u32 {
        for x in lo.x.ceil() as u32..hi.x.floor() as u32 {
            let p = image.get_pixel(x, y);
            all += 1;
            // The mortar is grey (r ≈ g); a brick is red over green, and
            // its colour is read where it is clearly so (not a pixel
            // shared with the mortar).
            let redder = f32::from(p[0]) - f32::from(p[1]);
            if redder > 12.0 {
                covered += 1;
            }
            if redder > 25.0 {
                bricks.push([0, 1, 2].map(|c| f32::from(p[c])));
            }
        }
    }
    let share = covered as f32 / all as f32;
    assert!(share > 0.5, "bricks cover {share} of the polygon");
    let n = bricks.len() as f32;
    let [r, g, b] = [0, 1, 2].map(|c| bricks.iter().map(|p| p[c]).sum::<f32>() / n);
    assert!(r > 60.0, "bricks ({r}, {g}, {b}) are nearly black");
    // Their hue, in the albedo view (lit, the specular's grey dilutes
    // it): the turbulence scales CD1, decoded (0.253, 0.0116, 0.119),
    // so the linear ratios are CD1's.
    let (_, albedo) = shown_as(&ctx, "presets/report/brique00.ron", size, 4, View::Albedo);
    let mut sum = [0.0f32; 3];
    let mut n = 0.0;
    for y in lo.y.ceil() as u32..hi.y.floor() as u32 {
        for x in lo.x.ceil() as u32..hi.x.floor() as u32 {
            let p = albedo.get_pixel(x, y);
            if p[0] > p[1].saturating_add(25) {
                for c in 0..3 {
                    sum[c] += eotf(f32::from(p[c]) / 255.0);
                }
                n += 1.0;
            }
        }
    }
    assert!(n > 0.5 * all as f32, "{n} brick albedos of {all} pixels");
    let [r, g, b] = sum.map(|s| s / n);
    assert!(
        r > 0.25 * 0.253,
        "brick albedo ({r}, {g}, {b}) nearly black"
    );
    assert!((b / r - 0.47).abs() < 0.06, "blue/red {} (CD1 0.47)", b / r);
    assert!(g / r < 0.1, "green/red {} (CD1 0.046)", g / r);
}

/// The course display: the report's examples show the colours their text
/// types. UNI CD 0.7 0 0 on the polygon, lit about evenly by the
/// preview's light and sky, shows as red 0.7 (ACES showed it as 0.78);
/// `marbre tx` previews with the same display as the preset.
#[test]
fn report_presets_show_their_typed_colours() {
    let Some(ctx) = gpu_or_skip("report_presets_show_their_typed_colours") else {
        return;
    };
    let size = (256, 192);
    let (scene, image) = shown(&ctx, "presets/report/uni.ron", size, 16);
    let doc = marbre_core::tx::parse("UNI CD 0.7 0.0 0.0 CS 0.7 0.0 0.0 FTX").unwrap();
    let preview = marbre_core::tx_preview::preview_scene(&doc, Path::new("")).unwrap();
    assert_eq!(preview.render.display, scene.render.display);
    // The polygon's upper part, above the sphere and the cylinder: its
    // mean red (the light falls off across it, a highlight included).
    let (lo, _) = project(&scene, size, Vec3::new(-1.2, 2.6, -1.2));
    let (hi, _) = project(&scene, size, Vec3::new(1.2, 1.6, -1.2));
    let mut sum = [0.0f32; 3];
    let mut n = 0.0;
    for y in lo.y.ceil() as u32..hi.y.floor() as u32 {
        for x in lo.x.ceil() as u32..hi.x.floor() as u32 {
            let p = image.get_pixel(x, y);
            for c in 0..3 {
                sum[c] += f32::from(p[c]) / 255.0;
            }
            n += 1.0;
        }
    }
    let [r, g, b] = sum.map(|s| s / n);
    assert!((r - 0.7).abs() < 0.03, "mean ({r}, {g}, {b})");
    assert!(g < 0.03 && b < 0.03, "mean ({r}, {g}, {b})");
}

/// The saturated (white) blobs of `image`, 4-connected, each as its pixel
/// count and bounding box (x0, y0, x1, y1), those of more than 3 pixels.
fn white_blobs(image: &image::RgbaImage) -> Vec<(usize, [u32; 4])> {
    let (w, h) = image.dimensions();
    let white = |x: u32, y: u32| image.get_pixel(x, y).0[..3].iter().all(|&c| c >= 250);
    let mut seen = vec![false; (w * h) as usize];
    let mut blobs = Vec::new();
    for y in 0..h {
        for x in 0..w {
            if seen[(y * w + x) as usize] || !white(x, y) {
                continue;
            }
            seen[(y * w + x) as usize] = true;
            let mut stack = vec![(x, y)];
            let (mut count, mut b) = (0, [x, y, x, y]);
            while let Some((a, c)) = stack.pop() {
                count += 1;
                b = [b[0].min(a), b[1].min(c), b[2].max(a), b[3].max(c)];
                for (da, dc) in [(1i64, 0i64), (-1, 0), (0, 1), (0, -1)] {
                    let (na, nc) = (a as i64 + da, c as i64 + dc);
                    if na < 0 || nc < 0 || na >= w as i64 || nc >= h as i64 {
                        continue;
                    }
                    let (na, nc) = (na as u32, nc as u32);
                    if !seen[(nc * w + na) as usize] && white(na, nc) {
                        seen[(nc * w + na) as usize] = true;
                        stack.push((na, nc));
                    }
                }
            }
            if count > 3 {
                blobs.push((count, b));
            }
        }
    }
    blobs
}

/// The lab's exercise 6: both panels in frame, the small one seen as a
/// patch (at least a third as tall as wide, away from the image's edges)
/// rather than a sliver, and the walls grey at the preset's fixed exposure
/// (90 % of the other pixels below 180), where auto exposure whitened
/// them.
#[test]
fn two_panels_frames_both_panels_at_a_fixed_exposure() {
    let Some(ctx) = gpu_or_skip("two_panels_frames_both_panels_at_a_fixed_exposure") else {
        return;
    };
    let size = (256, 144);
    let (scene, image) = shown(&ctx, "presets/two_panels.ron", size, 16);
    assert!(!scene.render.display.auto_exposure);
    let mut blobs = white_blobs(&image);
    blobs.sort_by_key(|b| std::cmp::Reverse(b.0));
    assert_eq!(blobs.len(), 2, "{blobs:?}");
    for (count, [x0, y0, x1, y1]) in &blobs {
        assert!(
            *x0 > 0 && *y0 > 0 && *x1 < size.0 - 1 && *y1 < size.1 - 1,
            "a panel of {count} pixels touches the edge: {blobs:?}"
        );
    }
    let [x0, y0, x1, y1] = blobs[1].1;
    assert!(
        3 * (y1 - y0 + 1) > x1 - x0,
        "the small panel is a sliver: {blobs:?}"
    );
    let mut rest: Vec<f32> = image
        .pixels()
        .filter(|p| p.0[..3].iter().any(|&c| c < 250))
        .map(luminance)
        .collect();
    let p90 = quantile(&mut rest, 0.9);
    assert!(p90 < 180.0, "walls at {p90}");
}

/// The studio: no black band along the top of the image (the dark walls
/// above the horizon showed there), and the mirror sphere whole: its lower
/// part mirrors the ground, not black (the old one was a black dome over a
/// lower half lost in the bright floor).
#[test]
fn studio_has_no_black_band_and_a_whole_mirror() {
    let Some(ctx) = gpu_or_skip("studio_has_no_black_band_and_a_whole_mirror") else {
        return;
    };
    let size = (256, 144);
    let (scene, image) = shown(&ctx, "presets/studio.ron", size, 16);
    for y in 0..size.1 / 30 {
        let mean = (0..size.0)
            .map(|x| luminance(image.get_pixel(x, y)))
            .sum::<f32>()
            / size.0 as f32;
        assert!(mean > 60.0, "row {y}: mean luminance {mean}");
    }
    let mut lower: Vec<f32> = disc(&scene, &image, Vec3::new(-1.6, 0.9, 0.0), 0.9, 0.85)
        .iter()
        .filter(|(offset, _)| offset.y > 0.3)
        .map(|(_, p)| luminance(p))
        .collect();
    let p10 = quantile(&mut lower, 0.1);
    assert!(p10 > 60.0, "the mirror's lower part: 10 % below {p10}");
}

/// The studio without heavy noise: after 32 samples a pixel the error
/// meter's estimate of the radiance's RMSE (from the spread of each
/// pixel's frames) is under 0.25 (measured 0.10); the mirror's caustics on
/// the ground, found by chance, kept it at 2.4 (white speckles
/// everywhere).
#[test]
fn studio_is_not_speckled() {
    let Some(ctx) = gpu_or_skip("studio_is_not_speckled") else {
        return;
    };
    let mut loaded = load_scene(&Path::new(crate::REPO).join("presets/studio.ron"), None).unwrap();
    loaded.scene.render.samples_per_frame = 1;
    let mut renderer = renderer_for(&ctx, &loaded, (128, 72)).unwrap();
    accumulate(&ctx, &mut renderer, 32, |_| {}).unwrap();
    let estimate = renderer.estimate_error(&ctx).unwrap().expect("32 frames");
    assert!(estimate.rmse < 0.25, "{estimate:?}");
}

/// The default preset crisp: over the bottom fifth of the image (the
/// checkered ground) dark and bright cells differ widely (10th and 90th
/// percentiles of luminance more than 80 apart, the dark ones below 80),
/// where the old glossy, pale ground was a haze between 152 and 197.
#[test]
fn default_ground_is_crisp_and_contrasting() {
    let Some(ctx) = gpu_or_skip("default_ground_is_crisp_and_contrasting") else {
        return;
    };
    let size = (256, 144);
    let (_, image) = shown(&ctx, "presets/default.ron", size, 16);
    let mut ground: Vec<f32> = image
        .enumerate_pixels()
        .filter(|(_, y, _)| *y >= size.1 * 4 / 5)
        .map(|(_, _, p)| luminance(p))
        .collect();
    let p10 = quantile(&mut ground, 0.1);
    let p90 = quantile(&mut ground, 0.9);
    assert!(p10 < 80.0, "dark cells at {p10}");
    assert!(p90 - p10 > 80.0, "cells from {p10} to {p90}");
}
