//! `marbre render --sample-offset` (issue 30): a render of N samples from
//! offset K traces samples [K, K + N) of the one long render, so batches
//! at offsets 0, N, 2N… differ from each other, rerun bit for bit, and
//! average to the render of all their samples; `--spp` traces exactly the
//! samples asked whatever the preset's samples per frame. On the GPU
//! (lavapipe here), with a small lit scene whose estimate is noisy. And
//! `marbre merge`, which averages such batches by their records.

use clap::Parser;
use marbre_commands::merge::{self, MergeArgs};
use marbre_commands::render::{self, RenderArgs};
use marbre_core::image_decode::{IntegerDecode, decode_file};
use marbre_render::gpu::testing::gpu_or_skip;
use std::path::{Path, PathBuf};

#[derive(Parser)]
struct Cli {
    #[command(flatten)]
    args: RenderArgs,
}

#[derive(Parser)]
struct MergeCli {
    #[command(flatten)]
    args: MergeArgs,
}

/// A diffuse ball under a point light and a constant sky, whose every
/// pixel's estimate is noisy, with `spf` samples per frame.
fn ball_preset(spf: u32) -> String {
    let text = include_str!("../../../../tests/data/noisy_ball.ron");
    assert!(text.contains("samples_per_frame: 1,"));
    text.replace(
        "samples_per_frame: 1,",
        &format!("samples_per_frame: {spf},"),
    )
}

pub(crate) fn scratch(name: &str, spf: u32) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("marbre-batch-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("ball.ron"), ball_preset(spf)).unwrap();
    dir
}

/// `marbre render` of the ball at 40×24 with the fragment kernel, `spp`
/// samples from `offset`, to `name` in `dir`; its pixels.
pub(crate) fn render_ball(
    dir: &Path,
    name: &str,
    spp: u32,
    offset: u32,
) -> anyhow::Result<Vec<[f32; 4]>> {
    let (spp, offset) = (spp.to_string(), offset.to_string());
    render_ball_with(dir, name, &["--spp", &spp, "--sample-offset", &offset])
}

/// `marbre render` of the ball at 40×24 with the fragment kernel and
/// `flags`, to `name` in `dir`; its pixels.
pub(crate) fn render_ball_with(
    dir: &Path,
    name: &str,
    flags: &[&str],
) -> anyhow::Result<Vec<[f32; 4]>> {
    render_ball_on(dir, name, "fragment", flags)
}

/// [`render_ball_with`] with the trace kernel named `kernel`.
pub(crate) fn render_ball_on(
    dir: &Path,
    name: &str,
    kernel: &str,
    flags: &[&str],
) -> anyhow::Result<Vec<[f32; 4]>> {
    let output = dir.join(name);
    let preset = dir.join("ball.ron");
    let mut all = vec![
        "render",
        "--preset",
        preset.to_str().unwrap(),
        "-o",
        output.to_str().unwrap(),
        "--size",
        "40x24",
        "--kernel",
        kernel,
    ];
    all.extend_from_slice(flags);
    render::run(&Cli::try_parse_from(all).unwrap().args)?;
    Ok(decode_file(&output, IntegerDecode::Linear).unwrap().pixels)
}

/// `marbre merge` of `inputs` to `output` with `flags`.
pub(crate) fn merge_files(inputs: &[PathBuf], output: &Path, flags: &[&str]) -> anyhow::Result<()> {
    let mut all: Vec<&str> = vec!["merge", "-o", output.to_str().unwrap()];
    all.extend(inputs.iter().map(|p| p.to_str().unwrap()));
    all.extend_from_slice(flags);
    merge::run(&MergeCli::try_parse_from(&all).unwrap().args)
}

/// The largest difference between two images, relative to the second's
/// value (at least 0.01).
pub(crate) fn largest_relative_difference(a: &[[f32; 4]], b: &[[f32; 4]]) -> f32 {
    a.iter()
        .zip(b)
        .flat_map(|(p, q)| (0..3).map(move |c| (p[c] - q[c]).abs() / q[c].abs().max(0.01)))
        .fold(0.0, f32::max)
}

/// Four batches of 4 samples at offsets 0, 4, 8 and 12 differ from each
/// other, the first again is the same bytes, and their mean is the
/// 16-sample render to float rounding; for 1 and 2 samples per frame.
#[test]
fn batches_are_disjoint_and_average_to_the_long_render() {
    if gpu_or_skip("batches_are_disjoint_and_average_to_the_long_render").is_none() {
        return;
    }
    for spf in [1, 2] {
        let dir = scratch("mean", spf);
        let batches: Vec<Vec<[f32; 4]>> = (0..4)
            .map(|i| render_ball(&dir, &format!("b{i}.exr"), 4, 4 * i).unwrap())
            .collect();
        for i in 0..4 {
            for j in i + 1..4 {
                assert!(
                    largest_relative_difference(&batches[i], &batches[j]) > 0.05,
                    "spf {spf}: batches {i} and {j} trace the same samples"
                );
            }
        }
        render_ball(&dir, "b0-again.exr", 4, 0).unwrap();
        assert_eq!(
            std::fs::read(dir.join("b0.exr")).unwrap(),
            std::fs::read(dir.join("b0-again.exr")).unwrap(),
            "spf {spf}: a batch traced again differs"
        );
        let long = render_ball(&dir, "all.exr", 16, 0).unwrap();
        let mean: Vec<[f32; 4]> = (0..long.len())
            .map(|p| {
                let mut m = [0.0; 4];
                for b in &batches {
                    for c in 0..4 {
                        m[c] += b[p][c] / 4.0;
                    }
                }
                m
            })
            .collect();
        let d = largest_relative_difference(&mean, &long);
        assert!(
            d < 1e-4,
            "spf {spf}: the mean of the batches is {d} from the long render"
        );
        let _ = std::fs::remove_dir_all(&dir);
    }
}

/// With 3 samples per frame: an offset that is not a multiple of 3 is
/// refused, naming it, and nothing is written; batches of 3 from 0 and
/// from 3 average to the render of 6; `--spp 5` traces exactly the long
/// render's first five samples (the first round's three and the second
/// round's first two, which weighted 3 : 2 make its image), not six.
#[test]
fn spp_is_exact_whatever_the_samples_per_frame() {
    if gpu_or_skip("spp_is_exact_whatever_the_samples_per_frame").is_none() {
        return;
    }
    let dir = scratch("exact", 3);
    let e = render_ball(&dir, "bad.exr", 3, 4).unwrap_err();
    assert!(
        format!("{e:#}").contains("--sample-offset 4") && format!("{e:#}").contains("(3)"),
        "{e:#}"
    );
    assert!(!dir.join("bad.exr").exists());
    let first = render_ball(&dir, "first3.exr", 3, 0).unwrap();
    let second = render_ball(&dir, "second3.exr", 3, 3).unwrap();
    let six = render_ball(&dir, "six.exr", 6, 0).unwrap();
    let five = render_ball(&dir, "five.exr", 5, 0).unwrap();
    let two_of_second = render_ball(&dir, "second2.exr", 2, 3).unwrap();
    // Five samples: the first round's three and the next round's first two.
    let expected: Vec<[f32; 4]> = (0..six.len())
        .map(|p| std::array::from_fn(|c| (3.0 * first[p][c] + 2.0 * two_of_second[p][c]) / 5.0))
        .collect();
    let d = largest_relative_difference(&five, &expected);
    assert!(d < 1e-4, "5 spp is {d} from the first five samples");
    let halves: Vec<[f32; 4]> = (0..six.len())
        .map(|p| std::array::from_fn(|c| (first[p][c] + second[p][c]) / 2.0))
        .collect();
    let d = largest_relative_difference(&halves, &six);
    assert!(d < 1e-4, "two batches of 3 are {d} from the render of 6");
    assert!(
        largest_relative_difference(&five, &six) > 1e-3,
        "5 spp traced 6"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// The root of the mean squared difference over the colour channels.
pub(crate) fn rmse(a: &[[f32; 4]], b: &[[f32; 4]]) -> f64 {
    let sum: f64 = a
        .iter()
        .zip(b)
        .flat_map(|(p, q)| (0..3).map(move |c| (f64::from(p[c]) - f64::from(q[c])).powi(2)))
        .sum();
    (sum / (3 * a.len()) as f64).sqrt()
}

/// `marbre merge` of four batches of 4: the merged EXR records 16 samples
/// from 0 and is the 16-sample render; against an independent reference
/// (256 samples from 4096) its error is 0.4–0.6× one batch's (1/√4, the
/// reference's own noise included: 0.51), and the error it estimates
/// from the batches' spread is within 0.6–1.5× the error measured.
/// Merging a batch with itself, or into one of the inputs, is refused
/// naming the files, and nothing is written.
#[test]
fn merged_batches_are_the_long_render_with_half_the_error() {
    if gpu_or_skip("merged_batches_are_the_long_render_with_half_the_error").is_none() {
        return;
    }
    let dir = scratch("merge", 1);
    let inputs: Vec<PathBuf> = (0..4u32)
        .map(|i| {
            let name = format!("b{i}.exr");
            render_ball(&dir, &name, 4, 4 * i).unwrap();
            dir.join(name)
        })
        .collect();
    let long = render_ball(&dir, "all.exr", 16, 0).unwrap();
    let reference = render_ball(&dir, "reference.exr", 256, 4096).unwrap();
    let merged_path = dir.join("merged.exr");
    merge_files(&inputs, &merged_path, &[]).unwrap();
    let merged = merge::read_batch(&merged_path).unwrap();
    assert_eq!((merged.record.spp, merged.record.sample_offset), (16, 0));
    let d = largest_relative_difference(&merged.pixels, &long);
    assert!(d < 1e-4, "the merge is {d} from the 16-sample render");
    let batch = decode_file(&inputs[0], IntegerDecode::Linear)
        .unwrap()
        .pixels;
    let ratio = rmse(&merged.pixels, &reference) / rmse(&batch, &reference);
    assert!(
        (0.4..=0.6).contains(&ratio),
        "merged / one batch's error: {ratio}"
    );
    let batches: Vec<_> = inputs
        .iter()
        .map(|p| merge::read_batch(p).unwrap())
        .collect();
    let estimate = marbre_core::merge::merge(&batches)
        .unwrap()
        .error
        .unwrap()
        .rmse;
    let measured = rmse(&merged.pixels, &reference);
    eprintln!(
        "merged / one batch's error: {ratio:.3}; estimated RMSE {estimate:.5}, measured {measured:.5}"
    );
    assert!(
        (0.6..=1.5).contains(&(estimate / measured)),
        "estimated RMSE {estimate}, measured {measured}"
    );

    let twice = dir.join("twice.exr");
    let flags = [
        "merge",
        "-o",
        twice.to_str().unwrap(),
        inputs[0].to_str().unwrap(),
        inputs[0].to_str().unwrap(),
    ];
    let e = merge::run(&MergeCli::try_parse_from(flags).unwrap().args).unwrap_err();
    assert!(format!("{e:#}").contains("overlap"), "{e:#}");
    assert!(!twice.exists());
    let flags = [
        "merge",
        "-o",
        inputs[1].to_str().unwrap(),
        inputs[0].to_str().unwrap(),
        inputs[1].to_str().unwrap(),
    ];
    let before = std::fs::read(&inputs[1]).unwrap();
    let e = merge::run(&MergeCli::try_parse_from(flags).unwrap().args).unwrap_err();
    assert!(
        format!("{e:#}").contains("b1.exr is one of the inputs"),
        "{e:#}"
    );
    assert_eq!(std::fs::read(&inputs[1]).unwrap(), before);
    let _ = std::fs::remove_dir_all(&dir);
}
