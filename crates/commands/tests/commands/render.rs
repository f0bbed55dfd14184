//! `marbre render` and the viewer's Render dialog run one function,
//! `final_render::render_to_file`: from the command's flags (`render::run`)
//! and from a scene already in memory (`final_render::snapshot`, what the
//! dialog hands its thread) the same settings write the same bytes. A
//! cancelled render and one into a missing folder write nothing.

use marbre_commands::render::{self, RenderArgs};
use marbre_core::scene::{DenoiseQuality, Denoiser};
use marbre_render::final_render::{
    FinalRender, Outcome, Progress, RenderObserver, Stop, render_to_file, snapshot,
};
use marbre_render::gpu::KernelChoice;
use marbre_render::gpu::testing::gpu_or_skip;
use marbre_render::session::load_scene;
use std::ops::ControlFlow;
use std::path::{Path, PathBuf};

/// A preset with an environment map and image textures: everything a
/// snapshot must carry or load again.
fn preset() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../presets/images.ron")
}

/// A scratch folder, removed when the test passes.
struct Scratch(PathBuf);

impl Scratch {
    fn new(name: &str) -> Self {
        let dir = std::env::temp_dir().join(format!("marbre-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        Scratch(dir)
    }

    fn files(&self) -> Vec<String> {
        let mut names: Vec<String> = std::fs::read_dir(&self.0)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        names
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        if !std::thread::panicking() {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }
}

/// Counts progress reports and cancels after `cancel_after` of them.
struct Counter {
    reports: Vec<Progress>,
    cancel_after: Option<usize>,
}

impl RenderObserver for Counter {
    fn note(&mut self, _line: &str) {}

    fn progress(&mut self, progress: &Progress) -> ControlFlow<()> {
        self.reports.push(*progress);
        match self.cancel_after {
            Some(n) if self.reports.len() >= n => ControlFlow::Break(()),
            _ => ControlFlow::Continue(()),
        }
    }
}

const SIZE: (u32, u32) = (40, 24);
const SPP: u32 = 4;

fn cli_args(output: PathBuf, auto_exposure: bool) -> RenderArgs {
    RenderArgs {
        preset: preset(),
        env: None,
        spp: Some(SPP),
        target_error: None,
        size: SIZE,
        output,
        auto_exposure: auto_exposure.then_some(render::MeteringArg::Key),
        kernel: KernelChoice::Fragment,
        view: None,
        light_points: None,
        strategy: None,
        denoise: None,
        denoise_quality: DenoiseQuality::High,
        denoise_exr: false,
        allow_placeholders: false,
        frames: None,
        fps: None,
        time: None,
        overwrite: false,
        animation: None,
        sample_offset: 0,
        tile: None,
        tiles: None,
        tile_index: None,
        max_tile_pixels: marbre_render::final_render::DEFAULT_MAX_TILE_PIXELS,
        moments: false,
        guides: false,
    }
}

fn dialog_job(output: PathBuf, auto_exposure: bool) -> FinalRender {
    FinalRender {
        size: SIZE,
        stop: Stop::Samples(SPP),
        auto_exposure: auto_exposure.then_some(marbre_core::scene::Metering::Key),
        kernel: KernelChoice::Fragment,
        output,
        denoise: None,
        denoise_quality: DenoiseQuality::High,
        denoise_exr: false,
        allow_placeholders: false,
        timing: Default::default(),
        sample_offset: 0,
        tile: None,
        max_tile_pixels: marbre_render::final_render::DEFAULT_MAX_TILE_PIXELS,
        moments: false,
        guides: false,
    }
}

/// The dialog's way in: the scene as loaded, handed over in memory with
/// its images, the environment read again.
fn render_as_the_dialog(job: &FinalRender, observer: &mut Counter) -> Outcome {
    let ctx = gpu_or_skip("render_as_the_dialog").expect("checked by the caller");
    let loaded = load_scene(&preset(), None).unwrap();
    let snap = snapshot(loaded.scene, loaded.images).unwrap();
    assert!(snap.env.is_some(), "the snapshot loads the preset's sky");
    render_to_file(&ctx, snap, job, observer).unwrap()
}

#[test]
fn the_command_and_the_dialog_write_the_same_bytes() {
    if gpu_or_skip("the_command_and_the_dialog_write_the_same_bytes").is_none() {
        return;
    }
    let dir = Scratch::new("render-same-bytes");
    for (name, auto_exposure) in [("a.png", false), ("b.png", true), ("c.exr", false)] {
        let cli = dir.0.join(format!("cli-{name}"));
        let dialog = dir.0.join(format!("dialog-{name}"));
        render::run(&cli_args(cli.clone(), auto_exposure)).unwrap();
        let mut counter = Counter {
            reports: Vec::new(),
            cancel_after: None,
        };
        let outcome =
            render_as_the_dialog(&dialog_job(dialog.clone(), auto_exposure), &mut counter);
        assert_eq!(outcome, Outcome::Written);
        let (a, b) = (
            std::fs::read(&cli).unwrap(),
            std::fs::read(&dialog).unwrap(),
        );
        assert!(
            a == b,
            "{name}: the dialog's file differs from the command's"
        );
        // A frame's worth of samples per report, ending at the count asked.
        let last = counter.reports.last().expect("progress was reported");
        assert_eq!((last.samples, last.max_samples), (SPP, SPP));
        assert_eq!(last.fraction(), 1.0);
    }
    // Not a vacuous equality: the image is not uniform.
    let png = image::open(dir.0.join("cli-a.png")).unwrap().to_rgb8();
    let first = *png.get_pixel(0, 0);
    assert!(png.pixels().any(|p| *p != first), "a uniform image");
    assert_eq!(png.dimensions(), SIZE);
}

#[test]
fn a_cancelled_render_writes_nothing() {
    if gpu_or_skip("a_cancelled_render_writes_nothing").is_none() {
        return;
    }
    let dir = Scratch::new("render-cancel");
    let output = dir.0.join("cancelled.png");
    let mut job = dialog_job(output.clone(), false);
    job.stop = Stop::Samples(1000);
    let mut counter = Counter {
        reports: Vec::new(),
        cancel_after: Some(2),
    };
    assert_eq!(render_as_the_dialog(&job, &mut counter), Outcome::Cancelled);
    assert_eq!(counter.reports.len(), 2, "it stopped at the second report");
    assert!(counter.reports[1].samples < 1000);
    assert_eq!(dir.files(), Vec::<String>::new(), "no file, no temporary");
}

#[test]
fn a_missing_folder_is_named_before_rendering() {
    let Some(ctx) = gpu_or_skip("a_missing_folder_is_named_before_rendering") else {
        return;
    };
    let dir = Scratch::new("render-missing-folder");
    let output = dir.0.join("no-such-folder/out.png");
    let loaded = load_scene(&preset(), None).unwrap();
    let mut counter = Counter {
        reports: Vec::new(),
        cancel_after: None,
    };
    let err = render_to_file(
        &ctx,
        loaded,
        &dialog_job(output.clone(), false),
        &mut counter,
    )
    .unwrap_err();
    let message = format!("{err:#}");
    assert!(
        message.contains(&output.display().to_string()) && message.contains("does not exist"),
        "{message}"
    );
    assert!(counter.reports.is_empty(), "nothing was traced");
    assert_eq!(dir.files(), Vec::<String>::new(), "no folder was made");
}

/// A GPU error that no error scope caught (here an invalid buffer made on
/// the render's device beforehand) no longer panics the process through
/// wgpu's default handler: the render fails, naming the file it does not
/// write, and writes nothing, since its pixels cannot be trusted
/// (issue 47).
#[test]
fn an_uncaptured_gpu_error_fails_the_render_and_writes_nothing() {
    let Some(ctx) = gpu_or_skip("an_uncaptured_gpu_error_fails_the_render_and_writes_nothing")
    else {
        return;
    };
    let dir = Scratch::new("render-uncaptured");
    let output = dir.0.join("out.png");
    let loaded = load_scene(&preset(), None).unwrap();
    let _invalid = ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("invalid on purpose"),
        size: 16,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::STORAGE,
        mapped_at_creation: false,
    });
    let mut counter = Counter {
        reports: Vec::new(),
        cancel_after: None,
    };
    let err = render_to_file(
        &ctx,
        loaded,
        &dialog_job(output.clone(), false),
        &mut counter,
    )
    .unwrap_err();
    let message = format!("{err:#}");
    assert!(
        message.contains(&format!("{} is not written", output.display()))
            && message.contains("the GPU reported 1 error(s)"),
        "{message}"
    );
    assert_eq!(dir.files(), Vec::<String>::new(), "nothing was written");
}

/// `--denoise` filters the PNG; the EXR stays the raw accumulation (the
/// same bytes as without the flag) unless `--denoise-exr` asks for the
/// filtered one, which then differs.
#[test]
fn denoise_filters_the_png_and_the_exr_only_when_asked() {
    if gpu_or_skip("denoise_filters_the_png_and_the_exr_only_when_asked").is_none() {
        return;
    }
    let dir = Scratch::new("render-denoise");
    let run = |name: &str, denoise: bool, denoise_exr: bool| {
        let output = dir.0.join(name);
        render::run(&RenderArgs {
            denoise: denoise.then_some(Denoiser::Atrous),
            denoise_exr,
            ..cli_args(output.clone(), false)
        })
        .unwrap();
        std::fs::read(output).unwrap()
    };
    assert_ne!(
        run("raw.png", false, false),
        run("denoised.png", true, false)
    );
    // The pixels (the render record is the same: the display's settings
    // are not part of the traced scene's name).
    let pixels = |bytes: Vec<u8>| {
        let path = dir.0.join("read.exr");
        std::fs::write(&path, bytes).unwrap();
        marbre_core::image_decode::decode_file(
            &path,
            marbre_core::image_decode::IntegerDecode::Linear,
        )
        .unwrap()
        .pixels
    };
    let raw_exr = run("raw.exr", false, false);
    assert_eq!(raw_exr, run("asked-png-only.exr", true, false));
    assert_ne!(pixels(raw_exr), pixels(run("denoised.exr", true, true)));
}

/// A preset whose image texture is missing renders a placeholder in the
/// viewer, but `marbre render` fails naming the file and writes nothing
/// (a script or a farm would take the image as good), unless
/// `--allow-placeholders` is given.
#[test]
fn a_missing_image_fails_the_render_unless_placeholders_are_allowed() {
    if gpu_or_skip("a_missing_image_fails_the_render_unless_placeholders_are_allowed").is_none() {
        return;
    }
    let dir = Scratch::new("render-placeholder");
    let missing = dir.0.join("missing.png");
    let sky = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../envmaps/sky.exr");
    let text = std::fs::read_to_string(preset())
        .unwrap()
        .replace("images/uv_grid.png", missing.to_str().unwrap())
        .replace("../envmaps/sky.exr", sky.to_str().unwrap());
    let broken = dir.0.join("broken.ron");
    std::fs::write(&broken, text).unwrap();
    let output = dir.0.join("out.png");
    let args = RenderArgs {
        preset: broken,
        ..cli_args(output.clone(), false)
    };
    let error = format!("{:#}", render::run(&args).unwrap_err());
    assert!(
        error.contains(missing.to_str().unwrap()) && error.contains("--allow-placeholders"),
        "{error}"
    );
    assert_eq!(dir.files(), ["broken.ron"], "nothing written");
    render::run(&RenderArgs {
        allow_placeholders: true,
        ..args
    })
    .unwrap();
    assert!(output.is_file());
}

/// The largest size the command accepts, 16384 × 16384: on an adapter
/// that cannot hold its images (lavapipe, whose largest allocation is under
/// one 4 GiB target) it fails with one line before tracing, where wgpu's
/// out-of-memory error used to panic; where it fits, it renders.
#[test]
fn the_largest_size_renders_or_fails_before_tracing() {
    if gpu_or_skip("the_largest_size_renders_or_fails_before_tracing").is_none() {
        return;
    }
    let dir = Scratch::new("render-largest");
    let output = dir.0.join("huge.png");
    // The cheapest scene (a grey ball under a constant sky, one bounce):
    // 268 M pixels of `images.ron` took lavapipe about five minutes.
    let ball = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/e2e/start.ron");
    let result = render::run(&RenderArgs {
        size: (16384, 16384),
        spp: Some(1),
        preset: ball,
        ..cli_args(output.clone(), false)
    });
    match result {
        Ok(()) => assert_eq!(image::image_dimensions(&output).unwrap(), (16384, 16384)),
        Err(e) => {
            let message = format!("{e:#}");
            assert!(
                message.contains("16384 × 16384") && message.contains("nothing was traced"),
                "{message}"
            );
            assert!(dir.files().is_empty(), "{:?}", dir.files());
        }
    }
}
