//! One file holding a sequence's frames: an animated GIF (the image
//! crate's encoder) or APNG (the png crate's, which the image crate
//! decodes but does not write), or, through ffmpeg when it is installed,
//! an animated WebP or an MP4 (H.264). Written atomically, as every
//! output.

use crate::atomic_write::{write_atomic, write_atomic_with};
use crate::child_process;
use anyhow::{Context, Result, bail};
use image::RgbaImage;
use std::borrow::Borrow;
use std::io::Write;
use std::path::Path;
use std::process::{Command, Stdio};

/// The kinds of animated file, by extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AnimatedFormat {
    Gif,
    Apng,
    Webp,
    Mp4,
}

impl AnimatedFormat {
    pub fn from_path(path: &Path) -> Result<Self> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        Ok(match ext.as_deref() {
            Some("gif") => AnimatedFormat::Gif,
            Some("apng") => AnimatedFormat::Apng,
            Some("webp") => AnimatedFormat::Webp,
            Some("mp4") => AnimatedFormat::Mp4,
            _ => bail!(
                "{}: an animation is written as .gif, .apng, .webp or .mp4",
                path.display()
            ),
        })
    }

    /// Whether writing it needs ffmpeg.
    pub fn needs_ffmpeg(self) -> bool {
        matches!(self, AnimatedFormat::Webp | AnimatedFormat::Mp4)
    }
}

/// Refuses, before any tracing, an animation that cannot be written: an
/// unknown extension, or ffmpeg missing for WebP and MP4.
pub fn check_writable(path: &Path) -> Result<AnimatedFormat> {
    let format = AnimatedFormat::from_path(path)?;
    if format.needs_ffmpeg() && !ffmpeg_available() {
        bail!(
            "{}: writing .webp and .mp4 animations needs ffmpeg (the Debian package `ffmpeg`), \
             which is not on PATH; .gif and .apng are written without it",
            path.display()
        );
    }
    Ok(format)
}

fn ffmpeg_available() -> bool {
    child_process::spawn(
        Command::new("ffmpeg")
            .arg("-version")
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .stdin(Stdio::null()),
    )
    .and_then(|p| p.wait_after(None))
    .is_ok_and(|(status, _)| status.success())
}

/// Writes `frames` (all one size) shown `fps` a second, looping forever.
pub fn save_animation(frames: &[RgbaImage], fps: f32, path: &Path) -> Result<()> {
    let format = check_writable(path)?;
    let Some(first) = frames.first() else {
        bail!("{}: no frames to write", path.display());
    };
    if let Some(odd) = frames.iter().find(|f| f.dimensions() != first.dimensions()) {
        bail!(
            "{}: the frames are not all one size ({:?} and {:?})",
            path.display(),
            first.dimensions(),
            odd.dimensions()
        );
    }
    let bytes = match format {
        AnimatedFormat::Gif => encode_gif(frames, fps)?,
        AnimatedFormat::Apng => encode_apng(frames, fps)?,
        AnimatedFormat::Webp | AnimatedFormat::Mp4 => {
            return save_through_ffmpeg(frames.iter().map(Ok), fps, path);
        }
    };
    write_atomic(path, &bytes).with_context(|| format!("writing {}", path.display()))?;
    Ok(())
}

/// A frame's delay as a fraction of a second: `1/fps` as a ratio of
/// integers, in hundredths for GIF (its unit).
fn delay_ms(fps: f32) -> (u32, u32) {
    let ms = (1000.0 / f64::from(fps)).round().max(10.0) as u32;
    (ms, 1)
}

fn encode_gif(frames: &[RgbaImage], fps: f32) -> Result<Vec<u8>> {
    use image::codecs::gif::{GifEncoder, Repeat};
    let mut bytes = Vec::new();
    {
        let mut encoder = GifEncoder::new_with_speed(&mut bytes, 10);
        encoder.set_repeat(Repeat::Infinite)?;
        let (numer, denom) = delay_ms(fps);
        let delay = image::Delay::from_numer_denom_ms(numer, denom);
        for frame in frames {
            encoder.encode_frame(image::Frame::from_parts(frame.clone(), 0, 0, delay))?;
        }
    }
    Ok(bytes)
}

fn encode_apng(frames: &[RgbaImage], fps: f32) -> Result<Vec<u8>> {
    let (width, height) = frames[0].dimensions();
    let mut bytes = Vec::new();
    {
        let mut encoder = png::Encoder::new(&mut bytes, width, height);
        encoder.set_color(png::ColorType::Rgba);
        encoder.set_depth(png::BitDepth::Eight);
        encoder.set_animated(frames.len() as u32, 0)?;
        // The delay as fps's ratio: 1/24 s is 1000/24000 exactly.
        encoder.set_frame_delay(1000, (f64::from(fps) * 1000.0).round() as u16)?;
        let mut writer = encoder.write_header()?;
        for frame in frames {
            writer.write_image_data(frame.as_raw())?;
        }
        writer.finish()?;
    }
    Ok(bytes)
}

/// Writes a WebP or an MP4 (by `path`'s extension) through ffmpeg, the
/// frames (all one size) piped in as PNGs as `frames` gives them: the
/// image crate writes neither an animated WebP nor video, and ffmpeg is
/// what Blender and every farm use for both. ffmpeg writes the save's
/// temporary beside `path` ([`write_atomic_with`]) and is listed as a
/// child ([`child_process`]): a command stopped by a signal ends it and
/// removes that temporary, and nothing is left in the system's temporary
/// folder.
pub fn save_through_ffmpeg<F: Borrow<RgbaImage>>(
    frames: impl IntoIterator<Item = Result<F>>,
    fps: f32,
    path: &Path,
) -> Result<()> {
    let format = AnimatedFormat::from_path(path)?;
    let (muxer, codec): (&str, &[&str]) = match format {
        // yuv420p plays everywhere; it needs even sides, hence the pad.
        AnimatedFormat::Mp4 => (
            "mp4",
            &[
                "-c:v",
                "libx264",
                "-pix_fmt",
                "yuv420p",
                "-vf",
                "pad=ceil(iw/2)*2:ceil(ih/2)*2",
            ],
        ),
        AnimatedFormat::Webp => (
            "webp",
            &["-c:v", "libwebp_anim", "-lossless", "1", "-loop", "0"],
        ),
        AnimatedFormat::Gif | AnimatedFormat::Apng => {
            bail!("{}: ffmpeg writes only .webp and .mp4 here", path.display())
        }
    };
    write_atomic_with(path, |temporary: &Path| -> Result<()> {
        let ffmpeg = child_process::spawn(
            Command::new("ffmpeg")
                .args(["-y", "-loglevel", "error", "-f", "image2pipe", "-framerate"])
                .arg(fps.to_string())
                .args(["-i", "-"])
                .args(codec)
                // The temporary's name ends in .tmp: the muxer is named.
                .args(["-f", muxer])
                .arg(temporary)
                .stdin(Stdio::piped())
                .stdout(Stdio::null())
                .stderr(Stdio::piped()),
        )
        .context("starting ffmpeg")?;
        let stdin = ffmpeg.take_stdin();
        let stderr = ffmpeg.take_stderr();
        // stderr is read on a thread while the frames go in, so that
        // neither pipe fills and stops the other.
        let errors = std::thread::spawn(move || ffmpeg.wait_after(stderr));
        let piped = pipe_frames(frames, stdin, path);
        let (status, text) = errors
            .join()
            .map_err(|_| anyhow::anyhow!("reading ffmpeg's messages failed"))??;
        if !status.success() {
            bail!("ffmpeg failed ({status}): {}", text.trim());
        }
        piped
    })
    .with_context(|| format!("writing {}", path.display()))
}

/// Writes each frame, as a PNG, to ffmpeg's stdin, which is closed after
/// the last (the end of ffmpeg's input).
fn pipe_frames<F: Borrow<RgbaImage>>(
    frames: impl IntoIterator<Item = Result<F>>,
    stdin: Option<std::process::ChildStdin>,
    path: &Path,
) -> Result<()> {
    let mut stdin = stdin.context("ffmpeg's stdin")?;
    let mut size = None;
    for frame in frames {
        let frame = frame?;
        let frame = frame.borrow();
        let first = *size.get_or_insert(frame.dimensions());
        if frame.dimensions() != first {
            bail!(
                "{}: the frames are not all one size ({first:?} and {:?})",
                path.display(),
                frame.dimensions()
            );
        }
        stdin.write_all(&crate::image_io::encode_png(frame)?)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use image::AnimationDecoder;

    fn frames(n: u8) -> Vec<RgbaImage> {
        (0..n)
            .map(|i| RgbaImage::from_fn(8, 6, |x, _| image::Rgba([i * 40, x as u8 * 30, 0, 255])))
            .collect()
    }

    /// GIF and APNG decode (with the image crate's decoders) to the
    /// frames written, in order, at 1/fps each.
    #[test]
    fn gif_and_apng_decode_with_their_frames() {
        let dir = tempfile::tempdir().unwrap();
        let written = frames(5);
        let gif = dir.path().join("a.gif");
        save_animation(&written, 25.0, &gif).unwrap();
        let decoder = image::codecs::gif::GifDecoder::new(std::io::BufReader::new(
            std::fs::File::open(&gif).unwrap(),
        ))
        .unwrap();
        let read: Vec<image::Frame> = decoder.into_frames().collect::<Result<_, _>>().unwrap();
        assert_eq!(read.len(), 5);
        assert_eq!(read[0].delay().numer_denom_ms(), (40, 1));
        // GIF's palette keeps these few colours exactly.
        assert_eq!(read[3].buffer().get_pixel(2, 1), written[3].get_pixel(2, 1));

        let apng = dir.path().join("a.apng");
        save_animation(&written, 24.0, &apng).unwrap();
        let decoder = image::codecs::png::PngDecoder::new(std::io::BufReader::new(
            std::fs::File::open(&apng).unwrap(),
        ))
        .unwrap();
        assert!(decoder.is_apng().unwrap());
        let read: Vec<image::Frame> = decoder
            .apng()
            .unwrap()
            .into_frames()
            .collect::<Result<_, _>>()
            .unwrap();
        assert_eq!(read.len(), 5);
        for (r, w) in read.iter().zip(&written) {
            assert_eq!(r.buffer(), w);
        }
        let (n, d) = read[1].delay().numer_denom_ms();
        assert!(
            (f64::from(n) / f64::from(d) - 1000.0 / 24.0).abs() < 1e-9,
            "{n}/{d}"
        );
    }

    /// Whether ffmpeg is here; without it, a loud banner (a failure
    /// under `MARBRE_REQUIRE_GPU=1`, as CI runs, where `.ci/run` installs
    /// it).
    fn ffmpeg_or_skip(test: &str) -> bool {
        if ffmpeg_available() {
            return true;
        }
        let banner = format!(
            "SKIPPED {test}: ffmpeg is not installed (Debian package `ffmpeg`); \
             its WebP and MP4 files are not checked"
        );
        assert!(
            std::env::var("MARBRE_REQUIRE_GPU").as_deref() != Ok("1"),
            "{banner} (MARBRE_REQUIRE_GPU=1 turns the skip into a failure)"
        );
        eprintln!("\n{}\n{banner}\n{}\n", "!".repeat(72), "!".repeat(72));
        false
    }

    /// The frames of an animated WebP, read from its RIFF chunks (ffmpeg
    /// 5 writes animated WebP but does not read it back): the canvas
    /// (VP8X) and the number of frames (ANMF).
    fn webp_canvas_and_frames(bytes: &[u8]) -> ((u32, u32), usize) {
        assert_eq!(&bytes[0..4], b"RIFF");
        assert_eq!(&bytes[8..12], b"WEBP");
        let (mut at, mut canvas, mut frames) = (12, (0, 0), 0);
        while at + 8 <= bytes.len() {
            let id = &bytes[at..at + 4];
            let size = u32::from_le_bytes(bytes[at + 4..at + 8].try_into().unwrap()) as usize;
            let data = &bytes[at + 8..at + 8 + size];
            let u24 = |b: &[u8]| u32::from_le_bytes([b[0], b[1], b[2], 0]) + 1;
            match id {
                b"VP8X" => canvas = (u24(&data[4..7]), u24(&data[7..10])),
                b"ANMF" => frames += 1,
                _ => {}
            }
            at += 8 + size + size % 2;
        }
        (canvas, frames)
    }

    /// Through ffmpeg: the WebP holds every frame at the frames' size;
    /// the MP4, probed by ffprobe, holds every frame, its sides padded
    /// to even numbers (yuv420p), at the frame rate asked.
    #[test]
    fn webp_and_mp4_hold_every_frame() {
        if !ffmpeg_or_skip("webp_and_mp4_hold_every_frame") {
            return;
        }
        let dir = tempfile::tempdir().unwrap();
        let written: Vec<RgbaImage> = (0..7u8)
            .map(|i| RgbaImage::from_fn(9, 5, |x, _| image::Rgba([i * 30, x as u8 * 25, 0, 255])))
            .collect();
        let webp = dir.path().join("a.webp");
        save_animation(&written, 12.0, &webp).unwrap();
        assert_eq!(
            webp_canvas_and_frames(&std::fs::read(&webp).unwrap()),
            ((9, 5), 7)
        );
        let mp4 = dir.path().join("a.mp4");
        save_animation(&written, 12.0, &mp4).unwrap();
        let probe = Command::new("ffprobe")
            .args(["-v", "error", "-count_frames", "-select_streams", "v:0"])
            .args([
                "-show_entries",
                "stream=nb_read_frames,width,height,r_frame_rate",
            ])
            .args(["-of", "default=noprint_wrappers=1"])
            .arg(&mp4)
            .output()
            .unwrap();
        let text = String::from_utf8(probe.stdout).unwrap();
        for expected in [
            "width=10",
            "height=6",
            "r_frame_rate=12/1",
            "nb_read_frames=7",
        ] {
            assert!(text.lines().any(|l| l == expected), "{expected} in {text}");
        }
    }

    /// An unknown extension, and WebP or MP4 without ffmpeg, are refused
    /// naming the file (and the package), nothing written.
    #[test]
    fn unwritable_animations_are_refused_before_work() {
        let dir = tempfile::tempdir().unwrap();
        let avi = dir.path().join("a.avi");
        let e = check_writable(&avi).unwrap_err().to_string();
        assert!(
            e.contains("a.avi") && e.contains(".gif, .apng, .webp or .mp4"),
            "{e}"
        );
        if !ffmpeg_available() {
            let mp4 = dir.path().join("a.mp4");
            let e = save_animation(&frames(2), 24.0, &mp4)
                .unwrap_err()
                .to_string();
            assert!(
                e.contains("a.mp4") && e.contains("Debian package `ffmpeg`"),
                "{e}"
            );
            assert!(!mp4.exists());
        }
    }
}
