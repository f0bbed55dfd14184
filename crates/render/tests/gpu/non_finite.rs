//! The trace pass's guard against NaN and Inf: a non-finite sample is
//! dropped, counted and shown magenta on request; finite samples near the
//! largest float never overflow into the accumulation. Needs a GPU adapter
//! (skips loudly without one, see `marbre_render::gpu::testing`).

use crate::common;

use crate::common::lambert;
use glam::Vec3;
use marbre_core::scene::{EnvSource, Material, OrbitCamera, Scene, Sphere, Texture};
use marbre_render::gpu::testing::gpu_or_skip;
use marbre_render::gpu::{GpuContext, Kernel, NonFiniteCounts, Renderer};
use marbre_render::session::accumulate;

const SIZE: (u32, u32) = (16, 12);
const SPP_PER_FRAME: u32 = 2;
const FRAMES: u32 = 3;

/// A sphere emitting `strength` × white, filling the whole view (the
/// camera 1.5 radii from its centre sees it over ±41.8°, wider than the
/// ±22.5° field of view), in a black world: every camera ray hits it.
fn emitter_filling_the_view(strength: f32) -> Scene {
    let mut scene = Scene {
        ground: None,
        ..Scene::default()
    };
    scene.spheres.push(Sphere {
        name: "emitter".into(),
        center: Vec3::ZERO,
        radius: 1.0,
        material: Material {
            emission: Texture::color(Vec3::ONE),
            emission_strength: strength,
            ..lambert(0.5)
        },
    });
    scene.environment.source = EnvSource::Constant {
        radiance: Vec3::ZERO,
    };
    scene.camera = OrbitCamera {
        target: Vec3::ZERO,
        distance: 1.5,
        yaw_degrees: 0.0,
        pitch_degrees: 0.0,
        fov_degrees: 45.0,
        ..Default::default()
    };
    scene.render.samples_per_frame = SPP_PER_FRAME;
    scene
}

fn render(
    ctx: &GpuContext,
    scene: &Scene,
    kernel: Kernel,
) -> (Renderer, NonFiniteCounts, Vec<[f32; 4]>) {
    let mut r = Renderer::with_kernel(ctx, scene, None, SIZE, kernel).unwrap();
    accumulate(ctx, &mut r, SPP_PER_FRAME * FRAMES, |_| {}).unwrap();
    let counts = r.count_non_finite(ctx).unwrap();
    let (_, _, pixels) = r.read_radiance(ctx).unwrap();
    for p in &pixels {
        assert!(
            p.iter().all(|c| c.is_finite()),
            "a non-finite value reached the accumulation: {p:?}"
        );
    }
    (r, counts, pixels)
}

const MAGENTA: [u8; 4] = [255, 0, 255, 255];

fn magenta_pixels(ctx: &GpuContext, r: &mut Renderer) -> usize {
    let image = r.read_display(ctx).unwrap();
    image.pixels().filter(|p| p.0 == MAGENTA).count()
}

/// Nothing but a constant environment of `radiance`, seen by every camera
/// ray. (The shading clamps an emission below at zero, which turns a NaN
/// emission into 0, so a broken environment is the simplest NaN source.)
fn world_of_radiance(radiance: f32) -> Scene {
    let mut scene = emitter_filling_the_view(1.0);
    scene.spheres.clear();
    scene.environment.source = EnvSource::Constant {
        radiance: Vec3::splat(radiance),
    };
    scene
}

#[test]
fn nan_samples_are_dropped_and_counted() {
    let Some(ctx) = gpu_or_skip("nan_samples_are_dropped_and_counted") else {
        return;
    };
    for kernel in common::kernels(&ctx) {
        eprintln!("{kernel} kernel");
        let (_, counts, pixels) = render(&ctx, &world_of_radiance(f32::NAN), kernel);
        let all_pixels = SIZE.0 * SIZE.1;
        assert_eq!(
            counts,
            NonFiniteCounts {
                nan: all_pixels * SPP_PER_FRAME * FRAMES,
                infinite: 0,
                pixels: all_pixels,
            }
        );
        // Every sample was dropped: the mean stays at the nothing it started from.
        assert!(pixels.iter().all(|p| p[..3] == [0.0; 3]), "{:?}", pixels[0]);
    }
}

#[test]
fn infinite_samples_are_counted_apart_and_shown_magenta_until_the_image_restarts() {
    let Some(ctx) = gpu_or_skip(
        "infinite_samples_are_counted_apart_and_shown_magenta_until_the_image_restarts",
    ) else {
        return;
    };
    for kernel in common::kernels(&ctx) {
        eprintln!("{kernel} kernel");
        let mut scene = world_of_radiance(f32::INFINITY);
        let (mut r, counts, _) = render(&ctx, &scene, kernel);
        let all_pixels = SIZE.0 * SIZE.1;
        assert_eq!(counts.infinite, all_pixels * SPP_PER_FRAME * FRAMES);
        assert_eq!((counts.nan, counts.pixels), (0, all_pixels));
        assert_eq!(magenta_pixels(&ctx, &mut r), 0, "the debug view is off");
        scene.render.display.show_non_finite = true;
        r.set_scene(&ctx, &scene).unwrap();
        assert_eq!(
            r.accumulated_samples(),
            SPP_PER_FRAME * FRAMES,
            "the debug view is display-only: it keeps the samples"
        );
        assert_eq!(magenta_pixels(&ctx, &mut r), all_pixels as usize);
        // A finite scene restarts the accumulation, and its counters with it.
        let mut finite = world_of_radiance(1.0);
        finite.render.display.show_non_finite = true;
        r.set_scene(&ctx, &finite).unwrap();
        accumulate(&ctx, &mut r, SPP_PER_FRAME, |_| {}).unwrap();
        assert!(r.count_non_finite(&ctx).unwrap().is_zero());
        assert_eq!(magenta_pixels(&ctx, &mut r), 0, "no stale count is painted");
    }
}

/// Samples of 0.75 × f32::MAX: two of them in one frame would sum to
/// infinity. The mean must come out as the emission itself, and the spread
/// finite.
#[test]
fn samples_near_the_largest_float_accumulate_without_overflow() {
    let Some(ctx) = gpu_or_skip("samples_near_the_largest_float_accumulate_without_overflow")
    else {
        return;
    };
    for kernel in common::kernels(&ctx) {
        eprintln!("{kernel} kernel");
        let strength = 0.75 * f32::MAX;
        let (r, counts, pixels) = render(&ctx, &emitter_filling_the_view(strength), kernel);
        assert!(counts.is_zero(), "{counts:?}");
        for p in &pixels {
            for c in &p[..3] {
                // The surface also reflects (albedo 0.5) a black world: the
                // sample is the emission, rounded by the running mean's
                // (x − mean)·w steps: a few ulps.
                assert!(
                    ((c - strength) / strength).abs() < 1e-6,
                    "{c} against {strength}"
                );
            }
        }
        let (_, _, spread) = r.read_spread(&ctx).unwrap();
        assert!(
            spread.iter().all(|s| s.iter().all(|c| c.is_finite())),
            "the spread overflowed: {:?}",
            spread[0]
        );
    }
}
