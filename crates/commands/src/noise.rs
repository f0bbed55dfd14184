//! `marbre noise`: evaluates noise at points read from stdin, on the GPU (the
//! real WGSL through the compute harness) or on the CPU reference.

use anyhow::{Context, Result, bail};
use clap::{Args, ValueEnum};
use glam::Vec3;
use marbre_core::noise::{self, FractalParams, HashKind, NoiseKind, NoiseSettings};
use marbre_render::gpu::GpuContext;
use marbre_render::gpu::harness::noise::{Evaluate, evaluate_scalar};
use std::io::{BufRead, Write};
use std::path::PathBuf;

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum KindArg {
    Gradient,
    Perlin,
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
    /// Print the fractal sum (fBm) instead of one octave of noise.
    #[arg(long, conflicts_with = "turbulence")]
    pub fbm: bool,
    /// Print turbulence (a sum of |noise|) instead of one octave of noise.
    #[arg(long)]
    pub turbulence: bool,
    /// Evaluate with the CPU reference instead of the shader.
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

/// Parses `x,y,z` lines (spaces allowed, blank lines and `#` comments skipped).
pub fn parse_points(input: impl BufRead) -> Result<Vec<Vec3>> {
    let mut points = Vec::new();
    for (i, line) in input.lines().enumerate() {
        let line = line.context("reading stdin")?;
        let t = line.trim();
        if t.is_empty() || t.starts_with('#') {
            continue;
        }
        let values: Vec<f32> = t
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
        points.push(Vec3::new(x, y, z));
    }
    Ok(points)
}

/// The CPU reference for the same request.
pub fn evaluate_cpu(settings: &NoiseSettings, what: Evaluate, points: &[Vec3]) -> Vec<f32> {
    points
        .iter()
        .map(|&p| match what {
            Evaluate::Fbm => noise::fbm(p, settings),
            Evaluate::Turbulence => noise::turbulence(p, settings),
            _ => noise::noise(p, settings.kind, settings.hash),
        })
        .collect()
}

pub fn run(args: &NoiseArgs) -> Result<()> {
    if let Some(path) = &args.stability_figure {
        return super::noise_figure::write(path);
    }
    let points = parse_points(std::io::stdin().lock())?;
    let settings = args.settings();
    let values = if args.cpu {
        evaluate_cpu(&settings, args.what(), &points)
    } else {
        let ctx = GpuContext::headless()?;
        evaluate_scalar(&ctx, &settings, args.what(), &points)?
    };
    let mut out = std::io::stdout().lock();
    for v in values {
        writeln!(out, "{v:.9}")?;
    }
    Ok(())
}
