//! `marbre bench-edit`: what one frame of a slider drag costs the CPU
//! before anything is traced. Each step edits the scene as the panel
//! would (an octave count, a colour, the camera, the exposure) and times
//! handing it to the renderer (`Renderer::request_scene`), the path every
//! frame of a drag takes in the viewer. The GPU is not waited on: this is
//! the render thread's own cost, which a timeline animating a parameter
//! would pay every frame.
//!
//! `--structural` times instead what a user waits for after a structural
//! edit (a pattern switched, as the node editor's Add or the tree panel's
//! pattern list do): the new pipeline built on its worker thread, then
//! frames of the viewer's budget traced until each preview
//! (`preview_ladder`) and the full round show.

use anyhow::{Result, ensure};
use clap::Args;
use marbre_core::scene::{Child, PatternKind, Scene, Texture};
use marbre_render::gpu::{GpuContext, Renderer};
use marbre_render::gpu::{Kernel, TraceBudget};
use marbre_render::session::{load_scene, renderer_with};
use std::path::PathBuf;
use std::time::Instant;

#[derive(Args, Debug)]
pub struct EditBenchArgs {
    /// The preset whose scene is edited.
    #[arg(long, default_value = "presets/default.ron")]
    pub preset: PathBuf,
    /// Edits timed per kind, interleaved.
    #[arg(long, default_value_t = 300)]
    pub steps: u32,
    /// Time structural edits to their previews instead (this many edits,
    /// at the render size `--size`).
    #[arg(long)]
    pub structural: bool,
    /// The render size of `--structural`: the viewer's default image.
    #[arg(long, default_value = "884x575", value_parser = crate::render::parse_size)]
    pub size: (u32, u32),
    /// The trace time per frame of `--structural`, as the viewer's
    /// `--frame-budget-ms`.
    #[arg(long, default_value_t = 12.0)]
    pub frame_budget_ms: f32,
}

/// The edits a drag makes, one step at a time.
#[derive(Clone, Copy, Debug)]
enum Drag {
    /// The octave count of the first noise pattern (a fractional slider).
    Octaves,
    /// The first constant colour of the first material.
    Colour,
    /// The camera's orbit angle.
    Camera,
    /// The display exposure.
    Exposure,
}

impl Drag {
    const ALL: [Drag; 4] = [Drag::Octaves, Drag::Colour, Drag::Camera, Drag::Exposure];

    fn name(self) -> &'static str {
        match self {
            Drag::Octaves => "octaves (noise parameter)",
            Drag::Colour => "colour (texture parameter)",
            Drag::Camera => "camera orbit",
            Drag::Exposure => "exposure (display)",
        }
    }

    /// Moves `scene` by step `i` of the drag; false if the scene has
    /// nothing this drag edits.
    fn apply(self, scene: &mut Scene, i: u32) -> bool {
        let wiggle = (i % 20) as f32 / 20.0;
        match self {
            Drag::Octaves => edit_first_texture(scene, &mut |t| match t.pattern.noise_mut() {
                Some(noise) => {
                    noise.fractal.octaves = 4.0 + wiggle;
                    true
                }
                None => false,
            }),
            Drag::Colour => edit_first_texture(scene, &mut |t| match &mut t.a {
                Child::Color(c) => {
                    c.y = 0.3 + 0.5 * wiggle;
                    true
                }
                _ => false,
            }),
            Drag::Camera => {
                scene.camera.yaw_degrees = 30.0 * wiggle;
                true
            }
            Drag::Exposure => {
                scene.render.display.exposure = wiggle;
                true
            }
        }
    }
}

/// Applies `edit` to the first texture node, in material order, for which
/// it returns true; false if it returned false for every node.
fn edit_first_texture(scene: &mut Scene, edit: &mut dyn FnMut(&mut Texture) -> bool) -> bool {
    let mut done = false;
    for material in scene.materials_mut() {
        material.visit_textures_mut(&mut |t| done = done || edit(t));
        if done {
            break;
        }
    }
    done
}

pub fn run(args: &EditBenchArgs) -> Result<()> {
    ensure!(args.steps > 0, "--steps must be at least 1");
    if args.structural {
        return structural(args);
    }
    let ctx = GpuContext::headless()?;
    let loaded = load_scene(&args.preset, None)?;
    let mut renderer = renderer_with(&ctx, &loaded, (64, 36), Kernel::Fragment)?;
    println!("adapter: {}", ctx.describe());
    println!("preset: {}", args.preset.display());
    let mut scene = loaded.scene.clone();
    let drags: Vec<Drag> = Drag::ALL
        .into_iter()
        .filter(|d| d.apply(&mut scene.clone(), 0))
        .collect();
    let mut times: Vec<Vec<f64>> = vec![Vec::new(); drags.len()];
    for i in 0..args.steps {
        for (k, drag) in drags.iter().enumerate() {
            drag.apply(&mut scene, i + 1);
            let start = Instant::now();
            hand_over(&ctx, &mut renderer, &scene)?;
            times[k].push(start.elapsed().as_secs_f64() * 1e6);
        }
    }
    println!("{:<28} {:>12} {:>12}", "edit", "median µs", "mean µs");
    for (drag, mut t) in drags.iter().zip(times) {
        let mean = t.iter().sum::<f64>() / t.len() as f64;
        t.sort_by(f64::total_cmp);
        println!(
            "{:<28} {:>12.1} {:>12.1}",
            drag.name(),
            t[t.len() / 2],
            mean
        );
    }
    Ok(())
}

/// What the viewer does with an edited scene each frame
/// (`app/viewer/frame.rs`): works out what changed since the scene the
/// renderer was last asked to draw, once, and hands it on.
fn hand_over(ctx: &GpuContext, renderer: &mut Renderer, scene: &Scene) -> Result<()> {
    let change = scene.changes_from(renderer.requested_scene());
    renderer.request_scene(ctx, scene, change)?;
    if let Some(result) = renderer.poll_build(ctx) {
        result?;
    }
    Ok(())
}

/// Milliseconds from a structural edit to each stage the window shows:
/// the new pipeline, each preview (its width as a fraction of the
/// render's), the full round.
#[derive(Debug, Default, Clone)]
struct Waited {
    build: f64,
    previews: Vec<(f32, f64)>,
    full_round: f64,
}

/// `--structural`: switches the first pattern between two kinds, each
/// switch a new pipeline, and traces the viewer's frames until the full
/// round shows, noting when each stage appeared.
fn structural(args: &EditBenchArgs) -> Result<()> {
    let ctx = GpuContext::headless()?;
    let loaded = load_scene(&args.preset, None)?;
    let mut renderer = renderer_with(&ctx, &loaded, args.size, Kernel::Fragment)?;
    println!("adapter: {}", ctx.describe());
    println!(
        "preset: {}, {}x{}, {} ms of tracing a frame",
        args.preset.display(),
        args.size.0,
        args.size.1,
        args.frame_budget_ms
    );
    // A whole round, for the cost of a pixel (the viewer learns it from
    // its frames' timestamps).
    let start = Instant::now();
    frame(&ctx, &mut renderer, TraceBudget::Round);
    let round_ms = start.elapsed().as_secs_f64() * 1000.0;
    let pixels = u64::from(args.size.0) * u64::from(args.size.1);
    let budget = (pixels as f64 * f64::from(args.frame_budget_ms) / round_ms).max(1.0) as u64;
    println!("one round: {round_ms:.0} ms, so {budget} pixels a frame");
    let mut scene = loaded.scene.clone();
    let kinds = [PatternKind::Waves, PatternKind::Checker];
    let mut waits = Vec::new();
    for i in 0..args.steps as usize {
        ensure!(
            edit_first_texture(&mut scene, &mut |t| {
                t.pattern = t.pattern.with_kind(kinds[i % 2]);
                true
            }),
            "{}: no texture node to switch",
            args.preset.display()
        );
        let edited = Instant::now();
        let ms = || edited.elapsed().as_secs_f64() * 1000.0;
        hand_over(&ctx, &mut renderer, &scene)?;
        let mut waited = Waited::default();
        while renderer.is_building() {
            if let Some(result) = renderer.poll_build(&ctx) {
                result?;
            }
            std::thread::sleep(std::time::Duration::from_millis(1));
        }
        waited.build = ms();
        let full = renderer.render_size();
        while renderer.accumulated_samples() == 0 {
            frame(&ctx, &mut renderer, TraceBudget::Pixels(budget));
            let shown = renderer.shown_size().0 as f32 / full.0 as f32;
            if renderer.accumulated_samples() == 0
                && waited.previews.last().is_none_or(|(s, _)| *s != shown)
            {
                waited.previews.push((shown, ms()));
            }
        }
        waited.full_round = ms();
        waits.push(waited);
    }
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    println!("structural edit, median of {} (ms)", waits.len());
    println!(
        "{:<36} {:>8.0}",
        "new pipeline built",
        median(waits.iter().map(|w| w.build).collect())
    );
    let steps = waits.iter().map(|w| w.previews.len()).min().unwrap_or(0);
    for k in 0..steps {
        let scale = waits[0].previews[k].0;
        println!(
            "{:<36} {:>8.0}",
            format!("preview {} shown ({scale:.2} scale)", k + 1),
            median(waits.iter().map(|w| w.previews[k].1).collect())
        );
    }
    println!(
        "{:<36} {:>8.0}",
        "the full round shown",
        median(waits.iter().map(|w| w.full_round).collect())
    );
    Ok(())
}

/// Traces one frame of `budget` and waits for the GPU.
fn frame(ctx: &GpuContext, renderer: &mut Renderer, budget: TraceBudget) {
    let mut encoder = ctx.device.create_command_encoder(&Default::default());
    renderer.trace_within(ctx, &mut encoder, budget, None);
    ctx.queue.submit([encoder.finish()]);
    let _ = ctx.device.poll(wgpu::PollType::wait_indefinitely());
}
