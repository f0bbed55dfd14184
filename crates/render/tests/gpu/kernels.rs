//! The two trace kernels (`fs_trace`, `cs_trace`: one WGSL body,
//! `trace_pixel`), rounds traced in bands of rows within a pixel budget,
//! the preview of a new accumulation, a kernel switch mid-accumulation and
//! the choice of kernel (`pick_kernel`, `time_kernels`).
//!
//! Every test needs a GPU adapter and skips loudly without one (see
//! `marbre_render::gpu::testing`). Sizes and sample counts are small: the whole
//! file runs in about 30 s on lavapipe on two cores.

use crate::common::{presets_in, root};

use glam::Vec3;
use marbre_core::scene::{EnvSource, Material, OrbitCamera, Scene, Sphere, Texture};
use marbre_render::gpu::kernel::{compute_support, faster, resolve};
use marbre_render::gpu::non_finite::NonFiniteCounts;
use marbre_render::gpu::testing::gpu_or_skip;
use marbre_render::gpu::{GpuContext, Kernel, KernelChoice, Renderer, TraceBudget, TraceWork};
use marbre_render::session::{
    LoadedScene, load_scene, pick_kernel, renderer_with, time_kernels, trace_frame,
};
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

/// The size every test traces at: small, and neither side a multiple of
/// the compute kernel's 16×8 workgroup (the invocations past the edge must
/// do nothing): 60 = 3.75 workgroups, 44 = 5.5.
pub(super) const SIZE: (u32, u32) = (60, 44);

pub(super) fn load(path: &Path) -> LoadedScene {
    load_scene(path, None).unwrap_or_else(|e| panic!("{}: {e:#}", path.display()))
}

pub(super) fn preset(name: &str) -> LoadedScene {
    load(&root().join("presets").join(name))
}

/// A GPU whose adapter runs the compute kernel, or `None` after a loud
/// skip (no adapter, or one without storage textures of the accumulation
/// format: then only the fragment kernel exists and there is nothing to
/// compare).
fn gpu_with_compute(test: &str) -> Option<GpuContext> {
    let ctx = gpu_or_skip(test)?;
    match compute_support(&ctx) {
        Ok(()) => Some(ctx),
        Err(why) => {
            marbre_render::gpu::testing::skip(test, &format!("no compute kernel: {why}"));
            None
        }
    }
}

/// What an accumulation holds, read back: the mean, the spread and the
/// dropped-sample counters.
pub(super) struct Image {
    pub(super) size: (u32, u32),
    pub(super) mean: Vec<[f32; 4]>,
    pub(super) spread: Vec<[f32; 4]>,
    pub(super) dropped: NonFiniteCounts,
    pub(super) samples: u32,
}

pub(super) fn read(ctx: &GpuContext, r: &Renderer) -> Image {
    let (w, h, mean) = r.read_radiance(ctx).unwrap();
    let (sw, sh, spread) = r.read_spread(ctx).unwrap();
    assert_eq!((w, h), (sw, sh));
    Image {
        size: (w, h),
        mean,
        spread,
        dropped: r.count_non_finite(ctx).unwrap(),
        samples: r.accumulated_samples(),
    }
}

/// One `trace_within` call, submitted and waited for.
fn trace_within(ctx: &GpuContext, r: &mut Renderer, pixels: u64) -> TraceWork {
    let mut encoder = ctx.device.create_command_encoder(&Default::default());
    let work = r.trace_within(ctx, &mut encoder, TraceBudget::Pixels(pixels), None);
    ctx.queue.submit([encoder.finish()]);
    ctx.device
        .poll(wgpu::PollType::wait_indefinitely())
        .unwrap();
    work
}

/// `rounds` whole rounds, one `trace` call each.
pub(super) fn trace_rounds(ctx: &GpuContext, r: &mut Renderer, rounds: u32) {
    for _ in 0..rounds {
        trace_frame(ctx, r).unwrap();
    }
}

/// A fresh renderer of `loaded` with `kernel`, `rounds` whole rounds traced.
pub(super) fn whole_pass(
    ctx: &GpuContext,
    loaded: &LoadedScene,
    kernel: Kernel,
    rounds: u32,
) -> Image {
    whole_pass_from_frame(ctx, loaded, kernel, 0, rounds)
}

/// [`whole_pass`], the accumulation started after `frames` frames of an
/// earlier one (then reset). The seed of a sample is its pixel, its index
/// in the accumulation and the renderer's frame index, which counts every
/// round and preview ever traced and goes on across resets: an
/// accumulation started later draws other (equally good) samples. So a
/// reference for an accumulation that began after `frames` frames must
/// begin there too.
fn whole_pass_from_frame(
    ctx: &GpuContext,
    loaded: &LoadedScene,
    kernel: Kernel,
    frames: u32,
    rounds: u32,
) -> Image {
    let mut r = renderer_with(ctx, loaded, SIZE, kernel).unwrap();
    assert_eq!(r.kernel(), kernel);
    if frames > 0 {
        trace_rounds(ctx, &mut r, frames);
        r.reset_accumulation();
        assert_eq!(r.accumulated_samples(), 0);
    }
    trace_rounds(ctx, &mut r, rounds);
    read(ctx, &r)
}

/// Whether `a` and `b` agree to within `tolerance(value)`: NaNs and
/// infinities must match exactly (there should be none, but a kernel that
/// made one where the other did not must not pass).
fn close(a: f32, b: f32, tolerance: impl Fn(f32) -> f32) -> bool {
    if a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan()) {
        return true;
    }
    if !(a.is_finite() && b.is_finite()) {
        return false;
    }
    (a - b).abs() <= tolerance(a.abs().max(b.abs()))
}

/// A pixel that differs: x, y, and its value in each image.
pub(super) type Difference = (u32, u32, [f32; 4], [f32; 4]);

/// The pixels of `a` and `b` (of `width` columns) that differ beyond
/// `tolerance`, as (x, y, a, b), worst first, and how many differ at all
/// (bit for bit).
pub(super) fn differences(
    a: &[[f32; 4]],
    b: &[[f32; 4]],
    width: u32,
    tolerance: impl Fn(f32) -> f32 + Copy,
) -> (Vec<Difference>, usize) {
    assert_eq!(a.len(), b.len());
    let mut beyond = Vec::new();
    let mut inexact = 0;
    for (i, (pa, pb)) in a.iter().zip(b).enumerate() {
        if pa.iter().zip(pb).any(|(x, y)| x.to_bits() != y.to_bits()) {
            inexact += 1;
        }
        if !pa.iter().zip(pb).all(|(&x, &y)| close(x, y, tolerance)) {
            let i = i as u32;
            beyond.push((i % width, i / width, *pa, *pb));
        }
    }
    let excess = |(_, _, pa, pb): &Difference| {
        pa.iter()
            .zip(pb)
            .map(|(x, y)| {
                let d = (x - y).abs() / tolerance(x.abs().max(y.abs()));
                if d.is_nan() { f32::INFINITY } else { d }
            })
            .fold(0.0, f32::max)
    };
    beyond.sort_by(|p, q| excess(q).total_cmp(&excess(p)));
    (beyond, inexact)
}

/// The tolerance of the kernel parity: float rounding only. Both kernels
/// run the same WGSL function on the same inputs (the same seeds, the same
/// accumulated texels), so only the compiler's codegen of the two entry
/// points can differ (e.g. FMA contraction): a few ulps of the value. On
/// lavapipe (Mesa 22.3) the two kernels are in fact bit-identical on every
/// preset compared; the tolerance is for drivers that contract differently
/// in fragment and compute code. A difference in a path's branch (a hit
/// missed, a roulette decided the other way) is far beyond it, and is a
/// bug.
fn rounding(value: f32) -> f32 {
    1e-5 * (1.0 + value)
}

/// Asserts that `a` and `b` hold the same accumulation to within
/// `tolerance`, naming the worst pixels on failure; returns how many
/// pixels differ at all.
fn assert_same_image(
    what: &str,
    a: &Image,
    b: &Image,
    tolerance: impl Fn(f32) -> f32 + Copy,
) -> usize {
    assert_eq!(a.size, b.size, "{what}: sizes");
    assert_eq!(a.samples, b.samples, "{what}: samples per pixel");
    assert_eq!(a.dropped, b.dropped, "{what}: non-finite samples dropped");
    let mut inexact_total = 0;
    for (name, pa, pb) in [("mean", &a.mean, &b.mean), ("spread", &a.spread, &b.spread)] {
        let (beyond, inexact) = differences(pa, pb, a.size.0, tolerance);
        assert!(
            beyond.is_empty(),
            "{what}: {} of {} pixels of the {name} differ beyond rounding; the worst: {:?}",
            beyond.len(),
            pa.len(),
            &beyond[..beyond.len().min(5)]
        );
        inexact_total += inexact;
    }
    inexact_total
}

/// The presets the kernel parity covers: the shipped ones that exercise the
/// most distinct shader features (procedural and image textures, alpha
/// cutouts, an enclosed Cornell box with many bounces) and every hard case
/// (extreme scales, radiances and noise parameters, degenerate meshes,
/// environment importance sampling, MIS).
pub(super) fn parity_presets() -> Vec<PathBuf> {
    let mut out: Vec<PathBuf> = [
        "default.ron",
        "cornell.ron",
        "tiles.ron",
        "cutouts.ron",
        "images.ron",
    ]
    .iter()
    .map(|name| root().join("presets").join(name))
    .collect();
    let hard = presets_in("presets/hard-cases");
    assert!(hard.len() >= 10, "hard cases: {hard:?}");
    out.extend(hard);
    out
}

/// The compute and the fragment kernel trace the same image: the same
/// sample sequence per pixel (the seed is the pixel, the sample index and
/// the frame index, never the invocation), the same running mean, spread
/// and dropped-sample counts, equal up to float rounding. A systematic
/// difference (a pixel offset, a band or workgroup edge traced twice or
/// not at all, an output written to the wrong target, a uniform read from
/// the wrong slot) shows as a difference far beyond it.
#[test]
fn compute_and_fragment_kernels_trace_the_same_image() {
    let Some(ctx) = gpu_with_compute("compute_and_fragment_kernels_trace_the_same_image") else {
        return;
    };
    let mut report = Vec::new();
    for path in parity_presets() {
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let loaded = load(&path);
        // Two rounds: the second reads what the first wrote (the mean, the
        // spread and the compensation), through the texture binding for
        // both kernels but written as attachments by one and as storage
        // textures by the other.
        let fragment = whole_pass(&ctx, &loaded, Kernel::Fragment, 2);
        let compute = whole_pass(&ctx, &loaded, Kernel::Compute, 2);
        assert_eq!(fragment.size, SIZE, "{name}");
        assert!(fragment.samples >= 2, "{name}: {} spp", fragment.samples);
        let inexact = assert_same_image(&name, &fragment, &compute, rounding);
        // Not black: an image of zeros would compare equal for any bug.
        let lit = fragment
            .mean
            .iter()
            .filter(|p| p[..3].iter().any(|&c| c > 0.0))
            .count();
        report.push(format!(
            "{name}: {inexact} of {} texels not bit-identical, {lit} pixels lit, dropped {:?}",
            2 * fragment.mean.len(),
            fragment.dropped
        ));
        assert!(lit > 0, "{name}: the image is black");
    }
    eprintln!("{}", report.join("\n"));
}

/// A sphere emitting an infinite radiance over the middle of the view, a
/// diffuse one beside it and a grey world: the pixels that see the emitter,
/// directly, by a bounce or only with some of their jittered samples, drop
/// infinite samples; the others are finite.
fn infinite_emitter() -> LoadedScene {
    let mut scene = Scene::default();
    let lambert = |albedo: f32| Material {
        diffuse: Texture::color(Vec3::splat(albedo)),
        specular: Texture::color(Vec3::ZERO),
        roughness: Texture::scalar(1.0),
        mirror: Texture::scalar(0.0),
        ..Material::default()
    };
    scene.spheres.push(Sphere {
        name: "infinite emitter".into(),
        center: Vec3::ZERO,
        radius: 0.7,
        material: Material {
            emission: Texture::color(Vec3::ONE),
            emission_strength: f32::INFINITY,
            ..lambert(0.5)
        },
    });
    scene.spheres.push(Sphere {
        name: "diffuse".into(),
        center: Vec3::new(1.6, 0.0, 0.0),
        radius: 0.7,
        material: lambert(0.8),
    });
    scene.environment.source = EnvSource::Constant {
        radiance: Vec3::splat(0.5),
    };
    scene.camera = OrbitCamera {
        target: Vec3::ZERO,
        distance: 5.0,
        yaw_degrees: 0.0,
        pitch_degrees: 0.0,
        fov_degrees: 50.0,
        ..Default::default()
    };
    scene.render.samples_per_frame = 2;
    // Unsanitised: `prepare_scene` would clamp the infinite strength.
    LoadedScene {
        scene,
        env: None,
        images: marbre_core::texture::ImageSet::empty(),
        notes: Vec::new(),
        substitutes: Vec::new(),
    }
}

/// The kernels drop and count the same non-finite samples: the counters
/// (NaN, infinite, pixels) and the spread's alpha (each pixel's dropped
/// samples) agree, and so does every finite pixel. The presets drop none,
/// so this scene makes some.
#[test]
fn both_kernels_drop_and_count_the_same_non_finite_samples() {
    let Some(ctx) = gpu_with_compute("both_kernels_drop_and_count_the_same_non_finite_samples")
    else {
        return;
    };
    let loaded = infinite_emitter();
    let fragment = whole_pass(&ctx, &loaded, Kernel::Fragment, 2);
    let compute = whole_pass(&ctx, &loaded, Kernel::Compute, 2);
    let dropped = fragment.dropped;
    let pixels = fragment.mean.len() as u32;
    assert!(dropped.infinite + dropped.nan > 0, "{dropped:?}");
    assert!(
        dropped.pixels > 0 && dropped.pixels < pixels,
        "{dropped:?} of {pixels} pixels"
    );
    let partial = fragment
        .spread
        .iter()
        .filter(|p| p[3] > 0.0 && p[3] < 4.0)
        .count();
    eprintln!("dropped {dropped:?}, {partial} pixels dropped some of their 4 samples");
    assert_same_image("an infinite emitter", &fragment, &compute, rounding);
}

/// The budgets a banded accumulation is traced with: a first call that
/// traces a whole round and a few rows more (a first round that fits in
/// the budget has no preview), then bands of a row, of a few rows, of
/// rows that end past the round (the call completes it and starts the
/// next), and a call over several rounds.
fn banded_budgets((w, h): (u32, u32)) -> Vec<u64> {
    let (w, h) = (u64::from(w), u64::from(h));
    vec![
        w * h + 5 * w,
        1,
        3 * w,
        7 * w + w / 2,
        w * h / 2,
        w,
        2 * w * h + 3 * w,
        3 * w * h,
    ]
}

/// Banded calls on `r` until `rounds` rounds are complete; the rows each
/// call traced are checked against the budget.
pub(super) fn trace_in_bands(ctx: &GpuContext, r: &mut Renderer, rounds: u32) {
    let (w, h) = r.render_size();
    let spf = r.scene().render.samples_per_frame.max(1);
    let mut budgets = banded_budgets((w, h)).into_iter().cycle();
    let mut done = 0;
    while done < rounds {
        let budget = budgets.next().unwrap();
        let work = trace_within(ctx, r, budget);
        assert!(work.pixels >= u64::from(w), "{work:?} for {budget}");
        assert!(
            work.pixels <= budget.max(u64::from(w)),
            "{work:?} for {budget}"
        );
        assert_eq!(work.pixels % u64::from(w), 0, "whole rows: {work:?}");
        done += work.rounds;
        assert_eq!(r.accumulated_samples(), done * spf);
        // No preview: the last complete round is on show.
        assert_eq!(r.shown_size(), (w, h));
    }
}

/// A round traced in bands of rows over several calls (both kernels, on
/// scenes with one and with two samples per frame) gives the image a
/// whole pass gives after the same number of rounds: every band of a
/// round reads the previous round's state and writes its own rows, each
/// pass reads its own frame-uniform slot, and no row is traced twice or
/// skipped. Bit for bit: the same kernel traces the same samples either
/// way.
#[test]
fn a_round_traced_in_bands_equals_a_whole_pass() {
    let Some(ctx) = gpu_with_compute("a_round_traced_in_bands_equals_a_whole_pass") else {
        return;
    };
    let mut two_per_frame = preset("cornell.ron");
    two_per_frame.scene.render.samples_per_frame = 2;
    for (name, loaded) in [
        ("default.ron", preset("default.ron")),
        ("cornell.ron, 2 spp per frame", two_per_frame),
    ] {
        for kernel in Kernel::GPU {
            let what = format!("{name}, {kernel}");
            let mut banded = renderer_with(&ctx, &loaded, SIZE, kernel).unwrap();
            trace_in_bands(&ctx, &mut banded, 5);
            let rounds = banded.accumulated_samples() / loaded.scene.render.samples_per_frame;
            // The last call may have left a round under way: the image is
            // the last complete round's.
            let banded = read(&ctx, &banded);
            let whole = whole_pass(&ctx, &loaded, kernel, rounds);
            let inexact = assert_same_image(&what, &banded, &whole, |_| 0.0);
            assert_eq!(inexact, 0, "{what}");
        }
    }
}

/// With accumulation off, every round starts anew, also the second and
/// third of one call whose budget covers three: the image holds one
/// round's samples, those of a whole pass at the same frame index.
#[test]
fn without_accumulation_each_round_of_a_call_starts_anew() {
    let Some(ctx) = gpu_with_compute("without_accumulation_each_round_of_a_call_starts_anew")
    else {
        return;
    };
    let mut loaded = preset("default.ron");
    loaded.scene.render.accumulate = false;
    let spp = loaded.scene.render.samples_per_frame;
    let round = u64::from(SIZE.0) * u64::from(SIZE.1);
    for kernel in Kernel::GPU {
        let mut r = renderer_with(&ctx, &loaded, SIZE, kernel).unwrap();
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        let work = r.trace_within(&ctx, &mut encoder, TraceBudget::Pixels(3 * round), None);
        ctx.queue.submit([encoder.finish()]);
        ctx.device
            .poll(wgpu::PollType::wait_indefinitely())
            .unwrap();
        assert_eq!(work.rounds, 3, "{kernel}");
        assert_eq!(
            r.accumulated_samples(),
            spp,
            "{kernel}: one round's samples"
        );
        let last = read(&ctx, &r);
        let whole = whole_pass_from_frame(&ctx, &loaded, kernel, 2, 1);
        let inexact =
            assert_same_image(&format!("{kernel}, no accumulation"), &last, &whole, |_| {
                0.0
            });
        assert_eq!(inexact, 0, "{kernel}");
    }
}

/// A fresh accumulation whose first round does not fit in the budget
/// shows a preview first: after the first call the image on show is
/// smaller than the render size, finite, lit, and counts no samples. The
/// rounds that follow replace it with the full-size image, equal (on both
/// kernels) to a whole-pass accumulation of the same rounds.
#[test]
fn a_preview_shows_first_and_the_full_image_follows() {
    let Some(ctx) = gpu_with_compute("a_preview_shows_first_and_the_full_image_follows") else {
        return;
    };
    let loaded = preset("default.ron");
    let full = SIZE;
    let round = u64::from(full.0) * u64::from(full.1);
    for kernel in Kernel::GPU {
        let mut r = renderer_with(&ctx, &loaded, full, kernel).unwrap();
        assert_eq!(r.render_size(), full);
        let work = trace_within(&ctx, &mut r, round / 4);
        assert_eq!(work.rounds, 0, "{kernel}");
        assert_eq!(
            r.accumulated_samples(),
            0,
            "{kernel}: a preview is not samples"
        );
        let shown = r.shown_size();
        assert!(
            shown.0 < full.0 && shown.1 < full.1 && shown.0 > 0 && shown.1 > 0,
            "{kernel}: preview {shown:?} of {full:?}"
        );
        // The budget covers the preview and at least a row of the round.
        assert!(work.pixels > u64::from(shown.0) * u64::from(shown.1));
        let preview = read(&ctx, &r);
        assert_eq!(preview.size, shown, "{kernel}: the preview is what is read");
        assert!(preview.dropped.is_zero(), "{kernel}: {:?}", preview.dropped);
        assert!(
            preview.mean.iter().all(|p| p.iter().all(|c| c.is_finite())),
            "{kernel}: non-finite preview"
        );
        assert!(
            preview.mean.iter().any(|p| p[..3].iter().any(|&c| c > 0.0)),
            "{kernel}: black preview"
        );
        // The round goes on in bands, the preview on show until it is done.
        let mut rounds = 0;
        while rounds < 3 {
            let work = trace_within(&ctx, &mut r, round / 4);
            rounds += work.rounds;
            let expected = if rounds == 0 { shown } else { full };
            assert_eq!(r.shown_size(), expected, "{kernel}");
        }
        assert_eq!(
            rounds, 3,
            "{kernel}: a quarter-round budget completes one at a time"
        );
        let banded = read(&ctx, &r);
        // The preview draws the first round's samples at its own size and
        // leaves the seed alone: the rounds after it are those of a fresh
        // renderer's whole passes.
        let whole = whole_pass_from_frame(&ctx, &loaded, kernel, 0, rounds);
        let inexact = assert_same_image(
            &format!("{kernel}, after a preview"),
            &banded,
            &whole,
            |_| 0.0,
        );
        assert_eq!(inexact, 0, "{kernel}");
    }
}

/// With a budget of a 64th of a round, a fresh accumulation refines: an
/// eighth-scale preview after the first call, then a quarter, then a half
/// (each traced in bands and shown when whole, never samples), then the
/// full image, which equals a whole-pass accumulation of the same rounds
/// (the previews leave the seeds alone) on both kernels.
#[test]
fn previews_refine_in_steps_before_the_first_round() {
    let Some(ctx) = gpu_with_compute("previews_refine_in_steps_before_the_first_round") else {
        return;
    };
    let loaded = preset("default.ron");
    let full = SIZE;
    let round = u64::from(full.0) * u64::from(full.1);
    for kernel in Kernel::GPU {
        let mut r = renderer_with(&ctx, &loaded, full, kernel).unwrap();
        let mut shown = vec![];
        let mut rounds = 0;
        for _ in 0..400 {
            rounds += trace_within(&ctx, &mut r, round / 64).rounds;
            if rounds > 0 {
                break;
            }
            assert_eq!(
                r.accumulated_samples(),
                0,
                "{kernel}: a preview is not samples"
            );
            let size = r.shown_size();
            if shown.last() != Some(&size) {
                let preview = read(&ctx, &r);
                assert_eq!(preview.size, size, "{kernel}");
                assert!(
                    preview.mean.iter().all(|p| p.iter().all(|c| c.is_finite())),
                    "{kernel}: non-finite preview at {size:?}"
                );
                assert!(
                    preview.mean.iter().any(|p| p[..3].iter().any(|&c| c > 0.0)),
                    "{kernel}: black preview at {size:?}"
                );
                shown.push(size);
            }
        }
        assert_eq!(shown, [(8, 6), (15, 11), (30, 22)], "{kernel}");
        assert_eq!(r.shown_size(), full, "{kernel}");
        while rounds < 2 {
            rounds += trace_within(&ctx, &mut r, round / 64).rounds;
        }
        let banded = read(&ctx, &r);
        let whole = whole_pass_from_frame(&ctx, &loaded, kernel, 0, rounds);
        let inexact = assert_same_image(
            &format!("{kernel}, after the previews"),
            &banded,
            &whole,
            |_| 0.0,
        );
        assert_eq!(inexact, 0, "{kernel}");
    }
}

/// A whole round asked for while a preview is being traced in bands (F12's
/// `complete_first_round` after an edit on a slow adapter) traces every
/// row of the full image: the preview's next row is a row of the preview,
/// not of the round. Before, the round began at that row, and the rows
/// above it kept, right of the preview's width, what the targets held from
/// before the edit: the old image, for as long as the accumulation ran.
/// Deterministic: two whole rounds fill both sets, a reset, then calls of
/// a 64th of a round until the second preview is under way (8 × 6 whole,
/// then 15 × 11 two rows a call), then the whole round.
#[test]
fn a_whole_round_during_a_preview_traces_every_row() {
    let Some(ctx) = gpu_with_compute("a_whole_round_during_a_preview_traces_every_row") else {
        return;
    };
    let loaded = preset("default.ron");
    let full = SIZE;
    let round = u64::from(full.0) * u64::from(full.1);
    for kernel in Kernel::GPU {
        let mut r = renderer_with(&ctx, &loaded, full, kernel).unwrap();
        trace_rounds(&ctx, &mut r, 2);
        r.reset_accumulation();
        for _ in 0..2 {
            assert_eq!(trace_within(&ctx, &mut r, round / 64).rounds, 0, "{kernel}");
        }
        assert_eq!(r.accumulated_frames(), 0, "{kernel}");
        assert_eq!(r.shown_size(), (8, 6), "{kernel}: the first preview");
        assert!(
            r.round_progress() > 0.0,
            "{kernel}: the second preview is under way"
        );
        r.complete_first_round(&ctx).unwrap();
        assert_eq!(r.accumulated_frames(), 1, "{kernel}");
        assert_eq!(r.shown_size(), full, "{kernel}");
        let completed = read(&ctx, &r);
        // The previews leave the seeds alone: the round is the one a
        // renderer traces after two rounds and a reset.
        let whole = whole_pass_from_frame(&ctx, &loaded, kernel, 2, 1);
        let inexact = assert_same_image(
            &format!("{kernel}, a whole round during a preview"),
            &completed,
            &whole,
            |_| 0.0,
        );
        assert_eq!(inexact, 0, "{kernel}");
    }
}

/// Switching the kernel mid-accumulation (mid-round, even) keeps the
/// rounds traced, as the viewer's auto kernel choice lands a few seconds
/// after the first image (which it must not throw away), and traces the
/// round under way again whole with the new kernel. Two rounds, half a
/// round, the switch and two more rounds are four rounds: the image
/// equals four rounds of either kernel alone (kernel parity).
#[test]
fn a_kernel_switch_keeps_the_rounds_traced() {
    let Some(ctx) = gpu_with_compute("a_kernel_switch_keeps_the_rounds_traced") else {
        return;
    };
    let loaded = preset("cornell.ron");
    let (w, h) = SIZE;
    for (from, to) in [
        (Kernel::Fragment, Kernel::Compute),
        (Kernel::Compute, Kernel::Fragment),
    ] {
        let what = format!("{from} -> {to}");
        let mut r = renderer_with(&ctx, &loaded, SIZE, from).unwrap();
        trace_rounds(&ctx, &mut r, 2);
        // Half a round more: the switch comes mid-round.
        let work = trace_within(&ctx, &mut r, u64::from(w) * u64::from(h / 2));
        assert_eq!(work.rounds, 0, "{what}");
        assert!(r.round_progress() > 0.0, "{what}");
        let generation = r.accumulation_generation();
        r.set_kernel(&ctx, to).unwrap();
        assert_eq!(r.kernel(), to, "{what}");
        assert_eq!(
            r.accumulated_samples(),
            2,
            "{what}: the rounds traced are kept"
        );
        assert_eq!(r.accumulation_generation(), generation, "{what}: restarted");
        assert_eq!(
            r.round_progress(),
            0.0,
            "{what}: the round under way starts again"
        );
        trace_rounds(&ctx, &mut r, 2);
        let switched = read(&ctx, &r);
        assert_eq!(switched.samples, 4, "{what}");
        for kernel in [from, to] {
            let alone = whole_pass_from_frame(&ctx, &loaded, kernel, 0, 4);
            assert_same_image(
                &format!("{what} vs four rounds of {kernel}"),
                &switched,
                &alone,
                rounding,
            );
        }
    }
}

/// `pick_kernel` honours a named kernel without timing anything, resolves
/// `compute` to the compute kernel where the adapter runs it (lavapipe
/// does), and for `auto` keeps the faster of the two as timed; the
/// timings are finite and positive, at the size asked (clamped to the
/// timing size), and `faster` names the one with the smaller median.
#[test]
fn pick_kernel_honours_the_choice_and_auto_keeps_the_faster() {
    let Some(ctx) = gpu_or_skip("pick_kernel_honours_the_choice_and_auto_keeps_the_faster") else {
        return;
    };
    let loaded = preset("default.ron");
    let size = (32, 24);
    let (kernel, timings) = pick_kernel(&ctx, &loaded, size, KernelChoice::Fragment).unwrap();
    assert_eq!((kernel, timings), (Kernel::Fragment, None));
    assert_eq!(
        resolve(&ctx, KernelChoice::Fragment).unwrap(),
        Kernel::Fragment
    );
    let compute = pick_kernel(&ctx, &loaded, size, KernelChoice::Compute);
    if let Err(why) = compute_support(&ctx) {
        assert!(compute.is_err(), "compute picked where {why}");
        let (kernel, timings) = pick_kernel(&ctx, &loaded, size, KernelChoice::Auto).unwrap();
        assert_eq!((kernel, timings), (Kernel::Fragment, None));
        marbre_render::gpu::testing::skip(
            "pick_kernel_honours_the_choice_and_auto_keeps_the_faster",
            &format!("the timing half: no compute kernel: {why}"),
        );
        return;
    }
    assert_eq!(compute.unwrap(), (Kernel::Compute, None));
    assert_eq!(
        resolve(&ctx, KernelChoice::Compute).unwrap(),
        Kernel::Compute
    );
    assert_eq!(resolve(&ctx, KernelChoice::Auto).unwrap(), Kernel::Compute);

    let t = time_kernels(&ctx, &loaded, size, &AtomicBool::new(false)).unwrap();
    assert_eq!(t.size, size);
    let compute_ms = t.compute_ms.expect("the compute kernel runs here");
    for ms in [t.fragment_ms, compute_ms] {
        assert!(ms.is_finite() && ms > 0.0, "{t}");
    }
    // Compute only when clearly faster: a near tie keeps fragment.
    let smaller = if compute_ms < t.fragment_ms * marbre_render::gpu::kernel::COMPUTE_MARGIN {
        Kernel::Compute
    } else {
        Kernel::Fragment
    };
    assert_eq!(faster(t.fragment_ms, compute_ms), smaller, "{t}");

    let (kernel, timings) = pick_kernel(&ctx, &loaded, size, KernelChoice::Auto).unwrap();
    let timings = timings.expect("auto times the kernels where both run");
    assert_eq!(kernel, timings.faster(), "{timings}");
    assert_eq!(timings.size, size);

    // A size beyond the timing size is clamped to it (and a zero side to
    // one): a slow adapter is never timed at a window's full size.
    let t = time_kernels(&ctx, &loaded, (0, 100_000), &AtomicBool::new(false)).unwrap();
    assert_eq!(t.size.0, 1, "{t}");
    assert!(t.size.1 < 100_000 && t.size.1 > 1, "{t}");

    // A cancelled timing (the viewer closing) stops after its first step
    // with an error, never with a verdict.
    let cancelled = time_kernels(&ctx, &loaded, size, &AtomicBool::new(true));
    assert!(
        cancelled
            .as_ref()
            .is_err_and(|e| e.to_string().contains("cancelled")),
        "{:?}",
        cancelled.map(|t| t.to_string())
    );
}
