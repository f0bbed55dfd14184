//! The CPU kernel (`marbre_render::cpu_kernel`) against the GPU kernels it
//! is the twin of: it draws the same random numbers in the same order and
//! follows the same path, so its accumulation is the fragment kernel's
//! pixel by pixel, up to the rounding of a different compiler (libm's
//! `sin`, `sqrt` and `normalize` against the driver's); where that
//! rounding sends a path the other way (a hit on a shared edge, a roulette
//! decided on the last bit) the pixel differs by a whole sample, which
//! must stay rare. Then what the renderer builds around it: rounds traced
//! in bands, and the fragment kernel standing in for scenes it does not
//! trace.

use crate::kernels::{
    Image, SIZE, differences, parity_presets, preset, read, trace_in_bands, trace_rounds,
    whole_pass,
};
use marbre_core::scene::EnvSource;
use marbre_render::cpu_kernel::support;
use marbre_render::gpu::Kernel;
use marbre_render::gpu::testing::gpu_or_skip;
use marbre_render::session::{load_scene, renderer_with};

/// Rounding between two compilers of the same arithmetic: a few ulps of
/// a path's radiance, through a handful of bounces.
fn rounding(value: f32) -> f32 {
    1e-4 * (1.0 + value)
}

/// At most this fraction of the pixels may differ beyond rounding: the
/// paths that rounding sent another way.
const DIVERGED: f64 = 0.02;

/// Compares the CPU kernel's accumulation of `loaded` with the fragment
/// kernel's: the same samples and dropped counts, all but a few pixels
/// equal to rounding, and the image's mean within 1 % (a path that went
/// another way is another unbiased sample).
fn assert_twin(what: &str, gpu: &Image, cpu: &Image) {
    assert_eq!(gpu.samples, cpu.samples, "{what}: samples");
    assert_eq!(
        gpu.dropped, cpu.dropped,
        "{what}: non-finite samples dropped"
    );
    let (beyond, _) = differences(&gpu.mean, &cpu.mean, gpu.size.0, rounding);
    let pixels = gpu.mean.len();
    assert!(
        (beyond.len() as f64) <= DIVERGED * pixels as f64,
        "{what}: {} of {pixels} pixels differ beyond rounding (at most {:.0} % may); the worst: {:?}",
        beyond.len(),
        DIVERGED * 100.0,
        &beyond[..beyond.len().min(5)]
    );
    let mean = |image: &Image| {
        image
            .mean
            .iter()
            .map(|p| f64::from(p[0] + p[1] + p[2]))
            .sum::<f64>()
            / pixels as f64
    };
    let (g, c) = (mean(gpu), mean(cpu));
    assert!(
        (g - c).abs() <= 0.01 * g.abs().max(1e-6),
        "{what}: image means {g} (fragment) and {c} (cpu)"
    );
}

/// Every parity preset the CPU kernel traces (the Cornell box, and the
/// hard cases of extreme radiance, scale and geometry among them) gives
/// the fragment kernel's image; there are enough of them that the test
/// means something.
#[test]
fn the_cpu_kernel_traces_the_gpu_kernels_paths() {
    let Some(ctx) = gpu_or_skip("the_cpu_kernel_traces_the_gpu_kernels_paths") else {
        return;
    };
    let mut compared = Vec::new();
    for path in parity_presets() {
        let loaded = load_scene(&path, None).unwrap();
        if support(&loaded.scene).is_err() {
            continue;
        }
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let gpu = whole_pass(&ctx, &loaded, Kernel::Fragment, 3);
        let cpu = whole_pass(&ctx, &loaded, Kernel::Cpu, 3);
        assert_twin(&name, &gpu, &cpu);
        compared.push(name);
    }
    assert!(
        compared.iter().any(|n| n == "cornell.ron") && compared.len() >= 4,
        "the CPU kernel traced too few parity presets: {compared:?}"
    );
}

/// Bands of rows over several calls give the CPU kernel's whole pass bit
/// for bit: each band is traced with its own rows' seeds and folded into
/// its own rows.
#[test]
fn cpu_rounds_traced_in_bands_equal_a_whole_pass() {
    let Some(ctx) = gpu_or_skip("cpu_rounds_traced_in_bands_equal_a_whole_pass") else {
        return;
    };
    let mut loaded = preset("cornell.ron");
    loaded.scene.render.samples_per_frame = 2;
    let mut banded = renderer_with(&ctx, &loaded, SIZE, Kernel::Cpu).unwrap();
    assert_eq!(banded.kernel(), Kernel::Cpu);
    trace_in_bands(&ctx, &mut banded, 3);
    let mut whole = renderer_with(&ctx, &loaded, SIZE, Kernel::Cpu).unwrap();
    trace_rounds(&ctx, &mut whole, 3);
    let (a, b) = (read(&ctx, &banded), read(&ctx, &whole));
    assert_eq!(a.samples, b.samples);
    let exact = |_: f32| 0.0;
    let (mean, _) = differences(&a.mean, &b.mean, a.size.0, exact);
    let (spread, _) = differences(&a.spread, &b.spread, a.size.0, exact);
    assert!(
        mean.is_empty() && spread.is_empty(),
        "{:?} {:?}",
        &mean[..mean.len().min(3)],
        &spread[..spread.len().min(3)]
    );
}

/// A scene the CPU kernel does not trace (the Cornell box under an
/// environment map) is traced by the fragment kernel, and the reason is
/// named; the same renderer goes back to the CPU kernel when the scene
/// becomes one it traces (a constant sky).
#[test]
fn the_fragment_kernel_stands_in_for_scenes_the_cpu_kernel_cannot_trace() {
    let Some(ctx) =
        gpu_or_skip("the_fragment_kernel_stands_in_for_scenes_the_cpu_kernel_cannot_trace")
    else {
        return;
    };
    let mut loaded = preset("cornell.ron");
    let sky = loaded.scene.clone();
    loaded.scene.environment.source = EnvSource::LatLong {
        path: crate::common::root().join("envmaps/esplanade.exr"),
    };
    let why = support(&loaded.scene).unwrap_err();
    assert!(why.contains("environment map"), "{why}");
    let mut r = renderer_with(&ctx, &loaded, SIZE, Kernel::Cpu).unwrap();
    assert_eq!(r.kernel(), Kernel::Fragment);
    assert_eq!(support(&sky), Ok(()));
    r.set_scene(&ctx, &sky).unwrap();
    assert_eq!(r.kernel(), Kernel::Cpu);
    trace_rounds(&ctx, &mut r, 1);
    let image = read(&ctx, &r);
    assert!(
        image
            .mean
            .iter()
            .all(|p| p[..3].iter().all(|v| v.is_finite() && *v >= 0.0))
    );
    assert!(image.mean.iter().any(|p| p[0] > 0.0), "a lit image");
}
