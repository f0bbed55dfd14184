//! The merge of a farm's sample batches (issue 30): renders of disjoint
//! samples of one scene's one long render (`render --sample-offset`),
//! averaged weighted by their samples, as pbrt-v4's `imgtool average` and
//! Cycles' sample subsets do. The spread between the batches estimates the
//! merged image's error, as the Quality strip's does from a render's
//! frames: the merge says how far it probably is from converged.

use crate::render_record::RenderRecord;
use std::path::PathBuf;

/// One input: a file's linear radiance and its render's record.
#[derive(Debug, Clone)]
pub struct Batch {
    pub path: PathBuf,
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<[f32; 4]>,
    pub record: RenderRecord,
}

/// The merged image and its estimated error.
#[derive(Debug, Clone)]
pub struct Merged {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<[f32; 4]>,
    /// The record of the merged render: all the samples, from the first.
    pub record: RenderRecord,
    /// √ of the mean over channels of the merged mean's variance.
    pub rmse: f64,
    /// √relMSE: the same relative to mean² + 0.01, as the Quality strip
    /// and the benchmarks measure it.
    pub relative_error: f64,
}

/// The relMSE's ε (`shaders/error_meter.wgsl`'s `REL_EPSILON`).
const REL_EPSILON: f64 = 0.01;

/// Averages `batches` weighted by their samples. Refused, naming the
/// files: fewer than two, sizes that differ, another scene or frame, and
/// samples counted twice (overlapping sample ranges).
pub fn merge(batches: &[Batch]) -> Result<Merged, String> {
    let [first, rest @ ..] = batches else {
        return Err("a merge needs two files or more (got none)".into());
    };
    if rest.is_empty() {
        return Err(format!(
            "a merge needs two files or more (got only {})",
            first.path.display()
        ));
    }
    let name = |b: &Batch| b.path.display().to_string();
    for b in rest {
        if (b.width, b.height) != (first.width, first.height) {
            return Err(format!(
                "{} is {}×{}, but {} is {}×{}: batches of one render have its size",
                name(b),
                b.width,
                b.height,
                name(first),
                first.width,
                first.height
            ));
        }
        if b.record.scene != first.record.scene {
            return Err(format!(
                "{} is a render of another scene than {} (scene {} and {})",
                name(b),
                name(first),
                b.record.scene,
                first.record.scene
            ));
        }
        if b.record.frame != first.record.frame {
            return Err(format!(
                "{} holds frame {}, but {} frame {}: merge one frame's batches",
                name(b),
                b.record.frame,
                name(first),
                first.record.frame
            ));
        }
    }
    let mut by_samples: Vec<&Batch> = batches.iter().collect();
    by_samples.sort_by_key(|b| b.record.sample_offset);
    for pair in by_samples.windows(2) {
        let (a, b) = (pair[0].record.samples(), pair[1].record.samples());
        if b.start < a.end {
            return Err(format!(
                "{} (samples {}..{}) and {} (samples {}..{}) overlap: those samples would \
                 count twice; render batches at offsets spp apart (--sample-offset)",
                name(pair[0]),
                a.start,
                a.end,
                name(pair[1]),
                b.start,
                b.end
            ));
        }
    }
    let total: u64 = batches.iter().map(|b| u64::from(b.record.spp)).sum();
    let n = total as f64;
    let mut pixels = vec![[0.0f32; 4]; first.pixels.len()];
    let (mut variance_sum, mut relative_sum, mut channels) = (0.0f64, 0.0f64, 0u64);
    for (p, merged) in pixels.iter_mut().enumerate() {
        for (c, out) in merged.iter_mut().enumerate() {
            let mean = batches
                .iter()
                .map(|b| f64::from(b.record.spp) * f64::from(b.pixels[p][c]))
                .sum::<f64>()
                / n;
            *out = mean as f32;
            if c == 3 || !mean.is_finite() {
                continue;
            }
            // Each batch's mean x_i of n_i samples has variance σ²/n_i:
            // Σ n_i (x_i − m)² / (K − 1) estimates σ², and the merged
            // mean's variance is σ² / N.
            let spread: f64 = batches
                .iter()
                .map(|b| f64::from(b.record.spp) * (f64::from(b.pixels[p][c]) - mean).powi(2))
                .sum();
            let variance = spread / ((batches.len() - 1) as f64 * n);
            variance_sum += variance;
            relative_sum += variance / (mean * mean + REL_EPSILON);
            channels += 1;
        }
    }
    let per_channel = |sum: f64| (sum / channels.max(1) as f64).sqrt();
    let mut kernels: Vec<&str> = batches.iter().map(|b| b.record.kernel.as_str()).collect();
    kernels.dedup();
    let mut adapters: Vec<&str> = batches.iter().map(|b| b.record.adapter.as_str()).collect();
    adapters.dedup();
    Ok(Merged {
        width: first.width,
        height: first.height,
        pixels,
        record: RenderRecord {
            spp: total.min(u64::from(u32::MAX)) as u32,
            sample_offset: by_samples[0].record.sample_offset,
            kernel: kernels.join(" + "),
            adapter: adapters.join(" + "),
            ..first.record.clone()
        },
        rmse: per_channel(variance_sum),
        relative_error: per_channel(relative_sum),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn batch(name: &str, offset: u32, spp: u32, value: f32) -> Batch {
        Batch {
            path: PathBuf::from(name),
            width: 2,
            height: 1,
            pixels: vec![[value, value, value, 1.0]; 2],
            record: RenderRecord {
                spp,
                sample_offset: offset,
                frame: 0,
                time: 0.0,
                scene: "0123456789abcdef".into(),
                kernel: "fragment".into(),
                adapter: "llvmpipe".into(),
                version: "0.1.0".into(),
            },
        }
    }

    /// Batches of 1, 1 and 2 samples of values 1, 3 and 2: the mean
    /// weighted by samples is 2; the spread Σ n_i (x_i − 2)² = 2 over
    /// K − 1 = 2 estimates σ² = 1, so the merged variance is 1/4: RMSE
    /// 0.5, relative 0.5 / √(4 + 0.01). The record counts 4 samples from
    /// the first.
    #[test]
    fn batches_average_by_their_samples_with_the_spread_as_error() {
        let merged = merge(&[
            batch("b.exr", 1, 1, 3.0),
            batch("a.exr", 0, 1, 1.0),
            batch("c.exr", 2, 2, 2.0),
        ])
        .unwrap();
        assert_eq!(merged.pixels, vec![[2.0, 2.0, 2.0, 1.0]; 2]);
        assert_eq!((merged.record.spp, merged.record.sample_offset), (4, 0));
        assert!((merged.rmse - 0.5).abs() < 1e-12, "{}", merged.rmse);
        let relative = 0.5 / (4.0f64 + REL_EPSILON).sqrt();
        assert!((merged.relative_error - relative).abs() < 1e-12);
    }

    /// Every refusal names its files and its cause.
    #[test]
    fn bad_merges_are_refused_naming_the_files() {
        let a = batch("a.exr", 0, 4, 1.0);
        let e = merge(std::slice::from_ref(&a)).unwrap_err();
        assert!(e.contains("two files") && e.contains("a.exr"), "{e}");
        let mut wide = batch("wide.exr", 4, 4, 1.0);
        wide.width = 3;
        wide.pixels.push([1.0; 4]);
        let e = merge(&[a.clone(), wide]).unwrap_err();
        assert!(
            e.contains("wide.exr is 3×1") && e.contains("a.exr is 2×1"),
            "{e}"
        );
        let mut other = batch("other.exr", 4, 4, 1.0);
        other.record.scene = "fedcba9876543210".into();
        let e = merge(&[a.clone(), other]).unwrap_err();
        assert!(e.contains("other.exr is a render of another scene"), "{e}");
        let mut later = batch("later.exr", 4, 4, 1.0);
        later.record.frame = 7;
        let e = merge(&[a.clone(), later]).unwrap_err();
        assert!(e.contains("later.exr holds frame 7"), "{e}");
        let overlapping = batch("again.exr", 2, 4, 1.0);
        let e = merge(&[a, overlapping]).unwrap_err();
        assert!(
            e.contains("a.exr (samples 0..4) and again.exr (samples 2..6) overlap"),
            "{e}"
        );
    }
}
