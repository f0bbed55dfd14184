//! `marbre bench-edit`: what one frame of a slider drag costs the CPU
//! before anything is traced. Each step edits the scene as the panel
//! would (an octave count, a colour, the camera, the exposure) and times
//! handing it to the renderer (`Renderer::request_scene`), the path every
//! frame of a drag takes in the viewer. The GPU is not waited on: this is
//! the render thread's own cost, which a timeline animating a parameter
//! would pay every frame.

use anyhow::{Result, ensure};
use clap::Args;
use marbre_core::scene::{Child, Scene, Texture};
use marbre_render::gpu::Kernel;
use marbre_render::gpu::{GpuContext, Renderer};
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
