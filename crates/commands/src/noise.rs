//! `marbre noise`: evaluates noise at points read from stdin, on the GPU (the
//! real WGSL through the compute harness, in f32) or on the CPU reference
//! (in f64: Perlin's own Java is double precision, and far from the origin
//! f32 has lost the noise's digits).

use anyhow::{Context, Result, bail};
use clap::{Args, ValueEnum};
use glam::DVec3;
use marbre_core::noise::fractal::{FractalShape, fractal_sum_f64, noise_f64};
use marbre_core::noise::{FractalParams, HashKind, NoiseKind, NoiseSettings, Progression};
use marbre_render::gpu::GpuContext;
use marbre_render::gpu::harness::noise::{Evaluate, evaluate_scalar};
use std::io::{BufRead, Write};
use std::path::PathBuf;

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum KindArg {
    Gradient,
    Perlin,
    /// Perlin's noise with the gradients of Massal's tutorial.
    PerlinMassal,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum ProgressionArg {
    Geometric,
    Linear,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum HashArg {
    Pcg,
    PcgTiled,
    Sin,
}

#[derive(Args, Debug)]
pub struct NoiseArgs {
    #[arg(long, value_enum, default_value = "gradient")]
    pub kind: KindArg,
    #[arg(long, value_enum, default_value = "pcg")]
    pub hash: HashArg,
    #[arg(long, default_value_t = 6.0)]
    pub octaves: f32,
    #[arg(long, default_value_t = 1.0)]
    pub frequency: f32,
    #[arg(long, default_value_t = 1.0)]
    pub amplitude: f32,
    #[arg(long, default_value_t = 0.5)]
    pub persistence: f32,
    #[arg(long, default_value_t = 2.0)]
    pub lacunarity: f32,
    /// How the octaves progress: geometric (frequency · lacunarityⁱ,
    /// amplitude · persistenceⁱ) or linear (Massal's harmonics: level k at
    /// frequency · k, weighted amplitude / k).
    #[arg(long, value_enum, default_value = "geometric")]
    pub progression: ProgressionArg,
    /// Print the fractal sum (fBm) instead of one octave of noise.
    #[arg(long, conflicts_with = "turbulence")]
    pub fbm: bool,
    /// Print turbulence (a sum of |noise|) instead of one octave of noise.
    #[arg(long)]
    pub turbulence: bool,
    /// Evaluate with the CPU reference (double precision, 12 decimals)
    /// instead of the shader (single precision, 9 decimals).
    #[arg(long)]
    pub cpu: bool,
    /// Instead of reading points, draw the far-from-the-origin figure (the
    /// sin hash against pcg3d, GPU against CPU) to this PNG.
    #[arg(long, value_name = "PNG")]
    pub stability_figure: Option<PathBuf>,
}

impl NoiseArgs {
    fn settings(&self) -> NoiseSettings {
        NoiseSettings {
            kind: match self.kind {
                KindArg::Gradient => NoiseKind::Gradient,
                KindArg::Perlin => NoiseKind::Perlin,
                KindArg::PerlinMassal => NoiseKind::PerlinMassal,
            },
            hash: match self.hash {
                HashArg::Pcg => HashKind::Pcg,
                HashArg::PcgTiled => HashKind::PcgTiled,
                HashArg::Sin => HashKind::Sin,
            },
            fractal: FractalParams {
                octaves: self.octaves,
                frequency: self.frequency,
                amplitude: self.amplitude,
                persistence: self.persistence,
                lacunarity: self.lacunarity,
                progression: match self.progression {
                    ProgressionArg::Geometric => Progression::Geometric,
                    ProgressionArg::Linear => Progression::Linear,
                },
                ..Default::default()
            },
        }
    }

    fn what(&self) -> Evaluate {
        if self.fbm {
            Evaluate::Fbm
        } else if self.turbulence {
            Evaluate::Turbulence
        } else {
            Evaluate::Noise
        }
    }
}

/// Parses `x,y,z` lines (spaces allowed, blank lines and `#` comments
/// skipped), in double precision.
pub fn parse_points(input: impl BufRead) -> Result<Vec<DVec3>> {
    let mut points = Vec::new();
    for (i, line) in input.lines().enumerate() {
        let line = line.context("reading stdin")?;
        let t = line.trim();
        if t.is_empty() || t.starts_with('#') {
            continue;
        }
        let values: Vec<f64> = t
            .split([',', ' ', '\t'])
            .filter(|s| !s.is_empty())
            .map(str::parse)
            .collect::<Result<_, _>>()
            .with_context(|| format!("line {}: `{t}` is not x,y,z", i + 1))?;
        let [x, y, z] = values[..] else {
            bail!(
                "line {}: expected 3 numbers x,y,z, found {}",
                i + 1,
                values.len()
            );
        };
        if !(x.is_finite() && y.is_finite() && z.is_finite()) {
            bail!("line {}: coordinates must be finite", i + 1);
        }
        points.push(DVec3::new(x, y, z));
    }
    Ok(points)
}

/// The CPU reference for the same request, in double precision.
pub fn evaluate_cpu(settings: &NoiseSettings, what: Evaluate, points: &[DVec3]) -> Vec<f64> {
    points
        .iter()
        .map(|&p| match what {
            Evaluate::Fbm => fractal_sum_f64(p, settings, FractalShape::Signed),
            Evaluate::Turbulence => fractal_sum_f64(p, settings, FractalShape::Absolute),
            _ => noise_f64(p, settings.kind, settings.hash),
        })
        .collect()
}

pub fn run(args: &NoiseArgs) -> Result<()> {
    if let Some(path) = &args.stability_figure {
        return super::noise_figure::write(path);
    }
    let points = parse_points(std::io::stdin().lock())?;
    let settings = args.settings();
    let mut out = std::io::stdout().lock();
    if args.cpu {
        for v in evaluate_cpu(&settings, args.what(), &points) {
            writeln!(out, "{v:.12}")?;
        }
    } else {
        let ctx = GpuContext::headless()?;
        let points: Vec<_> = points.iter().map(|p| p.as_vec3()).collect();
        for v in evaluate_scalar(&ctx, &settings, args.what(), &points)? {
            writeln!(out, "{v:.9}")?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;
    use marbre_core::noise::improved_noise_f32;

    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        args: NoiseArgs,
    }

    /// `marbre noise` with these flags.
    fn args(flags: &[&str]) -> NoiseArgs {
        Cli::parse_from(std::iter::once("noise").chain(flags.iter().copied())).args
    }

    /// Perlin's Java reference points, `x y z value` (80 of them, the last
    /// 16 at |c| up to 1e4), as `marbre noise` reads them: `x,y,z` lines.
    fn reference() -> (Vec<DVec3>, Vec<f64>) {
        let text = include_str!("../../core/tests/data/perlin/reference_points.txt");
        let rows: Vec<Vec<f64>> = text
            .lines()
            .map(|l| l.split(' ').map(|v| v.parse().unwrap()).collect())
            .collect();
        let input: String = rows
            .iter()
            .map(|r| format!("{},{},{}\n", r[0], r[1], r[2]))
            .collect();
        let points = parse_points(input.as_bytes()).unwrap();
        (points, rows.iter().map(|r| r[3]).collect())
    }

    #[test]
    fn the_cpu_reference_matches_perlins_java_far_from_the_origin() {
        let (points, expected) = reference();
        let args = args(&["--kind", "perlin", "--cpu"]);
        let values = evaluate_cpu(&args.settings(), args.what(), &points);
        for ((p, got), want) in points.iter().zip(&values).zip(&expected) {
            assert!(
                (got - want).abs() <= 1e-9,
                "noise({p}) = {got}, Java {want}"
            );
        }
        // Single precision is no reference out there: the same points in
        // f32 miss Perlin's values by far more.
        let worst_f32 = points
            .iter()
            .zip(&expected)
            .filter(|(p, _)| p.abs().max_element() > 1000.0)
            .map(|(p, want)| {
                let p = p.as_vec3();
                (f64::from(improved_noise_f32(p.x, p.y, p.z)) - want).abs()
            })
            .fold(0.0, f64::max);
        assert!(worst_f32 > 1e-4, "f32 is off by only {worst_f32:e}");
    }

    #[test]
    fn fractal_sums_of_one_octave_are_the_noise_itself() {
        let (points, _) = reference();
        let args = args(&["--kind", "perlin", "--cpu", "--octaves", "1"]);
        let noise = evaluate_cpu(&args.settings(), Evaluate::Noise, &points);
        let fbm = evaluate_cpu(&args.settings(), Evaluate::Fbm, &points);
        let turbulence = evaluate_cpu(&args.settings(), Evaluate::Turbulence, &points);
        for ((n, f), t) in noise.iter().zip(&fbm).zip(&turbulence) {
            assert_eq!(n, f);
            assert_eq!(n.abs(), *t);
        }
    }

    /// `--progression linear` with Massal's knobs is his turbulence, as the
    /// panel's recipe (`NoiseSettings::massal`) computes it.
    #[test]
    fn linear_progression_flags_give_massals_turbulence() {
        let args = args(&[
            "--kind",
            "perlin-massal",
            "--progression",
            "linear",
            "--octaves",
            "9",
            "--frequency",
            "0.05",
            "--turbulence",
            "--cpu",
        ]);
        assert_eq!(args.settings(), NoiseSettings::massal(0.05));
        let points = [
            DVec3::new(120.5, 33.25, 7.0),
            DVec3::new(-40.0, 250.0, 99.9),
        ];
        let values = evaluate_cpu(&args.settings(), args.what(), &points);
        for (p, got) in points.iter().zip(values) {
            let his: f64 = (1..10)
                .map(|level| {
                    let f = f64::from(level) * f64::from(0.05_f32);
                    marbre_core::noise::perlin::improved_noise_massal(f * p.x, f * p.y, f * p.z)
                        .abs()
                        / f64::from(level)
                })
                .sum();
            assert!((got - his).abs() < 1e-12, "{p}: {got} vs {his}");
        }
    }
}
