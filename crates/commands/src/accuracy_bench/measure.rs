//! Rendering a sweep: each variant at each of its sample counts, a fresh
//! accumulation each time, timed frame by frame and compared with the
//! variant's reference.

use super::error_metrics::ErrorMetrics;
use super::frame_timer::{FrameTimer, TimerKind};
use super::knob::Knob;
use super::sweeps::{Sweep, Variant};
use crate::references::{Reference, ReferenceCache};
use anyhow::{Context, Result};
use indicatif::ProgressBar;
use marbre_core::scene::Scene;
use marbre_render::gpu::{GpuContext, Kernel, KernelChoice, Renderer};
use marbre_render::session::{LoadedScene, accumulate, pick_kernel, renderer_with};
use std::time::Instant;

/// Untimed frames before a variant's first timed one.
const WARM_UP_FRAMES: u32 = 3;

/// One render of one variant at one sample count.
#[derive(Debug, Clone, PartialEq)]
pub struct Point {
    pub knob: Knob,
    pub scene: String,
    pub variant: String,
    pub spp: u32,
    /// The median frame; a frame is one sample per pixel.
    pub ms_per_frame: f64,
    /// Wall-clock seconds of the whole render, every frame waited for.
    pub seconds: f64,
    pub errors: ErrorMetrics,
    pub timer: TimerKind,
    /// For a denoised variant, the filter's wall-clock ms (its readback
    /// included; also in `seconds`).
    pub filter_ms: Option<f64>,
}

/// What a sweep measured.
pub struct Measured {
    pub points: Vec<Point>,
    /// The kernel every variant of the sweep was traced with.
    pub kernel: Kernel,
    pub references_rendered: usize,
    pub references_cached: usize,
}

/// What a sweep needs besides itself.
pub struct Bench<'a> {
    pub ctx: &'a GpuContext,
    pub cache: &'a ReferenceCache,
    pub timer: &'a FrameTimer,
    /// The trace kernel: the one named, or for `auto` the faster on each
    /// sweep's first variant, the same for all its variants so that they
    /// differ by the knob alone.
    pub kernel: KernelChoice,
    /// Counts samples per pixel rendered, references included.
    pub progress: &'a ProgressBar,
}

impl Bench<'_> {
    /// Every point of `sweep`.
    pub fn measure(&self, sweep: &Sweep) -> Result<Measured> {
        let references = distinct_references(sweep)
            .into_iter()
            .map(|scene| Ok((scene, self.reference(sweep, scene)?)))
            .collect::<Result<Vec<_>>>()?;
        let kernel = self.kernel_of(sweep)?;
        let mut points = Vec::new();
        for variant in &sweep.variants {
            let reference = references
                .iter()
                .find(|(s, _)| *s == &variant.reference)
                .map(|(_, reference)| &reference.pixels)
                .context("every reference was rendered above")?;
            let mut renderer = self.renderer(sweep, variant, kernel)?;
            for &spp in &sweep.spp {
                self.progress.set_message(format!(
                    "{}: {} / {}, {spp} spp",
                    sweep.knob.id(),
                    sweep.scene_name,
                    variant.name
                ));
                renderer.reset_accumulation();
                let start = self.progress.position();
                let times = self.timer.run(self.ctx, &mut renderer, spp, |done| {
                    self.progress.set_position(start + u64::from(done));
                })?;
                let (pixels, filter_ms) = if variant.denoise {
                    let start = Instant::now();
                    let (_, _, pixels) = renderer.read_denoised(self.ctx)?;
                    (pixels, Some(start.elapsed().as_secs_f64() * 1000.0))
                } else {
                    (renderer.read_radiance(self.ctx)?.2, None)
                };
                points.push(Point {
                    knob: sweep.knob,
                    scene: sweep.scene_name.clone(),
                    variant: variant.name.clone(),
                    spp,
                    ms_per_frame: times.median_ms,
                    seconds: times.seconds + filter_ms.unwrap_or(0.0) / 1000.0,
                    errors: ErrorMetrics::between(&pixels, reference),
                    timer: self.timer.kind(),
                    filter_ms,
                });
            }
        }
        Ok(Measured {
            points,
            kernel,
            references_rendered: references.iter().filter(|(_, r)| !r.cached).count(),
            references_cached: references.iter().filter(|(_, r)| r.cached).count(),
        })
    }

    /// The samples per pixel `sweep` renders, its references included.
    pub fn samples(sweep: &Sweep) -> u64 {
        let per_variant: u64 = sweep.spp.iter().map(|&n| u64::from(n)).sum();
        distinct_references(sweep).len() as u64 * u64::from(sweep.reference_spp)
            + sweep.variants.len() as u64 * per_variant
    }

    fn reference(&self, sweep: &Sweep, scene: &Scene) -> Result<Reference> {
        self.progress.set_message(format!(
            "{}: {} reference, {} spp",
            sweep.knob.id(),
            sweep.scene_name,
            sweep.reference_spp
        ));
        let start = self.progress.position();
        let reference = self
            .cache
            .get_or_render(
                self.ctx,
                &with_scene(sweep, scene.clone()),
                sweep.size,
                sweep.reference_spp,
                |done| self.progress.set_position(start + u64::from(done)),
            )
            .with_context(|| format!("the reference of {}", sweep.scene_name))?;
        self.progress
            .set_position(start + u64::from(sweep.reference_spp));
        Ok(reference)
    }

    /// A fresh renderer of `variant`, one sample per pixel a frame, warmed
    /// up by a few untimed frames: drivers that compile at the first draw
    /// do it there, and on lavapipe the next few frames still run slow.
    ///
    /// Fresh, so that every variant of a sweep draws the same random
    /// numbers (the shader seeds from the frame count): the variants'
    /// errors then differ by what the knob changes, not by luck, and the
    /// specialised and uber shaders make the same image.
    fn renderer(&self, sweep: &Sweep, variant: &Variant, kernel: Kernel) -> Result<Renderer> {
        let mut renderer = renderer_with(
            self.ctx,
            &with_scene(sweep, measured(variant)),
            sweep.size,
            kernel,
        )?;
        if variant.features.is_some() {
            renderer.set_feature_override(self.ctx, variant.features.clone())?;
        }
        accumulate(self.ctx, &mut renderer, WARM_UP_FRAMES, |_| {})?;
        if variant.denoise {
            // Builds the filter's pipelines, which its first timing would
            // otherwise include.
            renderer.read_denoised(self.ctx)?;
        }
        Ok(renderer)
    }
}

impl Bench<'_> {
    /// The kernel of `sweep`'s renders (see [`Bench::kernel`]).
    fn kernel_of(&self, sweep: &Sweep) -> Result<Kernel> {
        let Some(first) = sweep.variants.first() else {
            return Ok(Kernel::Fragment);
        };
        self.progress
            .set_message(format!("{}: {} kernel", sweep.knob.id(), sweep.scene_name));
        let loaded = with_scene(sweep, measured(first));
        Ok(pick_kernel(self.ctx, &loaded, sweep.size, self.kernel)?.0)
    }
}

/// `variant`'s scene as it is measured: one sample per pixel a frame,
/// accumulated.
fn measured(variant: &Variant) -> Scene {
    let mut scene = variant.scene.clone();
    scene.render.samples_per_frame = 1;
    scene.render.accumulate = true;
    scene
}

/// The scenes whose references the variants of `sweep` are measured
/// against, each once.
fn distinct_references(sweep: &Sweep) -> Vec<&Scene> {
    let mut distinct: Vec<&Scene> = Vec::new();
    for variant in &sweep.variants {
        if !distinct.contains(&&variant.reference) {
            distinct.push(&variant.reference);
        }
    }
    distinct
}

/// `scene` with the sweep's environment and images.
fn with_scene(sweep: &Sweep, scene: Scene) -> LoadedScene {
    LoadedScene {
        scene,
        env: sweep.env.clone(),
        images: sweep.images.clone(),
        notes: Vec::new(),
        substitutes: Vec::new(),
    }
}
