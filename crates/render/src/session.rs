//! Loading a preset and its environment into a ready renderer: shared by the
//! viewer, `render` and `bench`, so they all see the same scene.

use crate::gpu::kernel;
use crate::gpu::{GpuContext, Kernel, KernelChoice, Renderer};
use anyhow::{Context, Result};
use marbre_core::cubemap;
use marbre_core::envmap::{EnvImage, EnvLoad};
use marbre_core::preset;
use marbre_core::scene::{EnvSource, LdrImages, Scene};
use marbre_core::texture::ImageSet;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

/// The preset the viewer opens when none is named.
pub const DEFAULT_PRESET: &str = "presets/default.ron";

/// A preset's scene, with `--env` applied, and its loaded environment image
/// and image textures.
#[derive(Clone)]
pub struct LoadedScene {
    pub scene: Scene,
    pub env: Option<EnvImage>,
    pub images: ImageSet,
    /// Clamped values and sanitised pixels, for the user to see.
    pub notes: Vec<String>,
    /// The files that could not be read and were replaced (an image by a
    /// placeholder, a material library by grey), each with a note: the
    /// viewer shows the scene anyway, a command line render refuses it
    /// unless told otherwise.
    pub substitutes: Vec<PathBuf>,
}

impl LoadedScene {
    /// Nothing but the background: what the viewer draws while the scene
    /// it opens on loads.
    pub fn placeholder() -> Self {
        Self {
            scene: Scene::default(),
            env: None,
            images: ImageSet::empty(),
            notes: Vec::new(),
            substitutes: Vec::new(),
        }
    }
}

pub fn load_scene(preset_path: &Path, env_override: Option<&Path>) -> Result<LoadedScene> {
    load_scene_reporting(preset_path, env_override, &mut |_| {})
}

/// The steps of loading a preset, in order, for a progress bar.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LoadStage {
    Preset,
    Environment,
    Meshes,
    Images,
}

impl LoadStage {
    pub const COUNT: usize = 4;

    pub fn label(self) -> &'static str {
        match self {
            LoadStage::Preset => "reading the preset",
            LoadStage::Environment => "loading the environment map",
            LoadStage::Meshes => "loading the OBJ meshes",
            LoadStage::Images => "loading the image textures",
        }
    }

    pub fn index(self) -> usize {
        self as usize
    }
}

/// [`load_scene`], calling `report` as each stage starts.
pub fn load_scene_reporting(
    preset_path: &Path,
    env_override: Option<&Path>,
    report: &mut dyn FnMut(LoadStage),
) -> Result<LoadedScene> {
    report(LoadStage::Preset);
    let loaded = preset::load(preset_path)?;
    let mut scene = loaded.preset.scene;
    if let Some(env) = env_override {
        scene.environment.source = EnvSource::LatLong {
            path: env.to_owned(),
        };
    }
    prepare_scene_reporting(scene, loaded.notes, report)
}

/// Loads what `scene` reads (its environment, meshes and images) and
/// clamps what they bring, adding to `notes`: a scene built in code gets
/// exactly what a preset's would.
pub fn prepare_scene(scene: Scene, notes: Vec<String>) -> Result<LoadedScene> {
    prepare_scene_reporting(scene, notes, &mut |_| {})
}

/// The scene [`marbre_core::obj_scene`] makes around the OBJ file at
/// `obj_path` (framed for an image of width / height `aspect`), with
/// `env_override` in place of its environment if given, and what it reads
/// loaded: what the viewer opens from an OBJ file. `report` is called as
/// each stage starts (the meshes first: there is no preset to read).
pub fn load_obj_reporting(
    obj_path: &Path,
    aspect: f32,
    env_override: Option<&Path>,
    report: &mut dyn FnMut(LoadStage),
) -> Result<LoadedScene> {
    report(LoadStage::Meshes);
    let opened = marbre_core::obj_scene::scene_from_obj(obj_path, aspect)?;
    let mut scene = opened.scene;
    if let Some(env) = env_override {
        scene.environment.source = EnvSource::LatLong {
            path: env.to_owned(),
        };
    }
    let mut notes = opened.notes;
    let env = load_scene_environment(&scene, &mut notes)?;
    finish_scene(scene, env, notes, opened.substitutes, report)
}

fn prepare_scene_reporting(
    mut scene: Scene,
    mut notes: Vec<String>,
    report: &mut dyn FnMut(LoadStage),
) -> Result<LoadedScene> {
    report(LoadStage::Environment);
    let env = load_scene_environment(&scene, &mut notes)?;
    report(LoadStage::Meshes);
    let substitutes = marbre_core::obj_loader::load_meshes(&mut scene, &mut notes)?;
    finish_scene(scene, env, notes, substitutes, report)
}

/// The environment image `scene` names, its notes added to `notes`.
fn load_scene_environment(scene: &Scene, notes: &mut Vec<String>) -> Result<Option<EnvImage>> {
    // A cube map arrives resampled to lat-long (`cubemap::load_source`).
    Ok(
        cubemap::load_source(&scene.environment.source, scene.environment.ldr_images)?.map(|l| {
            notes.extend(l.notes);
            l.image
        }),
    )
}

/// The last stages of a load, once the meshes are in: clamping what they
/// brought, and the images; `substitutes` are the files already replaced.
fn finish_scene(
    mut scene: Scene,
    env: Option<EnvImage>,
    mut notes: Vec<String>,
    mut substitutes: Vec<PathBuf>,
    report: &mut dyn FnMut(LoadStage),
) -> Result<LoadedScene> {
    // The meshes' materials arrive with their files: clamp them as the
    // preset's own were. A warning that changes nothing (a polygon's flat
    // frame) comes again: it is said once.
    for note in scene.sanitize() {
        if !notes.contains(&note) {
            notes.push(note);
        }
    }
    report(LoadStage::Images);
    let images = load_images(&scene, &mut notes)?;
    substitutes.extend_from_slice(images.placeholders());
    Ok(LoadedScene {
        scene,
        env,
        images,
        notes,
        substitutes,
    })
}

impl LoadedScene {
    /// Shrinks the environment image to fit a texture of at most `max_side`
    /// texels a side (the GPU's `max_texture_dimension_2d`), with a note
    /// when it had to.
    pub fn fit_environment(mut self, max_side: u32) -> LoadedScene {
        if let Some(image) = self.env.take() {
            let fitted = EnvLoad {
                image,
                notes: Vec::new(),
            }
            .fit_within(max_side, &source_name(&self.scene.environment.source));
            self.notes.extend(fitted.notes);
            self.env = Some(fitted.image);
        }
        self
    }
}

/// The environment `source` stands for, as `cubemap::load_source` loads it
/// (8- and 16-bit files read as `ldr` says),
/// shrunk to fit a texture of at most `max_side` texels a side (the GPU's
/// `max_texture_dimension_2d`, [`max_texture_side`]) with a note when it
/// had to.
pub fn load_environment(
    source: &EnvSource,
    ldr: LdrImages,
    max_side: u32,
) -> Result<Option<EnvLoad>, cubemap::CubeMapError> {
    let name = source_name(source);
    Ok(cubemap::load_source(source, ldr)?.map(|l| l.fit_within(max_side, &name)))
}

/// The largest texture side `ctx`'s device takes.
pub fn max_texture_side(ctx: &GpuContext) -> u32 {
    ctx.device.limits().max_texture_dimension_2d
}

/// The files of an environment source, for notes.
fn source_name(source: &EnvSource) -> String {
    source
        .paths()
        .iter()
        .map(|p| p.display().to_string())
        .collect::<Vec<_>>()
        .join(", ")
}

/// The largest image atlas the renderer asks for: wgpu's default limit of
/// `max_texture_dimension_2d`, which every adapter it runs on offers.
pub const ATLAS_MAX_SIDE: u32 = 8192;

/// The image textures of `scene`. An unreadable file becomes a placeholder
/// with a note; only images too many to fit on the GPU are an error.
pub fn load_images(scene: &Scene, notes: &mut Vec<String>) -> Result<ImageSet> {
    Ok(ImageSet::load(
        &scene.image_sources(),
        ATLAS_MAX_SIDE,
        notes,
    )?)
}

/// A renderer for a loaded scene, with its environment and images,
/// tracing with the fragment kernel.
pub fn renderer_for(ctx: &GpuContext, loaded: &LoadedScene, size: (u32, u32)) -> Result<Renderer> {
    renderer_with(ctx, loaded, size, Kernel::Fragment)
}

/// [`renderer_for`], tracing with `kernel`.
pub fn renderer_with(
    ctx: &GpuContext,
    loaded: &LoadedScene,
    size: (u32, u32),
    kernel: Kernel,
) -> Result<Renderer> {
    let mut renderer =
        Renderer::with_kernel(ctx, &loaded.scene, loaded.env.as_ref(), size, kernel)?;
    renderer.set_images(ctx, loaded.images.clone())?;
    Ok(renderer)
}

/// The largest size `auto` times the kernels at: the cost per pixel is
/// what decides, and a slow adapter must not hold the start for long.
const KERNEL_TIMING_SIZE: (u32, u32) = (320, 180);

/// Frames each kernel is timed for, after two of warm-up.
const KERNEL_TIMING_FRAMES: u32 = 9;

/// The median ms of one whole round of each kernel on one scene, timed
/// interleaved (a frame of one, then of the other), so that a machine
/// busy with something else slows both alike.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KernelTimings {
    pub fragment_ms: f64,
    /// Where the adapter runs the compute kernel.
    pub compute_ms: Option<f64>,
    /// Where the CPU kernel traces the scene (`cpu_kernel::support`).
    pub cpu_ms: Option<f64>,
    pub size: (u32, u32),
}

impl KernelTimings {
    /// The fastest kernel timed ([`kernel::fastest`]).
    pub fn faster(&self) -> Kernel {
        kernel::fastest(self.fragment_ms, &self.others())
    }

    /// The milliseconds a frame of `kernel` took (NaN if not timed).
    pub fn ms(&self, kernel: Kernel) -> f64 {
        match kernel {
            Kernel::Fragment => self.fragment_ms,
            Kernel::Compute => self.compute_ms.unwrap_or(f64::NAN),
            Kernel::Cpu => self.cpu_ms.unwrap_or(f64::NAN),
        }
    }

    fn others(&self) -> Vec<(Kernel, f64)> {
        [
            (Kernel::Compute, self.compute_ms),
            (Kernel::Cpu, self.cpu_ms),
        ]
        .into_iter()
        .filter_map(|(k, ms)| ms.map(|ms| (k, ms)))
        .collect()
    }
}

impl std::fmt::Display for KernelTimings {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "fragment {:.2} ms", self.fragment_ms)?;
        for (kernel, ms) in self.others() {
            write!(f, ", {kernel} {ms:.2} ms")?;
        }
        write!(f, " per frame at {}x{}", self.size.0, self.size.1)
    }
}

/// Times every kernel the adapter runs and the CPU kernel where it traces the scene, on `loaded` at `size` (at most
/// [`KERNEL_TIMING_SIZE`]): see [`KernelTimings`]. `cancel` is looked at
/// between the steps that take long on a CPU adapter (each kernel's
/// pipeline build and first draw): once it is set, the timing stops there
/// with an error, so that a viewer closing meanwhile waits for one step
/// at most.
pub fn time_kernels(
    ctx: &GpuContext,
    loaded: &LoadedScene,
    size: (u32, u32),
    cancel: &AtomicBool,
) -> Result<KernelTimings> {
    let size = (
        size.0.clamp(1, KERNEL_TIMING_SIZE.0),
        size.1.clamp(1, KERNEL_TIMING_SIZE.1),
    );
    let go_on = || {
        anyhow::ensure!(
            !cancel.load(Ordering::Relaxed),
            "the kernel timing was cancelled"
        );
        Ok(())
    };
    let mut kernels = vec![Kernel::Fragment];
    if kernel::compute_support(ctx).is_ok() {
        kernels.push(Kernel::Compute);
    }
    if crate::cpu_kernel::support(&loaded.scene).is_ok() {
        kernels.push(Kernel::Cpu);
    }
    let mut renderers = Vec::new();
    for &kernel in &kernels {
        let mut renderer = renderer_with(ctx, loaded, size, kernel)?;
        go_on()?;
        trace_frame(ctx, &mut renderer)?;
        go_on()?;
        renderers.push(renderer);
    }
    // Each kernel drew its first frame above (the shader compile, on a CPU
    // adapter): one more untimed frame each makes the two of warm-up.
    let mut timed: Vec<&mut Renderer> = renderers.iter_mut().collect();
    let ms = time_interleaved(ctx, &mut timed, 1, KERNEL_TIMING_FRAMES)?;
    let of = |kernel| kernels.iter().position(|&k| k == kernel).map(|i| ms[i]);
    Ok(KernelTimings {
        fragment_ms: ms[0],
        compute_ms: of(Kernel::Compute),
        cpu_ms: of(Kernel::Cpu),
        size,
    })
}

/// The median wall-clock time per frame of each renderer, each frame waited
/// for (trace plus GPU sync), after `warm_up` untimed frames each, the
/// renderers' frames interleaved: a round is one frame of each, in turn,
/// the order reversed every other round. A machine busy with something
/// else then slows them all alike, so their ratios hold even when the times
/// drift. The median, not the mean: on a shared CPU (lavapipe) a few frames
/// stall for reasons unrelated to the shader.
pub fn time_interleaved(
    ctx: &GpuContext,
    renderers: &mut [&mut Renderer],
    warm_up: u32,
    frames: u32,
) -> Result<Vec<f64>> {
    for _ in 0..warm_up {
        for renderer in renderers.iter_mut() {
            trace_frame(ctx, renderer)?;
        }
    }
    let mut times = vec![Vec::with_capacity(frames as usize); renderers.len()];
    for round in 0..frames.max(1) {
        let mut order: Vec<usize> = (0..renderers.len()).collect();
        if round % 2 == 1 {
            order.reverse();
        }
        for i in order {
            let start = web_time::Instant::now();
            trace_frame(ctx, renderers[i])?;
            times[i].push(start.elapsed().as_secs_f64() * 1000.0);
        }
    }
    Ok(times
        .into_iter()
        .map(|mut t| {
            t.sort_by(f64::total_cmp);
            t[t.len() / 2]
        })
        .collect())
}

/// The kernel `choice` means for `loaded` on `ctx`: the one named (an
/// error if the adapter cannot run it), or for `auto` the faster on this
/// scene, with the timings that decided (the fragment kernel, untimed,
/// where the compute kernel cannot run).
pub fn pick_kernel(
    ctx: &GpuContext,
    loaded: &LoadedScene,
    size: (u32, u32),
    choice: KernelChoice,
) -> Result<(Kernel, Option<KernelTimings>)> {
    let kernel = kernel::resolve(ctx, choice)?.for_scene(&loaded.scene);
    let only_fragment =
        kernel == Kernel::Fragment && crate::cpu_kernel::support(&loaded.scene).is_err();
    if choice != KernelChoice::Auto || only_fragment {
        return Ok((kernel, None));
    }
    let timings = time_kernels(ctx, loaded, size, &AtomicBool::new(false))?;
    Ok((timings.faster(), Some(timings)))
}

/// One line on how the kernel was chosen for `scene`, for the commands'
/// output: the timings `auto` went by, or why the CPU kernel, asked for,
/// left the scene to the fragment kernel.
pub fn describe_pick(
    kernel: Kernel,
    timings: Option<&KernelTimings>,
    choice: KernelChoice,
    scene: &Scene,
) -> String {
    match (timings, crate::cpu_kernel::support(scene)) {
        (Some(t), _) => format!("kernel: {kernel} (auto: {t})"),
        (None, Err(why)) if choice == KernelChoice::Cpu => {
            format!("kernel: {kernel} ({why}: the fragment kernel traces this scene)")
        }
        _ => format!("kernel: {kernel}"),
    }
}

/// `path`, or the default preset.
pub fn preset_or_default(path: Option<&Path>) -> PathBuf {
    path.map_or_else(|| PathBuf::from(DEFAULT_PRESET), Path::to_owned)
}

/// Traces `spp` samples per pixel (in frames of the preset's samples per frame)
/// and waits for the GPU; `progress` is called after each frame.
pub fn accumulate(
    ctx: &GpuContext,
    renderer: &mut Renderer,
    spp: u32,
    mut progress: impl FnMut(u32),
) -> Result<()> {
    while renderer.accumulated_samples() < spp {
        trace_frame(ctx, renderer)?;
        progress(renderer.accumulated_samples());
    }
    Ok(())
}

/// Traces one frame and waits for the GPU, so that the caller is never
/// more than a frame ahead of it.
pub fn trace_frame(ctx: &GpuContext, renderer: &mut Renderer) -> Result<()> {
    let mut encoder = ctx.device.create_command_encoder(&Default::default());
    renderer.trace(ctx, &mut encoder, None);
    ctx.queue.submit([encoder.finish()]);
    ctx.device
        .poll(wgpu::PollType::wait_indefinitely())
        .context("waiting for the GPU")?;
    Ok(())
}
