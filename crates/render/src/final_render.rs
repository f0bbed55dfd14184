//! A final render to a file: a loaded scene traced to a number of samples
//! or an error target, then written atomically as PNG or EXR. `marbre
//! render` and the viewer's Render dialog both run [`render_to_file`], so
//! that the dialog's image is the command's, byte for byte; each caller
//! only says how progress is shown and whether to stop early.

use crate::cpu_display;
use crate::frame_sequence::{self, PlannedFrame, Timing};
use crate::gpu::auto_exposure;
use crate::gpu::error_meter::ErrorEstimate;
use crate::gpu::{GpuContext, KernelChoice, Renderer};
use crate::session::{
    LoadedScene, describe_pick, load_environment, max_texture_side, pick_kernel, renderer_with,
    trace_frame,
};
use anyhow::{Context, Result, bail};
use marbre_core::animated_image;
use marbre_core::image_io::{self, ImageFormat, LayerName};
use marbre_core::render_record::{RECORD_ATTRIBUTE, RenderRecord, scene_hash};
use marbre_core::scene::{DenoiseQuality, Denoiser, Metering, RenderSettings, Scene, View};
use marbre_core::texture::ImageSet;
use marbre_core::tile::{self, Tile};
use std::ops::ControlFlow;
use std::path::PathBuf;
use std::time::Duration;
use web_time::Instant;

/// When a final render stops.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Stop {
    /// After this many samples per pixel.
    Samples(u32),
    /// As soon as the estimated relative error (√relMSE, as the Quality
    /// panel shows it) is at most `target`, or at `max_spp` samples.
    TargetError { target: f64, max_spp: u32 },
}

impl Stop {
    /// The most samples per pixel the render may take.
    pub fn max_samples(self) -> u32 {
        match self {
            Stop::Samples(n) | Stop::TargetError { max_spp: n, .. } => n,
        }
    }
}

/// A size written WIDTHxHEIGHT, each from 1 to 16384: `render --size`
/// and the dialog's size field.
pub fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X', '×'])
        .ok_or_else(|| format!("`{s}` is not WIDTHxHEIGHT"))?;
    let parse = |v: &str| {
        v.trim()
            .parse::<u32>()
            .ok()
            .filter(|&n| (1..=16384).contains(&n))
            .ok_or_else(|| format!("`{v}` is not a size between 1 and 16384"))
    };
    Ok((parse(w)?, parse(h)?))
}

/// What to render from a loaded scene, and where to.
#[derive(Debug, Clone, PartialEq)]
pub struct FinalRender {
    pub size: (u32, u32),
    pub stop: Stop,
    /// Expose the PNG automatically with this metering, the scene's
    /// exposure becoming a compensation; `None`: as the scene says.
    pub auto_exposure: Option<Metering>,
    pub kernel: KernelChoice,
    /// `.png` (tone-mapped, sRGB) or `.exr` (linear radiance, float).
    pub output: PathBuf,
    /// Filter the image with this denoiser (`render --denoise`, the Render
    /// dialog's "denoise"), as the scene's display does when its
    /// `denoise` is on: the PNG, and the EXR too with `denoise_exr`. OIDN
    /// falls back to the à-trous filter, with a note, where its library is
    /// not found.
    pub denoise: Option<Denoiser>,
    /// OIDN's network for this render (`render --denoise-quality`; high,
    /// for final frames, unless asked).
    pub denoise_quality: DenoiseQuality,
    /// Write the EXR denoised (with `denoise`, or the scene's display's);
    /// otherwise an EXR is the raw accumulation.
    pub denoise_exr: bool,
    /// Render even when a file the scene reads could not be loaded and was
    /// replaced (a placeholder image, a grey material): the viewer does,
    /// so that the scene it shows can be rendered; `marbre render` does
    /// only with `--allow-placeholders`, so that a script or a farm never
    /// takes such an image as good.
    pub allow_placeholders: bool,
    /// The moment traced, or the frames of a sequence.
    pub timing: Timing,
    /// The first sample traced (`render --sample-offset`): `spp` samples
    /// from it are samples [offset, offset + spp) of the one long render
    /// of the frame, so that renders at offsets 0, N, 2N… of N samples
    /// each are disjoint batches whose mean is the render of all their
    /// samples. A multiple of the scene's samples per frame.
    pub sample_offset: u32,
    /// The tile of the image to trace (`render --tile`): the output holds
    /// its pixels only, traced with the whole image's camera and samples,
    /// for `marbre merge` to assemble; `None`: the whole image.
    pub tile: Option<Tile>,
    /// The most pixels one set of GPU targets holds: a larger image (or
    /// tile) is traced a piece at a time ([`tile::split`]) and put
    /// together on the CPU, so that any size completes in bounded GPU
    /// memory.
    pub max_tile_pixels: u64,
    /// Write each pixel's estimated variance of its mean beside the
    /// radiance, as the EXR's `variance` layer (`render --moments`), from
    /// the spread of its rounds: a merge of such files knows its error
    /// even with one batch a tile. Needs two rounds or more.
    pub moments: bool,
    /// Write the denoiser's guides beside the radiance, the EXR's
    /// `albedo` and `normal` layers (`render --guides`): the means of the
    /// samples' first-hit albedo and shading normal, so that a merge can
    /// denoise what it puts together.
    pub guides: bool,
}

/// [`FinalRender::max_tile_pixels`] by default: a 4K UHD frame (3840 ×
/// 2160), about 1.3 GB of targets at 160 bytes a pixel; every size up to
/// it is traced whole, as it always was.
pub const DEFAULT_MAX_TILE_PIXELS: u64 = 3840 * 2160;

/// How far a render has come, after each round of samples.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Progress {
    pub samples: u32,
    pub max_samples: u32,
    /// The last estimated relative error, when rendering to a target.
    pub relative_error: Option<f64>,
    /// Which of the frames to trace this is (0 for a still), and how many
    /// there are (1 for a still).
    pub frame: u32,
    pub frames: u32,
}

impl Progress {
    /// The fraction done, 0 to 1: frames done, and samples against the cap
    /// in the frame under way (a render to an error target may end well
    /// before it).
    pub fn fraction(&self) -> f32 {
        let in_frame = (f64::from(self.samples) / f64::from(self.max_samples.max(1))).min(1.0);
        ((f64::from(self.frame) + in_frame) / f64::from(self.frames.max(1))).min(1.0) as f32
    }
}

/// Where a render reports to: lines for the user (the kernel chosen, the
/// error reached, the exposure, notes on the scene), and progress after
/// each frame, whose answer can stop the render.
pub trait RenderObserver {
    fn note(&mut self, line: &str);
    /// What the render does before its first sample, as it starts it
    /// ("building the trace shader"): a dialog shows it in place of its
    /// progress. Nothing by default: a terminal shows the notes.
    fn stage(&mut self, _what: &str) {}
    /// `Break` cancels the render: nothing is written.
    fn progress(&mut self, progress: &Progress) -> ControlFlow<()>;
}

/// How a render ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Outcome {
    Written,
    Cancelled,
}

/// A scene already in memory (the viewer's, as edited) with the images it
/// has loaded, its environment read again from its files: what a render
/// of it on another device needs (the window's renderer keeps its
/// environment on its own device only).
pub fn snapshot(scene: Scene, images: ImageSet) -> Result<LoadedScene> {
    let mut notes = Vec::new();
    let env = load_environment(
        &scene.environment.source,
        scene.environment.ldr_images,
        u32::MAX,
    )?
    .map(|l| {
        notes.extend(l.notes);
        l.image
    });
    Ok(LoadedScene {
        substitutes: images.placeholders().to_vec(),
        scene,
        env,
        images,
        notes,
    })
}

/// The renderer of a final render, or one clear error before any tracing
/// if the GPU cannot hold its images: its targets are allocated under an
/// out-of-memory error scope, which wgpu would otherwise treat as fatal (a
/// 16384² render panicked on lavapipe, whose largest allocation is smaller
/// than one of its 4 GiB targets). The read-back after the render goes in
/// bands of bounded size (`gpu::readback`), so it needs no large buffer.
fn renderer_fitting(
    ctx: &GpuContext,
    loaded: &LoadedScene,
    size: (u32, u32),
    kernel: crate::gpu::Kernel,
) -> Result<crate::gpu::Renderer> {
    let memory = ctx.device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
    // What follows a failed allocation (a view of the texture that is not
    // there) is invalid too: caught, and reported as the allocation.
    let validity = ctx.device.push_error_scope(wgpu::ErrorFilter::Validation);
    let renderer = renderer_with(ctx, loaded, size, kernel);
    let invalid = pollster::block_on(validity.pop());
    let out_of_memory = pollster::block_on(memory.pop());
    if let Some(e) = out_of_memory {
        bail!(
            "a {} × {} render does not fit in the memory of {} ({e}); nothing was traced: \
             render a smaller size",
            size.0,
            size.1,
            ctx.adapter.get_info().name
        );
    }
    if let Some(e) = invalid {
        bail!(
            "the GPU refused the images of a {} × {} render ({e}); nothing was traced",
            size.0,
            size.1
        );
    }
    renderer
}

/// An error naming the files of `loaded` that could not be read and were
/// replaced (see the notes for why), if any.
pub fn refuse_substitutes(loaded: &LoadedScene) -> Result<()> {
    if loaded.substitutes.is_empty() {
        return Ok(());
    }
    let files: Vec<String> = loaded
        .substitutes
        .iter()
        .map(|p| p.display().to_string())
        .collect();
    bail!(
        "{} could not be loaded (the notes above say why); nothing was rendered. Fix the \
         file, or pass --allow-placeholders to render with a placeholder in its place",
        files.join(", ")
    )
}

/// What a job writes, checked before any loading or tracing: the output's
/// format, its folder, the samples, the target, and a sequence's
/// animated file; the latter is returned with the format.
pub fn check_job(job: &FinalRender) -> Result<(ImageFormat, Option<&PathBuf>)> {
    let format = ImageFormat::from_path(&job.output)?;
    // Found before the render, not after it, and never created by
    // surprise; a file in the way is named.
    image_io::check_output(&job.output)?;
    if job.stop.max_samples() == 0 {
        bail!("a render needs at least 1 sample per pixel");
    }
    if let Stop::TargetError { target, .. } = job.stop
        && !(target.is_finite() && target > 0.0)
    {
        bail!("the target error must be a positive number, like 0.01 for 1 %");
    }
    if job
        .sample_offset
        .checked_add(job.stop.max_samples())
        .is_none()
    {
        bail!(
            "--sample-offset {} is out of range: samples {}..{} pass the last one a render \
             numbers, {}",
            job.sample_offset,
            job.sample_offset,
            u64::from(job.sample_offset) + u64::from(job.stop.max_samples()),
            u32::MAX
        );
    }
    let animation = match &job.timing {
        Timing::Sequence {
            animation: Some(path),
            ..
        } => {
            if format != ImageFormat::Png {
                bail!(
                    "{}: an animation is assembled from PNG frames; write the frames as .png",
                    path.display()
                );
            }
            image_io::check_output(path)?;
            animated_image::check_writable(path)?;
            Some(path)
        }
        _ => None,
    };
    if let Some(tile) = job.tile {
        tile.check_within(job.size)
            .map_err(|e| anyhow::anyhow!("--tile: {e}"))?;
        if format != ImageFormat::Exr {
            bail!(
                "{}: a tile is written as linear radiance, an .exr, for `marbre merge` to \
                 assemble and tone-map",
                job.output.display()
            );
        }
    }
    if (job.moments || job.guides) && format != ImageFormat::Exr {
        bail!(
            "{}: --moments and --guides write layers beside the picture, which only an .exr \
             holds",
            job.output.display()
        );
    }
    if job.max_tile_pixels == 0 {
        bail!("the largest piece traced at once must hold at least 1 pixel");
    }
    frame_sequence::plan(&job.timing, &job.output)?;
    Ok((format, animation))
}

/// Renders `loaded` as `job` says on `ctx` and writes the image to
/// `job.output` atomically (a sibling file renamed over it: a cancelled or
/// failed render leaves no partial file), or, for a sequence, each frame
/// to its file, the scene at each frame's time traced by one renderer (a
/// moment differs from the next in numbers only: no pipeline is built
/// again). Errors name the output file.
pub fn render_to_file(
    ctx: &GpuContext,
    mut loaded: LoadedScene,
    job: &FinalRender,
    observer: &mut dyn RenderObserver,
) -> Result<Outcome> {
    let (format, animation) = check_job(job)?;
    let (frames, written) = frame_sequence::plan(&job.timing, &job.output)?;
    if !written.is_empty() {
        observer.note(&format!(
            "{} of the frames are written already and skipped (--overwrite traces them again): {} …",
            written.len(),
            written[0].output.display()
        ));
    }
    show_as_asked(&mut loaded.scene.render, job)?;
    if let Some(problem) = loaded
        .scene
        .animation
        .as_ref()
        .and_then(|a| a.problems(&loaded.scene).into_iter().next())
    {
        bail!("the scene's animation cannot be traced: {problem}");
    }
    let base = std::mem::take(&mut loaded.scene);
    let Some(first) = frames.first() else {
        return assemble(animation, &written, job, observer);
    };
    loaded.scene = base.at_time(first.time);
    let loaded = loaded.fit_environment(max_texture_side(ctx));
    for note in &loaded.notes {
        observer.note(&format!("note: {note}"));
    }
    if !job.allow_placeholders {
        refuse_substitutes(&loaded)?;
    }
    let per_round = loaded.scene.render.samples_per_frame.max(1);
    if !job.sample_offset.is_multiple_of(per_round) {
        bail!(
            "--sample-offset {} is not a multiple of the preset's samples_per_frame ({per_round}): \
             a batch starts where a round of the long render starts",
            job.sample_offset
        );
    }
    let region = job.tile.unwrap_or(Tile::whole(job.size));
    let max_side = ctx.device.limits().max_texture_dimension_2d;
    let pieces = tile::split(region, max_side, job.max_tile_pixels);
    let cropped = pieces != [Tile::whole(job.size)];
    if cropped {
        check_piecewise(&loaded.scene, job, format, pieces.len())?;
    }
    if pieces.len() > 1 {
        observer.note(&format!(
            "traced in {} pieces of at most {} × {} pixels",
            pieces.len(),
            pieces[0].size().0,
            pieces[0].size().1
        ));
    }
    if job.moments && job.stop.max_samples() <= per_round {
        bail!(
            "--moments estimates each pixel's variance from the spread of its rounds, and {} \
             samples are one round of the preset's {per_round}: give --spp above {per_round}",
            job.stop.max_samples()
        );
    }
    if job.kernel == crate::gpu::KernelChoice::Auto {
        observer.stage("timing the trace kernels");
    }
    let (kernel, timings) = pick_kernel(ctx, &loaded, pieces[0].size(), job.kernel)?;
    observer.note(&describe_pick(
        kernel,
        timings.as_ref(),
        job.kernel,
        &loaded.scene,
    ));
    observer.stage(&format!("building the {kernel} trace shader"));
    let mut renderer = renderer_fitting(ctx, &loaded, pieces[0].size(), kernel)?;
    observer.stage("tracing the first round");
    for (index, planned) in frames.iter().enumerate() {
        if index > 0 {
            renderer.set_scene(ctx, &base.at_time(planned.time))?;
        }
        if !cropped {
            let mut in_sequence = InSequence {
                observer: &mut *observer,
                frame: index as u32,
                frames: frames.len() as u32,
            };
            renderer.restart_at_sample(planned.frame, job.sample_offset);
            if trace_to_stop(ctx, &mut renderer, job.stop, &mut in_sequence)?.is_break() {
                return Ok(Outcome::Cancelled);
            }
            write_image(ctx, &mut renderer, job, format, planned, observer)?;
            continue;
        }
        let mut pixels = vec![[0.0f32; 4]; region.pixels() as usize];
        let mut layers: Vec<(LayerName, Vec<[f32; 3]>)> = Vec::new();
        for (p, piece) in pieces.iter().enumerate() {
            // The progress counts pieces as it counts frames.
            let mut in_sequence = InSequence {
                observer: &mut *observer,
                frame: (index * pieces.len() + p) as u32,
                frames: (frames.len() * pieces.len()) as u32,
            };
            renderer.set_crop(ctx, *piece, job.size);
            renderer.restart_at_sample(planned.frame, job.sample_offset);
            if trace_to_stop(ctx, &mut renderer, job.stop, &mut in_sequence)?.is_break() {
                return Ok(Outcome::Cancelled);
            }
            let (_, _, traced) = renderer.read_radiance(ctx)?;
            place(&mut pixels, region, *piece, &traced);
            for (i, (name, values)) in read_layers(ctx, &renderer, job)?.into_iter().enumerate() {
                if layers.len() == i {
                    layers.push((name, vec![[0.0; 3]; pixels.len()]));
                }
                place(&mut layers[i].1, region, *piece, &values);
            }
        }
        let record = record_of(ctx, &renderer, job, planned, region);
        let assembled = Assembled {
            pixels: &pixels,
            layers: &layers,
            record: &record,
        };
        refuse_gpu_errors(ctx, &planned.output)?;
        write_assembled(&renderer, &assembled, format, planned, observer)?;
    }
    let mut all: Vec<PlannedFrame> = frames.into_iter().chain(written).collect();
    all.sort_by_key(|f| f.frame);
    assemble(animation, &all, job, observer)
}

/// Refuses what a render traced in pieces cannot do: the denoiser and an
/// error target need the whole image on the GPU.
fn check_piecewise(
    scene: &Scene,
    job: &FinalRender,
    format: ImageFormat,
    pieces: usize,
) -> Result<()> {
    let why = if job.tile.is_some() {
        "a tile".to_owned()
    } else {
        format!(
            "a {} × {} render is traced in {pieces} pieces (--max-tile-pixels {})",
            job.size.0, job.size.1, job.max_tile_pixels
        )
    };
    if job.denoise_exr || (format == ImageFormat::Png && scene.render.shown_display().denoise) {
        bail!(
            "{why}, which the denoiser cannot filter (it needs the whole image); denoise the \
             merged image, or render without --denoise"
        );
    }
    if let Stop::TargetError { .. } = job.stop {
        bail!(
            "{why}, whose pieces would each stop at their own samples; give --spp instead of \
             --target-error"
        );
    }
    Ok(())
}

/// The layers `job` asks for beside the radiance, of the region traced:
/// each pixel's estimated variance of its mean (the spread of its rounds
/// over their number less one: `shaders/trace.wgsl`'s weighted Welford
/// keeps Σ n_i (x_i − m)² / N, whose expectation is (F − 1) σ² / N), and
/// the guides (the normal decoded from the target's 0.5 + 0.5·n).
fn read_layers(
    ctx: &GpuContext,
    renderer: &Renderer,
    job: &FinalRender,
) -> Result<Vec<(LayerName, Vec<[f32; 3]>)>> {
    let mut layers = Vec::new();
    if job.moments {
        let (_, _, spread) = renderer.read_spread(ctx)?;
        let rounds_less_one = renderer.accumulated_frames().saturating_sub(1).max(1) as f32;
        let variance = spread
            .iter()
            .map(|s| [s[0], s[1], s[2]].map(|v| v / rounds_less_one))
            .collect();
        layers.push((image_io::VARIANCE, variance));
    }
    if job.guides {
        let [albedo, normal] = renderer
            .read_guides(ctx)?
            .context("the renderer accumulated no guides")?;
        let rgb = |p: &[f32; 4]| [p[0], p[1], p[2]];
        layers.push((image_io::ALBEDO, albedo.iter().map(rgb).collect()));
        let decoded = normal
            .iter()
            .map(|p| rgb(p).map(|v| 2.0 * v - 1.0))
            .collect();
        layers.push((image_io::NORMAL, decoded));
    }
    Ok(layers)
}

/// Copies `piece`'s pixels (`traced`, rows of its width) into `region`'s
/// (rows of the region's width); `piece` lies within `region`.
fn place<T: Copy>(region_pixels: &mut [T], region: Tile, piece: Tile, traced: &[T]) {
    let (region_width, _) = region.size();
    let (piece_width, _) = piece.size();
    for (row, line) in traced.chunks_exact(piece_width as usize).enumerate() {
        let y = piece.y0 - region.y0 + row as u32;
        let start = (y * region_width + piece.x0 - region.x0) as usize;
        region_pixels[start..start + line.len()].copy_from_slice(line);
    }
}

/// What the file of `planned` records of its render.
fn record_of(
    ctx: &GpuContext,
    renderer: &Renderer,
    job: &FinalRender,
    planned: &PlannedFrame,
    region: Tile,
) -> RenderRecord {
    RenderRecord {
        spp: renderer.accumulated_samples(),
        sample_offset: job.sample_offset,
        image: job.size,
        tile: region,
        frame: planned.frame,
        time: planned.time,
        scene: scene_hash(renderer.scene()),
        kernel: renderer.kernel().to_string(),
        adapter: ctx.describe(),
        version: env!("CARGO_PKG_VERSION").to_owned(),
    }
}

/// An image traced in pieces, put together.
struct Assembled<'a> {
    pixels: &'a [[f32; 4]],
    layers: &'a [(LayerName, Vec<[f32; 3]>)],
    record: &'a RenderRecord,
}

/// Writes an image traced in pieces: an EXR of its radiance (and its
/// layers), or a PNG shown by the display pass's CPU twin (exposure
/// metered over the whole image).
fn write_assembled(
    renderer: &Renderer,
    image: &Assembled,
    format: ImageFormat,
    planned: &PlannedFrame,
    observer: &mut dyn RenderObserver,
) -> Result<()> {
    let output = &planned.output;
    let (w, h) = image.record.tile.size();
    let record = image.record.to_text();
    let text = Some((RECORD_ATTRIBUTE, record.as_str()));
    match format {
        ImageFormat::Exr => {
            let layers: Vec<(LayerName, &[[f32; 3]])> =
                image.layers.iter().map(|(n, v)| (*n, &v[..])).collect();
            image_io::save_exr_layers(w, h, image.pixels, &layers, text, output)
        }
        ImageFormat::Png => {
            let (shown, metered) = cpu_display::show(
                image.pixels,
                (w, h),
                &renderer.scene().render.shown_display(),
            );
            if let Some(stops) = metered {
                observer.note(&format!(
                    "auto exposure: {stops:+.2} stops (over the whole image)"
                ));
            }
            image_io::save_png_with_text(&shown, text, output)
        }
    }
    .with_context(|| format!("saving {}", output.display()))?;
    observer.note(&format!("wrote {}", output.display()));
    Ok(())
}

/// The display settings `job` asks of the render on top of the scene's:
/// auto exposure (the scene's exposure becoming a compensation), and the
/// denoiser, whose guides the trace then accumulates (`denoise`, and
/// `guides` for the EXR's layers), on the lit image only.
fn show_as_asked(render: &mut RenderSettings, job: &FinalRender) -> Result<()> {
    if let Some(metering) = job.auto_exposure {
        render.display.auto_exposure = true;
        render.display.metering = metering;
    }
    if job.denoise.is_some() || job.guides {
        if render.view != View::Lit {
            let what = if job.denoise.is_some() {
                "--denoise filters the lit image"
            } else {
                "--guides records the lit image's first hits"
            };
            bail!("{what}, not the {} view", render.view.name());
        }
        // An EXR stays the raw accumulation unless `denoise_exr`.
        render.display.denoise = true;
    }
    if let Some(denoiser) = job.denoise {
        render.display.denoiser = denoiser;
    }
    render.display.denoise_quality = job.denoise_quality;
    Ok(())
}

/// The observer of one frame of a sequence: its progress counts the
/// frames before it.
struct InSequence<'a> {
    observer: &'a mut dyn RenderObserver,
    frame: u32,
    frames: u32,
}

impl RenderObserver for InSequence<'_> {
    fn note(&mut self, line: &str) {
        self.observer.note(line);
    }

    fn stage(&mut self, what: &str) {
        self.observer.stage(what);
    }

    fn progress(&mut self, progress: &Progress) -> ControlFlow<()> {
        self.observer.progress(&Progress {
            frame: self.frame,
            frames: self.frames,
            ..*progress
        })
    }
}

/// Traces the frame under way until `stop`; `Break` if cancelled.
fn trace_to_stop(
    ctx: &GpuContext,
    renderer: &mut Renderer,
    stop: Stop,
    observer: &mut dyn RenderObserver,
) -> Result<ControlFlow<()>> {
    Ok(match stop {
        Stop::Samples(spp) => accumulate(ctx, renderer, spp, observer)?,
        Stop::TargetError { target, max_spp } => {
            let (flow, reached) = accumulate_to_error(ctx, renderer, target, max_spp, observer)?;
            if flow.is_continue() {
                observer.note(&describe_error(renderer, target, reached));
            }
            flow
        }
    })
}

/// Fails, naming the file that is then not written, if the device
/// reported an error no scope caught while the image was traced: its
/// pixels cannot be trusted (issue 47; `gpu::context::uncaptured`).
fn refuse_gpu_errors(ctx: &GpuContext, output: &std::path::Path) -> Result<()> {
    ctx.uncaptured
        .check()
        .with_context(|| format!("{} is not written", output.display()))
}

/// Writes the frame traced to its file.
fn write_image(
    ctx: &GpuContext,
    renderer: &mut Renderer,
    job: &FinalRender,
    format: ImageFormat,
    planned: &PlannedFrame,
    observer: &mut dyn RenderObserver,
) -> Result<()> {
    let output = &planned.output;
    // EXR output is the radiance, unscaled (as Blender and Mitsuba write
    // it): only a PNG is exposed. The exposure is reported either way, and
    // for an EXR the note says it was not applied.
    if renderer.scene().render.shown_display().auto_exposure {
        if format == ImageFormat::Exr {
            observer.note(&format!(
                "note: auto exposure does not scale {}: an EXR holds the unscaled radiance; \
                 the exposure below is for a viewer or compositor to apply",
                output.display()
            ));
        }
        observer.note(&describe_auto_exposure(ctx, renderer)?);
    }
    let record = record_of(ctx, renderer, job, planned, Tile::whole(job.size)).to_text();
    let text = Some((RECORD_ATTRIBUTE, record.as_str()));
    refuse_gpu_errors(ctx, output)?;
    match format {
        ImageFormat::Png => {
            if let Some(running) = renderer.finish_denoise(ctx)? {
                observer.note(&format!("denoised by {}", running.describe()));
            }
            let image = renderer.read_display(ctx)?;
            image_io::save_png_with_text(&image, text, output)
        }
        ImageFormat::Exr => {
            let (w, h, pixels) = if job.denoise_exr {
                if let Some(running) = renderer.finish_denoise(ctx)? {
                    observer.note(&format!("denoised by {}", running.describe()));
                }
                renderer.read_denoised(ctx)?
            } else {
                if renderer.scene().render.display.denoise && !job.guides {
                    observer.note("note: the EXR is the raw accumulation, not denoised");
                }
                renderer.read_radiance(ctx)?
            };
            let layers = read_layers(ctx, renderer, job)?;
            let layers: Vec<(LayerName, &[[f32; 3]])> =
                layers.iter().map(|(n, v)| (*n, &v[..])).collect();
            image_io::save_exr_layers(w, h, &pixels, &layers, text, output)
        }
    }
    .with_context(|| format!("saving {}", output.display()))?;
    observer.note(&format!("wrote {}", output.display()));
    Ok(())
}

/// The animated file of a sequence, from its frames' PNG files, if asked.
fn assemble(
    animation: Option<&PathBuf>,
    frames: &[PlannedFrame],
    job: &FinalRender,
    observer: &mut dyn RenderObserver,
) -> Result<Outcome> {
    let (Some(path), Timing::Sequence { fps, .. }) = (animation, &job.timing) else {
        return Ok(Outcome::Written);
    };
    let images = frames
        .iter()
        .map(|f| {
            let bytes =
                marbre_core::capped_read::read_capped(&f.output, marbre_core::capped_read::IMAGE)
                    .with_context(|| format!("reading the frame {}", f.output.display()))?;
            Ok(
                image::load_from_memory_with_format(&bytes, image::ImageFormat::Png)
                    .with_context(|| format!("decoding the frame {}", f.output.display()))?
                    .to_rgba8(),
            )
        })
        .collect::<Result<Vec<_>>>()?;
    animated_image::save_animation(&images, *fps, path)?;
    observer.note(&format!(
        "wrote {} ({} frames at {fps} fps)",
        path.display(),
        images.len()
    ));
    Ok(Outcome::Written)
}

/// Traces `spp` samples per pixel, a frame at a time, each waited for;
/// `Break` if the observer cancelled.
fn accumulate(
    ctx: &GpuContext,
    renderer: &mut Renderer,
    spp: u32,
    observer: &mut dyn RenderObserver,
) -> Result<ControlFlow<()>> {
    while renderer.accumulated_samples() < spp {
        // The last round traces only the samples left: `--spp` is exact.
        renderer.limit_round_samples(spp - renderer.accumulated_samples());
        trace_frame(ctx, renderer)?;
        let progress = Progress {
            samples: renderer.accumulated_samples(),
            max_samples: spp,
            relative_error: None,
            frame: 0,
            frames: 1,
        };
        if observer.progress(&progress).is_break() {
            return Ok(ControlFlow::Break(()));
        }
    }
    Ok(ControlFlow::Continue(()))
}

/// How often the error is measured while rendering to a target: each
/// measurement waits for the GPU, so not after every frame of a fast one.
const ERROR_CHECK_INTERVAL: Duration = Duration::from_millis(250);

/// Traces until the estimated relative error is at most `target`, or
/// `max_spp` samples per pixel, or the observer cancels; returns the last
/// estimate.
fn accumulate_to_error(
    ctx: &GpuContext,
    renderer: &mut Renderer,
    target: f64,
    max_spp: u32,
    observer: &mut dyn RenderObserver,
) -> Result<(ControlFlow<()>, Option<ErrorEstimate>)> {
    let mut last_check: Option<Instant> = None;
    let mut relative_error = None;
    while renderer.accumulated_samples() < max_spp {
        // Waiting for each frame keeps the GPU no further ahead than the
        // check: a target reached is not overshot by a queue of frames.
        renderer.limit_round_samples(max_spp - renderer.accumulated_samples());
        trace_frame(ctx, renderer)?;
        let due = last_check.is_none_or(|t| t.elapsed() >= ERROR_CHECK_INTERVAL);
        if due {
            last_check = Some(Instant::now());
            if let Some(e) = renderer.estimate_error(ctx)? {
                relative_error = Some(e.relative);
                if e.relative <= target {
                    return Ok((ControlFlow::Continue(()), Some(e)));
                }
            }
        }
        let progress = Progress {
            samples: renderer.accumulated_samples(),
            max_samples: max_spp,
            relative_error,
            frame: 0,
            frames: 1,
        };
        if observer.progress(&progress).is_break() {
            return Ok((ControlFlow::Break(()), None));
        }
    }
    // The cap: measure the final image.
    Ok((ControlFlow::Continue(()), renderer.estimate_error(ctx)?))
}

/// Where the error ended, against the target.
fn describe_error(renderer: &Renderer, target: f64, estimate: Option<ErrorEstimate>) -> String {
    let spp = renderer.accumulated_samples();
    let seconds = renderer.accumulation_time().as_secs_f64();
    match estimate {
        Some(e) if e.relative <= target => format!(
            "target reached: estimated relative error {:.3} % (RMSE {:.5}) at {spp} spp in {seconds:.1} s",
            100.0 * e.relative,
            e.rmse
        ),
        Some(e) => format!(
            "target not reached: estimated relative error {:.3} % (RMSE {:.5}) at the cap of {spp} spp \
             ({seconds:.1} s); raise the cap of samples per pixel (--spp), about {:.0} s more would do",
            100.0 * e.relative,
            e.rmse,
            e.seconds_to(target)
        ),
        None => format!("no error estimate: it needs two frames ({spp} spp is too few)"),
    }
}

/// The exposure the PNG gets: the GPU's metering (what the display pass
/// applies) and the CPU twin's average over the whole image.
fn describe_auto_exposure(ctx: &GpuContext, renderer: &mut Renderer) -> Result<String> {
    let metered = renderer.metering(ctx)?;
    let (_, _, pixels) = renderer.read_radiance(ctx)?;
    let display = renderer.scene().render.display;
    let compensation = display.exposure;
    let (what, metered_value, whole) = match display.metering {
        Metering::Key => (
            "log-average",
            metered.log_average,
            auto_exposure::log_average_luminance(&pixels),
        ),
        Metering::MassalRms => (
            "Massal's RMS",
            metered.rms,
            auto_exposure::rms_luminance(&pixels),
        ),
    };
    Ok(format!(
        "auto exposure: {:+.2} stops{} ({what} luminance {:.4} over {} metered texels; \
         {:.4} over the whole image)",
        metered.stops_for(display.metering),
        if compensation == 0.0 {
            String::new()
        } else {
            format!(", {compensation:+.2} stops of compensation on top")
        },
        metered_value,
        metered.count,
        whole,
    ))
}
