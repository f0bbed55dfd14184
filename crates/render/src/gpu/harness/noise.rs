//! Runs the shader's noise and mapping functions in a compute pass, so the
//! real WGSL can be checked against the CPU reference and queried from the
//! command line (`marbre noise`).

use super::points::PointsHarness;
use crate::gpu::context::GpuContext;
use crate::gpu::features::FeatureSet;
use crate::gpu::scene_gpu::NoiseParams;
use crate::gpu::shader_source::Program;
use anyhow::Result;
use bytemuck::{Pod, Zeroable};
use glam::{Vec2, Vec3};
use marbre_core::noise::{FractalShape, NoiseSettings};

/// What the harness evaluates at each point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Evaluate {
    Noise,
    /// The 4D lattice noise at the settings' evolution's w and period (an
    /// evolving `noise` only).
    Noise4,
    Fbm,
    Turbulence,
    Ridged,
    /// The octaves a footprint `width` wide keeps (x only).
    FootprintOctaves {
        width: f32,
    },
    Marble {
        stripe_frequency: f32,
    },
    /// The lat-long mapping of a direction.
    EnvUv,
    /// The environment rotation applied to a direction, in radians.
    RotateY {
        angle: f32,
    },
}

impl Evaluate {
    fn mode_and_param(self) -> (u32, f32) {
        match self {
            Evaluate::Noise => (0, 0.0),
            Evaluate::Fbm => (1, 0.0),
            Evaluate::Turbulence => (2, 0.0),
            Evaluate::Marble { stripe_frequency } => (3, stripe_frequency),
            Evaluate::EnvUv => (4, 0.0),
            Evaluate::RotateY { angle } => (5, angle),
            Evaluate::Ridged => (6, 0.0),
            Evaluate::FootprintOctaves { width } => (7, width),
            Evaluate::Noise4 => (8, 0.0),
        }
    }
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct NoiseHarness {
    noise: NoiseParams,
    mode: u32,
    count: u32,
    param: f32,
    _pad1: f32,
}

/// The noise harness built for one request, for any number of points:
/// `marbre noise` evaluates its input in batches with one pipeline.
pub struct NoiseEvaluator {
    harness: PointsHarness,
    params: NoiseHarness,
}

impl NoiseEvaluator {
    pub fn new(ctx: &GpuContext, noise: &NoiseSettings, what: Evaluate) -> Result<Self> {
        let (mode, param) = what.mode_and_param();
        Ok(Self {
            harness: PointsHarness::new(
                ctx,
                Program::NoiseHarness,
                &FeatureSet::for_noise_harness(noise),
                None,
            )?,
            params: NoiseHarness {
                noise: NoiseParams::new(noise, FractalShape::Signed),
                mode,
                count: 0,
                param,
                _pad1: 0.0,
            },
        })
    }

    /// One vec4 of results at each point (x for scalars, xy for uv, xyz
    /// for directions).
    pub fn evaluate(&self, ctx: &GpuContext, points: &[Vec3]) -> Result<Vec<[f32; 4]>> {
        self.harness.run(ctx, points, 1, |count| {
            let params = NoiseHarness {
                count: count as u32,
                ..self.params
            };
            Ok(bytemuck::bytes_of(&params).to_vec())
        })
    }

    /// The scalar results (the x component).
    pub fn evaluate_scalar(&self, ctx: &GpuContext, points: &[Vec3]) -> Result<Vec<f32>> {
        Ok(self.evaluate(ctx, points)?.iter().map(|r| r[0]).collect())
    }
}

/// Evaluates `what` at every point on the GPU; one vec4 of results each
/// (x for scalars, xy for uv, xyz for directions).
pub fn evaluate(
    ctx: &GpuContext,
    noise: &NoiseSettings,
    what: Evaluate,
    points: &[Vec3],
) -> Result<Vec<[f32; 4]>> {
    NoiseEvaluator::new(ctx, noise, what)?.evaluate(ctx, points)
}

/// Scalar results (the x component).
pub fn evaluate_scalar(
    ctx: &GpuContext,
    noise: &NoiseSettings,
    what: Evaluate,
    points: &[Vec3],
) -> Result<Vec<f32>> {
    NoiseEvaluator::new(ctx, noise, what)?.evaluate_scalar(ctx, points)
}

/// The GPU's lat-long uv for each direction.
pub fn env_uv(ctx: &GpuContext, directions: &[Vec3]) -> Result<Vec<Vec2>> {
    Ok(
        evaluate(ctx, &NoiseSettings::default(), Evaluate::EnvUv, directions)?
            .iter()
            .map(|r| Vec2::new(r[0], r[1]))
            .collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The harness uniform has its WGSL twin's layout, as naga lays it out.
    #[test]
    fn the_uniform_has_its_wgsl_twins_layout() {
        use crate::gpu::twin_layout::{module_of, twin_layout};
        let module = &module_of(
            Program::NoiseHarness,
            &FeatureSet::for_noise_harness(&Default::default()),
            "",
        );
        twin_layout!(module, NoiseHarness, [noise, mode, count, param]);
    }
}
