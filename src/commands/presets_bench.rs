//! `marbre bench-presets`: milliseconds per frame for every shipped preset.

use super::aa_scenes;
use super::session::{accumulate, load_scene, renderer_for};
use crate::gpu::{Feature, FeatureSet, GpuContext, Renderer};
use crate::scene::Scene;
use anyhow::{Context, Result};
use clap::Args;
use std::path::PathBuf;
use std::time::Instant;

#[derive(Args, Debug)]
pub struct PresetsBenchArgs {
    /// Folder of presets to time.
    #[arg(long, default_value = "presets")]
    pub presets: PathBuf,
    /// Frames timed per measurement, after warm-up.
    #[arg(long, default_value_t = 30)]
    pub frames: u32,
    /// Sizes to time, WIDTHxHEIGHT.
    #[arg(long, value_delimiter = ',', default_values = ["1280x720", "640x360"], value_parser = super::render::parse_size)]
    pub sizes: Vec<(u32, u32)>,
}

/// Median wall-clock time per frame, each frame waited for: trace plus GPU
/// sync. The median, not the mean: on a shared CPU (lavapipe) a few frames
/// stall for reasons unrelated to the shader.
fn time_frames(ctx: &GpuContext, renderer: &mut Renderer, frames: u32) -> Result<f64> {
    let frame = |renderer: &mut Renderer| -> Result<()> {
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        renderer.trace(ctx, &mut encoder, None);
        ctx.queue.submit([encoder.finish()]);
        ctx.device.poll(wgpu::PollType::wait_indefinitely())?;
        Ok(())
    };
    // Warm-up: the first draw compiles the pipeline on many drivers.
    for _ in 0..3 {
        frame(renderer)?;
    }
    let mut times = Vec::with_capacity(frames as usize);
    for _ in 0..frames.max(1) {
        let start = Instant::now();
        frame(renderer)?;
        times.push(start.elapsed().as_secs_f64() * 1000.0);
    }
    times.sort_by(f64::total_cmp);
    Ok(times[times.len() / 2])
}

/// Wall-clock times, in ms, to build the preset's trace pipeline (the
/// renderer with it), and then to draw its first small frame: some drivers
/// finish compiling the shader at the first draw.
fn time_build(ctx: &GpuContext, loaded: &super::session::LoadedScene) -> Result<(f64, f64)> {
    let start = Instant::now();
    let mut renderer = renderer_for(ctx, loaded, (64, 36))?;
    let built = start.elapsed().as_secs_f64() * 1000.0;
    let start = Instant::now();
    let mut encoder = ctx.device.create_command_encoder(&Default::default());
    renderer.trace(ctx, &mut encoder, None);
    ctx.queue.submit([encoder.finish()]);
    ctx.device.poll(wgpu::PollType::wait_indefinitely())?;
    Ok((built, start.elapsed().as_secs_f64() * 1000.0))
}

pub fn run(args: &PresetsBenchArgs) -> Result<()> {
    let ctx = GpuContext::headless()?;
    let mut presets: Vec<PathBuf> = std::fs::read_dir(&args.presets)
        .with_context(|| format!("reading {}", args.presets.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "ron"))
        .collect();
    presets.sort();
    println!("adapter: {}", ctx.describe());
    println!(
        "frames per measurement: {}, 1 sample per pixel per frame",
        args.frames
    );
    println!(
        "specialised: the shader holds only what the preset uses; uber: every feature compiled in"
    );
    println!(
        "build: a new trace pipeline (what a structural edit costs), from WGSL to a pipeline + its first small frame; cold only with an empty Mesa shader cache (MESA_SHADER_CACHE_DIR=$(mktemp -d))"
    );
    let header: Vec<String> = args
        .sizes
        .iter()
        .map(|(w, h)| format!("{w}x{h} ms (fps) | {w}x{h} uber ms | uber / specialised"))
        .collect();
    println!(
        "| preset | features | build ms (pipeline + first frame) | {} |",
        header.join(" | ")
    );
    println!("|---|---|---|{}", "---|".repeat(3 * args.sizes.len()));
    for path in &presets {
        let mut loaded = load_scene(path, None)?;
        loaded.scene.render.samples_per_frame = 1;
        let mut cells = Vec::new();
        let mut features = 0;
        let (pipeline_ms, first_frame_ms) = time_build(&ctx, &loaded)?;
        for &size in &args.sizes {
            let mut renderer = renderer_for(&ctx, &loaded, size)?;
            features = renderer.features().0.len();
            let ms = time_frames(&ctx, &mut renderer, args.frames)?;
            renderer.set_feature_override(&ctx, Some(FeatureSet::all()))?;
            let uber = time_frames(&ctx, &mut renderer, args.frames)?;
            cells.push(format!(
                "{ms:.1} ({:.0}) | {uber:.1} | {:.2}",
                1000.0 / ms,
                uber / ms
            ));
        }
        let name = path.file_stem().unwrap_or_default().to_string_lossy();
        println!(
            "| {name} | {features} | {pipeline_ms:.0} + {first_frame_ms:.0} | {} |",
            cells.join(" | ")
        );
    }
    println!();
    anti_aliasing_table(&ctx, &presets, args.frames)
}

/// What procedural anti-aliasing costs, per preset that compiles the
/// footprint in (ms per frame with the switches on and off), and what it
/// buys, on grazing grounds where only the texture can be wrong
/// ([`aa_scenes`]): the error of one sample per pixel against 256 point
/// samples per pixel, filtered and not.
fn anti_aliasing_table(ctx: &GpuContext, presets: &[PathBuf], frames: u32) -> Result<()> {
    let size = AA_SIZE;
    println!(
        "procedural anti-aliasing at {}x{}: its cost on each preset that uses it, ms per frame",
        size.0, size.1
    );
    println!("| preset | ms filtered | ms point sampled | filtered / point |");
    println!("|---|---|---|---|");
    for path in presets {
        let mut loaded = load_scene(path, None)?;
        loaded.scene.render.samples_per_frame = 1;
        if !FeatureSet::for_scene(&loaded.scene).contains(Feature::Footprint) {
            continue;
        }
        let mut renderer = renderer_for(ctx, &loaded, size)?;
        let filtered_ms = time_frames(ctx, &mut renderer, frames)?;
        renderer.set_scene(ctx, &point_sampled(&loaded.scene))?;
        let point_ms = time_frames(ctx, &mut renderer, frames)?;
        let name = path.file_stem().unwrap_or_default().to_string_lossy();
        println!(
            "| {name} | {filtered_ms:.1} | {point_ms:.1} | {:.2} |",
            filtered_ms / point_ms
        );
    }
    println!();
    println!(
        "and what it buys: a Lambert ground in white light seen 8 degrees from grazing, RMSE of 1 spp against 256 spp point sampled"
    );
    println!(
        "| texture | RMSE filtered | RMSE point sampled | filtered / point | ms filtered | ms point |"
    );
    println!("|---|---|---|---|---|---|");
    for (name, texture) in aa_scenes::textures() {
        let point = aa_scenes::grazing_ground(texture);
        let mut filtered = point.clone();
        filtered.render.filter_checkers = true;
        filtered.render.clamp_octaves = true;
        let mut renderer = Renderer::new(ctx, &point, None, size)?;
        let point_ms = time_frames(ctx, &mut renderer, frames)?;
        let point_image = one_sample(ctx, &mut renderer)?;
        renderer.reset_accumulation();
        accumulate(ctx, &mut renderer, 256, |_| {})?;
        let (_, _, reference) = renderer.read_radiance(ctx)?;
        renderer.set_scene(ctx, &filtered)?;
        let filtered_ms = time_frames(ctx, &mut renderer, frames)?;
        let filtered_image = one_sample(ctx, &mut renderer)?;
        let e_filtered = rmse(&filtered_image, &reference);
        let e_point = rmse(&point_image, &reference);
        println!(
            "| {name} | {e_filtered:.4} | {e_point:.4} | {:.2} | {filtered_ms:.1} | {point_ms:.1} |",
            e_filtered / e_point
        );
    }
    Ok(())
}

/// `scene` with footprint filtering off.
fn point_sampled(scene: &Scene) -> Scene {
    let mut point = scene.clone();
    point.render.filter_checkers = false;
    point.render.clamp_octaves = false;
    point
}

/// The image size of the anti-aliasing table.
const AA_SIZE: (u32, u32) = (320, 180);

/// A fresh image of one sample per pixel.
fn one_sample(ctx: &GpuContext, renderer: &mut Renderer) -> Result<Vec<[f32; 4]>> {
    renderer.reset_accumulation();
    accumulate(ctx, renderer, 1, |_| {})?;
    Ok(renderer.read_radiance(ctx)?.2)
}

/// Root mean square difference over every colour channel, each tone-mapped
/// by x / (1 + x) so that a few bright pixels do not decide it.
fn rmse(a: &[[f32; 4]], b: &[[f32; 4]]) -> f64 {
    let map = |x: f32| f64::from(x / (1.0 + x.max(0.0)));
    let sum: f64 = a
        .iter()
        .zip(b)
        .flat_map(|(p, q)| (0..3).map(move |c| (map(p[c]) - map(q[c])).powi(2)))
        .sum();
    (sum / (3 * a.len()) as f64).sqrt()
}
