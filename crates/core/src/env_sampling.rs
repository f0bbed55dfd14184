//! Importance sampling of a lat-long environment map: directions drawn in
//! proportion to luminance × sin θ (the solid angle a row of texels spans),
//! by a marginal CDF over rows and a conditional CDF over each row's
//! columns (pbrt's `Distribution2D`). The GPU holds the same CDFs and
//! samples them the same way (crates/core/src/env_sampling.wgsl).
//!
//! Coordinates are the image's texel uv `t` (row 0 at the top, as in
//! [`crate::envmap::uv_to_texel_uv`]): the lab's (u, v) = (t.x, 1 − t.y).
//! A density `p(t)` over [0, 1]² becomes a solid-angle density
//! `p / (2π² sin θ)`, where sin θ = sin(π t.y); at the poles (sin θ = 0)
//! the pdf is 0 and the sample is discarded.
//!
//! The renderer looks the map up bilinearly, so a sun's radiance bleeds
//! into the texels around it. A cell's weight is therefore the largest
//! luminance in its 3×3 neighbourhood (pbrt-v4 likewise builds its
//! distribution from the filtered image): where the lookup can be bright,
//! the pdf is too, and radiance / pdf stays bounded (without it, 16 samples
//! per pixel on `sky.exr` had 5× the error of cosine sampling). The
//! distribution is built at most [`EnvDistribution::MAX_WIDTH`] cells wide
//! (box-averaged from the map) so the GPU's binary searches stay short.

use crate::envmap::{EnvImage, direction_to_uv, rotate_y, uv_to_texel_uv};
use crate::texture::luminance;
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// The shader code this module is the CPU twin of (or, for a harness, runs).
pub const WGSL: crate::wgsl::WgslFile = crate::wgsl_file!("crates/core/src/env_sampling.wgsl");

/// Piecewise-constant 2D distribution over the map's texel uv.
#[derive(Debug, Clone, PartialEq)]
pub struct EnvDistribution {
    pub width: u32,
    pub height: u32,
    /// CDF over rows: `height + 1` values from 0 to 1.
    pub marginal: Vec<f32>,
    /// One CDF over columns per row: `height × (width + 1)` values.
    pub conditional: Vec<f32>,
}

impl EnvDistribution {
    pub const MAX_WIDTH: u32 = 512;

    pub fn new(image: &EnvImage) -> Self {
        let factor = image.width.div_ceil(Self::MAX_WIDTH).max(1);
        let (width, height) = (
            image.width.div_ceil(factor).max(1),
            image.height.div_ceil(factor).max(1),
        );
        let mut averaged = vec![0.0f64; (width * height) as usize];
        for y in 0..image.height {
            for x in 0..image.width {
                let p = image.texel(x, y);
                let lum = luminance(Vec3::new(p[0], p[1], p[2]));
                averaged[((y / factor) * width + x / factor) as usize] += f64::from(lum.max(0.0));
            }
        }
        // The bilinear lookup's reach: u wraps, v stops at the poles.
        let mut weights = vec![0.0f64; averaged.len()];
        for y in 0..height {
            for x in 0..width {
                let mut w = 0.0f64;
                for dy in [-1i64, 0, 1] {
                    let ny = (i64::from(y) + dy).clamp(0, i64::from(height) - 1) as u32;
                    for dx in [-1i64, 0, 1] {
                        let nx = (i64::from(x) + dx).rem_euclid(i64::from(width)) as u32;
                        w = w.max(averaged[(ny * width + nx) as usize]);
                    }
                }
                weights[(y * width + x) as usize] = w;
            }
        }
        for row in 0..height {
            let sin_theta = (PI * (row as f32 + 0.5) / height as f32).sin();
            for w in &mut weights[(row * width) as usize..((row + 1) * width) as usize] {
                *w *= f64::from(sin_theta);
            }
        }
        // A black map: sample uniformly in texel uv rather than divide by 0.
        let total: f64 = weights.iter().sum();
        if total.is_nan() || total <= 0.0 {
            weights.iter_mut().for_each(|w| *w = 1.0);
        }
        let mut conditional = Vec::with_capacity((height * (width + 1)) as usize);
        let mut row_sums = Vec::with_capacity(height as usize);
        for row in weights.chunks(width as usize) {
            let (cdf, sum) = cdf(row);
            conditional.extend(cdf);
            row_sums.push(sum);
        }
        let (marginal, _) = cdf(&row_sums);
        Self {
            width,
            height,
            marginal,
            conditional,
        }
    }

    fn row(&self, j: u32) -> &[f32] {
        let n = (self.width + 1) as usize;
        &self.conditional[j as usize * n..(j as usize + 1) * n]
    }

    /// The density over texel uv at `t` (integrates to 1 over [0, 1]²).
    pub fn pdf_texel_uv(&self, t: Vec2) -> f32 {
        let i = ((t.x * self.width as f32) as u32).min(self.width - 1);
        let j = ((t.y * self.height as f32) as u32).min(self.height - 1);
        let row = self.row(j);
        let p_row = self.marginal[j as usize + 1] - self.marginal[j as usize];
        let p_col = row[i as usize + 1] - row[i as usize];
        p_row * p_col * (self.width * self.height) as f32
    }

    /// A point of texel uv drawn from the distribution with two uniform
    /// numbers, and its density.
    pub fn sample(&self, u1: f32, u2: f32) -> (Vec2, f32) {
        let (j, y) = sample_cdf(&self.marginal, u1);
        let (i, x) = sample_cdf(self.row(j), u2);
        let t = Vec2::new(
            (i as f32 + x) / self.width as f32,
            (j as f32 + y) / self.height as f32,
        );
        (t, self.pdf_texel_uv(t))
    }

    /// The world direction of texel uv `t` for a map turned by
    /// `rotation_degrees` (the inverse of the lookup), and the solid-angle
    /// pdf of a texel-uv density `pdf` there (0 at the poles).
    pub fn direction(t: Vec2, pdf: f32, rotation_degrees: f32) -> (Vec3, f32) {
        let (u, v) = (t.x, 1.0 - t.y);
        let phi = 2.0 * PI * u - PI;
        let sin_theta = (PI * v).sin();
        let lookup = Vec3::new(
            sin_theta * phi.sin(),
            -(PI * v).cos(),
            sin_theta * phi.cos(),
        );
        let d = rotate_y(lookup, -rotation_degrees);
        let pdf = if sin_theta > 0.0 {
            pdf / (2.0 * PI * PI * sin_theta)
        } else {
            0.0
        };
        (d, pdf)
    }

    /// The solid-angle density with which [`EnvDistribution::sample`] and
    /// [`EnvDistribution::direction`] draw the world direction `d` for a
    /// map turned by `rotation_degrees`: the twin of the shader's
    /// `env_pdf` (0 at the poles, never NaN).
    pub fn pdf_direction(&self, d: Vec3, rotation_degrees: f32) -> f32 {
        let uv = direction_to_uv(rotate_y(d, rotation_degrees));
        let sin_theta = (PI * uv.y).sin();
        if sin_theta > 0.0 {
            self.pdf_texel_uv(uv_to_texel_uv(uv)) / (2.0 * PI * PI * sin_theta)
        } else {
            0.0
        }
    }

    /// The GPU's copy: the marginal CDF, then every row's.
    pub fn gpu_data(&self) -> Vec<f32> {
        let mut out = self.marginal.clone();
        out.extend(&self.conditional);
        out
    }
}

/// The normalised CDF of `weights` (`n + 1` values, 0 to 1) and their sum.
fn cdf(weights: &[f64]) -> (Vec<f32>, f64) {
    let sum: f64 = weights.iter().sum();
    let mut acc = 0.0;
    let mut out = Vec::with_capacity(weights.len() + 1);
    out.push(0.0);
    for (k, w) in weights.iter().enumerate() {
        acc += w;
        out.push(if sum > 0.0 {
            (acc / sum) as f32
        } else {
            (k + 1) as f32 / weights.len() as f32
        });
    }
    *out.last_mut().expect("a CDF has at least one step") = 1.0;
    (out, sum)
}

/// The cell `i` with `cdf[i] <= u < cdf[i + 1]` (by bisection, as the GPU
/// does) and where in it `u` falls, 0 to 1.
fn sample_cdf(cdf: &[f32], u: f32) -> (u32, f32) {
    let (mut lo, mut hi) = (0usize, cdf.len() - 1);
    while hi - lo > 1 {
        let mid = (lo + hi) / 2;
        if cdf[mid] <= u {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let span = cdf[lo + 1] - cdf[lo];
    let x = if span > 0.0 {
        ((u - cdf[lo]) / span).clamp(0.0, 1.0)
    } else {
        0.5
    };
    (lo as u32, x)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn map(width: u32, height: u32, bright: (u32, u32)) -> EnvImage {
        let mut image = crate::envmap::constant(width, height, [0.1, 0.1, 0.1]);
        let i = (bright.1 * width + bright.0) as usize;
        image.pixels[i] = [500.0, 400.0, 300.0, 1.0];
        image
    }

    /// The solid-angle pdf integrates to 1 over the sphere (midpoint rule
    /// in (θ, φ)).
    #[test]
    fn the_pdf_integrates_to_one_over_the_sphere() {
        let d = EnvDistribution::new(&map(64, 32, (40, 9)));
        let (nt, np) = (400, 800);
        let mut sum = 0.0f64;
        for a in 0..nt {
            let theta = PI * (a as f32 + 0.5) / nt as f32;
            for b in 0..np {
                let phi = 2.0 * PI * (b as f32 + 0.5) / np as f32;
                let dir = Vec3::new(
                    theta.sin() * phi.sin(),
                    -theta.cos(),
                    theta.sin() * phi.cos(),
                );
                let t = uv_to_texel_uv(direction_to_uv(dir));
                let pdf = d.pdf_texel_uv(t) / (2.0 * PI * PI * theta.sin());
                sum += f64::from(pdf * theta.sin())
                    * f64::from(PI / nt as f32)
                    * f64::from(2.0 * PI / np as f32);
            }
        }
        // The midpoint rule cuts the bright cell at its edges: ~1/400.
        assert!((sum - 1.0).abs() < 3e-3, "∫ pdf dω = {sum}");
    }

    /// Samples land where the light is and follow the pdf: the bright
    /// texel and its eight neighbours (the bilinear lookup's reach) share
    /// the same weight, the samples falling in the bright cell match its
    /// probability within 1 %, and each sample's direction looks up the
    /// cell it was drawn in.
    #[test]
    fn samples_follow_the_luminance_and_map_back_to_their_cell() {
        let image = map(64, 32, (40, 9));
        let d = EnvDistribution::new(&image);
        let centre = |x: u32, y: u32| Vec2::new((x as f32 + 0.5) / 64.0, (y as f32 + 0.5) / 32.0);
        let bright = d.pdf_texel_uv(centre(40, 9));
        assert!((d.pdf_texel_uv(centre(41, 9)) / bright - 1.0).abs() < 1e-4);
        let above = d.pdf_texel_uv(centre(40, 8));
        let sin = |y: u32| (PI * (y as f32 + 0.5) / 32.0).sin();
        assert!((above / bright - sin(8) / sin(9)).abs() < 1e-4);
        assert!(d.pdf_texel_uv(centre(10, 20)) < 1e-3 * bright);
        let (n, mut in_bright) = (20_000, 0);
        for k in 0..n {
            let u1 = (k as f32 + 0.5) / n as f32;
            let u2 = ((k as f32 * 0.618_034).fract() + 0.5 / n as f32).min(0.999_999);
            let (t, pdf) = d.sample(u1, u2);
            assert!(pdf > 0.0 && pdf.is_finite());
            let (dir, pdf_omega) = EnvDistribution::direction(t, pdf, 30.0);
            assert!(pdf_omega.is_finite());
            let back = uv_to_texel_uv(direction_to_uv(rotate_y(dir, 30.0)));
            assert!(
                (back - t).abs().max_element() < 1e-3 || (back.x - t.x).abs() > 0.999,
                "{t} -> {back}"
            );
            let cell = (t * Vec2::new(64.0, 32.0)).floor();
            in_bright += usize::from(cell == Vec2::new(40.0, 9.0));
        }
        let share = in_bright as f32 / n as f32;
        let expected = bright / (64.0 * 32.0);
        assert!(
            (share - expected).abs() < 0.01 * expected.max(0.1),
            "{share} vs {expected}"
        );
    }

    /// A black map samples uniformly; poles give a zero pdf, never NaN.
    #[test]
    fn black_maps_and_poles_stay_finite() {
        let d = EnvDistribution::new(&crate::envmap::constant(8, 4, [0.0; 3]));
        assert!((d.pdf_texel_uv(Vec2::new(0.3, 0.6)) - 1.0).abs() < 1e-5);
        let (_, pdf) = EnvDistribution::direction(Vec2::new(0.5, 0.0), 1.0, 0.0);
        assert_eq!(pdf, 0.0);
    }

    /// Maps wider than the cap are box-averaged into cells that keep the
    /// total: a 2048-wide map becomes 512 cells wide.
    #[test]
    fn wide_maps_are_averaged_into_fewer_cells() {
        let d = EnvDistribution::new(&map(2048, 1024, (1000, 300)));
        assert_eq!((d.width, d.height), (512, 256));
        let (t, _) = d.sample(0.5, 0.5);
        assert!(t.is_finite());
    }
}
