//! `marbre noise --stability-figure`: the figure of issue 6's first hard
//! case. One octave of gradient noise along a line four cells long, near the
//! origin and at 1e3 … 1e6, with the lab's `fract(sin)` hash and with pcg3d,
//! evaluated by the real WGSL on this adapter and by the CPU reference.
//! pcg3d's two curves coincide at every distance (only f32's spacing, 1/16
//! at 1e6, shows as steps); the sin hash's part once `dot(cell, k)` leaves
//! the range where WGSL bounds `sin`'s error.

use anyhow::{Context, Result, anyhow};
use glam::{DVec3, Vec3};
use marbre_core::noise::{self, HashKind, NoiseKind, NoiseSettings};
use marbre_render::gpu::GpuContext;
use marbre_render::gpu::harness::noise::{Evaluate, evaluate_scalar};
use plotters::prelude::*;
use std::path::Path;

const DISTANCES: [f64; 5] = [0.0, 1e3, 1e4, 1e5, 1e6];
const HASHES: [HashKind; 2] = [HashKind::Sin, HashKind::Pcg];
/// Samples along each line: 4 cells at 100 a cell, finer than f32's
/// spacing up to 1e5 and coarser than it (1/16) at 1e6.
const SAMPLES: usize = 400;
const CELLS: f64 = 4.0;
const PANEL: (u32, u32) = (520, 190);
const FONT: &str = "sans-serif";

/// The line's points at `distance` along the x axis, off the lattice in y
/// and z so the noise is not zero on it.
fn line(distance: f64) -> Vec<Vec3> {
    (0..SAMPLES)
        .map(|k| {
            let x = distance + CELLS * k as f64 / SAMPLES as f64;
            DVec3::new(x, 0.37 + distance * 0.5, 0.71 - distance * 0.25).as_vec3()
        })
        .collect()
}

/// Draws the figure to `path` (PNG), captioned with the adapter's name.
pub fn write(path: &Path) -> Result<()> {
    let ctx = GpuContext::headless()?;
    let adapter = ctx.adapter.get_info().name;
    register_font()?;
    let size = (
        PANEL.0 * HASHES.len() as u32,
        PANEL.1 * DISTANCES.len() as u32 + 40,
    );
    let mut pixels = vec![0u8; (size.0 * size.1 * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut pixels, size).into_drawing_area();
        root.fill(&WHITE)?;
        let root = root.titled(
            &format!("gradient noise far from the origin: GPU ({adapter}, red) and CPU (blue)"),
            (FONT, 18),
        )?;
        let panels = root.split_evenly((DISTANCES.len(), HASHES.len()));
        for (i, &distance) in DISTANCES.iter().enumerate() {
            let pts = line(distance);
            for (j, &hash) in HASHES.iter().enumerate() {
                let settings = NoiseSettings {
                    kind: NoiseKind::Gradient,
                    hash,
                    ..Default::default()
                };
                let gpu = evaluate_scalar(&ctx, &settings, Evaluate::Noise, &pts)?;
                let cpu: Vec<f32> = pts
                    .iter()
                    .map(|&p| noise::noise(p, settings.kind, hash))
                    .collect();
                panel(&panels[i * HASHES.len() + j], distance, hash, &gpu, &cpu)?;
            }
        }
        root.present()?;
    }
    let image = image::RgbImage::from_raw(size.0, size.1, pixels)
        .context("the figure's buffer has the wrong size")?;
    image
        .save(path)
        .with_context(|| format!("writing {}", path.display()))
}

fn panel(
    area: &DrawingArea<BitMapBackend<'_>, plotters::coord::Shift>,
    distance: f64,
    hash: HashKind,
    gpu: &[f32],
    cpu: &[f32],
) -> Result<()> {
    let worst = gpu
        .iter()
        .zip(cpu)
        .map(|(g, c)| (g - c).abs())
        .fold(0.0f32, f32::max);
    let mut chart = ChartBuilder::on(area)
        .caption(
            format!(
                "{}, x from {distance:.0e}: max |GPU − CPU| {worst:.1e}",
                hash.label()
            ),
            (FONT, 14),
        )
        .margin(6)
        .x_label_area_size(20)
        .y_label_area_size(34)
        .build_cartesian_2d(0.0..CELLS, -1.2f64..1.2)?;
    chart
        .configure_mesh()
        .x_labels(5)
        .y_labels(5)
        .max_light_lines(0)
        .label_style((FONT, 11))
        .draw()?;
    let series = |values: &[f32]| -> Vec<(f64, f64)> {
        values
            .iter()
            .enumerate()
            .map(|(k, &v)| (CELLS * k as f64 / SAMPLES as f64, f64::from(v)))
            .collect()
    };
    chart.draw_series(LineSeries::new(series(cpu), BLUE.stroke_width(3)))?;
    chart.draw_series(LineSeries::new(series(gpu), RED.stroke_width(1)))?;
    Ok(())
}

/// The text is drawn from a font compiled in (egui's Ubuntu Light), so no
/// system font is needed.
fn register_font() -> Result<()> {
    plotters::style::register_font(FONT, FontStyle::Normal, epaint_default_fonts::UBUNTU_LIGHT)
        .map_err(|_| anyhow!("the figure's font does not parse"))
}
