//! `marbre render --frames`: a keyed animation traced frame by frame, on
//! the GPU (lavapipe here). The keyed checker's edge lands on the pixel
//! the camera's projection puts it at in each frame; a stopped sequence
//! resumes where it stopped, tracing the same samples; an animated file
//! holds every frame; bad timing is refused before anything is written.

use clap::Parser;
use marbre_commands::render::{self, RenderArgs};
use marbre_core::image_decode::{IntegerDecode, decode_file};
use marbre_render::gpu::testing::gpu_or_skip;
use std::path::{Path, PathBuf};

#[derive(Parser)]
struct Cli {
    #[command(flatten)]
    args: RenderArgs,
}

fn args(flags: &[&str]) -> RenderArgs {
    Cli::try_parse_from(["render"].iter().chain(flags))
        .unwrap()
        .args
}

/// A board of 3D checker cubes of side `size` (black in the cell at the
/// origin, white next to it along x), facing a camera 4 units away on
/// its +z side, the board's `size` keyed linearly from 1.0 at t = 0 to
/// 1.4 at t = 0.5 s, seen in the albedo view (no light, no noise but the
/// pixel jitter) with the checkers unfiltered.
const BOARD: &str = r#"(
    format_version: 2,
    scene: (
        camera: (target: (0.0, 0.5, 0.25), distance: 4.0, yaw_degrees: 0.0, pitch_degrees: 0.0, fov_degrees: 40.0),
        spheres: [],
        polygons: [(
            name: "board",
            vertices: [(-10.0, -10.0, 0.25), (10.0, -10.0, 0.25), (10.0, 10.0, 0.25), (-10.0, 10.0, 0.25)],
            material: (diffuse: (pattern: Checker(size: 1.0), a: (0.0, 0.0, 0.0), b: (1.0, 1.0, 1.0))),
        )],
        ground: None,
        point_light: None,
        environment: (source: None),
        render: (view: Albedo, filter_checkers: false),
        animation: Some((
            duration: 1.0,
            fps: 4.0,
            tracks: [(
                path: "polygons[\"board\"].material.diffuse.pattern.size",
                keys: [(time: 0.0, value: 1.0, interpolation: Linear), (time: 0.5, value: 1.4)],
            )],
        )),
    ),
)"#;

const WIDTH: u32 = 100;
const HEIGHT: u32 = 50;

/// Where the edge x = `size` falls in the image, in pixels from the left:
/// the camera looks down −z at the board 4 units away with a vertical
/// field of 40° (`camera_ray` in shaders/trace.wgsl).
fn expected_edge(size: f64) -> f64 {
    let half_width = 4.0 * 20f64.to_radians().tan() * f64::from(WIDTH) / f64::from(HEIGHT);
    (size / half_width + 1.0) / 2.0 * f64::from(WIDTH)
}

/// The edge in the middle row, to a fraction of a pixel: the board is
/// black from x = 0 (the column past the image's centre) to the edge and
/// white beyond, so the black width is the sum of (1 − albedo) over the
/// columns between.
fn measured_edge(exr: &Path) -> f64 {
    let image = decode_file(exr, IntegerDecode::Linear).unwrap();
    assert_eq!((image.width, image.height), (WIDTH, HEIGHT));
    let row = (HEIGHT / 2) as usize;
    let from = (WIDTH / 2 + 1) as usize;
    let to = from + 30;
    let dark: f64 = (from..to)
        .map(|x| 1.0 - f64::from(image.pixels[row * WIDTH as usize + x][0]))
        .sum();
    from as f64 + dark
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("marbre-seq-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("board.ron"), BOARD).unwrap();
    dir
}

/// `marbre render` of `preset` to `output` at `size`, `spp` samples, the
/// fragment kernel, with the `extra` flags.
fn try_render(
    preset: &Path,
    output: &Path,
    size: &str,
    spp: &str,
    extra: &[&str],
) -> anyhow::Result<()> {
    let mut flags = vec![
        "--preset",
        preset.to_str().unwrap(),
        "-o",
        output.to_str().unwrap(),
        "--size",
        size,
        "--spp",
        spp,
        "--kernel",
        "fragment",
    ];
    flags.extend_from_slice(extra);
    render::run(&args(&flags))
}

fn render_board(dir: &Path, extra: &[&str]) {
    try_render(
        &dir.join("board.ron"),
        &dir.join("frame_##.exr"),
        "100x50",
        "64",
        extra,
    )
    .unwrap();
}

/// Frames 0, 1, 2 at 4 fps are t = 0, 0.25, 0.5 s: sizes 1.0, 1.2 and
/// 1.4, their edges 17.2 pixels apart; each lands within a quarter pixel
/// of its projection.
#[test]
fn each_frame_shows_its_keyed_moment() {
    if gpu_or_skip("each_frame_shows_its_keyed_moment").is_none() {
        return;
    }
    let dir = scratch("edge");
    render_board(&dir, &["--frames", "0..2"]);
    for (frame, size) in [(0, 1.0), (1, 1.2), (2, 1.4)] {
        let measured = measured_edge(&dir.join(format!("frame_{frame:02}.exr")));
        let expected = expected_edge(size);
        assert!(
            (measured - expected).abs() < 0.25,
            "frame {frame}: the edge at {measured:.3} px, expected {expected:.3}"
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A sequence stopped after some frames traces only the missing ones when
/// run again, and a frame traced again is the same file (its samples are
/// seeded by its number); --overwrite traces them all.
#[test]
fn a_stopped_sequence_resumes_with_the_same_samples() {
    if gpu_or_skip("a_stopped_sequence_resumes_with_the_same_samples").is_none() {
        return;
    }
    let dir = scratch("resume");
    render_board(&dir, &["--frames", "0..2"]);
    let bytes = |f: u32| std::fs::read(dir.join(format!("frame_{f:02}.exr"))).unwrap();
    let first: Vec<Vec<u8>> = (0..3).map(bytes).collect();
    assert!(first[0] != first[1], "frames differ");
    std::fs::remove_file(dir.join("frame_01.exr")).unwrap();
    // A marker in place of frame 2: skipped, so left as it is.
    std::fs::write(dir.join("frame_02.exr"), b"kept").unwrap();
    render_board(&dir, &["--frames", "0..2"]);
    assert!(
        bytes(1) == first[1],
        "frame 1 traced again, the same samples"
    );
    assert!(bytes(2) == b"kept", "an existing frame is skipped");
    render_board(&dir, &["--frames", "0..2", "--overwrite"]);
    assert!(
        bytes(2) == first[2],
        "frame 2 traced again, the same samples"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The frames of an unkeyed scene still trace their own samples: the
/// estimate's noise moves from frame to frame, and `--time` traces the
/// frame nearest its time.
#[test]
fn each_frame_traces_its_own_samples() {
    if gpu_or_skip("each_frame_traces_its_own_samples").is_none() {
        return;
    }
    let dir = scratch("seeds");
    let preset = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../presets/default.ron");
    let common = |output: &str, extra: &[&str]| {
        try_render(&preset, &dir.join(output), "32x24", "1", extra).unwrap()
    };
    common("f_#.exr", &["--frames", "0..1"]);
    common("still.exr", &[]);
    common("at.exr", &["--time", "0.5", "--fps", "2"]);
    // The pixels: each file's render record says its own frame and time.
    let read = |name: &str| {
        decode_file(&dir.join(name), IntegerDecode::Linear)
            .unwrap()
            .pixels
    };
    assert!(
        read("f_0.exr") != read("f_1.exr"),
        "frame 1's samples are its own"
    );
    assert!(read("f_0.exr") == read("still.exr"), "frame 0 is the still");
    assert!(
        read("f_1.exr") == read("at.exr"),
        "t = 0.5 s at 2 fps is frame 1"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `--animation` assembles the PNG frames: an APNG and a GIF decode with
/// one frame per frame rendered, the APNG's equal to the PNG files.
#[test]
fn an_animation_holds_every_frame() {
    if gpu_or_skip("an_animation_holds_every_frame").is_none() {
        return;
    }
    use image::AnimationDecoder;
    let dir = scratch("animated");
    let preset = dir.join("board.ron");
    for animated in ["board.apng", "board.gif"] {
        let animation = dir.join(animated);
        let extra = [
            "--frames",
            "0..3",
            "--animation",
            animation.to_str().unwrap(),
        ];
        try_render(&preset, &dir.join("f_#.png"), "40x20", "4", &extra).unwrap();
    }
    let file = |n: &str| std::io::BufReader::new(std::fs::File::open(dir.join(n)).unwrap());
    let apng = image::codecs::png::PngDecoder::new(file("board.apng")).unwrap();
    let frames: Vec<image::Frame> = apng
        .apng()
        .unwrap()
        .into_frames()
        .collect::<Result<_, _>>()
        .unwrap();
    assert_eq!(frames.len(), 4);
    for (i, frame) in frames.iter().enumerate() {
        let png = image::open(dir.join(format!("f_{i}.png")))
            .unwrap()
            .to_rgba8();
        assert_eq!(frame.buffer(), &png, "frame {i}");
    }
    let gif = image::codecs::gif::GifDecoder::new(file("board.gif")).unwrap();
    assert_eq!(gif.into_frames().count(), 4);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Timing that cannot be traced is refused before anything is written,
/// naming the flag or the field.
#[test]
fn bad_timing_is_refused_before_writing() {
    let dir = scratch("bad");
    let preset = dir.join("board.ron");
    let run = |extra: &[&str], output: &str| {
        try_render(&preset, &dir.join(output), "8x8", "1", extra)
            .unwrap_err()
            .to_string()
    };
    let e = run(&["--frames", "0..3", "--fps", "0"], "f_#.png");
    assert!(e.contains("--fps must be a positive number"), "{e}");
    let e = run(&["--frames", "0..3"], "f.png");
    assert!(e.contains("run of #"), "{e}");
    let e = run(&["--frames", "0..3", "--animation", "x.avi"], "f_#.png");
    assert!(e.contains("x.avi") && e.contains(".gif, .apng"), "{e}");
    let e = run(&["--frames", "0..3", "--animation", "x.gif"], "f_#.exr");
    assert!(e.contains("PNG frames"), "{e}");
    let reversed =
        Cli::try_parse_from(["render", "--preset", "p", "-o", "x.png", "--frames", "5..2"]);
    let e = reversed.err().unwrap().to_string();
    assert!(e.contains("reversed"), "{e}");
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names, ["board.ron"], "nothing written");
    std::fs::remove_dir_all(&dir).unwrap();
}
