//! The denoiser (`gpu::denoise`): the GPU pass against its CPU twin, on
//! degenerate input, on a constant image; the guides the trace pass
//! accumulates, with both kernels; and the shipped presets at 4 spp against
//! a higher-spp reference.

use crate::common::{assert_kernels_agree, kernels, rmse, root};
use marbre_core::scene::{Denoiser as Choice, Scene, View};
use marbre_render::gpu::denoise::{DenoiseImage, DenoiseSettings, Denoiser, denoise_cpu};
use marbre_render::gpu::testing::gpu_or_skip;
use marbre_render::gpu::{GpuContext, Kernel, Renderer};
use marbre_render::session::{LoadedScene, accumulate, load_scene, renderer_with};

/// A deterministic value in [0, 1) for pixel `i` and stream `k`.
fn hash(i: usize, k: u32) -> f32 {
    let x = (i as u32).wrapping_mul(2_654_435_761) ^ k.wrapping_mul(0x9E37_79B9);
    let x = x ^ (x >> 15);
    let x = x.wrapping_mul(0x2C1B_3C6D);
    ((x ^ (x >> 12)) >> 8) as f32 / 16_777_216.0
}

/// Mean, spread, albedo and normal of an image with two albedo regions, a
/// normal crease and noise; where `degenerate`, NaN, ±Inf, negative and
/// huge values in all four, black albedo and zero normals.
fn test_image(size: (u32, u32), degenerate: bool) -> [Vec<[f32; 4]>; 4] {
    let (w, h) = (size.0 as usize, size.1 as usize);
    let bad = [
        f32::NAN,
        f32::INFINITY,
        f32::NEG_INFINITY,
        -3.0,
        1e30,
        f32::MAX,
    ];
    let mut out: [Vec<[f32; 4]>; 4] = Default::default();
    for i in 0..w * h {
        let (x, y) = (i % w, i / w);
        let a = if x < w / 2 { 0.8 } else { 0.2 };
        let n = if y < h / 3 {
            [0.5, 1.0, 0.5, 1.0]
        } else {
            [1.0, 0.5, 0.5, 1.0]
        };
        let level = a * (0.5 + hash(i, 1));
        let mut pixel = [
            [level, level * hash(i, 2), 2.0 * level, 1.0],
            [0.05 * hash(i, 3); 4],
            [a, a, a, 1.0],
            n,
        ];
        if degenerate && i % 5 == 0 {
            let v = bad[(i / 5) % bad.len()];
            pixel[0][(i / 5) % 3] = v;
            pixel[1] = [v; 4];
            pixel[2] = if i % 2 == 0 {
                [0.0; 4]
            } else {
                [v, 0.0, v, 1.0]
            };
            pixel[3] = if i % 3 == 0 {
                [0.0; 4]
            } else {
                [v, v, 0.0, 0.0]
            };
        }
        for (channel, value) in out.iter_mut().zip(pixel) {
            channel.push(value);
        }
    }
    out
}

/// The GPU's and the CPU's filter of `images` after `frames` frames.
fn run_both(
    ctx: &GpuContext,
    size: (u32, u32),
    images: &[Vec<[f32; 4]>; 4],
    frames: u32,
) -> [Vec<[f32; 4]>; 2] {
    let image = DenoiseImage {
        size,
        mean: &images[0],
        spread: &images[1],
        frames,
        albedo: &images[2],
        normal: &images[3],
    };
    let settings = DenoiseSettings::default();
    let gpu = Denoiser::new(&ctx.device)
        .unwrap()
        .denoise(ctx, &image, &settings)
        .unwrap();
    [gpu, denoise_cpu(&image, &settings).unwrap()]
}

/// The GPU pass equals its CPU twin, within the rounding of exp, sqrt and
/// the sums' order (1e-4 relative), with the variance from the spread (4
/// frames) and from the neighbourhood (1 frame), on an ordinary image and
/// on one full of NaN, infinities and degenerate guides; neither makes a
/// NaN or Inf.
#[test]
fn the_gpu_filter_equals_its_cpu_twin_and_stays_finite() {
    let Some(ctx) = gpu_or_skip("the_gpu_filter_equals_its_cpu_twin_and_stays_finite") else {
        return;
    };
    let size = (37, 23);
    for degenerate in [false, true] {
        for frames in [1, 4] {
            let what = format!("degenerate {degenerate}, {frames} frames");
            let [gpu, cpu] = run_both(&ctx, size, &test_image(size, degenerate), frames);
            for (i, (g, c)) in gpu.iter().zip(&cpu).enumerate() {
                for ch in 0..4 {
                    assert!(g[ch].is_finite(), "{what}, pixel {i}: GPU {g:?}");
                    assert!(
                        (g[ch] - c[ch]).abs() <= 1e-4 * c[ch].abs().max(1.0),
                        "{what}, pixel {i}: GPU {g:?}, CPU {c:?}"
                    );
                }
            }
        }
    }
}

/// A constant image stays constant on the GPU (the filter sums differences
/// from the centre, so exactly), whatever the guides.
#[test]
fn the_gpu_filter_keeps_a_constant_image_constant() {
    let Some(ctx) = gpu_or_skip("the_gpu_filter_keeps_a_constant_image_constant") else {
        return;
    };
    let size = (29, 17);
    let [_, spread, albedo, normal] = test_image(size, false);
    let value = [0.37, 5.5, 120.0, 1.0];
    let mean = vec![value; albedo.len()];
    for frames in [1, 4] {
        let [gpu, _] = run_both(
            &ctx,
            size,
            &[mean.clone(), spread.clone(), albedo.clone(), normal.clone()],
            frames,
        );
        for p in gpu {
            for c in 0..3 {
                assert!(
                    (p[c] - value[c]).abs() <= 1e-6 * value[c],
                    "{frames} frames: {p:?}"
                );
            }
        }
    }
}

/// `name`'s preset at one sample a frame, with the à-trous filter's
/// display if `denoise`.
fn preset(name: &str, denoise: bool) -> LoadedScene {
    let path = root().join("presets").join(format!("{name}.ron"));
    let mut loaded = load_scene(&path, None).unwrap_or_else(|e| panic!("{name}: {e:#}"));
    let render = &mut loaded.scene.render;
    render.samples_per_frame = 1;
    render.accumulate = true;
    render.display.denoise = denoise;
    render.display.denoiser = Choice::Atrous;
    loaded
}

fn accumulated(
    ctx: &GpuContext,
    loaded: &LoadedScene,
    size: (u32, u32),
    spp: u32,
    kernel: Kernel,
) -> Renderer {
    let mut renderer = renderer_with(ctx, loaded, size, kernel).unwrap();
    accumulate(ctx, &mut renderer, spp, |_| {}).unwrap();
    renderer
}

/// On the default, Cornell and tiles presets at 4 spp, the filtered image
/// is closer to a 256-spp reference than the raw one, the same
/// accumulation (the guides do not change the radiance); on default and
/// tiles by a fifth at least. (Cornell's error at 4 spp is mostly its
/// visible light's edge pixels, which the filter keeps as they are: the
/// emission in the albedo guide is an edge.) The reference's own noise,
/// 1/64 of the 4-spp variance, adds alike to both.
#[test]
fn denoising_lowers_the_error_of_the_presets_at_4_spp() {
    let Some(ctx) = gpu_or_skip("denoising_lowers_the_error_of_the_presets_at_4_spp") else {
        return;
    };
    let size = (48, 36);
    for name in ["default", "cornell", "tiles"] {
        let (_, _, reference) =
            accumulated(&ctx, &preset(name, false), size, 256, Kernel::Fragment)
                .read_radiance(&ctx)
                .unwrap();
        let mut renderer = accumulated(&ctx, &preset(name, true), size, 4, Kernel::Fragment);
        let (_, _, raw) = renderer.read_radiance(&ctx).unwrap();
        let (_, _, denoised) = renderer.read_denoised(&ctx).unwrap();
        let (before, after) = (rmse(&raw, &reference), rmse(&denoised, &reference));
        eprintln!("{name}: RMSE at 4 spp {before:.4} raw, {after:.4} denoised");
        let gain = if name == "cornell" { 1.0 } else { 0.8 };
        assert!(
            after < gain * before,
            "{name}: {after} denoised vs {before} raw"
        );
    }
}

/// The guides accumulated by the trace pass leave the radiance as it was,
/// and both kernels write them alike: the denoised images agree.
#[test]
fn the_guides_leave_the_radiance_alone_and_both_kernels_write_them() {
    let Some(ctx) = gpu_or_skip("the_guides_leave_the_radiance_alone_and_both_kernels_write_them")
    else {
        return;
    };
    let size = (40, 30);
    let plain = accumulated(&ctx, &preset("cornell", false), size, 3, Kernel::Fragment);
    let (_, _, plain) = plain.read_radiance(&ctx).unwrap();
    let mut denoised = Vec::new();
    for kernel in kernels(&ctx) {
        let mut renderer = accumulated(&ctx, &preset("cornell", true), size, 3, kernel);
        let (_, _, raw) = renderer.read_radiance(&ctx).unwrap();
        assert_kernels_agree(&plain, &raw, &format!("{kernel}: radiance with guides"));
        denoised.push(renderer.read_denoised(&ctx).unwrap().2);
    }
    if let [fragment, compute] = denoised.as_slice() {
        assert_kernels_agree(fragment, compute, "denoised");
    }
}

/// Without `denoise` there is no denoised image to read: an error, no panic.
#[test]
fn reading_a_denoised_image_without_denoise_is_an_error() {
    let Some(ctx) = gpu_or_skip("reading_a_denoised_image_without_denoise_is_an_error") else {
        return;
    };
    let loaded = LoadedScene {
        scene: Scene::default(),
        env: None,
        images: Default::default(),
        notes: Vec::new(),
        substitutes: Vec::new(),
    };
    let mut renderer = accumulated(&ctx, &loaded, (8, 8), 1, Kernel::Fragment);
    let e = renderer.read_denoised(&ctx).unwrap_err();
    assert!(e.to_string().contains("denoise"), "{e}");
}

/// The guides the trace pass accumulates are the albedo and normal views
/// of the same samples (same jitter, so the same first hits), on a preset
/// with textures and no emitter, to the rounding of the two running means.
#[test]
fn the_guides_are_the_albedo_and_normal_views() {
    let Some(ctx) = gpu_or_skip("the_guides_are_the_albedo_and_normal_views") else {
        return;
    };
    let size = (32, 24);
    let renderer = accumulated(&ctx, &preset("tiles", true), size, 4, Kernel::Fragment);
    let [albedo, normal] = renderer.read_guides(&ctx).unwrap().expect("guides");
    for (view, guide) in [(View::Albedo, albedo), (View::Normal, normal)] {
        let mut loaded = preset("tiles", false);
        loaded.scene.render.view = view;
        let (_, _, expected) = accumulated(&ctx, &loaded, size, 4, Kernel::Fragment)
            .read_radiance(&ctx)
            .unwrap();
        for (i, (g, e)) in guide.iter().zip(&expected).enumerate() {
            for c in 0..3 {
                assert!(
                    (g[c] - e[c]).abs() < 1e-5,
                    "{view:?}, pixel {i}: guide {g:?}, view {e:?}"
                );
            }
        }
    }
}

/// The mean absolute difference between horizontally adjacent pixels of an
/// 8-bit image: what noise adds to most.
fn roughness(image: &image::RgbaImage) -> f64 {
    let (w, h) = image.dimensions();
    let mut sum = 0.0;
    for y in 0..h {
        for x in 1..w {
            let (a, b) = (image.get_pixel(x - 1, y), image.get_pixel(x, y));
            sum += (0..3).map(|c| f64::from(a[c].abs_diff(b[c]))).sum::<f64>();
        }
    }
    sum / f64::from(3 * (w - 1) * h)
}

/// What the window and PNG screenshots show (the display pass) is the
/// denoised image when denoise is on: at 4 spp on the tiles preset, far
/// smoother than the raw display of the same accumulation.
#[test]
fn the_display_shows_the_denoised_image() {
    let Some(ctx) = gpu_or_skip("the_display_shows_the_denoised_image") else {
        return;
    };
    let size = (48, 36);
    let raw = accumulated(&ctx, &preset("tiles", false), size, 4, Kernel::Fragment)
        .read_display(&ctx)
        .unwrap();
    let denoised = accumulated(&ctx, &preset("tiles", true), size, 4, Kernel::Fragment)
        .read_display(&ctx)
        .unwrap();
    let (raw, denoised) = (roughness(&raw), roughness(&denoised));
    eprintln!("neighbour difference: {raw:.2} raw, {denoised:.2} denoised");
    assert!(denoised < 0.6 * raw, "{denoised} denoised vs {raw} raw");
}
